//! Reading and writing meshes: Wavefront OBJ (through `tobj`), glTF 2.0 / GLB (through
//! `gltf`), PLY, STL and OFF (by hand: see each module for why).
//!
//! # Indices
//!
//! Vertex indices everywhere in beltrami (CLI pins, landmark files, correspondence output)
//! are the file's own 0-based order. Readers return the file's vertices in that order;
//! the halfedge mesh leaves out unreferenced vertices and [`crate::VertexMap`] converts.
//! Writers restore the input order: they write the vertices in input order, unreferenced
//! ones included, whenever no vertices were merged by a repair.
//!
//! # Atomic output
//!
//! Every writer goes through [`write_atomically`]: the file is written under a temporary
//! name in the destination's folder and renamed over the destination only once complete,
//! so a failed run never leaves a half-written file.

mod atomic;
pub mod gltf;
pub mod obj;
pub mod off;
pub mod ply;
mod seamed;
mod slots;
pub mod source;
pub mod stl;
mod text;

use std::path::{Path, PathBuf};

use nalgebra::{Point3, Vector2};
use thiserror::Error;

use crate::{BuildOptions, BuildReport, Mesh, MeshError, PolygonSoup};

pub use atomic::{remove_in_flight, write_atomically};
pub use seamed::{CornerUvs, write_seamed};

/// The content of a mesh file before validation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawMesh {
    /// Positions (in file order) and faces.
    pub soup: PolygonSoup,
    /// Texture coordinates per face corner, in the soup's face and corner order, when the
    /// file gives one for every corner.
    pub corner_uvs: Option<Vec<Vector2<f64>>>,
    /// For text files (OBJ, ASCII PLY, ASCII STL, OFF), the 1-based line number of every
    /// face, to name it in errors.
    pub face_lines: Option<Vec<u32>>,
    /// For STL files, which list every triangle's corners by position: how the corners
    /// were welded into vertices.
    pub weld: Option<Weld>,
    /// For OBJ files, the grouping lines (`o`, `g`, `s`, `usemtl`, `mtllib`) that stand
    /// before a face, as `(input face index, lines)`: an OBJ output of the same faces
    /// writes them back ([`VertexAttributes::obj_groups`]).
    pub obj_groups: Vec<(u32, String)>,
}

/// The welding of an STL file's triangle corners into shared vertices: corners with
/// bit-identical coordinates (`-0.0` counted as `0.0`) become one vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Weld {
    /// Triangle corners in the file (three per triangle).
    pub corners: usize,
    /// Vertices left after welding.
    pub vertices: usize,
}

/// A syntax error of the PLY, STL and OFF parsers: where it is, and what is wrong.
pub type SyntaxError = (FilePosition, String);

/// Where in a file a syntax error is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilePosition {
    /// A 1-based line of a text file or text section.
    Line(usize),
    /// A 0-based byte offset into a binary file.
    Byte(u64),
}

impl std::fmt::Display for FilePosition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FilePosition::Line(line) => write!(f, ":{line}"),
            FilePosition::Byte(byte) => write!(f, " (byte {byte})"),
        }
    }
}

/// A validated mesh read from a file.
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    /// The halfedge mesh.
    pub mesh: Mesh,
    /// What the builder changed (re-oriented faces, unreferenced vertices, repairs).
    pub report: BuildReport,
    /// Texture coordinates per face halfedge (indexed by the [`crate::HalfedgeId`] of
    /// the face halfedge leaving the corner's vertex), when the file has them.
    pub corner_uvs: Option<Vec<Vector2<f64>>>,
    /// How an STL file's corners were welded into vertices.
    pub weld: Option<Weld>,
    /// An OBJ file's grouping lines before its faces ([`RawMesh::obj_groups`]).
    pub obj_groups: Vec<(u32, String)>,
}

impl LoadedMesh {
    /// One texture coordinate per mesh vertex, when the file has texture coordinates and
    /// every vertex has a single one (no texture seams); otherwise `None`.
    pub fn vertex_uvs(&self) -> Option<Vec<Vector2<f64>>> {
        let corner = self.corner_uvs.as_ref()?;
        let mesh = &self.mesh;
        let mut uv: Vec<Option<Vector2<f64>>> = vec![None; mesh.vertex_count()];
        for f in mesh.faces() {
            for h in mesh.face_halfedges(f) {
                let slot = &mut uv[mesh.origin(h).idx()];
                let value = corner[h.idx()];
                match slot {
                    None => *slot = Some(value),
                    Some(old) if *old != value => return None,
                    Some(_) => {}
                }
            }
        }
        uv.into_iter().collect()
    }
}

/// Why a mesh file could not be read.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("cannot read {path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// The extension is not one beltrami reads.
    #[error("{path}: unknown mesh format (expected {})", Format::EXTENSIONS)]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The file is not valid PLY, STL or OFF.
    #[error("{path}{at}: not a valid {format} file: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The format the file was read as.
        format: Format,
        /// Where the error is.
        at: FilePosition,
        /// What is wrong.
        message: String,
    },
    /// The file is not valid OBJ.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Obj {
        /// The file.
        path: PathBuf,
        /// 1-based line number, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// An OBJ face corner whose vertex index names no vertex. The index is quoted as
    /// written: OBJ indices are 1-based, and negative ones count back from the face's
    /// line (-1 is the last `v` before it).
    #[error(
        "{path}:{line}: face {face} refers to vertex `{written}`, which names no vertex: the file has {vertex_count} vertices (indices 1..={vertex_count}), {before} of them before this line (relative indices -1..=-{before})"
    )]
    ObjVertexIndex {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the face.
        line: usize,
        /// 0-based face index.
        face: usize,
        /// The index as written in the file.
        written: String,
        /// Number of `v` lines in the file.
        vertex_count: usize,
        /// Number of `v` lines before the face.
        before: usize,
    },
    /// A texture coordinate that is NaN or infinite.
    #[error("{path}{}: {what} {index} is not finite ({u}, {v})", line.map(|l| format!(":{l}")).unwrap_or_default())]
    NonFiniteTexCoord {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the coordinate, when known (OBJ).
        line: Option<usize>,
        /// What `index` counts: "texture coordinate" (OBJ `vt`, 0-based) or
        /// "TEXCOORD_0 of face corner" (glTF).
        what: &'static str,
        /// 0-based index.
        index: usize,
        /// First component.
        u: f64,
        /// Second component.
        v: f64,
    },
    /// The file is not valid glTF, or has no triangles.
    #[error("{path}: {message}")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file parsed but its faces do not form a valid mesh.
    #[error("{path}{}: {error}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Mesh {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the offending face, when known.
        line: Option<usize>,
        /// The validation error (input indices = the file's 0-based order).
        error: MeshError,
    },
}

/// Why a mesh file could not be written. The destination is left untouched.
#[derive(Debug, Error)]
pub enum WriteError {
    /// Creating, writing or renaming the file failed.
    #[error("cannot write {path}: {error}")]
    Io {
        /// The destination.
        path: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// The extension is not one beltrami writes.
    #[error("{path}: unknown mesh format (expected {})", Format::EXTENSIONS)]
    UnknownFormat {
        /// The destination.
        path: PathBuf,
    },
    /// The format cannot hold an attribute that was asked for (texture coordinates in an
    /// STL file).
    #[error(
        "{path}: {format} files cannot hold {what}; write {} instead",
        Format::holding(what)
    )]
    Unsupported {
        /// The destination.
        path: PathBuf,
        /// The destination's format.
        format: Format,
        /// The attribute.
        what: &'static str,
    },
    /// Texture coordinates with seams did not split the mesh into a valid mesh (a
    /// coordinate shared by corners of one vertex that are not in one fan).
    #[error("the texture coordinates' seams do not split the mesh into a valid mesh: {message}")]
    Seams {
        /// Why the split mesh was refused.
        message: String,
    },
    /// A per-vertex attribute does not have one value per mesh vertex.
    #[error("{what} has {got} values but the mesh has {expected} vertices")]
    AttributeLength {
        /// Which attribute.
        what: &'static str,
        /// Number of mesh vertices.
        expected: usize,
        /// Number of values given.
        got: usize,
    },
    /// A value that cannot be written (NaN or infinite).
    #[error("{what} of vertex {vertex} is not finite")]
    NonFinite {
        /// Which attribute.
        what: &'static str,
        /// Input index of the vertex.
        vertex: usize,
    },
}

/// Per-vertex data to write beside the connectivity. Each slice, when given, has one
/// entry per mesh vertex ([`crate::VertexId`] order).
#[derive(Debug, Clone, Copy, Default)]
pub struct VertexAttributes<'a> {
    /// Positions to write instead of the mesh's own (e.g. a map into R^3).
    pub positions: Option<&'a [Point3<f64>]>,
    /// Texture coordinates (e.g. a planar map), written as `vt` / `TEXCOORD_0`.
    pub uvs: Option<&'a [Vector2<f64>]>,
    /// RGB colors in [0, 1], written as glTF `COLOR_0`, PLY `red green blue` bytes and
    /// COFF values (OBJ and STL have no vertex colors and leave them out).
    pub colors: Option<&'a [[f32; 3]]>,
    /// OBJ only: grouping lines to write before faces, by input face index, as read
    /// ([`LoadedMesh::obj_groups`]); the lines of a face the mesh dropped go before the
    /// next face it kept.
    pub obj_groups: &'a [(u32, String)],
}

impl VertexAttributes<'_> {
    /// Checks that every given attribute has one finite value per vertex.
    pub fn check(&self, mesh: &Mesh) -> Result<(), WriteError> {
        check_attribute(mesh, ["positions", "position"], self.positions, |p| {
            p.iter().all(|x| x.is_finite())
        })?;
        check_attribute(mesh, ["uvs", "uv"], self.uvs, |t| {
            t.iter().all(|x| x.is_finite())
        })?;
        check_attribute(mesh, ["colors", "color"], self.colors, |c| {
            c.iter().all(|x| x.is_finite())
        })
    }
}

/// Checks that an attribute, when given, has one value per mesh vertex and that
/// `finite` holds for each, naming the first bad vertex by its input index. `names` are
/// the attribute's plural (for the length) and singular (for a value) names.
fn check_attribute<T>(
    mesh: &Mesh,
    [plural, singular]: [&'static str; 2],
    values: Option<&[T]>,
    finite: impl Fn(&T) -> bool,
) -> Result<(), WriteError> {
    let Some(values) = values else {
        return Ok(());
    };
    if values.len() != mesh.vertex_count() {
        return Err(WriteError::AttributeLength {
            what: plural,
            expected: mesh.vertex_count(),
            got: values.len(),
        });
    }
    match values.iter().position(|v| !finite(v)) {
        Some(v) => Err(WriteError::NonFinite {
            what: singular,
            vertex: mesh.vertex_map().to_input(crate::VertexId(v as u32)),
        }),
        None => Ok(()),
    }
}

/// The mesh formats beltrami reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ.
    Obj,
    /// glTF 2.0, JSON with external or embedded buffers.
    Gltf,
    /// glTF 2.0 binary container.
    Glb,
    /// PLY (Stanford polygon file format), ASCII or binary.
    Ply,
    /// STL (stereolithography), ASCII or binary: triangles listed by corner positions.
    Stl,
    /// OFF (Geomview object file format) and its variants COFF, NOFF, STOFF.
    Off,
}

impl Format {
    /// The extensions beltrami reads and writes, for messages.
    pub const EXTENSIONS: &'static str = ".obj, .ply, .stl, .off, .gltf or .glb";

    /// The format named by a path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "gltf" => Some(Format::Gltf),
            "glb" => Some(Format::Glb),
            "ply" => Some(Format::Ply),
            "stl" => Some(Format::Stl),
            "off" => Some(Format::Off),
            _ => None,
        }
    }

    /// Whether files of this format can hold per-vertex texture coordinates.
    pub fn holds_uvs(self) -> bool {
        self != Format::Stl
    }

    /// Whether files of this format can hold per-vertex colors.
    pub fn holds_colors(self) -> bool {
        !matches!(self, Format::Obj | Format::Stl)
    }

    /// The extensions of the formats that hold `what` (an attribute named as in
    /// [`WriteError::Unsupported`]), for messages.
    fn holding(what: &str) -> &'static str {
        match what {
            "vertex colors" => ".ply, .off, .gltf or .glb",
            _ => ".obj, .ply, .off, .gltf or .glb",
        }
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Gltf => "glTF",
            Format::Glb => "GLB",
            Format::Ply => "PLY",
            Format::Stl => "STL",
            Format::Off => "OFF",
        })
    }
}

/// Reads a mesh file's content without validating it, choosing the reader by extension.
pub fn read_raw(path: &Path) -> Result<RawMesh, ReadError> {
    match Format::from_path(path) {
        Some(Format::Obj) => obj::read(path),
        Some(Format::Gltf | Format::Glb) => gltf::read(path),
        Some(Format::Ply) => ply::read(path),
        Some(Format::Stl) => stl::read(path),
        Some(Format::Off) => off::read(path),
        None => Err(ReadError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Reads `path` and parses its bytes with `parse`, a reader whose syntax errors say
/// where they are (PLY, STL, OFF).
fn read_with(
    path: &Path,
    format: Format,
    parse: fn(&[u8]) -> Result<RawMesh, SyntaxError>,
) -> Result<RawMesh, ReadError> {
    let bytes = source::read_bytes(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&bytes).map_err(|(at, message)| ReadError::Syntax {
        path: path.to_path_buf(),
        format,
        at,
        message,
    })
}

/// Reads and validates a mesh file (any [`Format`], by extension).
pub fn read(path: &Path, options: &BuildOptions) -> Result<LoadedMesh, ReadError> {
    let raw = read_raw(path)?;
    build_raw(path, raw, options)
}

/// Validates the content of a mesh file read from `path` (named in errors).
pub fn build_raw(
    path: &Path,
    raw: RawMesh,
    options: &BuildOptions,
) -> Result<LoadedMesh, ReadError> {
    let (mesh, report) = Mesh::build(&raw.soup, options).map_err(|error| {
        let line = raw
            .face_lines
            .as_ref()
            .and_then(|lines| offending_face(&error).and_then(|f| lines.get(f)))
            .map(|&l| l as usize);
        ReadError::Mesh {
            path: path.to_path_buf(),
            line,
            error,
        }
    })?;
    let corner_uvs = raw
        .corner_uvs
        .map(|uv| corner_uvs_of_mesh(&mesh, &raw.soup, &uv));
    Ok(LoadedMesh {
        mesh,
        report,
        corner_uvs,
        weld: raw.weld,
        obj_groups: raw.obj_groups,
    })
}

/// The input face an error names first, to find its line.
fn offending_face(e: &MeshError) -> Option<usize> {
    match e {
        MeshError::UnsupportedFaceSize { face, .. }
        | MeshError::VertexIndexOutOfRange { face, .. }
        | MeshError::RepeatedVertex { face, .. }
        | MeshError::DegenerateFace { face, .. }
        | MeshError::FoldedQuad { face, .. }
        | MeshError::DuplicateFace { face, .. }
        | MeshError::NonOrientable { face, .. } => Some(*face),
        MeshError::NonManifoldEdge { faces, .. } => faces.last().copied(),
        _ => None,
    }
}

/// Moves per-corner texture coordinates from the soup's corner order to the mesh's face
/// halfedges. A re-oriented face keeps its first vertex and reverses the others, so each
/// mesh corner is matched to the soup corner with the same input vertex.
fn corner_uvs_of_mesh(mesh: &Mesh, soup: &PolygonSoup, uv: &[Vector2<f64>]) -> Vec<Vector2<f64>> {
    let mut start = Vec::with_capacity(soup.face_count() + 1);
    let mut acc = 0usize;
    for face in soup.faces() {
        start.push(acc);
        acc += face.len();
    }
    let map = mesh.vertex_map();
    let mut out = vec![Vector2::zeros(); mesh.halfedge_count()];
    for f in mesh.faces() {
        let input = mesh.face_to_input(f);
        let face = soup.face(input);
        for h in mesh.face_halfedges(f) {
            let v = mesh.origin(h);
            let k = face
                .iter()
                .position(|&i| map.from_input(i as usize) == Some(v))
                .unwrap_or(0);
            out[h.idx()] = uv[start[input] + k];
        }
    }
    out.truncate(mesh.faces().last().map_or(0, |f| {
        mesh.face_halfedges(f).last().map_or(0, |h| h.idx() + 1)
    }));
    out
}

/// Writes `mesh` with the given attributes, choosing the format by extension. Colors go
/// where the format holds them and are left out elsewhere (they only decorate a result);
/// texture coordinates for a format that cannot hold them are an error
/// ([`WriteError::Unsupported`]), before anything is written.
pub fn write(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
) -> Result<(), WriteError> {
    match Format::from_path(path) {
        Some(Format::Obj) => obj::write(path, mesh, attributes),
        Some(Format::Gltf | Format::Glb) => gltf::write(path, mesh, attributes),
        Some(Format::Ply) => ply::write(path, mesh, attributes),
        Some(Format::Stl) => stl::write(path, mesh, attributes),
        Some(Format::Off) => off::write(path, mesh, attributes),
        None => Err(WriteError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}
