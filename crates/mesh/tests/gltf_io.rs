//! glTF / GLB reading and writing: round trips, node transforms and mirrors, strips and
//! fans, scene selection, the input vertex order on output, and errors.

use std::path::{Path, PathBuf};

use base64::Engine as _;
use beltrami_mesh::io::{self, ReadError, VertexAttributes, WriteError, gltf};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{BuildOptions, Mesh, Point3, PolygonSoup, Vector2, Vector3};
use serde_json::{Value, json};

fn load(path: &Path) -> io::LoadedMesh {
    io::read(path, &BuildOptions::default()).unwrap()
}

fn faces_of(soup: &PolygonSoup) -> Vec<Vec<u32>> {
    soup.faces().map(<[u32]>::to_vec).collect()
}

fn assert_close(a: Point3<f64>, b: Point3<f64>, tol: f64) {
    assert!((a - b).norm() <= tol, "{a} != {b}");
}

/// Builds the binary buffer, buffer views and accessors of a hand-written glTF file.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn view(&mut self, data: Vec<u8>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()
        }));
        self.bytes.extend(data);
        self.views.len() - 1
    }

    fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let view = self.view(p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect());
        let min: Vec<f32> = (0..3)
            .map(|k| p.iter().map(|q| q[k]).fold(f32::INFINITY, f32::min))
            .collect();
        let max: Vec<f32> = (0..3)
            .map(|k| p.iter().map(|q| q[k]).fold(f32::NEG_INFINITY, f32::max))
            .collect();
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": p.len(), "type": "VEC3",
            "min": min, "max": max
        }));
        self.accessors.len() - 1
    }

    fn indices(&mut self, i: &[u16]) -> usize {
        let view = self.view(i.iter().flat_map(|x| x.to_le_bytes()).collect());
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5123, "count": i.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// A glTF document with this buffer embedded as a base64 data URI.
    fn document(&self, mut rest: Value) -> Value {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bytes)
        );
        rest["asset"] = json!({ "version": "2.0" });
        rest["buffers"] = json!([{ "byteLength": self.bytes.len(), "uri": uri }]);
        rest["bufferViews"] = json!(self.views);
        rest["accessors"] = json!(self.accessors);
        rest
    }
}

fn write_json(dir: &Path, name: &str, doc: &Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_vec_pretty(doc).unwrap()).unwrap();
    path
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// A file whose mesh 0 is `TRIANGLE` (counter-clockwise seen from +z), with the given
/// nodes and scene list.
fn triangle_file(dir: &Path, name: &str, scenes_and_nodes: Value) -> PathBuf {
    let mut bin = Bin::default();
    let p = bin.positions(&TRIANGLE);
    let i = bin.indices(&[0, 1, 2]);
    let mut doc = bin.document(scenes_and_nodes);
    doc["meshes"] = json!([{ "primitives": [{ "attributes": { "POSITION": p }, "indices": i }] }]);
    write_json(dir, name, &doc)
}

/// The material of the first primitive of a glTF or GLB file, through the gltf crate.
fn first_material(bytes: &[u8]) -> Option<Material> {
    let doc = ::gltf::Gltf::from_slice(bytes).unwrap();
    let primitive = doc.meshes().next()?.primitives().next()?;
    let material = primitive.material();
    material.index().map(|_| Material {
        double_sided: material.double_sided(),
        metallic: material.pbr_metallic_roughness().metallic_factor(),
    })
}

struct Material {
    double_sided: bool,
    metallic: f32,
}

#[test]
fn triangle_mesh_round_trips_through_glb_and_gltf() {
    let soup = icosphere(2);
    let mesh = Mesh::from_soup(&soup).unwrap();
    let uvs: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(0.5 + 0.5 * p.x, 0.25 - p.y / 3.0))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    for name in ["sphere.glb", "sphere.gltf", "SPHERE.GLB"] {
        let path = dir.path().join(name);
        let attributes = VertexAttributes {
            uvs: Some(&uvs),
            ..Default::default()
        };
        io::write(&path, &mesh, &attributes).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            bytes.starts_with(b"glTF"),
            name.to_lowercase().ends_with(".glb")
        );
        // The texture coordinates' primitive has the two-sided material loaders need.
        let material = first_material(&bytes).expect("a material");
        assert!(material.double_sided);
        assert_eq!(material.metallic, 0.0);

        let loaded = load(&path);
        let back = &loaded.mesh;
        assert_eq!(back.vertex_count(), mesh.vertex_count());
        assert_eq!(back.face_count(), mesh.face_count());
        assert_eq!(loaded.report.faces_reoriented, 0);
        for f in mesh.faces() {
            assert!(
                back.face_vertices(f).eq(mesh.face_vertices(f)),
                "face {f:?}"
            );
        }
        for v in mesh.vertices() {
            let (a, b) = (mesh.position(v), back.position(v));
            assert!(
                (a - b).norm() <= 1e-6 * a.coords.norm(),
                "vertex {v:?}: {a} vs {b}"
            );
        }
        let back_uvs = loaded.vertex_uvs().expect("uvs read back");
        for (a, b) in uvs.iter().zip(&back_uvs) {
            assert!((a - b).norm() <= 1e-7, "{a} vs {b}");
        }
    }
}

#[test]
fn files_without_uvs_read_back_without_uvs() {
    let mesh = Mesh::from_soup(&torus(12, 8, 2.0, 0.5, Cells::Triangles)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.glb");
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    assert!(first_material(&std::fs::read(&path).unwrap()).is_none());
    let loaded = load(&path);
    assert!(loaded.corner_uvs.is_none());
    assert_eq!(loaded.mesh.genus(), Some(1));
    assert_eq!(loaded.mesh.face_count(), mesh.face_count());
}

#[test]
fn quads_are_written_as_two_triangles() {
    let mesh = Mesh::from_soup(&grid(4, 3, Cells::Quads)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for name in ["grid.glb", "grid.gltf"] {
        let path = dir.path().join(name);
        io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
        let back = load(&path).mesh;
        assert_eq!(back.face_count(), 2 * mesh.face_count());
        assert_eq!(back.triangle_count(), back.face_count());
        assert_eq!(back.vertex_count(), mesh.vertex_count());
        assert_eq!(back.euler_characteristic(), mesh.euler_characteristic());
        assert!(back.is_disk());
        assert!((back.total_area() - mesh.total_area()).abs() < 1e-6);
        // Quad (v0, v1, v2, v3) becomes (v0, v1, v2) and (v0, v2, v3), facing +z.
        let (q, _) = mesh.face_vertex_array(mesh.faces().next().unwrap());
        let mut faces = back.faces();
        let t0: Vec<_> = back.face_vertices(faces.next().unwrap()).collect();
        let t1: Vec<_> = back.face_vertices(faces.next().unwrap()).collect();
        assert_eq!(t0, vec![q[0], q[1], q[2]]);
        assert_eq!(t1, vec![q[0], q[2], q[3]]);
        for f in back.faces() {
            assert!(back.face_normal(f).z > 0.99);
        }
    }
}

#[test]
fn node_transforms_compose_from_the_root() {
    let dir = tempfile::tempdir().unwrap();
    // The child's matrix (column-major) scales by 2 and translates by (0, 0, 5); the
    // parent translates by (10, 0, 0). A transposed matrix would lose the z translation.
    let child_matrix = [
        2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 5.0, 1.0,
    ];
    let path = triangle_file(
        dir.path(),
        "nested.gltf",
        json!({
            "scene": 0,
            "scenes": [{ "nodes": [0] }],
            "nodes": [
                { "translation": [10.0, 0.0, 0.0], "children": [1] },
                { "matrix": child_matrix, "mesh": 0 }
            ]
        }),
    );
    let raw = gltf::read(&path).unwrap();
    let expected = [
        Point3::new(10.0, 0.0, 5.0),
        Point3::new(12.0, 0.0, 5.0),
        Point3::new(10.0, 2.0, 5.0),
    ];
    assert_eq!(raw.soup.positions.len(), 3);
    for (a, b) in raw.soup.positions.iter().zip(expected) {
        assert_close(*a, b, 1e-12);
    }
    assert_eq!(faces_of(&raw.soup), vec![vec![0, 1, 2]]);
    assert!(raw.corner_uvs.is_none());
    assert!(raw.face_lines.is_none());
}

#[test]
fn mirrored_instances_keep_their_front_face() {
    // One triangle, counter-clockwise seen from +z, instanced twice: translated, and
    // mirrored in x. The mirror turns the transformed vertices clockwise seen from +z;
    // glTF then takes clockwise as the front face, so the front still faces +z and the
    // reader must reverse that triangle to keep it counter-clockwise from its front.
    let dir = tempfile::tempdir().unwrap();
    let path = triangle_file(
        dir.path(),
        "mirror.gltf",
        json!({
            "scene": 0,
            "scenes": [{ "nodes": [0, 1] }],
            "nodes": [
                { "translation": [3.0, 0.0, 0.0], "mesh": 0 },
                { "scale": [-1.0, 1.0, 1.0], "mesh": 0 }
            ]
        }),
    );
    let raw = gltf::read(&path).unwrap();
    assert_eq!(raw.soup.positions.len(), 6);
    assert_close(raw.soup.positions[3], Point3::new(0.0, 0.0, 0.0), 0.0);
    assert_close(raw.soup.positions[4], Point3::new(-1.0, 0.0, 0.0), 0.0);
    assert_close(raw.soup.positions[5], Point3::new(0.0, 1.0, 0.0), 0.0);
    // Without the reversal the mirrored face would be [3, 4, 5], facing -z.
    assert_eq!(faces_of(&raw.soup), vec![vec![0, 1, 2], vec![3, 5, 4]]);

    let mesh = load(&path).mesh;
    assert_eq!(mesh.component_count(), 2);
    for f in mesh.faces() {
        let n = mesh.face_normal(f);
        assert!((n - Vector3::z()).norm() < 1e-12, "face {f:?} normal {n}");
    }
}

#[test]
fn strips_and_fans_become_consistently_oriented_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    // Unit square as a strip 0-1-2-3 (zigzag) with a trailing repeated index, and as a fan
    // around corner 0; a point primitive that must be ignored.
    let strip_p = bin.positions(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let strip_i = bin.indices(&[0, 1, 2, 3, 3]);
    let fan_p = bin.positions(&[
        [2.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
        [3.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
    ]);
    let fan_i = bin.indices(&[0, 1, 2, 3]);
    let points_p = bin.positions(&[[9.0, 9.0, 9.0]]);
    let mut doc = bin.document(json!({}));
    doc["meshes"] = json!([
        { "primitives": [
            { "attributes": { "POSITION": strip_p }, "indices": strip_i, "mode": 5 },
            { "attributes": { "POSITION": points_p }, "mode": 0 }
        ] },
        { "primitives": [
            { "attributes": { "POSITION": fan_p }, "indices": fan_i, "mode": 6 }
        ] }
    ]);
    // No scenes at all: every mesh once, untransformed.
    let path = write_json(dir.path(), "strips.gltf", &doc);
    let raw = gltf::read(&path).unwrap();
    assert_eq!(raw.soup.positions.len(), 8);
    assert_eq!(
        faces_of(&raw.soup),
        vec![vec![0, 1, 2], vec![1, 3, 2], vec![4, 5, 6], vec![4, 6, 7]]
    );
    let mesh = load(&path).mesh;
    assert_eq!(mesh.face_count(), 4);
    assert_eq!(mesh.component_count(), 2);
    assert!((mesh.total_area() - 2.0).abs() < 1e-12);
    for f in mesh.faces() {
        assert!(mesh.face_normal(f).z > 0.99, "face {f:?}");
    }
}

#[test]
fn the_default_scene_is_read_else_every_scene() {
    let dir = tempfile::tempdir().unwrap();
    let nodes = json!([
        { "translation": [0.0, 0.0, 1.0], "mesh": 0 },
        { "translation": [0.0, 0.0, 2.0], "mesh": 0 }
    ]);
    let z_of = |path: &Path| -> Vec<f64> {
        let raw = gltf::read(path).unwrap();
        raw.soup.positions.iter().step_by(3).map(|p| p.z).collect()
    };
    let default_1 = triangle_file(
        dir.path(),
        "default.gltf",
        json!({ "scene": 1, "scenes": [{ "nodes": [0] }, { "nodes": [1] }], "nodes": nodes }),
    );
    assert_eq!(z_of(&default_1), vec![2.0]);
    let no_default = triangle_file(
        dir.path(),
        "all.gltf",
        json!({ "scenes": [{ "nodes": [1] }, { "nodes": [0] }], "nodes": nodes }),
    );
    assert_eq!(z_of(&no_default), vec![2.0, 1.0]);
}

#[test]
fn unreferenced_vertices_keep_their_slots_on_write() {
    let positions = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(5.0, 6.0, 7.0),
        Point3::new(1.0, 1.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let soup = PolygonSoup::from_triangles(positions.clone(), &[[0, 1, 3], [0, 3, 4]]);
    let (mesh, report) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
    assert_eq!(report.unreferenced_vertices, vec![2]);
    assert_eq!(mesh.vertex_count(), 4);
    let uvs: Vec<Vector2<f64>> = mesh.positions().iter().map(|p| p.xy().coords).collect();
    let colors: Vec<[f32; 3]> = mesh.vertices().map(|_| [1.0, 0.5, 0.25]).collect();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("holes.glb");
    let attributes = VertexAttributes {
        uvs: Some(&uvs),
        colors: Some(&colors),
        ..Default::default()
    };
    io::write(&path, &mesh, &attributes).unwrap();
    let raw = gltf::read(&path).unwrap();
    assert_eq!(raw.soup.positions, positions);
    assert_eq!(faces_of(&raw.soup), faces_of(&soup));
    let corner_uvs = raw.corner_uvs.unwrap();
    let expected: Vec<Vector2<f64>> = soup
        .faces()
        .flatten()
        .map(|&i| positions[i as usize].xy().coords)
        .collect();
    assert_eq!(corner_uvs, expected);

    // The colors, through the gltf crate itself (which also validates the document).
    let doc = ::gltf::Gltf::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let blob = doc.blob.as_deref().unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let read: Vec<[f32; 3]> = prim
        .reader(|_| Some(blob))
        .read_colors(0)
        .unwrap()
        .into_rgb_f32()
        .collect();
    assert_eq!(read.len(), 5);
    assert_eq!(read[2], [0.0, 0.0, 0.0]);
    for i in [0, 1, 3, 4] {
        assert_eq!(read[i], [1.0, 0.5, 0.25]);
    }
}

#[test]
fn glb_container_is_well_formed() {
    let mesh = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grid.glb");
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32_at(4), 2);
    assert_eq!(u32_at(8), bytes.len());
    let json_len = u32_at(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let bin_start = 20 + json_len;
    let bin_len = u32_at(bin_start);
    assert_eq!(&bytes[bin_start + 4..bin_start + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_start + 8 + bin_len, bytes.len());

    let doc: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    assert_eq!(doc["asset"]["version"], "2.0");
    assert_eq!(doc["asset"]["generator"], "beltrami");
    assert_eq!(doc["scene"], 0);
    for view in doc["bufferViews"].as_array().unwrap() {
        assert_eq!(view["byteOffset"].as_u64().unwrap() % 4, 0);
    }
    let position = &doc["accessors"][0];
    assert_eq!(position["min"], json!([0.0, 0.0, 0.0]));
    assert_eq!(position["max"], json!([1.0, 1.0, 0.0]));
    let prim = &doc["meshes"][0]["primitives"][0];
    assert_eq!(prim["mode"], 4);
    let indices = &doc["accessors"][prim["indices"].as_u64().unwrap() as usize];
    assert_eq!(indices["componentType"], 5125);
    assert_eq!(indices["count"], 3 * mesh.face_count());
    let view = &doc["bufferViews"][indices["bufferView"].as_u64().unwrap() as usize];
    assert_eq!(view["target"], 34963);
}

fn read_error(path: &Path) -> String {
    match gltf::read(path) {
        Err(ReadError::Gltf { message, .. }) => message,
        other => panic!("expected a glTF error, got {other:?}"),
    }
}

#[test]
fn malformed_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.glb");
    std::fs::write(&garbage, [0x13u8, 0x37, 0xfe, 0x00, 0x42, 0x99, 0x01]).unwrap();
    read_error(&garbage);

    let mut short_header = b"glTF".to_vec();
    short_header.extend(2u32.to_le_bytes());
    short_header.extend(4u32.to_le_bytes());
    short_header.extend([0u8; 16]);
    let short = dir.path().join("short.glb");
    std::fs::write(&short, short_header).unwrap();
    read_error(&short);

    let missing = dir.path().join("missing.gltf");
    assert!(matches!(gltf::read(&missing), Err(ReadError::Io { .. })));
}

#[test]
fn a_buffer_file_that_does_not_exist_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let p = bin.positions(&TRIANGLE);
    let mut doc = bin.document(json!({}));
    doc["buffers"][0]["uri"] = json!("nowhere.bin");
    doc["meshes"] = json!([{ "primitives": [{ "attributes": { "POSITION": p } }] }]);
    let path = write_json(dir.path(), "external.gltf", &doc);
    match gltf::read(&path) {
        Err(ReadError::Io { path, .. }) => assert!(path.ends_with("nowhere.bin")),
        other => panic!("expected an IO error, got {other:?}"),
    }
    // Present but shorter than its byteLength.
    std::fs::write(dir.path().join("nowhere.bin"), [0u8; 8]).unwrap();
    assert!(read_error(&path).contains("buffer 0"));
}

#[test]
fn a_file_with_only_lines_has_no_triangle_primitives() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let p = bin.positions(&TRIANGLE);
    let i = bin.indices(&[0, 1, 1, 2]);
    let mut doc = bin.document(json!({}));
    doc["meshes"] = json!([{ "primitives": [
        { "attributes": { "POSITION": p }, "indices": i, "mode": 1 }
    ] }]);
    let path = write_json(dir.path(), "lines.gltf", &doc);
    assert!(read_error(&path).contains("no triangle primitives"));
}

#[test]
fn bad_accessors_and_indices_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let base = || {
        let mut bin = Bin::default();
        let p = bin.positions(&TRIANGLE);
        let i = bin.indices(&[0, 1, 2]);
        let mut doc = bin.document(json!({}));
        doc["meshes"] =
            json!([{ "primitives": [{ "attributes": { "POSITION": p }, "indices": i }] }]);
        doc
    };

    // POSITION names an accessor that does not exist.
    let mut doc = base();
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(7);
    let message = read_error(&write_json(dir.path(), "a.gltf", &doc));
    assert!(message.contains("accessor 7"), "{message}");

    // More elements than the buffer view holds.
    let mut doc = base();
    doc["accessors"][0]["count"] = json!(1_000_000_000_000u64);
    read_error(&write_json(dir.path(), "b.gltf", &doc));

    // Positions given as two-component vectors.
    let mut doc = base();
    doc["accessors"][0]["type"] = json!("VEC2");
    doc["accessors"][0]["count"] = json!(4);
    read_error(&write_json(dir.path(), "c.gltf", &doc));

    // A stride shorter than a position.
    let mut doc = base();
    doc["bufferViews"][0]["byteStride"] = json!(4);
    read_error(&write_json(dir.path(), "d.gltf", &doc));

    // An index past the primitive's vertices.
    let mut bin = Bin::default();
    let p = bin.positions(&TRIANGLE);
    let i = bin.indices(&[0, 1, 3]);
    let mut doc = bin.document(json!({}));
    doc["meshes"] = json!([{ "primitives": [{ "attributes": { "POSITION": p }, "indices": i }] }]);
    let message = read_error(&write_json(dir.path(), "e.gltf", &doc));
    assert!(message.contains("index 3"), "{message}");

    // Triangle list of 2 indices.
    let mut bin = Bin::default();
    let p = bin.positions(&TRIANGLE);
    let i = bin.indices(&[0, 1]);
    let mut doc = bin.document(json!({}));
    doc["meshes"] = json!([{ "primitives": [{ "attributes": { "POSITION": p }, "indices": i }] }]);
    read_error(&write_json(dir.path(), "f.gltf", &doc));

    // A node hierarchy with a cycle.
    let path = triangle_file(
        dir.path(),
        "cycle.gltf",
        json!({
            "scene": 0,
            "scenes": [{ "nodes": [0] }],
            "nodes": [{ "children": [1] }, { "children": [0], "mesh": 0 }]
        }),
    );
    read_error(&path);
}

#[test]
fn write_errors_leave_nothing_behind() {
    let mesh = Mesh::from_soup(&icosphere(1)).unwrap();
    let dir = tempfile::tempdir().unwrap();

    let path = dir.path().join("short_uvs.glb");
    let uvs = vec![Vector2::new(0.0, 0.0); mesh.vertex_count() - 1];
    let attributes = VertexAttributes {
        uvs: Some(&uvs),
        ..Default::default()
    };
    assert!(matches!(
        io::write(&path, &mesh, &attributes),
        Err(WriteError::AttributeLength { what: "uvs", .. })
    ));
    assert!(!path.exists());

    let huge: Vec<Point3<f64>> = mesh.positions().iter().map(|p| p * 1e300).collect();
    let attributes = VertexAttributes {
        positions: Some(&huge),
        ..Default::default()
    };
    let path = dir.path().join("huge.gltf");
    assert!(matches!(
        io::write(&path, &mesh, &attributes),
        Err(WriteError::NonFinite {
            what: "position",
            ..
        })
    ));
    assert!(!path.exists());

    let missing_dir = dir.path().join("no_such_dir");
    for name in ["out.glb", "out.gltf"] {
        let path = missing_dir.join(name);
        assert!(matches!(
            io::write(&path, &mesh, &VertexAttributes::default()),
            Err(WriteError::Io { .. })
        ));
        assert!(!missing_dir.exists());
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn node_transforms_must_be_finite_and_rotations_unit_quaternions() {
    let dir = tempfile::tempdir().unwrap();
    let node = |node: Value| json!({ "scene": 0, "scenes": [{ "nodes": [0] }], "nodes": [node] });
    let far = triangle_file(
        dir.path(),
        "far.gltf",
        node(json!({ "translation": [1e300, 0.0, 0.0], "mesh": 0 })),
    );
    assert!(read_error(&far).contains("node 0: its translation, rotation or scale is not finite"));
    // A quaternion of length 2 would scale the mesh by 4.
    let long = triangle_file(
        dir.path(),
        "long.gltf",
        node(json!({ "rotation": [0.0, 0.0, 0.0, 2.0], "mesh": 0 })),
    );
    assert!(
        read_error(&long).contains("rotation quaternion has length 2, not 1"),
        "{}",
        read_error(&long)
    );
    let unit = triangle_file(
        dir.path(),
        "unit.gltf",
        node(
            json!({ "rotation": [0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2, std::f32::consts::FRAC_1_SQRT_2], "mesh": 0 }),
        ),
    );
    let raw = gltf::read(&unit).unwrap();
    // A quarter turn about z: (1, 0, 0) goes to (0, 1, 0).
    assert!((raw.soup.positions[1] - Point3::new(0.0, 1.0, 0.0)).norm() < 1e-6);
}
