//! Mesh files as people write them: OBJ, OFF, PLY and STL in, one triangle soup out.
//!
//! Each reader turns its format into a [`Soup`]: positions, optional colours and triangles whose
//! indices are in range but which may be degenerate, repeated, non-manifold or inconsistently
//! oriented ([`crate::repair`] makes a buildable mesh of it). Polygons are fan-triangulated.
//! Vertex indices are global to the file, so its groups and objects never change the mesh.
//!
//! The format is found from the content first (the PLY and OFF keywords, a binary STL's length,
//! an ASCII STL's `solid`/`facet`) and from the extension second; every error names the format
//! and the line (text) or byte offset (binary) where reading stopped.
//!
//! The readers are ours rather than crates': `tobj` reads each `g`/`o` group as a separate vertex
//! set (so a closed mesh with one group line became non-manifold) and refuses a file with one
//! non-UTF-8 byte without a line number; `stl_io` takes a binary STL whose header starts with
//! `solid ` for ASCII; `ply-rs` pushes a record per claimed element even when an element has no
//! properties to read. Here nothing is allocated from a count before the bytes that hold it are
//! there, so a hostile header costs no memory.

mod obj;
mod off;
mod ply;
mod stl;
mod text;

use std::fmt;

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ.
    Obj,
    /// Object File Format (`OFF`, `COFF`, `NOFF`, ...).
    Off,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// STL, ASCII or binary.
    Stl,
}

impl Format {
    /// All formats, in the order detection tries their extensions.
    pub const ALL: [Format; 4] = [Format::Obj, Format::Off, Format::Ply, Format::Stl];

    /// The format's usual file extension, lower case.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Off => "off",
            Format::Ply => "ply",
            Format::Stl => "stl",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Off => "OFF",
            Format::Ply => "PLY",
            Format::Stl => "STL",
        })
    }
}

/// Triangles as a file states them: indices in range, nothing else promised.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Soup {
    /// Vertex positions, finite.
    pub positions: Vec<[f32; 3]>,
    /// Vertex colours, when the file has any (vertices without one are white).
    pub colors: Option<Vec<[u8; 3]>>,
    /// Triangles; every index is below `positions.len()`.
    pub triangles: Vec<[u32; 3]>,
}

/// Where in a file reading stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// A line of text, counted from 1.
    Line(usize),
    /// A byte offset in binary data.
    Byte(u64),
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Line(n) => write!(f, "line {n}"),
            Place::Byte(n) => write!(f, "byte {n}"),
        }
    }
}

/// What is wrong at a [`Place`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Syntax {
    /// A token that should be a number is not one.
    Number(String),
    /// Fewer values than the statement needs.
    TooFewValues {
        /// How many it needs.
        needed: usize,
        /// How many there are.
        found: usize,
    },
    /// A face refers to a vertex that does not exist.
    Index {
        /// The index as written (1-based for OBJ, 0-based elsewhere).
        index: i64,
        /// Vertices defined.
        vertices: usize,
    },
    /// The data ends before what the header promised.
    Truncated {
        /// What was being read.
        reading: &'static str,
    },
    /// A header line that cannot be understood.
    Header(String),
    /// A vertex has a NaN or infinite coordinate.
    NonFinite {
        /// Zero-based vertex number in the file.
        vertex: usize,
    },
}

impl fmt::Display for Syntax {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Syntax::Number(token) => write!(f, "`{token}` is not a number"),
            Syntax::TooFewValues { needed, found } => {
                write!(f, "{found} values where {needed} are needed")
            }
            Syntax::Index { index, vertices } => write!(
                f,
                "vertex index {index} is out of range ({vertices} vertices defined)"
            ),
            Syntax::Truncated { reading } => {
                write!(f, "the file ends while reading {reading}")
            }
            Syntax::Header(what) => write!(f, "header: {what}"),
            Syntax::NonFinite { vertex } => {
                write!(f, "vertex {} has a NaN or infinite coordinate", vertex + 1)
            }
        }
    }
}

/// A [`Syntax`] problem and where it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadError {
    /// Where reading stopped.
    pub place: Place,
    /// What is wrong there.
    pub syntax: Syntax,
}

impl ReadError {
    pub(crate) fn at(place: Place, syntax: Syntax) -> ReadError {
        ReadError { place, syntax }
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.place, self.syntax)
    }
}

/// What the first bytes of a file say it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detected {
    /// A mesh format.
    Mesh(Format),
    /// One of vdlod's own files, which hold no mesh to read.
    Vdlod(&'static str),
    /// Nothing recognisable.
    Unknown,
}

/// The format of `bytes`, from their content, else from the extension of `name`.
///
/// ```
/// use vdlod_demo::input::{detect, Detected, Format};
/// assert_eq!(detect("a.txt", b"ply\nformat ascii 1.0\n"), Detected::Mesh(Format::Ply));
/// assert_eq!(detect("b.obj", b"OFF\n3 1 0\n"), Detected::Mesh(Format::Off));
/// assert_eq!(detect("c.stl", b""), Detected::Mesh(Format::Stl));
/// ```
pub fn detect(name: &str, bytes: &[u8]) -> Detected {
    if bytes.starts_with(&vdlod_core::format::MAGIC) {
        return Detected::Vdlod("a vdlod hierarchy (.vdh)");
    }
    if bytes.starts_with(&vdlod_core::wavelet::format::MAGIC) {
        return Detected::Vdlod("a vdlod semi-regular mesh (.vdw)");
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Detected::Mesh(Format::Ply);
    }
    if stl::is_binary(bytes) || stl::is_ascii(bytes) {
        return Detected::Mesh(Format::Stl);
    }
    if off::has_keyword(bytes) {
        return Detected::Mesh(Format::Off);
    }
    let extension = name
        .rsplit_once('.')
        .map(|(_, e)| e.trim_end_matches(" (bundled)").to_ascii_lowercase());
    if let Some(format) = Format::ALL
        .into_iter()
        .find(|f| extension.as_deref() == Some(f.extension()))
    {
        return Detected::Mesh(format);
    }
    if obj::looks_like_obj(bytes) {
        return Detected::Mesh(Format::Obj);
    }
    Detected::Unknown
}

/// Reads `bytes` as `format`. Vertices that no triangle uses are kept ([`Soup::drop_unused`]
/// removes them).
pub fn read(format: Format, bytes: &[u8]) -> Result<Soup, ReadError> {
    match format {
        Format::Obj => obj::read(bytes),
        Format::Off => off::read(bytes),
        Format::Ply => ply::read(bytes),
        Format::Stl => stl::read(bytes),
    }
}

impl Soup {
    /// Appends a polygon's corners as a triangle fan (nothing for fewer than three corners).
    pub(crate) fn push_polygon(&mut self, corners: &[u32]) {
        if let Some((&first, rest)) = corners.split_first() {
            for pair in rest.windows(2) {
                self.triangles.push([first, pair[0], pair[1]]);
            }
        }
    }

    /// Drops the vertices no triangle uses and renumbers the rest in order of first use.
    pub fn drop_unused(&mut self) {
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut order = Vec::new();
        for i in self.triangles.iter_mut().flatten() {
            let slot = &mut new_index[*i as usize];
            if *slot == u32::MAX {
                *slot = order.len() as u32;
                order.push(*i as usize);
            }
            *i = *slot;
        }
        self.positions = order.iter().map(|&i| self.positions[i]).collect();
        if let Some(colors) = &self.colors {
            self.colors = Some(order.iter().map(|&i| colors[i]).collect());
        }
    }
}

/// The first non-finite vertex of `positions`, as an error at `place`.
pub(crate) fn check_finite(
    positions: &[[f32; 3]],
    place: impl Fn(usize) -> Place,
) -> Result<(), ReadError> {
    match positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        Some(vertex) => Err(ReadError::at(place(vertex), Syntax::NonFinite { vertex })),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_wins_over_extension() {
        assert_eq!(detect("x.obj", b"ply\r\n"), Detected::Mesh(Format::Ply));
        assert_eq!(detect("x.ply", b"COFF 3 1 0"), Detected::Mesh(Format::Off));
        assert_eq!(
            detect("x.obj", b"solid s\n facet normal 0 0 1\n"),
            Detected::Mesh(Format::Stl)
        );
        assert_eq!(
            detect("x.obj", b"VDLH...."),
            Detected::Vdlod("a vdlod hierarchy (.vdh)")
        );
        assert_eq!(detect("x.OFF", b"3 1 0"), Detected::Mesh(Format::Off));
        assert_eq!(
            detect("x", b"v 0 0 0\nf 1 1 1\n"),
            Detected::Mesh(Format::Obj)
        );
        assert_eq!(detect("x", b"\x00\x01"), Detected::Unknown);
    }

    #[test]
    fn unused_vertices_are_dropped_in_order_of_first_use() {
        let mut soup = Soup {
            positions: vec![[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]],
            colors: Some(vec![[0; 3], [1; 3], [2; 3], [3; 3]]),
            triangles: vec![[3, 1, 3]],
        };
        soup.drop_unused();
        assert_eq!(soup.positions, vec![[3.0; 3], [1.0; 3]]);
        assert_eq!(soup.colors, Some(vec![[3; 3], [1; 3]]));
        assert_eq!(soup.triangles, vec![[0, 1, 0]]);
    }

    #[test]
    fn polygons_become_fans() {
        let mut soup = Soup::default();
        soup.push_polygon(&[0, 1]);
        assert!(soup.triangles.is_empty());
        soup.push_polygon(&[0, 1, 2, 3, 4]);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }
}
