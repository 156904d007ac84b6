//! Generated meshes for tests, examples and benchmarks: grids, disks, annuli, spheres,
//! tori (among them the refinement families of Wong-Zhao 2014, section 5.1).
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
        triangles = split_triangles(&mut positions, &triangles, |m, _| {
            Point3::from(m.coords.normalize())
        });
    }
    PolygonSoup::from_triangles(positions, &triangles)
}

/// [`grid`] with every vertex off the square's boundary moved by independent uniform
/// offsets of up to `amount` cells in x and in y (`amount < 0.5` keeps every triangle
/// counter-clockwise, `amount < 0.25` every quad convex: at 0.25 a corner can reach the
/// line through its two neighbours, and a quad that folds is not a valid mesh). The offsets come from a SplitMix64 stream seeded with `seed`, so
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

/// One 1-to-4 split of `triangles` by their edge midpoints, new vertices appended to
/// `positions` at `place(midpoint, on_boundary)` (`on_boundary`: the edge belongs to one
/// triangle only). Children of triangle `t` are `4t .. 4t + 3`, with its orientation.
fn split_triangles(
    positions: &mut Vec<Point3<f64>>,
    triangles: &[[u32; 3]],
    place: impl Fn(Point3<f64>, bool) -> Point3<f64>,
) -> Vec<[u32; 3]> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut uses = std::collections::HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *uses.entry(key(t[k], t[(k + 1) % 3])).or_insert(0u32) += 1;
        }
    }
    let mut midpoint = std::collections::HashMap::new();
    let mut mid = |a: u32, b: u32, positions: &mut Vec<Point3<f64>>| -> u32 {
        *midpoint.entry(key(a, b)).or_insert_with(|| {
            let m = nalgebra::center(&positions[a as usize], &positions[b as usize]);
            positions.push(place(m, uses[&key(a, b)] == 1));
            (positions.len() - 1) as u32
        })
    };
    let mut next = Vec::with_capacity(4 * triangles.len());
    for &[a, b, c] in triangles {
        let ab = mid(a, b, positions);
        let bc = mid(b, c, positions);
        let ca = mid(c, a, positions);
        next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    next
}

/// `soup` with its vertices renumbered `i -> s i mod n` (`n` vertices, `s` the first
/// integer from `0.618 n` prime to `n`: steps of the golden ratio's share spread
/// consecutive indices evenly over the range): the same surface with neighbouring
/// vertices far apart in the numbering, as in the files of many scanned meshes; for
/// tests of numbering independence ([`crate::renumber`]).
pub fn scattered(soup: &PolygonSoup) -> PolygonSoup {
    let n = soup.vertex_count();
    let gcd = |mut a: usize, mut b: usize| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let start = (0.618 * n as f64).round() as usize;
    let stride = (start.max(1)..).find(|&s| gcd(s, n) == 1).unwrap_or(1);
    let place: Vec<u32> = (0..n).map(|i| ((stride * i) % n.max(1)) as u32).collect();
    let mut positions = soup.positions.clone();
    for (i, p) in soup.positions.iter().enumerate() {
        positions[place[i] as usize] = *p;
    }
    let mut out = PolygonSoup::new(positions);
    out.reserve(soup.face_count(), soup.faces().map(<[u32]>::len).sum());
    for face in soup.faces() {
        let corners: Vec<u32> = face.iter().map(|&v| place[v as usize]).collect();
        out.push_face(&corners);
    }
    out
}

/// The square `[-1, 1]^2` of Wong-Zhao's Table 5.3 in the plane z = 0: [`grid`] with `n`
/// by `n` cells split into triangles, scaled and centred (vertex `i + (n + 1) j` at
/// `(2 i / n - 1, 2 j / n - 1)`).
pub fn centered_square(n: usize) -> PolygonSoup {
    let mut soup = grid(n, n, Cells::Triangles);
    for p in &mut soup.positions {
        p.x = 2.0 * p.x - 1.0;
        p.y = 2.0 * p.y - 1.0;
    }
    soup
}

/// The unit disk of Wong-Zhao's Table 5.1: level 0 is the square with corners
/// `1, i, -1, -i` split into four triangles at the centre; each level splits every
/// triangle 1-to-4 by its edge midpoints, boundary midpoints projected radially onto the
/// unit circle (interior midpoints stay on their edges). Level `l` has `4^(l+1)` faces;
/// vertex 0 is the centre and vertex 1 the point `1`.
pub fn disk(level: usize) -> PolygonSoup {
    let mut positions = vec![
        Point3::origin(),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(-1.0, 0.0, 0.0),
        Point3::new(0.0, -1.0, 0.0),
    ];
    let mut triangles = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
    for _ in 0..level {
        triangles = split_triangles(&mut positions, &triangles, |m, boundary| {
            if boundary {
                Point3::from(m.coords.normalize())
            } else {
                m
            }
        });
    }
    PolygonSoup::from_triangles(positions, &triangles)
}

/// The unit sphere of Wong-Zhao's Table 5.2: level 0 is the octahedron with vertices
/// `+-e_x, +-e_y, +-e_z`; each level splits every triangle 1-to-4, midpoints projected
/// onto the sphere. Level `l` has `8 * 4^l` faces; vertex 0 is `(0, 0, -1)`, vertex 1 is
/// `(1, 0, 0)` and vertex 5 is `(0, 0, 1)` — the points `0`, `1` and `infinity` of the
/// stereographic coordinate from the north pole.
pub fn octahedral_sphere(level: usize) -> PolygonSoup {
    let mut positions = vec![
        Point3::new(0.0, 0.0, -1.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(-1.0, 0.0, 0.0),
        Point3::new(0.0, -1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
    ];
    let mut triangles = vec![
        [0, 2, 1],
        [0, 3, 2],
        [0, 4, 3],
        [0, 1, 4],
        [5, 1, 2],
        [5, 2, 3],
        [5, 3, 4],
        [5, 4, 1],
    ];
    for _ in 0..level {
        triangles = split_triangles(&mut positions, &triangles, |m, _| {
            Point3::from(m.coords.normalize())
        });
    }
    PolygonSoup::from_triangles(positions, &triangles)
}

/// The annulus `inner <= |z| <= 1` in the plane z = 0: `rings` layers of cells between
/// the two circles (radii spaced geometrically, so cells stay close to squares) and
/// `sectors` cells around, each cell split into two triangles along alternating
/// diagonals. Vertex `s + sectors * r` is at radius `inner^(1 - r / rings)`, angle
/// `2 pi s / sectors`; vertex `sectors * rings` is the point `1`.
pub fn annulus(inner: f64, rings: usize, sectors: usize) -> PolygonSoup {
    let mut positions = Vec::with_capacity((rings + 1) * sectors);
    for r in 0..=rings {
        let radius = inner.powf(1.0 - r as f64 / rings as f64);
        for s in 0..sectors {
            let angle = TAU * s as f64 / sectors as f64;
            positions.push(Point3::new(radius * angle.cos(), radius * angle.sin(), 0.0));
        }
    }
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(2 * rings * sectors, 6 * rings * sectors);
    let id = |s: usize, r: usize| (s % sectors + sectors * r) as u32;
    for r in 0..rings {
        for s in 0..sectors {
            let (a, b, c, d) = (id(s, r), id(s + 1, r), id(s + 1, r + 1), id(s, r + 1));
            // Counter-clockwise: a -> d is outward, a -> b turns with the angle.
            if (r + s) % 2 == 0 {
                soup.push_face(&[a, c, b]);
                soup.push_face(&[a, d, c]);
            } else {
                soup.push_face(&[a, d, b]);
                soup.push_face(&[b, d, c]);
            }
        }
    }
    soup
}

/// The modified tori of Wong-Zhao 2014 (T. W. Wong and H. Zhao, "Computation of
/// quasiconformal surface maps using discrete Beltrami flow", SIAM J. Imaging Sci. 7,
/// section 5.4), targets of their genus-1 registrations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModifiedTorus {
    /// `phi_1(u, v)`, with `r(u, v) = r1 + r2 cos 2 pi v + r3 cos 6 pi (u + v)`:
    /// `(r cos 2 pi u, r sin 2 pi u, r2 sin 2 pi v)`, `r1 = 4`, `r2 = 1.7`, `r3 = 0.3`
    /// (a tube whose distance from the axis ripples three times along a helix).
    Phi1,
    /// `phi_2(u, v)`, with tube radius `t(u) = r2 + r3 cos 10 pi u`:
    /// `((r1 + t cos 2 pi v) cos 2 pi u, (r1 + t cos 2 pi v) sin 2 pi u, t sin 2 pi v)`,
    /// `r1 = 4`, `r2 = 1.5`, `r3 = 0.4` (a tube that swells and narrows five times).
    Phi2,
}

impl ModifiedTorus {
    /// The point `phi(u, v)` for `(u, v)` in `[0, 1]^2` (periodic in both).
    pub fn point(self, u: f64, v: f64) -> Point3<f64> {
        let (su, cu) = (TAU * u).sin_cos();
        let (sv, cv) = (TAU * v).sin_cos();
        match self {
            ModifiedTorus::Phi1 => {
                let (r1, r2, r3) = (4.0, 1.7, 0.3);
                let r = r1 + r2 * cv + r3 * (3.0 * TAU * (u + v)).cos();
                Point3::new(r * cu, r * su, r2 * sv)
            }
            ModifiedTorus::Phi2 => {
                let (r1, r2, r3) = (4.0, 1.5, 0.4);
                let t = r2 + r3 * (5.0 * TAU * u).cos();
                let r = r1 + t * cv;
                Point3::new(r * cu, r * su, t * sv)
            }
        }
    }
}

/// A modified torus ([`ModifiedTorus`]) sampled on the `nu` by `nv` grid of `(u, v) =
/// (i / nu, j / nv)`, each cell split into two triangles; vertex `i nv + j` is at
/// `(i, j)`, and the faces are counter-clockwise seen from outside, as in [`torus`].
pub fn modified_torus(kind: ModifiedTorus, nu: usize, nv: usize) -> PolygonSoup {
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            positions.push(kind.point(i as f64 / nu as f64, j as f64 / nv as f64));
        }
    }
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(2 * nu * nv, 6 * nu * nv);
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    for i in 0..nu {
        for j in 0..nv {
            push_cell(
                &mut soup,
                Cells::Triangles,
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1),
            );
        }
    }
    soup
}
