//! One camera for both halves of a frame: the refinement policy's [`View`] and the rasterizer's
//! view-projection matrix come from the same [`Camera`], so they cannot disagree.
//!
//! All trigonometry goes through `libm`, so a camera path gives the same matrices, and therefore
//! the same frames, on every machine.

use core::fmt;

use glam::{Mat4, Vec3};
use vdlod_core::policy::View;

/// A perspective camera looking at a point, with the size of the frame it draws.
///
/// ```
/// use vdlod::{glam::Vec3, Camera};
/// let camera = Camera {
///     eye: Vec3::new(0.0, 1.0, 4.0),
///     target: Vec3::ZERO,
///     up: Vec3::Y,
///     fov_y: 1.0,
///     near: 0.5,
///     far: 10.0,
///     width: 320,
///     height: 240,
/// };
/// camera.check().unwrap();
/// let view = camera.view(); // for the refinement policy
/// let mvp = camera.view_projection(); // for the rasterizer
/// assert!((mvp * camera.target.extend(1.0)).w > 0.0);
/// # let _ = view;
/// ```
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
    /// Frame width in pixels.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
}

/// Why a [`Camera`] cannot be used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraError {
    /// The frame has zero width or height.
    ZeroViewport,
    /// A position, direction or distance is NaN or infinite.
    NotFinite,
    /// The eye is where it looks, or up is parallel to the view direction.
    NoDirection,
    /// The field of view is not between 0 and pi.
    FieldOfView(f32),
    /// Near is not positive or far is not beyond it.
    DepthRange {
        /// Near plane distance.
        near: f32,
        /// Far plane distance.
        far: f32,
    },
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CameraError::ZeroViewport => write!(f, "the camera's frame has zero width or height"),
            CameraError::NotFinite => write!(f, "a camera coordinate is not finite"),
            CameraError::NoDirection => write!(
                f,
                "the camera has no view direction (eye at the target, or up along the view)"
            ),
            CameraError::FieldOfView(v) => {
                write!(f, "field of view {v} rad is not between 0 and pi")
            }
            CameraError::DepthRange { near, far } => write!(
                f,
                "near plane {near} and far plane {far}: need 0 < near < far"
            ),
        }
    }
}

impl core::error::Error for CameraError {}

impl Camera {
    /// Checks that the camera can draw a frame.
    pub fn check(&self) -> Result<(), CameraError> {
        if self.width == 0 || self.height == 0 {
            return Err(CameraError::ZeroViewport);
        }
        let finite = self.eye.is_finite()
            && self.target.is_finite()
            && self.up.is_finite()
            && self.fov_y.is_finite()
            && self.near.is_finite()
            && self.far.is_finite();
        if !finite {
            return Err(CameraError::NotFinite);
        }
        let forward = self.target - self.eye;
        if forward.cross(self.up).length_squared() <= f32::MIN_POSITIVE {
            return Err(CameraError::NoDirection);
        }
        if !(self.fov_y > 0.0 && self.fov_y < core::f32::consts::PI) {
            return Err(CameraError::FieldOfView(self.fov_y));
        }
        if !(self.near > 0.0 && self.far > self.near) {
            return Err(CameraError::DepthRange {
                near: self.near,
                far: self.far,
            });
        }
        Ok(())
    }

    /// Width over height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height.max(1) as f32
    }

    /// World to clip space, depth `0..=1`: the rasterizer's `mvp` for an object placed at the
    /// origin of the world.
    pub fn view_projection(&self) -> Mat4 {
        Mat4::perspective_rh(self.fov_y, self.aspect(), self.near, self.far)
            * Mat4::look_at_rh(self.eye, self.target, self.up)
    }

    /// The refinement policy's view of this camera.
    pub fn view(&self) -> View {
        self.view_scaled(1.0)
    }

    /// The policy's view with the refinement frustum's cross-section `scale` times the camera's
    /// (the merge-tree paper's frustum size).
    pub fn view_scaled(&self, scale: f32) -> View {
        View::with_frustum_scale(
            self.eye.into(),
            self.target.into(),
            self.up.into(),
            self.fov_y,
            self.aspect(),
            self.height as f32,
            scale,
        )
    }
}

/// A circular camera path around a model, looking at its centre, with the whole model in view.
///
/// ```
/// use vdlod::{glam::Vec3, Orbit};
/// let orbit = Orbit::peer(Vec3::ZERO, 1.0, 36).viewport(320, 240);
/// let camera = orbit.camera(9);
/// assert!(camera.check().is_ok());
/// assert!((camera.eye.length() - 2.0).abs() < 1e-5); // sin(30 degrees) = 1/2
/// ```
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
    /// Frame width in pixels of the cameras it gives.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
}

impl Orbit {
    /// The merge-tree paper's orbit around a bounding sphere: a circle in the xz-plane at the
    /// height of the centre, looking at it, at the distance where the sphere just fills a
    /// 60-degree vertical field of view; 640x480 until [`Orbit::viewport`] says otherwise.
    pub fn merge_tree(center: Vec3, radius: f32, frames: u32) -> Orbit {
        Orbit::around(center, radius, frames, 0.0)
    }

    /// The orbit of the peer benchmarks (`shared/peers/README.md`): as [`Orbit::merge_tree`] but
    /// 20 degrees above the horizontal plane.
    pub fn peer(center: Vec3, radius: f32, frames: u32) -> Orbit {
        Orbit::around(center, radius, frames, 20.0f32.to_radians())
    }

    fn around(center: Vec3, radius: f32, frames: u32, elevation: f32) -> Orbit {
        let fov_y = 60.0f32.to_radians();
        let radius = radius.max(f32::MIN_POSITIVE);
        Orbit {
            center,
            radius,
            distance: radius / libm::sinf(fov_y * 0.5),
            elevation,
            fov_y,
            frames: frames.max(1),
            width: 640,
            height: 480,
        }
    }

    /// The same path for frames of `width` by `height` pixels.
    pub fn viewport(self, width: usize, height: usize) -> Orbit {
        Orbit {
            width,
            height,
            ..self
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
            width: self.width,
            height: self.height,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_circles_at_centre_height() {
        let o = Orbit::merge_tree(Vec3::new(0.0, 3.0, 0.0), 3f32.sqrt(), 4);
        for i in 0..4 {
            let c = o.camera(i);
            assert_eq!(c.eye.y, 3.0);
            assert!(((c.eye - c.target).length() - o.distance).abs() < 1e-5);
            assert_eq!(c.check(), Ok(()));
        }
        assert!((o.distance - 2.0 * 3f32.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn bad_cameras_are_typed_errors() {
        let good = Orbit::peer(Vec3::ZERO, 1.0, 8).camera(1);
        let bad = |c: Camera| c.check().unwrap_err();
        assert_eq!(bad(Camera { width: 0, ..good }), CameraError::ZeroViewport);
        assert_eq!(bad(Camera { height: 0, ..good }), CameraError::ZeroViewport);
        assert_eq!(
            bad(Camera {
                eye: Vec3::NAN,
                ..good
            }),
            CameraError::NotFinite
        );
        assert_eq!(
            bad(Camera {
                eye: good.target,
                ..good
            }),
            CameraError::NoDirection
        );
        assert_eq!(
            bad(Camera { fov_y: 4.0, ..good }),
            CameraError::FieldOfView(4.0)
        );
        assert_eq!(
            bad(Camera { near: 0.0, ..good }),
            CameraError::DepthRange {
                near: 0.0,
                far: good.far
            }
        );
    }

    #[test]
    fn view_and_matrix_agree_on_what_is_in_front() {
        let c = Orbit::peer(Vec3::ZERO, 1.0, 8).viewport(320, 240).camera(3);
        let clip = c.view_projection() * c.target.extend(1.0);
        assert!(clip.w > 0.0 && clip.x.abs() < 1e-4 * clip.w && clip.y.abs() < 1e-4 * clip.w);
        assert_eq!(c.view(), c.view_scaled(1.0));
    }
}
