//! Atlases of generated surfaces with a known answer: developable surfaces unroll with
//! stretch 1 along one straight seam, a cube gets its cones at its eight corners and
//! stretch 1, and every atlas is in the unit square with counter-clockwise charts that
//! overlap nowhere (checked here triangle against triangle).

use std::collections::HashMap;

use beltrami_atlas::{Atlas, AtlasError, AtlasOptions, ChartCount, ConeCount, atlas};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{FaceId, Mesh, Point3, PolygonSoup, Vector3};

/// A cylinder of radius `r` and height `h` without its caps (an annulus), `n` sectors
/// by `m` rows.
fn open_cylinder(r: f64, h: f64, n: usize, m: usize) -> Mesh {
    let positions = (0..=m)
        .flat_map(|j| {
            (0..n).map(move |i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                Point3::new(r * a.cos(), r * a.sin(), h * j as f64 / m as f64)
            })
        })
        .collect();
    let mut soup = PolygonSoup::new(positions);
    let at = |i: usize, j: usize| (j * n + i % n) as u32;
    for j in 0..m {
        for i in 0..n {
            soup.push_face(&[at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            soup.push_face(&[at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh::from_soup(&soup).unwrap()
}

/// The surface of the cube `[0, n]^3` with `n x n` squares per side, each split in two.
fn cube(n: usize) -> (Mesh, Vec<Point3<f64>>) {
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut vertex = |p: [i64; 3], positions: &mut Vec<Point3<f64>>| {
        *index.entry(p).or_insert_with(|| {
            positions.push(Point3::new(p[0] as f64, p[1] as f64, p[2] as f64));
            (positions.len() - 1) as u32
        })
    };
    let n = n as i64;
    // Each side: a fixed axis at 0 or n, two running axes ordered so the normal points out.
    for axis in 0..3 {
        for side in [0, n] {
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let (a, b) = if side == n { (a, b) } else { (b, a) };
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: i64, dj: i64| {
                        let mut p = [0; 3];
                        p[axis] = side;
                        p[a] = i + di;
                        p[b] = j + dj;
                        p
                    };
                    let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                        .map(|p| vertex(p, &mut positions));
                    faces.push([q[0], q[1], q[2]]);
                    faces.push([q[0], q[2], q[3]]);
                }
            }
        }
    }
    let corners = (0..8)
        .map(|k| {
            let c = |bit: i64| if k & (1 << bit) != 0 { n as f64 } else { 0.0 };
            Point3::new(c(0), c(1), c(2))
        })
        .collect();
    let mesh = Mesh::from_soup(&PolygonSoup::from_triangles(positions, &faces)).unwrap();
    (mesh, corners)
}

/// Twice the signed area of a UV triangle.
fn area2(t: [[f64; 2]; 3]) -> f64 {
    (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0])
}

/// Whether two counter-clockwise triangles share interior points: no edge of either
/// separates them (each edge's line has the other triangle wholly on its outer side or
/// on it).
fn interiors_meet(p: [[f64; 2]; 3], q: [[f64; 2]; 3]) -> bool {
    let separates = |t: [[f64; 2]; 3], other: [[f64; 2]; 3]| {
        (0..3).any(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            other.iter().all(|&c| area2([a, b, c]) <= 0.0)
        })
    };
    !(separates(p, q) || separates(q, p))
}

/// Checks what every atlas promises: UVs in the unit square, every face counter-clockwise
/// (no mirrored chart, no flipped face), and no two faces' UV triangles overlapping.
fn check_atlas(mesh: &Mesh, result: &Atlas) {
    assert!(
        result
            .uv
            .uvs
            .iter()
            .all(|p| (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]))
    );
    let triangles: Vec<[[f64; 2]; 3]> = mesh.faces().map(|f| result.uv.face_uvs(f)).collect();
    for (f, t) in triangles.iter().enumerate() {
        assert!(area2(*t) > 0.0, "face {f} is not counter-clockwise: {t:?}");
    }
    // Bucket the triangles' boxes in a grid and test every pair that shares a cell.
    let cells = ((triangles.len() as f64).sqrt() as usize).max(1);
    let cell = |x: f64| ((x * cells as f64) as usize).min(cells - 1);
    let mut buckets: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        let lo = [0, 1].map(|k| t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|k| t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
        for x in cell(lo[0])..=cell(hi[0]) {
            for y in cell(lo[1])..=cell(hi[1]) {
                buckets.entry((x, y)).or_default().push(f);
            }
        }
    }
    for bucket in buckets.values() {
        for (k, &f) in bucket.iter().enumerate() {
            for &g in &bucket[k + 1..] {
                assert!(
                    !interiors_meet(triangles[f], triangles[g]),
                    "faces {f} and {g} overlap in the texture"
                );
            }
        }
    }
}

/// The length of the seams of an atlas.
fn seam_length(mesh: &Mesh, result: &Atlas) -> f64 {
    result
        .uv
        .seams(mesh)
        .iter()
        .map(|&e| mesh.edge_length(e))
        .sum()
}

/// Every UV edge has the length of its surface edge times one factor per chart: the map
/// is an isometry up to scale on each chart.
fn assert_isometric(mesh: &Mesh, result: &Atlas, tolerance: f64) {
    let mut factor: HashMap<u32, f64> = HashMap::new();
    for f in mesh.faces() {
        let (v, _) = mesh.face_vertex_array(f);
        let t = result.uv.face_uvs(f);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let flat = (b[0] - a[0]).hypot(b[1] - a[1]);
            let surface = (mesh.position(v[(k + 1) % 3]) - mesh.position(v[k])).norm();
            let ratio = *factor
                .entry(result.face_chart[f.idx()])
                .or_insert(flat / surface);
            assert!(
                (flat / surface / ratio - 1.0).abs() < tolerance,
                "face {f:?} corner {k}: {} against {ratio}",
                flat / surface
            );
        }
    }
}

#[test]
fn an_open_cylinder_unrolls_to_a_rectangle_along_one_ruling() {
    let (r, h) = (1.0, 2.5);
    let mesh = open_cylinder(r, h, 48, 20);
    let result = atlas(&mesh, &AtlasOptions::default()).unwrap();
    check_atlas(&mesh, &result);
    assert_eq!(result.charts.len(), 1);
    assert!(result.charts[0].cones.is_empty());
    assert!(
        (result.stretch.l2 - 1.0).abs() < 1e-9,
        "{:?}",
        result.stretch
    );
    assert!(
        (result.stretch.linf - 1.0).abs() < 1e-9,
        "{:?}",
        result.stretch
    );
    // The seam is one ruling, as long as the cylinder is high.
    assert!((seam_length(&mesh, &result) - h).abs() < 1e-9);
    assert_isometric(&mesh, &result, 1e-9);
}

#[test]
fn a_cone_frustum_unrolls_isometrically() {
    // A frustum of the cone z = 2 (1 - rho): developable, no curvature inside.
    let flat = Mesh::from_soup(&grid(40, 8, Cells::Triangles)).unwrap();
    let positions: Vec<Point3<f64>> = flat
        .positions()
        .iter()
        .map(|p| {
            let a = std::f64::consts::PI * 1.5 * p.x;
            let rho = 1.0 - 0.6 * p.y;
            Point3::new(rho * a.cos(), rho * a.sin(), 2.0 * (1.0 - rho))
        })
        .collect();
    let mesh = flat.with_positions(positions).unwrap();
    let result = atlas(&mesh, &AtlasOptions::default()).unwrap();
    check_atlas(&mesh, &result);
    assert_eq!(result.charts.len(), 1);
    assert!(
        (result.stretch.l2 - 1.0).abs() < 1e-9,
        "{:?}",
        result.stretch
    );
    assert_eq!(result.uv.seams(&mesh), Vec::new());
    assert_isometric(&mesh, &result, 1e-9);
}

#[test]
fn a_cube_gets_its_cones_at_its_corners_and_no_stretch() {
    let (mesh, corners) = cube(6);
    let options = AtlasOptions {
        max_stretch: 1.0 + 1e-9,
        ..AtlasOptions::default()
    };
    let result = atlas(&mesh, &options).unwrap();
    check_atlas(&mesh, &result);
    let mut cones: Vec<Point3<f64>> = result
        .charts
        .iter()
        .flat_map(|c| c.cones.iter().map(|&v| mesh.position(v)))
        .collect();
    cones.sort_by(|a, b| {
        a.coords
            .as_slice()
            .partial_cmp(b.coords.as_slice())
            .unwrap()
    });
    let mut expected = corners.clone();
    expected.sort_by(|a, b| {
        a.coords
            .as_slice()
            .partial_cmp(b.coords.as_slice())
            .unwrap()
    });
    assert_eq!(result.charts.len(), 1);
    assert_eq!(cones, expected);
    assert!(
        (result.stretch.l2 - 1.0).abs() < 1e-6,
        "{:?}",
        result.stretch
    );
    assert_isometric(&mesh, &result, 1e-6);
}

#[test]
fn closed_surfaces_of_genus_zero_and_one_and_several_pieces_get_valid_atlases() {
    let sphere = Mesh::from_soup(&icosphere(4)).unwrap();
    let ring = Mesh::from_soup(&torus(60, 20, 1.0, 0.35, Cells::Triangles)).unwrap();
    for mesh in [&sphere, &ring] {
        let result = atlas(mesh, &AtlasOptions::default()).unwrap();
        check_atlas(mesh, &result);
        assert!(result.stretch.l2 <= 1.1, "{:?}", result.stretch);
    }
    // Two spheres side by side: each piece gets its own charts.
    let soup = icosphere(3);
    let n = soup.vertex_count() as u32;
    let mut positions = soup.positions.clone();
    positions.extend(
        soup.positions
            .iter()
            .map(|p| p + Vector3::new(3.0, 0.0, 0.0)),
    );
    let mut both = PolygonSoup::new(positions);
    for face in soup.faces() {
        both.push_face(face);
    }
    for face in soup.faces() {
        both.push_face(&face.iter().map(|v| v + n).collect::<Vec<_>>());
    }
    let mesh = Mesh::from_soup(&both).unwrap();
    let result = atlas(&mesh, &AtlasOptions::default()).unwrap();
    check_atlas(&mesh, &result);
    let first_half = |f: FaceId| f.idx() < mesh.face_count() / 2;
    for f in mesh.faces() {
        for g in mesh.faces() {
            if result.face_chart[f.idx()] == result.face_chart[g.idx()] {
                assert_eq!(first_half(f), first_half(g));
            }
        }
    }
}

#[test]
fn asking_for_more_charts_splits_the_most_stretched_until_there_are() {
    let ring = Mesh::from_soup(&torus(60, 20, 1.0, 0.35, Cells::Triangles)).unwrap();
    let automatic = atlas(&ring, &AtlasOptions::default()).unwrap();
    assert_eq!(automatic.splits.charts, 0);
    let mut l2 = vec![automatic.stretch.l2];
    for n in [automatic.charts.len() + 3, 12] {
        let options = AtlasOptions {
            charts: ChartCount::AtLeast(n),
            ..AtlasOptions::default()
        };
        let result = atlas(&ring, &options).unwrap();
        check_atlas(&ring, &result);
        println!(
            "at least {n}: {} charts, L2 {}, splits {:?}",
            result.charts.len(),
            result.stretch.l2,
            result.splits
        );
        assert!(
            (n..=n + 1).contains(&result.charts.len()),
            "{}",
            result.charts.len()
        );
        assert!(result.splits.charts >= 1);
        l2.push(result.stretch.l2);
    }
    // More charts, each flattened with its own cones: less stretch (measured 1.081,
    // 1.035 and 1.005 for 2, 5 and 12 charts).
    assert!(l2.windows(2).all(|w| w[1] < w[0]), "{l2:?}");
    // At least as many charts as the automatic atlas has already: the same atlas.
    let fewer = AtlasOptions {
        charts: ChartCount::AtLeast(1),
        ..AtlasOptions::default()
    };
    let same = atlas(&ring, &fewer).unwrap();
    assert_eq!(same.face_chart, automatic.face_chart);
    assert_eq!(same.uv.uvs, automatic.uv.uvs);
}

#[test]
fn quads_and_options_out_of_range_are_refused_by_name() {
    let quads = Mesh::from_soup(&grid(3, 3, Cells::Quads)).unwrap();
    let error = atlas(&quads, &AtlasOptions::default()).unwrap_err();
    assert!(
        matches!(error, AtlasError::NotTriangles { corners: 4, .. }),
        "{error}"
    );
    let square = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
    for (options, name) in [
        (
            AtlasOptions {
                max_stretch: 0.9,
                ..AtlasOptions::default()
            },
            "max-stretch",
        ),
        (
            AtlasOptions {
                padding: -0.1,
                ..AtlasOptions::default()
            },
            "padding",
        ),
        (
            AtlasOptions {
                cones: ConeCount::Exactly(20_000),
                ..AtlasOptions::default()
            },
            "cones",
        ),
        (
            AtlasOptions {
                charts: ChartCount::AtLeast(0),
                ..AtlasOptions::default()
            },
            "charts",
        ),
        (
            AtlasOptions {
                charts: ChartCount::AtLeast(square.face_count() + 1),
                ..AtlasOptions::default()
            },
            "charts",
        ),
    ] {
        match atlas(&square, &options) {
            Err(AtlasError::InvalidOption { option, .. }) => assert_eq!(option, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}
