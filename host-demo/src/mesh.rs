//! Triangle meshes as plain indexed arrays, loaded from files.
//!
//! [`load`] reads any format [`crate::input`] knows, turns the Z axis up if asked, repairs the
//! mesh ([`crate::repair`]) or, when strict, rejects what the builder would, and computes vertex
//! normals from the geometry. Every problem becomes a [`MeshError`] naming the file and its
//! format, never a panic.

use std::fmt;
use std::path::Path;

use glam::Vec3;
use vdlod_core::build::BuildError;

use crate::input::{self, Detected, Format, ReadError, Soup};
use crate::repair::Repairs;

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
            uvs: None,
        }
    }
}

/// Which way is up in a mesh file. The demo's cameras orbit around +Y.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// +Y is up (OBJ's usual convention): coordinates are used as they are.
    #[default]
    Y,
    /// +Z is up (CAD and many scanners): turned a quarter about X so +Z becomes +Y.
    Z,
}

/// How [`load`] reads a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Repair the mesh ([`crate::repair`]); when false, reject what the builder would reject.
    pub repair: bool,
    /// The file's up axis.
    pub up: Up,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            repair: true,
            up: Up::Y,
        }
    }
}

/// What is wrong with a mesh file.
#[derive(Debug)]
pub enum MeshProblem {
    /// The file could not be read.
    Io(std::io::Error),
    /// Neither the content nor the extension says which format the file is.
    UnknownFormat,
    /// The file is one of vdlod's own, which hold no mesh to read.
    NotAMesh(&'static str),
    /// The reader stopped.
    Read(ReadError),
    /// The file has no vertices.
    NoVertices,
    /// The file has vertices but no faces with three or more corners.
    NoTriangles,
    /// More vertices than the builder can address.
    TooLarge,
    /// Without repair: the mesh is not one the builder accepts.
    Invalid(BuildError),
}

impl fmt::Display for MeshProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshProblem::Io(e) => write!(f, "cannot read: {e}"),
            MeshProblem::UnknownFormat => write!(
                f,
                "not a mesh format vdlod reads (OBJ, OFF, PLY, STL; found by content or extension)"
            ),
            MeshProblem::NotAMesh(what) => write!(
                f,
                "this is {what}, not a mesh; `orbit` and `render` take .vdh files, `info` takes both"
            ),
            MeshProblem::Read(e) => write!(f, "{e}"),
            MeshProblem::NoVertices => write!(f, "no vertices"),
            MeshProblem::NoTriangles => {
                write!(
                    f,
                    "no triangles (only points, lines or faces of fewer than 3 vertices)"
                )
            }
            MeshProblem::TooLarge => write!(f, "more than 2^31 vertices"),
            MeshProblem::Invalid(e) => write!(f, "{e} (--strict: not repaired)"),
        }
    }
}

/// A [`MeshProblem`], the file it is about and, once known, its format.
#[derive(Debug)]
pub struct MeshError {
    /// The file as the user named it.
    pub file: String,
    /// The file's format, when it was found.
    pub format: Option<Format>,
    /// What is wrong.
    pub problem: MeshProblem,
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.format {
            Some(format) => write!(f, "{}: {format}: {}", self.file, self.problem),
            None => write!(f, "{}: {}", self.file, self.problem),
        }
    }
}

impl std::error::Error for MeshError {}

/// A mesh read from a file, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Loaded {
    /// The mesh, ready for the builder.
    pub mesh: IndexedMesh,
    /// The file's format.
    pub format: Format,
    /// What repair changed (`None` when repair was off).
    pub repairs: Option<Repairs>,
}

/// Loads a mesh file of any format vdlod reads.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Loaded, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError {
        file: file.clone(),
        format: None,
        problem: MeshProblem::Io(e),
    })?;
    load_bytes(&file, &bytes, options)
}

/// Loads mesh bytes held in memory; `name` is used in messages, and its extension when the
/// content does not tell the format.
///
/// ```
/// use vdlod_demo::mesh::{load_bytes, LoadOptions};
/// // An OFF square whose second triangle is listed the wrong way round.
/// let off = b"OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 3 2\n";
/// let loaded = load_bytes("square.off", off, &LoadOptions::default()).unwrap();
/// assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
/// assert_eq!(loaded.repairs.unwrap().to_string(), "1 triangle flipped");
/// let strict = LoadOptions { repair: false, ..LoadOptions::default() };
/// let e = load_bytes("square.off", off, &strict).unwrap_err();
/// assert_eq!(
///     e.to_string(),
///     "square.off: OFF: the two triangles on edge 0-2 are oriented inconsistently (--strict: not repaired)"
/// );
/// ```
pub fn load_bytes(name: &str, bytes: &[u8], options: &LoadOptions) -> Result<Loaded, MeshError> {
    let format = match input::detect(name, bytes) {
        Detected::Mesh(format) => format,
        Detected::Vdlod(what) => return Err(error(name, None, MeshProblem::NotAMesh(what))),
        Detected::Unknown => return Err(error(name, None, MeshProblem::UnknownFormat)),
    };
    let err = |problem| error(name, Some(format), problem);
    let mut soup = read_soup(name, format, bytes)?;
    if options.up == Up::Z {
        for p in &mut soup.positions {
            *p = [p[0], p[2], -p[1]];
        }
    }
    let vertices = soup.positions.len();
    soup.drop_unused();
    let unused = vertices - soup.positions.len();
    let repairs = if options.repair {
        let (repaired, mut repairs) = crate::repair::repair(soup);
        repairs.unused += unused;
        soup = repaired;
        Some(repairs)
    } else {
        let input = vdlod_core::build::InputMesh {
            positions: &soup.positions,
            colors: soup.colors.as_deref(),
            triangles: &soup.triangles,
        };
        vdlod_core::build::validate(&input).map_err(|e| err(MeshProblem::Invalid(e)))?;
        None
    };
    if soup.triangles.is_empty() {
        return Err(err(MeshProblem::NoTriangles));
    }
    Ok(Loaded {
        mesh: soup.into(),
        format,
        repairs,
    })
}

/// Reads `bytes` as `format`: a soup with at least one triangle and addressable vertices.
fn read_soup(name: &str, format: Format, bytes: &[u8]) -> Result<Soup, MeshError> {
    let err = |problem| error(name, Some(format), problem);
    let soup = input::read(format, bytes).map_err(|e| err(MeshProblem::Read(e)))?;
    if soup.triangles.is_empty() {
        return Err(err(if soup.positions.is_empty() {
            MeshProblem::NoVertices
        } else {
            MeshProblem::NoTriangles
        }));
    }
    if soup.positions.len() >= 1 << 31 {
        return Err(err(MeshProblem::TooLarge));
    }
    Ok(soup)
}

impl From<Soup> for IndexedMesh {
    /// The soup as it is, with vertex normals computed.
    fn from(soup: Soup) -> IndexedMesh {
        let normals = vertex_normals(&soup.positions, &soup.triangles);
        IndexedMesh {
            positions: soup.positions,
            normals,
            colors: soup.colors,
            triangles: soup.triangles,
        }
    }
}

fn error(name: &str, format: Option<Format>, problem: MeshProblem) -> MeshError {
    MeshError {
        file: name.to_string(),
        format,
        problem,
    }
}

/// Loads an OBJ file as it is: no repair and no validation (the builder validates).
pub fn load_obj(path: &Path) -> Result<IndexedMesh, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| error(&file, None, MeshProblem::Io(e)))?;
    load_obj_bytes(&file, &bytes)
}

/// Loads OBJ text held in memory as it is; `name` is used in error messages.
///
/// ```
/// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
/// let mesh = vdlod_demo::mesh::load_obj_bytes("tri.obj", obj).unwrap();
/// assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
/// assert_eq!(mesh.normals[0], [0.0, 0.0, 1.0]);
/// ```
pub fn load_obj_bytes(name: &str, bytes: &[u8]) -> Result<IndexedMesh, MeshError> {
    let mut soup = read_soup(name, Format::Obj, bytes)?;
    soup.drop_unused();
    Ok(soup.into())
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

/// OBJ text of a mesh: `v x y z` lines (`v x y z r g b` with colours, as fractions of 1) and
/// 1-based `f` lines. Coordinates are written so they read back to the same bits.
///
/// ```
/// let text = vdlod_demo::mesh::obj_text(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.5, 0.0]], None, [[0, 1, 2]]);
/// assert_eq!(text, "v 0 0 0\nv 1 0 0\nv 0 0.5 0\nf 1 2 3\n");
/// ```
pub fn obj_text(
    positions: &[[f32; 3]],
    colors: Option<&[[u8; 3]]>,
    triangles: impl IntoIterator<Item = [u32; 3]>,
) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(positions.len() * 40);
    for (i, p) in positions.iter().enumerate() {
        let _ = write!(s, "v {} {} {}", p[0], p[1], p[2]);
        if let Some(c) = colors.and_then(|c| c.get(i)) {
            let f = |v: u8| v as f32 / 255.0;
            let _ = write!(s, " {} {} {}", f(c[0]), f(c[1]), f(c[2]));
        }
        s.push('\n');
    }
    for t in triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
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
