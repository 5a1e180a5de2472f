//! The edge-collapse engine: a mutable triangle mesh, legality tests, and a heap of costs.
//!
//! Each collapse of an edge `a-b` creates a *new* vertex `p` (the merge-tree paper's renaming,
//! §3.2), so every vertex id names one position for ever and the collapses form a forest. Costs
//! live in a heap with lazy deletion ([`CostQueue`]): an entry whose endpoint has since been
//! merged is skipped when popped (or dropped in bulk, [`Engine::step`]), and the edges around a
//! collapse are pushed again with fresh costs, which keeps the whole build at O(n log n) for
//! meshes of bounded vertex degree.

use alloc::vec;
use alloc::vec::Vec;

use super::chunks::Chunks;
use super::closest::Surface;
use super::flatten::{flatten, PlanarCollapse};
use super::lists::{faces_in, ring_in, In, Lists, Merged};
use super::positions::Positions;
use super::quadric::{place, Quadric};
use super::queue::CostQueue;
use super::rejected::Rejected;
use super::vec3::{add, cross, dot, len, normalize, scale, sub, Vec3d};
use super::{BuildOptions, Cost, ErrorBound, InputMesh, Placement, NONE};

/// What one collapse did, enough to undo it by a vertex split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Collapse {
    /// The new vertex.
    pub parent: u32,
    /// The merged vertices; triangle `(children[0], children[1], wings[0])` was removed.
    pub children: [u32; 2],
    /// Third corners of the removed triangles; `wings[1]` is `NONE` on a boundary edge.
    pub wings: [u32; 2],
    /// The removed triangles (input triangle indices): `(c0, c1, w0)` and `(c1, c0, w1)` or `NONE`.
    pub faces: [u32; 2],
    /// The triangles across their outer edges, as input triangle indices or `NONE` on a border:
    /// across `c1-w0`, `w0-c0`, `c0-w1`, `w1-c1`.
    pub neighbours: [u32; 4],
}

/// What a run of collapses leaves for the hierarchy to be made from ([`super::attributes`]),
/// whichever engine made them.
pub(crate) struct Collapsed<'o> {
    pub opts: &'o BuildOptions,
    /// Every vertex id's position: the input's, then one per collapse.
    pub pos: Positions<'o>,
    /// Colours in `0..=1` by vertex id; empty when the mesh has none.
    pub color: Vec<Vec3d>,
    /// The input's triangles with their corners renamed by the collapses, and which are left.
    pub faces: Vec<[u32; 3]>,
    pub face_alive: Vec<bool>,
    pub collapses: Vec<Collapse>,
    /// As [`Engine::fans`] (empty under [`ErrorBound::Offset`]).
    pub fans: Vec<[u32; 3]>,
    pub fan_ends: Vec<u32>,
    /// Costs computed on the way: the work done ([`super::Hierarchy::heap_pushes`]).
    pub heap_pushes: u64,
}

/// Vertex `v`'s colour in `0..=1` among `color` (by vertex id; black when the mesh has none,
/// and `color` is empty).
pub(crate) fn color_of(color: &[Vec3d], v: u32) -> Vec3d {
    color.get(v as usize).copied().unwrap_or([0.0; 3])
}

pub(crate) struct Engine<'o> {
    pub opts: &'o BuildOptions,
    pub pos: Positions<'o>,
    /// Quadric and area of each live vertex, by its slot (as are its faces and ring below): a
    /// collapse's vertex takes its first child's slot, so there are never more slots than input
    /// vertices.
    quadric: Vec<Quadric>,
    area: Vec<f64>,
    /// The slot of each vertex id (meaningful while the vertex is live).
    slot: Vec<u32>,
    /// Colours in `0..=1` by vertex id; empty when the mesh has none ([`color_of`]).
    pub color: Vec<[f64; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub face_alive: Vec<bool>,
    /// Live faces around each live vertex and its sorted neighbours, by slot, kept up to date by
    /// [`Engine::collapse`].
    lists: Lists,
    pub alive: Vec<bool>,
    pub alive_count: usize,
    /// Edges by cost.
    pub queue: CostQueue,
    /// [`CostQueue::pushes`] at the queue's last purge of merged vertices' entries.
    purged_at: u64,
    /// Edges found illegal, by endpoint: retried when a collapse changes that endpoint's ring.
    rejected: Rejected,
    pub collapses: Chunks<Collapse>,
    /// For error bounds measured as residuals ([`ErrorBound::Spheroid`], [`ErrorBound::Hoppe`]):
    /// the triangles around each collapse's new vertex as it made them, collapse `k`'s at
    /// `fans[fan_ends[k - 1]..fan_ends[k]]` (vertex ids name one position for ever).
    pub fans: Vec<[u32; 3]>,
    pub fan_ends: Vec<u32>,
    /// The input surface, for [`Cost::Color`]'s `Gerr`.
    surface: Option<Surface>,
    /// When set, every collapse's planar maps (for the remesher); an edge whose region has no
    /// valid pair of maps is not collapsed.
    pub planar: Option<Vec<PlanarCollapse>>,
    /// Triangles the collapses may not make worse than this shape (`4 sqrt(3) area / sum of
    /// squared edges`, 1 for equilateral), unless the region already had one as bad: 0 for the
    /// hierarchy builder, where shape does not matter; the remesher's base faces need it.
    pub min_shape: f64,
    /// The remesher's border rules ([`Engine::keep_borders`]): which vertices sit on a corner of
    /// the input's border, where it turns by more than 30 degrees. Empty: no such rules.
    pub corners: Vec<bool>,
    /// Where a collapse gathers its new vertex's faces and ring.
    scratch_faces: Vec<u32>,
    scratch_ring: Vec<u32>,
}

/// Room the cost queue keeps for a collapse's pushes (the new vertex's edges, and retries).
const SPARE: usize = 64;
/// Queued entries per live vertex past which the entries of merged vertices are dropped.
const PER_VERTEX: usize = 5;

/// `4 sqrt(3) area / (sum of squared edge lengths)`: 1 for an equilateral triangle, 0 for a
/// degenerate one.
pub(crate) fn shape(t: [Vec3d; 3]) -> f64 {
    let [a, b, c] = t;
    let edges = [sub(b, a), sub(c, b), sub(a, c)];
    let squares: f64 = edges.iter().map(|&e| dot(e, e)).sum();
    if squares > 0.0 {
        2.0 * crate::root::sqrt(3.0) * len(cross(edges[0], sub(c, a))) / squares
    } else {
        0.0
    }
}

/// Which of `children`'s positions a parent at `v` keeps under [`Placement::Endpoint`] (the
/// first when both are there), or `None` under [`Placement::Cost`]: the parent then copies that
/// child's attributes.
pub(crate) fn kept(opts: &BuildOptions, v: Vec3d, children: [Vec3d; 2]) -> Option<usize> {
    (opts.placement == Placement::Endpoint)
        .then(|| children.iter().position(|&c| c == v))
        .flatten()
}

/// The corners that follow `v` counter-clockwise in triangle `t` (`None` when `v` is not one):
/// a face of a vertex's list has it once, so one test finds which edges of the face are its.
#[inline]
pub(crate) fn after(t: [u32; 3], v: u32) -> Option<(u32, u32)> {
    if t[0] == v {
        Some((t[1], t[2]))
    } else if t[1] == v {
        Some((t[2], t[0]))
    } else if t[2] == v {
        Some((t[0], t[1]))
    } else {
        None
    }
}

fn face_normal(p: &Positions<'_>, f: [u32; 3]) -> Vec3d {
    let [a, b, c] = f.map(|i| p.get(i));
    cross(sub(b, a), sub(c, a))
}

/// Where a collapse of `a-b` (at `pa` and `pb`, quadrics summed in `q`) puts its vertex, before
/// any border rule: [`Placement`]'s choice for [`BuildOptions::cost`]. (These rules, shared by
/// the heap engine and the passes, are inlined into each: out of line they cost the build a
/// twentieth more instructions.)
#[inline(always)]
pub(crate) fn placement(opts: &BuildOptions, q: &Quadric, pa: Vec3d, pb: Vec3d) -> Vec3d {
    match (opts.placement, opts.cost) {
        (Placement::Endpoint, _) if q.error(pb) < q.error(pa) => pb,
        (Placement::Endpoint, _) => pa,
        (Placement::Cost, Cost::Quadric) => place(q, pa, pb),
        (Placement::Cost, _) => scale(add(pa, pb), 0.5),
    }
}

/// What collapsing `a-b` (ends at `pa` and `pb`, quadrics summed in `q`, `colors` their
/// colours, asked only by [`Cost::Color`]) into a vertex at `v` costs under
/// [`BuildOptions::cost`]; `surface` is the input's, for [`Cost::Color`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn cost_at(
    opts: &BuildOptions,
    q: &Quadric,
    v: Vec3d,
    [pa, pb]: [Vec3d; 2],
    colors: impl FnOnce() -> [Vec3d; 2],
    surface: Option<&Surface>,
) -> f64 {
    let len2 = dot(sub(pa, pb), sub(pa, pb));
    match opts.cost {
        Cost::Quadric => q.error(v),
        Cost::ShortestEdge => len2,
        Cost::Color => {
            // The importance paper's Gerr^2 + length^2 + sqrt(length * dcolor): the new vertex
            // at the edge's midpoint (its Fig. 2; or on an endpoint), Gerr its distance to the
            // closest point of the input surface.
            let gerr = surface.map_or(0.0, |s| s.distance(v));
            let [ca, cb] = colors();
            let dc = len(sub(ca, cb));
            gerr * gerr + len2 + crate::root::sqrt(crate::root::sqrt(len2) * dc)
        }
    }
}

/// A cost as the order of collapses keys it: non-negative floats order like their bit
/// patterns; anything not finite goes last.
#[inline(always)]
pub(crate) fn cost_key(cost: f64) -> u32 {
    let key = if cost.is_finite() {
        (cost.max(0.0) as f32).min(f32::MAX)
    } else {
        f32::MAX
    };
    key.to_bits()
}

/// The colour of the vertex merging ends of colours `ca` and `cb` at `pa` and `pb` (areas
/// `area_a` and `area_b`) into `v`: the kept end's under [`Placement::Endpoint`], else the
/// area-weighted mean.
#[inline(always)]
pub(crate) fn merged_color(
    opts: &BuildOptions,
    v: Vec3d,
    [pa, pb]: [Vec3d; 2],
    [ca, cb]: [Vec3d; 2],
    [area_a, area_b]: [f64; 2],
) -> Vec3d {
    match kept(opts, v, [pa, pb]) {
        Some(k) => [ca, cb][k],
        None => {
            let (wa, wb) = (area_a.max(1e-30), area_b.max(1e-30));
            scale(add(scale(ca, wa), scale(cb, wb)), 1.0 / (wa + wb))
        }
    }
}

/// Each input vertex's quadric (the planes of its triangles, weighted by their areas) and, when
/// the mesh is `colored`, a third of its triangles' areas (which weigh merged colours, and
/// nothing else: none without colours), by vertex id, which is each engine's slot at the start.
pub(crate) fn face_sums(
    pos: &Positions<'_>,
    faces: &[[u32; 3]],
    n: usize,
    colored: bool,
) -> (Vec<Quadric>, Vec<f64>) {
    let mut quadric = vec![Quadric::default(); n];
    let mut area = if colored { vec![0.0; n] } else { Vec::new() };
    for tri in faces {
        let [a, b, c] = tri.map(|i| pos.get(i));
        let q = Quadric::triangle(a, b, c);
        for &v in tri {
            quadric[v as usize] = quadric[v as usize].add(&q);
        }
        if colored {
            let ar = 0.5 * len(cross(sub(b, a), sub(c, a)));
            for &v in tri {
                area[v as usize] += ar / 3.0;
            }
        }
    }
    (quadric, area)
}

/// What a collapse adds up of its two `ends` (vertex id, slot, position): the first end's slot
/// takes the summed quadric and, when the mesh has colours, the summed area, and the colour of
/// the vertex made at `v` is pushed. Both engines keep quadrics and areas by slot, colours by
/// vertex id.
#[inline(always)]
pub(crate) fn merge_sums(
    opts: &BuildOptions,
    quadric: &mut [Quadric],
    area: &mut [f64],
    color: &mut Vec<Vec3d>,
    ends: [(u32, usize, Vec3d); 2],
    v: Vec3d,
) {
    let [(a, sa, pa), (b, sb, pb)] = ends;
    quadric[sa] = quadric[sa].add(&quadric[sb]);
    if !color.is_empty() {
        let (area_a, area_b) = (area[sa], area[sb]);
        area[sa] = area_a + area_b;
        let (ca, cb) = (color[a as usize], color[b as usize]);
        let c = merged_color(opts, v, [pa, pb], [ca, cb], [area_a, area_b]);
        color.push(c);
    }
}

/// Whether a triangle keeps facing the same way, with an area, when its corners move from
/// `before` to `after` (the flip test of a collapse).
#[inline(always)]
pub(crate) fn stays_up(before: [Vec3d; 3], after: [Vec3d; 3]) -> bool {
    let n0 = cross(sub(before[1], before[0]), sub(before[2], before[0]));
    let n1 = cross(sub(after[1], after[0]), sub(after[2], after[0]));
    len(n1) > 1e-12 * len(n0) && dot(n0, n1) > 0.0
}

/// The faces with directed edge `a -> b` and `b -> a` among `around` (faces holding `a`), as
/// (third corner of each or NONE, number of faces on the edge).
#[inline(always)]
pub(crate) fn edge_wings(faces: &[[u32; 3]], around: &[u32], a: u32, b: u32) -> ([u32; 2], usize) {
    let mut wings = [NONE; 2];
    let mut count = 0;
    for &f in around {
        let Some((next, prev)) = after(faces[f as usize], a) else {
            continue;
        };
        if next == b {
            wings[0] = prev;
            count += 1;
        } else if prev == b {
            wings[1] = next;
            count += 1;
        }
    }
    (wings, count)
}

/// A split's records, as the file keeps them (Hoppe's `fn0..fn3`), gathered face by face from
/// the walks a collapse makes round its two ends anyway: the two faces on edge `c0-c1` (`c0 ->
/// c1`, then `c1 -> c0`) and the four across their outer edges (`w0 -> c1`, `c0 -> w0`, `w1 ->
/// c0`, `c1 -> w1`), or `NONE`. Every face that holds one of those directed edges holds `c0` or
/// `c1`, and holds it once, so each end's faces may come in the order of its list and the two
/// ends' in any order (they fill different records).
pub(crate) struct Split {
    children: [u32; 2],
    wings: [u32; 2],
    pub on_edge: [u32; 2],
    pub neighbours: [u32; 4],
}

impl Split {
    pub fn new(children: [u32; 2], wings: [u32; 2]) -> Split {
        Split {
            children,
            wings,
            on_edge: [NONE; 2],
            neighbours: [NONE; 4],
        }
    }

    /// Notes face `f`, of corners `t`, round end `end` (0 for `c0`, 1 for `c1`; a constant
    /// where this is inlined). Round `c0` the face with edge `c0 -> w0` is `n1` and the one with
    /// `w1 -> c0` is `n2`; round `c1`, `c1 -> w1` is `n3` and `w0 -> c1` is `n0`.
    #[inline(always)]
    pub fn see(&mut self, end: usize, f: u32, t: [u32; 3]) {
        let (other, [own, across]) = (1 - end, [end, 1 - end].map(|k| self.wings[k]));
        if let Some((next, prev)) = after(t, self.children[end]) {
            if next == self.children[other] {
                self.on_edge[end] = f;
            } else if next == own {
                self.neighbours[1 + 2 * end] = f;
            }
            if prev == across {
                self.neighbours[(2 + 2 * end) % 4] = f;
            }
        }
    }
}

/// Whether a vertex of these `faces` and `ring` (its neighbours) is on a border: in a manifold
/// fan an inner vertex has as many triangles as neighbours, a border vertex one fewer.
#[inline(always)]
fn borders(faces: &[u32], ring: &[u32]) -> bool {
    faces.len() < ring.len()
}

impl<'o> Engine<'o> {
    pub fn new(mesh: &InputMesh<'o>, opts: &'o BuildOptions) -> Engine<'o> {
        let n = mesh.positions.len();
        // Every collapse makes one vertex id and at most n - 1 are made.
        let pos = Positions::new(mesh.positions, n.saturating_sub(1));
        let faces = mesh.triangles.to_vec();
        // Each vertex's faces and neighbours in lists of their exact length (grown by pushing,
        // they took a sixth of the build's instructions and held twice the room): the faces
        // filed by vertex first (`start[v]..start[v + 1]` of `filed`, in face order), then each
        // vertex's lists made from its faces, and the filing freed.
        let mut start = vec![0u32; n + 1];
        for tri in &faces {
            for &v in tri {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut filed = vec![0u32; faces.len() * 3];
        let mut next = start.clone();
        for (f, tri) in faces.iter().enumerate() {
            for &v in tri {
                filed[next[v as usize] as usize] = f as u32;
                next[v as usize] += 1;
            }
        }
        drop(next);
        let mut lists = Lists::with_capacity(n);
        let mut ring = Vec::new();
        for v in 0..n {
            let around = &filed[start[v] as usize..start[v + 1] as usize];
            ring.clear();
            for &f in around {
                ring.extend(faces[f as usize].iter().filter(|&&x| x != v as u32));
            }
            ring.sort_unstable();
            ring.dedup();
            lists.push(around, &ring);
        }
        drop((start, filed, ring));
        // Colours in 0..=1, only when the mesh has them (none: black, and no array).
        let color: Vec<Vec3d> = mesh.colors.map_or_else(Vec::new, |c| {
            c.iter().map(|c| c.map(|v| v as f64 / 255.0)).collect()
        });
        let (quadric, area) = face_sums(&pos, &faces, n, !color.is_empty());
        let mut e = Engine {
            opts,
            pos,
            quadric,
            area,
            slot: (0..n as u32).collect(),
            color,
            face_alive: vec![true; faces.len()],
            faces,
            alive: lists.has_faces().collect(),
            alive_count: 0,
            lists,
            queue: CostQueue::default(),
            purged_at: 0,
            rejected: Rejected::with_ids(2 * n),
            collapses: Chunks::for_about(n),
            fans: Vec::new(),
            fan_ends: Vec::new(),
            surface: (opts.cost == Cost::Color)
                .then(|| Surface::new(mesh.positions, mesh.triangles)),
            planar: None,
            min_shape: 0.0,
            corners: Vec::new(),
            scratch_faces: Vec::new(),
            scratch_ring: Vec::new(),
        };
        e.alive_count = e.alive.iter().filter(|&&a| a).count();
        // Every collapse makes one vertex id and at most n - 1 are made: the per-id arrays are
        // sized once, so that none doubles (and, while it is copied, holds both sizes) mid-build;
        // the collapse records grow by chunks ([`Chunks`]).
        let ids = n.saturating_sub(1);
        e.slot.reserve_exact(ids);
        e.color
            .reserve_exact(if e.color.is_empty() { 0 } else { ids });
        e.alive.reserve_exact(ids);
        // Boundary quadrics keep open borders in place: on a border edge, the face itself is
        // the only one. Both its ends are border vertices, which have fewer faces than
        // neighbours: that test spares the other edges the search of a fan. (Asked once a
        // vertex, not once an edge end: looked up twice for each of a vertex's edges, it cost
        // a hundredth of the build's instructions.)
        let border: Vec<bool> = (0..n as u32).map(|v| e.on_border(v)).collect();
        for f in 0..e.faces.len() {
            let tri = e.faces[f];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if border[a as usize] && border[b as usize] && e.edge_faces(a, b).1 == 1 {
                    let n = normalize(face_normal(&e.pos, tri)).unwrap_or([0.0; 3]);
                    let q = Quadric::boundary(e.pos.get(a), e.pos.get(b), n, 16.0);
                    for v in [a, b] {
                        e.quadric[v as usize] = e.quadric[v as usize].add(&q);
                    }
                }
            }
        }
        let edges = e.lists.ring_total() / 2;
        // Room for an eighth more than the edges: a full queue drops its stale entries (`step`),
        // which leaves room, since every collapse makes about a dozen. With half as many again
        // (and growing whenever a purge left it two thirds full) the bunny's build peaked 0.7 MB
        // higher for 0.3% more instructions; with a 32nd the first purges leave too little and
        // it grows (a realloc: old and new room at once).
        e.queue.reserve(edges + edges / 8);
        // Each edge once, from its lower end: a sorted ring's higher neighbours are its tail
        // (read in place, not looked up again for each edge; slots are still vertex ids).
        for v in 0..n as u32 {
            let ring = e.lists.ring(v as usize);
            for &x in &ring[ring.partition_point(|&x| x < v)..] {
                let key = e.key(v, x);
                e.queue.push(key, (v, x));
            }
        }
        e
    }

    /// What the collapses leave for the hierarchy (positions, colours, faces, the collapse
    /// records and fans), all else (the heap of costs, the rings, quadrics, areas and the input
    /// surface) freed, so that the hierarchy's own arrays do not add to the engine's at the
    /// build's peak.
    pub fn into_collapsed(self) -> Collapsed<'o> {
        let (mut collapsed, records) = self.into_parts();
        // The rest of the engine is gone: the records can be joined.
        collapsed.collapses = records.into_vec();
        collapsed
    }

    /// [`Engine::into_collapsed`] but for the collapse records, still in chunks; the rest of
    /// the engine is freed on return.
    fn into_parts(self) -> (Collapsed<'o>, Chunks<Collapse>) {
        let collapsed = Collapsed {
            heap_pushes: self.queue.pushes(),
            opts: self.opts,
            pos: self.pos,
            color: self.color,
            faces: self.faces,
            face_alive: self.face_alive,
            collapses: Vec::new(),
            fans: self.fans,
            fan_ends: self.fan_ends,
        };
        (collapsed, self.collapses)
    }

    /// The slot of live vertex `v` (its quadric, area, faces and ring).
    fn at(&self, v: u32) -> usize {
        self.slot[v as usize] as usize
    }

    /// Whether live vertex `v` is on a border ([`borders`]).
    pub fn on_border(&self, v: u32) -> bool {
        let (faces, ring) = self.lists.both(self.at(v));
        borders(faces, ring)
    }

    /// Sorted distinct neighbours of a live vertex.
    pub fn neighbours(&self, v: u32) -> &[u32] {
        self.lists.ring(self.at(v))
    }

    /// The faces with directed edge `a -> b` and `b -> a`, as (third corner of the first or NONE,
    /// number of faces on the edge).
    #[inline]
    fn edge_faces(&self, a: u32, b: u32) -> ([u32; 2], usize) {
        edge_wings(&self.faces, self.lists.faces(self.at(a)), a, b)
    }

    fn boundary_neighbours(&self, v: u32) -> Vec<u32> {
        self.neighbours(v)
            .iter()
            .copied()
            .filter(|&x| self.edge_faces(v, x).1 == 1)
            .collect()
    }

    /// Turns on the remesher's border rules: the border stays where it is (an edge from it
    /// inwards merges onto its border end, a border edge at a corner onto the corner), and only
    /// a corner may be left with a single triangle (an ear). An ear where the border runs
    /// straight subdivides into a corner triangle whose three vertices lie on one line.
    pub fn keep_borders(&mut self) {
        let turn = libm::cos(30f64.to_radians());
        self.corners = (0..self.pos.len() as u32)
            .map(|v| match self.boundary_neighbours(v).as_slice() {
                &[x, y] => {
                    let at = self.pos.get(v);
                    let (dx, dy) = (sub(at, self.pos.get(x)), sub(self.pos.get(y), at));
                    let (lx, ly) = (len(dx), len(dy));
                    !(lx > 0.0 && ly > 0.0 && dot(dx, dy) / (lx * ly) > turn)
                }
                _ => false,
            })
            .collect();
    }

    /// Whether the vertex that merges `a` and `b` at `v` is on a corner: one of them was, and
    /// `v` is where it was.
    fn corner_at(&self, a: u32, b: u32, v: Vec3d) -> bool {
        let (pa, pb) = (self.pos.get(a), self.pos.get(b));
        (self.corners[a as usize] && v == pa) || (self.corners[b as usize] && v == pb)
    }

    /// Where the merged vertex goes and what the collapse costs.
    pub fn evaluate(&self, a: u32, b: u32) -> (Vec3d, f64) {
        let (pa, pb) = (self.pos.get(a), self.pos.get(b));
        let q = self.quadric[self.at(a)].add(&self.quadric[self.at(b)]);
        let v = placement(self.opts, &q, pa, pb);
        let v = if self.corners.is_empty() {
            v
        } else {
            let corner = |x: u32| self.corners[x as usize];
            match (self.on_border(a), self.on_border(b), corner(a), corner(b)) {
                (true, false, ..) | (true, true, true, false) => pa,
                (false, true, ..) | (true, true, false, true) => pb,
                _ => v,
            }
        };
        let colors = || [color_of(&self.color, a), color_of(&self.color, b)];
        let cost = cost_at(self.opts, &q, v, [pa, pb], colors, self.surface.as_ref());
        (v, cost)
    }

    fn push(&mut self, a: u32, b: u32) {
        let (a, b) = (a.min(b), a.max(b));
        // Ties go to the earlier push.
        self.queue.push(self.key(a, b), (a, b));
    }

    /// The queue's key for edge `a-b` ([`cost_key`] of its cost).
    fn key(&self, a: u32, b: u32) -> u32 {
        cost_key(self.evaluate(a, b).1)
    }

    /// Whether collapsing `a-b` into `v` keeps the mesh a manifold of the same topology with no
    /// flipped or degenerate triangle.
    #[cfg(test)]
    pub fn legal(&self, a: u32, b: u32, v: Vec3d) -> bool {
        let (wings, count) = self.edge_faces(a, b);
        self.legal_on(a, b, v, wings, count)
    }

    /// Whether collapsing `a-b` into `v` is legal, given the third corners of its faces and their
    /// number (`edge_faces`).
    fn legal_on(&self, a: u32, b: u32, v: Vec3d, wings: [u32; 2], count: usize) -> bool {
        if count == 0 {
            return false;
        }
        let ((fa, na), (fb, nb)) = (self.lists.both(self.at(a)), self.lists.both(self.at(b)));
        // Link condition: the common neighbours are exactly the wings (both rings are sorted,
        // so one merge finds them).
        let w = wings.map(|x| (x != NONE).then_some(x));
        let mut common = 0;
        let (mut i, mut j) = (0, 0);
        while let (Some(&x), Some(&y)) = (na.get(i), nb.get(j)) {
            if x == y {
                if !w.contains(&Some(x)) {
                    return false;
                }
                common += 1;
            }
            i += usize::from(x <= y);
            j += usize::from(y <= x);
        }
        if common != w.iter().flatten().count() || (w[0].is_some() && w[0] == w[1]) {
            return false;
        }
        let edge_on_border = count == 1;
        let (ba, bb) = (borders(fa, na), borders(fb, nb));
        if ba && bb && !edge_on_border {
            return false; // would pinch two borders (or a border and itself) together
        }
        if edge_on_border {
            // A border loop of three edges would close up.
            let oa: Vec<u32> = self
                .boundary_neighbours(a)
                .into_iter()
                .filter(|&x| x != b)
                .collect();
            let ob: Vec<u32> = self
                .boundary_neighbours(b)
                .into_iter()
                .filter(|&x| x != a)
                .collect();
            if oa.iter().any(|x| ob.contains(x)) {
                return false;
            }
        }
        // Degrees: the merged vertex and the wings keep enough neighbours (this also stops a
        // closed component from shrinking below a tetrahedron).
        let degree_p = na.len() + nb.len() - 2 - common;
        let border_p = ba || bb;
        // Under the remesher's border rules only a corner may be left as an ear.
        let ruled = !self.corners.is_empty();
        let straight = |x: u32| usize::from(ruled && !self.corners[x as usize]);
        let straight_p = usize::from(ruled && !self.corner_at(a, b, v));
        if degree_p < if border_p { 2 + straight_p } else { 3 } {
            return false;
        }
        for x in w.into_iter().flatten() {
            let (faces, ring) = self.lists.both(self.at(x));
            let min = if borders(faces, ring) {
                3 + straight(x)
            } else {
                4
            };
            if ring.len() < min {
                return false;
            }
        }
        // No flipped or collapsed triangle, and none worse shaped than `min_shape` allows.
        let mut worst_before = f64::INFINITY;
        let mut worst_after = f64::INFINITY;
        for (s, around) in [(a, fa), (b, fb)] {
            for &f in around {
                let t = self.faces[f as usize];
                if t.contains(&a) && t.contains(&b) {
                    continue;
                }
                let corners = t.map(|i| self.pos.get(i));
                let moved = t.map(|i| if i == s { v } else { self.pos.get(i) });
                if !stays_up(corners, moved) {
                    return false;
                }
                if self.min_shape > 0.0 {
                    worst_before = worst_before.min(shape(corners));
                    worst_after = worst_after.min(shape(moved));
                }
            }
        }
        self.min_shape <= 0.0 || worst_after >= self.min_shape.min(worst_before)
    }

    /// Collapses the cheapest legal edge; `false` when none is left.
    pub fn step(&mut self) -> bool {
        loop {
            // Entries of merged vertices would be skipped when popped, each after a sift from
            // the root that misses the cache at every level: they are dropped in one sequential
            // pass instead (the order of what is left does not change) when the queue holds more
            // than five entries per live vertex (a closed mesh has three edges per vertex; five
            // took 11% of the bunny's build instructions off, four and seven did less) and a
            // third of them came since the last purge (so a queue of live entries past that
            // count is not passed over again every step), and when it is about to grow; it
            // grows, by half, only if that left less than a sixteenth of it free.
            let (len, capacity) = (self.queue.len(), self.queue.capacity());
            let since = self.queue.pushes() - self.purged_at;
            let stale = len > PER_VERTEX * self.alive_count + 1024 && 3 * since > len as u64;
            if stale || capacity - len < SPARE {
                let alive = &self.alive;
                self.queue
                    .retain(|(a, b)| alive[a as usize] && alive[b as usize]);
                self.purged_at = self.queue.pushes();
                if 16 * (self.queue.len() + SPARE) > 15 * capacity {
                    self.queue.reserve(capacity / 2 + SPARE);
                }
            }
            let Some((a, b)) = self.queue.pop() else {
                return false;
            };
            if !self.alive[a as usize] || !self.alive[b as usize] {
                continue;
            }
            let (v, _) = self.evaluate(a, b);
            let (wings, count) = self.edge_faces(a, b);
            if self.legal_on(a, b, v, wings, count) && self.map_planar(a, b, v) {
                self.collapse(a, b, v, wings);
                return true;
            }
            self.rejected.add(a, b);
        }
    }

    /// With [`Engine::planar`] set, records the planar maps of collapsing `a-b` into `v`;
    /// `false` when there are none (the edge is then illegal).
    fn map_planar(&mut self, a: u32, b: u32, v: Vec3d) -> bool {
        if self.planar.is_none() {
            return true;
        }
        let mut ids: Vec<u32> = self
            .lists
            .faces(self.at(a))
            .iter()
            .chain(self.lists.faces(self.at(b)))
            .copied()
            .collect();
        ids.sort_unstable();
        ids.dedup();
        let before = ids.iter().map(|&f| (f, self.faces[f as usize])).collect();
        let pos = |x: u32| self.pos.get(x);
        let parent = self.pos.len() as u32;
        match flatten(before, [a, b], parent, v, &pos) {
            Some(map) => {
                if let Some(list) = self.planar.as_mut() {
                    list.push(map);
                }
                true
            }
            None => false,
        }
    }

    /// Removes face `f`, which holds `a` and `b`, from the mesh and from its third corner's faces.
    fn remove_face(&mut self, f: u32, (a, b): (u32, u32)) {
        let (Some(t), Some(alive)) = (
            self.faces.get(f as usize),
            self.face_alive.get_mut(f as usize),
        ) else {
            return;
        };
        *alive = false;
        let third = t
            .iter()
            .copied()
            .find(|&x| x != a && x != b)
            .unwrap_or(NONE);
        if let Some(&l) = self.slot.get(third as usize) {
            self.lists.remove_face(l as usize, f);
        }
    }

    /// Collapses `a-b` into a new vertex at `v`; `wings` are the third corners of the faces with
    /// directed edges `a -> b` and `b -> a` ([`Engine::edge_faces`]).
    fn collapse(&mut self, a: u32, b: u32, v: Vec3d, wings: [u32; 2]) {
        // Orient so that triangle (children[0], children[1], wings[0]) exists.
        let (children, wings) = if wings[0] != NONE {
            ([a, b], wings)
        } else {
            ([b, a], [wings[1], wings[0]])
        };
        // Which end each child is (0 or 1) for the split's records.
        let (end_a, end_b) = (usize::from(children[0] != a), usize::from(children[0] == a));
        let mut split = Split::new(children, wings);
        let p = self.pos.len() as u32;
        let (ia, ib) = (a as usize, b as usize);
        let (sa, sb) = (self.slot[ia] as usize, self.slot[ib] as usize);
        let ends = [(a, sa, self.pos.get(a)), (b, sb, self.pos.get(b))];
        merge_sums(
            self.opts,
            &mut self.quadric,
            &mut self.area,
            &mut self.color,
            ends,
            v,
        );
        self.pos.push(v);
        self.slot.push(sa as u32);
        if !self.corners.is_empty() {
            let corner = self.corner_at(a, b, v);
            self.corners.push(corner);
        }

        // The lists of p are built in scratch buffers and stored at their exact length in a's
        // slot once a's and b's are read.
        let mut pf = core::mem::take(&mut self.scratch_faces);
        pf.clear();
        let (la, lb) = (self.lists.take(sa), self.lists.take(sb));
        // Both face lists are sorted, and a face is in both exactly when it holds both ends (a
        // face is listed by each of its corners): walked together, they give p's faces sorted,
        // with no sort, and the faces to remove without a search of their corners. The split's
        // records are read off the same walk, before the corners are renamed.
        for (f, side) in Merged::new(faces_in(&la), faces_in(&lb)) {
            let Some(t) = self.faces.get_mut(f as usize) else {
                continue;
            };
            let s = match side {
                In::First => {
                    split.see(end_a, f, *t);
                    a
                }
                In::Second => {
                    split.see(end_b, f, *t);
                    b
                }
                In::Both => {
                    split.see(end_a, f, *t);
                    split.see(end_b, f, *t);
                    self.remove_face(f, (a, b));
                    continue;
                }
            };
            *t = t.map(|x| if x == s { p } else { x });
            pf.push(f);
        }
        if self.opts.bound != ErrorBound::Offset {
            self.fans.extend(pf.iter().map(|&f| self.faces[f as usize]));
            self.fan_ends.push(self.fans.len() as u32);
        }
        self.alive[ia] = false;
        self.alive[ib] = false;
        self.alive.push(true);
        self.alive_count -= 1;
        self.collapses.push(Collapse {
            parent: p,
            children,
            wings,
            faces: split.on_edge,
            neighbours: split.neighbours,
        });
        self.rejected.take(a);
        self.rejected.take(b);
        // The ring of p: both rings but a and b, sorted as both are, in one walk of both. Its
        // members swap a and b (or the one they hold) for p, which as the newest vertex goes
        // last and keeps their rings sorted.
        let mut ring = core::mem::take(&mut self.scratch_ring);
        ring.clear();
        for (x, side) in Merged::new(ring_in(&la), ring_in(&lb)) {
            if x == a || x == b {
                continue;
            }
            let s = self.at(x);
            match side {
                In::First => self.lists.replace_in_ring(s, a, p),
                In::Second => self.lists.replace_in_ring(s, b, p),
                In::Both => self.lists.swap_in_ring(s, (a, b), p),
            }
            ring.push(x);
        }
        // p's lists go in the longer of a's and b's when they fit (the other is freed first,
        // for the allocator to reuse when they do not).
        let (room, other) = if la.len() >= lb.len() {
            (la, lb)
        } else {
            (lb, la)
        };
        drop(other);
        self.lists.set_in(sa, &pf, &ring, room);
        self.scratch_faces = pf;
        // Fresh costs for the edges of p (no other edge's cost changed); edges around it that were
        // illegal may have become legal.
        for &x in &ring {
            self.push(p, x);
            let mut retry = self.rejected.take(x);
            retry.sort_unstable();
            retry.dedup();
            for y in retry {
                if self.alive[y as usize] {
                    // Out of y's list too, or every retry would push the edge once more per
                    // endpoint and the copies would double with each rejection.
                    self.rejected.drop_from(y, x);
                    self.push(x, y);
                }
            }
        }
        self.scratch_ring = ring;
    }
}
