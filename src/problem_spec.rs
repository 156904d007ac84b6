//! A mapping problem as a front end states it: the solver's name, the target and the
//! plane's boundary by name, the goal, the constraints and option values, with the
//! files and arrays behind them already read. [`ProblemSpec::problem`] is the one
//! translation of these words into a core [`Problem`] for the command line (`qc`,
//! `param`, `register`, and `batch`, whose jobs are command lines) and the Python
//! package (`beltrami.solve` and the named calls).
//!
//! It makes the choices that depend on the solver (the target of a solver that maps
//! onto one domain only, the plane's boundary when none is named, the extremal goal of
//! a solver that computes only extremal maps) and refuses, before any mesh is read
//! ([`ProblemSpec::check_words`]), words that the others make meaningless, so that no
//! front end ignores one silently. Errors name the words as the user wrote them:
//! `--boundary-map` on the command line, `boundary_map` in Python ([`Spelling`]).
//!
//! ```
//! use beltrami::problem_spec::{ProblemSpec, TargetName};
//! use beltrami::mesh::{Mesh, primitives};
//!
//! let disk = Mesh::from_soup(&primitives::disk(3)).unwrap();
//! let mut spec = ProblemSpec::new(TargetName::Disk);
//! spec.check_words().unwrap();
//! assert_eq!(spec.solver_name(), "beltrami-flow");
//! let registry = beltrami::registry();
//! let solver = registry.get(spec.solver_name()).unwrap();
//! let problem = spec.problem(&disk, None, solver).unwrap();
//! assert!(matches!(problem.target, beltrami::core::Target::Disk));
//! ```

use beltrami_core::{
    Constraint, Constraints, Features, Goal, GoalKind, Map, OptionValue, Options, PlanarBoundary,
    Position, Problem, Solver, Target, TargetKind,
};
use beltrami_fem::{BeltramiField, Expr};
use beltrami_mesh::{Mesh, Point3};
use num_complex::Complex64;
use thiserror::Error;

/// How a front end spells the words of a problem, for errors that name them as the
/// user wrote them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spelling {
    /// The command line: `--boundary-map`, `--target disk`.
    Flags,
    /// Python keywords: `boundary_map`, `target='disk'`.
    Keywords,
}

/// The words of a problem that a front end may get wrong together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Word {
    /// Where the map goes.
    Target,
    /// The plane's boundary condition.
    Boundary,
    /// The map whose boundary is held.
    BoundaryMap,
    /// The annulus's inner radius let free.
    FreeRadius,
    /// Pinned vertices.
    Pins,
    /// Landmarks of the four-point problem (boundary vertices onto the unit circle).
    Landmarks,
    /// The weight of the normal constraint.
    NormalConstraint,
    /// The area constraint.
    AreaConstraint,
    /// The Beltrami coefficient as an expression of `z`.
    MuExpr,
    /// The target mesh.
    TargetMesh,
}

impl Word {
    /// The command line's flag, without its dashes.
    fn flag(self) -> &'static str {
        match self {
            Word::Target => "target",
            Word::Boundary => "boundary",
            Word::BoundaryMap => "boundary-map",
            Word::FreeRadius => "free-radius",
            Word::Pins => "pin",
            Word::Landmarks => "landmarks",
            Word::NormalConstraint => "normal-constraint",
            Word::AreaConstraint => "area-constraint",
            Word::MuExpr => "mu-expr",
            Word::TargetMesh => "TARGET",
        }
    }

    /// The Python keyword.
    fn keyword(self) -> &'static str {
        match self {
            Word::Target => "target",
            Word::Boundary => "boundary",
            Word::BoundaryMap => "boundary_map",
            Word::FreeRadius => "free_radius",
            Word::Pins => "pins",
            Word::Landmarks => "landmarks",
            Word::NormalConstraint => "normal_constraint",
            Word::AreaConstraint => "area_constraint",
            Word::MuExpr => "mu_expr",
            Word::TargetMesh => "the target mesh (TV, TF)",
        }
    }
}

impl Spelling {
    /// `word` as this front end spells it: `--boundary-map` or `boundary_map`.
    pub fn word(self, word: Word) -> String {
        match (self, word) {
            (Spelling::Flags, Word::TargetMesh) => word.flag().to_string(),
            (Spelling::Flags, _) => format!("--{}", word.flag()),
            (Spelling::Keywords, _) => word.keyword().to_string(),
        }
    }

    /// `word` set to `value`: `--target disk` or `target='disk'`.
    pub fn setting(self, word: Word, value: &str) -> String {
        match self {
            Spelling::Flags => format!("--{} {value}", word.flag()),
            Spelling::Keywords => format!("{}='{value}'", word.keyword()),
        }
    }
}

/// Where a map goes, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetName {
    /// The plane, with a boundary condition ([`BoundaryName`]).
    Plane,
    /// The unit disk, the boundary sliding on the circle.
    Disk,
    /// The annulus `r <= |z| <= 1` of the input.
    Annulus,
    /// The unit sphere.
    Sphere,
    /// Points of R^3: the surface mapped into space.
    Space,
    /// A circle domain.
    CircleDomain,
    /// Another mesh (registration).
    Mesh,
}

impl TargetName {
    /// Every target, in the order of [`TargetName::name`]'s listing.
    pub const ALL: [TargetName; 7] = [
        TargetName::Plane,
        TargetName::Disk,
        TargetName::Annulus,
        TargetName::Sphere,
        TargetName::Space,
        TargetName::CircleDomain,
        TargetName::Mesh,
    ];

    /// The name: `plane`, `disk`, `annulus`, `sphere`, `space`, `circle-domain`, `mesh`.
    pub fn name(self) -> &'static str {
        match self {
            TargetName::Plane => "plane",
            TargetName::Disk => "disk",
            TargetName::Annulus => "annulus",
            TargetName::Sphere => "sphere",
            TargetName::Space => "space",
            TargetName::CircleDomain => "circle-domain",
            TargetName::Mesh => "mesh",
        }
    }

    /// The target of `name` ([`TargetName::name`]).
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The solver that maps onto this target when none is named: lsqc into the plane
    /// and into space (one linear solve), beltrami-flow onto the disk, an annulus and
    /// the sphere, qcmc onto a circle domain, register onto a mesh.
    pub fn default_solver(self) -> &'static str {
        match self {
            TargetName::Plane | TargetName::Space => "lsqc",
            TargetName::Disk | TargetName::Annulus | TargetName::Sphere => "beltrami-flow",
            TargetName::CircleDomain => "qcmc",
            TargetName::Mesh => "register",
        }
    }
}

/// The plane's boundary condition, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundaryName {
    /// The input's own boundary positions (a mesh in the plane z = 0).
    Keep,
    /// A free boundary (with pins).
    Free,
    /// The unit circle, by arc length.
    Circle,
    /// The unit square, corners a quarter of the boundary apart.
    Square,
    /// The boundary of a given map ([`ProblemSpec::boundary_map`]).
    Given,
}

impl BoundaryName {
    /// Every boundary condition, in the order of their names' listing.
    pub const ALL: [BoundaryName; 5] = [
        BoundaryName::Keep,
        BoundaryName::Free,
        BoundaryName::Circle,
        BoundaryName::Square,
        BoundaryName::Given,
    ];

    /// The name: `keep`, `free`, `circle`, `square`, `given`.
    pub fn name(self) -> &'static str {
        match self {
            BoundaryName::Keep => "keep",
            BoundaryName::Free => "free",
            BoundaryName::Circle => "circle",
            BoundaryName::Square => "square",
            BoundaryName::Given => "given",
        }
    }

    /// The boundary condition of `name` ([`BoundaryName::name`]).
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }
}

/// How the plane's boundary is chosen when none is named.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundaryDefault {
    /// A parameterization's (`beltrami param`): the first of circle, square and free
    /// in the order of the solver's accepted targets, circle when it takes none.
    Shaped,
    /// A prescribed or extremal map's (`beltrami qc`): free when the solver takes a
    /// free boundary, else the input's own.
    FreeOrKeep,
    /// The input's own boundary.
    Keep,
}

/// A map held on the boundary: planar images (the plane's `given` boundary) or points of
/// R^3 (the boundary held into space), one per mesh vertex; only boundary vertices are
/// read.
#[derive(Debug, Clone, PartialEq)]
pub enum BoundaryMap {
    /// Images in the plane.
    Planar(Vec<Complex64>),
    /// Points of R^3.
    Spatial(Vec<Point3<f64>>),
}

/// What the map should achieve.
#[derive(Debug, Clone, PartialEq)]
pub enum GoalSpec {
    /// The smallest `L^p` norm of mu, `p = 2` unless given.
    Conformal {
        /// The exponent.
        p: Option<f64>,
    },
    /// A Beltrami coefficient per face.
    Mu(BeltramiField),
    /// A Beltrami coefficient as an expression of `z` at the face centroids: `x + i y`
    /// on a planar target, the stereographic coordinate from the north pole,
    /// `(x + i y) / (1 - z)`, on the sphere.
    MuExpr(String),
    /// The extremal map of the boundary condition.
    Extremal,
    /// Scalar fields matched between the source and a target mesh.
    Features(Features),
}

/// A problem stated in a front end's words (module docs).
#[derive(Debug, Clone)]
pub struct ProblemSpec {
    /// The solver's name, or `None` for the target's ([`TargetName::default_solver`]).
    pub solver: Option<String>,
    /// Where the map goes.
    pub target: TargetName,
    /// The plane's boundary condition, or `None` for [`ProblemSpec::boundary_default`].
    pub boundary: Option<BoundaryName>,
    /// How the plane's boundary is chosen when none is named.
    pub boundary_default: BoundaryDefault,
    /// The map whose boundary is held: planar for the plane's `given` boundary, spatial
    /// for a map into space.
    pub boundary_map: Option<BoundaryMap>,
    /// Annulus: the inner radius moves (else the input's is kept).
    pub free_radius: bool,
    /// The goal, or `None` for the extremal map when the solver computes extremal maps
    /// and the most conformal one otherwise.
    pub goal: Option<GoalSpec>,
    /// Pins, landmarks and curves, in the source's (and target's) mesh ids. Into space,
    /// a pin without a position holds its vertex where it is.
    pub constraints: Constraints,
    /// Space: the weight of the normal constraint.
    pub normal_constraint: Option<f64>,
    /// Space: the area kept to first order.
    pub area_constraint: bool,
    /// A start map for iterative solvers (planar images, one per mesh vertex).
    pub initial: Option<Vec<Complex64>>,
    /// The front end's defaults of options, set when the solver declares them.
    pub defaults: Vec<(String, OptionValue)>,
    /// Option values the user gave, by name (typed, or as text parsed by the
    /// solver's declarations).
    pub options: Options,
    /// How errors name the words.
    pub spelling: Spelling,
}

/// A problem whose words do not fit together, or a value that cannot be used; the
/// message names the words in the front end's spelling.
#[derive(Debug, Error)]
pub enum SpecError {
    /// A word that the others make meaningless, or that needs another.
    #[error("{message}")]
    Words {
        /// The word at fault.
        word: Word,
        /// What is wrong, in the front end's words.
        message: String,
    },
    /// A mu expression that cannot be evaluated on the mesh.
    #[error("{message}")]
    Field {
        /// What was evaluated, in the front end's words.
        message: String,
        /// Why it could not be.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl SpecError {
    /// The word at fault.
    pub fn word(&self) -> Word {
        match self {
            SpecError::Words { word, .. } => *word,
            SpecError::Field { .. } => Word::MuExpr,
        }
    }
}

impl ProblemSpec {
    /// A problem onto `target` with no other word given, spelled as flags.
    pub fn new(target: TargetName) -> Self {
        Self {
            solver: None,
            target,
            boundary: None,
            boundary_default: BoundaryDefault::Keep,
            boundary_map: None,
            free_radius: false,
            goal: None,
            constraints: Constraints::new(),
            normal_constraint: None,
            area_constraint: false,
            initial: None,
            defaults: Vec::new(),
            options: Options::new(),
            spelling: Spelling::Flags,
        }
    }

    /// The solver's name: the one given, or the target's.
    pub fn solver_name(&self) -> &str {
        self.solver
            .as_deref()
            .unwrap_or_else(|| self.target.default_solver())
    }

    /// Refuses, before any mesh is read, words that the others make meaningless (they
    /// would be ignored silently) or that need another: a boundary condition off the
    /// plane and space, a boundary map without the `given` boundary, the normal and
    /// area constraints off space (and a weight that is not positive), space with
    /// nothing held, four-point landmarks off the disk, a free radius off the annulus.
    pub fn check_words(&self) -> Result<(), SpecError> {
        let s = self.spelling;
        let target = s.setting(Word::Target, self.target.name());
        let space = self.target == TargetName::Space;
        if self.boundary.is_some() && !matches!(self.target, TargetName::Plane) && !space {
            return Err(SpecError::Words {
                word: Word::Boundary,
                message: format!(
                    "{} is the boundary condition of {} and space; {target} has its own",
                    s.word(Word::Boundary),
                    s.setting(Word::Target, "plane")
                ),
            });
        }
        if let Some(w) = self.normal_constraint {
            if !space {
                return Err(SpecError::Words {
                    word: Word::NormalConstraint,
                    message: format!(
                        "{} keeps a map into space near the surface: it needs {}",
                        s.word(Word::NormalConstraint),
                        s.setting(Word::Target, "space")
                    ),
                });
            }
            if !(w.is_finite() && w > 0.0) {
                return Err(SpecError::Words {
                    word: Word::NormalConstraint,
                    message: format!(
                        "{} {w}: the weight must be a positive number",
                        s.word(Word::NormalConstraint)
                    ),
                });
            }
        }
        if self.area_constraint && !space {
            return Err(SpecError::Words {
                word: Word::AreaConstraint,
                message: format!(
                    "{} keeps the area of a map into space: it needs {}",
                    s.word(Word::AreaConstraint),
                    s.setting(Word::Target, "space")
                ),
            });
        }
        let given = self.boundary == Some(BoundaryName::Given);
        if space && !given && self.constraints.pins().next().is_none() {
            return Err(SpecError::Words {
                word: Word::Target,
                message: format!(
                    "{target} holds vertices where they go: the boundary at the positions of a map (add {} {}), or vertices where they are ({})",
                    s.setting(Word::Boundary, "given"),
                    s.word(Word::BoundaryMap),
                    s.word(Word::Pins)
                ),
            });
        }
        match (&self.boundary_map, given) {
            (None, true) => {
                return Err(SpecError::Words {
                    word: Word::BoundaryMap,
                    message: format!(
                        "{} needs {}",
                        s.setting(Word::Boundary, "given"),
                        s.word(Word::BoundaryMap)
                    ),
                });
            }
            (Some(BoundaryMap::Planar(_)), true) if space => {
                return Err(SpecError::Words {
                    word: Word::BoundaryMap,
                    message: format!(
                        "{} holds the boundary at points of R^3: {} gives points in the plane",
                        s.setting(Word::Target, "space"),
                        s.word(Word::BoundaryMap)
                    ),
                });
            }
            _ => {}
        }
        if self.boundary_map.is_some() && !given {
            return Err(SpecError::Words {
                word: Word::BoundaryMap,
                message: format!(
                    "{} gives the boundary of {}; add that or drop {}",
                    s.word(Word::BoundaryMap),
                    s.setting(Word::Boundary, "given"),
                    s.word(Word::BoundaryMap)
                ),
            });
        }
        let planar_landmarks = self
            .constraints
            .landmarks()
            .any(|l| matches!(l.position, Position::Planar(_)));
        if planar_landmarks && self.target != TargetName::Disk {
            return Err(SpecError::Words {
                word: Word::Landmarks,
                message: format!(
                    "{} moves boundary points of {} (the four-point problem); {target} holds its boundary otherwise",
                    s.word(Word::Landmarks),
                    s.setting(Word::Target, "disk")
                ),
            });
        }
        if self.free_radius && self.target != TargetName::Annulus {
            return Err(SpecError::Words {
                word: Word::FreeRadius,
                message: format!(
                    "{} lets the inner radius of {} move; {target} has none",
                    s.word(Word::FreeRadius),
                    s.setting(Word::Target, "annulus")
                ),
            });
        }
        Ok(())
    }

    /// The problem these words state for `solver` on `source` (and `target`, the target
    /// mesh of [`TargetName::Mesh`]), after [`ProblemSpec::check_words`]; the solver's
    /// own check then refuses what it cannot do.
    ///
    /// # Errors
    /// [`SpecError`] for words that do not fit together, a missing boundary map or
    /// target mesh, and a mu expression that cannot be evaluated on `source`.
    pub fn problem<'a>(
        &self,
        source: &'a Mesh,
        target: Option<&'a Mesh>,
        solver: &dyn Solver,
    ) -> Result<Problem<'a>, SpecError> {
        self.check_words()?;
        let mut problem = Problem::new(source, self.target_of(source, target, solver)?);
        problem.goal = self.goal_of(source, solver)?;
        problem.initial = self.initial.clone().map(Map::Planar);
        problem.constraints = self.constraints_of(source);
        problem.options = self.options_of(solver);
        Ok(problem)
    }

    /// The core target: the solver's only domain (a sphere or circle domain solver
    /// onto the plane without a named boundary), the plane with its boundary condition,
    /// or the named domain.
    fn target_of<'a>(
        &self,
        source: &Mesh,
        target: Option<&'a Mesh>,
        solver: &dyn Solver,
    ) -> Result<Target<'a>, SpecError> {
        let accepts = solver.accepts();
        let s = self.spelling;
        Ok(match self.target {
            TargetName::Plane
                if self.boundary.is_none() && accepts.targets == [TargetKind::Sphere] =>
            {
                Target::Sphere
            }
            TargetName::Plane
                if self.boundary.is_none() && accepts.targets == [TargetKind::CircleDomain] =>
            {
                Target::CircleDomain
            }
            TargetName::Plane => Target::Plane(self.planar_boundary(solver)?),
            TargetName::Disk => Target::Disk,
            TargetName::Annulus => Target::Annulus {
                inner_radius: if self.free_radius {
                    None
                } else {
                    beltrami_flow_engine::annulus_inner_radius(source)
                },
            },
            TargetName::Sphere => Target::Sphere,
            TargetName::Space => Target::Surface,
            TargetName::CircleDomain => Target::CircleDomain,
            TargetName::Mesh => Target::Mesh(target.ok_or_else(|| SpecError::Words {
                word: Word::TargetMesh,
                message: format!(
                    "{} maps onto a target mesh: {} is missing",
                    s.setting(Word::Target, "mesh"),
                    s.word(Word::TargetMesh)
                ),
            })?),
        })
    }

    /// The plane's boundary condition: the named one, or the default.
    fn planar_boundary(&self, solver: &dyn Solver) -> Result<PlanarBoundary, SpecError> {
        let targets = solver.accepts().targets;
        let name = self.boundary.unwrap_or(match self.boundary_default {
            BoundaryDefault::Shaped => targets
                .iter()
                .find_map(|kind| match kind {
                    TargetKind::PlaneCircle => Some(BoundaryName::Circle),
                    TargetKind::PlaneSquare => Some(BoundaryName::Square),
                    TargetKind::PlaneFree => Some(BoundaryName::Free),
                    _ => None,
                })
                .unwrap_or(BoundaryName::Circle),
            BoundaryDefault::FreeOrKeep if targets.contains(&TargetKind::PlaneFree) => {
                BoundaryName::Free
            }
            BoundaryDefault::FreeOrKeep | BoundaryDefault::Keep => BoundaryName::Keep,
        });
        Ok(match name {
            BoundaryName::Keep => PlanarBoundary::Keep,
            BoundaryName::Free => PlanarBoundary::Free,
            BoundaryName::Circle => PlanarBoundary::Circle,
            BoundaryName::Square => PlanarBoundary::Square { corners: None },
            BoundaryName::Given => match &self.boundary_map {
                Some(BoundaryMap::Planar(values)) => PlanarBoundary::Given(values.clone()),
                _ => {
                    let s = self.spelling;
                    return Err(SpecError::Words {
                        word: Word::BoundaryMap,
                        message: format!(
                            "{} holds the boundary at points of the plane: {} gives points of R^3",
                            s.setting(Word::Target, "plane"),
                            s.word(Word::BoundaryMap)
                        ),
                    });
                }
            },
        })
    }

    /// The core goal: the given one (a mu expression evaluated on `source`), else the
    /// extremal map for a solver that computes extremal maps and the most conformal
    /// one otherwise.
    fn goal_of(&self, source: &Mesh, solver: &dyn Solver) -> Result<Goal, SpecError> {
        Ok(match &self.goal {
            None if solver.accepts().goals.contains(&GoalKind::Extremal) => Goal::Extremal,
            None => Goal::default(),
            Some(GoalSpec::Conformal { p }) => Goal::Conformal {
                p: p.unwrap_or(2.0),
            },
            Some(GoalSpec::Mu(field)) => Goal::Prescribed(field.clone()),
            Some(GoalSpec::MuExpr(text)) => Goal::Prescribed(self.expression_field(text, source)?),
            Some(GoalSpec::Extremal) => Goal::Extremal,
            Some(GoalSpec::Features(features)) => Goal::Features(features.clone()),
        })
    }

    /// The field of the mu expression `text` at `source`'s face centroids
    /// ([`GoalSpec::MuExpr`]).
    fn expression_field(&self, text: &str, source: &Mesh) -> Result<BeltramiField, SpecError> {
        let named = match self.spelling {
            Spelling::Flags => format!("{} `{text}`", self.spelling.word(Word::MuExpr)),
            Spelling::Keywords => self.spelling.setting(Word::MuExpr, text),
        };
        let field_error = |message: String, source: Box<dyn std::error::Error + Send + Sync>| {
            SpecError::Field { message, source }
        };
        let expr = Expr::parse(text).map_err(|e| field_error(named.clone(), Box::new(e)))?;
        if self.target == TargetName::Sphere {
            beltrami_flow::stereographic::field(source, |z| expr.eval(z))
                .map_err(|e| field_error(format!("{named} on the sphere"), Box::new(e)))
        } else {
            expr.field(source).map_err(|e| {
                field_error(
                    format!(
                        "{} evaluates mu at z = x + i y and needs a mesh in the plane z = 0; give a per-face field instead",
                        self.spelling.word(Word::MuExpr)
                    ),
                    Box::new(e),
                )
            })
        }
    }

    /// The constraints: the given ones (into space, pins without a position held where
    /// they are), then the normal and area constraints and the boundary held into
    /// space.
    fn constraints_of(&self, source: &Mesh) -> Constraints {
        let space = self.target == TargetName::Space;
        let mut constraints: Constraints = self
            .constraints
            .iter()
            .map(|c| match c {
                // A vertex out of range is left for the solver's validation to name.
                Constraint::Pin(pin)
                    if space
                        && pin.position.is_none()
                        && pin.vertex.idx() < source.vertex_count() =>
                {
                    let mut pin = *pin;
                    pin.position = Some(Position::Spatial(source.position(pin.vertex)));
                    Constraint::Pin(pin)
                }
                other => other.clone(),
            })
            .collect();
        if let Some(weight) = self.normal_constraint {
            constraints.push(Constraint::Normal { weight });
        }
        if self.area_constraint {
            constraints.push(Constraint::Area);
        }
        if let (true, Some(BoundaryMap::Spatial(held))) = (space, &self.boundary_map) {
            constraints.hold_boundary(source, held);
        }
        constraints
    }

    /// The options: the front end's defaults the solver declares, then the given ones.
    fn options_of(&self, solver: &dyn Solver) -> Options {
        let mut options = Options::new();
        for (name, value) in &self.defaults {
            if solver.options().iter().any(|s| s.name == name) {
                options.set(name, value.clone());
            }
        }
        for (name, value) in self.options.iter() {
            options.set(name, value.clone());
        }
        options
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_core::Pin;
    use beltrami_mesh::VertexId;
    use beltrami_mesh::primitives::{self, Cells};

    fn solve_with(
        spec: &ProblemSpec,
        mesh: &Mesh,
    ) -> Result<(Target<'static>, Goal, Constraints, Options), SpecError> {
        let registry = crate::registry();
        let solver = registry.get(spec.solver_name()).unwrap();
        let problem = spec.problem(mesh, None, solver)?;
        let target = match problem.target {
            Target::Plane(b) => Target::Plane(b),
            Target::Disk => Target::Disk,
            Target::Annulus { inner_radius } => Target::Annulus { inner_radius },
            Target::Sphere => Target::Sphere,
            Target::CircleDomain => Target::CircleDomain,
            Target::Surface => Target::Surface,
            Target::Mesh(_) => panic!("no target mesh here"),
        };
        Ok((target, problem.goal, problem.constraints, problem.options))
    }

    fn square() -> Mesh {
        Mesh::from_soup(&primitives::grid(4, 4, Cells::Triangles)).unwrap()
    }

    fn words_error(spec: &ProblemSpec) -> (Word, String) {
        match spec.check_words() {
            Err(SpecError::Words { word, message }) => (word, message),
            other => panic!("expected refused words, got {other:?}"),
        }
    }

    #[test]
    fn the_plane_s_boundary_defaults_follow_the_command_and_the_solver() {
        let square = square();
        let boundary_of = |solver: &str, default: BoundaryDefault| {
            let mut spec = ProblemSpec::new(TargetName::Plane);
            spec.solver = Some(solver.to_string());
            spec.boundary_default = default;
            match solve_with(&spec, &square).unwrap().0 {
                Target::Plane(b) => b,
                other => panic!("{solver}: {other:?}"),
            }
        };
        assert_eq!(
            boundary_of("tutte", BoundaryDefault::Shaped),
            PlanarBoundary::Circle
        );
        assert_eq!(
            boundary_of("lscm", BoundaryDefault::Shaped),
            PlanarBoundary::Free
        );
        assert_eq!(
            boundary_of("lsqc", BoundaryDefault::FreeOrKeep),
            PlanarBoundary::Free
        );
        assert_eq!(
            boundary_of("beltrami-flow", BoundaryDefault::FreeOrKeep),
            PlanarBoundary::Keep
        );
        assert_eq!(
            boundary_of("lsqc", BoundaryDefault::Keep),
            PlanarBoundary::Keep
        );
        // A solver with one domain gets it when no boundary is named.
        let ball = Mesh::from_soup(&primitives::icosphere(1)).unwrap();
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.solver = Some("sphere".into());
        assert!(matches!(
            solve_with(&spec, &ball).unwrap().0,
            Target::Sphere
        ));
        assert_eq!(
            ProblemSpec::new(TargetName::Disk).solver_name(),
            "beltrami-flow"
        );
        assert_eq!(ProblemSpec::new(TargetName::Space).solver_name(), "lsqc");
        assert_eq!(ProblemSpec::new(TargetName::Mesh).solver_name(), "register");
    }

    #[test]
    fn meaningless_words_are_refused_in_the_front_end_s_spelling() {
        let mut spec = ProblemSpec::new(TargetName::Disk);
        spec.boundary = Some(BoundaryName::Keep);
        let (word, flags) = words_error(&spec);
        assert_eq!(word, Word::Boundary);
        assert!(
            flags.contains("--boundary") && flags.contains("--target disk"),
            "{flags}"
        );
        spec.spelling = Spelling::Keywords;
        let (_, keywords) = words_error(&spec);
        assert!(
            keywords.contains("target='disk'") && !keywords.contains("--"),
            "{keywords}"
        );

        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.free_radius = true;
        assert_eq!(words_error(&spec).0, Word::FreeRadius);
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.boundary = Some(BoundaryName::Given);
        let (word, message) = words_error(&spec);
        assert_eq!(word, Word::BoundaryMap);
        assert!(message.contains("--boundary-map"), "{message}");
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.boundary_map = Some(BoundaryMap::Planar(Vec::new()));
        assert_eq!(words_error(&spec).0, Word::BoundaryMap);
        let mut spec = ProblemSpec::new(TargetName::Space);
        assert_eq!(words_error(&spec).0, Word::Target);
        spec.normal_constraint = Some(-1.0);
        spec.constraints.push(Constraint::Pin(Pin {
            vertex: VertexId(0),
            position: None,
        }));
        assert_eq!(words_error(&spec).0, Word::NormalConstraint);
        let mut spec = ProblemSpec::new(TargetName::Sphere);
        spec.area_constraint = true;
        assert_eq!(words_error(&spec).0, Word::AreaConstraint);
    }

    #[test]
    fn the_goal_defaults_to_the_solver_s_and_expressions_are_evaluated_on_the_target() {
        let square = square();
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.solver = Some("lscm".into());
        assert_eq!(
            solve_with(&spec, &square).unwrap().1,
            Goal::Conformal { p: 2.0 }
        );
        spec.solver = Some("extremal".into());
        spec.boundary = Some(BoundaryName::Keep);
        assert_eq!(solve_with(&spec, &square).unwrap().1, Goal::Extremal);

        // On the plane z is x + i y at the centroids: mu = z / 10 is that per face.
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.goal = Some(GoalSpec::MuExpr("z/10".into()));
        let Goal::Prescribed(field) = solve_with(&spec, &square).unwrap().1 else {
            panic!("a prescribed goal");
        };
        for f in square.faces() {
            let c = square.face_centroid(f);
            assert!((field.mu[f.idx()] - Complex64::new(c.x, c.y) / 10.0).norm() < 1e-15);
        }
        // Off the plane, the expression cannot be evaluated: the error names it.
        let ball = Mesh::from_soup(&primitives::icosphere(1)).unwrap();
        match solve_with(&spec, &ball) {
            Err(e @ SpecError::Field { .. }) => {
                assert!(e.to_string().contains("--mu-expr"), "{e}")
            }
            other => panic!("expected a field error, got {other:?}"),
        }
        // On the sphere z is stereographic and mu is carried into each face's frame
        // (mu_face = conj(mu) a / conj(a)): a constant keeps its modulus on every face.
        let mut spec = ProblemSpec::new(TargetName::Sphere);
        spec.goal = Some(GoalSpec::MuExpr("0.25i".into()));
        let Goal::Prescribed(field) = solve_with(&spec, &ball).unwrap().1 else {
            panic!("a prescribed goal");
        };
        assert_eq!(field.frame, beltrami_fem::Frame::Face);
        assert!(field.mu.iter().all(|m| (m.norm() - 0.25).abs() < 1e-12));
    }

    #[test]
    fn into_space_pins_hold_their_vertex_and_the_boundary_map_is_held() {
        let mut soup = primitives::grid(4, 4, Cells::Triangles);
        for p in &mut soup.positions {
            p.z = p.x * p.y;
        }
        let sheet = Mesh::from_soup(&soup).unwrap();
        let mut spec = ProblemSpec::new(TargetName::Space);
        spec.constraints.push(Constraint::Pin(Pin {
            vertex: VertexId(5),
            position: None,
        }));
        spec.area_constraint = true;
        let (target, _, constraints, _) = solve_with(&spec, &sheet).unwrap();
        assert!(matches!(target, Target::Surface));
        let pins: Vec<_> = constraints.pins().collect();
        assert_eq!(
            pins[0].position,
            Some(Position::Spatial(sheet.position(VertexId(5))))
        );
        assert!(constraints.iter().any(|c| matches!(c, Constraint::Area)));

        let lifted: Vec<Point3<f64>> = sheet
            .positions()
            .iter()
            .map(|p| Point3::new(p.x, p.y, 1.0))
            .collect();
        let mut spec = ProblemSpec::new(TargetName::Space);
        spec.boundary = Some(BoundaryName::Given);
        spec.boundary_map = Some(BoundaryMap::Spatial(lifted.clone()));
        let (_, _, constraints, _) = solve_with(&spec, &sheet).unwrap();
        let held: Vec<_> = constraints.pins().collect();
        let boundary: usize = sheet
            .boundary_loop_list()
            .iter()
            .map(|l| l.vertices.len())
            .sum();
        assert_eq!(held.len(), boundary);
        for pin in held {
            assert_eq!(
                pin.position,
                Some(Position::Spatial(lifted[pin.vertex.idx()]))
            );
        }
    }

    #[test]
    fn defaults_apply_only_to_options_the_solver_declares_and_given_values_win() {
        let square = square();
        let mut spec = ProblemSpec::new(TargetName::Plane);
        spec.solver = Some("lscm".into());
        spec.defaults = vec![("max-iters".into(), OptionValue::Int(200))];
        let options = solve_with(&spec, &square).unwrap().3;
        assert!(options.get("max-iters").is_none());

        let mut spec = ProblemSpec::new(TargetName::Disk);
        spec.defaults = vec![("max-iters".into(), OptionValue::Int(200))];
        spec.options.set("max-iters", OptionValue::Int(7));
        let options = solve_with(&spec, &square).unwrap().3;
        assert_eq!(options.get("max-iters"), Some(&OptionValue::Int(7)));
    }
}
