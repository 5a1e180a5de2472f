//! Renumbering the cut's slots in an order that reads memory in sequence.
//!
//! Splits append their new vertex and triangles at the end of the tables and collapses move the
//! last record into the hole they leave, so after a camera has swept over the model the slots
//! follow the history of the operations, not the surface: drawing the cut fetches each vertex's
//! record from all over the hierarchy and each triangle's corners from all over the shaded
//! vertices, and a fan walk steps between distant triangles. [`Cut::renumber`] puts the vertices
//! in the order of their nodes (so their records are read from the file front to back: a
//! parent's id is below its children's, and the builder numbers nodes along the surface where
//! its input does) and the triangles in the order of their first corner's slot, walking each
//! vertex's fan. It needs no memory of its own: the node map lends its table as scratch and is
//! rebuilt after, which is why it needs room for two entries per vertex slot there (the
//! recommended `F = 2 V` has it).
//!
//! The cut stays the same cut: the same nodes and triangles, settled marks and geomorphs; only
//! the slots change, and with them the order in which later frames meet vertices (which a
//! window of the active list, `Budget::max_visits`, and the restless vertices' turns follow).

use super::fan::around;
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
        permute(to, |a, b| self.v.swap(a, b));
        // Triangles: dealt out vertex by vertex, each to its corner of least slot, in fan order.
        let to = self.map.scratch(nf);
        to.iter_mut().for_each(|t| *t = I::store(NIL));
        let mut next = 0u32;
        for s in 0..n as u32 {
            around(&self.v, &self.t, s, |f| {
                let first = self.t.get(f).and_then(|t| t.into_iter().min()) == Some(s);
                if let Some(t) = to.get_mut(f as usize).filter(|t| first && t.load() == NIL) {
                    *t = I::store(next);
                    next += 1;
                }
            });
        }
        // A triangle no fan reached (only in a cut a crafted file broke) keeps its order after.
        for t in to.iter_mut().filter(|t| t.load() == NIL) {
            *t = I::store(next);
            next += 1;
        }
        let triangle = |f: u32| through(to, f);
        self.t.renumber_neighbours(triangle);
        self.v.renumber_fans(triangle);
        permute(to, |f, g| self.t.swap(f, g));
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
