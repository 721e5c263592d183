//! Order-keeping parallel work on the current rayon thread pool.
//!
//! Every parallel stage of mmtrack (PNG decoding in ingest and odometry,
//! sweep and set rendering in the simulators, MPC detection) maps items on
//! rayon and hands the results on in input order, so outputs are identical
//! for any thread count. The thread count is the caller's: the current pool
//! (`ThreadPool::install`), else rayon's global pool (`RAYON_NUM_THREADS`, or
//! one thread per core).

use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

/// Maps `items` on the current rayon pool and passes the results to
/// `consume` in input order, keeping up to `per_thread` items per pool thread
/// in flight ahead of the consumer, so a sequential consumer overlaps the
/// parallel map without a barrier between batches.
///
/// Each item is mapped by its own task ([`rayon::scope_fifo`]); the consumer
/// takes the results in input order and, while the next one is not ready,
/// runs pending map tasks itself (`rayon::yield_now`) or sleeps until it is.
/// At most `per_thread * threads` results wait at once, so memory does not
/// grow with the number of items. `items` is pulled on the consumer's thread.
/// The first error of `consume` stops the work and is returned; items after
/// it are not consumed (the tasks already started finish first). Because
/// `consume` sees the results in order and the map is per item, the outcome
/// does not depend on the thread count. A panic in `map` is re-raised.
///
/// `consume` must be `Send`: it runs on a pool thread, not necessarily the
/// caller's.
///
/// # Errors
/// The first error returned by `consume`.
pub fn map_in_order<I, U, E>(
    items: I,
    per_thread: usize,
    map: impl Fn(I::Item) -> U + Sync,
    consume: impl FnMut(U) -> Result<(), E> + Send,
) -> Result<(), E>
where
    I: Iterator + Send,
    I::Item: Send,
    U: Send,
    E: Send,
{
    map_in_order_within(items, per_thread, usize::MAX, |_| 0, map, consume)
}

/// [`map_in_order`] within a memory budget: `cost(item)` (called on the
/// consumer's thread, in input order) is what the item may hold from the
/// start of its map until `consume` has taken its result, and the items
/// mapped or waiting at once cost at most `budget_bytes` together; an item
/// over the budget is mapped alone. Admission is decided by the consumer, so
/// no map task ever waits for memory (a task waiting for the consumer while
/// the consumer runs it would never end), and the outcome does not depend
/// on the thread count.
///
/// # Errors
/// The first error returned by `consume`.
pub fn map_in_order_within<I, U, E>(
    items: I,
    per_thread: usize,
    budget_bytes: usize,
    mut cost: impl FnMut(&I::Item) -> usize + Send,
    map: impl Fn(I::Item) -> U + Sync,
    mut consume: impl FnMut(U) -> Result<(), E> + Send,
) -> Result<(), E>
where
    I: Iterator + Send,
    I::Item: Send,
    U: Send,
    E: Send,
{
    let window = per_thread.max(1) * rayon::current_num_threads();
    let slots: Vec<Slot<U>> = (0..window).map(|_| Slot::default()).collect();
    let (map, slots) = (&map, &slots);
    let mut items = items;
    rayon::scope_fifo(move |scope| {
        let spawn = |index: usize, item: I::Item| {
            let slot = &slots[index % window];
            scope.spawn_fifo(move |_| {
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| map(item)));
                slot.fill(outcome);
            });
        };
        // Costs of the items spawned and not yet consumed, oldest first.
        let mut costs = std::collections::VecDeque::with_capacity(window);
        let (mut in_flight, mut spawned, mut next) = (0usize, 0usize, 0usize);
        // The next item with its cost, waiting for room in the budget.
        let mut waiting: Option<(I::Item, usize)> = None;
        loop {
            while spawned - next < window {
                let Some((item, bytes)) = waiting.take().or_else(|| {
                    items.next().map(|item| {
                        let bytes = cost(&item);
                        (item, bytes)
                    })
                }) else {
                    break;
                };
                if spawned > next && in_flight.saturating_add(bytes) > budget_bytes {
                    waiting = Some((item, bytes));
                    break;
                }
                in_flight = in_flight.saturating_add(bytes);
                costs.push_back(bytes);
                spawn(spawned, item);
                spawned += 1;
            }
            if next == spawned {
                return Ok(());
            }
            consume(slots[next % window].take())?;
            in_flight -= costs.pop_front().unwrap_or(0);
            next += 1;
        }
    })
}

/// Where a map task leaves its result for the consumer.
struct Slot<U> {
    value: Mutex<Option<std::thread::Result<U>>>,
    filled: Condvar,
}

impl<U> Default for Slot<U> {
    fn default() -> Self {
        Self { value: Mutex::new(None), filled: Condvar::new() }
    }
}

impl<U> Slot<U> {
    fn lock(&self) -> MutexGuard<'_, Option<std::thread::Result<U>>> {
        self.value.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn fill(&self, outcome: std::thread::Result<U>) {
        *self.lock() = Some(outcome);
        self.filled.notify_all();
    }

    /// The result, once its task has run: meanwhile this thread runs other
    /// pending tasks, or sleeps when there are none (the task is running on
    /// another thread).
    fn take(&self) -> U {
        loop {
            if let Some(outcome) = self.lock().take() {
                return outcome.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            }
            if rayon::yield_now() != Some(rayon::Yield::Executed) {
                let guard = self.lock();
                if guard.is_none() {
                    // Filled under the lock, so no notification is lost.
                    drop(self.filled.wait(guard).unwrap_or_else(PoisonError::into_inner));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
    }

    #[test]
    fn results_come_in_input_order_for_any_thread_count_and_batch() {
        let expected: Vec<u64> = (0..103u64).map(|i| i * i).collect();
        for threads in [1, 2, 3, 8] {
            for batch in [0, 1, 2, 7, 60] {
                let mut seen = Vec::new();
                pool(threads)
                    .install(|| {
                        map_in_order(
                            0..103u64,
                            batch,
                            |i| i * i,
                            |v| {
                                seen.push(v);
                                Ok::<(), ()>(())
                            },
                        )
                    })
                    .unwrap();
                assert_eq!(seen, expected, "threads {threads}, batch {batch}");
            }
        }
    }

    /// Without the budget, 4 threads map 8 items ahead (80 bytes of
    /// 10-byte items); within 30 bytes, at most 3 are held at once, and an
    /// item over the budget is held alone.
    #[test]
    fn items_held_at_once_stay_within_the_budget() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let cost = |i: &usize| if i % 7 == 3 { 100 } else { 10 };
        for threads in [1, 2, 4] {
            let (held, peak) = (AtomicUsize::new(0), AtomicUsize::new(0));
            let mut seen = Vec::new();
            pool(threads)
                .install(|| {
                    map_in_order_within(
                        0..40usize,
                        2,
                        30,
                        cost,
                        |i| {
                            let now = held.fetch_add(cost(&i), Ordering::SeqCst) + cost(&i);
                            peak.fetch_max(if cost(&i) > 30 { now - cost(&i) + 30 } else { now }, Ordering::SeqCst);
                            std::thread::sleep(std::time::Duration::from_millis(2));
                            i
                        },
                        |i| {
                            held.fetch_sub(cost(&i), Ordering::SeqCst);
                            seen.push(i);
                            Ok::<(), ()>(())
                        },
                    )
                })
                .unwrap();
            assert_eq!(seen, (0..40).collect::<Vec<_>>());
            assert!(peak.load(Ordering::SeqCst) <= 30, "{threads} threads: {} held", peak.load(Ordering::SeqCst));
        }
    }

    #[test]
    fn the_first_consume_error_stops_the_work() {
        for threads in [1, 2, 4] {
            let mut consumed = Vec::new();
            let err = pool(threads).install(|| {
                map_in_order(
                    0..50u32,
                    4,
                    |i| i,
                    |v| {
                        if v == 9 {
                            return Err(format!("item {v}"));
                        }
                        consumed.push(v);
                        Ok(())
                    },
                )
            });
            assert_eq!(err, Err("item 9".to_string()));
            assert_eq!(consumed, (0..9).collect::<Vec<_>>(), "threads {threads}");
        }
    }

    #[test]
    fn empty_input_consumes_nothing() {
        let mut calls = 0;
        map_in_order(
            std::iter::empty::<u8>(),
            4,
            |i| i,
            |_| {
                calls += 1;
                Ok::<(), ()>(())
            },
        )
        .unwrap();
        assert_eq!(calls, 0);
    }

    #[test]
    fn a_panic_in_map_reaches_the_caller() {
        for threads in [1, 2] {
            let outcome = std::panic::catch_unwind(|| {
                pool(threads).install(|| {
                    map_in_order(
                        0..20u32,
                        2,
                        |i| if i == 5 { panic!("deliberate test panic: map of item {i}") } else { i },
                        |_| Ok::<(), ()>(()),
                    )
                })
            });
            assert!(outcome.is_err(), "threads {threads}");
        }
    }
}
