//! Channels read side by side: a reader whose channels are independent in the file
//! (Parquet columns) hands them to [`map_ordered`], which runs on up to [`threads_for`]
//! threads and gives the results back in the channels' order, so the first error in file
//! order is still the one a reader reports.
//!
//! Not used for MAT v7.3: the HDF5 layer holds a dataset's bytes and its converted values
//! at once, so two datasets read together took the peak from 1.32 to 1.86 times the
//! channels (the limit is 1.5) for 11 % less time.

use std::sync::atomic::{AtomicUsize, Ordering};

/// At most this many threads read one file.
pub(crate) const MAX_THREADS: usize = 4;

/// Channels holding fewer bytes than this together are read one by one: starting threads
/// would cost more than it saves.
pub(crate) const PARALLEL_FROM: u64 = 1 << 20;

/// How many threads read `items` channels of `bytes` bytes together: one below
/// `parallel_from` bytes, else as many as the machine offers, at most one a channel and
/// [`MAX_THREADS`].
pub(crate) fn threads_for(items: usize, bytes: u64, parallel_from: u64) -> usize {
    if bytes < parallel_from {
        return 1;
    }
    std::thread::available_parallelism()
        .map_or(1, std::num::NonZeroUsize::get)
        .min(items)
        .clamp(1, MAX_THREADS)
}

/// `f` of every item, in the items' order, on up to `threads` threads, each taking the next
/// item not yet taken; `None` for the items of a thread that panicked (the readers catch
/// their parsers' panics, so none is expected).
pub(crate) fn map_ordered<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<Option<R>> {
    if threads <= 1 {
        return items.iter().map(|x| Some(f(x))).collect();
    }
    let next = AtomicUsize::new(0);
    let done: Vec<Vec<(usize, R)>> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(x) = items.get(i) else {
                            return out;
                        };
                        out.push((i, f(x)));
                    }
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().ok()).collect()
    });
    let mut results: Vec<Option<R>> = Vec::new();
    results.resize_with(items.len(), || None);
    for (i, r) in done.into_iter().flatten() {
        results[i] = Some(r);
    }
    results
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_order_whatever_the_threads() {
        let items: Vec<u64> = (0..100).collect();
        for threads in [1, 2, 3, 8] {
            // later items finish first
            let r = map_ordered(&items, threads, |&x| {
                std::thread::sleep(std::time::Duration::from_micros(100 - x));
                x * x
            });
            let want: Vec<Option<u64>> = items.iter().map(|x| Some(x * x)).collect();
            assert_eq!(r, want, "{threads} threads");
        }
        assert_eq!(threads_for(6, 10, 1 << 20), 1);
        assert_eq!(threads_for(1, u64::MAX, 0), 1);
        let n = threads_for(6, 1 << 20, 1 << 20);
        assert!((1..=MAX_THREADS).contains(&n));
    }
}
