//! STL (stereolithography), read and written by hand: a binary STL is a fixed 50-byte
//! record per triangle and an ASCII one five keywords; reading them here lets the reader
//! weld the corners itself, report the weld, and name the byte or line of every error.
//!
//! # Reading
//!
//! A file whose length is `84 + 50 n`, where `n` is the triangle count in bytes 80..84,
//! is binary (whatever its header says: some binary exporters start it with `solid`);
//! otherwise a file that starts with `solid` is ASCII (`solid name`, then `facet normal
//! nx ny nz`, `outer loop`, three `vertex x y z`, `endloop`, `endfacet`, and `endsolid`;
//! several solids in a row are read as one mesh; keywords in any case). Facet normals
//! and the binary attribute bytes are ignored: orientation comes from the corner order.
//!
//! STL lists every triangle by its corner positions. Corners with bit-identical
//! coordinates (`-0.0` as `0.0`) become one vertex, numbered in order of first
//! appearance; [`RawMesh::weld`] reports the counts. Corners that differ in the last bit
//! stay apart (the mesh then has boundary where the surface was meant to close);
//! `--repair` merges coincident vertices with a tolerance.
//!
//! # Writing
//!
//! Binary, with positions and facet normals as `f32` (STL's only type, so positions
//! keep about 7 significant digits), quads split along their first diagonal into
//! `(v0, v1, v2)` and `(v0, v2, v3)`. STL has no texture coordinates and no colors:
//! writing texture coordinates is [`WriteError::Unsupported`], colors are left out.

use std::collections::HashMap;
use std::io::Write as _;
use std::path::Path;

use nalgebra::Point3;

use super::text::{Words, as_text};
use super::{FilePosition, Format, RawMesh, ReadError, VertexAttributes, Weld, WriteError};
use crate::{FaceId, Mesh, PolygonSoup};

/// Bytes of the binary header before the triangle count.
const HEADER: usize = 80;
/// Bytes of a binary triangle record: normal, three corners, attribute.
const RECORD: usize = 50;

/// A syntax error: where, and what is wrong.
type Fail = super::SyntaxError;

/// Reads an STL file. See the module docs for what is kept.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    super::read_with(path, Format::Stl, parse)
}

/// Parses the bytes of an STL file.
pub fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let declared = bytes
        .get(HEADER..HEADER + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64);
    let binary_length = declared.map(|n| (HEADER + 4) as u64 + RECORD as u64 * n);
    if binary_length == Some(bytes.len() as u64) {
        return binary(bytes, declared.unwrap_or(0) as usize);
    }
    if bytes.trim_ascii_start().starts_with(b"solid") && as_text(bytes).is_ok() {
        return ascii(bytes);
    }
    Err(match (declared, binary_length) {
        (Some(n), Some(length)) => (
            FilePosition::Byte(HEADER as u64),
            format!(
                "the file is not ASCII STL (text that starts with `solid`), and as binary STL \
                 its header declares {n} triangles, which take {length} bytes, but the file has {} bytes",
                bytes.len()
            ),
        ),
        _ => (
            FilePosition::Byte(0),
            format!(
                "the file has {} bytes, fewer than a binary STL header (84), and is not ASCII STL (text that starts with `solid`)",
                bytes.len()
            ),
        ),
    })
}

/// Reads the triangles of a binary STL whose length was checked against `count`.
fn binary(bytes: &[u8], count: usize) -> Result<RawMesh, Fail> {
    let mut weld = Welder::with_capacity(count);
    for (k, record) in bytes[HEADER + 4..].chunks_exact(RECORD).enumerate() {
        let mut corners = [Point3::origin(); 3];
        for (c, corner) in corners.iter_mut().enumerate() {
            for axis in 0..3 {
                let at = 12 + 12 * c + 4 * axis;
                let value = f32::from_le_bytes([
                    record[at],
                    record[at + 1],
                    record[at + 2],
                    record[at + 3],
                ]);
                corner[axis] = value as f64;
            }
        }
        weld.triangle(&corners).map_err(|message| {
            (
                FilePosition::Byte((HEADER + 4 + RECORD * k) as u64),
                format!("triangle {k}: {message}"),
            )
        })?;
    }
    Ok(weld.finish(None))
}

/// Reads the facets of an ASCII STL.
fn ascii(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let text = as_text(bytes).map_err(|line| (FilePosition::Line(line), "not text".to_string()))?;
    let mut words = Words::new(text, 1).peekable();
    let mut weld = Welder::with_capacity(bytes.len() / 256);
    let mut face_lines = Vec::new();
    let mut solids = 0;
    while let Some((line, word)) = words.next() {
        let at = FilePosition::Line(line);
        if !word.eq_ignore_ascii_case("solid") {
            return Err((at, format!("expected `solid`, found `{word}`")));
        }
        solids += 1;
        // The solid's name: the rest of its line.
        while words.next_if(|&(l, _)| l == line).is_some() {}
        loop {
            let (line, word) = words.next().ok_or((
                at,
                "the file ends inside a solid (no `endsolid`)".to_string(),
            ))?;
            if word.eq_ignore_ascii_case("endsolid") {
                while words.next_if(|&(l, _)| l == line).is_some() {}
                break;
            }
            let facet = face_lines.len();
            let corners = facet_corners(&mut words, line, word).map_err(|(line, message)| {
                (
                    FilePosition::Line(line),
                    format!("facet {facet}: {message}"),
                )
            })?;
            weld.triangle(&corners).map_err(|message| {
                (
                    FilePosition::Line(line),
                    format!("facet {facet}: {message}"),
                )
            })?;
            face_lines.push(line as u32);
        }
    }
    if solids == 0 {
        return Err((FilePosition::Line(1), "the file is empty".into()));
    }
    Ok(weld.finish(Some(face_lines)))
}

/// Reads one facet, from its `facet` keyword (`first`, on `line`) to `endfacet`; a
/// failure names its line.
fn facet_corners<'a>(
    words: &mut impl Iterator<Item = (usize, &'a str)>,
    line: usize,
    first: &str,
) -> Result<[Point3<f64>; 3], (usize, String)> {
    if !first.eq_ignore_ascii_case("facet") {
        return Err((
            line,
            format!("expected `facet` or `endsolid`, found `{first}`"),
        ));
    }
    let mut last = line;
    last = keyword(words, "normal", last)?;
    numbers::<3>(words, last)?;
    last = keyword(words, "outer", last)?;
    last = keyword(words, "loop", last)?;
    let mut corners = [Point3::origin(); 3];
    for corner in &mut corners {
        last = keyword(words, "vertex", last)?;
        *corner = Point3::from(numbers::<3>(words, last)?);
    }
    last = keyword(words, "endloop", last)?;
    keyword(words, "endfacet", last)?;
    Ok(corners)
}

/// Reads the keyword `expected` (in any case) and returns its line; `last` is the line of
/// the word before, named when the file ends.
fn keyword<'a>(
    words: &mut impl Iterator<Item = (usize, &'a str)>,
    expected: &str,
    last: usize,
) -> Result<usize, (usize, String)> {
    match words.next() {
        Some((line, word)) if word.eq_ignore_ascii_case(expected) => Ok(line),
        Some((line, word)) => Err((line, format!("expected `{expected}`, found `{word}`"))),
        None => Err((last, format!("the file ends where `{expected}` belongs"))),
    }
}

/// The next `N` words as numbers.
fn numbers<'a, const N: usize>(
    words: &mut impl Iterator<Item = (usize, &'a str)>,
    line: usize,
) -> Result<[f64; N], (usize, String)> {
    let mut out = [0.0; N];
    for x in &mut out {
        let (l, word) = words
            .next()
            .ok_or((line, "the file ends where a number belongs".to_string()))?;
        *x = word
            .parse()
            .map_err(|_| (l, format!("`{word}` is not a number")))?;
    }
    Ok(out)
}

/// Welds triangle corners into vertices by exact position.
struct Welder {
    index: HashMap<[u64; 3], u32>,
    positions: Vec<Point3<f64>>,
    triangles: Vec<[u32; 3]>,
}

impl Welder {
    fn with_capacity(triangles: usize) -> Self {
        // A closed triangle mesh has about half as many vertices as triangles.
        Self {
            index: HashMap::with_capacity(triangles / 2),
            positions: Vec::with_capacity(triangles / 2),
            triangles: Vec::with_capacity(triangles),
        }
    }

    /// Adds a triangle, or says which corner is not finite.
    fn triangle(&mut self, corners: &[Point3<f64>; 3]) -> Result<(), String> {
        let mut t = [0; 3];
        for (c, p) in corners.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(format!(
                    "corner {c} is not finite ({}, {}, {})",
                    p.x, p.y, p.z
                ));
            }
            // Adding 0.0 turns -0.0 into 0.0, so the two weld.
            let key = [p.x, p.y, p.z].map(|x| (x + 0.0).to_bits());
            let next = self.positions.len() as u32;
            t[c] = *self.index.entry(key).or_insert(next);
            if t[c] == next {
                self.positions.push(*p);
            }
        }
        self.triangles.push(t);
        Ok(())
    }

    fn finish(self, face_lines: Option<Vec<u32>>) -> RawMesh {
        let weld = Weld {
            corners: 3 * self.triangles.len(),
            vertices: self.positions.len(),
        };
        RawMesh {
            soup: PolygonSoup::from_triangles(self.positions, &self.triangles),
            corner_uvs: None,
            face_lines,
            weld: Some(weld),
            obj_groups: Vec::new(),
        }
    }
}

/// Writes `mesh` as binary STL (see the module docs).
pub fn write(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
) -> Result<(), WriteError> {
    if attributes.uvs.is_some() {
        return Err(WriteError::Unsupported {
            path: path.to_path_buf(),
            format: Format::Stl,
            what: "texture coordinates",
        });
    }
    attributes.check(mesh)?;
    let positions = attributes.positions.unwrap_or(mesh.positions());
    let triangles = mesh.triangle_count() + 2 * mesh.quad_count();
    let count = u32::try_from(triangles).map_err(|_| WriteError::Io {
        path: path.to_path_buf(),
        error: std::io::Error::other(format!("{triangles} triangles are more than STL's 2^32")),
    })?;
    super::write_atomically(path, |w| {
        let mut header = [b' '; HEADER];
        let title = format!("beltrami binary STL, {triangles} triangles");
        header[..title.len()].copy_from_slice(title.as_bytes());
        w.write_all(&header)?;
        w.write_all(&count.to_le_bytes())?;
        for f in 0..mesh.face_count() {
            let (v, n) = mesh.face_vertex_array(FaceId::from_usize(f));
            let corner = |k: usize| positions[v[k].idx()];
            for [a, b, c] in [[0, 1, 2], [0, 2, 3]].into_iter().take(n - 2) {
                let p = [corner(a), corner(b), corner(c)];
                let normal = (p[1] - p[0]).cross(&(p[2] - p[0]));
                let normal = normal.try_normalize(0.0).unwrap_or_default();
                for x in normal.iter().chain(p.iter().flat_map(|q| q.iter())) {
                    w.write_all(&(*x as f32).to_le_bytes())?;
                }
                w.write_all(&[0, 0])?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of the given triangles (corner positions), with a header that starts
    /// with `solid` as some exporters write it.
    fn binary_file(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(HEADER, 0);
        bytes.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            bytes.extend([0u8; 12]);
            for c in t.iter().flatten() {
                bytes.extend(c.to_le_bytes());
            }
            bytes.extend([0u8; 2]);
        }
        bytes
    }

    const SQUARE: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
        [[-0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ];

    #[test]
    fn a_binary_square_welds_six_corners_into_four_vertices() {
        let raw = parse(&binary_file(&SQUARE)).unwrap();
        assert_eq!(
            raw.weld,
            Some(Weld {
                corners: 6,
                vertices: 4
            })
        );
        assert_eq!(raw.soup.face(0), [0, 1, 2]);
        assert_eq!(raw.soup.face(1), [0, 2, 3]);
        assert_eq!(raw.face_lines, None);
    }

    #[test]
    fn an_ascii_square_in_two_solids_reads_the_same() {
        let text = "solid one two\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n\
            vertex 1 0 0\n vertex 1 1 0\n endloop\n endfacet\nendsolid one two\n\
            SOLID\nFACET NORMAL 0 0 1 OUTER LOOP VERTEX -0 0 0 VERTEX 1 1 0 VERTEX 0 1 0\n\
            ENDLOOP ENDFACET ENDSOLID\n";
        let raw = parse(text.as_bytes()).unwrap();
        let binary = parse(&binary_file(&SQUARE)).unwrap();
        assert_eq!(raw.soup, binary.soup);
        assert_eq!(raw.weld, binary.weld);
        assert_eq!(raw.face_lines, Some(vec![2, 11]));
    }

    #[test]
    fn errors_name_the_byte_or_the_line() {
        let mut short = binary_file(&SQUARE);
        short.pop();
        let (at, message) = parse(&short).unwrap_err();
        assert_eq!(at, FilePosition::Byte(80));
        assert!(
            message.contains("declares 2 triangles, which take 184 bytes"),
            "{message}"
        );

        let mut nan = SQUARE;
        nan[1][2][1] = f32::NAN;
        let (at, message) = parse(&binary_file(&nan)).unwrap_err();
        assert_eq!(at, FilePosition::Byte(134));
        assert!(
            message.contains("triangle 1: corner 2 is not finite"),
            "{message}"
        );

        let cases: [(&str, usize, &str); 3] = [
            (
                "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0\nendloop",
                5,
                "facet 0: `endloop` is not a number",
            ),
            (
                "solid\nfacet normal 0 0 1\nouter lop\n",
                3,
                "expected `loop`, found `lop`",
            ),
            (
                "solid x\nfacet normal 0 0 1 outer loop vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 endloop endfacet\n",
                1,
                "no `endsolid`",
            ),
        ];
        for (text, line, expected) in cases {
            let (at, message) = parse(text.as_bytes()).unwrap_err();
            assert_eq!(at, FilePosition::Line(line), "{text:?}: {message}");
            assert!(message.contains(expected), "{text:?}: {message}");
        }
    }
}
