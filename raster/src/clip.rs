//! Homogeneous clipping against the near and far planes, `w > 0`, and a guard band.
//!
//! Only triangles with a vertex outside the clipping volume come here; most of a mesh goes
//! straight from the vertex stage to the edge stage. The volume is the view frustum widened to
//! [`GUARD_BAND`] times its width and height: triangles that merely poke out of the viewport are not
//! clipped in x and y (the edge stage's bounding box does that for free), but nothing that reaches
//! the edge stage can be behind the camera, at infinity, or far enough out to overflow fixed point.
//! Triangles with a non-finite vertex are dropped whole.
//!
//! A shared edge is always cut from its inside end towards its outside end, so two triangles
//! sharing an edge get bit-identical intersection points and stay watertight after clipping.

use glam::Vec4;

/// Half-extent of the clipping volume in normalised device units (the viewport is 1).
pub const GUARD_BAND: f32 = 4.0;
/// Smallest `w` kept: guards the perspective divide for projections with no near plane in `z`.
pub const W_MIN: f32 = 1.0e-5;

/// Outside `x >= -GUARD_BAND * w`.
pub const LEFT: u8 = 1 << 0;
/// Outside `x <= GUARD_BAND * w`.
pub const RIGHT: u8 = 1 << 1;
/// Outside `y >= -GUARD_BAND * w`.
pub const BOTTOM: u8 = 1 << 2;
/// Outside `y <= GUARD_BAND * w`.
pub const TOP: u8 = 1 << 3;
/// Outside `z >= 0` (the near plane, depth range `0..=1` as in Direct3D, Vulkan and glam's
/// `perspective_rh`).
pub const NEAR: u8 = 1 << 4;
/// Outside `z <= w` (the far plane).
pub const FAR: u8 = 1 << 5;
/// Outside `w >= W_MIN`.
pub const W_POSITIVE: u8 = 1 << 6;
/// A coordinate is NaN or infinite: the vertex cannot be clipped.
pub const INVALID: u8 = 1 << 7;

const PLANES: [u8; 7] = [NEAR, W_POSITIVE, FAR, LEFT, RIGHT, BOTTOM, TOP];

/// At most one vertex per plane is added to a triangle.
pub const MAX_POLYGON: usize = 3 + PLANES.len();

/// Signed distance-like value of `p` to `plane`, negative outside; [`outcode`] computes the same
/// expressions for all planes at once.
#[inline(always)]
fn distance(plane: u8, p: Vec4) -> f32 {
    let g = GUARD_BAND * p.w;
    match plane {
        LEFT => p.x + g,
        RIGHT => g - p.x,
        BOTTOM => p.y + g,
        TOP => g - p.y,
        NEAR => p.z,
        FAR => p.w - p.z,
        _ => p.w - W_MIN,
    }
}

/// The planes `p` is outside of, or [`INVALID`].
#[inline]
pub fn outcode(p: Vec4) -> u8 {
    // Branch-free, so the vertex stage's loop stays straight: bits by comparison, then a select.
    let finite = p.x.is_finite() & p.y.is_finite() & p.z.is_finite() & p.w.is_finite();
    let g = GUARD_BAND * p.w;
    let code = ((p.x + g < 0.0) as u8 * LEFT)
        | ((g - p.x < 0.0) as u8 * RIGHT)
        | ((p.y + g < 0.0) as u8 * BOTTOM)
        | ((g - p.y < 0.0) as u8 * TOP)
        | ((p.z < 0.0) as u8 * NEAR)
        | ((p.w - p.z < 0.0) as u8 * FAR)
        | ((p.w - W_MIN < 0.0) as u8 * W_POSITIVE);
    if finite {
        code
    } else {
        INVALID
    }
}

/// A clip-space vertex carrying its colour and texture coordinates through clipping.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipVertex {
    /// Homogeneous position.
    pub pos: Vec4,
    /// Colour in `0.0..=255.0`.
    pub rgb: [f32; 3],
    /// Texture coordinates (zeros for an untextured draw).
    pub uv: [f32; 2],
}

impl ClipVertex {
    fn lerp(a: &ClipVertex, b: &ClipVertex, t: f32) -> ClipVertex {
        ClipVertex {
            pos: a.pos + (b.pos - a.pos) * t,
            rgb: core::array::from_fn(|k| a.rgb[k] + (b.rgb[k] - a.rgb[k]) * t),
            uv: core::array::from_fn(|k| a.uv[k] + (b.uv[k] - a.uv[k]) * t),
        }
    }
}

/// A convex polygon of at most [`MAX_POLYGON`] vertices, on the stack.
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    verts: [ClipVertex; MAX_POLYGON],
    len: usize,
}

impl Polygon {
    fn empty() -> Polygon {
        Polygon {
            verts: [ClipVertex::default(); MAX_POLYGON],
            len: 0,
        }
    }

    fn push(&mut self, v: ClipVertex) {
        if let Some(slot) = self.verts.get_mut(self.len) {
            *slot = v;
            self.len += 1;
        }
    }

    /// The vertices, in the winding order of the input triangle.
    pub fn vertices(&self) -> &[ClipVertex] {
        &self.verts[..self.len]
    }
}

/// Puts a cut exactly on its plane. With huge coordinates (say 1e30 at one end of an edge and
/// -1e30 at the other) the interpolated coordinate across the plane loses all precision to
/// cancellation; the plane equation gives it back exactly.
#[inline]
fn snap_to_plane(plane: u8, p: &mut Vec4) {
    let g = GUARD_BAND * p.w;
    match plane {
        LEFT => p.x = -g,
        RIGHT => p.x = g,
        BOTTOM => p.y = -g,
        TOP => p.y = g,
        NEAR => p.z = 0.0,
        FAR => p.z = p.w,
        _ => p.w = p.w.max(W_MIN),
    }
}

/// Clips a triangle against the planes named in `planes` (the union of its vertices' outcodes).
///
/// The result has fewer than three vertices when nothing is left. Triangles with an [`INVALID`]
/// vertex must not be passed (their clipped shape is undefined); [`crate::draw_indexed`] drops
/// them.
///
/// ```
/// use glam::Vec4;
/// use vdlod_raster::clip::{clip_triangle, outcode, ClipVertex};
/// let v = |x: f32, z: f32| ClipVertex { pos: Vec4::new(x, 0.0, z, 1.0), ..ClipVertex::default() };
/// let tri = [v(0.0, -1.0), v(1.0, 0.5), v(-1.0, 0.5)]; // first vertex behind the near plane
/// let planes = tri.iter().fold(0, |acc, v| acc | outcode(v.pos));
/// let poly = clip_triangle(&tri, planes);
/// assert_eq!(poly.vertices().len(), 4);
/// assert!(poly.vertices().iter().all(|v| v.pos.z >= 0.0));
/// ```
pub fn clip_triangle(tri: &[ClipVertex; 3], planes: u8) -> Polygon {
    let mut poly = Polygon::empty();
    for v in tri {
        poly.push(*v);
    }
    for plane in PLANES {
        if planes & plane == 0 {
            continue;
        }
        let mut next = Polygon::empty();
        let verts = poly.vertices();
        for (i, cur) in verts.iter().enumerate() {
            let nxt = &verts[(i + 1) % verts.len()];
            let (dc, dn) = (distance(plane, cur.pos), distance(plane, nxt.pos));
            if dc >= 0.0 {
                next.push(*cur);
            }
            if (dc >= 0.0) != (dn >= 0.0) {
                // Always cut from the inside end, so both triangles of an edge agree.
                let mut cut = if dc >= 0.0 {
                    ClipVertex::lerp(cur, nxt, dc / (dc - dn))
                } else {
                    ClipVertex::lerp(nxt, cur, dn / (dn - dc))
                };
                snap_to_plane(plane, &mut cut.pos);
                next.push(cut);
            }
        }
        poly = next;
        if poly.len < 3 {
            break;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cv(x: f32, y: f32, z: f32, w: f32) -> ClipVertex {
        ClipVertex {
            pos: Vec4::new(x, y, z, w),
            rgb: [x, y, z],
            uv: [x, y],
        }
    }

    #[test]
    fn outcodes() {
        assert_eq!(outcode(Vec4::new(0.0, 0.0, 0.5, 1.0)), 0);
        assert_eq!(outcode(Vec4::new(-5.0, 0.0, 0.5, 1.0)), LEFT);
        assert_eq!(outcode(Vec4::new(0.0, 5.0, 0.5, 1.0)), TOP);
        assert_eq!(outcode(Vec4::new(0.0, 0.0, 2.0, 1.0)), FAR);
        assert_eq!(outcode(Vec4::new(0.0, 0.0, -0.1, 0.0)), NEAR | W_POSITIVE);
        assert_eq!(outcode(Vec4::new(f32::INFINITY, 0.0, 0.5, 1.0)), INVALID);
        assert_eq!(outcode(Vec4::new(0.0, f32::NAN, 0.5, 1.0)), INVALID);
    }

    #[test]
    fn fully_outside_clips_to_nothing() {
        let tri = [
            cv(0.0, 0.0, -1.0, 1.0),
            cv(1.0, 0.0, -2.0, 1.0),
            cv(0.0, 1.0, -1.0, 1.0),
        ];
        assert!(clip_triangle(&tri, NEAR).vertices().len() < 3);
    }

    #[test]
    fn shared_edge_cuts_are_bit_identical() {
        let a = cv(0.3, 0.1, -0.7, 1.0);
        let b = cv(-0.2, 0.4, 0.9, 1.3);
        let c = cv(0.5, -0.6, 0.4, 1.1);
        let d = cv(-0.9, -0.3, 0.2, 0.8);
        let p1 = clip_triangle(&[a, b, c], NEAR);
        let p2 = clip_triangle(&[b, a, d], NEAR);
        // Besides b itself, the only vertex both polygons can share is where edge a-b crosses z = 0,
        // computed once from a-to-b and once from b-to-a.
        let shared = p1
            .vertices()
            .iter()
            .filter(|v| v.pos != b.pos && p2.vertices().iter().any(|u| u == *v))
            .count();
        assert_eq!(shared, 1);
    }

    #[test]
    fn clipped_polygon_is_inside_every_plane() {
        let tri = [
            cv(-100.0, 3.0, -5.0, 0.5),
            cv(50.0, -80.0, 2.0, 3.0),
            cv(2.0, 90.0, 9.0, 4.0),
        ];
        let planes = tri.iter().fold(0, |a, v| a | outcode(v.pos));
        let poly = clip_triangle(&tri, planes);
        assert!(poly.vertices().len() >= 3);
        for v in poly.vertices() {
            for plane in PLANES {
                assert!(distance(plane, v.pos) >= -1e-3 * v.pos.w.abs().max(1.0));
            }
        }
    }
}
