//! One flight of the merge-tree paper's Table 1 (`vdlod-demo reproduce table1`), adapting only:
//! no drawing, so that a profiler sees the cut alone. Prints the mean visited and settled
//! vertices and operations per frame, and the mean adaptation time, over `COUNT` frames after
//! the first.
//!
//! ```text
//! cargo run --release -p vdlod-demo --example table1_adapt -- [FRAMES [SIZE [COUNT [FILE.vdh [EVICT_MB]]]]]
//! ```
//!
//! `FRAMES` frames per revolution (400: 0.9 degrees a frame), frustum size `SIZE` (0.2), `COUNT`
//! frames timed (100). The hierarchy of the Loop-subdivided bunny takes a few seconds to build;
//! with `FILE.vdh` it is read from there, or written there when the file does not exist. With
//! `EVICT_MB`, that many megabytes are written and read between frames, untimed, as a frame's
//! drawing would evict the cut from the caches (16 stands for `reproduce table1`'s draw). For
//! instruction counts, run it twice under callgrind with `--toggle-collect='*Cut*>::adapt'`,
//! with `COUNT` and with 0, and divide the difference by `COUNT`.

use std::time::Instant;

use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::MergeTree;
use vdlod_demo::camera::merge_tree_orbit;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::table1::{calibrate, Model};

/// The cut `reproduce table1` uses.
type BigCut = Cut<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize, default: f32| -> Result<f32, String> {
        args.get(k).map_or(Ok(default), |s| {
            s.parse().map_err(|_| format!("not a number: {s}"))
        })
    };
    let frames = number(0, 400.0)? as u32;
    let size = number(1, 0.2)?;
    let count = number(2, 100.0)? as u32;
    let file = args.get(3);
    let evict = number(4, 0.0)?;
    let mut sweep = vec![0u8; (evict * 1e6) as usize];
    let bunny = || load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string());
    let mesh = bunny()?.loop_subdivide();
    let bytes = match file.map(std::fs::read) {
        Some(Ok(bytes)) => bytes,
        _ => {
            let model = Model::new(bunny()?, 1, false)?;
            if let Some(path) = file {
                std::fs::write(path, &model.bytes).map_err(|e| format!("{path}: {e}"))?;
            }
            model.bytes
        }
    };
    let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
    let bounds = mesh.bounds();
    // The calibration and the near distance, as `reproduce table1` finds them.
    let circle = merge_tree_orbit(&bounds, 36, 640, 480);
    let near = circle.distance;
    let cameras: Vec<_> = (0..circle.frames).map(|i| circle.camera(i)).collect();
    let c = calibrate(&mesh.positions, &cameras, near);
    let orbit = merge_tree_orbit(&bounds, frames.max(2), 640, 480);
    let views: Vec<_> = (0..=count)
        .map(|i| orbit.camera(i).view_scaled(c * size))
        .collect();
    let policy = MergeTree { near };
    let mut cut = BigCut::boxed();
    cut.reset(&h).map_err(|e| e.to_string())?;
    cut.adapt(&h, &views[0], &policy, &Budget::default());
    let (mut visited, mut settled, mut ops) = (0u64, 0u64, 0u64);
    let mut adapting = std::time::Duration::ZERO;
    for (i, view) in views[1..].iter().enumerate() {
        vdlod_demo::sweep_caches(&mut sweep, i as u8);
        let start = Instant::now();
        let s = cut.adapt(&h, view, &policy, &Budget::default());
        adapting += start.elapsed();
        visited += u64::from(s.visited);
        settled += u64::from(s.settled);
        ops += u64::from(s.vsplits + s.ecols);
    }
    let n = u64::from(count.max(1));
    println!(
        "frames={frames} frustum={size} count={count} evict_mb={evict} visited={} settled={} ops={} adapt_ms={:.3}",
        visited / n,
        settled / n,
        ops / n,
        adapting.as_secs_f64() * 1e3 / n as f64
    );
    Ok(())
}
