//! The merge-tree paper's Table 1 (`vdlod-demo reproduce table1`).
//!
//! Kuo and Nathan's merge-tree paper ("View-dependent simplification using merge trees",
//! `../shared/seeds/000_*.txt`, §3.4 and §4) refines a Loop-subdivided bunny wherever a vertex's
//! bounding sphere is inside a modelled view frustum *and* near the camera, lets everything else
//! simplify, and moves that frustum on a circle in the xz-plane at the height of the model's
//! centre. Its Table 1: drawing every triangle ran at 4 frames per second; with frustum sizes
//! 0.4, 0.2 and 0.1 (each a quarter of the area of the one before) the adapted model ran at 20,
//! 40 and 50 (5x, 10x, 12.5x).
//!
//! Here, faithfully to that set-up:
//!
//! - the input is the bunny after one step of Loop subdivision (`vdlod-demo subdivide
//!   fixtures/bunny.obj --levels 1 -o bunny_loop.obj` writes the same mesh), its hierarchy built
//!   with the paper's cost (shortest edge first, region-of-influence balancing: `--cost edge
//!   --balanced`);
//! - the policy is [`MergeTree`] with `near` = the eye's distance from the model's centre (the
//!   half of the model that faces the eye is near);
//! - the frustum size `s` scales the width and height of the orbit camera's frustum by `c s`,
//!   where the calibration `c` is found by bisection so that at `s` = 0.2 the frustum and the
//!   near test hold 10% of the leaves (the input's vertices), averaged over the orbit: the
//!   paper's 4 -> 40 frames per second implies about a tenth of the model drawn. Sizes 0.4 and
//!   0.1 then have four times and a quarter of that cross-section;
//! - the whole adapted model is drawn from the orbit camera (the paper's Fig. 2), at 640x480,
//!   against drawing every triangle from the same camera, in the same frame.
//!
//! The summary gives, per frustum size, the triangles kept, the operations per frame, and the
//! median adapt, render and full-detail milliseconds; the speed-up is the full-detail frame's
//! median over the adapted frame's (adapt + render). A flight may put the cut's slots back in
//! order every so many frames (`Cut::renumber`), as an application drawing the cut would: that
//! is timed apart, and its mean per frame is added to the adapt column (`renumber_ms` says how
//! much of it it is), since a median would leave those frames out. With several rounds
//! (`reproduce table1 --rounds N`) every flight is flown N times in turn and each line gives the
//! medians over rounds and the range of the speed-up and of adaptation's share.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use vdlod::{Camera, Orbit};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::build::{BuildOptions, Cost};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{MergeTree, View};
use vdlod_raster::{CheckedMesh, Shading};

use crate::camera::merge_tree_orbit;
use crate::chart::{self, BLUE, GREY, ORANGE};
use crate::frame::Frame;
use crate::hierarchy::build_with_progress;
use crate::importance::{sheet, Panel};
use crate::mesh::IndexedMesh;
use crate::render::{camera_params, style};
use crate::stats::{mean, median};

/// The frustum sizes of the paper's Table 1, with the speed-up it measured at each.
pub const SIZES: [(f32, f32); 3] = [(0.4, 5.0), (0.2, 10.0), (0.1, 12.5)];
/// The share of the leaves the 0.2 frustum holds once calibrated.
pub const CALIBRATED_SHARE: f64 = 0.10;
/// The frames' size.
const WIDTH: usize = 640;
const HEIGHT: usize = 480;

/// The cut: the Loop-subdivided bunny at full detail fits.
type BigCut = Cut<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>;

/// What to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setup {
    /// Loop subdivision steps applied to the input (the paper: one, on its bunny).
    pub loop_steps: u32,
    /// One flight per entry: frames in one revolution of the orbit (how fast the frustum
    /// moves), and frames between renumberings of the cut's slots (`Cut::renumber`; 0: never).
    pub flights: &'static [(u32, u32)],
    /// Rounds: every flight is flown this many times in turn (at least once), and each summary
    /// line gives the median over rounds, with the range of the speed-up and of adaptation's
    /// share when there are several.
    pub rounds: u32,
    /// The flight whose frames `table1_ms.png` charts (an index into `flights`).
    pub charted: usize,
}

impl Setup {
    /// What `reproduce table1` runs on the bundled bunny: one subdivision step (301,632
    /// triangles); one revolution in 100 frames (3.6 degrees a frame), in 400 (0.9) and in 800
    /// (0.45), the 400-frame one also with the slots renumbered every 32 frames. The paper does
    /// not say how fast its frustum moved, and adaptation's share of the frame follows the
    /// speed.
    pub const REPRODUCE: Setup = Setup {
        loop_steps: 1,
        flights: &[(100, 0), (400, 0), (400, 32), (800, 0)],
        rounds: 1,
        charted: 1,
    };
}

/// The model of the experiment and its hierarchy.
pub struct Model {
    /// The subdivided input, its triangles in a locality order (as a renderer prepares a mesh).
    pub mesh: IndexedMesh,
    /// Its hierarchy (`--cost edge --balanced`).
    pub bytes: Vec<u8>,
    /// Seconds the build took.
    pub build_seconds: f64,
}

impl Model {
    /// `input` after `loop_steps` steps of Loop subdivision, and its hierarchy.
    pub fn new(mut mesh: IndexedMesh, loop_steps: u32, progress: bool) -> Result<Model, String> {
        for _ in 0..loop_steps {
            mesh = mesh.loop_subdivide();
        }
        let options = BuildOptions {
            cost: Cost::ShortestEdge,
            balanced: true,
            ..BuildOptions::default()
        };
        let (_, bytes, build_seconds) =
            build_with_progress(&mesh, &options, progress).map_err(|e| e.to_string())?;
        mesh.reorder_for_locality();
        Ok(Model {
            mesh,
            bytes,
            build_seconds,
        })
    }
}

/// The modelled frustum of `camera` at frustum size `scale` (already calibrated).
fn modelled(camera: &Camera, scale: f32) -> View {
    camera.view_scaled(scale)
}

/// The share of `points` inside the frustum of size `scale` and within `near` of the eye,
/// averaged over `cameras`.
pub fn share_in_view(points: &[[f32; 3]], cameras: &[Camera], scale: f32, near: f32) -> f64 {
    let inside: usize = cameras
        .iter()
        .map(|camera| {
            let view = modelled(camera, scale);
            points
                .iter()
                .filter(|&&p| {
                    let r = glam::Vec3::from(p) - camera.eye;
                    r.length_squared() < near * near && view.sphere_visible(p, 0.0)
                })
                .count()
        })
        .sum();
    inside as f64 / (points.len() * cameras.len()).max(1) as f64
}

/// The calibration `c`: the frustum scale per unit of frustum size at which size 0.2 holds
/// [`CALIBRATED_SHARE`] of `points` within `near` of the eyes of `cameras` (bisection: the share
/// grows with the scale).
pub fn calibrate(points: &[[f32; 3]], cameras: &[Camera], near: f32) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 40.0f32);
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if share_in_view(points, cameras, 0.2 * mid, near) < CALIBRATED_SHARE {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// One frustum size's flight.
#[derive(Clone, Debug, Default)]
pub struct Row {
    /// Frustum size.
    pub size: f32,
    /// Mean triangles of the adapted model, per frame after the first.
    pub triangles: f64,
    /// Mean splits + collapses per frame after the first.
    pub ops: f64,
    /// Median milliseconds adapting (plus `renumber_ms`), drawing the cut, drawing every
    /// triangle.
    pub adapt_ms: f64,
    /// Mean milliseconds per frame renumbering the cut's slots (`Cut::renumber`; 0 without).
    pub renumber_ms: f64,
    /// See `adapt_ms`.
    pub render_ms: f64,
    /// See `adapt_ms`.
    pub full_ms: f64,
    /// The first frame's adapt milliseconds (from the base mesh).
    pub first_adapt_ms: f64,
    /// Every frame after the first.
    pub frames: Vec<FrameTimes>,
}

/// One frame's milliseconds: adapting, renumbering the slots before it (0 in most frames),
/// drawing the cut, drawing every triangle.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    /// Adapting.
    pub adapt: f64,
    /// Renumbering the cut's slots before adapting.
    pub renumber: f64,
    /// Drawing the cut.
    pub render: f64,
    /// Drawing every triangle.
    pub full: f64,
}

/// One of `frames`' times, frame by frame.
fn column(frames: &[FrameTimes], time: fn(&FrameTimes) -> f64) -> Vec<f64> {
    frames.iter().map(time).collect()
}

impl Row {
    /// Full detail's median frame over the adapted frame's.
    pub fn speedup(&self) -> f64 {
        self.full_ms / (self.adapt_ms + self.render_ms).max(1e-9)
    }

    /// The share of the adapted frame spent adapting.
    pub fn adapt_share(&self) -> f64 {
        self.adapt_ms / (self.adapt_ms + self.render_ms).max(1e-9)
    }
}

/// Where a flight goes and what it refines: one revolution of `orbit`, the merge-tree policy
/// with `near`, the frustum of size `size` scaled by the calibration `c`.
struct Flight<'a> {
    orbit: &'a Orbit,
    near: f32,
    c: f32,
    size: f32,
    /// Frames between renumberings of the cut's slots (0: never).
    renumber_every: u32,
}

/// Flies `flight`, timing the cut's adaptation and its drawing in each frame, then full detail's
/// drawing from each frame's camera (a row of `csv` each); the cut at frame `picture` is drawn
/// into `shot` with its edges. Full detail is drawn in a pass of its own, as an application that
/// draws every triangle would (its indices checked once, `CheckedMesh`): drawn between two
/// adaptations, its 300,000 triangles would evict
/// the cut from the caches, which an application of the adapted model never does (it made
/// adaptation a quarter slower).
fn fly(
    model: &Model,
    h: &HierarchyView<'_>,
    (flight, round): (&Flight<'_>, u32),
    picture: u32,
    shot: &mut Frame,
    csv: &mut String,
) -> Result<Row, String> {
    let Flight {
        orbit,
        near,
        c,
        size,
        renumber_every,
    } = *flight;
    let mut cut = BigCut::boxed();
    cut.reset(h).map_err(|e| e.to_string())?;
    let policy = MergeTree { near };
    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    let mut reference = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    // An application that draws every triangle checks its index buffer once, not every frame.
    let full_mesh = CheckedMesh::new(model.mesh.as_raster_mesh()).map_err(|e| e.to_string())?;
    let look = style(Shading::Gouraud, false);
    let mut rows = Vec::new();
    for i in 0..orbit.frames {
        let camera = orbit.camera(i);
        let view = modelled(&camera, c * size);
        // Every `renumber_every` frames, before adapting, the slots are put back in order
        // (timed apart: the median would hide it, so its mean is added to the adaptation's).
        let start = Instant::now();
        if renumber_every > 0 && i % renumber_every == renumber_every - 1 {
            cut.renumber();
        }
        let t_renumber = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let stats: FrameStats = cut.adapt(h, &view, &policy, &Budget::default());
        let t_adapt = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        frame
            .draw_cut(&cut, h, &camera, &look)
            .map_err(|e| e.to_string())?;
        let t_render = start.elapsed().as_secs_f64() * 1e3;
        rows.push((stats, t_adapt, t_render, t_renumber));
        if i == picture {
            shot.draw_cut(&cut, h, &camera, &style(Shading::Gouraud, true))
                .map_err(|e| e.to_string())?;
        }
    }
    let first_adapt_ms = rows.first().map_or(0.0, |r| r.1);
    // Every frame after the first: its times and its triangles and operations.
    let mut frames = Vec::new();
    let (mut tris, mut ops) = (Vec::new(), Vec::new());
    for (i, (stats, t_adapt, t_render, t_renumber)) in (0..).zip(rows) {
        let camera = orbit.camera(i);
        let start = Instant::now();
        reference
            .draw(&full_mesh, &camera_params(&camera, Shading::Gouraud, false))
            .map_err(|e| e.to_string())?;
        let t_full = start.elapsed().as_secs_f64() * 1e3;
        if i > 0 {
            frames.push(FrameTimes {
                adapt: t_adapt,
                renumber: t_renumber,
                render: t_render,
                full: t_full,
            });
            tris.push(f64::from(stats.triangles));
            ops.push(f64::from(stats.vsplits + stats.ecols));
        }
        let _ = writeln!(
            csv,
            "{round},{},{renumber_every},{size},{i},{},{},{},{},{},{t_adapt:.3},{t_renumber:.3},{t_render:.3},{t_full:.3}",
            orbit.frames, stats.triangles, stats.vsplits, stats.ecols, stats.visited, stats.settled
        );
    }
    let of = |f: fn(&FrameTimes) -> f64| column(&frames, f);
    let renumber_ms = mean(frames.iter().map(|f| f.renumber));
    Ok(Row {
        size,
        triangles: mean(tris.into_iter()),
        ops: mean(ops.into_iter()),
        adapt_ms: median(of(|f| f.adapt)) + renumber_ms,
        renumber_ms,
        render_ms: median(of(|f| f.render)),
        full_ms: median(of(|f| f.full)),
        first_adapt_ms,
        frames,
    })
}

/// The part of a frame the sheet shows: the middle, where the model is.
const CROP: [usize; 2] = [320, 300];

/// The middle [`CROP`] of `frame`, captioned.
fn panel(frame: &Frame, caption: String) -> Panel {
    let [w, h] = CROP;
    let (x0, y0) = ((WIDTH - w) / 2, (HEIGHT - h) / 2);
    let pixels = (y0..y0 + h)
        .flat_map(|y| {
            frame.pixels()[y * WIDTH + x0..y * WIDTH + x0 + w]
                .iter()
                .copied()
        })
        .collect();
    Panel { caption, pixels }
}

/// Frustum sizes 0.4 and 0.2 of one flight (its first round), frame by frame: adaptation,
/// adaptation plus drawing, and drawing every triangle, in milliseconds, as a PNG.
fn chart_frames(rows: &[Vec<Row>], degrees: f64) -> Result<Vec<u8>, String> {
    let ink = (60, 60, 60);
    let heads = SIZES.map(|(size, _)| format!("frustum {size}, {degrees:.2} deg/frame, ms: "));
    let panel = |k: usize| {
        let frames = rows
            .get(k)
            .and_then(|r| r.first())
            .map_or(&[][..], |r| &r.frames);
        let series = |f: fn(&FrameTimes) -> f64| column(frames, f);
        chart::Panel {
            title: vec![
                (heads[k].as_str(), ink),
                ("adapt", ORANGE),
                (", adapt + render", BLUE),
                (", full detail", GREY),
            ],
            series: vec![
                (series(|f| f.full), GREY),
                (series(|f| f.adapt + f.renumber + f.render), BLUE),
                (series(|f| f.adapt + f.renumber), ORANGE),
            ],
        }
    };
    chart::panels(&[panel(0), panel(1)])
}

/// Runs the experiment on `input` into `out_dir` (`table1.csv`; for the first speed,
/// `frustum_S.png` per size and `full.png`, all of the same frame, and `table1.png`, their
/// middles side by side as in the paper's Fig. 2; `table1_ms.png`, the charted flight's frames'
/// times at sizes 0.4 and 0.2) and returns its summary lines.
pub fn table1(out_dir: &Path, input: IndexedMesh, setup: Setup) -> Result<Vec<String>, String> {
    let io = |e: std::io::Error| format!("{}: {e}", out_dir.display());
    std::fs::create_dir_all(out_dir).map_err(io)?;
    let model = Model::new(input, setup.loop_steps, true)?;
    let h = HierarchyView::parse(&model.bytes).map_err(|e| e.to_string())?;
    let bounds = model.mesh.bounds();
    // The calibration and the near distance depend on the circle, not on the speed.
    let circle = merge_tree_orbit(&bounds, 36, WIDTH, HEIGHT);
    let near = circle.distance;
    let cameras: Vec<Camera> = (0..circle.frames).map(|i| circle.camera(i)).collect();
    let c = calibrate(&model.mesh.positions, &cameras, near);
    let mut lines = vec![format!(
        "experiment=table1 triangles={} vertices={} build_s={:.2} hierarchy_bytes={} bytes_per_vertex={:.2} near_radii={:.1} calibration={c:.4} leaves_pct_0.2={:.1}",
        model.mesh.triangles.len(),
        model.mesh.positions.len(),
        model.build_seconds,
        model.bytes.len(),
        model.bytes.len() as f64 / model.mesh.positions.len().max(1) as f64,
        near / circle.radius,
        100.0 * share_in_view(&model.mesh.positions, &cameras, 0.2 * c, near),
    )];
    let mut csv = String::from(
        "round,frames,renumber_every,size,frame,triangles,vsplits,ecols,visited,settled,adapt_ms,renumber_ms,render_ms,full_ms\n",
    );
    let mut shot = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    let mut panels = Vec::new();
    let orbits: Vec<Orbit> = setup
        .flights
        .iter()
        .map(|&(frames, _)| merge_tree_orbit(&bounds, frames.max(2), WIDTH, HEIGHT))
        .collect();
    // Each flight's rows per frustum size, a row a round; the rounds go through every flight in
    // turn, so that a slow phase of the machine meets them alike.
    let mut rows = vec![vec![Vec::new(); SIZES.len()]; orbits.len()];
    for round in 0..setup.rounds.max(1) {
        for (run, (orbit, &(_, renumber_every))) in orbits.iter().zip(setup.flights).enumerate() {
            let pictures = round == 0 && run == 0;
            let picture = if pictures {
                (orbit.frames / 8).max(1)
            } else {
                u32::MAX
            };
            for (k, &(size, _)) in SIZES.iter().enumerate() {
                let flight = Flight {
                    orbit,
                    near,
                    c,
                    size,
                    renumber_every,
                };
                let row = fly(&model, &h, (&flight, round), picture, &mut shot, &mut csv)?;
                if pictures {
                    shot.save_png(&out_dir.join(format!("frustum_{size}.png")))
                        .map_err(|e| e.to_string())?;
                    panels.push(panel(&shot, format!("frustum {size}")));
                }
                rows[run][k].push(row);
            }
            if pictures {
                shot.draw(
                    &model.mesh.as_raster_mesh(),
                    &camera_params(&orbit.camera(picture), Shading::Gouraud, false),
                )
                .map_err(|e| e.to_string())?;
                shot.save_png(&out_dir.join("full.png"))
                    .map_err(|e| e.to_string())?;
                panels.push(panel(&shot, "full detail".into()));
                let png = sheet(&panels, panels.len(), CROP)?;
                std::fs::write(out_dir.join("table1.png"), png).map_err(io)?;
            }
        }
    }
    for ((orbit, &(_, renumber_every)), rows) in orbits.iter().zip(setup.flights).zip(&rows) {
        for (&(size, paper), rounds) in SIZES.iter().zip(rows) {
            let of = |f: fn(&Row) -> f64| median(rounds.iter().map(f).collect());
            let (speedup, share) = (of(Row::speedup), of(Row::adapt_share));
            let ranges = if rounds.len() > 1 {
                let range = |f: fn(&Row) -> f64, scale: f64, digits: usize| {
                    let v = rounds.iter().map(|r| scale * f(r));
                    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x), hi.max(x))
                    });
                    format!("{lo:.digits$}-{hi:.digits$}")
                };
                format!(
                    " rounds={} speedup_range={} adapt_share_range={}",
                    rounds.len(),
                    range(Row::speedup, 1.0, 2),
                    range(Row::adapt_share, 100.0, 0),
                )
            } else {
                String::new()
            };
            let triangles = of(|r| r.triangles);
            lines.push(format!(
                "experiment=table1 frames={} degrees_per_frame={:.2} renumber_every={renumber_every} frustum={size} kept_pct={:.1} triangles={triangles:.0} ops={:.0} adapt_ms={:.2} renumber_ms={:.3} render_ms={:.2} full_ms={:.2} speedup={speedup:.2} adapt_share_pct={:.0} first_adapt_ms={:.1} paper_speedup={paper}{ranges}",
                orbit.frames,
                360.0 / orbit.frames as f64,
                100.0 * triangles / model.mesh.triangles.len().max(1) as f64,
                of(|r| r.ops),
                of(|r| r.adapt_ms),
                of(|r| r.renumber_ms),
                of(|r| r.render_ms),
                of(|r| r.full_ms),
                100.0 * share,
                of(|r| r.first_adapt_ms),
            ));
        }
    }
    std::fs::write(out_dir.join("table1.csv"), csv).map_err(io)?;
    if let (Some(rows), Some(orbit)) = (rows.get(setup.charted), orbits.get(setup.charted)) {
        let png = chart_frames(rows, 360.0 / orbit.frames as f64)?;
        std::fs::write(out_dir.join("table1_ms.png"), png).map_err(io)?;
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{load_obj_bytes, COW_NAME, COW_OBJ};
    use crate::summary_value;

    fn cow() -> IndexedMesh {
        load_obj_bytes(COW_NAME, COW_OBJ).unwrap()
    }

    #[test]
    fn the_frustum_and_the_near_test_refine_to_every_leaf_they_hold() {
        let model = Model::new(cow(), 0, false).unwrap();
        let h = HierarchyView::parse(&model.bytes).unwrap();
        let orbit = merge_tree_orbit(&model.mesh.bounds(), 12, WIDTH, HEIGHT);
        let near = orbit.distance;
        let mut cut = BigCut::boxed();
        cut.reset(&h).unwrap();
        let policy = MergeTree { near };
        let mut inside_somewhere = 0;
        for i in 0..orbit.frames {
            let camera = orbit.camera(i);
            let view = modelled(&camera, 0.3);
            let stats = cut.adapt(&h, &view, &policy, &Budget::default());
            assert!(!stats.capacity_limited && !stats.queue_overflow);
            let active: std::collections::BTreeSet<u32> = cut.nodes().iter().copied().collect();
            // Every leaf whose own position is in the frustum and near is drawn as it is: its
            // ancestors' spheres hold it, so each of them was wanted and split.
            for leaf in h.leaf_nodes() {
                let (p, _, _) = h.vertex(leaf);
                let r = glam::Vec3::from(p) - camera.eye;
                if r.length() < near && view.sphere_visible(p, 0.0) {
                    inside_somewhere += 1;
                    assert!(active.contains(&leaf), "frame {i}: leaf {leaf} not refined");
                }
            }
            // And the rest simplifies: far fewer triangles than the model.
            assert!(
                stats.triangles < model.mesh.triangles.len() as u32 / 2,
                "{stats:?}"
            );
        }
        assert!(inside_somewhere > 100, "{inside_somewhere}");
    }

    #[test]
    fn the_calibration_puts_a_tenth_of_the_leaves_in_the_frustum() {
        let mesh = cow();
        let orbit = merge_tree_orbit(&mesh.bounds(), 8, WIDTH, HEIGHT);
        let cameras: Vec<Camera> = (0..8).map(|i| orbit.camera(i)).collect();
        let c = calibrate(&mesh.positions, &cameras, orbit.distance);
        let share = share_in_view(&mesh.positions, &cameras, 0.2 * c, orbit.distance);
        assert!((share - CALIBRATED_SHARE).abs() < 0.005, "{share}");
        // Twice the size holds more, half the size less.
        assert!(share_in_view(&mesh.positions, &cameras, 0.4 * c, orbit.distance) > 2.0 * share);
        assert!(share_in_view(&mesh.positions, &cameras, 0.1 * c, orbit.distance) < 0.5 * share);
    }

    #[test]
    fn smaller_frustums_keep_fewer_triangles() {
        let out = std::env::temp_dir().join(format!("vdlod_table1_{}", std::process::id()));
        let setup = Setup {
            loop_steps: 1,
            flights: &[(16, 4)],
            rounds: 2,
            charted: 0,
        };
        let lines = table1(&out, cow(), setup).unwrap();
        assert_eq!(lines.len(), 4);
        let leaves: f64 = summary_value(&lines[0], "leaves_pct_0.2").unwrap();
        assert!((leaves - 10.0).abs() <= 0.5, "{}", lines[0]);
        let kept: Vec<f64> = lines[1..]
            .iter()
            .map(|l| summary_value(l, "kept_pct").unwrap())
            .collect();
        assert!(kept[0] > kept[1] && kept[1] > kept[2], "{kept:?}");
        // The 0.2 frustum holds a tenth of the leaves; the coarse rest adds some.
        assert!((10.0..40.0).contains(&kept[1]), "{kept:?}");
        for l in &lines[1..] {
            assert!(summary_value::<f64>(l, "ops").unwrap() > 0.0, "{l}");
            assert!(summary_value::<f64>(l, "speedup").unwrap() > 0.0, "{l}");
        }
        for name in [
            "frustum_0.4.png",
            "frustum_0.2.png",
            "frustum_0.1.png",
            "full.png",
        ] {
            assert!(out.join(name).exists(), "{name}");
        }
        // The chart of the flight's frames: a picture of the chart's size.
        let (w, h, _) = crate::frame::load_png(&out.join("table1_ms.png")).unwrap();
        assert_eq!((w, h), (820, 470));
        let csv = std::fs::read_to_string(out.join("table1.csv")).unwrap();
        // Two rounds of three sizes, 16 frames each.
        assert_eq!(csv.lines().count(), 1 + 2 * 3 * 16);
        for l in &lines[1..] {
            assert_eq!(summary_value::<u32>(l, "rounds"), Some(2), "{l}");
            // The median of two rounds lies within their range.
            let speedup: f64 = summary_value(l, "speedup").unwrap();
            let range = l.split("speedup_range=").nth(1).unwrap();
            let (lo, hi) = range.split_once('-').unwrap();
            let hi = hi.split_whitespace().next().unwrap();
            let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
            assert!(lo <= speedup + 0.01 && speedup <= hi + 0.01, "{l}");
        }
        std::fs::remove_dir_all(&out).ok();
    }
}
