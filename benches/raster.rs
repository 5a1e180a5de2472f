//! Rasterizer throughput on the Stanford bunny, beside the `euc` software rasterizer in the same run.
//!
//! Scene: the bunny (75,408 triangles) whole in view from the peer camera of
//! `shared/peers/README.md` (60 degree vertical field of view, bounding sphere just filling it,
//! azimuth 30 and elevation 20 degrees), Gouraud shading with one directional light, depth test and
//! back-face culling, at 640x480 and 320x240. Both renderers clear their buffers, transform every
//! vertex and draw every triangle each iteration; `euc` gets the same matrix, the same per-vertex
//! light and the same triangles.
//!
//! The bunny's file lists its triangles in no spatial order; the demo reorders them along a Morton
//! curve at load time (`IndexedMesh::reorder_for_locality`), as any renderer's mesh preparation
//! would. The `bunny_*` groups draw that order; `bunny_file_order_640x480` draws the file's order.
//! Both renderers always get the same index buffer. vdlod's mesh is a `CheckedMesh`, its indices
//! checked once when the scene is made, as a renderer checks an index buffer when it takes it
//! (unchecked, each draw reads every index first to check it: about 5% of a 320x240 frame);
//! `euc` does not check indices.
//!
//! Run: `cargo bench --bench raster`. Criterion prints the time per frame and, as throughput,
//! triangles per second (Melem/s); then a second pass alternates the two renderers frame by frame
//! and prints minimum and median times and their ratios, which are the figures to quote. Its last
//! line, `bunny_bands16_320x240`, draws the 320x240 frame as a device does, binned and in bands of
//! 16 rows through one band-sized buffer, against `euc` drawing it whole.

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, Criterion, Throughput};
use euc::{buffer::Buffer2d, rasterizer, Pipeline};
use vdlod_demo::camera::peer_orbit;
use vdlod_demo::frame::{Frame, BACKGROUND};
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::camera_params;
use vdlod_raster::{shade, CheckedMesh, Light, Rgba8, ShadedVertex, Shading, Target, Window};

/// `euc` pipeline doing what our Gouraud mode does with `unit_normals`: per-vertex Lambert from
/// unit normals, interpolated colour.
struct Gouraud<'a> {
    mvp: vek::Mat4<f32>,
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    light: Light,
    light_unit: glam::Vec3,
    base: [f32; 3],
}

impl Pipeline for Gouraud<'_> {
    type Vertex = u32;
    type VsOut = vek::Vec3<f32>;
    type Pixel = u32;

    #[inline(always)]
    fn vert(&self, v: &u32) -> ([f32; 4], vek::Vec3<f32>) {
        let i = *v as usize;
        let clip = self.mvp * vek::Vec4::from_point(vek::Vec3::from(self.positions[i]));
        let l = self
            .light
            .intensity_unit(glam::Vec3::from(self.normals[i]), self.light_unit);
        (clip.into_array(), vek::Vec3::from(self.base) * l)
    }

    #[inline(always)]
    fn frag(&self, c: &vek::Vec3<f32>) -> u32 {
        let ch = |v: f32| v.clamp(0.0, 255.0) as u32;
        0xff00_0000 | (ch(c.x) << 16) | (ch(c.y) << 8) | ch(c.z)
    }
}

/// One scene drawn by both renderers, each with buffers of its own.
struct Scene<'a> {
    name: String,
    triangles: usize,
    mesh: CheckedMesh<vdlod_raster::Mesh<'a>>,
    params: vdlod_raster::DrawParams,
    frame: Frame,
    pipe: Gouraud<'a>,
    indices: Vec<u32>,
    color: Buffer2d<u32>,
    depth: Buffer2d<f32>,
}

impl<'a> Scene<'a> {
    fn new(name: &str, mesh: &'a IndexedMesh, w: usize, h: usize) -> Scene<'a> {
        let camera = peer_orbit(&mesh.bounds(), 12, w, h).camera(1); // azimuth 30 degrees
        let params = camera_params(&camera, Shading::Gouraud, false);
        Scene {
            name: format!("{name}_{w}x{h}"),
            triangles: mesh.triangles.len(),
            mesh: CheckedMesh::new(mesh.as_raster_mesh()).expect("indices in range"),
            params,
            frame: Frame::new(w, h).expect("frame"),
            pipe: Gouraud {
                mvp: vek::Mat4::from_col_array(params.mvp.to_cols_array()),
                positions: &mesh.positions,
                normals: &mesh.normals,
                light: params.light,
                light_unit: params.light.unit_direction(),
                base: params.base_color.map(|c| c as f32),
            },
            indices: mesh.triangles.iter().flatten().copied().collect(),
            color: Buffer2d::new([w, h], 0u32),
            depth: Buffer2d::new([w, h], 1.0f32),
        }
    }

    fn vdlod(&mut self) {
        black_box(self.frame.draw(&self.mesh, &self.params).expect("draw"));
    }

    fn euc(&mut self) {
        euc::Target::clear(&mut self.color, 0);
        euc::Target::clear(&mut self.depth, 1.0);
        self.pipe.draw::<rasterizer::Triangles<_>, _>(
            &self.indices,
            &mut self.color,
            Some(&mut self.depth),
        );
        black_box(&self.color);
    }
}

fn meshes() -> (IndexedMesh, IndexedMesh) {
    let file_order = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bundled bunny");
    let mut reordered = file_order.clone();
    reordered.reorder_for_locality();
    (reordered, file_order)
}

fn scenes<'a>(reordered: &'a IndexedMesh, file_order: &'a IndexedMesh) -> Vec<Scene<'a>> {
    vec![
        Scene::new("bunny", reordered, 640, 480),
        Scene::new("bunny", reordered, 320, 240),
        Scene::new("bunny_file_order", file_order, 640, 480),
    ]
}

fn bunny(c: &mut Criterion) {
    let (reordered, file_order) = meshes();
    for mut scene in scenes(&reordered, &file_order) {
        let mut group = c.benchmark_group(scene.name.clone());
        group.throughput(Throughput::Elements(scene.triangles as u64));
        group.sample_size(40);
        group.bench_function("vdlod", |b| b.iter(|| scene.vdlod()));
        group.bench_function("euc", |b| b.iter(|| scene.euc()));
        group.finish();
    }
}

/// Rows per band of the banded draw.
const BAND_ROWS: usize = 16;

/// The frame drawn as a device draws it: shaded once, binned by row, and drawn band by band
/// through one buffer of `BAND_ROWS` rows (the whole frame's pixel and depth types, so that only
/// the banding differs).
struct Bands {
    color: Vec<Rgba8>,
    depth: Vec<u32>,
    scratch: Vec<ShadedVertex>,
    bins: Vec<u32>,
}

impl Bands {
    fn new(mesh: &IndexedMesh, width: usize) -> Bands {
        Bands {
            color: vec![BACKGROUND; width * BAND_ROWS],
            depth: vec![0; width * BAND_ROWS],
            scratch: vec![ShadedVertex::default(); mesh.positions.len()],
            bins: vec![0; 3 * mesh.triangles.len() + 64],
        }
    }

    fn draw(&mut self, scene: &Scene<'_>) {
        let (w, h) = (scene.frame.width(), scene.frame.height());
        let shaded = shade(&scene.mesh, &scene.params, w, h, &mut self.scratch).expect("shades");
        let binned = shaded.bin(BAND_ROWS, &mut self.bins).expect("bins");
        for band in Window::bands(w, h, BAND_ROWS) {
            let mut t =
                Target::window(&mut self.color, &mut self.depth, w, h, band, w).expect("band");
            t.clear(BACKGROUND);
            black_box(binned.draw(&mut t).expect("draws"));
            black_box(t.color());
        }
    }
}

/// Frames of the two renderers alternated, so that both see the same machine: this shared machine
/// changes speed by tens of percent from one second to the next, which criterion's back-to-back
/// groups cannot separate from the renderers' own difference. The last line draws the 320x240
/// frame in bands of 16 rows (`euc` still draws it whole).
fn interleaved() {
    let (reordered, file_order) = meshes();
    println!("\ninterleaved, {ROUNDS} rounds of one frame each (milliseconds):");
    for mut scene in scenes(&reordered, &file_order) {
        let (name, triangles) = (scene.name.clone(), scene.triangles);
        compare(&name, triangles, |ours| match ours {
            true => scene.vdlod(),
            false => scene.euc(),
        });
    }
    let mut scene = Scene::new("bunny_bands16", &reordered, 320, 240);
    let mut bands = Bands::new(&reordered, 320);
    let (name, triangles) = (scene.name.clone(), scene.triangles);
    compare(&name, triangles, |ours| match ours {
        true => bands.draw(&scene),
        false => scene.euc(),
    });
}

const ROUNDS: usize = 200;

/// Times `ROUNDS` rounds of `frame(true)` (vdlod) and `frame(false)` (euc) in turn and prints
/// the minimums, medians and their ratios.
fn compare(name: &str, triangles: usize, mut frame: impl FnMut(bool)) {
    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    for _ in 0..ROUNDS {
        let t = Instant::now();
        frame(true);
        ours.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        frame(false);
        theirs.push(t.elapsed().as_secs_f64() * 1e3);
    }
    ours.sort_by(f64::total_cmp);
    theirs.sort_by(f64::total_cmp);
    let (om, tm) = (ours[ROUNDS / 2], theirs[ROUNDS / 2]);
    println!(
        "{:<26} vdlod min {:.3} median {:.3} | euc min {:.3} median {:.3} | euc/vdlod min {:.2}x median {:.2}x | Mtri/s at the median: vdlod {:.1}, euc {:.1}",
        name, ours[0], om, theirs[0], tm, theirs[0] / ours[0], tm / om,
        triangles as f64 / om / 1e3,
        triangles as f64 / tm / 1e3
    );
}

criterion_group!(benches, bunny);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    interleaved();
}
