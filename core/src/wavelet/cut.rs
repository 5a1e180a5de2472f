//! The wavelet engine's cut: which wavelets are in this frame's mesh, and the crack-free
//! triangles they make.
//!
//! The state is the paper's `U_t` (Azuma et al. §3.4) as one bit per wavelet, and two bits
//! more per wavelet: whether its vertex is in the emitted mesh, and whether it is blending.
//! [`WaveletCut::adapt`] moves it incrementally: a wavelet in `U_t` none of whose children is
//! in it leaves when the policy no longer wants it, and a wavelet both of whose parents are in
//! `U_t` joins when the policy wants it, largest error first, so `U_t` always
//! meets the closure condition (every ancestor of a member is a member). A frame's work is one
//! pass over the members and their children that the anchor below has not settled, a split or
//! removal for each change, and the emission again of the tiles those changes touch (see
//! the `emit` module: the mesh, its vertex slots and the triangles' order outlive the frame).
//!
//! Frame-to-frame coherence (`steady`, on unless
//! [`WaveletCut::set_settling`] turns it off): when the policy describes how its demand moves
//! with the view, an anchor frame proves, for each wavelet it asks, how far the eye and the
//! frustum may move before the answer could change; while the camera stays within that, later
//! frames skip a member that provably stays (wanted, or holding a child that stays) and the
//! children of a member that provably stay unwanted, with one bit each. A wavelet that comes,
//! goes or starts leaving clears its own bits and its parents'. The frames are the same as
//! asking every wavelet (a test flies both side by side).
//!
//! The triangles are emitted as §3.6 describes: every base triangle is subdivided
//! recursively while one of its edge midpoints is in `U_t`; a triangle that is not, but whose
//! neighbour across an edge is, is cut at that edge's midpoint, and each half is tested again, so
//! no T-vertex is left and the mesh has no crack: for a closed input every edge is shared by two
//! triangles run opposite ways ([`WaveletCut::check`], tested after every frame of long camera
//! paths). A vertex that is not in `U_t` (a T-vertex, or the corner of a subdivided triangle whose
//! own wavelet is out) sits at the midpoint of its parent edge, where `rho_t` puts it.
//!
//! The triangle count is kept exactly as wavelets come and go, without emitting: every vertex of
//! the emitted mesh that is not a base vertex adds two triangles (one on a border), and a vertex
//! is in the mesh when one of the two triangles around its parent edge is subdivided (a bit per
//! wavelet remembers which are, so emission tests a leaf's neighbours with one bit each). So the
//! budget is hard: a wavelet joins only when the triangles it brings fit
//! [`Budget::max_triangles`] and the arenas.
//!
//! Geomorphs (§3.5, equation 6) scale a joining or leaving wavelet's coefficient over a set
//! number of frames ([`WaveletCut::set_geomorph_frames`]); they overlap in space and time, and a
//! wavelet turned around mid-way starts from where it is.
//!
//! Memory (`Self::BYTES`, asserted in a test): six bits per wavelet (`24 WORDS`: in the set,
//! holding a member child, a vertex of the emitted mesh, blending, settled, children quiet),
//! 20 B per vertex slot (id, position, uses with two flags, a list link), 12 B per triangle slot
//! (corners as `u16`, vertex map, tile, next in the tile's list), 30 B per queue entry (a
//! candidate, a geomorph, a dirty run and a tile's head: a tile per queue entry at most), and
//! under 512 B of counts, list heads, the previous view and the anchor frame. With `V = T / 2`
//! (a closed mesh has about half as many vertices as triangles) and `Q = T / 8`, that is about
//! 25.8 B per triangle of capacity beside the bits.
//!
//! ```
//! # #[cfg(feature = "build")] {
//! use vdlod_core::adapt::Budget;
//! use vdlod_core::policy::{QRefine, View};
//! use vdlod_core::wavelet::{SemiRegular, SemiRegularView, WaveletCut};
//! let bytes = SemiRegular::sphere(4).unwrap().to_bytes().unwrap(); // 2,048 faces at full detail
//! let s = SemiRegularView::parse(&bytes).unwrap();
//! type Cut = WaveletCut<64, 4096, 2100, 512>;
//! let (mut cut, mut whole) = (Cut::boxed(), Cut::boxed());
//! cut.reset(&s).unwrap();
//! whole.reset(&s).unwrap();
//! whole.set_partial_emission(false); // every frame that changes emits the whole mesh
//! let mut scratch = vec![[0u32; 2]; 3 * 4096];
//! for step in 0..20 {
//!     let a = step as f32 * 0.1;
//!     let eye = [3.0 * libm::cosf(a), 0.5, 3.0 * libm::sinf(a)];
//!     let view = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 0.9, 1.0, 512.0);
//!     let stats = cut.adapt(&s, &view, &QRefine::new(1.0), &Budget::default());
//!     whole.adapt(&s, &view, &QRefine::new(1.0), &Budget::default());
//!     assert!(stats.triangles > 8 && stats.triangles < 2048);
//!     // The same mesh either way, without a crack.
//!     assert_eq!(cut.triangles().len(), whole.triangles().len());
//!     assert!(cut.check(&s, true, &mut scratch).is_ok());
//! }
//! # }
//! ```

use crate::adapt::{Budget, FrameStats};
use crate::cut::margin::Margins;
use crate::cut::slot::{Arena, SlotIndex};
use crate::cut::NIL;
use crate::nodemap::NodeMap;
use crate::policy::{dot, sub, Bounds, Demand, Policy, View};

use super::format::SemiRegularView;
use super::lattice::{Point, DIRECTIONS};

mod emit;
mod steady;

use steady::{Mode, Steady};

/// Why a cut cannot hold a semi-regular mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaveletCutError {
    /// The bit set has fewer bits than the mesh has wavelets.
    Bits {
        /// Wavelets of the mesh.
        wavelets: u32,
        /// Bits of the cut.
        bits: u32,
    },
    /// The base mesh has more faces than the cut has tiles (one per queue entry: at least
    /// one per base face).
    Tiles {
        /// Base triangles.
        faces: u32,
        /// Tiles of the cut.
        tiles: u32,
    },
    /// The base mesh alone does not fit the arenas.
    Capacity {
        /// Base vertices.
        vertices: u32,
        /// Base triangles.
        triangles: u32,
    },
}

impl core::fmt::Display for WaveletCutError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Bits { wavelets, bits } => write!(
                f,
                "the mesh has {wavelets} wavelets, the cut holds {bits} bits (raise WORDS)"
            ),
            Self::Tiles { faces, tiles } => write!(
                f,
                "the base mesh has {faces} faces, the cut {tiles} tiles (one per queue entry: raise Q)"
            ),
            Self::Capacity {
                vertices,
                triangles,
            } => write!(
                f,
                "the base mesh ({vertices} vertices, {triangles} triangles) does not fit the cut"
            ),
        }
    }
}

impl core::error::Error for WaveletCutError {}

/// What [`WaveletCut::check`] found wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WaveletDefect(pub &'static str);

impl core::fmt::Display for WaveletDefect {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.0)
    }
}

/// An arena filled up while emitting.
#[derive(Debug)]
struct Full;

/// Relative slack on the settling proofs' thresholds, far above float rounding.
const SLACK: f32 = 1.0 + 1e-5;

/// The level given to a piece's edges inside its leaf triangle (never tested for a neighbour).
const INSIDE: u32 = u32::MAX;

/// Whether wavelet vertex `id` is in the set `bits` of a mesh with `base` base vertices and
/// `wavelets` wavelets.
#[inline]
fn has(bits: &[u32], base: u32, wavelets: u32, id: u32) -> bool {
    let w = id.wrapping_sub(base);
    w < wavelets
        && bits
            .get((w / 32) as usize)
            .is_some_and(|b| b >> (w % 32) & 1 == 1)
}

/// Sets or clears wavelet vertex `id`'s bit in `bits` (see [`has`]).
#[inline]
fn put(bits: &mut [u32], base: u32, id: u32, on: bool) {
    let w = id.wrapping_sub(base);
    if let Some(word) = bits.get_mut((w / 32) as usize) {
        let bit = 1 << (w % 32);
        if on {
            *word |= bit;
        } else {
            *word &= !bit;
        }
    }
}

/// The wavelets in a frame's mesh as bits, and the triangles they make, in fixed arenas: up to
/// `32 WORDS` wavelets, `T` triangles, `V` vertices and `Q` candidates waiting to join,
/// indices stored as `I`.
pub struct WaveletCut<
    const WORDS: usize,
    const T: usize,
    const V: usize,
    const Q: usize,
    I: SlotIndex = u16,
> {
    included: [u32; WORDS],
    /// The wavelets with a child in the set, kept as wavelets come and go.
    holding: [u32; WORDS],
    /// The wavelets whose vertex is in the emitted mesh (in, or a T-vertex or corner of a
    /// subdivided triangle), kept as wavelets come and go.
    present: [u32; WORDS],
    base_vertices: u32,
    base_faces: u32,
    wavelets: u32,
    levels: u32,
    /// The emitted mesh's counts, kept as wavelets come and go.
    triangles: u32,
    vertices: u32,
    /// Per vertex slot: its vertex id (`NIL` when freed), position, uses by triangles (with the
    /// flags [`emit::PENDING`] and [`emit::MOVED`]) and link in the pending or free list (see
    /// [`emit`]).
    ids: Arena<u32, V>,
    positions: [[f32; 3]; V],
    uses: [u16; V],
    link: [I; V],
    free: u32,
    freed: u32,
    pending: u32,
    /// Per triangle slot: its corners, its tile, and the next triangle in the tile's list.
    tris: Arena<[I; 3], T>,
    owner: [u16; T],
    next: [I; T],
    spare: u32,
    /// Per tile, its first triangle; the tiles' level and count (see [`emit`]).
    head: [I; Q],
    tile_level: u32,
    tiles: u32,
    /// Runs of tiles to emit again (the first tile shifted by four bits over 15 less the
    /// base-4 logarithm of the run's length), and whether the mesh emitted is the set's apart
    /// from them (`false`: emit it all).
    dirty: Arena<u32, Q>,
    built: bool,
    /// Whether a frame that changes anything emits the whole mesh (see
    /// [`WaveletCut::set_partial_emission`]).
    whole: bool,
    /// Whether the whole mesh is being emitted now (every slot placed in this pass).
    all: bool,
    map: NodeMap<T, I>,
    heap: Arena<(u32, u32), Q>,
    threshold: f32,
    /// Running geomorphs, sorted by wavelet vertex id, and their wavelets as bits.
    morphs: Arena<Morph, Q>,
    morphing: [u32; WORDS],
    geomorph_frames: u16,
    /// The previous frame's view (valid with `has_previous`).
    previous: View,
    has_previous: bool,
    /// Frame-to-frame coherence (`steady`): the anchor
    /// frame, and per wavelet whether its answer provably holds while the anchor does
    /// (`settled`: a member with nothing to do, or a candidate the policy does not want) and,
    /// for a member, whether none of its children out of the set is wanted (`quiet`).
    steady: Steady,
    settled: [u32; WORDS],
    quiet: [u32; WORDS],
}

/// One running geomorph (Azuma et al. §3.5, equation 6): the wavelet's coefficient is scaled by
/// `weight`, which moves by `step` each frame, up to 1 for a wavelet joining and down to 0 for
/// one leaving (which then leaves, once no child of it is left).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Morph {
    id: u32,
    weight: f32,
    step: f32,
    leaving: bool,
}

impl Morph {
    const ZERO: Morph = Morph {
        id: 0,
        weight: 0.0,
        step: 0.0,
        leaving: false,
    };
}

impl<const WORDS: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex> Default
    for WaveletCut<WORDS, T, V, Q, I>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const WORDS: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex>
    core::fmt::Debug for WaveletCut<WORDS, T, V, Q, I>
{
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("WaveletCut")
            .field("triangles", &self.triangles)
            .field("vertices", &self.vertices)
            .field("capacity", &(WORDS * 32, T, V, Q))
            .field("bytes", &Self::BYTES)
            .finish()
    }
}

impl<const WORDS: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex>
    WaveletCut<WORDS, T, V, Q, I>
{
    /// Bytes of memory the cut occupies (it allocates nothing).
    pub const BYTES: usize = core::mem::size_of::<Self>();

    const CAPACITY_FITS: () = assert!(
        V < I::LIMIT && T < I::LIMIT,
        "a cut's vertex and triangle capacities must be below 65,535 with u16 indices"
    );

    /// An empty cut, all zeros (a `static` lands in `.bss`); [`WaveletCut::reset`] loads a
    /// mesh's base.
    #[must_use]
    pub const fn new() -> Self {
        let () = Self::CAPACITY_FITS;
        WaveletCut {
            included: [0; WORDS],
            holding: [0; WORDS],
            present: [0; WORDS],
            base_vertices: 0,
            base_faces: 0,
            wavelets: 0,
            levels: 0,
            triangles: 0,
            vertices: 0,
            ids: Arena::new(0),
            positions: [[0.0; 3]; V],
            uses: [0; V],
            link: [I::ZERO; V],
            free: 0,
            freed: 0,
            pending: 0,
            tris: Arena::new([I::ZERO; 3]),
            owner: [0; T],
            next: [I::ZERO; T],
            spare: 0,
            head: [I::ZERO; Q],
            tile_level: 0,
            tiles: 0,
            dirty: Arena::new(0),
            built: false,
            whole: false,
            all: false,
            map: NodeMap::new(),
            heap: Arena::new((0, 0)),
            threshold: 0.0,
            morphs: Arena::new(Morph::ZERO),
            morphing: [0; WORDS],
            geomorph_frames: 0,
            previous: View::ZERO,
            has_previous: false,
            steady: Steady::ZERO,
            settled: [0; WORDS],
            quiet: [0; WORDS],
        }
    }

    /// A cut on the heap, built in place (never on the stack).
    #[cfg(feature = "build")]
    #[must_use]
    pub fn boxed() -> alloc::boxed::Box<Self> {
        // All-zero bytes are `new()` (its fields are integers, floats and arrays of them).
        let layout = core::alloc::Layout::new::<Self>();
        if layout.size() == 0 {
            return alloc::boxed::Box::new(Self::new());
        }
        // SAFETY: the layout has a non-zero size, the memory is zeroed (which is a valid
        // `Self`, the state `new` returns), and `Box` takes it with the same layout.
        #[allow(unsafe_code)]
        unsafe {
            let p = alloc::alloc::alloc_zeroed(layout) as *mut Self;
            if p.is_null() {
                alloc::alloc::handle_alloc_error(layout);
            }
            alloc::boxed::Box::from_raw(p)
        }
    }

    /// Replaces the cut by `s`'s base mesh (no wavelet in).
    pub fn reset(&mut self, s: &SemiRegularView<'_>) -> Result<(), WaveletCutError> {
        let c = s.counts();
        let bits = (WORDS * 32).min(u32::MAX as usize) as u32;
        if s.wavelets() > bits {
            return Err(WaveletCutError::Bits {
                wavelets: s.wavelets(),
                bits,
            });
        }
        if c.base_faces as usize > T || c.base_vertices as usize > V.min(self.map.capacity()) {
            return Err(WaveletCutError::Capacity {
                vertices: c.base_vertices,
                triangles: c.base_faces,
            });
        }
        let tile_level =
            Self::tile_level_for(c.base_faces, c.levels).ok_or(WaveletCutError::Tiles {
                faces: c.base_faces,
                tiles: Self::TILES,
            })?;
        self.included.iter_mut().for_each(|w| *w = 0);
        self.holding.iter_mut().for_each(|w| *w = 0);
        self.present.iter_mut().for_each(|w| *w = 0);
        self.morphing.iter_mut().for_each(|w| *w = 0);
        self.settled.iter_mut().for_each(|w| *w = 0);
        self.quiet.iter_mut().for_each(|w| *w = 0);
        self.steady.clear();
        self.morphs.clear();
        self.has_previous = false;
        self.base_vertices = c.base_vertices;
        self.base_faces = c.base_faces;
        self.wavelets = s.wavelets();
        self.levels = c.levels;
        self.triangles = c.base_faces;
        self.vertices = c.base_vertices;
        self.threshold = 1.0;
        self.tile_level = tile_level;
        self.tiles = c.base_faces << (2 * self.tile_level);
        self.built = false;
        // The base mesh fits, so emitting it cannot fail. A base vertex no face uses (a file
        // may hold one) is not in the mesh.
        let _complete = self.emit(s);
        debug_assert!(_complete);
        self.vertices = self.live_vertices() as u32;
        Ok(())
    }

    #[inline]
    fn morphing_bit(&self, id: u32) -> bool {
        has(&self.morphing, self.base_vertices, self.wavelets, id)
    }

    /// The first member whose wavelet index is `from` or more, as a vertex id (members may come
    /// and go behind it while a loop walks them).
    fn member_from(&self, from: u32) -> Option<u32> {
        let words = (self.wavelets as usize).div_ceil(32).min(WORDS);
        let mut word = (from / 32) as usize;
        let mut bits = self.included.get(word)? & (u32::MAX << (from % 32));
        loop {
            if bits != 0 {
                return Some(self.base_vertices + word as u32 * 32 + bits.trailing_zeros());
            }
            word += 1;
            if word >= words {
                return None;
            }
            bits = self.included[word];
        }
    }

    /// Whether wavelet vertex `id` is in this frame's mesh.
    #[inline]
    #[must_use]
    pub fn includes(&self, id: u32) -> bool {
        has(&self.included, self.base_vertices, self.wavelets, id)
    }

    /// Wavelets in this frame's mesh.
    #[must_use]
    pub fn included(&self) -> u32 {
        self.included.iter().map(|w| w.count_ones()).sum()
    }

    /// The regulated error threshold (1 after [`WaveletCut::reset`]).
    #[must_use]
    pub fn threshold(&self) -> f32 {
        self.threshold
    }

    /// The emitted triangles, as vertex slots.
    #[must_use]
    pub fn triangles(&self) -> &[[I; 3]] {
        self.tris.as_slice()
    }

    /// Vertex slots in use or freed: the triangles index below this. A freed slot (a hole
    /// left for a later vertex, so that the others keep their slots) has id `u32::MAX`; holes
    /// stay fewer than half the live vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.ids.len()
    }

    /// Vertex slots the triangles use (the mesh's vertices).
    #[must_use]
    pub fn live_vertices(&self) -> usize {
        self.ids.len() - self.freed as usize
    }

    /// The mesh vertex id of vertex slot `i` (see [`super::format`]; `u32::MAX` out of range
    /// and for a freed slot).
    #[must_use]
    pub fn vertex_id(&self, i: usize) -> u32 {
        self.ids.as_slice().get(i).copied().unwrap_or(NIL)
    }

    /// The position of vertex slot `i` in this frame: its own for a base vertex or a wavelet in
    /// the mesh, the midpoint of its parent edge for any other.
    #[must_use]
    pub fn position(&self, i: usize) -> [f32; 3] {
        self.positions.get(i).copied().unwrap_or([0.0; 3])
    }

    /// The policy's demand for wavelet vertex `id` (canonical point `p`). A policy that judges triangles
    /// ([`Policy::judges_triangles`], the importance paper's) also speaks through the two
    /// triangles of the level above that the wavelet subdivides (the ones around its parent
    /// edge): when either is important the wavelet is wanted, which is the paper's rule that an
    /// important triangle splits everything it can. Those triangles are coarser than the
    /// wavelet, so its coming and going never changes its own verdict.
    #[inline]
    fn demand<P: Policy>(
        s: &SemiRegularView<'_>,
        id: u32,
        p: Point,
        view: &View,
        policy: &P,
    ) -> Demand {
        let b = s.bounds_at(p, id);
        let d = policy.demand(&b, view);
        if !policy.judges_triangles() {
            return d;
        }
        let [x, y] = s.parent_edge(p, s.level(p));
        let at = |q: Point| {
            s.canonical(q)
                .and_then(|c| Some(s.position_at(c, s.vertex_id(c)?)))
        };
        let (Some(a), Some(c)) = (at(x), at(y)) else {
            return d;
        };
        // Counter-clockwise: `x, y, left` and `y, x, right` (a border edge has one side).
        let triangles = [
            at(x.left_of(y)).map(|l| [a, c, l]),
            at(x.right_of(y)).map(|r| [c, a, r]),
        ]
        .into_iter()
        .flatten()
        .fold(0.0f32, |e, corners| {
            e.max(policy.triangle(&corners, b.radius, view))
        });
        d.raised(triangles)
    }

    #[inline]
    fn flip(&mut self, id: u32) {
        let w = id.wrapping_sub(self.base_vertices) as usize;
        if let Some(word) = self.included.get_mut(w / 32) {
            *word ^= 1 << (w % 32);
        }
    }

    /// Whether canonical point `v` (at level `level`) is a vertex of the emitted mesh (one of
    /// the two triangles around its parent edge is subdivided), and how many triangles it then
    /// adds: one per side of that edge (two inside, one on a border).
    fn presence(&self, s: &SemiRegularView<'_>, v: Point, level: u32) -> (bool, u32) {
        let [x, y] = s.parent_edge(v, level);
        let inc = |id| has(&self.included, self.base_vertices, self.wavelets, id);
        let mut sides = 0;
        let mut split = false;
        for (a, b, c) in [(x, y, x.left_of(y)), (y, x, x.right_of(y))] {
            if s.canonical(c).is_some() {
                sides += 1;
                split |= s.subdivided(a, b, c, inc);
            }
        }
        (split, sides)
    }

    /// Whether wavelet vertex `id` is in the emitted mesh.
    #[inline]
    fn is_present(&self, id: u32) -> bool {
        has(&self.present, self.base_vertices, self.wavelets, id)
    }

    /// Adds or removes wavelet `p` (vertex `id`, at `level`), updates the counts and marks
    /// what the emitted mesh must change. The points whose presence can change are the edge
    /// midpoints of the two triangles around its parent edge (`p` first).
    fn toggle(&mut self, s: &SemiRegularView<'_>, id: u32, p: Point, level: u32) {
        let [x, y] = s.parent_edge(p, level);
        let (l, r) = (x.left_of(y), x.right_of(y));
        self.flip(id);
        self.unsettle(s, id, p, level);
        // A parent holds a member child now if this one joined, else only if another is in.
        let joined = self.includes(id);
        for q in s.parents(p, level) {
            let holds = joined
                || s.point(q)
                    .is_some_and(|pq| self.scan_children(s, pq, s.level(pq), false));
            put(&mut self.holding, self.base_vertices, q, holds);
        }
        let mut changed = [NIL; 5];
        for (k, m) in [p, y.mid(l), l.mid(x), x.mid(r), r.mid(y)]
            .into_iter()
            .enumerate()
        {
            let Some(q) = s.canonical(m) else { continue };
            let Some(vid) = s.vertex_id(q) else { continue };
            let (now, sides) = self.presence(s, q, s.level(q));
            if now == self.is_present(vid) {
                continue;
            }
            changed[k] = vid;
            let w = vid.wrapping_sub(self.base_vertices) as usize;
            if let Some(word) = self.present.get_mut(w / 32) {
                *word ^= 1 << (w % 32);
            }
            if now {
                self.vertices += 1;
                self.triangles += sides;
            } else {
                self.vertices = self.vertices.saturating_sub(1);
                self.triangles = self.triangles.saturating_sub(sides);
            }
        }
        // An edge whose midpoint appeared or vanished changes the triangle across it.
        self.mark_wavelet(s, p, level, &changed);
    }

    /// Whether any child of wavelet `id` (at `p`, `level`) is in the mesh (with `staying`, only
    /// children that are not leaving count): its kept bit, and the children themselves only
    /// when some may be leaving.
    #[inline]
    fn any_child_in(
        &self,
        s: &SemiRegularView<'_>,
        (id, p): (u32, Point),
        level: u32,
        staying: bool,
    ) -> bool {
        has(&self.holding, self.base_vertices, self.wavelets, id)
            && (!staying || self.morphs.len() == 0 || self.scan_children(s, p, level, true))
    }

    /// [`Self::any_child_in`] from the children themselves.
    fn scan_children(&self, s: &SemiRegularView<'_>, p: Point, level: u32, staying: bool) -> bool {
        s.children(p, level).iter().flatten().any(|&c| {
            s.vertex_id(c)
                .is_some_and(|id| self.includes(id) && !(staying && self.leaving(id)))
        })
    }

    /// Geomorphs last `frames` frames (0, the default: none). Wavelets that join or leave
    /// because of the frustum or back-face tests never blend.
    pub fn set_geomorph_frames(&mut self, frames: u16) {
        self.geomorph_frames = frames;
    }

    /// Wavelets in a running geomorph.
    #[must_use]
    pub fn blending(&self) -> u32 {
        self.morphs.len() as u32
    }

    /// Where wavelet `id`'s geomorph is in the sorted arena (`Err`: where it would go).
    fn morph_at(&self, id: u32) -> Result<usize, usize> {
        if !has(&self.morphing, self.base_vertices, self.wavelets, id) {
            return Err(0);
        }
        self.morphs.as_slice().binary_search_by_key(&id, |m| m.id)
    }

    /// The weight of wavelet `id`'s coefficient: 1 unless it is in a geomorph.
    #[inline]
    fn weight(&self, id: u32) -> f32 {
        match self.morph_at(id) {
            Ok(i) => self.morphs.as_slice()[i].weight,
            Err(_) => 1.0,
        }
    }

    /// Whether wavelet `id` is leaving in a geomorph.
    #[inline]
    fn leaving(&self, id: u32) -> bool {
        self.morph_at(id)
            .is_ok_and(|i| self.morphs.as_slice()[i].leaving)
    }

    fn set_morphing(&mut self, id: u32, on: bool) {
        let w = id.wrapping_sub(self.base_vertices) as usize;
        if let Some(word) = self.morphing.get_mut(w / 32) {
            if on {
                *word |= 1 << (w % 32);
            } else {
                *word &= !(1 << (w % 32));
            }
        }
    }

    /// Forgets what the anchor frame proved about wavelet `id` (at `p`, `level`) and its
    /// parents: it came, went or started leaving, which changes what they have to do.
    fn unsettle(&mut self, s: &SemiRegularView<'_>, id: u32, p: Point, level: u32) {
        let base = self.base_vertices;
        for q in core::iter::once(id).chain(s.parents(p, level)) {
            if q != NIL {
                put(&mut self.settled, base, q, false);
                put(&mut self.quiet, base, q, false);
            }
        }
    }

    /// Whether frames skip the wavelets whose answers cannot have changed since an anchor
    /// frame (on by default). The frames are the same either way; only their time differs.
    pub fn set_settling(&mut self, on: bool) {
        self.steady.set_on(on);
    }

    /// Whether a frame emits again only the tiles its changes touch (on by default) or, in
    /// any frame that changes anything, the whole mesh. The triangles and positions are the
    /// same either way, in another order; only the time differs.
    pub fn set_partial_emission(&mut self, on: bool) {
        self.whole = !on;
    }

    /// Starts (or turns around) wavelet `id`'s geomorph towards leaving or towards staying,
    /// from where it is, over the set number of frames (`frames` 0: at once); `false` when the
    /// arena is full.
    fn start_morph(
        &mut self,
        s: &SemiRegularView<'_>,
        id: u32,
        leaving: bool,
        frames: u16,
    ) -> bool {
        let n = frames.max(1) as f32;
        let at = self.morph_at(id);
        let mut weight = match at {
            Ok(i) => self.morphs.as_slice()[i].weight,
            Err(_) if leaving => 1.0,
            Err(_) => 0.0,
        };
        let step = match (leaving, frames) {
            (true, 0) => {
                // Left the view: gone as soon as its children are.
                weight = 0.0;
                0.0
            }
            (true, _) => -weight / n,
            (false, _) => (1.0 - weight) / n,
        };
        let morph = Morph {
            id,
            weight,
            step,
            leaving,
        };
        self.mark_blend(s, id);
        match at {
            Ok(i) => self.morphs.as_mut_slice()[i] = morph,
            Err(_) => {
                let i = self.morphs.as_slice().partition_point(|m| m.id < id);
                if self.morphs.push(morph).is_err() {
                    return false;
                }
                self.morphs.as_mut_slice()[i..].rotate_right(1);
                self.set_morphing(id, true);
            }
        }
        true
    }

    /// Ends wavelet `id`'s geomorph, if any.
    fn end_morph(&mut self, s: &SemiRegularView<'_>, id: u32) {
        if let Ok(i) = self.morph_at(id) {
            self.morphs.as_mut_slice()[i..].rotate_left(1);
            self.morphs.pop();
            self.set_morphing(id, false);
            self.mark_blend(s, id);
        }
    }

    /// One frame of every geomorph: weights move; joined wavelets stop blending.
    fn advance_morphs(&mut self, s: &SemiRegularView<'_>) {
        let mut i = 0;
        while i < self.morphs.len() {
            let m = &mut self.morphs.as_mut_slice()[i];
            let was = m.weight;
            m.weight = (m.weight + m.step).clamp(0.0, 1.0);
            let (id, moved) = (m.id, m.weight != was);
            if !m.leaving && m.weight >= 1.0 {
                self.end_morph(s, id);
            } else {
                if moved {
                    self.mark_blend(s, id);
                }
                i += 1;
            }
        }
    }

    /// Removes the leaving wavelets whose weight reached 0 and whose children are gone
    /// (children first, so a parent that finished with them goes in the same frame).
    fn finish_leaving(&mut self, s: &SemiRegularView<'_>) {
        loop {
            let mut done = false;
            let mut i = 0;
            while i < self.morphs.len() {
                let m = self.morphs.as_slice()[i];
                let gone = m.leaving
                    && m.weight <= 0.0
                    && s.point(m.id).is_some_and(|p| {
                        let level = s.level(p);
                        !self.any_child_in(s, (m.id, p), level, false)
                    });
                if gone {
                    if let Some(p) = s.point(m.id) {
                        self.toggle(s, m.id, p, s.level(p));
                    }
                    self.end_morph(s, m.id);
                    done = true;
                } else {
                    i += 1;
                }
            }
            if !done {
                break;
            }
        }
    }

    /// Moves the cut for one frame seen from `view`: running geomorphs advance; wavelets the
    /// policy no longer wants leave (finest first: a wavelet may start leaving once its
    /// children are leaving, and is gone once they are); then wanted wavelets whose parents
    /// are in join, largest error first, while [`Budget::max_triangles`], [`Budget::max_ops`]
    /// and the arenas allow; then the triangles are emitted.
    ///
    /// With geomorphs ([`WaveletCut::set_geomorph_frames`]) a wavelet joins with its coefficient
    /// scaled from 0 to 1 and leaves scaled from where it is to 0 (the paper's equation 6); a
    /// wavelet and its descendants may blend at the same time, and a wavelet the policy wants
    /// back while leaving turns around from where it is. Wavelets that join or leave because
    /// they entered or left the view (frustum or back-face) do so at once.
    pub fn adapt<P: Policy>(
        &mut self,
        s: &SemiRegularView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
    ) -> FrameStats {
        let mut stats = FrameStats::default();
        if self.wavelets != s.wavelets() || self.base_faces != s.counts().base_faces {
            // Not reset with this mesh: nothing to do safely.
            stats.capacity_limited = true;
            return stats;
        }
        let t = self.threshold;
        let max_triangles = budget.max_triangles.min(T as u32);
        let max_vertices = (V.min(self.map.capacity()) as u32).max(self.base_vertices);
        let mut ops = 0u32;
        self.advance_morphs(s);
        self.finish_leaving(s);

        // Settled wavelets are skipped while the anchor holds; an anchor frame marks them anew.
        let envelope = if policy.judges_triangles() {
            None
        } else {
            policy.envelope(view)
        };
        let (lo, hi) = s.bounding_box();
        let half: [f32; 3] = core::array::from_fn(|k| 0.5 * (hi[k] - lo[k]));
        let model = (
            core::array::from_fn(|k| lo[k] + half[k]),
            crate::root::sqrtf(half[0] * half[0] + half[1] * half[1] + half[2] * half[2]),
        );
        let mode = self
            .steady
            .begin(view, envelope, t, self.geomorph_frames > 0, model);
        let skip = mode == Mode::Skip;
        let anchor = (mode == Mode::Anchor).then(|| {
            self.settled.iter_mut().for_each(|w| *w = 0);
            self.quiet.iter_mut().for_each(|w| *w = 0);
            self.steady.margins(t, SLACK, model)
        });

        // Coarsen: a member none of whose children stays leaves when unwanted (blending unless
        // it left the view); its parents may follow in the next pass.
        'coarsen: loop {
            let mut changed = false;
            let mut next = 0;
            while let Some(id) = self.member_from(next) {
                next = id - self.base_vertices + 1;
                if skip && self.settled_bit(id) {
                    stats.settled += 1;
                    continue;
                }
                let Some(p) = s.point(id) else { continue };
                let level = s.level(p);
                let leaving = self.leaving(id);
                if !leaving && self.any_child_in(s, (id, p), level, true) {
                    if anchor.is_some() {
                        // Stays while that child does (whose coming and going unsettles it).
                        put(&mut self.settled, self.base_vertices, id, true);
                    }
                    continue;
                }
                let d = Self::demand(s, id, p, view, policy);
                let wanted = d.visible && d.error > t;
                if let Some(m) = &anchor {
                    if wanted
                        && !leaving
                        && self.steady.stays_wanted(m, &s.bounds_at(p, id), t, SLACK)
                    {
                        put(&mut self.settled, self.base_vertices, id, true);
                    }
                }
                if leaving {
                    if wanted {
                        // Wanted back: it turns around where it is.
                        self.start_morph(s, id, false, self.geomorph_frames);
                    }
                    continue;
                }
                if wanted {
                    continue;
                }
                if ops >= budget.max_ops {
                    stats.ops_limited = true;
                    break 'coarsen;
                }
                let children = self.any_child_in(s, (id, p), level, false);
                let frames = if d.visible { self.geomorph_frames } else { 0 };
                // Leaving changes what its parents have to do.
                self.unsettle(s, id, p, level);
                if (frames == 0 && !children) || !self.start_morph(s, id, true, frames) {
                    if children {
                        stats.blend_limited = true;
                        continue;
                    }
                    self.end_morph(s, id);
                    self.toggle(s, id, p, level);
                }
                ops += 1;
                stats.ecols += 1;
                changed = true;
            }
            if !changed {
                break;
            }
        }
        self.finish_leaving(s);

        if self.triangles > max_triangles || self.vertices > max_vertices {
            self.enforce_max(s, view, policy, max_triangles, max_vertices, &mut stats);
        }

        // Refine: candidates are the level-1 wavelets and the children of members whose
        // parents are all in; the heap hands out the largest error first.
        self.heap.clear();
        let n = s.steps() as u32;
        for e in 0..s.counts().base_edges {
            let id = self.base_vertices + e * (n - 1) + n / 2 - 1;
            if skip && self.settled_bit(id) {
                stats.settled += 1;
                continue;
            }
            if let (false, Some(p)) = (self.includes(id), s.point(id)) {
                if let Some(m) = &anchor {
                    if self.stays_unwanted(m, &s.bounds_at(p, id), view) {
                        put(&mut self.settled, self.base_vertices, id, true);
                    }
                }
                self.offer(s, (id, p), view, policy, t, &mut stats);
            }
        }
        let mut next = 0;
        while let Some(id) = self.member_from(next) {
            next = id - self.base_vertices + 1;
            if skip && has(&self.quiet, self.base_vertices, self.wavelets, id) {
                stats.settled += 1;
                continue;
            }
            if !self.leaving(id) {
                if let Some(m) = &anchor {
                    if self.children_stay_unwanted(s, id, m, view) {
                        put(&mut self.quiet, self.base_vertices, id, true);
                    }
                }
                self.offer_children(s, id, true, view, policy, t, &mut stats);
            }
        }
        while let Some((_, id)) = self.heap.heap_pop() {
            if self.includes(id) {
                continue;
            }
            if ops >= budget.max_ops {
                stats.ops_limited = true;
                break;
            }
            let Some(p) = s.point(id) else { continue };
            let level = s.level(p);
            self.toggle(s, id, p, level);
            let (over_t, over_v) = (self.triangles > max_triangles, self.vertices > max_vertices);
            if over_t || over_v {
                self.toggle(s, id, p, level);
                if over_t && !over_v && max_triangles == budget.max_triangles {
                    stats.budget_limited = true;
                } else {
                    stats.capacity_limited = true;
                }
                break;
            }
            // It blends in unless it just came into view.
            if self.geomorph_frames > 0
                && self.has_previous
                && policy.demand(&s.bounds_at(p, id), &self.previous).visible
                && !self.start_morph(s, id, false, self.geomorph_frames)
            {
                stats.blend_limited = true;
            }
            ops += 1;
            stats.vsplits += 1;
            self.offer_children(s, id, false, view, policy, t, &mut stats);
        }
        self.heap.clear();

        if !self.emit(s) {
            stats.capacity_limited = true;
        }
        if anchor.is_some() {
            let settled: u32 = self.settled.iter().map(|w| w.count_ones()).sum();
            self.steady
                .anchored(settled as usize, self.included() as usize);
        }
        self.previous = *view;
        self.has_previous = true;
        self.threshold = budget.regulate(self.threshold, self.triangles);
        stats.triangles = self.tris.len() as u32;
        stats.vertices = self.live_vertices() as u32;
        stats.threshold = t;
        stats.blending = self.blending();
        stats.over_budget = stats.triangles > budget.max_triangles;
        stats
    }

    #[inline]
    fn settled_bit(&self, id: u32) -> bool {
        has(&self.settled, self.base_vertices, self.wavelets, id)
    }

    /// Whether a wavelet with bounds `b` provably stays unwanted while the anchor holds (see
    /// [`Steady::stays_unwanted`]).
    fn stays_unwanted(&self, m: &Margins, b: &Bounds, view: &View) -> bool {
        let r = sub(b.center, view.eye);
        self.steady.stays_unwanted(
            m,
            crate::root::sqrtf(b.a2.max(b.b2)),
            (b.center, b.radius),
            dot(r, r),
        )
    }

    /// Whether every child of member `id` out of the set provably stays unwanted while the
    /// anchor holds (whether it may join yet or not).
    fn children_stay_unwanted(
        &self,
        s: &SemiRegularView<'_>,
        id: u32,
        m: &Margins,
        view: &View,
    ) -> bool {
        let Some(p) = s.point(id) else { return false };
        s.children(p, s.level(p)).into_iter().flatten().all(|c| {
            s.vertex_id(c).is_some_and(|cid| {
                self.includes(cid) || self.stays_unwanted(m, &s.bounds_at(c, cid), view)
            })
        })
    }

    /// Removes members with no member child, smallest error first, until the mesh fits
    /// `max_triangles` and `max_vertices` (a lowered budget; the hard limit wins over
    /// [`Budget::max_ops`]).
    fn enforce_max<P: Policy>(
        &mut self,
        s: &SemiRegularView<'_>,
        view: &View,
        policy: &P,
        max_triangles: u32,
        max_vertices: u32,
        stats: &mut FrameStats,
    ) {
        let priority = |id: u32, p: Point| {
            let d = Self::demand(s, id, p, view, policy);
            !(if d.visible { d.error.max(0.0) } else { 0.0 }).to_bits()
        };
        self.heap.clear();
        let mut next = 0;
        while let Some(id) = self.member_from(next) {
            next = id - self.base_vertices + 1;
            let Some(p) = s.point(id) else { continue };
            if !self.any_child_in(s, (id, p), s.level(p), false)
                && self.heap.heap_push((priority(id, p), id)).is_err()
            {
                stats.queue_overflow = true;
            }
        }
        while self.triangles > max_triangles || self.vertices > max_vertices {
            let Some((_, id)) = self.heap.heap_pop() else {
                break;
            };
            let Some(p) = s.point(id) else { continue };
            let level = s.level(p);
            if !self.includes(id) || self.any_child_in(s, (id, p), level, false) {
                continue;
            }
            self.end_morph(s, id);
            self.toggle(s, id, p, level);
            stats.ecols += 1;
            stats.budget_ecols += 1;
            for q in s.parents(p, level) {
                let Some(pq) = s.point(q) else { continue };
                if self.includes(q)
                    && !self.any_child_in(s, (q, pq), s.level(pq), false)
                    && self.heap.heap_push((priority(q, pq), q)).is_err()
                {
                    stats.queue_overflow = true;
                }
            }
        }
        self.heap.clear();
    }

    /// Puts wavelet `id` (canonical point `p`) on the heap if the policy wants it.
    fn offer<P: Policy>(
        &mut self,
        s: &SemiRegularView<'_>,
        (id, p): (u32, Point),
        view: &View,
        policy: &P,
        t: f32,
        stats: &mut FrameStats,
    ) {
        let d = Self::demand(s, id, p, view, policy);
        if d.visible && d.error > t && self.heap.heap_push((d.error.to_bits(), id)).is_err() {
            stats.queue_overflow = true;
        }
    }

    /// Offers the children of member `id` that may join now (in a `sweep` over the members,
    /// only those whose first parent is `id`).
    #[allow(clippy::too_many_arguments)]
    fn offer_children<P: Policy>(
        &mut self,
        s: &SemiRegularView<'_>,
        id: u32,
        sweep: bool,
        view: &View,
        policy: &P,
        t: f32,
        stats: &mut FrameStats,
    ) {
        let Some(p) = s.point(id) else { return };
        let level = s.level(p);
        if level >= self.levels || self.leaving(id) {
            return;
        }
        // Child `p + h d` has the parent edge from `p` to `q = p + 2h d`: its parents are `p`
        // and `q` when `q` is of `p`'s level (as `joinable_from` finds, without unfolding the
        // child's frame again).
        let h = s.step_of(level + 1);
        for d in DIRECTIONS {
            let Some(c) = s.canonical(p.offset(d, h)) else {
                continue;
            };
            let Some(cid) = s.vertex_id(c) else { continue };
            if self.includes(cid) {
                continue;
            }
            let Some(q) = s.canonical(p.offset(d, 2 * h)) else {
                continue;
            };
            if s.level(q) == level {
                let Some(qid) = s.vertex_id(q) else { continue };
                if !self.includes(qid) || self.leaving(qid) || (sweep && qid < id) {
                    continue;
                }
            }
            self.offer(s, (cid, c), view, policy, t, stats);
        }
    }

    /// Whether each tile's list runs through exactly the triangles of that tile, all triangles
    /// are in one, and the lists of spare and pending slots are empty.
    fn check_lists(&self) -> Result<(), WaveletDefect> {
        let bad = |what| Err(WaveletDefect(what));
        if self.spare != NIL || self.pending != NIL || self.tiles > Self::TILES {
            return bad("a spare or pending list is left, or too many tiles");
        }
        let mut seen = 0usize;
        for tile in 0..self.tiles as usize {
            let mut x = self.head[tile].load();
            while x != NIL {
                let i = x as usize;
                if i >= self.tris.len() || seen >= self.tris.len() {
                    return bad("a tile's list leaves the triangles or runs in a loop");
                }
                if usize::from(self.owner[i]) != tile {
                    return bad("a tile's list holds a triangle of another tile");
                }
                seen += 1;
                x = self.next[i].load();
            }
        }
        if seen != self.tris.len() {
            return bad("a triangle is in no tile's list");
        }
        Ok(())
    }

    /// Checks the invariants: every member's parents are members, the kept counts are the
    /// emitted ones, every tile lists exactly its triangles, every vertex slot's use count is
    /// the number of triangle corners in it (none in a freed slot, and no live slot unused),
    /// no triangle repeats a vertex, no edge is run the same way twice or shared by more than
    /// two triangles, and on a mesh without border (`closed`) every edge is shared by exactly
    /// two. `scratch` needs three entries per triangle.
    pub fn check(
        &self,
        s: &SemiRegularView<'_>,
        closed: bool,
        scratch: &mut [[u32; 2]],
    ) -> Result<(), WaveletDefect> {
        let mut next = 0;
        while let Some(id) = self.member_from(next) {
            next = id - self.base_vertices + 1;
            let p = s
                .point(id)
                .ok_or(WaveletDefect("a member is not a wavelet"))?;
            let parents = s.parents(p, s.level(p));
            if parents.iter().any(|&q| q != NIL && !self.includes(q)) {
                return Err(WaveletDefect("a member's parent is not a member"));
            }
        }
        for id in self.base_vertices..self.base_vertices + self.wavelets {
            let p = s
                .point(id)
                .ok_or(WaveletDefect("a wavelet has no lattice point"))?;
            if self.presence(s, p, s.level(p)).0 != self.is_present(id) {
                return Err(WaveletDefect("a kept presence bit is wrong"));
            }
            let holding = has(&self.holding, self.base_vertices, self.wavelets, id);
            if holding != self.scan_children(s, p, s.level(p), false) {
                return Err(WaveletDefect("a kept has-a-member-child bit is wrong"));
            }
        }
        if self.tris.len() as u32 != self.triangles || self.live_vertices() as u32 != self.vertices
        {
            return Err(WaveletDefect("the kept counts are not the emitted mesh's"));
        }
        self.check_lists()?;
        let tris = self.tris.as_slice();
        let edges = scratch
            .get_mut(..3 * tris.len())
            .ok_or(WaveletDefect("scratch too small"))?;
        // Corners sorted by slot: each slot's run is its uses.
        for (t, e) in tris.iter().zip(edges.chunks_exact_mut(3)) {
            for k in 0..3 {
                e[k] = [t[k].load(), 0];
            }
        }
        edges.sort_unstable();
        let mut run = 0;
        for slot in 0..self.ids.len() {
            let mut count = 0u32;
            while run < edges.len() && edges[run][0] as usize == slot {
                count += 1;
                run += 1;
            }
            let freed = self.ids.as_slice()[slot] == NIL;
            if u32::from(self.uses[slot] & emit::USES) != count || (freed != (count == 0)) {
                return Err(WaveletDefect(
                    "a vertex slot's use count is not its triangles'",
                ));
            }
        }
        if run != edges.len() {
            return Err(WaveletDefect("a triangle's corner is not a vertex slot"));
        }
        for (t, e) in tris.iter().zip(edges.chunks_exact_mut(3)) {
            let v = t.map(|x| x.load());
            if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                return Err(WaveletDefect("a triangle repeats a vertex"));
            }
            for k in 0..3 {
                e[k] = [v[k], v[(k + 1) % 3]];
            }
        }
        // Sorted by (smaller, larger) end: an edge's runs are next to each other.
        edges.sort_unstable_by_key(|&[a, b]| (a.min(b), a.max(b), a));
        let mut i = 0;
        while i < edges.len() {
            let key = |e: [u32; 2]| (e[0].min(e[1]), e[0].max(e[1]));
            let mut j = i + 1;
            while j < edges.len() && key(edges[j]) == key(edges[i]) {
                j += 1;
            }
            match j - i {
                1 if closed => return Err(WaveletDefect("an edge of a closed mesh has one side")),
                1 => {}
                2 if edges[i][0] == edges[i + 1][0] => {
                    return Err(WaveletDefect("two triangles run an edge the same way"))
                }
                2 => {}
                _ => {
                    return Err(WaveletDefect(
                        "an edge is shared by more than two triangles",
                    ))
                }
            }
            i = j;
        }
        Ok(())
    }
}
