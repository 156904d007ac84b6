//! The four-point problem (paper section 5): the unit disk onto itself with the
//! boundary sliding on the circle and four boundary points moved from
//! `e^{i(pi/4 + j pi/2)}` to `e^{i phi}, e^{i(pi - phi)}, e^{i(pi + phi)}, e^{-i phi}`.
//!
//! The exact answer, derived here independently of the paper's (garbled) formula: a
//! disk with four marked boundary points is a quadrilateral; a Moebius map takes it to
//! the upper half-plane with the points at `-1/kappa, -1, 1, 1/kappa` (kappa from the
//! cross-ratio), where `sn^{-1}(., kappa)` maps it onto the rectangle with corners
//! `+-K, +-K + i K'`, so the side from the second point to the third has length
//! `2 K(kappa)` and the next `K'(kappa) = K(sqrt(1 - kappa^2))`: the modulus is
//! `M = 2 K / K'`. The extremal map between two quadrilaterals stretches one rectangle
//! onto the other: `K_dil = M_2 / M_1` (or its inverse) and `k = |M_2 - M_1| / (M_2 + M_1)`.

use beltrami_core::{Constraint, Context, Goal, Landmark, Position, Problem, Solver, Target};
use beltrami_extremal::Extremal;
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::{Elements, Frame};
use beltrami_mesh::{Mesh, VertexId, primitives};
use num_complex::Complex64;
use std::f64::consts::PI;

/// `K(kappa)`, the complete elliptic integral of the first kind of modulus `kappa`, by
/// the arithmetic-geometric mean: `K = pi / (2 agm(1, sqrt(1 - kappa^2)))`.
fn complete_k(kappa: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - kappa * kappa).sqrt());
    // The mean converges quadratically: 40 steps are far more than double precision
    // needs, and a fixed count cannot cycle on the last bit.
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

/// The cross-ratio `(z3 - z1)(z4 - z2) / ((z3 - z2)(z4 - z1))` (real for concyclic points).
fn cross_ratio(z: [Complex64; 4]) -> f64 {
    ((z[2] - z[0]) * (z[3] - z[1]) / ((z[2] - z[1]) * (z[3] - z[0]))).re
}

/// The modulus `2 K / K'` of the disk with the boundary points `z` (counter-clockwise).
fn modulus(z: [Complex64; 4]) -> f64 {
    let kappa = kappa_of(z);
    2.0 * complete_k(kappa) / complete_k((1.0 - kappa * kappa).sqrt())
}

/// The `kappa` of the half-plane points `-1/kappa, -1, 1, 1/kappa` with the cross-ratio
/// of `z`.
fn kappa_of(z: [Complex64; 4]) -> f64 {
    let target = cross_ratio(z);
    let real = |kappa: f64| {
        let x = [-1.0 / kappa, -1.0, 1.0, 1.0 / kappa].map(|x| Complex64::new(x, 0.0));
        cross_ratio(x)
    };
    // The half-plane's cross-ratio falls from +inf to 1 as kappa goes from 0 to 1.
    let (mut lo, mut hi) = (1e-12, 1.0 - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if real(mid) > target {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// Carlson's symmetric integral `R_F(x, y, z)` for complex arguments off the cut
/// `(-inf, 0]`, by duplication (B. C. Carlson, "Numerical computation of real or
/// complex elliptic integrals", Numer. Algorithms 10, 1995).
fn carlson_rf(mut x: Complex64, mut y: Complex64, mut z: Complex64) -> Complex64 {
    for _ in 0..200 {
        let mu = (x + y + z) / 3.0;
        let spread = [x, y, z]
            .iter()
            .map(|w| (1.0 - w / mu).norm())
            .fold(0.0, f64::max);
        if spread < 1e-4 {
            let (dx, dy) = (1.0 - x / mu, 1.0 - y / mu);
            let dz = -(dx + dy);
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / mu.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        (x, y, z) = ((x + lambda) / 4.0, (y + lambda) / 4.0, (z + lambda) / 4.0);
    }
    panic!("R_F did not converge")
}

/// The Moebius map taking `a, b, c` to `p, q, r`, as a function.
fn moebius(from: [Complex64; 3], to: [Complex64; 3]) -> impl Fn(Complex64) -> Complex64 {
    // M(z) = (z - a)(b - c) / ((z - c)(b - a)) takes a, b, c to 0, 1, infinity.
    let standard =
        |[a, b, c]: [Complex64; 3]| move |z: Complex64| (z - a) * (b - c) / ((z - c) * (b - a));
    let forward = standard(from);
    let [p, q, r] = to;
    move |z| {
        // Invert the standard map of p, q, r: w with (w - p)(q - r) / ((w - r)(q - p)) = m.
        let m = forward(z);
        let t = m * (q - p) / (q - r);
        (p - t * r) / (1.0 - t)
    }
}

/// The conformal map of the disk with the boundary points `z` (counter-clockwise) onto
/// the rectangle with corners `-K, K, K + i K', -K + i K'`: a Moebius map onto the upper
/// half-plane with the points at `-1/kappa, -1, 1, 1/kappa`, then
/// `sn^{-1}(x) = x R_F(1 - x^2, 1 - kappa^2 x^2, 1)`. Returns the map and `(K, K')`.
fn rectangle_map(z: [Complex64; 4]) -> (impl Fn(Complex64) -> Complex64, f64, f64) {
    let kappa = kappa_of(z);
    let real = |x: f64| Complex64::new(x, 0.0);
    let to_half_plane = moebius(
        [z[1], z[2], z[3]],
        [real(-1.0), real(1.0), real(1.0 / kappa)],
    );
    let map = move |w: Complex64| {
        let x = to_half_plane(w);
        let one = Complex64::new(1.0, 0.0);
        x * carlson_rf(one - x * x, one - kappa * kappa * x * x, one)
    };
    (
        map,
        complete_k(kappa),
        complete_k((1.0 - kappa * kappa).sqrt()),
    )
}

fn exact_k(from: [Complex64; 4], to: [Complex64; 4]) -> f64 {
    let (a, b) = (modulus(from), modulus(to));
    (a - b).abs() / (a + b)
}

fn destinations(phi: f64) -> [Complex64; 4] {
    [phi, PI - phi, PI + phi, 2.0 * PI - phi].map(|t| Complex64::from_polar(1.0, t))
}

/// The boundary vertex nearest to each of the angles `pi/4 + j pi/2`.
fn corners(mesh: &Mesh) -> [VertexId; 4] {
    let boundary = &mesh.boundary_loop_list()[0].vertices;
    std::array::from_fn(|j| {
        let w = Complex64::from_polar(1.0, PI / 4.0 + j as f64 * PI / 2.0);
        *boundary
            .iter()
            .min_by(|&&a, &&b| {
                let d = |v: VertexId| {
                    let p = mesh.position(v);
                    (Complex64::new(p.x, p.y) - w).norm()
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    })
}

fn at(mesh: &Mesh, v: VertexId) -> Complex64 {
    let p = mesh.position(v);
    Complex64::new(p.x, p.y)
}

struct Result4 {
    k: f64,
    exact: f64,
    map: Vec<Complex64>,
    l2: f64,
    flipped: usize,
    /// The largest distance, over the interior vertices, between `g_b(f(z))` and the
    /// exact `A(g_a(z))` in the target's rectangle (relative to its width `2 K_b`):
    /// `f = g_b^{-1} o A o g_a` with `A` the affine map between the rectangles.
    map_error: f64,
}

fn four_point(level: usize, phi: f64, init: &str) -> Result4 {
    let mesh = Mesh::from_soup(&primitives::disk(level)).unwrap();
    let c = corners(&mesh);
    let to = destinations(phi);
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.goal = Goal::Extremal;
    for (&v, &w) in c.iter().zip(&to) {
        problem.constraints.push(Constraint::Landmark(Landmark {
            vertex: v,
            position: Position::Planar(w),
        }));
    }
    problem.options.set_text("init", init);
    problem.options.set_text("tolerance", "1e-10");
    problem.options.set_text("max-iters", "400");
    let solution = match Extremal.solve(&problem, &mut Context::new()) {
        Ok(s) => s,
        Err(e) => panic!("level {level}: {e}"),
    };
    let map = solution.planar().unwrap().to_vec();
    for (&v, &w) in c.iter().zip(&to) {
        assert!(
            (map[v.idx()] - w).norm() < 1e-12,
            "landmark {v} is not at {w}"
        );
    }
    for v in &mesh.boundary_loop_list()[0].vertices {
        assert!(
            (map[v.idx()].norm() - 1.0).abs() < 1e-12,
            "{v} left the circle"
        );
    }
    let k = solution.metrics.k.unwrap();
    // The source is the inscribed polygon; its points are the corner vertices.
    let from = c.map(|v| at(&mesh, v) / at(&mesh, v).norm());
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let d = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
    let (mut sum, mut area) = (0.0, 0.0);
    for (q, d) in elements.points().iter().zip(&d) {
        sum += q.weight * (d.mu().norm() - k).powi(2);
        area += q.weight;
    }
    let (g_a, ka, ka_prime) = rectangle_map(from);
    let (g_b, kb, kb_prime) = rectangle_map(to);
    let on_boundary: Vec<bool> = {
        let mut b = vec![false; mesh.vertex_count()];
        for v in &mesh.boundary_loop_list()[0].vertices {
            b[v.idx()] = true;
        }
        b
    };
    let map_error = mesh
        .vertices()
        .filter(|v| !on_boundary[v.idx()])
        .map(|v| {
            let r = g_a(at(&mesh, v));
            let stretched = Complex64::new(r.re * kb / ka, r.im * kb_prime / ka_prime);
            (g_b(map[v.idx()]) - stretched).norm() / (2.0 * kb)
        })
        .fold(0.0, f64::max);
    Result4 {
        k,
        exact: exact_k(from, to),
        map,
        l2: (sum / area).sqrt(),
        flipped: solution.metrics.distortion.unwrap().flipped,
        map_error,
    }
}

#[test]
fn the_rectangle_map_sends_the_points_to_the_corners() {
    for z in [
        destinations(PI / 4.0),
        destinations(PI / 6.0),
        destinations(0.4),
    ] {
        let (g, k, k_prime) = rectangle_map(z);
        // Approach each corner from inside the disk (the points are on the cut's edge).
        let got = z.map(|w| g(w * (1.0 - 1e-12)));
        let corners = [
            Complex64::new(-k, k_prime),
            Complex64::new(-k, 0.0),
            Complex64::new(k, 0.0),
            Complex64::new(k, k_prime),
        ];
        for (g, c) in got.iter().zip(&corners) {
            assert!((g - c).norm() < 1e-5, "{g} != {c}");
        }
        // A point between the middle two corners goes onto the bottom side.
        let mid = Complex64::from_polar(1.0 - 1e-12, (z[1] / z[2]).arg() / 2.0 + z[2].arg());
        assert!(g(mid).im.abs() < 1e-5, "{}", g(mid));
    }
}

#[test]
fn the_modulus_of_the_symmetric_quadrilateral_is_one() {
    let square = destinations(PI / 4.0);
    assert!((modulus(square) - 1.0).abs() < 1e-12, "{}", modulus(square));
    // Moving the points closer in pairs lengthens one pair of sides.
    assert!(modulus(destinations(PI / 6.0)) < 1.0);
    assert!(modulus(destinations(PI / 3.0)) > 1.0);
}

#[test]
fn k_converges_to_the_exact_dilatation() {
    let phi = PI / 6.0;
    let mut errors = Vec::new();
    for level in [4, 5, 6] {
        let r = four_point(level, phi, "harmonic");
        let relative = (r.k - r.exact).abs() / r.exact;
        println!(
            "level {level}: k {:.6}, exact {:.6}, relative error {relative:.2e}, L2(|mu| - k) {:.3e}, map error {:.2e}, flipped {}",
            r.k, r.exact, r.l2, r.map_error, r.flipped
        );
        assert_eq!(r.flipped, 0);
        errors.push((relative, r.l2, r.map_error));
    }
    assert!(errors[2].0 < 0.01, "k within 1% at level 6: {errors:?}");
    // First order in the mesh size: each level (h halved) at least 1.5 times closer.
    for pair in errors.windows(2) {
        assert!(pair[1].0 < pair[0].0 / 1.5, "k converges: {errors:?}");
        assert!(
            pair[1].1 < pair[0].1 / 1.5,
            "L2(|mu| - k) falls: {errors:?}"
        );
    }
}

#[test]
fn the_map_does_not_depend_on_the_start() {
    let a = four_point(4, PI / 6.0, "harmonic");
    let b = four_point(4, PI / 6.0, "tutte");
    let distance = a
        .map
        .iter()
        .zip(&b.map)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(
        distance < 1e-5,
        "harmonic and tutte starts end {distance:e} apart"
    );
    assert!((a.k - b.k).abs() < 1e-7);
}
