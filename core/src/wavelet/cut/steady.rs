//! The wavelet cut's frame-to-frame coherence: which wavelets a frame may skip because their
//! answers cannot have changed since an anchor frame.
//!
//! A camera moves a little each frame, and most answers do not change. When the policy
//! describes how its demand depends on the view ([`crate::policy::Envelope`]), an anchor frame
//! asks every wavelet as usual and also proves, with the margins of `crate::cut::margin`, which
//! answers hold while the eye moves less than the reach and the frustum's planes sway less than
//! the sway: `STEPS` times the camera's mean step since the previous anchor. Later frames skip
//! those while the eye stays within that reach of the anchor's, the planes within that sway,
//! and the policy's envelope and the threshold are unchanged. The first frame that leaves the
//! reach anchors again; after an anchor that settled under an eighth of the wavelets (a camera
//! that moves far each frame) the next `2 STEPS` frames do not anchor, since an anchor costs
//! more than a plain frame. Skipping changes no decision: frames are the same with or without
//! it, only faster. (The vertex cut keeps a per-vertex expiry instead: `crate::cut::expiry`.)

use crate::cut::margin::{planes, sway, Margins, Planes};
use crate::policy::{dot, sub, Bounds, Envelope, View};

/// How many of the camera's mean steps since the previous anchor an anchor's margins must
/// cover: the anchor holds for about this many frames of steady motion.
const STEPS: f32 = 4.0;

/// What a frame does with the settled wavelets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Asks every wavelet; the settled bits mean nothing.
    Off,
    /// Asks every wavelet and marks the settled ones.
    Anchor,
    /// Skips the settled wavelets.
    Skip,
}

/// The anchor frame and the margins its settled wavelets have (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Steady {
    /// Whether an anchor was set since the cut was reset.
    set: bool,
    /// Never skip (see `Cut::set_settling`).
    off: bool,
    /// Whether the wavelets' settled bits were set against the anchor.
    valid: bool,
    /// Frames since the anchor.
    frames: u16,
    /// Frames left without anchoring: the last anchor settled too few wavelets to pay for
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

    /// Starts a frame seen from `view` with threshold `t`: skips the settled wavelets when the
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
        let moved = crate::root::sqrtf(dot(moved, moved));
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

    /// The terms of this anchor frame, with threshold `t` and the cut's bound slack `slack`,
    /// every node centre within the sphere `model`.
    pub fn margins(&self, t: f32, slack: f32, model: ([f32; 3], f32)) -> Margins {
        let (eye, planes) = (self.eye, self.planes);
        Margins::new(eye, planes, self.envelope, (t, slack), model, self.reach)
    }

    /// Whether a wavelet that wants no split (spheroid radius `s`, sphere `(center, radius)`
    /// at `d2` from the anchor's eye) provably wants none within the reach and sway.
    pub fn stays_unwanted(
        &self,
        m: &Margins,
        s: f32,
        (center, radius): ([f32; 3], f32),
        d2: f32,
    ) -> bool {
        let seen = if m.culls() {
            m.visibility(center, radius)
        } else {
            (None, f32::NAN)
        };
        m.unwanted(s, radius, d2, seen).holds(self.reach, self.sway)
    }

    /// Whether a parent with bounds `b` provably stays wanted within the reach and sway.
    pub fn stays_wanted(&self, m: &Margins, b: &Bounds, t: f32, slack: f32) -> bool {
        m.wanted(b, (t, slack), (self.reach, 1))
            .holds(self.reach, self.sway)
    }
}
