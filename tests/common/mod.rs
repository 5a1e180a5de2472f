//! Helpers shared by the workspace tests.
#![allow(dead_code)]

pub mod fly;

use vdlod_core::build::rotate_to_min;
use vdlod_demo::mesh::{load_obj, IndexedMesh};

/// A fixture mesh from `fixtures/`.
pub fn fixture(name: &str) -> IndexedMesh {
    load_obj(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures")
            .join(name),
    )
    .unwrap()
}

pub fn sorted(t: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut t: Vec<[u32; 3]> = t.iter().map(|&t| rotate_to_min(t)).collect();
    t.sort_unstable();
    t
}

/// Euler characteristic and number of border loops.
pub fn topology(triangles: &[[u32; 3]]) -> (i64, usize) {
    use std::collections::{BTreeMap, BTreeSet};
    let verts: BTreeSet<u32> = triangles.iter().flatten().copied().collect();
    let directed: BTreeSet<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    let undirected: BTreeSet<(u32, u32)> = directed
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    let border: BTreeMap<u32, u32> = directed
        .iter()
        .filter(|&&(a, b)| !directed.contains(&(b, a)))
        .map(|&(a, b)| (a, b))
        .collect();
    let mut seen = BTreeSet::new();
    let mut loops = 0;
    for &start in border.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let mut v = start;
        while seen.insert(v) {
            v = border[&v];
        }
    }
    let chi = verts.len() as i64 - undirected.len() as i64 + triangles.len() as i64;
    (chi, loops)
}

/// A vertex coordinate for property tests of the rasterizer: mostly moderate, some huge, some
/// anything at all (NaN and infinities included).
pub fn coordinate() -> impl proptest::strategy::Strategy<Value = f32> {
    use proptest::prelude::*;
    prop_oneof![
        8 => -3.0f32..3.0,
        2 => -1e6f32..1e6,
        1 => prop::num::f32::ANY,
    ]
}
