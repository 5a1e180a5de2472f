//! First frames: the bunny's cut refined from its base mesh for 20 views of the peer orbit, as
//! `cargo bench --bench lod` refines its first frame, and the time per split.
//!
//! ```text
//! cargo run --release -p vdlod-demo --example first_frames -- [TOLERANCE [EVICT_MB]]
//! ```
//!
//! Tolerance in pixels (1); `QRefine`, no budget, no geomorphs. The 20 views are refined twice
//! and the second pass timed. With `EVICT_MB`, that many megabytes are written and read before
//! each view, untimed, so that each first frame starts from cold caches, as the bench's does
//! after the peer has run. For instruction counts: `valgrind --tool=callgrind
//! --toggle-collect='first_frames::refine' target/release/examples/first_frames 1`, divided
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
fn refine(cut: &mut BunnyCut, h: &HierarchyView<'_>, view: &View, policy: &QRefine) -> u64 {
    if cut.reset(h).is_err() {
        return 0;
    }
    u64::from(cut.adapt(h, view, policy, &Budget::default()).vsplits)
}

/// Refines each view from the base mesh after sweeping `sweep` through the caches; the splits
/// done and the time they took (the sweeps left out).
fn refine_all(
    cut: &mut BunnyCut,
    h: &HierarchyView<'_>,
    views: &[View],
    policy: &QRefine,
    sweep: &mut [u8],
) -> (u64, f64) {
    let (mut splits, mut seconds) = (0, 0.0);
    for (i, view) in views.iter().enumerate() {
        vdlod_demo::sweep_caches(sweep, i as u8);
        let start = Instant::now();
        splits += refine(cut, h, view, policy);
        seconds += start.elapsed().as_secs_f64();
    }
    (splits, seconds)
}

fn main() -> Result<(), String> {
    let number = |k: usize, default: f32| -> Result<f32, String> {
        std::env::args().nth(k).map_or(Ok(default), |s| {
            s.parse().map_err(|_| format!("not a number: {s}"))
        })
    };
    let tolerance = number(1, 1.0)?;
    let mut sweep = vec![0u8; (number(2, 0.0)? * 1e6) as usize];
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?;
    let (_, bytes, _) =
        build_with_progress(&mesh, &Default::default(), false).map_err(|e| e.to_string())?;
    let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    let views: Vec<View> = (0..20).map(|i| orbit.camera(i * 10).view()).collect();
    let policy = QRefine::new(tolerance);
    let mut cut = BunnyCut::boxed();
    refine_all(&mut cut, &h, &views, &policy, &mut sweep);
    let (splits, seconds) = refine_all(&mut cut, &h, &views, &policy, &mut sweep);
    let us = seconds * 1e6;
    println!(
        "tolerance={tolerance} views={} splits_per_view={} us_per_view={:.0} ns_per_split={:.0}",
        views.len(),
        splits / views.len() as u64,
        us / views.len() as f64,
        1e3 * us / splits.max(1) as f64
    );
    Ok(())
}
