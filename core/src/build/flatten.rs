//! Planar maps of collapse regions, for the remesher's parameterization.
//!
//! Liu, Kim, Chen, Jacobson, Sharp and Aigerman ("Neural subdivision", 2020) parameterize a mesh
//! over its own simplification by mapping, at every edge collapse, the collapsed edge's region
//! (the triangles around either end) into the plane twice: before the collapse and after it,
//! with the same boundary polygon. A point in a triangle of one map is then a point in a
//! triangle of the other, and a chain of such maps carries any point of the coarse mesh down to
//! the input surface, one collapse at a time (Lee, Sweldens, Schröder, Cowsar and Dobkin's MAPS,
//! 1998, does the same per removed vertex with a conformal map of its star).
//!
//! [`flatten`] builds both maps. It tries a least-squares conformal map first (it unrolls a
//! region wrapped round a thin part), then the projection onto the region's mean plane, and
//! last a map that cannot fold: the boundary on a convex polygon (a circle, spaced by the 3D lengths of
//! its edges; a straight side for the border edge of an open mesh) and the inner vertices at
//! Floater's mean-value combinations of their neighbours ("Mean value coordinates", 2003), which
//! Tutte's theorem makes an embedding. Both maps are checked triangle by triangle before they are
//! used; a region that admits no valid pair (never seen on manifold input, but possible on
//! degenerate triangles) is reported as `None`, and the builder does not collapse that edge.

use alloc::vec;
use alloc::vec::Vec;

use super::vec3::{cross, dot, len, normalize, sub, Vec3d};

/// A point of a planar map.
pub type Uv = [f64; 2];

/// One collapse's two planar maps, sharing the boundary: every vertex of the region before the
/// collapse (the children and the ring) and the parent after it, each at one point.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarCollapse {
    /// The vertex the collapse made.
    pub parent: u32,
    /// The merged vertices.
    pub children: [u32; 2],
    /// The region before the collapse: (face id, corners), counter-clockwise.
    pub before: Vec<(u32, [u32; 3])>,
    /// Each vertex of the region (the parent included) with its point, sorted by vertex.
    pub uv: Vec<(u32, Uv)>,
}

impl PlanarCollapse {
    /// The point of vertex `v`, if it is in the region.
    pub fn uv_of(&self, v: u32) -> Option<Uv> {
        lookup(&self.uv, v)
    }

    /// The region after the collapse: the faces that were not on the collapsed edge, with the
    /// children renamed to the parent.
    pub fn after(&self) -> impl Iterator<Item = (u32, [u32; 3])> + '_ {
        let [a, b] = self.children;
        self.before
            .iter()
            .filter(move |(_, t)| !(t.contains(&a) && t.contains(&b)))
            .map(move |&(f, t)| (f, t.map(|x| if x == a || x == b { self.parent } else { x })))
    }
}

/// Twice the signed area of the planar triangle `a b c`.
pub fn area2(a: Uv, b: Uv, c: Uv) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Barycentric weights of `q` in the planar triangle `t` (`None` when it is degenerate).
pub fn barycentric(t: [Uv; 3], q: Uv) -> Option<[f64; 3]> {
    let d = area2(t[0], t[1], t[2]);
    if d.abs() <= 0.0 || !d.is_finite() {
        return None;
    }
    let w1 = area2(t[0], q, t[2]) / d;
    let w2 = area2(t[0], t[1], q) / d;
    Some([1.0 - w1 - w2, w1, w2])
}

/// The region's boundary as one counter-clockwise loop, or `None` when it is not a disk.
fn boundary_loop(faces: &[[u32; 3]]) -> Option<Vec<u32>> {
    let edges: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    let outer: Vec<(u32, u32)> = edges
        .iter()
        .copied()
        .filter(|&(x, y)| !edges.contains(&(y, x)))
        .collect();
    let first = outer.first()?;
    let mut ring = Vec::with_capacity(outer.len());
    let mut at = first.0;
    for _ in 0..outer.len() {
        ring.push(at);
        let from = at;
        let mut next = outer.iter().filter(|&&(x, _)| x == from);
        at = next.next()?.1;
        if next.next().is_some() {
            return None; // the boundary touches itself
        }
    }
    (at == first.0 && ring.len() >= 3).then_some(ring)
}

/// Whether every triangle of both maps is counter-clockwise with a useful area, and the
/// boundary polygon is simple (with all triangles positive, a disk's map is then an embedding).
fn valid(collapse: &PlanarCollapse, ring: &[u32]) -> bool {
    let Some(pts) = ring
        .iter()
        .map(|&v| collapse.uv_of(v))
        .collect::<Option<Vec<Uv>>>()
    else {
        return false;
    };
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in &pts {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(size > 0.0 && size.is_finite()) {
        return false;
    }
    let least = 1e-9 * size * size;
    let positive = |(_, t): (u32, [u32; 3])| match t.map(|v| collapse.uv_of(v)) {
        [Some(a), Some(b), Some(c)] => area2(a, b, c) > least,
        _ => false,
    };
    let faces_ok = collapse.before.iter().copied().all(positive) && collapse.after().all(positive);
    // Same boundary, positive triangles and the same area: both maps tile the same polygon.
    let area = |t: [u32; 3]| match t.map(|v| collapse.uv_of(v)) {
        [Some(a), Some(b), Some(c)] => area2(a, b, c),
        _ => f64::NAN,
    };
    let before: f64 = collapse.before.iter().map(|&(_, t)| area(t)).sum();
    let after: f64 = collapse.after().map(|(_, t)| area(t)).sum();
    faces_ok && (before - after).abs() <= 1e-9 * before.abs() && simple(&pts)
}

/// Whether the closed polygon `p` has no two non-adjacent edges that touch.
fn simple(p: &[Uv]) -> bool {
    let n = p.len();
    // Whether `q`, on the line through `a b`, lies within the segment.
    let within =
        |a: Uv, b: Uv, q: Uv| (0..2).all(|k| q[k] >= a[k].min(b[k]) && q[k] <= a[k].max(b[k]));
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        for j in i + 2..n {
            if (j + 1) % n == i {
                continue;
            }
            let (c, d) = (p[j], p[(j + 1) % n]);
            let (d1, d2) = (area2(a, b, c), area2(a, b, d));
            let (d3, d4) = (area2(c, d, a), area2(c, d, b));
            let proper = d1 * d2 < 0.0 && d3 * d4 < 0.0;
            let touching = (d1 == 0.0 && within(a, b, c))
                || (d2 == 0.0 && within(a, b, d))
                || (d3 == 0.0 && within(c, d, a))
                || (d4 == 0.0 && within(c, d, b));
            if proper || touching {
                return false;
            }
        }
    }
    true
}

/// `tan(theta / 2)` of the angle between `u` and `w`.
fn half_tan(u: Vec3d, w: Vec3d) -> f64 {
    let s = len(cross(u, w));
    let c = len(u) * len(w) + dot(u, w);
    if c > 0.0 {
        s / c
    } else {
        f64::INFINITY
    }
}

/// Floater's mean-value weights of vertex `v` (at `at`) over its neighbours in `faces`.
fn mean_value(
    v: u32,
    at: Vec3d,
    faces: &[[u32; 3]],
    pos: &dyn Fn(u32) -> Vec3d,
) -> Vec<(u32, f64)> {
    let mut w: Vec<(u32, f64)> = Vec::new();
    for t in faces {
        let Some(k) = t.iter().position(|&x| x == v) else {
            continue;
        };
        let (j, l) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let (dj, dl) = (sub(pos(j), at), sub(pos(l), at));
        let h = half_tan(dj, dl);
        for (x, d) in [(j, dj), (l, dl)] {
            let add = h / len(d);
            match w.iter_mut().find(|(y, _)| *y == x) {
                Some(e) => e.1 += add,
                None => w.push((x, add)),
            }
        }
    }
    w
}

/// Both maps of the collapse of `a-b` into `parent` (at `at`): `before` is every face around
/// `a` or `b` as (face id, corners), `pos` the 3D position of any other vertex. `None` when the
/// region is not a disk or no valid pair of maps was found.
pub fn flatten(
    before: Vec<(u32, [u32; 3])>,
    [a, b]: [u32; 2],
    parent: u32,
    at: Vec3d,
    pos: &dyn Fn(u32) -> Vec3d,
) -> Option<PlanarCollapse> {
    let faces: Vec<[u32; 3]> = before.iter().map(|&(_, t)| t).collect();
    let ring = boundary_loop(&faces)?;
    let on_ring = |v: u32| ring.iter().position(|&x| x == v);
    let inner_ok = faces
        .iter()
        .flatten()
        .all(|&v| v == a || v == b || on_ring(v).is_some());
    if !inner_ok {
        return None;
    }
    let mut collapse = PlanarCollapse {
        parent,
        children: [a, b],
        before,
        uv: Vec::new(),
    };
    // The projection cannot keep the polygon when both ends are on it (the parent would have
    // to lie on a straight line through them): that case always takes the convex map.
    let border_edge = on_ring(a).is_some() && on_ring(b).is_some();
    let region = Region {
        faces: &faces,
        ring: &ring,
        children: [a, b],
        parent,
        at,
        pos,
    };
    let maps = [
        (!border_edge).then(|| conformal(&region)).flatten(),
        (!border_edge).then(|| projected(&region)).flatten(),
        convex(&region),
    ];
    for uv in maps.into_iter().flatten() {
        collapse.uv = uv;
        if valid(&collapse, &ring) {
            return Some(collapse);
        }
    }
    None
}

/// The point of `v` in `uv` (sorted by vertex).
fn lookup(uv: &[(u32, Uv)], v: u32) -> Option<Uv> {
    let k = uv.binary_search_by_key(&v, |&(x, _)| x).ok()?;
    Some(uv[k].1)
}

/// The region's faces after the collapse of `a-b`, the parent named `u32::MAX`.
fn after_faces(faces: &[[u32; 3]], [a, b]: [u32; 2]) -> Vec<[u32; 3]> {
    faces
        .iter()
        .filter(|t| !(t.contains(&a) && t.contains(&b)))
        .map(|t| t.map(|x| if x == a || x == b { u32::MAX } else { x }))
        .collect()
}

/// What every map of a collapse reads: the region's faces and boundary loop, the merged
/// vertices, the parent and its position, and every other vertex's.
#[derive(Clone, Copy)]
struct Region<'a> {
    faces: &'a [[u32; 3]],
    ring: &'a [u32],
    children: [u32; 2],
    parent: u32,
    at: Vec3d,
    pos: &'a dyn Fn(u32) -> Vec3d,
}

/// Every point sorted by vertex, with the parent's.
fn finish(mut uv: Vec<(u32, Uv)>) -> Vec<(u32, Uv)> {
    uv.sort_by_key(|&(v, _)| v);
    uv.dedup_by_key(|&mut (v, _)| v);
    uv
}

/// `uv` (the region's points) sorted, with the parent's point: on a border where the boundary
/// fixes it (so the collapse keeps the polygon the same), inside where `inside` puts it.
fn with_parent(
    region: &Region<'_>,
    uv: Vec<(u32, Uv)>,
    inside: impl FnOnce(&[(u32, Uv)]) -> Option<Uv>,
) -> Option<Vec<(u32, Uv)>> {
    let Region {
        ring,
        children: [a, b],
        at,
        pos,
        ..
    } = *region;
    let mut uv = finish(uv);
    let p = match (ring.contains(&a), ring.contains(&b)) {
        (false, false) => inside(&uv)?,
        (true, false) => lookup(&uv, a)?,
        (false, true) => lookup(&uv, b)?,
        (true, true) => {
            // Both on the border: the parent on the segment between them, where it lies along
            // the edge in 3D.
            let (pa, pb) = (lookup(&uv, a)?, lookup(&uv, b)?);
            let (da, db) = (len(sub(at, pos(a))), len(sub(at, pos(b))));
            let t = if da + db > 0.0 { da / (da + db) } else { 0.5 };
            let t = t.clamp(0.05, 0.95);
            [pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])]
        }
    };
    uv.push((region.parent, p));
    // The parent is the newest vertex, so this is already sorted; kept sorted regardless.
    uv.sort_by_key(|&(v, _)| v);
    Some(uv)
}

/// The least-squares conformal map (Lévy, Petitjean, Ray and Maillot, "Least squares conformal
/// maps for automatic texture atlas generation", 2002) of the region with `a` and `b` pinned,
/// and the parent where the same energy over the triangles after the collapse puts it (or, on a
/// border, where the boundary fixes it). Isometric where the region is developable, so a region
/// wrapped round a thin part (a leg, an ear) is unrolled rather than squashed.
fn conformal(region: &Region<'_>) -> Option<Vec<(u32, Uv)>> {
    let Region {
        faces,
        ring,
        children: [a, b],
        at,
        pos,
        ..
    } = *region;
    let ab = len(sub(pos(b), pos(a)));
    let pinned = [(a, [0.0, 0.0]), (b, [ab, 0.0])];
    let mut free: Vec<u32> = faces.iter().flatten().copied().collect();
    free.sort_unstable();
    free.dedup();
    free.retain(|&v| v != a && v != b);
    let mut uv = least_squares_conformal(faces, pos, &pinned, &free)?;
    uv.extend_from_slice(&pinned);
    with_parent(region, uv, |uv| {
        let after = after_faces(faces, [a, b]);
        let with_parent = |v: u32| if v == u32::MAX { at } else { pos(v) };
        let fixed: Vec<(u32, Uv)> = ring
            .iter()
            .map(|&v| Some((v, lookup(uv, v)?)))
            .collect::<Option<_>>()?;
        Some(
            least_squares_conformal(&after, &with_parent, &fixed, &[u32::MAX])?
                .first()?
                .1,
        )
    })
}

/// The points of the `free` vertices minimising the conformal energy of `faces` (each
/// triangle's residual `sum_k W_k U_k`, `W_k` its edge opposite corner `k` in its own plane,
/// weighted by one over its area) with the `fixed` vertices where they are given.
fn least_squares_conformal(
    faces: &[[u32; 3]],
    pos: &dyn Fn(u32) -> Vec3d,
    fixed: &[(u32, Uv)],
    free: &[u32],
) -> Option<Vec<(u32, Uv)>> {
    let n = 2 * free.len();
    if n == 0 {
        return Some(Vec::new());
    }
    // Normal equations of the rows, accumulated: (A^T A) x = A^T r.
    let mut m = vec![0.0f64; n * n];
    let mut rhs = vec![0.0f64; n];
    for t in faces {
        let [p0, p1, p2] = t.map(pos);
        let (e1, e2) = (sub(p1, p0), sub(p2, p0));
        let l1 = len(e1);
        let normal = cross(e1, e2);
        let area = 0.5 * len(normal);
        if !(l1 > 0.0 && area > 0.0 && area.is_finite()) {
            return None;
        }
        let x = [e1[0] / l1, e1[1] / l1, e1[2] / l1];
        let y = normalize(cross(normal, x))?;
        let z = [[0.0, 0.0], [l1, 0.0], [dot(e2, x), dot(e2, y)]];
        let weight = 1.0 / crate::root::sqrt(area);
        // W_k = z_{k+2} - z_{k+1}; the residual's real and imaginary rows.
        let w: [Uv; 3] = core::array::from_fn(|k| {
            let (p, q) = (z[(k + 2) % 3], z[(k + 1) % 3]);
            [(p[0] - q[0]) * weight, (p[1] - q[1]) * weight]
        });
        for row in 0..2 {
            // Coefficients of (u_k, v_k): real row (wr, -wi), imaginary row (wi, wr).
            let coef = |k: usize| -> [f64; 2] {
                if row == 0 {
                    [w[k][0], -w[k][1]]
                } else {
                    [w[k][1], w[k][0]]
                }
            };
            let mut cols: [(Option<usize>, [f64; 2]); 3] = [(None, [0.0; 2]); 3];
            let mut known = 0.0;
            for k in 0..3 {
                let c = coef(k);
                match free.iter().position(|&v| v == t[k]) {
                    Some(i) => cols[k] = (Some(i), c),
                    None => {
                        let (_, p) = fixed.iter().find(|(v, _)| *v == t[k])?;
                        known += c[0] * p[0] + c[1] * p[1];
                    }
                }
            }
            for &(i, ci) in &cols {
                let Some(i) = i else { continue };
                for (di, &cv) in ci.iter().enumerate() {
                    let r = 2 * i + di;
                    rhs[r] -= cv * known;
                    for &(j, cj) in &cols {
                        let Some(j) = j else { continue };
                        for (dj, &cw) in cj.iter().enumerate() {
                            m[r * n + 2 * j + dj] += cv * cw;
                        }
                    }
                }
            }
        }
    }
    let x = solve(&mut m, &mut rhs, n)?;
    Some(
        free.iter()
            .enumerate()
            .map(|(i, &v)| (v, [x[2 * i], x[2 * i + 1]]))
            .collect(),
    )
}

/// Solves the `n` by `n` system `m x = r` by Gaussian elimination with partial pivoting.
fn solve(m: &mut [f64], r: &mut [f64], n: usize) -> Option<Vec<f64>> {
    for c in 0..n {
        let pivot = (c..n).max_by(|&i, &j| m[i * n + c].abs().total_cmp(&m[j * n + c].abs()))?;
        let size = m[pivot * n + c].abs();
        if size.is_nan() || size <= 1e-300 {
            return None;
        }
        if pivot != c {
            for k in 0..n {
                m.swap(c * n + k, pivot * n + k);
            }
            r.swap(c, pivot);
        }
        for i in c + 1..n {
            let f = m[i * n + c] / m[c * n + c];
            if f != 0.0 {
                for k in c..n {
                    m[i * n + k] -= f * m[c * n + k];
                }
                r[i] -= f * r[c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| m[c * n + k] * x[k]).sum();
        x[c] = (r[c] - s) / m[c * n + c];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The region projected onto its mean plane, the parent at its own position's projection (or,
/// on a border, where the boundary fixes it).
fn projected(region: &Region<'_>) -> Option<Vec<(u32, Uv)>> {
    let Region {
        faces,
        children: [a, _],
        at,
        pos,
        ..
    } = *region;
    let mut n = [0.0; 3];
    for t in faces {
        let [p, q, r] = t.map(pos);
        let c = cross(sub(q, p), sub(r, p));
        n = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
    }
    let n = normalize(n)?;
    let helper = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = normalize(cross(helper, n))?;
    let w = cross(n, u);
    let origin = pos(a);
    let project = |p: Vec3d| {
        let d = sub(p, origin);
        [dot(d, u), dot(d, w)]
    };
    let uv: Vec<(u32, Uv)> = faces
        .iter()
        .flatten()
        .map(|&v| (v, project(pos(v))))
        .collect();
    with_parent(region, uv, |_| Some(project(at)))
}

/// The map that cannot fold: the boundary on a convex polygon, inner vertices at mean-value
/// combinations of their neighbours.
fn convex(region: &Region<'_>) -> Option<Vec<(u32, Uv)>> {
    let Region {
        faces,
        ring,
        children: [a, b],
        at,
        pos,
        ..
    } = *region;
    let m = ring.len();
    let length = |i: usize| len(sub(pos(ring[(i + 1) % m]), pos(ring[i])));
    let mut uv: Vec<(u32, Uv)> = Vec::with_capacity(m + 3);
    match (
        ring.iter().position(|&x| x == a),
        ring.iter().position(|&x| x == b),
    ) {
        (Some(ia), Some(ib)) => {
            // The collapsed edge is on the border: it and the border edges either side of it on
            // a straight side, the rest of the boundary on a half circle over it.
            let k = if (ia + 1) % m == ib { ia } else { ib };
            if m < 5 {
                return None;
            }
            let start = (k + m - 1) % m; // the straight side is ring[start..start + 4]
            let side: [f64; 3] = [0, 1, 2].map(|i| length((start + i) % m));
            let total: f64 = side.iter().sum();
            let mut s = 0.0;
            for i in 0..4 {
                uv.push((ring[(start + i) % m], [-1.0 + 2.0 * s / total, 0.0]));
                if i < 3 {
                    s += side[i];
                }
            }
            // The arc runs from the side's far end (angle 0) round to its near end (angle pi).
            let arc: Vec<usize> = (3..m).map(|i| (start + i) % m).collect();
            let lengths: Vec<f64> = arc.iter().map(|&i| length(i)).collect();
            let total: f64 = lengths.iter().sum();
            let mut s = 0.0;
            for j in 1..arc.len() {
                s += lengths[j - 1];
                let t = core::f64::consts::PI * s / total;
                uv.push((ring[arc[j]], [libm::cos(t), libm::sin(t)]));
            }
        }
        _ => {
            let lengths: Vec<f64> = (0..m).map(length).collect();
            let total: f64 = lengths.iter().sum();
            let mut s = 0.0;
            for (i, &l) in lengths.iter().enumerate() {
                let t = 2.0 * core::f64::consts::PI * s / total;
                uv.push((ring[i], [libm::cos(t), libm::sin(t)]));
                s += l;
            }
        }
    }
    if !uv.iter().all(|(_, p)| p[0].is_finite() && p[1].is_finite()) {
        return None;
    }
    // Inner vertices: a and b where they are not on the boundary, solved together.
    let inner: Vec<u32> = [a, b].into_iter().filter(|v| !ring.contains(v)).collect();
    let boundary = finish(uv.clone());
    let known = |v: u32| lookup(&boundary, v);
    // Row of each inner vertex: its weights' sum, the weight of the other inner vertex, and the
    // weighted sum of its boundary neighbours.
    let mut rows = Vec::with_capacity(2);
    for &v in &inner {
        let w = mean_value(v, pos(v), faces, pos);
        let total: f64 = w.iter().map(|(_, x)| x).sum();
        let mut other = 0.0;
        let mut sum = [0.0; 2];
        for &(x, wx) in &w {
            if inner.contains(&x) {
                other += wx;
            } else {
                let p = known(x)?;
                sum = [sum[0] + wx * p[0], sum[1] + wx * p[1]];
            }
        }
        if !(total > 0.0 && total.is_finite() && other.is_finite()) {
            return None;
        }
        rows.push((total, other, sum));
    }
    match rows.as_slice() {
        [] => {}
        [(t, _, s)] => uv.push((inner[0], scale2(*s, 1.0 / t))),
        [(t0, o0, s0), (t1, o1, s1)] => {
            // t0 x0 - o0 x1 = s0, t1 x1 - o1 x0 = s1.
            let det = t0 * t1 - o0 * o1;
            if det.is_nan() || det <= 0.0 {
                return None;
            }
            let x0 = [0, 1].map(|k| (s0[k] * t1 + o0 * s1[k]) / det);
            let x1 = [0, 1].map(|k| (s1[k] * t0 + o1 * s0[k]) / det);
            uv.push((inner[0], x0));
            uv.push((inner[1], x1));
        }
        _ => return None,
    }
    with_parent(region, uv, |uv| {
        // Inside the strictly convex polygon at its mean-value combination of the ring.
        let after = after_faces(faces, [a, b]);
        let fake = |v: u32| if v == u32::MAX { at } else { pos(v) };
        let w = mean_value(u32::MAX, at, &after, &fake);
        let total: f64 = w.iter().map(|(_, x)| x).sum();
        let mut sum = [0.0; 2];
        for &(x, wx) in &w {
            let p = lookup(uv, x)?;
            sum = [sum[0] + wx * p[0], sum[1] + wx * p[1]];
        }
        (total > 0.0 && total.is_finite()).then(|| scale2(sum, 1.0 / total))
    })
}

fn scale2(p: Uv, s: f64) -> Uv {
    [p[0] * s, p[1] * s]
}
