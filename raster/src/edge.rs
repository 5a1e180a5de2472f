//! Fixed-point edge functions: triangle set-up and the pixel loop.
//!
//! Screen coordinates are snapped to [`SUBPIXEL_BITS`] = 8 fractional bits (1/256 pixel), the
//! precision Direct3D 10 class hardware uses. Eight bits keep slivers and long thin triangles from
//! visibly shifting when they are snapped, and they cost nothing in range: with the clipping guard
//! band every coordinate stays below 2^14 pixels, so a snapped coordinate fits in 23 bits, an edge
//! function's coefficients in 24 bits and its value anywhere in the viewport in 50 bits of an `i64`.
//! All coverage decisions are exact integer arithmetic, so they are the same on every target.
//!
//! Coverage follows the **top-left rule**: a pixel centre exactly on an edge belongs to the triangle
//! only if that edge is a top edge (horizontal, with the triangle below it) or a left edge. Two
//! triangles sharing an edge therefore never both cover, nor both miss, a pixel on it: meshes are
//! watertight with no double blending.
//!
//! Attributes (depth and colour) are affine in screen space. At each covered pixel they are
//! evaluated from the two barycentric weights the edge functions already hold, against per-triangle
//! differences pre-divided by the area: four multiply-adds on four lanes, no division in the pixel
//! loop, and no set-up at all for the many triangles of a detailed mesh that cover no pixel
//! centre. A triangle whose bounds hold one pixel centre (most of them, on a small frame) has
//! its edge functions evaluated at that centre alone, and its attributes set up only when it
//! covers it. Only IEEE basic operations are used, so the result is the same on every target.

use crate::target::{Depth, Pixel, Target, Window};
use crate::vertex::saturate_u8;

/// Fractional bits of snapped screen coordinates.
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in snapped units.
pub const SUBPIXEL_ONE: i32 = 1 << SUBPIXEL_BITS;
const HALF: i64 = (SUBPIXEL_ONE / 2) as i64;
/// Largest depth value written; [`crate::DEPTH_CLEAR`] is larger, so any fragment passes on an
/// empty pixel.
pub const DEPTH_MAX: u32 = (1 << 24) - 1;

/// A vertex after projection: snapped position, depth and colour.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScreenVertex {
    /// Horizontal position in 1/256 pixels, 0 at the left edge of the viewport.
    pub x: i32,
    /// Vertical position in 1/256 pixels, 0 at the top edge of the viewport.
    pub y: i32,
    /// Depth in `0.0..=DEPTH_MAX as f32` (normalised device depth times `DEPTH_MAX`).
    pub z: f32,
    /// Colour channels in `0.0..=255.0`.
    pub rgb: [f32; 3],
}

/// One covered pixel: its depth, and its colour on demand, so that a fragment failing the depth
/// test never pays for its colour.
#[derive(Clone, Copy)]
pub struct Fragment<'a> {
    /// Depth in `0..=DEPTH_MAX`.
    pub z: u32,
    w1: f32,
    w2: f32,
    attrs: &'a Attrs,
}

impl Fragment<'_> {
    /// Colour, rounded and saturated to 8 bits per channel.
    #[inline(always)]
    pub fn rgb(&self) -> [u8; 3] {
        let a = self.attrs;
        let c = |k: usize| saturate_u8(a.base[k] + self.w1 * a.d1[k] + self.w2 * a.d2[k]);
        [c(1), c(2), c(3)]
    }
}

/// Which triangles [`fill_triangle`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Only counter-clockwise triangles in normalised device coordinates (y up).
    Front,
    /// Both orientations.
    Both,
}

impl Facing {
    /// Whether a triangle of [`signed_area2`] `area` is drawn: front-facing ones (negative area)
    /// always, back-facing ones with [`Facing::Both`], zero-area ones never.
    #[inline(always)]
    pub fn draws(self, area: i64) -> bool {
        // One mask and no branch: the sign bit alone for front faces, any bit for both (the
        // mask is the same for every triangle of a loop, so it is chosen once).
        let mask = match self {
            Facing::Front => i64::MIN,
            Facing::Both => -1,
        };
        area & mask != 0
    }

    /// [`Facing::Front`] when back faces are culled, else [`Facing::Both`].
    #[inline(always)]
    pub fn culling(cull_back_faces: bool) -> Facing {
        if cull_back_faces {
            Facing::Front
        } else {
            Facing::Both
        }
    }
}

/// What happened to a triangle handed to [`fill_triangle`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// The triangle was scanned (it may still have covered no pixel centre).
    Scanned,
    /// Zero area after snapping, or back-facing with [`Facing::Front`].
    Culled,
    /// A coordinate beyond [`MAX_COORDINATE`], where the edge functions would not fit their
    /// integers: nothing drawn.
    OutOfRange,
}

/// The largest snapped coordinate [`fill_triangle`] takes, either sign: 2^21 pixels, far past
/// any guard band (the vertex stage's stay below 2^14 pixels), and small enough that every
/// edge function and area stays inside an `i64`.
pub const MAX_COORDINATE: i32 = 1 << 29;

/// Twice the signed area in snapped units; negative for triangles that are counter-clockwise in
/// device coordinates (front-facing), because screen y grows downwards.
#[inline(always)]
pub fn signed_area2(v: &[ScreenVertex; 3]) -> i64 {
    signed_area2_xy(v.map(|v| [v.x, v.y]))
}

/// [`signed_area2`] of three snapped points.
#[inline(always)]
pub fn signed_area2_xy(p: [[i32; 2]; 3]) -> i64 {
    let (x0, y0) = (p[0][0] as i64, p[0][1] as i64);
    (p[1][0] as i64 - x0) * (p[2][1] as i64 - y0) - (p[1][1] as i64 - y0) * (p[2][0] as i64 - x0)
}

/// The pixels whose centres the bounding box of three snapped points can contain, clipped to
/// `window` (in frame pixels), as inclusive `(x0, x1, y0, y1)`; `None` when there are none.
/// In 32-bit integers (a device's registers): exact in the guard band's range (see the module's
/// notes), which the vertex stage never leaves.
///
/// ```
/// use vdlod_raster::edge::{pixel_bounds, SUBPIXEL_ONE};
/// use vdlod_raster::Window;
/// let px = |x: f32| (x * SUBPIXEL_ONE as f32) as i32;
/// // From (0.2, 0.2) to (2.9, 1.4) pixels: the centres 0.5, 1.5 and 2.5 across, 0.5 down.
/// let p = [[px(0.2), px(0.2)], [px(2.9), px(0.2)], [px(0.2), px(1.4)]];
/// assert_eq!(pixel_bounds(p, &Window::full(8, 8)), Some([0, 2, 0, 0]));
/// // Between centres: nothing to scan.
/// let q = [[px(0.6), px(0.6)], [px(1.4), px(0.6)], [px(0.6), px(1.4)]];
/// assert_eq!(pixel_bounds(q, &Window::full(8, 8)), None);
/// ```
#[inline(always)]
pub fn pixel_bounds(p: [[i32; 2]; 3], window: &Window) -> Option<[i32; 4]> {
    let [x0, x1, y0, y1] = pixel_box(p, window);
    (x0 <= x1 && y0 <= y1).then_some([x0, x1, y0, y1])
}

/// [`pixel_bounds`] whether or not they hold a pixel: empty when `x0 > x1` or `y0 > y1`.
#[inline(always)]
pub(crate) fn pixel_box(p: [[i32; 2]; 3], window: &Window) -> [i32; 4] {
    let min_x = p[0][0].min(p[1][0]).min(p[2][0]);
    let max_x = p[0][0].max(p[1][0]).max(p[2][0]);
    let min_y = p[0][1].min(p[1][1]).min(p[2][1]);
    let max_y = p[0][1].max(p[1][1]).max(p[2][1]);
    // A target's window edges are below `MAX_DIMENSION`, so they fit; a window built by hand
    // past `i32` wraps (nonsense bounds, no panic).
    let (wx, wy) = (window.x as i32, window.y as i32);
    let x0 = first_centre(min_x).max(wx);
    let x1 = last_centre(max_x).min(wx.wrapping_add(window.width as i32).wrapping_sub(1));
    let y0 = first_centre(min_y).max(wy);
    let y1 = last_centre(max_y).min(wy.wrapping_add(window.height as i32).wrapping_sub(1));
    [x0, x1, y0, y1]
}

/// The first pixel whose centre (`i + 1/2`) is at or after snapped coordinate `c`. Wrapping, so
/// that no coordinate panics: within 128 of either end of `i32` a wrong bound only widens or
/// empties the pixels scanned, each of which is still tested exactly.
#[inline(always)]
fn first_centre(c: i32) -> i32 {
    c.wrapping_add(SUBPIXEL_ONE - 1 - HALF as i32) >> SUBPIXEL_BITS
}

/// The last pixel whose centre is at or before snapped coordinate `c` (wrapping, as
/// [`first_centre`]).
#[inline(always)]
fn last_centre(c: i32) -> i32 {
    c.wrapping_sub(HALF as i32) >> SUBPIXEL_BITS
}

/// One edge function `E(p) = dx * (p.y - a.y) - dy * (p.x - a.x)` for the edge `a -> b`.
#[derive(Clone, Copy)]
struct Edge {
    /// Value at the first pixel centre of the bounding box, biased by the fill rule.
    start: i64,
    /// Change per pixel to the right.
    step_x: i64,
    /// Change per pixel downwards.
    step_y: i64,
}

impl Edge {
    #[inline(always)]
    fn new(a: &ScreenVertex, b: &ScreenVertex, px: i64, py: i64) -> Edge {
        let (dx, dy) = (b.x as i64 - a.x as i64, b.y as i64 - a.y as i64);
        Edge {
            start: edge_at([a.x, a.y], [b.x, b.y], px, py),
            step_x: -dy * SUBPIXEL_ONE as i64,
            step_y: dx * SUBPIXEL_ONE as i64,
        }
    }
}

/// The edge function of `a -> b` at the point `(px, py)`, biased by the fill rule: not negative
/// exactly where the point is covered on that edge's side.
#[inline(always)]
fn edge_at(a: [i32; 2], b: [i32; 2], px: i64, py: i64) -> i64 {
    let dx = b[0] as i64 - a[0] as i64;
    let dy = b[1] as i64 - a[1] as i64;
    dx * (py - a[1] as i64) - dy * (px - a[0] as i64) - fill_bias(dx, dy)
}

/// What the top-left rule takes off the edge function of an edge `(dx, dy)` long: 0 on a top
/// edge (horizontal, pointing right) or a left edge (pointing up; clockwise on screen), 1 on
/// any other, so that a centre exactly on it stays out. Without a branch (as branches these
/// mispredicted on about a third of the edges, which cost the 320x240 bunny a tenth of its
/// frame time) and in one comparison: for `|dx| < 2^32` (coordinates within
/// [`MAX_COORDINATE`]), `dy * 2^32 - dx` is negative exactly on top and left edges.
#[inline(always)]
fn fill_bias(dx: i64, dy: i64) -> i64 {
    1 + ((dy << 32).wrapping_sub(dx) >> 63)
}

/// The edge functions (opposite vertices 0, 1 and 2) of a triangle clockwise on screen at
/// `(px, py)`, before the fill rule's bias: with the vertices taken relative to that point, the
/// edge `a -> b`'s function is the cross product `a.x * b.y - a.y * b.x`, exactly as
/// [`edge_at`] computes it without the bias, in fewer operations.
#[inline(always)]
fn unbiased_at(v: [[i32; 2]; 3], px: i64, py: i64) -> [i64; 3] {
    let r = v.map(|v| [v[0] as i64 - px, v[1] as i64 - py]);
    let cross = |a: [i64; 2], b: [i64; 2]| a[0] * b[1] - a[1] * b[0];
    [cross(r[1], r[2]), cross(r[2], r[0]), cross(r[0], r[1])]
}

/// The fill rule's biases of a clockwise triangle's edges (opposite vertices 0, 1 and 2).
#[inline(always)]
fn fill_biases(v: [[i32; 2]; 3]) -> [i64; 3] {
    let bias =
        |a: [i32; 2], b: [i32; 2]| fill_bias(b[0] as i64 - a[0] as i64, b[1] as i64 - a[1] as i64);
    [bias(v[1], v[2]), bias(v[2], v[0]), bias(v[0], v[1])]
}

/// The centre of pixel `(x, y)` in snapped units.
#[inline(always)]
fn centre(x: i32, y: i32) -> (i64, i64) {
    (
        ((x as i64) << SUBPIXEL_BITS) + HALF,
        ((y as i64) << SUBPIXEL_BITS) + HALF,
    )
}

/// Whether edge functions before their bias (`e`, [`unbiased_at`]) cover their point. The
/// bias matters only for a point on an edge: a value of zero (rare, so a branch).
#[inline(always)]
fn covered(e: [i64; 3], v: [[i32; 2]; 3]) -> bool {
    let least = e[0].min(e[1]).min(e[2]);
    if least != 0 {
        return least > 0;
    }
    on_an_edge(e, v)
}

/// [`covered`] for a point on an edge: the biases decide.
#[cold]
#[inline(never)]
fn on_an_edge(e: [i64; 3], v: [[i32; 2]; 3]) -> bool {
    let b = fill_biases(v);
    ((e[0] - b[0]) | (e[1] - b[1]) | (e[2] - b[2])) >= 0
}

/// Whether a triangle clockwise on screen covers the centre of pixel `(x, y)`, exactly as its
/// scan decides it.
#[inline(always)]
pub(crate) fn covers_centre(v: [[i32; 2]; 3], x: i32, y: i32) -> bool {
    let (px, py) = centre(x, y);
    covered(unbiased_at(v, px, py), v)
}

/// Depth and colour of a triangle, as functions of two barycentric weights.
#[derive(Clone, Copy)]
struct Attrs {
    /// Depth and colour at vertex 0.
    base: [f32; 4],
    /// Change per unit of the edge function opposite vertex 1 (vertex 1's weight times the area).
    d1: [f32; 4],
    /// Change per unit of the edge function opposite vertex 2.
    d2: [f32; 4],
}

impl Attrs {
    /// Relative to vertex 0 (its weight is 1 minus the others'), so that an attribute equal at all
    /// three vertices comes out exactly equal everywhere.
    #[inline(always)]
    fn new(v: &[ScreenVertex; 3], area: i64) -> Attrs {
        let inv = 1.0 / area as f32;
        let a = v.map(|v| [v.z, v.rgb[0], v.rgb[1], v.rgb[2]]);
        Attrs {
            base: a[0],
            d1: core::array::from_fn(|k| (a[1][k] - a[0][k]) * inv),
            d2: core::array::from_fn(|k| (a[2][k] - a[0][k]) * inv),
        }
    }

    /// The fragment where the edge functions opposite vertices 1 and 2 are `e1` and `e2`.
    #[inline(always)]
    fn at(&self, e1: i64, e2: i64) -> Fragment<'_> {
        let (w1, w2) = (e1 as f32, e2 as f32);
        Fragment {
            z: depth(self.base[0] + w1 * self.d1[0] + w2 * self.d2[0]),
            w1,
            w2,
            attrs: self,
        }
    }
}

/// Depth value in `0..=DEPTH_MAX` (NaN becomes 0).
#[inline(always)]
#[allow(clippy::manual_clamp)] // NaN must map into range
fn depth(z: f32) -> u32 {
    z.max(0.0).min(DEPTH_MAX as f32) as u32
}

/// Scans one triangle and calls `plot` for every pixel whose centre it covers.
///
/// `plot` receives the pixel's colour and depth slots and the interpolated fragment; the depth test
/// and the write are its business, so the same loop serves drawing, coverage queries and tests.
/// Pixels outside the target's window are never visited, whatever the coordinates; those inside
/// it get exactly the fragments a scan of the whole frame gives them (edge functions are exact
/// integers, evaluated from the frame's origin).
///
/// ```
/// use vdlod_raster::edge::{fill_triangle, Facing, ScreenVertex, SUBPIXEL_ONE};
/// use vdlod_raster::{Rgba8, Target};
/// let mut color = [Rgba8::default(); 8 * 8];
/// let mut depth = [0u32; 8 * 8];
/// let mut target = Target::new(&mut color, &mut depth, 8, 8).unwrap();
/// let v = |x: i32, y: i32| ScreenVertex { x: x * SUBPIXEL_ONE, y: y * SUBPIXEL_ONE, z: 0.0, rgb: [255.0; 3] };
/// let mut covered = 0;
/// fill_triangle(&mut target, &[v(0, 0), v(0, 8), v(8, 0)], Facing::Both, |_, _, _| covered += 1);
/// assert_eq!(covered, 28); // centres on the hypotenuse (a right edge) stay out
/// ```
#[inline(always)]
pub fn fill_triangle<P: Pixel, D: Depth, F>(
    target: &mut Target<'_, P, D>,
    tri: &[ScreenVertex; 3],
    facing: Facing,
    plot: F,
) -> Coverage
where
    F: FnMut(&mut P, &mut D, Fragment<'_>),
{
    let within = |c: i32| (-MAX_COORDINATE..=MAX_COORDINATE).contains(&c);
    if !tri.iter().all(|v| within(v.x) && within(v.y)) {
        return Coverage::OutOfRange;
    }
    let area = signed_area2(tri);
    if !facing.draws(area) {
        return Coverage::Culled;
    }
    let v = if area < 0 {
        [tri[0], tri[2], tri[1]]
    } else {
        *tri
    };
    if let Some(bounds) = pixel_bounds(v.map(|v| [v.x, v.y]), &target.window) {
        scan(target, &v, area.abs(), bounds, plot);
    }
    Coverage::Scanned
}

/// The pixel loop of [`fill_triangle`], for a triangle already oriented clockwise on screen (positive
/// [`signed_area2`] `area`) and its non-empty [`pixel_bounds`]: for callers that computed those
/// anyway.
#[inline(always)]
pub(crate) fn scan<P: Pixel, D: Depth, F>(
    target: &mut Target<'_, P, D>,
    v: &[ScreenVertex; 3],
    area: i64,
    bounds: [i32; 4],
    mut plot: F,
) where
    F: FnMut(&mut P, &mut D, Fragment<'_>),
{
    let [x0, x1, y0, y1] = bounds;
    if (x0 == x1) & (y0 == y1) {
        // One pixel centre (most triangles of a detailed mesh on a small frame): the edge
        // functions there, and the attributes only when it is covered.
        let xy = v.map(|v| [v.x, v.y]);
        let (px, py) = centre(x0, y0);
        let e = unbiased_at(xy, px, py);
        if covered(e, xy) {
            let i = target.index(x0 as usize, y0 as usize);
            if let (Some(c), Some(d)) = (target.color.get_mut(i), target.depth.get_mut(i)) {
                let [_, b1, b2] = fill_biases(xy);
                plot(c, d, Attrs::new(v, area).at(e[1] - b1, e[2] - b2));
            }
        }
        return;
    }
    let attrs = Attrs::new(v, area);
    pixels(target, v, bounds, |c, d, e1, e2| {
        plot(c, d, attrs.at(e1, e2))
    });
}

/// Texture coordinates over a triangle, perspective-correct: `u / w`, `v / w` and `1 / w` are
/// affine in screen space, so they are stepped like depth and colour, and `(u, v)` is their
/// quotient at each pixel.
#[derive(Clone, Copy)]
struct TexCoords {
    base: [f32; 3],
    d1: [f32; 3],
    d2: [f32; 3],
}

impl TexCoords {
    #[inline(always)]
    fn new(q: &[[f32; 3]; 3], area: i64) -> TexCoords {
        let inv = 1.0 / area as f32;
        TexCoords {
            base: q[0],
            d1: core::array::from_fn(|k| (q[1][k] - q[0][k]) * inv),
            d2: core::array::from_fn(|k| (q[2][k] - q[0][k]) * inv),
        }
    }

    #[inline(always)]
    fn at(&self, e1: i64, e2: i64) -> [f32; 2] {
        let (w1, w2) = (e1 as f32, e2 as f32);
        let c = |k: usize| self.base[k] + w1 * self.d1[k] + w2 * self.d2[k];
        let inv_w = c(2);
        [c(0) / inv_w, c(1) / inv_w]
    }
}

/// [`scan`] for a textured triangle: `q` holds each corner's `[u / w, v / w, 1 / w]` (`w` its
/// clip-space w), and `plot` also receives the pixel's `(u, v)`.
#[inline(always)]
pub(crate) fn scan_textured<P: Pixel, D: Depth, F>(
    target: &mut Target<'_, P, D>,
    v: &[ScreenVertex; 3],
    q: &[[f32; 3]; 3],
    area: i64,
    bounds: [i32; 4],
    mut plot: F,
) where
    F: FnMut(&mut P, &mut D, Fragment<'_>, [f32; 2]),
{
    let attrs = Attrs::new(v, area);
    let uv = TexCoords::new(q, area);
    pixels(target, v, bounds, |c, d, e1, e2| {
        plot(c, d, attrs.at(e1, e2), uv.at(e1, e2))
    });
}

/// The covered pixels of a clockwise triangle within `bounds`, each visited with the edge
/// functions opposite vertices 1 and 2 (the barycentric weights times the area).
#[inline(always)]
fn pixels<P: Pixel, D: Depth, F>(
    target: &mut Target<'_, P, D>,
    v: &[ScreenVertex; 3],
    [x0, x1, y0, y1]: [i32; 4],
    mut visit: F,
) where
    F: FnMut(&mut P, &mut D, i64, i64),
{
    let (px, py) = centre(x0, y0);
    let e = [
        Edge::new(&v[1], &v[2], px, py),
        Edge::new(&v[2], &v[0], px, py),
        Edge::new(&v[0], &v[1], px, py),
    ];
    let (x0, x1) = (x0 as usize, x1 as usize);
    let (span, stride) = (x1 - x0, target.stride);
    let mut first = target.index(x0, y0 as usize);
    let mut row = [e[0].start, e[1].start, e[2].start];
    for _ in y0..=y1 {
        let crow = &mut target.color[first..=first + span];
        let drow = &mut target.depth[first..=first + span];
        first += stride;
        let [mut e0, mut e1, mut e2] = row;
        let mut entered = false;
        for (c, d) in crow.iter_mut().zip(drow.iter_mut()) {
            if (e0 | e1 | e2) >= 0 {
                entered = true;
                visit(c, d, e1, e2);
            } else if entered {
                break; // a triangle meets each row in one span
            }
            e0 += e[0].step_x;
            e1 += e[1].step_x;
            e2 += e[2].step_x;
        }
        for (r, e) in row.iter_mut().zip(&e) {
            *r += e.step_y;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::Rgba8;

    fn sv(x: i32, y: i32) -> ScreenVertex {
        ScreenVertex {
            x,
            y,
            z: 100.0,
            rgb: [10.0, 20.0, 30.0],
        }
    }

    fn count(tris: &[[ScreenVertex; 3]], w: usize, h: usize) -> [u8; 256] {
        let mut color = [Rgba8::default(); 256];
        let mut depth = [0u32; 256];
        let n = w * h;
        let mut t = Target::new(&mut color[..n], &mut depth[..n], w, h).unwrap();
        for tri in tris {
            fill_triangle(&mut t, tri, Facing::Both, |c, _, _| c.0[0] += 1);
        }
        let mut out = [0u8; 256];
        for (o, c) in out.iter_mut().zip(t.color()) {
            *o = c.0[0];
        }
        out
    }

    #[test]
    fn front_facing_is_ccw_in_device_space() {
        let s = SUBPIXEL_ONE;
        // Counter-clockwise with y up = clockwise on screen with y down: area2 < 0.
        let tri = [sv(0, 4 * s), sv(4 * s, 4 * s), sv(0, 0)];
        assert!(signed_area2(&tri) < 0);
        let mut color = [Rgba8::default(); 16];
        let mut depth = [0u32; 16];
        let mut t = Target::new(&mut color, &mut depth, 4, 4).unwrap();
        assert_eq!(
            fill_triangle(&mut t, &tri, Facing::Front, |_, _, _| {}),
            Coverage::Scanned
        );
        let back = [tri[0], tri[2], tri[1]];
        assert_eq!(
            fill_triangle(&mut t, &back, Facing::Front, |_, _, _| {}),
            Coverage::Culled
        );
        assert_eq!(
            fill_triangle(&mut t, &back, Facing::Both, |_, _, _| {}),
            Coverage::Scanned
        );
    }

    #[test]
    fn square_split_on_diagonal_covers_each_pixel_once() {
        let s = SUBPIXEL_ONE;
        let (a, b, c, d) = (sv(0, 0), sv(8 * s, 0), sv(8 * s, 8 * s), sv(0, 8 * s));
        let counts = count(&[[a, b, c], [a, c, d]], 8, 8);
        assert!(counts[..64].iter().all(|&n| n == 1), "{:?}", &counts[..64]);
    }

    #[test]
    fn pixel_centre_on_shared_edge_goes_to_one_side() {
        let s = SUBPIXEL_ONE;
        // Vertical edge through pixel centres x = 2.5.
        let x = 2 * s + s / 2;
        let (top, bot) = (sv(x, 0), sv(x, 4 * s));
        let left = [top, sv(0, 2 * s), bot];
        let right = [top, bot, sv(5 * s, 2 * s)];
        let counts = count(&[left, right], 5, 4);
        assert!(counts[..20].iter().all(|&n| n <= 1));
        // Left edge rule: column 2 belongs to the right triangle, whose left edge it is.
        let only_right = count(&[right], 5, 4);
        assert_eq!(only_right[2 * 5 + 2], 1);
    }

    #[test]
    fn interpolates_constant_attributes_exactly() {
        let s = SUBPIXEL_ONE;
        let mut color = [Rgba8::default(); 64];
        let mut depth = [0u32; 64];
        let mut t = Target::new(&mut color, &mut depth, 8, 8).unwrap();
        let tri = [sv(0, 0), sv(0, 8 * s), sv(8 * s, 0)];
        let mut seen = 0;
        fill_triangle(&mut t, &tri, Facing::Both, |_, _, f| {
            assert_eq!(f.rgb(), [10, 20, 30]);
            assert_eq!(f.z, 100);
            seen += 1;
        });
        assert!(seen > 0);
    }

    #[test]
    fn fill_triangle_refuses_coordinates_past_its_range() {
        let mut color = [Rgba8::default(); 16];
        let mut depth = [0u32; 16];
        let mut t = Target::new(&mut color, &mut depth, 4, 4).unwrap();
        for far in [i32::MIN, i32::MAX, MAX_COORDINATE + 1, -MAX_COORDINATE - 1] {
            let tri = [sv(0, 0), sv(far, 0), sv(0, far)];
            assert_eq!(
                fill_triangle(&mut t, &tri, Facing::Both, |_, _, _| {}),
                Coverage::OutOfRange
            );
        }
        // At the range's ends, every edge function fits: scanned without an overflow (debug).
        let m = MAX_COORDINATE;
        let tri = [sv(-m, -m), sv(m, -m), sv(0, m)];
        let mut covered = 0;
        let c = fill_triangle(&mut t, &tri, Facing::Both, |_, _, _| covered += 1);
        assert_eq!((c, covered), (Coverage::Scanned, 16));
    }

    #[test]
    fn pixel_bounds_take_any_window_and_coordinates() {
        let huge = [
            usize::MAX,
            1 << 40,
            i32::MAX as usize,
            (i32::MAX as usize) + 5,
            0,
            7,
        ];
        let ends = [i32::MIN, i32::MAX, 0, -1, 1 << 30];
        for x in huge {
            for width in huge {
                let window = Window {
                    x,
                    y: x,
                    width,
                    height: width,
                };
                for a in ends {
                    for b in ends {
                        // Nonsense in, no panic (checked in debug builds, where overflow panics).
                        let _ = pixel_bounds([[a, b], [b, a], [a, a]], &window);
                    }
                }
            }
        }
        let frame = Window::full(8, 8);
        assert_eq!(
            pixel_bounds(
                [[0, 0], [8 * SUBPIXEL_ONE, 0], [0, 8 * SUBPIXEL_ONE]],
                &frame
            ),
            Some([0, 7, 0, 7])
        );
    }

    proptest::proptest! {
        /// The 32-bit pixel bounds are the pixels whose centres lie in `[min, max]`, computed in
        /// 64 bits by floor division: every position of a pixel (all 256 subpixel steps), the
        /// pixel anywhere in the guard band's range and past it by far.
        #[test]
        fn centres_bound_exactly(pixel in -(1i32 << 18)..(1 << 18)) {
            let one = i64::from(SUBPIXEL_ONE);
            for c in (pixel * SUBPIXEL_ONE)..((pixel + 1) * SUBPIXEL_ONE) {
                let first = (i64::from(c) - HALF + one - 1).div_euclid(one);
                let last = (i64::from(c) - HALF).div_euclid(one);
                proptest::prop_assert_eq!(i64::from(first_centre(c)), first, "{}", c);
                proptest::prop_assert_eq!(i64::from(last_centre(c)), last, "{}", c);
                // The centre `i + 1/2` is at or after `c` exactly from `first` on.
                proptest::prop_assert!(first * one + HALF >= i64::from(c));
                proptest::prop_assert!((first - 1) * one + HALF < i64::from(c));
            }
        }

        /// The fill rule's bias in one comparison is the top-left rule as written out, for edges
        /// anywhere in `fill_triangle`'s range (two coordinates within `MAX_COORDINATE`).
        #[test]
        fn fill_bias_is_the_top_left_rule(
            dx in -(2i64 * MAX_COORDINATE as i64)..=2 * MAX_COORDINATE as i64,
            dy in -(2i64 * MAX_COORDINATE as i64)..=2 * MAX_COORDINATE as i64,
            small in proptest::bool::ANY,
        ) {
            // Often short or level: the cases where the rule turns on `dx`.
            let (dx, dy) = if small { (dx % 3, dy % 2) } else { (dx, dy) };
            let top_left = dy < 0 || (dy == 0 && dx > 0);
            proptest::prop_assert_eq!(fill_bias(dx, dy), i64::from(!top_left), "{} {}", dx, dy);
        }

        /// The one-centre test the binning uses agrees with the scan at every pixel, edges and
        /// corners through centres included (coordinates on a coarse grid hit them often).
        #[test]
        fn covers_centre_is_the_scans_coverage(
            c in proptest::array::uniform6(-8i32..56),
            fine in proptest::bool::ANY,
        ) {
            // An eighth of a pixel (a 6x6 frame and a pixel around it), or a few subpixels.
            let unit = if fine { 5 } else { SUBPIXEL_ONE / 8 };
            let tri = [0, 1, 2].map(|k| sv(c[2 * k] * unit, c[2 * k + 1] * unit));
            let area = signed_area2(&tri);
            proptest::prop_assume!(area != 0);
            let cw = if area < 0 { [tri[0], tri[2], tri[1]] } else { tri };
            let covered = count(&[tri], 6, 6);
            for y in 0..6 {
                for x in 0..6 {
                    let one = covers_centre(cw.map(|v| [v.x, v.y]), x as i32, y as i32);
                    proptest::prop_assert_eq!(one, covered[y * 6 + x] == 1, "pixel {} {}", x, y);
                }
            }
        }
    }

    #[test]
    fn depth_saturates() {
        assert_eq!(depth(f32::NAN), 0);
        assert_eq!(depth(-5.0), 0);
        assert_eq!(depth(1e30), DEPTH_MAX);
        assert_eq!(depth(1234.75), 1234);
    }
}
