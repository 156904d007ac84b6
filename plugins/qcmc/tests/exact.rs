//! qcmc against exact answers: circle domains come back as themselves up to the disk
//! automorphism of the normalization, the affine image of a circle domain with the mu of
//! the inverse affine map comes back onto it, the eccentric annulus has the modulus of
//! the closed form, and the circles converge under refinement.

mod common;

use beltrami_core::{Goal, Stop};
use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::{Mesh, Point3, PolygonSoup};
use beltrami_qcmc::moebius::{PlaneCircle, concentric_radius};
use common::*;
use num_complex::Complex64;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// Two holes of different sizes, off the axes.
fn two_holes() -> Vec<PlaneCircle> {
    vec![
        PlaneCircle {
            center: c(-0.4, 0.1),
            radius: 0.22,
        },
        PlaneCircle {
            center: c(0.35, -0.25),
            radius: 0.15,
        },
    ]
}

/// What a map onto a circle domain is compared with: the exact map `exact` (per
/// vertex) and circles (per hole).
struct Errors {
    /// Largest vertex error.
    map: f64,
    /// Largest error of an inner circle's centre or radius.
    circles: f64,
}

/// Runs qcmc on `mesh` (whose vertices `domain` lie in the circle domain `holes`, or map
/// there) with `goal`, and compares with the normalized circle domain.
fn errors(mesh: &Mesh, holes: &[PlaneCircle], domain: &[Complex64], goal: Goal) -> Errors {
    let solution = run(mesh, goal, &[]);
    assert!(
        matches!(solution.metrics.stop, Some(Stop::Converged { .. })),
        "{:?}",
        solution.metrics.stop
    );
    assert_eq!(solution.metrics.flipped(), Some(0));
    let phi = normalization(mesh, holes, domain);
    let map = planar(&solution);
    let map_error = domain
        .iter()
        .zip(&map)
        .map(|(z, w)| (phi.apply(*z) - w).norm())
        .fold(0.0, f64::max);
    let loops = mesh.boundary_loop_list();
    let circles = solution.extras.circles.as_ref().unwrap();
    assert_eq!(circles.len(), holes.len() + 1);
    assert!(circles[0].center.norm() == 0.0 && circles[0].radius == 1.0);
    let mut circle_error: f64 = 0.0;
    for circle in &circles[1..] {
        let hole = hole_of(holes, domain[loops[circle.boundary_loop].vertices[0].idx()]);
        let exact = phi.circle(&holes[hole]).unwrap();
        circle_error = circle_error
            .max((exact.center - circle.center).norm())
            .max((exact.radius - circle.radius).abs());
    }
    Errors {
        map: map_error,
        circles: circle_error,
    }
}

#[test]
fn a_circle_domain_comes_back_as_itself_up_to_a_disk_automorphism() {
    let holes = two_holes();
    let mesh = circle_domain(&holes, 0.05);
    let domain = positions(&mesh);
    let e = errors(&mesh, &holes, &domain, Goal::Conformal { p: 2.0 });
    println!(
        "k = 3, h = 0.05, {} faces: map error {:.3e}, circle error {:.3e}",
        mesh.face_count(),
        e.map,
        e.circles
    );
    assert!(e.map < 1e-2 && e.circles < 2e-3, "{} {}", e.map, e.circles);
}

#[test]
fn the_affine_image_of_a_circle_domain_with_the_inverse_mu_comes_back() {
    // The source is A(D) for A(z) = z + k conj(z); the map A^-1 = (w - k conj w) / (1 -
    // |k|^2) back onto D has mu = -k: with that mu prescribed, qcmc must find D.
    let holes = two_holes();
    let disk = circle_domain(&holes, 0.05);
    let domain = positions(&disk);
    let k = c(0.3, 0.2);
    let image: Vec<Point3<f64>> = domain
        .iter()
        .map(|z| {
            let w = z + k * z.conj();
            Point3::new(w.re, w.im, 0.0)
        })
        .collect();
    let mut soup = PolygonSoup::new(image);
    for f in disk.faces() {
        let face: Vec<u32> = disk.face_vertices(f).map(|v| v.0).collect();
        soup.push_face(&face);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let field = BeltramiField::new(Frame::Global, vec![-k; mesh.face_count()]);
    let e = errors(&mesh, &holes, &domain, Goal::Prescribed(field));
    println!(
        "affine image, k = 0.3+0.2i: map error {:.3e}, circle error {:.3e}",
        e.map, e.circles
    );
    assert!(e.map < 1e-2 && e.circles < 2e-3, "{} {}", e.map, e.circles);
}

#[test]
fn the_eccentric_annulus_has_the_modulus_of_the_closed_form() {
    for (d, r) in [(0.3, 0.3), (0.5, 0.2)] {
        let holes = [PlaneCircle {
            center: c(d, 0.0),
            radius: r,
        }];
        let mesh = circle_domain(&holes, 0.04);
        let solution = run(&mesh, Goal::Conformal { p: 2.0 }, &[]);
        assert_eq!(solution.metrics.flipped(), Some(0));
        let circles = solution.extras.circles.unwrap();
        let exact = concentric_radius(d, r);
        println!(
            "d = {d}, r = {r}: radius {:.6} exact {exact:.6}, centre {:.2e}",
            circles[1].radius,
            circles[1].center.norm()
        );
        assert_eq!(circles[1].center, c(0.0, 0.0));
        assert!(
            (circles[1].radius - exact).abs() < 2e-3 * exact,
            "{} {exact}",
            circles[1].radius
        );
    }
}

#[test]
fn centres_and_radii_converge_under_refinement() {
    let holes = two_holes();
    let mut previous: Option<Errors> = None;
    for h in [0.1, 0.05, 0.025] {
        let mesh = circle_domain(&holes, h);
        let domain = positions(&mesh);
        let e = errors(&mesh, &holes, &domain, Goal::Conformal { p: 2.0 });
        println!(
            "h = {h}: {} faces, map error {:.3e}, circle error {:.3e}",
            mesh.face_count(),
            e.map,
            e.circles
        );
        if let Some(p) = previous {
            assert!(
                e.circles < 0.6 * p.circles,
                "{} after {}",
                e.circles,
                p.circles
            );
            assert!(e.map < 0.6 * p.map, "{} after {}", e.map, p.map);
        }
        previous = Some(e);
    }
}
