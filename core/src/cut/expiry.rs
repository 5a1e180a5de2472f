//! The vertex cut's frame-to-frame coherence: a settled vertex carries the camera motion at
//! which its answers expire, and frames skip it until the camera has moved that far.
//!
//! A camera moves a little each frame, and most of a cut's answers do not change: a vertex far
//! from wanting a split still wants none, a pair whose parent is well in view and far over the
//! threshold is still wanted. When the policy describes how its demand depends on the view
//! ([`crate::policy::Envelope`]), each vertex the walk asks also gets the margins of its
//! answers (`super::margin`): how far the eye may move and the frustum's planes sway before
//! they could change. The cut counts the camera's motion since the marks were made, each
//! frame's step being the larger of the eye's movement and the planes' sway over the model's
//! bounding sphere, the sway weighed by a scale measured from the camera's own motion (both
//! distances, so the sum of the steps bounds how far either has gone; see `SwayScale`),
//! rounded up to whole quanta of a 4096th of the model's radius. A vertex whose margin covers
//! at least the camera's last step is marked settled with the count at which it
//! expires; frames skip it until the count passes that. A vertex far from any change is asked
//! again only after the camera has moved most of the way to it; one near a change is asked
//! every frame, and since measuring its margins would not pay, it is marked restless and
//! measures them one frame in four; after a frame whose measures settled under an eighth of
//! the vertices or that skipped fewer vertices than it measured (a camera that moves far each
//! frame), every vertex measures one frame in 16.
//! There are no anchor frames, so no frame costs more than its neighbours.
//!
//! A second count runs beside the first: the camera's motion as seen from the camera
//! (`super::rigid`), in turns, under which a point moves at most the turns times its distance
//! from the model's centre (at least an eighth of the model's radius). Whether a vertex wants a
//! split, whether its sphere is in view and whether its pair's parent is still wanted (but for
//! its normal cone, which turns with the camera) depend only on distances a point keeps in the
//! camera's frame, so their margins count there too, divided by that distance. A vertex is
//! marked on the count on which its margins last more frames at the last frame's steps, with
//! the count's bit in its expiry: for a camera circling the model, the turning count lets a
//! vertex near the centre stay settled several times as long (the peer orbit asks 38% fewer
//! vertices a frame than on the eye's path alone). A camera that has turned about one axis for
//! a few frames (an orbit, a turntable) gets that axis, through the point it circles: a point
//! then counts its distance from the axis, not from the centre, and a plane's margin its
//! normal's part across the axis (`super::rigid`), so a vertex above the centre, or near the
//! top or bottom plane of a camera circling about its vertical, stays settled longer (Table 1's
//! 0.4 flight asks 29% fewer vertices a frame); a step about another axis drops it, with the
//! marks made about it.
//!
//! Skipping changes no decision: every skipped answer is proven the same as asking would give
//! (with a relative slack far above float rounding), so frames are the same with or without
//! it, only faster. A change of the policy's envelope, the threshold or geomorphs on or off, a
//! frame that skips nothing by design (a window of the active list) or a jump of the camera
//! forgets every mark.
//!
//! The expiry (with its count's bit) shares its 16-bit field with the vertex's blend entry
//! (`super::store`): a vertex in a geomorph is asked every frame, so it is never settled. With
//! geomorphs a vertex settles only when whether it is seen (which decides whether a change
//! around it blends) provably stays what it was in the frame before, and only on the first
//! count. Only for policies that do not judge triangles. Any operation that changes a vertex's
//! family (its sibling link, its node, its pair's illegal mark on either child) clears its
//! mark.

use super::margin::{planes, sway, Either, Margins, Planes};
use super::rigid::{self, norm, Axes};
use super::RESTLESS;
use crate::policy::{add, cross, dot, sub, Envelope, View};

/// Quanta of motion per unit of the model's bounding radius.
const QUANTA_PER_RADIUS: f32 = 4096.0;
/// Quanta of the turning count per unit of its step (see [`rigid::step`]).
const QUANTA_PER_TURN: f32 = 4096.0;
/// The turning count's lever floor, in the model's radii: a vertex nearer the centre counts
/// as this far from it.
const LEVER: f32 = 0.125;
/// When a count reaches this, it and every live expiry on it are lowered by it.
pub(crate) const REBASE: u32 = 1 << 14;
/// The longest margin kept, in quanta: expiries stay below `2 REBASE - 1`.
const CAP: u32 = REBASE - 2;
/// The tag bit of an expiry on the turning count; with an expiry below `2 REBASE - 1` a 16-bit
/// slot field holds it besides its all-ones `NIL`.
pub(crate) const TURNING: u32 = 1 << 15;

/// Whether a settled vertex's tag `tag` has not expired at the counts `now` (travelled,
/// turned).
#[inline(always)]
pub(crate) fn lives(tag: u32, now: [u32; 2]) -> bool {
    // The whole tag against its count's threshold, picked without a branch or an indexed load
    // (a lane of the eight-wide test); `u32::MAX` counts (a frame that trusts no mark) keep no
    // tag alive.
    let turning = (tag >> 15).wrapping_neg();
    tag >= now[0] ^ ((now[0] ^ TURNING.saturating_add(now[1])) & turning)
}
/// Steps a camera turns about one axis before the turning count's marks are made about it.
const HELD: u8 = 4;
/// Two steps' axes are one when the sine between them is under this.
const SAME_AXIS: f32 = 0.01;
/// A longer single step (a jump of the camera) forgets every mark.
const JUMP: f32 = (1 << 14) as f32;

/// What the cut does with its marks before a frame's walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Renew {
    /// They hold.
    Keep,
    /// They are stale: clear every mark.
    Forget,
    /// The counts (travelled, turned) were lowered by these, each 0 or [`REBASE`]: lower
    /// every live expiry on each as much, clear the expired ones.
    Rebase([u32; 2]),
}

/// What an asked vertex's measured margins make of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mark {
    /// Skipped until the count passes this: the travelled count's, or the turning count's
    /// with the [`TURNING`] bit (see [`lives`]).
    Settled(u32),
    /// The margins cover less than a step of the camera (or are unproven): the next asks
    /// measure them only in turn, one frame in [`TURN`].
    Restless,
}

/// How many vertices a frame measured, and how many of them it settled.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Tally {
    pub measured: u32,
    pub settled: u32,
}

impl Tally {
    /// Counts a mark made from `margin` (`-inf`: not measured).
    #[inline(always)]
    pub fn count(&mut self, margin: f32, mark: Mark) {
        self.measured += u32::from(margin != f32::NEG_INFINITY);
        self.settled += u32::from(matches!(mark, Mark::Settled(_)));
    }
}

/// A restless vertex's margins are measured one frame in this many (staggered by slot).
const TURN: u32 = 4;
/// After a frame that settled under an eighth of what it measured, every vertex measures one
/// frame in this many.
const SPARSE_TURN: u32 = 16;
/// Fewer vertices measured than this in a frame do not make the next one sparse.
const SPARSE_SAMPLE: u32 = 64;

/// One frame's settling: the count, the margins' terms, and how to turn a margin into an
/// expiry.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Settling {
    /// The camera's motion so far, in quanta, as travelled and as turned (see
    /// [`rigid::step`]): a settled vertex whose expiry is below its count is asked.
    pub now: [u32; 2],
    pub margins: Margins,
    /// What to do with the marks first.
    pub renew: Renew,
    /// The camera's last step (model units, at least a quantum; the planes' sway counted at
    /// `scale`): the along-axis spheroid margins are tried at multiples of it.
    pub step: f32,
    /// Eye units per unit of the planes' sway (see [`SwayScale`]): a sway margin counts as
    /// `scale` times its length.
    pub scale: f32,
    quantum: f32,
    /// The camera's last step as turned (at least a quantum; infinite when it cannot be
    /// counted this frame).
    pub turn: f32,
    /// The model's centre and the lever floor (see [`Settling::turned`]).
    centre: ([f32; 3], f32),
    /// The axis the turning count's marks are made about (zero for none).
    axis: [f32; 3],
    /// The eye's distance from the model's centre.
    eye: f32,
    /// Frames since the marks were made (wrapping), for the restless vertices' turns.
    tick: u32,
    /// The last frame settled under an eighth of the vertices it measured.
    sparse: bool,
}

impl Settling {
    /// Whether an asked vertex with `flags` at `slot` measures its margins this frame: always,
    /// unless it is restless and it is not its turn (one frame in [`TURN`]); after a frame
    /// whose measures settled too few to pay, only in its turn (one frame in [`SPARSE_TURN`]).
    #[inline(always)]
    pub fn measures(&self, flags: u8, slot: usize) -> bool {
        let turn = self.tick.wrapping_add(slot as u32);
        if self.sparse {
            turn.is_multiple_of(SPARSE_TURN)
        } else {
            (flags & RESTLESS == 0) | turn.is_multiple_of(TURN)
        }
    }

    /// The mark of a vertex whose answers' margin is `margin` as the eye travels (model
    /// units) and `turned` as the camera turns (in turns, see [`Settling::turned`]; `-inf` for
    /// either when not measured, NaN when unproven): on the count on which it lasts more frames
    /// at the last steps, settled when that is at least one frame.
    #[inline(always)]
    pub fn mark(&self, (margin, turned): (f32, f32)) -> Mark {
        // Both counts' expiries are computed first, so that picking one is a choice between
        // values, not a branch around work (which it is follows no pattern a branch predictor
        // learns).
        let reach = CAP as f32 * QUANTA_PER_TURN.recip();
        let frames = |m: f32, cap: f32, step: f32| {
            let frames = m.min(cap) / step;
            if m >= step {
                frames
            } else {
                0.0
            }
        };
        let travels = frames(margin, CAP as f32 * self.quantum, self.step);
        let turns = frames(turned, reach, self.turn);
        let by_turn = TURNING | (self.now[1] + ((turned * QUANTA_PER_TURN) as u32).min(CAP));
        let by_travel = self.now[0] + ((margin / self.quantum) as u32).min(CAP);
        if turns > travels {
            Mark::Settled(by_turn)
        } else if travels > 0.0 {
            Mark::Settled(by_travel)
        } else {
            Mark::Restless
        }
    }

    /// How far a node centred at `center` is from the axis the turning count's marks are made
    /// about, through the model's centre (from the centre itself without an axis).
    #[inline(always)]
    fn reach(&self, center: [f32; 3]) -> f32 {
        let r = sub(center, self.centre.0);
        let along = dot(r, self.axis);
        crate::root::sqrtf((dot(r, r) - along * along).max(0.0))
    }

    /// What [`Margins::wanted_turned`] needs of a parent centred at `center`: its
    /// [`Settling::reach`], the eye's distance from the model's centre and the lever floor.
    #[inline(always)]
    pub fn levers(&self, center: [f32; 3]) -> (f32, f32, f32) {
        (self.reach(center), self.eye, self.centre.1)
    }

    /// The margins `e` of a vertex that wants no split, centred at `center` with bounding
    /// `radius`, as turned: its eye margin over its lever (its reach, at least the floor), its
    /// sway margin plane by plane ([`Margins::turned_sway`]); `-inf` when neither could cover
    /// the last turning step at any lever (not worth the square root).
    #[inline(always)]
    pub fn turned(&self, e: Either, center: [f32; 3], radius: f32) -> f32 {
        let floor = self.centre.1;
        if e.displaced() >= self.turn * floor {
            let reach = self.reach(center);
            let sway = if e.sway > 0.0 {
                self.margins.turned_sway(center, radius, reach, floor)
            } else {
                f32::NEG_INFINITY
            };
            (e.eye / reach.max(floor)).max(sway)
        } else {
            f32::NEG_INFINITY
        }
    }
}

/// The camera's motion since the settled marks were made, and the terms they were made under.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Motion {
    /// Never skip (see `Cut::set_settling`).
    off: bool,
    /// Whether the marks were made under the terms below.
    valid: bool,
    /// The counts, travelled and turned.
    now: [u32; 2],
    quantum: f32,
    eye: [f32; 3],
    planes: Planes,
    /// The camera's axes at the last frame, when it had some (`has_axes`).
    axes: Axes,
    has_axes: bool,
    envelope: Envelope,
    threshold: f32,
    blends: bool,
    tick: u8,
    sparse: bool,
    /// Eye units per unit of the planes' sway in the count (see [`SwayScale`]), less one: zero
    /// is a scale of 1, so that a zeroed cut (`Cut::new`, a `static` in `.bss`) is a new one.
    scale_less_one: f32,
    /// The motion since the scale was last checked.
    seen: SwayScale,
    /// Whether this count has had its first check.
    checked: bool,
    /// The axis the turning count's marks are made about (a unit world direction; zero for
    /// none: about the model's centre).
    axis: [f32; 3],
    /// The axis the camera's last steps turned about, and for how many steps it has held.
    candidate: [f32; 3],
    held: Held,
    /// Where the axis passes, as an offset from the model's centre (zero without an axis): the
    /// point the turning count turns about, so that a camera circling a point off the centre
    /// does not shift it every step.
    offset: [f32; 3],
}

/// Steps a candidate axis has held (the low six bits) and axes dropped so far (the high two,
/// at most three): one byte, so that the cut keeps its size.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Held(u8);

impl Held {
    const STEPS: u8 = 63;

    /// Whether the candidate has held long enough to become the axis: [`HELD`] steps, twice
    /// as many after each drop.
    fn enough(self) -> bool {
        self.0 & Held::STEPS >= HELD << (self.0 >> 6)
    }

    /// One more step about the candidate.
    fn step(self) -> Held {
        Held(self.0 + u8::from(self.0 & Held::STEPS < Held::STEPS))
    }

    /// A new candidate: no steps yet.
    fn restart(self) -> Held {
        Held(self.0 & !Held::STEPS)
    }

    /// The axis was dropped: no steps, one more drop.
    fn dropped(self) -> Held {
        Held(((self.0 >> 6) + 1).min(3) << 6)
    }
}

/// How the count weighs the planes' sway against the eye's movement.
///
/// A step counts `max(eye movement, scale x planes' sway)`, and a margin of sway counts
/// `scale` times its length, so that a mark still expires before the eye has moved as far as
/// its eye margin *and* before the planes have swayed as far as its sway margin, for any fixed
/// positive `scale`. With `scale` 1 a camera circling a model at twice its radius spends its
/// vertices' plane margins twice as fast as the planes move (they turn about the model's
/// centre, sweeping its radius, while the eye travels the orbit's); the scale is therefore the
/// ratio of the two measured over the last frames. It changes only with the marks, which were
/// made under the old one: [`SwayScale::FIRST`] frames into the cut's motion, and every
/// [`SwayScale::EVERY`] frames after, when the ratio measured since has moved more than
/// [`SwayScale::DRIFT`] from the scale, the count forgets its marks and takes it. Frames are
/// the same under any scale; only how many vertices they skip differs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SwayScale {
    moved: f32,
    swayed: f32,
    frames: u8,
}

impl SwayScale {
    /// Nothing measured.
    const ZERO: SwayScale = SwayScale {
        moved: 0.0,
        swayed: 0.0,
        frames: 0,
    };
    /// Frames into a new count when the scale is first checked.
    const FIRST: u8 = 8;
    /// Frames between later checks.
    const EVERY: u8 = 128;
    /// A measured ratio within this factor of the scale keeps it.
    const DRIFT: f32 = 1.5;
    /// The scale stays within `1/LIMIT..=LIMIT` (positive and finite, so that an infinite
    /// margin stays infinite and a missing one missing).
    const LIMIT: f32 = 64.0;

    /// Adds a frame's step.
    fn add(&mut self, moved: f32, swayed: f32) {
        self.moved += moved;
        self.swayed += swayed;
        self.frames = self.frames.wrapping_add(1);
    }

    /// The ratio measured, when the eye or the planes moved at all.
    fn ratio(&self) -> Option<f32> {
        let ratio = self.moved / self.swayed;
        // 0/0 is NaN, which the comparison refuses.
        (ratio >= 0.0).then(|| ratio.clamp(1.0 / Self::LIMIT, Self::LIMIT))
    }
}

/// Whether a measured ratio `r` has moved more than [`SwayScale::DRIFT`] from `scale`.
fn drifted(scale: f32, r: f32) -> bool {
    r > scale * SwayScale::DRIFT || r * SwayScale::DRIFT < scale
}

impl Motion {
    /// No marks, no motion seen.
    pub const ZERO: Motion = Motion {
        off: false,
        valid: false,
        now: [0; 2],
        quantum: 0.0,
        eye: [0.0; 3],
        planes: [[0.0; 4]; 5],
        axes: Axes::ZERO,
        has_axes: false,
        envelope: Envelope::ZERO,
        threshold: 0.0,
        blends: false,
        tick: 0,
        sparse: false,
        scale_less_one: 0.0,
        seen: SwayScale::ZERO,
        checked: false,
        axis: [0.0; 3],
        candidate: [0.0; 3],
        held: Held(0),
        offset: [0.0; 3],
    };

    /// Starts a frame seen from `view` with threshold `t` and the cut's bound slack `slack`,
    /// every node centre within the sphere `model`: counts the camera's step and says what the
    /// marks need, or `None` (no skipping, no marking) when the policy has no `envelope` or
    /// skipping is off.
    pub fn begin(
        &mut self,
        view: &View,
        envelope: Option<Envelope>,
        (t, slack): (f32, f32),
        blends: bool,
        model: ([f32; 3], f32),
    ) -> Option<Settling> {
        let Some(envelope) = envelope.filter(|_| !self.off) else {
            self.valid = false;
            return None;
        };
        let now = planes(view);
        let moved = sub(view.eye, self.eye);
        let moved = crate::root::sqrtf(dot(moved, moved));
        let swayed = if envelope.frustum {
            sway(&self.planes, &now, model)
        } else {
            0.0
        };
        // The step as the count weighs it (see `SwayScale`).
        let scale = self.scale_less_one + 1.0;
        let step = |scale: f32| moved.max(scale * swayed);
        // And as turned, when both frames have axes.
        let lever = model.1 * LEVER;
        let offset = self.offset;
        let axes = Axes::of(view, &now, add(model.0, offset));
        let turned = match (&axes, self.has_axes) {
            (Some(b), true) => self.turning(b, model.1 + norm(offset), lever),
            _ => f32::INFINITY,
        };
        // An axis taken or dropped moves the pivot: this frame's axes are taken again about
        // the new one, so that the next step compares like with like.
        let pivot = add(model.0, self.offset);
        let axes = if self.offset == offset {
            axes
        } else {
            Axes::of(view, &now, pivot)
        };
        // Every node centre is within this of the pivot.
        let around = model.1 + norm(self.offset);
        let turns = libm::ceilf(turned * QUANTA_PER_TURN);
        let same =
            self.valid && envelope == self.envelope && t == self.threshold && blends == self.blends;
        let continues = same
            && libm::ceilf(step(scale) / self.quantum) <= JUMP
            && (turns <= JUMP || turned == f32::INFINITY);
        if continues && envelope.frustum {
            self.seen.add(moved, swayed);
        }
        let due = self.seen.frames
            == if self.checked {
                SwayScale::EVERY
            } else {
                SwayScale::FIRST
            };
        let drifted = self.seen.ratio().filter(|&r| due && drifted(scale, r));
        if due {
            self.seen = SwayScale::ZERO;
            self.checked = true;
        }
        // A larger scale only makes the marks made under the smaller one expire sooner (their
        // sway margins were counted at less than the count now spends on a sway): they hold.
        // Under a smaller one they could outlive their margins.
        let shrinks = drifted.is_some_and(|r| r < scale);
        if let Some(r) = drifted {
            self.scale_less_one = r - 1.0;
        }
        // The scale this frame counts its step and marks its vertices under.
        let scale = self.scale_less_one + 1.0;
        let renew = if !continues || shrinks {
            self.now = [0; 2];
            let q = model.1 / QUANTA_PER_RADIUS;
            // A degenerate model settles nothing (every margin is under an infinite quantum).
            self.quantum = if q > 0.0 && q.is_finite() {
                q
            } else {
                f32::INFINITY
            };
            Renew::Forget
        } else {
            // Without axes this frame or the last the turn is unknown: the count moves by
            // REBASE, which expires every mark on it (and nothing is marked on it this frame,
            // its step being infinite).
            let turns = if turned == f32::INFINITY {
                REBASE as f32
            } else {
                turns
            };
            let steps = [libm::ceilf(step(scale) / self.quantum), turns];
            let mut by = [0; 2];
            for k in 0..2 {
                self.now[k] += steps[k] as u32;
                if self.now[k] >= REBASE {
                    self.now[k] -= REBASE;
                    by[k] = REBASE;
                }
            }
            if by == [0; 2] {
                Renew::Keep
            } else {
                Renew::Rebase(by)
            }
        };
        let step = step(scale);
        *self = Motion {
            valid: true,
            tick: self.tick.wrapping_add(1),
            eye: view.eye,
            planes: now,
            axes: axes.unwrap_or(Axes::ZERO),
            has_axes: axes.is_some(),
            envelope,
            threshold: t,
            blends,
            ..*self
        };
        // The eye travels at most this far while a mark lasts; as turned, a point moves at
        // most as far again (at most CAP quanta of turns, times a lever within the model).
        let reach = CAP as f32 * (self.quantum + around / QUANTA_PER_TURN);
        Some(Settling {
            now: self.now,
            margins: Margins::new(view.eye, now, envelope, (t, slack), model, reach)
                .about(self.axis),
            renew,
            // After a jump (or in the first frame) the step says nothing of the next one: each
            // margin then settles its vertex for what it is worth, as under a still camera.
            step: if continues && step > self.quantum {
                step
            } else {
                self.quantum
            },
            quantum: self.quantum,
            scale,
            turn: turned.max(QUANTA_PER_TURN.recip()),
            centre: (pivot, lever),
            axis: self.axis,
            eye: norm(sub(pivot, view.eye)),
            tick: u32::from(self.tick),
            sparse: self.sparse,
        })
    }

    /// The turning count's step from the last frame's axes to `b` (see [`rigid::step`]), every
    /// node centre within `radius` of the model's, the lever floor `floor`; infinite when the
    /// axis the marks were made about is dropped. A camera that turns about one axis for
    /// [`HELD`] steps gets it as the marks' axis (marks made without one hold under any
    /// axis's steps, which are never shorter); one that turns about another drops it (with
    /// the count's marks on it, which its strays would soon expire anyway) until a new one
    /// holds, for twice as many steps after each drop (at most eight times as many): a camera
    /// that keeps changing its axis soon counts about the centre alone, as without axes.
    fn turning(&mut self, b: &Axes, radius: f32, floor: f32) -> f32 {
        let step = rigid::step(&self.axes, b, radius, floor, self.axis);
        let Some(spin) = rigid::spin(&self.axes, b) else {
            return step;
        };
        if self.axis != [0.0; 3] {
            // Strays that more than double the step: the camera turns about another axis.
            if step > 2.0 * rigid::step(&self.axes, b, radius, floor, [0.0; 3]) {
                self.axis = [0.0; 3];
                self.held = self.held.dropped();
                self.offset = [0.0; 3];
                return f32::INFINITY;
            }
            return step;
        }
        let same = self.candidate != [0.0; 3] && norm(cross(spin, self.candidate)) < SAME_AXIS;
        if same {
            self.held = self.held.step();
        } else {
            (self.candidate, self.held) = (spin, self.held.restart());
        }
        if self.held.enough() {
            self.axis = self.candidate;
            // Turning about a point within an eighth of the model's radius of its centre: else
            // about the centre (a camera circling far off it is better counted there).
            self.offset = rigid::pivot(&self.axes, b, self.axis)
                .filter(|d| norm(*d) <= radius * 0.125)
                .unwrap_or([0.0; 3]);
        }
        step
    }

    /// After a frame that measured the margins of `measured` vertices, settled `settled` of them
    /// and skipped `skipped`: when it settled under one in eight or skipped fewer than it
    /// measured (a camera that moves far each frame: measuring costs more than it saves), the
    /// next frame measures every vertex only in its sparse turn. Under [`SPARSE_SAMPLE`]
    /// measured says nothing either way (a cut's first frame measures only its base mesh, whose
    /// vertices all split): the next frame measures every vertex, or the cut would spend its
    /// first frames asking every vertex while measuring a sixteenth of them a frame.
    pub fn tally(&mut self, measured: u32, settled: u32, skipped: u32) {
        self.sparse = measured >= SPARSE_SAMPLE
            && (settled.saturating_mul(8) < measured || skipped < measured);
    }

    /// Forgets the marks, the motion seen and the axis (a new hierarchy): the scale is checked
    /// again [`SwayScale::FIRST`] frames on.
    pub fn clear(&mut self) {
        self.valid = false;
        self.seen = SwayScale::ZERO;
        self.checked = false;
        // Another model: the pivot's offset was from the last one's centre.
        (self.axis, self.candidate, self.held, self.offset) =
            ([0.0; 3], [0.0; 3], Held::default(), [0.0; 3]);
    }

    /// Turns skipping on or off (it starts on).
    pub fn set_on(&mut self, on: bool) {
        self.off = !on;
        self.valid = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::margin::Either;

    const MODEL: ([f32; 3], f32) = ([0.0; 3], 4096.0);
    const ENVELOPE: Envelope = Envelope {
        upper: 1.0,
        frustum: true,
        ..Envelope::ZERO
    };

    fn view(x: f32) -> View {
        View::look_at(
            [x, 0.0, 10_000.0],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            1.0,
            1.0,
            480.0,
        )
    }

    fn begin(m: &mut Motion, x: f32, t: f32) -> Settling {
        m.begin(&view(x), Some(ENVELOPE), (t, 1.0), false, MODEL)
            .expect("an envelope settles")
    }

    #[test]
    fn the_count_follows_the_eye_and_the_planes() {
        let mut m = Motion::ZERO;
        // The first frame forgets whatever was there; a quantum is a unit here.
        let first = begin(&mut m, 0.0, 1.0);
        assert_eq!((first.renew, first.now), (Renew::Forget, [0, 0]));
        // A still camera does not count.
        assert_eq!(begin(&mut m, 0.0, 1.0).now, [0, 0]);
        // The eye moves 2.5: at least three quanta (the planes sway at least as much), and the
        // camera turns a little.
        let moved = begin(&mut m, 2.5, 1.0);
        assert_eq!(moved.renew, Renew::Keep);
        assert!(moved.now[0] >= 3 && moved.now[1] >= 1, "{:?}", moved.now);
        // Another threshold, a jump, or a frame without settling forget.
        assert_eq!(begin(&mut m, 2.5, 2.0).renew, Renew::Forget);
        assert_eq!(begin(&mut m, 1e9, 2.0).renew, Renew::Forget);
        assert!(m
            .begin(&view(0.0), None, (2.0, 1.0), false, MODEL)
            .is_none());
        assert_eq!(begin(&mut m, 1e9, 2.0).renew, Renew::Forget);
        m.set_on(false);
        assert!(m
            .begin(&view(0.0), Some(ENVELOPE), (2.0, 1.0), false, MODEL)
            .is_none());
    }

    #[test]
    fn the_count_rebases_before_it_outgrows_the_tags() {
        let mut m = Motion::ZERO;
        begin(&mut m, 0.0, 1.0);
        let mut x = 0.0;
        let mut last = [0, 0];
        let mut rebased = [false; 2];
        for _ in 0..400 {
            x += 1000.0;
            let s = begin(&mut m, x, 1.0);
            assert!(s.now.iter().all(|&n| n < REBASE));
            let by = match s.renew {
                Renew::Rebase(by) => by,
                Renew::Keep => [0, 0],
                Renew::Forget => panic!("forgot"),
            };
            for k in 0..2 {
                if by[k] == REBASE {
                    assert!(s.now[k] < last[k]);
                    rebased[k] = true;
                } else {
                    assert_eq!(by[k], 0);
                    assert!(s.now[k] > last[k]);
                }
            }
            if rebased == [true; 2] {
                return;
            }
            last = s.now;
        }
        panic!("never rebased both counts");
    }

    #[test]
    fn an_expiry_lives_until_its_own_count_passes_it() {
        for other in [0, 99, 100, 101, REBASE - 1] {
            assert!(lives(100, [100, other]));
            assert!(!lives(100, [101, other]));
            assert!(lives(TURNING | 100, [other, 100]));
            assert!(!lives(TURNING | 100, [other, 101]));
        }
        // The largest expiries on either count, against the largest counts; none against the
        // counts of a frame that trusts no mark.
        let last = 2 * REBASE - 2;
        assert!(lives(last, [REBASE - 1, REBASE - 1]));
        assert!(lives(TURNING | last, [REBASE - 1, REBASE - 1]));
        assert!(!lives(last, [u32::MAX; 2]) && !lives(TURNING | last, [u32::MAX; 2]));
    }

    #[test]
    fn margins_under_a_step_make_a_vertex_restless() {
        let mut m = Motion::ZERO;
        begin(&mut m, 0.0, 1.0);
        let s = begin(&mut m, 10.0, 1.0);
        assert!(s.step >= 10.0);
        let none = f32::NEG_INFINITY;
        assert_eq!(s.mark((0.9 * s.step, none)), Mark::Restless);
        assert_eq!(s.mark((0.9 * s.step, 0.9 * s.turn)), Mark::Restless);
        assert_eq!(s.mark((f32::NAN, f32::NAN)), Mark::Restless);
        assert_eq!(s.mark((none, none)), Mark::Restless);
        assert_eq!(s.mark((100.0, none)), Mark::Settled(s.now[0] + 100));
        // On the count on which it lasts more frames.
        assert_eq!(s.mark((100.0, 0.5 * s.turn)), Mark::Settled(s.now[0] + 100));
        let turns = (100.0 / s.step) * 2.0 * s.turn;
        let quanta = (turns * QUANTA_PER_TURN) as u32;
        assert_eq!(
            s.mark((100.0, turns)),
            Mark::Settled(TURNING | (s.now[1] + quanta))
        );
        // The longest margin kept still fits a 16-bit tag besides its NIL, on either count.
        for margins in [(f32::INFINITY, none), (none, f32::INFINITY)] {
            let Mark::Settled(far) = s.mark(margins) else {
                panic!("an infinite margin settles");
            };
            assert!(far < u32::from(u16::MAX));
        }
        // A restless vertex measures one frame in four, staggered by slot.
        let turns = (0..8).filter(|&slot| s.measures(RESTLESS, slot)).count();
        assert_eq!(turns, 2);
        assert!((0..8).all(|slot| s.measures(0, slot)));
    }

    #[test]
    fn a_frame_whose_measures_do_not_pay_makes_the_next_measure_sparsely() {
        let mut m = Motion::ZERO;
        begin(&mut m, 0.0, 1.0);
        let measuring = |m: &mut Motion| {
            let s = begin(m, 1.0, 1.0);
            (0..64).filter(|&slot| s.measures(0, slot)).count()
        };
        assert_eq!(measuring(&mut m), 64);
        // Settled under an eighth of what it measured.
        m.tally(100, 10, 1_000);
        assert_eq!(measuring(&mut m), 4);
        // Skipped fewer than it measured.
        m.tally(100, 50, 90);
        assert_eq!(measuring(&mut m), 4);
        m.tally(100, 50, 1_000);
        assert_eq!(measuring(&mut m), 64);
    }

    /// A camera circling the model at twice its radius, looking at its centre: the eye
    /// travels twice as far as the planes sway over the model.
    fn circling(frame: u32) -> View {
        let a = frame as f32 * 0.01;
        let eye = [
            2.0 * 4096.0 * libm::sinf(a),
            0.0,
            2.0 * 4096.0 * libm::cosf(a),
        ];
        View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0)
    }

    /// A vertex marked in `marked` whose answer holds while the planes sway less than `room`
    /// (`room` counted at that frame's scale): flies on from frame `f` until the count passes
    /// the mark, asserting that the planes have not swayed past `room` meanwhile and that no
    /// frame forgets; the frames it stayed settled.
    fn settled_frames(
        frame: &mut impl FnMut(u32) -> Settling,
        marked: &Settling,
        mut f: u32,
        room: f32,
    ) -> u32 {
        let at = planes(&circling(f));
        let Mark::Settled(until) = marked.mark((
            Either {
                eye: 0.0,
                sway: room,
            }
            .within(marked.scale),
            f32::NEG_INFINITY,
        )) else {
            panic!("a margin of many steps settles");
        };
        let mut settled = 0;
        loop {
            f += 1;
            let s = frame(f);
            assert_ne!(s.renew, Renew::Forget, "frame {f}");
            if s.now[0] > until {
                return settled;
            }
            assert!(sway(&at, &planes(&circling(f)), MODEL) <= room, "frame {f}");
            settled += 1;
        }
    }

    #[test]
    fn the_sway_scale_follows_the_camera_and_marks_still_expire_in_time() {
        let mut m = Motion::ZERO;
        let mut frame = |f: u32| {
            m.begin(&circling(f), Some(ENVELOPE), (1.0, 1.0), false, MODEL)
                .expect("an envelope settles")
        };
        // Until the first check the scale is 1; at it the scale becomes the measured ratio,
        // about 2, and the marks made under 1 are kept (they only expire sooner).
        assert_eq!(frame(0).renew, Renew::Forget);
        let room = 2000.0;
        let last = u32::from(SwayScale::FIRST) - 1;
        for f in 1..last {
            let s = frame(f);
            assert_ne!(s.renew, Renew::Forget);
            assert_eq!(s.scale, 1.0);
        }
        // Marked under a scale of 1 the frame before the check: expires in time across it.
        let marked = frame(last);
        let early = settled_frames(&mut frame, &marked, last, room);
        let f = last + early + 1;
        let marked = frame(f);
        assert!((1.8..2.2).contains(&marked.scale), "{}", marked.scale);
        // Marked under the measured scale, a vertex stays settled no longer than the planes take
        // to sway `room`, but about twice as long as under a scale of 1.
        let settled = settled_frames(&mut frame, &marked, f, room);
        let per_frame = sway(&planes(&circling(0)), &planes(&circling(1)), MODEL);
        assert!(
            settled as f32 > 1.8 * room / (2.0 * per_frame),
            "{settled} frames"
        );
        assert!(
            settled as f32 > 1.8 * early as f32,
            "{settled} against {early}"
        );
    }

    #[test]
    fn a_smaller_sway_scale_forgets_the_marks() {
        // A camera turning where it stands: its planes sway, its eye does not move; at the first
        // check the scale falls to its floor, and the marks made under 1 would outlive their
        // margins.
        let mut m = Motion::ZERO;
        let turning = |f: u32| {
            let a = f as f32 * 0.01;
            let at = [libm::sinf(a), 0.0, libm::cosf(a)];
            View::look_at(
                [0.0, 0.0, 3.0 * 4096.0],
                at,
                [0.0, 1.0, 0.0],
                1.0,
                1.0,
                480.0,
            )
        };
        for f in 0..=u32::from(SwayScale::FIRST) {
            let s = m
                .begin(&turning(f), Some(ENVELOPE), (1.0, 1.0), false, MODEL)
                .expect("an envelope settles");
            let checked = f == u32::from(SwayScale::FIRST);
            assert_eq!(s.renew == Renew::Forget, f == 0 || checked, "frame {f}");
            let expected = if checked { 1.0 / SwayScale::LIMIT } else { 1.0 };
            assert_eq!(s.scale, expected, "frame {f}");
        }
    }

    #[test]
    fn a_camera_circling_one_axis_gets_it_and_drops_it_when_it_turns_about_another() {
        let mut m = Motion::ZERO;
        let above = [0.0, 3000.0, 0.0];
        let at = |m: &mut Motion, v: &View| {
            m.begin(v, Some(ENVELOPE), (1.0, 1.0), false, MODEL)
                .expect("an envelope settles")
        };
        // Until the axis has held, a point above the centre turns about the centre.
        let mut f = 0;
        let mut s = at(&mut m, &circling(f));
        while m.axis == [0.0; 3] {
            assert_eq!(s.levers(above).0, 3000.0, "frame {f}");
            assert!(f <= u32::from(HELD) + 1, "no axis after {f} frames");
            f += 1;
            s = at(&mut m, &circling(f));
        }
        assert!(libm::fabsf(m.axis[1]) > 0.9999, "{:?}", m.axis);
        // Then it is on the axis (the margins of its turning mark measured from there), and
        // the count goes on as before but for its strays (rounding, counted at the model's
        // radius over the lever floor: about 1% of this step).
        let next = at(&mut m, &circling(f + 1));
        assert!(next.levers(above).0 < 1.0, "{}", next.levers(above).0);
        assert!(
            next.turn < 0.0102 && next.renew == Renew::Keep,
            "{}",
            next.turn
        );
        // A step over the top (about the side axis) drops the axis and the marks made about
        // it: the turning count cannot count it (an infinite step expires them all).
        let over = View::look_at(
            [
                0.0,
                2.0 * 4096.0 * libm::sinf(0.02),
                2.0 * 4096.0 * libm::cosf(0.02),
            ],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            1.0,
            1.0,
            480.0,
        );
        let dropped = at(&mut m, &over);
        assert_eq!(dropped.turn, f32::INFINITY);
        assert_eq!(m.axis, [0.0; 3]);
        assert_eq!(dropped.levers(above).0, 3000.0);
        // Circling again, the axis comes back after holding twice as many steps as the first
        // time (the step back onto the circle, about neither axis, holds nothing).
        let steps = |m: &mut Motion, from: u32| {
            let mut f = from;
            while m.axis == [0.0; 3] {
                f += 1;
                at(m, &circling(f));
                assert!(f < from + 100, "no axis");
            }
            f - from
        };
        let again = steps(&mut m, 0);
        assert_eq!(f, u32::from(HELD) + 1);
        assert_eq!(again, 2 * u32::from(HELD) + 2);
        // Another hierarchy (another model) forgets the axis and where it passed.
        m.clear();
        assert_eq!(
            (m.axis, m.offset, m.held),
            ([0.0; 3], [0.0; 3], Held::default())
        );
    }

    #[test]
    fn each_drop_doubles_the_steps_an_axis_must_hold_up_to_eight_times() {
        let mut held = Held::default();
        for drops in 0..6u32 {
            let needed = u32::from(HELD) << drops.min(3);
            let mut steps = 0;
            while !held.enough() {
                held = held.step();
                steps += 1;
            }
            assert_eq!(steps, needed, "after {drops} drops");
            held = held.restart();
            assert!(!held.enough());
            held = held.dropped();
        }
        // The steps saturate instead of spilling into the drops.
        let mut held = Held::default();
        for _ in 0..200 {
            held = held.step();
        }
        assert_eq!(held, Held(Held::STEPS));
    }
}
