//! First frames: the bunny's cut refined from its base mesh for 20 views of the peer orbit, as
//! `cargo bench --bench lod` refines its first frame, and the time per split.
//!
//! ```text
//! cargo run --release -p vdlod-demo --example first_frames -- [TOLERANCE]
//! ```
//!
//! Tolerance in pixels (1); `QRefine`, no budget, no geomorphs. The 20 views are refined twice
//! and the second pass timed. For instruction counts: `valgrind --tool=callgrind
//! --toggle-collect='first_frames::refine_all' target/release/examples/first_frames 1`, divided
//! by 40 times `splits_per_view` (two passes over the 20 views).

use std::time::Instant;

use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{QRefine, View};
use vdlod_demo::camera::peer_orbit;
use vdlod_demo::hierarchy::build_with_progress;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};

/// The cut of `cargo bench --bench lod`.
type BunnyCut = Cut<16384, 32768, 2048>;

/// Refines each view from the base mesh; the splits done.
#[inline(never)]
fn refine_all(cut: &mut BunnyCut, h: &HierarchyView<'_>, views: &[View], policy: &QRefine) -> u64 {
    let mut splits = 0;
    for view in views {
        if cut.reset(h).is_err() {
            return splits;
        }
        splits += u64::from(cut.adapt(h, view, policy, &Budget::default()).vsplits);
    }
    splits
}

fn main() -> Result<(), String> {
    let tolerance: f32 = match std::env::args().nth(1) {
        Some(s) => s.parse().map_err(|_| format!("not a number: {s}"))?,
        None => 1.0,
    };
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?;
    let (_, bytes, _) =
        build_with_progress(&mesh, &Default::default(), false).map_err(|e| e.to_string())?;
    let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    let views: Vec<View> = (0..20).map(|i| orbit.camera(i * 10).view()).collect();
    let policy = QRefine::new(tolerance);
    let mut cut = BunnyCut::boxed();
    refine_all(&mut cut, &h, &views, &policy);
    let start = Instant::now();
    let splits = refine_all(&mut cut, &h, &views, &policy);
    let us = start.elapsed().as_secs_f64() * 1e6;
    println!(
        "tolerance={tolerance} views={} splits_per_view={} us_per_view={:.0} ns_per_split={:.0}",
        views.len(),
        splits / views.len() as u64,
        us / views.len() as f64,
        1e3 * us / splits.max(1) as f64
    );
    Ok(())
}
