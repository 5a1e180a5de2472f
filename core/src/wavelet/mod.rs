//! The wavelet engine: view-dependent refinement of meshes with subdivision connectivity.
//!
//! Azuma, Wood, Curless, Duchamp, Salesin and Stuetzle, "View-dependent refinement of
//! multiresolution meshes with subdivision connectivity" (2003). A semi-regular mesh (a base mesh
//! and `J` levels of 4-to-1 subdivision) is a sum of lazy wavelets, one per vertex that a
//! subdivision adds; each frame the cut keeps the wavelets the camera needs and emits the
//! crack-free triangles they make. It is the second engine beside the vertex forest of
//! [`crate::cut`]: the same [`crate::policy`] tests (a wavelet's bounds are a
//! [`crate::policy::Bounds`]), the same [`crate::adapt::Budget`] and
//! [`crate::adapt::FrameStats`], and triangles as vertex slots with positions, which the
//! rasterizer draws as it draws the vertex forest's cut.
//!
//! - [`format`]: the file, read in place and validated (one 12-byte record per vertex).
//! - [`heights`]: height fields in the same file, about two bytes per vertex.
//! - [`lattice`]: every level's connectivity, computed from the base mesh.
//! - [`cut`]: the set of wavelets as bits, its incremental adaptation and the emitted mesh.
//! - `build` (feature `build`): sources of semi-regular meshes and the per-wavelet bounds.
//!
//! ```
//! # #[cfg(feature = "build")] {
//! use vdlod_core::adapt::Budget;
//! use vdlod_core::policy::{QRefine, ScreenError, View};
//! use vdlod_core::wavelet::{SemiRegular, SemiRegularView, WaveletCut};
//! // The unit sphere as an octahedron subdivided four times (2,048 faces), as a file.
//! let bytes = SemiRegular::sphere(4).unwrap().to_bytes().unwrap();
//! let s = SemiRegularView::parse(&bytes).unwrap();
//! // Up to 64 x 32 wavelets, 4,096 triangles, 2,100 vertices, 512 queued candidates.
//! let mut cut = WaveletCut::<64, 4096, 2100, 512>::boxed();
//! cut.reset(&s).unwrap();
//! let view = View::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.8, 1.0, 480.0);
//! let policy = QRefine { error: ScreenError { silhouette: 0.5, interior: 3.5 } };
//! let stats = cut.adapt(&s, &view, &policy, &Budget::default());
//! assert!(stats.triangles > 8 && stats.triangles < 2048);
//! assert_eq!(stats.triangles as usize, cut.triangles().len());
//! // Every edge of the closed sphere is shared by two triangles run opposite ways.
//! let mut scratch = vec![[0u32; 2]; 3 * cut.triangles().len()];
//! assert!(cut.check(&s, true, &mut scratch).is_ok());
//! # }
//! ```

#[cfg(feature = "build")]
pub mod build;
pub mod cut;
pub mod format;
pub mod heights;
pub mod lattice;

#[cfg(feature = "build")]
pub use build::{Bound, Scheme, SemiRegular, SemiRegularBuildError};
pub use cut::{WaveletCut, WaveletCutError, WaveletDefect};
pub use format::{SemiRegularError, SemiRegularView};
pub use lattice::Point;

#[cfg(all(test, feature = "build"))]
mod tests;
