//! Untangling a patch of the remesh at once, for the folds single-vertex moves leave.
//!
//! The relaxation moves one vertex at a time, and a fold whose every vertex has an empty
//! kernel while its neighbours stay (the ring itself is tangled) stays folded. Here the
//! vertices of a few rings round a triangle facing the wrong way move together down the
//! gradient of an untangling energy, each step put back on the input. For each triangle, with
//! `s` its area seen along the input's normal there (negative when it faces the wrong way), the
//! energy is `sqrt(s^2 + d^2) - s = d^2 / (2 h(s))`, where `h(s) = (s + sqrt(s^2 + d^2)) / 2`
//! is the regularized area of Escobar, Rodriguez, Montenegro, Montero and Gonzalez-Yuste
//! ("Simultaneous untangling and smoothing of tetrahedral meshes", 2003), here for triangles on
//! a surface: about `2|s|` for a folded triangle, falling towards 0 as `s` grows past `d`.
//! Over a patch whose rim stays, the areas' sum is about fixed, so lowering the energy spreads
//! it until every triangle has some. A patch's moves are kept only when fewer of its
//! triangles face the wrong way and no gap from the input opens wider than the reach.
//!
//! The same descent lets the snapping pull a vertex onto a tip where that alone would fold
//! the triangles round it: the move stays when its neighbours can untangle them.

use alloc::vec;
use alloc::vec::Vec;

use super::relax::{OnInput, Relax, NONE_VERTEX};
use crate::build::closest::point;
use crate::build::vec3::{add, cross, dot, from_f32, len, normalize, scale, sub, Vec3d};

/// Steps of gradient descent per patch.
const STEPS: u32 = 300;

/// Rings round a folded triangle tried, smallest first.
const MAX_RINGS: u32 = 4;

/// Where some remesh vertices are, in space and on the input, to be put back.
struct Saved(Vec<([f32; 3], OnInput)>);

impl Saved {
    fn of(verts: &[u32], positions: &[[f32; 3]], on_input: &[OnInput]) -> Saved {
        Saved(
            verts
                .iter()
                .map(|&v| (positions[v as usize], on_input[v as usize]))
                .collect(),
        )
    }

    fn restore(&self, verts: &[u32], positions: &mut [[f32; 3]], on_input: &mut [OnInput]) {
        for (&v, &(p, o)) in verts.iter().zip(&self.0) {
            positions[v as usize] = p;
            on_input[v as usize] = o;
        }
    }
}

impl Relax<'_> {
    /// The untangling energy of triangle `t` and its gradient at each corner, with `d` the
    /// area below which a triangle counts as nearly flat.
    fn energy(
        &self,
        t: u32,
        d: f64,
        positions: &[[f32; 3]],
        on_input: &[OnInput],
    ) -> (f64, [Vec3d; 3]) {
        let tri = self.triangles[t as usize];
        let c = tri.map(|x| from_f32(positions[x as usize]));
        let seen = tri.iter().fold([0.0; 3], |s, &x| {
            add(s, self.normals[on_input[x as usize].0 as usize])
        });
        let Some(m) = normalize(seen) else {
            return (0.0, [[0.0; 3]; 3]);
        };
        let s = 0.5 * dot(cross(sub(c[1], c[0]), sub(c[2], c[0])), m);
        let root = crate::root::sqrt(s * s + d * d);
        let slope = s / root - 1.0;
        // d s / d corner k = 0.5 (c[k+1] - c[k+2]) x m.
        let g =
            [0, 1, 2].map(|k| scale(cross(sub(c[(k + 1) % 3], c[(k + 2) % 3]), m), 0.5 * slope));
        (root - s, g)
    }

    /// Untangles each triangle still facing the wrong way with its surrounding patch
    /// (see the module's documentation); returns how many triangles face the wrong way after.
    pub(super) fn untangle(&self, positions: &mut [[f32; 3]], on_input: &mut [OnInput]) -> u32 {
        let mut left = 0;
        for t in 0..self.triangles.len() as u32 {
            if !self.wrong(t, positions, on_input) {
                continue;
            }
            let seeds = self.triangles[t as usize];
            let solved = (1..=MAX_RINGS).any(|rings| {
                let (verts, tris) = self.patch(&seeds, rings, true);
                self.settle(&verts, &tris, None, self.reach, positions, on_input)
            });
            left += u32::from(!solved);
        }
        left
    }

    /// Moves `v` to `to` (a point, its input triangle and weights there) when the triangles
    /// it turns against the input can be untangled by its neighbours within a ring or two
    /// (snapped vertices stay) without opening a gap from the input wider than there was or
    /// than `reach`; else leaves every vertex where it was. Says whether `v` moved.
    pub(super) fn move_untangled(
        &self,
        v: u32,
        to: (Vec3d, u32, [f64; 3]),
        reach: f64,
        positions: &mut [[f32; 3]],
        on_input: &mut [OnInput],
    ) -> bool {
        let first = (v, (to.0.map(|c| c as f32), (to.1, to.2)));
        (2..=3).any(|rings| {
            let (mut verts, tris) = self.patch(&[v], rings, false);
            verts.retain(|&x| x != v);
            self.settle(&verts, &tris, Some(first), reach, positions, on_input)
        })
    }

    /// With `first`'s vertex moved first, untangles the triangles `tris` by moving `verts`
    /// ([`Relax::descend`]); keeps the result when none faces the wrong way and they leave the
    /// input by no more than they did or than `reach`, else puts every vertex back. Says
    /// which.
    fn settle(
        &self,
        verts: &[u32],
        tris: &[u32],
        first: Option<(u32, ([f32; 3], OnInput))>,
        reach: f64,
        positions: &mut [[f32; 3]],
        on_input: &mut [OnInput],
    ) -> bool {
        let mut all = verts.to_vec();
        all.extend(first.map(|(v, _)| v));
        let saved = Saved::of(&all, positions, on_input);
        if let Some((v, (p, o))) = first {
            positions[v as usize] = p;
            on_input[v as usize] = o;
        }
        if !self.descend(verts, tris, positions, on_input) {
            saved.restore(&all, positions, on_input);
            return false;
        }
        // The gaps are measured only now, after and (for a moment) before: most patches
        // do not untangle, and the distances are the dearest part.
        let after = self.gap(tris, NONE_VERTEX, [0.0; 3], positions);
        let untangled = Saved::of(&all, positions, on_input);
        saved.restore(&all, positions, on_input);
        let before = self.gap(tris, NONE_VERTEX, [0.0; 3], positions);
        if after <= before.max(reach) {
            untangled.restore(&all, positions, on_input);
            return true;
        }
        false
    }

    /// Whether triangle `t` faces against the input.
    pub(super) fn wrong(&self, t: u32, positions: &[[f32; 3]], on_input: &[OnInput]) -> bool {
        self.facing(&[t], NONE_VERTEX, None, positions, on_input).0 > 0
    }

    /// The vertices within `rings - 1` rings of `seeds` that may move (not on the border; not
    /// snapped onto a tip unless `snapped_move`), sorted, and the triangles round them.
    fn patch(&self, seeds: &[u32], rings: u32, snapped_move: bool) -> (Vec<u32>, Vec<u32>) {
        let mut verts: Vec<u32> = seeds.to_vec();
        verts.sort_unstable();
        verts.dedup();
        let mut ring = verts.clone();
        for _ in 1..rings {
            let mut next: Vec<u32> = Vec::new();
            for &v in &ring {
                for &s in self.around_remesh.of(v) {
                    next.extend(
                        self.triangles[s as usize]
                            .iter()
                            .filter(|x| verts.binary_search(x).is_err()),
                    );
                }
            }
            next.sort_unstable();
            next.dedup();
            verts.extend_from_slice(&next);
            verts.sort_unstable();
            ring = next;
        }
        verts.retain(|&v| !self.fixed[v as usize] && (snapped_move || !self.snapped[v as usize]));
        let mut tris: Vec<u32> = verts
            .iter()
            .chain(seeds)
            .flat_map(|&v| self.around_remesh.of(v).iter().copied())
            .collect();
        tris.sort_unstable();
        tris.dedup();
        (verts, tris)
    }

    /// Moves the patch `verts` (with the triangles `tris` round them) down the energy's
    /// gradient, each step put back on the input and taken only when it lowers the energy (else
    /// the step halves), until none of `tris` faces the wrong way; says whether that happened
    /// (if not, the patch is left wherever the descent stopped).
    fn descend(
        &self,
        verts: &[u32],
        tris: &[u32],
        positions: &mut [[f32; 3]],
        on_input: &mut [OnInput],
    ) -> bool {
        let count = |positions: &[[f32; 3]], on_input: &[OnInput]| {
            tris.iter()
                .filter(|&&t| self.wrong(t, positions, on_input))
                .count()
        };
        if count(positions, on_input) == 0 {
            return true;
        }
        if verts.is_empty() {
            return false;
        }
        // The scale of the patch: its mean triangle area; moves are a fraction of the mean edge.
        let mut area = 0.0;
        let mut edge = 0.0;
        for &t in tris {
            let c = self.triangles[t as usize].map(|x| from_f32(positions[x as usize]));
            area += 0.5 * len(cross(sub(c[1], c[0]), sub(c[2], c[0])));
            edge += len(sub(c[1], c[0]));
        }
        area /= tris.len() as f64;
        edge /= tris.len() as f64;
        let d = 0.1 * area;
        let index = |v: u32| verts.binary_search(&v).ok();
        let mut grad = vec![[0.0; 3]; verts.len()];
        let total = |positions: &[[f32; 3]], on_input: &[OnInput]| -> f64 {
            tris.iter()
                .map(|&t| self.energy(t, d, positions, on_input).0)
                .sum()
        };
        let mut e = total(positions, on_input);
        let mut step = 0.1 * edge;
        for _ in 0..STEPS {
            grad.iter_mut().for_each(|g| *g = [0.0; 3]);
            for &t in tris {
                let (_, g) = self.energy(t, d, positions, on_input);
                for (k, &x) in self.triangles[t as usize].iter().enumerate() {
                    if let Some(i) = index(x) {
                        grad[i] = add(grad[i], g[k]);
                    }
                }
            }
            let largest = grad.iter().map(|g| len(*g)).fold(0.0, f64::max);
            if largest <= 0.0 {
                break;
            }
            let old = Saved::of(verts, positions, on_input);
            for (i, &v) in verts.iter().enumerate() {
                let here = from_f32(positions[v as usize]);
                let target = sub(here, scale(grad[i], step / largest));
                let (face, w) = self.project(target, on_input[v as usize].0);
                positions[v as usize] = point(self.corners(face), w).map(|x| x as f32);
                on_input[v as usize] = (face, w);
            }
            let e2 = total(positions, on_input);
            if e2 >= e {
                old.restore(verts, positions, on_input);
                step *= 0.5;
                if step < 1e-4 * edge {
                    break;
                }
                continue;
            }
            e = e2;
            step *= 1.2;
            if count(positions, on_input) == 0 {
                return true;
            }
        }
        false
    }
}
