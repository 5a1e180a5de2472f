//! The runtime cut on the fixtures: long random camera paths, checked after every frame.
//!
//! Each path mixes close-ups (the eye near or inside the bounding box), far views, views from
//! inside the frustum and looking away from the mesh, changing tolerances, budgets and
//! geomorphs. After every frame the cut must be an oriented manifold without cracks with the
//! input's Euler characteristic and border loops, within the triangle budget; a second run must
//! give the same cut bit for bit.

mod common;

use common::fly::{fly, hierarchy_and_ids, hierarchy_bytes, node_triangles, Path};
use common::{fixture, sorted};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::ScreenError;

/// A desktop cut (32-bit indices) that holds every fixture at full detail.
type TestCut = Cut<{ 1 << 16 }, { 1 << 17 }, { 1 << 13 }, u32>;

fn long_path(name: &str, frames: u32) {
    let mesh = fixture(name);
    let bytes = hierarchy_bytes(&mesh);
    let first = fly::<{ 1 << 16 }, { 1 << 17 }, { 1 << 13 }, u32>(&bytes, &mesh, frames, 7);
    let second = fly::<{ 1 << 16 }, { 1 << 17 }, { 1 << 13 }, u32>(&bytes, &mesh, frames, 7);
    assert_eq!(first, second, "{name}: a second run differs");
    // A 16-bit cut with the same queues flies the same path to the same cuts when the mesh fits
    // it (the index width is not part of the input; capacities are only where one binds).
    if mesh.triangles.len() < 65_534 {
        let small = fly::<32_767, 65_534, { 1 << 13 }, u16>(&bytes, &mesh, frames, 7);
        let differs = first.iter().zip(&small).position(|(a, b)| a != b);
        assert_eq!(
            differs, None,
            "{name}: the 16-bit cut differs from frame {differs:?} on"
        );
    }
    // The path moved the cut.
    let mut distinct = first.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(
        distinct.len() > frames as usize / 4,
        "{name}: the cut hardly moved"
    );
}

#[test]
fn cow_over_a_long_random_path() {
    long_path("cow.obj", 1200);
}

#[test]
fn open_head_over_a_long_random_path() {
    long_path("head.obj", 1000);
}

#[test]
fn genus_one_elk_over_a_long_random_path() {
    long_path("elk.obj", 1000);
}

#[test]
fn cad_fandisk_over_a_long_random_path() {
    long_path("fandisk.obj", 1000);
}

#[test]
fn bunny_over_a_long_random_path() {
    long_path("bunny.obj", 1000);
}

#[test]
fn full_refinement_reproduces_every_fixture() {
    for name in ["bunny.obj", "cow.obj", "head.obj", "elk.obj", "fandisk.obj"] {
        let mesh = fixture(name);
        let (bytes, ids) = hierarchy_and_ids(&mesh);
        let input: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| ids[v as usize]))
            .collect();
        let (ok, base) = {
            let h = HierarchyView::parse(&bytes).unwrap();
            let mut cut: Box<TestCut> = Cut::boxed();
            cut.reset(&h).unwrap();
            let base = cut.triangles().len();
            while cut.refine_everything(&h) > 0 {}
            cut.check(&h).unwrap();
            (node_triangles(&cut) == sorted(&input), base)
        };
        assert!(ok, "{name}: full refinement is not the input");
        assert!(base > 0);
    }
}

#[test]
fn a_small_cut_reports_capacity_instead_of_failing() {
    let mesh = fixture("cow.obj");
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut: Box<Cut<256, 512, 64>> = Cut::boxed();
    cut.reset(&h).unwrap();
    let b = mesh.bounds();
    let mut path = Path::new(3);
    let mut limited = false;
    for _ in 0..100 {
        let view = path.view(b.center().to_array(), b.radius());
        let s = cut.adapt(&h, &view, &ScreenError::new(0.25), &Budget::default());
        cut.check(&h).unwrap();
        limited |= s.capacity_limited || s.queue_overflow;
        assert!(cut.vertex_count() <= 256 && cut.triangles().len() <= 512);
    }
    assert!(limited);
}

/// Adapting the same view a second time does nothing when no budget, capacity or operation cap
/// binds: one call reaches the cut the view asks for.
#[test]
fn one_call_converges_over_the_peer_orbit() {
    use vdlod_core::policy::QRefine;
    use vdlod_demo::camera::peer_orbit;
    let mesh = fixture("bunny.obj");
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    for tau in [0.25f32, 0.5, 1.0, 2.0, 4.0] {
        let mut cut = Cut::<16384, 32768, 2048>::boxed();
        cut.reset(&h).unwrap();
        let policy = QRefine::new(tau);
        let mut again = 0;
        for i in 0..40 {
            let view = orbit.camera(i * 5).view();
            let first = cut.adapt(&h, &view, &policy, &Budget::default());
            assert!(
                !first.queue_overflow && !first.capacity_limited,
                "{tau} px, frame {i}: {first:?}"
            );
            let second = cut.adapt(&h, &view, &policy, &Budget::default());
            again += second.vsplits + second.ecols;
        }
        assert_eq!(again, 0, "{tau} px: a second call still split or collapsed");
    }
}

/// The same model at scales from 1e-5 to 2e5, framed the same way, gives the same cut (within
/// 1% of the triangles) at the same pixel tolerance: positions and bounds are stored relative to
/// the model's bounding box.
#[test]
fn the_cut_does_not_depend_on_the_model_scale() {
    use vdlod_core::policy::QRefine;
    use vdlod_demo::camera::peer_orbit;
    let cow = fixture("cow.obj");
    let mut counts = Vec::new();
    for scale in [1e-5f32, 1.0, 1e3, 2e5] {
        let mut mesh = cow.clone();
        for p in &mut mesh.positions {
            *p = p.map(|c| c * scale);
        }
        let bytes = hierarchy_bytes(&mesh);
        let h = HierarchyView::parse(&bytes).unwrap();
        let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
        let mut cut = Cut::<8192, 16384, 1024>::boxed();
        cut.reset(&h).unwrap();
        let mut total = 0u64;
        for i in 0..10 {
            let view = orbit.camera(i * 20).view();
            total += cut
                .adapt(&h, &view, &QRefine::new(1.0), &Budget::default())
                .triangles as u64;
        }
        counts.push((scale, total));
    }
    let reference = counts[1].1 as f64;
    for (scale, total) in counts {
        let ratio = total as f64 / reference;
        assert!(
            (0.99..=1.01).contains(&ratio),
            "scale {scale}: {total} triangles against {reference}"
        );
    }
}

/// `adapt` and the draw of its output need little stack: 150 frames of the bunny under a
/// 5,000-triangle budget with geomorphs (splits, collapses, forced splits, trades), each drawn at
/// 320x240, on a thread whose whole stack is `STACK` bytes. Rust threads have a guard page, so an
/// overflow aborts the test process instead of passing unnoticed.
#[test]
fn adapt_and_draw_fit_a_small_stack() {
    use vdlod_core::policy::QRefine;
    use vdlod_demo::camera::peer_orbit;
    use vdlod_demo::frame::Frame;
    use vdlod_demo::render::style;
    use vdlod_raster::Shading;
    const STACK: usize = 16 * 1024;
    let mesh = fixture("bunny.obj");
    let bytes = hierarchy_bytes(&mesh);
    let bounds = mesh.bounds();
    let mut cut = Cut::<2600, 5000, 325>::boxed();
    let mut frame = Frame::new(320, 240).unwrap();
    let worker = std::thread::Builder::new()
        .stack_size(STACK)
        .spawn(move || {
            let h = HierarchyView::parse(&bytes).unwrap();
            cut.reset(&h).unwrap();
            cut.set_geomorph_frames(4);
            let orbit = peer_orbit(&bounds, 100, 320, 240);
            let budget = Budget {
                max_triangles: 5000,
                ..Budget::default()
            };
            let mut drawn = 0;
            for i in 0..150 {
                let camera = orbit.camera(i);
                let tolerance = [0.25, 1.0, 4.0][(i / 50) as usize];
                vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(tolerance), &budget).unwrap();
                let style = style(Shading::Gouraud, false);
                drawn += frame
                    .draw_cut(&*cut, &h, &camera, &style)
                    .unwrap()
                    .rasterized;
            }
            drawn
        });
    assert!(worker.unwrap().join().unwrap() > 0);
}

/// On an open mesh the outline honours the pixel tolerance: the coverage of the adapted head
/// (three holes) and of the full-detail head, drawn without back-face culling and refined
/// without the back-face test (so that what is drawn is what the policy looked at), lie within
/// about a pixel of each other. (Before border leaves bounded the error across the normal, a
/// coarse border edge cut across the notches of the fine one: 20 px at a 1 px tolerance.)
#[test]
fn open_borders_honour_the_tolerance() {
    use vdlod_core::policy::{Frustum, ScreenError};
    use vdlod_demo::camera::peer_orbit;
    use vdlod_demo::frame::{Frame, BACKGROUND};
    use vdlod_demo::render::style;
    use vdlod_raster::Shading;
    let (w, h_px) = (240usize, 180usize);
    let mesh = fixture("head.obj");
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let orbit = peer_orbit(&mesh.bounds(), 8, w, h_px);
    let mut cut = Cut::<4096, 8192, 512>::boxed();
    cut.reset(&h).unwrap();
    let (mut adapted, mut full) = (Frame::new(w, h_px).unwrap(), Frame::new(w, h_px).unwrap());
    let mask = |f: &Frame| -> Vec<bool> { f.pixels().iter().map(|p| *p != BACKGROUND).collect() };
    // The largest distance from a pixel covered in one mask to the nearest of the other.
    let stray = |a: &[bool], b: &[bool]| -> f64 {
        let theirs: Vec<(i64, i64)> = (0..w * h_px)
            .filter(|&i| b[i])
            .map(|i| ((i % w) as i64, (i / w) as i64))
            .collect();
        (0..w * h_px)
            .filter(|&i| a[i] && !b[i])
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                let d2 = theirs
                    .iter()
                    .map(|&(u, v)| (u - x).pow(2) + (v - y).pow(2))
                    .min();
                (d2.unwrap_or(0) as f64).sqrt()
            })
            .fold(0.0, f64::max)
    };
    let mut worst = 0.0f64;
    for i in 0..8 {
        let camera = orbit.camera(i);
        let s = vdlod::adapt(
            &mut cut,
            &h,
            &camera,
            &(Frustum, ScreenError::new(1.0)),
            &Budget::default(),
        )
        .unwrap();
        assert!(
            s.triangles < mesh.triangles.len() as u32 / 2,
            "frame {i}: {s:?}"
        );
        let style = vdlod::Style {
            cull_back_faces: false,
            ..style(Shading::Gouraud, false)
        };
        adapted.draw_cut(&*cut, &h, &camera, &style).unwrap();
        full.draw(&mesh.as_raster_mesh(), &style.params(&camera))
            .unwrap();
        let (a, b) = (mask(&adapted), mask(&full));
        worst = worst.max(stray(&a, &b)).max(stray(&b, &a));
    }
    assert!(
        worst <= 1.5,
        "the outline strays {worst:.1} px at a 1 px tolerance"
    );
}

/// A policy that asks every vertex every frame: the same demands as the one it wraps, but no
/// envelope and no sphere-only promise, so the cut neither decides vertices from their digests
/// nor skips settled ones.
struct Opaque<P>(P);

impl<P: vdlod_core::policy::Policy> vdlod_core::policy::Policy for Opaque<P> {
    fn demand(
        &self,
        b: &vdlod_core::policy::Bounds,
        view: &vdlod_core::policy::View,
    ) -> vdlod_core::policy::Demand {
        self.0.demand(b, view)
    }
}

/// Skipping settled vertices changes no frame: over the peer orbit (without and then with
/// geomorphs), a drifting path with jumps, zooms, pauses and a changing tolerance, and a phase
/// with a binding budget and an operation cap, the cut (and its blended positions) is the one the
/// same cut makes with settling off, and it does skip most vertices on the orbit. Until geomorphs
/// first come on, it is also the cut of a policy without an envelope, whose vertices are all
/// asked every frame (with geomorphs, a vertex decided from its digest counts as seen when its
/// sphere is in the frustum, an asked one when the policy sees it, so blends may differ).
#[test]
fn settled_vertices_change_no_frame() {
    use vdlod_core::policy::QRefine;
    for name in ["bunny.obj", "head.obj"] {
        settling_changes_no_frame(name, |tau, _| QRefine::new(tau), 1.0, 3);
    }
}

/// The same under the merge-tree paper's policy, which refines to the leaves near the eye and
/// in a narrowed frustum: its envelope settles the vertices that stay out of the frustum or
/// beyond the near zone, the leaves (whatever their own answer), and the pairs whose parent
/// stays near and in view.
#[test]
fn settled_vertices_change_no_frame_under_the_merge_tree() {
    use vdlod_core::policy::MergeTree;
    // Most of the head's cut is near the eye, refined to leaves, which settle because a leaf
    // never splits (a quarter of its vertices were skipped before they did, half now).
    for (name, share) in [("bunny.obj", 2), ("head.obj", 3)] {
        settling_changes_no_frame(
            name,
            |tau, radius| MergeTree {
                near: 1.5 * radius / tau,
            },
            0.4,
            share,
        );
    }
}

/// The merge-tree paper's level orbit, finely stepped, with narrowed frustums: the camera turns
/// about the vertical, so the cut soon counts its turns about that axis, where a vertex's
/// distance from a top or bottom plane hardly moves (see `cut/rigid.rs`). Settling must still
/// change no frame, and must skip more than it did about the centre alone.
#[test]
fn settling_about_the_orbits_axis_changes_no_frame_under_the_merge_tree() {
    use vdlod_core::policy::MergeTree;
    use vdlod_demo::camera::merge_tree_orbit;
    type C = Cut<32_767, 65_534, 4096>;
    let mesh = fixture("bunny.obj");
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let b = mesh.bounds();
    let orbit = merge_tree_orbit(&b, 400, 640, 480);
    let policy = MergeTree {
        near: 2.0 * b.radius(),
    };
    let [mut skipping, mut asked] = [C::boxed(), C::boxed()];
    asked.set_settling(false);
    for cut in [&mut skipping, &mut asked] {
        cut.reset(&h).unwrap();
    }
    let (mut settled, mut vertices) = (0u64, 0u64);
    for i in 0..240u32 {
        let size = if i < 120 { 0.4 } else { 0.2 };
        let view = orbit.camera(i).view_scaled(size);
        let s = skipping.adapt(&h, &view, &policy, &Budget::default());
        let a = asked.adapt(&h, &view, &policy, &Budget::default());
        assert_eq!(s.visited + s.settled, a.visited, "frame {i}");
        assert_eq!(
            node_triangles(&skipping),
            node_triangles(&asked),
            "frame {i}: the cuts differ"
        );
        settled += u64::from(s.settled);
        vertices += u64::from(s.vertices);
    }
    // 86% of the vertices are skipped a frame (84% when the turns count about the centre).
    assert!(
        settled * 100 > vertices * 85,
        "only {settled} of {vertices} vertices skipped"
    );
}

/// Flies `name` with and without settling under `policy(tau, model radius)` (`tau` 1, 0.5 or
/// 2), the orbit's frustum scaled by `scale`, and checks that the cuts agree and that at least
/// one vertex in `share` was skipped on the orbit.
fn settling_changes_no_frame<P: vdlod_core::policy::Policy + Copy>(
    name: &str,
    policy: impl Fn(f32, f32) -> P,
    scale: f32,
    share: u64,
) {
    use vdlod_core::policy::View;
    use vdlod_demo::camera::peer_orbit;
    type C = Cut<32_767, 65_534, 4096>;
    let mesh = fixture(name);
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let b = mesh.bounds();
    let (c, r) = (b.center().to_array(), b.radius());
    let orbit = peer_orbit(&b, 200, 640, 480);
    let mut path = Path::new(11);
    let mut views: Vec<(View, f32)> = (0..240)
        .map(|i| (orbit.camera(i).view_scaled(scale), 1.0))
        .collect();
    let mut held = path.view(c, r);
    for i in 0..240u32 {
        // Pauses (the same view again), drift with jumps, and a new tolerance now and then.
        if i % 40 >= 8 {
            held = path.view(c, r);
        }
        views.push((held, [0.5, 2.0][(i / 60) as usize % 2]));
    }
    let [mut skipping, mut asked, mut opaque] = [C::boxed(), C::boxed(), C::boxed()];
    asked.set_settling(false);
    for cut in [&mut skipping, &mut asked, &mut opaque] {
        cut.reset(&h).unwrap();
    }
    let positions = |cut: &C| -> Vec<[u32; 3]> {
        (0..cut.vertex_count())
            .map(|s| cut.vertex(&h, s).position.map(f32::to_bits))
            .collect()
    };
    let (mut settled, mut vertices, mut skipped_blending) = (0u64, 0u64, 0u64);
    for (i, (view, tau)) in views.iter().enumerate() {
        // Geomorphs over the second revolution and parts of the path.
        let frames = if (120..240).contains(&i) || (300..380).contains(&i) {
            4
        } else {
            0
        };
        skipping.set_geomorph_frames(frames);
        asked.set_geomorph_frames(frames);
        let budget = if (320..380).contains(&i) {
            Budget {
                max_triangles: 3000,
                max_ops: 40,
                ..Budget::default()
            }
        } else {
            Budget::default()
        };
        let policy = policy(*tau, r);
        let s = skipping.adapt(&h, view, &policy, &budget);
        let a = asked.adapt(&h, view, &policy, &budget);
        assert_eq!(a.settled, 0);
        // A skipped vertex is one not asked.
        assert_eq!(s.visited + s.settled, a.visited, "{name}, frame {i}");
        assert_eq!(
            FrameStats {
                settled: 0,
                visited: a.visited,
                ..s
            },
            a,
            "{name}, frame {i}: the stats differ"
        );
        assert_eq!(
            node_triangles(&skipping),
            node_triangles(&asked),
            "{name}, frame {i}: the cuts differ"
        );
        assert_eq!(
            positions(&skipping),
            positions(&asked),
            "{name}, frame {i}: the blended positions differ"
        );
        if i < 120 {
            let o = opaque.adapt(&h, view, &Opaque(policy), &budget);
            assert_eq!(o, a, "{name}, frame {i}: asking every vertex differs");
            assert_eq!(node_triangles(&opaque), node_triangles(&asked));
            settled += s.settled as u64;
            vertices += s.vertices as u64;
        } else if frames > 0 {
            skipped_blending += s.settled as u64;
        }
    }
    assert!(
        settled * share > vertices,
        "{name}: only {settled} of {vertices} vertices skipped on the orbit"
    );
    assert!(
        skipped_blending > 0,
        "{name}: nothing skipped with geomorphs"
    );
}

/// Regulation towards a triangle target does not overshoot with geomorphs: coarsening lands a
/// level per blend, and raising the threshold every frame meanwhile drove the cut far below the
/// target (a 4-frame blend took a 2,000-triangle target on the armadillo down to 774 triangles).
/// From well above the target, with 4-frame geomorphs, the bunny's cut never falls more than 10%
/// below it and settles within 5% of it.
#[test]
fn regulation_does_not_overshoot_with_geomorphs() {
    use vdlod_core::policy::QRefine;
    use vdlod_demo::camera::peer_orbit;
    let mesh = fixture("bunny.obj");
    let bytes = hierarchy_bytes(&mesh);
    let h = HierarchyView::parse(&bytes).unwrap();
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    let mut cut = Cut::<16384, 32768, 2048>::boxed();
    cut.reset(&h).unwrap();
    cut.set_geomorph_frames(4);
    let policy = QRefine::new(0.25);
    let budget = Budget {
        target_triangles: 2000,
        ..Budget::default()
    };
    // Well above the target first (0.25 px wants about 11,000 triangles).
    let first = cut.adapt(&h, &orbit.camera(0).view(), &policy, &Budget::default());
    assert!(first.triangles > 8000, "{first:?}");
    let mut least = u32::MAX;
    let mut last = 0;
    for i in 1..80 {
        let s = cut.adapt(&h, &orbit.camera(i).view(), &policy, &budget);
        least = least.min(s.triangles);
        last = s.triangles;
    }
    assert!(least >= 1800, "fell to {least} triangles");
    assert!((1900..=2100).contains(&last), "ended at {last} triangles");
}

/// A policy that reads only bounding spheres is answered from the cut's digests instead of the
/// file's records ([`vdlod_core::policy::Policy::sphere_only`]), and its envelope settles
/// vertices: the same cut, stats and positions in every frame as when the same policy does not say so, over the merge-tree
/// paper's level orbit (scaled frustums, near limits) and a random path, with and without
/// geomorphs.
#[test]
fn sphere_only_policies_decide_from_digests_exactly() {
    use vdlod_core::policy::{MergeTree, Policy, View};
    use vdlod_demo::camera::merge_tree_orbit;
    type C = Cut<32_767, 65_534, 4096>;
    for name in ["bunny.obj", "head.obj"] {
        let mesh = fixture(name);
        let bytes = hierarchy_bytes(&mesh);
        let h = HierarchyView::parse(&bytes).unwrap();
        let b = mesh.bounds();
        let (c, r) = (b.center().to_array(), b.radius());
        let orbit = merge_tree_orbit(&b, 60, 640, 480);
        let mut path = Path::new(5);
        let views: Vec<(View, f32)> = (0..240u32)
            .map(|i| {
                let near = [f32::INFINITY, 2.0 * r, 1.5 * r][(i / 40) as usize % 3];
                if i < 120 {
                    let size = [0.4, 0.2, 0.1][(i / 20) as usize % 3];
                    (orbit.camera(i).view_scaled(size), near)
                } else {
                    (path.view(c, r), near)
                }
            })
            .collect();
        let [mut digest, mut records] = [C::boxed(), C::boxed()];
        for cut in [&mut digest, &mut records] {
            cut.reset(&h).unwrap();
        }
        let mut changed = 0;
        for (i, (view, near)) in views.iter().enumerate() {
            let frames = if (60..100).contains(&i) || i >= 200 {
                4
            } else {
                0
            };
            digest.set_geomorph_frames(frames);
            records.set_geomorph_frames(frames);
            let policy = MergeTree { near: *near };
            assert!(policy.sphere_only() && !Opaque(policy).sphere_only());
            let d = digest.adapt(&h, view, &policy, &Budget::default());
            let a = records.adapt(&h, view, &Opaque(policy), &Budget::default());
            // The policy's envelope also lets the digest cut skip settled vertices.
            assert_eq!(d.visited + d.settled, a.visited, "{name}, frame {i}");
            assert_eq!(
                FrameStats {
                    settled: 0,
                    visited: a.visited,
                    ..d
                },
                a,
                "{name}, frame {i}: the stats differ"
            );
            assert_eq!(
                node_triangles(&digest),
                node_triangles(&records),
                "{name}, frame {i}: the cuts differ"
            );
            for s in 0..digest.vertex_count() {
                let (x, y) = (digest.vertex(&h, s), records.vertex(&h, s));
                assert_eq!(x.position.map(f32::to_bits), y.position.map(f32::to_bits));
            }
            changed += (d.vsplits + d.ecols > 0) as u32;
        }
        assert!(
            changed > 100,
            "{name}: the cut hardly moved ({changed} frames)"
        );
    }
}
