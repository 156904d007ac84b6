//! The current map, face by face: its derivatives in the frame of each image face, its
//! Beltrami coefficient, flips and the error the flow decreases.
//!
//! For a P1 face `T` of the source (one quadrature point, tangent frame `(e1, e2)` of
//! the source elements) and its image triangle `Y_0 Y_1 Y_2` on the target, the
//! reference normal is `N_T = sum_k n(Y_k)`, the target's normals at its vertices'
//! images summed (for a target mesh the rule of
//! `beltrami_spatial::SurfaceIndex::face_reference_normals`). The image frame is
//! `(r, s, n)`: `r` along `Y_1 - Y_0` projected onto the plane normal to `n`, `s = n x r`
//! (Wong-Zhao 2014, Appendix: "local isometric coordinates (r, s) on each image
//! face"), and `n` the triangle's unit normal turned to the side of `N_T` by the fem
//! rule ([`beltrami_fem::beltrami::oriented_normal`]) while the triangle faces the
//! target (`n . N_T / |N_T| >= 0.4`), turning smoothly to `N_T / |N_T|` as it tilts
//! (reached at 0.1, about 84 degrees). In its own plane a triangle standing edge-on to
//! the target keeps a healthy `|mu|` and jumps to a flip under a step of any size (the
//! flow stalls there); seen in the target's tangent plane it thins to a segment, its
//! `|mu|` rising continuously through 1 where it folds, which the barrier holds off.
//! The reported `mu` is the fem kernel's, in the triangle's own plane
//! ([`ImageFace::own_mu`]). With `f_x = sum_k Y_k d_x N_k` and `f_y = sum_k Y_k d_y N_k`
//! in R^3,
//!
//! ```text
//! F_x = f_x . r + i f_x . s,   F_y = f_y . r + i f_y . s,
//! f_z = (F_x - i F_y) / 2,     f_zbar = (F_x + i F_y) / 2,     mu = f_zbar / f_z.
//! ```
//!
//! The face is flipped when the fem kernel
//! ([`beltrami_fem::beltrami::image_derivatives`] of `f_x`, `f_y` and `N_T`) has a
//! Jacobian `<= 0` (the image triangle turns against the target's normal, or is
//! degenerate): the same decision as `beltrami_fem::distortion::measure_surface` with
//! `ReferenceNormal::PerFace` of these sums, face by face. `mu` does not depend on the
//! choice of `r` (a rotation of the image frame multiplies `f_z` and `f_zbar` by one
//! unit number); `f_z` does, and the flow uses it in the same image frame as its own
//! unknowns.

use beltrami_fem::Elements;
use beltrami_fem::beltrami::{PointDerivatives, image_derivatives, oriented_normal};
use beltrami_mesh::parallel::{map_blocks, map_chunks_mut};
use beltrami_mesh::{FaceId, Point3, Vector2, Vector3, VertexId};
use num_complex::Complex64;

/// One image face of the current map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageFace {
    /// `f_z` and `f_zbar` in the source frame and the image frame.
    pub derivatives: PointDerivatives,
    /// The image frame's real axis `r`.
    pub r: Vector3<f64>,
    /// The image frame's imaginary axis `s`.
    pub s: Vector3<f64>,
    /// The image triangle's vertices in `(r, s)` coordinates (the first at the origin).
    pub local: [Vector2<f64>; 3],
    /// Whether the fem kernel finds the image flipped or degenerate (module docs).
    flipped: bool,
    /// `mu` measured in the image triangle's own plane (the fem kernel's, which
    /// `beltrami distortion` reports).
    own_mu: Complex64,
    /// `n . N_T / |N_T|`: 1 where the image triangle lies in the target's tangent
    /// plane, near 0 where it stands edge-on to it.
    facing: f64,
}

impl ImageFace {
    /// `mu = f_zbar / f_z`, in the target's tangent plane (module docs).
    pub fn mu(&self) -> Complex64 {
        self.derivatives.mu()
    }

    /// `mu` in the image triangle's own plane: what the fem kernel measures and
    /// reports (equal to [`ImageFace::mu`] where the triangle lies in the tangent plane;
    /// smaller in modulus where it is tilted out of it).
    pub fn own_mu(&self) -> Complex64 {
        self.own_mu
    }

    /// Whether the image is flipped or degenerate: the Jacobian of the fem kernel
    /// [`image_derivatives`] is `<= 0` (module docs).
    pub fn flipped(&self) -> bool {
        self.flipped
    }

    /// Whether the image triangle stands nearly edge-on to the target's tangent plane
    /// (`n . N_T / |N_T| < EDGE_ON`): seen from the target's normal it is a sliver about
    /// to fold, whatever its own `|mu|`; a step of any size may flip it.
    pub fn edge_on(&self) -> bool {
        self.facing < EDGE_ON
    }

    /// The cosine between the image triangle's own normal and its reference normal (the
    /// sum of its corners' target normals): 1 where it faces the target, 0 edge-on.
    pub fn facing(&self) -> f64 {
        self.facing
    }

    /// Marks the face flipped (so that [`crate::untangle`] moves its vertices).
    pub(crate) fn mark_flipped(&mut self) {
        self.flipped = true;
    }
}

/// The cosine between an image triangle and the target's tangent plane below which the
/// triangle counts as edge-on ([`ImageFace::edge_on`]): about 84 degrees.
pub const EDGE_ON: f64 = 0.1;

/// The vertices of P1 face `f` of `elements`.
pub(crate) fn triangle(elements: &Elements, f: FaceId) -> [VertexId; 3] {
    let n = elements.nodes(f);
    [n[0], n[1], n[2]]
}

/// The edge vectors `e_1 = p_1 - p_0`, `e_2 = p_2 - p_0` of the image triangle with
/// vertex indices `corners`, and its reference normal: the sum of the target's normals
/// at its corners, against which its orientation is read.
pub(crate) fn edges_and_reference(
    corners: [usize; 3],
    image: &[Point3<f64>],
    normals: &[Vector3<f64>],
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let [a, b, c] = corners.map(|v| image[v]);
    let reference = corners.iter().map(|&v| normals[v]).sum();
    (b - a, c - a, reference)
}

/// The image face of `f` under the map `image`, oriented by the sum of the target's
/// normals `normals` at its vertices' images (module docs).
pub fn image_face(
    elements: &Elements,
    normals: &[Vector3<f64>],
    image: &[Point3<f64>],
    f: FaceId,
) -> ImageFace {
    let nodes = triangle(elements, f).map(|v| v.idx());
    image_face_of(
        elements,
        f,
        nodes.map(|v| image[v]),
        nodes.map(|v| normals[v]),
    )
}

/// `mu` ([`ImageFace::mu`]) of face `f` of `image` with its corner `k` moved to `to`,
/// where the target's normal is `normal` (the other corners and normals kept): the
/// measure whose rate the flow takes by differences where the frame tilts with the
/// corners ([`crate::system::FlowSystem::solve`]).
pub(crate) fn mu_with_corner_moved(
    elements: &Elements,
    normals: &[Vector3<f64>],
    image: &[Point3<f64>],
    f: FaceId,
    k: usize,
    (to, normal): (Point3<f64>, Vector3<f64>),
) -> Complex64 {
    let nodes = triangle(elements, f).map(|v| v.idx());
    let mut corners = nodes.map(|v| image[v]);
    let mut corner_normals = nodes.map(|v| normals[v]);
    (corners[k], corner_normals[k]) = (to, normal);
    image_face_of(elements, f, corners, corner_normals).mu()
}

/// [`image_face`] of face `f` with corners `corners` and the target's normals
/// `corner_normals` there.
fn image_face_of(
    elements: &Elements,
    f: FaceId,
    corners: [Point3<f64>; 3],
    corner_normals: [Vector3<f64>; 3],
) -> ImageFace {
    let q = &elements.face_points(f)[0];
    let (e1, e2) = (corners[1] - corners[0], corners[2] - corners[0]);
    let reference: Vector3<f64> = corner_normals.iter().sum();
    let own = oriented_normal(&e1, &e2, &reference);
    // The frame: the triangle's own plane where it faces the target (the measure of
    // the fem kernel), turning to the target's tangent plane (the plane of N_T) as the
    // triangle tilts towards edge-on, so that `mu` passes continuously through
    // |mu| = 1 where the image turns edge-on to the target and flips.
    let unit_reference = (reference.norm_squared() > 0.0).then(|| reference.normalize());
    // Whether the frame is the triangle's own plane (oriented by the reference), as the
    // fem kernel's is.
    let (n, own_plane) = match (own, unit_reference) {
        (Some(own), Some(unit)) => {
            let w = tilt_weight(own.dot(&unit));
            if w == 0.0 {
                (own, true)
            } else {
                ((own * (1.0 - w) + unit * w).normalize(), false)
            }
        }
        (Some(own), None) => (own, true),
        (None, Some(unit)) => (unit, false),
        (None, None) => (corner_normals[0], false),
    };
    let r = {
        let t = e1 - n * n.dot(&e1);
        if t.norm_squared() > 0.0 {
            t.normalize()
        } else {
            crate::target::orthonormal_basis(&n)[0]
        }
    };
    let s = n.cross(&r);
    let (mut fx, mut fy) = (Vector3::zeros(), Vector3::zeros());
    for (k, p) in corners.iter().enumerate() {
        fx += p.coords * q.grad[k].x;
        fy += p.coords * q.grad[k].y;
    }
    let along = |v: &Vector3<f64>| Complex64::new(v.dot(&r), v.dot(&s));
    let derivatives = PointDerivatives::from_xy(along(&fx), along(&fy));
    // In the own plane the kernel's frame differs from (r, s) by a rotation, which
    // leaves mu and the Jacobian as they are: measure once.
    let kernel = if own_plane {
        derivatives
    } else {
        image_derivatives(&fx, &fy, &reference)
    };
    ImageFace {
        derivatives,
        r,
        s,
        local: [
            Vector2::zeros(),
            Vector2::new(e1.dot(&r), e1.dot(&s)),
            Vector2::new(e2.dot(&r), e2.dot(&s)),
        ],
        flipped: kernel.jacobian() <= 0.0,
        own_mu: kernel.mu(),
        facing: match (own, unit_reference) {
            (Some(own), Some(unit)) => own.dot(&unit),
            _ => 1.0,
        },
    }
}

/// The share of the target's tangent plane in the frame of a face whose own normal
/// has cosine `facing` with the target's: 0 from [`TILT_START`] up, 1 at
/// [`TILT_FULL`] and below, a smooth step between.
fn tilt_weight(facing: f64) -> f64 {
    let x = ((TILT_START - facing) / (TILT_START - TILT_FULL)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Faces whose own normal has at least this cosine with the target's are measured in
/// their own plane ([`image_face`]).
pub(crate) const TILT_START: f64 = 0.4;

/// Faces whose own normal has at most this cosine with the target's are measured in
/// the target's tangent plane.
pub(crate) const TILT_FULL: f64 = 0.1;

/// Every image face of the map `image` ([`image_face`]), into `out` (resized to the face
/// count, every entry overwritten), on `threads` threads ([`beltrami_mesh::parallel`];
/// the faces are the same for any number).
pub fn image_faces(
    elements: &Elements,
    normals: &[Vector3<f64>],
    image: &[Point3<f64>],
    out: &mut Vec<ImageFace>,
    threads: usize,
) {
    let n = elements.face_count();
    out.truncate(n);
    if n == 0 {
        return;
    }
    // Every face is overwritten below: a vector kept from the last trial step (the
    // flow's case) is not filled first.
    if out.len() < n {
        let first = image_face(elements, normals, image, FaceId(0));
        out.resize(n, first);
    }
    map_chunks_mut(out, threads, |offset, chunk| {
        for (k, face) in chunk.iter_mut().enumerate() {
            *face = image_face(elements, normals, image, FaceId::from_usize(offset + k));
        }
    });
}

/// Where the near-fold barrier of [`Objective`] acts and how it weighs faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Barrier {
    /// `m0`, the `|mu|` above which the barrier acts.
    pub start: f64,
    /// Whether every face weighs at least the mean face area (else its own area).
    pub area_floor: bool,
}

impl Barrier {
    /// The barrier of maps onto planar targets (plane regions, the disk, annuli): from
    /// `|mu| = 0.25`, each face weighing at least the mean area. A conformal map onto
    /// such a target has `|mu|` of a few hundredths (discretization error), so a face
    /// above 0.25 is a defect, and the largest `|mu|` is what a texture shows whatever
    /// the face's size: a sliver must count as much as an ordinary face. Measured on
    /// `disk_human_face`, whose 54 slivers (angles 1.5-24 degrees) ended near `|mu|`
    /// 0.99 under an area-weighted energy: max `|mu|` 0.495 with [`Barrier::AREA_WEIGHTED`],
    /// 0.251 with this one, mean 0.0213 with both.
    pub const PLANAR: Self = Self {
        start: 0.25,
        area_floor: true,
    };

    /// The barrier of maps onto the sphere and onto target meshes: from `|mu| = 0.8`,
    /// area-weighted. A registration between different shapes has a genuine distortion
    /// the barrier must not fight; on the sphere, [`Barrier::PLANAR`] held the flow on
    /// the near-folds of the linear start without removing them (`g0_koala`: the step
    /// limit of 200 and 65 s against 61 steps and 12.5 s, the mean unchanged;
    /// `g0_bunny_closed`: max `|mu|` 0.985 against 0.998 in 8.6 s against 2.6 s).
    pub const AREA_WEIGHTED: Self = Self {
        start: 0.8,
        area_floor: false,
    };
}

/// What the flow decreases: `E = sum_T A_T |mu_T - sigma_T|^p` over the source faces
/// (areas `A_T`), with `sigma = 0` for the conformal goals, plus for those the near-fold
/// barrier
///
/// ```text
/// B = sum_T W_T b(|mu_T|),    b(m) = ((m - m0) / (1 - m))^2  for m0 < m < 1, else 0,
/// ```
///
/// with `m0` and the weights `W_T` (`A_T`, or `max(A_T, A_mean)`) of a [`Barrier`]. A
/// face near `|mu| = 1` is a near-fold (its image nearly collapses onto a segment); an
/// area-weighted `|mu|^p` alone lets the flow drive a sliver there, since the sliver's
/// area is tiny and the Gauss-Newton weight `(1 - |mu|^2)^2` of [`crate::flow`] vanishes
/// at the fold. `b` grows without bound at the fold; a flipped face, `|mu| > 1`, is kept
/// from multiplying by the flip count of the step search instead.
#[derive(Debug, Clone, PartialEq)]
pub struct Objective {
    /// Source face areas.
    pub areas: Vec<f64>,
    /// The target coefficient per face, in the source elements' frame (`None`: zero).
    pub sigma: Option<Vec<Complex64>>,
    /// The exponent, `2 <= p <= 100`.
    pub p: f64,
    /// The least weight of a face in the barrier: the mean of `areas` or zero
    /// ([`Barrier::area_floor`]).
    pub barrier_floor: f64,
    /// `m0`, the `|mu|` above which the barrier acts.
    pub barrier_start: f64,
}

/// The near-fold barrier `b(m)` of [`Objective`], acting from `m0`.
fn barrier(m: f64, m0: f64) -> f64 {
    if m > m0 && m < 1.0 {
        let b = (m - m0) / (1.0 - m);
        b * b
    } else {
        0.0
    }
}

impl Objective {
    /// The objective of faces of areas `areas`, target coefficients `sigma` (`None`:
    /// zero, a conformal goal, with `barrier`) and exponent `p`.
    pub fn new(areas: Vec<f64>, sigma: Option<Vec<Complex64>>, p: f64, barrier: Barrier) -> Self {
        let barrier_floor = if barrier.area_floor {
            areas.iter().sum::<f64>() / areas.len().max(1) as f64
        } else {
            0.0
        };
        Self {
            areas,
            sigma,
            p,
            barrier_floor,
            barrier_start: barrier.start,
        }
    }

    /// The weight of face `f` in the barrier: its area, at least the floor.
    #[inline]
    pub fn barrier_area(&self, f: usize) -> f64 {
        self.areas[f].max(self.barrier_floor)
    }

    /// The target coefficient of face `f`.
    #[inline]
    pub fn sigma(&self, f: usize) -> Complex64 {
        self.sigma.as_ref().map_or(Complex64::default(), |s| s[f])
    }

    /// Whether the near-fold barrier is part of `E` (the conformal goals).
    pub fn has_barrier(&self) -> bool {
        self.sigma.is_none()
    }

    /// The barrier's Gauss-Newton weight at `|mu| = m`: `b'(m) / (2 m)`, the factor by
    /// which the face's `|mu|^2` term must be weighted for its gradient to include the
    /// barrier's (iteratively reweighted least squares, as for `p > 2`); zero where the
    /// barrier is.
    pub fn barrier_weight(&self, m: f64) -> f64 {
        let m0 = self.barrier_start;
        if !(self.has_barrier() && m > m0 && m < 1.0) {
            return 0.0;
        }
        let gap = 1.0 - m;
        (m - m0) * (1.0 - m0) / (m * gap * gap * gap)
    }

    /// Face `f`'s term of `E` (with its barrier for the conformal goals) at `face`.
    pub fn face_energy(&self, f: usize, face: &ImageFace) -> f64 {
        let d = (face.mu() - self.sigma(f)).norm();
        let e = if self.p == 2.0 { d * d } else { d.powf(self.p) };
        let mut energy = self.areas[f] * e;
        if self.has_barrier() {
            energy += self.barrier_area(f) * barrier(d, self.barrier_start);
        }
        energy
    }

    /// `E` (with the barrier for the conformal goals) and the number of flipped faces of
    /// `faces`, summed over blocks of [`EVALUATION_BLOCK`] faces on `threads` threads
    /// (the blocks' sums are added in order: the same value for any number).
    pub fn evaluate(&self, faces: &[ImageFace], threads: usize) -> (f64, usize) {
        map_blocks(faces.len(), EVALUATION_BLOCK, threads, |range| {
            let mut energy = 0.0;
            let mut flipped = 0;
            for f in range {
                let face = &faces[f];
                energy += self.face_energy(f, face);
                flipped += usize::from(face.flipped());
            }
            (energy, flipped)
        })
        .into_iter()
        .fold((0.0, 0), |(e, n), (be, bn)| (e + be, n + bn))
    }
}

/// The faces per block of [`Objective::evaluate`].
pub const EVALUATION_BLOCK: usize = 8192;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_barrier_weight_is_the_barriers_gauss_newton_weight() {
        let m0 = Barrier::PLANAR.start;
        let objective = Objective::new(vec![1.0], None, 2.0, Barrier::PLANAR);
        // b'(m) / (2 m) by central differences.
        for m in [0.26, 0.4, 0.6, 0.81, 0.9, 0.95, 0.99, 0.999] {
            let h = 1e-7 * (1.0 - m);
            let slope = (barrier(m + h, m0) - barrier(m - h, m0)) / (2.0 * h);
            let expected = slope / (2.0 * m);
            let got = objective.barrier_weight(m);
            assert!(
                (got - expected).abs() <= 1e-6 * expected,
                "m = {m}: {got} vs {expected}"
            );
        }
        for m in [0.0, 0.1, m0, 1.0, 1.5] {
            assert_eq!(objective.barrier_weight(m), 0.0);
            assert_eq!(barrier(m, m0), 0.0);
        }
        let prescribed = Objective {
            sigma: Some(vec![Complex64::default()]),
            ..objective
        };
        assert_eq!(prescribed.barrier_weight(0.95), 0.0);
    }

    #[test]
    fn a_face_tilting_through_edge_on_passes_continuously_through_a_fold() {
        // The unit right triangle, its image turned about its first edge (the x axis)
        // by theta, the target's normals all z: the image keeps its shape (own |mu| 0),
        // but seen from the normal it thins to a segment at 90 degrees and folds over
        // beyond. The flow's |mu| must rise continuously through 1 there, with the flip
        // (the own-plane measure jumps from 0 to infinity).
        use beltrami_fem::Frame;
        use beltrami_mesh::{Mesh, PolygonSoup};
        let corners = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let mesh =
            Mesh::from_soup(&PolygonSoup::from_triangles(corners.to_vec(), &[[0, 1, 2]])).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let normals = vec![Vector3::z(); 3];
        let mut previous: Option<f64> = None;
        for tenths in 0..=1200 {
            let degrees = f64::from(tenths) / 10.0;
            let theta = degrees.to_radians();
            let image = [
                corners[0],
                corners[1],
                Point3::new(0.0, theta.cos(), theta.sin()),
            ];
            let face = image_face(&elements, &normals, &image, FaceId(0));
            let m = face.mu().norm();
            assert_eq!(face.flipped(), degrees > 90.0, "{degrees} degrees");
            if degrees < 90.0 {
                assert!(face.own_mu().norm() < 1e-12, "{degrees} degrees");
                assert!(m < 1.0, "{degrees} degrees: |mu| {m}");
            }
            if degrees > 90.0 {
                assert!(m > 1.0, "{degrees} degrees: |mu| {m}");
            }
            let facing = theta.cos().abs();
            if (facing - EDGE_ON).abs() > 1e-9 {
                assert_eq!(face.edge_on(), facing < EDGE_ON, "{degrees} degrees");
            }
            // Through the fold in small steps; beyond it (a flip, which the flow never
            // takes) |mu| goes on rising towards the reflection's infinity.
            if let Some(p) = previous {
                assert!(m >= p - 1e-12, "{degrees} degrees: {p} -> {m}");
                if degrees <= 95.0 {
                    assert!(m - p < 0.02, "{degrees} degrees: {p} -> {m}");
                }
            }
            previous = Some(m);
        }
    }

    #[test]
    fn faces_measured_in_their_own_plane_agree_with_the_fem_kernel() {
        use beltrami_fem::Frame;
        use beltrami_mesh::{Mesh, PolygonSoup};
        let corners = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.2, 0.0),
            Point3::new(0.3, 0.9, 0.0),
        ];
        let mesh =
            Mesh::from_soup(&PolygonSoup::from_triangles(corners.to_vec(), &[[0, 1, 2]])).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let q = &elements.face_points(FaceId(0))[0];
        // A fixed pseudo-random sequence in [-1, 1).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let (mut own_plane, mut tilted, mut flipped) = (0, 0, 0);
        for _ in 0..2000 {
            let image: Vec<Point3<f64>> = (0..3)
                .map(|_| Point3::new(next(), next(), next()))
                .collect();
            let normals: Vec<Vector3<f64>> = (0..3)
                .map(|_| Vector3::new(next(), next(), 0.3 + next()).normalize())
                .collect();
            let face = image_face(&elements, &normals, &image, FaceId(0));
            let (mut fx, mut fy) = (Vector3::zeros(), Vector3::zeros());
            for (k, p) in image.iter().enumerate() {
                fx += p.coords * q.grad[k].x;
                fy += p.coords * q.grad[k].y;
            }
            let reference: Vector3<f64> = normals.iter().sum();
            let kernel = image_derivatives(&fx, &fy, &reference);
            let scale = kernel.mu().norm().max(1.0);
            assert!(
                (face.own_mu() - kernel.mu()).norm() <= 1e-10 * scale,
                "{image:?}: {} against {}",
                face.own_mu(),
                kernel.mu()
            );
            assert_eq!(face.flipped(), kernel.jacobian() <= 0.0, "{image:?}");
            if face.facing >= TILT_START {
                own_plane += 1;
            } else {
                tilted += 1;
            }
            flipped += usize::from(face.flipped());
        }
        // Both frames and both orientations were met.
        assert!(own_plane > 200 && tilted > 200 && flipped > 200 && flipped < 1800);
    }

    #[test]
    fn the_objective_is_its_formula_summed_for_any_thread_count() {
        use beltrami_fem::Frame;
        use beltrami_mesh::{Mesh, PolygonSoup};
        let corners = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let mesh = Mesh::from_soup(&PolygonSoup::from_triangles(corners, &[[0, 1, 2]])).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let normals = vec![Vector3::z(); 3];
        // Images from conformal (|mu| 0) through near-folds to flips: the third corner
        // slides along the x axis direction and shrinks towards the first edge.
        let faces: Vec<ImageFace> = (0..20_000)
            .map(|k| {
                let a = k as f64 / 20_000.0;
                let image = [
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(1.0, 0.0, 0.0),
                    Point3::new(3.0 * a - 0.5, 1.2 - 1.3 * a, 0.0),
                ];
                image_face(&elements, &normals, &image, FaceId(0))
            })
            .collect();
        let areas: Vec<f64> = (0..faces.len()).map(|k| 1.0 + (k % 7) as f64).collect();
        for (p, barrier_kind) in [(2.0, Barrier::PLANAR), (3.0, Barrier::AREA_WEIGHTED)] {
            let objective = Objective::new(areas.clone(), None, p, barrier_kind);
            let mut expected = 0.0;
            let mut flips = 0;
            for (f, face) in faces.iter().enumerate() {
                let m = face.mu().norm();
                expected += areas[f] * m.powf(p)
                    + objective.barrier_area(f) * barrier(m, barrier_kind.start);
                flips += usize::from(face.flipped());
            }
            let one = objective.evaluate(&faces, 1);
            assert!(
                (one.0 - expected).abs() <= 1e-12 * expected,
                "p = {p}: {one:?} against {expected}"
            );
            assert_eq!(one.1, flips);
            assert!(flips > 0 && flips < faces.len());
            assert_eq!(objective.evaluate(&faces, 2), one);
            assert_eq!(objective.evaluate(&faces, 3), one);
        }
    }
}
