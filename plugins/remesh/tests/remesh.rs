//! The `remesh` solver through a registry: both methods give what the library gives
//! (the same meshes, bit for bit), the new mesh has the asked edge length and each
//! vertex's point on the source, and options the method does not read, a missing size
//! or an unknown parameterizer are refused before any work with typed errors naming
//! them.

use beltrami_core::{
    Context, Output, Problem, Registry, RemeshSummary, Remeshed, Solution, SolverError, Target,
};
use beltrami_mesh::primitives::{Cells, disk, grid, icosphere};
use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_qc_iteration::QcIteration;
use beltrami_remesh::in_place::{InPlaceOptions, remesh_in_place};
use beltrami_remesh::{RemeshError, RemeshOptions, param, remesh};
use beltrami_remesh_solver::RemeshOptionError;

/// The solvers `remesh` needs (the parameterizers of `init` and the QC iteration) and
/// `remesh` itself, built by this same function.
fn solvers() -> Registry {
    let mut registry = Registry::new();
    beltrami_init::register(&mut registry);
    beltrami_qc_iteration::register(&mut registry);
    beltrami_remesh_solver::register(&mut registry, solvers);
    registry
}

/// The upper unit hemisphere `z = sqrt(1 - x^2 - y^2)` over the generated unit disk of
/// level 4 (1024 faces).
fn hemisphere() -> Mesh {
    let mut soup = disk(4);
    for p in &mut soup.positions {
        p.z = (1.0 - p.x * p.x - p.y * p.y).max(0.0).sqrt();
    }
    Mesh::from_soup(&soup).unwrap()
}

/// Option values by name, as text.
type Values<'a> = &'a [(&'a str, &'a str)];

/// A remeshing problem of `mesh` with the option values `options`.
fn problem<'a>(mesh: &'a Mesh, options: Values<'_>) -> Problem<'a> {
    let mut problem = Problem::new(mesh, Target::Surface);
    for (name, value) in options {
        problem.options.set_text(name, value);
    }
    problem
}

fn solve(mesh: &Mesh, options: Values<'_>) -> Result<Solution, SolverError> {
    let registry = solvers();
    let solver = registry.get("remesh").unwrap();
    solver.solve(&problem(mesh, options), &mut Context::new())
}

fn new_mesh(solution: &Solution) -> &Remeshed {
    match &solution.output {
        Output::Mesh(remeshed) => remeshed,
        Output::Map(_) => panic!("remesh gave a map"),
    }
}

/// The mean edge length of `mesh`.
fn mean_edge(mesh: &Mesh) -> f64 {
    let lengths = mesh.edge_lengths();
    lengths.iter().sum::<f64>() / lengths.len() as f64
}

/// Every vertex of `remeshed` lies at its point on `source`, to `tolerance`.
fn assert_on_source(source: &Mesh, remeshed: &Remeshed, tolerance: f64) {
    assert_eq!(remeshed.on_source.len(), remeshed.mesh.vertex_count());
    for (p, point) in remeshed.mesh.positions().iter().zip(&remeshed.on_source) {
        let (v, n) = source.face_vertex_array(point.face);
        let on: Vector3<f64> = (0..n)
            .map(|i| source.position(v[i]).coords * point.coords[i])
            .sum();
        assert!((p.coords - on).norm() < tolerance, "{p} vs {on}");
    }
}

/// The refusal of `result` as the solver's typed option error.
fn option_error(result: Result<impl Sized, SolverError>) -> RemeshOptionError {
    match result {
        Err(SolverError::Plugin { solver, error }) => {
            assert_eq!(solver, "remesh");
            match error.downcast::<RemeshOptionError>() {
                Ok(error) => *error,
                Err(other) => panic!("not an option error: {other}"),
            }
        }
        Err(other) => panic!("not the plugin's error: {other}"),
        Ok(_) => panic!("accepted"),
    }
}

#[test]
fn the_registered_solver_remeshes_a_hemisphere_at_the_asked_edge_length() {
    let mesh = hemisphere();
    for l in [0.1, 0.05] {
        let solution = solve(&mesh, &[("edge-length", &l.to_string())]).unwrap();
        let remeshed = new_mesh(&solution);
        let ratio = mean_edge(&remeshed.mesh) / l;
        assert!((ratio - 1.0).abs() < 0.1, "at {l}: mean edge {ratio} L");
        assert_eq!(
            beltrami_core::topology::describe(&remeshed.mesh),
            beltrami_core::topology::describe(&mesh)
        );
        assert_on_source(&mesh, remeshed, 1e-12);
        let Some(RemeshSummary::Param(summary)) = &solution.extras.remesh else {
            panic!("no summary of method param");
        };
        assert_eq!((summary.parameterizer, summary.opening), ("lscm", "uncut"));
        assert_eq!(summary.edge_length, l);
        assert_eq!(summary.component, None);
        assert!(summary.components.is_empty());
        let stages: Vec<&str> = solution
            .report
            .timings
            .iter()
            .map(|(s, _)| s.as_str())
            .collect();
        assert_eq!(stages, ["chart", "parameterize", "triangulate", "assemble"]);
    }
}

#[test]
fn method_param_gives_the_librarys_mesh_bit_for_bit() {
    let sphere = Mesh::from_soup(&icosphere(3)).unwrap();
    let solution = solve(
        &sphere,
        &[
            ("vertices", "600"),
            ("size-field", "curvature"),
            ("min-angle", "25"),
        ],
    )
    .unwrap();
    let registry = solvers();
    let chosen = param::chosen(&registry, &sphere, "auto").unwrap();
    let options = RemeshOptions {
        resolution: beltrami_remesh::Resolution::Vertices(600),
        size_field: beltrami_remesh::SizeField::Curvature,
        min_angle: 25.0,
        ..RemeshOptions::default()
    };
    let direct = remesh(&sphere, &chosen, &options, &mut Context::new()).unwrap();
    let remeshed = new_mesh(&solution);
    assert_eq!(remeshed.mesh.positions(), direct.remeshed.mesh.positions());
    assert!(remeshed.mesh.faces().all(|f| {
        remeshed
            .mesh
            .face_vertices(f)
            .eq(direct.remeshed.mesh.face_vertices(f))
    }));
    assert_eq!(remeshed.on_source, direct.remeshed.on_source);
}

#[test]
fn method_qc_angles_gives_the_librarys_moved_vertices() {
    let sphere = Mesh::from_soup(&icosphere(2)).unwrap();
    let solution = solve(
        &sphere,
        &[
            ("method", "qc-angles"),
            ("max-iters", "3"),
            ("reference", "equiangular"),
        ],
    )
    .unwrap();
    let options = InPlaceOptions {
        max_iters: 3,
        reference: beltrami_remesh::reference_angles::Reference::Equiangular,
        ..InPlaceOptions::default()
    };
    let direct = remesh_in_place(&sphere, &QcIteration, &options, &mut Context::new()).unwrap();
    let remeshed = new_mesh(&solution);
    assert_eq!(remeshed.mesh.positions(), direct.mesh.positions());
    // Projected onto the source: each vertex is its own point on it.
    assert_on_source(&sphere, remeshed, 1e-12);
    let Some(RemeshSummary::InPlace(summary)) = &solution.extras.remesh else {
        panic!("no summary of method qc-angles");
    };
    assert_eq!(
        (summary.reference, summary.constraint),
        ("equiangular", "normal")
    );
    assert_eq!(summary.flipped, direct.flipped);
    assert_eq!(
        solution.metrics.iterations,
        direct.solution.metrics.iterations
    );
    assert_eq!(solution.metrics.k, direct.solution.metrics.k);
    assert_eq!(solution.report.solver, "remesh");
}

#[test]
fn options_of_the_other_method_are_refused_before_any_work_naming_the_option() {
    let mesh = hemisphere();
    let registry = solvers();
    let solver = registry.get("remesh").unwrap();
    let cases: [(Values<'_>, &str, &str); 4] = [
        (
            &[("method", "qc-angles"), ("min-angle", "25")],
            "min-angle",
            "qc-angles",
        ),
        (
            &[("method", "qc-angles"), ("edge-length", "0.1")],
            "edge-length",
            "qc-angles",
        ),
        (
            &[("edge-length", "0.1"), ("reference", "equiangular")],
            "reference",
            "param",
        ),
        (
            &[("edge-length", "0.1"), ("project", "false")],
            "project",
            "param",
        ),
    ];
    for (options, option, method) in cases {
        let problem = problem(&mesh, options);
        let expected = RemeshOptionError::OtherMethod {
            option,
            method,
            of: if method == "param" {
                "qc-angles"
            } else {
                "param"
            },
        };
        assert_eq!(
            option_error(solver.check(&problem)),
            expected,
            "{options:?}"
        );
        assert_eq!(
            option_error(solver.solve(&problem, &mut Context::new())),
            expected,
            "{options:?}"
        );
        let refused = beltrami_remesh_solver::check_options(&problem.options);
        assert_eq!(option_error(refused), expected, "{options:?}");
        assert!(expected.to_string().contains(&format!("option `{option}`")));
    }
}

#[test]
fn method_param_needs_one_size_and_positive_values() {
    let mesh = hemisphere();
    assert_eq!(option_error(solve(&mesh, &[])), RemeshOptionError::NoSize);
    assert_eq!(
        option_error(solve(&mesh, &[("edge-length", "0.1"), ("vertices", "500")])),
        RemeshOptionError::TwoSizes
    );
    assert_eq!(
        option_error(solve(&mesh, &[("method", "qc-angles"), ("tolerance", "0")])),
        RemeshOptionError::Value {
            option: "tolerance",
            got: 0.0,
            expected: "a positive number"
        }
    );
    // The library's own checks, typed: an edge length of 0 names its option.
    let Err(SolverError::Plugin { error, .. }) = solve(&mesh, &[("edge-length", "0")]) else {
        panic!("an edge length of 0 was accepted");
    };
    assert!(matches!(
        error.downcast_ref::<RemeshError>(),
        Some(RemeshError::InvalidOption {
            option: "edge-length",
            ..
        })
    ));
    // A declared range: the core's option error.
    assert!(matches!(
        solve(&mesh, &[("edge-length", "0.1"), ("min-angle", "40")]),
        Err(SolverError::Option(_))
    ));
}

#[test]
fn an_unknown_parameterizer_and_a_mesh_in_pieces_are_refused_by_the_check() {
    let registry = solvers();
    let solver = registry.get("remesh").unwrap();
    let mesh = hemisphere();
    let error = solver
        .check(&problem(
            &mesh,
            &[("edge-length", "0.1"), ("param", "nosuch")],
        ))
        .unwrap_err();
    assert!(
        error.to_string().contains("no solver named `nosuch`"),
        "{error}"
    );
    // Two unit squares side by side: refused whole, remeshed each.
    let mut soup = grid(6, 6, Cells::Triangles);
    let square = soup.clone();
    let offset = soup.positions.len() as u32;
    soup.positions.extend(
        square
            .positions
            .iter()
            .map(|p| Point3::new(p.x + 2.0, p.y, p.z)),
    );
    for f in square.faces() {
        soup.push_face(&f.iter().map(|i| i + offset).collect::<Vec<_>>());
    }
    let pieces = Mesh::from_soup(&soup).unwrap();
    let Err(SolverError::Plugin { error, .. }) =
        solver.check(&problem(&pieces, &[("edge-length", "0.1")]))
    else {
        panic!("a mesh in pieces was accepted whole");
    };
    assert!(matches!(
        error.downcast_ref::<RemeshError>(),
        Some(RemeshError::Components { components: 2 })
    ));
    let each = solve(&pieces, &[("edge-length", "0.1"), ("components", "each")]).unwrap();
    let Some(RemeshSummary::Param(summary)) = &each.extras.remesh else {
        panic!("no summary");
    };
    assert_eq!(summary.components.len(), 2);
    assert_on_source(&pieces, new_mesh(&each), 1e-12);
    let largest = solve(
        &pieces,
        &[("edge-length", "0.1"), ("components", "largest")],
    )
    .unwrap();
    let Some(RemeshSummary::Param(summary)) = &largest.extras.remesh else {
        panic!("no summary");
    };
    assert_eq!(summary.component, Some(0));
    // The points of the component remeshed alone are on the whole source.
    assert_on_source(&pieces, new_mesh(&largest), 1e-12);
    let input = beltrami_remesh_solver::remeshed_input(&pieces, summary).unwrap();
    assert_eq!(input.face_count(), square.face_count());
}

#[test]
fn a_problem_onto_another_target_is_refused() {
    let registry = solvers();
    let solver = registry.get("remesh").unwrap();
    let mesh = hemisphere();
    let mut problem = problem(&mesh, &[("edge-length", "0.1")]);
    problem.target = Target::Disk;
    let error = solver.check(&problem).unwrap_err();
    assert!(matches!(error, SolverError::Unsupported { .. }), "{error}");
}
