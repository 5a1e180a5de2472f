//! Cut tests on generated meshes (fixtures and long camera paths are in the workspace's `tests/`).

use alloc::boxed::Box;
use alloc::vec::Vec;

use super::*;
use crate::build::tests::{build_it, grid, sorted, sphere, topology};
use crate::build::BuildOptions;

type Small = Cut<1024, 2048, 256>;

fn node_triangles<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    cut: &Cut<V, F, Q, I>,
) -> Vec<[u32; 3]> {
    let nodes = cut.nodes();
    let t = cut
        .triangles()
        .iter()
        .map(|t| t.map(|s| nodes[s.index()]))
        .collect();
    sorted(t)
}

/// The positions of the cut's vertices as drawn, by slot.
fn positions<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    cut: &Cut<V, F, Q, I>,
    h: &HierarchyView<'_>,
) -> Vec<[f32; 3]> {
    (0..cut.vertex_count())
        .map(|s| cut.vertex(h, s).position)
        .collect()
}

/// A name, a hierarchy file, and the triangles it was built from (in the file's node ids).
type Case = (&'static str, Vec<u8>, Vec<[u32; 3]>);

fn meshes() -> Vec<Case> {
    let mut out = Vec::new();
    for (name, (p, t), balanced) in [
        ("sphere", sphere(3), false),
        ("sphere balanced", sphere(3), true),
        ("grid", grid(12), false),
        ("grid balanced", grid(12), true),
    ] {
        let opts = BuildOptions {
            balanced,
            ..BuildOptions::default()
        };
        let h = build_it(&p, &t, opts);
        let ids = h.file_ids();
        let t = t.iter().map(|tri| tri.map(|v| ids[v as usize])).collect();
        out.push((name, h.to_bytes(false), t));
    }
    out
}

#[test]
fn full_refinement_gives_the_input_and_full_coarsening_the_base() {
    for (name, bytes, input) in meshes() {
        let h = HierarchyView::parse(&bytes).unwrap();
        let mut cut: Box<Small> = Cut::boxed();
        cut.reset(&h).unwrap();
        let base = node_triangles(&cut);
        let mut rounds = 0;
        while cut.refine_everything(&h) > 0 {
            cut.check(&h).unwrap_or_else(|d| panic!("{name}: {d:?}"));
            rounds += 1;
            assert!(rounds < 100, "{name}: refinement does not end");
        }
        assert_eq!(node_triangles(&cut), sorted(input.clone()), "{name}");
        // Collapse finest first until nothing is left to collapse.
        let parents: Vec<u32> = h.parent_nodes().collect();
        loop {
            let mut done = 0;
            for &p in parents.iter().rev() {
                if cut.collapse(&h, p).is_ok() {
                    done += 1;
                    cut.check(&h).unwrap_or_else(|d| panic!("{name}: {d:?}"));
                }
            }
            if done == 0 {
                break;
            }
        }
        assert_eq!(node_triangles(&cut), base, "{name}");
    }
}

/// Marsaglia's 32-bit xorshift: `x`'s next state, returned.
fn xorshift(x: &mut u32) -> u32 {
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    *x
}

#[test]
fn random_splits_and_collapses_keep_a_valid_manifold() {
    for (name, bytes, input) in meshes() {
        let h = HierarchyView::parse(&bytes).unwrap();
        let expected = topology(&input);
        let mut cut: Box<Small> = Cut::boxed();
        cut.reset(&h).unwrap();
        let mut x = 0x2545_F491u32;
        let mut splits = 0;
        let mut collapses = 0;
        for _ in 0..3000 {
            xorshift(&mut x);
            let v = cut.nodes()[(x >> 8) as usize % cut.vertex_count()];
            if x & 1 == 0 || x & 6 == 0 {
                if let Ok(k) = cut.force_split(&h, v, 0, &mut |_, _| Ok(())) {
                    splits += k;
                }
            } else {
                let p = h.parent(v);
                if p != NONE && cut.collapse(&h, p).is_ok() {
                    collapses += 1;
                }
            }
            cut.check(&h).unwrap_or_else(|d| panic!("{name}: {d:?}"));
            assert_eq!(topology(&node_triangles(&cut)), expected, "{name}");
        }
        assert!(
            splits > 100 && collapses > 100,
            "{name}: {splits} {collapses}"
        );
    }
}

#[test]
fn slots_freed_by_collapses_are_taken_by_splits_or_filled() {
    // As a frame's collapses do (`Cut::coarsen`): each leaves its second child's slot empty,
    // the splits after them take those slots, and what is left is filled from the end.
    for (name, bytes, input) in meshes() {
        let h = HierarchyView::parse(&bytes).unwrap();
        let expected = topology(&input);
        let mut cut: Box<Small> = Cut::boxed();
        cut.reset(&h).unwrap();
        while cut.refine_everything(&h) > 0 {}
        let mut fans = PairFans::default();
        let mut x = 0x9E37_79B9u32;
        let mut next = || xorshift(&mut x);
        let (mut freed, mut taken, mut filled) = (0, 0, 0);
        for _ in 0..100 {
            for _ in 0..12 {
                let v = cut.nodes()[(next() >> 8) as usize % cut.vertex_count()];
                let p = h.parent(v);
                if v == NONE || p == NONE {
                    continue;
                }
                let split = h.split(p);
                let (Some(a), Some(b)) = (cut.slot(split.children[0]), cut.slot(split.children[1]))
                else {
                    continue;
                };
                if let Ok(plan) = cut.collapse_legal_at(&split, a, b, &mut fans, true) {
                    assert_eq!(cut.apply_collapse(&h, p, plan, &mut fans, true), a);
                    assert_eq!(cut.nodes()[b as usize], NONE, "{name}");
                    freed += 1;
                }
            }
            for _ in 0..6 {
                let v = cut.nodes()[(next() >> 8) as usize % cut.vertex_count()];
                let holes = cut.holes;
                if v != NONE && cut.force_split(&h, v, 0, &mut |_, _| Ok(())).is_ok() {
                    taken += holes - cut.holes;
                }
            }
            filled += cut.holes;
            cut.fill_holes();
            assert_eq!(cut.vertex_count(), cut.active(), "{name}");
            cut.check(&h).unwrap_or_else(|d| panic!("{name}: {d:?}"));
            assert_eq!(topology(&node_triangles(&cut)), expected, "{name}");
        }
        assert!(
            freed > 100 && taken > 50 && filled > 50,
            "{name}: {freed} freed, {taken} taken, {filled} filled"
        );
    }
}

#[test]
fn forced_splits_bring_what_a_split_needs() {
    let (p, t) = sphere(3);
    let built = build_it(&p, &t, BuildOptions::default());
    let bytes = built.to_bytes(false);
    let ids = built.file_ids();
    let t = t.iter().map(|tri| tri.map(|v| ids[v as usize])).collect();
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut: Box<Small> = Cut::boxed();
    cut.reset(&h).unwrap();
    // Every leaf's parent can be reached from the base mesh by forcing alone.
    for leaf in h.leaf_nodes() {
        let mut v = leaf;
        while !cut.is_active(v) {
            let mut a = h.parent(v);
            while !cut.is_active(a) {
                a = h.parent(a);
            }
            cut.force_split(&h, a, 0, &mut |_, _| Ok(())).unwrap();
            v = leaf;
        }
        cut.check(&h).unwrap();
    }
    assert_eq!(node_triangles(&cut), sorted(t));
}

#[test]
fn refusals_leave_the_cut_as_it_was() {
    let (p, t) = grid(8);
    let bytes = build_it(&p, &t, BuildOptions::default()).to_bytes(false);
    let h = HierarchyView::parse(&bytes).unwrap();
    // Room for the base mesh and hardly more.
    let mut cut: Box<Cut<8, 8, 8>> = Cut::boxed();
    cut.reset(&h).unwrap();
    let before = node_triangles(&cut);
    let mut refusals = 0;
    for _ in 0..4 {
        let nodes: Vec<u32> = cut.nodes().to_vec();
        for v in nodes {
            match cut.force_split(&h, v, 0, &mut |_, _| Ok(())) {
                Ok(_) | Err(Refused::NotActive) | Err(Refused::NoSuchOperation) => {}
                Err(Refused::Capacity) => refusals += 1,
                Err(e) => panic!("{e:?}"),
            }
            cut.check(&h).unwrap();
        }
    }
    assert!(refusals > 0);
    assert!(cut.vertex_count() <= 8 && cut.triangles().len() <= 8);
    assert_ne!(node_triangles(&cut), before);
    // A budget refusal changes nothing.
    let mut cut2: Box<Small> = Cut::boxed();
    cut2.reset(&h).unwrap();
    let v = cut2.nodes()[0];
    assert_eq!(
        cut2.force_split(&h, v, 0, &mut |_, _| Err(Refused::Budget)),
        Err(Refused::Budget)
    );
    assert_eq!(node_triangles(&cut2), before);
}

#[test]
fn the_size_is_what_the_documentation_says() {
    // With index size i: 17 + 2i bytes per vertex slot (with its 8-byte digest and 16-bit
    // tag), 7i + 4 per
    // triangle slot (with its node-map entry), 52 per queue entry, plus 368 bytes (lengths,
    // settings, the walk's position, the freed slots' chain and the terms the settled vertices
    // were marked under); the
    // same on 32- and 64-bit targets.
    let per =
        |i: usize, v: usize, f: usize, q: usize| (17 + 2 * i) * v + (7 * i + 4) * f + 52 * q + 368;
    assert_eq!(Cut::<1024, 2048, 128>::BYTES, per(2, 1024, 2048, 128));
    assert_eq!(Cut::<5120, 10240, 640>::BYTES, per(2, 5120, 10240, 640));
    assert_eq!(Cut::<1024, 2048, 128, u32>::BYTES, per(4, 1024, 2048, 128));
    // The documented figure is checked at compile time in the module, on every target.
}

#[test]
fn boxed_is_new() {
    let boxed = Cut::<64, 128, 8>::boxed();
    let new = Cut::<64, 128, 8>::new();
    assert_eq!(boxed.vertex_count(), new.vertex_count());
    assert_eq!(boxed.triangles().len(), new.triangles().len());
    assert_eq!(boxed.threshold(), new.threshold());
    assert_eq!(boxed.coloring, new.coloring);
    assert_eq!(boxed.geomorph_frames, new.geomorph_frames);
    assert_eq!(alloc::format!("{boxed:?}"), alloc::format!("{new:?}"));
    // Zeroed, the settling terms are new ones too (a field that is not zero in `new` would also
    // move a `static` cut from `.bss` to `.data`, a flash copy of its whole size).
    assert_eq!(
        alloc::format!("{:?}", boxed.motion),
        alloc::format!("{:?}", new.motion)
    );
}

mod adapt {
    use super::*;
    use crate::adapt::Budget;
    use crate::policy::{BackFace, Frustum, ScreenError, View};

    fn orbit(i: u32, distance: f32) -> View {
        let a = i as f32 * 0.07;
        let eye = [
            distance * libm::cosf(a),
            0.4 * libm::sinf(0.3 * i as f32),
            distance * libm::sinf(a),
        ];
        View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 4.0 / 3.0, 480.0)
    }

    fn sphere_bytes() -> Vec<u8> {
        let (p, t) = sphere(4);
        build_it(&p, &t, BuildOptions::default()).to_bytes(false)
    }

    type Mid = Cut<4096, 8192, 2048>;

    /// Adapts `cut` to `view` without limits until a frame changes nothing (within ten).
    fn settle(
        cut: &mut Mid,
        h: &HierarchyView<'_>,
        view: &View,
        policy: &impl crate::policy::Policy,
    ) {
        for _ in 0..10 {
            let s = cut.adapt(h, view, policy, &Budget::default());
            if s.vsplits + s.ecols == 0 {
                return;
            }
        }
        panic!("the cut does not settle");
    }

    #[test]
    fn frames_keep_the_mesh_valid_within_budget_and_repeat_exactly() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(0.5)));
        let budget = Budget {
            max_triangles: 600,
            ..Budget::default()
        };
        let run = || {
            let mut cut: Box<Mid> = Cut::boxed();
            cut.reset(&h).unwrap();
            cut.set_geomorph_frames(4);
            let mut frames = Vec::new();
            for i in 0..150 {
                let distance = 1.5 + 4.0 * libm::fabsf(libm::sinf(i as f32 * 0.05));
                let s = cut.adapt(&h, &orbit(i, distance), &policy, &budget);
                cut.check(&h).unwrap_or_else(|d| panic!("frame {i}: {d:?}"));
                assert!(s.triangles <= 600 && !s.over_budget, "frame {i}: {s:?}");
                assert_eq!(s.triangles as usize, cut.triangles().len());
                frames.push((node_triangles(&cut), positions(&cut, &h)));
            }
            frames
        };
        let first = run();
        assert!(first.iter().any(|(t, _)| t.len() > 500), "the budget binds");
        assert_eq!(first, run());
    }

    /// A pair marked illegal (`BLOCKED`) stays illegal until a collapse unblocks it: only the
    /// collapses that give its triangles new neighbours do (`Cut::unblock_pair_of`), so after
    /// every frame no marked pair may be legal, or a collapse the view asks for would wait.
    #[test]
    fn a_pair_marked_illegal_is_illegal_until_unblocked() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(0.5)));
        let mut marked = 0;
        for (frames, max_triangles) in [(0, u32::MAX), (4, u32::MAX), (0, 700)] {
            let mut cut: Box<Mid> = Cut::boxed();
            cut.reset(&h).unwrap();
            cut.set_geomorph_frames(frames);
            let budget = Budget {
                max_triangles,
                ..Budget::default()
            };
            let mut fans = PairFans::default();
            for i in 0..200 {
                let distance = 1.5 + 4.0 * libm::fabsf(libm::sinf(i as f32 * 0.05));
                cut.adapt(&h, &orbit(i, distance), &policy, &budget);
                for a in 0..cut.vertex_count() {
                    let Some(p) = cut.pair_parent(&h, a) else {
                        continue;
                    };
                    let b = cut.v.mate(a) as usize;
                    if cut.v.flags[a] & cut.v.flags[b] & BLOCKED != 0 {
                        marked += 1;
                        assert!(
                            cut.collapse_legal(&h, p, &mut fans, false).is_err(),
                            "frame {i}: pair of node {p} marked illegal, but legal"
                        );
                    }
                }
            }
        }
        assert!(marked > 1000, "pairs are marked illegal ({marked})");
    }

    /// Renumbering changes slots only: the same nodes, triangles and blended positions, and the
    /// frames after it the same as without it (but for which restless vertices are asked), with
    /// and without geomorphs; the vertices are in node order after it and the triangles in the
    /// order of their first corner.
    #[test]
    fn renumbering_keeps_the_cut_and_the_frames_after_it() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(0.5)));
        let (mut plain, mut renumbered): (Box<Mid>, Box<Mid>) = (Cut::boxed(), Cut::boxed());
        // With little room after its records a cut moves them by exchanges, not copies: the
        // same slots either way.
        let mut exchanged: Box<Cut<800, 1600, 2048>> = Cut::boxed();
        let mut exchanges = 0;
        let by_node = |cut: &Mid| {
            let mut v: Vec<(u32, [u32; 3])> = cut
                .nodes()
                .iter()
                .zip(positions(cut, &h))
                .map(|(&n, p)| (n, p.map(f32::to_bits)))
                .collect();
            v.sort_unstable();
            v
        };
        plain.reset(&h).unwrap();
        renumbered.reset(&h).unwrap();
        exchanged.reset(&h).unwrap();
        let mut renumbers = 0;
        for i in 0..240 {
            let frames = if (80..160).contains(&i) { 4 } else { 0 };
            plain.set_geomorph_frames(frames);
            renumbered.set_geomorph_frames(frames);
            exchanged.set_geomorph_frames(frames);
            let view = orbit(i, 1.5 + 4.0 * libm::fabsf(libm::sinf(i as f32 * 0.05)));
            let a = plain.adapt(&h, &view, &policy, &Budget::default());
            let b = renumbered.adapt(&h, &view, &policy, &Budget::default());
            assert_eq!(exchanged.adapt(&h, &view, &policy, &Budget::default()), b);
            // Restless vertices take turns by slot, so which are asked may differ.
            let asked = |s: crate::adapt::FrameStats| crate::adapt::FrameStats {
                settled: 0,
                visited: 0,
                ..s
            };
            assert_eq!(asked(a), asked(b), "frame {i}");
            if i % 9 == 4 {
                assert!(renumbered.renumber());
                renumbers += 1;
                exchanges += usize::from(2 * exchanged.vertex_count() > 800);
                assert!(exchanged.renumber());
                assert_eq!(exchanged.nodes(), renumbered.nodes(), "frame {i}");
                assert_eq!(exchanged.triangles(), renumbered.triangles(), "frame {i}");
                renumbered
                    .check(&h)
                    .unwrap_or_else(|d| panic!("frame {i}: {d:?}"));
                assert!(renumbered.nodes().windows(2).all(|w| w[0] < w[1]));
                let t = renumbered.triangles();
                let first = |k: usize| t[k].iter().map(|s| s.index()).min().unwrap_or(0);
                assert!((1..t.len()).all(|k| first(k - 1) <= first(k)), "frame {i}");
            }
            assert_eq!(
                node_triangles(&plain),
                node_triangles(&renumbered),
                "frame {i}"
            );
            assert_eq!(by_node(&plain), by_node(&renumbered), "frame {i}");
        }
        assert!(renumbers > 20);
        assert!(
            exchanges > 5 && exchanges < renumbers,
            "{exchanges} of {renumbers}"
        );
        // Without room for its scratch it refuses, and changes nothing.
        let mut tight: Cut<64, 100, 16> = Cut::new();
        tight.reset(&h).unwrap();
        while tight.vertex_count() * 2 <= 100 && tight.refine_everything(&h) > 0 {}
        let before = tight.nodes().to_vec();
        assert!(!tight.renumber());
        assert_eq!(tight.nodes(), &before[..]);
    }

    #[test]
    fn the_budget_goes_where_the_error_is_largest() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = ScreenError::new(0.1);
        // Close to the sphere: the near side's errors are many times the far side's.
        let view = orbit(0, 1.4);
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        let budget = Budget {
            max_triangles: 300,
            ..Budget::default()
        };
        for _ in 0..5 {
            cut.adapt(&h, &view, &policy, &budget);
        }
        assert!(cut.triangles().len() >= 290 && cut.triangles().len() <= 300);
        // Greedy optimality: no collapse the cut could make would pay for a split wanted more,
        // i.e. every vertex left unsplit wants it less than any collapsible pair's parent.
        use crate::policy::Policy;
        let mut max_unsplit = 0f32;
        let mut min_collapsible = f32::MAX;
        for (i, &n) in cut.nodes().iter().enumerate() {
            if h.is_parent(n) {
                max_unsplit = max_unsplit.max(policy.demand(&h.bounds(n), &view).error);
            }
            if let Some(p) = cut.pair_parent(&h, i) {
                if cut
                    .collapse_legal(&h, p, &mut Default::default(), false)
                    .is_ok()
                {
                    let e = policy.demand(&h.bounds(p), &view).error;
                    min_collapsible = min_collapsible.min(e);
                }
            }
        }
        assert!(max_unsplit > 1.0, "the budget binds");
        assert!(
            max_unsplit <= min_collapsible,
            "{max_unsplit} > {min_collapsible}"
        );
        // So the side facing the camera, with the larger projected errors, got more vertices.
        let eye = view.eye;
        let near = positions(&cut, &h)
            .iter()
            .filter(|p| p[0] * eye[0] + p[1] * eye[1] + p[2] * eye[2] > 0.0)
            .count();
        assert!(
            near * 2 > cut.vertex_count(),
            "{near} of {}",
            cut.vertex_count()
        );
    }

    #[test]
    fn regulation_reaches_the_target_and_ops_are_capped() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, ScreenError::new(1.0));
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        let budget = Budget {
            target_triangles: 400,
            max_ops: 40,
            ..Budget::default()
        };
        let mut last = 0;
        for i in 0..60 {
            let s = cut.adapt(&h, &orbit(0, 3.0), &policy, &budget);
            assert!(s.vsplits + s.ecols <= 40, "frame {i}: {s:?}");
            last = s.triangles;
        }
        assert!((360..=440).contains(&last), "{last}");
    }

    #[test]
    fn regulation_reaches_a_frame_time_target() {
        // A frame that costs 200 us plus 1 us per triangle, against a 600 us target: the cut
        // settles near 400 triangles, from above (0.25 px) and from below (the base mesh).
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, ScreenError::new(0.25));
        for start_fine in [true, false] {
            let mut cut: Box<Mid> = Cut::boxed();
            cut.reset(&h).unwrap();
            let mut frame_us = 0;
            if start_fine {
                let s = cut.adapt(&h, &orbit(0, 3.0), &policy, &Budget::default());
                assert!(s.triangles > 700, "{s:?}");
                frame_us = 200 + s.triangles;
            }
            let mut last = 0;
            for _ in 0..40 {
                let budget = Budget {
                    target_frame_us: 600,
                    frame_us,
                    ..Budget::default()
                };
                let s = cut.adapt(&h, &orbit(0, 3.0), &policy, &budget);
                frame_us = 200 + s.triangles;
                last = s.triangles;
            }
            assert!((340..=460).contains(&last), "{start_fine}: {last}");
        }
    }

    #[test]
    fn a_window_of_visits_reaches_the_cut_a_full_pass_asks_for() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(0.5)));
        // Both cuts start from the one a close view asks for; then the camera moves to the
        // other side, where a split's recursion cannot reach what must collapse.
        let (before, view) = (orbit(0, 1.5), orbit(45, 2.5));
        let mut full: Box<Mid> = Cut::boxed();
        full.reset(&h).unwrap();
        settle(&mut full, &h, &before, &policy);
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        settle(&mut cut, &h, &before, &policy);
        settle(&mut full, &h, &view, &policy);
        let budget = Budget {
            max_visits: 64,
            ..Budget::default()
        };
        let mut still = 0;
        let mut frames = 0;
        // Still once the walk has gone round the whole list without a change.
        while still <= cut.vertex_count() / 64 + 1 {
            let s = cut.adapt(&h, &view, &policy, &budget);
            assert!(s.visited <= 64, "frame {frames}: {s:?}");
            cut.check(&h).unwrap();
            still = if s.vsplits + s.ecols == 0 {
                still + 1
            } else {
                0
            };
            frames += 1;
            assert!(frames < 1000, "the window never settles");
        }
        assert!(full.vertex_count() > 64 * 4, "the window binds");
        assert_eq!(node_triangles(&cut), node_triangles(&full));
        let s = cut.adapt(&h, &view, &policy, &Budget::default());
        assert_eq!((s.vsplits, s.ecols), (0, 0), "{s:?}");
    }

    #[test]
    fn a_window_of_visits_keeps_budgets_and_finishes_geomorphs() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = (Frustum, (BackFace, ScreenError::new(0.5)));
        let budget = Budget {
            max_triangles: 600,
            max_visits: 50,
            ..Budget::default()
        };
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        cut.set_geomorph_frames(4);
        let mut most_blending = 0;
        for i in 0..200 {
            let distance = 1.5 + 4.0 * libm::fabsf(libm::sinf(i as f32 * 0.05));
            let morphing = cut.blends.len() as u32;
            let s = cut.adapt(&h, &orbit(i, distance), &policy, &budget);
            cut.check(&h).unwrap_or_else(|d| panic!("frame {i}: {d:?}"));
            assert!(s.triangles <= 600 && !s.over_budget, "frame {i}: {s:?}");
            // The window, plus the vertices in a geomorph (asked every frame).
            assert!(s.visited <= 50 + morphing, "frame {i}: {s:?}");
            most_blending = most_blending.max(s.blending);
        }
        assert!(most_blending > 0, "geomorphs ran");
        // Every geomorph arrives although most of its vertices' neighbours are not asked.
        let view = orbit(200, 3.0);
        for _ in 0..8 {
            cut.adapt(&h, &view, &policy, &budget);
        }
        let mut rest = budget;
        rest.max_visits = 0;
        for _ in 0..8 {
            let morphing = cut.blends.len() as u32;
            let s = cut.adapt(&h, &view, &policy, &rest);
            assert!(s.visited <= morphing, "{s:?}");
        }
        assert_eq!(cut.blending(), 0);
        let drawn = positions(&cut, &h);
        for (p, &n) in drawn.iter().zip(cut.nodes()) {
            assert_eq!(*p, h.node(n).position);
        }
    }

    #[test]
    fn an_operation_cap_is_spent_where_the_errors_are() {
        use crate::policy::Policy;
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = ScreenError::new(0.5);
        // Refined close to one side; then the eye moves round to the other side: the first
        // side's detail is no longer needed, the second side's is.
        let (before, after) = (orbit(0, 1.6), orbit(45, 1.6));
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        settle(&mut cut, &h, &before, &policy);
        let budget = Budget {
            max_ops: 8,
            ..Budget::default()
        };
        // The pairs that could collapse, with their parents' errors, before the frame.
        let collapsible = |cut: &Mid| -> Vec<(u32, f32)> {
            (0..cut.vertex_count())
                .filter_map(|i| cut.pair_parent(&h, i))
                .filter(|&p| {
                    cut.collapse_legal(&h, p, &mut Default::default(), false)
                        .is_ok()
                })
                .map(|p| (p, policy.demand(&h.bounds(p), &after).error))
                .filter(|&(_, e)| e <= 1.0)
                .collect()
        };
        let pairs = collapsible(&cut);
        let s = cut.adapt(&h, &after, &policy, &budget);
        assert!(s.ops_limited && s.vsplits + s.ecols <= 8, "{s:?}");
        // Splits got their half of the cap, and collapses the rest.
        assert!(s.vsplits >= 4 && s.ecols >= 3, "{s:?}");
        // The pairs collapsed were the least needed of those that could.
        let collapsed: Vec<f32> = pairs
            .iter()
            .filter(|&&(p, _)| cut.is_active(p))
            .map(|&(_, e)| e)
            .collect();
        let left = pairs
            .iter()
            .filter(|&&(p, _)| !cut.is_active(p))
            .map(|&(_, e)| e)
            .fold(f32::INFINITY, f32::min);
        let most = collapsed.iter().copied().fold(0.0, f32::max);
        assert!(
            collapsed.len() >= 2 && collapsed.len() < pairs.len() && most <= left,
            "{most} > {left}, {} of {}",
            collapsed.len(),
            pairs.len()
        );
    }

    #[test]
    fn importance_splits_the_corners_of_important_triangles_and_then_holds_still() {
        use crate::policy::{Importance, Policy};
        let (p, t) = grid(32);
        let bytes = build_it(&p, &t, BuildOptions::default()).to_bytes(false);
        let h = HierarchyView::parse(&bytes).unwrap();
        // Low over one corner of the grid, looking across it.
        let view = View::look_at(
            [0.05, 0.05, 0.35],
            [0.7, 0.7, 0.0],
            [0.0, 0.0, 1.0],
            1.0,
            4.0 / 3.0,
            480.0,
        );
        let importance = Importance::for_model(8e-4, &h);
        let policy = (Frustum, importance);
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(&h).unwrap();
        settle(&mut cut, &h, &view, &policy);
        cut.check(&h).unwrap();
        // Every triangle over the threshold has no corner left that could split (the paper's
        // rule), and the cut is neither the base nor full detail.
        let mut important = 0;
        for tri in cut.triangles() {
            let nodes = tri.map(|s| cut.nodes()[s.index()]);
            let c = nodes.map(|n| h.bounds(n).center);
            let reach = nodes
                .map(|n| h.bounds(n).radius)
                .into_iter()
                .fold(0.0, f32::max);
            if policy.triangle(&c, reach, &view) > 1.0 {
                important += 1;
                assert!(nodes.iter().all(|&n| !h.is_parent(n)), "{nodes:?}");
            }
        }
        assert!(
            important > 0,
            "some triangles are at full detail and still important"
        );
        let n = cut.triangles().len();
        assert!(n > 2 * h.base_triangles() as usize && n < t.len(), "{n}");
        // Detail falls with distance (as 1 / distance, the paper's measure): along the line of
        // sight, a patch about 0.5 from the eye holds more vertices than one about 1.35 away.
        let near = |q: [f32; 3], x: f32| (q[0] - x).abs() < 0.1 && (q[1] - x).abs() < 0.1;
        let ps = positions(&cut, &h);
        let (a, b) = (
            ps.iter().filter(|q| near(**q, 0.3)).count(),
            ps.iter().filter(|q| near(**q, 0.9)).count(),
        );
        assert!(2 * a > 3 * b, "{a} near, {b} far");
        // Judged from the triangles a collapse would make, nothing the view wants is undone.
        let again = cut.adapt(&h, &view, &policy, &Budget::default());
        assert_eq!((again.vsplits, again.ecols), (0, 0));
        // Under a binding budget the cut settles too (a split's neighbours want less after it,
        // so trades need a margin): after a few frames, at most 1% of the triangles change.
        let budget = Budget {
            max_triangles: (n * 3 / 4) as u32,
            ..Budget::default()
        };
        let mut last = again;
        for _ in 0..12 {
            last = cut.adapt(&h, &view, &policy, &budget);
            assert!(last.triangles <= budget.max_triangles, "{last:?}");
        }
        assert!(last.budget_limited, "{last:?}");
        assert!((last.vsplits + last.ecols) as usize * 100 <= n, "{last:?}");
    }

    /// A cut of `h` from its base mesh, with geomorphs over 8 frames.
    fn blending_cut(h: &HierarchyView<'_>) -> Box<Mid> {
        let mut cut: Box<Mid> = Cut::boxed();
        cut.reset(h).unwrap();
        cut.set_geomorph_frames(8);
        cut
    }

    /// The batch read gives every slot bit for bit as the one-at-a-time read does, from any
    /// start and for any count, in both colourings, with geomorphs running on some vertices of
    /// a batch and on none; past the last slot and past the count, the default.
    #[test]
    fn vertex_lanes_read_each_slot_as_vertex_does() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = ScreenError::new(2.0);
        let mut cut = blending_cut(&h);
        let bits = |v: VertexOut| {
            let f = |a: [f32; 3]| a.map(f32::to_bits);
            (f(v.position), f(v.normal), v.color)
        };
        let (mut mixed, mut plain) = (0, 0);
        for (frame, distance) in [30.0, 2.0, 2.0, 2.0, 30.0, 30.0].into_iter().enumerate() {
            cut.adapt(
                &h,
                &orbit(frame as u32, distance),
                &policy,
                &Budget::default(),
            );
            for coloring in [Coloring::Node, Coloring::Depth] {
                cut.set_coloring(coloring);
                let len = cut.vertex_count();
                for first in 0..len + 3 {
                    let blending = (first..(first + LANES).min(len))
                        .any(|s| cut.v.flags[s] & (BLENDING | COLLAPSING) != 0);
                    (mixed, plain) = (mixed + blending as u32, plain + !blending as u32);
                    for count in [0, 1, 5, LANES] {
                        for colors in [false, true] {
                            // Filled with garbage, which every lane must overwrite.
                            let mut p = [[f32::NAN; LANES]; 3];
                            let mut n = [[f32::NAN; LANES]; 3];
                            let mut c = [[7u8; LANES]; 3];
                            let asked = colors.then_some(&mut c);
                            cut.vertex_lanes(&h, first, count, &mut p, &mut n, asked);
                            for k in 0..LANES {
                                let want = match k < count {
                                    true => cut.vertex(&h, first + k),
                                    false => VertexOut::default(),
                                };
                                let got = VertexOut {
                                    position: [0, 1, 2].map(|a| p[a][k]),
                                    normal: [0, 1, 2].map(|a| n[a][k]),
                                    color: match colors {
                                        true => [0, 1, 2].map(|a| c[a][k]),
                                        false => want.color,
                                    },
                                };
                                assert_eq!(
                                    bits(got),
                                    bits(want),
                                    "frame {frame}, {coloring:?}, slot {first} + {k} of {count}"
                                );
                            }
                            if !colors {
                                assert_eq!(c, [[7; LANES]; 3], "colours written unasked");
                            }
                        }
                    }
                }
            }
        }
        assert!(
            mixed > 0 && plain > 0,
            "{mixed} batches blending, {plain} not"
        );
    }

    #[test]
    fn geomorphs_blend_and_settle() {
        let bytes = sphere_bytes();
        let h = HierarchyView::parse(&bytes).unwrap();
        let policy = ScreenError::new(2.0);
        let mut cut = blending_cut(&h);
        let far = orbit(0, 30.0);
        let near = orbit(0, 2.0);
        for _ in 0..20 {
            cut.adapt(&h, &far, &policy, &Budget::default());
        }
        let settled = |cut: &Mid| {
            positions(cut, &h)
                .iter()
                .zip(cut.nodes())
                .all(|(p, &n)| *p == h.node(n).position)
        };
        assert!(settled(&cut));
        let s = cut.adapt(&h, &near, &policy, &Budget::default());
        assert!(s.vsplits > 0 && s.blending > 0, "{s:?}");
        assert!(!settled(&cut));
        // Blending vertices lie on the segment from their parent's position to their own.
        for _ in 0..12 {
            cut.adapt(&h, &near, &policy, &Budget::default());
        }
        assert!(settled(&cut));
        // Moving away again blends the collapses before doing them.
        let s = cut.adapt(&h, &far, &policy, &Budget::default());
        assert_eq!(s.ecols, 0);
        assert!(s.blending > 0);
        let mut ecols = 0;
        for _ in 0..300 {
            ecols += cut.adapt(&h, &far, &policy, &Budget::default()).ecols;
            cut.check(&h).unwrap();
        }
        assert!(ecols > 0);
        assert!(settled(&cut));
    }
}

#[test]
fn the_budget_table_of_docs_runtime() {
    // A cut for a budget of B triangles: F = B triangle slots, V = F / 2, Q = V / 8.
    assert_eq!(Cut::<500, 1000, 62>::BYTES, 32_092);
    assert_eq!(Cut::<1000, 2000, 125>::BYTES, 63_868);
    assert_eq!(Cut::<2500, 5000, 312>::BYTES, 159_092);
    assert_eq!(Cut::<5000, 10000, 625>::BYTES, 317_868);
}

#[test]
fn the_figures_of_the_benchmark_cuts_in_docs_runtime() {
    assert_eq!(Cut::<16384, 32768, 2048>::BYTES, 1_040_752);
    assert_eq!(Cut::<262144, 524288, 32768, u32>::BYTES, 25_035_120);
}

#[test]
fn the_tag_is_the_blend_entry_or_the_expiry_never_both() {
    use super::expiry::{Mark, TURNING};
    let mut v = store::Vertices::<4, u16>::new();
    for node in 0..3 {
        v.push(node, VISIBLE).unwrap();
    }
    v.mark(0, Mark::Settled(10));
    v.mark(1, Mark::Settled(40_000));
    v.mark(2, Mark::Restless);
    assert_eq!(
        (v.flags[0] & SETTLED, v.expiry(0), v.blend(0)),
        (SETTLED, 10, NIL)
    );
    assert_eq!(v.flags[2] & (SETTLED | RESTLESS), RESTLESS);
    // Settling a vertex in a geomorph is refused; a blend unsettles.
    v.flags[2] |= BLENDING;
    v.set_blend(2, 3);
    v.mark(2, Mark::Settled(10));
    assert_eq!((v.flags[2] & SETTLED, v.blend(2)), (0, 3));
    v.set_blend(1, 0);
    assert_eq!(v.flags[1] & SETTLED, 0);
    v.mark(1, Mark::Settled(20_000));
    v.push(3, VISIBLE).unwrap();
    v.mark(3, Mark::Settled(TURNING | 20_000));
    // The first count lowered by 16,384 with the counts at 100 and 3,700: 10 had expired,
    // 20,000 lives on as 3,616; the one on the turning count stays as it was.
    v.rebase([100, 3_700], [16_384, 0]);
    assert_eq!(v.flags[0] & SETTLED, 0);
    assert_eq!((v.flags[1] & SETTLED, v.expiry(1)), (SETTLED, 3_616));
    assert_eq!(
        (v.flags[3] & SETTLED, v.expiry(3)),
        (SETTLED, TURNING | 20_000)
    );
    // Then the turning count, to 3,616: it lives on as 3,616, and expires past it.
    v.rebase([100, 3_616], [0, 16_384]);
    assert_eq!(
        (v.flags[3] & SETTLED, v.expiry(3)),
        (SETTLED, TURNING | 3_616)
    );
    v.rebase([100, 3_617], [0, 0]);
    assert_eq!(v.flags[3] & SETTLED, 0);
    assert_eq!((v.flags[1] & SETTLED, v.expiry(1)), (SETTLED, 3_616));
    v.unsettle_all();
    assert!(v.flags[..4].iter().all(|f| f & (SETTLED | RESTLESS) == 0));
}

#[test]
fn blends_stop_where_a_sixteen_bit_tag_can_no_longer_name_them() {
    // A 32-bit cut whose queues hold more entries than a vertex's 16-bit tag can name: past
    // 65,535 running blends a new one is refused (the change then lands unblended), never
    // stored under a truncated entry.
    type Wide = Cut<64, 128, 70_000, u32>;
    assert_eq!(Wide::BLEND_ROOM, 65_535);
    assert_eq!(Cut::<64, 128, 8>::BLEND_ROOM, 8);
    let (p, t) = grid(4);
    let bytes = build_it(&p, &t, BuildOptions::default()).to_bytes(false);
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut: Box<Wide> = Cut::boxed();
    cut.reset(&h).unwrap();
    cut.set_geomorph_frames(4);
    // Fill the arena up to the last entry a tag can name, as if that many blends ran.
    while cut.blends.len() < Wide::BLEND_ROOM - 1 {
        cut.blends.push(blend::Blend::ZERO).unwrap();
    }
    // The last one that fits is taken and named exactly; the next is refused.
    assert!(cut.start_blend(&h, 0, false));
    assert_eq!(cut.v.blend(0), 65_534);
    assert!(!cut.start_blend(&h, 1, false));
    assert_eq!(cut.v.blend(1), NIL);
    assert_eq!(cut.v.flags[1] & (BLENDING | COLLAPSING), 0);
    assert_eq!(cut.blends.len(), Wide::BLEND_ROOM);
}
