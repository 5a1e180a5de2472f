//! Small `f64` vector helpers for the offline builder (plain arrays, no SIMD, deterministic).

/// A point or direction in double precision.
pub type Vec3d = [f64; 3];

/// `a + b`.
pub fn add(a: Vec3d, b: Vec3d) -> Vec3d {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
pub fn sub(a: Vec3d, b: Vec3d) -> Vec3d {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a * s`.
pub fn scale(a: Vec3d, s: f64) -> Vec3d {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
pub fn dot(a: Vec3d, b: Vec3d) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: Vec3d, b: Vec3d) -> Vec3d {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn len(a: Vec3d) -> f64 {
    crate::root::sqrt(dot(a, a))
}

/// `a` scaled to unit length, or `None` for a zero or non-finite vector.
pub fn normalize(a: Vec3d) -> Option<Vec3d> {
    normalize_by(a, len(a))
}

/// [`normalize`] of `a` whose length `l` is already measured (as [`len`] measures it).
pub fn normalize_by(a: Vec3d, l: f64) -> Option<Vec3d> {
    (l > 0.0 && l.is_finite()).then(|| scale(a, 1.0 / l))
}

/// Widens an `f32` point.
pub fn from_f32(p: [f32; 3]) -> Vec3d {
    [p[0] as f64, p[1] as f64, p[2] as f64]
}
