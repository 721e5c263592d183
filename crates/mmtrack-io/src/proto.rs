//! mmtrack's own MCAP message schemas (`mmtrack.*`), encoded as protobuf.
//!
//! Each message is declared once, with `define_message!`: one line per field
//! (label, type, name, number, unit, meaning) gives both the prost struct and
//! its [`MessageSpec`]. The spec is the one source for the protobuf descriptor
//! embedded in the recording (so any MCAP tool with protobuf support, e.g.
//! Foxglove or Python `mcap-protobuf-support`, decodes the messages) and for
//! the documents in `schemas/`. Tests check the descriptors against what prost
//! encodes and pin both byte for byte.
//!
//! We build the descriptor in code rather than with `protoc` so that a fresh
//! machine needs nothing beyond the Rust toolchain.

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

/// Declares one message: the prost struct (each field documented with its
/// meaning and unit), its [`MessageSpec`] constant and the [`SpecMessage`]
/// impl, from one list of fields in field-number order, written as in
/// `.proto` followed by unit (`""` for unitless) and meaning:
///
/// ```text
/// define_message! {
///     /// Rust doc of the struct.
///     Pose2D as "mmtrack.Pose2D", spec POSE2D_SPEC:
///     "What one message means.";
///     required int64 t_ns = 1, "ns", "time of validity";
///     optional double altitude_m = 2, "m", "height, absent when unknown";
///     repeated bool valid = 3, "", "one flag per row";
/// }
/// ```
///
/// `required` is a plain field, `optional` an `Option`, `repeated` a `Vec`
/// (packed on the wire); the types are those of [`ProtoType`].
macro_rules! define_message {
    (
        $(#[$attr:meta])*
        $name:ident as $full_name:literal, spec $spec:ident:
        $description:literal;
        $($label:ident $ty:ident $field:ident = $number:tt, $unit:tt, $meaning:literal;)+
    ) => {
        $(#[$attr])*
        #[derive(Clone, PartialEq, ::prost::Message)]
        pub struct $name {
            $(
                #[doc = proto_field!(doc $meaning, $unit)]
                #[prost($ty, $label, tag = $number)]
                pub $field: proto_field!(rust $label $ty),
            )+
        }

        #[doc = concat!("Schema of [`", stringify!($name), "`].")]
        pub const $spec: MessageSpec = MessageSpec {
            full_name: $full_name,
            description: $description,
            fields: &[$(FieldSpec {
                name: stringify!($field),
                number: $number,
                ty: proto_field!(type $ty),
                cardinality: proto_field!(cardinality $label),
                unit: $unit,
                meaning: $meaning,
            }),+],
        };

        impl SpecMessage for $name {
            const SPEC: &'static MessageSpec = &$spec;
        }
    };
}

/// The parts of one field line of [`define_message!`]: its Rust doc
/// (meaning, then the unit in brackets as in [`MessageSpec::proto_text`]),
/// Rust type, [`ProtoType`] and [`Cardinality`].
macro_rules! proto_field {
    (doc $meaning:literal, "") => { $meaning };
    (doc $meaning:literal, $unit:literal) => { concat!($meaning, " \\[", $unit, "\\]") };
    (rust required $ty:ident) => { proto_field!(scalar $ty) };
    (rust optional $ty:ident) => { Option<proto_field!(scalar $ty)> };
    (rust repeated $ty:ident) => { Vec<proto_field!(scalar $ty)> };
    (scalar int64) => { i64 };
    (scalar uint64) => { u64 };
    (scalar uint32) => { u32 };
    (scalar double) => { f64 };
    (scalar bool) => { bool };
    (scalar string) => { ::std::string::String };
    (type int64) => { ProtoType::Int64 };
    (type uint64) => { ProtoType::Uint64 };
    (type uint32) => { ProtoType::Uint32 };
    (type double) => { ProtoType::Double };
    (type bool) => { ProtoType::Bool };
    (type string) => { ProtoType::String };
    (cardinality required) => { Cardinality::One };
    (cardinality optional) => { Cardinality::Optional };
    (cardinality repeated) => { Cardinality::Repeated };
}

mod slam;

define_message! {
    /// A planar pose `parent_from_child` at a time (`mmtrack.Pose2D`).
    Pose2D as "mmtrack.Pose2D", spec POSE2D_SPEC:
    "A planar rigid transform parent_from_child (SE(2)) valid at t_ns: p_parent = R(yaw) p_child + (x, y).";
    required int64 t_ns = 1, "ns", "time of validity, nanoseconds since the UNIX epoch (or scenario start)";
    required string parent_frame = 2, "", "frame the pose is expressed in, e.g. world";
    required string child_frame = 3, "", "frame being located: base_link (ground truth), estimate, tx or rx, the frame /tf moves";
    required double x_m = 4, "m", "translation along the parent x axis";
    required double y_m = 5, "m", "translation along the parent y axis";
    required double yaw_rad = 6, "rad", "rotation about z, counter-clockwise positive";
}

define_message! {
    /// A GNSS position fix (`mmtrack.GnssFix`).
    GnssFix as "mmtrack.GnssFix", spec GNSS_FIX_SPEC:
    "One WGS-84 GNSS position fix.";
    required int64 t_ns = 1, "ns", "fix time, nanoseconds since the UNIX epoch";
    required double latitude_deg = 2, "deg", "geodetic latitude, north positive";
    required double longitude_deg = 3, "deg", "geodetic longitude, east positive";
    optional double altitude_m = 4, "m",
        "height (datum in the recording metadata key gnss.altitude_datum), absent when the source gives none";
    optional double horizontal_sigma_m = 5, "m", "1-sigma horizontal uncertainty, absent when the source gives none";
    optional uint32 num_satellites = 6, "", "satellites used, absent when not reported";
    required uint32 quality = 7, "",
        "fix quality: 0 unknown, 1 no fix, 2 autonomous, 3 differential, 4 RTK fixed, 5 RTK float, 6 dead reckoning";
}

define_message! {
    /// Per-azimuth timing and geometry of one radar scan (`mmtrack.RadarScanMeta`).
    RadarScanMeta as "mmtrack.RadarScanMeta", spec RADAR_SCAN_META_SPEC:
    "Timing and geometry of one polar radar scan; the power image with the same MCAP sequence number on /radar/image holds the bins.";
    required int64 t_ns = 1, "ns", "scan timestamp as the dataset stamps it";
    required double range_resolution_m = 2, "m", "range bin size";
    required double range_offset_m = 3, "m", "range of bin 0";
    required uint32 bins_per_azimuth = 4, "", "range bins per azimuth row";
    required uint32 power_column_offset = 5, "",
        "image columns before bin 0 (11 for Oxford/Boreas PNGs carried unchanged, whose rows start with a timestamp/encoder header; 0 otherwise)";
    repeated int64 azimuth_t_ns = 6, "ns", "measurement time of each azimuth row";
    repeated double azimuth_rad = 7, "rad", "angle of each azimuth row, [0, 2 pi), as the sensor reports it";
    repeated bool valid = 8, "", "false where the sensor flagged a row invalid";
}

define_message! {
    /// One channel impulse response (`mmtrack.CirSnapshot`).
    CirSnapshot as "mmtrack.CirSnapshot", spec CIR_SNAPSHOT_SPEC:
    "One channel impulse response; tap k is at delay delay_offset_s + k * tap_spacing_s.";
    required int64 t_ns = 1, "ns", "measurement time";
    required uint64 set_index = 2, "", "index of the sounder's set of snapshots";
    required uint32 snapshot_index = 3, "", "index of the snapshot within its set";
    required uint32 tx_antenna = 4, "", "transmit antenna index (0 for SISO)";
    required uint32 rx_antenna = 5, "", "receive antenna index (0 for SISO)";
    required double carrier_hz = 6, "Hz", "carrier frequency (0 = baseband)";
    required double tap_spacing_s = 7, "s", "delay between consecutive taps";
    required double delay_offset_s = 8, "s", "delay of tap 0";
    repeated double taps_re = 9, "", "real parts of the complex taps (sounder's linear scale)";
    repeated double taps_im = 10, "", "imaginary parts of the complex taps, same length as taps_re";
    optional double first_path_hint_s = 11, "s",
        "the receiver's own first-path (leading-edge) estimate on the taps' delay axis, e.g. DW1000 HLP; absent when the source gives none";
}

define_message! {
    /// One true multipath component of one CIR snapshot, as a simulator knows it
    /// (`mmtrack.MpcTruth`).
    MpcTruth as "mmtrack.MpcTruth", spec MPC_TRUTH_SPEC:
    "One true multipath component (MPC) of the CIR snapshot with the same t_ns, set_index and snapshot_index on /channel/cir (simulator ground truth); power in dB is 20 log10 |amplitude|.";
    required int64 t_ns = 1, "ns", "time of the snapshot";
    required uint64 set_index = 2, "", "set of the snapshot";
    required uint32 snapshot_index = 3, "", "snapshot within its set";
    required uint64 path_id = 4, "",
        "propagation path, stable while the path exists (the simulator documents its numbering, e.g. 0 = LOS)";
    required double delay_s = 5, "s",
        "true propagation delay on the CIR's delay axis (tap k at delay_offset_s + k * tap_spacing_s)";
    required double amplitude_re = 6, "", "real part of the true complex amplitude (the taps' linear scale)";
    required double amplitude_im = 7, "", "imaginary part of the true complex amplitude";
    required double doppler_hz = 8, "Hz", "true Doppler shift, -carrier_hz * d(delay_s)/dt";
}

define_message! {
    /// One sweep of a measured beam codebook (`mmtrack.BeamSweep`).
    BeamSweep as "mmtrack.BeamSweep", spec BEAM_SWEEP_SPEC:
    "One sweep of a measured beam codebook (e.g. a roadside 60 GHz phased array's 64 beams): the received \
power of each beam that was measured, in codebook order.";
    required int64 t_ns = 1, "ns", "sweep time (the recording metadata says what it counts from)";
    required uint32 beam_count = 2, "",
        "beams of the codebook, at least one; power_linear and measured have this length";
    repeated double power_linear = 3, "",
        "received power of each beam, linear, on the source's scale (e.g. normalised); finite and >= 0; 0 for a beam not measured";
    repeated bool measured = 4, "", "whether each beam was measured in this sweep; at least one is";
    optional string codebook = 5, "",
        "codebook identifier, e.g. deepsense-60ghz-64 (beam index i is the same beam in every sweep of one codebook); absent when the source names none";
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
