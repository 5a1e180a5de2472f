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
        let len2 = n.dot(n) * l.dot(l);
        let cos = if len2 > 0.0 {
            n.dot(l) / libm::sqrtf(len2)
        } else {
            0.0
        };
        let cos = if cos > 0.0 { cos } else { 0.0 };
        self.ambient + self.diffuse * cos
    }
}

/// A vertex after the vertex stage; the scratch element of [`crate::draw_indexed`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadedVertex {
    /// Homogeneous clip-space position.
    pub clip: Vec4,
    /// Projected vertex; meaningful only when `outcode == 0`.
    pub screen: ScreenVertex,
    /// Light intensity at the vertex (1 when unlit).
    pub light: f32,
    /// Outside-bits of [`crate::clip`] (`clip::INVALID` for non-finite positions).
    pub outcode: u8,
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
            x: libm::roundf((nx + 1.0) * self.half_w * sub) as i32,
            y: libm::roundf((1.0 - ny) * self.half_h * sub) as i32,
            z: nz * DEPTH_MAX as f32,
            rgb,
        }
    }
}

#[inline(always)]
fn clamp_sym(v: f32, limit: f32) -> f32 {
    if v > limit {
        limit
    } else if v < -limit {
        -limit
    } else if v == v {
        v
    } else {
        0.0
    }
}

/// Transforms, lights and classifies one vertex.
///
/// `rgb` is the vertex's unlit colour in `0.0..=255.0`; the returned screen colour is lit with
/// `light` (pass `None` for unlit shading).
#[inline]
pub fn shade_vertex(
    mvp: &Mat4,
    viewport: &Viewport,
    position: Vec3,
    lighting: Option<(&Mat3, &Light, Vec3)>,
    rgb: [f32; 3],
) -> ShadedVertex {
    let clip = *mvp * position.extend(1.0);
    let light = match lighting {
        Some((normal_matrix, light, normal)) => light.intensity(*normal_matrix * normal),
        None => 1.0,
    };
    let rgb = rgb.map(|c| c * light);
    let outcode = clip::outcode(clip);
    let screen = if outcode == 0 {
        viewport.project(clip, rgb)
    } else {
        ScreenVertex {
            rgb,
            ..ScreenVertex::default()
        }
    };
    ShadedVertex {
        clip,
        screen,
        light,
        outcode,
    }
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
            None,
            [0.0; 3],
        );
        assert_ne!(behind.outcode & clip::NEAR, 0);
        let nan = shade_vertex(
            &Mat4::IDENTITY,
            &vp,
            Vec3::new(f32::NAN, 0.0, 0.5),
            None,
            [0.0; 3],
        );
        assert_ne!(nan.outcode & clip::INVALID, 0);
    }
}
