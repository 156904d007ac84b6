//! Reference data of Wong-Zhao 2014, section 5, for reproductions (the tests and
//! `beltrami bench flow`): the paper's tables and the test maps.
//!
//! The paper's "sup" column is `max_T |mu_T - target(centroid_T)|`; its "L2" column is
//! `sum_T A_T |mu_T - target_T|^2` (squared and not normalized by the area: it falls by
//! about 4 per level, while the area-weighted RMS error falls by about 2). Table 5.1's
//! levels 6 and 7 look misprinted by a factor of 10 (the other levels and the rate give
//! about 3.4e-4 and 8.6e-5).

use num_complex::Complex64;

/// A row of Table 5.1 (the unit disk, `mu = 0.6 z`, 0 and 1 fixed, tolerance `1e-8`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiskRow {
    /// Refinement level.
    pub level: usize,
    /// Faces (`4^(level + 1)`).
    pub faces: usize,
    /// Flow steps.
    pub steps: usize,
    /// `max_T |mu_T - 0.6 z_T|`.
    pub sup: f64,
    /// `sum_T A_T |mu_T - 0.6 z_T|^2`.
    pub l2: f64,
}

/// Table 5.1, as printed.
pub const TABLE_5_1: [DiskRow; 8] = [
    DiskRow {
        level: 0,
        faces: 4,
        steps: 4,
        sup: 0.2000,
        l2: 0.0800,
    },
    DiskRow {
        level: 1,
        faces: 16,
        steps: 12,
        sup: 0.2795,
        l2: 0.0813,
    },
    DiskRow {
        level: 2,
        faces: 64,
        steps: 12,
        sup: 0.2251,
        l2: 0.0458,
    },
    DiskRow {
        level: 3,
        faces: 256,
        steps: 13,
        sup: 0.1767,
        l2: 0.0176,
    },
    DiskRow {
        level: 4,
        faces: 1024,
        steps: 12,
        sup: 0.1060,
        l2: 0.0052,
    },
    DiskRow {
        level: 5,
        faces: 4096,
        steps: 10,
        sup: 0.0582,
        l2: 0.0013,
    },
    DiskRow {
        level: 6,
        faces: 16384,
        steps: 9,
        sup: 0.0306,
        l2: 0.341e-4,
    },
    DiskRow {
        level: 7,
        faces: 65536,
        steps: 9,
        sup: 0.0157,
        l2: 0.855e-5,
    },
];

/// A row of Table 5.2 (the unit sphere, `mu = 0.3 + 0.3 i` in the stereographic
/// coordinate, 0, 1 and infinity fixed, tolerance `1e-5`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereRow {
    /// Refinement level.
    pub level: usize,
    /// Faces (`8 * 4^level`).
    pub faces: usize,
    /// Flow steps.
    pub steps: usize,
    /// `sum_T A_T |mu_T - target_T|^2`.
    pub l2: f64,
}

/// Table 5.2, as printed.
pub const TABLE_5_2: [SphereRow; 7] = [
    SphereRow {
        level: 0,
        faces: 8,
        steps: 9,
        l2: 0.1246,
    },
    SphereRow {
        level: 1,
        faces: 32,
        steps: 13,
        l2: 0.3892,
    },
    SphereRow {
        level: 2,
        faces: 128,
        steps: 14,
        l2: 0.2692,
    },
    SphereRow {
        level: 3,
        faces: 512,
        steps: 14,
        l2: 0.1145,
    },
    SphereRow {
        level: 4,
        faces: 2048,
        steps: 12,
        l2: 0.0412,
    },
    SphereRow {
        level: 5,
        faces: 8192,
        steps: 11,
        l2: 0.0138,
    },
    SphereRow {
        level: 6,
        faces: 32768,
        steps: 10,
        l2: 0.0044,
    },
];

/// A row of Table 5.3, Beltrami flow (reconstructing a diffeomorphism of `[-1, 1]^2`,
/// tolerance `1e-3`, MATLAB on a 2.6 GHz quad-core laptop).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquareRow {
    /// Vertices per side.
    pub side: usize,
    /// Flow iterations.
    pub iterations: usize,
    /// Seconds.
    pub seconds: f64,
    /// The paper's L2 error of the reconstruction.
    pub error: f64,
}

/// Table 5.3 (Beltrami flow part), as printed.
pub const TABLE_5_3: [SquareRow; 4] = [
    SquareRow {
        side: 33,
        iterations: 9,
        seconds: 0.459429,
        error: 8.6697e-10,
    },
    SquareRow {
        side: 65,
        iterations: 7,
        seconds: 1.1837,
        error: 2.5620e-8,
    },
    SquareRow {
        side: 129,
        iterations: 7,
        seconds: 4.0143,
        error: 1.3582e-6,
    },
    SquareRow {
        side: 257,
        iterations: 7,
        seconds: 19.1423,
        error: 6.5365e-7,
    },
];

/// A strongly distorted diffeomorphism of the square `[-1, 1]^2` onto itself for the
/// Table 5.3 reproduction (the paper does not give its map; this one is ours): it fixes
/// the corners, slides points along the top and left sides, and reaches `|mu| = 0.71`.
/// A shear `S(x, y) = (x + 0.1 sin(pi x)(1 + y), y + 0.1 sin(pi y)(1 - x))`, then a swirl
/// turning the circle of radius `r <= 1` by `2 (1 - r^2)^3` radians.
pub fn square_diffeomorphism(p: Complex64) -> Complex64 {
    use std::f64::consts::PI;
    let (x, y) = (p.re, p.im);
    let s = Complex64::new(
        x + 0.1 * (PI * x).sin() * (1.0 + y),
        y + 0.1 * (PI * y).sin() * (1.0 - x),
    );
    let r2 = s.norm_sqr();
    if r2 >= 1.0 {
        return s;
    }
    s * Complex64::from_polar(1.0, 2.0 * (1.0 - r2).powi(3))
}

/// The Beltrami coefficient `f_zbar / f_z` of a smooth map `f` at `z`, from central
/// differences with step `1e-5` (error about `1e-10` for maps like
/// [`square_diffeomorphism`]).
pub fn beltrami_coefficient_of(f: impl Fn(Complex64) -> Complex64, z: Complex64) -> Complex64 {
    let h = 1e-5;
    let i = Complex64::i();
    let fx = (f(z + h) - f(z - h)) / (2.0 * h);
    let fy = (f(z + i * h) - f(z - i * h)) / (2.0 * h);
    (fx + i * fy) / (fx - i * fy)
}

#[cfg(test)]
mod tests {
    use super::*;

    type DistanceToSide = fn(Complex64) -> f64;

    #[test]
    fn the_diffeomorphism_keeps_the_square() {
        for k in 0..=20 {
            let t = -1.0 + 0.1 * k as f64;
            let sides: [(Complex64, DistanceToSide); 4] = [
                (Complex64::new(t, -1.0), |w: Complex64| (w.im + 1.0).abs()),
                (Complex64::new(t, 1.0), |w: Complex64| (w.im - 1.0).abs()),
                (Complex64::new(-1.0, t), |w: Complex64| (w.re + 1.0).abs()),
                (Complex64::new(1.0, t), |w: Complex64| (w.re - 1.0).abs()),
            ];
            for (p, side) in sides {
                assert!(side(square_diffeomorphism(p)) < 1e-15);
            }
        }
        let mu = beltrami_coefficient_of(|z| z + 0.3 * z.conj(), Complex64::new(0.2, 0.1));
        assert!((mu - 0.3).norm() < 1e-9);
    }
}
