//! A curved disk: the extremal solver lays it out conformally (LSCM) and measures mu on
//! the surface. Exact answer: the inverse stereographic projection `s` is conformal, so
//! for the affine map `A(z) = z + a conj(z)` the map `A o s^-1` of the spherical cap
//! `s(D)` has `|mu| = |a|` everywhere and a quadratic differential (the pull-back of
//! `A`'s constant one): it is the Teichmueller map of its boundary values, with
//! `k = |a|`, and its vertex images are `A` of the planar points the cap was lifted
//! from.

mod common;

use beltrami_mesh::{Mesh, Point3, primitives};
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
