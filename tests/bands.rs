//! Band and tile rendering: a frame drawn window by window through small buffers, stitched, is
//! bit-identical to the frame drawn whole, with `u32` and `u16` depth, clipping and wireframe.

mod common;

use common::coordinate;
use glam::{Mat4, Vec3};
use proptest::prelude::*;
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ};
use vdlod_raster::{
    draw_indexed, shade, Depth, DrawError, DrawParams, DrawStats, Mesh, Rgb565, Rgb565Be, Rgba8,
    ShadedVertex, Shading, Target, TargetError, Window,
};

const W: usize = 160;
const H: usize = 120;
const BG: Rgba8 = Rgba8([10, 20, 30, 255]);

/// The bunny standing on a floor that runs under the camera (so many triangles cross the near
/// plane and are clipped), seen from low and close.
fn scene() -> (IndexedMesh, Mat4) {
    let mut m = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
    let b = m.bounds();
    let base = m.positions.len() as u32;
    let (y, r) = (b.min.y, b.radius() * 6.0);
    let c = b.center();
    let n = 12;
    for j in 0..=n {
        for i in 0..=n {
            let t = |k: u32| (k as f32 / n as f32 - 0.5) * 2.0 * r;
            m.positions.push([c.x + t(i), y, c.z + t(j)]);
            m.normals.push([0.0, 1.0, 0.0]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |i: u32, j: u32| base + j * (n + 1) + i;
            m.triangles.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
            m.triangles.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
        }
    }
    let eye = c + Vec3::new(0.3, -0.2, 1.6) * b.radius() * 1.6;
    let mvp = Mat4::perspective_rh(1.1, W as f32 / H as f32, b.radius() * 0.02, r * 4.0)
        * Mat4::look_at_rh(eye, c, Vec3::Y);
    (m, mvp)
}

fn params(mvp: Mat4, wireframe: bool) -> DrawParams {
    DrawParams {
        mvp,
        shading: Shading::Gouraud,
        unit_normals: true,
        wireframe: wireframe.then_some([250, 40, 40]),
        ..DrawParams::default()
    }
}

fn whole<D: Depth>(mesh: &Mesh<'_>, params: &DrawParams) -> (Vec<Rgba8>, Vec<D>, DrawStats) {
    let mut color = vec![BG; W * H];
    let mut depth = vec![D::CLEAR; W * H];
    let mut target = Target::new(&mut color, &mut depth, W, H).unwrap();
    let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
    let stats = draw_indexed(&mut target, mesh, params, &mut scratch).unwrap();
    (color, depth, stats)
}

fn whole_stats(mesh: &Mesh<'_>, params: &DrawParams) -> DrawStats {
    whole::<u32>(mesh, params).2
}

/// How a windowed draw finds each window's triangles.
#[derive(Clone, Copy, Debug)]
enum Bins {
    /// Every window reads every triangle.
    None,
    /// Row bins only (one entry per triangle).
    Rows,
    /// Bins for bands of this many rows, with `entries` in all.
    Lists { band_rows: usize, entries: usize },
}

impl Bins {
    /// Bins for bands of `band_rows` rows with room to spare for the lists.
    fn ample(mesh: &Mesh<'_>, band_rows: usize) -> Bins {
        let entries = 8 * mesh.triangles.len() + H.div_ceil(band_rows) + 1;
        Bins::Lists { band_rows, entries }
    }
}

/// Draws the frame window by window through one buffer of `stride * rows` entries (with padding
/// columns that must stay untouched), shading once, and stitches the windows. Also says whether
/// the bins held band lists.
fn windowed<D: Depth>(
    mesh: &Mesh<'_>,
    params: &DrawParams,
    windows: &[Window],
    stride: usize,
    bins: Bins,
) -> (Vec<Rgba8>, Vec<D>, bool) {
    let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
    let (band_rows, entries) = match bins {
        Bins::None => (1, 0),
        Bins::Rows => (16, mesh.triangles.len()),
        Bins::Lists { band_rows, entries } => (band_rows, entries),
    };
    let mut space = vec![0u32; entries];
    let shaded = shade(mesh, params, W, H, &mut scratch).unwrap();
    let binned = (entries > 0).then(|| shaded.bin(band_rows, &mut space).unwrap());
    let listed = binned.is_some_and(|b| b.has_band_lists());
    let rows = windows.iter().map(|w| w.height).max().unwrap();
    let (mut color, mut depth) = (vec![BG; W * H], vec![D::CLEAR; W * H]);
    let sentinel = Rgba8([1, 2, 3, 4]);
    let mut stats = None;
    for &w in windows {
        let mut c = vec![sentinel; stride * rows];
        let mut d = vec![D::CLEAR; stride * rows];
        let len = (w.height - 1) * stride + w.width;
        for y in 0..w.height {
            c[y * stride..y * stride + w.width].fill(BG);
        }
        let mut target = Target::window(&mut c[..len], &mut d[..len], W, H, w, stride).unwrap();
        let s = match &binned {
            Some(b) => b.draw(&mut target).unwrap(),
            None => shaded.draw(&mut target).unwrap(),
        };
        // Every window reports the whole frame's statistics.
        assert_eq!(*stats.get_or_insert(s), s, "window {w:?}");
        assert_eq!(s, whole_stats(mesh, params), "window {w:?}");
        for y in 0..w.height {
            for x in 0..stride {
                let (src, dst) = (y * stride + x, (w.y + y) * W + w.x + x);
                if x < w.width {
                    color[dst] = c[src];
                    depth[dst] = d[src];
                } else if src < len {
                    assert_eq!(c[src], sentinel, "padding written in window {w:?}");
                }
            }
        }
    }
    (color, depth, listed)
}

#[test]
fn bands_stitch_to_the_whole_frame() {
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    for wire in [false, true] {
        let p = params(mvp, wire);
        let (color, depth, stats) = whole::<u32>(&mesh, &p);
        assert!(stats.clipped > 0 && stats.rasterized > 10_000, "{stats:?}");
        assert!(color.iter().filter(|&&c| c != BG).count() > W * H / 3);
        for rows in [1, 7, 16, 40, H] {
            let bands: Vec<Window> = Window::bands(W, H, rows).collect();
            // Lists for these bands, for bands of 16 rows (windows within a band read its
            // list, the others scan the rows), row bins, none.
            let bins = [
                Bins::ample(&mesh, rows),
                Bins::ample(&mesh, 16),
                Bins::Rows,
                Bins::None,
            ];
            for stride in [W, W + 3] {
                for bins in bins {
                    let (c, d, listed) = windowed::<u32>(&mesh, &p, &bands, stride, bins);
                    let case = format!("rows {rows}, stride {stride}, wire {wire}, {bins:?}");
                    assert_eq!(listed, matches!(bins, Bins::Lists { .. }), "{case}");
                    assert!(c == color, "{case}");
                    assert!(d == depth, "{case}");
                }
            }
        }
    }
}

/// Bins of every size the layouts switch at draw the same frame: row bins (one entry per
/// triangle), pairs without band lists (two per triangle and one per band plus one, or more
/// while the lists do not fit), and pairs with lists.
#[test]
fn bins_of_every_layout_draw_the_same_frame() {
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    // Back faces drawn too, and outlined: nearly every triangle meets a row.
    let p = DrawParams {
        cull_back_faces: false,
        ..params(mvp, true)
    };
    let (color, depth, _) = whole::<u32>(&mesh, &p);
    let n = mesh.triangles.len();
    for band_rows in [1, 16] {
        let bands: Vec<Window> = Window::bands(W, H, band_rows).collect();
        let pairs = 2 * n + bands.len() + 1;
        let draw =
            |entries| windowed::<u32>(&mesh, &p, &bands, W, Bins::Lists { band_rows, entries });
        let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
        let mut fits = |entries| {
            let shaded = shade(&mesh, &p, W, H, &mut scratch).unwrap();
            let mut space = vec![0u32; entries];
            shaded.bin(band_rows, &mut space).unwrap().has_band_lists()
        };
        // The fewest entries that hold the lists, by bisection (the answer is monotone).
        let (mut lo, mut hi) = (n, 8 * n);
        assert!(fits(hi) && !fits(lo));
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // Pairs without lists in between.
        assert!(
            lo >= pairs,
            "{lo} entries, pairs from {pairs}, {band_rows} rows"
        );
        for entries in [n, pairs - 1, pairs, lo, hi] {
            let (c, d, listed) = draw(entries);
            assert_eq!(listed, entries >= hi, "{entries} entries, {band_rows} rows");
            assert!(
                c == color && d == depth,
                "{entries} entries, {band_rows} rows"
            );
        }
    }
}

#[test]
fn tiles_stitch_to_the_whole_frame_with_16_bit_depth() {
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    let p = params(mvp, true);
    let (color, depth, _) = whole::<u16>(&mesh, &p);
    let mut tiles = Vec::new();
    for y in (0..H).step_by(32) {
        for x in (0..W).step_by(48) {
            tiles.push(Window {
                x,
                y,
                width: 48.min(W - x),
                height: 32.min(H - y),
            });
        }
    }
    for bins in [Bins::ample(&mesh, 32), Bins::Rows, Bins::None] {
        let (c, d, _) = windowed::<u16>(&mesh, &p, &tiles, 50, bins);
        assert!(c == color && d == depth, "{bins:?}");
    }
}

#[test]
fn sixteen_bit_depth_draws_the_same_surface() {
    // The top 16 of 24 depth bits resolve this scene's surfaces: the frames agree but for a few
    // pixels where nearly coplanar surfaces tie.
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    let p = params(mvp, false);
    let (c32, _, s32) = whole::<u32>(&mesh, &p);
    let (c16, _, s16) = whole::<u16>(&mesh, &p);
    assert_eq!(s32, s16);
    let differing = c32.iter().zip(&c16).filter(|(a, b)| a != b).count();
    assert!(differing < W * H / 200, "{differing} pixels differ");
}

#[test]
fn byte_swapped_rgb565_is_rgb565_with_its_bytes_swapped() {
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    let p = params(mvp, true);
    let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
    let shaded = shade(&mesh, &p, W, H, &mut scratch).unwrap();
    let mut native = vec![Rgb565(0); W * H];
    let mut swapped = vec![Rgb565Be([0; 2]); W * H];
    let mut depth = vec![0u16; W * H];
    let mut t = Target::new(&mut native, &mut depth, W, H).unwrap();
    t.clear(Rgb565(0x1234));
    shaded.draw(&mut t).unwrap();
    let mut t = Target::new(&mut swapped, &mut depth, W, H).unwrap();
    t.clear(Rgb565(0x1234).into());
    shaded.draw(&mut t).unwrap();
    assert!(native.iter().any(|c| c.0 != 0x1234));
    for (n, s) in native.iter().zip(&swapped) {
        assert_eq!(n.0.to_be_bytes(), s.0);
    }
}

#[test]
fn bad_windows_and_frames_are_typed_errors() {
    let (m, mvp) = scene();
    let mesh = m.as_raster_mesh();
    let p = params(mvp, false);
    let mut scratch = vec![ShadedVertex::default(); mesh.positions.len()];
    assert_eq!(
        shade(&mesh, &p, 0, H, &mut scratch).err(),
        Some(DrawError::Frame(TargetError::ZeroSize))
    );
    let mut bins = vec![0u32; mesh.triangles.len() - 1];
    let shaded = shade(&mesh, &p, W, H, &mut scratch).unwrap();
    assert_eq!(
        shaded.bin(0, &mut bins).err(),
        Some(DrawError::Frame(TargetError::ZeroSize))
    );
    assert_eq!(
        shaded.bin(16, &mut bins).err(),
        Some(DrawError::BinsTooSmall {
            needed: mesh.triangles.len(),
            available: mesh.triangles.len() - 1
        })
    );
    let shaded = shade(&mesh, &p, W, H, &mut scratch).unwrap();
    let mut c = vec![Rgba8::default(); W * 16];
    let mut d = vec![0u32; W * 16];
    let band = Window {
        x: 0,
        y: 0,
        width: W,
        height: 0,
    };
    assert_eq!(
        Target::window(&mut c, &mut d, W, H, band, W).err(),
        Some(TargetError::ZeroSize)
    );
    let band = Window { height: 16, ..band };
    assert_eq!(
        Target::window(&mut c, &mut d, W, H, band, W - 1).err(),
        Some(TargetError::StrideTooShort {
            stride: W - 1,
            width: W
        })
    );
    assert_eq!(
        Target::window(&mut c[..W * 15], &mut d, W, H, band, W).err(),
        Some(TargetError::ColorLength {
            expected: W * 16,
            actual: W * 15
        })
    );
    // A target for a frame of another size.
    let mut t = Target::window(&mut c, &mut d, W, H + 1, band, W).unwrap();
    assert_eq!(
        shaded.draw(&mut t).err(),
        Some(DrawError::FrameMismatch {
            shaded: (W, H),
            target: (W, H + 1)
        })
    );
}

/// A band steps over a run of triangles that draw nothing in one go; a run longer than a bin
/// entry can count (back faces, a triangle between pixel centres, and one off screen, 70,000 in
/// all) is stepped over in parts, and the triangles around it are drawn as in the whole frame.
#[test]
fn long_runs_of_empty_triangles_are_skipped_exactly() {
    let positions = [
        [-0.9, -0.9, 0.5],
        [0.9, -0.9, 0.5],
        [0.0, 0.9, 0.5],
        [0.001, 0.001, 0.2],
        [0.002, 0.001, 0.2],
        [0.001, 0.002, 0.2],
        [5.0, 5.0, 0.5],
        [6.0, 5.0, 0.5],
        [5.0, 6.0, 0.5],
        [-0.5, -0.5, 0.3],
        [0.5, -0.5, 0.3],
        [0.0, 0.5, 0.3],
    ];
    let normals = [[0.0, 0.0, 1.0]; 12];
    let (front, back, speck, away) = ([0u32, 1, 2], [0u32, 2, 1], [3u32, 4, 5], [6u32, 7, 8]);
    let mut triangles = vec![front];
    for k in 0..70_000 {
        triangles.push([back, speck, away][k % 3]);
    }
    triangles.push([9, 10, 11]);
    triangles.extend([back; 5]);
    let mesh = Mesh {
        positions: &positions,
        normals: Some(&normals),
        triangles: &triangles,
        ..Mesh::default()
    };
    let p = params(Mat4::IDENTITY, false);
    let (color, depth, stats) = whole::<u32>(&mesh, &p);
    assert_eq!(stats.rasterized, 2 + 70_000 / 3, "{stats:?}");
    assert!(color.iter().filter(|&&c| c != BG).count() > W * H / 4);
    for rows in [1, 16, H] {
        let bands: Vec<Window> = Window::bands(W, H, rows).collect();
        for bins in [Bins::ample(&mesh, rows), Bins::Rows] {
            let (c, d, listed) = windowed::<u32>(&mesh, &p, &bands, W, bins);
            assert_eq!(listed, matches!(bins, Bins::Lists { .. }), "rows {rows}");
            assert!(c == color && d == depth, "rows {rows}, {bins:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Any triangles, any camera, bands of any height and bins of every layout (row bins, pairs
    /// without lists, lists): no panic, and the bands stitch to the whole frame bit for bit.
    #[test]
    fn random_triangles_in_bands_stitch_to_the_whole_frame(
        pts in prop::collection::vec([coordinate(), coordinate(), coordinate()], 3..24),
        eye in [-4.0f32..4.0, -4.0f32..4.0, 0.5f32..6.0],
        wire in any::<bool>(),
        cull in any::<bool>(),
        band_rows in 1usize..=H,
        layout in 0usize..4,
    ) {
        let m = pts.len() as u32;
        let triangles: Vec<[u32; 3]> = (0..m - 2).map(|i| [i, i + 1, i + 2]).collect();
        let mesh = Mesh { positions: &pts, triangles: &triangles, ..Mesh::default() };
        let mvp = Mat4::perspective_rh(1.0, W as f32 / H as f32, 0.1, 50.0)
            * Mat4::look_at_rh(Vec3::from(eye), Vec3::ZERO, Vec3::Y);
        let p = DrawParams {
            mvp,
            shading: Shading::Flat,
            cull_back_faces: cull,
            wireframe: wire.then_some([250, 40, 40]),
            ..DrawParams::default()
        };
        let (color, depth, _) = whole::<u32>(&mesh, &p);
        let n = triangles.len();
        let bands: Vec<Window> = Window::bands(W, H, band_rows).collect();
        let pairs = 2 * n + bands.len() + 1;
        let entries = [n, pairs - 1, pairs, pairs + n * bands.len()][layout];
        let (c, d, listed) =
            windowed::<u32>(&mesh, &p, &bands, W, Bins::Lists { band_rows, entries });
        prop_assert!(listed || layout < 3);
        prop_assert!(c == color && d == depth);
    }
}

/// With every vertex inside the clipping volume, the triangle loops skip the outcodes; vertices
/// outside, used by no triangle, send the same triangles through the loops that read them: the
/// same frame, whole and in bands, and the same statistics.
#[test]
fn a_model_in_view_draws_as_with_vertices_outside() {
    let alone = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
    // The scene's bunny with the floor's vertices but not its triangles (the bunny's vertices
    // come first, so the triangles are the same).
    let (mut unused, mvp) = scene();
    unused.triangles.truncate(alone.triangles.len());
    let p = params(mvp, false);
    let outcodes = |m: &IndexedMesh| {
        let mut scratch = vec![ShadedVertex::default(); m.positions.len()];
        shade(&m.as_raster_mesh(), &p, W, H, &mut scratch).unwrap();
        scratch.iter().fold(0, |u, v| u | v.outcode)
    };
    assert_eq!(outcodes(&alone), 0, "the bunny is in view");
    assert_ne!(outcodes(&unused), 0, "the floor reaches behind the eye");
    let (with, without) = (unused.as_raster_mesh(), alone.as_raster_mesh());
    let (color, depth, stats) = whole::<u32>(&with, &p);
    assert!(stats.rasterized > 10_000 && stats.clipped == 0, "{stats:?}");
    let (c, d, s) = whole::<u32>(&without, &p);
    assert!(c == color && d == depth, "whole frame");
    assert_eq!(s, stats);
    let bands: Vec<Window> = Window::bands(W, H, 16).collect();
    for bins in [Bins::ample(&without, 16), Bins::Rows, Bins::None] {
        for mesh in [&with, &without] {
            let (c, d, _) = windowed::<u32>(mesh, &p, &bands, W, bins);
            assert!(c == color && d == depth, "{bins:?}");
        }
    }
}
