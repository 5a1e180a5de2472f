//! The frame loop, written once: adapt a cut to a [`Camera`], then draw it into a whole frame or
//! band by band, with drawing parameters that come from the same camera.
//!
//! [`CutMesh`] is the cut as the rasterizer reads it: its triangles as they are, its vertices
//! read one at a time from the hierarchy in place (or from a running geomorph), so a device needs
//! no per-vertex copy of positions, normals or colours, only the rasterizer's 16-byte scratch.

use core::fmt;

use glam::Vec3;
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::cut::{Cut, SlotIndex, LANES};
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::Policy;
use vdlod_raster::texture::Texture;
use vdlod_raster::{
    shade, Depth, DrawError, DrawParams, DrawStats, Light, MeshSource, Pixel, ShadedVertex,
    Shading, SourceVertex, Target, TargetError, Uv, VertexBatch, VertexIndex, Window, BATCH,
};

use crate::camera::{Camera, CameraError};

/// A cut as a mesh the rasterizer draws as is.
#[derive(Clone, Copy, Debug)]
pub struct CutMesh<'a, 'h, const V: usize, const F: usize, const Q: usize, I: SlotIndex> {
    cut: &'a Cut<V, F, Q, I>,
    h: &'a HierarchyView<'h>,
    colors: bool,
    uvs: Option<&'a [Uv]>,
}

impl<'a, 'h, const V: usize, const F: usize, const Q: usize, I: SlotIndex>
    CutMesh<'a, 'h, V, F, Q, I>
{
    /// The cut `cut` of hierarchy `h`; with `colors`, vertices are drawn in the cut's colours
    /// (the file's, or a false colour, see [`vdlod_core::cut::Coloring`]), else in the draw's base
    /// colour.
    pub fn new(cut: &'a Cut<V, F, Q, I>, h: &'a HierarchyView<'h>, colors: bool) -> Self {
        CutMesh {
            cut,
            h,
            colors,
            uvs: None,
        }
    }

    /// With texture coordinates for [`draw_mesh_textured`], one per node of the hierarchy (by
    /// node id; a node past the end reads zeros). The file has none: a vertex hierarchy gives a
    /// parent whatever coordinates its builder chose (the mean of its children's, say), which is
    /// why a texture slides over a vertex forest's cut and not over a wavelet cut.
    pub fn with_uvs(self, uvs: &'a [Uv]) -> Self {
        CutMesh {
            uvs: Some(uvs),
            ..self
        }
    }
}

// The cut hands out its vertices in batches of the vertex stage's size.
const _: () = assert!(LANES == BATCH);

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex + VertexIndex> MeshSource
    for CutMesh<'_, '_, V, F, Q, I>
{
    type Index = I;

    fn vertex_count(&self) -> usize {
        self.cut.vertex_count()
    }

    fn triangles(&self) -> &[[I; 3]] {
        self.cut.triangles()
    }

    #[inline]
    fn vertex(&self, i: usize) -> SourceVertex {
        let v = self.cut.vertex(self.h, i);
        SourceVertex {
            position: v.position,
            normal: v.normal,
            color: v.color,
        }
    }

    /// A batch through [`Cut::vertex_lanes`], out of line so that its loops are not unrolled
    /// into every caller. Without vertex colours the draw uses its base colour, so the colours
    /// are neither read nor converted.
    #[inline(never)]
    fn batch(&self, first: usize, len: usize, out: &mut VertexBatch) {
        let mut colors = [[0; LANES]; 3];
        let (p, n) = (&mut out.positions, &mut out.normals);
        let asked = self.colors.then_some(&mut colors);
        self.cut.vertex_lanes(self.h, first, len, p, n, asked);
        if self.colors {
            out.colors = colors.map(|c| c.map(f32::from));
        }
    }

    fn has_normals(&self) -> bool {
        true
    }

    fn has_colors(&self) -> bool {
        self.colors
    }

    fn has_uvs(&self) -> bool {
        self.uvs.is_some()
    }

    #[inline]
    fn uv(&self, i: usize) -> Uv {
        let node = self.cut.nodes().get(i).copied().unwrap_or(u32::MAX);
        self.uvs
            .and_then(|u| u.get(node as usize))
            .copied()
            .unwrap_or([0.0; 2])
    }
}

/// How a cut is drawn: everything but the camera and the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Shading mode.
    pub shading: Shading,
    /// Colour of the surface when vertex colours are off.
    pub base_color: [u8; 3],
    /// Draw in the cut's vertex colours (see [`CutMesh::new`]).
    pub vertex_colors: bool,
    /// Draw triangle edges in this colour over the filled frame.
    pub wireframe: Option<[u8; 3]>,
    /// Skip triangles facing away from the camera.
    pub cull_back_faces: bool,
    /// Light intensity everywhere.
    pub ambient: f32,
    /// Intensity of the key light, which comes from over the viewer's shoulder.
    pub diffuse: f32,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            shading: Shading::Gouraud,
            base_color: [214, 200, 176],
            vertex_colors: false,
            wireframe: None,
            cull_back_faces: true,
            ambient: Light::default().ambient,
            diffuse: Light::default().diffuse,
        }
    }
}

impl Style {
    /// The rasterizer's parameters for `camera`: its view-projection, and a light from over the
    /// viewer's shoulder.
    pub fn params(&self, camera: &Camera) -> DrawParams {
        let to_eye = (camera.eye - camera.target).normalize_or_zero();
        DrawParams {
            mvp: camera.view_projection(),
            light: Light {
                direction: to_eye + Vec3::Y * 0.6,
                ambient: self.ambient,
                diffuse: self.diffuse,
            },
            shading: self.shading,
            // The cut's normals are of unit length and the model matrix is the identity.
            unit_normals: true,
            base_color: self.base_color,
            cull_back_faces: self.cull_back_faces,
            wireframe: self.wireframe,
            ..DrawParams::default()
        }
    }
}

/// Why a frame was not adapted or drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameError {
    /// The camera cannot be used.
    Camera(CameraError),
    /// The band buffers cannot hold a band.
    Target(TargetError),
    /// The rasterizer refused the mesh or the target.
    Draw(DrawError),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::Camera(e) => e.fmt(f),
            FrameError::Target(e) => e.fmt(f),
            FrameError::Draw(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for FrameError {}

impl From<CameraError> for FrameError {
    fn from(e: CameraError) -> Self {
        FrameError::Camera(e)
    }
}

impl From<TargetError> for FrameError {
    fn from(e: TargetError) -> Self {
        FrameError::Target(e)
    }
}

impl From<DrawError> for FrameError {
    fn from(e: DrawError) -> Self {
        FrameError::Draw(e)
    }
}

/// Adapts `cut` to `camera` (see [`Cut::adapt`]); a camera that cannot be used changes nothing.
pub fn adapt<const V: usize, const F: usize, const Q: usize, I: SlotIndex, P: Policy>(
    cut: &mut Cut<V, F, Q, I>,
    h: &HierarchyView<'_>,
    camera: &Camera,
    policy: &P,
    budget: &Budget,
) -> Result<FrameStats, FrameError> {
    camera.check()?;
    Ok(cut.adapt(h, &camera.view(), policy, budget))
}

/// Draws `cut` as `camera` sees it into `target`, a whole frame of the camera's size (or a window
/// of one). `scratch` needs one entry per vertex slot of the cut that is in use.
///
/// ```
/// use vdlod::prelude::*;
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # use vdlod::core::build::{build, InputMesh};
/// # let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// # let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
/// # let input = InputMesh { positions: &positions, colors: None, triangles: &triangles };
/// # let bytes = build(&input, &Default::default(), &mut |_| {})?.to_bytes(false);
/// let h = HierarchyView::parse(&bytes)?;
/// let mut cut = Cut::<64, 128, 8>::boxed();
/// cut.reset(&h)?;
/// let (center, radius) = h.bounding_sphere();
/// let camera = Orbit::merge_tree(center.into(), radius, 8).viewport(40, 30).camera(1);
/// vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(1.0), &Budget::default())?;
/// let (mut color, mut depth) = (vec![Rgba8([0, 0, 0, 255]); 40 * 30], vec![0u32; 40 * 30]);
/// let mut target = Target::new(&mut color, &mut depth, 40, 30)?;
/// target.clear(Rgba8([0, 0, 0, 255]));
/// let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
/// let stats = vdlod::draw(&mut target, &cut, &h, &camera, &Style::default(), &mut scratch)?;
/// assert!(stats.rasterized > 0);
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn draw<P: Pixel, D: Depth, const V: usize, const F: usize, const Q: usize, I>(
    target: &mut Target<'_, P, D>,
    cut: &Cut<V, F, Q, I>,
    h: &HierarchyView<'_>,
    camera: &Camera,
    style: &Style,
    scratch: &mut [ShadedVertex],
) -> Result<DrawStats, FrameError>
where
    I: SlotIndex + VertexIndex,
{
    draw_mesh(
        target,
        &CutMesh::new(cut, h, style.vertex_colors),
        camera,
        style,
        scratch,
    )
}

/// Draws any engine's mesh (a [`CutMesh`], a [`crate::WaveletMesh`], or any [`MeshSource`]) as
/// `camera` sees it into `target`: [`draw`] for whichever engine made the mesh.
pub fn draw_mesh<P: Pixel, D: Depth, M: MeshSource>(
    target: &mut Target<'_, P, D>,
    mesh: &M,
    camera: &Camera,
    style: &Style,
    scratch: &mut [ShadedVertex],
) -> Result<DrawStats, FrameError> {
    camera.check()?;
    let params = style.params(camera);
    let shaded = shade(mesh, &params, camera.width, camera.height, scratch)?;
    Ok(shaded.draw(target)?)
}

/// [`draw_mesh`] with `texture` mapped by the mesh's texture coordinates (perspective-correct;
/// see [`vdlod_raster::ShadedMesh::draw_textured`]): each pixel is the texel times the lit
/// colour, so a white [`Style::base_color`] without vertex colours shows the texture as it is.
pub fn draw_mesh_textured<P: Pixel, D: Depth, M: MeshSource, T: Pixel>(
    target: &mut Target<'_, P, D>,
    mesh: &M,
    camera: &Camera,
    style: &Style,
    texture: &Texture<'_, T>,
    scratch: &mut [ShadedVertex],
) -> Result<DrawStats, FrameError> {
    camera.check()?;
    let params = style.params(camera);
    let shaded = shade(mesh, &params, camera.width, camera.height, scratch)?;
    Ok(shaded.draw_textured(target, texture)?)
}

/// Band buffers: one colour and one depth buffer of `rows` full-width rows, reused for every
/// band of a frame, and the triangles' bins.
pub struct Bands<'b, P: Pixel, D: Depth> {
    /// Colour, at least `width * rows` pixels.
    pub color: &'b mut [P],
    /// Depth, at least `width * rows` values.
    pub depth: &'b mut [D],
    /// Rows per band (the last band of a frame may be shorter).
    pub rows: usize,
    /// What each band is cleared to before it is drawn.
    pub background: P,
    /// Each triangle's rows, at least one entry per triangle slot of the cut (4 bytes each), so
    /// that a band skips the triangles that miss it; with two to four per slot and one per band
    /// plus one, each band reads only its own triangles (see [`vdlod_raster::ShadedMesh::bin`]).
    /// (Without bins every band re-reads every triangle's vertices: `vdlod_raster` can draw that
    /// way, at 2.3 times the time of a whole-frame draw in 16-row bands of 320x240.)
    pub bins: &'b mut [u32],
}

/// Draws `cut` as `camera` sees it, band by band through `bands`, calling `flush` with each
/// drawn band (top to bottom) so it can be sent to a display. The vertices are shaded once; the
/// bands together are bit-identical to [`draw`] into a whole frame. Returns the frame's
/// statistics.
///
/// ```
/// use vdlod::prelude::*;
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # use vdlod::core::build::{build, InputMesh};
/// # let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// # let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
/// # let input = InputMesh { positions: &positions, colors: None, triangles: &triangles };
/// # let bytes = build(&input, &Default::default(), &mut |_| {})?.to_bytes(false);
/// // `bytes`: a hierarchy file, in flash on a device (`include_bytes!`).
/// let h = HierarchyView::parse(&bytes)?;
/// let mut cut = Cut::<64, 128, 8>::boxed();
/// cut.reset(&h)?;
/// let (center, radius) = h.bounding_sphere();
/// let camera = Orbit::peer(center.into(), radius, 36).viewport(64, 48).camera(0);
/// vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(1.0), &Budget::default())?;
/// let (mut color, mut depth) = ([Rgb565(0); 64 * 16], [0u16; 64 * 16]);
/// // Four per triangle slot and one per band plus one: room for every band's list.
/// let mut bins = [0u32; 4 * 128 + 4];
/// let bands = Bands {
///     color: &mut color,
///     depth: &mut depth,
///     rows: 16,
///     background: Rgb565(0),
///     bins: &mut bins,
/// };
/// let mut scratch = [ShadedVertex::default(); 64];
/// let mut lit = 0;
/// vdlod::draw_bands(bands, &cut, &h, &camera, &Style::default(), &mut scratch, |band| {
///     lit += band.color().iter().filter(|p| p.0 != 0).count(); // send the band to the panel
/// })?;
/// assert!(lit > 0);
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn draw_bands<P: Pixel, D: Depth, const V: usize, const F: usize, const Q: usize, I>(
    bands: Bands<'_, P, D>,
    cut: &Cut<V, F, Q, I>,
    h: &HierarchyView<'_>,
    camera: &Camera,
    style: &Style,
    scratch: &mut [ShadedVertex],
    flush: impl FnMut(&Target<'_, P, D>),
) -> Result<DrawStats, FrameError>
where
    I: SlotIndex + VertexIndex,
{
    let mesh = CutMesh::new(cut, h, style.vertex_colors);
    draw_mesh_bands(bands, &mesh, camera, style, scratch, flush)
}

/// [`draw_bands`] for any engine's mesh (see [`draw_mesh`]).
pub fn draw_mesh_bands<P: Pixel, D: Depth, M: MeshSource>(
    bands: Bands<'_, P, D>,
    mesh: &M,
    camera: &Camera,
    style: &Style,
    scratch: &mut [ShadedVertex],
    mut flush: impl FnMut(&Target<'_, P, D>),
) -> Result<DrawStats, FrameError> {
    camera.check()?;
    let (width, height) = (camera.width, camera.height);
    let params = style.params(camera);
    let Bands {
        color,
        depth,
        rows,
        background,
        bins,
    } = bands;
    if rows == 0 {
        return Err(TargetError::ZeroSize.into());
    }
    let binned = shade(mesh, &params, width, height, scratch)?.bin(rows, bins)?;
    let mut stats = DrawStats::default();
    for band in Window::bands(width, height, rows) {
        let mut target = Target::window(color, depth, width, height, band, width)?;
        target.clear(background);
        stats = binned.draw(&mut target)?;
        flush(&target);
    }
    Ok(stats)
}
