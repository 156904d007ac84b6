//! Helpers shared by the integration tests of beltrami-fem: a reproducible random
//! generator (no dev-dependency needed), jittered planar meshes and the bundled
//! hemisphere.
// Each test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use std::path::Path;

use beltrami_mesh::io::read;
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{BuildOptions, Mesh, VertexId};
use num_complex::Complex64;

/// splitmix64: a reproducible stream of random numbers.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [-1, 1).
    pub fn uniform(&mut self) -> f64 {
        2.0 * self.next() - 1.0
    }

    /// Uniform in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// A Beltrami coefficient with `|mu| < 0.9`.
    pub fn mu(&mut self) -> Complex64 {
        Complex64::from_polar(0.9 * self.next(), std::f64::consts::TAU * self.next())
    }
}

/// The unit-square grid of `n x n` cells with interior vertices moved randomly by up to
/// `amount` cells in x and y.
pub fn jittered(n: usize, cells: Cells, amount: f64, seed: u64) -> Mesh {
    Mesh::from_soup(&jittered_grid(n, n, cells, amount, seed))
        .expect("a jittered grid is a valid mesh")
}

/// The bundled hemisphere (a cap of the unit sphere, 3600 triangles).
pub fn hemisphere() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/disk_hemisphere.obj"
    );
    read(Path::new(path), &BuildOptions::default())
        .expect("the bundled hemisphere reads")
        .mesh
}

/// Boundary vertices of the (single) boundary loop.
pub fn boundary_vertices(mesh: &Mesh) -> Vec<VertexId> {
    mesh.boundary_loop_list()[0].vertices.clone()
}

/// `a.re b.im - a.im b.re`.
pub fn cross(a: Complex64, b: Complex64) -> f64 {
    a.re * b.im - a.im * b.re
}
