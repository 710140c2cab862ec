//! Large arrays in 2 MiB pages: the tree's nodes and blocks are read at random by every ray,
//! and with 4 KiB pages a large scene's rays miss the TLB on most of them.

/// Arrays from this size on are worth 2 MiB pages: the terrain of the traversal bench has
/// 89 MB of them, and with 4 KiB pages its random rays miss the TLB on most nodes.
const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;
const HUGE_PAGE_BYTES: usize = 2 << 20;

/// `items` in an allocation of their own: for large arrays on Linux, one the kernel is asked
/// to back with 2 MiB pages (transparent huge pages, which Debian and Ubuntu enable on
/// request by default), as Embree does for its BVH. Random rays on the bench's terrain gained
/// about 10% from it. Elsewhere, or if the kernel declines, the pages stay 4 KiB.
pub(super) fn in_huge_pages<T: Copy>(mut items: Vec<T>) -> Vec<T> {
    let bytes = size_of_val(items.as_slice());
    if !cfg!(target_os = "linux") || bytes < HUGE_PAGE_MIN_BYTES {
        items.shrink_to_fit();
        return items;
    }
    // Huge pages cover the copy but for its unaligned ends.
    let mut copy = Vec::with_capacity(items.len());
    #[cfg(target_os = "linux")]
    {
        let start = copy.as_ptr() as usize;
        let first_page = start.next_multiple_of(HUGE_PAGE_BYTES);
        let end_of_pages = (start + copy.capacity() * size_of::<T>()) & !(HUGE_PAGE_BYTES - 1);
        if end_of_pages > first_page {
            // SAFETY: advice about whole pages inside `copy`'s own allocation, which nothing
            // else refers to; it changes how the kernel backs them, never their contents, and
            // its failure (ignored) leaves them as they were.
            unsafe {
                libc::madvise(
                    first_page as *mut libc::c_void,
                    end_of_pages - first_page,
                    libc::MADV_HUGEPAGE,
                )
            };
        }
    }
    copy.extend_from_slice(&items);
    copy
}
