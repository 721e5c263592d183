//! mmtrack's own MCAP message schemas (`mmtrack.*`), encoded as protobuf.
//!
//! Each message is a prost struct plus a [`MessageSpec`]: the spec is the one
//! source for the protobuf descriptor embedded in the recording (so any MCAP
//! tool with protobuf support, e.g. Foxglove or Python `mcap-protobuf-support`,
//! decodes the messages) and for the documents in `schemas/`. A test decodes
//! prost-encoded messages through the descriptor to keep the two in step.
//!
//! We build the descriptor in code rather than with `protoc` so that a fresh
//! machine needs nothing beyond the Rust toolchain.

mod slam;

use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FieldOptions, FileDescriptorProto, FileDescriptorSet};

/// Protobuf scalar types used by mmtrack messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProtoType {
    /// `int64`
    Int64,
    /// `uint64`
    Uint64,
    /// `uint32`
    Uint32,
    /// `double`
    Double,
    /// `bool`
    Bool,
    /// `string`
    String,
}

impl ProtoType {
    fn descriptor_type(self) -> Type {
        match self {
            Self::Int64 => Type::Int64,
            Self::Uint64 => Type::Uint64,
            Self::Uint32 => Type::Uint32,
            Self::Double => Type::Double,
            Self::Bool => Type::Bool,
            Self::String => Type::String,
        }
    }

    /// The type's name in `.proto` syntax.
    #[must_use]
    pub fn proto_name(self) -> &'static str {
        match self {
            Self::Int64 => "int64",
            Self::Uint64 => "uint64",
            Self::Uint32 => "uint32",
            Self::Double => "double",
            Self::Bool => "bool",
            Self::String => "string",
        }
    }
}

/// How many values a field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cardinality {
    /// Exactly one (proto2 `required`: always written, so `-0.0` survives;
    /// proto3's implicit presence would drop it as a default value).
    One,
    /// Zero or one, with presence (proto2 `optional`).
    Optional,
    /// Any number (packed).
    Repeated,
}

/// One field of a message: wire layout plus its documentation.
#[derive(Debug, Clone, Copy)]
pub struct FieldSpec {
    /// Field name (units in the name).
    pub name: &'static str,
    /// Protobuf field number.
    pub number: i32,
    /// Scalar type.
    pub ty: ProtoType,
    /// Cardinality.
    pub cardinality: Cardinality,
    /// Unit, or "" for unitless.
    pub unit: &'static str,
    /// Meaning, one sentence.
    pub meaning: &'static str,
}

/// A message schema: its fully qualified name, description and fields.
#[derive(Debug, Clone, Copy)]
pub struct MessageSpec {
    /// Package-qualified name, e.g. `mmtrack.Pose2D`; also the MCAP schema name.
    pub full_name: &'static str,
    /// What one message means.
    pub description: &'static str,
    /// Fields in field-number order.
    pub fields: &'static [FieldSpec],
}

impl MessageSpec {
    fn package_and_name(&self) -> (&'static str, &'static str) {
        self.full_name.rsplit_once('.').unwrap_or(("", self.full_name))
    }

    /// The serialized `FileDescriptorSet` that MCAP's protobuf profile expects
    /// as schema data.
    #[must_use]
    pub fn file_descriptor_set(&self) -> Vec<u8> {
        let (package, name) = self.package_and_name();
        let fields = self
            .fields
            .iter()
            .map(|f| {
                let packed = f.cardinality == Cardinality::Repeated && f.ty != ProtoType::String;
                FieldDescriptorProto {
                    name: Some(f.name.to_string()),
                    number: Some(f.number),
                    label: Some(match f.cardinality {
                        Cardinality::One => Label::Required,
                        Cardinality::Optional => Label::Optional,
                        Cardinality::Repeated => Label::Repeated,
                    } as i32),
                    r#type: Some(f.ty.descriptor_type() as i32),
                    json_name: Some(f.name.to_string()),
                    options: packed.then(|| FieldOptions { packed: Some(true), ..Default::default() }),
                    ..Default::default()
                }
            })
            .collect();
        let file = FileDescriptorProto {
            name: Some(format!("{}.proto", self.full_name.replace('.', "/"))),
            package: Some(package.to_string()),
            message_type: vec![DescriptorProto { name: Some(name.to_string()), field: fields, ..Default::default() }],
            syntax: Some("proto2".to_string()),
            ..Default::default()
        };
        FileDescriptorSet { file: vec![file] }.encode_to_vec()
    }

    /// The message in `.proto` syntax, with units and meanings as comments.
    #[must_use]
    pub fn proto_text(&self) -> String {
        let (package, name) = self.package_and_name();
        let mut out =
            format!("syntax = \"proto2\";\npackage {package};\n\n// {}\nmessage {name} {{\n", self.description);
        for f in self.fields {
            let (label, options) = match f.cardinality {
                Cardinality::One => ("required", ""),
                Cardinality::Optional => ("optional", ""),
                Cardinality::Repeated => ("repeated", " [packed = true]"),
            };
            let unit = if f.unit.is_empty() { String::new() } else { format!(" [{}]", f.unit) };
            out.push_str(&format!(
                "  // {}{unit}\n  {label} {} {} = {}{options};\n",
                f.meaning,
                f.ty.proto_name(),
                f.name,
                f.number
            ));
        }
        out.push_str("}\n");
        out
    }
}

/// A prost message with a documented mmtrack schema.
pub trait SpecMessage: Message + Default {
    /// The schema.
    const SPEC: &'static MessageSpec;
}

const fn field(
    name: &'static str,
    number: i32,
    ty: ProtoType,
    cardinality: Cardinality,
    unit: &'static str,
    meaning: &'static str,
) -> FieldSpec {
    FieldSpec { name, number, ty, cardinality, unit, meaning }
}

use Cardinality::{One, Optional, Repeated};
use ProtoType::{Bool, Double, Int64, String as Str, Uint32, Uint64};

/// A planar pose `parent_from_child` at a time (`mmtrack.Pose2D`).
#[derive(Clone, PartialEq, Message)]
pub struct Pose2D {
    /// See [`POSE2D_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`POSE2D_SPEC`].
    #[prost(string, required, tag = "2")]
    pub parent_frame: String,
    /// See [`POSE2D_SPEC`].
    #[prost(string, required, tag = "3")]
    pub child_frame: String,
    /// See [`POSE2D_SPEC`].
    #[prost(double, required, tag = "4")]
    pub x_m: f64,
    /// See [`POSE2D_SPEC`].
    #[prost(double, required, tag = "5")]
    pub y_m: f64,
    /// See [`POSE2D_SPEC`].
    #[prost(double, required, tag = "6")]
    pub yaw_rad: f64,
}

/// Schema of [`Pose2D`].
pub const POSE2D_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.Pose2D",
    description: "A planar rigid transform parent_from_child (SE(2)) valid at t_ns: p_parent = R(yaw) p_child + (x, y).",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "time of validity, nanoseconds since the UNIX epoch (or scenario start)"),
        field("parent_frame", 2, Str, One, "", "frame the pose is expressed in, e.g. world"),
        field("child_frame", 3, Str, One, "", "frame being located, e.g. vehicle or radar"),
        field("x_m", 4, Double, One, "m", "translation along the parent x axis"),
        field("y_m", 5, Double, One, "m", "translation along the parent y axis"),
        field("yaw_rad", 6, Double, One, "rad", "rotation about z, counter-clockwise positive"),
    ],
};

impl SpecMessage for Pose2D {
    const SPEC: &'static MessageSpec = &POSE2D_SPEC;
}

/// A GNSS position fix (`mmtrack.GnssFix`).
#[derive(Clone, PartialEq, Message)]
pub struct GnssFix {
    /// See [`GNSS_FIX_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(double, required, tag = "2")]
    pub latitude_deg: f64,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(double, required, tag = "3")]
    pub longitude_deg: f64,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(double, optional, tag = "4")]
    pub altitude_m: Option<f64>,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(double, optional, tag = "5")]
    pub horizontal_sigma_m: Option<f64>,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(uint32, optional, tag = "6")]
    pub num_satellites: Option<u32>,
    /// See [`GNSS_FIX_SPEC`].
    #[prost(uint32, required, tag = "7")]
    pub quality: u32,
}

/// Schema of [`GnssFix`].
pub const GNSS_FIX_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.GnssFix",
    description: "One WGS-84 GNSS position fix.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "fix time, nanoseconds since the UNIX epoch"),
        field("latitude_deg", 2, Double, One, "deg", "geodetic latitude, north positive"),
        field("longitude_deg", 3, Double, One, "deg", "geodetic longitude, east positive"),
        field(
            "altitude_m",
            4,
            Double,
            Optional,
            "m",
            "height (datum in the recording metadata key gnss.altitude_datum), absent when the source gives none",
        ),
        field(
            "horizontal_sigma_m",
            5,
            Double,
            Optional,
            "m",
            "1-sigma horizontal uncertainty, absent when the source gives none",
        ),
        field("num_satellites", 6, Uint32, Optional, "", "satellites used, absent when not reported"),
        field(
            "quality",
            7,
            Uint32,
            One,
            "",
            "fix quality: 0 unknown, 1 no fix, 2 autonomous, 3 differential, 4 RTK fixed, 5 RTK float, 6 dead reckoning",
        ),
    ],
};

impl SpecMessage for GnssFix {
    const SPEC: &'static MessageSpec = &GNSS_FIX_SPEC;
}

/// Per-azimuth timing and geometry of one radar scan (`mmtrack.RadarScanMeta`).
#[derive(Clone, PartialEq, Message)]
pub struct RadarScanMeta {
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(double, required, tag = "2")]
    pub range_resolution_m: f64,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(double, required, tag = "3")]
    pub range_offset_m: f64,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(uint32, required, tag = "4")]
    pub bins_per_azimuth: u32,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(uint32, required, tag = "5")]
    pub power_column_offset: u32,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(int64, repeated, tag = "6")]
    pub azimuth_t_ns: Vec<i64>,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(double, repeated, tag = "7")]
    pub azimuth_rad: Vec<f64>,
    /// See [`RADAR_SCAN_META_SPEC`].
    #[prost(bool, repeated, tag = "8")]
    pub valid: Vec<bool>,
}

/// Schema of [`RadarScanMeta`].
pub const RADAR_SCAN_META_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.RadarScanMeta",
    description: "Timing and geometry of one polar radar scan; the power image with the same MCAP sequence number on /radar/image holds the bins.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "scan timestamp as the dataset stamps it"),
        field("range_resolution_m", 2, Double, One, "m", "range bin size"),
        field("range_offset_m", 3, Double, One, "m", "range of bin 0"),
        field("bins_per_azimuth", 4, Uint32, One, "", "range bins per azimuth row"),
        field(
            "power_column_offset",
            5,
            Uint32,
            One,
            "",
            "image columns before bin 0 (11 for Oxford/Boreas PNGs carried unchanged, whose rows start with a timestamp/encoder header; 0 otherwise)",
        ),
        field("azimuth_t_ns", 6, Int64, Repeated, "ns", "measurement time of each azimuth row"),
        field(
            "azimuth_rad",
            7,
            Double,
            Repeated,
            "rad",
            "angle of each azimuth row, [0, 2 pi), as the sensor reports it",
        ),
        field("valid", 8, Bool, Repeated, "", "false where the sensor flagged a row invalid"),
    ],
};

impl SpecMessage for RadarScanMeta {
    const SPEC: &'static MessageSpec = &RADAR_SCAN_META_SPEC;
}

/// One channel impulse response (`mmtrack.CirSnapshot`).
#[derive(Clone, PartialEq, Message)]
pub struct CirSnapshot {
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(uint64, required, tag = "2")]
    pub set_index: u64,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(uint32, required, tag = "3")]
    pub snapshot_index: u32,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(uint32, required, tag = "4")]
    pub tx_antenna: u32,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(uint32, required, tag = "5")]
    pub rx_antenna: u32,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, required, tag = "6")]
    pub carrier_hz: f64,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, required, tag = "7")]
    pub tap_spacing_s: f64,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, required, tag = "8")]
    pub delay_offset_s: f64,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, repeated, tag = "9")]
    pub taps_re: Vec<f64>,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, repeated, tag = "10")]
    pub taps_im: Vec<f64>,
    /// See [`CIR_SNAPSHOT_SPEC`].
    #[prost(double, optional, tag = "11")]
    pub first_path_hint_s: Option<f64>,
}

/// Schema of [`CirSnapshot`].
pub const CIR_SNAPSHOT_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.CirSnapshot",
    description: "One channel impulse response; tap k is at delay delay_offset_s + k * tap_spacing_s.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "measurement time"),
        field("set_index", 2, Uint64, One, "", "index of the sounder's set of snapshots"),
        field("snapshot_index", 3, Uint32, One, "", "index of the snapshot within its set"),
        field("tx_antenna", 4, Uint32, One, "", "transmit antenna index (0 for SISO)"),
        field("rx_antenna", 5, Uint32, One, "", "receive antenna index (0 for SISO)"),
        field("carrier_hz", 6, Double, One, "Hz", "carrier frequency (0 = baseband)"),
        field("tap_spacing_s", 7, Double, One, "s", "delay between consecutive taps"),
        field("delay_offset_s", 8, Double, One, "s", "delay of tap 0"),
        field("taps_re", 9, Double, Repeated, "", "real parts of the complex taps (sounder's linear scale)"),
        field("taps_im", 10, Double, Repeated, "", "imaginary parts of the complex taps, same length as taps_re"),
        field(
            "first_path_hint_s",
            11,
            Double,
            Optional,
            "s",
            "the receiver's own first-path (leading-edge) estimate on the taps' delay axis, e.g. DW1000 HLP; absent when the source gives none",
        ),
    ],
};

impl SpecMessage for CirSnapshot {
    const SPEC: &'static MessageSpec = &CIR_SNAPSHOT_SPEC;
}

/// One true multipath component of one CIR snapshot, as a simulator knows it
/// (`mmtrack.MpcTruth`).
#[derive(Clone, PartialEq, Message)]
pub struct MpcTruth {
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(uint64, required, tag = "2")]
    pub set_index: u64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(uint32, required, tag = "3")]
    pub snapshot_index: u32,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(uint64, required, tag = "4")]
    pub path_id: u64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(double, required, tag = "5")]
    pub delay_s: f64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(double, required, tag = "6")]
    pub amplitude_re: f64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(double, required, tag = "7")]
    pub amplitude_im: f64,
    /// See [`MPC_TRUTH_SPEC`].
    #[prost(double, required, tag = "8")]
    pub doppler_hz: f64,
}

/// Schema of [`MpcTruth`].
pub const MPC_TRUTH_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.MpcTruth",
    description: "One true multipath component (MPC) of the CIR snapshot with the same t_ns, set_index and snapshot_index on /channel/cir (simulator ground truth); power in dB is 20 log10 |amplitude|.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "time of the snapshot"),
        field("set_index", 2, Uint64, One, "", "set of the snapshot"),
        field("snapshot_index", 3, Uint32, One, "", "snapshot within its set"),
        field(
            "path_id",
            4,
            Uint64,
            One,
            "",
            "propagation path, stable while the path exists (the simulator documents its numbering, e.g. 0 = LOS)",
        ),
        field(
            "delay_s",
            5,
            Double,
            One,
            "s",
            "true propagation delay on the CIR's delay axis (tap k at delay_offset_s + k * tap_spacing_s)",
        ),
        field("amplitude_re", 6, Double, One, "", "real part of the true complex amplitude (the taps' linear scale)"),
        field("amplitude_im", 7, Double, One, "", "imaginary part of the true complex amplitude"),
        field("doppler_hz", 8, Double, One, "Hz", "true Doppler shift, -carrier_hz * d(delay_s)/dt"),
    ],
};

impl SpecMessage for MpcTruth {
    const SPEC: &'static MessageSpec = &MPC_TRUTH_SPEC;
}

/// One sweep of a measured beam codebook (`mmtrack.BeamSweep`).
#[derive(Clone, PartialEq, Message)]
pub struct BeamSweep {
    /// See [`BEAM_SWEEP_SPEC`].
    #[prost(int64, required, tag = "1")]
    pub t_ns: i64,
    /// See [`BEAM_SWEEP_SPEC`].
    #[prost(uint32, required, tag = "2")]
    pub beam_count: u32,
    /// See [`BEAM_SWEEP_SPEC`].
    #[prost(double, repeated, tag = "3")]
    pub power_linear: Vec<f64>,
    /// See [`BEAM_SWEEP_SPEC`].
    #[prost(bool, repeated, tag = "4")]
    pub measured: Vec<bool>,
    /// See [`BEAM_SWEEP_SPEC`].
    #[prost(string, optional, tag = "5")]
    pub codebook: Option<String>,
}

/// Schema of [`BeamSweep`].
pub const BEAM_SWEEP_SPEC: MessageSpec = MessageSpec {
    full_name: "mmtrack.BeamSweep",
    description: "One sweep of a measured beam codebook (e.g. a roadside 60 GHz phased array's 64 beams): the received \
power of each beam that was measured, in codebook order.",
    fields: &[
        field("t_ns", 1, Int64, One, "ns", "sweep time (the recording metadata says what it counts from)"),
        field(
            "beam_count",
            2,
            Uint32,
            One,
            "",
            "beams of the codebook, at least one; power_linear and measured have this length",
        ),
        field(
            "power_linear",
            3,
            Double,
            Repeated,
            "",
            "received power of each beam, linear, on the source's scale (e.g. normalised); finite and >= 0; 0 for a beam not measured",
        ),
        field("measured", 4, Bool, Repeated, "", "whether each beam was measured in this sweep; at least one is"),
        field(
            "codebook",
            5,
            Str,
            Optional,
            "",
            "codebook identifier, e.g. deepsense-60ghz-64 (beam index i is the same beam in every sweep of one codebook); absent when the source names none",
        ),
    ],
};

impl SpecMessage for BeamSweep {
    const SPEC: &'static MessageSpec = &BEAM_SWEEP_SPEC;
}

pub use slam::{
    PATH_MEASUREMENTS_SPEC, PathMeasurements, SLAM_SOURCE_SPEC, SLAM_UE_TRUTH_SPEC, SlamSource, SlamUeTruth,
};

/// All mmtrack message schemas, for documentation and tests.
pub const ALL_SPECS: &[&MessageSpec] = &[
    &POSE2D_SPEC,
    &GNSS_FIX_SPEC,
    &RADAR_SCAN_META_SPEC,
    &CIR_SNAPSHOT_SPEC,
    &MPC_TRUTH_SPEC,
    &BEAM_SWEEP_SPEC,
    &PATH_MEASUREMENTS_SPEC,
    &SLAM_UE_TRUTH_SPEC,
    &SLAM_SOURCE_SPEC,
];
