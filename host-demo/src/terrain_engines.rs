//! Both engines on one terrain (`vdlod-demo reproduce terrain-engines`).
//!
//! A square grid of `2^k + 1` samples has subdivision connectivity, so the wavelet engine
//! (Azuma et al., "View-dependent refinement of multiresolution meshes with subdivision
//! connectivity", 2003) takes it as it is ([`Terrain::semi_regular`]), while the vertex forest
//! builds its hierarchy from the same grid. Both fly the same low fly-over: the wavelet engine at
//! a 1 px tolerance, the forest at 0.1 px under a budget of the wavelet engine's triangle count in
//! each frame, so they are compared at equal triangles: PSNR against full detail, the share of
//! triangles that are new in a frame (ROAM's measure of frame-to-frame coherence), adaptation
//! time, file bytes per height sample and cut bytes per triangle of capacity. The forest flies
//! twice: built with the default placement (each collapse's vertex where its quadrics put it),
//! and on endpoints ([`Placement::Endpoint`], a half-edge hierarchy whose vertices are all
//! samples, as the wavelet engine's are), where a split leaves the triangles round the staying
//! child as they were ([`vertex_names`] names a vertex by what it is, not by its node).
//!
//! The frames are coloured per vertex (one colour per sample); `reproduce textures` draws the
//! same flight with the colours as a texture.
//!
//! [`tolerances`] (`vdlod-demo reproduce terrain-tolerances`) sets both engines beside the
//! anchor of Lindstrom et al. ("Real-time, continuous level of detail rendering of height
//! fields", 1996): at 0.5, 1, 2 and 4 px they keep 62,497, 23,287, 8,612 and 3,385 polygons of a
//! 13.3M-triangle terrain with under 5% of the pixels differing from full detail; here, the
//! triangles and the share of differing pixels on our largest procedural terrain, with the
//! colours per vertex and as a texture.

use std::path::Path;
use std::time::Instant;

use vdlod::{Camera, CutMesh, Style, WaveletMesh};
use vdlod_core::adapt::{Budget, FrameStats};
use vdlod_core::build::{BuildOptions, Placement};
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::QRefine;
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};
use vdlod_raster::{MeshSource, Rgba8, Shading};

use crate::chart::{self, Panel, BLUE, GREEN, ORANGE};
use crate::frame::Frame;
use crate::ground::{draw_on_ground, GroundTexture};
use crate::hierarchy::build_with_progress;
use crate::lod::{cut_triangle_set, new_triangles, psnr, triangle_set, vertex_names};
use crate::mesh::IndexedMesh;
use crate::render::style;
use crate::stats::{mean, median};
use crate::terrain::{FlyOver, Terrain, DEFAULT_VERTICAL_SCALE, UP_AXIS};
use crate::wavelet::DemoWaveletCut;

/// The terrain's seed (the `terrain` command's default).
const SEED: u32 = 1;
/// The frames' size.
const WIDTH: usize = 640;
const HEIGHT: usize = 480;

/// What to fly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setup {
    /// Samples along each side of the procedural terrain: `2^k + 1`.
    pub samples: usize,
    /// Frames of the fly-over's loop.
    pub frames: u32,
}

impl Setup {
    /// The experiment `reproduce terrain-engines` runs: the `terrain` command's default terrain
    /// (257 x 257), its loop in 720 frames (half a degree of the loop a frame, about 0.7
    /// samples of flight: a smooth frame rate for a low flight).
    pub const REPRODUCE: Setup = Setup {
        samples: 257,
        frames: 720,
    };
}

/// The forest's cut: up to 32,000 triangles (the wavelet engine's, [`DemoWaveletCut`], holds
/// 60,000).
pub(crate) type ForestCut = Cut<16_000, 32_000, 2_000>;

/// Both engines' cuts, adapted at equal triangles: the wavelet engine at 1 px, then the forest
/// at 0.1 px under a budget of the wavelet engine's count.
pub(crate) struct Engines {
    pub(crate) wavelet: Box<DemoWaveletCut>,
    pub(crate) forest: Box<ForestCut>,
}

impl Engines {
    /// Both cuts at their base meshes.
    pub(crate) fn new(s: &SemiRegularView<'_>, h: &HierarchyView<'_>) -> Result<Engines, String> {
        let mut wavelet = DemoWaveletCut::boxed();
        wavelet.reset(s).map_err(|e| e.to_string())?;
        let mut forest = ForestCut::boxed();
        forest.reset(h).map_err(|e| e.to_string())?;
        Ok(Engines { wavelet, forest })
    }

    /// The wavelet engine to `camera`.
    pub(crate) fn adapt_wavelet(
        &mut self,
        s: &SemiRegularView<'_>,
        camera: &Camera,
    ) -> Result<FrameStats, String> {
        let policy = QRefine::new(1.0);
        vdlod::adapt_wavelets(&mut self.wavelet, s, camera, &policy, &Budget::default())
            .map_err(|e| e.to_string())
    }

    /// The forest to `camera`, at most `triangles`.
    pub(crate) fn adapt_forest(
        &mut self,
        h: &HierarchyView<'_>,
        camera: &Camera,
        triangles: u32,
    ) -> Result<FrameStats, String> {
        adapt_forest(&mut self.forest, h, camera, triangles)
    }
}

/// `forest` to `camera` at 0.1 px, at most `triangles`.
fn adapt_forest(
    forest: &mut ForestCut,
    h: &HierarchyView<'_>,
    camera: &Camera,
    triangles: u32,
) -> Result<FrameStats, String> {
    let budget = Budget {
        max_triangles: triangles,
        ..Budget::default()
    };
    vdlod::adapt(forest, h, camera, &QRefine::new(0.1), &budget).map_err(|e| e.to_string())
}

/// A forest built with [`Placement::Endpoint`] from the flight's terrain: its file, the file's
/// size without colours, and the build's seconds.
fn endpoint_forest(land: &Terrain) -> Result<(Vec<u8>, usize, f64), String> {
    let opts = BuildOptions {
        placement: Placement::Endpoint,
        ..BuildOptions::default()
    };
    let (hierarchy, bytes, seconds) =
        build_with_progress(&land.mesh(), &opts, false).map_err(|e| format!("terrain: {e}"))?;
    Ok((bytes, hierarchy.to_bytes(false).len(), seconds))
}

/// What both engines fly: the procedural terrain of `side` samples a side as a semi-regular file
/// and as a hierarchy, its full-detail mesh, and the fly-over's cameras.
pub(crate) struct Flight {
    pub(crate) land: Terrain,
    pub(crate) full: IndexedMesh,
    pub(crate) cameras: Vec<Camera>,
    pub(crate) drawn: Style,
    pub(crate) sbytes: Vec<u8>,
    pub(crate) hbytes: Vec<u8>,
    /// The two files' sizes without their colours: heights (or positions) and hierarchy.
    pub(crate) shape_bytes: [usize; 2],
    pub(crate) wavelet_build_s: f64,
    pub(crate) forest_build_s: f64,
}

impl Flight {
    /// The flight of the `side`-square terrain in `frames` frames of `size` pixels.
    pub(crate) fn new(
        side: usize,
        frames: u32,
        [width, height]: [usize; 2],
        progress: bool,
    ) -> Result<Flight, String> {
        let land = Terrain::procedural(side, SEED, DEFAULT_VERTICAL_SCALE);
        let semi = land
            .semi_regular()
            .ok_or("the terrain is not 2^k + 1 samples square")?;
        let start = Instant::now();
        let sbytes = semi.to_height_bytes(UP_AXIS).map_err(|e| e.to_string())?;
        let wavelet_build_s = start.elapsed().as_secs_f64();
        drop(semi);
        let mut full = land.mesh();
        let (hierarchy, hbytes, forest_build_s) =
            build_with_progress(&full, &BuildOptions::default(), progress)
                .map_err(|e| format!("terrain: {e}"))?;
        let colours = if land.colors.is_some() {
            vdlod_core::wavelet::format::COLOR_SIZE * side * side
        } else {
            0
        };
        let shape_bytes = [sbytes.len() - colours, hierarchy.to_bytes(false).len()];
        full.reorder_for_locality();
        let fly_over = FlyOver::new(&land, frames, width, height);
        Ok(Flight {
            full,
            cameras: (0..frames).map(|i| fly_over.camera(i)).collect(),
            drawn: Style {
                vertex_colors: true,
                ..style(Shading::Gouraud, false)
            },
            sbytes,
            hbytes,
            shape_bytes,
            wavelet_build_s,
            forest_build_s,
            land,
        })
    }

    /// The two files, read.
    pub(crate) fn views(&self) -> Result<(SemiRegularView<'_>, HierarchyView<'_>), String> {
        Ok((
            SemiRegularView::parse(&self.sbytes).map_err(|e| e.to_string())?,
            HierarchyView::parse(&self.hbytes).map_err(|e| e.to_string())?,
        ))
    }
}

/// One engine's frame.
#[derive(Clone, Copy, Debug, Default)]
struct EngineFrame {
    triangles: u32,
    /// Triangles not in the previous frame's mesh.
    new: u32,
    adapt_us: f64,
    psnr_db: f64,
}

/// Runs the comparison, writing `terrain_engines.csv` and `terrain_engines.png` (new triangles
/// and PSNR per frame) into `out`; returns one summary line per engine.
pub fn terrain_engines(out: &Path, setup: Setup) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let Setup {
        samples: side,
        frames: count,
    } = setup;
    let samples = (side * side) as f64;
    let flight = Flight::new(side, count, [WIDTH, HEIGHT], false)?;
    let (s, h) = flight.views()?;
    let Flight {
        full,
        cameras,
        drawn,
        sbytes,
        hbytes,
        shape_bytes,
        wavelet_build_s,
        forest_build_s,
        ..
    } = &flight;
    let (ebytes, endpoint_shape_bytes, endpoint_build_s) = endpoint_forest(&flight.land)?;
    let e = HierarchyView::parse(&ebytes).map_err(|e| e.to_string())?;
    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    let mut engines = Engines::new(&s, &h)?;
    let mut endpoint = ForestCut::boxed();
    endpoint.reset(&e).map_err(|e| e.to_string())?;
    let names = [vertex_names(&h), vertex_names(&e)];
    let mut frames: Vec<[EngineFrame; 3]> = Vec::with_capacity(cameras.len());
    let mut before: [Vec<[u32; 3]>; 3] = Default::default();
    for camera in cameras {
        frame
            .draw(&full.as_raster_mesh(), &drawn.params(camera))
            .map_err(|e| e.to_string())?;
        let reference = frame.pixels().to_vec();

        let start = Instant::now();
        let stats = engines.adapt_wavelet(&s, camera)?;
        let adapt_us = start.elapsed().as_secs_f64() * 1e6;
        let wavelet = &engines.wavelet;
        frame
            .draw_styled(&WaveletMesh::new(wavelet, &s, true), camera, drawn)
            .map_err(|e| e.to_string())?;
        let now = triangle_set(
            wavelet
                .triangles()
                .iter()
                .map(|t| t.map(|i| wavelet.vertex_id(i as usize))),
        );
        let w = EngineFrame {
            triangles: stats.triangles,
            new: new_triangles(&before[0], &now),
            adapt_us,
            psnr_db: psnr(frame.pixels(), &reference),
        };
        before[0] = now;

        let mut forests = [EngineFrame::default(); 2];
        for (k, (cut, h)) in [(&mut engines.forest, &h), (&mut endpoint, &e)]
            .into_iter()
            .enumerate()
        {
            let start = Instant::now();
            let stats = adapt_forest(cut, h, camera, w.triangles)?;
            let adapt_us = start.elapsed().as_secs_f64() * 1e6;
            frame
                .draw_cut(cut, h, camera, drawn)
                .map_err(|e| e.to_string())?;
            let now = cut_triangle_set(cut, &names[k]);
            forests[k] = EngineFrame {
                triangles: stats.triangles,
                new: new_triangles(&before[k + 1], &now),
                adapt_us,
                psnr_db: psnr(frame.pixels(), &reference),
            };
            before[k + 1] = now;
        }
        frames.push([w, forests[0], forests[1]]);
    }

    let mut csv = String::from("frame,wavelet_triangles,forest_triangles,wavelet_new,forest_new,wavelet_adapt_us,forest_adapt_us,wavelet_psnr_db,forest_psnr_db,endpoint_triangles,endpoint_new,endpoint_adapt_us,endpoint_psnr_db\n");
    for (i, [w, f, e]) in frames.iter().enumerate() {
        csv.push_str(&format!(
            "{i},{},{},{},{},{:.1},{:.1},{:.2},{:.2},{},{},{:.1},{:.2}\n",
            w.triangles,
            f.triangles,
            w.new,
            f.new,
            w.adapt_us,
            f.adapt_us,
            w.psnr_db,
            f.psnr_db,
            e.triangles,
            e.new,
            e.adapt_us,
            e.psnr_db
        ));
    }
    let path = out.join("terrain_engines.csv");
    std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let series = |k: usize, f: fn(&EngineFrame) -> f64| -> Vec<f64> {
        frames.iter().skip(1).map(|x| f(&x[k])).collect()
    };
    let new_pct = |f: &EngineFrame| 100.0 * f.new as f64 / f.triangles.max(1) as f64;
    let psnr_db = |f: &EngineFrame| f.psnr_db.min(99.0);
    let panel = |what: &'static str, f: fn(&EngineFrame) -> f64| Panel {
        title: vec![
            (what, BLUE),
            (", vertex forest", ORANGE),
            (", on endpoints", GREEN),
        ],
        series: vec![
            (series(0, f), BLUE),
            (series(1, f), ORANGE),
            (series(2, f), GREEN),
        ],
    };
    let png = chart::panels(&[
        panel("percent new triangles per frame: wavelets", new_pct),
        panel("PSNR dB: wavelets", psnr_db),
    ])?;
    let path = out.join("terrain_engines.png");
    std::fs::write(&path, png).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;

    let engines = [
        (
            "wavelet",
            [sbytes.len(), shape_bytes[0]],
            DemoWaveletCut::BYTES,
            60_000,
            wavelet_build_s,
        ),
        (
            "forest",
            [hbytes.len(), shape_bytes[1]],
            ForestCut::BYTES,
            32_000,
            forest_build_s,
        ),
        (
            "forest-endpoint",
            [ebytes.len(), endpoint_shape_bytes],
            ForestCut::BYTES,
            32_000,
            &endpoint_build_s,
        ),
    ];
    let mut lines = Vec::new();
    for (k, (engine, file, cut, capacity, build_s)) in engines.into_iter().enumerate() {
        // The first frame starts from the base mesh: the others show coherence.
        let after_first = || frames.iter().skip(1).map(|f| f[k]);
        let new_pct: Vec<f64> = after_first()
            .map(|f| 100.0 * f.new as f64 / f.triangles.max(1) as f64)
            .collect();
        lines.push(format!(
            "experiment=terrain-engines engine={engine} grid={side}x{side} frames={count} triangles_mean={:.0} psnr_db_mean={:.2} new_triangles_pct_median={:.2} new_triangles_pct_max={:.2} adapt_us_median={:.0} build_s={build_s:.2} file_bytes_per_sample={:.2} without_colors_bytes_per_sample={:.3} cut_bytes_per_triangle={:.1}",
            mean(after_first().map(|f| f.triangles as f64)),
            mean(after_first().map(|f| f.psnr_db.min(99.0))),
            median(new_pct.clone()),
            new_pct.iter().copied().fold(0.0, f64::max),
            median(after_first().map(|f| f.adapt_us).collect()),
            file[0] as f64 / samples,
            file[1] as f64 / samples,
            cut as f64 / capacity as f64,
        ));
    }
    Ok(lines)
}

/// One engine's frame at one tolerance.
struct Measured {
    triangles: u32,
    /// Percent of pixels that differ at all from full detail.
    differing: f64,
    /// Percent of pixels with a channel more than 16 levels (of 255) away.
    differing_16: f64,
    psnr_db: f64,
    /// The same two for the frame drawn with the colours as a texture, against full detail
    /// drawn so.
    textured_16: f64,
    textured_psnr_db: f64,
    /// A capacity or queue limit was met.
    limited: bool,
}

/// Percent of `pixels` with a channel more than `by` levels away from `reference`'s.
fn share(pixels: &[Rgba8], reference: &[Rgba8], by: u8) -> f64 {
    let off = pixels
        .iter()
        .zip(reference)
        .filter(|(x, y)| (0..3).any(|k| x.0[k].abs_diff(y.0[k]) > by))
        .count();
    100.0 * off as f64 / pixels.len().max(1) as f64
}

impl Measured {
    /// `mesh` drawn coloured per vertex and textured, against full detail drawn the same ways
    /// (`reference`), from `camera` in `style`.
    fn drawn<M: MeshSource>(
        frame: &mut Frame,
        mesh: &M,
        (camera, style, ground, reference): (&Camera, &Style, &GroundTexture, &[Vec<Rgba8>; 2]),
        stats: &FrameStats,
    ) -> Result<Measured, String> {
        frame
            .draw_styled(mesh, camera, style)
            .map_err(|e| e.to_string())?;
        let colored = frame.pixels().to_vec();
        draw_on_ground(frame, mesh, camera, style, ground).map_err(|e| e.to_string())?;
        Ok(Measured::of(stats, [&colored, frame.pixels()], reference))
    }

    /// `colored` and `textured` against full detail drawn the same ways.
    fn of(
        stats: &FrameStats,
        [colored, textured]: [&[Rgba8]; 2],
        reference: &[Vec<Rgba8>; 2],
    ) -> Measured {
        Measured {
            triangles: stats.triangles,
            differing: share(colored, &reference[0], 0),
            differing_16: share(colored, &reference[0], 16),
            psnr_db: psnr(colored, &reference[0]),
            textured_16: share(textured, &reference[1], 16),
            textured_psnr_db: psnr(textured, &reference[1]),
            limited: stats.capacity_limited || stats.queue_overflow,
        }
    }
}

/// Lindstrom et al.'s tolerances, in pixels, and the polygons they kept at each.
pub const LINDSTROM: [(f32, u32); 4] = [(0.5, 62_497), (1.0, 23_287), (2.0, 8_612), (4.0, 3_385)];

/// Cuts big enough for a 1025 x 1025 terrain at 0.5 px (32-bit indices).
type BigWaveletCut = WaveletCut<32_832, 400_000, 200_000, 32_768, u32>;
type BigForestCut = Cut<200_000, 400_000, 100_000, u32>;

/// Flies both engines over the `samples`-square terrain's fly-over (`frames` views) at each of
/// [`LINDSTROM`]'s tolerances, without a budget; returns one line per engine and tolerance:
/// mean triangles, and the mean share of pixels that differ at all from full detail, and by
/// more than 16 levels of 255 in a channel.
pub fn tolerances(out: &Path, samples: usize, frames: u32) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let flight = Flight::new(samples, frames, [WIDTH, HEIGHT], show)?;
    let (s, h) = flight.views()?;
    let Flight {
        land,
        full,
        cameras,
        drawn,
        ..
    } = &flight;
    let ground = GroundTexture::of(land).ok_or("the terrain has no colours")?;
    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    // Full detail, coloured per vertex and textured.
    let mut references = Vec::with_capacity(cameras.len());
    for camera in cameras {
        let full_mesh = full.as_raster_mesh();
        frame
            .draw(&full_mesh, &drawn.params(camera))
            .map_err(|e| e.to_string())?;
        let colored = frame.pixels().to_vec();
        draw_on_ground(&mut frame, &full_mesh, camera, drawn, &ground)
            .map_err(|e| e.to_string())?;
        references.push([colored, frame.pixels().to_vec()]);
    }
    let mut wavelet = BigWaveletCut::boxed();
    let mut forest = BigForestCut::boxed();
    let mut lines = Vec::new();
    let mut csv = String::from(
        "engine,tolerance_px,frame,triangles,differing_pct,differing_by_16_pct,psnr_db,textured_differing_by_16_pct,textured_psnr_db\n",
    );
    for (tau, paper) in LINDSTROM {
        let policy = QRefine::new(tau);
        wavelet.reset(&s).map_err(|e| e.to_string())?;
        forest.reset(&h).map_err(|e| e.to_string())?;
        let mut rows: [Vec<Measured>; 2] = [Vec::new(), Vec::new()];
        for (camera, reference) in cameras.iter().zip(&references) {
            let drawing = (camera, drawn, &ground, reference);
            let w = vdlod::adapt_wavelets(&mut wavelet, &s, camera, &policy, &Budget::default())
                .map_err(|e| e.to_string())?;
            let mesh = WaveletMesh::new(&wavelet, &s, true);
            rows[0].push(Measured::drawn(&mut frame, &mesh, drawing, &w)?);
            let f = vdlod::adapt(&mut forest, &h, camera, &policy, &Budget::default())
                .map_err(|e| e.to_string())?;
            let mesh = CutMesh::new(&forest, &h, true);
            rows[1].push(Measured::drawn(&mut frame, &mesh, drawing, &f)?);
        }
        for (k, engine) in ["wavelet", "forest"].into_iter().enumerate() {
            let rows = &rows[k];
            for (i, r) in rows.iter().enumerate() {
                csv.push_str(&format!(
                    "{engine},{tau},{i},{},{:.3},{:.3},{:.2},{:.3},{:.2}\n",
                    r.triangles,
                    r.differing,
                    r.differing_16,
                    r.psnr_db,
                    r.textured_16,
                    r.textured_psnr_db
                ));
            }
            let limited = rows.iter().filter(|r| r.limited).count();
            lines.push(format!(
                "experiment=terrain-tolerances engine={engine} grid={samples}x{samples} full_triangles={} frames={frames} tolerance_px={tau} triangles_mean={:.0} differing_pixels_pct_mean={:.2} differing_pixels_pct_max={:.2} differing_by_16_pct_mean={:.2} psnr_db_mean={:.2} textured_differing_by_16_pct_mean={:.2} textured_psnr_db_mean={:.2} limited_frames={limited} lindstrom_polygons={paper} lindstrom_full_triangles=13300000 lindstrom_differing_pct_below=5",
                full.triangles.len(),
                mean(rows.iter().map(|r| r.triangles as f64)),
                mean(rows.iter().map(|r| r.differing)),
                rows.iter().map(|r| r.differing).fold(0.0, f64::max),
                mean(rows.iter().map(|r| r.differing_16)),
                mean(rows.iter().map(|r| r.psnr_db.min(99.0))),
                mean(rows.iter().map(|r| r.textured_16)),
                mean(rows.iter().map(|r| r.textured_psnr_db.min(99.0))),
            ));
        }
    }
    let path = out.join("terrain_tolerances.csv");
    std::fs::write(&path, csv).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(line: &str, key: &str) -> f64 {
        crate::summary_value(line, key).unwrap_or_else(|| panic!("no {key} in {line}"))
    }

    #[test]
    fn both_engines_fly_the_same_terrain_at_equal_triangles() {
        let out =
            std::env::temp_dir().join(format!("vdlod_terrain_engines_{}", std::process::id()));
        let setup = Setup {
            samples: 65,
            frames: 24,
        };
        let lines = terrain_engines(&out, setup).unwrap();
        assert_eq!(lines.len(), 3);
        let (w, f, e) = (&lines[0], &lines[1], &lines[2]);
        assert!(w.contains("engine=wavelet") && f.contains("engine=forest "));
        assert!(e.contains("engine=forest-endpoint "));
        // Both forests run under the wavelet engine's count, at a finer tolerance: the same
        // triangles in every frame (a split adds two, so they may stop one short).
        let csv = std::fs::read_to_string(out.join("terrain_engines.csv")).unwrap();
        for row in csv.lines().skip(1) {
            let v: Vec<u32> = row
                .split(',')
                .map(|x| x.parse::<f64>().unwrap() as u32)
                .collect();
            for forest in [v[2], v[9]] {
                assert!(forest <= v[1] && forest + 1 >= v[1], "{row}");
            }
            assert!(v[3] <= v[1] && v[4] <= v[2] && v[10] <= v[9], "{row}");
        }
        for forest in [f, e] {
            assert!((field(w, "triangles_mean") - field(forest, "triangles_mean")).abs() <= 1.0);
        }
        // A split of a forest on endpoints leaves the triangles round the staying child.
        let churn = |l: &str| field(l, "new_triangles_pct_median");
        assert!(churn(e) < churn(f), "{e}\n{f}");
        // Heights on a grid need no connectivity: the wavelet file is the smaller, two bytes a
        // sample and under a tenth of hierarchy and header beside the colours on a grid this
        // small.
        assert!(field(w, "file_bytes_per_sample") < field(f, "file_bytes_per_sample"));
        let heights = field(w, "without_colors_bytes_per_sample");
        assert!(heights > 2.0 && heights <= 2.1, "{w}");
        assert!(
            (field(w, "file_bytes_per_sample") - heights - 3.0).abs() < 0.01,
            "{w}"
        );
        for line in &lines {
            let pct = field(line, "new_triangles_pct_median");
            assert!((0.0..=100.0).contains(&pct), "{line}");
            assert!(field(line, "psnr_db_mean") > 20.0, "{line}");
        }
        assert!(out.join("terrain_engines.png").exists());
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn coarser_tolerances_keep_fewer_triangles_and_differ_more() {
        let out = std::env::temp_dir().join(format!("vdlod_tolerances_{}", std::process::id()));
        let lines = tolerances(&out, 65, 6).unwrap();
        assert_eq!(lines.len(), 8);
        for engine in ["wavelet", "forest"] {
            let of: Vec<&String> = lines
                .iter()
                .filter(|l| l.contains(&format!("engine={engine} ")))
                .collect();
            assert_eq!(of.len(), 4);
            for pair in of.windows(2) {
                let (fine, coarse) = (pair[0], pair[1]);
                assert!(field(fine, "tolerance_px") < field(coarse, "tolerance_px"));
                assert!(
                    field(fine, "triangles_mean") >= field(coarse, "triangles_mean"),
                    "{fine}\n{coarse}"
                );
            }
            for l in &of {
                let d = field(l, "differing_pixels_pct_mean");
                assert!((0.0..=100.0).contains(&d), "{l}");
                assert_eq!(field(l, "limited_frames"), 0.0, "{l}");
                let textured = field(l, "textured_differing_by_16_pct_mean");
                assert!((0.0..=100.0).contains(&textured), "{l}");
                assert!(field(l, "textured_psnr_db_mean") > 15.0, "{l}");
            }
        }
        assert!(out.join("terrain_tolerances.csv").exists());
        std::fs::remove_dir_all(&out).unwrap();
    }
}
