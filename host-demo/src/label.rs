//! Text for plots: a 3x5-pixel font of the characters the demo's pictures need, drawn into a
//! tiny-skia pixmap at any integer scale (no font files, same pixels everywhere).

/// Glyph rows, top to bottom, three bits each (bit 2 = left column).
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c.to_ascii_lowercase() {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'a' => [2, 5, 7, 5, 5],
        'b' => [6, 5, 6, 5, 6],
        'c' => [3, 4, 4, 4, 3],
        'd' => [6, 5, 5, 5, 6],
        'e' => [7, 4, 6, 4, 7],
        'f' => [7, 4, 6, 4, 4],
        'g' => [3, 4, 5, 5, 3],
        'h' => [5, 5, 7, 5, 5],
        'i' => [7, 2, 2, 2, 7],
        'k' => [5, 5, 6, 5, 5],
        'l' => [4, 4, 4, 4, 7],
        'm' => [5, 7, 7, 5, 5],
        'n' => [6, 5, 5, 5, 5],
        'o' => [2, 5, 5, 5, 2],
        'p' => [6, 5, 6, 4, 4],
        'r' => [6, 5, 6, 5, 5],
        's' => [3, 4, 2, 1, 6],
        't' => [7, 2, 2, 2, 2],
        'u' => [5, 5, 5, 5, 7],
        'v' => [5, 5, 5, 5, 2],
        'w' => [5, 5, 7, 7, 5],
        'x' => [5, 5, 2, 5, 5],
        'y' => [5, 5, 2, 2, 2],
        '+' => [0, 2, 7, 2, 0],
        '-' => [0, 0, 7, 0, 0],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        ':' => [0, 2, 0, 2, 0],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        '/' => [1, 1, 2, 4, 4],
        ' ' => [0; 5],
        _ => return None,
    })
}

/// Draws `text` with its top-left corner at `(x, y)`, each font pixel `scale` pixels wide, in
/// `rgb`; characters without a glyph are drawn as blanks. Returns the x after the text.
pub fn draw(
    pixmap: &mut tiny_skia::Pixmap,
    text: &str,
    x: f32,
    y: f32,
    scale: f32,
    rgb: (u8, u8, u8),
) -> f32 {
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(rgb.0, rgb.1, rgb.2, 255);
    let mut cx = x;
    for c in text.chars() {
        if let Some(rows) = glyph(c) {
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) != 0 {
                        let px = cx + col as f32 * scale;
                        let py = y + r as f32 * scale;
                        if let Some(rect) = tiny_skia::Rect::from_xywh(px, py, scale, scale) {
                            pixmap.fill_rect(rect, &paint, tiny_skia::Transform::identity(), None);
                        }
                    }
                }
            }
        }
        cx += 4.0 * scale;
    }
    cx
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_puts_ink_where_it_says() {
        let mut p = tiny_skia::Pixmap::new(40, 10).unwrap();
        let end = draw(&mut p, "1 ms", 0.0, 0.0, 1.0, (0, 0, 0));
        assert_eq!(end, 16.0);
        let ink = |x: u32, y: u32| p.pixel(x, y).unwrap().alpha() > 0;
        // The '1': its stem is the middle column, its foot the whole bottom row.
        assert!(ink(1, 0) && ink(1, 2) && ink(0, 4) && ink(2, 4));
        assert!(!ink(2, 0));
        // The blank draws nothing.
        assert!((4..8).all(|x| (0..5).all(|y| !ink(x, y))));
    }
}
