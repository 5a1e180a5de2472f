//! A deterministic, allocation-free triangle rasterizer for `no_std` targets.
//!
//! `vdlod-raster` draws triangles into colour and depth buffers that the caller owns: a host
//! window, a PNG, or the frame buffer of a microcontroller driving a small panel. It exists so that
//! the end of every vdlod pipeline is **watertight** (a pixel on an edge shared by two triangles is
//! drawn exactly once), **deterministic** (the same inputs give the same bytes on every target: only
//! IEEE basic operations and `libm` reach a pixel, and coverage is exact integer arithmetic) and
//! **fast** (each vertex is transformed once, the pixel loop steps integers with no division).
//!
//! The stages, one module each:
//! - [`vertex`]: transform, light, classify and project every vertex once;
//! - [`clip`]: homogeneous clipping for the few triangles that cross the near plane or the guard band;
//! - [`edge`]: fixed-point edge functions with the top-left fill rule, depth and colour stepping;
//! - [`wire`]: the wireframe overlay;
//! - [`target`]: caller-owned buffers, whole frames or bands of them, pixel formats ([`Rgba8`],
//!   [`Rgb565`], [`Rgb565Be`]) and depth types (`u32`, `u16`);
//! - [`texture`]: texels in a caller-provided slice, sampled nearest or bilinear in fixed point,
//!   for [`ShadedMesh::draw_textured`] (perspective-correct).
//!
//! [`shade`] and [`ShadedMesh::draw`] compose them for an indexed mesh ([`Mesh`], or any
//! [`MeshSource`]); [`draw_indexed`] does both for a whole frame.
//!
//! ```
//! use glam::{Mat4, Vec3};
//! use vdlod_raster::{draw_indexed, DrawParams, Mesh, Rgb565, ShadedVertex, Shading, Target};
//!
//! // A square of two triangles, drawn into a 16-bit panel buffer.
//! let positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
//! let triangles: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
//! let mesh = Mesh { positions: &positions, triangles: &triangles, ..Mesh::default() };
//! let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y);
//! let proj = Mat4::perspective_rh(0.8, 1.0, 0.5, 10.0);
//! let params = DrawParams { mvp: proj * view, shading: Shading::Flat, ..DrawParams::default() };
//!
//! let mut color = [Rgb565(0); 24 * 24];
//! let mut depth = [0u32; 24 * 24];
//! let mut target = Target::new(&mut color, &mut depth, 24, 24).unwrap();
//! target.clear(Rgb565(0));
//! let mut scratch = [ShadedVertex::default(); 4];
//! let stats = draw_indexed(&mut target, &mesh, &params, &mut scratch).unwrap();
//! assert_eq!(stats.rasterized, 2);
//! ```
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod clip;
#[cfg(feature = "embedded-graphics")]
pub mod display;
mod draw;
pub mod edge;
mod mesh;
pub mod target;
pub mod texture;
pub mod vertex;
pub mod wire;

#[cfg(feature = "embedded-graphics")]
pub use display::{flush, flush_with};
pub use draw::{
    draw_indexed, shade, BinnedMesh, DrawError, DrawParams, DrawStats, ShadedMesh, Shading,
};
pub use mesh::{
    CheckedMesh, IndexProof, Mesh, MeshSource, SourceVertex, Uv, VertexBatch, VertexIndex, BATCH,
};
pub use target::{
    Depth, Pixel, Rgb565, Rgb565Be, Rgba8, Target, TargetError, Window, DEPTH_CLEAR, MAX_DIMENSION,
};
pub use vertex::{Light, ShadedVertex};
