//! Drawing a Table 1 cut (`vdlod-demo reproduce table1`): the cut of the 0.9 degrees a frame
//! flight at frame `AT`, drawn at 640x480 as it is and after `Cut::renumber`, beside all
//! 301,632 triangles from the same camera; median milliseconds of 41 draws each.
//!
//! ```text
//! cargo run --release -p vdlod-demo --example cut_draw -- [SIZE [AT [FILE.vdh]]]
//! ```
//!
//! Each is drawn at 64x48 from the same camera too: a hundredth of the pixels, the same vertex
//! stage and triangle setup, so the difference between the two sizes is what the pixels cost.
//!
//! Frustum size `SIZE` (0.4), frame `AT` (200). With `FILE.vdh` the hierarchy of the
//! Loop-subdivided bunny is read from there, or written there when the file does not exist.
//! For instruction counts: `valgrind --tool=callgrind --toggle-collect='cut_draw::draw'` (the cut's
//! draws; `cut_draw::draw_full` for full detail's).

use std::time::Instant;

use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::MergeTree;
use vdlod_demo::camera::{merge_tree_orbit, Camera};
use vdlod_demo::frame::Frame;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::{camera_params, style};
use vdlod_demo::table1::{calibrate, Model};
use vdlod_raster::Shading;

/// The cut `reproduce table1` uses.
type BigCut = Cut<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>;

/// Draws `cut` once.
#[inline(never)]
fn draw(frame: &mut Frame, cut: &BigCut, h: &HierarchyView<'_>, camera: &Camera) {
    let look = style(Shading::Gouraud, false);
    frame
        .draw_cut(cut, h, camera, &look)
        .expect("a valid camera");
}

/// Draws every triangle of the model once.
#[inline(never)]
fn draw_full(frame: &mut Frame, mesh: &vdlod_raster::Mesh<'_>, params: &vdlod_raster::DrawParams) {
    frame.draw(mesh, params).expect("a valid camera");
}

/// Median milliseconds of 41 runs of `f`.
fn median_ms(mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..41)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[20]
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize, default: f32| -> Result<f32, String> {
        args.get(k).map_or(Ok(default), |s| {
            s.parse().map_err(|_| format!("not a number: {s}"))
        })
    };
    let size = number(0, 0.4)?;
    let at = number(1, 200.0)? as u32;
    let bunny = || load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string());
    let model = match args.get(2).map(std::fs::read) {
        Some(Ok(bytes)) => {
            let mut mesh = bunny()?.loop_subdivide();
            mesh.reorder_for_locality();
            Model {
                mesh,
                bytes,
                build_seconds: 0.0,
            }
        }
        _ => {
            let model = Model::new(bunny()?, 1, false)?;
            if let Some(path) = args.get(2) {
                std::fs::write(path, &model.bytes).map_err(|e| format!("{path}: {e}"))?;
            }
            model
        }
    };
    let h = HierarchyView::parse(&model.bytes).map_err(|e| e.to_string())?;
    let bounds = model.mesh.bounds();
    // The calibration and the near distance, as `reproduce table1` finds them.
    let circle = merge_tree_orbit(&bounds, 36, 640, 480);
    let near = circle.distance;
    let cameras: Vec<_> = (0..circle.frames).map(|i| circle.camera(i)).collect();
    let c = calibrate(&model.mesh.positions, &cameras, near);
    let orbit = merge_tree_orbit(&bounds, 400, 640, 480);
    let policy = MergeTree { near };
    let mut cut = BigCut::boxed();
    cut.reset(&h).map_err(|e| e.to_string())?;
    for i in 0..=at {
        let view = orbit.camera(i).view_scaled(c * size);
        cut.adapt(&h, &view, &policy, &Budget::default());
    }
    // Each draw twice: at 640x480, and at 64x48 from the same camera (the same field of view,
    // a hundredth of the pixels), where what is left is the vertex stage and each triangle's
    // setup; the difference is what the pixels cost.
    let camera = orbit.camera(at);
    let small_camera = merge_tree_orbit(&bounds, 400, 64, 48).camera(at);
    let mut frame = Frame::new(640, 480).map_err(|e| e.to_string())?;
    let mut small = Frame::new(64, 48).map_err(|e| e.to_string())?;
    let as_is = median_ms(|| draw(&mut frame, &cut, &h, &camera));
    let as_is_small = median_ms(|| draw(&mut small, &cut, &h, &small_camera));
    let start = Instant::now();
    cut.renumber();
    let renumber_ms = start.elapsed().as_secs_f64() * 1e3;
    let renumbered = median_ms(|| draw(&mut frame, &cut, &h, &camera));
    let renumbered_small = median_ms(|| draw(&mut small, &cut, &h, &small_camera));
    let mesh = model.mesh.as_raster_mesh();
    let params = camera_params(&camera, Shading::Gouraud, false);
    let full = median_ms(|| draw_full(&mut frame, &mesh, &params));
    let small_params = camera_params(&small_camera, Shading::Gouraud, false);
    let full_small = median_ms(|| draw_full(&mut small, &mesh, &small_params));
    println!(
        "frustum={size} frame={at} triangles={} vertices={} cut_ms={as_is:.3} renumbered_ms={renumbered:.3} full_ms={full:.3} renumber_ms={renumber_ms:.2} at_64x48: cut_ms={as_is_small:.3} renumbered_ms={renumbered_small:.3} full_ms={full_small:.3}",
        cut.triangles().len(),
        cut.vertex_count()
    );
    Ok(())
}
