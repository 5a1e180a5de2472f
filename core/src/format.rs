//! The hierarchy file format, read in place from `&[u8]` without allocating.
//!
//! A device keeps the bytes in flash (`include_bytes!`) and reads them through a [`HierarchyView`]:
//! [`HierarchyView::parse`] checks everything once (sizes, magic, version, checksum, every index in
//! range, parent links acyclic and consistent with the children, floats finite) so that hostile or
//! corrupted bytes give a [`FormatError`], never a panic; afterwards every accessor is a bounds-safe
//! little-endian read.
//!
//! Layout, all little-endian, sections back to back in this order (`docs` in the module source
//! gives each field's offset):
//!
//! | section | size | content |
//! |---|---|---|
//! | header | 40 | magic `VDLH`, version `u16` = 2, flags `u16` (bit 0: colours present), `leaves`, `nodes`, `base_triangles` (`u32` each), 4 zero bytes, CRC-32 of everything after the header (`u32`), 12 reserved zero bytes |
//! | nodes | 34 per node | position `3 x f32`; radius, `mu`, `delta`, spheroid `a`, `b` as `f16` rounded up; normal octahedral `2 x i8`; cone sine `u8` (`ceil(255 sin)`, 255: no useful cone); colour `3 x u8`; depth `u16`; parent `u32` (`0xFFFF_FFFF` for a root) |
//! | splits | 32 per parent | children `2 x u32`, wings `2 x u32` (second `0xFFFF_FFFF` on a border), neighbour triangles `4 x u32` |
//! | base triangles | 12 each | `3 x u32` root ids, counter-clockwise |
//!
//! Nodes `0..leaves` are the input vertices; nodes `leaves..nodes` are parents, each with a larger
//! id than its children, so parent links can never form a cycle.
//!
//! Triangles have ids too ([`split_face`]): base triangle `k` is `k`, and the split of parent `p`
//! adds triangle `base + 2 (p - leaves)` = `(c0, c1, w0)` and, unless on a border, the next id =
//! `(c1, c0, w1)`. A split record's neighbours are the triangles across those two triangles'
//! outer edges (`c1-w0`, `w0-c0`, `c0-w1`, `w1-c1`; `0xFFFF_FFFF` on a border), Hoppe's
//! `fn0..fn3`: a split is legal when its neighbours exist, which is what the runtime cut checks
//! and, when they do not, forces (each neighbour is a base triangle or made by a coarser split, so
//! forcing ends).

use core::fmt;

/// First four bytes of a hierarchy file.
pub const MAGIC: [u8; 4] = *b"VDLH";
/// The version this crate reads and writes.
pub const VERSION: u16 = 2;
/// Header size in bytes.
pub const HEADER_SIZE: usize = 40;
/// Bytes per node record.
pub const NODE_SIZE: usize = 34;
/// Bytes per split record.
pub const SPLIT_SIZE: usize = 32;
/// "No node" in parent and wing fields.
pub const NONE: u32 = u32::MAX;
/// Header flag: the nodes carry meaningful colours.
pub const FLAG_COLORS: u16 = 1;

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
    /// The counts in the header contradict each other.
    BadCounts,
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
            FormatError::UnsupportedVersion(v) => {
                write!(f, "format version {v}, this build reads version {VERSION}")
            }
            FormatError::BadCounts => write!(f, "inconsistent counts in the header"),
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
pub fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(!0u32, |c, &b| {
        CRC_TABLE[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8)
    })
}

/// Decodes an IEEE half-precision float.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1F) as u32;
    let man = (h & 0x3FF) as u32;
    let bits = match exp {
        0 => {
            // Zero or subnormal: man * 2^-24.
            let v = man as f32 * (1.0 / 16_777_216.0);
            return if sign != 0 { -v } else { v };
        }
        31 => sign | 0x7F80_0000 | (man << 13),
        _ => sign | ((exp + 112) << 23) | (man << 13),
    };
    f32::from_bits(bits)
}

/// The smallest half-precision value not below `v` (for non-negative finite `v`; NaN and negative
/// values give 0, values beyond the half range give infinity, which [`HierarchyView::parse`]
/// rejects).
pub fn f32_to_f16_up(v: f32) -> u16 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if v > 65504.0 {
        return 0x7C00;
    }
    // Start from truncation, then step up while below.
    let bits = v.to_bits();
    let exp = ((bits >> 23) & 0xFF) as i32 - 127;
    let mut h: u16 = if exp < -14 {
        // Subnormal half: units of 2^-24.
        (v * 16_777_216.0) as u16
    } else {
        (((exp + 15) as u16) << 10) | ((bits >> 13) & 0x3FF) as u16
    };
    while f16_to_f32(h) < v {
        h += 1;
    }
    h
}

/// A validated hierarchy, borrowed in place.
#[derive(Clone, Copy, Debug)]
pub struct HierarchyView<'a> {
    bytes: &'a [u8],
    flags: u16,
    leaves: u32,
    nodes: u32,
    base_triangles: u32,
    /// Byte offsets of the node, split and base-triangle sections.
    offsets: [usize; 3],
}

/// One node, read from a [`HierarchyView`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeView {
    /// Position.
    pub position: [f32; 3],
    /// Bounding-sphere radius of the node's region and all its descendants'.
    pub radius: f32,
    /// Hoppe's uniform deviation (across the normal).
    pub mu: f32,
    /// Hoppe's normal deviation (along the normal).
    pub delta: f32,
    /// The wavelet paper's spheroid `[a, b]`.
    pub spheroid: [f32; 2],
    /// Cone axis (unit length, decoded from 8-bit octahedral coordinates).
    pub normal: [f32; 3],
    /// Sine of the cone's half-angle, rounded up; 1 when the cone bounds nothing.
    pub cone_sin: f32,
    /// Colour.
    pub color: [u8; 3],
    /// Depth in the forest (0 for roots).
    pub depth: u16,
    /// Parent, or [`NONE`].
    pub parent: u32,
}

/// One parent's split record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitView {
    /// The two children.
    pub children: [u32; 2],
    /// The wings; the second is [`NONE`] on a border.
    pub wings: [u32; 2],
    /// Triangles across the added triangles' outer edges (`c1-w0`, `w0-c0`, `c0-w1`, `w1-c1`),
    /// or [`NONE`].
    pub neighbours: [u32; 4],
}

/// The id of a triangle a split adds: the first (`second == false`) or the second of parent
/// `parent`'s split, in a hierarchy with `base` base triangles and `leaves` leaves. Wraps for
/// ids out of range (a [`HierarchyView`] never stores those).
#[inline]
pub fn split_face(base: u32, leaves: u32, parent: u32, second: bool) -> u32 {
    base.wrapping_add(parent.wrapping_sub(leaves).wrapping_mul(2))
        .wrapping_add(second as u32)
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
fn u16_at(b: &[u8], o: usize) -> u16 {
    match b.get(o..o.saturating_add(2)) {
        Some(s) => u16::from_le_bytes([s[0], s[1]]),
        None => 0,
    }
}

#[inline]
fn u32_at(b: &[u8], o: usize) -> u32 {
    match b.get(o..o.saturating_add(4)) {
        Some(s) => u32::from_le_bytes([s[0], s[1], s[2], s[3]]),
        None => NONE,
    }
}

/// What an out-of-range node id reads as: zeros, no parent.
const OUT_OF_RANGE_NODE: [u8; NODE_SIZE] = {
    let mut r = [0u8; NODE_SIZE];
    r[30] = 0xFF;
    r[31] = 0xFF;
    r[32] = 0xFF;
    r[33] = 0xFF;
    r
};

#[inline]
fn ru32<const N: usize>(r: &[u8; N], o: usize) -> u32 {
    u32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]])
}

#[inline]
fn rf32<const N: usize>(r: &[u8; N], o: usize) -> f32 {
    f32::from_bits(ru32(r, o))
}

#[inline]
fn rf16<const N: usize>(r: &[u8; N], o: usize) -> f32 {
    f16_to_f32(u16::from_le_bytes([r[o], r[o + 1]]))
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
    let q = |x: f32| libm::roundf(x.clamp(-1.0, 1.0) * 127.0) as i8;
    (q(u), q(v))
}

/// Decodes octahedral coordinates in `[-127, 127]` to a unit vector.
pub fn oct_decode(x: i8, y: i8) -> [f32; 3] {
    let (mut u, mut v) = (x as f32 / 127.0, y as f32 / 127.0);
    let z = 1.0 - u.abs() - v.abs();
    if z < 0.0 {
        let (ou, ov) = (u, v);
        u = (1.0 - ov.abs()) * if ou >= 0.0 { 1.0 } else { -1.0 };
        v = (1.0 - ou.abs()) * if ov >= 0.0 { 1.0 } else { -1.0 };
    }
    let l = libm::sqrtf(u * u + v * v + z * z);
    if l > 0.0 {
        [u / l, v / l, z / l]
    } else {
        [0.0, 0.0, 1.0]
    }
}

impl<'a> HierarchyView<'a> {
    /// Byte offsets of the sections: nodes, splits, base triangles, total.
    fn layout(leaves: u32, nodes: u32, base: u32) -> [u64; 4] {
        let n = HEADER_SIZE as u64;
        let s = n + nodes as u64 * NODE_SIZE as u64;
        let b = s + (nodes as u64 - leaves as u64) * SPLIT_SIZE as u64;
        let end = b + base as u64 * 12;
        [n, s, b, end]
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
        let view = HierarchyView {
            bytes,
            flags: u16_at(bytes, 6),
            leaves: u32_at(bytes, 8),
            nodes: u32_at(bytes, 12),
            base_triangles: u32_at(bytes, 16),
            offsets: [0; 3],
        };
        if view.nodes < view.leaves
            || view.nodes - view.leaves > view.leaves
            || view.nodes == NONE
            || view.flags & !FLAG_COLORS != 0
            || (view.base_triangles as u64 + 2 * (view.nodes - view.leaves) as u64) >= NONE as u64
            || bytes[20..24].iter().any(|&b| b != 0)
            || bytes[28..40].iter().any(|&b| b != 0)
        {
            return Err(FormatError::BadCounts);
        }
        let layout = Self::layout(view.leaves, view.nodes, view.base_triangles);
        let end = layout[3];
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
        // The sections fit in `bytes`, so their offsets fit in usize.
        let view = HierarchyView {
            offsets: [layout[0] as usize, layout[1] as usize, layout[2] as usize],
            ..view
        };
        let stored = u32_at(bytes, 24);
        let computed = crc32(&bytes[HEADER_SIZE..]);
        if stored != computed {
            return Err(FormatError::Checksum { stored, computed });
        }
        view.check_nodes()?;
        view.check_splits()?;
        view.check_base()?;
        Ok(view)
    }

    fn check_nodes(&self) -> Result<(), FormatError> {
        for i in 0..self.nodes {
            let bad = |what| Err(FormatError::BadNode { node: i, what });
            let n = self.node(i);
            if !n.position.iter().all(|c| c.is_finite()) {
                return bad("position is not finite");
            }
            let bounds = [n.radius, n.mu, n.delta, n.spheroid[0], n.spheroid[1]];
            if !bounds.iter().all(|b| b.is_finite() && *b >= 0.0) {
                return bad("a bound is negative or not finite");
            }
            if n.parent != NONE {
                if n.parent <= i || n.parent >= self.nodes || n.parent < self.leaves {
                    return bad("parent out of range");
                }
                if !self.split(n.parent).children.contains(&i) {
                    return bad("parent does not list it as a child");
                }
            }
        }
        Ok(())
    }

    fn check_splits(&self) -> Result<(), FormatError> {
        let faces = self.faces();
        for p in self.leaves..self.nodes {
            let bad = |what| Err(FormatError::BadNode { node: p, what });
            let s = self.split(p);
            let [a, b] = s.children;
            if a >= p || b >= p || a == b {
                return bad("children out of range");
            }
            if self.parent(a) != p || self.parent(b) != p {
                return bad("children do not point back");
            }
            let [w0, w1] = s.wings;
            if w0 >= self.nodes || (w1 != NONE && w1 >= self.nodes) {
                return bad("wing out of range");
            }
            if s.children.contains(&w0) || s.children.contains(&w1) || w0 == w1 {
                return bad("wing equals a child or the other wing");
            }
            // Each neighbour exists before this split: a base triangle or one a coarser split
            // (larger id) adds; none across a missing triangle. (One triangle can be the
            // neighbour of both added ones, when a child has three neighbours.)
            let n = s.neighbours;
            for &f in n.iter().filter(|&&f| f != NONE) {
                if f >= faces || self.face_creator(f).is_some_and(|q| q <= p) {
                    return bad("neighbour triangle out of range or not older than the split");
                }
            }
            if n[0] == n[1] || (n[2] == n[3] && n[2] != NONE) {
                return bad("a triangle neighbours one added triangle twice");
            }
            if n[0] == NONE && n[1] == NONE {
                return bad("first added triangle has no neighbour");
            }
            if w1 == NONE && (n[2] != NONE || n[3] != NONE) {
                return bad("neighbours of a missing triangle");
            }
            if w1 != NONE && n[2] == NONE && n[3] == NONE {
                return bad("second added triangle has no neighbour");
            }
        }
        Ok(())
    }

    fn check_base(&self) -> Result<(), FormatError> {
        for t in 0..self.base_triangles {
            let tri = self.base_triangle(t);
            let ok = tri
                .iter()
                .all(|&v| v < self.nodes && self.node(v).parent == NONE)
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

    /// Input vertices: nodes `0..leaves()`.
    pub fn leaves(&self) -> u32 {
        self.leaves
    }

    /// All nodes.
    pub fn nodes(&self) -> u32 {
        self.nodes
    }

    /// Triangles of the base mesh.
    pub fn base_triangles(&self) -> u32 {
        self.base_triangles
    }

    /// Triangle ids in use: the base triangles plus two per split.
    pub fn faces(&self) -> u32 {
        self.base_triangles + 2 * (self.nodes - self.leaves)
    }

    /// The parent whose split adds triangle `face`, or `None` for a base triangle (and for ids out
    /// of range).
    #[inline]
    pub fn face_creator(&self, face: u32) -> Option<u32> {
        let k = face.checked_sub(self.base_triangles)?;
        let p = self.leaves.checked_add(k / 2)?;
        (p < self.nodes).then_some(p)
    }

    /// The id of a triangle parent `p`'s split adds (see [`split_face`]).
    #[inline]
    pub fn split_face(&self, p: u32, second: bool) -> u32 {
        split_face(self.base_triangles, self.leaves, p, second)
    }

    /// Node `i`'s parent, or [`NONE`] (cheaper than [`HierarchyView::node`]).
    #[inline]
    pub fn parent(&self, i: u32) -> u32 {
        let o = record(self.offsets[0], i, NODE_SIZE).saturating_add(30);
        self.fixed::<4>(o).map_or(NONE, u32::from_le_bytes)
    }

    /// Whether the nodes carry meaningful colours.
    pub fn has_colors(&self) -> bool {
        self.flags & FLAG_COLORS != 0
    }

    /// Size of the file in bytes.
    pub fn size(&self) -> usize {
        self.bytes.len()
    }

    /// The `N` bytes at `o`, if they are inside the file.
    #[inline]
    fn fixed<const N: usize>(&self, o: usize) -> Option<[u8; N]> {
        let end = o.checked_add(N)?;
        self.bytes.get(o..end)?.try_into().ok()
    }

    /// Node `i`'s record (an out-of-range id reads as zeros with no parent).
    #[inline]
    fn node_record(&self, i: u32) -> [u8; NODE_SIZE] {
        self.fixed(record(self.offsets[0], i, NODE_SIZE))
            .unwrap_or(OUT_OF_RANGE_NODE)
    }

    /// Node `i` (`i < nodes()`; out-of-range ids read as zeros with no parent, never panic).
    pub fn node(&self, i: u32) -> NodeView {
        let r = self.node_record(i);
        NodeView {
            position: [rf32(&r, 0), rf32(&r, 4), rf32(&r, 8)],
            radius: rf16(&r, 12),
            mu: rf16(&r, 14),
            delta: rf16(&r, 16),
            spheroid: [rf16(&r, 18), rf16(&r, 20)],
            normal: oct_decode(r[22] as i8, r[23] as i8),
            cone_sin: r[24] as f32 / 255.0,
            color: [r[25], r[26], r[27]],
            depth: u16::from_le_bytes([r[28], r[29]]),
            parent: ru32(&r, 30),
        }
    }

    /// What the refinement policies need of node `i`, decoded without the rest of the record.
    #[inline]
    pub fn bounds(&self, i: u32) -> crate::policy::Bounds {
        let r = self.node_record(i);
        let (sa, sb) = (rf16(&r, 18), rf16(&r, 20));
        crate::policy::Bounds {
            center: [rf32(&r, 0), rf32(&r, 4), rf32(&r, 8)],
            radius: rf16(&r, 12),
            axis: oct_decode(r[22] as i8, r[23] as i8),
            cone_sin: r[24] as f32 / 255.0,
            a2: sa * sa,
            b2: sb * sb,
        }
    }

    /// The split record of parent `p` (`leaves() <= p < nodes()`; anything else reads as
    /// [`NONE`]s).
    #[inline]
    pub fn split(&self, p: u32) -> SplitView {
        let o = if p < self.leaves {
            usize::MAX
        } else {
            record(self.offsets[1], p - self.leaves, SPLIT_SIZE)
        };
        let r: [u8; SPLIT_SIZE] = self.fixed(o).unwrap_or([0xFF; SPLIT_SIZE]);
        SplitView {
            children: [ru32(&r, 0), ru32(&r, 4)],
            wings: [ru32(&r, 8), ru32(&r, 12)],
            neighbours: [ru32(&r, 16), ru32(&r, 20), ru32(&r, 24), ru32(&r, 28)],
        }
    }

    /// Base triangle `t`.
    pub fn base_triangle(&self, t: u32) -> [u32; 3] {
        let o = record(self.offsets[2], t, 12);
        [0, 4, 8].map(|k| u32_at(self.bytes, o.saturating_add(k)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_matches_the_standard_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn half_floats_round_up() {
        for v in [0.0f32, 1.0, 0.1, 2.71, 1e-7, 6.0e-5, 65504.0, 1234.567] {
            let h = f32_to_f16_up(v);
            let back = f16_to_f32(h);
            assert!(back >= v, "{v} -> {back}");
            if h > 0 {
                assert!(f16_to_f32(h - 1) < v, "{v}: not the smallest");
            }
        }
        assert_eq!(f16_to_f32(f32_to_f16_up(1e6)), f32::INFINITY);
        assert_eq!(f32_to_f16_up(f32::NAN), 0);
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
                needed: 40,
                actual: 4
            })
        );
        assert_eq!(
            HierarchyView::parse(&[0u8; 64]).err(),
            Some(FormatError::BadMagic)
        );
    }
}
