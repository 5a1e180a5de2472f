//! How the cut stores its indices, and the fixed-capacity arenas that hold its records.
//!
//! Every index the cut keeps (a triangle's corners and neighbours, a vertex's fan triangle, its
//! sibling's slot, the node map's entries) is a slot number below the cut's capacities, so it is
//! stored in the narrowest type that holds them: [`SlotIndex`] is `u16` for cuts of up to 65,534
//! vertex and triangle slots (what a microcontroller holds, and half the bytes) and `u32` for the
//! larger cuts a desktop uses. The cut's logic computes with `u32` slots and [`NIL`]; only the
//! arrays narrow them.
//!
//! `Arena` is the one fixed-capacity list of the cut's queues: its `push` hands the item back
//! when full (nothing is dropped silently), and its all-zero state is the empty arena, so a
//! `static` cut lands in `.bss`.

use super::NIL;

mod sealed {
    pub trait Sealed {}
    impl Sealed for u16 {}
    impl Sealed for u32 {}
}

/// The stored form of a slot number: `u16` or `u32` (see the module documentation).
pub trait SlotIndex: Copy + Eq + core::fmt::Debug + sealed::Sealed + 'static {
    /// Capacities must be below this (the all-ones value stores [`NIL`]).
    const LIMIT: usize;
    /// Zero, for constant initialisers.
    const ZERO: Self;
    /// The slot number; [`NIL`] for the all-ones value.
    fn load(self) -> u32;
    /// Stores slot number `slot` (below [`SlotIndex::LIMIT`]) or [`NIL`].
    fn store(slot: u32) -> Self;
    /// The slot as an array index (the all-ones value gives an index past any capacity).
    fn index(self) -> usize;
}

impl SlotIndex for u16 {
    const LIMIT: usize = u16::MAX as usize;
    const ZERO: u16 = 0;
    #[inline(always)]
    fn load(self) -> u32 {
        if self == u16::MAX {
            NIL
        } else {
            self as u32
        }
    }
    #[inline(always)]
    fn store(slot: u32) -> u16 {
        slot as u16
    }
    #[inline(always)]
    fn index(self) -> usize {
        self as usize
    }
}

impl SlotIndex for u32 {
    const LIMIT: usize = if (u32::MAX as u64) < usize::MAX as u64 {
        u32::MAX as usize
    } else {
        usize::MAX
    };
    const ZERO: u32 = 0;
    #[inline(always)]
    fn load(self) -> u32 {
        self
    }
    #[inline(always)]
    fn store(slot: u32) -> u32 {
        slot
    }
    #[inline(always)]
    fn index(self) -> usize {
        self as usize
    }
}

/// Loads the three slots of a triangle record.
#[inline(always)]
pub(crate) fn load3<I: SlotIndex>(t: [I; 3]) -> [u32; 3] {
    [t[0].load(), t[1].load(), t[2].load()]
}

/// Stores three slots.
#[inline(always)]
pub(crate) fn store3<I: SlotIndex>(t: [u32; 3]) -> [I; 3] {
    [I::store(t[0]), I::store(t[1]), I::store(t[2])]
}

/// Up to `N` items of `T` in place, with a `u32` length (the same size on every target).
#[derive(Clone, Debug)]
pub(crate) struct Arena<T: Copy, const N: usize> {
    len: u32,
    items: [T; N],
}

impl<T: Copy, const N: usize> Arena<T, N> {
    /// An empty arena; `zero` fills the unused items (pass an all-zero value, so that a
    /// `static` holding the arena is all zeros).
    pub const fn new(zero: T) -> Self {
        Arena {
            len: 0,
            items: [zero; N],
        }
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.len as usize
    }

    #[inline]
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Appends `x` and returns its index, or hands `x` back when full.
    #[inline]
    pub fn push(&mut self, x: T) -> Result<u32, T> {
        match self.items.get_mut(self.len as usize) {
            Some(slot) => {
                *slot = x;
                self.len += 1;
                Ok(self.len - 1)
            }
            None => Err(x),
        }
    }

    #[inline]
    pub fn pop(&mut self) -> Option<T> {
        let i = self.len.checked_sub(1)?;
        self.len = i;
        Some(self.items[i as usize])
    }

    #[inline]
    pub fn last(&self) -> Option<&T> {
        self.as_slice().last()
    }

    /// Removes item `i` by moving the last item into its place; returns the removed item and
    /// the index the last one moved from (`None` when `i` was the last).
    pub fn swap_remove(&mut self, i: usize) -> Option<(T, Option<u32>)> {
        let last = self.len().checked_sub(1)?;
        if i > last {
            return None;
        }
        let removed = self.items[i];
        self.items[i] = self.items[last];
        self.len = last as u32;
        Some((removed, (i != last).then_some(last as u32)))
    }

    #[inline]
    pub fn as_slice(&self) -> &[T] {
        &self.items[..self.len as usize]
    }

    #[inline]
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.items[..self.len as usize]
    }
}

impl<const N: usize> Arena<(u32, u32), N> {
    /// Pushes onto a binary max-heap kept in the arena (ordered by the pair, so that ties
    /// between equal keys are broken the same way everywhere); hands the item back when full.
    pub fn heap_push(&mut self, x: (u32, u32)) -> Result<(), (u32, u32)> {
        let mut i = self.push(x)? as usize;
        let items = self.as_mut_slice();
        // Parents smaller than `x` move down into the hole; `x` is written once.
        while i > 0 {
            let up = (i - 1) / 2;
            if heap_key(items[up]) >= heap_key(x) {
                break;
            }
            items[i] = items[up];
            i = up;
        }
        items[i] = x;
        Ok(())
    }

    /// Pops the largest item of the heap.
    pub fn heap_pop(&mut self) -> Option<(u32, u32)> {
        let last = self.pop()?;
        let items = self.as_mut_slice();
        let Some(&top) = items.first() else {
            return Some(last);
        };
        // Floyd's pop: the hole left by the top goes down to a leaf, the larger child moving up
        // each level (the left one on a tie), and the last item rises from there to its place
        // (it came from the bottom, so it rarely rises far): one comparison a level instead of
        // two. Keys are distinct or equal as pairs, so the order popped is the same as any
        // other heap's.
        let (n, key) = (items.len(), heap_key(last));
        let mut i = 0;
        loop {
            let l = 2 * i + 1;
            if l + 1 >= n {
                if l < n {
                    items[i] = items[l];
                    i = l;
                }
                break;
            }
            let big = l + usize::from(heap_key(items[l + 1]) > heap_key(items[l]));
            items[i] = items[big];
            i = big;
        }
        while i > 0 {
            let up = (i - 1) / 2;
            if heap_key(items[up]) >= key {
                break;
            }
            items[i] = items[up];
            i = up;
        }
        items[i] = last;
        Some(top)
    }
}

/// A heap item as one integer, ordered as the pair is.
#[inline(always)]
fn heap_key((a, b): (u32, u32)) -> u64 {
    (a as u64) << 32 | b as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_arena_hands_the_item_back() {
        let mut a = Arena::<u32, 2>::new(0);
        assert_eq!(a.push(7), Ok(0));
        assert_eq!(a.push(8), Ok(1));
        assert_eq!(a.push(9), Err(9));
        assert_eq!(a.swap_remove(0), Some((7, Some(1))));
        assert_eq!(a.as_slice(), &[8]);
        assert_eq!(a.swap_remove(0), Some((8, None)));
        assert_eq!(a.swap_remove(0), None);
    }

    #[test]
    fn the_heap_pops_in_decreasing_order() {
        let mut h = Arena::<(u32, u32), 64>::new((0, 0));
        let mut x = 0x1234_5678u32;
        let mut all = [(0u32, 0u32); 64];
        for (i, slot) in all.iter_mut().enumerate() {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            *slot = (x % 16, i as u32);
            assert!(h.heap_push(*slot).is_ok());
        }
        assert!(h.heap_push((0, 0)).is_err());
        all.sort_unstable_by(|a, b| b.cmp(a));
        for want in all {
            assert_eq!(h.heap_pop(), Some(want));
        }
        assert_eq!(h.heap_pop(), None);
    }

    #[test]
    fn pops_between_pushes_take_the_largest_so_far() {
        // Pushes and pops interleaved, as refinement uses the heap: every pop must be the
        // largest of what is in it, checked against a sorted copy.
        let mut h = Arena::<(u32, u32), 256>::new((0, 0));
        let mut kept: [(u32, u32); 256] = [(0, 0); 256];
        let mut len = 0;
        let mut x = 0x9E37_79B9u32;
        for step in 0..2000u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            if !x.is_multiple_of(3) && len < 256 {
                let item = (x % 64, step);
                assert!(h.heap_push(item).is_ok());
                kept[len] = item;
                len += 1;
            } else {
                kept[..len].sort_unstable();
                let want = len.checked_sub(1).map(|last| kept[last]);
                assert_eq!(h.heap_pop(), want);
                len = len.saturating_sub(1);
            }
        }
    }

    #[test]
    fn narrow_slots_keep_nil() {
        assert_eq!(<u16 as SlotIndex>::store(NIL).load(), NIL);
        assert_eq!(<u16 as SlotIndex>::store(65_534).load(), 65_534);
        assert_eq!(<u32 as SlotIndex>::store(NIL).load(), NIL);
    }
}
