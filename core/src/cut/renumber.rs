//! Renumbering the cut's slots in an order that reads memory in sequence.
//!
//! Splits append their new vertex and triangles at the end of the tables and collapses move the
//! last record into the hole they leave, so after a camera has swept over the model the slots
//! follow the history of the operations, not the surface: drawing the cut fetches each vertex's
//! record from all over the hierarchy and each triangle's corners from all over the shaded
//! vertices, and a fan walk steps between distant triangles. [`Cut::renumber`] puts the vertices
//! in the order of their nodes (so their records are read from the file front to back: a
//! parent's id is below its children's, and the builder numbers nodes along the surface where
//! its input does) and the triangles in the order of their first corner's slot (counted out,
//! with no fan walk: walks step between distant triangles one dependent read after another).
//! It needs no memory of its own: the node map lends its table as scratch and is rebuilt
//! after, which is why it needs room for two entries per vertex slot there (the recommended
//! `F = 2 V` has it), and the vertices' fan entries count the triangles and are set again.
//!
//! The cut stays the same cut: the same nodes and triangles, settled marks and geomorphs; only
//! the slots change, and with them the order in which later frames meet vertices (which a
//! window of the active list, `Budget::max_visits`, and the restless vertices' turns follow).

use super::slot::SlotIndex;
use super::{Cut, NIL};

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Renumbers the vertex slots in node order and the triangle slots in the order of their
    /// first corner (see the module documentation); `false`, with nothing changed, when the
    /// node map's table (`F` entries) holds fewer than two entries per active vertex. Takes
    /// time in proportion to the cut (a sort of its vertices); an application calls it between
    /// frames, every few dozen frames of a moving camera.
    ///
    /// ```
    /// # #[cfg(feature = "build")] {
    /// use vdlod_core::build::{build, BuildOptions, InputMesh};
    /// use vdlod_core::cut::Cut;
    /// use vdlod_core::format::HierarchyView;
    /// let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
    ///                  [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    /// let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
    ///                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    /// let mesh = InputMesh { positions: &positions, colors: None, triangles: &triangles };
    /// let bytes = build(&mesh, &BuildOptions::default(), &mut |_| {}).unwrap().to_bytes(false);
    /// let h = HierarchyView::parse(&bytes).unwrap();
    /// let mut cut = Cut::<16, 32, 16>::new();
    /// cut.reset(&h).unwrap();
    /// while cut.refine_everything(&h) > 0 {}
    /// let mut before: Vec<u32> = cut.nodes().to_vec();
    /// assert!(cut.renumber());
    /// assert!(cut.nodes().windows(2).all(|w| w[0] < w[1])); // in node order
    /// before.sort();
    /// assert_eq!(cut.nodes(), &before[..]); // the same vertices
    /// assert!(cut.check(&h).is_ok());
    /// # }
    /// ```
    #[inline(never)]
    pub fn renumber(&mut self) -> bool {
        let n = self.v.len();
        let nf = self.t.len();
        if n.saturating_mul(2) > F {
            return false;
        }
        let scratch = self.map.scratch(2 * n);
        // Vertices: `order[k]` is the slot that becomes `k`, `to[s]` the slot `s` becomes.
        let (order, to) = scratch.split_at_mut(n);
        let to = &mut to[..n];
        for (k, o) in order.iter_mut().enumerate() {
            *o = I::store(k as u32);
        }
        // Node ids are distinct, so the order does not depend on the sort.
        order.sort_unstable_by_key(|s| self.v.node[s.index()]);
        for (k, o) in order.iter().enumerate() {
            to[o.index()] = I::store(k as u32);
        }
        let vertex = |s: u32| through(to, s);
        self.t.renumber_corners(vertex);
        self.v.renumber_mates(vertex);
        for b in self.blends.as_mut_slice() {
            b.slot = vertex(b.slot);
        }
        if !self.v.scatter(to) {
            permute(to, |a, b| self.v.swap(a, b));
        }
        // Triangles: counted out by their corner of least slot, in their old order among those
        // of one vertex (a counting sort whose counters are the vertices' fan entries, which
        // are set again after). A triangle without such a corner (only in a cut a crafted file
        // broke) goes after the others, in its order. No count or place reaches `F`, which is
        // below `I::LIMIT`, so none is stored as `NIL`.
        // `to[f]` holds the triangle's least corner (or `NIL`) until it holds its place.
        let to = self.map.scratch(nf);
        let counts = self.v.fans_mut();
        counts.iter_mut().for_each(|c| *c = I::store(0));
        for (f, t) in (0..nf as u32).zip(to.iter_mut()) {
            let least = self.t.get(f).and_then(|t| t.into_iter().min());
            *t = I::store(NIL);
            if let Some(m) = least.filter(|&m| (m as usize) < n) {
                counts[m as usize] = I::store(counts[m as usize].load() + 1);
                *t = I::store(m);
            }
        }
        let mut sum = 0u32;
        for c in counts.iter_mut() {
            let k = c.load();
            *c = I::store(sum);
            sum += k;
        }
        let mut after = sum;
        for t in to.iter_mut() {
            let place = match counts.get_mut(t.index()).filter(|_| t.load() != NIL) {
                Some(c) => {
                    let p = c.load();
                    *c = I::store(p + 1);
                    p
                }
                None => {
                    after += 1;
                    after - 1
                }
            };
            *t = I::store(place);
        }
        debug_assert_eq!(after as usize, nf);
        let triangle = |f: u32| through(to, f);
        self.t.renumber_neighbours(triangle);
        if !self.t.scatter(to) {
            permute(to, |f, g| self.t.swap(f, g));
        }
        // Each vertex's fan starts at its first triangle, as `reset` makes it.
        let fans = self.v.fans_mut();
        fans.iter_mut().for_each(|f| *f = I::store(NIL));
        for f in (0..nf as u32).rev() {
            for c in self.t.at(f) {
                if let Some(x) = fans.get_mut(c as usize) {
                    *x = I::store(f);
                }
            }
        }
        // The per-frame lists name slots: they start empty each frame anyway.
        self.stack.clear();
        self.candidates.clear();
        self.pairs.clear();
        self.walk = 0;
        self.rebuild_map(n);
        true
    }
}

/// Where `to` sends `x` (`NIL` stays `NIL`, and so does anything out of its range).
fn through<I: SlotIndex>(to: &[I], x: u32) -> u32 {
    if x == NIL {
        NIL
    } else {
        to.get(x as usize).map_or(NIL, |t| t.load())
    }
}

/// Moves `a[s]` to `a[to[s]]` for every `s` below `to.len()`, through the entries after them
/// (`a` at least twice as long as `to`, which must be a permutation): the reads and writes are
/// independent of each other, where exchanges along a cycle wait for one another.
pub(super) fn scatter<T: Copy, I: SlotIndex>(a: &mut [T], to: &[I]) {
    let n = to.len();
    let (low, high) = a.split_at_mut(n);
    for (x, t) in low.iter().zip(to) {
        if let Some(y) = high.get_mut(t.index()) {
            *y = *x;
        }
    }
    if let Some(high) = high.get(..n) {
        low.copy_from_slice(high);
    }
}

/// Moves every record `s` to `to[s]` by exchanges (`swap`), emptying `to` into the identity on
/// the way; `to` must be a permutation.
fn permute<I: SlotIndex>(to: &mut [I], mut swap: impl FnMut(usize, usize)) {
    for i in 0..to.len() {
        // Each exchange puts one record where it belongs, so a cycle closes within its length.
        while to[i].index() != i {
            let j = to[i].index();
            if j >= to.len() {
                return;
            }
            swap(i, j);
            to.swap(i, j);
        }
    }
}
