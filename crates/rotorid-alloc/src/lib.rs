//! The allocator of the `rotorid` binary and of the Python extension (each declares it as
//! its `#[global_allocator]`): the system's, with every block of [`THRESHOLD`] bytes or
//! more offered to the kernel for transparent huge pages (`madvise(MADV_HUGEPAGE)` on the
//! 2 MiB pages the block covers). In the Python extension it serves the extension's own
//! allocations (the channels a reader fills, which numpy then owns and frees through it),
//! not Python's.
//!
//! Why: a binary recording's channels are tens of megabytes written once. With 4 KiB pages
//! each page costs a fault on first touch, and on the 2-core test machine those faults were
//! about a quarter of reading a MAT, NPZ or Parquet file (`perf record` of `rotorid
//! inspect`: `clear_page`, `exc_page_fault`, the page allocator). Where the kernel's THP
//! mode is `madvise` (Debian's default) a huge page takes the place of 512 faults; where it
//! is `always` or `never` the advice changes nothing. Timings: docs/performance.md.
//!
//! Only the advice is added: the blocks, their alignment and their contents are the system
//! allocator's, and a refused `madvise` is ignored (it is advice).

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks at least this large \[bytes\] are advised (two huge pages: a smaller block
/// rarely covers a whole aligned one).
pub const THRESHOLD: usize = 4 << 20;

/// The size of a transparent huge page on x86_64 and aarch64 with 4 KiB base pages \[bytes\].
const HUGE_PAGE: usize = 2 << 20;

/// The system allocator, advising large blocks for huge pages (module doc).
pub struct HugePageAdvice;

/// The whole huge pages inside the block `[start, start + size)`: (first, length), or
/// `None` when the block is under [`THRESHOLD`] or covers no whole huge page.
fn huge_span(start: usize, size: usize) -> Option<(usize, usize)> {
    if size < THRESHOLD {
        return None;
    }
    let first = start.checked_next_multiple_of(HUGE_PAGE)?;
    let end = start.checked_add(size)? / HUGE_PAGE * HUGE_PAGE;
    (end > first).then(|| (first, end - first))
}

fn advise(ptr: *mut u8, size: usize) {
    #[cfg(target_os = "linux")]
    if let Some((first, len)) = huge_span(ptr as usize, size) {
        // SAFETY: [first, first + len) lies inside a block the system allocator has just
        // handed out (or grown) to its owner; MADV_HUGEPAGE only changes how the kernel
        // backs those pages, never their contents, so no live data is affected.
        unsafe {
            libc::madvise(first as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (ptr, size);
}

// SAFETY: every method forwards to `System` with the caller's arguments and returns its
// result unchanged; `advise` only gives the kernel advice about pages inside the block.
unsafe impl GlobalAlloc for HugePageAdvice {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_whole_huge_pages_inside_large_blocks_are_advised() {
        let m = HUGE_PAGE;
        assert_eq!(huge_span(0, THRESHOLD - 1), None);
        assert_eq!(huge_span(0, THRESHOLD), Some((0, THRESHOLD)));
        // an unaligned start: from the next boundary to the last one inside
        assert_eq!(huge_span(16, 3 * m), Some((m, 2 * m)));
        assert_eq!(huge_span(m + 4096, 4 * m), Some((2 * m, 3 * m)));
        // a block of two huge pages that straddles boundaries covers one whole
        assert_eq!(huge_span(m - 16, THRESHOLD), Some((m, m)));
        assert_eq!(huge_span(16, THRESHOLD), Some((m, m)));
        // near the top of the address space: no overflow
        assert_eq!(huge_span(usize::MAX - 10, THRESHOLD), None);
    }

    /// Large blocks through the allocator keep their contents when grown and shrunk (the
    /// advice never touches data).
    #[test]
    fn large_blocks_keep_their_contents() {
        let mut v: Vec<u64> = (0..(THRESHOLD as u64)).collect();
        v.extend(0..(THRESHOLD as u64));
        v.truncate(THRESHOLD + 3);
        v.shrink_to_fit();
        assert!(v
            .iter()
            .take(THRESHOLD)
            .enumerate()
            .all(|(i, &x)| x == i as u64));
        assert_eq!(&v[THRESHOLD..], &[0, 1, 2]);
        let z = vec![0u8; 3 * THRESHOLD];
        assert!(z.iter().all(|&b| b == 0));
    }
}
