//! What drawing a frame in bands costs against drawing it whole, in one run.
//!
//! Scenes, both at 320x240 in Rgb565 with 16-bit depth, from the peer camera (azimuth 30 and
//! elevation 20 degrees): the bunny's cut under a 5,000-triangle budget at 1 px (what a device
//! draws), and the full-detail bunny (75,408 triangles). Each frame is drawn whole (one 320x240
//! colour and depth buffer) and in bands through one band-sized buffer (vertices shaded once per
//! frame): 16-row bands that re-read every triangle; 16- and 40-row bands that scan the row bins
//! (`ShadedMesh::bin` with 4 bytes per triangle); and the same with room for the per-band lists,
//! so that each band reads only its own triangles. The six alternate frame by frame, and the
//! minimum and median per frame and the ratios to the whole-frame draw are printed.
//!
//! Run: `cargo bench --bench bands`.

use std::hint::black_box;
use std::time::Instant;

use vdlod::prelude::*;
use vdlod_demo::camera::peer_orbit;
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::style;
use vdlod_raster::{shade, MeshSource};

const W: usize = 320;
const H: usize = 240;
/// Rounds of the five draws; `VDLOD_BENCH_ROUNDS` overrides it (1 under callgrind).
fn rounds() -> usize {
    std::env::var("VDLOD_BENCH_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

#[inline(never)]
fn whole<M: MeshSource>(mesh: &M, params: &vdlod_raster::DrawParams, buf: &mut Buffers) -> u32 {
    let shaded = shade(mesh, params, W, H, &mut buf.scratch).expect("shades");
    let mut t = Target::new(&mut buf.color, &mut buf.depth, W, H).expect("target");
    t.clear(Rgb565(0));
    shaded.draw(&mut t).expect("draws").rasterized
}

/// How a band finds its triangles.
#[derive(Clone, Copy)]
enum Bins {
    /// It reads them all.
    None,
    /// It scans the row bins (4 bytes per triangle).
    Rows,
    /// It reads its own list (the bins have room for them).
    Lists,
}

/// Bands without bins (a function of its own per kind, so that profiles tell them apart).
#[inline(never)]
fn plain<M: MeshSource>(m: &M, p: &vdlod_raster::DrawParams, b: &mut Buffers, rows: usize) -> u32 {
    banded(m, p, b, rows, Bins::None)
}

/// Bands with row bins.
#[inline(never)]
fn scanned<M: MeshSource>(
    m: &M,
    p: &vdlod_raster::DrawParams,
    b: &mut Buffers,
    rows: usize,
) -> u32 {
    banded(m, p, b, rows, Bins::Rows)
}

/// Bands with a list each.
#[inline(never)]
fn listed<M: MeshSource>(m: &M, p: &vdlod_raster::DrawParams, b: &mut Buffers, rows: usize) -> u32 {
    banded(m, p, b, rows, Bins::Lists)
}

#[inline(always)]
fn banded<M: MeshSource>(
    mesh: &M,
    params: &vdlod_raster::DrawParams,
    buf: &mut Buffers,
    rows: usize,
    bins: Bins,
) -> u32 {
    let shaded = shade(mesh, params, W, H, &mut buf.scratch).expect("shades");
    let space = match bins {
        Bins::None => None,
        Bins::Rows => Some(&mut buf.bins[..mesh.triangles().len()]),
        Bins::Lists => Some(&mut buf.bins[..]),
    };
    let binned = space.map(|space| shaded.bin(rows, space).expect("bins"));
    assert_eq!(
        binned.is_some_and(|b| b.has_band_lists()),
        matches!(bins, Bins::Lists)
    );
    let mut n = 0;
    for band in Window::bands(W, H, rows) {
        let mut t = Target::window(&mut buf.color, &mut buf.depth, W, H, band, W).expect("band");
        t.clear(Rgb565(0));
        let stats = match &binned {
            Some(b) => b.draw(&mut t),
            None => shaded.draw(&mut t),
        };
        n = stats.expect("draws").rasterized;
        black_box(t.color());
    }
    n
}

struct Buffers {
    color: Vec<Rgb565>,
    depth: Vec<u16>,
    scratch: Vec<ShadedVertex>,
    bins: Vec<u32>,
}

fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2])
}

fn run<M: MeshSource>(name: &str, mesh: &M, params: &vdlod_raster::DrawParams) {
    let mut buf = Buffers {
        color: vec![Rgb565(0); W * H],
        depth: vec![0; W * H],
        scratch: vec![ShadedVertex::default(); mesh.vertex_count()],
        bins: vec![0; 3 * mesh.triangles().len() + H + 1],
    };
    let mut times: [Vec<f64>; 6] = Default::default();
    for _ in 0..rounds() {
        for (k, t) in times.iter_mut().enumerate() {
            let start = Instant::now();
            black_box(match k {
                0 => whole(mesh, params, &mut buf),
                1 => plain(mesh, params, &mut buf, 16),
                2 => scanned(mesh, params, &mut buf, 16),
                3 => scanned(mesh, params, &mut buf, 40),
                4 => listed(mesh, params, &mut buf, 16),
                _ => listed(mesh, params, &mut buf, 40),
            });
            t.push(start.elapsed().as_secs_f64() * 1e6);
        }
    }
    let [w, rest @ ..] = times.map(stats);
    let mut line = format!("| {name} | {:.0} / {:.0} |", w.0, w.1);
    for b in rest {
        line += &format!(" {:.0} / {:.0} ({:.2}x) |", b.0, b.1, b.1 / w.1);
    }
    println!("{line}");
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo test --benches` lists benchmarks; there is nothing to list
    }
    let mut mesh: IndexedMesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bunny");
    mesh.reorder_for_locality();
    let (_, bytes, _) =
        vdlod_demo::hierarchy::build_with_progress(&mesh, &Default::default(), false)
            .expect("builds");
    let h = HierarchyView::parse(&bytes).expect("valid");
    let orbit = peer_orbit(&mesh.bounds(), 12, W, H);
    let camera = orbit.camera(1);
    let mut cut = Cut::<2508, 5000, 313>::boxed();
    cut.reset(&h).expect("fits");
    let budget = Budget {
        max_triangles: 5000,
        ..Budget::default()
    };
    for _ in 0..4 {
        vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(1.0), &budget).expect("adapts");
    }
    let drawn = style(Shading::Gouraud, false);
    let params = drawn.params(&camera);
    println!(
        "| scene | whole frame us (min / median) | 15 bands of 16 rows, unbinned \
         | 16 rows, row bins | 40 rows, row bins | 16 rows, band lists | 40 rows, band lists |"
    );
    println!("|---|---|---|---|---|---|---|");
    let cut_mesh = CutMesh::new(&cut, &h, false);
    run(
        &format!("bunny cut, {} triangles", cut.triangles().len()),
        &cut_mesh,
        &params,
    );
    if std::env::var_os("VDLOD_BENCH_CUT_ONLY").is_some() {
        return;
    }
    run(
        &format!("full bunny, {} triangles", mesh.triangles.len()),
        &mesh.as_raster_mesh(),
        &params,
    );
}
