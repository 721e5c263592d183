//! The checks and conversions of ingest options that every front end shares
//! (the CLI's flags, the Python package's keywords): one place for each
//! rule and its message, which names the flag as the CLI spells it.

use crate::beams::VehiclePositions;
use crate::sweep::{StampAt, SweepTiming};

/// `value` when it is a positive, finite number of metres.
///
/// # Errors
/// Anything else, naming `flag`.
pub fn positive_metres(flag: &str, value: f64) -> Result<f64, String> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(format!("{flag} {value}: expected a positive number of metres"))
    }
}

/// `--bins`: range bins per azimuth, or `auto` (`None`: the PNG width as it is).
///
/// # Errors
/// Neither a number nor `auto`.
pub fn parse_bins(text: &str) -> Result<Option<usize>, String> {
    match text {
        "auto" => Ok(None),
        n => n.parse::<usize>().map(Some).map_err(|e| format!("--bins '{n}': expected a number or `auto`: {e}")),
    }
}

/// `--stamp-at` (`start` or `end`) and `--scan-period-s` of polar images
/// that carry one stamp per sweep.
///
/// # Errors
/// An unknown stamp position, or a period that is not a positive number of
/// seconds below 60.
pub fn sweep_timing(stamp_at: &str, scan_period_s: f64) -> Result<SweepTiming, String> {
    let stamp_at = match stamp_at {
        "start" => StampAt::Start,
        "end" => StampAt::End,
        other => return Err(format!("--stamp-at '{other}': expected start or end")),
    };
    if !(scan_period_s.is_finite() && scan_period_s > 0.0 && scan_period_s < 60.0) {
        return Err(format!("--scan-period-s {scan_period_s}: expected a positive number of seconds below 60"));
    }
    Ok(SweepTiming { period_ns: (scan_period_s * 1e9).round() as i64, stamp_at })
}

/// `--sweep-period-s` of `ingest beams`, in nanoseconds.
///
/// # Errors
/// Not a positive number of seconds below 3600.
pub fn sweep_period_ns(sweep_period_s: f64) -> Result<i64, String> {
    if !(sweep_period_s.is_finite() && sweep_period_s > 0.0 && sweep_period_s < 3600.0) {
        return Err(format!("--sweep-period-s {sweep_period_s}: expected a positive number of seconds below 3600"));
    }
    Ok((sweep_period_s * 1e9).round() as i64)
}

/// `--positions` of `ingest beams`: `raw`, `calibrated` or `auto`.
///
/// # Errors
/// Any other name.
pub fn vehicle_positions(name: &str) -> Result<VehiclePositions, String> {
    match name {
        "raw" => Ok(VehiclePositions::Raw),
        "calibrated" => Ok(VehiclePositions::Calibrated),
        "auto" => Ok(VehiclePositions::Auto),
        other => Err(format!("--positions '{other}': expected raw, calibrated or auto")),
    }
}

/// `--format` of `ingest cir`: `npy`, `npz`, `mat`, `hdf5`, `sigmf`, `csv`
/// or `decawave`.
///
/// # Errors
/// Any other name.
pub fn cir_format(name: &str) -> Result<crate::cir::CirFormat, String> {
    use crate::cir::CirFormat;
    Ok(match name {
        "npy" => CirFormat::Npy,
        "npz" => CirFormat::Npz,
        "mat" => CirFormat::Mat,
        "hdf5" => CirFormat::Hdf5,
        "sigmf" => CirFormat::Sigmf,
        "csv" => CirFormat::Csv,
        "decawave" => CirFormat::Decawave,
        other => return Err(format!("--format '{other}': expected npy, npz, mat, hdf5, sigmf, csv or decawave")),
    })
}

/// Whether the output must replace an existing file: `force`, or adding
/// to the output file itself (`--add-to` naming the output), which replaces
/// it once the new one is complete.
#[must_use]
pub fn replaces_output(add_to: Option<&std::path::Path>, output: &std::path::Path, force: bool) -> bool {
    force || add_to.is_some_and(|existing| existing.canonicalize().ok() == output.canonicalize().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_are_checked_with_the_cli_words() {
        assert_eq!(positive_metres("--range-resolution-m", 0.0438), Ok(0.0438));
        assert_eq!(
            positive_metres("--range-resolution-m", -1.0).unwrap_err(),
            "--range-resolution-m -1: expected a positive number of metres"
        );
        assert_eq!(parse_bins("auto"), Ok(None));
        assert_eq!(parse_bins("3768"), Ok(Some(3768)));
        assert!(parse_bins("many").unwrap_err().starts_with("--bins 'many': expected a number or `auto`: "));
        let timing = sweep_timing("start", 0.25).unwrap();
        assert_eq!((timing.period_ns, timing.stamp_at), (250_000_000, StampAt::Start));
        assert!(sweep_timing("end", 60.0).unwrap_err().starts_with("--scan-period-s 60:"));
        assert!(sweep_timing("middle", 0.25).unwrap_err().starts_with("--stamp-at 'middle'"));
        assert_eq!(sweep_period_ns(0.1), Ok(100_000_000));
        assert!(sweep_period_ns(0.0).is_err());
        assert_eq!(vehicle_positions("raw"), Ok(VehiclePositions::Raw));
        assert!(vehicle_positions("gps").is_err());
    }
}
