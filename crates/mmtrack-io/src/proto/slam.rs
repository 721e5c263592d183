//! The messages of 5G mmWave SLAM recordings (Kim et al. 2018): the path
//! measurements of each epoch, the simulator's UE state and path origins,
//! and the sources of the paths.

use prost::Message;

use super::{Cardinality, MessageSpec, ProtoType, SpecMessage, field};

use Cardinality::{One, Repeated};
use ProtoType::{Double, Int64, String as Str, Uint32};

/// The path measurements of one epoch (`mmtrack.PathMeasurements`).
#[derive(Clone, PartialEq, Message)]
pub struct PathMeasurements {
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(double, repeated, tag = "2")]
    pub toa_m: Vec<f64>,
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(double, repeated, tag = "3")]
    pub doa_az_rad: Vec<f64>,
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(double, repeated, tag = "4")]
    pub doa_el_rad: Vec<f64>,
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(double, repeated, tag = "5")]
    pub dod_az_rad: Vec<f64>,
    /// See [`PATH_MEASUREMENTS_SPEC`].
    #[prost(double, repeated, tag = "6")]
    pub dod_el_rad: Vec<f64>,
}

/// Schema of [`PathMeasurements`].
pub const PATH_MEASUREMENTS_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.PathMeasurements",
    description: "The propagation paths a 5G mmWave UE estimated in one epoch from the base station's downlink \
(Kim et al. 2018, eq. (2)): an unordered set, path i is index i of every list; all lists have the same length, \
possibly 0 (an epoch without paths).",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "epoch time (the recording metadata says what it counts from)"),
        field(
            "toa_m",
            2,
            Double,
            Repeated,
            "m",
            "time of arrival times the speed of light, clock bias included, per path",
        ),
        field(
            "doa_az_rad",
            3,
            Double,
            Repeated,
            "rad",
            "direction of arrival, azimuth in the UE frame (world azimuth minus heading), per path",
        ),
        field("doa_el_rad", 4, Double, Repeated, "rad", "direction of arrival, elevation in [-pi/2, pi/2], per path"),
        field(
            "dod_az_rad",
            5,
            Double,
            Repeated,
            "rad",
            "direction of departure at the base station, azimuth in the world frame, per path",
        ),
        field("dod_el_rad", 6, Double, Repeated, "rad", "direction of departure, elevation in [-pi/2, pi/2], per path"),
    ],
};

impl SpecMessage for PathMeasurements {
    const SPEC: &'static MessageSpec = &PATH_MEASUREMENTS_SPEC;
}

/// The true UE state of one epoch and the origin of each measured path
/// (`mmtrack.SlamUeTruth`).
#[derive(Clone, PartialEq, Message)]
pub struct SlamUeTruth {
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "2")]
    pub x_m: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "3")]
    pub y_m: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "4")]
    pub z_m: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "5")]
    pub heading_rad: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "6")]
    pub speed_mps: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "7")]
    pub turn_rate_radps: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(double, required, tag = "8")]
    pub clock_bias_m: f64,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(string, repeated, tag = "9")]
    pub path_source: Vec<String>,
    /// See [`SLAM_UE_TRUTH_SPEC`].
    #[prost(uint32, repeated, tag = "10")]
    pub path_source_index: Vec<u32>,
}

/// Schema of [`SlamUeTruth`].
pub const SLAM_UE_TRUTH_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.SlamUeTruth",
    description: "Simulator ground truth of one 5G mmWave SLAM epoch: the UE state of the constant turn-rate velocity \
model (Kim et al. 2018, Sec. II-A) and where each path of the /slam/paths message of the same t_ns came from (path i \
is index i of path_source and path_source_index).",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "epoch time, equal to the t_ns of its /slam/paths message"),
        field("x_m", 2, Double, One, "m", "UE position x, world frame"),
        field("y_m", 3, Double, One, "m", "UE position y, world frame"),
        field("z_m", 4, Double, One, "m", "UE position z (height), world frame"),
        field("heading_rad", 5, Double, One, "rad", "UE heading, counter-clockwise from world x"),
        field("speed_mps", 6, Double, One, "m/s", "UE longitudinal speed"),
        field("turn_rate_radps", 7, Double, One, "rad/s", "UE turn rate"),
        field("clock_bias_m", 8, Double, One, "m", "UE clock bias times the speed of light"),
        field(
            "path_source",
            9,
            Str,
            Repeated,
            "",
            "type of each path's source: bs (line of sight), va (reflection off the wall of a virtual anchor), sp \
(scattering point) or clutter (no physical source)",
        ),
        field(
            "path_source_index",
            10,
            Uint32,
            Repeated,
            "",
            "index of each path's source among the /slam/sources messages of its type (0 for bs and clutter)",
        ),
    ],
};

impl SpecMessage for SlamUeTruth {
    const SPEC: &'static MessageSpec = &SLAM_UE_TRUTH_SPEC;
}

/// One source of the paths: the base station, a virtual anchor or a
/// scattering point (`mmtrack.SlamSource`).
#[derive(Clone, PartialEq, Message)]
pub struct SlamSource {
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(string, required, tag = "2")]
    pub kind: String,
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(uint32, required, tag = "3")]
    pub index: u32,
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(double, required, tag = "4")]
    pub x_m: f64,
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(double, required, tag = "5")]
    pub y_m: f64,
    /// See [`SLAM_SOURCE_SPEC`].
    #[prost(double, required, tag = "6")]
    pub z_m: f64,
}

/// Schema of [`SlamSource`].
pub const SLAM_SOURCE_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.SlamSource",
    description: "One source of the 5G mmWave paths (Kim et al. 2018, Sec. II): the base station, whose position the \
UE knows, or, as simulator ground truth, a virtual anchor (the base station mirrored in a reflecting wall) or a \
scattering point. The map is static: each source is written once.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "time from which the source is valid (the first epoch)"),
        field(
            "kind",
            2,
            Str,
            One,
            "",
            "bs (base station, known), va (virtual anchor, truth) or sp (scattering point, truth)",
        ),
        field("index", 3, Uint32, One, "", "index among the sources of its kind, 0, 1, ... (the bs is 0)"),
        field("x_m", 4, Double, One, "m", "position x, world frame"),
        field("y_m", 5, Double, One, "m", "position y, world frame"),
        field("z_m", 6, Double, One, "m", "position z (height), world frame"),
    ],
};

impl SpecMessage for SlamSource {
    const SPEC: &'static MessageSpec = &SLAM_SOURCE_SPEC;
}
