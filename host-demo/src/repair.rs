//! Turning a triangle soup into a mesh the hierarchy builder accepts.
//!
//! [`repair`] promises a result that passes [`vdlod_core::build::validate`]: every edge in one
//! or two triangles, those two oriented consistently, every vertex's triangles one fan. It gets
//! there by changing as little as it can, in this order:
//!
//! 1. weld border vertices (on an edge of a single triangle) closer than [`WELD_TOLERANCE`] times
//!    the bounding-box diagonal, each to the first vertex of its cluster, so a chain of near
//!    points does not collapse into one. This closes the cracks of an STL soup or of an OBJ whose
//!    groups repeat their seam vertices, and never touches a surface that is already whole: two
//!    closed surfaces that happen to share a point stay two surfaces;
//! 2. drop triangles that then repeat a vertex, and triangles with the same three vertices as an
//!    earlier one (in either orientation). Triangles with three distinct but collinear corners
//!    stay: dropping one would open a crack, and the builder handles zero area;
//! 3. join two triangles across an edge only when that edge has exactly two triangles; orient each
//!    connected part consistently by walking across joined edges (keeping the orientation most
//!    of its triangles had), and cut the edge where a walk meets itself reversed (a Möbius band);
//! 4. give each fan of triangles around a vertex its own copy of the vertex, so surfaces that touch
//!    at a point or along a non-manifold edge come apart into a manifold with borders;
//! 5. turn each closed part outward (positive enclosed volume).
//!
//! Vertices no kept triangle uses are dropped. Everything is deterministic: ties go to the
//! earlier triangle or vertex of the input.

use std::collections::HashMap;
use std::fmt;

use crate::input::Soup;

/// Vertices closer than this fraction of the bounding-box diagonal are welded.
pub const WELD_TOLERANCE: f64 = 1e-6;

/// What [`repair`] changed, counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Repairs {
    /// Vertices welded into an earlier one.
    pub welded: usize,
    /// Triangles dropped because two of their corners are one vertex.
    pub degenerate: usize,
    /// Triangles dropped because an earlier one has the same vertices.
    pub duplicate: usize,
    /// Triangles whose orientation was reversed.
    pub flipped: usize,
    /// Edges cut apart: non-manifold ones, and where orientation could not agree.
    pub cut_edges: usize,
    /// Vertex copies added so each fan has its own vertex.
    pub split: usize,
    /// Vertices dropped because no kept triangle uses them.
    pub unused: usize,
}

impl Repairs {
    /// Whether nothing was changed.
    pub fn is_empty(&self) -> bool {
        *self == Repairs::default()
    }
}

impl fmt::Display for Repairs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let items = [
            (self.welded, "vertex", "vertices", "welded"),
            (
                self.degenerate,
                "degenerate triangle",
                "degenerate triangles",
                "dropped",
            ),
            (
                self.duplicate,
                "repeated triangle",
                "repeated triangles",
                "dropped",
            ),
            (self.flipped, "triangle", "triangles", "flipped"),
            (
                self.cut_edges,
                "non-manifold or unorientable edge",
                "non-manifold or unorientable edges",
                "cut",
            ),
            (self.split, "vertex", "vertices", "split"),
            (self.unused, "unused vertex", "unused vertices", "dropped"),
        ];
        let said: Vec<String> = items
            .iter()
            .filter(|item| item.0 > 0)
            .map(|&(n, one, many, done)| format!("{n} {} {done}", if n == 1 { one } else { many }))
            .collect();
        if said.is_empty() {
            f.write_str("nothing to repair")
        } else {
            f.write_str(&said.join(", "))
        }
    }
}

/// Repairs `soup` (see the module documentation); returns the mesh and what changed.
///
/// ```
/// use vdlod_demo::input::Soup;
/// // Two triangles of a square, the second listed clockwise and with its own copy of a corner.
/// let soup = Soup {
///     positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
///     colors: None,
///     triangles: vec![[0, 1, 2], [0, 3, 2]],
/// };
/// let (mesh, repairs) = vdlod_demo::repair::repair(soup);
/// assert_eq!(repairs.flipped, 1);
/// assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
/// ```
pub fn repair(soup: Soup) -> (Soup, Repairs) {
    let mut repairs = Repairs::default();
    let border = border_edges(&soup.triangles);
    let near = weld(
        &soup.positions,
        &on_border(soup.positions.len(), &soup.triangles, &border),
    );
    let representative = zipping(&near, &border);
    let welded = (0..representative.len())
        .filter(|&i| representative[i] != i as u32)
        .count();
    repairs.welded = welded;
    let mut triangles = Vec::with_capacity(soup.triangles.len());
    for t in &soup.triangles {
        let t = t.map(|i| representative[i as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            repairs.degenerate += 1;
        } else {
            triangles.push(t);
        }
    }
    let before = triangles.len();
    drop_repeated(&mut triangles);
    repairs.duplicate = before - triangles.len();

    let edges = EdgeGroups::new(&triangles);
    let mut joined = edges.joinable();
    repairs.cut_edges = edges.non_manifold;
    let flips = orient(&triangles, &edges, &mut joined, &mut repairs.cut_edges);
    for (t, &flip) in triangles.iter_mut().zip(&flips) {
        if flip {
            t.swap(1, 2);
        }
    }
    // Flipping moved edges between slots; the groups (sorted by their two vertices) keep their
    // numbers, so `joined` still applies.
    let edges = EdgeGroups::new(&triangles);

    // Split fans; cut more edges if two fans still share an output edge.
    let (mut out, mut copies) = split_fans(&triangles, &edges, &joined);
    loop {
        let bad = bad_output_edges(&out);
        if bad.is_empty() {
            break;
        }
        let before = joined.iter().filter(|&&j| j).count();
        for &(t, corner) in &bad {
            // Cut the joined edges of `t` at `corner`, in the input numbering.
            let v = triangles[t][corner];
            for k in 0..3 {
                let (a, b) = (triangles[t][k], triangles[t][(k + 1) % 3]);
                if a == v || b == v {
                    if let Some(g) = edges.group_of(t, k) {
                        joined[g] = false;
                    }
                }
            }
        }
        let cut = before - joined.iter().filter(|&&j| j).count();
        if cut == 0 {
            break;
        }
        repairs.cut_edges += cut;
        (out, copies) = split_fans(&triangles, &edges, &joined);
    }
    let used = copies
        .iter()
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    repairs.split = copies.len() - used;
    repairs.unused = soup.positions.len() - welded - used;

    let mut positions: Vec<[f32; 3]> = copies.iter().map(|&v| soup.positions[v as usize]).collect();
    let colors = soup
        .colors
        .as_ref()
        .map(|c| copies.iter().map(|&v| c[v as usize]).collect());
    let outward = turn_outward(&positions, &mut out);
    repairs.flipped = flips.iter().zip(&outward).filter(|(a, b)| *a != *b).count();
    positions.shrink_to_fit();
    (
        Soup {
            positions,
            colors,
            triangles: out,
        },
        repairs,
    )
}

/// The edges that only one triangle has, as (low, high) vertex pairs, sorted.
fn border_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let edges = EdgeGroups::new(triangles);
    (0..edges.count())
        .filter_map(|g| match edges.members(g) {
            &[(t, k)] => {
                let (a, b) = (triangles[t][k], triangles[t][(k + 1) % 3]);
                Some((a.min(b), a.max(b)))
            }
            _ => None,
        })
        .collect()
}

/// Whether each vertex is on a border (an end of a border edge) or unused.
fn on_border(vertices: usize, triangles: &[[u32; 3]], border: &[(u32, u32)]) -> Vec<bool> {
    let mut on = vec![true; vertices];
    for &i in triangles.iter().flatten() {
        on[i as usize] = false;
    }
    for &(a, b) in border {
        on[a as usize] = true;
        on[b as usize] = true;
    }
    on
}

/// `near` restricted to the welds that close a crack: a vertex is welded only when one of its
/// `border` edges then coincides with another border edge. Border vertices that merely lie close
/// together (the two lips of a slit, a hole's rim pinched to a point) stay apart.
fn zipping(near: &[u32], border: &[(u32, u32)]) -> Vec<u32> {
    // Border edges keyed by their welded ends.
    let mut welded: Vec<((u32, u32), (u32, u32))> = border
        .iter()
        .map(|&(a, b)| {
            let (x, y) = (near[a as usize], near[b as usize]);
            ((x.min(y), x.max(y)), (a, b))
        })
        .collect();
    welded.sort_unstable();
    let mut zips = vec![false; near.len()];
    for run in welded
        .chunk_by(|p, q| p.0 == q.0)
        .filter(|run| run.len() > 1)
    {
        for &(_, (a, b)) in run {
            zips[a as usize] = true;
            zips[b as usize] = true;
        }
    }
    (0..near.len())
        .map(|v| if zips[v] { near[v] } else { v as u32 })
        .collect()
}

/// The vertex each vertex is near enough to weld to; only `border` vertices weld.
fn weld(positions: &[[f32; 3]], border: &[bool]) -> Vec<u32> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a] as f64);
            hi[a] = hi[a].max(p[a] as f64);
        }
    }
    let square = |x: f64| x * x;
    let diagonal = libm::sqrt((0..3).map(|a| square(hi[a] - lo[a])).sum::<f64>());
    let tolerance = diagonal * WELD_TOLERANCE;
    let mut representative = Vec::with_capacity(positions.len());
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        // A single point (or nothing): exact matches only.
        let mut seen: HashMap<[u32; 3], u32> = HashMap::new();
        for (i, p) in positions.iter().enumerate() {
            if !border[i] {
                representative.push(i as u32);
                continue;
            }
            let key = p.map(|c| (c + 0.0).to_bits());
            representative.push(*seen.entry(key).or_insert(i as u32));
        }
        return representative;
    }
    let cell = |p: &[f32; 3]| -> [i64; 3] {
        std::array::from_fn(|a| libm::floor((p[a] as f64 - lo[a]) / tolerance) as i64)
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, p) in positions.iter().enumerate() {
        if !border[i] {
            representative.push(i as u32);
            continue;
        }
        let c = cell(p);
        let mut best: Option<u32> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &r in list {
                        let q = positions[r as usize];
                        let d2: f64 = (0..3).map(|a| square(p[a] as f64 - q[a] as f64)).sum();
                        if d2 <= tolerance * tolerance && best.is_none_or(|b| r < b) {
                            best = Some(r);
                        }
                    }
                }
            }
        }
        match best {
            Some(r) => representative.push(r),
            None => {
                grid.entry(c).or_default().push(i as u32);
                representative.push(i as u32);
            }
        }
    }
    representative
}

/// Drops triangles with the same vertices as an earlier one, keeping the order.
fn drop_repeated(triangles: &mut Vec<[u32; 3]>) {
    let mut keyed: Vec<([u32; 3], usize)> = triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mut k = *t;
            k.sort_unstable();
            (k, i)
        })
        .collect();
    keyed.sort_unstable();
    let mut keep = vec![true; triangles.len()];
    for w in keyed.windows(2) {
        if w[0].0 == w[1].0 {
            keep[w[1].1] = false;
        }
    }
    let mut i = 0;
    triangles.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

/// The triangles' edges grouped by their two vertices.
struct EdgeGroups {
    /// `(triangle, slot)` pairs, grouped: slot `k` is the edge from corner `k` to `k + 1`.
    sides: Vec<(usize, usize)>,
    /// Start of each group in `sides` (and one past the end).
    starts: Vec<usize>,
    /// The group of each triangle's three edges.
    group: Vec<[u32; 3]>,
    /// Groups with more than two triangles.
    non_manifold: usize,
}

impl EdgeGroups {
    fn new(triangles: &[[u32; 3]]) -> EdgeGroups {
        let keyed = Self::sorted(triangles);
        let mut sides = Vec::with_capacity(keyed.len());
        let mut starts = Vec::new();
        let mut group = vec![[0u32; 3]; triangles.len()];
        let mut non_manifold = 0;
        for run in keyed.chunk_by(|p, q| p.0 == q.0) {
            let g = starts.len() as u32;
            starts.push(sides.len());
            non_manifold += usize::from(run.len() > 2);
            for &(_, t, k) in run {
                group[t][k] = g;
                sides.push((t, k));
            }
        }
        starts.push(sides.len());
        EdgeGroups {
            sides,
            starts,
            group,
            non_manifold,
        }
    }

    /// Every triangle's edges as `((low, high), triangle, slot)`, in that order: counted out by
    /// their low vertex (in triangle and slot order), then each low vertex's run sorted stably
    /// by the high one. A comparison sort of all of them, which a mesh's repair needs five
    /// times, took most of the time of loading one; it remains for vertex numbers far beyond
    /// the edge count, which a count would have to span.
    fn sorted(triangles: &[[u32; 3]]) -> Vec<((u32, u32), usize, usize)> {
        let edges = triangles.iter().enumerate().flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                ((a.min(b), a.max(b)), t, k)
            })
        });
        let span = triangles
            .iter()
            .flatten()
            .max()
            .map_or(0, |&m| m as usize + 1);
        if span > 4 * triangles.len() + 1024 {
            let mut keyed: Vec<_> = edges.collect();
            keyed.sort_unstable();
            return keyed;
        }
        let mut starts = vec![0usize; span + 1];
        for ((low, _), _, _) in edges.clone() {
            starts[low as usize + 1] += 1;
        }
        for v in 1..starts.len() {
            starts[v] += starts[v - 1];
        }
        let mut keyed = vec![((0, 0), 0, 0); 3 * triangles.len()];
        let mut next = starts.clone();
        for edge in edges {
            let low = edge.0 .0 as usize;
            keyed[next[low]] = edge;
            next[low] += 1;
        }
        for run in starts.windows(2) {
            keyed[run[0]..run[1]].sort_by_key(|e| e.0 .1);
        }
        keyed
    }

    /// How many edges (groups) there are.
    fn count(&self) -> usize {
        self.starts.len() - 1
    }

    fn members(&self, g: usize) -> &[(usize, usize)] {
        &self.sides[self.starts[g]..self.starts[g + 1]]
    }

    /// Groups of exactly two triangles: the edges that may join them.
    fn joinable(&self) -> Vec<bool> {
        (0..self.count())
            .map(|g| self.members(g).len() == 2)
            .collect()
    }

    fn group_of(&self, t: usize, k: usize) -> Option<usize> {
        self.group.get(t).map(|g| g[k] as usize)
    }

    /// The other triangle across a joined edge.
    fn across(&self, g: usize, t: usize) -> (usize, usize) {
        let m = self.members(g);
        if m[0].0 == t {
            m[1]
        } else {
            m[0]
        }
    }
}

/// Whether each triangle must be flipped so that joined neighbours agree; cuts the joined edges
/// where they cannot.
fn orient(
    triangles: &[[u32; 3]],
    edges: &EdgeGroups,
    joined: &mut [bool],
    cut: &mut usize,
) -> Vec<bool> {
    let n = triangles.len();
    let mut flip = vec![false; n];
    let mut seen = vec![false; n];
    let mut part = Vec::new();
    let forward = |t: usize, k: usize| triangles[t][k] < triangles[t][(k + 1) % 3];
    for root in 0..n {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        part.clear();
        part.push(root);
        let mut next = 0;
        while next < part.len() {
            let t = part[next];
            next += 1;
            for k in 0..3 {
                let g = edges.group[t][k] as usize;
                if !joined[g] {
                    continue;
                }
                let (u, j) = edges.across(g, t);
                // Consistent when the shared edge runs opposite ways after flipping.
                let want = forward(t, k) ^ flip[t] ^ forward(u, j) ^ true;
                if !seen[u] {
                    seen[u] = true;
                    flip[u] = want;
                    part.push(u);
                } else if flip[u] != want {
                    joined[g] = false;
                    *cut += 1;
                }
            }
        }
        // Keep the orientation most of the part had.
        let flipped = part.iter().filter(|&&t| flip[t]).count();
        if 2 * flipped > part.len() {
            for &t in &part {
                flip[t] = !flip[t];
            }
        }
    }
    flip
}

/// Union-find over triangle corners.
struct Corners(Vec<u32>);

impl Corners {
    fn find(&mut self, mut c: usize) -> usize {
        while self.0[c] as usize != c {
            let up = self.0[c] as usize;
            self.0[c] = self.0[up];
            c = up;
        }
        c
    }

    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            let (lo, hi) = (a.min(b), a.max(b));
            self.0[hi] = lo as u32;
        }
    }
}

/// Triangles over vertex copies (one per fan of joined triangles around each vertex), and the
/// input vertex of each copy.
fn split_fans(
    triangles: &[[u32; 3]],
    edges: &EdgeGroups,
    joined: &[bool],
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut corners = Corners((0..3 * triangles.len() as u32).collect());
    let corner_of =
        |t: usize, v: u32| 3 * t + triangles[t].iter().position(|&x| x == v).unwrap_or(0);
    for (g, &is_joined) in joined.iter().enumerate() {
        if !is_joined {
            continue;
        }
        let m = edges.members(g);
        let ((t, k), (u, _)) = (m[0], m[1]);
        for v in [triangles[t][k], triangles[t][(k + 1) % 3]] {
            corners.union(corner_of(t, v), corner_of(u, v));
        }
    }
    let mut copy_of_class: HashMap<usize, u32> = HashMap::new();
    let mut copies = Vec::new();
    let out: Vec<[u32; 3]> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            std::array::from_fn(|k| {
                let class = corners.find(3 * t + k);
                *copy_of_class.entry(class).or_insert_with(|| {
                    copies.push(tri[k]);
                    (copies.len() - 1) as u32
                })
            })
        })
        .collect();
    // Number the copies in the order of the vertices they copy, so that a mesh with nothing to
    // split keeps its numbering.
    let mut order: Vec<u32> = (0..copies.len() as u32).collect();
    order.sort_by_key(|&c| copies[c as usize]);
    let mut new_id = vec![0u32; copies.len()];
    for (id, &c) in order.iter().enumerate() {
        new_id[c as usize] = id as u32;
    }
    let copies = order.iter().map(|&c| copies[c as usize]).collect();
    let out = out.iter().map(|t| t.map(|c| new_id[c as usize])).collect();
    (out, copies)
}

/// `(triangle, corner)` pairs at the ends of output edges that are still not manifold (more than
/// two triangles, or two running the same way).
fn bad_output_edges(triangles: &[[u32; 3]]) -> Vec<(usize, usize)> {
    let edges = EdgeGroups::new(triangles);
    let forward = |(t, k): (usize, usize)| triangles[t][k] < triangles[t][(k + 1) % 3];
    let mut bad = Vec::new();
    for g in 0..edges.count() {
        let run = edges.members(g);
        let manifold = run.len() == 1 || (run.len() == 2 && forward(run[0]) != forward(run[1]));
        if !manifold {
            for &(t, k) in run {
                bad.push((t, k));
                bad.push((t, (k + 1) % 3));
            }
        }
    }
    bad
}

/// Flips every closed connected part whose enclosed volume is negative; returns, per triangle,
/// whether it was flipped.
fn turn_outward(positions: &[[f32; 3]], triangles: &mut [[u32; 3]]) -> Vec<bool> {
    let n = triangles.len();
    let edges = EdgeGroups::new(triangles);
    let mut stack = Vec::new();
    let mut flipped = vec![false; n];
    let mut seen = vec![false; n];
    for root in 0..n {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        stack.clear();
        stack.push(root);
        let mut members = Vec::new();
        let mut closed = true;
        while let Some(t) = stack.pop() {
            members.push(t);
            for k in 0..3 {
                let g = edges.group[t][k] as usize;
                if edges.members(g).len() != 2 {
                    closed = false;
                    continue;
                }
                let (u, _) = edges.across(g, t);
                if !seen[u] {
                    seen[u] = true;
                    stack.push(u);
                }
            }
        }
        if !closed {
            continue;
        }
        let p = |i: u32| positions[i as usize].map(f64::from);
        let volume: f64 = members
            .iter()
            .map(|&t| {
                let [a, b, c] = triangles[t].map(p);
                a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0])
            })
            .sum();
        if volume < 0.0 {
            for &t in &members {
                triangles[t].swap(1, 2);
                flipped[t] = true;
            }
        }
    }
    flipped
}

#[cfg(test)]
mod tests {
    use super::EdgeGroups;
    use proptest::prelude::*;

    proptest! {
        /// The counted order is the order of a comparison sort of `((low, high), t, k)`, for
        /// small vertex numbers (counted) and large ones (sorted), repeated edges included.
        #[test]
        fn edges_are_counted_into_the_sorted_order(
            triangles in prop::collection::vec(prop::array::uniform3(0u32..40), 0..60),
            far in any::<bool>(),
        ) {
            let triangles: Vec<[u32; 3]> = triangles
                .into_iter()
                .map(|t| if far { t.map(|v| v * 100_000_000) } else { t })
                .collect();
            let mut expected = Vec::new();
            for (t, tri) in triangles.iter().enumerate() {
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    expected.push(((a.min(b), a.max(b)), t, k));
                }
            }
            expected.sort_unstable();
            prop_assert_eq!(EdgeGroups::sorted(&triangles), expected);
        }
    }
}
