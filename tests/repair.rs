//! Real-world defects, made on purpose from the fixtures: each is read, repaired, built and flown
//! with the cut's invariant checks after every frame.

mod common;

use common::fly::{fly, hierarchy_bytes};
use common::topology;
use vdlod_core::build::{validate, InputMesh};
use vdlod_demo::mesh::{load_bytes, load_obj_bytes, IndexedMesh, LoadOptions, Up};
use vdlod_demo::repair::Repairs;

type Fly = (usize, usize, usize);

fn cow() -> IndexedMesh {
    load_obj_bytes(vdlod_demo::mesh::COW_NAME, vdlod_demo::mesh::COW_OBJ).unwrap()
}

/// Each triangle as its corners' coordinate bits, starting from the smallest; sorted.
fn corners(mesh: &IndexedMesh) -> Vec<[[u32; 3]; 3]> {
    let mut out: Vec<[[u32; 3]; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let c = t.map(|i| mesh.positions[i as usize].map(f32::to_bits));
            let first = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
            std::array::from_fn(|k| c[(first + k) % 3])
        })
        .collect();
    out.sort_unstable();
    out
}

/// OBJ text of positions and triangles.
fn obj(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = String::new();
    for p in positions {
        out += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in triangles {
        out += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out.into_bytes()
}

/// Loads `bytes` with repair, checks the result is what the builder accepts, builds it and flies
/// a random path over it; returns what was repaired.
fn repair_build_fly(name: &str, bytes: &[u8]) -> (IndexedMesh, Repairs) {
    let loaded = load_bytes(name, bytes, &LoadOptions::default()).unwrap();
    let mesh = loaded.mesh;
    validate(&InputMesh {
        positions: &mesh.positions,
        colors: mesh.colors.as_deref(),
        triangles: &mesh.triangles,
    })
    .unwrap();
    let hierarchy = hierarchy_bytes(&mesh);
    let prints = fly::<{ 1 << 15 }, { 1 << 16 }, { 1 << 12 }, u32>(&hierarchy, &mesh, 120, 3);
    assert_eq!(prints.len(), 120);
    (mesh, loaded.repairs.unwrap())
}

#[test]
fn the_fixtures_need_no_repair() {
    for name in ["cow", "bunny", "elk", "fandisk", "head"] {
        let path = format!("{}/fixtures/{name}.obj", env!("CARGO_MANIFEST_DIR"));
        let bytes = std::fs::read(&path).unwrap();
        let plain = load_obj_bytes(&path, &bytes).unwrap();
        let loaded = load_bytes(&path, &bytes, &LoadOptions::default()).unwrap();
        assert_eq!(loaded.repairs, Some(Repairs::default()), "{name}");
        assert!(loaded.mesh == plain, "{name}: the repaired mesh differs");
    }
}

#[test]
fn a_bow_tie_vertex_is_split() {
    // Two cows touching at one vertex: the second cow's copy of it is replaced by the first's.
    let c = cow();
    let n = c.positions.len() as u32;
    let lowest = (0..n)
        .min_by(|&a, &b| c.positions[a as usize][1].total_cmp(&c.positions[b as usize][1]))
        .unwrap();
    let highest = (0..n)
        .max_by(|&a, &b| c.positions[a as usize][1].total_cmp(&c.positions[b as usize][1]))
        .unwrap();
    // Stack the second cow so its lowest vertex lands on the first's highest.
    let shift: [f32; 3] =
        std::array::from_fn(|k| c.positions[highest as usize][k] - c.positions[lowest as usize][k]);
    let mut positions = c.positions.clone();
    positions.extend(
        c.positions
            .iter()
            .map(|p| std::array::from_fn(|k| p[k] + shift[k])),
    );
    let mut triangles = c.triangles.clone();
    triangles.extend(
        c.triangles
            .iter()
            .map(|t| t.map(|i| if i == lowest { highest } else { i + n })),
    );
    let (mesh, repairs) = repair_build_fly("bowtie.obj", &obj(&positions, &triangles));
    assert_eq!(repairs.split, 1, "{repairs}");
    assert_eq!(mesh.triangles.len(), 2 * c.triangles.len());
    // Two closed surfaces of genus 0: Euler characteristic 4, no borders.
    assert_eq!(topology(&mesh.triangles), (4, 0));
}

#[test]
fn flipped_and_repeated_triangles_are_undone() {
    let c = cow();
    let mut triangles = c.triangles.clone();
    for t in [3, 500, 4000] {
        triangles[t].swap(0, 1);
    }
    triangles.push(c.triangles[10]);
    let reversed = [c.triangles[20][0], c.triangles[20][2], c.triangles[20][1]];
    triangles.push(reversed);
    triangles.push([c.triangles[30][0], c.triangles[30][0], c.triangles[30][1]]);
    let (mesh, repairs) = repair_build_fly("messy.obj", &obj(&c.positions, &triangles));
    assert_eq!(repairs.flipped, 3, "{repairs}");
    assert_eq!(repairs.duplicate, 2, "{repairs}");
    assert_eq!(repairs.degenerate, 1, "{repairs}");
    // A flipped triangle comes back as a rotation of the original.
    assert!(
        corners(&mesh) == corners(&c),
        "the triangles differ from the cow's"
    );
}

#[test]
fn a_whole_cow_turned_inside_out_is_turned_back() {
    let c = cow();
    let inside_out: Vec<[u32; 3]> = c.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let (mesh, repairs) = repair_build_fly("inside_out.obj", &obj(&c.positions, &inside_out));
    assert_eq!(repairs.flipped, c.triangles.len(), "{repairs}");

    assert!(
        corners(&mesh) == corners(&c),
        "the triangles differ from the cow's"
    );
}

#[test]
fn an_stl_soup_welds_back_into_the_cow() {
    let c = cow();
    let mut stl = vec![b' '; 80];
    stl.extend((c.triangles.len() as u32).to_le_bytes());
    for t in &c.triangles {
        stl.extend([0u8; 12]);
        for &i in t {
            for x in c.positions[i as usize] {
                stl.extend(x.to_le_bytes());
            }
        }
        stl.extend([0u8; 2]);
    }
    let (mesh, repairs) = repair_build_fly("cow.stl", &stl);
    // The cow has two vertices at the same point (-0.410173, 0.204796, -1.55991e-8). STL cannot
    // tell them apart; the repair splits them again, as two fans.
    let expected = Repairs {
        split: 1,
        ..Repairs::default()
    };
    assert_eq!(repairs, expected, "{repairs}");
    assert_eq!(mesh.positions.len(), c.positions.len());
    assert_eq!(topology(&mesh.triangles), topology(&c.triangles));
}

#[test]
fn a_sliver_and_a_zero_area_face_are_built_and_flown() {
    let mut c = cow();
    let [a, b, z] = c.triangles[100];
    let (pa, pb) = (c.positions[a as usize], c.positions[b as usize]);
    // Corner z on the segment ab: triangle 100 has zero area, its neighbours become slivers.
    c.positions[z as usize] = std::array::from_fn(|k| pa[k] + 0.25 * (pb[k] - pa[k]));
    let [d, e, s] = c.triangles[2000];
    let (pd, pe) = (c.positions[d as usize], c.positions[e as usize]);
    c.positions[s as usize] = std::array::from_fn(|k| 0.5 * (pd[k] + pe[k]) + 1e-4);
    let (mesh, repairs) = repair_build_fly("sliver.obj", &obj(&c.positions, &c.triangles));
    assert!(repairs.is_empty(), "{repairs}");
    assert_eq!(mesh.triangles.len(), c.triangles.len());
}

#[test]
fn millimetres_and_kilometres_weld_alike() {
    let c = cow();
    let mut counts: Vec<Fly> = Vec::new();
    for scale in [1e3f32, 1e-3] {
        // The cow with its first 50 vertices duplicated a hair away and used by one triangle each.
        let mut positions: Vec<[f32; 3]> =
            c.positions.iter().map(|p| p.map(|x| x * scale)).collect();
        let mut triangles = c.triangles.clone();
        for v in 0..50u32 {
            let copy = positions.len() as u32;
            let p = positions[v as usize];
            positions.push([p[0] + 1e-8 * scale, p[1], p[2]]);
            let t = triangles.iter().position(|t| t.contains(&v)).unwrap();
            for i in triangles[t].iter_mut() {
                if *i == v {
                    *i = copy;
                }
            }
        }
        let (mesh, repairs) = repair_build_fly("scaled.obj", &obj(&positions, &triangles));
        assert_eq!(topology(&mesh.triangles), topology(&c.triangles), "{scale}");
        counts.push((repairs.welded, repairs.split, mesh.positions.len()));
    }
    assert_eq!(counts[0], (50, 0, c.positions.len()));
    assert_eq!(counts[0], counts[1]);
}

#[test]
fn z_up_turns_a_quarter_about_x() {
    let text = b"v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
    let options = LoadOptions {
        up: Up::Z,
        ..LoadOptions::default()
    };
    let mesh = load_bytes("z.obj", text, &options).unwrap().mesh;
    assert_eq!(
        mesh.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    // The triangle faced -Y; now it faces +Z... turned with the model, not mirrored.
    assert_eq!(mesh.normals[0], [0.0, 0.0, 1.0]);
}

#[test]
fn groups_materials_and_latin1_do_not_change_the_cow() {
    // As modellers write it: the faces split over groups and objects (tobj read each group as a
    // separate vertex set, so this cow used to be refused as non-manifold), an empty `usemtl`, a
    // Latin-1 comment, CRLF line ends and tabs.
    let text = String::from_utf8_lossy(vdlod_demo::mesh::COW_OBJ).into_owned();
    let mut messy: Vec<u8> = b"# vache \xe0 l'envers\r\nmtllib cow.mtl\r\ng body\r\n".to_vec();
    let mut faces = 0;
    for line in text.lines() {
        if line.starts_with("f ") {
            faces += 1;
            if faces % 1000 == 0 {
                messy.extend_from_slice(b"o part\r\nusemtl\r\ng legs\r\ns 1\r\n");
            }
        }
        messy.extend_from_slice(line.replacen(' ', "\t", 1).as_bytes());
        messy.extend_from_slice(b"\r\n");
    }
    let strict = LoadOptions {
        repair: false,
        ..LoadOptions::default()
    };
    let loaded = load_bytes("messy_cow.obj", &messy, &strict).unwrap();
    assert!(loaded.mesh == cow(), "the cow changed");
}
