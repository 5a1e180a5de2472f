//! The cut: the mesh of the currently active vertices, in fixed-capacity arenas.
//!
//! A [`Cut`] holds one triangle mesh whose vertices are hierarchy nodes, starting from the base
//! mesh. A vertex split replaces an active node by its two children and adds the one or two
//! triangles its collapse removed; an edge collapse undoes that. Both use Hoppe's rule, which the
//! file stores per split as the four neighbour triangles `fn0..fn3` ([`crate::format`]): a split
//! is legal when those triangles exist, a collapse when they are still next to the two triangles
//! it removes. [`Cut::force_split`] makes a split legal by first splitting, recursively, whatever
//! must exist (the merge-tree paper's forced refinement, §3.6), so detail that is asked for is
//! never lost. The mesh stays a manifold with the input's topology and orientation after every
//! operation; [`Cut::check`] proves it in tests.
//!
//! Storage is plain arrays of `u32` slots (structure of arrays), with capacities in the type:
//! `V` active vertices, `F` active triangles, `Q` entries of each work queue. The triangle slice is
//! what the rasterizer draws ([`Cut::triangles`]), and the position, normal and colour slices are
//! indexed by the same vertex slots, so drawing a cut copies nothing. Nothing allocates, nothing
//! panics on any hierarchy [`HierarchyView::parse`] accepted: an operation that would overflow a
//! capacity is refused and counted instead.
//!
//! Memory: [`Cut::BYTES`] = 165 bytes per vertex slot (node, a triangle of its fan and their number, cached
//! bounds, parent, sibling and the parent's bounds, position, normal, colours, flags, blend state), 36 per triangle slot (corners,
//! neighbours, id, and a node-map entry) and 24 per queue entry, plus a few words; asserted in
//! the tests. A closed mesh has about two triangles per vertex, so `F = 2 V` and
//! `Q = V / 4` cost about 240 bytes per active vertex.
//!
//! ```
//! # #[cfg(feature = "build")] {
//! use vdlod_core::build::{build, BuildOptions, InputMesh};
//! use vdlod_core::cut::Cut;
//! use vdlod_core::format::HierarchyView;
//! let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
//!                  [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
//! let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
//!                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
//! let mesh = InputMesh { positions: &positions, colors: None, triangles: &triangles };
//! let bytes = build(&mesh, &BuildOptions::default(), &mut |_| {}).unwrap().to_bytes(false);
//! let h = HierarchyView::parse(&bytes).unwrap();
//! let mut cut = Cut::<16, 32, 16>::new();
//! cut.reset(&h).unwrap();
//! assert_eq!(cut.triangles().len(), 4); // the base mesh: a tetrahedron
//! while cut.refine_everything(&h) > 0 {}
//! assert_eq!(cut.triangles().len(), 8); // every split done: the octahedron again
//! assert!(cut.check(&h).is_ok());
//! # }
//! ```

use core::fmt;

use heapless::binary_heap::{BinaryHeap, Max};
use heapless::Vec;

use crate::format::{HierarchyView, NodeView, NONE};
use crate::nodemap::NodeMap;
use crate::policy::Bounds;

/// A slot that holds nothing (no neighbour across a border edge, no incident triangle).
pub const NIL: u32 = u32::MAX;

/// Vertex flag: visible at the last evaluation.
pub(crate) const VISIBLE: u8 = 1;
/// Vertex flag: visible at the evaluation before.
pub(crate) const WAS_VISIBLE: u8 = 2;
/// Vertex flag, set on both children: their collapse was found illegal, and nothing around
/// them has collapsed since (a collapse clears it on its fan), so it is not retried.
pub(crate) const BLOCKED: u8 = 4;
/// Vertex flag: a geomorph runs (its blend state has frames left).
pub(crate) const BLENDING: u8 = 8;
/// Vertex flag: the geomorph runs towards the parent, for a collapse.
pub(crate) const COLLAPSING: u8 = 16;

/// Longest fan walked around one vertex; a hierarchy with larger vertex degrees is refused
/// rather than walked forever.
pub const MAX_FAN: usize = 1024;

/// The triangles around the two vertices of a collapse, found while proving it legal and used
/// again to do it.
pub(crate) type PairFans = [Vec<u32, MAX_FAN>; 2];

/// Why the cut could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CutError {
    /// The base mesh needs more vertex or triangle slots than the cut has.
    Capacity {
        /// Vertices the base mesh needs.
        vertices: u32,
        /// Triangles the base mesh needs.
        triangles: u32,
    },
    /// The base mesh is not an oriented manifold (an edge used twice the same way, or by three
    /// triangles).
    BaseNotManifold {
        /// The base triangle where that was found.
        triangle: u32,
    },
}

impl fmt::Display for CutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CutError::Capacity {
                vertices,
                triangles,
            } => write!(
                f,
                "the base mesh needs {vertices} vertices and {triangles} triangles, more than the cut holds"
            ),
            CutError::BaseNotManifold { triangle } => {
                write!(f, "base triangle {triangle} breaks the manifold")
            }
        }
    }
}

impl core::error::Error for CutError {}

/// Why one split or collapse did not happen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// The node is not active (already split, or not yet made).
    NotActive,
    /// The node is a leaf (split) or a root (collapse).
    NoSuchOperation,
    /// A neighbour triangle the split needs does not exist yet (carries its id).
    Missing(u32),
    /// A collapse whose neighbourhood has since been refined (Hoppe's condition fails).
    Illegal,
    /// A vertex or triangle arena, or a work queue, is full.
    Capacity,
    /// The triangle budget does not allow it.
    Budget,
    /// The per-frame operation limit is used up.
    Ops,
    /// The hierarchy contradicts the mesh (only for files crafted to pass the format checks).
    Inconsistent,
}

/// What went wrong in [`Cut::check`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Defect {
    /// What is wrong.
    pub what: &'static str,
    /// Where: a vertex or triangle slot.
    pub slot: u32,
}

/// Blend state of one vertex (see [`crate::adapt`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Morph {
    pub from_pos: [f32; 3],
    pub from_normal: [f32; 3],
    pub from_color: [u8; 3],
    /// Frames left; 0: not blending.
    pub left: u16,
    /// Blending towards the parent, to be collapsed when done.
    pub collapsing: bool,
}

/// Colours of the vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Coloring {
    /// The nodes' colours from the file.
    #[default]
    Node,
    /// A false colour by depth in the forest ([`depth_color`]).
    Depth,
}

/// The active mesh; see the module documentation. `V` vertex slots, `F` triangle slots, `Q`
/// queue entries.
pub struct Cut<const V: usize, const F: usize, const Q: usize> {
    // Vertices, by slot.
    pub(crate) node: Vec<u32, V>,
    /// One triangle around the vertex (`NIL` for none).
    pub(crate) fan: Vec<u32, V>,
    /// Triangles using the vertex, kept by every operation: a fan walk that finds this many
    /// distinct triangles found them all, which is what makes renaming a vertex complete (and
    /// the cut safe from hierarchies crafted to contradict the mesh).
    pub(crate) degree: Vec<u16, V>,
    pub(crate) bounds: Vec<Bounds, V>,
    /// The parent, and when this is the parent's first child its sibling and the sibling's
    /// slot when active (else `NIL`s), so that each pair is looked at once per frame without
    /// reading the file or the node map.
    pub(crate) family: Vec<[u32; 3], V>,
    /// The parent's bounds, for first children (the collapse test reads them every frame).
    pub(crate) parent_bounds: Vec<Bounds, V>,
    pub(crate) positions: Vec<[f32; 3], V>,
    pub(crate) normals: Vec<[f32; 3], V>,
    pub(crate) colors: Vec<[u8; 3], V>,
    /// The colour the vertex blends towards (its node's, or the depth colour).
    pub(crate) tint: Vec<[u8; 3], V>,
    /// [`VISIBLE`], [`WAS_VISIBLE`], [`BLOCKED`], [`BLENDING`], [`COLLAPSING`]: one byte per
    /// vertex, so the per-frame pass reads the blend state only of vertices that blend.
    pub(crate) flags: Vec<u8, V>,
    pub(crate) morph: Vec<Morph, V>,
    pub(crate) slot_of: NodeMap<F>,
    // Triangles, by slot.
    pub(crate) tri: Vec<[u32; 3], F>,
    /// `adj[f][k]`: the triangle across edge `tri[f][k] -> tri[f][k + 1]`, or `NIL`.
    pub(crate) adj: Vec<[u32; 3], F>,
    /// Triangle ids in the hierarchy's numbering.
    pub(crate) fid: Vec<u32, F>,
    // Work queues.
    pub(crate) stack: Vec<u32, Q>,
    /// Split candidates: (error bits, node), largest error first.
    pub(crate) candidates: BinaryHeap<(u32, u32), Max, Q>,
    /// Collapse candidates: (parent's error, parent, first child's slot when found); the error
    /// is negative when culled.
    pub(crate) pairs: Vec<(f32, u32, u32), Q>,
    pub(crate) coloring: Coloring,
    pub(crate) threshold: f32,
    pub(crate) geomorph_frames: u16,
}

impl<const V: usize, const F: usize, const Q: usize> Default for Cut<V, F, Q> {
    fn default() -> Self {
        Self::new()
    }
}

#[inline]
fn corner(t: [u32; 3], v: u32) -> Option<usize> {
    if t[0] == v {
        Some(0)
    } else if t[1] == v {
        Some(1)
    } else if t[2] == v {
        Some(2)
    } else {
        None
    }
}

#[inline]
fn next3(k: usize) -> usize {
    if k == 2 {
        0
    } else {
        k + 1
    }
}

#[inline]
fn prev3(k: usize) -> usize {
    if k == 0 {
        2
    } else {
        k - 1
    }
}

/// The false colour of a forest depth: eight distinct hues, repeating, so that neighbouring
/// levels always differ.
pub fn depth_color(depth: u16) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [230, 25, 75],
        [245, 130, 48],
        [255, 225, 25],
        [60, 180, 75],
        [70, 240, 240],
        [0, 130, 200],
        [145, 30, 180],
        [240, 50, 230],
    ];
    PALETTE[depth as usize % PALETTE.len()]
}

pub(crate) fn bounds_of(n: &NodeView) -> Bounds {
    Bounds {
        center: n.position,
        radius: n.radius,
        axis: n.normal,
        cone_sin: n.cone_sin,
        a2: n.spheroid[0] * n.spheroid[0],
        b2: n.spheroid[1] * n.spheroid[1],
    }
}

impl<const V: usize, const F: usize, const Q: usize> Cut<V, F, Q> {
    /// Bytes of memory the cut occupies: the arenas and queues, nothing else (it allocates
    /// nothing).
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// An empty cut; [`Cut::reset`] loads a hierarchy's base mesh.
    pub const fn new() -> Self {
        Cut {
            node: Vec::new(),
            fan: Vec::new(),
            degree: Vec::new(),
            bounds: Vec::new(),
            family: Vec::new(),
            parent_bounds: Vec::new(),
            positions: Vec::new(),
            normals: Vec::new(),
            colors: Vec::new(),
            tint: Vec::new(),
            flags: Vec::new(),
            morph: Vec::new(),
            slot_of: NodeMap::new(),
            tri: Vec::new(),
            adj: Vec::new(),
            fid: Vec::new(),
            stack: Vec::new(),
            candidates: BinaryHeap::new(),
            pairs: Vec::new(),
            coloring: Coloring::Node,
            threshold: 1.0,
            geomorph_frames: 0,
        }
    }

    /// Sets the vertex colouring (applies to vertices from now on; call before [`Cut::reset`]
    /// to colour all of them).
    pub fn set_coloring(&mut self, coloring: Coloring) {
        self.coloring = coloring;
    }

    /// Replaces the cut by the base mesh of `h`.
    pub fn reset(&mut self, h: &HierarchyView<'_>) -> Result<(), CutError> {
        self.clear();
        let base = h.base_triangles();
        let too_big = || CutError::Capacity {
            vertices: base.saturating_mul(3),
            triangles: base,
        };
        if base as usize > F {
            return Err(too_big());
        }
        for t in 0..base {
            let nodes = h.base_triangle(t);
            let mut slots = [NIL; 3];
            for (k, &n) in nodes.iter().enumerate() {
                slots[k] = match self.slot_of.get(n) {
                    Some(s) => s,
                    None => {
                        let s = self.node.len() as u32;
                        if !self.push_vertex(h, n, None) {
                            self.clear();
                            return Err(too_big());
                        }
                        s
                    }
                };
            }
            let f = self.tri.len() as u32;
            // Capacity was checked above.
            let _ = self.tri.push(slots);
            let _ = self.adj.push([NIL; 3]);
            let _ = self.fid.push(t);
            for &s in &slots {
                if self.fan[s as usize] == NIL {
                    self.fan[s as usize] = f;
                }
                self.degree[s as usize] = self.degree[s as usize].saturating_add(1);
            }
        }
        for v in 0..self.node.len() as u32 {
            self.link_family(h, v);
        }
        // Adjacency by matching each directed edge with its reverse (the base mesh is small).
        let n = self.tri.len();
        for f in 0..n {
            for k in 0..3 {
                let (a, b) = (self.tri[f][k], self.tri[f][next3(k)]);
                for g in 0..n {
                    for j in 0..3 {
                        let (c, d) = (self.tri[g][j], self.tri[g][next3(j)]);
                        let same = g != f && c == a && d == b;
                        let paired = c == b && d == a;
                        if same || (paired && self.adj[f][k] != NIL && self.adj[f][k] != g as u32) {
                            self.clear();
                            return Err(CutError::BaseNotManifold { triangle: f as u32 });
                        }
                        if paired {
                            self.adj[f][k] = g as u32;
                        }
                    }
                }
            }
        }
        // Every vertex's fan must be one edge-connected fan.
        if let Err(d) = self.check_fans() {
            let triangle = self.fan.get(d.slot as usize).copied().unwrap_or(0);
            self.clear();
            return Err(CutError::BaseNotManifold { triangle });
        }
        Ok(())
    }

    fn clear(&mut self) {
        self.node.clear();
        self.fan.clear();
        self.degree.clear();
        self.bounds.clear();
        self.family.clear();
        self.parent_bounds.clear();
        self.positions.clear();
        self.normals.clear();
        self.colors.clear();
        self.tint.clear();
        self.flags.clear();
        self.morph.clear();
        self.slot_of.clear();
        self.tri.clear();
        self.adj.clear();
        self.fid.clear();
        self.stack.clear();
        self.candidates.clear();
        self.pairs.clear();
        self.threshold = 1.0;
    }

    pub(crate) fn tint_of(&self, n: &NodeView) -> [u8; 3] {
        match self.coloring {
            Coloring::Node => n.color,
            Coloring::Depth => depth_color(n.depth),
        }
    }

    /// Fills slot `s`'s family entry, and its first sibling's if `s` holds a second child.
    fn link_family(&mut self, h: &HierarchyView<'_>, s: u32) {
        let node = self.node[s as usize];
        let p = h.parent(node);
        let mut entry = [NONE, NIL, NIL];
        let mut pb = Bounds::default();
        if p != NONE {
            let [c0, c1] = h.split(p).children;
            entry[0] = p;
            if c0 == node {
                entry[1] = c1;
                entry[2] = self.slot_of.get(c1).unwrap_or(NIL);
                pb = h.bounds(p);
            } else if let Some(x) = self.slot_of.get(c0) {
                self.family[x as usize][2] = s;
            }
        }
        self.family[s as usize] = entry;
        self.parent_bounds[s as usize] = pb;
    }

    /// Whether the vertex at slot `i` is a first child whose sibling is active; then returns
    /// the parent.
    #[inline]
    pub(crate) fn pair_parent(&self, i: usize) -> Option<u32> {
        let [p, sibling, slot] = self.family[i];
        (sibling != NIL && self.node.get(slot as usize) == Some(&sibling)).then_some(p)
    }

    /// Inserts into the node map, first re-spanning it when the count calls for it.
    fn map_insert(&mut self, node: u32, slot: u32) -> bool {
        self.respan_map(self.node.len() + 1);
        self.slot_of.insert(node, slot)
    }

    /// Rebuilds the node map over a span fit for `entries` active vertices, if it needs another.
    pub(crate) fn respan_map(&mut self, entries: usize) {
        if !self.slot_of.should_resize(entries) {
            return;
        }
        self.slot_of.reset(NodeMap::<F>::span_for(entries));
        for (s, &n) in self.node.iter().enumerate() {
            let _ = self.slot_of.insert(n, s as u32);
        }
    }

    /// Appends a vertex for `node`; `false` when full. `start` = the blend it starts with.
    fn push_vertex(&mut self, h: &HierarchyView<'_>, node: u32, start: Option<Morph>) -> bool {
        if self.node.is_full() || !self.map_insert(node, self.node.len() as u32) {
            return false;
        }
        let n = h.node(node);
        let tint = self.tint_of(&n);
        let _ = self.node.push(node);
        let _ = self.fan.push(NIL);
        let _ = self.degree.push(0);
        let _ = self.bounds.push(bounds_of(&n));
        let _ = self.family.push([NONE, NIL, NIL]);
        let _ = self.parent_bounds.push(Bounds::default());
        let (pos, normal, color, morph) = match start {
            Some(m) => (m.from_pos, m.from_normal, m.from_color, m),
            None => (n.position, n.normal, tint, Morph::default()),
        };
        let _ = self.positions.push(pos);
        let _ = self.normals.push(normal);
        let _ = self.colors.push(color);
        let _ = self.tint.push(tint);
        let _ = self.flags.push(VISIBLE | Self::blend_flags(&morph));
        let _ = self.morph.push(morph);
        true
    }

    fn blend_flags(m: &Morph) -> u8 {
        (if m.left > 0 { BLENDING } else { 0 }) | (if m.collapsing { COLLAPSING } else { 0 })
    }

    /// Makes slot `s` hold `node` (in place of the node it held).
    fn set_vertex(&mut self, h: &HierarchyView<'_>, s: usize, node: u32, start: Option<Morph>) {
        let n = h.node(node);
        let tint = self.tint_of(&n);
        self.slot_of.remove(self.node[s]);
        // The old entry was removed, so there is room.
        let _ = self.slot_of.insert(node, s as u32);
        self.node[s] = node;
        self.bounds[s] = bounds_of(&n);
        self.tint[s] = tint;
        let m = match start {
            Some(m) => {
                self.positions[s] = m.from_pos;
                self.normals[s] = m.from_normal;
                self.colors[s] = m.from_color;
                m
            }
            None => {
                self.positions[s] = n.position;
                self.normals[s] = n.normal;
                self.colors[s] = tint;
                Morph::default()
            }
        };
        self.morph[s] = m;
        self.flags[s] = (self.flags[s] & (VISIBLE | WAS_VISIBLE)) | Self::blend_flags(&m);
    }

    /// Active vertices.
    pub fn vertices(&self) -> usize {
        self.node.len()
    }

    /// The node at each vertex slot.
    pub fn nodes(&self) -> &[u32] {
        &self.node
    }

    /// Vertex positions (blended while a geomorph runs), by slot.
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    /// Unit vertex normals (blended), by slot.
    pub fn normals(&self) -> &[[f32; 3]] {
        &self.normals
    }

    /// Vertex colours (blended; see [`Coloring`]), by slot.
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.colors
    }

    /// Triangles over vertex slots, counter-clockwise seen from the front.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.tri
    }

    /// The slot of `node` if it is active.
    pub fn slot(&self, node: u32) -> Option<u32> {
        self.slot_of.get(node)
    }

    /// Whether `node` is active.
    pub fn is_active(&self, node: u32) -> bool {
        self.slot_of.get(node).is_some()
    }

    /// The triangle after `f` going counter-clockwise around vertex `v` (`NIL` at a border).
    #[inline]
    fn ccw(&self, f: u32, v: u32) -> Option<u32> {
        let t = *self.tri.get(f as usize)?;
        let k = corner(t, v)?;
        Some(self.adj[f as usize][prev3(k)])
    }

    /// The triangle before `f` going counter-clockwise around `v` (`NIL` at a border).
    #[inline]
    fn cw(&self, f: u32, v: u32) -> Option<u32> {
        let t = *self.tri.get(f as usize)?;
        let k = corner(t, v)?;
        Some(self.adj[f as usize][k])
    }

    /// Collects `v`'s triangles into `out` and says whether the walk found every triangle that
    /// uses `v`, each once. Each step of a walk is a function of the triangle it stands on, so a
    /// walk that comes back to its start (or reaches a border) without exceeding [`MAX_FAN`]
    /// steps repeats nothing; only the two halves of a border fan can overlap, which is checked,
    /// and the count must match the vertex's triangle count.
    fn complete_fan(&self, v: u32, out: &mut Vec<u32, MAX_FAN>) -> bool {
        out.clear();
        let Some(&start) = self.fan.get(v as usize) else {
            return false;
        };
        let degree = self
            .degree
            .get(v as usize)
            .map_or(usize::MAX, |&d| d as usize);
        if start == NIL {
            return degree == 0;
        }
        let mut f = start;
        loop {
            if out.push(f).is_err() {
                return false;
            }
            match self.ccw(f, v) {
                Some(g) if g == start => return out.len() == degree,
                Some(NIL) => break,
                Some(g) => f = g,
                None => return false,
            }
        }
        // A border: the rest lies clockwise of the start, and must not meet the first half.
        let ccw_part = out.len();
        let mut g = match self.cw(start, v) {
            Some(g) => g,
            None => return false,
        };
        while g != NIL {
            if out[..ccw_part].contains(&g) || out.push(g).is_err() {
                return false;
            }
            g = match self.cw(g, v) {
                Some(g) => g,
                None => return false,
            };
        }
        out.len() == degree
    }

    /// Whether walking `v`'s fan finds every triangle that uses `v`, each once.
    fn fan_complete(&self, v: u32) -> bool {
        self.complete_fan(v, &mut Vec::new())
    }

    /// Points the edge `a -> b` of triangle `f` at `to`.
    fn set_adj(&mut self, f: u32, a: u32, b: u32, to: u32) -> Option<()> {
        let t = *self.tri.get(f as usize)?;
        let k = corner(t, a)?;
        (t[next3(k)] == b).then_some(())?;
        self.adj[f as usize][k] = to;
        Some(())
    }

    /// Splits active `node` if legal now. On success returns the children's slots.
    pub fn split(&mut self, h: &HierarchyView<'_>, node: u32) -> Result<[u32; 2], Refused> {
        self.split_with(h, node, 0)
    }

    /// Splits `node`; with `frames > 0` its children start at its current (blended) position,
    /// normal and colour and blend to their own over that many frames.
    pub(crate) fn split_with(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        frames: u16,
    ) -> Result<[u32; 2], Refused> {
        let ps = self.slot_of.get(node).ok_or(Refused::NotActive)?;
        if node < h.leaves() {
            return Err(Refused::NoSuchOperation);
        }
        let s = h.split(node);
        let [c0, c1] = s.children;
        let n = s.neighbours;
        let second = s.wings[1] != NONE;
        // The neighbour triangles must all be around the vertex (whose fan must be whole).
        let mut fan: Vec<u32, MAX_FAN> = Vec::new();
        if !self.complete_fan(ps, &mut fan) {
            return Err(Refused::Inconsistent);
        }
        let mut ns = [NIL; 4];
        for &f in &fan {
            let id = self.fid[f as usize];
            for k in 0..4 {
                if n[k] == id {
                    ns[k] = f;
                }
            }
        }
        for k in 0..4 {
            if n[k] != NONE && ns[k] == NIL {
                return Err(Refused::Missing(n[k]));
            }
        }
        let added = 1 + second as usize;
        if self.node.is_full() || self.tri.len() + added > F {
            return Err(Refused::Capacity);
        }

        // Wings, read off the neighbours (the nodes there now may be finer than at formation).
        let third = |f: u32, v: u32, offset: usize| -> Option<u32> {
            let t = *self.tri.get(f as usize)?;
            let k = corner(t, v)?;
            Some(t[(k + offset) % 3])
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
            let t = *self.tri.get(f as usize)?;
            let k = corner(t, a)?;
            (t[next3(k)] == b).then(|| self.adj[f as usize][k])
        };
        let pairs_meet = |x: u32, y: u32, w: u32| -> bool {
            // x holds w -> p, y holds p -> w; across each lies the other (or a border).
            let xy = if x == NIL {
                true
            } else {
                across(x, w, ps) == Some(y)
            };
            let yx = if y == NIL {
                true
            } else {
                across(y, ps, w) == Some(x)
            };
            xy && yx
        };
        if !pairs_meet(ns[0], ns[1], wl) || (second && !pairs_meet(ns[2], ns[3], wr)) {
            return Err(Refused::Inconsistent);
        }
        // The triangles that go to c1: counter-clockwise from n3 to n0, or up to a border and
        // then clockwise from n0 to the other border (as `Hierarchy::refine_all` does).
        let mut moved: Vec<u32, MAX_FAN> = Vec::new();
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
                if moved.contains(&f) {
                    return Err(Refused::Inconsistent);
                }
                moved.push(f).map_err(|_| Refused::Inconsistent)?;
                f = self.cw(f, ps).ok_or(Refused::Inconsistent)?;
            }
        }
        if (ns[1] != NIL && moved.contains(&ns[1])) || (ns[2] != NIL && moved.contains(&ns[2])) {
            return Err(Refused::Inconsistent);
        }

        // Checks done; from here on nothing fails.
        let start = (frames > 0).then(|| Morph {
            from_pos: self.positions[ps as usize],
            from_normal: self.normals[ps as usize],
            from_color: self.colors[ps as usize],
            left: frames,
            collapsing: false,
        });
        let c1s = self.node.len() as u32;
        let own = self.bounds[ps as usize];
        let (family, parent_bounds) = (self.family[ps as usize], self.parent_bounds[ps as usize]);
        self.set_vertex(h, ps as usize, c0, start);
        if !self.push_vertex(h, c1, start) {
            // Only the node map can refuse here (the arena was checked): undo.
            self.set_vertex(h, ps as usize, node, None);
            self.family[ps as usize] = family;
            self.parent_bounds[ps as usize] = parent_bounds;
            return Err(Refused::Capacity);
        }
        // The children's family is known: no need to read it from the file.
        self.family[ps as usize] = [node, c1, c1s];
        self.parent_bounds[ps as usize] = own;
        self.family[c1s as usize] = [node, NIL, NIL];
        for &f in &moved {
            let t = &mut self.tri[f as usize];
            if let Some(k) = corner(*t, ps) {
                t[k] = c1s;
            }
        }
        let m = moved.len() as u16;
        let d = self.degree[ps as usize];
        self.degree[ps as usize] = d.saturating_sub(m).saturating_add(added as u16);
        self.degree[c1s as usize] = m.saturating_add(added as u16);
        for w in [wl, wr] {
            if let Some(d) = self.degree.get_mut(w as usize) {
                *d = d.saturating_add(1);
            }
        }
        let fl = self.tri.len() as u32;
        let fr = if second { fl + 1 } else { NIL };
        let _ = self.tri.push([ps, c1s, wl]);
        let _ = self.adj.push([fr, ns[0], ns[1]]);
        let _ = self.fid.push(h.split_face(node, false));
        if second {
            let _ = self.tri.push([c1s, ps, wr]);
            let _ = self.adj.push([fl, ns[2], ns[3]]);
            let _ = self.fid.push(h.split_face(node, true));
        }
        if ns[0] != NIL {
            let _ = self.set_adj(ns[0], wl, c1s, fl);
        }
        if ns[1] != NIL {
            let _ = self.set_adj(ns[1], ps, wl, fl);
        }
        if ns[2] != NIL {
            let _ = self.set_adj(ns[2], wr, ps, fr);
        }
        if ns[3] != NIL {
            let _ = self.set_adj(ns[3], c1s, wr, fr);
        }
        self.fan[ps as usize] = fl;
        self.fan[c1s as usize] = fl;
        Ok([ps, c1s])
    }

    /// Splits active `node`, first splitting whatever its split needs (Hoppe's forced split; the
    /// merge-tree paper's forced refinement, §3.6), each with a blend of `frames` frames.
    /// `allow` is asked before each split with the node and the number of triangles it adds, and
    /// answers why not or `Ok` to go on. Returns the splits done; on a refusal the splits done so far stay.
    pub fn force_split(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        frames: u16,
        allow: &mut dyn FnMut(u32, u32) -> Result<(), Refused>,
    ) -> Result<u32, Refused> {
        if !self.is_active(node) {
            return Err(Refused::NotActive);
        }
        self.stack.clear();
        self.stack.push(node).map_err(|_| Refused::Capacity)?;
        let mut done = 0;
        // Each round splits once or pushes a coarser node; bounded for crafted files.
        let mut rounds = 0u32;
        let limit = h.nodes().saturating_mul(4).saturating_add(64);
        while let Some(&v) = self.stack.last() {
            rounds += 1;
            if rounds > limit {
                return Err(Refused::Inconsistent);
            }
            if !self.is_active(v) {
                // Either split already (by an earlier forced split), or coarser than the cut
                // here: then its first active ancestor goes first.
                let mut a = h.parent(v);
                let mut steps = 0;
                while a != NONE && !self.is_active(a) {
                    a = h.parent(a);
                    steps += 1;
                    if steps > h.nodes() {
                        return Err(Refused::Inconsistent);
                    }
                }
                if a == NONE {
                    self.stack.pop();
                } else {
                    self.stack.push(a).map_err(|_| Refused::Capacity)?;
                }
                continue;
            }
            let added = if h.split(v).wings[1] != NONE { 2 } else { 1 };
            allow(v, added)?;
            match self.split_with(h, v, frames) {
                Ok(_) => {
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
                    if self.stack.contains(&creator) {
                        return Err(Refused::Inconsistent);
                    }
                    self.stack.push(creator).map_err(|_| Refused::Capacity)?;
                }
                Err(e) => return Err(e),
            }
        }
        Ok(done)
    }

    /// Collapses active siblings into their parent `node` if Hoppe's condition holds. Returns the
    /// parent's slot.
    pub fn collapse(&mut self, h: &HierarchyView<'_>, node: u32) -> Result<u32, Refused> {
        let mut fans = PairFans::default();
        let ok = self.collapse_legal(h, node, &mut fans)?;
        Ok(self.collapse_unchecked(h, node, ok, &fans))
    }

    /// The slots `[a, b, fl, fr]` of a legal collapse of `node`.
    pub(crate) fn collapse_legal(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        fans: &mut PairFans,
    ) -> Result<[u32; 4], Refused> {
        if node < h.leaves() || node >= h.nodes() {
            return Err(Refused::NoSuchOperation);
        }
        let s = h.split(node);
        let [c0, c1] = s.children;
        let a = self.slot_of.get(c0).ok_or(Refused::NotActive)?;
        let b = self.slot_of.get(c1).ok_or(Refused::NotActive)?;
        self.collapse_legal_at(h, node, &s, a, b, fans)
    }

    /// [`Cut::collapse_legal`] with the children's slots `a` and `b` known.
    pub(crate) fn collapse_legal_at(
        &self,
        h: &HierarchyView<'_>,
        node: u32,
        s: &crate::format::SplitView,
        a: u32,
        b: u32,
        fans: &mut PairFans,
    ) -> Result<[u32; 4], Refused> {
        let [fan_a, fan_b] = fans;
        if !self.complete_fan(a, fan_a) {
            return Err(Refused::Inconsistent);
        }
        let id = h.split_face(node, false);
        let fl = fan_a
            .iter()
            .copied()
            .find(|&f| self.fid[f as usize] == id)
            .ok_or(Refused::Illegal)?;
        let t = self.tri[fl as usize];
        let k = corner(t, a).ok_or(Refused::Inconsistent)?;
        if t[next3(k)] != b {
            return Err(Refused::Inconsistent);
        }
        let adj = self.adj[fl as usize];
        let id = |f: u32| {
            if f == NIL {
                NONE
            } else {
                self.fid[f as usize]
            }
        };
        // fl = (a, b, wl): edge b -> wl has n0, edge wl -> a has n1.
        if id(adj[next3(k)]) != s.neighbours[0] || id(adj[prev3(k)]) != s.neighbours[1] {
            return Err(Refused::Illegal);
        }
        let fr = adj[k];
        if s.wings[1] != NONE {
            let Some(&t) = self.tri.get(fr as usize) else {
                return Err(Refused::Illegal);
            };
            if self.fid[fr as usize] != h.split_face(node, true) {
                return Err(Refused::Illegal);
            }
            let j = corner(t, b).ok_or(Refused::Inconsistent)?;
            if t[next3(j)] != a {
                return Err(Refused::Inconsistent);
            }
            // fr = (b, a, wr): edge a -> wr has n2, edge wr -> b has n3.
            let adj = self.adj[fr as usize];
            if id(adj[next3(j)]) != s.neighbours[2] || id(adj[prev3(j)]) != s.neighbours[3] {
                return Err(Refused::Illegal);
            }
        } else if fr != NIL {
            return Err(Refused::Inconsistent);
        }
        // Renaming b and moving the last vertex into b's slot must reach every triangle.
        let last = self.node.len() as u32 - 1;
        if !self.complete_fan(b, fan_b) || !self.fan_complete(last) {
            return Err(Refused::Inconsistent);
        }
        Ok([a, b, fl, fr])
    }

    /// Performs a collapse [`Cut::collapse_legal`] approved, with the fans it found; returns the
    /// parent's slot.
    pub(crate) fn collapse_unchecked(
        &mut self,
        h: &HierarchyView<'_>,
        node: u32,
        [a, b, fl, fr]: [u32; 4],
        [fan_a, fan_b]: &PairFans,
    ) -> u32 {
        // Collapses around here may become legal: clear the marks on every corner of the
        // triangles around both vertices (the parent's fan and its neighbours).
        for &f in fan_a.iter().chain(fan_b.iter()) {
            for v in self.tri[f as usize] {
                self.flags[v as usize] &= !BLOCKED;
            }
        }
        // The removed triangles' corners lose one triangle each; then b's become a's.
        for f in [fl, fr] {
            if let Some(t) = self.tri.get(f as usize).copied() {
                for v in t {
                    if let Some(d) = self.degree.get_mut(v as usize) {
                        *d = d.saturating_sub(1);
                    }
                }
            }
        }
        let db = self.degree[b as usize];
        self.degree[a as usize] = self.degree[a as usize].saturating_add(db);
        self.degree[b as usize] = 0;
        for &f in fan_b.iter() {
            if f == fl || f == fr {
                continue;
            }
            if let Some(k) = corner(self.tri[f as usize], b) {
                self.tri[f as usize][k] = a;
            }
        }
        // The neighbours of each removed triangle become each other's.
        let mut new_fan = NIL;
        for f in [fl, fr] {
            if f == NIL {
                continue;
            }
            let t = self.tri[f as usize];
            let adj = self.adj[f as usize];
            // The third corner w and the neighbours across its two edges.
            let j = (0..3).find(|&j| t[j] != a && t[j] != b).unwrap_or(0);
            let w = t[j];
            let (x, y) = (adj[j], adj[prev3(j)]);
            for (p, q) in [(x, y), (y, x)] {
                if p != NIL {
                    for e in self.adj[p as usize].iter_mut() {
                        if *e == f {
                            *e = q;
                        }
                    }
                }
            }
            let keep = if x != NIL { x } else { y };
            if let Some(fw) = self.fan.get_mut(w as usize) {
                if *fw == fl || *fw == fr {
                    *fw = keep;
                }
            }
            if new_fan == NIL {
                new_fan = keep;
            }
        }
        self.fan[a as usize] = new_fan;
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
        self.set_vertex(h, a as usize, node, None);
        self.link_family(h, a);
        self.slot_of.remove(self.node[b as usize]);
        self.remove_vertex(h, b)
            .map(|moved_to| if moved_to == a { b } else { a })
            .unwrap_or(a)
    }

    /// Swap-removes triangle slot `f`, re-pointing whatever pointed at the moved one.
    fn remove_triangle(&mut self, f: u32) {
        let last = self.tri.len() as u32 - 1;
        if f != last {
            let t = self.tri[last as usize];
            let adj = self.adj[last as usize];
            for g in adj {
                if let Some(ga) = self.adj.get_mut(g as usize) {
                    for e in ga.iter_mut() {
                        if *e == last {
                            *e = f;
                        }
                    }
                }
            }
            for v in t {
                if let Some(fv) = self.fan.get_mut(v as usize) {
                    if *fv == last {
                        *fv = f;
                    }
                }
            }
            self.tri[f as usize] = t;
            self.adj[f as usize] = adj;
            self.fid[f as usize] = self.fid[last as usize];
        }
        self.tri.pop();
        self.adj.pop();
        self.fid.pop();
    }

    /// Swap-removes vertex slot `v` (its node is already out of the map). Returns the slot the
    /// last vertex moved from, if it moved.
    fn remove_vertex(&mut self, h: &HierarchyView<'_>, v: u32) -> Option<u32> {
        let last = self.node.len() as u32 - 1;
        let moved = (v != last).then(|| {
            let mut fan: Vec<u32, MAX_FAN> = Vec::new();
            // Proven whole before the collapse that removes `v`.
            let _ = self.complete_fan(last, &mut fan);
            for &f in &fan {
                if let Some(k) = corner(self.tri[f as usize], last) {
                    self.tri[f as usize][k] = v;
                }
            }
            let i = v as usize;
            let j = last as usize;
            self.node[i] = self.node[j];
            self.fan[i] = self.fan[j];
            self.degree[i] = self.degree[j];
            self.bounds[i] = self.bounds[j];
            self.family[i] = self.family[j];
            self.parent_bounds[i] = self.parent_bounds[j];
            self.positions[i] = self.positions[j];
            self.normals[i] = self.normals[j];
            self.colors[i] = self.colors[j];
            self.tint[i] = self.tint[j];
            self.flags[i] = self.flags[j];
            self.morph[i] = self.morph[j];
            let _ = self.slot_of.insert(self.node[i], v);
            // A second child tells its first sibling where it went.
            let [p, sibling, _] = self.family[i];
            if p != NONE && sibling == NIL {
                let c0 = h.split(p).children[0];
                if let Some(x) = self.slot_of.get(c0) {
                    self.family[x as usize][2] = v;
                }
            }
            last
        });
        self.node.pop();
        self.fan.pop();
        self.degree.pop();
        self.bounds.pop();
        self.family.pop();
        self.parent_bounds.pop();
        self.positions.pop();
        self.normals.pop();
        self.colors.pop();
        self.tint.pop();
        self.flags.pop();
        self.morph.pop();
        moved
    }

    /// Splits every active vertex that has children, once (children are not split again in the
    /// same call); returns the splits done. Repeat until it returns 0 for full detail.
    pub fn refine_everything(&mut self, h: &HierarchyView<'_>) -> u32 {
        let mut done = 0;
        let mut i = 0;
        let n = self.node.len();
        while i < n.min(self.node.len()) {
            let v = self.node[i];
            if v >= h.leaves() {
                if let Ok(k) = self.force_split(h, v, 0, &mut |_, _| Ok(())) {
                    done += k;
                }
            }
            i += 1;
        }
        done
    }

    /// Every vertex's fan walk finds all its triangles, each once, and the counts add up to
    /// three corners per triangle: each vertex's triangles form one fan (a manifold).
    fn check_fans(&self) -> Result<(), Defect> {
        let mut corners = 0usize;
        for v in 0..self.node.len() as u32 {
            if !self.fan_complete(v) {
                return Err(Defect {
                    what: "a vertex's triangles are not one fan, or its count is wrong",
                    slot: v,
                });
            }
            corners += self.degree[v as usize] as usize;
        }
        if corners != 3 * self.tri.len() {
            return Err(Defect {
                what: "triangle counts do not add up",
                slot: 0,
            });
        }
        Ok(())
    }

    /// Verifies the cut: slots in range, adjacency symmetric along reversed edges (consistent
    /// orientation, no crack: every edge has one triangle on each side or is a border), every
    /// vertex's triangles one fan (a manifold), no degenerate triangle, the node map and the
    /// triangle ids right for `h`.
    pub fn check(&self, h: &HierarchyView<'_>) -> Result<(), Defect> {
        let bad = |what, slot| Err(Defect { what, slot });
        let nv = self.node.len() as u32;
        let nf = self.tri.len() as u32;
        for f in 0..nf {
            let t = self.tri[f as usize];
            if t.iter().any(|&v| v >= nv) {
                return bad("corner out of range", f);
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return bad("degenerate triangle", f);
            }
            let id = self.fid[f as usize];
            if id >= h.faces() {
                return bad("triangle id out of range", f);
            }
            for k in 0..3 {
                let g = self.adj[f as usize][k];
                if g == NIL {
                    continue;
                }
                if g >= nf {
                    return bad("neighbour out of range", f);
                }
                let (a, b) = (t[k], t[next3(k)]);
                let u = self.tri[g as usize];
                let Some(j) = corner(u, b) else {
                    return bad("neighbour does not share the edge", f);
                };
                if u[next3(j)] != a || self.adj[g as usize][j] != f {
                    return bad("adjacency not symmetric or orientation flipped", f);
                }
            }
        }
        for v in 0..nv {
            let node = self.node[v as usize];
            if self.slot_of.get(node) != Some(v) {
                return bad("node map wrong", v);
            }
            if node >= h.nodes() {
                return bad("node out of range", v);
            }
        }
        if self.slot_of.len() != nv as usize {
            return bad("node map has extra entries", 0);
        }
        self.check_fans()
    }
}

#[cfg(all(test, feature = "build"))]
mod tests;
