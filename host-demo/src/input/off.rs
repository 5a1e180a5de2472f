//! Object File Format: `[ST][C][N]OFF`, then vertex, face and edge counts, one vertex per line,
//! one face per line (`n i1 ... in`, 0-based, optionally followed by a face colour).
//!
//! `COFF` vertex colours are read as bytes (`255 0 0`) or, written with a decimal point, as
//! fractions of 1. Normals and texture coordinates are skipped; binary and 4-dimensional OFF
//! are refused with a message.

use super::text::{self, lines, tokens};
use super::{check_finite, Place, ReadError, Soup, Syntax};

/// The keyword's prefix letters, if `token` is an OFF keyword (`OFF`, `COFF`, `STCNOFF`, ...).
fn keyword(token: &[u8]) -> Option<&[u8]> {
    let prefix = token.strip_suffix(b"OFF")?;
    prefix
        .iter()
        .all(|b| b"STCN4n".contains(b))
        .then_some(prefix)
}

/// Whether the first token of the text is an OFF keyword.
pub(crate) fn has_keyword(bytes: &[u8]) -> bool {
    lines(bytes)
        .flat_map(|(_, line)| tokens(line))
        .next()
        .is_some_and(|t| keyword(t).is_some())
}

/// Reads OFF text.
pub(crate) fn read(bytes: &[u8]) -> Result<Soup, ReadError> {
    let mut lines = lines(bytes).filter(|(_, l)| tokens(l).next().is_some());
    let header =
        |line: usize, what: &str| ReadError::at(Place::Line(line), Syntax::Header(what.into()));
    let truncated = |reading| {
        ReadError::at(
            Place::Line(bytes.split(|&b| b == b'\n').count()),
            Syntax::Truncated { reading },
        )
    };

    // Keyword (optional) and counts, which may share its line.
    let (mut line, first) = lines.next().ok_or(truncated("the header"))?;
    let mut t: Vec<&[u8]> = tokens(first).collect();
    let mut prefix: &[u8] = b"";
    if let Some(p) = keyword(t[0]) {
        prefix = p;
        if p.contains(&b'4') || p.contains(&b'n') {
            return Err(header(line, "only 3-dimensional OFF is read"));
        }
        if t.get(1) == Some(&&b"BINARY"[..]) {
            return Err(header(line, "binary OFF is not read; write it as text"));
        }
        t.remove(0);
        if t.is_empty() {
            let (l, counts) = lines.next().ok_or(truncated("the counts"))?;
            line = l;
            t = tokens(counts).collect();
        }
    }
    if t.len() < 2 {
        return Err(ReadError::at(
            Place::Line(line),
            Syntax::TooFewValues {
                needed: 3,
                found: t.len(),
            },
        ));
    }
    let count = |token: &[u8]| -> Result<usize, ReadError> {
        let n = text::integer(token).map_err(|s| ReadError::at(Place::Line(line), s))?;
        usize::try_from(n)
            .ok()
            .filter(|&n| n < 1 << 31)
            .ok_or_else(|| header(line, &format!("count {n} is out of range")))
    };
    let (vertices, faces) = (count(t[0])?, count(t[1])?);
    let has_normals = prefix.contains(&b'N');
    let has_colors = prefix.contains(&b'C');

    // No allocation from a count before the bytes are there: a vertex takes at least 6 bytes.
    let mut soup = Soup {
        positions: Vec::with_capacity(vertices.min(bytes.len() / 6)),
        ..Soup::default()
    };
    let mut colors = Vec::new();
    let mut vertex_lines = Vec::new();
    for _ in 0..vertices {
        let (line, text) = lines.next().ok_or(truncated("the vertices"))?;
        let mut t = tokens(text);
        soup.positions.push(text::numbers::<3>(&mut t, line)?);
        vertex_lines.push(line);
        if has_colors {
            if has_normals {
                text::numbers::<3>(&mut t, line)?;
            }
            let rgb: Vec<&[u8]> = t.take(3).collect();
            let mut c = [255u8; 3];
            if rgb.len() == 3 {
                for (out, token) in c.iter_mut().zip(&rgb) {
                    let v = text::number(token).map_err(|s| ReadError::at(Place::Line(line), s))?;
                    *out = text::channel(token, v);
                }
            }
            colors.push(c);
        }
    }
    check_finite(&soup.positions, |v| Place::Line(vertex_lines[v]))?;
    let mut corners = Vec::new();
    for _ in 0..faces {
        let (line, text) = lines.next().ok_or(truncated("the faces"))?;
        let at = |s| ReadError::at(Place::Line(line), s);
        let mut t = tokens(text);
        let n = text::integer(t.next().unwrap_or(b"")).map_err(at)?;
        let n = usize::try_from(n).map_err(|_| at(Syntax::Number(n.to_string())))?;
        corners.clear();
        for k in 0..n {
            let token = t.next().ok_or(at(Syntax::TooFewValues {
                needed: n + 1,
                found: k + 1,
            }))?;
            let i = text::integer(token).map_err(at)?;
            if !(0..vertices as i64).contains(&i) {
                return Err(at(Syntax::Index { index: i, vertices }));
            }
            corners.push(i as u32);
        }
        soup.push_polygon(&corners);
    }
    if has_colors {
        soup.colors = Some(colors);
    }
    Ok(soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_square_with_colours() {
        let soup = read(b"COFF\n# a square\n4 2 0\n0 0 0 255 0 0\n1 0 0 0 1.0 0 1\n1 1 0\n0 1 0 0 0 255\n\n3 0 1 2\n3 0 2 3 9 9 9\n").unwrap();
        assert_eq!(soup.positions.len(), 4);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(
            soup.colors,
            Some(vec![[255, 0, 0], [0, 255, 0], [255, 255, 255], [0, 0, 255]])
        );
    }

    #[test]
    fn counts_may_share_the_keyword_line_or_stand_alone() {
        let a = read(b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
        let b = read(b"3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
        assert_eq!(a, b);
        assert_eq!(a.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn quads_are_fanned() {
        let soup = read(b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n").unwrap();
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn hostile_headers_are_errors_without_allocation() {
        let e = read(b"OFF\n2000000000 1 0\n0 0 0\n").unwrap_err();
        assert_eq!(
            e.syntax,
            Syntax::Truncated {
                reading: "the vertices"
            }
        );
        let e = read(b"OFF\n-1 1 0\n").unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
        let e = read(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 6: vertex index 3 is out of range (3 vertices defined)"
        );
        let e = read(b"OFF BINARY\n").unwrap_err();
        assert!(e.to_string().contains("binary OFF"), "{e}");
        let e = read(b"OFF\n1 0 0\n0 inf 0\n").unwrap_err();
        assert_eq!(e.syntax, Syntax::NonFinite { vertex: 0 });
    }
}
