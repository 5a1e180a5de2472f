//! A texture over the base faces of a semi-regular mesh, closed or not: each base face is its
//! own chart (the wavelet paper, Azuma et al. 2003, §3.1: a texture defined over the parametric
//! domain is never distorted by the adaptation).
//!
//! One texture coordinate per vertex cannot do it on a closed base mesh: a vertex on a base
//! edge belongs to two charts. So a mesh is drawn with unshared corners ([`CornerMesh`]): every
//! triangle finds the base face it lies in and gives each corner its weights in that face's
//! frame. Every triangle the wavelet engine emits lies in one base face (it subdivides base
//! faces and cuts their pieces), so its corners map exactly. A vertex-forest triangle need not:
//! its corners are nodes, given the parametric point of a leaf below them; when no face holds
//! all three, the frame of one corner's face is extended across its edges (the neighbour
//! unfolded into its plane, one weight negative), and a triangle wider than that keeps each
//! corner's own coordinates, so the texture tears there.

use vdlod_core::wavelet::SemiRegularView;
use vdlod_raster::{Mesh, MeshSource, Rgba8, Uv, VertexIndex};

/// A mesh with three vertices of its own per triangle, each with texture coordinates in its
/// triangle's chart.
#[derive(Clone, Debug, Default)]
pub struct CornerMesh {
    /// Corner positions.
    pub positions: Vec<[f32; 3]>,
    /// Corner normals.
    pub normals: Vec<[f32; 3]>,
    /// Corner texture coordinates.
    pub uvs: Vec<Uv>,
    /// `[3k, 3k + 1, 3k + 2]`.
    pub triangles: Vec<[u32; 3]>,
    /// Triangles no base face holds (charted by unfolding a neighbour into one's frame, or
    /// torn).
    pub across: usize,
    /// Of those, triangles that no chart reaches, not even unfolded: their texture tears.
    pub torn: usize,
}

impl CornerMesh {
    /// The mesh as the rasterizer reads it.
    pub fn as_raster_mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            normals: Some(&self.normals),
            uvs: Some(&self.uvs),
            triangles: &self.triangles,
            ..Mesh::default()
        }
    }
}

/// The texels of a checker of `cells` x `cells` cells of one texel each, light and dark: drawn
/// with nearest sampling and repeated, a checker over any chart.
pub fn checker_texels(cells: usize) -> Vec<Rgba8> {
    (0..cells * cells)
        .map(|k| match (k % cells + k / cells) % 2 {
            0 => Rgba8([236, 232, 220, 255]),
            _ => Rgba8([60, 70, 110, 255]),
        })
        .collect()
}

/// Texture coordinates of the point at weights `w` (units of `1 / n`) of any base face: the
/// face's chart is the triangle `(0, 0), (1, 0), (0, 1)`.
pub fn chart(w: [i32; 3], n: i32) -> Uv {
    [w[1] as f32 / n as f32, w[2] as f32 / n as f32]
}

/// The weights of vertex `v` in the frame of base face `f`, when `v` lies on that face (inside
/// it, on one of its edges or at a corner).
pub fn weights_in(s: &SemiRegularView<'_>, v: u32, f: u32) -> Option<[i32; 3]> {
    let corners = s.corners(f);
    let mut w = [0; 3];
    match s.point(v) {
        None => {
            // A base vertex: a corner of `f`, or not on it.
            w[corners.iter().position(|&c| c == v)?] = s.steps();
        }
        Some(p) if p.face == f => return Some(p.w),
        Some(p) => {
            // On an edge of its own face (or a corner of it): carry the weights over by the
            // corners they sit on.
            let own = s.corners(p.face);
            for (k, &weight) in p.w.iter().enumerate() {
                if weight != 0 {
                    w[corners.iter().position(|&c| c == own[k])?] = weight;
                }
            }
        }
    }
    Some(w)
}

/// The weights of vertex `v` in the frame of base face `f` with its neighbours unfolded into
/// its plane: [`weights_in`], or for a point of a face across an edge of `f`, its weights there
/// carried over (one of them negative), as [`SemiRegularView::canonical`] undoes.
pub fn unfolded_weights_in(s: &SemiRegularView<'_>, v: u32, f: u32) -> Option<[i32; 3]> {
    if let Some(w) = weights_in(s, v, f) {
        return Some(w);
    }
    (0..3).find_map(|k| {
        // Face `g`'s corner `kk` is `f`'s corner `k + 1`, its `kk + 1` is `f`'s `k`, and its
        // third corner unfolds to `f`'s corners `k + (k + 1) - (k + 2)`.
        let (g, kk) = s.across(f, k)?;
        let wg = weights_in(s, v, g)?;
        let (a, b, c) = (k, (k + 1) % 3, (k + 2) % 3);
        let mut w = [0; 3];
        w[b] += wg[kk];
        w[a] += wg[(kk + 1) % 3];
        let third = wg[(kk + 2) % 3];
        w[a] += third;
        w[b] += third;
        w[c] -= third;
        Some(w)
    })
}

/// The base face holding the triangle with corner vertices `t`, and the corners' weights there;
/// `None` when no face holds all three.
pub fn face_of(s: &SemiRegularView<'_>, t: [u32; 3]) -> Option<(u32, [[i32; 3]; 3])> {
    let candidates = t.iter().filter_map(|&v| s.point(v).map(|p| p.face));
    for f in candidates.chain(0..s.counts().base_faces) {
        if let [Some(a), Some(b), Some(c)] = t.map(|v| weights_in(s, v, f)) {
            return Some((f, [a, b, c]));
        }
    }
    None
}

/// A chart for a triangle no base face holds: the frame of one of its corners' faces with the
/// neighbours unfolded into it, when that reaches all three corners.
fn unfolded_chart(s: &SemiRegularView<'_>, t: [u32; 3]) -> Option<[[i32; 3]; 3]> {
    t.iter()
        .filter_map(|&v| s.point(v).map(|p| p.face))
        .find_map(|f| match t.map(|v| unfolded_weights_in(s, v, f)) {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            _ => None,
        })
}

/// `mesh` with unshared corners, each in its triangle's chart; `vertex_id(i)` is the
/// semi-regular vertex that stands for `mesh`'s vertex `i` (its own, or a leaf's below it).
pub fn corners<M: MeshSource>(
    mesh: &M,
    s: &SemiRegularView<'_>,
    vertex_id: impl Fn(usize) -> u32,
) -> CornerMesh {
    let n = s.steps();
    let mut out = CornerMesh::default();
    for t in mesh.triangles() {
        let slots = t.map(|i| i.to_u32() as usize);
        let ids = slots.map(&vertex_id);
        let weights = match face_of(s, ids) {
            Some((_, w)) => w,
            None => {
                out.across += 1;
                unfolded_chart(s, ids).unwrap_or_else(|| {
                    out.torn += 1;
                    ids.map(|v| s.point(v).map_or([n, 0, 0], |p| p.w))
                })
            }
        };
        let first = out.positions.len() as u32;
        for (k, &slot) in slots.iter().enumerate() {
            let v = mesh.vertex(slot);
            out.positions.push(v.position);
            out.normals.push(v.normal);
            out.uvs.push(chart(weights[k], n));
        }
        out.triangles.push([first, first + 1, first + 2]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use vdlod_core::wavelet::build::SemiRegular;

    #[test]
    fn every_finest_triangle_lies_in_one_face_with_weights_that_sum_to_n() {
        let bytes = SemiRegular::sphere(3).unwrap().to_bytes().unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let triangles = vdlod_core::wavelet::build::finest_triangles(&s);
        let n = s.steps();
        for t in &triangles {
            let (f, w) = face_of(&s, *t).expect("in a face");
            for (k, w) in w.iter().enumerate() {
                assert_eq!(w.iter().sum::<i32>(), n);
                assert!(w.iter().all(|&x| x >= 0));
                // The weights name the corner's own vertex in that face's frame.
                let p = vdlod_core::wavelet::Point { face: f, w: *w };
                assert_eq!(s.vertex_id(p), Some(t[k]), "{t:?} corner {k}");
            }
        }
        // Opposite base vertices share no face: a triangle over them has no chart.
        let base = s.counts().base_vertices;
        let faces = s.counts().base_faces;
        let shared = |u: u32, v: u32| {
            (0..faces).any(|f| {
                let c = s.corners(f);
                c.contains(&u) && c.contains(&v)
            })
        };
        let (u, v) = (0..base)
            .flat_map(|u| (0..base).map(move |v| (u, v)))
            .find(|&(u, v)| u != v && !shared(u, v))
            .expect("an octahedron has opposite vertices");
        assert_eq!(face_of(&s, [u, v, u]), None);
    }

    #[test]
    fn unfolding_is_what_canonical_undoes() {
        let bytes = SemiRegular::sphere(3).unwrap().to_bytes().unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let n = s.steps();
        let mut unfolded = 0;
        for v in 0..s.vertices() {
            let Some(p) = s.point(v) else { continue };
            for f in 0..s.counts().base_faces {
                let Some(w) = unfolded_weights_in(&s, v, f) else {
                    continue;
                };
                assert_eq!(w.iter().sum::<i32>(), n);
                let q = vdlod_core::wavelet::Point { face: f, w };
                assert_eq!(s.canonical(q).and_then(|q| s.vertex_id(q)), Some(v));
                unfolded += usize::from(f != p.face && w.iter().any(|&x| x < 0));
            }
        }
        // Every inner point of a face unfolds into its three neighbours.
        assert!(unfolded > 3 * 8 * 20, "{unfolded}");
    }

    #[test]
    fn the_wavelet_engine_emits_every_triangle_inside_one_base_face() {
        use vdlod::WaveletMesh;
        use vdlod_core::adapt::Budget;
        use vdlod_core::policy::QRefine;
        let bytes = SemiRegular::sphere(4).unwrap().to_bytes().unwrap();
        let s = SemiRegularView::parse(&bytes).unwrap();
        let mut cut = crate::wavelet::DemoWaveletCut::boxed();
        cut.reset(&s).unwrap();
        let camera = crate::wavelet::fig11_camera();
        let stats = cut.adapt(&s, &camera.view(), &QRefine::new(1.0), &Budget::default());
        // Adapted: some faces refined, not all (T-vertex cuts happen between them).
        assert!(stats.triangles > 8 && stats.triangles < 2048, "{stats:?}");
        let mesh = WaveletMesh::new(&cut, &s, false);
        let c = corners(&mesh, &s, |i| cut.vertex_id(i));
        assert_eq!(c.triangles.len(), cut.triangles().len());
        assert_eq!((c.across, c.torn), (0, 0));
        // Corners keep their face's coordinates: inside the chart triangle.
        for uv in &c.uvs {
            assert!(
                uv[0] >= 0.0 && uv[1] >= 0.0 && uv[0] + uv[1] <= 1.0 + 1e-6,
                "{uv:?}"
            );
        }
    }
}
