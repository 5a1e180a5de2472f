//! Host side of vdlod: mesh loading, camera paths, frames and PNG output.
//!
//! The `vdlod-demo` binary is a thin command line over this library; the workspace's tests and
//! benchmarks use it too, so what they render is exactly what the demo renders.

pub mod camera;
pub mod chart;
pub mod frame;
pub mod hierarchy;
pub mod importance;
pub mod input;
pub mod label;
pub mod lod;
pub mod mesh;
pub mod render;
pub mod repair;
pub mod terrain;
pub mod terrain_engines;
pub mod wavelet;
