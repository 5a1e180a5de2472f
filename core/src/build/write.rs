//! Writing a [`Hierarchy`] in the format [`crate::format`] reads.

use alloc::vec::Vec;

use super::Hierarchy;
use crate::format::{
    crc32, f32_to_f16_up, oct_encode, FLAG_COLORS, HEADER_SIZE, MAGIC, NODE_SIZE, SPLIT_SIZE,
    VERSION,
};

impl Hierarchy {
    /// The hierarchy as bytes for [`crate::format::HierarchyView::parse`]. `colors` sets the
    /// header flag saying the nodes' colours mean something.
    pub fn to_bytes(&self, colors: bool) -> Vec<u8> {
        // A hierarchy that is not `is_consistent` gives bytes that `parse` rejects, not a panic.
        let parent_nodes = self.nodes.get(self.leaves as usize..).unwrap_or(&[]);
        let parents = parent_nodes.len();
        let size = HEADER_SIZE
            + self.nodes.len() * NODE_SIZE
            + parents * SPLIT_SIZE
            + self.base_triangles.len() * 12;
        let mut out = Vec::with_capacity(size);
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(if colors { FLAG_COLORS } else { 0 }).to_le_bytes());
        for count in [
            self.leaves,
            self.nodes.len() as u32,
            self.base_triangles.len() as u32,
            0,
        ] {
            out.extend_from_slice(&count.to_le_bytes());
        }
        out.extend_from_slice(&[0u8; 16]); // checksum, then reserved
        for n in &self.nodes {
            for c in n.position {
                out.extend_from_slice(&c.to_le_bytes());
            }
            for b in [n.radius, n.mu, n.delta, n.spheroid[0], n.spheroid[1]] {
                out.extend_from_slice(&f32_to_f16_up(b).to_le_bytes());
            }
            let (x, y) = oct_encode(n.normal);
            out.extend_from_slice(&[x as u8, y as u8]);
            out.push(libm::ceilf(n.cone_sin.clamp(0.0, 1.0) * 255.0) as u8);
            out.extend_from_slice(&n.color);
            out.extend_from_slice(&n.depth.to_le_bytes());
            out.extend_from_slice(&n.parent.to_le_bytes());
        }
        for n in parent_nodes {
            for v in n.children.iter().chain(&n.wings).chain(&n.neighbours) {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        for t in &self.base_triangles {
            for v in t {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }

        let crc = crc32(&out[HEADER_SIZE..]);
        out[24..28].copy_from_slice(&crc.to_le_bytes());
        out
    }
}
