//! A fixed-capacity map from hierarchy node ids to active-vertex slots.
//!
//! The cut needs "is node `n` active, and where?" when it forces a split (the first active
//! ancestor of a missing neighbour's creator) and when it collapses a pair. A table indexed by
//! node id would cost memory in proportion to the whole hierarchy; this one costs memory in
//! proportion to the cut: each entry is one slot number (`slot + 1`, 0 for empty), two bytes in a
//! 16-bit cut, and the key is not stored at all but read from the cut's node array
//! (`nodes[slot]`), which the cut keeps anyway. Open addressing with linear probing and
//! backward-shift deletion: no tombstones, so lookups stay short however long the cut runs, and
//! nothing depends on iteration order (the map is never iterated).
//!
//! Only the first `span` entries of the table are in use, two to 32 times the entries, so
//! that a small cut's map stays small and in cache however large its capacity; the cut rebuilds
//! the map (from its node array: no scratch memory) when the span must grow or may shrink.
//!
//! Every call takes the node array, and every entry's slot must hold its key in it: the cut
//! writes a slot's node before inserting it and removes or re-points an entry before the slot
//! changes node.

use crate::cut::SlotIndex;

/// Node id to slot, `M` entries of one slot index each; keep it at most about half full.
#[derive(Clone, Debug)]
pub(crate) struct NodeMap<const M: usize, I: SlotIndex> {
    table: [I; M],
    len: u32,
    span: u32,
}

/// The smallest span used.
const MIN_SPAN: usize = 256;

impl<const M: usize, I: SlotIndex> NodeMap<M, I> {
    /// An empty map; all zeros (its span is set by the first [`NodeMap::reset`]).
    pub const fn new() -> Self {
        NodeMap {
            table: [I::ZERO; M],
            len: 0,
            span: 0,
        }
    }

    #[inline]
    fn home(&self, key: u32) -> usize {
        // Fibonacci hashing, then a multiply-shift into 0..span (no power of two needed).
        let h = key.wrapping_mul(0x9E37_79B9);
        ((h as u64 * self.span as u64) >> 32) as usize
    }

    #[inline]
    fn next(&self, i: usize) -> usize {
        if i + 1 >= self.span as usize {
            0
        } else {
            i + 1
        }
    }

    /// The span this many entries should use: eight times as many (an eighth full, so that
    /// many entries come and go before the next rebuild, and a cut growing from its base mesh
    /// rebuilds its map a third as often as at four times), at least [`MIN_SPAN`], at most `M`.
    pub fn span_for(entries: usize) -> usize {
        entries.saturating_mul(8).max(MIN_SPAN).min(M)
    }

    /// Whether `entries` entries call for another span: more than half of it, or (when it is
    /// above the minimum) less than a 32nd.
    pub fn should_resize(&self, entries: usize) -> bool {
        let span = self.span as usize;
        self.should_grow(entries) || (entries * 32 < span && span > MIN_SPAN.min(M))
    }

    /// Whether `entries` entries call for a wider span: more than half of it (and it is below
    /// `M`).
    #[inline(always)]
    pub fn should_grow(&self, entries: usize) -> bool {
        let span = self.span as usize;
        entries * 2 > span && span < M
    }

    /// Empties the map and makes it use `span` entries (clamped to `1..=M`).
    pub fn reset(&mut self, span: usize) {
        let used = (self.span as usize).max(span).min(M);
        self.table[..used].iter_mut().for_each(|e| *e = I::ZERO);
        self.span = span.clamp(1, M.max(1)) as u32;
        self.len = 0;
    }

    /// Empties the map and lends the first `len` entries of its table (at most `M`) as
    /// scratch; [`NodeMap::reset`] clears them after.
    pub fn scratch(&mut self, len: usize) -> &mut [I] {
        let len = len.min(M);
        self.len = 0;
        self.span = self.span.max(len as u32);
        &mut self.table[..len]
    }

    /// Entries the map takes at most (7/8 of its table).
    pub fn capacity(&self) -> usize {
        M / 8 * 7 + M % 8 * 7 / 8
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// The slot stored in table entry `i`, if any. Read as the raw index: an entry is a slot
    /// plus one, below the index type's [`SlotIndex::LIMIT`], never its all-ones `NIL` (which
    /// `load` would test for).
    #[inline]
    fn entry(&self, i: usize) -> Option<u32> {
        let e = self.table.get(i)?.index() as u32;
        e.checked_sub(1)
    }

    /// Index of `key`'s entry (`Ok`), or of the empty entry where it would go (`Err`).
    #[inline]
    fn find(&self, key: u32, nodes: &[u32]) -> Option<Result<usize, usize>> {
        let mut i = self.home(key);
        for _ in 0..self.span {
            match self.entry(i) {
                None => return Some(Err(i)),
                Some(s) if nodes.get(s as usize) == Some(&key) => return Some(Ok(i)),
                Some(_) => i = self.next(i),
            }
        }
        None
    }

    /// The slot holding `key`.
    #[inline]
    pub fn get(&self, key: u32, nodes: &[u32]) -> Option<u32> {
        match self.find(key, nodes)? {
            Ok(i) => self.entry(i),
            Err(_) => None,
        }
    }

    /// Maps `nodes[slot]` to `slot` (overwriting); `false` when the span is too full (kept
    /// below 7/8) or `slot` is not in `nodes`.
    pub fn insert(&mut self, slot: u32, nodes: &[u32]) -> bool {
        let Some(&key) = nodes.get(slot as usize) else {
            return false;
        };
        match self.find(key, nodes) {
            Some(Ok(i)) => self.table[i] = I::store(slot + 1),
            Some(Err(i)) => {
                if (self.len() + 1) * 8 > self.span as usize * 7 {
                    return false;
                }
                self.len += 1;
                self.table[i] = I::store(slot + 1);
            }
            None => return false,
        }
        true
    }

    /// [`NodeMap::insert`] of a key the map does not hold (a node just made active): the
    /// first empty entry from its home takes it, no key compared on the way. Were the key
    /// there after all, both entries would name slots holding it, and a lookup finds either.
    #[inline]
    pub fn insert_new(&mut self, slot: u32, nodes: &[u32]) -> bool {
        let Some(&key) = nodes.get(slot as usize) else {
            return false;
        };
        if (self.len() + 1) * 8 > self.span as usize * 7 {
            return false;
        }
        let mut i = self.home(key);
        for _ in 0..self.span {
            match self.table.get_mut(i) {
                Some(e) if e.load() == 0 => {
                    *e = I::store(slot + 1);
                    self.len += 1;
                    return true;
                }
                Some(_) => i = self.next(i),
                None => return false,
            }
        }
        false
    }

    /// Points `key`'s entry at `slot` (which will hold `key` from now on).
    pub fn repoint(&mut self, key: u32, slot: u32, nodes: &[u32]) {
        if let Some(Ok(i)) = self.find(key, nodes) {
            self.table[i] = I::store(slot + 1);
        }
    }

    /// Removes `key`'s entry, if any. Inlined: every split removes its parent's entry.
    #[inline(always)]
    pub fn remove(&mut self, key: u32, nodes: &[u32]) {
        let Some(Ok(mut hole)) = self.find(key, nodes) else {
            return;
        };
        self.table[hole] = I::ZERO;
        self.len -= 1;
        // Shift back every entry of the probe run that would not be found past the hole.
        let mut j = hole;
        for _ in 0..self.span {
            j = self.next(j);
            let Some(s) = self.entry(j) else {
                return;
            };
            let Some(&k) = nodes.get(s as usize) else {
                return;
            };
            let h = self.home(k);
            // Entry j may move to the hole unless its home lies cyclically in (hole, j].
            let stays = if hole <= j {
                hole < h && h <= j
            } else {
                hole < h || h <= j
            };
            if !stays {
                self.table[hole] = self.table[j];
                self.table[j] = I::ZERO;
                hole = j;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map over a node array whose slot `s` holds node `keys[s]`.
    struct Shadow {
        nodes: [u32; 64],
        used: [bool; 64],
    }

    #[test]
    fn behaves_like_a_map_under_churn() {
        let mut m = NodeMap::<97, u16>::new();
        m.reset(97);
        // Slot s holds key s * 7 + (s % 3); keys come and go.
        let mut sh = Shadow {
            nodes: core::array::from_fn(|s| s as u32 * 7 + (s as u32 % 3)),
            used: [false; 64],
        };
        let mut x = 12345u32;
        for _ in 0..20_000u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let s = (x % 64) as usize;
            if x & 0x100 != 0 {
                // A key not held goes in by `insert_new` half the time (as the cut's new nodes).
                let new = !sh.used[s] && x & 0x200 != 0;
                let inserted = if new {
                    m.insert_new(s as u32, &sh.nodes)
                } else {
                    m.insert(s as u32, &sh.nodes)
                };
                assert!(inserted);
                sh.used[s] = true;
            } else {
                m.remove(sh.nodes[s], &sh.nodes);
                sh.used[s] = false;
            }
            for t in 0..64 {
                let want = sh.used[t].then_some(t as u32);
                assert_eq!(m.get(sh.nodes[t], &sh.nodes), want);
            }
            assert_eq!(m.len(), sh.used.iter().filter(|&&u| u).count());
        }
    }

    #[test]
    fn refuses_to_fill_up() {
        let mut m = NodeMap::<8, u32>::new();
        m.reset(8);
        let nodes: [u32; 8] = core::array::from_fn(|s| s as u32 * 3);
        let stored = (0..8).filter(|&s| m.insert(s, &nodes)).count();
        assert_eq!(stored, 7);
        assert!(!m.insert(9, &nodes));
    }

    #[test]
    fn spans_grow_and_shrink_with_the_entries() {
        let mut m = NodeMap::<4096, u16>::new();
        m.reset(NodeMap::<4096, u16>::span_for(0));
        assert!(!m.should_resize(100));
        assert!(m.should_resize(200));
        m.reset(NodeMap::<4096, u16>::span_for(200));
        let nodes: [u32; 200] = core::array::from_fn(|s| s as u32 * 7);
        for s in 0..200 {
            assert!(m.insert(s, &nodes));
        }
        assert!((0..200).all(|s| m.get(s * 7, &nodes) == Some(s)));
        // A rebuild leaves room both ways.
        assert!(!m.should_resize(201) && !m.should_resize(150) && !m.should_resize(60));
        assert!(!m.should_resize(800) && !m.should_resize(51));
        assert!(m.should_resize(49) && m.should_resize(801));
        assert_eq!(NodeMap::<4096, u16>::span_for(1 << 20), 4096);
    }
}
