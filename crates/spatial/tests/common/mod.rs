//! Helpers shared by the integration tests of beltrami-spatial.
// Each test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami_mesh::{BuildOptions, Mesh, PolygonSoup, io};
use nalgebra::{Point3, Vector3};

/// Deterministic SplitMix64 generator.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// Uniform in the box [lo, hi].
    pub fn in_box(&mut self, lo: &Point3<f64>, hi: &Point3<f64>) -> Point3<f64> {
        Point3::new(
            self.range(lo.x, hi.x),
            self.range(lo.y, hi.y),
            self.range(lo.z, hi.z),
        )
    }

    /// Uniform direction.
    pub fn direction(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// `../shared/meshes/NAME` beside the repository, or `None` with a SKIPPED note.
pub fn shared_mesh(name: &str) -> Option<Mesh> {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/meshes")
        .join(name);
    if !path.is_file() {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: {} not found; the shared-mesh tests need ../shared beside the repo",
            path.display()
        );
        return None;
    }
    Some(
        io::read(&path, &BuildOptions::default())
            .expect("the shared meshes load")
            .mesh,
    )
}

pub fn build(soup: &PolygonSoup) -> Mesh {
    Mesh::from_soup(soup).expect("test mesh builds")
}

/// An open prism around the z axis: `n` sides on the unit circle, `rows` rows of height
/// `h` each, every cell split into two triangles.
pub fn prism(n: usize, rows: usize, h: f64) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=rows {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            positions.push(Point3::new(a.cos(), a.sin(), j as f64 * h));
        }
    }
    let id = |i: usize, j: usize| ((i % n) + n * j) as u32;
    let mut triangles = Vec::new();
    for j in 0..rows {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    build(&PolygonSoup::from_triangles(positions, &triangles))
}

/// The surface of the unit cube [0, 1]^3, each side a `k` x `k` grid of quads or of
/// triangle pairs, outward oriented.
pub fn cube(k: usize, quads: bool) -> Mesh {
    let mut positions: Vec<Point3<f64>> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut id = |p: Point3<f64>| -> u32 {
        let key = (
            (p.x * k as f64).round() as i64,
            (p.y * k as f64).round() as i64,
            (p.z * k as f64).round() as i64,
        );
        *index.entry(key).or_insert_with(|| {
            positions.push(p);
            (positions.len() - 1) as u32
        })
    };
    let mut faces: Vec<Vec<u32>> = Vec::new();
    // Each side: origin o, in-plane axes a, b with a x b the outward normal.
    let sides: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // z = 0, normal -z
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), // z = 1, normal +z
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // y = 0, normal -y
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), // y = 1, normal +y
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), // x = 0, normal -x
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), // x = 1, normal +x
    ];
    for (o, a, b) in sides {
        let at = |i: usize, j: usize| {
            let (s, t) = (i as f64 / k as f64, j as f64 / k as f64);
            Point3::new(
                o[0] + s * a[0] + t * b[0],
                o[1] + s * a[1] + t * b[1],
                o[2] + s * a[2] + t * b[2],
            )
        };
        for j in 0..k {
            for i in 0..k {
                let c = [
                    id(at(i, j)),
                    id(at(i + 1, j)),
                    id(at(i + 1, j + 1)),
                    id(at(i, j + 1)),
                ];
                if quads {
                    faces.push(c.to_vec());
                } else {
                    faces.push(vec![c[0], c[1], c[2]]);
                    faces.push(vec![c[0], c[2], c[3]]);
                }
            }
        }
    }
    let mut soup = PolygonSoup::new(positions);
    for f in &faces {
        soup.push_face(f);
    }
    build(&soup)
}

/// The unit square as a `k` x `k` grid whose cells are alternately quads and triangle
/// pairs (a checkerboard of both kinds).
pub fn mixed_grid(k: usize) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            positions.push(Point3::new(i as f64 / k as f64, j as f64 / k as f64, 0.0));
        }
    }
    let id = |i: usize, j: usize| (i + (k + 1) * j) as u32;
    let mut soup = PolygonSoup::new(positions);
    for j in 0..k {
        for i in 0..k {
            let c = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if (i + j) % 2 == 0 {
                soup.push_face(&c);
            } else {
                soup.push_face(&[c[0], c[1], c[2]]);
                soup.push_face(&[c[0], c[2], c[3]]);
            }
        }
    }
    build(&soup)
}
