//! The cut's vertex and triangle tables: structure-of-arrays records with one length each, and
//! the only code that appends, moves or drops a record.
//!
//! A vertex record is 21 bytes with 16-bit slots (25 with 32-bit ones): its node (`u32`), one
//! triangle of its fan, its triangle count, its sibling's slot when both are active ("mate"),
//! a 16-bit tag (its geomorph's entry in the blend arena while it blends, the motion at which
//! its answers expire while it is settled: it is never both), a flag byte, and the node's
//! 8-byte [`Digest`] (quantized position and two bound codes), with which the per-frame pass
//! skips most vertices without reading the file. Normals, colours and the rest of the bounds
//! are not stored: they are read from the hierarchy in place ([`super::Cut::vertex`]), except
//! for vertices in a geomorph. A triangle record is 16 bytes: three corner slots, the three
//! neighbouring triangles' slots (across edges `t[k] -> t[k + 1]`) and its id in the
//! hierarchy's numbering.

use core::hint::select_unpredictable;

use super::expiry::{lives, Mark, TURNING};
use super::renumber::scatter;
use super::slot::{load3, store3, SlotIndex};
use super::{first_of, BLENDING, COLLAPSING, NIL, RESTLESS, SETTLED};
use crate::format::Digest;

/// Blend entries a tag can name: its all-ones value is `NIL`.
pub(crate) const NAMEABLE_BLENDS: usize = u16::MAX as usize;

/// `a[k]` (`k < 3`), picked in registers: the three are loaded before `k` is known, so that
/// their load does not wait for it.
#[inline(always)]
fn pick<T: Copy>([a0, a1, a2]: [T; 3], k: usize) -> T {
    select_unpredictable(k == 0, a0, select_unpredictable(k == 1, a1, a2))
}

/// The vertex records.
#[derive(Clone, Debug)]
pub(crate) struct Vertices<const V: usize, I: SlotIndex> {
    len: u32,
    pub node: [u32; V],
    fan: [I; V],
    /// Triangles using the vertex, kept by every operation: a fan walk that finds this many
    /// distinct triangles found them all, which is what makes renaming a vertex complete (and
    /// the cut safe from hierarchies crafted to contradict the mesh).
    pub degree: [u16; V],
    mate: [I; V],
    /// The blend entry while `BLENDING` or `COLLAPSING`, the expiry while `SETTLED`: 16 bits
    /// whatever the slot index, since an expiry fits them and blend entries stay below
    /// [`NAMEABLE_BLENDS`] (a 32-bit cut's walk then scans half the bytes).
    tag: [u16; V],
    pub flags: [u8; V],
    /// What the per-frame pass needs of the node without reading the file (see [`Digest`]).
    pub digest: [Digest; V],
}

impl<const V: usize, I: SlotIndex> Vertices<V, I> {
    pub const fn new() -> Self {
        Vertices {
            len: 0,
            node: [0; V],
            fan: [I::ZERO; V],
            degree: [0; V],
            mate: [I::ZERO; V],
            tag: [0; V],
            flags: [0; V],
            digest: [Digest::ZERO; V],
        }
    }

    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len as usize
    }

    #[inline]
    pub fn is_full(&self) -> bool {
        self.len() >= V
    }

    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The nodes of the active vertices, by slot.
    #[inline(always)]
    pub fn nodes(&self) -> &[u32] {
        &self.node[..self.len as usize]
    }

    #[inline(always)]
    pub fn fan(&self, s: usize) -> u32 {
        self.fan.get(s).map_or(NIL, |f| f.load())
    }

    #[inline(always)]
    pub fn set_fan(&mut self, s: usize, f: u32) {
        if let Some(x) = self.fan.get_mut(s) {
            *x = I::store(f);
        }
    }

    /// The sibling's slot when this vertex and its sibling are both active, else `NIL`.
    #[inline(always)]
    pub fn mate(&self, s: usize) -> u32 {
        self.mate.get(s).map_or(NIL, |m| m.load())
    }

    /// Links slot `s` to its sibling's slot `m` (or `NIL`); the vertex is no longer settled.
    #[inline(always)]
    pub fn set_mate(&mut self, s: usize, m: u32) {
        if let (Some(x), Some(f)) = (self.mate.get_mut(s), self.flags.get_mut(s)) {
            *x = I::store(m);
            *f &= !SETTLED;
        }
    }

    /// The vertex's entry in the blend arena, or `NIL` (not blending).
    #[inline(always)]
    pub fn blend(&self, s: usize) -> u32 {
        match (self.tag.get(s), self.flags.get(s)) {
            (Some(b), Some(f)) if f & (BLENDING | COLLAPSING) != 0 => b.load(),
            _ => NIL,
        }
    }

    /// Makes `b` (below [`NAMEABLE_BLENDS`]) slot `s`'s blend entry (the caller sets `BLENDING`);
    /// it is no longer settled.
    #[inline(always)]
    pub fn set_blend(&mut self, s: usize, b: u32) {
        if let (Some(x), Some(f)) = (self.tag.get_mut(s), self.flags.get_mut(s)) {
            *x = <u16 as SlotIndex>::store(b);
            *f &= !SETTLED;
        }
    }

    /// The count at which slot `s`'s answers expire, when it is settled (`s` in range), with
    /// the count's bit (see `super::expiry::lives`).
    #[inline(always)]
    pub fn expiry(&self, s: usize) -> u32 {
        u32::from(self.tag[s])
    }

    /// Marks slot `s` as its measured margins say: settled until the motion passes the
    /// expiry (below `u16::MAX`), unless it is in a geomorph (asked every frame, and its tag
    /// is its blend entry), or restless.
    #[inline(always)]
    pub fn mark(&mut self, s: usize, mark: Mark) {
        if let (Some(x), Some(f)) = (self.tag.get_mut(s), self.flags.get_mut(s)) {
            // Written whatever the mark (the old values when it changes nothing): which it is
            // follows no pattern a branch predictor learns.
            let (settles, until) = match mark {
                Mark::Settled(until) => (*f & (BLENDING | COLLAPSING) == 0, until),
                Mark::Restless => (false, 0),
            };
            let restless = u8::from(mark == Mark::Restless) * RESTLESS;
            *x = if settles { until as u16 } else { *x };
            *f = if settles {
                (*f & !RESTLESS) | SETTLED
            } else {
                *f | restless
            };
        }
    }

    /// Which of the `count` (at most `usize::BITS`) slots from `first` (in range) are settled
    /// with an expiry its count in `now` has not passed, as bits.
    #[inline(always)]
    pub fn settled_until(&self, first: usize, count: usize, now: [u32; 2]) -> usize {
        let flags = &self.flags[first..first + count];
        let tags = &self.tag[first..first + count];
        if let Some(bits) = settled_word(flags, tags, now) {
            return bits;
        }
        // Eight slots at a time: a byte of 0 or 1 each (the SETTLED bits shifted down, and the
        // expiries compared), gathered into eight bits; the rest one at a time.
        const ONES: u64 = 0x0101_0101_0101_0101;
        let mut bits = 0usize;
        let (fs, xs) = (flags.chunks_exact(8), tags.chunks_exact(8));
        let rest = fs.remainder().iter().zip(xs.remainder());
        for (c, (f, x)) in fs.zip(xs).enumerate() {
            let f = u64::from_le_bytes(core::array::from_fn(|k| f[k]));
            let late = u64::from_le_bytes(core::array::from_fn(|k| {
                u8::from(lives(u32::from(x[k]), now))
            }));
            let lanes = (f >> SETTLED.trailing_zeros()) & ONES & late;
            bits |= gathered(lanes) << (8 * c);
        }
        for (k, (f, x)) in rest.enumerate() {
            let k = count / 8 * 8 + k;
            bits |= usize::from((f & SETTLED != 0) & lives(u32::from(*x), now)) << k;
        }
        bits
    }

    /// Clears every vertex's settled and restless marks.
    pub fn unsettle_all(&mut self) {
        let len = self.len();
        self.flags[..len]
            .iter_mut()
            .for_each(|f| *f &= !(SETTLED | RESTLESS));
    }

    /// Lowers every live expiry on each count by `by` after the count was lowered as much to
    /// `now`; clears the marks that expired.
    pub fn rebase(&mut self, now: [u32; 2], by: [u32; 2]) {
        let len = self.len();
        for (f, x) in self.flags[..len].iter_mut().zip(&mut self.tag[..len]) {
            if *f & SETTLED == 0 {
                continue;
            }
            let tag = u32::from(*x);
            let (count, e) = (tag & TURNING, tag & !TURNING);
            let k = usize::from(count != 0);
            match e.checked_sub(by[k]) {
                Some(e) if e >= now[k] => *x = (count | e) as u16,
                _ => *f &= !SETTLED,
            }
        }
    }

    /// Appends a vertex for `node` with no triangles, no mate and no blend; its slot, or `None`
    /// when full.
    pub fn push(&mut self, node: u32, flags: u8) -> Option<u32> {
        let s = self.len as usize;
        if s >= V {
            return None;
        }
        self.fill(s, node, flags);
        self.len += 1;
        Some(s as u32)
    }

    /// Makes record `s` (in range) a new vertex for `node`, as [`Vertices::push`] makes one.
    pub fn fill(&mut self, s: usize, node: u32, flags: u8) {
        self.node[s] = node;
        self.fan[s] = I::store(NIL);
        self.degree[s] = 0;
        self.mate[s] = I::store(NIL);
        self.tag[s] = u16::MAX;
        self.flags[s] = flags;
    }

    /// Copies record `from` over record `to`.
    pub fn copy(&mut self, from: usize, to: usize) {
        self.node[to] = self.node[from];
        self.fan[to] = self.fan[from];
        self.degree[to] = self.degree[from];
        self.mate[to] = self.mate[from];
        self.tag[to] = self.tag[from];
        self.flags[to] = self.flags[from];
        self.digest[to] = self.digest[from];
    }

    /// Drops the last record.
    pub fn pop(&mut self) {
        self.len = self.len.saturating_sub(1);
    }

    /// Exchanges records `a` and `b` (both in range), references to them unchanged.
    pub fn swap(&mut self, a: usize, b: usize) {
        self.node.swap(a, b);
        self.fan.swap(a, b);
        self.degree.swap(a, b);
        self.mate.swap(a, b);
        self.tag.swap(a, b);
        self.flags.swap(a, b);
        self.digest.swap(a, b);
    }

    /// Moves every record `s` to `to[s]` (a permutation of the active records) through the free
    /// records after them; `false`, with nothing moved, when fewer are free than active.
    pub fn scatter(&mut self, to: &[I]) -> bool {
        if to.len() != self.len() || 2 * self.len() > V {
            return false;
        }
        scatter(&mut self.node, to);
        scatter(&mut self.fan, to);
        scatter(&mut self.degree, to);
        scatter(&mut self.mate, to);
        scatter(&mut self.tag, to);
        scatter(&mut self.flags, to);
        scatter(&mut self.digest, to);
        true
    }

    /// Renumbers every record's mate by `vertex`.
    pub fn renumber_mates(&mut self, vertex: impl Fn(u32) -> u32) {
        let n = self.len();
        for m in &mut self.mate[..n] {
            *m = I::store(vertex(m.load()));
        }
    }

    /// The active records' fan entries, to be set anew.
    pub fn fans_mut(&mut self) -> &mut [I] {
        &mut self.fan[..self.len as usize]
    }
}

/// The triangle records.
#[derive(Clone, Debug)]
pub(crate) struct Triangles<const F: usize, I: SlotIndex> {
    len: u32,
    corners: [[I; 3]; F],
    adj: [[I; 3]; F],
    /// Triangle ids in the hierarchy's numbering.
    pub id: [u32; F],
}

impl<const F: usize, I: SlotIndex> Triangles<F, I> {
    pub const fn new() -> Self {
        Triangles {
            len: 0,
            corners: [[I::ZERO; 3]; F],
            adj: [[I::ZERO; 3]; F],
            id: [0; F],
        }
    }

    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The corner records, as the rasterizer reads them.
    #[inline(always)]
    pub fn corners(&self) -> &[[I; 3]] {
        &self.corners[..self.len as usize]
    }

    /// Triangle `f`'s corners (`None` out of range).
    #[inline(always)]
    pub fn get(&self, f: u32) -> Option<[u32; 3]> {
        (f < self.len).then(|| load3(self.corners[f as usize]))
    }

    /// Triangle `f`'s corners (`f` in range).
    #[inline(always)]
    pub fn at(&self, f: u32) -> [u32; 3] {
        load3(self.corners[f as usize])
    }

    #[inline(always)]
    pub fn set_corner(&mut self, f: u32, k: usize, v: u32) {
        self.corners[f as usize][k] = I::store(v);
    }

    /// Which corner of triangle `f` is vertex slot `v` (`None` when `f` is out of range or `v`
    /// is not a corner; `v` a vertex slot or `NIL`; the first when it is several): compared in
    /// the stored form, so nothing is widened, and computed ([`first_of`]).
    #[inline(always)]
    pub fn corner_of(&self, f: u32, v: u32) -> Option<usize> {
        let t = self.corners[..self.len as usize].get(f as usize)?;
        let v = I::store(v);
        first_of(|k| t[k] == v)
    }

    /// Corner `k` of triangle `f` alone (`f` in range).
    #[inline(always)]
    pub fn corner_at(&self, f: u32, k: usize) -> u32 {
        self.corners[f as usize][k].load()
    }

    /// Whether corner `k` of triangle `f` (in range) is `v` (a vertex slot or `NIL`), compared
    /// in the stored form, so nothing is widened.
    #[inline(always)]
    pub fn corner_is(&self, f: u32, k: usize, v: u32) -> bool {
        self.corners[f as usize][k] == I::store(v)
    }

    /// Whether `adj(f)[k]` (`f` in range) is `g` (a triangle slot or `NIL`), compared in the
    /// stored form.
    #[inline(always)]
    pub fn adj_is(&self, f: u32, k: usize, g: u32) -> bool {
        self.adj[f as usize][k] == I::store(g)
    }

    /// `adj(f)[k]`: the triangle across edge `t[k] -> t[k + 1]`, or `NIL`.
    #[inline(always)]
    pub fn adj(&self, f: u32) -> [u32; 3] {
        load3(self.adj[f as usize])
    }

    #[inline(always)]
    pub fn set_adj(&mut self, f: u32, k: usize, g: u32) {
        self.adj[f as usize][k] = I::store(g);
    }

    /// Makes triangle `f` (in range) name `to` wherever it names neighbour `from`: all three
    /// written, picked without branches (which edge it is follows no pattern a branch
    /// predictor learns).
    #[inline(always)]
    pub fn replace_adj(&mut self, f: u32, from: u32, to: u32) {
        let (from, to) = (I::store(from), I::store(to));
        for g in &mut self.adj[f as usize] {
            *g = select_unpredictable(*g == from, to, *g);
        }
    }

    /// Appends a triangle; its slot, or `None` when full.
    pub fn push(&mut self, corners: [u32; 3], adj: [u32; 3], id: u32) -> Option<u32> {
        let f = self.len as usize;
        if f >= F {
            return None;
        }
        self.corners[f] = store3(corners);
        self.adj[f] = store3(adj);
        self.id[f] = id;
        self.len += 1;
        Some(f as u32)
    }

    /// Copies record `from` over record `to`.
    pub fn copy(&mut self, from: u32, to: u32) {
        let (from, to) = (from as usize, to as usize);
        self.corners[to] = self.corners[from];
        self.adj[to] = self.adj[from];
        self.id[to] = self.id[from];
    }

    pub fn pop(&mut self) {
        self.len = self.len.saturating_sub(1);
    }

    /// The triangle after `f` going counter-clockwise around vertex `v` (`NIL` at a border;
    /// `None` when `f` is not a triangle of `v`).
    ///
    /// The three neighbours are read before the corner is known: their load then overlaps the
    /// corners' (both miss together on a cold fan), where reading the one neighbour would wait
    /// for the corner the comparisons give.
    #[inline]
    pub fn ccw(&self, f: u32, v: u32) -> Option<u32> {
        self.ccw_at(f, v).map(|(_, g)| g)
    }

    /// The triangle before `f` going counter-clockwise around `v` (as [`Triangles::ccw`]).
    #[inline]
    pub fn cw(&self, f: u32, v: u32) -> Option<u32> {
        self.cw_at(f, v).map(|(_, g)| g)
    }

    /// [`Triangles::ccw`], and the corner `v` takes in `f`.
    #[inline(always)]
    pub fn ccw_at(&self, f: u32, v: u32) -> Option<(usize, u32)> {
        // Bounded by the length, as `corner_of` is: one test serves both.
        let adj = *self.adj[..self.len as usize].get(f as usize)?;
        let k = self.corner_of(f, v)?;
        // `adj[prev3(k)]`.
        Some((k, pick([adj[2], adj[0], adj[1]], k).load()))
    }

    /// [`Triangles::cw`], and the corner `v` takes in `f`.
    #[inline(always)]
    pub fn cw_at(&self, f: u32, v: u32) -> Option<(usize, u32)> {
        let adj = *self.adj[..self.len as usize].get(f as usize)?;
        let k = self.corner_of(f, v)?;
        Some((k, pick(adj, k).load()))
    }

    /// Exchanges records `f` and `g` (both in range), references to them unchanged.
    pub fn swap(&mut self, f: usize, g: usize) {
        self.corners.swap(f, g);
        self.adj.swap(f, g);
        self.id.swap(f, g);
    }

    /// Moves every record `f` to `to[f]` as [`Vertices::scatter`] does.
    pub fn scatter(&mut self, to: &[I]) -> bool {
        if to.len() != self.len() || 2 * self.len() > F {
            return false;
        }
        scatter(&mut self.corners, to);
        scatter(&mut self.adj, to);
        scatter(&mut self.id, to);
        true
    }

    /// Renumbers every record's corners by `vertex`.
    pub fn renumber_corners(&mut self, vertex: impl Fn(u32) -> u32) {
        let n = self.len();
        for c in self.corners[..n].iter_mut().flatten() {
            *c = I::store(vertex(c.load()));
        }
    }

    /// Renumbers every record's neighbours by `triangle`.
    pub fn renumber_neighbours(&mut self, triangle: impl Fn(u32) -> u32) {
        let n = self.len();
        for a in self.adj[..n].iter_mut().flatten() {
            *a = I::store(triangle(a.load()));
        }
    }
}

/// Eight bytes of 0 or 1 as eight bits, byte `i` to bit `i`, by one multiplication (byte `i`
/// lands on bit `56 + i`, and no two products share a bit).
#[inline(always)]
fn gathered(bytes: u64) -> usize {
    (bytes.wrapping_mul(0x0102_0408_1020_4080) >> 56) as usize
}

/// [`Vertices::settled_until`] of a whole word (`usize::BITS` slots) while the counts run, on
/// targets with vectors: a settled tag fits 16 bits (an expiry below `2 REBASE - 1` and the
/// count's bit), and so do both thresholds (not `u32::MAX` counts, a frame that trusts no
/// mark), so the expiries are tested as lanes of 16 bits, which the compiler vectorizes, and
/// their answers gathered by a transposition. `None` when it does not apply.
#[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
#[inline(always)]
fn settled_word(flags: &[u8], tags: &[u16], now: [u32; 2]) -> Option<usize> {
    let count = flags.len();
    let thresholds = [now[0], TURNING.saturating_add(now[1])].map(u16::try_from);
    let ([Ok(t0), Ok(t1)], true) = (thresholds, count == usize::BITS as usize) else {
        return None;
    };
    let d = t0 ^ t1;
    let mut lanes = [0u8; 64];
    // Slot `8c + j`'s answer is bit `c` of its byte, so that the eight chunks of bytes stack
    // into one word by `|` (slot `8c + j` at bit `c` of byte `j`), which a transposition moves
    // to bit `8c + j`: a few shifts, where gathering chunk by chunk took multiplications the
    // compiler vectorized poorly.
    for (k, ((l, &f), &t)) in lanes.iter_mut().zip(flags).zip(tags).enumerate() {
        // `lives` in 16 bits (as `lives` on 32-bit lanes, the frame takes 0.5% more).
        let threshold = t0 ^ (d & (t >> 15).wrapping_neg());
        *l = (((f >> SETTLED.trailing_zeros()) & 1) & u8::from(t >= threshold)) << (k / 8);
    }
    let mut stacked = 0u64;
    for chunk in lanes[..count].chunks_exact(8) {
        stacked |= u64::from_le_bytes(core::array::from_fn(|k| chunk[k]));
    }
    Some(transposed(stacked) as usize)
}

/// The transpose of the 8x8 bit matrix whose row `r` is byte `r` of `x` (column `c` its bit
/// `c`): bit `8r + c` moves to bit `8c + r`, by three exchanges of bit blocks (the method of
/// Henry S. Warren, Jr., *Hacker's Delight*, 2nd ed., 2012, section 7-3, "Transposing a Bit
/// Matrix").
#[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
#[inline(always)]
fn transposed(mut x: u64) -> u64 {
    let t = (x ^ (x >> 7)) & 0x00aa_00aa_00aa_00aa;
    x ^= t ^ (t << 7);
    let t = (x ^ (x >> 14)) & 0x0000_cccc_0000_cccc;
    x ^= t ^ (t << 14);
    let t = (x ^ (x >> 28)) & 0x0000_0000_f0f0_f0f0;
    x ^ t ^ (t << 28)
}

/// Without vectors (a Cortex-M) lanes of 16 bits cost more than the byte test of
/// [`Vertices::settled_until`]: never applies.
#[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
#[inline(always)]
fn settled_word(_: &[u8], _: &[u16], _: [u32; 2]) -> Option<usize> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The word-at-a-time settled bits are the per-slot test, for every start and length,
    /// whatever the other flags and the expiries.
    #[test]
    fn settled_bits_are_each_slots_own_test() {
        let mut v = Vertices::<200, u16>::new();
        let mut x = 0x9E37_79B9u32;
        let mut random = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        for s in 0..200 {
            v.push(s, random() as u8);
            if random() % 3 != 0 {
                // On either count.
                let count = if random() % 2 == 0 { TURNING } else { 0 };
                // Mostly near the counts below, some anywhere a count's expiry can be.
                let until = if random() % 4 == 0 {
                    random() % 0x7FFF
                } else {
                    random() % 400
                };
                v.mark(s as usize, Mark::Settled(count | until));
            }
        }
        for first in 0..70 {
            for count in 0..=(usize::BITS as usize).min(200 - first) {
                // Counts whose thresholds fit 16 bits (the whole word's vector test) and ones
                // that do not (a frame that trusts no mark, a turning threshold past 16 bits).
                for now in [
                    [0, 0],
                    [1, 150],
                    [150, 1],
                    [399, 400],
                    [400, 399],
                    [0x7FFE, 0x7FFF],
                    [20_000, 30_000],
                    [3, 0x8000],
                    [70_000, 5],
                    [u32::MAX, u32::MAX],
                ] {
                    let mut want = 0usize;
                    for k in 0..count {
                        let s = first + k;
                        let settled = v.flags[s] & SETTLED != 0 && lives(v.expiry(s), now);
                        want |= usize::from(settled) << k;
                    }
                    assert_eq!(
                        v.settled_until(first, count, now),
                        want,
                        "{first} {count} {now:?}"
                    );
                }
            }
        }
    }
}
