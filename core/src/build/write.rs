//! Writing a [`Hierarchy`] in the format [`crate::format`] reads (version 3).

use alloc::vec::Vec;

use super::Hierarchy;
use crate::format::{
    crc32, encode_length, id_width, oct_encode, ModelBox, BOX_OFFSET, COUNT_OFFSETS, CRC_OFFSET,
    FLAG_COLORS, HEADER_SIZE, MAGIC, NONE, VERSION,
};

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
            moved = moved.max(libm::sqrt(e));
        }
        let grow = (2.0 * moved) as f32 * 1.001;
        let code = |v: f32| encode_length((v + grow) / model.unit());

        let mut out = Vec::new();
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(if colors { FLAG_COLORS } else { 0 }).to_le_bytes());
        out.resize(HEADER_SIZE, 0);
        for (o, c) in COUNT_OFFSETS.into_iter().zip([leaves, n, base]) {
            out[o..o + 4].copy_from_slice(&c.to_le_bytes());
        }
        model.write(&mut out, BOX_OFFSET);
        for (i, node) in self.nodes.iter().enumerate() {
            for q in model.quantize(node.position) {
                out.extend_from_slice(&q.to_le_bytes());
            }
            let (x, y) = oct_encode(node.normal);
            out.extend_from_slice(&[x as u8, y as u8]);
            if i >= leaves as usize {
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
            for node in &self.nodes {
                out.extend_from_slice(&node.color);
            }
        }
        let mut bits = BitWriter::new(&mut out);
        for node in &self.nodes {
            bits.push_id(node.parent, wn);
        }
        bits.finish();
        let mut bits = BitWriter::new(&mut out);
        for node in self.nodes.get(leaves as usize..).unwrap_or(&[]) {
            for &c in &node.children {
                bits.push_id(c, wn);
            }
            for &f in &node.neighbours {
                bits.push_id(f, wf);
            }
        }
        bits.finish();
        for t in &self.base_triangles {
            for v in t {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }

        let crc = crc32(&out[HEADER_SIZE..]);
        out[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
        out
    }
}
