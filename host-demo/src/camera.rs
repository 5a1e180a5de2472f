//! Cameras and the camera paths the demo and the benchmarks fly.
//!
//! All trigonometry goes through `libm`, so a path gives the same matrices, and therefore the same
//! frames, on every machine.

use glam::{Mat4, Vec3};

use crate::mesh::Bounds;

/// A perspective camera looking at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
}

impl Camera {
    /// World to clip space for a viewport of the given aspect ratio (width / height), depth `0..=1`.
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.fov_y, aspect, self.near, self.far)
            * Mat4::look_at_rh(self.eye, self.target, self.up)
    }
}

/// A circular path around a model, looking at its centre, with the whole model in view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Centre of the circle and point looked at.
    pub center: Vec3,
    /// Radius of the model's bounding sphere.
    pub radius: f32,
    /// Distance from the centre to the eye.
    pub distance: f32,
    /// Elevation of the eye above the horizontal plane through the centre, in radians.
    pub elevation: f32,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Frames per revolution.
    pub frames: u32,
}

impl Orbit {
    /// The merge-tree paper's orbit: a circle in the xz-plane at the height of the bounding-box
    /// centre, looking at the centre, at the distance where the bounding sphere just fills the
    /// 60-degree vertical field of view.
    pub fn merge_tree(bounds: &Bounds, frames: u32) -> Orbit {
        Orbit::around(bounds, frames, 0.0)
    }

    /// The orbit of the peer benchmarks (`shared/peers/README.md`): as [`Orbit::merge_tree`] but
    /// 20 degrees above the horizontal plane.
    pub fn peer(bounds: &Bounds, frames: u32) -> Orbit {
        Orbit::around(bounds, frames, 20.0f32.to_radians())
    }

    fn around(bounds: &Bounds, frames: u32, elevation: f32) -> Orbit {
        let fov_y = 60.0f32.to_radians();
        let radius = bounds.radius().max(f32::MIN_POSITIVE);
        Orbit {
            center: bounds.center(),
            radius,
            distance: radius / libm::sinf(fov_y * 0.5),
            elevation,
            fov_y,
            frames: frames.max(1),
        }
    }

    /// The camera of frame `i` (azimuth `2 pi i / frames`).
    pub fn camera(&self, i: u32) -> Camera {
        let az = 2.0 * core::f32::consts::PI * (i % self.frames) as f32 / self.frames as f32;
        let (ce, se) = (libm::cosf(self.elevation), libm::sinf(self.elevation));
        let dir = Vec3::new(ce * libm::cosf(az), se, ce * libm::sinf(az));
        Camera {
            eye: self.center + dir * self.distance,
            target: self.center,
            up: Vec3::Y,
            fov_y: self.fov_y,
            near: (self.distance - 1.5 * self.radius).max(self.radius * 0.01),
            far: self.distance + 1.5 * self.radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_circles_at_centre_height() {
        let b = Bounds {
            min: Vec3::new(-1.0, 2.0, -1.0),
            max: Vec3::new(1.0, 4.0, 1.0),
        };
        let o = Orbit::merge_tree(&b, 4);
        for i in 0..4 {
            let c = o.camera(i);
            assert_eq!(c.eye.y, 3.0);
            assert!(((c.eye - c.target).length() - o.distance).abs() < 1e-5);
            assert!(c.near > 0.0 && c.far > c.near);
        }
        assert!((o.distance - 2.0 * 3f32.sqrt()).abs() < 1e-5);
    }
}
