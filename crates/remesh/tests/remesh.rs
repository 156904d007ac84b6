//! Remeshing on generated surfaces with known geometry: planes, a hemisphere laid out
//! by a map with a 4:1 area distortion, the sphere, a torus and an annulus.

use beltrami_core::{Context, Solver, topology::describe};
use beltrami_init::{Lscm, Sphere, Tutte};
use beltrami_mesh::primitives::{Cells, annulus, disk, grid, icosphere, jittered_grid, torus};
use beltrami_mesh::{Mesh, Point3, PolygonSoup, Vector3};
use beltrami_remesh::{RemeshError, RemeshOptions, Remeshing, Resolution, quality, remesh};

fn mesh(soup: &PolygonSoup) -> Mesh {
    Mesh::from_soup(soup).expect("generated meshes are valid")
}

fn run(input: &Mesh, edge_length: f64) -> Remeshing {
    let solvers: [&dyn Solver; 2] = [&Lscm, &Tutte];
    remesh(
        input,
        &solvers,
        &RemeshOptions::with_edge_length(edge_length),
        &mut Context::new(),
    )
    .expect("remeshing succeeds")
}

/// `soup` with every position replaced by `f(position)`.
fn mapped(mut soup: PolygonSoup, f: impl Fn(Point3<f64>) -> Point3<f64>) -> PolygonSoup {
    for p in &mut soup.positions {
        *p = f(*p);
    }
    soup
}

/// The largest distance between two vertices that are closer than `tolerance` (a
/// duplicate), if any pair is.
fn has_duplicate_vertex(m: &Mesh, tolerance: f64) -> bool {
    let mut p: Vec<Point3<f64>> = m.positions().to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x));
    (0..p.len()).any(|i| {
        p[i + 1..]
            .iter()
            .take_while(|q| q.x - p[i].x < tolerance)
            .any(|q| (q - p[i]).norm() < tolerance)
    })
}

#[test]
fn a_tilted_plane_region_stays_exactly_in_its_plane() {
    // The jittered unit square rotated into the plane n . x = d.
    let n = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let e1 = Vector3::new(2.0, -1.0, 0.0).normalize();
    let e2 = n.cross(&e1);
    let d = 0.7;
    let input = mesh(&mapped(
        jittered_grid(12, 9, Cells::Triangles, 0.3, 7),
        |p| Point3::from(d * n + p.x * e1 + 1.5 * p.y * e2),
    ));
    let result = run(&input, 0.04);
    let out = &result.remeshed.mesh;
    assert!(out.vertex_count() > 500, "{} vertices", out.vertex_count());
    let worst = out
        .positions()
        .iter()
        .map(|p| (p.coords.dot(&n) - d).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-14, "a vertex leaves the plane by {worst}");
    assert_eq!(describe(out), "genus 0 and one boundary loop");
}

#[test]
fn lifted_vertices_are_their_surface_points_on_the_input() {
    let input = mesh(&mapped(disk(4), |p| {
        Point3::new(p.x, p.y, 0.3 * (3.0 * p.x).sin() * p.y)
    }));
    let result = run(&input, 0.05);
    let r = &result.remeshed;
    assert_eq!(r.on_source.len(), r.mesh.vertex_count());
    for v in r.mesh.vertices() {
        let sp = r.on_source[v.idx()];
        sp.validate(&input)
            .expect("a valid surface point of the input");
        let gap = (sp.position(&input) - r.mesh.position(v)).norm();
        assert!(gap < 1e-14, "vertex {v} is {gap} from its surface point");
    }
}

#[test]
fn the_size_field_compensates_the_area_distortion_of_the_map() {
    // The lower hemisphere as the inverse stereographic image of the unit disk: the
    // disk is a conformal parameterization with length scale 2 / (1 + |z|^2), from 2 at
    // the pole to 1 at the rim (4:1 in area). LSCM finds it up to a similarity.
    let input = mesh(&mapped(disk(5), |p| {
        let r2 = p.x * p.x + p.y * p.y;
        Point3::new(2.0 * p.x, 2.0 * p.y, r2 - 1.0) / (1.0 + r2)
    }));
    let l = 0.08;
    let result = run(&input, l);
    let out = &result.remeshed.mesh;
    let (mut polar, mut rim) = (Vec::new(), Vec::new());
    for e in out.edges() {
        let [a, b] = out.edge_vertices(e);
        let mid = (out.position(a).coords + out.position(b).coords) / 2.0;
        let length = out.edge_length(e);
        if mid.z < -0.8 {
            polar.push(length);
        } else if mid.z > -0.3 {
            rim.push(length);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let all = out.edge_lengths();
    for (name, m) in [
        ("all", mean(&all)),
        ("polar", mean(&polar)),
        ("rim", mean(&rim)),
    ] {
        assert!(
            (m / l - 1.0).abs() < 0.1,
            "{name} edges have mean length {m}, asked {l}; polar {}, rim {}, all {}",
            mean(&polar),
            mean(&rim),
            mean(&all)
        );
    }
    let q = quality::measure(&input, out).unwrap();
    assert!(q.min_angle > 20.0, "smallest angle {}", q.min_angle);
}

#[test]
fn the_asked_vertex_count_is_met() {
    let input = mesh(&grid(8, 8, Cells::Triangles));
    let options = RemeshOptions {
        resolution: Resolution::Vertices(2000),
        ..RemeshOptions::default()
    };
    let solvers: [&dyn Solver; 1] = [&Lscm];
    let result = remesh(&input, &solvers, &options, &mut Context::new()).unwrap();
    let n = result.remeshed.mesh.vertex_count() as f64;
    assert!(
        (n / 2000.0 - 1.0).abs() < 0.15,
        "{n} vertices for 2000 asked"
    );
}

/// The mean edge length `h`, and the mean and largest distance from the unit sphere of
/// the face centroids, of a remeshing of a fine icosphere at edge length `l`.
fn sphere_error(input: &Mesh, l: f64) -> (f64, f64, f64) {
    let result = run(input, l);
    let out = &result.remeshed.mesh;
    assert_eq!(describe(out), "genus 0 and no boundary");
    assert!(!has_duplicate_vertex(out, 1e-3 * l));
    let d: Vec<f64> = out
        .faces()
        .map(|f| (out.face_centroid(f).coords.norm() - 1.0).abs())
        .collect();
    let h = out.edge_lengths().iter().sum::<f64>() / out.edge_count() as f64;
    (
        h,
        d.iter().sum::<f64>() / d.len() as f64,
        d.iter().copied().fold(0.0, f64::max),
    )
}

#[test]
fn the_sphere_remeshed_stays_on_the_sphere_to_second_order() {
    // Input vertices are on the sphere and its own chords deviate by at most 5e-5. The
    // centroid of an equilateral triangle of edge l inscribed in the unit sphere lies
    // l^2 / 6 + O(l^4) inside it: the mean deviation must fall like the square of the
    // mesh's mean edge length h, and the largest stay below a fixed multiple of h^2.
    let input = mesh(&icosphere(6));
    let sizes = [0.2, 0.1, 0.05];
    let errors: Vec<(f64, f64, f64)> = sizes.iter().map(|&l| sphere_error(&input, l)).collect();
    for i in 0..2 {
        let ((h0, e0, _), (h1, e1, _)) = (errors[i], errors[i + 1]);
        let rate = (e0 / e1).ln() / (h0 / h1).ln();
        assert!(
            (1.8..2.2).contains(&rate),
            "(h, mean, largest deviation) {errors:?} at {sizes:?}: order {rate}"
        );
    }
    for &(h, mean, max) in &errors {
        assert!(mean < 0.2 * h * h, "mean deviation {mean} at h = {h}");
        assert!(max < 0.5 * h * h, "largest deviation {max} at h = {h}");
    }
}

#[test]
fn a_torus_closes_up_along_its_seams() {
    let input = mesh(&torus(60, 24, 1.0, 0.35, Cells::Triangles));
    let l = 0.06;
    let result = run(&input, l);
    let q = closes_up(&input, &result, l, "cut-graph", "genus 1 and no boundary");
    assert!(q.min_angle > 15.0, "smallest angle {}", q.min_angle);
}

/// Checks that `result` (of `input` at edge length `l`) was opened by `opening`, has
/// the topology `topology`, no duplicate vertex (its seams are closed) and a mean edge
/// within 10% of `l`; returns its quality.
fn closes_up(
    input: &Mesh,
    result: &Remeshing,
    l: f64,
    opening: &str,
    topology: &str,
) -> quality::Quality {
    let out = &result.remeshed.mesh;
    assert_eq!(result.opening.name(), opening);
    assert_eq!(describe(out), topology);
    assert!(!has_duplicate_vertex(out, 1e-3 * l));
    let q = quality::measure(input, out).unwrap();
    assert!(
        (q.edge_mean / l - 1.0).abs() < 0.1,
        "mean edge {}",
        q.edge_mean
    );
    q
}

#[test]
fn an_annulus_keeps_both_boundary_loops() {
    let input = mesh(&annulus(0.4, 12, 64));
    let l = 0.04;
    let result = run(&input, l);
    let out = &result.remeshed.mesh;
    assert_eq!(describe(out), "genus 0 and 2 boundary loops");
    assert!(!has_duplicate_vertex(out, 1e-3 * l));
    assert!(out.positions().iter().all(|p| p.z == 0.0));
    // Boundary vertices stay on their circles (they lie on the input's boundary chords).
    for v in out.vertices().filter(|&v| out.is_boundary_vertex(v)) {
        let r = out.position(v).coords.norm();
        assert!(
            r > 0.39 && r < 1.0 + 1e-12,
            "boundary vertex {v} at radius {r}"
        );
    }
}

#[test]
fn quality_measures_the_distance_between_parallel_planes_exactly() {
    let a = mesh(&grid(4, 4, Cells::Triangles));
    let b = mesh(&mapped(grid(7, 5, Cells::Triangles), |p| {
        Point3::new(p.x, p.y, 0.25)
    }));
    let q = quality::measure(&a, &b).unwrap();
    assert!((q.hausdorff - 0.25).abs() < 1e-15, "{}", q.hausdorff);
    assert!(
        (q.mean_distance - 0.25).abs() < 1e-15,
        "{}",
        q.mean_distance
    );
    assert!((q.mean_angle - 60.0).abs() < 1e-12);
    assert!((q.min_angle - (5.0f64 / 7.0).atan().to_degrees()).abs() < 1e-9);
}

#[test]
fn bad_options_get_errors_naming_the_option() {
    let input = mesh(&grid(4, 4, Cells::Triangles));
    let solvers: [&dyn Solver; 1] = [&Lscm];
    let cases = [
        (Resolution::EdgeLength(0.0), 30.0, "edge-length"),
        (Resolution::EdgeLength(-0.1), 30.0, "edge-length"),
        (Resolution::EdgeLength(f64::NAN), 30.0, "edge-length"),
        (Resolution::EdgeLength(f64::INFINITY), 30.0, "edge-length"),
        (Resolution::Vertices(2), 30.0, "vertices"),
        (Resolution::EdgeLength(0.1), 40.0, "min-angle"),
        (Resolution::EdgeLength(0.1), 0.0, "min-angle"),
        (Resolution::EdgeLength(0.1), f64::NAN, "min-angle"),
    ];
    for (resolution, min_angle, name) in cases {
        let options = RemeshOptions {
            resolution,
            min_angle,
            ..RemeshOptions::default()
        };
        match remesh(&input, &solvers, &options, &mut Context::new()) {
            Err(RemeshError::InvalidOption { option, .. }) => assert_eq!(option, name),
            other => panic!("{resolution:?}, {min_angle}: expected an option error, got {other:?}"),
        }
    }
    for tolerance in [0.0, -0.2, f64::NAN] {
        let options = RemeshOptions {
            feature_tolerance: tolerance,
            ..RemeshOptions::with_edge_length(0.1)
        };
        match remesh(&input, &solvers, &options, &mut Context::new()) {
            Err(RemeshError::InvalidOption { option, .. }) => {
                assert_eq!(option, "feature-tolerance")
            }
            other => panic!("tolerance {tolerance}: expected an option error, got {other:?}"),
        }
    }
}

#[test]
fn a_sphere_remeshed_through_its_spherical_map_in_two_charts() {
    // The icosphere's own vertices are its spherical map (up to the solver's Moebius
    // normalization), so both charts are stereographic images of round caps: the result
    // must close up along the shared loop, keep the sphere's shape to second order and
    // the angle limit.
    let input = mesh(&icosphere(5));
    let solvers: [&dyn Solver; 1] = [&Sphere];
    let l = 0.08;
    let result = remesh(
        &input,
        &solvers,
        &RemeshOptions::with_edge_length(l),
        &mut Context::new(),
    )
    .expect("a closed genus-0 surface is remeshed through its spherical map");
    let q = closes_up(&input, &result, l, "two-charts", "genus 0 and no boundary");
    assert!(q.min_angle > 20.0, "smallest angle {}", q.min_angle);
    let out = &result.remeshed.mesh;
    let worst = out
        .faces()
        .map(|f| (out.face_centroid(f).coords.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 0.5 * l * l,
        "a face centroid {worst} off the sphere"
    );
    for v in out.vertices() {
        let sp = result.remeshed.on_source[v.idx()];
        let gap = (sp.position(&input) - out.position(v)).norm();
        assert!(gap < 1e-12, "vertex {v} is {gap} from its surface point");
    }
    // Anything but a closed genus-0 surface is refused, naming its topology.
    let torus_mesh = mesh(&torus(24, 8, 1.0, 0.4, Cells::Triangles));
    let error = remesh(
        &torus_mesh,
        &solvers,
        &RemeshOptions::with_edge_length(0.2),
        &mut Context::new(),
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            RemeshError::Parameterizer {
                solver: "sphere",
                ..
            }
        ),
        "{error}"
    );
    assert!(error.to_string().contains("genus 1"), "{error}");
}

#[test]
fn two_components_are_refused() {
    let mut soup = grid(2, 2, Cells::Triangles);
    let offset = soup.positions.len() as u32;
    let far: Vec<_> = soup
        .positions
        .iter()
        .map(|p| p + Vector3::new(5.0, 0.0, 0.0))
        .collect();
    soup.positions.extend(far);
    let faces: Vec<Vec<u32>> = soup
        .faces()
        .map(|f| f.iter().map(|i| i + offset).collect())
        .collect();
    for f in faces {
        soup.push_face(&f);
    }
    let solvers: [&dyn Solver; 1] = [&Lscm];
    let error = remesh(
        &mesh(&soup),
        &solvers,
        &RemeshOptions::with_edge_length(0.2),
        &mut Context::new(),
    )
    .unwrap_err();
    assert!(
        matches!(error, RemeshError::Components { components: 2 }),
        "{error}"
    );
}

#[test]
fn a_size_that_would_make_too_many_vertices_is_refused_before_any_work() {
    // The unit disk (area about pi): at L = 0.0426 an equilateral mesh has
    // 2 A / (sqrt(3) L^2) = 2000 vertices, twice the allowed 1000.
    let input = mesh(&disk(3));
    let area = input.total_area();
    let solvers: [&dyn Solver; 1] = [&Lscm];
    let run = |options: &RemeshOptions| {
        remesh(&input, &solvers, options, &mut Context::new())
            .map(|r| r.remeshed.mesh.vertex_count())
    };
    let l = (2.0 * area / (3f64.sqrt() * 2000.0)).sqrt();
    let options = RemeshOptions {
        max_vertices: 1000,
        ..RemeshOptions::with_edge_length(l)
    };
    match run(&options) {
        Err(RemeshError::TooFine {
            estimate,
            max_vertices,
            suggested,
            ..
        }) => {
            assert!((estimate - 2000.0).abs() < 1e-6, "{estimate}");
            assert_eq!(max_vertices, 1000);
            // The suggested length makes exactly the allowed count.
            assert!(
                (suggested / (l * 2f64.sqrt()) - 1.0).abs() < 1e-12,
                "{suggested}"
            );
        }
        other => panic!("{other:?}"),
    }
    // Half the count passes the check and is remeshed.
    let fits = RemeshOptions {
        max_vertices: 1000,
        ..RemeshOptions::with_edge_length(l * 2f64.sqrt() * 1.05)
    };
    assert!(run(&fits).is_ok_and(|n| n <= 1000));
    // Far too small (these ran for minutes or aborted on a 150 GB allocation).
    for options in [
        RemeshOptions::with_edge_length(1e-9),
        RemeshOptions::with_edge_length(1e-300),
        RemeshOptions {
            resolution: Resolution::Vertices(1_000_000_000_000),
            ..RemeshOptions::default()
        },
    ] {
        assert!(
            matches!(run(&options), Err(RemeshError::TooFine { .. })),
            "{options:?}"
        );
    }
}

#[test]
fn every_input_vertex_of_a_rough_surface_stays_within_the_feature_tolerance() {
    // Ripples of wavelength 0.07 and height up to 0.02 (0.4 h) on a flat boundary: a
    // chord of length h = 0.05 cuts them off unless their vertices are inserted (an
    // input vertex farther than t h from the interpolated result over its parameter
    // point is inserted and held, t the feature tolerance, 0.2 by default). The
    // smoothing moves the neighbours of the inserted vertices, so the check must hold
    // for the final mesh, not only where the size passes end.
    let input = mesh(&mapped(
        jittered_grid(48, 48, Cells::Triangles, 0.3, 11),
        |p| {
            let bump = 16.0 * p.x * (1.0 - p.x) * p.y * (1.0 - p.y);
            let ripple = (90.0 * p.x + 1.3).sin() * (90.0 * p.y + 0.7).sin();
            Point3::new(p.x, p.y, 0.02 * bump * ripple)
        },
    ));
    let l = 0.05;
    let farthest = |tolerance: f64| {
        let solvers: [&dyn Solver; 2] = [&Lscm, &Tutte];
        let options = RemeshOptions {
            feature_tolerance: tolerance,
            ..RemeshOptions::with_edge_length(l)
        };
        let result = remesh(&input, &solvers, &options, &mut Context::new()).unwrap();
        let out = &result.remeshed.mesh;
        let index = beltrami_spatial::SurfaceIndex::new(out).unwrap();
        input
            .vertices()
            .filter(|&v| !input.is_boundary_vertex(v))
            .map(|v| index.locate(&input.position(v)).unwrap().distance)
            .fold(0.0, f64::max)
            / l
    };
    for tolerance in [0.2, 0.1] {
        let worst = farthest(tolerance);
        assert!(
            worst <= tolerance * (1.0 + 1e-9),
            "tolerance {tolerance}: an input vertex is {worst} h from the result"
        );
    }
    // Without features the ripples are cut off.
    let worst = farthest(f64::INFINITY);
    assert!(
        worst > 0.2,
        "no features: the farthest input vertex is {worst} h away"
    );
}

#[test]
fn the_corners_of_a_boundary_are_kept() {
    // A jittered square (its boundary stays on the square) at an edge length that
    // divides none of its sides: equal-length samples along the whole loop would cut the
    // corners off by up to 0.06, more than the feature tolerance 0.2 L.
    let square = mesh(&jittered_grid(10, 10, Cells::Triangles, 0.3, 3));
    let l = 0.13;
    let out = run(&square, l).remeshed.mesh;
    for corner in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        let c = Point3::new(corner.0, corner.1, 0.0);
        let nearest = out
            .positions()
            .iter()
            .map(|p| (p - c).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1e-12,
            "corner {corner:?}: nearest vertex at {nearest}"
        );
    }
    let q = quality::measure(&square, &out).unwrap();
    assert!(
        q.hausdorff < 1e-12,
        "a planar region: Hausdorff {}",
        q.hausdorff
    );
}

/// An edge length too long for a closed surface is named as such, with a length that
/// works, instead of "face 3 duplicates face 0" (torus) or "the mesh has no faces"
/// (sphere).
#[test]
fn an_edge_length_too_long_for_the_surface_is_refused_with_one_that_works() {
    let solvers: [&dyn Solver; 2] = [&Lscm, &Tutte];
    for input in [
        mesh(&icosphere(3)),
        mesh(&torus(40, 20, 1.0, 0.4, Cells::Triangles)),
    ] {
        let options = RemeshOptions::with_edge_length(1e9);
        match remesh(&input, &solvers, &options, &mut Context::new()) {
            Err(RemeshError::TooCoarse {
                edge_length,
                suggested,
                ..
            }) => {
                assert_eq!(edge_length, 1e9);
                let result = run(&input, suggested);
                assert_eq!(describe(&result.remeshed.mesh), describe(&input));
            }
            other => panic!("expected TooCoarse, got {other:?}"),
        }
    }
}
