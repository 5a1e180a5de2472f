//! Refinement policies: where does this camera want detail?
//!
//! The cut asks a [`Policy`] about every active vertex each frame, so a policy is a few
//! multiply-adds over the vertex's cached [`Bounds`] and the frame's [`View`]: no square root on
//! the common path, no allocation, no state. It answers with a [`Demand`]: whether the vertex's
//! region can be seen at all (frustum and back-face tests: changes they cause are not blended),
//! and how far over tolerance its error is (`error > 1` asks for a split; larger is more urgent,
//! which orders the budget's priority queue).
//!
//! A policy may also judge triangles ([`Policy::judges_triangles`], [`Policy::triangle`]), as
//! the importance paper's does: the vertex forest then raises each vertex's demand to that of
//! the triangles around it, and a pair's to that of the triangles its collapse would make.
//!
//! Policies compose: a tuple `(A, B)` is visible when both are and demands the larger error, so
//! the LOD lecture's `qrefine` is `(Frustum, (BackFace, ScreenError::new(1.0)))`. [`QRefine`] is
//! the same three tests fused, sharing their subexpressions: the one to use when speed matters
//! (it gives the same answers, tested below).
//!
//! | policy | source |
//! |---|---|
//! | [`Frustum`] | bounding spheres against the six planes (merge-tree paper §3.4, wavelet paper §3.3.1) |
//! | [`BackFace`] | normal cones, Hoppe's `oriented_away` (wavelet paper §3.3.2) |
//! | [`ScreenError`] | the spheroid's projected radius in pixels, equations 4 and 5 of the wavelet paper, with separate silhouette and interior tolerances (§3.3.3) |
//! | [`MergeTree`] | the merge-tree paper's `shouldRefine`: near the camera and in the frustum |
//! | [`Importance`] | the importance paper's per-triangle `area / (distance tan(FOV)) max(-cos θ, sin θ)` against a threshold, in units of the model's size |
//!
//! ```
//! use vdlod_core::policy::{BackFace, Bounds, Frustum, Policy, ScreenError, View};
//! let view = View::look_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 1.0, 0.0], 1.0, 4.0 / 3.0, 480.0);
//! let qrefine = (Frustum, (BackFace, ScreenError::new(1.0)));
//! // A vertex facing the camera with a 0.05-unit error, 5 units away: about 4 px on screen.
//! let b = Bounds { center: [0.0; 3], radius: 0.1, axis: [0.0, 0.0, 1.0], cone_sin: 0.2,
//!                  a2: 0.05 * 0.05, b2: 0.05 * 0.05 };
//! let d = qrefine.demand(&b, &view);
//! assert!(d.visible && d.error > 1.0);
//! ```

/// What a policy needs to know about a vertex: its node's bounds as the file stores them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bounds {
    /// The node's position.
    pub center: [f32; 3],
    /// Radius of a sphere around `center` holding the node's region.
    pub radius: f32,
    /// Axis of the cone of normals (unit length).
    pub axis: [f32; 3],
    /// Sine of the cone's half-angle (1: no useful cone).
    pub cone_sin: f32,
    /// Square of the error spheroid's radius along the axis (`a^2`, wavelet paper eq. 4).
    pub a2: f32,
    /// Square of the error spheroid's radius across the axis (`b^2`).
    pub b2: f32,
}

/// A policy's answer for one vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Demand {
    /// Whether the vertex's region may be seen (in the frustum, not facing away).
    pub visible: bool,
    /// How far over tolerance: a split is wanted when `error > 1`; larger is more urgent.
    pub error: f32,
}

impl Demand {
    /// Visible, wanting nothing.
    pub const NONE: Demand = Demand {
        visible: true,
        error: 0.0,
    };
    /// Culled: wants nothing, and changes it causes are not blended.
    pub const CULLED: Demand = Demand {
        visible: false,
        error: 0.0,
    };

    /// This demand raised by `triangles`, the largest demand of the triangles a vertex stands
    /// for ([`Policy::triangle`]): a triangle in view speaks for a vertex whose own bounds the
    /// frustum culled.
    #[must_use]
    pub fn raised(self, triangles: f32) -> Demand {
        let own = if self.visible { self.error } else { 0.0 };
        let error = own.max(triangles);
        Demand {
            visible: self.visible || error > 0.0,
            error,
        }
    }
}

/// How a policy's demand depends on the view, for the cut to skip vertices whose answer is
/// known: with `r = b.center - eye`, `d2 = |r|^2` and `p2 = d2 - (r . b.axis)^2` (the squared
/// distance of the eye from the axis), for every [`Bounds`] `b`,
///
/// - `demand(b, view)` is culled exactly when `frustum` and `b`'s sphere misses the frustum
///   ([`View::sphere_visible`]), or `back_face` and `b`'s normal cone faces away ([`BackFace`]);
/// - otherwise, when `near` is 0 or `b`'s sphere keeps at least `near` from the eye
///   (`sqrt(d2) - b.radius >= near`), `max(b.b2 d2, b.a2 p2) lower / d2^2 <= demand(b,
///   view).error` and `demand(b, view).error <= max(b.a2, b.b2) upper / d2`;
/// - otherwise (the sphere comes within `near > 0` of the eye) `demand(b, view).error >=
///   near_error`, with no upper bound;
/// - and the error depends on the view only through its eye and these scales.
///
/// (Up to float rounding: a policy's sums may cancel, so a user of the lower bound leaves a
/// margin of a small share of `max(b.a2, b.b2) d2`.)
///
/// A cut proves "wants no split" from `upper`, `near` and a node's largest spheroid radius and
/// bounding sphere (its digest), and, while the eye moves less than a margin, "still wants no
/// split" and "the parent is still wanted" without asking again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope {
    /// Scale of the upper bound (0: never wants a split).
    pub upper: f32,
    /// Scale of the lower bound (0: proves nothing).
    pub lower: f32,
    /// Culls by the frustum.
    pub frustum: bool,
    /// Culls by the normal cone.
    pub back_face: bool,
    /// Distance from the eye within which the error is only bounded below (0: nowhere).
    pub near: f32,
    /// The least error of a seen vertex whose sphere comes within `near` of the eye.
    pub near_error: f32,
}

impl Envelope {
    /// Culls nothing and wants nothing.
    pub const ZERO: Envelope = Envelope {
        upper: 0.0,
        lower: 0.0,
        frustum: false,
        back_face: false,
        near: 0.0,
        near_error: 0.0,
    };

    /// Both policies' tests: culled when either culls, the larger error otherwise (the tuple
    /// policy's rule). Outside both near zones both bounds hold; inside either, the error is at
    /// least the smaller near error of those that have a zone.
    #[must_use]
    pub fn and(self, other: Envelope) -> Envelope {
        let near_error = match (self.near > 0.0, other.near > 0.0) {
            (true, true) => self.near_error.min(other.near_error),
            (true, false) => self.near_error,
            (false, true) => other.near_error,
            (false, false) => 0.0,
        };
        Envelope {
            upper: self.upper.max(other.upper),
            lower: self.lower.max(other.lower),
            frustum: self.frustum || other.frustum,
            back_face: self.back_face || other.back_face,
            near: self.near.max(other.near),
            near_error,
        }
    }

    /// Whether a seen sphere at squared distance `d2` from the eye with radius `radius`
    /// provably keeps `near` from it, with relative slack `slack` (`> 1`) for rounding: where
    /// the upper bound holds.
    #[inline(always)]
    #[must_use]
    pub fn beyond_near(&self, d2: f32, radius: f32, slack: f32) -> bool {
        // Without a zone (a loop invariant for the cut's walk) nothing more is computed.
        let edge = self.near + radius;
        self.near == 0.0 || d2 >= edge * edge * slack
    }
}

/// A camera for one frame, reduced to what the policies test against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub eye: [f32; 3],
    /// Unit viewing direction.
    pub forward: [f32; 3],
    /// Frustum planes (left, right, bottom, top, near; the far plane is not tested), transposed:
    /// `lanes[k][i]` is component `k` of plane `i`'s `(n, d)` with inward unit normal `n`, so a
    /// point `x` is inside plane `i` when `n . x + d >= 0`. Eight lanes, the last three planes
    /// that never cull, so the test runs as two four-wide vector operations.
    lanes: [[f32; 8]; 4],
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// `tan(fov_y)`, for the importance policy (kept away from zero).
    tan_fov: f32,
    /// Pixels covered by one unit of length at distance one, across the view:
    /// `height / (2 tan(fov_y / 2))`.
    pub pixels_per_unit: f32,
}

#[inline]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// What every view-dependent test of a vertex starts from: the squared distance from the eye
/// and the eye vector's component along the cone axis.
#[derive(Clone, Copy)]
struct Eye {
    d2: f32,
    rn: f32,
}

impl Eye {
    #[inline(always)]
    fn of(b: &Bounds, view: &View) -> Eye {
        let r = sub(b.center, view.eye);
        Eye {
            d2: dot(r, r),
            rn: dot(r, b.axis),
        }
    }

    /// Hoppe's `oriented_away`, with the cone's apex moved towards the eye by the radius.
    #[inline(always)]
    fn faces_away(self, b: &Bounds) -> bool {
        let s = self.rn - b.radius;
        s > 0.0 && s * s > self.d2 * (b.cone_sin * b.cone_sin)
    }

    /// Whether the normal cone holds a direction perpendicular to the view (a silhouette).
    #[inline(always)]
    fn on_silhouette(self, b: &Bounds) -> bool {
        self.rn * self.rn <= self.d2 * (b.cone_sin * b.cone_sin)
    }

    /// The spheroid's squared projected radius times `d^4`: equation 4 (seen at an angle) and
    /// equation 5 (its cross-section, seen from any direction).
    #[inline(always)]
    fn spheroid(self, b: &Bounds) -> f32 {
        (b.a2 * self.d2 + (b.b2 - b.a2) * self.rn * self.rn).max(b.b2 * self.d2)
    }

    /// Hoppe's sphere-plus-cones shape with `a` as its `delta` (along the axis) and `b` as its
    /// `mu` (around it): its squared projected radius times `d^4`.
    #[inline(always)]
    fn sphere_and_cones(self, b: &Bounds) -> f32 {
        (b.b2 * self.d2).max(b.a2 * (self.d2 - self.rn * self.rn))
    }
}

pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f32; 3]) -> Option<[f32; 3]> {
    let l = crate::root::sqrtf(dot(a, a));
    (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}

impl View {
    /// All zeros: a placeholder for "no view yet" in an all-zero (`.bss`) state.
    pub(crate) const ZERO: View = View {
        eye: [0.0; 3],
        forward: [0.0; 3],
        lanes: [[0.0; 8]; 4],
        fov_y: 0.0,
        tan_fov: 0.0,
        pixels_per_unit: 0.0,
    };

    /// The view from `eye` towards `target` with `up` roughly up, a vertical field of view of
    /// `fov_y` radians, width / height `aspect`, on a viewport `height` pixels tall. Degenerate
    /// input (eye on the target, `up` along the view) falls back to looking down `-z` with `+y` up.
    pub fn look_at(
        eye: [f32; 3],
        target: [f32; 3],
        up: [f32; 3],
        fov_y: f32,
        aspect: f32,
        height: f32,
    ) -> View {
        Self::with_frustum_scale(eye, target, up, fov_y, aspect, height, 1.0)
    }

    /// Like [`View::look_at`], but the frustum planes are those of a frustum whose cross-section
    /// is `scale` times the camera's in each direction (the merge-tree paper's frustum size,
    /// Table 1: 0.2 keeps a fifth of the width and height); the pixel scale stays the camera's.
    pub fn with_frustum_scale(
        eye: [f32; 3],
        target: [f32; 3],
        up: [f32; 3],
        fov_y: f32,
        aspect: f32,
        height: f32,
        scale: f32,
    ) -> View {
        let forward = normalize(sub(target, eye)).unwrap_or([0.0, 0.0, -1.0]);
        let right = normalize(cross(forward, up))
            .or_else(|| normalize(cross(forward, [0.0, 0.0, 1.0])))
            .unwrap_or([1.0, 0.0, 0.0]);
        let true_up = cross(right, forward);
        let tan_y = libm::tanf(fov_y * 0.5);
        let ty = tan_y * scale;
        let tx = ty * aspect;
        let plane = |n: [f32; 3]| {
            let n = normalize(n).unwrap_or(forward);
            [n[0], n[1], n[2], -dot(n, eye)]
        };
        let comb = |t: f32, side: [f32; 3], sign: f32| {
            [
                forward[0] * t + side[0] * sign,
                forward[1] * t + side[1] * sign,
                forward[2] * t + side[2] * sign,
            ]
        };
        let planes = [
            plane(comb(tx, right, 1.0)),
            plane(comb(tx, right, -1.0)),
            plane(comb(ty, true_up, 1.0)),
            plane(comb(ty, true_up, -1.0)),
            plane(forward),
        ];
        // Unused lanes: n = 0, d = MAX, never culling (centres are finite).
        let mut lanes = [[0.0f32; 8]; 4];
        lanes[3] = [f32::MAX; 8];
        for (i, p) in planes.iter().enumerate() {
            for k in 0..4 {
                lanes[k][i] = p[k];
            }
        }
        View {
            eye,
            forward,
            lanes,
            fov_y,
            tan_fov: libm::tanf(fov_y).abs().max(1e-6),
            pixels_per_unit: height / (2.0 * tan_y),
        }
    }

    /// Whether the sphere `(center, radius)` reaches into the frustum.
    #[inline]
    pub fn sphere_visible(&self, center: [f32; 3], radius: f32) -> bool {
        // Branch-free over all planes at once (each lane computes what a scalar loop would).
        let [x, y, z, d] = &self.lanes;
        let mut outside = false;
        for i in 0..8 {
            let dist = x[i] * center[0] + y[i] * center[1] + z[i] * center[2] + d[i];
            outside |= dist < -radius;
        }
        !outside
    }

    /// Frustum plane `i` (left, right, bottom, top, near) as `(n, d)`; `None` past the fifth.
    pub fn plane(&self, i: usize) -> Option<[f32; 4]> {
        (i < 5).then(|| [0, 1, 2, 3].map(|k| self.lanes[k][i]))
    }
}

/// A refinement policy (see the module documentation).
pub trait Policy {
    /// The policy's demand for a vertex with bounds `b` seen from `view`.
    fn demand(&self, b: &Bounds, view: &View) -> Demand;

    /// How the demand depends on `view` ([`Envelope`]), or `None` when the policy cannot say
    /// (the default): a cut then asks about every vertex every frame.
    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        let _ = view;
        None
    }

    /// Whether the demand reads nothing of the bounds but the bounding sphere (`center` and
    /// `radius`), so that a cut may decide from its own copy of each vertex's sphere without
    /// reading the hierarchy; `false` (the default) promises nothing.
    #[inline]
    fn sphere_only(&self) -> bool {
        false
    }

    /// Whether the policy also judges triangles ([`Policy::triangle`]); `false` (the default)
    /// lets the cut skip the walk around each vertex that judging them costs.
    #[inline]
    fn judges_triangles(&self) -> bool {
        false
    }

    /// The demand an active triangle with these corners (counter-clockwise seen from the
    /// front) puts on each of its corners, over tolerance when `> 1`: the importance paper
    /// decides per triangle, and an important triangle splits every corner that can split.
    /// `reach` is the largest bounding radius of the corners' regions: what the corners'
    /// splits can make lies within `reach` of the triangle (for the frustum test; a coarse
    /// triangle at a border can lie well inside the surface it stands for). Asked only when
    /// [`Policy::judges_triangles`]; 0 by default.
    #[inline]
    fn triangle(&self, corners: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        let _ = (corners, reach, view);
        0.0
    }
}

impl<A: Policy, B: Policy> Policy for (A, B) {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        let x = self.0.demand(b, view);
        if !x.visible {
            return Demand::CULLED;
        }
        let y = self.1.demand(b, view);
        if !y.visible {
            return Demand::CULLED;
        }
        Demand {
            visible: true,
            error: x.error.max(y.error),
        }
    }

    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        Some(self.0.envelope(view)?.and(self.1.envelope(view)?))
    }

    #[inline]
    fn sphere_only(&self) -> bool {
        self.0.sphere_only() && self.1.sphere_only()
    }

    #[inline]
    fn judges_triangles(&self) -> bool {
        self.0.judges_triangles() || self.1.judges_triangles()
    }

    #[inline]
    fn triangle(&self, corners: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        self.0
            .triangle(corners, reach, view)
            .max(self.1.triangle(corners, reach, view))
    }
}

impl<P: Policy + ?Sized> Policy for &P {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        (**self).demand(b, view)
    }

    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        (**self).envelope(view)
    }

    #[inline]
    fn sphere_only(&self) -> bool {
        (**self).sphere_only()
    }

    #[inline]
    fn judges_triangles(&self) -> bool {
        (**self).judges_triangles()
    }

    #[inline]
    fn triangle(&self, corners: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        (**self).triangle(corners, reach, view)
    }
}

/// Culls vertices whose bounding sphere lies outside the view frustum; wants nothing itself.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frustum;

impl Policy for Frustum {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        if view.sphere_visible(b.center, b.radius) {
            Demand::NONE
        } else {
            Demand::CULLED
        }
    }

    #[inline]
    fn envelope(&self, _: &View) -> Option<Envelope> {
        Some(Envelope {
            frustum: true,
            ..Envelope::ZERO
        })
    }

    #[inline]
    fn sphere_only(&self) -> bool {
        true
    }
}

/// Culls vertices whose whole cone of normals faces away from the eye (Hoppe's `oriented_away`,
/// with the cone's apex moved towards the eye by the bounding radius so that regions seen at an
/// angle stay in); wants nothing itself.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BackFace;

impl Policy for BackFace {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        if Eye::of(b, view).faces_away(b) {
            Demand::CULLED
        } else {
            Demand::NONE
        }
    }

    #[inline]
    fn envelope(&self, _: &View) -> Option<Envelope> {
        Some(Envelope {
            back_face: true,
            ..Envelope::ZERO
        })
    }
}

/// Wants a split while the node's error spheroid projects to more than the tolerance in pixels
/// (wavelet paper equations 4 and 5). Vertices whose normal cone spans both front- and
/// back-facing directions may lie on the silhouette and get the silhouette tolerance; the others
/// get the interior one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenError {
    /// Tolerance in pixels near the silhouette.
    pub silhouette: f32,
    /// Tolerance in pixels elsewhere.
    pub interior: f32,
}

impl ScreenError {
    /// The same tolerance, in pixels, everywhere.
    pub fn new(pixels: f32) -> ScreenError {
        ScreenError {
            silhouette: pixels,
            interior: pixels,
        }
    }

    /// The projected error radius of `b` in pixels (for tests and pictures; the policy itself
    /// needs no square root).
    pub fn pixels(b: &Bounds, view: &View) -> f32 {
        let e = Eye::of(b, view);
        crate::root::sqrtf(e.spheroid(b) / (e.d2 * e.d2)) * view.pixels_per_unit
    }

    /// `(projected radius / tolerance)^2 = lhs ppu^2 / (tol^2 d^4)`, with one division.
    #[inline(always)]
    fn ratio(&self, b: &Bounds, e: Eye, view: &View) -> f32 {
        let lhs = e.spheroid(b);
        let tol = if e.on_silhouette(b) {
            self.silhouette
        } else {
            self.interior
        };
        let rhs = tol * tol * e.d2 * e.d2;
        if rhs > 0.0 {
            lhs * (view.pixels_per_unit * view.pixels_per_unit) / rhs
        } else if lhs > 0.0 {
            f32::MAX
        } else {
            0.0
        }
    }
}

impl Policy for ScreenError {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        Demand {
            visible: true,
            error: self.ratio(b, Eye::of(b, view), view),
        }
    }

    /// `max(b^2 |d|^2, a^2 p^2) <= lhs <= max(a^2, b^2) |d|^2` for any axis (wavelet paper eq.
    /// 4-5; `p` the eye's distance from the axis), so the ratio lies between
    /// `max(b^2 |d|^2, a^2 p^2) ppu^2 / (tol^2 |d|^4)` with the larger tolerance and
    /// `max(a^2, b^2) ppu^2 / (tol^2 |d|^2)` with the smaller.
    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        let ppu2 = view.pixels_per_unit * view.pixels_per_unit;
        let (lo, hi) = (
            self.silhouette.min(self.interior),
            self.silhouette.max(self.interior),
        );
        Some(Envelope {
            upper: ppu2 / (lo * lo),
            lower: ppu2 / (hi * hi),
            ..Envelope::ZERO
        })
    }
}

/// [`ScreenError`] with Hoppe's bound instead of the spheroid ("View-dependent refinement of
/// progressive meshes", 1997): the error lies in a sphere of radius `mu` swept along the axis
/// by `delta`, read from [`Bounds::b2`] (`mu^2`) and [`Bounds::a2`] (`delta^2`). A split is
/// wanted while `mu^2 >= k^2 |d|^2` or `delta^2 (|d|^2 - (d.n)^2) >= k^2 |d|^4`, `k` the
/// tolerance over the pixels per unit length. For the wavelet paper's comparison (its Fig. 10)
/// with bounds built as Hoppe's (`Bound::Hoppe` for semi-regular files, `ErrorBound::Hoppe`
/// for vertex hierarchies, both under the `build` feature; such files set a header flag).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoppeError {
    /// Screen-space tolerances.
    pub error: ScreenError,
}

impl Policy for HoppeError {
    #[inline]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        let e = Eye::of(b, view);
        let lhs = e.sphere_and_cones(b);
        let tol = if e.on_silhouette(b) {
            self.error.silhouette
        } else {
            self.error.interior
        };
        let rhs = tol * tol * e.d2 * e.d2;
        let error = if rhs > 0.0 {
            lhs * (view.pixels_per_unit * view.pixels_per_unit) / rhs
        } else if lhs > 0.0 {
            f32::MAX
        } else {
            0.0
        };
        Demand {
            visible: true,
            error,
        }
    }

    /// `lhs = max(mu^2 |d|^2, delta^2 p^2)`, within the spheroid's envelope.
    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        self.error.envelope(view)
    }
}

/// The LOD lecture's `qrefine`: [`Frustum`], [`BackFace`] and [`ScreenError`] in one pass that
/// computes the eye vector and its length once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QRefine {
    /// Screen-space tolerances.
    pub error: ScreenError,
}

impl QRefine {
    /// The same tolerance, in pixels, everywhere.
    pub fn new(pixels: f32) -> QRefine {
        QRefine {
            error: ScreenError::new(pixels),
        }
    }
}

impl Policy for QRefine {
    #[inline(always)]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        if !view.sphere_visible(b.center, b.radius) {
            return Demand::CULLED;
        }
        let e = Eye::of(b, view);
        if e.faces_away(b) {
            return Demand::CULLED;
        }
        Demand {
            visible: true,
            error: self.error.ratio(b, e, view),
        }
    }

    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        Some(Envelope {
            frustum: true,
            back_face: true,
            ..self.error.envelope(view)?
        })
    }
}

/// The merge-tree paper's `shouldRefine` (§3.4): refine while the bounding sphere reaches into
/// the frustum and comes within `near` of the eye; nearer is more urgent. Everything so placed
/// refines to the leaves (`vdlod-demo reproduce table1` uses `near` = the eye's distance from
/// the model's centre; with `near` infinite, the whole frustum refines). It reads only bounding
/// spheres ([`Policy::sphere_only`]), so a cut decides most vertices without reading the file,
/// and describes itself by a near zone ([`Envelope::near`]), so a cut skips the vertices whose
/// answer cannot change while the camera moves a little.
///
/// ```
/// use vdlod_core::policy::{Bounds, MergeTree, Policy, View};
/// let view = View::look_at([0.0, 0.0, 10.0], [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
/// let policy = MergeTree { near: 5.0 };
/// let at = |z: f32| Bounds { center: [0.0, 0.0, z], radius: 0.5, ..Bounds::default() };
/// assert!(policy.demand(&at(6.0), &view).error > 1.0); // 3.5 from the eye: refine
/// assert_eq!(policy.demand(&at(-6.0), &view).error, 0.0); // too far: simplify
/// assert!(!policy.demand(&at(20.0), &view).visible); // behind the eye
/// let envelope = policy.envelope(&view).unwrap();
/// assert_eq!((envelope.near, envelope.frustum), (5.0, true));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MergeTree {
    /// Distance from the eye within which detail is wanted.
    pub near: f32,
}

impl Policy for MergeTree {
    #[inline(always)]
    fn demand(&self, b: &Bounds, view: &View) -> Demand {
        // Both tests are made for every sphere and the answer picked, not returned early:
        // which spheres are in view and near follows no pattern a branch predictor learns.
        let visible = view.sphere_visible(b.center, b.radius);
        let r = sub(b.center, view.eye);
        let gap = (crate::root::sqrtf(dot(r, r)) - b.radius).max(0.0);
        let wanted = 1.0 + 1.0 / (1.0 + gap);
        Demand {
            visible,
            error: if visible & (gap < self.near) {
                wanted
            } else {
                0.0
            },
        }
    }

    /// Wants nothing (error 0) but where the sphere comes within `near` of the eye, and there
    /// wants a split at an error over `1 + 1 / (1 + near)`.
    #[inline]
    fn envelope(&self, _: &View) -> Option<Envelope> {
        // A `near` of 0, negative or NaN wants nothing anywhere: no zone.
        let near = if self.near > 0.0 { self.near } else { 0.0 };
        Some(Envelope {
            frustum: true,
            near,
            near_error: 1.0 + 1.0 / (1.0 + near),
            ..Envelope::ZERO
        })
    }

    #[inline]
    fn sphere_only(&self) -> bool {
        true
    }
}

/// The importance paper's triangle importance (§IV): a triangle in the frustum is important when
///
/// `area / (distance tan(FOV)) max(-cos θ, sin θ) > threshold`
///
/// with `distance` from the eye to the triangle's centre, `FOV` the vertical field of view and
/// `θ` the angle between the triangle's normal and the eye-to-centre direction (largest for
/// triangles facing the eye or seen edge-on, zero for those facing away); an important triangle
/// splits each of its corners that can split ([`Policy::triangle`]). The cut asks the question
/// of every triangle around a vertex, and of the triangles a collapse would make before it
/// makes them, so a collapse never undoes a split the view still wants.
///
/// **Normalised**: lengths are measured in units of the model's size, the diagonal of its
/// bounding box ([`Importance::for_model`]), so `area / distance` is scale-free and a threshold
/// means the same on a bunny a few units across and on a terrain of thousands: roughly the
/// triangle's area as a fraction of the model's squared size, for a camera about one diagonal
/// away. [`Importance::DEFAULT_THRESHOLD`] is measured to give a sensible mesh on both (see
/// `docs/terrain.md`). The paper's 0.3 was in the units of its own 100-sample terrain,
/// whose diagonal is about 141 samples: 0.3 there is about 0.002 here.
///
/// [`Importance::demand`] wants nothing of a vertex by itself: both engines ask the triangles.
/// The vertex forest judges the active triangles around each vertex; the wavelet engine judges
/// the two triangles of the level above that a wavelet subdivides.
///
/// ```
/// use vdlod_core::policy::{Importance, Policy, View};
/// let view = View::look_at([0.0, 0.0, 10.0], [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
/// let policy = Importance::new(1e-3, 4.0); // a model whose bounding box is 4 units across
/// let facing = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 2.0, 0.0]];
/// assert!(policy.triangle(&facing, 0.0, &view) > 1.0); // important: its corners split
/// let away = [facing[0], facing[2], facing[1]];
/// assert_eq!(policy.triangle(&away, 0.0, &view), 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Importance {
    /// Importance above which a triangle splits its corners.
    pub threshold: f32,
    /// The model's size (its bounding-box diagonal): the unit lengths are measured in.
    pub size: f32,
}

impl Importance {
    /// A threshold that gives a sensible mesh on the terrain and on the bunny (see the type's
    /// documentation).
    pub const DEFAULT_THRESHOLD: f32 = 1e-4;

    /// The policy for a model whose bounding box has diagonal `size` (kept above zero).
    #[must_use]
    pub fn new(threshold: f32, size: f32) -> Importance {
        Importance {
            threshold,
            size: if size > 0.0 && size.is_finite() {
                size
            } else {
                1.0
            },
        }
    }

    /// The policy for a model in the box `(min, max)`, sized by its diagonal.
    #[must_use]
    pub fn for_box(threshold: f32, (min, max): ([f32; 3], [f32; 3])) -> Importance {
        let d = sub(max, min);
        Importance::new(threshold, crate::root::sqrtf(dot(d, d)))
    }

    /// The policy for the model `h` holds, sized by its bounding box.
    #[must_use]
    pub fn for_model(threshold: f32, h: &crate::format::HierarchyView<'_>) -> Importance {
        Importance::for_box(threshold, h.bounding_box())
    }

    /// The paper's importance of the triangle with corners `c` seen from `view`, in this
    /// policy's units: 0 when no point within `reach` of it is in the frustum, or when it faces
    /// exactly away.
    #[must_use]
    pub fn importance(&self, c: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        let center = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) * (1.0 / 3.0));
        let spread = c
            .iter()
            .map(|&x| {
                let r = sub(x, center);
                dot(r, r)
            })
            .fold(0.0f32, f32::max);
        if !view.sphere_visible(center, crate::root::sqrtf(spread) + reach.max(0.0)) {
            return 0.0;
        }
        let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let twice_area = crate::root::sqrtf(dot(n, n));
        let r = sub(center, view.eye);
        let d = crate::root::sqrtf(dot(r, r));
        if !(twice_area > 0.0 && d > 0.0) {
            // Degenerate, or the eye on its centre: only its size can speak.
            return if twice_area > 0.0 { f32::MAX } else { 0.0 };
        }
        let cos = (dot(n, r) / (twice_area * d)).clamp(-1.0, 1.0);
        let sin = crate::root::sqrtf(1.0 - cos * cos);
        let area = 0.5 * twice_area / (self.size * self.size);
        area / (d / self.size * view.tan_fov) * (-cos).max(sin)
    }
}

impl Policy for Importance {
    /// Wants nothing of a vertex by itself: the demand comes from its triangles.
    #[inline]
    fn demand(&self, _: &Bounds, _: &View) -> Demand {
        Demand::NONE
    }

    #[inline]
    fn judges_triangles(&self) -> bool {
        true
    }

    #[inline]
    fn triangle(&self, corners: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        let i = self.importance(corners, reach, view);
        if self.threshold > 0.0 {
            i / self.threshold
        } else if i > 0.0 {
            f32::MAX
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> View {
        View::look_at(
            [0.0, 0.0, 10.0],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            core::f32::consts::FRAC_PI_3,
            4.0 / 3.0,
            480.0,
        )
    }

    /// Numbers in `[0, 1)` from a xorshift generator seeded with `seed` (non-zero).
    fn uniform(seed: u32) -> impl FnMut() -> f32 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    fn bounds(center: [f32; 3], axis: [f32; 3], a: f32, b: f32) -> Bounds {
        Bounds {
            center,
            radius: 0.1,
            axis,
            cone_sin: 0.1,
            a2: a * a,
            b2: b * b,
        }
    }

    #[test]
    fn frustum_keeps_what_is_ahead_and_culls_what_is_behind_or_aside() {
        let v = view();
        let f = |c| Frustum.demand(&bounds(c, [0.0, 0.0, 1.0], 0.0, 0.0), &v);
        assert!(f([0.0; 3]).visible);
        assert!(!f([0.0, 0.0, 20.0]).visible); // behind the eye
        assert!(!f([100.0, 0.0, 0.0]).visible);
        // tan(30 deg) * 10 = 5.77 at the target plane, times the aspect horizontally.
        assert!(f([0.0, 5.6, 0.0]).visible && !f([0.0, 6.0, 0.0]).visible);
        let small = View::with_frustum_scale(
            v.eye,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            v.fov_y,
            4.0 / 3.0,
            480.0,
            0.2,
        );
        assert!(!small.sphere_visible([0.0, 2.0, 0.0], 0.1));
        assert!(small.sphere_visible([0.0, 1.0, 0.0], 0.1));
    }

    #[test]
    fn back_facing_cones_are_culled() {
        let v = view();
        let toward = bounds([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.0);
        let away = bounds([0.0; 3], [0.0, 0.0, -1.0], 0.0, 0.0);
        let edge_on = bounds([0.0; 3], [1.0, 0.0, 0.0], 0.0, 0.0);
        assert!(BackFace.demand(&toward, &v).visible);
        assert!(!BackFace.demand(&away, &v).visible);
        assert!(BackFace.demand(&edge_on, &v).visible);
    }

    #[test]
    fn screen_error_matches_the_projected_size_in_pixels() {
        let v = view();
        // A disc of radius 0.1 facing the eye at distance 10: 0.1 / (2 tan 30) * 480 / 10 px.
        let b = bounds([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.1);
        let px = 0.1 * 480.0 / (2.0 * libm::tanf(core::f32::consts::FRAC_PI_6) * 10.0);
        assert!((ScreenError::pixels(&b, &v) - px).abs() < 1e-3 * px);
        assert!(ScreenError::new(px * 0.99).demand(&b, &v).error > 1.0);
        assert!(ScreenError::new(px * 1.01).demand(&b, &v).error < 1.0);
        // Error along the normal is invisible face-on and full size edge-on (equation 4).
        let along = bounds([0.0; 3], [0.0, 0.0, 1.0], 0.1, 0.0);
        assert!(ScreenError::pixels(&along, &v) < 1e-3);
        let sideways = bounds([0.0; 3], [1.0, 0.0, 0.0], 0.1, 0.0);
        assert!((ScreenError::pixels(&sideways, &v) - px).abs() < 1e-3 * px);
    }

    #[test]
    fn silhouette_vertices_get_the_silhouette_tolerance() {
        let v = view();
        let p = ScreenError {
            silhouette: 0.5,
            interior: 4.0,
        };
        // About 2.1 px of error: over the silhouette tolerance, under the interior one.
        let facing = bounds([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.05);
        let edge_on = bounds([0.0; 3], [1.0, 0.0, 0.0], 0.05, 0.05);
        assert!(p.demand(&facing, &v).error < 1.0);
        assert!(p.demand(&edge_on, &v).error > 1.0);
    }

    #[test]
    fn qrefine_is_the_three_tests_composed() {
        let v = view();
        let composed = (
            Frustum,
            (
                BackFace,
                ScreenError {
                    silhouette: 0.5,
                    interior: 3.0,
                },
            ),
        );
        let fused = QRefine {
            error: ScreenError {
                silhouette: 0.5,
                interior: 3.0,
            },
        };
        let mut next = uniform(0x1234_5678);
        for _ in 0..10_000 {
            let c = [
                next() * 20.0 - 10.0,
                next() * 20.0 - 10.0,
                next() * 20.0 - 10.0,
            ];
            let n =
                normalize([next() - 0.5, next() - 0.5, next() - 0.5]).unwrap_or([0.0, 0.0, 1.0]);
            let a = next() * 0.2;
            let b = Bounds {
                center: c,
                radius: next(),
                axis: n,
                cone_sin: next(),
                a2: a * a,
                b2: if next() < 0.5 { 0.0 } else { a * a * next() },
            };
            assert_eq!(composed.demand(&b, &v), fused.demand(&b, &v), "{b:?}");
            // The envelope the cut skips vertices with holds, and is the same for both forms.
            let env = fused.envelope(&v).unwrap();
            assert_eq!(composed.envelope(&v), Some(env));
            let d = fused.demand(&b, &v);
            let r = sub(c, v.eye);
            let d2 = dot(r, r);
            let culled = (env.frustum && !v.sphere_visible(c, b.radius))
                || (env.back_face && Eye::of(&b, &v).faces_away(&b));
            assert_eq!(d.visible, !culled, "{b:?}");
            if !culled {
                let s2 = b.a2.max(b.b2);
                let rn = dot(r, b.axis);
                let floor = ((b.b2 * d2).max(b.a2 * (d2 - rn * rn)) - 1e-5 * s2 * d2) * env.lower
                    / (d2 * d2);
                assert!(d.error <= s2 * env.upper / d2 * (1.0 + 1e-5), "{b:?}");
                assert!(d.error >= floor * (1.0 - 1e-5), "{b:?}");
            }
        }
        assert_eq!(
            Frustum.envelope(&v),
            Some(Envelope {
                frustum: true,
                ..Envelope::ZERO
            })
        );
        // Different tolerances: the lower bound uses the larger one.
        let two = ScreenError {
            silhouette: 0.5,
            interior: 2.0,
        }
        .envelope(&v)
        .unwrap();
        assert_eq!(two.upper, 16.0 * two.lower);
    }

    /// The merge-tree policy's envelope holds: culled exactly outside the frustum, error 0
    /// beyond the near zone, at least the near error inside it; a `near` that wants nothing
    /// has no zone.
    #[test]
    fn the_merge_tree_envelope_holds() {
        let v = view();
        let mut next = uniform(0x2545_f491);
        for near in [0.5, 4.0, 12.0, f32::INFINITY] {
            let m = MergeTree { near };
            let env = m.envelope(&v).unwrap();
            assert_eq!((env.near, env.frustum, env.back_face), (near, true, false));
            let (mut inside, mut beyond) = (0, 0);
            for _ in 0..10_000 {
                let c = [0, 1, 2].map(|_| next() * 30.0 - 15.0);
                let b = Bounds {
                    center: c,
                    radius: 2.0 * next(),
                    ..Bounds::default()
                };
                let d = m.demand(&b, &v);
                assert_eq!(d.visible, v.sphere_visible(c, b.radius), "{b:?}");
                if !d.visible {
                    assert_eq!(d.error, 0.0);
                    continue;
                }
                let r = sub(c, v.eye);
                if env.beyond_near(dot(r, r), b.radius, 1.0 + 1e-5) {
                    beyond += 1;
                    assert_eq!(d.error, 0.0, "{b:?}");
                } else {
                    inside += 1;
                    assert!(d.error >= env.near_error * (1.0 - 1e-6), "{b:?}");
                }
            }
            assert!(
                inside > 0 && (beyond > 100 || near > 12.0),
                "{near}: {inside} {beyond}"
            );
        }
        for near in [0.0, -1.0, f32::NAN] {
            let env = MergeTree { near }.envelope(&v).unwrap();
            assert_eq!(env.near, 0.0);
            let b = bounds([0.0, 0.0, 9.0], [0.0, 0.0, 1.0], 0.0, 0.0);
            assert_eq!(MergeTree { near }.demand(&b, &v).error, 0.0);
        }
        // Beside a screen-space policy, inside the zone the near error still holds.
        let both = (MergeTree { near: 4.0 }, ScreenError::new(1.0))
            .envelope(&v)
            .unwrap();
        assert_eq!((both.near, both.near_error), (4.0, 1.2));
        assert!(both.upper > 0.0);
    }

    #[test]
    fn merge_tree_prefers_what_is_near() {
        let v = view();
        let near = bounds([0.0, 0.0, 5.0], [0.0, 0.0, 1.0], 0.0, 0.0);
        let far = bounds([0.0, 0.0, -20.0], [0.0, 0.0, 1.0], 0.0, 0.0);
        let m = MergeTree { near: 10.0 };
        assert!(m.demand(&near, &v).error > 1.0);
        assert!(m.demand(&far, &v).error <= 1.0);
        let both = (Frustum, m);
        assert!(
            !both
                .demand(&bounds([0.0, 0.0, 50.0], [0.0; 3], 0.0, 0.0), &v)
                .visible
        );
    }

    #[test]
    fn importance_is_the_papers_formula_in_units_of_the_model() {
        let v = view(); // eye at z = 10 looking down -z, fov 60 degrees
        let tan = libm::tanf(core::f32::consts::FRAC_PI_3);
        let facing = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 2.0, 0.0]]; // area 3, centred
        let i = Importance::new(1e-3, 4.0);
        // Facing the eye: -cos(theta) = 1; area / size^2 over distance / size times tan(FOV).
        let want = (3.0 / 16.0) / (10.0 / 4.0 * tan);
        let got = i.importance(&facing, 0.0, &v);
        assert!((got - want).abs() < 1e-5 * want, "{got} vs {want}");
        assert!((i.triangle(&facing, 0.0, &v) - want / 1e-3).abs() < 1e-2 * want / 1e-3);
        // Seen edge-on: sin(theta) = 1, the same weight; facing away: nothing.
        let edge_on = [[0.0, -1.0, -1.0], [0.0, -1.0, 1.0], [0.0, 2.0, 0.0]];
        let twisted = i.importance(&edge_on, 0.0, &v);
        assert!((twisted - want).abs() < 1e-3 * want, "{twisted}");
        let away = [facing[0], facing[2], facing[1]];
        assert_eq!(i.importance(&away, 0.0, &v), 0.0);
        // Nearer is more important, as 1 / distance.
        let nearer = facing.map(|c| [c[0], c[1], 5.0]);
        let n = i.importance(&nearer, 0.0, &v);
        assert!((n - 2.0 * want).abs() < 1e-3 * want, "{n}");
        // Outside the frustum: nothing, unless its corners' regions reach in.
        let aside = facing.map(|c| [c[0] + 30.0, c[1], c[2]]);
        assert_eq!(i.importance(&aside, 0.0, &v), 0.0);
        assert!(i.importance(&aside, 30.0, &v) > 0.0);
        // Scale-free: the model, the eye and the size scaled together give the same number.
        let s = 1000.0;
        let big = View::look_at(
            [0.0, 0.0, 10.0 * s],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            core::f32::consts::FRAC_PI_3,
            4.0 / 3.0,
            480.0,
        );
        let scaled = facing.map(|c| c.map(|x| x * s));
        let k = Importance::new(1e-3, 4.0 * s).importance(&scaled, 0.0, &big);
        assert!((k - want).abs() < 1e-4 * want, "{k}");
        // The vertex alone wants nothing; the cut asks the triangles.
        let b = bounds([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.0);
        assert_eq!(i.demand(&b, &v), Demand::NONE);
        assert!(i.judges_triangles() && (Frustum, i).judges_triangles());
        assert!(!QRefine::new(1.0).judges_triangles());
        assert_eq!(QRefine::new(1.0).triangle(&facing, 0.0, &v), 0.0);
    }
}
