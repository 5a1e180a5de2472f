//! View-dependent level of detail for memory-scarce renderers.
//!
//! This crate will hold the read side of the vertex-hierarchy format, the runtime cut, the
//! refinement policies, the triangle budget and geomorphs, all `no_std` and allocation-free, with
//! the offline hierarchy builder behind a feature that enables `alloc`. It is empty today: the
//! rasterizer (`vdlod-raster`) and the host demo come first.
#![no_std]
#![forbid(unsafe_code)]
