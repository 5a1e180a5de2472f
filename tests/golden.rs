//! Golden frames: the demo's renders compared bit for bit with PNGs under `fixtures/golden/`.
//!
//! After an intended change to what a frame looks like, regenerate them with
//!
//! ```text
//! VDLOD_BLESS=1 cargo test --test golden
//! ```
//!
//! and look at the new PNGs before committing them. A mismatch writes the frame actually rendered
//! to `target/golden-actual/NAME.png` for comparison.

use std::path::PathBuf;

use vdlod_demo::frame::{load_png, save_png, Frame};
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ, COW_NAME, COW_OBJ};
use vdlod_demo::render::{camera_params, render_orbit_frame, style, RenderOptions};
use vdlod_raster::{
    draw_indexed, Pixel, Rgb565, Rgba8, ShadedVertex, Shading, Target, DEPTH_CLEAR,
};

const W: usize = 320;
const H: usize = 240;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bunny() -> IndexedMesh {
    let mut m = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
    m.reorder_for_locality();
    m
}

fn cow() -> IndexedMesh {
    load_obj_bytes(COW_NAME, COW_OBJ).unwrap()
}

/// Compares `pixels` with `fixtures/golden/NAME.png`, or writes it when blessing.
fn check(name: &str, pixels: &[Rgba8]) {
    let path = root().join("fixtures/golden").join(format!("{name}.png"));
    if std::env::var_os("VDLOD_BLESS").is_some() {
        save_png(&path, W, H, pixels).unwrap();
        return;
    }
    let (w, h, expected) = load_png(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; regenerate with VDLOD_BLESS=1 cargo test --test golden",
            path.display()
        )
    });
    assert_eq!((w, h), (W, H), "{name}: golden frame has another size");
    let differing = expected.iter().zip(pixels).filter(|(a, b)| a != b).count();
    if differing > 0 {
        let dir = root().join("target/golden-actual");
        std::fs::create_dir_all(&dir).unwrap();
        save_png(&dir.join(format!("{name}.png")), W, H, pixels).unwrap();
        panic!(
            "{name}: {differing} of {} pixels differ from {} (actual frame in {})",
            W * H,
            path.display(),
            dir.display()
        );
    }
}

fn orbit_frame(mesh: &IndexedMesh, index: u32, opts: &RenderOptions) -> Vec<Rgba8> {
    let mut frame = Frame::new(W, H).unwrap();
    render_orbit_frame(&mut frame, mesh, index, opts).unwrap();
    frame.pixels().to_vec()
}

fn small(shading: Shading, wireframe: bool) -> RenderOptions {
    RenderOptions {
        width: W,
        height: H,
        frames: 36,
        shading,
        wireframe,
    }
}

#[test]
fn bunny_orbit_gouraud() {
    let mesh = bunny();
    for i in [0, 9, 22] {
        check(
            &format!("bunny_gouraud_{i:02}"),
            &orbit_frame(&mesh, i, &small(Shading::Gouraud, false)),
        );
    }
}

#[test]
fn cow_flat_with_wireframe() {
    check(
        "cow_flat_wire",
        &orbit_frame(&cow(), 5, &small(Shading::Flat, true)),
    );
}

/// Per-triangle colour override (what later shows hierarchy depth), into a 16-bit RGB565 target.
#[test]
fn cow_face_colors_rgb565() {
    let mesh = cow();
    let palette = [[230, 80, 60], [80, 170, 90], [70, 110, 220], [230, 200, 70]];
    let face_colors: Vec<[u8; 3]> = (0..mesh.triangles.len())
        .map(|t| palette[(t / 64) % palette.len()])
        .collect();
    let raster_mesh = vdlod_raster::Mesh {
        face_colors: Some(&face_colors),
        ..mesh.as_raster_mesh()
    };
    let orbit = vdlod_demo::camera::merge_tree_orbit(&mesh.bounds(), 36, W, H);
    let params = camera_params(&orbit.camera(30), Shading::Gouraud, false);
    let mut color = vec![Rgb565(0); W * H];
    let mut depth = vec![DEPTH_CLEAR; W * H];
    let mut target = Target::new(&mut color, &mut depth, W, H).unwrap();
    target.clear(Rgb565::from_rgb(24, 26, 32));
    let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
    draw_indexed(&mut target, &raster_mesh, &params, &mut scratch).unwrap();
    let pixels: Vec<Rgba8> = color
        .iter()
        .map(|p| {
            let [r, g, b] = p.to_rgb();
            Rgba8([r, g, b, 255])
        })
        .collect();
    check("cow_faces_rgb565", &pixels);
}

#[test]
fn frames_are_identical_from_run_to_run() {
    let mesh = cow();
    let opts = small(Shading::Gouraud, true);
    assert_eq!(orbit_frame(&mesh, 3, &opts), orbit_frame(&mesh, 3, &opts));
}

/// Frames `indices` of the peer orbit flown by a cut of the bunny (1 px, geomorphs over 4
/// frames), optionally in false colour by forest depth.
fn lod_frames(indices: &'static [u32], depth: bool) -> Vec<Vec<Rgba8>> {
    use vdlod_core::adapt::Budget;
    use vdlod_core::cut::{Coloring, Cut};
    use vdlod_core::format::HierarchyView;
    use vdlod_core::policy::{BackFace, Frustum, ScreenError};
    use vdlod_demo::camera::peer_orbit;
    {
        let mesh = bunny();
        let (_, bytes, _) =
            vdlod_demo::hierarchy::build_with_progress(&mesh, &Default::default(), false).unwrap();
        let h = HierarchyView::parse(&bytes).unwrap();
        let mut cut = Cut::<32_000, 64_000, 4_000>::boxed();
        cut.set_coloring(if depth {
            Coloring::Depth
        } else {
            Coloring::Node
        });
        cut.reset(&h).unwrap();
        cut.set_geomorph_frames(4);
        let orbit = peer_orbit(&mesh.bounds(), 36, W, H);
        let mut frame = Frame::new(W, H).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(1.0)));
        let mut out = Vec::new();
        for i in 0..=*indices.iter().max().unwrap() {
            let camera = orbit.camera(i);
            vdlod::adapt(&mut cut, &h, &camera, &policy, &Budget::default()).unwrap();
            if indices.contains(&i) {
                let style = vdlod::Style {
                    vertex_colors: depth,
                    ..style(Shading::Gouraud, false)
                };
                frame.draw_cut(&cut, &h, &camera, &style).unwrap();
                out.push(frame.pixels().to_vec());
            }
        }
        out
    }
}

#[test]
fn bunny_cut_over_the_peer_orbit() {
    for (k, pixels) in lod_frames(&[0, 5, 20], false).iter().enumerate() {
        check(&format!("bunny_cut_{k}"), pixels);
    }
}

#[test]
fn bunny_cut_in_depth_colours() {
    check("bunny_cut_depth", &lod_frames(&[12], true)[0]);
}

/// The bunny's cut drawn the way a device draws it: 320x16 bands of Rgb565 with 16-bit depth,
/// through `vdlod::draw_bands`, stitched.
#[test]
fn bunny_cut_in_bands_rgb565_u16_depth() {
    use vdlod::prelude::*;
    use vdlod_demo::camera::peer_orbit;
    let mesh = bunny();
    let (_, bytes, _) =
        vdlod_demo::hierarchy::build_with_progress(&mesh, &Default::default(), false).unwrap();
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut = Cut::<2508, 5000, 313>::boxed();
    cut.reset(&h).unwrap();
    cut.set_geomorph_frames(4);
    let orbit = peer_orbit(&mesh.bounds(), 36, W, H);
    let budget = Budget {
        max_triangles: 5000,
        ..Budget::default()
    };
    let mut scratch = vec![ShadedVertex::default(); 2508];
    let (mut color, mut depth) = (vec![Rgb565(0); W * 16], vec![0u16; W * 16]);
    let mut pixels = Vec::with_capacity(W * H);
    let mut bins = vec![0u32; 5000]; // row bins only, as on the device
    for i in 0..=7 {
        let camera = orbit.camera(i);
        vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(1.0), &budget).unwrap();
        if i < 7 {
            continue;
        }
        let bands = Bands {
            color: &mut color,
            depth: &mut depth,
            rows: 16,
            background: Rgb565::from_rgb(24, 26, 32),
            bins: &mut bins,
        };
        let style = vdlod_demo::render::style(Shading::Gouraud, false);
        vdlod::draw_bands(bands, &cut, &h, &camera, &style, &mut scratch, |band| {
            pixels.extend(band.color().iter().map(|p| {
                let [r, g, b] = p.to_rgb();
                Rgba8([r, g, b, 255])
            }))
        })
        .unwrap();
    }
    check("bunny_cut_bands_rgb565_u16", &pixels);
}

/// The wavelet engine's cut of the 2,048-face sphere (an octahedron subdivided four times) at
/// the paper's Fig. 11 tolerances, drawn whole with its edges, and drawn again in 16-row bands
/// through the same `draw_mesh_bands` a device uses: the bands are the same pixels. The file,
/// its bounds and the cut are made here, so this checks the builder too.
#[test]
fn sphere_wavelet_cut() {
    use vdlod::prelude::*;
    use vdlod_core::wavelet::build::SemiRegular;
    let bytes = SemiRegular::sphere(4).unwrap().to_bytes().unwrap();
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = WaveletCut::<64, 4096, 2100, 512>::boxed();
    cut.reset(&s).unwrap();
    let camera = Camera {
        eye: glam::Vec3::new(0.4, 0.5, 2.6),
        target: glam::Vec3::new(0.5, 0.0, 0.0),
        up: glam::Vec3::Y,
        fov_y: 0.8,
        near: 0.1,
        far: 10.0,
        width: W,
        height: H,
    };
    let policy = QRefine {
        error: ScreenError {
            silhouette: 0.5,
            interior: 3.5,
        },
    };
    let stats = vdlod::adapt_wavelets(&mut cut, &s, &camera, &policy, &Budget::default()).unwrap();
    assert!(stats.triangles > 100 && stats.triangles < 2048, "{stats:?}");
    let style = Style {
        wireframe: Some([30, 30, 30]),
        ..Style::default()
    };
    let mesh = WaveletMesh::new(&cut, &s, false);
    let mut frame = Frame::new(W, H).unwrap();
    frame.draw_styled(&mesh, &camera, &style).unwrap();
    let whole = frame.pixels().to_vec();
    check("sphere_wavelet_cut", &whole);

    let (mut color, mut depth) = (vec![Rgba8([0; 4]); W * 16], vec![0u32; W * 16]);
    let mut bins = vec![0u32; 8192]; // rows and band lists
    let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
    let bands = Bands {
        color: &mut color,
        depth: &mut depth,
        rows: 16,
        background: vdlod_demo::frame::BACKGROUND,
        bins: &mut bins,
    };
    let mut stitched = Vec::with_capacity(W * H);
    vdlod::draw_mesh_bands(bands, &mesh, &camera, &style, &mut scratch, |band| {
        stitched.extend_from_slice(band.color())
    })
    .unwrap();
    assert!(stitched == whole, "bands differ from the whole frame");
}
