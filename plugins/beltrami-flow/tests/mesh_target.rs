//! The flow onto target meshes: the map stays on the target, no face flips, the error
//! falls, boundaries slide on the target's boundary and feature curves on their chain.

mod common;

use beltrami_core::OptionValue;
use beltrami_core::{Context, Curve, Goal, Map, Problem, Solver, Target};
use beltrami_flow::BeltramiFlow;
use beltrami_mesh::primitives;
use beltrami_mesh::{Mesh, Point3, PolygonSoup, SurfacePoint, VertexId};
use beltrami_spatial::SurfaceIndex;

/// `soup` with every vertex lifted to `z = height(x, y)`.
fn lifted(mut soup: PolygonSoup, height: impl Fn(f64, f64) -> f64) -> Mesh {
    for p in &mut soup.positions {
        p.z = height(p.x, p.y);
    }
    Mesh::from_soup(&soup).unwrap()
}

/// The map of a graph over the unit disk onto another one by vertical projection: each
/// source vertex goes to the target point above the same `(x, y)`.
fn vertical(source: &Mesh, target: &Mesh) -> Vec<SurfacePoint> {
    let mut flat = PolygonSoup::new(
        target
            .positions()
            .iter()
            .map(|p| Point3::new(p.x, p.y, 0.0))
            .collect(),
    );
    for f in target.faces() {
        let v: Vec<u32> = target.face_vertices(f).map(|v| v.0).collect();
        flat.push_face(&v);
    }
    let flat = Mesh::from_soup(&flat).unwrap();
    let index = SurfaceIndex::new(&flat).unwrap();
    source
        .positions()
        .iter()
        .map(|p| index.locate(&Point3::new(p.x, p.y, 0.0)).unwrap().point)
        .collect()
}

fn distance_to(target: &Mesh, p: &Point3<f64>) -> f64 {
    SurfaceIndex::new(target)
        .unwrap()
        .locate(p)
        .unwrap()
        .distance
}

#[test]
fn conformal_flow_between_two_disk_surfaces() {
    let source = lifted(primitives::disk(4), |x, y| 0.4 * (x * x + y * y));
    let target = lifted(primitives::disk(5), |x, y| 0.3 * (2.0 * x).sin() * y);
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    problem.initial = Some(Map::OnMesh(vertical(&source, &target)));
    problem.goal = Goal::Conformal { p: 2.0 };
    problem.options.set("tolerance", OptionValue::Float(1e-7));
    let solution = BeltramiFlow.solve(&problem, &mut Context::new()).unwrap();
    let Map::OnMesh(points) = solution.map().expect("a map") else {
        panic!("a map onto the target mesh")
    };
    assert_eq!(solution.metrics.flipped(), Some(0));
    let history = &solution.metrics.energy_history;
    assert!(*history.last().unwrap() < 0.5 * history[0]);
    let index = SurfaceIndex::new(&target).unwrap();
    let boundary = target.boundary_loop_list()[0].vertices.clone();
    for v in source.vertices() {
        let p = points[v.idx()];
        p.validate(&target).unwrap();
        let q = p.position(&target);
        assert!(index.locate(&q).unwrap().distance < 1e-12);
        if source.is_boundary_vertex(v) {
            // On the target's boundary polyline.
            let d = boundary
                .iter()
                .zip(boundary.iter().cycle().skip(1))
                .map(|(&a, &b)| {
                    let (a, b) = (target.position(a), target.position(b));
                    let t = ((q - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                    (a + t * (b - a) - q).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-12, "boundary vertex {v} off the boundary by {d}");
        }
    }
}

#[test]
fn feature_curves_slide_on_their_chain_with_ends_fixed() {
    let source = lifted(primitives::disk(4), |x, y| 0.2 * x * y);
    let target = lifted(primitives::disk(5), |x, y| 0.2 * (x * x - y * y));
    // The vertices on the real axis between -0.5 and 0.5, in order, in both meshes (the
    // disks are nested refinements, so the source's lie on the target's).
    let chain = |mesh: &Mesh| {
        let mut v: Vec<VertexId> = mesh
            .vertices()
            .filter(|&v| {
                let p = mesh.position(v);
                p.y.abs() < 1e-12 && p.x.abs() <= 0.5 + 1e-12
            })
            .collect();
        v.sort_by(|&a, &b| mesh.position(a).x.total_cmp(&mesh.position(b).x));
        v
    };
    let (source_chain, target_chain) = (chain(&source), chain(&target));
    assert!(source_chain.len() >= 5 && target_chain.len() > source_chain.len());
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    let start = vertical(&source, &target);
    problem.initial = Some(Map::OnMesh(start.clone()));
    problem.constraints = vec![Curve::open(source_chain.clone(), target_chain.clone())].into();
    let solution = BeltramiFlow.solve(&problem, &mut Context::new()).unwrap();
    let Map::OnMesh(points) = solution.map().expect("a map") else {
        panic!()
    };
    assert_eq!(solution.metrics.flipped(), Some(0));
    let polyline: Vec<Point3<f64>> = target_chain.iter().map(|&v| target.position(v)).collect();
    for (k, &v) in source_chain.iter().enumerate() {
        let q = points[v.idx()].position(&target);
        if k == 0 || k + 1 == source_chain.len() {
            assert!(
                (q - start[v.idx()].position(&target)).norm() < 1e-12,
                "ends stay"
            );
        } else {
            let d = polyline
                .windows(2)
                .map(|w| {
                    let t = ((q - w[0]).dot(&(w[1] - w[0])) / (w[1] - w[0]).norm_squared())
                        .clamp(0.0, 1.0);
                    (w[0] + t * (w[1] - w[0]) - q).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-12, "vertex {v} off the curve by {d}");
        }
    }
    assert!(distance_to(&target, &points[0].position(&target)) < 1e-12);
}

/// An icosphere, an ellipsoid mesh (a finer icosphere scaled by `(1, 0.8, 0.6)`), and a
/// start: the same scaling of the source, then the closest point on the target.
fn sphere_onto_ellipsoid() -> (Mesh, Mesh, Vec<SurfacePoint>) {
    let source = Mesh::from_soup(&primitives::icosphere(3)).unwrap();
    let mut soup = primitives::icosphere(4);
    for p in &mut soup.positions {
        p.y *= 0.8;
        p.z *= 0.6;
    }
    let target = Mesh::from_soup(&soup).unwrap();
    let index = SurfaceIndex::new(&target).unwrap();
    let start = source
        .positions()
        .iter()
        .map(|p| {
            index
                .locate(&Point3::new(p.x, 0.8 * p.y, 0.6 * p.z))
                .unwrap()
                .point
        })
        .collect();
    (source, target, start)
}

#[test]
fn sphere_onto_an_ellipsoid_mesh() {
    let (source, target, start) = sphere_onto_ellipsoid();
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    problem.initial = Some(Map::OnMesh(start));
    problem.options.set("tolerance", OptionValue::Float(1e-7));
    let solution = BeltramiFlow.solve(&problem, &mut Context::new()).unwrap();
    assert_eq!(solution.metrics.flipped(), Some(0));
    let history = &solution.metrics.energy_history;
    assert!(*history.last().unwrap() < 0.5 * history[0]);

    // Topology mismatch: a disk onto the ellipsoid.
    let disk = Mesh::from_soup(&primitives::disk(2)).unwrap();
    let mut problem = Problem::new(&disk, Target::Mesh(&target));
    problem.initial = Some(Map::Spatial(disk.positions().to_vec()));
    let error = BeltramiFlow.check(&problem).unwrap_err().to_string();
    assert!(error.contains("differ in topology"), "{error}");
}

#[test]
fn landmarks_pull_their_vertex_onto_the_goal() {
    let (source, target, start) = sphere_onto_ellipsoid();
    // Source vertex 0 goes to a target vertex about 0.15 away from where it starts.
    let from = start[0].position(&target);
    let goal_vertex = target
        .vertices()
        .min_by(|&a, &b| {
            let d = |v: VertexId| ((target.position(v) - from).norm() - 0.15).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let goal = target.position(goal_vertex);
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    problem.initial = Some(Map::OnMesh(start));
    problem
        .constraints
        .push(beltrami_core::Constraint::Landmark(
            beltrami_core::Landmark {
                vertex: VertexId(0),
                position: beltrami_core::Position::Spatial(goal),
            },
        ));
    problem.options.set("tolerance", OptionValue::Float(1e-9));
    let solution = BeltramiFlow.solve(&problem, &mut Context::new()).unwrap();
    let Map::OnMesh(points) = solution.map().expect("a map") else {
        panic!()
    };
    assert_eq!(solution.metrics.flipped(), Some(0));
    let reached = points[0].position(&target);
    assert!(
        (reached - goal).norm() < 1e-9,
        "{}",
        (reached - goal).norm()
    );
}

#[test]
fn a_curve_must_follow_target_edges() {
    let (source, target, start) = sphere_onto_ellipsoid();
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    problem.initial = Some(Map::OnMesh(start));
    // Vertices 0 and 3 of the icosahedron are antipodal: no edge joins them.
    problem.constraints = vec![Curve::open(
        vec![VertexId(0), VertexId(11)],
        vec![VertexId(0), VertexId(3)],
    )]
    .into();
    let message = BeltramiFlow.check(&problem).unwrap_err().to_string();
    assert!(message.contains("not joined by an edge"), "{message}");
}
