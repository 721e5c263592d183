//! Epochs: the GGA, RMC, GST and ZDA sentences of one time of day joined,
//! dated and turned into fixes (the rules are in the parent module's
//! documentation).

use mmtrack_core::{GnssFix, GnssFixQuality};

use super::sentence::{self, GgaPosition, NS_PER_DAY};
use super::{NmeaLog, SkippedLine};

/// GGA, RMC, GST and ZDA sentences sharing one time of day.
pub(super) struct Epoch {
    pub(super) time_of_day_ns: i64,
    /// Line of the epoch's first sentence.
    line: usize,
    /// The first GGA: its position (`None`: quality 0, no fix) and quality.
    gga: Option<(Option<GgaPosition>, GnssFixQuality)>,
    /// The first RMC.
    rmc: Option<sentence::Rmc>,
    /// The date of the first ZDA that gives one, days since the UNIX epoch.
    zda_days: Option<i64>,
    horizontal_sigma_m: Option<f64>,
}

impl Epoch {
    pub(super) fn new(time_of_day_ns: i64, line: usize) -> Self {
        Self { time_of_day_ns, line, gga: None, rmc: None, zda_days: None, horizontal_sigma_m: None }
    }

    /// Adds a sentence of this epoch; the first of each type wins. Returns
    /// whether it was a second GGA (a duplicate epoch).
    pub(super) fn join(&mut self, part: Part) -> bool {
        match part {
            Part::Gga(gga) if self.gga.is_none() => self.gga = Some((gga.position, gga.quality)),
            Part::Gga(_) => return true,
            Part::Rmc(rmc) => {
                self.rmc.get_or_insert(rmc);
            }
            Part::Gst(gst) => self.horizontal_sigma_m = self.horizontal_sigma_m.or(gst.horizontal_sigma_m),
            Part::Zda(zda) => self.zda_days = self.zda_days.or(zda.days),
        }
        false
    }

    /// The epoch's date, days since the UNIX epoch: the RMC's, else the ZDA's.
    fn days(&self) -> Option<i64> {
        self.rmc.as_ref().and_then(|rmc| rmc.days).or(self.zda_days)
    }

    /// The fix this epoch gives: from the GGA when there is one (and the RMC
    /// does not say no fix), else from a valid RMC. `Err(())` is an epoch
    /// without a fix, `Ok(None)` one with neither GGA nor RMC (a lone GST or
    /// ZDA).
    fn fix(&self) -> Result<Option<Candidate>, ()> {
        let rmc_says_no_fix = self.rmc.as_ref().is_some_and(|rmc| !rmc.valid);
        let candidate = match (&self.gga, &self.rmc) {
            (Some((Some(p), quality)), _) if !rmc_says_no_fix => Candidate {
                latitude_deg: p.latitude_deg,
                longitude_deg: p.longitude_deg,
                altitude_msl_m: p.altitude_msl_m,
                geoid_separation_m: p.geoid_separation_m,
                num_satellites: p.num_satellites,
                quality: *quality,
                rmc_only: false,
            },
            (None, Some(sentence::Rmc { position: Some(p), .. })) => Candidate {
                latitude_deg: p.latitude_deg,
                longitude_deg: p.longitude_deg,
                altitude_msl_m: None,
                geoid_separation_m: None,
                num_satellites: None,
                quality: p.quality,
                rmc_only: true,
            },
            (None, None) => return Ok(None),
            _ => return Err(()),
        };
        Ok(Some(candidate))
    }
}

/// A parsed sentence of a type we use.
pub(super) enum Part {
    Gga(sentence::Gga),
    Rmc(sentence::Rmc),
    Gst(sentence::Gst),
    Zda(sentence::Zda),
}

impl Part {
    pub(super) fn time_of_day_ns(&self) -> Option<i64> {
        match self {
            Self::Gga(gga) => gga.time_of_day_ns,
            Self::Rmc(rmc) => rmc.time_of_day_ns,
            Self::Gst(gst) => gst.time_of_day_ns,
            Self::Zda(zda) => zda.time_of_day_ns,
        }
    }
}

/// What an epoch's fix is made of, before it has a UNIX time.
pub(super) struct Candidate {
    latitude_deg: f64,
    longitude_deg: f64,
    altitude_msl_m: Option<f64>,
    geoid_separation_m: Option<f64>,
    num_satellites: Option<u32>,
    quality: GnssFixQuality,
    /// From an RMC without a usable GGA.
    rmc_only: bool,
}

/// A fix whose date is not known yet (GGAs before the first RMC).
pub(super) struct Undated {
    time_of_day_ns: i64,
    candidate: Candidate,
    horizontal_sigma_m: Option<f64>,
    pub(super) line: usize,
}

/// The time `time_of_day_ns` on the day that puts it nearest `reference_ns`.
fn nearest_ns(reference_ns: i64, time_of_day_ns: i64) -> i64 {
    let midnight = reference_ns.div_euclid(NS_PER_DAY) * NS_PER_DAY;
    [midnight - NS_PER_DAY, midnight, midnight + NS_PER_DAY]
        .map(|day| day + time_of_day_ns)
        .into_iter()
        .min_by_key(|t| t.abs_diff(reference_ns))
        .unwrap_or(midnight + time_of_day_ns)
}

/// `YYYY-MM-DD hhmmss.sssssssss` of a time in nanoseconds, for messages
/// (the date too: a wrong date in one RMC is a step of whole days).
fn clock(t_ns: i64) -> String {
    let ns = t_ns.rem_euclid(NS_PER_DAY);
    let (year, month, day) = mmtrack_core::calendar::civil_from_days(t_ns.div_euclid(NS_PER_DAY));
    let s = ns / 1_000_000_000;
    format!("{year:04}-{month:02}-{day:02} {:02}{:02}{:02}.{:09}", s / 3600, s / 60 % 60, s % 60, ns % 1_000_000_000)
}

/// How altitudes are put on their datum, which is known only once every
/// fix has been seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) enum Datum {
    /// Keep the fixes and each one's geoid separation; [`Assembler::finish`]
    /// moves them to the ellipsoid if every one gives it (one pass).
    #[default]
    Collect,
    /// Decide the datum only (first of two passes; fixes are taken away as
    /// they come and their separations not kept).
    Decide,
    /// Decided by a first pass: each fix goes on it as it is made.
    Known { ellipsoid: bool },
}

#[derive(Default)]
pub(super) struct Assembler {
    pub(super) log: NmeaLog,
    pub(super) datum: Datum,
    /// Time and line of the latest fix, for ordering and messages.
    last_fix: Option<(i64, usize)>,
    /// Geoid separation of each fix that has an altitude, while every one
    /// of them gives it (to move altitudes to the ellipsoid); only with
    /// [`Datum::Collect`].
    separations_m: Vec<f64>,
    /// Whether some fix has an altitude with a geoid separation.
    separation_seen: bool,
    /// Whether some fix has an altitude without a geoid separation (the
    /// datum is then mean sea level, and `separations_m` is emptied).
    separation_missing: bool,
    /// Latest known UNIX time (an RMC's date and time, or a fix), for dating.
    reference_ns: Option<i64>,
    /// The UNIX time of the first dated epoch, which dates the fixes before
    /// it: found by a first pass, given to the second
    /// ([`Assembler::first_dated_ns`]), so those fixes need not wait.
    pub(super) first_dated_ns: Option<i64>,
    pub(super) undated: Vec<Undated>,
    /// The first fix's altitude above mean sea level with its geoid
    /// separation, for the ENU origin ([`Assembler::first_altitude_m`]).
    first_altitude: Option<(f64, Option<f64>)>,
}

impl Assembler {
    /// An assembler putting altitudes on their datum as `datum` says, dating
    /// fixes before the first dated epoch by `first_dated_ns` when known.
    pub(super) fn new(datum: Datum, first_dated_ns: Option<i64>) -> Self {
        Self { datum, first_dated_ns, ..Self::default() }
    }

    pub(super) fn close(&mut self, epoch: Epoch) {
        let rmc_date = epoch.days();
        if let Some(days) = rmc_date {
            let reference_ns = days * NS_PER_DAY + epoch.time_of_day_ns;
            self.reference_ns = Some(reference_ns);
            self.first_dated_ns.get_or_insert(reference_ns);
            for undated in std::mem::take(&mut self.undated) {
                let t_ns = nearest_ns(reference_ns, undated.time_of_day_ns);
                self.emit(t_ns, undated.candidate, undated.horizontal_sigma_m, undated.line);
            }
        }
        let candidate = match epoch.fix() {
            Ok(Some(candidate)) => candidate,
            Ok(None) => return,
            Err(()) => {
                self.log.epochs_without_fix += 1;
                return;
            }
        };
        if epoch.time_of_day_ns >= NS_PER_DAY {
            self.log.leap_second_epochs += 1;
            self.log.first_leap_second_line.get_or_insert(epoch.line);
            return;
        }
        let t_ns = match (rmc_date, self.reference_ns) {
            (Some(days), _) => days * NS_PER_DAY + epoch.time_of_day_ns,
            (None, Some(reference_ns)) => nearest_ns(reference_ns, epoch.time_of_day_ns),
            // Dated as the first pass found (the first dated epoch will date
            // them so): the same fixes, in the same order, none kept waiting.
            (None, None) if self.first_dated_ns.is_some() && matches!(self.datum, Datum::Known { .. }) => {
                let first_dated_ns = self.first_dated_ns.unwrap_or_default();
                let t_ns = nearest_ns(first_dated_ns, epoch.time_of_day_ns);
                self.emit(t_ns, candidate, epoch.horizontal_sigma_m, epoch.line);
                return;
            }
            (None, None) => {
                let (time_of_day_ns, horizontal_sigma_m, line) =
                    (epoch.time_of_day_ns, epoch.horizontal_sigma_m, epoch.line);
                self.undated.push(Undated { time_of_day_ns, candidate, horizontal_sigma_m, line });
                return;
            }
        };
        if self.emit(t_ns, candidate, epoch.horizontal_sigma_m, epoch.line) {
            self.reference_ns = Some(t_ns);
        }
    }

    /// Appends a fix; returns whether it was kept (not a repeated or
    /// out-of-order epoch, which are counted instead).
    fn emit(&mut self, t_ns: i64, candidate: Candidate, horizontal_sigma_m: Option<f64>, line: usize) -> bool {
        if let Some((last_t_ns, last_line)) = self.last_fix {
            let step_ns = t_ns.abs_diff(last_t_ns);
            if step_ns > super::MAX_DATE_STEP_NS as u64 && self.log.first_date_step.is_none() {
                let reason = format!(
                    "fix at {} UTC is {} days {} the previous fix ({} UTC, line {last_line}): one of them is likely \
                     misdated (at most {} days between consecutive fixes)",
                    clock(t_ns),
                    step_ns / NS_PER_DAY as u64,
                    if t_ns > last_t_ns { "after" } else { "before" },
                    clock(last_t_ns),
                    super::MAX_DATE_STEP_NS / NS_PER_DAY
                );
                self.log.first_date_step = Some(SkippedLine { line, reason });
            }
            if t_ns == last_t_ns {
                self.log.duplicate_epochs += 1;
                return false;
            }
            if t_ns < last_t_ns {
                self.log.out_of_order_epochs += 1;
                if self.log.first_out_of_order.is_none() {
                    let back_ns = last_t_ns - t_ns;
                    let reason = format!(
                        "fix at {} UTC is {}.{:09} s before the previous fix ({} UTC, line {last_line})",
                        clock(t_ns),
                        back_ns / 1_000_000_000,
                        back_ns % 1_000_000_000,
                        clock(last_t_ns),
                    );
                    self.log.first_out_of_order = Some(SkippedLine { line, reason });
                }
                return false;
            }
        }
        self.last_fix = Some((t_ns, line));
        let mut altitude_m = candidate.altitude_msl_m;
        if let Some(altitude_msl_m) = candidate.altitude_msl_m {
            self.first_altitude.get_or_insert((altitude_msl_m, candidate.geoid_separation_m));
            match candidate.geoid_separation_m {
                Some(separation_m) => {
                    self.separation_seen = true;
                    match self.datum {
                        Datum::Collect if !self.separation_missing => self.separations_m.push(separation_m),
                        Datum::Known { ellipsoid: true } => altitude_m = Some(altitude_msl_m + separation_m),
                        _ => {}
                    }
                }
                None => {
                    self.separation_missing = true;
                    self.separations_m = Vec::new();
                }
            }
        }
        self.log.rmc_only_fixes += u64::from(candidate.rmc_only);
        self.log.fix_count += 1;
        self.log.fixes_without_altitude += u64::from(altitude_m.is_none());
        self.log.fixes.push(GnssFix {
            t_ns,
            latitude_deg: candidate.latitude_deg,
            longitude_deg: candidate.longitude_deg,
            altitude_m,
            horizontal_sigma_m,
            num_satellites: candidate.num_satellites,
            quality: candidate.quality,
        });
        true
    }

    pub(super) fn unparsable(&mut self, line: usize, reason: impl FnOnce() -> String) {
        self.log.unparsable_lines += 1;
        if self.log.first_unparsable.is_none() {
            self.log.first_unparsable = Some(SkippedLine { line, reason: reason() });
        }
    }

    /// The first fix's altitude on the datum [`Assembler::finish`] decides:
    /// the same number as that fix's `altitude_m` in the log.
    pub(super) fn first_altitude_m(&self) -> Option<f64> {
        let (altitude_msl_m, separation_m) = self.first_altitude?;
        match separation_m {
            Some(separation_m) if !self.separation_missing => Some(altitude_msl_m + separation_m),
            _ => Some(altitude_msl_m),
        }
    }

    /// The log, altitudes moved to the ellipsoid when every fix with an
    /// altitude gives the geoid separation.
    pub(super) fn finish(self) -> NmeaLog {
        let mut log = self.log;
        if self.separation_missing {
            log.altitude_datum = "mean sea level";
        } else if !self.separation_seen {
            log.altitude_datum = "";
        } else if self.datum != Datum::Collect {
            log.altitude_datum = "ellipsoid";
        } else {
            let mut separations = self.separations_m.iter();
            for altitude_m in log.fixes.iter_mut().filter_map(|fix| fix.altitude_m.as_mut()) {
                *altitude_m += separations.next().copied().unwrap_or(0.0);
            }
            log.altitude_datum = "ellipsoid";
        }
        log
    }
}
