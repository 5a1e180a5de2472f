//! The `remesh` command's work: any mesh into a semi-regular one, with a progress bar and the
//! remesh's distances to the input.

use std::time::Instant;

use vdlod_core::build::InputMesh;
use vdlod_core::remesh::{remesh, Quality, Remesh, RemeshOptions, RemeshProgress};

use crate::mesh::IndexedMesh;

/// A remesh, its quality and the seconds it took (remeshing only, not measuring).
pub struct Remeshed {
    /// The remesh.
    pub remesh: Remesh,
    /// Measured against the input.
    pub quality: Quality,
    /// Seconds the remesher took.
    pub seconds: f64,
}

/// Remeshes `mesh`, showing a progress bar on standard error when `show_progress`.
pub fn remesh_with_progress(
    mesh: &IndexedMesh,
    options: &RemeshOptions,
    show_progress: bool,
) -> Result<Remeshed, String> {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: mesh.colors.as_deref(),
        triangles: &mesh.triangles,
    };
    let bar = if show_progress {
        indicatif::ProgressBar::new(0)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let style = |what: &str| {
        indicatif::ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:40}}] {{pos}}/{{len}} {{elapsed}}"
        ))
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> ")
    };
    let start = Instant::now();
    let result = remesh(&input, options, &mut |p| {
        let (what, done, total) = match p {
            RemeshProgress::Simplify { done, total } => ("collapsing edges", done, total),
            RemeshProgress::Map { done, total } => ("mapping back", done, total),
        };
        bar.set_style(style(what));
        bar.set_length(u64::from(total));
        bar.set_position(u64::from(done));
    });
    let seconds = start.elapsed().as_secs_f64();
    bar.set_style(style("measuring"));
    let remesh = result.map_err(|e| e.to_string())?;
    let quality = remesh.quality(&input);
    bar.finish_and_clear();
    Ok(Remeshed {
        remesh,
        quality,
        seconds,
    })
}

/// One `key=value` line of a remesh's figures.
pub fn summary(r: &Remeshed, levels: u32) -> String {
    let q = &r.quality;
    let triangles: u32 = q.shapes.iter().sum();
    let below = |x: usize| q.shapes[..x].iter().sum::<u32>() as f64 / triangles.max(1) as f64;
    format!(
        "base_faces={} levels={} faces={} collapses={} hausdorff_pct={:.3} rms_pct={:.4} \
         flipped={} worst_weight={:.1e} shape_below_0.3_pct={:.2} shape_below_0.5_pct={:.2} \
         seconds={:.2} farthest={:?}",
        r.remesh.base_faces,
        levels,
        triangles,
        r.remesh.collapses,
        100.0 * q.hausdorff,
        100.0 * q.rms,
        q.flipped,
        r.remesh.worst_weight,
        100.0 * below(3),
        100.0 * below(5),
        r.seconds,
        q.farthest
    )
}
