//! Loading triangle meshes from OBJ files into plain indexed arrays.
//!
//! OBJ text is parsed by `tobj`; this module turns its output into one [`IndexedMesh`] (all objects
//! of the file merged, polygons fan-triangulated, positions indexed by position only so that
//! connectivity survives for the hierarchy builder), checks it, and computes vertex normals from the
//! geometry. Every problem becomes a [`MeshError`] naming the file, never a panic.

use std::fmt;
use std::io::BufRead;
use std::path::Path;

use glam::Vec3;

/// The Stanford bunny (37,706 vertices, 75,408 triangles), bundled so the demo runs anywhere.
pub const BUNNY_OBJ: &[u8] = include_bytes!("../../fixtures/bunny.obj");
/// Name under which the bundled bunny appears in messages.
pub const BUNNY_NAME: &str = "fixtures/bunny.obj (bundled)";
/// The cow of CGAL's data set (2,904 vertices, 5,804 triangles): a small closed mesh for fast tests.
pub const COW_OBJ: &[u8] = include_bytes!("../../fixtures/cow.obj");
/// Name under which the bundled cow appears in messages.
pub const COW_NAME: &str = "fixtures/cow.obj (bundled)";

/// An indexed triangle mesh with per-vertex normals and optional per-vertex colours.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, area-weighted from the incident triangles (zero for isolated vertices).
    pub normals: Vec<[f32; 3]>,
    /// Vertex colours, when the file has them (`v x y z r g b`).
    pub colors: Option<Vec<[u8; 3]>>,
    /// Triangles, counter-clockwise seen from the outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Axis-aligned bounds of a point set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Smallest coordinates.
    pub min: Vec3,
    /// Largest coordinates.
    pub max: Vec3,
}

impl Bounds {
    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the diagonal: the radius of a sphere around [`Bounds::center`] holding the box.
    pub fn radius(&self) -> f32 {
        (self.max - self.min).length() * 0.5
    }
}

impl IndexedMesh {
    /// Bounds of the positions (a degenerate box at the origin for an empty mesh).
    pub fn bounds(&self) -> Bounds {
        let mut it = self.positions.iter().map(|p| Vec3::from(*p));
        let first = it.next().unwrap_or(Vec3::ZERO);
        let (min, max) = it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
        Bounds { min, max }
    }

    /// Reorders triangles along a Morton (Z-order) curve through their centroids and renumbers the
    /// vertices in order of first use.
    ///
    /// The drawn image does not change (but for which of two triangles at exactly equal depth
    /// wins), while neighbouring triangles come to share cache lines: scanned meshes such as the
    /// bunny list their triangles in no spatial order, and a renderer then spends much of its time
    /// waiting for vertex data. Deterministic: ties keep the file order.
    pub fn reorder_for_locality(&mut self) {
        let bounds = self.bounds();
        let extent = (bounds.max - bounds.min).max(Vec3::splat(f32::MIN_POSITIVE));
        let mut keyed: Vec<(u32, [u32; 3])> = self
            .triangles
            .iter()
            .map(|t| {
                let c = t.iter().fold(Vec3::ZERO, |acc, &i| {
                    acc + Vec3::from(self.positions[i as usize])
                }) / 3.0;
                let q = ((c - bounds.min) / extent * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
                (morton3(q.x as u32, q.y as u32, q.z as u32), *t)
            })
            .collect();
        keyed.sort_by_key(|&(key, _)| key); // stable
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut order = Vec::with_capacity(self.positions.len());
        for (_, t) in &keyed {
            for &i in t {
                if new_index[i as usize] == u32::MAX {
                    new_index[i as usize] = order.len() as u32;
                    order.push(i as usize);
                }
            }
        }
        for (i, slot) in new_index.iter_mut().enumerate() {
            if *slot == u32::MAX {
                *slot = order.len() as u32;
                order.push(i);
            }
        }
        self.triangles = keyed
            .iter()
            .map(|(_, t)| t.map(|i| new_index[i as usize]))
            .collect();
        self.positions = order.iter().map(|&i| self.positions[i]).collect();
        self.normals = order.iter().map(|&i| self.normals[i]).collect();
        if let Some(colors) = &self.colors {
            self.colors = Some(order.iter().map(|&i| colors[i]).collect());
        }
    }

    /// Borrows the mesh for the rasterizer.
    pub fn as_raster_mesh(&self) -> vdlod_raster::Mesh<'_> {
        vdlod_raster::Mesh {
            positions: &self.positions,
            normals: Some(&self.normals),
            colors: self.colors.as_deref(),
            triangles: &self.triangles,
            face_colors: None,
        }
    }
}

/// What is wrong with a mesh file.
#[derive(Debug)]
pub enum MeshProblem {
    /// The file could not be read.
    Io(std::io::Error),
    /// `tobj` rejected the text.
    Malformed(tobj::LoadError),
    /// The file has no vertices.
    NoVertices,
    /// The file has vertices but no faces with three or more corners.
    NoTriangles,
    /// A vertex has a NaN or infinite coordinate.
    NonFinite {
        /// Zero-based vertex number in the file.
        vertex: usize,
    },
    /// More vertices than 32-bit indices can address.
    TooLarge,
}

impl fmt::Display for MeshProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshProblem::Io(e) => write!(f, "cannot read: {e}"),
            MeshProblem::Malformed(tobj::LoadError::FaceVertexOutOfBounds) => {
                write!(f, "malformed OBJ: a face uses a vertex index out of range")
            }
            MeshProblem::Malformed(e) => write!(f, "malformed OBJ: {e}"),
            MeshProblem::NoVertices => write!(f, "no vertices"),
            MeshProblem::NoTriangles => {
                write!(
                    f,
                    "no triangles (only points, lines or faces of fewer than 3 vertices)"
                )
            }
            MeshProblem::NonFinite { vertex } => {
                write!(f, "vertex {} has a NaN or infinite coordinate", vertex + 1)
            }
            MeshProblem::TooLarge => write!(f, "more than 2^32 vertices"),
        }
    }
}

/// A [`MeshProblem`] and the file it is about.
#[derive(Debug)]
pub struct MeshError {
    /// The file as the user named it.
    pub file: String,
    /// What is wrong.
    pub problem: MeshProblem,
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file, self.problem)
    }
}

impl std::error::Error for MeshError {}

/// Loads an OBJ file.
pub fn load_obj(path: &Path) -> Result<IndexedMesh, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError {
        file: file.clone(),
        problem: MeshProblem::Io(e),
    })?;
    load_obj_bytes(&file, &bytes)
}

/// Loads OBJ text held in memory; `name` is used in error messages.
///
/// ```
/// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
/// let mesh = vdlod_demo::mesh::load_obj_bytes("tri.obj", obj).unwrap();
/// assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
/// assert_eq!(mesh.normals[0], [0.0, 0.0, 1.0]);
/// ```
pub fn load_obj_bytes(name: &str, bytes: &[u8]) -> Result<IndexedMesh, MeshError> {
    let err = |problem| MeshError {
        file: name.to_string(),
        problem,
    };
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let text = without_polylines(bytes);
    let mut reader: &mut dyn BufRead = &mut &text[..];
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| err(MeshProblem::Malformed(e)))?;

    let mut mesh = IndexedMesh::default();
    let mut colors = Vec::new();
    let mut any_colors = false;
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        let count = m.positions.len() / 3;
        for (i, p) in m.positions.chunks_exact(3).enumerate() {
            let p = [p[0], p[1], p[2]];
            if !p.iter().all(|c| c.is_finite()) {
                return Err(err(MeshProblem::NonFinite { vertex: base + i }));
            }
            mesh.positions.push(p);
        }
        if m.vertex_color.len() == m.positions.len() && !m.vertex_color.is_empty() {
            any_colors = true;
            let channel = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            colors.extend(
                m.vertex_color
                    .chunks_exact(3)
                    .map(|c| [channel(c[0]), channel(c[1]), channel(c[2])]),
            );
        } else {
            colors.extend(std::iter::repeat_n([255u8; 3], count));
        }
        let base = u32::try_from(base).map_err(|_| err(MeshProblem::TooLarge))?;
        for t in m.indices.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for (out, &i) in tri.iter_mut().zip(t) {
                if i as usize >= count {
                    return Err(err(MeshProblem::Malformed(
                        tobj::LoadError::FaceVertexOutOfBounds,
                    )));
                }
                *out = base + i;
            }
            mesh.triangles.push(tri);
        }
    }
    if mesh.triangles.is_empty() {
        // tobj keeps only the vertices that faces use; look at the text to tell the two apart.
        let declares_vertices = bytes
            .split(|&b| b == b'\n')
            .any(|line| line.trim_ascii_start().starts_with(b"v "));
        return Err(err(if declares_vertices {
            MeshProblem::NoTriangles
        } else {
            MeshProblem::NoVertices
        }));
    }
    if u32::try_from(mesh.positions.len()).is_err() {
        return Err(err(MeshProblem::TooLarge));
    }
    if any_colors {
        mesh.colors = Some(colors);
    }
    mesh.normals = vertex_normals(&mesh.positions, &mesh.triangles);
    Ok(mesh)
}

impl IndexedMesh {
    /// One step of Loop subdivision: every triangle becomes four, vertices move to the Loop
    /// averages (borders use the cubic B-spline rule), so a smooth surface gets four times the
    /// triangles. Stands in for the merge-tree paper's 160k-face subdivided bunny.
    pub fn loop_subdivide(&self) -> IndexedMesh {
        use std::collections::HashMap;
        let n = self.positions.len();
        let p = |i: u32| Vec3::from(self.positions[i as usize]);
        // Opposite corners of each undirected edge, in first-seen order.
        let mut edges: HashMap<(u32, u32), (u32, [u32; 2])> = HashMap::new();
        let mut order = Vec::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let key = (a.min(b), a.max(b));
                let next = (n + order.len()) as u32;
                let entry = edges.entry(key).or_insert_with(|| {
                    order.push(key);
                    (next, [c, u32::MAX])
                });
                if entry.1[0] != c {
                    entry.1[1] = c;
                }
            }
        }
        let mut positions = Vec::with_capacity(n + order.len());
        // Old vertices: neighbour sums, and border neighbours.
        let mut ring_sum = vec![Vec3::ZERO; n];
        let mut ring_len = vec![0u32; n];
        let mut border: Vec<Vec<u32>> = vec![Vec::new(); n];
        for &(a, b) in &order {
            let (_, opp) = edges[&(a, b)];
            ring_sum[a as usize] += p(b);
            ring_sum[b as usize] += p(a);
            ring_len[a as usize] += 1;
            ring_len[b as usize] += 1;
            if opp[1] == u32::MAX {
                border[a as usize].push(b);
                border[b as usize].push(a);
            }
        }
        for v in 0..n {
            let old = p(v as u32);
            let moved = if border[v].len() == 2 {
                old * 0.75 + (p(border[v][0]) + p(border[v][1])) * 0.125
            } else if ring_len[v] >= 3 && border[v].is_empty() {
                let k = ring_len[v] as f32;
                let beta = if ring_len[v] == 3 {
                    3.0 / 16.0
                } else {
                    3.0 / (8.0 * k)
                };
                old * (1.0 - k * beta) + ring_sum[v] * beta
            } else {
                old
            };
            positions.push(moved.to_array());
        }
        for &(a, b) in &order {
            let (_, opp) = edges[&(a, b)];
            let mid = if opp[1] == u32::MAX {
                (p(a) + p(b)) * 0.5
            } else {
                (p(a) + p(b)) * 0.375 + (p(opp[0]) + p(opp[1])) * 0.125
            };
            positions.push(mid.to_array());
        }
        let e = |a: u32, b: u32| edges[&(a.min(b), a.max(b))].0;
        let mut triangles = Vec::with_capacity(self.triangles.len() * 4);
        for &[a, b, c] in &self.triangles {
            let (ab, bc, ca) = (e(a, b), e(b, c), e(c, a));
            triangles.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        let normals = vertex_normals(&positions, &triangles);
        IndexedMesh {
            positions,
            normals,
            colors: None,
            triangles,
        }
    }
}

/// Whether an OBJ line is a polyline (`l v1 v2 ...`).
fn is_polyline(line: &[u8]) -> bool {
    let line = line.trim_ascii_start();
    line.first() == Some(&b'l') && line.get(1).is_none_or(|c| c.is_ascii_whitespace())
}

/// The text with polyline statements removed: tobj reads `l a b c` as a triangle, but a polyline
/// has no surface.
fn without_polylines(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    if !bytes.split(|&b| b == b'\n').any(is_polyline) {
        return std::borrow::Cow::Borrowed(bytes);
    }
    let mut out = Vec::with_capacity(bytes.len());
    for line in bytes.split(|&b| b == b'\n') {
        if !is_polyline(line) {
            out.extend_from_slice(line);
        }
        out.push(b'\n');
    }
    std::borrow::Cow::Owned(out)
}

/// Interleaves the low 10 bits of three coordinates.
fn morton3(x: u32, y: u32, z: u32) -> u32 {
    fn spread(mut v: u32) -> u32 {
        v &= 0x3FF;
        v = (v | (v << 16)) & 0x0300_00FF;
        v = (v | (v << 8)) & 0x0300_F00F;
        v = (v | (v << 4)) & 0x030C_30C3;
        (v | (v << 2)) & 0x0924_9249
    }
    spread(x) | (spread(y) << 1) | (spread(z) << 2)
}

/// Area-weighted unit vertex normals; zero where the incident area is zero.
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| Vec3::from(positions[i as usize]));
        let n = (b - a).cross(c - a);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    acc.into_iter()
        .map(|n| {
            let len = libm::sqrtf(n.dot(n));
            if len > 0.0 && len.is_finite() {
                (n / len).to_array()
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn quad_is_fan_triangulated() {
        let m =
            load_obj_bytes("q.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.colors.is_none());
        let b = m.bounds();
        assert_eq!(b.center(), Vec3::new(0.5, 0.5, 0.0));
    }

    #[test]
    fn reads_vertex_colours() {
        let m = load_obj_bytes(
            "c.obj",
            b"v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(m.colors, Some(vec![[255, 0, 0], [0, 255, 0], [0, 0, 255]]));
    }

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton3(1, 0, 0), 1);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 4);
        assert_eq!(morton3(3, 0, 0), 0b1001);
        assert_eq!(morton3(1023, 1023, 1023), (1 << 30) - 1);
    }

    type Bits = [u32; 3];

    /// Triangles as position bits, and vertices as position-and-normal bits: what reordering
    /// must keep, whatever the numbering.
    fn content(m: &IndexedMesh) -> (BTreeSet<[Bits; 3]>, BTreeSet<[Bits; 2]>) {
        let bits = |v: &[f32; 3]| v.map(f32::to_bits);
        let triangles = m
            .triangles
            .iter()
            .map(|t| t.map(|i| bits(&m.positions[i as usize])))
            .collect();
        let vertices = m
            .positions
            .iter()
            .zip(&m.normals)
            .map(|(p, n)| [bits(p), bits(n)])
            .collect();
        (triangles, vertices)
    }

    #[test]
    fn reordering_keeps_the_same_triangles() {
        let mut m = load_obj_bytes(COW_NAME, COW_OBJ).unwrap();
        let before = content(&m);
        m.reorder_for_locality();
        assert_eq!(before, content(&m));
        assert_eq!(before.0.len(), m.triangles.len());
        // First uses come in order: vertex k is first referenced before vertex k + 1.
        let mut next = 0;
        for &i in m.triangles.iter().flatten() {
            assert!(i <= next);
            if i == next {
                next += 1;
            }
        }
    }

    #[test]
    fn loop_subdivision_quadruples_triangles() {
        let cow = load_obj_bytes(COW_NAME, COW_OBJ).unwrap();
        let fine = cow.loop_subdivide();
        assert_eq!(fine.triangles.len(), 4 * cow.triangles.len());
        // Closed: V - E + F stays 2, so V grows by E = 3F / 2.
        assert_eq!(
            fine.positions.len(),
            cow.positions.len() + cow.triangles.len() * 3 / 2
        );
        assert!(fine.positions.iter().flatten().all(|c| c.is_finite()));
    }

    #[test]
    fn bundled_bunny_loads() {
        let m = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
        assert_eq!(m.positions.len(), 37_706);
        assert_eq!(m.triangles.len(), 75_408);
    }
}
