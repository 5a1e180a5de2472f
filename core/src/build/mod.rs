//! The offline hierarchy builder (feature `build`, needs `alloc`).
//!
//! From an indexed triangle mesh to a vertex forest by repeated legal edge collapse (the
//! merge-tree paper §3.1, with Hoppe-style renaming, §3.2): each collapse of `a-b` makes a new
//! vertex, the parent of `a` and `b`, until no legal collapse is left or the mesh is down to
//! [`BuildOptions::base_vertices`]. Unlike the paper's implementation the builder accepts open
//! meshes (borders are kept in place by boundary quadrics and never pinched or closed), runs in
//! O(n log n) with a heap of costs, and keeps genus and border loops.
//!
//! Costs ([`Cost`]): the quadric error metric with optimal placement (the LOD lecture; default),
//! the shortest edge (merge-tree paper), and the importance paper's colour-aware
//! `Gerr^2 + length^2 + sqrt(length * dcolor)` (with `Gerr` the exact distance to the input
//! surface, found through a grid of its triangles). With [`BuildOptions::balanced`], the merge-tree
//! paper's region-of-influence marking keeps the forest shallow: a triangle touched by a collapse
//! blocks further collapses around it until no unblocked collapse is left, which the builder
//! runs as passes over the edges sorted by cost (`passes.rs`).
//!
//! Each node then gets what the run-time tests need ([`Node`]): a bounding-sphere radius over its
//! subtree's region (merge-tree §3.3), a cone of normals, an error bound ([`ErrorBound`]: the
//! leaves' offsets, or the wavelet paper's spheroid or Hoppe's deviation space over the
//! residuals to the coarse surface), colour, depth, and its
//! neighbouring triangles (Hoppe's `fn0..fn3`). [`Hierarchy::refine_all`] replays every split from the base mesh with nothing but
//! the nodes' records.
//!
//! ```
//! use vdlod_core::build::{build, rotate_to_min, BuildOptions, InputMesh};
//! // An octahedron collapses to a tetrahedron, the smallest closed surface.
//! let positions = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
//!                  [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
//! let triangles = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
//!                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
//! let mesh = InputMesh { positions: &positions, colors: None, triangles: &triangles };
//! let h = build(&mesh, &BuildOptions::default(), &mut |_| {}).unwrap();
//! assert_eq!(h.base_triangles.len(), 4);
//! // Every split replayed from the base mesh gives back the octahedron.
//! let mut full = h.refine_all();
//! full.sort();
//! let mut expected: Vec<[u32; 3]> = triangles.iter().map(|&t| rotate_to_min(t)).collect();
//! expected.sort();
//! assert_eq!(full, expected);
//! ```

pub(crate) mod around;
mod attributes;
pub mod bound;
mod chunks;
pub(crate) mod closest;
pub(crate) mod collapse;
pub(crate) mod flatten;
mod input;
mod lists;
mod passes;
mod positions;
mod quadric;
mod queue;
mod rejected;
pub(crate) mod vec3;
mod write;

use alloc::vec::Vec;

pub use collapse::Collapse;
pub use input::{validate, BuildError, InputMesh};

/// "No vertex": a missing wing (border edge) or parent (root); the same value the file stores.
pub use crate::format::NONE;

/// How the next edge to collapse is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Cost {
    /// Quadric error metric with optimal placement.
    #[default]
    Quadric,
    /// Shortest edge first, merged at its midpoint (merge-tree paper §3.1; see [`Placement`]).
    ShortestEdge,
    /// The importance paper's colour-aware cost `Gerr^2 + length^2 + sqrt(length * dcolor)`:
    /// the merged vertex at the edge's midpoint ([`Placement`]), `Gerr` its distance to the
    /// closest point of the input surface, `dcolor` the RGB distance of the two colours (0..1
    /// per channel).
    Color,
}

/// Where a collapse puts the vertex it makes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Placement {
    /// Where the cost puts it: the quadrics' minimiser for [`Cost::Quadric`], the edge's
    /// midpoint for the other two.
    #[default]
    Cost,
    /// On the endpoint with the smaller quadric error (a half-edge collapse), with that
    /// endpoint's normal and colour: every vertex of the forest is an input vertex, so a split
    /// leaves the triangles around the staying child as they were (a terrain's vertices stay on
    /// its samples). Fewer triangles change from frame to frame, at some cost in fidelity
    /// (`vdlod-demo reproduce terrain-engines`).
    Endpoint,
}

/// What a parent's two error-bound lengths hold (the file's `a` and `b` codes), and how they are
/// measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ErrorBound {
    /// The leaves' offsets from the node along its normal: `a` the largest and `b = a` (a
    /// sphere of that radius), `b` widened on a border by how far the outline moves. Measures
    /// the error against the node's tangent plane, so on a curved region it grows with the
    /// region's width even where the coarse surface follows the fine one.
    #[default]
    Offset,
    /// The wavelet paper's spheroid (equation 3, [`bound::equation3`]) over the *residuals*:
    /// from each leaf below the node to the closest point of the triangles around the node when
    /// the builder made it (Hoppe's deviation space, measured the same way). Read by
    /// [`crate::policy::ScreenError`].
    Spheroid,
    /// Hoppe's `delta` and `mu` ([`bound::hoppe`]) over the same residuals, in the `a` and `b`
    /// fields; the file says so with [`crate::format::FLAG_HOPPE`], and
    /// [`crate::policy::HoppeError`] reads them.
    Hoppe,
}

/// Settings of [`build`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildOptions {
    /// Collapse cost.
    pub cost: Cost,
    /// Region-of-influence marking (merge-tree paper §3.1) for a balanced, shallow forest: the
    /// collapses run in passes, each collapsing, cheapest first, the edges whose regions no
    /// other collapse of the pass has touched.
    pub balanced: bool,
    /// Stop when this many vertices are left (0: collapse while any collapse is legal).
    pub base_vertices: u32,
    /// The error bound the parents carry.
    pub bound: ErrorBound,
    /// Where merged vertices go.
    pub placement: Placement,
}

/// Progress of a build, for a progress bar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Collapses done.
    pub done: u32,
    /// Collapses the build can do at most (vertices minus the base size).
    pub total: u32,
}

/// One vertex of the forest.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Position.
    pub position: [f32; 3],
    /// Parent, or [`NONE`] for a root (a vertex of the base mesh).
    pub parent: u32,
    /// Children, `[NONE; 2]` for a leaf (a vertex of the input mesh). The split of this node adds
    /// triangles `(children[0], children[1], wings[0])` and `(children[1], children[0], wings[1])`.
    pub children: [u32; 2],
    /// Third corners of the triangles the split adds; `wings[1]` is [`NONE`] on a border.
    pub wings: [u32; 2],
    /// The triangles across the outer edges of the two the split adds, in the order
    /// `c1-w0`, `w0-c0`, `c0-w1`, `w1-c1`, or [`NONE`] on a border; triangles are numbered as
    /// [`Hierarchy::face_id`] says. They are Hoppe's `fn0..fn3`: the split is legal when all four
    /// exist in the current mesh, the collapse when they are still the added triangles'
    /// neighbours. Leaves: `[NONE; 4]`.
    pub neighbours: [u32; 4],
    /// Radius of a sphere around `position` holding the node's region and all its descendants'.
    pub radius: f32,
    /// Axis of the cone of normals of the node's region (unit length).
    pub normal: [f32; 3],
    /// Sine of the cone's half-angle (`1.0` or more: the cone is not a useful bound).
    pub cone_sin: f32,
    /// The error bound of [`Hierarchy::bound`] over the descendant leaves, `[a, b]`: a
    /// normal-aligned spheroid (`a` along the normal, `b` across it) or Hoppe's `[delta, mu]`.
    /// At least the children's, component by component.
    pub spheroid: [f32; 2],
    /// Colour (area-weighted mean of the region's vertex colours).
    pub color: [u8; 3],
    /// Depth in the forest: 0 for roots.
    pub depth: u16,
}

/// A built vertex forest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hierarchy {
    /// The input's vertex count: nodes `0..leaves` are the input vertices, in input order (in
    /// the file they are numbered otherwise: [`Hierarchy::file_ids`]).
    pub leaves: u32,
    /// All nodes: the leaves, then the parents in the order they were formed.
    pub nodes: Vec<Node>,
    /// The triangles left after the last collapse, over root nodes.
    pub base_triangles: Vec<[u32; 3]>,
    /// What the nodes' [`Node::spheroid`] holds.
    pub bound: ErrorBound,
    /// Edges pushed on the cost heap during the build: the work done, linear in the mesh size for
    /// meshes of bounded vertex degree.
    pub heap_pushes: u64,
}

impl Default for Node {
    fn default() -> Node {
        Node {
            position: [0.0; 3],
            parent: NONE,
            children: [NONE; 2],
            wings: [NONE; 2],
            neighbours: [NONE; 4],
            radius: 0.0,
            normal: [0.0, 0.0, 1.0],
            cone_sin: 1.0,
            spheroid: [0.0; 2],
            color: [0; 3],
            depth: 0,
        }
    }
}

impl Hierarchy {
    /// The id of a triangle: base triangle `k` is `k`; the split of parent `p` adds triangles
    /// `base + 2 (p - leaves)` (`children[0], children[1], wings[0]`) and the next id
    /// (`children[1], children[0], wings[1]`, absent on a border). Every triangle of every cut
    /// has one id for as long as it exists, whatever its corners are renamed to. (These are the
    /// build's ids; the file renumbers nodes and triangles: see [`Hierarchy::file_ids`].)
    pub fn face_id(&self, parent: u32, second: bool) -> u32 {
        (self.base_triangles.len() as u32)
            .wrapping_add(parent.wrapping_sub(self.leaves).wrapping_mul(2))
            .wrapping_add(second as u32)
    }

    /// The parent whose split adds triangle `face` ([`Hierarchy::face_id`]'s inverse), or `None`
    /// for a base triangle and ids out of range.
    pub fn face_creator(&self, face: u32) -> Option<u32> {
        let k = face.checked_sub(self.base_triangles.len() as u32)? / 2;
        let p = self.leaves.checked_add(k)?;
        ((p as usize) < self.nodes.len()).then_some(p)
    }

    /// The roots: the vertices of the base mesh (including input vertices no triangle used).
    pub fn roots(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.nodes.len() as u32).filter(|&i| self.nodes[i as usize].parent == NONE)
    }

    /// Deepest leaf and mean leaf depth.
    pub fn depth_stats(&self) -> (u32, f64) {
        let leaves = &self.nodes[..self.leaves as usize];
        let max = leaves.iter().map(|n| n.depth as u32).max().unwrap_or(0);
        let mean = leaves.iter().map(|n| n.depth as f64).sum::<f64>() / leaves.len().max(1) as f64;
        (max, mean)
    }

    /// Whether every id in the hierarchy is in range and children come before their parents (always
    /// so for [`build`]'s output; the replays below return nothing for anything else).
    pub fn is_consistent(&self) -> bool {
        let n = self.nodes.len() as u32;
        let leaves = self.leaves;
        leaves <= n
            && self.nodes.iter().enumerate().all(|(i, node)| {
                let i = i as u32;
                let parent_ok = node.parent == NONE || (node.parent > i && node.parent < n);
                let split_ok = if i < leaves {
                    node.children == [NONE; 2]
                } else {
                    node.children.iter().all(|&c| c < i)
                        && node.children[0] != node.children[1]
                        && node.wings[0] < n
                        && (node.wings[1] == NONE || node.wings[1] < n)
                };
                parent_ok && split_ok
            })
            && self.base_triangles.iter().flatten().all(|&v| v < n)
    }

    /// Replays every collapse, first to last, on `input` (the triangles the hierarchy was built
    /// from) using only the nodes' children and wings: each removes the triangles
    /// `(c0, c1, w0)` and `(c1, c0, w1)` and renames `c0` and `c1` to the parent. Returns the
    /// triangles left, each rotated to start at its smallest index; for a hierarchy from
    /// [`build`] they are [`Hierarchy::base_triangles`].
    pub fn collapse_all(&self, input: &[[u32; 3]]) -> Vec<[u32; 3]> {
        let n = self.nodes.len() as u32;
        if !self.is_consistent() || input.iter().flatten().any(|&v| v >= n) {
            return Vec::new();
        }
        let mut faces: Vec<Option<[u32; 3]>> = input.iter().map(|&t| Some(t)).collect();
        let mut around: Vec<Vec<u32>> = alloc::vec![Vec::new(); self.nodes.len()];
        for (f, t) in input.iter().enumerate() {
            for &v in t {
                if let Some(list) = around.get_mut(v as usize) {
                    list.push(f as u32);
                }
            }
        }
        for p in self.leaves..self.nodes.len() as u32 {
            let node = &self.nodes[p as usize];
            let [c0, c1] = node.children;
            let [w0, w1] = node.wings;
            let removed = [rotate_to_min([c0, c1, w0]), rotate_to_min([c1, c0, w1])];
            for c in [c0, c1] {
                for f in core::mem::take(&mut around[c as usize]) {
                    let Some(t) = faces[f as usize] else { continue };
                    if removed.contains(&rotate_to_min(t)) {
                        faces[f as usize] = None;
                        continue;
                    }
                    let renamed = t.map(|v| if v == c0 || v == c1 { p } else { v });
                    faces[f as usize] = Some(renamed);
                    around[p as usize].push(f);
                }
            }
        }
        faces.into_iter().flatten().map(rotate_to_min).collect()
    }

    /// Replays every vertex split, last collapse first, from the base mesh, using only the nodes'
    /// children and wings; returns the triangles with each rotated to start at its smallest index.
    /// For a hierarchy from [`build`], these are exactly the input's triangles; for one that is not
    /// [`Hierarchy::is_consistent`], nothing.
    pub fn refine_all(&self) -> Vec<[u32; 3]> {
        if !self.is_consistent() {
            return Vec::new();
        }
        let mut faces: Vec<[u32; 3]> = self.base_triangles.clone();
        // Faces around each vertex, kept up to date.
        let mut around: Vec<Vec<u32>> = alloc::vec![Vec::new(); self.nodes.len()];
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                around[v as usize].push(f as u32);
            }
        }
        for p in (self.leaves..self.nodes.len() as u32).rev() {
            let node = &self.nodes[p as usize];
            let [c0, c1] = node.children;
            let [w0, w1] = node.wings;
            // Walk the fan around p counter-clockwise from the triangle (p, w0, .) until the
            // triangle (p, ., w1): those triangles belonged to c0, the rest to c1. If c0 was on a
            // border, the walk meets it first; c0's other triangles then lie clockwise of w1.
            let find = |faces: &[[u32; 3]], around: &[Vec<u32>], x: u32, ccw: bool| {
                around[p as usize].iter().copied().find_map(|f| {
                    let t = faces[f as usize];
                    let k = (0..3).find(|&k| t[k] == p)?;
                    let (next, prev) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                    match ccw {
                        true if next == x => Some((f, prev)),
                        false if prev == x => Some((f, next)),
                        _ => None,
                    }
                })
            };
            let mut to_c0 = Vec::new();
            let guard = around[p as usize].len();
            let mut x = w0;
            let mut reached_w1 = false;
            while let Some((f, y)) = find(&faces, &around, x, true) {
                if to_c0.contains(&f) || to_c0.len() > guard {
                    break;
                }
                to_c0.push(f);
                if y == w1 {
                    reached_w1 = true;
                    break;
                }
                x = y;
            }
            if !reached_w1 && w1 != NONE {
                let mut x = w1;
                while let Some((f, y)) = find(&faces, &around, x, false) {
                    if to_c0.contains(&f) || to_c0.len() > guard {
                        break;
                    }
                    to_c0.push(f);
                    x = y;
                }
            }
            for f in core::mem::take(&mut around[p as usize]) {
                let child = if to_c0.contains(&f) { c0 } else { c1 };
                for v in faces[f as usize].iter_mut() {
                    if *v == p {
                        *v = child;
                    }
                }
                around[child as usize].push(f);
            }
            for t in [[c0, c1, w0], [c1, c0, w1]] {
                if t.contains(&NONE) {
                    continue;
                }
                let f = faces.len() as u32;
                faces.push(t);
                for v in t {
                    around[v as usize].push(f);
                }
            }
        }
        faces.iter().map(|&t| rotate_to_min(t)).collect()
    }
}

/// The same oriented triangle, starting at its smallest index.
pub fn rotate_to_min(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

/// Builds the vertex forest of `mesh`; `progress` is called now and then.
pub fn build(
    mesh: &InputMesh<'_>,
    opts: &BuildOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Hierarchy, BuildError> {
    let on_border = input::checked(mesh)?;
    let target = (opts.base_vertices as usize).max(1);
    // The balanced forest is made in passes (each collapses the cheapest edges whose regions
    // do not touch), the other by one collapse at a time from a heap of costs.
    let collapsed = if opts.balanced {
        let mut engine = passes::Passes::new(mesh, opts, &on_border);
        let total = engine.alive_count.saturating_sub(target) as u32;
        progress(Progress { done: 0, total });
        engine.run(target, &mut |done| progress(Progress { done, total }));
        engine.into_collapsed()
    } else {
        let mut engine = collapse::Engine::new(mesh, opts);
        let total = engine.alive_count.saturating_sub(target) as u32;
        let step = (total / 200).max(1);
        let mut done = 0u32;
        progress(Progress { done, total });
        while engine.alive_count > target && engine.step() {
            done += 1;
            if done.is_multiple_of(step) {
                progress(Progress { done, total });
            }
        }
        progress(Progress { done, total });
        engine.into_collapsed()
    };
    Ok(attributes::finish(mesh, collapsed, &on_border))
}

#[cfg(test)]
pub(crate) mod tests;
