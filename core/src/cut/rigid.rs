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

/// The step from `a` to `b` in turns: every node centre within `radius` of the model's centre,
/// at `r` from it, moves in the camera's frame, relative to the planes, by at most the step
/// times `max(r, lever)`; 0 when the two are the same.
pub(crate) fn step(a: &Axes, b: &Axes, radius: f32, lever: f32) -> f32 {
    if a == b {
        return 0.0;
    }
    // The rows' difference: for two rotations its Frobenius norm is sqrt(2) times its norm.
    let mut squares = 0.0f32;
    for (p, q) in a.rows.iter().zip(&b.rows) {
        let d = sub(*p, *q);
        squares += dot(d, d);
    }
    let turn = libm::sqrtf(squares * 0.5) + 4.0 * ROUNDING;
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
    turn + (shift + planes) / lever
}

fn norm(v: [f32; 3]) -> f32 {
    libm::sqrtf(dot(v, v))
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
        assert_eq!(step(&axes(&v), &axes(&v), 1.0, 0.5), 0.0);
    }

    #[test]
    fn circling_the_centre_turns_by_the_angle_and_shifts_nothing() {
        let (a, b) = (view(0.3, [0.0; 3]), view(0.31, [0.0; 3]));
        let s = step(&axes(&a), &axes(&b), 1.0, 0.5);
        // 2 sin(0.005) turned, and rounding.
        assert!(s > 0.01 && s < 0.0101, "{s}");
    }

    #[test]
    fn every_point_moves_less_than_the_step_says() {
        // Points on and in the unit sphere about the centre, cameras turning, shifting and
        // changing their frustum.
        let points: [[f32; 3]; 200] = core::array::from_fn(|i| {
            let t = i as f32 * 0.37;
            let r = (i % 7) as f32 / 6.0;
            [
                r * libm::cosf(t) * libm::sinf(1.3 * t),
                r * libm::cosf(2.1 * t),
                r * libm::sinf(t) * libm::sinf(1.3 * t),
            ]
        });
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
            let s = step(&axes(&a), &axes(&b), 1.0, 0.5);
            for &p in &points {
                let bound = s * libm::sqrtf(dot(p, p)).max(0.5);
                let ((pa, da), (pb, db)) = (seen(&a, p), seen(&b, p));
                let moved = norm(sub(pa, pb));
                assert!(moved <= bound, "{moved} > {bound}");
                for i in 0..5 {
                    assert!(libm::fabsf(da[i] - db[i]) <= bound, "plane {i}");
                }
            }
        }
    }
}
