//! Binning a shaded mesh's triangles by pixel row once per frame, so that a frame drawn in bands
//! does not read every triangle in every band.
//!
//! [`ShadedMesh::bin`] runs the culling part of the triangle loop once and keeps what a band
//! needs to find its triangles, in a buffer of `u32` the caller sizes:
//!
//! - **Row bins**, with as little as one entry per triangle (a device's choice): each triangle's
//!   first and last row, and for a run of triangles that draw nothing its remaining length, so
//!   that a band steps over the run at once.
//! - **Band lists**, with two entries per triangle and one per band plus one, and room left: the
//!   triangles that draw something, as pairs of index and rows, and each band's own list of them
//!   in draw order (a counting sort), so that a band reads only its triangles. When the lists do
//!   not fit, the bands scan the pairs instead.
//!
//! Either way a band draws its triangles in the frame's order, so the bands stitch to the whole
//! frame bit for bit.

use super::{clockwise, corners, for_each_clipped, outcodes, Facing, Plain, Window, SUBPIXEL_BITS};
use super::{needs_clipping, signed_area2_xy, DrawError, DrawStats, ShadedMesh};
use crate::edge::{covers_centre, pixel_bounds, pixel_box, signed_area2};
use crate::mesh::MeshSource;
use crate::target::{Depth, Pixel, Target, TargetError};

/// Whether binning's front faces are kept without a branch ([`ShadedMesh::for_each_row_span`]):
/// where a mispredicted branch costs many cycles. Whether a small triangle's bounds hold a
/// pixel centre, and whether it covers it, are as good as random; tested whatever the bounds
/// (more instructions: 6.5 -> 8.1 million a frame for the full bunny at 320x240), the frame
/// in 16-row bands with lists took 1.02-1.03x the whole frame's time on x86-64 instead of
/// 1.18-1.20x. The Cortex-M7 pays little for a branch and would draw its frames in 3% more
/// instructions.
const BRANCH_FREE: bool = cfg!(any(target_arch = "x86_64", target_arch = "aarch64"));

/// A [`ShadedMesh`] with its triangles binned by pixel row ([`ShadedMesh::bin`]), for a frame
/// drawn in bands.
#[derive(Debug)]
pub struct BinnedMesh<'a, M: MeshSource> {
    shaded: ShadedMesh<'a, M>,
    bins: Bins<'a>,
    stats: DrawStats,
}

// By hand: a derive would ask `M: Copy`, and it holds only references and plain values.
impl<M: MeshSource> Clone for BinnedMesh<'_, M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M: MeshSource> Copy for BinnedMesh<'_, M> {}

/// What a band reads to find its triangles.
#[derive(Clone, Copy, Debug)]
pub(super) enum Bins<'a> {
    /// One entry per triangle: its rows ([`pack_rows`]), or, in a run of triangles that meet no
    /// row, [`SKIP`] and the run's remaining length.
    Rows(&'a [u32]),
    /// The triangles that meet a row as pairs of index and rows, in draw order, and, when they
    /// fitted, each band's list.
    Pairs {
        pairs: &'a [u32],
        lists: Option<BandLists<'a>>,
    },
}

/// Each band's triangles in draw order: band `b`'s are `entries[starts[b]..starts[b + 1]]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BandLists<'a> {
    band_rows: usize,
    starts: &'a [u32],
    entries: &'a [u32],
}

impl<'a> BandLists<'a> {
    /// The list of the band that holds all of `window`'s rows, if one does.
    fn band(&self, window: &Window) -> Option<&'a [u32]> {
        let b = window.y / self.band_rows;
        let within = window.y + window.height <= (b + 1) * self.band_rows;
        let (start, end) = (*self.starts.get(b)?, *self.starts.get(b + 1)?);
        within
            .then(|| self.entries.get(start as usize..end as usize))
            .flatten()
    }
}

/// First row of a row bin in a run of triangles that meet no row; its last row is the run's
/// remaining length. (Rows are below [`crate::MAX_DIMENSION`].)
const SKIP: u16 = u16::MAX;

/// A triangle's first and last pixel rows as one entry.
#[inline(always)]
fn pack_rows(first: u16, last: u16) -> u32 {
    u32::from(first) | u32::from(last) << 16
}

/// The first and last rows of an entry.
#[inline(always)]
fn unpack_rows(entry: u32) -> (usize, usize) {
    ((entry & 0xffff) as usize, (entry >> 16) as usize)
}

/// Whether an entry's rows meet `top..=bottom` (without a branch).
#[inline(always)]
fn meets(entry: u32, top: usize, bottom: usize) -> bool {
    let (first, last) = unpack_rows(entry);
    (last >= top) & (first <= bottom)
}

/// The band of a row, by a multiplication instead of a division: for rows below 2^16 and band
/// heights up to 2^16, `row * m / 2^32` with `m = 2^32 / band_rows + 1` is `row / band_rows`
/// exactly (the error of `m`, below 1, times `row` stays below `2^32 / band_rows`).
#[derive(Clone, Copy)]
struct BandOf {
    m: u64,
}

impl BandOf {
    fn new(band_rows: usize) -> BandOf {
        // Taller bands than 2^16 rows hold every row in the first, as bands of 2^16 do.
        let rows = band_rows.clamp(1, 1 << 16) as u64;
        BandOf {
            m: (1u64 << 32) / rows + 1,
        }
    }

    #[inline(always)]
    fn row(self, row: u16) -> usize {
        ((u64::from(row) * self.m) >> 32) as usize
    }

    /// The bands of an entry's first and last rows.
    #[inline(always)]
    fn span(self, entry: u32) -> (usize, usize) {
        (self.row(entry as u16), self.row((entry >> 16) as u16))
    }
}

/// The triangles whose row bins meet `top..=bottom`, in draw order, stepping over runs of
/// triangles that meet no row at once.
#[derive(Clone)]
struct RowScan<'a> {
    rows: &'a [u32],
    next: usize,
    top: usize,
    bottom: usize,
}

impl Iterator for RowScan<'_> {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        while let Some(&entry) = self.rows.get(self.next) {
            let t = self.next;
            let (first, last) = unpack_rows(entry);
            if first == usize::from(SKIP) {
                self.next = t + last.max(1);
                continue;
            }
            self.next = t + 1;
            if meets(entry, self.top, self.bottom) {
                return Some(t);
            }
        }
        None
    }
}

/// The triangles a window of a binned mesh reads, in draw order.
#[derive(Clone)]
enum BandOrder<'a> {
    /// Those of a band's list.
    List(core::slice::Iter<'a, u32>),
    /// Those whose row bins meet the window.
    Rows(RowScan<'a>),
    /// Those whose pairs' rows meet `top..=bottom`.
    Pairs {
        pairs: core::slice::ChunksExact<'a, u32>,
        top: usize,
        bottom: usize,
    },
}

impl Iterator for BandOrder<'_> {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        match self {
            BandOrder::List(list) => list.next().map(|&t| t as usize),
            BandOrder::Rows(rows) => rows.next(),
            BandOrder::Pairs { pairs, top, bottom } => {
                pairs.find_map(|pair| meets(pair[1], *top, *bottom).then_some(pair[0] as usize))
            }
        }
    }
}

impl<M: MeshSource> BinnedMesh<'_, M> {
    /// Draws the triangles that meet `target`'s window, which must be (a window of) the frame
    /// the mesh was shaded for; returns the statistics of the whole frame, counted by
    /// [`ShadedMesh::bin`]. A window within one band reads that band's list when there are
    /// lists; any other window scans the bins.
    pub fn draw<P: Pixel, D: Depth>(
        &self,
        target: &mut Target<'_, P, D>,
    ) -> Result<DrawStats, DrawError> {
        self.shaded.check_frame(target)?;
        let window = target.window;
        let (top, bottom) = (window.y, window.y + window.height - 1);
        let list = match self.bins {
            Bins::Pairs {
                lists: Some(lists), ..
            } => lists.band(&window),
            _ => None,
        };
        // One iterator for the three ways, so that the triangle loop is compiled once for them
        // (a copy each took about 8 KB of a device's flash).
        let order = match (list, self.bins) {
            (Some(list), _) => BandOrder::List(list.iter()),
            (None, Bins::Rows(rows)) => BandOrder::Rows(RowScan {
                rows,
                next: 0,
                top,
                bottom,
            }),
            (None, Bins::Pairs { pairs, .. }) => BandOrder::Pairs {
                pairs: pairs.chunks_exact(2),
                top,
                bottom,
            },
        };
        self.shaded.draw_triangles(target, order, &Plain);
        Ok(self.stats)
    }

    /// Whether the bins had room for each band's list (see [`ShadedMesh::bin`]).
    pub fn has_band_lists(&self) -> bool {
        matches!(self.bins, Bins::Pairs { lists: Some(_), .. })
    }
}

impl<'a, M: MeshSource> ShadedMesh<'a, M> {
    /// Bins the triangles by pixel row once per frame, for a frame drawn in bands of
    /// `band_rows` rows ([`Window::bands`]), so that a band does not read the triangles that
    /// miss it. `bins` needs at least one entry per triangle (4 bytes each): then each
    /// triangle's rows are kept, and each band scans them, stepping over runs of triangles that
    /// draw nothing at once. With at least two entries per triangle and one per band plus one,
    /// the triangles that draw something are kept as pairs of index and rows, and, when what
    /// is left holds one entry per band each of them meets, each band's own list in draw order,
    /// so that a band reads only its triangles ([`BinnedMesh::has_band_lists`]). Four entries
    /// per triangle and one per band plus one always hold the lists when no triangle is taller
    /// than a band (each meets two bands at most); a mesh whose triangles mostly face away or
    /// fall between pixel centres needs far fewer. The
    /// statistics of the whole frame are counted here, and every draw returns them.
    ///
    /// ```
    /// use glam::{Mat4, Vec3};
    /// use vdlod_raster::{shade, DrawParams, Mesh, Rgb565, ShadedVertex, Shading, Target, Window};
    /// let positions = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mesh = Mesh { positions: &positions, triangles: &[[0u16, 1, 2]], ..Mesh::default() };
    /// let proj = Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0);
    /// let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
    /// let params = DrawParams { mvp: proj * view, shading: Shading::Flat, ..DrawParams::default() };
    /// let mut scratch = [ShadedVertex::default(); 3];
    /// let shaded = shade(&mesh, &params, 32, 32, &mut scratch).unwrap();
    /// // 4 bands of 8 rows: a pair for the triangle, 4 + 1 list starts, and the triangle in
    /// // each of the 4 bands it spans.
    /// let mut bins = [0u32; 2 + 5 + 4];
    /// let binned = shaded.bin(8, &mut bins).unwrap();
    /// assert!(binned.has_band_lists());
    /// let (mut color, mut depth) = ([Rgb565(0); 32 * 8], [0u16; 32 * 8]);
    /// for band in Window::bands(32, 32, 8) {
    ///     let mut target = Target::window(&mut color, &mut depth, 32, 32, band, 32).unwrap();
    ///     target.clear(Rgb565(0));
    ///     assert_eq!(binned.draw(&mut target).unwrap().rasterized, 1);
    /// }
    /// ```
    pub fn bin(
        self,
        band_rows: usize,
        bins: &'a mut [u32],
    ) -> Result<BinnedMesh<'a, M>, DrawError> {
        let triangles = self.mesh.triangles().len();
        if band_rows == 0 {
            return Err(DrawError::Frame(TargetError::ZeroSize));
        }
        if bins.len() < triangles {
            return Err(DrawError::BinsTooSmall {
                needed: triangles,
                available: bins.len(),
            });
        }
        let bands = self.frame.1.div_ceil(band_rows);
        let pairs = bins.len() > 2 * triangles + bands && u32::try_from(triangles).is_ok();
        let (bins, stats) = if pairs {
            self.bin_pairs(band_rows, bands, bins)
        } else {
            self.bin_rows(&mut bins[..triangles])
        };
        Ok(BinnedMesh {
            shaded: self,
            bins,
            stats,
        })
    }

    /// Each triangle's rows into `rows` (see [`Bins::Rows`]).
    fn bin_rows(&self, rows: &'a mut [u32]) -> (Bins<'a>, DrawStats) {
        const EMPTY: u32 = 1; // first row 1, last row 0
        rows.fill(EMPTY);
        let stats = self.for_each_row_span(|t, first, last, keep| {
            rows[t] = if keep { pack_rows(first, last) } else { EMPTY };
        });
        // Each run of triangles that meet no row holds its remaining length, so that a band
        // steps over the run at once: the full-detail bunny on a small frame has five such
        // triangles to each one drawn.
        let mut run = 0u16;
        for row in rows.iter_mut().rev() {
            let (first, last) = unpack_rows(*row);
            if first > last {
                run = run.saturating_add(1);
                *row = pack_rows(SKIP, run);
            } else {
                run = 0;
            }
        }
        (Bins::Rows(rows), stats)
    }

    /// The pairs of the triangles that meet a row, and each band's list when it fits (see
    /// [`Bins::Pairs`]). A counting sort: the bands each triangle meets are counted as
    /// differences (+1 at its first band, -1 after its last), summed into each list's start,
    /// and the triangles dealt out.
    fn bin_pairs(
        &self,
        band_rows: usize,
        bands: usize,
        bins: &'a mut [u32],
    ) -> (Bins<'a>, DrawStats) {
        let (starts, rest) = bins.split_at_mut(bands + 1);
        starts.fill(0);
        let band_of = BandOf::new(band_rows);
        let mut len = 0;
        let stats = self.for_each_row_span(|t, first, last, keep| {
            // Written whether kept or not, and counted only if kept (without a branch). In
            // bounds: `rest` holds two entries per triangle, and a triangle not kept has rows
            // 0 and 0.
            let rows = pack_rows(first, last);
            rest[len] = t as u32;
            rest[len + 1] = rows;
            len += 2 * usize::from(keep);
            let (a, b) = band_of.span(rows);
            let kept = u32::from(keep);
            starts[a] = starts[a].wrapping_add(kept);
            starts[b + 1] = starts[b + 1].wrapping_sub(kept);
        });
        let (pairs, entries) = rest.split_at_mut(len);
        let (mut count, mut total) = (0u32, 0usize);
        for start in starts.iter_mut() {
            count = count.wrapping_add(*start);
            *start = total as u32;
            // Saturating: a total past `u32::MAX` does not fit, and must not wrap into fitting.
            total = total.saturating_add(count as usize);
        }
        let fits = total <= entries.len() && u32::try_from(total).is_ok();
        let lists = fits.then(|| {
            // Each band's start moves to its end (the next band's start) as it is dealt to ...
            for pair in pairs.chunks_exact(2) {
                let (a, b) = band_of.span(pair[1]);
                for start in &mut starts[a..=b] {
                    entries[*start as usize] = pair[0];
                    *start += 1;
                }
            }
            // ... so it moves back by one band.
            starts.copy_within(..bands, 1);
            starts[0] = 0;
            BandLists {
                band_rows,
                starts,
                entries: &entries[..total],
            }
        });
        (Bins::Pairs { pairs, lists }, stats)
    }

    /// The culling part of the triangle loop, once: calls `span(t, first, last, true)` with the
    /// pixel rows of each triangle `t` that meets a row (in order), and returns the frame's
    /// statistics. It may also call `span(t, 0, 0, false)` for a triangle that meets none, to
    /// be ignored.
    #[inline(always)]
    fn for_each_row_span(&self, span: impl FnMut(usize, u16, u16, bool)) -> DrawStats {
        // A model in view with back faces culled and no wireframe (the common case) has a loop
        // of its own, which reads no outcode and counts only the front faces: 0.7 million
        // fewer instructions a frame for the full bunny at 320x240 than the general loop with
        // its outcodes skipped, whose flags and counters spilled to the stack (before
        // `BRANCH_FREE`; no faster on x86-64, 0.4% fewer on the Cortex-M7).
        let params = self.params;
        if self.outside == 0 && params.cull_back_faces && params.wireframe.is_none() {
            self.front_spans(span)
        } else {
            self.row_spans(span)
        }
    }

    /// [`ShadedMesh::for_each_row_span`] with no vertex outside the clipping volume, back faces
    /// culled and no wireframe: a triangle is front-facing or culled, so only the front faces
    /// are counted.
    #[inline(always)]
    fn front_spans(&self, mut span: impl FnMut(usize, u16, u16, bool)) -> DrawStats {
        let triangles = self.mesh.triangles();
        let scratch = self.vertices;
        let frame = Window::full(self.frame.0, self.frame.1);
        let mut front = 0u32;
        for (t, tri) in triangles.iter().enumerate() {
            let (_, v) = corners(scratch, tri);
            let xy = v.map(|v| [v.x, v.y]);
            let area = signed_area2_xy(xy);
            if !Facing::Front.draws(area) {
                continue;
            }
            front += 1;
            // The rows of the pixel centres it may cover: a band without them has nothing of
            // it to fill. Bounds of one pixel centre: whether it covers that centre decides
            // whether any band draws it (most such triangles of a detailed mesh on a small
            // frame cover none).
            let [x0, x1, first, end] = pixel_box(xy, &frame);
            let any = (x0 <= x1) & (first <= end);
            let single = (x0 == x1) & (first == end);
            if BRANCH_FREE {
                // Each vertex is inside the clipping volume, so every bound is within the
                // guard band's range, and the edge functions at any of them fit.
                let keep = any & (!single | covers_centre(clockwise(area, xy), x0, first));
                let (first, end) = if keep { (first, end) } else { (0, 0) };
                span(t, first as u16, end as u16, keep);
            } else if any && (!single || covers_centre(clockwise(area, xy), x0, first)) {
                span(t, first as u16, end as u16, true);
            }
        }
        let submitted = triangles.len() as u32;
        DrawStats {
            submitted,
            rasterized: front,
            culled: submitted - front,
            ..DrawStats::default()
        }
    }

    /// [`ShadedMesh::for_each_row_span`] in general.
    #[inline(always)]
    fn row_spans(&self, mut span: impl FnMut(usize, u16, u16, bool)) -> DrawStats {
        let triangles = self.mesh.triangles();
        let (params, scratch) = (self.params, self.vertices);
        let facing = Facing::culling(params.cull_back_faces);
        let last = self.frame.1 as i32 - 1;
        let frame = Window::full(self.frame.0, self.frame.1);
        // Without a wireframe, a triangle that covers no pixel centre's box draws nothing.
        let outlined = params.wireframe.is_some();
        let mut stats = DrawStats {
            submitted: triangles.len() as u32,
            ..DrawStats::default()
        };
        for (t, tri) in triangles.iter().enumerate() {
            let ([i0, i1, i2], v) = corners(scratch, tri);
            let union = outcodes::<true>(&v);
            if union == 0 {
                let xy = v.map(|v| [v.x, v.y]);
                let area = signed_area2_xy(xy);
                if facing.draws(area) {
                    stats.rasterized += 1;
                } else {
                    stats.culled += 1;
                    if !outlined || facing == Facing::Front {
                        continue; // neither filled nor outlined
                    }
                }
                if !outlined {
                    // The rows of the pixel centres it may cover: a band without them has
                    // nothing of it to fill.
                    if let Some([x0, x1, first, end]) = pixel_bounds(xy, &frame) {
                        // Bounds of one pixel centre: whether it covers that centre decides
                        // whether any band draws it (most such triangles of a detailed mesh
                        // on a small frame cover none).
                        let single = (x0 == x1) & (first == end);
                        if !single || covers_centre(clockwise(area, xy), x0, first) {
                            span(t, first as u16, end as u16, true);
                        }
                    }
                    continue;
                }
                // Whole pixel rows: they hold the wireframe's pixels.
                let ys = v.map(|v| v.y >> SUBPIXEL_BITS);
                let first = ys[0].min(ys[1]).min(ys[2]).max(0);
                let end = ys[0].max(ys[1]).max(ys[2]).min(last);
                if first <= end {
                    span(t, first as u16, end as u16, true);
                }
                continue;
            }
            if needs_clipping(&v, union, &mut stats) {
                self.count_clipped(&[i0, i1, i2], union, facing, &mut stats);
                span(t, 0, last as u16, true);
            }
        }
        stats
    }

    /// Counts the pieces of a clipped triangle (vertex indices `tri`, outcodes' union `union`)
    /// as filled or culled. Out of line: few triangles need it, and inlined in the binning loop
    /// it held registers that loop wants.
    #[cold]
    #[inline(never)]
    fn count_clipped(&self, tri: &[u32; 3], union: u8, facing: Facing, stats: &mut DrawStats) {
        let colors = [[0.0; 3]; 3];
        let uvs = [[0.0; 2]; 3];
        for_each_clipped(
            &self.viewport,
            self.params,
            self.mesh,
            tri,
            colors,
            uvs,
            union,
            |s, _| {
                if facing.draws(signed_area2(s)) {
                    stats.rasterized += 1;
                } else {
                    stats.culled += 1;
                }
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::BandOf;

    #[test]
    fn the_band_of_a_row_is_its_quotient() {
        let heights = (1..=70).chain([100, 127, 128, 255, 256, 1000, 4095, 4096, 65535, 65536]);
        for band_rows in heights.chain([65537, 1 << 20, usize::MAX]) {
            let band_of = BandOf::new(band_rows);
            for row in 0..=u16::MAX {
                assert_eq!(
                    band_of.row(row),
                    usize::from(row) / band_rows,
                    "{row} / {band_rows}"
                );
            }
        }
    }
}
