//! The initial bijection on every supported topology: zero flips, images on the target,
//! valid surface points, landmarks, the identity, topology errors and the torus loops.
//! The shared meshes (`../shared/meshes`) are skipped with a message when absent.

use std::f64::consts::TAU;
use std::io::Write;
use std::path::{Path, PathBuf};

use beltrami_core::{Landmark, Position};
use beltrami_mesh::primitives::{self, Cells, ModifiedTorus};
use beltrami_mesh::{BuildOptions, Mesh, Point3, PolygonSoup, VertexId, io};
use beltrami_register::{InitialMap, RegisterError, Topology, check_topology, initial_map};
use beltrami_spatial::SurfaceIndex;

fn mesh(soup: &PolygonSoup) -> Mesh {
    Mesh::from_soup(soup).unwrap()
}

fn shared(file: &str) -> Option<Mesh> {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes");
    let path = dir.join(file);
    if !path.exists() {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: {} not found; this test needs ../shared beside the repo",
            path.display()
        );
        return None;
    }
    Some(io::read(&path, &BuildOptions::default()).unwrap().mesh)
}

/// Every image is a valid surface point of the target, its position matches, and it is
/// on the target surface.
fn check_on_target(source: &Mesh, target: &Mesh, map: &InitialMap) {
    assert_eq!(map.points.len(), source.vertex_count());
    assert_eq!(map.positions.len(), source.vertex_count());
    let index = SurfaceIndex::new(target).unwrap();
    let scale = target.bounding_box().diagonal();
    for (p, x) in map.points.iter().zip(&map.positions) {
        p.validate(target).unwrap();
        assert!((p.position(target) - x).norm() <= 1e-12 * scale);
        let located = index.locate(x).unwrap();
        assert!(located.distance <= 1e-9 * scale, "{}", located.distance);
    }
}

fn jittered_disk(level: usize, amount: f64, seed: u64) -> Mesh {
    let mut soup = primitives::disk(level);
    let mut state = seed;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    for p in &mut soup.positions {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        if r < 1.0 - 1e-9 {
            p.x += amount * next();
            p.y += amount * next();
        }
        p.z = 0.3 * (p.x * 2.0).sin() * (p.y * 3.0).cos();
    }
    mesh(&soup)
}

#[test]
fn disk_onto_disk_has_no_flips() {
    let source = jittered_disk(4, 0.01, 1);
    let target = jittered_disk(5, 0.005, 2);
    let map = initial_map(&source, &target, &[]).unwrap();
    assert_eq!(map.topology, Topology::Disk);
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
    // Boundary onto boundary.
    let index = SurfaceIndex::new(&target).unwrap();
    for v in source.vertices().filter(|&v| source.is_boundary_vertex(v)) {
        let p = map.positions[v.idx()];
        assert!((p.x * p.x + p.y * p.y).sqrt() > 0.99, "{p:?}");
        let _ = index.locate(&p).unwrap();
    }
}

#[test]
fn bundled_hemisphere_onto_planar_disk() {
    let source = io::read(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../meshes/disk_hemisphere.obj"),
        &BuildOptions::default(),
    )
    .unwrap()
    .mesh;
    let target = mesh(&primitives::disk(6));
    let map = initial_map(&source, &target, &[]).unwrap();
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
}

#[test]
fn disk_boundary_landmark_lands_exactly() {
    let source = jittered_disk(4, 0.01, 3);
    let target = jittered_disk(4, 0.01, 4);
    let s = source
        .vertices()
        .filter(|&v| source.is_boundary_vertex(v))
        .nth(5)
        .unwrap();
    let t = target
        .vertices()
        .filter(|&v| target.is_boundary_vertex(v))
        .nth(20)
        .unwrap();
    let landmarks = [Landmark {
        vertex: s,
        position: Position::TargetVertex(t),
    }];
    let map = initial_map(&source, &target, &landmarks).unwrap();
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0);
    assert_eq!(map.positions[s.idx()], target.position(t));
    // An interior source vertex cannot go onto the boundary.
    let inner = source
        .vertices()
        .find(|&v| !source.is_boundary_vertex(v))
        .unwrap();
    let bad = [Landmark {
        vertex: inner,
        position: Position::TargetVertex(t),
    }];
    assert!(matches!(
        initial_map(&source, &target, &bad),
        Err(RegisterError::Landmark { index: 0, .. })
    ));
    // Nor a boundary one inside, also after a landmark that pins the boundary.
    let inside = target
        .vertices()
        .find(|&v| !target.is_boundary_vertex(v))
        .unwrap();
    let bad = [
        landmarks[0],
        Landmark {
            vertex: source
                .vertices()
                .filter(|&v| source.is_boundary_vertex(v))
                .nth(9)
                .unwrap(),
            position: Position::TargetVertex(inside),
        },
    ];
    assert!(matches!(
        initial_map(&source, &target, &bad),
        Err(RegisterError::Landmark { index: 1, .. })
    ));
}

/// The `k`-th of `n` boundary vertices spread along the loop of `mesh`.
fn along_boundary(mesh: &Mesh, k: usize, n: usize) -> VertexId {
    let lp: Vec<VertexId> = mesh
        .loop_vertices(beltrami_mesh::BoundaryLoopId(0))
        .collect();
    lp[k * lp.len() / n]
}

#[test]
fn every_disk_landmark_lands_exactly_and_boundary_order_is_kept() {
    let source = jittered_disk(4, 0.01, 5);
    let target = jittered_disk(5, 0.005, 6);
    // Three boundary landmarks given as the positions of target boundary vertices (as
    // a `v SRC TGT` line arrives), each moved a little along the loop, and four interior
    // ones onto points a tenth of the disk away from where the plain map puts them.
    let plain = initial_map(&source, &target, &[]).unwrap();
    let mut landmarks: Vec<Landmark> = (0..3)
        .map(|k| Landmark {
            vertex: along_boundary(&source, k, 3),
            position: Position::Spatial(target.position(along_boundary(&target, 3 * k + 1, 9))),
        })
        .collect();
    let interior: Vec<VertexId> = source
        .vertices()
        .filter(|&v| !source.is_boundary_vertex(v))
        .step_by(37)
        .take(4)
        .collect();
    for (k, &v) in interior.iter().enumerate() {
        let angle = k as f64 * std::f64::consts::FRAC_PI_2;
        let p = plain.positions[v.idx()];
        landmarks.push(Landmark {
            vertex: v,
            position: Position::Spatial(Point3::new(
                p.x + 0.1 * angle.cos(),
                p.y + 0.1 * angle.sin(),
                p.z,
            )),
        });
    }
    let map = initial_map(&source, &target, &landmarks).unwrap();
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
    let index = SurfaceIndex::new(&target).unwrap();
    let scale = target.bounding_box().diagonal();
    for (k, mark) in landmarks.iter().enumerate() {
        let Position::Spatial(p) = mark.position else {
            unreachable!()
        };
        let goal = index.locate(&p).unwrap().position;
        let d = (map.positions[mark.vertex.idx()] - goal).norm();
        assert!(d <= 1e-12 * scale, "landmark {k}: {d:e}");
    }
    // The boundary landmarks in the other turn of the target's loop: refused, naming
    // the one that breaks the order.
    let reversed: Vec<Landmark> = (0..3)
        .map(|k| Landmark {
            vertex: along_boundary(&source, k, 3),
            position: Position::TargetVertex(along_boundary(&target, (3 - k) % 3, 3)),
        })
        .collect();
    match initial_map(&source, &target, &reversed) {
        Err(RegisterError::Landmark { reason, .. }) => {
            assert!(reason.contains("order"), "{reason}")
        }
        other => panic!("reversed boundary landmarks: {other:?}"),
    }
}

#[test]
fn disk_onto_itself_is_the_identity() {
    let m = jittered_disk(4, 0.01, 5);
    let b = m.vertices().find(|&v| m.is_boundary_vertex(v)).unwrap();
    let landmarks = [Landmark {
        vertex: b,
        position: Position::TargetVertex(b),
    }];
    let map = initial_map(&m, &m, &landmarks).unwrap();
    for v in m.vertices() {
        assert!((map.positions[v.idx()] - m.position(v)).norm() < 1e-9);
    }
}

#[test]
fn human_face_onto_hand() {
    let (Some(source), Some(target)) = (shared("disk_human_face.obj"), shared("disk_hand.obj"))
    else {
        return;
    };
    let map = initial_map(&source, &target, &[]).unwrap();
    check_on_target(&source, &target, &map);
    let _ = writeln!(std::io::stderr(), "face onto hand: {:?}", map.notes);
    // Real meshes: a handful of flips (reported in the notes) are tolerated.
    assert!(
        map.flipped() * 1000 <= source.face_count(),
        "{:?}",
        map.notes
    );
}

fn ellipsoid(level: usize) -> Mesh {
    let mut soup = primitives::icosphere(level);
    for p in &mut soup.positions {
        *p = Point3::new(2.0 * p.x, p.y + 0.2 * p.x * p.x, 0.7 * p.z);
    }
    mesh(&soup)
}

#[test]
fn sphere_onto_ellipsoid_has_no_flips() {
    let source = mesh(&primitives::icosphere(3));
    let target = ellipsoid(4);
    let map = initial_map(&source, &target, &[]).unwrap();
    assert_eq!(map.topology, Topology::Sphere);
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
}

#[test]
fn sphere_landmarks_land_exactly() {
    let source = mesh(&primitives::icosphere(3));
    let target = ellipsoid(3);
    for count in 1..=3 {
        let landmarks: Vec<Landmark> = [(0u32, 5u32), (17, 40), (100, 90)][..count]
            .iter()
            .map(|&(s, t)| Landmark {
                vertex: VertexId(s),
                position: Position::TargetVertex(VertexId(t)),
            })
            .collect();
        let map = initial_map(&source, &target, &landmarks).unwrap();
        check_on_target(&source, &target, &map);
        for l in &landmarks {
            let Position::TargetVertex(t) = l.position else {
                unreachable!()
            };
            assert_eq!(map.positions[l.vertex.idx()], target.position(t));
        }
        assert_eq!(map.flipped(), 0, "{count} landmarks: {:?}", map.notes);
    }
    // A point target.
    let p = Point3::new(0.3, 0.9, 0.1);
    let map = initial_map(
        &source,
        &target,
        &[Landmark {
            vertex: VertexId(7),
            position: Position::Spatial(p),
        }],
    )
    .unwrap();
    let expected = SurfaceIndex::new(&target)
        .unwrap()
        .locate(&p)
        .unwrap()
        .position;
    assert!((map.positions[7] - expected).norm() < 1e-12);
}

#[test]
fn sphere_onto_itself_is_the_identity() {
    let m = ellipsoid(3);
    let map = initial_map(&m, &m, &[]).unwrap();
    for v in m.vertices() {
        assert!(
            (map.positions[v.idx()] - m.position(v)).norm() < 1e-6,
            "{v}"
        );
    }
}

#[test]
fn spot_onto_bunny() {
    let (Some(source), Some(target)) = (shared("g0_spot.obj"), shared("g0_bunny_closed.obj"))
    else {
        return;
    };
    let map = initial_map(&source, &target, &[]).unwrap();
    check_on_target(&source, &target, &map);
    let _ = writeln!(
        std::io::stderr(),
        "spot onto bunny: {} flips; {:?}",
        map.flipped(),
        map.notes
    );
    assert!(
        map.flipped() * 500 <= source.face_count(),
        "{:?}",
        map.notes
    );
    let sphere = mesh(&primitives::icosphere(4));
    let map = initial_map(&source, &sphere, &[]).unwrap();
    check_on_target(&source, &sphere, &map);
    let _ = writeln!(
        std::io::stderr(),
        "spot onto icosphere: {} flips",
        map.flipped()
    );
    assert!(
        map.flipped() * 1000 <= source.face_count(),
        "{:?}",
        map.notes
    );
}

/// Every landmark (all onto target vertices) lands on its vertex to rounding.
fn assert_vertex_landmarks_exact(map: &InitialMap, target: &Mesh, marks: &[Landmark]) {
    for mark in marks {
        let Position::TargetVertex(v) = mark.position else {
            panic!("landmark {} is not onto a vertex", mark.vertex);
        };
        let miss = (map.positions[mark.vertex.idx()] - target.position(v)).norm();
        assert!(miss < 1e-12, "landmark {}: {miss:.3e}", mark.vertex);
    }
}

fn torus(nu: usize, nv: usize) -> Mesh {
    mesh(&primitives::torus(nu, nv, 3.0, 1.0, Cells::Triangles))
}

#[test]
fn torus_onto_modified_tori_has_no_flips_and_names_its_loops() {
    let source = torus(48, 16);
    for kind in [ModifiedTorus::Phi1, ModifiedTorus::Phi2] {
        let target = mesh(&primitives::modified_torus(kind, 80, 32));
        let map = initial_map(&source, &target, &[]).unwrap();
        assert_eq!(map.topology, Topology::Torus);
        check_on_target(&source, &target, &map);
        assert_eq!(map.flipped(), 0, "{:?}", map.notes);
        // The loops: a around the tube on both (shortest paired with shortest).
        let loops: Vec<&String> = map.notes.iter().filter(|n| n.contains(" loop ")).collect();
        assert_eq!(loops.len(), 4, "{:?}", map.notes);
        assert!(
            loops[0].contains("source loop a: length 6.2"),
            "{}",
            loops[0]
        );
        assert!(loops[2].contains("target loop a"), "{}", loops[2]);
    }
}

#[test]
fn torus_landmarks_and_identity() {
    let m = torus(40, 16);
    let landmarks = [Landmark {
        vertex: VertexId(0),
        position: Position::TargetVertex(VertexId(0)),
    }];
    let map = initial_map(&m, &m, &landmarks).unwrap();
    assert_eq!(map.flipped(), 0);
    for v in m.vertices() {
        assert!(
            (map.positions[v.idx()] - m.position(v)).norm() < 1e-9,
            "{v}"
        );
    }
    let target = mesh(&primitives::modified_torus(ModifiedTorus::Phi1, 60, 24));
    let landmarks = [
        Landmark {
            vertex: VertexId(3),
            position: Position::TargetVertex(VertexId(100)),
        },
        Landmark {
            vertex: VertexId(300),
            position: Position::TargetVertex(VertexId(900)),
        },
    ];
    let map = initial_map(&m, &target, &landmarks).unwrap();
    check_on_target(&m, &target, &map);
    assert_eq!(map.positions[3], target.position(VertexId(100)));
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
}

#[test]
fn every_torus_landmark_lands_exactly_under_a_twist() {
    // A torus onto a finer mesh of the same torus, six landmarks along a twist of the
    // tube (up to two target edges off the rotation that places the first): no
    // symmetry of the square places them all, the matching on the torus does.
    let (nu, nv) = (40, 16);
    let source = torus(nu, nv);
    let target = torus(60, 24);
    let marks: Vec<Landmark> = [(0, 0), (7, 3), (13, 8), (20, 12), (27, 5), (33, 14)]
        .iter()
        .map(|&(i, j): &(usize, usize)| {
            let twist = 2.0 * (TAU * j as f64 / nv as f64).sin();
            let ti = (1.5 * i as f64 + twist).round().rem_euclid(60.0) as usize;
            let tj = (1.5 * j as f64).round() as usize % 24;
            Landmark {
                vertex: VertexId::from_usize(i * nv + j),
                position: Position::TargetVertex(VertexId::from_usize(ti * 24 + tj)),
            }
        })
        .collect();
    let map = initial_map(&source, &target, &marks).unwrap();
    check_on_target(&source, &target, &map);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
    assert!(
        map.notes.iter().any(|n| n.contains("matched on the torus")),
        "{:?}",
        map.notes
    );
    assert_vertex_landmarks_exact(&map, &target, &marks);
}

#[test]
fn kitten_onto_modified_tori() {
    let Some(source) = shared("g1_kitten.obj") else {
        return;
    };
    for kind in [ModifiedTorus::Phi1, ModifiedTorus::Phi2] {
        let target = mesh(&primitives::modified_torus(kind, 160, 64));
        let map = initial_map(&source, &target, &[]).unwrap();
        check_on_target(&source, &target, &map);
        let _ = writeln!(std::io::stderr(), "kitten onto {kind:?}: {:?}", map.notes);
        assert!(
            map.flipped() * 1000 <= source.face_count(),
            "{:?}",
            map.notes
        );
    }
}

#[test]
fn topology_mismatches_are_errors() {
    let disk = jittered_disk(2, 0.0, 1);
    let sphere = mesh(&primitives::icosphere(1));
    let torus = torus(12, 6);
    let err = check_topology(&disk, &sphere).unwrap_err();
    assert!(matches!(err, RegisterError::TopologyMismatch { .. }));
    assert!(
        err.to_string().contains("genus 0 with 1 boundary loop"),
        "{err}"
    );
    let err = initial_map(&torus, &sphere, &[]).unwrap_err();
    assert!(
        err.to_string().contains("genus 1 with 0 boundary loops"),
        "{err}"
    );
    assert_eq!(check_topology(&torus, &torus).unwrap(), Topology::Torus);
    assert_eq!(check_topology(&sphere, &sphere).unwrap(), Topology::Sphere);
    assert_eq!(check_topology(&disk, &disk).unwrap(), Topology::Disk);
    if let Some(eight) = shared("g2_eight.obj") {
        assert_eq!(
            check_topology(&eight, &eight).unwrap(),
            Topology::HigherGenus
        );
    }
    let annulus = mesh(&primitives::annulus(0.4, 4, 16));
    assert_eq!(
        check_topology(&annulus, &annulus).unwrap(),
        Topology::MultiplyConnected
    );
    // Two spheres side by side: two components.
    let one = primitives::icosphere(1);
    let mut positions = one.positions.clone();
    positions.extend(
        one.positions
            .iter()
            .map(|p| p + nalgebra::Vector3::new(3.0, 0.0, 0.0)),
    );
    let mut pair = PolygonSoup::new(positions);
    let n = one.positions.len() as u32;
    for f in one.faces() {
        pair.push_face(f);
        pair.push_face(&f.iter().map(|&v| v + n).collect::<Vec<u32>>());
    }
    let pair = mesh(&pair);
    let err = check_topology(&pair, &pair).unwrap_err();
    assert!(matches!(err, RegisterError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("2 connected components"), "{err}");
}

#[test]
fn bad_landmarks_name_their_index() {
    let sphere = mesh(&primitives::icosphere(2));
    let out_of_range = [
        Landmark {
            vertex: VertexId(0),
            position: Position::TargetVertex(VertexId(1)),
        },
        Landmark {
            vertex: VertexId(100_000),
            position: Position::TargetVertex(VertexId(1)),
        },
    ];
    let err = initial_map(&sphere, &sphere, &out_of_range).unwrap_err();
    assert!(
        matches!(err, RegisterError::Landmark { index: 1, .. }),
        "{err}"
    );
    let nan = [Landmark {
        vertex: VertexId(0),
        position: Position::Spatial(Point3::new(f64::NAN, 0.0, 0.0)),
    }];
    assert!(matches!(
        initial_map(&sphere, &sphere, &nan),
        Err(RegisterError::Landmark { index: 0, .. })
    ));
    let repeated = [out_of_range[0], out_of_range[0]];
    assert!(matches!(
        initial_map(&sphere, &sphere, &repeated),
        Err(RegisterError::Landmark { index: 1, .. })
    ));
    // Two source vertices onto one target, once as a vertex and once as its position.
    let one_point = [
        Landmark {
            vertex: VertexId(3),
            position: Position::TargetVertex(VertexId(7)),
        },
        Landmark {
            vertex: VertexId(5),
            position: Position::TargetVertex(VertexId(9)),
        },
        Landmark {
            vertex: VertexId(4),
            position: Position::Spatial(sphere.position(VertexId(7))),
        },
    ];
    let err = initial_map(&sphere, &sphere, &one_point).unwrap_err();
    assert!(
        matches!(err, RegisterError::Landmark { index: 2, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("landmark 0"), "{err}");
}

#[test]
fn genus_two_onto_a_turned_copy_through_matched_cuts() {
    // A quarter turn about z: four landmarks fit the turn, the matched cut graphs (with
    // the landmarks as slit tips) give a bijection with no flipped face, and every
    // landmark lands exactly.
    let Some(eight) = shared("g2_eight.obj") else {
        return;
    };
    let turned: Vec<Point3<f64>> = eight
        .positions()
        .iter()
        .map(|p| Point3::new(-p.y, p.x, p.z))
        .collect();
    let target = eight.with_positions(turned).unwrap();
    let marks: Vec<Landmark> = [0u32, 200, 400, 600]
        .iter()
        .map(|&v| Landmark {
            vertex: VertexId(v),
            position: Position::TargetVertex(VertexId(v)),
        })
        .collect();
    let map = initial_map(&eight, &target, &marks).unwrap();
    check_on_target(&eight, &target, &map);
    assert_eq!(map.topology, Topology::HigherGenus);
    assert_eq!(map.flipped(), 0, "{:?}", map.notes);
    assert!(
        map.notes.iter().any(|n| n.contains("cut graphs")),
        "{:?}",
        map.notes
    );
    assert_vertex_landmarks_exact(&map, &target, &marks);
}
