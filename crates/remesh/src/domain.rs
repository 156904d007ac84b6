//! The parameter domain: the chart laid out in the plane, for point location, and the
//! lift of a point of the domain onto the surface.
//!
//! A point `q` of the domain lies in one image face `f` with coordinates `w_i` (the
//! barycentric coordinates of `q` in the image triangle, or the bilinear weights of an
//! image quad); its lift is the surface point `sum_i w_i p_i` of the same face with the
//! same coordinates. The lift is exact on the input surface: the lifted point lies on
//! face `f` of the input, and a planar input stays in its plane.
//!
//! Point location walks from a hint face (a face near `q`, typically that of a
//! neighbouring vertex of the new triangulation) across the edge that separates the
//! face from `q`, until a face contains `q` (a visibility walk: O. Devillers, S. Pion,
//! M. Teillaud, "Walking in a triangulation", SoCG 2001). A conformal map shrinks parts
//! of a surface by orders of magnitude (a hand's finger tips against its palm), so the
//! parameter faces differ as much in size, and the kd-tree of
//! [`SurfaceIndex`] must then search a ball as large as the largest face around every
//! point; the walk visits only the faces between the hint and `q`. A walk that leaves
//! the domain, or does not arrive within [`MAX_WALK`] faces, falls back to the index.

use beltrami_mesh::{BuildOptions, FaceId, Mesh, Point3, PolygonSoup, Repair, SurfacePoint};
use beltrami_spatial::SurfaceIndex;
use beltrami_spatial::closest_point::closest_on_face;
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
    /// outside the domain. `hint`: a chart face near `q`, where the search starts.
    pub fn lift(
        &self,
        q: Complex64,
        hint: Option<FaceId>,
    ) -> Result<Option<(SurfacePoint, Point3<f64>)>, RemeshError> {
        let point = match self.walk(q, hint) {
            Some(point) => point,
            None => {
                let located = self.index.locate(&Point3::new(q.re, q.im, 0.0))?;
                if located.distance > self.tolerance {
                    return Ok(None);
                }
                located.point
            }
        };
        Ok(Some((point, point.position(self.chart))))
    }

    /// The chart point over the point of the domain closest to `q`, and its position.
    /// `hint` as in [`Domain::lift`].
    pub fn lift_closest(
        &self,
        q: Complex64,
        hint: Option<FaceId>,
    ) -> Result<(SurfacePoint, Point3<f64>), RemeshError> {
        let point = match self.walk(q, hint) {
            Some(point) => point,
            None => self.index.locate(&Point3::new(q.re, q.im, 0.0))?.point,
        };
        Ok((point, point.position(self.chart)))
    }

    /// The face containing `q` and `q`'s coordinates in it, found by walking from
    /// `hint` (module docs); `None` when the walk leaves the domain or gives up.
    fn walk(&self, q: Complex64, hint: Option<FaceId>) -> Option<SurfacePoint> {
        let planar = self.index.mesh();
        let mut face = hint.filter(|f| f.idx() < planar.face_count())?;
        let xy = |h| {
            let p = planar.position(planar.origin(h));
            Complex64::new(p.x, p.y)
        };
        for _ in 0..MAX_WALK {
            let corners: [Complex64; 4] = {
                let mut c = [Complex64::new(0.0, 0.0); 4];
                for (slot, h) in c.iter_mut().zip(planar.face_halfedges(face)) {
                    *slot = xy(h);
                }
                c
            };
            let n = planar.face_degree(face);
            // Twice the signed area: the walk's sides follow the face's own orientation.
            let orientation = (0..n)
                .map(|k| cross(corners[k], corners[(k + 1) % n]))
                .sum::<f64>()
                .signum();
            let exit = planar.face_halfedges(face).zip(0..n).find(|&(_, k)| {
                let (a, b) = (corners[k], corners[(k + 1) % n]);
                orientation * cross(b - a, q - a) < 0.0
            });
            match exit {
                None => {
                    let c = closest_on_face(planar, face, &Point3::new(q.re, q.im, 0.0));
                    return (c.distance() <= self.tolerance).then_some(SurfacePoint {
                        face,
                        coords: c.coords,
                    });
                }
                Some((h, _)) => face = planar.face(planar.twin(h))?,
            }
        }
        None
    }
}

/// Faces a walk visits at most before the kd-tree takes over.
pub const MAX_WALK: usize = 256;

/// `Im(conj(a) b)`, twice the signed area of the triangle `0, a, b`.
pub(crate) fn cross(a: Complex64, b: Complex64) -> f64 {
    a.re * b.im - a.im * b.re
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::disk;

    #[test]
    fn the_walk_finds_what_the_index_finds() {
        // The unit disk laid out by `exp(2.5 z)` (one to one: `|Im 2.5 z| < pi`): faces
        // near `z = -1` are 150 times smaller than near `z = 1`, as a conformal map
        // shrinks a finger against a palm.
        let chart = Mesh::from_soup(&disk(5)).unwrap();
        let uv: Vec<Complex64> = chart
            .positions()
            .iter()
            .map(|p| (2.5 * Complex64::new(p.x, p.y)).exp())
            .collect();
        let planar = planar_mesh(&chart, &uv).unwrap();
        let domain = Domain::new(&chart, &planar).unwrap();
        let faces = chart.face_count() as u32;
        let mut inside = 0;
        for k in 0..2000u32 {
            // Points on a spiral through and around the domain, hints anywhere.
            let t = k as f64 * 0.0137;
            let q = (2.5 * Complex64::from_polar(1.3 * t.sin().abs(), 7.0 * t)).exp();
            let hint = Some(FaceId(k.wrapping_mul(2_654_435_761) % faces));
            let walked = domain.lift(q, hint).unwrap();
            let searched = domain.lift(q, None).unwrap();
            match (walked, searched) {
                (Some((_, a)), Some((_, b))) => {
                    assert!((a - b).norm() < 1e-12, "{q}: {a} against {b}");
                    inside += 1;
                }
                (None, None) => {}
                _ => panic!("{q}: inside for one search only"),
            }
            let (_, a) = domain.lift_closest(q, hint).unwrap();
            let (_, b) = domain.lift_closest(q, None).unwrap();
            assert!((a - b).norm() < 1e-12, "closest to {q}: {a} against {b}");
        }
        assert!(inside > 500, "{inside} points inside");
    }
}
