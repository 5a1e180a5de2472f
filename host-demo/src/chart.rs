//! Line charts of per-frame figures: two panels stacked, each with its coloured title and its
//! series over the frames, drawn with tiny-skia and the demo's pixel font.

use crate::label;

/// The colours the demo's charts use.
pub const BLUE: (u8, u8, u8) = (40, 90, 200);
/// Orange.
pub const ORANGE: (u8, u8, u8) = (230, 120, 20);
/// Grey.
pub const GREY: (u8, u8, u8) = (150, 150, 150);
/// Green.
pub const GREEN: (u8, u8, u8) = (40, 150, 60);

/// One panel: its title in coloured pieces, and its series (one value per frame) with their
/// colours, drawn in order.
pub struct Panel<'a> {
    /// Title pieces.
    pub title: Vec<(&'a str, (u8, u8, u8))>,
    /// Series.
    pub series: Vec<(Vec<f64>, (u8, u8, u8))>,
}

/// The smallest 1, 2 or 5 times a power of ten at least `v`.
fn nice_ceiling(v: f64) -> f64 {
    if v <= 0.0 || !v.is_finite() {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&c| c >= v * (1.0 - 1e-9))
        .unwrap_or(10.0 * p)
}

fn tick(v: f64) -> String {
    if v >= 100.0 || v == v.round() {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// Draws the lines of `path` two pixels wide in `rgb`.
pub fn stroke(
    pixmap: &mut tiny_skia::Pixmap,
    path: tiny_skia::PathBuilder,
    rgb: (u8, u8, u8),
    anti_alias: bool,
) {
    let Some(path) = path.finish() else { return };
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(rgb.0, rgb.1, rgb.2, 255);
    paint.anti_alias = anti_alias;
    let stroke = tiny_skia::Stroke {
        width: 2.0,
        ..Default::default()
    };
    pixmap.stroke_path(
        &path,
        &paint,
        &stroke,
        tiny_skia::Transform::identity(),
        None,
    );
}

/// Two panels, one above the other, over the same frames, as a PNG.
pub fn panels(panels: &[Panel<'_>; 2]) -> Result<Vec<u8>, String> {
    let (w, h) = (820u32, 470u32);
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or("cannot make the plot")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    let (left, width, height) = (70.0f32, w as f32 - 90.0, 160.0f32);
    let tops = [34.0f32, 264.0];
    let frames = panels
        .iter()
        .flat_map(|p| p.series.iter().map(|s| s.0.len()))
        .max()
        .unwrap_or(0);
    let n = frames.max(2) as f32;
    let ink = (60, 60, 60);
    let mut grid = tiny_skia::Paint::default();
    grid.set_color_rgba8(215, 215, 215, 255);
    for (panel, top) in panels.iter().zip(tops) {
        let Some(r) = tiny_skia::Rect::from_xywh(left, top, width, height) else {
            continue;
        };
        let max = nice_ceiling(
            panel
                .series
                .iter()
                .flat_map(|s| s.0.iter().cloned())
                .fold(0.0, f64::max),
        );
        for q in 0..=4 {
            let y = r.top() + r.height() * q as f32 / 4.0;
            if let Some(line) = tiny_skia::Rect::from_xywh(r.left(), y, r.width(), 1.0) {
                pixmap.fill_rect(line, &grid, tiny_skia::Transform::identity(), None);
            }
            let text = tick(max * (4 - q) as f64 / 4.0);
            let x = r.left() - 8.0 - 8.0 * text.len() as f32;
            label::draw(&mut pixmap, &text, x, y - 5.0, 2.0, ink);
        }
        label::draw(&mut pixmap, "0", r.left(), r.bottom() + 6.0, 2.0, ink);
        let last = format!("frame {}", frames.saturating_sub(1));
        let x = r.right() - 8.0 * last.len() as f32;
        label::draw(&mut pixmap, &last, x, r.bottom() + 6.0, 2.0, ink);
        let mut x = left;
        for (text, rgb) in &panel.title {
            x = label::draw(&mut pixmap, text, x, top - 24.0, 2.0, *rgb);
        }
        for (values, rgb) in &panel.series {
            let mut pb = tiny_skia::PathBuilder::new();
            for (i, v) in values.iter().enumerate() {
                let x = r.left() + r.width() * i as f32 / (n - 1.0);
                let y = r.bottom() - r.height() * (v / max).min(1.0) as f32;
                if i == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            stroke(&mut pixmap, pb, *rgb, true);
        }
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_maxima_are_round() {
        assert_eq!(nice_ceiling(3120.0), 5000.0);
        assert_eq!(nice_ceiling(8.7), 10.0);
        assert_eq!(nice_ceiling(0.15), 0.2);
        assert_eq!(nice_ceiling(2.0), 2.0);
        assert_eq!(nice_ceiling(0.0), 1.0);
    }
}
