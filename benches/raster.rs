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
//! Both renderers always get the same index buffer.
//!
//! Run: `cargo bench --bench raster`. Criterion prints the time per frame and, as throughput,
//! triangles per second (Melem/s); the ratio of the two is the speed-up.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use euc::{buffer::Buffer2d, rasterizer, Pipeline};
use vdlod_demo::camera::Orbit;
use vdlod_demo::frame::Frame;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::camera_params;
use vdlod_raster::{Light, Shading};

/// `euc` pipeline doing what our Gouraud mode does: per-vertex Lambert, interpolated colour.
struct Gouraud<'a> {
    mvp: vek::Mat4<f32>,
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    light: Light,
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
        let l = self.light.intensity(glam::Vec3::from(self.normals[i]));
        (clip.into_array(), vek::Vec3::from(self.base) * l)
    }

    #[inline(always)]
    fn frag(&self, c: &vek::Vec3<f32>) -> u32 {
        let ch = |v: f32| v.clamp(0.0, 255.0) as u32;
        0xff00_0000 | (ch(c.x) << 16) | (ch(c.y) << 8) | ch(c.z)
    }
}

fn bunny(c: &mut Criterion) {
    let file_order = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).expect("bundled bunny");
    let mut reordered = file_order.clone();
    reordered.reorder_for_locality();
    let runs = [
        ("bunny", &reordered, 640usize, 480usize),
        ("bunny", &reordered, 320, 240),
        ("bunny_file_order", &file_order, 640, 480),
    ];
    for (name, mesh, w, h) in runs {
        let camera = Orbit::peer(&mesh.bounds(), 12).camera(1); // azimuth 30 degrees
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let mut group = c.benchmark_group(format!("{name}_{w}x{h}"));
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        group.sample_size(40);

        let params = camera_params(&camera, w as f32 / h as f32, Shading::Gouraud, false);
        let mut frame = Frame::new(w, h).expect("frame");
        let raster_mesh = mesh.as_raster_mesh();
        group.bench_function("vdlod", |b| {
            b.iter(|| frame.draw(&raster_mesh, &params).expect("draw"))
        });

        let pipe = Gouraud {
            mvp: vek::Mat4::from_col_array(params.mvp.to_cols_array()),
            positions: &mesh.positions,
            normals: &mesh.normals,
            light: params.light,
            base: params.base_color.map(|c| c as f32),
        };
        let mut color = Buffer2d::new([w, h], 0u32);
        let mut depth = Buffer2d::new([w, h], 1.0f32);
        group.bench_function("euc", |b| {
            b.iter(|| {
                euc::Target::clear(&mut color, 0);
                euc::Target::clear(&mut depth, 1.0);
                pipe.draw::<rasterizer::Triangles<_>, _>(&indices, &mut color, Some(&mut depth));
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bunny);
criterion_main!(benches);
