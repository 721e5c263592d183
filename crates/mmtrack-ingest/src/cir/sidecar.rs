//! The sidecar TOML of a channel-sounder file: what the file itself does not
//! say (carrier, tap spacing, timing, domain, which array axis is what).
//!
//! Every key is optional at parse time; each format then says which keys it
//! uses ([`CirSidecar::check_keys_apply`]) and which it needs. Keys:
//!
//! | key | meaning |
//! |---|---|
//! | `carrier_hz` | carrier (centre) frequency, Hz (>= 0; 0 = baseband) |
//! | `tap_spacing_s` | delay between CIR taps, s |
//! | `bandwidth_hz` | the sampled span, Hz: tap spacing = 1 / `bandwidth_hz` (for a CFR of N bins `df` apart, N * df) |
//! | `subcarrier_spacing_hz` | CFR only: bin spacing df, Hz; tap spacing = 1 / (N * df) |
//! | `domain` | `"cir"` (default) or `"cfr"`: a CFR is turned into a CIR by the inverse DFT, `h[n] = (1/N) sum_k H[k] exp(+j 2 pi k n / N)`, bins in file order |
//! | `delay_offset_s` | delay of tap 0, s (default 0) |
//! | `t0_ns` | time of snapshot 0, ns since the UNIX epoch (default 0, or the SigMF `core:datetime`) |
//! | `snapshot_period_s` | time between snapshots of a set, s |
//! | `snapshots_per_set` | snapshots per set (default 1, > 0) |
//! | `set_period_s` | time between sets, s (default `snapshots_per_set * snapshot_period_s`) |
//! | `axes` | array formats: role of each array dimension, from `"snapshot"`, `"tx"`, `"rx"`, `"tap"` |
//! | `variable` | `.mat`: the MATLAB variable; `.npz`: the member (without `.npy`) |
//! | `dataset` | HDF5: path of the dataset in the file, e.g. `"/sounder/cir"` (default: the file's only dataset) |
//! | `allow_real` | `.mat`: read a real array as taps with zero imaginary part (default false) |
//! | `taps_per_snapshot` | SigMF: samples per CIR (the data file is one stream) |
//!
//! Exactly one of `tap_spacing_s`, `bandwidth_hz`, `subcarrier_spacing_hz` may
//! be given. Unknown keys, wrong types and out-of-range values are errors
//! naming the sidecar file and the key.

use std::path::{Path, PathBuf};

use crate::IngestError;

/// Whether the file holds impulse responses or frequency responses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Domain {
    /// Channel impulse responses (taps over delay).
    #[default]
    Cir,
    /// Channel frequency responses (bins over frequency), turned into CIRs.
    Cfr,
}

impl Domain {
    /// `cir` or `cfr`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Cir => "cir",
            Self::Cfr => "cfr",
        }
    }
}

/// What one array dimension indexes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisRole {
    /// Successive snapshots in time (cut into sets by `snapshots_per_set`).
    Snapshot,
    /// Transmit antenna.
    Tx,
    /// Receive antenna.
    Rx,
    /// Delay taps (or frequency bins of a CFR).
    Tap,
}

impl AxisRole {
    fn parse(name: &str) -> Option<Self> {
        match name {
            "snapshot" => Some(Self::Snapshot),
            "tx" => Some(Self::Tx),
            "rx" => Some(Self::Rx),
            "tap" => Some(Self::Tap),
            _ => None,
        }
    }

    /// The name used in sidecars.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Snapshot => "snapshot",
            Self::Tx => "tx",
            Self::Rx => "rx",
            Self::Tap => "tap",
        }
    }
}

/// How the delay axis is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TapSpacing {
    /// Tap spacing in seconds.
    Seconds(f64),
    /// Sampled span: spacing = 1 / bandwidth.
    Bandwidth(f64),
    /// CFR bin spacing: spacing = 1 / (bins * df).
    SubcarrierSpacing(f64),
}

impl TapSpacing {
    /// Tap spacing, seconds, for `bins` taps or frequency bins.
    #[must_use]
    pub fn seconds(self, bins: usize) -> f64 {
        match self {
            Self::Seconds(s) => s,
            Self::Bandwidth(b) => 1.0 / b,
            Self::SubcarrierSpacing(df) => 1.0 / (bins as f64 * df),
        }
    }
}

/// A parsed, validated sidecar (see the module docs for the keys).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CirSidecar {
    /// The file it came from (for messages); empty for a default sidecar.
    pub path: PathBuf,
    /// Keys present in the file, sorted.
    pub keys: Vec<String>,
    /// `carrier_hz`.
    pub carrier_hz: Option<f64>,
    /// `tap_spacing_s`, `bandwidth_hz` or `subcarrier_spacing_hz`.
    pub tap_spacing: Option<TapSpacing>,
    /// `domain`.
    pub domain: Domain,
    /// `delay_offset_s`.
    pub delay_offset_s: f64,
    /// `t0_ns`.
    pub t0_ns: Option<i64>,
    /// `snapshot_period_s`.
    pub snapshot_period_s: Option<f64>,
    /// `snapshots_per_set` (default 1).
    pub snapshots_per_set: u32,
    /// `set_period_s`.
    pub set_period_s: Option<f64>,
    /// `axes`.
    pub axes: Option<Vec<AxisRole>>,
    /// `variable`.
    pub variable: Option<String>,
    /// `dataset`.
    pub dataset: Option<String>,
    /// `allow_real`.
    pub allow_real: bool,
    /// `taps_per_snapshot`.
    pub taps_per_snapshot: Option<usize>,
}

const KNOWN_KEYS: &[&str] = &[
    "allow_real",
    "axes",
    "bandwidth_hz",
    "carrier_hz",
    "dataset",
    "delay_offset_s",
    "domain",
    "set_period_s",
    "snapshot_period_s",
    "snapshots_per_set",
    "subcarrier_spacing_hz",
    "t0_ns",
    "tap_spacing_s",
    "taps_per_snapshot",
    "variable",
];

impl CirSidecar {
    /// An empty sidecar (every default) for files that need none.
    #[must_use]
    pub fn empty() -> Self {
        Self { snapshots_per_set: 1, ..Self::default() }
    }

    /// Reads and validates a sidecar file.
    pub fn read(path: &Path) -> Result<Self, IngestError> {
        let text = crate::error::read_text(path)?;
        Self::parse(path, &text)
    }

    /// Parses and validates sidecar text.
    pub fn parse(path: &Path, text: &str) -> Result<Self, IngestError> {
        let bad =
            |key: &str, detail: String| IngestError::BadSidecar { path: path.to_path_buf(), key: key.into(), detail };
        // A syntax error as one line naming its line (its multi-line snippet printed as literal `\n`s).
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            let line = e.span().map_or(1, |span| text[..span.start.min(text.len())].matches('\n').count() + 1);
            IngestError::bad_line(path, line, "TOML syntax", e.message().trim().to_string())
        })?;
        let mut out = Self { path: path.to_path_buf(), ..Self::empty() };
        for (key, value) in &table {
            if !KNOWN_KEYS.contains(&key.as_str()) {
                return Err(bad(key, format!("unknown key; known keys: {}", KNOWN_KEYS.join(", "))));
            }
            out.keys.push(key.clone());
            out.set(key, value).map_err(|detail| bad(key, detail))?;
        }
        out.keys.sort();
        let spacing_keys: Vec<&str> = ["tap_spacing_s", "bandwidth_hz", "subcarrier_spacing_hz"]
            .into_iter()
            .filter(|k| table.contains_key(*k))
            .collect();
        if spacing_keys.len() > 1 {
            return Err(bad(spacing_keys[1], format!("give only one of {}", spacing_keys.join(", "))));
        }
        if matches!(out.tap_spacing, Some(TapSpacing::SubcarrierSpacing(_))) && out.domain != Domain::Cfr {
            return Err(bad("subcarrier_spacing_hz", "only for domain = \"cfr\"; give tap_spacing_s for a CIR".into()));
        }
        if let (Some(snapshot), Some(set)) = (out.snapshot_period_s, out.set_period_s)
            && f64::from(out.snapshots_per_set - 1) * snapshot >= set
        {
            return Err(bad(
                "set_period_s",
                format!(
                    "{set} s is not longer than the {} snapshots of a set span ({snapshot} s apart): times would not increase",
                    out.snapshots_per_set
                ),
            ));
        }
        Ok(out)
    }

    fn set(&mut self, key: &str, value: &toml::Value) -> Result<(), String> {
        match key {
            "carrier_hz" => self.carrier_hz = Some(number(value, 0.0, true)?),
            "tap_spacing_s" => self.tap_spacing = Some(TapSpacing::Seconds(number(value, 0.0, false)?)),
            "bandwidth_hz" => self.tap_spacing = Some(TapSpacing::Bandwidth(number(value, 0.0, false)?)),
            "subcarrier_spacing_hz" => {
                self.tap_spacing = Some(TapSpacing::SubcarrierSpacing(number(value, 0.0, false)?));
            }
            "domain" => {
                self.domain = match value.as_str() {
                    Some("cir") => Domain::Cir,
                    Some("cfr") => Domain::Cfr,
                    _ => return Err(format!("{value}, expected \"cir\" or \"cfr\"")),
                }
            }
            "delay_offset_s" => {
                // One second is 300 000 km of propagation: beyond it the value is a unit slip (ns as s).
                let offset_s = number(value, f64::NEG_INFINITY, true)?;
                if offset_s.abs() > 1.0 {
                    return Err(format!(
                        "{offset_s:e} s, expected a delay of at most 1 s in magnitude (seconds, not ns)"
                    ));
                }
                self.delay_offset_s = offset_s;
            }
            "t0_ns" => {
                let t0_ns = value.as_integer().filter(|t| *t >= 0);
                self.t0_ns =
                    Some(t0_ns.ok_or_else(|| format!("{value}, expected an integer >= 0 (ns since the time base)"))?);
            }
            "snapshot_period_s" => self.snapshot_period_s = Some(number(value, 0.0, false)?),
            "set_period_s" => self.set_period_s = Some(number(value, 0.0, false)?),
            "snapshots_per_set" => self.snapshots_per_set = count(value)?,
            "taps_per_snapshot" => self.taps_per_snapshot = Some(count(value)? as usize),
            "allow_real" => {
                self.allow_real = value.as_bool().ok_or_else(|| format!("{value}, expected true or false"))?
            }
            "variable" => {
                self.variable = Some(value.as_str().ok_or_else(|| format!("{value}, expected a string"))?.to_string());
            }
            "dataset" => {
                self.dataset = Some(value.as_str().ok_or_else(|| format!("{value}, expected a string"))?.to_string());
            }
            "axes" => self.axes = Some(axes(value)?),
            _ => return Err("unknown key".into()),
        }
        Ok(())
    }

    /// Fails when the file sets a key that `format` does not use.
    pub fn check_keys_apply(&self, format: &str, used: &[&str]) -> Result<(), IngestError> {
        match self.keys.iter().find(|k| !used.contains(&k.as_str())) {
            None => Ok(()),
            Some(key) => Err(IngestError::BadSidecar {
                path: self.path.clone(),
                key: key.clone(),
                detail: format!("does not apply to --format {format} (it uses: {})", used.join(", ")),
            }),
        }
    }

    /// An error about `key` of this sidecar.
    pub(crate) fn error(&self, key: &str, detail: String) -> IngestError {
        let path = if self.path.as_os_str().is_empty() { PathBuf::from("(no sidecar)") } else { self.path.clone() };
        IngestError::BadSidecar { path, key: key.into(), detail }
    }

    /// Time, set index and index in the set of the `s`-th snapshot (0-based).
    pub(crate) fn snapshot_time(&self, s: usize, count: usize) -> Result<(i64, u64, u32), IngestError> {
        let per_set = self.snapshots_per_set.max(1) as usize;
        let (set, k) = (s / per_set, s % per_set);
        let t0 = self.t0_ns.unwrap_or(0);
        if count <= 1 {
            return Ok((t0, 0, 0));
        }
        let snapshot_period = self.snapshot_period_s;
        let set_period = self.set_period_s.or(snapshot_period.map(|p| p * per_set as f64));
        let (Some(set_period), Some(snapshot_period)) = (set_period, snapshot_period.or((per_set == 1).then_some(0.0)))
        else {
            return Err(self.error(
                "snapshot_period_s",
                format!(
                    "the file holds {count} snapshots; give snapshot_period_s (and set_period_s for sets of several)"
                ),
            ));
        };
        let offset_ns = (set as f64 * set_period + k as f64 * snapshot_period) * 1e9;
        // The offset from t0_ns overflowing is the periods' fault; the sum
        // overflowing only once t0_ns is added is t0_ns's.
        let offset_ns = i64::try_from(offset_ns.round() as i128).map_err(|_| {
            let (key, period) = match self.set_period_s {
                Some(set_period) if set > 0 => ("set_period_s", set_period),
                _ => ("snapshot_period_s", snapshot_period),
            };
            self.error(
                key,
                format!("{period:e} s puts snapshot {s} beyond the i64 nanosecond range (about 292 years after t0_ns)"),
            )
        })?;
        let t = offset_ns.checked_add(t0).ok_or_else(|| {
            self.error("t0_ns", format!("snapshot {s} ({offset_ns} ns after t0_ns {t0}) overflows i64 nanoseconds"))
        })?;
        Ok((t, set as u64, k as u32))
    }
}

/// A finite number (TOML float or integer) above `min` (or equal when `inclusive`).
fn number(value: &toml::Value, min: f64, inclusive: bool) -> Result<f64, String> {
    let x = match value {
        toml::Value::Float(x) => *x,
        toml::Value::Integer(i) => *i as f64,
        other => return Err(format!("{other}, expected a number")),
    };
    let ok = x.is_finite() && if inclusive { x >= min } else { x > min };
    if !ok {
        let bound = if min == f64::NEG_INFINITY {
            "a finite number".to_string()
        } else if inclusive {
            format!("a finite number >= {min}")
        } else {
            format!("a finite number > {min}")
        };
        return Err(format!("{x}, expected {bound}"));
    }
    Ok(x)
}

/// A positive integer that fits a u32.
fn count(value: &toml::Value) -> Result<u32, String> {
    match value.as_integer().map(u32::try_from) {
        Some(Ok(n)) if n > 0 => Ok(n),
        _ => Err(format!("{value}, expected a positive integer")),
    }
}

fn axes(value: &toml::Value) -> Result<Vec<AxisRole>, String> {
    let expected = "an array of \"snapshot\", \"tx\", \"rx\", \"tap\" (each at most once, \"tap\" required)";
    let items = value.as_array().ok_or_else(|| format!("{value}, expected {expected}"))?;
    let mut roles = Vec::with_capacity(items.len());
    for item in items {
        let role =
            item.as_str().and_then(AxisRole::parse).ok_or_else(|| format!("item {item}, expected {expected}"))?;
        if roles.contains(&role) {
            return Err(format!("\"{}\" appears twice, expected {expected}", role.as_str()));
        }
        roles.push(role);
    }
    if !roles.contains(&AxisRole::Tap) {
        return Err(format!("no \"tap\" axis, expected {expected}"));
    }
    Ok(roles)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<CirSidecar, String> {
        CirSidecar::parse(Path::new("s.toml"), text).map_err(|e| e.to_string())
    }

    #[test]
    fn keys_parse_and_times_follow_sets() {
        let s = parse(
            "carrier_hz = 5.7e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 0.000717\nsnapshots_per_set = 6\n\
             set_period_s = 0.01\nt0_ns = 1000\naxes = [\"snapshot\", \"rx\", \"tap\"]\ndomain = \"cir\"\n",
        )
        .unwrap();
        assert_eq!(s.carrier_hz, Some(5.7e9));
        assert_eq!(s.axes.as_deref(), Some(&[AxisRole::Snapshot, AxisRole::Rx, AxisRole::Tap][..]));
        // Snapshot 7 = set 1, snapshot 1: 10 ms + 0.717 ms after t0.
        assert_eq!(s.snapshot_time(7, 12).unwrap(), (1000 + 10_717_000, 1, 1));
        let cfr = parse("domain = \"cfr\"\nsubcarrier_spacing_hz = 10e6\n").unwrap();
        // 1001 bins 10 MHz apart: taps 99.9 ps apart (1e-24: rounding).
        assert!((cfr.tap_spacing.unwrap().seconds(1001) - 1.0 / 10.01e9).abs() < 1e-24);
        // One snapshot needs no period; several do.
        assert_eq!(CirSidecar::empty().snapshot_time(0, 1).unwrap(), (0, 0, 0));
        assert!(CirSidecar::empty().snapshot_time(1, 2).unwrap_err().to_string().contains("snapshot_period_s"));
        // A huge period is named, not t0_ns; a t0_ns that overflows only once
        // the offset is added is.
        let huge = parse("snapshot_period_s = 1e300").unwrap();
        let err = huge.snapshot_time(1, 2).unwrap_err().to_string();
        assert!(err.starts_with("s.toml: key `snapshot_period_s`: 1e300 s puts snapshot 1 beyond"), "{err}");
        let late = parse("snapshot_period_s = 1.0\nt0_ns = 9223372036000000000").unwrap();
        let err = late.snapshot_time(1, 2).unwrap_err().to_string();
        assert!(err.starts_with("s.toml: key `t0_ns`: snapshot 1 (1000000000 ns after t0_ns"), "{err}");
        // A delay offset in ns typed as s is named (1e300 was accepted).
        let err = parse("delay_offset_s = 1e300").unwrap_err().to_string();
        assert!(err.contains("delay_offset_s") && err.contains("at most 1 s"), "{err}");
        assert_eq!(parse("delay_offset_s = -2e-7").unwrap().delay_offset_s, -2e-7);
        // A negative start is named here (the recording would refuse it, naming itself).
        let err = parse("t0_ns = -1").unwrap_err().to_string();
        assert!(err.contains("t0_ns") && err.contains("expected an integer >= 0"), "{err}");
    }

    #[test]
    fn bad_sidecars_name_file_and_key() {
        for (text, needle) in [
            ("bandwidth_hz = -5e6", "s.toml: key `bandwidth_hz`: -5000000, expected a finite number > 0"),
            ("snapshots_per_set = 0", "key `snapshots_per_set`: 0, expected a positive integer"),
            ("carrier = 1e9", "key `carrier`: unknown key; known keys: allow_real"),
            ("domain = \"time\"", "key `domain`: \"time\", expected \"cir\" or \"cfr\""),
            ("tap_spacing_s = 1e-9\nbandwidth_hz = 1e9", "give only one of tap_spacing_s, bandwidth_hz"),
            ("subcarrier_spacing_hz = 1e6", "key `subcarrier_spacing_hz`: only for domain = \"cfr\""),
            ("axes = [\"tx\", \"rx\"]", "key `axes`: no \"tap\" axis"),
            ("axes = [\"tap\", \"tap\"]", "\"tap\" appears twice"),
            ("axes = [\"delay\"]", "item \"delay\""),
            ("carrier_hz = nan", "key `carrier_hz`: NaN"),
            ("tap_spacing_s = \"1ns\"", "expected a number"),
            ("snapshot_period_s = 0.002\nsnapshots_per_set = 6\nset_period_s = 0.01", "key `set_period_s`"),
            ("carrier_hz = ", "s.toml: line 1: TOML syntax: "),
        ] {
            let err = parse(text).unwrap_err();
            assert!(err.contains(needle), "{text}: {err}");
        }
        let s = parse("axes = [\"tap\"]").unwrap();
        let err = s.check_keys_apply("decawave", &["carrier_hz"]).unwrap_err().to_string();
        assert!(err.contains("key `axes`: does not apply to --format decawave"), "{err}");
    }
}
