//! Hostile hierarchies into the runtime cut: whatever `HierarchyView::parse` accepts can be reset,
//! refined, adapted over a few frames under a budget (its slots renumbered now and then),
//! coarsened, and flown in small steps without geomorphs or a budget (refinement depth first,
//! new children decided from their digests, settled vertices skipped) under a policy that judges
//! bounds and one that reads spheres only, without a panic; the cut stays whole
//! (`Cut::check`) after every frame, and every frame's vertices read a batch at a time are the
//! ones read one at a time, bit for bit.
//!
//! Each input is tried with its checksum recomputed, so that mutations of valid files (the seeds
//! in `seeds/hierarchy`) reach the cut.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vdlod_core::adapt::Budget;
use vdlod_core::cut::{Cut, VertexOut, LANES};
use vdlod_core::format::{crc32, HierarchyView, CRC_OFFSET, HEADER_SIZE};
use vdlod_core::policy::{MergeTree, QRefine, View};

fuzz_target!(|data: &[u8]| {
    if data.len() < HEADER_SIZE {
        return;
    }
    let mut sealed = data.to_vec();
    let crc = crc32(&sealed[HEADER_SIZE..]);
    sealed[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
    let Ok(view) = HierarchyView::parse(&sealed) else {
        return;
    };
    let mut cut = Cut::<256, 512, 64>::boxed();
    if cut.reset(&view).is_err() {
        return;
    }
    cut.set_geomorph_frames(2);
    let _ = cut.refine_everything(&view);
    for i in 0..4 {
        let a = i as f32;
        let eye = [3.0 * a.cos(), 0.5, 3.0 * a.sin()];
        let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.3, 240.0);
        let budget = Budget {
            max_triangles: 40 + 100 * (i % 2),
            ..Budget::default()
        };
        let _ = cut.adapt(&view, &v, &QRefine::new(0.25 + a), &budget);
        whole(&cut, &view);
        same_both_ways(&cut, &view);
        if i % 2 == 1 {
            let _ = cut.renumber();
        }
    }
    for p in view.parent_nodes().take(512) {
        let _ = cut.collapse(&view, p);
    }
    whole(&cut, &view);
    cut.set_geomorph_frames(0);
    for i in 0..8 {
        let (a, d) = (0.03 * i as f32, 2.0 + 0.5 * (i % 4) as f32);
        let v = View::look_at(
            [d * a.cos(), 0.4, d * a.sin()],
            [0.0; 3],
            [0.0, 1.0, 0.0],
            1.0,
            1.3,
            240.0,
        );
        if i < 4 {
            let _ = cut.adapt(&view, &v, &QRefine::new(0.5), &Budget::default());
        } else {
            let _ = cut.adapt(&view, &v, &MergeTree { near: 2.5 }, &Budget::default());
        }
        whole(&cut, &view);
        same_both_ways(&cut, &view);
    }
});

/// The cut's invariants hold, whatever the file.
fn whole(cut: &Cut<256, 512, 64>, h: &HierarchyView<'_>) {
    if let Err(d) = cut.check(h) {
        panic!("the cut is not whole: {d:?}");
    }
}

/// Every slot (and a few past the last) read by `Cut::vertex_lanes`, from every start, is what
/// `Cut::vertex` reads.
fn same_both_ways(cut: &Cut<256, 512, 64>, h: &HierarchyView<'_>) {
    let bits = |v: &VertexOut| {
        (
            v.position.map(f32::to_bits),
            v.normal.map(f32::to_bits),
            v.color,
        )
    };
    for first in 0..cut.vertex_count() + 2 {
        let (mut p, mut n, mut c) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3], [[0; LANES]; 3]);
        cut.vertex_lanes(h, first, LANES, &mut p, &mut n, Some(&mut c));
        for k in 0..LANES {
            let lane = VertexOut {
                position: [0, 1, 2].map(|a| p[a][k]),
                normal: [0, 1, 2].map(|a| n[a][k]),
                color: [0, 1, 2].map(|a| c[a][k]),
            };
            assert_eq!(
                bits(&lane),
                bits(&cut.vertex(h, first + k)),
                "slot {first} + {k}"
            );
        }
    }
}
