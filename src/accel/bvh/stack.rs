//! The traversal stack: references still to visit, kept in a fixed array on the query's own
//! stack frame, with the closest-hit query's ordering of a node's children (`descend`) and its
//! skipping of those beyond the closest hit so far (`pop_within`); and `Lanes`, the entry
//! distances `descend` orders by, as each width's box test gives them.

use super::layout::EMPTY;
use std::mem::MaybeUninit;

/// A node's entry distances as its box test leaves them, in a vector register. `descend`
/// stores them as an array only for nodes where the ray enters several children, not for
/// every node tested.
pub(super) trait Lanes<const N: usize>: Copy {
    fn lanes(self) -> [f32; N];
}

/// Entries of the traversal stack. A query holds at most, summed over the nodes on one path
/// from the root, each node's child count minus one (plus one for the root in occlusion
/// queries); the build checks that its tree fits. The bench's scenes need 40-50 (4-wide) and
/// 60-70 (8-wide).
pub(super) const STACK_SIZE: usize = 256;

/// The traversal stack. Its storage is left uninitialized: zeroing all `STACK_SIZE` entries
/// for every ray cost about a tenth of a render's time on small scenes.
pub(super) struct TraversalStack<T: Copy> {
    entries: [MaybeUninit<T>; STACK_SIZE],
    len: usize,
}

impl<T: Copy> TraversalStack<T> {
    #[inline(always)]
    pub(super) fn new() -> Self {
        TraversalStack {
            entries: [const { MaybeUninit::uninit() }; STACK_SIZE],
            len: 0,
        }
    }

    /// Panics (bounds check) past `STACK_SIZE`, which the build's depth limit rules out.
    #[inline(always)]
    pub(super) fn push(&mut self, value: T) {
        self.entries[self.len].write(value);
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every entry below the old `len` was written by `push`, and entries are
        // only ever read below `len`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }
}

impl TraversalStack<(u32, f32)> {
    /// The children of a node that `mask` says the ray enters (at least one): returns the
    /// nearest to go on with and pushes the others, farthest first, with their entry
    /// distances. `prefetch` is called on each of them when there are several.
    ///
    /// Empty slots are skipped, and `EMPTY` is returned if the ray entered only those: a
    /// box test enters an empty slot's box (min +inf, max -inf) when every slab is NaN,
    /// for an origin so far out that origin / direction overflows on every axis.
    #[inline(always)]
    pub(super) fn descend<const N: usize>(
        &mut self,
        mut mask: u32,
        children: &[u32; N],
        t_near: impl Lanes<N>,
        prefetch: impl Fn(u32),
    ) -> u32 {
        if mask & (mask - 1) == 0 {
            return children[mask.trailing_zeros() as usize];
        }
        let t_near = t_near.lanes();
        let mut hits = [(0u32, 0f32); N];
        let mut count = 0;
        while mask != 0 {
            let slot = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let entry = (children[slot], t_near[slot]);
            if entry.0 == EMPTY {
                continue;
            }
            prefetch(entry.0);
            // Insertion sort, nearest last.
            let mut at = count;
            while at > 0 && hits[at - 1].1 < entry.1 {
                hits[at] = hits[at - 1];
                at -= 1;
            }
            hits[at] = entry;
            count += 1;
        }
        if count == 0 {
            return EMPTY;
        }
        for &entry in &hits[..count - 1] {
            self.push(entry);
        }
        hits[count - 1].0
    }

    /// The nearest pushed reference whose entry distance the ray can still reach.
    #[inline(always)]
    pub(super) fn pop_within(&mut self, tmax: f32) -> Option<u32> {
        while let Some((reference, t_near)) = self.pop() {
            if t_near <= tmax {
                return Some(reference);
            }
        }
        None
    }
}
