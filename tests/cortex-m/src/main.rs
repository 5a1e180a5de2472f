//! vdlod frames on an emulated Cortex-M7 (qemu `mps2-an500`), and the host twin of the same
//! source: both run [`frames::run_frames`] over the same embedded hierarchy and print one hash
//! per frame; `run.sh` compares them.
//!
//! The hierarchy is embedded with `include_bytes!` from the file `VDLOD_HIERARCHY` names (an
//! absolute path; `run.sh` builds the file and exports it). On the device it stays in flash
//! (`.rodata`) and is read in place.
#![cfg_attr(target_os = "none", no_std, no_main)]

mod clock;
#[cfg(target_os = "none")]
mod device;
mod frames;

/// The hierarchy file, in flash on the device.
static HIERARCHY: &[u8] = include_bytes!(env!("VDLOD_HIERARCHY"));

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    match frames::run_frames(HIERARCHY, &mut |r| println!("{r}")) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            println!("error={e}");
            std::process::ExitCode::FAILURE
        }
    }
}
