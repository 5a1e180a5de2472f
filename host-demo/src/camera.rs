//! The camera paths the demo flies: the facade's [`Camera`] and [`Orbit`], framed on a mesh.

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
