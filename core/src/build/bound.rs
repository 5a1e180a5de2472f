//! Error bounds fitted to a set of error vectors, shared by both builders.
//!
//! Each error vector `e` is given by its lengths along a unit normal `n` (`|e . n|`) and across
//! it (`|e x n|`). Two shapes bound the set:
//!
//! - the normal-aligned spheroid of Azuma, Wood, Curless, Duchamp, Salesin and Stuetzle,
//!   "View-dependent refinement of multiresolution meshes with subdivision connectivity" (2003),
//!   equation 3: its axis ratio `a / b` is the ratio of the largest lengths along and across,
//!   and it is then scaled so that every vector lies inside
//!   (`(along / a)^2 + (across / b)^2 <= 1`);
//! - Hoppe's deviation space ("View-dependent refinement of progressive meshes", 1997): a sphere
//!   of radius `mu` swept along the normal by `delta`. With `delta` the largest length along and
//!   `mu` the largest across, every vector lies inside.

/// The spheroid `[a, b]` of equation 3 holding every `(along, across)` pair of `errors`: `a`
/// along the normal, `b` across it. With nothing across (every vector on the normal) it is the
/// segment `[a, 0]`; with nothing along, the disc `[0, b]`.
///
/// ```
/// # use vdlod_core::build::bound::equation3;
/// // One vector along the normal, one across it, one in between: ratio 2 : 1, then scaled.
/// let [a, b] = equation3(&[(2.0, 0.0), (0.0, 1.0), (1.6, 0.8)]);
/// assert!((a / b - 2.0).abs() < 1e-6);
/// for (along, across) in [(2.0f32, 0.0f32), (0.0, 1.0), (1.6, 0.8)] {
///     let (x, y) = (along / a, across / b);
///     assert!(x * x + y * y <= 1.0 + 1e-6);
/// }
/// ```
#[must_use]
pub fn equation3(errors: &[(f32, f32)]) -> [f32; 2] {
    let [along, across] = hoppe(errors);
    if across <= 0.0 {
        return [along, 0.0];
    }
    if along <= 0.0 {
        return [0.0, across];
    }
    let ratio = along / across;
    let b = errors.iter().fold(0.0f32, |m, &(a, b)| {
        m.max(crate::root::sqrtf((a / ratio) * (a / ratio) + b * b))
    });
    [ratio * b, b]
}

/// Hoppe's `[delta, mu]` holding every `(along, across)` pair of `errors`: the largest length
/// along the normal and the largest across it.
#[must_use]
pub fn hoppe(errors: &[(f32, f32)]) -> [f32; 2] {
    errors
        .iter()
        .fold([0.0f32; 2], |[a, b], &(x, y)| [a.max(x), b.max(y)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spheroid_holds_every_vector_and_keeps_the_ratio() {
        let errors = [(0.3f32, 0.1f32), (0.05, 0.4), (0.25, 0.3), (0.0, 0.0)];
        let [a, b] = equation3(&errors);
        assert!((a / b - 0.3 / 0.4).abs() < 1e-6);
        for (x, y) in errors {
            assert!((x / a) * (x / a) + (y / b) * (y / b) <= 1.0 + 1e-5);
        }
        // Tight: some vector is on the surface.
        assert!(errors
            .iter()
            .any(|&(x, y)| ((x / a) * (x / a) + (y / b) * (y / b) - 1.0).abs() < 1e-5));
    }

    #[test]
    fn degenerate_sets_give_segments_and_discs() {
        assert_eq!(equation3(&[(0.5, 0.0), (0.2, 0.0)]), [0.5, 0.0]);
        assert_eq!(equation3(&[(0.0, 0.5), (0.0, 0.7)]), [0.0, 0.7]);
        assert_eq!(equation3(&[]), [0.0, 0.0]);
        assert_eq!(hoppe(&[(0.5, 0.1), (0.2, 0.3)]), [0.5, 0.3]);
    }
}
