//! Hostile bytes into the hierarchy loader: an error or a consistent view, never a panic.
//!
//! Each input is tried as it is and with its checksum recomputed, so that mutations reach the
//! structural checks behind the CRC.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vdlod_core::format::{crc32, HierarchyView, CRC_OFFSET, HEADER_SIZE, NONE};

fn check(data: &[u8]) {
    if let Ok(view) = HierarchyView::parse(data) {
        for i in 0..view.nodes() + 2 {
            let n = view.node(i);
            assert!(n.parent == NONE || n.parent < i);
            // What drawing reads of a node is what its whole record says.
            let same = |a: [f32; 3], b: [f32; 3]| a.map(f32::to_bits) == b.map(f32::to_bits);
            let (position, normal, color) = view.vertex(i);
            assert!(same(position, n.position) && same(normal, n.normal) && color == n.color);
        }
        for p in view.parent_nodes() {
            let s = view.split(p);
            assert!(s.children.iter().all(|&c| c > p && view.parent(c) == p));
            assert!(s
                .neighbours
                .iter()
                .all(|&f| f == NONE || view.face_creator(f).is_none_or(|q| !view.is_below(q, p))));
        }
        for t in 0..view.base_triangles() {
            assert!(view.base_triangle(t).iter().all(|&v| v < view.nodes()));
        }
    }
}

fuzz_target!(|data: &[u8]| {
    check(data);
    if data.len() >= HEADER_SIZE {
        let mut sealed = data.to_vec();
        let crc = crc32(&sealed[HEADER_SIZE..]);
        sealed[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
        check(&sealed);
    }
});
