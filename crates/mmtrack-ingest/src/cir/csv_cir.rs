//! CIRs (or CFRs) in CSV, one snapshot per row ("wide" format).
//!
//! We chose one snapshot per row over a long format (one tap per row) because
//! it is what `numpy.savetxt` and spreadsheet exports of sounder data give,
//! it needs no grouping or sorting, and a missing tap cannot go unnoticed.
//!
//! The first non-comment line is the header. Columns, in this order:
//! - optional `t_ns` (integer ns since the UNIX epoch, increasing on each link), `set_index`,
//!   `snapshot_index`, `tx_antenna`, `rx_antenna` (non-negative integers; each
//!   may be left out: antennas default to 0, the indices follow from the row
//!   number and the sidecar's `snapshots_per_set`, and times from the sidecar's
//!   `t0_ns`, `snapshot_period_s` and `set_period_s` by that same ordinal);
//! - `re_0, im_0, re_1, im_1, ..., re_<N-1>, im_<N-1>`: N taps (or CFR bins),
//!   complete, contiguous and in order.
//!
//! Any other column, a duplicate, a gap in the tap numbering or a row with the
//! wrong number of fields is an error naming the line and the column, and so
//! is a row whose set or time comes before the previous row of its link (tx,
//! rx antenna): each link's snapshots must be in set and time order. Lines
//! starting with `#` and blank lines are skipped, and so is a UTF-8 byte
//! order mark at the start of the file. Values that are NaN or
//! infinite are errors (a CIR with a hole is not a CIR).

use std::path::Path;

use mmtrack_core::{CirSnapshot, Complex64};
use rustfft::FftPlanner;

use super::array::{carrier_and_spacing, inverse_dft};
use super::sidecar::{CirSidecar, Domain};
use crate::IngestError;

const INDEX_COLUMNS: [&str; 5] = ["t_ns", "set_index", "snapshot_index", "tx_antenna", "rx_antenna"];

/// Parses CSV text into snapshots (see the module docs).
pub(crate) fn parse_cir_csv(path: &Path, text: &str, sidecar: &CirSidecar) -> Result<Vec<CirSnapshot>, IngestError> {
    let bad = |line: usize, field: &str, detail: String| IngestError::bad_line(path, line, field, detail);
    let mut lines = crate::csv::without_bom(text)
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(IngestError::BadLayout { path: path.to_path_buf(), detail: "empty: no header line".into() });
    };
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let index_count = columns.iter().take_while(|c| INDEX_COLUMNS.contains(c)).count();
    let (index_cols, tap_cols) = columns.split_at(index_count);
    check_header(index_cols, tap_cols).map_err(|(field, detail)| bad(header_line, &field, detail))?;
    let n_taps = tap_cols.len() / 2;
    let (carrier_hz, tap_spacing_s) = carrier_and_spacing(path, sidecar, n_taps, None)?;
    let has = |name: &str| index_cols.contains(&name);
    let per_set = u64::from(sidecar.snapshots_per_set.max(1));
    let rows: Vec<(usize, &str)> = lines.collect();
    let mut planner = FftPlanner::<f64>::new();
    let mut out = Vec::with_capacity(rows.len());
    let mut last_on_link = std::collections::BTreeMap::new();
    for (row, &(line, text)) in rows.iter().enumerate() {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != columns.len() {
            return Err(bad(line, "row", format!("{} fields, the header has {} columns", fields.len(), columns.len())));
        }
        let int = |name: &str| -> Result<Option<i64>, IngestError> {
            let Some(k) = index_cols.iter().position(|c| *c == name) else { return Ok(None) };
            // Times too: a recording's times are ns since its time base, never negative.
            let ok = fields[k].parse::<i64>().ok().filter(|v| *v >= 0);
            ok.map(Some).ok_or_else(|| bad(line, name, format!("`{}`, expected an integer >= 0", fields[k])))
        };
        let ordinal = match (int("set_index")?, int("snapshot_index")?) {
            (Some(set), Some(k)) => {
                (set as u64).checked_mul(per_set).and_then(|o| o.checked_add(k as u64)).ok_or_else(|| {
                    bad(line, "set_index", format!("set {set}, snapshot {k}: the snapshot's ordinal overflows u64"))
                })?
            }
            _ => row as u64,
        };
        let set_index = int("set_index")?.map_or(ordinal / per_set, |v| v as u64);
        let snapshot_index = int("snapshot_index")?.map_or(ordinal % per_set, |v| v as u64);
        let t_ns = match int("t_ns")? {
            Some(t) => t,
            None => sidecar.snapshot_time(ordinal as usize, if has("t_ns") { 1 } else { rows.len() })?.0,
        };
        let narrow = |name: &str, v: u64| u32::try_from(v).map_err(|_| bad(line, name, format!("{v} exceeds u32")));
        let mut taps = Vec::with_capacity(n_taps);
        for k in 0..n_taps {
            let value = |c: usize| -> Result<f64, IngestError> {
                let field = fields[index_count + c];
                match field.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(bad(line, tap_cols[c], format!("`{field}`, expected a finite number"))),
                }
            };
            taps.push(Complex64::new(value(2 * k)?, value(2 * k + 1)?));
        }
        if sidecar.domain == Domain::Cfr {
            inverse_dft(&mut planner, &mut taps);
        }
        let snapshot = CirSnapshot {
            t_ns,
            set_index,
            snapshot_index: narrow("snapshot_index", snapshot_index)?,
            tx_antenna: narrow("tx_antenna", int("tx_antenna")?.unwrap_or(0) as u64)?,
            rx_antenna: narrow("rx_antenna", int("rx_antenna")?.unwrap_or(0) as u64)?,
            carrier_hz,
            tap_spacing_s,
            delay_offset_s: sidecar.delay_offset_s,
            taps,
            first_path_hint_s: None,
        };
        snapshot.validate().map_err(|e| bad(line, "snapshot", e.to_string()))?;
        check_link_order(&mut last_on_link, line, &snapshot).map_err(|(field, detail)| bad(line, field, detail))?;
        out.push(snapshot);
    }
    if out.is_empty() {
        return Err(bad(header_line, "rows", "a header but no snapshot rows".into()));
    }
    Ok(out)
}

/// The line, set and time of the last snapshot of each link (tx, rx antenna).
type LastOnLink = std::collections::BTreeMap<(u32, u32), (usize, u64, i64)>;

/// Refuses a snapshot whose set comes before, or whose time is not after,
/// the previous snapshot of its link (what `process mpc` requires: each
/// link's snapshots in set and time order), naming the field and the line
/// of that previous snapshot.
fn check_link_order(last: &mut LastOnLink, line: usize, snapshot: &CirSnapshot) -> Result<(), (&'static str, String)> {
    let link = (snapshot.tx_antenna, snapshot.rx_antenna);
    if let Some(&(previous_line, set, t_ns)) = last.get(&link) {
        let on = format!("link tx{}:rx{}", link.0, link.1);
        if snapshot.set_index < set {
            return Err((
                "set_index",
                format!(
                    "set {} after set {set} (line {previous_line}) on {on}: expected each link's snapshots in set order",
                    snapshot.set_index
                ),
            ));
        }
        if snapshot.t_ns <= t_ns {
            let relation = if snapshot.t_ns == t_ns { "the same time as" } else { "before" };
            return Err((
                "t_ns",
                format!(
                    "{} ns, {relation} the {t_ns} ns of line {previous_line} on {on}: expected each link's snapshots \
                     in increasing time",
                    snapshot.t_ns
                ),
            ));
        }
    }
    last.insert(link, (line, snapshot.set_index, snapshot.t_ns));
    Ok(())
}

fn check_header(index_cols: &[&str], tap_cols: &[&str]) -> Result<(), (String, String)> {
    for (i, c) in index_cols.iter().enumerate() {
        if index_cols[..i].contains(c) {
            return Err((c.to_string(), "appears twice".into()));
        }
    }
    let order = index_cols.iter().map(|c| INDEX_COLUMNS.iter().position(|k| k == c)).collect::<Vec<_>>();
    if order.windows(2).any(|w| w[0] > w[1]) {
        return Err(("header".into(), format!("index columns in order {}", INDEX_COLUMNS.join(", "))));
    }
    if tap_cols.is_empty() {
        return Err(("header".into(), "no tap columns; expected re_0, im_0, re_1, im_1, ...".into()));
    }
    for (c, name) in tap_cols.iter().enumerate() {
        let expected = format!("{}_{}", if c % 2 == 0 { "re" } else { "im" }, c / 2);
        if *name != expected {
            let known = INDEX_COLUMNS.contains(name);
            return Err((
                name.to_string(),
                format!(
                    "column {} is `{name}`, expected `{expected}`{}",
                    index_cols.len() + c + 1,
                    if known { " (index columns go before the taps)" } else { "" }
                ),
            ));
        }
    }
    if tap_cols.len() % 2 == 1 {
        return Err((tap_cols[tap_cols.len() - 1].to_string(), "has no matching imaginary column".into()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sidecar(text: &str) -> CirSidecar {
        CirSidecar::parse(Path::new("s.toml"), text).unwrap()
    }

    const SIDECAR: &str = "carrier_hz = 5.7e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 0.001\nsnapshots_per_set = 2\n\
                           set_period_s = 0.01\nt0_ns = 100";

    #[test]
    fn rows_with_and_without_index_columns() {
        let text = "# exported\nre_0,im_0,re_1,im_1\n1,2,3,4\n5,6,7,8\n\n-1,0,0,1e-3\n";
        let cs = parse_cir_csv(Path::new("c.csv"), text, &sidecar(SIDECAR)).unwrap();
        assert_eq!(cs.len(), 3);
        assert_eq!(cs[1].taps, [Complex64::new(5.0, 6.0), Complex64::new(7.0, 8.0)]);
        // Row 2 = set 1, snapshot 0: 10 ms after t0.
        assert_eq!((cs[2].t_ns, cs[2].set_index, cs[2].snapshot_index), (10_000_100, 1, 0));
        assert_eq!((cs[1].t_ns, cs[1].snapshot_index), (1_000_100, 1));
        let text = "t_ns,set_index,snapshot_index,tx_antenna,rx_antenna,re_0,im_0\n5,3,1,2,1,1,0\n";
        let cs = parse_cir_csv(Path::new("c.csv"), text, &sidecar(SIDECAR)).unwrap();
        assert_eq!(
            (cs[0].t_ns, cs[0].set_index, cs[0].snapshot_index, cs[0].tx_antenna, cs[0].rx_antenna),
            (5, 3, 1, 2, 1)
        );
    }

    #[test]
    fn bad_csv_is_named() {
        let s = sidecar(SIDECAR);
        let err = |text: &str| parse_cir_csv(Path::new("c.csv"), text, &s).unwrap_err().to_string();
        let e = err("re_0,im_0,re_2,im_2\n1,2,3,4\n");
        assert!(e.contains("c.csv: line 1: re_2: column 3 is `re_2`, expected `re_1`"), "{e}");
        let e = err("time,re_0,im_0\n1,2,3\n");
        assert!(e.contains("line 1: time: column 1 is `time`, expected `re_0`"), "{e}");
        let e = err("re_0,im_0,t_ns\n1,2,3\n");
        assert!(e.contains("index columns go before the taps"), "{e}");
        let e = err("t_ns,t_ns,re_0,im_0\n1,1,2,3\n");
        assert!(e.contains("t_ns: appears twice"), "{e}");
        let e = err("re_0,im_0,re_1\n1,2,3\n");
        assert!(e.contains("re_1: has no matching imaginary column"), "{e}");
        let e = err("re_0,im_0\n1,2\n3\n");
        assert!(e.contains("line 3: row: 1 fields, the header has 2 columns"), "{e}");
        let e = err("re_0,im_0\n1,NaN\n");
        assert!(e.contains("line 2: im_0: `NaN`, expected a finite number"), "{e}");
        let e = err("re_0,im_0\n1,inf\n");
        assert!(e.contains("im_0: `inf`"), "{e}");
        let e = err("tx_antenna,re_0,im_0\n-1,1,2\n");
        assert!(e.contains("tx_antenna: `-1`, expected an integer >= 0"), "{e}");
        assert!(err("# only a comment\n").contains("empty: no header line"));
        assert!(err("re_0,im_0\n").contains("no snapshot rows"));
        // A UTF-8 byte order mark is not part of the first column's name.
        let with_bom = parse_cir_csv(Path::new("c.csv"), "\u{feff}re_0,im_0\n1,2\n", &sidecar(SIDECAR));
        assert_eq!(with_bom.unwrap().len(), 1);
        assert!(err("\u{feff}time,re_0,im_0\n1,2,3\n").contains("line 1: time: column 1 is `time`"));
        let e = parse_cir_csv(Path::new("c.csv"), "re_0,im_0\n1,2\n", &sidecar("tap_spacing_s = 1e-9"));
        assert!(e.unwrap_err().to_string().contains("key `carrier_hz`"));
    }

    /// Before: rows out of set or time order were taken, and `process mpc`
    /// refused the recording ("snapshots must come in set order").
    #[test]
    fn rows_out_of_set_or_time_order_on_a_link_are_refused_naming_the_line() {
        let s = sidecar(SIDECAR);
        let parse = |text: &str| parse_cir_csv(Path::new("c.csv"), text, &s);
        let header = "t_ns,set_index,tx_antenna,rx_antenna,re_0,im_0\n";
        let e = parse(&format!("{header}10,5,0,0,1,0\n20,5,0,1,1,0\n30,3,0,0,1,0\n")).unwrap_err().to_string();
        assert_eq!(
            e,
            "c.csv: line 4: set_index: set 3 after set 5 (line 2) on link tx0:rx0: expected each link's snapshots \
             in set order"
        );
        let e = parse(&format!("{header}30,5,0,0,1,0\n20,6,0,0,1,0\n")).unwrap_err().to_string();
        assert_eq!(
            e,
            "c.csv: line 3: t_ns: 20 ns, before the 30 ns of line 2 on link tx0:rx0: expected each link's snapshots \
             in increasing time"
        );
        // The same time twice on a link (`process mpc` would refuse the recording) and a negative time
        // (the recording would, naming itself rather than this line).
        let e = parse(&format!("{header}30,5,0,0,1,0\n30,6,0,0,1,0\n")).unwrap_err().to_string();
        assert!(e.starts_with("c.csv: line 3: t_ns: 30 ns, the same time as the 30 ns of line 2"), "{e}");
        let e = parse(&format!("{header}-5,5,0,0,1,0\n")).unwrap_err().to_string();
        assert_eq!(e, "c.csv: line 2: t_ns: `-5`, expected an integer >= 0");
        // Two links interleaved, each in order; the same time on two antennas.
        let ok = parse(&format!("{header}10,1,0,0,1,0\n10,1,0,1,1,0\n20,2,0,0,1,0\n20,2,0,1,1,0\n")).unwrap();
        assert_eq!(ok.len(), 4);
    }

    /// Seen while adding the CSV fuzz target: with two snapshots per set, a
    /// huge set index overflowed the snapshot's ordinal (a panic in debug
    /// builds, a wrapped ordinal in release).
    #[test]
    fn huge_set_index_is_an_error() {
        // 2 (i64::MAX) + 2 = 2^64.
        let text = "set_index,snapshot_index,re_0,im_0\n9223372036854775807,2,1,2\n";
        let e = parse_cir_csv(Path::new("c.csv"), text, &sidecar(SIDECAR)).unwrap_err().to_string();
        assert!(
            e.contains(
                "c.csv: line 2: set_index: set 9223372036854775807, snapshot 2: the snapshot's ordinal overflows"
            ),
            "{e}"
        );
    }
}
