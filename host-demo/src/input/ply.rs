//! Stanford PLY, ASCII and binary (either byte order).
//!
//! The `vertex` element gives positions (`x`, `y`, `z`, any numeric type) and colours (`red`,
//! `green`, `blue` or their `diffuse_` forms: bytes as they are, floating-point values as
//! fractions of 1); the `face` element's `vertex_indices` (or `vertex_index`) list gives
//! polygons. Every other element and property is read past. Counts in the header are promises,
//! not allocations: arrays grow as the data proves them.

use super::text::{self, lines, raw_lines, tokens};
use super::{Place, ReadError, Soup, Syntax};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: Vec<u8>,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: Vec<u8>,
    count: u64,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// The header: encoding, elements, and the offset where the data starts.
fn header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize, usize), ReadError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    // Comments are whole lines here, and `#` is not special.
    for (line, raw, end) in raw_lines(bytes) {
        let bad = |what: String| ReadError::at(Place::Line(line), Syntax::Header(what));
        let mut t = tokens(raw);
        let Some(keyword) = t.next() else { continue };
        match keyword {
            b"ply" if line == 1 => {}
            b"comment" | b"obj_info" => {}
            b"format" => {
                encoding = Some(match t.next() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::Little,
                    Some(b"binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(bad(format!(
                            "unknown format `{}`",
                            text::show(other.unwrap_or(b""))
                        )))
                    }
                });
            }
            b"element" => {
                let name = t
                    .next()
                    .ok_or_else(|| bad("an element without a name".into()))?;
                let count = t
                    .next()
                    .and_then(|c| text::integer(c).ok())
                    .and_then(|c| u64::try_from(c).ok())
                    .ok_or_else(|| bad(format!("element `{}` has no count", text::show(name))))?;
                elements.push(Element {
                    name: name.to_vec(),
                    count,
                    properties: Vec::new(),
                });
            }
            b"property" => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad("a property before any element".into()))?;
                let parts: Vec<&[u8]> = t.collect();
                let scalar = |name: &[u8]| {
                    Scalar::parse(name)
                        .ok_or_else(|| bad(format!("unknown type `{}`", text::show(name))))
                };
                let (kind, name) = match parts.as_slice() {
                    [b"list", count, item, name] => (
                        Kind::List {
                            count: scalar(count)?,
                            item: scalar(item)?,
                        },
                        name,
                    ),
                    [kind, name] => (Kind::Scalar(scalar(kind)?), name),
                    _ => return Err(bad(format!("cannot read `{}`", text::show(raw)))),
                };
                element.properties.push(Property {
                    name: name.to_vec(),
                    kind,
                });
            }
            b"end_header" => {
                let encoding = encoding.ok_or_else(|| bad("no `format` line".into()))?;
                return Ok((encoding, elements, end, line + 1));
            }
            other => return Err(bad(format!("unknown keyword `{}`", text::show(other)))),
        }
    }
    Err(ReadError::at(
        Place::Line(lines(bytes).count().max(1)),
        Syntax::Truncated {
            reading: "the header (no `end_header`)",
        },
    ))
}

/// Values in the body, one at a time.
trait Values {
    fn next(&mut self, kind: Scalar, reading: &'static str) -> Result<f64, ReadError>;
    /// Where the next value is.
    fn place(&self) -> Place;
}

struct Binary<'a> {
    bytes: &'a [u8],
    offset: usize,
    big: bool,
}

impl Values for Binary<'_> {
    fn next(&mut self, kind: Scalar, reading: &'static str) -> Result<f64, ReadError> {
        let n = kind.size();
        let Some(raw) = self.bytes.get(self.offset..self.offset + n) else {
            return Err(ReadError::at(self.place(), Syntax::Truncated { reading }));
        };
        self.offset += n;
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(raw);
        if self.big {
            b[..n].reverse();
        }
        Ok(match kind {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    fn place(&self) -> Place {
        Place::Byte(self.offset as u64)
    }
}

struct Ascii<'a, I: Iterator<Item = (usize, &'a [u8])>> {
    lines: I,
    tokens: Vec<&'a [u8]>,
    next_token: usize,
    line: usize,
}

impl<'a, I: Iterator<Item = (usize, &'a [u8])>> Values for Ascii<'a, I> {
    fn next(&mut self, kind: Scalar, reading: &'static str) -> Result<f64, ReadError> {
        while self.next_token == self.tokens.len() {
            let Some((line, text)) = self.lines.next() else {
                return Err(ReadError::at(self.place(), Syntax::Truncated { reading }));
            };
            self.line = line;
            self.tokens = tokens(text).collect();
            self.next_token = 0;
        }
        let token = self.tokens[self.next_token];
        self.next_token += 1;
        let at = |s| ReadError::at(Place::Line(self.line), s);
        if kind.is_float() {
            text::number(token).map(f64::from).map_err(at)
        } else {
            text::integer(token).map(|v| v as f64).map_err(at)
        }
    }

    fn place(&self) -> Place {
        Place::Line(self.line)
    }
}

/// Reads PLY bytes.
pub(crate) fn read(bytes: &[u8]) -> Result<Soup, ReadError> {
    let (encoding, elements, start, first_line) = header(bytes)?;
    let body = &bytes[start..];
    match encoding {
        Encoding::Ascii => {
            let lines = lines(body).map(move |(n, l)| (n + first_line - 1, l));
            body_of(
                &elements,
                &mut Ascii {
                    lines,
                    tokens: Vec::new(),
                    next_token: 0,
                    line: first_line,
                },
                body.len(),
            )
        }
        Encoding::Little | Encoding::Big => body_of(
            &elements,
            &mut Binary {
                bytes,
                offset: start,
                big: encoding == Encoding::Big,
            },
            body.len(),
        ),
    }
}

/// Where a vertex property goes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Slot {
    Position(usize),
    Color(usize),
    Skip,
}

fn body_of(elements: &[Element], values: &mut impl Values, body: usize) -> Result<Soup, ReadError> {
    let header_error = |what: String| ReadError::at(Place::Line(1), Syntax::Header(what));
    let vertices = elements
        .iter()
        .find(|e| e.name == b"vertex")
        .ok_or_else(|| header_error("no `vertex` element".into()))?;
    if vertices.count >= 1 << 31 {
        return Err(header_error(format!(
            "{} vertices is more than 2^31",
            vertices.count
        )));
    }
    let vertex_count = vertices.count as usize;
    let mut soup = Soup {
        positions: Vec::with_capacity(vertex_count.min(body / 3)),
        ..Soup::default()
    };
    let mut colors = Vec::new();
    let mut corners = Vec::new();
    for element in elements {
        if element.name == b"vertex" {
            let slots: Vec<Slot> = element
                .properties
                .iter()
                .map(|p| match (p.name.as_slice(), p.kind) {
                    (b"x", Kind::Scalar(_)) => Slot::Position(0),
                    (b"y", Kind::Scalar(_)) => Slot::Position(1),
                    (b"z", Kind::Scalar(_)) => Slot::Position(2),
                    (b"red" | b"diffuse_red" | b"r", Kind::Scalar(_)) => Slot::Color(0),
                    (b"green" | b"diffuse_green" | b"g", Kind::Scalar(_)) => Slot::Color(1),
                    (b"blue" | b"diffuse_blue" | b"b", Kind::Scalar(_)) => Slot::Color(2),
                    _ => Slot::Skip,
                })
                .collect();
            for axis in 0..3 {
                if !slots.contains(&Slot::Position(axis)) {
                    return Err(header_error(format!(
                        "the vertex element has no `{}` property",
                        ["x", "y", "z"][axis]
                    )));
                }
            }
            let has_colors = (0..3).all(|c| slots.contains(&Slot::Color(c)));
            for _ in 0..element.count {
                let mut p = [0f32; 3];
                let mut c = [255u8; 3];
                for (property, slot) in element.properties.iter().zip(&slots) {
                    let v = read_property(values, property.kind, "the vertices", &mut corners)?;
                    match (slot, property.kind) {
                        (Slot::Position(a), _) => p[*a] = v as f32,
                        (Slot::Color(k), Kind::Scalar(s)) => {
                            let scaled = if s.is_float() { v * 255.0 } else { v };
                            c[*k] = (scaled.clamp(0.0, 255.0) + 0.5) as u8;
                        }
                        _ => {}
                    }
                }
                if !p.iter().all(|c| c.is_finite()) {
                    let vertex = soup.positions.len();
                    return Err(ReadError::at(values.place(), Syntax::NonFinite { vertex }));
                }
                soup.positions.push(p);
                if has_colors {
                    colors.push(c);
                }
            }
            if has_colors {
                soup.colors = Some(std::mem::take(&mut colors));
            }
        } else if !element.properties.is_empty() {
            let faces = element.name == b"face";
            for _ in 0..element.count {
                for property in &element.properties {
                    read_property(values, property.kind, "the faces", &mut corners)?;
                    let place = values.place();
                    let is_indices = matches!(
                        property.name.as_slice(),
                        b"vertex_indices" | b"vertex_index"
                    );
                    if faces && is_indices && matches!(property.kind, Kind::List { .. }) {
                        let mut polygon = Vec::with_capacity(corners.len());
                        for &i in &corners {
                            if !(0.0..vertex_count as f64).contains(&i) {
                                return Err(ReadError::at(
                                    place,
                                    Syntax::Index {
                                        index: i as i64,
                                        vertices: vertex_count,
                                    },
                                ));
                            }
                            polygon.push(i as u32);
                        }
                        soup.push_polygon(&polygon);
                    }
                }
            }
        }
    }
    Ok(soup)
}

/// Reads one property's value (a scalar, returned) or list (into `list`, its length returned).
fn read_property(
    values: &mut impl Values,
    kind: Kind,
    reading: &'static str,
    list: &mut Vec<f64>,
) -> Result<f64, ReadError> {
    match kind {
        Kind::Scalar(s) => values.next(s, reading),
        Kind::List { count, item } => {
            let place = values.place();
            let n = values.next(count, reading)?;
            if !(0.0..=u32::MAX as f64).contains(&n) {
                return Err(ReadError::at(
                    place,
                    Syntax::Header(format!("a list of {n} items")),
                ));
            }
            list.clear();
            for _ in 0..n as u64 {
                list.push(values.next(item, reading)?);
            }
            Ok(n)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &[u8] = b"ply\nformat ascii 1.0\ncomment made # by hand\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
        property uchar green\nproperty uchar blue\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\
        0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n4 0 1 2 3\n";

    fn binary(big: bool) -> Vec<u8> {
        let order = if big { "big" } else { "little" };
        let mut out = format!(
            "ply\r\nformat binary_{order}_endian 1.0\r\nelement vertex 4\r\nproperty double x\r\n\
             property float y\r\nproperty int z\r\nproperty float nx\r\nproperty uchar red\r\n\
             property uchar green\r\nproperty uchar blue\r\nelement edge 1\r\nproperty int a\r\n\
             element face 1\r\nproperty uchar flags\r\nproperty list uchar uint vertex_indices\r\nend_header\r\n"
        )
        .into_bytes();
        let corners: [[f64; 3]; 4] = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let colors = [[255u8, 0, 0], [0, 255, 0], [0, 0, 255], [9, 9, 9]];
        for (p, c) in corners.iter().zip(colors) {
            let (x, y, z, nx) = (p[0], p[1] as f32, p[2] as i32, 0.5f32);
            if big {
                out.extend(
                    x.to_be_bytes()
                        .iter()
                        .chain(&y.to_be_bytes())
                        .chain(&z.to_be_bytes())
                        .chain(&nx.to_be_bytes()),
                );
            } else {
                out.extend(
                    x.to_le_bytes()
                        .iter()
                        .chain(&y.to_le_bytes())
                        .chain(&z.to_le_bytes())
                        .chain(&nx.to_le_bytes()),
                );
            }
            out.extend(c);
        }
        out.extend(if big {
            7i32.to_be_bytes()
        } else {
            7i32.to_le_bytes()
        });
        out.extend([1u8, 4]);
        for i in 0u32..4 {
            out.extend(if big {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
        out
    }

    #[test]
    fn ascii_and_both_binary_orders_agree() {
        let a = read(ASCII).unwrap();
        assert_eq!(a.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(
            a.colors.as_ref().unwrap()[..3],
            [[255, 0, 0], [0, 255, 0], [0, 0, 255]]
        );
        assert_eq!(read(&binary(false)).unwrap(), a);
        assert_eq!(read(&binary(true)).unwrap(), a);
    }

    #[test]
    fn truncation_and_lies_are_errors() {
        let full = binary(false);
        for cut in [full.len() - 1, full.len() - 17, full.len() - 60] {
            let e = read(&full[..cut]).unwrap_err();
            assert!(matches!(e.syntax, Syntax::Truncated { .. }), "{cut}: {e}");
            assert!(matches!(e.place, Place::Byte(_)), "{e}");
        }
        let huge = String::from_utf8_lossy(&full).replace("vertex 4", "vertex 4000000000");
        assert!(read(huge.as_bytes())
            .unwrap_err()
            .to_string()
            .contains("2^31"));
        let many = String::from_utf8_lossy(ASCII).replace("face 1", "face 2000000000");
        let e = read(many.as_bytes()).unwrap_err();
        assert_eq!(
            e.syntax,
            Syntax::Truncated {
                reading: "the faces"
            }
        );
        let bad_index = String::from_utf8_lossy(ASCII).replace("4 0 1 2 3", "3 0 1 4");
        let e = read(bad_index.as_bytes()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 18: vertex index 4 is out of range (4 vertices defined)"
        );
        let e = read(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n").unwrap_err();
        assert!(e.to_string().contains("end_header"), "{e}");
        let e = read(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n")
            .unwrap_err();
        assert_eq!(e.to_string(), "line 4: header: unknown type `half`");
        // A vertex element without properties gives no positions, whatever its count says (the
        // mesh fuzz target's finding of 2026-12-07: the faces' indices, checked against the
        // count, then reached past the positions).
        let e = read(
            b"ply\nformat ascii 1.0\nelement vertex 3\nelement face 1\n\
            property list uchar int vertex_indices\nend_header\n3 0 1 2\n",
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 1: header: the vertex element has no `x` property"
        );
    }
}
