//! The facade's frame loop: bad cameras and band buffers are typed errors, and a frame drawn in
//! bands through `draw_bands` equals the same frame drawn whole through `draw`.

use vdlod::prelude::*;
use vdlod::{CameraError, FrameError};
use vdlod_core::build::{build, InputMesh};
use vdlod_raster::TargetError;

/// A bumpy sphere's hierarchy: enough splits for a cut that changes with the view.
fn hierarchy() -> Vec<u8> {
    let (rings, segments) = (24usize, 48usize);
    let mut positions = vec![[0.0f32, 1.0, 0.0]];
    for r in 1..rings {
        let theta = core::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * core::f32::consts::PI * s as f32 / segments as f32;
            let bump = 1.0 + 0.05 * libm::sinf(5.0 * phi) * libm::sinf(3.0 * theta);
            positions.push([
                bump * libm::sinf(theta) * libm::cosf(phi),
                bump * libm::cosf(theta),
                bump * libm::sinf(theta) * libm::sinf(phi),
            ]);
        }
    }
    positions.push([0.0, -1.0, 0.0]);
    let ring = |r: usize, s: usize| (1 + (r - 1) * segments + s % segments) as u32;
    let bottom = positions.len() as u32 - 1;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, ring(1, s + 1), ring(1, s)]);
        triangles.push([bottom, ring(rings - 1, s), ring(rings - 1, s + 1)]);
        for r in 1..rings - 1 {
            triangles.push([ring(r, s), ring(r, s + 1), ring(r + 1, s + 1)]);
            triangles.push([ring(r, s), ring(r + 1, s + 1), ring(r + 1, s)]);
        }
    }
    let input = InputMesh {
        positions: &positions,
        colors: None,
        triangles: &triangles,
    };
    build(&input, &Default::default(), &mut |_| {})
        .unwrap()
        .to_bytes(false)
}

#[test]
fn bands_through_the_facade_equal_the_whole_frame() {
    let bytes = hierarchy();
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut = Cut::<4096, 8192, 512>::boxed();
    cut.reset(&h).unwrap();
    let (center, radius) = h.bounding_sphere();
    let orbit = Orbit::peer(center.into(), radius, 12).viewport(96, 72);
    let style = Style {
        wireframe: Some([250, 30, 30]),
        ..Style::default()
    };
    for i in 0..4 {
        let camera = orbit.camera(i);
        let s = vdlod::adapt(
            &mut cut,
            &h,
            &camera,
            &QRefine::new(0.5),
            &Budget::default(),
        )
        .unwrap();
        assert!(s.triangles > 100, "{s:?}");
        let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
        let (mut color, mut depth) = (vec![Rgba8::default(); 96 * 72], vec![0u16; 96 * 72]);
        let mut whole = Target::new(&mut color, &mut depth, 96, 72).unwrap();
        whole.clear(Rgba8([1, 2, 3, 255]));
        let stats = vdlod::draw(&mut whole, &cut, &h, &camera, &style, &mut scratch).unwrap();
        {
            let mut rows = vec![0u32; 2 * cut.triangles().len() + 8];
            let (mut c, mut d) = (vec![Rgba8::default(); 96 * 10], vec![0u16; 96 * 10]);
            let bands = Bands {
                color: &mut c,
                depth: &mut d,
                rows: 10,
                background: Rgba8([1, 2, 3, 255]),
                bins: &mut rows,
            };
            let mut stitched = Vec::new();
            let banded = vdlod::draw_bands(bands, &cut, &h, &camera, &style, &mut scratch, |b| {
                for y in 0..b.area().height {
                    stitched.extend_from_slice(b.row(y));
                }
            })
            .unwrap();
            assert_eq!(banded, stats);
            assert!(stitched == color, "frame {i}");
        }
    }
}

#[test]
fn bad_cameras_and_band_buffers_are_typed_errors() {
    let bytes = hierarchy();
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut = Cut::<4096, 8192, 512>::boxed();
    cut.reset(&h).unwrap();
    let (center, radius) = h.bounding_sphere();
    let camera = Orbit::peer(center.into(), radius, 12)
        .viewport(64, 48)
        .camera(0);
    let zero = Camera { width: 0, ..camera };
    let policy = QRefine::new(1.0);
    let before = cut.triangles().len();
    assert_eq!(
        vdlod::adapt(&mut cut, &h, &zero, &policy, &Budget::default()).err(),
        Some(FrameError::Camera(CameraError::ZeroViewport))
    );
    assert_eq!(
        cut.triangles().len(),
        before,
        "a bad camera changes nothing"
    );
    let mut scratch = vec![ShadedVertex::default(); 4096];
    let (mut c, mut d) = (vec![Rgb565(0); 64 * 8], vec![0u16; 64 * 8]);
    let mut bins = vec![0u32; 8192];
    let mut bands = |rows: usize, len: usize, camera: &Camera| {
        let b = Bands {
            color: &mut c[..len],
            depth: &mut d[..len],
            rows,
            background: Rgb565(0),
            bins: &mut bins,
        };
        vdlod::draw_bands(b, &cut, &h, camera, &Style::default(), &mut scratch, |_| {}).err()
    };
    assert_eq!(
        bands(0, 64 * 8, &camera),
        Some(FrameError::Target(TargetError::ZeroSize))
    );
    assert_eq!(
        bands(8, 64 * 7, &camera),
        Some(FrameError::Target(TargetError::ColorLength {
            expected: 64 * 8,
            actual: 64 * 7
        }))
    );
    assert_eq!(
        bands(8, 64 * 8, &zero),
        Some(FrameError::Camera(CameraError::ZeroViewport))
    );
    let far = Camera {
        near: 2.0,
        far: 1.0,
        ..camera
    };
    assert_eq!(
        bands(8, 64 * 8, &far),
        Some(FrameError::Camera(CameraError::DepthRange {
            near: 2.0,
            far: 1.0
        }))
    );
    assert_eq!(bands(8, 64 * 8, &camera), None);
}
