//! Where the rasterizer reads a mesh: borrowed arrays ([`Mesh`]), or anything that can hand out
//! its vertices one by one ([`MeshSource`]).
//!
//! A device that keeps its geometry compressed in flash (vdlod's cut reads quantized positions,
//! octahedral normals and colours from the hierarchy file in place) should not have to unpack every
//! vertex into RAM before a draw: the vertex stage asks the source for each vertex once, and the
//! rare clipped or flat-shaded triangle asks for its corners' positions again.

use core::marker::PhantomData;

use crate::draw::DrawError;

/// A vertex index type of a mesh's triangles: `u32`, or `u16` for meshes of up to 65,535
/// vertices (as a 16-bit cut hands them out).
pub trait VertexIndex: Copy + core::fmt::Debug {
    /// The index as a `u32`.
    fn to_u32(self) -> u32;
}

impl VertexIndex for u16 {
    #[inline(always)]
    fn to_u32(self) -> u32 {
        self as u32
    }
}

impl VertexIndex for u32 {
    #[inline(always)]
    fn to_u32(self) -> u32 {
        self
    }
}

/// One vertex as a [`MeshSource`] hands it out; attributes the source does not have are zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SourceVertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space normal.
    pub normal: [f32; 3],
    /// Colour.
    pub color: [u8; 3],
}

/// Texture coordinates of a vertex (see [`crate::texture`] for their meaning).
pub type Uv = [f32; 2];

/// Vertices per [`VertexBatch`]: two AVX or four SSE/NEON registers per attribute.
pub const BATCH: usize = 8;

/// Up to [`BATCH`] vertices attribute by attribute (structure of arrays), as the vertex stage
/// transforms them: `positions[axis][lane]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexBatch {
    /// Object-space positions.
    pub positions: [[f32; BATCH]; 3],
    /// Object-space normals.
    pub normals: [[f32; BATCH]; 3],
    /// Colour channels in `0.0..=255.0`.
    pub colors: [[f32; BATCH]; 3],
}

/// A triangle mesh the rasterizer can draw: triangles over vertices it reads by index.
///
/// Implementations must be consistent: the same index gives the same vertex for the whole draw.
pub trait MeshSource {
    /// The type of [`MeshSource::triangles`]' indices.
    type Index: VertexIndex;
    /// Vertices; indices run from 0 to this, exclusive.
    fn vertex_count(&self) -> usize;
    /// Triangles, counter-clockwise when seen from the front.
    fn triangles(&self) -> &[[Self::Index; 3]];
    /// Vertex `i` (below [`MeshSource::vertex_count`]).
    fn vertex(&self, i: usize) -> SourceVertex;
    /// Vertices `first..first + len` (`len` at most [`BATCH`], all below
    /// [`MeshSource::vertex_count`]) into the first `len` lanes of `out`: how the vertex stage
    /// reads a mesh; override when a batch is cheaper than its vertices one by one. The colours
    /// are used only when [`MeshSource::has_colors`], the normals only when
    /// [`MeshSource::has_normals`]. `out` arrives zeroed for a draw's first batch and its last,
    /// partial one; between them it holds what the batch before left, so an implementation
    /// writes every lane of each attribute it writes at all, the same attributes every time.
    #[inline(always)]
    fn batch(&self, first: usize, len: usize, out: &mut VertexBatch) {
        for k in 0..len.min(BATCH) {
            let v = self.vertex(first + k);
            for a in 0..3 {
                out.positions[a][k] = v.position[a];
                out.normals[a][k] = v.normal[a];
                out.colors[a][k] = v.color[a] as f32;
            }
        }
    }
    /// The position of vertex `i`; override when it is cheaper than the whole vertex.
    #[inline(always)]
    fn position(&self, i: usize) -> [f32; 3] {
        self.vertex(i).position
    }
    /// Whether [`SourceVertex::normal`] is meaningful (Gouraud shading needs it).
    fn has_normals(&self) -> bool;
    /// Whether [`SourceVertex::color`] is meaningful (else the draw's base colour is used).
    fn has_colors(&self) -> bool;
    /// Per-triangle colours that replace the vertex or base colour; lighting still applies.
    fn face_colors(&self) -> Option<&[[u8; 3]]> {
        None
    }
    /// Whether the vertices have texture coordinates ([`crate::ShadedMesh::draw_textured`]
    /// needs them).
    fn has_uvs(&self) -> bool {
        false
    }
    /// Vertex `i`'s texture coordinates (zeros without them).
    fn uv(&self, i: usize) -> Uv {
        let _ = i;
        [0.0; 2]
    }
    /// Checks what the source itself can get wrong (attribute arrays of the wrong length).
    fn check(&self) -> Result<(), DrawError> {
        Ok(())
    }
    /// The proof that [`MeshSource::triangles`]' indices were checked, when they were
    /// ([`CheckedMesh`]); a draw then does not check them again. `None` by default: every draw
    /// checks them.
    fn index_proof(&self) -> Option<IndexProof<'_>> {
        None
    }
}

/// That a mesh's indices are all below its vertex count, made only by a [`CheckedMesh`] and
/// borrowing it (so no proof outlives the triangles it is about). It names what was checked
/// (the triangles' address and count, and the vertex count), so a source that hands it on with
/// other triangles or another vertex count has them checked again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IndexProof<'a> {
    triangles: usize,
    len: usize,
    vertices: usize,
    mesh: PhantomData<&'a ()>,
}

impl IndexProof<'_> {
    /// What `mesh` holds now; a [`CheckedMesh`] keeps it and lends it out only for as long as
    /// it is borrowed.
    fn of<M: MeshSource + ?Sized>(mesh: &M) -> IndexProof<'static> {
        let t = mesh.triangles();
        IndexProof {
            triangles: t.as_ptr() as usize,
            len: t.len(),
            vertices: mesh.vertex_count(),
            mesh: PhantomData,
        }
    }

    /// Whether this proof is about `mesh`'s triangles and vertex count as they are now.
    pub fn covers<M: MeshSource + ?Sized>(&self, mesh: &M) -> bool {
        *self == IndexProof::of(mesh)
    }
}

/// Whether every index of `mesh` is below its vertex count: one comparison and one `or` per
/// index, no branch (the reduction runs in SIMD registers, where an unsigned maximum would cost
/// twice as much on baseline x86-64); the offender is searched for only when there is one.
pub(crate) fn check_indices<M: MeshSource + ?Sized>(mesh: &M) -> Result<(), DrawError> {
    let n = mesh.vertex_count();
    let Ok(limit) = u32::try_from(n) else {
        return Ok(()); // every `u32` index is in range
    };
    let over = mesh
        .triangles()
        .as_flattened()
        .iter()
        .fold(0u32, |o, &i| o | (i.to_u32() >= limit) as u32);
    if over == 0 {
        return Ok(());
    }
    for (triangle, tri) in mesh.triangles().iter().enumerate() {
        if let Some(index) = tri
            .map(VertexIndex::to_u32)
            .into_iter()
            .find(|&i| i as usize >= n)
        {
            return Err(DrawError::IndexOutOfRange {
                triangle,
                index,
                vertices: n,
            });
        }
    }
    Ok(())
}

/// A mesh whose indices were checked once, for a mesh drawn frame after frame: each draw
/// otherwise reads every index to check it, about a twentieth of a 320x240 frame of the
/// full bunny (75,408 triangles). Its triangles must stay where they are when it moves
/// (borrowed, as in [`Mesh`], or on the heap); a source whose triangles move with it is checked
/// at every draw as before.
///
/// ```
/// use vdlod_raster::{CheckedMesh, DrawError, Mesh, MeshSource};
/// let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// let mesh: Mesh = Mesh { positions: &positions, triangles: &[[0, 1, 2]], ..Mesh::default() };
/// let checked = CheckedMesh::new(mesh).unwrap();
/// assert!(checked.index_proof().is_some_and(|p| p.covers(&checked)));
/// // An index past the vertices is refused once, here, rather than at every draw.
/// let bad: Mesh = Mesh { positions: &positions, triangles: &[[0, 1, 3]], ..Mesh::default() };
/// assert!(matches!(
///     CheckedMesh::new(bad),
///     Err(DrawError::IndexOutOfRange { triangle: 0, index: 3, vertices: 3 })
/// ));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct CheckedMesh<M> {
    mesh: M,
    proof: IndexProof<'static>,
}

impl<M: MeshSource> CheckedMesh<M> {
    /// Checks `mesh` ([`MeshSource::check`], and every index below the vertex count).
    pub fn new(mesh: M) -> Result<CheckedMesh<M>, DrawError> {
        mesh.check()?;
        check_indices(&mesh)?;
        let proof = IndexProof::of(&mesh);
        Ok(CheckedMesh { mesh, proof })
    }

    /// The mesh.
    pub fn mesh(&self) -> &M {
        &self.mesh
    }
}

impl<M: MeshSource> MeshSource for CheckedMesh<M> {
    type Index = M::Index;

    #[inline(always)]
    fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    #[inline(always)]
    fn triangles(&self) -> &[[M::Index; 3]] {
        self.mesh.triangles()
    }

    #[inline(always)]
    fn vertex(&self, i: usize) -> SourceVertex {
        self.mesh.vertex(i)
    }

    #[inline(always)]
    fn batch(&self, first: usize, len: usize, out: &mut VertexBatch) {
        self.mesh.batch(first, len, out)
    }

    #[inline(always)]
    fn position(&self, i: usize) -> [f32; 3] {
        self.mesh.position(i)
    }

    fn has_normals(&self) -> bool {
        self.mesh.has_normals()
    }

    fn has_colors(&self) -> bool {
        self.mesh.has_colors()
    }

    fn face_colors(&self) -> Option<&[[u8; 3]]> {
        self.mesh.face_colors()
    }

    fn has_uvs(&self) -> bool {
        self.mesh.has_uvs()
    }

    fn uv(&self, i: usize) -> Uv {
        self.mesh.uv(i)
    }

    fn check(&self) -> Result<(), DrawError> {
        self.mesh.check()
    }

    fn index_proof(&self) -> Option<IndexProof<'_>> {
        Some(self.proof)
    }
}

/// Borrowed mesh data: per-vertex arrays of equal length and triangles indexing them (with
/// `u32` or `u16` indices).
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a, I: VertexIndex = u32> {
    /// Object-space positions.
    pub positions: &'a [[f32; 3]],
    /// Object-space vertex normals (needed by [`crate::Shading::Gouraud`]).
    pub normals: Option<&'a [[f32; 3]]>,
    /// Per-vertex colours; [`crate::DrawParams::base_color`] is used without them.
    pub colors: Option<&'a [[u8; 3]]>,
    /// Triangles, counter-clockwise when seen from the front.
    pub triangles: &'a [[I; 3]],
    /// Per-triangle colours that replace the vertex or base colour (for example a false colour by
    /// hierarchy depth); lighting still applies.
    pub face_colors: Option<&'a [[u8; 3]]>,
    /// Per-vertex texture coordinates, for [`crate::ShadedMesh::draw_textured`].
    pub uvs: Option<&'a [Uv]>,
}

impl<I: VertexIndex> Default for Mesh<'_, I> {
    fn default() -> Self {
        Mesh {
            positions: &[],
            normals: None,
            colors: None,
            triangles: &[],
            face_colors: None,
            uvs: None,
        }
    }
}

fn check_len(attribute: &'static str, expected: usize, actual: usize) -> Result<(), DrawError> {
    if expected == actual {
        Ok(())
    } else {
        Err(DrawError::AttributeLength {
            attribute,
            expected,
            actual,
        })
    }
}

/// Copies up to [`BATCH`] triples into lanes: `lanes[axis][k] = f(triples[k][axis])`.
#[inline(always)]
fn transpose<T: Copy>(triples: &[[T; 3]], lanes: &mut [[f32; BATCH]; 3], f: impl Fn(T) -> f32) {
    for (k, t) in triples.iter().enumerate().take(BATCH) {
        for (lane, &c) in lanes.iter_mut().zip(t) {
            lane[k] = f(c);
        }
    }
}

impl<I: VertexIndex> MeshSource for Mesh<'_, I> {
    type Index = I;

    #[inline(always)]
    fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    #[inline(always)]
    fn triangles(&self) -> &[[I; 3]] {
        self.triangles
    }

    #[inline(always)]
    fn vertex(&self, i: usize) -> SourceVertex {
        SourceVertex {
            position: self.positions[i],
            normal: self.normals.map_or([0.0; 3], |n| n[i]),
            color: self.colors.map_or([0; 3], |c| c[i]),
        }
    }

    #[inline(always)]
    fn batch(&self, first: usize, len: usize, out: &mut VertexBatch) {
        // Slices checked once per batch, attributes copied array by array.
        let end = first + len.min(BATCH);
        transpose(&self.positions[first..end], &mut out.positions, |c| c);
        if let Some(normals) = self.normals {
            transpose(&normals[first..end], &mut out.normals, |c| c);
        }
        if let Some(colors) = self.colors {
            transpose(&colors[first..end], &mut out.colors, |c| c as f32);
        }
    }

    #[inline(always)]
    fn position(&self, i: usize) -> [f32; 3] {
        self.positions[i]
    }

    fn has_normals(&self) -> bool {
        self.normals.is_some()
    }

    fn has_colors(&self) -> bool {
        self.colors.is_some()
    }

    fn face_colors(&self) -> Option<&[[u8; 3]]> {
        self.face_colors
    }

    fn has_uvs(&self) -> bool {
        self.uvs.is_some()
    }

    fn uv(&self, i: usize) -> Uv {
        self.uvs.map_or([0.0; 2], |u| u[i])
    }

    fn check(&self) -> Result<(), DrawError> {
        let n = self.positions.len();
        if let Some(normals) = self.normals {
            check_len("normals", n, normals.len())?;
        }
        if let Some(colors) = self.colors {
            check_len("colors", n, colors.len())?;
        }
        if let Some(uvs) = self.uvs {
            check_len("uvs", n, uvs.len())?;
        }
        if let Some(faces) = self.face_colors {
            check_len("face_colors", self.triangles.len(), faces.len())?;
        }
        Ok(())
    }
}
