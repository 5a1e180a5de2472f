//! Per-node bounds the run-time tests need, computed once the collapses are done.
//!
//! - bounding-sphere radius: for a leaf, the sphere around it through its farthest neighbour; for
//!   a parent, the smallest sphere around it holding its children's spheres (merge-tree §3.3);
//! - cone of normals: a leaf's cone holds the normals of its triangles; a parent's holds its
//!   children's cones;
//! - an error bound over the leaves below a node, as [`ErrorBound`] chooses: their offsets
//!   along the node's normal, or the *residuals* from each leaf to the closest point of the
//!   triangles around the node as the builder made it, bounded by the wavelet paper's
//!   normal-aligned spheroid (equation 3) or Hoppe's sphere swept along the normal (Hoppe,
//!   "View-dependent refinement of progressive meshes", 1997, measures his deviation space the
//!   same way: residuals of the fine surface to the coarse neighbourhood);
//! - all bounds made monotonic up the tree (a parent's bound is at least its children's), which is
//!   what makes a cut chosen by them consistent.

use alloc::vec;
use alloc::vec::Vec;

use super::bound::{equation3, hoppe};
use super::closest::{closest, point};
use super::collapse::{kept, Collapsed};
use super::input::Borders;
use super::vec3::{add, cross, dot, from_f32, len, normalize, normalize_by, scale, sub, Vec3d};
use super::{ErrorBound, Hierarchy, InputMesh, Node, NONE};
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

/// Every node's position as the file stores it (`f32`): the input's, then the made ones'. The
/// bounds are measured from these, read here, twelve bytes apart, rather than from the 84-byte
/// nodes: on the Loop-subdivided bunny, whose nodes (50 MB) outgrow the caches, 8% fewer
/// simulated cache misses for the whole build (its time the same within the machine's noise).
struct Stored<'m> {
    input: &'m [[f32; 3]],
    made: Vec<[f32; 3]>,
}

impl Stored<'_> {
    /// Node `i`'s position as stored.
    fn get(&self, i: u32) -> [f32; 3] {
        match self.input.get(i as usize) {
            Some(&p) => p,
            None => self.made[i as usize - self.input.len()],
        }
    }

    /// Node `i`'s position as stored, widened.
    fn at(&self, i: u32) -> Vec3d {
        from_f32(self.get(i))
    }
}

/// A node's radius and normal cone as they are gathered: from its triangles for a leaf, from
/// its children for a parent.
#[derive(Clone, Copy, Default)]
struct Gathered {
    axis: Vec3d,
    weight: f64,
    radius: f64,
    half: f64,
}

/// `a.max(b)` where `a` is never NaN (and a zero's sign does not matter): a NaN `b` fails the
/// comparison, as `max` skips it, and `max`'s test for a NaN `a` is left out; on the maxima
/// taken per triangle corner and per leaf below a node it was a third of their instructions.
fn larger(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// `a.min(b)` where `a` is never NaN, as [`larger`].
fn smaller(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// Angle between two unit vectors.
fn angle(a: Vec3d, b: Vec3d) -> f64 {
    libm::atan2(len(cross(a, b)), dot(a, b))
}

/// The hierarchy of the collapses `e` made on `mesh`, whose vertices on a border `on_border`
/// names (as `input::checked` finds them).
pub(crate) fn finish(mesh: &InputMesh<'_>, mut e: Collapsed<'_>, on_border: &Borders) -> Hierarchy {
    let heap_pushes = e.heap_pushes;
    let leaves = mesh.positions.len();
    let m = e.pos.len();
    // The base mesh, and the collapsed faces freed, before the nodes are made (where this
    // function's memory peaks).
    let base_triangles = e
        .faces
        .iter()
        .zip(&e.face_alive)
        .filter(|(_, &alive)| alive)
        .map(|(t, _)| *t)
        .collect();
    e.faces = Vec::new();
    // The made positions rounded as stored, and the collapse-time ones freed.
    let stored = Stored {
        input: mesh.positions,
        made: (leaves..m).map(|i| to_f32(e.pos.get(i as u32))).collect(),
    };
    e.pos.release();
    let at = |i: u32| stored.at(i);
    // The input's triangles and the leaves below a node are the input's own vertices.
    let leaf = |i: u32| from_f32(mesh.positions[i as usize]);
    // Leaves: radius to the farthest neighbour, cone around the incident triangles' normals.
    // Each node's terms side by side, so that a triangle's corners are three records read (the
    // input's triangles come in no order of their vertices).
    let mut g = vec![Gathered::default(); m];
    // Each triangle's unit normal, for the cones below (`None` for a degenerate one).
    let mut unit = Vec::with_capacity(mesh.triangles.len());
    for t in mesh.triangles {
        let corner = t.map(leaf);
        let [a, b, c] = corner;
        let n = cross(sub(b, a), sub(c, a));
        let area = len(n);
        unit.push(normalize_by(n, area));
        // Each edge's length once: measured either way it is the same number.
        let edge: [f64; 3] = core::array::from_fn(|k| len(sub(corner[(k + 1) % 3], corner[k])));
        for (k, &v) in t.iter().enumerate() {
            let g = &mut g[v as usize];
            g.axis = add(g.axis, n);
            g.weight += area;
            g.radius = larger(larger(g.radius, edge[k]), edge[(k + 2) % 3]);
        }
    }
    for g in g.iter_mut().take(leaves) {
        g.axis = quantized_axis(normalize(g.axis).unwrap_or([0.0, 0.0, 1.0]));
    }
    // The cone's half-angle is the widest angle between the axis and a triangle's normal, the
    // one of the smallest cosine: `atan2` only measures the triangles within `1e-9` of it
    // (angles whose cosines differ by that differ by as much, far above the rounding of either
    // measure, so the largest is among them), one or two of a vertex's six or so. The unit
    // normals are kept from the loop above (32 bytes a triangle, less than the nodes and their
    // cones take below, where this function's memory peaks); a degenerate triangle opens the
    // cone wide (`-inf`: no cosine is that small).
    let mut least = vec![f64::INFINITY; leaves];
    for (t, &n) in mesh.triangles.iter().zip(&unit) {
        for &v in t {
            let (g, least) = (&g[v as usize], &mut least[v as usize]);
            *least = n.map_or(f64::NEG_INFINITY, |n| smaller(*least, dot(g.axis, n)));
        }
    }
    for (t, &n) in mesh.triangles.iter().zip(&unit) {
        for &v in t {
            let (g, least) = (&mut g[v as usize], least[v as usize]);
            let widest = match n {
                None => core::f64::consts::PI,
                Some(n) if dot(g.axis, n) <= least + 1e-9 => angle(g.axis, n),
                Some(_) => continue,
            };
            g.half = g.half.max(widest);
        }
    }
    drop((least, unit));
    // Parents, in formation order (children first).
    for c in &e.collapses {
        let p = c.parent as usize;
        let [a, b] = c.children.map(|x| g[x as usize]);
        let [pa, pb] = c.children.map(at);
        let at_p = at(p as u32);
        let radius = (len(sub(pa, at_p)) + a.radius).max(len(sub(pb, at_p)) + b.radius);
        let sum = add(
            scale(a.axis, a.weight.max(1e-30)),
            scale(b.axis, b.weight.max(1e-30)),
        );
        let axis = match kept(e.opts, at_p, [pa, pb]) {
            Some(k) => [a, b][k].axis,
            None => quantized_axis(normalize(sum).unwrap_or(a.axis)),
        };
        g[p] = Gathered {
            axis,
            weight: a.weight + b.weight,
            radius,
            half: (angle(axis, a.axis) + a.half).max(angle(axis, b.axis) + b.half),
        };
    }
    // As the nodes store them; the axis is an `f32` octahedral code's, so the node's normal is
    // the axis exactly and the error bounds below read it there. (Made before the nodes, the
    // gathered terms never sit beside them.)
    let cones: Vec<(f32, [f32; 3], f32)> = g
        .iter()
        .map(|g| {
            let sin = if g.half < core::f64::consts::FRAC_PI_2 {
                up(libm::sin(g.half)).min(1.0)
            } else {
                1.0
            };
            (up(g.radius), to_f32(g.axis), sin)
        })
        .collect();
    drop(g);
    let mut nodes: Vec<Node> = (0..m)
        .map(|i| Node {
            position: stored.get(i as u32),
            radius: cones[i].0,
            normal: cones[i].1,
            cone_sin: cones[i].2,
            parent: NONE,
            children: [NONE; 2],
            wings: [NONE; 2],
            // Black without colours (what `color_of`'s zero rounds to), at no cost per node.
            color: e.color.get(i).map_or([0; 3], |c| {
                c.map(|c| (c * 255.0 + 0.5).clamp(0.0, 255.0) as u8)
            }),
            ..Node::default()
        })
        .collect();
    // The colours and cones are in the nodes now.
    e.color = Vec::new();
    drop(cones);
    // Triangle ids as the file numbers them: the base triangles first, then two per split.
    let base_count = e.face_alive.iter().filter(|&&a| a).count() as u32;
    let mut face_id = vec![NONE; e.face_alive.len()];
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
    drop(face_id);

    // Depth, top-down: a parent always has a larger id than its children.
    for p in (leaves..m).rev() {
        let d = nodes[p].depth.saturating_add(1);
        for ch in nodes[p].children {
            nodes[ch as usize].depth = d;
        }
    }

    let (below, range) = depth_first(&nodes, leaves, on_border);

    let mut errors: Vec<(f32, f32)> = Vec::new();
    for (k, c) in e.collapses.iter().enumerate() {
        let p = c.parent as usize;
        let n = from_f32(nodes[p].normal);
        let (s, t) = range[p - leaves];
        let own = if e.opts.bound == ErrorBound::Offset {
            offset_bound(&below, s, t, at(p as u32), n)
        } else {
            let start = k.checked_sub(1).map_or(0, |j| e.fan_ends[j] as usize);
            let fan = &e.fans[start..e.fan_ends[k] as usize];
            errors.clear();
            errors.extend(below.positions[s as usize..t as usize].iter().map(|&x| {
                let x = from_f32(x);
                let d = sub(x, nearest(x, fan, &stored).unwrap_or(at(p as u32)));
                (up(dot(d, n).abs()), up(len(cross(d, n))))
            }));
            match e.opts.bound {
                ErrorBound::Hoppe => hoppe(&errors),
                _ => equation3(&errors),
            }
        };
        let [c0, c1] = c.children.map(|x| nodes[x as usize].spheroid);
        nodes[p].spheroid = core::array::from_fn(|i| own[i].max(c0[i]).max(c1[i]));
    }
    Hierarchy {
        bound: e.opts.bound,
        leaves: leaves as u32,
        nodes,
        base_triangles,
        heap_pushes,
    }
}

/// The leaves in depth-first order, so that each node's leaves form one range: their positions,
/// and which of them lie on a border. The error bounds visit every leaf below every node, and
/// read them here one after the other rather than each at its index.
struct Below {
    positions: Vec<[f32; 3]>,
    on_border: Borders,
}

/// The `leaves` first of `nodes` (`on_border` naming those on a border) in depth-first order, and
/// each parent's range in that order (at its id less the leaves').
fn depth_first(nodes: &[Node], leaves: usize, on_border: &Borders) -> (Below, Vec<(u32, u32)>) {
    let mut below = Below {
        positions: Vec::with_capacity(leaves),
        on_border: Borders::new(leaves),
    };
    let mut range = vec![(0u32, 0u32); nodes.len().saturating_sub(leaves)];
    let mut stack: Vec<(u32, bool)> = (0..nodes.len() as u32)
        .rev()
        .filter(|&i| nodes[i as usize].parent == NONE)
        .map(|i| (i, false))
        .collect();
    while let Some((v, closing)) = stack.pop() {
        let node = &nodes[v as usize];
        let here = below.positions.len() as u32;
        if node.children[0] == NONE {
            if on_border.contains(v) {
                below.on_border.insert(here);
            }
            below.positions.push(node.position);
        } else if closing {
            range[v as usize - leaves].1 = here;
        } else {
            range[v as usize - leaves].0 = here;
            stack.push((v, true));
            stack.push((node.children[1], false));
            stack.push((node.children[0], false));
        }
    }
    (below, range)
}

/// [`ErrorBound::Offset`] of a node at `center` with normal `n` over the leaves `start..end` of
/// `below`.
fn offset_bound(below: &Below, start: u32, end: u32, center: Vec3d, n: Vec3d) -> [f32; 2] {
    let offset = |p: [f32; 3]| sub(from_f32(p), center);
    let leaves = &below.positions[start as usize..end as usize];
    let along = leaves
        .iter()
        .fold(0.0f64, |along, &p| larger(along, dot(offset(p), n).abs()));
    // Only the border leaves measure across the normal (the largest is the same in any order).
    let outline = below
        .on_border
        .within(start, end)
        .fold(0.0f64, |outline, i| {
            outline.max(len(cross(offset(below.positions[i as usize]), n)))
        });
    // The error of replacing the region by the node: each leaf's offset from the coarse
    // surface, which near the node is its tangent plane, so the offset lies along the normal.
    // A region's extent across the normal is not an error: a flat region simplifies to nothing
    // visible however wide it is. `b = a`: with `b = 0` face-on regions cost nothing and lose
    // their shading, which measured 0.6 to 1.3 dB worse PSNR at equal triangle counts
    // (`cargo bench --bench lod -- quality`). On a border the extent across the normal is an
    // error: it is how far the outline moves (a coarse border edge cuts across the notches of
    // the fine one), so there `b` also bounds the border leaves' offsets across the normal;
    // without it an open mesh's outline strayed 16 px at a 1 px tolerance.
    [up(along), up(along.max(outline))]
}

/// The closest point to `x` on the triangles `fan` (corners at their `stored` positions), or
/// `None` for no triangle.
fn nearest(x: Vec3d, fan: &[[u32; 3]], stored: &Stored<'_>) -> Option<Vec3d> {
    fan.iter()
        .map(|t| {
            let corners = t.map(|v| stored.at(v));
            let (w, d2) = closest(x, corners);
            (d2, point(corners, w))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, q)| q)
}
