//! How close a remesh is to its input, and how well shaped.
//!
//! Distances are measured both ways with the builder's closest-point grid: from the remesh to
//! the input at every finest triangle's centroid and edge midpoints (its vertices lie on the
//! input by construction), and from the input to the remesh at every input vertex and triangle
//! centroid. The two-sided Hausdorff distance is the largest of them all, the RMS distance the
//! root of their mean square, both as fractions of the input's bounding-box diagonal.

use super::Remesh;
use crate::build::closest::Surface;
use crate::build::vec3::{cross, dot, from_f32, len, normalize, sub, Vec3d};
use crate::build::{validate, InputMesh};

/// A remesh measured against its input.
#[derive(Clone, Debug, PartialEq)]
pub struct Quality {
    /// Two-sided Hausdorff distance over the samples, as a fraction of the bounding-box diagonal.
    pub hausdorff: f64,
    /// Root-mean-square distance over the samples, as a fraction of the diagonal.
    pub rms: f64,
    /// Finest triangles facing against the input there (their normal's dot product with the
    /// input's normal at their corners is negative): 0 for a remesh without fold-overs.
    pub flipped: u32,
    /// Finest triangles by shape, `4 sqrt(3) area / (sum of squared edge lengths)` (1 for an
    /// equilateral triangle, 0 for a sliver) in ten bins of 0.1.
    pub shapes: [u32; 10],
    /// Distances sampled.
    pub samples: u64,
    /// Where the largest distance was found: a point of the input (`true`: the remesh misses
    /// the input there) or of the remesh (`false`: it leaves the input there).
    pub farthest: ([f32; 3], bool),
}

impl Remesh {
    /// Measures this remesh against `input`, the mesh it was made from. Against a mesh that is
    /// not valid input or has fewer triangles than this remesh's places name, the distances are
    /// infinite and nothing else is measured.
    #[must_use]
    pub fn quality(&self, input: &InputMesh<'_>) -> Quality {
        let faces = input.triangles.len();
        if validate(input).is_err() || self.on_input.iter().any(|&(f, _)| f as usize >= faces) {
            return Quality {
                hausdorff: f64::INFINITY,
                rms: f64::INFINITY,
                flipped: 0,
                shapes: [0; 10],
                samples: 0,
                farthest: ([0.0; 3], true),
            };
        }
        let finest = self.mesh.finest_triangles();
        let positions = &self.mesh.positions;
        let d = distances(positions, &finest, input);
        let mut flipped = 0;
        let mut shapes = [0u32; 10];
        let input_normal = |v: u32| -> Vec3d {
            let (f, _) = self.on_input[v as usize];
            let t = input.triangles[f as usize].map(|i| from_f32(input.positions[i as usize]));
            normalize(cross(sub(t[1], t[0]), sub(t[2], t[0]))).unwrap_or([0.0; 3])
        };
        for t in &finest {
            let [a, b, c] = t.map(|v| from_f32(positions[v as usize]));
            let n = cross(sub(b, a), sub(c, a));
            let seen = t.iter().fold([0.0; 3], |s, &v| {
                let m = input_normal(v);
                [s[0] + m[0], s[1] + m[1], s[2] + m[2]]
            });
            if dot(n, seen) < 0.0 {
                flipped += 1;
            }
            let edges = [sub(b, a), sub(c, b), sub(a, c)];
            let squares: f64 = edges.iter().map(|&e| dot(e, e)).sum();
            let shape = if squares > 0.0 {
                2.0 * crate::root::sqrt(3.0) * len(n) / squares
            } else {
                0.0
            };
            shapes[((shape * 10.0) as usize).min(9)] += 1;
        }
        Quality {
            hausdorff: d.hausdorff,
            rms: d.rms,
            flipped,
            shapes,
            samples: d.samples,
            farthest: d.farthest,
        }
    }
}

/// Two-sided distances between a triangle mesh and a reference surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Distances {
    /// The largest distance, as a fraction of the reference's bounding-box diagonal.
    pub hausdorff: f64,
    /// The root-mean-square distance, as a fraction of the diagonal.
    pub rms: f64,
    /// Distances sampled.
    pub samples: u64,
    /// Where the largest distance was found: a point of the reference (`true`) or of the mesh
    /// (`false`).
    pub farthest: ([f32; 3], bool),
}

/// The two-sided distances between the mesh `positions`, `triangles` and the valid mesh
/// `reference`: from the mesh at every triangle's centroid and edge midpoints, from the
/// reference at every vertex and triangle centroid (a mesh whose vertices lie on the reference,
/// as a remesh's do, is measured where it may leave it). Infinite when `reference` is not valid
/// input or `triangles` name a vertex that is not there.
///
/// ```
/// use vdlod_core::build::InputMesh;
/// use vdlod_core::remesh::distances;
/// let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// let triangles = [[0, 1, 2]];
/// let flat = InputMesh { positions: &positions, colors: None, triangles: &triangles };
/// assert_eq!(distances(&positions, &triangles, &flat).hausdorff, 0.0);
/// let raised = [[0.0, 0.0, 0.1], [1.0, 0.0, 0.1], [0.0, 1.0, 0.1]];
/// let d = distances(&raised, &triangles, &flat);
/// assert!((d.hausdorff - 0.1 / 2f64.sqrt()).abs() < 1e-6);
/// ```
#[must_use]
pub fn distances(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    reference: &InputMesh<'_>,
) -> Distances {
    let named = |t: &[u32; 3]| t.iter().all(|&v| (v as usize) < positions.len());
    if validate(reference).is_err() || !triangles.iter().all(named) {
        return Distances {
            hausdorff: f64::INFINITY,
            rms: f64::INFINITY,
            samples: 0,
            farthest: ([0.0; 3], true),
        };
    }
    let to_reference = Surface::new(reference.positions, reference.triangles);
    let to_mesh = Surface::new(positions, triangles);
    let diagonal = diagonal(reference.positions).max(f64::MIN_POSITIVE);
    let mut largest = 0.0f64;
    let mut squares = 0.0f64;
    let mut samples = 0u64;
    let mut farthest = ([0.0f32; 3], false);
    let mut add = |d: f64, at: Vec3d, on_reference: bool| {
        if d > largest {
            farthest = (at.map(|x| x as f32), on_reference);
        }
        largest = largest.max(d);
        squares += d * d;
        samples += 1;
    };
    for t in triangles {
        let [a, b, c] = t.map(|v| from_f32(positions[v as usize]));
        for p in [
            centroid(&[a, b, c]),
            centroid(&[a, b]),
            centroid(&[b, c]),
            centroid(&[c, a]),
        ] {
            add(to_reference.distance(p), p, false);
        }
    }
    for p in reference.positions {
        add(to_mesh.distance(from_f32(*p)), from_f32(*p), true);
    }
    for t in reference.triangles {
        let c = t.map(|v| from_f32(reference.positions[v as usize]));
        add(to_mesh.distance(centroid(&c)), centroid(&c), true);
    }
    Distances {
        hausdorff: largest / diagonal,
        rms: crate::root::sqrt(squares / samples.max(1) as f64) / diagonal,
        samples,
        farthest,
    }
}

fn centroid(points: &[Vec3d]) -> Vec3d {
    let n = points.len() as f64;
    let s = points
        .iter()
        .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
    [s[0] / n, s[1] / n, s[2] / n]
}

/// The bounding box's diagonal.
pub(crate) fn diagonal(positions: &[[f32; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    if positions.is_empty() {
        return 0.0;
    }
    len(sub(hi, lo))
}
