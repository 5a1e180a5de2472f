//! The runtime cut, measured beside its peers in the same run.
//!
//! 1. **Adaptation** on the bunny over the peer orbit of `../shared/peers/README.md` (640x480,
//!    60 degree vertical field of view, eye at `R / sin 30deg`, 20 degrees up, 200 frames per
//!    revolution), tolerances 0.25/0.5/1/2/4 px, policy [`QRefine`] (frustum, back-face, screen
//!    error: the test OpenMesh's VDPM and Hoppe's SrMesh use), no geomorphs, no budget. The first
//!    frame (from the base mesh) is reported alone; the others give the median microseconds,
//!    mean triangles and operations per frame. Ours runs before and after OpenMesh's VDPM
//!    (`om_vdpm` from `../shared/peers/run.sh`, when built; `VDLOD_PEERS` names its directory,
//!    default `$TMPDIR/vdlod-peers`), and the ratio compares our median of both runs with its
//!    median, at equal tolerance and at the nearest triangle count.
//! 2. (The merge-tree paper's Table 1, adapted vs full detail on the Loop-subdivided bunny, is
//!    `vdlod-demo reproduce table1`.)
//! 3. **Image quality at equal triangles**: PSNR against the full-detail frame of the adapted
//!    frame and of the bunny simplified uniformly by meshoptimizer (`meshopt` 0.7) to the same
//!    triangle count, over 20 frames of the peer orbit.
//! 4. **Memory**: the cut's bytes for the capacities used.
//! 5. **Policies**: the importance paper's per-triangle test ([`Importance`] at its default
//!    threshold) against [`QRefine`] at 0.3 px (about as many triangles) over the same orbit,
//!    interleaved (QRefine, importance, QRefine): median microseconds, mean triangles, and the
//!    time per triangle as a ratio.
//!
//! 6. **Hoppe's SrMesh** (`srmesh_orbit` from `../shared/peers/hoppe/run.sh`, when built), the
//!    same orbit and policy: ours and SrMesh's runs over a finer tolerance grid in turn, in
//!    rounds (`VDLOD_ROUNDS`, 3), and the speed-up at equal triangle counts (SrMesh's time
//!    interpolated log-log at ours), steady frames and the first frame (each side in fresh
//!    processes, and warm: in a new cut and after a reset, against SrMesh's driver warmed up),
//!    as the median over rounds and its range. SrMesh is compiled for the processor
//!    it runs on (`-march=native`); a line says what this bench was compiled for, and
//!    `RUSTFLAGS="-C target-cpu=native"` compiles ours alike.
//!
//! 7. **Settled vertices** skipped or asked (`Cut::set_settling`), without and with geomorphs.
//!
//! 8. **The wavelet engine's coherence**: the cut as it is against one that asks settled
//!    wavelets (`WaveletCut::set_settling`) and one that emits the whole mesh in every frame
//!    that changes (`WaveletCut::set_partial_emission`), over the wavelet paper's session on the
//!    subdivided cow (`reproduce fig9`'s, at 90 and at 720 frames, 0.5 / 3.5 px, without and
//!    with geomorphs), interleaved frame by frame, and a frame whose view has not moved.
//!
//! 9. **Amortized traversal** ([`Budget::max_visits`], the LOD lecture's "distribute traversing
//!    the tree over frames"): the bunny over the peer orbit at 0.5 / 1 / 2 px with all the
//!    active vertices asked each frame, then a half, a quarter and an eighth of them (of the
//!    full pass's mean count): median microseconds, vertices asked, triangles, and what the lag
//!    costs, as the PSNR of each frame against the full pass's frame from the same camera.
//!
//! Run: `../shared/peers/run.sh` and `../shared/peers/hoppe/run.sh` once (they build the peers),
//! then `cargo bench --bench lod` (`-- adaptation`, `-- quality`, `-- policies`,
//! `-- srmesh`, `-- settling`, `-- wavelets` or `-- amortized` for one section).

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use meshopt::{SimplifyOptions, VertexDataAdapter};
use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{Frustum, Importance, Policy, QRefine, ScreenError};
use vdlod_demo::camera::peer_orbit;
use vdlod_demo::frame::Frame;
use vdlod_demo::hierarchy::build_with_progress;
use vdlod_demo::lod::psnr;
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::{camera_params, style};
use vdlod_demo::stats::median;
use vdlod_raster::Shading;

/// The cut of the adaptation benchmark: room for the bunny at 0.25 px with margin.
type BunnyCut = Cut<16384, 32768, 2048>;
/// A cut that holds the Loop-subdivided bunny at full detail (section 4's figure).
type BigCut = Cut<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>;

const TOLERANCES: [f32; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];
const FRAMES: u32 = 200;
const W: usize = 640;
const H: usize = 480;

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// One tolerance's figures.
#[derive(Clone, Debug, Default)]
struct Adapt {
    first_us: f64,
    first_tris: u32,
    /// The first frame again after the revolutions, from a reset of the same cut.
    reset_us: f64,
    reset_tris: u32,
    us: Vec<f64>,
    tris: Vec<f64>,
    ops: Vec<f64>,
    /// Share of the active vertices skipped as settled.
    settled: Vec<f64>,
}

fn adapt_orbit(
    h: &HierarchyView<'_>,
    mesh: &IndexedMesh,
    tolerance: f32,
    revolutions: u32,
) -> Adapt {
    adapt_orbit_with(h, mesh, &QRefine::new(tolerance), revolutions)
}

fn adapt_orbit_with(
    h: &HierarchyView<'_>,
    mesh: &IndexedMesh,
    policy: &impl Policy,
    revolutions: u32,
) -> Adapt {
    adapt_orbit_set(h, mesh, policy, revolutions, 0, true, &[])
}

/// What SrMesh's driver reads and writes between two of its timed frames, to count the
/// operations of the last: its face array (8 bytes a face, 75,412 on the bunny, every line of
/// it read) and two vectors of a byte a split (37,702), about 680 KB. The bench reads as much
/// between ours in the SrMesh section, so that both meet the same caches (in the bench's
/// other sections ours run back to back).
const DRIVER_BETWEEN: usize = 680 * 1024;

/// Reads every cache line of `bytes` (untimed, between frames).
fn read_through(bytes: &[u8]) {
    std::hint::black_box(bytes.iter().step_by(64).fold(0u8, |a, &b| a ^ b));
}

/// [`adapt_orbit_with`] with geomorphs over `geomorph` frames and settled vertices skipped or not.
fn adapt_orbit_set(
    h: &HierarchyView<'_>,
    mesh: &IndexedMesh,
    policy: &impl Policy,
    revolutions: u32,
    geomorph: u16,
    settling: bool,
    between: &[u8],
) -> Adapt {
    let orbit = peer_orbit(&mesh.bounds(), FRAMES, W, H);
    let mut cut = BunnyCut::boxed();
    cut.reset(h).expect("base mesh fits");
    cut.set_geomorph_frames(geomorph);
    cut.set_settling(settling);
    let mut out = Adapt::default();
    for i in 0..FRAMES * revolutions {
        let view = orbit.camera(i).view();
        read_through(between);
        let start = Instant::now();
        let s = cut.adapt(h, &view, policy, &Budget::default());
        let us = start.elapsed().as_secs_f64() * 1e6;
        if i == 0 {
            out.first_us = us;
            out.first_tris = s.triangles;
        } else if i % FRAMES != 0 {
            out.us.push(us);
            out.tris.push(s.triangles as f64);
            out.ops.push((s.vsplits + s.ecols) as f64);
            out.settled
                .push(s.settled as f64 / s.vertices.max(1) as f64);
        }
    }
    cut.reset(h).expect("base mesh fits");
    let view = orbit.camera(0).view();
    read_through(between);
    let start = Instant::now();
    let s = cut.adapt(h, &view, policy, &Budget::default());
    out.reset_us = start.elapsed().as_secs_f64() * 1e6;
    out.reset_tris = s.triangles;
    out
}

/// [`every_tolerance`], the file loaded anew for each tolerance (`HierarchyView::parse`, which
/// reads every byte to validate it), as SrMesh's driver loads its own before each: the first
/// frame then meets the file as an application's first frame after loading it would. Before
/// each frame, `between` is read through, as the driver reads its bookkeeping between its own.
fn every_tolerance_loaded(bytes: &[u8], mesh: &IndexedMesh, between: &[u8]) -> Vec<Adapt> {
    TOLERANCES
        .iter()
        .map(|&t| {
            let h = HierarchyView::parse(bytes).expect("valid");
            adapt_orbit_set(&h, mesh, &QRefine::new(t), 2, 0, true, between)
        })
        .collect()
}

/// Two revolutions of the peer orbit at each of [`TOLERANCES`].
fn every_tolerance(h: &HierarchyView<'_>, mesh: &IndexedMesh) -> Vec<Adapt> {
    TOLERANCES
        .iter()
        .map(|&t| adapt_orbit(h, mesh, t, 2))
        .collect()
}

/// The median microseconds, mean triangles and mean operations of two runs together.
fn both(a: &Adapt, b: &Adapt) -> (f64, f64, f64) {
    (
        median(a.us.iter().chain(&b.us).copied().collect()),
        mean(&[a.tris.clone(), b.tris.clone()].concat()),
        mean(&[a.ops.clone(), b.ops.clone()].concat()),
    )
}

/// One tolerance of OpenMesh's VDPM: tolerance, median us, mean triangles, operations per frame.
type Peer = (f32, f64, f64, f64);

/// The `vdpm_adapt` lines of `om_vdpm`, by tolerance.
fn run_vdpm() -> Vec<Peer> {
    let dir = std::env::var_os("VDLOD_PEERS")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("vdlod-peers"));
    let (bin, off) = (dir.join("bin/om_vdpm"), dir.join("bunny00.off"));
    if !bin.exists() || !off.exists() {
        println!(
            "(OpenMesh VDPM not built in {}: run ../shared/peers/run.sh for the peer column)",
            dir.display()
        );
        return Vec::new();
    }
    let mut cmd = Command::new(bin);
    cmd.arg(&off)
        .arg(dir.join("vdpm"))
        .arg(FRAMES.to_string())
        .arg("1");
    cmd.args(TOLERANCES.map(|t| t.to_string()));
    let Ok(out) = cmd.output() else {
        return Vec::new();
    };
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.starts_with("vdpm_adapt"))
        .filter_map(|l| {
            let get = |k: &str| field(l, k);
            let ops = get("vsplits_per_frame")? + get("ecols_per_frame")?;
            Some((
                get("tol_px")? as f32,
                get("median_us")?,
                get("tris_mean")?,
                ops,
            ))
        })
        .collect()
}

fn adaptation(h: &HierarchyView<'_>, mesh: &IndexedMesh) {
    println!("\n## 1. Adaptation per frame, bunny, peer orbit (640x480, 60 deg, 200 frames)\n");
    let before = every_tolerance(h, mesh);
    let peer = run_vdpm();
    let after = every_tolerance(h, mesh);
    println!(
        "| tol px | first frame | median us | mean tris | ns/active vertex | ops/frame | VDPM median us | VDPM tris | VDPM ops/frame | speed-up, same tol | VDPM at nearest tris | speed-up, nearest tris |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (k, &t) in TOLERANCES.iter().enumerate() {
        let (a, b) = (&before[k], &after[k]);
        let (us, tris, ops) = both(a, b);
        let per_vertex = us * 1e3 / (tris / 2.0);
        let same = peer.iter().find(|p| (p.0 - t).abs() < 1e-3);
        let nearest = peer
            .iter()
            .min_by(|x, y| (x.2 - tris).abs().total_cmp(&(y.2 - tris).abs()));
        let cell = |p: Option<&Peer>, f: &dyn Fn(&Peer) -> String| p.map_or("-".to_string(), f);
        println!(
            "| {t} | {:.0} us, {} tris | {us:.1} | {tris:.0} | {per_vertex:.1} | {ops:.1} | {} | {} | {} | {} | {} | {} |",
            a.first_us,
            a.first_tris,
            cell(same, &|p| format!("{:.0}", p.1)),
            cell(same, &|p| format!("{:.0}", p.2)),
            cell(same, &|p| format!("{:.1}", p.3)),
            cell(same, &|p| format!("{:.1}x", p.1 / us)),
            cell(nearest, &|p| format!("{:.0} us at {:.0} tris ({} px)", p.1, p.2, p.0)),
            cell(nearest, &|p| format!("{:.1}x", p.1 / us)),
        );
    }
    println!(
        "\nOur runs before / after the peer (median us): {}",
        TOLERANCES
            .iter()
            .enumerate()
            .map(|(k, t)| format!(
                "{t} px {:.1} / {:.1}",
                median(before[k].us.clone()),
                median(after[k].us.clone())
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
}

/// One tolerance of Hoppe's SrMesh: tolerance, median us, mean triangles, operations per frame,
/// first-frame us and triangles.
#[derive(Clone, Copy, Debug)]
struct SrPeer {
    tol: f64,
    us: f64,
    tris: f64,
    ops: f64,
    first_us: f64,
    first_tris: f64,
}

/// SrMesh's first frames with its code and heap warm, as ours run in this process: one driver
/// process flies [`SR_TOLERANCES`] after a warm-up tolerance, with glibc told never to return
/// freed memory (`GLIBC_TUNABLES` thresholds), so each tolerance's new mesh grows into pages
/// the one before touched. Run alone per tolerance ([`run_srmesh`]), the driver's first frame
/// also pays for its code's first run and for faulting in every page its active mesh grows
/// into (about 2.5 us a page on the machine of 2026-12-07), which our cut in this process
/// never does: there it took 2-3 times as long. `(first-frame triangles, us)` by tolerance.
fn run_srmesh_warm() -> Vec<(f64, f64)> {
    let Some((bin, srm, off)) = srmesh_files() else {
        return Vec::new();
    };
    let taus: Vec<String> = std::iter::once(SR_TOLERANCES[0])
        .chain(SR_TOLERANCES)
        .map(|t| t.to_string())
        .collect();
    let never = "1073741824";
    let Ok(out) = Command::new(&bin)
        .arg(&srm)
        .arg(&off)
        .args(["--tau", &taus.join(","), "--revs", "1"])
        .env(
            "GLIBC_TUNABLES",
            format!("glibc.malloc.mmap_threshold={never}:glibc.malloc.trim_threshold={never}"),
        )
        .output()
    else {
        return Vec::new();
    };
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.starts_with("srmesh_adapt"))
        .skip(1)
        .filter_map(|l| {
            let get = |k: &str| field(l, k);
            Some((get("first_faces")?, get("first_us")?))
        })
        .collect()
}

/// The driver, the `.srm` and the mesh of `../shared/peers/hoppe/` (`VDLOD_SRMESH` names its
/// work folder, default `$TMPDIR/hoppe-srmesh`), when built.
fn srmesh_files() -> Option<(PathBuf, PathBuf, PathBuf)> {
    let dir = std::env::var_os("VDLOD_SRMESH")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("hoppe-srmesh"));
    let files = (
        dir.join("build/bin/srmesh_orbit"),
        dir.join("bunny.srm"),
        dir.join("bunny00.off"),
    );
    (files.0.exists() && files.1.exists() && files.2.exists()).then_some(files)
}

/// SrMesh's tolerances: a finer grid than ours, reaching below 0.25 px, so that each of our
/// triangle counts falls between two of its own.
const SR_TOLERANCES: [f32; 11] = [
    0.125, 0.177, 0.25, 0.354, 0.5, 0.707, 1.0, 1.414, 2.0, 2.828, 4.0,
];

/// The instruction-set extensions this bench was compiled with, of those the cut's code can
/// use (the baseline x86-64 target has none of them; `-C target-cpu=native` enables what the
/// processor has).
fn compiled_for() -> String {
    let features = [
        ("popcnt", cfg!(target_feature = "popcnt")),
        ("sse4.2", cfg!(target_feature = "sse4.2")),
        ("avx2", cfg!(target_feature = "avx2")),
        ("bmi2", cfg!(target_feature = "bmi2")),
        ("fma", cfg!(target_feature = "fma")),
        ("avx512f", cfg!(target_feature = "avx512f")),
    ];
    let on: Vec<&str> = features.iter().filter(|f| f.1).map(|f| f.0).collect();
    if on.is_empty() {
        format!(
            "{}, baseline (none of popcnt, sse4.2, avx2, bmi2, fma)",
            std::env::consts::ARCH
        )
    } else {
        format!("{} with {}", std::env::consts::ARCH, on.join(", "))
    }
}

/// The `srmesh_adapt` lines of `srmesh_orbit` ([`srmesh_files`]), one fresh process per
/// tolerance: its first frame there runs cold code into fresh memory (see [`run_srmesh_warm`]).
fn run_srmesh() -> Vec<SrPeer> {
    let Some((bin, srm, off)) = srmesh_files() else {
        return Vec::new();
    };
    let mut peers = Vec::new();
    for t in SR_TOLERANCES {
        let Ok(out) = Command::new(&bin)
            .arg(&srm)
            .arg(&off)
            .args(["--tau", &t.to_string(), "--revs", "2"])
            .output()
        else {
            continue;
        };
        for l in String::from_utf8_lossy(&out.stdout).lines() {
            if !l.starts_with("srmesh_adapt") {
                continue;
            }
            let get = |k: &str| field(l, k);
            if let (Some(tol), Some(us), Some(tris), Some(v), Some(e), Some(fu), Some(ft)) = (
                get("tol_px"),
                get("median_us"),
                get("tris_mean"),
                get("vsplits_per_frame"),
                get("ecols_per_frame"),
                get("first_us"),
                get("first_faces"),
            ) {
                peers.push(SrPeer {
                    tol,
                    us,
                    tris,
                    ops: v + e,
                    first_us: fu,
                    first_tris: ft,
                });
            }
        }
    }
    peers
}

/// The number after `key=` in a peer's `key=value` line.
fn field(line: &str, key: &str) -> Option<f64> {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .and_then(|v| v.parse::<f64>().ok())
}

/// `y` at `x` on the log-log polyline through `points` (sorted by `x`), or `None` outside it.
fn log_log(points: &[(f64, f64)], x: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        (x0.min(x1) <= x && x <= x0.max(x1) && x0 != x1).then(|| {
            let f = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            (y0.ln() + f * (y1.ln() - y0.ln())).exp()
        })
    })
}

/// How many rounds the SrMesh section runs (`VDLOD_ROUNDS`, default 3, at least 1).
fn rounds() -> usize {
    std::env::var("VDLOD_ROUNDS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(3)
        .max(1)
}

/// The median of `v` and its range, as `1.23x (1.10-1.40x)`; `-` when empty.
fn spread(mut v: Vec<f64>) -> String {
    if v.is_empty() {
        return "-".to_string();
    }
    v.sort_by(f64::total_cmp);
    // Sorted, so the median is the middle (as `median` picks it) and the ends the range.
    format!(
        "{:.2}x ({:.2}-{:.2}x)",
        v[v.len() / 2],
        v[0],
        v[v.len() - 1]
    )
}

/// Our cut beside Hoppe's SrMesh in the same run, in rounds: ours at every tolerance, then
/// SrMesh's whole grid, then ours again, and so on ([`rounds`] of SrMesh, one more of ours).
/// Each round's speed-up compares SrMesh's time at our triangle count (interpolated log-log
/// between its two nearest tolerances) with ours in the runs either side of it; the table gives
/// the median over rounds and their range. First frames, from the base mesh, compared alike
/// (until 2026-12-07 ours ran warm against SrMesh's cold, which made them look 1.2-1.4x
/// SrMesh's speed): in fresh processes, ours ([`first_frame_fresh`]) against the driver's own
/// run of each tolerance; and warm, ours in a cut just made after loading the file and after a
/// reset of a cut that has run (as after a jump of the camera), against SrMesh's warm run
/// ([`run_srmesh_warm`]). Ours read [`DRIVER_BETWEEN`] before each frame, as the driver reads
/// its bookkeeping (until 2026-12-07 ours ran back to back, which at 4 px made SrMesh's frame
/// look nearly twice its time without the driver's reads).
fn srmesh(bytes: &[u8], mesh: &IndexedMesh) {
    println!("\n## 6. Beside Hoppe's SrMesh, bunny, peer orbit (640x480, 60 deg, 200 frames)\n");
    if srmesh_files().is_none() {
        println!(
            "(Hoppe's SrMesh not built (VDLOD_SRMESH, default $TMPDIR/hoppe-srmesh): run \
             ../shared/peers/hoppe/run.sh for the SrMesh section)"
        );
        return;
    }
    let sorted = |mut v: Vec<(f64, f64)>| {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    let path = std::env::temp_dir().join(format!("vdlod-lod-bench-{}.vdh", std::process::id()));
    if std::fs::write(&path, bytes).is_err() {
        println!(
            "(could not write {}: no first frames in fresh processes)",
            path.display()
        );
    }
    let between = vec![1u8; DRIVER_BETWEEN];
    let mut ours = vec![every_tolerance_loaded(bytes, mesh, &between)];
    let mut peers = Vec::new();
    let mut warm = Vec::new();
    let mut fresh = Vec::new();
    for _ in 0..rounds() {
        let peer = run_srmesh();
        if peer.is_empty() {
            println!("(SrMesh's driver printed no figures)");
            let _ = std::fs::remove_file(&path);
            return;
        }
        peers.push(peer);
        warm.push(sorted(run_srmesh_warm()));
        fresh.push(every_first_fresh(&path));
        ours.push(every_tolerance_loaded(bytes, mesh, &between));
    }
    let _ = std::fs::remove_file(&path);
    let steady: Vec<_> = peers
        .iter()
        .map(|p| sorted(p.iter().map(|p| (p.tris, p.us)).collect()))
        .collect();
    let first: Vec<_> = peers
        .iter()
        .map(|p| sorted(p.iter().map(|p| (p.first_tris, p.first_us)).collect()))
        .collect();
    println!(
        "Compiled for: ours {}; SrMesh with its library's release flags (-march=native, \
         -ffast-math). Ours for this processor too: RUSTFLAGS=\"-C target-cpu=native\".\n",
        compiled_for()
    );
    println!(
        "{} rounds. SrMesh over its own tolerances (median over rounds): {}\n",
        peers.len(),
        peers[0]
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let us = median(
                    peers
                        .iter()
                        .filter_map(|q| q.get(k))
                        .map(|q| q.us)
                        .collect(),
                );
                format!(
                    "{} px {us:.0} us, {:.0} tris, {:.1} ops",
                    p.tol, p.tris, p.ops
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    );
    println!(
        "Before each timed frame each side reads about {} KB untimed: SrMesh's driver its \
         bookkeeping (its face array, to count the operations), ours as much \
         (DRIVER_BETWEEN), so that both meet the same caches.\n",
        DRIVER_BETWEEN / 1024
    );
    println!(
        "First frames from the base mesh, compared alike: each side in a process of its own \
         (code run for the first time, memory never touched: SrMesh's driver as it ships), and \
         warm (ours in this process, SrMesh's in one driver process after a warm-up, its freed \
         memory kept for the next tolerance's mesh).\n"
    );
    println!("| tol px | our median us | our mean us | our tris | ops/frame | SrMesh median us at our tris | speed-up (medians) | speed-up (our mean) | first frame, fresh processes: ours | speed-up | first frame, warm: ours, file just loaded | speed-up | ours after a reset | speed-up |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (k, &t) in TOLERANCES.iter().enumerate() {
        let all: Vec<&Adapt> = ours.iter().map(|o| &o[k]).collect();
        let cat = |f: fn(&Adapt) -> &Vec<f64>| -> Vec<f64> {
            all.iter().flat_map(|a| f(a).iter().copied()).collect()
        };
        let (us, mean_us) = (median(cat(|a| &a.us)), mean(&cat(|a| &a.us)));
        let (tris, ops) = (mean(&cat(|a| &a.tris)), mean(&cat(|a| &a.ops)));
        let mut up = Vec::new();
        let mut up_mean = Vec::new();
        let mut up_first = Vec::new();
        let mut up_reset = Vec::new();
        let mut up_fresh = Vec::new();
        let mut fresh_us = Vec::new();
        let mut fresh_tris = 0.0;
        let mut sr_us = Vec::new();
        for (r, (round_steady, round_first)) in steady.iter().zip(&first).enumerate() {
            // The runs either side of SrMesh's round `r`.
            let (a, b) = (&ours[r][k], &ours[r + 1][k]);
            let round: Vec<f64> = a.us.iter().chain(&b.us).copied().collect();
            let tris = mean(&[a.tris.clone(), b.tris.clone()].concat());
            if let Some(sr) = log_log(round_steady, tris) {
                sr_us.push(sr);
                up.push(sr / median(round.clone()));
                up_mean.push(sr / mean(&round));
            }
            // SrMesh walks its whole active list every frame: its median is its mean.
            if let Some(&Some((tris, us))) = fresh[r].get(k) {
                fresh_us.push(us);
                fresh_tris = tris;
                if let Some(sr) = log_log(round_first, tris) {
                    up_fresh.push(sr / us);
                }
            }
            if let Some(sr) = log_log(&warm[r], a.first_tris as f64) {
                up_first.push(sr / a.first_us);
            }
            if let Some(sr) = log_log(&warm[r], a.reset_tris as f64) {
                up_reset.push(sr / a.reset_us);
            }
        }
        let fresh_us = if fresh_us.is_empty() {
            "-".to_string()
        } else {
            format!("{:.0} us, {fresh_tris} tris", median(fresh_us))
        };
        let sr = if sr_us.is_empty() {
            "-".to_string()
        } else {
            format!("{:.0}", median(sr_us))
        };
        let first_us = median(all.iter().map(|a| a.first_us).collect());
        let reset_us = median(all.iter().map(|a| a.reset_us).collect());
        println!(
            "| {t} | {us:.1} | {mean_us:.1} | {tris:.0} | {ops:.1} | {sr} | {} | {} | {fresh_us} | {} | {first_us:.0} us, {} tris | {} | {reset_us:.0} us, {} tris | {} |",
            spread(up),
            spread(up_mean),
            spread(up_fresh),
            all[0].first_tris,
            spread(up_first),
            all[0].reset_tris,
            spread(up_reset),
        );
    }
}

/// Settled vertices skipped or not ([`Cut::set_settling`]), without and with 4-frame geomorphs:
/// the same cuts, interleaved (on, off, on, off), medians of both runs of each.
fn settling(h: &HierarchyView<'_>, mesh: &IndexedMesh) {
    println!("\n## 7. Settled vertices skipped or asked, bunny, peer orbit (640x480, 60 deg, 200 frames)\n");
    println!("| tol px | geomorphs | skipped: median us | asked: median us | ratio | skipped: mean us | asked: mean us | ratio | share of vertices skipped |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for geomorph in [0u16, 4] {
        for &t in &TOLERANCES {
            let policy = QRefine::new(t);
            let mut on = Vec::new();
            let mut off = Vec::new();
            let mut share = Vec::new();
            for _ in 0..2 {
                let a = adapt_orbit_set(h, mesh, &policy, 1, geomorph, true, &[]);
                share.extend(a.settled.iter().copied());
                on.extend(a.us);
                off.extend(adapt_orbit_set(h, mesh, &policy, 1, geomorph, false, &[]).us);
            }
            let (on_mean, off_mean) = (mean(&on), mean(&off));
            let (on, off) = (median(on), median(off));
            println!(
                "| {t} | {geomorph} frames | {on:.1} | {off:.1} | {:.2}x | {on_mean:.1} | {off_mean:.1} | {:.2}x | {:.0}% |",
                on / off,
                on_mean / off_mean,
                100.0 * mean(&share)
            );
        }
    }
}

/// One revolution of the peer orbit with [`Budget::max_visits`] at `visits`.
struct Window {
    us: Vec<f64>,
    visited: Vec<f64>,
    tris: Vec<f64>,
    /// Every tenth frame as drawn (from the fifth).
    frames: Vec<Vec<vdlod_raster::Rgba8>>,
}

fn window_orbit(
    h: &HierarchyView<'_>,
    mesh: &IndexedMesh,
    policy: &impl Policy,
    visits: u32,
    draw: bool,
) -> Window {
    let orbit = peer_orbit(&mesh.bounds(), FRAMES, W, H);
    let mut cut = BunnyCut::boxed();
    cut.reset(h).expect("base mesh fits");
    let budget = Budget {
        max_visits: visits,
        ..Budget::default()
    };
    let mut frame = Frame::new(W, H).expect("frame");
    let mut out = Window {
        us: Vec::new(),
        visited: Vec::new(),
        tris: Vec::new(),
        frames: Vec::new(),
    };
    for i in 0..FRAMES {
        let camera = orbit.camera(i);
        let view = camera.view();
        let start = Instant::now();
        let s = cut.adapt(h, &view, policy, &budget);
        let us = start.elapsed().as_secs_f64() * 1e6;
        if i > 0 {
            out.us.push(us);
            out.visited.push(s.visited as f64);
            out.tris.push(s.triangles as f64);
        }
        if draw && i % 10 == 5 {
            frame
                .draw_cut(&cut, h, &camera, &style(Shading::Gouraud, false))
                .expect("draws");
            out.frames.push(frame.pixels().to_vec());
        }
    }
    out
}

/// The traversal spread over frames: windows of a half, a quarter and an eighth of the active
/// list against the full pass, interleaved (full, windows, full, windows), medians of both runs.
fn amortized(h: &HierarchyView<'_>, mesh: &IndexedMesh) {
    println!(
        "\n## 9. Amortized traversal (Budget::max_visits), bunny, peer orbit (640x480, 60 deg, 200 frames)\n"
    );
    println!("| tol px | vertices asked per frame | median us | ratio to full | mean tris | PSNR against the full pass dB |");
    println!("|---|---|---|---|---|---|");
    for t in [0.5f32, 1.0, 2.0] {
        let policy = QRefine::new(t);
        let full = window_orbit(h, mesh, &policy, u32::MAX, true);
        let active = full.tris.iter().sum::<f64>() / full.tris.len() as f64 / 2.0;
        // All, a half, a quarter and an eighth of the full pass's mean active count.
        const SHARES: [u32; 4] = [1, 2, 4, 8];
        let windows = SHARES.map(|d| match d {
            1 => u32::MAX,
            d => (active / d as f64).round() as u32,
        });
        let mut us: Vec<Vec<f64>> = vec![Vec::new(); windows.len()];
        let mut runs: Vec<Option<Window>> = (0..windows.len()).map(|_| None).collect();
        for _ in 0..2 {
            for (k, &w) in windows.iter().enumerate() {
                // The full pass's frames are `full`'s: only the windows' first runs draw.
                let draw = k > 0 && runs[k].is_none();
                let run = window_orbit(h, mesh, &policy, w, draw);
                us[k].extend(run.us.iter().copied());
                runs[k].get_or_insert(run);
            }
        }
        let full_us = median(us[0].clone());
        for (k, run) in runs.iter().enumerate() {
            let run = run.as_ref().expect("ran");
            let quality: Vec<f64> = run
                .frames
                .iter()
                .zip(&full.frames)
                .map(|(a, b)| psnr(a, b))
                .collect();
            let m = median(us[k].clone());
            let shown = if k == 0 {
                "all".to_string()
            } else {
                format!("{:.0} (1/{})", mean(&run.visited), SHARES[k])
            };
            let psnr_cell = if k == 0 {
                "-".to_string()
            } else {
                format!("{:.2}", mean(&quality))
            };
            println!(
                "| {t} | {shown} | {m:.1} | {:.2}x | {:.0} | {psnr_cell} |",
                m / full_us,
                mean(&run.tris)
            );
        }
    }
}

/// The wavelet cut as it is, with settled wavelets asked, and with the whole mesh emitted in
/// every frame that changes, interleaved frame by frame over the session of `reproduce fig9` on
/// the subdivided cow (without and with geomorphs); then the same view twice in a row.
fn wavelets() {
    use vdlod_core::wavelet::SemiRegularView;
    use vdlod_demo::wavelet::{cow_loop, finest_mesh, session, DemoWaveletCut};
    println!(
        "\n## 8. The wavelet engine's coherence, subdivided cow (51,200 faces), 0.5 / 3.5 px\n"
    );
    let mesh = cow_loop().expect("the cow subdivides");
    let bytes = mesh.to_bytes().expect("writes");
    let s = SemiRegularView::parse(&bytes).expect("valid");
    let b = finest_mesh(&mesh).bounds();
    let policy = QRefine {
        error: ScreenError {
            silhouette: 0.5,
            interior: 3.5,
        },
    };
    println!("| session | geomorph frames | as it is: median us | settled asked | ratio | whole mesh emitted | ratio | wavelets skipped per frame | the same view again, as it is / settled asked: median us |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (frames, morphs) in [(90u32, 0u16), (720, 0), (90, 8), (720, 8)] {
        let cameras = session(b.center(), b.radius(), frames, 512, 512);
        // Each frame's view once, then (other cuts) each view twice in a row.
        let mut rows = Vec::new();
        for twice in [false, true] {
            let mut cuts = [
                DemoWaveletCut::boxed(),
                DemoWaveletCut::boxed(),
                DemoWaveletCut::boxed(),
            ];
            for cut in &mut cuts {
                cut.reset(&s).expect("fits");
                cut.set_geomorph_frames(morphs);
            }
            cuts[1].set_settling(false);
            cuts[2].set_partial_emission(false);
            let (mut times, mut skipped) = ([Vec::new(), Vec::new(), Vec::new()], 0.0);
            for _ in 0..2 {
                for camera in &cameras {
                    let view = camera.view();
                    for (k, cut) in cuts.iter_mut().enumerate() {
                        if twice {
                            cut.adapt(&s, &view, &policy, &Budget::default());
                        }
                        let start = Instant::now();
                        let stats = cut.adapt(&s, &view, &policy, &Budget::default());
                        times[k].push(start.elapsed().as_secs_f64() * 1e6);
                        if k == 0 {
                            skipped += stats.settled as f64;
                        }
                    }
                }
            }
            let [us, asked, whole] = times.map(median);
            rows.push((us, asked, whole, skipped / (2 * frames) as f64));
        }
        let ((us, asked, whole, skipped), (still, still_asked, _, _)) = (rows[0], rows[1]);
        println!(
            "| {frames} frames | {morphs} | {us:.0} | {asked:.0} | {:.2}x | {whole:.0} | {:.2}x | {skipped:.0} | {still:.0} / {still_asked:.0} |",
            us / asked,
            us / whole,
        );
    }
}

fn policies(h: &HierarchyView<'_>, mesh: &IndexedMesh) {
    println!("\n## 5. Policies, bunny, peer orbit (640x480, 60 deg, 200 frames)\n");
    let screen = QRefine::new(0.3);
    let importance = (
        Frustum,
        Importance::for_model(Importance::DEFAULT_THRESHOLD, h),
    );
    let before = adapt_orbit_with(h, mesh, &screen, 1);
    let judged = adapt_orbit_with(h, mesh, &importance, 1);
    let after = adapt_orbit_with(h, mesh, &screen, 1);
    let us = median(before.us.iter().chain(&after.us).copied().collect());
    let tris = mean(&[before.tris, after.tris].concat());
    let (i_us, i_tris) = (median(judged.us), mean(&judged.tris));
    println!("| policy | median us | mean tris | ns per triangle |");
    println!("|---|---|---|---|");
    println!(
        "| QRefine 0.3 px | {us:.0} | {tris:.0} | {:.0} |",
        us * 1e3 / tris
    );
    println!(
        "| importance, threshold {} | {i_us:.0} | {i_tris:.0} | {:.0} |",
        Importance::DEFAULT_THRESHOLD,
        i_us * 1e3 / i_tris
    );
    println!(
        "\nThe importance test takes {:.1}x QRefine's time per triangle (it walks every vertex's triangles).",
        (i_us / i_tris) / (us / tris)
    );
}

fn quality(h: &HierarchyView<'_>, mesh: &IndexedMesh) {
    println!("\n## 3. PSNR against full detail at equal triangles, peer orbit, 20 frames\n");
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let adapter =
        VertexDataAdapter::new(meshopt::typed_to_bytes(&mesh.positions), 12, 0).expect("positions");
    println!("| tolerance px (silhouette / interior) | mean tris | adapted PSNR dB | meshopt PSNR dB | difference dB |");
    println!("|---|---|---|---|---|");
    for (silhouette, interior) in [
        (0.5f32, 0.5f32),
        (1.0, 1.0),
        (2.0, 2.0),
        (4.0, 4.0),
        (0.5, 1.5),
        (1.0, 3.0),
        (2.0, 6.0),
    ] {
        let orbit = peer_orbit(&mesh.bounds(), FRAMES, W, H);
        let mut cut = BunnyCut::boxed();
        cut.reset(h).expect("fits");
        let policy = QRefine {
            error: ScreenError {
                silhouette,
                interior,
            },
        };
        let mut frame = Frame::new(W, H).expect("frame");
        let mut reference = Frame::new(W, H).expect("frame");
        let (mut ours, mut theirs, mut tris) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..FRAMES {
            let camera = orbit.camera(i);
            let view = camera.view();
            let s = cut.adapt(h, &view, &policy, &Budget::default());
            if i % 10 != 5 {
                continue;
            }
            let params = camera_params(&camera, Shading::Gouraud, false);
            reference
                .draw(&mesh.as_raster_mesh(), &params)
                .expect("draws");
            frame
                .draw_cut(&cut, h, &camera, &style(Shading::Gouraud, false))
                .expect("draws");
            ours.push(psnr(frame.pixels(), reference.pixels()));
            let simplified = meshopt::simplify(
                &indices,
                &adapter,
                s.triangles as usize * 3,
                1.0,
                SimplifyOptions::None,
                None,
            );
            let triangles: Vec<[u32; 3]> = simplified
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect();
            let uniform = IndexedMesh {
                triangles,
                ..mesh.clone()
            };
            frame
                .draw(&uniform.as_raster_mesh(), &params)
                .expect("draws");
            theirs.push(psnr(frame.pixels(), reference.pixels()));
            tris.push(s.triangles as f64);
        }
        let (o, t) = (mean(&ours), mean(&theirs));
        println!(
            "| {silhouette} / {interior} | {:.0} | {o:.2} | {t:.2} | {:+.2} |",
            mean(&tris),
            o - t
        );
    }
    // The ceiling: every split done, drawn with the file's 8-bit octahedral normals.
    let mut cut = BigCut::boxed();
    cut.reset(h).expect("fits");
    while cut.refine_everything(h) > 0 {}
    let orbit = peer_orbit(&mesh.bounds(), FRAMES, W, H);
    let camera = orbit.camera(5);
    let mut frame = Frame::new(W, H).expect("frame");
    let mut reference = Frame::new(W, H).expect("frame");
    let params = camera_params(&camera, Shading::Gouraud, false);
    reference
        .draw(&mesh.as_raster_mesh(), &params)
        .expect("draws");
    frame
        .draw_cut(&cut, h, &camera, &style(Shading::Gouraud, false))
        .expect("draws");
    println!(
        "\nCeiling: the fully refined cut ({} tris, normals as the file stores them) scores {:.2} dB.",
        cut.triangles().len(),
        psnr(frame.pixels(), reference.pixels())
    );
}

/// The argument after which [`srmesh`] runs this bench again for [`first_frame_fresh`].
const FRESH: &str = "__first-frame-fresh";

/// Our first frame in a process of its own, as SrMesh's driver runs its own: the hierarchy read
/// from `path` and the cut made before anything else allocates (so its memory is untouched, as
/// an application's first cut's is), then the first view of the peer orbit refined from the
/// base mesh at `tolerance`; prints `first_fresh us=... tris=...`.
fn first_frame_fresh(path: &str, tolerance: f32) {
    let bytes = std::fs::read(path).expect("the hierarchy written by the bench");
    let mut cut = BunnyCut::boxed();
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bundled bunny");
    let h = HierarchyView::parse(&bytes).expect("valid");
    cut.reset(&h).expect("base mesh fits");
    let view = peer_orbit(&mesh.bounds(), FRAMES, W, H).camera(0).view();
    read_through(&vec![1u8; DRIVER_BETWEEN]);
    let start = Instant::now();
    let s = cut.adapt(&h, &view, &QRefine::new(tolerance), &Budget::default());
    let us = start.elapsed().as_secs_f64() * 1e6;
    println!("first_fresh us={us} tris={}", s.triangles);
}

/// [`first_frame_fresh`] at each of [`TOLERANCES`], a process each: `(triangles, us)` by
/// tolerance, `None` where the process gave no figures (so every entry stays at its
/// tolerance's place).
fn every_first_fresh(path: &std::path::Path) -> Vec<Option<(f64, f64)>> {
    let Ok(me) = std::env::current_exe() else {
        return Vec::new();
    };
    TOLERANCES
        .iter()
        .map(|t| {
            let out = Command::new(&me)
                .args(["--bench", FRESH])
                .arg(path)
                .arg(t.to_string())
                .output()
                .ok()?;
            let text = String::from_utf8_lossy(&out.stdout).into_owned();
            let line = text.lines().find(|l| l.starts_with("first_fresh"))?;
            let get = |k: &str| field(line, k);
            Some((get("tris")?, get("us")?))
        })
        .collect()
}

fn main() {
    // `cargo test --benches` runs bench binaries without `--bench`: keep that quick.
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") {
        return;
    }
    if let Some(k) = args.iter().position(|a| a == FRESH) {
        let tolerance = args.get(k + 2).and_then(|t| t.parse().ok());
        if let (Some(path), Some(t)) = (args.get(k + 1), tolerance) {
            first_frame_fresh(path, t);
        }
        return;
    }
    {
        let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bundled bunny");
        let (_, bytes, _) = build_with_progress(&mesh, &Default::default(), false).expect("builds");
        let h = HierarchyView::parse(&bytes).expect("valid");
        println!(
            "## 4. Memory\n\nBunny cut `Cut<16384, 32768, 2048>`: {} bytes ({:.1} MB); Loop-bunny cut `Cut<262144, 524288, 32768, u32>`: {} bytes ({:.1} MB).",
            BunnyCut::BYTES,
            BunnyCut::BYTES as f64 / 1e6,
            BigCut::BYTES,
            BigCut::BYTES as f64 / 1e6
        );
        // `cargo bench --bench lod -- quality` runs the sections whose name contains `quality`.
        let filter: Vec<String> = std::env::args()
            .skip(1)
            .filter(|a| !a.starts_with("--"))
            .collect();
        let wanted = |name: &str| filter.is_empty() || filter.iter().any(|f| name.contains(f));
        if wanted("adaptation") {
            adaptation(&h, &mesh);
        }
        if wanted("quality") {
            quality(&h, &mesh);
        }
        if wanted("policies") {
            policies(&h, &mesh);
        }
        if wanted("srmesh") {
            srmesh(&bytes, &mesh);
        }
        if wanted("settling") {
            settling(&h, &mesh);
        }
        if wanted("wavelets") {
            wavelets();
        }
        if wanted("amortized") {
            amortized(&h, &mesh);
        }
    }
}
