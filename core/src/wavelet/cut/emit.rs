//! The emitted mesh of a wavelet cut, kept across frames and emitted again only where the
//! wavelets changed.
//!
//! Emission (Azuma et al. 2003, §3.6) walks every base triangle down while one of its edge
//! midpoints is in the set and cuts each leaf at the present midpoints of its edges. Doing that
//! for the whole mesh in every frame that changes makes a frame's work follow the mesh's size,
//! not the change. So the mesh is kept between frames:
//!
//! - **Tiles.** The triangles of the lattice level `d` (two levels above the finest, or coarser
//!   so that there are at most as many as queue entries) are tiles, numbered base face by base
//!   face in the order of the recursion's children, so the tiles under any coarser lattice
//!   triangle are one run of numbers. Each emitted triangle belongs to one tile: the one it lies
//!   in, or, for a leaf coarser than the tiles, its first tile (the leaf's first child's first
//!   child...). A tile lists its triangles, linked through the triangle slots; a triangle moved
//!   into a freed slot finds its predecessor by walking its tile, which is small.
//! - **Dirty runs.** When a wavelet comes, goes or blends, the lattice triangles whose emission
//!   or vertex positions can change are the two around its parent edge (their subdivision, and
//!   the wavelet's position and its dependents' inside them) and the neighbours across an edge
//!   whose midpoint appeared or vanished (their T-vertex cuts). Each is marked as a run of
//!   tiles: all tiles under it when it is in the recursion, else the first tile of the coarser
//!   leaf that holds it. Only those runs are released and emitted again, and a frame that
//!   changed nothing emits nothing. A frame with more runs than half the tiles emits the whole
//!   mesh and stops marking.
//! - **Vertex slots that outlive a frame.** A slot counts the triangles that use it; one that
//!   drops to none is freed at the end of the frame (it may be taken up again first) and its
//!   slot reused, so a clean tile's triangles keep pointing at their vertices. A slot freed is a
//!   hole ([`super::WaveletCut::vertex_id`] is `u32::MAX`) until reused; when holes pass half
//!   the live vertices, when most tiles are dirty, when the id map wants another size, or when
//!   a partial emission does not fit the arenas, the whole mesh is emitted again from scratch
//!   (the same triangles and positions, so the frames are the same).
//!
//! Positions follow `rho_t`: a vertex's position depends on its own wavelet's state and on the
//! drawn ends of its parent edge, so it can change only inside the star of a wavelet that came,
//! went or blended, which lies inside the two triangles around that wavelet's parent edge. Those
//! are marked, and a dirty run recomputes every slot it touches, parents before children.

use crate::cut::slot::SlotIndex;
use crate::cut::NIL;
use crate::nodemap::NodeMap;

use super::super::format::SemiRegularView;
use super::super::lattice::Point;
use super::{Full, WaveletCut, INSIDE};

/// A slot's use count's flag: the slot is on the list of slots to free if still unused.
pub(super) const PENDING: u16 = 0x8000;

/// A slot's use count's flag: its position is not its own (a geomorph moves it or an end of its
/// parent edge).
pub(super) const MOVED: u16 = 0x4000;

/// The use count under the flags.
pub(super) const USES: u16 = MOVED - 1;

/// A triangle slot's tile when it is spare.
const SPARE: u16 = u16::MAX;

/// The most tiles: a triangle's tile is a `u16` ([`SPARE`] aside), and a dirty run is its first
/// tile and the base-4 logarithm of its length in one `u32`.
const MAX_TILES: u32 = SPARE as u32;

/// `4^k` tiles under a lattice triangle `k` levels above the tiles.
#[inline]
fn tiles_under(k: u32) -> u32 {
    1u32.checked_shl(2 * k).unwrap_or(0)
}

/// `a + b + c`, weights summed in `a`'s frame: three times the centroid of a lattice triangle.
#[inline]
fn sum3(a: Point, b: Point, c: Point) -> Point {
    Point {
        face: a.face,
        w: [0, 1, 2].map(|k| a.w[k] + b.w[k] + c.w[k]),
    }
}

/// The four child triangles of the lattice triangle `p` in the recursion's order, with
/// midpoints `m` (of edges `p0 p1`, `p1 p2`, `p2 p0`).
#[inline]
fn quarters<X: Copy>(p: [X; 3], m: [X; 3]) -> [[X; 3]; 4] {
    [
        [p[0], m[0], m[2]],
        [m[0], p[1], m[1]],
        [m[2], m[1], p[2]],
        [m[0], m[1], m[2]],
    ]
}

/// The corners, counter-clockwise, of the lattice triangle of step `h` whose weights sum to
/// `q` (three times its centroid) in a face of `n` steps a side.
fn corners_of(q: Point, h: i32, n: i32) -> [Point; 3] {
    let h = h.max(1);
    let f = q.w.map(|x| x.div_euclid(3 * h) * h);
    let at = |w| Point { face: q.face, w };
    if f[0] + f[1] + f[2] == n - h {
        // Pointing like the base face: the floors plus a step along each weight.
        [
            at([f[0] + h, f[1], f[2]]),
            at([f[0], f[1] + h, f[2]]),
            at([f[0], f[1], f[2] + h]),
        ]
    } else {
        // Upside down (a middle child): the ceilings less a step along each weight.
        let u = f.map(|x| x + h);
        [
            at([u[0], u[1], u[2] - h]),
            at([u[0] - h, u[1], u[2]]),
            at([u[0], u[1] - h, u[2]]),
        ]
    }
}

/// Whether lattice triangle `t` holds the point whose weights are three times `q`'s.
#[inline]
fn holds(t: &[Point; 3], q: Point) -> bool {
    (0..3).all(|i| {
        let lo = t[0].w[i].min(t[1].w[i]).min(t[2].w[i]);
        let hi = t[0].w[i].max(t[1].w[i]).max(t[2].w[i]);
        3 * lo <= q.w[i] && q.w[i] <= 3 * hi
    })
}

impl<const WORDS: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex>
    WaveletCut<WORDS, T, V, Q, I>
{
    /// The most tiles this cut holds: one per queue entry (so at least eight triangles of
    /// capacity per tile with `Q = T / 8`), at most [`MAX_TILES`].
    pub(super) const TILES: u32 = if Q < MAX_TILES as usize {
        Q as u32
    } else {
        MAX_TILES
    };

    /// The tile level for a mesh of `faces` base faces and `levels` levels: two above the
    /// finest, or coarser until the tiles fit [`Self::TILES`] (`None` when the base faces
    /// alone do not).
    pub(super) fn tile_level_for(faces: u32, levels: u32) -> Option<u32> {
        if faces > Self::TILES {
            return None;
        }
        let mut d = levels.saturating_sub(2);
        while d > 0 && u64::from(faces) << (2 * d) > u64::from(Self::TILES) {
            d -= 1;
        }
        Some(d)
    }

    /// Marks the lattice triangle whose weights sum to `sum` (three times its centroid, in a
    /// frame at most one face away) at level `level` (see [`Self::mark_at`]).
    fn mark(&mut self, s: &SemiRegularView<'_>, sum: Point, level: u32) {
        if let Some(q) = s.canonical_scaled(sum, 3 * s.steps()) {
            self.mark_at(s, q, level);
        } // else across a border: no triangle
    }

    /// Marks the lattice triangle whose weights sum to `q` in its own face at level `level`:
    /// the tiles under it when it is in the recursion, else the first tile of the leaf that
    /// holds it.
    fn mark_at(&mut self, s: &SemiRegularView<'_>, q: Point, level: u32) {
        let n = s.steps();
        let d = self.tile_level;
        let mut t = [[n, 0, 0], [0, n, 0], [0, 0, n]].map(|w| Point { face: q.face, w });
        let mut at = q.face.saturating_mul(tiles_under(d));
        for l in 0..level.min(d) {
            // Subdivided when a midpoint is in (ids read lazily: the descent needs no slots).
            let m = [t[0].mid(t[1]), t[1].mid(t[2]), t[2].mid(t[0])];
            if !m
                .iter()
                .any(|&x| s.vertex_id(x).is_some_and(|id| self.includes(id)))
            {
                return self.mark_run(at, 0);
            }
            let Some(c) = quarters(t, m).iter().position(|c| holds(c, q)) else {
                return self.mark_run(at, 0);
            };
            at += c as u32 * tiles_under(d - l - 1);
            t = quarters(t, m)[c];
        }
        self.mark_run(at, d.saturating_sub(level));
    }

    /// Adds the run of `4^up` tiles from `first` to the dirty list (the whole mesh when full),
    /// as one number that sorts by first tile, then longest first.
    fn mark_run(&mut self, first: u32, up: u32) {
        let run = first << 4 | (15 - up.min(15));
        if self.dirty.last() == Some(&run) {
            return;
        }
        // A full list, or more runs than half the tiles: the frame emits the whole mesh.
        if self.dirty.push(run).is_err() || self.dirty.len() as u32 > self.tiles / 2 {
            self.built = false;
        }
    }

    /// Marks what wavelet `p` (at `level`) coming, going or blending changes: the two triangles
    /// around its parent edge, and the neighbours across their edges whose midpoints are in
    /// `changed` (those that appeared or vanished).
    pub(super) fn mark_wavelet(
        &mut self,
        s: &SemiRegularView<'_>,
        p: Point,
        level: u32,
        changed: &[u32],
    ) {
        if level == 0 || !self.built {
            return; // the whole mesh is emitted this frame anyway
        }
        let [x, y] = s.parent_edge(p, level);
        let up = level - 1;
        let n = s.steps();
        for sum in [sum3(x, y, x.left_of(y)), sum3(y, x, x.right_of(y))] {
            let Some(q) = s.canonical_scaled(sum, 3 * n) else {
                continue; // across a border
            };
            self.mark_at(s, q, up);
            if changed.is_empty() {
                continue;
            }
            // In the triangle's own frame its neighbours are at most one face away; the one
            // across edge `a -> b` of a counter-clockwise triangle is `b, a, ...`.
            let c = corners_of(q, s.step_of(up), n);
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                let mid = s.canonical(a.mid(b)).and_then(|m| s.vertex_id(m));
                if mid.is_some_and(|id| changed.contains(&id)) {
                    self.mark(s, sum3(b, a, a.right_of(b)), up);
                }
            }
        }
    }

    /// Marks what wavelet `id`'s weight changing moves (see [`Self::mark_wavelet`]).
    pub(super) fn mark_blend(&mut self, s: &SemiRegularView<'_>, id: u32) {
        if let Some(p) = s.point(id) {
            self.mark_wavelet(s, p, s.level(p), &[]);
        }
    }

    /// Brings the emitted mesh up to date with the set and the geomorphs: the dirty runs again,
    /// or the whole mesh (see the module doc); `false` when an arena filled up (the mesh is then
    /// incomplete, which the budget's admission prevents).
    pub(super) fn emit(&mut self, s: &SemiRegularView<'_>) -> bool {
        if self.built && self.dirty.len() == 0 {
            return true;
        }
        let live = self.vertices as usize;
        let holes = self.freed as usize;
        if !self.built || self.whole || holes > live / 2 + 64 || self.map.should_resize(live) {
            return self.emit_all(s);
        }
        // Runs are aligned subtrees: sorted by start, longest first, each is inside the one
        // kept before it or apart from it.
        let run = |x: u32| (x >> 4, tiles_under(15 - (x & 15)));
        self.dirty.as_mut_slice().sort_unstable();
        let mut covered = 0u64;
        let mut end = 0u32;
        for &x in self.dirty.as_slice() {
            let (first, len) = run(x);
            if first >= end {
                covered += u64::from(len);
                end = first.saturating_add(len);
            }
        }
        if covered * 2 >= u64::from(self.tiles) {
            return self.emit_all(s);
        }
        let mut end = 0u32;
        for i in 0..self.dirty.len() {
            let (first, len) = run(self.dirty.as_slice()[i]);
            if first < end {
                continue;
            }
            end = first.saturating_add(len);
            for tile in first..end.min(self.tiles) {
                self.release(tile);
            }
            if self.emit_run(s, first, len).is_err() {
                return self.emit_all(s);
            }
        }
        self.drop_spares();
        self.free_unused();
        self.dirty.clear();
        true
    }

    /// Emits the whole mesh from scratch.
    fn emit_all(&mut self, s: &SemiRegularView<'_>) -> bool {
        self.ids.clear();
        self.tris.clear();
        self.head[..self.tiles as usize]
            .iter_mut()
            .for_each(|h| *h = I::store(NIL));
        (self.free, self.pending, self.spare, self.freed) = (NIL, NIL, NIL, 0);
        self.dirty.clear();
        self.map
            .reset(NodeMap::<T, I>::span_for(self.vertices as usize));
        let per_face = tiles_under(self.tile_level);
        self.all = true;
        for f in 0..self.base_faces {
            if self.emit_run(s, f * per_face, per_face).is_err() {
                self.all = false;
                self.built = false;
                return false;
            }
        }
        self.all = false;
        self.free_unused();
        self.built = true;
        true
    }

    /// Emits the lattice triangle whose tiles are the `len` from `first` (an aligned run): its
    /// subtree when it is in the recursion; when a coarser leaf holds it, that leaf's pieces if
    /// they belong to `first`, else nothing.
    fn emit_run(&mut self, s: &SemiRegularView<'_>, first: u32, len: u32) -> Result<(), Full> {
        let d = self.tile_level;
        let per_face = tiles_under(d);
        let face = first / per_face.max(1);
        let n = s.steps();
        let mut p = [[n, 0, 0], [0, n, 0], [0, 0, n]].map(|w| Point { face, w });
        let mut v = [0u32; 3];
        for k in 0..3 {
            v[k] = self.slot(s, p[k], [NIL; 2])?;
        }
        let mut at = face * per_face;
        let mut level = 0;
        while tiles_under(d - level) > len {
            let Some((m, ids)) = self.subdivision(s, &p) else {
                // A leaf coarser than the run: its pieces belong to its first tile.
                return if at == first {
                    self.emit_piece(s, p, v, [level; 3], at)
                } else {
                    Ok(())
                };
            };
            let mv = self.midpoint_slots(s, m, ids, v)?;
            let below = tiles_under(d - level - 1);
            let c = ((first - at) / below).min(3) as usize;
            at += c as u32 * below;
            p = quarters(p, m)[c];
            v = quarters(v, mv)[c];
            level += 1;
        }
        self.emit_triangle(s, p, v, level, first)
    }

    /// Frees the triangles of tile `tile`: their slots go on the spare list, their vertices
    /// lose a use each.
    fn release(&mut self, tile: u32) {
        let Some(h) = self.head.get_mut(tile as usize) else {
            return;
        };
        let mut x = h.load();
        *h = I::store(NIL);
        while x != NIL {
            let i = x as usize;
            let next = self.next[i].load();
            for c in self.tris.as_slice()[i] {
                self.unuse(c.load());
            }
            self.owner[i] = SPARE;
            self.next[i] = I::store(self.spare);
            self.spare = x;
            x = next;
        }
    }

    /// One use fewer of vertex slot `v`; unused, it goes on the list of slots to free.
    fn unuse(&mut self, v: u32) {
        let i = v as usize;
        let u = self.uses[i];
        self.uses[i] = if u & USES > 0 { u - 1 } else { u };
        if u & (PENDING | USES) == 1 {
            self.uses[i] |= PENDING;
            self.link[i] = I::store(self.pending);
            self.pending = v;
        }
    }

    /// Frees the slots on the pending list that are still unused.
    fn free_unused(&mut self) {
        let mut x = self.pending;
        self.pending = NIL;
        while x != NIL {
            let i = x as usize;
            let next = self.link[i].load();
            self.uses[i] &= !PENDING;
            if self.uses[i] & USES == 0 {
                let id = self.ids.as_slice()[i];
                self.map.remove(id, self.ids.as_slice());
                self.ids.as_mut_slice()[i] = NIL;
                self.link[i] = I::store(self.free);
                self.free = x;
                self.freed += 1;
            }
            x = next;
        }
    }

    /// Closes the holes the spare triangle slots left by moving the last triangles into them
    /// (a moved triangle's tile list is walked to its predecessor: tiles are small).
    fn drop_spares(&mut self) {
        let mut x = self.spare;
        self.spare = NIL;
        while x != NIL {
            let next = self.next[x as usize].load();
            while let Some(last) = self.tris.len().checked_sub(1) {
                if self.owner[last] != SPARE {
                    break;
                }
                self.tris.pop();
            }
            // The last triangle is not spare, so a spare slot before it is not the last.
            if (x as usize) < self.tris.len() {
                self.move_triangle(self.tris.len() - 1, x as usize);
            }
            x = next;
        }
    }

    /// Moves the triangle in slot `from` (the last) into the spare slot `to`.
    fn move_triangle(&mut self, from: usize, to: usize) {
        let t = self.tris.as_slice()[from];
        self.tris.as_mut_slice()[to] = t;
        let (next, owner) = (self.next[from], self.owner[from]);
        (self.next[to], self.owner[to]) = (next, owner);
        let to_i = I::store(to as u32);
        if let Some(h) = self.head.get_mut(usize::from(owner)) {
            if h.index() == from {
                *h = to_i;
            } else {
                let mut x = h.index();
                while x < self.tris.len() && self.next[x].index() != from {
                    x = self.next[x].index();
                }
                if x < self.tris.len() {
                    self.next[x] = to_i;
                }
            }
        }
        self.tris.pop();
    }

    /// Adds triangle `v` to tile `tile`'s list.
    fn push_triangle(&mut self, v: [u32; 3], tile: u32) -> Result<(), Full> {
        let h = self.head.get(tile as usize).ok_or(Full)?.load();
        if v.iter().any(|&c| self.uses[c as usize] & USES == USES) {
            return Err(Full);
        }
        let t = [I::store(v[0]), I::store(v[1]), I::store(v[2])];
        let slot = if self.spare != NIL {
            let x = self.spare;
            self.spare = self.next[x as usize].load();
            self.tris.as_mut_slice()[x as usize] = t;
            x
        } else {
            self.tris.push(t).map_err(|_| Full)?
        };
        for c in v {
            self.uses[c as usize] += 1;
        }
        let i = slot as usize;
        (self.owner[i], self.next[i]) = (tile as u16, I::store(h));
        self.head[tile as usize] = I::store(slot);
        Ok(())
    }

    /// The vertex slot of point `p`, added if new: at its own position when it is a base vertex
    /// or a member, else at the midpoint of the slots `ends` (its parent edge).
    fn slot(&mut self, s: &SemiRegularView<'_>, p: Point, ends: [u32; 2]) -> Result<u32, Full> {
        let id = s.canonical(p).and_then(|q| s.vertex_id(q)).ok_or(Full)?;
        self.slot_of(s, (id, p), ends)
    }

    /// [`Self::slot`] of vertex `id` at point `p` (in any frame holding it); an existing slot
    /// has its position computed again, unless the whole mesh is being emitted (then it was
    /// placed in this pass).
    fn slot_of(
        &mut self,
        s: &SemiRegularView<'_>,
        (id, p): (u32, Point),
        ends: [u32; 2],
    ) -> Result<u32, Full> {
        let found = self.map.get(id, self.ids.as_slice());
        if let (Some(slot), true) = (found, self.all) {
            // Emitting everything, every slot is new and placed once.
            return Ok(slot);
        }
        let end = |k: usize| ends[k] as usize;
        let ends_moved = ends[0] != NIL && (self.uses[end(0)] | self.uses[end(1)]) & MOVED != 0;
        let at_own =
            id < self.base_vertices || (self.includes(id) && !ends_moved && !self.morphing_bit(id));
        let (position, moved) = if at_own {
            (s.position_at(p, id), false)
        } else {
            // rho_t at this vertex: the midpoint of its parent edge as drawn, plus its
            // coefficient (its own position minus its parent edge's midpoint) scaled by its
            // weight (0 when it is not in the mesh).
            let a = self.position(end(0));
            let b = self.position(end(1));
            let w = if self.includes(id) {
                self.weight(id)
            } else {
                0.0
            };
            let mut at = [0, 1, 2].map(|k| (a[k] + b[k]) * 0.5);
            if w > 0.0 {
                let (own, x, y) = (
                    s.position_at(p, id),
                    s.position(self.vertex_id(end(0))),
                    s.position(self.vertex_id(end(1))),
                );
                for k in 0..3 {
                    at[k] += w * (own[k] - (x[k] + y[k]) * 0.5);
                }
            }
            (at, true)
        };
        let slot = match found {
            Some(slot) => slot,
            None => self.new_slot(id)?,
        };
        let i = slot as usize;
        self.positions[i] = position;
        self.uses[i] = self.uses[i] & !MOVED | if moved { MOVED } else { 0 };
        Ok(slot)
    }

    /// A slot for vertex `id`: a freed one or a new one, unused (so on the pending list, unless
    /// the whole mesh is being emitted).
    fn new_slot(&mut self, id: u32) -> Result<u32, Full> {
        let slot = if self.free != NIL {
            let x = self.free;
            self.free = self.link[x as usize].load();
            self.freed -= 1;
            self.ids.as_mut_slice()[x as usize] = id;
            x
        } else {
            self.ids.push(id).map_err(|_| Full)?
        };
        let i = slot as usize;
        if self.all {
            // Emitting everything, every slot made is used.
            self.uses[i] = 0;
        } else {
            self.uses[i] = PENDING;
            self.link[i] = I::store(self.pending);
            self.pending = slot;
        }
        if !self.map.insert(slot, self.ids.as_slice()) {
            return Err(Full);
        }
        Ok(slot)
    }

    /// The edge midpoints of lattice triangle `p` (of `p0 p1`, `p1 p2`, `p2 p0`: inside its
    /// face, so their ids need no unfolding) and their vertex ids, when one of them is in the
    /// set (the triangle is subdivided); `None` for a leaf.
    #[inline(always)]
    fn subdivision(
        &self,
        s: &SemiRegularView<'_>,
        p: &[Point; 3],
    ) -> Option<([Point; 3], [Option<u32>; 3])> {
        let m = [p[0].mid(p[1]), p[1].mid(p[2]), p[2].mid(p[0])];
        let ids = m.map(|q| s.vertex_id(q));
        ids.iter()
            .any(|&id| id.is_some_and(|id| self.includes(id)))
            .then_some((m, ids))
    }

    /// The vertex slots of a subdivided triangle's midpoints `m` (ids `ids`, from
    /// [`Self::subdivision`]), each placed on its edge between the corner slots `v`.
    #[inline]
    fn midpoint_slots(
        &mut self,
        s: &SemiRegularView<'_>,
        m: [Point; 3],
        ids: [Option<u32>; 3],
        v: [u32; 3],
    ) -> Result<[u32; 3], Full> {
        let mut mv = [0; 3];
        for k in 0..3 {
            let id = ids[k].ok_or(Full)?;
            mv[k] = self.slot_of(s, (id, m[k]), [v[k], v[(k + 1) % 3]])?;
        }
        Ok(mv)
    }

    /// Emits the triangle `p` (vertex slots `v`) of level `level`, whose first tile is `tile`:
    /// its four children when it is subdivided, else itself, cut where its neighbours are
    /// finer.
    fn emit_triangle(
        &mut self,
        s: &SemiRegularView<'_>,
        p: [Point; 3],
        v: [u32; 3],
        level: u32,
        tile: u32,
    ) -> Result<(), Full> {
        let split = (level < self.levels)
            .then(|| self.subdivision(s, &p))
            .flatten();
        let Some((m, ids)) = split else {
            return self.emit_piece(s, p, v, [level; 3], tile);
        };
        let mv = self.midpoint_slots(s, m, ids, v)?;
        let below = if level < self.tile_level {
            tiles_under(self.tile_level - level - 1)
        } else {
            0
        };
        let (ps, vs) = (quarters(p, m), quarters(v, mv));
        for c in 0..4 {
            self.emit_triangle(s, ps[c], vs[c], level + 1, tile + c as u32 * below)?;
        }
        Ok(())
    }

    /// Emits a piece of a leaf triangle whose edges are at `levels` (edge `k` from corner `k`;
    /// [`INSIDE`] for a cut inside the leaf) into tile `tile`: halved at the midpoint of the
    /// first edge whose neighbour across is subdivided (the paper's T-vertex removal, Fig. 7),
    /// else as it is.
    fn emit_piece(
        &mut self,
        s: &SemiRegularView<'_>,
        p: [Point; 3],
        v: [u32; 3],
        levels: [u32; 3],
        tile: u32,
    ) -> Result<(), Full> {
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            if levels[i] >= self.levels {
                continue;
            }
            let (a, b) = (p[i], p[j]);
            // The leaf is not subdivided, so the midpoint of this edge is a vertex of the mesh
            // exactly when the triangle across is subdivided.
            let m = a.mid(b);
            let Some(mid) = s.canonical(m).and_then(|q| s.vertex_id(q)) else {
                continue;
            };
            if !self.is_present(mid) {
                continue;
            }
            let mv = self.slot_of(s, (mid, m), [v[i], v[j]])?;
            let finer = levels[i] + 1;
            self.emit_piece(
                s,
                [a, m, p[k]],
                [v[i], mv, v[k]],
                [finer, INSIDE, levels[k]],
                tile,
            )?;
            return self.emit_piece(
                s,
                [m, b, p[k]],
                [mv, v[j], v[k]],
                [finer, levels[j], INSIDE],
                tile,
            );
        }
        self.push_triangle(v, tile)
    }
}
