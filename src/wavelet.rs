//! The wavelet engine in the frame loop: [`adapt_wavelets`] moves a
//! [`WaveletCut`](vdlod_core::wavelet::WaveletCut) to a [`Camera`], and [`WaveletMesh`] is its
//! mesh as the rasterizer reads it, so [`crate::draw_mesh`] and [`crate::draw_mesh_bands`] draw
//! it exactly as they draw the vertex forest's [`crate::CutMesh`].

use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::cut::SlotIndex;
use vdlod_core::policy::Policy;
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
use vdlod_raster::{MeshSource, SourceVertex, Uv, VertexIndex};

use crate::camera::Camera;
use crate::frame::FrameError;

/// A wavelet cut as a mesh the rasterizer draws as is: its triangles, each vertex at its
/// position this frame (a vertex whose wavelet is out sits on its parent edge), with the
/// normal and colour the file gives it.
#[derive(Clone, Copy, Debug)]
pub struct WaveletMesh<
    'a,
    's,
    const W: usize,
    const T: usize,
    const V: usize,
    const Q: usize,
    I: SlotIndex,
> {
    cut: &'a WaveletCut<W, T, V, Q, I>,
    s: &'a SemiRegularView<'s>,
    colors: bool,
    base_uvs: Option<&'a [Uv]>,
}

impl<'a, 's, const W: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex>
    WaveletMesh<'a, 's, W, T, V, Q, I>
{
    /// The mesh of `cut` over `s`; with `colors`, in the file's vertex colours.
    pub fn new(
        cut: &'a WaveletCut<W, T, V, Q, I>,
        s: &'a SemiRegularView<'s>,
        colors: bool,
    ) -> Self {
        WaveletMesh {
            cut,
            s,
            colors,
            base_uvs: None,
        }
    }

    /// With texture coordinates over the parametric domain: `base_uvs` gives one per base
    /// vertex, and every vertex of every level gets the barycentric mix of its base face's
    /// corners, the weights of its lattice point (the wavelet paper, §3.1). Whatever the cut,
    /// a vertex keeps its coordinates, so the texture never slides. (One pair per base vertex:
    /// a base mesh whose chart has seams needs its seams cut in the base mesh.)
    pub fn with_uvs(self, base_uvs: &'a [Uv]) -> Self {
        WaveletMesh {
            base_uvs: Some(base_uvs),
            ..self
        }
    }
}

impl<
        const W: usize,
        const T: usize,
        const V: usize,
        const Q: usize,
        I: SlotIndex + VertexIndex,
    > MeshSource for WaveletMesh<'_, '_, W, T, V, Q, I>
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
        let id = self.cut.vertex_id(i);
        SourceVertex {
            position: self.cut.position(i),
            normal: self.s.normal(id),
            color: self.s.color(id),
        }
    }

    fn has_normals(&self) -> bool {
        true
    }

    fn has_colors(&self) -> bool {
        self.colors
    }

    fn has_uvs(&self) -> bool {
        self.base_uvs.is_some()
    }

    #[inline]
    fn uv(&self, i: usize) -> Uv {
        let Some(uvs) = self.base_uvs else {
            return [0.0; 2];
        };
        let id = self.cut.vertex_id(i);
        // A base vertex has its own; a wavelet's point is in the frame of a base face.
        let Some(p) = self.s.point(id) else {
            return uvs.get(id as usize).copied().unwrap_or([0.0; 2]);
        };
        let corners = self.s.corners(p.face);
        let n = self.s.steps() as f32;
        let mut uv = [0.0f32; 2];
        for (k, &c) in corners.iter().enumerate() {
            let base = uvs.get(c as usize).copied().unwrap_or([0.0; 2]);
            let w = p.w[k] as f32 / n;
            uv[0] += w * base[0];
            uv[1] += w * base[1];
        }
        uv
    }
}

/// Adapts a wavelet cut to `camera` (see [`WaveletCut::adapt`]); a camera that cannot be used
/// changes nothing. The cut is then drawn like any engine's mesh:
///
/// ```
/// use vdlod::prelude::*;
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use vdlod::core::wavelet::SemiRegular;
/// let bytes = SemiRegular::sphere(3)?.to_bytes()?; // a device keeps these in flash
/// let s = SemiRegularView::parse(&bytes)?;
/// let mut cut = WaveletCut::<16, 1024, 600, 128>::boxed();
/// cut.reset(&s)?;
/// let camera = Orbit::peer(glam::Vec3::ZERO, 1.0, 8).viewport(40, 30).camera(0);
/// vdlod::adapt_wavelets(&mut cut, &s, &camera, &QRefine::new(1.0), &Budget::default())?;
/// let (mut color, mut depth) = (vec![Rgba8([0, 0, 0, 255]); 40 * 30], vec![0u32; 40 * 30]);
/// let mut target = Target::new(&mut color, &mut depth, 40, 30)?;
/// target.clear(Rgba8([0, 0, 0, 255]));
/// let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
/// let mesh = WaveletMesh::new(&cut, &s, false);
/// let stats = vdlod::draw_mesh(&mut target, &mesh, &camera, &Style::default(), &mut scratch)?;
/// assert!(stats.rasterized > 0);
/// # Ok(())
/// # }
/// ```
pub fn adapt_wavelets<
    const W: usize,
    const T: usize,
    const V: usize,
    const Q: usize,
    I: SlotIndex,
    P: Policy,
>(
    cut: &mut WaveletCut<W, T, V, Q, I>,
    s: &SemiRegularView<'_>,
    camera: &Camera,
    policy: &P,
    budget: &Budget,
) -> Result<FrameStats, FrameError> {
    camera.check()?;
    Ok(cut.adapt(s, &camera.view(), policy, budget))
}
