//! Builder tests on generated meshes (the fixtures are tested from the workspace's `tests/`).

use crate::wavelet::build::{OCTAHEDRON_FACES, OCTAHEDRON_VERTICES};
use alloc::vec::Vec;

use super::*;

/// Euler characteristic `V - E + F` and the number of border loops of a triangle list.
pub fn topology(triangles: &[[u32; 3]]) -> (i64, usize) {
    let mut verts: Vec<u32> = triangles.iter().flatten().copied().collect();
    verts.sort_unstable();
    verts.dedup();
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    let mut undirected: Vec<(u32, u32)> =
        edges.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    undirected.sort_unstable();
    undirected.dedup();
    edges.sort_unstable();
    // Border edges: directed edges whose reverse is missing. Follow them into loops.
    let border: Vec<(u32, u32)> = edges
        .iter()
        .copied()
        .filter(|&(a, b)| edges.binary_search(&(b, a)).is_err())
        .collect();
    let mut used = alloc::vec![false; border.len()];
    let mut loops = 0;
    for start in 0..border.len() {
        if used[start] {
            continue;
        }
        loops += 1;
        let mut k = start;
        while !used[k] {
            used[k] = true;
            let next = border[k].1;
            match border.iter().position(|&(a, _)| a == next) {
                Some(j) => k = j,
                None => break,
            }
        }
    }
    (
        verts.len() as i64 - undirected.len() as i64 + triangles.len() as i64,
        loops,
    )
}

pub(crate) fn sorted(mut t: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    for x in t.iter_mut() {
        *x = rotate_to_min(*x);
    }
    t.sort_unstable();
    t
}

/// An `n` by `n` grid of quads, split in two, gently curved so collapses have costs that differ.
pub(crate) fn grid(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push([x, y, 0.3 * libm::sinf(3.0 * x) * libm::cosf(2.0 * y)]);
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            t.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    (p, t)
}

/// A unit sphere: an octahedron subdivided `levels` times (4-to-1), vertices pushed outwards.
pub(crate) fn sphere(levels: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut p: Vec<[f32; 3]> = OCTAHEDRON_VERTICES.to_vec();
    let mut t: Vec<[u32; 3]> = OCTAHEDRON_FACES.to_vec();
    for _ in 0..levels {
        let mut mids: Vec<((u32, u32), u32)> = Vec::new();
        let mut mid = |a: u32, b: u32, p: &mut Vec<[f32; 3]>| {
            let key = (a.min(b), a.max(b));
            if let Some(&(_, m)) = mids.iter().find(|(k, _)| *k == key) {
                return m;
            }
            let (pa, pb) = (p[a as usize], p[b as usize]);
            let m = [0, 1, 2].map(|k| (pa[k] + pb[k]) * 0.5);
            let l = crate::root::sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
            p.push(m.map(|c| c / l));
            let id = p.len() as u32 - 1;
            mids.push((key, id));
            id
        };
        let mut next = Vec::new();
        for &[a, b, c] in &t {
            let (ab, bc, ca) = (mid(a, b, &mut p), mid(b, c, &mut p), mid(c, a, &mut p));
            next.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        t = next;
    }
    (p, t)
}

/// Positions and triangles as a mesh without colours.
pub(crate) fn input<'a>(p: &'a [[f32; 3]], t: &'a [[u32; 3]]) -> InputMesh<'a> {
    InputMesh {
        positions: p,
        colors: None,
        triangles: t,
    }
}

pub(crate) fn build_it(p: &[[f32; 3]], t: &[[u32; 3]], opts: BuildOptions) -> Hierarchy {
    build(&input(p, t), &opts, &mut |_| {}).expect("valid mesh")
}

#[test]
fn open_grid_round_trips_and_keeps_its_border() {
    let (p, t) = grid(12);
    for cost in [Cost::Quadric, Cost::ShortestEdge, Cost::Color] {
        for balanced in [false, true] {
            let h = build_it(
                &p,
                &t,
                BuildOptions {
                    cost,
                    balanced,
                    ..BuildOptions::default()
                },
            );
            assert_eq!(
                sorted(h.refine_all()),
                sorted(t.clone()),
                "{cost:?} {balanced}"
            );
            assert_eq!(topology(&h.base_triangles), topology(&t));
            assert_eq!(topology(&t), (1, 1)); // a disk
                                              // The grid (169 vertices) collapses to a handful.
            assert!(h.base_triangles.len() <= 8, "{}", h.base_triangles.len());
        }
    }
}

/// A flat square simplified to four vertices still covers the square: on a plane every
/// collapse costs nothing but for the boundary quadrics, which alone keep a border vertex from
/// moving inwards and a corner from moving at all. (Past four, a corner has to go.)
#[test]
fn flat_square_keeps_its_outline() {
    let (mut p, t) = grid(10);
    for v in p.iter_mut() {
        v[2] = 0.0;
    }
    for placement in [Placement::Cost, Placement::Endpoint] {
        for balanced in [false, true] {
            let opts = BuildOptions {
                placement,
                balanced,
                base_vertices: 4,
                ..BuildOptions::default()
            };
            let h = build_it(&p, &t, opts);
            let area: f64 = h
                .base_triangles
                .iter()
                .map(|tri| {
                    let [a, b, c] = tri.map(|v| h.nodes[v as usize].position.map(f64::from));
                    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
                })
                .sum();
            assert!(
                (area - 1.0).abs() < 1e-6,
                "{placement:?} {balanced}: area {area}"
            );
        }
    }
}

/// Under the remesher's border rules ([`collapse::Engine::keep_borders`]) an edge from the
/// border inwards merges onto its border end, and a border edge at a corner onto the corner,
/// exactly: the border is where the input's is, whatever the quadrics would prefer.
#[test]
fn border_rules_merge_onto_the_border_end_and_the_corner() {
    let (p, t) = grid(10);
    let mesh = input(&p, &t);
    let opts = BuildOptions::default();
    let mut e = collapse::Engine::new(&mesh, &opts);
    e.keep_borders();
    // The grid's corners are the border's only turns, and stay where they are.
    let corner = |q: vec3::Vec3d| (q[0] == 0.0 || q[0] == 1.0) && (q[1] == 0.0 || q[1] == 1.0);
    let (mut inwards, mut at_corners) = (0, 0);
    loop {
        let border: Vec<bool> = (0..e.pos.len() as u32)
            .map(|v| e.alive[v as usize] && e.on_border(v))
            .collect();
        if !e.step() {
            break;
        }
        let c = e.collapses.last().expect("a step collapses");
        let [a, b] = c.children;
        let (pa, pb, v) = (e.pos.get(a), e.pos.get(b), e.pos.get(c.parent));
        let (ba, bb) = (border[a as usize], border[b as usize]);
        if ba != bb {
            assert_eq!(v, if ba { pa } else { pb }, "{a}-{b}");
            inwards += 1;
        } else if ba && corner(pa) != corner(pb) {
            assert_eq!(v, if corner(pa) { pa } else { pb }, "{a}-{b}");
            at_corners += 1;
        }
    }
    assert!(inwards > 0 && at_corners > 0, "{inwards} {at_corners}");
}

/// A border vertex may be left with two neighbours (one triangle, an ear) where an inner
/// vertex may not: merging an inner vertex onto the border vertex it meets leaves a single
/// triangle, and is legal, though the merged vertex keeps only two neighbours.
#[test]
fn a_merged_border_vertex_may_keep_two_neighbours() {
    // A triangle a = 0, w0 = 1, w1 = 2 split around the inner vertex b = 3.
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.3, 0.3, 0.0],
    ];
    let t = [[0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let opts = BuildOptions::default();
    let mesh = input(&p, &t);
    let e = collapse::Engine::new(&mesh, &opts);
    assert!(e.on_border(0) && !e.on_border(3));
    assert!(e.legal(0, 3, [0.0, 0.0, 0.0]));
    assert!(e.legal(3, 0, [0.0, 0.0, 0.0]));
}

/// Under the remesher's border rules only a corner may be left with a single triangle (an
/// ear), neither the merged vertex nor a wing; without them both collapses below are legal.
#[test]
fn ears_are_left_only_at_corners() {
    // b = 0, a = 1, w = 2, x = 3 (and y = 4): the border edge b-a has wing w, and b has no
    // other triangle, so merging a and b leaves a single triangle at the merged vertex.
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [2.0, 1.0, 0.0],
        [1.5, 2.0, 0.0],
    ];
    let t = [[0, 1, 2], [1, 3, 2], [3, 4, 2]];
    let opts = BuildOptions::default();
    let mesh = input(&p, &t);
    let mut e = collapse::Engine::new(&mesh, &opts);
    let (mid, at_a) = ([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert!(e.legal(1, 0, mid));
    e.keep_borders();
    // a turns the border by 45 degrees (a corner), the midpoint of a-b is no corner.
    assert!(!e.legal(1, 0, mid));
    assert!(e.legal(1, 0, at_a));
    // Without y, and x on the line from b through w: w's border runs straight there, and
    // merging a and b would leave w with a single triangle.
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [1.0, 2.0, 0.0],
    ];
    let t = [[0, 1, 2], [1, 3, 2]];
    let mesh = input(&p, &t);
    let mut e = collapse::Engine::new(&mesh, &opts);
    assert!(e.legal(1, 0, at_a));
    e.keep_borders();
    assert!(!e.legal(1, 0, at_a));
}

/// A collapse that would turn a triangle over is illegal even when none loses its area: on a
/// flat grid, merging two inner vertices at their midpoint is legal, and at a point beyond
/// their neighbours, where the fans fold over, it is not.
#[test]
fn a_collapse_that_turns_a_triangle_over_is_illegal() {
    let (mut p, t) = grid(3);
    for v in p.iter_mut() {
        v[2] = 0.0;
    }
    let mesh = input(&p, &t);
    let opts = BuildOptions::default();
    let e = collapse::Engine::new(&mesh, &opts);
    // Vertices 5 and 6 are the inner (1/3, 1/3) and (2/3, 1/3).
    assert!(e.legal(5, 6, [0.5, 1.0 / 3.0, 0.0]));
    assert!(!e.legal(5, 6, [0.5, 1.5, 0.0]));
    assert!(!e.legal(5, 6, [0.5, -0.8, 0.0]));
}

/// The importance paper's colour cost, `Gerr^2 + length^2 + sqrt(length * dcolor)`, with the
/// merged vertex at the edge's midpoint. On the input every edge's midpoint lies on the surface
/// (`Gerr` = 0), so the length and the colour difference (channels in 0..=1) make it.
#[test]
fn colour_cost_is_the_papers_formula() {
    let p = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 1.0, 0.5],
    ];
    let t = [[0, 1, 3], [0, 3, 2]];
    let colors = [[255, 0, 0], [0, 0, 255], [255, 0, 0], [0, 255, 0]];
    let mesh = InputMesh {
        positions: &p,
        colors: Some(&colors),
        triangles: &t,
    };
    let opts = BuildOptions {
        cost: Cost::Color,
        ..BuildOptions::default()
    };
    let e = collapse::Engine::new(&mesh, &opts);
    // Length 2, colours red and blue: dcolor = sqrt(2).
    let (v, cost) = e.evaluate(0, 1);
    assert_eq!(v, [1.0, 0.0, 0.0]);
    let want = 4.0 + crate::root::sqrt(2.0 * crate::root::sqrt(2.0));
    assert!((cost - want).abs() < 1e-9, "{cost} {want}");
    // Length sqrt(5.25) along the diagonal, colours red and green.
    let (v, cost) = e.evaluate(0, 3);
    assert_eq!(v, [1.0, 0.5, 0.25]);
    let want = 5.25 + crate::root::sqrt(crate::root::sqrt(5.25) * crate::root::sqrt(2.0));
    assert!((cost - want).abs() < 1e-9, "{cost} {want}");
    // Across the other diagonal (no edge), the midpoint lies off the surface: 0.5 / sqrt(5)
    // below the plane -y + 2z = 0 of triangle 0-1-3, over that triangle, so Gerr^2 = 1/20.
    let (v, cost) = e.evaluate(1, 2);
    assert_eq!(v, [1.0, 0.5, 0.0]);
    let want = 0.05 + 5.0 + crate::root::sqrt(crate::root::sqrt(5.0) * crate::root::sqrt(2.0));
    assert!((cost - want).abs() < 1e-9, "{cost} {want}");
}

#[test]
fn sphere_round_trips_keeps_genus_and_stays_shallow_when_balanced() {
    let (p, t) = sphere(4); // 1026 vertices, 2048 triangles
    let plain = build_it(&p, &t, BuildOptions::default());
    assert_eq!(sorted(plain.refine_all()), sorted(t.clone()));
    assert_eq!(topology(&plain.base_triangles), (2, 0));
    assert_eq!(plain.base_triangles.len(), 4); // down to a tetrahedron

    let balanced = build_it(
        &p,
        &t,
        BuildOptions {
            balanced: true,
            ..BuildOptions::default()
        },
    );
    assert_eq!(sorted(balanced.refine_all()), sorted(t.clone()));
    let (max, _) = balanced.depth_stats();
    let bound = 3 * libm::ceil(libm::log2(p.len() as f64)) as u32;
    assert!(max <= bound, "depth {max} > 3 log2 n = {bound}");
}

#[test]
fn endpoint_placement_keeps_every_vertex_an_input_vertex() {
    // A coloured grid: every parent repeats one child's position, normal and colour bit for
    // bit (the child that stays), so the whole forest holds only input vertices; the forest
    // still replays to the input and its bounds hold.
    let (p, t) = grid(10);
    let colors: Vec<[u8; 3]> = (0..p.len())
        .map(|i| [(i % 7 * 30) as u8, (i % 5 * 50) as u8, 128])
        .collect();
    let mesh = InputMesh {
        positions: &p,
        colors: Some(&colors),
        triangles: &t,
    };
    for cost in [Cost::Quadric, Cost::ShortestEdge, Cost::Color] {
        let opts = BuildOptions {
            cost,
            placement: Placement::Endpoint,
            ..BuildOptions::default()
        };
        let h = build(&mesh, &opts, &mut |_| {}).expect("valid mesh");
        assert_eq!(sorted(h.refine_all()), sorted(t.clone()), "{cost:?}");
        let vertex = |n: &Node| (n.position, n.normal, n.color);
        for node in &h.nodes[h.leaves as usize..] {
            let [a, b] = node.children.map(|c| vertex(&h.nodes[c as usize]));
            assert!(vertex(node) == a || vertex(node) == b, "{cost:?}");
            assert!(p.contains(&node.position), "{cost:?}");
        }
        bounds_hold(&h);
    }
    // Placed by the cost, a parent of the curved grid sits between its children.
    let h = build(&mesh, &BuildOptions::default(), &mut |_| {}).expect("valid mesh");
    let moved = h.nodes[h.leaves as usize..]
        .iter()
        .filter(|n| !p.contains(&n.position))
        .count();
    assert!(moved * 2 > h.nodes.len() - h.leaves as usize, "{moved}");
}

#[test]
fn base_size_is_respected() {
    let (p, t) = sphere(3);
    let h = build_it(
        &p,
        &t,
        BuildOptions {
            base_vertices: 100,
            ..BuildOptions::default()
        },
    );
    assert_eq!(h.roots().count(), 100);
    assert_eq!(sorted(h.refine_all()), sorted(t));
}

#[test]
fn bounds_are_monotonic_and_hold_the_leaves() {
    let (p, t) = sphere(3);
    for bound in [ErrorBound::Offset, ErrorBound::Spheroid, ErrorBound::Hoppe] {
        bounds_hold(&build_it(
            &p,
            &t,
            BuildOptions {
                bound,
                ..BuildOptions::default()
            },
        ));
    }
}

/// The balanced forest, made in passes: every bound and placement, on a closed and an open
/// surface, replays to the input and back to the base, holds its bounds, and parses as a file.
#[test]
fn balanced_passes_make_whole_forests_under_every_option() {
    for (p, t) in [sphere(3), grid(10)] {
        for bound in [ErrorBound::Offset, ErrorBound::Spheroid, ErrorBound::Hoppe] {
            for placement in [Placement::Cost, Placement::Endpoint] {
                let opts = BuildOptions {
                    balanced: true,
                    bound,
                    placement,
                    ..BuildOptions::default()
                };
                let h = build_it(&p, &t, opts);
                let why = alloc::format!("{bound:?} {placement:?} on {} triangles", t.len());
                assert_eq!(sorted(h.refine_all()), sorted(t.clone()), "{why}");
                assert_eq!(
                    sorted(h.collapse_all(&t)),
                    sorted(h.base_triangles.clone()),
                    "{why}"
                );
                assert_eq!(topology(&h.base_triangles), topology(&t), "{why}");
                assert!(h.base_triangles.len() <= 8, "{why}");
                bounds_hold(&h);
                let bytes = h.to_bytes(false);
                assert!(crate::format::HierarchyView::parse(&bytes).is_ok(), "{why}");
            }
        }
    }
}

fn bounds_hold(h: &Hierarchy) {
    for (i, node) in h.nodes.iter().enumerate() {
        if node.parent == NONE {
            continue;
        }
        let parent = &h.nodes[node.parent as usize];
        assert!(parent.spheroid[0] >= node.spheroid[0] && parent.spheroid[1] >= node.spheroid[1]);
        assert!(parent.depth + 1 == node.depth);
        // The parent's sphere holds the child's.
        let d = vec3::len(vec3::sub(
            vec3::from_f32(node.position),
            vec3::from_f32(parent.position),
        ));
        assert!(
            d + node.radius as f64 <= parent.radius as f64 * (1.0 + 1e-6),
            "node {i}"
        );
    }
    if h.bound != ErrorBound::Offset {
        return;
    }
    // Every leaf lies within each ancestor's spheroid height of its tangent plane.
    for leaf in 0..h.leaves {
        let lp = vec3::from_f32(h.nodes[leaf as usize].position);
        let mut a = h.nodes[leaf as usize].parent;
        while a != NONE {
            let n = &h.nodes[a as usize];
            let d = vec3::sub(lp, vec3::from_f32(n.position));
            let u = vec3::dot(d, vec3::from_f32(n.normal));
            assert!(
                u.abs() <= n.spheroid[0] as f64 * (1.0 + 1e-4) + 1e-7,
                "leaf {leaf} outside the spheroid of {a}"
            );
            a = n.parent;
        }
    }
}

#[test]
fn residual_bounds_follow_the_coarse_surface() {
    // A residual runs from a leaf to the nearest point of the coarse triangles, so it lies
    // mostly along the normal: the spheroid is flat (`b` well under the offset bound's `b = a`).
    // The three bounds share one forest; the spheroid holds Hoppe's box.
    let (p, t) = sphere(3);
    let of = |bound| {
        build_it(
            &p,
            &t,
            BuildOptions {
                bound,
                ..BuildOptions::default()
            },
        )
    };
    let (offset, spheroid, hoppe) = (
        of(ErrorBound::Offset),
        of(ErrorBound::Spheroid),
        of(ErrorBound::Hoppe),
    );
    let parents = offset.leaves as usize..offset.nodes.len();
    let mut tighter = 0;
    for i in parents.clone() {
        let (o, s, h) = (&offset.nodes[i], &spheroid.nodes[i], &hoppe.nodes[i]);
        assert_eq!((o.children, s.children), (h.children, h.children));
        assert!(s.spheroid[0] >= h.spheroid[0] && s.spheroid[1] >= h.spheroid[1]);
        tighter += usize::from(s.spheroid[1] < 0.5 * o.spheroid[1]);
    }
    assert!(
        tighter * 2 > parents.len(),
        "{tighter} of {} parents",
        parents.len()
    );
    // Only Hoppe's file says its codes are `delta` and `mu`.
    for (h, flag) in [(&offset, false), (&spheroid, false), (&hoppe, true)] {
        let bytes = h.to_bytes(false);
        let view = crate::format::HierarchyView::parse(&bytes).expect("valid");
        assert_eq!(view.hoppe_bounds(), flag);
    }
}

#[test]
fn tetrahedron_does_not_collapse() {
    let p = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    let t = [[0, 2, 3], [0, 3, 1], [0, 1, 2], [1, 3, 2]];
    let h = build_it(&p, &t, BuildOptions::default());
    assert_eq!(h.nodes.len(), 4);
    assert_eq!(sorted(h.base_triangles.clone()), sorted(t.to_vec()));
}

#[test]
fn isolated_vertices_become_roots() {
    let (mut p, t) = grid(3);
    p.push([5.0, 5.0, 5.0]);
    let h = build_it(&p, &t, BuildOptions::default());
    let lonely = p.len() as u32 - 1;
    assert_eq!(h.nodes[lonely as usize].parent, NONE);
    assert!(h.roots().any(|r| r == lonely));
    assert_eq!(sorted(h.refine_all()), sorted(t));
}

#[test]
fn errors_are_reported() {
    let p = [[0.0; 3]; 3];
    let mesh = InputMesh {
        positions: &p,
        colors: None,
        triangles: &[[0, 1, 1]],
    };
    assert_eq!(
        build(&mesh, &BuildOptions::default(), &mut |_| {}),
        Err(BuildError::DegenerateTriangle { triangle: 0 })
    );
}

#[test]
fn bytes_round_trip_through_the_format() {
    use crate::format::{FormatError, HierarchyView};
    let (p, t) = grid(6);
    let h = build_it(&p, &t, BuildOptions::default());
    let bytes = h.to_bytes(false);
    let view = HierarchyView::parse(&bytes).expect("valid");
    assert_eq!(view.leaves(), h.leaves);
    assert_eq!(view.nodes() as usize, h.nodes.len());
    // Positions are quantized to 1/65535 of the bounding box.
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for n in &h.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(n.position[k]);
            hi[k] = hi[k].max(n.position[k]);
        }
    }
    let quantum = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f32, f32::max) / 65535.0;
    // The file numbers the nodes breadth first: `ids` maps the build's ids to the file's.
    let ids = h.file_ids();
    let id = |i: u32| if i == NONE { NONE } else { ids[i as usize] };
    let mut seen = ids.clone();
    seen.sort_unstable();
    assert!(seen.iter().enumerate().all(|(k, &i)| i == k as u32));
    for (i, n) in h.nodes.iter().enumerate() {
        let f = id(i as u32);
        let v = view.node(f);
        for k in 0..3 {
            assert!((v.position[k] - n.position[k]).abs() <= quantum, "node {i}");
        }
        assert_eq!(v.parent, id(n.parent));
        assert!(n.parent == NONE || n.parent > i as u32 && v.parent < f);
        assert_eq!(v.depth, n.depth);
        assert_eq!(view.is_parent(f), i as u32 >= h.leaves);
        if (i as u32) < h.leaves {
            continue; // leaves carry no bounds
        }
        // Bounds are rounded up, never down, by at most a code step (4.4%) and the quantum.
        let close =
            |read: f32, built: f32| read >= built && read <= built * 1.045 + 4.0 * quantum + 1e-4;
        assert!(
            close(v.radius, n.radius),
            "node {i}: {} {}",
            v.radius,
            n.radius
        );
        assert!(close(v.spheroid[0], n.spheroid[0]) && close(v.spheroid[1], n.spheroid[1]));
        assert!(v.cone_sin >= n.cone_sin.min(1.0));
        // Siblings are adjacent, in the build's order.
        let s = view.split(f);
        assert_eq!(s.children, n.children.map(id));
        assert_eq!(s.children[1], s.children[0] + 1);
        assert_eq!(s.second(), n.wings[1] != NONE);
        // The split's triangles and neighbours keep their meaning under the renumbering.
        for face in s.faces {
            assert_eq!(view.face_creator(face), Some(f));
        }
        for (k, &g) in n.neighbours.iter().enumerate() {
            let read = s.neighbours[k];
            assert_eq!(read == NONE, g == NONE);
            let creator = h.face_creator(g);
            assert_eq!(view.face_creator(read), creator.map(id), "node {i}");
        }
    }
    let base: Vec<[u32; 3]> = (0..view.base_triangles())
        .map(|k| view.base_triangle(k))
        .collect();
    let mapped: Vec<[u32; 3]> = h.base_triangles.iter().map(|t| t.map(id)).collect();
    assert_eq!(base, mapped);
    assert!(base.iter().flatten().all(|&r| r < view.roots()));

    // Out-of-range ids read as nothing, never panic (the offsets would overflow on small targets).
    for id in [u32::MAX, u32::MAX - 1] {
        assert_eq!(view.node(id).parent, NONE);
        assert_eq!(view.split(id).children, [NONE; 2]);
        assert_eq!(view.base_triangle(id), [NONE; 3]);
    }
    let leaf = view.leaf_nodes().next().unwrap();
    assert_eq!(view.split(leaf).children, [NONE; 2]); // a leaf has no split record

    // One flipped bit anywhere after the header breaks the checksum.
    let mut bad = bytes.clone();
    bad[bytes.len() / 2] ^= 0x10;
    assert!(matches!(
        HierarchyView::parse(&bad),
        Err(FormatError::Checksum { .. })
    ));
    // Truncation and trailing bytes are caught before anything is read.
    assert!(matches!(
        HierarchyView::parse(&bytes[..bytes.len() - 1]),
        Err(FormatError::Truncated { .. })
    ));
    let mut long = bytes.clone();
    long.push(0);
    assert!(matches!(
        HierarchyView::parse(&long),
        Err(FormatError::TrailingBytes { .. })
    ));
}

#[test]
fn replays_refuse_inconsistent_hierarchies() {
    let (p, t) = grid(3);
    let mut h = build_it(&p, &t, BuildOptions::default());
    assert!(h.is_consistent());
    let last = h.nodes.len() - 1;
    h.nodes[last].children[0] = 10_000;
    assert!(!h.is_consistent());
    assert!(h.refine_all().is_empty());
    assert!(h.collapse_all(&t).is_empty());
}
