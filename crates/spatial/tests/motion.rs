//! `SurfaceIndex::move_point`: walks against exact answers (flat meshes, an unrolled
//! prism, a cube's edges and corners), boundary modes, projection, batch moves.

mod common;

use beltrami_mesh::primitives::{Cells, grid, icosphere, jittered_grid, torus};
use beltrami_mesh::{FaceId, Mesh, SurfacePoint};
use beltrami_spatial::{
    BoundaryMode, MoveMethod, MoveOptions, MoveOutcome, SpatialError, SurfaceIndex,
};
use common::{Rng, build, cube, mixed_grid, prism};
use nalgebra::{Point3, Vector3};

fn walk(boundary: BoundaryMode) -> MoveOptions {
    MoveOptions {
        boundary,
        ..MoveOptions::default()
    }
}

/// The surface point at `x` (exact closest point).
fn at(index: &SurfaceIndex, x: Point3<f64>) -> SurfacePoint {
    let l = index.locate(&x).unwrap();
    assert!(l.distance < 1e-14, "{x:?} is not on the mesh");
    l.point
}

fn assert_close(a: &Point3<f64>, b: &Point3<f64>, tol: f64, what: &str) {
    assert!((a - b).norm() <= tol, "{what}: {a:?} vs {b:?}");
}

#[test]
fn a_displacement_within_a_face_is_exact() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&jittered_grid(8, 8, cells, 0.3, 2));
        let index = SurfaceIndex::new(&mesh).unwrap();
        for f in mesh.faces() {
            let start = if mesh.face_degree(f) == 3 {
                SurfacePoint::in_triangle(f, [0.4, 0.3, 0.3])
            } else {
                SurfacePoint::in_quad(f, 0.4, 0.6)
            };
            let x = start.position(&mesh);
            // Towards the face's vertex average, a third of the way: stays inside.
            let d = (mesh.face_centroid(f) - x) / 3.0;
            let moved = index
                .move_point(&start, &d, &MoveOptions::default())
                .unwrap();
            assert_eq!(moved.outcome, MoveOutcome::Arrived);
            assert_eq!(moved.point.face, f);
            assert_eq!(moved.faces_crossed, 0);
            assert_close(&moved.position, &(x + d), 1e-15, "within a face");
        }
    }
    // On a curved mesh the length of the tangential part is kept.
    let mesh = build(&icosphere(3));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let mut rng = Rng::new(5);
    for f in mesh.faces().step_by(7) {
        let start = SurfacePoint::in_triangle(f, [0.34, 0.33, 0.33]);
        let frame = index.frame(&start).unwrap();
        let d = 0.002
            * frame.to_world(&nalgebra::Vector2::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ));
        let moved = index
            .move_point(&start, &d, &MoveOptions::default())
            .unwrap();
        if moved.point.face == f {
            assert!(((moved.position - frame.origin).norm() - d.norm()).abs() < 1e-15);
        }
    }
}

#[test]
fn a_walk_on_a_flat_grid_is_vector_addition() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&jittered_grid(20, 20, cells, 0.3, 9));
        let index = SurfaceIndex::new(&mesh).unwrap();
        let mut rng = Rng::new(11);
        let mut crossed = 0;
        for _ in 0..2000 {
            let x = Point3::new(rng.range(0.2, 0.8), rng.range(0.2, 0.8), 0.0);
            let d = Vector3::new(
                rng.range(-0.2, 0.2),
                rng.range(-0.2, 0.2),
                rng.range(-1.0, 1.0),
            );
            let moved = index
                .move_point(&at(&index, x), &d, &MoveOptions::default())
                .unwrap();
            assert_eq!(moved.outcome, MoveOutcome::Arrived);
            let expected = x + Vector3::new(d.x, d.y, 0.0);
            assert_close(&moved.position, &expected, 1e-13, "flat walk");
            crossed += moved.faces_crossed;
        }
        assert!(crossed > 2000 * 4, "the walks cross faces ({crossed})");
    }
    // Across a checkerboard of quads and triangle pairs.
    let mesh = mixed_grid(10);
    let index = SurfaceIndex::new(&mesh).unwrap();
    let mut rng = Rng::new(12);
    for _ in 0..1000 {
        let x = Point3::new(rng.range(0.2, 0.8), rng.range(0.2, 0.8), 0.0);
        let d = Vector3::new(rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), 0.0);
        let moved = index
            .move_point(&at(&index, x), &d, &MoveOptions::default())
            .unwrap();
        assert_close(&moved.position, &(x + d), 1e-13, "mixed walk");
    }
    // Through vertices and along edges of a regular grid.
    let mesh = build(&grid(10, 10, Cells::Triangles));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let cases = [
        (Point3::new(0.2, 0.2, 0.0), Vector3::new(0.5, 0.5, 0.0)), // diagonals, vertex to vertex
        (Point3::new(0.2, 0.2, 0.0), Vector3::new(0.45, 0.0, 0.0)), // along grid lines
        (Point3::new(0.25, 0.3, 0.0), Vector3::new(0.0, 0.55, 0.0)), // through vertices
        (Point3::new(0.2, 0.2, 0.0), Vector3::new(-0.1, 0.6, 0.0)), // from a vertex
        (Point3::new(0.15, 0.1, 0.0), Vector3::new(0.3, 0.6, 0.0)), // through vertices
    ];
    for (x, d) in cases {
        let moved = index
            .move_point(&at(&index, x), &d, &MoveOptions::default())
            .unwrap();
        assert_eq!(moved.outcome, MoveOutcome::Arrived);
        assert_close(&moved.position, &(x + d), 1e-13, "grid lines and vertices");
    }
}

/// Unrolled coordinates (arc length around, height) of a point of the prism `n` sides.
fn unroll(x: &Point3<f64>, n: usize) -> (f64, f64) {
    let step = std::f64::consts::TAU / n as f64;
    let side = 2.0 * (step / 2.0).sin();
    let angle = x.y.atan2(x.x).rem_euclid(std::f64::consts::TAU);
    let i = ((angle / step).floor() as usize).min(n - 1);
    let a = Point3::new((i as f64 * step).cos(), (i as f64 * step).sin(), 0.0);
    let b = Point3::new(
        ((i + 1) as f64 * step).cos(),
        ((i + 1) as f64 * step).sin(),
        0.0,
    );
    let f = (Vector3::new(x.x, x.y, 0.0) - a.coords).dot(&(b - a)) / (b - a).norm_squared();
    ((i as f64 + f) * side, x.z)
}

#[test]
fn a_walk_on_a_prism_is_the_unrolled_straight_line() {
    let n = 24;
    let mesh = prism(n, 10, 0.2);
    let index = SurfaceIndex::new(&mesh).unwrap();
    let perimeter = n as f64 * 2.0 * (std::f64::consts::PI / n as f64).sin();
    let mut rng = Rng::new(23);
    for _ in 0..500 {
        let f = FaceId(rng.below(mesh.face_count()) as u32);
        let (a, b) = (rng.range(0.05, 0.9), rng.unit());
        let (a, b) = (a, b * (0.95 - a));
        let start = SurfacePoint::in_triangle(f, [1.0 - a - b, a, b]);
        let x = start.position(&mesh);
        if !(0.5..=1.5).contains(&x.z) {
            continue;
        }
        let frame = index.frame(&start).unwrap();
        // Around by up to more than a full turn, up or down by at most 0.4.
        let around = rng.range(-8.0, 8.0);
        let up = rng.range(-0.4, 0.4);
        let horizontal = Vector3::z().cross(&frame.normal).normalize();
        let d = around * horizontal + up * Vector3::z();
        let moved = index
            .move_point(&start, &d, &MoveOptions::default())
            .unwrap();
        assert_eq!(moved.outcome, MoveOutcome::Arrived);
        let (s0, z0) = unroll(&x, n);
        let (s1, z1) = unroll(&moved.position, n);
        let ds = (s1 - s0 - around).rem_euclid(perimeter);
        let ds = ds.min(perimeter - ds);
        assert!(
            ds < 1e-12 && (z1 - z0 - up).abs() < 1e-12,
            "{ds} {}",
            z1 - z0 - up
        );
        assert!(moved.faces_crossed > 0);
    }
}

#[test]
fn walks_cross_sharp_edges_and_corners_of_a_cube() {
    for quads in [false, true] {
        let mesh = cube(5, quads);
        let index = SurfaceIndex::new(&mesh).unwrap();
        let opts = MoveOptions::default();
        // Over an edge: 0.6 to x = 1 on top, then 0.2 down the side.
        let start = at(&index, Point3::new(0.4, 0.55, 1.0));
        let moved = index
            .move_point(&start, &Vector3::new(0.8, 0.0, 0.0), &opts)
            .unwrap();
        assert_close(
            &moved.position,
            &Point3::new(1.0, 0.55, 0.8),
            1e-13,
            "over an edge",
        );
        // Obliquely over an edge: the unfolded line.
        let moved = index
            .move_point(&start, &Vector3::new(0.8, 0.3, 0.0), &opts)
            .unwrap();
        let expected = Point3::new(1.0, 0.55 + 0.3 * 0.6 / 0.8 + 0.3 * 0.2 / 0.8, 0.8);
        assert_close(&moved.position, &expected, 1e-13, "oblique");
        // Into a corner along the bisector: straight on down the vertical edge (the
        // corner's angle is 3 pi / 2; half of it from the incoming direction).
        let start = at(&index, Point3::new(0.7, 0.7, 1.0));
        let d = Vector3::new(1.0, 1.0, 0.0).normalize() * (0.3 * 2f64.sqrt() + 0.25);
        let moved = index.move_point(&start, &d, &opts).unwrap();
        assert_eq!(moved.outcome, MoveOutcome::Arrived);
        assert_close(
            &moved.position,
            &Point3::new(1.0, 1.0, 0.75),
            1e-13,
            "corner",
        );
        // Around the cube and back: four edges, same point.
        let start = at(&index, Point3::new(0.3, 0.45, 1.0));
        let moved = index
            .move_point(&start, &Vector3::new(4.0, 0.0, 0.0), &opts)
            .unwrap();
        assert_close(
            &moved.position,
            &Point3::new(0.3, 0.45, 1.0),
            1e-12,
            "around",
        );
        assert!(moved.faces_crossed >= 20);
    }
}

#[test]
fn boundary_stop_and_slide() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = build(&grid(10, 10, cells));
        let index = SurfaceIndex::new(&mesh).unwrap();
        let (stop, slide) = (walk(BoundaryMode::Stop), walk(BoundaryMode::Slide));
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let d = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        let mv = |x: Point3<f64>, dv: Vector3<f64>, o: &MoveOptions| {
            index.move_point(&at(&index, x), &dv, o).unwrap()
        };
        let m = mv(p(0.55, 0.55), d(1.0, 0.3), &stop);
        assert_eq!(m.outcome, MoveOutcome::StoppedAtBoundary);
        assert_close(&m.position, &p(1.0, 0.685), 1e-14, "stop");
        let m = mv(p(0.55, 0.55), d(1.0, 0.3), &slide);
        assert_eq!(m.outcome, MoveOutcome::SlidAlongBoundary);
        assert_close(&m.position, &p(1.0, 0.85), 1e-14, "slide");
        // Around a corner: x = 1 at y = 0.81, then 0.36 of slide: 0.19 up to the
        // corner and 0.17 along the top.
        let m = mv(p(0.55, 0.45), d(0.9, 0.72), &slide);
        assert_close(&m.position, &p(0.83, 1.0), 1e-14, "slide round a corner");
        // Exactly through a boundary vertex: slides by the remaining tangential part.
        let m = mv(p(0.5, 0.4), d(1.0, 0.2), &slide);
        assert_close(&m.position, &p(1.0, 0.6), 1e-14, "slide from a vertex");
        let m = mv(p(0.5, 0.4), d(1.0, 0.2), &stop);
        assert_close(&m.position, &p(1.0, 0.5), 1e-14, "stop at a vertex");
        // From a boundary point: outwards it stays, or slides; inwards it leaves.
        let m = mv(p(1.0, 0.45), d(0.3, 0.2), &stop);
        assert_eq!(m.outcome, MoveOutcome::StoppedAtBoundary);
        assert_close(&m.position, &p(1.0, 0.45), 1e-14, "stuck");
        let m = mv(p(1.0, 0.45), d(0.3, 0.2), &slide);
        assert_close(&m.position, &p(1.0, 0.65), 1e-14, "slide from the boundary");
        let m = mv(p(1.0, 0.45), d(-0.2, 0.1), &slide);
        assert_eq!(m.outcome, MoveOutcome::Arrived);
        assert_close(&m.position, &p(0.8, 0.55), 1e-14, "inwards");
        // Along the boundary through boundary vertices.
        let m = mv(p(1.0, 0.15), d(0.0, 0.5), &stop);
        assert_eq!(m.outcome, MoveOutcome::Arrived);
        assert_close(&m.position, &p(1.0, 0.65), 1e-14, "along the boundary");
        // From a boundary vertex, outwards at an angle.
        let m = mv(p(1.0, 0.3), d(0.5, -0.1), &slide);
        assert_close(&m.position, &p(1.0, 0.2), 1e-14, "from a boundary vertex");
        // Keep: boundary points move along the boundary only.
        let keep = walk(BoundaryMode::Keep);
        let m = mv(p(1.0, 0.45), d(-0.2, 0.1), &keep);
        assert_eq!(m.outcome, MoveOutcome::SlidAlongBoundary);
        assert_close(&m.position, &p(1.0, 0.55), 1e-14, "keep on an edge");
        let m = mv(p(1.0, 0.3), d(-0.3, 0.1), &keep);
        assert_close(&m.position, &p(1.0, 0.4), 1e-14, "keep from a vertex");
        let m = mv(p(1.0, 1.0), d(-0.2, -0.1), &keep);
        assert_close(&m.position, &p(0.8, 1.0), 1e-14, "keep from a corner");
        // Down 0.35 to the corner, then on along the bottom by the remaining 0.25.
        let m = mv(p(0.0, 0.35), d(0.5, -0.6), &keep);
        assert_close(&m.position, &p(0.25, 0.0), 1e-14, "keep round a corner");
        let project_keep = MoveOptions {
            method: MoveMethod::Project,
            boundary: BoundaryMode::Keep,
            ..MoveOptions::default()
        };
        let m = mv(p(0.45, 0.0), d(0.1, 0.3), &project_keep);
        assert_close(&m.position, &p(0.55, 0.0), 1e-14, "keep with projection");
        let m = mv(p(0.55, 0.55), d(1.0, 0.3), &keep);
        assert_close(
            &m.position,
            &p(1.0, 0.85),
            1e-14,
            "keep slides inner points",
        );
        let m = mv(p(0.5, 0.5), d(0.1, 0.2), &keep);
        assert_eq!(m.outcome, MoveOutcome::Arrived);
        // A long slide wraps around the loop.
        let m = mv(p(1.0, 0.45), d(1.0, 4.0 * 3.0 + 0.1), &slide);
        assert_close(&m.position, &p(1.0, 0.55), 1e-12, "wrapping");
    }
}

#[test]
fn projection_and_fallback() {
    let mesh = build(&icosphere(4));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let mut rng = Rng::new(8);
    let project = MoveOptions {
        method: MoveMethod::Project,
        ..MoveOptions::default()
    };
    let starved = MoveOptions {
        max_steps: 1,
        ..MoveOptions::default()
    };
    for _ in 0..300 {
        let f = FaceId(rng.below(mesh.face_count()) as u32);
        let start = SurfacePoint::in_triangle(f, [0.2, 0.3, 0.5]);
        let frame = index.frame(&start).unwrap();
        let d = 0.05
            * frame.to_world(&nalgebra::Vector2::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ));
        let walked = index
            .move_point(&start, &d, &MoveOptions::default())
            .unwrap();
        let projected = index.move_point(&start, &d, &project).unwrap();
        assert_eq!(projected.outcome, MoveOutcome::Projected);
        // Both land on the sphere-like surface, within second order of each other.
        let gap = (walked.position - projected.position).norm();
        assert!(
            gap < 2.0 * d.norm_squared(),
            "{gap} for a step of {}",
            d.norm()
        );
        let located = index.locate(&(frame.origin + d)).unwrap();
        assert_eq!(projected.point.face, located.point.face);
        assert_close(&projected.position, &located.position, 1e-15, "projection");
        let fallback = index.move_point(&start, &d, &starved).unwrap();
        if walked.faces_crossed > 0 {
            assert_eq!(fallback.outcome, MoveOutcome::Projected);
        }
    }
}

#[test]
fn walks_land_on_warped_quads_and_spheres() {
    for mesh in [
        build(&torus(24, 12, 1.0, 0.4, Cells::Quads)),
        build(&icosphere(3)),
    ] {
        let index = SurfaceIndex::new(&mesh).unwrap();
        let mut rng = Rng::new(31);
        for _ in 0..500 {
            let f = FaceId(rng.below(mesh.face_count()) as u32);
            let start = if mesh.face_degree(f) == 4 {
                SurfacePoint::in_quad(f, rng.unit(), rng.unit())
            } else {
                SurfacePoint::in_triangle(f, [0.5, 0.25, 0.25])
            };
            let d = 0.5 * rng.direction();
            let moved = index
                .move_point(&start, &d, &MoveOptions::default())
                .unwrap();
            moved.point.validate(&mesh).unwrap();
            assert_eq!(moved.position, moved.point.position(&mesh));
            assert!(index.locate(&moved.position).unwrap().distance < 1e-12);
            assert_ne!(moved.outcome, MoveOutcome::Projected);
        }
    }
}

#[test]
fn face_reference_normals_sum_the_normals_at_the_corners_images() {
    // A coarse sphere (the source) mapped onto a finer one (the target) by locating its
    // vertices there: the reference of each source face is the sum of the target's
    // normals at its corners' images, pointing outward like the face.
    let source = build(&icosphere(1));
    let target = build(&icosphere(3));
    let index = SurfaceIndex::new(&target).unwrap();
    let images: Vec<SurfacePoint> = index
        .locate_all(source.positions())
        .unwrap()
        .into_iter()
        .map(|l| l.point)
        .collect();
    let normals = index.face_reference_normals(&source, &images).unwrap();
    assert_eq!(normals.len(), source.face_count());
    for f in source.faces() {
        let expected: Vector3<f64> = source
            .face_vertices(f)
            .map(|v| index.normal(&images[v.idx()]).unwrap())
            .sum();
        assert_eq!(normals[f.idx()], expected);
        // Three unit normals within about 40 degrees of one another.
        assert!(normals[f.idx()].norm() > 2.5, "{}", normals[f.idx()].norm());
        assert!(normals[f.idx()].normalize().dot(&source.face_normal(f)) > 0.95);
    }
    // One image per source vertex, each a point of the target.
    assert!(matches!(
        index.face_reference_normals(&source, &images[1..]),
        Err(SpatialError::LengthMismatch { .. })
    ));
    let mut bad = images.clone();
    bad[4] = SurfacePoint::in_triangle(FaceId(target.face_count() as u32), [1.0, 0.0, 0.0]);
    assert!(matches!(
        index.face_reference_normals(&source, &bad),
        Err(SpatialError::InBatch { index: 4, .. })
    ));
}

#[test]
fn frames_are_orthonormal_and_tangent() {
    let meshes: Vec<Mesh> = vec![
        build(&icosphere(2)),
        build(&torus(16, 8, 1.0, 0.3, Cells::Quads)),
        cube(3, false),
        build(&jittered_grid(5, 5, Cells::Triangles, 0.3, 4)),
    ];
    for mesh in &meshes {
        let index = SurfaceIndex::new(mesh).unwrap();
        let mut rng = Rng::new(2);
        let mut points: Vec<SurfacePoint> = mesh
            .vertices()
            .map(|v| SurfacePoint::at_vertex(mesh, v))
            .collect();
        for _ in 0..200 {
            let f = FaceId(rng.below(mesh.face_count()) as u32);
            points.push(if mesh.face_degree(f) == 4 {
                SurfacePoint::in_quad(f, rng.unit(), rng.unit())
            } else {
                SurfacePoint::in_triangle(f, [0.1, 0.6, 0.3])
            });
        }
        for p in &points {
            let fr = index.frame(p).unwrap();
            for v in [fr.e1, fr.e2, fr.normal] {
                assert!((v.norm() - 1.0).abs() < 1e-14);
            }
            assert!(fr.e1.dot(&fr.e2).abs() < 1e-14);
            assert!(fr.e1.dot(&fr.normal).abs() < 1e-14);
            assert!((fr.e1.cross(&fr.e2) - fr.normal).norm() < 1e-14);
            assert_eq!(fr.normal, index.normal(p).unwrap());
            // The normal agrees with the face's orientation.
            assert!(fr.normal.dot(&mesh.face_normal(p.face)) > 0.0);
            let t = Vector3::new(0.3, -1.0, 2.0);
            assert!(fr.tangential(&t).dot(&fr.normal).abs() < 1e-14);
            let local = fr.to_local(&fr.tangential(&t));
            assert!((fr.to_world(&local) - fr.tangential(&t)).norm() < 1e-14);
        }
        // At a vertex: the vertex normal.
        for v in mesh.vertices() {
            let fr = index.frame(&SurfacePoint::at_vertex(mesh, v)).unwrap();
            assert!((fr.normal - index.vertex_normals()[v.idx()]).norm() < 1e-15);
        }
    }
    // On a flat mesh: the face frame.
    let mesh = &meshes[3];
    let index = SurfaceIndex::new(mesh).unwrap();
    for f in mesh.faces() {
        let fr = index
            .frame(&SurfacePoint::in_triangle(f, [0.2, 0.2, 0.6]))
            .unwrap();
        let face = mesh.face_frame(f);
        assert!((fr.e1 - face.e1).norm() < 1e-15 && (fr.e2 - face.e2).norm() < 1e-15);
    }
}

#[test]
fn frames_follow_the_first_edge_on_curved_meshes() {
    // On an icosahedron and a cube the vertex normals turn 37 and 55 degrees from the
    // face normals; e1 stays the first edge's tangential direction all over each face.
    for mesh in [build(&icosphere(0)), cube(2, false)] {
        let index = SurfaceIndex::new(&mesh).unwrap();
        for f in mesh.faces() {
            let (v, _) = mesh.face_vertex_array(f);
            let edge = mesh.position(v[1]) - mesh.position(v[0]);
            for l in [
                [1.0, 0.0, 0.0],
                [0.05, 0.9, 0.05],
                [0.0, 0.0, 1.0],
                [0.4, 0.3, 0.3],
            ] {
                let fr = index.frame(&SurfacePoint::in_triangle(f, l)).unwrap();
                let t = fr.tangential(&edge).normalize();
                assert!((fr.e1 - t).norm() < 1e-14);
            }
        }
    }
}

#[test]
fn the_index_can_be_shared_across_threads() {
    fn shared<T: Send + Sync>(_: &T) {}
    let mesh = build(&icosphere(1));
    shared(&SurfaceIndex::new(&mesh).unwrap());
}

#[test]
fn zero_and_normal_displacements_stay_put() {
    let mesh = build(&torus(12, 8, 1.0, 0.3, Cells::Quads));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let p = SurfacePoint::in_quad(FaceId(5), 0.3, 0.7);
    let n = index.normal(&p).unwrap();
    for d in [Vector3::zeros(), 0.5 * n] {
        let moved = index.move_point(&p, &d, &MoveOptions::default()).unwrap();
        assert_eq!(moved.point, p);
        assert_eq!(moved.outcome, MoveOutcome::Arrived);
    }
}

#[test]
fn bad_moves_are_typed_errors_and_batches_are_all_or_nothing() {
    let mesh = build(&grid(4, 4, Cells::Triangles));
    let index = SurfaceIndex::new(&mesh).unwrap();
    let p = SurfacePoint::in_triangle(FaceId(3), [0.2, 0.3, 0.5]);
    let opts = MoveOptions::default();
    let err = index
        .move_point(&p, &Vector3::new(f64::NAN, 0.0, 0.0), &opts)
        .unwrap_err();
    assert!(matches!(err, SpatialError::NonFiniteDisplacement { .. }));
    let bad = SurfacePoint::in_triangle(FaceId(99), [1.0, 0.0, 0.0]);
    let err = index
        .move_point(&bad, &Vector3::zeros(), &opts)
        .unwrap_err();
    assert!(matches!(err, SpatialError::InvalidSurfacePoint(_)));
    assert!(err.to_string().contains("f99"), "{err}");
    assert!(index.frame(&bad).is_err());

    let mut points = vec![p, p, SurfacePoint::in_triangle(FaceId(1), [0.5, 0.6, 0.0])];
    let before = points.clone();
    let d = vec![Vector3::new(0.1, 0.0, 0.0); 3];
    let err = index.move_all(&mut points, &d, &opts).unwrap_err();
    assert!(err.to_string().starts_with("item 2:"), "{err}");
    assert_eq!(points, before);
    let err = index.move_all(&mut points, &d[..2], &opts).unwrap_err();
    assert!(matches!(err, SpatialError::LengthMismatch { .. }));

    let mut points = vec![p; 3];
    let d = vec![
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(5.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 0.0),
    ];
    let summary = index
        .move_all(&mut points, &d, &walk(BoundaryMode::Stop))
        .unwrap();
    assert_eq!(summary.arrived, 2);
    assert_eq!(summary.stopped_at_boundary, 1);
    assert_eq!(points[2], p);
    assert_close(
        &points[0].position(&mesh),
        &(p.position(&mesh) + d[0]),
        1e-15,
        "batch",
    );
}

#[test]
fn batches_on_several_threads_give_each_point_the_same_answer() {
    // A torus of 64 x 128 x 2 faces and 20,000 points: enough for several chunks per
    // thread (beltrami_mesh::parallel::MIN_CHUNK).
    let mesh = build(&torus(128, 64, 3.0, 1.0, Cells::Triangles));
    let one = SurfaceIndex::new(&mesh).unwrap();
    let mut rng = Rng::new(11);
    let points: Vec<Point3<f64>> = (0..20_000)
        .map(|_| {
            Point3::new(
                8.0 * rng.unit() - 4.0,
                8.0 * rng.unit() - 4.0,
                2.0 * rng.unit() - 1.0,
            )
        })
        .collect();
    let located = one.locate_all(&points).unwrap();
    let hints: Vec<FaceId> = located.iter().map(|l| l.point.face).collect();
    let steps: Vec<Vector3<f64>> = (0..points.len())
        .map(|_| Vector3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5))
        .collect();
    let mut walked_one: Vec<SurfacePoint> = located.iter().map(|l| l.point).collect();
    let summary_one = one
        .move_all(&mut walked_one, &steps, &walk(BoundaryMode::Stop))
        .unwrap();
    for threads in [2, 3, 0] {
        let many = SurfaceIndex::new(&mesh).unwrap().with_threads(threads);
        assert!(many.threads() >= 1);
        assert_eq!(many.locate_all(&points).unwrap(), located);
        assert_eq!(many.locate_all_near(&points, &hints).unwrap(), located);
        let mut walked: Vec<SurfacePoint> = located.iter().map(|l| l.point).collect();
        let summary = many
            .move_all(&mut walked, &steps, &walk(BoundaryMode::Stop))
            .unwrap();
        assert_eq!(walked, walked_one, "{threads} threads");
        assert_eq!(summary, summary_one);
        // A few thousand searches are shared between threads too (in stretches of a
        // few hundred points, each starting without the previous point's face).
        let few = &points[..3_000];
        assert_eq!(many.locate_all(few).unwrap(), located[..3_000]);
        assert_eq!(
            many.locate_all_near(few, &hints[..3_000]).unwrap(),
            located[..3_000]
        );
    }
    // A failure names the first bad point in point order, whatever the threads.
    let mut bad = steps.clone();
    bad[15_000] = Vector3::new(f64::NAN, 0.0, 0.0);
    bad[17_000] = Vector3::new(f64::NAN, 0.0, 0.0);
    let many = SurfaceIndex::new(&mesh).unwrap().with_threads(2);
    let mut walked: Vec<SurfacePoint> = located.iter().map(|l| l.point).collect();
    let error = many
        .move_all(&mut walked, &bad, &walk(BoundaryMode::Stop))
        .unwrap_err();
    assert!(error.to_string().contains("15000"), "{error}");
}
