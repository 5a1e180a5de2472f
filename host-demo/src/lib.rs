//! Host side of vdlod: mesh loading, camera paths, frames and PNG output.
//!
//! The `vdlod-demo` binary is a thin command line over this library; the workspace's tests and
//! benchmarks use it too, so what they render is exactly what the demo renders.

pub mod atlas;
pub mod camera;
pub mod chart;
pub mod frame;
pub mod ground;
pub mod hierarchy;
pub mod importance;
pub mod input;
pub mod label;
pub mod lod;
pub mod mesh;
pub mod remesh;
pub mod render;
pub mod repair;
pub mod stats;
pub mod table1;
pub mod terrain;
pub mod terrain_engines;
pub mod textures;
pub mod wavelet;

/// The value of `key` in one of the `key=value` summary lines `vdlod-demo reproduce` prints
/// (`None` when the line has no such key or its value does not parse).
///
/// ```
/// let line = "experiment=terrain cost=color triangles=5001 psnr_top_db=27.82";
/// assert_eq!(vdlod_demo::summary_value::<u32>(line, "triangles"), Some(5001));
/// assert_eq!(vdlod_demo::summary_value::<f64>(line, "psnr_top_db"), Some(27.82));
/// assert_eq!(vdlod_demo::summary_value::<u32>(line, "faces"), None);
/// ```
pub fn summary_value<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    line.split(' ')
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .and_then(|v| v.parse().ok())
}

/// Writes `pass` over all of `buffer` and reads it back, as a frame's drawing would between two
/// adaptations: a profiling example that sweeps a buffer larger than the caches before a timed
/// call sees that call start cold.
///
/// ```
/// let mut buffer = vec![0u8; 1 << 16];
/// vdlod_demo::sweep_caches(&mut buffer, 3);
/// assert!(buffer.iter().all(|&b| b == 3));
/// ```
pub fn sweep_caches(buffer: &mut [u8], pass: u8) {
    buffer.fill(pass);
    std::hint::black_box(buffer.iter().fold(0u8, |a, &b| a ^ b));
}
