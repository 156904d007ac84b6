//! One chart laid flat: cones placed ([`crate::cones`]), the chart cut open through them
//! ([`crate::cone_cut`]), the disk flattened ([`crate::boundary_first`]) and checked
//! ([`crate::overlap`]).

use beltrami_mesh::{Mesh, VertexId, cut_along};

use crate::AtlasError;
use crate::boundary_first::{FlattenFailure, flatten_disk};
use crate::cone_cut::cone_cut;
use crate::cones::{ConeGoal, place_cones};
use crate::overlap::folded_faces;
use beltrami_mesh::closed_curve::crosses_itself;

/// A chart laid flat.
#[derive(Debug, Clone)]
pub struct FlatChart {
    /// The chart cut open into a disk (faces in the chart's order).
    pub disk: Mesh,
    /// For each vertex of the disk, the chart vertex it is a copy of.
    pub to_chart: Vec<VertexId>,
    /// The flat position of each vertex of the disk, at the surface's scale.
    pub uv: Vec<[f64; 2]>,
    /// The cones, as chart vertices.
    pub cones: Vec<VertexId>,
}

/// Why a chart must be split before it can be laid flat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChartFailure {
    /// The flattening could not be built.
    Flatten(FlattenFailure),
    /// Faces came out with a non-positive area.
    Flipped(usize),
    /// The boundary of the flat chart crosses itself.
    Overlap,
}

/// Lays `chart` (one connected triangle mesh) flat with cones placed for `goal`.
pub fn flatten_chart(
    chart: &Mesh,
    goal: ConeGoal,
) -> Result<Result<FlatChart, ChartFailure>, AtlasError> {
    let cones = place_cones(chart, goal)?;
    let cut = cone_cut(chart, &cones.vertices);
    let (disk, to_chart) = cut_along(chart, &cut)?;
    let scale: Vec<f64> = to_chart.iter().map(|v| cones.scale[v.idx()]).collect();
    let uv = match flatten_disk(&disk, &scale)? {
        Ok(uv) => uv,
        Err(failure) => return Ok(Err(ChartFailure::Flatten(failure))),
    };
    let flipped = folded_faces(&disk, &uv);
    if flipped > 0 {
        return Ok(Err(ChartFailure::Flipped(flipped)));
    }
    let ring: Vec<[f64; 2]> = disk
        .boundary_loops()
        .next()
        .map(|b| disk.loop_vertices(b).map(|v| uv[v.idx()]).collect())
        .unwrap_or_default();
    if crosses_itself(&ring) {
        return Ok(Err(ChartFailure::Overlap));
    }
    Ok(Ok(FlatChart {
        disk,
        to_chart,
        uv,
        cones: cones.vertices,
    }))
}
