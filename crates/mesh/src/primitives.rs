//! Generated meshes for tests, examples and benchmarks: grids, spheres, tori.
//!
//! Each returns a [`PolygonSoup`] (so callers can permute or corrupt it before building)
//! with counter-clockwise faces seen from outside (or from +z for planar grids).

use std::f64::consts::TAU;

use nalgebra::Point3;

use crate::PolygonSoup;

/// Which cells a structured mesh is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cells {
    /// Each grid cell split into two triangles along its (0,0)-(1,1) diagonal.
    Triangles,
    /// One quad per grid cell.
    Quads,
}

fn push_cell(soup: &mut PolygonSoup, cells: Cells, a: u32, b: u32, c: u32, d: u32) {
    // a, b, c, d counter-clockwise.
    match cells {
        Cells::Triangles => {
            soup.push_face(&[a, b, c]);
            soup.push_face(&[a, c, d]);
        }
        Cells::Quads => soup.push_face(&[a, b, c, d]),
    }
}

/// The unit square `[0, 1]^2` in the plane z = 0, with `nx` by `ny` cells. Vertex
/// `i + (nx + 1) j` is at `(i / nx, j / ny)`.
pub fn grid(nx: usize, ny: usize, cells: Cells) -> PolygonSoup {
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            positions.push(Point3::new(i as f64 / nx as f64, j as f64 / ny as f64, 0.0));
        }
    }
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(2 * nx * ny, 6 * nx * ny);
    let id = |i: usize, j: usize| (i + (nx + 1) * j) as u32;
    for j in 0..ny {
        for i in 0..nx {
            push_cell(
                &mut soup,
                cells,
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1),
            );
        }
    }
    soup
}

/// A torus with `n_major` cells around the axis (z) and `n_minor` around the tube, major
/// radius `major`, tube radius `minor`.
pub fn torus(n_major: usize, n_minor: usize, major: f64, minor: f64, cells: Cells) -> PolygonSoup {
    let mut positions = Vec::with_capacity(n_major * n_minor);
    for i in 0..n_major {
        let u = TAU * i as f64 / n_major as f64;
        for j in 0..n_minor {
            let v = TAU * j as f64 / n_minor as f64;
            let r = major + minor * v.cos();
            positions.push(Point3::new(r * u.cos(), r * u.sin(), minor * v.sin()));
        }
    }
    let mut soup = PolygonSoup::new(positions);
    let id = |i: usize, j: usize| ((i % n_major) * n_minor + (j % n_minor)) as u32;
    for i in 0..n_major {
        for j in 0..n_minor {
            push_cell(
                &mut soup,
                cells,
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1),
            );
        }
    }
    soup
}

/// The unit sphere: an icosahedron whose triangles are split 1-to-4 `subdivisions`
/// times, new vertices projected onto the sphere. It has `10 * 4^s + 2` vertices and
/// `20 * 4^s` faces.
pub fn icosphere(subdivisions: usize) -> PolygonSoup {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<Point3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Point3::from(nalgebra::Vector3::from(*p).normalize()))
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Point3<f64>>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize].coords + positions[b as usize].coords).normalize();
                positions.push(Point3::from(m));
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(4 * triangles.len());
        for &[a, b, c] in &triangles {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    PolygonSoup::from_triangles(positions, &triangles)
}

/// [`grid`] with every vertex off the square's boundary moved by independent uniform
/// offsets of up to `amount` cells in x and in y (`amount < 0.5` keeps every face
/// counter-clockwise). The offsets come from a SplitMix64 stream seeded with `seed`, so
/// the same arguments give the same mesh on every machine: irregular meshes for tests and
/// benchmarks.
pub fn jittered_grid(nx: usize, ny: usize, cells: Cells, amount: f64, seed: u64) -> PolygonSoup {
    let mut soup = grid(nx, ny, cells);
    let mut state = seed;
    let mut uniform = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    };
    let (hx, hy) = (1.0 / nx as f64, 1.0 / ny as f64);
    for p in &mut soup.positions {
        let interior = p.x > 0.5 * hx * 1e-6
            && p.x < 1.0 - 0.5 * hx * 1e-6
            && p.y > 0.5 * hy * 1e-6
            && p.y < 1.0 - 0.5 * hy * 1e-6;
        if interior {
            p.x += uniform() * amount * hx;
            p.y += uniform() * amount * hy;
        }
    }
    soup
}
