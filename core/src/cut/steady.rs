//! Frame-to-frame coherence: which vertices a frame may skip because their answers cannot have
//! changed since an anchor frame.
//!
//! A camera moves a little each frame, and most of a cut's answers do not change: a vertex far
//! from wanting a split still wants none, a pair whose parent is well in view, facing the eye
//! and far over the threshold is still wanted. When the policy describes how its demand depends
//! on the view ([`Envelope`]), an anchor frame asks every vertex as usual and also measures each
//! answer's margin: how far the eye (and the frustum's planes, over the model's bounding sphere)
//! may move before the answer could change. A vertex or pair whose margin covers `STEPS` times
//! the camera's mean step since the previous anchor is marked settled (the `SETTLED` flag);
//! later frames skip settled
//! vertices as long as the eye stays within that reach of the anchor's, the planes within that
//! sway, and the policy's envelope and the threshold are unchanged. The first frame that leaves
//! the reach anchors again; after an anchor that settled under an eighth of the vertices (a
//! camera that moves far each frame) the next `2 STEPS` frames do not anchor, since an anchor
//! costs more than a plain frame. Skipping changes no decision: every skipped answer is proven the same
//! as asking would give (with a relative slack far above float rounding), so frames are the
//! same with or without it, only faster.
//!
//! With geomorphs a vertex settles only when it is in no blend and whether it is seen (which
//! decides whether a change around it blends) provably stays what it was in the frame before.
//! Only for policies that do not judge triangles. Any operation that changes a vertex's family
//! (its sibling link, its node, its pair's illegal mark on either child) clears its mark.

use crate::policy::{dot, sub, Bounds, Envelope, View};

/// How many of the camera's mean steps since the previous anchor an anchor's margins must
/// cover: the anchor holds for about this many frames of steady motion.
const STEPS: f32 = 4.0;
/// Relative slack on every margin, far above float rounding.
const SLACK: f32 = 1e-4;

/// A frustum's planes as `(n, d)` (left, right, bottom, top, near).
type Planes = [[f32; 4]; 5];

fn planes(view: &View) -> Planes {
    core::array::from_fn(|i| view.plane(i).unwrap_or([0.0; 4]))
}

/// How far any point within `radius` of `center` moves relative to any plane between `a` and
/// `b`: `max_i |n_a - n_b| radius + |(n_a - n_b) . center + d_a - d_b|`.
fn sway(a: &Planes, b: &Planes, (center, radius): ([f32; 3], f32)) -> f32 {
    let mut most = 0.0f32;
    for (p, q) in a.iter().zip(b) {
        let dn = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let shift = libm::sqrtf(dot(dn, dn)) * radius + libm::fabsf(dot(dn, center) + p[3] - q[3]);
        most = most.max(shift);
    }
    most
}

/// An anchor frame's terms for the `stays_*` tests, computed once per anchor: a vertex whose
/// spheroid radius is at most `s` wants no split while it is at least `s scale` from the eye;
/// `slop` covers float rounding on any distance from the eye to a node centre.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Margins {
    scale: f32,
    slop: f32,
}

/// What a frame does with the settled vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Asks every vertex; the `SETTLED` flags mean nothing.
    Off,
    /// Asks every vertex and marks the settled ones.
    Anchor,
    /// Skips the settled vertices.
    Skip,
}

/// The anchor frame and the margins its settled vertices have (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Steady {
    /// Whether an anchor was set since the cut was reset.
    set: bool,
    /// Never skip (see `Cut::set_settling`).
    off: bool,
    /// Whether the vertices' `SETTLED` flags were set against the anchor.
    valid: bool,
    /// Frames since the anchor.
    frames: u16,
    /// Frames left without anchoring: the last anchor settled too few vertices to pay for
    /// itself (the camera moves too far per frame).
    idle: u16,
    /// Whether geomorphs were on at the anchor (settling then also proved visibility).
    blends: bool,
    eye: [f32; 3],
    planes: Planes,
    envelope: Envelope,
    threshold: f32,
    /// How far the eye may move from the anchor's.
    reach: f32,
    /// How far the planes may move within the model's bounding sphere.
    sway: f32,
}

impl Steady {
    /// No anchor (all zeros).
    pub const ZERO: Steady = Steady {
        set: false,
        off: false,
        valid: false,
        frames: 0,
        idle: 0,
        blends: false,
        eye: [0.0; 3],
        planes: [[0.0; 4]; 5],
        envelope: Envelope::ZERO,
        threshold: 0.0,
        reach: 0.0,
        sway: 0.0,
    };

    /// Starts a frame seen from `view` with threshold `t`: skips the settled vertices when the
    /// anchor holds (same `envelope`, threshold and geomorphs on or off, eye within the reach,
    /// planes within the sway over the bounding sphere `model`), else anchors here when it can
    /// (`envelope` known), else asks everything.
    pub fn begin(
        &mut self,
        view: &View,
        envelope: Option<Envelope>,
        t: f32,
        blends: bool,
        model: ([f32; 3], f32),
    ) -> Mode {
        self.frames = self.frames.saturating_add(1);
        let Some(envelope) = envelope.filter(|_| !self.off) else {
            self.valid = false;
            return Mode::Off;
        };
        if self.idle > 0 {
            self.idle -= 1;
            self.valid = false;
            return Mode::Off;
        }
        let now = planes(view);
        let moved = sub(view.eye, self.eye);
        let moved = libm::sqrtf(dot(moved, moved));
        let swayed = sway(&self.planes, &now, model);
        if self.valid
            && envelope == self.envelope
            && t == self.threshold
            && blends == self.blends
            && moved <= self.reach
            && (!envelope.frustum || swayed <= self.sway)
        {
            return Mode::Skip;
        }
        // The margins cover `STEPS` times the mean step since the last anchor.
        let steps = STEPS / self.frames as f32;
        let (reach, sway_) = if self.set {
            (moved * steps, swayed * steps)
        } else {
            (0.0, 0.0)
        };
        *self = Steady {
            set: true,
            off: false,
            valid: reach.is_finite() && sway_.is_finite(),
            frames: 0,
            idle: 0,
            blends,
            eye: view.eye,
            planes: now,
            envelope,
            threshold: t,
            reach,
            sway: sway_,
        };
        Mode::Anchor
    }

    /// After an anchor frame that settled `settled` of `vertices`: when that is under one in
    /// eight, the next `2 STEPS` frames do not anchor (an anchor costs more than a plain frame,
    /// and a camera that moves that far per frame leaves little to skip).
    pub fn anchored(&mut self, settled: usize, vertices: usize) {
        if settled * 8 < vertices {
            self.idle = 2 * STEPS as u16;
        }
    }

    /// Forgets everything but whether it is on (a new hierarchy).
    pub fn clear(&mut self) {
        *self = Steady {
            off: self.off,
            ..Steady::ZERO
        };
    }

    /// Turns skipping on or off (it starts on).
    pub fn set_on(&mut self, on: bool) {
        self.off = !on;
        self.valid = false;
    }

    /// The terms of this anchor frame, with envelope scale `upper`, threshold `t` and the cut's
    /// bound slack `slack`, every node centre within the sphere `model`: the square roots once
    /// per anchor instead of once per vertex.
    pub fn margins(&self, upper: f32, t: f32, slack: f32, model: ([f32; 3], f32)) -> Margins {
        let to = sub(model.0, self.eye);
        let farthest = libm::sqrtf(dot(to, to)) + model.1;
        Margins {
            scale: libm::sqrtf(upper * slack * (1.0 + SLACK) / t),
            slop: SLACK * (farthest + self.reach),
        }
    }

    /// Whether a vertex of spheroid radius `s` and bounding radius `radius`, at `d2` from the
    /// anchor's eye, keeps its bound `s^2 upper / d^2` at most `t / slack` within the reach
    /// (`slack` the cut's own margin on its bound), and its sphere beyond the envelope's near
    /// zone: whether `d >= max(s sqrt(upper slack / t), near + radius) + reach`, with float slop.
    pub fn stays_quiet(&self, m: &Margins, s: f32, radius: f32, d2: f32) -> bool {
        let near = self.envelope.near;
        let zone = if near > 0.0 {
            (near + radius) * (1.0 + SLACK)
        } else {
            0.0
        };
        let least = (s * m.scale).max(zone) + self.reach + m.slop;
        d2 >= least * least
    }

    /// Whether a vertex that wants no split (spheroid radius `s`, sphere `(center, radius)` at
    /// `d2` from the anchor's eye) provably wants none within the reach and sway: it stays
    /// quiet ([`Steady::stays_quiet`]), or the envelope culls by the frustum and the sphere
    /// stays out of it (a culled vertex's error is 0).
    pub fn stays_unwanted(
        &self,
        m: &Margins,
        s: f32,
        (center, radius): ([f32; 3], f32),
        d2: f32,
    ) -> bool {
        self.stays_quiet(m, s, radius, d2)
            || (self.envelope.frustum && self.stays_visible(m, center, radius) == Some(false))
    }

    /// Whether a sphere at `center` of `radius` provably stays in the frustum (`Some(true)`)
    /// or out of it (`Some(false)`) within the sway.
    pub fn stays_visible(&self, m: &Margins, center: [f32; 3], radius: f32) -> Option<bool> {
        let margin = self.sway * (1.0 + SLACK) + m.slop;
        let (mut inside, mut outside) = (true, false);
        for p in &self.planes {
            let dist = p[0] * center[0] + p[1] * center[1] + p[2] * center[2] + p[3] + radius;
            let slop = margin + SLACK * libm::fabsf(p[3]);
            inside &= dist >= slop;
            outside |= dist < -slop;
        }
        if inside {
            Some(true)
        } else if outside {
            Some(false)
        } else {
            None
        }
    }

    /// Whether a parent with bounds `b` stays wanted within the reach and sway: seen (with
    /// margin from every culling plane), facing the eye (with margin), and its error's lower
    /// bound over `t * slack` wherever the eye gets: the spheroid's at the farthest the eye
    /// can get while the sphere may be beyond the near zone, the near error while it may be
    /// inside.
    pub fn stays_wanted(&self, m: &Margins, b: &Bounds, t: f32, slack: f32) -> bool {
        let e = &self.envelope;
        let seen = !e.frustum || self.stays_visible(m, b.center, b.radius) == Some(true);
        let r = sub(b.center, self.eye);
        let d = libm::sqrtf(dot(r, r));
        let rn = dot(r, b.axis);
        let shift = self.reach + m.slop;
        // Not facing away (`s <= 0` or `s^2 <= d2 cone_sin^2`, `s = rn - radius`) wherever the
        // eye gets: `s` grows by at most the reach, `d` shrinks by at most the reach.
        let s = rn - b.radius + shift;
        let facing = !e.back_face || s <= ((d - shift) * b.cone_sin).max(0.0);
        // The error's lower bound where the eye is farthest from the centre and nearest the
        // axis: `max(b2 d2, a2 p2) lower / d2^2`.
        let far = d + shift;
        let p = (libm::sqrtf((d * d - rn * rn).max(0.0)) - shift).max(0.0);
        // Less what rounding can take from the policy's own sum (which cancels when the eye is
        // near the axis): far below this share of its largest term.
        let floor = (b.b2 * far * far).max(b.a2 * p * p) - SLACK * b.a2.max(b.b2) * far * far;
        let spheroid = floor * e.lower > t * slack * (1.0 + SLACK) * far * far * far * far;
        // Where the sphere can get relative to the near zone (`d - radius < near`).
        let edge = e.near + b.radius;
        let inside = e.near > 0.0 && far * (1.0 + SLACK) < edge;
        let outside = e.near == 0.0 || d - shift >= edge * (1.0 + SLACK);
        let near = e.near_error > t * slack * (1.0 + SLACK);
        seen && facing
            && if inside {
                near
            } else {
                spheroid && (outside || near)
            }
    }
}
