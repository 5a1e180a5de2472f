//! Hierarchy build time and peak memory, beside meshoptimizer (`meshopt` 0.7) simplifying the same
//! mesh to the same base size, in the same run.
//!
//! Meshes: the bunny (75,408 triangles) and the bunny after one step of Loop subdivision (301,632
//! triangles, the stand-in for the merge-tree paper's 160k-face model). vdlod builds the whole
//! forest (QEM cost, default options) down to the base mesh, and then the balanced forest
//! (`balanced`, made in passes); meshopt's `simplify` is asked for the same number of triangles
//! with no error limit. Each is run `RUNS` times, the three interleaved round by round; the table
//! gives the median time (and the time ratios as the median of the rounds' ratios, with their
//! range) and the peak heap in use during the call (from a counting allocator, which also
//! serves meshoptimizer's own temporary allocations through `meshopt_setAllocator`), plus the
//! ratios vdlod / meshopt.
//!
//! The remesher (`remesh`: its simplification, the map back through the collapses and the
//! relaxation, at the default 300-face base and four levels) on every fixture and the
//! Loop-subdivided bunny: time and peak heap, and both per input triangle, so a user with a large
//! scan knows what to expect. It has no peer here.
//!
//! `scale` builds the bunny after one, two and three steps of Loop subdivision (up to 4.8M
//! triangles), beside meshopt, and prints both per input triangle: minutes and several GB.
//!
//! Run: `cargo bench --bench hierarchy` (build and remesh), `-- build` or `-- remesh` (one),
//! `-- scale` (only that).

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::c_void;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use meshopt::{SimplifyOptions, VertexDataAdapter};
use vdlod_core::build::{build, BuildOptions, InputMesh};
use vdlod_core::remesh::{remesh, RemeshOptions};
use vdlod_demo::mesh::{load_obj, load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::stats::median;

/// The system allocator, counting the bytes in use and their peak.
struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = IN_USE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Bytes before each of meshoptimizer's blocks, holding the block's whole size (its
/// `deallocate` is told only the pointer), at the alignment `operator new` gives.
const MESHOPT_HEADER: usize = 16;

/// meshoptimizer's temporary allocations, through the counting allocator. Its `simplify`
/// allocates everything it works in with `operator new` (its `meshopt_Allocator`), which Rust's
/// global allocator never sees: until 2026-12-07 the count held only the index buffer it
/// returns (12 bytes a triangle), not its working memory.
unsafe extern "C" fn meshopt_allocate(size: usize) -> *mut c_void {
    let Some(layout) = size
        .checked_add(MESHOPT_HEADER)
        .and_then(|total| Layout::from_size_align(total, MESHOPT_HEADER).ok())
    else {
        return std::ptr::null_mut();
    };
    // SAFETY: `layout` is at least `MESHOPT_HEADER` bytes, so not zero-sized; a null result is
    // handed to `handle_alloc_error` (as `operator new` would throw). The header is inside the
    // block and aligned for a `usize`.
    unsafe {
        let p = std::alloc::alloc(layout);
        if p.is_null() {
            std::alloc::handle_alloc_error(layout);
        }
        p.cast::<usize>().write(layout.size());
        p.add(MESHOPT_HEADER).cast()
    }
}

/// Frees a block of [`meshopt_allocate`].
unsafe extern "C" fn meshopt_deallocate(p: *mut c_void) {
    if p.is_null() {
        return;
    }
    // SAFETY: meshoptimizer hands back only pointers `meshopt_allocate` returned, once each:
    // the header before it holds the size the block was allocated with, at this alignment.
    unsafe {
        let base = p.cast::<u8>().sub(MESHOPT_HEADER);
        let size = base.cast::<usize>().read();
        std::alloc::dealloc(
            base,
            Layout::from_size_align_unchecked(size, MESHOPT_HEADER),
        );
    }
}

const RUNS: usize = 3;

/// Median seconds and peak extra heap bytes of `f` over [`RUNS`] runs, and its last result.
fn measure<T>(f: impl FnMut() -> T) -> (f64, usize, T) {
    measure_runs(RUNS, f)
}

/// [`measure`] over `runs` runs (at least one).
fn measure_runs<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, usize, T) {
    let runs = runs.max(1);
    let mut times = Vec::new();
    let mut peak = 0;
    let mut last = None;
    for _ in 0..runs {
        let base = IN_USE.load(Ordering::Relaxed);
        PEAK.store(base, Ordering::Relaxed);
        let t = Instant::now();
        let out = f();
        times.push(t.elapsed().as_secs_f64());
        peak = peak.max(PEAK.load(Ordering::Relaxed) - base);
        last = Some(out);
    }
    times.sort_by(f64::total_cmp);
    (times[runs / 2], peak, last.expect("runs > 0"))
}

/// The median of per-round ratios and their range, as `4.2x (3.9-4.6x)`.
fn ratios(ours: &[f64], theirs: &[f64]) -> String {
    let r: Vec<f64> = ours.iter().zip(theirs).map(|(a, b)| a / b).collect();
    let (lo, hi) = r
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
    format!("{:.1}x ({lo:.1}-{hi:.1}x)", median(r))
}

/// Our build, meshoptimizer's `simplify` to the same base and our balanced build, interleaved
/// round by round (this machine's speed drifts within a run): medians of `runs` rounds, and the
/// time ratios as the median of the rounds' ratios with their range.
fn compare(name: &str, mesh: &IndexedMesh, runs: usize) {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: None,
        triangles: &mesh.triangles,
    };
    let ours = || build(&input, &BuildOptions::default(), &mut |_| {}).expect("valid mesh");
    let balanced = || {
        let opts = BuildOptions {
            balanced: true,
            ..BuildOptions::default()
        };
        build(&input, &opts, &mut |_| {}).expect("valid mesh")
    };
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let adapter =
        VertexDataAdapter::new(meshopt::typed_to_bytes(&mesh.positions), 12, 0).expect("positions");
    let mut times = [Vec::new(), Vec::new(), Vec::new()];
    let mut peaks = [0usize; 3];
    let (mut base, mut base_bal, mut out_len) = (0, 0, 0);
    for _ in 0..runs.max(1) {
        let (t, m, h) = measure_runs(1, ours);
        base = h.base_triangles.len();
        drop(h);
        times[0].push(t);
        peaks[0] = peaks[0].max(m);
        let (t, m, out) = measure_runs(1, || {
            meshopt::simplify(
                &indices,
                &adapter,
                base * 3,
                1.0,
                SimplifyOptions::None,
                None,
            )
        });
        out_len = out.len();
        times[1].push(t);
        peaks[1] = peaks[1].max(m);
        let (t, m, hb) = measure_runs(1, balanced);
        base_bal = hb.base_triangles.len();
        times[2].push(t);
        peaks[2] = peaks[2].max(m);
    }
    let [m_ours, m_theirs, m_bal] = peaks;
    // Its working memory (the edge adjacency alone, two `u32`s an index) is far above the
    // index buffer it returns: a peak not above that buffer means its allocations went uncounted.
    assert!(
        m_theirs > 2 * std::mem::size_of_val(indices.as_slice()),
        "meshoptimizer's allocations were not counted: {m_theirs} bytes"
    );
    let [t_ours, t_theirs, t_bal] = times.clone().map(median);
    println!(
        "{name:<24} {:>8} tris | vdlod build {:>8.1} ms {:>7.1} MB -> base {:>5} tris | \
         meshopt simplify {:>7.1} ms {:>6.1} MB -> {:>5} tris | vdlod/meshopt time {} memory {:.1}x",
        mesh.triangles.len(),
        t_ours * 1e3,
        m_ours as f64 / 1e6,
        base,
        t_theirs * 1e3,
        m_theirs as f64 / 1e6,
        out_len / 3,
        ratios(&times[0], &times[1]),
        m_ours as f64 / m_theirs as f64
    );
    // The balanced forest (`--balanced`, made in passes), beside the same meshopt runs.
    println!(
        "{:<24} {:>8} balanced | vdlod build {:>8.1} ms {:>7.1} MB -> base {:>5} tris | \
         vdlod/meshopt time {} memory {:.1}x",
        "",
        "",
        t_bal * 1e3,
        m_bal as f64 / 1e6,
        base_bal,
        ratios(&times[2], &times[1]),
        m_bal as f64 / m_theirs as f64
    );
    let n = mesh.triangles.len() as f64;
    println!(
        "{:<24} {:>8} per input triangle: vdlod {:.2} us {:.0} B | meshopt {:.3} us {:.1} B",
        "",
        "",
        t_ours * 1e6 / n,
        m_ours as f64 / n,
        t_theirs * 1e6 / n,
        m_theirs as f64 / n
    );
}

fn remesh_figures(name: &str, mesh: &IndexedMesh) {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: None,
        triangles: &mesh.triangles,
    };
    let options = RemeshOptions::default();
    let (t, m, out) = measure(|| remesh(&input, &options, &mut |_| {}).expect("remeshable"));
    let n = mesh.triangles.len() as f64;
    println!(
        "{name:<24} {:>8} tris | remesh {:>8.1} ms {:>7.1} MB -> base {:>4}, {:>6} tris | \
         {:>6.2} us and {:>5.0} B per input triangle",
        mesh.triangles.len(),
        t * 1e3,
        m as f64 / 1e6,
        out.base_faces,
        out.mesh.finest_triangles().len(),
        t * 1e6 / n,
        m as f64 / n
    );
}

fn main() {
    // `cargo test --benches` runs bench binaries with `--bench` absent: keep that quick.
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") {
        return;
    }
    // SAFETY: set once, before any other meshoptimizer call, and this program calls it from
    // one thread only.
    unsafe {
        meshopt::ffi::meshopt_setAllocator(Some(meshopt_allocate), Some(meshopt_deallocate));
    }
    let named = |what: &str| args.iter().any(|a| a == what);
    // `scale` (minutes, several GB) runs only when named.
    let only = |what: &str| !["build", "remesh", "scale"].iter().any(|a| named(a)) || named(what);
    let bunny = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bundled bunny");
    let loop_bunny = bunny.loop_subdivide();
    if only("build") {
        compare("bunny", &bunny, RUNS);
        compare("bunny, Loop-subdivided", &loop_bunny, RUNS);
    }
    if named("scale") {
        // Time and memory per input triangle as the input grows: the bunny after one, two and
        // three steps of Loop subdivision (301,632 / 1,206,528 / 4,826,112 triangles), one run
        // each of the largest.
        let mut mesh = loop_bunny.clone();
        for level in 1..=3 {
            compare(
                &format!("bunny, Loop x{level}"),
                &mesh,
                if level < 3 { RUNS } else { 1 },
            );
            if level < 3 {
                mesh = mesh.loop_subdivide();
            }
        }
    }
    if only("remesh") {
        let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
        for name in ["head", "elk", "cow", "fandisk"] {
            let mesh = load_obj(&fixtures.join(format!("{name}.obj"))).expect("fixture");
            remesh_figures(name, &mesh);
        }
        remesh_figures("bunny", &bunny);
        remesh_figures("bunny, Loop-subdivided", &loop_bunny);
    }
}
