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

fn check<M: SpecMessage>(message: &M) {
    let spec = M::SPEC;
    let bytes = message.encode_to_vec();
    let fields = wire_fields(&bytes);
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

#[test]
fn descriptors_match_prost_encoding() {
    check(&proto::Pose2D {
        t_ns: 1,
        parent_frame: "w".into(),
        child_frame: "v".into(),
        x_m: 1.0,
        y_m: 2.0,
        yaw_rad: 3.0,
    });
    check(&proto::GnssFix {
        t_ns: 1,
        latitude_deg: 1.0,
        longitude_deg: 2.0,
        altitude_m: Some(3.0),
        horizontal_sigma_m: Some(0.5),
        num_satellites: Some(3),
        quality: 2,
    });
    check(&proto::RadarScanMeta {
        t_ns: 1,
        range_resolution_m: 0.04,
        range_offset_m: 0.1,
        bins_per_azimuth: 3,
        power_column_offset: 11,
        azimuth_t_ns: vec![1, 2],
        azimuth_rad: vec![0.1, 0.2],
        valid: vec![true, true],
    });
    check(&proto::CirSnapshot {
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
    });
    check(&proto::MpcTruth {
        t_ns: 1,
        set_index: 1,
        snapshot_index: 1,
        path_id: 1,
        delay_s: 1.0,
        amplitude_re: 1.0,
        amplitude_im: 1.0,
        doppler_hz: 1.0,
    });
    check(&proto::BeamSweep {
        t_ns: 1,
        beam_count: 2,
        power_linear: vec![1.0, 2.0],
        measured: vec![true, false],
        codebook: Some("c".into()),
    });
    check(&proto::PathMeasurements {
        t_ns: 1,
        toa_m: vec![1.0],
        doa_az_rad: vec![0.1],
        doa_el_rad: vec![0.2],
        dod_az_rad: vec![0.3],
        dod_el_rad: vec![0.4],
    });
    check(&proto::SlamUeTruth {
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
    });
    check(&proto::SlamSource { t_ns: 1, kind: "va".into(), index: 1, x_m: 1.0, y_m: 2.0, z_m: 3.0 });
    assert_eq!(ALL_SPECS.len(), 9, "a new message needs a sample above");
}
