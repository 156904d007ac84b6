//! Triangle meshes of circle domains: the unit disk minus closed disks, the canonical
//! domains of the multiply-connected solvers (`qcmc`) and test beds for registration.
//!
//! Every circle (the unit circle and each hole's) is sampled evenly with about `h`
//! between samples and kept as constraint edges of spade's constrained Delaunay
//! triangulation; inside, the points of a hexagonal lattice of spacing `h` at least
//! `h / 2` from every circle. The mesh has the faces of the triangulation whose
//! centroids lie in the domain, counter-clockwise in the plane z = 0.

use beltrami_mesh::{Mesh, Point3, PolygonSoup};
use num_complex::Complex64;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::RemeshError;

/// A hole of a circle domain: the closed disk `|z - center| <= radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hole {
    /// Its centre.
    pub center: Complex64,
    /// Its radius.
    pub radius: f64,
}

/// A mesh of the unit disk minus `holes` with edges about `h` long (module docs).
///
/// # Errors
/// [`RemeshError::InvalidOption`] (option `holes` or `h`) when `h` is not in
/// `(0, 0.5]`, a hole is not finite, has a radius under `h / 2`, reaches within `h` of
/// the unit circle or of another hole; [`RemeshError::Build`] if the triangulation does not give a valid mesh.
pub fn circle_domain(holes: &[Hole], h: f64) -> Result<Mesh, RemeshError> {
    let invalid =
        |option: &'static str, message: String| RemeshError::InvalidOption { option, message };
    if !(h > 0.0 && h <= 0.5) {
        return Err(invalid(
            "h",
            format!("the edge length must be in (0, 0.5], got {h}"),
        ));
    }
    for (k, hole) in holes.iter().enumerate() {
        let Hole { center, radius } = *hole;
        if !(center.re.is_finite() && center.im.is_finite() && radius > 0.0 && radius.is_finite()) {
            return Err(invalid(
                "holes",
                format!("hole {k} ({center}, radius {radius}) is not a disk"),
            ));
        }
        if radius < h / 2.0 {
            // Its circle's samples would crowd into slivers against the lattice.
            return Err(invalid(
                "holes",
                format!(
                    "hole {k} ({center}, radius {radius}) is smaller than half the edge length {h}: give a radius of at least {} or a smaller edge length",
                    h / 2.0
                ),
            ));
        }
        if center.norm() + radius > 1.0 - h {
            return Err(invalid(
                "holes",
                format!(
                    "hole {k} ({center}, radius {radius}) reaches within {h} of the unit circle"
                ),
            ));
        }
        for (j, other) in holes.iter().enumerate().take(k) {
            if (center - other.center).norm() < radius + other.radius + h {
                return Err(invalid(
                    "holes",
                    format!("holes {j} and {k} come within {h} of each other"),
                ));
            }
        }
    }
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut circle = |c: Complex64, r: f64| -> Result<(), RemeshError> {
        let n = ((std::f64::consts::TAU * r / h).ceil() as usize).max(8);
        let handles = (0..n)
            .map(|i| {
                let z = c + r * Complex64::cis(std::f64::consts::TAU * i as f64 / n as f64);
                cdt.insert(Point2::new(z.re, z.im))
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| invalid("holes", format!("triangulating a circle: {e:?}")))?;
        for i in 0..n {
            cdt.add_constraint(handles[i], handles[(i + 1) % n]);
        }
        Ok(())
    };
    circle(Complex64::new(0.0, 0.0), 1.0)?;
    for hole in holes {
        circle(hole.center, hole.radius)?;
    }
    let inside = |z: Complex64, margin: f64| {
        z.norm() < 1.0 - margin
            && holes
                .iter()
                .all(|c| (z - c.center).norm() > c.radius + margin)
    };
    let row = h * 0.75f64.sqrt();
    let rows = (1.0 / row).ceil() as i64;
    let columns = (1.0 / h).ceil() as i64 + 1;
    for j in -rows..=rows {
        for i in -columns..=columns {
            let z = Complex64::new(
                h * (i as f64 + 0.5 * j.rem_euclid(2) as f64),
                row * j as f64,
            );
            if inside(z, 0.5 * h) {
                cdt.insert(Point2::new(z.re, z.im))
                    .map_err(|e| invalid("h", format!("triangulating the lattice: {e:?}")))?;
            }
        }
    }
    let positions: Vec<Point3<f64>> = cdt
        .vertices()
        .map(|v| Point3::new(v.position().x, v.position().y, 0.0))
        .collect();
    let mut soup = PolygonSoup::new(positions);
    for f in cdt.inner_faces() {
        let [a, b, c] = f.vertices();
        let centroid = Complex64::new(
            (a.position().x + b.position().x + c.position().x) / 3.0,
            (a.position().y + b.position().y + c.position().y) / 3.0,
        );
        if inside(centroid, 0.0) {
            soup.push_face(&[
                a.fix().index() as u32,
                b.fix().index() as u32,
                c.fix().index() as u32,
            ]);
        }
    }
    Mesh::from_soup(&soup).map_err(|error| RemeshError::Build {
        what: "circle-domain mesh",
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mesh_has_one_loop_per_circle_with_every_vertex_on_it() {
        let holes = [
            Hole {
                center: Complex64::new(-0.4, 0.0),
                radius: 0.2,
            },
            Hole {
                center: Complex64::new(0.35, 0.3),
                radius: 0.15,
            },
        ];
        let mesh = circle_domain(&holes, 0.05).unwrap();
        assert_eq!(mesh.boundary_loop_count(), 3);
        assert_eq!(mesh.genus(), Some(0));
        for l in mesh.boundary_loop_list() {
            let p = mesh.position(l.vertices[0]);
            let z = Complex64::new(p.x, p.y);
            let (c, r) = if (z.norm() - 1.0).abs() < 1e-12 {
                (Complex64::new(0.0, 0.0), 1.0)
            } else {
                let hole = holes
                    .iter()
                    .min_by(|a, b| {
                        ((z - a.center).norm() - a.radius)
                            .abs()
                            .total_cmp(&((z - b.center).norm() - b.radius).abs())
                    })
                    .unwrap();
                (hole.center, hole.radius)
            };
            for v in l.vertices {
                let p = mesh.position(v);
                assert!(((Complex64::new(p.x, p.y) - c).norm() - r).abs() < 1e-12);
            }
        }
        // Counter-clockwise faces: positive area about +z.
        for f in mesh.faces() {
            assert!(mesh.face_normal(f).z > 0.0);
        }
    }

    #[test]
    fn overlapping_holes_and_bad_lengths_are_refused() {
        let hole = |x: f64, r: f64| Hole {
            center: Complex64::new(x, 0.0),
            radius: r,
        };
        for (holes, h, expected) in [
            (vec![hole(0.0, 0.2)], 0.0, "(0, 0.5]"),
            (vec![hole(0.0, 0.2)], f64::NAN, "(0, 0.5]"),
            (vec![hole(0.7, 0.3)], 0.05, "unit circle"),
            (vec![hole(-0.2, 0.2), hole(0.2, 0.2)], 0.05, "holes 0 and 1"),
            (vec![hole(0.0, -1.0)], 0.05, "not a disk"),
        ] {
            let message = circle_domain(&holes, h).unwrap_err().to_string();
            assert!(message.contains(expected), "{message}");
        }
    }
}
