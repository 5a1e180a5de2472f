//! The hierarchy file format (version 4), read in place from `&[u8]` without allocating.
//!
//! A device keeps the bytes in flash (`include_bytes!`) and reads them through a [`HierarchyView`]:
//! [`HierarchyView::parse`] checks everything once (sizes, magic, version, checksum, every index in
//! range, parent links acyclic and consistent with the children, header floats finite) so that
//! hostile or corrupted bytes give a [`FormatError`], never a panic; afterwards every accessor is a
//! bounds-safe little-endian read.
//!
//! The format is laid out for size (about 31 bytes per input vertex, against 37 for version 3
//! and 100 for version 2): positions are 16-bit fractions of the model's bounding box, bounds are
//! 8-bit logarithms in units of the box's diagonal (so a model built at any scale gives the same
//! file but for the header, and the same cut), triangle ids are bit-packed at the width the counts
//! need, leaves carry no bounds (they never split), a split's wings are not stored (the cut reads
//! them off its neighbours) and neither are depths (walked when asked for).
//!
//! **Numbering.** Nodes are numbered breadth first, coarse to fine: the `roots = 2 leaves - nodes`
//! roots are `0..roots`, and the children of the `k`-th parent (in id order) are the sibling pair
//! `roots + 2k` and `roots + 2k + 1`. So a parent's children are never stored (they follow from
//! how many parents come before it, counted with the kind bits below), a parent is stored once
//! per pair, records of siblings are adjacent, and every node has a larger id than its parent.
//! Leaves are wherever the numbering puts them; an input vertex's id is not its input index
//! (the builder reports the mapping: `Hierarchy::file_ids`).
//!
//! All little-endian, sections back to back in this order; `parents = nodes - leaves`, `w_n` =
//! the bits that hold a node id below `nodes` and all-ones as "none" (`id_width(nodes)`), `w_f`
//! the same for triangle ids below `faces = base_triangles + 2 parents`:
//!
//! | section | size | content |
//! |---|---|---|
//! | header | 64 | see below |
//! | kinds | 12 per block of 64 nodes | the number of parents among the nodes before the block (`u32`), then one bit per node of the block, set for a parent (`u64`; bits past `nodes` zero) |
//! | nodes | 8 per leaf, 12 per parent, in id order (node `i` at `8 i + 4 rank(i)`, `rank(i)` the parents below `i`) | position `3 x u16` (`origin + q * extent / 65535`); normal octahedral `2 x i8` (also the axis of the cone of normals); for a parent then the codes of its radius, spheroid `a`, spheroid `b` ([`decode_length`]; with flag bit 1 Hoppe's `delta`, `mu`) and the cone's sine (`ceil(255 sin)`; 255: no useful cone), 8 bits each, so that everything the refinement test reads of a vertex is one record |
//! | colours | 3 per node, only with flag bit 0 | `3 x u8` |
//! | parents | `w_n` bits per sibling pair, padded to a byte | the pair's parent |
//! | splits | `4 w_f` bits per parent, padded to a byte | neighbour triangles `n0..n3` (`w_f` bits each, all ones for none) |
//! | base triangles | 12 each | `3 x u32` root ids, counter-clockwise |
//!
//! Header: offset 0 magic `VDLH`; 4 version `u16` = 4; 6 flags `u16` (bit 0: colours; bit 1:
//! the `a` and `b` codes are Hoppe's `delta` and `mu`, [`FLAG_HOPPE`]); 8
//! `leaves`, 12 `nodes`, 16 `base_triangles` (`u32` each); 20 CRC-32 of everything after the
//! header ([`CRC_OFFSET`]); 24 bounding-box origin `3 x f32`; 36 extent `3 x f32` (non-negative);
//! 48 the length unit of the bounds, `f32` (the box's diagonal); 52 to 63 zero.
//!
//! Bits are packed least significant first: field `k` of a section starts at bit `k * width`,
//! and bit `b` is bit `b % 8` of byte `b / 8`.
//!
//! Triangles have ids too ([`SplitView::faces`]): base triangle `k` is `k`, and the
//! split of the `k`-th parent adds triangle `base + 2k` = `(c0, c1, w0)` and, when it has a
//! second triangle (a neighbour `n2` or `n3`), the next id = `(c1, c0, w1)`. A split record's
//! neighbours are the triangles across those two triangles' outer edges (`c1-w0`, `w0-c0`,
//! `c0-w1`, `w1-c1`), the `fn0..fn3` of Hoppe's "View-dependent refinement of progressive meshes"
//! (1997): a split is legal when its neighbours exist, which is what the runtime cut checks and,
//! when they do not, forces. `parse` checks that no neighbour is made by the split itself or by a
//! split below it; the builder's files do every split legally in the reverse of its collapse
//! order, and the cut's forcing refuses a crafted file whose splits wait on each other.

use core::fmt;
use core::hint::select_unpredictable;

use crate::policy::dot;

/// First four bytes of a hierarchy file.
pub const MAGIC: [u8; 4] = *b"VDLH";
/// The version this crate reads and writes.
pub const VERSION: u16 = 4;
/// Header size in bytes.
pub const HEADER_SIZE: usize = 64;
/// Offset of the CRC-32 in the header.
pub const CRC_OFFSET: usize = 20;
/// Offsets of the `leaves`, `nodes` and `base_triangles` counts in the header.
pub const COUNT_OFFSETS: [usize; 3] = [8, 12, 16];
/// Offset of the bounding-box origin, extent and length unit in the header.
pub const BOX_OFFSET: usize = 24;
/// Bytes per leaf record.
pub const NODE_SIZE: usize = 8;
/// Bytes per parent record (a node record and four bound codes).
pub const PARENT_SIZE: usize = 12;
/// Nodes per block of kind bits.
pub const KIND_BLOCK: u32 = 64;
/// Bytes per block of kind bits: the parents before the block (`u32`) and the block's bits.
pub const KIND_SIZE: usize = 12;
/// Bytes per colour record.
pub const COLOR_SIZE: usize = 3;
/// Bytes per base triangle.
pub const TRIANGLE_SIZE: usize = 12;
/// "No node" / "no triangle" as the accessors return it.
pub const NONE: u32 = u32::MAX;
/// Header flag: the nodes carry meaningful colours.
pub const FLAG_COLORS: u16 = 1;
/// Header flag: a parent's `a` and `b` codes are Hoppe's `delta` and `mu` (a sphere of radius
/// `mu` swept along the normal by `delta`, read by [`crate::policy::HoppeError`]) instead of a
/// normal-aligned spheroid.
pub const FLAG_HOPPE: u16 = 2;
/// Quantization steps of a position coordinate over the bounding box.
pub const POSITION_STEPS: f32 = 65535.0;

/// Why bytes are not a valid hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatError {
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
    /// Not a hierarchy file.
    BadMagic,
    /// A version this crate does not read.
    UnsupportedVersion(u16),
    /// The counts in the header contradict each other, or a reserved field is not zero.
    BadCounts,
    /// The bounding box or length unit in the header is not finite, or negative.
    BadBox,
    /// The checksum does not match: the bytes were corrupted.
    Checksum {
        /// Stored CRC-32.
        stored: u32,
        /// Computed CRC-32.
        computed: u32,
    },
    /// A node's field is out of range or inconsistent.
    BadNode {
        /// The node.
        node: u32,
        /// What is wrong.
        what: &'static str,
    },
    /// A base triangle refers to a missing or non-root node.
    BadReference {
        /// The section.
        section: &'static str,
        /// The entry.
        index: u32,
    },
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FormatError::Truncated { needed, actual } => {
                write!(f, "truncated: {actual} bytes, {needed} needed")
            }
            FormatError::TrailingBytes { needed, actual } => {
                write!(f, "{actual} bytes, but the header describes {needed}")
            }
            FormatError::BadMagic => write!(f, "not a vdlod hierarchy (bad magic)"),
            FormatError::UnsupportedVersion(v) if v < VERSION => write!(
                f,
                "format version {v} is older than this build's version {VERSION}: rebuild the \
                 file from its mesh (vdlod-demo build MESH -o FILE)"
            ),
            FormatError::UnsupportedVersion(v) => {
                write!(f, "format version {v}, this build reads version {VERSION}")
            }
            FormatError::BadCounts => write!(f, "inconsistent counts in the header"),
            FormatError::BadBox => write!(f, "the header's bounding box is not finite"),
            FormatError::Checksum { stored, computed } => write!(
                f,
                "checksum mismatch (stored {stored:08x}, computed {computed:08x}): corrupted"
            ),
            FormatError::BadNode { node, what } => write!(f, "node {node}: {what}"),
            FormatError::BadReference { section, index } => {
                write!(f, "{section} entry {index} refers to an invalid node")
            }
        }
    }
}

impl core::error::Error for FormatError {}

const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

/// CRC-32 (IEEE 802.3, as in zip and PNG).
#[must_use]
pub fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(!0u32, |c, &b| {
        CRC_TABLE[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8)
    })
}

/// `2^(j / 16)` for `j` in `0..16`, the mantissas of the length codes.
#[allow(clippy::excessive_precision)]
const OCTAVE: [f32; 16] = [
    1.0,
    1.044_273_8,
    1.090_507_7,
    1.138_788_6,
    1.189_207_1,
    1.241_857_8,
    1.296_839_6,
    1.354_256_6,
    core::f32::consts::SQRT_2,
    1.476_826_1,
    1.542_210_8,
    1.610_490_2,
    1.681_792_8,
    1.756_252_1,
    1.834_008_1,
    1.915_206_6,
];

/// The length an 8-bit code stands for, in units of the file's length unit: 0 for code 0, else
/// `2^((code - 224) / 16)` (from about `6e-5` to `3.8`, 4.4% apart): a table made at compile time
/// (one multiplication each, exact on every target), no `exp`.
#[inline]
#[must_use]
pub fn decode_length(code: u8) -> f32 {
    LENGTHS[code as usize]
}

/// [`decode_length`] of every code.
const LENGTHS: [f32; 256] = {
    let mut t = [0.0f32; 256];
    let mut k = 1;
    while k < 256 {
        let octave = (k >> 4) as i32 - 14;
        t[k] = OCTAVE[k & 15] * f32::from_bits(((octave + 127) as u32) << 23);
        k += 1;
    }
    t
};

/// `k / 255` for every cone code `k`, the sine it stands for.
const CONE_SINES: [f32; 256] = {
    let mut t = [0.0f32; 256];
    let mut k = 0;
    while k < 256 {
        t[k] = k as f32 / 255.0;
        k += 1;
    }
    t
};

/// The sine a cone code stands for (`code / 255`).
#[inline(always)]
pub(crate) fn cone_sine(code: u8) -> f32 {
    CONE_SINES[code as usize]
}

/// The model's bounding box and length unit as both file formats store them (seven `f32`s:
/// origin, extent, unit): positions are 16-bit fractions of the box ([`POSITION_STEPS`] steps
/// per axis), bound codes lengths in the unit ([`decode_length`]), so a model built at any scale
/// gives the same file but for these seven numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ModelBox {
    /// Position of quantum 0, size of one quantum per axis, and the length unit.
    origin: [f32; 3],
    step: [f32; 3],
    unit: f32,
    /// The box's size as stored (only a writer needs it again).
    #[cfg_attr(not(feature = "build"), allow(dead_code))]
    extent: [f32; 3],
}

impl ModelBox {
    #[cfg(feature = "build")]
    const ZERO: ModelBox = ModelBox {
        origin: [0.0; 3],
        step: [0.0; 3],
        unit: 1.0,
        extent: [0.0; 3],
    };

    fn new(origin: [f32; 3], extent: [f32; 3], unit: f32) -> ModelBox {
        ModelBox {
            origin,
            step: extent.map(|e| e / POSITION_STEPS),
            unit,
            extent,
        }
    }

    /// The box stored at byte `offset`; `None` when a number is not finite, an extent is
    /// negative or the unit is not positive.
    pub(crate) fn read(bytes: &[u8], offset: usize) -> Option<ModelBox> {
        let float = |k: usize| f32_at(bytes, offset.saturating_add(4 * k));
        let origin = [float(0), float(1), float(2)];
        let extent = [float(3), float(4), float(5)];
        let unit = float(6);
        let valid = origin.iter().chain(&extent).all(|c| c.is_finite())
            && extent.iter().all(|&e| e >= 0.0)
            && unit.is_finite()
            && unit > 0.0;
        valid.then(|| ModelBox::new(origin, extent, unit))
    }

    /// The box around `points` with its diagonal as the unit (1 when the diagonal is zero; a
    /// box at the origin for no points).
    #[cfg(feature = "build")]
    pub(crate) fn around(points: impl Iterator<Item = [f32; 3]>) -> ModelBox {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        let mut any = false;
        for p in points {
            any = true;
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if !any {
            return ModelBox::ZERO;
        }
        let extent = [0, 1, 2].map(|k| (hi[k] - lo[k]).max(0.0));
        let diagonal = crate::root::sqrtf(extent.iter().map(|e| e * e).sum::<f32>());
        let unit = if diagonal.is_finite() && diagonal > 0.0 {
            diagonal
        } else {
            1.0
        };
        ModelBox::new(lo, extent, unit)
    }

    /// Writes the seven numbers at byte `offset` of `out`.
    #[cfg(feature = "build")]
    pub(crate) fn write(&self, out: &mut [u8], offset: usize) {
        for (k, v) in self
            .origin
            .iter()
            .chain(&self.extent)
            .chain([&self.unit])
            .enumerate()
        {
            let o = offset + 4 * k;
            out[o..o + 4].copy_from_slice(&v.to_le_bytes());
        }
    }

    /// The nearest 16-bit fractions of the box to `p`.
    #[cfg(feature = "build")]
    pub(crate) fn quantize(&self, p: [f32; 3]) -> [u16; 3] {
        [0, 1, 2].map(|k| {
            if self.step[k] > 0.0 {
                libm::roundf((p[k] - self.origin[k]) / self.step[k]).clamp(0.0, POSITION_STEPS)
                    as u16
            } else {
                0
            }
        })
    }

    /// A quantized position in the model's coordinates.
    #[inline(always)]
    pub(crate) fn dequantize(&self, q: [u16; 3]) -> [f32; 3] {
        [
            self.origin[0] + q[0] as f32 * self.step[0],
            self.origin[1] + q[1] as f32 * self.step[1],
            self.origin[2] + q[2] as f32 * self.step[2],
        ]
    }

    /// The position a record starts with (`3 x u16`, little-endian).
    #[inline(always)]
    pub(crate) fn position(&self, r: &[u8]) -> [f32; 3] {
        let q = |k: usize| u16_at(r, 2 * k);
        self.dequantize([q(0), q(1), q(2)])
    }

    /// The box's minimum and maximum corners.
    pub(crate) fn corners(&self) -> ([f32; 3], [f32; 3]) {
        let max = core::array::from_fn(|k| self.origin[k] + self.step[k] * POSITION_STEPS);
        (self.origin, max)
    }

    /// The length unit of the bound codes.
    pub(crate) fn unit(&self) -> f32 {
        self.unit
    }

    /// The length a bound code stands for.
    #[inline(always)]
    pub(crate) fn length(&self, code: u8) -> f32 {
        LENGTHS[code as usize] * self.unit
    }
}

/// The smallest code whose length is at least `v` (in the file's unit), so that a bound stays a
/// bound; 0 for `v <= 0` or NaN; 255 (the largest length) above it.
#[must_use]
pub fn encode_length(v: f32) -> u8 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    let (mut lo, mut hi) = (1u8, 255u8);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if decode_length(mid) >= v {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// The number of bits that hold every id below `count` and an all-ones "none" above them.
#[must_use]
pub const fn id_width(count: u32) -> u32 {
    32 - count.leading_zeros()
}

/// The bits of one split record.
#[must_use]
pub const fn split_bits(face_width: u32) -> u64 {
    4 * face_width as u64
}

/// Encodes a unit vector as octahedral coordinates in `[-127, 127]` (nearest).
pub fn oct_encode(n: [f32; 3]) -> (i8, i8) {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    let usable = l1 > 0.0 && l1.is_finite();
    if !usable {
        return (0, 0);
    }
    let (mut u, mut v) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        let (ou, ov) = (u, v);
        u = (1.0 - ov.abs()) * if ou >= 0.0 { 1.0 } else { -1.0 };
        v = (1.0 - ou.abs()) * if ov >= 0.0 { 1.0 } else { -1.0 };
    }
    let q = |x: f32| round_small(x.clamp(-1.0, 1.0) * 127.0);
    (q(u), q(v))
}

/// `libm::roundf(x) as i8` (halves away from zero) for `x` in `[-127, 127]` or NaN (0), without
/// the call: `x` less its integer part toward zero is exact there (Sterbenz), so comparing it
/// with a half decides as `roundf` does.
fn round_small(x: f32) -> i8 {
    let whole = x as i32;
    let rest = x - whole as f32;
    (whole + i32::from(rest >= 0.5) - i32::from(rest <= -0.5)) as i8
}

/// Decodes octahedral coordinates in `[-127, 127]` to a unit vector (one square root and one
/// division: the policies decode an axis per vertex per frame).
#[inline]
pub fn oct_decode(x: i8, y: i8) -> [f32; 3] {
    let w = oct_unfold(x, y);
    // Never zero: the components' magnitudes add up to 127.
    scale(w, 1.0 / crate::root::sqrtf(dot(w, w)))
}

/// [`oct_decode`] before normalizing: in units of 1/127, `|u| + |v| + |z| = 127`. The lower
/// hemisphere's fold is computed always and selected, so that it costs no branch (a plain `if`
/// compiled to one, which mispredicts on every other record).
#[inline(always)]
fn oct_unfold(x: i8, y: i8) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    let z = 127.0 - x.abs() - y.abs();
    let sign = |a: f32| select_unpredictable(a >= 0.0, 1.0, -1.0);
    let fold = z < 0.0;
    let u = select_unpredictable(fold, (127.0 - y.abs()) * sign(x), x);
    let v = select_unpredictable(fold, (127.0 - x.abs()) * sign(y), y);
    [u, v, z]
}

#[inline(always)]
fn scale(w: [f32; 3], by: f32) -> [f32; 3] {
    [w[0] * by, w[1] * by, w[2] * by]
}

/// A validated hierarchy, borrowed in place.
#[derive(Clone, Copy)]
pub struct HierarchyView<'a> {
    bytes: &'a [u8],
    flags: u16,
    leaves: u32,
    nodes: u32,
    /// Nodes `0..roots` are the roots.
    roots: u32,
    base_triangles: u32,
    /// Bits of a node id and of a triangle id.
    node_width: u32,
    face_width: u32,
    /// Byte offsets of the kind, node, colour, parent, split and base-triangle sections.
    offsets: [usize; 6],
    /// The positions' box and the bounds' unit.
    model: ModelBox,
}

impl fmt::Debug for HierarchyView<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("HierarchyView")
            .field("bytes", &self.bytes.len())
            .field("leaves", &self.leaves)
            .field("nodes", &self.nodes)
            .field("base_triangles", &self.base_triangles)
            .field("colors", &self.has_colors())
            .finish()
    }
}

/// One node, read from a [`HierarchyView`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeView {
    /// Position.
    pub position: [f32; 3],
    /// Bounding-sphere radius of the node's region and all its descendants' (0 for a leaf).
    pub radius: f32,
    /// The wavelet paper's spheroid `[a, b]` (0 for a leaf).
    pub spheroid: [f32; 2],
    /// Normal, and axis of the cone of normals (unit length, from 8-bit octahedral coordinates).
    pub normal: [f32; 3],
    /// Sine of the cone's half-angle, rounded up; 1 when the cone bounds nothing (and for a leaf).
    pub cone_sin: f32,
    /// Colour (white without colours).
    pub color: [u8; 3],
    /// Depth in the forest (0 for roots), counted by walking the parents.
    pub depth: u16,
    /// Parent, or [`NONE`].
    pub parent: u32,
}

/// What a cut keeps of an active node so that most frames need not read its record: the
/// quantized position, and the codes of its larger spheroid radius and of its bounding radius
/// (zeros for a leaf). Eight bytes; [`HierarchyView::digest_center`] and
/// [`HierarchyView::length`] decode them exactly as [`HierarchyView::bounds`] does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Digest {
    /// Position as 16-bit fractions of the bounding box.
    pub position: [u16; 3],
    /// Code of `max(a, b)`.
    pub spheroid: u8,
    /// Code of the bounding radius.
    pub radius: u8,
}

impl Digest {
    /// All zeros.
    pub const ZERO: Digest = Digest {
        position: [0; 3],
        spheroid: 0,
        radius: 0,
    };
}

/// Where a node's record is in a [`HierarchyView`] ([`HierarchyView::record`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Record {
    /// Byte offset (`usize::MAX` for a node out of range).
    offset: usize,
    /// Whether it is a parent's record.
    parent: bool,
}

impl Record {
    /// Whether it is a parent's record (the node splits).
    #[inline(always)]
    #[must_use]
    pub fn is_parent(&self) -> bool {
        self.parent
    }
}

/// One parent's split record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitView {
    /// The two children.
    pub children: [u32; 2],
    /// The ids of the triangles the split adds (the second means nothing unless
    /// [`SplitView::second`]).
    pub faces: [u32; 2],
    /// Triangles across the added triangles' outer edges (`c1-w0`, `w0-c0`, `c0-w1`, `w1-c1`),
    /// or [`NONE`].
    pub neighbours: [u32; 4],
}

impl SplitView {
    /// No split: what a leaf (or an id out of range) has.
    pub const NONE: SplitView = SplitView {
        children: [NONE; 2],
        faces: [NONE; 2],
        neighbours: [NONE; 4],
    };

    /// Whether the split adds a second triangle (it is not on a border).
    #[inline]
    #[must_use]
    pub fn second(&self) -> bool {
        self.neighbours[2] != NONE || self.neighbours[3] != NONE
    }
}

/// Offset of record `index` of `size` bytes in a section at `base`; `usize::MAX` (which reads as
/// nothing) when it overflows, as it can on 16- and 32-bit targets for out-of-range ids.
#[inline]
fn record(base: usize, index: u32, size: usize) -> usize {
    (index as usize)
        .checked_mul(size)
        .and_then(|o| o.checked_add(base))
        .unwrap_or(usize::MAX)
}

#[inline]
pub(crate) fn u16_at(b: &[u8], o: usize) -> u16 {
    match b.get(o..o.saturating_add(2)) {
        Some(s) => u16::from_le_bytes([s[0], s[1]]),
        None => 0,
    }
}

#[inline]
pub(crate) fn u32_at(b: &[u8], o: usize) -> u32 {
    match b.get(o..o.saturating_add(4)) {
        Some(s) => u32::from_le_bytes([s[0], s[1], s[2], s[3]]),
        None => NONE,
    }
}

#[inline]
fn f32_at(b: &[u8], o: usize) -> f32 {
    f32::from_bits(u32_at(b, o))
}

/// `width` (at most 32) bits at bit `bit` of `b`, least significant first; bits past the end
/// read as ones.
#[inline]
fn bits_at(b: &[u8], bit: u64, width: u32) -> u32 {
    word_at(b, bit) as u32 & low(width)
}

/// The 64 bits from bit `bit` of `b` on, shifted so that bit `bit` is bit 0 (at least 57 of
/// them read from `b`); bytes past the end read as ones.
#[inline]
fn word_at(b: &[u8], bit: u64) -> u64 {
    let byte = usize::try_from(bit / 8).unwrap_or(usize::MAX);
    let word = match b.get(byte..byte.saturating_add(8)) {
        Some(s) => u64::from_le_bytes([s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]]),
        // Near the end of the file: the slow window, ones past the end.
        None => window(b, bit & !7) as u64,
    };
    word >> (bit % 8)
}

/// The low `width` bits set (all for 32 and more).
#[inline(always)]
fn low(width: u32) -> u32 {
    if width >= 32 {
        u32::MAX
    } else {
        (1u32 << width) - 1
    }
}

/// The 128 bits from bit `bit` of `b` on, least significant first, shifted so that bit `bit` is
/// bit 0 (the top `bit % 8` bits are zeros); bytes past the end read as ones.
#[inline]
fn window(b: &[u8], bit: u64) -> u128 {
    let byte = usize::try_from(bit / 8).unwrap_or(usize::MAX);
    // Two loads when the 16 bytes are there (a copy into a shared array made it sixteen).
    if let Some(Ok(w)) = b
        .get(byte..byte.saturating_add(16))
        .map(<[u8; 16]>::try_from)
    {
        return u128::from_le_bytes(w) >> (bit % 8);
    }
    window_at_end(b, byte) >> (bit % 8)
}

/// [`window`]'s 16 bytes from `byte` on, near the end of `b`.
#[cold]
#[inline(never)]
fn window_at_end(b: &[u8], byte: usize) -> u128 {
    let w: [u8; 16] =
        core::array::from_fn(|k| b.get(byte.saturating_add(k)).copied().unwrap_or(0xFF));
    u128::from_le_bytes(w)
}

/// An id read at `width` bits: all ones becomes [`NONE`].
#[inline]
fn id(raw: u32, width: u32) -> u32 {
    field_id(raw, low(width))
}

/// The id in the low bits `mask` ([`low`] of its width) of `raw`, all ones becoming [`NONE`]:
/// one more than the field, kept to the field and less one, so that all ones wraps round to
/// zero and from there to [`NONE`] (`u32::MAX`), without a test.
#[inline(always)]
fn field_id(raw: u32, mask: u32) -> u32 {
    (raw.wrapping_add(1) & mask).wrapping_sub(1)
}

impl<'a> HierarchyView<'a> {
    /// Byte offsets of the sections (kinds, nodes, colours, parents, splits, base triangles) and
    /// the end, for the counts of a header.
    fn layout(leaves: u32, nodes: u32, base: u32, colors: bool) -> [u64; 7] {
        let parents = (nodes - leaves) as u64;
        let (wn, wf) = (id_width(nodes), id_width(faces_of(leaves, nodes, base)));
        let k = HEADER_SIZE as u64;
        let n = k + (nodes as u64).div_ceil(KIND_BLOCK as u64) * KIND_SIZE as u64;
        let c = n + leaves as u64 * NODE_SIZE as u64 + parents * PARENT_SIZE as u64;
        let p = c + if colors {
            nodes as u64 * COLOR_SIZE as u64
        } else {
            0
        };
        let s = p + (parents * wn as u64).div_ceil(8);
        let b = s + (parents * split_bits(wf)).div_ceil(8);
        let end = b + base as u64 * TRIANGLE_SIZE as u64;
        [k, n, c, p, s, b, end]
    }

    /// Validates `bytes` and returns a view of them.
    pub fn parse(bytes: &'a [u8]) -> Result<HierarchyView<'a>, FormatError> {
        if bytes.len() < HEADER_SIZE {
            return Err(FormatError::Truncated {
                needed: HEADER_SIZE as u64,
                actual: bytes.len() as u64,
            });
        }
        if bytes[0..4] != MAGIC {
            return Err(FormatError::BadMagic);
        }
        let version = u16_at(bytes, 4);
        if version != VERSION {
            return Err(FormatError::UnsupportedVersion(version));
        }
        let flags = u16_at(bytes, 6);
        let [leaves, nodes, base] = COUNT_OFFSETS.map(|o| u32_at(bytes, o));
        if nodes < leaves
            || nodes - leaves > leaves
            || nodes >= 1 << 31
            || flags & !(FLAG_COLORS | FLAG_HOPPE) != 0
            || (base as u64 + 2 * (nodes - leaves) as u64) >= 1 << 31
            || bytes[52..HEADER_SIZE].iter().any(|&b| b != 0)
        {
            return Err(FormatError::BadCounts);
        }
        let model = ModelBox::read(bytes, BOX_OFFSET).ok_or(FormatError::BadBox)?;
        let layout = Self::layout(leaves, nodes, base, flags & FLAG_COLORS != 0);
        let end = layout[6];
        let actual = bytes.len() as u64;
        if actual < end {
            return Err(FormatError::Truncated {
                needed: end,
                actual,
            });
        }
        if actual > end {
            return Err(FormatError::TrailingBytes {
                needed: end,
                actual,
            });
        }
        let stored = u32_at(bytes, CRC_OFFSET);
        let computed = crc32(&bytes[HEADER_SIZE..]);
        if stored != computed {
            return Err(FormatError::Checksum { stored, computed });
        }
        // The sections fit in `bytes`, so their offsets fit in usize.
        let view = HierarchyView {
            bytes,
            flags,
            leaves,
            nodes,
            roots: leaves - (nodes - leaves),
            base_triangles: base,
            node_width: id_width(nodes),
            face_width: id_width(faces_of(leaves, nodes, base)),
            offsets: core::array::from_fn(|k| layout[k] as usize),
            model,
        };
        view.check_kinds()?;
        view.check_pairs()?;
        view.check_splits()?;
        view.check_base()?;
        Ok(view)
    }

    /// Every block's count is the parents before it, bits past the last node are clear, and
    /// there are `nodes - leaves` parents in all.
    fn check_kinds(&self) -> Result<(), FormatError> {
        let blocks = self.nodes.div_ceil(KIND_BLOCK);
        let mut before = 0u32;
        for b in 0..blocks {
            let (count, bits) = self.kind_block(b);
            let first = b * KIND_BLOCK;
            let used = (self.nodes - first).min(KIND_BLOCK);
            let stray = used < KIND_BLOCK && bits >> used != 0;
            if count != before || stray {
                return Err(FormatError::BadNode {
                    node: first,
                    what: "the kind bits or their counts are inconsistent",
                });
            }
            before += bits.count_ones();
        }
        if before != self.nodes - self.leaves {
            return Err(FormatError::BadCounts);
        }
        Ok(())
    }

    /// The `k`-th parent is the stored parent of pair `k`, and comes before its children.
    fn check_pairs(&self) -> Result<(), FormatError> {
        for (k, p) in (0..).zip(self.parent_nodes()) {
            let [child, _] = self.pair(k);
            if p >= child || self.parent(child) != p {
                return Err(FormatError::BadNode {
                    node: p,
                    what: "parent out of range or not the parent its children name",
                });
            }
        }
        Ok(())
    }

    fn check_splits(&self) -> Result<(), FormatError> {
        let faces = self.faces();
        for p in self.parent_nodes() {
            let bad = |what| Err(FormatError::BadNode { node: p, what });
            // Each neighbour is a base triangle or made by a split that is neither this one nor
            // below it; none across a missing triangle. (One triangle can be the neighbour of
            // both added ones, when a child has three neighbours.)
            let n = self.split(p).neighbours;
            for &f in n.iter().filter(|&&f| f != NONE) {
                if f >= faces || self.face_creator(f).is_some_and(|q| self.is_below(q, p)) {
                    return bad("neighbour triangle out of range or made by this split or below");
                }
            }
            if n[0] == n[1] || (n[2] == n[3] && n[2] != NONE) {
                return bad("a triangle neighbours one added triangle twice");
            }
            if n[0] == NONE && n[1] == NONE {
                return bad("first added triangle has no neighbour");
            }
        }
        Ok(())
    }

    /// Whether node `q` is `p` or a descendant of `p` (walks up from `q`: a parent's id is
    /// smaller than its children's).
    #[must_use]
    pub fn is_below(&self, mut q: u32, p: u32) -> bool {
        while q != NONE && q > p {
            q = self.parent(q);
        }
        q == p
    }

    fn check_base(&self) -> Result<(), FormatError> {
        for t in 0..self.base_triangles {
            let tri = self.base_triangle(t);
            let ok = tri.iter().all(|&v| v < self.roots)
                && tri[0] != tri[1]
                && tri[1] != tri[2]
                && tri[0] != tri[2];
            if !ok {
                return Err(FormatError::BadReference {
                    section: "base triangles",
                    index: t,
                });
            }
        }
        Ok(())
    }

    /// The box every position of the file lies in, as its minimum and maximum corners.
    #[must_use]
    pub fn bounding_box(&self) -> ([f32; 3], [f32; 3]) {
        self.model.corners()
    }

    /// The centre of [`HierarchyView::bounding_box`] and the radius of the sphere through its
    /// corners: what a camera needs to frame the whole model.
    #[must_use]
    pub fn bounding_sphere(&self) -> ([f32; 3], f32) {
        let (min, max) = self.bounding_box();
        let center = core::array::from_fn(|k| 0.5 * (min[k] + max[k]));
        let d = [0, 1, 2].map(|k| max[k] - min[k]);
        let radius = 0.5 * crate::root::sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        (center, radius)
    }

    /// How many leaves (input vertices) there are; which ids they have, [`HierarchyView::is_parent`]
    /// says.
    #[must_use]
    pub fn leaves(&self) -> u32 {
        self.leaves
    }

    /// All nodes.
    #[must_use]
    pub fn nodes(&self) -> u32 {
        self.nodes
    }

    /// The roots, nodes `0..roots()`: the vertices of the base mesh (and input vertices no
    /// triangle used).
    #[must_use]
    pub fn roots(&self) -> u32 {
        self.roots
    }

    /// Triangles of the base mesh.
    #[must_use]
    pub fn base_triangles(&self) -> u32 {
        self.base_triangles
    }

    /// Triangle ids in use: the base triangles plus two per split.
    #[must_use]
    pub fn faces(&self) -> u32 {
        faces_of(self.leaves, self.nodes, self.base_triangles)
    }

    /// Block `b` of the kind section: the parents before it and its bits (zeros out of range).
    #[inline(always)]
    fn kind_block(&self, b: u32) -> (u32, u64) {
        let o = record(self.offsets[0], b, KIND_SIZE);
        let b: [u8; KIND_SIZE] = self.fixed(o).unwrap_or([0; KIND_SIZE]);
        let before = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let bits = u64::from_le_bytes([b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11]]);
        (before, bits)
    }

    /// Whether node `i` is a parent (it splits), and how many parents have smaller ids.
    #[inline(always)]
    fn kind(&self, i: u32) -> (bool, u32) {
        let (before, bits) = self.kind_block(i / KIND_BLOCK);
        let at = i % KIND_BLOCK;
        let below = bits & ((1u64 << at) - 1);
        (
            i < self.nodes && (bits >> at) & 1 != 0,
            before.wrapping_add(below.count_ones()),
        )
    }

    /// Whether node `i` is a parent, i.e. it has a split (false for leaves and ids out of range).
    #[inline]
    #[must_use]
    pub fn is_parent(&self, i: u32) -> bool {
        self.kind(i).0
    }

    /// Node `i`'s place among the leaves (`0..leaves()`, in id order), or `None` for a parent or
    /// an id out of range: what numbers the vertices of a full-detail mesh.
    #[must_use]
    pub fn leaf_index(&self, i: u32) -> Option<u32> {
        let (parent, rank) = self.kind(i);
        (i < self.nodes && !parent).then(|| i - rank)
    }

    /// Every parent in id order: coarse to fine, each after its own parent.
    pub fn parent_nodes(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.nodes).filter(|&i| self.is_parent(i))
    }

    /// Every leaf in id order.
    pub fn leaf_nodes(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.nodes).filter(|&i| !self.is_parent(i))
    }

    /// The children of the split that adds triangle `face` (the `k`-th pair for the `k`-th
    /// split's triangles: nothing is read), or `None` for a base triangle (and for ids out of
    /// range).
    #[inline]
    #[must_use]
    pub fn face_children(&self, face: u32) -> Option<[u32; 2]> {
        self.face_split(face).map(|k| self.pair(k))
    }

    /// Which split adds triangle `face` (the `k`-th adds triangles `2k` and `2k + 1` past the
    /// base), or `None` for a base triangle and ids out of range.
    #[inline]
    fn face_split(&self, face: u32) -> Option<u32> {
        let k = face.checked_sub(self.base_triangles)? / 2;
        (k < self.nodes - self.leaves).then_some(k)
    }

    /// The parent whose split adds triangle `face`, or `None` for a base triangle (and for ids out
    /// of range).
    #[inline]
    #[must_use]
    pub fn face_creator(&self, face: u32) -> Option<u32> {
        self.face_split(face).map(|k| self.pair_parent(k))
    }

    /// Node `i`'s parent, or [`NONE`] (also for ids out of range).
    #[inline]
    #[must_use]
    pub fn parent(&self, i: u32) -> u32 {
        if i < self.roots || i >= self.nodes {
            return NONE;
        }
        self.pair_parent((i - self.roots) / 2)
    }

    /// Node `i`'s parent and where the parent's record is, or `None` for roots (and ids out of
    /// range). The parent of sibling pair `k` is the `k`-th parent (`parse` checks it), so this
    /// counts nothing: it costs one read, where [`HierarchyView::record`] of the parent costs two.
    #[inline(always)]
    #[must_use]
    pub fn parent_record(&self, i: u32) -> Option<(u32, Record)> {
        if i < self.roots || i >= self.nodes {
            return None;
        }
        let k = (i - self.roots) / 2;
        let p = self.pair_parent(k);
        // `parse` proved every stored parent below `nodes`.
        Some((
            p,
            Record {
                offset: self.record_offset(p, k),
                parent: true,
            },
        ))
    }

    /// Node `i`'s sibling and whether `i` is the first child (`(NONE, false)` for roots and
    /// ids out of range): siblings are adjacent, so this reads nothing.
    #[inline]
    #[must_use]
    pub fn sibling(&self, i: u32) -> (u32, bool) {
        if i < self.roots || i >= self.nodes {
            return (NONE, false);
        }
        let k = i - self.roots;
        (self.roots + (k ^ 1), k & 1 == 0)
    }

    /// The parent of sibling pair `k` (`k < nodes - leaves`).
    #[inline(always)]
    fn pair_parent(&self, k: u32) -> u32 {
        let bit = self.offsets[3] as u64 * 8 + k as u64 * self.node_width as u64;
        id(bits_at(self.bytes, bit, self.node_width), self.node_width)
    }

    /// Whether the nodes carry meaningful colours.
    #[must_use]
    pub fn has_colors(&self) -> bool {
        self.flags & FLAG_COLORS != 0
    }

    /// Whether the parents' error bounds are Hoppe's ([`FLAG_HOPPE`]): draw with
    /// [`crate::policy::HoppeError`] rather than [`crate::policy::ScreenError`].
    #[must_use]
    pub fn hoppe_bounds(&self) -> bool {
        self.flags & FLAG_HOPPE != 0
    }

    /// Size of the file in bytes.
    #[must_use]
    pub fn size(&self) -> usize {
        self.bytes.len()
    }

    /// The `N` bytes at `o`, if they are inside the file.
    #[inline]
    fn fixed<const N: usize>(&self, o: usize) -> Option<[u8; N]> {
        let end = o.checked_add(N)?;
        self.bytes.get(o..end)?.try_into().ok()
    }

    /// Where node `i`'s record is: counting the parents before it costs a little, so a caller
    /// that reads a record twice (touches it, then decodes it) finds it once.
    #[inline(always)]
    #[must_use]
    pub fn record(&self, i: u32) -> Record {
        let (parent, rank) = self.kind(i);
        if i >= self.nodes {
            return Record {
                offset: usize::MAX,
                parent: false,
            };
        }
        Record {
            offset: self.record_offset(i, rank),
            parent,
        }
    }

    /// Where the record of node `i` (in range), with `rank` parents before it, starts: `parse`
    /// proved the section inside the file, so this does not overflow.
    #[inline(always)]
    fn record_offset(&self, i: u32, rank: u32) -> usize {
        self.offsets[1] + i as usize * NODE_SIZE + rank as usize * (PARENT_SIZE - NODE_SIZE)
    }

    /// The records of sibling pair `first` and `first + 1` ([`HierarchyView::split`]'s
    /// children): [`HierarchyView::record`] of both, counting the parents before them once.
    #[inline(always)]
    #[must_use]
    pub fn pair_records(&self, first: u32) -> [Record; 2] {
        let second = first.wrapping_add(1);
        let (parent, rank) = self.kind(first);
        let located = |i: u32, parent: bool, rank: u32| {
            if i >= self.nodes {
                Record {
                    offset: usize::MAX,
                    parent: false,
                }
            } else {
                Record {
                    offset: self.record_offset(i, rank),
                    parent,
                }
            }
        };
        [
            located(first, parent, rank),
            located(
                second,
                self.is_parent(second),
                rank.wrapping_add(parent as u32),
            ),
        ]
    }

    /// The first byte of node `i`'s record (0 out of range): reading it brings the record into
    /// the cache. A caller that touches a batch of nodes before decoding them has the processor
    /// fetch all their records at once instead of one after the other.
    #[inline(always)]
    #[must_use]
    pub fn touch(&self, i: u32) -> u8 {
        self.touch_record(self.record(i))
    }

    /// [`HierarchyView::touch`] of a located record.
    #[inline(always)]
    #[must_use]
    pub fn touch_record(&self, r: Record) -> u8 {
        self.bytes.get(r.offset).copied().unwrap_or(0)
    }

    /// Node `i`'s [`Digest`] (zeros out of range).
    #[inline]
    #[must_use]
    pub fn digest(&self, i: u32) -> Digest {
        self.digest_at(self.record(i))
    }

    /// [`HierarchyView::digest`] of a located record.
    #[inline]
    #[must_use]
    pub fn digest_at(&self, at: Record) -> Digest {
        // A leaf's record and a parent's both start with the position, read as one word (as
        // bytes, LLVM loaded them one by one); only a parent's has the bound codes, one word
        // more (a leaf's are zeros). A record not in the file reads as all zeros, as in
        // `record_bytes_at`.
        let Record { offset: o, parent } = at;
        let size = if parent { PARENT_SIZE } else { NODE_SIZE };
        let Some(r) = o.checked_add(size).and_then(|end| self.bytes.get(o..end)) else {
            return Digest::ZERO;
        };
        let head = r.first_chunk::<8>().map_or(0, |h| u64::from_le_bytes(*h));
        let codes = r
            .get(NODE_SIZE..)
            .and_then(<[u8]>::first_chunk::<4>)
            .map_or(0, |c| u32::from_le_bytes(*c));
        let [radius, a, b, _] = codes.to_le_bytes();
        Digest {
            position: [head as u16, (head >> 16) as u16, (head >> 32) as u16],
            spheroid: a.max(b),
            radius,
        }
    }

    /// The position a [`Digest`] holds, as [`HierarchyView::bounds`] decodes it.
    #[inline(always)]
    #[must_use]
    pub fn digest_center(&self, d: &Digest) -> [f32; 3] {
        self.model.dequantize(d.position)
    }

    /// The length a bound code stands for in this file's units.
    #[inline(always)]
    #[must_use]
    pub fn length(&self, code: u8) -> f32 {
        self.model.length(code)
    }

    /// Node `i`'s record: position, normal and (for a parent) its bound codes (radius, `a`, `b`,
    /// cone sine); a leaf's codes (and anything out of range) are zeros and no cone.
    #[inline]
    fn node_record(&self, i: u32) -> ([f32; 3], [f32; 3], [u8; 4]) {
        let r = self.record_bytes(i);
        let normal = oct_decode(r[6] as i8, r[7] as i8);
        (self.model.position(&r), normal, [r[8], r[9], r[10], r[11]])
    }

    /// Node `i`'s record as a parent's: a leaf's padded with zero codes and no cone, anything
    /// out of range all zeros but no cone.
    #[inline]
    fn record_bytes(&self, i: u32) -> [u8; PARENT_SIZE] {
        self.record_bytes_at(self.record(i))
    }

    /// [`HierarchyView::record_bytes`] of a located record.
    #[inline(always)]
    fn record_bytes_at(&self, at: Record) -> [u8; PARENT_SIZE] {
        let Record { offset: o, parent } = at;
        if parent {
            return self.fixed(o).unwrap_or([0; PARENT_SIZE]);
        }
        let mut r = [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 255];
        if let Some(leaf) = self.fixed::<NODE_SIZE>(o) {
            r[..NODE_SIZE].copy_from_slice(&leaf);
        }
        r
    }

    /// Node `i` (`i < nodes()`; out-of-range ids read as zeros with no parent, never panic).
    #[must_use]
    pub fn node(&self, i: u32) -> NodeView {
        let (position, normal, [r, a, b, cone]) = self.node_record(i);
        NodeView {
            position,
            radius: self.length(r),
            spheroid: [self.length(a), self.length(b)],
            normal,
            cone_sin: cone_sine(cone),
            color: self.color(i),
            depth: self.depth(i),
            parent: self.parent(i),
        }
    }

    /// Node `i`'s position, normal and colour (white without colours): what drawing it needs,
    /// without the walk up the parents that [`HierarchyView::node`]'s depth takes.
    #[inline]
    #[must_use]
    pub fn vertex(&self, i: u32) -> ([f32; 3], [f32; 3], [u8; 3]) {
        self.vertex_inline(i)
    }

    /// [`HierarchyView::vertex`], inlined where it is called.
    #[inline(always)]
    pub(crate) fn vertex_inline(&self, i: u32) -> ([f32; 3], [f32; 3], [u8; 3]) {
        let r = self.leading(i);
        let normal = oct_decode(r[6] as i8, r[7] as i8);
        (self.model.position(&r), normal, self.color(i))
    }

    /// The leading 8 bytes of node `i`'s record: position and normal lead every record, a
    /// leaf's and a parent's alike (out of range: zeros, as `record_bytes` reads it).
    #[inline(always)]
    pub(crate) fn leading(&self, i: u32) -> [u8; 8] {
        self.fixed(self.record(i).offset).unwrap_or([0; 8])
    }

    /// Positions and normals of the leading bytes of `N` records ([`HierarchyView::leading`]),
    /// attribute by attribute: [`ModelBox::position`] and [`oct_decode`] lane by lane, in the
    /// same operations (so the same floats), but in loops the compiler runs in SIMD registers;
    /// only the square roots go one at a time.
    #[inline(always)]
    pub(crate) fn decode_lanes<const N: usize>(
        &self,
        r: &[[u8; 8]; N],
        positions: &mut [[f32; N]; 3],
        normals: &mut [[f32; N]; 3],
    ) {
        let mut squares = [0.0f32; N];
        for k in 0..N {
            let p = self.model.position(&r[k]);
            let w = oct_unfold(r[k][6] as i8, r[k][7] as i8);
            for a in 0..3 {
                positions[a][k] = p[a];
                normals[a][k] = w[a];
            }
            squares[k] = dot(w, w);
        }
        let mut inv = [0.0f32; N];
        for (i, s) in inv.iter_mut().zip(squares) {
            *i = 1.0 / crate::root::sqrtf(s);
        }
        for axis in normals.iter_mut() {
            for (c, i) in axis.iter_mut().zip(inv) {
                *c *= i;
            }
        }
    }

    /// Node `i`'s colour: white without colours, black out of range.
    #[inline(always)]
    pub(crate) fn color(&self, i: u32) -> [u8; 3] {
        if !self.has_colors() {
            return [255; 3];
        }
        self.fixed(record(self.offsets[2], i, COLOR_SIZE))
            .unwrap_or([0; 3])
    }

    /// Node `i`'s depth in the forest, counted up its parents (0 for roots and ids out of range).
    #[must_use]
    pub fn depth(&self, i: u32) -> u16 {
        let mut d = 0u16;
        let mut p = self.parent(i);
        while p != NONE && d < u16::MAX {
            d += 1;
            p = self.parent(p);
        }
        d
    }

    /// What the refinement policies need of node `i`, decoded without the rest of the record. A
    /// leaf has no bounds (it never splits): radius and spheroid 0, no cone, and its axis is not
    /// decoded (+z).
    #[inline]
    #[must_use]
    pub fn bounds(&self, i: u32) -> crate::policy::Bounds {
        self.bounds_at(self.record(i))
    }

    /// The bounding sphere of a located record, as [`crate::policy::Bounds`] with the rest at
    /// its default: all a policy that reads only spheres ([`crate::policy::Policy::sphere_only`])
    /// needs, without decoding the normal, the cone or the spheroid.
    #[inline]
    #[must_use]
    pub fn sphere_at(&self, at: Record) -> crate::policy::Bounds {
        // A leaf's padded radius code is 0, which decodes to 0.
        let r = self.record_bytes_at(at);
        crate::policy::Bounds {
            center: self.model.position(&r),
            radius: self.length(r[8]),
            ..crate::policy::Bounds::default()
        }
    }

    /// [`HierarchyView::bounds`] of a located record.
    #[inline]
    #[must_use]
    pub fn bounds_at(&self, at: Record) -> crate::policy::Bounds {
        let Record { offset: o, parent } = at;
        let r: [u8; PARENT_SIZE] = match parent {
            true => self.fixed(o).unwrap_or([0; PARENT_SIZE]),
            false => {
                let leaf: [u8; 6] = self.fixed(o).unwrap_or([0; 6]);
                return crate::policy::Bounds {
                    center: self.model.position(&leaf),
                    radius: 0.0,
                    axis: [0.0, 0.0, 1.0],
                    cone_sin: 1.0,
                    a2: 0.0,
                    b2: 0.0,
                };
            }
        };
        let (a, b) = (self.length(r[9]), self.length(r[10]));
        crate::policy::Bounds {
            center: self.model.position(&r),
            radius: self.length(r[8]),
            axis: oct_decode(r[6] as i8, r[7] as i8),
            cone_sin: cone_sine(r[11]),
            a2: a * a,
            b2: b * b,
        }
    }

    /// The split record of parent `p` (anything else reads as [`NONE`]s).
    #[inline(always)]
    #[must_use]
    pub fn split(&self, p: u32) -> SplitView {
        match self.kind(p) {
            (true, rank) => self.split_at(rank),
            _ => SplitView::NONE,
        }
    }

    /// [`HierarchyView::split`] of the parent of the sibling pair whose first child is `first`
    /// ([`SplitView::NONE`] for a root or an id out of range): the `k`-th pair's parent is the
    /// `k`-th parent, so its split is found without counting the parents before it.
    #[inline]
    #[must_use]
    pub fn pair_split(&self, first: u32) -> SplitView {
        if first < self.roots || first >= self.nodes {
            return SplitView::NONE;
        }
        self.split_at((first - self.roots) / 2)
    }

    /// The split of the parent of rank `rank` (the `rank`-th parent in id order).
    #[inline(always)]
    fn split_at(&self, rank: u32) -> SplitView {
        let wf = self.face_width;
        let at = self.offsets[4] as u64 * 8 + rank as u64 * split_bits(wf);
        let neighbours = if 2 * wf + 7 <= 64 {
            // Two ids in each of two 64-bit words (every hierarchy below 2^28 faces).
            let mask = low(wf);
            let two = |bit: u64| {
                let w = word_at(self.bytes, bit);
                [w as u32, (w >> wf) as u32].map(|raw| field_id(raw, mask))
            };
            let ([n0, n1], [n2, n3]) = (two(at), two(at + 2 * wf as u64));
            [n0, n1, n2, n3]
        } else {
            [0, 1, 2, 3].map(|k| id(bits_at(self.bytes, at + k as u64 * wf as u64, wf), wf))
        };
        let first = self.base_triangles.wrapping_add(rank.wrapping_mul(2));
        SplitView {
            children: self.pair(rank),
            faces: [first, first.wrapping_add(1)],
            neighbours,
        }
    }

    /// The children of parent `p` (`[NONE; 2]` for anything else): [`HierarchyView::split`]
    /// without the neighbours.
    #[inline]
    #[must_use]
    pub fn children(&self, p: u32) -> [u32; 2] {
        match self.kind(p) {
            (true, rank) => self.pair(rank),
            _ => [NONE; 2],
        }
    }

    /// Sibling pair `k`.
    #[inline(always)]
    fn pair(&self, k: u32) -> [u32; 2] {
        let c0 = self.roots.wrapping_add(k.wrapping_mul(2));
        [c0, c0.wrapping_add(1)]
    }

    /// Base triangle `t`.
    #[must_use]
    pub fn base_triangle(&self, t: u32) -> [u32; 3] {
        let o = record(self.offsets[5], t, TRIANGLE_SIZE);
        [0, 4, 8].map(|k| u32_at(self.bytes, o.saturating_add(k)))
    }
}

/// Triangle ids of a hierarchy: the base triangles plus two per split.
#[inline]
fn faces_of(leaves: u32, nodes: u32, base: u32) -> u32 {
    base.saturating_add(nodes.saturating_sub(leaves).saturating_mul(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `e`'s message contains `word` (formatted into a fixed buffer: no allocation).
    fn alloc_free_contains(e: FormatError, word: &str) -> bool {
        struct Buf([u8; 256], usize);
        impl fmt::Write for Buf {
            fn write_str(&mut self, s: &str) -> fmt::Result {
                let end = (self.1 + s.len()).min(self.0.len());
                self.0[self.1..end].copy_from_slice(&s.as_bytes()[..end - self.1]);
                self.1 = end;
                Ok(())
            }
        }
        let mut b = Buf([0; 256], 0);
        let _ = fmt::write(&mut b, format_args!("{e}"));
        b.0[..b.1].windows(word.len()).any(|w| w == word.as_bytes())
    }

    #[test]
    fn octahedral_rounding_is_roundf() {
        // Every half and its neighbours, and the integers (all of `[-127, 127]` was checked
        // once against `libm::roundf`).
        for k in -254..=254 {
            let half = k as f32 / 2.0;
            for x in [half.next_down(), half, half.next_up()] {
                assert_eq!(round_small(x), libm::roundf(x) as i8, "{x}");
            }
        }
        assert_eq!(round_small(f32::NAN), 0);
    }

    #[test]
    fn crc_matches_the_standard_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn length_codes_round_up() {
        for v in [1e-4f32, 0.001, 0.1, 0.5, 1.0, 2.71, 3.8] {
            let k = encode_length(v);
            assert!(decode_length(k) >= v, "{v} -> {}", decode_length(k));
            assert!(decode_length(k - 1) < v, "{v}: not the smallest");
            // 16 codes per octave: at most 4.5% above.
            assert!(decode_length(k) <= v * 1.045, "{v} -> {}", decode_length(k));
        }
        assert_eq!(decode_length(224), 1.0);
        assert_eq!(encode_length(0.0), 0);
        assert_eq!(encode_length(f32::NAN), 0);
        assert_eq!(encode_length(1e9), 255);
        assert!((1..=255).all(|k| decode_length(k) > decode_length(k - 1)));
    }

    #[test]
    fn bits_pack_least_significant_first() {
        let b = [0b1010_1100u8, 0xFF, 0x01, 0, 0, 0, 0, 0, 0, 0];
        assert_eq!(bits_at(&b, 2, 3), 0b011);
        assert_eq!(bits_at(&b, 4, 8), 0xFA);
        assert_eq!(bits_at(&b, 16, 1), 1);
        // Past the end: ones.
        assert_eq!(bits_at(&b, 80, 4), 0xF);
        assert_eq!(id_width(4), 3);
        assert_eq!(id(7, 3), NONE);
        assert_eq!((id(6, 3), id(0, 3)), (6, 0));
        assert_eq!((id(u32::MAX, 32), id(5, 32), id(0, 0)), (NONE, 5, NONE));
    }

    #[test]
    fn octahedral_round_trip_is_close() {
        for n in [
            [0.0f32, 0.0, -1.0],
            [0.6, 0.0, 0.8],
            [0.0, -0.8, -0.6],
            [0.577, 0.577, -0.577],
        ] {
            let (x, y) = oct_encode(n);
            let d = oct_decode(x, y);
            let dot = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            assert!(dot > 0.999, "{n:?} -> {d:?}");
        }
    }

    #[test]
    fn octahedral_axes() {
        assert_eq!(oct_decode(0, 0), [0.0, 0.0, 1.0]);
        assert_eq!(oct_decode(127, 0), [1.0, 0.0, 0.0]);
        let n = oct_decode(-127, 0);
        assert_eq!(n, [-1.0, 0.0, 0.0]);
    }

    #[test]
    fn rejects_short_and_foreign_bytes() {
        assert_eq!(
            HierarchyView::parse(b"VDLH").err(),
            Some(FormatError::Truncated {
                needed: 64,
                actual: 4
            })
        );
        assert_eq!(
            HierarchyView::parse(&[0u8; 64]).err(),
            Some(FormatError::BadMagic)
        );
        let mut v2 = [0u8; 64];
        v2[..4].copy_from_slice(&MAGIC);
        v2[4] = 2;
        let e = HierarchyView::parse(&v2).unwrap_err();
        assert_eq!(e, FormatError::UnsupportedVersion(2));
        assert!(alloc_free_contains(e, "rebuild"));
    }
}
