//! Hostile bytes into the demo's OBJ loader: a mesh or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = vdlod_demo::mesh::load_obj_bytes("fuzz.obj", data) {
        let n = mesh.positions.len() as u32;
        assert!(mesh.triangles.iter().flatten().all(|&i| i < n));
    }
});
