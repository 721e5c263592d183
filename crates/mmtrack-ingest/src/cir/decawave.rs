//! DecaWave DecaRanging accumulator logs (DW1000 / EVK1000, "AllAccum" logs):
//! one channel impulse response per received frame.
//!
//! The log is CRLF or LF text. Line 2 gives the radio settings
//! (`Mode: 2, Chan 2, Code 9, PRF 64, Plength 1024, ...`). Each good reception
//! is a header line, `Accum Len <n>`, then `n` lines `I, Q` (integers: the raw
//! accumulator, one complex sample per line):
//!
//! ```text
//! RX OK WInd(0735), HLP(0745.3125), PSC(0274), SLP(0000.0000), RC(0095 3B8FDBD7), DCR(0), DCI(0), NTH(077A), T(83BD), RSL(-078.9641), FSL(-081.7507), RSMPL(31)
//! Accum Len 1016
//! -24, 100
//! ...
//! ```
//!
//! Between frames come ranging lines (`Rx time`, `RX DATA`, `Anchor ToF`, ...),
//! which are ignored. Of the header we interpret `HLP`, the chip's own
//! leading-edge (first path) index in taps with a 6-bit fraction; `RC`, the raw
//! 40-bit receive timestamp in two hex words (high, low), in units of
//! 1 / (128 x 499.2 MHz) = 15.65 ps (it matches the seconds of the `Rx time`
//! line before the header); `RSL` and `FSL`, the receive and first-path
//! signal levels in dBm. Every `NAME(value)` pair is also kept as written.
//! Receptions whose header is not `RX OK` (the sample has one `RX E` with error
//! flags instead of `HLP`) are skipped with their accumulator and reported by
//! header line.
//!
//! Choices:
//! - Tap spacing: the DW1000 accumulator is sampled at 2 x 499.2 MHz =
//!   998.4 MHz, so taps are 1.0016 ns apart ([`DecawaveConfig::tap_spacing_s`]).
//! - Carrier: channel 2's centre, 3993.6 MHz, by default. When the log names
//!   its channel and the configured carrier is not that channel's centre, the
//!   log is refused rather than labelled with the wrong carrier.
//! - Time: the log has no absolute time per frame (the file name has a local
//!   date and time without time zone). By default frames are timed by their
//!   `RC` receive timestamp, unwrapped across the counter's 17.2 s wrap, with
//!   the first frame at [`DecawaveConfig::t0_ns`]; a gap of more than 17.2 s
//!   between two frames cannot be seen and would shorten the time line.
//!   [`DecawaveTimeBase::FramePeriod`] instead gives `t0_ns + index * period`.
//! - Delay: tap 0 is at delay 0 (the accumulator's own start) by default;
//!   [`DecawaveDelayReference::FirstPath`] puts the chip's first path (`HLP`)
//!   at delay 0, as the dataset authors' `loadCIR.py` does.
//! - `HLP` is also kept on the snapshot as
//!   [`CirSnapshot::first_path_hint_s`] = `delay_offset_s + HLP * tap_spacing_s`
//!   (0 under [`DecawaveDelayReference::FirstPath`]).
//! - `set_index` is the index of the frame among the `RX OK` frames (0-based;
//!   error messages use the same "frame N"), `snapshot_index` and antennas 0.
//!
//! Real data used by the tests: file `1.log` of M. Kolakowski, "UWB Channel
//! Impulse Responses Registered in a Furnished Apartment" (2021), Zenodo,
//! doi:10.5281/zenodo.4742391, CC BY 4.0 (collected for M. Kolakowski and
//! J. Modelski, "Detection of direct path component absence in NLOS UWB
//! channel", MIKON 2018).

use std::path::Path;

use mmtrack_core::{CirSnapshot, Complex64};

use crate::IngestError;

/// DW1000 accumulator sample rate, hertz (2 x 499.2 MHz).
pub const DW1000_ACCUMULATOR_RATE_HZ: f64 = 998.4e6;
/// DW1000 timestamp counter rate, hertz (128 x 499.2 MHz).
pub const DW1000_TIMESTAMP_RATE_HZ: f64 = 63.8976e9;
/// The timestamp counter is 40 bits wide.
const TIMESTAMP_WRAP: u64 = 1 << 40;

/// Centre frequency of a DW1000 channel, hertz (IEEE 802.15.4a channels 1-5 and 7).
#[must_use]
pub fn dw1000_channel_carrier_hz(channel: u32) -> Option<f64> {
    match channel {
        1 => Some(3494.4e6),
        2 | 4 => Some(3993.6e6),
        3 => Some(4492.8e6),
        5 | 7 => Some(6489.6e6),
        _ => None,
    }
}

/// How frames are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecawaveTimeBase {
    /// From the `RC` receive timestamp, unwrapped; the first frame at `t0_ns`.
    RxTimestamp,
    /// `t0_ns + frame_index * period_ns`.
    FramePeriod {
        /// Time between frames, nanoseconds (> 0).
        period_ns: i64,
    },
}

/// Which delay tap 0 is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecawaveDelayReference {
    /// Tap 0 at delay 0: delays count from the accumulator's start.
    AccumulatorStart,
    /// The chip's first path (`HLP`) at delay 0: `delay_offset_s = -HLP * tap_spacing_s`.
    FirstPath,
}

/// What the log does not say, or says in a way we let the caller override.
#[derive(Debug, Clone, PartialEq)]
pub struct DecawaveConfig {
    /// Carrier, hertz. Default: channel 2, 3993.6 MHz.
    pub carrier_hz: f64,
    /// Tap spacing, seconds. Default: 1 / 998.4 MHz = 1.0016 ns.
    pub tap_spacing_s: f64,
    /// How frames are timed. Default: [`DecawaveTimeBase::RxTimestamp`].
    pub time_base: DecawaveTimeBase,
    /// Time of the first frame, nanoseconds. Default 0.
    pub t0_ns: i64,
    /// Delay of tap 0. Default: [`DecawaveDelayReference::AccumulatorStart`].
    pub delay_reference: DecawaveDelayReference,
}

impl Default for DecawaveConfig {
    fn default() -> Self {
        Self {
            carrier_hz: 3993.6e6,
            tap_spacing_s: 1.0 / DW1000_ACCUMULATOR_RATE_HZ,
            time_base: DecawaveTimeBase::RxTimestamp,
            t0_ns: 0,
            delay_reference: DecawaveDelayReference::AccumulatorStart,
        }
    }
}

/// One `RX OK` frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DecawaveFrame {
    /// The accumulator as a CIR.
    pub cir: CirSnapshot,
    /// The chip's hardware first-path (leading-edge) index, taps (`HLP`).
    pub hlp_taps: f64,
    /// Raw 40-bit receive timestamp (`RC`), units of 1 / 63.8976 GHz.
    pub rx_timestamp_ticks: Option<u64>,
    /// Receive signal level, dBm (`RSL`).
    pub rx_level_dbm: Option<f64>,
    /// First-path signal level, dBm (`FSL`).
    pub first_path_level_dbm: Option<f64>,
    /// Line of the header, 1-based.
    pub header_line: usize,
    /// Every `NAME(value)` pair of the header, as written.
    pub header_fields: Vec<(String, String)>,
}

/// Everything a log gave.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DecawaveLog {
    /// The `RX OK` frames in file order.
    pub frames: Vec<DecawaveFrame>,
    /// Channel named by the log's `Mode:` line.
    pub channel: Option<u32>,
    /// Header lines (1-based) of receptions that were not `RX OK`, skipped.
    pub skipped_receptions: Vec<usize>,
}

/// Parses a DecaRanging log into its `RX OK` frames (see [`parse_decawave_log_detailed`]).
pub fn parse_decawave_log(path: &Path, text: &str, config: &DecawaveConfig) -> Result<Vec<DecawaveFrame>, IngestError> {
    parse_decawave_log_detailed(path, text, config).map(|log| log.frames)
}

/// Reads and parses a DecaRanging log file. Bytes that are not UTF-8 are
/// replaced (they only occur in lines this reader ignores or rejects).
pub fn read_decawave_log(path: &Path, config: &DecawaveConfig) -> Result<DecawaveLog, IngestError> {
    let bytes = crate::error::read_capped(path, &mmtrack_core::limits::TEXT_FILE_BYTES)?;
    parse_decawave_log_detailed(path, &String::from_utf8_lossy(&bytes), config)
}

/// A reception header waiting for its `Accum Len`.
struct Pending {
    line: usize,
    /// `None` for a reception that is not `RX OK`.
    header: Option<Header>,
}

struct Header {
    fields: Vec<(String, String)>,
    hlp_taps: f64,
    rx_timestamp_ticks: Option<u64>,
    rx_level_dbm: Option<f64>,
    first_path_level_dbm: Option<f64>,
}

/// Parses a DecaRanging log: frames, channel and skipped receptions. Errors
/// name the frame (0-based, as `set_index`), the line and the field.
pub fn parse_decawave_log_detailed(
    path: &Path,
    text: &str,
    config: &DecawaveConfig,
) -> Result<DecawaveLog, IngestError> {
    check_config(path, config)?;
    let lines: Vec<&str> = text.lines().collect();
    let mut log = DecawaveLog::default();
    let mut pending: Option<Pending> = None;
    let mut first_ticks: Option<u64> = None;
    let mut unwrap = Unwrapper::default();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        let line_no = i + 1;
        let frame = log.frames.len();
        let bad = |line_no: usize, field: &str, detail: String| IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("frame {frame} (line {line_no})"),
            field: field.into(),
            detail,
        };
        let unfinished = |p: &Pending| {
            bad(
                p.line,
                "Accum Len",
                format!("RX OK header not followed by `Accum Len <n>` (line {line_no} is `{}`)", excerpt(line)),
            )
        };
        if let Some(rest) = line.strip_prefix("RX OK") {
            if let Some(p) = pending.as_ref().filter(|p| p.header.is_some()) {
                return Err(unfinished(p));
            }
            let header = parse_header(rest).map_err(|(field, detail)| bad(line_no, field, detail))?;
            pending = Some(Pending { line: line_no, header: Some(header) });
        } else if line.starts_with("RX ") && line.contains('(') {
            if let Some(p) = pending.as_ref().filter(|p| p.header.is_some()) {
                return Err(unfinished(p));
            }
            log.skipped_receptions.push(line_no);
            pending = Some(Pending { line: line_no, header: None });
        } else if let Some(count) = line.strip_prefix("Accum Len") {
            let taps_count = match count.trim().parse::<usize>() {
                Ok(n) if n > 0 => n,
                _ => {
                    return Err(bad(
                        line_no,
                        "Accum Len",
                        format!("`{}`, expected a positive tap count", excerpt(line)),
                    ));
                }
            };
            let Some(p) = pending.take() else {
                return Err(bad(line_no, "Accum Len", "no `RX OK` header before the accumulator".into()));
            };
            let available = lines.len() - (i + 1);
            if available < taps_count {
                return Err(bad(
                    line_no,
                    "Accum Len",
                    format!("promises {taps_count} I/Q lines, the file ends after {available} (truncated?)"),
                ));
            }
            let samples = &lines[i + 1..i + 1 + taps_count];
            i += 1 + taps_count;
            // The next line that is not blank must not be one more sample.
            if let Some(k) = lines[i..].iter().position(|l| !l.trim().is_empty())
                && parse_iq(lines[i + k].trim()).is_some()
            {
                return Err(bad(
                    i + k + 1,
                    "Accum Len",
                    format!(
                        "`Accum Len {taps_count}` (line {line_no}) but another I/Q line follows its {taps_count} \
                         samples: expected the header's count to match the accumulator"
                    ),
                ));
            }
            let Some(header) = p.header else {
                continue;
            };
            if header.hlp_taps >= taps_count as f64 {
                return Err(bad(
                    p.line,
                    "HLP",
                    format!(
                        "first path at tap {}, beyond the accumulator of {taps_count} taps (`Accum Len`, line \
                         {line_no}): expected an index within it",
                        header.hlp_taps
                    ),
                ));
            }
            let mut taps = Vec::with_capacity(taps_count);
            for (k, sample) in samples.iter().enumerate() {
                let tap = parse_iq(sample).ok_or_else(|| {
                    bad(
                        line_no + 1 + k,
                        "I/Q",
                        format!(
                            "accumulator sample {k} of {taps_count}: expected two integers `I, Q`, found `{}`",
                            excerpt(sample)
                        ),
                    )
                })?;
                taps.push(tap);
            }
            let t_ns = match config.time_base {
                DecawaveTimeBase::RxTimestamp => {
                    let Some(ticks) = header.rx_timestamp_ticks else {
                        return Err(bad(
                            p.line,
                            "RC",
                            "missing; the RX timestamp time base needs RC(<hex> <hex>) in the header \
                             (or use a frame period)"
                                .into(),
                        ));
                    };
                    let first = *first_ticks.get_or_insert(ticks);
                    let elapsed = unwrap.unwrapped(ticks).saturating_sub(first);
                    // ns = ticks / 63.8976 = ticks * 10_000 / 638_976, rounded.
                    let ns = (i128::from(elapsed) * 10_000 + 319_488) / 638_976;
                    i64::try_from(ns).ok().and_then(|ns| ns.checked_add(config.t0_ns))
                }
                DecawaveTimeBase::FramePeriod { period_ns } => i64::try_from(frame)
                    .ok()
                    .and_then(|k| k.checked_mul(period_ns))
                    .and_then(|t| t.checked_add(config.t0_ns)),
            }
            .ok_or_else(|| bad(p.line, "time", "overflows i64 nanoseconds".into()))?;
            let delay_offset_s = match config.delay_reference {
                DecawaveDelayReference::AccumulatorStart => 0.0,
                DecawaveDelayReference::FirstPath => -header.hlp_taps * config.tap_spacing_s,
            };
            let cir = CirSnapshot {
                t_ns,
                set_index: frame as u64,
                snapshot_index: 0,
                tx_antenna: 0,
                rx_antenna: 0,
                carrier_hz: config.carrier_hz,
                tap_spacing_s: config.tap_spacing_s,
                delay_offset_s,
                taps,
                first_path_hint_s: Some(delay_offset_s + header.hlp_taps * config.tap_spacing_s),
            };
            cir.validate().map_err(|e| bad(p.line, "CIR", e.to_string()))?;
            log.frames.push(DecawaveFrame {
                cir,
                hlp_taps: header.hlp_taps,
                rx_timestamp_ticks: header.rx_timestamp_ticks,
                rx_level_dbm: header.rx_level_dbm,
                first_path_level_dbm: header.first_path_level_dbm,
                header_line: p.line,
                header_fields: header.fields,
            });
            continue;
        } else {
            if let Some(p) = pending.as_ref().filter(|p| p.header.is_some() && !line.is_empty()) {
                return Err(unfinished(p));
            }
            if !line.is_empty() {
                // A non-OK reception without an accumulator: nothing to skip.
                pending = None;
            }
            if let Some(settings) = line.strip_prefix("Mode:") {
                log.channel = channel_of(settings);
                check_carrier(path, line_no, log.channel, config)?;
            }
        }
        i += 1;
    }
    if let Some(p) = pending.filter(|p| p.header.is_some()) {
        return Err(IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("frame {} (line {})", log.frames.len(), p.line),
            field: "Accum Len".into(),
            detail: "the file ends after the RX OK header, before its accumulator (truncated?)".into(),
        });
    }
    Ok(log)
}

fn check_config(path: &Path, config: &DecawaveConfig) -> Result<(), IngestError> {
    let bad = |detail: String| Err(IngestError::BadLayout { path: path.to_path_buf(), detail });
    if !(config.tap_spacing_s.is_finite() && config.tap_spacing_s > 0.0) {
        return bad(format!("config: tap spacing {} s, expected a positive finite value", config.tap_spacing_s));
    }
    if !(config.carrier_hz.is_finite() && config.carrier_hz >= 0.0) {
        return bad(format!("config: carrier {} Hz, expected a finite value >= 0", config.carrier_hz));
    }
    match config.time_base {
        DecawaveTimeBase::FramePeriod { period_ns } if period_ns <= 0 => {
            bad(format!("config: frame period {period_ns} ns, expected > 0"))
        }
        _ => Ok(()),
    }
}

/// `Chan N` from the settings line.
fn channel_of(settings: &str) -> Option<u32> {
    settings.split(',').find_map(|item| item.trim().strip_prefix("Chan")?.trim().parse().ok())
}

fn check_carrier(
    path: &Path,
    line_no: usize,
    channel: Option<u32>,
    config: &DecawaveConfig,
) -> Result<(), IngestError> {
    let Some(channel) = channel else {
        return Ok(());
    };
    match dw1000_channel_carrier_hz(channel) {
        Some(centre_hz) if (centre_hz - config.carrier_hz).abs() <= 1e3 => Ok(()),
        centre_hz => Err(IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("line {line_no}"),
            field: "Chan".into(),
            detail: format!(
                "the log says channel {channel} ({}) but the configured carrier is {} MHz; set carrier_hz to match",
                centre_hz.map_or("not a DW1000 channel".to_string(), |hz| format!("centre {} MHz", hz / 1e6)),
                config.carrier_hz / 1e6
            ),
        }),
    }
}

/// Parses `NAME(value), NAME(value), ...` after `RX OK`.
fn parse_header(text: &str) -> Result<Header, (&'static str, String)> {
    let mut fields = Vec::new();
    let mut rest = text;
    loop {
        rest = rest.trim_start_matches([' ', ',', '\t']);
        if rest.is_empty() {
            break;
        }
        let Some((name, after)) = rest.split_once('(') else {
            return Err(("header", format!("expected NAME(value) items, found `{}`", excerpt(rest))));
        };
        let Some((value, after)) = after.split_once(')') else {
            return Err(("header", format!("`{}` has no closing parenthesis", excerpt(rest))));
        };
        fields.push((name.trim().to_string(), value.trim().to_string()));
        rest = after;
    }
    let get = |name: &str| fields.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str());
    let hlp_taps = match get("HLP").map(|v| (v, v.parse::<f64>())) {
        None => return Err(("HLP", "missing; expected HLP(<first path index>) in the RX OK header".into())),
        Some((_, Ok(hlp))) if hlp.is_finite() && hlp >= 0.0 => hlp,
        Some((value, _)) => {
            return Err(("HLP", format!("`{}`, expected a non-negative number of taps", excerpt(value))));
        }
    };
    let rx_timestamp_ticks = match get("RC") {
        None => None,
        Some(value) => Some(parse_rx_timestamp(value).ok_or_else(|| {
            ("RC", format!("`{}`, expected a 40-bit timestamp as two hex words `HHHH LLLLLLLL`", excerpt(value)))
        })?),
    };
    let level = |name: &'static str| -> Result<Option<f64>, (&'static str, String)> {
        match get(name) {
            None => Ok(None),
            Some(value) => match value.parse::<f64>() {
                Ok(dbm) if dbm.is_finite() => Ok(Some(dbm)),
                _ => Err((name, format!("`{}`, expected a level in dBm", excerpt(value)))),
            },
        }
    };
    Ok(Header {
        hlp_taps,
        rx_timestamp_ticks,
        rx_level_dbm: level("RSL")?,
        first_path_level_dbm: level("FSL")?,
        fields,
    })
}

/// `0095 3B8FDBD7` -> 0x95_3B8F_DBD7.
fn parse_rx_timestamp(value: &str) -> Option<u64> {
    let mut words = value.split_whitespace();
    let high = u64::from_str_radix(words.next()?, 16).ok()?;
    let low = u32::from_str_radix(words.next()?, 16).ok()?;
    if words.next().is_some() {
        return None;
    }
    let ticks = high.checked_shl(32)? | u64::from(low);
    (high < 1 << 8).then_some(ticks)
}

/// `-24, 100` -> -24 + 100 j.
fn parse_iq(line: &str) -> Option<Complex64> {
    let (i, q) = line.split_once(',')?;
    let i: i32 = i.trim().parse().ok()?;
    let q: i32 = q.trim().parse().ok()?;
    Some(Complex64::new(f64::from(i), f64::from(q)))
}

/// Unwraps the 40-bit timestamp counter.
#[derive(Default)]
struct Unwrapper {
    previous: Option<u64>,
    wraps: u64,
}

impl Unwrapper {
    fn unwrapped(&mut self, ticks: u64) -> u64 {
        if self.previous.is_some_and(|p| ticks < p) {
            self.wraps += 1;
        }
        self.previous = Some(ticks);
        ticks.saturating_add(self.wraps.saturating_mul(TIMESTAMP_WRAP))
    }
}

/// At most 60 characters of a line, for messages.
fn excerpt(text: &str) -> String {
    let mut out: String = text.chars().take(60).collect();
    if out.len() < text.len() {
        out.push_str("...");
    }
    out.escape_debug().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    const PREAMBLE: &str = "File:20180108-115817_DecaWaveAllAccum.log, created by DecaRanging MP Version 3.05\n\
        Mode: 2, Chan 2, Code 9, PRF 64, Plength 1024, DataRate 1, PAC 2, ic:1000fa35, ucode:xxxx, antdl:808A\n\n";

    fn frame(hlp: &str, rc: &str, taps: &[(i32, i32)]) -> String {
        let mut out = format!(
            "21 4B Rx time = 1.003088395769168e+001 953B8FDBD7\n\ntxdly 4045 rxdly 4045\nRX DATA: 41cc4bca\n\n\
             RX OK WInd(0735), HLP({hlp}), PSC(0274), SLP(0000.0000), RC({rc}), DCR(0), DCI(0), NTH(077A), \
             T(83BD), RSL(-078.9641), FSL(-081.7507), RSMPL(31)\nAccum Len {}\n",
            taps.len()
        );
        for (i, q) in taps {
            out.push_str(&format!("{i}, {q}\n"));
        }
        out.push_str("\nAnchor ToF: 8.986 ns Dist: 2.693148 m\n\n");
        out
    }

    const ERROR_RECEPTION: &str = "RX E\0 WInd(0735), PSC(0264), CE(0000), RSE(0000), HE(0000), STO(0001), \
        FFE(0000), T(82BE), RSL(-078.4136), FSL(-081.8368), RSMPL(34)\nAccum Len 2\n725, 443\n525, 158\n\n";

    fn sample_log() -> String {
        // Three taps a frame, so first paths (HLP) at taps 1 and 2.
        // Second frame's RC is below the first: the 40-bit counter wrapped.
        let mut text = PREAMBLE.to_string();
        text.push_str(&frame("0001.3125", "00FF FFFFFFF0", &[(-24, 100), (-242, 87), (5, -6)]));
        text.push_str(ERROR_RECEPTION);
        text.push_str(&frame("0002.2969", "0000 00000010", &[(1, 2), (3, 4), (5, 6)]));
        text
    }

    #[test]
    fn frames_headers_and_wrapped_time() {
        let path = Path::new("1.log");
        for text in [sample_log(), sample_log().replace('\n', "\r\n")] {
            let log = parse_decawave_log_detailed(path, &text, &DecawaveConfig::default()).unwrap();
            assert_eq!(log.channel, Some(2));
            assert_eq!(log.frames.len(), 2);
            assert_eq!(log.skipped_receptions.len(), 1);
            let [a, b] = &log.frames[..] else { unreachable!() };
            assert_eq!(
                a.cir.taps,
                [Complex64::new(-24.0, 100.0), Complex64::new(-242.0, 87.0), Complex64::new(5.0, -6.0)]
            );
            assert_eq!((a.hlp_taps, b.hlp_taps), (1.3125, 2.2969));
            assert_eq!(a.rx_timestamp_ticks, Some(0xFF_FFFF_FFF0));
            assert_eq!((a.rx_level_dbm, a.first_path_level_dbm), (Some(-78.9641), Some(-81.7507)));
            assert_eq!(a.header_fields[2], ("PSC".to_string(), "0274".to_string()));
            assert_eq!((a.cir.set_index, b.cir.set_index), (0, 1));
            assert_eq!((a.cir.carrier_hz, a.cir.delay_offset_s), (3993.6e6, 0.0));
            assert!((a.cir.tap_spacing_s - 1.001_602_564e-9).abs() < 1e-18);
            // HLP kept as a delay: 1.3125 taps of 1.0016 ns (1e-21 s: rounding of one product).
            assert!((a.cir.first_path_hint_s.unwrap() - 1.3125 / 998.4e6).abs() < 1e-21);
            // 0x20 ticks across the wrap = 32 / 63.8976 GHz = 0.5 ns, rounded to 1 ns.
            assert_eq!((a.cir.t_ns, b.cir.t_ns), (0, 1));
            assert_eq!(text.lines().nth(b.header_line - 1).map(|l| l.starts_with("RX OK")), Some(true));
        }
    }

    #[test]
    fn frame_period_and_first_path_options() {
        let config = DecawaveConfig {
            time_base: DecawaveTimeBase::FramePeriod { period_ns: 350_000_000 },
            t0_ns: 1_000,
            delay_reference: DecawaveDelayReference::FirstPath,
            ..DecawaveConfig::default()
        };
        let frames = parse_decawave_log(Path::new("1.log"), &sample_log(), &config).unwrap();
        assert_eq!(frames.iter().map(|f| f.cir.t_ns).collect::<Vec<_>>(), [1_000, 350_001_000]);
        let f = &frames[0];
        assert!((f.cir.delay_s(1) - (1.0 - 1.3125) * f.cir.tap_spacing_s).abs() < 1e-18);
        // The HLP hint sits at delay 0 when the first path is the reference.
        assert_eq!(f.cir.first_path_hint_s, Some(0.0));
        // The frame period does not need RC.
        let no_rc = sample_log().replace("RC(00FF FFFFFFF0), ", "");
        assert_eq!(parse_decawave_log(Path::new("1.log"), &no_rc, &config).unwrap().len(), 2);
        let err = parse_decawave_log(Path::new("1.log"), &no_rc, &DecawaveConfig::default()).unwrap_err().to_string();
        assert!(err.contains("frame 0 (line ") && err.contains(": RC: missing"), "{err}");
    }

    fn err_of(text: &str) -> String {
        parse_decawave_log(Path::new("bad.log"), text, &DecawaveConfig::default()).unwrap_err().to_string()
    }

    #[test]
    fn bad_inputs_are_named() {
        let good = sample_log();
        let line_of = |needle: &str| good.lines().position(|l| l.contains(needle)).unwrap() + 1;
        // Truncated: Accum Len promises more lines than the file has.
        let cut = &good[..good.find("3, 4\n").unwrap()];
        let err = err_of(cut);
        let accum = cut.lines().collect::<Vec<_>>().iter().rposition(|l| l.starts_with("Accum Len")).unwrap() + 1;
        assert!(err.starts_with("bad.log: frame 1 (line "), "{err}");
        assert!(
            err.contains(&format!("line {accum})")) && err.contains("promises 3 I/Q lines") && err.contains("after 1")
        );
        // A non-integer I or Q.
        let err = err_of(&good.replace("-242, 87", "-242, 8.7"));
        let line = line_of("-242, 87");
        assert!(err.contains(&format!("frame 0 (line {line}): I/Q: accumulator sample 1 of 3")), "{err}");
        assert!(err.contains("`-242, 8.7`"), "{err}");
        let err = err_of(&good.replace("-242, 87", "-242"));
        assert!(err.contains("I/Q") && err.contains(&format!("line {line}")), "{err}");
        // The next header where I/Q lines were promised.
        let err = err_of(&good.replace("Accum Len 3", "Accum Len 4"));
        assert!(err.contains("I/Q") && err.contains("found ``"), "{err}");
        // More I/Q lines than `Accum Len` says (before: the surplus was
        // dropped), and a first path beyond the accumulator (before: kept).
        let surplus = good.replace("-24, 100\n-242, 87\n5, -6\n", "-24, 100\n-242, 87\n5, -6\n7, 8\n");
        let err = err_of(&surplus);
        let extra = surplus.lines().position(|l| l == "7, 8").unwrap() + 1;
        assert!(
            err.starts_with(&format!(
                "bad.log: frame 0 (line {extra}): Accum Len: `Accum Len 3` (line {}) but",
                extra - 4
            )) && err.contains("another I/Q line follows its 3 samples"),
            "{err}"
        );
        let err = err_of(&good.replace("HLP(0001.3125)", "HLP(99999.0)"));
        assert!(
            err.starts_with(&format!("bad.log: frame 0 (line {}): HLP: first path at tap 99999", line_of("HLP(0001")))
                && err.contains("beyond the accumulator of 3 taps"),
            "{err}"
        );
        let err = err_of(&good.replace("HLP(0001.3125)", "HLP(3.0)"));
        assert!(err.contains("HLP: first path at tap 3, beyond the accumulator of 3 taps"), "{err}");
        // A missing or malformed HLP.
        let err = err_of(&good.replace("HLP(0002.2969), ", ""));
        assert!(err.contains(&format!("frame 1 (line {}): HLP: missing", line_of("HLP(0002.2969)"))), "{err}");
        let err = err_of(&good.replace("HLP(0001.3125)", "HLP(74x)"));
        assert!(err.contains("frame 0") && err.contains("HLP: `74x`"), "{err}");
        // A header without accumulator, an accumulator without header.
        let err = err_of(&good.replace("Accum Len 3\n-24", "-24"));
        assert!(err.contains("frame 0") && err.contains("not followed by `Accum Len"), "{err}");
        let err = err_of(&format!("{PREAMBLE}Accum Len 2\n1, 2\n3, 4\n"));
        assert!(err.contains("line 4") && err.contains("no `RX OK` header"), "{err}");
        let err = err_of(&format!("{PREAMBLE}RX OK HLP(1), RC(0 0)\n"));
        assert!(err.contains("ends after the RX OK header"), "{err}");
        let err = err_of(&good.replace("Accum Len 3", "Accum Len 0"));
        assert!(err.contains("positive tap count"), "{err}");
        // A log of another channel with the default (channel 2) carrier.
        let err = err_of(&good.replace("Chan 2", "Chan 5"));
        assert!(err.contains("line 2: Chan: the log says channel 5 (centre 6489.6 MHz)"), "{err}");
        let ch5 = DecawaveConfig { carrier_hz: 6489.6e6, ..DecawaveConfig::default() };
        let frames = parse_decawave_log(Path::new("1.log"), &good.replace("Chan 2", "Chan 5"), &ch5).unwrap();
        assert_eq!(frames[0].cir.carrier_hz, 6489.6e6);
        // Bad RC, bad config.
        let err = err_of(&good.replace("RC(00FF FFFFFFF0)", "RC(01FF FFFFFFF0)"));
        assert!(err.contains("RC: `01FF FFFFFFF0`, expected a 40-bit timestamp"), "{err}");
        let bad_period =
            DecawaveConfig { time_base: DecawaveTimeBase::FramePeriod { period_ns: 0 }, ..Default::default() };
        assert!(parse_decawave_log(Path::new("1.log"), &good, &bad_period).is_err());
        // Every truncation is an error or a shorter list of frames, never a panic.
        for cut in (0..good.len()).filter(|&c| good.is_char_boundary(c)) {
            if let Ok(frames) = parse_decawave_log(Path::new("1.log"), &good[..cut], &DecawaveConfig::default()) {
                assert!(frames.len() <= 2);
            }
        }
    }

    const REAL_LOG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/realdata/uwb-cirs-2018/1.log");

    /// Kolakowski, "UWB Channel Impulse Responses Registered in a Furnished
    /// Apartment", Zenodo 10.5281/zenodo.4742391, CC BY 4.0: file 1.log.
    #[test]
    fn real_kolakowski_uwb_log() {
        let path = Path::new(REAL_LOG);
        if !path.exists() {
            eprintln!("skipped: real data not found at {REAL_LOG}");
            return;
        }
        let log = read_decawave_log(path, &DecawaveConfig::default()).unwrap();
        assert_eq!(log.channel, Some(2));
        assert_eq!(log.frames.len(), 252);
        assert!(log.frames.iter().all(|f| f.cir.taps.len() == 1016 && f.cir.validate().is_ok()));
        // One reception with error flags (`RX E`) and its accumulator is skipped.
        assert_eq!(log.skipped_receptions, [61985]);
        let first = &log.frames[0];
        assert_eq!((first.header_line, first.hlp_taps), (11, 745.3125));
        assert_eq!(first.rx_timestamp_ticks, Some(0x95_3B8F_DBD7));
        assert_eq!(first.cir.taps[0], Complex64::new(-24.0, 100.0));
        let last = &log.frames[251];
        assert_eq!((last.header_line, last.hlp_taps), (260_311, 750.5313));
        assert_eq!((last.cir.taps[0], last.cir.taps[1015]), (Complex64::new(9.0, -54.0), Complex64::new(88.0, 52.0)));
        // HLP: the chip's first path, median 747.51 taps, all within 718.6-814.8.
        let mut hlp: Vec<f64> = log.frames.iter().map(|f| f.hlp_taps).collect();
        hlp.sort_by(f64::total_cmp);
        assert_eq!((hlp[0], hlp[251]), (718.625, 814.7188));
        assert!(((hlp[125] + hlp[126]) / 2.0 - 747.507_85).abs() < 1e-9);
        // Timed by the RX timestamp: 8 counter wraps, frames 0.35-0.68 s apart, 128.6 s in all.
        let t: Vec<i64> = log.frames.iter().map(|f| f.cir.t_ns).collect();
        assert_eq!(t[0], 0);
        assert!(t.windows(2).all(|w| (349_000_000..677_000_000).contains(&(w[1] - w[0]))), "{t:?}");
        assert!((t[251] - 128_601_623_203).abs() <= 1, "{}", t[251]);
        // In every frame the strongest tap lies 0.7-4.8 taps after the chip's first path.
        for f in &log.frames {
            let peak = (0..1016).max_by(|&a, &b| f.cir.taps[a].norm().total_cmp(&f.cir.taps[b].norm())).unwrap();
            let after = peak as f64 - f.hlp_taps;
            assert!((0.5..5.0).contains(&after), "frame {}: peak {peak}, HLP {}", f.cir.set_index, f.hlp_taps);
        }
    }

    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        /// Arbitrary text, and a valid log with lines cut, swapped or garbled, never panics.
        #[test]
        fn parser_never_panics(
            junk in "(RX OK |Accum Len |HLP\\(|RC\\(|[-0-9, ()A-Za-z\n\r.])*",
            edits in proptest::collection::vec((any::<usize>(), any::<usize>(), "[-0-9a-zA-Z ,()\r\n]{0,12}"), 1..6),
        ) {
            let config = DecawaveConfig::default();
            let _ = parse_decawave_log(Path::new("p.log"), &junk, &config);
            let mut lines: Vec<String> = sample_log().lines().map(str::to_string).collect();
            for (at, other, text) in edits {
                let (at, other) = (at % lines.len(), other % lines.len());
                match other % 3 {
                    0 => lines[at] = text,
                    1 => lines.swap(at, other),
                    _ => { lines.remove(at); }
                }
                if lines.is_empty() { break; }
            }
            let _ = parse_decawave_log(Path::new("p.log"), &lines.join("\n"), &config);
            let period = DecawaveConfig { time_base: DecawaveTimeBase::FramePeriod { period_ns: i64::MAX }, ..config };
            let _ = parse_decawave_log(Path::new("p.log"), &lines.join("\n"), &period);
        }
    }
}
