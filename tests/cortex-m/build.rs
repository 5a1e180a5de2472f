//! Links the firmware for the emulated board, makes the hierarchy file a build input, and writes
//! the frame's configuration (`VDLOD_FW_BUDGET` triangles, default 5,000, and a
//! `VDLOD_FW_WIDTH` x `VDLOD_FW_HEIGHT` frame, default 320x240) as constants, so that
//! `tests/cortex-m/table.sh` can link and run other sizes.
//!
//! On `target_os = "none"` (thumbv7em-none-eabihf) it puts `memory.x` where cortex-m-rt's
//! `link.x` includes it from and passes `-Tlink.x` to the binary's link; a host build of the same
//! crate gets none of that, so no `.cargo/config.toml` with target rustflags is needed.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-env-changed=VDLOD_HIERARCHY");

    match env::var("VDLOD_HIERARCHY") {
        Ok(path) if !path.is_empty() => println!("cargo:rerun-if-changed={path}"),
        _ => panic!(
            "VDLOD_HIERARCHY must name the .vdh file to embed (absolute path); \
             tests/cortex-m/run.sh builds one and exports it"
        ),
    }

    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let number = |name: &str, default: usize| -> usize {
        println!("cargo:rerun-if-env-changed={name}");
        match env::var(name) {
            Ok(v) => v
                .parse()
                .unwrap_or_else(|_| panic!("{name}={v} is not a positive number")),
            Err(_) => default,
        }
    };
    let budget = number("VDLOD_FW_BUDGET", 5000).max(16);
    let (width, height) = (
        number("VDLOD_FW_WIDTH", 320),
        number("VDLOD_FW_HEIGHT", 240),
    );
    // The capacities of the table in `docs/device.md`: half a vertex slot per triangle plus
    // eight, and a queue of an eighth of the vertex slots.
    let vertices = budget / 2 + 8;
    fs::write(
        out.join("config.rs"),
        format!(
            "/// Triangle slots of the cut (and the budget).\n\
             pub const TRIANGLES: usize = {budget};\n\
             /// Vertex slots of the cut.\n\
             pub const VERTICES: usize = {vertices};\n\
             /// Entries of each work queue of the cut.\n\
             pub const QUEUE: usize = {};\n\
             /// Frame width in pixels.\n\
             pub const WIDTH: usize = {width};\n\
             /// Frame height in pixels.\n\
             pub const HEIGHT: usize = {height};\n",
            vertices / 8
        ),
    )
    .expect("write config.rs");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
    }
}
