//! Edge collapses: Hoppe's legality test (`ecol_legal`) and the collapse itself (`apply_ecol`).

use core::hint::select_unpredictable;

use super::fan::PairFans;
use super::slot::SlotIndex;
use super::{corner, first_of, next3, prev3, Cut, Refused, BLOCKED, NIL, SETTLED};
use crate::format::{HierarchyView, SplitView, NONE};

/// The slots of a legal collapse: the two children `a` and `b`, and the triangles it removes
/// (`right` is `NIL` on a border).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CollapsePlan {
    pub a: u32,
    pub b: u32,
    pub left: u32,
    pub right: u32,
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Collapses active siblings into their parent `node` if Hoppe's condition holds. Returns the
    /// parent's slot.
    pub fn collapse(&mut self, h: &HierarchyView<'_>, node: u32) -> Result<u32, Refused> {
        let mut fans = PairFans::default();
        let plan = self.collapse_legal(h, node, &mut fans, false)?;
        Ok(self.apply_collapse(h, node, plan, &mut fans, false))
    }

    /// Proves the collapse of `node`'s children legal (see [`Cut::collapse_legal_at`] for
    /// `frees`).
    pub(crate) fn collapse_legal(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        fans: &mut PairFans,
        frees: bool,
    ) -> Result<CollapsePlan, Refused> {
        let s = h.split(node);
        let [c0, c1] = s.children;
        if c0 == NONE {
            return Err(Refused::NoSuchOperation);
        }
        let a = self.slot(c0).ok_or(Refused::NotActive)?;
        let b = self.slot(c1).ok_or(Refused::NotActive)?;
        self.collapse_legal_at(&s, a, b, fans, frees)
    }

    /// [`Cut::collapse_legal`] with the children's slots `a` and `b` known; `frees` when the
    /// collapse will leave `b`'s slot empty ([`Cut::free_vertex`]) instead of moving the last
    /// vertex into it (whose fan must then be whole).
    pub(crate) fn collapse_legal_at(
        &self,
        s: &SplitView,
        a: u32,
        b: u32,
        fans: &mut PairFans,
        frees: bool,
    ) -> Result<CollapsePlan, Refused> {
        // Only `b`'s triangles are renamed, so `a`'s fan is walked only as far as `fl` (most
        // collapses tried are refused by `fl`'s neighbours).
        let id = s.faces[0];
        let fl = self
            .find_around(a, |f| self.t.id[f as usize] == id)
            .ok_or(Refused::Illegal)?;
        let t = self.t.at(fl);
        let k = corner(t, a).ok_or(Refused::Inconsistent)?;
        if t[next3(k)] != b {
            return Err(Refused::Inconsistent);
        }
        let adj = self.t.adj(fl);
        let id = |f: u32| {
            if f == NIL {
                NONE
            } else {
                self.t.id[f as usize]
            }
        };
        // fl = (a, b, wl): edge b -> wl has n0, edge wl -> a has n1.
        if id(adj[next3(k)]) != s.neighbours[0] || id(adj[prev3(k)]) != s.neighbours[1] {
            return Err(Refused::Illegal);
        }
        let fr = adj[k];
        if s.second() {
            let Some(t) = self.t.get(fr) else {
                return Err(Refused::Illegal);
            };
            if self.t.id[fr as usize] != s.faces[1] {
                return Err(Refused::Illegal);
            }
            let j = corner(t, b).ok_or(Refused::Inconsistent)?;
            if t[next3(j)] != a {
                return Err(Refused::Inconsistent);
            }
            // fr = (b, a, wr): edge a -> wr has n2, edge wr -> b has n3.
            let adj = self.t.adj(fr);
            if id(adj[next3(j)]) != s.neighbours[2] || id(adj[prev3(j)]) != s.neighbours[3] {
                return Err(Refused::Illegal);
            }
        } else if fr != NIL {
            return Err(Refused::Inconsistent);
        }
        // Renaming b, and moving the last vertex into b's slot, must reach every triangle.
        let last = self.v.len() as u32 - 1;
        if !self.complete_fan(b, &mut fans.fan) || !(frees || self.fan_complete(last)) {
            return Err(Refused::Inconsistent);
        }
        Ok(CollapsePlan {
            a,
            b,
            left: fl,
            right: fr,
        })
    }

    /// Performs a collapse [`Cut::collapse_legal`] approved, with the fans it found (used as
    /// scratch afterwards), leaving `b`'s slot empty when `frees` (as approved); returns the
    /// parent's slot.
    pub(crate) fn apply_collapse(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        plan: CollapsePlan,
        fans: &mut PairFans,
        frees: bool,
    ) -> u32 {
        let CollapsePlan {
            a,
            b,
            left: fl,
            right: fr,
        } = plan;
        let fan_b = &fans.fan;
        // The removed triangles' corners lose one triangle each; then b's become a's.
        for f in [fl, fr] {
            if let Some(t) = self.t.get(f) {
                for v in t {
                    if let Some(d) = self.v.degree.get_mut(v as usize) {
                        *d = d.saturating_sub(1);
                    }
                }
            }
        }
        let db = self.v.degree[b as usize];
        self.v.degree[a as usize] = self.v.degree[a as usize].saturating_add(db);
        self.v.degree[b as usize] = 0;
        for &f in fan_b {
            // (The removed two keep `b`: written back, not skipped by a branch.)
            if let Some(k) = self.t.corner_of(f, b) {
                let kept = (f == fl) | (f == fr);
                self.t.set_corner(f, k, select_unpredictable(kept, b, a));
            }
        }
        // The neighbours of each removed triangle become each other's: a new neighbour may be
        // what the collapse of the pair that made them waited for.
        let mut new_fan = NIL;
        fans.unblocked.clear();
        for f in [fl, fr] {
            let Some(t) = self.t.get(f) else {
                continue;
            };
            let adj = self.t.adj(f);
            // The third corner w and the neighbours across its two edges.
            let j = first_of(|k| (t[k] != a) & (t[k] != b)).unwrap_or(0);
            let w = t[j];
            let (x, y) = (adj[j], adj[prev3(j)]);
            for (p, q) in [(x, y), (y, x)] {
                if p == NIL {
                    continue;
                }
                self.unblock_pair_of(h, p, fans);
                self.t.replace_adj(p, f, q);
            }
            let keep = if x != NIL { x } else { y };
            let fw = self.v.fan(w as usize);
            if fw == fl || fw == fr {
                self.v.set_fan(w as usize, keep);
            }
            if new_fan == NIL {
                new_fan = keep;
            }
        }
        self.v.set_fan(a as usize, new_fan);
        // Remove the triangles, the higher slot first so the lower stays where it is.
        let (hi, lo) = if fr != NIL && fr > fl {
            (fr, fl)
        } else {
            (fl, fr)
        };
        self.remove_triangle(hi);
        if lo != NIL {
            self.remove_triangle(lo);
        }
        // `b` leaves the map first (remove_vertex expects it gone); renaming `a` breaks their
        // mate link.
        self.map.remove(self.v.node[b as usize], self.v.nodes());
        self.rename_vertex(h, a as usize, node);
        if frees {
            self.free_vertex(b);
            return a;
        }
        match self.remove_vertex(b) {
            Some(moved_from) if moved_from == a => b,
            _ => a,
        }
    }

    /// Clears the illegal mark of the pair that made triangle `f`, which a collapse is giving a
    /// new neighbour, and remembers its first child in `fans.unblocked`.
    ///
    /// A collapse is legal when its two triangles have the four neighbours its split record
    /// names (Hoppe's condition), and the triangles of an active pair are always there (only the
    /// collapse of their own pair removes them), so an illegal collapse can become legal only
    /// when one of its triangles gets a new neighbour. A split never gives it the one it waits
    /// for: the triangles a split makes are new neighbours only of the triangles its own record
    /// names, which the file's order of splits makes before it, while a blocked collapse waits
    /// for a triangle made before its own. So only collapses unblock, and only the pairs that
    /// made the triangles next to the two a collapse removes: at most four.
    fn unblock_pair_of(&mut self, h: &HierarchyView<'_>, f: u32, fans: &mut PairFans) {
        let Some([c0, c1]) = h.face_children(self.t.id[f as usize]) else {
            return;
        };
        // While the pair is active its children are corners of the triangles it made.
        let (mut a, mut b) = (NIL, NIL);
        for v in self.t.at(f) {
            let n = self.v.node.get(v as usize).copied().unwrap_or(NONE);
            a = select_unpredictable(n == c0, v, a);
            b = select_unpredictable(n == c1, v, b);
        }
        let (Some(fa), Some(fb)) = (self.v.flags.get(a as usize), self.v.flags.get(b as usize))
        else {
            return;
        };
        if fa & fb & BLOCKED == 0 {
            return;
        }
        // Judged again (by its first child): no longer settled either.
        for s in [a, b] {
            self.v.flags[s as usize] &= !(BLOCKED | SETTLED);
        }
        // At most four a collapse (two neighbours of each of two triangles), which `unblocked`
        // holds; were one left out, its pair, unmarked and unsettled, would be asked by the
        // next frame's walk and listed there.
        let remembered = fans.unblocked.push(c0).is_ok();
        debug_assert!(remembered, "a collapse unblocks at most four pairs");
    }
}
