use super::*;

/// A `.npy` (version 1) with the given header dict and data.
pub(crate) fn npy(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
    let dict = format!(
        "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
        if fortran { "True" } else { "False" }
    );
    let mut header = dict.into_bytes();
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(b' ');
    }
    header.push(b'\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend(header);
    out.extend_from_slice(data);
    out
}

/// A stored (uncompressed) ZIP of `(name, bytes)` members.
pub(crate) fn stored_zip(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let (mut out, mut central) = (Vec::new(), Vec::new());
    for (name, data) in members {
        let offset = out.len() as u32;
        let (crc, len) = (crc32fast::hash(data), data.len() as u32);
        let common = |out: &mut Vec<u8>| {
            out.extend_from_slice(&20u16.to_le_bytes()); // version needed
            out.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0]); // flags, method 0, time, date
            out.extend_from_slice(&crc.to_le_bytes());
            out.extend_from_slice(&len.to_le_bytes());
            out.extend_from_slice(&len.to_le_bytes());
            out.extend_from_slice(&(name.len() as u16).to_le_bytes());
            out.extend_from_slice(&0u16.to_le_bytes()); // extra
        };
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        common(&mut out);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes()); // version made by
        common(&mut central);
        central.extend_from_slice(&[0; 6]); // comment, disk, internal attrs
        central.extend_from_slice(&0u32.to_le_bytes()); // external attrs
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let cd_offset = out.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0, 0, 0, 0]);
    out.extend_from_slice(&(members.len() as u16).to_le_bytes());
    out.extend_from_slice(&(members.len() as u16).to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&cd_offset.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out
}

fn c16(values: &[(f64, f64)]) -> Vec<u8> {
    values.iter().flat_map(|(re, im)| [re.to_le_bytes(), im.to_le_bytes()].concat()).collect()
}

#[test]
fn dtypes_orders_and_versions() {
    let p = Path::new("a.npy");
    let a =
        parse_npy(p, "array", &npy("<c16", false, "(2, 2)", &c16(&[(1.0, -1.0), (2.0, 0.0), (3.0, 0.5), (4.0, 4.0)])))
            .unwrap();
    assert_eq!(a.dims, [2, 2]);
    assert_eq!(a.values[2], Complex64::new(3.0, 0.5));
    assert_eq!(a.strides, [2, 1]);
    let f = parse_npy(p, "array", &npy("<c16", true, "(2, 2)", &c16(&[(1.0, 0.0); 4]))).unwrap();
    assert_eq!(f.strides, [1, 2]);
    let c8: Vec<u8> = [1.5f32, -2.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    assert_eq!(parse_npy(p, "array", &npy("<c8", false, "(1,)", &c8)).unwrap().values, [Complex64::new(1.5, -2.0)]);
    let be: Vec<u8> = [1.5f32, -2.0].iter().flat_map(|v| v.to_be_bytes()).collect();
    assert_eq!(parse_npy(p, "array", &npy(">f4", false, "(1, 2)", &be)).unwrap().values, [Complex64::new(1.5, -2.0)]);
    let i2: Vec<u8> = [3i16, -4, 5, 6].iter().flat_map(|v| v.to_le_bytes()).collect();
    let iq = parse_npy(p, "array", &npy("<i2", false, "(2, 2)", &i2)).unwrap();
    assert_eq!((iq.dims.as_slice(), iq.values[1]), (&[2][..], Complex64::new(5.0, 6.0)));
    // Version 2 header (u32 length).
    let mut v2 = npy("<c16", false, "(1,)", &c16(&[(7.0, 8.0)]));
    let header_len = u16::from_le_bytes([v2[8], v2[9]]);
    v2.splice(6..10, [2u8, 0, 0, 0, 0, 0]);
    v2[8..12].copy_from_slice(&u32::from(header_len).to_le_bytes());
    assert_eq!(parse_npy(p, "array", &v2).unwrap().values, [Complex64::new(7.0, 8.0)]);
}

#[test]
fn bad_npy_is_named() {
    let p = Path::new("bad.npy");
    let err = |bytes: &[u8]| parse_npy(p, "array", bytes).unwrap_err().to_string();
    let e = err(&npy("<i4", false, "(2,)", &[0; 8]));
    assert!(e.starts_with("bad.npy: array: descr: dtype `<i4`, expected complex64"), "{e}");
    let e = err(&npy("|O", false, "(2,)", &[0; 16]));
    assert!(e.contains("dtype `|O`"), "{e}");
    let e = err(&npy("<f8", false, "(3,)", &[0; 24]));
    assert!(e.contains("trailing I/Q axis of size 2"), "{e}");
    let good = npy("<c16", false, "(2, 3)", &c16(&[(1.0, 1.0); 6]));
    let e = err(&good[..good.len() - 1]);
    assert!(e.contains("data: truncated: shape [2, 3] of `<c16` needs 96 bytes of data, the file has 95"), "{e}");
    assert!(err(b"PK\x03\x04").contains("magic"));
    assert!(err(&npy("<c16", false, "(2, x)", &[])).contains("shape: `(2, x)`"));
    // Every truncation and byte flip: an error or an array, never a panic.
    for cut in 0..good.len() {
        assert!(parse_npy(p, "array", &good[..cut]).is_err(), "cut {cut}");
    }
    for at in 0..good.len() {
        let mut b = good.clone();
        b[at] ^= 0xa5;
        let _ = parse_npy(p, "array", &b);
    }
}

#[test]
fn npz_members() {
    let p = Path::new("a.npz");
    let h = npy("<c16", false, "(3,)", &c16(&[(1.0, 2.0), (3.0, 4.0), (5.0, 6.0)]));
    let g = npy("<c8", false, "(0,)", &[]);
    let zip = stored_zip(&[("h.npy", h.clone()), ("g.npy", g)]);
    let (name, a) = parse_npz(p, &zip, Some("h")).unwrap();
    assert_eq!((name.as_str(), a.values[2]), ("h", Complex64::new(5.0, 6.0)));
    let e = parse_npz(p, &zip, None).unwrap_err().to_string();
    assert!(e.contains("holds [\"h\", \"g\"]; choose one with `variable"), "{e}");
    let e = parse_npz(p, &zip, Some("x")).unwrap_err().to_string();
    assert!(e.contains("no array `x`"), "{e}");
    let single = stored_zip(&[("h.npy", h)]);
    assert_eq!(parse_npz(p, &single, None).unwrap().0, "h");
    // A flipped data byte fails the CRC; truncations fail cleanly.
    let mut flipped = single.clone();
    flipped[200] ^= 1;
    let e = parse_npz(p, &flipped, None).unwrap_err().to_string();
    assert!(e.contains("member `h.npy`: ZIP member: CRC-32"), "{e}");
    for cut in 0..single.len() {
        assert!(parse_npz(p, &single[..cut], None).is_err(), "cut {cut}");
    }
}

/// Found by fuzzing (the npy target was killed at 24 GB of memory): a small
/// npz could declare and inflate to 4 GiB, which cut into one-tap snapshots
/// takes about 35 times as much. A member may inflate to 16 MiB plus 100
/// times its compressed size.
#[test]
fn npz_decompression_bomb_is_refused() {
    let p = Path::new("a.npz");
    // `data` as a deflated member (stored DEFLATE blocks) declaring `declared` bytes.
    let deflated_zip = |data: &[u8], declared: u32| {
        let mut stream = vec![1];
        stream.extend_from_slice(&(data.len() as u16).to_le_bytes());
        stream.extend_from_slice(&(!(data.len() as u16)).to_le_bytes());
        stream.extend_from_slice(data);
        let mut zip = stored_zip(&[("h.npy", stream)]);
        let directory = u32::from_le_bytes(zip[zip.len() - 6..zip.len() - 2].try_into().unwrap()) as usize;
        zip[directory + 10..directory + 12].copy_from_slice(&8u16.to_le_bytes());
        zip[directory + 16..directory + 20].copy_from_slice(&crc32fast::hash(data).to_le_bytes());
        zip[directory + 24..directory + 28].copy_from_slice(&declared.to_le_bytes());
        zip
    };
    let h = npy("<c16", false, "(3,)", &c16(&[(1.0, 2.0), (3.0, 4.0), (5.0, 6.0)]));
    let (_, a) = parse_npz(p, &deflated_zip(&h, h.len() as u32), None).unwrap();
    assert_eq!(a.values[2], Complex64::new(5.0, 6.0));
    // Declaring 200 MB from a few hundred bytes: refused before inflating.
    let e = parse_npz(p, &deflated_zip(&h, 200_000_000), None).unwrap_err().to_string();
    let compressed = h.len() + 5;
    assert!(
        e.contains(&format!("200000000 bytes when inflated from {compressed} compressed bytes: more than 100 times")),
        "{e}"
    );
}

/// The bound holds while inflating, not only on what the directory
/// declares: a member declaring a plausible size whose stream (32 MiB of
/// zeros, really deflated) inflates past it is refused once the output
/// reaches the declared size, naming the file, the member and the field.
#[test]
fn npz_member_inflating_past_its_declared_size_is_refused() {
    let p = Path::new("bomb.npz");
    let zeros = vec![0u8; 32 << 20];
    let stream = miniz_oxide::deflate::compress_to_vec(&zeros, 6);
    let declared = 1_000_000u32;
    let mut zip = stored_zip(&[("h.npy", stream.clone())]);
    let directory = u32::from_le_bytes(zip[zip.len() - 6..zip.len() - 2].try_into().unwrap()) as usize;
    zip[directory + 10..directory + 12].copy_from_slice(&8u16.to_le_bytes());
    zip[directory + 16..directory + 20].copy_from_slice(&crc32fast::hash(&zeros).to_le_bytes());
    zip[directory + 24..directory + 28].copy_from_slice(&declared.to_le_bytes());
    let e = parse_npz(p, &zip, None).unwrap_err().to_string();
    assert!(
        e.starts_with("bomb.npz: member `h.npy`: ZIP member: ")
            && e.contains("decompresses to more than 1000000 bytes"),
        "{e}"
    );
    // Declaring the true size, the member is refused before inflating.
    zip[directory + 24..directory + 28].copy_from_slice(&(zeros.len() as u32).to_le_bytes());
    let e = parse_npz(p, &zip, None).unwrap_err().to_string();
    let expected =
        format!("{} bytes when inflated from {} compressed bytes: more than 100 times", zeros.len(), stream.len());
    assert!(e.starts_with("bomb.npz: member `h.npy`: ZIP member: ") && e.contains(&expected), "{e}");
}

/// Before: a 3-D array without `axes` was reported as "252 CIR snapshots"
/// although it is read as 252 RX antennas at one time ([rx, tx, tap], the
/// module's default); the report now says which.
#[test]
fn a_3d_array_without_axes_is_reported_as_antennas_at_one_time() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("uwb-3d.npy");
    std::fs::write(&input, npy("<c16", false, "(252, 1, 4)", &c16(&[(1.0, 0.0); 252 * 4]))).unwrap();
    let sidecar = dir.path().join("uwb.toml");
    std::fs::write(&sidecar, "carrier_hz = 3.9936e9\ntap_spacing_s = 1.0016e-9\n").unwrap();
    let out = dir.path().join("c.mcap");
    let report = crate::cir::ingest_cir(
        crate::cir::CirFormat::Npy,
        &input,
        Some(&sidecar),
        &out,
        &Default::default(),
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!((report.snapshots, report.times_tx_rx), (252, (1, 1, 252)));
}
