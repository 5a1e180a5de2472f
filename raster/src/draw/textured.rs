//! The textured triangle loop: [`ShadedMesh::draw_textured`].
//!
//! The same pipeline as [`ShadedMesh::draw`] (cull, clip, fill with a strict-less depth test,
//! wireframe after), with each corner's texture coordinates divided by its clip-space `w` so that
//! the texture is mapped perspective-correctly, and each fragment's colour the texel at its
//! `(u, v)` modulated by its lit colour (so a white mesh colour shows the texture as it is, lit).

use glam::Vec3;

use super::{for_each_clipped, needs_clipping, triangle_colors, DrawError, DrawStats, ShadedMesh};
use crate::edge::ScreenVertex;
use crate::edge::{pixel_bounds, scan_textured, signed_area2, signed_area2_xy, Facing, Fragment};
use crate::mesh::{MeshSource, VertexIndex};
use crate::target::{Depth, Pixel, Target};
use crate::texture::{modulate, Texture};
use crate::vertex::to_clip;

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
        let (mesh, params, scratch) = (self.mesh, self.params, self.vertices);
        let facing = Facing::culling(params.cull_back_faces);
        let mut stats = DrawStats {
            submitted: mesh.triangles().len() as u32,
            ..DrawStats::default()
        };
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
        for (t, tri) in mesh.triangles().iter().enumerate() {
            let tri = &tri.map(VertexIndex::to_u32);
            let v = tri.map(|i| &scratch[i as usize]);
            let union = v[0].outcode | v[1].outcode | v[2].outcode;
            let uvs = tri.map(|i| mesh.uv(i as usize));
            if union == 0 {
                let xy = v.map(|v| [v.x, v.y]);
                let area = signed_area2_xy(xy);
                if !facing.draws(area) {
                    stats.culled += 1;
                    continue;
                }
                stats.rasterized += 1;
                let Some(bounds) = pixel_bounds(xy, &target.window) else {
                    continue;
                };
                let colors = triangle_colors(mesh, params, self.lighting.as_ref(), t, tri, &v);
                let q: [[f32; 3]; 3] = core::array::from_fn(|k| {
                    let p = Vec3::from(mesh.position(tri[k] as usize));
                    // Inside the clipping volume: `w` is positive.
                    let inv_w = 1.0 / to_clip(&params.mvp, p).w;
                    [uvs[k][0] * inv_w, uvs[k][1] * inv_w, inv_w]
                });
                let order = if area < 0 { [0, 2, 1] } else { [0, 1, 2] };
                let s = order.map(|k| ScreenVertex {
                    x: v[k].x,
                    y: v[k].y,
                    z: v[k].z,
                    rgb: colors[k],
                });
                scan_textured(target, &s, &order.map(|k| q[k]), area.abs(), bounds, plot);
            } else if needs_clipping(&v, union, &mut stats) {
                let colors = triangle_colors(mesh, params, self.lighting.as_ref(), t, tri, &v);
                let viewport = &self.viewport;
                for_each_clipped(viewport, params, mesh, tri, colors, uvs, union, |s, q| {
                    let area = signed_area2(s);
                    if !facing.draws(area) {
                        stats.culled += 1;
                        return;
                    }
                    stats.rasterized += 1;
                    let Some(bounds) = pixel_bounds(s.map(|v| [v.x, v.y]), &target.window) else {
                        return;
                    };
                    let order = if area < 0 { [0, 2, 1] } else { [0, 1, 2] };
                    let (s, q) = (order.map(|k| s[k]), order.map(|k| q[k]));
                    scan_textured(target, &s, &q, area.abs(), bounds, plot);
                });
            }
        }
        self.draw_wireframe::<P, D, false>(target, &[]);
        Ok(stats)
    }
}
