//! Bad input found by the hardening campaign: each case ends in a typed error that names
//! the element (vertex, face, line, index as written), never in a panic, a hang or a
//! misleading message; and every mesh the builder accepts can be cut without a panic.

use std::path::Path;

use beltrami_mesh::io::{self, ReadError};
use beltrami_mesh::{
    BuildOptions, MAX_COORDINATE, MIN_EXTENT, Mesh, MeshError, Point3, PolygonSoup, Repair,
    cut_graph, cut_to_disk,
};

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

/// The triangle (0,0,0), (s,0,0), (0,s,0).
fn scaled_triangle(s: f64) -> PolygonSoup {
    PolygonSoup::from_triangles(
        vec![p(0.0, 0.0, 0.0), p(s, 0.0, 0.0), p(0.0, s, 0.0)],
        &[[0, 1, 2]],
    )
}

fn build_error(soup: &PolygonSoup, options: &BuildOptions) -> MeshError {
    match Mesh::build(soup, options) {
        Ok(_) => panic!("the builder accepted a mesh it should refuse"),
        Err(e) => e,
    }
}

#[test]
fn huge_coordinates_are_reported_as_overflow_with_the_range_that_works() {
    for s in [1e308, 1e200, 1e76] {
        let e = build_error(&scaled_triangle(s), &BuildOptions::default());
        assert_eq!(
            e,
            MeshError::CoordinateOverflow {
                vertex: 1,
                value: s,
                max: MAX_COORDINATE
            }
        );
        let text = e.to_string();
        assert!(
            text.contains("overflows") && text.contains("1e75"),
            "{text}"
        );
    }
    // The limit itself works, and the area is right.
    let (mesh, _) = Mesh::build(&scaled_triangle(MAX_COORDINATE), &BuildOptions::default())
        .expect("coordinates at the limit are accepted");
    let area = mesh.total_area();
    assert!((area / (0.5 * MAX_COORDINATE * MAX_COORDINATE) - 1.0).abs() < 1e-12);
}

#[test]
fn tiny_extents_are_reported_as_underflow_with_the_range_that_works() {
    for s in [1e-308, 1e-200, 1e-76] {
        let e = build_error(&scaled_triangle(s), &BuildOptions::default());
        match &e {
            MeshError::ExtentUnderflow { diagonal, min } => {
                assert!((diagonal / s - 2f64.sqrt()).abs() < 1e-12);
                assert_eq!(*min, MIN_EXTENT);
            }
            other => panic!("expected ExtentUnderflow, got {other:?}"),
        }
        let text = e.to_string();
        assert!(
            text.contains("underflows") && text.contains("1e-75"),
            "{text}"
        );
    }
    let (mesh, _) = Mesh::build(&scaled_triangle(MIN_EXTENT), &BuildOptions::default())
        .expect("an extent at the limit is accepted");
    assert!(mesh.total_area() > 0.0);
}

#[test]
fn a_tolerance_that_is_nan_or_infinite_is_refused() {
    for value in [f64::NAN, f64::INFINITY] {
        let options = BuildOptions {
            degenerate_area_tolerance: value,
            ..BuildOptions::default()
        };
        let e = build_error(&scaled_triangle(1.0), &options);
        assert!(
            matches!(e, MeshError::InvalidTolerance { value: v } if v.to_bits() == value.to_bits()),
            "{e:?}"
        );
    }
    // Minus infinity, like any negative tolerance, accepts every face.
    let options = BuildOptions {
        degenerate_area_tolerance: f64::NEG_INFINITY,
        ..BuildOptions::default()
    };
    assert!(Mesh::build(&scaled_triangle(1.0), &options).is_ok());
}

/// The reproducer of the `cut_to_disk` panic ("a vertex deeper than another has a
/// parent"): coordinates near 1e300, a zero tolerance, every repair. The builder now
/// refuses it by its range; the same mesh scaled into range cuts without a panic.
#[test]
fn the_cut_panic_reproducer_is_refused_and_its_scaled_copy_cuts() {
    let options = BuildOptions {
        degenerate_area_tolerance: 0.0,
        repair: Repair::ALL,
    };
    let soup = |big: f64| {
        let mut s = PolygonSoup::new(vec![
            p(1.0, 2.0, 1.0),
            p(0.0, 0.0, 0.0),
            p(big, 1.0, 0.0),
            p(1.0, 0.0, 1.0),
        ]);
        s.push_face(&[0, 3, 1, 2]);
        s.push_face(&[1, 2, 0]);
        s
    };
    assert!(matches!(
        build_error(&soup(1e300), &options),
        MeshError::CoordinateOverflow { vertex: 2, .. }
    ));
    for big in [1e75, 1e10, 3.0] {
        if let Ok((mesh, _)) = Mesh::build(&soup(big), &options) {
            let graph = cut_graph(&mesh);
            assert_eq!(graph.components.len(), mesh.components().len());
            // A disk (or a refusal) either way; only a panic would fail here.
            let _ = cut_to_disk(&mesh);
        }
    }
}

fn obj_error(text: &str) -> ReadError {
    match io::obj::parse(Path::new("t.obj"), text.as_bytes()) {
        Ok(raw) => match io::build_raw(Path::new("t.obj"), raw, &BuildOptions::default()) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e,
        },
        Err(e) => e,
    }
}

#[test]
fn face_indices_out_of_range_are_quoted_as_written() {
    let square = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
    for (index, before) in [("0", 4), ("-9", 4), ("5", 4), ("-5", 4)] {
        let e = obj_error(&format!("{square}f {index} 2 3\n"));
        match &e {
            ReadError::ObjVertexIndex {
                line,
                face,
                written,
                vertex_count,
                before: b,
                ..
            } => {
                assert_eq!(
                    (*line, *face, written.as_str(), *vertex_count, *b),
                    (5, 0, index, 4, before)
                );
            }
            other => panic!("expected ObjVertexIndex, got {other:?}"),
        }
        assert!(e.to_string().contains(&format!("`{index}`")), "{e}");
    }
    // With texture and normal fields, the vertex field is quoted alone.
    let e = obj_error(&format!("{square}vt 0 0\nf 1/1 2/1 3/1\nf -7/1 2/1 3/1\n"));
    assert!(
        e.to_string().contains("`-7`") && e.to_string().contains("face 1"),
        "{e}"
    );
}

#[test]
fn a_nan_texture_coordinate_is_named_not_taken_for_a_seam() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt nan 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let e = obj_error(text);
    assert!(
        matches!(
            e,
            ReadError::NonFiniteTexCoord {
                line: Some(5),
                index: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("not finite"), "{e}");
}

/// A minimal glTF whose only buffer is the file `uri` with `length` declared bytes.
fn gltf_with_buffer(dir: &Path, uri: &str, length: u64) -> std::path::PathBuf {
    let doc = serde_json::json!({
        "asset": { "version": "2.0" },
        "buffers": [{ "uri": uri, "byteLength": length }],
        "bufferViews": [{ "buffer": 0, "byteOffset": 0, "byteLength": 36 }],
        "accessors": [{
            "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
            "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]
        }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
        "nodes": [{ "mesh": 0 }],
        "scenes": [{ "nodes": [0] }],
        "scene": 0
    });
    let path = dir.join("buffer.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

#[test]
fn a_gltf_buffer_on_a_special_file_or_longer_than_its_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    if Path::new("/dev/zero").exists() {
        // Before the fix this read /dev/zero until memory ran out.
        let e = io::gltf::read(&gltf_with_buffer(dir.path(), "/dev/zero", 36)).unwrap_err();
        assert!(
            matches!(&e, ReadError::Io { path, .. } if path == Path::new("/dev/zero")),
            "{e:?}"
        );
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
    let triangle: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    std::fs::write(dir.path().join("tri.bin"), &triangle).unwrap();
    let e = io::gltf::read(&gltf_with_buffer(dir.path(), "tri.bin", 1 << 50)).unwrap_err();
    assert!(
        e.to_string().contains("buffer 0 has 36 bytes")
            && e.to_string().contains(&(1u64 << 50).to_string()),
        "{e}"
    );
    // The same file with its true length reads.
    let raw = io::gltf::read(&gltf_with_buffer(dir.path(), "tri.bin", 36)).unwrap();
    assert_eq!(raw.soup.face_count(), 1);
}

#[test]
fn a_mesh_path_that_is_a_folder_or_a_device_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    let e = io::read_raw(&folder).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
    #[cfg(unix)]
    {
        let link = dir.path().join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let e = io::read_raw(&link).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
}

#[test]
fn stale_temporary_files_of_dead_processes_are_removed_by_the_next_write() {
    if !Path::new("/proc/self").exists() {
        eprintln!("SKIPPED: no /proc to tell dead processes");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // Pid 0 is never a user process: /proc/0 does not exist.
    let stale = dir.path().join(".beltrami-0-abcdef.tmp");
    std::fs::write(&stale, b"half").unwrap();
    let mine = dir
        .path()
        .join(format!(".beltrami-{}-abcdef.tmp", std::process::id()));
    std::fs::write(&mine, b"in use").unwrap();
    let other = dir.path().join("keep.tmp");
    std::fs::write(&other, b"not ours").unwrap();
    io::write_atomically(&dir.path().join("out.txt"), |w| {
        std::io::Write::write_all(w, b"done")
    })
    .unwrap();
    assert!(!stale.exists(), "the stale file of a dead process is left");
    assert!(mine.exists() && other.exists());
    assert_eq!(std::fs::read(dir.path().join("out.txt")).unwrap(), b"done");
}
