//! The wavelet cut on generated meshes: closure, exact counts and a crack-free mesh after every
//! frame of random camera paths, full refinement giving the finest level, and convergence.

use alloc::vec;
use alloc::vec::Vec;

use super::build::{interpolate, SemiRegular};
use super::{SemiRegularView, WaveletCut};
use crate::adapt::{Budget, FrameStats};
use crate::policy::{MergeTree, Policy, QRefine, ScreenError, View};

type Cut = WaveletCut<1024, 16_384, 8_192, 4_096>;

fn sphere(levels: u32) -> Vec<u8> {
    SemiRegular::sphere(levels).unwrap().to_bytes().unwrap()
}

/// A xorshift stream in `[0, 1)`.
struct Rng(u32);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
}

fn random_view(rng: &mut Rng) -> View {
    let d = 1.3 + 6.0 * rng.next();
    let (a, b) = (core::f32::consts::TAU * rng.next(), 3.0 * rng.next() - 1.5);
    let eye = [
        d * libm::cosf(a) * libm::cosf(b),
        d * libm::sinf(b),
        d * libm::sinf(a) * libm::cosf(b),
    ];
    let target = [
        0.6 * rng.next() - 0.3,
        0.6 * rng.next() - 0.3,
        0.6 * rng.next() - 0.3,
    ];
    View::look_at(eye, target, [0.0, 1.0, 0.0], 0.9, 4.0 / 3.0, 480.0)
}

/// A budget of at most `most` triangles (from `least`) every `every`-th frame, none otherwise.
fn sometimes(frame: u32, every: u32, least: u32, most: f32, rng: &mut Rng) -> Budget {
    if frame.is_multiple_of(every) {
        Budget {
            max_triangles: least + (rng.next() * most) as u32,
            ..Budget::default()
        }
    } else {
        Budget::default()
    }
}

/// Flies `cut` over `frames` random views with the policy and budget `pick` gives each frame,
/// checking the invariants (`closed`: every edge has two sides) and the budget after each, and
/// hands every frame to `each`.
fn fly_random(
    cut: &mut Cut,
    s: &SemiRegularView<'_>,
    rng: &mut Rng,
    frames: u32,
    closed: bool,
    pick: impl Fn(u32, &mut Rng) -> (QRefine, Budget),
    mut each: impl FnMut(u32, &FrameStats, &Cut),
) {
    let mut scratch = vec![[0u32; 2]; 3 * 16_384];
    cut.check(s, closed, &mut scratch).unwrap();
    for frame in 0..frames {
        let view = random_view(rng);
        let (policy, budget) = pick(frame, rng);
        let stats = cut.adapt(s, &view, &policy, &budget);
        cut.check(s, closed, &mut scratch)
            .unwrap_or_else(|d| panic!("frame {frame}: {d}"));
        assert!(stats.triangles <= budget.max_triangles, "frame {frame}");
        each(frame, &stats, cut);
    }
}

#[test]
fn random_camera_paths_keep_the_mesh_closed_and_the_counts_exact() {
    let bytes = sphere(4);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    let mut seen = (u32::MAX, 0);
    let pick = |frame, rng: &mut Rng| {
        let tol = 0.25 + 4.0 * rng.next();
        let policy = QRefine {
            error: ScreenError {
                silhouette: tol,
                interior: tol * 7.0,
            },
        };
        (policy, sometimes(frame, 3, 300, 2000.0, rng))
    };
    fly_random(
        &mut cut,
        &s,
        &mut Rng(0x9E37_79B9),
        300,
        true,
        pick,
        |_, stats, cut| {
            assert_eq!(stats.triangles as usize, cut.triangles().len());
            seen = (seen.0.min(stats.triangles), seen.1.max(stats.triangles));
        },
    );
    // The paths went from coarse to fine.
    assert!(seen.0 < 400 && seen.1 > 500, "{seen:?}");
}

#[test]
fn full_refinement_is_the_finest_level() {
    let mesh = SemiRegular::sphere(3).unwrap();
    let bytes = mesh.to_bytes().unwrap();
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    let view = View::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.9, 1.0, 480.0);
    let stats = cut.adapt(&s, &view, &ScreenError::new(1e-9), &Budget::default());
    assert_eq!(cut.included(), s.wavelets());
    assert_eq!(stats.triangles, 8 * 64);
    let mut scratch = vec![[0u32; 2]; 3 * 512];
    cut.check(&s, true, &mut scratch).unwrap();
    // The same triangles as the finest level, vertex for vertex.
    let mut want: Vec<[u32; 3]> = mesh
        .finest_triangles()
        .iter()
        .map(|&t| rotate_min(t))
        .collect();
    let mut got: Vec<[u32; 3]> = cut
        .triangles()
        .iter()
        .map(|t| rotate_min(t.map(|x| cut.vertex_id(x as usize))))
        .collect();
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, want);
    for i in 0..cut.vertex_count() {
        assert_eq!(cut.position(i), s.position(cut.vertex_id(i)));
    }
}

fn rotate_min(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap();
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

#[test]
fn a_second_call_with_the_same_view_does_nothing() {
    let bytes = sphere(5);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    let mut rng = Rng(7);
    for _ in 0..20 {
        let view = random_view(&mut rng);
        let policy = QRefine::new(0.5 + 2.0 * rng.next());
        cut.adapt(&s, &view, &policy, &Budget::default());
        let again = cut.adapt(&s, &view, &policy, &Budget::default());
        assert_eq!((again.vsplits, again.ecols), (0, 0));
    }
}

#[test]
fn the_importance_test_subdivides_important_triangles_facing_the_eye() {
    use crate::policy::{Frustum, Importance};
    let bytes = sphere(5);
    let s = SemiRegularView::parse(&bytes).unwrap();
    // Close in front of the sphere, seeing all of it: the cap facing the eye is near and seen
    // face-on; the cap behind faces exactly away, so its triangles weigh nothing.
    let view = View::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.0, 480.0);
    let policy = (
        Frustum,
        Importance::new(2e-3, 2.0 * crate::root::sqrtf(3.0)),
    );
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    let first = cut.adapt(&s, &view, &policy, &Budget::default());
    assert!(first.vsplits > 0 && first.triangles < 8192, "{first:?}");
    // Judged on coarser triangles than the wavelets themselves: one call settles.
    let again = cut.adapt(&s, &view, &policy, &Budget::default());
    assert_eq!((again.vsplits, again.ecols), (0, 0));
    let cap = |front: bool| {
        (s.counts().base_vertices..s.vertices())
            .filter(|&v| cut.includes(v))
            .filter(|&v| {
                let z = s.position(v)[2];
                if front {
                    z > 0.8
                } else {
                    z < -0.8
                }
            })
            .count()
    };
    // Triangles are counter-clockwise from outside: were they not, the front cap would weigh
    // as little as the back one does.
    let (front, back) = (cap(true), cap(false));
    assert!(front > 4 * back.max(1), "{front} in front, {back} behind");
    // The vertex alone wants nothing: a policy that does not judge triangles keeps the base.
    let mut plain = Cut::boxed();
    plain.reset(&s).unwrap();
    let none = plain.adapt(&s, &view, &Frustum, &Budget::default());
    assert_eq!(none.vsplits, 0);
}

#[test]
fn the_budget_keeps_the_largest_errors() {
    let bytes = sphere(5);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    let view = View::look_at([0.0, 0.0, 2.5], [0.0; 3], [0.0, 1.0, 0.0], 0.9, 1.0, 480.0);
    let free = cut.adapt(&s, &view, &QRefine::new(0.5), &Budget::default());
    cut.reset(&s).unwrap();
    let budget = Budget {
        max_triangles: free.triangles / 3,
        ..Budget::default()
    };
    let capped = cut.adapt(&s, &view, &QRefine::new(0.5), &budget);
    assert!(capped.budget_limited);
    assert!(capped.triangles <= budget.max_triangles);
    assert!(
        capped.triangles + 8 >= budget.max_triangles / 2,
        "{capped:?}"
    );
}

#[test]
fn geomorphs_blend_and_settle() {
    let bytes = sphere(4);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    cut.set_geomorph_frames(4);
    let mut blended = 0;
    let pick = |frame, rng: &mut Rng| {
        let policy = QRefine::new(0.3 + 3.0 * rng.next());
        (policy, sometimes(frame, 4, 200, 1500.0, rng))
    };
    fly_random(
        &mut cut,
        &s,
        &mut Rng(0x1234_5678),
        200,
        true,
        pick,
        |_, stats, _| {
            blended = blended.max(stats.blending);
        },
    );
    assert!(blended > 0);
    // A joining wavelet starts on its parent edge; a still view settles every blend, and every
    // member is then at its own position.
    let view = View::look_at([0.0, 0.3, 2.2], [0.0; 3], [0.0, 1.0, 0.0], 0.9, 1.0, 480.0);
    cut.reset(&s).unwrap();
    cut.adapt(&s, &view, &QRefine::new(4.0), &Budget::default());
    let first = cut.adapt(&s, &view, &QRefine::new(0.5), &Budget::default());
    assert!(first.vsplits > 0 && first.blending > 0, "{first:?}");
    for _ in 0..5 {
        cut.adapt(&s, &view, &QRefine::new(0.5), &Budget::default());
    }
    let settled = cut.adapt(&s, &view, &QRefine::new(0.5), &Budget::default());
    assert_eq!(
        (settled.blending, settled.vsplits, settled.ecols),
        (0, 0, 0)
    );
    for i in 0..cut.vertex_count() {
        let id = cut.vertex_id(i);
        if id < 6 || cut.includes(id) {
            assert_eq!(cut.position(i), s.position(id));
        }
    }
    // Coarser again: wavelets leave over four frames, then are gone.
    let leave = cut.adapt(&s, &view, &QRefine::new(4.0), &Budget::default());
    assert!(leave.ecols > 0 && leave.blending > 0);
    assert_eq!(
        leave.triangles, settled.triangles,
        "leaving wavelets stay until they are flat"
    );
    for _ in 0..8 {
        cut.adapt(&s, &view, &QRefine::new(4.0), &Budget::default());
    }
    let gone = cut.adapt(&s, &view, &QRefine::new(4.0), &Budget::default());
    assert_eq!(gone.blending, 0);
    assert!(gone.triangles < settled.triangles);
}

#[test]
fn the_cut_costs_under_32_bytes_per_triangle_beside_its_bits() {
    // With V = T / 2 and Q = T / 8: 12 B per triangle slot (corners, vertex map, tile, next in
    // the tile's list), 20 per vertex slot (id, position, uses and flags, list link), 30 per
    // queue entry (candidate, geomorph, dirty run, a tile's head), 24 per word of bits
    // (included, holding a member child, present, blending, settled, quiet), and under 512 B of
    // counts, list heads, the previous view and the anchor frame.
    type C = WaveletCut<128, 5000, 2500, 625>;
    let arenas = 5000 * 12 + 2500 * 20 + 625 * 30 + 128 * 24;
    assert!(
        C::BYTES >= arenas && C::BYTES <= arenas + 512,
        "{}",
        C::BYTES
    );
    let per_triangle = (C::BYTES - 128 * 24) as f64 / 5000.0;
    assert!(per_triangle <= 26.0, "{per_triangle}");
    // With the bits of 32,768 wavelets (the engines experiment's cut), under 32 B in all.
    type Engines = WaveletCut<1024, 5000, 2500, 625>;
    let in_all = Engines::BYTES as f64 / 5000.0;
    assert!(in_all <= 32.0, "{in_all}");
}

#[test]
fn a_cut_needs_a_tile_per_base_face() {
    let bytes = sphere(2);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut small = WaveletCut::<16, 1024, 600, 4>::boxed();
    let err = small.reset(&s).unwrap_err();
    assert_eq!(err, super::WaveletCutError::Tiles { faces: 8, tiles: 4 });
    assert!(alloc::format!("{err}").contains("raise Q"), "{err}");
    let mut enough = WaveletCut::<16, 1024, 600, 8>::boxed();
    enough.reset(&s).unwrap();
    assert_eq!(enough.triangles().len(), 8);
}

/// A bumpy open grid: 4 x 4 squares of two triangles, subdivided four times.
fn open_grid() -> Vec<u8> {
    let n = 4;
    let base: Vec<[f32; 3]> = (0..=n * n + 2 * n)
        .map(|i| {
            [
                (i % (n + 1)) as f32 * 0.5 - 1.0,
                (i / (n + 1)) as f32 * 0.5 - 1.0,
                0.0,
            ]
        })
        .collect();
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let v = (y * (n + 1) + x) as u32;
            let w = n as u32 + 1;
            faces.push([v, v + 1, v + w + 1]);
            faces.push([v, v + w + 1, v + w]);
        }
    }
    let steps = 16.0;
    SemiRegular::from_fn(&base, &faces, 4, |f, w| {
        let p = interpolate(faces[f as usize].map(|v| base[v as usize]), w, steps);
        [
            p[0],
            p[1],
            0.15 * libm::sinf(5.0 * p[0]) * libm::cosf(4.0 * p[1]),
        ]
    })
    .unwrap()
    .to_bytes()
    .unwrap()
}

#[test]
fn an_open_mesh_keeps_its_invariants_over_random_paths() {
    let bytes = open_grid();
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut cut = Cut::boxed();
    cut.reset(&s).unwrap();
    cut.set_geomorph_frames(3);
    let mut most = 0;
    let pick = |frame, rng: &mut Rng| {
        let policy = QRefine::new(0.25 + 3.0 * rng.next());
        (policy, sometimes(frame, 2, 100, 3000.0, rng))
    };
    fly_random(
        &mut cut,
        &s,
        &mut Rng(0xDEAD_BEEF),
        200,
        false,
        pick,
        |frame, stats, cut| {
            most = most.max(stats.triangles);
            // An edge with one side lies on the grid's border: no crack inside.
            let mut sides = alloc::collections::BTreeMap::new();
            for t in cut.triangles() {
                for k in 0..3 {
                    let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                    *sides.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            let on_border = |i: usize| {
                let p = cut.position(i);
                (p[0].abs() - 1.0).abs() < 1e-3 || (p[1].abs() - 1.0).abs() < 1e-3
            };
            for (&(a, b), &n) in &sides {
                assert!(
                    n == 2 || (on_border(a) && on_border(b)),
                    "frame {frame}: crack at {a}-{b}"
                );
            }
        },
    );
    assert!(most > 1000, "{most}");
}

/// Where the camera of [`smooth_view`] is at `frame`.
fn smooth_eye(frame: u32) -> [f32; 3] {
    let a = frame as f32 * 0.004;
    let d = 2.2 + 0.8 * libm::sinf(frame as f32 * 0.01);
    [d * libm::cosf(a), 0.3 * d, d * libm::sinf(a)]
}

/// A camera circling the sphere in small steps, so that anchors hold for several frames.
fn smooth_view(frame: u32) -> View {
    let eye = smooth_eye(frame);
    View::look_at(eye, [0.1, 0.0, 0.0], [0.0, 1.0, 0.0], 0.9, 4.0 / 3.0, 480.0)
}

#[test]
fn settling_skips_work_but_changes_no_frame() {
    let policy = QRefine {
        error: ScreenError {
            silhouette: 0.5,
            interior: 3.5,
        },
    };
    // Most of the members were skipped on most frames.
    settling_changes_no_frame(&policy, smooth_view, 400 * 100);
}

/// The same under the merge-tree paper's policy (near the eye and in a narrowed frustum: the
/// near zone of its envelope).
#[test]
fn settling_under_the_merge_tree_changes_no_frame() {
    let narrow = |frame| {
        let eye = smooth_eye(frame);
        View::with_frustum_scale(
            eye,
            [0.1, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            0.9,
            4.0 / 3.0,
            480.0,
            0.4,
        )
    };
    settling_changes_no_frame(&MergeTree { near: 2.4 }, narrow, 400 * 400);
}

/// Flies the level-5 sphere with and without settling under `policy`, seen by `view(frame)`:
/// the same meshes every frame, and more than `least` wavelets skipped in all.
fn settling_changes_no_frame<P: Policy>(policy: &P, view: impl Fn(u32) -> View, least: u32) {
    let bytes = sphere(5);
    let s = SemiRegularView::parse(&bytes).unwrap();
    let mut skipping = Cut::boxed();
    let mut asking = Cut::boxed();
    for cut in [&mut skipping, &mut asking] {
        cut.reset(&s).unwrap();
    }
    asking.set_settling(false);
    let (mut skipped, mut changed) = (0, 0);
    for frame in 0..400 {
        let view = view(frame);
        // Geomorphs on for the second half, and now and then a budget.
        let morphs = if frame >= 200 { 4 } else { 0 };
        skipping.set_geomorph_frames(morphs);
        asking.set_geomorph_frames(morphs);
        let budget = if frame % 50 == 25 {
            Budget {
                max_triangles: 400,
                ..Budget::default()
            }
        } else {
            Budget::default()
        };
        let a = skipping.adapt(&s, &view, policy, &budget);
        let b = asking.adapt(&s, &view, policy, &budget);
        assert_eq!(b.settled, 0);
        skipped += a.settled;
        assert_eq!(
            (a.triangles, a.vsplits, a.ecols),
            (b.triangles, b.vsplits, b.ecols),
            "frame {frame}"
        );
        assert_eq!(skipping.triangles(), asking.triangles(), "frame {frame}");
        let ids = |c: &Cut| {
            (0..c.vertex_count())
                .map(|i| (c.vertex_id(i), c.position(i)))
                .collect::<Vec<_>>()
        };
        assert_eq!(ids(&skipping), ids(&asking), "frame {frame}");
        changed += u32::from(a.vsplits + a.ecols > 0);
    }
    assert!(skipped > least, "{skipped}");
    assert!(changed > 50, "the mesh changed in only {changed} frames");
}

/// A mesh as sets: triangles by vertex id, and each vertex's id and position bits.
type MeshSet = (Vec<[u32; 3]>, Vec<(u32, [u32; 3])>);

/// The mesh a cut emits as a set: triangles by vertex id (each from its smallest id), and each
/// live vertex's id and position.
fn mesh_set(c: &Cut) -> MeshSet {
    let id = |i: usize| c.vertex_id(i);
    let mut tris: Vec<[u32; 3]> = c
        .triangles()
        .iter()
        .map(|t| rotate_min(t.map(|v| id(v as usize))))
        .collect();
    tris.sort_unstable();
    let mut vertices: Vec<(u32, [u32; 3])> = (0..c.vertex_count())
        .filter(|&i| id(i) != u32::MAX)
        .map(|i| (id(i), c.position(i).map(f32::to_bits)))
        .collect();
    vertices.sort_unstable();
    (tris, vertices)
}

#[test]
fn emitting_the_changed_tiles_gives_the_mesh_emitting_all_does() {
    let sphere = sphere(5);
    let grid = open_grid();
    for (bytes, closed) in [(&sphere, true), (&grid, false)] {
        let s = SemiRegularView::parse(bytes).unwrap();
        let mut partial = Cut::boxed();
        let mut whole = Cut::boxed();
        for cut in [&mut partial, &mut whole] {
            cut.reset(&s).unwrap();
        }
        whole.set_partial_emission(false);
        let mut rng = Rng(0x5eed_1234);
        let mut scratch = vec![[0u32; 2]; 3 * 16_384];
        let (mut moved, mut holes) = (0u32, 0usize);
        for frame in 0..600 {
            // Random views now and then, small steps between; geomorphs in the second half.
            let view = if frame % 40 == 0 {
                random_view(&mut rng)
            } else {
                smooth_view(frame)
            };
            let morphs = if frame >= 300 { 5 } else { 0 };
            let budget = sometimes(frame, 7, 200, 3_000.0, &mut rng);
            let policy = QRefine::new(0.5 + 4.0 * rng.next());
            for cut in [&mut partial, &mut whole] {
                cut.set_geomorph_frames(morphs);
            }
            let a = partial.adapt(&s, &view, &policy, &budget);
            let b = whole.adapt(&s, &view, &policy, &budget);
            partial
                .check(&s, closed, &mut scratch)
                .unwrap_or_else(|d| panic!("frame {frame}: {d}"));
            assert_eq!((a.triangles, a.vertices), (b.triangles, b.vertices));
            assert_eq!(mesh_set(&partial), mesh_set(&whole), "frame {frame}");
            moved += u32::from(partial.triangles() != whole.triangles());
            holes = holes.max(partial.vertex_count() - partial.live_vertices());
        }
        // The partial cut did emit in its own order, and left holes it reused.
        assert!(moved > 50 && holes > 0, "{moved} {holes}");
    }
}
