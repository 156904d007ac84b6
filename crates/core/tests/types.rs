//! Core's types on their own: constraint validation, option declarations and ranges,
//! the capability check from `Accepts`, the shared validation of `check` and `solve`,
//! and error sources across crates.

use std::error::Error as _;
use std::sync::atomic::{AtomicUsize, Ordering};

use beltrami_core::{
    Accepts, Constraint, ConstraintError, ConstraintKind, Constraints, Context, Curve, Direction,
    Element, Goal, GoalKind, Landmark, LoopMatch, Map, OptionError, OptionKind, OptionSpec,
    OptionValue, Options, Pin, PlanarBoundary, Position, Problem, Report, Settings, Slide,
    Solution, Solver, SolverError, SolverInfo, Target, TargetKind, Topology,
};
use beltrami_fem::{BeltramiField, FieldError, Frame};
use beltrami_mesh::primitives::{Cells, grid, icosphere};
use beltrami_mesh::{HalfedgeId, Mesh, Point3, Vector3, VertexId};
use num_complex::Complex64;

fn square() -> Mesh {
    Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap()
}

fn pin(v: u32) -> Constraint {
    Constraint::Pin(Pin {
        vertex: VertexId(v),
        position: None,
    })
}

fn validate(constraints: Vec<Constraint>, mesh: &Mesh) -> Result<(), ConstraintError> {
    constraints
        .into_iter()
        .collect::<Constraints>()
        .validate(mesh, None)
}

#[test]
fn well_formed_constraints_pass() {
    let mesh = square();
    let angles = vec![std::f64::consts::FRAC_PI_3; mesh.halfedge_count()];
    let all = vec![
        pin(0),
        Constraint::Pin(Pin {
            vertex: VertexId(1),
            position: Some(Position::Planar(Complex64::new(1.0, 0.0))),
        }),
        Constraint::Landmark(Landmark {
            vertex: VertexId(2),
            position: Position::Spatial(Point3::new(0.0, 1.0, 2.0)),
        }),
        Constraint::Slide(Slide {
            vertex: VertexId(3),
            direction: Direction::Spatial(Vector3::new(0.0, 0.0, 1.0)),
        }),
        Constraint::Curve(Curve::open(
            vec![VertexId(4), VertexId(5)],
            vec![VertexId(4), VertexId(5)],
        )),
        Constraint::Curve(Curve {
            source: vec![VertexId(0), VertexId(1), VertexId(5)],
            target: vec![VertexId(0), VertexId(1), VertexId(5)],
            closed: true,
        }),
        Constraint::Normal { weight: 0.5 },
        Constraint::Area,
        Constraint::ReferenceAngles(angles),
    ];
    let kinds: Vec<ConstraintKind> = all.iter().map(Constraint::kind).collect();
    assert_eq!(
        kinds,
        [
            ConstraintKind::Hold,
            ConstraintKind::Pin,
            ConstraintKind::Landmark,
            ConstraintKind::Slide,
            ConstraintKind::OpenCurve,
            ConstraintKind::ClosedCurve,
            ConstraintKind::Normal,
            ConstraintKind::Area,
            ConstraintKind::ReferenceAngles,
        ]
    );
    validate(all, &mesh).unwrap();
}

#[test]
fn malformed_constraints_name_the_constraint_and_the_element() {
    let mesh = square();
    let n = mesh.vertex_count();
    let e = validate(vec![pin(0), pin(n as u32)], &mesh).unwrap_err();
    assert_eq!(
        e,
        ConstraintError::MissingVertex {
            index: 1,
            kind: ConstraintKind::Hold,
            side: "source",
            vertex: VertexId(n as u32),
            count: n,
        }
    );
    assert!(e.to_string().contains(&format!("v{n}")), "{e}");

    let nan = Constraint::Pin(Pin {
        vertex: VertexId(2),
        position: Some(Position::Planar(Complex64::new(f64::NAN, 0.0))),
    });
    assert!(matches!(
        validate(vec![nan], &mesh),
        Err(ConstraintError::NonFinite {
            index: 0,
            what: "point",
            ..
        })
    ));

    let zero = Constraint::Slide(Slide {
        vertex: VertexId(2),
        direction: Direction::Planar(Complex64::new(0.0, 0.0)),
    });
    assert!(matches!(
        validate(vec![zero], &mesh),
        Err(ConstraintError::ZeroDirection { index: 0, .. })
    ));

    let twice = vec![
        pin(3),
        Constraint::Landmark(Landmark {
            vertex: VertexId(3),
            position: Position::Planar(Complex64::new(0.0, 0.0)),
        }),
    ];
    assert!(matches!(
        validate(twice, &mesh),
        Err(ConstraintError::Repeated {
            index: 1,
            first: 0,
            ..
        })
    ));

    let short = Constraint::Curve(Curve {
        source: vec![VertexId(0), VertexId(1)],
        target: vec![VertexId(0), VertexId(1)],
        closed: true,
    });
    assert!(matches!(
        validate(vec![short], &mesh),
        Err(ConstraintError::ShortChain {
            needed: 3,
            got: 2,
            ..
        })
    ));

    // A chain that comes back to a vertex: 0, 1, 2, 1, 3.
    let looped = Constraint::Curve(Curve {
        source: [0, 1, 2, 1, 3].map(VertexId).to_vec(),
        target: [0, 1, 2, 3, 4].map(VertexId).to_vec(),
        closed: false,
    });
    let e = validate(vec![looped], &mesh).unwrap_err();
    assert!(
        matches!(
            e,
            ConstraintError::RepeatedChainVertex {
                side: "source",
                first: 1,
                second: 3,
                ..
            }
        ),
        "{e}"
    );

    assert!(matches!(
        validate(vec![Constraint::Normal { weight: -1.0 }], &mesh),
        Err(ConstraintError::Weight { .. })
    ));
    assert!(matches!(
        validate(vec![Constraint::Normal { weight: 1e300 }], &mesh),
        Err(ConstraintError::Weight { .. })
    ));
    assert!(matches!(
        validate(vec![Constraint::ReferenceAngles(vec![1.0; 3])], &mesh),
        Err(ConstraintError::AngleCount { got: 3, .. })
    ));
    let mut angles = vec![1.0; mesh.halfedge_count()];
    let corner = mesh
        .face_halfedges(mesh.faces().nth(2).unwrap())
        .nth(1)
        .unwrap();
    angles[corner.idx()] = std::f64::consts::PI;
    let e = validate(vec![Constraint::ReferenceAngles(angles.clone())], &mesh).unwrap_err();
    assert_eq!(
        e,
        ConstraintError::Angle {
            index: 0,
            corner,
            angle: std::f64::consts::PI
        }
    );
    // Entries of boundary halfedges are not read.
    angles[corner.idx()] = 1.0;
    let boundary = (0..mesh.halfedge_count())
        .map(|h| HalfedgeId(h as u32))
        .find(|&h| mesh.is_boundary_halfedge(h))
        .unwrap();
    angles[boundary.idx()] = f64::NAN;
    validate(vec![Constraint::ReferenceAngles(angles)], &mesh).unwrap();

    // Loop matches need a target mesh and existing loops on both sides.
    let loops = vec![Constraint::LoopMatch(LoopMatch {
        source: 0,
        target: 1,
    })];
    assert!(matches!(
        validate(loops.clone(), &mesh),
        Err(ConstraintError::NoTargetMesh { index: 0, .. })
    ));
    let e = loops
        .into_iter()
        .collect::<Constraints>()
        .validate(&mesh, Some(&mesh))
        .unwrap_err();
    assert!(matches!(
        e,
        ConstraintError::MissingLoop {
            side: "target",
            boundary_loop: 1,
            count: 1,
            ..
        }
    ));
}

#[test]
fn curve_target_vertices_are_checked_on_the_target_mesh() {
    let source = square();
    let target = Mesh::from_soup(&icosphere(0)).unwrap();
    let big = VertexId(target.vertex_count() as u32);
    let curve: Constraints = vec![Curve::open(
        vec![VertexId(0), VertexId(1)],
        vec![VertexId(0), big],
    )]
    .into();
    let e = curve.validate(&source, Some(&target)).unwrap_err();
    assert!(
        matches!(e, ConstraintError::MissingVertex { side: "target", vertex, .. } if vertex == big),
        "{e}"
    );
    // The same id exists on the (larger) source, which is what a map of the surface into
    // itself checks against.
    curve.validate(&source, None).unwrap();
}

#[test]
fn target_vertex_landmarks_need_a_target_mesh_that_has_the_vertex() {
    let source = square();
    let target = Mesh::from_soup(&icosphere(0)).unwrap();
    let onto = |w: usize| -> Constraints {
        vec![Constraint::Landmark(Landmark {
            vertex: VertexId(4),
            position: Position::TargetVertex(VertexId(w as u32)),
        })]
        .into_iter()
        .collect()
    };
    let last = target.vertex_count() - 1;
    onto(last).validate(&source, Some(&target)).unwrap();
    assert!(matches!(
        onto(last).validate(&source, None),
        Err(ConstraintError::NoTargetMesh { index: 0, .. })
    ));
    let e = onto(last + 1).validate(&source, Some(&target)).unwrap_err();
    assert!(
        matches!(e, ConstraintError::MissingVertex { side: "target", vertex, .. } if vertex.idx() == last + 1),
        "{e}"
    );
    // The point of a target vertex is that vertex's position on the target, and none
    // without a target.
    let mark = Position::TargetVertex(VertexId(last as u32));
    assert_eq!(
        mark.point(Some(&target)),
        Some(target.position(VertexId(last as u32)))
    );
    assert_eq!(mark.point(None), None);
}

const SPECS: &[OptionSpec] = &[
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-6,
            min: 0.0,
            max: 1.0,
        },
        help: "a tolerance",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 10,
            min: 1,
            max: 100,
        },
        help: "iterations",
    },
    OptionSpec {
        name: "verbose",
        kind: OptionKind::Bool { default: false },
        help: "talk",
    },
    OptionSpec {
        name: "weights",
        kind: OptionKind::Choice {
            default: "uniform",
            choices: &["uniform", "cotan"],
        },
        help: "the weights (cotan: see harmonic)",
    },
];

fn resolve(set: &[(&str, OptionValue)]) -> Result<Settings, OptionError> {
    let mut options = Options::new();
    for (name, value) in set {
        options.set(name, value.clone());
    }
    Settings::resolve("demo", SPECS, &options)
}

#[test]
fn options_take_their_defaults() {
    let s = resolve(&[]).unwrap();
    assert_eq!(s.float("tolerance"), 1e-6);
    assert_eq!(s.int("max-iters"), 10);
    assert!(!s.flag("verbose"));
    assert_eq!(s.choice("weights"), "uniform");
    assert_eq!(s.iter().count(), SPECS.len());
}

#[test]
fn options_parse_text_and_accept_ints_for_floats() {
    let mut options = Options::new();
    options
        .set_text("tolerance", "1e-3")
        .set_text("max-iters", " 7 ")
        .set_text("verbose", "yes")
        .set_text("weights", "cotan");
    let s = Settings::resolve("demo", SPECS, &options).unwrap();
    assert_eq!(s.float("tolerance"), 1e-3);
    assert_eq!(s.int("max-iters"), 7);
    assert!(s.flag("verbose"));
    assert_eq!(s.choice("weights"), "cotan");
    // A later value of the same name replaces the earlier one.
    options.set("max-iters", OptionValue::Int(8));
    let s = Settings::resolve("demo", SPECS, &options).unwrap();
    assert_eq!(s.int("max-iters"), 8);
    let s = resolve(&[("tolerance", OptionValue::Int(1))]).unwrap();
    assert_eq!(s.float("tolerance"), 1.0);
}

#[test]
fn bad_options_are_named() {
    let e = resolve(&[("tolerence", OptionValue::Float(1.0))]).unwrap_err();
    assert!(matches!(&e, OptionError::Unknown { option, .. } if option == "tolerence"));
    assert!(
        e.to_string()
            .contains("tolerance, max-iters, verbose, weights"),
        "{e}"
    );

    for (name, value) in [
        ("tolerance", OptionValue::Float(2.0)),
        ("tolerance", OptionValue::Float(f64::NAN)),
        ("tolerance", OptionValue::Float(-1e-9)),
        ("max-iters", OptionValue::Int(0)),
        ("max-iters", OptionValue::Int(101)),
    ] {
        let e = resolve(&[(name, value.clone())]).unwrap_err();
        assert!(
            matches!(&e, OptionError::Range { option, .. } if *option == name),
            "{name} = {value}: {e}"
        );
    }
    let e = resolve(&[("max-iters", OptionValue::Float(2.5))]).unwrap_err();
    assert!(matches!(
        e,
        OptionError::Type {
            option: "max-iters",
            ..
        }
    ));
    assert!(
        e.to_string().contains("takes a whole number from ")
            && e.to_string().ends_with("got `2.5`"),
        "{e}"
    );
    let e = resolve(&[("max-iters", OptionValue::Choice("many".into()))]).unwrap_err();
    assert!(matches!(
        e,
        OptionError::Type {
            option: "max-iters",
            ..
        }
    ));
    let e = resolve(&[("verbose", OptionValue::Choice("maybe".into()))]).unwrap_err();
    assert!(matches!(
        e,
        OptionError::Type {
            option: "verbose",
            ..
        }
    ));
    assert!(
        e.to_string().contains("takes true or false, got `maybe`"),
        "{e}"
    );
    let e = resolve(&[("weights", OptionValue::Choice("mean".into()))]).unwrap_err();
    assert!(matches!(
        e,
        OptionError::Choice {
            option: "weights",
            ..
        }
    ));
    assert!(
        e.to_string().contains("uniform, cotan") && e.to_string().contains("see harmonic"),
        "{e}"
    );
    let e = resolve(&[("weights", OptionValue::Int(1))]).unwrap_err();
    assert!(matches!(
        e,
        OptionError::Type {
            option: "weights",
            ..
        }
    ));
}

/// A solver that counts its runs, to see what `check` and `solve` share.
struct Counting {
    runs: AtomicUsize,
}

const COUNTING_ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: &[Topology::Disk],
    targets: &[TargetKind::PlaneFree, TargetKind::Disk],
    goals: &[GoalKind::Conformal],
    constraints: &[ConstraintKind::Hold],
};

/// What [`Counting`] is: its name, one line on what it computes, what it accepts and
/// its options.
const COUNTING_INFO: SolverInfo = SolverInfo {
    name: "counting",
    description: "counts its runs",
    accepts: COUNTING_ACCEPTS,
    options: SPECS,
};

impl Solver for Counting {
    fn info(&self) -> &'static SolverInfo {
        &COUNTING_INFO
    }
    fn check_problem(&self, problem: &Problem<'_>, _: &Settings) -> Result<(), SolverError> {
        if matches!(problem.target, Target::Disk) {
            return Err(SolverError::Unsupported {
                solver: "counting",
                message: "the disk is refused by the solver's own check".into(),
            });
        }
        Ok(())
    }
    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        _: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        self.runs.fetch_add(1, Ordering::Relaxed);
        let z =
            vec![Complex64::new(settings.float("tolerance"), 0.0); problem.source.vertex_count()];
        Ok(Solution::from_map(Map::Planar(z), Report::new("counting")))
    }
}

#[test]
fn check_and_solve_share_one_validation_before_any_work() {
    let mesh = square();
    let solver = Counting {
        runs: AtomicUsize::new(0),
    };
    let refused = |problem: &Problem<'_>| {
        let checked = solver.check(problem).unwrap_err().to_string();
        let solved = solver
            .solve(problem, &mut Context::new())
            .unwrap_err()
            .to_string();
        assert_eq!(checked, solved);
        checked
    };
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Free));
    problem.options.set("tolerance", OptionValue::Float(5.0));
    assert!(refused(&problem).contains("`tolerance` must lie in [0, 1]"));
    problem.options = Options::new();
    problem.constraints.push(pin(1_000));
    assert!(refused(&problem).contains("constraint 0 (hold)"));
    problem.constraints = Constraints::new();
    problem.target = Target::Disk;
    assert!(refused(&problem).contains("solver's own check"));
    // The kinds outside `Accepts`, with the solver's own check silent.
    problem.target = Target::Sphere;
    assert!(refused(&problem).contains("target `sphere`; its targets: plane-free, disk"));
    problem.target = Target::Plane(PlanarBoundary::Free);
    problem.goal = Goal::Conformal { p: 4.0 };
    assert!(refused(&problem).contains("goal `conformal-lp`"));
    problem.goal = Goal::default();
    problem.constraints.push(Constraint::Area);
    assert!(
        refused(&problem)
            .contains("constraint 0 (area) is not one counting honours; it takes hold")
    );
    problem.constraints = Constraints::new();
    let sphere = Mesh::from_soup(&icosphere(0)).unwrap();
    let other = Problem::new(&sphere, Target::Plane(PlanarBoundary::Free));
    assert!(refused(&other).contains("the source is sphere (genus 0 and no boundary)"));
    let quads = Mesh::from_soup(&grid(2, 2, Cells::Quads)).unwrap();
    let other = Problem::new(&quads, Target::Plane(PlanarBoundary::Free));
    assert!(refused(&other).contains("is a quad; counting takes triangle"));
    assert_eq!(solver.runs.load(Ordering::Relaxed), 0, "nothing ran");

    problem.options.set_text("tolerance", "0.25");
    let solution = solver.solve(&problem, &mut Context::new()).unwrap();
    assert_eq!(solver.runs.load(Ordering::Relaxed), 1);
    assert_eq!(solution.planar().unwrap()[0], Complex64::new(0.25, 0.0));
    assert!(solution.metrics.flipped().is_none() && solution.extras.circles.is_none());
}

#[test]
fn topologies_are_classified() {
    let disk = square();
    assert_eq!(Topology::of(&disk), Topology::Disk);
    let sphere = Mesh::from_soup(&icosphere(1)).unwrap();
    assert_eq!(Topology::of(&sphere), Topology::Sphere);
    let torus = Mesh::from_soup(&beltrami_mesh::primitives::torus(
        8,
        6,
        2.0,
        0.5,
        Cells::Triangles,
    ))
    .unwrap();
    assert_eq!(Topology::of(&torus), Topology::Torus);
    // The lists solvers accept: every classified mesh is in ANY, the two components of
    // two disks are not CONNECTED, each connected one is.
    let two = Mesh::from_soup(&beltrami_mesh::PolygonSoup::from_triangles(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(3.0, 0.0, 0.0),
            Point3::new(4.0, 0.0, 0.0),
            Point3::new(3.0, 1.0, 0.0),
        ],
        &[[0, 1, 2], [3, 4, 5]],
    ))
    .unwrap();
    assert_eq!(Topology::of(&two), Topology::Components);
    for mesh in [&disk, &sphere, &torus, &two] {
        let topology = Topology::of(mesh);
        assert!(Topology::ANY.contains(&topology));
        assert_eq!(
            Topology::CONNECTED.contains(&topology),
            topology != Topology::Components
        );
    }
}

#[test]
fn errors_keep_their_sources_across_crates() {
    let mesh = square();
    // A field error from fem stays typed inside SolverError and is its source chain.
    let field = BeltramiField::new(Frame::Global, vec![Complex64::new(0.0, 0.0); 1]);
    let error: SolverError = field.check(mesh.face_count()).unwrap_err().into();
    assert!(matches!(
        error,
        SolverError::Field(FieldError::Length { .. })
    ));
    // A constraint error is the source of the solver error that carries it.
    let error = SolverError::Constraint {
        solver: "demo",
        error: ConstraintError::Weight {
            index: 2,
            weight: 0.0,
        },
    };
    let source = error.source().expect("a source");
    assert!(source.downcast_ref::<ConstraintError>().is_some());
    assert!(error.to_string().starts_with("demo: constraint 2 (normal)"));
    // Option errors convert with `?`.
    let from: SolverError = resolve(&[("nope", OptionValue::Bool(true))])
        .unwrap_err()
        .into();
    assert!(matches!(
        from,
        SolverError::Option(OptionError::Unknown { .. })
    ));
}
