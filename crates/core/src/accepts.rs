//! What a solver accepts, as data: element types, source topologies, targets, goals and
//! constraint kinds ([`Accepts`]), for listings (`beltrami solvers --json`) and for the
//! check every solve runs ([`Accepts::check`]).

use std::fmt;

use beltrami_mesh::Mesh;

use crate::{ConstraintKind, Goal, PlanarBoundary, Problem, SolverError, Target};

/// The face types of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Element {
    /// Triangles (P1).
    Triangle,
    /// Quads (Q1).
    Quad,
}

impl Element {
    /// The stable name in listings.
    pub fn name(self) -> &'static str {
        match self {
            Element::Triangle => "triangle",
            Element::Quad => "quad",
        }
    }
}

/// Source topologies, by component count, genus and boundary loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topology {
    /// One component, genus 0, one boundary loop.
    Disk,
    /// One component, genus 0, two boundary loops.
    Annulus,
    /// One component, genus 0, three or more boundary loops.
    MultiplyConnected,
    /// One component, genus 0, closed.
    Sphere,
    /// One component, genus 1, closed.
    Torus,
    /// One component, genus 2 or more, closed.
    HigherGenus,
    /// One component, genus 1 or more, with boundary.
    BoundedHigherGenus,
    /// Several components.
    Components,
}

impl Topology {
    /// Every topology, several components last: what a solver that takes any mesh
    /// lists in [`Accepts::topologies`].
    pub const ANY: &'static [Topology] = &[
        Topology::Disk,
        Topology::Annulus,
        Topology::MultiplyConnected,
        Topology::Sphere,
        Topology::Torus,
        Topology::HigherGenus,
        Topology::BoundedHigherGenus,
        Topology::Components,
    ];

    /// Every one-component topology ([`Topology::ANY`] but `Components`): what a solver
    /// that maps any connected surface lists in [`Accepts::topologies`].
    pub const CONNECTED: &'static [Topology] = Self::ANY.split_at(Self::ANY.len() - 1).0;

    /// The topology of `mesh`.
    pub fn of(mesh: &Mesh) -> Self {
        let components = mesh.components();
        if components.len() != 1 {
            return Topology::Components;
        }
        let c = &components[0];
        match (c.genus, c.boundary_loops) {
            (0, 0) => Topology::Sphere,
            (0, 1) => Topology::Disk,
            (0, 2) => Topology::Annulus,
            (0, _) => Topology::MultiplyConnected,
            (1, 0) => Topology::Torus,
            (_, 0) => Topology::HigherGenus,
            _ => Topology::BoundedHigherGenus,
        }
    }

    /// The stable name in listings.
    pub fn name(self) -> &'static str {
        match self {
            Topology::Disk => "disk",
            Topology::Annulus => "annulus",
            Topology::MultiplyConnected => "multiply-connected",
            Topology::Sphere => "sphere",
            Topology::Torus => "torus",
            Topology::HigherGenus => "closed-genus-2+",
            Topology::BoundedHigherGenus => "genus-1+-with-boundary",
            Topology::Components => "several-components",
        }
    }
}

/// The kinds of [`Target`] (planar targets by their boundary condition).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetKind {
    /// `Plane(Free)`.
    PlaneFree,
    /// `Plane(Circle)`.
    PlaneCircle,
    /// `Plane(Square)`.
    PlaneSquare,
    /// `Plane(Polygon)`.
    PlanePolygon,
    /// `Plane(Keep)`.
    PlaneKeep,
    /// `Plane(Given)`.
    PlaneGiven,
    /// `Disk`.
    Disk,
    /// `Annulus`.
    Annulus,
    /// `Sphere`.
    Sphere,
    /// `CircleDomain`.
    CircleDomain,
    /// `Mesh`.
    Mesh,
    /// `Surface`.
    Surface,
}

impl TargetKind {
    /// The kind of `target`.
    pub fn of(target: &Target<'_>) -> Self {
        match target {
            Target::Plane(PlanarBoundary::Free) => TargetKind::PlaneFree,
            Target::Plane(PlanarBoundary::Circle) => TargetKind::PlaneCircle,
            Target::Plane(PlanarBoundary::Square { .. }) => TargetKind::PlaneSquare,
            Target::Plane(PlanarBoundary::Polygon(_)) => TargetKind::PlanePolygon,
            Target::Plane(PlanarBoundary::Keep) => TargetKind::PlaneKeep,
            Target::Plane(PlanarBoundary::Given(_)) => TargetKind::PlaneGiven,
            Target::Disk => TargetKind::Disk,
            Target::Annulus { .. } => TargetKind::Annulus,
            Target::Sphere => TargetKind::Sphere,
            Target::CircleDomain => TargetKind::CircleDomain,
            Target::Mesh(_) => TargetKind::Mesh,
            Target::Surface => TargetKind::Surface,
        }
    }

    /// The stable name in listings.
    pub fn name(self) -> &'static str {
        match self {
            TargetKind::PlaneFree => "plane-free",
            TargetKind::PlaneCircle => "plane-circle",
            TargetKind::PlaneSquare => "plane-square",
            TargetKind::PlanePolygon => "plane-polygon",
            TargetKind::PlaneKeep => "plane-keep",
            TargetKind::PlaneGiven => "plane-given",
            TargetKind::Disk => "disk",
            TargetKind::Annulus => "annulus",
            TargetKind::Sphere => "sphere",
            TargetKind::CircleDomain => "circle-domain",
            TargetKind::Mesh => "mesh",
            TargetKind::Surface => "surface",
        }
    }
}

/// The kinds of [`Goal`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GoalKind {
    /// `Conformal { p: 2 }`: least squares.
    Conformal,
    /// `Conformal { p > 2 }`.
    ConformalLp,
    /// `Prescribed(field)`.
    Prescribed,
    /// `Extremal`.
    Extremal,
    /// `Features(fields)`.
    Features,
}

impl GoalKind {
    /// The kind of `goal`.
    pub fn of(goal: &Goal) -> Self {
        match goal {
            Goal::Conformal { p } if *p == 2.0 => GoalKind::Conformal,
            Goal::Conformal { .. } => GoalKind::ConformalLp,
            Goal::Prescribed(_) => GoalKind::Prescribed,
            Goal::Extremal => GoalKind::Extremal,
            Goal::Features(_) => GoalKind::Features,
        }
    }

    /// The stable name in listings.
    pub fn name(self) -> &'static str {
        match self {
            GoalKind::Conformal => "conformal",
            GoalKind::ConformalLp => "conformal-lp",
            GoalKind::Prescribed => "prescribed-mu",
            GoalKind::Extremal => "extremal",
            GoalKind::Features => "features",
        }
    }
}

macro_rules! display_by_name {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
    )*};
}
display_by_name!(Element, Topology, TargetKind, GoalKind);

/// What a solver accepts. Every list is exhaustive: a problem outside it is refused
/// before any work by [`Accepts::check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accepts {
    /// Face types.
    pub elements: &'static [Element],
    /// Source topologies (a target may narrow them: the solver's own check says so).
    pub topologies: &'static [Topology],
    /// Targets.
    pub targets: &'static [TargetKind],
    /// Goals.
    pub goals: &'static [GoalKind],
    /// Constraint kinds.
    pub constraints: &'static [ConstraintKind],
}

impl Accepts {
    /// Refuses a problem with a face type, topology, target, goal or constraint kind
    /// outside the lists, naming the first one found (a face by its input index, a
    /// constraint by its index).
    pub fn check(&self, solver: &'static str, problem: &Problem<'_>) -> Result<(), SolverError> {
        let unsupported = |message: String| Err(SolverError::unsupported(solver, message));
        let names = |list: &[&str]| list.join(", ");
        let mesh = problem.source;
        for f in mesh.faces() {
            let element = if mesh.face_degree(f) == 3 {
                Element::Triangle
            } else {
                Element::Quad
            };
            if !self.elements.contains(&element) {
                return unsupported(format!(
                    "face {} (input index) is a {element}; {solver} takes {}",
                    mesh.face_to_input(f),
                    names(&self.elements.iter().map(|e| e.name()).collect::<Vec<_>>())
                ));
            }
        }
        let topology = Topology::of(mesh);
        if !self.topologies.contains(&topology) {
            return unsupported(format!(
                "the source is {topology} ({}); {solver} takes {}",
                crate::topology::describe(mesh),
                names(&self.topologies.iter().map(|t| t.name()).collect::<Vec<_>>())
            ));
        }
        let target = TargetKind::of(&problem.target);
        if !self.targets.contains(&target) {
            return unsupported(format!(
                "{solver} does not map onto the target `{target}`; its targets: {}",
                names(&self.targets.iter().map(|t| t.name()).collect::<Vec<_>>())
            ));
        }
        let goal = GoalKind::of(&problem.goal);
        if !self.goals.contains(&goal) {
            return unsupported(format!(
                "{solver} does not take the goal `{goal}`; its goals: {}",
                names(&self.goals.iter().map(|g| g.name()).collect::<Vec<_>>())
            ));
        }
        for (index, constraint) in problem.constraints.iter().enumerate() {
            let kind = constraint.kind();
            if !self.constraints.contains(&kind) {
                let accepted: Vec<&str> = self.constraints.iter().map(|c| c.name()).collect();
                return unsupported(format!(
                    "constraint {index} ({kind}) is not one {solver} honours; it takes {}",
                    if accepted.is_empty() {
                        "no constraints".to_string()
                    } else {
                        names(&accepted)
                    }
                ));
            }
        }
        Ok(())
    }
}
