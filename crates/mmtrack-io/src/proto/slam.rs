//! The messages of 5G mmWave SLAM recordings (Kim et al. 2018): the path
//! measurements of each epoch, the simulator's UE state and path origins,
//! and the sources of the paths.

use super::{Cardinality, FieldSpec, MessageSpec, ProtoType, SpecMessage};

define_message! {
    /// The path measurements of one epoch (`mmtrack.PathMeasurements`).
    PathMeasurements as "mmtrack.PathMeasurements", spec PATH_MEASUREMENTS_SPEC:
    "The propagation paths a 5G mmWave UE estimated in one epoch from the base station's downlink \
(Kim et al. 2018, eq. (2)): an unordered set, path i is index i of every list; all lists have the same length, \
possibly 0 (an epoch without paths).";
    required int64 t_ns = 1, "ns", "epoch time (the recording metadata says what it counts from)";
    repeated double toa_m = 2, "m", "time of arrival times the speed of light, clock bias included, per path";
    repeated double doa_az_rad = 3, "rad",
        "direction of arrival, azimuth in the UE frame (world azimuth minus heading), per path";
    repeated double doa_el_rad = 4, "rad", "direction of arrival, elevation in [-pi/2, pi/2], per path";
    repeated double dod_az_rad = 5, "rad",
        "direction of departure at the base station, azimuth in the world frame, per path";
    repeated double dod_el_rad = 6, "rad", "direction of departure, elevation in [-pi/2, pi/2], per path";
}

define_message! {
    /// The true UE state of one epoch and the origin of each measured path
    /// (`mmtrack.SlamUeTruth`).
    SlamUeTruth as "mmtrack.SlamUeTruth", spec SLAM_UE_TRUTH_SPEC:
    "Simulator ground truth of one 5G mmWave SLAM epoch: the UE state of the constant turn-rate velocity \
model (Kim et al. 2018, Sec. II-A) and where each path of the /slam/paths message of the same t_ns came from (path i \
is index i of path_source and path_source_index).";
    required int64 t_ns = 1, "ns", "epoch time, equal to the t_ns of its /slam/paths message";
    required double x_m = 2, "m", "UE position x, world frame";
    required double y_m = 3, "m", "UE position y, world frame";
    required double z_m = 4, "m", "UE position z (height), world frame";
    required double heading_rad = 5, "rad", "UE heading, counter-clockwise from world x";
    required double speed_mps = 6, "m/s", "UE longitudinal speed";
    required double turn_rate_radps = 7, "rad/s", "UE turn rate";
    required double clock_bias_m = 8, "m", "UE clock bias times the speed of light";
    repeated string path_source = 9, "",
        "type of each path's source: bs (line of sight), va (reflection off the wall of a virtual anchor), sp \
(scattering point) or clutter (no physical source)";
    repeated uint32 path_source_index = 10, "",
        "index of each path's source among the /slam/sources messages of its type (0 for bs and clutter)";
}

define_message! {
    /// One source of the paths: the base station, a virtual anchor or a
    /// scattering point (`mmtrack.SlamSource`).
    SlamSource as "mmtrack.SlamSource", spec SLAM_SOURCE_SPEC:
    "One source of the 5G mmWave paths (Kim et al. 2018, Sec. II): the base station, whose position the \
UE knows, or, as simulator ground truth, a virtual anchor (the base station mirrored in a reflecting wall) or a \
scattering point. The map is static: each source is written once.";
    required int64 t_ns = 1, "ns", "time from which the source is valid (the first epoch)";
    required string kind = 2, "",
        "bs (base station, known), va (virtual anchor, truth) or sp (scattering point, truth)";
    required uint32 index = 3, "", "index among the sources of its kind, 0, 1, ... (the bs is 0)";
    required double x_m = 4, "m", "position x, world frame";
    required double y_m = 5, "m", "position y, world frame";
    required double z_m = 6, "m", "position z (height), world frame";
}
