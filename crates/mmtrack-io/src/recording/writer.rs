use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use foxglove::Encode;
use foxglove::schemas::{CompressedImage, FrameTransforms, LocationFix, Pose, PoseInFrame, RawImage, Vector3};
use mmtrack_core::{BeamSweep, CirSnapshot, GnssFix, MpcTruth, PolarScan, PolarScanHeader, Se2, StampedPose};
use prost::Message;

use super::METADATA_NAME;
use super::cartesian::{CartesianGrid, CartesianResampler};
use super::channels::{
    BEAM_SWEEP_TOPIC, CIR_TOPIC, CIR_VIZ_TOPIC, GNSS_ARRAY_TOPIC, GNSS_ARRAY_VIZ_TOPIC, GNSS_TOPIC, GNSS_VIZ_TOPIC,
    MPC_TRUTH_TOPIC, PoseStream, RADAR_CARTESIAN_TOPIC, RADAR_IMAGE_TOPIC, RADAR_META_TOPIC, TF_STATIC_TOPIC, TF_TOPIC,
};
use super::cir_view::{CirWaterfall, WaterfallImage};
use super::metadata::RecordingMetadata;
use super::reader::RawMessage;
use super::tf::{GNSS_FRAME, RADAR_FRAME, VEHICLE_FRAME, frame_transform, timestamp, vehicle_frame, yaw_quaternion};
use crate::atomic::{AtomicFile, Durability, Overwrite};
use crate::error::{IoError, Result};
use crate::proto::{self, SpecMessage};

mod mpc_paths;
mod slam;

/// Chunk compression of a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// Uncompressed chunks: fastest; radar PNGs carried unchanged are already compressed.
    None,
    /// zstd at the given level (1 is fast; 3 is zstd's default).
    Zstd {
        /// zstd level, 1..=19.
        level: u32,
    },
    /// lz4 frame compression.
    Lz4,
}

/// How a recording is written.
#[derive(Debug, Clone)]
pub struct RecordingOptions {
    /// Chunk compression.
    pub compression: Compression,
    /// Target uncompressed chunk size, bytes.
    pub chunk_size_bytes: u64,
    /// What to do if the file exists.
    pub overwrite: Overwrite,
    /// Also write Foxglove display channels (`/viz/...`).
    pub foxglove_views: bool,
    /// Flush to disk before the final rename.
    pub durability: Durability,
    /// Also write each radar scan resampled onto this Cartesian grid
    /// (`/radar/cartesian`, for Foxglove's image panel; see
    /// [`super::cartesian`]). Off by default here, since it costs a resampling
    /// per scan; `mmtrack ingest` and `mmtrack simulate` turn it on unless
    /// `--no-radar-cartesian`.
    pub radar_cartesian: Option<CartesianGrid>,
}

/// The output flags of every ingest and simulate call, as the front ends
/// name them (`--force`, `--compression`, ...; the Python keywords are the
/// same words), turned into [`RecordingOptions`] in one place.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingFlags {
    /// Replace an existing output (atomically, once the new one is complete).
    pub force: bool,
    /// `none`, `zstd` or `lz4`.
    pub compression: String,
    /// zstd level, 1 (fast) ..= 19 (small).
    pub zstd_level: u32,
    /// Omit the Foxglove display channels (`/viz/...`, `/tf`, `/radar/cartesian`).
    pub no_foxglove_views: bool,
    /// Omit the Cartesian radar view (`/radar/cartesian`).
    pub no_radar_cartesian: bool,
    /// Pixel size of the Cartesian radar view, metres.
    pub radar_cartesian_m_per_px: f64,
    /// Width and height of the Cartesian radar view, pixels.
    pub radar_cartesian_size_px: u32,
    /// Skip the fsync before the final rename.
    pub no_sync: bool,
}

impl Default for RecordingFlags {
    fn default() -> Self {
        Self {
            force: false,
            compression: "zstd".into(),
            zstd_level: 1,
            no_foxglove_views: false,
            no_radar_cartesian: false,
            radar_cartesian_m_per_px: CartesianGrid::default().metres_per_pixel,
            radar_cartesian_size_px: CartesianGrid::default().size_px,
            no_sync: false,
        }
    }
}

impl RecordingFlags {
    /// The compression names of `--compression`.
    pub const COMPRESSIONS: [&'static str; 3] = ["none", "zstd", "lz4"];

    /// The writer's options.
    ///
    /// # Errors
    /// An unknown compression, a zstd level outside 1..=19, a Cartesian size
    /// outside 1..=[`super::cartesian::MAX_CARTESIAN_SIZE_PX`] or a pixel size
    /// that is not a positive number of metres, naming the flag.
    pub fn options(&self) -> std::result::Result<RecordingOptions, String> {
        if !(1..=19).contains(&self.zstd_level) {
            return Err(format!("--zstd-level {}: expected 1 (fast) ..= 19 (small)", self.zstd_level));
        }
        let max = super::cartesian::MAX_CARTESIAN_SIZE_PX;
        if !(1..=max).contains(&self.radar_cartesian_size_px) {
            return Err(format!(
                "--radar-cartesian-size-px {}: expected 1..={max} pixels",
                self.radar_cartesian_size_px
            ));
        }
        let m = self.radar_cartesian_m_per_px;
        if !(m.is_finite() && m > 0.0) {
            return Err(format!("--radar-cartesian-m-per-px {m}: expected a positive number of metres"));
        }
        let compression = match self.compression.as_str() {
            "none" => Compression::None,
            "zstd" => Compression::Zstd { level: self.zstd_level },
            "lz4" => Compression::Lz4,
            other => return Err(format!("--compression '{other}': expected one of none, zstd, lz4")),
        };
        Ok(RecordingOptions {
            compression,
            overwrite: if self.force { Overwrite::Replace } else { Overwrite::Refuse },
            foxglove_views: !self.no_foxglove_views,
            durability: if self.no_sync { Durability::PageCache } else { Durability::Fsync },
            radar_cartesian: (!self.no_radar_cartesian && !self.no_foxglove_views)
                .then_some(CartesianGrid { metres_per_pixel: m, size_px: self.radar_cartesian_size_px }),
            ..RecordingOptions::default()
        })
    }
}

impl Default for RecordingOptions {
    fn default() -> Self {
        Self {
            compression: Compression::Zstd { level: 1 },
            chunk_size_bytes: 4 << 20,
            overwrite: Overwrite::Refuse,
            foxglove_views: true,
            durability: Durability::Fsync,
            radar_cartesian: None,
        }
    }
}

/// What [`RecordingWriter::finish`] reports.
#[derive(Debug, Clone, PartialEq)]
pub struct WriteSummary {
    /// Final path.
    pub path: PathBuf,
    /// Messages per topic (display copies included).
    pub message_counts: BTreeMap<String, u64>,
    /// Bytes on disk.
    pub file_bytes: u64,
}

/// Encodings and metadata of a channel being registered.
struct ChannelEncoding<'a> {
    schema: &'a str,
    message: &'a str,
    metadata: &'a BTreeMap<String, String>,
}

struct ChannelState {
    id: u16,
    next_sequence: u32,
}

/// Writes one canonical recording. Nothing appears at the target path until
/// [`RecordingWriter::finish`] succeeds; dropping the writer discards the file.
pub struct RecordingWriter {
    file: AtomicFile,
    overwrite: Overwrite,
    durability: Durability,
    foxglove_views: bool,
    mcap: mcap::Writer<BufWriter<File>>,
    channels: BTreeMap<String, ChannelState>,
    counts: BTreeMap<String, u64>,
    buffer: Vec<u8>,
    cartesian: Option<CartesianResampler>,
    /// Earliest log time written, for the sensor mounts on `/tf`.
    first_log_time_ns: Option<u64>,
    /// Sensor frames that need a mount on `/tf` (sensors written).
    mounts_needed: BTreeSet<&'static str>,
    /// Mounts `base_link -> sensor` already in the file (copied `/tf`).
    mounts_present: BTreeSet<String>,
    /// Positions of the SLAM sources written, by kind (`bs`, `va`, `sp`) and
    /// index, for the path markers of later epochs.
    slam_sources_m: BTreeMap<(&'static str, usize), [f64; 3]>,
    /// The delay x time view of the CIR snapshots (`/viz/cir`) and the time
    /// of the last snapshot added to it.
    cir_waterfall: CirWaterfall,
    cir_last_t_ns: i64,
}

impl RecordingWriter {
    /// Starts a recording at `path` with its metadata.
    pub fn create(path: &Path, metadata: &RecordingMetadata, options: &RecordingOptions) -> Result<Self> {
        let file = AtomicFile::create(path, options.overwrite)?;
        let (compression, level) = match options.compression {
            Compression::None => (None, 0),
            Compression::Zstd { level } => (Some(mcap::Compression::Zstd), level),
            Compression::Lz4 => (Some(mcap::Compression::Lz4), 0),
        };
        let mut write_options = mcap::WriteOptions::new()
            .compression(compression)
            .chunk_size(Some(options.chunk_size_bytes))
            .profile("")
            .library(concat!("mmtrack ", env!("CARGO_PKG_VERSION")));
        if level > 0 {
            // zstd's own worker threads compress chunks beside the writer, as
            // many as the current rayon pool has threads (`--threads`); zstd
            // writes the same bytes for any worker count of at least one.
            let threads = u32::try_from(rayon::current_num_threads()).unwrap_or(1).max(1);
            write_options = write_options.compression_level(level).compression_threads(threads);
        }
        let cartesian = match options.radar_cartesian {
            Some(grid) => Some(CartesianResampler::new(grid).map_err(|detail| IoError::BadValue {
                path: path.to_path_buf(),
                record: "recording options".into(),
                field: "radar_cartesian",
                detail,
            })?),
            None => None,
        };
        let mut mcap = write_options.create(file.writer()?).map_err(|e| write_err(path, e))?;
        mcap.write_metadata(&mcap::records::Metadata { name: METADATA_NAME.into(), metadata: metadata.to_map() })
            .map_err(|e| write_err(path, e))?;
        Ok(Self {
            file,
            overwrite: options.overwrite,
            durability: options.durability,
            foxglove_views: options.foxglove_views,
            mcap,
            channels: BTreeMap::new(),
            counts: BTreeMap::new(),
            buffer: Vec::with_capacity(1 << 16),
            cartesian,
            first_log_time_ns: None,
            mounts_needed: BTreeSet::new(),
            mounts_present: BTreeSet::new(),
            slam_sources_m: BTreeMap::new(),
            cir_waterfall: CirWaterfall::default(),
            cir_last_t_ns: 0,
        })
    }

    /// The Cartesian radar view's resampler, when the options ask for one;
    /// callers that decode scans on worker threads clone it and pass each
    /// view to [`Self::write_radar_png_and_view`] or
    /// [`Self::write_radar_scan_and_view`].
    #[must_use]
    pub fn cartesian_resampler(&self) -> Option<&CartesianResampler> {
        self.cartesian.as_ref()
    }

    fn saw_log_time(&mut self, log_time_ns: u64) {
        self.first_log_time_ns = Some(self.first_log_time_ns.map_or(log_time_ns, |t| t.min(log_time_ns)));
    }

    /// Notes the sensor mounts a copied message implies or carries.
    fn note_copied(&mut self, message: &RawMessage) {
        match message.channel.topic.as_str() {
            RADAR_IMAGE_TOPIC => {
                self.mounts_needed.insert(RADAR_FRAME);
            }
            GNSS_TOPIC => {
                self.mounts_needed.insert(GNSS_FRAME);
            }
            TF_TOPIC | TF_STATIC_TOPIC if message.channel.schema_name == "foxglove.FrameTransforms" => {
                if let Ok(tf) = <FrameTransforms as Message>::decode(message.data.clone()) {
                    for t in tf.transforms.into_iter().filter(|t| t.parent_frame_id == VEHICLE_FRAME) {
                        self.mounts_present.insert(t.child_frame_id);
                    }
                }
            }
            _ => {}
        }
    }

    fn path(&self) -> &Path {
        self.file.target()
    }

    /// Registers `topic` on first use and returns its channel id.
    fn channel(&mut self, topic: &str, schema_name: &str, schema_data: &[u8]) -> Result<u16> {
        let encoding = ChannelEncoding { schema: "protobuf", message: "protobuf", metadata: &BTreeMap::new() };
        self.channel_with(topic, schema_name, schema_data, &encoding)
    }

    fn channel_with(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_data: &[u8],
        encoding: &ChannelEncoding<'_>,
    ) -> Result<u16> {
        if let Some(state) = self.channels.get(topic) {
            return Ok(state.id);
        }
        let path = self.file.target().to_path_buf();
        let schema_id = if schema_name.is_empty() {
            0
        } else {
            self.mcap.add_schema(schema_name, encoding.schema, schema_data).map_err(|e| write_err(&path, e))?
        };
        let id = self
            .mcap
            .add_channel(schema_id, topic, encoding.message, encoding.metadata)
            .map_err(|e| write_err(&path, e))?;
        self.channels.insert(topic.to_string(), ChannelState { id, next_sequence: 0 });
        Ok(id)
    }

    /// Copies a message read from another file (e.g. the recording being
    /// extended), keeping its channel, schema, sequence number and log time.
    pub fn copy_message(&mut self, message: &RawMessage) -> Result<()> {
        let channel = &message.channel;
        let encoding = ChannelEncoding {
            schema: &channel.schema_encoding,
            message: &channel.message_encoding,
            metadata: &channel.metadata,
        };
        let id = self.channel_with(&channel.topic, &channel.schema_name, &channel.schema_data, &encoding)?;
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: message.sequence,
            log_time: message.log_time_ns,
            publish_time: message.log_time_ns,
        };
        let path = self.file.target().to_path_buf();
        self.mcap.write_to_known_channel(&header, &message.data).map_err(|e| write_err(&path, e))?;
        self.saw_log_time(message.log_time_ns);
        self.note_copied(message);
        if let Some(state) = self.channels.get_mut(&channel.topic) {
            state.next_sequence = state.next_sequence.max(message.sequence.wrapping_add(1));
        }
        *self.counts.entry(channel.topic.clone()).or_insert(0) += 1;
        Ok(())
    }

    /// Writes `self.buffer` as the next message on `topic`, with an explicit
    /// sequence number when given (radar image and meta share one).
    fn emit(&mut self, topic: &str, channel_id: u16, t_ns: i64, sequence: Option<u32>) -> Result<u32> {
        let log_time = u64::try_from(t_ns).map_err(|_| IoError::BadValue {
            path: self.path().to_path_buf(),
            record: format!("message on {topic}"),
            field: "t_ns",
            detail: format!("{t_ns} is negative; recordings store non-negative nanoseconds"),
        })?;
        let state = self.channels.get_mut(topic).ok_or_else(|| IoError::RecordingWrite {
            path: self.file.target().to_path_buf(),
            detail: format!("channel {topic} used before registration"),
        })?;
        let sequence = sequence.unwrap_or(state.next_sequence);
        state.next_sequence = sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader { channel_id, sequence, log_time, publish_time: log_time };
        let path = self.file.target().to_path_buf();
        self.mcap.write_to_known_channel(&header, &self.buffer).map_err(|e| write_err(&path, e))?;
        self.saw_log_time(log_time);
        *self.counts.entry(topic.to_string()).or_insert(0) += 1;
        Ok(sequence)
    }

    fn write_spec<M: SpecMessage>(
        &mut self,
        topic: &'static str,
        t_ns: i64,
        message: &M,
        sequence: Option<u32>,
    ) -> Result<u32> {
        let id = self.channel(topic, M::SPEC.full_name, &M::SPEC.file_descriptor_set())?;
        self.buffer.clear();
        message.encode(&mut self.buffer).map_err(|e| write_err(self.file.target(), e))?;
        self.emit(topic, id, t_ns, sequence)
    }

    pub(super) fn write_foxglove<M: Encode + Message>(
        &mut self,
        topic: &'static str,
        t_ns: i64,
        message: &M,
        sequence: Option<u32>,
    ) -> Result<u32> {
        let schema = M::get_schema().ok_or_else(|| IoError::RecordingWrite {
            path: self.path().to_path_buf(),
            detail: format!("foxglove schema missing for {topic}"),
        })?;
        let id = self.channel(topic, &schema.name, &schema.data)?;
        self.buffer.clear();
        self.buffer.reserve(Message::encoded_len(message));
        Message::encode(message, &mut self.buffer).map_err(|e| write_err(self.file.target(), e))?;
        self.emit(topic, id, t_ns, sequence)
    }

    fn header_message(&self, header: &PolarScanHeader, power_column_offset: u32) -> Result<proto::RadarScanMeta> {
        let bins = u32::try_from(header.bins_per_azimuth).map_err(|_| IoError::BadValue {
            path: self.path().to_path_buf(),
            record: format!("radar scan at {} ns", header.t_ns),
            field: "bins_per_azimuth",
            detail: "does not fit in 32 bits".into(),
        })?;
        Ok(proto::RadarScanMeta {
            t_ns: header.t_ns,
            range_resolution_m: header.range_resolution_m,
            range_offset_m: header.range_offset_m,
            bins_per_azimuth: bins,
            power_column_offset,
            azimuth_t_ns: header.azimuths.iter().map(|a| a.t_ns).collect(),
            azimuth_rad: header.azimuths.iter().map(|a| a.azimuth_rad).collect(),
            valid: header.azimuths.iter().map(|a| a.valid).collect(),
        })
    }

    /// Writes a radar scan: its power as a mono8 `foxglove.RawImage` and its
    /// per-azimuth metadata, both with the same sequence number, and, when the
    /// options ask for it, its Cartesian view (resampled here).
    pub fn write_radar_scan(&mut self, scan: &PolarScan) -> Result<()> {
        let view = match &self.cartesian {
            Some(resampler) => Some(
                resampler
                    .resample(&scan.header, &scan.power, scan.header.bins_per_azimuth, 0)
                    .map_err(|detail| self.bad_scan(&scan.header, detail))?,
            ),
            None => None,
        };
        self.write_radar_scan_and_view(scan, view.as_deref())
    }

    fn bad_scan(&self, header: &PolarScanHeader, detail: String) -> IoError {
        IoError::BadValue {
            path: self.path().to_path_buf(),
            record: format!("radar scan at {} ns", header.t_ns),
            field: "power",
            detail,
        }
    }

    /// [`Self::write_radar_scan`] with the Cartesian view computed by the
    /// caller (e.g. on worker threads, with [`Self::cartesian_resampler`]);
    /// `None` writes no view.
    pub fn write_radar_scan_and_view(&mut self, scan: &PolarScan, cartesian: Option<&[u8]>) -> Result<()> {
        let header = &scan.header;
        let meta = self.header_message(header, 0)?;
        let sequence = self.write_spec(RADAR_META_TOPIC, header.t_ns, &meta, None)?;
        let image = RawImage {
            timestamp: timestamp(header.t_ns),
            frame_id: "radar".into(),
            width: meta.bins_per_azimuth,
            height: header.azimuths.len() as u32,
            encoding: "mono8".into(),
            step: meta.bins_per_azimuth,
            data: bytes::Bytes::copy_from_slice(&scan.power),
        };
        self.write_foxglove(RADAR_IMAGE_TOPIC, header.t_ns, &image, Some(sequence))?;
        self.mounts_needed.insert(RADAR_FRAME);
        if let Some(pixels) = cartesian {
            self.write_radar_cartesian(header.t_ns, pixels, sequence)?;
        }
        Ok(())
    }

    /// Writes a Cartesian view on `/radar/cartesian` (mono8 `foxglove.RawImage`,
    /// frame `radar`, the grid of [`Self::cartesian_resampler`]), with the
    /// sequence number of the polar scan it shows.
    fn write_radar_cartesian(&mut self, t_ns: i64, pixels: &[u8], sequence: u32) -> Result<()> {
        let Some(grid) = self.cartesian.as_ref().map(CartesianResampler::grid) else {
            return Err(IoError::RecordingWrite {
                path: self.path().to_path_buf(),
                detail: "a Cartesian radar view was given but the recording options set no radar_cartesian grid".into(),
            });
        };
        let side = grid.size_px as usize;
        if pixels.len() != side * side {
            return Err(IoError::BadValue {
                path: self.path().to_path_buf(),
                record: format!("radar scan at {t_ns} ns"),
                field: "cartesian view",
                detail: format!("{} bytes, expected {side} x {side}", pixels.len()),
            });
        }
        let image = RawImage {
            timestamp: timestamp(t_ns),
            frame_id: RADAR_FRAME.into(),
            width: grid.size_px,
            height: grid.size_px,
            encoding: "mono8".into(),
            step: grid.size_px,
            data: bytes::Bytes::copy_from_slice(pixels),
        };
        self.write_foxglove(RADAR_CARTESIAN_TOPIC, t_ns, &image, Some(sequence))?;
        Ok(())
    }

    /// Writes a radar scan whose power is a dataset PNG carried byte for byte
    /// (`foxglove.CompressedImage`, format `png`). `power_column_offset` is the
    /// number of leading image columns that are not range bins (11 for the
    /// Oxford/Boreas row header). The caller has checked the PNG's shape.
    pub fn write_radar_png(&mut self, header: &PolarScanHeader, png: &[u8], power_column_offset: u32) -> Result<()> {
        self.write_radar_png_and_view(header, png, power_column_offset, None)
    }

    /// [`Self::write_radar_png`] and the scan's Cartesian view computed by the
    /// caller from the decoded PNG (with [`Self::cartesian_resampler`]);
    /// `None` writes no view.
    pub fn write_radar_png_and_view(
        &mut self,
        header: &PolarScanHeader,
        png: &[u8],
        power_column_offset: u32,
        cartesian: Option<&[u8]>,
    ) -> Result<()> {
        let meta = self.header_message(header, power_column_offset)?;
        let sequence = self.write_spec(RADAR_META_TOPIC, header.t_ns, &meta, None)?;
        let image = CompressedImage {
            timestamp: timestamp(header.t_ns),
            frame_id: "radar".into(),
            data: bytes::Bytes::copy_from_slice(png),
            format: "png".into(),
        };
        self.write_foxglove(RADAR_IMAGE_TOPIC, header.t_ns, &image, Some(sequence))?;
        self.mounts_needed.insert(RADAR_FRAME);
        if let Some(pixels) = cartesian {
            self.write_radar_cartesian(header.t_ns, pixels, sequence)?;
        }
        Ok(())
    }

    /// Writes a pose of a trajectory (and its Foxglove display copy and
    /// `/tf` transform). Its child frame is the stream's frame in `/tf`
    /// ([`vehicle_frame`]: `base_link`, `estimate`, `tx`, `rx`), one name
    /// for the vehicle on every channel; which sensor's pose the ground truth
    /// is goes in the metadata (`ground_truth.frame`).
    pub fn write_pose(&mut self, stream: PoseStream, pose: &StampedPose, parent_frame: &str) -> Result<()> {
        let p = pose.parent_from_child;
        let child_frame = vehicle_frame(stream);
        let message = proto::Pose2D {
            t_ns: pose.t_ns,
            parent_frame: parent_frame.into(),
            child_frame: child_frame.into(),
            x_m: p.x_m,
            y_m: p.y_m,
            yaw_rad: p.yaw_rad,
        };
        self.write_spec(stream.topic(), pose.t_ns, &message, None)?;
        if self.foxglove_views {
            let view = PoseInFrame {
                timestamp: timestamp(pose.t_ns),
                frame_id: parent_frame.into(),
                pose: Some(Pose {
                    position: Some(Vector3 { x: p.x_m, y: p.y_m, z: 0.0 }),
                    orientation: Some(yaw_quaternion(p.yaw_rad)),
                }),
            };
            self.write_foxglove(stream.viz_topic(), pose.t_ns, &view, None)?;
            let tf = FrameTransforms { transforms: vec![frame_transform(pose.t_ns, parent_frame, child_frame, p)] };
            self.write_foxglove(TF_TOPIC, pose.t_ns, &tf, None)?;
        }
        Ok(())
    }

    /// Writes a GNSS fix of the vehicle (and its Foxglove display copy).
    pub fn write_gnss_fix(&mut self, fix: &GnssFix) -> Result<()> {
        self.mounts_needed.insert(GNSS_FRAME);
        self.write_fix(GNSS_TOPIC, GNSS_VIZ_TOPIC, GNSS_FRAME, fix)
    }

    /// Writes a GNSS fix of the beam-sweeping array, e.g. a roadside unit
    /// (`/gnss/array`, and its Foxglove display copy).
    pub fn write_array_gnss_fix(&mut self, fix: &GnssFix) -> Result<()> {
        self.write_fix(GNSS_ARRAY_TOPIC, GNSS_ARRAY_VIZ_TOPIC, "gnss_array", fix)
    }

    fn write_fix(&mut self, topic: &'static str, viz_topic: &'static str, frame_id: &str, fix: &GnssFix) -> Result<()> {
        let message = proto::GnssFix {
            t_ns: fix.t_ns,
            latitude_deg: fix.latitude_deg,
            longitude_deg: fix.longitude_deg,
            altitude_m: fix.altitude_m,
            horizontal_sigma_m: fix.horizontal_sigma_m,
            num_satellites: fix.num_satellites,
            quality: fix.quality.code(),
        };
        self.write_spec(topic, fix.t_ns, &message, None)?;
        if self.foxglove_views {
            let (covariance, covariance_type) = match fix.horizontal_sigma_m {
                Some(sigma_m) => {
                    let var_m2 = sigma_m * sigma_m;
                    (vec![var_m2, 0.0, 0.0, 0.0, var_m2, 0.0, 0.0, 0.0, 0.0], 1)
                }
                None => (vec![0.0; 9], 0),
            };
            let view = LocationFix {
                timestamp: timestamp(fix.t_ns),
                frame_id: frame_id.into(),
                latitude: fix.latitude_deg,
                longitude: fix.longitude_deg,
                // As sensor_msgs/NavSatFix, which LocationFix mirrors: NaN
                // when no altitude is available.
                altitude: fix.altitude_m.unwrap_or(f64::NAN),
                position_covariance: covariance,
                position_covariance_type: covariance_type,
                ..Default::default()
            };
            self.write_foxglove(viz_topic, fix.t_ns, &view, None)?;
        }
        Ok(())
    }

    /// Writes a channel impulse response snapshot.
    pub fn write_cir(&mut self, cir: &CirSnapshot) -> Result<()> {
        let message = proto::CirSnapshot {
            t_ns: cir.t_ns,
            set_index: cir.set_index,
            snapshot_index: cir.snapshot_index,
            tx_antenna: cir.tx_antenna,
            rx_antenna: cir.rx_antenna,
            carrier_hz: cir.carrier_hz,
            tap_spacing_s: cir.tap_spacing_s,
            delay_offset_s: cir.delay_offset_s,
            taps_re: cir.taps.iter().map(|t| t.re).collect(),
            taps_im: cir.taps.iter().map(|t| t.im).collect(),
            first_path_hint_s: cir.first_path_hint_s,
        };
        self.write_spec(CIR_TOPIC, cir.t_ns, &message, None)?;
        if self.foxglove_views {
            if let Some(image) = self.cir_waterfall.add(cir.set_index, cir.taps.iter().map(|t| t.norm_sqr())) {
                self.write_cir_view(self.cir_last_t_ns, &image)?;
            }
            self.cir_last_t_ns = cir.t_ns;
        }
        Ok(())
    }

    /// Writes one image of the CIR waterfall on `/viz/cir` (mono8
    /// `foxglove.RawImage`, frame `rx`), at the time of its newest set's
    /// last snapshot ([`super::cir_view`]).
    fn write_cir_view(&mut self, t_ns: i64, image: &WaterfallImage) -> Result<()> {
        let view = RawImage {
            timestamp: timestamp(t_ns),
            frame_id: "rx".into(),
            width: image.width,
            height: image.height,
            encoding: "mono8".into(),
            step: image.width,
            data: bytes::Bytes::copy_from_slice(&image.pixels),
        };
        self.write_foxglove(CIR_VIZ_TOPIC, t_ns, &view, None)?;
        Ok(())
    }

    /// Writes one true multipath component of a simulated CIR snapshot
    /// (`mmtrack.MpcTruth` on `/channel/mpc_truth`, log time `truth.t_ns`).
    pub fn write_mpc_truth(&mut self, truth: &MpcTruth) -> Result<()> {
        let message = proto::MpcTruth {
            t_ns: truth.t_ns,
            set_index: truth.set_index,
            snapshot_index: truth.snapshot_index,
            path_id: truth.path_id,
            delay_s: truth.delay_s,
            amplitude_re: truth.amplitude.re,
            amplitude_im: truth.amplitude.im,
            doppler_hz: truth.doppler_hz,
        };
        self.write_spec(MPC_TRUTH_TOPIC, truth.t_ns, &message, None)?;
        Ok(())
    }

    /// Writes a beam sweep (`mmtrack.BeamSweep` on `/beam/sweeps`), with the
    /// codebook's identifier when the source names one.
    pub fn write_beam_sweep(&mut self, sweep: &BeamSweep, codebook: Option<&str>) -> Result<()> {
        let beams = sweep.beam_count();
        let beam_count = u32::try_from(beams).map_err(|_| IoError::BadValue {
            path: self.path().to_path_buf(),
            record: format!("beam sweep at {} ns", sweep.t_ns()),
            field: "beam_count",
            detail: format!("{beams} beams do not fit in 32 bits"),
        })?;
        let message = proto::BeamSweep {
            t_ns: sweep.t_ns(),
            beam_count,
            power_linear: (0..beams).map(|b| sweep.power(b).unwrap_or(0.0)).collect(),
            measured: (0..beams).map(|b| sweep.is_measured(b)).collect(),
            codebook: codebook.map(str::to_string),
        };
        self.write_spec(BEAM_SWEEP_TOPIC, sweep.t_ns(), &message, None)?;
        Ok(())
    }

    /// Writes the sensor mounts `base_link -> radar` / `base_link -> gnss`
    /// (identity, see [`super::tf`]) on `/tf_static` at the first log time, for the
    /// sensors written and not already mounted in a copied `/tf` or `/tf_static`.
    fn write_mounts(&mut self) -> Result<()> {
        let Some(first_ns) = self.first_log_time_ns else { return Ok(()) };
        let t_ns = i64::try_from(first_ns).map_err(|_| IoError::RecordingWrite {
            path: self.path().to_path_buf(),
            detail: format!("first log time {first_ns} ns does not fit in 63 bits"),
        })?;
        let transforms: Vec<_> = self
            .mounts_needed
            .iter()
            .filter(|frame| !self.mounts_present.contains(**frame))
            .map(|frame| frame_transform(t_ns, VEHICLE_FRAME, frame, Se2::IDENTITY))
            .collect();
        if transforms.is_empty() {
            return Ok(());
        }
        self.write_foxglove(TF_STATIC_TOPIC, t_ns, &FrameTransforms { transforms }, None)?;
        Ok(())
    }

    /// Completes the file (sensor mounts on `/tf_static`, summary, index, footer) and
    /// moves it into place.
    pub fn finish(mut self) -> Result<WriteSummary> {
        if self.foxglove_views {
            self.write_mounts()?;
            if let Some(image) = self.cir_waterfall.finish_set() {
                self.write_cir_view(self.cir_last_t_ns, &image)?;
            }
        }
        let path = self.file.target().to_path_buf();
        self.mcap.finish().map_err(|e| write_err(&path, e))?;
        let mut inner = self.mcap.into_inner();
        std::io::Write::flush(&mut inner).map_err(|source| IoError::Os { path: path.clone(), source })?;
        drop(inner);
        let path = self.file.commit(self.overwrite, self.durability)?;
        let file_bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        Ok(WriteSummary { path, message_counts: self.counts, file_bytes })
    }
}

fn write_err(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::RecordingWrite { path: path.to_path_buf(), detail: e.to_string() }
}
