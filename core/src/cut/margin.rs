//! How far the camera may move before a policy's answer about a vertex could change.
//!
//! A policy that describes how its demand depends on the view ([`Envelope`]) lets a cut prove,
//! from one frame's view, that an answer stays the same while the eye moves less than some
//! distance and the frustum's planes sway less than some distance over the model's bounding
//! sphere (see [`sway`]). This module computes those distances, the *margins*, for the three
//! answers the cuts reuse: a vertex wants no split ([`Margins::unwanted`]), a sphere is in or
//! out of the frustum ([`Margins::visibility`]), and a parent is still wanted
//! ([`Margins::wanted`]). The wavelet cut compares them with the reach of an anchor frame
//! (`crate::wavelet`'s `steady`); the vertex cut turns them into a per-vertex expiry
//! (`super::expiry`).
//!
//! Every margin leaves a relative slack far above float rounding, and a margin that cannot be
//! proven (a NaN anywhere) is never positive.

use super::rigid::across;
use crate::policy::{dot, sub, Bounds, Envelope, View};

/// Relative slack on every margin, far above float rounding.
pub(crate) const SLACK: f32 = 1e-4;

/// A frustum's planes as `(n, d)` (left, right, bottom, top, near).
pub(crate) type Planes = [[f32; 4]; 5];

/// The planes of `view`.
pub(crate) fn planes(view: &View) -> Planes {
    core::array::from_fn(|i| view.plane(i).unwrap_or([0.0; 4]))
}

/// How far any point within `radius` of `center` moves relative to any plane between `a` and
/// `b`: `max_i |n_a - n_b| radius + |(n_a - n_b) . center + d_a - d_b|`. A distance: the sway
/// from `a` to `c` is at most the sway from `a` to `b` plus that from `b` to `c`.
pub(crate) fn sway(a: &Planes, b: &Planes, (center, radius): ([f32; 3], f32)) -> f32 {
    let mut most = 0.0f32;
    for (p, q) in a.iter().zip(b) {
        let dn = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let shift =
            crate::root::sqrtf(dot(dn, dn)) * radius + libm::fabsf(dot(dn, center) + p[3] - q[3]);
        most = most.max(shift);
    }
    most
}

/// The lane of `v` that `first(a, b)` prefers to every other, halving the lanes at each step
/// (a tree, which vectorizes where a running minimum would not).
#[inline(always)]
fn fold(v: [f32; 8], first: impl Fn(f32, f32) -> bool) -> f32 {
    let pick = |a: f32, b: f32| if first(a, b) { a } else { b };
    let q: [f32; 4] = core::array::from_fn(|i| pick(v[i], v[i + 4]));
    let p = [pick(q[0], q[2]), pick(q[1], q[3])];
    pick(p[0], p[1])
}

/// The smaller of `a` and `b`, NaN when either is (an unproven term fails a conjunction).
#[inline(always)]
pub(crate) fn lesser(a: f32, b: f32) -> f32 {
    if a < b || a.is_nan() {
        a
    } else {
        b
    }
}

/// Margins of an answer that holds while *either* the eye moves at most `eye` *or* the planes
/// sway at most `sway` (a vertex out of the frustum wants nothing however near the eye comes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Either {
    pub eye: f32,
    pub sway: f32,
}

/// Margins of an answer that holds while the eye moves at most `eye` *and* the planes sway at
/// most `sway`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Both {
    pub eye: f32,
    pub sway: f32,
}

impl Either {
    /// The one distance the vertex may move relative to the eye and the planes standing
    /// still, as seen from the camera (`super::rigid`): either margin is such a distance.
    #[inline(always)]
    pub fn displaced(self) -> f32 {
        self.eye.max(self.sway)
    }

    /// Whether the answer holds for an eye within `reach` and planes within `sway`.
    #[inline(always)]
    pub fn holds(self, reach: f32, sway: f32) -> bool {
        self.eye >= reach || self.sway >= sway
    }

    /// The one distance the eye may move, the planes' sway counted at `scale` times its length
    /// (see `super::expiry`'s sway scale); NaN-free: an unproven term is ignored, since the
    /// other alone suffices.
    #[inline(always)]
    pub fn within(self, scale: f32) -> f32 {
        self.eye.max(self.sway * scale)
    }
}

impl Both {
    /// Whether the answer holds for an eye within `reach` and planes within `sway`.
    #[inline(always)]
    pub fn holds(self, reach: f32, sway: f32) -> bool {
        self.eye >= reach && self.sway >= sway
    }

    /// The one distance the eye may move, the planes' sway counted at `scale` times its length
    /// (NaN when either term is unproven).
    #[inline(always)]
    pub fn within(self, scale: f32) -> f32 {
        lesser(self.eye, self.sway * scale)
    }
}

/// One frame's terms for the margins: its eye and planes, the policy's envelope, and the
/// constants every vertex shares (square roots once per frame, not once per vertex).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Margins {
    eye: [f32; 3],
    /// The planes transposed, `lanes[k][i]` component `k` of plane `i`, as [`View`] keeps them
    /// (three unused lanes that never cull: `n = 0`, `d = MAX`), so the tests run as vector
    /// operations.
    lanes: [[f32; 8]; 4],
    envelope: Envelope,
    /// A vertex whose spheroid radius is at most `s` wants no split while at least `s scale`
    /// from the eye.
    scale: f32,
    /// Float rounding on any distance from an eye within the largest reach asked of a node
    /// centre.
    slop: f32,
    /// `slop` plus rounding on each plane's distances, by lane.
    plane_slop: [f32; 8],
    /// One over each plane's normal's part across the axis the camera turns about, by lane (1
    /// for every lane without an axis; see `super::rigid`).
    per_across: [f32; 8],
}

impl Margins {
    /// The terms of a frame seen from `eye` with `planes`, for a policy with `envelope`, the
    /// threshold `t` and the cut's bound slack `slack`, every node centre within the sphere
    /// `model`, for margins up to `reach` (the slop covers distances from anywhere within it).
    pub fn new(
        eye: [f32; 3],
        planes: Planes,
        envelope: Envelope,
        (t, slack): (f32, f32),
        model: ([f32; 3], f32),
        reach: f32,
    ) -> Margins {
        let to = sub(model.0, eye);
        let farthest = crate::root::sqrtf(dot(to, to)) + model.1;
        let slop = SLACK * (farthest + reach);
        let mut lanes = [[0.0f32; 8]; 4];
        lanes[3] = [f32::MAX; 8];
        let mut plane_slop = [slop; 8];
        for (i, p) in planes.iter().enumerate() {
            for (k, lane) in lanes.iter_mut().enumerate() {
                lane[i] = p[k];
            }
            plane_slop[i] = slop + SLACK * libm::fabsf(p[3]);
        }
        Margins {
            eye,
            lanes,
            envelope,
            scale: crate::root::sqrtf(envelope.upper * slack * (1.0 + SLACK) / t),
            slop,
            plane_slop,
            per_across: [1.0; 8],
        }
    }

    /// These terms for a camera turning about the unit `axis` (a world direction; the zero
    /// vector for none), for [`Margins::turned_sway`].
    pub fn about(mut self, axis: [f32; 3]) -> Margins {
        if axis != [0.0; 3] {
            let [x, y, z, _] = &self.lanes;
            for i in 0..5 {
                self.per_across[i] = 1.0 / across([x[i], y[i], z[i]], axis);
            }
        }
        self
    }

    /// How far the eye may move while a vertex of spheroid radius `s` and bounding radius
    /// `radius`, at `d` from the eye, keeps its bound `s^2 upper / d^2` at most `t / slack` and
    /// its sphere beyond the envelope's near zone: `d - max(s sqrt(upper slack / t), near +
    /// radius)`, less float slop.
    #[inline(always)]
    pub fn quiet(&self, s: f32, radius: f32, d: f32) -> f32 {
        let near = self.envelope.near;
        let zone = if near > 0.0 {
            (near + radius) * (1.0 + SLACK)
        } else {
            0.0
        };
        d - (s * self.scale).max(zone) - self.slop
    }

    /// Whether a sphere at `center` of `radius` is in the frustum (`Some(true)`) or out of it
    /// (`Some(false)`) with room to spare, and how far the planes may sway before that could
    /// change; `(None, NaN)` when neither is proven.
    #[inline(always)]
    pub fn visibility(&self, center: [f32; 3], radius: f32) -> (Option<bool>, f32) {
        self.weighed_visibility(center, radius, [1.0; 8])
    }

    /// How far the camera may turn, in turns (see `super::rigid`), while a sphere at `center`
    /// of `radius`, `reach` from the axis the camera turns about (from the model's centre
    /// without one), stays in or out of the frustum: each plane's margin over
    /// `max(|n⊥| reach, floor)`; NaN when neither is proven.
    #[inline(always)]
    pub fn turned_sway(&self, center: [f32; 3], radius: f32, reach: f32, floor: f32) -> f32 {
        // 1 / max(a reach, floor), without a division per lane (a plane along the axis, or a
        // centre on it, gets the floor's: an infinite product).
        let (per_reach, per_floor) = (1.0 / reach, 1.0 / floor);
        let per = self.per_across.map(|a| (a * per_reach).min(per_floor));
        self.weighed_visibility(center, radius, per).1
    }

    /// [`Margins::visibility`] with each plane's margin multiplied by its lane of `per`
    /// (positive).
    #[inline(always)]
    fn weighed_visibility(
        &self,
        center: [f32; 3],
        radius: f32,
        per: [f32; 8],
    ) -> (Option<bool>, f32) {
        let [x, y, z, d] = &self.lanes;
        let mut nan = false;
        let mut inside = [0.0f32; 8];
        let mut outside = [0.0f32; 8];
        for i in 0..8 {
            let dist = x[i] * center[0] + y[i] * center[1] + z[i] * center[2] + d[i] + radius;
            nan |= dist.is_nan();
            inside[i] = (dist - self.plane_slop[i]) * per[i];
            outside[i] = (-dist - self.plane_slop[i]) * per[i];
        }
        // Halved lane by lane with plain comparisons (a NaN is caught by `nan`), so the lanes
        // reduce as vectors.
        let (inside, outside) = (fold(inside, |a, b| a < b), fold(outside, |a, b| a > b));
        if nan {
            (None, f32::NAN)
        } else if inside >= 0.0 {
            (Some(true), inside / (1.0 + SLACK))
        } else if outside > 0.0 {
            (Some(false), outside / (1.0 + SLACK))
        } else {
            (None, f32::NAN)
        }
    }

    /// Whether the envelope culls by the frustum (so that [`Margins::unwanted`] wants the
    /// sphere's [`Margins::visibility`]).
    #[inline(always)]
    pub fn culls(&self) -> bool {
        self.envelope.frustum
    }

    /// The margins of "wants no split" for a vertex that wants none (spheroid radius `s`,
    /// bounding radius `radius` at `d2` from the eye, `seen` its sphere's
    /// [`Margins::visibility`] when the envelope [`Margins::culls`]): it stays quiet
    /// ([`Margins::quiet`]), or the envelope culls by the frustum and the sphere stays out of it
    /// (a culled vertex's error is 0).
    #[inline(always)]
    pub fn unwanted(&self, s: f32, radius: f32, d2: f32, seen: (Option<bool>, f32)) -> Either {
        let out = match (self.envelope.frustum, seen) {
            (true, (Some(false), m)) => m,
            _ => f32::NEG_INFINITY,
        };
        Either {
            eye: self.quiet(s, radius, crate::root::sqrtf(d2)),
            sway: out,
        }
    }

    /// How far the eye may move while the normal cone of bounds `b` stays turned away from it
    /// (Hoppe's `oriented_away` with the apex moved towards the eye by the radius, as the
    /// envelope's back-face test: `rn - radius > d cone_sin`, `rn` the eye-to-centre vector
    /// along the axis, `d` its length), so that the vertex stays culled and wants nothing;
    /// `-inf` when the envelope does not cull back faces, negative or NaN when unproven.
    #[inline(always)]
    pub fn averted(&self, b: &Bounds) -> f32 {
        if !self.envelope.back_face {
            return f32::NEG_INFINITY;
        }
        let r = sub(b.center, self.eye);
        let d = crate::root::sqrtf(dot(r, r));
        // The test squares the sine: its sign does not matter.
        let cs = libm::fabsf(b.cone_sin);
        // An eye moved by `e` shortens `rn` and lengthens `d` by at most `|e|` each.
        (dot(r, b.axis) - b.radius - d * cs) / (1.0 + cs) / (1.0 + SLACK) - self.slop
    }

    /// The margins of "still wanted" for a parent with bounds `b`, threshold `t` and the cut's
    /// bound slack `slack`: seen (with margin from every culling plane), facing the eye, and its
    /// error over `t * slack` wherever the eye gets: the spheroid's lower bound where the eye
    /// is farthest from the centre and nearest the axis while the sphere may be beyond the
    /// near zone, the near error while it may be inside. The spheroid's across-axis term is
    /// solved exactly; its along-axis term is tried at `step` times 1, 4, 16, ... (`levels`
    /// of them) and gives the largest that holds.
    pub fn wanted(&self, b: &Bounds, (t, slack): (f32, f32), (step, levels): (f32, u32)) -> Both {
        self.wanted_turned(b, (t, slack), (step, levels), (1.0, 1.0, 1.0))
            .0
    }

    /// [`Margins::wanted`], and how far the camera may turn while the parent stays wanted, in
    /// turns (see `super::rigid`), for a centre `reach` from the axis the camera turns about
    /// (from the model's centre without one), the lever floor `floor` (by which the model's
    /// centre shifts at most per turn) and an eye `eye` from the model's centre: its sphere
    /// seen ([`Margins::turned_sway`]) and its error over `t * slack` while the centre moves at
    /// most the turns times `lever = max(reach, floor)`, and its normal cone not turned away
    /// while the axis turns as far too. With `u` the centre's offset from the model's and `w`
    /// the model's from the eye, `rn = (u + w) . axis` and `u . axis` keeps under a rotation,
    /// so `s = rn - radius` changes by at most `|w| turn + shift` and `d` by at most `lever
    /// turn + shift` (`super::rigid` counts what else the steps stray by). The spheroid's
    /// along-axis term, which needs the axis to stay where it is, is left out.
    #[inline(always)]
    pub fn wanted_turned(
        &self,
        b: &Bounds,
        (t, slack): (f32, f32),
        (step, levels): (f32, u32),
        (reach, eye, floor): (f32, f32, f32),
    ) -> (Both, f32) {
        let e = &self.envelope;
        let lever = reach.max(floor);
        let sway = match (e.frustum, self.visibility(b.center, b.radius)) {
            (false, _) => f32::INFINITY,
            (true, (Some(true), m)) => m,
            (true, _) => f32::NAN,
        };
        let r = sub(b.center, self.eye);
        let d = crate::root::sqrtf(dot(r, r));
        let rn = dot(r, b.axis);
        // Not facing away (`s <= 0` or `s <= (d - shift) cone_sin`, `s = rn - radius + shift`,
        // the shift being the reach plus slop): either holds for shifts up to its bound.
        let (facing, facing_turned) = if e.back_face {
            let cs = b.cone_sin.max(0.0);
            let (g1, g2) = (b.radius - rn, d * cs - rn + b.radius);
            (
                g1.max(g2 / (1.0 + cs)) - self.slop,
                ((g1 - self.slop) / (eye + floor))
                    .max((g2 - self.slop) / (eye + cs * lever + (1.0 + cs) * floor)),
            )
        } else {
            (f32::INFINITY, f32::INFINITY)
        };
        let k = t * slack * (1.0 + SLACK);
        let across = self.across(b, d, k);
        let spheroid = self.spheroid(b, (d, rn), k, (step, levels), across);
        // Where the sphere can get relative to the near zone (`d - radius < near`): provably
        // inside for shifts below `edge / (1 + SLACK) - d`, provably outside up to
        // `d - edge (1 + SLACK)`.
        let edge = e.near + b.radius;
        let error = |spheroid: f32| {
            if e.near > 0.0 {
                if e.near_error > k {
                    (edge / (1.0 + SLACK) - d - self.slop).max(spheroid)
                } else {
                    lesser(spheroid, d - edge * (1.0 + SLACK) - self.slop)
                }
            } else {
                spheroid
            }
        };
        // The sway's margin plane by plane is at least the whole sphere's over the lever: only
        // worked out when that would decide.
        let others = lesser(facing_turned, error(across) / lever);
        let sway_turned = sway / lever;
        let turned = if sway_turned < others {
            lesser(others, self.turned_sway(b.center, b.radius, reach, floor))
        } else {
            lesser(others, sway_turned)
        };
        (
            Both {
                eye: lesser(facing, error(spheroid)),
                sway,
            },
            turned,
        )
    }

    /// How far the eye may move while the spheroid's across-axis lower bound, `b2 lower /
    /// far^2` with `far` the eye's greatest distance from the centre (less what rounding can
    /// take from the policy's own sum), stays over `k`: `-inf` when it never is.
    #[inline(always)]
    fn across(&self, b: &Bounds, d: f32, k: f32) -> f32 {
        let lower = self.envelope.lower;
        // (Also when `lower` is NaN.)
        if lower.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return f32::NEG_INFINITY;
        }
        let most = b.a2.max(b.b2);
        // `(b2 - SLACK most) lower far^2 > k far^4` while `far^2 < (b2 - SLACK most) lower / k`.
        let across = (b.b2 - SLACK * most) * lower / k;
        if across > 0.0 {
            crate::root::sqrtf(across) / (1.0 + SLACK) - d - self.slop
        } else {
            f32::NEG_INFINITY
        }
    }

    /// How far the eye may move while the spheroid's lower bound, `max(b2 far^2, a2 p^2)
    /// lower / far^4` with `far` the eye's greatest distance from the centre and `p` its least
    /// from the axis (less what rounding can take from the policy's own sum), stays over `k`,
    /// given the across-axis term's margin `across` ([`Margins::across`]); `-inf` when it never
    /// is.
    fn spheroid(
        &self,
        b: &Bounds,
        (d, rn): (f32, f32),
        k: f32,
        (step, levels): (f32, u32),
        across: f32,
    ) -> f32 {
        let lower = self.envelope.lower;
        let mut margin = across;
        // Along the axis: `(a2 p^2 - SLACK most far^2) lower > k far^4`, which only gets
        // harder as the shift grows, and cannot hold beyond the across-axis term's reach when
        // `a2 <= b2` (`p <= far`): then no rung can add more than rounding (a sphere, the
        // default bound, is such a spheroid). Without a positive `lower` nothing is proven
        // (and `across` is `-inf`).
        let positive = lower.partial_cmp(&0.0) == Some(core::cmp::Ordering::Greater);
        if !positive || b.a2 <= b.b2 {
            return margin;
        }
        let most = b.a2.max(b.b2);
        let axial = crate::root::sqrtf((d * d - rn * rn).max(0.0));
        let holds = |reach: f32| {
            let shift = reach + self.slop;
            let far = d + shift;
            let p = (axial - shift).max(0.0);
            (b.a2 * p * p - SLACK * most * far * far) * lower > k * far * far * far * far
        };
        let mut reach = step;
        for _ in 0..levels {
            if reach > margin {
                if !holds(reach) {
                    break;
                }
                margin = reach;
            }
            reach *= 4.0;
        }
        margin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> View {
        View::look_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0)
    }

    fn margins(envelope: Envelope) -> Margins {
        let v = view();
        Margins::new(
            v.eye,
            planes(&v),
            envelope,
            (1.0, 1.0),
            ([0.0; 3], 1.0),
            1.0,
        )
    }

    #[test]
    fn a_quiet_vertex_stays_quiet_until_the_eye_reaches_its_zone() {
        let m = margins(Envelope {
            upper: 1.0,
            near: 1.0,
            near_error: 2.0,
            ..Envelope::ZERO
        });
        // 5 from the eye, radius 0.5: the zone's edge is 1.5 away, the bound's 0.2.
        let q = m.quiet(0.2, 0.5, 5.0);
        assert!(q < 3.5 && q > 3.49, "{q}");
        // Already inside: no margin.
        assert!(m.quiet(0.2, 0.5, 1.0) < 0.0);
    }

    #[test]
    fn visibility_margins_are_the_distances_to_the_planes() {
        let m = margins(Envelope {
            frustum: true,
            ..Envelope::ZERO
        });
        let (inside, room) = m.visibility([0.0; 3], 0.1);
        assert_eq!(inside, Some(true));
        assert!(room > 0.5 && room < 5.0, "{room}");
        let (outside, room) = m.visibility([0.0, 0.0, 10.0], 0.1);
        assert_eq!(outside, Some(false));
        assert!(room > 4.0, "{room}");
        // A sphere moved by less than its margin keeps its state: sweep one across the left
        // and right planes and check every margin against where the state changes.
        let xs: [f32; 401] = core::array::from_fn(|i| -4.0 + 0.02 * i as f32);
        let states = xs.map(|x| m.visibility([x, 0.0, 0.0], 0.1));
        assert!(states.iter().any(|s| s.0 == Some(true)));
        assert!(states.iter().any(|s| s.0 == Some(false)));
        for (a, (state, room)) in xs.iter().zip(&states) {
            for (b, other) in xs.iter().zip(&states) {
                if (a - b).abs() < *room {
                    assert_eq!(other.0, *state, "{a} -> {b} within {room}");
                }
            }
        }
        // A NaN proves nothing.
        assert_eq!(m.visibility([f32::NAN, 0.0, 0.0], 0.1).0, None);
    }

    #[test]
    fn either_and_both_combine_as_named() {
        let e = Either {
            eye: 1.0,
            sway: 3.0,
        };
        assert!(e.holds(2.0, 2.0) && !e.holds(2.0, 4.0));
        assert_eq!(e.within(1.0), 3.0);
        // Planes that sway half as fast as the eye moves: three of sway last six of the count.
        assert_eq!(e.within(2.0), 6.0);
        assert_eq!(e.within(0.25), 1.0);
        let b = Both {
            eye: 1.0,
            sway: 3.0,
        };
        assert!(b.holds(1.0, 3.0) && !b.holds(2.0, 2.0));
        assert_eq!(b.within(1.0), 1.0);
        assert_eq!(b.within(0.25), 0.75);
        assert_eq!(b.within(2.0), 1.0);
        assert!(Both {
            eye: f32::NAN,
            sway: 1.0
        }
        .within(1.0)
        .is_nan());
        assert!(Both {
            eye: 1.0,
            sway: f32::NAN
        }
        .within(1.0)
        .is_nan());
    }

    #[test]
    fn a_turned_away_cone_stays_culled_while_the_eye_moves_less_than_its_margin() {
        use crate::policy::{BackFace, Policy};
        let m = margins(Envelope {
            back_face: true,
            ..Envelope::ZERO
        });
        // Facing away from the eye at z = 5, within a cone of half-angle asin 0.3.
        let b = Bounds {
            center: [0.0; 3],
            radius: 0.2,
            axis: [0.0, 0.0, -1.0],
            cone_sin: 0.3,
            ..Bounds::default()
        };
        let room = m.averted(&b);
        // 5 - 0.2 - 5 * 0.3 = 3.3 over 1.3.
        assert!(room > 2.5 && room < 2.54, "{room}");
        let culled = |eye: [f32; 3]| {
            let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
            !BackFace.demand(&b, &v).visible
        };
        // Every eye within the margin, in 26 directions and at 20 distances, still sees it
        // turned away; far enough round to its front it is seen.
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let dir = [dx as f32, dy as f32, dz as f32];
                    let len = crate::root::sqrtf(dot(dir, dir));
                    if len == 0.0 {
                        continue;
                    }
                    for k in 1..=20 {
                        let t = room * k as f32 / 20.0 / len;
                        let eye = [dir[0] * t, dir[1] * t, 5.0 + dir[2] * t];
                        assert!(culled(eye), "{eye:?} within {room}");
                    }
                }
            }
        }
        assert!(!culled([0.0, 0.0, -5.0]));
        // Seen now, or not culling back faces, or NaN: no margin.
        let front = Bounds {
            axis: [0.0, 0.0, 1.0],
            ..b
        };
        assert!(m.averted(&front) < 0.0);
        assert_eq!(margins(Envelope::ZERO).averted(&b), f32::NEG_INFINITY);
        let nan = Bounds {
            cone_sin: f32::NAN,
            ..b
        };
        assert!(m.averted(&nan).is_nan());
    }

    #[test]
    fn a_parent_facing_the_eye_stays_so_while_the_camera_turns_less_than_its_margin() {
        use crate::policy::{cross, BackFace, Policy};
        // The eye at z = 5 looks at the model's centre; the parent, off the centre, faces it
        // within a cone of half-angle asin 0.3, its error far over the threshold.
        let m = margins(Envelope {
            back_face: true,
            lower: 1.0,
            ..Envelope::ZERO
        });
        let b = Bounds {
            center: [0.3, 0.2, 0.0],
            radius: 0.1,
            axis: [0.6, 0.0, 0.8],
            cone_sin: 0.3,
            a2: 100.0,
            b2: 100.0,
        };
        let (w, turns) = m.wanted_turned(&b, (1.0, 1.0), (0.1, 1), (0.5, 5.0, 0.5));
        assert!(w.eye > 0.0 && turns > 0.05, "{w:?} {turns}");
        // The camera turned about the centre round six axes, by angles whose turn (`2 sin(a /
        // 2)`) is within the margin: still facing. Round to the far side: turned away.
        let seen = |axis: [f32; 3], angle: f32| {
            let (c, s) = (libm::cosf(angle), libm::sinf(angle));
            // Rodrigues' rotation of `p` about the unit `axis`.
            let turn = |p: [f32; 3]| {
                let (kxp, kp) = (cross(axis, p), dot(axis, p) * (1.0 - c));
                core::array::from_fn(|i| p[i] * c + kxp[i] * s + axis[i] * kp)
            };
            let v = View::look_at(
                turn([0.0, 0.0, 5.0]),
                [0.0; 3],
                turn([0.0, 1.0, 0.0]),
                1.0,
                1.0,
                480.0,
            );
            BackFace.demand(&b, &v).visible
        };
        let axes = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
        ];
        for axis in axes {
            for k in 1..=20 {
                let angle = 2.0 * libm::asinf(turns * k as f32 / 40.0);
                assert!(seen(axis, angle), "{axis:?} {angle}");
            }
        }
        assert!(!seen([0.0, 1.0, 0.0], core::f32::consts::PI));
    }

    #[test]
    fn a_parent_inside_the_near_zone_stays_wanted_until_it_may_leave_it() {
        let m = margins(Envelope {
            frustum: true,
            near: 10.0,
            near_error: 2.0,
            ..Envelope::ZERO
        });
        let b = Bounds {
            center: [0.0; 3],
            radius: 0.1,
            ..Bounds::default()
        };
        let w = m.wanted(&b, (1.0, 1.0), (0.1, 1));
        // The sphere's edge is 10.1 from the centre, the eye 5 from it.
        assert!(w.eye > 5.0 && w.eye < 5.1, "{w:?}");
        assert!(w.sway > 0.0, "{w:?}");
        // Out of the frustum: never proven wanted.
        let aside = Bounds {
            center: [0.0, 0.0, 10.0],
            ..b
        };
        assert!(m.wanted(&aside, (1.0, 1.0), (0.1, 1)).within(1.0).is_nan());
    }
}
