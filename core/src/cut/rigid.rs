//! The camera's motion seen from the camera: how far any point of the model can have moved in
//! the camera's own frame, for the answers that depend on nothing else.
//!
//! A vertex's distance from the eye and its sphere's distances from the frustum's planes are the
//! same measured in the world or in the camera's frame, where the planes stand still. From the
//! camera, a frame's motion moves the model rigidly: it turns it about the model's centre `C`
//! and carries `C` along, so a point at `r` from `C` moves by at most `turn r + shift`, where
//! `turn` is how far the camera's axes turned (the norm of the difference of the two rotations,
//! `2 sin(angle / 2)`) and `shift` how far `C` moved in the camera's frame. A camera circling the
//! model while it looks at the centre turns by the angle it circles and shifts nothing, so a
//! point at `r` from the centre moves `r / D` times as far as the eye, `D` the orbit's radius:
//! the margins of a vertex near the centre last several times as many frames counted so as on
//! the eye's path (`super::expiry`'s second count).
//!
//! The frame is any orthonormal one fixed to the camera (built from the view's forward
//! direction and its side planes): should the planes themselves change in it (a new aspect or
//! frustum scale), the change is counted in the step too, so the bound holds for any view.
//!
//! A camera that keeps turning about one axis (an orbit, a turntable) turns the model about
//! that axis through its centre, and a point then moves by `turn r⊥`, `r⊥` its distance from
//! the axis, not from the centre; its distance from a plane moves by at most that times the
//! part of the plane's normal across the axis (`|n⊥|`: small for the top and bottom planes of
//! a camera circling about its vertical). The steps of such a camera are the same rotation
//! each frame, so with an axis `a` the step counts, beside the turn, how far the step strays
//! from a rotation about `a` by the same angle (`‖N − R_a‖`, see [`step`]); over any run of
//! frames the model's rotation is one about `a` by at most the turns' sum, followed by a
//! rotation within the strays' sum of the identity. So a point moves at most the count times
//! `max(r⊥, lever)`, and a plane's distance at most the count times `max(|n⊥| r⊥, lever)`,
//! `n⊥` taken from the frame the mark was made in. The axis passes through the point the
//! camera circles ([`pivot`]), which need not be the model's centre: taken about it, the
//! axes' centre does not shift from step to step.

use super::margin::Planes;
use crate::policy::{cross, dot, sub, View};

/// Float rounding allowed on the axes and on the centre's position in the camera's frame,
/// relative (about eight times a float's epsilon, far above what the few products commit).
const ROUNDING: f32 = 1e-6;

/// A view's axes and what stands still in them when the camera moves rigidly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Axes {
    /// Rows: side, up, forward (orthonormal up to rounding).
    rows: [[f32; 3]; 3],
    /// The model's centre in the camera's frame.
    center: [f32; 3],
    /// The frustum's planes in the camera's frame (`n` turned into it, `d` the plane's value
    /// at the eye).
    planes: Planes,
}

impl Axes {
    /// None (all zeros, as a zeroed cut holds them).
    pub const ZERO: Axes = Axes {
        rows: [[0.0; 3]; 3],
        center: [0.0; 3],
        planes: [[0.0; 4]; 5],
    };

    /// The axes of `view` with its `planes`, the model's centre at `center`; `None` when the
    /// view's forward direction and side planes span no frame (a degenerate view).
    pub fn of(view: &View, planes: &Planes, center: [f32; 3]) -> Option<Axes> {
        let f = view.forward;
        let side = sub(
            [planes[0][0], planes[0][1], planes[0][2]],
            [planes[1][0], planes[1][1], planes[1][2]],
        );
        let along = dot(side, f);
        let x = [
            side[0] - along * f[0],
            side[1] - along * f[1],
            side[2] - along * f[2],
        ];
        let (length, unit) = (norm(x), norm(f));
        // Far from degenerate, and from rounding mattering.
        if !(length > 1e-3 && libm::fabsf(unit - 1.0) < 1e-5) {
            return None;
        }
        let x = x.map(|c| c / length);
        let rows = [x, cross(f, x), f];
        let to = sub(center, view.eye);
        let planes = planes.map(|p| {
            let n = [p[0], p[1], p[2]];
            [
                dot(rows[0], n),
                dot(rows[1], n),
                dot(rows[2], n),
                dot(n, view.eye) + p[3],
            ]
        });
        Some(Axes {
            rows,
            center: rows.map(|r| dot(r, to)),
            planes,
        })
    }
}

/// The step from `a` to `b` in turns: every node centre within `radius` of the point both
/// axes were taken about ([`Axes::of`]'s `center`), at `r` from it, moves in the camera's
/// frame, relative to the planes, by at most the step times `max(r, lever)`; 0 when the two
/// are the same. With a unit `axis` (a world direction; the zero vector for none), `r` is the
/// distance from the axis through that point, and a plane's distance moves by at most the
/// step times `max(|n⊥| r, lever)` (see the module).
pub(crate) fn step(a: &Axes, b: &Axes, radius: f32, lever: f32, axis: [f32; 3]) -> f32 {
    if a == b {
        return 0.0;
    }
    let turned = turn(a, b);
    let strays = if axis == [0.0; 3] {
        0.0
    } else {
        stray(&rotation(a, b), turned, axis)
    };
    let turn = turned + 4.0 * ROUNDING;
    let moved = sub(b.center, a.center);
    let (from, to) = (norm(a.center), norm(b.center));
    let shift = norm(moved) + ROUNDING * (from + to);
    // A plane that changed in the camera's frame moves relative to any point within `reach`
    // of the eye by at most `|dn| reach + |dd|`.
    let reach = from.max(to) + radius;
    let mut planes = 0.0f32;
    for (p, q) in a.planes.iter().zip(&b.planes) {
        let dn = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        planes = planes.max(norm(dn) * reach + libm::fabsf(p[3] - q[3]));
    }
    turn + (shift + planes + strays * radius) / lever
}

/// `‖I − N‖` for the step's rotation `N`: `2 sin(angle / 2)`, without rounding's allowance.
fn turn(a: &Axes, b: &Axes) -> f32 {
    // The rows' difference: for two rotations its Frobenius norm is sqrt(2) times its norm.
    let mut squares = 0.0f32;
    for (p, q) in a.rows.iter().zip(&b.rows) {
        let d = sub(*p, *q);
        squares += dot(d, d);
    }
    crate::root::sqrtf(squares * 0.5)
}

/// The model's rotation from `a` to `b`, in the world: `N = Bᵀ A` (row `i` of `A` is the
/// camera's axis `i` as a world direction). A point at `q` from the model's centre is seen
/// from the two at `A q` and `B q`, and `B q − A q = B (I − N) q`: it moves as far as the
/// rotation `N` moves `q`.
fn rotation(a: &Axes, b: &Axes) -> [[f32; 3]; 3] {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            b.rows[0][i] * a.rows[0][j] + b.rows[1][i] * a.rows[1][j] + b.rows[2][i] * a.rows[2][j]
        })
    })
}

/// `sin(angle) axis` of a rotation `n`, from its skew part.
fn skew(n: &[[f32; 3]; 3]) -> [f32; 3] {
    [
        0.5 * (n[2][1] - n[1][2]),
        0.5 * (n[0][2] - n[2][0]),
        0.5 * (n[1][0] - n[0][1]),
    ]
}

/// How far the rotation `n` (with `‖I − n‖ = turned`) strays from the rotation about the unit
/// `axis` by the same angle, turned the same way round it: the Frobenius norm of their
/// difference (at least its norm), with rounding's allowance.
fn stray(n: &[[f32; 3]; 3], turned: f32, axis: [f32; 3]) -> f32 {
    // turned = 2 sin(angle / 2): cos = 1 - turned^2 / 2, |sin| = turned sqrt(1 - turned^2 / 4).
    let cos = 1.0 - 0.5 * turned * turned;
    let sin = turned * crate::root::sqrtf((1.0 - 0.25 * turned * turned).max(0.0));
    let sin = if dot(skew(n), axis) < 0.0 { -sin } else { sin };
    let [x, y, z] = axis;
    // Rodrigues: cos I + sin [axis]x + (1 - cos) axis axisᵀ.
    let k = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]];
    let mut squares = 0.0f32;
    for i in 0..3 {
        for j in 0..3 {
            let r =
                if i == j { cos } else { 0.0 } + sin * k[i][j] + (1.0 - cos) * axis[i] * axis[j];
            squares += (n[i][j] - r) * (n[i][j] - r);
        }
    }
    crate::root::sqrtf(squares) + 8.0 * ROUNDING
}

/// The unit axis the step from `a` to `b` turned about (a world direction, either way along
/// it), when it turned by more than a ten-thousandth of a radian; the axes of smaller turns
/// are mostly rounding.
pub(crate) fn spin(a: &Axes, b: &Axes) -> Option<[f32; 3]> {
    if a == b {
        return None;
    }
    let w = skew(&rotation(a, b));
    let sin = norm(w);
    (sin > 1e-4).then(|| w.map(|c| c / sin))
}

/// The point the step from `a` to `b` turned about, as an offset from the point both axes were
/// taken about ([`Axes::of`]'s `center`), across the unit `axis`: a camera circling a point
/// off that centre turns about the circle's axis, where a point stands still in the camera's
/// frame. `None` when the step turned too little to tell.
pub(crate) fn pivot(a: &Axes, b: &Axes, axis: [f32; 3]) -> Option<[f32; 3]> {
    // A point `c + d` is seen at `A (c - e_a) + A d` and `B (c - e_b) + B d`; with `A = B N`
    // it stands still where `(N - I) d = Bᵀ (c_b - c_a)`, solved across the axis.
    let n = rotation(a, b);
    let moved = sub(b.center, a.center);
    let g: [f32; 3] = core::array::from_fn(|i| {
        b.rows[0][i] * moved[0] + b.rows[1][i] * moved[1] + b.rows[2][i] * moved[2]
    });
    let other = if libm::fabsf(axis[0]) < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let e1 = cross(axis, other);
    let e1 = e1.map(|c| c / norm(e1));
    let e2 = cross(axis, e1);
    let less_i = |v: [f32; 3]| -> [f32; 3] { core::array::from_fn(|i| dot(n[i], v) - v[i]) };
    let (m1, m2) = (less_i(e1), less_i(e2));
    let [a11, a21, a12, a22] = [dot(e1, m1), dot(e2, m1), dot(e1, m2), dot(e2, m2)];
    let det = a11 * a22 - a12 * a21;
    // det = turn^2 for a rotation about the axis: a tenth of a degree at least.
    if det.partial_cmp(&3e-6) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let (g1, g2) = (dot(g, e1), dot(g, e2));
    let (d1, d2) = ((a22 * g1 - a12 * g2) / det, (a11 * g2 - a21 * g1) / det);
    Some(core::array::from_fn(|i| d1 * e1[i] + d2 * e2[i]))
}

/// The part across the unit `axis` of the unit normal `n`: `|n − (n . axis) axis|`.
pub(crate) fn across(n: [f32; 3], axis: [f32; 3]) -> f32 {
    let along = dot(n, axis);
    crate::root::sqrtf((dot(n, n) - along * along).max(0.0))
}

pub(crate) fn norm(v: [f32; 3]) -> f32 {
    crate::root::sqrtf(dot(v, v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::margin::planes;

    fn view(angle: f32, target: [f32; 3]) -> View {
        let eye = [10.0 * libm::sinf(angle), 3.0, 10.0 * libm::cosf(angle)];
        View::look_at(eye, target, [0.0, 1.0, 0.0], 1.0, 1.5, 480.0)
    }

    fn axes(v: &View) -> Axes {
        Axes::of(v, &planes(v), [0.0; 3]).expect("a look-at view has axes")
    }

    /// Points on and in the unit sphere about the origin, spread over it.
    fn points<const N: usize>() -> [[f32; 3]; N] {
        core::array::from_fn(|i| {
            let t = i as f32 * 0.37;
            let r = (i % 7) as f32 / 6.0;
            [
                r * libm::cosf(t) * libm::sinf(1.3 * t),
                r * libm::cosf(2.1 * t),
                r * libm::sinf(t) * libm::sinf(1.3 * t),
            ]
        })
    }

    /// Where `p` is in `v`'s frame, and its distances from `v`'s planes.
    fn seen(v: &View, p: [f32; 3]) -> ([f32; 3], [f32; 5]) {
        let a = axes(v);
        let to = sub(p, v.eye);
        let ps = planes(v);
        (
            a.rows.map(|r| dot(r, to)),
            core::array::from_fn(|i| dot([ps[i][0], ps[i][1], ps[i][2]], p) + ps[i][3]),
        )
    }

    #[test]
    fn a_still_camera_does_not_step() {
        let v = view(0.3, [0.0; 3]);
        assert_eq!(step(&axes(&v), &axes(&v), 1.0, 0.5, [0.0; 3]), 0.0);
    }

    #[test]
    fn circling_the_centre_turns_by_the_angle_and_shifts_nothing() {
        let (a, b) = (view(0.3, [0.0; 3]), view(0.31, [0.0; 3]));
        let s = step(&axes(&a), &axes(&b), 1.0, 0.5, [0.0; 3]);
        // 2 sin(0.005) turned, and rounding.
        assert!(s > 0.01 && s < 0.0101, "{s}");
        // It turned about the vertical, and about it strays by no more than rounding.
        let spin = spin(&axes(&a), &axes(&b)).expect("it turned");
        assert!(norm(cross(spin, [0.0, 1.0, 0.0])) < 1e-4, "{spin:?}");
        let about = step(&axes(&a), &axes(&b), 1.0, 0.5, [0.0, 1.0, 0.0]);
        assert!(about >= s && about < s + 1e-4, "{about} against {s}");
        // About an axis 0.1 rad off it strays by about sqrt(2) times the angle turned times
        // 0.1 (the Frobenius norm of the two rotations' difference), counted at the model's
        // radius over the lever floor, twice: about 0.0028 more.
        let tilted = [0.0, libm::cosf(0.1), libm::sinf(0.1)];
        let off = step(&axes(&a), &axes(&b), 1.0, 0.5, tilted) - s;
        assert!(off > 0.002 && off < 0.0035, "{off}");
    }

    #[test]
    fn every_point_moves_less_than_the_step_says() {
        // Points on and in the unit sphere about the centre, cameras turning, shifting and
        // changing their frustum.
        let points: [[f32; 3]; 200] = points();
        let scaled = View::with_frustum_scale(
            [0.0, 3.0, 10.0],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            1.0,
            1.5,
            480.0,
            0.5,
        );
        let pairs = [
            (view(0.3, [0.0; 3]), view(0.35, [0.0; 3])),
            (view(0.3, [0.0; 3]), view(0.3, [0.2, 0.1, 0.0])),
            (view(0.0, [0.0; 3]), scaled),
            (view(0.3, [0.0; 3]), view(2.0, [0.5, 0.0, 0.0])),
        ];
        for (a, b) in pairs {
            let s = step(&axes(&a), &axes(&b), 1.0, 0.5, [0.0; 3]);
            for &p in &points {
                let bound = s * crate::root::sqrtf(dot(p, p)).max(0.5);
                let ((pa, da), (pb, db)) = (seen(&a, p), seen(&b, p));
                let moved = norm(sub(pa, pb));
                assert!(moved <= bound, "{moved} > {bound}");
                for i in 0..5 {
                    assert!(libm::fabsf(da[i] - db[i]) <= bound, "plane {i}");
                }
            }
        }
    }

    /// Seven views turning about the vertical through the centre, wobbling a little about
    /// other axes (as rounding would, and more), and changing their frustum once.
    fn wobbling_orbit() -> [View; 7] {
        core::array::from_fn(|k| {
            let t = 0.3 + 0.02 * k as f32;
            let eye = [
                10.0 * libm::sinf(t),
                3.0 + 0.05 * (k % 3) as f32,
                10.0 * libm::cosf(t),
            ];
            let target = [0.0, 0.001 * (k % 2) as f32, 0.0];
            let scale = if k == 5 { 0.9 } else { 1.0 };
            View::with_frustum_scale(eye, target, [0.0, 1.0, 0.0], 1.0, 1.5, 480.0, scale)
        })
    }

    #[test]
    fn about_an_axis_every_point_and_plane_moves_less_than_the_counted_steps_say() {
        // From the first view to each later one, every point moves by at most the steps' sum
        // times its distance from the axis (at least the floor), and its distance from each
        // plane by at most that sum times the plane's normal's part across the axis (in the
        // first view) times that distance (at least the floor): the bound a mark relies on.
        let points: [[f32; 3]; 300] = points();
        let up = [0.0, 1.0, 0.0];
        let views = wobbling_orbit();
        let first = &views[0];
        let ps = planes(first);
        let across_up: [f32; 5] =
            core::array::from_fn(|i| across([ps[i][0], ps[i][1], ps[i][2]], up));
        // The top and bottom planes are mostly across the vertical: their distances move
        // slowly as the camera circles.
        assert!(across_up[2] < 0.8 && across_up[3] < 0.3, "{across_up:?}");
        let mut counted = 0.0;
        for pair in views.windows(2) {
            counted += step(&axes(&pair[0]), &axes(&pair[1]), 1.0, 0.5, up);
            let b = pair[1];
            for &p in &points {
                let reach = norm([p[0], 0.0, p[2]]);
                let ((pa, da), (pb, db)) = (seen(first, p), seen(&b, p));
                let moved = norm(sub(pa, pb));
                assert!(
                    moved <= counted * reach.max(0.5),
                    "{moved} > {counted} x {reach}"
                );
                for i in 0..5 {
                    let bound = counted * (across_up[i] * reach).max(0.5);
                    assert!(
                        libm::fabsf(da[i] - db[i]) <= bound,
                        "plane {i}: {} > {bound}",
                        libm::fabsf(da[i] - db[i])
                    );
                }
            }
        }
        // And the wobble costs little: the count about the axis is near the plain one.
        let plain: f32 = views
            .windows(2)
            .map(|pair| step(&axes(&pair[0]), &axes(&pair[1]), 1.0, 0.5, [0.0; 3]))
            .sum();
        assert!(counted < 1.5 * plain, "{counted} against {plain}");
    }

    #[test]
    fn a_turn_about_another_axis_strays_by_about_itself() {
        // Circling the centre over it (about the side axis): about the vertical the step
        // strays by about twice what it turns, so the count more than doubles.
        let over = |t: f32| {
            let eye = [0.0, 10.0 * libm::sinf(t), 10.0 * libm::cosf(t)];
            View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.5, 480.0)
        };
        let (a, b) = (over(0.1), over(0.12));
        let plain = step(&axes(&a), &axes(&b), 1.0, 0.5, [0.0; 3]);
        let about = step(&axes(&a), &axes(&b), 1.0, 0.5, [0.0, 1.0, 0.0]);
        assert!(about > 2.0 * plain, "{about} against {plain}");
        let spin = spin(&axes(&a), &axes(&b)).expect("it turned");
        assert!(libm::fabsf(spin[0]) > 0.999, "{spin:?}");
    }

    #[test]
    fn a_camera_circling_a_point_off_the_centre_turns_about_it() {
        let (o, up) = ([0.3, 0.0, 0.2], [0.0, 1.0, 0.0]);
        let view = |t: f32| {
            let eye = [
                o[0] + 10.0 * libm::sinf(t),
                3.0,
                o[2] + 10.0 * libm::cosf(t),
            ];
            View::look_at(eye, o, up, 1.0, 1.5, 480.0)
        };
        let (a, b) = (view(0.3), view(0.31));
        let d = pivot(&axes(&a), &axes(&b), up).expect("it turned");
        assert!(norm(sub(d, o)) < 1e-3, "{d:?}");
        // About the pivot the step is the turn alone; about the centre the centre shifts too.
        let about = |v: &View| Axes::of(v, &planes(v), d).expect("axes");
        let plain = step(&axes(&a), &axes(&b), 1.0, 0.5, up);
        let pivoted = step(&about(&a), &about(&b), 1.0, 0.5, up);
        assert!(
            pivoted < 0.0101 && plain > pivoted + 0.005,
            "{plain} against {pivoted}"
        );
        // A still camera says nothing of where it turns.
        assert_eq!(pivot(&axes(&a), &axes(&a), up), None);
    }
}
