//! One frame of the bunny, adapted to a camera under a triangle budget and drawn into a PNG:
//! the whole frame loop of an integration, on the host.
//!
//! ```text
//! cargo run --release --example frame [OUT.png]
//! ```
//!
//! On a device the same calls run against a hierarchy in flash (`include_bytes!`), a cut in a
//! `static` and band buffers flushed to the panel (see `vdlod::draw_bands` and
//! `tests/cortex-m/`).

use vdlod::prelude::*;
use vdlod_demo::frame::save_png;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "frame.png".into());

    // The hierarchy file: built here; a device keeps it in flash and only parses it.
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ)?;
    let (_, bytes, _) =
        vdlod_demo::hierarchy::build_with_progress(&mesh, &Default::default(), true)?;
    let h = HierarchyView::parse(&bytes)?;

    // A cut for a 5,000-triangle budget: 159,120 bytes, fixed, on the heap here.
    let mut cut = Cut::<2508, 5000, 313>::boxed();
    cut.reset(&h)?;
    let budget = Budget {
        max_triangles: 5000,
        ..Budget::default()
    };

    // One camera for the policy and the rasterizer.
    let (center, radius) = h.bounding_sphere();
    let camera = Orbit::peer(center.into(), radius, 36)
        .viewport(320, 240)
        .camera(4);
    let stats = vdlod::adapt(&mut cut, &h, &camera, &QRefine::new(1.0), &budget)?;

    // Draw into a whole frame (a device would use `vdlod::draw_bands`).
    let (w, hgt) = (camera.width, camera.height);
    let mut color = vec![Rgba8([24, 26, 32, 255]); w * hgt];
    let mut depth = vec![u16::CLEAR; w * hgt];
    let mut target = Target::new(&mut color, &mut depth, w, hgt)?;
    let mut scratch = vec![ShadedVertex::default(); cut.vertex_count()];
    let drawn = vdlod::draw(
        &mut target,
        &cut,
        &h,
        &camera,
        &Style::default(),
        &mut scratch,
    )?;
    save_png(std::path::Path::new(&out), w, hgt, &color)?;
    println!(
        "{out}: {} triangles ({} splits), {} rasterized",
        stats.triangles, stats.vsplits, drawn.rasterized
    );
    Ok(())
}
