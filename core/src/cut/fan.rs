//! Walks around a vertex: the triangles of its fan, proven complete, or just visited.
//!
//! Every operation renames corners around one or two vertices, so it must reach every triangle
//! that uses them. A walk steps from triangle to neighbouring triangle around the vertex; it is
//! complete when it found exactly as many distinct triangles as the vertex's triangle count,
//! which every operation keeps. That count check is what keeps the cut whole on hierarchies
//! crafted to contradict the mesh.

use super::slot::SlotIndex;
use super::{Cut, NIL};

/// Longest fan walked around one vertex; a hierarchy with larger vertex degrees is refused
/// rather than walked forever.
pub const MAX_FAN: usize = 1024;

/// The triangle slots of one fan: scratch on the stack, never in the cut, so an uninitialised
/// vector (making one writes no memory; an arena would zero its 4 KiB each time).
pub(crate) type Fan = heapless::Vec<u32, MAX_FAN>;

/// One triangle of a [`Ring`]: its slot, and which of its corners the vertex is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Around {
    pub slot: u32,
    pub corner: u8,
}

/// A vertex's triangles in counter-clockwise order, each with the corner the vertex takes in
/// it: what a split reads its neighbours, its wings and the triangles that move to its second
/// child from, in one walk. On a border the order runs from the triangle after the border to
/// the one before it; otherwise it is cyclic and starts anywhere. (One vector: a struct of two
/// would be made with a `memset` of the first's 4 KiB, its two lengths being one aggregate.)
pub(crate) type Ring = heapless::Vec<Around, MAX_FAN>;

/// Most pairs one collapse unblocks: those that made the four triangles next to the two it
/// removes.
pub(crate) const MAX_UNBLOCKED: usize = 4;

/// The triangles around the second vertex of a collapse, found while proving it legal and used
/// again to do it (renamed to the first); and the pairs whose illegal mark the collapse cleared.
pub(crate) struct PairFans {
    /// First children of the pairs the last collapse unblocked (see `crate::cut::BLOCKED`).
    pub unblocked: heapless::Vec<u32, MAX_UNBLOCKED>,
    pub fan: Fan,
}

impl Default for PairFans {
    fn default() -> Self {
        PairFans {
            // The fan is the struct's last field: first, LLVM wrote the new struct as one
            // aggregate, a constant of zeros and uninitialised bytes, with a 4 KiB `memset` per
            // call (2% of a steady frame's instructions at 1 px; the two fans of before
            // 2026-12-06 cost 3%, 10% at 4 px, until made one at a time).
            unblocked: heapless::Vec::new(),
            fan: Fan::new(),
        }
    }
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Collects `v`'s triangles into `out` and says whether the walk found every triangle that
    /// uses `v`, each once. Out of line: inlined into a caller that makes `out` just for it,
    /// it lets LLVM see the whole of a fresh vector's life, which it then zeroes (4 KiB).
    #[inline(never)]
    pub(crate) fn complete_fan(&self, v: u32, out: &mut Fan) -> bool {
        self.walk_fan(v, out, |f, _| f, |&f| f).is_some()
    }

    /// [`Cut::complete_fan`] in counter-clockwise order with each triangle's corner (see
    /// [`Ring`]): the border fan's clockwise half reversed and put first. Whether the fan closes
    /// (then the order is cyclic), or `None` when it is not whole.
    pub(crate) fn ring(&self, v: u32, out: &mut Ring) -> Option<bool> {
        let make = |slot, k: usize| Around {
            slot,
            corner: k as u8,
        };
        let (ccw_part, closed) = self.walk_fan(v, out, make, |a| a.slot)?;
        if !closed {
            out[ccw_part..].reverse();
            out.rotate_left(ccw_part);
        }
        Some(closed)
    }

    /// Walks `v`'s fan into `out`, each triangle as `make(slot, v's corner in it)`:
    /// counter-clockwise from the vertex's fan triangle, and at a border clockwise from it
    /// (`slot` reads an entry's slot back). Each step of a walk is a function of the triangle
    /// it stands on, so a walk that comes back to its start (or reaches a border) without
    /// exceeding [`MAX_FAN`] steps repeats nothing; only the two halves of a border fan can
    /// overlap, which is checked, and the count must match the vertex's triangle count. `None`
    /// when the walk does not find every triangle that uses `v`, each once; else how many
    /// entries the counter-clockwise walk made, and whether it came back to its start.
    #[inline(always)]
    fn walk_fan<T>(
        &self,
        v: u32,
        out: &mut heapless::Vec<T, MAX_FAN>,
        make: impl Fn(u32, usize) -> T,
        slot: impl Fn(&T) -> u32,
    ) -> Option<(usize, bool)> {
        out.clear();
        if v as usize >= self.v.len() {
            return None;
        }
        let start = self.v.fan(v as usize);
        let degree = self.v.degree[v as usize] as usize;
        if start == NIL {
            return (degree == 0).then_some((0, false));
        }
        let mut f = start;
        loop {
            let (k, g) = self.t.ccw_at(f, v)?;
            if out.push(make(f, k)).is_err() {
                return None;
            }
            match g {
                g if g == start => return (out.len() == degree).then_some((out.len(), true)),
                NIL => break,
                g => f = g,
            }
        }
        // A border: the rest lies clockwise of the start, and must not meet the first half.
        let ccw_part = out.len();
        let (_, mut g) = self.t.cw_at(start, v)?;
        while g != NIL {
            let (k, next) = self.t.cw_at(g, v)?;
            let met = out[..ccw_part].iter().any(|e| slot(e) == g);
            if met || out.push(make(g, k)).is_err() {
                return None;
            }
            g = next;
        }
        (out.len() == degree).then_some((ccw_part, false))
    }

    /// Calls `visit` with each triangle around slot `v`, walking at most as many steps as the
    /// vertex has triangles (so a fan a crafted file broke ends the walk, not the program).
    #[inline]
    pub(crate) fn for_each_around(&self, v: u32, mut visit: impl FnMut(u32)) {
        self.find_around(v, |f| {
            visit(f);
            false
        });
    }

    /// The first triangle around slot `v` for which `wanted` holds, walking counter-clockwise
    /// from the vertex's fan triangle, then (at a border) clockwise from it, at most as many
    /// steps as the vertex has triangles.
    pub(crate) fn find_around(&self, v: u32, mut wanted: impl FnMut(u32) -> bool) -> Option<u32> {
        if v as usize >= self.v.len() {
            return None;
        }
        let start = self.v.fan(v as usize);
        let mut left = self.v.degree[v as usize];
        if start == NIL {
            return None;
        }
        let mut f = start;
        while left > 0 {
            if wanted(f) {
                return Some(f);
            }
            left -= 1;
            match self.t.ccw(f, v) {
                Some(g) if g == start => return None,
                Some(g) if g != NIL => f = g,
                _ => break,
            }
        }
        // A border: the rest lies clockwise of the start.
        let mut g = self.t.cw(start, v).unwrap_or(NIL);
        while g != NIL && left > 0 {
            if wanted(g) {
                return Some(g);
            }
            left -= 1;
            g = self.t.cw(g, v).unwrap_or(NIL);
        }
        None
    }

    /// Whether walking `v`'s fan finds every triangle that uses `v`, each once.
    pub(crate) fn fan_complete(&self, v: u32) -> bool {
        self.complete_fan(v, &mut Fan::new())
    }
}
