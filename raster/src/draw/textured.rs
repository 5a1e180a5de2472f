//! Textured drawing: [`ShadedMesh::draw_textured`].
//!
//! The triangle loop of [`ShadedMesh::draw`] (cull, clip, strict-less depth test, wireframe
//! after), told to divide each corner's texture coordinates by its clip-space `w` (so that the
//! texture is mapped perspective-correctly), with a fill that colours each fragment with the texel
//! at its `(u, v)` modulated by its lit colour (so a white mesh shows the texture as it is, lit).

use super::{DrawError, DrawStats, Fill, ShadedMesh};
use crate::edge::{scan_textured, Fragment, ScreenVertex};
use crate::mesh::MeshSource;
use crate::target::{Depth, Pixel, Target};
use crate::texture::{modulate, Texture};

impl<M: MeshSource> ShadedMesh<'_, M> {
    /// Draws the triangles with `texture` mapped by the mesh's texture coordinates
    /// ([`MeshSource::uv`]) into `target`, which must be (a window of) the frame the mesh was
    /// shaded for. Every fragment is the texel at its `(u, v)` times its lit colour over 255.
    ///
    /// ```
    /// use glam::{Mat4, Vec3};
    /// use vdlod_raster::texture::{Filter, Texture, Wrap};
    /// use vdlod_raster::{shade, DrawParams, Mesh, Rgba8, ShadedVertex, Shading, Target};
    /// // A square with a 2 x 2 checker, seen head-on.
    /// let positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
    /// let uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    /// let triangles = [[0u32, 1, 2], [0, 2, 3]];
    /// let mesh = Mesh { positions: &positions, triangles: &triangles, uvs: Some(&uvs), ..Mesh::default() };
    /// let (b, w) = (Rgba8([0, 0, 0, 255]), Rgba8([255, 255, 255, 255]));
    /// let checker = [w, b, b, w];
    /// let texture = Texture::new(&checker, 2, 2, Filter::Nearest, Wrap::Repeat).unwrap();
    /// let params = DrawParams {
    ///     mvp: Mat4::from_scale(Vec3::new(1.0, 1.0, 0.5)),
    ///     shading: Shading::Unlit,
    ///     base_color: [255; 3],
    ///     ..DrawParams::default()
    /// };
    /// let mut scratch = [ShadedVertex::default(); 4];
    /// let shaded = shade(&mesh, &params, 8, 8, &mut scratch).unwrap();
    /// let (mut color, mut depth) = ([Rgba8::default(); 64], [0u32; 64]);
    /// let mut target = Target::new(&mut color, &mut depth, 8, 8).unwrap();
    /// target.clear(Rgba8([9, 9, 9, 255]));
    /// shaded.draw_textured(&mut target, &texture).unwrap();
    /// let px = |x: usize, y: usize| target.color()[y * 8 + x].0[0];
    /// assert_eq!((px(1, 1), px(6, 1), px(1, 6), px(6, 6)), (255, 0, 0, 255));
    /// ```
    pub fn draw_textured<P: Pixel, D: Depth, T: Pixel>(
        &self,
        target: &mut Target<'_, P, D>,
        texture: &Texture<'_, T>,
    ) -> Result<DrawStats, DrawError> {
        self.check_frame(target)?;
        if !self.mesh.has_uvs() {
            return Err(DrawError::MissingUvs);
        }
        let all = 0..self.mesh.triangles().len();
        Ok(self.draw_triangles(target, all, &Textured(texture)))
    }
}

/// The textured fill: each fragment that passes the strict-less depth test takes the texel at
/// its `(u, v)` times its lit colour.
struct Textured<'a, 't, T: Pixel>(&'a Texture<'t, T>);

impl<P: Pixel, D: Depth, T: Pixel> Fill<P, D> for Textured<'_, '_, T> {
    const TEXTURED: bool = true;

    #[inline(always)]
    fn fill(
        &self,
        target: &mut Target<'_, P, D>,
        s: &[ScreenVertex; 3],
        q: &[[f32; 3]; 3],
        area: i64,
        bounds: [i32; 4],
    ) {
        let texture = self.0;
        let plot = |c: &mut P, d: &mut D, f: Fragment<'_>, uv: [f32; 2]| {
            let z = D::from_depth(f.z);
            if z < *d {
                *d = z;
                let (t, l) = (texture.sample(uv[0], uv[1]), f.rgb());
                *c = P::from_rgb(
                    modulate(t[0], l[0]),
                    modulate(t[1], l[1]),
                    modulate(t[2], l[2]),
                );
            }
        };
        scan_textured(target, s, q, area, bounds, plot);
    }
}
