//! Writing semi-regular files: the base mesh's topology, the positions of every level, and
//! per wavelet the bounds the run-time tests read (Azuma et al. §3.3).
//!
//! For each wavelet, over the image of its support (its one-ring at its own level):
//!
//! - the radius of the sphere around its vertex holding every finest vertex of the support
//!   (the view-frustum test, §3.3.1);
//! - the cone of normals around its vertex normal holding every finest triangle's normal (the
//!   back-face and silhouette tests, §3.3.2);
//! - the error spheroid of equation 3, aligned with the normal: at each finest vertex `q` of the
//!   support, the error `rho(q) - rho_t(q)` when the wavelet is left out. The paper computes it
//!   with every coarser wavelet in and every sibling out, and notes that a sibling coming in can
//!   raise the error. Here coarser wavelets are in, as the paper assumes (the closure condition
//!   puts the ancestors in, and the monotonic bounds below make the coarser neighbours wanted
//!   wherever the wavelet is); the wavelet and its descendants are out; and every other
//!   wavelet of its level or finer whose hat is not zero at `q` (the four siblings and their
//!   descendants) may be in or out: the bound holds for all of those sets. The error vectors
//!   of every such set (up to ten candidates at a vertex, 1,024 sets; beyond, a box of the
//!   extremes along and across the normal) are listed; the ratio `a / b` is that of their
//!   largest parts along and across the normal (equation 3), and the spheroid is then scaled to
//!   hold them all. Hoppe's `delta` and `mu` ([`Bound::Hoppe`]) are those largest parts.
//!
//! Bounds are then made monotonic down the dependency graph (a parent's sphere holds its
//! children's, its cone theirs, its `a` and `b` are at least theirs), so that a wavelet the tests
//! want has parents the tests want too.

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use super::format::{
    Counts, SemiRegularView, CRC_OFFSET, FACE_SIZE, FLAG_COLORS, FLAG_HOPPE, HEADER_SIZE, MAGIC,
    MAX_LEVELS, NONE, VERSION, VERTEX_SIZE,
};
use super::lattice::{hex_len, Point};
use crate::build::bound::{equation3, hoppe};
use crate::format::{crc32, encode_length, oct_decode, oct_encode, ModelBox};

/// Why a semi-regular mesh cannot be made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SemiRegularBuildError {
    /// No base face, or a base face names a vertex that is not there or names one twice.
    BadFace(u32),
    /// A base edge is run the same way twice or shared by more than two faces.
    NotManifold {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// Levels outside `1..=12`, or more vertices than a file holds.
    TooLarge,
    /// A position is not finite.
    NotFinite(u32),
    /// The positions or colours do not match the vertex count.
    Count {
        /// What was given.
        given: usize,
        /// What the levels and base mesh need.
        needed: usize,
    },
    /// Asked for a height field ([`SemiRegular::to_height_bytes`]): the up axis is not 0 to 2,
    /// or this vertex does not lie over the point of its base face that its weights name.
    NotHeightField(u32),
}

impl fmt::Display for SemiRegularBuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadFace(face) => write!(f, "base face {face} is degenerate or out of range"),
            Self::NotManifold { a, b } => {
                write!(
                    f,
                    "base edge {a}-{b} is not manifold (or faces disagree on orientation)"
                )
            }
            Self::TooLarge => write!(f, "levels must be 1 to 12 and the mesh below 2^31 vertices"),
            Self::NotFinite(v) => write!(f, "vertex {v}'s position is not finite"),
            Self::Count { given, needed } => write!(f, "{given} values given, {needed} needed"),
            Self::NotHeightField(v) => write!(
                f,
                "not a height field: vertex {v} does not lie over its point of the base face \
                 (or the up axis is not 0, 1 or 2)"
            ),
        }
    }
}

impl core::error::Error for SemiRegularBuildError {}

/// The unit octahedron's vertices: the base of [`SemiRegular::sphere`].
pub const OCTAHEDRON_VERTICES: [[f32; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

/// The unit octahedron's faces, counter-clockwise seen from outside.
pub const OCTAHEDRON_FACES: [[u32; 3]; 8] = [
    [0, 2, 4],
    [2, 1, 4],
    [1, 3, 4],
    [3, 0, 4],
    [2, 0, 5],
    [1, 2, 5],
    [3, 1, 5],
    [0, 3, 5],
];

/// The point at weights `w` (summing to `n`) of the triangle with corners `c`, on its plane.
#[must_use]
pub fn interpolate(c: [[f32; 3]; 3], w: [i32; 3], n: f32) -> [f32; 3] {
    core::array::from_fn(|k| (0..3).map(|i| c[i][k] * w[i] as f32 / n).sum())
}

/// The shape that bounds a wavelet's error in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// The spheroid of equation 3 (the default; read by [`crate::policy::ScreenError`]).
    Spheroid,
    /// Hoppe's sphere of radius `mu` swept along the normal by `delta`, in the `a` and `b`
    /// fields (read by [`crate::policy::HoppeError`]; for the paper's Fig. 10).
    Hoppe,
}

/// How [`SemiRegular::subdivide`] places the vertices of each level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// On the base triangles: every wavelet coefficient is zero.
    Midpoint,
    /// Loop subdivision.
    Loop,
}

/// A semi-regular mesh in memory: a base mesh, its levels, and every vertex's position (and
/// colour) in the file's vertex order.
#[derive(Clone, Debug)]
pub struct SemiRegular {
    /// The file's bytes with every record zero (a view for the lattice walks).
    skeleton: Vec<u8>,
    counts: Counts,
    /// Positions of every vertex, in file order.
    pub positions: Vec<[f32; 3]>,
    /// Colours of every vertex, if any.
    pub colors: Option<Vec<[u8; 3]>>,
}

/// The file's face and edge sections for a base mesh: corners, edge ids in the order sides
/// first name them, across links; and the edge count.
fn topology(
    vertices: u32,
    faces: &[[u32; 3]],
) -> Result<(Vec<u8>, Vec<u8>, u32), SemiRegularBuildError> {
    use alloc::collections::BTreeMap;
    if faces.is_empty() || faces.len() >= 1 << 29 {
        return Err(SemiRegularBuildError::BadFace(0));
    }
    // Directed edge -> face side.
    let mut sides: BTreeMap<(u32, u32), (u32, usize)> = BTreeMap::new();
    for (f, c) in faces.iter().enumerate() {
        if c.iter().any(|&v| v >= vertices) || c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            return Err(SemiRegularBuildError::BadFace(f as u32));
        }
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            if sides.insert((a, b), (f as u32, k)).is_some() {
                return Err(SemiRegularBuildError::NotManifold { a, b });
            }
        }
    }
    let mut edge_of = vec![[NONE; 3]; faces.len()];
    let mut face_bytes = Vec::with_capacity(faces.len() * FACE_SIZE);
    let mut owners: Vec<u32> = Vec::new();
    for (f, c) in faces.iter().enumerate() {
        for k in 0..3 {
            let across = sides.get(&(c[(k + 1) % 3], c[k])).copied();
            match across {
                Some((g, kk)) if (g as usize, kk) < (f, k) => {
                    edge_of[f][k] = edge_of[g as usize][kk]
                }
                _ => {
                    edge_of[f][k] = owners.len() as u32;
                    owners.push(((f as u32) << 2) | k as u32);
                }
            }
        }
    }
    for (f, c) in faces.iter().enumerate() {
        for v in c {
            face_bytes.extend_from_slice(&v.to_le_bytes());
        }
        for e in edge_of[f] {
            face_bytes.extend_from_slice(&e.to_le_bytes());
        }
        for k in 0..3 {
            let a = match sides.get(&(c[(k + 1) % 3], c[k])) {
                Some(&(g, kk)) => (g << 2) | kk as u32,
                None => NONE,
            };
            face_bytes.extend_from_slice(&a.to_le_bytes());
        }
    }
    let edges = owners.len() as u32;
    let edge_bytes = owners.iter().flat_map(|o| o.to_le_bytes()).collect();
    Ok((face_bytes, edge_bytes, edges))
}

/// Bytes of a file: header, faces, edges, vertex records, colours; the checksum filled in.
#[allow(clippy::too_many_arguments)]
fn file_bytes(
    counts: Counts,
    faces: &[u8],
    edges: &[u8],
    records: &[[u8; VERTEX_SIZE]],
    colors: Option<&[[u8; 3]]>,
    hoppe: bool,
    model: &ModelBox,
) -> Vec<u8> {
    let flags = if colors.is_some() { FLAG_COLORS } else { 0 } | if hoppe { FLAG_HOPPE } else { 0 };
    let mut out = header(counts, flags, model);
    out.extend_from_slice(faces);
    out.extend_from_slice(edges);
    for r in records {
        out.extend_from_slice(r);
    }
    if let Some(c) = colors {
        for x in c {
            out.extend_from_slice(x);
        }
    }
    seal(&mut out);
    out
}

/// A header with `counts`, `flags` and `model`, the checksum not yet filled in.
pub(super) fn header(counts: Counts, flags: u16, model: &ModelBox) -> Vec<u8> {
    let mut out = vec![0u8; HEADER_SIZE];
    out[0..4].copy_from_slice(&MAGIC);
    out[4..6].copy_from_slice(&VERSION.to_le_bytes());
    out[6..8].copy_from_slice(&flags.to_le_bytes());
    for (k, v) in [
        counts.levels,
        counts.base_vertices,
        counts.base_faces,
        counts.base_edges,
    ]
    .iter()
    .enumerate()
    {
        out[8 + 4 * k..12 + 4 * k].copy_from_slice(&v.to_le_bytes());
    }
    model.write(&mut out, super::format::BOX_OFFSET);
    out
}

/// The code of a cone of half-angle `angle` (radians): its sine rounded up, 255 past a right
/// angle.
pub(super) fn cone_code(angle: f32) -> u8 {
    if angle >= core::f32::consts::FRAC_PI_2 {
        255
    } else {
        libm::ceilf(libm::sinf(angle) * 255.0).clamp(0.0, 255.0) as u8
    }
}

/// Fills in the checksum of everything after the header.
pub(super) fn seal(out: &mut [u8]) {
    let crc = crc32(&out[HEADER_SIZE..]);
    out[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
}

impl SemiRegular {
    /// A semi-regular mesh over the base mesh `faces` (counter-clockwise, a manifold with or
    /// without border, `base.len()` vertices) with `levels` subdivisions, where the vertex at
    /// weights `w` (units of `1/2^levels`, see [`Point`]) of base face `f` is at `place(f, w)`
    /// (base vertices are at `base`).
    pub fn from_fn(
        base: &[[f32; 3]],
        faces: &[[u32; 3]],
        levels: u32,
        mut place: impl FnMut(u32, [i32; 3]) -> [f32; 3],
    ) -> Result<SemiRegular, SemiRegularBuildError> {
        if levels == 0 || levels > MAX_LEVELS || base.len() >= 1 << 30 {
            return Err(SemiRegularBuildError::TooLarge);
        }
        let (face_bytes, edge_bytes, edges) = topology(base.len() as u32, faces)?;
        let counts = Counts {
            levels,
            base_vertices: base.len() as u32,
            base_faces: faces.len() as u32,
            base_edges: edges,
        };
        if counts.vertices() >= 1 << 31 {
            return Err(SemiRegularBuildError::TooLarge);
        }
        let n = counts.vertices() as usize;
        let records = vec![[0u8; VERTEX_SIZE]; n];
        let skeleton = file_bytes(
            counts,
            &face_bytes,
            &edge_bytes,
            &records,
            None,
            false,
            &ModelBox::around(core::iter::empty()),
        );
        let view =
            SemiRegularView::parse(&skeleton).map_err(|_| SemiRegularBuildError::TooLarge)?;
        let mut positions = Vec::with_capacity(n);
        positions.extend_from_slice(base);
        for v in base.len() as u32..n as u32 {
            let p = view.point(v).ok_or(SemiRegularBuildError::TooLarge)?;
            positions.push(place(p.face, p.w));
        }
        if let Some(v) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(SemiRegularBuildError::NotFinite(v as u32));
        }
        Ok(SemiRegular {
            skeleton,
            counts,
            positions,
            colors: None,
        })
    }

    /// The unit sphere as an octahedron subdivided `levels` times, each new vertex pushed out
    /// to the sphere: `8 * 4^levels` faces (8,192 at 5 levels, the paper's Fig. 11 sphere).
    pub fn sphere(levels: u32) -> Result<SemiRegular, SemiRegularBuildError> {
        let n = (1u32 << levels.min(MAX_LEVELS)) as f32;
        SemiRegular::from_fn(&OCTAHEDRON_VERTICES, &OCTAHEDRON_FACES, levels, |f, w| {
            let c = OCTAHEDRON_FACES[f as usize].map(|v| OCTAHEDRON_VERTICES[v as usize]);
            let p = interpolate(c, w, n);
            let l = crate::root::sqrtf(p.iter().map(|x| x * x).sum());
            p.map(|x| x / l)
        })
    }

    /// The base mesh `faces` over `base` subdivided `levels` times by `scheme`: midpoint
    /// subdivision keeps every level flat on the base triangles; Loop subdivision (Loop, "Smooth
    /// subdivision surfaces based on triangles", 1987) smooths every level, moving the old
    /// vertices too (borders follow the cubic B-spline rule), so the base vertices of the
    /// result sit where the finest level puts them.
    pub fn subdivide(
        base: &[[f32; 3]],
        faces: &[[u32; 3]],
        levels: u32,
        scheme: Scheme,
    ) -> Result<SemiRegular, SemiRegularBuildError> {
        let n = (1u32 << levels.min(MAX_LEVELS)) as f32;
        let mut mesh = SemiRegular::from_fn(base, faces, levels, |f, w| {
            interpolate(faces[f as usize].map(|v| base[v as usize]), w, n)
        })?;
        if scheme == Scheme::Midpoint {
            return Ok(mesh);
        }
        let view = mesh.view().ok_or(SemiRegularBuildError::TooLarge)?;
        let count = view.vertices() as usize;
        let nb = base.len();
        // The faces around each base vertex, and every vertex's level.
        let mut around: Vec<Vec<(u32, usize)>> = vec![Vec::new(); nb];
        for (f, c) in faces.iter().enumerate() {
            for (k, &v) in c.iter().enumerate() {
                around[v as usize].push((f as u32, k));
            }
        }
        let level: Vec<u32> = (0..count as u32)
            .map(|v| view.point(v).map_or(0, |p| view.level(p)))
            .collect();
        let corner = |f: u32, k: usize| {
            let mut w = [0; 3];
            w[k] = view.steps();
            Point { face: f, w }
        };
        let id_of = |p: Point| view.canonical(p).and_then(|q| view.vertex_id(q));
        let border = |p: Point, q: Point| {
            view.canonical(p.left_of(q)).is_none() || view.canonical(p.right_of(q)).is_none()
        };
        let mut pos = mesh.positions.clone();
        for j in 0..levels {
            let step = view.step_of(j);
            let mut next = pos.clone();
            for v in 0..count {
                let lv = level[v];
                if lv == j + 1 {
                    // A new vertex: 3/8 of its edge's ends and 1/8 of the far corners.
                    let Some(p) = view.point(v as u32) else {
                        continue;
                    };
                    let [x, y] = view.parent_edge(p, lv);
                    let ends = [id_of(x), id_of(y)];
                    let far = [id_of(x.left_of(y)), id_of(x.right_of(y))];
                    let at = |id: Option<u32>| id.map_or([0.0; 3], |i| pos[i as usize]);
                    let (a, b) = (at(ends[0]), at(ends[1]));
                    next[v] = match far {
                        [Some(c), Some(d)] => {
                            let (c, d) = (pos[c as usize], pos[d as usize]);
                            [0, 1, 2].map(|k| 0.375 * (a[k] + b[k]) + 0.125 * (c[k] + d[k]))
                        }
                        _ => [0, 1, 2].map(|k| 0.5 * (a[k] + b[k])),
                    };
                } else if lv <= j {
                    // An old vertex: its ring at level j.
                    let mut ring: Vec<(u32, bool)> = Vec::new();
                    let mut add = |p: Point, q: Point| {
                        if let Some(id) = id_of(q) {
                            if ring.iter().all(|&(r, _)| r != id) {
                                ring.push((id, border(p, q)));
                            }
                        }
                    };
                    if v < nb {
                        for &(f, k) in &around[v] {
                            let c = corner(f, k);
                            let toward = |m: usize| {
                                let d = c.to(corner(f, m));
                                let unit = [0, 1, 2].map(|i| d[i] / view.steps());
                                c.offset(unit, step)
                            };
                            add(c, toward((k + 1) % 3));
                            add(c, toward((k + 2) % 3));
                        }
                    } else if let Some(p) = view.point(v as u32) {
                        for d in super::lattice::DIRECTIONS {
                            add(p, p.offset(d, step));
                        }
                    }
                    let here = pos[v];
                    let edges: Vec<u32> = ring.iter().filter(|r| r.1).map(|r| r.0).collect();
                    next[v] = if edges.len() >= 2 {
                        let (a, b) = (pos[edges[0] as usize], pos[edges[1] as usize]);
                        [0, 1, 2].map(|k| 0.75 * here[k] + 0.125 * (a[k] + b[k]))
                    } else if ring.is_empty() {
                        here
                    } else {
                        let m = ring.len() as f32;
                        let c = 0.375 + 0.25 * libm::cosf(core::f32::consts::TAU / m);
                        let beta = (0.625 - c * c) / m;
                        let sum = ring.iter().fold([0.0f32; 3], |acc, &(r, _)| {
                            let q = pos[r as usize];
                            [acc[0] + q[0], acc[1] + q[1], acc[2] + q[2]]
                        });
                        [0, 1, 2].map(|k| (1.0 - m * beta) * here[k] + beta * sum[k])
                    };
                }
            }
            pos = next;
        }
        mesh.positions = pos;
        Ok(mesh)
    }

    /// The lattice of this mesh (every record zero); `from_fn` validated these bytes, so this
    /// is never `None`.
    pub(super) fn view(&self) -> Option<SemiRegularView<'_>> {
        SemiRegularView::parse(&self.skeleton).ok()
    }

    /// The file's face and edge sections.
    pub(super) fn topology_bytes(&self) -> (&[u8], &[u8]) {
        let faces_at = HEADER_SIZE;
        let edges_at = faces_at + self.counts.base_faces as usize * FACE_SIZE;
        let records_at = edges_at + self.counts.base_edges as usize * super::format::EDGE_SIZE;
        (
            &self.skeleton[faces_at..edges_at],
            &self.skeleton[edges_at..records_at],
        )
    }

    /// The header's counts.
    #[must_use]
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// The finest level as a triangle mesh over [`SemiRegular::positions`] (counter-clockwise).
    #[must_use]
    pub fn finest_triangles(&self) -> Vec<[u32; 3]> {
        self.view()
            .map_or_else(Vec::new, |view| finest_triangles(&view))
    }

    /// The file: positions quantized over the bounding box, normals, and every wavelet's bounds
    /// (see the module documentation), with the error bounded by the spheroid.
    pub fn to_bytes(&self) -> Result<Vec<u8>, SemiRegularBuildError> {
        self.to_bytes_with(Bound::Spheroid)
    }

    /// [`SemiRegular::to_bytes`] with the error bounded by `bound`.
    pub fn to_bytes_with(&self, bound: Bound) -> Result<Vec<u8>, SemiRegularBuildError> {
        let view = self.view().ok_or(SemiRegularBuildError::TooLarge)?;
        let counts = view.counts();
        let n = counts.vertices() as usize;
        if self.positions.len() != n {
            return Err(SemiRegularBuildError::Count {
                given: self.positions.len(),
                needed: n,
            });
        }
        if let Some(c) = &self.colors {
            if c.len() != n {
                return Err(SemiRegularBuildError::Count {
                    given: c.len(),
                    needed: n,
                });
            }
        }
        let model = ModelBox::around(self.positions.iter().copied());
        let (face_bytes, edge_bytes) = self.topology_bytes();
        // Quantized positions first: every bound is measured on what the file will hold.
        let quantized: Vec<[u16; 3]> = self.positions.iter().map(|&p| model.quantize(p)).collect();
        let positions: Vec<[f32; 3]> = quantized.iter().map(|&q| model.dequantize(q)).collect();
        let mut records: Vec<[u8; VERTEX_SIZE]> = quantized
            .iter()
            .map(|q| {
                let mut r = [0u8; VERTEX_SIZE];
                for k in 0..3 {
                    r[2 * k..2 * k + 2].copy_from_slice(&q[k].to_le_bytes());
                }
                r
            })
            .collect();
        let normals = vertex_normals(&view, &positions);
        for (r, nrm) in records.iter_mut().zip(&normals) {
            let (x, y) = oct_encode(*nrm);
            r[6] = x as u8;
            r[7] = y as u8;
        }
        let axes: Vec<[f32; 3]> = records
            .iter()
            .map(|r| oct_decode(r[6] as i8, r[7] as i8))
            .collect();
        let mut bounds = wavelet_bounds(&view, &positions, &axes);
        monotonic(&view, &positions, &axes, &mut bounds);
        let base = counts.base_vertices as usize;
        for (k, b) in bounds.iter().enumerate() {
            let r = &mut records[base + k];
            r[8] = encode_length(b.radius / model.unit());
            let (a, bb) = match bound {
                Bound::Spheroid => (b.a, b.b),
                Bound::Hoppe => (b.delta, b.mu),
            };
            r[9] = encode_length(a / model.unit());
            r[10] = encode_length(bb / model.unit());
            r[11] = cone_code(b.cone);
        }
        Ok(file_bytes(
            counts,
            face_bytes,
            edge_bytes,
            &records,
            self.colors.as_deref(),
            bound == Bound::Hoppe,
            &model,
        ))
    }
}

/// The finest level of the file `view` as a triangle mesh over its vertex ids
/// (counter-clockwise): what a full-detail picture of a `.vdw` file draws.
#[must_use]
pub fn finest_triangles(view: &SemiRegularView<'_>) -> Vec<[u32; 3]> {
    let faces = usize::try_from(view.counts().finest_faces()).unwrap_or(0);
    let mut out = Vec::with_capacity(faces);
    for_finest_triangles(view, |_, t| out.push(t));
    out
}

/// Calls `f(face, triangle)` for every triangle of `K^J` (vertex ids, counter-clockwise), face
/// by face, rows of increasing `j`.
fn for_finest_triangles(view: &SemiRegularView<'_>, mut f: impl FnMut(u32, [u32; 3])) {
    let n = view.steps();
    for face in 0..view.counts().base_faces {
        let id = |i: i32, j: i32| {
            view.vertex_id(Point {
                face,
                w: [n - i - j, i, j],
            })
            .unwrap_or(0)
        };
        for j in 0..n {
            for i in 0..n - j {
                f(face, [id(i, j), id(i + 1, j), id(i, j + 1)]);
                if i + j + 2 <= n {
                    f(face, [id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f32; 3]) -> f32 {
    crate::root::sqrtf(dot(a, a))
}

fn unit(a: [f32; 3]) -> [f32; 3] {
    let l = norm(a);
    if l > 0.0 && l.is_finite() {
        a.map(|x| x / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Area-weighted vertex normals of the finest level.
fn vertex_normals(view: &SemiRegularView<'_>, positions: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![[0.0f32; 3]; positions.len()];
    for_finest_triangles(view, |_, t| {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let n = cross(sub(b, a), sub(c, a));
        for v in t {
            for k in 0..3 {
                acc[v as usize][k] += n[k];
            }
        }
    });
    acc.into_iter().map(unit).collect()
}

/// One wavelet's bounds before encoding.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct WaveletBounds {
    pub(super) radius: f32,
    pub(super) a: f32,
    pub(super) b: f32,
    /// Hoppe's `delta` (largest error along the normal) and `mu` (largest across it).
    pub(super) delta: f32,
    pub(super) mu: f32,
    /// Cone half-angle in radians.
    pub(super) cone: f32,
}

/// How a wavelet relates to the one being bounded.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kin {
    /// It, or a descendant: out when it is out.
    Out,
    /// An ancestor: in whenever it is tested.
    In,
    /// Anything else: in or out.
    Either,
}

/// The bounds of every wavelet (index = vertex id - base vertices).
pub(super) fn wavelet_bounds(
    view: &SemiRegularView<'_>,
    positions: &[[f32; 3]],
    axes: &[[f32; 3]],
) -> Vec<WaveletBounds> {
    let c = view.counts();
    let base = c.base_vertices;
    // Coefficients: a wavelet's position minus its parent edge's midpoint.
    let coefficient: Vec<[f32; 3]> = (base..view.vertices())
        .map(|v| {
            let p = view.point(v).unwrap_or(Point { face: 0, w: [0; 3] });
            let [x, y] = view.parent_edge(p, view.level(p));
            let pos = |q: Point| {
                view.vertex_id(q)
                    .map_or([0.0; 3], |id| positions[id as usize])
            };
            let (px, py) = (pos(x), pos(y));
            let m = [0, 1, 2].map(|k| (px[k] + py[k]) * 0.5);
            sub(positions[v as usize], m)
        })
        .collect();
    let levels = c.levels;
    (base..view.vertices())
        .map(|v| {
            let Some(m) = view.point(v) else {
                return WaveletBounds::default();
            };
            let level = view.level(m);
            let s = view.step_of(level);
            let center = positions[v as usize];
            let axis = axes[v as usize];
            let mut out = WaveletBounds::default();
            let mut worst: Vec<(f32, f32)> = Vec::new();
            // Every finest triangle of the support (by its lower-left lattice point), for the
            // cone of normals.
            for dj in -s - 1..=s {
                for di in -s - 1..=s {
                    let q = m.offset([-1, 1, 0], di).offset([-1, 0, 1], dj);
                    let right = q.offset([-1, 1, 0], 1);
                    let up = q.offset([-1, 0, 1], 1);
                    for t in [[q, right, up], [right, right.offset([-1, 0, 1], 1), up]] {
                        if t.iter().any(|&x| hex_len(m.to(x)) > s) {
                            continue;
                        }
                        let ids = t.map(|x| view.canonical(x).and_then(|x| view.vertex_id(x)));
                        let [Some(a), Some(b), Some(cc)] = ids else {
                            continue;
                        };
                        let [a, b, cc] = [a, b, cc].map(|k| positions[k as usize]);
                        let nrm = unit(cross(sub(b, a), sub(cc, a)));
                        let cos = dot(nrm, axis).clamp(-1.0, 1.0);
                        out.cone = out.cone.max(libm::acosf(cos));
                    }
                }
            }
            // Every finest point of the support, in the wavelet's frame.
            for dj in -s..=s {
                for di in -s..=s {
                    if hex_len([-di - dj, di, dj]) > s {
                        continue;
                    }
                    let q = m.offset([-1, 1, 0], di).offset([-1, 0, 1], dj);
                    let Some(qc) = view.canonical(q) else {
                        continue;
                    };
                    let Some(qid) = view.vertex_id(qc) else {
                        continue;
                    };
                    let pq = positions[qid as usize];
                    out.radius = out.radius.max(norm(sub(pq, center)));
                    // The error at q: what the wavelet and its descendants carry, plus what
                    // the others may or may not.
                    let mut out_part = [0.0f32; 3];
                    let mut either: Vec<[f32; 3]> = Vec::new();
                    for l in 1..=levels {
                        let sl = view.step_of(l);
                        for (corner, weight) in containing(q, sl) {
                            let Some(cc) = view.canonical(corner) else {
                                continue;
                            };
                            if view.level(cc) != l || weight == 0 {
                                continue;
                            }
                            let Some(id) = view.vertex_id(cc) else {
                                continue;
                            };
                            let contrib = coefficient[(id - base) as usize]
                                .map(|x| x * weight as f32 / sl as f32);
                            let kin = if id == v || (l > level && hex_len(m.to(corner)) + sl <= s) {
                                Kin::Out
                            } else if l < level {
                                Kin::In
                            } else {
                                Kin::Either
                            };
                            match kin {
                                Kin::Out => {
                                    for k in 0..3 {
                                        out_part[k] += contrib[k];
                                    }
                                }
                                Kin::In => {}
                                Kin::Either => either.push(contrib),
                            }
                        }
                    }
                    worst_case(out_part, &either, axis, &mut worst);
                }
            }
            [out.delta, out.mu] = hoppe(&worst);
            [out.a, out.b] = equation3(&worst);
            out
        })
        .collect()
}

/// Candidates beyond which [`worst_case`] bounds the error set by a box instead of listing it.
const MAX_LISTED: usize = 10;

/// Appends to `worst` the (along, across) lengths of the error vectors `fixed + sum(S)` for
/// every subset `S` of `either`: their convex hull holds every error the cut can show, and a
/// spheroid that holds those points holds the hull. With more than [`MAX_LISTED`] candidates,
/// one point instead: the extremes along the normal (exact) and across it (the lengths added).
fn worst_case(fixed: [f32; 3], either: &[[f32; 3]], axis: [f32; 3], worst: &mut Vec<(f32, f32)>) {
    if either.len() <= MAX_LISTED {
        for mask in 0u32..1 << either.len() {
            let mut e = fixed;
            for (k, c) in either.iter().enumerate() {
                if mask >> k & 1 == 1 {
                    for i in 0..3 {
                        e[i] += c[i];
                    }
                }
            }
            worst.push((dot(e, axis).abs(), norm(cross(e, axis))));
        }
        return;
    }
    let along = dot(fixed, axis);
    let (lo, hi) = either.iter().fold((along, along), |(lo, hi), c| {
        let x = dot(*c, axis);
        (lo + x.min(0.0), hi + x.max(0.0))
    });
    let across = either.iter().fold(norm(cross(fixed, axis)), |acc, c| {
        acc + norm(cross(*c, axis))
    });
    worst.push((lo.abs().max(hi.abs()), across));
}

/// The corners of the lattice triangle of step `s` holding `q` (same frame), each with `q`'s
/// weight on it in units of `1/s` (the three sum to `s`).
fn containing(q: Point, s: i32) -> [(Point, i32); 3] {
    let (i, j) = (q.w[1], q.w[2]);
    let (ci, cj) = (i.div_euclid(s), j.div_euclid(s));
    let (fi, fj) = (i - ci * s, j - cj * s);
    let at = |a: i32, b: i32| Point {
        face: q.face,
        w: [q.w[0] + i + j - a * s - b * s, a * s, b * s],
    };
    if fi + fj <= s {
        [
            (at(ci, cj), s - fi - fj),
            (at(ci + 1, cj), fi),
            (at(ci, cj + 1), fj),
        ]
    } else {
        [
            (at(ci + 1, cj + 1), fi + fj - s),
            (at(ci, cj + 1), s - fi),
            (at(ci + 1, cj), s - fj),
        ]
    }
}

/// Makes bounds monotonic down the dependency graph, finest level first.
pub(super) fn monotonic(
    view: &SemiRegularView<'_>,
    positions: &[[f32; 3]],
    axes: &[[f32; 3]],
    bounds: &mut [WaveletBounds],
) {
    let base = view.counts().base_vertices;
    let mut order: Vec<(u32, u32)> = (base..view.vertices())
        .filter_map(|v| view.point(v).map(|p| (view.level(p), v)))
        .collect();
    order.sort_unstable_by(|a, b| b.cmp(a));
    for (level, v) in order {
        let Some(p) = view.point(v) else { continue };
        let child = bounds[(v - base) as usize];
        for q in view.parents(p, level) {
            if q == NONE {
                continue;
            }
            let gap = norm(sub(positions[v as usize], positions[q as usize]));
            let turn = libm::acosf(dot(axes[v as usize], axes[q as usize]).clamp(-1.0, 1.0));
            let parent = &mut bounds[(q - base) as usize];
            parent.radius = parent.radius.max(gap + child.radius);
            parent.a = parent.a.max(child.a);
            parent.b = parent.b.max(child.b);
            parent.delta = parent.delta.max(child.delta);
            parent.mu = parent.mu.max(child.mu);
            parent.cone = parent.cone.max(turn + child.cone);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wavelet::lattice::Site;

    #[test]
    fn vertex_ids_and_points_round_trip() {
        let s = SemiRegular::sphere(3).unwrap();
        let view = s.view().unwrap();
        assert_eq!(view.vertices(), 6 + 12 * 7 + 8 * 21);
        for v in 6..view.vertices() {
            let p = view.point(v).unwrap();
            assert_eq!(view.vertex_id(p), Some(v), "{p:?}");
            assert!(matches!(view.site(p), Site::Edge(..) | Site::Inner));
        }
    }

    #[test]
    fn loop_subdivision_smooths_an_octahedron_towards_a_sphere() {
        let (base, faces) = (OCTAHEDRON_VERTICES, OCTAHEDRON_FACES);
        let spread = |m: &SemiRegular| {
            let r: Vec<f32> = m.positions.iter().map(|&p| norm(p)).collect();
            let (lo, hi) = r
                .iter()
                .fold((f32::MAX, 0.0f32), |(a, b), &x| (a.min(x), b.max(x)));
            hi / lo
        };
        let flat = SemiRegular::subdivide(&base, &faces, 3, Scheme::Midpoint).unwrap();
        let smooth = SemiRegular::subdivide(&base, &faces, 3, Scheme::Loop).unwrap();
        // The flat octahedron's radii range over 1/sqrt(3) .. 1; Loop's are within a few %.
        assert!(spread(&flat) > 1.7);
        assert!(spread(&smooth) < 1.1, "{}", spread(&smooth));
        // Symmetric: the six base vertices stay on their axes at one radius.
        let r0 = norm(smooth.positions[0]);
        for v in 0..6 {
            assert!((norm(smooth.positions[v]) - r0).abs() < 1e-5);
        }
        smooth.to_bytes().unwrap();
    }

    #[test]
    fn the_sphere_has_the_papers_face_count() {
        let s = SemiRegular::sphere(5).unwrap();
        assert_eq!(s.finest_triangles().len(), 8192);
        assert_eq!(s.counts().finest_faces(), 8192);
    }
}
