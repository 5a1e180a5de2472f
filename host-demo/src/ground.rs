//! A terrain's colours as a texture over the ground plane (`vdlod-demo terrain --texture`).
//!
//! A terrain's vertices stand over the sample they come from, and a coarse vertex over the ground
//! it spans, so texture coordinates from where a vertex stands (`x`, `z`) put every sample's colour
//! where it belongs whatever the engine and the cut: the colours keep their detail where the mesh
//! is coarse, instead of being averaged into the few vertices left (see `reproduce textures`).

use vdlod::{Camera, Style};
use vdlod_raster::texture::{Filter, Texture, TextureError, Wrap};
use vdlod_raster::{DrawError, MeshSource, Rgba8, SourceVertex, Uv, VertexBatch};

use crate::frame::{Frame, FrameError};
use crate::terrain::Terrain;

/// One texel per sample of a terrain's colours.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundTexture {
    texels: Vec<Rgba8>,
    width: usize,
    depth: usize,
}

impl GroundTexture {
    /// The texture of `terrain`'s colours (`None` without colours).
    pub fn of(terrain: &Terrain) -> Option<GroundTexture> {
        let colors = terrain.colors.as_ref()?;
        Some(GroundTexture {
            texels: colors
                .iter()
                .map(|c| Rgba8([c[0], c[1], c[2], 255]))
                .collect(),
            width: terrain.width,
            depth: terrain.depth,
        })
    }

    /// The texels, sampled bilinearly and clamped at the terrain's edges.
    pub fn texture(&self) -> Result<Texture<'_, Rgba8>, TextureError> {
        Texture::new(
            &self.texels,
            self.width,
            self.depth,
            Filter::Bilinear,
            Wrap::Clamp,
        )
    }

    /// Texture coordinates of a point over the ground: sample `(c, r)` at texel `(c, r)`'s centre.
    pub fn uv(&self, p: [f32; 3]) -> Uv {
        [
            (p[0] + 0.5) / self.width as f32,
            (p[2] + 0.5) / self.depth as f32,
        ]
    }
}

/// `mesh` with texture coordinates from where its vertices stand over the ground, and without
/// vertex colours (the texture colours it).
#[derive(Clone, Copy, Debug)]
pub struct OnGround<'a, M> {
    /// The mesh.
    pub mesh: &'a M,
    /// The ground's texture.
    pub ground: &'a GroundTexture,
}

impl<M: MeshSource> MeshSource for OnGround<'_, M> {
    type Index = M::Index;

    fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    fn triangles(&self) -> &[[M::Index; 3]] {
        self.mesh.triangles()
    }

    #[inline]
    fn vertex(&self, i: usize) -> SourceVertex {
        self.mesh.vertex(i)
    }

    #[inline]
    fn batch(&self, first: usize, len: usize, out: &mut VertexBatch) {
        self.mesh.batch(first, len, out);
    }

    #[inline]
    fn position(&self, i: usize) -> [f32; 3] {
        self.mesh.position(i)
    }

    fn has_normals(&self) -> bool {
        self.mesh.has_normals()
    }

    fn has_colors(&self) -> bool {
        false
    }

    fn has_uvs(&self) -> bool {
        true
    }

    #[inline]
    fn uv(&self, i: usize) -> Uv {
        self.ground.uv(self.mesh.position(i))
    }

    fn check(&self) -> Result<(), DrawError> {
        self.mesh.check()
    }
}

/// `mesh` into `frame`, textured by `ground` (white under the light, whatever `style`'s colours).
pub fn draw_on_ground<M: MeshSource>(
    frame: &mut Frame,
    mesh: &M,
    camera: &Camera,
    style: &Style,
    ground: &GroundTexture,
) -> Result<(), FrameError> {
    let texture = ground.texture().map_err(FrameError::Texture)?;
    let on = OnGround { mesh, ground };
    let white = Style {
        base_color: [255; 3],
        vertex_colors: false,
        ..*style
    };
    frame
        .draw_textured(&on, camera, &white, &texture)
        .map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::DEFAULT_VERTICAL_SCALE;

    #[test]
    fn a_sample_reads_its_own_colour() {
        let land = Terrain::procedural(9, 2, DEFAULT_VERTICAL_SCALE);
        let ground = GroundTexture::of(&land).unwrap();
        let texture = ground.texture().unwrap();
        let colors = land.colors.as_ref().unwrap();
        for r in 0..9 {
            for c in 0..9 {
                let uv = ground.uv([c as f32, 123.0, r as f32]);
                assert_eq!(texture.sample(uv[0], uv[1]), colors[r * 9 + c], "{c} {r}");
            }
        }
        // The full mesh over it: no vertex colours, coordinates from the positions.
        let full = land.mesh();
        let mesh = full.as_raster_mesh();
        let on = OnGround {
            mesh: &mesh,
            ground: &ground,
        };
        assert!(on.has_uvs() && !on.has_colors());
        let p = on.position(10);
        assert_eq!(on.uv(10), ground.uv(p));
    }
}
