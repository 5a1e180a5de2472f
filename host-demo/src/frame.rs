//! Frames: owned buffers for the rasterizer, and PNG in and out.
//!
//! The rasterizer borrows its buffers; on the host, a [`Frame`] owns them (colour, depth and the
//! vertex scratch) and reuses them from frame to frame.

use std::path::Path;

use vdlod::{Camera, CutMesh, Style};
use vdlod_core::cut::{Cut, SlotIndex};
use vdlod_core::format::HierarchyView;
use vdlod_raster::texture::Texture;
use vdlod_raster::{
    draw_indexed, DrawParams, DrawStats, MeshSource, Pixel, Rgba8, ShadedVertex, Target,
    VertexIndex,
};

/// Background colour of demo frames.
pub const BACKGROUND: Rgba8 = Rgba8([24, 26, 32, 255]);

/// Why a frame could not be drawn or written.
#[derive(Debug)]
pub enum FrameError {
    /// The viewport or the buffers are unusable.
    Target(vdlod_raster::TargetError),
    /// The mesh does not fit the draw call.
    Draw(vdlod_raster::DrawError),
    /// The camera cannot be used.
    Camera(vdlod::CameraError),
    /// PNG encoding or decoding failed.
    Png(String),
    /// Writing or reading the file failed.
    Io(std::io::Error),
    /// The texels cannot be a texture.
    Texture(vdlod_raster::texture::TextureError),
}

impl std::fmt::Display for FrameError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FrameError::Target(e) => e.fmt(f),
            FrameError::Draw(e) => e.fmt(f),
            FrameError::Camera(e) => e.fmt(f),
            FrameError::Png(e) => write!(f, "PNG: {e}"),
            FrameError::Io(e) => e.fmt(f),
            FrameError::Texture(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for FrameError {}

impl From<vdlod::FrameError> for FrameError {
    fn from(e: vdlod::FrameError) -> Self {
        match e {
            vdlod::FrameError::Camera(e) => FrameError::Camera(e),
            vdlod::FrameError::Target(e) => FrameError::Target(e),
            vdlod::FrameError::Draw(e) => FrameError::Draw(e),
        }
    }
}

/// An RGBA8 frame with its depth buffer and vertex scratch.
pub struct Frame {
    width: usize,
    height: usize,
    color: Vec<Rgba8>,
    depth: Vec<u32>,
    scratch: Vec<ShadedVertex>,
}

impl Frame {
    /// A frame of `width` by `height` pixels (checked against the rasterizer's limits).
    pub fn new(width: usize, height: usize) -> Result<Frame, FrameError> {
        let n = width.saturating_mul(height);
        if width > vdlod_raster::MAX_DIMENSION || height > vdlod_raster::MAX_DIMENSION {
            return Err(FrameError::Target(vdlod_raster::TargetError::TooLarge {
                width,
                height,
            }));
        }
        let mut frame = Frame {
            width,
            height,
            color: vec![BACKGROUND; n],
            depth: vec![0; n],
            scratch: Vec::new(),
        };
        frame.target()?; // validates the size
        Ok(frame)
    }

    fn target(&mut self) -> Result<Target<'_, Rgba8>, FrameError> {
        Target::new(&mut self.color, &mut self.depth, self.width, self.height)
            .map_err(FrameError::Target)
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Width over height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The pixels, row-major.
    pub fn pixels(&self) -> &[Rgba8] {
        &self.color
    }

    /// Clears to [`BACKGROUND`] and draws `mesh`.
    pub fn draw<M: MeshSource>(
        &mut self,
        mesh: &M,
        params: &DrawParams,
    ) -> Result<DrawStats, FrameError> {
        let mut scratch = self.take_scratch(mesh.vertex_count());
        let result = {
            let mut target = self.target()?;
            target.clear(BACKGROUND);
            draw_indexed(&mut target, mesh, params, &mut scratch).map_err(FrameError::Draw)
        };
        self.scratch = scratch;
        result
    }

    /// Clears to [`BACKGROUND`] and draws `cut` as `camera` sees it (see [`vdlod::draw`]).
    pub fn draw_cut<const V: usize, const F: usize, const Q: usize, I>(
        &mut self,
        cut: &Cut<V, F, Q, I>,
        h: &HierarchyView<'_>,
        camera: &Camera,
        style: &Style,
    ) -> Result<DrawStats, FrameError>
    where
        I: SlotIndex + VertexIndex,
    {
        self.draw_styled(&CutMesh::new(cut, h, style.vertex_colors), camera, style)
    }

    /// Clears to [`BACKGROUND`] and draws any engine's `mesh` as `camera` sees it (see
    /// [`vdlod::draw_mesh`]).
    pub fn draw_styled<M: MeshSource>(
        &mut self,
        mesh: &M,
        camera: &Camera,
        style: &Style,
    ) -> Result<DrawStats, FrameError> {
        let mut scratch = self.take_scratch(mesh.vertex_count());
        let result = {
            let mut target = self.target()?;
            target.clear(BACKGROUND);
            vdlod::draw_mesh(&mut target, mesh, camera, style, &mut scratch)
                .map_err(FrameError::from)
        };
        self.scratch = scratch;
        result
    }

    /// [`Frame::draw_styled`] with `texture` mapped by the mesh's texture coordinates.
    pub fn draw_textured<M: MeshSource, T: Pixel>(
        &mut self,
        mesh: &M,
        camera: &Camera,
        style: &Style,
        texture: &Texture<'_, T>,
    ) -> Result<DrawStats, FrameError> {
        let mut scratch = self.take_scratch(mesh.vertex_count());
        let result = {
            let mut target = self.target()?;
            target.clear(BACKGROUND);
            vdlod::draw_mesh_textured(&mut target, mesh, camera, style, texture, &mut scratch)
                .map_err(FrameError::from)
        };
        self.scratch = scratch;
        result
    }

    /// The vertex scratch, at least `n` long, taken out of the frame while its target is borrowed.
    fn take_scratch(&mut self, n: usize) -> Vec<ShadedVertex> {
        if self.scratch.len() < n {
            self.scratch.resize(n, ShadedVertex::default());
        }
        std::mem::take(&mut self.scratch)
    }

    /// Writes the frame as a PNG file.
    pub fn save_png(&self, path: &Path) -> Result<(), FrameError> {
        save_png(path, self.width, self.height, &self.color)
    }
}

/// Encodes row-major RGBA8 pixels as PNG.
pub fn encode_png(width: usize, height: usize, pixels: &[Rgba8]) -> Result<Vec<u8>, FrameError> {
    let size = u32::try_from(width)
        .ok()
        .zip(u32::try_from(height).ok())
        .and_then(|(w, h)| tiny_skia::IntSize::from_wh(w, h))
        .ok_or_else(|| FrameError::Png(format!("cannot encode a {width}x{height} image")))?;
    let bytes = pixels.iter().flat_map(|p| p.0).collect();
    let pixmap = tiny_skia::Pixmap::from_vec(bytes, size)
        .ok_or_else(|| FrameError::Png("pixel count does not match the size".into()))?;
    pixmap
        .encode_png()
        .map_err(|e| FrameError::Png(e.to_string()))
}

/// Writes row-major RGBA8 pixels as a PNG file.
pub fn save_png(
    path: &Path,
    width: usize,
    height: usize,
    pixels: &[Rgba8],
) -> Result<(), FrameError> {
    std::fs::write(path, encode_png(width, height, pixels)?).map_err(FrameError::Io)
}

/// Reads a PNG file as `(width, height, RGBA8 pixels)`.
pub fn load_png(path: &Path) -> Result<(usize, usize, Vec<Rgba8>), FrameError> {
    let bytes = std::fs::read(path).map_err(FrameError::Io)?;
    let pixmap =
        tiny_skia::Pixmap::decode_png(&bytes).map_err(|e| FrameError::Png(e.to_string()))?;
    let pixels = pixmap
        .pixels()
        .iter()
        .map(|p| {
            let c = p.demultiply();
            Rgba8([c.red(), c.green(), c.blue(), c.alpha()])
        })
        .collect();
    Ok((pixmap.width() as usize, pixmap.height() as usize, pixels))
}
