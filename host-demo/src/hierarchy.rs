//! The `build` and `info` commands: mesh to hierarchy file, and a file's figures.

use std::fmt;
use std::path::Path;
use std::time::Instant;

use vdlod_core::build::{build, BuildOptions, Hierarchy, InputMesh, Progress};
use vdlod_core::format::HierarchyView;

use crate::mesh::IndexedMesh;

/// The figures `build` and `info` print.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Input vertices (leaves).
    pub vertices: u32,
    /// Input triangles (the base triangles plus two per split but one per border split).
    pub faces: u32,
    /// Vertices of the base mesh (roots).
    pub base_vertices: u32,
    /// Triangles of the base mesh.
    pub base_faces: u32,
    /// Deepest leaf.
    pub max_depth: u32,
    /// Mean leaf depth.
    pub mean_depth: f64,
    /// File size.
    pub bytes: usize,
    /// Whether the error bounds are Hoppe's (else spheroids).
    pub hoppe_bounds: bool,
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "vertices {}, faces {}, base mesh {} vertices / {} faces, depth max {} mean {:.1}, \
             {} bytes ({:.1} bytes per vertex)",
            self.vertices,
            self.faces,
            self.base_vertices,
            self.base_faces,
            self.max_depth,
            self.mean_depth,
            self.bytes,
            self.bytes as f64 / self.vertices.max(1) as f64
        )?;
        if self.hoppe_bounds {
            write!(f, ", Hoppe's error bounds")?;
        }
        Ok(())
    }
}

/// Figures of a validated file.
pub fn summarize(view: &HierarchyView<'_>) -> Summary {
    let mut max_depth = 0u32;
    let mut sum = 0u64;
    for i in view.leaf_nodes() {
        let d = view.depth(i) as u32;
        max_depth = max_depth.max(d);
        sum += d as u64;
    }
    let base_vertices = view.roots();
    let border_splits = view
        .parent_nodes()
        .filter(|&p| !view.split(p).second())
        .count() as u32;
    let splits = view.nodes() - view.leaves();
    Summary {
        vertices: view.leaves(),
        faces: view.base_triangles() + 2 * splits - border_splits,
        base_vertices,
        base_faces: view.base_triangles(),
        max_depth,
        mean_depth: sum as f64 / view.leaves().max(1) as f64,
        bytes: view.size(),
        hoppe_bounds: view.hoppe_bounds(),
    }
}

/// Builds `mesh`'s hierarchy, showing a progress bar on standard error; returns it, its bytes
/// and the seconds the build took.
pub fn build_with_progress(
    mesh: &IndexedMesh,
    opts: &BuildOptions,
    show_progress: bool,
) -> Result<(Hierarchy, Vec<u8>, f64), vdlod_core::build::BuildError> {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: mesh.colors.as_deref(),
        triangles: &mesh.triangles,
    };
    let bar = if show_progress {
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} collapsing edges [{bar:40}] {pos}/{len} {elapsed}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar
    } else {
        indicatif::ProgressBar::hidden()
    };
    let start = Instant::now();
    let result = build(&input, opts, &mut |p: Progress| {
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
    });
    bar.finish_and_clear();
    let hierarchy = result?;
    let bytes = hierarchy.to_bytes(mesh.colors.is_some());
    Ok((hierarchy, bytes, start.elapsed().as_secs_f64()))
}

/// Reads and validates a hierarchy file, returning its bytes.
pub fn read(path: &Path) -> Result<Vec<u8>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(bytes)
}
