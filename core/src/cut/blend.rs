//! Geomorph state, and what each vertex looks like this frame.
//!
//! A vertex that is not blending is exactly its node: [`Cut::vertex`] reads its position,
//! normal and colour from the hierarchy in place, so the cut stores none of them. A blending
//! vertex has an entry in the blend arena (`Q` entries of 28 bytes, shared by all running
//! geomorphs): where it started, how many frames are left, and whether it blends towards its
//! parent (a collapse) or its own node (a split). Its output is a function of that entry and
//! the file, so starting a blend from "where it is now" is exact however blends overlap (the
//! wavelet paper's overlapping geomorphs, Azuma et al., "View-dependent refinement of
//! multiresolution meshes with subdivision connectivity", 2003, equation 6). When the arena is
//! full a change happens without a blend and the frame says so.

use super::slot::SlotIndex;
use super::{depth_color, Coloring, Cut, BLENDING, COLLAPSING, NIL};
use crate::format::HierarchyView;

/// Vertices in a batch of [`Cut::vertex_lanes`].
pub const LANES: usize = 8;

/// A vertex as drawn this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexOut {
    /// Position.
    pub position: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
    /// Colour (see [`Coloring`]).
    pub color: [u8; 3],
}

/// One running geomorph.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Blend {
    /// The vertex slot.
    pub slot: u32,
    pub from_position: [f32; 3],
    /// The start normal in units of 1/32767.
    pub from_normal: [i16; 3],
    pub from_color: [u8; 3],
    /// Towards the parent, for a collapse that happens when it arrives.
    pub collapsing: bool,
    /// Frames left; 0 once arrived (only a collapse waits there).
    pub left: u16,
}

impl Blend {
    pub const ZERO: Blend = Blend {
        slot: 0,
        from_position: [0.0; 3],
        from_normal: [0; 3],
        from_color: [0; 3],
        collapsing: false,
        left: 0,
    };
}

#[inline]
fn lerp3(a: [f32; 3], b: [f32; 3], s: f32) -> [f32; 3] {
    [
        a[0] + (b[0] - a[0]) * s,
        a[1] + (b[1] - a[1]) * s,
        a[2] + (b[2] - a[2]) * s,
    ]
}

impl<const V: usize, const F: usize, const Q: usize, I: SlotIndex> Cut<V, F, Q, I> {
    /// Node `node` as drawn when no geomorph moves it.
    #[inline(always)]
    fn node_out(&self, h: &HierarchyView<'_>, node: u32) -> VertexOut {
        let (position, normal, color) = h.vertex_inline(node);
        VertexOut {
            position,
            normal,
            color: self.node_color(h, node, color),
        }
    }

    /// Node `node`'s colour as drawn, `color` its colour in the file (see [`Coloring`]).
    #[inline(always)]
    fn node_color(&self, h: &HierarchyView<'_>, node: u32, color: [u8; 3]) -> [u8; 3] {
        match self.coloring {
            Coloring::Node => color,
            Coloring::Depth => depth_color(h.depth(node)),
        }
    }

    /// Slot `s` as drawn this frame: its node's position, normal and colour, or the blend
    /// between where it started and where it goes while a geomorph runs. (Slots out of range
    /// read as the default.)
    #[must_use]
    pub fn vertex(&self, h: &HierarchyView<'_>, s: usize) -> VertexOut {
        self.vertex_inline(h, s)
    }

    /// Slots `first..first + count` (at most [`LANES`]) as [`Cut::vertex`] reads them, into the
    /// caller's arrays attribute by attribute (lane `k` is slot `first + k`): how a renderer
    /// reads the cut a batch at a time. The slots in no geomorph (nearly all) are decoded lane
    /// by lane, in loops the compiler runs in SIMD registers, into the same floats
    /// [`Cut::vertex`] gives. Colours are read only when `colors` is given; lanes past `count`
    /// and slots past the last read as [`VertexOut::default`].
    ///
    /// ```
    /// # #[cfg(feature = "build")] {
    /// use vdlod_core::build::{build, BuildOptions, InputMesh};
    /// use vdlod_core::cut::{Cut, LANES};
    /// use vdlod_core::format::HierarchyView;
    /// let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
    ///                  [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    /// let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
    ///                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    /// let mesh = InputMesh { positions: &positions, colors: None, triangles: &triangles };
    /// let bytes = build(&mesh, &BuildOptions::default(), &mut |_| {}).unwrap().to_bytes(false);
    /// let h = HierarchyView::parse(&bytes).unwrap();
    /// let mut cut = Cut::<16, 32, 16>::new();
    /// cut.reset(&h).unwrap();
    /// let (mut p, mut n) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
    /// cut.vertex_lanes(&h, 0, LANES, &mut p, &mut n, None);
    /// assert_eq!([p[0][1], p[1][1], p[2][1]], cut.vertex(&h, 1).position);
    /// assert_eq!([n[0][7], n[1][7], n[2][7]], [0.0; 3]); // past the last slot
    /// # }
    /// ```
    #[inline(always)]
    pub fn vertex_lanes(
        &self,
        h: &HierarchyView<'_>,
        first: usize,
        count: usize,
        positions: &mut [[f32; LANES]; 3],
        normals: &mut [[f32; LANES]; 3],
        mut colors: Option<&mut [[u8; LANES]; 3]>,
    ) {
        let n = count.min(LANES);
        let slots = first..first.saturating_add(n);
        let still = |f: &[u8]| f.iter().all(|f| f & (BLENDING | COLLAPSING) == 0);
        let plain = self
            .v
            .nodes()
            .get(slots.clone())
            .filter(|_| self.v.flags.get(slots.clone()).is_some_and(still));
        let Some(nodes) = plain else {
            for k in 0..LANES {
                let v = match k < n {
                    true => self.vertex_inline(h, first.saturating_add(k)),
                    false => VertexOut::default(),
                };
                for a in 0..3 {
                    positions[a][k] = v.position[a];
                    normals[a][k] = v.normal[a];
                    if let Some(c) = colors.as_deref_mut() {
                        c[a][k] = v.color[a];
                    }
                }
            }
            return;
        };
        let mut leading = [[0u8; 8]; LANES];
        for (r, &node) in leading.iter_mut().zip(nodes) {
            *r = h.leading(node);
        }
        h.decode_lanes(&leading, positions, normals);
        for k in n..LANES {
            for a in 0..3 {
                positions[a][k] = 0.0;
                normals[a][k] = 0.0;
            }
        }
        if let Some(c) = colors {
            *c = [[0; LANES]; 3];
            for (k, &node) in nodes.iter().enumerate() {
                let color = self.node_color(h, node, h.color(node));
                for (channel, color) in c.iter_mut().zip(color) {
                    channel[k] = color;
                }
            }
        }
    }

    /// [`Cut::vertex`], inlined where it is called.
    #[inline(always)]
    fn vertex_inline(&self, h: &HierarchyView<'_>, s: usize) -> VertexOut {
        let Some(&node) = self.v.nodes().get(s) else {
            return VertexOut::default();
        };
        let Some(b) = self.blends.as_slice().get(self.v.blend(s) as usize) else {
            return self.node_out(h, node);
        };
        let to = self.node_out(h, if b.collapsing { h.parent(node) } else { node });
        let total = self.geomorph_frames.max(1);
        if b.left == 0 {
            // Arrived: exactly the target (a + (b - a) need not round to b).
            return to;
        }
        let done = 1.0 - b.left.min(total) as f32 / total as f32;
        let from_normal = b.from_normal.map(|c| c as f32 / 32767.0);
        let n = lerp3(from_normal, to.normal, done);
        let l = crate::root::sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        let c = |k: usize| {
            let (x, y) = (b.from_color[k] as f32, to.color[k] as f32);
            (x + (y - x) * done + 0.5) as u8
        };
        VertexOut {
            position: lerp3(b.from_position, to.position, done),
            normal: if l > 1e-12 {
                [n[0] / l, n[1] / l, n[2] / l]
            } else {
                to.normal
            },
            color: [c(0), c(1), c(2)],
        }
    }

    /// Starts (or restarts) a blend of slot `s` from `from` over `frames` frames, towards the
    /// parent when `collapsing`, else towards its own node. `false` (and no blend) when the
    /// arena is full or `frames` is 0.
    pub(crate) fn start_blend_from(
        &mut self,
        s: usize,
        from: &VertexOut,
        frames: u16,
        collapsing: bool,
    ) -> bool {
        let entry = Blend {
            slot: s as u32,
            from_position: from.position,
            from_normal: from.normal.map(|c| (c.clamp(-1.0, 1.0) * 32767.0) as i16),
            from_color: from.color,
            collapsing,
            left: frames,
        };
        if frames == 0 {
            self.free_blend(s);
            return false;
        }
        // Read before the flags are cleared: the tag is the blend entry only while they are set.
        let k = self.v.blend(s) as usize;
        self.v.flags[s] &= !(BLENDING | COLLAPSING);
        if let Some(b) = self.blends.as_mut_slice().get_mut(k) {
            *b = entry;
        } else if Q > Self::BLEND_ROOM && self.blends.len() >= Self::BLEND_ROOM {
            // (Only a cut whose arena outgrows what a tag can name checks: for the others a
            // full arena is this limit, and the push below refuses.)
            return false;
        } else {
            match self.blends.push(entry) {
                Ok(k) => self.v.set_blend(s, k),
                Err(_) => return false,
            }
        }
        self.v.flags[s] |= BLENDING | if collapsing { COLLAPSING } else { 0 };
        true
    }

    /// Starts (or reverses) a blend of slot `s` from where it is now; see
    /// [`Cut::start_blend_from`].
    pub(crate) fn start_blend(
        &mut self,
        h: &HierarchyView<'_>,
        s: usize,
        collapsing: bool,
    ) -> bool {
        let from = self.vertex(h, s);
        self.start_blend_from(s, &from, self.geomorph_frames, collapsing)
    }

    /// Ends slot `s`'s blend, if any: it is its node again. The test is inlined (most vertices
    /// a split or collapse renames are not blending, and none in a first frame), the rest not.
    #[inline(always)]
    pub(crate) fn free_blend(&mut self, s: usize) {
        let k = self.v.blend(s);
        if k != NIL {
            self.end_blend(s, k);
        }
    }

    /// [`Cut::free_blend`] of slot `s`, blending with entry `k`.
    #[inline(never)]
    fn end_blend(&mut self, s: usize, k: u32) {
        self.v.set_blend(s, NIL);
        self.v.flags[s] &= !(BLENDING | COLLAPSING);
        if let Some((_, Some(_))) = self.blends.swap_remove(k as usize) {
            // The last entry moved into k: tell its vertex.
            let moved = self.blends.as_slice()[k as usize].slot;
            self.v.set_blend(moved as usize, k);
        }
    }

    /// Advances slot `s`'s blend by one frame; a split's blend ends when it arrives, a
    /// collapse's waits there for the collapse.
    pub(crate) fn advance(&mut self, s: usize) {
        let total = self.geomorph_frames.max(1);
        let k = self.v.blend(s) as usize;
        let Some(b) = self.blends.as_mut_slice().get_mut(k) else {
            self.v.flags[s] &= !(BLENDING | COLLAPSING);
            return;
        };
        b.left = b.left.saturating_sub(1).min(total);
        if b.left > 0 {
            return;
        }
        if b.collapsing {
            self.v.flags[s] &= !BLENDING;
        } else {
            self.free_blend(s);
        }
    }

    /// Vertices with a geomorph running.
    #[must_use]
    pub fn blending(&self) -> u32 {
        self.blends.as_slice().iter().filter(|b| b.left > 0).count() as u32
    }
}
