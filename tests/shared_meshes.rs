//! Topology of every mesh in `../shared/meshes/` against the table of its README, and the
//! typed errors of the dirty ones. Skipped, with a message, when `../shared` is absent
//! (a user's fresh clone); CI has it.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami::mesh::io::{self, ReadError};
use beltrami::mesh::{BuildOptions, MeshError};

fn shared_meshes() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    if dir.is_dir() {
        Some(dir)
    } else {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: {} not found; the shared-mesh tests need ../shared beside the repo",
            dir.display()
        );
        None
    }
}

struct Expected {
    file: &'static str,
    vertices: usize,
    faces: usize,
    quads: bool,
    /// Boundary loop vertex counts, sorted descending (empty when closed).
    loops: &'static [usize],
    chi: i64,
    genus: i64,
}

const fn e(
    file: &'static str,
    vertices: usize,
    faces: usize,
    quads: bool,
    loops: &'static [usize],
    chi: i64,
    genus: i64,
) -> Expected {
    Expected {
        file,
        vertices,
        faces,
        quads,
        loops,
        chi,
        genus,
    }
}

/// The README table (loop sizes from its notes where it gives them, else only the count
/// is checked: `&[0]` entries stand for "one loop of any size").
const TABLE: &[Expected] = &[
    e("disk_hemisphere.obj", 1861, 3600, false, &[0], 1, 0),
    e("disk_human_face.obj", 17157, 34144, false, &[0], 1, 0),
    e("disk_hand.obj", 53054, 105860, false, &[0], 1, 0),
    e("mc2_sophie.obj", 20814, 41038, false, &[497, 93], 0, 0),
    e(
        "mc4_face_a.obj",
        13969,
        27306,
        false,
        &[420, 84, 70, 62],
        -2,
        0,
    ),
    e(
        "mc4_face_b.obj",
        5053,
        9756,
        false,
        &[180, 63, 60, 51],
        -2,
        0,
    ),
    e(
        "mc8_peaks.obj",
        1850,
        3418,
        false,
        &[138, 28, 24, 24, 20, 20, 20, 20],
        -6,
        0,
    ),
    e("g0_spot.obj", 2930, 5856, false, &[], 2, 0),
    e("g0_bunny_closed.obj", 34835, 69666, false, &[], 2, 0),
    e("g0_koala.obj", 49999, 99994, false, &[], 2, 0),
    e("g1_kitten.obj", 10000, 20000, false, &[], 0, 1),
    e("g1_bob.obj", 5344, 10688, false, &[], 0, 1),
    e("g2_eight.obj", 766, 1536, false, &[], -2, 2),
    e("g2b1_eight_hole.obj", 765, 1530, false, &[0], -3, 2),
    e("g4_fertility.obj", 4494, 9000, false, &[], -6, 4),
    e("quad_horse.obj", 2400, 2398, true, &[], 2, 0),
    e("quad_fandisk.obj", 766, 764, true, &[], 2, 0),
    e("quad_disk_inspired.obj", 1963, 1838, true, &[0], 1, 0),
];

#[test]
fn every_shared_mesh_has_the_topology_of_the_readme_table() {
    let Some(dir) = shared_meshes() else { return };
    for x in TABLE {
        let loaded = io::read(&dir.join(x.file), &BuildOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", x.file));
        let m = &loaded.mesh;
        let r = &loaded.report;
        assert_eq!(m.vertex_count(), x.vertices, "{} vertices", x.file);
        assert_eq!(m.face_count(), x.faces, "{} faces", x.file);
        let (tris, quads) = (m.triangle_count(), m.quad_count());
        if x.quads {
            assert_eq!((tris, quads), (0, x.faces), "{} face types", x.file);
        } else {
            assert_eq!((tris, quads), (x.faces, 0), "{} face types", x.file);
        }
        assert_eq!(m.component_count(), 1, "{} components", x.file);
        assert_eq!(m.euler_characteristic(), x.chi, "{} chi", x.file);
        assert_eq!(m.genus(), Some(x.genus), "{} genus", x.file);
        assert_eq!(m.is_closed(), x.loops.is_empty(), "{} closed", x.file);
        assert_eq!(
            m.is_disk(),
            x.genus == 0 && x.loops.len() == 1,
            "{} disk",
            x.file
        );
        let mut loops = m.boundary_loop_sizes();
        loops.sort_unstable_by(|a, b| b.cmp(a));
        assert_eq!(loops.len(), x.loops.len(), "{} loop count", x.file);
        if x.loops != [0] {
            assert_eq!(loops, x.loops, "{} loop sizes", x.file);
        }
        // The README says these files are consistently oriented and fully referenced.
        assert_eq!(r.faces_reoriented, 0, "{} re-oriented", x.file);
        assert!(r.unreferenced_vertices.is_empty(), "{}", x.file);
        assert!(m.vertex_map().is_identity(), "{}", x.file);
        // Closed meshes have positive signed volume (outward normals).
        if m.is_closed() {
            let volume: f64 = m
                .faces()
                .map(|f| {
                    let c = m.face_centroid(f).coords;
                    c.dot(&m.face_vector_area(f)) / 3.0
                })
                .sum();
            assert!(volume > 0.0, "{} volume {volume}", x.file);
        }
    }
}

#[test]
fn landmark_file_loops_are_the_boundary_loops_in_file_indices() {
    let Some(dir) = shared_meshes() else { return };
    let text = std::fs::read_to_string(dir.join("mc4_face_pair_landmarks.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    for side in ["face_a", "face_b"] {
        let entry = &json[side];
        let file = entry["mesh"].as_str().unwrap();
        let file = Path::new(file).file_name().unwrap();
        let loaded = io::read(&dir.join(file), &BuildOptions::default()).unwrap();
        let m = &loaded.mesh;
        let ours: Vec<Vec<usize>> = m
            .boundary_loops()
            .map(|b| {
                m.loop_vertices(b)
                    .map(|v| m.vertex_map().to_input(v))
                    .collect()
            })
            .collect();
        for given in entry["boundaries"].as_array().unwrap() {
            let given: Vec<usize> = given
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as usize)
                .collect();
            let found = ours.iter().any(|loop_| same_cycle(loop_, &given));
            assert!(found, "{side}: loop of {} vertices not found", given.len());
        }
    }
}

/// True if `b` is the cycle `a`, up to rotation and reversal.
fn same_cycle(a: &[usize], b: &[usize]) -> bool {
    if a.len() != b.len() || a.is_empty() {
        return false;
    }
    let Some(k) = a.iter().position(|&x| x == b[0]) else {
        return false;
    };
    let n = a.len();
    let forward = (0..n).all(|i| a[(k + i) % n] == b[i]);
    let backward = (0..n).all(|i| a[(k + n - i) % n] == b[i]);
    forward || backward
}

#[test]
fn dirty_meshes_give_typed_errors_naming_the_element() {
    let Some(dir) = shared_meshes() else { return };
    let beetle = io::read(
        &dir.join("dirty/beetle_nonmanifold.obj"),
        &BuildOptions::default(),
    );
    match beetle {
        Err(ReadError::Mesh {
            error: MeshError::NonManifoldEdge { a, b, faces },
            line,
            ..
        }) => {
            // The README lists (56, 62) among the edges with three faces.
            assert_eq!((a, b), (56, 62));
            assert_eq!(faces.len(), 3);
            assert!(line.is_some());
        }
        other => panic!("beetle: unexpected {other:?}"),
    }
    let cow = io::read(
        &dir.join("dirty/cow_pinched_vertex.obj"),
        &BuildOptions::default(),
    );
    match cow {
        Err(ReadError::Mesh {
            error: MeshError::NonManifoldVertex { vertex, fans },
            ..
        }) => {
            assert_eq!(vertex, 253, "README: vertex 253 (0-based) is the pinch");
            assert_eq!(fans, 2);
        }
        other => panic!("cow: unexpected {other:?}"),
    }
}

#[test]
fn spot_texture_coordinates_are_read_per_corner() {
    let Some(dir) = shared_meshes() else { return };
    let loaded = io::read(&dir.join("g0_spot.obj"), &BuildOptions::default()).unwrap();
    let corner = loaded.corner_uvs.as_ref().expect("spot has vt");
    let m = &loaded.mesh;
    // Parse the vt lines and the vt index of every face corner directly from the file.
    let text = std::fs::read_to_string(dir.join("g0_spot.obj")).unwrap();
    let vt: Vec<[f64; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [c[0], c[1]]
        })
        .collect();
    let corners: Vec<Vec<usize>> = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            l.split_whitespace()
                .map(|t| t.split('/').nth(1).unwrap().parse::<usize>().unwrap() - 1)
                .collect()
        })
        .collect();
    assert_eq!(corners.len(), m.face_count());
    for f in m.faces() {
        for (k, h) in m.face_halfedges(f).enumerate() {
            let expected = vt[corners[f.idx()][k]];
            assert_eq!([corner[h.idx()].x, corner[h.idx()].y], expected, "face {f}");
        }
    }
    // 3225 vt for 2930 v: there are seams, so no single uv per vertex.
    assert!(loaded.vertex_uvs().is_none());
}
