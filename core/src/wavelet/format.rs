//! The semi-regular file (version 1), read in place from `&[u8]` without allocating.
//!
//! A semi-regular mesh is a base mesh `K0` and `J` levels of 4-to-1 subdivision. Its vertices
//! are those of `K^J`: the base vertices, then the points of each base edge, then the points
//! inside each base face. Every vertex that is not a base vertex is the centre of one lazy
//! wavelet (its level is the first subdivision that made it), so the file holds one record per
//! wavelet plus one per base vertex, and nothing else grows with the mesh: the connectivity of
//! every level is implicit in the base mesh (see [`super::lattice`]).
//!
//! Each record holds the vertex's position `rho(v)` on the finest surface. The lazy wavelet's
//! coefficient (Azuma et al. §3.2, `s = v - midpoint of the parent edge`) is that position minus
//! the midpoint of its parent edge's ends, derived at run time: storing it instead would cost the
//! same six bytes and make positions accumulate rounding down the levels.
//!
//! All little-endian, sections back to back in this order (`N = 2^J`, `V = base_vertices +
//! base_edges (N - 1) + base_faces (N - 1)(N - 2) / 2` vertices):
//!
//! | section | size | content |
//! |---|---|---|
//! | header | 64 | see below |
//! | faces | 36 per base face | corners `3 x u32` (counter-clockwise); edge ids `3 x u32` (edge `k` runs from corner `k` to corner `k + 1`); across `3 x u32`: `4 g + k'` when face `g`'s edge `k'` is the same edge run the other way, all ones on a border |
//! | edges | 4 per base edge | one face side holding it, `4 f + k` |
//! | vertices | 12 per vertex | position `3 x u16` (`origin + q * extent / 65535`); normal octahedral `2 x i8` (also the axis of the cone of normals); codes of the bounding radius, spheroid `a` and `b` ([`crate::format::decode_length`], in units of the header's length unit) and the cone's sine (`ceil(255 sin)`; 255: no useful cone), 8 bits each; zeros but the position and normal for a base vertex |
//! | colours | 3 per vertex, only with flag bit 0 | `3 x u8` |
//!
//! Header: offset 0 magic `VDLW`; 4 version `u16` = 1; 6 flags `u16` (bit 0: colours; bit 1:
//! the `a` and `b` codes hold Hoppe's `delta` and `mu` instead of the spheroid's radii; bit 2:
//! a height field); 8 `levels` (`J`, 1 to [`MAX_LEVELS`]), 12 `base_vertices`, 16
//! `base_faces`, 20 `base_edges` (`u32` each); 24 CRC-32 of everything after the header; 28
//! bounding-box origin `3 x f32`; 40 extent `3 x f32` (non-negative); 52 the length unit of the
//! bound codes, `f32`; 56 to 63 zero, but for a height field 56 its up axis and 57 its fine
//! levels.
//!
//! A height field (flag bit 2, [`super::heights`]) replaces the vertex section by a record per
//! base vertex, one `u16` height per wavelet and bounds per coarse wavelet and per block of
//! fine ones: about two bytes per vertex instead of twelve.
//!
//! Edge ids are numbered in the order the face sides first name them (face 0's edges 0, 1, 2,
//! then face 1's, ...; a side names a new edge unless its across side comes earlier), so that
//! [`SemiRegularView::parse`] proves every id names one edge of one or two faces without a table.
//! A vertex on base edge `e` at `t` steps from the edge's end with the smaller vertex id has id
//! `base_vertices + e (N - 1) + t - 1`; a point inside face `f` with weights `(N - i - j, i, j)`
//! has id `base_vertices + base_edges (N - 1) + f (N - 1)(N - 2) / 2` plus its rank in rows of
//! increasing `j`, then `i`.

use core::fmt;

use super::lattice::Point;
use crate::format::{cone_sine, crc32, oct_decode, u16_at, u32_at, ModelBox};
use crate::policy::Bounds;

/// First four bytes of a semi-regular file.
pub const MAGIC: [u8; 4] = *b"VDLW";
/// The version this crate reads and writes.
pub const VERSION: u16 = 1;
/// Header size in bytes.
pub const HEADER_SIZE: usize = 64;
/// Offset of the CRC-32 in the header.
pub const CRC_OFFSET: usize = 24;
/// Offset of the bounding-box origin, extent and length unit.
pub const BOX_OFFSET: usize = 28;
/// Bytes per base face.
pub const FACE_SIZE: usize = 36;
/// Bytes per base edge.
pub const EDGE_SIZE: usize = 4;
/// Bytes per vertex record.
pub const VERTEX_SIZE: usize = 12;
/// Bytes per colour.
pub const COLOR_SIZE: usize = 3;
/// Header flag: the vertices carry colours.
pub const FLAG_COLORS: u16 = 1;
/// Header flag: the `a` and `b` codes are Hoppe's `delta` and `mu` (see
/// [`crate::policy::HoppeError`]), not the spheroid's radii.
pub const FLAG_HOPPE: u16 = 2;
/// Header flag: a height field (see [`super::heights`]): one height per wavelet, and bounds per
/// coarse wavelet and per block of fine ones, instead of a record per vertex.
pub const FLAG_HEIGHTS: u16 = 4;
/// Bytes per height of a height field.
pub const HEIGHT_SIZE: usize = 2;
/// Bytes per bound record of a height field: the codes of the radius, `a` and the cone's sine.
pub const CODES_SIZE: usize = 3;
/// The most subdivision levels a file may have (`N = 4096` steps per base edge).
pub const MAX_LEVELS: u32 = 12;
/// "No face" in the across fields.
pub const NONE: u32 = u32::MAX;

/// Why bytes are not a valid semi-regular file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SemiRegularError {
    /// Shorter than the header, or than the header says the sections need.
    Truncated {
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        actual: u64,
    },
    /// Longer than the sections need.
    TrailingBytes {
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        actual: u64,
    },
    /// Not a semi-regular file.
    BadMagic,
    /// A version this crate does not read.
    UnsupportedVersion(u16),
    /// The header's counts are out of range or contradict each other.
    BadCounts(&'static str),
    /// The bounding box or length unit is not finite, or negative.
    BadBox,
    /// The checksum does not match: the bytes were corrupted.
    Checksum {
        /// Stored CRC-32.
        stored: u32,
        /// Computed CRC-32.
        computed: u32,
    },
    /// A base face is malformed.
    BadFace {
        /// The face.
        face: u32,
        /// What is wrong.
        what: &'static str,
    },
    /// A base edge's record is malformed.
    BadEdge {
        /// The edge.
        edge: u32,
        /// What is wrong.
        what: &'static str,
    },
}

impl fmt::Display for SemiRegularError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Truncated { needed, actual } => {
                write!(f, "truncated: {actual} bytes, {needed} needed")
            }
            Self::TrailingBytes { needed, actual } => {
                write!(f, "{actual} bytes, but the header describes {needed}")
            }
            Self::BadMagic => write!(f, "not a vdlod semi-regular mesh (bad magic)"),
            Self::UnsupportedVersion(v) => {
                write!(
                    f,
                    "semi-regular format version {v}, this build reads {VERSION}"
                )
            }
            Self::BadCounts(what) => write!(f, "bad header: {what}"),
            Self::BadBox => write!(f, "the header's bounding box is not finite"),
            Self::Checksum { stored, computed } => write!(
                f,
                "checksum mismatch (stored {stored:08x}, computed {computed:08x}): corrupted"
            ),
            Self::BadFace { face, what } => write!(f, "base face {face}: {what}"),
            Self::BadEdge { edge, what } => write!(f, "base edge {edge}: {what}"),
        }
    }
}

impl core::error::Error for SemiRegularError {}

/// The counts a header gives, and what follows from them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    /// Subdivision levels `J`.
    pub levels: u32,
    /// Vertices of the base mesh.
    pub base_vertices: u32,
    /// Faces of the base mesh.
    pub base_faces: u32,
    /// Edges of the base mesh.
    pub base_edges: u32,
}

impl Counts {
    /// Steps per base edge, `N = 2^J`.
    #[must_use]
    pub const fn steps(&self) -> u32 {
        1 << self.levels
    }

    /// Points strictly inside one base face: `(N - 1)(N - 2) / 2`.
    #[must_use]
    pub const fn inner_points(&self) -> u64 {
        let n = self.steps() as u64;
        (n - 1) * n.saturating_sub(2) / 2
    }

    /// Vertices of `K^J` (base vertices and wavelets).
    #[must_use]
    pub const fn vertices(&self) -> u64 {
        let n = self.steps() as u64;
        self.base_vertices as u64
            + self.base_edges as u64 * (n - 1)
            + self.base_faces as u64 * self.inner_points()
    }

    /// Faces of `K^J`: `4^J` per base face.
    #[must_use]
    pub const fn finest_faces(&self) -> u64 {
        self.base_faces as u64 * (1u64 << (2 * self.levels))
    }

    /// Byte offsets of the face, edge, vertex and colour sections and of the end (a file
    /// without [`FLAG_HEIGHTS`]).
    #[must_use]
    pub fn layout(&self, colors: bool) -> [u64; 5] {
        let s = self.sections(if colors { FLAG_COLORS } else { 0 }, 0);
        [s[0], s[1], s[2], s[6], s[7]]
    }

    /// Byte offsets of the face, edge, vertex record, height, coarse bound, fine bound and
    /// colour sections and of the end, for a file with header flags `flags` and (for a height
    /// field) `fine` fine levels (`fine <= J`).
    #[must_use]
    pub fn sections(&self, flags: u16, fine: u32) -> [u64; 8] {
        let heights = flags & FLAG_HEIGHTS != 0;
        let f = HEADER_SIZE as u64;
        let e = f + self.base_faces as u64 * FACE_SIZE as u64;
        let v = e + self.base_edges as u64 * EDGE_SIZE as u64;
        let records = if heights {
            self.base_vertices as u64
        } else {
            self.vertices()
        };
        let h = v + records * VERTEX_SIZE as u64;
        let (height_bytes, coarse, blocks) = if heights {
            let coarse = Counts {
                levels: self.levels.saturating_sub(fine),
                ..*self
            };
            let wavelets = self.vertices() - self.base_vertices as u64;
            let coarse_wavelets = coarse.vertices() - self.base_vertices as u64;
            // Blocks: the triangles of the coarse mesh, a record for each finer level.
            (
                wavelets * HEIGHT_SIZE as u64,
                coarse_wavelets * CODES_SIZE as u64,
                coarse.finest_faces() * fine as u64 * CODES_SIZE as u64,
            )
        } else {
            (0, 0, 0)
        };
        let c = h + height_bytes;
        let b = c + coarse;
        let colours = b + blocks;
        let end = colours
            + if flags & FLAG_COLORS != 0 {
                self.vertices() * COLOR_SIZE as u64
            } else {
                0
            };
        [f, e, v, h, c, b, colours, end]
    }
}

/// A validated semi-regular mesh, borrowed in place.
#[derive(Clone, Copy)]
pub struct SemiRegularView<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) counts: Counts,
    flags: u16,
    /// Offsets of the face, edge, vertex record, height, coarse bound, fine bound and colour
    /// sections.
    pub(super) offsets: [usize; 7],
    /// A height field's up axis and fine levels (see [`super::heights`]); zeros otherwise.
    pub(super) up: usize,
    pub(super) fine: u32,
    /// The positions' box and the bounds' unit.
    pub(super) model: ModelBox,
    /// `N`, and the number of vertices (which fits in `u32`).
    pub(super) n: i32,
    pub(super) vertices: u32,
    /// The id of the first point inside a face, and the points inside each face.
    pub(super) first_inner: u32,
    pub(super) inner: u32,
}

impl fmt::Debug for SemiRegularView<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SemiRegularView")
            .field("bytes", &self.bytes.len())
            .field("counts", &self.counts)
            .field("colors", &self.has_colors())
            .finish()
    }
}

impl<'a> SemiRegularView<'a> {
    /// Validates `bytes` and returns a view of them: sizes, magic, version, checksum, the
    /// header's counts and box, every base face's corners and edge ids, and the symmetry of the
    /// across links (a face side and its across side hold the same edge, run the other way), so
    /// that every lattice walk of [`super::lattice`] stays in range.
    pub fn parse(bytes: &'a [u8]) -> Result<SemiRegularView<'a>, SemiRegularError> {
        use SemiRegularError as E;
        if bytes.len() < HEADER_SIZE {
            return Err(E::Truncated {
                needed: HEADER_SIZE as u64,
                actual: bytes.len() as u64,
            });
        }
        if bytes[0..4] != MAGIC {
            return Err(E::BadMagic);
        }
        let version = u16_at(bytes, 4);
        if version != VERSION {
            return Err(E::UnsupportedVersion(version));
        }
        let flags = u16_at(bytes, 6);
        let heights = flags & FLAG_HEIGHTS != 0;
        let reserved = if heights { 58 } else { 56 };
        if flags & !(FLAG_COLORS | FLAG_HOPPE | FLAG_HEIGHTS) != 0
            || bytes[reserved..HEADER_SIZE].iter().any(|&b| b != 0)
        {
            return Err(E::BadCounts("unknown flags or non-zero reserved bytes"));
        }
        if heights && flags & FLAG_HOPPE != 0 {
            return Err(E::BadCounts("a height field has no Hoppe bounds"));
        }
        let (up, fine) = if heights {
            (bytes[56] as usize, bytes[57] as u32)
        } else {
            (0, 0)
        };
        let counts = Counts {
            levels: u32_at(bytes, 8),
            base_vertices: u32_at(bytes, 12),
            base_faces: u32_at(bytes, 16),
            base_edges: u32_at(bytes, 20),
        };
        if counts.levels == 0 || counts.levels > MAX_LEVELS {
            return Err(E::BadCounts("levels must be 1 to 12"));
        }
        if counts.base_vertices < 3 || counts.base_faces == 0 || counts.base_edges < 3 {
            return Err(E::BadCounts("a base mesh needs a face"));
        }
        if counts.base_faces >= 1 << 29 || counts.base_edges as u64 > 3 * counts.base_faces as u64 {
            return Err(E::BadCounts("more edges than face sides"));
        }
        if counts.vertices() >= 1 << 31 {
            return Err(E::BadCounts("more than 2^31 vertices"));
        }
        if heights && (up > 2 || fine == 0 || fine > counts.levels) {
            return Err(E::BadCounts(
                "a height field's up axis must be 0 to 2 and its fine levels 1 to its levels",
            ));
        }
        let model = ModelBox::read(bytes, BOX_OFFSET).ok_or(E::BadBox)?;
        let layout = counts.sections(flags, fine);
        let (needed, actual) = (layout[7], bytes.len() as u64);
        if actual < needed {
            return Err(E::Truncated { needed, actual });
        }
        if actual > needed {
            return Err(E::TrailingBytes { needed, actual });
        }
        let stored = u32_at(bytes, CRC_OFFSET);
        let computed = crc32(&bytes[HEADER_SIZE..]);
        if stored != computed {
            return Err(E::Checksum { stored, computed });
        }
        // The sections fit in `bytes`, so their offsets fit in usize.
        let view = SemiRegularView {
            bytes,
            counts,
            flags,
            offsets: core::array::from_fn(|k| layout[k] as usize),
            up,
            fine,
            model,
            n: 1 << counts.levels,
            vertices: counts.vertices() as u32,
            first_inner: counts.base_vertices + counts.base_edges * ((1u32 << counts.levels) - 1),
            inner: counts.inner_points() as u32,
        };
        view.check_faces()?;
        view.check_edges()?;
        Ok(view)
    }

    fn check_faces(&self) -> Result<(), SemiRegularError> {
        let mut next_edge = 0u32;
        for f in 0..self.counts.base_faces {
            let bad = |what| Err(SemiRegularError::BadFace { face: f, what });
            let c = self.corners(f);
            if c.iter().any(|&v| v >= self.counts.base_vertices) {
                return bad("corner out of range");
            }
            if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                return bad("a corner repeats");
            }
            for k in 0..3 {
                let e = self.face_edge(f, k);
                match self.across(f, k) {
                    Some((g, kk)) => {
                        if g >= self.counts.base_faces {
                            return bad("across face out of range");
                        }
                        if self.across(g, kk) != Some((f, k)) {
                            return bad("across link is not symmetric");
                        }
                        let cg = self.corners(g);
                        if cg[kk] != c[(k + 1) % 3] || cg[(kk + 1) % 3] != c[k] {
                            return bad("across edge is not the same edge run the other way");
                        }
                        if (g, kk) < (f, k) {
                            if self.face_edge(g, kk) != e {
                                return bad("across sides name different edges");
                            }
                            continue;
                        }
                    }
                    None if self.raw_across(f, k) != NONE => {
                        return bad("across field is neither a side nor all ones");
                    }
                    None => {}
                }
                if e != next_edge {
                    return bad("edge ids are not numbered in the order sides first name them");
                }
                next_edge += 1;
            }
        }
        if next_edge != self.counts.base_edges {
            return Err(SemiRegularError::BadCounts(
                "the faces name a different number of edges",
            ));
        }
        Ok(())
    }

    fn check_edges(&self) -> Result<(), SemiRegularError> {
        for e in 0..self.counts.base_edges {
            let (f, k) = self.edge_side(e);
            if f >= self.counts.base_faces || self.face_edge(f, k) != e {
                return Err(SemiRegularError::BadEdge {
                    edge: e,
                    what: "its side does not hold it",
                });
            }
        }
        Ok(())
    }

    /// The header's counts.
    #[must_use]
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// Subdivision levels `J`.
    #[must_use]
    pub fn levels(&self) -> u32 {
        self.counts.levels
    }

    /// Vertices of `K^J`.
    #[must_use]
    pub fn vertices(&self) -> u32 {
        self.vertices
    }

    /// Wavelets: every vertex but the base vertices.
    #[must_use]
    pub fn wavelets(&self) -> u32 {
        self.vertices - self.counts.base_vertices
    }

    /// Whether the vertices carry colours.
    #[must_use]
    pub fn has_colors(&self) -> bool {
        self.flags & FLAG_COLORS != 0
    }

    /// Size of the file in bytes.
    #[must_use]
    pub fn size(&self) -> usize {
        self.bytes.len()
    }

    /// Whether the `a` and `b` bounds are Hoppe's `delta` and `mu` rather than the spheroid's
    /// radii (flag bit 1).
    #[must_use]
    pub fn hoppe_bounds(&self) -> bool {
        self.flags & FLAG_HOPPE != 0
    }

    /// The box every position lies in, as its minimum and maximum corners.
    #[must_use]
    pub fn bounding_box(&self) -> ([f32; 3], [f32; 3]) {
        self.model.corners()
    }

    /// Base face `f`'s corners (out of range: all ones).
    #[inline]
    #[must_use]
    pub fn corners(&self, f: u32) -> [u32; 3] {
        let o = self.face_offset(f);
        match o.checked_add(12).and_then(|end| self.bytes.get(o..end)) {
            Some(b) => [0, 4, 8].map(|k| u32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]])),
            None => [NONE; 3],
        }
    }

    /// Corners `k` and `k + 1` of base face `f` and the id of the edge between them (edge `k`).
    #[inline]
    pub(super) fn edge_of(&self, f: u32, k: usize) -> ([u32; 2], u32) {
        let o = self.face_offset(f);
        let at = |offset: usize| u32_at(self.bytes, o.saturating_add(offset));
        ([at(4 * k), at(4 * ((k + 1) % 3))], at(12 + 4 * k))
    }

    /// The id of base face `f`'s edge `k` (from corner `k` to corner `k + 1`).
    #[inline]
    #[must_use]
    pub fn face_edge(&self, f: u32, k: usize) -> u32 {
        u32_at(self.bytes, self.face_offset(f).saturating_add(12 + 4 * k))
    }

    #[inline]
    fn raw_across(&self, f: u32, k: usize) -> u32 {
        u32_at(self.bytes, self.face_offset(f).saturating_add(24 + 4 * k))
    }

    /// The face and edge across base face `f`'s edge `k`; `None` on a border.
    #[inline]
    #[must_use]
    pub fn across(&self, f: u32, k: usize) -> Option<(u32, usize)> {
        let a = self.raw_across(f, k);
        (a != NONE && a & 3 != 3).then_some((a >> 2, (a & 3) as usize))
    }

    /// A face side `(f, k)` holding base edge `e`.
    #[inline]
    #[must_use]
    pub fn edge_side(&self, e: u32) -> (u32, usize) {
        let o = (e as usize)
            .checked_mul(EDGE_SIZE)
            .and_then(|o| o.checked_add(self.offsets[1]))
            .unwrap_or(usize::MAX);
        let a = u32_at(self.bytes, o);
        (a >> 2, (a & 3).min(2) as usize)
    }

    #[inline]
    fn face_offset(&self, f: u32) -> usize {
        (f as usize)
            .checked_mul(FACE_SIZE)
            .and_then(|o| o.checked_add(self.offsets[0]))
            .unwrap_or(usize::MAX)
    }

    /// Vertex `v`'s 12-byte record (zeros out of range; a height field has records for its base
    /// vertices only).
    #[inline]
    pub(super) fn record(&self, v: u32) -> [u8; VERTEX_SIZE] {
        if self.is_height_field() && v >= self.counts.base_vertices {
            return [0; VERTEX_SIZE];
        }
        let o = (v as usize)
            .checked_mul(VERTEX_SIZE)
            .and_then(|o| o.checked_add(self.offsets[2]));
        o.and_then(|o| self.bytes.get(o..o + VERTEX_SIZE))
            .and_then(|s| s.try_into().ok())
            .unwrap_or([0; VERTEX_SIZE])
    }

    /// Whether this is a height field (flag bit 2, see [`super::heights`]).
    #[inline]
    #[must_use]
    pub fn is_height_field(&self) -> bool {
        self.flags & FLAG_HEIGHTS != 0
    }

    /// Vertex `v`'s position on the finest surface, `rho(v)`.
    #[inline]
    #[must_use]
    pub fn position(&self, v: u32) -> [f32; 3] {
        if self.is_height_field() && v >= self.counts.base_vertices {
            return self.height_position(v);
        }
        self.model.position(&self.record(v))
    }

    /// [`SemiRegularView::position`] of vertex `v` at lattice point `p` (in the frame of any
    /// base face holding it; a caller that has the point saves finding it again).
    #[inline]
    #[must_use]
    pub fn position_at(&self, p: Point, v: u32) -> [f32; 3] {
        if self.is_height_field() {
            return self.height_position_at(p, v);
        }
        self.position(v)
    }

    /// Vertex `v`'s normal (unit length).
    #[inline]
    #[must_use]
    pub fn normal(&self, v: u32) -> [f32; 3] {
        if self.is_height_field() {
            return self.height_normal(v);
        }
        let r = self.record(v);
        oct_decode(r[6] as i8, r[7] as i8)
    }

    /// Vertex `v`'s colour: white without colours, black out of range.
    #[inline]
    #[must_use]
    pub fn color(&self, v: u32) -> [u8; 3] {
        if !self.has_colors() {
            return [255; 3];
        }
        let o = (v as usize)
            .checked_mul(COLOR_SIZE)
            .and_then(|o| o.checked_add(self.offsets[6]));
        o.and_then(|o| self.bytes.get(o..o + COLOR_SIZE))
            .and_then(|s| s.try_into().ok())
            .unwrap_or([0; 3])
    }

    /// The length a bound code stands for in this file's units.
    #[inline]
    #[must_use]
    pub fn length(&self, code: u8) -> f32 {
        self.model.length(code)
    }

    /// What the refinement policies need of wavelet vertex `v`: its position, the radius of a
    /// sphere around it holding the image of its support, its normal cone and its error
    /// spheroid (Azuma et al. §3.3).
    #[inline]
    #[must_use]
    pub fn bounds(&self, v: u32) -> Bounds {
        if self.is_height_field() {
            return self.height_bounds(v);
        }
        let r = self.record(v);
        let (a, b) = (self.length(r[9]), self.length(r[10]));
        Bounds {
            center: self.model.position(&r),
            radius: self.length(r[8]),
            axis: oct_decode(r[6] as i8, r[7] as i8),
            cone_sin: cone_sine(r[11]),
            a2: a * a,
            b2: b * b,
        }
    }

    /// [`SemiRegularView::bounds`] of vertex `v` whose canonical point is `p` (a caller that
    /// has the point saves finding it again).
    #[inline]
    #[must_use]
    pub fn bounds_at(&self, p: Point, v: u32) -> Bounds {
        if self.is_height_field() {
            return self.height_bounds_at(p, v);
        }
        self.bounds(v)
    }

    /// The raw bound codes of vertex `v` (radius, `a`, `b`, cone sine).
    #[must_use]
    pub fn codes(&self, v: u32) -> [u8; 4] {
        if self.is_height_field() {
            let [r, a, c] = self.height_codes(v);
            return [r, a, 0, c];
        }
        let r = self.record(v);
        [r[8], r[9], r[10], r[11]]
    }
}
