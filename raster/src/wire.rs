//! Wireframe overlay: depth-tested lines along triangle edges.
//!
//! Lines are stepped with a fixed-point DDA along their major axis, one pixel per step, and pass the
//! depth test when they are no farther than [`WIRE_DEPTH_BIAS`] behind what is already drawn, so the
//! edges of visible faces show and hidden edges do not. Pixels outside the target's window are
//! skipped; a line is stepped from its first end whatever the window, so the bands of a frame get
//! the pixels of the whole frame's lines.

use crate::edge::{ScreenVertex, DEPTH_MAX, SUBPIXEL_BITS};
pub use crate::target::WIRE_DEPTH_BIAS;
use crate::target::{Depth, Pixel, Target};

/// Draws the segment `a -> b` in `color` over what the target holds.
pub fn draw_line<P: Pixel, D: Depth>(
    target: &mut Target<'_, P, D>,
    a: &ScreenVertex,
    b: &ScreenVertex,
    color: P,
) {
    const FRAC: u32 = 16;
    let (ax, ay) = (a.x as i64, a.y as i64);
    let (dx, dy) = (b.x as i64 - ax, b.y as i64 - ay);
    let w = target.window;
    // Every step lies between the ends, so a line whose rows miss the window has nothing to draw.
    let (top, bottom) = (ay.min(b.y as i64), ay.max(b.y as i64));
    if (bottom >> SUBPIXEL_BITS) < w.y as i64 || (top >> SUBPIXEL_BITS) >= (w.y + w.height) as i64 {
        return;
    }
    // One step per pixel along the major axis (coordinates are in 1/256 pixels).
    let steps = (dx.abs().max(dy.abs()) >> SUBPIXEL_BITS) + 1;
    let (sx, sy) = ((dx << FRAC) / steps, (dy << FRAC) / steps);
    let z0 = a.z as i64;
    let sz = (b.z as i64 - z0) / steps;
    let (mut x, mut y, mut z) = (ax << FRAC, ay << FRAC, z0);
    let (x0, y0) = (w.x as i64, w.y as i64);
    let (x1, y1) = (x0 + w.width as i64, y0 + w.height as i64);
    for _ in 0..=steps {
        let px = x >> (FRAC + SUBPIXEL_BITS);
        let py = y >> (FRAC + SUBPIXEL_BITS);
        if px >= x0 && py >= y0 && px < x1 && py < y1 {
            let i = target.index(px as usize, py as usize);
            let zi = z.clamp(0, DEPTH_MAX as i64) as u32;
            if let (Some(&d), Some(c)) = (target.depth.get(i), target.color.get_mut(i)) {
                if D::shows_line(zi, d) {
                    *c = color;
                }
            }
        }
        x += sx;
        y += sy;
        z += sz;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edge::SUBPIXEL_ONE;
    use crate::target::{Rgba8, DEPTH_CLEAR};

    fn sv(x: i32, y: i32, z: f32) -> ScreenVertex {
        ScreenVertex {
            x: x * SUBPIXEL_ONE + SUBPIXEL_ONE / 2,
            y: y * SUBPIXEL_ONE + SUBPIXEL_ONE / 2,
            z,
            rgb: [0.0; 3],
        }
    }

    #[test]
    fn draws_horizontal_line_and_respects_depth() {
        let mut color = [Rgba8::default(); 40];
        let mut depth = [DEPTH_CLEAR; 40];
        depth[10 + 5] = 0; // something nearer at (5, 1)
        let mut t = Target::new(&mut color, &mut depth, 10, 4).unwrap();
        let red = Rgba8([255, 0, 0, 255]);
        draw_line(&mut t, &sv(1, 1, 100_000.0), &sv(8, 1, 100_000.0), red);
        let row: [bool; 10] = core::array::from_fn(|x| t.color()[10 + x] == red);
        assert_eq!(
            row,
            [false, true, true, true, true, false, true, true, true, false]
        );
    }

    #[test]
    fn huge_lines_stay_inside() {
        let mut color = [Rgba8::default(); 16];
        let mut depth = [DEPTH_CLEAR; 16];
        let mut t = Target::new(&mut color, &mut depth, 4, 4).unwrap();
        let far = 1 << 13;
        draw_line(
            &mut t,
            &sv(-far, -far, 0.0),
            &sv(far, far, 0.0),
            Rgba8([1, 2, 3, 255]),
        );
        let lit = t.color().iter().filter(|c| c.0[0] == 1).count();
        assert_eq!(lit, 4); // the diagonal
    }
}
