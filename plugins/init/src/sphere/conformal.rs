//! The linear conformal start of the sphere solver: a harmonic map of the punctured
//! mesh into the plane, then harmonic corrections in the two stereographic charts of
//! the sphere, alternating, each with the other half of the sphere held fixed.
//!
//! # The punctured harmonic map
//!
//! The idea is that of FLASH (P. T. Choi, K. C. Lam, L. M. Lui, "FLASH: Fast landmark
//! aligned spherical harmonic parameterization for genus-0 closed brain surfaces", SIAM
//! J. Imaging Sci. 8(1), 2015, section 3): a conformal map of the sphere minus a point
//! onto the plane has harmonic coordinates, so it is approximated by the discrete
//! harmonic map `sum_j w_ij (z_i - z_j) = 0` (cotangent weights `w_ij`, U. Pinkall and
//! K. Polthier, Experimental Math. 2, 1993) at every vertex except the `n` vertices of
//! one face `r`, which are fixed at a similar copy of `r` (`r` laid out isometrically in
//! its own plane, counter-clockwise as seen from outside). With `r` as the outer face
//! of the planar drawing, every other face runs clockwise in the plane, as the inverse
//! stereographic projection from the north pole needs (module docs of
//! [`super`]). The cotangent Laplacian is the P1/Q1 stiffness matrix, positive
//! semi-definite on any mesh, so with `r`'s vertices fixed the system is symmetric
//! positive definite; its weights are negative across edges opposite obtuse angles, so
//! the drawing is not guaranteed to be an embedding (as FLASH's is not).
//!
//! The map is conformal only away from `r`: a full turn around each corner of `r` is
//! squeezed into the corner angle of the copy, and the boundary correspondence along
//! `r`'s sides is linear instead of the conformal one. The image is centred (vertex mean
//! at 0) and scaled so that the median `|z|` is 1 (half the vertices in each hemisphere
//! after the projection), projected, and the area is Moebius-centred (module docs of
//! [`super`]), which keeps conformality and spreads the area before the corrections.
//!
//! # Chart corrections (a Schwarz alternation)
//!
//! FLASH corrects the distortion near `r` by one more linear solve in the chart of the
//! other pole, with a tenth of the vertices (those farthest from `r`) held fixed: a
//! quasiconformal map whose Beltrami coefficient cancels that of the first map. Here
//! the same correction is a harmonic solve: on the free vertices, a map with
//! `f_zbar ~ 0` and given values on the fixed ones minimizes the least-squares conformal
//! energy `E_C = sum_t A_t |f_zbar|^2 = E_D / 2 - A(f)` (Levy, Petitjean, Ray, Maillot,
//! SIGGRAPH 2002), whose area term `A(f)` depends only on the fixed values around the
//! free region, so its minimizer is the cotangent-harmonic map with those values fixed
//! (the same weights as the first solve).
//!
//! Rotate the sphere so that the image of `r` (the mean of its vertex images) is the
//! north pole `N`, and let `h_v` be the height of vertex `v`'s image. Two charts cover
//! the sphere:
//!
//! ```text
//! north chart (N at 0):  w = (x + i y) / (1 + z),   p = (2w, 1 - |w|^2) / (1 + |w|^2)
//! south chart (S at 0):  w = (x + i y) / (1 - z),   p = (2w, |w|^2 - 1) / (1 + |w|^2)
//! ```
//!
//! (the two are related by `w_north = 1 / conj(w_south)`). A correction in the north chart frees the
//! vertices with `h_v > -tau` (around `r`) and holds the others at their current chart
//! coordinates; a correction in the south chart frees those with `h_v < tau` and holds the
//! northern cap. Corrections alternate north, south, north, ... The first is FLASH's correction with
//! a fixed region of heights below `-tau` instead of a tenth of the vertices; the next
//! ones remove the seam the fixed region leaves, since the region held fixed by each
//! solve was recomputed, as a conformal map, by the previous one. This is H. A.
//! Schwarz's alternating method ("Ueber einen Grenzuebergang durch alternirendes
//! Verfahren", 1870) for the conformal map of the sphere, with the overlap
//! `|h| < tau`: in the north chart the free disk has radius `R = sqrt((1 + tau) / (1 - tau))`
//! and the other chart's free region begins at radius `1 / R`, so an error mode
//! `w^k` shrinks by about `R^(-2k)` per pair of solves. The fixed sets are chosen once
//! (from the heights after the punctured map), so each chart's matrix is factorized
//! once. The area is Moebius-centred after each solve, which keeps the alternation from
//! drifting along the Moebius group (each solve's discretization error is not invariant
//! under it).

use beltrami_fem::EdgeWeights;
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use beltrami_sparse::fill_reducing_order;
use beltrami_sparse::{SolveError, SolveOptions, SpdSolver};
use faer::Mat;
use faer::sparse::{FaerError, SparseColMat, Triplet};
use nalgebra::Rotation3;
use num_complex::Complex64;

use super::inverse_stereographic;

/// The fill-reducing elimination order (`fill_reducing_order`) of the vertex graph of
/// `weights`
/// (the pattern of the cotangent Laplacian), shared by the three systems of the
/// conformal start: eliminating a subset in the order of the whole keeps the fill low
/// (the separators of the whole graph restricted to the subset).
pub(super) fn vertex_order(weights: &EdgeWeights) -> Result<Vec<usize>, SolveError> {
    let n = weights.vertex_count();
    let mut triplets = Vec::new();
    for i in 0..n {
        triplets.push(Triplet::new(i, i, 1.0));
        for (j, _) in weights.row(VertexId::from_usize(i)) {
            triplets.push(Triplet::new(j.idx(), i, 1.0));
        }
    }
    let pattern = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
        .map_err(|_| SolveError::Faer(FaerError::IndexOverflow))?;
    fill_reducing_order(pattern.symbolic())
}

/// The discrete harmonic map of `mesh` with the vertices of face `removed` fixed at a
/// similar copy of it (module docs), centred and scaled to a median `|z|` of 1.
pub(super) fn punctured_harmonic(
    mesh: &Mesh,
    weights: &EdgeWeights,
    removed: FaceId,
    order: &[usize],
    options: SolveOptions,
) -> Result<Vec<Complex64>, SolveError> {
    let (corners, n) = mesh.face_vertex_array(removed);
    let normal = mesh.face_normal(removed);
    let origin = mesh.position(corners[0]);
    let e1 = (mesh.position(corners[1]) - origin).normalize();
    let e2 = normal.cross(&e1);
    let fixed: Vec<(VertexId, Complex64)> = corners[..n]
        .iter()
        .map(|&v| {
            let d = mesh.position(v) - origin;
            (v, Complex64::new(d.dot(&e1), d.dot(&e2)))
        })
        .collect();
    let mut system = ChartSystem::new(
        weights,
        f64::NEG_INFINITY,
        |v| !fixed.iter().any(|&(f, _)| f == v),
        Some(order),
        options,
    )?;
    let solved = system
        .solve(weights, |v| lookup(&fixed, v))?
        .ok_or(SolveError::NonFinite {
            what: "the removed face's layout",
            index: removed.idx(),
        })?;
    let mut z = vec![Complex64::new(0.0, 0.0); mesh.vertex_count()];
    for (&v, &zv) in system.free().iter().zip(&solved) {
        z[v.idx()] = zv;
    }
    for &(v, zv) in &fixed {
        z[v.idx()] = zv;
    }
    let mean = z.iter().sum::<Complex64>() / z.len() as f64;
    let mut radii: Vec<f64> = z.iter().map(|&zi| (zi - mean).norm()).collect();
    let middle = radii.len() / 2;
    let (_, &mut median, _) = radii.select_nth_unstable_by(middle, f64::total_cmp);
    let scale = if median > 0.0 && median.is_finite() {
        1.0 / median
    } else {
        1.0
    };
    for zi in &mut z {
        *zi = (*zi - mean) * scale;
    }
    Ok(z)
}

/// The fixed value of `v` in `fixed` (zero if absent; only fixed vertices are asked).
fn lookup(fixed: &[(VertexId, Complex64)], v: VertexId) -> Complex64 {
    fixed
        .iter()
        .find(|&&(f, _)| f == v)
        .map_or(Complex64::new(0.0, 0.0), |&(_, z)| z)
}

/// One of the two stereographic charts of the corrections (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Chart {
    /// The north pole at 0: `w = (x + i y) / (1 + z)`.
    North,
    /// The south pole at 0: `w = (x + i y) / (1 - z)`.
    South,
}

impl Chart {
    /// The chart coordinate of a point of the unit sphere.
    pub(super) fn coordinate(self, p: &Point3<f64>) -> Complex64 {
        let d = match self {
            Chart::North => 1.0 + p.z,
            Chart::South => 1.0 - p.z,
        };
        Complex64::new(p.x, p.y) / d
    }

    /// The point of the unit sphere at chart coordinate `w`.
    pub(super) fn point(self, w: Complex64) -> Point3<f64> {
        match self {
            Chart::South => inverse_stereographic(w),
            Chart::North => {
                let p = inverse_stereographic(w);
                Point3::new(p.x, p.y, -p.z)
            }
        }
    }
}

/// The cotangent Laplacian restricted to the free vertices of one chart, factorized
/// once: `L_II w_I = sum_{j fixed} w_ij w_j` (the weighted-mean system of
/// [`beltrami_fem::weighted_mean`] with an arbitrary fixed set, whose factorization is
/// kept for the repeated corrections).
pub(super) struct ChartSystem {
    /// Weights below this are raised to it (`-inf`: the weights as they are).
    floor: f64,
    /// The sparse Cholesky factorization of `L_II` (rows and columns in the order of
    /// `free`).
    cholesky: SpdSolver<f64>,
    /// The free vertices in unknown order.
    free: Vec<VertexId>,
    /// The unknown index of each vertex, `usize::MAX` when fixed.
    slot: Vec<usize>,
}

impl ChartSystem {
    /// The system of `weights` (each raised to at least `floor`) with the vertices where
    /// `is_free` holds as unknowns.
    ///
    /// `order`, when given, is an elimination order of all the vertices
    /// ([`vertex_order`]); the free vertices are eliminated in its order, which saves a
    /// minimum-degree ordering per system. Without it the system is ordered by AMD.
    pub(super) fn new(
        weights: &EdgeWeights,
        floor: f64,
        is_free: impl Fn(VertexId) -> bool,
        order: Option<&[usize]>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = weights.vertex_count();
        let mut slot = vec![usize::MAX; n];
        let free: Vec<VertexId> = (0..n)
            .map(VertexId::from_usize)
            .filter(|&v| is_free(v))
            .collect();
        for (k, v) in free.iter().enumerate() {
            slot[v.idx()] = k;
        }
        let mut triplets = Vec::new();
        for (k, &v) in free.iter().enumerate() {
            let mut diagonal = 0.0;
            for (j, w) in weights.row(v) {
                let w = w.max(floor);
                diagonal += w;
                let l = slot[j.idx()];
                if l != usize::MAX && l > k {
                    triplets.push(Triplet::new(l, k, -w));
                }
            }
            triplets.push(Triplet::new(k, k, diagonal));
        }
        let matrix = SparseColMat::try_new_from_triplets(free.len(), free.len(), &triplets)
            .map_err(|_| SolveError::Faer(FaerError::IndexOverflow))?;
        let mut cholesky = match order {
            Some(order) => {
                let restricted: Vec<usize> = order
                    .iter()
                    .map(|&i| slot[i])
                    .filter(|&k| k != usize::MAX)
                    .collect();
                SpdSolver::with_order(matrix.symbolic(), &restricted, options)?
            }
            None => SpdSolver::new(matrix.symbolic(), options)?,
        };
        cholesky.factorize(matrix.as_ref())?;
        Ok(Self {
            floor,
            cholesky,
            free,
            slot,
        })
    }

    /// The free vertices, in the order of [`ChartSystem::solve`]'s values.
    pub(super) fn free(&self) -> &[VertexId] {
        &self.free
    }

    /// Solves for the free vertices with the fixed ones at `fixed(v)` (asked only for
    /// fixed neighbours of free vertices); returns the values of the free vertices in
    /// the order of [`ChartSystem::free`], or `None` when a fixed value asked for is not
    /// finite (a fixed vertex at the pole the chart sends to infinity).
    pub(super) fn solve(
        &mut self,
        weights: &EdgeWeights,
        fixed: impl Fn(VertexId) -> Complex64,
    ) -> Result<Option<Vec<Complex64>>, SolveError> {
        let mut rhs = Mat::<f64>::zeros(self.free.len(), 2);
        for (k, &v) in self.free.iter().enumerate() {
            for (j, w) in weights.row(v) {
                if self.slot[j.idx()] == usize::MAX {
                    let w = w.max(self.floor);
                    let z = fixed(j);
                    if !z.is_finite() {
                        return Ok(None);
                    }
                    rhs[(k, 0)] += w * z.re;
                    rhs[(k, 1)] += w * z.im;
                }
            }
        }
        self.cholesky.solve_in_place(rhs.as_mut())?;
        Ok(Some(
            (0..self.free.len())
                .map(|k| Complex64::new(rhs[(k, 0)], rhs[(k, 1)]))
                .collect(),
        ))
    }
}

/// How the chart corrections went.
#[derive(Debug, Clone, Copy)]
pub(super) struct Corrections {
    /// Corrections done.
    pub done: usize,
    /// The largest move of a vertex image in the last correction.
    pub last_move: f64,
}

/// What the chart corrections do (module docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct CorrectionSettings {
    /// `tau`: the north chart frees heights above `-tau`, the south chart below `tau`.
    pub overlap: f64,
    /// Corrections at most.
    pub count: usize,
    /// The corrections stop once no vertex image moves farther than this.
    pub tolerance: f64,
}

/// The chart corrections (module docs): `settings.count` harmonic solves alternating
/// between the north chart and the south chart, with the overlap
/// `|h| < settings.overlap`, on the image rotated so that `axis` is the north pole.
/// After each solve `recentre` moves the centre of mass of the area back to the origin
/// (a conformal change): the charts' discretization errors are not invariant under the
/// Moebius group, and without it the alternation can drift along it (on a coarse,
/// unevenly spread mesh, until the area crowds one side and the charts no longer
/// resolve it). Stops early once no solve moves a vertex image more than
/// `settings.tolerance`. `image` holds unit vectors; it is left in the rotated frame.
pub(super) fn correct<E>(
    weights: &EdgeWeights,
    image: &mut Vec<Point3<f64>>,
    axis: Vector3<f64>,
    settings: CorrectionSettings,
    order: &[usize],
    options: SolveOptions,
    mut recentre: impl FnMut(&mut Vec<Point3<f64>>) -> Result<(), E>,
) -> Result<Corrections, E>
where
    E: From<SolveError>,
{
    turn_to_north(image, axis);
    let heights: Vec<f64> = image.iter().map(|p| p.z).collect();
    let tau = settings.overlap;
    let north_free = free_set(&heights, |h| h > -tau);
    let south_free = free_set(&heights, |h| h < tau);
    let mut systems = [
        (
            Chart::North,
            ChartSystem::new(
                weights,
                f64::NEG_INFINITY,
                |v| north_free[v.idx()],
                Some(order),
                options,
            )?,
        ),
        (
            Chart::South,
            ChartSystem::new(
                weights,
                f64::NEG_INFINITY,
                |v| south_free[v.idx()],
                Some(order),
                options,
            )?,
        ),
    ];
    let mut result = Corrections {
        done: 0,
        last_move: 0.0,
    };
    for k in 0..settings.count {
        let (chart, system) = &mut systems[k % 2];
        let coordinates: Vec<Complex64> = image.iter().map(|p| chart.coordinate(p)).collect();
        let Some(solved) = system.solve(weights, |v| coordinates[v.idx()])? else {
            break;
        };
        let mut largest: f64 = 0.0;
        for (&v, &w) in system.free.iter().zip(&solved) {
            let q = chart.point(w);
            largest = largest.max((q - image[v.idx()]).norm());
            image[v.idx()] = q;
        }
        recentre(image)?;
        result.done += 1;
        result.last_move = largest;
        if largest <= settings.tolerance {
            break;
        }
    }
    Ok(result)
}

/// Rotates the points so that the direction `axis` becomes the north pole `(0, 0, 1)`.
pub(super) fn turn_to_north(points: &mut [Point3<f64>], axis: Vector3<f64>) {
    if let Some(rotation) = Rotation3::rotation_between(&axis, &Vector3::z()) {
        for p in points.iter_mut() {
            *p = rotation * *p;
        }
    } else if axis.z < 0.0 {
        // `axis` points south: turn the sphere over.
        for p in points.iter_mut() {
            *p = Point3::new(p.x, -p.y, -p.z);
        }
    }
}

/// Per vertex: free where `free(h)` holds, except that at least [`MIN_FIXED`] vertices
/// (the ones the predicate frees last: lowest `h` for the north chart's `h > -tau`, highest for
/// the south chart's) stay fixed so the system is nonsingular.
fn free_set(heights: &[f64], free: impl Fn(f64) -> bool) -> Vec<bool> {
    let mut is_free: Vec<bool> = heights.iter().map(|&h| free(h)).collect();
    let fixed = is_free.iter().filter(|&&f| !f).count();
    if fixed < MIN_FIXED {
        // The predicate is monotone in h: sort by "freeness" and fix the least free.
        let mut order: Vec<usize> = (0..heights.len()).collect();
        let prefers_high = free(1.0) && !free(-1.0);
        order.sort_by(|&a, &b| {
            let (x, y) = (heights[a], heights[b]);
            if prefers_high {
                x.total_cmp(&y)
            } else {
                y.total_cmp(&x)
            }
        });
        for &i in order.iter().take(MIN_FIXED.min(heights.len())) {
            is_free[i] = false;
        }
    }
    is_free
}

/// Each chart correction holds at least this many vertices fixed.
const MIN_FIXED: usize = 3;
