//! The camera paths the demo flies: the facade's [`Camera`] and [`Orbit`], framed on a mesh, and
//! paths read from a file.

pub use vdlod::{Camera, Orbit};

use crate::mesh::Bounds;

/// The merge-tree paper's orbit (level) around `bounds`, for `width` by `height` frames.
pub fn merge_tree_orbit(bounds: &Bounds, frames: u32, width: usize, height: usize) -> Orbit {
    Orbit::merge_tree(bounds.center(), bounds.radius(), frames).viewport(width, height)
}

/// The peer benchmarks' orbit (20 degrees up) around `bounds`, for `width` by `height` frames.
pub fn peer_orbit(bounds: &Bounds, frames: u32, width: usize, height: usize) -> Orbit {
    Orbit::peer(bounds.center(), bounds.radius(), frames).viewport(width, height)
}

/// Why a camera path file cannot be flown.
#[derive(Clone, Debug, PartialEq)]
pub struct PathError {
    /// Line number, from 1 (0: the file as a whole).
    pub line: usize,
    /// What is wrong.
    pub what: String,
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.what)
        } else {
            write!(f, "line {}: {}", self.line, self.what)
        }
    }
}

impl std::error::Error for PathError {}

/// The columns of a camera path file, in order.
pub const PATH_COLUMNS: &str =
    "eye_x,eye_y,eye_z,target_x,target_y,target_z,up_x,up_y,up_z,fov_y_degrees";

/// Cameras from a path file: one frame per line of ten comma-separated numbers ([`PATH_COLUMNS`];
/// a first line naming them, blank lines and `#` comments are skipped). The near and far planes
/// are set from each eye's distance to the scene in `bounds`.
///
/// ```
/// use vdlod_demo::camera::path_cameras;
/// use vdlod_demo::mesh::Bounds;
/// let bounds = Bounds { min: glam::Vec3::splat(-1.0), max: glam::Vec3::splat(1.0) };
/// let text = "eye_x,eye_y,eye_z,target_x,target_y,target_z,up_x,up_y,up_z,fov_y_degrees\n\
///             0,0,5, 0,0,0, 0,1,0, 45\n";
/// let cameras = path_cameras(text, &bounds, 64, 48).unwrap();
/// assert_eq!(cameras.len(), 1);
/// let e = path_cameras("0,0,5,0,0,5,0,1,0,45\n", &bounds, 64, 48).unwrap_err();
/// assert_eq!(e.to_string(), "line 1: the camera cannot look this way: the eye is where it looks, or up is along the view");
/// ```
pub fn path_cameras(
    text: &str,
    bounds: &Bounds,
    width: usize,
    height: usize,
) -> Result<Vec<Camera>, PathError> {
    let mut cameras = Vec::new();
    let (center, radius) = (bounds.center(), bounds.radius().max(f32::MIN_POSITIVE));
    for (number, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        let err = |what: String| PathError {
            line: number + 1,
            what,
        };
        if line.is_empty() || (cameras.is_empty() && line.starts_with(|c: char| c.is_alphabetic()))
        {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 10 {
            return Err(err(format!(
                "{} values where 10 are needed ({PATH_COLUMNS})",
                fields.len()
            )));
        }
        let mut v = [0f32; 10];
        for (slot, field) in v.iter_mut().zip(&fields) {
            *slot = field
                .parse::<f32>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(format!("`{field}` is not a finite number")))?;
        }
        if !(v[9] > 0.0 && v[9] < 180.0) {
            return Err(err(format!(
                "field of view {} degrees: must be above 0 and below 180",
                v[9]
            )));
        }
        let eye = glam::Vec3::new(v[0], v[1], v[2]);
        let distance = (eye - center).length();
        let camera = Camera {
            eye,
            target: glam::Vec3::new(v[3], v[4], v[5]),
            up: glam::Vec3::new(v[6], v[7], v[8]),
            fov_y: v[9].to_radians(),
            near: (distance - radius).max(radius * 1e-3),
            far: distance + radius,
            width,
            height,
        };
        camera.check().map_err(|_| {
            err("the camera cannot look this way: the eye is where it looks, or up is along the view".into())
        })?;
        cameras.push(camera);
    }
    if cameras.is_empty() {
        return Err(PathError {
            line: 0,
            what: format!("no cameras (one line per frame: {PATH_COLUMNS})"),
        });
    }
    Ok(cameras)
}
