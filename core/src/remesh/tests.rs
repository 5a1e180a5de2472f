//! Remesher tests on generated meshes (the fixtures are remeshed in the workspace's `tests/`).

use alloc::vec::Vec;

use super::*;
use crate::build::around::Around;
use crate::build::tests::{grid, input, sphere, topology};

/// Checks what every remesh must be: the counts of its levels, its vertices on the input, the
/// input's topology and no fold in the map.
fn check(mesh: &InputMesh<'_>, out: &Remesh, levels: u32) -> Quality {
    let finest = out.mesh.finest_triangles();
    assert_eq!(finest.len(), out.base_faces as usize * (1 << (2 * levels)));
    assert_eq!(out.on_input.len(), out.mesh.positions.len());
    assert_eq!(topology(&finest), topology(mesh.triangles));
    assert!(out.worst_weight > -1e-9, "a fold: {}", out.worst_weight);
    let q = out.quality(mesh);
    // Every vertex on the input surface (up to f32 rounding).
    let surface = crate::build::closest::Surface::new(mesh.positions, mesh.triangles);
    let diagonal = quality::diagonal(mesh.positions);
    for p in &out.mesh.positions {
        let d = surface.distance(crate::build::vec3::from_f32(*p));
        assert!(d < 1e-6 * diagonal, "{p:?} is {d} off the input");
    }
    q
}

#[test]
fn a_sphere_remeshes_onto_itself() {
    let (p, t) = sphere(4); // 2,048 faces
    let mesh = input(&p, &t);
    let options = RemeshOptions {
        base_faces: 40,
        levels: 3,
    };
    let out = remesh(&mesh, &options, &mut |_| {}).unwrap();
    assert!(
        out.base_faces <= 40 && out.base_faces >= 36,
        "{}",
        out.base_faces
    );
    let q = check(&mesh, &out, 3);
    assert!(q.hausdorff < 0.01 && q.rms < 0.001, "{q:?}");
    assert_eq!(q.flipped, 0);
    // Most triangles are far from slivers.
    let good: u32 = q.shapes[5..].iter().sum();
    assert!(
        good as usize * 10 >= 8 * out.mesh.finest_triangles().len(),
        "{q:?}"
    );
}

#[test]
fn an_open_grid_keeps_its_border() {
    let (p, t) = grid(24);
    let mesh = input(&p, &t);
    for levels in [1, 2, 4] {
        let options = RemeshOptions {
            base_faces: 30,
            levels,
        };
        let out = remesh(&mesh, &options, &mut |_| {}).unwrap();
        let q = check(&mesh, &out, levels);
        assert_eq!(q.flipped, 0, "{levels}: {q:?}");
        assert_eq!(topology(&t), (1, 1));
        // The finest level covers the grid's whole square: its border is the grid's.
        let (lo, hi) = out.mesh.positions.iter().fold(
            ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1])],
                    [hi[0].max(p[0]), hi[1].max(p[1])],
                )
            },
        );
        assert_eq!((lo, hi), ([0.0; 2], [1.0; 2]));
        // No base ear where the border runs straight: a corner triangle with three vertices on
        // it would have no area (the grid's own corners turn, and may keep theirs).
        let finest = out.mesh.finest_triangles();
        let mut edges: Vec<(u32, u32)> = finest
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        let mut on_border = vec![false; out.mesh.positions.len()];
        for &(a, b) in &edges {
            if edges.binary_search(&(b, a)).is_err() {
                on_border[a as usize] = true;
                on_border[b as usize] = true;
            }
        }
        for t in finest
            .iter()
            .filter(|t| t.iter().all(|&v| on_border[v as usize]))
        {
            let corners = t.map(|v| crate::build::vec3::from_f32(out.mesh.positions[v as usize]));
            let shape = crate::build::collapse::shape(corners);
            assert!(shape > 0.1, "{levels}: {t:?} {shape}");
        }
        if levels == 4 {
            assert!(q.hausdorff < 0.01 && q.rms < 0.001, "{q:?}");
        }
    }
}

#[test]
fn colours_follow_the_map() {
    let (p, t) = sphere(3);
    // Red along x, green along y: a linear function, so interpolation keeps it exactly.
    let colors: Vec<[u8; 3]> = p
        .iter()
        .map(|q| {
            [
                ((q[0] + 1.0) * 100.0) as u8,
                ((q[1] + 1.0) * 100.0) as u8,
                7,
            ]
        })
        .collect();
    let mesh = InputMesh {
        positions: &p,
        colors: Some(&colors),
        triangles: &t,
    };
    let options = RemeshOptions {
        base_faces: 24,
        levels: 2,
    };
    let out = remesh(&mesh, &options, &mut |_| {}).unwrap();
    let got = out.mesh.colors.as_ref().unwrap();
    for (&(f, w), c) in out.on_input.iter().zip(got) {
        let corners = t[f as usize].map(|v| colors[v as usize]);
        for k in 0..3 {
            let want: f64 = (0..3).map(|i| w[i] * f64::from(corners[i][k])).sum();
            assert!((f64::from(c[k]) - want).abs() <= 0.5 + 1e-9);
        }
        assert_eq!(c[2], 7);
    }
}

#[test]
fn bad_requests_are_typed_errors() {
    let (p, t) = sphere(2); // 128 faces
    let mesh = input(&p, &t);
    let ask =
        |base_faces, levels| remesh(&mesh, &RemeshOptions { base_faces, levels }, &mut |_| {});
    assert_eq!(
        ask(128, 2).unwrap_err(),
        RemeshError::BaseSize {
            base_faces: 128,
            input_faces: 128
        }
    );
    assert!(matches!(ask(2, 2), Err(RemeshError::BaseSize { .. })));
    assert_eq!(ask(20, 0).unwrap_err(), RemeshError::Levels(0));
    assert_eq!(ask(20, 13).unwrap_err(), RemeshError::Levels(13));
    // Measured against the wrong mesh: no panic, infinite distances.
    let out = ask(40, 1).unwrap();
    let tiny = input(&p[..4], &t[..1]);
    assert_eq!(out.quality(&tiny).hausdorff, f64::INFINITY);
    // A non-manifold edge: three triangles on 0-1.
    let p3 = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let t3 = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
    let err = remesh(&input(&p3, &t3), &RemeshOptions::default(), &mut |_| {}).unwrap_err();
    assert!(matches!(err, RemeshError::Input(_)), "{err}");
    // Three separate tetrahedra cannot shrink below twelve faces.
    let tet_p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let tet = [[0u32, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    let mut pp = Vec::new();
    let mut tt = Vec::new();
    for k in 0..3u32 {
        pp.extend(tet_p.iter().map(|q| [q[0] + 5.0 * k as f32, q[1], q[2]]));
        tt.extend(tet.iter().map(|f| f.map(|v| v + 4 * k)));
    }
    let options = RemeshOptions {
        base_faces: 4,
        levels: 1,
    };
    let err = remesh(&input(&pp, &tt), &options, &mut |_| {});
    assert_eq!(
        err.unwrap_err(),
        RemeshError::NotReached {
            base_faces: 4,
            reached: 12
        }
    );
}

#[test]
fn a_folded_patch_is_untangled() {
    // A remeshed bumpy grid with one interior vertex thrown across a neighbour: the triangles
    // round it face the wrong way, and the patch descent turns them back, every vertex still on
    // the input.
    let (p, t) = grid(24);
    let mesh = input(&p, &t);
    let options = RemeshOptions {
        base_faces: 30,
        levels: 3,
    };
    let out = remesh(&mesh, &options, &mut |_| {}).unwrap();
    let triangles = out.mesh.finest_triangles();
    let mut positions = out.mesh.positions.clone();
    let mut on_input = out.on_input.clone();
    let n = positions.len();
    let around = Around::triangles(p.len(), &t);
    let surface = crate::build::closest::Surface::new(&p, &t);
    let around_remesh = Around::triangles(n, &triangles);
    let mut fixed = vec![false; n];
    for v in 0..n as u32 {
        let star = around_remesh.of(v);
        let ring: usize = star.len();
        // On a closed fan every neighbour is shared by two triangles; count edges seen once.
        let mut ends: Vec<u32> = star
            .iter()
            .flat_map(|&s| triangles[s as usize].into_iter().filter(move |&x| x != v))
            .collect();
        ends.sort_unstable();
        let paired = ends.chunks(2).all(|c| c.len() == 2 && c[0] == c[1]);
        fixed[v as usize] = ring == 0 || !paired;
    }
    let relax = relax::Relax {
        input: &mesh,
        around: &around,
        triangles: &triangles,
        fixed,
        snapped: vec![false; n],
        surface: &surface,
        normals: relax::Relax::normals(&mesh),
        around_remesh,
        reach: 0.02,
    };
    let wrong = |positions: &[[f32; 3]], on_input: &[(u32, [f64; 3])]| {
        (0..triangles.len() as u32)
            .filter(|&t| relax.wrong(t, positions, on_input))
            .count()
    };
    assert_eq!(wrong(&positions, &on_input), 0);
    // The interior vertex nearest the middle, thrown across its first neighbour (on the input).
    let v = (0..n)
        .filter(|&v| !relax.fixed[v])
        .min_by(|&a, &b| {
            let d = |x: usize| (positions[x][0] - 0.5).abs() + (positions[x][1] - 0.5).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let star = relax.around_remesh.of(v as u32);
    let x = triangles[star[0] as usize]
        .into_iter()
        .find(|&x| x as usize != v)
        .unwrap() as usize;
    let across = [0, 1, 2].map(|k| 2.0 * f64::from(positions[x][k]) - f64::from(positions[v][k]));
    let (face, w) = relax.project(across, on_input[x].0);
    positions[v] = crate::build::closest::point(relax.corners(face), w).map(|c| c as f32);
    on_input[v] = (face, w);
    let folded = wrong(&positions, &on_input);
    assert!(folded >= 2, "{folded}");
    assert_eq!(relax.untangle(&mut positions, &mut on_input), 0);
    assert_eq!(wrong(&positions, &on_input), 0);
    for (q, &(f, w)) in positions.iter().zip(&on_input) {
        let at = crate::build::closest::point(relax.corners(f), w);
        let d = crate::build::vec3::sub(crate::build::vec3::from_f32(*q), at);
        assert!(
            crate::build::vec3::dot(d, d) < 1e-10,
            "{q:?} is off its input point"
        );
    }
}
