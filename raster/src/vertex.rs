//! The vertex stage: transform, light, classify and project each vertex once.
//!
//! Every vertex of an indexed mesh is processed once into a caller-provided scratch slice of
//! [`ShadedVertex`], however many triangles share it. Each gets an outcode against the clipping
//! volume (see [`crate::clip`]); vertices inside it are projected and snapped right away, so a
//! triangle whose three vertices are inside goes straight to the edge stage.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::clip::{self, GUARD_BAND};
use crate::edge::{ScreenVertex, DEPTH_MAX, SUBPIXEL_ONE};
use crate::mesh::{MeshSource, VertexBatch, BATCH};

/// One directional light plus an ambient term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction from the surface towards the light, in the space the normal matrix maps to; need
    /// not be normalised.
    pub direction: Vec3,
    /// Intensity added everywhere.
    pub ambient: f32,
    /// Intensity scaled by the cosine between normal and light direction.
    pub diffuse: f32,
}

impl Default for Light {
    /// A key light from the upper right front, as in most model viewers.
    fn default() -> Self {
        Light {
            direction: Vec3::new(0.4, 0.8, 0.6),
            ambient: 0.15,
            diffuse: 0.85,
        }
    }
}

impl Light {
    /// Intensity for a (not necessarily unit) normal `n`; 0 for a zero or non-finite normal's
    /// diffuse part.
    #[inline]
    pub fn intensity(&self, n: Vec3) -> f32 {
        let l = self.direction;
        // Branch-free: half the vertices of a mesh face away from the light, unpredictably.
        // A zero normal gives 0 / tiny = 0; a NaN gives NaN, which `max` turns into 0.
        let len2 = (n.dot(n) * l.dot(l)).max(f32::MIN_POSITIVE);
        let cos = (n.dot(l) / libm::sqrtf(len2)).max(0.0);
        self.ambient + self.diffuse * cos
    }

    /// [`Light::direction`] scaled to unit length (`+z` when it is zero or not finite).
    pub fn unit_direction(&self) -> Vec3 {
        let l = self.direction;
        let len = libm::sqrtf(l.dot(l));
        if len > 0.0 && len.is_finite() {
            l / len
        } else {
            Vec3::Z
        }
    }

    /// Intensity for a normal already of unit length, given [`Light::unit_direction`]: no square
    /// root, no division.
    #[inline]
    pub fn intensity_unit(&self, n: Vec3, unit_direction: Vec3) -> f32 {
        self.ambient + self.diffuse * n.dot(unit_direction).max(0.0)
    }
}

/// A vertex after the vertex stage; the scratch element of [`crate::draw_indexed`].
///
/// Sixteen bytes, so that the scratch of a mesh of 50,000 vertices stays in a 1 MB cache: the
/// triangle loop reads its vertices in the mesh's index order, which is seldom cache friendly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct ShadedVertex {
    /// Snapped horizontal position (see [`ScreenVertex::x`]); meaningful when `outcode == 0`.
    pub x: i32,
    /// Snapped vertical position; meaningful when `outcode == 0`.
    pub y: i32,
    /// Depth (see [`ScreenVertex::z`]); meaningful when `outcode == 0`.
    pub z: f32,
    /// Lit colour.
    pub rgb: [u8; 3],
    /// Outside-bits of [`crate::clip`] (`clip::INVALID` for non-finite positions).
    pub outcode: u8,
}

impl ShadedVertex {
    /// All zeros, for `static` scratch arrays (`Default::default` is not `const`).
    pub const ZERO: ShadedVertex = ShadedVertex {
        x: 0,
        y: 0,
        z: 0.0,
        rgb: [0; 3],
        outcode: 0,
    };

    /// The vertex as the edge stage takes it.
    #[inline(always)]
    pub fn screen(&self) -> ScreenVertex {
        ScreenVertex {
            x: self.x,
            y: self.y,
            z: self.z,
            rgb: self.rgb.map(|c| c as f32),
        }
    }
}

/// Maps clip space to the viewport: what the projection of a vertex inside the clipping volume
/// needs to know about the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    half_w: f32,
    half_h: f32,
}

impl Viewport {
    /// Viewport of `width` by `height` pixels.
    pub fn new(width: usize, height: usize) -> Viewport {
        Viewport {
            half_w: width as f32 * 0.5,
            half_h: height as f32 * 0.5,
        }
    }

    /// Projects a clip-space position with `w > 0` to snapped screen coordinates and depth.
    ///
    /// Positions outside the guard band are clamped to it, so the result always stays in the range
    /// the edge stage is proven for.
    #[inline]
    pub fn project(&self, clip: Vec4, rgb: [f32; 3]) -> ScreenVertex {
        let (x, y, z) = self.project_xyz(clip.x, clip.y, clip.z, clip.w);
        ScreenVertex { x, y, z, rgb }
    }

    /// [`Viewport::project`] on loose coordinates, branch-free so that [`shade_vertices`] can run
    /// it on eight vertices at once.
    #[inline(always)]
    #[allow(clippy::manual_clamp)] // `f32::clamp` keeps NaN; `max` then `min` maps it into range
    fn project_xyz(&self, x: f32, y: f32, z: f32, w: f32) -> (i32, i32, f32) {
        let inv_w = 1.0 / w;
        let limit = GUARD_BAND + 1.0;
        let nx = clamp_sym(x * inv_w, limit);
        let ny = clamp_sym(y * inv_w, limit);
        let nz = (z * inv_w).max(0.0).min(1.0);
        let sub = SUBPIXEL_ONE as f32;
        (
            round((nx + 1.0) * self.half_w * sub),
            round((1.0 - ny) * self.half_h * sub),
            nz * DEPTH_MAX as f32,
        )
    }
}

/// Rounds to the nearest integer, ties to even, for `|v| < 2^22`: adding 1.5 * 2^23 leaves the
/// integer in the low mantissa bits, read off by a bit cast. One IEEE addition, the same on every
/// target, several times cheaper than `libm::roundf` and, unlike a saturating `as` conversion, it
/// vectorizes. Callers clamp first: snapped coordinates stay below 2^22 (see [`crate::edge`]).
#[inline(always)]
fn round(v: f32) -> i32 {
    const MAGIC: f32 = 12_582_912.0;
    (v + MAGIC).to_bits() as i32 - MAGIC.to_bits() as i32
}

/// Clamps to `[-limit, limit]`; NaN becomes `-limit` (it cannot occur for a vertex that passed
/// [`clip::outcode`], but the edge stage's range must not depend on that).
#[inline(always)]
fn clamp_sym(v: f32, limit: f32) -> f32 {
    v.max(-limit).min(limit)
}

/// Object space to clip space, the one way both the vertex stage and clipping compute it.
#[inline(always)]
pub fn to_clip(mvp: &Mat4, position: Vec3) -> Vec4 {
    mvp.x_axis * position.x + mvp.y_axis * position.y + mvp.z_axis * position.z + mvp.w_axis
}

/// What lit shading needs per vertex.
#[derive(Clone, Copy, Debug)]
pub struct VertexLighting<'a> {
    /// Maps normals into the light's space.
    pub normal_matrix: &'a Mat3,
    /// The light.
    pub light: &'a Light,
    /// The normals are of unit length after the normal matrix: skip renormalizing them.
    pub unit_normals: bool,
}

impl VertexLighting<'_> {
    /// What stays the same for every vertex of a draw.
    pub fn prepare(&self) -> PreparedLighting {
        PreparedLighting {
            columns: (*self.normal_matrix != Mat3::IDENTITY)
                .then(|| self.normal_matrix.to_cols_array_2d()),
            unit_direction: self.light.unit_direction(),
            unit_normals: self.unit_normals,
            light: *self.light,
        }
    }
}

/// [`VertexLighting`] prepared for a draw: the one place a vertex's light intensity is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedLighting {
    columns: Option<[[f32; 3]; 3]>,
    unit_direction: Vec3,
    unit_normals: bool,
    light: Light,
}

impl PreparedLighting {
    /// Intensity at a vertex with object-space normal `n`.
    #[inline(always)]
    pub fn intensity(&self, n: Vec3) -> f32 {
        match (self.columns.is_some(), self.unit_normals) {
            (false, false) => self.lane::<false, false>(n),
            (false, true) => self.lane::<false, true>(n),
            (true, false) => self.lane::<true, false>(n),
            (true, true) => self.lane::<true, true>(n),
        }
    }

    /// [`PreparedLighting::intensity`] of a batch of normals, attribute by attribute: the choice
    /// of formula made once for the batch, so that the lanes run straight (and in SIMD registers).
    #[inline(always)]
    fn intensities(&self, n: &[[f32; BATCH]; 3], out: &mut [f32; BATCH]) {
        match (self.columns.is_some(), self.unit_normals) {
            (false, false) => self.lanes::<false, false>(n, out),
            (false, true) => self.lanes::<false, true>(n, out),
            (true, false) => self.lanes::<true, false>(n, out),
            (true, true) => self.lanes::<true, true>(n, out),
        }
    }

    #[inline(always)]
    fn lanes<const ROTATE: bool, const UNIT: bool>(
        &self,
        n: &[[f32; BATCH]; 3],
        out: &mut [f32; BATCH],
    ) {
        for (k, l) in out.iter_mut().enumerate() {
            *l = self.lane::<ROTATE, UNIT>(Vec3::new(n[0][k], n[1][k], n[2][k]));
        }
    }

    /// One normal's intensity: rotated by the normal matrix when `ROTATE` (object-space
    /// lighting, the common case, skips the identity product), then lit as a unit normal when
    /// `UNIT`.
    #[inline(always)]
    fn lane<const ROTATE: bool, const UNIT: bool>(&self, n: Vec3) -> f32 {
        let n = match (ROTATE, &self.columns) {
            (true, Some(m)) => Vec3::new(
                m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
                m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
                m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z,
            ),
            _ => n,
        };
        if UNIT {
            self.light.intensity_unit(n, self.unit_direction)
        } else {
            self.light.intensity(n)
        }
    }
}

/// Runs the vertex stage over a whole mesh.
///
/// Vertices go through in batches of eight, attribute by attribute (structure of arrays), so that
/// the compiler can use SIMD registers. Each lane runs the same per-vertex routines the clipping
/// path uses ([`to_clip`]'s order of operations, [`Viewport::project`], [`clip::outcode`],
/// [`PreparedLighting::intensity`]), so both agree to the bit, on every target (a SIMD lane rounds
/// as a scalar operation does). `lighting`, when given, lights the vertices by their normals;
/// vertices take the mesh's colours, or `base` when it has none.
///
/// `out` must hold exactly the mesh's vertices ([`crate::shade`] checks this). Returns the union
/// of their outcodes: 0 when every vertex is inside the clipping volume, so that no triangle
/// needs its own outcodes looked at.
#[inline]
pub fn shade_vertices<M: MeshSource>(
    mvp: &Mat4,
    viewport: &Viewport,
    mesh: &M,
    lighting: Option<&PreparedLighting>,
    base: [f32; 3],
    out: &mut [ShadedVertex],
) -> u8 {
    let stage = Stage {
        m: mvp.to_cols_array_2d(),
        viewport,
        lighting,
        base,
        colors: mesh.has_colors(),
    };
    // Whole batches as fixed-size arrays, so that every lane loop is unrolled and runs in SIMD
    // registers; only the last, partial batch takes the variable-length path.
    let whole = out.len() - out.len() % BATCH;
    let mut batches = out.chunks_exact_mut(BATCH);
    // One batch of inputs for the whole batches, zeroed once: each fills every lane of what it
    // has (see `MeshSource::batch`), so zeroing it for every batch (a `memset` call) was waste.
    let mut input = VertexBatch::default();
    let mut union = 0;
    for (first, out) in (0..).step_by(BATCH).zip(&mut batches) {
        if let Ok(out) = <&mut [ShadedVertex; BATCH]>::try_from(out) {
            union |= stage.batch(mesh, first, BATCH, &mut input, out);
        }
    }
    let tail = batches.into_remainder();
    if !tail.is_empty() {
        let mut lanes = [ShadedVertex::ZERO; BATCH];
        let len = tail.len();
        union |= stage.batch(mesh, whole, len, &mut VertexBatch::default(), &mut lanes);
        tail.copy_from_slice(&lanes[..len]);
    }
    union
}

/// What the vertex stage keeps the same for every vertex of a draw.
#[derive(Clone, Copy)]
struct Stage<'a> {
    /// The matrix's columns.
    m: [[f32; 4]; 4],
    viewport: &'a Viewport,
    lighting: Option<&'a PreparedLighting>,
    /// Colour of vertices when the mesh has none.
    base: [f32; 3],
    /// Whether the mesh has vertex colours.
    colors: bool,
}

impl Stage<'_> {
    /// Vertices `first..first + len` into the first `len` of `out`, read through `batch`;
    /// returns the union of those vertices' outcodes.
    #[inline(always)]
    fn batch<M: MeshSource>(
        &self,
        mesh: &M,
        first: usize,
        len: usize,
        batch: &mut VertexBatch,
        out: &mut [ShadedVertex; BATCH],
    ) -> u8 {
        let Stage {
            m,
            viewport,
            lighting,
            base,
            colors,
        } = *self;
        // Gather the batch; lanes past the end of the mesh hold zeros and are not stored.
        mesh.batch(first, len, batch);
        // Read in place: moving the arrays out copied them through registers.
        if !colors {
            for (channel, b) in batch.colors.iter_mut().zip(base) {
                *channel = [b; BATCH];
            }
        }
        let rgb = &batch.colors;

        let clip = transform(&m, &batch.positions);
        let mut light = [1.0f32; BATCH];
        if let Some(p) = lighting {
            p.intensities(&batch.normals, &mut light);
        }
        // Attribute by attribute here too: an array of tuples would be vectorized vertex by
        // vertex, with shuffles between the stages.
        let (mut sx, mut sy, mut sz) = ([0i32; BATCH], [0i32; BATCH], [0.0f32; BATCH]);
        for k in 0..BATCH {
            (sx[k], sy[k], sz[k]) =
                viewport.project_xyz(clip[0][k], clip[1][k], clip[2][k], clip[3][k]);
        }
        // Colour and outcode packed in one 32-bit lane (the record's last four bytes, little end
        // first), so that each record is stored as four words rather than byte by byte.
        let mut packed = [0u32; BATCH];
        for (k, word) in packed.iter_mut().enumerate() {
            let channel = |a: usize| saturate_u8(rgb[a][k] * light[k]) as u32;
            let code = clip::outcode(Vec4::new(clip[0][k], clip[1][k], clip[2][k], clip[3][k]));
            *word = channel(0) | channel(1) << 8 | channel(2) << 16 | (code as u32) << 24;
        }
        for (k, v) in out.iter_mut().enumerate() {
            let [r, g, b, outcode] = packed[k].to_le_bytes();
            *v = ShadedVertex {
                x: sx[k],
                y: sy[k],
                z: sz[k],
                rgb: [r, g, b],
                outcode,
            };
        }
        (packed.iter().take(len).fold(0, |u, &w| u | w) >> 24) as u8
    }
}

/// Clip space of a batch of positions, in the order of `to_clip`: x, y, z columns, then the
/// translation. Out of line where there are vector registers, so that it is vectorized lane by
/// lane on its own (inlined, the vectorizer laid the lanes out vertex by vertex for the stages
/// after it, and shuffled them); inlined on a processor without them (a Cortex-M7 drew 0.7%
/// more instructions with the call).
#[cfg_attr(any(target_arch = "x86_64", target_arch = "aarch64"), inline(never))]
#[cfg_attr(
    not(any(target_arch = "x86_64", target_arch = "aarch64")),
    inline(always)
)]
fn transform(m: &[[f32; 4]; 4], p: &[[f32; BATCH]; 3]) -> [[f32; BATCH]; 4] {
    core::array::from_fn(|r| {
        let [a, b, c, d] = [m[0][r], m[1][r], m[2][r], m[3][r]];
        let [x, y, z] = p;
        let mut row = [0.0f32; BATCH];
        for half in 0..BATCH / 4 {
            for j in 0..4 {
                let k = 4 * half + j;
                row[k] = a * x[k] + b * y[k] + c * z[k] + d;
            }
        }
        row
    })
}

/// Rounds a colour channel to `0..=255`, ties to even (NaN becomes 0).
#[inline(always)]
#[allow(clippy::manual_clamp)] // NaN must map into range
pub fn saturate_u8(c: f32) -> u8 {
    round(c.max(0.0).min(255.0)) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projects_device_corners_to_viewport_corners() {
        let vp = Viewport::new(320, 240);
        let top_left = vp.project(Vec4::new(-2.0, 2.0, 0.0, 2.0), [0.0; 3]);
        assert_eq!((top_left.x, top_left.y, top_left.z), (0, 0, 0.0));
        let bottom_right = vp.project(Vec4::new(1.0, -1.0, 1.0, 1.0), [0.0; 3]);
        assert_eq!(
            (bottom_right.x, bottom_right.y),
            (320 * SUBPIXEL_ONE, 240 * SUBPIXEL_ONE)
        );
        assert_eq!(bottom_right.z, DEPTH_MAX as f32);
    }

    #[test]
    fn light_faces_and_turns_away() {
        let l = Light {
            direction: Vec3::Y,
            ambient: 0.25,
            diffuse: 0.5,
        };
        assert_eq!(l.intensity(Vec3::new(0.0, 3.0, 0.0)), 0.75);
        assert_eq!(l.intensity(-Vec3::Y), 0.25);
        assert_eq!(l.intensity(Vec3::ZERO), 0.25);
        assert_eq!(l.intensity(Vec3::splat(f32::NAN)), 0.25);
    }

    /// Unlit vertex stage for up to 19 vertices, on the stack (the crate has no allocator).
    fn shade(positions: &[[f32; 3]], mvp: &Mat4, vp: &Viewport) -> [ShadedVertex; 19] {
        let mut out = [ShadedVertex::default(); 19];
        let n = positions.len();
        let mesh: crate::Mesh<'_> = crate::Mesh {
            positions,
            ..crate::Mesh::default()
        };
        shade_vertices(mvp, vp, &mesh, None, [10.0, 20.0, 30.0], &mut out[..n]);
        out
    }

    /// The vertex stage's union of outcodes is the union of the vertices', whichever vertex is
    /// outside: in a whole batch, in the partial one, or none; lanes past the end (zeros: the
    /// eye, outside) do not count.
    #[test]
    fn the_union_of_outcodes_is_the_vertices_union() {
        let mvp = Mat4::perspective_rh(1.0, 1.0, 0.5, 10.0)
            * Mat4::look_at_rh(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
        let vp = Viewport::new(8, 8);
        let mut eye = [ShadedVertex::ZERO; 1];
        let origin = [[0.0f32; 3]];
        let m = crate::Mesh::<u32> {
            positions: &origin,
            ..crate::Mesh::default()
        };
        shade_vertices(&mvp, &vp, &m, None, [0.0; 3], &mut eye);
        assert_ne!(eye[0].outcode, 0, "the eye is outside");
        for n in [3, 8, 16, 19] {
            for out_at in (0..n).map(Some).chain([None]) {
                let mut positions = [[0.0, 0.0, -3.0]; 19];
                positions[0][0] = 0.5; // still in view
                if let Some(k) = out_at {
                    positions[k] = [0.0, 0.0, 3.0]; // behind the eye
                }
                let m = crate::Mesh::<u32> {
                    positions: &positions[..n],
                    ..crate::Mesh::default()
                };
                let mut out = [ShadedVertex::ZERO; 19];
                let union = shade_vertices(&mvp, &vp, &m, None, [0.0; 3], &mut out[..n]);
                let want = out[..n].iter().fold(0, |u, v| u | v.outcode);
                assert_eq!(union, want, "{n} vertices, outside at {out_at:?}");
                assert_eq!(
                    union != 0,
                    out_at.is_some(),
                    "{n} vertices, outside at {out_at:?}"
                );
            }
        }
    }

    #[test]
    fn classifies_behind_camera_and_non_finite() {
        let vp = Viewport::new(8, 8);
        let out = shade(
            &[[0.0, 0.0, -1.0], [f32::NAN, 0.0, 0.5], [0.0, 0.0, 0.5]],
            &Mat4::IDENTITY,
            &vp,
        );
        assert_ne!(out[0].outcode & clip::NEAR, 0);
        assert_ne!(out[1].outcode & clip::INVALID, 0);
        assert_eq!(out[2].outcode, 0);
        assert_eq!(out[2].rgb, [10, 20, 30]);
    }

    #[test]
    fn batches_agree_with_the_per_vertex_routines() {
        // 19 vertices: two full batches of eight and a partial one.
        let mut positions = [[0.0f32; 3]; 19];
        for (i, p) in positions.iter_mut().enumerate() {
            let t = i as f32;
            *p = [
                libm::sinf(t) * 1.7,
                libm::cosf(1.3 * t) * 1.1,
                libm::sinf(0.7 * t) * 2.5,
            ];
        }
        let mvp = Mat4::perspective_rh(1.1, 1.5, 0.2, 20.0)
            * Mat4::look_at_rh(Vec3::new(0.5, 0.8, 3.0), Vec3::ZERO, Vec3::Y);
        let vp = Viewport::new(96, 64);
        let out = shade(&positions, &mvp, &vp);
        for (p, v) in positions.iter().zip(&out) {
            let c = to_clip(&mvp, Vec3::from(*p));
            let s = vp.project(c, [0.0; 3]);
            assert_eq!(
                (v.x, v.y, v.z, v.outcode),
                (s.x, s.y, s.z, clip::outcode(c))
            );
        }
    }
    #[test]
    fn rounds_half_to_even_like_libm_rint() {
        for v in [
            0.5f32,
            1.5,
            2.5,
            -0.5,
            -1.5,
            1234.49,
            -1234.51,
            4_000_000.5,
            0.0,
        ] {
            assert_eq!(round(v), libm::rintf(v) as i32, "{v}");
        }
    }

    #[test]
    fn saturates_channels() {
        assert_eq!(saturate_u8(300.0), 255);
        assert_eq!(saturate_u8(-3.0), 0);
        assert_eq!(saturate_u8(f32::NAN), 0);
        assert_eq!(saturate_u8(127.6), 128);
        assert_eq!(saturate_u8(0.5), 0);
        assert_eq!(saturate_u8(1.5), 2);
    }
}
