//! glTF 2.0 / GLB reading and writing.
//!
//! # Reading
//!
//! [`read`] takes every triangle primitive (modes `TRIANGLES`, `TRIANGLE_STRIP` and
//! `TRIANGLE_FAN`) of every mesh instance reachable from the scene: the default scene, or
//! every scene when the file names no default, or every mesh once (untransformed) when the
//! file has no scenes. Each instance is placed by its node's world transform (the product
//! of its ancestors' transforms; only the affine part is used, as glTF requires node
//! matrices to be affine). Point and line primitives are ignored, as are skins and morph
//! targets. Vertices are merged into one soup in traversal order (scene roots in order,
//! depth first, children in order; primitives in order), without welding: primitives
//! that share a border stay disconnected.
//!
//! Faces keep glTF's front face, counter-clockwise: strips alternate their winding so that
//! every triangle keeps the strip's orientation, and instances whose transform has a
//! negative determinant (mirrors) get their triangles reversed, so that faces stay
//! counter-clockwise seen from the front in world space.
//!
//! # Writing
//!
//! [`write()`] writes one mesh with one triangle primitive under one node in one scene
//! (with texture coordinates, the primitive gets a white two-sided material, without
//! which loaders such as trimesh drop them):
//! quads are split along their first diagonal, `(v0, v1, v2)` and `(v0, v2, v3)`. Vertex
//! `k` of the file is input vertex `k` whenever no vertices were merged (unreferenced
//! vertices included, with their own positions, zero texture coordinates and black
//! color); otherwise the mesh's vertices are written in [`crate::VertexId`] order.
//! Positions, texture coordinates and colors are stored as `f32`.
//!
//! # Texture coordinates
//!
//! `TEXCOORD_0` values are read and written as they are, without flipping `v`: glTF puts
//! the texture origin at the top-left corner of the image, OBJ at the bottom-left, so the
//! same coordinates show an image mirrored upside down in the two formats.

use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::{Source, View};
use ::gltf::mesh::Mode;
use ::gltf::{Accessor, Document, Gltf, Primitive, Semantic};
use base64::Engine as _;
use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use nalgebra::{Matrix3, Matrix4, Point3, Vector2, Vector3};
use serde_json::{Value, json};

use super::slots::OutputSlots;
use super::{RawMesh, ReadError, VertexAttributes, WriteError};
use crate::{Mesh, PolygonSoup};

/// Base64 for `data:` URIs; exporters disagree on trailing `=` padding, so accept both.
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// Reads all triangle primitives of a `.gltf` or `.glb` file into one soup.
///
/// Conventions (scene traversal, node transforms, winding, vertex order) are in the
/// [module docs](self). Buffers come from the GLB binary chunk, from base64 `data:` URIs,
/// or from files named by a URI relative to the file's folder (not percent-decoded).
/// `corner_uvs` holds `TEXCOORD_0` per face corner when every triangle primitive has it.
///
/// Fails with [`ReadError::Io`] when the file or an external buffer cannot be read and
/// with [`ReadError::Gltf`] when the file is not valid glTF, an accessor is malformed or
/// of an unsupported type, an index is out of its primitive's range, or the file has no
/// triangle primitives.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    let bytes = super::source::read_bytes(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse_bytes(path, &bytes)
}

/// Parses glTF or GLB content held in memory as [`read`] does; `path` names the file in
/// errors, and its folder is where external buffer URIs are looked up.
pub fn parse_bytes(path: &Path, bytes: &[u8]) -> Result<RawMesh, ReadError> {
    let invalid = |message: String| ReadError::Gltf {
        path: path.to_path_buf(),
        message,
    };
    let gltf = parse(bytes).map_err(invalid)?;
    let buffers = load_buffers(&gltf, path)?;
    let instances = mesh_instances(&gltf.document).map_err(invalid)?;

    let mut merged = Merged::default();
    for (mesh, world) in &instances {
        for prim in mesh.primitives() {
            merged
                .add_primitive(mesh.index(), &prim, world, &buffers)
                .map_err(invalid)?;
        }
    }
    if merged.triangle_primitives == 0 {
        return Err(invalid(
            "the file has no triangle primitives (only points or lines, or no meshes in its scene)"
                .into(),
        ));
    }
    Ok(RawMesh {
        soup: merged.soup,
        corner_uvs: merged.uvs,
        face_lines: None,
        weld: None,
        obj_groups: Vec::new(),
    })
}

/// Parses and validates a glTF or GLB file.
///
/// `gltf::Gltf::from_slice` would validate too, but its validation indexes the accessor
/// list with the `POSITION` index before checking it, and its GLB header parsing
/// subtracts from the declared length unchecked: both panic on malformed files, so those
/// two things are checked first.
fn parse(bytes: &[u8]) -> Result<Gltf, String> {
    const HEADER: usize = 12;
    if let Some(length) = bytes.strip_prefix(b"glTF").and_then(|b| b.get(4..8)) {
        let length = u32::from_le_bytes([length[0], length[1], length[2], length[3]]);
        if (length as usize) < HEADER {
            return Err(format!("GLB header declares a length of {length} bytes"));
        }
    }
    let gltf = Gltf::from_slice_without_validation(bytes)
        .map_err(|e| format!("not a valid glTF or GLB file: {e}"))?;
    let root = gltf.as_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim
                .attributes
                .get(&::gltf::json::validation::Checked::Valid(
                    Semantic::Positions,
                ));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(format!(
                    "mesh {m} primitive {p}: POSITION refers to accessor {}, but there are only {}",
                    index.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    let mut problems = Vec::new();
    ::gltf::json::validation::Validate::validate(
        root,
        root,
        ::gltf::json::Path::new,
        &mut |path, error| problems.push(format!("{}: {error}", path())),
    );
    if !problems.is_empty() {
        const SHOWN: usize = 5;
        let more = problems.len().saturating_sub(SHOWN);
        problems.truncate(SHOWN);
        let mut message = format!("invalid glTF: {}", problems.join("; "));
        if more > 0 {
            message.push_str(&format!(" (and {more} more)"));
        }
        return Err(message);
    }
    Ok(gltf)
}

/// The data of every buffer, in buffer order, each at least its declared `byteLength`
/// long (readers cut it to that length).
fn load_buffers<'a>(gltf: &'a Gltf, path: &Path) -> Result<Vec<Cow<'a, [u8]>>, ReadError> {
    let invalid = |message: String| ReadError::Gltf {
        path: path.to_path_buf(),
        message,
    };
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut out = Vec::with_capacity(gltf.buffers().len());
    for buffer in gltf.buffers() {
        let i = buffer.index();
        let data: Cow<'a, [u8]> = match buffer.source() {
            Source::Bin => match &gltf.blob {
                Some(blob) => Cow::Borrowed(blob),
                None => {
                    return Err(invalid(format!(
                        "buffer {i} refers to the GLB binary chunk, but the file has none"
                    )));
                }
            },
            Source::Uri(uri) => match uri.strip_prefix("data:") {
                Some(rest) => Cow::Owned(
                    decode_data_uri(rest).map_err(|m| invalid(format!("buffer {i}: {m}")))?,
                ),
                None => {
                    // Check the declared length against the file before reading, and
                    // read no more than it: the URI may name a device or a huge file.
                    let file = folder.join(uri);
                    let declared = buffer.length() as u64;
                    let io = |error| ReadError::Io {
                        path: file.clone(),
                        error,
                    };
                    let len = super::source::regular_file_length(&file).map_err(io)?;
                    if len < declared {
                        return Err(invalid(format!(
                            "buffer {i} has {len} bytes in {uri}, but its byteLength is {declared}"
                        )));
                    }
                    Cow::Owned(super::source::read_prefix(&file, declared).map_err(io)?)
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(invalid(format!(
                "buffer {i} has {} bytes, but its byteLength is {}",
                data.len(),
                buffer.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// Decodes the part of a `data:` URI after the scheme (`<media type>;base64,<payload>`).
fn decode_data_uri(rest: &str) -> Result<Vec<u8>, String> {
    let (header, payload) = rest
        .split_once(',')
        .ok_or_else(|| "malformed data URI (no comma)".to_string())?;
    if !header.ends_with(";base64") {
        return Err("only base64 data URIs are supported".into());
    }
    BASE64
        .decode(payload)
        .map_err(|e| format!("invalid base64 in data URI: {e}"))
}

/// Every mesh instance to read with its world transform, in traversal order.
fn mesh_instances(doc: &Document) -> Result<Vec<(::gltf::Mesh<'_>, Matrix4<f64>)>, String> {
    let scenes: Vec<_> = match doc.default_scene() {
        Some(scene) => vec![scene],
        None => doc.scenes().collect(),
    };
    if scenes.is_empty() {
        return Ok(doc.meshes().map(|m| (m, Matrix4::identity())).collect());
    }
    let mut out = Vec::new();
    for scene in scenes {
        // glTF node hierarchies are disjoint trees; a node reached twice means a cycle or
        // a node with two parents, which would loop forever or blow up exponentially.
        let mut seen = vec![false; doc.nodes().len()];
        let mut stack: Vec<_> = scene.nodes().map(|n| (n, Matrix4::identity())).collect();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            let seen_before = seen
                .get_mut(node.index())
                .map(|s| std::mem::replace(s, true))
                .unwrap_or(true);
            if seen_before {
                return Err(format!(
                    "node {} is reached twice in scene {} (a cycle, or a node with two parents)",
                    node.index(),
                    scene.index()
                ));
            }
            check_transform(&node)?;
            let local = node.transform().matrix();
            let world = parent * Matrix4::from_fn(|r, c| f64::from(local[c][r]));
            if let Some(mesh) = node.mesh() {
                out.push((mesh, world));
            }
            let first_child = stack.len();
            stack.extend(node.children().map(|c| (c, world)));
            stack[first_child..].reverse();
        }
    }
    Ok(out)
}

/// Refuses a node transform that is not finite (a value beyond `f32`, which glTF stores)
/// or whose rotation is not a unit quaternion, as glTF requires (a longer one would scale
/// the mesh by its squared length without a word).
fn check_transform(node: &::gltf::Node<'_>) -> Result<(), String> {
    let finite = |values: &[f32]| values.iter().all(|x| x.is_finite());
    match node.transform() {
        ::gltf::scene::Transform::Matrix { matrix } => {
            if !finite(matrix.as_flattened()) {
                return Err(format!("node {}: its matrix is not finite", node.index()));
            }
        }
        ::gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            if !(finite(&translation) && finite(&rotation) && finite(&scale)) {
                return Err(format!(
                    "node {}: its translation, rotation or scale is not finite (beyond the 32-bit floats glTF stores)",
                    node.index()
                ));
            }
            let length = rotation
                .iter()
                .map(|&q| f64::from(q).powi(2))
                .sum::<f64>()
                .sqrt();
            if (length - 1.0).abs() > 1e-3 {
                return Err(format!(
                    "node {}: its rotation quaternion has length {length}, not 1 (glTF requires unit quaternions)",
                    node.index()
                ));
            }
        }
    }
    Ok(())
}

/// The soup being assembled from the primitives.
struct Merged {
    soup: PolygonSoup,
    /// Corner texture coordinates, `None` once a primitive without `TEXCOORD_0` is seen.
    uvs: Option<Vec<Vector2<f64>>>,
    triangle_primitives: usize,
}

impl Default for Merged {
    fn default() -> Self {
        Self {
            soup: PolygonSoup::new(Vec::new()),
            uvs: Some(Vec::new()),
            triangle_primitives: 0,
        }
    }
}

impl Merged {
    /// Appends one primitive of mesh `mesh` placed by `world`; non-triangle primitives are
    /// skipped.
    fn add_primitive(
        &mut self,
        mesh: usize,
        prim: &Primitive<'_>,
        world: &Matrix4<f64>,
        buffers: &[Cow<'_, [u8]>],
    ) -> Result<(), String> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(());
        }
        self.triangle_primitives += 1;
        let name = format!("mesh {mesh} primitive {}", prim.index());
        let reader = prim.reader(|b| buffers.get(b.index()).and_then(|d| d.get(..b.length())));
        let unreadable = |what: &str| format!("{name}: cannot read {what}");

        let positions_accessor = prim
            .get(&Semantic::Positions)
            .ok_or_else(|| format!("{name} has no POSITION attribute"))?;
        check_accessor(&positions_accessor, &[Dimensions::Vec3], &[DataType::F32])
            .map_err(|m| format!("{name}: POSITION {m}"))?;
        let positions: Vec<[f32; 3]> = reader
            .read_positions()
            .ok_or_else(|| unreadable("POSITION"))?
            .collect();
        let n = positions.len();
        let offset = self.soup.positions.len();
        // Soup indices are u32: the merged vertices must stay addressable.
        let offset = u32::try_from(offset)
            .ok()
            .filter(|&o| n <= (u32::MAX - o) as usize)
            .ok_or_else(|| format!("{name}: more than {} vertices in all", u32::MAX))?;

        let indices: Vec<u32> = match prim.indices() {
            Some(accessor) => {
                check_accessor(
                    &accessor,
                    &[Dimensions::Scalar],
                    &[DataType::U8, DataType::U16, DataType::U32],
                )
                .map_err(|m| format!("{name}: indices {m}"))?;
                reader
                    .read_indices()
                    .ok_or_else(|| unreadable("indices"))?
                    .into_u32()
                    .collect()
            }
            // n fits in u32 (checked above).
            None => (0..n as u32).collect(),
        };
        // Checked per primitive: an index past this primitive's vertices would silently
        // pick a vertex of the next primitive once merged.
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "{name}: vertex index {bad} is out of range ({n} vertices)"
            ));
        }

        let uvs: Option<Vec<[f32; 2]>> = match prim.get(&Semantic::TexCoords(0)) {
            Some(accessor) => {
                check_accessor(
                    &accessor,
                    &[Dimensions::Vec2],
                    &[DataType::F32, DataType::U8, DataType::U16],
                )
                .map_err(|m| format!("{name}: TEXCOORD_0 {m}"))?;
                let uvs: Vec<[f32; 2]> = reader
                    .read_tex_coords(0)
                    .ok_or_else(|| unreadable("TEXCOORD_0"))?
                    .into_f32()
                    .collect();
                if uvs.len() != n {
                    return Err(format!(
                        "{name}: TEXCOORD_0 has {} values for {n} vertices",
                        uvs.len()
                    ));
                }
                if let Some((k, t)) = uvs
                    .iter()
                    .enumerate()
                    .find(|(_, t)| !(t[0].is_finite() && t[1].is_finite()))
                {
                    return Err(format!(
                        "{name}: TEXCOORD_0 of vertex {k} is not finite ({}, {})",
                        t[0], t[1]
                    ));
                }
                Some(uvs)
            }
            None => None,
        };

        let triangles = triangles(mode, &indices).map_err(|m| format!("{name}: {m}"))?;

        let linear: Matrix3<f64> = world.fixed_view::<3, 3>(0, 0).into_owned();
        let translation: Vector3<f64> = world.fixed_view::<3, 1>(0, 3).into_owned();
        let mirrored = linear.determinant() < 0.0;
        self.soup.positions.extend(positions.iter().map(|p| {
            let p = Vector3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            Point3::from(linear * p + translation)
        }));
        if uvs.is_none() {
            self.uvs = None;
        }
        self.soup.reserve(triangles.len(), 3 * triangles.len());
        for [a, b, c] in triangles {
            let corners = if mirrored { [a, c, b] } else { [a, b, c] };
            self.soup.push_face(&corners.map(|i| i + offset));
            if let (Some(all), Some(uvs)) = (&mut self.uvs, &uvs) {
                all.extend(corners.map(|i| {
                    let [u, v] = uvs[i as usize];
                    Vector2::new(f64::from(u), f64::from(v))
                }));
            }
        }
        Ok(())
    }
}

/// The triangles of a triangle-mode primitive, counter-clockwise as glTF defines them.
fn triangles(mode: Mode, indices: &[u32]) -> Result<Vec<[u32; 3]>, String> {
    Ok(match mode {
        Mode::TriangleStrip => indices
            .windows(3)
            .enumerate()
            // Every other strip triangle runs clockwise; swapping its last two corners
            // keeps the whole strip facing one way.
            .map(|(i, w)| {
                if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[0], w[2], w[1]]
                }
            })
            // Strips are stitched together with repeated indices: those triangles are
            // padding, not faces.
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect(),
        Mode::TriangleFan => match indices.split_first() {
            Some((&first, rest)) => rest.windows(2).map(|w| [first, w[0], w[1]]).collect(),
            None => Vec::new(),
        },
        _ => {
            if !indices.len().is_multiple_of(3) {
                return Err(format!(
                    "{} indices is not a whole number of triangles",
                    indices.len()
                ));
            }
            indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect()
        }
    })
}

/// Checks an accessor before `gltf`'s reader touches it: the reader assumes the type
/// matches what it is asked for and that the data lies inside the buffer views, and
/// panics or computes out-of-range slices otherwise.
fn check_accessor(
    accessor: &Accessor<'_>,
    dimensions: &[Dimensions],
    data_types: &[DataType],
) -> Result<(), String> {
    let i = accessor.index();
    if !dimensions.contains(&accessor.dimensions()) || !data_types.contains(&accessor.data_type()) {
        return Err(format!(
            "accessor {i} has the unsupported type {:?} of {:?}",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(format!("accessor {i} has count 0"));
    }
    let size = accessor.size();
    if let Some(view) = accessor.view() {
        check_range(&view, accessor.offset(), count, size)
            .map_err(|m| format!("accessor {i}: {m}"))?;
    }
    if let Some(sparse) = accessor.sparse() {
        let count = sparse.count();
        if count == 0 {
            return Err(format!("sparse accessor {i} has count 0"));
        }
        let indices = sparse.indices();
        check_range(
            &indices.view(),
            indices.offset(),
            count,
            indices.index_type().size(),
        )
        .map_err(|m| format!("sparse indices of accessor {i}: {m}"))?;
        let values = sparse.values();
        check_range(&values.view(), values.offset(), count, size)
            .map_err(|m| format!("sparse values of accessor {i}: {m}"))?;
    }
    Ok(())
}

/// Checks that `count >= 1` elements of `size` bytes starting at `offset` in `view` lie
/// inside the view, and the view inside its buffer's declared length.
fn check_range(view: &View<'_>, offset: usize, count: usize, size: usize) -> Result<(), String> {
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "buffer view {} has a stride of {stride} bytes for {size}-byte elements",
            view.index()
        ));
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|e| e.checked_add(size))
        .and_then(|e| e.checked_add(offset));
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!(
            "{count} elements at offset {offset} do not fit in buffer view {} ({} bytes)",
            view.index(),
            view.length()
        ));
    }
    let buffer = view.buffer();
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|end| end > buffer.length()) {
        return Err(format!(
            "buffer view {} does not fit in buffer {} ({} bytes)",
            view.index(),
            buffer.index(),
            buffer.length()
        ));
    }
    Ok(())
}

/// `componentType` of 32-bit floats.
const FLOAT: u32 = 5126;
/// `componentType` of 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// `target` of vertex attribute buffer views.
const ARRAY_BUFFER: u32 = 34962;
/// `target` of index buffer views.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Primitive `mode` of triangle lists.
const TRIANGLES: u32 = 4;

/// Writes `mesh` as GLB (`.glb`, case-insensitive) or as glTF JSON with the buffer
/// embedded as a base64 `data:` URI (any other extension, normally `.gltf`).
///
/// Layout and conventions (vertex order, quad splitting, `f32` storage, no `v` flip) are
/// in the [module docs](self). `POSITION` comes from `attributes.positions` when given,
/// else from the mesh; `TEXCOORD_0` and `COLOR_0` are written when given. The file is
/// written atomically. Fails with the errors of [`VertexAttributes::check`], with
/// [`WriteError::NonFinite`] for a value too large for `f32`, and with
/// [`WriteError::Io`].
pub fn write(
    path: &Path,
    mesh: &Mesh,
    attributes: &VertexAttributes<'_>,
) -> Result<(), WriteError> {
    attributes.check(mesh)?;
    let vertices = OutputVertices::new(mesh, attributes)?;
    let binary = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));

    let mut buffer = BufferBuilder::default();
    let mut attribute_map = serde_json::Map::new();
    let position = buffer.push_floats(&vertices.positions, "VEC3", ARRAY_BUFFER, true);
    attribute_map.insert("POSITION".into(), position.into());
    if let Some(uvs) = &vertices.uvs {
        let uv = buffer.push_floats(uvs, "VEC2", ARRAY_BUFFER, false);
        attribute_map.insert("TEXCOORD_0".into(), uv.into());
    }
    if let Some(colors) = &vertices.colors {
        let color = buffer.push_floats(colors, "VEC3", ARRAY_BUFFER, false);
        attribute_map.insert("COLOR_0".into(), color.into());
    }
    let indices = buffer.push_indices(&vertices.triangles);

    let mut buffer_json = json!({ "byteLength": buffer.bytes.len() });
    if !binary {
        buffer_json["uri"] = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&buffer.bytes)
        )
        .into();
    }
    let mut primitive = json!({
        "attributes": attribute_map,
        "indices": indices,
        "mode": TRIANGLES,
    });
    let mut document = json!({
        "asset": { "version": "2.0", "generator": "beltrami" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "accessors": buffer.accessors,
        "bufferViews": buffer.views,
        "buffers": [buffer_json],
    });
    if vertices.uvs.is_some() {
        // Viewers and loaders (trimesh, three.js) keep texture coordinates only on a
        // primitive with a material: a plain white, rough, two-sided one.
        primitive["material"] = 0.into();
        document["materials"] = json!([{
            "name": "beltrami",
            "doubleSided": true,
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
        }]);
    }
    document["meshes"] = json!([{ "primitives": [primitive] }]);

    super::write_atomically(path, |w| {
        if binary {
            write_glb(w, &serde_json::to_vec(&document)?, &buffer.bytes)
        } else {
            serde_json::to_writer_pretty(&mut *w, &document)?;
            w.write_all(b"\n")
        }
    })
}

/// Writes a GLB container: header, JSON chunk padded with spaces, BIN chunk padded with
/// zeros (both to 4 bytes, as the format requires).
fn write_glb(w: &mut impl Write, json: &[u8], bin: &[u8]) -> std::io::Result<()> {
    let json_len = json.len().next_multiple_of(4);
    let bin_len = bin.len().next_multiple_of(4);
    let total = u32::try_from(12 + 8 + json_len + 8 + bin_len).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the mesh is too large for a GLB file (4 GiB)",
        )
    })?;
    // Both chunk lengths are below `total`, so they fit in u32 too.
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(json_len as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(json)?;
    w.write_all(&b"   "[..json_len - json.len()])?;
    w.write_all(&(bin_len as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(bin)?;
    w.write_all(&[0u8; 3][..bin_len - bin.len()])
}

/// The vertex data to write, in file order, and the triangles as file vertex indices.
struct OutputVertices {
    positions: Vec<[f32; 3]>,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<[f32; 3]>>,
    triangles: Vec<u32>,
}

impl OutputVertices {
    fn new(mesh: &Mesh, attributes: &VertexAttributes<'_>) -> Result<Self, WriteError> {
        let slots = OutputSlots::new(mesh);
        let positions = slots
            .positions(mesh, attributes)
            .iter()
            .enumerate()
            .map(|(s, p)| to_f32(p.coords.into(), "position", slots.input_index(mesh, s)))
            .collect::<Result<Vec<_>, _>>()?;
        let uvs = match attributes.uvs {
            Some(uvs) => Some(
                slots
                    .scatter(uvs)
                    .iter()
                    .enumerate()
                    .map(|(s, uv)| to_f32((*uv).into(), "uv", slots.input_index(mesh, s)))
                    .collect::<Result<Vec<_>, _>>()?,
            ),
            None => None,
        };
        let colors = attributes.colors.map(|colors| slots.scatter(colors));

        let mut triangles = Vec::with_capacity(3 * (mesh.face_count() + mesh.quad_count()));
        for f in mesh.faces() {
            let (vs, n) = mesh.face_vertex_array(f);
            // Slots are input indices or mesh indices, both below u32::MAX.
            let s = |k: usize| slots.slot(vs[k]) as u32;
            if n == 4 {
                triangles.extend([s(0), s(1), s(2), s(0), s(2), s(3)]);
            } else {
                triangles.extend([s(0), s(1), s(2)]);
            }
        }
        Ok(Self {
            positions,
            uvs,
            colors,
            triangles,
        })
    }
}

/// Converts to `f32`, failing on values that overflow it (the input is finite).
fn to_f32<const N: usize>(
    x: [f64; N],
    what: &'static str,
    vertex: usize,
) -> Result<[f32; N], WriteError> {
    let y = x.map(|x| x as f32);
    if y.iter().all(|y| y.is_finite()) {
        Ok(y)
    } else {
        Err(WriteError::NonFinite { what, vertex })
    }
}

/// The binary buffer with its buffer views and accessors, as glTF JSON.
#[derive(Default)]
struct BufferBuilder {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl BufferBuilder {
    /// Starts a buffer view of `target` holding `data`; returns the view index.
    fn push_view(&mut self, data: impl IntoIterator<Item = [u8; 4]>, target: u32) -> usize {
        // glTF requires accessor offsets aligned to their component size (4 here).
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let offset = self.bytes.len();
        self.bytes.extend(data.into_iter().flatten());
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": self.bytes.len() - offset,
            "target": target,
        }));
        self.views.len() - 1
    }

    /// Adds a float vector attribute of glTF type `kind` (`"VEC2"`, `"VEC3"`), with its
    /// per-component `min`/`max` when `bounds`; returns the accessor index.
    fn push_floats<const N: usize>(
        &mut self,
        data: &[[f32; N]],
        kind: &str,
        target: u32,
        bounds: bool,
    ) -> usize {
        let view = self.push_view(data.iter().flatten().map(|x| x.to_le_bytes()), target);
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": data.len(),
            "type": kind,
        });
        if bounds {
            let mut min = [f32::INFINITY; N];
            let mut max = [f32::NEG_INFINITY; N];
            for x in data {
                for k in 0..N {
                    min[k] = min[k].min(x[k]);
                    max[k] = max[k].max(x[k]);
                }
            }
            accessor["min"] = json!(&min[..]);
            accessor["max"] = json!(&max[..]);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Adds the triangle index list; returns the accessor index.
    fn push_indices(&mut self, indices: &[u32]) -> usize {
        let view = self.push_view(
            indices.iter().map(|i| i.to_le_bytes()),
            ELEMENT_ARRAY_BUFFER,
        );
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": indices.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}
