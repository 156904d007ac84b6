//! PLY (the Stanford polygon file format), read and written by hand.
//!
//! Why not a crate: `ply-rs` (last release 2020) reads every element into a map from
//! property names to values, a hash map per vertex, and its errors carry no position;
//! what a mesh needs from PLY (three coordinates, two texture coordinates, a list of
//! vertex indices) is a small reader over the header's element descriptions, and it names
//! the line or byte of every error.
//!
//! # Reading
//!
//! All three encodings: `ascii`, `binary_little_endian` and `binary_big_endian`, with
//! every scalar type of the format (`char`/`int8` .. `double`/`float64`). The `vertex`
//! element gives the positions (`x`, `y`, `z`) and, when present, per-vertex texture
//! coordinates (`s t`, `u v`, `texture_u texture_v` or `texture_s texture_t`). The `face`
//! element gives the faces (the list `vertex_indices`, or `vertex_index`) and, when every
//! face has one, per-corner texture coordinates (MeshLab's list `texcoord`, two numbers per
//! corner), which win over per-vertex ones. Every other property and element is skipped.
//! ASCII values are read as written, as `f64`, whatever type the header declares.
//!
//! # Writing
//!
//! `binary_little_endian`: positions as `double` (they read back to the last bit),
//! texture coordinates as `double` `s t`, colors as `uchar` `red green blue`, faces as a
//! `uchar` count and `int` indices (`uint` when a mesh has more than 2^31 vertices).
//! Vertex `k` of the file is input vertex `k` whenever no vertices were merged (see
//! `super::slots`).

use std::io::Write as _;
use std::path::Path;

use nalgebra::{Point3, Vector2};

use super::slots::{OutputSlots, VertexValues};
use super::text::{Words, as_text};
use super::{FilePosition, Format, RawMesh, ReadError, VertexAttributes, WriteError};
use crate::{FaceId, Mesh, PolygonSoup};

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
    /// The type of a header's type name (both the original and the sized names).
    fn named(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Bytes per value in the binary encodings.
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

/// A property: one scalar, or a list of scalars preceded by its length.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

impl Element {
    fn property(&self, names: &[&str]) -> Option<usize> {
        names
            .iter()
            .find_map(|n| self.properties.iter().position(|p| p.name == *n))
    }

    /// The fewest bytes one element takes in `encoding`, to bound reservations by the
    /// file's size: each ASCII value takes a digit and a separator.
    fn least_bytes(&self, encoding: Encoding) -> usize {
        let sizes = self.properties.iter().map(|p| match (encoding, p.kind) {
            (Encoding::Ascii, _) => 2,
            (_, Kind::Scalar(s) | Kind::List { count: s, .. }) => s.size(),
        });
        sizes.sum::<usize>().max(1)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body: usize,
    /// 1-based line the body starts on (for ASCII files).
    body_line: usize,
}

/// A syntax error: where, and what is wrong.
type Fail = super::SyntaxError;

/// Reads a PLY file. See the module docs for what is kept.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    super::read_with(path, Format::Ply, parse)
}

/// Parses the bytes of a PLY file.
pub fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let header = header(bytes)?;
    let body = &bytes[header.body..];
    match header.encoding {
        Encoding::Ascii => {
            let text = as_text(body).map_err(|line| {
                (
                    FilePosition::Line(header.body_line + line - 1),
                    "the ASCII body is not UTF-8 text".to_string(),
                )
            })?;
            let mut values = Ascii {
                words: Words::new(text, header.body_line),
            };
            read_body(&header, body.len(), &mut values)
        }
        Encoding::LittleEndian | Encoding::BigEndian => {
            let mut values = Binary {
                bytes,
                at: header.body,
                big_endian: header.encoding == Encoding::BigEndian,
            };
            read_body(&header, body.len(), &mut values)
        }
    }
}

/// Parses the header: the lines from `ply` to `end_header`.
fn header(bytes: &[u8]) -> Result<Header, Fail> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut start = 0;
    let mut line = 0;
    loop {
        line += 1;
        let at = FilePosition::Line(line);
        let Some(length) = bytes[start..].iter().position(|&b| b == b'\n') else {
            return Err((at, "the header has no `end_header` line".into()));
        };
        let raw = &bytes[start..start + length];
        start += length + 1;
        let text = std::str::from_utf8(raw)
            .map_err(|_| (at, "the header is not text".to_string()))?
            .trim_ascii();
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        if line == 1 {
            if text != "ply" {
                return Err((at, "the file does not start with the line `ply`".into()));
            }
            continue;
        }
        match words.as_slice() {
            ["end_header"] => break,
            ["format", name, _version] => {
                encoding = Some(match *name {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::LittleEndian,
                    "binary_big_endian" => Encoding::BigEndian,
                    other => return Err((at, format!("unknown encoding `{other}`"))),
                });
            }
            ["comment" | "obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count
                    .parse::<u64>()
                    .ok()
                    .and_then(|c| usize::try_from(c).ok());
                let count = count.ok_or_else(|| {
                    (at, format!("the count of element `{name}` is not a number"))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| (at, "a property before any element".to_string()))?;
                let property = property(rest).map_err(|message| (at, message))?;
                element.properties.push(property);
            }
            _ => return Err((at, format!("unexpected header line `{text}`"))),
        }
    }
    let encoding = encoding.ok_or((
        FilePosition::Line(line),
        "the header has no `format` line".into(),
    ))?;
    Ok(Header {
        encoding,
        elements,
        body: start,
        body_line: line + 1,
    })
}

/// A `property` line's words after `property`.
fn property(words: &[&str]) -> Result<Property, String> {
    let scalar =
        |name: &str| Scalar::named(name).ok_or_else(|| format!("unknown property type `{name}`"));
    match words {
        ["list", count, item, name] => Ok(Property {
            name: name.to_string(),
            kind: Kind::List {
                count: scalar(count)?,
                item: scalar(item)?,
            },
        }),
        [ty, name] => Ok(Property {
            name: name.to_string(),
            kind: Kind::Scalar(scalar(ty)?),
        }),
        _ => Err(format!(
            "malformed property line `property {}`",
            words.join(" ")
        )),
    }
}

/// The values of a PLY body, in order.
trait Values {
    /// The next value, read as `ty`, or what is wrong with it.
    fn value(&mut self, ty: Scalar) -> Result<f64, String>;
    /// Where the last value read (or failed) is.
    fn position(&self) -> FilePosition;
    /// Skips `count` elements of `element`, which has only scalar properties.
    fn skip_scalars(&mut self, element: &Element, count: usize) -> Result<(), String> {
        for _ in 0..count {
            for p in &element.properties {
                if let Kind::Scalar(s) = p.kind {
                    self.value(s)?;
                }
            }
        }
        Ok(())
    }
}

struct Ascii<'a> {
    words: Words<'a>,
}

impl Values for Ascii<'_> {
    fn value(&mut self, _ty: Scalar) -> Result<f64, String> {
        let (_, word) = self.words.next().ok_or("the file ends")?;
        word.parse()
            .map_err(|_| format!("`{word}` is not a number"))
    }

    fn position(&self) -> FilePosition {
        FilePosition::Line(self.words.line())
    }
}

struct Binary<'a> {
    bytes: &'a [u8],
    at: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let bytes = self
            .bytes
            .get(self.at..self.at + N)
            .ok_or("the file ends")?;
        self.at += N;
        let mut out = [0; N];
        out.copy_from_slice(bytes);
        if self.big_endian {
            out.reverse();
        }
        Ok(out)
    }
}

impl Values for Binary<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64, String> {
        Ok(match ty {
            Scalar::I8 => i8::from_le_bytes(self.take()?) as f64,
            Scalar::U8 => u8::from_le_bytes(self.take()?) as f64,
            Scalar::I16 => i16::from_le_bytes(self.take()?) as f64,
            Scalar::U16 => u16::from_le_bytes(self.take()?) as f64,
            Scalar::I32 => i32::from_le_bytes(self.take()?) as f64,
            Scalar::U32 => u32::from_le_bytes(self.take()?) as f64,
            Scalar::F32 => f32::from_le_bytes(self.take()?) as f64,
            Scalar::F64 => f64::from_le_bytes(self.take()?),
        })
    }

    fn position(&self) -> FilePosition {
        FilePosition::Byte(self.at as u64)
    }

    fn skip_scalars(&mut self, element: &Element, count: usize) -> Result<(), String> {
        let size = element.least_bytes(Encoding::LittleEndian);
        let end = size
            .checked_mul(count)
            .and_then(|n| n.checked_add(self.at))
            .filter(|&end| end <= self.bytes.len())
            .ok_or("the file ends")?;
        self.at = end;
        Ok(())
    }
}

/// What a vertex property is used for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Coordinate(usize),
    Texture(usize),
    Skipped,
}

/// What the body's elements give.
#[derive(Default)]
struct Body {
    positions: Vec<Point3<f64>>,
    vertex_uvs: Option<Vec<Vector2<f64>>>,
    soup_faces: Vec<u32>,
    face_sizes: Vec<u32>,
    face_lines: Vec<u32>,
    /// Per-corner texture coordinates, while every face so far has them.
    corner_uvs: Option<Vec<Vector2<f64>>>,
}

/// Reads the body's elements in order.
fn read_body(
    header: &Header,
    body_bytes: usize,
    values: &mut impl Values,
) -> Result<RawMesh, Fail> {
    let mut body = Body::default();
    let mut has_vertices = false;
    let mut has_faces = false;
    for element in &header.elements {
        let room = element
            .count
            .min(body_bytes / element.least_bytes(header.encoding));
        let at_error = |values: &dyn Values, k: usize, message: String| {
            (
                values.position(),
                format!("{} {k}: {message}", element.name),
            )
        };
        match element.name.as_str() {
            "vertex" => {
                has_vertices = true;
                read_vertices(element, room, values, &mut body)
                    .map_err(|(k, m)| at_error(values, k, m))?;
            }
            "face" => {
                has_faces = true;
                read_faces(element, header.encoding, room, values, &mut body)
                    .map_err(|(k, m)| at_error(values, k, m))?;
            }
            _ if element
                .properties
                .iter()
                .all(|p| matches!(p.kind, Kind::Scalar(_))) =>
            {
                values
                    .skip_scalars(element, element.count)
                    .map_err(|m| at_error(values, 0, m))?;
            }
            _ => {
                for k in 0..element.count {
                    for p in &element.properties {
                        skip(values, p.kind).map_err(|m| at_error(values, k, m))?;
                    }
                }
            }
        }
    }
    let end = FilePosition::Line(1);
    if !has_vertices {
        return Err((end, "the header declares no `vertex` element".into()));
    }
    if !has_faces {
        return Err((
            end,
            "the header declares no `face` element (a point cloud is not a mesh)".into(),
        ));
    }
    let mut soup = PolygonSoup::new(body.positions);
    soup.reserve(body.face_sizes.len(), body.soup_faces.len());
    let mut start = 0;
    for &n in &body.face_sizes {
        soup.push_face(&body.soup_faces[start..start + n as usize]);
        start += n as usize;
    }
    let corner_uvs = body.corner_uvs.or_else(|| {
        body.vertex_uvs.map(|uv| {
            body.soup_faces
                .iter()
                .map(|&v| uv.get(v as usize).copied().unwrap_or_default())
                .collect()
        })
    });
    Ok(RawMesh {
        soup,
        corner_uvs,
        face_lines: (header.encoding == Encoding::Ascii).then_some(body.face_lines),
        weld: None,
        obj_groups: Vec::new(),
    })
}

/// Reads past one property's values.
fn skip(values: &mut impl Values, kind: Kind) -> Result<(), String> {
    match kind {
        Kind::Scalar(s) => values.value(s).map(drop),
        Kind::List { count, item } => {
            let n = list_length(values.value(count)?)?;
            (0..n).try_for_each(|_| values.value(item).map(drop))
        }
    }
}

/// A list's length as read.
fn list_length(value: f64) -> Result<usize, String> {
    if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
        Ok(value as usize)
    } else {
        Err(format!("a list length of {value}"))
    }
}

/// An element's failure: its index and what is wrong.
type ElementFail = (usize, String);

fn read_vertices(
    element: &Element,
    room: usize,
    values: &mut impl Values,
    body: &mut Body,
) -> Result<(), ElementFail> {
    if element.count > u32::MAX as usize {
        return Err((0, format!("{} vertices are more than 2^32", element.count)));
    }
    let mut roles = vec![Role::Skipped; element.properties.len()];
    for (c, name) in ["x", "y", "z"].into_iter().enumerate() {
        let p = element
            .property(&[name])
            .filter(|&p| matches!(element.properties[p].kind, Kind::Scalar(_)))
            .ok_or((0, format!("the element has no scalar property `{name}`")))?;
        roles[p] = Role::Coordinate(c);
    }
    let pairs = [
        ("s", "t"),
        ("u", "v"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ];
    let texture = pairs
        .iter()
        .find_map(|(u, v)| Some((element.property(&[u])?, element.property(&[v])?)));
    if let Some((u, v)) = texture {
        roles[u] = Role::Texture(0);
        roles[v] = Role::Texture(1);
        body.vertex_uvs = Some(Vec::with_capacity(room));
    }
    body.positions.reserve(room);
    for k in 0..element.count {
        let mut xyz = [0.0; 3];
        let mut st = [0.0; 2];
        for (p, role) in element.properties.iter().zip(&roles) {
            match (p.kind, role) {
                (Kind::Scalar(s), Role::Coordinate(c)) => {
                    xyz[*c] = values.value(s).map_err(|m| (k, m))?
                }
                (Kind::Scalar(s), Role::Texture(c)) => {
                    st[*c] = values.value(s).map_err(|m| (k, m))?
                }
                (kind, _) => skip(values, kind).map_err(|m| (k, m))?,
            }
        }
        body.positions.push(Point3::from(xyz));
        if let Some(uv) = &mut body.vertex_uvs {
            uv.push(Vector2::from(st));
        }
    }
    Ok(())
}

fn read_faces(
    element: &Element,
    encoding: Encoding,
    room: usize,
    values: &mut impl Values,
    body: &mut Body,
) -> Result<(), ElementFail> {
    let list = |names: &[&str]| {
        element
            .property(names)
            .filter(|&p| matches!(element.properties[p].kind, Kind::List { .. }))
    };
    let indices = list(&["vertex_indices", "vertex_index"]).ok_or((
        0,
        "the element has no list property `vertex_indices`".to_string(),
    ))?;
    let texcoord = list(&["texcoord"]);
    if texcoord.is_some() {
        body.corner_uvs = Some(Vec::with_capacity(3 * room));
    }
    body.face_sizes.reserve(room);
    body.soup_faces.reserve(3 * room);
    let mut numbers = Vec::new();
    for k in 0..element.count {
        let mut size = None;
        for (p, property) in element.properties.iter().enumerate() {
            let Kind::List { count, item } = property.kind else {
                skip(values, property.kind).map_err(|m| (k, m))?;
                continue;
            };
            if p != indices && Some(p) != texcoord {
                skip(values, property.kind).map_err(|m| (k, m))?;
                continue;
            }
            let n = list_length(values.value(count).map_err(|m| (k, m))?).map_err(|m| (k, m))?;
            numbers.clear();
            for _ in 0..n {
                numbers.push(values.value(item).map_err(|m| (k, m))?);
            }
            if p == indices {
                for &index in &numbers {
                    if !(index >= 0.0 && index.fract() == 0.0 && index <= u32::MAX as f64) {
                        return Err((k, format!("refers to vertex `{index}`, not a vertex index")));
                    }
                    body.soup_faces.push(index as u32);
                }
                size = Some(n);
            } else if let Some(uv) = &mut body.corner_uvs {
                uv.extend(numbers.chunks_exact(2).map(|c| Vector2::new(c[0], c[1])));
            }
        }
        body.face_sizes.push(size.unwrap_or(0) as u32);
        // A face whose `texcoord` list has not two numbers per corner: the file has no
        // per-corner texture coordinates.
        if body
            .corner_uvs
            .as_ref()
            .is_some_and(|uv| uv.len() != body.soup_faces.len())
        {
            body.corner_uvs = None;
        }
        if let (Encoding::Ascii, FilePosition::Line(line)) = (encoding, values.position()) {
            body.face_lines.push(line as u32);
        }
    }
    Ok(())
}

/// Writes `mesh` as binary little-endian PLY (see the module docs).
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
    let index_type = if slots.len() <= i32::MAX as usize {
        "int"
    } else {
        "uint"
    };
    super::write_atomically(path, |w| {
        writeln!(w, "ply\nformat binary_little_endian 1.0")?;
        writeln!(
            w,
            "comment beltrami: {} vertices, {} faces",
            slots.len(),
            mesh.face_count()
        )?;
        writeln!(w, "element vertex {}", slots.len())?;
        writeln!(w, "property double x\nproperty double y\nproperty double z")?;
        if uvs.is_some() {
            writeln!(w, "property double s\nproperty double t")?;
        }
        if colors.is_some() {
            writeln!(
                w,
                "property uchar red\nproperty uchar green\nproperty uchar blue"
            )?;
        }
        writeln!(w, "element face {}", mesh.face_count())?;
        writeln!(
            w,
            "property list uchar {index_type} vertex_indices\nend_header"
        )?;
        for (k, p) in positions.iter().enumerate() {
            for c in [p.x, p.y, p.z] {
                w.write_all(&c.to_le_bytes())?;
            }
            if let Some(uvs) = &uvs {
                w.write_all(&uvs[k].x.to_le_bytes())?;
                w.write_all(&uvs[k].y.to_le_bytes())?;
            }
            if let Some(colors) = &colors {
                w.write_all(&colors[k].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))?;
            }
        }
        for f in 0..mesh.face_count() {
            let vertices = mesh.face_vertices(FaceId::from_usize(f));
            w.write_all(&[vertices.len() as u8])?;
            for v in vertices {
                w.write_all(&(slots.slot(v) as u32).to_le_bytes())?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRIANGLE_HEADER: &str = "element vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    /// A binary file of one triangle in the given byte order.
    fn binary_triangle(big_endian: bool) -> Vec<u8> {
        let name = if big_endian { "big" } else { "little" };
        let mut bytes =
            format!("ply\nformat binary_{name}_endian 1.0\n{TRIANGLE_HEADER}").into_bytes();
        for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5] {
            bytes.extend(if big_endian {
                c.to_be_bytes()
            } else {
                c.to_le_bytes()
            });
        }
        bytes.push(3);
        for i in [0i32, 1, 2] {
            bytes.extend(if big_endian {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
        bytes
    }

    #[test]
    fn the_three_encodings_give_the_same_triangle() {
        let ascii = format!(
            "ply\nformat ascii 1.0\ncomment hi\n{TRIANGLE_HEADER}0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n"
        );
        let expected = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]].map(Point3::from);
        for bytes in [
            ascii.into_bytes(),
            binary_triangle(false),
            binary_triangle(true),
        ] {
            let raw = parse(&bytes).unwrap();
            assert_eq!(raw.soup.positions, expected);
            assert_eq!(raw.soup.face(0), [0, 1, 2]);
        }
    }

    #[test]
    fn other_properties_and_elements_are_skipped_and_texture_coordinates_kept() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty list uchar float junk\n\
            property double x\nproperty double y\nproperty double z\nproperty float s\n\
            property float t\nproperty uchar red\nelement edge 1\nproperty int a\n\
            element face 1\nproperty int flags\nproperty list uchar uint vertex_index\n\
            property list int float other\nend_header\n\
            2 9 9 0 0 0 0.1 0.2 255\n0 1 0 0 0.3 0.4 0\n1 9 0 1 0 0.5 0.6 7\n\
            5\n\
            7 3 2 1 0 1 4.5\n";
        let raw = parse(text.as_bytes()).unwrap();
        assert_eq!(raw.soup.positions[1], Point3::new(1.0, 0.0, 0.0));
        assert_eq!(raw.soup.face(0), [2, 1, 0]);
        assert_eq!(raw.face_lines, Some(vec![22]));
        // ASCII values are read as written (f64), whatever type the header declares.
        let uv = raw.corner_uvs.unwrap();
        assert_eq!(uv, [[0.5, 0.6], [0.3, 0.4], [0.1, 0.2]].map(Vector2::from));
    }

    #[test]
    fn per_corner_texcoord_lists_win_over_vertex_coordinates() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
            property float z\nproperty float u\nproperty float v\nelement face 1\n\
            property list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n\
            0 0 0 9 9\n1 0 0 9 9\n0 1 0 9 9\n3 0 1 2 6 0 0 1 0 0 1\n";
        let uv = parse(text.as_bytes()).unwrap().corner_uvs.unwrap();
        assert_eq!(uv, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]].map(Vector2::from));
    }

    #[test]
    fn errors_name_the_line_or_the_byte() {
        let mut truncated = binary_triangle(false);
        truncated.truncate(truncated.len() - 2);
        let header_len = truncated.len() - 36 - 1 - 10;
        let (at, message) = parse(&truncated).unwrap_err();
        assert_eq!(
            at,
            FilePosition::Byte((header_len + 36 + 1 + 8) as u64),
            "{message}"
        );
        assert!(message.contains("face 0: the file ends"), "{message}");

        let cases: [(&str, usize, &str); 5] = [
            ("PLY\n", 1, "does not start with the line `ply`"),
            (
                "ply\nformat ascii 1.0\nelement vertex x\n",
                3,
                "count of element `vertex`",
            ),
            (
                "ply\nformat ascii 1.0\nproperty float x\n",
                3,
                "before any element",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                5,
                "no `end_header`",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
              property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
              0 0 0\n3 0 -1 2\n",
                11,
                "face 0: refers to vertex `-1`",
            ),
        ];
        for (text, line, expected) in cases {
            let (at, message) = parse(text.as_bytes()).unwrap_err();
            assert_eq!(at, FilePosition::Line(line), "{text:?}: {message}");
            assert!(message.contains(expected), "{text:?}: {message}");
        }
    }

    #[test]
    fn a_huge_declared_count_fails_at_the_end_of_the_file_without_a_huge_reservation() {
        let text = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\n\
             property double y\nproperty double z\nelement face 0\n\
             property list uchar int vertex_indices\nend_header\n",
            u32::MAX
        );
        let (_, message) = parse(text.as_bytes()).unwrap_err();
        assert!(message.contains("vertex 0: the file ends"), "{message}");
    }
}
