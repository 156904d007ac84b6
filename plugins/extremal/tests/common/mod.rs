//! Meshes and exact maps shared by the extremal tests.
#![allow(dead_code)]

use std::f64::consts::TAU;

use beltrami_core::{Context, Goal, Map, PlanarBoundary, Problem, Solution, Solver, Target};
use beltrami_extremal::Extremal;
use beltrami_fem::{Elements, Frame, beltrami::planar_map};
use beltrami_mesh::{Mesh, primitives};
use num_complex::Complex64;

/// A SplitMix64 stream of uniform numbers in [-1, 1): reproducible noise.
pub fn noise(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// The annulus `r0 <= |z| <= 1` with `rings x sectors` cells, every interior vertex
/// moved by up to 0.3 cells in log-radius and in angle: an irregular mesh.
pub fn irregular_annulus(r0: f64, rings: usize, sectors: usize, seed: u64) -> Mesh {
    let mut soup = primitives::annulus(r0, rings, sectors);
    let mut u = noise(seed);
    let d_log = -r0.ln() / rings as f64;
    let d_angle = TAU / sectors as f64;
    for p in &mut soup.positions {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        if (r - 1.0).abs() < 1e-9 || (r - r0).abs() < 1e-9 {
            continue;
        }
        let r = (r.ln() + 0.3 * d_log * u()).exp();
        let a = p.y.atan2(p.x) + 0.3 * d_angle * u();
        p.x = r * a.cos();
        p.y = r * a.sin();
    }
    Mesh::from_soup(&soup).expect("a valid annulus")
}

/// The ring map `(r, theta) -> (r0' (r / r0)^K, theta)`, `K = ln(r1'/r0') / ln(r1/r0)`:
/// the extremal map between the rings (paper section 5), with `mu = k z / conj(z)`,
/// `k = (K - 1) / (K + 1)`.
#[derive(Debug, Clone, Copy)]
pub struct RingMap {
    pub r0: f64,
    pub r1: f64,
    pub s0: f64,
    pub s1: f64,
}

impl RingMap {
    pub fn exponent(&self) -> f64 {
        (self.s1 / self.s0).ln() / (self.r1 / self.r0).ln()
    }

    pub fn k(&self) -> f64 {
        let big_k = self.exponent();
        (big_k - 1.0).abs() / (big_k + 1.0)
    }

    pub fn at(&self, z: Complex64) -> Complex64 {
        let r = z.norm();
        z / r * self.s0 * (r / self.r0).powf(self.exponent())
    }
}

/// The images of every vertex under `f`.
pub fn image(mesh: &Mesh, f: impl Fn(Complex64) -> Complex64) -> Vec<Complex64> {
    mesh.positions()
        .iter()
        .map(|p| f(Complex64::new(p.x, p.y)))
        .collect()
}

/// Area-weighted RMS of `|mu| - k` over the faces of the planar map `map`.
pub fn l2_deviation(mesh: &Mesh, map: &[Complex64], k: f64) -> f64 {
    let elements = Elements::new(mesh, Frame::Global).unwrap();
    let d = planar_map(&elements, mesh.vertex_count(), map).unwrap();
    let (mut sum, mut area) = (0.0, 0.0);
    for (q, d) in elements.points().iter().zip(&d) {
        sum += q.weight * (d.mu().norm() - k).powi(2);
        area += q.weight;
    }
    (sum / area).sqrt()
}

/// Largest `|a - b|` over the vertices.
pub fn max_distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

/// The extremal map of `mesh` with the boundary values of `boundary`, from `initial`
/// (or the option `init`), with a tight tolerance.
pub fn solve(
    mesh: &Mesh,
    boundary: Vec<Complex64>,
    initial: Option<Vec<Complex64>>,
    init: &str,
) -> Solution {
    let mut problem = Problem::new(mesh, Target::Plane(PlanarBoundary::Given(boundary)));
    problem.goal = Goal::Extremal;
    problem.initial = initial.map(Map::Planar);
    problem.options.set_text("init", init);
    problem.options.set_text("tolerance", "1e-9");
    problem.options.set_text("max-iters", "500");
    Extremal.solve(&problem, &mut Context::new()).unwrap()
}
