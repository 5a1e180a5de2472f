//! `vdlod`: view-dependent level of detail for memory-scarce renderers.
//!
//! This facade re-exports the two `no_std` crates of the project:
//! - [`core`] (`vdlod-core`): vertex hierarchy, runtime cut, refinement policies, budget;
//! - [`raster`] (`vdlod-raster`): the deterministic triangle rasterizer.
#![no_std]
#![forbid(unsafe_code)]

pub use vdlod_core as core;
pub use vdlod_raster as raster;
