//! What a policy that judges triangles says about a vertex, or about the parent a collapse would
//! make (the importance paper's test, [`crate::policy::Importance`]).
//!
//! A vertex is wanted split when any triangle around it is over tolerance; a pair's parent is
//! wanted when any triangle the collapse would leave around it is, judged before the collapse
//! with the parent in the children's place. So a collapse never makes a triangle the next frame
//! would split again, and a split is never undone while the view still wants it. Policies that
//! judge only vertices ([`Policy::judges_triangles`] false) pass through untouched. The paper
//! tests each triangle against the frustum, so a triangle in view speaks for its corners even
//! when the frustum culled a corner's own bounds.

use super::slot::SlotIndex;
use super::Cut;
use crate::format::HierarchyView;
use crate::policy::{Bounds, Demand, Policy, View};

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// The position of slot `s`'s node, as the file stores it.
    #[inline]
    fn node_position(&self, h: &HierarchyView<'_>, s: u32) -> [f32; 3] {
        h.digest_center(&self.v.digest[s as usize])
    }

    /// The bounding radius of slot `s`'s node's region.
    #[inline]
    fn node_reach(&self, h: &HierarchyView<'_>, s: u32) -> f32 {
        h.length(self.v.digest[s as usize].radius)
    }

    /// The policy's demand for the active triangle `f`, with the corner at slot `moved` (if
    /// any) standing at a position of its own with a region of its own.
    #[inline]
    fn judge_triangle<P: Policy>(
        &self,
        h: &HierarchyView<'_>,
        f: u32,
        moved: Option<(u32, [f32; 3], f32)>,
        view: &View,
        policy: &P,
    ) -> f32 {
        let t = self.t.at(f);
        let at = |x: u32| match moved {
            Some((slot, position, reach)) if slot == x => (position, reach),
            _ => (self.node_position(h, x), self.node_reach(h, x)),
        };
        let corners = t.map(at);
        let reach = corners.iter().fold(0.0f32, |r, c| r.max(c.1));
        policy.triangle(&corners.map(|c| c.0), reach, view)
    }

    /// The policy's demand for slot `s`, whose node has bounds `b`, raised by the triangles
    /// around it.
    #[inline]
    pub(crate) fn judged<P: Policy>(
        &self,
        h: &HierarchyView<'_>,
        s: usize,
        b: &Bounds,
        view: &View,
        policy: &P,
    ) -> Demand {
        let d = policy.demand(b, view);
        if !policy.judges_triangles() {
            return d;
        }
        let mut triangles = 0.0f32;
        self.for_each_around(s as u32, |f| {
            triangles = triangles.max(self.judge_triangle(h, f, None, view, policy));
        });
        d.raised(triangles)
    }

    /// The policy's demand for the parent (bounds `b`) of the pair at slots `a` and `b`, raised
    /// by the triangles the pair's collapse would leave around the parent.
    #[inline]
    pub(crate) fn judged_pair<P: Policy>(
        &self,
        h: &HierarchyView<'_>,
        (a, b): (usize, usize),
        parent: &Bounds,
        view: &View,
        policy: &P,
    ) -> Demand {
        let d = policy.demand(parent, view);
        if !policy.judges_triangles() {
            return d;
        }
        let (a, b) = (a as u32, b as u32);
        let mut triangles = 0.0f32;
        for (x, other) in [(a, b), (b, a)] {
            self.for_each_around(x, |f| {
                // A triangle on both is removed by the collapse.
                if !self.t.at(f).contains(&other) {
                    let moved = Some((x, parent.center, parent.radius));
                    triangles = triangles.max(self.judge_triangle(h, f, moved, view, policy));
                }
            });
        }
        d.raised(triangles)
    }
}
