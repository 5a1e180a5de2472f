//! The connectivity of every level of a semi-regular mesh, computed from its base mesh.
//!
//! A point of `K^J` is named in the frame of a base face by its barycentric weights in units of
//! `1/N` (`N = 2^J`): three integers that sum to `N`. The lattice has three edge directions, and
//! every level's vertices, edges and triangles are lattice points, segments and triangles at a
//! step of `N / 2^j`, so parents, children, midpoints and the triangle across an edge are a few
//! integer additions. A point just across an edge of its face (one negative weight) is the same
//! point of the neighbouring face, unfolded into this face's plane; [`SemiRegularView::canonical`]
//! carries it over. Nothing here allocates or reads more than the base faces.

use super::format::SemiRegularView;

/// A point of the finest lattice in the frame of base face `face`: the weights of the face's
/// corners in units of `1/N`, summing to `N`. One weight may be negative for a point across an
/// edge (see [`SemiRegularView::canonical`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Point {
    /// The base face whose frame the weights are in.
    pub face: u32,
    /// The weights of the face's corners.
    pub w: [i32; 3],
}

/// The six lattice directions, as weight changes.
pub const DIRECTIONS: [[i32; 3]; 6] = [
    [-1, 1, 0],
    [0, -1, 1],
    [1, 0, -1],
    [1, -1, 0],
    [0, 1, -1],
    [-1, 0, 1],
];

impl Point {
    /// This point moved by `k` steps of direction `d`.
    #[inline]
    #[must_use]
    pub fn offset(self, d: [i32; 3], k: i32) -> Point {
        Point {
            face: self.face,
            w: [
                self.w[0] + k * d[0],
                self.w[1] + k * d[1],
                self.w[2] + k * d[2],
            ],
        }
    }

    /// The midpoint of `self` and `q` (same frame; exact when the sums are even).
    #[inline]
    #[must_use]
    pub fn mid(self, q: Point) -> Point {
        Point {
            face: self.face,
            w: [
                (self.w[0] + q.w[0]) >> 1,
                (self.w[1] + q.w[1]) >> 1,
                (self.w[2] + q.w[2]) >> 1,
            ],
        }
    }

    /// `q - self` as a weight change.
    #[inline]
    #[must_use]
    pub fn to(self, q: Point) -> [i32; 3] {
        [q.w[0] - self.w[0], q.w[1] - self.w[1], q.w[2] - self.w[2]]
    }

    /// The third corner of the lattice triangle on the left of `self -> q` (counter-clockwise
    /// `self, q, corner`).
    #[inline]
    #[must_use]
    pub fn left_of(self, q: Point) -> Point {
        self.offset(rot60(self.to(q)), 1)
    }

    /// The third corner of the lattice triangle on the right of `self -> q` (counter-clockwise
    /// `q, self, corner`).
    #[inline]
    #[must_use]
    pub fn right_of(self, q: Point) -> Point {
        q.offset(rot60(self.to(q)), -1)
    }
}

/// A weight change turned a sixth of a turn counter-clockwise.
#[inline]
#[must_use]
pub fn rot60(d: [i32; 3]) -> [i32; 3] {
    [-d[1], -d[2], -d[0]]
}

/// The lattice distance of a weight change (steps along the three directions).
#[inline]
#[must_use]
pub fn hex_len(d: [i32; 3]) -> i32 {
    d[0].abs().max(d[1].abs()).max(d[2].abs())
}

/// What a lattice point is in the base mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Site {
    /// Corner `k` of its face.
    Corner(usize),
    /// On edge `k` of its face, `t` steps from corner `k`.
    Edge(usize, i32),
    /// Inside its face.
    Inner,
}

impl SemiRegularView<'_> {
    /// `N = 2^J`, the finest steps per base edge.
    #[inline]
    #[must_use]
    pub fn steps(&self) -> i32 {
        self.n
    }

    /// The lattice step of level `level` (`N / 2^level`).
    #[inline]
    #[must_use]
    pub fn step_of(&self, level: u32) -> i32 {
        self.n >> level.min(31)
    }

    /// `p` in the frame of the face it lies in: a point across one edge of its face (one
    /// negative weight) moves into the face across that edge; `None` across a border, for
    /// points that are not one face away, and for weights that do not sum to `N`.
    #[inline]
    #[must_use]
    pub fn canonical(&self, p: Point) -> Option<Point> {
        self.canonical_scaled(p, self.n)
    }

    /// [`SemiRegularView::canonical`] of weights that sum to `total` rather than `N` (the
    /// unfolding is linear): three times a triangle's centroid names the triangle.
    #[inline]
    #[must_use]
    pub(super) fn canonical_scaled(&self, p: Point, total: i32) -> Option<Point> {
        let w = p.w;
        let sum = i64::from(w[0]) + i64::from(w[1]) + i64::from(w[2]);
        if w[0] >= 0 && w[1] >= 0 && w[2] >= 0 && sum == i64::from(total) {
            return Some(p);
        }
        self.unfold(p, total)
    }

    /// [`SemiRegularView::canonical_scaled`] of a point outside its face's frame.
    #[inline]
    fn unfold(&self, p: Point, total: i32) -> Option<Point> {
        let w = p.w;
        if w[0].checked_add(w[1])?.checked_add(w[2])? != total {
            return None;
        }
        for k in 0..3 {
            let opp = (k + 2) % 3;
            if w[opp] >= 0 {
                continue;
            }
            let (g, kk) = self.across(p.face, k)?;
            // In the across face: its corner kk is this face's corner k + 1, its corner kk + 1
            // is corner k, and its third corner is the unfolded point corner k + corner k + 1 -
            // corner k + 2.
            let ua = w[(k + 1) % 3] + w[opp];
            let ub = w[k] + w[opp];
            if ua < 0 || ub < 0 {
                return None;
            }
            let mut q = [0; 3];
            q[kk] = ua;
            q[(kk + 1) % 3] = ub;
            q[(kk + 2) % 3] = -w[opp];
            return Some(Point { face: g, w: q });
        }
        Some(p)
    }

    /// Where canonical point `p` lies in its face.
    #[inline]
    #[must_use]
    pub fn site(&self, p: Point) -> Site {
        let w = p.w;
        if let Some(k) = w.iter().position(|&x| x == self.n) {
            return Site::Corner(k);
        }
        for k in 0..3 {
            if w[(k + 2) % 3] == 0 {
                return Site::Edge(k, w[(k + 1) % 3]);
            }
        }
        Site::Inner
    }

    /// The level of canonical point `p`: 0 for a base vertex, else the first subdivision that
    /// makes it.
    #[inline]
    #[must_use]
    pub fn level(&self, p: Point) -> u32 {
        let tz = |x: i32| if x == 0 { 32 } else { x.trailing_zeros() };
        let t = tz(p.w[0]).min(tz(p.w[1])).min(tz(p.w[2]));
        self.counts.levels.saturating_sub(t)
    }

    /// The vertex id of canonical point `p` (see [`super::format`]); `None` for weights out of
    /// range.
    #[inline]
    #[must_use]
    pub fn vertex_id(&self, p: Point) -> Option<u32> {
        self.id_on_grid(p, self.n, self.first_inner, self.inner)
    }

    /// The id canonical point `p` would have in the mesh of the same base with `n` steps per
    /// base edge (a power of two, at most `N`): what a height field's coarse bounds are indexed
    /// by (see [`super::heights`]).
    #[must_use]
    pub(super) fn vertex_id_in(&self, p: Point, n: i32) -> Option<u32> {
        if n < 1 || n > self.n {
            return None;
        }
        let steps = n as u32;
        let first_inner = self.counts.base_vertices + self.counts.base_edges * (steps - 1);
        let inner = (steps - 1) * steps.saturating_sub(2) / 2;
        self.id_on_grid(p, n, first_inner, inner)
    }

    /// The id of `p` on the grid of `n` steps per base edge whose first point inside a face has
    /// id `first_inner` and whose faces hold `inner` points each.
    #[inline]
    fn id_on_grid(&self, p: Point, n: i32, first_inner: u32, inner: u32) -> Option<u32> {
        let [w0, w1, w2] = p.w;
        if w0 < 0 || w1 < 0 || w2 < 0 || w0 > n || w1 > n || w2 > n {
            return None;
        }
        if p.face >= self.counts.base_faces {
            return None;
        }
        let steps = n as u32;
        if w0 != 0 && w1 != 0 && w2 != 0 {
            // Inside the face: rows of increasing j, then i.
            let (i, j) = (w1 as u32, w2 as u32);
            let row = (j - 1) * (steps - 1) - (j - 1) * j / 2;
            return Some(first_inner + p.face * inner + row + i - 1);
        }
        if let Some(k) = p.w.iter().position(|&x| x == n) {
            return Some(self.corners(p.face)[k]);
        }
        // On edge `k`, `t` steps from corner `k`.
        let k = (0..3).find(|&k| p.w[(k + 2) % 3] == 0)?;
        let t = p.w[(k + 1) % 3];
        let ([a, b], e) = self.edge_of(p.face, k);
        let t = if a < b { t } else { n - t };
        Some(self.counts.base_vertices + e * (steps - 1) + t as u32 - 1)
    }

    /// The canonical point of vertex `v` when it is a wavelet (not a base vertex).
    #[must_use]
    pub fn point(&self, v: u32) -> Option<Point> {
        let n = self.n as u32;
        let r = v.checked_sub(self.counts.base_vertices)?;
        let on_edges = self.counts.base_edges * (n - 1);
        if r < on_edges {
            let (e, t) = (r / (n - 1), (r % (n - 1) + 1) as i32);
            let (f, k) = self.edge_side(e);
            let c = self.corners(f);
            let t = if c[k] < c[(k + 1) % 3] {
                t
            } else {
                n as i32 - t
            };
            let mut w = [0; 3];
            w[k] = n as i32 - t;
            w[(k + 1) % 3] = t;
            return Some(Point { face: f, w });
        }
        let r = r - on_edges;
        let inner = self.counts.inner_points() as u32;
        if inner == 0 || v >= self.vertices {
            return None;
        }
        let (face, idx) = (r / inner, r % inner);
        // Row u = j - 1 starts at u (2N - 3 - u) / 2: solve for the last start <= idx.
        let m = 2.0 * n as f64 - 3.0;
        let disc = crate::root::sqrt((m * m - 8.0 * idx as f64).max(0.0));
        let mut u = ((m - disc) / 2.0) as u32;
        let start = |u: u32| u * (2 * n - 3 - u) / 2;
        while u > 0 && start(u) > idx {
            u -= 1;
        }
        while u + 1 < n - 2 && start(u + 1) <= idx {
            u += 1;
        }
        let (j, i) = (u + 1, idx - start(u) + 1);
        Some(Point {
            face,
            w: [(n - i - j) as i32, i as i32, j as i32],
        })
    }

    /// The ends of the parent edge of canonical point `p` at level `level >= 1` (the edge of
    /// `K^(level-1)` whose midpoint it is), in `p`'s frame (always inside the face).
    #[inline]
    #[must_use]
    pub fn parent_edge(&self, p: Point, level: u32) -> [Point; 2] {
        let s = self.step_of(level);
        let odd = |k: usize| (p.w[k] / s) & 1 == 1;
        let (a, b) = if !odd(0) {
            (1, 2)
        } else if !odd(1) {
            (0, 2)
        } else {
            (0, 1)
        };
        let mut d = [0; 3];
        d[a] = 1;
        d[b] = -1;
        [p.offset(d, s), p.offset(d, -s)]
    }

    /// The ids of wavelet `p`'s parents (at level `level >= 1`): the ends of its parent edge
    /// that are wavelets of the level above; `u32::MAX` for none.
    #[inline]
    #[must_use]
    pub fn parents(&self, p: Point, level: u32) -> [u32; 2] {
        self.parent_edge(p, level).map(|q| {
            if level >= 2 && self.level(q) == level - 1 {
                self.vertex_id(q).unwrap_or(u32::MAX)
            } else {
                u32::MAX
            }
        })
    }

    /// The canonical points of wavelet `p`'s children (at level `level < J`): the midpoints of
    /// the level's edges around it, six inside the mesh, four on a border.
    #[inline]
    #[must_use]
    pub fn children(&self, p: Point, level: u32) -> [Option<Point>; 6] {
        if level >= self.counts.levels {
            return [None; 6];
        }
        let h = self.step_of(level + 1);
        DIRECTIONS.map(|d| self.canonical(p.offset(d, h)))
    }

    /// Whether the triangle `a, b, c` (counter-clockwise, one frame) is a triangle of the mesh
    /// that the included set `included` subdivides: it exists (its corners are points of the
    /// mesh) and one of its edge midpoints is included.
    #[inline]
    #[must_use]
    pub fn subdivided(&self, a: Point, b: Point, c: Point, included: impl Fn(u32) -> bool) -> bool {
        if self.canonical(c).is_none() || self.canonical(a).is_none() {
            return false;
        }
        [a.mid(b), b.mid(c), c.mid(a)].iter().any(|&m| {
            self.canonical(m)
                .and_then(|m| self.vertex_id(m))
                .is_some_and(&included)
        })
    }
}
