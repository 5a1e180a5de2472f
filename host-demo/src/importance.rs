//! The importance paper's terrain experiment (`vdlod-demo reproduce terrain`).
//!
//! Ng, Kluge, Sheng and Guo, "View importance for selective refinement of progressive meshes"
//! (the importance paper): a 101 x 101 heightmap with a colormap makes a 20,000-triangle terrain;
//! its colour-aware collapse cost `Gerr^2 + length^2 + sqrt(length * dcolor)` reduces it to 25%
//! (its Figs. 3-4) and 10%, and the 10% mesh is then refined from one camera with the triangle
//! importance test at a threshold of 0.3 (its Figs. 7-10). Here the terrain is the procedural
//! island at 101 x 101 samples, one unit between samples as in the paper's grid, so the paper's
//! threshold carries over: 0.3 in the paper's units is `0.3 / diagonal` in
//! [`Importance`]'s. Each reduction is made twice, with the colour cost and with QEM, and
//! compared with full detail by PSNR from the top and in perspective at the same triangle
//! count.
//!
//! The paper gives neither its terrain's units nor its field of view. With one unit between
//! samples and a 45 degree field of view, its threshold refines only the triangles nearest the
//! camera (about 90 of them here), so the refinement is also shown at [`Importance`]'s default.
//!
//! Writes the paper's figure set (`colormap.png`, `heightmap.png`, and the original, 25%, 10%
//! and refined meshes from the top and in perspective, with their edges) and `figure.png`, all
//! of them on one sheet; returns one `key=value` line per reduction, threshold and cost.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use vdlod::Style;
use vdlod_core::adapt::Budget;
use vdlod_core::build::{BuildOptions, Cost};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{Frustum, Importance};
use vdlod_raster::{Rgba8, Shading};

use crate::camera::Camera;
use crate::frame::{encode_png, Frame};
use crate::hierarchy::build_with_progress;
use crate::label;
use crate::lod::psnr;
use crate::mesh::IndexedMesh;
use crate::render::style;
use crate::terrain::{Terrain, DEFAULT_VERTICAL_SCALE};

/// Samples along each side: the paper's 20,000-triangle grid.
pub const SAMPLES: usize = 101;
/// The procedural island's seed.
const SEED: u32 = 7;
/// The paper's importance threshold, in its terrain's units (one unit between samples).
pub const PAPER_THRESHOLD: f32 = 0.3;
/// Each picture's size.
const WIDTH: usize = 480;
const HEIGHT: usize = 360;

/// A cut big enough for the whole terrain (10,201 vertices, 20,000 triangles).
type TerrainCut = Cut<10_240, 20_480, 2_560>;

/// The two views of every figure: straight down, and the paper's perspective from one side.
fn cameras() -> [(&'static str, Camera); 2] {
    let c = (SAMPLES - 1) as f32 * 0.5;
    let base = Camera {
        eye: Vec3::ZERO,
        target: Vec3::new(c, 0.0, c),
        up: Vec3::Y,
        fov_y: 60f32.to_radians(),
        near: 0.5,
        far: 600.0,
        width: WIDTH,
        height: HEIGHT,
    };
    [
        (
            "top",
            Camera {
                eye: Vec3::new(c, 2.2 * c, c),
                up: Vec3::NEG_Z,
                fov_y: 55f32.to_radians(),
                ..base
            },
        ),
        (
            "perspective",
            Camera {
                eye: Vec3::new(c, 0.14 * c, 0.05 * c),
                target: Vec3::new(c, 0.0, 0.7 * c),
                fov_y: 45f32.to_radians(),
                ..base
            },
        ),
    ]
}

/// One hierarchy built for the experiment.
struct Built {
    bytes: Vec<u8>,
    seconds: f64,
    /// The parents (file ids) in the reverse of the order the builder collapsed them.
    replay: Vec<u32>,
}

fn build(mesh: &IndexedMesh, cost: Cost, base_vertices: u32) -> Result<Built, String> {
    let opts = BuildOptions {
        cost,
        base_vertices,
        ..BuildOptions::default()
    };
    let (hierarchy, bytes, seconds) =
        build_with_progress(mesh, &opts, false).map_err(|e| format!("terrain: {e}"))?;
    let ids = hierarchy.file_ids();
    let replay = (hierarchy.leaves as usize..ids.len())
        .rev()
        .map(|p| ids[p])
        .collect();
    Ok(Built {
        bytes,
        seconds,
        replay,
    })
}

/// The mesh the builder had when `triangles` were left: the splits replayed from the base mesh
/// in the reverse of the order the collapses were made, until there are at least `triangles`.
fn reduced(
    h: &HierarchyView<'_>,
    replay: &[u32],
    triangles: usize,
) -> Result<Box<TerrainCut>, String> {
    let mut cut = TerrainCut::boxed();
    cut.reset(h).map_err(|e| e.to_string())?;
    for &p in replay {
        if cut.triangles().len() >= triangles {
            break;
        }
        cut.split(h, p)
            .map_err(|e| format!("replaying split {p}: {e:?}"))?;
    }
    Ok(cut)
}

/// Shaded with the terrain's colours, with dark edges when `edges`.
fn terrain_style(edges: bool) -> Style {
    Style {
        vertex_colors: true,
        ..style(Shading::Gouraud, edges)
    }
}

/// Pixels of `cut` seen by `camera`.
fn draw_cut(
    frame: &mut Frame,
    cut: &TerrainCut,
    h: &HierarchyView<'_>,
    camera: &Camera,
    edges: bool,
) -> Result<Vec<Rgba8>, String> {
    let drawn = terrain_style(edges);
    frame
        .draw_cut(cut, h, camera, &drawn)
        .map_err(|e| e.to_string())?;
    Ok(frame.pixels().to_vec())
}

/// Pixels of the full-detail mesh seen by `camera`.
fn draw_full(
    frame: &mut Frame,
    full: &IndexedMesh,
    camera: &Camera,
    edges: bool,
) -> Result<Vec<Rgba8>, String> {
    let params = terrain_style(edges).params(camera);
    frame
        .draw(&full.as_raster_mesh(), &params)
        .map_err(|e| e.to_string())?;
    Ok(frame.pixels().to_vec())
}

/// A picture of a figure sheet ([`sheet`]), with its caption.
pub(crate) struct Panel {
    pub(crate) caption: String,
    pub(crate) pixels: Vec<Rgba8>,
}

/// A `SAMPLES`-square image scaled up to a panel, nearest sample.
fn map_panel(caption: &str, sample: impl Fn(usize, usize) -> [u8; 3]) -> Panel {
    let side = HEIGHT;
    let mut pixels = vec![crate::frame::BACKGROUND; WIDTH * HEIGHT];
    let left = (WIDTH - side) / 2;
    for y in 0..side {
        for x in 0..side {
            let (c, r) = (x * SAMPLES / side, y * SAMPLES / side);
            let [red, green, blue] = sample(c, r);
            pixels[y * WIDTH + left + x] = Rgba8([red, green, blue, 255]);
        }
    }
    Panel {
        caption: caption.to_string(),
        pixels,
    }
}

fn save(out: &Path, name: &str, width: usize, height: usize, px: &[Rgba8]) -> Result<(), String> {
    let path = out.join(name);
    let png = encode_png(width, height, px).map_err(|e| e.to_string())?;
    std::fs::write(&path, png).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// The panels (each `width x height`) in `columns` columns, each captioned, as one PNG.
pub(crate) fn sheet(
    panels: &[Panel],
    columns: usize,
    [width, height]: [usize; 2],
) -> Result<Vec<u8>, String> {
    let rows = panels.len().div_ceil(columns);
    let (w, h) = (width * columns, height * rows);
    let mut pixels = vec![crate::frame::BACKGROUND; w * h];
    for (k, p) in panels.iter().enumerate() {
        let (x0, y0) = ((k % columns) * width, (k / columns) * height);
        for y in 0..height {
            let row = &p.pixels[y * width..(y + 1) * width];
            pixels[(y0 + y) * w + x0..(y0 + y) * w + x0 + width].copy_from_slice(row);
        }
    }
    let bytes = encode_png(w, h, &pixels).map_err(|e| e.to_string())?;
    let mut pixmap = tiny_skia::Pixmap::decode_png(&bytes).map_err(|e| e.to_string())?;
    for (k, p) in panels.iter().enumerate() {
        let (x0, y0) = ((k % columns) * width, (k / columns) * height);
        let text = p.caption.as_str();
        let (x, y) = (x0 as f32 + 6.0, y0 as f32 + 6.0);
        label::draw(&mut pixmap, text, x, y, 2.0, (235, 235, 235));
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}

/// Runs the experiment, writing its pictures into `out`; returns its summary lines.
pub fn terrain(out: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let land = Terrain::procedural(SAMPLES, SEED, DEFAULT_VERTICAL_SCALE);
    let mut full = land.mesh();
    let total = full.triangles.len();
    let views = cameras();
    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;

    // The maps and the original.
    let colors = land.colors.clone().unwrap_or_default();
    let colormap = map_panel("colormap", |c, r| colors[r * SAMPLES + c]);
    let top = land
        .heights
        .iter()
        .copied()
        .fold(f32::MIN_POSITIVE, f32::max);
    let heightmap = map_panel("heightmap", |c, r| {
        [(land.heights[r * SAMPLES + c] / top * 255.0) as u8; 3]
    });
    save(out, "colormap.png", WIDTH, HEIGHT, &colormap.pixels)?;
    save(out, "heightmap.png", WIDTH, HEIGHT, &heightmap.pixels)?;
    let mut references = Vec::new();
    let mut top_row = vec![colormap];
    let mut side_row = vec![heightmap];
    for (k, (view, camera)) in views.iter().enumerate() {
        references.push(draw_full(&mut frame, &full, camera, false)?);
        let edges = draw_full(&mut frame, &full, camera, true)?;
        save(out, &format!("original_{view}.png"), WIDTH, HEIGHT, &edges)?;
        let panel = Panel {
            caption: format!("original: {total} triangles"),
            pixels: edges,
        };
        if k == 0 { &mut top_row } else { &mut side_row }.push(panel);
    }
    full.reorder_for_locality();

    let mut lines = Vec::new();
    let costs = [(Cost::Color, "color"), (Cost::Quadric, "qem")];
    let mut ten_percent_vertices = [0u32; 2];
    for (ci, &(cost, cost_name)) in costs.iter().enumerate() {
        let built = build(&full, cost, 0)?;
        let h = HierarchyView::parse(&built.bytes).map_err(|e| e.to_string())?;
        for percent in [25usize, 10] {
            let want = total * percent / 100;
            let cut = reduced(&h, &built.replay, want)?;
            if percent == 10 {
                ten_percent_vertices[ci] = cut.vertex_count() as u32;
            }
            let mut line = format!(
                "experiment=terrain cost={cost_name} mesh={percent}% grid={SAMPLES}x{SAMPLES} full_triangles={total} triangles={} paper_triangles={want} build_s={:.3}",
                cut.triangles().len(),
                built.seconds,
            );
            for (k, (view, camera)) in views.iter().enumerate() {
                let shaded = draw_cut(&mut frame, &cut, &h, camera, false)?;
                let _ = write!(line, " psnr_{view}_db={:.2}", psnr(&shaded, &references[k]));
                if cost == Cost::Color {
                    let edges = draw_cut(&mut frame, &cut, &h, camera, true)?;
                    save(out, &format!("{percent}_{view}.png"), WIDTH, HEIGHT, &edges)?;
                    let panel = Panel {
                        caption: format!("{percent} percent: {} triangles", cut.triangles().len()),
                        pixels: edges,
                    };
                    if k == 0 { &mut top_row } else { &mut side_row }.push(panel);
                }
            }
            lines.push(line);
        }
    }

    // Refined from the 10% mesh with the importance test, seen from the perspective camera: at
    // the paper's threshold, and at ours (the same test, normalised; see `Importance`).
    let (_, eye) = &views[1];
    let mut bases = Vec::new();
    for (ci, &(cost, _)) in costs.iter().enumerate() {
        bases.push(build(&full, cost, ten_percent_vertices[ci])?);
    }
    for (setting, paper_units) in [("paper", Some(PAPER_THRESHOLD)), ("default", None)] {
        let mut color_triangles = 0;
        for (ci, &(cost, cost_name)) in costs.iter().enumerate() {
            let h = HierarchyView::parse(&bases[ci].bytes).map_err(|e| e.to_string())?;
            let mut policy = Importance::for_model(Importance::DEFAULT_THRESHOLD, &h);
            if let Some(t) = paper_units {
                policy.threshold = t / policy.size;
            }
            let mut budget = Budget::default();
            if cost == Cost::Quadric {
                // At the colour cut's triangle count: a lower threshold, the count as a budget.
                policy.threshold *= 0.25;
                budget.max_triangles = color_triangles;
            }
            let mut cut = TerrainCut::boxed();
            cut.reset(&h).map_err(|e| e.to_string())?;
            let start = Instant::now();
            let mut rounds = 0;
            while rounds < 16 {
                let s = cut.adapt(&h, &eye.view(), &(Frustum, policy), &budget);
                rounds += 1;
                if s.vsplits + s.ecols == 0 {
                    break;
                }
            }
            let adapt_ms = start.elapsed().as_secs_f64() * 1e3;
            let n = cut.triangles().len();
            if cost == Cost::Color {
                color_triangles = n as u32;
            }
            let mut line = format!(
                "experiment=terrain cost={cost_name} mesh=10%+importance threshold_setting={setting} base_triangles={} triangles={n} threshold={:.6} threshold_paper_units={:.4} rounds={rounds} adapt_ms={adapt_ms:.2}",
                h.base_triangles(),
                policy.threshold,
                policy.threshold * policy.size,
            );
            if cost == Cost::Quadric {
                line.push_str(" budget=color_triangles");
            }
            for (k, (view, camera)) in views.iter().enumerate() {
                let shaded = draw_cut(&mut frame, &cut, &h, camera, false)?;
                let _ = write!(line, " psnr_{view}_db={:.2}", psnr(&shaded, &references[k]));
                if cost == Cost::Color {
                    let edges = draw_cut(&mut frame, &cut, &h, camera, true)?;
                    save(
                        out,
                        &format!("refined_{setting}_{view}.png"),
                        WIDTH,
                        HEIGHT,
                        &edges,
                    )?;
                    let panel = Panel {
                        caption: format!("refined ({setting} threshold): {n} triangles"),
                        pixels: edges,
                    };
                    if k == 0 { &mut top_row } else { &mut side_row }.push(panel);
                }
            }
            lines.push(line);
        }
    }
    let columns = top_row.len();
    top_row.extend(side_row);
    let png = sheet(&top_row, columns, [WIDTH, HEIGHT])?;
    let path = out.join("figure.png");
    std::fs::write(&path, png).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    Ok(lines)
}
