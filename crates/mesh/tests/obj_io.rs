//! OBJ reading and writing: the file's vertex order, texture coordinates, errors with
//! line numbers, round trips and atomic output.

use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, ReadError, VertexAttributes, WriteError, obj};
use beltrami_mesh::primitives::{Cells, grid, icosphere};
use beltrami_mesh::{BuildOptions, Mesh, MeshError, Point3, Vector2, VertexId};

fn write_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn load(path: &Path) -> io::LoadedMesh {
    io::read(path, &BuildOptions::default()).unwrap()
}

/// The `v` lines of an OBJ text, in order.
fn v_lines(text: &str) -> Vec<Point3<f64>> {
    text.lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            Point3::new(c[0], c[1], c[2])
        })
        .collect()
}

// Two triangles and a quad whose faces use the vertices far from file order, with
// groups, materials and normals in between, and a face that comes before some `v` lines.
const SHUFFLED: &str = "\
mtllib missing.mtl
o first
v 2 0 0
v 0 0 0
v 2 1 0
vn 0 0 1
g part_a
usemtl red
v 1 1 0
v 1 0 0
f 5//1 3//1 4//1
f 2 5 4
s 1
v 3 0 0
v 3 1 0
g part_b
f 1 6 7 3
f 5 1 3
";

#[test]
fn objects_groups_and_materials_are_written_back_before_their_faces() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_file(dir.path(), "shuffled.obj", SHUFFLED);
    let loaded = load(&path);
    let uvs: Vec<Vector2<f64>> = loaded
        .mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(p.x, p.y))
        .collect();
    let out = dir.path().join("out.obj");
    let attributes = VertexAttributes {
        uvs: Some(&uvs),
        obj_groups: &loaded.obj_groups,
        ..Default::default()
    };
    io::write(&out, &loaded.mesh, &attributes).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let after_vertices: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("v ") && !l.starts_with("vt ") && !l.starts_with('#'))
        .map(|l| l.split(' ').next().unwrap())
        .collect();
    assert_eq!(
        after_vertices,
        ["mtllib", "o", "g", "usemtl", "f", "f", "s", "g", "f", "f"],
        "{text}"
    );
    assert!(
        text.contains("g part_a\nusemtl red\nf 5/5 3/3 4/4\n"),
        "{text}"
    );
    // The output reads back to the same groups.
    assert_eq!(load(&out).obj_groups, loaded.obj_groups);
}

#[test]
fn vertex_indices_follow_the_file_when_faces_use_them_out_of_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_file(dir.path(), "shuffled.obj", SHUFFLED);
    let raw = obj::read(&path).unwrap();
    let expected = v_lines(SHUFFLED);
    assert_eq!(raw.soup.positions, expected);
    let faces: Vec<Vec<u32>> = raw.soup.faces().map(<[u32]>::to_vec).collect();
    assert_eq!(
        faces,
        vec![
            vec![4, 2, 3],
            vec![1, 4, 3],
            vec![0, 5, 6, 2],
            vec![4, 0, 2]
        ]
    );
    assert_eq!(raw.face_lines, Some(vec![11, 12, 17, 18]));

    let loaded = load(&path);
    let mesh = &loaded.mesh;
    assert!(mesh.vertex_map().is_identity());
    for (i, p) in expected.iter().enumerate() {
        let v = mesh.vertex_map().from_input(i).unwrap();
        assert_eq!(mesh.position(v), *p);
        assert_eq!(mesh.vertex_map().to_input(v), i);
    }
    assert_eq!(mesh.face_count(), 4);
    assert_eq!(mesh.quad_count(), 1);
    assert_eq!(mesh.component_count(), 1);
    assert!(mesh.is_disk());
    assert!((mesh.total_area() - 2.5).abs() < 1e-12);
}

#[test]
fn unreferenced_vertices_keep_the_file_numbering_and_survive_a_write() {
    let text = "\
v 9 9 9
v 0 0 0
v 1 0 0
v 5 5 5
v 1 1 0
v 0 1 0
v 7 7 7
f 2 3 5 6
";
    let dir = tempfile::tempdir().unwrap();
    let path = write_file(dir.path(), "unref.obj", text);
    let loaded = load(&path);
    let mesh = &loaded.mesh;
    assert_eq!(mesh.vertex_count(), 4);
    assert_eq!(loaded.report.unreferenced_vertices, vec![0, 3, 6]);
    let map = mesh.vertex_map();
    assert_eq!(map.input_len(), 7);
    for i in [0, 3, 6] {
        assert_eq!(map.from_input(i), None);
    }
    for (i, p) in v_lines(text).iter().enumerate() {
        if let Some(v) = map.from_input(i) {
            assert_eq!(mesh.position(v), *p);
        }
    }
    assert_eq!(map.to_input(VertexId(0)), 1);

    // Written back, vertex k of the output is vertex k of the input, with a per-vertex
    // uv on the referenced ones.
    let uv: Vec<Vector2<f64>> = mesh
        .vertices()
        .map(|v| mesh.position(v).xy().coords)
        .collect();
    let out = dir.path().join("out.obj");
    obj::write(
        &out,
        mesh,
        &VertexAttributes {
            uvs: Some(&uv),
            ..Default::default()
        },
    )
    .unwrap();
    let written = std::fs::read_to_string(&out).unwrap();
    assert_eq!(v_lines(&written), v_lines(text));
    assert!(written.contains("f 2/2 3/3 5/5 6/6"));
    let back = load(&out);
    assert_eq!(back.report.unreferenced_vertices, vec![0, 3, 6]);
    let back_uv = back.vertex_uvs().unwrap();
    for v in back.mesh.vertices() {
        assert_eq!(back_uv[v.idx()], back.mesh.position(v).xy().coords);
    }
}

#[test]
fn relative_indices_and_crlf_line_ends() {
    let text = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf -3 -2 -1\r\nv 1 1 0\r\nf -3 -1 -2\r\n";
    let dir = tempfile::tempdir().unwrap();
    let raw = obj::read(&write_file(dir.path(), "rel.obj", text)).unwrap();
    let faces: Vec<Vec<u32>> = raw.soup.faces().map(<[u32]>::to_vec).collect();
    assert_eq!(faces, vec![vec![0, 1, 2], vec![1, 3, 2]]);
    assert_eq!(raw.soup.positions[3], Point3::new(1.0, 1.0, 0.0));
}

#[test]
fn corner_texture_coordinates_and_seams() {
    // Two triangles sharing the edge 1-3; vertex 3 has a different uv in each face.
    let text = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 0.5
f 1/1 2/2 4/4
f 2/2 3/3 4/5
";
    let dir = tempfile::tempdir().unwrap();
    let loaded = load(&write_file(dir.path(), "seam.obj", text));
    let corner = loaded.corner_uvs.as_ref().unwrap();
    let mesh = &loaded.mesh;
    for f in mesh.faces() {
        for h in mesh.face_halfedges(f) {
            let v = mesh.vertex_map().to_input(mesh.origin(h));
            let expected = match (f.idx(), v) {
                (1, 3) => Vector2::new(0.5, 0.5),
                (_, 0) => Vector2::new(0.0, 0.0),
                (_, 1) => Vector2::new(1.0, 0.0),
                (_, 2) => Vector2::new(1.0, 1.0),
                _ => Vector2::new(0.0, 1.0),
            };
            assert_eq!(corner[h.idx()], expected, "face {f} vertex {v}");
        }
    }
    assert!(loaded.vertex_uvs().is_none(), "a seam has no per-vertex uv");

    // Without the seam, per-vertex uvs exist.
    let no_seam = text.replace("4/5", "4/4");
    let loaded = load(&write_file(dir.path(), "noseam.obj", &no_seam));
    let uv = loaded.vertex_uvs().unwrap();
    for v in loaded.mesh.vertices() {
        assert_eq!(uv[v.idx()], loaded.mesh.position(v).xy().coords);
    }

    // A face without texture coordinates means none are kept.
    let partial = text.replace("f 2/2 3/3 4/5", "f 2 3 4");
    let loaded = load(&write_file(dir.path(), "partial.obj", &partial));
    assert!(loaded.corner_uvs.is_none());
}

#[test]
fn reoriented_faces_keep_their_texture_coordinates() {
    // The second face is listed clockwise; it is flipped on build and each of its
    // corners must keep its own uv.
    let text = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3
f 1/1 4/4 3/3
";
    let dir = tempfile::tempdir().unwrap();
    let loaded = load(&write_file(dir.path(), "flip.obj", text));
    assert_eq!(loaded.report.faces_reoriented, 1);
    let uv = loaded.vertex_uvs().unwrap();
    for v in loaded.mesh.vertices() {
        assert_eq!(uv[v.idx()], loaded.mesh.position(v).xy().coords);
    }
    for f in loaded.mesh.faces() {
        assert!(loaded.mesh.face_normal(f).z > 0.99);
    }
}

#[test]
fn round_trip_gives_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for (name, soup) in [
        ("sphere.obj", icosphere(3)),
        ("quads.obj", grid(7, 5, Cells::Quads)),
    ] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let uv: Vec<Vector2<f64>> = mesh
            .vertices()
            .map(|v| Vector2::new(mesh.position(v).x * 0.5, mesh.position(v).y / 3.0))
            .collect();
        let path = dir.path().join(name);
        io::write(
            &path,
            &mesh,
            &VertexAttributes {
                uvs: Some(&uv),
                ..Default::default()
            },
        )
        .unwrap();
        let back = load(&path);
        assert_eq!(back.mesh.vertex_count(), mesh.vertex_count());
        assert_eq!(back.mesh.face_count(), mesh.face_count());
        assert_eq!(
            back.mesh.positions(),
            mesh.positions(),
            "positions are exact"
        );
        for f in mesh.faces() {
            assert!(
                back.mesh.face_vertices(f).eq(mesh.face_vertices(f)),
                "face {f}"
            );
        }
        assert_eq!(back.vertex_uvs().unwrap(), uv);
    }
}

#[test]
fn written_positions_can_replace_the_mesh_positions() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
    let lifted: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.x * p.y))
        .collect();
    let path = dir.path().join("lifted.obj");
    obj::write(
        &path,
        &mesh,
        &VertexAttributes {
            positions: Some(&lifted),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(load(&path).mesh.positions(), lifted.as_slice());
}

fn read_err(text: &str) -> ReadError {
    let dir = tempfile::tempdir().unwrap();
    io::read(
        &write_file(dir.path(), "bad.obj", text),
        &BuildOptions::default(),
    )
    .unwrap_err()
}

#[test]
fn a_bad_vertex_line_is_named_by_line() {
    let err = read_err("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
    match err {
        ReadError::Obj { line, .. } => assert_eq!(line, Some(2)),
        e => panic!("unexpected {e:?}"),
    }
}

#[test]
fn an_out_of_range_index_names_face_index_and_line() {
    let err = read_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# comment\nf 1 3 9\n");
    match &err {
        ReadError::ObjVertexIndex {
            line,
            face,
            written,
            vertex_count,
            before,
            ..
        } => {
            // The index is quoted as written in the file (1-based), not converted.
            assert_eq!(
                (*line, *face, written.as_str(), *vertex_count, *before),
                (6, 1, "9", 3, 3)
            );
        }
        e => panic!("unexpected {e:?}"),
    }
    assert!(err.to_string().contains("bad.obj:6"), "{err}");
    assert!(err.to_string().contains("`9`"), "{err}");
}

#[test]
fn an_unparsable_face_is_named_by_line() {
    let err = read_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
    assert!(
        matches!(err, ReadError::Obj { line: Some(4), .. }),
        "{err:?}"
    );
}

#[test]
fn polygons_and_lines_are_rejected_with_their_line() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 0\nf 1 2 3\nf 1 2 3 5 4\n";
    match read_err(text) {
        ReadError::Mesh {
            line: Some(7),
            error: MeshError::UnsupportedFaceSize { face: 1, size: 5 },
            ..
        } => {}
        e => panic!("unexpected {e:?}"),
    }
    match read_err("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2\n") {
        ReadError::Mesh {
            line: Some(4),
            error: MeshError::UnsupportedFaceSize { face: 0, size: 2 },
            ..
        } => {}
        e => panic!("unexpected {e:?}"),
    }
}

#[test]
fn nan_coordinates_name_the_vertex() {
    match read_err("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n") {
        ReadError::Mesh {
            error: MeshError::NonFiniteCoordinate { vertex: 2, .. },
            ..
        } => {}
        e => panic!("unexpected {e:?}"),
    }
}

#[test]
fn a_file_without_faces_is_an_error() {
    match read_err("v 0 0 0\nv 1 0 0\n") {
        ReadError::Mesh {
            error: MeshError::NoFaces,
            ..
        } => {}
        e => panic!("unexpected {e:?}"),
    }
    match read_err("") {
        ReadError::Mesh {
            error: MeshError::NoFaces,
            ..
        } => {}
        e => panic!("unexpected {e:?}"),
    }
}

#[test]
fn missing_files_and_unknown_formats_are_typed_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.obj");
    assert!(matches!(
        io::read(&missing, &BuildOptions::default()),
        Err(ReadError::Io { .. })
    ));
    let xyz = write_file(dir.path(), "mesh.xyz", "0 0 0\n");
    assert!(matches!(
        io::read(&xyz, &BuildOptions::default()),
        Err(ReadError::UnknownFormat { .. })
    ));
    // STL is a known format: a solid without facets or `endsolid` is a syntax error.
    let stl = write_file(dir.path(), "mesh.stl", "solid x\n");
    assert!(matches!(
        io::read(&stl, &BuildOptions::default()),
        Err(ReadError::Syntax { .. })
    ));
}

#[test]
fn failed_writes_leave_no_file_and_keep_an_existing_one() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
    let short = vec![Vector2::zeros(); 3];
    let bad = VertexAttributes {
        uvs: Some(&short),
        ..Default::default()
    };

    let fresh = dir.path().join("fresh.obj");
    assert!(matches!(
        obj::write(&fresh, &mesh, &bad),
        Err(WriteError::AttributeLength {
            expected: 9,
            got: 3,
            ..
        })
    ));
    assert!(!fresh.exists());

    let existing = write_file(dir.path(), "existing.obj", "keep me\n");
    assert!(obj::write(&existing, &mesh, &bad).is_err());
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "keep me\n");

    let nan = vec![Vector2::new(f64::NAN, 0.0); mesh.vertex_count()];
    assert!(matches!(
        obj::write(
            &existing,
            &mesh,
            &VertexAttributes {
                uvs: Some(&nan),
                ..Default::default()
            }
        ),
        Err(WriteError::NonFinite { .. })
    ));
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "keep me\n");

    let nowhere = dir.path().join("no/such/dir/out.obj");
    assert!(matches!(
        obj::write(&nowhere, &mesh, &VertexAttributes::default()),
        Err(WriteError::Io { .. })
    ));

    // Nothing but the one file we made is left in the folder (no temporary files).
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("existing.obj")]);
}

#[test]
fn a_group_line_after_faces_leaves_the_numbering_and_the_faces_as_they_were() {
    // Read as it is until the `o` line; from there the reader copies the lines it keeps.
    let plain = "# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\nv 1 1 0\nf 2 4 3\n";
    let grouped =
        "# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no second\nv 1 1 0\ng g\nf 2 4 3\n";
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, text: &str| obj::read(&write_file(dir.path(), name, text)).unwrap();
    let (a, b) = (read("plain.obj", plain), read("grouped.obj", grouped));
    assert_eq!(a.soup.positions, v_lines(plain));
    assert_eq!(b.soup.positions, a.soup.positions);
    let faces = |raw: &io::RawMesh| raw.soup.faces().map(<[u32]>::to_vec).collect::<Vec<_>>();
    assert_eq!(faces(&a), vec![vec![0, 1, 2], vec![1, 3, 2]]);
    assert_eq!(faces(&b), faces(&a));
    assert_eq!(a.face_lines, Some(vec![5, 8]));
    assert_eq!(b.face_lines, Some(vec![5, 9]));
}
