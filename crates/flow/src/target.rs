//! The geometry of a fixed target domain, as the flow sees it.
//!
//! The flow moves the image `Y_i` of every source vertex by a tangent vector of the
//! target (Wong-Zhao 2014, section 4.5): a vertex with [`Role::Free`] moves in the
//! target's tangent plane at `Y_i` (two unknowns), a vertex with [`Role::Curve`] along
//! the tangent of a boundary curve (one unknown), a [`Role::Fixed`] vertex not at all.
//! After each step a curve vertex slides along its curve by its move
//! ([`TargetGeometry::slide`]; at a corner of a polyline, along the side its move points
//! into, [`TargetGeometry::curve_corner`]) and [`TargetGeometry::project`] puts every
//! image back onto the target (the surface, or its boundary curve). A curve may have a free normal offset (the
//! inner circle of an annulus whose radius is an unknown): one more unknown shared by the
//! vertices on it, moving them along [`TargetGeometry::curve_offset_direction`].
//!
//! Orientation: [`TargetGeometry::normal`] is the side a counter-clockwise source face
//! must face once mapped; an image face turning the other way is flipped. A free vertex
//! moves in the plane orthogonal to the normal at its image, along the positively
//! oriented basis [`orthonormal_basis`] of that plane.

use beltrami_core::SolverError;
use beltrami_mesh::{Point3, Vector3};
use beltrami_spatial::closest_point::closest_on_segment;

/// How a vertex may move on the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Anywhere on the target surface (two tangent unknowns).
    Free,
    /// Along boundary curve `c` of the target (one unknown).
    Curve(usize),
    /// Held where it is (a pin or a polygon corner).
    Fixed,
}

/// A target domain of the flow: its normals, tangents, boundary curves and projections.
pub trait TargetGeometry: Clone {
    /// The unit normal at `p` (the orientation reference).
    fn normal(&self, p: &Point3<f64>) -> Vector3<f64>;

    /// The unit tangent of boundary curve `curve` at `p`.
    fn curve_tangent(&self, curve: usize, p: &Point3<f64>) -> Vector3<f64>;

    /// The unit tangents `[behind, ahead]` of curve `curve` on either side of `p` when
    /// `p` is a corner of it (two pieces meeting at an angle), both along the curve's
    /// orientation: a move forward from `p` follows `ahead`, a move back `behind`.
    /// `None` where the curve is smooth (the default).
    fn curve_corner(&self, _curve: usize, _p: &Point3<f64>) -> Option<[Vector3<f64>; 2]> {
        None
    }

    /// `p`, a point of curve `curve`, moved along the curve by `d`, a tangent of the
    /// curve at `p` (at a corner, of the side it points to). The default projects
    /// `p + d` onto the curve; a polyline walks `|d|` along itself instead, so that a
    /// point past a corner goes on along the next segment as far as the step asked.
    fn slide(&self, curve: usize, p: &Point3<f64>, d: &Vector3<f64>) -> Point3<f64> {
        self.project(Role::Curve(curve), &(p + d))
    }

    /// The unit outward direction of the target's boundary where the image `p` of free
    /// vertex `vertex` touches it, `None` where it does not (the default: targets whose
    /// free vertices cannot reach a boundary). A free vertex there that the flow pushes
    /// outwards slides along the boundary instead (its outward part is lost), which the
    /// flow models as a contact ([`crate::system::FlowSystem::solve`]).
    fn boundary_outward(&self, _vertex: usize, _p: &Point3<f64>) -> Option<Vector3<f64>> {
        None
    }

    /// The direction a free offset of `curve` moves its points at `p`, or `None` when
    /// the curve is fixed (the default).
    fn curve_offset_direction(&self, _curve: usize, _p: &Point3<f64>) -> Option<Vector3<f64>> {
        None
    }

    /// Moves `curve` by `delta` along its offset direction (curves with a free offset
    /// only; others ignore it).
    fn offset_curve(&mut self, _curve: usize, _delta: f64) {}

    /// The number of boundary curves.
    fn curve_count(&self) -> usize;

    /// Whether a point moved along a curve's tangent can leave the curve (a circle), so
    /// that its projection back must be spread into the interior; false for straight
    /// curves.
    fn curved(&self) -> bool {
        true
    }

    /// How far from its curves a [`curved`](TargetGeometry::curved) target's
    /// projection correction is spread ([`crate::extension`]): over the whole interior
    /// (`None`, the default: a smooth curve such as a circle pulls every boundary vertex
    /// a stepped tangent moves, and the interior must follow as a whole), or over that
    /// many rings of edges next to the boundary.
    fn correction_rings(&self) -> Option<usize> {
        None
    }

    /// The point of the target (for [`Role::Free`]) or of its curve (for
    /// [`Role::Curve`]) nearest to `p`; [`Role::Fixed`] points are returned unchanged.
    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64>;

    /// Called once per flow step, before the step sizes are tried, with the images the
    /// step starts from (targets that locate points in a mesh locate them once here).
    fn prepare_step(&self, _from: &[Point3<f64>]) -> Result<(), SolverError> {
        Ok(())
    }

    /// [`TargetGeometry::project`] of every point by its role, and into `normals` the
    /// target's unit normal at each projected point (free vertices move in the plane
    /// orthogonal to it; image faces are oriented by it). `from`, when given, holds
    /// where each point was on the target before it moved to `points` (a flow step):
    /// targets that locate points in a mesh override this to batch the work and to walk
    /// free points along the surface from there instead of projecting from far away.
    fn project_all(
        &self,
        roles: &[Role],
        _from: Option<&[Point3<f64>]>,
        points: &mut [Point3<f64>],
        normals: &mut Vec<Vector3<f64>>,
    ) -> Result<(), SolverError> {
        normals.clear();
        for (p, &role) in points.iter_mut().zip(roles) {
            *p = self.project(role, p);
            normals.push(self.normal(p));
        }
        Ok(())
    }
}

/// A positively oriented orthonormal basis `(u, v)` of the plane orthogonal to the unit
/// vector `n` (`u x v = n`), continuous away from `n = -e_z`.
pub fn orthonormal_basis(n: &Vector3<f64>) -> [Vector3<f64>; 2] {
    // Frisvad's construction with the branch at the south pole (Duff et al. 2017).
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        Vector3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vector3::new(b, sign + n.y * n.y * a, -n.y),
    ]
}

/// A straight side of a planar region, from corner `a` to corner `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Side {
    /// Start corner.
    pub a: Point3<f64>,
    /// End corner.
    pub b: Point3<f64>,
}

impl Side {
    fn closest(&self, p: &Point3<f64>) -> Point3<f64> {
        closest_on_segment(p, &self.a, &self.b).position
    }
}

/// A polygonal region of the plane z = 0 (possibly with holes): its boundary is a set of
/// straight [`Side`]s between corners. Boundary points slide along their side; corners
/// stay. Curve `c` is side `c`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneRegion {
    /// The sides, one curve each.
    pub sides: Vec<Side>,
}

impl TargetGeometry for PlaneRegion {
    fn normal(&self, _p: &Point3<f64>) -> Vector3<f64> {
        Vector3::z()
    }

    fn curve_tangent(&self, curve: usize, _p: &Point3<f64>) -> Vector3<f64> {
        let s = &self.sides[curve];
        (s.b - s.a).normalize()
    }

    fn curve_count(&self) -> usize {
        self.sides.len()
    }

    fn curved(&self) -> bool {
        false
    }

    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64> {
        match role {
            Role::Free => Point3::new(p.x, p.y, 0.0),
            Role::Curve(c) => self.sides[c].closest(p),
            Role::Fixed => *p,
        }
    }
}

/// Circles centred at the origin of the plane z = 0, as boundary curves.
fn circle_tangent(p: &Point3<f64>) -> Vector3<f64> {
    Vector3::new(-p.y, p.x, 0.0).normalize()
}

fn onto_circle(p: &Point3<f64>, radius: f64) -> Point3<f64> {
    let r = p.x.hypot(p.y);
    if r > 0.0 {
        Point3::new(p.x * radius / r, p.y * radius / r, 0.0)
    } else {
        Point3::new(radius, 0.0, 0.0)
    }
}

/// The unit disk `|z| <= 1`; curve 0 is the unit circle, traversed counter-clockwise.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UnitDisk;

impl TargetGeometry for UnitDisk {
    fn normal(&self, _p: &Point3<f64>) -> Vector3<f64> {
        Vector3::z()
    }

    fn curve_tangent(&self, _curve: usize, p: &Point3<f64>) -> Vector3<f64> {
        circle_tangent(p)
    }

    fn curve_count(&self) -> usize {
        1
    }

    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64> {
        match role {
            Role::Free => Point3::new(p.x, p.y, 0.0),
            Role::Curve(_) => onto_circle(p, 1.0),
            Role::Fixed => *p,
        }
    }
}

/// The annulus `r <= |z| <= 1`: curve 0 is the unit circle, curve 1 the inner circle.
/// With `free_inner`, `r` is an unknown of the flow (the conformal modulus
/// `log(1/r) / 2 pi` is then found, not imposed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Annulus {
    /// The inner radius `0 < r < 1`.
    pub inner_radius: f64,
    /// Whether the inner radius moves with the flow.
    pub free_inner: bool,
}

/// The outer circle of an [`Annulus`].
pub const OUTER: usize = 0;
/// The inner circle of an [`Annulus`].
pub const INNER: usize = 1;

impl TargetGeometry for Annulus {
    fn normal(&self, _p: &Point3<f64>) -> Vector3<f64> {
        Vector3::z()
    }

    fn curve_tangent(&self, _curve: usize, p: &Point3<f64>) -> Vector3<f64> {
        circle_tangent(p)
    }

    fn curve_offset_direction(&self, curve: usize, p: &Point3<f64>) -> Option<Vector3<f64>> {
        (curve == INNER && self.free_inner).then(|| Vector3::new(p.x, p.y, 0.0).normalize())
    }

    fn offset_curve(&mut self, curve: usize, delta: f64) {
        if curve == INNER && self.free_inner {
            self.inner_radius += delta;
        }
    }

    fn curve_count(&self) -> usize {
        2
    }

    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64> {
        match role {
            Role::Free => Point3::new(p.x, p.y, 0.0),
            Role::Curve(OUTER) => onto_circle(p, 1.0),
            Role::Curve(_) => onto_circle(p, self.inner_radius),
            Role::Fixed => *p,
        }
    }
}

/// The unit sphere centred at the origin, outward normal; no boundary curves.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UnitSphere;

impl TargetGeometry for UnitSphere {
    fn normal(&self, p: &Point3<f64>) -> Vector3<f64> {
        p.coords.normalize()
    }

    fn curve_tangent(&self, _curve: usize, p: &Point3<f64>) -> Vector3<f64> {
        orthonormal_basis(&self.normal(p))[0]
    }

    fn curve_count(&self) -> usize {
        0
    }

    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64> {
        match role {
            Role::Fixed => *p,
            _ => Point3::from(p.coords.normalize()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_and_positive() {
        for n in [
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(0.3, -0.4, 0.2).normalize(),
            Vector3::new(-0.1, 0.2, -0.9).normalize(),
        ] {
            let [u, v] = orthonormal_basis(&n);
            assert!((u.norm() - 1.0).abs() < 1e-14 && (v.norm() - 1.0).abs() < 1e-14);
            assert!(u.dot(&v).abs() < 1e-14 && u.dot(&n).abs() < 1e-14);
            assert!((u.cross(&v) - n).norm() < 1e-14);
        }
    }

    #[test]
    fn projections_land_on_the_target() {
        let p = Point3::new(0.3, -1.7, 0.2);
        assert!((UnitDisk.project(Role::Curve(0), &p).coords.norm() - 1.0).abs() < 1e-15);
        let annulus = Annulus {
            inner_radius: 0.4,
            free_inner: false,
        };
        let q = annulus.project(Role::Curve(INNER), &p);
        assert!((q.coords.norm() - 0.4).abs() < 1e-15 && q.z == 0.0);
        assert!((UnitSphere.project(Role::Free, &p).coords.norm() - 1.0).abs() < 1e-15);
        let square = PlaneRegion {
            sides: vec![Side {
                a: Point3::new(0.0, 0.0, 0.0),
                b: Point3::new(1.0, 0.0, 0.0),
            }],
        };
        assert_eq!(
            square.project(Role::Curve(0), &p),
            Point3::new(0.3, 0.0, 0.0)
        );
        assert_eq!(square.project(Role::Fixed, &p), p);
    }
}
