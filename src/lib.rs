//! `vdlod`: view-dependent level of detail for memory-scarce renderers.
//!
//! This facade composes the two `no_std` crates of the project into one frame loop:
//! - [`core`] (`vdlod-core`): vertex hierarchy, runtime cut, refinement policies, budget;
//! - [`raster`] (`vdlod-raster`): the deterministic triangle rasterizer;
//! - [`Camera`] (and the [`Orbit`] path): one camera for both, giving the policy's view and the
//!   rasterizer's matrix;
//! - [`adapt`], [`draw`] and [`draw_bands`]: a frame, whole or in bands, with [`CutMesh`] as the
//!   cut's mesh output and [`Style`] for everything else about the drawing;
//! - the wavelet engine beside it: [`adapt_wavelets`] and [`WaveletMesh`], drawn by
//!   [`draw_mesh`] and [`draw_mesh_bands`] (which draw any engine's mesh).
//!
//! `use vdlod::prelude::*` brings what a frame loop needs; `examples/frame.rs` draws one frame
//! into a PNG.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod camera;
mod frame;
pub mod prelude;
mod wavelet;

pub use camera::{Camera, CameraError, Orbit};
pub use frame::{
    adapt, draw, draw_bands, draw_mesh, draw_mesh_bands, draw_mesh_textured, Bands, CutMesh,
    FrameError, Style,
};
pub use glam;
pub use vdlod_core as core;
pub use vdlod_raster as raster;
pub use wavelet::{adapt_wavelets, WaveletMesh};
