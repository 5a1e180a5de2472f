//! The demo's command line: bad input gives one clear line naming the file, and a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn demo(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vdlod-demo"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run vdlod-demo")
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn assert_one_line_error(name: &str, text: &str, problem: &str) {
    let dir = scratch_dir(&format!("cli_{name}"));
    std::fs::write(dir.join(name), text).unwrap();
    let out = demo(
        &[
            "render", name, "--frames", "1", "--width", "32", "--height", "24",
        ],
        &dir,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{name}: expected failure");
    assert_eq!(stderr.lines().count(), 1, "{name}: {stderr}");
    assert!(
        stderr.contains(name),
        "{name}: message does not name the file: {stderr}"
    );
    assert!(
        stderr.contains(problem),
        "{name}: expected '{problem}' in: {stderr}"
    );
}

#[test]
fn missing_file() {
    let dir = scratch_dir("cli_missing");
    let out = demo(&["render", "nope.obj"], &dir);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1);
    assert!(stderr.contains("nope.obj: cannot read"), "{stderr}");
}

#[test]
fn malformed_obj() {
    assert_one_line_error("bad.obj", "v 0 0 zero\nf 1 2 3\n", "malformed OBJ");
}

#[test]
fn index_out_of_range() {
    assert_one_line_error(
        "range.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
        "out of range",
    );
}

#[test]
fn non_finite_coordinates() {
    assert_one_line_error(
        "nan.obj",
        "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
        "vertex 2 has a NaN",
    );
    assert_one_line_error(
        "inf.obj",
        "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n",
        "vertex 3 has a NaN or infinite",
    );
}

#[test]
fn no_triangles() {
    assert_one_line_error("empty.obj", "# nothing\n", "no vertices");
    assert_one_line_error(
        "points.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n",
        "no triangles",
    );
    assert_one_line_error(
        "lines.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n",
        "no triangles",
    );
}

#[test]
fn bad_viewport() {
    let dir = scratch_dir("cli_viewport");
    let out = demo(&["render", "--frames", "1", "--width", "0"], &dir);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("zero width or height"), "{stderr}");
}

#[test]
fn renders_a_small_mesh() {
    let dir = scratch_dir("cli_ok");
    std::fs::write(
        dir.join("tetra.obj"),
        "v 1 1 1\nv 1 -1 -1\nv -1 1 -1\nv -1 -1 1\nf 1 3 4\nf 1 4 2\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let out = demo(
        &[
            "render",
            "tetra.obj",
            "--out",
            "frames",
            "--frames",
            "2",
            "--width",
            "40",
            "--height",
            "30",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("frame 0001  triangles"), "{stdout}");
    let (w, h, pixels) = vdlod_demo::frame::load_png(&dir.join("frames/frame_0000.png")).unwrap();
    assert_eq!((w, h), (40, 30));
    assert!(pixels.iter().any(|p| *p != vdlod_demo::frame::BACKGROUND));
    assert!(dir.join("frames/frame_0001.png").exists());
}
