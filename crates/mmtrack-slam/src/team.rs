//! One parallel region per epoch: a team of the calling thread (the leader)
//! and helper threads started once on the rayon pool, which run the
//! epoch's parallel phases one after the other without a fork-join each.
//!
//! Why not rayon's parallel iterators: an epoch has tens of short passes
//! over the particles (20-300 us each at 2000 particles), and on this
//! project's 2-core VM a rayon fork-join costs about 20 us, so most of a
//! second core's gain went to starting and joining work (docs/benchmarks.md,
//! "SLAM time per epoch").
//!
//! A phase is `tasks` independent tasks. The leader publishes it in one
//! atomic word (a generation number and the range of unclaimed tasks);
//! every member claims tasks from that word until none is left, the leader
//! from the front of the range and the helpers from its back, and the
//! leader waits until every claimed task is done. A pass over the particles
//! ([`Team::map_blocks`]) is one task per member, each a contiguous block
//! of chunks, so with the helpers on time a chunk stays on the same core
//! from phase to phase and a phase costs one claim per member. Measured at
//! 2000 particles on two threads (docs/benchmarks.md): with one task per
//! chunk the tasks took 3-13 % longer than on one thread (the chunks moving
//! between the cores' caches) and each of the epoch's ~29 phases paid 8
//! claims; with one block per member the tasks take as long as on one
//! thread. Claiming from the two ends still hands a late helper's block to
//! the leader. Between phases the
//! leader alone runs the serial steps (the chunks' partial sums added in
//! chunk order, the tempering
//! decisions, the assignment) while the helpers wait, spinning a little
//! and then yielding the core.
//!
//! The leader never waits for a helper that has not started: it claims
//! whatever nobody else has, so a phase ends even when the pool's other
//! threads are busy elsewhere (e.g. `reproduce kim` running filters in
//! parallel on the same pool), and a helper that starts late finds the
//! region over and returns. Which member runs which task varies from run to
//! run; a task writes only its own outputs, so results do not depend on it.
//!
//! Safe Rust (the workspace denies `unsafe`): a phase's job is an owned
//! closure (`'static`, sharing data through `Arc`s), handed to the helpers
//! through a mutex once per phase and generation.

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// A phase's job: runs task `t`.
type Job = Arc<dyn Fn(usize) + Send + Sync>;

/// Bits of the published word: generation (24), first (20) and one past
/// the last (20) unclaimed task.
const TASK_BITS: u32 = 20;
const TASK_MASK: u64 = (1 << TASK_BITS) - 1;
/// Phases with more tasks than fit in the word run on the leader alone.
const MAX_TASKS: usize = TASK_MASK as usize;

/// Spins (each a `spin_loop` hint) before a waiting member starts yielding
/// its core.
const SPINS_BEFORE_YIELD: u32 = 2000;

fn pack(generation: u64, front: usize, back: usize) -> u64 {
    (generation << (2 * TASK_BITS)) | ((front as u64) << TASK_BITS) | back as u64
}

/// `(front, back)` of a published word: tasks `front..back` are unclaimed.
fn front_back(word: u64) -> (usize, usize) {
    (((word >> TASK_BITS) & TASK_MASK) as usize, (word & TASK_MASK) as usize)
}

/// What the members share.
struct Shared {
    /// The published phase: generation and the unclaimed tasks.
    word: AtomicU64,
    /// Tasks of the current phase finished.
    done: AtomicUsize,
    /// The current phase's job (set before its word is published).
    job: Mutex<Option<Job>>,
    /// A task panicked (the leader re-raises it after the phase).
    panicked: AtomicBool,
    /// The region is over: helpers return.
    finished: AtomicBool,
}

impl Shared {
    /// Claims the first (`from_back`: the last) unclaimed task of the phase
    /// `word` was read from; `None` when none is left or the phase changed.
    fn claim(&self, mut word: u64, from_back: bool) -> Option<(u64, usize)> {
        loop {
            let (front, back) = front_back(word);
            if front >= back {
                return None;
            }
            let (claimed, next) = if from_back { (back - 1, word - 1) } else { (front, word + (1 << TASK_BITS)) };
            match self.word.compare_exchange_weak(word, next, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Some((word >> (2 * TASK_BITS), claimed)),
                Err(now) => {
                    if now >> (2 * TASK_BITS) != word >> (2 * TASK_BITS) {
                        return None;
                    }
                    word = now;
                }
            }
        }
    }

    /// Runs task `t` of `job` and counts it done (a panic is recorded, not
    /// propagated, so the phase still ends).
    fn run(&self, job: &Job, t: usize) {
        if catch_unwind(AssertUnwindSafe(|| job(t))).is_err() {
            self.panicked.store(true, Ordering::Relaxed);
        }
        self.done.fetch_add(1, Ordering::Release);
    }

    /// A helper: claims and runs tasks of each phase until the region ends.
    fn help(&self) {
        let mut cached: Option<(u64, Job)> = None;
        let mut idle = 0u32;
        while !self.finished.load(Ordering::Acquire) {
            let word = self.word.load(Ordering::Acquire);
            if let Some((generation, t)) = self.claim(word, true) {
                let job = match &cached {
                    Some((g, job)) if *g == generation => job.clone(),
                    _ => {
                        let job = self.job.lock().unwrap_or_else(PoisonError::into_inner).clone();
                        let Some(job) = job else {
                            // Cannot happen (the job is set before its phase is
                            // published); count the task as failed, not lost.
                            self.panicked.store(true, Ordering::Relaxed);
                            self.done.fetch_add(1, Ordering::Release);
                            continue;
                        };
                        cached = Some((generation, job.clone()));
                        job
                    }
                };
                self.run(&job, t);
                idle = 0;
            } else {
                wait(&mut idle);
            }
        }
    }
}

/// One wait step: a spin hint, or after [`SPINS_BEFORE_YIELD`] of them a
/// yield of the core.
fn wait(idle: &mut u32) {
    if *idle < SPINS_BEFORE_YIELD {
        *idle += 1;
        std::hint::spin_loop();
    } else {
        std::thread::yield_now();
    }
}

/// The members of one parallel region, seen from the leader.
pub(crate) struct Team {
    /// `None`: the leader alone (one thread, or a single task).
    shared: Option<Arc<Shared>>,
    /// Generation of the last published phase.
    generation: std::cell::Cell<u64>,
    /// Phases run with more than one task: synchronisation points when the
    /// team has helpers, the same count on any team.
    phases: std::cell::Cell<u64>,
    /// The leader and its helpers: the blocks of [`Team::map_blocks`].
    members: usize,
}

impl Team {
    /// A team of the calling thread alone: every phase runs inline.
    pub(crate) fn solo() -> Self {
        Self { shared: None, generation: 0.into(), phases: 0.into(), members: 1 }
    }

    /// Phases run with more than one task.
    pub(crate) fn phases(&self) -> u64 {
        self.phases.get()
    }

    /// Runs `f(t)` for `t` in `0..tasks` on the team and returns the
    /// results in task order.
    pub(crate) fn map<R: Send + 'static>(
        &self,
        tasks: usize,
        f: impl Fn(usize) -> R + Send + Sync + 'static,
    ) -> Vec<R> {
        if tasks > 1 {
            self.phases.set(self.phases.get() + 1);
        }
        self.run_tasks(tasks, f)
    }

    /// [`Team::map`] over `items` split into one contiguous block per
    /// member (the items' order kept): a task runs `f` over its block's
    /// items in order. The results do not depend on the team; the phase
    /// counts when `items > 1`, as on any team.
    pub(crate) fn map_blocks<R: Send + 'static>(
        &self,
        items: usize,
        f: impl Fn(usize) -> R + Send + Sync + 'static,
    ) -> Vec<R> {
        if items > 1 {
            self.phases.set(self.phases.get() + 1);
        }
        let blocks = self.members.clamp(1, items.max(1));
        let per_block = self.run_tasks(blocks, move |b| {
            let (first, end) = (b * items / blocks, (b + 1) * items / blocks);
            (first..end).map(&f).collect::<Vec<R>>()
        });
        per_block.into_iter().flatten().collect()
    }

    /// [`Team::map`] without counting the phase.
    fn run_tasks<R: Send + 'static>(&self, tasks: usize, f: impl Fn(usize) -> R + Send + Sync + 'static) -> Vec<R> {
        let shared = match &self.shared {
            Some(shared) if tasks > 1 && tasks <= MAX_TASKS => shared,
            _ => return (0..tasks).map(f).collect(),
        };
        let slots: Arc<Vec<Mutex<Option<R>>>> = Arc::new((0..tasks).map(|_| Mutex::new(None)).collect());
        let out = slots.clone();
        let job: Job = Arc::new(move |t| {
            let r = f(t);
            *out[t].lock().unwrap_or_else(PoisonError::into_inner) = Some(r);
        });
        let generation = self.generation.get() + 1;
        self.generation.set(generation);
        *shared.job.lock().unwrap_or_else(PoisonError::into_inner) = Some(job.clone());
        shared.done.store(0, Ordering::Relaxed);
        shared.word.store(pack(generation, 0, tasks), Ordering::Release);
        loop {
            let word = shared.word.load(Ordering::Acquire);
            let Some((_, t)) = shared.claim(word, false) else { break };
            shared.run(&job, t);
        }
        let mut idle = 0;
        while shared.done.load(Ordering::Acquire) < tasks {
            wait(&mut idle);
        }
        if shared.panicked.swap(false, Ordering::Relaxed) {
            resume_unwind(Box::new("a task of the SLAM filter's parallel phase panicked"));
        }
        slots
            .iter()
            .map(|s| s.lock().unwrap_or_else(PoisonError::into_inner).take())
            .collect::<Option<Vec<R>>>()
            .unwrap_or_else(|| resume_unwind(Box::new("a task of the SLAM filter's parallel phase left no result")))
    }
}

/// Sets `finished` when the region ends, also by a panic, so the helpers
/// return and the scope can close.
struct Finish(Arc<Shared>);

impl Drop for Finish {
    fn drop(&mut self) {
        self.0.finished.store(true, Ordering::Release);
    }
}

/// Runs `body` with a team of one member per thread of the current rayon
/// pool, at most `max_members` (the leader is the calling thread).
pub(crate) fn with_team<T>(max_members: usize, body: impl FnOnce(&Team) -> T) -> T {
    let members = rayon::current_num_threads().min(max_members);
    if members <= 1 {
        return body(&Team::solo());
    }
    let shared = Arc::new(Shared {
        word: AtomicU64::new(0),
        done: AtomicUsize::new(0),
        job: Mutex::new(None),
        panicked: AtomicBool::new(false),
        finished: AtomicBool::new(false),
    });
    rayon::in_place_scope(|scope| {
        for _ in 1..members {
            let helper = shared.clone();
            scope.spawn(move |_| helper.help());
        }
        let _finish = Finish(shared.clone());
        let team = Team { shared: Some(shared.clone()), generation: 0.into(), phases: 0.into(), members };
        body(&team)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_task_runs_once_and_results_come_in_task_order() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (results, phases) = pool.install(|| {
                with_team(4, |team| {
                    let counts = Arc::new((0..100).map(|_| AtomicUsize::new(0)).collect::<Vec<_>>());
                    let mut all = Vec::new();
                    for phase in 0..50 {
                        let c = counts.clone();
                        all.push(team.map(100, move |t| {
                            c[t].fetch_add(1, Ordering::Relaxed);
                            t * 1000 + phase
                        }));
                    }
                    assert!(counts.iter().all(|c| c.load(Ordering::Relaxed) == 50), "{threads} threads");
                    (all, team.phases())
                })
            });
            assert_eq!(phases, 50);
            for (phase, r) in results.iter().enumerate() {
                assert_eq!(*r, (0..100).map(|t| t * 1000 + phase).collect::<Vec<_>>(), "{threads} threads");
            }
        }
    }

    #[test]
    fn blocks_run_every_item_once_and_keep_the_item_order() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                with_team(8, |team| {
                    for items in [0, 1, 2, 5, 8, 11] {
                        let counts = Arc::new((0..items).map(|_| AtomicUsize::new(0)).collect::<Vec<_>>());
                        let c = counts.clone();
                        let out = team.map_blocks(items, move |i| {
                            c[i].fetch_add(1, Ordering::Relaxed);
                            10 * i
                        });
                        assert_eq!(out, (0..items).map(|i| 10 * i).collect::<Vec<_>>(), "{threads} threads");
                        assert!(counts.iter().all(|c| c.load(Ordering::Relaxed) == 1), "{threads} threads");
                    }
                    // Phases of more than one item count, on any team.
                    assert_eq!(team.phases(), 4, "{threads} threads");
                });
            });
        }
    }

    #[test]
    fn a_busy_pool_does_not_stall_the_leader() {
        // Two regions at once on a 2-thread pool: each leader may find no
        // free helper and must finish its phases alone.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let sums: Vec<usize> = pool.install(|| {
            use rayon::prelude::*;
            (0..4)
                .into_par_iter()
                .map(|r| {
                    with_team(8, |team| (0..20).map(|p| team.map(8, move |t| t + p + r).iter().sum::<usize>()).sum())
                })
                .collect()
        });
        let expected = |r: usize| (0..20).map(|p| (0..8).map(|t| t + p + r).sum::<usize>()).sum::<usize>();
        assert_eq!(sums, (0..4).map(expected).collect::<Vec<_>>());
    }

    #[test]
    fn a_panicking_task_reaches_the_leader() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let caught = pool.install(|| {
            catch_unwind(AssertUnwindSafe(|| {
                with_team(2, |team| {
                    team.map(4, |t| assert!(t != 3, "task 3"));
                })
            }))
        });
        assert!(caught.is_err());
    }
}
