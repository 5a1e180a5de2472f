//! STL, binary and ASCII. Every triangle lists its own three corners; corners with the same
//! coordinates (bit for bit, `-0` equal to `0`) are welded into one vertex here, in order of
//! first appearance, which is what makes an STL file a mesh at all.
//!
//! A binary file is recognised by its length (84 bytes plus 50 per triangle, as its count
//! says), even when its 80-byte header starts with `solid`, as many exporters write it.

use std::collections::HashMap;

use super::text::{self, lines, tokens};
use super::{Place, ReadError, Soup, Syntax};

/// Whether `bytes` has exactly the length a binary STL with its triangle count has.
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    triangle_count(bytes).is_some_and(|n| 84 + 50 * n as u64 == bytes.len() as u64)
}

/// Whether `bytes` starts with `solid` and has a `facet` or `endsolid` keyword after it.
pub(crate) fn is_ascii(bytes: &[u8]) -> bool {
    let head = bytes.trim_ascii_start();
    head.starts_with(b"solid")
        && head
            .windows(8)
            .any(|w| w[..5].eq_ignore_ascii_case(b"facet") || w.eq_ignore_ascii_case(b"endsolid"))
}

fn triangle_count(bytes: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?))
}

/// Welds corners with equal coordinates into vertices.
#[derive(Default)]
struct Welder {
    index: HashMap<[u32; 3], u32>,
    soup: Soup,
}

impl Welder {
    fn corner(&mut self, p: [f32; 3]) -> u32 {
        // `+ 0.0` turns -0 into +0, so the two weld.
        let key = p.map(|c| (c + 0.0).to_bits());
        let next = self.soup.positions.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.soup.positions.push(p);
            next
        })
    }
}

/// Reads STL bytes.
pub(crate) fn read(bytes: &[u8]) -> Result<Soup, ReadError> {
    if !is_binary(bytes) && is_ascii(bytes) {
        ascii(bytes)
    } else {
        binary(bytes)
    }
}

fn binary(bytes: &[u8]) -> Result<Soup, ReadError> {
    let n = triangle_count(bytes).ok_or(ReadError::at(
        Place::Byte(bytes.len() as u64),
        Syntax::Truncated {
            reading: "the 84-byte header",
        },
    ))?;
    let mut welder = Welder::default();
    // The count is only believed as far as the bytes go.
    let records = bytes[84..].chunks_exact(50);
    if (records.len() as u64) < n as u64 {
        let whole = records.len() as u64;
        return Err(ReadError::at(
            Place::Byte(84 + 50 * whole),
            Syntax::Truncated {
                reading: "the triangles (the header promises more)",
            },
        ));
    }
    welder.soup.triangles.reserve(n as usize);
    for (t, record) in records.take(n as usize).enumerate() {
        let mut tri = [0u32; 3];
        for (k, corner) in tri.iter_mut().enumerate() {
            let at = 12 + 12 * k;
            let p: [f32; 3] = std::array::from_fn(|a| {
                let o = at + 4 * a;
                f32::from_le_bytes([record[o], record[o + 1], record[o + 2], record[o + 3]])
            });
            if !p.iter().all(|c| c.is_finite()) {
                return Err(ReadError::at(
                    Place::Byte((84 + 50 * t + at) as u64),
                    Syntax::NonFinite { vertex: 3 * t + k },
                ));
            }
            *corner = welder.corner(p);
        }
        welder.soup.triangles.push(tri);
    }
    Ok(welder.soup)
}

fn ascii(bytes: &[u8]) -> Result<Soup, ReadError> {
    let mut welder = Welder::default();
    let mut corners: Vec<u32> = Vec::new();
    let mut count = 0;
    for (line, text) in lines(bytes) {
        let mut t = tokens(text);
        while let Some(token) = t.next() {
            if token.eq_ignore_ascii_case(b"vertex") {
                let p: [f32; 3] = text::numbers(&mut t, line)?;
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(ReadError::at(
                        Place::Line(line),
                        Syntax::NonFinite { vertex: count },
                    ));
                }
                count += 1;
                corners.push(welder.corner(p));
            } else if token.eq_ignore_ascii_case(b"endloop") {
                welder.soup.push_polygon(&corners);
                corners.clear();
            }
        }
    }
    Ok(welder.soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `triangles`, with a header that starts with `solid`.
    pub(crate) fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut out = b"solid made by a test".to_vec();
        out.resize(80, b' ');
        out.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend([0u8; 12]);
            for c in t.iter().flatten() {
                out.extend(c.to_le_bytes());
            }
            out.extend([0u8; 2]);
        }
        out
    }

    const SQUARE: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
        [[-0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ];

    #[test]
    fn binary_and_ascii_weld_to_the_same_square() {
        let bytes = binary_stl(&SQUARE);
        assert!(is_binary(&bytes));
        let b = read(&bytes).unwrap();
        assert_eq!(b.positions.len(), 4);
        assert_eq!(b.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let text =
            b"solid sq\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n\
            vertex 1 1 0\n  endloop\n endfacet\n FACET NORMAL 0 0 1\n OUTER LOOP\n VERTEX -0 0 0\n\
            VERTEX 1 1 0\n VERTEX 0 1 0\n ENDLOOP\n ENDFACET\nendsolid sq\n";
        assert!(is_ascii(text));
        assert_eq!(read(text).unwrap(), b);
    }

    #[test]
    fn a_short_binary_file_is_truncated_not_allocated() {
        let mut bytes = binary_stl(&SQUARE);
        bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = read(&bytes).unwrap_err();
        assert_eq!(e.place, Place::Byte(84 + 100));
        assert!(e.to_string().contains("promises more"), "{e}");
        bytes[..5].copy_from_slice(b"SOLID");
        let e = read(&bytes[..50]).unwrap_err();
        assert!(e.to_string().contains("84-byte header"), "{e}");
        let mut nan = binary_stl(&SQUARE);
        nan[84 + 12 + 4..84 + 12 + 8].copy_from_slice(&f32::NAN.to_le_bytes());
        let e = read(&nan).unwrap_err();
        assert_eq!(e.syntax, Syntax::NonFinite { vertex: 0 });
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let e =
            read(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\nendloop\n").unwrap_err();
        assert_eq!(e.place, Place::Line(4));
    }
}
