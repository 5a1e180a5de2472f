//! One frame of selective refinement: [`Cut::adapt`].
//!
//! Incremental from the previous frame's cut, as in the merge-tree paper (Berkey and Song, §3.5)
//! and Hoppe's `adapt_refinement` ("View-dependent refinement of progressive meshes", 1997): one
//! pass over the active vertices asks the [`Policy`] about each (a vertex whose digest proves,
//! through the policy's [`crate::policy::Envelope`], that it wants no split is decided without
//! reading the file; a vertex or pair whose answer provably cannot have changed since it was last
//! asked, the camera having moved less than the margin measured then, is not asked at all:
//! [`FrameStats::settled`]), then
//!
//! 1. **coarsen**: sibling pairs whose parent the policy no longer needs are collapsed where
//!    Hoppe's condition allows; a collapse lists the pair it makes and the pairs whose illegal
//!    mark it cleared (those whose triangles it gave a new neighbour), so when no budget, queue
//!    or operation cap binds, one call reaches the cut the view asks for and a second call with
//!    the same view does nothing (a test over the peer orbit at 0.25-4 px); a collapse leaves its
//!    second child's vertex slot empty;
//! 2. **refine**: vertices over tolerance are split largest error first (a priority queue), each
//!    forcing the splits it depends on, and their children join the queue (when nothing can stop
//!    refinement part way and the order cannot change the cut, the children go next, depth
//!    first); new vertices take the slots collapses left, and the last vertices fill the rest;
//! 3. **budget**: splits stop at [`Budget::max_triangles`]; when the budget binds, pairs whose
//!    parent's error is below the next split's are collapsed to make room, so the cut is the best
//!    the budget allows. [`Budget::target_triangles`] regulates the error threshold from frame to
//!    frame (the LOD lecture's regulation), [`Budget::max_ops`] caps the splits and collapses of
//!    one frame (least needed pairs first, up to half the cap kept for the largest errors'
//!    splits) and [`Budget::max_visits`] the vertices the pass asks, each frame asking the next
//!    window of the active list (its amortization).
//!
//! Geomorphs ([`Cut::set_geomorph_frames`]): a split's children start at the parent's current
//! position, normal and colour and blend to their own; a collapse first blends both children to
//! the parent and collapses when they arrive. A collapse that starts while a split still blends
//! starts where the vertices are (the wavelet paper's overlapping geomorphs, §3.5, equation 6), and
//! a blend is reversed, not restarted, when the policy changes its mind. Changes caused by
//! culling (a region entering the view, or a culled pair collapsing) are not blended.
//!
//! Full capacity, a full queue, the budget and the operation limit keep the cut coarser and are
//! reported in [`FrameStats`]; nothing panics.
//!
//! ```
//! # #[cfg(feature = "build")] {
//! use vdlod_core::adapt::Budget;
//! use vdlod_core::build::{build, BuildOptions, InputMesh};
//! use vdlod_core::cut::Cut;
//! use vdlod_core::format::HierarchyView;
//! use vdlod_core::policy::{QRefine, View};
//! // A bumpy 16 x 16 grid, its hierarchy, and a cut of it seen from above.
//! let n = 16;
//! let positions: Vec<[f32; 3]> = (0..=n * n + 2 * n)
//!     .map(|i| [(i % (n + 1)) as f32, (i / (n + 1)) as f32, ((i * 7) % 5) as f32 * 0.05])
//!     .collect();
//! let mut triangles = Vec::new();
//! for y in 0..n {
//!     for x in 0..n {
//!         let v = y * (n + 1) + x;
//!         triangles.push([v, v + 1, v + n + 2]);
//!         triangles.push([v, v + n + 2, v + n + 1]);
//!     }
//! }
//! let mesh = InputMesh { positions: &positions, colors: None, triangles: &triangles };
//! let bytes = build(&mesh, &BuildOptions::default(), &mut |_| {}).unwrap().to_bytes(false);
//! let h = HierarchyView::parse(&bytes).unwrap();
//! let mut cut = Cut::<512, 1024, 256>::boxed();
//! cut.reset(&h).unwrap();
//! let view = View::look_at([8.0, 8.0, 12.0], [8.0, 8.0, 0.0], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
//! let budget = Budget { max_triangles: 200, ..Budget::default() };
//! let stats = cut.adapt(&h, &view, &QRefine::new(1.0), &budget);
//! assert!(stats.vsplits > 0 && stats.triangles <= 200);
//! assert_eq!(stats.triangles as usize, cut.triangles().len());
//! assert!(cut.check(&h).is_ok());
//! # }
//! ```

use crate::cut::expiry::{lives, Mark, Renew, Settling, Tally};
use crate::cut::margin::lesser;
use crate::cut::split::Split;
use crate::cut::NIL;
use crate::cut::{
    Cut, Pair, PairFans, Refused, SlotIndex, BLENDING, BLOCKED, COLLAPSING, FIRST_CHILD, SETTLED,
    VISIBLE, WAS_VISIBLE,
};
use crate::format::{HierarchyView, Record, NONE};
use crate::policy::{dot, sub, Bounds, Demand, Envelope, Policy, View};

/// Limits on one frame's cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// The cut never has more triangles than this after [`Cut::adapt`] (unless the base mesh
    /// alone has more; [`FrameStats::over_budget`] says so).
    pub max_triangles: u32,
    /// Regulate the error threshold towards this many triangles (0: off).
    pub target_triangles: u32,
    /// Relative band around the target inside which the threshold is left alone.
    pub target_band: f32,
    /// Splits plus collapses per frame at most: the least needed pairs collapse first, and up
    /// to half of it stays for the waiting splits, largest error first.
    pub max_ops: u32,
    /// Regulate the error threshold towards this frame time, in microseconds (0: off): the LOD
    /// lecture's constant frame rate. The core has no clock; the caller measures its frames and
    /// gives the last one's time in [`Budget::frame_us`].
    pub target_frame_us: u32,
    /// The previous frame's time in microseconds, as the caller measured it (adapting and
    /// drawing; 0: not measured).
    pub frame_us: u32,
    /// Active vertices asked per frame at most: the LOD lecture's amortization, the traversal
    /// spread over frames. Each frame asks the next `max_visits` vertices of the active list,
    /// going on where the previous frame stopped and wrapping round; vertices in a geomorph are
    /// asked every frame besides (a blend may turn back). Below the active count, frames do not
    /// skip settled vertices (the window is the saving instead). The vertex cut only.
    pub max_visits: u32,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            max_triangles: u32::MAX,
            target_triangles: 0,
            target_band: 0.05,
            max_ops: u32::MAX,
            target_frame_us: 0,
            frame_us: 0,
            max_visits: u32::MAX,
        }
    }
}

/// What one [`Cut::adapt`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Triangles after the frame.
    pub triangles: u32,
    /// Active vertices after the frame.
    pub vertices: u32,
    /// Vertex splits done (forced ones included).
    pub vsplits: u32,
    /// Of those, splits forced by dependencies.
    pub forced: u32,
    /// Edge collapses done.
    pub ecols: u32,
    /// Of those, collapses that only enforced [`Budget::max_triangles`] after it was lowered
    /// (the hard limit wins over [`Budget::max_ops`]).
    pub budget_ecols: u32,
    /// Vertices with a geomorph running.
    pub blending: u32,
    /// Vertices skipped because their answers could not have changed since they were last
    /// asked (see [`Cut::adapt`]; the frame is the same as if they had been asked).
    pub settled: u32,
    /// Vertices asked this frame (all active ones but the settled, unless
    /// [`Budget::max_visits`] binds; 0 from the wavelet cut, which asks wavelets).
    pub visited: u32,
    /// The error threshold used (1 unless regulated).
    pub threshold: f32,
    /// Splits were refused by [`Budget::max_triangles`].
    pub budget_limited: bool,
    /// Splits were refused by [`Budget::max_ops`].
    pub ops_limited: bool,
    /// Splits were refused because an arena is full.
    pub capacity_limited: bool,
    /// A work queue overflowed: some split or collapse candidates waited for a later frame.
    pub queue_overflow: bool,
    /// The blend arena was full: some collapses happened without a geomorph.
    pub blend_limited: bool,
    /// More triangles than [`Budget::max_triangles`] remain (collapses the budget needed were
    /// not legal yet, or the base mesh alone is larger).
    pub over_budget: bool,
}

impl Budget {
    /// Whether a cut of `triangles` may grow by `added` triangles.
    #[inline]
    #[must_use]
    pub fn admits(&self, triangles: u32, added: u32) -> bool {
        triangles.saturating_add(added) <= self.max_triangles
    }

    /// The error threshold for the next frame, after a frame of `triangles` at `threshold`:
    /// scaled by the ratio to [`Budget::target_triangles`], or of [`Budget::frame_us`] to
    /// [`Budget::target_frame_us`] (with both, the larger ratio: the stricter target wins), at
    /// most 2x either way, when it is outside [`Budget::target_band`] (the LOD lecture's
    /// regulation); unchanged without a target.
    ///
    /// ```
    /// use vdlod_core::adapt::Budget;
    /// let budget = Budget { target_frame_us: 10_000, frame_us: 15_000, ..Budget::default() };
    /// // A frame 1.5x too slow raises the threshold 1.5x: fewer triangles next frame.
    /// assert_eq!(budget.regulate(1.0, 5_000), 1.5);
    /// // Within 5% of the target, it stays.
    /// let close = Budget { frame_us: 10_300, ..budget };
    /// assert_eq!(close.regulate(1.0, 5_000), 1.0);
    /// ```
    #[must_use]
    pub fn regulate(&self, threshold: f32, triangles: u32) -> f32 {
        let ratio = |value: u32, target: u32| {
            (target > 0 && value > 0).then(|| value as f32 / target as f32)
        };
        let by_triangles = ratio(triangles.max(1), self.target_triangles);
        let by_time = ratio(self.frame_us, self.target_frame_us);
        let ratio = match (by_triangles, by_time) {
            (Some(a), Some(b)) => a.max(b),
            (Some(r), None) | (None, Some(r)) => r,
            (None, None) => return threshold,
        };
        if (ratio - 1.0).abs() > self.target_band {
            (threshold * ratio.clamp(0.5, 2.0)).clamp(1e-6, 1e6)
        } else {
            threshold
        }
    }
}

/// Float rounding between the cut's bounds and the exact tests stays far below this.
const SLACK: f32 = 1.0 + 1e-5;

/// A pair's parent's error as the collapse candidates keep it: negative when culled, so that
/// culled pairs collapse first and without a blend.
#[inline]
fn pair_error(d: Demand) -> f32 {
    if d.visible {
        d.error
    } else {
        -1.0
    }
}

/// The bounds in `record` that a policy reads: only the sphere for one answered from spheres
/// (`sphere_only`: no normal to decode), all of them otherwise.
#[inline(always)]
fn bounds_read(h: &HierarchyView<'_>, record: Record, sphere_only: bool) -> Bounds {
    if sphere_only {
        h.sphere_at(record)
    } else {
        h.bounds_at(record)
    }
}

/// The envelope the cut trusts of `policy` at `view` (none for a policy that judges triangles,
/// whose demand moves with its neighbours), and what [`bound_proves_none`] reads of it: the
/// upper bound's scale (infinite without an envelope) and the near zone beyond which it holds
/// (everywhere without one).
#[inline(always)]
fn trusted_envelope<P: Policy>(policy: &P, view: &View) -> (Option<Envelope>, (f32, Envelope)) {
    let envelope = if policy.judges_triangles() {
        None
    } else {
        policy.envelope(view)
    };
    let upper = envelope.map_or(f32::INFINITY, |e| e.upper);
    (envelope, (upper, envelope.unwrap_or(Envelope::ZERO)))
}

/// Whether the policy's envelope (its upper bound `upper`, which holds beyond `zone`'s near
/// zone) proves that a vertex of spheroid radius `s` and bounding radius `radius`, at squared
/// distance `d2` from the eye, wants no split at threshold `t`.
#[inline(always)]
fn bound_proves_none(
    s: f32,
    radius: f32,
    d2: f32,
    (upper, zone): (f32, &Envelope),
    t: f32,
) -> bool {
    (s * s * upper * SLACK <= t * d2) & zone.beyond_near(d2, radius, SLACK)
}

/// The demand of a policy that reads only spheres ([`reads_spheres`]) for a vertex whose
/// sphere is `center` and `radius` (its digest's: the floats its record decodes to).
#[inline(always)]
fn sphere_demand<P: Policy>(policy: &P, (center, radius): ([f32; 3], f32), view: &View) -> Demand {
    let b = Bounds {
        center,
        radius,
        ..Bounds::default()
    };
    policy.demand(&b, view)
}

/// Whether `policy` reads nothing of a vertex but its bounding sphere, for vertices and pairs
/// alike (see [`Policy::sphere_only`]).
#[inline(always)]
fn reads_spheres<P: Policy>(policy: &P) -> bool {
    policy.sphere_only() && !policy.judges_triangles()
}

/// A vertex's flags after a frame in which it was `visible` or not, with geomorphs on
/// (`blends`) or off: `VISIBLE` moves to `WAS_VISIBLE`. Only geomorphs read them (whether a
/// change blends), so a frame without them stores "not seen" ([`kept`]): the flags of a
/// vertex skipped in such frames are then those of one asked, and the first frame with
/// geomorphs blends nothing, as after a reset.
#[inline(always)]
fn seen(flags: u8, visible: bool, blends: bool) -> u8 {
    let was = if flags & VISIBLE != 0 { WAS_VISIBLE } else { 0 };
    (flags & !(VISIBLE | WAS_VISIBLE)) | was | kept(visible, blends) as u8
}

/// The visibility a vertex's flags keep: only with geomorphs (see [`seen`]).
#[inline(always)]
fn kept(visible: bool, blends: bool) -> bool {
    visible & blends
}

/// Sorts pairs by error, then parent (a total order: the result never depends on the order
/// they were found in).
fn sort_pairs(pairs: &mut [Pair]) {
    pairs.sort_unstable_by(|x, y| x.error.total_cmp(&y.error).then(x.parent.cmp(&y.parent)));
}

/// The running totals of one frame.
struct Frame {
    stats: FrameStats,
    /// The error threshold of this frame.
    threshold: f32,
    /// Splits plus collapses so far.
    ops: u32,
}

/// Whether a frame's operations read ahead ([`Cut::touch_pairs`], [`Cut::touch_candidates`]):
/// where a miss costs a long wait and the processor keeps many in flight (x86-64, aarch64).
/// A Cortex-M waits a few cycles on its memory, so there the reads would only add
/// instructions (1.5% of the firmware's frames).
const READ_AHEAD: bool = cfg!(any(target_arch = "x86_64", target_arch = "aarch64"));

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Splits and collapses blend over `frames` frames (0: no geomorphs, the default).
    pub fn set_geomorph_frames(&mut self, frames: u16) {
        self.geomorph_frames = frames;
    }

    /// Whether frames skip the vertices whose answers cannot have changed since they were last
    /// asked (on by default). The frames are the same either way; only their time differs.
    pub fn set_settling(&mut self, on: bool) {
        self.motion.set_on(on);
    }

    /// The regulated error threshold (1 after [`Cut::reset`] unless
    /// [`Budget::target_triangles`] moved it).
    #[must_use]
    pub fn threshold(&self) -> f32 {
        self.threshold
    }

    /// Marks the pair at slots `a` and `b` as found illegal (see [`crate::cut`]'s `BLOCKED`).
    fn block(&mut self, a: usize, b: usize) {
        self.v.flags[a] |= BLOCKED;
        self.v.flags[b] |= BLOCKED;
    }

    /// Collapses `parent` now if legal, with `fans` as scratch, leaving the second child's slot
    /// empty when `frees` (see [`Cut::free_vertex`]); `true` when done.
    fn collapse_now(
        &mut self,
        h: &HierarchyView<'_>,
        parent: u32,
        fans: &mut PairFans,
        frees: bool,
    ) -> bool {
        match self.collapse_legal(h, parent, fans, frees) {
            Ok(plan) => {
                self.apply_collapse(h, parent, plan, fans, frees);
                true
            }
            Err(_) => false,
        }
    }

    /// Moves the cut for one frame seen from `view`: see the module documentation.
    pub fn adapt<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
    ) -> FrameStats {
        let mut frame = Frame {
            stats: FrameStats::default(),
            threshold: self.threshold,
            ops: 0,
        };
        let settling = self.evaluate(h, view, policy, budget.max_visits, &mut frame);
        self.coarsen(h, view, policy, budget, &mut frame);
        self.refine(h, view, policy, budget, settling.as_ref(), &mut frame);
        self.fill_holes();
        self.enforce_max(h, view, policy, budget, &mut frame.stats);
        // A cut that shrank gets a smaller node map (faster lookups).
        self.respan_map(self.v.len());
        let triangles = self.t.len() as u32;
        // Regulated on the triangles the cut will have once its running collapses arrive (about
        // one fewer per collapsing vertex), and raised at most once per geomorph: coarsening
        // lands a level per blend, so raising every frame while it lands ran far past the target.
        let collapsing = self
            .blends
            .as_slice()
            .iter()
            .filter(|b| b.collapsing)
            .count() as u32;
        let next = budget.regulate(self.threshold, triangles.saturating_sub(collapsing));
        self.raise_wait = self.raise_wait.saturating_sub(1);
        if next <= self.threshold || self.raise_wait == 0 {
            if next > self.threshold {
                self.raise_wait = self.geomorph_frames.min(u8::MAX as u16) as u8;
            }
            self.threshold = next;
        }
        let mut stats = frame.stats;
        stats.triangles = triangles;
        stats.vertices = self.v.len() as u32;
        stats.threshold = frame.threshold;
        stats.blending = self.blending();
        stats
    }

    /// One pass over the active vertices: blends advance first, the policy speaks for every vertex
    /// (split candidates go to the heap) and every sibling pair (collapse candidates to the
    /// pair list).
    #[inline(never)]
    fn evaluate<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        max_visits: u32,
        frame: &mut Frame,
    ) -> Option<Settling> {
        self.candidates.clear();
        self.pairs.clear();
        self.advance_blends();
        // Most vertices are far from wanting a split: the policy's envelope and the cut's digest
        // of the node (position and largest spheroid radius) prove it without reading the file,
        // and a vertex proven so that judges no pair is done with in the first pass. The others
        // (vertices the bound cannot decide, first children of active pairs, vertices in a
        // geomorph) are listed and read in batches: first every record the batch needs is
        // touched (independent loads the processor overlaps), then decoded.
        const BATCH: usize = 32;
        let t = frame.threshold;
        let blends = self.geomorph_frames > 0;
        // No geomorph runs or can start: no decision reaches a vertex but its own and its
        // pair's first child's, so a second child is done with as early as a lone vertex.
        let calm = !blends && self.blends.len() == 0;
        let (envelope, (upper, zone)) = trusted_envelope(policy, view);
        // A policy that reads only the bounding sphere is answered from the digest's copy of it:
        // the same floats the record decodes to, so the same demand, without reading the file.
        let sphere_only = reads_spheres(policy);
        // Settled vertices are skipped until their expiry; every vertex asked is marked anew
        // (see `crate::cut::expiry`).
        let model = h.bounding_sphere();
        // The walk: positions 0..len of the active list from slot `start`, wrapping round; the
        // first `visits` are the window, past it only vertices in a geomorph are asked.
        let len = self.v.len();
        let visits = (max_visits as usize).min(len);
        let windowed = visits < len;
        let start = if windowed {
            self.walk as usize % len
        } else {
            0
        };
        self.walk = if windowed {
            ((start + visits) % len) as u32
        } else {
            0
        };
        let end = if windowed && self.blends.len() == 0 {
            visits
        } else {
            len
        };
        let steady_envelope = if windowed { None } else { envelope };
        let settling = self
            .motion
            .begin(view, steady_envelope, (t, SLACK), blends, model);
        if let Some(m) = &settling {
            match m.renew {
                Renew::Forget => self.v.unsettle_all(),
                Renew::Rebase(by) => self.v.rebase(m.now, by),
                Renew::Keep => {}
            }
        }
        // Without settling no mark is trusted (they may be stale) and none is made.
        let now = settling.as_ref().map_or([u32::MAX; 2], |m| m.now);
        // Batch lists, built without branches (each item is written, and counted when it
        // belongs): the vertices still to decide, those of them the bound could not decide
        // ("slow"), and those that judge a pair (by place in the first list).
        let mut listed = [0usize; BATCH];
        let mut slow = [0usize; BATCH];
        let mut pairs = [0usize; BATCH];
        // Those that split (by place in the first list).
        let mut splitting = [0usize; BATCH];
        let mut margin = [f32::NAN; BATCH];
        // The same as turned (see `crate::cut::rigid`), without geomorphs.
        let mut turned = [f32::NAN; BATCH];
        let mut demands = [Demand::NONE; BATCH];
        let mut parents = [NONE; BATCH];
        let mut records = [Record::default(); BATCH];
        let mut parent_bounds = [Bounds::default(); BATCH];
        let mut lone = [false; BATCH];
        // Pairs whose parent is proven wanted (by its margins).
        let mut kept = [false; BATCH];
        let slot = |place: usize| {
            if start + place < len {
                start + place
            } else {
                start + place - len
            }
        };
        // The places still to ask are found a machine word at a time without branches (a
        // quarter or fewer of them are asked on a moving orbit, in no pattern a branch
        // predictor learns); with a window, one at a time, since a geomorph started on a mate
        // during the walk makes a vertex past the window one to ask.
        let word = if windowed { 1 } else { usize::BITS as usize };
        let mut tally = Tally::default();
        let mut visited = 0u32;
        let (mut next, mut base, mut pending) = (0, 0, 0usize);
        while next < end || pending != 0 {
            // 1. The digests, until the batch holds `BATCH` vertices still to decide. A vertex
            // the bound decides that has no pair to judge and no geomorph is done with here:
            // only its visibility flag moves (computed only with geomorphs, the one use of it).
            let mut n = 0;
            let mut ns = 0;
            while n < BATCH {
                if pending == 0 {
                    if next >= end {
                        break;
                    }
                    let count = (end - next).min(word);
                    let (asked, settled) = self.asked((next, count), slot, visits, now);
                    frame.stats.settled += settled;
                    (base, pending) = (next, asked);
                    next += count;
                    continue;
                }
                let i = slot(base + pending.trailing_zeros() as usize);
                pending &= pending - 1;
                visited += 1;
                let flags = self.v.flags[i];
                let digest = &self.v.digest[i];
                let center = h.digest_center(digest);
                let s = h.length(digest.spheroid);
                let radius = h.length(digest.radius);
                let r = sub(center, view.eye);
                let d2 = dot(r, r);
                // A leaf never splits, whatever it is asked (a parent's bounding radius is not
                // 0 but where its whole region is a point: looked up then). Without geomorphs,
                // the one reader of whether it is seen, it wants nothing the policy could say:
                // it is not asked (a second child or a lone leaf is done with here).
                let leaf = digest.radius == 0 && !h.is_parent(self.v.node[i]);
                let quiet = leaf & !blends;
                let sphere = if sphere_only {
                    Some(if quiet {
                        Demand::NONE
                    } else {
                        sphere_demand(policy, (center, radius), view)
                    })
                } else {
                    None
                };
                let wants_none = match sphere {
                    Some(d) => d.error <= t,
                    None => quiet || bound_proves_none(s, radius, d2, (upper, &zone), t),
                };
                let mate = self.v.mate(i);
                let still = flags & (BLENDING | COLLAPSING) == 0;
                let alone = still & ((mate == NIL) | (calm & (flags & FIRST_CHILD == 0)));
                let done = wants_none & alone;
                // Marked below: alone, or a first child with its pair (not in a geomorph).
                let markable = alone | (still & (flags & FIRST_CHILD != 0) & (mate != NIL));
                let visible = match sphere {
                    Some(d) => d.visible,
                    None => blends && view.sphere_visible(center, radius),
                };
                let seen_flags = seen(flags, visible, blends);
                // Calm, whatever else the frame asks of it, its flags move as a vertex's seen
                // without geomorphs: now, which nothing until then reads.
                let mut next_flags = if done | calm { seen_flags } else { flags };
                margin[n] = f32::NEG_INFINITY;
                turned[n] = f32::NEG_INFINITY;
                let measured = settling
                    .as_ref()
                    .filter(|m| markable & m.measures(flags, i));
                if let Some(m) = measured {
                    // How far the camera may move while it wants no split (answered from its
                    // sphere); with geomorphs also while it is seen (or not) as in the frame
                    // before, since that flag decides whether a change blends. A leaf's
                    // answer holds on either count however far the camera goes, so nothing of
                    // it is measured but, with geomorphs, whether it is seen.
                    let seen = if blends || (!leaf & wants_none && m.margins.culls()) {
                        m.margins.visibility(center, radius)
                    } else {
                        (None, f32::NAN)
                    };
                    let (own, turns) = if leaf {
                        (f32::INFINITY, f32::INFINITY)
                    } else if wants_none {
                        let e = m.margins.unwanted(s, radius, d2, seen);
                        (e.within(m.scale), m.turned(e, center, radius))
                    } else {
                        // Unproven, on either count.
                        (f32::NAN, f32::NEG_INFINITY)
                    };
                    if !blends {
                        turned[n] = turns;
                    }
                    margin[n] = match (blends, seen) {
                        (false, _) => own,
                        (true, (Some(v), room)) if v == visible && (flags & VISIBLE != 0) == v => {
                            lesser(own, room * m.scale)
                        }
                        (true, _) => f32::NAN,
                    };
                }
                if settling.is_some() {
                    next_flags &= !SETTLED;
                }
                self.v.flags[i] = next_flags;
                // A vertex whose record is read is marked once its facing is known (stage 2).
                let slow_one = !wants_none & sphere.is_none();
                if let Some(m) = settling.as_ref().filter(|_| alone & !slow_one) {
                    if measured.is_some() {
                        self.mark(i, m, (margin[n], turned[n]), &mut tally);
                    } else {
                        // What `Settling::mark` makes of margins not measured.
                        self.v.mark(i, Mark::Restless);
                    }
                }
                listed[n] = i;
                lone[n] = alone;
                slow[ns] = n;
                demands[n] = sphere.unwrap_or(Demand {
                    visible,
                    error: 0.0,
                });
                ns += slow_one as usize;
                n += !done as usize;
            }
            let (listed, slow) = (&listed[..n], &slow[..ns]);
            // 2. The records of the vertices the bound could not decide, and their demands.
            let mut touched = 0u8;
            for &k in slow {
                records[k] = h.record(self.v.node[listed[k]]);
                touched ^= h.touch_record(records[k]);
            }
            core::hint::black_box(touched);
            for &k in slow {
                let bounds = h.bounds_at(records[k]);
                demands[k] = self.judged(h, listed[k], &bounds, view, policy);
                if let Some(m) = &settling {
                    // Its bound could not say it wants no split, but a normal cone that stays
                    // turned away does (a culled vertex wants nothing): most such vertices are
                    // the coarse ones on the far side. Measured ones only; with geomorphs its
                    // visibility would have to stay too.
                    if !blends && margin[k] != f32::NEG_INFINITY {
                        margin[k] = margin[k].max(m.margins.averted(&bounds));
                    }
                    if lone[k] {
                        self.mark(listed[k], m, (margin[k], turned[k]), &mut tally);
                    }
                }
            }
            // 3. The parent of a pair matters unless the first child is to be split or both
            // were found illegal to collapse (see `decide`).
            let (mut np, mut nsp) = (0, 0);
            for (k, &i) in listed.iter().enumerate() {
                let flags = self.v.flags[i];
                let m = self.v.mate(i);
                // The sibling's flags (another cache line) only when its own mark says the
                // pair may be illegal.
                let blocked = flags & BLOCKED != 0
                    && self
                        .v
                        .flags
                        .get(m as usize)
                        .is_some_and(|f| f & BLOCKED != 0);
                let splits = demands[k].error > t && h.is_parent(self.v.node[i]);
                let judges = (flags & FIRST_CHILD != 0) & (m != NIL) & !splits & !blocked;
                pairs[np] = k;
                np += judges as usize;
                splitting[nsp] = k;
                nsp += splits as usize;
                // A first child whose pair is marked illegal settles on its own answer (a
                // collapse that clears the mark on either child clears this one too).
                if let Some(s) = settling
                    .as_ref()
                    .filter(|_| !judges & (flags & FIRST_CHILD != 0) & (m != NIL))
                {
                    self.mark(i, s, (margin[k], turned[k]), &mut tally);
                }
            }
            let pairs = &pairs[..np];
            let mut touched = 0u8;
            for &k in pairs {
                let (p, r) = h
                    .parent_record(self.v.node[listed[k]])
                    .unwrap_or((NONE, Record::default()));
                parents[k] = p;
                records[k] = r;
            }
            for &k in pairs {
                touched ^= h.touch_record(records[k]);
            }
            core::hint::black_box(touched);
            for &k in pairs {
                parent_bounds[k] = bounds_read(h, records[k], sphere_only);
                kept[k] = false;
            }
            if let Some(m) = &settling {
                for &k in pairs {
                    // Not measured (restless, not its turn), or already too small: no need,
                    // and the mark is restless (under a step on either count).
                    if margin[k] >= m.step || turned[k] >= m.turn {
                        let b = &parent_bounds[k];
                        let (wanted, turns) =
                            m.margins
                                .wanted_turned(b, (t, SLACK), (m.step, 4), m.levers(b.center));
                        let wanted = wanted.within(m.scale);
                        // Still wanted from where the eye is now: the pair stays.
                        kept[k] = wanted >= 0.0;
                        let room = (lesser(margin[k], wanted), lesser(turned[k], turns));
                        self.mark(listed[k], m, room, &mut tally);
                    } else {
                        tally.count(margin[k], Mark::Restless);
                        self.v.mark(listed[k], Mark::Restless);
                    }
                }
            }
            // 4. The decisions, in slot order. Without geomorphs they touch nothing but the
            // split heap and the pair list, so the pairs can follow the vertices.
            if calm {
                // What `decide` does without geomorphs: every vertex's flags move (done in the
                // first pass), and those that split join the heap, from lists made without
                // branches (whether a vertex splits, or a pair is judged, follows no pattern a
                // branch predictor learns).
                for &k in &splitting[..nsp] {
                    self.want_split(self.v.node[listed[k]], demands[k], frame);
                }
                // A pair whose parent was just proven wanted is left as it is, as judging it
                // would (without geomorphs nothing blends back). The others are listed in the
                // splitting list's room, which has served.
                let mut judged = 0;
                for &k in pairs {
                    splitting[judged] = k;
                    judged += usize::from(!kept[k]);
                }
                for &k in &splitting[..judged] {
                    self.decide_pair(
                        h,
                        view,
                        policy,
                        listed[k],
                        parents[k],
                        &parent_bounds[k],
                        frame,
                    );
                }
            } else {
                let mut pairs = pairs.iter().peekable();
                for (k, &i) in listed.iter().enumerate() {
                    self.decide(h, i, demands[k], frame);
                    if pairs.next_if_eq(&&k).is_some() {
                        self.decide_pair(h, view, policy, i, parents[k], &parent_bounds[k], frame);
                    }
                }
            }
        }
        frame.stats.visited += visited;
        self.motion
            .tally(tally.measured, tally.settled, frame.stats.settled);
        settling
    }

    /// Marks slot `i` as the margin `margin` of its answers says (see [`Settling::mark`]), and
    /// counts it in `tally`.
    #[inline(always)]
    fn mark(&mut self, i: usize, settling: &Settling, margins: (f32, f32), tally: &mut Tally) {
        let mark = settling.mark(margins);
        tally.count(margins.0, mark);
        self.v.mark(i, mark);
    }

    /// Which of the `count` places from `first` of the walk (slot `slot(place)`) are asked
    /// this frame, as bits: all but those past the window of `visits` in no geomorph and the
    /// settled ones whose expiry the count `now` has not passed; and how many were settled.
    #[inline(always)]
    fn asked(
        &self,
        (first, count): (usize, usize),
        slot: impl Fn(usize) -> usize,
        visits: usize,
        now: [u32; 2],
    ) -> (usize, u32) {
        if first + count <= visits && first + count <= self.v.len() && slot(first) == first {
            // In the window and in slot order (always, without a window): only the settled are
            // skipped (none without settling).
            let all = usize::MAX >> (usize::BITS as usize - count.clamp(1, usize::BITS as usize));
            if now == [u32::MAX; 2] {
                return (all, 0);
            }
            let skipped = self.v.settled_until(first, count, now);
            return (!skipped & all, skipped.count_ones());
        }
        let (mut asked, mut settled) = (0usize, 0u32);
        for k in 0..count {
            let i = slot(first + k);
            let flags = self.v.flags[i];
            let outside = (first + k >= visits) & (flags & (BLENDING | COLLAPSING) == 0);
            let skips = (flags & SETTLED != 0) & lives(self.v.expiry(i), now);
            asked |= usize::from(!outside & !skips) << k;
            settled += u32::from(!outside & skips);
        }
        (asked, settled)
    }

    /// Reads what each listed pair's collapse reads first, for the first `limit` pairs (those
    /// an operation cap leaves room for) before the first collapse: both vertices' nodes, fans
    /// and first fan triangles, and the pair's split record. Independent loads, which the
    /// processor overlaps, where each collapse in turn would wait on them after a frame's
    /// drawing has evicted the cut.
    fn touch_pairs(&self, h: &HierarchyView<'_>, limit: usize) {
        if !READ_AHEAD {
            return;
        }
        let mut touched = 0u32;
        for pair in self.pairs.as_slice().iter().take(limit) {
            let a = pair.first as usize;
            touched ^= self.touch_fan(a) ^ self.touch_fan(self.v.mate(a) as usize);
            if let Some(&node) = self.v.node.get(a) {
                touched ^= h.pair_split(node).neighbours[0];
            }
        }
        core::hint::black_box(touched);
    }

    /// Reads what each waiting split reads first, for the first `limit` candidates of the heap
    /// (its top levels: those an operation cap leaves room for) before the first split: its
    /// slot (the node map), its fan's first triangle and its split record.
    fn touch_candidates(&self, h: &HierarchyView<'_>, limit: usize) {
        if !READ_AHEAD {
            return;
        }
        let mut touched = 0u32;
        for &(_, node) in self.candidates.as_slice().iter().take(limit) {
            if let Some(s) = self.slot(node) {
                touched ^= self.touch_fan(s as usize);
            }
            touched ^= h.split(node).neighbours[0];
        }
        core::hint::black_box(touched);
    }

    /// Reads slot `s`'s fan triangle (its id, corners and neighbours), where a walk of the fan
    /// starts; 0 for a slot out of range.
    #[inline(always)]
    fn touch_fan(&self, s: usize) -> u32 {
        let f = self.v.fan(s);
        if (f as usize) < self.t.len() {
            self.t.id[f as usize] ^ self.t.corner_at(f, 0) ^ self.t.adj(f)[0]
        } else {
            0
        }
    }

    /// Every running blend advances a frame, before the walk decides anything. A pair whose
    /// collapse is reversed restarts both children's blends from where they are; advanced as
    /// the walk reached it, the second child was a frame further or not depending on whether
    /// its slot came before the first child's, so frames depended on the slot order.
    fn advance_blends(&mut self) {
        let mut k = 0;
        while let Some(b) = self.blends.as_slice().get(k) {
            let (s, before) = (b.slot as usize, self.blends.len());
            if self.v.flags.get(s).is_some_and(|f| f & BLENDING != 0) {
                self.advance(s);
            }
            // A split's blend that arrived was freed and the last entry moved into its place.
            k += usize::from(self.blends.len() == before);
        }
    }

    /// Slot `i`'s own decisions (see [`Cut::evaluate`]) with its demand `d`: its visibility
    /// moves, and it joins the split heap when over the threshold.
    #[inline(always)]
    fn decide(&mut self, h: &HierarchyView<'_>, i: usize, d: Demand, frame: &mut Frame) {
        let t = frame.threshold;
        let node = self.v.node[i];
        let flags = self.v.flags[i];
        self.v.flags[i] = seen(flags, d.visible, self.geomorph_frames > 0);
        let collapsing = flags & COLLAPSING != 0;
        if collapsing && self.v.mate(i) == NIL {
            // The pair was broken up (a forced split took the sibling): blend back.
            self.start_blend(h, i, false);
        }
        if d.error > t && h.is_parent(node) {
            if self.v.flags[i] & COLLAPSING != 0 {
                // Wanted again: reverse the collapse's blend; no split this frame.
                self.start_blend(h, i, false);
            } else {
                self.want_split(node, d, frame);
            }
        }
    }

    /// Puts `node`, whose demand `d` is over the threshold, in the split heap.
    #[inline(always)]
    fn want_split(&mut self, node: u32, d: Demand, frame: &mut Frame) {
        if self
            .candidates
            .heap_push((d.error.to_bits(), node))
            .is_err()
        {
            frame.stats.queue_overflow = true;
        }
    }

    /// The decision for the pair whose first child is at slot `i` (its sibling is active, it
    /// does not split, and the pair is not marked illegal): parent `p` with bounds
    /// `parent_bounds`, still wanted (a collapse under way blends back) or listed for coarsening.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn decide_pair<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        i: usize,
        p: u32,
        parent_bounds: &Bounds,
        frame: &mut Frame,
    ) {
        let j = self.v.mate(i) as usize;
        let e = pair_error(self.judged_pair(h, (i, j), parent_bounds, view, policy));
        if e > frame.threshold {
            // (A collapse under way has a blend entry: without any, the flags are not read.)
            if self.blends.len() != 0 && (self.v.flags[i] | self.v.flags[j]) & COLLAPSING != 0 {
                self.start_blend(h, i, false);
                self.start_blend(h, j, false);
            }
            return;
        }
        self.list_pair(e, p, i, &mut frame.stats);
    }

    /// Appends the pair of first child `first` and parent `parent` (error `error`) to the
    /// collapse list; `false`, and the overflow noted, when the list is full.
    fn list_pair(&mut self, error: f32, parent: u32, first: usize, stats: &mut FrameStats) -> bool {
        let pair = Pair {
            error,
            parent,
            first: first as u32,
        };
        let listed = self.pairs.push(pair).is_ok();
        stats.queue_overflow |= !listed;
        listed
    }

    /// Collapses the listed pairs where the parent is no longer needed and Hoppe's condition
    /// allows; with geomorphs, visible pairs first blend to the parent and collapse on arrival.
    /// A collapse that makes a new pair lists it too, so coarsening goes as far as the view asks
    /// in one call.
    #[inline(never)]
    fn coarsen<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
        frame: &mut Frame,
    ) {
        let frames = self.geomorph_frames;
        if self.pairs.len() == 0 {
            return;
        }
        // Under an operation cap, the least needed pairs go first (culled ones before all), and
        // up to half the cap stays for the splits waiting in the heap, which refinement spends
        // largest error first: a cap that binds is spent where the errors are.
        let cap = if budget.max_ops == u32::MAX {
            u32::MAX
        } else {
            sort_pairs(self.pairs.as_mut_slice());
            budget.max_ops - (self.candidates.len() as u32).min(budget.max_ops / 2)
        };
        // (Under a cap the pairs are sorted, the first to go first.)
        self.touch_pairs(h, cap.saturating_sub(frame.ops) as usize);
        // Scratch for the fans of every collapse tried (made once: making one costs a memset).
        let mut fans = PairFans::default();
        // One pass over a list that grows: a collapse lists the pair it makes and the pairs
        // whose illegal mark it cleared, so a pair that waited for it is tried again.
        let mut k = 0;
        while k < self.pairs.len() {
            let pair = self.pairs.as_slice()[k];
            k += 1;
            let Pair {
                error: e,
                parent: p,
                first,
            } = pair;
            // The first child's slot from the pass, unless a collapse since moved it.
            let a = if (first as usize) < self.v.len()
                && self.pair_parent(h, first as usize) == Some(p)
            {
                first
            } else {
                match self.slot(h.children(p)[0]) {
                    Some(a) if self.pair_parent(h, a as usize) == Some(p) => a,
                    _ => continue,
                }
            };
            let b = self.v.mate(a as usize);
            let (a, b) = (a as usize, b as usize);
            if frame.ops >= cap {
                frame.stats.ops_limited = true;
                return;
            }
            let (fa, fb) = (self.v.flags[a], self.v.flags[b]);
            let blending = fa & fb & COLLAPSING != 0;
            if blending && (fa | fb) & BLENDING != 0 {
                continue;
            }
            if !blending && frame.stats.ecols > 0 && policy.judges_triangles() {
                // Collapses since the pair was listed may have made the triangles it would
                // leave larger: judge them as they are now, so no collapse makes what the next
                // frame splits.
                let d = self.judged_pair(h, (a, b), &h.bounds(p), view, policy);
                if pair_error(d) > frame.threshold {
                    continue;
                }
            }
            let seen = e >= 0.0 && (fa | fb) & WAS_VISIBLE != 0;
            // `a` is the first child: its pair's split is found without counting parents.
            let split = h.pair_split(self.v.node[a]);
            let legal = self.collapse_legal_at(&split, a as u32, b as u32, &mut fans, true);
            if legal.is_err() && !blending {
                self.block(a, b);
                continue;
            }
            if !blending && frames > 0 && seen {
                if self.blends.len() + 2 <= Self::BLEND_ROOM {
                    self.start_blend(h, a, true);
                    self.start_blend(h, b, true);
                    continue;
                }
                frame.stats.blend_limited = true;
            }
            match legal {
                Ok(plan) => {
                    let s = self.apply_collapse(h, p, plan, &mut fans, true);
                    frame.stats.ecols += 1;
                    frame.ops += 1;
                    self.list_new_pair(h, view, policy, s as usize, frame);
                    self.list_unblocked(h, view, policy, &fans, frame);
                }
                Err(_) => {
                    // Arrived, but the neighbourhood changed meanwhile: blend back.
                    self.start_blend(h, a, false);
                    self.start_blend(h, b, false);
                }
            }
        }
    }

    /// Lists the pair slot `s` now belongs to, if its sibling is active and their parent is no
    /// longer needed.
    fn list_new_pair<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        s: usize,
        frame: &mut Frame,
    ) {
        let m = self.v.mate(s);
        if m == NIL {
            return;
        }
        let first = if self.v.flags[s] & FIRST_CHILD != 0 {
            s
        } else {
            m as usize
        };
        let p = h.parent(self.v.node[first]);
        let pair = (first, self.v.mate(first) as usize);
        let bounds = bounds_read(h, h.record(p), reads_spheres(policy));
        let error = pair_error(self.judged_pair(h, pair, &bounds, view, policy));
        if error <= frame.threshold {
            self.list_pair(error, p, first, &mut frame.stats);
        }
    }

    /// After a collapse: lists the pairs whose illegal mark it cleared (`fans.unblocked`, see
    /// `Cut::unblock_pair_of`), when their parent is no longer needed: they may be legal now.
    fn list_unblocked<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        fans: &PairFans,
        frame: &mut Frame,
    ) {
        for &first in &fans.unblocked {
            if let Some(x) = self.slot(first) {
                self.list_new_pair(h, view, policy, x as usize, frame);
            }
        }
    }

    /// Lists every active pair with its parent's error, least needed first (for trades and
    /// for [`Cut::enforce_max`]).
    fn list_all_pairs<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        stats: &mut FrameStats,
    ) {
        self.pairs.clear();
        for i in 0..self.v.len() {
            if let Some(p) = self.pair_parent(h, i) {
                let pair = (i, self.v.mate(i) as usize);
                let bounds = bounds_read(h, h.record(p), reads_spheres(policy));
                let e = pair_error(self.judged_pair(h, pair, &bounds, view, policy));
                if !self.list_pair(e, p, i, stats) {
                    break;
                }
            }
        }
        sort_pairs(self.pairs.as_mut_slice());
    }

    /// Splits the candidates largest error first (their children depth first when the order
    /// cannot matter), each forcing what it needs, within the budget; when the budget binds,
    /// pairs whose parent is needed less than the next split are collapsed to pay for it.
    #[inline(never)]
    fn refine<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
        settling: Option<&Settling>,
        frame: &mut Frame,
    ) {
        let t = frame.threshold;
        let frames = self.geomorph_frames;
        // A leaf a split makes is marked where it is judged, as next frame's walk would mark
        // it (without geomorphs, as there): a leaf's own answer never expires, so only a first
        // child's pair has a margin to measure (new parents are left to the walk: their margins
        // are mostly under a step, just past the threshold that split their parent). A pair is
        // marked on the travelled count only: its turning margin would cost more here, where a
        // first frame makes thousands of leaves, than the walk saves by it.
        let settling = settling.filter(|_| frames == 0 && self.blends.len() == 0);
        let sphere_only = reads_spheres(policy);
        let (_, (upper, zone)) = trusted_envelope(policy, view);
        let mut traded = 0usize;
        let mut listed = false;
        // Without a budget, an operation cap, geomorphs (whose blends' room may run out) or a
        // policy that judges triangles (whose demand changes as neighbours split), every split
        // over the threshold is done whatever the order: a split's children that want to split
        // then go next, depth first, while their neighbourhood is in the cache, and skip the
        // heap (past `DEPTH` waiting, they join it). The same cut as largest error first, in
        // other slots; the order follows nodes and errors only, never slots, so a renumbered cut
        // refines alike. Otherwise every candidate goes largest error first.
        const DEPTH: usize = 32;
        self.touch_candidates(h, budget.max_ops.saturating_sub(frame.ops) as usize);
        let depth_first = budget.max_triangles == u32::MAX
            && budget.max_ops == u32::MAX
            && frames == 0
            && !policy.judges_triangles();
        let mut depth = heapless::Vec::<(u32, u32), DEPTH>::new();
        while let Some((bits, v)) = depth.pop().or_else(|| self.candidates.heap_pop()) {
            let Some(s) = self.slot(v) else {
                continue;
            };
            if frame.ops >= budget.max_ops {
                frame.stats.ops_limited = true;
                break;
            }
            let blend = if self.v.flags[s as usize] & WAS_VISIBLE != 0 {
                frames
            } else {
                0
            };
            let before = self.active();
            let mut tris = self.t.len() as u32;
            let mut spent = frame.ops;
            // The splits done (forced ones first): their children are evaluated next (past 64
            // forced splits, the rest wait for the next frame's pass).
            let mut done_splits = heapless::Vec::<Split, 64>::new();
            let result = self.force_split_at(
                h,
                (v, s),
                blend,
                &mut |_, added| {
                    if !budget.admits(tris, added) {
                        Err(Refused::Budget)
                    } else if spent >= budget.max_ops {
                        Err(Refused::Ops)
                    } else {
                        tris += added;
                        spent += 1;
                        Ok(())
                    }
                },
                &mut |split| {
                    // Past 64, a split's children are not judged now: they are new, so
                    // unsettled, and next frame's pass asks them (nothing is lost, only a
                    // frame's delay for a chain that long).
                    if done_splits.is_full() {
                        return;
                    }
                    done_splits.push(split).ok();
                },
            );
            let done = (self.active() - before) as u32;
            frame.stats.vsplits += done;
            frame.stats.forced += done.saturating_sub(result.is_ok() as u32);
            frame.ops += done;
            for split in &done_splits {
                for k in 0..2 {
                    let (c, cs, record) = (split.children[k], split.slots[k], split.records[k]);
                    // A later split of the chain may have split the child too (its first child
                    // then holds the slot).
                    if self.v.node.get(cs as usize) != Some(&c) {
                        continue;
                    }
                    // Whether it splits: never for a leaf (without geomorphs, the one reader of
                    // whether it is seen, a leaf is not asked, as in the walk); else from its
                    // digest where that decides (a policy that reads spheres gets the digest's,
                    // the record's floats; without geomorphs, an envelope that proves no split
                    // is enough, as in the walk), else from its record.
                    let digest = &self.v.digest[cs as usize];
                    let (center, radius) = (h.digest_center(digest), h.length(digest.radius));
                    let proven = || {
                        let r = sub(center, view.eye);
                        let s = h.length(digest.spheroid);
                        bound_proves_none(s, radius, dot(r, r), (upper, &zone), t)
                    };
                    let d = if frames == 0 && (!record.is_parent() || !sphere_only && proven()) {
                        Demand::NONE
                    } else if sphere_only {
                        sphere_demand(policy, (center, radius), view)
                    } else {
                        self.judged(h, cs as usize, &h.bounds_at(record), view, policy)
                    };
                    let flags = &mut self.v.flags[cs as usize];
                    *flags = (*flags & !VISIBLE) | kept(d.visible, frames > 0) as u8;
                    if d.error > t && record.is_parent() {
                        let item = (d.error.to_bits(), c);
                        let waiting = (depth_first && depth.push(item).is_ok())
                            || self.candidates.heap_push(item).is_ok();
                        frame.stats.queue_overflow |= !waiting;
                    }
                    if let Some(m) = settling.filter(|_| !record.is_parent()) {
                        let i = cs as usize;
                        let room = match self.pair_parent(h, i) {
                            Some(p) => {
                                let p = bounds_read(h, h.record(p), sphere_only);
                                let wanted = m.margins.wanted(&p, (t, SLACK), (m.step, 4));
                                (wanted.within(m.scale), f32::NEG_INFINITY)
                            }
                            None => (f32::INFINITY, f32::INFINITY),
                        };
                        self.v.mark(i, m.mark(room));
                    }
                }
            }
            match result {
                Ok(_) => {}
                Err(Refused::Budget) => {
                    // Make room from the pairs whose parent matters least, if less than this.
                    if !listed {
                        self.list_all_pairs(h, view, policy, &mut frame.stats);
                        listed = true;
                    }
                    // A triangle's demand falls when a neighbour splits, so a policy that
                    // judges triangles trades only for twice the error (else the cut never
                    // settles under a binding budget).
                    let margin = if policy.judges_triangles() { 0.5 } else { 1.0 };
                    let error = f32::from_bits(bits) * margin;
                    let freed = self.trade(h, budget, error, &mut traded, frame);
                    if freed && self.candidates.heap_push((bits, v)).is_ok() {
                        continue;
                    }
                    frame.stats.budget_limited = true;
                    break;
                }
                Err(Refused::Capacity) => {
                    frame.stats.capacity_limited = true;
                    break;
                }
                Err(Refused::Ops) => {
                    frame.stats.ops_limited = true;
                    break;
                }
                Err(_) => {}
            }
        }
    }

    /// Collapses listed pairs (`self.pairs`, least needed first, from `*traded` on) whose parent
    /// is needed less than `error`, until two triangles are free; whether any collapsed. Not
    /// inlined, so that its scratch fans are not on the stack while splits run.
    #[inline(never)]
    fn trade(
        &mut self,
        h: &HierarchyView<'_>,
        budget: &Budget,
        error: f32,
        traded: &mut usize,
        frame: &mut Frame,
    ) -> bool {
        let mut fans = PairFans::default();
        let mut freed = false;
        while *traded < self.pairs.len() && frame.ops < budget.max_ops {
            let pair = self.pairs.as_slice()[*traded];
            if pair.error >= error {
                break;
            }
            *traded += 1;
            if self.collapse_now(h, pair.parent, &mut fans, true) {
                frame.stats.ecols += 1;
                frame.ops += 1;
                freed = true;
                if budget.admits(self.t.len() as u32, 2) {
                    break;
                }
            }
        }
        freed
    }

    /// Collapses the least needed pairs until the cut fits [`Budget::max_triangles`] (after the
    /// budget was lowered, or while collapse blends still hold triangles).
    #[inline(never)]
    fn enforce_max<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
        stats: &mut FrameStats,
    ) {
        if self.t.len() as u32 <= budget.max_triangles {
            return;
        }
        let mut fans = PairFans::default();
        for _ in 0..64 {
            if self.t.len() as u32 <= budget.max_triangles {
                return;
            }
            self.list_all_pairs(h, view, policy, stats);
            let mut progress = false;
            for k in 0..self.pairs.len() {
                if self.t.len() as u32 <= budget.max_triangles {
                    return;
                }
                if self.collapse_now(h, self.pairs.as_slice()[k].parent, &mut fans, false) {
                    stats.ecols += 1;
                    stats.budget_ecols += 1;
                    progress = true;
                }
            }
            if !progress {
                break;
            }
        }
        stats.over_budget = self.t.len() as u32 > budget.max_triangles;
    }
}
