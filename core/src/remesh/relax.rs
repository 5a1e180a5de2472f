//! Tangential relaxation of the remesh on the input surface.
//!
//! The map the collapses build is a bijection, but a chain of a few dozen planar maps is only
//! nearly conformal, and the small errors compound: here and there it stretches the lattice into
//! slivers, and a sliver across a bend of the input can face the wrong way. Each round moves
//! every free vertex part of the way towards the centroid of its neighbours, within its tangent
//! plane, and puts it back on the input at the closest point of the triangles around where it
//! was (a local walk, so a point never jumps across a thin part to the far side). A move is kept
//! when it leaves fewer triangles around the vertex facing against the input, or as few and none
//! worse shaped than the worst it had; a vertex of a triangle facing the wrong way also tries
//! the centre of its star's kernel in a plane across the input there. Border vertices stay, and
//! vertices snapped onto a tip move only to untangle. The folds this leaves are untangled a
//! patch at a time (`untangle`).

use alloc::vec;
use alloc::vec::Vec;

use crate::build::around::Around;
use crate::build::closest::{closest, point, Surface};
use crate::build::collapse::shape;
use crate::build::vec3::{add, cross, dot, from_f32, normalize, scale, sub, Vec3d};
use crate::build::InputMesh;

/// How many of the nearest free vertices a far input vertex tries to pull.
const SNAP_TRIES: usize = 8;

/// How many of those a tip tries to pull with its neighbours untangling round it.
const UNTANGLE_TRIES: usize = 3;

/// A remesh vertex's place on the input: a triangle and barycentric weights there.
pub(super) type OnInput = (u32, [f64; 3]);

/// What the relaxation works on.
pub(super) struct Relax<'a> {
    pub input: &'a InputMesh<'a>,
    pub around: &'a Around<u32>,
    /// The remesh's finest triangles.
    pub triangles: &'a [[u32; 3]],
    /// Vertices that never move: the border's.
    pub fixed: Vec<bool>,
    /// Vertices snapped onto a tip: they move only to untangle a triangle facing the wrong way.
    pub snapped: Vec<bool>,
    /// The input, for distances.
    pub surface: &'a Surface,
    /// The input triangles' unit normals.
    pub normals: Vec<Vec3d>,
    /// The remesh's triangles around each of its vertices.
    pub around_remesh: Around<u32>,
    /// A gap from the input that an untangling move may open wherever it is, however close
    /// the triangles were (the snapping's reach).
    pub reach: f64,
}

impl Relax<'_> {
    pub(super) fn corners(&self, f: u32) -> [Vec3d; 3] {
        self.input.triangles[f as usize].map(|v| from_f32(self.input.positions[v as usize]))
    }

    /// The unit normals of `input`'s triangles (zero for a degenerate one).
    pub(super) fn normals(input: &InputMesh<'_>) -> Vec<Vec3d> {
        input
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| from_f32(input.positions[v as usize]));
                normalize(cross(sub(b, a), sub(c, a))).unwrap_or([0.0; 3])
            })
            .collect()
    }

    /// The closest point to `p` on the input triangles around `face`, walking on while a
    /// neighbouring triangle is closer (at most a few steps).
    pub(super) fn project(&self, p: Vec3d, face: u32) -> OnInput {
        let mut best = (face, closest(p, self.corners(face)));
        for _ in 0..4 {
            let start = best.0;
            for &v in &self.input.triangles[start as usize] {
                for &f in self.around.of(v) {
                    let c = closest(p, self.corners(f));
                    if c.1 < best.1 .1 {
                        best = (f, c);
                    }
                }
            }
            if best.0 == start {
                break;
            }
        }
        (best.0, best.1 .0)
    }

    /// Moves one of the nearest free remesh vertices onto each input vertex farther than `reach`
    /// from the remesh (a spike's tip the map left unsampled), farthest first, where that turns
    /// no triangle against the input or its neighbours can untangle what it turns
    /// ([`Relax::move_untangled`]), preferring moves that open no gap wider than `reach`; a
    /// vertex moved there stays. Returns how many moved.
    pub(super) fn snap(
        &mut self,
        reach: f64,
        positions: &mut [[f32; 3]],
        on_input: &mut [OnInput],
    ) -> u32 {
        let surface = Surface::new(positions, self.triangles);
        let mut far: Vec<(f64, u32)> = self
            .input
            .positions
            .iter()
            .enumerate()
            .map(|(x, p)| (surface.distance(from_f32(*p)), x as u32))
            .filter(|&(d, _)| d > reach)
            .collect();
        far.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut moved = 0;
        let mut candidates: Vec<(u32, bool, f64)> = Vec::new();
        for (distance, x) in far {
            let Some(&face) = self.around.of(x).first() else {
                continue;
            };
            let slot = self.input.triangles[face as usize]
                .iter()
                .position(|&c| c == x)
                .unwrap_or(0);
            let mut w = [0.0; 3];
            w[slot] = 1.0;
            let target = from_f32(self.input.positions[x as usize]);
            // The nearest free vertices, nearest first: the first whose move turns no triangle
            // against the input goes.
            let mut nearest: Vec<(f64, usize)> = (0..positions.len())
                .filter(|&v| !self.fixed[v] && !self.snapped[v])
                .map(|v| {
                    let d = sub(from_f32(positions[v]), target);
                    (dot(d, d), v)
                })
                .collect();
            let tried = nearest.len().min(SNAP_TRIES);
            if tried == 0 {
                continue;
            }
            nearest
                .select_nth_unstable_by(tried - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            nearest.truncate(tried);
            nearest.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            // Nearest first, the first move that turns no triangle against the input and opens
            // no gap wider than the reach; else the first whose folds its neighbours can
            // untangle within the reach; else, of the moves that turn nothing, the one opening
            // the smallest gap, if narrower than the one it closes.
            candidates.clear();
            let mut chosen = None;
            for (_, v) in nearest {
                let tris = self.around_remesh.of(v as u32);
                let (before, _) = self.facing(tris, v as u32, None, positions, on_input);
                let (after, _) =
                    self.facing(tris, v as u32, Some((target, face)), positions, on_input);
                let gap = self.gap(tris, v as u32, target, positions);
                if after <= before && gap <= reach {
                    chosen = Some(v as u32);
                    break;
                }
                if gap < distance {
                    candidates.push((v as u32, after <= before, gap));
                }
            }
            let chosen = chosen
                .or_else(|| {
                    candidates
                        .iter()
                        .filter(|&&(_, turns_none, _)| !turns_none)
                        .take(UNTANGLE_TRIES)
                        .find_map(|&(v, ..)| {
                            self.move_untangled(v, (target, face, w), reach, positions, on_input)
                                .then_some(v)
                        })
                })
                .or_else(|| {
                    candidates
                        .iter()
                        .filter(|&&(_, turns_none, _)| turns_none)
                        .min_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)))
                        .map(|&(v, ..)| v)
                });
            if let Some(v) = chosen {
                positions[v as usize] = target.map(|c| c as f32);
                on_input[v as usize] = (face, w);
                self.snapped[v as usize] = true;
                moved += 1;
            }
        }
        moved
    }

    /// The largest distance from the input of the centroids and edge midpoints of the
    /// triangles `tris` around `v`, with `v` at `at`.
    pub(super) fn gap(&self, tris: &[u32], v: u32, at: Vec3d, positions: &[[f32; 3]]) -> f64 {
        tris.iter().fold(0.0f64, |g, &t| {
            let c = self.triangles[t as usize].map(|x| {
                if x == v {
                    at
                } else {
                    from_f32(positions[x as usize])
                }
            });
            let mid = |a: Vec3d, b: Vec3d| scale(add(a, b), 0.5);
            let centre = scale(add(add(c[0], c[1]), c[2]), 1.0 / 3.0);
            [centre, mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0])]
                .iter()
                .fold(g, |g, &p| g.max(self.surface.distance(p)))
        })
    }

    /// How many of the triangles `tris` around `v` face against the input, and the worst
    /// shape among them, with `v` where it is or at `moved` (a point and its input triangle).
    pub(super) fn facing(
        &self,
        tris: &[u32],
        v: u32,
        moved: Option<(Vec3d, u32)>,
        positions: &[[f32; 3]],
        on_input: &[OnInput],
    ) -> (u32, f64) {
        let mut against = 0u32;
        let mut least = f64::INFINITY;
        for &t in tris {
            let tri = self.triangles[t as usize];
            let c = tri.map(|x| match moved {
                Some((at, _)) if x == v => at,
                _ => from_f32(positions[x as usize]),
            });
            let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
            let seen = tri.iter().fold([0.0; 3], |s, &x| {
                let f = match moved {
                    Some((_, face)) if x == v => face,
                    _ => on_input[x as usize].0,
                };
                add(s, self.normals[f as usize])
            });
            against += u32::from(dot(n, seen) <= 0.0);
            least = least.min(shape(c));
        }
        (against, least)
    }

    /// Where `v` makes every triangle around it face the way the input does, as far as a plane
    /// can tell: the ring of `v`'s neighbours is laid on the plane across the input's normals
    /// there, and the region of that plane from which every ring edge is seen counter-clockwise
    /// (the star's kernel, the ring's half-planes clipped from a box round it) gives its area
    /// centroid. `None` when the kernel is empty (the ring itself is tangled: its vertices
    /// must move first) or the input's normals there cancel out.
    fn kernel(
        &self,
        tris: &[u32],
        v: u32,
        positions: &[[f32; 3]],
        on_input: &[OnInput],
    ) -> Option<Vec3d> {
        let here = from_f32(positions[v as usize]);
        let mut normal = self.normals[on_input[v as usize].0 as usize];
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tris.len());
        for &t in tris {
            let tri = self.triangles[t as usize];
            let k = tri.iter().position(|&x| x == v)?;
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            normal = add(normal, self.normals[on_input[a as usize].0 as usize]);
            edges.push((a, b));
        }
        let n = normalize(normal)?;
        // Any unit vector across n, and the third axis.
        let seed = if n[0].abs() < 0.6 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = normalize(sub(seed, scale(n, dot(seed, n))))?;
        let w = cross(n, u);
        let flat = |x: u32| {
            let d = sub(from_f32(positions[x as usize]), here);
            [dot(d, u), dot(d, w)]
        };
        let mut extent = 0.0f64;
        for &(a, _) in &edges {
            let [x, y] = flat(a);
            extent = extent.max(x.abs()).max(y.abs());
        }
        if extent <= 0.0 {
            return None;
        }
        let r = 2.0 * extent;
        let mut poly: Vec<[f64; 2]> = vec![[-r, -r], [r, -r], [r, r], [-r, r]];
        let mut next: Vec<[f64; 2]> = Vec::with_capacity(poly.len() + edges.len());
        for &(a, b) in &edges {
            let (pa, pb) = (flat(a), flat(b));
            let e = [pb[0] - pa[0], pb[1] - pa[1]];
            // Positive on the side from which a -> b turns counter-clockwise.
            let side = |p: [f64; 2]| e[0] * (p[1] - pa[1]) - e[1] * (p[0] - pa[0]);
            next.clear();
            for (i, &p) in poly.iter().enumerate() {
                let q = poly[(i + 1) % poly.len()];
                let (sp, sq) = (side(p), side(q));
                if sp > 0.0 {
                    next.push(p);
                }
                if (sp > 0.0) != (sq > 0.0) {
                    let t = sp / (sp - sq);
                    next.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
                }
            }
            core::mem::swap(&mut poly, &mut next);
            if poly.len() < 3 {
                return None;
            }
        }
        // The area centroid of the (convex) kernel.
        let (mut area, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for (i, &p) in poly.iter().enumerate() {
            let q = poly[(i + 1) % poly.len()];
            let c = p[0] * q[1] - q[0] * p[1];
            area += c;
            cx += (p[0] + q[0]) * c;
            cy += (p[1] + q[1]) * c;
        }
        if area <= 0.0 {
            return None;
        }
        let (x, y) = (cx / (3.0 * area), cy / (3.0 * area));
        Some(add(here, add(scale(u, x), scale(w, y))))
    }

    /// Where `v` may go this round: part of the way to its neighbours' centroid within its
    /// tangent plane; for a vertex of a triangle facing the wrong way (`before > 0`) also all the
    /// way and its star's kernel; in the last rounds over the tangles (`tangled`) also half way to
    /// each neighbour (a tip stays unless a move untangles; it does not wander between
    /// neighbours). Returns the worst shape round `v`, or `None` when its star has no normal.
    fn targets(
        &self,
        v: u32,
        before: u32,
        tangled: bool,
        positions: &[[f32; 3]],
        on_input: &[OnInput],
        out: &mut Vec<Vec3d>,
    ) -> Option<f64> {
        out.clear();
        let tris = self.around_remesh.of(v);
        let here = from_f32(positions[v as usize]);
        let mut centroid = [0.0; 3];
        let mut normal = [0.0; 3];
        let mut count = 0.0;
        let mut worst = f64::INFINITY;
        for &t in tris {
            let c = self.triangles[t as usize].map(|x| from_f32(positions[x as usize]));
            normal = add(normal, cross(sub(c[1], c[0]), sub(c[2], c[0])));
            worst = worst.min(shape(c));
            for (k, &x) in self.triangles[t as usize].iter().enumerate() {
                if x != v {
                    centroid = add(centroid, c[k]);
                    count += 1.0;
                }
            }
        }
        let normal = normalize(normal)?;
        if count == 0.0 {
            return None;
        }
        let towards = sub(scale(centroid, 1.0 / count), here);
        let tangent = sub(towards, scale(normal, dot(towards, normal)));
        out.push(add(here, scale(tangent, 0.5)));
        if before > 0 {
            out.push(add(here, tangent));
            out.extend(self.kernel(tris, v, positions, on_input));
        }
        if tangled && !self.snapped[v as usize] {
            for &t in tris {
                for &x in &self.triangles[t as usize] {
                    if x != v {
                        out.push(scale(add(here, from_f32(positions[x as usize])), 0.5));
                    }
                }
            }
        }
        Some(worst)
    }

    /// `rounds` rounds over every free vertex (or, with `tangled`, over the vertices of
    /// triangles facing the wrong way only); `on_input` and `positions` are updated together.
    pub(super) fn run(
        &self,
        rounds: u32,
        tangled: bool,
        positions: &mut [[f32; 3]],
        on_input: &mut [OnInput],
    ) {
        let n = positions.len();
        let mut targets: Vec<Vec3d> = Vec::new();
        for _ in 0..rounds {
            for v in 0..n as u32 {
                if self.fixed[v as usize] {
                    continue;
                }
                let tris = self.around_remesh.of(v);
                let (before, _) = self.facing(tris, v, None, positions, on_input);
                if (self.snapped[v as usize] || tangled) && before == 0 {
                    continue;
                }
                let Some(worst) =
                    self.targets(v, before, tangled, positions, on_input, &mut targets)
                else {
                    continue;
                };
                if let Some((_, face, w, moved)) =
                    self.best_move(v, before, worst, tangled, &targets, positions, on_input)
                {
                    positions[v as usize] = moved.map(|x| x as f32);
                    on_input[v as usize] = (face, w);
                }
            }
        }
    }

    /// The move of `v` among `targets` to keep, if any: with no triangle round it facing the
    /// wrong way (`before == 0`), the first target if it turns none and makes no triangle worse
    /// shaped than the worst (or 0.5); else the one that leaves fewest triangles facing the wrong
    /// way, even if no fewer yet (its neighbours' moves may finish it; a tip needs fewer), and in
    /// the last rounds (`tangled`) opens no gap from the input wider than there was or than
    /// [`Relax::reach`].
    #[allow(clippy::too_many_arguments)]
    fn best_move(
        &self,
        v: u32,
        before: u32,
        worst: f64,
        tangled: bool,
        targets: &[Vec3d],
        positions: &[[f32; 3]],
        on_input: &[OnInput],
    ) -> Option<(u32, u32, [f64; 3], Vec3d)> {
        let tris = self.around_remesh.of(v);
        let here = from_f32(positions[v as usize]);
        let mut best: Option<(u32, u32, [f64; 3], Vec3d)> = None;
        let mut gap = None;
        for &target in targets {
            let (face, w) = self.project(target, on_input[v as usize].0);
            let moved = point(self.corners(face), w);
            let (after, least) = self.facing(tris, v, Some((moved, face)), positions, on_input);
            if before == 0 {
                if after == 0 && least >= worst.min(0.5) {
                    best = Some((after, face, w, moved));
                }
                break;
            }
            let enough = if self.snapped[v as usize] {
                after < before
            } else {
                after <= before
            };
            if enough
                && best.is_none_or(|(a, ..)| after < a)
                && (!tangled
                    || self.gap(tris, v, moved, positions)
                        <= *gap.get_or_insert_with(|| {
                            self.gap(tris, v, here, positions).max(self.reach)
                        }))
            {
                best = Some((after, face, w, moved));
            }
        }
        best
    }
}

/// No vertex: [`Relax::facing`] and [`Relax::gap`] then measure the triangles as they are.
pub(super) const NONE_VERTEX: u32 = u32::MAX;
