//! Every vertex id's position during a build: the input's own vertices read from the input (in
//! `f32`, widened where asked), the vertices the collapses make kept in `f64`.
//!
//! The builder's memory peaks as its collapses start, when no vertex has been made yet: a copy of
//! the input's positions in `f64`, with room reserved for the made ones beside it, held 48 bytes
//! an input vertex there; this holds 24 bytes a made vertex, room for them reserved at the start
//! (kept in chunks, which the collapse records are, the reads of a position cost 3% more
//! instructions to save 1% of the peak).

use alloc::vec::Vec;

use super::vec3::{from_f32, Vec3d};

/// The positions of vertex ids `0..len()`: the input's first, then one per collapse.
pub(crate) struct Positions<'m> {
    input: &'m [[f32; 3]],
    made: Vec<Vec3d>,
}

impl<'m> Positions<'m> {
    /// The input's vertices, with room for `made` more.
    pub fn new(input: &'m [[f32; 3]], made: usize) -> Self {
        Positions {
            input,
            made: Vec::with_capacity(made),
        }
    }

    /// Vertex `v`'s position (panics past [`Positions::len`], as indexing an array would).
    #[inline]
    pub fn get(&self, v: u32) -> Vec3d {
        match self.input.get(v as usize) {
            Some(&p) => from_f32(p),
            None => self.made[v as usize - self.input.len()],
        }
    }

    /// Vertex ids so far.
    pub fn len(&self) -> usize {
        self.input.len() + self.made.len()
    }

    /// Adds the next vertex id's position.
    pub fn push(&mut self, p: Vec3d) {
        self.made.push(p);
    }

    /// Frees the made vertices' positions (the input's are borrowed).
    pub fn release(&mut self) {
        self.made = Vec::new();
    }
}
