//! Seed corpora: a few records of the real samples in `../shared/realdata`
//! (when present; see its README for sources and licences) and small valid
//! inputs written by [`crate::writers`] and by our own encoders.
//!
//! The CIR targets read a sidecar with the file, so their inputs are
//! `sidecar TOML, NUL, file bytes` (SigMF: `sidecar, NUL, meta JSON, NUL,
//! data`); see [`crate::targets`].

use std::path::{Path, PathBuf};

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader};
use mmtrack_ingest::cir::{MatCirLayout, read_mat_cir};
use mmtrack_ingest::oxford::{NavtechLayout, OXFORD, decode_scan_png, encode_scan_png};
use mmtrack_io::recording::RawReader;

use crate::writers::{CdrWriter, mat_v5, nmea_sentence, npy, zip};

/// Oxford's layout with any number of bins and rows, as Boreas and MulRan
/// read: the layout the small PNG seeds are encoded with and the `png`
/// target's first decode.
pub const ANY_SIZE: NavtechLayout = NavtechLayout { expected_bins: None, expected_azimuths: None, ..OXFORD };

/// The real-data folder: `$MMTRACK_REALDATA`, else `../shared/realdata`
/// beside the workspace; `None` when absent (a user's fresh clone).
#[must_use]
pub fn realdata_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("MMTRACK_REALDATA")
        .map_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata"), PathBuf::from);
    dir.canonicalize().ok().filter(|d| d.is_dir())
}

/// `sidecar`, NUL, `file`: the input of a CIR target.
fn with_sidecar(sidecar: &str, file: &[u8]) -> Vec<u8> {
    let mut out = sidecar.as_bytes().to_vec();
    out.push(0);
    out.extend_from_slice(file);
    out
}

/// The first `max` bytes of a file, cut after the last newline when `lines`.
fn head(path: &Path, max: usize, lines: bool) -> Option<Vec<u8>> {
    let mut bytes = std::fs::read(path).ok()?;
    bytes.truncate(max);
    if lines && let Some(end) = bytes.iter().rposition(|&b| b == b'\n') {
        bytes.truncate(end + 1);
    }
    Some(bytes)
}

/// A scan of `rows` azimuths and `bins` bins with increasing times and angles.
/// Stamp of the seed scans (the real Oxford sample's first scan), ns.
pub const SCAN_T0_NS: i64 = 1_547_131_046_353_776_000;

fn scan(rows: usize, bins: usize) -> PolarScan {
    let azimuths = (0..rows)
        .map(|i| AzimuthSample {
            t_ns: SCAN_T0_NS + i as i64 * 625_000,
            azimuth_rad: i as f64 * std::f64::consts::TAU / 400.0,
            valid: i % 3 != 2,
        })
        .collect();
    let header = PolarScanHeader {
        t_ns: SCAN_T0_NS,
        range_resolution_m: OXFORD.range_resolution_m,
        range_offset_m: 0.0,
        bins_per_azimuth: bins,
        azimuths,
    };
    PolarScan { header, power: (0..rows * bins).map(|k| (k * 37 % 251) as u8).collect() }
}

/// Navtech polar PNGs: small encoded scans; the head of a real Oxford scan
/// (signature, header chunk, the start of the image data); a real scan
/// cropped to a few rows, at full and at reduced width; and the real scan's
/// 400 row headers with the power of its first rows only (a full-size
/// Oxford scan that compresses to a few KiB).
#[must_use]
pub fn png(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let any = ANY_SIZE;
    let mut out: Vec<Vec<u8>> =
        [(4, 16), (2, 1), (8, 40)].iter().filter_map(|&(r, b)| encode_scan_png(&scan(r, b), &any).ok()).collect();
    let Some(dir) = realdata else { return out };
    let Some(first) = std::fs::read_dir(dir.join("oxford-radar-tiny/radar")).ok().and_then(|entries| {
        let mut pngs: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        pngs.sort();
        pngs.into_iter().find(|p| p.extension().is_some_and(|e| e == "png"))
    }) else {
        return out;
    };
    out.extend(head(&first, 4096, false));
    // The file name is the scan's stamp in microseconds (the row times must lie near it).
    let stamp_ns = first.file_stem().and_then(|s| s.to_str()?.parse::<i64>().ok()).map_or(0, |us| us * 1000);
    let Some(real) = std::fs::read(&first).ok().and_then(|b| decode_scan_png(&first, &b, stamp_ns, &OXFORD).ok())
    else {
        return out;
    };
    let real = real.into_scan();
    for (rows, bins) in [(3, real.header.bins_per_azimuth), (6, 64)] {
        let mut header = real.header.clone();
        header.azimuths.truncate(rows);
        header.bins_per_azimuth = bins;
        let power = real.power.chunks_exact(real.header.bins_per_azimuth).take(rows).flat_map(|r| &r[..bins]);
        let cropped = PolarScan { header, power: power.copied().collect() };
        out.extend(encode_scan_png(&cropped, &any).ok());
    }
    let bins = real.header.bins_per_azimuth;
    let mut sparse = real.clone();
    if let Some(rest) = sparse.power.get_mut(4 * bins..) {
        rest.fill(0);
    }
    out.extend(encode_scan_png(&sparse, &OXFORD).ok());
    out
}

/// NMEA logs: the first epochs of the real u-blox drive, and three written
/// epochs (GGA, RMC, GST) across midnight.
#[must_use]
pub fn nmea(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let mut written = String::new();
    for (time, date) in [("235958.00", "311299"), ("235959.00", "311299"), ("000000.00", "010100")] {
        written += &nmea_sentence(&format!("GPGGA,{time},4807.0380,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,"));
        written += &nmea_sentence(&format!("GPRMC,{time},A,4807.0380,N,01131.0000,E,022.4,084.4,{date},003.1,W,A"));
        written += &nmea_sentence(&format!("GPGST,{time},1.0,0.5,0.4,45.0,0.5,0.4,0.8"));
    }
    // GGA + ZDA without RMC, through the leap second of 2016-12-31.
    let mut zda = String::new();
    for (time, date) in [("235959.00", "31,12,2016"), ("235960.00", "31,12,2016"), ("000000.00", "01,01,2017")] {
        zda += &nmea_sentence(&format!("GNGGA,{time},4807.0380,N,01131.0000,E,4,12,0.7,545.4,M,46.9,M,,"));
        zda += &nmea_sentence(&format!("GNZDA,{time},{date},00,00"));
    }
    let mut out = vec![written.into_bytes(), zda.into_bytes()];
    if let Some(dir) = realdata {
        out.extend(head(&dir.join("nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea"), 6000, true));
    }
    out
}

/// ROS 2 CDR messages: the first real `/odom`, `/amcl_pose` and `/tf`
/// messages of the turtlebot bag, and written Odometry, NavSatFix and mono8
/// Image messages.
#[must_use]
pub fn cdr(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let mut odometry = CdrWriter::default();
    odometry.header(1_700_000_000, 5, "odom").string("base_link");
    for v in [1.5, -2.0, 0.0, 0.0, 0.0, 0.38, 0.92] {
        odometry.f64(v);
    }
    for k in 0..36 {
        odometry.f64(if k % 7 == 0 { 0.01 } else { 0.0 });
    }
    let mut fix = CdrWriter::default();
    fix.header(1_700_000_000, 999_999_999, "gps").u8(0).u16(1);
    for v in [48.1173, 11.5167, 545.4, 0.25, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0] {
        fix.f64(v);
    }
    fix.u8(2);
    let pixels: Vec<u8> = (0..4 * 16).map(|k| (k * 13 % 256) as u8).collect();
    let mut image = CdrWriter::default();
    image.header(1_700_000_000, 250_000_000, "radar").u32(4).u32(16).string("mono8").u8(0).u32(16).bytes(&pixels);
    let mut out = vec![odometry.finish(), fix.finish(), image.finish()];
    let Some(dir) = realdata else { return out };
    let Ok(mut reader) = RawReader::open(&dir.join("ros2-mcap/nav2_turtlebot.mcap")) else { return out };
    let mut wanted = vec!["/odom", "/odom", "/amcl_pose", "/tf"];
    while !wanted.is_empty()
        && let Ok(Some(message)) = reader.next_message()
    {
        if let Some(i) = wanted.iter().position(|t| *t == message.channel.topic) {
            wanted.remove(i);
            out.push(message.data.to_vec());
        }
    }
    out
}

/// DecaWave logs: a written log (two 8-tap frames and an `RX E` reception),
/// the real log's first two frames, and the same frames cut to 16 taps
/// (their first paths moved to tap 8.5).
#[must_use]
pub fn decawave(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let frame = |hlp: &str, rc: &str| {
        let mut text = format!(
            "RX OK WInd(0005), HLP({hlp}), PSC(0274), SLP(0000.0000), RC({rc}), DCR(0), DCI(0), NTH(077A), \
             T(83BD), RSL(-078.9641), FSL(-081.7507), RSMPL(31)\r\nAccum Len 8\r\n"
        );
        for k in 0..8i32 {
            text += &format!("{}, {}\r\n", 100 - 20 * k, k * k - 7);
        }
        text
    };
    let mut written = "File:fuzz_DecaWaveAllAccum.log, created by mmtrack-fuzz\r\n\
                       Mode: 2, Chan 2, Code 9, PRF 64, Plength 1024, DataRate 1, PAC 2\r\n\r\n"
        .to_string();
    written += "21 4B Rx time = 1.003088395769168e+001 953B8FDBD7\r\n";
    written += &frame("0004.5000", "0095 3B8FDBD7");
    written += "RX E  WInd(0735), PSC(0264), CE(0000), RSE(0000), HE(0000), STO(0001), FFE(0000), T(82BE), \
                RSL(-078.4136), FSL(-081.8368), RSMPL(34)\r\nAccum Len 2\r\n1, 2\r\n3, 4\r\n";
    written += &frame("0003.0156", "009A 70917D5E");
    let mut out = vec![written.into_bytes()];
    let Some(dir) = realdata else { return out };
    let Some(bytes) = head(&dir.join("uwb-cirs-2018/1.log"), 1 << 20, true) else { return out };
    let text = String::from_utf8_lossy(&bytes);
    let (mut full, mut cut, mut frames, mut taps_left, mut keep_left) = (String::new(), String::new(), 0, 0, 0);
    for line in text.split_inclusive('\n') {
        if line.starts_with("RX ") {
            frames += 1;
            if frames > 2 {
                break;
            }
        }
        full += line;
        if let Some(n) = line.trim().strip_prefix("Accum Len ").and_then(|n| n.parse::<usize>().ok()) {
            (taps_left, keep_left) = (n, 16.min(n));
            cut += &format!("Accum Len {keep_left}\r\n");
        } else if taps_left > 0 {
            taps_left -= 1;
            if keep_left > 0 {
                keep_left -= 1;
                cut += line;
            }
        } else if let Some((before, after)) = line.split_once("HLP(").filter(|_| line.starts_with("RX OK")) {
            // The first path moved within the 16 kept taps (the reader
            // refuses one beyond the accumulator).
            let rest = after.split_once(')').map_or("", |(_, rest)| rest);
            cut += &format!("{before}HLP(0008.5000){rest}");
        } else {
            cut += line;
        }
    }
    out.push(full.into_bytes());
    out.push(cut.into_bytes());
    out
}

fn f64_bytes(values: impl IntoIterator<Item = f64>, big: bool) -> Vec<u8> {
    values.into_iter().flat_map(|v| if big { v.to_be_bytes() } else { v.to_le_bytes() }).collect()
}

/// `.npy` and `.npz` files with their sidecars: written complex, I/Q and
/// Fortran-order arrays and archives (stored and deflated); the real
/// DeepSense position array cut to 16 rows (read as I/Q), and the head of
/// its int64 index array (a dtype the reader refuses).
#[must_use]
pub fn npy_files(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let sidecar = "carrier_hz = 60e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 0.001\n";
    let c16 = npy(1, "<c16", false, "(2, 8)", &f64_bytes((0..32).map(f64::from), false));
    let c8: Vec<u8> = (0..2 * 2 * 8 * 2).flat_map(|k| (k as f32 * 0.5).to_le_bytes()).collect();
    let c8 = npy(2, "<c8", true, "(2, 2, 8)", &c8);
    let iq = npy(1, ">f8", false, "(8, 2)", &f64_bytes((0..16).map(|k| f64::from(k) - 4.0), true));
    let i2: Vec<u8> = (0..3 * 4 * 2).flat_map(|k: i16| (k * 300 - 2000).to_le_bytes()).collect();
    let i2 = npy(1, "<i2", false, "(3, 4, 2)", &i2);
    let mut out = vec![
        with_sidecar(sidecar, &c16),
        with_sidecar("carrier_hz = 5.7e9\nbandwidth_hz = 1e9\naxes = [\"tap\", \"rx\", \"tx\"]\n", &c8),
        with_sidecar("carrier_hz = 1e9\ndomain = \"cfr\"\nsubcarrier_spacing_hz = 1e6\n", &iq),
        with_sidecar(sidecar, &i2),
        with_sidecar(&format!("{sidecar}variable = \"h\"\n"), &zip(&[("h.npy", c16.clone()), ("g.npy", iq)], false)),
        with_sidecar(sidecar, &zip(&[("cir.npy", c8)], true)),
    ];
    // Beam-sweep matrices in the narrower dtypes: float32 power, big-endian
    // int32 pass indices (`parse_npy_matrix` widens them).
    let f4: Vec<u8> = (0..4 * 3).flat_map(|k| (k as f32 * 0.125).to_le_bytes()).collect();
    out.push(with_sidecar(sidecar, &npy(1, "<f4", false, "(4, 3)", &f4)));
    let i4: Vec<u8> = [1i32, 1, 2, 2].iter().flat_map(|k| k.to_be_bytes()).collect();
    out.push(with_sidecar(sidecar, &npy(1, ">i4", false, "(4,)", &i4)));
    let Some(dir) = realdata else { return out };
    let beams = dir.join("deepsense-60ghz-beams");
    if let Ok(loc) = std::fs::read(beams.join("scenario1_unit2_loc_1-2422.npy")) {
        // Same header length: the shorter shape is padded with spaces.
        let header_end = loc.iter().position(|&b| b == b'\n').map_or(0, |p| p + 1);
        let (old, new) = (b"(2422, 2), }", b"(16, 2), }  ");
        let mut cut = loc[..header_end].to_vec();
        if let Some(at) = cut.windows(old.len()).position(|w| w == old) {
            cut[at..at + new.len()].copy_from_slice(new);
        }
        cut.extend(loc.iter().skip(header_end).take(16 * 2 * 8));
        out.push(with_sidecar(sidecar, &cut));
        out.push(with_sidecar(sidecar, &zip(&[("loc.npy", cut)], true)));
    }
    out.extend(head(&beams.join("scenario1_seq_index_1-2422.npy"), 256, false).map(|h| with_sidecar(sidecar, &h)));
    out
}

/// MATLAB v5 files with their sidecars: the real `CIR.mat` (a Huffman-coded
/// zlib stream) whole; its first 8 taps rewritten by our writer, plain and
/// compressed; a written real-valued 2-D array.
#[must_use]
pub fn mat(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let sidecar = "variable = \"CIR_mat\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\n";
    let real: Vec<f64> = (0..2 * 8).map(|k| f64::from(k) - 3.5).collect();
    let mut out = vec![with_sidecar(
        "variable = \"h\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\nallow_real = true\nsnapshot_period_s = 0.1\n",
        &mat_v5("h", &[2, 8], &real, None, false),
    )];
    let Some(dir) = realdata else { return out };
    let Ok(bytes) = std::fs::read(dir.join("but-60ghz-mimo/CIR.mat")) else { return out };
    out.push(with_sidecar(sidecar, &bytes));
    let layout = MatCirLayout {
        variable: "CIR_mat".into(),
        carrier_hz: 60e9,
        tap_spacing_s: 1e-10,
        delay_offset_s: 0.0,
        t_ns: 0,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: false,
    };
    if let Ok(snapshots) = read_mat_cir(Path::new("CIR.mat"), &bytes, &layout) {
        // Column-major (rx, tx, tap): element (r, t, k) at r + 4 (t + 4 k).
        let (mut re, mut im) = (vec![0.0; 4 * 4 * 8], vec![0.0; 4 * 4 * 8]);
        for s in &snapshots {
            for (k, tap) in s.taps.iter().take(8).enumerate() {
                let at = s.rx_antenna as usize + 4 * (s.tx_antenna as usize + 4 * k);
                if let (Some(r), Some(i)) = (re.get_mut(at), im.get_mut(at)) {
                    (*r, *i) = (tap.re, tap.im);
                }
            }
        }
        for compressed in [false, true] {
            out.push(with_sidecar(sidecar, &mat_v5("CIR_mat", &[4, 4, 8], &re, Some(&im), compressed)));
        }
    }
    out
}

/// SigMF recordings with their sidecars: a written cf32 stream, and the
/// first 16 taps of the real DecaWave log's first frame as ci16.
#[must_use]
pub fn sigmf(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let record = |sidecar: &str, meta: &str, data: &[u8]| {
        let mut out = with_sidecar(sidecar, meta.as_bytes());
        out.push(0);
        out.extend_from_slice(data);
        out
    };
    let meta = |datatype: &str| {
        format!(
            "{{\"global\": {{\"core:datatype\": \"{datatype}\", \"core:sample_rate\": 998.4e6, \
             \"core:num_channels\": 1, \"core:version\": \"1.0.0\"}}, \"captures\": [{{\"core:sample_start\": 0, \
             \"core:frequency\": 3993.6e6, \"core:datetime\": \"2018-01-08T11:58:17.25Z\"}}], \"annotations\": []}}"
        )
    };
    let cf32: Vec<u8> = (0..2 * 8 * 2).flat_map(|k| (k as f32 - 9.0).to_le_bytes()).collect();
    let mut out = vec![record("taps_per_snapshot = 8\nsnapshot_period_s = 0.01\n", &meta("cf32_le"), &cf32)];
    let mut ci16: Vec<u8> =
        (0..16i16).flat_map(|k| [(k * 9 - 50).to_le_bytes(), (40 - k * k).to_le_bytes()]).flatten().collect();
    if let Some(log) = realdata.and_then(|dir| head(&dir.join("uwb-cirs-2018/1.log"), 4096, true)) {
        let taps: Vec<u8> = String::from_utf8_lossy(&log)
            .lines()
            .skip_while(|l| !l.starts_with("Accum Len"))
            .skip(1)
            .take(16)
            .filter_map(|l| l.split_once(','))
            .filter_map(|(i, q)| Some([i.trim().parse::<i16>().ok()?, q.trim().parse::<i16>().ok()?]))
            .flat_map(|[i, q]| [i.to_le_bytes(), q.to_le_bytes()])
            .flatten()
            .collect();
        if taps.len() == 16 * 4 {
            ci16 = taps;
        }
    }
    out.push(record("taps_per_snapshot = 16\n", &meta("ci16_le"), &ci16));
    out
}

/// CIR CSV files with their sidecars: written rows with and without index
/// columns, and the first 8 taps of the real DecaWave log's first frames.
#[must_use]
pub fn csv(realdata: Option<&Path>) -> Vec<Vec<u8>> {
    let sidecar = "carrier_hz = 3993.6e6\ntap_spacing_s = 1.0016e-9\nsnapshot_period_s = 0.001\n\
                   snapshots_per_set = 2\nset_period_s = 0.01\nt0_ns = 100\n";
    let mut out = vec![
        with_sidecar(sidecar, b"# exported\nre_0,im_0,re_1,im_1\n1,2,3,4\n5,6,7,8\n\n-1,0,0,1e-3\n"),
        with_sidecar(
            sidecar,
            b"t_ns,set_index,snapshot_index,tx_antenna,rx_antenna,re_0,im_0,re_1,im_1\n5,3,1,2,1,1,0,0.5,-0.5\n\
              6,4,0,0,0,2,1,1,2\n",
        ),
        with_sidecar(
            "carrier_hz = 60e9\ndomain = \"cfr\"\nsubcarrier_spacing_hz = 10e6\n",
            b"set_index,snapshot_index,re_0,im_0,re_1,im_1,re_2,im_2\n0,0,1,0,0,1,-1,0\n",
        ),
    ];
    let Some(log) = realdata.and_then(|dir| head(&dir.join("uwb-cirs-2018/1.log"), 40_000, true)) else {
        return out;
    };
    let mut text = "re_0,im_0,re_1,im_1,re_2,im_2,re_3,im_3,re_4,im_4,re_5,im_5,re_6,im_6,re_7,im_7\n".to_string();
    let log = String::from_utf8_lossy(&log);
    let mut lines = log.lines();
    while lines.by_ref().any(|l| l.starts_with("Accum Len")) {
        let row: Vec<&str> =
            lines.by_ref().take(8).filter_map(|l| l.split_once(',')).flat_map(|(i, q)| [i.trim(), q.trim()]).collect();
        text += &row.join(",");
        text.push('\n');
    }
    out.push(with_sidecar(sidecar, text.as_bytes()));
    out
}
