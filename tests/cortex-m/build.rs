//! Links the firmware for the emulated board and makes the hierarchy file a build input.
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

    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
    }
}
