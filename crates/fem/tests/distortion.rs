//! Distortion statistics: formulas by hand, affine maps (constant mu), flipped faces.

use beltrami_fem::beltrami::planar_map;
use beltrami_fem::distortion::{measure_planar, measure_surface};
use beltrami_fem::{
    Distortion, DistortionStats, Elements, FemError, Frame, Histogram, ReferenceNormal,
};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use num_complex::Complex64;

mod common;
use common::jittered;

fn complex(p: &Point3<f64>) -> Complex64 {
    Complex64::new(p.x, p.y)
}

#[test]
fn statistics_of_a_known_field_by_hand() {
    // |mu| = 0.1, 0.5, 0.5, 0.95, 1.2 on faces of areas 1..5.
    let mu = [
        Complex64::new(0.1, 0.0),
        Complex64::new(0.0, 0.5),
        Complex64::new(0.3, -0.4),
        Complex64::new(-0.95, 0.0),
        Complex64::new(0.0, -1.2),
    ];
    let areas = [1.0, 2.0, 3.0, 4.0, 5.0];
    let flipped = [false, false, false, false, true];
    let s = DistortionStats::new(&mu, &areas, &flipped).unwrap();
    assert_eq!(s.faces, 5);
    assert_eq!(s.flipped, 1);
    // mean = 3.25 / 5.
    assert!((s.mu_mean - 0.65).abs() < 1e-15, "{}", s.mu_mean);
    assert_eq!(s.mu_max, 1.2);
    // Deviations -0.55, -0.15, -0.15, 0.3, 0.55: sum of squares 0.74.
    assert!(
        (s.mu_std - (0.74f64 / 5.0).sqrt()).abs() < 1e-15,
        "{}",
        s.mu_std
    );
    // sum A |mu|^2 = 0.01 + 0.5 + 0.75 + 3.61 + 7.2 = 12.07 over a total area of 15.
    assert!(
        (s.mu_l2 - (12.07f64 / 15.0).sqrt()).abs() < 1e-15,
        "{}",
        s.mu_l2
    );
    assert_eq!(s.histogram.bins, [0, 1, 0, 0, 0, 2, 0, 0, 0, 1]);
    assert_eq!(s.histogram.at_least_one, 1);

    // Equal areas: the L2 norm is the root mean square (sum |mu|^2 = 2.8525).
    let s = DistortionStats::new(&mu, &[2.0; 5], &flipped).unwrap();
    assert!((s.mu_l2 - (2.8525f64 / 5.0).sqrt()).abs() < 1e-15);
    // The unequal areas above weight the large values more.
    assert!((12.07f64 / 15.0).sqrt() > s.mu_l2);
}

#[test]
fn histogram_bins_cover_zero_to_one() {
    let moduli = [
        0.0, 0.05, 0.1, 0.15, 0.25, 0.45, 0.55, 0.65, 0.75, 0.85, 0.999, 1.0, 3.0,
    ];
    let mu: Vec<Complex64> = moduli.iter().map(|&m| Complex64::new(0.0, m)).collect();
    let s = DistortionStats::new(&mu, &[1.0; 13], &[false; 13]).unwrap();
    assert_eq!(s.histogram.bins, [2, 2, 1, 0, 1, 1, 1, 1, 1, 1]);
    assert_eq!(s.histogram.at_least_one, 2);
    assert_eq!(Histogram::BINS, 10);
    assert_eq!(Histogram::WIDTH, 0.1);
    assert_eq!(
        s.histogram.bins.iter().sum::<usize>() + s.histogram.at_least_one,
        s.faces
    );
}

#[test]
fn bad_statistics_input_is_a_typed_error() {
    let mu = [Complex64::new(0.1, 0.0); 3];
    assert!(matches!(
        DistortionStats::new(&mu, &[1.0; 2], &[false; 3]),
        Err(FemError::Length {
            expected: 3,
            got: 2,
            ..
        })
    ));
    assert!(matches!(
        DistortionStats::new(&mu, &[1.0; 3], &[false; 4]),
        Err(FemError::Length {
            expected: 3,
            got: 4,
            ..
        })
    ));
    let mut bad = mu;
    bad[1].im = f64::NAN;
    assert!(matches!(
        DistortionStats::new(&bad, &[1.0; 3], &[false; 3]),
        Err(FemError::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        DistortionStats::new(&mu, &[1.0, -1.0, 1.0], &[false; 3]),
        Err(FemError::NonFinite { index: 1, .. })
    ));
    assert_eq!(
        DistortionStats::new(&[], &[], &[]).unwrap(),
        DistortionStats::default()
    );
}

#[test]
fn an_affine_map_has_constant_mu() {
    // f(z) = z + 0.3 conj(z): mu = 0.3 everywhere, in every frame (the plane's, and the
    // faces' where only the argument turns).
    let k = 0.3;
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(12, cells, 0.3, 3);
        let map: Vec<Complex64> = mesh
            .positions()
            .iter()
            .map(|p| complex(p) + k * complex(p).conj())
            .collect();
        for frame in [Frame::Global, Frame::Face] {
            let d = measure_planar(&mesh, &map, frame).unwrap();
            let s = &d.stats;
            assert_eq!(d.field.frame, frame);
            assert_eq!(s.faces, mesh.face_count());
            assert_eq!(s.flipped, 0);
            assert!(d.flipped.iter().all(|&f| !f));
            assert!(
                (s.mu_max - k).abs() < 1e-12,
                "{cells:?} {frame:?} {}",
                s.mu_max
            );
            assert!((s.mu_mean - k).abs() < 1e-12, "{}", s.mu_mean);
            assert!((s.mu_l2 - k).abs() < 1e-12, "{}", s.mu_l2);
            assert!(s.mu_std < 1e-12, "{}", s.mu_std);
            // 0.3 sits on the edge between bins 2 and 3; rounding decides which.
            assert_eq!(s.histogram.bins[2] + s.histogram.bins[3], s.faces);
            if frame == Frame::Global {
                assert!(
                    d.field
                        .mu
                        .iter()
                        .all(|m| (m - Complex64::new(k, 0.0)).norm() < 1e-12)
                );
            }
        }
    }
}

#[test]
fn similarities_of_surfaces_are_conformal() {
    // Scale 2.5, rotation by 40 degrees about (1, 2, 2) / 3, translation.
    let axis = nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 2.0));
    let rotation = nalgebra::Rotation3::from_axis_angle(&axis, 40f64.to_radians());
    for soup in [icosphere(2), torus(16, 10, 2.0, 0.6, Cells::Quads)] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let image: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::from(2.5 * (rotation * p.coords) + Vector3::new(1.0, -2.0, 0.5)))
            .collect();
        let d = measure_surface(&mesh, &image, ReferenceNormal::Source).unwrap();
        assert_eq!(d.field.frame, Frame::Face);
        assert_eq!(d.stats.flipped, 0);
        assert!(d.stats.mu_max < 1e-12, "{}", d.stats.mu_max);
    }
}

/// Reflects `p` across the line through `a` and `b`.
fn reflect(p: Complex64, a: Complex64, b: Complex64) -> Complex64 {
    let u = (b - a) / (b - a).norm();
    a + u * u * (p - a).conj()
}

/// Signed area of the image of a triangle.
fn signed_area(map: &[Complex64], v: &[VertexId]) -> f64 {
    let (a, b, c) = (map[v[0].idx()], map[v[1].idx()], map[v[2].idx()]);
    0.5 * ((b - a).conj() * (c - a)).im
}

#[test]
fn a_planar_map_as_positions_judged_by_the_plane_is_the_planar_map() {
    // A smooth map with a fold: past x = 0.6 the image turns back with half the speed
    // (f = 0.6 - (x - 0.6) / 2 + i y there, |mu| = 3), so the faces beyond are flipped.
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(16, cells, 0.3, 7);
        let map: Vec<Complex64> = mesh
            .positions()
            .iter()
            .map(|p| {
                let x = if p.x > 0.6 {
                    0.6 - 0.5 * (p.x - 0.6)
                } else {
                    p.x
                };
                let z = Complex64::new(x, p.y);
                z + 0.2 * z * z
            })
            .collect();
        let image: Vec<Point3<f64>> = map.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect();
        assert_eq!(ReferenceNormal::for_image(&image), ReferenceNormal::Plane);
        let planar = measure_planar(&mesh, &map, Frame::Face).unwrap();
        let spatial = measure_surface(&mesh, &image, ReferenceNormal::Plane).unwrap();
        assert_eq!(spatial.field.frame, Frame::Face);
        assert_eq!(spatial.flipped, planar.flipped, "{cells:?}");
        let flips = planar.stats.flipped;
        assert!(flips > mesh.face_count() / 5, "{cells:?}: {flips} flips");
        for f in 0..mesh.face_count() {
            let (a, b) = (planar.field.mu[f], spatial.field.mu[f]);
            assert!(
                (a - b).norm() <= 1e-12 * a.norm().max(1.0),
                "{cells:?} face {f}: planar {a}, positions {b}"
            );
        }
        assert_eq!(spatial.stats.histogram, planar.stats.histogram);
        assert!((spatial.stats.mu_max - planar.stats.mu_max).abs() <= 1e-12 * planar.stats.mu_max);
        // Judged against the source normals (+z here) the answer is the same; the
        // image's own orientation is never asked.
        let source = measure_surface(&mesh, &image, ReferenceNormal::Source).unwrap();
        assert_eq!(source.flipped, planar.flipped);
    }
}

#[test]
fn the_reference_is_chosen_from_the_image() {
    let mesh = Mesh::from_soup(&icosphere(2)).unwrap();
    let sphere = mesh.positions().to_vec();
    assert_eq!(ReferenceNormal::for_image(&sphere), ReferenceNormal::Radial);
    let moved: Vec<Point3<f64>> = sphere
        .iter()
        .map(|p| p + Vector3::new(0.0, 0.0, 0.5))
        .collect();
    assert_eq!(ReferenceNormal::for_image(&moved), ReferenceNormal::Source);
    let mut bumped = sphere.clone();
    bumped[3] *= 1.0 + 1e-5;
    assert_eq!(ReferenceNormal::for_image(&bumped), ReferenceNormal::Source);
    bumped[3] = sphere[3] * (1.0 + 1e-7);
    assert_eq!(ReferenceNormal::for_image(&bumped), ReferenceNormal::Radial);
    let flat: Vec<Point3<f64>> = sphere.iter().map(|p| Point3::new(p.x, p.y, 0.0)).collect();
    assert_eq!(ReferenceNormal::for_image(&flat), ReferenceNormal::Plane);
    let tilted: Vec<Point3<f64>> = flat
        .iter()
        .map(|p| Point3::new(p.x, p.y, 1e-3 * p.x))
        .collect();
    assert_eq!(ReferenceNormal::for_image(&tilted), ReferenceNormal::Source);
    assert_eq!(ReferenceNormal::Plane.name(), "plane");
    assert_eq!(ReferenceNormal::Radial.name(), "radial");
    assert_eq!(ReferenceNormal::Source.name(), "source");
    assert_eq!(ReferenceNormal::PerFace(&[]).name(), "per-face");
    // One normal per face, finite.
    let short = vec![Vector3::z(); 3];
    assert!(matches!(
        measure_surface(&mesh, &sphere, ReferenceNormal::PerFace(&short)),
        Err(FemError::Length { got: 3, .. })
    ));
    let mut nan = vec![Vector3::z(); mesh.face_count()];
    nan[5].x = f64::NAN;
    assert!(matches!(
        measure_surface(&mesh, &sphere, ReferenceNormal::PerFace(&nan)),
        Err(FemError::NonFinite { index: 5, .. })
    ));
}

#[test]
fn a_reflected_vertex_flips_its_faces() {
    let mesh = jittered(8, Cells::Triangles, 0.25, 41);
    let mut map: Vec<Complex64> = mesh.positions().iter().map(complex).collect();
    // An interior vertex, reflected across the opposite side of one of its triangles.
    let v = mesh
        .vertices()
        .find(|&v| !mesh.is_boundary_vertex(v) && v.idx() > 30)
        .unwrap();
    let h = mesh.vertex_halfedge(v);
    let f = mesh.face(h).unwrap();
    let (a, b) = (mesh.target(h), mesh.target(mesh.next(h)));
    map[v.idx()] = reflect(map[v.idx()], map[a.idx()], map[b.idx()]);

    let d = measure_planar(&mesh, &map, Frame::Global).unwrap();
    assert!(d.flipped[f.idx()], "the reflected triangle {f} is flipped");
    let mut count = 0;
    for g in mesh.faces() {
        let vertices: Vec<VertexId> = mesh.face_vertices(g).collect();
        let negative = signed_area(&map, &vertices) < 0.0;
        assert_eq!(d.flipped[g.idx()], negative, "face {g}");
        assert_eq!(d.field.mu[g.idx()].norm() > 1.0, negative, "face {g}");
        if negative {
            assert!(
                vertices.contains(&v),
                "face {g} does not touch the moved vertex"
            );
            count += 1;
        }
    }
    assert_eq!(d.stats.flipped, count);
    assert_eq!(d.stats.histogram.at_least_one, count);

    // The same map seen as a map of a surface into R^3, judged against the source
    // normals: the same faces flip.
    let image: Vec<Point3<f64>> = map.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect();
    let s = measure_surface(&mesh, &image, ReferenceNormal::Source).unwrap();
    assert_eq!(s.flipped, d.flipped);
    // Judged against normals pointing down instead, every other face is flipped.
    let down = vec![-Vector3::z(); mesh.face_count()];
    let s = measure_surface(&mesh, &image, ReferenceNormal::PerFace(&down)).unwrap();
    assert!(s.flipped.iter().zip(&d.flipped).all(|(a, b)| a != b));
}

#[test]
fn a_quad_folded_by_a_moved_corner_is_flipped() {
    let n = 6;
    let mesh = Mesh::from_soup(&grid(n, n, Cells::Quads)).unwrap();
    let mut map: Vec<Complex64> = mesh.positions().iter().map(complex).collect();
    // Vertex (2, 2) moved beyond the opposite corner (3, 3) of the quad it starts.
    let id = |i: usize, j: usize| VertexId((i + (n + 1) * j) as u32);
    let h = 1.0 / n as f64;
    map[id(2, 2).idx()] = Complex64::new(3.6 * h, 3.6 * h);
    let d = measure_planar(&mesh, &map, Frame::Global).unwrap();
    let folded = FaceId((2 + n * 2) as u32);
    assert!(d.flipped[folded.idx()]);
    for g in mesh.faces() {
        if d.flipped[g.idx()] {
            assert!(mesh.face_vertices(g).any(|w| w == id(2, 2)), "face {g}");
        }
    }
    assert_eq!(d.stats.flipped, d.flipped.iter().filter(|&&f| f).count());
}

#[test]
fn measured_face_by_face_as_through_the_stored_elements() {
    // A curved surface (triangles and quads) under a map that folds part of it: the
    // streamed measure gives the very values of the elements' path (8192 and 4096 faces:
    // several ranges of faces on a machine of several cores).
    for (cells, amount) in [(Cells::Triangles, 0.3), (Cells::Quads, 0.24)] {
        let flat = jittered(64, cells, amount, 41);
        let bent: Vec<Point3<f64>> = flat
            .positions()
            .iter()
            .map(|p| Point3::new(p.x, p.y, 0.5 * p.x * p.y - 0.3 * p.x * p.x))
            .collect();
        let mesh = flat.with_positions(bent).unwrap();
        let map: Vec<Complex64> = mesh
            .positions()
            .iter()
            .map(|p| {
                let z = complex(p);
                // |mu| = 3 |z| / |1 - 0.9 z^2| passes 1 (a fold) beyond |z| ~ 1/3.
                z - Complex64::new(0.0, 0.3) * z * z * z + 1.5 * z.conj() * z.conj()
            })
            .collect();
        {
            let frame = Frame::Face;
            let elements = Elements::new(&mesh, frame).unwrap();
            let derivatives = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
            let expected = Distortion::from_derivatives(&elements, &derivatives).unwrap();
            let got = measure_planar(&mesh, &map, frame).unwrap();
            assert!(
                expected.flipped.iter().any(|&f| f),
                "{cells:?}: nothing folds"
            );
            assert_eq!(got, expected, "{cells:?}");
        }
    }
    // The global frame on a planar mesh, and its check.
    let mesh = jittered(9, Cells::Triangles, 0.3, 42);
    let map: Vec<Complex64> = mesh
        .positions()
        .iter()
        .map(|p| complex(p) * complex(p))
        .collect();
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let derivatives = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
    let expected = Distortion::from_derivatives(&elements, &derivatives).unwrap();
    assert_eq!(
        measure_planar(&mesh, &map, Frame::Global).unwrap(),
        expected
    );
    let lifted: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.x))
        .collect();
    let lifted = mesh.with_positions(lifted).unwrap();
    assert!(matches!(
        measure_planar(&lifted, &map, Frame::Global),
        Err(FemError::NotPlanar { .. })
    ));
    let mut broken = map.clone();
    broken[3] = Complex64::new(f64::NAN, 0.0);
    assert!(matches!(
        measure_planar(&mesh, &broken, Frame::Face),
        Err(FemError::NonFinite { index: 3, .. })
    ));
}
