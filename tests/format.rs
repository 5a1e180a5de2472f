//! The hierarchy format against hostile bytes: corrupted, truncated or forged files give an error,
//! never a panic, and whatever parses is internally consistent and can be flown by a cut without
//! a panic.

use std::sync::OnceLock;

use proptest::prelude::*;
use vdlod_core::adapt::Budget;
use vdlod_core::build::{build, BuildOptions, InputMesh};
use vdlod_core::cut::Cut;
use vdlod_core::format::{crc32, HierarchyView, COUNT_OFFSETS, CRC_OFFSET, HEADER_SIZE, NONE};
use vdlod_core::policy::{MergeTree, QRefine, View};
use vdlod_demo::mesh::{load_obj_bytes, COW_NAME, COW_OBJ};

fn cow_bytes() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| {
        let cow = load_obj_bytes(COW_NAME, COW_OBJ).unwrap();
        let input = InputMesh {
            positions: &cow.positions,
            colors: None,
            triangles: &cow.triangles,
        };
        build(&input, &BuildOptions::default(), &mut |_| {})
            .unwrap()
            .to_bytes(false)
    })
}

/// Reads everything a valid view offers and checks the promises `parse` makes.
fn walk(view: &HierarchyView<'_>) {
    for i in 0..view.nodes() {
        let n = view.node(i);
        assert!(n.parent == NONE || n.parent < i);
        assert_eq!(n.parent == NONE, i < view.roots());
        assert!(n.radius >= 0.0 && n.position.iter().all(|c| c.is_finite()));
    }
    // What drawing reads of a node is what the whole record says, past the last node too.
    for i in (0..view.nodes()).chain([view.nodes(), view.nodes() + 7, NONE]) {
        let n = view.node(i);
        assert_eq!(view.vertex(i), (n.position, n.normal, n.color), "node {i}");
    }
    // A pair's records located together are each located alone, for every node (a sibling
    // pair's first child, the second, a leaf of the next kind block) and past the last.
    for i in (0..view.nodes()).chain([view.nodes().saturating_sub(1), view.nodes(), NONE - 1, NONE])
    {
        let alone = [view.record(i), view.record(i.wrapping_add(1))];
        assert_eq!(view.pair_records(i), alone, "node {i}");
    }
    let mut parents = 0;
    for p in view.parent_nodes() {
        parents += 1;
        let s = view.split(p);
        assert!(s.children[1] == s.children[0] + 1);
        assert!(s
            .children
            .iter()
            .all(|&c| c > p && c < view.nodes() && view.node(c).parent == p));
        assert!(s
            .neighbours
            .iter()
            .all(|&f| f == NONE || view.face_creator(f).is_none_or(|q| !view.is_below(q, p))));
    }
    assert_eq!(parents, view.nodes() - view.leaves());
    for t in 0..view.base_triangles() {
        assert!(view
            .base_triangle(t)
            .iter()
            .all(|&v| view.node(v).parent == NONE));
    }
    fly(view);
}

/// A small cut over whatever parsed: refinement, a few frames from around and inside (its slots
/// renumbered now and then), coarsening; then frames without geomorphs or a budget, in small
/// steps (refinement depth first, new children decided from their digests, settled vertices
/// skipped until their marks expire), under a policy that judges bounds and one that reads
/// spheres only. Hostile files may be refused or leave the cut coarse, but nothing may panic,
/// and the cut stays whole ([`Cut::check`]) after everything it does. Returns, for the frames
/// without geomorphs under each policy, the splits, collapses and settled vertices they counted.
fn fly(view: &HierarchyView<'_>) -> [[u32; 3]; 2] {
    let mut counted = [[0u32; 3]; 2];
    let mut cut = Cut::<512, 1024, 128>::boxed();
    if cut.reset(view).is_err() {
        return counted;
    }
    let whole = |cut: &Cut<512, 1024, 128>, what: &str| {
        if let Err(d) = cut.check(view) {
            panic!("{what}: {d:?}");
        }
    };
    cut.set_geomorph_frames(2);
    let _ = cut.refine_everything(view);
    whole(&cut, "refine_everything");
    for i in 0..6 {
        let a = i as f32;
        let eye = [3.0 * a.cos(), 0.5 - 0.2 * a, 3.0 * a.sin() - 0.5 * a];
        let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.3, 240.0);
        let budget = Budget {
            max_triangles: 300 + 400 * (i % 2),
            ..Budget::default()
        };
        let _ = cut.adapt(view, &v, &QRefine::new(0.5 + a), &budget);
        whole(&cut, "adapt under a budget");
        if i % 2 == 1 {
            let _ = cut.renumber();
            whole(&cut, "renumber");
        }
    }
    for p in view.parent_nodes().take(2000) {
        let _ = cut.collapse(view, p);
    }
    whole(&cut, "collapse");
    cut.set_geomorph_frames(0);
    for i in 0..12 {
        // Small steps, receding: marks are made and expire, and detail is given back.
        let (a, d) = (0.03 * i as f32, 2.0 + 0.25 * (i % 8) as f32);
        let eye = [d * a.cos(), 0.4, d * a.sin()];
        let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.3, 240.0);
        let (k, stats) = if i < 8 {
            (
                0,
                cut.adapt(view, &v, &QRefine::new(0.5), &Budget::default()),
            )
        } else {
            (
                1,
                cut.adapt(view, &v, &MergeTree { near: 2.5 }, &Budget::default()),
            )
        };
        whole(&cut, "adapt without geomorphs or a budget");
        for (c, n) in counted[k]
            .iter_mut()
            .zip([stats.vsplits, stats.ecols, stats.settled])
        {
            *c += n;
        }
    }
    counted
}

/// Forges the checksum so that corruption reaches the structural checks.
fn reseal(bytes: &mut [u8]) {
    if bytes.len() >= HEADER_SIZE {
        let crc = crc32(&bytes[HEADER_SIZE..]);
        bytes[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
    }
}

#[test]
fn the_valid_file_parses() {
    let view = HierarchyView::parse(cow_bytes()).unwrap();
    assert_eq!(view.leaves(), 2904);
    walk(&view);
    // The hostile files' flight reaches what it is meant to on a valid one: both policies split,
    // collapse and skip settled vertices.
    for (policy, [splits, collapses, settled]) in ["QRefine", "MergeTree"].iter().zip(fly(&view)) {
        assert!(
            splits > 0 && collapses > 0 && settled > 0,
            "{policy}: {splits} {collapses} {settled}"
        );
    }
}

/// The `hierarchy` and `cut` fuzz targets start from `fuzz/seeds/hierarchy`: the seeds must stay
/// valid files of this format version, or the fuzzers would spend their runs on the version check.
#[test]
fn the_fuzz_seeds_are_valid_files() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/hierarchy");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 3, "{paths:?}");
    for path in paths {
        let bytes = std::fs::read(&path).unwrap();
        match HierarchyView::parse(&bytes) {
            Ok(view) => walk(&view),
            Err(e) => panic!(
                "{}: {e} (rebuild the seeds: fuzz/README.md)",
                path.display()
            ),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn corrupted_files_are_rejected_or_consistent(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        resealed in any::<bool>(),
    ) {
        let mut bytes = cow_bytes().to_vec();
        for (at, value) in &edits {
            let i = at.index(bytes.len());
            bytes[i] = *value;
        }
        if resealed {
            reseal(&mut bytes);
        }
        if let Ok(view) = HierarchyView::parse(&bytes) {
            walk(&view);
        }
    }

    #[test]
    fn truncated_files_are_rejected(cut in any::<prop::sample::Index>()) {
        let bytes = cow_bytes();
        let n = cut.index(bytes.len());
        prop_assert!(HierarchyView::parse(&bytes[..n]).is_err());
    }

    #[test]
    fn random_bytes_behind_a_valid_header_are_rejected_or_consistent(
        body in prop::collection::vec(any::<u8>(), 0..2048),
        counts in [0u32..64, 0u32..64, 0u32..64],
    ) {
        let mut bytes = cow_bytes()[..HEADER_SIZE].to_vec();
        for (&o, c) in COUNT_OFFSETS.iter().zip(counts) {
            bytes[o..o + 4].copy_from_slice(&c.to_le_bytes());
        }
        bytes.extend_from_slice(&body);
        reseal(&mut bytes);
        if let Ok(view) = HierarchyView::parse(&bytes) {
            walk(&view);
        }
    }
}
