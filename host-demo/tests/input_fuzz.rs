//! The mesh readers and the repair pass take untrusted bytes: whatever they are, the result is a
//! mesh the hierarchy builder accepts, or an error; never a panic.

use proptest::prelude::*;
use vdlod_core::build::{build, rotate_to_min, validate, BuildOptions, InputMesh};
use vdlod_demo::input::Soup;
use vdlod_demo::mesh::{load_bytes, load_obj_bytes, IndexedMesh, LoadOptions};
use vdlod_demo::repair::repair;

/// Whether the builder accepts `m`.
fn buildable(m: &IndexedMesh) -> bool {
    validate(&InputMesh {
        positions: &m.positions,
        colors: m.colors.as_deref(),
        triangles: &m.triangles,
    })
    .is_ok()
}

/// A tetrahedron in each binary format, and OFF, to corrupt.
fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let p = [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let t = [[0u32, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n\
        property float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for c in p.iter().flatten() {
        ply.extend(c.to_le_bytes());
    }
    for tri in t {
        ply.push(3);
        for i in tri {
            ply.extend((i as i32).to_le_bytes());
        }
    }
    let mut stl = vec![b' '; 80];
    stl.extend(4u32.to_le_bytes());
    for tri in t {
        stl.extend([0u8; 12]);
        for i in tri {
            for c in p[i as usize] {
                stl.extend(c.to_le_bytes());
            }
        }
        stl.extend([0u8; 2]);
    }
    let off =
        b"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n".to_vec();
    vec![("t.ply", ply), ("t.stl", stl), ("t.off", off)]
}

/// Lines that look like OBJ, with hostile numbers, so the parser gets past its first checks.
fn obj_line() -> impl Strategy<Value = String> {
    let num = prop_oneof![
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("1e39".to_string()),
        any::<f32>().prop_map(|v| v.to_string()),
        (-5i64..5).prop_map(|v| v.to_string()),
    ];
    let idx = prop_oneof![
        (-6i64..12).prop_map(|v| v.to_string()),
        Just("1/2/3".to_string()),
        Just("//".to_string()),
    ];
    prop_oneof![
        prop::collection::vec(num.clone(), 0..7).prop_map(|v| format!("v {}", v.join(" "))),
        prop::collection::vec(idx, 0..6).prop_map(|v| format!("f {}", v.join(" "))),
        prop::collection::vec(num, 0..4).prop_map(|v| format!("vn {}", v.join(" "))),
        Just("o part".to_string()),
        Just("usemtl x".to_string()),
        Just("l 1 2".to_string()),
        ".{0,12}",
    ]
}

/// The `mesh` fuzz target starts from `fuzz/seeds/mesh`, whose first byte picks the name the rest
/// is read under (as the target does): every seed must load, or the fuzzer would start from errors.
#[test]
fn the_fuzz_seeds_load() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds/mesh");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 6, "{paths:?}");
    for path in paths {
        let data = std::fs::read(&path).unwrap();
        let (&pick, bytes) = data.split_first().unwrap();
        let name = ["f.obj", "f.off", "f.ply", "f.stl"][pick as usize % 4];
        match load_bytes(name, bytes, &LoadOptions::default()) {
            Ok(loaded) => assert!(buildable(&loaded.mesh), "{}", path.display()),
            Err(e) => panic!("{}: {e}", path.display()),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn random_bytes_under_any_name_give_a_buildable_mesh_or_an_error(
        bytes in prop::collection::vec(any::<u8>(), 0..256),
        name in prop_oneof![Just("x.obj"), Just("x.off"), Just("x.ply"), Just("x.stl"), Just("x")],
        strict in any::<bool>(),
    ) {
        let options = LoadOptions { repair: !strict, ..LoadOptions::default() };
        if let Ok(loaded) = load_bytes(name, &bytes, &options) {
            prop_assert!(buildable(&loaded.mesh));
        }
    }

    #[test]
    fn corrupted_and_truncated_files_give_a_buildable_mesh_or_an_error(
        which in 0usize..3,
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..4),
        keep in any::<prop::sample::Index>(),
    ) {
        let (name, mut bytes) = valid_files().swap_remove(which);
        for (at, value) in flips {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        bytes.truncate(keep.index(bytes.len() + 1));
        if let Ok(loaded) = load_bytes(name, &bytes, &LoadOptions::default()) {
            prop_assert!(buildable(&loaded.mesh));
        }
    }

    #[test]
    fn any_triangle_soup_repairs_to_a_buildable_mesh(
        points in prop::collection::vec((0u8..4, 0u8..4, 0u8..3), 3..24),
        triangles in prop::collection::vec((0u32..24, 0u32..24, 0u32..24), 1..40),
    ) {
        // Few distinct points, so that welds, repeats, fins, bow ties and flips are common.
        let n = points.len() as u32;
        let soup = Soup {
            positions: points.iter().map(|&(x, y, z)| [x as f32, y as f32, z as f32 * 0.5]).collect(),
            colors: None,
            triangles: triangles.iter().map(|&(a, b, c)| [a % n, b % n, c % n]).collect(),
        };
        let (mesh, repairs) = repair(soup.clone());
        prop_assert!(mesh.triangles.len() <= soup.triangles.len());
        prop_assert_eq!(
            mesh.triangles.len() + repairs.degenerate + repairs.duplicate,
            soup.triangles.len()
        );
        if !mesh.triangles.is_empty() {
            let input = InputMesh { positions: &mesh.positions, colors: None, triangles: &mesh.triangles };
            prop_assert_eq!(validate(&input), Ok(()), "{}", repairs);
            // Both engines (the heap's, and the balanced forest's passes) take what the repair
            // gives (flat, folded, coincident corners) and make a forest that replays to it.
            let mut expected: Vec<[u32; 3]> = mesh.triangles.iter().map(|&t| rotate_to_min(t)).collect();
            expected.sort_unstable();
            for balanced in [false, true] {
                let opts = BuildOptions { balanced, ..BuildOptions::default() };
                let h = build(&input, &opts, &mut |_| {});
                prop_assert!(h.is_ok(), "balanced {}: {:?}", balanced, h.err());
                let h = h.unwrap();
                let mut replayed = h.refine_all();
                replayed.sort_unstable();
                prop_assert_eq!(&replayed, &expected, "balanced {}", balanced);
                let mut base = h.collapse_all(&mesh.triangles);
                base.sort_unstable();
                let mut kept: Vec<[u32; 3]> = h.base_triangles.iter().map(|&t| rotate_to_min(t)).collect();
                kept.sort_unstable();
                prop_assert_eq!(base, kept, "balanced {}", balanced);
            }
        }
        // Deterministic.
        prop_assert_eq!(repair(soup).0, mesh);
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..256)) {
        let _ = load_obj_bytes("fuzz.obj", &bytes);
    }

    #[test]
    fn obj_like_text_gives_a_valid_mesh_or_an_error(lines in prop::collection::vec(obj_line(), 0..16)) {
        let text = lines.join("\n");
        if let Ok(mesh) = load_obj_bytes("fuzz.obj", text.as_bytes()) {
            let n = mesh.positions.len() as u32;
            prop_assert!(!mesh.triangles.is_empty());
            prop_assert!(mesh.triangles.iter().flatten().all(|&i| i < n));
            prop_assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
            prop_assert_eq!(mesh.normals.len(), mesh.positions.len());
        }
    }
}
