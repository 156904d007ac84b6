//! Boundary maps: arc length, orientation (clockwise in loop order), corners, and the
//! errors for bad polygons and corner vertices.

mod common;

use std::f64::consts::TAU;

use beltrami_fem::boundary::{self, BoundaryError, BoundaryMap};
use beltrami_mesh::primitives::{Cells, grid, icosphere};
use beltrami_mesh::{Mesh, VertexId};
use common::{boundary_vertices, cross, hemisphere, jittered};
use num_complex::Complex64;

fn signed_area(z: &[Complex64]) -> f64 {
    let n = z.len();
    (0..n).map(|k| cross(z[k], z[(k + 1) % n])).sum::<f64>() / 2.0
}

/// Arc lengths between consecutive loop vertices, in 3D.
fn edge_lengths(mesh: &Mesh, map: &BoundaryMap) -> Vec<f64> {
    let n = map.vertices.len();
    (0..n)
        .map(|k| (mesh.position(map.vertices[(k + 1) % n]) - mesh.position(map.vertices[k])).norm())
        .collect()
}

#[test]
fn circle_by_arc_length_clockwise() {
    let mesh = hemisphere();
    let map = boundary::circle(&mesh, None).unwrap();
    assert_eq!(map.vertices, boundary_vertices(&mesh));
    assert_eq!(map.positions[0], Complex64::new(1.0, 0.0));
    assert!(signed_area(&map.positions) < 0.0);
    let lengths = edge_lengths(&mesh, &map);
    let total: f64 = lengths.iter().sum();
    let n = map.positions.len();
    for (k, length) in lengths.iter().enumerate() {
        assert!((map.positions[k].norm() - 1.0).abs() < 1e-15);
        // The clockwise angle from vertex k to k + 1 is 2 pi times its share of length.
        let step = (map.positions[k] / map.positions[(k + 1) % n]).arg();
        assert!((step - TAU * length / total).abs() < 1e-12, "{k}");
    }
    let start = map.vertices[9];
    let rotated = boundary::circle(&mesh, Some(start)).unwrap();
    assert_eq!(rotated.vertices[0], start);
    assert_eq!(rotated.positions[0], Complex64::new(1.0, 0.0));
}

#[test]
fn square_of_a_grid_is_the_grid_boundary_up_to_a_rotation() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = Mesh::from_soup(&grid(5, 5, cells)).unwrap();
        let map = boundary::square(&mesh, None, None).unwrap();
        let own: Vec<Complex64> = map
            .vertices
            .iter()
            .map(|&v| Complex64::new(mesh.position(v).x, mesh.position(v).y))
            .collect();
        let centre = Complex64::new(0.5, 0.5);
        let fits = (0..4).any(|r| {
            let rot = Complex64::i().powu(r);
            own.iter()
                .zip(&map.positions)
                .all(|(&p, &q)| ((p - centre) * rot + centre - q).norm() < 1e-14)
        });
        assert!(fits, "{cells:?}: {:?}", map.positions);
    }
}

#[test]
fn given_square_corners_and_their_errors() {
    let mesh = jittered(6, Cells::Triangles, 0.2, 31);
    let b = boundary_vertices(&mesh);
    let n = b.len();
    let ccw = [b[2], b[2 + 3 * n / 4], b[2 + n / 2], b[2 + n / 4]];
    let map = boundary::square(&mesh, Some(ccw), None).unwrap();
    assert_eq!(map.vertices[0], ccw[0]);
    let at = |v: VertexId| map.positions[map.vertices.iter().position(|&w| w == v).unwrap()];
    assert_eq!(at(ccw[0]), Complex64::new(0.0, 0.0));
    assert_eq!(at(ccw[1]), Complex64::new(1.0, 0.0));
    assert_eq!(at(ccw[2]), Complex64::new(1.0, 1.0));
    assert_eq!(at(ccw[3]), Complex64::new(0.0, 1.0));
    assert!(signed_area(&map.positions) < 0.0);

    let cw = [ccw[0], ccw[3], ccw[2], ccw[1]];
    assert!(matches!(
        boundary::square(&mesh, Some(cw), None),
        Err(BoundaryError::CornerOrder { .. })
    ));
    let repeated = [ccw[0], ccw[1], ccw[1], ccw[3]];
    assert_eq!(
        boundary::square(&mesh, Some(repeated), None),
        Err(BoundaryError::RepeatedCorner { vertex: ccw[1] })
    );
    let interior = mesh
        .vertices()
        .find(|&v| !mesh.is_boundary_vertex(v))
        .unwrap();
    let off = [ccw[0], ccw[1], interior, ccw[3]];
    assert_eq!(
        boundary::square(&mesh, Some(off), None),
        Err(BoundaryError::NotOnBoundary { vertex: interior })
    );
    assert_eq!(
        boundary::square(&mesh, Some(ccw), Some(ccw[1])),
        Err(BoundaryError::StartNotFirstCorner {
            start: ccw[1],
            corner: ccw[0]
        })
    );
}

#[test]
fn polygon_corners_and_sides() {
    let mesh = hemisphere();
    let corners = vec![
        Complex64::new(0.0, 0.0),
        Complex64::new(3.0, 0.0),
        Complex64::new(4.0, 2.0),
        Complex64::new(1.0, 3.0),
        Complex64::new(-1.0, 1.0),
    ];
    let map = boundary::polygon(&mesh, &corners, None).unwrap();
    assert_eq!(map.positions[0], corners[0]);
    assert!(signed_area(&map.positions) < 0.0);
    // Every corner is the image of a vertex, and every vertex lies on a side.
    for c in &corners {
        assert!(map.positions.contains(c), "{c}");
    }
    let m = corners.len();
    for z in &map.positions {
        let d = (0..m)
            .map(|k| {
                let (a, b) = (corners[k], corners[(k + 1) % m]);
                let t = ((z - a) * (b - a).conj()).re / (b - a).norm_sqr();
                assert!((-1e-15..=1.0 + 1e-15).contains(&t) || cross(b - a, z - a).abs() > 1e-9);
                cross(b - a, z - a).abs() / (b - a).norm()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-14, "{z}: {d:e}");
    }
    // The sharpest boundary vertex is the default start; a given one is honoured.
    let start = map.vertices[17];
    let moved = boundary::polygon(&mesh, &corners, Some(start)).unwrap();
    assert_eq!(moved.vertices[0], start);
    assert_eq!(moved.positions[0], corners[0]);
}

#[test]
fn bad_polygons_name_the_corner() {
    let mesh = hemisphere();
    let c = |pts: &[(f64, f64)]| -> Vec<Complex64> {
        pts.iter().map(|&(x, y)| Complex64::new(x, y)).collect()
    };
    let polygon = |pts: &[(f64, f64)]| boundary::polygon(&mesh, &c(pts), None);
    assert_eq!(
        polygon(&[(0.0, 0.0), (1.0, 0.0)]),
        Err(BoundaryError::TooFewCorners { corners: 2 })
    );
    assert_eq!(
        polygon(&[(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]),
        Err(BoundaryError::NotCounterClockwise { corner: 0 })
    );
    // A dart: reflex at corner 2.
    assert_eq!(
        polygon(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.5), (1.0, 2.0)]),
        Err(BoundaryError::NotConvex { corner: 2 })
    );
    // A straight corner.
    assert_eq!(
        polygon(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)]),
        Err(BoundaryError::NotConvex { corner: 1 })
    );
    // A pentagram turns left everywhere but winds twice.
    let star: Vec<Complex64> = (0..5)
        .map(|k| Complex64::from_polar(1.0, TAU * (2 * k) as f64 / 5.0))
        .collect();
    assert!(matches!(
        boundary::polygon(&mesh, &star, None),
        Err(BoundaryError::NotConvex { .. })
    ));
    assert_eq!(
        polygon(&[(0.0, 0.0), (f64::NAN, 0.0), (1.0, 1.0)]),
        Err(BoundaryError::NonFiniteCorner { corner: 1 })
    );
    let tiny = Mesh::from_soup(&grid(1, 1, Cells::Quads)).unwrap();
    let pentagon: Vec<Complex64> = (0..5)
        .map(|k| Complex64::from_polar(1.0, TAU * k as f64 / 5.0))
        .collect();
    assert_eq!(
        boundary::polygon(&tiny, &pentagon, None),
        Err(BoundaryError::TooFewVertices {
            vertices: 4,
            corners: 5
        })
    );
    // As many vertices as corners: every vertex is a corner.
    let square = boundary::square(&tiny, None, None).unwrap();
    let mut images = square.positions.clone();
    images.sort_by(|a, b| (a.re, a.im).partial_cmp(&(b.re, b.im)).unwrap());
    assert_eq!(images, c(&[(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]));
}

#[test]
fn keep_given_and_closed_meshes() {
    let mesh = jittered(4, Cells::Quads, 0.2, 32);
    let kept = boundary::keep(&mesh).unwrap();
    for (v, z) in kept.vertices.iter().zip(&kept.positions) {
        assert_eq!(*z, Complex64::new(mesh.position(*v).x, mesh.position(*v).y));
    }
    assert!(matches!(
        boundary::keep(&hemisphere()),
        Err(BoundaryError::NotPlanar { .. })
    ));
    let values: Vec<Complex64> = (0..mesh.vertex_count())
        .map(|i| Complex64::new(i as f64, 0.0))
        .collect();
    let given = boundary::given(&mesh, &values).unwrap();
    for (v, z) in given.vertices.iter().zip(&given.positions) {
        assert_eq!(z.re, v.idx() as f64);
    }
    assert_eq!(
        boundary::given(&mesh, &values[1..]),
        Err(BoundaryError::Length {
            expected: values.len(),
            got: values.len() - 1
        })
    );
    let mut bad = values.clone();
    let b0 = kept.vertices[0];
    bad[b0.idx()] = Complex64::new(f64::INFINITY, 0.0);
    assert_eq!(
        boundary::given(&mesh, &bad),
        Err(BoundaryError::NonFiniteValue { vertex: b0 })
    );
    let sphere = Mesh::from_soup(&icosphere(1)).unwrap();
    assert_eq!(
        boundary::circle(&sphere, None),
        Err(BoundaryError::NoBoundary)
    );
    assert_eq!(
        boundary::circle(&mesh, Some(VertexId(999))),
        Err(BoundaryError::VertexOutOfRange {
            vertex: VertexId(999),
            vertex_count: mesh.vertex_count()
        })
    );
}
