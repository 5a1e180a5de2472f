//! Checking a mesh before it is simplified.
//!
//! The builder needs an oriented 2-manifold, possibly with boundaries: every edge in one or two
//! triangles (in opposite directions when two), every vertex's triangles forming one fan, no NaN
//! or infinite coordinate, no triangle repeating a vertex, no triangle listed twice. Anything else
//! is reported as a [`BuildError`] naming the first offender. Vertices used by no triangle are
//! accepted (documented repair): they become roots of their own and never collapse.

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use super::around::Around;

/// An indexed triangle mesh to build a hierarchy from.
#[derive(Clone, Copy, Debug, Default)]
pub struct InputMesh<'a> {
    /// Vertex positions.
    pub positions: &'a [[f32; 3]],
    /// Optional per-vertex colours (needed by the colour-aware cost).
    pub colors: Option<&'a [[u8; 3]]>,
    /// Triangles, counter-clockwise seen from the front.
    pub triangles: &'a [[u32; 3]],
}

/// Why a mesh cannot be built into a hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildError {
    /// No triangles.
    Empty,
    /// More vertices or triangles than the format can address (2^31).
    TooLarge,
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// The vertex.
        vertex: u32,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle.
        triangle: u32,
        /// Its offending index.
        index: u32,
    },
    /// A triangle uses the same vertex twice.
    DegenerateTriangle {
        /// The triangle.
        triangle: u32,
    },
    /// A triangle has the same three vertices as an earlier one.
    DuplicateTriangle {
        /// The later triangle.
        triangle: u32,
        /// The earlier one.
        first: u32,
    },
    /// An edge belongs to more than two triangles.
    NonManifoldEdge {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// Two triangles share an edge in the same direction: their orientations disagree.
    InconsistentOrientation {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// A vertex's triangles form more than one fan (two surfaces touching at a point).
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
    },
    /// The colour array's length differs from the vertex count.
    ColorLength {
        /// Vertex count.
        expected: u32,
        /// Colour count.
        actual: u32,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BuildError::Empty => write!(f, "the mesh has no triangles"),
            BuildError::TooLarge => write!(f, "the mesh has more than 2^31 vertices or triangles"),
            BuildError::NonFinite { vertex } => {
                write!(f, "vertex {vertex} has a NaN or infinite coordinate")
            }
            BuildError::IndexOutOfRange { triangle, index } => {
                write!(
                    f,
                    "triangle {triangle} uses vertex {index}, which does not exist"
                )
            }
            BuildError::DegenerateTriangle { triangle } => {
                write!(f, "triangle {triangle} uses a vertex twice")
            }
            BuildError::DuplicateTriangle { triangle, first } => {
                write!(f, "triangle {triangle} repeats triangle {first}")
            }
            BuildError::NonManifoldEdge { a, b } => {
                write!(
                    f,
                    "edge {a}-{b} belongs to more than two triangles (non-manifold)"
                )
            }
            BuildError::InconsistentOrientation { a, b } => write!(
                f,
                "the two triangles on edge {a}-{b} are oriented inconsistently"
            ),
            BuildError::NonManifoldVertex { vertex } => write!(
                f,
                "vertex {vertex} joins surfaces that touch only there (non-manifold)"
            ),
            BuildError::ColorLength { expected, actual } => {
                write!(f, "{actual} colours for {expected} vertices")
            }
        }
    }
}

impl core::error::Error for BuildError {}

/// Checks `mesh`; on success every edge is in one or two consistently oriented triangles and every
/// vertex's triangles form a single fan.
pub fn validate(mesh: &InputMesh<'_>) -> Result<(), BuildError> {
    checked(mesh).map(|_| ())
}

/// Which vertices lie on a border (an endpoint of an edge that one triangle uses), a bit each:
/// the builder keeps them through its collapses.
pub(crate) struct Borders(Vec<u64>);

impl Borders {
    /// None of `n` vertices.
    pub(crate) fn new(n: usize) -> Borders {
        Borders(vec![0; n.div_ceil(64)])
    }

    /// Marks vertex `v` (nothing for one out of range).
    pub(crate) fn insert(&mut self, v: u32) {
        if let Some(w) = self.0.get_mut(v as usize / 64) {
            *w |= 1 << (v % 64);
        }
    }

    /// Whether vertex `v` is on a border (false for anything out of range).
    pub fn contains(&self, v: u32) -> bool {
        self.0
            .get(v as usize / 64)
            .is_some_and(|w| w >> (v % 64) & 1 != 0)
    }

    /// The members in `start..end`, ascending: a word read per 64 vertices, so that a range with
    /// none (an inner region of the mesh) costs next to nothing.
    pub(crate) fn within(&self, start: u32, end: u32) -> impl Iterator<Item = u32> + '_ {
        let (start, end) = (start as usize, end as usize);
        (start / 64..end.div_ceil(64)).flat_map(move |w| {
            let first = w * 64;
            // The word's bits from `start` on and before `end`.
            let from = !0u64 << (start.max(first) - first);
            let before = match end - first {
                k if k < 64 => (1u64 << k) - 1,
                _ => !0,
            };
            let mut bits = self.0.get(w).map_or(0, |&b| b & from & before);
            core::iter::from_fn(move || {
                let bit = (bits != 0).then(|| bits.trailing_zeros())?;
                bits &= bits - 1;
                Some((first as u32) + bit)
            })
        })
    }
}

/// [`validate`], and on success which vertices lie on a border, which the checks find on the
/// way and the builder needs after.
pub(crate) fn checked(mesh: &InputMesh<'_>) -> Result<Borders, BuildError> {
    let n = mesh.positions.len();
    if mesh.triangles.is_empty() {
        return Err(BuildError::Empty);
    }
    if n >= 1 << 31 || mesh.triangles.len() >= 1 << 30 {
        return Err(BuildError::TooLarge);
    }
    if let Some(c) = mesh.colors {
        if c.len() != n {
            return Err(BuildError::ColorLength {
                expected: n as u32,
                actual: c.len().min(u32::MAX as usize) as u32,
            });
        }
    }
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(BuildError::NonFinite { vertex: v as u32 });
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(BuildError::IndexOutOfRange {
                triangle: t as u32,
                index,
            });
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(BuildError::DegenerateTriangle { triangle: t as u32 });
        }
    }

    // Every check reads one table: for each vertex `v`, the link edges `x -> y` of its
    // triangles `(v, x, y)`, with the triangle's index. Each check walks the whole table
    // before the next starts, so the first offender is the one the order of the checks names.
    let around = link_edges(n, mesh.triangles);
    let mut scratch: Vec<(u32, u32, u32)> = Vec::new();

    // Duplicates: a triangle is filed under its smallest corner; equal corner sets are then
    // neighbours once that vertex's triangles are sorted by their other two corners.
    for v in 0..n as u32 {
        scratch.clear();
        scratch.extend(
            around
                .of(v)
                .iter()
                .filter(|e| e.0 > v && e.1 > v)
                .map(|&(x, y, t)| (x.min(y), x.max(y), t)),
        );
        scratch.sort_unstable();
        if let Some(w) = scratch
            .windows(2)
            .find(|w| (w[0].0, w[0].1) == (w[1].0, w[1].1))
        {
            return Err(BuildError::DuplicateTriangle {
                triangle: w[1].2,
                first: w[0].2,
            });
        }
    }

    // Edges, by their lower end `v`: the triangles `(v, x, y)` hold `v -> x` and `y -> v`; an
    // edge must be in one triangle (a border) or in two, once in each direction. Each end `b`
    // is kept as `2 b + 1` leaving `v`, `2 b` entering it: plain integers sort cheaper than
    // pairs, in the same order (the ends are below 2^31).
    let mut on_border = Borders::new(n);
    let mut ends: Vec<u32> = Vec::new();
    for v in 0..n as u32 {
        ends.clear();
        for &(x, y, _) in around.of(v) {
            if x > v {
                ends.push(2 * x + 1);
            }
            if y > v {
                ends.push(2 * y);
            }
        }
        ends.sort_unstable();
        let mut i = 0;
        while i < ends.len() {
            let b = ends[i] / 2;
            let mut j = i + 1;
            while j < ends.len() && ends[j] / 2 == b {
                j += 1;
            }
            match j - i {
                1 => {
                    on_border.insert(v);
                    on_border.insert(b);
                }
                2 if ends[i] != ends[i + 1] => {}
                2 => return Err(BuildError::InconsistentOrientation { a: v, b }),
                _ => return Err(BuildError::NonManifoldEdge { a: v, b }),
            }
            i = j;
        }
    }

    // Fans: around each vertex, the link edges must form one chain.
    for v in 0..n as u32 {
        let link = around.of(v);
        if !link.is_empty() && !single_fan(link) {
            return Err(BuildError::NonManifoldVertex { vertex: v });
        }
    }
    Ok(on_border)
}

/// Links up to this long stay in triangle order and are searched one edge after another (a
/// vertex has six or so: cheaper than sorting them); longer ones, a pole's, are sorted by `x` and
/// searched by halves, so that a vertex of many triangles costs no square of them.
const SHORT_LINK: usize = 16;

/// For each vertex `v`, the link edges `(x, y, t)` of the triangles `t = (v, x, y)` around it:
/// in triangle order, or sorted by `x` when longer than [`SHORT_LINK`].
fn link_edges(n: usize, triangles: &[[u32; 3]]) -> Around<(u32, u32, u32)> {
    let mut around = Around::filed(n, triangles, |t, k| {
        let tri = triangles[t as usize];
        (tri[(k + 1) % 3], tri[(k + 2) % 3], t)
    });
    for v in 0..n as u32 {
        let link = around.of_mut(v);
        if link.len() > SHORT_LINK {
            link.sort_unstable_by_key(|e| e.0);
        }
    }
    around
}

/// Whether the link edges `(x, y, _)` of one vertex (as [`link_edges`] orders them) form a
/// single path or cycle. They come from manifold, consistently oriented edges, so each `x`
/// starts one link edge and each `y` ends one: the edges form paths and cycles, and the one
/// through the first edge must hold them all (whichever edge is first). Walked forwards from
/// there (a cycle closes; most vertices are inside the surface), then, when a path's end stopped
/// the walk, backwards to its start.
fn single_fan(link: &[(u32, u32, u32)]) -> bool {
    let next = |x: u32| {
        if link.len() > SHORT_LINK {
            link.binary_search_by_key(&x, |e| e.0)
                .ok()
                .map(|k| link[k].1)
        } else {
            link.iter().find(|e| e.0 == x).map(|e| e.1)
        }
    };
    let start = link[0].0;
    let mut steps = 0;
    let mut x = start;
    while let Some(y) = next(x) {
        steps += 1;
        if y == start || steps > link.len() {
            return steps == link.len();
        }
        x = y;
    }
    let mut y = start;
    while let Some(e) = link.iter().find(|e| e.1 == y) {
        steps += 1;
        if steps > link.len() {
            return false;
        }
        y = e.0;
    }
    steps == link.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<(), BuildError> {
        validate(&InputMesh {
            positions,
            colors: None,
            triangles,
        })
    }

    const P: [[f32; 3]; 7] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];

    #[test]
    fn the_table_around_each_vertex_holds_its_link_edges() {
        // A small generator (xorshift), so the test needs no dependency.
        let mut x = 0x9E37_79B9u32;
        let mut next = |m: u32| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x % m
        };
        for n in [3u32, 7, 50] {
            let triangles: Vec<[u32; 3]> = (0..300).map(|_| [next(n), next(n), next(n)]).collect();
            let mut full: Vec<(u32, u32, u32, u32)> = Vec::new();
            for (t, tri) in triangles.iter().enumerate() {
                for k in 0..3 {
                    full.push((tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3], t as u32));
                }
            }
            full.sort_unstable();
            let around = link_edges(n as usize, &triangles);
            let mut grouped: Vec<(u32, u32, u32, u32)> = Vec::new();
            for v in 0..n {
                let link = around.of(v);
                let sorted = link.len() <= SHORT_LINK || link.is_sorted_by_key(|e| e.0);
                assert!(sorted, "{n} {v}");
                let at = grouped.len();
                grouped.extend(link.iter().map(|&(x, y, t)| (v, x, y, t)));
                grouped[at..].sort_unstable();
            }
            assert_eq!(grouped, full, "{n}");
        }
        assert!(link_edges(3, &[]).of(2).is_empty());
    }

    #[test]
    fn accepts_open_and_closed_surfaces() {
        assert_eq!(check(&P, &[[0, 1, 2], [1, 3, 2]]), Ok(()));
        let tetra = [[0, 2, 1], [0, 1, 4], [1, 2, 4], [2, 0, 4]];
        assert_eq!(check(&P, &tetra), Ok(()));
    }

    #[test]
    fn rejects_bad_meshes() {
        assert_eq!(check(&P, &[]), Err(BuildError::Empty));
        assert_eq!(
            check(&P, &[[0, 1, 9]]),
            Err(BuildError::IndexOutOfRange {
                triangle: 0,
                index: 9
            })
        );
        assert_eq!(
            check(&P, &[[0, 1, 1]]),
            Err(BuildError::DegenerateTriangle { triangle: 0 })
        );
        assert_eq!(
            check(&P, &[[0, 1, 2], [1, 2, 0]]),
            Err(BuildError::DuplicateTriangle {
                triangle: 1,
                first: 0
            })
        );
        assert_eq!(
            check(&P, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]),
            Err(BuildError::NonManifoldEdge { a: 0, b: 1 })
        );
        assert_eq!(
            check(&P, &[[0, 1, 2], [0, 1, 3]]),
            Err(BuildError::InconsistentOrientation { a: 0, b: 1 })
        );
        // Two triangles touching at vertex 0 only.
        assert_eq!(
            check(&P, &[[0, 1, 3], [0, 5, 6]]),
            Err(BuildError::NonManifoldVertex { vertex: 0 })
        );
        // Fans longer than `SHORT_LINK`, searched by halves: one closed disc around vertex 0
        // passes, two touching at it do not.
        let fan = |rim: core::ops::Range<u32>| {
            let (first, last) = (rim.start, rim.end - 1);
            rim.map(move |i| [0, i, if i == last { first } else { i + 1 }])
        };
        let points = [[0.0f32; 3]; 41];
        let disc: Vec<[u32; 3]> = fan(1..21).collect();
        assert_eq!(check(&points, &disc), Ok(()));
        let bowtie: Vec<[u32; 3]> = fan(1..21).chain(fan(21..41)).collect();
        assert_eq!(
            check(&points, &bowtie),
            Err(BuildError::NonManifoldVertex { vertex: 0 })
        );
        let nan = [[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(
            check(&nan, &[[0, 1, 2]]),
            Err(BuildError::NonFinite { vertex: 0 })
        );
    }
}
