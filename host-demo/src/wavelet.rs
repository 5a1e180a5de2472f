//! The wavelet engine on the host: semi-regular files made and described, and the wavelet
//! paper's experiments (Azuma et al., "View-dependent refinement of multiresolution meshes with
//! subdivision connectivity", 2003) beside the vertex forest on the same mesh.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use vdlod::{Camera, CutMesh, Style, WaveletMesh};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::build::{build, BuildOptions, ErrorBound, Hierarchy, InputMesh};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{BackFace, Frustum, HoppeError, Policy, QRefine, ScreenError};
use vdlod_core::wavelet::build::{Bound, Scheme, SemiRegular};
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
use vdlod_raster::Rgba8;

use crate::chart::{self, Panel, BLUE, GREEN, GREY, ORANGE};
use crate::frame::{encode_png, Frame};
use crate::lod::psnr;
use crate::mesh::{load_obj_bytes, vertex_normals, IndexedMesh, COW_NAME, COW_OBJ};
use crate::stats::{mean, median};

/// The demo's wavelet cut: up to 262,144 wavelets, 60,000 triangles and 30,000 vertices (about
/// 1.1 MB, on the heap).
pub type DemoWaveletCut = WaveletCut<8192, 60_000, 30_000, 8_192>;

/// The figures of a semi-regular file, one line.
pub fn summarize(s: &SemiRegularView<'_>) -> String {
    let c = s.counts();
    let layout = if s.is_height_field() {
        format!(
            "; a height field along axis {}, bounds per block for its {} finest levels",
            s.up_axis(),
            s.fine_levels()
        )
    } else {
        String::new()
    };
    format!(
        "semi-regular mesh: base {} vertices, {} faces, {} edges; {} levels ({} faces at full detail); {} wavelets; {} bytes, {:.1} per wavelet{layout}",
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
    let text = crate::mesh::obj_text(&mesh.positions, None, mesh.finest_triangles());
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
    chart::stroke(&mut pixmap, pb, (255, 210, 60), false);
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

/// A base mesh of about `faces` triangles made from `mesh` by the vertex hierarchy's edge
/// collapses (its roots and base triangles, renumbered), so that any mesh can be subdivided
/// into a semi-regular one with a small base.
pub fn simplified_base(mesh: &IndexedMesh, faces: u32) -> Result<BaseMesh, String> {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: None,
        triangles: &mesh.triangles,
    };
    let opts = BuildOptions {
        base_vertices: faces / 2 + 2,
        ..BuildOptions::default()
    };
    let h = build(&input, &opts, &mut |_| {}).map_err(|e| e.to_string())?;
    let mut index = std::collections::BTreeMap::new();
    let mut positions = Vec::new();
    let triangles = h
        .base_triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                *index.entry(v).or_insert_with(|| {
                    positions.push(h.nodes[v as usize].position);
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    Ok(BaseMesh {
        positions,
        triangles,
    })
}

/// A base mesh: positions and counter-clockwise triangles.
#[derive(Clone, Debug)]
pub struct BaseMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// The demo's subdivided mesh for the paper's fish experiments: the cow simplified to a base
/// of about 200 faces and Loop-subdivided four times (the fish: 199 base faces, 50,944 at four
/// levels).
pub fn cow_loop() -> Result<SemiRegular, String> {
    let cow = load_obj_bytes(COW_NAME, COW_OBJ).map_err(|e| e.to_string())?;
    let base = simplified_base(&cow, 200)?;
    SemiRegular::subdivide(&base.positions, &base.triangles, 4, Scheme::Loop)
        .map_err(|e| e.to_string())
}

/// The paper's interactive-style session (§4): `frames` cameras, the first two thirds turning
/// once around the model at three radii, where it lies whole in the view, the rest zooming in
/// to a close-up of its surface.
pub fn session(center: Vec3, radius: f32, frames: u32, width: usize, height: usize) -> Vec<Camera> {
    let turn = (frames * 2 / 3).max(1);
    let direction = |i: u32| {
        let a = std::f32::consts::TAU * i.min(turn - 1) as f32 / turn as f32;
        Vec3::new(libm::sinf(a), 0.35, libm::cosf(a)).normalize()
    };
    (0..frames)
        .map(|i| {
            let dir = direction(i);
            let (eye, target) = if i < turn {
                (center + dir * 3.0 * radius, center)
            } else {
                let t = (i - turn + 1) as f32 / (frames - turn) as f32;
                let surface = center + dir * radius;
                let distance = 3.0 * (1.0 - t) + 1.3 * t;
                (center + dir * distance * radius, center.lerp(surface, t))
            };
            Camera {
                eye,
                target,
                up: Vec3::Y,
                fov_y: 45f32.to_radians(),
                near: radius * 0.01,
                far: radius * 10.0,
                width,
                height,
            }
        })
        .collect()
}

/// One frame of a session.
#[derive(Clone, Copy, Debug, Default)]
pub struct SessionFrame {
    /// Triangles drawn.
    pub faces: u32,
    /// Wavelets in the mesh (0 for the vertex forest).
    pub wavelets: u32,
    /// Milliseconds adapting, drawing the adapted mesh, drawing the full mesh.
    pub adapt_ms: f64,
    /// Milliseconds drawing the adapted mesh.
    pub render_ms: f64,
    /// Milliseconds drawing the full-detail mesh.
    pub full_ms: f64,
    /// PSNR against the full-detail frame.
    pub psnr_db: f64,
}

/// The finest level of a semi-regular file, for drawing (with its colours, if it has them).
pub fn finest_of(s: &SemiRegularView<'_>) -> IndexedMesh {
    let positions: Vec<[f32; 3]> = (0..s.vertices()).map(|v| s.position(v)).collect();
    let triangles = vdlod_core::wavelet::build::finest_triangles(s);
    IndexedMesh {
        normals: vertex_normals(&positions, &triangles),
        colors: s
            .has_colors()
            .then(|| (0..s.vertices()).map(|v| s.color(v)).collect()),
        positions,
        triangles,
    }
}

/// The full-detail mesh of a semi-regular mesh, for drawing.
pub fn finest_mesh(mesh: &SemiRegular) -> IndexedMesh {
    let triangles = mesh.finest_triangles();
    IndexedMesh {
        normals: vertex_normals(&mesh.positions, &triangles),
        positions: mesh.positions.clone(),
        colors: None,
        triangles,
    }
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// What a session needs of an engine: adapt to a camera, then draw.
trait Engine {
    fn adapt(&mut self, camera: &Camera) -> Result<FrameStats, String>;
    fn draw(&self, frame: &mut Frame, camera: &Camera, style: &Style) -> Result<(), String>;
    /// Wavelets in the mesh (0 for the vertex forest).
    fn wavelets(&self) -> u32;
}

/// The wavelet engine with a policy.
struct Wavelets<'a, 's, P> {
    cut: Box<DemoWaveletCut>,
    s: &'a SemiRegularView<'s>,
    policy: P,
}

impl<P: Policy> Engine for Wavelets<'_, '_, P> {
    fn adapt(&mut self, camera: &Camera) -> Result<FrameStats, String> {
        vdlod::adapt_wavelets(
            &mut self.cut,
            self.s,
            camera,
            &self.policy,
            &Budget::default(),
        )
        .map_err(|e| e.to_string())
    }

    fn draw(&self, frame: &mut Frame, camera: &Camera, style: &Style) -> Result<(), String> {
        let mesh = WaveletMesh::new(&self.cut, self.s, false);
        frame
            .draw_styled(&mesh, camera, style)
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn wavelets(&self) -> u32 {
        self.cut.included()
    }
}

/// The demo's vertex-forest cut for the experiments' meshes (up to 32,000 triangles).
type ForestCut = Cut<16_000, 32_000, 2_000>;

/// The vertex forest with a policy and, per frame, a triangle budget.
struct Forest<'a, 'h, P> {
    cut: Box<ForestCut>,
    h: &'a HierarchyView<'h>,
    policy: P,
    budgets: Vec<u32>,
    frame: usize,
}

impl<P: Policy> Engine for Forest<'_, '_, P> {
    fn adapt(&mut self, camera: &Camera) -> Result<FrameStats, String> {
        let budget = Budget {
            max_triangles: self.budgets.get(self.frame).copied().unwrap_or(u32::MAX),
            ..Budget::default()
        };
        self.frame += 1;
        vdlod::adapt(&mut self.cut, self.h, camera, &self.policy, &budget)
            .map_err(|e| e.to_string())
    }

    fn draw(&self, frame: &mut Frame, camera: &Camera, style: &Style) -> Result<(), String> {
        frame
            .draw_cut(&self.cut, self.h, camera, style)
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn wavelets(&self) -> u32 {
        0
    }
}

/// Flies `engine` along `cameras`, drawing each frame and the full mesh beside it.
fn fly(
    engine: &mut impl Engine,
    full: &IndexedMesh,
    cameras: &[Camera],
) -> Result<Vec<SessionFrame>, String> {
    let Some(first) = cameras.first() else {
        return Ok(Vec::new());
    };
    let mut frame = Frame::new(first.width, first.height).map_err(|e| e.to_string())?;
    let style = Style::default();
    let mut out = Vec::with_capacity(cameras.len());
    for camera in cameras {
        let start = Instant::now();
        let stats = engine.adapt(camera)?;
        let adapt_ms = ms(start);
        let start = Instant::now();
        frame
            .draw(&full.as_raster_mesh(), &style.params(camera))
            .map_err(|e| e.to_string())?;
        let full_ms = ms(start);
        let reference = frame.pixels().to_vec();
        let start = Instant::now();
        engine.draw(&mut frame, camera, &style)?;
        out.push(SessionFrame {
            faces: stats.triangles,
            wavelets: engine.wavelets(),
            adapt_ms,
            render_ms: ms(start),
            full_ms,
            psnr_db: psnr(frame.pixels(), &reference),
        });
    }
    Ok(out)
}

/// Flies a wavelet cut of `s` along `cameras` with `policy`, drawing each frame and the full
/// mesh beside it.
pub fn fly_wavelets<P: Policy + Copy>(
    s: &SemiRegularView<'_>,
    full: &IndexedMesh,
    cameras: &[Camera],
    policy: &P,
) -> Result<Vec<SessionFrame>, String> {
    let mut cut = DemoWaveletCut::boxed();
    cut.reset(s).map_err(|e| e.to_string())?;
    let mut engine = Wavelets {
        cut,
        s,
        policy: *policy,
    };
    fly(&mut engine, full, cameras)
}

fn write_csv(path: &Path, frames: &[SessionFrame]) -> Result<(), String> {
    let mut csv = String::from("frame,faces,wavelets,adapt_ms,render_ms,full_render_ms,psnr_db\n");
    for (i, f) in frames.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{i},{},{},{:.3},{:.3},{:.3},{:.2}",
            f.faces, f.wavelets, f.adapt_ms, f.render_ms, f.full_ms, f.psnr_db
        );
    }
    std::fs::write(path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// One of the experiments' meshes, ready to fly: its file (spheroid bounds), its full-detail
/// mesh and the session's cameras over it.
struct Flight {
    mesh: SemiRegular,
    bytes: Vec<u8>,
    full: IndexedMesh,
    cameras: Vec<Camera>,
}

impl Flight {
    fn new(mesh: SemiRegular) -> Result<Flight, String> {
        let bytes = mesh.to_bytes().map_err(|e| e.to_string())?;
        let full = finest_mesh(&mesh);
        let b = full.bounds();
        let cameras = session(b.center(), b.radius(), 90, 512, 512);
        Ok(Flight {
            mesh,
            bytes,
            full,
            cameras,
        })
    }

    /// The file, parsed.
    fn view(&self) -> Result<SemiRegularView<'_>, String> {
        SemiRegularView::parse(&self.bytes).map_err(|e| e.to_string())
    }
}

/// The meshes of `fig9` and `engines`: the 8,192-face sphere and the subdivided cow.
fn experiment_meshes() -> Result<[(&'static str, Flight); 2], String> {
    Ok([
        (
            "sphere",
            Flight::new(SemiRegular::sphere(5).map_err(|e| e.to_string())?)?,
        ),
        ("cow_loop4", Flight::new(cow_loop()?)?),
    ])
}

/// The paper's Fig. 9: the session over the 8,192-face sphere and over the cow subdivided to
/// 51,200 faces from a 200-face base (our stand-in for the fish), at a 0.5 px silhouette and 3.5
/// px interior tolerance (7x, as the paper sets it), with faces and milliseconds per frame;
/// and, as in its Fig. 13, the subdivided cow at 2 / 10 px from the first camera against three
/// uniform levels. Writes `NAME.csv` and `NAME.png` per mesh into `out`.
pub fn fig9(out: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let policy = QRefine {
        error: ScreenError {
            silhouette: 0.5,
            interior: 3.5,
        },
    };
    let mut lines = Vec::new();
    for (name, flight) in experiment_meshes()? {
        let s = flight.view()?;
        let (full, cameras) = (&flight.full, &flight.cameras);
        let frames = fly_wavelets(&s, full, cameras, &policy)?;
        write_csv(&out.join(format!("{name}.csv")), &frames)?;
        let faces: Vec<f64> = frames.iter().map(|f| f.faces as f64).collect();
        let full_faces = vec![full.triangles.len() as f64; frames.len()];
        let ours: Vec<f64> = frames.iter().map(|f| f.adapt_ms + f.render_ms).collect();
        let adapt: Vec<f64> = frames.iter().map(|f| f.adapt_ms).collect();
        let full_ms: Vec<f64> = frames.iter().map(|f| f.full_ms).collect();
        let png = chart::panels(&[
            Panel {
                title: vec![("faces per frame", BLUE), (", full model", GREY)],
                series: vec![(full_faces, GREY), (faces.clone(), BLUE)],
            },
            Panel {
                title: vec![
                    ("ms: adapt + render", ORANGE),
                    (", adapt", GREEN),
                    (", full model", GREY),
                ],
                series: vec![
                    (full_ms.clone(), GREY),
                    (ours, ORANGE),
                    (adapt.clone(), GREEN),
                ],
            },
        ])?;
        save(out, &format!("{name}.png"), &png)?;
        let mut line = format!(
            "experiment=fig9 mesh={name} full_faces={} base_faces={} faces_mean={:.0} faces_max={:.0} faces_last={:.0} psnr_db_mean={:.2} adapt_ms_median={:.3} render_ms_median={:.3} full_render_ms_median={:.3}",
            full.triangles.len(),
            s.counts().base_faces,
            mean(faces.iter().cloned()),
            faces.iter().cloned().fold(0.0, f64::max),
            faces.last().copied().unwrap_or(0.0),
            mean(frames.iter().map(|f| f.psnr_db.min(99.0))),
            median(adapt),
            median(frames.iter().map(|f| f.render_ms).collect()),
            median(full_ms),
        );
        if name == "cow_loop4" {
            let coarse = QRefine {
                error: ScreenError {
                    silhouette: 2.0,
                    interior: 10.0,
                },
            };
            let one = fly_wavelets(&s, full, &cameras[..1], &coarse)?;
            let _ = write!(
                line,
                " adaptive_2_10px_faces={} uniform3_faces={} paper_adaptive_faces=3943 paper_uniform3_faces=12736",
                one[0].faces,
                s.counts().base_faces * 64
            );
        }
        lines.push(line);
    }
    Ok(lines)
}

/// The paper's Fig. 10: the spheroid against Hoppe's bound over the session on the subdivided
/// cow, face counts per frame (at a distance, and in the close-up), for both engines: the
/// wavelet engine with its two bounds, and the vertex forest of the same finest mesh with
/// equation 3's spheroid and Hoppe's bound over the same residuals (and, for reference, its
/// default offset bound). Writes `fig10.csv` and `fig10.png` into `out`.
pub fn fig10(out: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let flight = Flight::new(cow_loop()?)?;
    let (full, cameras) = (&flight.full, &flight.cameras);
    let error = ScreenError {
        silhouette: 0.5,
        interior: 3.5,
    };
    let spheroid = QRefine { error };
    let hoppe = (Frustum, (BackFace, HoppeError { error }));
    let hoppe_bytes = flight
        .mesh
        .to_bytes_with(Bound::Hoppe)
        .map_err(|e| e.to_string())?;
    let s = flight.view()?;
    let h = SemiRegularView::parse(&hoppe_bytes).map_err(|e| e.to_string())?;
    let file = |bound| forest_file(full, bound);
    let offset = file(ErrorBound::Offset)?;
    let runs = [
        (
            "wavelet",
            "spheroid",
            fly_wavelets(&s, full, cameras, &spheroid)?,
        ),
        ("wavelet", "hoppe", fly_wavelets(&h, full, cameras, &hoppe)?),
        (
            "forest",
            "spheroid",
            fly_forest(&file(ErrorBound::Spheroid)?, full, cameras, &[], spheroid)?,
        ),
        (
            "forest",
            "hoppe",
            fly_forest(&file(ErrorBound::Hoppe)?, full, cameras, &[], hoppe)?,
        ),
        (
            "forest",
            "offset",
            fly_forest(&offset, full, cameras, &[], spheroid)?,
        ),
    ];
    // The offset bound held to the spheroid's faces frame by frame: PSNR at equal triangles.
    let budgets: Vec<u32> = runs[2].2.iter().map(|f| f.faces).collect();
    let held = fly_forest(&offset, full, cameras, &budgets, QRefine::new(0.1))?;
    let turn = cameras.len() * 2 / 3;
    let mut csv = String::from("frame");
    for (engine, bound, _) in &runs {
        let _ = write!(csv, ",{engine}_{bound}_faces,{engine}_{bound}_adapt_ms");
    }
    csv.push('\n');
    for i in 0..cameras.len() {
        csv.push_str(&i.to_string());
        for (_, _, frames) in &runs {
            let _ = write!(csv, ",{},{:.3}", frames[i].faces, frames[i].adapt_ms);
        }
        csv.push('\n');
    }
    let path = out.join("fig10.csv");
    std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let faces = |k: usize| runs[k].2.iter().map(|f| f.faces as f64).collect::<Vec<_>>();
    let png = chart::panels(&[
        Panel {
            title: vec![("wavelet faces: spheroid", BLUE), (", hoppe", ORANGE)],
            series: vec![(faces(1), ORANGE), (faces(0), BLUE)],
        },
        Panel {
            title: vec![
                ("forest faces: spheroid", BLUE),
                (", hoppe", ORANGE),
                (", offset", GREY),
            ],
            series: vec![(faces(4), GREY), (faces(3), ORANGE), (faces(2), BLUE)],
        },
    ])?;
    save(out, "fig10.png", &png)?;
    let held = ("forest", "offset_at_spheroid_faces", held);
    Ok(runs
        .iter()
        .chain([&held])
        .map(|(engine, bound, frames)| {
            format!(
                "experiment=fig10 mesh=cow_loop4 engine={engine} bound={bound} faces_far_mean={:.0} faces_close_mean={:.0} psnr_db_mean={:.2} adapt_ms_median={:.3}",
                mean(frames[..turn].iter().map(|f| f.faces as f64)),
                mean(frames[turn..].iter().map(|f| f.faces as f64)),
                mean(frames.iter().map(|f| f.psnr_db.min(99.0))),
                median(frames.iter().map(|f| f.adapt_ms).collect()),
            )
        })
        .collect())
}

/// Both engines over the same meshes at equal triangle counts: the wavelet engine at 1 px over
/// the session, the vertex forest of the same finest mesh held to the wavelet engine's triangle
/// count frame by frame (a budget, with a tolerance fine enough that it binds); PSNR against
/// full detail, adaptation time, file bytes per vertex and the cuts' memory at a 5,000-triangle
/// capacity. Writes `NAME.csv` per mesh into `out`.
pub fn engines(out: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut lines = Vec::new();
    for (name, flight) in experiment_meshes()? {
        let s = flight.view()?;
        let (mesh, full, cameras) = (&flight.mesh, &flight.full, &flight.cameras);
        let wavelet = fly_wavelets(&s, full, cameras, &QRefine::new(1.0))?;
        let budgets: Vec<u32> = wavelet.iter().map(|f| f.faces).collect();
        let (forest, hbytes) = forest_at(full, full, cameras, &budgets)?;
        let mut csv = String::from("frame,wavelet_faces,forest_faces,wavelet_psnr_db,forest_psnr_db,wavelet_adapt_ms,forest_adapt_ms\n");
        for (i, (w, f)) in wavelet.iter().zip(&forest).enumerate() {
            let _ = writeln!(
                csv,
                "{i},{},{},{:.2},{:.2},{:.3},{:.3}",
                w.faces, f.faces, w.psnr_db, f.psnr_db, w.adapt_ms, f.adapt_ms
            );
        }
        let path = out.join(format!("{name}.csv"));
        std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        let vertices = mesh.positions.len() as f64;
        for (engine, frames, file, cut_bytes) in [
            (
                "wavelet",
                &wavelet,
                flight.bytes.len(),
                WaveletCut::<1024, 5000, 2500, 625>::BYTES,
            ),
            ("forest", &forest, hbytes, Cut::<2508, 5000, 313>::BYTES),
        ] {
            lines.push(format!(
                "experiment=engines mesh={name} engine={engine} triangles_mean={:.0} psnr_db_mean={:.2} adapt_us_median={:.0} file_bytes_per_vertex={:.1} cut_bytes_5k_triangles={cut_bytes}",
                mean(frames.iter().map(|f| f.faces as f64)),
                mean(frames.iter().map(|f| f.psnr_db.min(99.0))),
                median(frames.iter().map(|f| f.adapt_ms * 1e3).collect()),
                file as f64 / vertices,
            ));
        }
    }
    Ok(lines)
}

/// The vertex forest of `source` flown over `cameras` with the triangle budgets `budgets` frame
/// by frame (and a tolerance fine enough that they bind), against `full` for PSNR; with its
/// file's size.
fn forest_at(
    source: &IndexedMesh,
    full: &IndexedMesh,
    cameras: &[Camera],
    budgets: &[u32],
) -> Result<(Vec<SessionFrame>, usize), String> {
    let hbytes = forest_file(source, ErrorBound::default())?;
    let frames = fly_forest(&hbytes, full, cameras, budgets, QRefine::new(0.1))?;
    Ok((frames, hbytes.len()))
}

/// The vertex forest of `source` with error bounds `bound`.
fn forest(source: &IndexedMesh, bound: ErrorBound) -> Result<Hierarchy, String> {
    let input = InputMesh {
        positions: &source.positions,
        colors: None,
        triangles: &source.triangles,
    };
    let options = BuildOptions {
        bound,
        ..BuildOptions::default()
    };
    build(&input, &options, &mut |_| {}).map_err(|e| e.to_string())
}

/// The vertex-forest file of `source` with error bounds `bound`.
fn forest_file(source: &IndexedMesh, bound: ErrorBound) -> Result<Vec<u8>, String> {
    Ok(forest(source, bound)?.to_bytes(false))
}

/// Flies the vertex forest of the file `hbytes` along `cameras` with `policy` and the triangle
/// budgets `budgets` frame by frame (none past their end), against `full` for PSNR.
fn fly_forest<P: Policy>(
    hbytes: &[u8],
    full: &IndexedMesh,
    cameras: &[Camera],
    budgets: &[u32],
    policy: P,
) -> Result<Vec<SessionFrame>, String> {
    let h = HierarchyView::parse(hbytes).map_err(|e| e.to_string())?;
    let mut cut = ForestCut::boxed();
    cut.reset(&h).map_err(|e| e.to_string())?;
    let mut engine = Forest {
        cut,
        h: &h,
        policy,
        budgets: budgets.to_vec(),
        frame: 0,
    };
    fly(&mut engine, full, cameras)
}

/// The wavelet engine's mesh of `s` adapted from the base mesh for `camera` by `policy`, drawn
/// in `style`.
fn wavelet_frame<P: Policy>(
    s: &SemiRegularView<'_>,
    camera: &Camera,
    policy: &P,
    style: &Style,
) -> Result<Frame, String> {
    let mut cut = DemoWaveletCut::boxed();
    cut.reset(s).map_err(|e| e.to_string())?;
    cut.adapt(s, &camera.view(), policy, &Budget::default());
    let mut frame = Frame::new(camera.width, camera.height).map_err(|e| e.to_string())?;
    frame
        .draw_styled(&WaveletMesh::new(&cut, s, false), camera, style)
        .map_err(|e| e.to_string())?;
    Ok(frame)
}

/// Checker cells along each base edge in [`checker_sheet`].
const CHECKER_CELLS: usize = 8;

/// A checker over the base faces of `s` (each face its own chart, [`crate::atlas`]) from
/// `camera`: the base mesh, the wavelet engine adapted by `policy`, the vertex forest of the
/// same finest mesh held to the same triangle count, and full detail, in `NAME_checker.png` in
/// `out`; returns the summary line.
fn checker_sheet(
    name: &str,
    s: &SemiRegularView<'_>,
    camera: &Camera,
    policy: &impl Policy,
    out: &Path,
) -> Result<String, String> {
    use crate::atlas::{checker_texels, corners};
    use crate::importance::{sheet, Panel};
    use vdlod_raster::texture::{Filter, Texture, Wrap};
    let cells = CHECKER_CELLS;
    let texels = checker_texels(cells);
    let checker = Texture::new(&texels, cells, cells, Filter::Nearest, Wrap::Repeat)
        .map_err(|e| e.to_string())?;
    let style = Style {
        base_color: [255; 3],
        ..Style::default()
    };
    let mut frame = Frame::new(camera.width, camera.height).map_err(|e| e.to_string())?;
    let mut draw = |mesh: &crate::atlas::CornerMesh| -> Result<Vec<Rgba8>, String> {
        frame
            .draw_textured(&mesh.as_raster_mesh(), camera, &style, &checker)
            .map_err(|e| e.to_string())?;
        Ok(frame.pixels().to_vec())
    };

    let full = finest_of(s);
    let reference = draw(&corners(&full.as_raster_mesh(), s, |i| i as u32))?;

    let mut wavelet = DemoWaveletCut::boxed();
    wavelet.reset(s).map_err(|e| e.to_string())?;
    let base = corners(&WaveletMesh::new(&wavelet, s, false), s, |i| {
        wavelet.vertex_id(i)
    });
    let base_pixels = draw(&base)?;
    let w = wavelet.adapt(s, &camera.view(), policy, &Budget::default());
    let w_mesh = WaveletMesh::new(&wavelet, s, false);
    let w_corners = corners(&w_mesh, s, |i| wavelet.vertex_id(i));
    let w_pixels = draw(&w_corners)?;

    let hierarchy = forest(&full, ErrorBound::default())?;
    let hbytes = hierarchy.to_bytes(false);
    let h = HierarchyView::parse(&hbytes).map_err(|e| e.to_string())?;
    // A node stands for the leaf down its first children: a point of the surface it covers.
    // Leaves are input vertices, that is semi-regular vertex ids, numbered anew in the file.
    let mut leaf_of = vec![0u32; h.nodes() as usize];
    for (v, &id) in hierarchy.file_ids().iter().enumerate() {
        leaf_of[id as usize] = v as u32;
    }
    for i in (0..h.nodes()).rev().filter(|&i| h.is_parent(i)) {
        leaf_of[i as usize] = leaf_of[h.children(i)[0] as usize];
    }
    let mut forest_cut = ForestCut::boxed();
    forest_cut.reset(&h).map_err(|e| e.to_string())?;
    let budget = Budget {
        max_triangles: w.triangles,
        ..Budget::default()
    };
    let f = forest_cut.adapt(&h, &camera.view(), &QRefine::new(0.1), &budget);
    let f_mesh = CutMesh::new(&forest_cut, &h, false);
    let nodes = forest_cut.nodes();
    let f_corners = corners(&f_mesh, s, |i| leaf_of[nodes[i] as usize]);
    let f_pixels = draw(&f_corners)?;

    let (w_db, f_db) = (
        psnr(&w_pixels, &reference).min(99.0),
        psnr(&f_pixels, &reference).min(99.0),
    );
    let panels = [
        Panel {
            caption: format!("base mesh: {} triangles", base.triangles.len()),
            pixels: base_pixels,
        },
        Panel {
            caption: format!("wavelets: {} triangles, {w_db:.1} dB", w.triangles),
            pixels: w_pixels,
        },
        Panel {
            caption: format!("vertex forest: {} triangles, {f_db:.1} dB", f.triangles),
            pixels: f_pixels,
        },
        Panel {
            caption: format!("full detail: {} triangles", full.triangles.len()),
            pixels: reference,
        },
    ];
    let png = sheet(&panels, 2, [camera.width, camera.height])?;
    save(out, &format!("{name}_checker.png"), &png)?;
    Ok(format!(
        "experiment=fish mesh={name} stage=checker wavelet_triangles={} forest_triangles={} \
         wavelet_checker_psnr_db={w_db:.2} forest_checker_psnr_db={f_db:.2} \
         forest_triangles_across_faces={} forest_triangles_torn={} \
         wavelet_triangles_across_faces={}",
        w.triangles, f.triangles, f_corners.across, f_corners.torn, w_corners.across
    ))
}

/// The wavelet paper's fish experiment (its Fig. 13 and §4) on our meshes: the bunny and the
/// cow remeshed over a base of about 200 faces with four levels (the fish: 199 base faces,
/// 50,944 at four levels); the remesh's distances to the input; from the session's first
/// camera, the adaptive mesh at a 2 px silhouette / 10 px interior tolerance against three
/// uniform levels (paper: 3,943 against 12,736 faces); and over the whole session both engines
/// at equal triangle counts, PSNR against the *input* (the vertex forest built from the input
/// itself). Writes `NAME.csv` and `NAME_coarse.png`, `NAME_adapted.png` and `NAME_fine.png`
/// (wireframe, from that first camera), and `NAME_checker.png` (the same with a checker over
/// the base faces, and the vertex forest beside them: `checker_sheet`) per mesh into `out`.
pub fn fish(out: &Path) -> Result<Vec<String>, String> {
    use crate::mesh::{BUNNY_NAME, BUNNY_OBJ};
    use vdlod_core::remesh::RemeshOptions;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut lines = Vec::new();
    for (name, file, obj) in [("bunny", BUNNY_NAME, BUNNY_OBJ), ("cow", COW_NAME, COW_OBJ)] {
        let input = load_obj_bytes(file, obj).map_err(|e| e.to_string())?;
        let options = RemeshOptions {
            base_faces: 200,
            levels: 4,
        };
        let done = crate::remesh::remesh_with_progress(&input, &options, false)?;
        lines.push(format!(
            "experiment=fish mesh={name} stage=remesh input_faces={} {}",
            input.triangles.len(),
            crate::remesh::summary(&done, options.levels)
        ));
        let bytes = done.remesh.mesh.to_bytes().map_err(|e| e.to_string())?;
        let s = SemiRegularView::parse(&bytes).map_err(|e| e.to_string())?;
        let b = input.bounds();
        let cameras = session(b.center(), b.radius(), 90, 512, 512);
        let coarse = QRefine {
            error: ScreenError {
                silhouette: 2.0,
                interior: 10.0,
            },
        };
        let first = fly_wavelets(&s, &input, &cameras[..1], &coarse)?;
        // The pictures: the base mesh, the adapted mesh and the finest level from that camera.
        let wire = Style {
            wireframe: Some([20, 20, 20]),
            ..Style::default()
        };
        for (picture, frame) in [
            (
                "coarse",
                wavelet_frame(&s, &cameras[0], &ScreenError::new(1e9), &wire)?,
            ),
            ("adapted", wavelet_frame(&s, &cameras[0], &coarse, &wire)?),
            (
                "fine",
                wavelet_frame(&s, &cameras[0], &ScreenError::new(1e-6), &wire)?,
            ),
        ] {
            save(out, &format!("{name}_{picture}.png"), &frame_png(&frame)?)?;
        }
        lines.push(checker_sheet(name, &s, &cameras[0], &coarse, out)?);
        lines.push(format!(
            "experiment=fish mesh={name} stage=fig13 adaptive_2_10px_faces={} uniform3_faces={} \
             full_faces={} psnr_db={:.2} paper_adaptive_faces=3943 paper_uniform3_faces=12736",
            first[0].faces,
            s.counts().base_faces * 64,
            s.counts().finest_faces(),
            first[0].psnr_db,
        ));
        let wavelet = fly_wavelets(&s, &input, &cameras, &QRefine::new(1.0))?;
        let budgets: Vec<u32> = wavelet.iter().map(|f| f.faces).collect();
        let (forest, _) = forest_at(&input, &input, &cameras, &budgets)?;
        let mut csv =
            String::from("frame,wavelet_faces,forest_faces,wavelet_psnr_db,forest_psnr_db\n");
        for (i, (w, f)) in wavelet.iter().zip(&forest).enumerate() {
            let _ = writeln!(
                csv,
                "{i},{},{},{:.2},{:.2}",
                w.faces, f.faces, w.psnr_db, f.psnr_db
            );
        }
        let path = out.join(format!("{name}.csv"));
        std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        for (engine, frames) in [("wavelet", &wavelet), ("forest", &forest)] {
            lines.push(format!(
                "experiment=fish mesh={name} engine={engine} triangles_mean={:.0} psnr_db_mean={:.2} adapt_us_median={:.0}",
                mean(frames.iter().map(|f| f.faces as f64)),
                mean(frames.iter().map(|f| f.psnr_db.min(99.0))),
                median(frames.iter().map(|f| f.adapt_ms * 1e3).collect()),
            ));
        }
    }
    Ok(lines)
}
