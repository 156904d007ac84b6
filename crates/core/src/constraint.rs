//! Typed constraints of a mapping problem.
//!
//! A [`Problem`](crate::Problem) carries a list of [`Constraint`]s. Each says what one
//! part of the map must do, in the source's vertex ids and the target's terms:
//!
//! | constraint | what it asks | typical solvers |
//! |---|---|---|
//! | [`Pin`] | a vertex stays at a point (or where the initial map puts it) | lscm, lsqc, flow |
//! | [`Landmark`] | a vertex is moved to a point or a vertex of the target, then held | register |
//! | [`Slide`] | a vertex moves only along a line through its position | lsqc, qc-iteration |
//! | [`Curve`] | a source chain (open or closed) lies on a target chain | register, flow |
//! | [`LoopMatch`] | a boundary loop of the source maps onto one of the target | register, qcmc |
//! | `Normal` | the image keeps the source's normals (weight `w`) | quaternionic lsqc |
//! | `Area` | the image keeps the source's area | quaternionic lsqc |
//! | `ReferenceAngles` | the corner angles the map aims at, one per face corner | remesh by angles |
//!
//! [`Constraints::validate`] checks what every solver needs before any work (vertices
//! and loops exist, points and directions are finite, chains are long enough, angles lie
//! in `(0, pi)`), with a [`ConstraintError`] naming the constraint and the element; a
//! solver's capability check then says which kinds it honours ([`ConstraintKind`]).

use std::fmt;

use beltrami_mesh::{HalfedgeId, Mesh, Point3, Vector3, VertexId};
use num_complex::Complex64;
use thiserror::Error;

use crate::Position;

/// The largest weight of the normal constraint: the penalty then outweighs the conformal
/// energy by about 1e8, and in double precision a larger ratio leaves the conformal
/// part of the normal equations below rounding.
pub const MAX_NORMAL_WEIGHT: f64 = 1e8;

/// A vertex held at a point: `position: None` lets the solver choose (LSCM's default
/// `(0, 0)` and `(1, 0)`, or where the initial map puts it for iterative solvers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pin {
    /// The pinned vertex.
    pub vertex: VertexId,
    /// Where it goes, if prescribed.
    pub position: Option<Position>,
}

/// A vertex that must end at a given point of the target (a point of a target mesh for
/// registration): the solver moves it there, then holds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmark {
    /// The source vertex.
    pub vertex: VertexId,
    /// Its destination.
    pub position: Position,
}

/// A vertex that moves only along the line through its position with `direction`
/// (`x = p + t d`, `t` real): a planar direction, or a direction in R^3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slide {
    /// The sliding vertex.
    pub vertex: VertexId,
    /// The direction of the line (need not be of unit length, must not be zero).
    pub direction: Direction,
}

/// A direction in the plane or in space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Direction {
    /// A planar direction `dx + i dy`.
    Planar(Complex64),
    /// A direction in R^3.
    Spatial(Vector3<f64>),
}

/// A chain of source vertices that must lie on a chain of target vertices (a feature
/// curve). An open curve keeps its ends on the target chain's ends and slides in
/// between; a closed one (first vertex not repeated at the end) slides all round.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Source vertices, in order.
    pub source: Vec<VertexId>,
    /// The target chain: vertices of the target mesh (or of the source, for maps of the
    /// surface into itself), in order.
    pub target: Vec<VertexId>,
    /// Whether both chains are closed loops.
    pub closed: bool,
}

impl Curve {
    /// An open curve from `source` onto `target`.
    pub fn open(source: Vec<VertexId>, target: Vec<VertexId>) -> Self {
        Self {
            source,
            target,
            closed: false,
        }
    }
}

/// Boundary loop `source` of the source mesh maps onto boundary loop `target` of the
/// target (indices into [`Mesh::boundary_loop_list`] of each mesh).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoopMatch {
    /// The source's boundary loop.
    pub source: usize,
    /// The target's boundary loop.
    pub target: usize,
}

/// One constraint of a problem (module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum Constraint {
    /// A vertex held at a point.
    Pin(Pin),
    /// A vertex moved to a point, then held.
    Landmark(Landmark),
    /// A vertex sliding along a line.
    Slide(Slide),
    /// A chain onto a chain.
    Curve(Curve),
    /// A boundary loop onto a boundary loop.
    LoopMatch(LoopMatch),
    /// The image keeps the source surface's normals: the least-squares penalty
    /// `weight * sum |n_image - n_source|^2` (Gruber-Aulisa 2022, section 4.1).
    Normal {
        /// The penalty weight, `> 0`.
        weight: f64,
    },
    /// The image keeps the source surface's total area (Gruber-Aulisa 2022, section 4.2).
    Area,
    /// Target corner angles indexed by halfedge id: the angle of a face corner is stored
    /// at the halfedge leaving the corner's vertex inside the face, each in `(0, pi)`;
    /// entries of boundary halfedges are not read (Gruber-Aulisa 2022, section 6.2).
    ReferenceAngles(Vec<f64>),
}

/// The kinds of [`Constraint`], for capability listings and checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConstraintKind {
    /// [`Constraint::Pin`] without a position (held where the solver or initial map puts it).
    Hold,
    /// [`Constraint::Pin`] at a given point.
    Pin,
    /// [`Constraint::Landmark`].
    Landmark,
    /// [`Constraint::Slide`].
    Slide,
    /// [`Constraint::Curve`], open.
    OpenCurve,
    /// [`Constraint::Curve`], closed.
    ClosedCurve,
    /// [`Constraint::LoopMatch`].
    LoopMatch,
    /// [`Constraint::Normal`].
    Normal,
    /// [`Constraint::Area`].
    Area,
    /// [`Constraint::ReferenceAngles`].
    ReferenceAngles,
}

impl ConstraintKind {
    /// Every kind, in declaration order.
    pub const ALL: [ConstraintKind; 10] = [
        ConstraintKind::Hold,
        ConstraintKind::Pin,
        ConstraintKind::Landmark,
        ConstraintKind::Slide,
        ConstraintKind::OpenCurve,
        ConstraintKind::ClosedCurve,
        ConstraintKind::LoopMatch,
        ConstraintKind::Normal,
        ConstraintKind::Area,
        ConstraintKind::ReferenceAngles,
    ];

    /// The stable name in listings (`beltrami solvers --json`).
    pub fn name(self) -> &'static str {
        match self {
            ConstraintKind::Hold => "hold",
            ConstraintKind::Pin => "pin",
            ConstraintKind::Landmark => "landmark",
            ConstraintKind::Slide => "slide",
            ConstraintKind::OpenCurve => "open-curve",
            ConstraintKind::ClosedCurve => "closed-curve",
            ConstraintKind::LoopMatch => "loop-match",
            ConstraintKind::Normal => "normal",
            ConstraintKind::Area => "area",
            ConstraintKind::ReferenceAngles => "reference-angles",
        }
    }
}

impl fmt::Display for ConstraintKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Constraint {
    /// Its kind.
    pub fn kind(&self) -> ConstraintKind {
        match self {
            Constraint::Pin(Pin { position: None, .. }) => ConstraintKind::Hold,
            Constraint::Pin(_) => ConstraintKind::Pin,
            Constraint::Landmark(_) => ConstraintKind::Landmark,
            Constraint::Slide(_) => ConstraintKind::Slide,
            Constraint::Curve(c) if c.closed => ConstraintKind::ClosedCurve,
            Constraint::Curve(_) => ConstraintKind::OpenCurve,
            Constraint::LoopMatch(_) => ConstraintKind::LoopMatch,
            Constraint::Normal { .. } => ConstraintKind::Normal,
            Constraint::Area => ConstraintKind::Area,
            Constraint::ReferenceAngles(_) => ConstraintKind::ReferenceAngles,
        }
    }
}

/// Why a constraint is malformed; `index` is its position in the problem's list.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConstraintError {
    /// A vertex id outside the mesh.
    #[error(
        "constraint {index} ({kind}): {side} vertex {vertex} does not exist (the {side} mesh has {count} vertices)"
    )]
    MissingVertex {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
        /// Which mesh (`source` or `target`).
        side: &'static str,
        /// The vertex.
        vertex: VertexId,
        /// The number of vertices of that mesh.
        count: usize,
    },
    /// A point or direction with a NaN or infinite coordinate.
    #[error("constraint {index} ({kind}) on vertex {vertex}: the {what} is not finite")]
    NonFinite {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
        /// The vertex.
        vertex: VertexId,
        /// `point` or `direction`.
        what: &'static str,
    },
    /// A zero slide direction.
    #[error("constraint {index} (slide) on vertex {vertex}: the direction is zero")]
    ZeroDirection {
        /// The constraint's index.
        index: usize,
        /// The vertex.
        vertex: VertexId,
    },
    /// A vertex constrained twice by point constraints (pins, landmarks, slides).
    #[error(
        "constraint {index} ({kind}): vertex {vertex} is already constrained by constraint {first}"
    )]
    Repeated {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
        /// The vertex.
        vertex: VertexId,
        /// The constraint that came first.
        first: usize,
    },
    /// A curve chain that is too short.
    #[error(
        "constraint {index} ({kind}): the {side} chain has {got} vertices, at least {needed} are needed"
    )]
    ShortChain {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
        /// `source` or `target`.
        side: &'static str,
        /// Its length.
        got: usize,
        /// The least length (2 open, 3 closed).
        needed: usize,
    },
    /// A curve chain that visits a vertex twice.
    #[error(
        "constraint {index} ({kind}): the {side} chain visits vertex {vertex} twice (at positions {first} and {second}); a chain is a simple path, and a closed one does not repeat its first vertex at the end"
    )]
    RepeatedChainVertex {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
        /// `source` or `target`.
        side: &'static str,
        /// The vertex.
        vertex: VertexId,
        /// Its first position in the chain (0-based).
        first: usize,
        /// Its second position.
        second: usize,
    },
    /// A boundary loop index outside the mesh's loops.
    #[error(
        "constraint {index} (loop-match): the {side} has no boundary loop {boundary_loop} (it has {count})"
    )]
    MissingLoop {
        /// The constraint's index.
        index: usize,
        /// `source` or `target`.
        side: &'static str,
        /// The loop asked for.
        boundary_loop: usize,
        /// The number of boundary loops.
        count: usize,
    },
    /// A weight that is not in `(0, MAX_NORMAL_WEIGHT]`.
    #[error(
        "constraint {index} (normal): the weight must be > 0 and at most {MAX_NORMAL_WEIGHT} (a larger penalty drowns the conformal energy in rounding), got {weight}"
    )]
    Weight {
        /// The constraint's index.
        index: usize,
        /// The weight given.
        weight: f64,
    },
    /// Reference angles of the wrong count.
    #[error(
        "constraint {index} (reference-angles): {got} angles for {expected} halfedges (one per halfedge id)"
    )]
    AngleCount {
        /// The constraint's index.
        index: usize,
        /// Angles given.
        got: usize,
        /// Halfedges of the source.
        expected: usize,
    },
    /// A reference angle outside `(0, pi)`.
    #[error(
        "constraint {index} (reference-angles): the angle at corner {corner} is {angle}, not in (0, pi)"
    )]
    Angle {
        /// The constraint's index.
        index: usize,
        /// The corner's halfedge.
        corner: HalfedgeId,
        /// The angle given.
        angle: f64,
    },
    /// A constraint that needs a target mesh in a problem without one.
    #[error("constraint {index} ({kind}) refers to a target mesh, and the problem has none")]
    NoTargetMesh {
        /// The constraint's index.
        index: usize,
        /// Its kind.
        kind: ConstraintKind,
    },
}

/// The constraints of a problem, in the order given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Constraints {
    list: Vec<Constraint>,
}

impl Constraints {
    /// No constraints.
    pub fn new() -> Self {
        Self::default()
    }

    /// Holds every boundary vertex of `mesh` (all loops) at its point in `held` (one
    /// point of R^3 per mesh vertex, by [`VertexId`]): a [`Pin`] with a spatial position
    /// each, as a map into space with a prescribed boundary needs.
    pub fn hold_boundary(&mut self, mesh: &Mesh, held: &[Point3<f64>]) -> &mut Self {
        self.extend(
            mesh.boundary_loop_list()
                .into_iter()
                .flat_map(|l| l.vertices)
                .map(|v| {
                    Constraint::Pin(Pin {
                        vertex: v,
                        position: Some(Position::Spatial(held[v.idx()])),
                    })
                }),
        );
        self
    }

    /// Appends `constraint`.
    pub fn push(&mut self, constraint: Constraint) -> &mut Self {
        self.list.push(constraint);
        self
    }

    /// Every constraint, in order.
    pub fn iter(&self) -> impl Iterator<Item = &Constraint> {
        self.list.iter()
    }

    /// Number of constraints.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Removes every constraint for which `keep` is false.
    pub fn retain(&mut self, keep: impl FnMut(&Constraint) -> bool) {
        self.list.retain(keep);
    }

    /// The pins (held vertices, with or without a position), in order.
    pub fn pins(&self) -> impl Iterator<Item = &Pin> {
        self.list.iter().filter_map(|c| match c {
            Constraint::Pin(p) => Some(p),
            _ => None,
        })
    }

    /// The landmarks, in order.
    pub fn landmarks(&self) -> impl Iterator<Item = &Landmark> {
        self.list.iter().filter_map(|c| match c {
            Constraint::Landmark(l) => Some(l),
            _ => None,
        })
    }

    /// The slides, in order.
    pub fn slides(&self) -> impl Iterator<Item = &Slide> {
        self.list.iter().filter_map(|c| match c {
            Constraint::Slide(s) => Some(s),
            _ => None,
        })
    }

    /// The curves (open and closed), in order.
    pub fn curves(&self) -> impl Iterator<Item = &Curve> {
        self.list.iter().filter_map(|c| match c {
            Constraint::Curve(c) => Some(c),
            _ => None,
        })
    }

    /// The loop matches, in order.
    pub fn loop_matches(&self) -> impl Iterator<Item = &LoopMatch> {
        self.list.iter().filter_map(|c| match c {
            Constraint::LoopMatch(m) => Some(m),
            _ => None,
        })
    }

    /// The first constraint of `kind` with its index, if any.
    pub fn first_of(&self, kind: ConstraintKind) -> Option<(usize, &Constraint)> {
        self.list.iter().enumerate().find(|(_, c)| c.kind() == kind)
    }

    /// Checks what holds for every solver: referenced vertices and boundary loops exist
    /// (in `source`, and in `target` for the target side of curves, loop matches and
    /// target-vertex positions, which need a target mesh),
    /// points and directions are finite, slide directions are not zero, no vertex has two
    /// point constraints (pin, landmark, slide), open chains have at least 2 vertices and
    /// closed ones 3, a normal weight is positive, reference angles are one per face
    /// corner of `source` and lie in `(0, pi)`.
    pub fn validate(&self, source: &Mesh, target: Option<&Mesh>) -> Result<(), ConstraintError> {
        let mut point_constraint: Vec<Option<usize>> = vec![None; source.vertex_count()];
        for (index, constraint) in self.list.iter().enumerate() {
            let kind = constraint.kind();
            let check = Checked { index, kind };
            if let Some(v) = check.point_vertex(constraint, source, target)? {
                if let Some(first) = point_constraint[v.idx()] {
                    return Err(ConstraintError::Repeated {
                        index,
                        kind,
                        vertex: v,
                        first,
                    });
                }
                point_constraint[v.idx()] = Some(index);
            }
        }
        Ok(())
    }
}

/// The constraint [`Constraints::validate`] checks: its index in the list and its kind,
/// which the errors name.
#[derive(Clone, Copy)]
struct Checked {
    index: usize,
    kind: ConstraintKind,
}

impl Checked {
    /// Fails unless `vertex` is a vertex of `mesh` (`side` names the mesh in the error).
    fn exists(
        self,
        mesh: &Mesh,
        side: &'static str,
        vertex: VertexId,
    ) -> Result<(), ConstraintError> {
        if vertex.idx() < mesh.vertex_count() {
            Ok(())
        } else {
            Err(ConstraintError::MissingVertex {
                index: self.index,
                kind: self.kind,
                side,
                vertex,
                count: mesh.vertex_count(),
            })
        }
    }

    /// Fails unless `ok`, naming `what` at `vertex` as not finite.
    fn finite(self, vertex: VertexId, what: &'static str, ok: bool) -> Result<(), ConstraintError> {
        if ok {
            Ok(())
        } else {
            Err(ConstraintError::NonFinite {
                index: self.index,
                kind: self.kind,
                vertex,
                what,
            })
        }
    }

    /// Checks `constraint` on its own; returns the vertex it holds to a point (pin,
    /// landmark, slide), if any, for the check across constraints.
    fn point_vertex(
        self,
        constraint: &Constraint,
        source: &Mesh,
        target: Option<&Mesh>,
    ) -> Result<Option<VertexId>, ConstraintError> {
        let index = self.index;
        Ok(match constraint {
            Constraint::Pin(pin) => {
                self.exists(source, "source", pin.vertex)?;
                if let Some(p) = pin.position {
                    self.position(pin.vertex, p, target)?;
                }
                Some(pin.vertex)
            }
            Constraint::Landmark(mark) => {
                self.exists(source, "source", mark.vertex)?;
                self.position(mark.vertex, mark.position, target)?;
                Some(mark.vertex)
            }
            Constraint::Slide(slide) => {
                self.slide(slide, source)?;
                Some(slide.vertex)
            }
            Constraint::Curve(curve) => {
                self.curve(curve, source, target)?;
                None
            }
            Constraint::LoopMatch(m) => {
                self.loop_match(m, source, target)?;
                None
            }
            Constraint::Normal { weight } => {
                if !(*weight > 0.0 && *weight <= MAX_NORMAL_WEIGHT) {
                    return Err(ConstraintError::Weight {
                        index,
                        weight: *weight,
                    });
                }
                None
            }
            Constraint::Area => None,
            Constraint::ReferenceAngles(angles) => {
                self.reference_angles(angles, source)?;
                None
            }
        })
    }

    /// Where `vertex` must go: a finite point, or a vertex of the target mesh.
    fn position(
        self,
        vertex: VertexId,
        position: Position,
        target: Option<&Mesh>,
    ) -> Result<(), ConstraintError> {
        match position {
            Position::TargetVertex(w) => match target {
                Some(target) => self.exists(target, "target", w),
                None => Err(ConstraintError::NoTargetMesh {
                    index: self.index,
                    kind: self.kind,
                }),
            },
            p => self.finite(vertex, "point", p.is_finite()),
        }
    }

    /// A slide: its vertex exists and its direction is finite and not zero.
    fn slide(self, slide: &Slide, source: &Mesh) -> Result<(), ConstraintError> {
        self.exists(source, "source", slide.vertex)?;
        let (ok, zero) = match slide.direction {
            Direction::Planar(d) => (d.is_finite(), d.norm_sqr() == 0.0),
            Direction::Spatial(d) => (d.iter().all(|x| x.is_finite()), d.norm_squared() == 0.0),
        };
        self.finite(slide.vertex, "direction", ok)?;
        if zero {
            return Err(ConstraintError::ZeroDirection {
                index: self.index,
                vertex: slide.vertex,
            });
        }
        Ok(())
    }

    /// A curve: both chains long enough (2 vertices open, 3 closed), without a repeated
    /// vertex, their vertices existing in `source` and in `target` (`source` when there
    /// is none).
    fn curve(
        self,
        curve: &Curve,
        source: &Mesh,
        target: Option<&Mesh>,
    ) -> Result<(), ConstraintError> {
        let (index, kind) = (self.index, self.kind);
        let needed = if curve.closed { 3 } else { 2 };
        for (side, chain) in [("source", &curve.source), ("target", &curve.target)] {
            if chain.len() < needed {
                return Err(ConstraintError::ShortChain {
                    index,
                    kind,
                    side,
                    got: chain.len(),
                    needed,
                });
            }
        }
        for (side, chain) in [("source", &curve.source), ("target", &curve.target)] {
            let mut seen = std::collections::HashMap::with_capacity(chain.len());
            for (second, &vertex) in chain.iter().enumerate() {
                if let Some(first) = seen.insert(vertex, second) {
                    return Err(ConstraintError::RepeatedChainVertex {
                        index,
                        kind,
                        side,
                        vertex,
                        first,
                        second,
                    });
                }
            }
        }
        for &v in &curve.source {
            self.exists(source, "source", v)?;
        }
        let target_mesh = target.unwrap_or(source);
        for &v in &curve.target {
            self.exists(target_mesh, "target", v)?;
        }
        Ok(())
    }

    /// A loop match: a target mesh is given and both boundary loops exist.
    fn loop_match(
        self,
        m: &LoopMatch,
        source: &Mesh,
        target: Option<&Mesh>,
    ) -> Result<(), ConstraintError> {
        let Some(target) = target else {
            return Err(ConstraintError::NoTargetMesh {
                index: self.index,
                kind: self.kind,
            });
        };
        for (side, mesh, l) in [("source", source, m.source), ("target", target, m.target)] {
            let count = mesh.boundary_loop_count();
            if l >= count {
                return Err(ConstraintError::MissingLoop {
                    index: self.index,
                    side,
                    boundary_loop: l,
                    count,
                });
            }
        }
        Ok(())
    }

    /// Reference angles: one per halfedge of `source`, those of face corners in `(0, pi)`
    /// (the first one outside named, in face order).
    fn reference_angles(self, angles: &[f64], source: &Mesh) -> Result<(), ConstraintError> {
        let index = self.index;
        let corners: Vec<HalfedgeId> = source
            .faces()
            .flat_map(|f| source.face_halfedges(f))
            .collect();
        if angles.len() != source.halfedge_count() {
            return Err(ConstraintError::AngleCount {
                index,
                got: angles.len(),
                expected: source.halfedge_count(),
            });
        }
        for corner in corners {
            let angle = angles[corner.idx()];
            if !(angle > 0.0 && angle < std::f64::consts::PI) {
                return Err(ConstraintError::Angle {
                    index,
                    corner,
                    angle,
                });
            }
        }
        Ok(())
    }
}

impl FromIterator<Constraint> for Constraints {
    fn from_iter<I: IntoIterator<Item = Constraint>>(iter: I) -> Self {
        Self {
            list: iter.into_iter().collect(),
        }
    }
}

impl From<Vec<Pin>> for Constraints {
    fn from(pins: Vec<Pin>) -> Self {
        pins.into_iter().map(Constraint::Pin).collect()
    }
}

impl From<Vec<Curve>> for Constraints {
    fn from(curves: Vec<Curve>) -> Self {
        curves.into_iter().map(Constraint::Curve).collect()
    }
}

impl Extend<Constraint> for Constraints {
    fn extend<I: IntoIterator<Item = Constraint>>(&mut self, iter: I) {
        self.list.extend(iter);
    }
}

impl Position {
    /// True if every coordinate is finite (a target vertex has none).
    pub fn is_finite(&self) -> bool {
        match self {
            Position::Planar(z) => z.is_finite(),
            Position::Spatial(p) => p.iter().all(|x| x.is_finite()),
            Position::TargetVertex(_) => true,
        }
    }

    /// The point in R^3: `(x, y, 0)` for a planar position, the vertex's position on
    /// `target` for a target vertex (`None` without a target mesh or for a vertex it
    /// does not have).
    pub fn point(&self, target: Option<&Mesh>) -> Option<Point3<f64>> {
        match *self {
            Position::Planar(z) => Some(Point3::new(z.re, z.im, 0.0)),
            Position::Spatial(p) => Some(p),
            Position::TargetVertex(w) => target
                .filter(|t| w.idx() < t.vertex_count())
                .map(|t| t.position(w)),
        }
    }
}
