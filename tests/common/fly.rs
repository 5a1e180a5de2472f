//! Random camera paths over a cut, checked after every frame.
//!
//! Each path mixes close-ups (the eye near or inside the bounding box), far views, views from
//! inside the frustum and looking away from the mesh, changing tolerances, budgets, operation
//! caps, visit windows and geomorphs. After every frame the cut must be an oriented manifold without cracks with the
//! input's Euler characteristic and border loops, within the triangle budget.

use super::{sorted, topology};
use vdlod_core::adapt::Budget;
use vdlod_core::build::{build, BuildOptions, InputMesh};
use vdlod_core::cut::{Cut, SlotIndex};
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::{BackFace, Frustum, ScreenError, View};
use vdlod_demo::mesh::IndexedMesh;

pub fn hierarchy_bytes(mesh: &IndexedMesh) -> Vec<u8> {
    hierarchy_and_ids(mesh).0
}

/// The file, and the node id it gives each input vertex.
pub fn hierarchy_and_ids(mesh: &IndexedMesh) -> (Vec<u8>, Vec<u32>) {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: mesh.colors.as_deref(),
        triangles: &mesh.triangles,
    };
    let h = build(&input, &BuildOptions::default(), &mut |_| {}).unwrap();
    (h.to_bytes(false), h.file_ids())
}

pub fn node_triangles<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    cut: &Cut<V, F, Q, I>,
) -> Vec<[u32; 3]> {
    let nodes = cut.nodes();
    let t: Vec<[u32; 3]> = cut
        .triangles()
        .iter()
        .map(|t| t.map(|s| nodes[s.index()]))
        .collect();
    sorted(&t)
}

pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// One frame of a random walk around a mesh of centre `c` and radius `r`.
pub struct Path {
    pub rng: Rng,
    azimuth: f32,
    elevation: f32,
    distance: f32,
    look_away: bool,
}

impl Path {
    pub fn new(seed: u64) -> Path {
        Path {
            rng: Rng(seed),
            azimuth: 0.0,
            elevation: 0.2,
            distance: 3.0,
            look_away: false,
        }
    }

    pub fn view(&mut self, c: [f32; 3], r: f32) -> View {
        let rng = &mut self.rng;
        self.azimuth += 0.2 * (rng.next() - 0.3);
        self.elevation = (self.elevation + 0.1 * (rng.next() - 0.5)).clamp(-1.4, 1.4);
        // Mostly drift; now and then jump near (even inside the bounding sphere) or far.
        self.distance = match (rng.next() * 20.0) as u32 {
            0 => 0.2 + rng.next() * 0.8,
            1 => 5.0 + rng.next() * 20.0,
            _ => (self.distance * (0.9 + 0.2 * rng.next())).clamp(0.2, 25.0),
        };
        if rng.next() < 0.05 {
            self.look_away = !self.look_away;
        }
        let (ce, se) = (self.elevation.cos(), self.elevation.sin());
        let dir = [ce * self.azimuth.cos(), se, ce * self.azimuth.sin()];
        let eye = [0, 1, 2].map(|k| c[k] + dir[k] * self.distance * r);
        let target = if self.look_away {
            [0, 1, 2].map(|k| eye[k] + dir[k])
        } else {
            [0, 1, 2].map(|k| c[k] + (rng.next() - 0.5) * r * 0.5)
        };
        View::look_at(eye, target, [0.0, 1.0, 0.0], 1.0, 4.0 / 3.0, 480.0)
    }
}

/// Flies `frames` random frames; returns a fingerprint of every frame's cut.
pub fn fly<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    bytes: &[u8],
    mesh: &IndexedMesh,
    frames: u32,
    seed: u64,
) -> Vec<u64> {
    let h = HierarchyView::parse(bytes).unwrap();
    let expected = topology(&mesh.triangles);
    let b = mesh.bounds();
    let (c, r) = (b.center().to_array(), b.radius());
    let mut cut = Cut::<V, F, Q, I>::boxed();
    cut.reset(&h).unwrap();
    let mut path = Path::new(seed);
    let mut prints = Vec::new();
    let full = mesh.triangles.len() as u32;
    for i in 0..frames {
        let view = path.view(c, r);
        let k = path.rng.next();
        let tolerance = [0.5, 1.0, 2.0, 4.0][(k * 4.0) as usize % 4];
        let max = [u32::MAX, full / 3, full / 8, full / 20][(i / 97) as usize % 4];
        let budget = Budget {
            max_triangles: max.max(h.base_triangles() + 2),
            max_ops: if i % 7 == 0 { 50 } else { u32::MAX },
            max_visits: if i % 150 < 40 { 150 } else { u32::MAX },
            ..Budget::default()
        };
        cut.set_geomorph_frames(((i / 50) % 3) as u16 * 2);
        let policy = (Frustum, (BackFace, ScreenError::new(tolerance)));
        let s = cut.adapt(&h, &view, &policy, &budget);
        if let Err(d) = cut.check(&h) {
            panic!("frame {i}: {d:?}");
        }
        let tris = node_triangles(&cut);
        assert_eq!(topology(&tris), expected, "frame {i}: topology changed");
        assert!(
            s.triangles <= budget.max_triangles && !s.over_budget,
            "frame {i}: {s:?} over {}",
            budget.max_triangles
        );
        if budget.max_ops != u32::MAX {
            assert!(
                s.vsplits + s.ecols - s.budget_ecols <= budget.max_ops,
                "frame {i}: {s:?}"
            );
        }
        let mut fp = 0xcbf2_9ce4_8422_2325u64;
        for v in tris.iter().flatten().copied().chain(
            (0..cut.vertex_count()).flat_map(|s| cut.vertex(&h, s).position.map(f32::to_bits)),
        ) {
            fp = (fp ^ v as u64).wrapping_mul(0x100_0000_01b3);
        }
        prints.push(fp);
    }
    prints
}
