//! Vertex splits: Hoppe's legality test (`vspl_legal`), the split itself (`apply_vspl`), and
//! forced splits (`force_vsplit`; the merge-tree paper's forced refinement, §3.6).

use core::hint::select_unpredictable;

use super::fan::Ring;
use super::slot::SlotIndex;
use super::{next3, prev3, Cut, Refused, NIL};
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
    /// The neighbour triangles' slots (`fn0..fn3`, `NIL` where the file has none) and the
    /// parent's corner in each.
    neighbours: [u32; 4],
    corners: [u8; 4],
    /// The children's node ids and the ids of the triangles the split adds.
    children: [u32; 2],
    faces: [u32; 2],
    /// The wing vertices' slots (the second `NIL` on a border).
    wings: [u32; 2],
    /// The triangles that move to the second child: `count` entries of the parent's [`Ring`]
    /// from entry `from` on, wrapping round its end.
    from: usize,
    count: usize,
}

/// No entry of a [`Ring`].
const NOWHERE: usize = usize::MAX;

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Splits active `node` if legal now. On success returns the children's slots.
    pub fn split(&mut self, h: &HierarchyView<'_>, node: u32) -> Result<[u32; 2], Refused> {
        let ps = self.slot(node).ok_or(Refused::NotActive)?;
        let mut ring = Ring::new();
        let plan = self.split_legal_at(h, node, ps, &mut ring)?;
        Ok(self.apply_split(h, node, &plan, &ring, 0).0)
    }

    /// Proves the split of `node`, active at slot `ps`, legal: its neighbour triangles are all
    /// around it and meet along the edges the new triangles take over, and there is room. Leaves
    /// the parent's triangles in `ring`; the plan says which of them move to the second child.
    fn split_legal_at(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        ps: u32,
        ring: &mut Ring,
    ) -> Result<SplitPlan, Refused> {
        let s = h.split(node);
        if s.children[0] == NONE {
            return Err(Refused::NoSuchOperation);
        }
        let n = s.neighbours;
        let second = s.second();
        // The neighbour triangles must all be around the vertex (whose fan must be whole).
        let closed = self.ring(ps, ring).ok_or(Refused::Inconsistent)?;
        let mut at = [NOWHERE; 4];
        for (i, a) in ring.iter().enumerate() {
            // (Picked without a branch: which triangle is which neighbour follows no pattern
            // a branch predictor learns.)
            let id = self.t.id[a.slot as usize];
            for k in 0..4 {
                at[k] = select_unpredictable(n[k] == id, i, at[k]);
            }
        }
        for k in 0..4 {
            if n[k] != NONE && at[k] == NOWHERE {
                return Err(Refused::Missing(n[k]));
            }
        }
        let added = 1 + second as usize;
        if (self.v.is_full() && self.free == 0)
            || self.active() >= self.map.capacity()
            || self.t.len() + added > F
        {
            return Err(Refused::Capacity);
        }
        let present = at.map(|i| i != NOWHERE);
        let ns = at.map(|i| ring.get(i).map_or(NIL, |a| a.slot));
        let nc = at.map(|i| ring.get(i).map_or(0, |a| a.corner));
        // Corner `k` of neighbour `j`, the parent's plus `offset` (one read a wing, so that
        // it is inlined, where a closure called at four places was not).
        let beside = |(j, offset): (usize, usize)| (ns[j], (nc[j] as usize + offset) % 3);

        // Wings, read off the neighbours (the nodes there now may be finer than at formation).
        // n1 holds c0 -> wl, n2 holds wr -> c0: both still have the parent's slot as c0.
        let (f, k) = beside(match present {
            [_, true, _, _] => (1, 1),
            [true, ..] => (0, 2),
            _ => return Err(Refused::Inconsistent),
        });
        let wl = self.t.corner_at(f, k);
        let wr = if second {
            let (f, k) = beside(match present {
                [_, _, true, _] => (2, 2),
                [.., true] => (3, 1),
                _ => return Err(Refused::Inconsistent),
            });
            self.t.corner_at(f, k)
        } else {
            NIL
        };
        // Each neighbour pair must meet along the edge the new triangle will take over
        // (n0: wl -> p, n1: p -> wl, n2: wr -> p, n3: p -> wr), so the new links are mutual:
        // across each lies the other (or a border).
        let meet = |into: usize, out: usize, w: u32| -> bool {
            let (x, y) = (ns[into], ns[out]);
            let (kx, ky) = (nc[into] as usize, nc[out] as usize);
            let xy = !present[into]
                || (self.t.corner_is(x, prev3(kx), w) && self.t.adj_is(x, prev3(kx), y));
            let yx =
                !present[out] || (self.t.corner_is(y, next3(ky), w) && self.t.adj_is(y, ky, x));
            xy && yx
        };
        if !meet(0, 1, wl) || (second && !meet(2, 3, wr)) {
            return Err(Refused::Inconsistent);
        }
        // The triangles that go to c1: counter-clockwise from n3 to n0, through the border if
        // the fan has one; from the border to n0, or from n3 to the border, when one of them
        // is missing (on a closed fan, a contradiction).
        let len = ring.len();
        let (from, count) = match (present[3], present[0]) {
            (true, true) if at[3] <= at[0] => (at[3], at[0] - at[3] + 1),
            (true, true) => (at[3], len - at[3] + at[0] + 1),
            (true, false) if !closed => (at[3], len - at[3]),
            (false, true) if !closed => (0, at[0] + 1),
            (false, false) => (0, 0),
            _ => return Err(Refused::Inconsistent),
        };
        let moves = |j: usize| {
            let i = at[j];
            let d = if i >= from { i - from } else { i + len - from };
            present[j] && d < count
        };
        if moves(1) | moves(2) {
            return Err(Refused::Inconsistent);
        }
        Ok(SplitPlan {
            parent: ps,
            neighbours: ns,
            corners: nc,
            children: s.children,
            faces: s.faces,
            wings: [wl, wr],
            from,
            count,
        })
    }

    /// Performs a split [`Cut::split_legal_at`] approved, with the parent's triangles it left
    /// in `ring`; with `frames > 0` the children start at the parent's current (blended)
    /// position, normal and colour and blend to their own over that many frames. Returns the
    /// children's slots and records.
    pub(crate) fn apply_split(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        plan: &SplitPlan,
        ring: &Ring,
        frames: u16,
    ) -> ([u32; 2], [Record; 2]) {
        let SplitPlan {
            parent: ps,
            neighbours: ns,
            corners: nc,
            children: [c0, c1],
            faces,
            wings: [wl, wr],
            from,
            count,
        } = *plan;
        let second = wr != NIL;
        let start = (frames > 0 && self.blends.len() + 2 <= Self::BLEND_ROOM)
            .then(|| self.vertex(h, ps as usize));
        // Room was proven: the vertex arena has a slot, and the node map takes the second child
        // because the first replaces the parent's entry.
        self.reassign(ps as usize, c0);
        let Some(c1s) = self.push_vertex(c1) else {
            // `split_legal_at` proved room in the vertex arena and the node map, so this cannot
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
        // The moved entries: from `from` to the ring's end, then from its start.
        let (head, tail) = ring.split_at(from.min(ring.len()));
        let wrapped = (from + count).saturating_sub(ring.len()).min(head.len());
        for a in &tail[..count.min(tail.len())] {
            self.t.set_corner(a.slot, a.corner as usize, c1s);
        }
        for a in &head[..wrapped] {
            self.t.set_corner(a.slot, a.corner as usize, c1s);
        }
        let added = 1 + second as u16;
        let m = count as u16;
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
        // `split_legal_at` proved room for both.
        let first = self.t.push([ps, c1s, wl], [fr, ns[0], ns[1]], faces[0]);
        debug_assert_eq!(first, Some(fl), "room for a split's triangles was proven");
        if second {
            let pushed = self.t.push([c1s, ps, wr], [fl, ns[2], ns[3]], faces[1]);
            debug_assert_eq!(pushed, Some(fr), "room for a split's triangles was proven");
        }
        // The edges `split_legal_at` proved: n0's wl -> c1 and n2's wr -> c0 end at the
        // parent's corner, n1's c0 -> wl and n3's c1 -> wr start there.
        let to = [fl, fl, fr, fr];
        for j in 0..4 {
            if ns[j] != NIL {
                let k = nc[j] as usize;
                let edge = if j % 2 == 0 { prev3(k) } else { k };
                self.t.set_adj(ns[j], edge, to[j]);
            }
        }
        self.v.set_fan(ps as usize, fl);
        self.v.set_fan(c1s as usize, fl);
        ([ps, c1s], records)
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
        let mut ring = Ring::new();
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
            match self.split_legal_at(h, v, vs, &mut ring) {
                Ok(plan) => {
                    let added = if plan.wings[1] != NIL { 2 } else { 1 };
                    allow(v, added)?;
                    let (slots, records) = self.apply_split(h, v, &plan, &ring, frames);
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
