//! Hostile bytes into the demo's mesh readers (OBJ, OFF, PLY, STL, found by content or by the
//! name's extension) and the repair pass: a mesh the builder accepts, or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vdlod_demo::mesh::{load_bytes, LoadOptions};

fuzz_target!(|data: &[u8]| {
    // The first byte picks the name, so each reader also sees what its content test rejects.
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let name = ["f.obj", "f.off", "f.ply", "f.stl"][pick as usize % 4];
    let strict = pick & 4 != 0;
    let options = LoadOptions {
        repair: !strict,
        ..LoadOptions::default()
    };
    if let Ok(loaded) = load_bytes(name, bytes, &options) {
        let m = &loaded.mesh;
        let input = vdlod_core::build::InputMesh {
            positions: &m.positions,
            colors: m.colors.as_deref(),
            triangles: &m.triangles,
        };
        assert_eq!(vdlod_core::build::validate(&input), Ok(()));
    }
});
