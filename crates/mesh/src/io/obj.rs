//! Wavefront OBJ: reading through `tobj`, writing by hand.
//!
//! # Reading
//!
//! Only `v`, `vt` and `f` lines make the mesh; normals, points and polylines are
//! ignored. Objects, groups, smoothing groups, materials and material libraries (`o`,
//! `g`, `s`, `usemtl`, `mtllib`) are kept as text with the face they stand before
//! ([`RawMesh::obj_groups`]) and written back before it by [`write_with_sections`]. Faces keep their vertex count (no
//! triangulation), so triangles and quads come through as they are and other polygons
//! are rejected by the mesh builder with their face index and line.
//!
//! `tobj` numbers vertices in the order faces first use them, and starts a new index
//! space at every `o`/`g`/`usemtl` line. To keep the file's own numbering, the reader
//! drops those lines and puts in front of the file a single face that lists every `v` in
//! order: first use is then file order. That face is removed from the result. A file
//! with nothing to drop (only `v`, `vt`, `f`, blank lines and comments) reaches tobj
//! behind that face without being copied.
//!
//! Positions are read as `f64` (tobj's `use_f64` feature). Texture coordinates are kept
//! per face corner when every face corner names one.
//!
//! A plain file, only `v x y z` and `f a b c ...` lines with vertex indices (and blank
//! lines and comments), is read without tobj, into the same soup: tobj keeps a record per
//! face and a hash map of face corners, which cost 255 MB and 0.8 s for a 44 MB file of
//! 1M triangles. Anything else (texture or normal indices, other lines, a number that
//! does not parse, an index to a vertex not yet listed) goes to tobj, which also words
//! the errors.

use std::io::{Read as _, Write as _};
use std::path::Path;

use nalgebra::{Point3, Vector2};

use super::slots::OutputSlots;
use super::{RawMesh, ReadError, VertexAttributes, WriteError};
use crate::parallel::{available_threads, map_blocks};
use crate::{FaceId, Mesh, PolygonSoup};

/// Reads an OBJ file. See the module docs for what is kept.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    let bytes = super::source::read_bytes(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(path, &bytes)
}

/// What the first pass over the file found.
struct Prepared {
    /// The face that lists every vertex, which tobj reads first.
    prefix: Vec<u8>,
    /// The lines tobj should read after the prefix, when the file has lines to leave
    /// out (anything but `v`, `vt`, `f`, blank lines and comments); `None` when tobj
    /// can read the file as it is.
    kept: Option<Vec<u8>>,
    vertex_count: usize,
    /// 1-based line of every face.
    face_lines: Vec<u32>,
    /// Whether every corner of every face names a texture coordinate.
    all_corners_have_uv: bool,
    /// The first `vt` line with a NaN or infinite coordinate: its 1-based line, its
    /// 0-based texture coordinate index and its two values.
    non_finite_uv: Option<(usize, usize, f64, f64)>,
    /// The grouping lines before faces ([`RawMesh::obj_groups`]).
    groups: Vec<(u32, String)>,
}

/// Whether a line's first token starts a grouping line kept for output: objects, groups,
/// smoothing groups, materials and material libraries.
fn is_grouping(token: &[u8]) -> bool {
    matches!(token, b"o" | b"g" | b"s" | b"usemtl" | b"mtllib")
}

/// The first two numbers of a `vt` line, when both parse.
fn texcoord(line: &[u8]) -> Option<(f64, f64)> {
    let text = std::str::from_utf8(line).ok()?;
    let mut tokens = text.split_whitespace().skip(1);
    let u = tokens.next()?.parse().ok()?;
    let v = tokens.next()?.parse().ok()?;
    Some((u, v))
}

fn first_token(line: &[u8]) -> &[u8] {
    let line = line.trim_ascii_start();
    let end = line
        .iter()
        .position(|c| c.is_ascii_whitespace())
        .unwrap_or(line.len());
    &line[..end]
}

/// A face corner token `v`, `v/vt`, `v/vt/vn` or `v//vn` names a texture coordinate when
/// its second field is present and non-empty.
fn corner_has_uv(token: &[u8]) -> bool {
    let mut parts = token.split(|&c| c == b'/');
    parts.next();
    parts.next().is_some_and(|vt| !vt.is_empty())
}

/// The face `f 1 2 ... n` listing `n` vertices (nothing for none).
fn listing_face(n: usize) -> Vec<u8> {
    let mut face = Vec::with_capacity(8 * n + 2);
    if n > 0 {
        face.push(b'f');
        for i in 1..=n {
            face.push(b' ');
            face.extend_from_slice(i.to_string().as_bytes());
        }
        face.push(b'\n');
    }
    face
}

fn prepare(bytes: &[u8]) -> Prepared {
    let mut vertex_count = 0;
    let mut kept: Option<Vec<u8>> = None;
    let mut face_lines = Vec::new();
    let mut all_corners_have_uv = true;
    let mut non_finite_uv = None;
    let mut texcoords = 0usize;
    let mut groups: Vec<(u32, String)> = Vec::new();
    let mut pending = String::new();
    let mut start = 0;
    for (i, line) in bytes.split(|&c| c == b'\n').enumerate() {
        let token = first_token(line);
        if is_grouping(token) {
            pending.push_str(String::from_utf8_lossy(line.trim_ascii()).as_ref());
            pending.push('\n');
        }
        let keep = match token {
            b"v" => {
                vertex_count += 1;
                true
            }
            b"vt" => {
                if let Some((u, v)) = texcoord(line)
                    && !(u.is_finite() && v.is_finite())
                    && non_finite_uv.is_none()
                {
                    non_finite_uv = Some((i + 1, texcoords, u, v));
                }
                texcoords += 1;
                true
            }
            b"f" => {
                if !pending.is_empty() {
                    groups.push((face_lines.len() as u32, std::mem::take(&mut pending)));
                }
                face_lines.push((i + 1) as u32);
                all_corners_have_uv &= line
                    .trim_ascii()
                    .split(|c| c.is_ascii_whitespace())
                    .filter(|t| !t.is_empty())
                    .skip(1)
                    .all(corner_has_uv);
                true
            }
            _ => false,
        };
        if let Some(text) = &mut kept {
            if keep {
                text.extend_from_slice(line);
                text.push(b'\n');
            }
        } else if !keep && !token.is_empty() && !token.starts_with(b"#") {
            // The first line tobj must not see: from here on the lines are copied.
            kept = Some(bytes[..start].to_vec());
        }
        start += line.len() + 1;
    }
    Prepared {
        prefix: listing_face(vertex_count),
        kept,
        vertex_count,
        face_lines,
        all_corners_have_uv,
        non_finite_uv,
        groups,
    }
}

/// Parses OBJ text held in memory; `path` only names the file in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<RawMesh, ReadError> {
    if let Some((soup, face_lines)) = parse_plain(bytes) {
        return Ok(RawMesh {
            soup,
            corner_uvs: None,
            face_lines: Some(face_lines),
            weld: None,
            obj_groups: Vec::new(),
        });
    }
    let prepared = prepare(bytes);
    if let Some((line, index, u, v)) = prepared.non_finite_uv {
        return Err(ReadError::NonFiniteTexCoord {
            path: path.to_path_buf(),
            line: Some(line),
            what: "texture coordinate",
            index,
            u,
            v,
        });
    }
    parse_with_tobj(path, bytes, prepared)
}

/// [`parse`] through tobj, after the first pass.
fn parse_with_tobj(path: &Path, bytes: &[u8], prepared: Prepared) -> Result<RawMesh, ReadError> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: false,
        ignore_lines: false,
    };
    let body = prepared.kept.as_deref().unwrap_or(bytes);
    let loaded = tobj::load_obj_buf(
        &mut prepared.prefix.as_slice().chain(body),
        &options,
        |_| Ok(Default::default()),
    );
    let models = match loaded {
        Ok((models, _)) => models,
        Err(e) => return Err(locate_tobj_error(path, bytes, e, &prepared)),
    };
    let n = prepared.vertex_count;
    let Some(model) = models.into_iter().next() else {
        // No vertices and no faces at all.
        return Ok(RawMesh {
            soup: PolygonSoup::new(Vec::new()),
            corner_uvs: None,
            face_lines: Some(prepared.face_lines),
            weld: None,
            obj_groups: Vec::new(),
        });
    };
    let m = model.mesh;
    let positions: Vec<Point3<f64>> = m
        .positions
        .chunks_exact(3)
        .map(|p| Point3::new(p[0], p[1], p[2]))
        .collect();
    if positions.len() != n {
        return Err(ReadError::Obj {
            path: path.to_path_buf(),
            line: None,
            message: format!(
                "read {} vertex positions but the file has {n} `v` lines",
                positions.len()
            ),
        });
    }
    // An empty arity list means every face is a triangle.
    let arities: Vec<u32> = if m.face_arities.is_empty() {
        vec![3; m.indices.len() / 3]
    } else {
        m.face_arities
    };
    let (&prefix, arities) = arities.split_first().unwrap_or((&0, &[]));
    let prefix = prefix as usize;
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(arities.len(), m.indices.len() - prefix);
    let mut at = prefix;
    for &k in arities {
        let k = k as usize;
        soup.push_face(&m.indices[at..at + k]);
        at += k;
    }
    let corner_uvs = (prepared.all_corners_have_uv
        && !m.texcoords.is_empty()
        && m.texcoord_indices.len() == m.indices.len())
    .then(|| {
        m.texcoord_indices[prefix..]
            .iter()
            .map(|&t| {
                let t = t as usize;
                Vector2::new(m.texcoords[2 * t], m.texcoords[2 * t + 1])
            })
            .collect()
    });
    Ok(RawMesh {
        soup,
        corner_uvs,
        face_lines: Some(prepared.face_lines),
        weld: None,
        obj_groups: prepared.groups,
    })
}

/// The positions and faces of a plain OBJ file, read without tobj, with the 1-based line
/// of every face: every line is blank, a comment, `v x y z` (three numbers) or
/// `f a b c ...` (at least three vertex indices, 1-based or negative relative to the `v`
/// lines before it, no `/`). `None` as soon as a line is anything else, or names a
/// vertex not yet listed: tobj then reads the file and words any error. tobj's
/// generality costs on large files (per-face records and a hash map of corners: 255 MB
/// and 0.8 s for a 44 MB file of 1M triangles); the values are the same (both parse
/// numbers with the standard library's correctly rounded parser).
///
/// A large file is read in parts, one per core, cut after line breaks
/// ([`parse_plain_part`]); the parts are joined in order. A negative index after the
/// first part needs the count of vertices listed before its part: then the whole file is
/// read again in one part.
fn parse_plain(bytes: &[u8]) -> Option<(PolygonSoup, Vec<u32>)> {
    parse_plain_in_parts(bytes, &plain_parts(bytes, available_threads()))
}

/// [`parse_plain`] with `bytes` cut into `parts` (consecutive byte ranges covering it,
/// each but the last ending with a line break), read at once.
fn parse_plain_in_parts(
    bytes: &[u8],
    parts: &[std::ops::Range<usize>],
) -> Option<(PolygonSoup, Vec<u32>)> {
    let read = map_blocks(parts.len(), 1, parts.len(), |k| {
        let k = k.start;
        parse_plain_part(&bytes[parts[k].clone()], (k == 0).then_some(0))
    });
    let mut joined: Option<(PolygonSoup, Vec<u32>)> = None;
    let mut lines = 0u32;
    for part in read {
        let part = match part {
            PlainPart::Read(part) => part,
            PlainPart::NotPlain => return None,
            PlainPart::Relative => {
                return match parse_plain_part(bytes, Some(0)) {
                    PlainPart::Read(whole) => Some((whole.soup, whole.face_lines)),
                    PlainPart::NotPlain | PlainPart::Relative => None,
                };
            }
        };
        let listed = joined.as_ref().map_or(0, |(soup, _)| soup.vertex_count());
        if part.reach > listed {
            return None;
        }
        let face_lines = part
            .face_lines
            .iter()
            .map(|&line| line.checked_add(lines))
            .collect::<Option<Vec<u32>>>()?;
        lines = lines.checked_add(part.newlines)?;
        match &mut joined {
            None => joined = Some((part.soup, face_lines)),
            Some((soup, all_lines)) => {
                soup.append(part.soup);
                all_lines.extend(face_lines);
            }
        }
    }
    joined
}

/// Bytes of a plain OBJ file per part read at once ([`parse_plain`]), at least: below,
/// a thread costs more than it saves.
const PLAIN_PART_BYTES: usize = 1 << 20;

/// The byte ranges of the parts of `bytes` read at once: at most `threads`, each at
/// least [`PLAIN_PART_BYTES`] long but the last, each but the last ending with a line
/// break.
fn plain_parts(bytes: &[u8], threads: usize) -> Vec<std::ops::Range<usize>> {
    let count = threads.min(bytes.len() / PLAIN_PART_BYTES).max(1);
    let mut parts = Vec::with_capacity(count);
    let mut start = 0;
    for k in 1..count {
        let cut = (k * bytes.len() / count).max(start);
        let Some(end) = bytes[cut..].iter().position(|&c| c == b'\n') else {
            break;
        };
        parts.push(start..cut + end + 1);
        start = cut + end + 1;
    }
    parts.push(start..bytes.len());
    parts
}

/// How a part of a plain OBJ file read ([`parse_plain_part`]).
enum PlainPart {
    Read(PlainRead),
    /// A line that is not plain, or an index that cannot name a vertex listed before it.
    NotPlain,
    /// A negative index in a part whose count of vertices listed before it is unknown.
    Relative,
}

/// The content of a part of a plain OBJ file.
struct PlainRead {
    /// Its positions, and its faces with 0-based indices into the whole file's vertices.
    soup: PolygonSoup,
    /// The line of each face, counted from the part's first line (line 1).
    face_lines: Vec<u32>,
    /// The line breaks in the part: the first line of the next part is `newlines + 1`.
    newlines: u32,
    /// The most vertices that must be listed before the part for its faces to name
    /// vertices listed before them (0 when they all name the part's own).
    reach: usize,
}

/// Reads `bytes`, a run of whole lines of a plain OBJ file ([`parse_plain`]), with
/// `listed_before` vertices listed before it when known (`Some(0)` for the first part):
/// a positive index `i` names vertex `i - 1` of the file, a negative one counts back
/// from the last vertex listed (and needs `listed_before`).
fn parse_plain_part(bytes: &[u8], listed_before: Option<usize>) -> PlainPart {
    let mut soup = PolygonSoup::new(Vec::new());
    let mut face_lines = Vec::new();
    let mut corners: Vec<u32> = Vec::with_capacity(4);
    let mut reach = 0;
    let mut newlines = 0;
    for (i, line) in bytes.split(|&c| c == b'\n').enumerate() {
        newlines = i;
        let mut tokens = line
            .split(|c| c.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        match tokens.next() {
            None => {}
            Some(t) if t.starts_with(b"#") => {}
            Some(b"v") => {
                let mut p = [0.0; 3];
                for x in &mut p {
                    let Some(value) = plain_number(tokens.next()) else {
                        return PlainPart::NotPlain;
                    };
                    *x = value;
                }
                if tokens.next().is_some() {
                    return PlainPart::NotPlain;
                }
                soup.positions.push(Point3::new(p[0], p[1], p[2]));
            }
            Some(b"f") => {
                corners.clear();
                let listed = soup.positions.len();
                for token in tokens {
                    let Some(index) = plain_number::<i64>(Some(token)) else {
                        return PlainPart::NotPlain;
                    };
                    let vertex = if index > 0 {
                        let index = index as usize;
                        reach = reach.max(index.saturating_sub(listed));
                        index - 1
                    } else if index < 0 {
                        let Some(before) = listed_before else {
                            return PlainPart::Relative;
                        };
                        match (before + listed).checked_sub(index.unsigned_abs() as usize) {
                            Some(vertex) => vertex,
                            None => return PlainPart::NotPlain,
                        }
                    } else {
                        return PlainPart::NotPlain;
                    };
                    let Ok(vertex) = u32::try_from(vertex) else {
                        return PlainPart::NotPlain;
                    };
                    corners.push(vertex);
                }
                if corners.len() < 3 {
                    return PlainPart::NotPlain;
                }
                soup.push_face(&corners);
                let Ok(line) = u32::try_from(i + 1) else {
                    return PlainPart::NotPlain;
                };
                face_lines.push(line);
            }
            Some(_) => return PlainPart::NotPlain,
        }
    }
    if listed_before.is_some_and(|before| reach > before) {
        return PlainPart::NotPlain;
    }
    let Ok(newlines) = u32::try_from(newlines) else {
        return PlainPart::NotPlain;
    };
    PlainPart::Read(PlainRead {
        soup,
        face_lines,
        newlines,
        reach,
    })
}

/// A token of a plain OBJ file read as a number (`None` when absent or not one).
fn plain_number<T: std::str::FromStr>(token: Option<&[u8]>) -> Option<T> {
    std::str::from_utf8(token?).ok()?.parse().ok()
}

/// tobj's errors carry no line number: find the first line that explains the error.
fn locate_tobj_error(
    path: &Path,
    bytes: &[u8],
    error: tobj::LoadError,
    prepared: &Prepared,
) -> ReadError {
    let path = path.to_path_buf();
    let mut positions = 0usize;
    let mut texcoords = 0usize;
    let mut face = 0usize;
    for (i, raw) in bytes.split(|&c| c == b'\n').enumerate() {
        let line = String::from_utf8_lossy(raw);
        let mut tokens = line.split_whitespace();
        let kind = tokens.next().unwrap_or("");
        let at = Some(i + 1);
        let bad = |message: String| ReadError::Obj {
            path: path.clone(),
            line: at,
            message,
        };
        match kind {
            "v" => {
                let coords: Vec<&str> = tokens.collect();
                if coords.len() < 3 || coords[..3].iter().any(|t| t.parse::<f64>().is_err()) {
                    return bad(format!(
                        "cannot read a vertex position from `{}`",
                        line.trim()
                    ));
                }
                positions += 1;
            }
            "vt" => {
                let coords: Vec<&str> = tokens.collect();
                if coords.len() < 2 || coords[..2].iter().any(|t| t.parse::<f64>().is_err()) {
                    return bad(format!(
                        "cannot read a texture coordinate from `{}`",
                        line.trim()
                    ));
                }
                texcoords += 1;
            }
            "f" => {
                for token in tokens {
                    let mut fields = token.split('/');
                    let resolve = |field: Option<&str>, count: usize| -> Result<Option<i64>, ()> {
                        match field {
                            None | Some("") => Ok(None),
                            Some(s) => {
                                let x: i64 = s.parse().map_err(|_| ())?;
                                Ok(Some(if x < 0 { count as i64 + x } else { x - 1 }))
                            }
                        }
                    };
                    let written = token.split('/').next().unwrap_or("");
                    let (Ok(v), Ok(vt)) = (
                        resolve(fields.next(), positions),
                        resolve(fields.next(), texcoords),
                    ) else {
                        return bad(format!("cannot read face corner `{token}`"));
                    };
                    if v.is_some_and(|v| v < 0 || v as usize >= prepared.vertex_count) {
                        return ReadError::ObjVertexIndex {
                            path,
                            line: i + 1,
                            face,
                            written: written.to_string(),
                            vertex_count: prepared.vertex_count,
                            before: positions,
                        };
                    }
                    if vt.is_some_and(|t| t < 0 || t as usize >= texcoords) {
                        return bad(format!(
                            "face corner `{token}` refers to a missing texture coordinate"
                        ));
                    }
                }
                face += 1;
            }
            _ => {}
        }
    }
    ReadError::Obj {
        path,
        line: None,
        message: format!("cannot parse OBJ: {error}"),
    }
}

/// Writes `mesh` as OBJ: `v` lines (the mesh's positions, or `attributes.positions`),
/// one `vt` per vertex with the same indexing when `attributes.uvs` is given, then the
/// faces. Vertices are written in input order, unreferenced ones included, whenever the
/// mesh's vertex map preserves order (see [`crate::VertexMap::is_order_preserving`]), so
/// vertex `k` of the output is vertex `k` of the file the mesh was read from.
pub fn write(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
) -> Result<(), WriteError> {
    write_with_sections(path, mesh, attributes, None)
}

/// [`write()`], taking the text of the sections that do not depend on the map from
/// `sections` when they fit `attributes` (formatted earlier by
/// [`MeshSections::format`] for the same mesh: the `v` lines when `attributes` keeps the
/// mesh's own positions, the `f` lines when the texture-coordinate indices agree);
/// what does not fit is formatted here. The file is the same byte for byte either way.
pub fn write_with_sections(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
    sections: Option<&MeshSections>,
) -> Result<(), WriteError> {
    attributes.check(mesh)?;
    let slots = OutputSlots::new(mesh);
    let with_uvs = attributes.uvs.is_some();
    let ready = sections.filter(|s| s.faces_len == mesh.face_count() && s.slots == slots.len());
    let vertices = ready.filter(|_| attributes.positions.is_none());
    let faces = ready.filter(|s| s.with_uvs == with_uvs && attributes.obj_groups.is_empty());
    let groups = groups_before_faces(mesh, attributes.obj_groups);
    let position = match vertices {
        Some(_) => Vec::new(),
        None => slots.positions(mesh, attributes),
    };
    let uv = attributes.uvs.map(|u| slots.scatter(u));
    super::write_atomically(path, |w| {
        writeln!(w, "{}", header(&slots, mesh))?;
        match vertices {
            Some(sections) => w.write_all(&sections.vertices)?,
            None => write_lines(w, position.len(), |i, line| vertex_line(&position[i], line))?,
        }
        if let Some(uv) = &uv {
            write_lines(w, uv.len(), |i, line| {
                writeln!(line, "vt {} {}", uv[i].x, uv[i].y)
            })?;
        }
        match faces {
            Some(sections) => w.write_all(&sections.faces),
            None => write_lines(w, mesh.face_count(), |i, line| {
                if let Some(text) = &groups[i] {
                    line.extend_from_slice(text.as_bytes());
                }
                face_line(mesh, &slots, with_uvs, i, line);
                Ok(())
            }),
        }
    })
}

/// Per mesh face, the grouping lines to write before it: those of its input face and of
/// the input faces the mesh dropped since the previous face it kept.
pub(super) fn groups_before_faces(mesh: &Mesh, groups: &[(u32, String)]) -> Vec<Option<String>> {
    let mut out = vec![None; mesh.face_count()];
    let mut next = groups.iter().peekable();
    for f in mesh.faces() {
        let input = mesh.face_to_input(f);
        let mut text = String::new();
        while let Some((_, lines)) = next.next_if(|(g, _)| *g as usize <= input) {
            text.push_str(lines);
        }
        if !text.is_empty() {
            out[f.idx()] = Some(text);
        }
    }
    out
}

/// The text of the `v` and `f` lines of a mesh's OBJ file, formatted before the map to
/// write with it is known (a solver runs meanwhile, mostly on one core), so that writing
/// the map then only formats its `vt` lines. Holds about 60 bytes per vertex and 30 per
/// face.
#[derive(Debug, Clone)]
pub struct MeshSections {
    /// Whether the `f` lines name texture coordinates (`f a/a b/b c/c`).
    with_uvs: bool,
    /// The mesh's face count and the file's vertex count, to recognize the mesh.
    faces_len: usize,
    slots: usize,
    /// `v` lines of the mesh's own positions.
    vertices: Vec<u8>,
    /// `f` lines.
    faces: Vec<u8>,
}

impl MeshSections {
    /// Formats the `v` lines of `mesh`'s positions and its `f` lines, with
    /// texture-coordinate indices when `with_uvs`, on the calling thread.
    pub fn format(mesh: &Mesh, with_uvs: bool) -> Self {
        let slots = OutputSlots::new(mesh);
        let position = slots.positions(mesh, &VertexAttributes::default());
        let mut vertices = Vec::new();
        for p in &position {
            // Writing into a vector cannot fail.
            let _ = vertex_line(p, &mut vertices);
        }
        let mut faces = Vec::new();
        for i in 0..mesh.face_count() {
            face_line(mesh, &slots, with_uvs, i, &mut faces);
        }
        Self {
            with_uvs,
            faces_len: mesh.face_count(),
            slots: slots.len(),
            vertices,
            faces,
        }
    }
}

/// The first line of every written file (without its line break).
fn header(slots: &OutputSlots, mesh: &Mesh) -> String {
    format!(
        "# beltrami: {} vertices, {} faces",
        slots.len(),
        mesh.face_count()
    )
}

/// Appends the `v` line of `p`.
pub(super) fn vertex_line(p: &Point3<f64>, line: &mut Vec<u8>) -> std::io::Result<()> {
    writeln!(line, "v {} {} {}", p.x, p.y, p.z)
}

/// Appends the `f` line of face `i`, each corner `k` or `k/k` (the vertex's slot + 1).
fn face_line(mesh: &Mesh, slots: &OutputSlots, with_uvs: bool, i: usize, line: &mut Vec<u8>) {
    line.push(b'f');
    for v in mesh.face_vertices(FaceId::from_usize(i)) {
        let k = slots.slot(v) + 1;
        line.push(b' ');
        push_decimal(line, k);
        if with_uvs {
            line.push(b'/');
            push_decimal(line, k);
        }
    }
    line.push(b'\n');
}

/// Appends the decimal digits of `k` (the formatting machinery of `write!` costs more
/// than the digits on face lines, a third of writing a large mesh).
pub(super) fn push_decimal(line: &mut Vec<u8>, mut k: usize) {
    let mut digits = [0u8; 20];
    let mut at = digits.len();
    loop {
        at -= 1;
        digits[at] = b'0' + (k % 10) as u8;
        k /= 10;
        if k == 0 {
            break;
        }
    }
    line.extend_from_slice(&digits[at..]);
}

/// Lines formatted per block by one thread.
const LINE_BLOCK: usize = 1 << 14;

/// Writes `count` lines in order, line `i` appended to a buffer by `line(i, buffer)`.
/// Formatting numbers is most of the cost of writing a large mesh (shortest round-trip
/// decimals), so consecutive blocks of lines are formatted on the available cores at
/// once and written in order; at most one block per core is held in memory.
pub(super) fn write_lines(
    w: &mut impl std::io::Write,
    count: usize,
    line: impl Fn(usize, &mut Vec<u8>) -> std::io::Result<()> + Sync,
) -> std::io::Result<()> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut buffers = vec![Vec::new(); threads.min(count.div_ceil(LINE_BLOCK)).max(1)];
    let format = |buffer: &mut Vec<u8>, begin: usize| {
        buffer.clear();
        (begin..(begin + LINE_BLOCK).min(count)).try_for_each(|i| line(i, buffer))
    };
    let mut start = 0;
    while start < count {
        if let [buffer] = buffers.as_mut_slice() {
            format(buffer, start)?;
        } else {
            std::thread::scope(|scope| {
                let formatting: Vec<_> = buffers
                    .iter_mut()
                    .enumerate()
                    .map(|(t, buffer)| {
                        let begin = start + t * LINE_BLOCK;
                        let format = &format;
                        scope.spawn(move || -> std::io::Result<()> {
                            buffer.clear();
                            if begin < count {
                                format(buffer, begin)?;
                            }
                            Ok(())
                        })
                    })
                    .collect();
                formatting.into_iter().try_for_each(|thread| {
                    thread
                        .join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                })
            })?;
        }
        for buffer in &buffers {
            w.write_all(buffer)?;
        }
        start += buffers.len() * LINE_BLOCK;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{LINE_BLOCK, MeshSections, push_decimal, write, write_lines, write_with_sections};
    use crate::Mesh;
    use crate::io::VertexAttributes;
    use crate::primitives::{Cells, grid};
    use nalgebra::{Point3, Vector2};

    #[test]
    fn sections_formatted_ahead_give_the_same_file_and_are_ignored_where_they_do_not_fit() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = Mesh::from_soup(&grid(7, 5, Cells::Triangles)).unwrap();
        let other = Mesh::from_soup(&grid(3, 3, Cells::Quads)).unwrap();
        let uvs: Vec<Vector2<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Vector2::new(0.3 * p.x + 0.1, p.y / 3.0))
            .collect();
        let moved: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(p.y, -p.x, 0.25 + p.x * p.y))
            .collect();
        let with_uvs = VertexAttributes {
            uvs: Some(&uvs),
            ..Default::default()
        };
        let with_positions = VertexAttributes {
            positions: Some(&moved),
            ..Default::default()
        };
        let plain = VertexAttributes::default();
        let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
        for (attributes, tag) in [
            (&with_uvs, "uv"),
            (&with_positions, "xyz"),
            (&plain, "plain"),
        ] {
            write(&dir.path().join(format!("{tag}.obj")), &mesh, attributes).unwrap();
            let expected = read(&format!("{tag}.obj"));
            // Sections of either kind, and sections of another mesh: same bytes.
            let kinds = [
                MeshSections::format(&mesh, true),
                MeshSections::format(&mesh, false),
                MeshSections::format(&other, true),
            ];
            for (k, sections) in kinds.iter().enumerate() {
                let name = format!("{tag}-{k}.obj");
                write_with_sections(&dir.path().join(&name), &mesh, attributes, Some(sections))
                    .unwrap();
                assert_eq!(read(&name), expected, "{name}");
            }
        }
        let text = String::from_utf8(read("uv.obj")).unwrap();
        assert!(text.contains("\nvt 0.1 0\n") && text.contains("\nf 1/1 2/2 "));
    }

    #[test]
    fn decimal_digits_match_display() {
        for k in [0, 7, 10, 99, 100, 123_456_789, usize::MAX] {
            let mut s = b"x".to_vec();
            push_decimal(&mut s, k);
            assert_eq!(s, format!("x{k}").into_bytes());
        }
    }

    #[test]
    fn lines_come_out_in_order_across_blocks() {
        // More lines than one block per core, and a last block cut short.
        let count = 5 * LINE_BLOCK + 17;
        let mut out = Vec::new();
        write_lines(&mut out, count, |i, line| {
            push_decimal(line, i);
            line.push(b'\n');
            Ok(())
        })
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<usize> = text.lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(lines, (0..count).collect::<Vec<_>>());
        let mut empty = Vec::new();
        write_lines(&mut empty, 0, |_, _| unreachable!()).unwrap();
        assert!(empty.is_empty());
    }
}

#[cfg(test)]
mod plain_tests {
    use super::{
        PLAIN_PART_BYTES, PlainPart, parse, parse_plain, parse_plain_in_parts, parse_plain_part,
        parse_with_tobj, plain_parts, prepare,
    };
    use crate::PolygonSoup;
    use std::path::Path;

    /// The soup through tobj, for files [`parse`] reads without it.
    fn through_tobj(bytes: &[u8]) -> PolygonSoup {
        parse_with_tobj(Path::new("test.obj"), bytes, prepare(bytes))
            .expect("tobj reads the file")
            .soup
    }

    fn assert_same(plain: &PolygonSoup, tobj: &PolygonSoup) {
        assert_eq!(plain.positions, tobj.positions);
        assert!(plain.faces().eq(tobj.faces()));
    }

    #[test]
    fn plain_files_read_as_through_tobj() {
        // Comments, blank lines, CRLF ends, leading blanks, negative indices, a quad, an
        // unused vertex and numbers in every notation.
        let text = b"# a plain file\r\nv 0 0 0\r\nv 1.5 0 -0.0\r\n\r\n  v 1 1e0 0.25\r\nv -2.5E-1 1 0\r\nv 3 3 3\r\nf 1 2 3\r\n# quad\r\nf -4 -3 -2 -1\r\nf 2 3 4\n";
        let raw = parse(Path::new("test.obj"), text).unwrap();
        assert_same(&raw.soup, &through_tobj(text));
        assert_eq!(raw.soup.face_count(), 3);
        assert_eq!(raw.soup.face(1), [1, 2, 3, 4]);
        assert_eq!(raw.face_lines, Some(vec![8, 10, 11]));
        assert!(raw.corner_uvs.is_none());
    }

    /// The ranges of `bytes` cut after the line breaks at the byte positions `cuts`.
    fn cut_after(bytes: &[u8], cuts: &[usize]) -> Vec<std::ops::Range<usize>> {
        let mut parts = Vec::new();
        let mut start = 0;
        for &cut in cuts {
            parts.push(start..cut + 1);
            start = cut + 1;
        }
        parts.push(start..bytes.len());
        parts
    }

    #[test]
    fn a_file_read_in_parts_reads_as_in_one() {
        let plain = "# a plain file\r\nv 0 0 0\r\nv 1.5 0 -0.0\r\n\r\n  v 1 1e0 0.25\r\nv -2.5E-1 1 0\r\nv 3 3 3\r\nf 1 2 3\r\n# quad\r\nf 1 2 3 4\r\nv 4 4 4\nf 2 3 6\nf 5 6 4\n";
        let relative = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 0\nf -3 -1 -2\n";
        let later = "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n";
        let prefix = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let other = format!("{prefix}f 1 2 3\nvt 0 0\n");
        for text in [plain, relative, later, other.as_str()] {
            let bytes = text.as_bytes();
            let whole = parse_plain_part(bytes, Some(0));
            let breaks: Vec<usize> = (0..bytes.len().saturating_sub(1))
                .filter(|&i| bytes[i] == b'\n')
                .collect();
            let mut cuts: Vec<Vec<usize>> = breaks.iter().map(|&b| vec![b]).collect();
            for (k, &a) in breaks.iter().enumerate() {
                cuts.extend(breaks[k + 1..].iter().map(|&b| vec![a, b]));
            }
            for cut in cuts {
                let parts = parse_plain_in_parts(bytes, &cut_after(bytes, &cut));
                match (&whole, parts) {
                    (PlainPart::Read(whole), Some((soup, lines))) => {
                        assert_same(&soup, &whole.soup);
                        assert_eq!(lines, whole.face_lines, "{text:?} cut at {cut:?}");
                    }
                    (PlainPart::NotPlain, None) => {}
                    _ => panic!("{text:?} cut at {cut:?}: one part and several differ"),
                }
            }
        }
        // The plain file as one part reads as tobj reads it; the negative indices of the
        // second file name the vertices before them, also in a later part.
        assert_same(
            &parse_plain(plain.as_bytes()).unwrap().0,
            &through_tobj(plain.as_bytes()),
        );
        let PlainPart::Read(relative) = parse_plain_part(relative.as_bytes(), Some(0)) else {
            panic!("a plain file");
        };
        assert_eq!(relative.soup.face(1), [1, 3, 2]);
        assert_eq!(relative.face_lines, [4, 6]);
        // A face naming a vertex listed after it is not plain, whichever part holds it.
        assert!(matches!(
            parse_plain_part(later.as_bytes(), Some(0)),
            PlainPart::NotPlain
        ));
        assert!(matches!(
            parse_plain_part(other.as_bytes(), Some(0)),
            PlainPart::NotPlain
        ));
        // Parts cut by size end after line breaks and cover the file.
        let long = plain.repeat(PLAIN_PART_BYTES / plain.len() * 3);
        let parts = plain_parts(long.as_bytes(), 2);
        assert_eq!(parts.len(), 2);
        assert_eq!((parts[0].start, parts[0].end), (0, parts[1].start));
        assert_eq!(parts[1].end, long.len());
        assert_eq!(long.as_bytes()[parts[0].end - 1], b'\n');
        assert_eq!(plain_parts(long.as_bytes(), 1).len(), 1);
        assert_eq!(plain_parts(plain.as_bytes(), 2).len(), 1);
    }

    #[test]
    fn anything_else_is_left_to_tobj() {
        let prefix = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
        for (body, why) in [
            ("f 1/1 2/2 3/3\n", "texture indices"),
            ("f 1//1 2//1 3//1\n", "normal indices"),
            ("vt 0 0\nf 1 2 3\n", "a texture coordinate"),
            ("vn 0 0 1\nf 1 2 3\n", "a normal"),
            ("g part\nf 1 2 3\n", "a group"),
            ("v 1 2 3 1\nf 1 2 3\n", "a weight"),
            ("v 1 2\nf 1 2 3\n", "two coordinates"),
            (
                "f 1 2 6\nv 2 2 0\nv 3 3 0\n",
                "a vertex listed after the face",
            ),
            ("f 1 2 0\n", "index 0"),
            ("f 1 -5 3\n", "a relative index before the first vertex"),
            ("f 1 2\n", "a face of two vertices"),
            ("f 1 2 x\n", "a word"),
            ("v 1 2 nan-ish\n", "a bad number"),
        ] {
            let text = format!("{prefix}{body}");
            let bytes = text.as_bytes();
            assert!(parse_plain(bytes).is_none(), "{why}");
        }
        // tobj reads what it can, and the result is the same as before the fast path.
        let text = format!("{prefix}vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
        let raw = parse(Path::new("test.obj"), text.as_bytes()).unwrap();
        assert_eq!(raw.soup.face(0), [0, 1, 2]);
        assert!(raw.corner_uvs.is_some());
    }

    #[test]
    fn the_shared_meshes_read_as_through_tobj() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            eprintln!(
                "SKIPPED the_shared_meshes_read_as_through_tobj: {} is absent",
                dir.display()
            );
            return;
        };
        let mut plain = 0;
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_none_or(|e| e != "obj") {
                continue;
            }
            let bytes = std::fs::read(&path).unwrap();
            if let Some((fast, face_lines)) = parse_plain(&bytes) {
                assert_same(&fast, &through_tobj(&bytes));
                assert_eq!(face_lines, prepare(&bytes).face_lines);
                plain += 1;
            }
        }
        println!("{plain} shared meshes read without tobj, the same as through it");
        assert!(plain > 0);
    }
}
