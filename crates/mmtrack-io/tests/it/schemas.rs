//! The documents in `schemas/` are what the code would write, and the protobuf
//! descriptors we embed describe what prost actually encodes.

use std::path::PathBuf;

use mmtrack_io::proto::{self, ALL_SPECS, Cardinality, MessageSpec, ProtoType, SpecMessage};
use prost::Message;
use prost_types::FileDescriptorSet;

fn schemas_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../schemas")
}

#[test]
fn schemas_match_code() {
    let dir = schemas_dir();
    let mut stale = Vec::new();
    for (relative, contents) in mmtrack_io::schema_docs::documents() {
        let path = dir.join(&relative);
        if std::fs::read_to_string(&path).ok().as_deref() != Some(contents.as_str()) {
            stale.push(relative);
        }
    }
    assert!(
        stale.is_empty(),
        "schemas/ differs from the code for {stale:?}; run `cargo run -p mmtrack-cli -- schemas --write schemas` and review the diff"
    );
}

/// Walks the protobuf wire format of `bytes` and returns (field number, wire type).
fn wire_fields(mut bytes: &[u8]) -> Vec<(u32, u8)> {
    let mut out = Vec::new();
    while !bytes.is_empty() {
        let key = prost::encoding::decode_varint(&mut bytes).unwrap();
        let (number, wire) = ((key >> 3) as u32, (key & 7) as u8);
        match wire {
            0 => {
                prost::encoding::decode_varint(&mut bytes).unwrap();
            }
            1 => bytes = &bytes[8..],
            2 => {
                let len = prost::encoding::decode_varint(&mut bytes).unwrap() as usize;
                bytes = &bytes[len..];
            }
            5 => bytes = &bytes[4..],
            other => panic!("unexpected wire type {other}"),
        }
        out.push((number, wire));
    }
    out
}

fn expected_wire(spec: &MessageSpec, number: u32) -> u8 {
    let field = spec
        .fields
        .iter()
        .find(|f| f.number as u32 == number)
        .unwrap_or_else(|| panic!("{}: field {number} not in spec", spec.full_name));
    match (field.cardinality, field.ty) {
        (Cardinality::Repeated, _) | (_, ProtoType::String) => 2,
        (_, ProtoType::Double) => 1,
        _ => 0,
    }
}

/// A sample of `M` with every field set, encoded, with its schema.
fn sample<M: SpecMessage>(message: &M) -> (&'static MessageSpec, Vec<u8>) {
    (M::SPEC, message.encode_to_vec())
}

fn check((spec, bytes): &(&'static MessageSpec, Vec<u8>)) {
    let fields = wire_fields(bytes);
    // Every spec field is present in the sample, so the wire must show all of them.
    let mut numbers: Vec<u32> = fields.iter().map(|f| f.0).collect();
    numbers.dedup();
    assert_eq!(numbers, spec.fields.iter().map(|f| f.number as u32).collect::<Vec<_>>(), "{}", spec.full_name);
    for (number, wire) in fields {
        assert_eq!(wire, expected_wire(spec, number), "{} field {number}", spec.full_name);
    }
    let set = FileDescriptorSet::decode(spec.file_descriptor_set().as_slice()).unwrap();
    let message_type = &set.file[0].message_type[0];
    assert_eq!(format!("{}.{}", set.file[0].package(), message_type.name()), spec.full_name);
    assert_eq!(message_type.field.len(), spec.fields.len());
}

/// One sample of every message, in [`ALL_SPECS`] order.
fn samples() -> Vec<(&'static MessageSpec, Vec<u8>)> {
    let samples = vec![
        sample(&proto::Pose2D {
            t_ns: 1,
            parent_frame: "w".into(),
            child_frame: "v".into(),
            x_m: -0.0,
            y_m: 2.0,
            yaw_rad: 3.0,
        }),
        sample(&proto::GnssFix {
            t_ns: 1,
            latitude_deg: 1.0,
            longitude_deg: 2.0,
            altitude_m: Some(3.0),
            horizontal_sigma_m: Some(0.5),
            num_satellites: Some(3),
            quality: 2,
        }),
        sample(&proto::RadarScanMeta {
            t_ns: 1,
            range_resolution_m: 0.04,
            range_offset_m: 0.1,
            bins_per_azimuth: 3,
            power_column_offset: 11,
            azimuth_t_ns: vec![1, 2],
            azimuth_rad: vec![0.1, 0.2],
            valid: vec![true, true],
        }),
        sample(&proto::CirSnapshot {
            t_ns: 1,
            set_index: 1,
            snapshot_index: 1,
            tx_antenna: 1,
            rx_antenna: 1,
            carrier_hz: 1.0,
            tap_spacing_s: 1.0,
            delay_offset_s: 1.0,
            taps_re: vec![1.0],
            taps_im: vec![1.0],
            first_path_hint_s: Some(1.0),
        }),
        sample(&proto::MpcTruth {
            t_ns: 1,
            set_index: 1,
            snapshot_index: 1,
            path_id: 1,
            delay_s: 1.0,
            amplitude_re: 1.0,
            amplitude_im: 1.0,
            doppler_hz: 1.0,
        }),
        sample(&proto::BeamSweep {
            t_ns: 1,
            beam_count: 2,
            power_linear: vec![1.0, 2.0],
            measured: vec![true, false],
            codebook: Some("c".into()),
        }),
        sample(&proto::PathMeasurements {
            t_ns: 1,
            toa_m: vec![1.0],
            doa_az_rad: vec![0.1],
            doa_el_rad: vec![0.2],
            dod_az_rad: vec![0.3],
            dod_el_rad: vec![0.4],
        }),
        sample(&proto::SlamUeTruth {
            t_ns: 1,
            x_m: 1.0,
            y_m: 2.0,
            z_m: 3.0,
            heading_rad: 0.1,
            speed_mps: 2.0,
            turn_rate_radps: 0.3,
            clock_bias_m: 300.0,
            path_source: vec!["bs".into()],
            path_source_index: vec![0],
        }),
        sample(&proto::SlamSource { t_ns: 1, kind: "va".into(), index: 1, x_m: 1.0, y_m: 2.0, z_m: 3.0 }),
    ];
    assert_eq!(samples.len(), ALL_SPECS.len(), "a new message needs a sample above");
    samples
}

#[test]
fn descriptors_match_prost_encoding() {
    for sample in samples() {
        check(&sample);
    }
}

const PINNED_BYTES: &str = "tests/it/proto_bytes.txt";

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The schema data written into every MCAP recording (the serialized
/// `FileDescriptorSet` of each message) and the encoding of one sample of
/// each message are pinned byte for byte: changing either changes what
/// recordings hold. `MMTRACK_BLESS=1 cargo test -p mmtrack-io` rewrites the
/// file after an intended change.
#[test]
fn descriptor_and_encoding_bytes_are_pinned() {
    let mut text = String::new();
    for (spec, bytes) in samples() {
        text.push_str(&format!("{} descriptor {}\n", spec.full_name, hex(&spec.file_descriptor_set())));
        text.push_str(&format!("{} sample {}\n", spec.full_name, hex(&bytes)));
    }
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(PINNED_BYTES);
    if std::env::var_os("MMTRACK_BLESS").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let pinned = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        pinned == text,
        "{PINNED_BYTES} differs from the code; rerun with MMTRACK_BLESS=1 if the change is intended"
    );
}
