//! `mmtrack ingest <kind> <input> -o <recording.mcap>`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use mmtrack_ingest::beams::{DeepsenseOptions, VehiclePositions};
use mmtrack_ingest::boreas::BoreasOptions;
use mmtrack_ingest::cir::{CirFormat, ingest_cir};
use mmtrack_ingest::mulran::{self, MulranOptions};
use mmtrack_ingest::oxford::{self, OxfordOptions};
use mmtrack_ingest::poses::{self, Plane};
use mmtrack_ingest::ros2::Ros2Topics;
use mmtrack_io::RecordingOptions;
use mmtrack_io::recording::PoseStream;
use mmtrack_io::recording::RecordingFlags;
use mmtrack_io::recording::cartesian::{CartesianGrid, MAX_CARTESIAN_SIZE_PX};

use crate::progress;
use crate::threads::ThreadsArg;

mod folders;

pub use folders::oxford_folder;
use folders::{RecordingDirArgs, SweepArgs, boreas_folder, deepsense_folder, mulran_folder, positive_metres};

/// Options shared by every ingest kind.
#[derive(Args, Clone)]
pub struct OutputArgs {
    /// The recording to write (one MCAP file per sequence).
    #[arg(short, long, value_name = "RECORDING.mcap")]
    pub output: PathBuf,
    /// Replace an existing output (atomically, once the new one is complete).
    #[arg(long)]
    pub force: bool,
    /// Chunk compression of the recording.
    #[arg(long, value_enum, default_value_t = CompressionArg::Zstd)]
    pub compression: CompressionArg,
    /// zstd level (1 fast .. 19 small).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=19))]
    pub zstd_level: u32,
    /// Omit the Foxglove display channels (/viz/..., /tf, /radar/cartesian).
    #[arg(long)]
    pub no_foxglove_views: bool,
    /// Skip the fsync before the final rename: faster on large recordings, but a
    /// power cut right afterwards may lose the new file.
    #[arg(long)]
    pub no_sync: bool,
}

/// The Cartesian radar view's options, on the commands that write radar scans.
#[derive(Args, Clone)]
pub struct RadarViewArgs {
    /// Omit the Cartesian radar view (/radar/cartesian: each scan resampled onto a square grid around the radar
    /// for Foxglove's image panel); the polar /radar/image is written either way.
    #[arg(long)]
    pub no_radar_cartesian: bool,
    /// Pixel size of the Cartesian radar view, metres.
    #[arg(long, default_value_t = CartesianGrid::default().metres_per_pixel, value_name = "M")]
    pub radar_cartesian_m_per_px: f64,
    /// Width and height of the Cartesian radar view, pixels (odd puts the radar on a pixel centre).
    #[arg(long, default_value_t = CartesianGrid::default().size_px, value_name = "PX",
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_CARTESIAN_SIZE_PX)))]
    pub radar_cartesian_size_px: u32,
}

/// Chunk compression choices.
#[derive(Clone, Copy, ValueEnum)]
pub enum CompressionArg {
    /// No compression (fastest; radar scans gain little from zstd or lz4: they are carried as PNG, compressed already).
    None,
    /// zstd (see --zstd-level).
    Zstd,
    /// lz4.
    Lz4,
}

impl OutputArgs {
    /// The writer's options ([`RecordingFlags::options`]) of a command
    /// without radar scans: no Cartesian view.
    pub fn recording_options(&self) -> anyhow::Result<RecordingOptions> {
        self.flags().options().map_err(crate::usage)
    }

    /// The writer's options of a command that writes radar scans.
    pub fn radar_recording_options(&self, view: &RadarViewArgs) -> anyhow::Result<RecordingOptions> {
        let flags = RecordingFlags {
            no_radar_cartesian: view.no_radar_cartesian,
            radar_cartesian_m_per_px: view.radar_cartesian_m_per_px,
            radar_cartesian_size_px: view.radar_cartesian_size_px,
            ..self.flags()
        };
        flags.options().map_err(crate::usage)
    }

    fn flags(&self) -> RecordingFlags {
        RecordingFlags {
            force: self.force,
            compression: match self.compression {
                CompressionArg::None => "none",
                CompressionArg::Zstd => "zstd",
                CompressionArg::Lz4 => "lz4",
            }
            .to_string(),
            zstd_level: self.zstd_level,
            no_foxglove_views: self.no_foxglove_views,
            no_radar_cartesian: true,
            no_sync: self.no_sync,
            ..RecordingFlags::default()
        }
    }
}

/// Trajectory file formats.
#[derive(Clone, Copy, ValueEnum)]
pub enum PoseFormat {
    /// `timestamp tx ty tz qx qy qz qw` per line.
    Tum,
    /// 12 numbers per line (3x4 matrix), times from --times.
    Kitti,
    /// Oxford Radar RobotCar gt/radar_odometry.csv (relative poses, chained).
    Oxford,
}

impl PoseFormat {
    /// The library's trajectory format.
    #[must_use]
    pub fn trajectory_format(self) -> mmtrack_ingest::poses::TrajectoryFormat {
        use mmtrack_ingest::poses::TrajectoryFormat;
        match self {
            Self::Tum => TrajectoryFormat::Tum,
            Self::Kitti => TrajectoryFormat::Kitti,
            Self::Oxford => TrajectoryFormat::Oxford,
        }
    }
}

/// CIR file formats.
#[derive(Clone, Copy, ValueEnum)]
pub enum CirFormatArg {
    /// NumPy .npy (complex64/complex128, or real with a trailing I/Q axis of 2).
    Npy,
    /// NumPy .npz archive (the sidecar's `variable` picks the array).
    Npz,
    /// MATLAB .mat, v5/v7 (the sidecar's `variable` picks the array); v7.3 (HDF5) in builds with `--features hdf5`.
    Mat,
    /// HDF5 (the sidecar's `dataset` picks the array: complex {r,i}/{real,imag} or a trailing I/Q axis of 2);
    /// needs a build with `--features hdf5` (libhdf5).
    Hdf5,
    /// SigMF .sigmf-meta + .sigmf-data (cf32_le, ci16_le).
    Sigmf,
    /// CSV, one snapshot per row: [t_ns,set_index,snapshot_index,tx_antenna,rx_antenna,]re_0,im_0,re_1,im_1,...
    Csv,
    /// DecaWave DecaRanging accumulator log (DW1000; HLP kept as first-path hint).
    Decawave,
}

impl CirFormatArg {
    fn format(self) -> CirFormat {
        match self {
            Self::Npy => CirFormat::Npy,
            Self::Npz => CirFormat::Npz,
            Self::Mat => CirFormat::Mat,
            Self::Hdf5 => CirFormat::Hdf5,
            Self::Sigmf => CirFormat::Sigmf,
            Self::Csv => CirFormat::Csv,
            Self::Decawave => CirFormat::Decawave,
        }
    }
}

/// Beam-sweep array formats.
#[derive(Clone, Copy, ValueEnum)]
pub enum BeamFormatArg {
    /// DeepSense 6G 60 GHz arrays: scenarioS_unit1_pwr_60ghz_1-N.npy (power per beam), scenarioS_unit1_loc_...,
    /// scenarioS_unit2_loc_... (roadside unit, car), scenarioS_seq_index_... (pass per sweep).
    Deepsense,
}

/// Which of the car's positions to carry.
#[derive(Clone, Copy, ValueEnum)]
pub enum PositionsArg {
    /// As the GPS gave them (unit2_loc).
    Raw,
    /// The calibrated ones (unit2_loc_cal); an error for a scenario without them.
    Calibrated,
    /// Calibrated where the scenario has them, raw otherwise.
    Auto,
}

/// Ground planes.
#[derive(Clone, Copy, ValueEnum)]
pub enum PlaneArg {
    /// x-y with z up.
    Xy,
    /// x-z of a camera frame (x right, y down, z forward).
    XzCamera,
}

#[derive(Args)]
pub struct IngestArgs {
    #[command(subcommand)]
    kind: Kind,
}

#[derive(Subcommand)]
enum Kind {
    /// Oxford Radar RobotCar sequence folder: radar/<t_us>.png, radar.timestamps, gt/radar_odometry.csv, gps/gps.csv, gps/ins.csv.
    Oxford {
        /// The sequence folder.
        input: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
        #[command(flatten)]
        radar_view: RadarViewArgs,
        #[command(flatten)]
        threads: ThreadsArg,
        /// Range bin size in metres (dataset SDK: 0.0432; CFEAR uses 0.0438).
        #[arg(long, default_value_t = oxford::OXFORD.range_resolution_m)]
        range_resolution_m: f64,
        /// Range bins per azimuth: a number, or `auto` to take the PNG width as it is.
        #[arg(long, default_value = "3768")]
        bins: String,
        /// Store decoded mono8 images instead of carrying the PNG bytes unchanged.
        #[arg(long)]
        decode: bool,
        /// Sequence id (default: the folder name).
        #[arg(long)]
        sequence_id: Option<String>,
    },
    /// Boreas sequence folder: radar/<t_us>.png, applanix/radar_poses.csv.
    ///
    /// Range bins of 0.0596 m before 2021-09-21 and 0.04381 m from then on (date
    /// from the folder name boreas-YYYY-MM-DD-HH-MM), range offset -0.31 m, bins
    /// per azimuth from each PNG; poses in a local east-north frame whose origin
    /// is in the metadata.
    Boreas {
        /// The sequence folder.
        input: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
        #[command(flatten)]
        radar_view: RadarViewArgs,
        #[command(flatten)]
        threads: ThreadsArg,
        /// Range bin size in metres (default: chosen by recording date).
        #[arg(long)]
        range_resolution_m: Option<f64>,
        /// Store decoded mono8 images instead of carrying the PNG bytes unchanged.
        #[arg(long)]
        decode: bool,
        /// Sequence id (default: the folder name).
        #[arg(long)]
        sequence_id: Option<String>,
    },
    /// MulRan sequence folder: sensor_data/radar/polar/<t_ns>.png, global_pose.csv.
    ///
    /// Polar PNGs with range along rows and azimuth along columns, transposed
    /// into one row per azimuth; per-azimuth times spread evenly over the scan
    /// period against the file time (--stamp-at); global_pose.csv as ground truth
    /// in a local frame whose origin is in the metadata.
    Mulran {
        /// The sequence folder.
        input: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
        #[command(flatten)]
        radar_view: RadarViewArgs,
        #[command(flatten)]
        threads: ThreadsArg,
        /// Range bin size in metres.
        #[arg(long, default_value_t = mulran::RANGE_RESOLUTION_M)]
        range_resolution_m: f64,
        #[command(flatten)]
        sweep: SweepArgs,
        /// Sequence id (default: the folder name).
        #[arg(long)]
        sequence_id: Option<String>,
    },
    /// Trajectory file (TUM, KITTI, Oxford radar_odometry.csv) into a new recording or added to one.
    Poses {
        /// The trajectory file.
        input: PathBuf,
        /// File format.
        #[arg(long, value_enum)]
        format: PoseFormat,
        #[command(flatten)]
        output: OutputArgs,
        /// Copy this recording and add the poses to it (may be the output itself).
        #[arg(long, value_name = "RECORDING.mcap")]
        add_to: Option<PathBuf>,
        /// Record the poses as an estimate instead of ground truth.
        #[arg(long)]
        estimate: bool,
        /// KITTI: the times file (decimal seconds per line).
        #[arg(long, value_name = "times.txt")]
        times: Option<PathBuf>,
        /// KITTI: nanoseconds added to every time of --times.
        #[arg(long, default_value_t = 0)]
        t0_ns: i64,
        /// Ground plane: x-y with z up, or the x-z plane of a KITTI camera frame.
        #[arg(long, value_enum, default_value_t = PlaneArg::Xy)]
        plane: PlaneArg,
    },
    /// NMEA 0183 GNSS log (GGA with RMC or ZDA, or RMC alone; any talker) into a new recording or added to one.
    Nmea {
        /// The log.
        input: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
        /// Copy this recording and add the fixes to it (may be the output itself).
        #[arg(long, value_name = "RECORDING.mcap")]
        add_to: Option<PathBuf>,
    },
    /// Channel-sounder CIR/CFR file (NumPy, MATLAB, HDF5, SigMF, CSV, DecaWave log) into a new recording.
    ///
    /// A sidecar TOML gives what the file lacks (carrier_hz, tap_spacing_s or
    /// bandwidth_hz, snapshot/set timing, domain = "cir" | "cfr", axes, variable, dataset);
    /// every key, and an example for the real 60 GHz MIMO sample, in docs/commands.md ("mmtrack ingest cir").
    Cir {
        /// The file (.npy, .npz, .mat, .h5, .sigmf-meta/.sigmf-data, .csv, DecaRanging .log).
        input: PathBuf,
        /// File format.
        #[arg(long, value_enum)]
        format: CirFormatArg,
        /// Sidecar TOML with what the file does not say.
        #[arg(long, value_name = "SIDECAR.toml")]
        sidecar: Option<PathBuf>,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Measured beam sweeps with both units' positions (DeepSense 6G 60 GHz arrays) into one recording per pass.
    ///
    /// Writes <DIR>/scenario<S>-pass<PP>.mcap for every pass (sequence id the
    /// same): beam sweeps on /beam/sweeps, the car's positions on /gnss/fix,
    /// the roadside unit's on /gnss/array. The arrays carry no timestamps:
    /// sweep r of a scenario is at r x --sweep-period-s. Every array is
    /// checked first (equal row counts, finite non-negative power,
    /// consecutive passes); nothing is written on an error.
    #[command(verbatim_doc_comment)]
    Beams {
        /// The folder holding the arrays.
        input: PathBuf,
        /// Array format.
        #[arg(long, value_enum)]
        format: BeamFormatArg,
        /// Only this scenario (default: every scenario in the folder).
        #[arg(long, value_name = "S")]
        scenario: Option<u32>,
        /// The car's positions: raw, calibrated, or calibrated where present.
        #[arg(long, value_enum, default_value_t = PositionsArg::Auto)]
        positions: PositionsArg,
        /// Time between consecutive sweeps, seconds.
        #[arg(long, default_value_t = 0.1, value_name = "S")]
        sweep_period_s: f64,
        #[command(flatten)]
        output: RecordingDirArgs,
    },
    /// ROS 2 MCAP bag (cdr): poses from nav_msgs/Odometry or PoseWithCovarianceStamped, fixes from NavSatFix,
    /// Navtech polar scans from sensor_msgs/Image.
    ///
    /// Radar images carry one stamp per sweep: azimuth times are spread evenly over
    /// --scan-period-s with header.stamp at the sweep's end (--stamp-at start to change).
    ///
    /// `mmtrack inspect <bag.mcap>` lists the topics a bag holds.
    Ros2 {
        /// The bag (.mcap).
        input: PathBuf,
        #[command(flatten)]
        output: OutputArgs,
        #[command(flatten)]
        radar_view: RadarViewArgs,
        /// Pose topic (Odometry or PoseWithCovarianceStamped); `none` to skip poses.
        #[arg(long, default_value = "/odom")]
        pose_topic: String,
        /// Record the poses as ground truth instead of as an estimate.
        #[arg(long)]
        poses_are_ground_truth: bool,
        /// A second pose topic recorded as ground truth (e.g. /amcl_pose beside /odom), to score the estimate.
        #[arg(long)]
        ground_truth_topic: Option<String>,
        /// NavSatFix topic, if any.
        #[arg(long)]
        gnss_topic: Option<String>,
        /// sensor_msgs/Image topic of Navtech polar scans (mono8, one row per azimuth), if any.
        #[arg(long, requires = "radar_range_resolution_m")]
        radar_topic: Option<String>,
        /// Range bin size of the radar images in metres (CTS350-X: 0.0438, CIR204-H: 0.0596).
        #[arg(long)]
        radar_range_resolution_m: Option<f64>,
        #[command(flatten)]
        sweep: SweepArgs,
    },
}

impl Kind {
    /// Refuses, before any reading, an output that is one of the inputs or
    /// that cannot be replaced by a new file (a directory, a FIFO, a device
    /// node; [`mmtrack_io::check_output_file`]) or folder.
    fn check_output(&self) -> anyhow::Result<()> {
        let (output, inputs): (&std::path::Path, Vec<&std::path::Path>) = match self {
            Self::Oxford { input, output, .. }
            | Self::Boreas { input, output, .. }
            | Self::Mulran { input, output, .. }
            | Self::Nmea { input, output, .. }
            | Self::Ros2 { input, output, .. } => (&output.output, vec![input]),
            Self::Poses { input, output, times, .. } => {
                (&output.output, [Some(input), times.as_ref()].into_iter().flatten().map(PathBuf::as_path).collect())
            }
            Self::Cir { input, sidecar, output, .. } => {
                (&output.output, [Some(input), sidecar.as_ref()].into_iter().flatten().map(PathBuf::as_path).collect())
            }
            Self::Beams { input, output, .. } => {
                mmtrack_io::check_output_is_not_input(&output.output, &[input])?;
                return Ok(mmtrack_io::check_output_dir(&output.output)?);
            }
        };
        mmtrack_io::check_output_is_not_input(output, &inputs)?;
        Ok(mmtrack_io::check_output_file(output)?)
    }
}

pub fn run(args: IngestArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    args.kind.check_output()?;
    match args.kind {
        Kind::Oxford { input, output, radar_view, threads, range_resolution_m, bins, decode, sequence_id } => {
            let expected_bins = mmtrack_ingest::flags::parse_bins(&bins).map_err(crate::usage)?;
            positive_metres("--range-resolution-m", range_resolution_m)?;
            let options = OxfordOptions {
                layout: oxford::NavtechLayout { range_resolution_m, expected_bins, ..oxford::OXFORD },
                carry_png: !decode,
                sequence_id,
            };
            threads.install(|| oxford_folder(&input, &output, &radar_view, &options, quiet))?
        }
        Kind::Boreas { input, output, radar_view, threads, range_resolution_m, decode, sequence_id } => {
            if let Some(r) = range_resolution_m {
                positive_metres("--range-resolution-m", r)?;
            }
            let options = BoreasOptions { range_resolution_m, decode, sequence_id };
            threads.install(|| boreas_folder(&input, &output, &radar_view, &options, quiet))?
        }
        Kind::Mulran { input, output, radar_view, threads, range_resolution_m, sweep, sequence_id } => {
            positive_metres("--range-resolution-m", range_resolution_m)?;
            let options = MulranOptions { range_resolution_m, timing: sweep.timing()?, sequence_id };
            threads.install(|| mulran_folder(&input, &output, &radar_view, &options, quiet))?
        }
        Kind::Poses { input, format, mut output, add_to, estimate, times, t0_ns, plane } => {
            let plane = match plane {
                PlaneArg::Xy => Plane::Xy,
                PlaneArg::XzCamera => Plane::XzCamera,
            };
            let file = poses::PoseFile {
                path: &input,
                format: format.trajectory_format(),
                times: times.as_deref(),
                t0_ns,
                plane,
            };
            allow_in_place(add_to.as_deref(), &mut output);
            let stream = if estimate { PoseStream::Estimate } else { PoseStream::GroundTruth };
            let (summary, count) =
                poses::ingest_poses(&file, stream, add_to.as_deref(), &output.output, &output.recording_options()?)?;
            if !quiet {
                println!("{}: {count} poses on {}", summary.path.display(), stream.topic());
            }
            Ok(ExitCode::SUCCESS)
        }
        Kind::Nmea { input, mut output, add_to } => {
            allow_in_place(add_to.as_deref(), &mut output);
            let report = mmtrack_ingest::nmea::ingest_nmea(
                &input,
                &output.output,
                add_to.as_deref(),
                &output.recording_options()?,
            )?;
            if !quiet {
                println!("{}", report.summary());
            }
            Ok(ExitCode::SUCCESS)
        }
        Kind::Cir { input, format, sidecar, output } => {
            cir_file(&input, format.format(), sidecar.as_deref(), &output, quiet)
        }
        Kind::Beams { input, format: BeamFormatArg::Deepsense, scenario, positions, sweep_period_s, output } => {
            let options = DeepsenseOptions {
                scenario,
                positions: match positions {
                    PositionsArg::Raw => VehiclePositions::Raw,
                    PositionsArg::Calibrated => VehiclePositions::Calibrated,
                    PositionsArg::Auto => VehiclePositions::Auto,
                },
                sweep_period_ns: mmtrack_ingest::flags::sweep_period_ns(sweep_period_s).map_err(crate::usage)?,
            };
            deepsense_folder(&input, &output, &options, quiet)
        }
        Kind::Ros2 {
            input,
            output,
            radar_view,
            pose_topic,
            poses_are_ground_truth,
            ground_truth_topic,
            gnss_topic,
            radar_topic,
            radar_range_resolution_m,
            sweep,
        } => {
            let topics = Ros2Topics::from_flags(
                &pose_topic,
                poses_are_ground_truth,
                ground_truth_topic,
                gnss_topic,
                radar_topic,
                radar_range_resolution_m,
                sweep.timing()?,
            )
            .map_err(crate::usage)?;
            folders::ros2_bag(&input, &output, &radar_view, &topics, quiet)
        }
    }
}

/// Adding to the output file itself replaces it, once the new one is complete.
fn allow_in_place(add_to: Option<&std::path::Path>, output: &mut OutputArgs) {
    output.force = mmtrack_ingest::flags::replaces_output(add_to, &output.output, output.force);
}

/// Ingests one CIR file, with a progress bar.
fn cir_file(
    input: &std::path::Path,
    format: CirFormat,
    sidecar: Option<&std::path::Path>,
    output: &OutputArgs,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let bar = progress::bar(0, "ingest cir", "snapshots", quiet);
    let report =
        ingest_cir(format, input, sidecar, &output.output, &output.recording_options()?, &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        println!("{}", report.summary());
    }
    Ok(ExitCode::SUCCESS)
}
