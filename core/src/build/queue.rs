//! The collapse engine's queue of edges by cost: a 4-ary min-heap with lazy deletion (an entry
//! whose edge has since gone is skipped by the caller when it comes out).
//!
//! Why 4-ary and not `alloc`'s binary heap: on the bunny's build, half of a collapse step's time
//! was the binary heap's sift-down, one cache miss per level of a heap of a few hundred thousand
//! entries. Four children side by side are one cache line's read for a level, and there are half
//! as many levels. Each entry carries its edge, so no list of every edge ever pushed is kept.
//!
//! Order: by cost, and among equal costs by push order (the key is the cost's bits above the push
//! index), so the collapses, and so the files the builder writes, do not depend on the heap's
//! shape.

use alloc::vec::Vec;

/// One queued edge: `key` is the cost's `f32` bits (non-negative floats order like their bits)
/// above the push index.
#[derive(Clone, Copy)]
struct Entry {
    key: u64,
    edge: (u32, u32),
}

/// Edges by cost, cheapest first; ties go to the earlier push.
#[derive(Default)]
pub(crate) struct CostQueue {
    items: Vec<Entry>,
    pushes: u64,
}

/// Children per node.
const ARITY: usize = 4;

/// The cheapest of the first [`ARITY`] of `children` (a node's, side by side) and where it is
/// among them; `None` for a leaf's. Taken as one slice, the children are read without a bounds
/// check apiece (those checks were a sixth of the queue's instructions), and a full node's, of
/// known length, without a loop.
#[inline]
fn cheapest(children: &[Entry]) -> Option<(usize, Entry)> {
    match children.first_chunk::<ARITY>() {
        Some(full) => Some(least_of_four(full)),
        None => least(children),
    }
}

/// [`least`] of a full node's children, as the winner of two pairs: only keys and places are
/// carried through the comparisons, and the entry is read once, where it won.
#[inline(always)]
fn least_of_four(full: &[Entry; ARITY]) -> (usize, Entry) {
    let pair = |i: usize| {
        if full[i + 1].key < full[i].key {
            i + 1
        } else {
            i
        }
    };
    let (low, high) = (pair(0), pair(2));
    let k = if full[high].key < full[low].key {
        high
    } else {
        low
    };
    (k, full[k])
}

/// The entry of least key among `entries` and where it is; keys differ, so which of equal keys
/// wins never arises.
#[inline(always)]
fn least(entries: &[Entry]) -> Option<(usize, Entry)> {
    let (mut k, mut least) = (0, *entries.first()?);
    for (c, &e) in entries.iter().enumerate().skip(1) {
        if e.key < least.key {
            (k, least) = (c, e);
        }
    }
    Some((k, least))
}

impl CostQueue {
    /// Queues `edge` at `cost` (a non-negative float's bits). Past `u32::MAX` pushes an edge is
    /// not queued: the push index would not fit its half of the key.
    pub fn push(&mut self, cost: u32, edge: (u32, u32)) {
        let Ok(index) = u32::try_from(self.pushes) else {
            return;
        };
        self.pushes += 1;
        let entry = Entry {
            key: u64::from(cost) << 32 | u64::from(index),
            edge,
        };
        let items = &mut self.items;
        let mut i = items.len();
        items.push(entry);
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if items[parent].key <= entry.key {
                break;
            }
            items[i] = items[parent];
            i = parent;
        }
        items[i] = entry;
    }

    /// The cheapest edge, out of the queue.
    pub fn pop(&mut self) -> Option<(u32, u32)> {
        let last = self.items.pop()?;
        let top = self.items.first().copied();
        match top {
            Some(top) => {
                // The last entry sinks from the root into the hole the cheapest leaves.
                self.sink(0, last);
                Some(top.edge)
            }
            None => Some(last.edge),
        }
    }

    /// Puts `entry` at `i` and moves it down past every cheaper child.
    fn sink(&mut self, mut i: usize, entry: Entry) {
        let items = &mut self.items;
        loop {
            let first = ARITY * i + 1;
            let Some((k, least)) = items.get(first..).and_then(cheapest) else {
                break;
            };
            if least.key >= entry.key {
                break;
            }
            items[i] = least;
            i = first + k;
        }
        items[i] = entry;
    }

    /// Entries queued and not popped.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Entries the queue holds without growing.
    pub fn capacity(&self) -> usize {
        self.items.capacity()
    }

    /// Makes room for `more` entries beyond those queued, exactly.
    pub fn reserve(&mut self, more: usize) {
        self.items.reserve_exact(more);
    }

    /// Keeps only the entries whose edge `keep` accepts, in the same order of popping.
    pub fn retain(&mut self, mut keep: impl FnMut((u32, u32)) -> bool) {
        self.items.retain(|e| keep(e.edge));
        // Heapify: sink every node that has children, the deepest first.
        for i in (0..self.items.len() / ARITY + 1).rev() {
            if let Some(&entry) = self.items.get(i) {
                self.sink(i, entry);
            }
        }
    }

    /// Edges queued so far: the build's work.
    pub fn pushes(&self) -> u64 {
        self.pushes
    }
}

#[cfg(test)]
mod tests {
    use super::CostQueue;
    use alloc::collections::BinaryHeap;
    use alloc::vec::Vec;
    use core::cmp::Reverse;

    /// Random pushes and pops, many equal costs among them, come out as a binary heap keyed
    /// by (cost, push index) gives them.
    #[test]
    fn pops_by_cost_then_push_order() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut queue = CostQueue::default();
        let mut reference = BinaryHeap::new();
        let mut index = 0u32;
        let mut popped = 0;
        for round in 0..200_000u32 {
            let r = next();
            if r % 5 < 3 || round < 10 {
                let cost = (r >> 8) as u32 % if round % 2 == 0 { 16 } else { 100_000 };
                let edge = (round, (r >> 40) as u32);
                queue.push(cost, edge);
                reference.push(Reverse((cost, index, edge)));
                index += 1;
            } else {
                let expected = reference.pop().map(|Reverse((_, _, e))| e);
                assert_eq!(queue.pop(), expected, "round {round}");
                popped += usize::from(expected.is_some());
            }
        }
        // Dropping the entries of odd first vertices keeps the order of the rest.
        queue.retain(|(a, _)| a % 2 == 0);
        let kept: Vec<_> = reference.into_sorted_vec();
        for Reverse((_, _, e)) in kept
            .into_iter()
            .rev()
            .filter(|Reverse((_, _, e))| e.0 % 2 == 0)
        {
            assert_eq!(queue.pop(), Some(e));
        }
        assert_eq!(queue.pop(), None);
        assert_eq!(queue.pushes(), u64::from(index));
        assert!(popped > 50_000, "{popped}");
    }
}
