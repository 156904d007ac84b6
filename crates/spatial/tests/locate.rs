//! `SurfaceIndex::locate` against a brute-force search over all faces.

mod common;

use beltrami_mesh::primitives::{Cells, icosphere, jittered_grid, torus};
use beltrami_mesh::{BuildOptions, FaceId, Mesh, SurfacePoint};
use beltrami_spatial::closest_point::closest_on_face;
use beltrami_spatial::{SpatialError, SurfaceIndex};
use common::{Rng, build, mixed_grid, shared_mesh};
use nalgebra::{Point3, Vector3};

/// The smallest distance from `p` to any face, and the lowest face attaining it.
fn brute_force(mesh: &Mesh, p: &Point3<f64>) -> (FaceId, f64) {
    let mut best = (FaceId(0), f64::INFINITY);
    for f in mesh.faces() {
        let d = closest_on_face(mesh, f, p).distance();
        if d < best.1 {
            best = (f, d);
        }
    }
    best
}

/// A random point on a random face.
fn random_surface_point(mesh: &Mesh, rng: &mut Rng) -> SurfacePoint {
    let f = FaceId(rng.below(mesh.face_count()) as u32);
    if mesh.face_degree(f) == 3 {
        let (a, b) = (rng.unit(), rng.unit());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        SurfacePoint::in_triangle(f, [1.0 - a - b, a, b])
    } else {
        SurfacePoint::in_quad(f, rng.unit(), rng.unit())
    }
}

/// Query points: near the surface (a surface point moved along a random direction by up
/// to `near` ), and anywhere in the bounding box grown by a tenth of its diagonal.
fn queries(mesh: &Mesh, rng: &mut Rng, count: usize, near: f64) -> Vec<Point3<f64>> {
    let bbox = mesh.bounding_box();
    let grow = Vector3::repeat(0.1 * bbox.diagonal());
    let (lo, hi) = (bbox.min - grow, bbox.max + grow);
    (0..count)
        .map(|i| {
            if i % 4 == 3 {
                rng.in_box(&lo, &hi)
            } else {
                let x = random_surface_point(mesh, rng).position(mesh);
                x + rng.range(0.0, near) * rng.direction()
            }
        })
        .collect()
}

fn check_against_brute_force(name: &str, mesh: &Mesh, count: usize, near: f64) {
    let index = SurfaceIndex::new(mesh).unwrap();
    let mut rng = Rng::new(17);
    let points = queries(mesh, &mut rng, count, near);
    let located = index.locate_all(&points).unwrap();
    for (p, l) in points.iter().zip(&located) {
        let (face, d) = brute_force(mesh, p);
        assert!(
            (l.distance - d).abs() <= 1e-12 * (1.0 + d),
            "{name}: {p:?}: located {} on {} but face {face} is at {d}",
            l.distance,
            l.point.face
        );
        l.point.validate(mesh).unwrap();
        // The coordinates reproduce the returned position bit for bit, and the
        // distance is measured to it.
        assert_eq!(l.point.position(mesh), l.position, "{name}");
        assert!(((p - l.position).norm() - l.distance).abs() <= 1e-15 * (1.0 + d));
    }
    // Hints anywhere give the same answer.
    let hints: Vec<FaceId> = (0..points.len())
        .map(|_| FaceId(rng.below(mesh.face_count()) as u32))
        .collect();
    let hinted = index.locate_all_near(&points, &hints).unwrap();
    for (a, b) in located.iter().zip(&hinted) {
        assert!((a.distance - b.distance).abs() <= 1e-12 * (1.0 + a.distance));
    }
}

#[test]
fn jittered_grid_triangles_and_quads() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&jittered_grid(20, 15, cells, 0.3, 5));
        check_against_brute_force("jittered grid", &mesh, 2000, 0.2);
    }
}

#[test]
fn icosphere_points_inside_and_outside() {
    let mesh = build(&icosphere(3));
    check_against_brute_force("icosphere", &mesh, 2000, 0.3);
    // The center is (nearly) equidistant from everything: still exact.
    let index = SurfaceIndex::new(&mesh).unwrap();
    let l = index.locate(&Point3::origin()).unwrap();
    let (_, d) = brute_force(&mesh, &Point3::origin());
    assert!((l.distance - d).abs() < 1e-12);
}

#[test]
fn torus_triangles_and_warped_quads() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&torus(32, 12, 1.0, 0.3, cells));
        check_against_brute_force("torus", &mesh, 2000, 0.2);
    }
}

#[test]
fn shared_meshes() {
    for name in ["g0_bunny_closed.obj", "g1_kitten.obj"] {
        let Some(mesh) = shared_mesh(name) else {
            return;
        };
        let diagonal = mesh.bounding_box().diagonal();
        check_against_brute_force(name, &mesh, 300, 0.02 * diagonal);
    }
}

#[test]
fn surface_points_locate_to_themselves() {
    for mesh in [
        build(&jittered_grid(12, 9, Cells::Triangles, 0.3, 1)),
        build(&icosphere(2)),
        build(&torus(20, 10, 1.0, 0.4, Cells::Quads)),
    ] {
        let index = SurfaceIndex::new(&mesh).unwrap();
        let mut rng = Rng::new(3);
        for _ in 0..500 {
            let sp = random_surface_point(&mesh, &mut rng);
            let x = sp.position(&mesh);
            let l = index.locate(&x).unwrap();
            assert!(l.distance < 1e-14, "{}", l.distance);
            assert!((l.position - x).norm() < 1e-14);
            if l.point.face == sp.face {
                for k in 0..4 {
                    assert!((l.point.coords[k] - sp.coords[k]).abs() < 1e-12);
                }
            }
        }
        // Vertices too.
        for v in mesh.vertices() {
            let l = index.locate(&mesh.position(v)).unwrap();
            assert!(l.distance < 1e-14);
        }
    }
}

#[test]
fn bad_queries_are_typed_errors() {
    let mesh = build(&icosphere(1));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let nan = Point3::new(0.0, f64::NAN, 1.0);
    assert!(matches!(
        index.locate(&nan),
        Err(SpatialError::NonFinitePoint { .. })
    ));
    let inf = Point3::new(f64::INFINITY, 0.0, 1.0);
    assert!(matches!(
        index.locate_near(&inf, FaceId(0)),
        Err(SpatialError::NonFinitePoint { .. })
    ));
    let err = index
        .locate_near(&Point3::origin(), FaceId(80))
        .unwrap_err();
    assert!(matches!(err, SpatialError::HintOutOfRange { .. }));
    assert!(err.to_string().contains("f80"), "{err}");
    let err = index.locate_all(&[Point3::origin(), nan]).unwrap_err();
    assert!(err.to_string().starts_with("item 1:"), "{err}");
    let err = index.locate_all_near(&[Point3::origin()], &[]).unwrap_err();
    assert!(matches!(err, SpatialError::LengthMismatch { .. }));
}

#[test]
fn mixed_triangles_and_quads() {
    check_against_brute_force("mixed grid", &mixed_grid(12), 1500, 0.2);
}

#[test]
fn a_zero_area_face_is_handled() {
    // A 4 x 4 grid whose corner (1, 0) is moved onto the segment between its neighbours
    // (0.75, 0) and (1, 0.25): the triangle of the three is collinear, which a negative
    // degenerate-area tolerance lets through.
    let mut soup = beltrami_mesh::primitives::grid(4, 4, Cells::Triangles);
    soup.positions[4] = Point3::new(0.875, 0.125, 0.0);
    let options = BuildOptions {
        degenerate_area_tolerance: -1.0,
        ..BuildOptions::default()
    };
    let (mesh, _) = Mesh::build(&soup, &options).unwrap();
    let degenerate = mesh.faces().filter(|&f| mesh.face_area(f) < 1e-17).count();
    assert_eq!(degenerate, 1, "the test mesh has one zero-area face");
    check_against_brute_force("degenerate", &mesh, 1500, 0.3);
    // Walking onto it: the walk falls back to the projection, which lands on the cut
    // corner's diagonal.
    let index = SurfaceIndex::new(&mesh).unwrap();
    let start = index.locate(&Point3::new(0.8, 0.1, 0.0)).unwrap().point;
    let moved = index
        .move_point(
            &start,
            &Vector3::new(0.1, -0.05, 0.0),
            &beltrami_spatial::MoveOptions::default(),
        )
        .unwrap();
    let expected = index.locate(&Point3::new(0.9, 0.05, 0.0)).unwrap();
    assert!((moved.position - expected.position).norm() < 1e-12);
    moved.point.validate(&mesh).unwrap();
}

#[test]
fn faces_within_a_radius_include_every_face_that_close() {
    // Warped quads and triangles; radii from zero to a few face sizes.
    let mesh = build(&torus(24, 12, 1.0, 0.4, Cells::Quads));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let mut rng = Rng::new(5);
    for (i, p) in queries(&mesh, &mut rng, 200, 0.2).iter().enumerate() {
        let radius = [0.0, 0.05, 0.2, 0.6][i % 4];
        let listed = index.faces_within(p, radius).unwrap();
        assert!(listed.windows(2).all(|w| w[0] < w[1]), "sorted and unique");
        let within: Vec<FaceId> = mesh
            .faces()
            .filter(|&f| closest_on_face(&mesh, f, p).distance() <= radius)
            .collect();
        for f in &within {
            assert!(
                listed.contains(f),
                "face {f} within {radius} of {p} is missing"
            );
        }
        // The lower bounds keep the list close to the true one.
        assert!(
            listed.len() <= 4 * within.len() + 8,
            "{} listed for {}",
            listed.len(),
            within.len()
        );
    }
    assert!(matches!(
        index.faces_within(&Point3::origin(), f64::NAN),
        Err(SpatialError::InvalidRadius { .. })
    ));
    assert!(matches!(
        index.faces_within(&Point3::origin(), -1.0),
        Err(SpatialError::InvalidRadius { .. })
    ));
}
