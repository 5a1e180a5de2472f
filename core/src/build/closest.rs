//! Distances to the input surface, for the importance paper's `Gerr`.
//!
//! Ng, Kluge, Sheng and Guo ("View importance for selective refinement of progressive meshes",
//! the importance paper) price an edge collapse by, among other terms, the distance from the
//! edge's midpoint to "the true closest point on the original mesh". [`Surface`] answers that
//! exactly: the input triangles are binned in a uniform grid of cells about twice a triangle's
//! size, and a query searches rings of cells outwards from the point until no unsearched cell can
//! hold anything nearer than the nearest triangle found. Plain flat arrays (cell offsets and
//! triangle lists), no recursion; the answer is the same whatever order the cells are visited in.

use alloc::vec;
use alloc::vec::Vec;

use super::vec3::{add, cross, dot, from_f32, scale, sub, Vec3d};

/// The input triangles, binned for nearest-point queries.
pub(crate) struct Surface {
    corners: Vec<[Vec3d; 3]>,
    min: Vec3d,
    cell: f64,
    dims: [usize; 3],
    /// Cell `c`'s triangles are `items[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// Most cells per triangle the grid may have (it coarsens past that).
const CELLS_PER_TRIANGLE: f64 = 8.0;

/// Squared distance from `p` to segment `a-b`.
fn segment_distance2(p: Vec3d, a: Vec3d, b: Vec3d) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = sub(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]);
    dot(d, d)
}

/// Squared distance from `p` to the triangle `t`: to its plane when `p` projects inside it,
/// else to the nearest of its edges.
pub(crate) fn triangle_distance2(p: Vec3d, t: &[Vec3d; 3]) -> f64 {
    let [a, b, c] = *t;
    let n = cross(sub(b, a), sub(c, a));
    let nn = dot(n, n);
    if nn > 0.0 {
        let h = dot(sub(p, a), n) / nn;
        let q = sub(p, scale(n, h));
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(x, y)| dot(cross(sub(y, x), sub(q, x)), n) >= 0.0);
        if inside {
            return h * h * nn;
        }
    }
    segment_distance2(p, a, b)
        .min(segment_distance2(p, b, c))
        .min(segment_distance2(p, c, a))
}

/// The closest point of triangle `t` to `p`: its barycentric weights and squared distance.
pub(crate) fn closest(p: Vec3d, t: [Vec3d; 3]) -> ([f64; 3], f64) {
    // Ericson, "Real-time collision detection" (2004), 5.1.5: by the Voronoi regions.
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let weights = if d1 <= 0.0 && d2 <= 0.0 {
        [1.0, 0.0, 0.0]
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            [0.0, 1.0, 0.0]
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let v = d1 / (d1 - d3);
            [1.0 - v, v, 0.0]
        } else if d6 >= 0.0 && d5 <= d6 {
            [0.0, 0.0, 1.0]
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let w = d2 / (d2 - d6);
            [1.0 - w, 0.0, w]
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            [0.0, 1.0 - w, w]
        } else {
            let s = va + vb + vc;
            if s > 0.0 && s.is_finite() {
                [va / s, vb / s, vc / s]
            } else {
                [1.0 / 3.0; 3]
            }
        }
    };
    let q = point(t, weights);
    let d = sub(p, q);
    (weights, dot(d, d))
}

pub(crate) fn point(t: [Vec3d; 3], w: [f64; 3]) -> Vec3d {
    add(add(scale(t[0], w[0]), scale(t[1], w[1])), scale(t[2], w[2]))
}

impl Surface {
    /// Bins the triangles `triangles` over `positions` (indices already validated).
    pub fn new(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Surface {
        let corners: Vec<[Vec3d; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| from_f32(positions[i as usize])))
            .collect();
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        let mut area = 0.0;
        for t in &corners {
            for p in t {
                for k in 0..3 {
                    min[k] = min[k].min(p[k]);
                    max[k] = max[k].max(p[k]);
                }
            }
            let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
            area += 0.5 * crate::root::sqrt(dot(n, n));
        }
        if corners.is_empty() {
            min = [0.0; 3];
            max = [0.0; 3];
        }
        let n = corners.len().max(1) as f64;
        let extent = [0, 1, 2].map(|k| max[k] - min[k]);
        let largest = extent[0].max(extent[1]).max(extent[2]);
        // About two triangles across a cell, fewer cells when the box is mostly empty.
        let mut cell = (2.0 * crate::root::sqrt(area / n)).max(largest * 1e-6);
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        let dims_for = |cell: f64| extent.map(|e| ((e / cell) as usize).clamp(0, 1 << 20) + 1);
        let mut dims = dims_for(cell);
        // Counted in floating point: the product of three clamped sides overflows a 32-bit usize.
        let cells_of = |d: [usize; 3]| d[0] as f64 * d[1] as f64 * d[2] as f64;
        while cells_of(dims) > CELLS_PER_TRIANGLE * n + 64.0 {
            cell *= 1.25;
            dims = dims_for(cell);
        }
        let mut s = Surface {
            corners,
            min,
            cell,
            dims,
            starts: Vec::new(),
            items: Vec::new(),
        };
        // Two passes over each triangle's box of cells: count, then fill.
        let cells = dims[0] * dims[1] * dims[2];
        let mut counts = vec![0u32; cells + 1];
        for t in 0..s.corners.len() {
            s.for_each_cell_of(t, |c| counts[c] += 1);
        }
        let mut starts = vec![0u32; cells + 1];
        for c in 0..cells {
            starts[c + 1] = starts[c] + counts[c];
        }
        let mut fill = starts.clone();
        let mut items = vec![0u32; starts[cells] as usize];
        for t in 0..s.corners.len() {
            s.for_each_cell_of(t, |c| {
                items[fill[c] as usize] = t as u32;
                fill[c] += 1;
            });
        }
        s.starts = starts;
        s.items = items;
        s
    }

    /// The cell coordinates of `p`, clamped to the grid.
    fn cell_of(&self, p: Vec3d) -> [usize; 3] {
        [0, 1, 2].map(|k| {
            let x = (p[k] - self.min[k]) / self.cell;
            if x > 0.0 {
                (x as usize).min(self.dims[k] - 1)
            } else {
                0
            }
        })
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Calls `visit` with every cell triangle `t`'s bounding box overlaps.
    fn for_each_cell_of(&self, t: usize, mut visit: impl FnMut(usize)) {
        let tri = self.corners[t];
        let lo = [0, 1, 2].map(|k| tri[0][k].min(tri[1][k]).min(tri[2][k]));
        let hi = [0, 1, 2].map(|k| tri[0][k].max(tri[1][k]).max(tri[2][k]));
        let (a, b) = (self.cell_of(lo), self.cell_of(hi));
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    visit(self.index([x, y, z]));
                }
            }
        }
    }

    /// The distance from `p` to the nearest point of the surface (infinite without triangles).
    pub fn distance(&self, p: Vec3d) -> f64 {
        let mut best = f64::INFINITY;
        if self.corners.is_empty() {
            return best;
        }
        let c = self.cell_of(p);
        let rings = self.dims.iter().copied().max().unwrap_or(1);
        for r in 0..rings {
            // Rings 0..r are searched: a cell of ring r or beyond lies past r - 1 whole cells
            // (from a point outside the grid, further still).
            let reach = r.saturating_sub(1) as f64 * self.cell;
            if reach * reach >= best {
                break;
            }
            let lo = c.map(|x| x.saturating_sub(r));
            let hi = [0, 1, 2].map(|k| (c[k] + r).min(self.dims[k] - 1));
            let mut search = |x: usize, y: usize, z: usize| {
                let i = self.index([x, y, z]);
                let cell = &self.items[self.starts[i] as usize..self.starts[i + 1] as usize];
                for &t in cell {
                    best = best.min(triangle_distance2(p, &self.corners[t as usize]));
                }
            };
            // Only the cells of ring r: a whole row where y or z is on the ring, else its two
            // ends (inner cells were searched in earlier rings).
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    if z.abs_diff(c[2]) == r || y.abs_diff(c[1]) == r {
                        for x in lo[0]..=hi[0] {
                            search(x, y, z);
                        }
                    } else if r > 0 {
                        if c[0] >= r {
                            search(c[0] - r, y, z);
                        }
                        if c[0] + r < self.dims[0] {
                            search(c[0] + r, y, z);
                        }
                    }
                }
            }
        }
        crate::root::sqrt(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::tests::{grid, sphere};

    /// The same answer by looking at every triangle.
    fn brute(s: &Surface, p: Vec3d) -> f64 {
        let d = s
            .corners
            .iter()
            .map(|t| triangle_distance2(p, t))
            .fold(f64::INFINITY, f64::min);
        crate::root::sqrt(d)
    }

    #[test]
    fn triangle_distance_takes_the_plane_the_edges_or_the_corners() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        assert_eq!(triangle_distance2([0.5, 0.5, 3.0], &t), 9.0); // above the inside
        assert_eq!(triangle_distance2([1.0, -2.0, 0.0], &t), 4.0); // beside an edge
        assert_eq!(triangle_distance2([-3.0, -4.0, 0.0], &t), 25.0); // beyond a corner
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]; // degenerate: its segment
        assert_eq!(triangle_distance2([1.0, 1.0, 0.0], &flat), 1.0);
    }

    #[test]
    fn the_grid_finds_what_looking_at_every_triangle_finds() {
        for (p, t) in [grid(20), sphere(3)] {
            let s = Surface::new(&p, &t);
            let mut x = 0x9e37_79b9u32;
            let mut next = || {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                (x >> 8) as f64 / (1u32 << 24) as f64 * 4.0 - 2.0
            };
            for _ in 0..2000 {
                let q = [next(), next(), next()];
                assert_eq!(s.distance(q), brute(&s, q), "{q:?}");
            }
            // On the surface: zero (at a vertex) or within rounding.
            assert_eq!(s.distance(from_f32(p[7])), 0.0);
        }
        assert_eq!(Surface::new(&[], &[]).distance([0.0; 3]), f64::INFINITY);
    }
}
