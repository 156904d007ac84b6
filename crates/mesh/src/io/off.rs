//! OFF (Geomview's object file format), read and written by hand: the format is a header
//! word, three counts and one line per vertex and per face, less code than an adapter to
//! a crate would take.
//!
//! # Reading
//!
//! The header word is `[ST][C][N]OFF` (`OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`,
//! `STCNOFF`, ...); the homogeneous (`4OFF`) and n-dimensional (`nOFF`) variants are
//! refused. The counts (vertices, faces, edges; the edge count is ignored) may follow the
//! header word on its line or start the next line. Each vertex line starts with `x y z`;
//! with the `ST` prefix its last two numbers are the texture coordinates `s t`; normals
//! and colors are skipped. Each face line is `n i_1 .. i_n` with 0-based vertex indices,
//! followed by an optional color (skipped). `#` starts a comment; blank lines are skipped.
//! Only the ASCII form is read.
//!
//! # Writing
//!
//! `OFF`, or `STOFF` with texture coordinates, `COFF` with colors (RGBA, floats in
//! [0, 1], alpha 1), `STCOFF` with both. Positions are written as shortest round-trip
//! decimals, so they read back to the last bit. Vertex `k` of the file is input vertex
//! `k` whenever no vertices were merged (see `super::slots`).

use std::io::Write as _;
use std::path::Path;

use nalgebra::{Point3, Vector2};

use super::obj::{push_decimal, write_lines};
use super::slots::{OutputSlots, VertexValues};
use super::text::{Lines, as_text};
use super::{FilePosition, Format, RawMesh, ReadError, VertexAttributes, WriteError};
use crate::{FaceId, Mesh, PolygonSoup};

/// What the header word announces.
#[derive(Debug, Clone, Copy, Default)]
struct Variant {
    /// `ST`: every vertex line ends with texture coordinates.
    texture: bool,
}

/// Reads an OFF file. See the module docs for what is kept.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    super::read_with(path, Format::Off, parse)
}

/// Parses the bytes of an OFF file; a syntax error says where (its line) and what is
/// wrong.
pub fn parse(bytes: &[u8]) -> Result<RawMesh, super::SyntaxError> {
    parse_lines(bytes).map_err(|(line, message)| (FilePosition::Line(line), message))
}

/// A syntax error: the 1-based line and what is wrong.
type Fail = (usize, String);

/// The counts the header announces, and the line they are on (where a file that ends
/// too early is reported).
struct Counts {
    vertices: usize,
    faces: usize,
    line: usize,
}

/// Parses the text of an OFF file: the header, then the vertex lines, then the face lines.
fn parse_lines(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let text = as_text(bytes).map_err(|line| (line, "the file is not UTF-8 text".into()))?;
    let mut lines = Lines::new(text, Some('#'), 1);
    let (variant, counts) = read_header(&mut lines)?;
    // Every vertex and face line holds at least two bytes: reserve no more than that.
    let room = bytes.len() / 2;
    let VertexLines { positions, uvs } = read_vertices(&mut lines, variant, &counts, room)?;
    let mut soup = PolygonSoup::new(positions);
    let face_lines = read_faces(&mut lines, &mut soup, &counts, room)?;
    let corner_uvs = variant.texture.then(|| {
        soup.faces()
            .flat_map(|f| {
                f.iter()
                    .map(|&v| uvs.get(v as usize).copied().unwrap_or_default())
            })
            .collect()
    });
    Ok(RawMesh {
        soup,
        corner_uvs,
        face_lines: Some(face_lines),
        weld: None,
        obj_groups: Vec::new(),
    })
}

/// Reads the header word and the vertex and face counts, on its line or the next.
fn read_header(lines: &mut Lines) -> Result<(Variant, Counts), Fail> {
    let Some((header_line, header)) = lines.next() else {
        return Err((1, "the file is empty".into()));
    };
    let mut words = header.split_ascii_whitespace();
    let variant = variant(words.next().unwrap_or("")).map_err(|message| (header_line, message))?;
    let mut counts: Vec<&str> = words.collect();
    let mut counts_line = header_line;
    if counts.is_empty() {
        let (line, content) = lines.next().ok_or((
            header_line,
            "the file ends before the vertex and face counts".into(),
        ))?;
        counts = content.split_ascii_whitespace().collect();
        counts_line = line;
    }
    let count = |k: usize, what: &str| -> Result<usize, Fail> {
        let word = counts.get(k).ok_or_else(|| {
            (
                counts_line,
                format!("expected the counts `vertices faces edges`, found no {what} count"),
            )
        })?;
        word.parse::<u32>().map(|n| n as usize).map_err(|_| {
            (
                counts_line,
                format!("the {what} count `{word}` is not a whole number below 2^32"),
            )
        })
    };
    let vertices = count(0, "vertex")?;
    let faces = count(1, "face")?;
    Ok((
        variant,
        Counts {
            vertices,
            faces,
            line: counts_line,
        },
    ))
}

/// What the vertex lines hold.
struct VertexLines {
    positions: Vec<Point3<f64>>,
    /// The texture coordinates with the `ST` prefix; empty without.
    uvs: Vec<Vector2<f64>>,
}

/// Reads the vertex lines: the positions, and with the `ST` prefix the texture
/// coordinates (the last two numbers of each line; empty otherwise). At most `room`
/// entries are reserved ahead.
fn read_vertices(
    lines: &mut Lines,
    variant: Variant,
    counts: &Counts,
    room: usize,
) -> Result<VertexLines, Fail> {
    let vertex_count = counts.vertices;
    let mut positions = Vec::with_capacity(vertex_count.min(room));
    let mut uvs = Vec::with_capacity(if variant.texture {
        vertex_count.min(room)
    } else {
        0
    });
    for k in 0..vertex_count {
        let (line, content) = lines.next().ok_or_else(|| {
            (
                counts.line,
                format!("the header announces {vertex_count} vertices but the file ends after {k}"),
            )
        })?;
        let numbers = numbers(content).map_err(|message| (line, message))?;
        let least = if variant.texture { 5 } else { 3 };
        if numbers.len() < least {
            return Err((
                line,
                format!(
                    "vertex {k} has {} numbers, fewer than the {least} its line needs",
                    numbers.len()
                ),
            ));
        }
        positions.push(Point3::new(numbers[0], numbers[1], numbers[2]));
        if variant.texture {
            let n = numbers.len();
            uvs.push(Vector2::new(numbers[n - 2], numbers[n - 1]));
        }
    }
    Ok(VertexLines { positions, uvs })
}

/// Reads the face lines into `soup`; returns the line of each face. At most `room`
/// entries are reserved ahead.
fn read_faces(
    lines: &mut Lines,
    soup: &mut PolygonSoup,
    counts: &Counts,
    room: usize,
) -> Result<Vec<u32>, Fail> {
    let face_count = counts.faces;
    let mut face_lines = Vec::with_capacity(face_count.min(room));
    let mut face = Vec::new();
    for k in 0..face_count {
        let (line, content) = lines.next().ok_or_else(|| {
            (
                counts.line,
                format!("the header announces {face_count} faces but the file ends after {k}"),
            )
        })?;
        face.clear();
        face_indices(content, k, counts.vertices, &mut face).map_err(|message| (line, message))?;
        soup.push_face(&face);
        face_lines.push(line as u32);
    }
    Ok(face_lines)
}

/// Parses face `k`'s line `n i_1 .. i_n` (anything after is its color, skipped) and
/// appends the indices to `face`, or says what is wrong; `vertex_count` only words the
/// message.
fn face_indices(
    content: &str,
    k: usize,
    vertex_count: usize,
    face: &mut Vec<u32>,
) -> Result<(), String> {
    let mut words = content.split_ascii_whitespace();
    let size = words.next().unwrap_or("");
    let size: usize = size
        .parse()
        .map_err(|_| format!("face {k} starts with `{size}`, not a vertex count"))?;
    for j in 0..size {
        let word = words
            .next()
            .ok_or_else(|| format!("face {k} announces {size} vertices but lists {j}"))?;
        let index = word.parse::<u32>().map_err(|_| {
            format!(
                "face {k} refers to vertex `{word}`: indices are whole numbers 0..{vertex_count}"
            )
        })?;
        face.push(index);
    }
    Ok(())
}

/// The variant named by the header word, or why it is not one that is read.
fn variant(word: &str) -> Result<Variant, String> {
    let Some(prefix) = word.strip_suffix("OFF") else {
        return Err(format!(
            "the file starts with `{word}`, not with the header word OFF (or COFF, NOFF, STOFF, ...)"
        ));
    };
    let mut rest = prefix;
    let mut variant = Variant::default();
    if let Some(r) = rest.strip_prefix("ST") {
        variant.texture = true;
        rest = r;
    }
    for flag in ["C", "N"] {
        if let Some(r) = rest.strip_prefix(flag) {
            rest = r;
        }
    }
    match rest {
        "" => Ok(variant),
        r if r.contains('4') || r.contains('n') => Err(format!(
            "`{word}` is a homogeneous or n-dimensional OFF file; only 3D files are read"
        )),
        _ => Err(format!("`{word}` is not an OFF header word")),
    }
}

/// The numbers of a line, or a message naming the first word that is not one.
fn numbers(content: &str) -> Result<Vec<f64>, String> {
    content
        .split_ascii_whitespace()
        .map(|w| {
            w.parse::<f64>()
                .map_err(|_| format!("`{w}` is not a number"))
        })
        .collect()
}

/// Writes `mesh` as OFF (see the module docs for the variant written).
pub fn write(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
) -> Result<(), WriteError> {
    attributes.check(mesh)?;
    let slots = OutputSlots::new(mesh);
    let VertexValues {
        positions,
        uvs,
        colors,
    } = slots.vertex_values(mesh, attributes);
    super::write_atomically(path, |w| {
        let st = if uvs.is_some() { "ST" } else { "" };
        let c = if colors.is_some() { "C" } else { "" };
        writeln!(w, "{st}{c}OFF")?;
        writeln!(w, "{} {} 0", positions.len(), mesh.face_count())?;
        write_lines(w, positions.len(), |k, line| {
            let p = positions[k];
            write!(line, "{} {} {}", p.x, p.y, p.z)?;
            if let Some(colors) = &colors {
                let [r, g, b] = colors[k];
                write!(line, " {r} {g} {b} 1")?;
            }
            if let Some(uvs) = &uvs {
                write!(line, " {} {}", uvs[k].x, uvs[k].y)?;
            }
            writeln!(line)
        })?;
        write_lines(w, mesh.face_count(), |f, line| {
            let vertices = mesh.face_vertices(FaceId::from_usize(f));
            push_decimal(line, vertices.len());
            for v in vertices {
                line.push(b' ');
                push_decimal(line, slots.slot(v));
            }
            line.push(b'\n');
            Ok(())
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_corner_with_comments_counts_on_the_header_line_and_a_face_color() {
        let text = "OFF 4 2 0 # counts on the header line\n\
                    0 0 0\n1 0 0\n\n1 1 0\n0 1 0 # last vertex\n\
                    3 0 1 2 0.5 0.5 0.5\n3 0 2 3\n";
        let raw = parse(text.as_bytes()).unwrap();
        assert_eq!(raw.soup.vertex_count(), 4);
        assert_eq!(raw.soup.face(0), [0, 1, 2]);
        assert_eq!(raw.soup.face(1), [0, 2, 3]);
        assert_eq!(raw.soup.positions[2], Point3::new(1.0, 1.0, 0.0));
        assert_eq!(raw.face_lines, Some(vec![7, 8]));
        assert!(raw.corner_uvs.is_none());
    }

    #[test]
    fn stoff_texture_coordinates_come_last_on_the_vertex_line_after_a_color() {
        let text = "STCOFF\n3 1 0\n0 0 0 1 0 0 1 0.25 0.5\n1 0 0 0 1 0 1 0.75 0.5\n\
                    0 1 0 0 0 1 1 0.25 1\n3 2 0 1\n";
        let raw = parse(text.as_bytes()).unwrap();
        let uv = raw.corner_uvs.unwrap();
        assert_eq!(
            uv,
            [[0.25, 1.0], [0.25, 0.5], [0.75, 0.5]].map(Vector2::from)
        );
    }

    #[test]
    fn errors_name_the_line() {
        let cases: [(&str, usize, &str); 6] = [
            ("PLY\n", 1, "not with the header word OFF"),
            ("4OFF\n", 1, "homogeneous"),
            ("OFF\n3 x 0\n", 2, "face count `x`"),
            ("OFF\n3 1 0\n0 0 0\n1 0\n", 4, "vertex 1 has 2 numbers"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n",
                6,
                "vertex `-2`",
            ),
            (
                "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                2,
                "announces 2 faces",
            ),
        ];
        for (text, line, message) in cases {
            let (at, got) = parse(text.as_bytes()).unwrap_err();
            assert_eq!(at, FilePosition::Line(line), "{text:?}: {got}");
            assert!(got.contains(message), "{text:?}: {got}");
        }
    }
}
