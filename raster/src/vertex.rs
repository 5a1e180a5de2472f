//! The vertex stage: transform, light, classify and project each vertex once.
//!
//! Every vertex of an indexed mesh is processed once into a caller-provided scratch slice of
//! [`ShadedVertex`], however many triangles share it. Each gets an outcode against the clipping
//! volume (see [`crate::clip`]); vertices inside it are projected and snapped right away, so a
//! triangle whose three vertices are inside goes straight to the edge stage.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::clip::{self, GUARD_BAND};
use crate::edge::{ScreenVertex, DEPTH_MAX, SUBPIXEL_ONE};

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
        let inv_w = 1.0 / clip.w;
        let limit = GUARD_BAND + 1.0;
        let nx = clamp_sym(clip.x * inv_w, limit);
        let ny = clamp_sym(clip.y * inv_w, limit);
        let nz = clip.z * inv_w;
        let nz = if nz > 0.0 {
            if nz < 1.0 {
                nz
            } else {
                1.0
            }
        } else {
            0.0
        };
        let sub = SUBPIXEL_ONE as f32;
        ScreenVertex {
            x: round((nx + 1.0) * self.half_w * sub),
            y: round((1.0 - ny) * self.half_h * sub),
            z: nz * DEPTH_MAX as f32,
            rgb,
        }
    }
}

/// Rounds to the nearest integer, ties to even, for `|v| < 2^22`: adding and subtracting 1.5 * 2^23
/// leaves no fraction bits, a basic IEEE operation pair that rounds the same on every target and
/// is several times cheaper than `libm::roundf`. Snapped coordinates stay below 2^22 (see
/// [`crate::edge`]).
#[inline(always)]
fn round(v: f32) -> i32 {
    const MAGIC: f32 = 12_582_912.0;
    ((v + MAGIC) - MAGIC) as i32
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
    *mvp * position.extend(1.0)
}

/// Transforms, lights and classifies one vertex.
///
/// `rgb` is the vertex's unlit colour in `0.0..=255.0`, multiplied by `light`.
#[inline]
pub fn shade_vertex(
    mvp: &Mat4,
    viewport: &Viewport,
    position: Vec3,
    light: f32,
    rgb: [f32; 3],
) -> ShadedVertex {
    let clip = to_clip(mvp, position);
    let outcode = clip::outcode(clip);
    let rgb = rgb.map(|c| saturate_u8(c * light));
    if outcode == 0 {
        let s = viewport.project(clip, [0.0; 3]);
        ShadedVertex {
            x: s.x,
            y: s.y,
            z: s.z,
            rgb,
            outcode,
        }
    } else {
        ShadedVertex {
            rgb,
            outcode,
            ..ShadedVertex::default()
        }
    }
}

/// Rounds a colour channel to `0..=255` (NaN becomes 0).
#[inline(always)]
pub fn saturate_u8(c: f32) -> u8 {
    (c + 0.5) as u8
}

/// Intensity of `light` on `normal` after `normal_matrix`.
#[inline(always)]
pub fn light_normal(normal_matrix: &Mat3, light: &Light, normal: Vec3) -> f32 {
    light.intensity(*normal_matrix * normal)
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

    #[test]
    fn classifies_behind_camera_and_non_finite() {
        let vp = Viewport::new(8, 8);
        let behind = shade_vertex(
            &Mat4::IDENTITY,
            &vp,
            Vec3::new(0.0, 0.0, -1.0),
            1.0,
            [0.0; 3],
        );
        assert_ne!(behind.outcode & clip::NEAR, 0);
        let nan = shade_vertex(
            &Mat4::IDENTITY,
            &vp,
            Vec3::new(f32::NAN, 0.0, 0.5),
            1.0,
            [0.0; 3],
        );
        assert_ne!(nan.outcode & clip::INVALID, 0);
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
    }
}
