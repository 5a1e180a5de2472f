//! What a frame loop needs, in one `use vdlod::prelude::*`.

pub use crate::{
    adapt, adapt_wavelets, draw, draw_bands, draw_mesh, draw_mesh_bands, draw_mesh_textured, Bands,
    Camera, CutMesh, FrameError, Orbit, Style, WaveletMesh,
};
pub use vdlod_core::adapt::{Budget, FrameStats};
pub use vdlod_core::cut::{Coloring, Cut};
pub use vdlod_core::format::HierarchyView;
pub use vdlod_core::policy::{BackFace, Frustum, Policy, QRefine, ScreenError, View};
pub use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
pub use vdlod_raster::texture::{Filter, Texture, Wrap};
pub use vdlod_raster::{
    Depth, DrawStats, Pixel, Rgb565, Rgb565Be, Rgba8, ShadedVertex, Shading, Target, Window,
};
