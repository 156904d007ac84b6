//! Geometry of generated meshes: areas (including non-planar bilinear quads), corner
//! angles, vertex normals, edge lengths, bounding boxes, face frames and centroids.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{BoundingBox, FaceId, Mesh, Point3, PolygonSoup, Vector2, Vector3, VertexId};

mod common;
use common::Rng;

fn mesh(soup: &PolygonSoup) -> Mesh {
    Mesh::from_soup(soup).expect("valid mesh")
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn rel_err(a: f64, exact: f64) -> f64 {
    ((a - exact) / exact).abs()
}

/// Area of the bilinear patch through `p` by an `n` x `n` midpoint rule.
fn bilinear_area_midpoint(p: [Point3<f64>; 4], n: usize) -> f64 {
    let (d01, d32, d03, d12) = (p[1] - p[0], p[2] - p[3], p[3] - p[0], p[2] - p[1]);
    let h = 1.0 / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        let u = (i as f64 + 0.5) * h;
        for j in 0..n {
            let v = (j as f64 + 0.5) * h;
            let xu = (1.0 - v) * d01 + v * d32;
            let xv = (1.0 - u) * d03 + u * d12;
            sum += xu.cross(&xv).norm();
        }
    }
    sum * h * h
}

/// Area of the bilinear patch through `p` by the 2x2 Gauss rule.
fn bilinear_area_gauss2(p: [Point3<f64>; 4]) -> f64 {
    let g = [0.5 - 0.5 / 3f64.sqrt(), 0.5 + 0.5 / 3f64.sqrt()];
    let (d01, d32, d03, d12) = (p[1] - p[0], p[2] - p[3], p[3] - p[0], p[2] - p[1]);
    let mut sum = 0.0;
    for &u in &g {
        for &v in &g {
            let xu = (1.0 - v) * d01 + v * d32;
            let xv = (1.0 - u) * d03 + u * d12;
            sum += 0.25 * xu.cross(&xv).norm();
        }
    }
    sum
}

fn single_quad(p: [Point3<f64>; 4]) -> Mesh {
    mesh(&PolygonSoup::from_quads(p.to_vec(), &[[0, 1, 2, 3]]))
}

fn corner_angle_sum(m: &Mesh, f: FaceId) -> f64 {
    m.face_halfedges(f).map(|h| m.corner_angle(h)).sum()
}

fn vertex_angle_sum(m: &Mesh, v: VertexId) -> f64 {
    m.outgoing_halfedges(v)
        .filter(|&h| m.face(h).is_some())
        .map(|h| m.corner_angle(h))
        .sum()
}

// ---------------------------------------------------------------------------------------
// Areas
// ---------------------------------------------------------------------------------------

#[test]
fn unit_grid_has_unit_area() {
    for &(nx, ny) in &[(1, 1), (2, 3), (7, 4), (16, 16), (1, 30)] {
        for cells in [Cells::Triangles, Cells::Quads] {
            let m = mesh(&primitives::grid(nx, ny, cells));
            assert!(
                close(m.total_area(), 1.0, 1e-12),
                "{nx}x{ny} {cells:?}: {}",
                m.total_area()
            );
            let per_cell = if cells == Cells::Quads { 1.0 } else { 0.5 };
            let expected = per_cell / (nx * ny) as f64;
            for f in m.faces() {
                assert!(close(m.face_area(f), expected, 1e-15), "{f:?}");
                // For planar faces the vector area has the same norm, pointing +z.
                let va = m.face_vector_area(f);
                assert!(close(va.norm(), expected, 1e-15));
                assert!(close(va.z, expected, 1e-15));
            }
        }
    }
}

#[test]
fn icosphere_area_converges_quadratically() {
    let exact = 4.0 * PI;
    let errors: Vec<f64> = (0..=5)
        .map(|s| {
            let m = mesh(&primitives::icosphere(s));
            exact - m.total_area()
        })
        .collect();
    // An inscribed polyhedron has less area than the sphere.
    assert!(errors.iter().all(|&e| e > 0.0), "{errors:?}");
    assert!(
        errors[4] / exact < 3e-3,
        "icosphere(4) relative error {}",
        errors[4] / exact
    );
    assert!(
        errors[5] / exact < 1e-3,
        "icosphere(5) relative error {}",
        errors[5] / exact
    );
    // The error shrinks by about 4 per level (h halves, error ~ h^2).
    for s in 1..5 {
        let ratio = errors[s] / errors[s + 1];
        assert!(
            (3.5..4.5).contains(&ratio),
            "ratio at level {s}: {ratio} ({errors:?})"
        );
    }
}

#[test]
fn icosahedron_area_is_exact() {
    // icosphere(0) is the regular icosahedron inscribed in the unit sphere: edge
    // a = 4 / sqrt(10 + 2 sqrt 5), area 5 sqrt 3 a^2.
    let m = mesh(&primitives::icosphere(0));
    let a = 4.0 / (10.0 + 2.0 * 5f64.sqrt()).sqrt();
    assert!(close(m.total_area(), 5.0 * 3f64.sqrt() * a * a, 1e-12));
    for e in m.edges() {
        assert!(close(m.edge_length(e), a, 1e-12));
    }
}

#[test]
fn torus_area_approaches_4_pi_squared_r_r() {
    let (big, small) = (2.0, 0.5);
    let exact = 4.0 * PI * PI * big * small;
    for cells in [Cells::Triangles, Cells::Quads] {
        let coarse = mesh(&primitives::torus(24, 12, big, small, cells)).total_area();
        let fine = mesh(&primitives::torus(192, 96, big, small, cells)).total_area();
        assert!(rel_err(fine, exact) < 1e-3, "{cells:?}: {fine} vs {exact}");
        assert!(
            rel_err(fine, exact) < rel_err(coarse, exact) / 10.0,
            "{cells:?}"
        );
        // Faces are inscribed, so the area is below the smooth one.
        assert!(fine < exact && coarse < fine, "{cells:?}");
    }
}

#[test]
fn torus_quads_are_planar_trapezoids() {
    // Each torus cell is an isosceles trapezoid: its bilinear area equals its vector
    // area norm and equals the area of the two triangles of the split cell.
    let q = mesh(&primitives::torus(10, 7, 2.0, 0.7, Cells::Quads));
    let t = mesh(&primitives::torus(10, 7, 2.0, 0.7, Cells::Triangles));
    for f in q.faces() {
        let a = q.face_area(f);
        assert!(close(a, q.face_vector_area(f).norm(), 1e-12 * a));
        let split = t.face_area(FaceId(2 * f.0)) + t.face_area(FaceId(2 * f.0 + 1));
        assert!(close(a, split, 1e-12 * a), "{f:?}: {a} vs {split}");
    }
    assert!(close(q.total_area(), t.total_area(), 1e-10));
}

#[test]
fn hyperbolic_paraboloid_quad_area() {
    // z = x y over the unit square is exactly the bilinear patch of these corners.
    let p = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 1.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let m = single_quad(p);
    let f = FaceId(0);
    // Integral of sqrt(1 + x^2 + y^2) over the unit square by a fine midpoint rule.
    let n = 2000;
    let h = 1.0 / n as f64;
    let mut exact = 0.0;
    for i in 0..n {
        let x = (i as f64 + 0.5) * h;
        for j in 0..n {
            let y = (j as f64 + 0.5) * h;
            exact += (1.0 + x * x + y * y).sqrt();
        }
    }
    exact *= h * h;
    assert!(
        close(exact, 1.280_789_3, 1e-6),
        "reference integral {exact}"
    );
    assert!(close(bilinear_area_midpoint(p, 500), exact, 1e-6));
    let area = m.face_area(f);
    assert!(rel_err(area, exact) < 1e-3, "{area} vs {exact}");
    // The 2x2 Gauss rule is not exact for a twisted patch, and the vector area (half the
    // cross product of the diagonals, sqrt(6)/2) is a different, smaller quantity.
    assert!(area != exact);
    assert!(close(area, bilinear_area_gauss2(p), 1e-14));
    let va = m.face_vector_area(f);
    assert!(close(va.norm(), 6f64.sqrt() / 2.0, 1e-15));
    assert!(area > va.norm() + 0.05);
    assert!(close(m.total_area(), area, 0.0));
}

#[test]
fn random_bilinear_quads_match_midpoint_rule() {
    let mut rng = Rng::new(17);
    for _ in 0..20 {
        // A convex base quad, lifted by a random twist.
        // (Mild twists: the 2x2 Gauss rule the library documents is off by more than
        // 1e-3 for strong ones, e.g. 1.4e-3 at a twist of 0.32 on a 1.5-wide quad.)
        let twist = rng.range(-0.25, 0.25);
        let mut p = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(rng.range(0.8, 1.6), rng.range(-0.2, 0.2), 0.0),
            Point3::new(rng.range(0.8, 1.6), rng.range(0.8, 1.6), 0.0),
            Point3::new(rng.range(-0.2, 0.2), rng.range(0.8, 1.6), 0.0),
        ];
        p[0].z = twist;
        p[2].z = twist;
        p[1].z = -twist;
        p[3].z = -twist;
        let m = single_quad(p);
        let exact = bilinear_area_midpoint(p, 800);
        let area = m.face_area(FaceId(0));
        assert!(rel_err(area, exact) < 1e-3, "{p:?}: {area} vs {exact}");
        // It is the documented 2x2 Gauss rule on the bilinear patch.
        assert!(close(area, bilinear_area_gauss2(p), 1e-14), "{p:?}");
    }
}

#[test]
fn planar_quads_in_space_have_exact_area() {
    // Random convex planar quads, rotated into a tilted plane: the bilinear area equals
    // the vector area norm and the sum of the two triangles.
    let mut rng = Rng::new(23);
    for _ in 0..50 {
        let local = [
            Vector2::new(rng.range(-1.0, -0.3), rng.range(-1.0, -0.3)),
            Vector2::new(rng.range(0.3, 1.0), rng.range(-1.0, -0.3)),
            Vector2::new(rng.range(0.3, 1.0), rng.range(0.3, 1.0)),
            Vector2::new(rng.range(-1.0, -0.3), rng.range(0.3, 1.0)),
        ];
        let n = Vector3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 1.0).normalize();
        let a = n.cross(&Vector3::x()).normalize();
        let b = n.cross(&a);
        let o = Point3::new(
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
        );
        let p = local.map(|q| o + q.x * a + q.y * b);
        let shoelace: f64 = 0.5
            * (0..4)
                .map(|k| {
                    let (s, t) = (local[k], local[(k + 1) % 4]);
                    s.x * t.y - s.y * t.x
                })
                .sum::<f64>();
        let m = single_quad(p);
        let f = FaceId(0);
        assert!(
            close(m.face_area(f), shoelace.abs(), 1e-12),
            "{} vs {shoelace}",
            m.face_area(f)
        );
        assert!(close(m.face_vector_area(f).norm(), shoelace.abs(), 1e-12));
        // The normal is the plane normal (a x b = -n... orientation by the shoelace sign).
        let expected_normal = a.cross(&b) * shoelace.signum();
        assert!((m.face_normal(f) - expected_normal).norm() < 1e-12);
        let corners: f64 = corner_angle_sum(&m, f);
        assert!(close(corners, TAU, 1e-12));
    }
}

// ---------------------------------------------------------------------------------------
// Angles and normals
// ---------------------------------------------------------------------------------------

#[test]
fn triangle_angles_sum_to_pi() {
    let meshes = [
        mesh(&primitives::grid(5, 3, Cells::Triangles)),
        mesh(&primitives::icosphere(2)),
        mesh(&primitives::torus(9, 5, 2.0, 0.6, Cells::Triangles)),
    ];
    for m in &meshes {
        for f in m.faces() {
            assert_eq!(m.face_degree(f), 3);
            let s = corner_angle_sum(m, f);
            assert!(close(s, PI, 1e-12), "{f:?}: {s}");
            for h in m.face_halfedges(f) {
                let a = m.corner_angle(h);
                assert!(a > 0.0 && a < PI);
            }
        }
    }
}

#[test]
fn planar_quad_angles_sum_to_two_pi() {
    let meshes = [
        mesh(&primitives::grid(5, 3, Cells::Quads)),
        mesh(&primitives::torus(9, 5, 2.0, 0.6, Cells::Quads)),
    ];
    for m in &meshes {
        for f in m.faces() {
            let s = corner_angle_sum(m, f);
            assert!(close(s, TAU, 1e-12), "{f:?}: {s}");
        }
    }
    // Grid quads have four right angles; grid triangles (diagonal (0,0)-(1,1) of a
    // square cell) have angles pi/2, pi/4, pi/4.
    let m = mesh(&primitives::grid(4, 4, Cells::Quads));
    for h in m.halfedges().filter(|&h| m.face(h).is_some()) {
        assert!(close(m.corner_angle(h), FRAC_PI_2, 1e-14));
    }
    let m = mesh(&primitives::grid(4, 4, Cells::Triangles));
    for f in m.faces() {
        let mut a: Vec<f64> = m.face_halfedges(f).map(|h| m.corner_angle(h)).collect();
        a.sort_by(f64::total_cmp);
        assert!(close(a[0], PI / 4.0, 1e-14) && close(a[1], PI / 4.0, 1e-14));
        assert!(close(a[2], FRAC_PI_2, 1e-14));
    }
}

#[test]
fn planar_grid_vertex_angle_sums() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let m = mesh(&primitives::grid(6, 5, cells));
        for v in m.vertices() {
            let p = m.position(v);
            let on_x = p.x == 0.0 || p.x == 1.0;
            let on_y = p.y == 0.0 || p.y == 1.0;
            let expected = match (on_x, on_y) {
                (false, false) => TAU,
                (true, true) => FRAC_PI_2,
                _ => PI,
            };
            let s = vertex_angle_sum(&m, v);
            assert!(close(s, expected, 1e-12), "{cells:?} {p:?}: {s}");
            assert_eq!(m.is_boundary_vertex(v), on_x || on_y);
        }
    }
}

#[test]
fn discrete_gauss_bonnet() {
    // Sum of angle defects over a closed mesh is 2 pi chi.
    let cases = [
        (mesh(&primitives::icosphere(3)), 2.0),
        (
            mesh(&primitives::torus(12, 7, 2.0, 0.6, Cells::Triangles)),
            0.0,
        ),
        (mesh(&primitives::torus(12, 7, 2.0, 0.6, Cells::Quads)), 0.0),
    ];
    for (m, chi) in &cases {
        let total: f64 = m.vertices().map(|v| TAU - vertex_angle_sum(m, v)).sum();
        assert!(close(total, TAU * chi, 1e-9), "{total} vs {}", TAU * chi);
    }
}

#[test]
fn icosphere_vertex_normals_are_radial() {
    for s in [1, 2, 3] {
        let m = mesh(&primitives::icosphere(s));
        let all = m.vertex_normals();
        assert_eq!(all.len(), m.vertex_count());
        let mut worst: f64 = 1.0;
        for v in m.vertices() {
            let n = m.vertex_normal(v);
            assert!(close(n.norm(), 1.0, 1e-12));
            assert!((n - all[v.idx()]).norm() < 1e-12, "{v:?}");
            let radial = m.position(v).coords.normalize();
            worst = worst.min(n.dot(&radial));
            if v.idx() < 12 {
                // The icosahedron's vertices are symmetric: exactly radial.
                assert!((n - radial).norm() < 1e-12, "{v:?}");
            }
        }
        // Deviation shrinks with refinement.
        let bound = [0.0, 0.999, 0.9997, 0.99993][s];
        assert!(worst > bound, "s = {s}: worst cosine {worst}");
    }
}

#[test]
fn planar_vertex_normals_are_up() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let m = mesh(&primitives::grid(4, 3, cells));
        for n in m.vertex_normals() {
            assert!((n - Vector3::z()).norm() < 1e-14);
        }
        for f in m.faces() {
            assert!((m.face_normal(f) - Vector3::z()).norm() < 1e-14);
        }
    }
}

// ---------------------------------------------------------------------------------------
// Lengths, boxes, centroids
// ---------------------------------------------------------------------------------------

#[test]
fn grid_edge_lengths() {
    let (nx, ny) = (4usize, 5usize);
    let (hx, hy) = (1.0 / nx as f64, 1.0 / ny as f64);
    let diag = (hx * hx + hy * hy).sqrt();
    for cells in [Cells::Triangles, Cells::Quads] {
        let m = mesh(&primitives::grid(nx, ny, cells));
        let lengths = m.edge_lengths();
        assert_eq!(lengths.len(), m.edge_count());
        let (mut horizontal, mut vertical, mut diagonal) = (0, 0, 0);
        for e in m.edges() {
            let l = lengths[e.idx()];
            assert_eq!(l, m.edge_length(e));
            let [a, b] = m.edge_vertices(e);
            assert!(close(l, (m.position(a) - m.position(b)).norm(), 0.0));
            if close(l, hx, 1e-15) {
                horizontal += 1;
            } else if close(l, hy, 1e-15) {
                vertical += 1;
            } else if close(l, diag, 1e-15) {
                diagonal += 1;
            } else {
                panic!("unexpected edge length {l}");
            }
        }
        assert_eq!(horizontal, nx * (ny + 1));
        assert_eq!(vertical, ny * (nx + 1));
        assert_eq!(
            diagonal,
            if cells == Cells::Triangles {
                nx * ny
            } else {
                0
            }
        );
        // Boundary loop length is the perimeter.
        let loops = m.boundary_loop_list();
        assert!(close(loops[0].length, 4.0, 1e-12));
    }
}

#[test]
fn bounding_boxes() {
    let m = mesh(&primitives::grid(3, 7, Cells::Quads));
    let b = m.bounding_box();
    assert_eq!(b.min, Point3::new(0.0, 0.0, 0.0));
    assert_eq!(b.max, Point3::new(1.0, 1.0, 0.0));
    assert!(close(b.diagonal(), 2f64.sqrt(), 1e-15));

    // Torus with n_major and n_minor divisible by 4 attains its extremes.
    let (big, small) = (2.0, 0.5);
    let m = mesh(&primitives::torus(16, 8, big, small, Cells::Quads));
    let b = m.bounding_box();
    let r = big + small;
    assert!(
        (b.min - Point3::new(-r, -r, -small)).norm() < 1e-12,
        "{b:?}"
    );
    assert!((b.max - Point3::new(r, r, small)).norm() < 1e-12, "{b:?}");

    // The icosahedron: coordinates of (0, +-1, +-t) normalized, t the golden ratio.
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let c = t / (1.0 + t * t).sqrt();
    let b = mesh(&primitives::icosphere(0)).bounding_box();
    assert!((b.max - Point3::new(c, c, c)).norm() < 1e-12, "{b:?}");
    assert!(
        (b.min + Point3::new(c, c, c).coords).coords.norm() < 1e-12,
        "{b:?}"
    );

    // Every vertex lies inside; unreferenced vertices are not in the mesh, so not in the
    // box.
    let mut soup = primitives::grid(2, 2, Cells::Triangles);
    soup.positions.push(Point3::new(5.0, -5.0, 3.0));
    let m = mesh(&soup);
    let b = m.bounding_box();
    assert_eq!(b.max, Point3::new(1.0, 1.0, 0.0));
    assert_eq!(b.min, Point3::new(0.0, 0.0, 0.0));

    assert_eq!(BoundingBox::around(std::iter::empty()), None);
    let pts = [Point3::new(1.0, -2.0, 3.0), Point3::new(-1.0, 4.0, 0.5)];
    let b = BoundingBox::around(&pts).unwrap();
    assert_eq!(b.min, Point3::new(-1.0, -2.0, 0.5));
    assert_eq!(b.max, Point3::new(1.0, 4.0, 3.0));
    assert!(close(b.diagonal(), (4.0f64 + 36.0 + 6.25).sqrt(), 1e-15));
    // Inside, on a face, beside a face, beyond an edge and beyond a corner.
    assert_eq!(b.distance_squared(&Point3::new(0.0, 1.0, 2.0)), 0.0);
    assert_eq!(b.distance_squared(&Point3::new(1.0, 1.0, 2.0)), 0.0);
    assert_eq!(b.distance_squared(&Point3::new(3.0, 1.0, 2.0)), 4.0);
    assert_eq!(b.distance_squared(&Point3::new(0.0, -5.0, 0.0)), 9.0 + 0.25);
    assert_eq!(
        b.distance_squared(&Point3::new(-2.0, 5.0, 4.0)),
        1.0 + 1.0 + 1.0
    );
}

#[test]
fn face_centroids() {
    let (nx, ny) = (4usize, 3usize);
    let m = mesh(&primitives::grid(nx, ny, Cells::Quads));
    for f in m.faces() {
        let (i, j) = (f.idx() % nx, f.idx() / nx);
        let expected = Point3::new(
            (i as f64 + 0.5) / nx as f64,
            (j as f64 + 0.5) / ny as f64,
            0.0,
        );
        assert!((m.face_centroid(f) - expected).norm() < 1e-15, "{f:?}");
    }
    let m = mesh(&primitives::icosphere(1));
    for f in m.faces() {
        let (v, n) = m.face_vertex_array(f);
        assert_eq!(n, 3);
        let expected =
            (m.position(v[0]).coords + m.position(v[1]).coords + m.position(v[2]).coords) / 3.0;
        assert!((m.face_centroid(f).coords - expected).norm() < 1e-15);
        // Inside the sphere, along the outward normal.
        let c = m.face_centroid(f).coords;
        assert!(c.norm() < 1.0);
        assert!(c.normalize().dot(&m.face_normal(f)) > 0.99);
    }
}

// ---------------------------------------------------------------------------------------
// Face frames
// ---------------------------------------------------------------------------------------

fn check_frame_basics(m: &Mesh, f: FaceId) {
    let fr = m.face_frame(f);
    let h = m.face_halfedge(f);
    let (v, n) = m.face_vertex_array(f);
    assert_eq!(fr.origin, m.position(v[0]), "{f:?}");
    assert_eq!(m.origin(h), v[0]);
    let first = (m.position(v[1]) - m.position(v[0])).normalize();
    assert!((fr.e1 - first).norm() < 1e-14, "{f:?}");
    for (a, b, expected) in [
        (fr.e1, fr.e1, 1.0),
        (fr.e2, fr.e2, 1.0),
        (fr.normal, fr.normal, 1.0),
        (fr.e1, fr.e2, 0.0),
        (fr.e1, fr.normal, 0.0),
        (fr.e2, fr.normal, 0.0),
    ] {
        assert!(close(a.dot(&b), expected, 1e-14), "{f:?}");
    }
    assert!((fr.e2 - fr.normal.cross(&fr.e1)).norm() < 1e-14);
    // Right-handed and aligned with the face normal.
    assert!(fr.normal.dot(&m.face_normal(f)) > 0.0);
    let (local, k) = m.face_local_coordinates(f);
    assert_eq!(k, n);
    assert_eq!(local[0], Vector2::zeros());
    let l = (m.position(v[1]) - m.position(v[0])).norm();
    assert!(
        close(local[1].x, l, 1e-14) && close(local[1].y, 0.0, 1e-14),
        "{f:?}"
    );
    for i in 0..n {
        assert!((local[i] - fr.to_local(&m.position(v[i]))).norm() < 1e-15);
    }
    // vector_to_local of an edge is the difference of the local coordinates.
    for i in 0..n {
        let j = (i + 1) % n;
        let d = fr.vector_to_local(&(m.position(v[j]) - m.position(v[i])));
        assert!((d - (local[j] - local[i])).norm() < 1e-13);
    }
    // Counter-clockwise in the local plane: positive signed area.
    let signed: f64 = 0.5
        * (0..n)
            .map(|i| {
                let (a, b) = (local[i], local[(i + 1) % n]);
                a.x * b.y - a.y * b.x
            })
            .sum::<f64>();
    assert!(signed > 0.0, "{f:?}");
}

#[test]
fn triangle_frames_are_isometries() {
    let mut rng = Rng::new(31);
    // Triangles from several meshes, plus random triangles in space.
    let mut soups = vec![
        primitives::icosphere(2),
        primitives::torus(7, 5, 2.0, 0.6, Cells::Triangles),
        primitives::grid(3, 3, Cells::Triangles),
    ];
    let mut positions = Vec::new();
    let mut tris = Vec::new();
    for k in 0..40u32 {
        for _ in 0..3 {
            positions.push(Point3::new(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
            ));
        }
        tris.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    soups.push(PolygonSoup::from_triangles(positions, &tris));
    for soup in &soups {
        let m = mesh(soup);
        for f in m.faces() {
            check_frame_basics(&m, f);
            let (v, _) = m.face_vertex_array(f);
            let (q, _) = m.face_local_coordinates(f);
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                let world = (m.position(v[j]) - m.position(v[i])).norm();
                let local = (q[j] - q[i]).norm();
                assert!(
                    close(world, local, 1e-12 * world.max(1.0)),
                    "{f:?}: {world} vs {local}"
                );
            }
            assert!(q[2].y > 0.0, "{f:?}: third vertex below the x axis");
            // Area is preserved as well.
            let local_area = 0.5 * (q[1].x * q[2].y - q[1].y * q[2].x);
            assert!(close(
                local_area,
                m.face_area(f),
                1e-12 * m.face_area(f).max(1.0)
            ));
            // Round trip of in-plane points (random barycentric combinations).
            let fr = m.face_frame(f);
            for _ in 0..5 {
                let (a, b) = (rng.unit(), rng.unit());
                let c = 1.0 - a - b;
                let p = Point3::from(
                    a * m.position(v[0]).coords
                        + b * m.position(v[1]).coords
                        + c * m.position(v[2]).coords,
                );
                let back = fr.to_world(&fr.to_local(&p));
                assert!((back - p).norm() < 1e-12, "{f:?}: {p:?} -> {back:?}");
                // And the other way around.
                let q0 = Vector2::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
                assert!((fr.to_local(&fr.to_world(&q0)) - q0).norm() < 1e-12);
            }
        }
    }
}

#[test]
fn grid_frames_are_axis_aligned() {
    // For a grid quad (p0 at the lower left, first edge along +x) the frame is the
    // standard basis translated to p0.
    let m = mesh(&primitives::grid(3, 2, Cells::Quads));
    for f in m.faces() {
        check_frame_basics(&m, f);
        let fr = m.face_frame(f);
        assert!((fr.e1 - Vector3::x()).norm() < 1e-15);
        assert!((fr.e2 - Vector3::y()).norm() < 1e-15);
        assert!((fr.normal - Vector3::z()).norm() < 1e-15);
        let (q, n) = m.face_local_coordinates(f);
        assert_eq!(n, 4);
        assert!((q[2] - Vector2::new(1.0 / 3.0, 0.5)).norm() < 1e-15);
        assert!((q[3] - Vector2::new(0.0, 0.5)).norm() < 1e-15);
    }
}

#[test]
fn nonplanar_quad_frame_projects() {
    let p = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 1.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let m = single_quad(p);
    let f = FaceId(0);
    check_frame_basics(&m, f);
    let fr = m.face_frame(f);
    // The normal is the vector area's direction made orthogonal to e1 = x:
    // (-1, -1, 2) -> (0, -1, 2) / sqrt 5.
    let n = Vector3::new(0.0, -1.0, 2.0) / 5f64.sqrt();
    assert!((fr.normal - n).norm() < 1e-14, "{:?}", fr.normal);
    // Local coordinates are the orthogonal projection.
    let (q, _) = m.face_local_coordinates(f);
    for k in 0..4 {
        let d = p[k] - p[0];
        let expected = Vector2::new(d.dot(&fr.e1), d.dot(&fr.e2));
        assert!((q[k] - expected).norm() < 1e-15);
        let back = fr.to_world(&q[k]);
        // Going back lands on the plane; the offset is along the normal.
        let off = p[k] - back;
        assert!((off - off.dot(&fr.normal) * fr.normal).norm() < 1e-14);
    }
}

/// A simple (non-self-intersecting) planar quad with a reflex corner at p2, area 1.2.
/// The builder accepts it.
/// A concave quad: the builder refuses one (`MeshError::FoldedQuad`), but a map's image
/// of a convex one may be one, and is measured by the same functions.
fn dart() -> Mesh {
    let square = single_quad([
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(2.0, 0.0, 0.0),
        Point3::new(2.0, 2.0, 0.0),
        Point3::new(0.0, 2.0, 0.0),
    ]);
    let mut positions = square.positions().to_vec();
    positions[2] = Point3::new(0.6, 0.6, 0.0);
    square.with_positions(positions).expect("finite positions")
}

#[test]
fn nonconvex_planar_quad_area() {
    // The 2x2 Gauss rule is exact only for convex planar quads: here the bilinear Jacobian
    // changes sign inside the square and the rule would give 1.40829..., not the
    // polygon's area 1.2 (the norm of the vector area).
    let m = dart();
    let f = FaceId(0);
    assert!(close(m.face_vector_area(f).norm(), 1.2, 1e-14));
    assert!(
        close(m.face_area(f), 1.2, 1e-12),
        "face_area = {}",
        m.face_area(f)
    );
    assert!(close(m.total_area(), 1.2, 1e-12));
}

#[test]
fn nonconvex_planar_quad_corner_angles() {
    // At the reflex corner p2 the interior angle is 2 pi - 2.3806 = 3.9026 > pi (an
    // unsigned atan2 would give 2.3806 and a sum of 4.7612).
    let m = dart();
    let f = FaceId(0);
    let angles: Vec<f64> = m.face_halfedges(f).map(|h| m.corner_angle(h)).collect();
    let sum: f64 = angles.iter().sum();
    assert!(
        close(sum, TAU, 1e-12),
        "corner angles {angles:?} sum to {sum}"
    );
    assert!(close(angles[0], FRAC_PI_2, 1e-14), "{angles:?}");
    assert!(angles[2] > PI, "{angles:?}");
    // The sides at p2 are (1.4, -0.6) and (-0.6, 1.4): they meet at acos(-1.68 / 2.32).
    let unsigned = (-1.68f64 / 2.32).acos();
    assert!(close(angles[2], TAU - unsigned, 1e-12), "{angles:?}");
    assert!(close(angles[1], angles[3], 1e-14), "{angles:?}");
}

#[test]
fn subdivision_keeps_topology_and_area_and_quarters_faces() {
    use beltrami_mesh::subdivision::subdivide;
    for soup in [
        primitives::icosphere(1),
        primitives::grid(3, 2, Cells::Quads),
        primitives::torus(6, 5, 2.0, 0.5, Cells::Triangles),
    ] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let fine = Mesh::from_soup(&subdivide(&mesh)).unwrap();
        assert_eq!(fine.face_count(), 4 * mesh.face_count());
        assert_eq!(fine.euler_characteristic(), mesh.euler_characteristic());
        assert_eq!(fine.boundary_loop_count(), mesh.boundary_loop_count());
        assert!((fine.total_area() - mesh.total_area()).abs() < 1e-12 * mesh.total_area());
        for f in mesh.faces() {
            for k in 0..4 {
                let child = beltrami_mesh::FaceId((4 * f.idx() + k) as u32);
                assert!(fine.face_normal(child).dot(&mesh.face_normal(f)) > 0.999);
            }
        }
    }
}

#[test]
fn nearest_vertex_is_the_closest_one() {
    let mesh = Mesh::from_soup(&beltrami_mesh::primitives::grid(4, 4, Cells::Triangles)).unwrap();
    for v in mesh.vertices() {
        let p = mesh.position(v) + beltrami_mesh::Vector3::new(1e-3, -1e-3, 0.5);
        assert_eq!(mesh.nearest_vertex(&p), Some(v));
    }
    let far = Point3::new(1e6, -1e6, 0.0);
    let expected = mesh
        .vertices()
        .min_by(|&a, &b| {
            (mesh.position(a) - far)
                .norm()
                .total_cmp(&(mesh.position(b) - far).norm())
        })
        .unwrap();
    assert_eq!(mesh.nearest_vertex(&far), Some(expected));
}

#[test]
fn with_positions_keeps_the_connectivity_and_checks_the_count() {
    let mesh = Mesh::from_soup(&beltrami_mesh::primitives::grid(
        3,
        2,
        beltrami_mesh::primitives::Cells::Triangles,
    ))
    .unwrap();
    let lifted: Vec<_> = mesh
        .positions()
        .iter()
        .map(|p| beltrami_mesh::Point3::new(p.x, p.y, p.x * p.y))
        .collect();
    let moved = mesh.with_positions(lifted.clone()).unwrap();
    assert_eq!(moved.positions(), &lifted[..]);
    for f in mesh.faces() {
        assert!(mesh.face_vertices(f).eq(moved.face_vertices(f)));
    }
    assert_eq!(moved.boundary_loop_list().len(), 1);
    let short = lifted[..3].to_vec();
    assert!(matches!(
        mesh.with_positions(short),
        Err(beltrami_mesh::MeshError::PositionCount {
            expected: 12,
            got: 3
        })
    ));
    let mut bad = lifted;
    bad[5].z = f64::NAN;
    assert!(matches!(
        mesh.with_positions(bad),
        Err(beltrami_mesh::MeshError::NonFiniteCoordinate { vertex: 5, .. })
    ));
}

/// Gauss-Bonnet: the angle defects of all vertices sum to `2 pi chi` (sphere 4 pi, disk
/// 2 pi, torus 0), and a flat grid has no defect inside and `pi / 2` at its corners.
#[test]
fn angle_defects_sum_to_two_pi_chi() {
    let total = |m: &Mesh| m.vertices().map(|v| m.angle_defect(v)).sum::<f64>();
    let sphere = mesh(&primitives::icosphere(3));
    assert!(close(total(&sphere), 2.0 * TAU, 1e-9));
    let disk = mesh(&primitives::disk(3));
    assert!(close(total(&disk), TAU, 1e-9));
    let torus = mesh(&primitives::torus(24, 12, 1.0, 0.3, Cells::Triangles));
    assert!(close(total(&torus), 0.0, 1e-9));
    let grid = mesh(&primitives::grid(4, 4, Cells::Triangles));
    for v in grid.vertices() {
        let p = grid.position(v);
        let corner = (p.x == 0.0 || p.x == 1.0) && (p.y == 0.0 || p.y == 1.0);
        let expected = if corner { FRAC_PI_2 } else { 0.0 };
        assert!(
            close(grid.angle_defect(v), expected, 1e-12),
            "{v:?} at {p:?}"
        );
    }
}
