//! What drawing a frame in bands costs against drawing it whole, in one run.
//!
//! Scenes, both at 320x240 in Rgb565 with 16-bit depth, from the peer camera (azimuth 30 and
//! elevation 20 degrees): the bunny's cut under a 5,000-triangle budget at 1 px (what a device
//! draws), and the full-detail bunny (75,408 triangles). Each frame is drawn whole (one 320x240
//! colour and depth buffer) and in bands of 16 and of 40 rows through one band-sized buffer
//! (vertices shaded once per frame, every triangle re-read per band); the three alternate frame
//! by frame, and the minimum and median per frame and the ratios to the whole-frame draw are
//! printed; then the same bands with the triangles binned by row once per frame
//! (`ShadedMesh::bin`, 4 bytes per triangle).
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

/// Bands without bins (a function of its own, so that profiles tell the two apart).
#[inline(never)]
fn plain<M: MeshSource>(m: &M, p: &vdlod_raster::DrawParams, b: &mut Buffers, rows: usize) -> u32 {
    banded(m, p, b, rows, false)
}

/// Bands with row bins.
#[inline(never)]
fn binned<M: MeshSource>(m: &M, p: &vdlod_raster::DrawParams, b: &mut Buffers, rows: usize) -> u32 {
    banded(m, p, b, rows, true)
}

#[inline(always)]
fn banded<M: MeshSource>(
    mesh: &M,
    params: &vdlod_raster::DrawParams,
    buf: &mut Buffers,
    rows: usize,
    binned: bool,
) -> u32 {
    let shaded = shade(mesh, params, W, H, &mut buf.scratch).expect("shades");
    let binned = binned.then(|| shaded.bin(&mut buf.bins).expect("bins"));
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
    bins: Vec<[u16; 2]>,
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
        bins: vec![[0; 2]; mesh.triangles().len()],
    };
    let mut times = [Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..rounds() {
        for (k, t) in times.iter_mut().enumerate() {
            let start = Instant::now();
            black_box(match k {
                0 => whole(mesh, params, &mut buf),
                1 => plain(mesh, params, &mut buf, 16),
                2 => plain(mesh, params, &mut buf, 40),
                3 => binned(mesh, params, &mut buf, 16),
                _ => binned(mesh, params, &mut buf, 40),
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
        "| scene | whole frame us (min / median) | 15 bands of 16 rows | 6 bands of 40 rows \
         | 16 rows, binned | 40 rows, binned |"
    );
    println!("|---|---|---|---|---|---|");
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
