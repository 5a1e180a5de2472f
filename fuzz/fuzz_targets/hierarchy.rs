//! Hostile bytes into the hierarchy loader: an error or a consistent view, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vdlod_core::format::{HierarchyView, NONE};

fuzz_target!(|data: &[u8]| {
    if let Ok(view) = HierarchyView::parse(data) {
        for i in 0..view.nodes() {
            let n = view.node(i);
            assert!(n.parent == NONE || n.parent > i);
        }
        for p in view.leaves()..view.nodes() {
            let s = view.split(p);
            for d in s.dependencies.0..s.dependencies.1 {
                assert!(view.dependency(d) < view.nodes());
            }
        }
        for t in 0..view.base_triangles() {
            let _ = view.base_triangle(t);
        }
    }
});
