//! The OBJ loader takes untrusted bytes: whatever they are, it returns a mesh or an error.

use proptest::prelude::*;
use vdlod_demo::mesh::load_obj_bytes;

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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

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
