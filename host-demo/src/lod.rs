//! The `orbit` command: a view-dependent cut flown around a mesh, frame by frame, beside the
//! full-detail mesh, with statistics, a plot and an image comparison.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::time::Instant;

use vdlod::{CutMesh, Style, WaveletMesh};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::cut::{Coloring, Cut, SlotIndex};
use vdlod_core::format::{HierarchyView, NONE};
use vdlod_core::policy::{
    BackFace, Bounds as NodeBounds, Demand, Envelope, Frustum, HoppeError, Importance, MergeTree,
    Policy, QRefine, ScreenError, View,
};
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
use vdlod_raster::{Rgba8, Shading, VertexIndex};

use crate::camera::{merge_tree_orbit, peer_orbit, Camera, Orbit};
use crate::chart::{self, Panel, BLUE, GREY, ORANGE};
use crate::frame::{encode_png, Frame, FrameError};
use crate::ground::{draw_on_ground, GroundTexture};
use crate::label;
use crate::mesh::{vertex_normals, Bounds, IndexedMesh};
use crate::render::style;
use crate::stats::median;
use crate::wavelet::DemoWaveletCut;

/// Calls `$body` with `$cut` bound to a new boxed cut of the smallest capacity class that holds
/// `$vertices` vertices and `$triangles` triangles: 16-bit cuts up to 32,767 vertices and 65,534
/// triangles, then 32-bit cuts of 2^18, 2^20 and 2^22 vertices (twice the triangles), each with a
/// queue of an eighth of its vertices. A cut is made on the heap directly, never on the stack, and
/// its untouched pages cost nothing.
macro_rules! with_cut {
    ($vertices:expr, $triangles:expr, |$cut:ident| $body:expr) => {{
        let (v, f): (u64, u64) = ($vertices, $triangles);
        if v <= 4096 && f <= 8192 {
            let mut $cut = Cut::<4096, 8192, 512>::boxed();
            $body
        } else if v <= 16384 && f <= 32768 {
            let mut $cut = Cut::<16384, 32768, 2048>::boxed();
            $body
        } else if v <= 32767 && f <= 65534 {
            let mut $cut = Cut::<32767, 65534, 4096>::boxed();
            $body
        } else if v <= 1 << 18 && f <= 1 << 19 {
            let mut $cut = Cut::<{ 1 << 18 }, { 1 << 19 }, { 1 << 15 }, u32>::boxed();
            $body
        } else if v <= 1 << 20 && f <= 1 << 21 {
            let mut $cut = Cut::<{ 1 << 20 }, { 1 << 21 }, { 1 << 17 }, u32>::boxed();
            $body
        } else {
            let mut $cut = Cut::<{ 1 << 22 }, { 1 << 23 }, { 1 << 19 }, u32>::boxed();
            $body
        }
    }};
}

/// Vertices and triangles a cut of `h` needs for full detail, or at most `max_triangles`: a
/// connected surface has at most two more vertices than triangles, plus one per root that no
/// triangle uses (every component adds two; roots bound components).
pub fn cut_size(h: &HierarchyView<'_>, max_triangles: u32) -> (u64, u64) {
    let full = h.base_triangles() as u64 + 2 * (h.nodes() - h.leaves()) as u64;
    let triangles = full
        .min(max_triangles as u64)
        .max(h.base_triangles() as u64);
    let roots = h.roots() as u64;
    let vertices = (h.leaves() as u64).min(triangles + 2 * roots + 2);
    (vertices, triangles)
}

/// Which policy decides where detail goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PolicyChoice {
    /// Frustum, back-face and screen-space error with silhouette and interior tolerances (px).
    Screen {
        /// Silhouette tolerance in pixels.
        silhouette: f32,
        /// Interior tolerance in pixels.
        interior: f32,
    },
    /// The merge-tree paper's `shouldRefine`: everything in the (scaled) frustum and near the
    /// eye, to the leaves.
    MergeTree {
        /// How near, in radii of the model's bounding sphere (infinite: everything in the
        /// frustum).
        near: f32,
    },
    /// The importance paper's triangle importance over a threshold, in the frustum.
    Importance {
        /// Threshold.
        threshold: f32,
    },
}

/// Settings of [`run_orbit`].
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitOptions {
    /// Frame width in pixels.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
    /// Frames in one revolution.
    pub frames: u32,
    /// The merge-tree paper's frustum size: the refinement frustum's width and height relative
    /// to the camera's.
    pub frustum: f32,
    /// The policy.
    pub policy: PolicyChoice,
    /// Triangle budget.
    pub budget: Budget,
    /// Geomorph length in frames.
    pub geomorph_frames: u16,
    /// False colour by forest depth.
    pub depth_colors: bool,
    /// Draw triangle edges.
    pub wireframe: bool,
    /// Write each frame's active mesh as `mesh_NNNN.obj`.
    pub dump_mesh: bool,
    /// Write `frame_NNNN.png` (the statistics, plot and comparison are always written).
    pub write_frames: bool,
    /// Fly the peer orbit (20 degrees up) instead of the merge-tree paper's (level).
    pub peer_orbit: bool,
    /// Draw the written frames from an observer a quarter turn ahead and a quarter farther (the cut
    /// still adapts to the orbit camera), to show where the detail went; with a `path`, from above.
    pub observer: bool,
    /// Fly these cameras, one per frame, instead of an orbit (`frames` should be their number).
    pub path: Option<Vec<Camera>>,
    /// Draw a terrain with its colours as a texture over the ground (the full-detail frames
    /// too) instead of a colour per vertex.
    pub ground: Option<GroundTexture>,
}

impl Default for OrbitOptions {
    fn default() -> Self {
        OrbitOptions {
            width: 640,
            height: 480,
            frames: 72,
            frustum: 1.0,
            policy: PolicyChoice::Screen {
                silhouette: 1.0,
                interior: 1.0,
            },
            budget: Budget::default(),
            geomorph_frames: 4,
            depth_colors: false,
            wireframe: false,
            dump_mesh: false,
            write_frames: true,
            peer_orbit: false,
            observer: false,
            path: None,
            ground: None,
        }
    }
}

/// One frame's figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitFrame {
    /// Frame number.
    pub index: u32,
    /// What the cut did.
    pub stats: FrameStats,
    /// Microseconds in [`Cut::adapt`].
    pub adapt_us: f64,
    /// Microseconds drawing the cut.
    pub render_us: f64,
    /// Microseconds drawing the full-detail mesh.
    pub full_render_us: f64,
    /// PSNR of the adapted frame against the full-detail frame, in dB (infinite when equal).
    pub psnr_db: f64,
    /// Triangles not in the previous frame's mesh (all of them in the first frame).
    pub new_triangles: u32,
}

/// A camera a quarter turn ahead of frame `i`'s and a quarter farther from the centre.
pub fn observer(orbit: &Orbit, i: u32) -> Camera {
    let ahead = orbit.camera(i + orbit.frames / 4);
    let eye = orbit.center + (ahead.eye - orbit.center) * 1.25;
    Camera {
        eye,
        near: (orbit.distance * 1.25 - 1.5 * orbit.radius).max(orbit.radius * 0.01),
        far: orbit.distance * 1.25 + 1.5 * orbit.radius,
        ..ahead
    }
}

/// A camera high above `bounds`, looking down at its centre at 60 degrees: where a path's
/// observer watches from.
pub fn overview(bounds: &Bounds, width: usize, height: usize) -> Camera {
    let (center, radius) = (bounds.center(), bounds.radius().max(f32::MIN_POSITIVE));
    let eye = center + glam::Vec3::new(0.0, 1.3, 0.9) * radius;
    Camera {
        eye,
        target: center,
        up: glam::Vec3::Y,
        fov_y: 50f32.to_radians(),
        near: radius * 0.5,
        far: radius * 4.0,
        width,
        height,
    }
}

/// The full-detail mesh of a hierarchy: every split done, in leaf numbering. Also proves the file
/// consistent with its mesh (the cut's invariants hold and every leaf is reached).
pub fn full_detail(h: &HierarchyView<'_>) -> Result<IndexedMesh, String> {
    let (v, f) = cut_size(h, u32::MAX);
    with_cut!(v, f, |cut| full_detail_with(h, &mut cut))
}

fn full_detail_with<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    h: &HierarchyView<'_>,
    cut: &mut Cut<V, F, Q, I>,
) -> Result<IndexedMesh, String> {
    cut.reset(h).map_err(|e| e.to_string())?;
    while cut.refine_everything(h) > 0 {}
    let leaves: Vec<u32> = h.leaf_nodes().collect();
    let positions: Vec<[f32; 3]> = leaves.iter().map(|&i| h.node(i).position).collect();
    let nodes = cut.nodes();
    // Vertices numbered by leaf index (NONE for a corner that is not a leaf).
    let triangles: Vec<[u32; 3]> = cut
        .triangles()
        .iter()
        .map(|t| t.map(|s| h.leaf_index(nodes[s.index()]).unwrap_or(NONE)))
        .collect();
    cut.check(h).map_err(|d| {
        format!(
            "the file contradicts its own mesh: {} (slot {})",
            d.what, d.slot
        )
    })?;
    if triangles.iter().flatten().any(|&v| v == NONE) {
        return Err(if cut.vertex_count() >= V || triangles.len() + 2 > F {
            format!("full detail needs more than the largest cut's {V} vertices and {F} triangles")
        } else {
            "full refinement does not reach every input vertex: the file's split records \
             contradict its mesh (forged or corrupted)"
                .into()
        });
    }
    let colors = h
        .has_colors()
        .then(|| leaves.iter().map(|&i| h.node(i).color).collect());
    let mut mesh = IndexedMesh {
        normals: vertex_normals(&positions, &triangles),
        positions,
        colors,
        triangles,
    };
    mesh.reorder_for_locality();
    Ok(mesh)
}

/// Bounds of the hierarchy's leaves.
pub fn leaf_bounds(h: &HierarchyView<'_>) -> Bounds {
    let mut min = glam::Vec3::splat(f32::INFINITY);
    let mut max = glam::Vec3::splat(f32::NEG_INFINITY);
    for i in h.leaf_nodes() {
        let p = glam::Vec3::from(h.node(i).position);
        min = min.min(p);
        max = max.max(p);
    }
    Bounds { min, max }
}

/// The policy a [`PolicyChoice`] names, dispatched by a `match` per call (a trait object would
/// cost an indirect call per vertex, about half of a frame's adaptation time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DemoPolicy {
    /// [`QRefine`].
    Screen(QRefine),
    /// [`HoppeError`] in the [`Frustum`], facing the eye: `qrefine` for files with Hoppe's
    /// bounds.
    Hoppe((Frustum, (BackFace, HoppeError))),
    /// [`MergeTree`].
    MergeTree(MergeTree),
    /// [`Importance`] in the [`Frustum`].
    Importance((Frustum, Importance)),
}

impl Policy for DemoPolicy {
    #[inline]
    fn demand(&self, b: &NodeBounds, view: &View) -> Demand {
        match self {
            DemoPolicy::Screen(p) => p.demand(b, view),
            DemoPolicy::Hoppe(p) => p.demand(b, view),
            DemoPolicy::MergeTree(p) => p.demand(b, view),
            DemoPolicy::Importance(p) => p.demand(b, view),
        }
    }

    #[inline]
    fn envelope(&self, view: &View) -> Option<Envelope> {
        match self {
            DemoPolicy::Screen(p) => p.envelope(view),
            DemoPolicy::Hoppe(p) => p.envelope(view),
            DemoPolicy::MergeTree(p) => p.envelope(view),
            DemoPolicy::Importance(p) => p.envelope(view),
        }
    }

    #[inline]
    fn sphere_only(&self) -> bool {
        match self {
            DemoPolicy::Screen(p) => p.sphere_only(),
            DemoPolicy::Hoppe(p) => p.sphere_only(),
            DemoPolicy::MergeTree(p) => p.sphere_only(),
            DemoPolicy::Importance(p) => p.sphere_only(),
        }
    }

    #[inline]
    fn judges_triangles(&self) -> bool {
        matches!(self, DemoPolicy::Importance(_))
    }

    #[inline]
    fn triangle(&self, corners: &[[f32; 3]; 3], reach: f32, view: &View) -> f32 {
        match self {
            DemoPolicy::Importance(p) => p.triangle(corners, reach, view),
            _ => 0.0,
        }
    }
}

/// The policy for `choice` on a model in the box `bounding_box` (its diagonal sizes the
/// importance test); screen-space tolerances read Hoppe's bound where the file has it
/// (`hoppe_bounds`).
pub fn make_policy(
    choice: PolicyChoice,
    bounding_box: ([f32; 3], [f32; 3]),
    hoppe_bounds: bool,
) -> DemoPolicy {
    match choice {
        PolicyChoice::Screen {
            silhouette,
            interior,
        } => {
            let error = ScreenError {
                silhouette,
                interior,
            };
            if hoppe_bounds {
                DemoPolicy::Hoppe((Frustum, (BackFace, HoppeError { error })))
            } else {
                DemoPolicy::Screen(QRefine { error })
            }
        }
        PolicyChoice::MergeTree { near } => {
            let radius = (glam::Vec3::from(bounding_box.1) - glam::Vec3::from(bounding_box.0))
                .length()
                * 0.5;
            DemoPolicy::MergeTree(MergeTree {
                near: near * radius,
            })
        }
        PolicyChoice::Importance { threshold } => {
            DemoPolicy::Importance((Frustum, Importance::for_box(threshold, bounding_box)))
        }
    }
}

/// A mesh's triangles over global vertex ids (hierarchy nodes, wavelet vertices), each from its
/// smallest corner, sorted: what [`new_triangles`] compares from frame to frame.
pub fn triangle_set(triangles: impl Iterator<Item = [u32; 3]>) -> Vec<[u32; 3]> {
    let mut v: Vec<[u32; 3]> = triangles
        .map(|t| {
            let m = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
            [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
        })
        .collect();
    v.sort_unstable();
    v
}

/// Each node's vertex, as [`triangle_set`] names it: the node itself, or, for a parent that
/// repeats a child's vertex bit for bit (position, normal and colour, as a hierarchy built with
/// `--placement endpoint` does), that child's name. A split then leaves the triangles around the
/// child that stays where its parent was as they were, and they do not count as new.
pub fn vertex_names(h: &HierarchyView<'_>) -> Vec<u32> {
    let key = |i: u32| {
        let (p, n, c) = h.vertex(i);
        (p.map(f32::to_bits), n.map(f32::to_bits), c)
    };
    // A child's id is larger than its parent's: from the last node down, every child is named
    // before its parent.
    let mut names: Vec<u32> = (0..h.nodes()).collect();
    for n in (0..h.nodes()).rev().filter(|&n| h.is_parent(n)) {
        let k = key(n);
        if let Some(c) = h.children(n).into_iter().find(|&c| key(c) == k) {
            names[n as usize] = names[c as usize];
        }
    }
    names
}

/// A vertex cut's triangles as [`triangle_set`] compares them, each corner by its node's
/// [`vertex_names`] entry.
pub fn cut_triangle_set<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    cut: &Cut<V, F, Q, I>,
    names: &[u32],
) -> Vec<[u32; 3]> {
    let nodes = cut.nodes();
    triangle_set(
        cut.triangles()
            .iter()
            .map(|t| t.map(|i| names[nodes[i.index()] as usize])),
    )
}

/// How many of `now` are not in `before` (both from [`triangle_set`]): ROAM's measure of how
/// much a frame changed.
pub fn new_triangles(before: &[[u32; 3]], now: &[[u32; 3]]) -> u32 {
    now.iter()
        .filter(|t| before.binary_search(t).is_err())
        .count() as u32
}

/// PSNR in dB of `a` against `b` over the RGB channels (infinite when equal).
pub fn psnr(a: &[Rgba8], b: &[Rgba8]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    let sum: u64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| {
            (0..3)
                .map(|k| {
                    let d = x.0[k] as i64 - y.0[k] as i64;
                    (d * d) as u64
                })
                .sum::<u64>()
        })
        .sum();
    if sum == 0 {
        return f64::INFINITY;
    }
    let mse = sum as f64 / (3 * n) as f64;
    10.0 * (255.0f64 * 255.0 / mse).log10()
}

/// Adapted frame, full-detail frame and their difference (amplified 4x, red where the adapted
/// frame differs) side by side.
pub fn side_by_side(width: usize, height: usize, a: &[Rgba8], b: &[Rgba8]) -> Vec<Rgba8> {
    let mut out = vec![Rgba8([255; 4]); width * 3 * height];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let row = y * width * 3;
            out[row + x] = a[i];
            out[row + width + x] = b[i];
            let d = (0..3)
                .map(|k| (a[i].0[k] as i32 - b[i].0[k] as i32).unsigned_abs())
                .max()
                .unwrap_or(0);
            let v = (d * 4).min(255) as u8;
            out[row + 2 * width + x] = Rgba8([255, 255 - v, 255 - v, 255]);
        }
    }
    out
}

/// The smallest 1, 2 or 5 times a power of ten not below `v`.
/// A plot of triangles (top, blue) and milliseconds (bottom: adapt + render in orange, the
/// full-detail render in grey) per frame, labelled.
pub fn plot(frames: &[OrbitFrame]) -> Result<Vec<u8>, FrameError> {
    let tris: Vec<f64> = frames.iter().map(|f| f.stats.triangles as f64).collect();
    let ours: Vec<f64> = frames
        .iter()
        .map(|f| (f.adapt_us + f.render_us) / 1e3)
        .collect();
    let full: Vec<f64> = frames.iter().map(|f| f.full_render_us / 1e3).collect();
    let panels = [
        Panel {
            title: vec![("triangles per frame", BLUE)],
            series: vec![(tris, BLUE)],
        },
        Panel {
            title: vec![
                ("ms per frame: adapt + render", ORANGE),
                (", full detail", GREY),
            ],
            series: vec![(full, GREY), (ours, ORANGE)],
        },
    ];
    chart::panels(&panels).map_err(FrameError::Png)
}

/// The three panels of [`side_by_side`] as a PNG, each with its caption along the top.
fn captioned(
    width: usize,
    height: usize,
    pixels: &[Rgba8],
    captions: &[String; 3],
) -> Result<Vec<u8>, String> {
    let mut bytes = encode_png(width * 3, height, pixels).map_err(|e| e.to_string())?;
    let mut pixmap = tiny_skia::Pixmap::decode_png(&bytes).map_err(|e| e.to_string())?;
    let scale = if width >= 320 { 2.0 } else { 1.0 };
    for (k, text) in captions.iter().enumerate() {
        let ink = if k == 2 {
            (150, 20, 20)
        } else {
            (225, 225, 225)
        };
        label::draw(&mut pixmap, text, (k * width) as f32 + 6.0, 6.0, scale, ink);
    }
    bytes = pixmap.encode_png().map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Writes the cut's mesh as an OBJ file (positions as blended, 1-based faces).
pub fn write_obj<const V: usize, const F: usize, const Q: usize, I: SlotIndex>(
    path: &Path,
    cut: &Cut<V, F, Q, I>,
    h: &HierarchyView<'_>,
) -> std::io::Result<()> {
    let positions: Vec<[f32; 3]> = (0..cut.vertex_count())
        .map(|i| cut.vertex(h, i).position)
        .collect();
    let triangles = cut.triangles().iter().map(|t| t.map(|i| i.index() as u32));
    let s = crate::mesh::obj_text(&positions, None, triangles);
    std::fs::write(path, s)
}

/// What [`run_orbit`] measured over the whole orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitSummary {
    /// Per frame.
    pub frames: Vec<OrbitFrame>,
    /// Frame whose comparison went into `side_by_side.png`.
    pub compared: u32,
    /// Whether the screen-space test was Hoppe's (the file has his bounds).
    pub hoppe_test: bool,
}

/// Each limit of [`FrameStats`] with its name: `budget`, `ops`, `capacity`, `queue`, `blend`,
/// `over-budget`.
fn limit_flags(stats: &FrameStats) -> [(bool, &'static str); 6] {
    [
        (stats.budget_limited, "budget"),
        (stats.ops_limited, "ops"),
        (stats.capacity_limited, "capacity"),
        (stats.queue_overflow, "queue"),
        (stats.blend_limited, "blend"),
        (stats.over_budget, "over-budget"),
    ]
}

/// The limits a frame hit, by name, joined with `+`; empty when none.
pub fn limits(stats: &FrameStats) -> String {
    let hit: Vec<&str> = limit_flags(stats)
        .iter()
        .filter(|n| n.0)
        .map(|n| n.1)
        .collect();
    hit.join("+")
}

impl OrbitSummary {
    /// How many frames hit each limit, as `name in N` items (see [`limits`]); empty when none did.
    pub fn limit_counts(&self) -> String {
        let mut counts = [0usize; 6];
        for f in &self.frames {
            for (count, (hit, _)) in counts.iter_mut().zip(limit_flags(&f.stats)) {
                *count += usize::from(hit);
            }
        }
        let names = limit_flags(&FrameStats::default()).map(|(_, name)| name);
        let hit: Vec<String> = counts
            .iter()
            .zip(names)
            .filter(|(n, _)| **n > 0)
            .map(|(n, name)| format!("{name} in {n}"))
            .collect();
        hit.join(", ")
    }

    /// Median of a per-frame figure over the frames after the first (the first refines from the
    /// base mesh and is reported on its own).
    pub fn median_after_first(&self, f: impl Fn(&OrbitFrame) -> f64) -> f64 {
        median(self.frames.iter().skip(1).map(f).collect())
    }

    /// Mean of a per-frame figure over the frames after the first.
    pub fn mean_after_first(&self, f: impl Fn(&OrbitFrame) -> f64) -> f64 {
        let v: Vec<f64> = self.frames.iter().skip(1).map(f).collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }
}

/// Flies the orbit: adapts the cut, draws it and the full-detail mesh, writes `frame_NNNN.png`,
/// `stats.csv`, `plot.png`, `side_by_side.png` (and `mesh_NNNN.obj` with `dump_mesh`) into
/// `out_dir`. `report` is called after each frame.
pub fn run_orbit(
    bytes: &[u8],
    full: &IndexedMesh,
    opts: &OrbitOptions,
    out_dir: &Path,
    mut report: impl FnMut(&OrbitFrame),
) -> Result<OrbitSummary, String> {
    if bytes.starts_with(&vdlod_core::wavelet::format::MAGIC) {
        let s = SemiRegularView::parse(bytes).map_err(|e| e.to_string())?;
        if opts.depth_colors {
            return Err("--depth-colors needs the vertex forest (a .vdh file or a mesh)".into());
        }
        if opts.budget.max_visits != u32::MAX {
            return Err("--max-visits needs the vertex forest (a .vdh file or a mesh)".into());
        }
        let triangles = s
            .counts()
            .finest_faces()
            .min(opts.budget.max_triangles as u64);
        if s.wavelets() <= 8192 * 32 && triangles <= 60_000 {
            let mut cut = DemoWaveletCut::boxed();
            let engine = Wavelets::new(&s, &mut cut, opts)?;
            return fly_orbit(engine, full, opts, out_dir, &mut report);
        }
        let mut cut = LargeWaveletCut::boxed();
        let engine = Wavelets::new(&s, &mut cut, opts)?;
        return fly_orbit(engine, full, opts, out_dir, &mut report);
    }
    let h = HierarchyView::parse(bytes).map_err(|e| e.to_string())?;
    let (v, f) = cut_size(&h, opts.budget.max_triangles);
    with_cut!(v, f, |cut| {
        let engine = Forest::new(h, &mut cut, opts)?;
        fly_orbit(engine, full, opts, out_dir, &mut report)
    })
}

/// The wavelet engine's cut for files beyond [`DemoWaveletCut`]: up to 4M wavelets and 2^20
/// triangles, 32-bit indices.
type LargeWaveletCut = WaveletCut<{ 1 << 17 }, { 1 << 20 }, { 1 << 19 }, { 1 << 15 }, u32>;

/// What a flight needs of an engine: the vertex forest ([`Forest`]) or the wavelet engine
/// ([`Wavelets`]), set up for the flight's options.
trait FlightEngine {
    /// Triangles of the coarsest mesh.
    fn base_triangles(&self) -> u32;
    /// Whether the file has colours.
    fn has_colors(&self) -> bool;
    /// Whether the file's error bounds are Hoppe's.
    fn hoppe_bounds(&self) -> bool;
    /// The model's bounding box.
    fn bounding_box(&self) -> ([f32; 3], [f32; 3]);
    fn adapt(&mut self, view: &View, policy: &DemoPolicy, budget: &Budget) -> FrameStats;
    /// Draws the current mesh; with `ground`, textured by it.
    fn draw(
        &self,
        frame: &mut Frame,
        camera: &Camera,
        style: &Style,
        ground: Option<&GroundTexture>,
    ) -> Result<(), FrameError>;
    /// Writes the current mesh as an OBJ file.
    fn write_obj(&self, path: &Path) -> std::io::Result<()>;
    /// The current mesh's triangles ([`triangle_set`]).
    fn triangle_set(&self) -> Vec<[u32; 3]>;
}

/// `mesh` in `style`, or textured by `ground` when there is one.
fn draw_either<M: vdlod_raster::MeshSource>(
    frame: &mut Frame,
    mesh: &M,
    camera: &Camera,
    style: &Style,
    ground: Option<&GroundTexture>,
) -> Result<(), FrameError> {
    match ground {
        None => frame.draw_styled(mesh, camera, style).map(|_| ()),
        Some(ground) => draw_on_ground(frame, mesh, camera, style, ground),
    }
}

/// The vertex forest in a flight.
struct Forest<'a, 'h, const V: usize, const F: usize, const Q: usize, I: SlotIndex> {
    h: HierarchyView<'h>,
    cut: &'a mut Cut<V, F, Q, I>,
    /// [`vertex_names`] of `h`.
    names: Vec<u32>,
}

impl<'a, 'h, const V: usize, const F: usize, const Q: usize, I: SlotIndex>
    Forest<'a, 'h, V, F, Q, I>
{
    fn new(
        h: HierarchyView<'h>,
        cut: &'a mut Cut<V, F, Q, I>,
        opts: &OrbitOptions,
    ) -> Result<Self, String> {
        cut.set_coloring(if opts.depth_colors {
            Coloring::Depth
        } else {
            Coloring::Node
        });
        cut.reset(&h).map_err(|e| e.to_string())?;
        cut.set_geomorph_frames(opts.geomorph_frames);
        let names = vertex_names(&h);
        Ok(Forest { h, cut, names })
    }
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex + VertexIndex> FlightEngine
    for Forest<'_, '_, V, F, Q, I>
{
    fn base_triangles(&self) -> u32 {
        self.h.base_triangles()
    }

    fn has_colors(&self) -> bool {
        self.h.has_colors()
    }

    fn hoppe_bounds(&self) -> bool {
        self.h.hoppe_bounds()
    }

    fn bounding_box(&self) -> ([f32; 3], [f32; 3]) {
        self.h.bounding_box()
    }

    fn adapt(&mut self, view: &View, policy: &DemoPolicy, budget: &Budget) -> FrameStats {
        self.cut.adapt(&self.h, view, policy, budget)
    }

    fn draw(
        &self,
        frame: &mut Frame,
        camera: &Camera,
        style: &Style,
        ground: Option<&GroundTexture>,
    ) -> Result<(), FrameError> {
        let mesh = CutMesh::new(self.cut, &self.h, style.vertex_colors);
        draw_either(frame, &mesh, camera, style, ground)
    }

    fn write_obj(&self, path: &Path) -> std::io::Result<()> {
        write_obj(path, self.cut, &self.h)
    }

    fn triangle_set(&self) -> Vec<[u32; 3]> {
        cut_triangle_set(self.cut, &self.names)
    }
}

/// The wavelet engine in a flight.
struct Wavelets<
    'a,
    's,
    const W: usize,
    const T: usize,
    const V: usize,
    const Q: usize,
    I: SlotIndex,
> {
    s: SemiRegularView<'s>,
    cut: &'a mut WaveletCut<W, T, V, Q, I>,
}

impl<'a, 's, const W: usize, const T: usize, const V: usize, const Q: usize, I: SlotIndex>
    Wavelets<'a, 's, W, T, V, Q, I>
{
    fn new(
        s: &SemiRegularView<'s>,
        cut: &'a mut WaveletCut<W, T, V, Q, I>,
        opts: &OrbitOptions,
    ) -> Result<Self, String> {
        cut.reset(s).map_err(|e| e.to_string())?;
        cut.set_geomorph_frames(opts.geomorph_frames);
        Ok(Wavelets { s: *s, cut })
    }
}

impl<const W: usize, const T: usize, const V: usize, const Q: usize, I> FlightEngine
    for Wavelets<'_, '_, W, T, V, Q, I>
where
    I: SlotIndex + VertexIndex,
{
    fn base_triangles(&self) -> u32 {
        self.s.counts().base_faces
    }

    fn has_colors(&self) -> bool {
        self.s.has_colors()
    }

    fn hoppe_bounds(&self) -> bool {
        self.s.hoppe_bounds()
    }

    fn bounding_box(&self) -> ([f32; 3], [f32; 3]) {
        self.s.bounding_box()
    }

    fn adapt(&mut self, view: &View, policy: &DemoPolicy, budget: &Budget) -> FrameStats {
        self.cut.adapt(&self.s, view, policy, budget)
    }

    fn draw(
        &self,
        frame: &mut Frame,
        camera: &Camera,
        style: &Style,
        ground: Option<&GroundTexture>,
    ) -> Result<(), FrameError> {
        let mesh = WaveletMesh::new(self.cut, &self.s, style.vertex_colors);
        draw_either(frame, &mesh, camera, style, ground)
    }

    fn write_obj(&self, path: &Path) -> std::io::Result<()> {
        let positions: Vec<[f32; 3]> = (0..self.cut.vertex_count())
            .map(|i| self.cut.position(i))
            .collect();
        let triangles = self
            .cut
            .triangles()
            .iter()
            .map(|t| t.map(|i| i.index() as u32));
        std::fs::write(path, crate::mesh::obj_text(&positions, None, triangles))
    }

    fn triangle_set(&self) -> Vec<[u32; 3]> {
        let ids = self.cut.triangles().iter();
        triangle_set(ids.map(|t| t.map(|i| self.cut.vertex_id(i.index()))))
    }
}

/// [`run_orbit`] with its engine.
fn fly_orbit(
    mut engine: impl FlightEngine,
    full: &IndexedMesh,
    opts: &OrbitOptions,
    out_dir: &Path,
    report: &mut impl FnMut(&OrbitFrame),
) -> Result<OrbitSummary, String> {
    let io = |e: std::io::Error| format!("{}: {e}", out_dir.display());
    std::fs::create_dir_all(out_dir).map_err(io)?;
    // Only what this run writes is cleaned: frames (and meshes) past its last one.
    let stale: Vec<(&str, u32)> = [("frame_", opts.write_frames), ("mesh_", opts.dump_mesh)]
        .into_iter()
        .filter(|s| s.1)
        .map(|(prefix, _)| (prefix, opts.frames))
        .collect();
    crate::render::remove_stale(out_dir, &stale).map_err(io)?;
    // The comparison with full detail uses the mesh's own colours; false colours, the wireframe
    // and the observer's view are drawn after it, for the pictures only.
    let true_colors = engine.has_colors() && !opts.depth_colors;
    let colors = opts.depth_colors || engine.has_colors();
    let picture = opts.depth_colors || opts.wireframe || opts.observer;
    let bounds = full.bounds();
    let orbit = if opts.peer_orbit {
        peer_orbit(&bounds, opts.frames, opts.width, opts.height)
    } else {
        merge_tree_orbit(&bounds, opts.frames, opts.width, opts.height)
    };
    let policy = make_policy(opts.policy, engine.bounding_box(), engine.hoppe_bounds());
    let mut frame = Frame::new(opts.width, opts.height).map_err(|e| e.to_string())?;
    let mut reference = Frame::new(opts.width, opts.height).map_err(|e| e.to_string())?;
    let full_mesh = full.as_raster_mesh();
    let ground = opts.ground.as_ref();
    let mut csv = String::from(
        "frame,triangles,vsplits,ecols,adapt_us,render_us,full_render_us,psnr_db,vertices,forced,blending,threshold,budget_limited,ops_limited,capacity_limited,queue_overflow,blend_limited,over_budget,new_triangles,visited\n",
    );
    let mut frames = Vec::with_capacity(opts.frames as usize);
    let mut before = Vec::new();
    let mut warned = false;
    let compared = opts.frames / 2;
    let camera_of = |i: u32| match &opts.path {
        Some(path) if !path.is_empty() => path[i as usize % path.len()],
        _ => orbit.camera(i),
    };
    // The previous frame's adapt + render time, for a frame-time target.
    let mut frame_us = 0u32;
    for i in 0..opts.frames {
        let camera = camera_of(i);
        let view = camera.view_scaled(opts.frustum);
        let budget = Budget {
            frame_us,
            ..opts.budget
        };
        let start = Instant::now();
        let stats = engine.adapt(&view, &policy, &budget);
        let base = engine.base_triangles();
        if stats.over_budget && !warned && base > opts.budget.max_triangles {
            eprintln!(
                "vdlod-demo: warning: the base mesh has {} triangles, more than the budget of {}: \
                 no cut of this hierarchy fits it",
                base, opts.budget.max_triangles
            );
            warned = true;
        }
        let adapt_us = start.elapsed().as_secs_f64() * 1e6;
        let drawn = Style {
            vertex_colors: true_colors,
            ..style(Shading::Gouraud, false)
        };
        let start = Instant::now();
        engine
            .draw(&mut frame, &camera, &drawn, ground)
            .map_err(|e| e.to_string())?;
        let render_us = start.elapsed().as_secs_f64() * 1e6;
        frame_us = (adapt_us + render_us).round().min(u32::MAX as f64) as u32;
        let start = Instant::now();
        draw_either(&mut reference, &full_mesh, &camera, &drawn, ground)
            .map_err(|e| e.to_string())?;
        let full_render_us = start.elapsed().as_secs_f64() * 1e6;
        let f = OrbitFrame {
            index: i,
            stats,
            adapt_us,
            render_us,
            full_render_us,
            psnr_db: psnr(frame.pixels(), reference.pixels()),
            new_triangles: {
                let now = engine.triangle_set();
                let new = new_triangles(&before, &now);
                before = now;
                new
            },
        };
        if i == compared {
            let side = side_by_side(opts.width, opts.height, frame.pixels(), reference.pixels());
            let captions = [
                format!("adapted: {} triangles", stats.triangles),
                format!("full detail: {} triangles", full.triangles.len()),
                format!("difference x4: psnr {:.2} db", f.psnr_db),
            ];
            let png = captioned(opts.width, opts.height, &side, &captions)?;
            std::fs::write(out_dir.join("side_by_side.png"), png).map_err(io)?;
        }
        if picture {
            let seen_from = if opts.observer && opts.path.is_some() {
                overview(&bounds, opts.width, opts.height)
            } else if opts.observer {
                observer(&orbit, i)
            } else {
                camera
            };
            let drawn = Style {
                vertex_colors: colors,
                ..style(Shading::Gouraud, opts.wireframe)
            };
            engine
                .draw(
                    &mut frame,
                    &seen_from,
                    &drawn,
                    ground.filter(|_| !opts.depth_colors),
                )
                .map_err(|e| e.to_string())?;
        }
        if opts.write_frames {
            frame
                .save_png(&out_dir.join(format!("frame_{i:04}.png")))
                .map_err(|e| e.to_string())?;
        }
        if opts.dump_mesh {
            engine
                .write_obj(&out_dir.join(format!("mesh_{i:04}.obj")))
                .map_err(io)?;
        }
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.1},{:.1},{:.1},{:.3},{},{},{},{},{},{},{},{},{},{},{},{}",
            i,
            stats.triangles,
            stats.vsplits,
            stats.ecols,
            adapt_us,
            render_us,
            full_render_us,
            f.psnr_db,
            stats.vertices,
            stats.forced,
            stats.blending,
            stats.threshold,
            stats.budget_limited as u8,
            stats.ops_limited as u8,
            stats.capacity_limited as u8,
            stats.queue_overflow as u8,
            stats.blend_limited as u8,
            stats.over_budget as u8,
            f.new_triangles,
            stats.visited,
        );
        report(&f);
        frames.push(f);
    }
    let mut file = std::fs::File::create(out_dir.join("stats.csv")).map_err(io)?;
    file.write_all(csv.as_bytes()).map_err(io)?;
    let png = plot(&frames).map_err(|e| e.to_string())?;
    std::fs::write(out_dir.join("plot.png"), png).map_err(io)?;
    Ok(OrbitSummary {
        frames,
        compared,
        hoppe_test: matches!(policy, DemoPolicy::Hoppe(_)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_known_differences() {
        let a = vec![Rgba8([10, 20, 30, 255]); 100];
        assert_eq!(psnr(&a, &a), f64::INFINITY);
        // Every channel off by one: MSE 1, PSNR 20 log10(255) = 48.13 dB.
        let b = vec![Rgba8([11, 21, 31, 255]); 100];
        assert!((psnr(&a, &b) - 48.1308).abs() < 1e-3);
    }

    #[test]
    fn vertex_names_follow_a_vertex_that_stays() {
        use vdlod_core::build::{BuildOptions, Placement};
        let mesh = crate::terrain::Terrain::procedural(17, 1, 0.1).mesh();
        let named = |placement| {
            let opts = BuildOptions {
                placement,
                ..BuildOptions::default()
            };
            let bytes = crate::hierarchy::build_with_progress(&mesh, &opts, false)
                .unwrap()
                .1;
            let h = HierarchyView::parse(&bytes).unwrap();
            let names = vertex_names(&h);
            // A name is the node itself or a node below it with the same vertex.
            for (n, &m) in names.iter().enumerate() {
                assert!(m == n as u32 || h.is_below(m, n as u32));
                assert_eq!(h.vertex(m), h.vertex(n as u32));
            }
            let parents = h.parent_nodes().count();
            let renamed = h.parent_nodes().filter(|&p| names[p as usize] != p).count();
            (parents, renamed)
        };
        // On endpoints every parent is an input vertex: each is named by a leaf.
        let (parents, renamed) = named(Placement::Endpoint);
        assert!(
            parents > 200 && renamed == parents,
            "{renamed} of {parents}"
        );
        // Placed by the quadrics, a parent is a vertex of its own.
        let (parents, renamed) = named(Placement::Cost);
        assert!(renamed * 10 < parents, "{renamed} of {parents}");
    }
}
