//! Shared pieces of the flow tests: running a problem, error measures, the paper's
//! diffeomorphism of the square.

#![allow(dead_code)]

use beltrami_core::{Context, Map, Pin, Problem, Solution, Solver};
use beltrami_fem::MuError;
use beltrami_fem::{Elements, Frame};
use beltrami_flow::BeltramiFlow;
use beltrami_mesh::{Mesh, Point3, VertexId};
use num_complex::Complex64;

/// Pins without positions at `vertices`.
pub fn pins(vertices: &[u32]) -> Vec<Pin> {
    vertices
        .iter()
        .map(|&v| Pin {
            vertex: VertexId(v),
            position: None,
        })
        .collect()
}

/// Solves `problem` with the flow.
pub fn flow(problem: &Problem<'_>) -> Solution {
    BeltramiFlow
        .solve(problem, &mut Context::new())
        .expect("the flow runs")
}

/// `|mu - target|` of a solution (measured in `frame`).
pub fn mu_error(mesh: &Mesh, solution: &Solution, target: &[Complex64], frame: Frame) -> MuError {
    let elements = Elements::new(mesh, frame).unwrap();
    let measured = solution.metrics.mu.as_ref().expect("mu is reported");
    assert_eq!(measured.frame, frame);
    MuError::new(&elements, &measured.mu, target).unwrap()
}

/// The planar images of a solution.
pub fn planar(solution: &Solution) -> &[Complex64] {
    match solution.map().expect("a map") {
        Map::Planar(z) => z,
        other => panic!("expected a planar map, got {other:?}"),
    }
}

/// The spatial images of a solution.
pub fn spatial(solution: &Solution) -> &[Point3<f64>] {
    match solution.map().expect("a map") {
        Map::Spatial(p) => p,
        other => panic!("expected a spatial map, got {other:?}"),
    }
}

/// `z = x + i y` of a point.
pub fn complex(p: &Point3<f64>) -> Complex64 {
    Complex64::new(p.x, p.y)
}

/// `mu` at the face centroids of a planar mesh.
pub fn sample(mesh: &Mesh, mu: impl Fn(Complex64) -> Complex64) -> Vec<Complex64> {
    mesh.faces()
        .map(|f| mu(complex(&mesh.face_centroid(f))))
        .collect()
}

/// The square `[-1, 1]^2` with `n` by `n` cells split into triangles.
pub fn square(n: usize) -> Mesh {
    Mesh::from_soup(&beltrami_mesh::primitives::centered_square(n)).unwrap()
}

/// The bundled hemisphere (a cap of the unit sphere, 3600 triangles).
pub fn hemisphere() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/disk_hemisphere.obj"
    );
    beltrami_mesh::io::read(std::path::Path::new(path), &Default::default())
        .expect("the bundled hemisphere reads")
        .mesh
}

/// A deterministic pseudo-random number in `[-1, 1)` for index `i` (SplitMix64).
pub fn noise(seed: u64, i: usize) -> f64 {
    let mut z = seed.wrapping_add((i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0
}
