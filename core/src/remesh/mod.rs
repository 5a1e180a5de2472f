//! The remesher: any manifold triangle mesh into a semi-regular one for the wavelet engine
//! (feature `build`).
//!
//! Azuma et al.'s engine needs subdivision connectivity, which they say "can be readily generated
//! from surfaces of arbitrary topology using existing surface parameterization algorithms"; this
//! is ours, after Liu, Kim, Chen, Jacobson, Sharp and Aigerman's successive self-parameterization
//! ("Neural subdivision", 2020), itself a descendant of Lee et al.'s MAPS (1998):
//!
//! 1. The vertex forest's own edge collapses (quadric costs, the same legality tests) simplify
//!    the input to the chosen base size; each collapse also maps its region into the plane
//!    before and after ([`crate::build`]'s `flatten`), and an edge whose region cannot be mapped
//!    without a fold is not collapsed. A border stays where it is: edges from it merge onto it,
//!    border edges at a corner onto the corner, and only a corner may be left with a single base
//!    triangle (an ear on a straight stretch subdivides into triangles with no area).
//! 2. The base mesh is subdivided `J` times; every vertex of every level is a point of a base
//!    face at known barycentric weights.
//! 3. Each point is carried back through the collapses, last first: where a collapse touched its
//!    triangle, the point goes through that collapse's two planar maps into a triangle of the
//!    finer mesh. After the first collapse it lies in an input triangle, and its position is
//!    there, on the input surface.
//! 4. The composition of piecewise-linear bijections is one, so the points are the images of a
//!    bijective map from the base domain onto the input; but a chain of a few dozen nearly
//!    conformal maps compounds its small errors into slivers here and there, and conformal maps
//!    shrink spikes, so a horn's tip gets no point. A relaxation on the input surface evens the
//!    triangles out and untangles the few that face the wrong way, then the input vertices
//!    still farther from the remesh than 0.3% of the diagonal and than its mean edge (the tips)
//!    each pull one of the nearest remesh vertices onto themselves (`relax`); the last folds
//!    are untangled a patch at a time, by descent on an untangling energy (`untangle`).
//!
//! Every vertex stays on the input surface, the result keeps the input's genus and borders,
//! and colours follow each vertex's place on the input ([`Remesh::on_input`]).
//! [`Remesh::quality`] measures what came out: two-sided distances, flipped triangles, triangle
//! shapes.
//!
//! ```
//! use vdlod_core::build::InputMesh;
//! use vdlod_core::remesh::{remesh, RemeshOptions};
//! // A 16 x 16 grid of a gentle bump, remeshed over a base of about 8 faces, 3 levels.
//! let n = 16u32;
//! let positions: Vec<[f32; 3]> = (0..=n).flat_map(|j| (0..=n).map(move |i| {
//!     let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
//!     [x, y, 0.1 * (x * (1.0 - x) * y * (1.0 - y))]
//! })).collect();
//! let triangles: Vec<[u32; 3]> = (0..n).flat_map(|j| (0..n).flat_map(move |i| {
//!     let v = j * (n + 1) + i;
//!     [[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]]
//! })).collect();
//! let input = InputMesh { positions: &positions, colors: None, triangles: &triangles };
//! let options = RemeshOptions { base_faces: 8, levels: 3 };
//! let out = remesh(&input, &options, &mut |_| {}).unwrap();
//! assert_eq!(out.mesh.finest_triangles().len(), out.base_faces as usize * 64);
//! // Every planar map was a bijection: no point fell outside the triangle it was placed in.
//! assert!(out.worst_weight > -1e-9);
//! let q = out.quality(&input);
//! assert!(q.hausdorff < 0.01 && q.rms < 0.001);
//! ```

mod quality;
mod relax;
mod untangle;

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use crate::build::around::Around;
use crate::build::collapse::Engine;
use crate::build::flatten::{area2, barycentric, PlanarCollapse, Uv};
use crate::build::vec3::{dot, from_f32, sub};
use crate::build::{validate, BuildError, BuildOptions, InputMesh, NONE};
use crate::wavelet::format::MAX_LEVELS;
use crate::wavelet::{SemiRegular, SemiRegularBuildError};

pub use quality::{distances, Distances, Quality};

/// The worst base triangle shape a collapse may make (unless its region had one as bad).
const MIN_SHAPE: f64 = 0.3;

/// Settings of [`remesh`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RemeshOptions {
    /// Faces of the base mesh to aim for (the simplification stops at or just below it).
    pub base_faces: u32,
    /// Levels of 4-to-1 subdivision over the base (`1..=12`).
    pub levels: u32,
}

impl Default for RemeshOptions {
    /// A base of about 300 faces and four levels (76,800 faces at the finest level).
    fn default() -> RemeshOptions {
        RemeshOptions {
            base_faces: 300,
            levels: 4,
        }
    }
}

/// Why a mesh cannot be remeshed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RemeshError {
    /// The input is not an oriented manifold triangle mesh (see [`BuildError`]).
    Input(BuildError),
    /// The base must have fewer faces than the input, and at least 4.
    BaseSize {
        /// What was asked for.
        base_faces: u32,
        /// The input's triangles.
        input_faces: u32,
    },
    /// Levels outside `1..=12`.
    Levels(u32),
    /// The simplification stopped far above the base size (no legal collapse was left).
    NotReached {
        /// What was asked for.
        base_faces: u32,
        /// Where it stopped.
        reached: u32,
    },
    /// The semi-regular mesh could not be made (too many vertices for the levels).
    Output(SemiRegularBuildError),
}

impl fmt::Display for RemeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Input(e) => write!(f, "the input cannot be remeshed: {e}"),
            Self::BaseSize {
                base_faces,
                input_faces,
            } => write!(
                f,
                "a base of {base_faces} faces: it must have at least 4 and fewer than the \
                 input's {input_faces}"
            ),
            Self::Levels(l) => write!(f, "{l} levels: between 1 and {MAX_LEVELS}"),
            Self::NotReached {
                base_faces,
                reached,
            } => write!(
                f,
                "no collapse is left at {reached} faces, more than twice the {base_faces} asked \
                 for (small closed components or pinched borders cannot shrink further)"
            ),
            Self::Output(e) => write!(f, "the semi-regular mesh cannot be made: {e}"),
        }
    }
}

impl core::error::Error for RemeshError {}

impl From<SemiRegularBuildError> for RemeshError {
    fn from(e: SemiRegularBuildError) -> RemeshError {
        RemeshError::Output(e)
    }
}

/// What [`remesh`] is doing, for a progress bar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemeshProgress {
    /// Simplifying: collapses done, and at most how many are needed.
    Simplify {
        /// Collapses done.
        done: u32,
        /// About how many the base size needs.
        total: u32,
    },
    /// Carrying the subdivided base's vertices back through the collapses.
    Map {
        /// Collapses undone.
        done: u32,
        /// All of them.
        total: u32,
    },
}

/// A remeshed surface.
#[derive(Clone, Debug)]
pub struct Remesh {
    /// The semi-regular mesh: write it with [`SemiRegular::to_bytes`].
    pub mesh: SemiRegular,
    /// Faces of its base mesh.
    pub base_faces: u32,
    /// Edge collapses the simplification made.
    pub collapses: u32,
    /// Where each vertex of the semi-regular mesh lies on the input: an input triangle and
    /// barycentric weights over its corners (for colours and textures).
    pub on_input: Vec<(u32, [f64; 3])>,
    /// The most negative barycentric weight met when a point was carried into a finer triangle
    /// (before the relaxation): 0 (up to rounding, about `-1e-12`) when every planar map was a
    /// bijection; a fold shows up as a clearly negative value.
    pub worst_weight: f64,
}

/// A point of the mesh being unwound: a live face and weights over its corners.
#[derive(Clone, Copy, Debug)]
struct Located {
    face: u32,
    w: [f64; 3],
}

/// Remeshes `input` into a semi-regular mesh of about `options.base_faces` base faces and
/// `options.levels` levels whose every vertex lies on the input surface.
pub fn remesh(
    input: &InputMesh<'_>,
    options: &RemeshOptions,
    progress: &mut dyn FnMut(RemeshProgress),
) -> Result<Remesh, RemeshError> {
    validate(input).map_err(RemeshError::Input)?;
    let input_faces = input.triangles.len() as u32;
    if options.base_faces < 4 || options.base_faces >= input_faces {
        return Err(RemeshError::BaseSize {
            base_faces: options.base_faces,
            input_faces,
        });
    }
    if options.levels == 0 || options.levels > MAX_LEVELS {
        return Err(RemeshError::Levels(options.levels));
    }
    let build_options = BuildOptions::default();
    let mut engine = Engine::new(input, &build_options);
    engine.planar = Some(Vec::new());
    engine.min_shape = MIN_SHAPE;
    engine.keep_borders();
    let (faces, collapses) = simplify(&mut engine, options.base_faces, input_faces, progress);
    if faces > options.base_faces.saturating_mul(2) {
        return Err(RemeshError::NotReached {
            base_faces: options.base_faces,
            reached: faces,
        });
    }
    // The base mesh: the live faces in id order over the vertices they use, renumbered.
    let live: Vec<u32> = (0..input_faces)
        .filter(|&f| engine.face_alive[f as usize])
        .collect();
    let mut number = vec![NONE; engine.pos.len()];
    let mut base_positions: Vec<[f32; 3]> = Vec::new();
    let mut corner_of: Vec<Located> = Vec::new(); // each base vertex as a point of a live face
    let base_triangles: Vec<[u32; 3]> = live
        .iter()
        .map(|&f| {
            let t = engine.faces[f as usize];
            core::array::from_fn(|k| {
                let v = t[k] as usize;
                if number[v] == NONE {
                    number[v] = base_positions.len() as u32;
                    base_positions.push(engine.pos.get(v as u32).map(|x| x as f32));
                    let mut w = [0.0; 3];
                    w[k] = 1.0;
                    corner_of.push(Located { face: f, w });
                }
                number[v]
            })
        })
        .collect();
    // Every vertex of every level: a point of a base face, found by laying the levels out.
    let steps = f64::from(1u32 << options.levels);
    let mut points = corner_of;
    let mut mesh =
        SemiRegular::from_fn(&base_positions, &base_triangles, options.levels, |f, w| {
            points.push(Located {
                face: live[f as usize],
                w: w.map(|x| f64::from(x) / steps),
            });
            [0.0; 3]
        })?;
    let planar = engine.planar.take().unwrap_or_default();
    let worst_weight = unwind(&mut points, &planar, input_faces, progress);
    let mut on_input: Vec<(u32, [f64; 3])> = points.iter().map(|p| (p.face, p.w)).collect();
    mesh.positions = on_input
        .iter()
        .map(|&(f, w)| {
            let t = input.triangles[f as usize].map(|v| input.positions[v as usize]);
            core::array::from_fn(|k| (0..3).map(|i| w[i] * f64::from(t[i][k])).sum::<f64>() as f32)
        })
        .collect();
    relaxed(input, &mut mesh, &mut on_input);
    mesh.colors = input.colors.map(|colors| {
        on_input
            .iter()
            .map(|&(f, w)| {
                let t = input.triangles[f as usize].map(|v| colors[v as usize]);
                core::array::from_fn(|k| {
                    let c: f64 = (0..3).map(|i| w[i] * f64::from(t[i][k])).sum();
                    libm::round(c).clamp(0.0, 255.0) as u8
                })
            })
            .collect()
    });
    Ok(Remesh {
        mesh,
        base_faces: live.len() as u32,
        collapses,
        on_input,
        worst_weight,
    })
}

/// Rounds of tangential relaxation after the map.
const RELAX_ROUNDS: u32 = 24;

/// Input vertices farther than this fraction of the diagonal (or the remesh's mean edge, if
/// longer) from the relaxed remesh get a remesh vertex snapped onto them.
const SNAP_REACH: f64 = 0.003;

/// Rounds over the vertices of triangles still facing the wrong way, at the end.
const UNTANGLE_ROUNDS: u32 = 128;

/// Passes of snapping (each followed by a few rounds of relaxation).
const SNAP_PASSES: u32 = 3;

/// Relaxes the finest level on the input (see `relax`), keeping the border where it is.
fn relaxed(input: &InputMesh<'_>, mesh: &mut SemiRegular, on_input: &mut [(u32, [f64; 3])]) {
    let triangles = mesh.finest_triangles();
    let n = mesh.positions.len();
    let mut fixed = vec![false; n];
    // Border vertices: on an edge only one triangle has.
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    edges.sort_unstable();
    for &(a, b) in &edges {
        if edges.binary_search(&(b, a)).is_err() {
            fixed[a as usize] = true;
            fixed[b as usize] = true;
        }
    }
    let around = Around::triangles(input.positions.len(), input.triangles);
    let surface = crate::build::closest::Surface::new(input.positions, input.triangles);
    let mut relax = relax::Relax {
        input,
        around: &around,
        triangles: &triangles,
        fixed,
        snapped: vec![false; n],
        surface: &surface,
        normals: relax::Relax::normals(input),
        around_remesh: Around::triangles(n, &triangles),
        reach: 0.0,
    };
    relax.run(RELAX_ROUNDS, false, &mut mesh.positions, on_input);
    // Past the chord error a remesh this fine has anyway: its mean edge.
    let edges: f64 = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| {
            let d = sub(
                from_f32(mesh.positions[a as usize]),
                from_f32(mesh.positions[b as usize]),
            );
            crate::root::sqrt(dot(d, d))
        })
        .sum::<f64>()
        / (3 * triangles.len()).max(1) as f64;
    let reach = (SNAP_REACH * quality::diagonal(input.positions)).max(edges);
    for _ in 0..SNAP_PASSES {
        if relax.snap(reach, &mut mesh.positions, on_input) == 0 {
            break;
        }
        relax.run(RELAX_ROUNDS / 4, false, &mut mesh.positions, on_input);
    }
    relax.reach = reach;
    relax.run(UNTANGLE_ROUNDS, true, &mut mesh.positions, on_input);
    relax.untangle(&mut mesh.positions, on_input);
}

/// Collapses edges until at most `base_faces` faces are left or none is legal; returns the faces
/// left and the collapses made.
fn simplify(
    engine: &mut Engine<'_>,
    base_faces: u32,
    input_faces: u32,
    progress: &mut dyn FnMut(RemeshProgress),
) -> (u32, u32) {
    let mut faces = input_faces;
    let total = (input_faces - base_faces) / 2;
    let every = (total / 200).max(1);
    let mut done = 0u32;
    while faces > base_faces && engine.step() {
        let removed = engine
            .collapses
            .last()
            .map_or(0, |c| if c.faces[1] == NONE { 1 } else { 2 });
        faces -= removed;
        done += 1;
        if done.is_multiple_of(every) {
            progress(RemeshProgress::Simplify { done, total });
        }
    }
    progress(RemeshProgress::Simplify { done, total });
    (faces, done)
}

/// Carries every point back through the collapses, last first, into the input triangles; returns
/// the most negative weight a point had in the triangle it was placed in.
fn unwind(
    points: &mut [Located],
    planar: &[PlanarCollapse],
    faces: u32,
    progress: &mut dyn FnMut(RemeshProgress),
) -> f64 {
    let mut in_face: Vec<Vec<u32>> = vec![Vec::new(); faces as usize];
    for (i, p) in points.iter().enumerate() {
        in_face[p.face as usize].push(i as u32);
    }
    let total = planar.len() as u32;
    let every = (total / 200).max(1);
    let mut worst = 0.0f64;
    for (done, step) in planar.iter().rev().enumerate() {
        // All the region's points leave their faces first: the faces before and after share
        // ids, and a point placed in one must not be moved again.
        let mut moving: Vec<(u32, Uv)> = Vec::new();
        for (f, t) in step.after() {
            let Some(after) = corners(step, t) else {
                continue;
            };
            for i in core::mem::take(&mut in_face[f as usize]) {
                let w = points[i as usize].w;
                let uv = [0, 1].map(|k| (0..3).map(|c| w[c] * after[c][k]).sum::<f64>());
                moving.push((i, uv));
            }
        }
        let before: Vec<(u32, [Uv; 3])> = if moving.is_empty() {
            Vec::new()
        } else {
            step.before
                .iter()
                .filter_map(|&(f, t)| Some((f, corners(step, t)?)))
                .collect()
        };
        for (i, uv) in moving {
            let p = &mut points[i as usize];
            match locate(&before, uv) {
                Some((face, w, least)) => {
                    worst = worst.min(least);
                    *p = Located { face, w };
                }
                None => worst = worst.min(-1.0), // never for valid maps: reported as a fold
            }
            in_face[p.face as usize].push(i);
        }
        let done = done as u32 + 1;
        if done.is_multiple_of(every) || done == total {
            progress(RemeshProgress::Map { done, total });
        }
    }
    worst
}

/// The planar corners of a face of the collapse's region.
fn corners(step: &PlanarCollapse, t: [u32; 3]) -> Option<[Uv; 3]> {
    let [a, b, c] = t.map(|v| step.uv_of(v));
    Some([a?, b?, c?])
}

/// The triangle of `faces` holding `uv` best (its smallest weight largest), with the weights
/// clamped to the triangle, and the smallest weight before clamping.
fn locate(faces: &[(u32, [Uv; 3])], uv: Uv) -> Option<(u32, [f64; 3], f64)> {
    let mut best: Option<(u32, [f64; 3], f64)> = None;
    for &(f, t) in faces {
        if area2(t[0], t[1], t[2]) <= 0.0 {
            continue;
        }
        let Some(w) = barycentric(t, uv) else {
            continue;
        };
        let least = w[0].min(w[1]).min(w[2]);
        if best.is_none_or(|(_, _, l)| least > l) {
            best = Some((f, w, least));
        }
    }
    best.map(|(f, w, least)| {
        let w = w.map(|x| x.max(0.0));
        let s: f64 = w.iter().sum();
        (f, w.map(|x| x / s), least)
    })
}

#[cfg(test)]
mod tests;
