//! The topics of a canonical recording: the contract `schemas/mcap/` documents.

/// One topic of a canonical recording.
#[derive(Debug, Clone, Copy)]
pub struct ChannelSpec {
    /// MCAP topic.
    pub topic: &'static str,
    /// MCAP schema name(s) allowed on the topic.
    pub schema_names: &'static [&'static str],
    /// Whether readers take data from it (`true`) or it only serves display.
    pub canonical: bool,
    /// What one message means.
    pub meaning: &'static str,
}

/// Topic of radar power images.
pub const RADAR_IMAGE_TOPIC: &str = "/radar/image";
/// Display view of radar scans resampled onto a Cartesian grid.
pub const RADAR_CARTESIAN_TOPIC: &str = "/radar/cartesian";
/// Topic of radar per-azimuth metadata.
pub const RADAR_META_TOPIC: &str = "/radar/scan_meta";
/// Topic of GNSS fixes.
pub const GNSS_TOPIC: &str = "/gnss/fix";
/// Display view of GNSS fixes.
pub const GNSS_VIZ_TOPIC: &str = "/viz/gnss";
/// Topic of the coordinate-frame transforms (`foxglove.FrameTransforms`; the
/// frames are in [`super::tf`]).
pub const TF_TOPIC: &str = "/tf";
/// Topic of the fixed transforms (the sensor mounts), written once
/// (`foxglove.FrameTransforms`, as ROS's `/tf_static`).
pub const TF_STATIC_TOPIC: &str = "/tf_static";
/// Topic of channel impulse responses.
pub const CIR_TOPIC: &str = "/channel/cir";
/// Display view of the CIRs: a delay x time image (`foxglove.RawImage`).
pub const CIR_VIZ_TOPIC: &str = "/viz/cir";
/// Topic of the true multipath components of simulated CIRs.
pub const MPC_TRUTH_TOPIC: &str = "/channel/mpc_truth";
/// Display lines of a simulated sounder run's true paths (`foxglove.SceneUpdate`).
pub const MPC_PATHS_VIZ_TOPIC: &str = "/viz/mpc_paths";
/// Topic of beam sweeps of a measured codebook.
pub const BEAM_SWEEP_TOPIC: &str = "/beam/sweeps";
/// Topic of GNSS fixes of the beam-sweeping array (e.g. a roadside unit);
/// the vehicle's own fixes stay on [`GNSS_TOPIC`].
pub const GNSS_ARRAY_TOPIC: &str = "/gnss/array";
/// Display view of the array's GNSS fixes.
pub const GNSS_ARRAY_VIZ_TOPIC: &str = "/viz/gnss_array";
/// Topic of the path measurements of 5G mmWave SLAM epochs.
pub const SLAM_PATHS_TOPIC: &str = "/slam/paths";
/// Topic of the simulator's UE state and path origins per SLAM epoch.
pub const SLAM_UE_TRUTH_TOPIC: &str = "/slam/ue_truth";
/// Topic of the sources of the SLAM paths (base station, true VAs and SPs).
pub const SLAM_SOURCES_TOPIC: &str = "/slam/sources";
/// Display markers of the SLAM sources (`foxglove.SceneUpdate`).
pub const SLAM_SOURCES_VIZ_TOPIC: &str = "/viz/slam_sources";
/// Display markers of each epoch's true paths (`foxglove.SceneUpdate`).
pub const SLAM_PATHS_VIZ_TOPIC: &str = "/viz/slam_paths";
/// Display markers of the SLAM filter's map after each epoch, added by
/// `mmtrack export --format mcap` (`foxglove.SceneUpdate`).
pub const SLAM_ESTIMATE_VIZ_TOPIC: &str = "/viz/slam_estimate";
/// Recording metadata key naming the site of a beam-sweep recording: one
/// array at one place (e.g. `deepsense-scenario1`). Recordings of one site
/// share the array's boresight and codebook, so a beam map fitted on some of
/// them applies to the others.
pub const BEAM_SITE_KEY: &str = "beam.site";

/// Which trajectory a pose belongs to.
///
/// A recording of one platform (radar, GNSS) uses [`PoseStream::GroundTruth`]
/// and [`PoseStream::Estimate`]. A channel-sounder recording has two vehicles:
/// its ground truth is [`PoseStream::GroundTruthTx`] and
/// [`PoseStream::GroundTruthRx`], on their own topics, so readers of
/// `/ground_truth/pose` never mistake one car's poses for the other's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PoseStream {
    /// Ground truth (dataset reference trajectory or simulator truth).
    GroundTruth,
    /// An estimated trajectory (odometry, SLAM).
    Estimate,
    /// Ground truth of a channel sounder's transmitter vehicle.
    GroundTruthTx,
    /// Ground truth of a channel sounder's receiver vehicle.
    GroundTruthRx,
}

impl PoseStream {
    /// Every stream.
    pub const ALL: [PoseStream; 4] = [Self::GroundTruth, Self::Estimate, Self::GroundTruthTx, Self::GroundTruthRx];

    /// Canonical topic.
    #[must_use]
    pub fn topic(self) -> &'static str {
        match self {
            Self::GroundTruth => "/ground_truth/pose",
            Self::Estimate => "/estimate/pose",
            Self::GroundTruthTx => "/ground_truth/tx",
            Self::GroundTruthRx => "/ground_truth/rx",
        }
    }

    /// Foxglove display topic.
    #[must_use]
    pub fn viz_topic(self) -> &'static str {
        match self {
            Self::GroundTruth => "/viz/ground_truth",
            Self::Estimate => "/viz/estimate",
            Self::GroundTruthTx => "/viz/ground_truth_tx",
            Self::GroundTruthRx => "/viz/ground_truth_rx",
        }
    }

    /// Whether the stream is ground truth (of any vehicle).
    #[must_use]
    pub fn is_ground_truth(self) -> bool {
        self != Self::Estimate
    }

    /// The stream a canonical topic belongs to.
    #[must_use]
    pub fn from_topic(topic: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.topic() == topic)
    }
}

/// Every topic a canonical recording may contain.
pub const CHANNELS: &[ChannelSpec] = &[
    ChannelSpec {
        topic: RADAR_IMAGE_TOPIC,
        schema_names: &["foxglove.RawImage", "foxglove.CompressedImage"],
        canonical: true,
        meaning: "radar power of one scan as an image: one row per azimuth, one column per range bin (mono8 RawImage), \
                  or the dataset's PNG carried byte for byte (CompressedImage, format png, with power_column_offset header columns)",
    },
    ChannelSpec {
        topic: RADAR_META_TOPIC,
        schema_names: &["mmtrack.RadarScanMeta"],
        canonical: true,
        meaning: "per-azimuth time, angle and validity of the scan whose image has the same MCAP sequence number",
    },
    ChannelSpec {
        topic: "/ground_truth/pose",
        schema_names: &["mmtrack.Pose2D"],
        canonical: true,
        meaning: "ground-truth pose world_from_vehicle",
    },
    ChannelSpec {
        topic: "/estimate/pose",
        schema_names: &["mmtrack.Pose2D"],
        canonical: true,
        meaning: "estimated pose world_from_vehicle (odometry or SLAM output)",
    },
    ChannelSpec {
        topic: "/ground_truth/tx",
        schema_names: &["mmtrack.Pose2D"],
        canonical: true,
        meaning: "ground-truth pose world_from_vehicle of a channel sounder's transmitter car (one per set)",
    },
    ChannelSpec {
        topic: "/ground_truth/rx",
        schema_names: &["mmtrack.Pose2D"],
        canonical: true,
        meaning: "ground-truth pose world_from_vehicle of a channel sounder's receiver car (one per set)",
    },
    ChannelSpec {
        topic: GNSS_TOPIC,
        schema_names: &["mmtrack.GnssFix"],
        canonical: true,
        meaning: "GNSS position fix",
    },
    ChannelSpec {
        topic: CIR_TOPIC,
        schema_names: &["mmtrack.CirSnapshot"],
        canonical: true,
        meaning: "one channel impulse response snapshot",
    },
    ChannelSpec {
        topic: MPC_TRUTH_TOPIC,
        schema_names: &["mmtrack.MpcTruth"],
        canonical: true,
        meaning: "one true multipath component of a simulated CIR snapshot (same t_ns, set_index, snapshot_index); \
                  a snapshot has as many as it has true paths, possibly none",
    },
    ChannelSpec {
        topic: BEAM_SWEEP_TOPIC,
        schema_names: &["mmtrack.BeamSweep"],
        canonical: true,
        meaning: "one sweep of a measured beam codebook: received power of each measured beam (the array that sweeps \
                  is located by /gnss/array, the vehicle by /gnss/fix)",
    },
    ChannelSpec {
        topic: GNSS_ARRAY_TOPIC,
        schema_names: &["mmtrack.GnssFix"],
        canonical: true,
        meaning: "GNSS position fix of the beam-sweeping array (e.g. a roadside unit); the vehicle's fixes are on /gnss/fix",
    },
    ChannelSpec {
        topic: SLAM_PATHS_TOPIC,
        schema_names: &["mmtrack.PathMeasurements"],
        canonical: true,
        meaning: "the propagation paths (TOA, DOA and DOD azimuth and elevation) a 5G mmWave UE estimated in one \
                  epoch; the UE's true pose per epoch is on /ground_truth/pose when the recording has ground truth",
    },
    ChannelSpec {
        topic: SLAM_UE_TRUTH_TOPIC,
        schema_names: &["mmtrack.SlamUeTruth"],
        canonical: true,
        meaning: "simulator ground truth of one SLAM epoch (same t_ns as its /slam/paths): the full UE state \
                  (position, heading, speed, turn rate, clock bias) and the source of each path",
    },
    ChannelSpec {
        topic: SLAM_SOURCES_TOPIC,
        schema_names: &["mmtrack.SlamSource"],
        canonical: true,
        meaning: "one source of the SLAM paths, written once: the base station (known to the UE) and, as ground \
                  truth, each virtual anchor and scattering point",
    },
    ChannelSpec {
        topic: CIR_VIZ_TOPIC,
        schema_names: &["foxglove.RawImage"],
        canonical: false,
        meaning: "display view of /channel/cir for Foxglove's image panel: a delay x time waterfall (mono8, frame \
                  rx), one image per completed snapshot set holding the last 64 sets, newest at the bottom; a row is \
                  the set's power delay profile (mean |h|^2 over its snapshots), a column up to ceil(taps / 256) taps \
                  (their largest power); grey 255 = the image's strongest tap, 0 = 60 dB below it or weaker",
    },
    ChannelSpec {
        topic: SLAM_SOURCES_VIZ_TOPIC,
        schema_names: &["foxglove.SceneUpdate"],
        canonical: false,
        meaning: "display copy of /slam/sources for Foxglove's 3D panel (frame world): one entity per source, id \
                  <kind>-<index>, a sphere 1.5 m across (base station blue, virtual anchors orange, scattering \
                  points green) and its label, without lifetime",
    },
    ChannelSpec {
        topic: SLAM_PATHS_VIZ_TOPIC,
        schema_names: &["foxglove.SceneUpdate"],
        canonical: false,
        meaning: "the true paths of each epoch from /slam/ue_truth as lines in the 3D panel (frame world; entity \
                  paths, replaced every epoch): line of sight base station -> UE, a virtual anchor's path VA -> UE \
                  (the unfolded reflection, as long as the path), a scattering point's base station -> SP -> UE; \
                  clutter has no line",
    },
    ChannelSpec {
        topic: MPC_PATHS_VIZ_TOPIC,
        schema_names: &["foxglove.SceneUpdate"],
        canonical: false,
        meaning: "where the true paths of a simulated sounder run go, at each set's first snapshot, as lines in the \
                  3D panel (frame world; entity paths, replaced every set): one line strip per path of \
                  /channel/mpc_truth from the transmitter through its wall bounces or scattering car to the \
                  receiver; direct blue, one interaction orange, two green; diffuse scatterers are not drawn",
    },
    ChannelSpec {
        topic: SLAM_ESTIMATE_VIZ_TOPIC,
        schema_names: &["foxglove.SceneUpdate"],
        canonical: false,
        meaning: "the SLAM filter's map after each epoch (table slam_map), added by export --format mcap, in the 3D \
                  panel (frame world; replaced every epoch): one entity per source, id est-<source_id>, a sphere as \
                  wide as twice the belief's spread (1.5 m to 10 m), the base station and confirmed VAs and SPs in \
                  their kind's colour half transparent, unconfirmed sources grey, labelled with kind, id and spread",
    },
    ChannelSpec {
        topic: RADAR_CARTESIAN_TOPIC,
        schema_names: &["foxglove.RawImage"],
        canonical: false,
        meaning: "display copy of a radar scan resampled onto a Cartesian grid (mono8, frame radar, the sensor at the \
                  centre pixel, image up = forward, image left = left; metres per pixel and size in the recording \
                  options, default 0.25 m x 501 px; bilinear in azimuth and range, header columns and invalid rows \
                  left out; power x 2, saturating at 255, for viewing, as the Oxford SDK shows it); same sequence \
                  number and time as the /radar/image it shows",
    },
    ChannelSpec {
        topic: TF_TOPIC,
        schema_names: &["foxglove.FrameTransforms"],
        canonical: false,
        meaning: "coordinate frames for Foxglove's 3D panel: world -> base_link at each ground-truth pose, \
                  world -> estimate at each estimated pose, world -> tx / rx at each sounder car pose (parent: the \
                  pose's parent frame; child: the same frame as the pose's child_frame)",
    },
    ChannelSpec {
        topic: TF_STATIC_TOPIC,
        schema_names: &["foxglove.FrameTransforms"],
        canonical: false,
        meaning: "the fixed sensor mounts, once, at the first log time: base_link -> radar and base_link -> gnss \
                  (identity: the ground truth is the pose of the sensor the metadata key ground_truth.frame names)",
    },
    ChannelSpec {
        topic: "/viz/ground_truth",
        schema_names: &["foxglove.PoseInFrame"],
        canonical: false,
        meaning: "display copy of /ground_truth/pose for Foxglove's 3D panel (frame world)",
    },
    ChannelSpec {
        topic: "/viz/estimate",
        schema_names: &["foxglove.PoseInFrame"],
        canonical: false,
        meaning: "display copy of /estimate/pose for Foxglove's 3D panel (frame world)",
    },
    ChannelSpec {
        topic: "/viz/ground_truth_tx",
        schema_names: &["foxglove.PoseInFrame"],
        canonical: false,
        meaning: "display copy of /ground_truth/tx for Foxglove's 3D panel (frame world)",
    },
    ChannelSpec {
        topic: "/viz/ground_truth_rx",
        schema_names: &["foxglove.PoseInFrame"],
        canonical: false,
        meaning: "display copy of /ground_truth/rx for Foxglove's 3D panel (frame world)",
    },
    ChannelSpec {
        topic: GNSS_VIZ_TOPIC,
        schema_names: &["foxglove.LocationFix"],
        canonical: false,
        meaning: "display copy of /gnss/fix for Foxglove's map panel",
    },
    ChannelSpec {
        topic: GNSS_ARRAY_VIZ_TOPIC,
        schema_names: &["foxglove.LocationFix"],
        canonical: false,
        meaning: "display copy of /gnss/array for Foxglove's map panel",
    },
];
