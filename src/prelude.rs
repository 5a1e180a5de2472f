//! What a frame loop needs, in one `use vdlod::prelude::*`.

pub use crate::{adapt, draw, draw_bands, Bands, Camera, CutMesh, FrameError, Orbit, Style};
pub use vdlod_core::adapt::{Budget, FrameStats};
pub use vdlod_core::cut::{Coloring, Cut};
pub use vdlod_core::format::HierarchyView;
pub use vdlod_core::policy::{BackFace, Frustum, Policy, QRefine, ScreenError, View};
pub use vdlod_raster::{
    Depth, DrawStats, Pixel, Rgb565, Rgb565Be, Rgba8, ShadedVertex, Shading, Target, Window,
};
