//! View-dependent level of detail for memory-scarce renderers.
//!
//! This crate holds the parts of vdlod that run on the device, `no_std` and allocation-free: the
//! read side of the hierarchy [`format`], the runtime [`cut`] in fixed-capacity arenas, the
//! refinement [`policy`]s, and [`adapt`], which moves the cut each frame under a triangle budget
//! with geomorphs. Behind the `build` feature sits the offline `build`er that turns a triangle
//! mesh into a vertex hierarchy (it needs `alloc`).
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "build")]
extern crate alloc;

pub mod adapt;
#[cfg(feature = "build")]
pub mod build;
pub mod cut;
pub mod format;
mod nodemap;
pub mod policy;
#[cfg(feature = "build")]
pub mod remesh;
pub mod root;
pub mod wavelet;
