//! The fuzz loop: mutate, run under `catch_unwind`, check the allocation
//! cap and the time, save findings.
//!
//! A finding is a panic, a single allocation above
//! [`crate::alloc::ALLOCATION_CAP_BYTES`], allocations adding up to more than
//! [`crate::alloc::TOTAL_CAP_BYTES`] for one input, or (when [`RunConfig::slow_is_finding`])
//! an input that took longer than [`RunConfig::slow_limit`] twice in a row. Each distinct
//! finding (a panic by its location, other kinds by kind) is saved once, as
//! `<findings_dir>/<target>/<hash>.bin` (the input) and `<hash>.txt` (the
//! message); later hits only count, except that a slower input replaces a
//! slow one. An input still running after
//! [`HANG_EXIT`] is saved by a watchdog thread, which then ends the process
//! (a thread cannot be stopped from outside).
//!
//! Inputs that give an outcome not seen before (see [`crate::targets`]) join
//! the corpus, a cheap stand-in for coverage feedback that leads the
//! mutations past the first checks of a format. Half of the inputs start
//! from a seed, half from any corpus entry.

use std::cell::{Cell, RefCell};
use std::collections::{BTreeMap, BTreeSet};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

use crate::alloc::{ALLOCATION_CAP_BYTES, Alarm, TOTAL_CAP_BYTES, Usage, set_alarm_hook, take_usage};
use crate::mutate::Mutator;
use crate::targets::{Scratch, Target};

/// An input still running after this long is a hang: saved, and the process ends.
pub const HANG_EXIT: Duration = Duration::from_secs(60);
/// Corpus entries kept besides the seeds.
const MAX_GROWN_CORPUS: usize = 512;

/// When a run stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// After this many executions (deterministic: CI).
    Executions(u64),
    /// After this much wall-clock time (offline).
    Time(Duration),
}

/// How to run one target.
#[derive(Debug, Clone)]
pub struct RunConfig {
    /// Seed of the mutation stream.
    pub seed: u64,
    /// When to stop.
    pub budget: Budget,
    /// Largest input made, bytes.
    pub max_input_bytes: usize,
    /// Whether an input slower than `slow_limit` is a finding (offline runs;
    /// CI does not judge wall-clock time).
    pub slow_is_finding: bool,
    /// Time per input above which it is slow.
    pub slow_limit: Duration,
    /// Findings go to `<findings_dir>/<target>/`.
    pub findings_dir: PathBuf,
}

/// What kind of defect an input revealed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FindingKind {
    /// The reader panicked.
    Panic,
    /// The reader asked for one allocation above the cap.
    OverCapAllocation,
    /// The reader's allocations for one input added up to more than the total cap.
    OverCapTotal,
    /// The input took longer than the slow limit.
    Slow,
}

/// One distinct finding.
#[derive(Debug, Clone)]
pub struct Finding {
    /// Its kind.
    pub kind: FindingKind,
    /// The panic message and location, the allocation size, or the time.
    pub message: String,
    /// How many inputs gave it.
    pub hits: u64,
    /// The saved input (`.bin`; the message is beside it as `.txt`).
    pub input: PathBuf,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Report {
    /// The target.
    pub target: &'static str,
    /// Inputs run (seeds included).
    pub executions: u64,
    /// Wall-clock time of the run.
    pub elapsed: Duration,
    /// Seeds given.
    pub seeds: usize,
    /// Corpus size at the end (seeds and grown entries).
    pub corpus: usize,
    /// Distinct outcomes seen.
    pub outcomes: usize,
    /// Inputs some entry point of the target accepted (outcome "ok..."): a
    /// check that mutations still reach the end of the readers.
    pub accepted: u64,
    /// The slowest input's time.
    pub slowest: Duration,
    /// Distinct findings, in the order found.
    pub findings: Vec<Finding>,
}

impl Report {
    /// Executions per second.
    #[must_use]
    pub fn rate(&self) -> f64 {
        self.executions as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// The input a thread is running, for the watchdog and the allocator's alarms.
struct InFlight {
    thread: ThreadId,
    target: &'static str,
    dir: PathBuf,
    input: Vec<u8>,
    started: Option<Instant>,
    /// Kinds of alarm already saved in this run (each kind is saved once).
    alarms_saved: Vec<FindingKind>,
}

static IN_FLIGHT: Mutex<Vec<InFlight>> = Mutex::new(Vec::new());

thread_local! {
    /// Set while this thread runs a fuzz input: its panics are recorded, not printed.
    static FUZZING: Cell<bool> = const { Cell::new(false) };
    /// The last panic of this thread while fuzzing: message and location.
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

fn in_flight() -> MutexGuard<'static, Vec<InFlight>> {
    IN_FLIGHT.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Installs, once per process, the panic hook, the allocator's alarm hook and the watchdog.
fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if FUZZING.with(Cell::get) {
                LAST_PANIC.with(|p| *p.borrow_mut() = Some(info.to_string()));
            } else {
                previous(info);
            }
        }));
        set_alarm_hook(on_alarm);
        std::thread::spawn(watchdog);
    });
}

/// Saves the in-flight input of this thread when the allocator raises an
/// alarm, before the input goes on (the OOM killer may end the process) or
/// the process aborts (a refused allocation).
fn on_alarm(alarm: Alarm) {
    let Ok(mut all) = IN_FLIGHT.try_lock() else { return };
    let me = std::thread::current().id();
    let Some(f) = all.iter_mut().find(|f| f.thread == me && f.started.is_some()) else { return };
    let (kind, message) = match alarm {
        Alarm::OverCap(size) => (FindingKind::OverCapAllocation, over_cap_message(size)),
        Alarm::Total(bytes) => (FindingKind::OverCapTotal, total_message(bytes)),
        Alarm::Failed(size) => (
            FindingKind::OverCapAllocation,
            format!("allocation of {size} bytes (cap {ALLOCATION_CAP_BYTES}) failed: the process aborts"),
        ),
    };
    if f.alarms_saved.contains(&kind) && !matches!(alarm, Alarm::Failed(_)) {
        return;
    }
    f.alarms_saved.push(kind);
    let path = save(&f.dir, &f.input, &format!("{kind:?}: {message} (saved while running)"));
    eprintln!("fuzz {}: FINDING {kind:?} (while running): {message}\n  input: {}", f.target, path.display());
}

fn over_cap_message(size: usize) -> String {
    format!("one allocation of {size} bytes, above the cap of {ALLOCATION_CAP_BYTES}")
}

fn total_message(bytes: u64) -> String {
    format!("allocations of {bytes} bytes in all for one input, above the cap of {TOTAL_CAP_BYTES}")
}

/// Ends the process when an input runs longer than [`HANG_EXIT`], saving it first.
fn watchdog() {
    loop {
        std::thread::sleep(Duration::from_millis(250));
        let all = in_flight();
        if let Some(f) = all.iter().find(|f| f.started.is_some_and(|t| t.elapsed() > HANG_EXIT)) {
            let message =
                format!("hang: still running after {} s; {} bytes of input", HANG_EXIT.as_secs(), f.input.len());
            let path = save(&f.dir, &f.input, &message);
            eprintln!("fuzz {}: FINDING {message}\n  input: {}", f.target, path.display());
            std::process::exit(2);
        }
    }
}

/// FNV-1a, 64 bits: names a saved input.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// Writes `input` and `message` under `dir`; returns the input's path.
fn save(dir: &Path, input: &[u8], message: &str) -> PathBuf {
    let path = dir.join(format!("{:016x}.bin", fnv1a(input)));
    let written = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&path, input))
        .and_then(|()| std::fs::write(path.with_extension("txt"), format!("{message}\n")));
    if let Err(e) = written {
        eprintln!("fuzz: could not save a finding under {}: {e}", dir.display());
    }
    path
}

/// Digits removed: two findings or outcomes that differ only in numbers are one.
fn signature(text: &str) -> u64 {
    use std::hash::{Hash, Hasher};
    // SipHash with fixed keys: the same signature in every run.
    let mut hasher = std::hash::DefaultHasher::new();
    for c in text.chars().filter(|c| !c.is_ascii_digit()) {
        c.hash(&mut hasher);
    }
    hasher.finish()
}

/// Outcome signatures remembered at most. Error texts quote escaped input,
/// so the set of distinct signatures has no bound; keeping every one (as
/// strings) grew a 10-minute run to 6-24 GB resident. When full, the set is
/// forgotten and starts again: the corpus keeps growing by replacement.
const MAX_OUTCOMES: usize = 1 << 20;

/// Runs `target` from `seeds` until the budget is spent. Fails only when
/// the scratch directory cannot be made.
pub fn run(target: &Target, seeds: &[Vec<u8>], config: &RunConfig) -> std::io::Result<Report> {
    let scratch = Scratch::new()?;
    install();
    let dir = config.findings_dir.join(target.name);
    let me = std::thread::current().id();
    {
        let mut all = in_flight();
        all.retain(|f| f.thread != me);
        all.push(InFlight {
            thread: me,
            target: target.name,
            dir: dir.clone(),
            input: Vec::new(),
            started: None,
            alarms_saved: Vec::new(),
        });
    }
    let mut mutator = Mutator::new(config.seed, config.max_input_bytes);
    let mut corpus: Vec<Vec<u8>> = seeds.to_vec();
    if corpus.is_empty() {
        corpus.push(Vec::new());
    }
    let mut outcomes = BTreeSet::new();
    let mut findings: Vec<Finding> = Vec::new();
    let mut by_signature: BTreeMap<(FindingKind, String), usize> = BTreeMap::new();
    let mut input = Vec::new();
    let (start, mut executions, mut accepted, mut slowest) = (Instant::now(), 0u64, 0u64, Duration::ZERO);
    let mut slowest_finding = Duration::ZERO;
    loop {
        let done = match config.budget {
            Budget::Executions(n) => executions >= n,
            Budget::Time(t) => start.elapsed() >= t,
        };
        if done {
            break;
        }
        if let Some(seed) = seeds.get(executions as usize) {
            input.clone_from(seed);
        } else {
            // Half the time a seed: grown entries are mostly inputs some check
            // refused, and mutating only those rarely reaches the end of a reader.
            let from = if mutator.below(2) == 0 { seeds.len().max(1) } else { corpus.len() };
            let base = mutator.below(from);
            let other = mutator.below(corpus.len());
            mutator.mutate(&corpus[base], &corpus[other], &mut input);
            (target.fixup)(&mut input);
        }
        executions += 1;
        let (outcome, took, usage) = run_one(target, &scratch, &input, me);
        slowest = slowest.max(took);
        let mut found = Vec::new();
        match outcome {
            Ok(outcome) => {
                accepted += u64::from(outcome.split(" | ").any(|part| part.starts_with("ok")));
                if outcomes.len() >= MAX_OUTCOMES {
                    outcomes.clear();
                }
                if outcomes.insert(signature(&outcome)) && executions as usize > seeds.len() {
                    if corpus.len() < seeds.len() + MAX_GROWN_CORPUS {
                        corpus.push(input.clone());
                    } else {
                        let replace = seeds.len() + mutator.below(MAX_GROWN_CORPUS);
                        corpus[replace].clone_from(&input);
                    }
                }
            }
            Err(panic) => found.push((FindingKind::Panic, panic)),
        }
        if usage.largest_over_cap > 0 {
            found.push((FindingKind::OverCapAllocation, over_cap_message(usage.largest_over_cap)));
        }
        if usage.total_bytes > TOTAL_CAP_BYTES {
            found.push((FindingKind::OverCapTotal, total_message(usage.total_bytes)));
        }
        if config.slow_is_finding && took > config.slow_limit {
            // Once more: on a busy machine a single slow run may be the
            // scheduler's doing, not the reader's.
            let again = run_one(target, &scratch, &input, me).1;
            if again > config.slow_limit {
                let message = format!(
                    "took {:.1} s and {:.1} s, above {:.1} s",
                    took.as_secs_f64(),
                    again.as_secs_f64(),
                    config.slow_limit.as_secs_f64()
                );
                found.push((FindingKind::Slow, message));
            }
        }
        for (kind, message) in found {
            // A panic is known by its location (the first line of the hook's
            // message); other kinds by their kind alone.
            let key = match kind {
                FindingKind::Panic => message.lines().next().unwrap_or("").to_string(),
                _ => String::new(),
            };
            if let Some(&i) = by_signature.get(&(kind, key.clone())) {
                findings[i].hits += 1;
                // Of slow inputs, the slowest is the one worth keeping.
                if kind == FindingKind::Slow && took > slowest_finding {
                    slowest_finding = took;
                    findings[i].input = save(&dir, &input, &format!("{kind:?}: {message}"));
                    findings[i].message = message;
                }
                continue;
            }
            if kind == FindingKind::Slow {
                slowest_finding = took;
            }
            let path = save(&dir, &input, &format!("{kind:?}: {message}"));
            eprintln!("fuzz {}: FINDING {kind:?}: {message}\n  input: {}", target.name, path.display());
            by_signature.insert((kind, key), findings.len());
            findings.push(Finding { kind, message, hits: 1, input: path });
        }
    }
    in_flight().retain(|f| f.thread != me);
    Ok(Report {
        target: target.name,
        executions,
        elapsed: start.elapsed(),
        seeds: seeds.len(),
        corpus: corpus.len(),
        outcomes: outcomes.len(),
        accepted,
        slowest,
        findings,
    })
}

/// Runs one input: its outcome (or the panic message), its time and what it
/// asked the allocator for.
fn run_one(
    target: &Target,
    scratch: &Scratch,
    input: &[u8],
    me: ThreadId,
) -> (Result<String, String>, Duration, Usage) {
    if let Some(f) = in_flight().iter_mut().find(|f| f.thread == me) {
        f.input.clear();
        f.input.extend_from_slice(input);
        f.started = Some(Instant::now());
    }
    let _ = take_usage();
    FUZZING.with(|f| f.set(true));
    let started = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| (target.run)(scratch, input)));
    let took = started.elapsed();
    FUZZING.with(|f| f.set(false));
    let usage = take_usage();
    if let Some(f) = in_flight().iter_mut().find(|f| f.thread == me) {
        f.started = None;
    }
    let result = result.map_err(|payload| {
        let recorded = LAST_PANIC.with(|p| p.borrow_mut().take());
        recorded.unwrap_or_else(|| {
            payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic with a non-text payload".into())
        })
    });
    (result, took, usage)
}
