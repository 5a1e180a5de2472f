//! One frame of selective refinement: [`Cut::adapt`].
//!
//! Incremental from the previous frame's cut, as in the merge-tree paper (§3.5) and Hoppe's
//! `adapt_refinement`: one pass over the active vertices asks the [`Policy`] about each, then
//!
//! 1. **coarsen**: sibling pairs whose parent the policy no longer needs are collapsed where
//!    Hoppe's condition allows (collapses it forbids wait for a later frame);
//! 2. **refine**: vertices over tolerance are split largest error first (a priority queue), each
//!    forcing the splits it depends on, and their children join the queue;
//! 3. **budget**: splits stop at [`Budget::max_triangles`]; when the budget binds, pairs whose
//!    parent's error is below the next split's are collapsed to make room, so the cut is the best
//!    the budget allows. [`Budget::target_triangles`] regulates the error threshold from frame to
//!    frame (the LOD lecture's regulation), [`Budget::max_ops`] caps the splits and collapses of
//!    one frame (its amortization).
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
//! let mut cut = Box::new(Cut::<512, 1024, 256>::new());
//! cut.reset(&h).unwrap();
//! let view = View::look_at([8.0, 8.0, 12.0], [8.0, 8.0, 0.0], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
//! let budget = Budget { max_triangles: 200, ..Budget::default() };
//! let stats = cut.adapt(&h, &view, &QRefine::new(1.0), &budget);
//! assert!(stats.vsplits > 0 && stats.triangles <= 200);
//! assert_eq!(stats.triangles as usize, cut.triangles().len());
//! assert!(cut.check(&h).is_ok());
//! # }
//! ```

use crate::cut::{
    Cut, Morph, PairFans, Refused, BLENDING, BLOCKED, COLLAPSING, VISIBLE, WAS_VISIBLE,
};
use crate::format::{HierarchyView, NONE};
use crate::policy::{Policy, View};

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
    /// Splits plus collapses per frame at most.
    pub max_ops: u32,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            max_triangles: u32::MAX,
            target_triangles: 0,
            target_band: 0.05,
            max_ops: u32::MAX,
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
    /// More triangles than [`Budget::max_triangles`] remain (collapses the budget needed were
    /// not legal yet, or the base mesh alone is larger).
    pub over_budget: bool,
}

#[inline]
fn lerp3(a: [f32; 3], b: [f32; 3], s: f32) -> [f32; 3] {
    [
        a[0] + (b[0] - a[0]) * s,
        a[1] + (b[1] - a[1]) * s,
        a[2] + (b[2] - a[2]) * s,
    ]
}

/// A pair's parent's error as the collapse candidates keep it: negative when culled, so that
/// culled pairs collapse first and without a blend.
#[inline]
fn pair_error(d: crate::policy::Demand) -> f32 {
    if d.visible {
        d.error
    } else {
        -1.0
    }
}

/// Sorts `(error, id)` pairs by error, then id (a total order: the result never depends on the
/// order they were found in).
fn sort_pairs(pairs: &mut [(f32, u32, u32)]) {
    pairs.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
}

impl<const V: usize, const F: usize, const Q: usize> Cut<V, F, Q> {
    /// Splits and collapses blend over `frames` frames (0: no geomorphs, the default).
    pub fn set_geomorph_frames(&mut self, frames: u16) {
        self.geomorph_frames = frames;
    }

    /// The regulated error threshold (1 unless [`Budget::target_triangles`] moved it).
    pub fn threshold(&self) -> f32 {
        self.threshold
    }

    /// Advances vertex `i`'s blend by one frame.
    fn advance(&mut self, h: &HierarchyView<'_>, i: usize) {
        let m = &mut self.morph[i];
        if m.left == 0 {
            self.flags[i] &= !BLENDING;
            return;
        }
        let total = self.geomorph_frames.max(1);
        m.left = (m.left - 1).min(total);
        if m.left == 0 {
            self.flags[i] &= !BLENDING;
        }
        let done = 1.0 - m.left as f32 / total as f32;
        let m = *m;
        let (pos, normal, color) = if m.collapsing {
            let p = h.node(h.parent(self.node[i]));
            (p.position, p.normal, self.tint_of(&p))
        } else {
            let b = self.bounds[i];
            (b.center, b.axis, self.tint[i])
        };
        if m.left == 0 {
            // Arrived: exactly the target (a + (b - a) need not round to b).
            self.positions[i] = pos;
            self.normals[i] = normal;
            self.colors[i] = color;
            return;
        }
        self.positions[i] = lerp3(m.from_pos, pos, done);
        let n = lerp3(m.from_normal, normal, done);
        let l = libm::sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        self.normals[i] = if l > 1e-12 {
            [n[0] / l, n[1] / l, n[2] / l]
        } else {
            normal
        };
        let c = |k: usize| {
            let (a, b) = (m.from_color[k] as f32, color[k] as f32);
            (a + (b - a) * done + 0.5) as u8
        };
        self.colors[i] = [c(0), c(1), c(2)];
    }

    /// Starts (or reverses) a blend of slot `i`: towards the parent when `collapsing`, else
    /// towards its own node, from where it is now.
    fn start_blend(&mut self, i: usize, collapsing: bool) {
        self.morph[i] = Morph {
            from_pos: self.positions[i],
            from_normal: self.normals[i],
            from_color: self.colors[i],
            left: self.geomorph_frames,
            collapsing,
        };
        self.flags[i] &= !(BLENDING | COLLAPSING);
        if self.geomorph_frames > 0 {
            self.flags[i] |= BLENDING;
        }
        if collapsing {
            self.flags[i] |= COLLAPSING;
        }
    }

    fn sibling_active(&self, h: &HierarchyView<'_>, i: usize) -> bool {
        let p = self.family[i][0];
        p != NONE && {
            let [c0, c1] = h.split(p).children;
            let other = if c0 == self.node[i] { c1 } else { c0 };
            self.slot_of.get(other).is_some()
        }
    }

    /// Marks the pair at slots `a` and `b` as found illegal (see [`crate::cut`]'s `BLOCKED`).
    fn block(&mut self, a: usize, b: usize) {
        self.flags[a] |= BLOCKED;
        self.flags[b] |= BLOCKED;
    }

    /// Collapses `parent` now if legal; `true` when done.
    fn collapse_now(&mut self, h: &HierarchyView<'_>, parent: u32) -> bool {
        let mut fans = PairFans::default();
        match self.collapse_legal(h, parent, &mut fans) {
            Ok(slots) => {
                self.collapse_unchecked(h, parent, slots, &fans);
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
        let mut stats = FrameStats::default();
        let t = self.threshold;
        let frames = self.geomorph_frames;
        let mut ops = 0u32;
        self.candidates.clear();
        self.pairs.clear();

        // One pass: blends advance, the policy speaks for every vertex and every sibling pair.
        for i in 0..self.node.len() {
            if self.flags[i] & BLENDING != 0 {
                self.advance(h, i);
            }
            let d = policy.demand(&self.bounds[i], view);
            let was = if self.flags[i] & VISIBLE != 0 {
                WAS_VISIBLE
            } else {
                0
            };
            self.flags[i] =
                (self.flags[i] & (BLOCKED | BLENDING | COLLAPSING)) | was | d.visible as u8;
            let node = self.node[i];
            if self.flags[i] & COLLAPSING != 0 && !self.sibling_active(h, i) {
                // The pair was broken up (a forced split took the sibling): blend back.
                self.start_blend(i, false);
            }
            if d.error > t && node >= h.leaves() {
                if self.flags[i] & COLLAPSING != 0 {
                    // Wanted again: reverse the collapse's blend; no split this frame.
                    self.start_blend(i, false);
                } else if self.candidates.push((d.error.to_bits(), node)).is_err() {
                    stats.queue_overflow = true;
                }
                continue;
            }
            let Some(p) = self.pair_parent(i) else {
                continue;
            };
            let e = pair_error(policy.demand(&self.parent_bounds[i], view));
            let j = self.family[i][2] as usize;
            if e <= t && self.flags[i] & self.flags[j] & BLOCKED != 0 {
                continue;
            }
            if e > t {
                // The parent is wanted: a collapse under way blends back.
                if (self.flags[i] | self.flags[j]) & COLLAPSING != 0 {
                    self.start_blend(i, false);
                    self.start_blend(j, false);
                }
            }
            if self.pairs.push((e, p, i as u32)).is_err() {
                stats.queue_overflow = true;
            }
        }

        // Coarsen where the parent is no longer needed.
        for k in 0..self.pairs.len() {
            let (e, p, first) = self.pairs[k];
            if e > t {
                continue;
            }
            // The first child's slot from the pass, unless a collapse since moved it.
            let a = if self.family.get(first as usize).map(|f| f[0]) == Some(p)
                && self.pair_parent(first as usize) == Some(p)
            {
                first
            } else {
                match self.slot_of.get(h.split(p).children[0]) {
                    Some(a) if self.pair_parent(a as usize) == Some(p) => a,
                    _ => continue,
                }
            };
            let b = self.family[a as usize][2];
            let (a, b) = (a as usize, b as usize);
            let (ma, mb) = (self.morph[a], self.morph[b]);
            let blending = self.flags[a] & self.flags[b] & COLLAPSING != 0;
            if ops >= budget.max_ops {
                stats.ops_limited = true;
                break;
            }
            let seen = e >= 0.0 && (self.flags[a] | self.flags[b]) & WAS_VISIBLE != 0;
            if blending && (ma.left > 0 || mb.left > 0) {
                continue;
            }
            let split = h.split(p);
            let mut fans = PairFans::default();
            if !blending && frames > 0 && seen {
                if self
                    .collapse_legal_at(h, p, &split, a as u32, b as u32, &mut fans)
                    .is_ok()
                {
                    self.start_blend(a, true);
                    self.start_blend(b, true);
                } else {
                    self.block(a, b);
                }
                continue;
            }
            if let Ok(slots) = self.collapse_legal_at(h, p, &split, a as u32, b as u32, &mut fans) {
                self.collapse_unchecked(h, p, slots, &fans);
                stats.ecols += 1;
                ops += 1;
            } else if !blending {
                self.block(a, b);
            } else {
                // Arrived, but the neighbourhood changed meanwhile: blend back.
                self.start_blend(a, false);
                self.start_blend(b, false);
            }
        }

        // Refine, largest error first, within the budget.
        let mut traded = 0usize;
        let mut sorted = false;
        while let Some((bits, v)) = self.candidates.pop() {
            let Some(s) = self.slot_of.get(v) else {
                continue;
            };
            if ops >= budget.max_ops {
                stats.ops_limited = true;
                break;
            }
            let blend = if self.flags[s as usize] & WAS_VISIBLE != 0 {
                frames
            } else {
                0
            };
            let before = self.node.len();
            let mut tris = self.tri.len() as u32;
            let mut spent = ops;
            // The nodes split (forced ones first): their children are evaluated next (past 64
            // forced splits, the rest wait for the next frame's pass).
            let mut split = [0u32; 64];
            let mut logged = 0usize;
            let result = self.force_split(h, v, blend, &mut |node, added| {
                if tris.saturating_add(added) > budget.max_triangles {
                    Err(Refused::Budget)
                } else if spent >= budget.max_ops {
                    Err(Refused::Ops)
                } else {
                    tris += added;
                    spent += 1;
                    if let Some(slot) = split.get_mut(logged) {
                        *slot = node;
                        logged += 1;
                    }
                    Ok(())
                }
            });
            let done = (self.node.len() - before) as u32;
            stats.vsplits += done;
            stats.forced += done.saturating_sub(result.is_ok() as u32);
            ops += done;
            for &node in &split[..logged] {
                if self.slot_of.get(node).is_some() {
                    continue; // refused after all
                }
                for c in h.split(node).children {
                    let Some(cs) = self.slot_of.get(c) else {
                        continue;
                    };
                    let d = policy.demand(&self.bounds[cs as usize], view);
                    self.flags[cs as usize] =
                        (self.flags[cs as usize] & !VISIBLE) | d.visible as u8;
                    if d.error > t
                        && c >= h.leaves()
                        && self.candidates.push((d.error.to_bits(), c)).is_err()
                    {
                        stats.queue_overflow = true;
                    }
                }
            }
            match result {
                Ok(_) => {}
                Err(Refused::Budget) => {
                    // Make room from the pairs whose parent matters least, if less than this.
                    if !sorted {
                        sort_pairs(&mut self.pairs);
                        sorted = true;
                    }
                    let e = f32::from_bits(bits);
                    let mut freed = false;
                    while traded < self.pairs.len() && ops < budget.max_ops {
                        let (pe, p, _) = self.pairs[traded];
                        if pe >= e {
                            break;
                        }
                        traded += 1;
                        if self.collapse_now(h, p) {
                            stats.ecols += 1;
                            ops += 1;
                            freed = true;
                            if self.tri.len() as u32 + 2 <= budget.max_triangles {
                                break;
                            }
                        }
                    }
                    if freed && self.candidates.push((bits, v)).is_ok() {
                        continue;
                    }
                    stats.budget_limited = true;
                    break;
                }
                Err(Refused::Capacity) => {
                    stats.capacity_limited = true;
                    break;
                }
                Err(Refused::Ops) => {
                    stats.ops_limited = true;
                    break;
                }
                Err(_) => {}
            }
        }

        self.enforce_max(h, view, policy, budget, &mut stats);
        // A cut that shrank gets a smaller node map (faster lookups).
        self.respan_map(self.node.len());

        // Regulation towards the target triangle count.
        let tris = self.tri.len() as u32;
        if budget.target_triangles > 0 {
            let ratio = tris.max(1) as f32 / budget.target_triangles as f32;
            if (ratio - 1.0).abs() > budget.target_band {
                self.threshold = (self.threshold * ratio.clamp(0.5, 2.0)).clamp(1e-6, 1e6);
            }
        }
        stats.triangles = tris;
        stats.vertices = self.node.len() as u32;
        stats.threshold = t;
        stats.blending = self.flags.iter().filter(|&&f| f & BLENDING != 0).count() as u32;
        stats
    }

    /// Collapses the least needed pairs until the cut fits [`Budget::max_triangles`] (after the
    /// budget was lowered, or while collapse blends still hold triangles).
    fn enforce_max<P: Policy>(
        &mut self,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &P,
        budget: &Budget,
        stats: &mut FrameStats,
    ) {
        for _ in 0..64 {
            if self.tri.len() as u32 <= budget.max_triangles {
                return;
            }
            self.pairs.clear();
            for i in 0..self.node.len() {
                if let Some(p) = self.pair_parent(i) {
                    let e = pair_error(policy.demand(&self.parent_bounds[i], view));
                    if self.pairs.push((e, p, i as u32)).is_err() {
                        stats.queue_overflow = true;
                        break;
                    }
                }
            }
            sort_pairs(&mut self.pairs);
            let mut progress = false;
            for k in 0..self.pairs.len() {
                if self.tri.len() as u32 <= budget.max_triangles {
                    return;
                }
                if self.collapse_now(h, self.pairs[k].1) {
                    stats.ecols += 1;
                    stats.budget_ecols += 1;
                    progress = true;
                }
            }
            if !progress {
                break;
            }
        }
        stats.over_budget = self.tri.len() as u32 > budget.max_triangles;
    }
}
