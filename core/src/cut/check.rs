//! The invariants of a cut, verified (Hoppe's `ok()`): the tests call [`Cut::check`] after
//! every operation and every frame.

use super::slot::SlotIndex;
use super::{corner, next3, Cut, BLENDING, COLLAPSING, FIRST_CHILD, NIL};
use crate::format::{HierarchyView, NONE};

/// What went wrong in [`Cut::check`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Defect {
    /// What is wrong.
    pub what: &'static str,
    /// Where: a vertex or triangle slot.
    pub slot: u32,
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Every vertex's fan walk finds all its triangles, each once, and the counts add up to
    /// three corners per triangle: each vertex's triangles form one fan (a manifold).
    pub(crate) fn check_fans(&self) -> Result<(), Defect> {
        let mut corners = 0usize;
        for v in 0..self.v.len() as u32 {
            if !self.fan_complete(v) {
                return Err(Defect {
                    what: "a vertex's triangles are not one fan, or its count is wrong",
                    slot: v,
                });
            }
            corners += self.v.degree[v as usize] as usize;
        }
        if corners != 3 * self.t.len() {
            return Err(Defect {
                what: "triangle counts do not add up",
                slot: 0,
            });
        }
        Ok(())
    }

    /// Verifies the cut: slots in range, adjacency symmetric along reversed edges (consistent
    /// orientation, no crack: every edge has one triangle on each side or is a border), every
    /// vertex's triangles one fan (a manifold), no degenerate triangle, the node map, the
    /// sibling links, the blend entries and the triangle ids right for `h`.
    pub fn check(&self, h: &HierarchyView<'_>) -> Result<(), Defect> {
        let bad = |what, slot| Err(Defect { what, slot });
        if self.holes != 0 || self.free != 0 {
            return bad(
                "vertex slots a collapse freed are left empty",
                self.free.wrapping_sub(1),
            );
        }
        let nv = self.v.len() as u32;
        let nf = self.t.len() as u32;
        for f in 0..nf {
            let t = self.t.at(f);
            if t.iter().any(|&v| v >= nv) {
                return bad("corner out of range", f);
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return bad("degenerate triangle", f);
            }
            if self.t.id[f as usize] >= h.faces() {
                return bad("triangle id out of range", f);
            }
            for k in 0..3 {
                let g = self.t.adj(f)[k];
                if g == NIL {
                    continue;
                }
                if g >= nf {
                    return bad("neighbour out of range", f);
                }
                let (a, b) = (t[k], t[next3(k)]);
                let u = self.t.at(g);
                let Some(j) = corner(u, b) else {
                    return bad("neighbour does not share the edge", f);
                };
                if u[next3(j)] != a || self.t.adj(g)[j] != f {
                    return bad("adjacency not symmetric or orientation flipped", f);
                }
            }
        }
        for v in 0..nv {
            let i = v as usize;
            let node = self.v.node[i];
            if self.slot(node) != Some(v) {
                return bad("node map wrong", v);
            }
            if node >= h.nodes() {
                return bad("node out of range", v);
            }
            // The sibling link: set exactly when the sibling is active, both ways.
            let p = h.parent(node);
            let (first, sibling) = if p == NONE {
                (false, None)
            } else {
                let [c0, c1] = h.children(p);
                (c0 == node, self.slot(if c0 == node { c1 } else { c0 }))
            };
            if (self.v.flags[i] & FIRST_CHILD != 0) != first {
                return bad("first-child flag wrong", v);
            }
            if self.v.mate(i) != sibling.unwrap_or(NIL) {
                return bad("sibling link wrong", v);
            }
            let b = self.v.blend(i);
            let blending = self.v.flags[i] & (BLENDING | COLLAPSING) != 0;
            match self.blends.as_slice().get(b as usize) {
                Some(e) if e.slot == v => {}
                None if b == NIL && !blending => {}
                _ => return bad("blend entry wrong", v),
            }
        }
        if self.map.len() != nv as usize {
            return bad("node map has extra entries", 0);
        }
        self.check_fans()
    }
}
