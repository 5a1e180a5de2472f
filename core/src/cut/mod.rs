//! The cut: the mesh of the currently active vertices, in fixed-capacity arenas.
//!
//! A [`Cut`] holds one triangle mesh whose vertices are hierarchy nodes, starting from the base
//! mesh. A vertex split replaces an active node by its two children and adds the one or two
//! triangles its collapse removed; an edge collapse undoes that. Both use the legality rule of
//! Hoppe ("View-dependent refinement of progressive meshes", SIGGRAPH 1997), which the file stores
//! per split as the four neighbour triangles `fn0..fn3` ([`crate::format`]): a split is legal
//! when those triangles exist ([`Cut::split`]), a collapse when they are still next to the two
//! triangles it removes ([`Cut::collapse`]). [`Cut::force_split`] makes a split legal by first
//! splitting whatever must exist (the forced refinement of Berkey and Song's merge-tree paper,
//! §3.6, done with a stack rather than recursion), so detail that is asked for is never lost. The
//! mesh stays a manifold with the input's topology and orientation after every operation;
//! [`Cut::check`] proves it (Hoppe's `ok()`).
//!
//! The rooms: [`slot`] (index widths and the queue arena), `store` (vertex and triangle
//! records), `fan` (walks around a vertex), `judge` (policies that judge triangles), `split`,
//! `collapse`, `blend` (geomorph state and the vertex output), `margin` (how far the camera may
//! move before an answer changes), `rigid` (the camera's motion seen from the camera), `expiry`
//! (which vertices a frame may skip), `check` (the invariants).
//!
//! # Memory
//!
//! Capacities are in the type: `V` vertex slots, `F` triangle slots, `Q` entries of each work
//! queue (and of the blend arena), and `I` the stored index ([`SlotIndex`]: `u16`, the default,
//! for `V` and `F` below 65,535; `u32` above). Nothing else is kept: normals, colours and bounds
//! are read from the hierarchy in place (an 8-byte digest of each active node lets most frames
//! skip that read), a vertex's family from its sibling link.
//! [`Cut::BYTES`] is, with `i` the index size (2 or 4 bytes), the same on 32- and 64-bit
//! targets (all lengths are `u32`):
//!
//! | per | bytes | what |
//! |---|---|---|
//! | vertex slot | `4 + 2i + 2 + 3 + 8` (21 with `u16`, 25 with `u32`) | node, fan triangle, mate; a 16-bit tag (blend entry while blending, expiry while settled); triangle count (`u16`) and flags (`u8`); the node's [`crate::format::Digest`] (quantized position and two bound codes: most frames decide a vertex from it without reading the file) |
//! | triangle slot | `6i + 4 + i` (18 with `u16`) | corners, neighbours, id; one node-map entry |
//! | queue entry | `4 + 8 + 12 + 28 = 52` | forcing stack, split heap, collapse pairs, blend arena |
//!
//! plus 368 bytes of lengths, settings, the walk's position, the chain of vertex slots a
//! frame's collapses freed and the terms the settled vertices were marked under (`expiry`).
//! With the recommended `F = 2 V` and `Q = V / 8` that is 21 + 36 + 6.5 = 63.5 bytes per vertex
//! slot, **31.75 bytes per triangle of capacity** with `u16` (47.75 with `u32`), 32.09 for a
//! 1,000-triangle cut. A cut for a 10,000-triangle budget, `Cut<5000, 10000, 625>`, is 317,868
//! bytes. The queues only bound how much one frame can do: when one overflows, the rest
//! waits for the next frame and [`crate::adapt::FrameStats`] says so. (At most 65,535
//! geomorphs run at once, whatever `Q`, since a vertex names its blend entry in 16 bits; past
//! that, changes land without a blend.)
//!
//! [`Cut::new`] is `const` and all zeros, so `static CUT: Mutex<RefCell<Cut<..>>>` lands in
//! `.bss` and never passes through the stack; `Cut::boxed` (feature `build`) puts one on the heap
//! the same way.
//!
//! # Determinism
//!
//! The cut is a function of the hierarchy, the sequence of calls and the capacities: the same
//! inputs give the same cut, bit for bit, on every target. When no capacity, queue, budget or
//! operation limit binds, the capacities do not matter; when one binds, the cut stays coarser
//! where the limit was met, so frames are identical across machines for the same capacities.
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
use core::hint::select_unpredictable;

use crate::format::{HierarchyView, Record, NONE};
use crate::nodemap::NodeMap;

mod blend;
mod check;
mod collapse;
pub(crate) mod expiry;
mod fan;
mod judge;
pub(crate) mod margin;
mod renumber;
mod rigid;
pub mod slot;
pub(crate) mod split;
mod store;

pub(crate) use blend::Blend;
pub use blend::{VertexOut, LANES};
pub use check::Defect;
pub(crate) use fan::PairFans;
pub use fan::MAX_FAN;
pub use slot::SlotIndex;

use expiry::Motion;
use slot::Arena;
use store::{Triangles, Vertices};

// The documented figure, checked when the crate is compiled for any target (CI builds it for
// x86_64 and a 32-bit Cortex-M): a cut of 10,240 triangle slots with the recommended
// capacities is 325,488 bytes, at most 32 bytes per triangle of capacity.
const _: () = assert!(Cut::<5120, 10240, 640>::BYTES == 325_488);
const _: () = assert!(Cut::<5120, 10240, 640>::BYTES <= 32 * 10240);

/// A slot that holds nothing (no neighbour across a border edge, no incident triangle).
pub const NIL: u32 = u32::MAX;

/// Vertex flag: visible at the last evaluation.
pub(crate) const VISIBLE: u8 = 1;
/// Vertex flag: visible at the evaluation before.
pub(crate) const WAS_VISIBLE: u8 = 2;
/// Vertex flag, set on both children: their collapse was found illegal, and no collapse has
/// given their triangles a new neighbour since (the one thing that can make it legal: see
/// `Cut::unblock_pair_of`), so it is not retried.
pub(crate) const BLOCKED: u8 = 4;
/// Vertex flag: a geomorph runs (its blend entry has frames left).
pub(crate) const BLENDING: u8 = 8;
/// Vertex flag: the geomorph runs towards the parent, for a collapse.
pub(crate) const COLLAPSING: u8 = 16;
/// Vertex flag: the node is its parent's first child (the one a pair is looked at from).
pub(crate) const FIRST_CHILD: u8 = 32;
/// Vertex flag: its answer (and, for a first child, its pair's) cannot change until the camera
/// has moved as far as its expiry says (see `expiry`); cleared by anything that changes its
/// family.
pub(crate) const SETTLED: u8 = 64;
/// Vertex flag: when last measured, its answers' margins covered less than one of the camera's
/// steps, so most asks do not measure them again (see `expiry`).
pub(crate) const RESTLESS: u8 = 128;

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

/// Colours of the vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Coloring {
    /// The nodes' colours from the file.
    #[default]
    Node = 0,
    /// A false colour by depth in the forest ([`depth_color`]).
    Depth = 1,
}

/// A pair of active siblings, as the adaptation's collapse list keeps it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Pair {
    /// The parent's error (negative when culled, so culled pairs sort first).
    pub error: f32,
    /// The parent.
    pub parent: u32,
    /// The first child's slot when the pair was listed.
    pub first: u32,
}

/// The active mesh; see the module documentation. `V` vertex slots, `F` triangle slots, `Q`
/// queue entries, indices stored as `I`.
pub struct Cut<const V: usize, const F: usize, const Q: usize, I: SlotIndex = u16> {
    pub(crate) v: Vertices<V, I>,
    pub(crate) t: Triangles<F, I>,
    pub(crate) map: NodeMap<F, I>,
    /// Nodes waiting for a forced split, the one on top first.
    pub(crate) stack: Arena<u32, Q>,
    /// Split candidates, a max-heap of (error bits, node).
    pub(crate) candidates: Arena<(u32, u32), Q>,
    /// Collapse candidates.
    pub(crate) pairs: Arena<Pair, Q>,
    /// Running geomorphs.
    pub(crate) blends: Arena<Blend, Q>,
    pub(crate) coloring: Coloring,
    pub(crate) geomorph_frames: u16,
    /// Frames before regulation may raise the threshold again (see [`Cut::adapt`]).
    pub(crate) raise_wait: u8,
    /// The regulated error threshold; 0 before [`Cut::reset`] (which makes it 1).
    pub(crate) threshold: f32,
    /// The camera's motion since the vertices marked `SETTLED` were marked.
    pub(crate) motion: Motion,
    /// Where the next frame's walk starts when [`crate::adapt::Budget::max_visits`] binds.
    pub(crate) walk: u32,
    /// Vertex slots a collapse freed and no split has taken yet (see [`Cut::free_vertex`]):
    /// the first one's slot plus one (0: none, so that a new cut is all zeros and a `static`
    /// one lands in `.bss`), each chained to the next through its fan entry (`NIL` ends the
    /// chain); and how many.
    pub(crate) free: u32,
    pub(crate) holes: u32,
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> fmt::Debug for Cut<V, F, Q, I> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Cut")
            .field("vertices", &self.v.len())
            .field("triangles", &self.t.len())
            .field("capacity", &(V, F, Q))
            .field("bytes", &Self::BYTES)
            .finish()
    }
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Default for Cut<V, F, Q, I> {
    fn default() -> Self {
        Self::new()
    }
}

/// The corner of `t` holding `v` (the first, when several do).
#[inline]
pub(crate) fn corner(t: [u32; 3], v: u32) -> Option<usize> {
    first_of(|k| t[k] == v)
}

/// The first of the indices 0, 1, 2 for which `holds` holds, computed rather than searched:
/// which corner of a triangle something is follows no pattern a branch predictor learns (a
/// third each way), and fan walks ask it at every step.
#[inline(always)]
pub(crate) fn first_of(holds: impl Fn(usize) -> bool) -> Option<usize> {
    // 0 when the first holds, else 1 when the second does, else 2 (if that one does).
    let k = usize::from(!holds(0)) << usize::from(!holds(1));
    holds(k).then_some(k)
}

#[inline]
pub(crate) fn next3(k: usize) -> usize {
    if k == 2 {
        0
    } else {
        k + 1
    }
}

#[inline]
pub(crate) fn prev3(k: usize) -> usize {
    if k == 0 {
        2
    } else {
        k - 1
    }
}

/// The false colour of a forest depth: eight distinct hues, repeating, so that neighbouring
/// levels always differ.
#[must_use]
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

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Bytes of memory the cut occupies: the arenas and queues, nothing else (it allocates
    /// nothing). See the module documentation for the formula.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// Blends that can run at once: the queue capacity, up to what a vertex's 16-bit tag can
    /// name.
    pub(crate) const BLEND_ROOM: usize = if Q < store::NAMEABLE_BLENDS {
        Q
    } else {
        store::NAMEABLE_BLENDS
    };

    /// Fails to compile when a capacity does not fit the index type.
    const CAPACITY_FITS: () = assert!(
        V < I::LIMIT && F < I::LIMIT && Q < u32::MAX as usize,
        "a cut's vertex and triangle capacities must be below 65,535 with u16 indices"
    );

    /// An empty cut, all zeros; [`Cut::reset`] loads a hierarchy's base mesh.
    #[must_use]
    pub const fn new() -> Self {
        let () = Self::CAPACITY_FITS;
        Cut {
            v: Vertices::new(),
            t: Triangles::new(),
            map: NodeMap::new(),
            stack: Arena::new(0),
            candidates: Arena::new((0, 0)),
            pairs: Arena::new(Pair {
                error: 0.0,
                parent: 0,
                first: 0,
            }),
            blends: Arena::new(Blend::ZERO),
            coloring: Coloring::Node,
            geomorph_frames: 0,
            raise_wait: 0,
            threshold: 0.0,
            motion: Motion::ZERO,
            walk: 0,
            free: 0,
            holes: 0,
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
                slots[k] = match self.slot(n) {
                    Some(s) => s,
                    None => match self.push_vertex(n) {
                        Some(s) => s,
                        None => {
                            self.clear();
                            return Err(too_big());
                        }
                    },
                };
            }
            // Capacity was checked above.
            let Some(f) = self.t.push(slots, [NIL; 3], t) else {
                self.clear();
                return Err(too_big());
            };
            for &s in &slots {
                if self.v.fan(s as usize) == NIL {
                    self.v.set_fan(s as usize, f);
                }
                self.v.degree[s as usize] = self.v.degree[s as usize].saturating_add(1);
            }
        }
        for s in 0..self.v.len() as u32 {
            self.link_family(h, s);
        }
        // Adjacency by matching each directed edge with its reverse (the base mesh is small).
        let n = self.t.len() as u32;
        for f in 0..n {
            let tf = self.t.at(f);
            for k in 0..3 {
                let (a, b) = (tf[k], tf[next3(k)]);
                for g in 0..n {
                    let tg = self.t.at(g);
                    for j in 0..3 {
                        let (c, d) = (tg[j], tg[next3(j)]);
                        let same = g != f && c == a && d == b;
                        let paired = c == b && d == a;
                        let taken = self.t.adj(f)[k];
                        if same || (paired && taken != NIL && taken != g) {
                            self.clear();
                            return Err(CutError::BaseNotManifold { triangle: f });
                        }
                        if paired {
                            self.t.set_adj(f, k, g);
                        }
                    }
                }
            }
        }
        // Every vertex's fan must be one edge-connected fan.
        if let Err(d) = self.check_fans() {
            let triangle = self.v.fan(d.slot as usize);
            self.clear();
            return Err(CutError::BaseNotManifold {
                triangle: if triangle == NIL { 0 } else { triangle },
            });
        }
        Ok(())
    }

    /// Empties the cut. The node map keeps a span fit for the vertices the cut had: a cut
    /// refined again after a reset grows back to about its size, and would otherwise rebuild
    /// its map two or three times on the way (the end of a frame shrinks it if it stays small).
    fn clear(&mut self) {
        let entries = self.active();
        self.v.clear();
        self.t.clear();
        self.map.reset(NodeMap::<F, I>::span_for(entries));
        self.stack.clear();
        self.candidates.clear();
        self.pairs.clear();
        self.blends.clear();
        self.threshold = 1.0;
        self.motion.clear();
        self.walk = 0;
        self.free = 0;
        self.holes = 0;
    }

    /// Active vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.v.len()
    }

    /// The node at each vertex slot.
    #[must_use]
    pub fn nodes(&self) -> &[u32] {
        self.v.nodes()
    }

    /// Triangles over vertex slots, counter-clockwise seen from the front: what the rasterizer
    /// draws, with [`Cut::vertex`] giving each slot's position, normal and colour.
    #[must_use]
    pub fn triangles(&self) -> &[[I; 3]] {
        self.t.corners()
    }

    /// The slot of `node` if it is active.
    #[must_use]
    pub fn slot(&self, node: u32) -> Option<u32> {
        self.map.get(node, self.v.nodes())
    }

    /// Whether `node` is active.
    #[must_use]
    pub fn is_active(&self, node: u32) -> bool {
        self.slot(node).is_some()
    }

    /// Whether the vertex at slot `i` is a first child whose sibling is active; then returns
    /// the parent.
    #[inline]
    pub(crate) fn pair_parent(&self, h: &HierarchyView<'_>, i: usize) -> Option<u32> {
        (self.v.flags[i] & FIRST_CHILD != 0 && self.v.mate(i) != NIL)
            .then(|| h.parent(self.v.node[i]))
    }

    /// Sets slot `s`'s digest, first-child flag and mate links from the file and the node map.
    fn link_family(&mut self, h: &HierarchyView<'_>, s: u32) {
        let i = s as usize;
        let node = self.v.node[i];
        self.v.digest[i] = h.digest(node);
        let p = h.parent(node);
        self.v.flags[i] &= !FIRST_CHILD;
        self.v.set_mate(i, NIL);
        if p == NONE {
            return;
        }
        let (sibling, first) = h.sibling(node);
        if first {
            self.v.flags[i] |= FIRST_CHILD;
        }
        if let Some(m) = self.slot(sibling) {
            self.v.set_mate(i, m);
            self.v.set_mate(m as usize, s);
        }
    }

    /// Breaks slot `s`'s mate link on both sides.
    fn unlink_mate(&mut self, s: usize) {
        let m = self.v.mate(s);
        if m != NIL {
            self.v.set_mate(m as usize, NIL);
        }
        self.v.set_mate(s, NIL);
    }

    /// Inserts slot `s` (the last, just pushed) into the node map, which the map's rebuild does
    /// when the count calls for a wider span. Only growth is checked: a map left wide by
    /// [`Cut::clear`] is not narrowed while the cut grows back, and shrinking is for the end of
    /// a frame ([`Cut::respan_map`]). Inlined into its callers (a split pushes a vertex): out
    /// of line, its call cost a first frame about 20 instructions a split.
    #[inline(always)]
    fn map_insert(&mut self, s: u32) -> bool {
        if self.map.should_grow(self.active()) {
            self.rebuild_map(self.active());
            return self.slot(self.v.node[s as usize]) == Some(s);
        }
        self.map.insert_new(s, self.v.nodes())
    }

    /// Rebuilds the node map over a span fit for `entries` active vertices, if it needs another.
    #[inline(always)]
    pub(crate) fn respan_map(&mut self, entries: usize) {
        if self.map.should_resize(entries) {
            self.rebuild_map(entries);
        }
    }

    /// Empties the node map, sizes it for `entries` entries and enters every active vertex.
    #[cold]
    #[inline(never)]
    pub(crate) fn rebuild_map(&mut self, entries: usize) {
        self.map.reset(NodeMap::<F, I>::span_for(entries));
        for s in 0..self.v.len() as u32 {
            if self.v.node[s as usize] != NONE {
                self.map.insert(s, self.v.nodes());
            }
        }
    }

    /// Active vertices: the slots in use less the holes collapses left.
    #[inline(always)]
    pub(crate) fn active(&self) -> usize {
        self.v.len() - self.holes as usize
    }

    /// Adds a vertex for `node` (visible, no blend, not linked) in the last slot a collapse
    /// freed, else at the end; its slot, or `None` when the arena or the node map is full.
    #[inline(always)]
    fn push_vertex(&mut self, node: u32) -> Option<u32> {
        let hole = self.free.wrapping_sub(1);
        let s = if hole != NIL {
            self.free = self.v.fan(hole as usize).wrapping_add(1);
            self.holes = self.holes.saturating_sub(1);
            self.v.fill(hole as usize, node, VISIBLE);
            hole
        } else {
            self.v.push(node, VISIBLE)?
        };
        if !self.map_insert(s) {
            if hole != NIL {
                self.free_vertex(s);
            } else {
                self.v.pop();
            }
            return None;
        }
        Some(s)
    }

    /// Makes slot `s` hold `node` in place of the node it held (no blend; links redone).
    fn rename_vertex(&mut self, h: &HierarchyView<'_>, s: usize, node: u32) {
        self.reassign(s, node);
        self.link_family(h, s as u32);
    }

    /// [`Cut::rename_vertex`] without the links: the caller sets them (slot `s`'s mate too,
    /// so only the old mate's link back is broken here).
    #[inline(always)]
    fn reassign(&mut self, s: usize, node: u32) {
        self.map.remove(self.v.node[s], self.v.nodes());
        let m = self.v.mate(s);
        if m != NIL {
            self.v.set_mate(m as usize, NIL);
        }
        self.free_blend(s);
        self.v.node[s] = node;
        // The old entry was removed, so there is room.
        self.map.insert_new(s as u32, self.v.nodes());
        self.v.flags[s] &= VISIBLE | WAS_VISIBLE;
    }

    /// Links slots `first` and `second`, just given a split's two children (in the order
    /// [`HierarchyView::split`] lists them), as mates: what [`Cut::link_family`] finds for each,
    /// without looking up their parent or each other (both records are adjacent in the file).
    fn link_children(
        &mut self,
        h: &HierarchyView<'_>,
        [first, second]: [u32; 2],
        records: [Record; 2],
    ) {
        let (a, b) = (first as usize, second as usize);
        self.v.digest[a] = h.digest_at(records[0]);
        self.v.digest[b] = h.digest_at(records[1]);
        self.v.flags[a] |= FIRST_CHILD;
        self.v.flags[b] &= !FIRST_CHILD;
        self.v.set_mate(a, second);
        self.v.set_mate(b, first);
    }

    /// Leaves vertex slot `v` (its node already out of the map, its triangles gone or renamed)
    /// empty, to be taken by the next vertex added ([`Cut::push_vertex`]) or filled by the
    /// last at the end of the frame ([`Cut::fill_holes`]). Moving the last vertex into the slot
    /// at once, as [`Cut::remove_vertex`] does, walks the last vertex's fan, which nothing else
    /// in a collapse touches: a frame's collapses leave their slots to its splits instead.
    pub(crate) fn free_vertex(&mut self, v: u32) {
        let i = v as usize;
        self.unlink_mate(i);
        self.free_blend(i);
        self.v.node[i] = NONE;
        self.v.flags[i] = 0;
        self.v.set_fan(i, self.free.wrapping_sub(1));
        self.free = v + 1;
        self.holes += 1;
    }

    /// Fills the slots collapses left empty with the last vertices (dropping the empty ones at
    /// the end), so that the slots in use are the active vertices again.
    pub(crate) fn fill_holes(&mut self) {
        while self.holes > 0 {
            let last = self.v.len() - 1;
            if self.v.node[last] == NONE {
                // Still in the chain, past the end: passed over below.
                self.v.pop();
                self.holes -= 1;
                continue;
            }
            let mut hole = self.free.wrapping_sub(1);
            while hole as usize >= self.v.len() && hole != NIL {
                hole = self.v.fan(hole as usize);
            }
            if hole == NIL {
                // The chain holds fewer than the count (never, as kept): nothing more to fill.
                debug_assert!(false, "{} empty slots not in the chain", self.holes);
                break;
            }
            self.free = self.v.fan(hole as usize).wrapping_add(1);
            self.holes -= 1;
            self.move_last_into(hole);
        }
        self.free = 0;
        self.holes = 0;
    }

    /// Swap-removes vertex slot `v` (its node already out of the map, its triangles gone or
    /// renamed). Returns the slot the last vertex moved from, if it moved.
    fn remove_vertex(&mut self, v: u32) -> Option<u32> {
        self.unlink_mate(v as usize);
        self.free_blend(v as usize);
        let last = self.v.len() as u32 - 1;
        if v == last {
            self.v.pop();
            return None;
        }
        self.move_last_into(v);
        Some(last)
    }

    /// Moves the last vertex into slot `v` (empty, or its vertex removed) and drops the last
    /// slot: its triangles' corners, its map entry, its mate's link and its blend follow it.
    fn move_last_into(&mut self, v: u32) {
        let last = self.v.len() as u32 - 1;
        if !self.rename_fan(last, v) {
            // Only in a cut already broken: every triangle is searched for the rest.
            for f in 0..self.t.len() as u32 {
                while let Some(k) = self.t.corner_of(f, last) {
                    self.t.set_corner(f, k, v);
                }
            }
        }
        let key = self.v.node[last as usize];
        self.map.repoint(key, v, self.v.nodes());
        self.v.copy(last as usize, v as usize);
        let m = self.v.mate(v as usize);
        if m != NIL {
            self.v.set_mate(m as usize, v);
        }
        let b = self.v.blend(v as usize);
        if let Some(entry) = self.blends.as_mut_slice().get_mut(b as usize) {
            entry.slot = v;
        }
        self.v.pop();
    }

    /// Makes slot `to` (which no triangle names) the corner of every triangle around slot
    /// `from` in its place, walking `from`'s fan as it goes (nothing is kept: a kept fan would
    /// cost 4 KiB of stack); whether the walk renamed as many triangles as `from` has.
    fn rename_fan(&mut self, from: u32, to: u32) -> bool {
        if from as usize >= self.v.len() {
            return false;
        }
        let (start, degree) = (
            self.v.fan(from as usize),
            self.v.degree[from as usize] as usize,
        );
        if start == NIL {
            return degree == 0;
        }
        let mut renamed = 0;
        let mut f = start;
        // Counter-clockwise from the fan triangle, round to it or to a border.
        loop {
            let Some((k, g)) = self.t.ccw_at(f, from) else {
                return false;
            };
            self.t.set_corner(f, k, to);
            renamed += 1;
            if g == start {
                return renamed == degree;
            }
            if g == NIL || renamed > degree {
                break;
            }
            f = g;
        }
        // A border: the rest lies clockwise of the fan triangle, which names `to` now.
        let Some((_, mut g)) = self.t.cw_at(start, to) else {
            return false;
        };
        while g != NIL && renamed <= degree {
            let Some((k, next)) = self.t.cw_at(g, from) else {
                return false;
            };
            self.t.set_corner(g, k, to);
            renamed += 1;
            g = next;
        }
        renamed == degree
    }

    /// Swap-removes triangle slot `f`, re-pointing whatever pointed at the moved one.
    fn remove_triangle(&mut self, f: u32) {
        let last = self.t.len() as u32 - 1;
        if f != last {
            let t = self.t.at(last);
            for g in self.t.adj(last) {
                if g == NIL || g >= self.t.len() as u32 {
                    continue;
                }
                self.t.replace_adj(g, last, f);
            }
            for v in t {
                let fan = self.v.fan(v as usize);
                self.v
                    .set_fan(v as usize, select_unpredictable(fan == last, f, fan));
            }
            self.t.copy(last, f);
        }
        self.t.pop();
    }

    /// Splits every active vertex that has children, once (children are not split again in the
    /// same call); returns the splits done. Repeat until it returns 0 for full detail.
    pub fn refine_everything(&mut self, h: &HierarchyView<'_>) -> u32 {
        let mut done = 0;
        let n = self.v.len();
        let mut i = 0;
        while i < n.min(self.v.len()) {
            let v = self.v.node[i];
            if h.is_parent(v) {
                if let Ok(k) = self.force_split(h, v, 0, &mut |_, _| Ok(())) {
                    done += k;
                }
            }
            i += 1;
        }
        done
    }
}

#[cfg(feature = "build")]
impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// An empty cut on the heap, made there directly (a large cut never passes through the
    /// stack, as `Box::new(Cut::new())` may).
    #[must_use]
    #[allow(unsafe_code)]
    pub fn boxed() -> alloc::boxed::Box<Self> {
        let () = Self::CAPACITY_FITS;
        let layout = core::alloc::Layout::new::<Self>();
        // SAFETY: a cut is never zero-sized (it holds its lengths), so `alloc_zeroed` may be
        // called with its layout; a null result is handed to `handle_alloc_error`. Every field of
        // a cut, recursively, is an integer, a float, a `bool`, an array of those or `Coloring`
        // (`repr(u8)`, 0 = `Node`), for all of which the all-zero bytes are a valid value, and
        // all zeros is exactly the state `Cut::new` builds (lengths 0, threshold 0, colouring
        // `Node`; the test `boxed_is_new` compares them); so the pointer is a valid, owned
        // `Self` allocated with the global allocator and `Self`'s layout, as `Box` requires.
        unsafe {
            let p = alloc::alloc::alloc_zeroed(layout).cast::<Self>();
            if p.is_null() {
                alloc::alloc::handle_alloc_error(layout);
            }
            alloc::boxed::Box::from_raw(p)
        }
    }
}

#[cfg(all(test, feature = "build"))]
mod tests;
