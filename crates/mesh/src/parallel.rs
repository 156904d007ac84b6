//! Data-parallel loops over mesh elements on scoped threads.
//!
//! The work is cut into consecutive chunks of at least [`MIN_CHUNK`] items (below that,
//! starting a thread costs more than it saves), about [`CHUNKS_PER_THREAD`] per thread;
//! the calling thread and `threads - 1` scoped threads take the next chunk in turn until
//! none is left, so that chunks of costly items (long walks in one region of a surface)
//! do not leave a thread waiting. The results come back in chunk order. Loops whose
//! items are independent (a closest-point search or a walk per point, a Jacobian per
//! face) give the same results for any number of threads.

use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The fewest items worth a chunk of their own.
pub const MIN_CHUNK: usize = 2048;

/// Chunks per thread: enough for the turns to even out uneven chunks.
pub const CHUNKS_PER_THREAD: usize = 8;

/// The cores of this machine (1 when unknown): what a `threads` option of 0 means.
pub fn available_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The consecutive ranges of `0..len` the loops hand out for `threads` threads: one for
/// a single thread, else about [`CHUNKS_PER_THREAD`] per thread of at least
/// [`MIN_CHUNK`] items (at least one range), of equal sizes up to one.
pub fn chunk_ranges(len: usize, threads: usize) -> Vec<Range<usize>> {
    chunk_ranges_of(len, threads, MIN_CHUNK)
}

/// [`chunk_ranges`] with `min_chunk` items at least per range instead of [`MIN_CHUNK`]:
/// for loops whose items cost much more than a thread start (a closest-point search,
/// about a microsecond, against tens of microseconds), so that a few thousand of them
/// are shared too.
pub fn chunk_ranges_of(len: usize, threads: usize, min_chunk: usize) -> Vec<Range<usize>> {
    let count = if threads <= 1 {
        1
    } else {
        (threads * CHUNKS_PER_THREAD)
            .min(len / min_chunk.max(1))
            .max(1)
    };
    (0..count)
        .map(|k| k * len / count..(k + 1) * len / count)
        .collect()
}

/// Runs `a` on the calling thread and `b` on a scoped thread at once and returns both
/// results: two independent computations (the two sides of a factorization, the two
/// meshes of a registration) on two cores. A panic in `b` is passed on.
pub fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    std::thread::scope(|scope| {
        let b = scope.spawn(b);
        let a = a();
        (
            a,
            b.join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
        )
    })
}

/// Runs `work` on every item of `chunks` (in turns, on the calling thread and
/// `threads - 1` scoped threads) and returns the results in the order of `chunks`.
pub(crate) fn in_turns<C: Send, R: Send>(
    chunks: Vec<C>,
    threads: usize,
    work: impl Fn(C) -> R + Sync,
) -> Vec<R> {
    let count = chunks.len();
    if count <= 1 || threads <= 1 {
        return chunks.into_iter().map(work).collect();
    }
    let chunks: Vec<Mutex<Option<C>>> = chunks.into_iter().map(|c| Mutex::new(Some(c))).collect();
    let next = AtomicUsize::new(0);
    let turns = || {
        let mut done = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(slot) = chunks.get(k) else {
                break done;
            };
            let chunk = slot
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .take();
            if let Some(chunk) = chunk {
                done.push((k, work(chunk)));
            }
        }
    };
    let mut done = std::thread::scope(|scope| {
        let others: Vec<_> = (1..threads.min(count))
            .map(|_| scope.spawn(turns))
            .collect();
        let mut done = turns();
        for thread in others {
            done.extend(
                thread
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            );
        }
        done
    });
    done.sort_unstable_by_key(|&(k, _)| k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// `work(range)` over the [`chunk_ranges`] of `0..len`, results in range order.
pub fn map_ranges<R: Send>(
    len: usize,
    threads: usize,
    work: impl Fn(Range<usize>) -> R + Sync,
) -> Vec<R> {
    map_ranges_of(len, threads, MIN_CHUNK, work)
}

/// `work(range)` over the [`chunk_ranges_of`] of `0..len` (ranges of at least
/// `min_chunk` items), results in range order.
pub fn map_ranges_of<R: Send>(
    len: usize,
    threads: usize,
    min_chunk: usize,
    work: impl Fn(Range<usize>) -> R + Sync,
) -> Vec<R> {
    in_turns(chunk_ranges_of(len, threads, min_chunk), threads, work)
}

/// `work(range)` over consecutive ranges of `block` items (the last may be shorter) of
/// `0..len`, results in range order. The ranges do not depend on `threads`, so a
/// reduction that combines the results in order (a sum of floating-point terms) gives
/// the same value for any number of threads.
pub fn map_blocks<R: Send>(
    len: usize,
    block: usize,
    threads: usize,
    work: impl Fn(Range<usize>) -> R + Sync,
) -> Vec<R> {
    let block = block.max(1);
    let ranges = (0..len.div_ceil(block))
        .map(|k| k * block..((k + 1) * block).min(len))
        .collect();
    in_turns(ranges, threads, work)
}

/// `work(offset, chunk)` over the chunks of `items` at the [`chunk_ranges`] (`offset`
/// the index of the chunk's first item), results in chunk order.
pub fn map_chunks_mut<T: Send, R: Send>(
    items: &mut [T],
    threads: usize,
    work: impl Fn(usize, &mut [T]) -> R + Sync,
) -> Vec<R> {
    let ranges = chunk_ranges(items.len(), threads);
    let mut chunks = Vec::with_capacity(ranges.len());
    let mut rest = items;
    for r in &ranges {
        let (chunk, tail) = rest.split_at_mut(r.len());
        chunks.push((r.start, chunk));
        rest = tail;
    }
    in_turns(chunks, threads, |(offset, chunk)| work(offset, chunk))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ranges` tile `0..len` in order, `count` of them, each of at least `least` items
    /// when there are several.
    fn assert_tiling(ranges: &[Range<usize>], len: usize, count: usize, least: usize) {
        assert_eq!(ranges.len(), count, "{len} items, at least {least} a range");
        assert_eq!(ranges[0].start, 0);
        assert_eq!(ranges.last().unwrap().end, len);
        for pair in ranges.windows(2) {
            assert_eq!(pair[0].end, pair[1].start);
        }
        if count > 1 {
            assert!(ranges.iter().all(|r| r.len() >= least));
        }
    }

    #[test]
    fn ranges_cover_the_items_in_order_with_enough_items_each() {
        for (len, threads, count) in [
            (0, 4, 1),
            (10, 4, 1),
            (MIN_CHUNK * 2 - 1, 4, 1),
            (MIN_CHUNK * 2, 4, 2),
            (MIN_CHUNK * 100 + 3, 3, 3 * CHUNKS_PER_THREAD),
            (MIN_CHUNK * 100, 1, 1),
        ] {
            assert_tiling(&chunk_ranges(len, threads), len, count, MIN_CHUNK);
        }
    }

    #[test]
    fn a_smaller_least_chunk_shares_smaller_batches() {
        for (len, threads, least, count) in [
            (2930, 2, 256, 11),
            (2930, 2, MIN_CHUNK, 1),
            (2930, 1, 256, 1),
            (255, 2, 256, 1),
            (100_000, 2, 256, 2 * CHUNKS_PER_THREAD),
            (10, 2, 0, 10),
        ] {
            assert_tiling(&chunk_ranges_of(len, threads, least), len, count, least);
        }
        let lengths = map_ranges_of(2930, 2, 256, |r| r.len());
        assert_eq!(lengths.len(), 11);
        assert_eq!(lengths.iter().sum::<usize>(), 2930);
    }

    #[test]
    fn blocks_are_the_same_for_any_number_of_threads() {
        let sum = |threads| {
            map_blocks(10_007, 1000, threads, |r| {
                r.map(|i| 1.0 / (1.0 + i as f64)).sum::<f64>()
            })
        };
        let one = sum(1);
        assert_eq!(one.len(), 11);
        for threads in [2, 3, 8] {
            assert_eq!(sum(threads), one);
        }
        let lengths = map_blocks(10_007, 1000, 2, |r| r.len());
        assert_eq!(lengths[..10], [1000; 10]);
        assert_eq!(lengths[10], 7);
        assert!(map_blocks(0, 1000, 2, |r| r.len()).is_empty());
    }

    #[test]
    fn chunks_see_their_offsets_and_results_come_back_in_order() {
        let len = MIN_CHUNK * 40 + 5;
        let mut items = vec![0usize; len];
        let parts = map_chunks_mut(&mut items, 2, |offset, chunk| {
            if offset == 0 {
                // The first chunk finishes last.
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            for (i, x) in chunk.iter_mut().enumerate() {
                *x = offset + i;
            }
            (offset, chunk.len())
        });
        assert_eq!(items, (0..len).collect::<Vec<_>>());
        assert_eq!(parts.len(), 2 * CHUNKS_PER_THREAD);
        assert_eq!(parts[0].0, 0);
        assert!(parts.windows(2).all(|p| p[0].0 + p[0].1 == p[1].0));
        assert_eq!(parts.last().map(|p| p.0 + p.1), Some(len));
        let ranges = map_ranges(len, 2, |r| r);
        assert_eq!(ranges, chunk_ranges(len, 2));
        assert_eq!(map_ranges(0, 2, |r| r.len()), vec![0]);
    }

    #[test]
    fn join_runs_both_at_once_and_passes_on_the_other_s_panic() {
        // Each side waits for the other's signal: only two threads at once finish.
        let (to_b, from_a) = std::sync::mpsc::channel();
        let (to_a, from_b) = std::sync::mpsc::channel();
        let (a, b) = join(
            move || {
                to_b.send(1).unwrap();
                from_b.recv().unwrap() + 10
            },
            move || {
                to_a.send(2).unwrap();
                from_a.recv().unwrap() + 20
            },
        );
        assert_eq!((a, b), (12, 21));
        let panicked = std::panic::catch_unwind(|| join(|| 1, || -> i32 { panic!("b failed") }));
        assert!(panicked.is_err());
    }
}
