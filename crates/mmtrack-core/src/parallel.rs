//! Order-keeping parallel work on the current rayon thread pool.
//!
//! Every parallel stage of mmtrack (PNG decoding in ingest and odometry,
//! sweep and set rendering in the simulators, MPC detection) maps items on
//! rayon and hands the results on in input order, so outputs are identical
//! for any thread count. The thread count is the caller's: the current pool
//! (`ThreadPool::install`), else rayon's global pool (`RAYON_NUM_THREADS`, or
//! one thread per core).

use rayon::prelude::*;

/// Maps `items` on the current rayon pool and passes the results to
/// `consume` in input order, one batch (`per_thread` items for each thread of
/// the pool) while the next batch is mapped, so a sequential consumer
/// overlaps the parallel map.
///
/// At most two batches are held at once (the one being consumed and the one
/// being mapped), so memory does not grow with the number of items. `items`
/// is pulled from one thread at a time. The first error of `consume` stops
/// the work and is returned; items after it are not consumed (at most one
/// more batch has been mapped). Because `consume` sees the results in order
/// and the map is per item, the outcome does not depend on the thread count.
///
/// `consume` must be `Send`: it runs on a pool thread (with
/// [`rayon::join`]), not necessarily the caller's.
///
/// # Errors
/// The first error returned by `consume`.
pub fn map_in_order<I, U, E>(
    items: I,
    per_thread: usize,
    map: impl Fn(I::Item) -> U + Sync,
    mut consume: impl FnMut(U) -> Result<(), E> + Send,
) -> Result<(), E>
where
    I: Iterator + Send,
    I::Item: Send,
    U: Send,
    E: Send,
{
    let batch_len = per_thread.max(1) * rayon::current_num_threads();
    let mut items = items;
    let mut map_next = || -> Vec<U> {
        let batch: Vec<I::Item> = items.by_ref().take(batch_len).collect();
        batch.into_par_iter().map(&map).collect()
    };
    let mut ready = map_next();
    while !ready.is_empty() {
        let (next, consumed) = rayon::join(&mut map_next, || ready.into_iter().try_for_each(&mut consume));
        consumed?;
        ready = next;
    }
    Ok(())
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
}
