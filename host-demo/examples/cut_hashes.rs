//! Hashes of the cut along fixed flights, for a change meant to leave every cut as it was: run
//! it before and after and compare the lines.
//!
//! ```text
//! cargo run --release -p vdlod-demo --example cut_hashes -- [LOOP.vdh]
//! ```
//!
//! The bundled bunny's default hierarchy over the peer orbit at 0.25, 1 and 4 px: plain, with a
//! 4-frame geomorph, under a 2,000-triangle budget, and under a cap of 20 operations a frame;
//! with `LOOP.vdh` (the Loop-subdivided bunny's hierarchy, as `table1_adapt` writes it) also the
//! merge-tree paper's Table 1 flight at frustum 0.2. Each line is one flight's hashes after its
//! first frame and after frames 50, 200 and 400: FNV-1a over the active nodes, sorted, then the
//! triangles as node triples (each rotated to start at its smallest node), sorted. Slots do not
//! enter, so a change that only moves vertices or triangles between slots keeps the lines.

use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{MergeTree, Policy, QRefine, View};
use vdlod_demo::camera::{merge_tree_orbit, peer_orbit};
use vdlod_demo::hierarchy::build_with_progress;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::table1::calibrate;

/// The cut of `cargo bench --bench lod`.
type BunnyCut = Cut<16384, 32768, 2048>;
/// The cut `reproduce table1` uses.
type BigCut = Cut<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>;

/// Frames after which a flight's cut is hashed (0: the first frame).
const CHECKPOINTS: [usize; 4] = [0, 50, 200, 400];

/// FNV-1a, 64 bits, over 32-bit words.
fn fnv(words: impl IntoIterator<Item = u32>) -> u64 {
    words.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, w| {
        w.to_le_bytes()
            .iter()
            .fold(h, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
    })
}

/// The cut's hash: its nodes and its triangles, by node, in no slot's order.
fn hash<const V: usize, const F: usize, const Q: usize, I>(cut: &Cut<V, F, Q, I>) -> u64
where
    I: vdlod_core::cut::SlotIndex,
{
    let nodes = cut.nodes();
    let mut sorted = nodes.to_vec();
    sorted.sort_unstable();
    let mut triangles: Vec<[u32; 3]> = cut
        .triangles()
        .iter()
        .map(|t| {
            let n = t.map(|s| nodes[s.load() as usize]);
            let k = (0..3).min_by_key(|&k| n[k]).unwrap_or(0);
            [n[k], n[(k + 1) % 3], n[(k + 2) % 3]]
        })
        .collect();
    triangles.sort_unstable();
    fnv(sorted.into_iter().chain(triangles.into_iter().flatten()))
}

/// Flies `views` from a reset cut and prints `name` and the hashes at [`CHECKPOINTS`].
fn fly<const V: usize, const F: usize, const Q: usize, I, P>(
    name: &str,
    cut: &mut Cut<V, F, Q, I>,
    (h, views, policy, budget): (&HierarchyView<'_>, &[View], &P, &Budget),
) -> Result<(), String>
where
    I: vdlod_core::cut::SlotIndex,
    P: Policy,
{
    cut.reset(h).map_err(|e| e.to_string())?;
    let mut line = name.to_string();
    for (i, view) in views.iter().enumerate() {
        cut.adapt(h, view, policy, budget);
        if CHECKPOINTS.contains(&i) {
            line.push_str(&format!(" {i}:{:016x}", hash(cut)));
        }
    }
    println!("{line}");
    Ok(())
}

fn main() -> Result<(), String> {
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?;
    let (_, bytes, _) =
        build_with_progress(&mesh, &Default::default(), false).map_err(|e| e.to_string())?;
    let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
    let last = *CHECKPOINTS.last().unwrap_or(&0);
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    let views: Vec<View> = (0..=last as u32).map(|i| orbit.camera(i).view()).collect();
    let mut cut = BunnyCut::boxed();
    let budgets = [
        ("plain", Budget::default(), 0),
        ("geomorph4", Budget::default(), 4),
        (
            "budget2000",
            Budget {
                max_triangles: 2000,
                ..Budget::default()
            },
            0,
        ),
        (
            "ops20",
            Budget {
                max_ops: 20,
                ..Budget::default()
            },
            0,
        ),
    ];
    for tolerance in [0.25, 1.0, 4.0] {
        let policy = QRefine::new(tolerance);
        for (name, budget, frames) in &budgets {
            cut.set_geomorph_frames(*frames);
            let name = format!("bunny tol={tolerance} {name}");
            fly(&name, &mut cut, (&h, &views, &policy, budget))?;
        }
    }
    if let Some(path) = std::env::args().nth(1) {
        let bytes = std::fs::read(&path).map_err(|e| format!("{path}: {e}"))?;
        let h = HierarchyView::parse(&bytes).map_err(|e| e.to_string())?;
        let loop_mesh = mesh.loop_subdivide();
        let bounds = loop_mesh.bounds();
        let circle = merge_tree_orbit(&bounds, 36, 640, 480);
        let near = circle.distance;
        let cameras: Vec<_> = (0..circle.frames).map(|i| circle.camera(i)).collect();
        let c = calibrate(&loop_mesh.positions, &cameras, near);
        let orbit = merge_tree_orbit(&bounds, 400, 640, 480);
        let views: Vec<View> = (0..=last as u32)
            .map(|i| orbit.camera(i).view_scaled(c * 0.2))
            .collect();
        let mut cut = BigCut::boxed();
        fly(
            "table1 frustum=0.2",
            &mut cut,
            (&h, &views, &MergeTree { near }, &Budget::default()),
        )?;
    }
    Ok(())
}
