//! The remesher on the fixtures: every vertex on the input, the input's topology, no fold in
//! the map, and the distances `docs/remesher.md` reports (as regression bounds); hostile inputs
//! give typed errors.

mod common;

use common::{fixture, topology};
use proptest::prelude::*;
use vdlod_core::build::InputMesh;
use vdlod_core::remesh::{remesh, RemeshError, RemeshOptions};
use vdlod_core::wavelet::SemiRegularView;

fn input(mesh: &vdlod_demo::mesh::IndexedMesh) -> InputMesh<'_> {
    InputMesh {
        positions: &mesh.positions,
        colors: None,
        triangles: &mesh.triangles,
    }
}

#[test]
fn fixtures_remesh_onto_themselves() {
    // The goal at the default base (300 faces) and four levels: Hausdorff at most 1% and
    // RMS at most 0.1% of the diagonal.
    for name in ["head.obj", "fandisk.obj", "elk.obj", "cow.obj"] {
        let mesh = fixture(name);
        let options = RemeshOptions::default();
        let out = remesh(&input(&mesh), &options, &mut |_| {}).unwrap();
        let finest = out.mesh.finest_triangles();
        assert!(out.base_faces <= 300 && out.base_faces >= 290, "{name}");
        assert_eq!(finest.len(), out.base_faces as usize * 256, "{name}");
        assert_eq!(topology(&finest), topology(&mesh.triangles), "{name}");
        assert!(out.worst_weight > -1e-9, "{name}: a fold");
        let q = out.quality(&input(&mesh));
        assert!(q.rms < 0.001, "{name}: {q:?}");
        assert!(q.hausdorff < 0.01, "{name}: {q:?}");
        assert_eq!(q.flipped, 0, "{name}: {q:?}");
        // The relaxation leaves few slivers.
        assert!(
            q.shapes[..3].iter().sum::<u32>() * 10 < finest.len() as u32,
            "{name}: {q:?}"
        );
        // The file parses and says what it holds.
        let bytes = out.mesh.to_bytes().unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        assert_eq!(s.counts().base_faces, out.base_faces);
        assert_eq!(s.counts().levels, 4);
    }
}

#[test]
fn the_fish_base_has_no_fold() {
    // `reproduce fish` remeshes over about 200 base faces, where each base triangle spans more
    // of the input's bends: the same goals hold.
    for name in ["cow.obj", "elk.obj"] {
        let mesh = fixture(name);
        let options = RemeshOptions {
            base_faces: 200,
            levels: 4,
        };
        let out = remesh(&input(&mesh), &options, &mut |_| {}).unwrap();
        let q = out.quality(&input(&mesh));
        assert_eq!(q.flipped, 0, "{name}: {q:?}");
        assert!(q.hausdorff < 0.01 && q.rms < 0.001, "{name}: {q:?}");
    }
}

#[test]
fn a_mesh_with_holes_keeps_them() {
    let mesh = fixture("head.obj");
    let (_, loops) = topology(&mesh.triangles);
    assert!(loops > 0);
    let options = RemeshOptions {
        base_faces: 300,
        levels: 2,
    };
    let out = remesh(&input(&mesh), &options, &mut |_| {}).unwrap();
    assert_eq!(topology(&out.mesh.finest_triangles()).1, loops);
}

fn tetrahedron() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    (
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
}

#[test]
fn bad_inputs_are_named() {
    let (p, t) = tetrahedron();
    let mesh = InputMesh {
        positions: &p,
        colors: None,
        triangles: &t,
    };
    // A base as large as the input.
    let err = remesh(&mesh, &RemeshOptions::default(), &mut |_| {}).unwrap_err();
    assert!(matches!(err, RemeshError::BaseSize { .. }));
    assert!(
        err.to_string().contains("fewer than the input's 4"),
        "{err}"
    );
    // Inconsistent orientation: one triangle turned over.
    let mut flipped = t.clone();
    flipped[0] = [0, 1, 2];
    let mesh = InputMesh {
        triangles: &flipped,
        ..mesh
    };
    let err = remesh(&mesh, &RemeshOptions::default(), &mut |_| {}).unwrap_err();
    assert!(matches!(err, RemeshError::Input(_)), "{err}");
    // A NaN.
    let mut nan = p.clone();
    nan[2][1] = f32::NAN;
    let mesh = InputMesh {
        positions: &nan,
        colors: None,
        triangles: &t,
    };
    let err = remesh(&mesh, &RemeshOptions::default(), &mut |_| {}).unwrap_err();
    assert!(
        err.to_string().contains("NaN") || err.to_string().contains("finite"),
        "{err}"
    );
    // Too many levels for the format.
    let big = fixture("cow.obj");
    let options = RemeshOptions {
        base_faces: 200,
        levels: 13,
    };
    let err = remesh(&input(&big), &options, &mut |_| {}).unwrap_err();
    assert_eq!(err, RemeshError::Levels(13));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Any jitter of the cow's vertices, flat slivers and all: a remesh with no fold whose
    /// vertices lie on the input, or a typed error; never a panic.
    #[test]
    fn jittered_meshes_remesh_or_say_why(seed in any::<u64>(), amount in 0.0f32..0.02) {
        let mut mesh = fixture("cow.obj");
        let mut x = seed | 1;
        for p in mesh.positions.iter_mut() {
            for c in p.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *c += amount * ((x >> 40) as f32 / (1u64 << 24) as f32 - 0.5);
            }
        }
        let options = RemeshOptions { base_faces: 100, levels: 2 };
        match remesh(&input(&mesh), &options, &mut |_| {}) {
            Ok(out) => {
                prop_assert!(out.worst_weight > -1e-9);
                prop_assert_eq!(out.mesh.finest_triangles().len(), out.base_faces as usize * 16);
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}
