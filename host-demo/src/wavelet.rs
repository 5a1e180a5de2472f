//! The wavelet engine on the host: semi-regular files made and described, and the wavelet
//! paper's experiments (Azuma et al., "View-dependent refinement of multiresolution meshes with
//! subdivision connectivity", 2003) beside the vertex forest on the same mesh.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use vdlod::{Camera, Style, WaveletMesh};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::build::{build, BuildOptions, InputMesh};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{QRefine, ScreenError};
use vdlod_core::wavelet::build::SemiRegular;
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
use vdlod_raster::Rgba8;

use crate::frame::{encode_png, Frame};
use crate::lod::psnr;

/// The demo's wavelet cut: up to 262,144 wavelets, 60,000 triangles and 30,000 vertices (about
/// 1.1 MB, on the heap).
pub type DemoWaveletCut = WaveletCut<8192, 60_000, 30_000, 8_192>;

/// The figures of a semi-regular file, one line.
pub fn summarize(s: &SemiRegularView<'_>) -> String {
    let c = s.counts();
    format!(
        "semi-regular mesh: base {} vertices, {} faces, {} edges; {} levels ({} faces at full detail); {} wavelets; {} bytes, {:.1} per wavelet",
        c.base_vertices,
        c.base_faces,
        c.base_edges,
        c.levels,
        c.finest_faces(),
        s.wavelets(),
        s.size(),
        s.size() as f64 / s.wavelets().max(1) as f64
    )
}

/// Writes `bytes` to `out` through `OUT.partial` and a rename (never a partial file).
pub fn write_file(out: &Path, bytes: &[u8]) -> Result<(), String> {
    let mut partial = out.to_path_buf().into_os_string();
    partial.push(".partial");
    let partial = std::path::PathBuf::from(partial);
    std::fs::write(&partial, bytes)
        .and_then(|()| std::fs::rename(&partial, out))
        .map_err(|e| {
            let _ = std::fs::remove_file(&partial);
            format!("{}: cannot write: {e}", out.display())
        })
}

/// Writes a semi-regular mesh's finest level as an OBJ file.
pub fn write_obj(mesh: &SemiRegular, out: &Path) -> Result<(), String> {
    let mut text = String::new();
    for p in &mesh.positions {
        let _ = writeln!(text, "v {} {} {}", p[0], p[1], p[2]);
    }
    for t in mesh.finest_triangles() {
        let _ = writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(out, text).map_err(|e| format!("{}: cannot write: {e}", out.display()))
}

/// The camera of our Fig. 11: a unit sphere 3 units away, seen at 45 degrees over 512 x 512
/// pixels, aimed 0.6 to the right of its centre so that its left limb leaves the frustum.
pub fn fig11_camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::new(0.6, 0.0, 0.0),
        up: Vec3::Y,
        fov_y: 45f32.to_radians(),
        near: 0.1,
        far: 10.0,
        width: 512,
        height: 512,
    }
}

/// The observer of Fig. 11c: high above, looking down on the sphere and the camera (which is
/// at the bottom of the picture).
fn observer() -> Camera {
    Camera {
        eye: Vec3::new(0.3, 7.5, 1.6),
        target: Vec3::new(0.3, 0.0, 1.2),
        up: Vec3::NEG_Z,
        ..fig11_camera()
    }
}

/// One engine's result in an experiment.
#[derive(Clone, Debug)]
pub struct EngineRun {
    /// `wavelet` or `forest`.
    pub engine: &'static str,
    /// The adaptation's statistics.
    pub stats: FrameStats,
    /// Microseconds of the adaptation from the base mesh.
    pub adapt_us: f64,
    /// PSNR of the frame against the full-detail frame.
    pub psnr_db: f64,
}

/// Draws the camera's frustum (to `depth` units) over `frame` as seen by `observer`, and
/// encodes the result as PNG.
fn with_frustum(
    frame: &Frame,
    camera: &Camera,
    observer: &Camera,
    depth: f32,
) -> Result<Vec<u8>, String> {
    let (w, h) = (frame.width() as u32, frame.height() as u32);
    let bytes: Vec<u8> = frame.pixels().iter().flat_map(|p| p.0).collect();
    let size = tiny_skia::IntSize::from_wh(w, h).ok_or("empty frame")?;
    let mut pixmap = tiny_skia::Pixmap::from_vec(bytes, size).ok_or("bad frame")?;
    let forward = (camera.target - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let ty = (camera.fov_y * 0.5).tan();
    let tx = ty * camera.width as f32 / camera.height as f32;
    let corner =
        |sx: f32, sy: f32| camera.eye + (forward + right * (sx * tx) + up * (sy * ty)) * depth;
    let m = observer.view_projection();
    let project = |p: Vec3| {
        let c = m * p.extend(1.0);
        (
            (c.x / c.w * 0.5 + 0.5) * w as f32,
            (0.5 - c.y / c.w * 0.5) * h as f32,
        )
    };
    let corners = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    let mut pb = tiny_skia::PathBuilder::new();
    let eye = project(camera.eye);
    for k in 0..4 {
        let (a, b) = (project(corners[k]), project(corners[(k + 1) % 4]));
        pb.move_to(eye.0, eye.1);
        pb.line_to(a.0, a.1);
        pb.line_to(b.0, b.1);
    }
    if let Some(path) = pb.finish() {
        let mut paint = tiny_skia::Paint::default();
        paint.set_color_rgba8(255, 210, 60, 255);
        paint.anti_alias = false;
        let stroke = tiny_skia::Stroke {
            width: 2.0,
            ..tiny_skia::Stroke::default()
        };
        pixmap.stroke_path(
            &path,
            &paint,
            &stroke,
            tiny_skia::Transform::identity(),
            None,
        );
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}

fn save(out: &Path, name: &str, png: &[u8]) -> Result<(), String> {
    let path = out.join(name);
    std::fs::write(&path, png).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

fn frame_png(frame: &Frame) -> Result<Vec<u8>, String> {
    encode_png(frame.width(), frame.height(), frame.pixels()).map_err(|e| e.to_string())
}

/// The paper's Fig. 11: the 8,192-face sphere (an octahedron subdivided five times) at a 0.5 px
/// silhouette and 3.5 px interior tolerance, through both engines; writes `full.png`,
/// `wavelet.png`, `forest.png`, `observer.png` (the wavelet engine's mesh and the camera's
/// frustum seen from above, Fig. 11c) and `fig11.csv` into `out`, and returns one summary line
/// per engine.
pub fn fig11(out: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mesh = SemiRegular::sphere(5).map_err(|e| e.to_string())?;
    let bytes = mesh.to_bytes().map_err(|e| e.to_string())?;
    let s = SemiRegularView::parse(&bytes).map_err(|e| e.to_string())?;
    let camera = fig11_camera();
    let (silhouette, interior) = (0.5, 3.5);
    let policy = QRefine {
        error: ScreenError {
            silhouette,
            interior,
        },
    };
    let plain = Style::default();
    let wire = Style {
        wireframe: Some([20, 20, 20]),
        ..Style::default()
    };
    let mut frame = Frame::new(camera.width, camera.height).map_err(|e| e.to_string())?;

    // Full detail: every wavelet in.
    let mut full_cut = DemoWaveletCut::boxed();
    full_cut.reset(&s).map_err(|e| e.to_string())?;
    full_cut.adapt(
        &s,
        &camera.view(),
        &ScreenError::new(1e-6),
        &Budget::default(),
    );
    let full_mesh = WaveletMesh::new(&full_cut, &s, false);
    frame
        .draw_styled(&full_mesh, &camera, &plain)
        .map_err(|e| e.to_string())?;
    let full: Vec<Rgba8> = frame.pixels().to_vec();
    frame
        .draw_styled(&full_mesh, &camera, &wire)
        .map_err(|e| e.to_string())?;
    save(out, "full.png", &frame_png(&frame)?)?;

    // The wavelet engine.
    let mut cut = DemoWaveletCut::boxed();
    cut.reset(&s).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let stats = cut.adapt(&s, &camera.view(), &policy, &Budget::default());
    let adapt_us = start.elapsed().as_secs_f64() * 1e6;
    let adapted = WaveletMesh::new(&cut, &s, false);
    frame
        .draw_styled(&adapted, &camera, &plain)
        .map_err(|e| e.to_string())?;
    let wavelet = EngineRun {
        engine: "wavelet",
        stats,
        adapt_us,
        psnr_db: psnr(frame.pixels(), &full),
    };
    frame
        .draw_styled(&adapted, &camera, &wire)
        .map_err(|e| e.to_string())?;
    save(out, "wavelet.png", &frame_png(&frame)?)?;
    let watcher = observer();
    let mut above = Frame::new(watcher.width, watcher.height).map_err(|e| e.to_string())?;
    above
        .draw_styled(&adapted, &watcher, &wire)
        .map_err(|e| e.to_string())?;
    save(
        out,
        "observer.png",
        &with_frustum(&above, &camera, &watcher, 4.0)?,
    )?;

    // The vertex forest of the same finest mesh.
    let triangles = mesh.finest_triangles();
    let input = InputMesh {
        positions: &mesh.positions,
        colors: None,
        triangles: &triangles,
    };
    let hierarchy =
        build(&input, &BuildOptions::default(), &mut |_| {}).map_err(|e| e.to_string())?;
    let hbytes = hierarchy.to_bytes(false);
    let h = HierarchyView::parse(&hbytes).map_err(|e| e.to_string())?;
    let mut forest = Cut::<4200, 8400, 1050>::boxed();
    forest.reset(&h).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let stats = forest.adapt(&h, &camera.view(), &policy, &Budget::default());
    let adapt_us = start.elapsed().as_secs_f64() * 1e6;
    frame
        .draw_cut(&forest, &h, &camera, &plain)
        .map_err(|e| e.to_string())?;
    let forest_run = EngineRun {
        engine: "forest",
        stats,
        adapt_us,
        psnr_db: psnr(frame.pixels(), &full),
    };
    frame
        .draw_cut(&forest, &h, &camera, &wire)
        .map_err(|e| e.to_string())?;
    save(out, "forest.png", &frame_png(&frame)?)?;

    let mut csv = String::from("engine,faces,vertices,adapt_us,psnr_db\n");
    let mut lines = Vec::new();
    for run in [&wavelet, &forest_run] {
        let _ = writeln!(
            csv,
            "{},{},{},{:.1},{:.2}",
            run.engine, run.stats.triangles, run.stats.vertices, run.adapt_us, run.psnr_db
        );
        lines.push(format!(
            "experiment=fig11 engine={} faces={} paper_faces=732 full_faces=8192 silhouette_px={silhouette} interior_px={interior} adapt_us={:.0} psnr_db={:.2}",
            run.engine, run.stats.triangles, run.adapt_us, run.psnr_db
        ));
    }
    let path = out.join("fig11.csv");
    std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    Ok(lines)
}
