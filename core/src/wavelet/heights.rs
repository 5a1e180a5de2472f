//! Height fields: a semi-regular file of about two bytes per vertex.
//!
//! A terrain sampled on a `(2^J + 1)`-square grid is a semi-regular mesh whose vertices move only
//! along one axis: every vertex lies over the point of its base face that its lattice weights
//! name. So the file needs one height per vertex, not a 12-byte record (position, normal and
//! four bound codes): positions across the up axis are the base corners interpolated, and the
//! wavelet coefficients (Azuma et al. 2003, §3.2) point along the up axis, so every error
//! spheroid of equation 3 is a segment (`b = 0`) and every cone of normals is around the up
//! axis. The bounds that remain, the radius, `a` and the cone's sine, are kept per wavelet only
//! for the coarse levels; a wavelet of the `F` finest levels (the header's "fine levels") takes
//! its block's: the largest of its level's wavelets in the same triangle of the coarse mesh
//! `K^(J-F)`. With `F = 5` a block covers 512 samples and holds 15 bytes, so the hierarchy costs
//! about 0.03 bytes per sample beside the two of the height. The writer makes these bounds
//! monotonic down the dependency graph again after the blocks took their maxima, so that a
//! wavelet the tests want still has parents the tests want.
//!
//! Layout, after the faces and edges (see [`super::format`]): a 12-byte record per base vertex
//! (position only), the heights (`u16` per wavelet in vertex order, over the bounding box along
//! the up axis), the coarse bound records (three code bytes per wavelet of `K^(J-F)`, in that
//! mesh's vertex order), the fine ones (per block in the order of [`SemiRegularView::block_of`],
//! `F` records from the coarsest fine level), then the colours. Header byte 56 is the up axis
//! (0 to 2), byte 57 the fine levels `F` (at most `J`).

use super::format::{SemiRegularView, CODES_SIZE, HEIGHT_SIZE};
use super::lattice::{rot60, Point, DIRECTIONS};
use crate::format::{cone_sine, encode_length, u16_at};
use crate::policy::Bounds;

impl SemiRegularView<'_> {
    /// The up axis of a height field (0 to 2).
    #[must_use]
    pub fn up_axis(&self) -> usize {
        self.up
    }

    /// The fine levels of a height field: those whose bounds are kept per block.
    #[must_use]
    pub fn fine_levels(&self) -> u32 {
        self.fine
    }

    /// The stored height of wavelet vertex `v`, quantized (0 out of range).
    #[inline]
    fn height_code(&self, v: u32) -> u16 {
        let o = (v.wrapping_sub(self.counts.base_vertices) as usize)
            .checked_mul(HEIGHT_SIZE)
            .and_then(|o| o.checked_add(self.offsets[3]));
        match o {
            Some(o) if o.saturating_add(HEIGHT_SIZE) <= self.offsets[4] => u16_at(self.bytes, o),
            _ => 0,
        }
    }

    /// The position of wavelet vertex `v`: its base face's corners interpolated at its weights
    /// across the up axis, its height along it.
    pub(super) fn height_position(&self, v: u32) -> [f32; 3] {
        self.point(v)
            .map_or([0.0; 3], |p| self.height_position_at(p, v))
    }

    /// The point at `p`'s weights on its base face's plane.
    fn at_weights(&self, p: Point) -> [f32; 3] {
        let c = self
            .corners(p.face)
            .map(|b| self.model.position(&self.record(b)));
        let n = self.n as f32;
        core::array::from_fn(|k| {
            (c[0][k] * p.w[0] as f32 + c[1][k] * p.w[1] as f32 + c[2][k] * p.w[2] as f32) / n
        })
    }

    /// The up axis as a unit vector.
    fn up_vector(&self) -> [f32; 3] {
        core::array::from_fn(|k| if k == self.up { 1.0 } else { 0.0 })
    }

    /// The normal of vertex `v`: the sum of the finest triangles' normals around it (a base
    /// vertex, or a vertex with no triangle: the up axis).
    pub(super) fn height_normal(&self, v: u32) -> [f32; 3] {
        let up = self.up_vector();
        let Some(p) = self.point(v) else {
            return up;
        };
        let c = self.height_position_at(p, v);
        let around = |d: [i32; 3]| {
            self.canonical(p.offset(d, 1))
                .and_then(|q| Some((q, self.vertex_id(q)?)))
                .map(|(q, id)| {
                    let x = self.height_position_at(q, id);
                    [x[0] - c[0], x[1] - c[1], x[2] - c[2]]
                })
        };
        let mut sum = [0.0f32; 3];
        let mut d = DIRECTIONS[0];
        for _ in 0..6 {
            let next = rot60(d);
            if let (Some(a), Some(b)) = (around(d), around(next)) {
                sum[0] += a[1] * b[2] - a[2] * b[1];
                sum[1] += a[2] * b[0] - a[0] * b[2];
                sum[2] += a[0] * b[1] - a[1] * b[0];
            }
            d = next;
        }
        let len = crate::root::sqrtf(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
        if len > 0.0 && len.is_finite() {
            sum.map(|x| x / len)
        } else {
            up
        }
    }

    /// The block of fine point `p` (canonical): the triangle of `K^(J-F)` holding it, numbered
    /// face by face; in each face the triangles with a corner at weights `(.., i, j)` and the
    /// edge `i + j = const` above them (rows of increasing `j`, then `i`), then those below such
    /// an edge.
    #[must_use]
    pub fn block_of(&self, p: Point) -> u32 {
        let s = 1i32 << self.fine.min(30);
        let m = (self.n / s).max(1) as u32;
        let (i, j) = (p.w[1].max(0), p.w[2].max(0));
        let (ci, cj) = ((i / s) as u32, (j / s) as u32);
        let (fi, fj) = (i % s, j % s);
        let row_start = |row: u32, len: u32| row * len - row * row.saturating_sub(1) / 2;
        let index = if fi + fj <= s {
            row_start(cj, m) + ci
        } else {
            m * (m + 1) / 2 + row_start(cj, m - 1) + ci
        };
        p.face
            .saturating_mul(m * m)
            .saturating_add(index.min(m * m - 1))
    }

    /// The byte offset of the bound record of wavelet `p` at `level`: its own for a coarse
    /// wavelet, its block's for a fine one (`None` out of range).
    fn codes_offset(&self, p: Point, level: u32) -> Option<usize> {
        let coarse_levels = self.counts.levels - self.fine;
        let (o, end) = if level <= coarse_levels {
            let s = 1i32 << self.fine;
            let q = Point {
                face: p.face,
                w: p.w.map(|x| x / s),
            };
            let id = self.vertex_id_in(q, self.n / s)?;
            let k = id.checked_sub(self.counts.base_vertices)? as usize;
            (k * CODES_SIZE + self.offsets[4], self.offsets[5])
        } else {
            let slot = level.checked_sub(coarse_levels + 1)? as usize;
            let k = self.block_of(p) as usize * self.fine as usize + slot;
            (k * CODES_SIZE + self.offsets[5], self.offsets[6])
        };
        (o + CODES_SIZE <= end).then_some(o)
    }

    /// The radius, `a` and cone codes of wavelet `p` at `level` (zeros out of range).
    fn stored_codes(&self, p: Point, level: u32) -> [u8; 3] {
        self.codes_offset(p, level)
            .and_then(|o| self.bytes.get(o..o + CODES_SIZE))
            .map_or([0; 3], |c| [c[0], c[1], c[2]])
    }

    /// The radius, `a` and cone codes of wavelet `v` (zeros for a base vertex; at the finest
    /// level, `a` is the measured error's code).
    pub(super) fn height_codes(&self, v: u32) -> [u8; 3] {
        let Some(p) = self.point(v) else {
            return [0; 3];
        };
        let level = self.level(p);
        let mut codes = self.stored_codes(p, level);
        if level == self.counts.levels {
            codes[1] = encode_length(self.finest_error(p, v) / self.model.unit());
        }
        codes
    }

    /// The bounds of wavelet `v`: a segment along the up axis for the error, a cone around it.
    pub(super) fn height_bounds(&self, v: u32) -> Bounds {
        match self.point(v) {
            Some(p) => self.height_bounds_at(p, v),
            None => Bounds {
                center: self.position(v),
                radius: 0.0,
                axis: self.up_vector(),
                cone_sin: 0.0,
                a2: 0.0,
                b2: 0.0,
            },
        }
    }

    /// [`SemiRegularView::height_bounds`] of wavelet `v` at canonical point `p`.
    pub(super) fn height_bounds_at(&self, p: Point, v: u32) -> Bounds {
        let level = self.level(p);
        let [r, a, c] = self.stored_codes(p, level);
        let a = if level == self.counts.levels {
            self.finest_error(p, v)
        } else {
            self.length(a)
        };
        Bounds {
            center: self.height_position_at(p, v),
            radius: self.length(r),
            axis: self.up_vector(),
            cone_sin: cone_sine(c),
            a2: a * a,
            b2: 0.0,
        }
    }

    /// The position of vertex `id`, whose canonical point is `p` (without finding the point
    /// from the id).
    pub(super) fn height_position_at(&self, p: Point, id: u32) -> [f32; 3] {
        if id < self.counts.base_vertices {
            return self.model.position(&self.record(id));
        }
        let mut out = self.at_weights(p);
        out[self.up] = self.height_at(id);
        out
    }

    /// The height of vertex `id`.
    #[inline]
    fn height_at(&self, id: u32) -> f32 {
        let q = if id < self.counts.base_vertices {
            let r = self.record(id);
            u16_at(&r, 2 * self.up)
        } else {
            self.height_code(id)
        };
        self.model.dequantize([q; 3])[self.up]
    }

    /// The height at lattice point `p` (any frame; 0 off the mesh).
    #[inline]
    fn height_of(&self, p: Point) -> f32 {
        self.canonical(p)
            .and_then(|c| self.vertex_id(c))
            .map_or(0.0, |id| self.height_at(id))
    }

    /// The error bound of finest-level wavelet `p` (vertex `id`), measured on the heights as
    /// the writer measures every wavelet's (see [`super::build`]): over its support, the six
    /// finest triangles around it, the error when it is out is its own coefficient at its
    /// vertex and, at each neighbour that is a sibling (which may be out too), that sibling's.
    /// The two triangles of the level above that hold the wavelet's parent edge `x y` have
    /// third corners `l` and `r`; the siblings are the middles of their other four edges.
    pub(super) fn finest_error(&self, p: Point, id: u32) -> f32 {
        let [x, y] = self.parent_edge(p, self.counts.levels);
        let (hx, hy) = (self.height_of(x), self.height_of(y));
        let mut a = libm::fabsf(self.height_at(id) - (hx + hy) * 0.5);
        for (corner, hc) in [(x, hx), (y, hy)] {
            for wing in [x.left_of(y), x.right_of(y)] {
                let Some(m) = self.canonical(corner.mid(wing)) else {
                    continue;
                };
                let Some(mid) = self.vertex_id(m) else {
                    continue;
                };
                let coefficient = self.height_at(mid) - (hc + self.height_of(wing)) * 0.5;
                a = a.max(libm::fabsf(coefficient));
            }
        }
        a
    }
}

#[cfg(feature = "build")]
mod write {
    use alloc::vec;
    use alloc::vec::Vec;

    use super::super::build::{
        cone_code, header, interpolate, monotonic, seal, wavelet_bounds, SemiRegular,
        SemiRegularBuildError, WaveletBounds,
    };
    use super::super::format::{
        SemiRegularView, CODES_SIZE, FLAG_COLORS, FLAG_HEIGHTS, NONE, VERTEX_SIZE,
    };
    use super::super::lattice::Point;
    use crate::format::{encode_length, ModelBox};

    /// The fine levels the writer keeps per block (fewer when the mesh has fewer levels).
    pub const FINE_LEVELS: u32 = 5;

    /// One bound record before encoding.
    #[derive(Clone, Copy, Default)]
    struct Kept {
        radius: f32,
        a: f32,
        cone: f32,
    }

    impl Kept {
        fn raise(&mut self, radius: f32, a: f32, cone: f32) {
            self.radius = self.radius.max(radius);
            self.a = self.a.max(a);
            self.cone = self.cone.max(cone);
        }
    }

    impl SemiRegular {
        /// The file of this mesh as a height field along coordinate axis `up` (see
        /// [`super`]): about two bytes per vertex instead of twelve. Every vertex must lie over
        /// the point of its base face that its weights name (the base corners interpolated
        /// across the up axis, to 1e-4 of the bounding box's diagonal), as the vertices of a
        /// terrain grid do.
        ///
        /// ```
        /// use vdlod_core::wavelet::build::interpolate;
        /// use vdlod_core::wavelet::{SemiRegular, SemiRegularView};
        /// // A 65 x 65 grid of heights over the unit square, z up.
        /// let base = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        /// let faces = [[0, 1, 2], [0, 2, 3]];
        /// let mesh = SemiRegular::from_fn(&base, &faces, 6, |f, w| {
        ///     let [x, y, _] = interpolate(faces[f as usize].map(|v| base[v as usize]), w, 64.0);
        ///     [x, y, 0.1 * libm::sinf(7.0 * x) * libm::cosf(5.0 * y)]
        /// })
        /// .unwrap();
        /// let bytes = mesh.to_height_bytes(2).unwrap();
        /// let view = SemiRegularView::parse(&bytes).unwrap();
        /// assert!(view.is_height_field());
        /// // Two bytes per height, 0.08 per vertex of header, base and bounds on a grid this small.
        /// assert!((bytes.len() as f64) < 2.1 * view.vertices() as f64);
        /// ```
        pub fn to_height_bytes(&self, up: usize) -> Result<Vec<u8>, SemiRegularBuildError> {
            let view = self.view().ok_or(SemiRegularBuildError::TooLarge)?;
            let counts = view.counts();
            let n = counts.vertices() as usize;
            for given in [
                Some(self.positions.len()),
                self.colors.as_ref().map(Vec::len),
            ]
            .into_iter()
            .flatten()
            {
                if given != n {
                    return Err(SemiRegularBuildError::Count { given, needed: n });
                }
            }
            if up > 2 {
                return Err(SemiRegularBuildError::NotHeightField(0));
            }
            let model = ModelBox::around(self.positions.iter().copied());
            let base = counts.base_vertices;
            let steps = view.steps() as f32;
            let tolerance = 1e-4 * model.unit();
            for v in base..n as u32 {
                let p = view.point(v).ok_or(SemiRegularBuildError::TooLarge)?;
                let corners = view.corners(p.face).map(|c| self.positions[c as usize]);
                let over = interpolate(corners, p.w, steps);
                let here = self.positions[v as usize];
                if (0..3).any(|k| k != up && (over[k] - here[k]).abs() > tolerance) {
                    return Err(SemiRegularBuildError::NotHeightField(v));
                }
            }
            let fine = FINE_LEVELS.min(counts.levels);
            let flags = FLAG_HEIGHTS
                | if self.colors.is_some() {
                    FLAG_COLORS
                } else {
                    0
                };
            let sections = counts.sections(flags, fine);
            let mut out = header(counts, flags, &model);
            out[56] = up as u8;
            out[57] = fine as u8;
            let (faces, edges) = self.topology_bytes();
            out.extend_from_slice(faces);
            out.extend_from_slice(edges);
            for p in &self.positions[..base as usize] {
                let mut r = [0u8; VERTEX_SIZE];
                for (k, q) in model.quantize(*p).iter().enumerate() {
                    r[2 * k..2 * k + 2].copy_from_slice(&q.to_le_bytes());
                }
                out.extend_from_slice(&r);
            }
            for p in &self.positions[base as usize..] {
                out.extend_from_slice(&model.quantize(*p)[up].to_le_bytes());
            }
            // The bounds, zero for now: they are measured on the positions the file gives.
            out.resize(sections[6] as usize, 0);
            for c in self.colors.iter().flatten() {
                out.extend_from_slice(c);
            }
            seal(&mut out);
            let codes = {
                let file =
                    SemiRegularView::parse(&out).map_err(|_| SemiRegularBuildError::TooLarge)?;
                kept_codes(&file, &model)
            };
            let at = sections[4] as usize;
            out[at..at + codes.len()].copy_from_slice(&codes);
            seal(&mut out);
            Ok(out)
        }
    }

    /// The coarse and block bound sections of height field `file` (whose bounds are still zero).
    fn kept_codes(file: &SemiRegularView<'_>, model: &ModelBox) -> Vec<u8> {
        let n = file.vertices();
        let base = file.counts().base_vertices;
        let positions: Vec<[f32; 3]> = (0..n).map(|v| file.position(v)).collect();
        let axes = vec![file.up_vector(); n as usize];
        let mut bounds: Vec<WaveletBounds> = wavelet_bounds(file, &positions, &axes);
        monotonic(file, &positions, &axes, &mut bounds);
        let first = file.offsets[4];
        let slot = |p: Point| {
            file.codes_offset(p, file.level(p))
                .map(|o| (o - first) / CODES_SIZE)
        };
        let mut kept = vec![Kept::default(); (file.offsets[6] - first) / CODES_SIZE];
        for (v, b) in (base..n).zip(&bounds) {
            if let Some(k) = file.point(v).and_then(slot) {
                // The error vectors are along the up axis: `delta` is the segment's half-length.
                kept[k].raise(b.radius, b.delta, b.cone);
            }
        }
        // Monotonic again, now that blocks took their maxima: finest level first, so that a
        // record is final before its wavelets raise their parents'.
        let mut order: Vec<(u32, u32)> = (base..n)
            .filter_map(|v| file.point(v).map(|p| (file.level(p), v)))
            .collect();
        order.sort_unstable_by(|a, b| b.cmp(a));
        for (level, v) in order {
            let Some(p) = file.point(v) else { continue };
            // The child's bounds as the file will give them, so that the codes stay monotonic.
            let Some(k) = slot(p) else { continue };
            let child = Kept {
                radius: file.length(encode_length(kept[k].radius / model.unit())),
                // A finest wavelet's error is measured, not its block's.
                a: if level == file.levels() {
                    file.finest_error(p, v)
                } else {
                    kept[k].a
                },
                cone: kept[k].cone,
            };
            for q in file.parents(p, level) {
                let Some(kq) = (q != NONE).then(|| file.point(q).and_then(slot)).flatten() else {
                    continue;
                };
                let (a, b) = (positions[v as usize], positions[q as usize]);
                let gap = crate::root::sqrtf((0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum());
                kept[kq].raise(gap + child.radius, child.a, child.cone);
            }
        }
        kept.iter()
            .flat_map(|k| {
                [
                    encode_length(k.radius / model.unit()),
                    encode_length(k.a / model.unit()),
                    cone_code(k.cone),
                ]
            })
            .collect()
    }
}

#[cfg(feature = "build")]
pub use write::FINE_LEVELS;

#[cfg(all(test, feature = "build"))]
mod tests {
    use alloc::vec;
    use alloc::vec::Vec;

    use super::super::build::{interpolate, monotonic, wavelet_bounds, SemiRegular};
    use super::super::format::NONE;
    use super::super::{SemiRegularBuildError, SemiRegularView, WaveletCut};
    use crate::adapt::Budget;
    use crate::policy::{QRefine, View};

    /// A bumpy grid over `[-1, 1]^2`, z up: 2 x 2 squares of two triangles, `levels` deep.
    fn grid(levels: u32) -> SemiRegular {
        let base: Vec<[f32; 3]> = (0..9)
            .map(|i| [(i % 3) as f32 - 1.0, (i / 3) as f32 - 1.0, 0.0])
            .collect();
        let mut faces = Vec::new();
        for y in 0..2u32 {
            for x in 0..2u32 {
                let v = y * 3 + x;
                faces.push([v, v + 1, v + 4]);
                faces.push([v, v + 4, v + 3]);
            }
        }
        let steps = (1 << levels) as f32;
        SemiRegular::from_fn(&base, &faces, levels, |f, w| {
            let p = interpolate(faces[f as usize].map(|v| base[v as usize]), w, steps);
            let z = 0.15 * libm::sinf(5.0 * p[0]) * libm::cosf(4.0 * p[1])
                + 0.01 * libm::sinf(40.0 * p[0] * p[1]);
            [p[0], p[1], z]
        })
        .unwrap()
    }

    #[test]
    fn a_height_field_holds_the_positions_in_two_bytes_a_vertex() {
        let mesh = grid(7);
        let records = mesh.to_bytes().unwrap();
        let heights = mesh.to_height_bytes(2).unwrap();
        let (r, h) = (
            SemiRegularView::parse(&records).unwrap(),
            SemiRegularView::parse(&heights).unwrap(),
        );
        assert!(h.is_height_field() && !r.is_height_field());
        assert_eq!((h.up_axis(), h.fine_levels()), (2, 5));
        assert_eq!(h.vertices(), r.vertices());
        let per_vertex = heights.len() as f64 / h.vertices() as f64;
        assert!(per_vertex < 2.05, "{per_vertex}");
        // One quantum of the records' positions (2 / 65535 across, 0.33 / 65535 up) apart.
        for v in 0..h.vertices() {
            let (a, b) = (r.position(v), h.position(v));
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 4e-5, "vertex {v}: {a:?} {b:?}");
            }
            if v >= h.counts().base_vertices {
                let (m, n) = (r.normal(v), h.normal(v));
                let cos: f32 = (0..3).map(|k| m[k] * n[k]).sum();
                assert!(cos > 0.99, "vertex {v}: {m:?} {n:?}");
            }
        }
    }

    #[test]
    fn height_field_bounds_hold_every_wavelets_own_and_stay_monotonic() {
        let bytes = grid(7).to_height_bytes(2).unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let n = s.vertices();
        let base = s.counts().base_vertices;
        let positions: Vec<[f32; 3]> = (0..n).map(|v| s.position(v)).collect();
        let axes = vec![[0.0, 0.0, 1.0]; n as usize];
        let mut own = wavelet_bounds(&s, &positions, &axes);
        monotonic(&s, &positions, &axes, &mut own);
        let mut fine_coarser_than_own = 0;
        for v in base..n {
            let b = s.bounds(v);
            let w = own[(v - base) as usize];
            assert!(
                b.radius >= w.radius && b.a2 >= w.delta * w.delta,
                "wavelet {v}"
            );
            assert!(
                b.cone_sin >= libm::sinf(w.cone.min(1.57)) - 1e-6,
                "wavelet {v}"
            );
            assert_eq!((b.b2, b.axis), (0.0, [0.0, 0.0, 1.0]));
            if b.a2 > 1.5 * 1.5 * w.delta * w.delta {
                fine_coarser_than_own += 1;
            }
            let p = s.point(v).unwrap();
            for q in s.parents(p, s.level(p)) {
                if q == NONE {
                    continue;
                }
                let c = s.bounds(q);
                let d = [0, 1, 2].map(|k| b.center[k] - c.center[k]);
                let gap = crate::root::sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                assert!(c.a2 >= b.a2 && c.cone_sin >= b.cone_sin, "{q} over {v}");
                assert!(c.radius >= (gap + b.radius) * 0.9999, "{q} over {v}");
            }
        }
        // Blocks share their largest bound, so some wavelets are over-refined; not all.
        assert!(
            fine_coarser_than_own > 0 && fine_coarser_than_own < (n - base) / 2,
            "{fine_coarser_than_own} of {}",
            n - base
        );
    }

    #[test]
    fn a_cut_flies_a_height_field_to_full_detail_without_cracks() {
        let bytes = grid(6).to_height_bytes(2).unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let mut cut = WaveletCut::<1100, 32_768, 34_000, 8_192, u32>::boxed();
        cut.reset(&s).unwrap();
        let mut scratch = vec![[0u32; 2]; 3 * 32_768];
        for k in 0..40 {
            let a = k as f32 * 0.3;
            let d = 1.2 + 0.1 * k as f32;
            let eye = [d * libm::cosf(a), d * libm::sinf(a), 0.4 + 0.05 * k as f32];
            let view = View::look_at(eye, [0.0; 3], [0.0, 0.0, 1.0], 0.9, 4.0 / 3.0, 480.0);
            let budget = Budget {
                max_triangles: 800 + 2200 * (k % 2),
                ..Budget::default()
            };
            let stats = cut.adapt(&s, &view, &QRefine::new(0.5 + (k % 4) as f32), &budget);
            assert!(stats.triangles <= budget.max_triangles, "{k}: {stats:?}");
            cut.check(&s, false, &mut scratch)
                .unwrap_or_else(|d| panic!("frame {k}: {d}"));
        }
        let view = View::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.9, 1.0, 480.0);
        // A full queue leaves the rest to the next frame.
        let mut stats = cut.adapt(&s, &view, &QRefine::new(1e-9), &Budget::default());
        for _ in 0..8 {
            if !stats.queue_overflow {
                break;
            }
            stats = cut.adapt(&s, &view, &QRefine::new(1e-9), &Budget::default());
        }
        assert!(!stats.queue_overflow);
        assert_eq!(stats.triangles as usize, cut.triangles().len());
        // Every wavelet that changes the surface is in (a flat one, whose heights quantized
        // to its parents' middle, may stay out).
        let base = s.counts().base_vertices;
        let wanted = (base..s.vertices()).filter(|&v| s.bounds(v).a2 > 0.0);
        for v in wanted {
            assert!(cut.includes(v), "wavelet {v}");
        }
        assert!(cut.included() > s.wavelets() * 4 / 5);
        for i in 0..cut.vertex_count() {
            assert_eq!(cut.position(i), s.position(cut.vertex_id(i)));
        }
    }

    #[test]
    fn only_height_fields_are_written_as_heights() {
        let sphere = SemiRegular::sphere(2).unwrap();
        assert!(matches!(
            sphere.to_height_bytes(2),
            Err(SemiRegularBuildError::NotHeightField(_))
        ));
        assert!(matches!(
            grid(3).to_height_bytes(3),
            Err(SemiRegularBuildError::NotHeightField(0))
        ));
        // Heights along x are not a height field of this grid either.
        assert!(grid(3).to_height_bytes(0).is_err());
        // A grid shallower than the fine levels keeps every wavelet's bound per block.
        let shallow = grid(3).to_height_bytes(2).unwrap();
        let s = SemiRegularView::parse(&shallow).unwrap();
        assert_eq!(s.fine_levels(), 3);
    }
}
