//! Landmarks and feature curves that no bijection can honour, refused before any work.
//!
//! [`beltrami_core::Constraints::validate`] checks each constraint on its own (ids,
//! finiteness, a vertex constrained twice). A registration also needs them to agree:
//!
//! - two landmarks onto one target point would make the map non-injective;
//! - a landmark point far from the target (more than [`FAR_OFF`] of the target's
//!   bounding-box diagonal from its closest point) is almost surely a point of another
//!   mesh or in other units, and silently snapping it would hide that;
//! - feature curves (a source chain onto a target chain, Wong-Zhao 2014 section 5.3)
//!   must meet on both sides or on neither: chains that share a vertex on one mesh and
//!   none on the other cross on one side only, and a bijection maps crossing curves to
//!   crossing curves;
//! - on a mesh with several boundary loops or handles, a landmark on a boundary loop
//!   must go onto a boundary loop, each loop onto one loop, and the landmarks along
//!   paired loops must come in the same cyclic order
//!   ([`crate::routing::check_boundary_landmarks`]).

use beltrami_core::Problem;
use beltrami_mesh::{Mesh, VertexId};
use beltrami_spatial::SurfaceIndex;

use crate::error::RegisterError;
use crate::landmarks::SAME_POINT;

/// The largest distance of a landmark point from the target, relative to the target's
/// bounding-box diagonal.
pub(crate) const FAR_OFF: f64 = 0.05;

/// Checks that the problem's landmarks and curves can be honoured together by a
/// bijection onto `target` (module docs).
pub(crate) fn check(problem: &Problem<'_>, target: &Mesh) -> Result<(), RegisterError> {
    let diagonal = target.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    let marks: Vec<_> = problem.constraints.landmarks().collect();
    if !marks.is_empty() {
        let index = SurfaceIndex::new(target)?;
        let mut located = Vec::with_capacity(marks.len());
        let mut points = Vec::with_capacity(marks.len());
        for (i, mark) in marks.iter().enumerate() {
            let p = mark.position.to_point();
            let found = index.locate(&p)?;
            if found.distance > FAR_OFF * diagonal {
                return Err(RegisterError::Landmark {
                    index: i,
                    vertex: mark.vertex,
                    reason: format!(
                        "its point ({}, {}, {}) is {:.4e} from the target, more than {:.0}% of the target's size ({:.4e}): is it a point of the target mesh, in its units?",
                        p.x,
                        p.y,
                        p.z,
                        found.distance,
                        100.0 * FAR_OFF,
                        diagonal
                    ),
                });
            }
            let q = found.position;
            located.push(q);
            points.push(found.point);
        }
        if let Some((j, i)) = crate::landmarks::coincident(&located, SAME_POINT * diagonal) {
            return Err(crate::landmarks::same_point(
                i,
                marks[i].vertex,
                j,
                marks[j].vertex,
            ));
        }
        if matches!(
            crate::Shape::of(problem.source).topology(),
            Some(crate::Topology::MultiplyConnected | crate::Topology::HigherGenus)
        ) && problem.source.boundary_loop_count() > 0
        {
            let resolved: Vec<crate::landmarks::Resolved> = marks
                .iter()
                .zip(points)
                .enumerate()
                .map(|(i, (mark, target))| crate::landmarks::Resolved {
                    index: i,
                    source: mark.vertex,
                    target,
                    vertex: None,
                })
                .collect();
            crate::routing::check_boundary_landmarks(problem.source, target, &resolved)?;
        }
    }
    let curves: Vec<_> = problem.constraints.curves().collect();
    for (i, a) in curves.iter().enumerate() {
        for (j, b) in curves.iter().enumerate().skip(i + 1) {
            let (side, vertex, other) =
                match (shared(&a.source, &b.source), shared(&a.target, &b.target)) {
                    (Some(v), None) => ("source", v, "target"),
                    (None, Some(v)) => ("target", v, "source"),
                    _ => continue,
                };
            return Err(RegisterError::Curves {
                first: i,
                second: j,
                side,
                vertex,
                other,
            });
        }
    }
    Ok(())
}

/// A vertex on both chains.
fn shared(a: &[VertexId], b: &[VertexId]) -> Option<VertexId> {
    a.iter().copied().find(|v| b.contains(v))
}
