//! Landmarks and feature curves that no bijection can honour, refused before any work.
//!
//! [`beltrami_core::Constraints::validate`] checks each constraint on its own (ids,
//! finiteness, a vertex constrained twice). A registration also needs them to agree:
//!
//! - two landmarks onto one target point would make the map non-injective;
//! - a landmark point far from the target (more than [`crate::landmarks::FAR_OFF`] of the target's
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

use beltrami_core::{Landmark, Problem};
use beltrami_mesh::{Mesh, VertexId};
use beltrami_spatial::SurfaceIndex;

use crate::error::RegisterError;

/// Checks that the problem's landmarks and curves can be honoured together by a
/// bijection onto `target` (module docs).
pub(crate) fn check(problem: &Problem<'_>, target: &Mesh) -> Result<(), RegisterError> {
    let marks: Vec<Landmark> = problem.constraints.landmarks().copied().collect();
    if !marks.is_empty() {
        let index = SurfaceIndex::new(target)?;
        let resolved = crate::landmarks::resolve(problem.source, target, &index, &marks)?;
        if matches!(
            crate::Shape::of(problem.source).topology(),
            Some(crate::Topology::MultiplyConnected | crate::Topology::HigherGenus)
        ) && problem.source.boundary_loop_count() > 0
        {
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
