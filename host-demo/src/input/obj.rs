//! Wavefront OBJ: `v` and `f` statements, everything else ignored.
//!
//! Read as modellers write it: groups, objects, smoothing groups and materials (even an empty
//! `usemtl`) do not change the mesh; `v x y z r g b` carries a colour (fractions of 1); face
//! corners may be `i`, `i/t`, `i//n` or `i/t/n`, negative indices count back from the latest
//! vertex; a line ending in `\` continues on the next; points (`p`) and polylines (`l`) have no
//! surface and are skipped.

use super::text::{self, lines, tokens};
use super::{check_finite, Place, ReadError, Soup, Syntax};

/// Whether the text has an OBJ vertex or face statement.
pub(crate) fn looks_like_obj(bytes: &[u8]) -> bool {
    lines(bytes).any(|(_, line)| {
        let mut t = tokens(line);
        matches!(t.next(), Some(b"v") | Some(b"f"))
    })
}

/// Statements with their first line numbers, continuation lines joined.
fn statements(bytes: &[u8]) -> impl Iterator<Item = (usize, std::borrow::Cow<'_, [u8]>)> {
    let mut inner = lines(bytes);
    std::iter::from_fn(move || {
        let (number, line) = inner.next()?;
        if !line.trim_ascii_end().ends_with(b"\\") {
            return Some((number, std::borrow::Cow::Borrowed(line)));
        }
        let mut joined = Vec::new();
        let mut part = line;
        loop {
            let trimmed = part.trim_ascii_end();
            match trimmed.strip_suffix(b"\\") {
                Some(head) => {
                    joined.extend_from_slice(head);
                    joined.push(b' ');
                }
                None => {
                    joined.extend_from_slice(part);
                    break;
                }
            }
            match inner.next() {
                Some((_, next)) => part = next,
                None => break,
            }
        }
        Some((number, std::borrow::Cow::Owned(joined)))
    })
}

/// Reads OBJ text.
pub(crate) fn read(bytes: &[u8]) -> Result<Soup, ReadError> {
    let total = statements(bytes)
        .filter(|(_, s)| tokens(s).next() == Some(b"v"))
        .count();
    let mut soup = Soup {
        positions: Vec::with_capacity(total),
        ..Soup::default()
    };
    let mut colors: Vec<[u8; 3]> = Vec::new();
    let mut vertex_lines = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    for (line, statement) in statements(bytes) {
        let mut t = tokens(&statement);
        match t.next() {
            Some(b"v") => {
                let p: [f32; 3] = text::numbers(&mut t, line)?;
                // `v x y z r g b`: three more values are a colour (a fourth alone is `w`).
                let mut rest: [&[u8]; 3] = [b""; 3];
                let mut extra = 0;
                for (slot, token) in rest.iter_mut().zip(t) {
                    *slot = token;
                    extra += 1;
                }
                if extra == 3 {
                    let mut c = [255u8; 3];
                    for (out, token) in c.iter_mut().zip(&rest) {
                        let v =
                            text::number(token).map_err(|s| ReadError::at(Place::Line(line), s))?;
                        *out = (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                    }
                    colors.resize(soup.positions.len(), [255; 3]);
                    colors.push(c);
                }
                soup.positions.push(p);
                vertex_lines.push(line);
            }
            Some(b"f") => {
                corners.clear();
                for token in t {
                    let index = token.split(|&b| b == b'/').next().unwrap_or(token);
                    let i =
                        text::integer(index).map_err(|s| ReadError::at(Place::Line(line), s))?;
                    let seen = soup.positions.len() as i64;
                    let resolved = if (1..=total as i64).contains(&i) {
                        i - 1
                    } else if (-seen..0).contains(&i) {
                        seen + i
                    } else {
                        return Err(ReadError::at(
                            Place::Line(line),
                            Syntax::Index {
                                index: i,
                                vertices: if i < 0 { seen as usize } else { total },
                            },
                        ));
                    };
                    corners.push(resolved as u32);
                }
                // A face of one or two corners has no surface: skipped, as points and lines.
                soup.push_polygon(&corners);
            }
            _ => {}
        }
    }
    check_finite(&soup.positions, |v| Place::Line(vertex_lines[v]))?;
    if !colors.is_empty() {
        colors.resize(soup.positions.len(), [255; 3]);
        soup.colors = Some(colors);
    }
    Ok(soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(text: &str) -> Result<Soup, ReadError> {
        read(text.as_bytes())
    }

    #[test]
    fn groups_materials_and_odd_text_do_not_change_the_mesh() {
        let plain = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n").unwrap();
        let messy = read(
            b"# caf\xe9\r\nmtllib x.mtl\no a\ng one\nv 0 0 0\nv\t1 0 0 \nusemtl\nv 0 1 0\n\
              s off\nf 1/1 2/2/2 3//3\ng two\nv 1.0e0 1 0\nf -3 -1 \\\n -2\nl 1 2\np 1\n",
        )
        .unwrap();
        assert_eq!(plain, messy);
    }

    #[test]
    fn colours_are_fractions_and_default_to_white() {
        let soup = read_str("v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0.5 1\nf 1 2 3\n").unwrap();
        assert_eq!(
            soup.colors,
            Some(vec![[255, 0, 0], [255, 255, 255], [0, 128, 255]])
        );
    }

    #[test]
    fn errors_name_the_line() {
        let e = read_str("v 0 0 0\nv 1 0 x\n").unwrap_err();
        assert_eq!(e.to_string(), "line 2: `x` is not a number");
        let e = read_str("v 0 0 0\nv 1 0\n").unwrap_err();
        assert_eq!(e.place, Place::Line(2));
        let e = read_str("v 0 0 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: vertex index 2 is out of range (1 vertices defined)"
        );
        let e = read_str("v 0 0 0\nf -2 1 1\n").unwrap_err();
        assert_eq!(e.place, Place::Line(2));
        let two = read_str("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap();
        assert!(two.triangles.is_empty());
        let e = read_str("v 0 0 0\nv 0 nan 0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: vertex 2 has a NaN or infinite coordinate"
        );
    }

    #[test]
    fn forward_references_are_allowed() {
        let soup = read_str("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(soup.triangles, vec![[0, 1, 2]]);
    }
}
