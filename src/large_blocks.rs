//! A global allocator that maps large blocks itself: huge pages, freed blocks kept for
//! the next large allocation, and growth without copying.
//!
//! The solvers allocate operators and factors of hundreds of megabytes and touch every
//! page. The kernel clears a page the first time a process touches it, and on the
//! virtual machines measured (docs/benchmarks.md) that first touch cost 1-2.5 s per GB,
//! a quarter of the CPU time of an LSCM map of 1M triangles, whose large blocks add up
//! to 4.6 GB over the run against a peak of 2.7 GB live. So, for blocks of at least
//! 2 MiB (alignment at most a page):
//!
//! - a block is mapped anonymously, rounded up to whole huge pages and advised
//!   `MADV_HUGEPAGE` (2 MiB pages where transparent huge pages are in `madvise` mode,
//!   the common default);
//! - a freed block is kept (at most [`KEEP_BYTES`] in at most [`KEEP_BLOCKS`] blocks)
//!   and serves the next large allocation: the head of the smallest kept block that
//!   holds it (the rest stays kept), else the largest kept block grown by `mremap`,
//!   which moves page tables, not bytes; `alloc_zeroed` clears what it reuses;
//! - `realloc` between large sizes is `mremap`: a growing vector keeps its pages.
//!
//! Smaller blocks go to the system allocator unchanged.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Size from which a block is mapped here: one huge page.
const HUGE: usize = 2 << 20;

/// Largest alignment a mapping guarantees.
const PAGE: usize = 4096;

/// Most bytes kept in freed blocks.
const KEEP_BYTES: usize = 1 << 30;

/// Most freed blocks kept.
const KEEP_BLOCKS: usize = 64;

/// The allocator (module docs).
pub struct LargeBlocks;

/// Whether a block of `layout` is mapped here.
fn is_large(layout: Layout) -> bool {
    layout.size() >= HUGE && layout.align() <= PAGE
}

/// The bytes mapped for a large block of `size` bytes: whole huge pages.
fn mapped_len(size: usize) -> Option<usize> {
    size.checked_next_multiple_of(HUGE)
}

/// A mapped range: its start address and length, a multiple of [`HUGE`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Range {
    start: usize,
    len: usize,
}

/// How a kept range serves a request of `len` bytes ([`Kept::take`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reuse {
    /// The first `len` bytes of a kept range, whose rest stays kept.
    Head(usize),
    /// A kept range shorter than the request, to grow to it.
    Grow(Range),
}

/// Freed large blocks.
struct Kept {
    ranges: [Range; KEEP_BLOCKS],
    count: usize,
    bytes: usize,
}

static KEPT: Mutex<Kept> = Mutex::new(Kept::EMPTY);

/// The kept ranges (nothing panics while they are locked, so a poisoned lock is only
/// another thread's panic elsewhere).
fn kept() -> MutexGuard<'static, Kept> {
    KEPT.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Kept {
    /// No range kept.
    const EMPTY: Kept = Kept {
        ranges: [Range { start: 0, len: 0 }; KEEP_BLOCKS],
        count: 0,
        bytes: 0,
    };

    /// Keeps `range` if the limits allow; whether it was kept.
    fn keep(&mut self, range: Range) -> bool {
        if self.count == KEEP_BLOCKS || self.bytes + range.len > KEEP_BYTES {
            return false;
        }
        self.ranges[self.count] = range;
        self.count += 1;
        self.bytes += range.len;
        true
    }

    fn remove(&mut self, i: usize) -> Range {
        let range = self.ranges[i];
        self.count -= 1;
        self.ranges[i] = self.ranges[self.count];
        self.bytes -= range.len;
        range
    }

    /// A kept range for a request of `len` bytes (a multiple of [`HUGE`]): the head of
    /// the smallest range at least that long, else the longest range, to grow; `None`
    /// when nothing is kept.
    fn take(&mut self, len: usize) -> Option<Reuse> {
        let ranges = &self.ranges[..self.count];
        let fitting = (0..ranges.len())
            .filter(|&i| ranges[i].len >= len)
            .min_by_key(|&i| ranges[i].len);
        if let Some(i) = fitting {
            let range = self.remove(i);
            if range.len > len {
                // Taken from a longer range than it was, the rest always fits the limits.
                self.keep(Range {
                    start: range.start + len,
                    len: range.len - len,
                });
            }
            return Some(Reuse::Head(range.start));
        }
        let longest = (0..ranges.len()).max_by_key(|&i| ranges[i].len)?;
        Some(Reuse::Grow(self.remove(longest)))
    }
}

/// Advises the kernel to back `len` bytes at `ptr` with huge pages (best effort: the
/// advice changes performance only, so its result is ignored).
///
/// # Safety
/// `ptr..ptr + len` is a mapping of this module.
unsafe fn advise(ptr: *mut u8, len: usize) {
    // SAFETY: madvise does not access the memory; the range is mapped.
    unsafe {
        libc::madvise(ptr.cast(), len, libc::MADV_HUGEPAGE);
    }
}

/// A fresh anonymous mapping of `len` bytes (zeros), or null.
fn map(len: usize) -> *mut u8 {
    // SAFETY: a new private anonymous mapping aliases nothing.
    let ptr = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            len,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    if ptr == libc::MAP_FAILED {
        return std::ptr::null_mut();
    }
    let ptr = ptr.cast::<u8>();
    // SAFETY: just mapped.
    unsafe { advise(ptr, len) };
    ptr
}

/// The mapping of `old_len` bytes at `ptr` resized to `new_len` bytes (moved if need
/// be, contents kept) and advised; null when the kernel refuses, the mapping then left
/// as it was.
///
/// # Safety
/// `ptr..ptr + old_len` is a mapping of this module that nothing else refers to.
unsafe fn remap(ptr: *mut u8, old_len: usize, new_len: usize) -> *mut u8 {
    // SAFETY: the caller's contract; mremap moves page tables only.
    let moved = unsafe { libc::mremap(ptr.cast(), old_len, new_len, libc::MREMAP_MAYMOVE) };
    if moved == libc::MAP_FAILED {
        return std::ptr::null_mut();
    }
    let moved = moved.cast::<u8>();
    // SAFETY: `moved..moved + new_len` is now mapped.
    unsafe { advise(moved, new_len) };
    moved
}

/// `len` bytes from a kept range, when one is kept: the start and how many of the
/// first bytes may hold old contents (a grown range's new pages are zeros).
fn reuse(len: usize) -> Option<(*mut u8, usize)> {
    let reuse = kept().take(len)?;
    match reuse {
        Reuse::Head(start) => Some((start as *mut u8, len)),
        Reuse::Grow(range) => {
            // SAFETY: the range was mapped here and freed; nothing else refers to it.
            let moved = unsafe { remap(range.start as *mut u8, range.len, len) };
            if moved.is_null() {
                // SAFETY: as above; a failed mremap leaves the range mapped.
                unsafe { libc::munmap(range.start as *mut libc::c_void, range.len) };
                return None;
            }
            Some((moved, range.len))
        }
    }
}

/// A large block for `layout`, zeroed when `zeroed`, or null.
fn alloc_large(layout: Layout, zeroed: bool) -> *mut u8 {
    let Some(len) = mapped_len(layout.size()) else {
        return std::ptr::null_mut();
    };
    match reuse(len) {
        Some((ptr, used)) => {
            if zeroed {
                // SAFETY: `ptr..ptr + len` is mapped and ours, and `used <= len`.
                unsafe { std::ptr::write_bytes(ptr, 0, used.min(layout.size())) };
            }
            ptr
        }
        None => map(len),
    }
}

// SAFETY: large blocks (`is_large` of the caller's layout, which `dealloc` and
// `realloc` recompute from the same layout) are mappings of whole huge pages made here
// and aligned to a page, which satisfies their alignment; each is either live with one
// owner or kept, never both. Other blocks come from and return to `System` with the
// caller's layout.
unsafe impl GlobalAlloc for LargeBlocks {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if is_large(layout) {
            alloc_large(layout, false)
        } else {
            // SAFETY: forwarded contract of `GlobalAlloc::alloc`.
            unsafe { System.alloc(layout) }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if is_large(layout) {
            alloc_large(layout, true)
        } else {
            // SAFETY: forwarded contract of `GlobalAlloc::alloc_zeroed`.
            unsafe { System.alloc_zeroed(layout) }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if !is_large(layout) {
            // SAFETY: `ptr` came from `System` with this layout.
            return unsafe { System.dealloc(ptr, layout) };
        }
        // The block was allocated, so its length did not overflow.
        let Some(len) = mapped_len(layout.size()) else {
            return;
        };
        let range = Range {
            start: ptr as usize,
            len,
        };
        if !kept().keep(range) {
            // SAFETY: the block is this module's mapping of `len` bytes, now unused.
            unsafe { libc::munmap(ptr.cast(), len) };
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let Ok(new_layout) = Layout::from_size_align(new_size, layout.align()) else {
            return std::ptr::null_mut();
        };
        match (is_large(layout), is_large(new_layout)) {
            // SAFETY: a small block of `System` with this layout, to a small size.
            (false, false) => unsafe { System.realloc(ptr, layout, new_size) },
            (true, true) => {
                let (Some(old_len), Some(new_len)) =
                    (mapped_len(layout.size()), mapped_len(new_size))
                else {
                    return std::ptr::null_mut();
                };
                if old_len == new_len {
                    return ptr;
                }
                // SAFETY: the block is this module's mapping of `old_len` bytes, owned by
                // the caller; on failure it stays as it was (realloc's contract).
                unsafe { remap(ptr, old_len, new_len) }
            }
            // Crossing the threshold changes who holds the block: move it.
            // SAFETY: `new_layout` has a non-zero size (realloc's contract) and the old
            // block is valid for `min(old, new)` bytes; it is freed with its own layout
            // after the copy.
            _ => unsafe {
                let new_ptr = self.alloc(new_layout);
                if !new_ptr.is_null() {
                    std::ptr::copy_nonoverlapping(ptr, new_ptr, layout.size().min(new_size));
                    self.dealloc(ptr, layout);
                }
                new_ptr
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_keep_their_contents_across_the_threshold() {
        // Grow a vector from small to huge (each reallocation a move or an mremap) and
        // back, checking every element survives.
        let mut v: Vec<u64> = (0..1000).collect();
        v.extend(1000..2_000_000);
        assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64));
        v.truncate(100);
        v.shrink_to_fit();
        assert_eq!(v, (0..100).collect::<Vec<u64>>());
    }

    #[test]
    fn zeroed_blocks_are_zeros_after_a_dirty_block_was_freed() {
        // Every freed block here is dirty, so a zeroed block reusing one (its head, or
        // grown from it) must have been cleared.
        for round in 1..20usize {
            let dirty = vec![0xa5u8; (3 + round % 5) << 20];
            drop(dirty);
            let zeroed = vec![0u8; (2 + round % 7) << 20];
            assert!(zeroed.iter().all(|&b| b == 0), "round {round}");
        }
    }

    fn range(start: usize, megabytes: usize) -> Range {
        Range {
            start,
            len: megabytes * HUGE,
        }
    }

    #[test]
    fn a_request_takes_the_head_of_the_smallest_range_that_holds_it() {
        let mut kept = Kept::EMPTY;
        assert_eq!(kept.take(HUGE), None);
        for r in [range(1 << 40, 8), range(2 << 40, 3), range(3 << 40, 5)] {
            assert!(kept.keep(r));
        }
        // 4 huge pages: the 5-page range's head; its last page stays kept.
        assert_eq!(kept.take(4 * HUGE), Some(Reuse::Head(3 << 40)));
        assert_eq!(kept.count, 3);
        assert_eq!(kept.bytes, (8 + 3 + 1) * HUGE);
        assert!(kept.ranges[..3].contains(&Range {
            start: (3 << 40) + 4 * HUGE,
            len: HUGE
        }));
        // Longer than any: the longest, to grow.
        assert_eq!(kept.take(20 * HUGE), Some(Reuse::Grow(range(1 << 40, 8))));
        assert_eq!(kept.bytes, (3 + 1) * HUGE);
    }

    #[test]
    fn kept_ranges_stay_within_the_limits() {
        let mut kept = Kept::EMPTY;
        assert!(!kept.keep(Range {
            start: 0,
            len: KEEP_BYTES + HUGE
        }));
        for i in 0..KEEP_BLOCKS {
            assert!(kept.keep(range(i << 30, 1)));
        }
        assert!(!kept.keep(range(1 << 45, 1)));
        assert_eq!(kept.count, KEEP_BLOCKS);
    }
}
