//! Quadric error metric (Garland and Heckbert; the LOD lecture's "v^T Q v").
//!
//! A quadric holds the sum of squared distances to a set of planes as the symmetric 4x4 matrix
//! `Q = sum p p^T` (10 distinct entries), so that `v^T Q v` is that sum for a point `v`. Kept in
//! `f64`: the entries are differences of large, nearly equal products.

use super::vec3::{add, cross, dot, len, scale, sub, Vec3d};

/// Sum of squared distances to planes, `v^T Q v`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadric {
    // Upper triangle of Q: a2 ab ac ad / b2 bc bd / c2 cd / d2.
    q: [f64; 10],
}

impl Quadric {
    /// The quadric of the plane `n . x + d = 0` (`n` of unit length), times `weight`.
    pub fn plane(n: Vec3d, d: f64, weight: f64) -> Quadric {
        let [a, b, c] = n;
        let w = weight;
        Quadric {
            q: [
                w * a * a,
                w * a * b,
                w * a * c,
                w * a * d,
                w * b * b,
                w * b * c,
                w * b * d,
                w * c * c,
                w * c * d,
                w * d * d,
            ],
        }
    }

    /// The plane of triangle `(p0, p1, p2)` weighted by its area; zero for a degenerate triangle.
    pub fn triangle(p0: Vec3d, p1: Vec3d, p2: Vec3d) -> Quadric {
        let n = cross(sub(p1, p0), sub(p2, p0));
        let l = len(n);
        if l <= 0.0 || !l.is_finite() {
            return Quadric::default();
        }
        let unit = scale(n, 1.0 / l);
        Quadric::plane(unit, -dot(unit, p0), 0.5 * l)
    }

    /// A plane through the boundary edge `p0 -> p1` perpendicular to the face normal `face_n`:
    /// keeps open borders from shrinking. Weighted by the squared edge length times `weight`.
    pub fn boundary(p0: Vec3d, p1: Vec3d, face_n: Vec3d, weight: f64) -> Quadric {
        let e = sub(p1, p0);
        let n = cross(e, face_n);
        let l = len(n);
        if l <= 0.0 || !l.is_finite() {
            return Quadric::default();
        }
        let unit = scale(n, 1.0 / l);
        Quadric::plane(unit, -dot(unit, p0), weight * dot(e, e))
    }

    /// Sum of two quadrics.
    pub fn add(&self, o: &Quadric) -> Quadric {
        let mut q = self.q;
        for (a, b) in q.iter_mut().zip(o.q) {
            *a += b;
        }
        Quadric { q }
    }

    /// `v^T Q v` (clamped at zero against rounding).
    pub fn error(&self, v: Vec3d) -> f64 {
        let [x, y, z] = v;
        let q = &self.q;
        let e = q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9];
        e.max(0.0)
    }

    /// The point minimising `v^T Q v`, when the 3x3 system is well conditioned.
    #[inline(always)]
    pub fn optimum(&self) -> Option<Vec3d> {
        let q = &self.q;
        let m = [[q[0], q[1], q[2]], [q[1], q[4], q[5]], [q[2], q[5], q[7]]];
        let rhs = [-q[3], -q[6], -q[8]];
        let det = dot(m[0], cross(m[1], m[2]));
        let scale_ = (q[0] + q[4] + q[7]).abs();
        let conditioned = det.abs() > 1e-12 * scale_ * scale_ * scale_ && det.is_finite();
        if !conditioned {
            return None;
        }
        // Cramer's rule.
        let col = |k: usize, r: Vec3d| -> [Vec3d; 3] {
            let mut c = m;
            for (row, v) in c.iter_mut().zip(r) {
                row[k] = v;
            }
            c
        };
        let d = |c: [Vec3d; 3]| dot(c[0], cross(c[1], c[2]));
        let v = [
            d(col(0, rhs)) / det,
            d(col(1, rhs)) / det,
            d(col(2, rhs)) / det,
        ];
        v.iter().all(|c| c.is_finite()).then_some(v)
    }
}

/// Both quadrics' minimiser, or the best of the two endpoints and their midpoint. (Inlined, as
/// is [`Quadric::optimum`]: out of line, once two engines called them, they cost each cost
/// measurement a tenth more instructions.)
#[inline(always)]
pub fn place(q: &Quadric, a: Vec3d, b: Vec3d) -> Vec3d {
    if let Some(v) = q.optimum() {
        return v;
    }
    let mid = scale(add(a, b), 0.5);
    let mut best = mid;
    for c in [a, b] {
        if q.error(c) < q.error(best) {
            best = c;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_plane() {
        let q = Quadric::plane([0.0, 0.0, 1.0], -2.0, 1.0);
        assert_eq!(q.error([5.0, -3.0, 2.0]), 0.0);
        assert!((q.error([0.0, 0.0, 5.0]) - 9.0).abs() < 1e-12);
    }

    #[test]
    fn three_planes_meet_in_a_point() {
        let q = Quadric::plane([1.0, 0.0, 0.0], -1.0, 1.0)
            .add(&Quadric::plane([0.0, 1.0, 0.0], -2.0, 1.0))
            .add(&Quadric::plane([0.0, 0.0, 1.0], -3.0, 1.0));
        let v = q.optimum().unwrap();
        for (a, b) in v.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-9);
        }
        // One plane only: no unique optimum; placement falls back to the best candidate.
        let flat = Quadric::plane([0.0, 0.0, 1.0], 0.0, 1.0);
        assert!(flat.optimum().is_none());
        assert_eq!(
            place(&flat, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
            [0.0, 0.0, 0.0]
        );
    }
}
