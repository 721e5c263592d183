//! ROS 2 MCAP bags (message encoding `cdr`).
//!
//! Decoded message types: `nav_msgs/msg/Odometry` and
//! `geometry_msgs/msg/PoseWithCovarianceStamped` (as planar poses: x, y and
//! the yaw of the orientation quaternion; ROS frames are z up, as ours),
//! `sensor_msgs/msg/NavSatFix` (as GNSS fixes) and `sensor_msgs/msg/Image`
//! (as Navtech polar scans, see [`crate::ros2_image`]). A pose is stamped with its
//! message's `header.stamp`, not the bag's log time.
//!
//! Messages are decoded by hand with the bounds-checked CDR reader of
//! [`crate::cdr`]: a truncated or corrupted message is an error naming the
//! field, never a panic.

use std::collections::BTreeMap;
use std::path::Path;

use mmtrack_core::plausible::{ALTITUDE_M, COORDINATE_M, LATITUDE_DEG, LONGITUDE_DEG};
use mmtrack_core::{GnssFix, GnssFixQuality, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, RawReader, RecordingMetadata, TimeBase, WriteSummary};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::cdr::Cdr;
use crate::sweep::SweepTiming;
use crate::{IngestError, Progress};

/// A planar pose decoded from a ROS message, with its frames.
#[derive(Debug, Clone, PartialEq)]
pub struct RosPose {
    /// `header.stamp` as the pose, parent from child.
    pub pose: StampedPose,
    /// `header.frame_id`.
    pub frame_id: String,
    /// `child_frame_id` (Odometry), empty otherwise.
    pub child_frame_id: String,
}

fn header(cdr: &mut Cdr<'_>) -> Result<(i64, String), String> {
    Ok((cdr.stamp_ns("header.stamp")?, cdr.string("header.frame_id")?))
}

/// `geometry_msgs/Pose` as a planar transform: yaw of the quaternion,
/// `atan2(2 (w z + x y), 1 - 2 (y^2 + z^2))`, after a check that it is a unit
/// quaternion ([`crate::poses::unit_quaternion`]: a zero quaternion is an error).
fn planar_pose(cdr: &mut Cdr<'_>) -> Result<Se2, String> {
    let (x, y) = (cdr.f64("pose.position.x")?, cdr.f64("pose.position.y")?);
    let _z = cdr.f64("pose.position.z")?;
    let q =
        [cdr.f64("orientation.x")?, cdr.f64("orientation.y")?, cdr.f64("orientation.z")?, cdr.f64("orientation.w")?];
    let q = crate::poses::unit_quaternion(q).map_err(|e| format!("pose.orientation: {e}"))?;
    let x = COORDINATE_M.check(x).map_err(|e| format!("pose.position.x: {e}"))?;
    let y = COORDINATE_M.check(y).map_err(|e| format!("pose.position.y: {e}"))?;
    Ok(Se2::new(x, y, (2.0 * (q[3] * q[2] + q[0] * q[1])).atan2(1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]))))
}

/// Decodes `nav_msgs/msg/Odometry` (the pose part).
pub fn decode_odometry(data: &[u8]) -> Result<RosPose, String> {
    let mut cdr = Cdr::new(data)?;
    let (t_ns, frame_id) = header(&mut cdr)?;
    let child_frame_id = cdr.string("child_frame_id")?;
    let pose = planar_pose(&mut cdr)?;
    Ok(RosPose { pose: StampedPose { t_ns, parent_from_child: pose }, frame_id, child_frame_id })
}

/// Decodes `geometry_msgs/msg/PoseWithCovarianceStamped` (the pose part).
pub fn decode_pose_with_covariance_stamped(data: &[u8]) -> Result<RosPose, String> {
    let mut cdr = Cdr::new(data)?;
    let (t_ns, frame_id) = header(&mut cdr)?;
    let pose = planar_pose(&mut cdr)?;
    Ok(RosPose { pose: StampedPose { t_ns, parent_from_child: pose }, frame_id, child_frame_id: String::new() })
}

/// Decodes `sensor_msgs/msg/NavSatFix`; `None` when its status says no fix (-1).
/// A NaN altitude is "no altitude available", as the message definition
/// says; an infinite one is an error.
///
/// `horizontal_sigma_m` is `sqrt((C_ee + C_nn) / 2)` from the ENU covariance
/// when its type is not UNKNOWN (0). ROS status 0/1/2 (fix, SBAS, GBAS) map to
/// autonomous / differential / differential.
pub fn decode_nav_sat_fix(data: &[u8]) -> Result<Option<GnssFix>, String> {
    let mut cdr = Cdr::new(data)?;
    let (t_ns, _) = header(&mut cdr)?;
    let status = cdr.u8("status.status")? as i8;
    let _service = cdr.u16("status.service")?;
    let (latitude_deg, longitude_deg, altitude) = (cdr.f64("latitude")?, cdr.f64("longitude")?, cdr.f64("altitude")?);
    let mut covariance = [0.0; 9];
    for c in &mut covariance {
        *c = cdr.f64("position_covariance")?;
    }
    let covariance_type = cdr.u8("position_covariance_type")?;
    if status < 0 {
        return Ok(None);
    }
    let latitude_deg = LATITUDE_DEG.check(latitude_deg).map_err(|e| format!("latitude: {e}"))?;
    let longitude_deg = LONGITUDE_DEG.check(longitude_deg).map_err(|e| format!("longitude: {e}"))?;
    // NaN is the message's "unknown altitude".
    let altitude_m = match altitude {
        a if a.is_nan() => None,
        a => Some(ALTITUDE_M.check(a).map_err(|e| format!("altitude: {e} (NaN when unknown)"))?),
    };
    let sigma =
        (covariance_type != 0).then(|| ((covariance[0] + covariance[4]) / 2.0).sqrt()).filter(|s| s.is_finite());
    Ok(Some(GnssFix {
        t_ns,
        latitude_deg,
        longitude_deg,
        altitude_m,
        horizontal_sigma_m: sigma,
        num_satellites: None,
        quality: if status == 0 { GnssFixQuality::Autonomous } else { GnssFixQuality::Differential },
    }))
}

/// A `sensor_msgs/msg/Image` topic of Navtech polar scans (see
/// [`crate::ros2_image`]).
#[derive(Debug, Clone)]
pub struct RadarTopic {
    /// The topic.
    pub topic: String,
    /// Range bin size, metres (not in the message).
    pub range_resolution_m: f64,
    /// How azimuth times are placed against `header.stamp`.
    pub timing: SweepTiming,
}

/// Message types a pose topic may have.
pub const POSE_TYPES: [&str; 2] = ["nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseWithCovarianceStamped"];
/// Message type of a GNSS topic.
pub const GNSS_TYPES: [&str; 1] = ["sensor_msgs/msg/NavSatFix"];
/// Message type of a radar topic.
pub const RADAR_TYPES: [&str; 1] = ["sensor_msgs/msg/Image"];

/// Which topics to take from a bag, and as what.
#[derive(Debug, Clone)]
pub struct Ros2Topics {
    /// Pose topic (`nav_msgs/msg/Odometry` or `geometry_msgs/msg/PoseWithCovarianceStamped`).
    pub pose_topic: Option<String>,
    /// Whether the poses are ground truth or an estimate.
    pub pose_stream: PoseStream,
    /// A second pose topic recorded as ground truth (e.g. `/amcl_pose`
    /// beside `/odom`), so one recording holds an estimate and its reference.
    pub ground_truth_topic: Option<String>,
    /// `sensor_msgs/msg/NavSatFix` topic.
    pub gnss_topic: Option<String>,
    /// Polar radar image topic.
    pub radar: Option<RadarTopic>,
}

impl Ros2Topics {
    /// The topics `mmtrack ingest ros2`'s flags choose (the Python keywords
    /// are the same words): `--pose-topic` (`none` for no poses),
    /// `--poses-are-ground-truth`, `--ground-truth-topic`, `--gnss-topic`,
    /// `--radar-topic` with `--radar-range-resolution-m` and the sweep timing.
    ///
    /// # Errors
    /// A radar topic without its range resolution, a resolution that is not
    /// a positive number of metres, or a ground-truth topic that is the pose
    /// topic or comes with `--poses-are-ground-truth`.
    pub fn from_flags(
        pose_topic: &str,
        poses_are_ground_truth: bool,
        ground_truth_topic: Option<String>,
        gnss_topic: Option<String>,
        radar_topic: Option<String>,
        radar_range_resolution_m: Option<f64>,
        timing: SweepTiming,
    ) -> Result<Self, String> {
        let radar = match (radar_topic, radar_range_resolution_m) {
            (Some(topic), Some(r)) => Some(RadarTopic {
                topic,
                range_resolution_m: crate::flags::positive_metres("--radar-range-resolution-m", r)?,
                timing,
            }),
            (Some(topic), None) => {
                return Err(format!(
                    "--radar-topic {topic}: give --radar-range-resolution-m (the images do not carry it; CTS350-X: \
                     0.0438, CIR204-H: 0.0596)"
                ));
            }
            (None, _) => None,
        };
        if let Some(topic) = &ground_truth_topic {
            if topic == pose_topic {
                return Err(format!(
                    "--ground-truth-topic {topic} is also --pose-topic: give the estimate's topic there"
                ));
            }
            if poses_are_ground_truth {
                return Err(format!(
                    "--ground-truth-topic {topic} with --poses-are-ground-truth: one ground truth per recording"
                ));
            }
        }
        Ok(Self {
            pose_topic: (pose_topic != "none").then(|| pose_topic.to_string()),
            pose_stream: if poses_are_ground_truth { PoseStream::GroundTruth } else { PoseStream::Estimate },
            ground_truth_topic,
            gnss_topic,
            radar,
        })
    }

    /// Each chosen topic with its role and the message types that role takes.
    fn roles(&self) -> impl Iterator<Item = (&'static str, &str, &'static [&'static str])> {
        [
            self.pose_topic.as_deref().map(|t| ("pose", t, &POSE_TYPES[..])),
            self.ground_truth_topic.as_deref().map(|t| ("ground-truth", t, &POSE_TYPES[..])),
            self.gnss_topic.as_deref().map(|t| ("GNSS", t, &GNSS_TYPES[..])),
            self.radar.as_ref().map(|r| ("radar", r.topic.as_str(), &RADAR_TYPES[..])),
        ]
        .into_iter()
        .flatten()
    }

    /// Checks that `topic`, whose messages are of type `schema`, suits every
    /// role it was chosen for, e.g. `radar topic /odom has type
    /// nav_msgs/msg/Odometry; expected sensor_msgs/msg/Image`.
    pub fn check_type(&self, topic: &str, schema: &str) -> Result<(), String> {
        match self.roles().find(|(_, t, types)| *t == topic && !types.contains(&schema)) {
            Some((role, _, types)) => {
                Err(format!("{role} topic {topic} has type {schema}; expected {}", types.join(" or ")))
            }
            None => Ok(()),
        }
    }
}

impl Default for Ros2Topics {
    fn default() -> Self {
        Self {
            pose_topic: Some("/odom".into()),
            pose_stream: PoseStream::Estimate,
            ground_truth_topic: None,
            gnss_topic: None,
            radar: None,
        }
    }
}

/// What a bag ingest did.
#[derive(Debug, Clone)]
pub struct Ros2Report {
    /// Poses written from the pose topic.
    pub poses: u64,
    /// Poses written from the ground-truth topic.
    pub ground_truth_poses: u64,
    /// GNSS fixes written.
    pub gnss_fixes: u64,
    /// NavSatFix messages without a fix (skipped).
    pub no_fix: u64,
    /// Radar scans written.
    pub radar_scans: u64,
    /// The recording.
    pub output: WriteSummary,
}

impl Ros2Report {
    /// One line for a terminal: what was written where.
    #[must_use]
    pub fn summary(&self) -> String {
        format!(
            "{}: {} poses, {} ground-truth poses, {} GNSS fixes ({} NavSatFix without a fix skipped), {} radar scans",
            self.output.path.display(),
            self.poses,
            self.ground_truth_poses,
            self.gnss_fixes,
            self.no_fix,
            self.radar_scans
        )
    }
}

/// Writes the chosen topics' messages, checking that each topic's header
/// stamps increase.
struct Sink<'a> {
    topics: &'a Ros2Topics,
    writer: RecordingWriter,
    poses: u64,
    ground_truth_poses: u64,
    gnss_fixes: u64,
    no_fix: u64,
    radar_scans: u64,
    last_ns: [i64; 4],
}

impl Sink<'_> {
    fn increasing(&mut self, slot: usize, t_ns: i64) -> Result<(), String> {
        if t_ns <= self.last_ns[slot] {
            return Err(format!("header.stamp {t_ns} ns does not increase (previous {} ns)", self.last_ns[slot]));
        }
        self.last_ns[slot] = t_ns;
        Ok(())
    }

    /// Handles one message; `Ok(Err(..))` is a bad message (the caller names it).
    fn handle(&mut self, topic: &str, schema: &str, data: &[u8]) -> Result<Result<(), String>, IngestError> {
        let topics = self.topics;
        let pose_role = if topics.pose_topic.as_deref() == Some(topic) {
            Some((0, topics.pose_stream))
        } else if topics.ground_truth_topic.as_deref() == Some(topic) {
            Some((3, PoseStream::GroundTruth))
        } else {
            None
        };
        if let Some((slot, stream)) = pose_role {
            let decoded = match schema {
                "nav_msgs/msg/Odometry" => decode_odometry(data),
                "geometry_msgs/msg/PoseWithCovarianceStamped" => decode_pose_with_covariance_stamped(data),
                other => Err(format!("type {other}; expected {}", POSE_TYPES.join(" or "))),
            };
            let decoded = match decoded.and_then(|d| self.increasing(slot, d.pose.t_ns).map(|()| d)) {
                Ok(d) => d,
                Err(e) => return Ok(Err(e)),
            };
            self.writer.write_pose(stream, &decoded.pose, &decoded.frame_id)?;
            if slot == 0 { self.poses += 1 } else { self.ground_truth_poses += 1 }
        } else if topics.gnss_topic.as_deref() == Some(topic) {
            match decode_nav_sat_fix(data) {
                Ok(Some(fix)) => {
                    if let Err(e) = self.increasing(1, fix.t_ns) {
                        return Ok(Err(e));
                    }
                    self.writer.write_gnss_fix(&fix)?;
                    self.gnss_fixes += 1;
                }
                Ok(None) => self.no_fix += 1,
                Err(e) => return Ok(Err(e)),
            }
        } else if let Some(radar) = topics.radar.as_ref().filter(|r| r.topic == topic) {
            let scan = crate::ros2_image::decode_image(data)
                .and_then(|image| crate::ros2_image::image_to_scan(&image, &radar.timing, radar.range_resolution_m))
                .and_then(|scan| self.increasing(2, scan.header.t_ns).map(|()| scan));
            match scan {
                Ok(scan) => self.writer.write_radar_scan(&scan)?,
                Err(e) => return Ok(Err(e)),
            }
            self.radar_scans += 1;
        }
        Ok(Ok(()))
    }
}

/// `header.stamp` of the first message on a chosen topic (every type we take
/// starts with a `std_msgs/Header`), read ahead of the ingest so the
/// recording's time base is known before it is written; `None` when the bag
/// has no such message or it does not decode (the ingest then reports it).
fn first_stamp_ns(bag: &Path, wanted: &[&str]) -> Result<Option<i64>, IngestError> {
    let mut reader = RawReader::open(bag)?;
    while let Some(message) = reader.next_message()? {
        if wanted.contains(&message.channel.topic.as_str()) {
            return Ok(Cdr::new(&message.data).and_then(|mut cdr| cdr.stamp_ns("header.stamp")).ok());
        }
    }
    Ok(None)
}

fn metadata(bag: &Path, sequence_id: String, topics: &Ros2Topics, first_stamp_ns: Option<i64>) -> RecordingMetadata {
    let time_base = first_stamp_ns.map_or(TimeBase::UnixEpoch, |t| TimeBase::unix_or(t, TimeBase::SimTime));
    let time_note = match (first_stamp_ns, time_base) {
        (Some(t), TimeBase::SimTime) => format!(
            "header.stamp as in the bag; the first is {t} ns, before 2000-01-01, so the bag was stamped with a \
             simulator's clock (use_sim_time), not UNIX time"
        ),
        (Some(t), _) => format!("header.stamp as in the bag (UNIX time; the first is {t} ns)"),
        (None, _) => "header.stamp as in the bag (taken as UNIX time: no stamp was read ahead)".to_string(),
    };
    let mut extra = BTreeMap::from([
        ("time.note".to_string(), time_note),
        ("ros2.pose_topic".to_string(), topics.pose_topic.clone().unwrap_or_default()),
        ("ros2.ground_truth_topic".to_string(), topics.ground_truth_topic.clone().unwrap_or_default()),
        ("ros2.gnss_topic".to_string(), topics.gnss_topic.clone().unwrap_or_default()),
    ]);
    if let Some(radar) = &topics.radar {
        extra.insert("ros2.radar_topic".into(), radar.topic.clone());
        extra.insert("radar.format".into(), "ros2 sensor_msgs/Image mono8 (rows = azimuths)".into());
        extra.insert("radar.range_resolution_m".into(), radar.range_resolution_m.to_string());
        extra.insert(
            "radar.azimuth_times".into(),
            format!(
                "spread evenly over {} ns, header.stamp at the sweep's {}",
                radar.timing.period_ns,
                radar.timing.stamp_at.name()
            ),
        );
        extra.insert("radar.scan_period_ns".into(), radar.timing.period_ns.to_string());
        extra.insert("radar.stamp_at".into(), radar.timing.stamp_at.name().into());
    }
    RecordingMetadata { sequence_id, source: format!("ros2:{}", mmtrack_io::paths::canonical(bag)), time_base, extra }
}

/// Ingests the chosen topics of a ROS 2 bag into a new recording. Messages
/// must come in increasing header time per topic; a chosen topic missing
/// from the bag, or of a message type its role does not take
/// ([`Ros2Topics::check_type`]), is an error. A bad message is named by its
/// topic, its 0-based index among that topic's messages in file order and
/// its log time.
pub fn ingest_ros2(
    bag: &Path,
    out: &Path,
    topics: &Ros2Topics,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<Ros2Report, IngestError> {
    let sequence_id = crate::scan_folder::sequence_id_of_file(bag, "bag")?;
    let bag_bytes = std::fs::metadata(bag).map(|m| m.len()).unwrap_or(0);
    let wanted: Vec<&str> =
        [topics.pose_topic.as_deref(), topics.ground_truth_topic.as_deref(), topics.gnss_topic.as_deref()]
            .into_iter()
            .flatten()
            .chain(topics.radar.as_ref().map(|r| r.topic.as_str()))
            .collect();
    let first_stamp = first_stamp_ns(bag, &wanted)?;
    let mut reader = RawReader::open(bag)?;
    let writer = RecordingWriter::create(out, &metadata(bag, sequence_id, topics, first_stamp), recording)?;
    let mut sink = Sink {
        topics,
        writer,
        poses: 0,
        ground_truth_poses: 0,
        gnss_fixes: 0,
        no_fix: 0,
        radar_scans: 0,
        last_ns: [i64::MIN; 4],
    };
    // Messages seen per topic: a message is named by its 0-based index among
    // its topic's messages in file order, and its log time. Not by the MCAP
    // sequence number: rosbag2 writers leave it 0.
    let mut per_topic: BTreeMap<String, u64> = BTreeMap::new();
    while let Some(message) = reader.next_message()? {
        let channel = &message.channel;
        let seen = per_topic.entry(channel.topic.clone()).or_insert(0);
        let index = *seen;
        *seen += 1;
        let bad = |detail: String| IngestError::BadRecord {
            path: bag.to_path_buf(),
            record: format!("message {index} on {} (0-based, log time {} ns)", channel.topic, message.log_time_ns),
            field: channel.schema_name.clone(),
            detail,
        };
        if wanted.contains(&channel.topic.as_str()) {
            topics
                .check_type(&channel.topic, &channel.schema_name)
                .map_err(|detail| IngestError::BadLayout { path: bag.to_path_buf(), detail })?;
            if channel.message_encoding != "cdr" {
                return Err(bad(format!("message encoding '{}', expected cdr", channel.message_encoding)));
            }
        }
        sink.handle(&channel.topic, &channel.schema_name, &message.data)?.map_err(bad)?;
        progress(reader.bytes_read(), bag_bytes);
    }
    if let Some(topic) = wanted.iter().find(|t| !per_topic.contains_key(**t)) {
        return Err(IngestError::BadLayout {
            path: bag.to_path_buf(),
            detail: format!(
                "no topic {topic} in the bag (topics: {})",
                per_topic.keys().cloned().collect::<Vec<_>>().join(", ")
            ),
        });
    }
    let Sink { poses, ground_truth_poses, gnss_fixes, no_fix, radar_scans, writer, .. } = sink;
    Ok(Ros2Report { poses, ground_truth_poses, gnss_fixes, no_fix, radar_scans, output: writer.finish()? })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A CDR writer for test messages, little-endian unless made big-endian.
    struct Writer(Vec<u8>, bool);

    impl Writer {
        fn new() -> Self {
            Self(vec![0, 1, 0, 0], false)
        }
        fn big_endian() -> Self {
            Self(vec![0, 0, 0, 0], true)
        }
        fn align(&mut self, n: usize) {
            while !(self.0.len() - 4).is_multiple_of(n) {
                self.0.push(0);
            }
        }
        fn u32(&mut self, v: u32) -> &mut Self {
            self.align(4);
            self.0.extend_from_slice(&if self.1 { v.to_be_bytes() } else { v.to_le_bytes() });
            self
        }
        fn f64(&mut self, v: f64) -> &mut Self {
            self.align(8);
            self.0.extend_from_slice(&if self.1 { v.to_be_bytes() } else { v.to_le_bytes() });
            self
        }
        fn string(&mut self, s: &str) -> &mut Self {
            self.u32(s.len() as u32 + 1);
            self.0.extend_from_slice(s.as_bytes());
            self.0.push(0);
            self
        }
    }

    fn odometry(yaw: f64) -> Vec<u8> {
        odometry_in(Writer::new(), yaw)
    }

    fn odometry_in(mut w: Writer, yaw: f64) -> Vec<u8> {
        w.u32(12).u32(500).string("odom").string("base_link");
        w.f64(1.5).f64(-2.0).f64(0.0);
        w.f64(0.0).f64(0.0).f64((yaw / 2.0).sin()).f64((yaw / 2.0).cos());
        for _ in 0..36 {
            w.f64(0.0);
        }
        w.0
    }

    #[test]
    fn odometry_decodes_with_alignment_and_yaw() {
        let decoded = decode_odometry(&odometry(0.75)).unwrap();
        assert_eq!(decoded.pose.t_ns, 12_000_000_500);
        assert_eq!((decoded.frame_id.as_str(), decoded.child_frame_id.as_str()), ("odom", "base_link"));
        let p = decoded.pose.parent_from_child;
        assert_eq!((p.x_m, p.y_m), (1.5, -2.0));
        assert!((p.yaw_rad - 0.75).abs() < 1e-12);
    }

    fn nav_sat_fix(altitude: f64) -> Vec<u8> {
        nav_sat_fix_at(37.4, altitude)
    }

    fn nav_sat_fix_at(latitude: f64, altitude: f64) -> Vec<u8> {
        let mut w = Writer::new();
        w.u32(12).u32(500).string("gnss");
        // status.status = 0 (fix) at an odd offset, then status.service = 1
        // (GPS) on the next even one.
        assert_eq!(w.0.len() % 2, 1);
        w.0.push(0);
        w.0.extend_from_slice(&1u16.to_le_bytes());
        w.f64(latitude).f64(-122.1).f64(altitude);
        for _ in 0..9 {
            w.f64(0.0);
        }
        w.0.push(0); // covariance type unknown
        w.0
    }

    #[test]
    fn big_endian_payloads_decode_and_a_wrong_header_is_named() {
        let little = decode_odometry(&odometry(0.75)).unwrap();
        let big = odometry_in(Writer::big_endian(), 0.75);
        assert_eq!(decode_odometry(&big).unwrap(), little);
        // A big-endian payload under a little-endian header: the stamp's
        // nanoseconds 500 read as 4093706240, or with nanoseconds 0, the
        // string length 5 as 83886080 (was "field needs 83886092").
        let mut lying = big.clone();
        lying[1] = 0x01;
        let err = decode_odometry(&lying).unwrap_err();
        assert!(
            err.starts_with("header.stamp: nanosec 4093706240 is not below one second, but 500 read big-endian"),
            "{err}"
        );
        lying[8..12].copy_from_slice(&[0; 4]);
        let err = decode_odometry(&lying).unwrap_err();
        assert!(
            err.starts_with("header.frame_id: length 83886080 is more than the")
                && err.contains("but 5 read big-endian: the encapsulation header says little-endian and the payload looks big-endian"),
            "{err}"
        );
        // Parameter lists and XCDR2 are refused by name.
        for (id, name) in [(0x03, "parameter list (PL_CDR)"), (0x07, "XCDR2")] {
            let mut other = odometry(0.75);
            other[1] = id;
            let err = decode_odometry(&other).unwrap_err();
            assert!(err.contains(name) && err.contains("not supported"), "{err}");
        }
    }

    #[test]
    fn nav_sat_fix_nan_altitude_is_no_altitude() {
        let fix = decode_nav_sat_fix(&nav_sat_fix(12.5)).unwrap().unwrap();
        assert_eq!(
            (fix.t_ns, fix.latitude_deg, fix.altitude_m, fix.horizontal_sigma_m),
            (12_000_000_500, 37.4, Some(12.5), None)
        );
        assert_eq!(decode_nav_sat_fix(&nav_sat_fix(f64::NAN)).unwrap().unwrap().altitude_m, None);
        let err = decode_nav_sat_fix(&nav_sat_fix(f64::INFINITY)).unwrap_err();
        assert!(err.contains("altitude: inf"), "{err}");
    }

    /// Before: a NavSatFix latitude of 200 and an altitude of 1e300 were
    /// ingested as fixes.
    #[test]
    fn nav_sat_fix_latitude_and_altitude_out_of_range_are_refused() {
        let err = decode_nav_sat_fix(&nav_sat_fix_at(200.0, 12.5)).unwrap_err();
        assert_eq!(err, "latitude: 200 is not a latitude within [-90, 90] deg");
        let err = decode_nav_sat_fix(&nav_sat_fix(1e300)).unwrap_err();
        assert!(err.starts_with("altitude: 1e300 is not an altitude within"), "{err}");
        let mut w = Writer::new();
        w.u32(12).u32(500).string("odom").string("base_link");
        w.f64(1e300).f64(-2.0).f64(0.0);
        w.f64(0.0).f64(0.0).f64(0.0).f64(1.0);
        let err = decode_odometry(&w.0).unwrap_err();
        assert!(err.starts_with("pose.position.x: 1e300 is not a coordinate"), "{err}");
    }

    #[test]
    fn a_zero_quaternion_is_refused() {
        let mut w = Writer::new();
        w.u32(12).u32(500).string("odom").string("base_link");
        w.f64(1.5).f64(-2.0).f64(0.0);
        w.f64(0.0).f64(0.0).f64(0.0).f64(0.0);
        let err = decode_odometry(&w.0).unwrap_err();
        assert!(err.contains("pose.orientation") && err.contains("norm 0"), "{err}");
    }

    #[test]
    fn truncated_message_names_the_field() {
        let data = odometry(0.1);
        let err = decode_odometry(&data[..60]).unwrap_err();
        assert!(err.contains("orientation") || err.contains("pose.position"), "{err}");
        assert!(decode_odometry(&[0, 1]).unwrap_err().contains("encapsulation"));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]
        #[test]
        fn decoders_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400), cut in 0usize..400) {
            let _ = decode_odometry(&bytes);
            let _ = decode_nav_sat_fix(&bytes);
            let mut valid = odometry(0.3);
            valid.truncate(cut.min(valid.len()));
            let _ = decode_odometry(&valid);
            let _ = decode_pose_with_covariance_stamped(&valid);
        }
    }
}
