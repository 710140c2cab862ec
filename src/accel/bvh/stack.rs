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

    /// The places of the lanes in `mask` ordered farthest first: for each, how many lanes
    /// in `mask` hold a larger distance. Distances are compared as integers with the lane
    /// in their lowest bits ([`distance_key`]), so no two are equal. Lanes outside `mask`
    /// get the last place, N − 1.
    fn places(self, mask: u32) -> [u32; N];
}

/// Entry distance `t` of lane `lane` as a key whose integer order is the distances' order,
/// ties broken by lane: the three lowest bits of `t` replaced by `lane`. Entry distances are
/// at least tmin >= 0, and the bits of non-negative floats order as the floats do.
#[inline(always)]
pub(super) fn distance_key(t: f32, lane: u32) -> i32 {
    ((t.to_bits() & !7) | lane) as i32
}

/// Entries of the traversal stack. A query holds at most, summed over the nodes on one path
/// from the root, each node's child count minus one (plus one for the root in occlusion
/// queries); the build checks that its tree fits. The bench's scenes need 40-50 (4-wide) and
/// 60-70 (8-wide). `descend` also writes a node's whole width above the entries it keeps.
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
        let rest = mask & (mask - 1);
        if rest == 0 {
            return children[mask.trailing_zeros() as usize];
        }
        let distances = t_near.lanes();
        if rest & (rest - 1) == 0 {
            // Two children, the commonest case after one: ordered without a branch on
            // their distances, which would mispredict about half the time.
            let (first, second) = (
                mask.trailing_zeros() as usize,
                rest.trailing_zeros() as usize,
            );
            let (a, b) = (children[first], children[second]);
            if a != EMPTY && b != EMPTY {
                let a_nearer = distances[first] <= distances[second];
                let (near, far) = select_pair(a_nearer, (a, b));
                let far_t = if a_nearer {
                    distances[second]
                } else {
                    distances[first]
                };
                prefetch(far);
                prefetch(near);
                self.push((far, far_t));
                return near;
            }
        }
        // Three or more: each child's place is the number of entered children farther
        // than it (`Lanes::places`), and all are written to their places at once, with no
        // branch on the distances (an insertion sort's mispredicted about twice per ray).
        for (slot, &child) in children.iter().enumerate() {
            if child == EMPTY {
                mask &= !(1 << slot);
            }
        }
        let count = mask.count_ones() as usize;
        if count == 0 {
            return EMPTY;
        }
        let order = t_near.places(mask);
        let base = self.len;
        let places = &mut self.entries[base..base + N];
        // A child not entered goes to the last place, beyond the entered ones when there
        // are fewer than N of them.
        for (slot, &place) in order.iter().enumerate() {
            places[place as usize % N].write((children[slot], distances[slot]));
        }
        let mut entered = mask;
        while entered != 0 {
            prefetch(children[entered.trailing_zeros() as usize]);
            entered &= entered - 1;
        }
        // SAFETY: place `count - 1` holds the nearest entered child, written above.
        let (nearest, _) = unsafe { places[count - 1].assume_init() };
        self.len = base + count - 1;
        nearest
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

/// `(a, b)` if `keep`, else `(b, a)`, computed without a branch.
#[inline(always)]
fn select_pair(keep: bool, (a, b): (u32, u32)) -> (u32, u32) {
    let swap = (a ^ b) & (keep as u32).wrapping_sub(1);
    (a ^ swap, b ^ swap)
}
