//! One frame of the wavelet engine: the unit sphere as a semi-regular mesh, its wavelets chosen
//! for a camera at the wavelet paper's Fig. 11 tolerances, drawn in bands through the same calls
//! that draw the vertex forest's cut.
//!
//! ```text
//! cargo run --release --example wavelets [OUT.png]
//! ```

use vdlod::core::wavelet::SemiRegular;
use vdlod::prelude::*;
use vdlod_demo::frame::save_png;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "wavelets.png".into());

    // The file: made here; a device keeps it in flash and only parses it.
    let bytes = SemiRegular::sphere(5)?.to_bytes()?;
    let s = SemiRegularView::parse(&bytes)?;

    // Bits for 4,096 wavelets, 5,000 triangles, 2,500 vertices, 625 queued candidates.
    let mut cut = WaveletCut::<128, 5000, 2500, 625>::boxed();
    cut.reset(&s)?;
    cut.set_geomorph_frames(8);
    let camera = Camera {
        eye: glam::Vec3::new(0.0, 0.4, 2.8),
        target: glam::Vec3::new(0.4, 0.0, 0.0),
        ..Orbit::peer(glam::Vec3::ZERO, 1.0, 8)
            .viewport(320, 240)
            .camera(0)
    };
    let policy = QRefine {
        error: ScreenError {
            silhouette: 0.5,
            interior: 3.5,
        },
    };
    // A few frames, so the geomorphs settle.
    let mut stats = FrameStats::default();
    for _ in 0..10 {
        stats = vdlod::adapt_wavelets(&mut cut, &s, &camera, &policy, &Budget::default())?;
    }

    // Drawn in 16-row bands, stitched into a picture.
    let (w, h) = (camera.width, camera.height);
    let (mut color, mut depth) = (vec![Rgb565(0); w * 16], vec![0u16; w * 16]);
    let mut bins = vec![0u32; 10_000]; // rows and band lists for up to 5,000 triangles
    let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
    let bands = Bands {
        color: &mut color,
        depth: &mut depth,
        rows: 16,
        background: Rgb565::from_rgb(24, 26, 32),
        bins: &mut bins,
    };
    let style = Style {
        wireframe: Some([30, 30, 30]),
        ..Style::default()
    };
    let mesh = WaveletMesh::new(&cut, &s, false);
    let mut picture = Vec::with_capacity(w * h);
    vdlod::draw_mesh_bands(bands, &mesh, &camera, &style, &mut scratch, |band| {
        picture.extend(band.color().iter().map(|p| {
            let [r, g, b] = p.to_rgb();
            Rgba8([r, g, b, 255])
        }))
    })?;
    save_png(std::path::Path::new(&out), w, h, &picture)?;
    println!(
        "{out}: {} triangles from {} wavelets of {} ({} bytes of cut)",
        stats.triangles,
        cut.included(),
        s.wavelets(),
        WaveletCut::<128, 5000, 2500, 625>::BYTES
    );
    Ok(())
}
