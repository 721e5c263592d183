//! NMEA 0183 GNSS logs: GGA and RMC or ZDA (and GST when present) from any
//! talker (GP, GN, GL, GA, GB, GQ, ...), one fix per epoch.
//!
//! The log is read as a stream, one line at a time. [`ingest_nmea`] reads a
//! file twice (the first pass decides the altitude datum, which needs every
//! fix, and finds the first fix; the second writes each fix as it is made),
//! so its memory grows neither with the file nor with the number of fixes;
//! from a pipe, which cannot be read again, and in [`parse_nmea`], the fixes
//! are kept (about 90 bytes each). A line longer than
//! [`MAX_LINE_BYTES`] (NMEA 0183 sentences are at most 82 characters), or a
//! file with no sentence in its first [`MAX_LINES_BEFORE_FIRST_SENTENCE`]
//! lines, is not an NMEA log (binary data, `/dev/zero`, a wrong file): it is
//! refused, naming the file and the line, without reading further.
//!
//! Each line is `$<talker:2><type:3>,<fields>*<checksum:2 hex>`, the checksum
//! being the XOR of the bytes between `$` and `*`. Every line is accounted for
//! in [`NmeaLog`]:
//! - a wrong checksum: skipped and counted ([`NmeaLog::bad_checksum_lines`]),
//!   never fatal;
//! - not a sentence at all (blank, binary junk, truncated, a missing `*` or a
//!   checksum that is not two hex digits), *and* GGA/RMC/GST sentences with a
//!   valid checksum whose fields do not parse (non-numeric or out-of-range
//!   latitude, a NaN altitude, a bad date, ...): skipped and counted as
//!   [`NmeaLog::unparsable_lines`], the first one described in
//!   [`NmeaLog::first_unparsable`]. Skipping rather than failing is deliberate:
//!   an 8-bit checksum lets about one corrupted line in 256 through, and one
//!   such line must not make a whole drive unreadable;
//! - other sentence types (GSA, GSV, VTG, GLL, TXT, ...) and proprietary ones
//!   (`$PUBX`, ...): counted as [`NmeaLog::ignored_sentences`].
//!
//! Epochs: consecutive GGA, RMC, GST and ZDA sentences with the same time of
//! day form one epoch, whatever their order (u-blox writes RMC before GGA,
//! other receivers GGA before RMC). The GGA gives time of day, position,
//! quality, satellites and altitude (an empty altitude field is a fix without
//! altitude); the RMC of the same epoch gives the date, and its status `V`
//! means no fix; a ZDA gives the date (day, month, four-digit year, UTC) when
//! there is no RMC, so receivers that log GGA + ZDA give fixes; the GST gives
//! `horizontal_sigma_m`. An epoch with a valid
//! RMC but no usable GGA (none, or one that does not parse) is a fix from the
//! RMC alone, counted in [`NmeaLog::rmc_only_fixes`]: its position, its
//! quality from the RMC mode indicator (A autonomous, D differential, E dead
//! reckoning, F RTK float, R RTK fixed, none or other unknown), no altitude
//! and no satellite count: receivers configured for RMC alone, and logs
//! whose GGAs lack a height, are not lost. An epoch
//! without its own RMC is dated from the latest known time (the latest RMC or
//! fix), taking the day that puts it nearest, so a midnight rollover between
//! RMCs is handled; GGAs before the first RMC are dated by that RMC the same
//! way. (Here and below, "RMC" dating means an RMC or a ZDA: a ZDA whose time
//! differs from every GGA's dates them the same way.) A log with GGA fixes
//! but no dated RMC or ZDA at all is an error: there is no way to give UNIX
//! times. Time is computed from the digits with integers, so
//! fractional seconds are exact to the nanosecond.
//!
//! Epochs whose GGA quality is 0, or whose RMC status is `V` or mode `N`, are not fixes:
//! they are counted ([`NmeaLog::epochs_without_fix`]), not emitted (u-blox
//! receivers print `$GPGGA,,,,,,0,...` with no time before their first fix;
//! that is such an epoch, not an error). Fix quality maps from GGA: 1
//! autonomous, 2 differential, 4 RTK fixed, 5 RTK float, 6 dead reckoning,
//! anything else unknown. An epoch seen twice (the same GGA time again, e.g.
//! `GPGGA` and `GNGGA` of one epoch) is merged into the first and counted in
//! [`NmeaLog::duplicate_epochs`]. An epoch earlier than the fix before it (a
//! receiver stepping its clock back) is skipped and counted in
//! [`NmeaLog::out_of_order_epochs`], the first one described in
//! [`NmeaLog::first_out_of_order`]: the recording needs increasing time, and
//! one such step must not reject the rest of a drive. Lines named for an
//! epoch are those of its first GGA, RMC, GST or ZDA sentence.
//!
//! Leap seconds: an epoch at 23:59:60.f UTC has, as POSIX defines UNIX time,
//! the UNIX time of 00:00:00.f of the next day, which belongs to the epoch
//! that really is at 00:00:00.f (the recording's `t_ns` is UNIX time, which
//! has no instant of its own for a leap second). Such an epoch is therefore
//! never a fix: it is counted in [`NmeaLog::leap_second_epochs`] (the first
//! one's line in [`NmeaLog::first_leap_second_line`]) and skipped; its date,
//! if it carries one, still dates the epochs around it. Second 60 is accepted
//! only at 23:59.
//!
//! `altitude_m` is the height above the WGS-84 ellipsoid (GGA altitude above
//! mean sea level plus the geoid separation) when every fix with an altitude
//! gives the geoid separation, else the altitude above mean sea level for all
//! fixes; [`NmeaLog::altitude_datum`] says which. Fixes without an altitude
//! have `altitude_m: None`. HDOP is not a standard deviation
//! and there is no standard factor from it to metres, so `horizontal_sigma_m`
//! is `None` unless a GST sentence of the same epoch gives the latitude and
//! longitude sigmas; it is then their RMS, `sqrt((s_lat^2 + s_lon^2) / 2)`,
//! as for the other GNSS sources.
//!
//! Written by hand: the `nmea` crate is not a dependency of this crate, and we
//! need what a sentence-at-a-time parser does not give: bad checksums told
//! apart from junk with line numbers, empty-field cold-start sentences
//! accepted, time from the digits. GGA, RMC, GST and ZDA are four short,
//! fixed layouts (the field parsers are in the private `sentence` submodule,
//! the joining and dating of epochs in `epoch`).

mod enu;
mod epoch;
mod sentence;
#[cfg(test)]
mod tests;

use std::io::{BufRead, Read};
use std::path::Path;

use mmtrack_core::GnssFix;

use self::epoch::{Assembler, Datum, Epoch, Part};
use self::sentence::Line;
use crate::IngestError;
use crate::error::os_err;

pub use self::enu::{EnuOrigin, geodetic_to_enu_m};

/// Longest line accepted, in bytes (line end included). NMEA 0183 limits a
/// sentence to 82 characters; the margin admits vendor extensions and long
/// proprietary sentences, and a longer line means the file is not an NMEA
/// log.
pub const MAX_LINE_BYTES: usize = 4096;

/// Lines read without any sentence (`$...*hh`, whatever its checksum) before
/// the file is refused as not an NMEA log.
pub const MAX_LINES_BEFORE_FIRST_SENTENCE: usize = 1000;

/// A skipped line and why it was skipped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedLine {
    /// Line number, 1-based.
    pub line: usize,
    /// What is wrong and what was expected, e.g. `GNGGA: latitude: '37x5.58,N' is not ddmm.mm,N|S ...`.
    pub reason: String,
}

/// What a log gave.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NmeaLog {
    /// Fixes in strictly increasing time order ([`parse_nmea`], [`read_nmea`];
    /// empty from [`ingest_nmea`], which streams them into the recording).
    pub fixes: Vec<GnssFix>,
    /// How many fixes the log gave.
    pub fix_count: u64,
    /// Fixes without an altitude.
    pub fixes_without_altitude: u64,
    /// Fixes from an RMC alone (no GGA, or one that did not parse): no
    /// altitude and no satellite count.
    pub rmc_only_fixes: u64,
    /// Lines skipped for a wrong checksum.
    pub bad_checksum_lines: u64,
    /// First line (1-based) with a wrong checksum.
    pub first_bad_checksum_line: Option<usize>,
    /// Lines skipped because they are not NMEA sentences, or are GGA/RMC/GST
    /// sentences whose fields do not parse.
    pub unparsable_lines: u64,
    /// The first unparsable line and why.
    pub first_unparsable: Option<SkippedLine>,
    /// Valid sentences of other types (GSA, GSV, VTG, GLL, TXT, proprietary, ...).
    pub ignored_sentences: u64,
    /// Epochs without a fix (GGA quality 0, RMC status V or mode N), not emitted.
    pub epochs_without_fix: u64,
    /// Repeated epochs (a fix time already seen) merged into the first.
    pub duplicate_epochs: u64,
    /// Epochs earlier than the fix before them, skipped.
    pub out_of_order_epochs: u64,
    /// Epochs with a fix at a leap second (23:59:60.f UTC), skipped: UNIX
    /// time has no instant for them (see the module documentation).
    pub leap_second_epochs: u64,
    /// Line of the first leap-second epoch.
    pub first_leap_second_line: Option<usize>,
    /// The first epoch skipped for its time, and by how much it went back.
    pub first_out_of_order: Option<SkippedLine>,
    /// The first step between consecutive fixes (either way) longer than
    /// [`MAX_DATE_STEP_NS`]: a misdated RMC, which `ingest_nmea` refuses.
    pub first_date_step: Option<SkippedLine>,
    /// `ellipsoid` or `mean sea level`; empty when no fix has an altitude.
    pub altitude_datum: &'static str,
}

/// Reads a log line by line. Fails when a line is too long or no sentence
/// comes early enough (not an NMEA log), on a read error, and when there are
/// fixes but no date; everything else is skipped and counted (see the module
/// documentation). Bytes that are not UTF-8 make their lines unparsable, not
/// the log. The fixes are kept in memory (about 90 bytes each), since their
/// altitude datum is decided by the last; [`ingest_nmea`] streams a file
/// twice instead.
pub fn parse_nmea(path: &Path, input: impl BufRead) -> Result<NmeaLog, IngestError> {
    Ok(run(path, input, Parser::default(), &mut |_| Ok(()))?.log)
}

/// What a pass over a log found beside its [`NmeaLog`].
struct Pass {
    log: NmeaLog,
    /// The first fix with an altitude: its altitude on the log's datum.
    first_altitude_m: Option<f64>,
    /// The UNIX time of the first dated epoch (dates the fixes before it).
    first_dated_ns: Option<i64>,
}

/// Reads a log line by line with `parser`, handing each fix to `sink` as
/// it is made when the parser does not keep them ([`Datum::Decide`],
/// [`Datum::Known`]).
fn run(
    path: &Path,
    mut input: impl BufRead,
    mut parser: Parser,
    sink: &mut dyn FnMut(&GnssFix) -> Result<(), IngestError>,
) -> Result<Pass, IngestError> {
    let streamed = parser.assembler.datum != Datum::Collect;
    let mut drain = |parser: &mut Parser| -> Result<(), IngestError> {
        if streamed {
            for fix in parser.assembler.log.fixes.drain(..) {
                sink(&fix)?;
            }
        }
        Ok(())
    };
    let mut bytes = Vec::with_capacity(MAX_LINE_BYTES + 1);
    let mut line_number = 0;
    let mut seen_sentence = false;
    loop {
        bytes.clear();
        let limit = MAX_LINE_BYTES as u64 + 1;
        if input.by_ref().take(limit).read_until(b'\n', &mut bytes).map_err(os_err(path))? == 0 {
            break;
        }
        line_number += 1;
        let not_nmea = |detail: String| IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("line {line_number}"),
            field: "line".into(),
            detail,
        };
        if bytes.len() > MAX_LINE_BYTES {
            return Err(not_nmea(format!(
                "longer than {MAX_LINE_BYTES} bytes (NMEA 0183 sentences are at most 82 characters): \
                 not an NMEA text log (binary data?)"
            )));
        }
        seen_sentence |= parser.line(line_number, String::from_utf8_lossy(&bytes).trim());
        if !seen_sentence && line_number >= MAX_LINES_BEFORE_FIRST_SENTENCE {
            return Err(not_nmea(format!(
                "no NMEA sentence ($<address>,...*<checksum>) in the first {MAX_LINES_BEFORE_FIRST_SENTENCE} lines: \
                 not an NMEA text log (binary data?)"
            )));
        }
        drain(&mut parser)?;
    }
    parser.finish(path, &mut drain)
}

/// The epoch being read and what the closed ones gave.
#[derive(Default)]
struct Parser {
    assembler: Assembler,
    current: Option<Epoch>,
}

impl Parser {
    /// Takes one line (trimmed); returns whether it is framed as a sentence
    /// (`$...*hh`, whatever its checksum).
    fn line(&mut self, line_number: usize, text: &str) -> bool {
        let assembler = &mut self.assembler;
        let (id, kind, fields) = match sentence::split_sentence(text) {
            Line::Sentence { id, kind, fields } => (id, kind, fields),
            Line::Proprietary => {
                assembler.log.ignored_sentences += 1;
                return true;
            }
            Line::BadChecksum => {
                assembler.log.bad_checksum_lines += 1;
                assembler.log.first_bad_checksum_line.get_or_insert(line_number);
                return true;
            }
            Line::Junk(reason) => {
                assembler.unparsable(line_number, || format!("not an NMEA sentence: {reason}"));
                return false;
            }
        };
        let parsed = match kind {
            "GGA" => sentence::parse_gga(&fields).map(Part::Gga),
            "RMC" => sentence::parse_rmc(&fields).map(Part::Rmc),
            "GST" => sentence::parse_gst(&fields).map(Part::Gst),
            "ZDA" => sentence::parse_zda(&fields).map(Part::Zda),
            _ => {
                assembler.log.ignored_sentences += 1;
                return true;
            }
        };
        let part = match parsed {
            Ok(part) => part,
            Err(e) => {
                assembler.unparsable(line_number, || format!("{id}: {}: {}", e.field, e.detail));
                return true;
            }
        };
        let Some(time_of_day_ns) = part.time_of_day_ns() else {
            // No time: a GGA without fix counts as such; an RMC `V` has
            // nothing to add, nor a GST or ZDA without time.
            match part {
                Part::Gga(_) => assembler.log.epochs_without_fix += 1,
                Part::Gst(_) | Part::Zda(_) => assembler.log.ignored_sentences += 1,
                Part::Rmc(_) => {}
            }
            return true;
        };
        if let Some(epoch) = self.current.take_if(|epoch| epoch.time_of_day_ns != time_of_day_ns) {
            assembler.close(epoch);
        }
        let epoch = self.current.get_or_insert_with(|| Epoch::new(time_of_day_ns, line_number));
        if epoch.join(part) {
            assembler.log.duplicate_epochs += 1;
        }
        true
    }

    /// Closes the last epoch (its fix to `drain`); fails when fixes could
    /// not be dated.
    fn finish(
        mut self,
        path: &Path,
        drain: &mut dyn FnMut(&mut Self) -> Result<(), IngestError>,
    ) -> Result<Pass, IngestError> {
        if let Some(epoch) = self.current.take() {
            self.assembler.close(epoch);
        }
        drain(&mut self)?;
        if let Some(first) = self.assembler.undated.first() {
            return Err(IngestError::BadLayout {
                path: path.to_path_buf(),
                detail: format!(
                    "{} GGA fixes (the first at line {}) but no RMC or ZDA sentence with a date: \
                     fixes cannot be given UNIX times",
                    self.assembler.undated.len(),
                    first.line
                ),
            });
        }
        let (first_altitude_m, first_dated_ns) = (self.assembler.first_altitude_m(), self.assembler.first_dated_ns);
        Ok(Pass { log: self.assembler.finish(), first_altitude_m, first_dated_ns })
    }
}

/// The longest step between consecutive fixes of one log that is taken as
/// real: a logger off for a month is not a drive; a step of years is one
/// RMC's wrong date (a first fix dated 1998 made a 22-year recording whose
/// times were then labelled relative, not UNIX).
pub const MAX_DATE_STEP_NS: i64 = 30 * sentence::NS_PER_DAY;

/// Refuses a log with a misdated fix: a step over [`MAX_DATE_STEP_NS`]
/// between consecutive fixes, or more epochs going back in time than are
/// kept (one epoch stepped back is skipped, a receiver's clock correction;
/// when most are "before the previous fix", the fix they are measured
/// against is the wrong one, and keeping it would drop the drive).
fn refuse_misdated_fixes(path: &Path, log: &NmeaLog) -> Result<(), IngestError> {
    if let Some(step) = &log.first_date_step {
        return Err(IngestError::bad_line(path, step.line, "date", step.reason.clone()));
    }
    match &log.first_out_of_order {
        Some(first) if log.out_of_order_epochs > log.fix_count => Err(IngestError::bad_line(
            path,
            first.line,
            "time",
            format!(
                "{} epochs are before an earlier fix and only {} would be kept (the first: {}); \
                 the fix they are before is likely misdated",
                log.out_of_order_epochs, log.fix_count, first.reason
            ),
        )),
        _ => Ok(()),
    }
}

/// Opens and parses a log file (streamed: see [`parse_nmea`]).
pub fn read_nmea(path: &Path) -> Result<NmeaLog, IngestError> {
    let file = std::fs::File::open(path).map_err(os_err(path))?;
    parse_nmea(path, std::io::BufReader::new(file))
}

/// What an NMEA ingest did.
#[derive(Debug, Clone)]
pub struct NmeaReport {
    /// The parsed log (fixes and skip counts).
    pub log: NmeaLog,
    /// The recording.
    pub output: mmtrack_io::recording::WriteSummary,
}

impl NmeaReport {
    /// The one-line summary the CLI prints: fixes, and every kind of line
    /// or epoch skipped, with the first of each.
    #[must_use]
    pub fn summary(&self) -> String {
        let log = &self.log;
        let without_altitude = log.fixes_without_altitude;
        let partial = if without_altitude > 0 {
            format!(" ({} from RMC alone, {without_altitude} without altitude)", log.rmc_only_fixes)
        } else {
            String::new()
        };
        let out_of_order = match &log.first_out_of_order {
            Some(first) => format!(
                ", {} epoch{} out of time order (first at line {}: {})",
                log.out_of_order_epochs,
                if log.out_of_order_epochs == 1 { "" } else { "s" },
                first.line,
                first.reason
            ),
            None => String::new(),
        };
        let leap_seconds = match log.first_leap_second_line {
            Some(line) => format!(
                ", {} leap-second epoch{} (23:59:60 UTC has no UNIX time of its own; first at line {line})",
                log.leap_second_epochs,
                if log.leap_second_epochs == 1 { "" } else { "s" },
            ),
            None => String::new(),
        };
        format!(
            "{}: {} GNSS fixes{partial}; skipped {} lines with bad checksums{}, {} unparsable lines, {} epochs \
             without a fix{out_of_order}{leap_seconds}; {} other sentences ignored",
            self.output.path.display(),
            log.fix_count,
            log.bad_checksum_lines,
            log.first_bad_checksum_line.map(|l| format!(" (first at line {l})")).unwrap_or_default(),
            log.unparsable_lines,
            log.epochs_without_fix,
            log.ignored_sentences
        )
    }
}

/// Writes the fixes of an NMEA log into `out` (new, or a copy of `extend` plus
/// the fixes). The metadata records the altitude datum (`none (no fix gives
/// an altitude)` when no fix has one) and the origin of the local ENU frame
/// that analyses use, e.g. for distance travelled: the first fix's latitude
/// and longitude, and the height of the first fix that has one (the key is
/// left out when none has).
pub fn ingest_nmea(
    input: &Path,
    out: &Path,
    extend: Option<&Path>,
    recording: &mmtrack_io::RecordingOptions,
) -> Result<NmeaReport, IngestError> {
    use mmtrack_io::recording::channels::{GNSS_TOPIC, GNSS_VIZ_TOPIC};
    let file = std::fs::File::open(input).map_err(os_err(input))?;
    let regular = file.metadata().map_err(os_err(input))?.is_file();
    // A file is read twice: the first pass decides the altitude datum (and
    // finds the first fix), the second writes; a pipe cannot be read again,
    // so its fixes are kept in memory until the datum is known.
    let (first_pass, kept) = if regular {
        let mut first_fix = None;
        let decide = Parser { assembler: Assembler::new(Datum::Decide, None), current: None };
        let pass = run(input, std::io::BufReader::new(file), decide, &mut |fix| {
            first_fix.get_or_insert_with(|| fix.clone());
            Ok(())
        })?;
        (pass, first_fix)
    } else {
        let pass = run(input, std::io::BufReader::new(file), Parser::default(), &mut |_| Ok(()))?;
        let first = pass.log.fixes.first().cloned();
        (pass, first)
    };
    let log = &first_pass.log;
    let first = kept.ok_or_else(|| IngestError::BadLayout {
        path: input.to_path_buf(),
        detail: format!(
            "no fixes (bad checksums {}, unparsable lines {}{}, epochs without fix {})",
            log.bad_checksum_lines,
            log.unparsable_lines,
            log.first_unparsable
                .as_ref()
                .map(|s| format!(" (first at line {}: {})", s.line, s.reason))
                .unwrap_or_default(),
            log.epochs_without_fix
        ),
    })?;
    refuse_misdated_fixes(input, log)?;
    let altitude_datum = match log.altitude_datum {
        "" => "none (no fix gives an altitude)",
        datum => datum,
    };
    let mut extra = std::collections::BTreeMap::from([
        ("gnss.source".to_string(), format!("nmea:{}", mmtrack_io::paths::canonical(input))),
        ("gnss.altitude_datum".to_string(), altitude_datum.to_string()),
        ("gnss.enu_origin_latitude_deg".to_string(), first.latitude_deg.to_string()),
        ("gnss.enu_origin_longitude_deg".to_string(), first.longitude_deg.to_string()),
    ]);
    if let Some(altitude_m) = first_pass.first_altitude_m {
        extra.insert("gnss.enu_origin_altitude_m".to_string(), altitude_m.to_string());
    }
    let source = format!("nmea:{}", mmtrack_io::paths::canonical(input));
    let mut target = crate::target::open_writer(
        out,
        extend,
        &source,
        extra,
        Some(first.t_ns),
        &[GNSS_TOPIC, GNSS_VIZ_TOPIC],
        recording,
    )?;
    if !regular {
        for fix in &first_pass.log.fixes {
            target.writer().write_gnss_fix(fix)?;
            target.added(fix.t_ns);
        }
        let output = target.finish(input, "GNSS fixes")?;
        return Ok(NmeaReport { log: first_pass.log, output });
    }
    let file = std::fs::File::open(input).map_err(os_err(input))?;
    let write = Parser {
        assembler: Assembler::new(
            Datum::Known { ellipsoid: log.altitude_datum == "ellipsoid" },
            first_pass.first_dated_ns,
        ),
        current: None,
    };
    let second_pass = run(input, std::io::BufReader::new(file), write, &mut |fix| {
        target.writer().write_gnss_fix(fix)?;
        target.added(fix.t_ns);
        Ok(())
    })?;
    if second_pass.log != first_pass.log {
        return Err(IngestError::BadLayout {
            path: input.to_path_buf(),
            detail: format!(
                "changed while it was read: {} fixes on the first reading, {} on the second",
                first_pass.log.fix_count, second_pass.log.fix_count
            ),
        });
    }
    let output = target.finish(input, "GNSS fixes")?;
    Ok(NmeaReport { log: second_pass.log, output })
}
