//! PLY, STL and OFF files through the public reader and writer: round trips that keep
//! positions to the last bit (PLY, OFF) or to `f32` (STL), texture coordinates and
//! colors, the STL weld, and typed errors that name the file, the place and leave no
//! output behind.

use std::path::Path;

use beltrami_mesh::io::{self, Format, ReadError, VertexAttributes, Weld, WriteError};
use beltrami_mesh::primitives::{Cells, jittered_grid, torus};
use beltrami_mesh::{BuildOptions, Mesh, Point3, Vector2};

fn build(soup: &beltrami_mesh::PolygonSoup) -> Mesh {
    Mesh::build(soup, &BuildOptions::default()).unwrap().0
}

fn load(path: &Path) -> io::LoadedMesh {
    io::read(path, &BuildOptions::default()).unwrap()
}

/// Positions whose decimal expansions are long, so that a lossy writer shows.
fn irrational(mesh: &Mesh) -> Vec<Point3<f64>> {
    mesh.positions()
        .iter()
        .map(|p| {
            Point3::new(
                p.x * std::f64::consts::PI,
                p.y / 3.0,
                (p.x * p.y).sqrt() * 1e-7,
            )
        })
        .collect()
}

fn face_lists(mesh: &Mesh) -> Vec<Vec<usize>> {
    mesh.faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.idx()).collect())
        .collect()
}

#[test]
fn ply_and_off_keep_positions_faces_and_texture_coordinates_to_the_last_bit() {
    // Triangles and quads, irregular positions.
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&jittered_grid(7, 5, cells, 0.3, 11));
        let positions = irrational(&mesh);
        let uvs: Vec<Vector2<f64>> = positions
            .iter()
            .map(|p| Vector2::new(p.y, -p.x / 7.0))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        for name in ["out.ply", "out.off"] {
            let path = dir.path().join(name);
            let attributes = VertexAttributes {
                positions: Some(&positions),
                uvs: Some(&uvs),
                ..Default::default()
            };
            io::write(&path, &mesh, &attributes).unwrap();
            let back = load(&path);
            assert_eq!(
                back.mesh.positions(),
                positions.as_slice(),
                "{name} {cells:?}"
            );
            assert_eq!(
                face_lists(&back.mesh),
                face_lists(&mesh),
                "{name} {cells:?}"
            );
            assert_eq!(back.vertex_uvs().unwrap(), uvs, "{name} {cells:?}");
        }
    }
}

#[test]
fn colors_reach_ply_and_coff_and_the_file_still_reads() {
    let mesh = build(&torus(8, 6, 2.0, 0.5, Cells::Triangles));
    let colors: Vec<[f32; 3]> = (0..mesh.vertex_count())
        .map(|v| [v as f32 / 48.0, 0.5, 1.0])
        .collect();
    let attributes = VertexAttributes {
        colors: Some(&colors),
        ..Default::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("c.ply");
    io::write(&ply, &mesh, &attributes).unwrap();
    let bytes = std::fs::read(&ply).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("property uchar red\nproperty uchar green\nproperty uchar blue\n"));
    let off = dir.path().join("c.off");
    io::write(&off, &mesh, &attributes).unwrap();
    let text = std::fs::read_to_string(&off).unwrap();
    assert!(text.starts_with("COFF\n"));
    // Vertex 24: color (0.5, 0.5, 1) with alpha 1 after its position.
    let line = text.lines().nth(2 + 24).unwrap();
    assert!(line.ends_with(" 0.5 0.5 1 1"), "{line}");
    for path in [ply, off] {
        assert_eq!(load(&path).mesh.positions(), mesh.positions());
    }
}

#[test]
fn stl_round_trip_welds_back_to_the_same_mesh_in_f32() {
    let mesh = build(&torus(12, 8, 2.0, 0.5, Cells::Quads));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.stl");
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 84 + 50 * 2 * 96);
    let back = load(&path);
    assert_eq!(
        back.weld,
        Some(Weld {
            corners: 3 * 192,
            vertices: 96
        })
    );
    assert_eq!(back.mesh.face_count(), 192);
    assert_eq!(back.mesh.euler_characteristic(), 0);
    assert!(back.mesh.boundary_loop_sizes().is_empty());
    // Vertices come in order of first appearance; each is the f32 of a source vertex.
    for p in back.mesh.positions() {
        let found = mesh
            .positions()
            .iter()
            .any(|q| (0..3).all(|c| q[c] as f32 as f64 == p[c]));
        assert!(found, "{p:?}");
    }
}

#[test]
fn stl_refuses_texture_coordinates_before_writing_anything() {
    let mesh = build(&jittered_grid(3, 3, Cells::Triangles, 0.0, 1));
    let uvs = vec![Vector2::zeros(); mesh.vertex_count()];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("uv.stl");
    let attributes = VertexAttributes {
        uvs: Some(&uvs),
        ..Default::default()
    };
    let error = io::write(&path, &mesh, &attributes).unwrap_err();
    assert!(matches!(
        error,
        WriteError::Unsupported {
            format: Format::Stl,
            ..
        }
    ));
    assert!(
        error
            .to_string()
            .contains("write .obj, .ply, .off, .gltf or .glb instead"),
        "{error}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn syntax_errors_name_the_file_the_format_and_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[u8], &str); 3] = [
        (
            "bad.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nbogus\n",
            "bad.ply:5: not a valid PLY file: unexpected header line `bogus`",
        ),
        (
            "bad.off",
            b"OFF\n1 0 0\n0 0\n",
            "bad.off:3: not a valid OFF file: vertex 0 has 2 numbers",
        ),
        (
            "bad.stl",
            &[0u8; 90],
            "bad.stl (byte 80): not a valid STL file: the file is not ASCII STL",
        ),
    ];
    for (name, bytes, expected) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let error = io::read(&path, &BuildOptions::default()).unwrap_err();
        assert!(matches!(error, ReadError::Syntax { .. }), "{error:?}");
        assert!(error.to_string().contains(expected), "{error}");
    }
}

#[test]
fn a_mesh_error_in_an_ascii_file_names_the_face_line() {
    // Face 1 repeats a vertex: the builder's error carries the face's line.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rep.off");
    std::fs::write(
        &path,
        "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n# a comment\n3 0 2 2\n",
    )
    .unwrap();
    let error = io::read(&path, &BuildOptions::default()).unwrap_err();
    assert!(
        matches!(error, ReadError::Mesh { line: Some(9), .. }),
        "{error:?}"
    );
}
