//! Textures over both engines (`vdlod-demo reproduce textures`).
//!
//! The wavelet paper (Azuma et al., "View-dependent refinement of multiresolution meshes with
//! subdivision connectivity", 2003, §3.1) keeps a texture over the parametric domain of the base
//! mesh: every vertex of every level has fixed coordinates there, so however the cut moves, the
//! texture stays where it belongs. A vertex hierarchy has no such domain: a parent sits where its
//! builder put it (the quadric's optimum, off the surface the leaves sample) and carries whatever
//! coordinates it was given (here the mean of its children's, the usual choice), so its
//! texture slides as the cut coarsens.
//!
//! On the `terrain` command's 257 x 257 terrain and its fly-over, both engines at equal
//! triangles (the wavelet engine at 1 px, the forest budgeted to the wavelet engine's count):
//! PSNR against the full-detail mesh drawn the same way, for the terrain's colours as a texture
//! (bilinear, one texel per sample: the importance paper's colormap), for a checker over the
//! parametric domain, and for the colours per vertex (as the engines drew them before
//! textures); and a sheet of one frame's pictures.

use std::path::Path;
use std::time::Instant;

use vdlod::{CutMesh, Style, WaveletMesh};
use vdlod_raster::texture::{Filter, Texture, Wrap};
use vdlod_raster::{Rgba8, Shading, Uv};

use crate::frame::Frame;
use crate::importance::{sheet, Panel};
use crate::lod::psnr;
use crate::render::style;
use crate::stats::mean;
use crate::terrain_engines::{Engines, Flight, Setup};

const WIDTH: usize = 480;
const HEIGHT: usize = 360;
/// Checker cells along each side of the terrain.
const CELLS: usize = 16;

/// `reproduce textures`: the `terrain` command's default terrain, its loop in 120 frames.
pub const REPRODUCE: Setup = Setup {
    samples: 257,
    frames: 120,
};

/// The three ways a frame is drawn.
const KINDS: [&str; 3] = ["colormap texture", "checker texture", "colours per vertex"];

/// Texture coordinates of a point of the terrain: sample `(c, r)` at the centre of texel
/// `(c, r)` of a `side x side` texture.
fn planar(p: [f32; 3], side: usize) -> Uv {
    [(p[0] + 0.5) / side as f32, (p[2] + 0.5) / side as f32]
}

/// Runs the experiment, writing `textures.png` (the pictures of frame `pictured`) into `out`;
/// returns one summary line per engine.
pub fn textures(out: &Path, setup: Setup, pictured: u32) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let side = setup.samples;
    let flight = Flight::new(side, setup.frames, [WIDTH, HEIGHT], false)?;
    let (s, h) = flight.views()?;
    let Flight {
        land,
        full,
        cameras,
        ..
    } = &flight;
    let colors = land.colors.clone().ok_or("the terrain has no colours")?;

    // Coordinates: the full mesh's and the leaves' from where they sample the grid, the base
    // vertices' the same way, a parent's the mean of its children's (children have larger ids).
    let full_uvs: Vec<Uv> = full.positions.iter().map(|&p| planar(p, side)).collect();
    let base_uvs: Vec<Uv> = (0..s.counts().base_vertices)
        .map(|v| planar(s.position(v), side))
        .collect();
    let mut node_uvs = vec![[0.0f32; 2]; h.nodes() as usize];
    for i in (0..h.nodes()).rev() {
        node_uvs[i as usize] = match h.children(i) {
            [c0, c1] if h.is_parent(i) => {
                let (a, b) = (node_uvs[c0 as usize], node_uvs[c1 as usize]);
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
            }
            _ => planar(h.node(i).position, side),
        };
    }

    let texels: Vec<Rgba8> = colors
        .iter()
        .map(|c| Rgba8([c[0], c[1], c[2], 255]))
        .collect();
    let colormap = Texture::new(&texels, side, side, Filter::Bilinear, Wrap::Clamp)
        .map_err(|e| e.to_string())?;
    let checker_texels = crate::atlas::checker_texels(CELLS);
    let checker = Texture::new(&checker_texels, CELLS, CELLS, Filter::Nearest, Wrap::Repeat)
        .map_err(|e| e.to_string())?;
    let textured = Style {
        base_color: [255; 3],
        ..style(Shading::Gouraud, false)
    };
    let per_vertex = Style {
        vertex_colors: true,
        ..style(Shading::Gouraud, false)
    };

    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    let mut engines = Engines::new(&s, &h)?;
    // Textured meshes have no vertex colours: the texel is modulated by the light alone.
    let full_colored = full.as_raster_mesh();
    let full_textured = vdlod_raster::Mesh {
        uvs: Some(&full_uvs),
        colors: None,
        ..full_colored
    };
    // Per engine and frame: triangles, and PSNR per kind.
    let mut measured: [Vec<(u32, [f64; 3])>; 2] = [Vec::new(), Vec::new()];
    let mut panels = Vec::new();
    let start = Instant::now();
    for (i, camera) in (0..).zip(cameras) {
        let mut references = Vec::new();
        frame
            .draw_textured(&full_textured, camera, &textured, &colormap)
            .map_err(|e| e.to_string())?;
        references.push(frame.pixels().to_vec());
        frame
            .draw_textured(&full_textured, camera, &textured, &checker)
            .map_err(|e| e.to_string())?;
        references.push(frame.pixels().to_vec());
        frame
            .draw_styled(&full_colored, camera, &per_vertex)
            .map_err(|e| e.to_string())?;
        references.push(frame.pixels().to_vec());

        let stats = engines.adapt_wavelet(&s, camera)?;
        let forest_stats = engines.adapt_forest(&h, camera, stats.triangles)?;
        let (wavelet, forest) = (&engines.wavelet, &engines.forest);
        let wavelet_mesh = WaveletMesh::new(wavelet, &s, false).with_uvs(&base_uvs);
        let forest_mesh = CutMesh::new(forest, &h, false).with_uvs(&node_uvs);
        let wavelet_colored = WaveletMesh::new(wavelet, &s, true);
        let forest_colored = CutMesh::new(forest, &h, true);
        for (engine, triangles) in [(0, stats.triangles), (1, forest_stats.triangles)] {
            let mut scores = [0.0; 3];
            for (k, score) in scores.iter_mut().enumerate() {
                let drawn = match (engine, k) {
                    (0, 0) => frame.draw_textured(&wavelet_mesh, camera, &textured, &colormap),
                    (0, 1) => frame.draw_textured(&wavelet_mesh, camera, &textured, &checker),
                    (0, _) => frame.draw_styled(&wavelet_colored, camera, &per_vertex),
                    (_, 0) => frame.draw_textured(&forest_mesh, camera, &textured, &colormap),
                    (_, 1) => frame.draw_textured(&forest_mesh, camera, &textured, &checker),
                    (_, _) => frame.draw_styled(&forest_colored, camera, &per_vertex),
                };
                drawn.map_err(|e| e.to_string())?;
                *score = psnr(frame.pixels(), &references[k]).min(99.0);
                // The pictures: both engines textured, the wavelet engine also coloured per vertex.
                if i == pictured && (k < 2 || engine == 0) {
                    let name = ["wavelets", "vertex forest"][engine];
                    panels.push((
                        engine * 3 + k,
                        Panel {
                            caption: format!(
                                "{name}, {}: {triangles} triangles, {score:.1} dB",
                                KINDS[k]
                            ),
                            pixels: frame.pixels().to_vec(),
                        },
                    ));
                }
            }
            measured[engine].push((triangles, scores));
        }
        if i == pictured {
            frame
                .draw_textured(&full_textured, camera, &textured, &checker)
                .map_err(|e| e.to_string())?;
            panels.push((
                5,
                Panel {
                    caption: format!("full detail, {} triangles", full.triangles.len()),
                    pixels: frame.pixels().to_vec(),
                },
            ));
        }
    }
    panels.sort_by_key(|p| p.0);
    let panels: Vec<Panel> = panels.into_iter().map(|p| p.1).collect();
    let png = sheet(&panels, 3, [WIDTH, HEIGHT])?;
    let path = out.join("textures.png");
    std::fs::write(&path, png).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;

    let seconds = start.elapsed().as_secs_f64();
    let mut lines = Vec::new();
    for (engine, name) in ["wavelet", "forest"].into_iter().enumerate() {
        // The first frame starts from the base mesh.
        let after_first = || measured[engine].iter().skip(1);
        let kind = |k: usize| mean(after_first().map(|m| m.1[k]));
        lines.push(format!(
            "experiment=textures engine={name} grid={side}x{side} frames={} triangles_mean={:.0} psnr_colormap_texture_db={:.2} psnr_checker_db={:.2} psnr_vertex_colors_db={:.2} seconds={seconds:.1}",
            setup.frames,
            mean(after_first().map(|m| m.0 as f64)),
            kind(0),
            kind(1),
            kind(2),
        ));
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::{Terrain, DEFAULT_VERTICAL_SCALE, UP_AXIS};
    use crate::wavelet::DemoWaveletCut;
    use vdlod::Orbit;
    use vdlod_core::adapt::Budget;
    use vdlod_core::policy::QRefine;
    use vdlod_core::wavelet::SemiRegularView;
    use vdlod_raster::MeshSource;

    #[test]
    fn wavelet_coordinates_are_the_parametric_domain() {
        // On a terrain the parametric domain is the grid: every vertex a cut emits, wherever
        // its wavelet stands, has the coordinates of the sample its lattice point names.
        let side = 17;
        let land = Terrain::procedural(side, 3, DEFAULT_VERTICAL_SCALE);
        let bytes = land
            .semi_regular()
            .unwrap()
            .to_height_bytes(UP_AXIS)
            .unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let base_uvs: Vec<Uv> = (0..s.counts().base_vertices)
            .map(|v| planar(s.position(v), side))
            .collect();
        let mut cut = DemoWaveletCut::boxed();
        cut.reset(&s).unwrap();
        cut.set_geomorph_frames(4);
        let center = glam::Vec3::new(8.0, 0.0, 8.0);
        let orbit = Orbit::peer(center, 12.0, 16).viewport(64, 48);
        let mut checked = 0;
        for i in 0..6 {
            let camera = orbit.camera(i);
            vdlod::adapt_wavelets(
                &mut cut,
                &s,
                &camera,
                &QRefine::new(0.5),
                &Budget::default(),
            )
            .unwrap();
            let mesh = WaveletMesh::new(&cut, &s, false).with_uvs(&base_uvs);
            assert!(mesh.has_uvs());
            for v in 0..mesh.vertex_count() {
                let id = cut.vertex_id(v);
                let expected = planar(s.position(id), side);
                let uv = mesh.uv(v);
                assert!(
                    (uv[0] - expected[0]).abs() < 1e-5 && (uv[1] - expected[1]).abs() < 1e-5,
                    "vertex {id}: {uv:?} != {expected:?}"
                );
                checked += 1;
            }
        }
        assert!(checked > 6 * 20, "{checked}");
    }

    #[test]
    fn the_experiment_runs_on_a_small_terrain() {
        let out = std::env::temp_dir().join(format!("vdlod_textures_{}", std::process::id()));
        let setup = Setup {
            samples: 33,
            frames: 6,
        };
        let lines = textures(&out, setup, 3).unwrap();
        assert_eq!(lines.len(), 2);
        for line in &lines {
            for key in [
                "psnr_colormap_texture_db",
                "psnr_checker_db",
                "psnr_vertex_colors_db",
            ] {
                let db: f64 = crate::summary_value(line, key).unwrap();
                assert!(db > 15.0 && db <= 99.0, "{line}");
            }
        }
        assert!(out.join("textures.png").exists());
        std::fs::remove_dir_all(&out).unwrap();
    }
}
