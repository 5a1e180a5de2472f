//! A fixed-capacity map from hierarchy node ids to active-vertex slots.
//!
//! The cut needs "is node `n` active, and where?" when it forces a split (the merge-tree paper's
//! "closest active ancestor", §3.6) and when it collapses a pair. A table indexed by node id would
//! cost memory in proportion to the whole hierarchy; this one costs memory in proportion to the
//! active mesh, like the rest of the cut. Open addressing with linear probing and backward-shift
//! deletion: no tombstones, so lookups stay short however long the cut runs, and nothing depends on
//! iteration order (the map is never iterated).
//!
//! Only the first `span` entries of the table are in use, two to sixteen times the entries,
//! so that a small cut's map stays small and in cache however large its capacity; the cut rebuilds the map (from its node array: no scratch memory) when the
//! span must grow or may shrink.

/// The empty-slot key (never a node id: the format reserves `u32::MAX`).
const EMPTY: u32 = u32::MAX;

/// Node id to slot, `M` entries of 8 bytes; keep it at most about half full.
#[derive(Clone, Debug)]
pub(crate) struct NodeMap<const M: usize> {
    keys: [u32; M],
    values: [u32; M],
    len: usize,
    span: usize,
}

/// The smallest span used.
const MIN_SPAN: usize = 256;

impl<const M: usize> NodeMap<M> {
    pub const fn new() -> Self {
        NodeMap {
            keys: [EMPTY; M],
            values: [0; M],
            len: 0,
            span: if M < MIN_SPAN { M } else { MIN_SPAN },
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
        if i + 1 == self.span {
            0
        } else {
            i + 1
        }
    }

    /// The span this many entries should use: four times as many (a quarter full, so that
    /// many entries come and go before the next rebuild), at least [`MIN_SPAN`], at most `M`.
    pub fn span_for(entries: usize) -> usize {
        entries.saturating_mul(4).max(MIN_SPAN).min(M)
    }

    /// Whether `entries` entries call for another span: more than half of it, or (when it is
    /// above the minimum) less than a sixteenth.
    pub fn should_resize(&self, entries: usize) -> bool {
        (entries * 2 > self.span && self.span < M)
            || (entries * 16 < self.span && self.span > MIN_SPAN.min(M))
    }

    /// Empties the map and makes it use `span` entries (clamped to `1..=M`).
    pub fn reset(&mut self, span: usize) {
        let old = self.span;
        self.span = span.clamp(1, M);
        let used = old.max(self.span);
        self.keys[..used].iter_mut().for_each(|k| *k = EMPTY);
        self.len = 0;
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Removes every entry.
    pub fn clear(&mut self) {
        self.reset(Self::span_for(0));
    }

    /// Index of `key`'s entry, or of the empty slot where it would go.
    #[inline]
    fn find(&self, key: u32) -> Option<usize> {
        let mut i = self.home(key);
        for _ in 0..self.span {
            let k = *self.keys.get(i)?;
            if k == key || k == EMPTY {
                return Some(i);
            }
            i = self.next(i);
        }
        None
    }

    #[inline]
    pub fn get(&self, key: u32) -> Option<u32> {
        let i = self.find(key)?;
        (self.keys[i] == key && key != EMPTY).then(|| self.values[i])
    }

    /// Inserts or overwrites; `false` when the span is too full (kept below 7/8) or `key` is the
    /// reserved value.
    pub fn insert(&mut self, key: u32, value: u32) -> bool {
        if key == EMPTY {
            return false;
        }
        let Some(i) = self.find(key) else {
            return false;
        };
        if self.keys[i] == EMPTY {
            if (self.len + 1) * 8 > self.span * 7 {
                return false;
            }
            self.len += 1;
            self.keys[i] = key;
        }
        self.values[i] = value;
        true
    }

    pub fn remove(&mut self, key: u32) {
        let Some(mut hole) = self.find(key) else {
            return;
        };
        if self.keys[hole] != key || key == EMPTY {
            return;
        }
        self.keys[hole] = EMPTY;
        self.len -= 1;
        // Shift back every entry of the probe run that would not be found past the hole.
        let mut j = hole;
        for _ in 0..self.span {
            j = self.next(j);
            let k = self.keys[j];
            if k == EMPTY {
                return;
            }
            let h = self.home(k);
            // Entry j may move to the hole unless its home lies cyclically in (hole, j].
            let stays = if hole <= j {
                hole < h && h <= j
            } else {
                hole < h || h <= j
            };
            if !stays {
                self.keys[hole] = k;
                self.values[hole] = self.values[j];
                self.keys[j] = EMPTY;
                hole = j;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn behaves_like_a_map_under_churn() {
        let mut m = NodeMap::<97>::new();
        let mut shadow = [None::<u32>; 400];
        let mut x = 12345u32;
        for step in 0..20_000u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let key = x % 400;
            if x & 0x100 != 0 && m.len() < 60 {
                assert!(m.insert(key, step));
                shadow[key as usize] = Some(step);
            } else {
                m.remove(key);
                shadow[key as usize] = None;
            }
            for (k, v) in shadow.iter().enumerate() {
                assert_eq!(m.get(k as u32), *v);
            }
            assert_eq!(m.len(), shadow.iter().flatten().count());
        }
    }

    #[test]
    fn refuses_to_fill_up() {
        let mut m = NodeMap::<8>::new();
        let stored = (0..8).filter(|&k| m.insert(k, k)).count();
        assert_eq!(stored, 7);
        assert!(!m.insert(u32::MAX, 0));
    }

    #[test]
    fn spans_grow_and_shrink_with_the_entries() {
        let mut m = NodeMap::<4096>::new();
        assert!(!m.should_resize(100));
        assert!(m.should_resize(200));
        m.reset(NodeMap::<4096>::span_for(200));
        for k in 0..200 {
            assert!(m.insert(k * 7, k));
        }
        assert!((0..200).all(|k| m.get(k * 7) == Some(k)));
        // A rebuild leaves room both ways.
        assert!(!m.should_resize(201) && !m.should_resize(150) && !m.should_resize(60));
        assert!(m.should_resize(10) && m.should_resize(401));
        assert_eq!(NodeMap::<4096>::span_for(1 << 20), 4096);
    }
}
