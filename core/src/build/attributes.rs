//! Per-node bounds the run-time tests need, computed once the collapses are done.
//!
//! - bounding-sphere radius: for a leaf, the sphere around it through its farthest neighbour; for
//!   a parent, the smallest sphere around it holding its children's spheres (merge-tree §3.3);
//! - cone of normals: a leaf's cone holds the normals of its triangles; a parent's holds its
//!   children's cones;
//! - error bounds over the *error vectors* `leaf - node` of all leaves below a node: Hoppe's
//!   uniform (`mu`, across the normal) and normal (`delta`) deviations, and the wavelet paper's
//!   normal-aligned spheroid, its axis ratio from equation 3 and its size the smallest that holds
//!   every vector;
//! - all bounds made monotonic up the tree (a parent's bound is at least its children's), which is
//!   what makes a cut chosen by them consistent.

use alloc::vec;
use alloc::vec::Vec;

use super::collapse::Engine;
use super::vec3::{add, cross, dot, from_f32, len, normalize, scale, sub, Vec3d};
use super::{Hierarchy, InputMesh, Node, NONE};
use crate::format::{oct_decode, oct_encode};

fn to_f32(v: Vec3d) -> [f32; 3] {
    v.map(|c| c as f32)
}

/// Rounds up to the next `f32`, so a bound computed in `f64` stays a bound.
fn up(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v {
        f32::from_bits(f.to_bits() + 1)
    } else {
        f
    }
}

/// The axis as the file stores it (8-bit octahedral), so that bounds measured against it hold for
/// what a device reads.
fn quantized_axis(a: Vec3d) -> Vec3d {
    let (x, y) = oct_encode(to_f32(a));
    from_f32(oct_decode(x, y))
}

/// Angle between two unit vectors.
fn angle(a: Vec3d, b: Vec3d) -> f64 {
    libm::atan2(len(cross(a, b)), dot(a, b))
}

pub(crate) fn finish(mesh: &InputMesh<'_>, e: Engine<'_>) -> Hierarchy {
    let heap_pushes = e.pushed.len() as u64;
    let leaves = mesh.positions.len();
    let m = e.pos.len();
    let mut nodes: Vec<Node> = (0..m)
        .map(|i| Node {
            position: if i < leaves {
                mesh.positions[i]
            } else {
                to_f32(e.pos[i])
            },
            parent: NONE,
            children: [NONE; 2],
            wings: [NONE; 2],
            color: e.color[i].map(|c| (c * 255.0 + 0.5).clamp(0.0, 255.0) as u8),
            ..Node::default()
        })
        .collect();
    // Triangle ids as the file numbers them: the base triangles first, then two per split.
    let base_count = e.face_alive.iter().filter(|&&a| a).count() as u32;
    let mut face_id = vec![NONE; e.faces.len()];
    let mut next = 0;
    for (f, &alive) in e.face_alive.iter().enumerate() {
        if alive {
            face_id[f] = next;
            next += 1;
        }
    }
    for (s, c) in e.collapses.iter().enumerate() {
        for (k, &f) in c.faces.iter().enumerate() {
            if let Some(id) = face_id.get_mut(f as usize) {
                *id = base_count + 2 * s as u32 + k as u32;
            }
        }
    }
    for c in &e.collapses {
        let p = c.parent as usize;
        nodes[p].children = c.children;
        nodes[p].wings = c.wings;
        nodes[p].neighbours = c
            .neighbours
            .map(|f| face_id.get(f as usize).copied().unwrap_or(NONE));
        for ch in c.children {
            nodes[ch as usize].parent = c.parent;
        }
    }
    // Positions as stored (f32) are what the bounds are measured from.
    let pos: Vec<Vec3d> = nodes.iter().map(|n| from_f32(n.position)).collect();

    // Leaves: radius to the farthest neighbour, cone around the incident triangles' normals.
    let mut radius = vec![0.0f64; m];
    let mut axis = vec![[0.0f64; 3]; m];
    let mut half = vec![0.0f64; m];
    let mut weight = vec![0.0f64; m];
    let mut face_normals = Vec::with_capacity(mesh.triangles.len());
    for t in mesh.triangles {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        let n = cross(sub(b, a), sub(c, a));
        face_normals.push(normalize(n));
        for &v in t {
            let v = v as usize;
            axis[v] = add(axis[v], n);
            weight[v] += len(n);
            for &w in t {
                radius[v] = radius[v].max(len(sub(pos[w as usize], pos[v])));
            }
        }
    }
    for a in axis.iter_mut().take(leaves) {
        *a = quantized_axis(normalize(*a).unwrap_or([0.0, 0.0, 1.0]));
    }
    for (t, n) in mesh.triangles.iter().zip(&face_normals) {
        for &v in t {
            let v = v as usize;
            half[v] = half[v].max(n.map_or(core::f64::consts::PI, |n| angle(axis[v], n)));
        }
    }
    // Parents, in formation order (children first).
    for c in &e.collapses {
        let p = c.parent as usize;
        let [a, b] = c.children.map(|x| x as usize);
        radius[p] =
            (len(sub(pos[a], pos[p])) + radius[a]).max(len(sub(pos[b], pos[p])) + radius[b]);
        weight[p] = weight[a] + weight[b];
        let sum = add(
            scale(axis[a], weight[a].max(1e-30)),
            scale(axis[b], weight[b].max(1e-30)),
        );
        axis[p] = quantized_axis(normalize(sum).unwrap_or(axis[a]));
        half[p] = (angle(axis[p], axis[a]) + half[a]).max(angle(axis[p], axis[b]) + half[b]);
    }

    // Depth, top-down: a parent always has a larger id than its children.
    for p in (leaves..m).rev() {
        let d = nodes[p].depth.saturating_add(1);
        for ch in nodes[p].children {
            nodes[ch as usize].depth = d;
        }
    }

    // Leaves in depth-first order, so that each node's leaves form one range.
    let mut order = Vec::with_capacity(leaves);
    let mut range = vec![(0u32, 0u32); m];
    let mut stack: Vec<(u32, bool)> = (0..m as u32)
        .rev()
        .filter(|&i| nodes[i as usize].parent == NONE)
        .map(|i| (i, false))
        .collect();
    while let Some((v, closing)) = stack.pop() {
        let node = &nodes[v as usize];
        if closing {
            range[v as usize].1 = order.len() as u32;
        } else if node.children[0] == NONE {
            range[v as usize] = (order.len() as u32, order.len() as u32 + 1);
            order.push(v);
        } else {
            range[v as usize].0 = order.len() as u32;
            stack.push((v, true));
            stack.push((node.children[1], false));
            stack.push((node.children[0], false));
        }
    }

    // Input vertices on a border (an endpoint of an edge only one triangle uses).
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    let mut on_border = vec![false; leaves];
    let mut k = 0;
    while k < edges.len() {
        let mut j = k + 1;
        while j < edges.len() && edges[j] == edges[k] {
            j += 1;
        }
        if j - k == 1 {
            let (a, b) = edges[k];
            for v in [a, b] {
                if let Some(flag) = on_border.get_mut(v as usize) {
                    *flag = true;
                }
            }
        }
        k = j;
    }

    for c in &e.collapses {
        let p = c.parent as usize;
        let n = axis[p];
        let (mut along, mut across, mut outline) = (0.0f64, 0.0f64, 0.0f64);
        let (s, t) = range[p];
        for &leaf in &order[s as usize..t as usize] {
            let d = sub(pos[leaf as usize], pos[p]);
            along = along.max(dot(d, n).abs());
            across = across.max(len(cross(d, n)));
            if on_border.get(leaf as usize) == Some(&true) {
                outline = outline.max(len(cross(d, n)));
            }
        }
        // The error of replacing the region by the node: each leaf's offset from the coarse
        // surface, which near the node is its tangent plane, so the offset lies along the normal
        // (Hoppe's normal deviation `delta`). A region's extent across the normal is not an
        // error: a flat region simplifies to nothing visible however wide it is. The spheroid of
        // equation 3 gets `a` = the largest offset and, across, the same radius `b = a` (Hoppe's
        // uniform term `mu` = `delta`): with `b = 0` face-on regions cost nothing and lose their
        // shading, which measured 0.6 to 1.3 dB worse PSNR at equal triangle counts
        // (`cargo bench --bench lod -- quality`). On a border the extent across the normal is an
        // error: it is how far the outline moves (a coarse border edge cuts across the notches
        // of the fine one), so there `b` also bounds the border leaves' offsets across the
        // normal; without it an open mesh's outline strayed 16 px at a 1 px tolerance.
        let (a, b) = (along, along.max(outline));
        let [c0, c1] = c.children.map(|x| &nodes[x as usize]);
        let mono = |own: f64, f: fn(&Node) -> f32| own.max(f(c0) as f64).max(f(c1) as f64);
        let mu = mono(across, |n| n.mu);
        let delta = mono(along, |n| n.delta);
        let sa = mono(a, |n| n.spheroid[0]);
        let sb = mono(b, |n| n.spheroid[1]);
        let node = &mut nodes[p];
        node.mu = up(mu);
        node.delta = up(delta);
        node.spheroid = [up(sa), up(sb)];
    }
    for (i, node) in nodes.iter_mut().enumerate() {
        node.radius = up(radius[i]);
        node.normal = to_f32(axis[i]);
        node.cone_sin = if half[i] < core::f64::consts::FRAC_PI_2 {
            up(libm::sin(half[i])).min(1.0)
        } else {
            1.0
        };
    }

    let base_triangles = e
        .faces
        .iter()
        .zip(&e.face_alive)
        .filter(|(_, &alive)| alive)
        .map(|(t, _)| *t)
        .collect();
    Hierarchy {
        leaves: leaves as u32,
        nodes,
        base_triangles,
        heap_pushes,
    }
}
