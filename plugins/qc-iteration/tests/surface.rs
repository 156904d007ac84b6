//! The quaternionic QC iteration into R^3 (Gruber-Aulisa 2022, section 5) against an
//! exact Teichmueller map on a curved surface: the map of a cylinder patch onto a
//! coaxial cylinder that keeps every normal and develops to an affine map. An affine
//! map is the Teichmueller map of its own boundary values (constant mu, the quadratic
//! differential dz^2), the patch is developable, and the map keeps the normals, so the
//! quaternionic problem has it as its exact answer: the iteration finds its `k` and
//! its vertices, closer as the mesh is refined.

use beltrami_core::{
    Constraint, Context, Goal, Map, OptionValue, Pin, Position, Problem, Solver, Stop, Target,
};
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{Mesh, Point3};
use beltrami_qc_iteration::QcIteration;
use num_complex::Complex64;

const A: f64 = 1.3;
const B: f64 = 0.4;
const C: f64 = 0.8;

/// The patch `theta in [0, 1.2]`, `z in [0, 1]` of the unit cylinder (a jittered grid
/// rolled up) and the exact map: radius `A`, height `B theta + C z`.
fn patch(n: usize, cells: Cells) -> (Mesh, Vec<Point3<f64>>) {
    let mut soup = jittered_grid(n, n, cells, 0.3, 7);
    let developed: Vec<(f64, f64)> = soup.positions.iter().map(|p| (1.2 * p.x, p.y)).collect();
    for (p, &(s, t)) in soup.positions.iter_mut().zip(&developed) {
        *p = Point3::new(s.cos(), s.sin(), t);
    }
    let exact = developed
        .iter()
        .map(|&(s, t)| Point3::new(A * s.cos(), A * s.sin(), B * s + C * t))
        .collect();
    (Mesh::from_soup(&soup).unwrap(), exact)
}

/// `k`, the largest vertex error, the flips and whether it converged.
fn run(n: usize, cells: Cells) -> (f64, f64, usize, bool) {
    let (mesh, exact) = patch(n, cells);
    let mut problem = Problem::new(&mesh, Target::Surface);
    problem.goal = Goal::Extremal;
    problem.constraints.hold_boundary(&mesh, &exact);
    problem
        .options
        .set("max-iters", OptionValue::Int(5000))
        .set("tolerance", OptionValue::Float(1e-8));
    let solution = QcIteration.solve(&problem, &mut Context::new()).unwrap();
    let Some(Map::Spatial(image)) = solution.map() else {
        panic!("expected a map into space");
    };
    let error = image
        .iter()
        .zip(&exact)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    let stats = solution.metrics.distortion.unwrap();
    (
        solution.metrics.k.unwrap(),
        error,
        stats.flipped,
        matches!(solution.metrics.stop, Some(Stop::Converged { .. })),
    )
}

#[test]
fn the_iteration_finds_the_affine_map_of_a_developable_patch() {
    let k_exact = (Complex64::new(A - C, B) / Complex64::new(A + C, B)).norm();
    for cells in [Cells::Triangles, Cells::Quads] {
        let mut last: Option<f64> = None;
        for n in [6, 12, 24] {
            let (k, error, flips, converged) = run(n, cells);
            println!("{cells:?} {n}x{n}: k {k:.6} (exact {k_exact:.6}), vertex error {error:.3e}");
            assert!(converged, "{cells:?} {n}: not converged");
            assert_eq!(flips, 0);
            assert!(
                (k - k_exact).abs() < 0.01 * k_exact,
                "k {k}, exact {k_exact}"
            );
            if let Some(e) = last {
                assert!(error < 0.5 * e, "{cells:?}: vertex error {error} after {e}");
            }
            last = Some(error);
        }
    }
}

#[test]
fn a_closed_surface_needs_a_pin_with_the_area_constraint() {
    let mesh = Mesh::from_soup(&beltrami_mesh::primitives::icosphere(2)).unwrap();
    let mut problem = Problem::new(&mesh, Target::Surface);
    problem.goal = Goal::Extremal;
    problem.constraints.push(Constraint::Area);
    let error = QcIteration.check(&problem).unwrap_err().to_string();
    assert!(error.contains("pin a vertex"), "{error}");
    problem.constraints.push(Constraint::Pin(Pin {
        vertex: beltrami_mesh::VertexId(0),
        position: Some(Position::Spatial(mesh.position(beltrami_mesh::VertexId(0)))),
    }));
    QcIteration.check(&problem).unwrap();
}
