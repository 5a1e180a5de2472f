//! Drawing an indexed triangle mesh: the pipeline from vertices to pixels.
//!
//! [`shade`] runs the vertex stage once per vertex into caller-provided scratch; [`ShadedMesh::draw`]
//! then takes each triangle: rejects it if all three vertices are outside one clipping plane, clips
//! it if any vertex is outside the clipping volume, culls back faces, skips it if it misses the
//! target's window, and fills it with a strict-less depth test. The wireframe overlay, when asked
//! for, is drawn afterwards over the filled window. [`draw_indexed`] does both for a whole frame.
//!
//! A frame drawn in bands shades once and draws once per band. [`ShadedMesh::draw`] re-reads every
//! triangle's three shaded vertices in every band; [`ShadedMesh::bin`] culls once and records
//! which rows each triangle meets (from 4 bytes per triangle, see `bins`) so that
//! [`BinnedMesh::draw`] reads only the triangles that meet a band. Triangles that span several
//! bands are set up once per band, and the few that need clipping are clipped again in each.

mod bins;
mod textured;

pub use bins::BinnedMesh;

use core::fmt;

use glam::{Mat3, Mat4, Vec3};

use crate::clip::{self, clip_triangle, ClipVertex};
use crate::edge::{
    pixel_bounds, scan, signed_area2, signed_area2_xy, Facing, Fragment, ScreenVertex,
    SUBPIXEL_BITS,
};
use crate::mesh::{check_indices, MeshSource, Uv, VertexIndex};
use crate::target::{check_frame, Depth, Pixel, Target, TargetError, Window};
use crate::vertex::{
    shade_vertices, to_clip, Light, PreparedLighting, ShadedVertex, VertexLighting, Viewport,
};
use crate::wire::draw_line;

/// How colour is spread over a triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    /// One colour per triangle, lit by its face normal.
    Flat,
    /// Colours lit at the vertices by their normals and interpolated.
    #[default]
    Gouraud,
    /// Vertex colours interpolated without lighting.
    Unlit,
}

/// Everything about a draw call except the mesh and the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawParams {
    /// Object space to clip space (depth range `0..=1`, e.g. glam's `perspective_rh * look_at_rh`).
    pub mvp: Mat4,
    /// Maps normals into the space of [`Light::direction`]; the inverse transpose of the model
    /// matrix's upper 3x3 (identity when lighting in object space).
    pub normal_matrix: Mat3,
    /// The light.
    pub light: Light,
    /// Shading mode.
    pub shading: Shading,
    /// Colour of vertices when the mesh has none.
    pub base_color: [u8; 3],
    /// Skip triangles facing away from the camera.
    pub cull_back_faces: bool,
    /// The normals are of unit length after [`DrawParams::normal_matrix`]: skip renormalizing them
    /// (like OpenGL without `GL_NORMALIZE`), which saves a square root and a division per vertex.
    /// Shading is wrong if they are not.
    pub unit_normals: bool,
    /// Draw triangle edges in this colour over the filled frame.
    pub wireframe: Option<[u8; 3]>,
}

impl Default for DrawParams {
    fn default() -> Self {
        DrawParams {
            mvp: Mat4::IDENTITY,
            normal_matrix: Mat3::IDENTITY,
            light: Light::default(),
            shading: Shading::default(),
            base_color: [200, 200, 200],
            cull_back_faces: true,
            unit_normals: false,
            wireframe: None,
        }
    }
}

/// What became of the triangles of one draw call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Triangles submitted.
    pub submitted: u32,
    /// Triangles (or clipped pieces) scanned by the edge stage.
    pub rasterized: u32,
    /// Back-facing or zero-area triangles (or clipped pieces).
    pub culled: u32,
    /// Triangles entirely outside one clipping plane.
    pub outside: u32,
    /// Triangles that needed clipping.
    pub clipped: u32,
    /// Triangles dropped for a NaN or infinite vertex.
    pub invalid: u32,
}

/// Why a draw call drew nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError {
    /// The scratch slice is shorter than the vertex count.
    ScratchTooSmall {
        /// Vertices in the mesh.
        needed: usize,
        /// Length of the scratch slice.
        available: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Position of the triangle in the mesh.
        triangle: usize,
        /// The offending index.
        index: u32,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// A per-vertex or per-triangle array has the wrong length.
    AttributeLength {
        /// Which array.
        attribute: &'static str,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        actual: usize,
    },
    /// Gouraud shading needs vertex normals.
    MissingNormals,
    /// A textured draw needs texture coordinates.
    MissingUvs,
    /// The frame size given to [`shade`] is zero or too large.
    Frame(TargetError),
    /// The bins given to [`ShadedMesh::bin`] are fewer than the triangles.
    BinsTooSmall {
        /// Triangles in the mesh.
        needed: usize,
        /// Length of the bins slice.
        available: usize,
    },
    /// The target is for a frame of another size than the one the mesh was shaded for.
    FrameMismatch {
        /// The frame [`shade`] was given.
        shaded: (usize, usize),
        /// The target's frame.
        target: (usize, usize),
    },
}

impl fmt::Display for DrawError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            DrawError::ScratchTooSmall { needed, available } => write!(
                f,
                "scratch holds {available} vertices, the mesh has {needed}"
            ),
            DrawError::IndexOutOfRange {
                triangle,
                index,
                vertices,
            } => write!(
                f,
                "triangle {triangle} uses vertex {index}, but the mesh has {vertices} vertices"
            ),
            DrawError::AttributeLength {
                attribute,
                expected,
                actual,
            } => write!(f, "{attribute} has {actual} entries, expected {expected}"),
            DrawError::MissingNormals => write!(f, "Gouraud shading needs vertex normals"),
            DrawError::MissingUvs => write!(f, "a textured draw needs texture coordinates"),
            DrawError::Frame(e) => write!(f, "{e}"),
            DrawError::BinsTooSmall { needed, available } => write!(
                f,
                "bins hold {available} entries, the mesh has {needed} triangles (one each at least)"
            ),
            DrawError::FrameMismatch { shaded, target } => write!(
                f,
                "the mesh was shaded for a {}x{} frame, the target is part of a {}x{} frame",
                shaded.0, shaded.1, target.0, target.1
            ),
        }
    }
}

impl core::error::Error for DrawError {}

fn validate<M: MeshSource>(mesh: &M, params: &DrawParams, scratch: usize) -> Result<(), DrawError> {
    let n = mesh.vertex_count();
    if scratch < n {
        return Err(DrawError::ScratchTooSmall {
            needed: n,
            available: scratch,
        });
    }
    mesh.check()?;
    if params.shading == Shading::Gouraud && !mesh.has_normals() {
        return Err(DrawError::MissingNormals);
    }
    // A mesh checked once (`CheckedMesh`) is not checked again.
    if mesh.index_proof().is_some_and(|p| p.covers(mesh)) {
        return Ok(());
    }
    check_indices(mesh)
}

#[inline(always)]
fn rgb_f32(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| v as f32)
}

/// Draws an indexed mesh into a whole frame: [`shade`], then [`ShadedMesh::draw`].
///
/// `scratch` must hold at least one [`ShadedVertex`] per mesh vertex; it is overwritten. Nothing
/// is drawn when an error is returned.
///
/// ```
/// use glam::{Mat4, Vec3};
/// use vdlod_raster::{draw_indexed, DrawParams, Mesh, Rgba8, ShadedVertex, Shading, Target};
/// let positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
/// let mesh = Mesh { positions: &positions, triangles: &[[0u32, 1, 2]], ..Mesh::default() };
/// let proj = Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0);
/// let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
/// let params = DrawParams { mvp: proj * view, shading: Shading::Flat, ..DrawParams::default() };
/// let mut color = [Rgba8::default(); 32 * 32];
/// let mut depth = [0u32; 32 * 32];
/// let mut target = Target::new(&mut color, &mut depth, 32, 32).unwrap();
/// target.clear(Rgba8([0, 0, 0, 255]));
/// let mut scratch = [ShadedVertex::default(); 3];
/// let stats = draw_indexed(&mut target, &mesh, &params, &mut scratch).unwrap();
/// assert_eq!(stats.rasterized, 1);
/// assert!(target.color().iter().any(|p| p.0[0] > 0));
/// ```
pub fn draw_indexed<P: Pixel, D: Depth, M: MeshSource>(
    target: &mut Target<'_, P, D>,
    mesh: &M,
    params: &DrawParams,
    scratch: &mut [ShadedVertex],
) -> Result<DrawStats, DrawError> {
    shade(mesh, params, target.width, target.height, scratch)?.draw(target)
}

/// A mesh after the vertex stage of one frame, ready to be drawn into the whole frame or into any
/// window of it, as often as needed (once per band), without shading its vertices again.
#[derive(Debug)]
pub struct ShadedMesh<'a, M: MeshSource> {
    mesh: &'a M,
    params: &'a DrawParams,
    vertices: &'a [ShadedVertex],
    lighting: Option<PreparedLighting>,
    viewport: Viewport,
    frame: (usize, usize),
    /// The union of the vertices' outcodes: 0 when none is outside the clipping volume.
    outside: u8,
}

// By hand: a derive would ask `M: Copy`, and both hold only references and plain values.
impl<M: MeshSource> Clone for ShadedMesh<'_, M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M: MeshSource> Copy for ShadedMesh<'_, M> {}

/// Runs the vertex stage of `mesh` for a `width` by `height` frame into `scratch` (at least one
/// [`ShadedVertex`] per vertex; it is overwritten).
///
/// ```
/// use glam::{Mat4, Vec3};
/// use vdlod_raster::{shade, DrawParams, Mesh, Rgb565, ShadedVertex, Shading, Target, Window};
/// let positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
/// let mesh = Mesh { positions: &positions, triangles: &[[0u16, 1, 2]], ..Mesh::default() };
/// let proj = Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0);
/// let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
/// let params = DrawParams { mvp: proj * view, shading: Shading::Flat, ..DrawParams::default() };
/// let mut scratch = [ShadedVertex::default(); 3];
/// let shaded = shade(&mesh, &params, 32, 32, &mut scratch).unwrap();
/// // A 32x32 frame in bands of 8 rows, through one band-sized pair of buffers.
/// let (mut color, mut depth) = ([Rgb565(0); 32 * 8], [0u16; 32 * 8]);
/// let mut lit = 0;
/// for band in Window::bands(32, 32, 8) {
///     let mut target = Target::window(&mut color, &mut depth, 32, 32, band, 32).unwrap();
///     target.clear(Rgb565(0));
///     shaded.draw(&mut target).unwrap();
///     lit += target.color().iter().filter(|p| p.0 != 0).count();
/// }
/// assert!(lit > 100);
/// ```
pub fn shade<'a, M: MeshSource>(
    mesh: &'a M,
    params: &'a DrawParams,
    width: usize,
    height: usize,
    scratch: &'a mut [ShadedVertex],
) -> Result<ShadedMesh<'a, M>, DrawError> {
    check_frame(width, height).map_err(DrawError::Frame)?;
    validate(mesh, params, scratch.len())?;
    let viewport = Viewport::new(width, height);
    let scratch = &mut scratch[..mesh.vertex_count()];
    let prepared = (params.shading == Shading::Gouraud && mesh.has_normals()).then(|| {
        VertexLighting {
            normal_matrix: &params.normal_matrix,
            light: &params.light,
            unit_normals: params.unit_normals,
        }
        .prepare()
    });
    let outside = shade_vertices(
        &params.mvp,
        &viewport,
        mesh,
        prepared.as_ref(),
        rgb_f32(params.base_color),
        scratch,
    );
    Ok(ShadedMesh {
        mesh,
        params,
        vertices: scratch,
        lighting: prepared,
        viewport,
        frame: (width, height),
        outside,
    })
}

impl<'a, M: MeshSource> ShadedMesh<'a, M> {
    /// Draws the triangles into `target`, which must be (a window of) the frame the mesh was
    /// shaded for. The statistics are those of the whole frame, whatever the window.
    pub fn draw<P: Pixel, D: Depth>(
        &self,
        target: &mut Target<'_, P, D>,
    ) -> Result<DrawStats, DrawError> {
        self.check_frame(target)?;
        Ok(self.draw_triangles(target, 0..self.mesh.triangles().len(), &Plain))
    }

    fn check_frame<P: Pixel, D: Depth>(&self, target: &Target<'_, P, D>) -> Result<(), DrawError> {
        if (target.width, target.height) == self.frame {
            Ok(())
        } else {
            Err(DrawError::FrameMismatch {
                shaded: self.frame,
                target: (target.width, target.height),
            })
        }
    }

    /// The triangle loop and the wireframe pass over the triangles `order` yields (all of them,
    /// or those a band's bins name), in draw order. `fill` fills each triangle kept (see
    /// [`Fill`]).
    fn draw_triangles<P: Pixel, D: Depth, F: Fill<P, D>>(
        &self,
        target: &mut Target<'_, P, D>,
        order: impl Iterator<Item = usize> + Clone,
        fill: &F,
    ) -> DrawStats {
        // With every vertex inside the clipping volume (a model in view), no triangle's outcodes
        // need reading.
        let stats = match self.outside {
            0 => self.triangle_loop::<false, P, D, F>(target, order.clone(), fill),
            _ => self.triangle_loop::<true, P, D, F>(target, order.clone(), fill),
        };
        self.draw_wireframe(target, order);
        stats
    }

    /// [`ShadedMesh::draw_triangles`]' triangle loop; `CLIPS` false when no vertex is outside
    /// the clipping volume. Out of line on a device: inlined, both loops' locals took room in
    /// one stack frame (1.3 KB more at the Cortex-M7's peak); inlined where stacks are large
    /// (out of line, the whole 320x240 bunny took 3% more instructions on x86-64).
    #[cfg_attr(any(target_arch = "x86_64", target_arch = "aarch64"), inline(always))]
    #[cfg_attr(
        not(any(target_arch = "x86_64", target_arch = "aarch64")),
        inline(never)
    )]
    fn triangle_loop<const CLIPS: bool, P: Pixel, D: Depth, F: Fill<P, D>>(
        &self,
        target: &mut Target<'_, P, D>,
        order: impl Iterator<Item = usize>,
        fill: &F,
    ) -> DrawStats {
        let (mesh, params, scratch) = (self.mesh, self.params, self.vertices);
        let viewport = &self.viewport;
        let prepared = self.lighting.as_ref();
        let facing = Facing::culling(params.cull_back_faces);
        let mut stats = DrawStats {
            submitted: mesh.triangles().len() as u32,
            ..DrawStats::default()
        };
        let triangles = mesh.triangles();
        for t in order {
            let ([i0, i1, i2], v) = corners(scratch, &triangles[t]);
            let union = outcodes::<CLIPS>(&v);
            let uvs = |mesh: &M| match F::TEXTURED {
                true => [i0, i1, i2].map(|i| mesh.uv(i as usize)),
                false => [[0.0; 2]; 3],
            };
            if union == 0 {
                // Cull before any colour work: half the triangles of a closed mesh face away.
                let xy = v.map(|v| [v.x, v.y]);
                let area = signed_area2_xy(xy);
                if !facing.draws(area) {
                    stats.culled += 1;
                    continue;
                }
                let tri = &[i0, i1, i2];
                stats.rasterized += 1;
                // Smaller than a pixel and between pixel centres: nothing to draw, no set-up to pay.
                let Some(bounds) = pixel_bounds(xy, &target.window) else {
                    continue;
                };
                let colors = triangle_colors(mesh, params, prepared, t, tri, &v);
                let mut q = [[0.0f32; 3]; 3];
                if F::TEXTURED {
                    let uv = uvs(mesh);
                    for (k, q) in q.iter_mut().enumerate() {
                        let p = Vec3::from(mesh.position(tri[k] as usize));
                        // Inside the clipping volume: `w` is positive.
                        let inv_w = 1.0 / to_clip(&params.mvp, p).w;
                        *q = [uv[k][0] * inv_w, uv[k][1] * inv_w, inv_w];
                    }
                }
                let s: [ScreenVertex; 3] = core::array::from_fn(|k| ScreenVertex {
                    x: v[k].x,
                    y: v[k].y,
                    z: v[k].z,
                    rgb: colors[k],
                });
                fill.fill(
                    target,
                    &clockwise(area, s),
                    &clockwise(area, q),
                    area.abs(),
                    bounds,
                );
            } else if needs_clipping(&v, union, &mut stats) {
                let tri = &[i0, i1, i2];
                let colors = triangle_colors(mesh, params, prepared, t, tri, &v);
                let uv = uvs(mesh);
                for_each_clipped(viewport, params, mesh, tri, colors, uv, union, |s, q| {
                    let area = signed_area2(s);
                    if !facing.draws(area) {
                        stats.culled += 1;
                        return;
                    }
                    stats.rasterized += 1;
                    let Some(bounds) = pixel_bounds(s.map(|v| [v.x, v.y]), &target.window) else {
                        return;
                    };
                    fill.fill(
                        target,
                        &clockwise(area, *s),
                        &clockwise(area, *q),
                        area.abs(),
                        bounds,
                    );
                });
            }
        }
        stats
    }

    /// The wireframe overlay, when [`DrawParams::wireframe`] asks for it, over the triangles
    /// `order` yields.
    fn draw_wireframe<P: Pixel, D: Depth>(
        &self,
        target: &mut Target<'_, P, D>,
        order: impl Iterator<Item = usize>,
    ) {
        let (mesh, params, scratch) = (self.mesh, self.params, self.vertices);
        let viewport = &self.viewport;
        if let Some(wire) = params.wireframe {
            let color = P::from_rgb(wire[0], wire[1], wire[2]);
            let triangles = mesh.triangles();
            for t in order {
                let tri = &triangles[t];
                let tri = &tri.map(VertexIndex::to_u32);
                let v = tri.map(|i| scratch[i as usize]);
                let union = v[0].outcode | v[1].outcode | v[2].outcode;
                if union & clip::INVALID != 0 || v[0].outcode & v[1].outcode & v[2].outcode != 0 {
                    continue;
                }
                let mut edges = |s: &[ScreenVertex; 3]| {
                    if params.cull_back_faces && signed_area2(s) >= 0 {
                        return;
                    }
                    for k in 0..3 {
                        draw_line(target, &s[k], &s[(k + 1) % 3], color);
                    }
                };
                if union == 0 {
                    edges(&v.map(|v| v.screen()));
                } else {
                    let (colors, uvs) = ([[0.0; 3]; 3], [[0.0; 2]; 3]);
                    for_each_clipped(viewport, params, mesh, tri, colors, uvs, union, |s, _| {
                        edges(s)
                    });
                }
            }
        }
    }
}

/// A triangle's vertex indices and its three shaded vertices. Scalars and references, not
/// copies: a culled triangle reads only positions and outcodes (an index array in the triangle
/// loop went through the stack, and reading one index back from the wider store stalled every
/// triangle).
#[inline(always)]
fn corners<'s, I: VertexIndex>(
    scratch: &'s [ShadedVertex],
    tri: &[I; 3],
) -> ([u32; 3], [&'s ShadedVertex; 3]) {
    let [i0, i1, i2] = tri.map(VertexIndex::to_u32);
    let v = [
        &scratch[i0 as usize],
        &scratch[i1 as usize],
        &scratch[i2 as usize],
    ];
    ([i0, i1, i2], v)
}

/// The union of a triangle's outcodes, or 0 without reading them when no vertex of the mesh is
/// outside the clipping volume (`CLIPS` false).
#[inline(always)]
fn outcodes<const CLIPS: bool>(v: &[&ShadedVertex; 3]) -> u8 {
    match CLIPS {
        true => v[0].outcode | v[1].outcode | v[2].outcode,
        false => 0,
    }
}

/// Whether a triangle with a vertex outside the clipping volume (outcodes' union `union`, not 0)
/// is to be clipped; if not, it is counted as dropped for a non-finite vertex or as entirely
/// outside one plane.
#[inline(always)]
fn needs_clipping(v: &[&ShadedVertex; 3], union: u8, stats: &mut DrawStats) -> bool {
    if union & clip::INVALID != 0 {
        stats.invalid += 1;
        false
    } else if v[0].outcode & v[1].outcode & v[2].outcode != 0 {
        stats.outside += 1;
        false
    } else {
        stats.clipped += 1;
        true
    }
}

/// A triangle's corners (or their attributes) clockwise on screen, as the pixel loop wants them,
/// given its [`signed_area2`].
#[inline(always)]
fn clockwise<T>(area: i64, [a, b, c]: [T; 3]) -> [T; 3] {
    if area < 0 {
        [a, c, b]
    } else {
        [a, b, c]
    }
}

/// How the triangle loop fills each triangle it keeps: the one thing a plain and a textured draw
/// do differently. A trait rather than a closure, so that the fill is inlined at both of the
/// loop's call sites (a closure called twice stayed out of line, and its arguments went through
/// memory: 12% more instructions per frame).
pub(crate) trait Fill<P: Pixel, D: Depth> {
    /// Whether [`Fill::fill`] needs each corner's `[u / w, v / w, 1 / w]` (zeros without).
    const TEXTURED: bool;

    /// Fills triangle `s`, clockwise on screen, of twice the area `area`, within its pixel
    /// `bounds`; `q` holds its corners' texture terms when [`Fill::TEXTURED`].
    fn fill(
        &self,
        target: &mut Target<'_, P, D>,
        s: &[ScreenVertex; 3],
        q: &[[f32; 3]; 3],
        area: i64,
        bounds: [i32; 4],
    );
}

/// The untextured fill: Gouraud or flat colours, strict-less depth test.
struct Plain;

impl<P: Pixel, D: Depth> Fill<P, D> for Plain {
    const TEXTURED: bool = false;

    #[inline(always)]
    fn fill(
        &self,
        target: &mut Target<'_, P, D>,
        s: &[ScreenVertex; 3],
        _: &[[f32; 3]; 3],
        area: i64,
        bounds: [i32; 4],
    ) {
        scan(target, s, area, bounds, depth_test::<P, D>);
    }
}

/// Writes a fragment nearer than what the pixel holds (strict less: the first of equal depths wins).
#[inline(always)]
fn depth_test<P: Pixel, D: Depth>(c: &mut P, d: &mut D, f: Fragment<'_>) {
    let z = D::from_depth(f.z);
    if z < *d {
        *d = z;
        let [r, g, b] = f.rgb();
        *c = P::from_rgb(r, g, b);
    }
}

/// The colours the three corners of triangle `t` are drawn with.
#[inline(always)]
fn triangle_colors<M: MeshSource>(
    mesh: &M,
    params: &DrawParams,
    lighting: Option<&PreparedLighting>,
    t: usize,
    tri: &[u32; 3],
    v: &[&ShadedVertex; 3],
) -> [[f32; 3]; 3] {
    let face = mesh.face_colors().map(|f| rgb_f32(f[t]));
    match params.shading {
        Shading::Gouraud | Shading::Unlit => match face {
            Some(c) => tri.map(|i| {
                let light = match lighting {
                    Some(l) => l.intensity(Vec3::from(mesh.vertex(i as usize).normal)),
                    None => 1.0,
                };
                c.map(|c| c * light)
            }),
            None => v.map(|v| rgb_f32(v.rgb)),
        },
        Shading::Flat => {
            let p = tri.map(|i| Vec3::from(mesh.position(i as usize)));
            let normal = params.normal_matrix * (p[1] - p[0]).cross(p[2] - p[0]);
            let light = params.light.intensity(normal);
            let c = face.unwrap_or_else(|| {
                // Unlit vertex colours: their mean.
                let mut sum = [0.0f32; 3];
                for v in v {
                    for (s, c) in sum.iter_mut().zip(v.rgb) {
                        *s += c as f32;
                    }
                }
                sum.map(|s| s / 3.0)
            });
            [c.map(|c| c * light); 3]
        }
    }
}

/// Clips a triangle with its corner colours and texture coordinates (zeros when not textured)
/// and calls `f` with each projected piece and its corners' `[u / w, v / w, 1 / w]`.
#[allow(clippy::too_many_arguments)]
fn for_each_clipped<M: MeshSource>(
    viewport: &Viewport,
    params: &DrawParams,
    mesh: &M,
    tri: &[u32; 3],
    colors: [[f32; 3]; 3],
    uvs: [Uv; 3],
    planes: u8,
    mut f: impl FnMut(&[ScreenVertex; 3], &[[f32; 3]; 3]),
) {
    let tri: [ClipVertex; 3] = core::array::from_fn(|k| ClipVertex {
        pos: to_clip(&params.mvp, Vec3::from(mesh.position(tri[k] as usize))),
        rgb: colors[k],
        uv: uvs[k],
    });
    let poly = clip_triangle(&tri, planes);
    let verts = poly.vertices();
    if verts.len() < 3 {
        return;
    }
    let corner = |cv: &ClipVertex| {
        // Clipped to the near plane and the guard band: `w` is positive.
        let inv_w = 1.0 / cv.pos.w;
        (
            viewport.project(cv.pos, cv.rgb),
            [cv.uv[0] * inv_w, cv.uv[1] * inv_w, inv_w],
        )
    };
    let first = corner(&verts[0]);
    let mut prev = corner(&verts[1]);
    for cv in &verts[2..] {
        let cur = corner(cv);
        f(&[first.0, prev.0, cur.0], &[first.1, prev.1, cur.1]);
        prev = cur;
    }
}
