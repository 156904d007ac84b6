//! Distortion of a map: per-face Beltrami coefficients, flipped faces and `|mu|`
//! statistics.
//!
//! For faces `f = 1..F` with coefficients `mu_f`, areas `A_f` (of the source face) and
//! flip flags, [`DistortionStats`] holds
//!
//! ```text
//! mu_mean = (1/F) sum_f |mu_f|
//! mu_max  = max_f |mu_f|
//! mu_std  = sqrt((1/F) sum_f (|mu_f| - mu_mean)^2)          (population std)
//! mu_l2   = sqrt(sum_f A_f |mu_f|^2 / sum_f A_f)            (area-weighted L2 norm)
//! ```
//!
//! and a [`Histogram`] of `|mu_f|` over `[0, 1)` plus the count of faces with
//! `|mu_f| >= 1`. A conformal map has all of them 0; an affine map `z + k conj(z)` has
//! `|mu| = |k|` on every face. `|mu|` does not depend on the frame (a frame rotation
//! multiplies `mu` by a unit number), so the statistics do not either.
//!
//! [`measure_planar`] and [`measure_surface`] go from a mesh and the images of its
//! vertices to a [`Distortion`]: the field, the flags and the statistics.

use beltrami_mesh::parallel::{available_threads, map_ranges};
use beltrami_mesh::{FaceId, Mesh, Point3, VertexId};
use num_complex::Complex64;

use crate::QuadraturePoint;
use crate::beltrami::{self, PointDerivatives, ReferenceNormal};
use crate::element::{check_planar, visit_face_points};
use crate::{BeltramiField, Elements, FemError, Frame};

/// A histogram of `|mu|` over faces: [`Histogram::BINS`] bins of width
/// [`Histogram::WIDTH`] over `[0, 1)`, and the faces beyond.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Histogram {
    /// `bins[k]` counts the faces with `floor(|mu| / WIDTH) = k` (evaluated in floating
    /// point), i.e. `k WIDTH <= |mu| < (k + 1) WIDTH`.
    pub bins: [usize; Histogram::BINS],
    /// Faces with `|mu| >= 1` (flipped or collapsed, see [`crate::beltrami`]).
    pub at_least_one: usize,
}

impl Histogram {
    /// Number of bins over `[0, 1)`.
    pub const BINS: usize = 10;
    /// Width of a bin, `1 / BINS`.
    pub const WIDTH: f64 = 1.0 / Self::BINS as f64;

    /// Counts one value `|mu| >= 0`.
    fn add(&mut self, modulus: f64) {
        if modulus >= 1.0 {
            self.at_least_one += 1;
        } else {
            let k = (modulus * Self::BINS as f64) as usize;
            self.bins[k.min(Self::BINS - 1)] += 1;
        }
    }
}

/// Statistics of `|mu|` over the faces of a map; the formulas are in the module docs.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DistortionStats {
    /// Number of faces `F`.
    pub faces: usize,
    /// Number of flipped faces (a quadrature point with Jacobian `<= 0`).
    pub flipped: usize,
    /// Mean of `|mu|` over faces (unweighted).
    pub mu_mean: f64,
    /// Largest `|mu|`.
    pub mu_max: f64,
    /// Population standard deviation of `|mu|` over faces (unweighted).
    pub mu_std: f64,
    /// Area-weighted L2 norm `sqrt(sum A_f |mu_f|^2 / sum A_f)`.
    pub mu_l2: f64,
    /// Histogram of `|mu|`.
    pub histogram: Histogram,
}

impl DistortionStats {
    /// The statistics of per-face values `mu`, source face areas `areas` and flip flags
    /// `flipped` (all of the same length). With no faces every statistic is 0.
    ///
    /// Fails with [`FemError::Length`] if the lengths differ and with
    /// [`FemError::NonFinite`] for a non-finite `mu`, or an area that is non-finite or
    /// negative. If every area is 0, `mu_l2` is the unweighted root mean square.
    pub fn new(mu: &[Complex64], areas: &[f64], flipped: &[bool]) -> Result<Self, FemError> {
        let faces = mu.len();
        for (what, got) in [("face areas", areas.len()), ("flip flags", flipped.len())] {
            if got != faces {
                return Err(FemError::Length {
                    what,
                    expected: faces,
                    got,
                });
            }
        }
        if let Some(index) = mu
            .iter()
            .position(|m| !(m.re.is_finite() && m.im.is_finite()))
        {
            return Err(FemError::NonFinite {
                what: "Beltrami coefficient",
                index,
            });
        }
        if let Some(index) = areas.iter().position(|a| !(a.is_finite() && *a >= 0.0)) {
            return Err(FemError::NonFinite {
                what: "face area",
                index,
            });
        }
        if faces == 0 {
            return Ok(Self::default());
        }
        let modulus: Vec<f64> = mu.iter().map(|m| m.norm()).collect();
        let n = faces as f64;
        let mu_mean = modulus.iter().sum::<f64>() / n;
        let mu_max = modulus.iter().copied().fold(0.0, f64::max);
        let mu_std = (modulus.iter().map(|m| (m - mu_mean).powi(2)).sum::<f64>() / n).sqrt();
        let total_area: f64 = areas.iter().sum();
        let mu_l2 = if total_area > 0.0 {
            let weighted: f64 = modulus.iter().zip(areas).map(|(m, a)| a * m * m).sum();
            (weighted / total_area).sqrt()
        } else {
            (modulus.iter().map(|m| m * m).sum::<f64>() / n).sqrt()
        };
        let mut histogram = Histogram::default();
        for &m in &modulus {
            histogram.add(m);
        }
        Ok(Self {
            faces,
            flipped: flipped.iter().filter(|&&f| f).count(),
            mu_mean,
            mu_max,
            mu_std,
            mu_l2,
            histogram,
        })
    }
}

/// The distortion of a map: its per-face Beltrami field, the flipped faces and the
/// statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Distortion {
    /// `mu` per face ([`beltrami::face_mu`]: the value at the centroid of a triangle, the
    /// weighted mean over the four Gauss points of a quad), in the frame of the elements.
    pub field: BeltramiField,
    /// Per face: true if the Jacobian of the map is `<= 0` at one of its quadrature points
    /// ([`beltrami::flipped_faces`]).
    pub flipped: Vec<bool>,
    /// Statistics of `|mu|`, weighted by the source face areas (the sums of the
    /// quadrature weights of each face).
    pub stats: DistortionStats,
}

impl Distortion {
    /// The distortion of a map from its derivatives at every quadrature point of
    /// `elements` (from [`beltrami::planar_map`] or [`beltrami::surface_map`]).
    pub fn from_derivatives(
        elements: &Elements,
        derivatives: &[PointDerivatives],
    ) -> Result<Self, FemError> {
        if derivatives.len() != elements.point_count() {
            return Err(FemError::Length {
                what: "derivatives",
                expected: elements.point_count(),
                got: derivatives.len(),
            });
        }
        let mu = beltrami::face_mu(elements, &beltrami::point_mu(derivatives));
        let flipped = beltrami::flipped_faces(elements, derivatives);
        let areas = elements.face_areas();
        let stats = DistortionStats::new(&mu, &areas, &flipped)?;
        Ok(Self {
            field: BeltramiField::new(elements.frame(), mu),
            flipped,
            stats,
        })
    }
}

/// The distortion of a map into the plane, `map[v]` the image of vertex `v`, measured in
/// `frame` ([`Frame::Global`] for a mesh in the plane z = 0, [`Frame::Face`] for a
/// surface): the values of [`Distortion::from_derivatives`] on
/// [`beltrami::planar_map`]'s derivatives, computed face by face without keeping the
/// elements ([`for_each_face_points`](crate::element::for_each_face_points)), ranges of faces on all cores (the values do not
/// depend on their number).
///
/// Fails like [`Elements::new`] (non-planar mesh for the global frame, degenerate face)
/// and [`beltrami::planar_map`] (wrong length, non-finite image).
pub fn measure_planar(
    mesh: &Mesh,
    map: &[Complex64],
    frame: Frame,
) -> Result<Distortion, FemError> {
    beltrami::check_planar_map(mesh.vertex_count(), map)?;
    if frame == Frame::Global {
        check_planar(mesh)?;
    }
    let parts = map_ranges(mesh.face_count(), available_threads(), |faces| {
        let mut part = FaceDistortion::with_capacity(faces.len());
        visit_face_points(mesh, frame, faces, |_, vertices, points| {
            part.push(map, vertices, points)
        })
        .map(|()| part)
    });
    let mut all = FaceDistortion::with_capacity(mesh.face_count());
    for part in parts {
        let part = part?;
        all.mu.extend(part.mu);
        all.areas.extend(part.areas);
        all.flipped.extend(part.flipped);
    }
    let FaceDistortion { mu, areas, flipped } = all;
    let stats = DistortionStats::new(&mu, &areas, &flipped)?;
    Ok(Distortion {
        field: BeltramiField::new(frame, mu),
        flipped,
        stats,
    })
}

/// `mu`, area and flip flag of consecutive faces of a planar map ([`measure_planar`]).
struct FaceDistortion {
    mu: Vec<Complex64>,
    areas: Vec<f64>,
    flipped: Vec<bool>,
}

impl FaceDistortion {
    fn with_capacity(faces: usize) -> Self {
        Self {
            mu: Vec::with_capacity(faces),
            areas: Vec::with_capacity(faces),
            flipped: Vec::with_capacity(faces),
        }
    }

    /// Appends the face with `vertices` and quadrature `points` under `map`, with the
    /// arithmetic of `planar_map`, `point_mu`, `face_mu`, `flipped_faces` and
    /// `face_areas`.
    fn push(&mut self, map: &[Complex64], vertices: &[VertexId], points: &[QuadraturePoint]) {
        let mut point_mu = [Complex64::new(0.0, 0.0); 4];
        let mut turned = false;
        for (q, m) in points.iter().zip(&mut point_mu) {
            let derivatives = beltrami::planar_derivatives(q, vertices, map);
            *m = derivatives.mu();
            turned |= derivatives.jacobian() <= 0.0;
        }
        let area: f64 = points.iter().map(|q| q.weight).sum();
        self.mu.push(if points.len() == 1 {
            point_mu[0]
        } else {
            points
                .iter()
                .zip(&point_mu)
                .map(|(q, &m)| m * q.weight)
                .sum::<Complex64>()
                / area
        });
        self.areas.push(area);
        self.flipped.push(turned);
    }
}

/// The distortion of a map of a surface into R^3, `image[v]` the image of vertex `v`,
/// measured intrinsically in the face frames ([`beltrami::surface_map`]), its orientation
/// judged against `reference` ([`ReferenceNormal`]: `Plane` for an image in the plane
/// z = 0, `Radial` for one on a sphere about the origin, `Source` for an image close to
/// the source, `PerFace` for a target surface's normals at the image;
/// [`ReferenceNormal::for_image`] chooses among the first three). A face is flipped when
/// one of its quadrature points has `m . N <= 0`, `m` the image's area element and `N`
/// the reference normal there.
///
/// Fails like [`Elements::new`] (degenerate face) and [`beltrami::surface_map`] (wrong
/// length, non-finite image or normal).
pub fn measure_surface(
    mesh: &Mesh,
    image: &[Point3<f64>],
    reference: ReferenceNormal<'_>,
) -> Result<Distortion, FemError> {
    let elements = Elements::new(mesh, Frame::Face)?;
    let derivatives = beltrami::surface_map(&elements, mesh.vertex_count(), image, reference)?;
    Distortion::from_derivatives(&elements, &derivatives)
}

/// `|mu - target|` over the faces, weighted by the face areas (the sums of the
/// quadrature weights of each face): how far a map is from a prescribed Beltrami
/// coefficient, in the measures of Wong-Zhao's tables 5.1-5.3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuError {
    /// The area-weighted RMS `sqrt(sum_f A_f |mu_f - target_f|^2 / sum_f A_f)`.
    pub rms: f64,
    /// `sum_f A_f |mu_f - target_f|^2`, the squared "L2" column of Wong-Zhao's tables
    /// (not normalized by the area).
    pub l2_squared: f64,
    /// `max_f |mu_f - target_f|`.
    pub sup: f64,
    /// The face where the sup is reached (the first of equal ones).
    pub sup_face: FaceId,
}

impl MuError {
    /// The error of `measured` against `target` (one value per face of `elements`, in
    /// the same frame). Fails with [`FemError::Length`] for a wrong length.
    pub fn new(
        elements: &Elements,
        measured: &[Complex64],
        target: &[Complex64],
    ) -> Result<Self, FemError> {
        let areas = elements.face_areas();
        Self::from_areas(&areas, measured, target)
    }

    /// The error of `measured` against `target` with face areas `areas` (one value per
    /// face each). Fails with [`FemError::Length`] for a wrong length.
    pub fn from_areas(
        areas: &[f64],
        measured: &[Complex64],
        target: &[Complex64],
    ) -> Result<Self, FemError> {
        let faces = areas.len();
        for (what, values) in [("measured mu", measured), ("target mu", target)] {
            if values.len() != faces {
                return Err(FemError::Length {
                    what,
                    expected: faces,
                    got: values.len(),
                });
            }
        }
        let (mut area, mut l2_squared, mut sup, mut sup_face) = (0.0, 0.0, 0.0, FaceId(0));
        for (f, (m, t)) in measured.iter().zip(target).enumerate() {
            let face = FaceId(f as u32);
            let a = areas[f];
            let d = (m - t).norm();
            area += a;
            l2_squared += a * d * d;
            if d > sup {
                (sup, sup_face) = (d, face);
            }
        }
        let rms = if area > 0.0 {
            (l2_squared / area).sqrt()
        } else {
            0.0
        };
        Ok(Self {
            rms,
            l2_squared,
            sup,
            sup_face,
        })
    }
}
