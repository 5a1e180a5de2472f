//! The peer orbit's adaptation alone, with settled vertices skipped and asked: the median, mean,
//! 90th percentile and slowest frame of each, so that frames of uneven cost are seen as they
//! are (a median alone hides a slow frame in five).
//!
//! ```text
//! cargo run --release -p vdlod-demo --example orbit_adapt -- \
//!     [TOLERANCE [GEOMORPH [ROUNDS [on|off]]]]
//! ```
//!
//! Tolerance in pixels (1), geomorph frames (0), rounds of two revolutions of 200 frames (3),
//! each round flying settling on then off (or only one of them); the bundled bunny, its default
//! hierarchy, `QRefine`, no budget, as `cargo bench --bench lod` flies it. The first frame of
//! each revolution (refined from the base mesh or a jump) is left out.
//!
//! For instruction counts: `valgrind --tool=callgrind --toggle-collect='orbit_adapt::adapt'
//! target/release/examples/orbit_adapt 1 0 1 on`, divided by the 400 frames (the two first
//! frames included, a few tenths of a percent at 1 px).

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

/// One frame's adaptation, a function of its own so that a profiler can count it alone.
#[inline(never)]
fn adapt(cut: &mut BunnyCut, h: &HierarchyView<'_>, view: &View, policy: &QRefine) {
    cut.adapt(h, view, policy, &Budget::default());
}
const FRAMES: u32 = 200;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize, default: f32| -> Result<f32, String> {
        args.get(k).map_or(Ok(default), |s| {
            s.parse().map_err(|_| format!("not a number: {s}"))
        })
    };
    let tolerance = number(0, 1.0)?;
    let geomorph = number(1, 0.0)? as u16;
    let rounds = number(2, 3.0)? as u32;
    let only = args.get(3).map(|s| s == "on");
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?;
    let (_, bytes, _) =
        build_with_progress(&mesh, &Default::default(), false).map_err(|e| e.to_string())?;
    let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
    let orbit = peer_orbit(&mesh.bounds(), FRAMES, 640, 480);
    let policy = QRefine::new(tolerance);
    let mut times = [Vec::new(), Vec::new()];
    for _ in 0..rounds {
        for (k, settling) in [true, false].into_iter().enumerate() {
            if only.is_some_and(|o| o != settling) {
                continue;
            }
            let mut cut = BunnyCut::boxed();
            cut.reset(&h).map_err(|e| e.to_string())?;
            cut.set_geomorph_frames(geomorph);
            cut.set_settling(settling);
            for i in 0..2 * FRAMES {
                let view = orbit.camera(i).view();
                let start = Instant::now();
                adapt(&mut cut, &h, &view, &policy);
                let us = start.elapsed().as_secs_f64() * 1e6;
                if i % FRAMES != 0 {
                    times[k].push(us);
                }
            }
        }
    }
    for (name, us) in ["settling on", "settling off"].iter().zip(&mut times) {
        if us.is_empty() {
            continue;
        }
        let mean = us.iter().sum::<f64>() / us.len() as f64;
        us.sort_by(f64::total_cmp);
        println!(
            "{name}: median {:.1} us, mean {mean:.1} us, 90th percentile {:.1} us, slowest {:.1} us ({} frames)",
            us[us.len() / 2],
            us[us.len() * 9 / 10],
            us[us.len() - 1],
            us.len()
        );
    }
    Ok(())
}
