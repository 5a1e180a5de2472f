//! Vertex splits: Hoppe's legality test (`vspl_legal`), the split itself (`apply_vspl`), and
//! forced splits (`force_vsplit`; the merge-tree paper's forced refinement, §3.6).

use core::hint::select_unpredictable;

use super::fan::{holds, Fan};
use super::slot::SlotIndex;
use super::{next3, Cut, Refused, NIL};
use crate::format::{HierarchyView, Record, NONE};

/// A split done: its children's ids, slots and records.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Split {
    pub children: [u32; 2],
    pub slots: [u32; 2],
    pub records: [Record; 2],
}

/// Everything a legal split needs, found while proving it legal.
pub(crate) struct SplitPlan {
    /// The parent's slot (it becomes the first child's).
    parent: u32,
    /// The neighbour triangles' slots (`fn0..fn3`, `NIL` where the file has none).
    neighbours: [u32; 4],
    /// The children's node ids and the ids of the triangles the split adds.
    children: [u32; 2],
    faces: [u32; 2],
    /// The wing vertices' slots (the second `NIL` on a border).
    wings: [u32; 2],
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Splits active `node` if legal now. On success returns the children's slots.
    pub fn split(&mut self, h: &HierarchyView<'_>, node: u32) -> Result<[u32; 2], Refused> {
        let mut moved = Fan::new();
        let plan = self.split_legal(h, node, &mut moved)?;
        Ok(self.apply_split(h, node, &plan, &moved, 0).0)
    }

    /// Proves the split of `node` legal: it is active, its neighbour triangles are all around
    /// it and meet along the edges the new triangles take over, and there is room. Collects the
    /// triangles that move to the second child into `moved`.
    pub(crate) fn split_legal(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        moved: &mut Fan,
    ) -> Result<SplitPlan, Refused> {
        let ps = self.slot(node).ok_or(Refused::NotActive)?;
        self.split_legal_at(h, node, ps, moved)
    }

    /// [`Cut::split_legal`] of the node at slot `ps`.
    fn split_legal_at(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        ps: u32,
        moved: &mut Fan,
    ) -> Result<SplitPlan, Refused> {
        let s = h.split(node);
        if s.children[0] == NONE {
            return Err(Refused::NoSuchOperation);
        }
        let n = s.neighbours;
        let second = s.second();
        // The neighbour triangles must all be around the vertex (whose fan must be whole).
        let mut fan = Fan::new();
        if !self.complete_fan(ps, &mut fan) {
            return Err(Refused::Inconsistent);
        }
        let mut ns = [NIL; 4];
        for &f in &fan {
            // (Picked without a branch: which triangle is which neighbour follows no pattern
            // a branch predictor learns.)
            let id = self.t.id[f as usize];
            for k in 0..4 {
                ns[k] = select_unpredictable(n[k] == id, f, ns[k]);
            }
        }
        for k in 0..4 {
            if n[k] != NONE && ns[k] == NIL {
                return Err(Refused::Missing(n[k]));
            }
        }
        let added = 1 + second as usize;
        if self.v.is_full() || self.v.len() >= self.map.capacity() || self.t.len() + added > F {
            return Err(Refused::Capacity);
        }

        // Wings, read off the neighbours (the nodes there now may be finer than at formation).
        let third = |f: u32, v: u32, offset: usize| -> Option<u32> {
            let k = self.t.corner_of(f, v)?;
            Some(self.t.corner_at(f, (k + offset) % 3))
        };
        // n1 holds c0 -> wl, n2 holds wr -> c0: both still have the parent's slot as c0.
        let wl = if ns[1] != NIL {
            third(ns[1], ps, 1)
        } else {
            third(ns[0], ps, 2)
        }
        .ok_or(Refused::Inconsistent)?;
        let wr = if !second {
            NIL
        } else if ns[2] != NIL {
            third(ns[2], ps, 2).ok_or(Refused::Inconsistent)?
        } else {
            third(ns[3], ps, 1).ok_or(Refused::Inconsistent)?
        };
        // Each neighbour pair must meet along the edge the new triangle will take over
        // (n0: wl -> p, n1: p -> wl, n2: wr -> p, n3: p -> wr), so the new links are mutual.
        let across = |f: u32, a: u32, b: u32| -> Option<u32> {
            let k = self.t.corner_of(f, a)?;
            (self.t.corner_at(f, next3(k)) == b).then(|| self.t.adj_at(f, k))
        };
        let pairs_meet = |x: u32, y: u32, w: u32| -> bool {
            // x holds w -> p, y holds p -> w; across each lies the other (or a border).
            let xy = x == NIL || across(x, w, ps) == Some(y);
            let yx = y == NIL || across(y, ps, w) == Some(x);
            xy && yx
        };
        if !pairs_meet(ns[0], ns[1], wl) || (second && !pairs_meet(ns[2], ns[3], wr)) {
            return Err(Refused::Inconsistent);
        }
        // The triangles that go to c1: counter-clockwise from n3 to n0, or up to a border and
        // then clockwise from n0 to the other border.
        moved.clear();
        let mut reached = false;
        if ns[3] != NIL {
            let mut f = ns[3];
            while f != NIL {
                moved.push(f).map_err(|_| Refused::Inconsistent)?;
                if f == ns[0] {
                    reached = true;
                    break;
                }
                f = self.ccw(f, ps).ok_or(Refused::Inconsistent)?;
                if f == ns[3] {
                    return Err(Refused::Inconsistent);
                }
            }
        }
        if !reached && ns[0] != NIL {
            let mut f = ns[0];
            while f != NIL {
                if holds(moved, f) {
                    return Err(Refused::Inconsistent);
                }
                moved.push(f).map_err(|_| Refused::Inconsistent)?;
                f = self.cw(f, ps).ok_or(Refused::Inconsistent)?;
            }
        }
        let moves = |f: u32| f != NIL && holds(moved, f);
        if moves(ns[1]) | moves(ns[2]) {
            return Err(Refused::Inconsistent);
        }
        Ok(SplitPlan {
            parent: ps,
            neighbours: ns,
            children: s.children,
            faces: s.faces,
            wings: [wl, wr],
        })
    }

    /// Performs a split [`Cut::split_legal`] approved; with `frames > 0` the children start at
    /// the parent's current (blended) position, normal and colour and blend to their own over
    /// that many frames. Returns the children's slots and records.
    pub(crate) fn apply_split(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        plan: &SplitPlan,
        moved: &Fan,
        frames: u16,
    ) -> ([u32; 2], [Record; 2]) {
        let SplitPlan {
            parent: ps,
            neighbours: ns,
            children: [c0, c1],
            faces,
            wings: [wl, wr],
        } = *plan;
        let second = wr != NIL;
        let start = (frames > 0 && self.blends.len() + 2 <= Q).then(|| self.vertex(h, ps as usize));
        // Room was proven: the vertex arena has a slot, and the node map takes the second child
        // because the first replaces the parent's entry.
        self.reassign(ps as usize, c0);
        let Some(c1s) = self.push_vertex(c1) else {
            // `split_legal` proved room in the vertex arena and the node map, so this cannot
            // happen; should it, the parent comes back rather than the cut breaking.
            debug_assert!(false, "room for a split's second child was proven");
            self.rename_vertex(h, ps as usize, node);
            return ([ps, ps], [h.record(node); 2]);
        };
        // Siblings have adjacent ids (`c1 = c0 + 1`).
        let records = h.pair_records(c0);
        self.link_children(h, [ps, c1s], records);
        if let Some(from) = start {
            self.start_blend_from(ps as usize, &from, frames, false);
            self.start_blend_from(c1s as usize, &from, frames, false);
        }
        for &f in moved {
            if let Some(k) = self.t.corner_of(f, ps) {
                self.t.set_corner(f, k, c1s);
            }
        }
        let added = 1 + second as u16;
        let m = moved.len() as u16;
        let d = self.v.degree[ps as usize];
        self.v.degree[ps as usize] = d.saturating_sub(m).saturating_add(added);
        self.v.degree[c1s as usize] = m.saturating_add(added);
        for w in [wl, wr] {
            if let Some(d) = self.v.degree.get_mut(w as usize) {
                *d = d.saturating_add(1);
            }
        }
        let fl = self.t.len() as u32;
        let fr = if second { fl + 1 } else { NIL };
        // `split_legal` proved room for both.
        let first = self.t.push([ps, c1s, wl], [fr, ns[0], ns[1]], faces[0]);
        debug_assert_eq!(first, Some(fl), "room for a split's triangles was proven");
        if second {
            let pushed = self.t.push([c1s, ps, wr], [fl, ns[2], ns[3]], faces[1]);
            debug_assert_eq!(pushed, Some(fr), "room for a split's triangles was proven");
        }
        self.point_edge(ns[0], wl, c1s, fl);
        self.point_edge(ns[1], ps, wl, fl);
        self.point_edge(ns[2], wr, ps, fr);
        self.point_edge(ns[3], c1s, wr, fr);
        self.v.set_fan(ps as usize, fl);
        self.v.set_fan(c1s as usize, fl);
        ([ps, c1s], records)
    }

    /// Points the edge `a -> b` of triangle `f` (if `f` is a triangle with that edge) at `to`.
    fn point_edge(&mut self, f: u32, a: u32, b: u32, to: u32) {
        if let Some(k) = self.t.corner_of(f, a) {
            if self.t.corner_at(f, next3(k)) == b {
                self.t.set_adj(f, k, to);
            }
        }
    }

    /// Splits active `node`, first splitting whatever its split needs (Hoppe's forced split; the
    /// merge-tree paper's forced refinement, §3.6), each with a blend of `frames` frames.
    /// `allow` is asked before each split with the node and the number of triangles it adds, and
    /// answers why not or `Ok` to go on. Returns the splits done; on a refusal the splits done
    /// so far stay.
    pub fn force_split(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        frames: u16,
        allow: &mut dyn FnMut(u32, u32) -> Result<(), Refused>,
    ) -> Result<u32, Refused> {
        let slot = self.slot(node).ok_or(Refused::NotActive)?;
        self.force_split_at(h, (node, slot), frames, allow, &mut |_| {})
    }

    /// [`Cut::force_split`] of `node` at slot `slot`, telling `split` of each split done (its
    /// children's ids, slots and records).
    pub(crate) fn force_split_at(
        &mut self,
        h: &HierarchyView<'_>,
        (node, slot): (u32, u32),
        frames: u16,
        allow: &mut dyn FnMut(u32, u32) -> Result<(), Refused>,
        split: &mut dyn FnMut(Split),
    ) -> Result<u32, Refused> {
        self.stack.clear();
        self.stack.push(node).map_err(|_| Refused::Capacity)?;
        let mut done = 0;
        let mut moved = Fan::new();
        // The slot of the node on top of the stack, when known.
        let mut known = Some(slot);
        // Each round splits once or pushes a coarser node; bounded for crafted files.
        let mut rounds = 0u32;
        let limit = h.nodes().saturating_mul(4).saturating_add(64);
        while let Some(&v) = self.stack.last() {
            rounds += 1;
            if rounds > limit {
                return Err(Refused::Inconsistent);
            }
            let Some(vs) = known.take().or_else(|| self.slot(v)) else {
                // Either split already (by an earlier forced split), or coarser than the cut
                // here: then its first active ancestor goes first.
                let mut a = h.parent(v);
                let mut steps = 0;
                let ancestor = loop {
                    if a == NONE {
                        break None;
                    }
                    if let Some(s) = self.slot(a) {
                        break Some(s);
                    }
                    a = h.parent(a);
                    steps += 1;
                    if steps > h.nodes() {
                        return Err(Refused::Inconsistent);
                    }
                };
                match ancestor {
                    None => {
                        self.stack.pop();
                    }
                    Some(s) => {
                        self.stack.push(a).map_err(|_| Refused::Capacity)?;
                        known = Some(s);
                    }
                }
                continue;
            };
            match self.split_legal_at(h, v, vs, &mut moved) {
                Ok(plan) => {
                    let added = if plan.wings[1] != NIL { 2 } else { 1 };
                    allow(v, added)?;
                    let (slots, records) = self.apply_split(h, v, &plan, &moved, frames);
                    split(Split {
                        children: plan.children,
                        slots,
                        records,
                    });
                    done += 1;
                    self.stack.pop();
                    if v == node {
                        return Ok(done);
                    }
                }
                Err(Refused::Missing(face)) => {
                    let Some(creator) = h.face_creator(face) else {
                        return Err(Refused::Inconsistent);
                    };
                    if self.stack.as_slice().contains(&creator) {
                        return Err(Refused::Inconsistent);
                    }
                    self.stack.push(creator).map_err(|_| Refused::Capacity)?;
                }
                Err(e) => return Err(e),
            }
        }
        Ok(done)
    }
}
