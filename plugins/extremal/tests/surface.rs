//! A curved disk: the extremal solver lays it out conformally (LSCM) and measures mu on
//! the surface. Exact answer: the inverse stereographic projection `s` is conformal, so
//! for the affine map `A(z) = z + a conj(z)` the map `A o s^-1` of the spherical cap
//! `s(D)` has `|mu| = |a|` everywhere and a quadratic differential (the pull-back of
//! `A`'s constant one): it is the Teichmueller map of its boundary values, with
//! `k = |a|`, and its vertex images are `A` of the planar points the cap was lifted
//! from.

mod common;

use beltrami_mesh::{Mesh, Point3, PolygonSoup, primitives};
use common::{max_distance, solve};
use num_complex::Complex64;

/// The unit disk of `level` lifted onto the lower unit hemisphere by the inverse
/// stereographic projection from the north pole, and the planar points.
fn cap(level: usize) -> (Mesh, Vec<Complex64>) {
    let mut soup = primitives::disk(level);
    // Off the symmetric grid, so that nothing is exact by symmetry.
    let mut u = common::noise(11);
    let spacing = 0.5f64.powi(level as i32);
    for p in &mut soup.positions {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        if r < 1.0 - 1e-9 {
            p.x += 0.15 * spacing * u();
            p.y += 0.15 * spacing * u();
        }
    }
    let planar: Vec<Complex64> = soup
        .positions
        .iter()
        .map(|p| Complex64::new(p.x, p.y))
        .collect();
    for p in &mut soup.positions {
        let r2 = p.x * p.x + p.y * p.y;
        *p = Point3::new(2.0 * p.x, 2.0 * p.y, r2 - 1.0) / (r2 + 1.0);
    }
    let mesh = Mesh::from_soup(&soup).expect("a valid cap");
    let planar = mesh
        .vertices()
        .map(|v| planar[mesh.vertex_map().to_input(v)])
        .collect();
    (mesh, planar)
}

#[test]
fn a_spherical_cap_gives_the_affine_map_through_its_conformal_layout() {
    let a = Complex64::new(0.25, 0.1);
    let affine = |z: Complex64| z + a * z.conj();
    let mut last: Option<(f64, f64)> = None;
    for level in [3, 4, 5] {
        let (mesh, planar) = cap(level);
        let exact: Vec<Complex64> = planar.iter().map(|&z| affine(z)).collect();
        let solution = solve(&mesh, exact.clone(), None, "harmonic");
        let k = solution.metrics.k.unwrap();
        let map = solution.planar().unwrap();
        let error = max_distance(map, &exact);
        let stats = solution.metrics.distortion.as_ref().unwrap();
        let k_error = (k - a.norm()).abs() / a.norm();
        println!(
            "level {level}: {} faces, k {k:.6} (exact {:.6}), |mu| mean {:.4} max {:.4}, vertex error {error:.3e}",
            mesh.face_count(),
            a.norm(),
            stats.mu_mean,
            stats.mu_max
        );
        assert_eq!(stats.flipped, 0);
        assert!(
            solution.report.notes.iter().any(|n| n.contains("LSCM")),
            "{:?}",
            solution.report.notes
        );
        if let Some((e, ke)) = last {
            assert!(error < 0.6 * e, "vertex error {error} after {e}");
            assert!(
                k_error < 0.6 * ke || k_error < 1e-3,
                "k error {k_error} after {ke}"
            );
        }
        last = Some((error, k_error));
    }
    let (_, k_error) = last.unwrap();
    assert!(k_error < 0.01, "k off by {k_error} of |a|");
}

/// `mesh` (planar) with its faces in counter-clockwise order, so that the face frames of
/// its lift agree with the plane's orientation.
fn counter_clockwise(mesh: &Mesh) -> Mesh {
    let mut soup = PolygonSoup::new(mesh.positions().to_vec());
    for f in mesh.faces() {
        let mut face: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        let p: Vec<Point3<f64>> = face.iter().map(|&v| mesh.positions()[v as usize]).collect();
        if (p[1] - p[0]).cross(&(p[2] - p[0])).z < 0.0 {
            face.reverse();
        }
        soup.push_face(&face);
    }
    Mesh::from_soup(&soup).unwrap()
}

/// A curved annulus: the irregular planar annulus lifted onto the unit sphere by the
/// inverse stereographic projection (conformal), with the boundary values of the ring
/// map of the planar points. The solver fills the inner loop, lays the surface out by
/// LSCM, removes the fill, and must find the ring map's `k` and vertex images (the ring
/// map composed with the projection is the Teichmueller map of those values).
#[test]
fn a_curved_annulus_gives_the_ring_map_through_its_filled_layout() {
    let ring = common::RingMap {
        r0: 0.4,
        r1: 1.0,
        s0: 0.25,
        s1: 1.2,
    };
    let mut last: Option<(f64, f64)> = None;
    for rings in [4, 8, 16] {
        let planar_mesh =
            counter_clockwise(&common::irregular_annulus(ring.r0, rings, 6 * rings, 5));
        let planar: Vec<Complex64> = planar_mesh
            .positions()
            .iter()
            .map(|p| Complex64::new(p.x, p.y))
            .collect();
        let lifted: Vec<Point3<f64>> = planar
            .iter()
            .map(|z| {
                let r2 = z.norm_sqr();
                Point3::new(2.0 * z.re, 2.0 * z.im, r2 - 1.0) / (r2 + 1.0)
            })
            .collect();
        let mesh = planar_mesh.with_positions(lifted).unwrap();
        let exact: Vec<Complex64> = planar.iter().map(|&z| ring.at(z)).collect();
        let solution = solve(&mesh, exact.clone(), None, "harmonic");
        let k = solution.metrics.k.unwrap();
        let error = max_distance(solution.planar().unwrap(), &exact);
        let stats = solution.metrics.distortion.as_ref().unwrap();
        let k_error = (k - ring.k()).abs() / ring.k();
        println!(
            "{rings} rings: {} faces, k {k:.6} (exact {:.6}), |mu| max {:.4}, vertex error {error:.3e}",
            mesh.face_count(),
            ring.k(),
            stats.mu_max
        );
        assert_eq!(stats.flipped, 0);
        assert!(solution.report.notes.iter().any(|n| n.contains("LSCM")));
        if let Some((e, ke)) = last {
            assert!(error < 0.6 * e, "vertex error {error} after {e}");
            assert!(
                k_error < 0.6 * ke || k_error < 2e-3,
                "k error {k_error} after {ke}"
            );
        }
        last = Some((error, k_error));
    }
    let (_, k_error) = last.unwrap();
    assert!(k_error < 0.01, "k off by {k_error} of the exact k");
}
