//! Writing a [`Hierarchy`] in the format [`crate::format`] reads (version 4): the nodes renumbered
//! breadth first, so that siblings are adjacent and a parent's children follow from its rank.

use alloc::vec::Vec;

use super::{ErrorBound, Hierarchy};
use crate::format::{
    crc32, encode_length, id_width, oct_encode, ModelBox, BOX_OFFSET, COUNT_OFFSETS, CRC_OFFSET,
    FLAG_COLORS, FLAG_HOPPE, HEADER_SIZE, KIND_BLOCK, MAGIC, NONE, VERSION,
};

/// The file's numbering of a hierarchy's nodes (see [`crate::format`], "Numbering").
struct FileOrder {
    /// File id of each node.
    id: Vec<u32>,
    /// Node of each file id.
    node: Vec<u32>,
    /// Parents in file order: the `k`-th has children `roots + 2k` and `roots + 2k + 1`.
    parents: Vec<u32>,
}

impl FileOrder {
    /// Breadth first from the roots (in id order); `None` unless that reaches every node once
    /// (a hierarchy that is not [`Hierarchy::is_consistent`]).
    fn of(h: &Hierarchy) -> Option<FileOrder> {
        let n = h.nodes.len();
        let mut id = alloc::vec![NONE; n];
        let mut node: Vec<u32> = h.roots().collect();
        let mut parents = Vec::new();
        for (k, &r) in node.iter().enumerate() {
            id[r as usize] = k as u32;
        }
        let mut next = 0;
        while let Some(&v) = node.get(next) {
            next += 1;
            if v < h.leaves {
                continue;
            }
            parents.push(v);
            for c in h.nodes[v as usize].children {
                let slot = id.get_mut(c as usize)?;
                if *slot != NONE || h.nodes[c as usize].parent != v {
                    return None;
                }
                *slot = node.len() as u32;
                node.push(c);
            }
        }
        (node.len() == n).then_some(FileOrder { id, node, parents })
    }
}

/// Appends values of a few bits each, least significant first.
struct BitWriter<'a> {
    out: &'a mut Vec<u8>,
    acc: u64,
    bits: u32,
}

impl<'a> BitWriter<'a> {
    fn new(out: &'a mut Vec<u8>) -> Self {
        BitWriter {
            out,
            acc: 0,
            bits: 0,
        }
    }

    /// Appends the low `width` (at most 32) bits of `v`.
    fn push(&mut self, v: u32, width: u32) {
        let v = if width >= 32 {
            v as u64
        } else {
            (v & ((1u32 << width) - 1)) as u64
        };
        self.acc |= v << self.bits;
        self.bits += width;
        while self.bits >= 8 {
            self.out.push(self.acc as u8);
            self.acc >>= 8;
            self.bits -= 8;
        }
    }

    /// An id at `width` bits; [`NONE`] as all ones.
    fn push_id(&mut self, id: u32, width: u32) {
        self.push(if id == NONE { u32::MAX } else { id }, width);
    }

    /// Pads the last byte with zeros.
    fn finish(self) {
        if self.bits > 0 {
            self.out.push(self.acc as u8);
        }
    }
}

impl Hierarchy {
    /// Each node's id in the file [`Hierarchy::to_bytes`] writes (empty for a hierarchy that
    /// is not [`Hierarchy::is_consistent`]): the file numbers nodes breadth first, so input
    /// vertex `v` is node `file_ids()[v]` there.
    pub fn file_ids(&self) -> Vec<u32> {
        FileOrder::of(self).map(|o| o.id).unwrap_or_default()
    }

    /// The hierarchy as bytes for [`crate::format::HierarchyView::parse`]. `colors` sets the
    /// header flag saying the nodes' colours mean something (and stores them).
    ///
    /// Positions are quantized to 16 bits over the nodes' bounding box, and every bound grows by
    /// twice the largest quantization error (a node and a leaf each move by at most that much),
    /// then rounds up to its 8-bit code: bounds stay bounds of what a device reads.
    pub fn to_bytes(&self, colors: bool) -> Vec<u8> {
        // A hierarchy that is not `is_consistent` gives bytes that `parse` rejects, not a panic.
        let n = self.nodes.len() as u32;
        let leaves = self.leaves.min(n);
        let base = self.base_triangles.len() as u32;
        let order = FileOrder::of(self).filter(|_| self.is_consistent());
        let faces = base.saturating_add((n - leaves).saturating_mul(2));
        let (wn, wf) = (id_width(n), id_width(faces));

        let model = ModelBox::around(self.nodes.iter().map(|node| node.position));
        let decoded = |p: [f32; 3]| model.dequantize(model.quantize(p));
        let mut moved = 0.0f64;
        for node in &self.nodes {
            let d = decoded(node.position);
            let e: f64 = (0..3)
                .map(|k| {
                    let x = d[k] as f64 - node.position[k] as f64;
                    x * x
                })
                .sum();
            moved = moved.max(crate::root::sqrt(e));
        }
        let grow = (2.0 * moved) as f32 * 1.001;
        let code = |v: f32| encode_length((v + grow) / model.unit());

        let mut out = Vec::new();
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        let hoppe = self.bound == ErrorBound::Hoppe;
        let flags = if colors { FLAG_COLORS } else { 0 } | if hoppe { FLAG_HOPPE } else { 0 };
        out.extend_from_slice(&flags.to_le_bytes());
        out.resize(HEADER_SIZE, 0);
        let Some(order) = order else {
            // More parents than leaves: `parse` refuses the counts.
            out[COUNT_OFFSETS[1]..COUNT_OFFSETS[1] + 4].copy_from_slice(&1u32.to_le_bytes());
            return out;
        };
        for (o, c) in COUNT_OFFSETS.into_iter().zip([leaves, n, base]) {
            out[o..o + 4].copy_from_slice(&c.to_le_bytes());
        }
        model.write(&mut out, BOX_OFFSET);
        let is_parent = |v: u32| v >= leaves;
        let mut before = 0u32;
        for block in order.node.chunks(KIND_BLOCK as usize) {
            let bits = block
                .iter()
                .enumerate()
                .filter(|&(_, &v)| is_parent(v))
                .fold(0u64, |b, (k, _)| b | 1 << k);
            out.extend_from_slice(&before.to_le_bytes());
            out.extend_from_slice(&bits.to_le_bytes());
            before += bits.count_ones();
        }
        for &v in &order.node {
            let node = &self.nodes[v as usize];
            for q in model.quantize(node.position) {
                out.extend_from_slice(&q.to_le_bytes());
            }
            let (x, y) = oct_encode(node.normal);
            out.extend_from_slice(&[x as u8, y as u8]);
            if is_parent(v) {
                let cone = libm::ceilf(node.cone_sin.clamp(0.0, 1.0) * 255.0) as u8;
                out.extend_from_slice(&[
                    code(node.radius),
                    code(node.spheroid[0]),
                    code(node.spheroid[1]),
                    cone,
                ]);
            }
        }
        if colors {
            for &v in &order.node {
                out.extend_from_slice(&self.nodes[v as usize].color);
            }
        }
        let mut bits = BitWriter::new(&mut out);
        for &p in &order.parents {
            bits.push_id(order.id[p as usize], wn);
        }
        bits.finish();
        // Triangle ids follow the parents' ranks: build id `base + 2 (p - leaves) + s` becomes
        // `base + 2 rank(p) + s`.
        let mut rank = alloc::vec![NONE; self.nodes.len()];
        for (k, &p) in order.parents.iter().enumerate() {
            rank[p as usize] = k as u32;
        }
        let face = |f: u32| match self.face_creator(f) {
            None if f < base => f,
            Some(p) if rank[p as usize] != NONE => base + 2 * rank[p as usize] + (f - base) % 2,
            _ => NONE,
        };
        let mut bits = BitWriter::new(&mut out);
        for &p in &order.parents {
            for &f in &self.nodes[p as usize].neighbours {
                bits.push_id(face(f), wf);
            }
        }
        bits.finish();
        for t in &self.base_triangles {
            for &v in t {
                out.extend_from_slice(&order.id[v as usize].to_le_bytes());
            }
        }

        let crc = crc32(&out[HEADER_SIZE..]);
        out[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
        out
    }
}
