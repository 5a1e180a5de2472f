//! The `render` command: fly an orbit around a full-detail mesh and write PNG frames.

use std::path::Path;
use std::time::Instant;

use vdlod::Style;
use vdlod_raster::{DrawParams, Shading};

use crate::camera::{merge_tree_orbit, Camera};
use crate::frame::{Frame, FrameError};
use crate::mesh::IndexedMesh;

/// The demo's drawing style: the facade's default, with dark edges when `wireframe` is set.
pub fn style(shading: Shading, wireframe: bool) -> Style {
    Style {
        shading,
        wireframe: wireframe.then_some([20, 20, 20]),
        ..Style::default()
    }
}

/// Drawing parameters for a camera: view-projection, a light over the viewer's shoulder
/// ([`Style::params`]; `IndexedMesh` normals are unit length, as the cut's are).
pub fn camera_params(camera: &Camera, shading: Shading, wireframe: bool) -> DrawParams {
    style(shading, wireframe).params(camera)
}

/// Settings of [`render_orbit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Frame width in pixels.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
    /// Frames to render, one revolution in all.
    pub frames: u32,
    /// Shading mode.
    pub shading: Shading,
    /// Draw triangle edges over the shaded frame.
    pub wireframe: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 640,
            height: 480,
            frames: 36,
            shading: Shading::Gouraud,
            wireframe: false,
        }
    }
}

/// What one frame of [`render_orbit`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameReport {
    /// Frame number.
    pub index: u32,
    /// Triangles submitted.
    pub submitted: u32,
    /// Triangles (or clipped pieces) that reached the edge stage, i.e. not culled or outside.
    pub rasterized: u32,
    /// Milliseconds spent drawing (PNG encoding excluded).
    pub ms: f64,
}

/// Renders frame `index` of the merge-tree orbit into `frame`.
pub fn render_orbit_frame(
    frame: &mut Frame,
    mesh: &IndexedMesh,
    index: u32,
    opts: &RenderOptions,
) -> Result<FrameReport, FrameError> {
    let orbit = merge_tree_orbit(&mesh.bounds(), opts.frames, frame.width(), frame.height());
    let params = camera_params(&orbit.camera(index), opts.shading, opts.wireframe);
    let start = Instant::now();
    let stats = frame.draw(&mesh.as_raster_mesh(), &params)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(FrameReport {
        index,
        submitted: stats.submitted,
        rasterized: stats.rasterized,
        ms,
    })
}

/// Removes the numbered outputs an earlier, longer run left in `dir`: each `PREFIXNNNN.EXT` (a
/// prefix of `stale`, four or more digits, any extension) whose number is at least the prefix's
/// count of files this run writes. Nothing else is touched.
pub fn remove_stale(dir: &Path, stale: &[(&str, u32)]) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let name = entry?.file_name();
        let Some(name) = name.to_str() else { continue };
        for &(prefix, kept) in stale {
            let Some((digits, _ext)) = name.strip_prefix(prefix).and_then(|r| r.split_once('.'))
            else {
                continue;
            };
            let numbered = digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit());
            if numbered && digits.parse::<u64>().is_ok_and(|n| n >= kept as u64) {
                std::fs::remove_file(dir.join(name))?;
            }
        }
    }
    Ok(())
}

/// Renders the whole orbit into `out_dir/frame_NNNN.png`, calling `report` after each frame.
pub fn render_orbit(
    mesh: &IndexedMesh,
    opts: &RenderOptions,
    out_dir: &Path,
    mut report: impl FnMut(&FrameReport),
) -> Result<Vec<FrameReport>, FrameError> {
    std::fs::create_dir_all(out_dir).map_err(FrameError::Io)?;
    remove_stale(out_dir, &[("frame_", opts.frames)]).map_err(FrameError::Io)?;
    let mut frame = Frame::new(opts.width, opts.height)?;
    let mut reports = Vec::with_capacity(opts.frames as usize);
    for i in 0..opts.frames {
        let r = render_orbit_frame(&mut frame, mesh, i, opts)?;
        frame.save_png(&out_dir.join(format!("frame_{i:04}.png")))?;
        report(&r);
        reports.push(r);
    }
    Ok(reports)
}
