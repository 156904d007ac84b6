//! Closed genus 0: both meshes onto the unit sphere with the `sphere` initialization of
//! `beltrami-init` (Tutte embedding of the mesh minus one face, inverse stereographic
//! projection, Moebius centering), the source's sphere aligned with the target's, and
//! the source's images located radially in the target's sphere polyhedron
//! ([`crate::compose::locate_radial`]).
//!
//! Alignment (applied to the source's sphere positions):
//!
//! - no landmark: the rotation `R` minimizing `sum_i |R S_i - T(q_i)|^2` over (up to
//!   4096 evenly picked) source vertices, `S_i` a source vertex's sphere position and
//!   `T(q_i)` the target's sphere position at the spatial partner `q_i` of that vertex
//!   (the closest point of the target after centring and scaling, no rotation in space);
//! - one landmark: that rotation, then the smallest rotation taking the landmark's image
//!   onto its target's sphere position (exact);
//! - two or more: the Moebius transformation taking the first three landmarks' images
//!   onto their targets' (exact); with two, the third pair is the poles of the great
//!   circles through the two, so the transformation fixes the pole and slides along
//!   the circle. Further landmarks are left to the flow (their distances are noted).

use beltrami_core::{Context, Map, Problem, Solver, SolverError, Target};
use beltrami_init::Sphere;
use beltrami_mesh::{Mesh, Point3, SurfacePoint, Vector3};
use beltrami_spatial::SurfaceIndex;

use crate::compose;
use crate::error::{RegisterError, Side};
use crate::landmarks::{
    Moebius, Resolved, SpatialMatch, best_rotation, interpolate, rotation_between,
};
use crate::param::{domain_mesh, each_mesh};

/// Source vertices used by the rotation fit at most.
const FIT_SAMPLES: usize = 4096;

/// The source's images on the target and the landmarks honoured exactly (indices into
/// `marks`).
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError> {
    // The two sphere maps are independent: computed at once, on two cores.
    let (source_sphere, target_sphere) = each_mesh(source, target, notes, sphere)?;
    let target_at =
        |p: &SurfacePoint| -> Vector3<f64> { interpolate(target, &target_sphere, p).normalize() };

    let fit = || -> Result<nalgebra::Matrix3<f64>, RegisterError> {
        let spatial = SpatialMatch::new(source, target);
        let step = source.vertex_count().div_ceil(FIT_SAMPLES).max(1);
        let mut pairs = Vec::new();
        for v in source.vertices().step_by(step) {
            let partner = target_index.locate(&spatial.to_target(&source.position(v)))?;
            pairs.push((source_sphere[v.idx()], target_at(&partner.point)));
        }
        Ok(best_rotation(&pairs))
    };

    let (images, honoured): (Vec<Vector3<f64>>, Vec<usize>) = match marks {
        [] => {
            let r = fit()?;
            notes.push(
                "sphere: no landmark; source sphere rotated to match a rough spatial correspondence (centroids and sizes)"
                    .to_string(),
            );
            (source_sphere.iter().map(|s| r * s).collect(), Vec::new())
        }
        [mark] => {
            let r0 = fit()?;
            let r = rotation_between(
                &(r0 * source_sphere[mark.source.idx()]),
                &target_at(&mark.target),
            ) * r0;
            notes.push(format!(
                "sphere: rotated so that landmark {} lands on its target, the rest by a rough spatial correspondence",
                mark.index
            ));
            (source_sphere.iter().map(|s| r * s).collect(), vec![0])
        }
        _ => {
            let s: Vec<Vector3<f64>> = marks
                .iter()
                .map(|m| source_sphere[m.source.idx()])
                .collect();
            let t: Vec<Vector3<f64>> = marks.iter().map(|m| target_at(&m.target)).collect();
            let (from, to, used) = if marks.len() == 2 {
                let pole = |a: &Vector3<f64>, b: &Vector3<f64>| {
                    let c = a.cross(b);
                    if c.norm() > 0.0 { c.normalize() } else { c }
                };
                (
                    [s[0], s[1], pole(&s[0], &s[1])],
                    [t[0], t[1], pole(&t[0], &t[1])],
                    2,
                )
            } else {
                ([s[0], s[1], s[2]], [t[0], t[1], t[2]], 3)
            };
            let moebius = Moebius::through(from, to).ok_or_else(|| RegisterError::Landmark {
                index: marks[1].index,
                vertex: marks[1].source,
                reason: "its position on the sphere coincides with (or is opposite to) another landmark's, so no Moebius transformation takes the landmarks onto their targets".to_string(),
            })?;
            notes.push(format!(
                "sphere: Moebius transformation taking landmarks {} onto their targets",
                marks[..used]
                    .iter()
                    .map(|m| m.index.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
            (
                source_sphere
                    .iter()
                    .map(|p| moebius.apply(p).normalize())
                    .collect(),
                (0..used).collect(),
            )
        }
    };

    let domain = domain_mesh(
        target,
        target_sphere.iter().map(|v| Point3::from(*v)).collect(),
        Side::Target,
    )?;
    let points: Vec<Point3<f64>> = images.iter().map(|v| Point3::from(*v)).collect();
    let (located, fallbacks) = compose::locate_radial(&domain, &points)?;
    if fallbacks > 0 {
        notes.push(format!(
            "sphere: {fallbacks} source images were located by closest point instead of along the ray (quads or a target sphere map with inward faces)"
        ));
    }
    Ok((located, honoured))
}

/// The `sphere` initialization of `mesh` as unit vectors, its notes added to `notes`.
fn sphere(
    mesh: &Mesh,
    side: Side,
    notes: &mut Vec<String>,
) -> Result<Vec<Vector3<f64>>, RegisterError> {
    let mut problem = Problem::new(mesh, Target::Sphere);
    // The Tutte start, which the registration was tuned from: the sphere solver's default
    // conformal start gives a near-conformal initial map, from which the flow's
    // objective no longer halves mean |mu| (issue 12; switching is a separate change).
    problem.options.set_text("start", "tutte");
    let solution = Sphere
        .solve(&problem, &mut Context::new())
        .map_err(|error| RegisterError::Sphere { side, error })?;
    notes.extend(
        solution
            .report
            .notes
            .iter()
            .map(|n| format!("sphere map of the {side}: {n}")),
    );
    match solution.map() {
        Some(Map::Spatial(points)) => Ok(points.iter().map(|p| p.coords.normalize()).collect()),
        _ => Err(RegisterError::Sphere {
            side,
            error: SolverError::InvalidInput {
                solver: "sphere",
                message: "the sphere initialization returned no positions in space".to_string(),
            },
        }),
    }
}
