//! The parameter domain: the chart laid out in the plane, for point location, and the
//! lift of a point of the domain onto the surface.
//!
//! A point `q` of the domain lies in one image face `f` with coordinates `w_i` (the
//! barycentric coordinates of `q` in the image triangle, or the bilinear weights of an
//! image quad); its lift is the surface point `sum_i w_i p_i` of the same face with the
//! same coordinates. The lift is exact on the input surface: the lifted point lies on
//! face `f` of the input, and a planar input stays in its plane.

use beltrami_mesh::{BuildOptions, Mesh, Point3, PolygonSoup, Repair, SurfacePoint};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::RemeshError;

/// The image of a chart in the plane (positions `(u, v, 0)`, the chart's faces with the
/// same ids and first vertices).
pub fn planar_mesh(chart: &Mesh, uv: &[Complex64]) -> Result<Mesh, RemeshError> {
    let positions = uv.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect();
    let mut soup = PolygonSoup::new(positions);
    let mut face = Vec::with_capacity(4);
    for f in chart.faces() {
        face.clear();
        face.extend(chart.face_vertices(f).map(|v| v.0));
        soup.push_face(&face);
    }
    // The faces are the chart's, already validated, and none is folded: accept every
    // area, however small its image.
    let options = BuildOptions {
        degenerate_area_tolerance: -1.0,
        repair: Repair::NONE,
    };
    Mesh::build(&soup, &options)
        .map(|(mesh, _)| mesh)
        .map_err(|error| RemeshError::Build {
            what: "parameter-domain mesh",
            error,
        })
}

/// Point location in the parameter domain and lifting onto the chart.
pub struct Domain<'m> {
    chart: &'m Mesh,
    index: SurfaceIndex<'m>,
    tolerance: f64,
}

impl<'m> Domain<'m> {
    /// The domain of `planar` (from [`planar_mesh`]) over `chart`.
    pub fn new(chart: &'m Mesh, planar: &'m Mesh) -> Result<Self, RemeshError> {
        let index = SurfaceIndex::new(planar)?;
        // Rounding of the closest-point computation, relative to the domain's size.
        let tolerance = 1e-10 * planar.bounding_box().diagonal();
        Ok(Self {
            chart,
            index,
            tolerance,
        })
    }

    /// The chart point over `q` and its position on the surface, or `None` if `q` lies
    /// outside the domain.
    pub fn lift(&self, q: Complex64) -> Result<Option<(SurfacePoint, Point3<f64>)>, RemeshError> {
        let located = self.index.locate(&Point3::new(q.re, q.im, 0.0))?;
        if located.distance > self.tolerance {
            return Ok(None);
        }
        Ok(Some((located.point, located.point.position(self.chart))))
    }

    /// The chart point over the point of the domain closest to `q`, and its position.
    pub fn lift_closest(&self, q: Complex64) -> Result<(SurfacePoint, Point3<f64>), RemeshError> {
        let located = self.index.locate(&Point3::new(q.re, q.im, 0.0))?;
        Ok((located.point, located.point.position(self.chart)))
    }
}
