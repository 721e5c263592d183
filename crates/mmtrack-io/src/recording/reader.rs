use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use foxglove::schemas::{CompressedImage, RawImage};
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mmtrack_core::slam::{PathOrigin, SlamEpoch, SourceType, UeState};
use mmtrack_core::{
    AzimuthSample, BeamSweep, CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcTruth, PolarScan, PolarScanHeader,
    Se2, StampedPose,
};
use prost::Message;

use super::METADATA_NAME;
use super::channels::{
    BEAM_SWEEP_TOPIC, CIR_TOPIC, GNSS_ARRAY_TOPIC, GNSS_TOPIC, MPC_TRUTH_TOPIC, PoseStream, RADAR_IMAGE_TOPIC,
    RADAR_META_TOPIC,
};
use crate::error::{IoError, Result, os_err};
use crate::proto;

mod slam;

/// A channel of an MCAP file.
#[derive(Debug)]
pub struct ChannelInfo {
    /// Topic.
    pub topic: String,
    /// Schema name (e.g. `nav_msgs/msg/Odometry`), empty without a schema.
    pub schema_name: String,
    /// Message encoding (e.g. `cdr`, `protobuf`).
    pub message_encoding: String,
    /// Schema encoding (e.g. `ros2msg`, `protobuf`), empty without a schema.
    pub schema_encoding: String,
    /// Schema data (e.g. a protobuf `FileDescriptorSet`).
    pub schema_data: Arc<[u8]>,
    /// Channel metadata.
    pub metadata: BTreeMap<String, String>,
}

/// A raw message: its channel, sequence, time and payload.
#[derive(Debug)]
pub struct RawMessage {
    /// The channel.
    pub channel: Arc<ChannelInfo>,
    /// MCAP sequence number.
    pub sequence: u32,
    /// Log time, nanoseconds.
    pub log_time_ns: u64,
    /// Owned payload; `Bytes` so that prost decodes `bytes` fields as
    /// zero-copy slices of it.
    pub data: bytes::Bytes,
}

/// The longest MCAP record, and decompressed chunk, a reader accepts: far
/// above what we (a radar scan is 1.5 MB, a chunk 4 MiB) or a ROS 2 bag
/// write, far below what a corrupt length field can ask for, so a damaged
/// file is an error instead of an allocation of its garbage length.
pub const RECORD_LENGTH_LIMIT_BYTES: usize = 256 << 20;

/// Streams the messages of any MCAP file (ours, ROS 2 bags, ...) in file
/// order with bounded memory, without decoding them. Every chunk's CRC is
/// checked before any of its messages is returned, and the data section's
/// at its end, so a damaged file is refused rather than read as other
/// values.
pub struct RawReader {
    path: PathBuf,
    file: File,
    bytes_read: u64,
    messages_read: u64,
    reader: LinearReader,
    schemas: HashMap<u16, (String, String, Arc<[u8]>)>,
    channels: HashMap<u16, Arc<ChannelInfo>>,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
}

impl RawReader {
    /// Opens a file.
    pub fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(os_err(path))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            bytes_read: 0,
            messages_read: 0,
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_prevalidate_chunk_crcs(true)
                    .with_validate_data_section_crc(true)
                    .with_record_length_limit(RECORD_LENGTH_LIMIT_BYTES),
            ),
            schemas: HashMap::new(),
            channels: HashMap::new(),
            metadata: BTreeMap::new(),
        })
    }

    fn corrupt(&self, detail: impl std::fmt::Display) -> IoError {
        IoError::CorruptRecording { path: self.path.clone(), detail: detail.to_string() }
    }

    /// The file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Metadata records read so far, by name (writers put them first).
    #[must_use]
    pub fn metadata(&self) -> &BTreeMap<String, BTreeMap<String, String>> {
        &self.metadata
    }

    /// Bytes of the file read so far (for progress).
    #[must_use]
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read
    }

    /// The next message, or `None` at a clean end of file.
    pub fn next_message(&mut self) -> Result<Option<RawMessage>> {
        while let Some(event) = self.reader.next_event() {
            match event.map_err(|e| corrupt_at(&self.path, &e, self.messages_read, self.bytes_read))? {
                LinearReadEvent::ReadRequest(need) => {
                    let read = self.file.read(self.reader.insert(need)).map_err(os_err(&self.path))?;
                    self.reader.notify_read(read);
                    self.bytes_read += read as u64;
                }
                LinearReadEvent::Record { opcode, data } => {
                    let record = mcap::parse_record(opcode, data)
                        .map_err(|e| IoError::CorruptRecording { path: self.path.clone(), detail: e.to_string() })?;
                    match record {
                        Record::Schema { header, data } => {
                            self.schemas.insert(header.id, (header.name, header.encoding, Arc::from(data.as_ref())));
                        }
                        Record::Channel(c) => {
                            let (schema_name, schema_encoding, schema_data) = self
                                .schemas
                                .get(&c.schema_id)
                                .cloned()
                                .unwrap_or_else(|| (String::new(), String::new(), Arc::from(&[][..])));
                            self.channels.insert(
                                c.id,
                                Arc::new(ChannelInfo {
                                    topic: c.topic,
                                    schema_name,
                                    message_encoding: c.message_encoding,
                                    schema_encoding,
                                    schema_data,
                                    metadata: c.metadata,
                                }),
                            );
                        }
                        Record::Metadata(m) => {
                            self.metadata.insert(m.name, m.metadata);
                        }
                        Record::Message { header, data } => {
                            let Some(channel) = self.channels.get(&header.channel_id).cloned() else {
                                return Err(self.corrupt(format!(
                                    "message {} refers to unknown channel {}",
                                    header.sequence, header.channel_id
                                )));
                            };
                            self.messages_read += 1;
                            return Ok(Some(RawMessage {
                                channel,
                                sequence: header.sequence,
                                log_time_ns: header.log_time,
                                data: bytes::Bytes::from(data.into_owned()),
                            }));
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(None)
    }
}

/// A reader error, with where in the file it was met.
fn corrupt_at(path: &Path, error: &mcap::McapError, messages_read: u64, bytes_read: u64) -> IoError {
    let limit = match error {
        mcap::McapError::RecordTooLarge { .. } | mcap::McapError::ChunkTooLarge(_) => {
            format!(" (the limit is {} MiB)", RECORD_LENGTH_LIMIT_BYTES >> 20)
        }
        _ => String::new(),
    };
    IoError::CorruptRecording {
        path: path.to_path_buf(),
        detail: format!("{error}{limit}, after message {messages_read} (within the first {bytes_read} bytes)"),
    }
}

/// One decoded item of a recording, in file order.
#[derive(Debug, Clone, PartialEq)]
pub enum RecordingEvent {
    /// A complete radar scan (image and metadata joined).
    RadarScan(PolarScan),
    /// A trajectory pose.
    Pose {
        /// Which trajectory.
        stream: PoseStream,
        /// The pose.
        pose: StampedPose,
    },
    /// A GNSS fix of the vehicle (`/gnss/fix`).
    Gnss(GnssFix),
    /// A GNSS fix of the beam-sweeping array, e.g. a roadside unit
    /// (`/gnss/array`).
    ArrayGnss(GnssFix),
    /// A beam sweep of a measured codebook (`/beam/sweeps`).
    BeamSweep {
        /// The sweep (unmeasured beams hold power 0).
        sweep: BeamSweep,
        /// The codebook's identifier, when the recording names one.
        codebook: Option<String>,
    },
    /// A channel impulse response.
    Cir(CirSnapshot),
    /// A true multipath component of a simulated CIR snapshot.
    MpcTruth(MpcTruth),
    /// The path measurements of a 5G mmWave SLAM epoch (`/slam/paths`).
    SlamPaths(SlamEpoch),
    /// The simulator's truth of a SLAM epoch (`/slam/ue_truth`).
    SlamUeTruth {
        /// Epoch time, nanoseconds.
        t_ns: i64,
        /// The true UE state.
        ue: UeState,
        /// The source of each path of the epoch's measurements, same order.
        origins: Vec<PathOrigin>,
    },
    /// A source of the SLAM paths (`/slam/sources`).
    SlamSource {
        /// Time from which it is valid, nanoseconds.
        t_ns: i64,
        /// Base station, virtual anchor or scattering point.
        kind: SourceType,
        /// Index among the sources of its kind.
        index: usize,
        /// Position, metres.
        position_m: [f64; 3],
    },
}

/// Reads a canonical recording as a stream of [`RecordingEvent`]s, holding at
/// most one scan in memory. Display channels and unknown topics are skipped.
pub struct RecordingReader {
    raw: RawReader,
    pending_meta: Option<(u32, proto::RadarScanMeta)>,
}

impl RecordingReader {
    /// Opens a recording.
    pub fn open(path: &Path) -> Result<Self> {
        Ok(Self { raw: RawReader::open(path)?, pending_meta: None })
    }

    /// The recording metadata (`mmtrack.recording`); complete once the first
    /// event has been read, since writers put it at the start of the file.
    #[must_use]
    pub fn metadata(&self) -> Option<&BTreeMap<String, String>> {
        self.raw.metadata.get(METADATA_NAME)
    }

    /// Bytes of the file read so far (for progress bars).
    #[must_use]
    pub fn bytes_read(&self) -> u64 {
        self.raw.bytes_read()
    }

    fn bad(&self, m: &RawMessage, detail: impl std::fmt::Display) -> IoError {
        IoError::BadMessage {
            path: self.raw.path.clone(),
            topic: m.channel.topic.clone(),
            sequence: m.sequence,
            detail: detail.to_string(),
        }
    }

    fn decode<M: Message + Default>(&self, m: &RawMessage) -> Result<M> {
        if m.channel.message_encoding != "protobuf" {
            return Err(self.bad(m, format!("message encoding '{}', expected protobuf", m.channel.message_encoding)));
        }
        M::decode(m.data.clone()).map_err(|e| self.bad(m, format!("cannot decode {}: {e}", m.channel.schema_name)))
    }

    /// The next item with radar scans left undecoded: [`EncodedScan::decode`]
    /// (the PNG inflate, most of the reading time) can then run on other
    /// threads while this one reads on. Items come in file order.
    pub fn next_item(&mut self) -> Option<Result<RecordingItem>> {
        self.next_item_inner().transpose()
    }

    fn next_item_inner(&mut self) -> Result<Option<RecordingItem>> {
        while let Some(m) = self.raw.next_message()? {
            let topic = m.channel.topic.as_str();
            if topic == RADAR_META_TOPIC {
                let meta: proto::RadarScanMeta = self.decode(&m)?;
                // A writer puts each scan's image right after its metadata.
                if let Some((sequence, previous)) = self.pending_meta.replace((m.sequence, meta)) {
                    return Err(self.scan_without_image(
                        sequence,
                        previous.t_ns,
                        "the next scan's metadata came first",
                    ));
                }
            } else if topic == RADAR_IMAGE_TOPIC {
                return self.join_scan(m).map(|s| Some(RecordingItem::Scan(s)));
            } else if let Some(stream) = PoseStream::from_topic(topic) {
                let p: proto::Pose2D = self.decode(&m)?;
                let pose = StampedPose { t_ns: p.t_ns, parent_from_child: Se2::new(p.x_m, p.y_m, p.yaw_rad) };
                return Ok(Some(RecordingItem::Event(RecordingEvent::Pose { stream, pose })));
            } else if topic == GNSS_TOPIC {
                return Ok(Some(RecordingItem::Event(RecordingEvent::Gnss(self.decode_fix(&m)?))));
            } else if topic == GNSS_ARRAY_TOPIC {
                return Ok(Some(RecordingItem::Event(RecordingEvent::ArrayGnss(self.decode_fix(&m)?))));
            } else if topic == BEAM_SWEEP_TOPIC {
                let b: proto::BeamSweep = self.decode(&m)?;
                let beams = b.beam_count as usize;
                if b.power_linear.len() != beams || b.measured.len() != beams {
                    return Err(self.bad(
                        &m,
                        format!(
                            "beam_count {beams} but {} power_linear values and {} measured flags",
                            b.power_linear.len(),
                            b.measured.len()
                        ),
                    ));
                }
                let sweep = BeamSweep::new(b.t_ns, b.power_linear, b.measured).map_err(|e| self.bad(&m, e))?;
                return Ok(Some(RecordingItem::Event(RecordingEvent::BeamSweep { sweep, codebook: b.codebook })));
            } else if topic == CIR_TOPIC {
                let c: proto::CirSnapshot = self.decode(&m)?;
                if c.taps_re.len() != c.taps_im.len() {
                    return Err(self.bad(
                        &m,
                        format!("taps_re has {} values but taps_im has {}", c.taps_re.len(), c.taps_im.len()),
                    ));
                }
                let taps = c.taps_re.iter().zip(&c.taps_im).map(|(&re, &im)| Complex64::new(re, im)).collect();
                return Ok(Some(RecordingItem::Event(RecordingEvent::Cir(CirSnapshot {
                    t_ns: c.t_ns,
                    set_index: c.set_index,
                    snapshot_index: c.snapshot_index,
                    tx_antenna: c.tx_antenna,
                    rx_antenna: c.rx_antenna,
                    carrier_hz: c.carrier_hz,
                    tap_spacing_s: c.tap_spacing_s,
                    delay_offset_s: c.delay_offset_s,
                    taps,
                    first_path_hint_s: c.first_path_hint_s,
                }))));
            } else if let Some(event) = self.decode_slam(&m)? {
                return Ok(Some(RecordingItem::Event(event)));
            } else if topic == MPC_TRUTH_TOPIC {
                let t: proto::MpcTruth = self.decode(&m)?;
                return Ok(Some(RecordingItem::Event(RecordingEvent::MpcTruth(MpcTruth {
                    t_ns: t.t_ns,
                    set_index: t.set_index,
                    snapshot_index: t.snapshot_index,
                    path_id: t.path_id,
                    delay_s: t.delay_s,
                    amplitude: Complex64::new(t.amplitude_re, t.amplitude_im),
                    doppler_hz: t.doppler_hz,
                }))));
            }
        }
        if let Some((sequence, meta)) = self.pending_meta.take() {
            return Err(self.scan_without_image(sequence, meta.t_ns, "the file ends first"));
        }
        Ok(None)
    }

    /// A scan's metadata whose image never came: the error names the
    /// metadata message and its scan time.
    fn scan_without_image(&self, sequence: u32, t_ns: i64, why: &str) -> IoError {
        IoError::BadMessage {
            path: self.raw.path.clone(),
            topic: RADAR_META_TOPIC.to_string(),
            sequence,
            detail: format!("the radar scan at t_ns {t_ns} has no {RADAR_IMAGE_TOPIC} message: {why}"),
        }
    }

    fn decode_fix(&self, m: &RawMessage) -> Result<GnssFix> {
        let f: proto::GnssFix = self.decode(m)?;
        let quality = GnssFixQuality::from_code(f.quality)
            .ok_or_else(|| self.bad(m, format!("unknown fix quality code {}", f.quality)))?;
        Ok(GnssFix {
            t_ns: f.t_ns,
            latitude_deg: f.latitude_deg,
            longitude_deg: f.longitude_deg,
            altitude_m: f.altitude_m,
            horizontal_sigma_m: f.horizontal_sigma_m,
            num_satellites: f.num_satellites,
            quality,
        })
    }

    /// Joins a radar image with the metadata of the same sequence number.
    fn join_scan(&mut self, m: RawMessage) -> Result<EncodedScan> {
        match self.pending_meta.take() {
            Some((sequence, meta)) if sequence == m.sequence => {
                Ok(EncodedScan { path: self.raw.path.clone(), message: m, meta })
            }
            _ => {
                Err(self.bad(&m, format!("radar image without {RADAR_META_TOPIC} message of the same sequence number")))
            }
        }
    }
}

/// An item of [`RecordingReader::next_item`].
#[derive(Debug)]
pub enum RecordingItem {
    /// Anything but a radar scan, decoded.
    Event(RecordingEvent),
    /// A radar scan, still encoded.
    Scan(EncodedScan),
}

/// A radar scan as stored: its metadata message and its (PNG or raw) image.
#[derive(Debug)]
pub struct EncodedScan {
    path: PathBuf,
    message: RawMessage,
    meta: proto::RadarScanMeta,
}

impl EncodedScan {
    /// Scan time (first azimuth), nanoseconds.
    #[must_use]
    pub fn t_ns(&self) -> i64 {
        self.meta.t_ns
    }

    fn bad(&self, detail: impl std::fmt::Display) -> IoError {
        IoError::BadMessage {
            path: self.path.clone(),
            topic: self.message.channel.topic.clone(),
            sequence: self.message.sequence,
            detail: detail.to_string(),
        }
    }

    fn decode_message<M: Message + Default>(&self) -> Result<M> {
        let m = &self.message;
        if m.channel.message_encoding != "protobuf" {
            return Err(self.bad(format!("message encoding '{}', expected protobuf", m.channel.message_encoding)));
        }
        M::decode(m.data.clone()).map_err(|e| self.bad(format!("cannot decode {}: {e}", m.channel.schema_name)))
    }

    /// Decodes the image (inflating a PNG) and checks it against the metadata.
    pub fn decode(self) -> Result<PolarScan> {
        let meta = &self.meta;
        let n = meta.azimuth_t_ns.len();
        if meta.azimuth_rad.len() != n || meta.valid.len() != n {
            return Err(self.bad("azimuth_t_ns, azimuth_rad and valid differ in length"));
        }
        let bins = meta.bins_per_azimuth as usize;
        let offset = meta.power_column_offset as usize;
        let (width, height, pixels) = match self.message.channel.schema_name.as_str() {
            "foxglove.RawImage" => {
                let image: RawImage = self.decode_message()?;
                if image.encoding != "mono8" || image.step != image.width {
                    return Err(self.bad(format!(
                        "raw image encoding '{}' step {}, expected mono8 packed",
                        image.encoding, image.step
                    )));
                }
                (image.width as usize, image.height as usize, image.data.to_vec())
            }
            "foxglove.CompressedImage" => {
                let image: CompressedImage = self.decode_message()?;
                if image.format != "png" {
                    return Err(self.bad(format!("compressed image format '{}', expected png", image.format)));
                }
                crate::png_gray::decode_gray8(&image.data).map_err(|e| self.bad(e))?
            }
            other => return Err(self.bad(format!("schema {other} is not an image schema"))),
        };
        if height != n || width != offset + bins {
            return Err(self
                .bad(format!("image is {width} x {height}, metadata says {n} azimuths of {offset} + {bins} columns")));
        }
        let power = if offset == 0 {
            pixels
        } else {
            pixels.chunks_exact(width).flat_map(|row| &row[offset..]).copied().collect()
        };
        let azimuths = (0..n)
            .map(|i| AzimuthSample {
                t_ns: meta.azimuth_t_ns[i],
                azimuth_rad: meta.azimuth_rad[i],
                valid: meta.valid[i],
            })
            .collect();
        let header = PolarScanHeader {
            t_ns: meta.t_ns,
            range_resolution_m: meta.range_resolution_m,
            range_offset_m: meta.range_offset_m,
            bins_per_azimuth: bins,
            azimuths,
        };
        PolarScan::new(header, power).map_err(|e| self.bad(e))
    }
}

impl Iterator for RecordingReader {
    type Item = Result<RecordingEvent>;

    fn next(&mut self) -> Option<Self::Item> {
        Some(self.next_item()?.and_then(|item| match item {
            RecordingItem::Event(event) => Ok(event),
            RecordingItem::Scan(scan) => scan.decode().map(RecordingEvent::RadarScan),
        }))
    }
}

/// Per-topic statistics of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSummary {
    /// Topic.
    pub topic: String,
    /// MCAP schema name.
    pub schema_name: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Number of messages.
    pub message_count: u64,
    /// Earliest log time, nanoseconds.
    pub start_ns: u64,
    /// Latest log time, nanoseconds.
    pub end_ns: u64,
}

/// What `mmtrack inspect` reports about a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingSummary {
    /// The file.
    pub path: PathBuf,
    /// Channels sorted by topic.
    pub channels: Vec<ChannelSummary>,
    /// Metadata records by name.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
}

/// Reads a whole recording (any MCAP file, including ROS 2 bags) and
/// summarises its channels. Fails on a truncated or corrupted file.
pub fn inspect_recording(path: &Path) -> Result<RecordingSummary> {
    inspect_recording_with_progress(path, &mut |_, _| {})
}

/// [`inspect_recording`], reporting `(bytes read, file size)` as it goes.
pub fn inspect_recording_with_progress(path: &Path, progress: &mut dyn FnMut(u64, u64)) -> Result<RecordingSummary> {
    let mut raw = RawReader::open(path)?;
    let total = raw.file.metadata().map(|m| m.len()).unwrap_or(0);
    let mut by_topic: BTreeMap<(String, String), ChannelSummary> = BTreeMap::new();
    while let Some(m) = raw.next_message()? {
        let key = (m.channel.topic.clone(), m.channel.schema_name.clone());
        let entry = by_topic.entry(key).or_insert_with(|| ChannelSummary {
            topic: m.channel.topic.clone(),
            schema_name: m.channel.schema_name.clone(),
            message_encoding: m.channel.message_encoding.clone(),
            message_count: 0,
            start_ns: m.log_time_ns,
            end_ns: m.log_time_ns,
        });
        entry.message_count += 1;
        entry.start_ns = entry.start_ns.min(m.log_time_ns);
        entry.end_ns = entry.end_ns.max(m.log_time_ns);
        progress(raw.bytes_read, total);
    }
    Ok(RecordingSummary {
        path: path.to_path_buf(),
        channels: by_topic.into_values().collect(),
        metadata: raw.metadata,
    })
}
