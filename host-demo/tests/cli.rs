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

/// Runs the demo and checks it succeeded, showing its error output when it did not.
fn succeed(args: &[&str], cwd: &Path) -> Output {
    let out = demo(args, cwd);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `text` to `name`, runs the demo with `args` (where `FILE` stands for `name`), and checks
/// it fails with one line naming the file and the problem.
fn assert_one_line_failure(name: &str, text: &str, args: &[&str], problem: &str) {
    let dir = scratch_dir(&format!("cli_{}_{name}", args[0]));
    std::fs::write(dir.join(name), text).unwrap();
    let args: Vec<&str> = args
        .iter()
        .map(|&a| if a == "FILE" { name } else { a })
        .collect();
    let out = demo(&args, &dir);
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

fn assert_one_line_error(name: &str, text: &str, problem: &str) {
    let render = [
        "render", "FILE", "--frames", "1", "--width", "32", "--height", "24",
    ];
    assert_one_line_failure(name, text, &render, problem);
}

fn assert_build_error(name: &str, text: &str, problem: &str) {
    assert_one_line_failure(name, text, &["build", "FILE", "-o", "x.vdh"], problem);
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
    assert_one_line_error(
        "bad.obj",
        "v 0 0 zero\nf 1 2 3\n",
        "bad.obj: OBJ: line 1: `zero` is not a number",
    );
    assert_one_line_error(
        "bad.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty half x\nend_header\n",
        "bad.ply: PLY: line 4: header: unknown type `half`",
    );
    assert_one_line_error(
        "short.off",
        "OFF\n3 1 0\n0 0 0\n1 0 0\n",
        "short.off: OFF: line 5: the file ends while reading the vertices",
    );
    let mut stl = vec![0u8; 80];
    stl.extend(16u32.to_le_bytes());
    assert_one_line_error(
        "short.stl",
        &String::from_utf8(stl).unwrap(),
        "short.stl: STL: byte 84: the file ends while reading the triangles",
    );
    assert_build_error(
        "x.vdh",
        "VDLH and more",
        "x.vdh: this is a vdlod hierarchy (.vdh), not a mesh",
    );
    assert_one_line_error(
        "what.bin",
        "\u{1}\u{2}",
        "what.bin: not a mesh format vdlod reads",
    );
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

/// Flag values that mean nothing are refused before any work, with the allowed range.
#[test]
fn bad_flag_values_are_refused_with_their_range() {
    let dir = scratch_dir("cli_flags");
    for (args, range) in [
        (
            &["render", "--frames", "1", "--width", "0"][..],
            "1 to 4096",
        ),
        (&["render", "--height", "5000"][..], "1 to 4096"),
        (&["orbit", "--width", "0"][..], "1 to 4096"),
        (&["orbit", "--tolerance", "nan"][..], "at least 0"),
        (&["orbit", "--tolerance", "-1"][..], "at least 0"),
        (&["orbit", "--interior", "inf"][..], "at least 0"),
        (&["orbit", "--threshold", "-0.5"][..], "at least 0"),
        (&["orbit", "--frustum", "0"][..], "above 0"),
        (&["orbit", "--budget", "0"][..], "1.."),
        (&["orbit", "--target", "0"][..], "1.."),
        (&["orbit", "--max-ops", "0"][..], "1.."),
        (&["orbit", "--max-visits", "0"][..], "1.."),
    ] {
        let out = demo(args, &dir);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let first = stderr.lines().next().unwrap_or("");
        assert!(first.contains(args[args.len() - 2]), "{args:?}: {stderr}");
        assert!(first.contains(range), "{args:?}: {stderr}");
        assert!(
            !dir.join("out").exists(),
            "{args:?} did work before refusing"
        );
    }
}

#[test]
fn renders_a_small_mesh() {
    let dir = scratch_dir("cli_ok");
    std::fs::write(
        dir.join("tetra.obj"),
        "v 1 1 1\nv 1 -1 -1\nv -1 1 -1\nv -1 -1 1\nf 1 3 4\nf 1 4 2\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let out = succeed(
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
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("frame 0001  triangles"), "{stdout}");
    let (w, h, pixels) = vdlod_demo::frame::load_png(&dir.join("frames/frame_0000.png")).unwrap();
    assert_eq!((w, h), (40, 30));
    assert!(pixels.iter().any(|p| *p != vdlod_demo::frame::BACKGROUND));
    assert!(dir.join("frames/frame_0001.png").exists());
}

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures")
        .join(name)
}

#[test]
fn build_and_info_agree_on_an_open_mesh() {
    let dir = scratch_dir("cli_build");
    let head = fixture("head.obj");
    let out = succeed(
        &[
            "build",
            head.to_str().unwrap(),
            "-o",
            "head.vdh",
            "--balanced",
        ],
        &dir,
    );
    let built = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(built.contains("vertices 1487, faces 2918"), "{built}");
    let info = demo(&["info", "head.vdh"], &dir);
    assert!(info.status.success());
    let info = String::from_utf8_lossy(&info.stdout).into_owned();
    // Same figures line from the file as from the build.
    assert_eq!(built.lines().next(), info.lines().next());
}

#[test]
fn hoppe_bounds_are_built_marked_and_flown_with_his_test() {
    let dir = scratch_dir("cli_bound");
    let head = fixture("head.obj");
    for bound in ["spheroid", "hoppe"] {
        let file = format!("{bound}.vdh");
        let args = [
            "build",
            head.to_str().unwrap(),
            "-o",
            &file,
            "--bound",
            bound,
        ];
        let built = String::from_utf8_lossy(&succeed(&args, &dir).stdout).into_owned();
        let info = String::from_utf8_lossy(&succeed(&["info", &file], &dir).stdout).into_owned();
        let marked = bound == "hoppe";
        assert_eq!(info.contains("Hoppe's error bounds"), marked, "{info}");
        assert_eq!(built.lines().next(), info.lines().next());
        let flown = succeed(&["orbit", &file, "--frames", "2", "-o", bound], &dir);
        let said = String::from_utf8_lossy(&flown.stdout);
        assert_eq!(said.contains("tested as he does"), marked, "{said}");
    }
    let out = demo(&["build", "x.obj", "-o", "x.vdh", "--bound", "box"], &dir);
    assert!(!out.status.success());
}

#[test]
fn endpoint_placement_builds_and_flies() {
    let dir = scratch_dir("cli_placement");
    let head = fixture("head.obj");
    let args = ["build", head.to_str().unwrap(), "-o", "e.vdh"];
    let built = succeed(&[&args[..], &["--placement", "endpoint"]].concat(), &dir);
    let built = String::from_utf8_lossy(&built.stdout).into_owned();
    assert!(built.contains("vertices 1487, faces 2918"), "{built}");
    succeed(&["orbit", "e.vdh", "--frames", "2", "-o", "o"], &dir);
    // The terrain's forest too; the stats count new triangles by what the vertices are.
    let terrain = ["terrain", "--size", "33", "--frames", "3", "--width", "48"];
    let out = succeed(
        &[&terrain[..], &["--height", "32", "--placement", "endpoint"]].concat(),
        &dir,
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("new)"));
    assert!(dir.join("out/terrain/stats.csv").exists());
    let out = demo(&[&args[..], &["--placement", "middle"]].concat(), &dir);
    assert!(!out.status.success());
}

#[test]
fn info_rejects_corrupted_files_in_one_line() {
    let dir = scratch_dir("cli_info_bad");
    let out = demo(
        &[
            "build",
            fixture("cow.obj").to_str().unwrap(),
            "-o",
            "cow.vdh",
        ],
        &dir,
    );
    assert!(out.status.success());
    let mut bytes = std::fs::read(dir.join("cow.vdh")).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0xFF;
    std::fs::write(dir.join("bad.vdh"), &bytes).unwrap();
    let out = demo(&["info", "bad.vdh"], &dir);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("bad.vdh: checksum mismatch"), "{stderr}");
}

#[test]
fn strict_build_rejects_non_manifold_meshes_in_one_line() {
    let strict = ["build", "FILE", "--strict", "-o", "x.vdh"];
    let fin = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    assert_one_line_failure("fin.obj", fin, &strict, "non-manifold");
    let dup = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 3 1\n";
    assert_one_line_failure("dup.obj", dup, &strict, "repeats triangle 0");
}

#[test]
fn repair_says_what_it_did_and_writes_a_mesh_strict_accepts() {
    let dir = scratch_dir("cli_repair");
    // Two squares touching at a corner (a bow tie), one triangle listed twice, one flipped.
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0 0\nv -1 -1 0\nv 0 -1 0\n\
                f 1 2 3\nf 1 4 3\nf 1 3 4\nf 1 5 6\nf 1 6 7\n";
    std::fs::write(dir.join("tie.obj"), text).unwrap();
    let out = succeed(&["repair", "tie.obj", "-o", "fixed.obj"], &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(
            "tie.obj: OBJ, 8 vertices, 4 triangles after repair: 1 repeated triangle dropped, \
             1 triangle flipped, 1 vertex split"
        ),
        "{stdout}"
    );
    succeed(&["build", "fixed.obj", "--strict", "-o", "x.vdh"], &dir);
    // The same file builds without --strict, saying what was repaired.
    let out = succeed(&["build", "tie.obj", "-o", "y.vdh"], &dir);
    assert!(String::from_utf8_lossy(&out.stdout).contains("tie.obj: OBJ: repaired: "));
}

#[test]
fn every_format_builds_and_renders() {
    let dir = scratch_dir("cli_formats");
    // A tetrahedron in each format.
    let p = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"];
    let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let off = format!(
        "OFF\n4 4 0\n{}\n{}\n",
        p.join("\n"),
        t.map(|t| format!("3 {} {} {}", t[0], t[1], t[2]))
            .join("\n")
    );
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n{}\n{}\n",
        p.join("\n"),
        t.map(|t| format!("3 {} {} {}", t[0], t[1], t[2])).join("\n")
    );
    let facets: String = t
        .iter()
        .map(|t| {
            let v: String = t.iter().map(|&i| format!("vertex {}\n", p[i])).collect();
            format!("facet normal 0 0 0\nouter loop\n{v}endloop\nendfacet\n")
        })
        .collect();
    let stl = format!("solid t\n{facets}endsolid t\n");
    for (name, text) in [("t.off", off), ("t.ply", ply), ("t.stl", stl)] {
        std::fs::write(dir.join(name), text).unwrap();
        succeed(
            &["build", name, "--strict", "--up", "z", "-o", "t.vdh"],
            &dir,
        );
    }
    // `render` takes the hierarchy too, found by its content.
    std::fs::rename(dir.join("t.vdh"), dir.join("t.bin")).unwrap();
    succeed(
        &[
            "render", "t.bin", "--frames", "1", "--width", "16", "--height", "12",
        ],
        &dir,
    );
    assert!(dir.join("out/frame_0000.png").exists());
}

#[test]
fn orbit_writes_frames_statistics_plot_comparison_and_meshes() {
    let dir = scratch_dir("cli_orbit");
    let cow = fixture("cow.obj");
    let out = demo(&["build", cow.to_str().unwrap(), "-o", "cow.vdh"], &dir);
    assert!(out.status.success());
    for input in [cow.to_str().unwrap(), "cow.vdh"] {
        succeed(
            &[
                "orbit",
                input,
                "--out",
                "o",
                "--frames",
                "4",
                "--width",
                "64",
                "--height",
                "48",
                "--budget",
                "1500",
                "--dump-mesh",
            ],
            &dir,
        );
        let csv = std::fs::read_to_string(dir.join("o/stats.csv")).unwrap();
        let mut lines = csv.lines();
        assert!(lines
            .next()
            .unwrap()
            .starts_with("frame,triangles,vsplits,ecols,adapt_us,render_us"));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), 4);
        for (i, row) in rows.iter().enumerate() {
            let triangles: usize = row[1].parse().unwrap();
            assert!(triangles > 0 && triangles <= 1500, "{row:?}");
            // The dumped mesh has exactly the frame's triangles, over its own vertices.
            let obj = std::fs::read_to_string(dir.join(format!("o/mesh_{i:04}.obj"))).unwrap();
            let faces = obj.lines().filter(|l| l.starts_with("f ")).count();
            let vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
            assert_eq!(faces, triangles);
            assert!(obj
                .lines()
                .filter(|l| l.starts_with("f "))
                .flat_map(|l| l.split_whitespace().skip(1))
                .all(|k| (1..=vertices).contains(&k.parse::<usize>().unwrap())));
            assert!(dir.join(format!("o/frame_{i:04}.png")).exists());
        }
        let (w, h, _) = vdlod_demo::frame::load_png(&dir.join("o/side_by_side.png")).unwrap();
        assert_eq!((w, h), (192, 48));
        assert!(dir.join("o/plot.png").exists());
    }
}

#[test]
fn orbit_rejects_a_corrupted_hierarchy_in_one_line() {
    let dir = scratch_dir("cli_orbit_bad");
    std::fs::write(dir.join("bad.vdh"), b"VDLH not really").unwrap();
    let out = demo(&["orbit", "bad.vdh", "--frames", "1"], &dir);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("bad.vdh: truncated"), "{stderr}");
}

/// A forged split record with a valid checksum passes the format checks but not a full
/// refinement: `info` rejects it as `orbit` does, with the same reason.
#[test]
fn info_rejects_what_orbit_rejects() {
    use vdlod_core::build::{build, InputMesh};
    use vdlod_core::format::{HierarchyView, NONE};
    use vdlod_demo::mesh::{load_obj_bytes, COW_NAME, COW_OBJ};
    let dir = scratch_dir("cli_info_forged");
    let cow = load_obj_bytes(COW_NAME, COW_OBJ).unwrap();
    let input = InputMesh {
        positions: &cow.positions,
        colors: None,
        triangles: &cow.triangles,
    };
    let mut h = build(&input, &Default::default(), &mut |_| {}).unwrap();
    // Swap the neighbours of the first added triangle of the first split that has both.
    let p = (h.leaves as usize..h.nodes.len())
        .find(|&p| h.nodes[p].neighbours[0] != NONE && h.nodes[p].neighbours[1] != NONE)
        .unwrap();
    h.nodes[p].neighbours.swap(0, 1);
    let bytes = h.to_bytes(false);
    assert!(
        HierarchyView::parse(&bytes).is_ok(),
        "the forgery passes the format checks"
    );
    std::fs::write(dir.join("forged.vdh"), &bytes).unwrap();
    for args in [
        &["info", "forged.vdh"][..],
        &["orbit", "forged.vdh", "--frames", "1"],
    ] {
        let out = demo(args, &dir);
        assert!(!out.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("forged.vdh: "), "{stderr}");
        assert!(stderr.contains("contradict"), "{args:?}: {stderr}");
    }
    // An old file says to rebuild it.
    let mut old = bytes.clone();
    old[4] = 2;
    std::fs::write(dir.join("old.vdh"), &old).unwrap();
    let out = demo(&["info", "old.vdh"], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("rebuild"),
        "{stderr}"
    );
}

/// A budget below the base mesh is honoured as far as it can be, and said once.
#[test]
fn orbit_warns_once_when_the_base_mesh_exceeds_the_budget() {
    let dir = scratch_dir("cli_orbit_budget");
    let head = fixture("head.obj");
    let args = [
        "orbit",
        head.to_str().unwrap(),
        "--budget",
        "5",
        "--frames",
        "3",
        "--width",
        "32",
        "--height",
        "24",
    ];
    let out = demo(&args, &dir);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches("warning").count(), 1, "{stderr}");
    assert!(stderr.contains("more than the budget of 5"), "{stderr}");
}

#[test]
fn sphere_info_and_subdivide_write_semi_regular_files() {
    let dir = scratch_dir("cli_semi_regular");
    let out = succeed(
        &["sphere", "--levels", "3", "-o", "s.vdw", "--obj", "s.obj"],
        &dir,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("8 faces") && stdout.contains("512 faces at full detail"),
        "{stdout}"
    );
    let obj = std::fs::read_to_string(dir.join("s.obj")).unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 512);
    let info = demo(&["info", "s.vdw"], &dir);
    assert!(String::from_utf8_lossy(&info.stdout).contains("252 wavelets"));
    // Measured against its own finest level (within the 16-bit positions), then against that
    // level subdivided once more (Loop moves the vertices inwards): the distances say so.
    let pct = |args: &[&str]| {
        let out = succeed(args, &dir);
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let field = text
            .split("hausdorff_pct=")
            .nth(1)
            .unwrap_or_else(|| panic!("{text}"));
        field.split(' ').next().unwrap().parse::<f64>().unwrap()
    };
    assert!(pct(&["info", "s.vdw", "--against", "s.obj"]) < 0.01);
    succeed(
        &[
            "subdivide",
            "s.obj",
            "--levels",
            "1",
            "-o",
            "u.vdw",
            "--obj",
            "u.obj",
        ],
        &dir,
    );
    let apart = pct(&["info", "s.vdw", "--against", "u.obj"]);
    assert!(apart > 0.1 && apart < 10.0, "{apart}");
    // A corrupted file: one line, the file and the problem.
    let mut bytes = std::fs::read(dir.join("s.vdw")).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(dir.join("bad.vdw"), &bytes).unwrap();
    let bad = demo(&["info", "bad.vdw"], &dir);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("bad.vdw") && stderr.contains("checksum"),
        "{stderr}"
    );
    // Subdividing an OBJ (the sphere's own finest level, as a base of 512 faces).
    let sub = succeed(
        &["subdivide", "s.obj", "--levels", "1", "-o", "t.vdw"],
        &dir,
    );
    assert!(String::from_utf8_lossy(&sub.stdout).contains("2048 faces at full detail"));
}

#[test]
fn subdivide_rejects_a_non_manifold_mesh_in_one_line() {
    let fan = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 1 2 4\nf 1 2 5\n";
    assert_one_line_failure(
        "fan.obj",
        fan,
        &["subdivide", "FILE", "--strict", "-o", "x.vdw"],
        "non-manifold",
    );
}

#[test]
fn subdivide_to_obj_writes_the_loop_subdivided_mesh() {
    let dir = scratch_dir("cli_subdivide_obj");
    let tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    std::fs::write(dir.join("tetra.obj"), tetra).unwrap();
    let out = succeed(
        &["subdivide", "tetra.obj", "--levels", "2", "-o", "fine.obj"],
        &dir,
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("34 vertices, 64 triangles"), "{said}");
    let text = std::fs::read_to_string(dir.join("fine.obj")).unwrap();
    // Each step makes four triangles of one and a vertex on every edge: 4 -> 16 -> 64
    // triangles, 4 -> 10 -> 34 vertices.
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 64);
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 34);
    // It reads back and builds like any mesh.
    succeed(&["build", "fine.obj", "-o", "fine.vdh"], &dir);
    // Options that only a semi-regular output has are refused, in one line.
    let out = demo(
        &["subdivide", "tetra.obj", "--base", "2", "-o", "x.obj"],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--base"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!dir.join("x.obj").exists());
}

#[test]
fn a_frame_time_target_regulates_and_bad_ones_are_refused() {
    let dir = scratch_dir("cli_target_ms");
    // A target far below any frame's time: the threshold rises every frame the blends allow.
    succeed(
        &[
            "orbit",
            "--target-ms",
            "0.001",
            "--frames",
            "12",
            "-o",
            "out",
        ],
        &dir,
    );
    let csv = std::fs::read_to_string(dir.join("out/stats.csv")).unwrap();
    let thresholds: Vec<f32> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(11).unwrap().parse().unwrap())
        .collect();
    assert_eq!(thresholds[0], 1.0);
    assert!(
        thresholds.windows(2).all(|w| w[1] >= w[0]),
        "{thresholds:?}"
    );
    assert!(thresholds[11] >= 4.0, "{thresholds:?}");
    for bad in ["0", "-1", "nan"] {
        let out = demo(&["orbit", "--target-ms", bad, "-o", "out"], &dir);
        assert!(!out.status.success(), "{bad}");
    }
}

#[test]
fn a_visit_window_asks_at_most_that_many_vertices() {
    let dir = scratch_dir("cli_max_visits");
    succeed(
        &["orbit", "--max-visits", "100", "--frames", "6", "-o", "out"],
        &dir,
    );
    let csv = std::fs::read_to_string(dir.join("out/stats.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|&c| c == name).unwrap();
    let (visited, blending, vertices) = (column("visited"), column("blending"), column("vertices"));
    for line in csv.lines().skip(1) {
        let row: Vec<u32> = line
            .split(',')
            .map(|c| c.parse::<f32>().unwrap() as u32)
            .collect();
        // The window, plus the vertices of the running geomorphs (two per split or collapse).
        assert!(row[visited] >= 1, "{line}");
        assert!(row[visited] <= 100 + 2 * row[blending] + 2, "{line}");
        assert!(row[vertices] > 100, "{line}");
    }
}

#[test]
fn near_needs_the_merge_tree_policy() {
    let dir = scratch_dir("cli_near");
    let out = demo(&["orbit", "--near", "2", "-o", "out"], &dir);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--near needs --policy merge-tree"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let out = demo(&["orbit", "--policy", "merge-tree", "--near", "-1"], &dir);
    assert!(!out.status.success());
}

#[test]
fn reproduce_fig11_writes_pictures_csv_and_summary_lines() {
    let dir = scratch_dir("cli_reproduce");
    let help = demo(&["reproduce", "--help"], &dir);
    let text = String::from_utf8_lossy(&help.stdout);
    for name in [
        "fig11",
        "fig9",
        "fig10",
        "table1",
        "engines",
        "terrain",
        "Azuma",
        "importance",
    ] {
        assert!(text.contains(name), "{name} missing from: {text}");
    }
    let out = demo(&["reproduce", "fig11", "--rounds", "2"], &dir);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--rounds applies to table1 only"), "{err}");
    let out = succeed(&["reproduce", "fig11", "-o", "out"], &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("experiment=fig11"))
        .collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    for line in &lines {
        let faces: u32 = field(line, "faces");
        assert!(faces > 100 && faces < 8192, "{line}");
    }
    for file in [
        "full.png",
        "wavelet.png",
        "forest.png",
        "observer.png",
        "fig11.csv",
    ] {
        assert!(dir.join("out/fig11").join(file).exists(), "{file}");
    }
}

/// The value of `key` in a `key=value` summary line.
fn field<T: std::str::FromStr>(line: &str, key: &str) -> T {
    vdlod_demo::summary_value(line, key).unwrap_or_else(|| panic!("no {key} in {line}"))
}

#[test]
fn reproduce_terrain_reduces_refines_and_compares_the_costs() {
    let dir = scratch_dir("cli_reproduce_terrain");
    let out = succeed(&["reproduce", "terrain", "-o", "out"], &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = |cost: &str, mesh: &str, setting: Option<&str>| -> String {
        stdout
            .lines()
            .find(|l| {
                l.starts_with("experiment=terrain")
                    && l.contains(&format!(" cost={cost} "))
                    && l.contains(&format!(" mesh={mesh} "))
                    && setting.is_none_or(|s| l.contains(&format!("threshold_setting={s} ")))
            })
            .unwrap_or_else(|| panic!("no {cost} {mesh} line in {stdout}"))
            .to_string()
    };
    for (mesh, want) in [("25%", 5000), ("10%", 2000)] {
        let (color, qem) = (line("color", mesh, None), line("qem", mesh, None));
        for l in [&color, &qem] {
            assert_eq!(field::<u32>(l, "full_triangles"), 20_000);
            let n: u32 = field(l, "triangles");
            assert!(n == want || n == want + 1, "{l}");
        }
        // Seen from above, where colour is all there is to see, the two costs come within a
        // dB of each other (25%: colour 27.8, QEM 27.4 dB; 10%: 24.2 and 25.1). QEM keeps the
        // island's outline by its boundary quadrics: without them its border crept inwards and
        // it scored 8 dB below the colour cost from above.
        let (c, q): (f64, f64) = (field(&color, "psnr_top_db"), field(&qem, "psnr_top_db"));
        assert!((c - q).abs() < 2.0, "{color}\n{qem}");
    }
    let refined = "10%+importance";
    let paper = line("color", refined, Some("paper"));
    let default = line("color", refined, Some("default"));
    assert_eq!(field::<f64>(&paper, "threshold_paper_units"), 0.3);
    let base: u32 = field(&paper, "base_triangles");
    let (p, d): (u32, u32) = (field(&paper, "triangles"), field(&default, "triangles"));
    assert!(base == 2000 || base == 2001, "{paper}");
    assert!(p > base && d > 2 * p, "{paper}\n{default}");
    // QEM is refined to the colour cut's count.
    let qem: u32 = field(&line("qem", refined, Some("default")), "triangles");
    assert!(qem <= d && qem + 10 > d, "{qem} vs {d}");
    for file in [
        "figure.png",
        "colormap.png",
        "heightmap.png",
        "original_top.png",
        "25_perspective.png",
        "10_top.png",
        "refined_paper_perspective.png",
        "refined_default_top.png",
    ] {
        assert!(dir.join("out/terrain").join(file).exists(), "{file}");
    }
}

/// Runs the demo with standard output going to `stdout`.
fn demo_into(args: &[&str], cwd: &Path, stdout: std::process::Stdio) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vdlod-demo"))
        .args(args)
        .current_dir(cwd)
        .stdout(stdout)
        .stderr(std::process::Stdio::piped())
        .output()
        .expect("run vdlod-demo")
}

#[test]
fn a_closed_standard_output_is_a_normal_end_and_a_full_one_an_error_line() {
    let dir = scratch_dir("cli_stdout");
    let render = ["render", "--frames", "2", "--width", "32", "--height", "24"];
    for args in [&["sphere", "--levels", "2", "-o", "s.vdw"][..], &render[..]] {
        // The reader is gone before the first line: `vdlod-demo ... | head -0`.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = demo_into(args, &dir, writer.into());
        assert!(out.status.success(), "{args:?}: {:?}", out.status);
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        // `> /dev/full`: one line saying so, and a failure.
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = demo_into(args, &dir, full.into());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("standard output"), "{stderr}");
    }
}

#[test]
fn a_shorter_run_leaves_no_stale_frames_and_names_its_limits() {
    let dir = scratch_dir("cli_stale");
    let cow = fixture("cow.obj");
    let cow = cow.to_str().unwrap();
    let small = ["--width", "32", "--height", "24", "-o", "o"];
    let run = |extra: &[&str]| {
        let mut args = vec!["orbit", cow];
        args.extend_from_slice(extra);
        args.extend_from_slice(&small);
        let out = succeed(&args, &dir);
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    run(&["--frames", "5", "--dump-mesh"]);
    std::fs::write(dir.join("o/frame_notes.txt"), "mine").unwrap();
    let stdout = run(&["--frames", "2", "--max-ops", "5"]);
    let mut left: Vec<String> = std::fs::read_dir(dir.join("o"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("frame_") || n.starts_with("mesh_"))
        .collect();
    left.sort();
    // Meshes are not written this time, so they are not this run's to clean.
    assert_eq!(
        left,
        [
            "frame_0000.png",
            "frame_0001.png",
            "frame_notes.txt",
            "mesh_0000.obj",
            "mesh_0001.obj",
            "mesh_0002.obj",
            "mesh_0003.obj",
            "mesh_0004.obj"
        ]
    );
    assert!(stdout.contains("limits: ops"), "{stdout}");
    assert!(stdout.contains("limits hit (frames): ops in 2"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("o/stats.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let ops = header.iter().position(|&c| c == "ops_limited").unwrap();
    let first: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(first[ops], "1");
    let one = run(&["--frames", "1"]);
    assert!(one.contains("one frame only"), "{one}");
    assert!(!one.contains("-0.0"), "{one}");
}

#[test]
fn terrain_flies_the_procedural_island_and_a_path_file() {
    let dir = scratch_dir("cli_terrain");
    let small = ["--width", "48", "--height", "32", "--frames", "3"];
    let mut args = vec!["terrain", "--size", "33", "-o", "t"];
    args.extend_from_slice(&small);
    let out = succeed(&args, &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("procedural terrain (size 33, seed 1): 33 x 33 samples"),
        "{stdout}"
    );
    assert!(
        stdout.contains("1089 vertices, 2048 triangles at full detail; 3 frames"),
        "{stdout}"
    );
    for f in [
        "t/frame_0002.png",
        "t/stats.csv",
        "t/plot.png",
        "t/side_by_side.png",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    // The colours as a texture, both engines: the frames differ from the colours per vertex.
    for engine in ["forest", "wavelet"] {
        let out_dir = format!("x{engine}");
        let mut textured = vec!["terrain", "--size", "33", "--texture", "--engine", engine];
        textured.extend_from_slice(&["-o", &out_dir]);
        textured.extend_from_slice(&small);
        succeed(&textured, &dir);
        let textured = std::fs::read(dir.join(&out_dir).join("frame_0002.png")).unwrap();
        if engine == "forest" {
            let plain = std::fs::read(dir.join("t/frame_0002.png")).unwrap();
            assert_ne!(textured, plain);
        }
    }
    // A path file: two frames looking down from above, with a header and a comment.
    std::fs::write(
        dir.join("path.csv"),
        "eye_x,eye_y,eye_z,target_x,target_y,target_z,up_x,up_y,up_z,fov_y_degrees\n\
         16,40,16, 16,0,16, 0,0,-1, 50\n# second frame\n16,30,40, 16,0,16, 0,1,0, 50\n",
    )
    .unwrap();
    let out = succeed(
        &[
            "terrain", "--size", "33", "--path", "path.csv", "-o", "p", "--width", "32",
            "--height", "24",
        ],
        &dir,
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 frames"));
    assert!(dir.join("p/frame_0001.png").exists() && !dir.join("p/frame_0002.png").exists());
    // The wavelet paper's session, over the island.
    succeed(
        &[
            "terrain",
            "--size",
            "17",
            "--session",
            "--frames",
            "6",
            "-o",
            "s",
            "--width",
            "32",
            "--height",
            "24",
        ],
        &dir,
    );
    assert!(dir.join("s/frame_0005.png").exists());
    // A bad row is named by its line.
    std::fs::write(dir.join("bad.csv"), "16,40,16,16,0,16,0,0,-1,50\n1,2,3\n").unwrap();
    assert_one_line_failure(
        "bad.csv",
        "16,40,16,16,0,16,0,0,-1,50\n1,2,3\n",
        &["terrain", "--size", "9", "--path", "FILE"],
        "bad.csv: line 2: 3 values where 10 are needed",
    );
    // A heightmap that is not a PNG, and a bad scale.
    assert_one_line_failure(
        "h.png",
        "not a png",
        &["terrain", "--heightmap", "FILE"],
        "h.png: heightmap: not a PNG we read",
    );
    for scale in ["-1", "0", "11", "nan"] {
        let out = demo(&["terrain", "--vertical-scale", scale], &dir);
        assert!(!out.status.success(), "{scale}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("at most 10"), "{scale}: {stderr}");
    }
}

#[test]
fn the_wavelet_engine_flies_terrains_paths_and_vdw_files() {
    let dir = scratch_dir("cli_wavelet_flights");
    let small = ["--width", "48", "--height", "32", "--frames", "3"];
    let mut args = vec!["terrain", "--engine", "wavelet", "--size", "33", "-o", "t"];
    args.extend_from_slice(&small);
    let out = succeed(&args, &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("33 x 33 samples, semi-regular mesh built"),
        "{stdout}"
    );
    assert!(stdout.contains("2048 triangles at full detail"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("t/stats.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let new = header.iter().position(|&c| c == "new_triangles").unwrap();
    // Adapted: more than the two base triangles, fewer than full detail; every triangle of the
    // first frame is new, and later frames keep some of the last one's.
    for (i, row) in csv.lines().skip(1).enumerate() {
        let (triangles, fresh): (u32, u32) = (
            row.split(',').nth(1).unwrap().parse().unwrap(),
            row.split(',').nth(new).unwrap().parse().unwrap(),
        );
        assert!(triangles > 2 && triangles <= 2048, "{row}");
        assert!(
            if i == 0 {
                fresh == triangles
            } else {
                fresh < triangles
            },
            "{row}"
        );
    }
    // A grid that is not 2^k + 1 square: one line saying what the engine needs.
    let out = demo(&["terrain", "--engine", "wavelet", "--size", "32"], &dir);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("2^k + 1 samples a side") && stderr.contains("32 x 32"));
    // A .vdw file through `orbit`, on the wavelet paper's session, with meshes dumped.
    succeed(&["sphere", "--levels", "3", "-o", "s.vdw"], &dir);
    let mut args = vec!["orbit", "s.vdw", "--session", "--dump-mesh", "-o", "o"];
    args.extend_from_slice(&small);
    let out = succeed(&args, &dir);
    assert!(String::from_utf8_lossy(&out.stdout).contains("512 triangles at full detail"));
    assert!(dir.join("o/frame_0002.png").exists() && dir.join("o/mesh_0002.obj").exists());
    // False colours by forest depth need the forest.
    let out = demo(&["orbit", "s.vdw", "--depth-colors", "--frames", "1"], &dir);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("vertex forest"));
}
