//! ROS 2 `sensor_msgs/msg/Image` as a Navtech polar scan.
//!
//! Layout (CDR, after the encapsulation header): `header` (`stamp`,
//! `frame_id`), `uint32 height`, `uint32 width`, `string encoding`,
//! `uint8 is_bigendian`, `uint32 step`, `sequence<uint8> data`. Decoded by hand
//! with the bounds-checked reader of [`crate::cdr`]: a truncated or corrupt
//! message is an error naming the field.
//!
//! As a polar scan: `mono8` (or `8UC1`), one image row per azimuth and one
//! column per range bin, rows `step` bytes apart. The message carries one
//! stamp per sweep, so azimuth times are spread evenly over the scan period
//! against `header.stamp` ([`SweepTiming`]; by default the stamp is the last
//! azimuth, as a driver publishes a sweep once complete) and row `a` of `n`
//! is at angle `a * 2 pi / n`. The range bin size is not in the message and
//! must be given.

use mmtrack_core::{PolarScan, PolarScanHeader};

use crate::cdr::Cdr;
use crate::sweep::SweepTiming;

/// A decoded `sensor_msgs/msg/Image`, pixels borrowed from the message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RosImage<'a> {
    /// `header.stamp`, nanoseconds.
    pub t_ns: i64,
    /// `header.frame_id`.
    pub frame_id: String,
    /// Rows.
    pub height: usize,
    /// Columns.
    pub width: usize,
    /// Pixel encoding, e.g. `mono8`.
    pub encoding: String,
    /// Bytes from one row to the next.
    pub step: usize,
    /// The pixel bytes.
    pub data: &'a [u8],
}

/// Decodes a CDR `sensor_msgs/msg/Image`.
pub fn decode_image(data: &[u8]) -> Result<RosImage<'_>, String> {
    let mut cdr = Cdr::new(data)?;
    let t_ns = cdr.stamp_ns("header.stamp")?;
    let frame_id = cdr.string("header.frame_id")?;
    let height = cdr.u32("height")? as usize;
    let width = cdr.u32("width")? as usize;
    let encoding = cdr.string("encoding")?;
    let _is_bigendian = cdr.u8("is_bigendian")?;
    let step = cdr.u32("step")? as usize;
    let data = cdr.byte_sequence("data")?;
    Ok(RosImage { t_ns, frame_id, height, width, encoding, step, data })
}

/// The image as a polar scan: rows are azimuths, columns range bins.
pub fn image_to_scan(image: &RosImage<'_>, timing: &SweepTiming, range_resolution_m: f64) -> Result<PolarScan, String> {
    if image.encoding != "mono8" && image.encoding != "8UC1" {
        return Err(format!("encoding: '{}', expected mono8 (8UC1) polar power", image.encoding));
    }
    if image.height == 0 || image.width == 0 {
        return Err(format!("height/width: {} x {} image has no pixels", image.height, image.width));
    }
    if image.step < image.width {
        return Err(format!("step: {} bytes per row is less than the width {}", image.step, image.width));
    }
    let needed = (image.height - 1).checked_mul(image.step).and_then(|n| n.checked_add(image.width));
    if needed.is_none_or(|n| image.data.len() < n) {
        return Err(format!(
            "data: {} bytes, expected {} rows of step {} (width {})",
            image.data.len(),
            image.height,
            image.step,
            image.width
        ));
    }
    let mut power = Vec::with_capacity(image.height * image.width);
    for row in image.data.chunks(image.step).take(image.height) {
        power.extend_from_slice(&row[..image.width]);
    }
    let azimuths = timing.azimuths(image.t_ns, image.height).map_err(|e| format!("azimuth times: {e}"))?;
    let header = PolarScanHeader {
        t_ns: image.t_ns,
        range_resolution_m,
        range_offset_m: 0.0,
        bins_per_azimuth: image.width,
        azimuths,
    };
    PolarScan::new(header, power).map_err(|e| format!("geometry: {e}"))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sweep::StampAt;
    use proptest::prelude::*;

    /// A little-endian CDR `sensor_msgs/msg/Image` (what rclcpp writes).
    pub(crate) fn image_message(
        stamp: (i32, u32),
        height: u32,
        width: u32,
        encoding: &str,
        step: u32,
        data: &[u8],
    ) -> Vec<u8> {
        let mut out = vec![0, 1, 0, 0];
        let align = |out: &mut Vec<u8>, n: usize| {
            while !(out.len() - 4).is_multiple_of(n) {
                out.push(0);
            }
        };
        let string = |out: &mut Vec<u8>, s: &str| {
            align(out, 4);
            out.extend_from_slice(&(s.len() as u32 + 1).to_le_bytes());
            out.extend_from_slice(s.as_bytes());
            out.push(0);
        };
        out.extend_from_slice(&stamp.0.to_le_bytes());
        out.extend_from_slice(&stamp.1.to_le_bytes());
        string(&mut out, "radar");
        align(&mut out, 4);
        out.extend_from_slice(&height.to_le_bytes());
        out.extend_from_slice(&width.to_le_bytes());
        string(&mut out, encoding);
        out.push(0);
        align(&mut out, 4);
        out.extend_from_slice(&step.to_le_bytes());
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(data);
        out
    }

    #[test]
    fn mono8_image_becomes_a_scan_with_rows_as_azimuths() {
        // 4 azimuths of 3 bins, rows padded to a step of 5.
        let data: Vec<u8> = (0..4u8).flat_map(|a| [10 * a, 10 * a + 1, 10 * a + 2, 99, 99]).collect();
        let message = image_message((1_600_000_000, 250_000_000), 4, 3, "mono8", 5, &data);
        let image = decode_image(&message).unwrap();
        assert_eq!(
            (image.t_ns, image.frame_id.as_str(), image.height, image.width),
            (1_600_000_000_250_000_000, "radar", 4, 3)
        );
        let scan = image_to_scan(&image, &SweepTiming::default(), 0.0438).unwrap();
        assert_eq!(scan.row(2).unwrap(), &[20, 21, 22]);
        assert_eq!(scan.header.azimuths[3].t_ns, 1_600_000_000_250_000_000);
        assert_eq!(scan.header.azimuths[0].t_ns, 1_600_000_000_250_000_000 - 3 * 62_500_000);
        let start = SweepTiming { stamp_at: StampAt::Start, ..SweepTiming::default() };
        assert_eq!(image_to_scan(&image, &start, 0.0438).unwrap().header.azimuths[0].t_ns, image.t_ns);
    }

    #[test]
    fn bad_images_name_the_field() {
        let message = image_message((1, 0), 4, 3, "rgb8", 3, &[0; 12]);
        let err = image_to_scan(&decode_image(&message).unwrap(), &SweepTiming::default(), 0.05).unwrap_err();
        assert!(err.contains("encoding") && err.contains("mono8"), "{err}");
        let message = image_message((1, 0), 4, 3, "mono8", 3, &[0; 11]);
        let err = image_to_scan(&decode_image(&message).unwrap(), &SweepTiming::default(), 0.05).unwrap_err();
        assert!(err.starts_with("data: 11 bytes"), "{err}");
        let message = image_message((1, 0), 4, 3, "mono8", 2, &[0; 12]);
        let err = image_to_scan(&decode_image(&message).unwrap(), &SweepTiming::default(), 0.05).unwrap_err();
        assert!(err.starts_with("step"), "{err}");
        let message = image_message((1, 0), 4, 3, "mono8", 3, &[0; 12]);
        let err = decode_image(&message[..message.len() - 1]).unwrap_err();
        assert!(err.starts_with("data"), "{err}");
    }

    /// Writes a bag (MCAP, cdr) with one `sensor_msgs/msg/Image` channel.
    fn bag(path: &std::path::Path, messages: &[Vec<u8>]) {
        use mmtrack_io::recording::{ChannelInfo, RawMessage, RecordingMetadata, TimeBase};
        let channel = std::sync::Arc::new(ChannelInfo {
            topic: "/Navtech/Polar".into(),
            schema_name: "sensor_msgs/msg/Image".into(),
            message_encoding: "cdr".into(),
            schema_encoding: "ros2msg".into(),
            schema_data: std::sync::Arc::from(&b"std_msgs/Header header\nuint32 height\n"[..]),
            metadata: Default::default(),
        });
        let metadata = RecordingMetadata {
            sequence_id: "bag".into(),
            source: "test".into(),
            time_base: TimeBase::UnixEpoch,
            extra: Default::default(),
        };
        let options = mmtrack_io::RecordingOptions {
            overwrite: mmtrack_io::Overwrite::Replace,
            ..mmtrack_io::RecordingOptions::default()
        };
        let mut writer = mmtrack_io::RecordingWriter::create(path, &metadata, &options).unwrap();
        for (index, data) in messages.iter().enumerate() {
            // Sequence 0 on every message, as rosbag2 writes them.
            let message = RawMessage {
                channel: channel.clone(),
                sequence: 0,
                log_time_ns: 1_000 + index as u64,
                data: bytes::Bytes::from(data.clone()),
            };
            writer.copy_message(&message).unwrap();
        }
        writer.finish().unwrap();
    }

    #[test]
    fn a_bag_radar_topic_becomes_scans_and_bad_messages_are_named() {
        use crate::ros2::{RadarTopic, Ros2Topics, ingest_ros2};
        let dir = tempfile::tempdir().unwrap();
        let messages: Vec<Vec<u8>> =
            (0..3).map(|i| image_message((1_600_000_000 + i, 0), 8, 5, "mono8", 5, &[i as u8; 40])).collect();
        let input = dir.path().join("bag.mcap");
        bag(&input, &messages);
        let topics = Ros2Topics {
            pose_topic: None,
            ground_truth_topic: None,
            radar: Some(RadarTopic {
                topic: "/Navtech/Polar".into(),
                range_resolution_m: 0.0596,
                timing: SweepTiming::default(),
            }),
            ..Ros2Topics::default()
        };
        let out = dir.path().join("rec.mcap");
        let report = ingest_ros2(&input, &out, &topics, &Default::default(), &mut |_, _| {}).unwrap();
        assert_eq!(report.radar_scans, 3);
        let scans: Vec<PolarScan> = mmtrack_io::RecordingReader::open(&out)
            .unwrap()
            .filter_map(|e| match e.unwrap() {
                mmtrack_io::RecordingEvent::RadarScan(s) => Some(s),
                _ => None,
            })
            .collect();
        assert_eq!(scans.len(), 3);
        assert_eq!((scans[2].header.azimuths.len(), scans[2].header.bins_per_azimuth), (8, 5));
        assert_eq!(scans[2].header.azimuths[7].t_ns, 1_600_000_002_000_000_000);
        assert_eq!(scans[2].power, vec![2; 40]);

        // A stamp going backwards and a truncated message: named, no output.
        let backwards = vec![messages[1].clone(), messages[0].clone()];
        bag(&input, &backwards);
        let out = dir.path().join("bad.mcap");
        let err = ingest_ros2(&input, &out, &topics, &Default::default(), &mut |_, _| {}).unwrap_err().to_string();
        assert!(
            err.contains("message 1 on /Navtech/Polar (0-based, log time 1001 ns)")
                && err.contains("does not increase"),
            "{err}"
        );
        // Before: every message was "message 0" (the MCAP sequence, which
        // rosbag2 leaves 0); the 51st message is message 50.
        let mut long: Vec<Vec<u8>> =
            (0..60).map(|i| image_message((1_600_000_000 + i, 0), 8, 5, "mono8", 5, &[0; 40])).collect();
        long[50] = messages[0].clone();
        bag(&input, &long);
        let err = ingest_ros2(&input, &out, &topics, &Default::default(), &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("message 50 on /Navtech/Polar (0-based, log time 1050 ns)"), "{err}");
        let cut = messages[0][..messages[0].len() - 3].to_vec();
        bag(&input, &[cut]);
        let err = ingest_ros2(&input, &out, &topics, &Default::default(), &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("sensor_msgs/msg/Image") && err.contains("data"), "{err}");
        assert!(!out.exists(), "no partial output");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]
        /// Random bytes, truncations and byte flips of a valid message never panic
        /// the decoder or the conversion.
        #[test]
        fn image_decoder_never_panics(
            bytes in proptest::collection::vec(any::<u8>(), 0..300),
            cut in 0usize..200,
            flips in proptest::collection::vec((0usize..200, any::<u8>()), 0..4),
        ) {
            let _ = decode_image(&bytes).map(|i| image_to_scan(&i, &SweepTiming::default(), 0.05));
            let mut valid = image_message((5, 0), 6, 7, "mono8", 8, &[3; 48]);
            for (at, value) in flips {
                let len = valid.len();
                valid[at % len] = value;
            }
            valid.truncate(cut.max(4).min(valid.len()));
            let _ = decode_image(&valid).map(|i| image_to_scan(&i, &SweepTiming::default(), 0.05));
        }
    }
}
