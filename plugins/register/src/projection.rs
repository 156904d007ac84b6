//! A second candidate for the initial map of closed surfaces that lie close to each other
//! in space (a remeshed or slightly moved copy): every source vertex onto the target point
//! closest to its placed position.
//!
//! A map of a closed connected surface onto another of the same genus `g >= 2` (the
//! only closed surfaces that come here) that flips no face is a local homeomorphism,
//! hence a covering, of degree `chi(S) / chi(T) = 1` since `chi = 2 - 2g` is not 0: a
//! bijection. So the projection is kept only when no face is
//! flipped (judged as every initial map is, against the target's normals at the images),
//! and only when it beats the matched-cut map: fewer flips, or as few and a smaller mean
//! |mu|. On meshes of one surface it is close to the identity, where the cut map's
//! Tutte embeddings crowd faces into corners far from the cut and the flow may not undo
//! every flip there. Landmarks and boundary loops keep the cut map (the projection
//! honours neither).

use beltrami_mesh::{Mesh, Point3, SurfacePoint};
use beltrami_spatial::SurfaceIndex;

use crate::compose;
use crate::error::RegisterError;
use crate::landmarks::SpatialMatch;

/// The projection of `source` onto `target` when it is a flip-free map better than the
/// matched cuts' map `cut` (module docs) or when that failed, else `cut` (its error when
/// it failed); a note says which.
pub(crate) fn better(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    cut: Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError>,
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError> {
    let place = SpatialMatch::new(source, target);
    let placed: Vec<Point3<f64>> = source
        .positions()
        .iter()
        .map(|p| place.to_target(p))
        .collect();
    let projected: Vec<SurfacePoint> = target_index
        .locate_all(&placed)?
        .into_iter()
        .map(|l| l.point)
        .collect();
    let positions = |points: &[SurfacePoint]| -> Vec<Point3<f64>> {
        points.iter().map(|p| p.position(target)).collect()
    };
    let by_projection =
        compose::distortion(source, target_index, &projected, &positions(&projected))?;
    if by_projection.flipped > 0 {
        return cut;
    }
    let instead = match cut {
        Ok(cut) => {
            let by_cut = compose::distortion(source, target_index, &cut.0, &positions(&cut.0))?;
            if by_cut.flipped == 0 && by_cut.mu_mean <= by_projection.mu_mean {
                return Ok(cut);
            }
            format!(
                "the matched cuts' map ({} flipped, mean |mu| {:.4})",
                by_cut.flipped, by_cut.mu_mean
            )
        }
        Err(error) => format!("the matched cuts, which failed ({error})"),
    };
    notes.push(format!(
        "initial map: the closest points of the placed source (no flipped face, mean |mu| {:.4}) instead of {instead}; a flip-free map between closed surfaces of one genus >= 2 is a bijection",
        by_projection.mu_mean
    ));
    Ok((projected, Vec::new()))
}
