//! SigMF recordings (`<name>.sigmf-meta` JSON + `<name>.sigmf-data` samples)
//! holding a stream of CIRs.
//!
//! Read from the meta: `global.core:datatype` (required; `cf32_le` or
//! `ci16_le`), `global.core:sample_rate` (the tap rate, used when the sidecar
//! gives no tap spacing), `global.core:num_channels` (must be 1), and from the
//! first capture `core:frequency` (the carrier, when the sidecar gives none)
//! and `core:datetime` (ISO 8601 UTC, the time of snapshot 0 when the sidecar
//! gives no `t0_ns`). The data is one stream: the sidecar's
//! `taps_per_snapshot` cuts it into consecutive snapshots (SISO).

use std::path::{Path, PathBuf};

use mmtrack_core::Complex64;
use serde_json::Value;

use super::array::NdComplex;
use super::sidecar::CirSidecar;
use crate::IngestError;

/// A SigMF recording as an array `[snapshot, tap]` plus what its meta says.
pub(crate) struct SigmfCirs {
    pub array: NdComplex,
    pub sample_rate_hz: Option<f64>,
    pub frequency_hz: Option<f64>,
    pub t0_ns: Option<i64>,
    pub datatype: String,
}

/// The meta and data paths of a recording given by either file or the base name.
pub(crate) fn sigmf_paths(input: &Path) -> (PathBuf, PathBuf) {
    let base = match input.extension().and_then(|e| e.to_str()) {
        Some("sigmf-meta" | "sigmf-data") => input.with_extension(""),
        _ => input.to_path_buf(),
    };
    (base.with_extension("sigmf-meta"), base.with_extension("sigmf-data"))
}

/// Reads a SigMF recording of CIRs.
pub(crate) fn read_sigmf(input: &Path, sidecar: &CirSidecar) -> Result<SigmfCirs, IngestError> {
    let (meta_path, data_path) = sigmf_paths(input);
    let meta_text = crate::error::read_text(&meta_path)?;
    let data = crate::error::read_capped(&data_path, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
    parse_sigmf(&meta_path, &meta_text, &data_path, &data, sidecar)
}

pub(crate) fn parse_sigmf(
    meta_path: &Path,
    meta_text: &str,
    data_path: &Path,
    data: &[u8],
    sidecar: &CirSidecar,
) -> Result<SigmfCirs, IngestError> {
    let bad = |record: &str, field: &str, detail: String| IngestError::BadRecord {
        path: meta_path.to_path_buf(),
        record: record.into(),
        field: field.into(),
        detail,
    };
    let meta: Value = serde_json::from_str(meta_text).map_err(|e| bad("JSON", "(syntax)", e.to_string()))?;
    let global = meta.get("global").ok_or_else(|| bad("meta", "global", "missing object".into()))?;
    let datatype = match global.get("core:datatype") {
        Some(Value::String(s)) => s.clone(),
        Some(other) => return Err(bad("global", "core:datatype", format!("{other}, expected a string"))),
        None => return Err(bad("global", "core:datatype", "missing; expected \"cf32_le\" or \"ci16_le\"".into())),
    };
    let number = |v: Option<&Value>, record: &str, field: &str| -> Result<Option<f64>, IngestError> {
        match v {
            None => Ok(None),
            Some(v) => match v.as_f64() {
                Some(x) if x.is_finite() && x >= 0.0 => Ok(Some(x)),
                _ => Err(bad(record, field, format!("{v}, expected a finite number >= 0"))),
            },
        }
    };
    let sample_rate_hz = number(global.get("core:sample_rate"), "global", "core:sample_rate")?.filter(|&r| r > 0.0);
    if let Some(n) = global.get("core:num_channels").filter(|n| n.as_u64() != Some(1)) {
        return Err(bad("global", "core:num_channels", format!("{n}; only single-channel recordings are read")));
    }
    let capture = meta.get("captures").and_then(|c| c.get(0));
    let frequency_hz = number(capture.and_then(|c| c.get("core:frequency")), "captures[0]", "core:frequency")?;
    let t0_ns = match capture.and_then(|c| c.get("core:datetime")) {
        None => None,
        Some(v) => Some(v.as_str().and_then(parse_datetime_ns).ok_or_else(|| {
            bad("captures[0]", "core:datetime", format!("{v}, expected ISO 8601 UTC like 2024-05-01T12:00:00.5Z"))
        })?),
    };
    let values = samples(data_path, &datatype, data).map_err(|detail| bad("global", "core:datatype", detail))?;
    let Some(taps) = sidecar.taps_per_snapshot else {
        return Err(sidecar.error("taps_per_snapshot", "required for SigMF: the data is one stream of samples".into()));
    };
    if values.is_empty() || !values.len().is_multiple_of(taps) {
        return Err(IngestError::BadRecord {
            path: data_path.to_path_buf(),
            record: format!("sample {}", values.len() - values.len() % taps),
            field: "data".into(),
            detail: format!("{} samples are not a whole number of snapshots of {taps} taps (truncated?)", values.len()),
        });
    }
    let array = NdComplex::new(vec![values.len() / taps, taps], values, false);
    Ok(SigmfCirs { array, sample_rate_hz, frequency_hz, t0_ns, datatype })
}

fn samples(data_path: &Path, datatype: &str, data: &[u8]) -> Result<Vec<Complex64>, String> {
    let width = match datatype {
        "cf32_le" => 8,
        "ci16_le" => 4,
        other => return Err(format!("\"{other}\", expected \"cf32_le\" or \"ci16_le\"")),
    };
    if !data.len().is_multiple_of(width) {
        return Err(format!(
            "{} has {} bytes, not a whole number of {width}-byte {datatype} samples (truncated?)",
            data_path.display(),
            data.len()
        ));
    }
    Ok(data
        .chunks_exact(width)
        .map(|c| {
            if width == 8 {
                let f = |i: usize| f64::from(f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]));
                Complex64::new(f(0), f(4))
            } else {
                Complex64::new(f64::from(i16::from_le_bytes([c[0], c[1]])), f64::from(i16::from_le_bytes([c[2], c[3]])))
            }
        })
        .collect())
}

/// Exactly `n` ASCII digits as a number.
fn digits(text: &str, n: usize) -> Option<i64> {
    (text.len() == n && text.bytes().all(|b| b.is_ascii_digit())).then(|| text.parse().ok()).flatten()
}

/// `YYYY-MM-DDTHH:MM:SS[.fraction]Z` (RFC 3339 in UTC: fixed-width fields,
/// years 0000-9999) -> ns since the UNIX epoch; `None` when malformed or
/// beyond the i64 nanosecond range (years before 1677 or after 2262).
fn parse_datetime_ns(text: &str) -> Option<i64> {
    let text = text.strip_suffix('Z')?;
    let (date, time) = text.split_once('T')?;
    let mut d = date.split('-');
    let (y, m, day) = (digits(d.next()?, 4)?, digits(d.next()?, 2)?, digits(d.next()?, 2)?);
    let (hms, frac) = time.split_once('.').unwrap_or((time, ""));
    let mut t = hms.split(':');
    let (hh, mm, ss) = (digits(t.next()?, 2)?, digits(t.next()?, 2)?, digits(t.next()?, 2)?);
    if !(1..=12).contains(&m) || !(1..=31).contains(&day) || hh > 23 || mm > 59 || ss > 60 {
        return None;
    }
    if d.next().is_some() || t.next().is_some() || frac.len() > 9 || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let frac_ns: i64 = if frac.is_empty() { 0 } else { format!("{frac:0<9}").parse().ok()? };
    let days = mmtrack_core::calendar::days_from_civil(y, m, day);
    (days * 86_400 + hh * 3600 + mm * 60 + ss).checked_mul(1_000_000_000)?.checked_add(frac_ns)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sidecar(text: &str) -> CirSidecar {
        CirSidecar::parse(Path::new("s.toml"), text).unwrap()
    }

    const META: &str = r#"{"global": {"core:datatype": "ci16_le", "core:sample_rate": 1e9, "core:version": "1.0.0"},
        "captures": [{"core:sample_start": 0, "core:frequency": 5.7e9, "core:datetime": "2021-09-21T00:00:01.25Z"}],
        "annotations": []}"#;

    #[test]
    fn meta_and_samples() {
        let data: Vec<u8> = [1i16, -2, 3, 4, 5, 6, 7, 8].iter().flat_map(|v| v.to_le_bytes()).collect();
        let s = sidecar("taps_per_snapshot = 2");
        let r = parse_sigmf(Path::new("a.sigmf-meta"), META, Path::new("a.sigmf-data"), &data, &s).unwrap();
        assert_eq!(r.array.dims, [2, 2]);
        assert_eq!(r.array.values[1], Complex64::new(3.0, 4.0));
        assert_eq!((r.sample_rate_hz, r.frequency_hz), (Some(1e9), Some(5.7e9)));
        // 2021-09-21 is day 18891 since 1970-01-01 (date -d 2021-09-21 +%s = 1632182400).
        assert_eq!(r.t0_ns, Some(1_632_182_401_250_000_000));
        let cf32 = META.replace("ci16_le", "cf32_le");
        let data: Vec<u8> = [0.5f32, -0.25].iter().flat_map(|v| v.to_le_bytes()).collect();
        let s = sidecar("taps_per_snapshot = 1");
        let r = parse_sigmf(Path::new("a.sigmf-meta"), &cf32, Path::new("a.sigmf-data"), &data, &s).unwrap();
        assert_eq!((r.array.values[0], r.datatype.as_str()), (Complex64::new(0.5, -0.25), "cf32_le"));
        assert_eq!(sigmf_paths(Path::new("x/r.sigmf-data")).0, Path::new("x/r.sigmf-meta"));
    }

    #[test]
    fn bad_meta_and_data_are_named() {
        let data = vec![0u8; 16];
        let s = sidecar("taps_per_snapshot = 2");
        let err = |meta: &str, data: &[u8], s: &CirSidecar| {
            parse_sigmf(Path::new("a.sigmf-meta"), meta, Path::new("a.sigmf-data"), data, s).err().unwrap().to_string()
        };
        let e = err(&META.replace("\"core:datatype\": \"ci16_le\", ", ""), &data, &s);
        assert!(e.contains("a.sigmf-meta: global: core:datatype: missing"), "{e}");
        let e = err(&META.replace("ci16_le", "ri8"), &data, &s);
        assert!(e.contains("core:datatype: \"ri8\", expected \"cf32_le\" or \"ci16_le\""), "{e}");
        let e = err(META, &data[..15], &s);
        assert!(e.contains("15 bytes") && e.contains("truncated"), "{e}");
        let e = err(META, &data[..12], &s);
        assert!(e.contains("a.sigmf-data: sample 2: data: 3 samples are not a whole number"), "{e}");
        let e = err(META, &data, &CirSidecar::empty());
        assert!(e.contains("key `taps_per_snapshot`: required"), "{e}");
        let e = err("{\"global\": ", &data, &s);
        assert!(e.contains("JSON"), "{e}");
        let e = err(&META.replace("2021-09-21T00:00:01.25Z", "yesterday"), &data, &s);
        assert!(e.contains("core:datetime"), "{e}");
        let e = err(&META.replace("1e9", "-1"), &data, &s);
        assert!(e.contains("core:sample_rate: -1"), "{e}");
        assert_eq!(parse_datetime_ns("1970-01-01T00:00:00Z"), Some(0));
        assert_eq!(parse_datetime_ns("2000-03-01T00:00:00.000000001Z"), Some(951_868_800_000_000_001));
    }

    /// Found by fuzzing: a year of 11 digits overflowed the day arithmetic
    /// (a panic in debug builds); signs and short fields were accepted.
    #[test]
    fn datetimes_out_of_range_or_malformed_are_refused() {
        for text in [
            "99999999999-01-01T00:00:00Z",
            "-9223372036854775808-01-01T00:00:00Z",
            "9999-12-31T23:59:59Z",
            "1000-01-01T00:00:00Z",
            "2021-09-21T-1:00:00Z",
            "2021-09-21T+1:00:00Z",
            "2021-9-21T00:00:00Z",
            "2021-09-21T00:00:00:00Z",
        ] {
            assert_eq!(parse_datetime_ns(text), None, "{text}");
        }
        // The ends of the i64 nanosecond range.
        assert_eq!(parse_datetime_ns("2262-04-11T23:47:16.854775807Z"), Some(i64::MAX));
        assert_eq!(parse_datetime_ns("2262-04-11T23:47:17Z"), None);
        assert_eq!(parse_datetime_ns("1677-09-21T00:12:44Z"), Some(-9_223_372_036_000_000_000));
    }
}
