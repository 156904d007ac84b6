//! Step 4 of the QC iteration (Gruber-Aulisa 2022, section 5.4): the best coefficient on
//! the segment from `mu_k` to the smoothed `mu_(k+1)` for the current map `f_k`.
//!
//! The residual `r(mu) = df^- - mu df^+` of a fixed map is affine in `mu`, so along
//! `mu(t) = mu_k + t (mu_(k+1) - mu_k)` it is `r(t) = r_k - t (r_k - r_(k+1))` and the
//! distortion `|r(t)|^2` is least at
//!
//! ```text
//! t0 = <r_k - r_(k+1), r_k> / |r_k - r_(k+1)|^2
//! ```
//!
//! (the paper's `t0` with `mu_dot df^+ = r_k - r_(k+1)`), taken in `[0, 1]` so that the
//! coefficient stays between two coefficients of norm below one.

/// `t0` of the module docs from the weighted residuals of `f_k` under `mu_k` and under
/// the smoothed `mu_(k+1)`; `1` when both residuals agree (nothing to choose).
pub(crate) fn best_step(current: &[f64], next: &[f64]) -> f64 {
    let (mut along, mut length) = (0.0, 0.0);
    for (a, b) in current.iter().zip(next) {
        let d = a - b;
        along += d * a;
        length += d * d;
    }
    if length > 0.0 {
        (along / length).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::best_step;

    /// `|r_k - t d|^2` for a few residual pairs: `t0` is its minimum over `[0, 1]`.
    #[test]
    fn the_step_minimizes_the_distortion_on_the_segment() {
        let cases: [(&[f64], &[f64]); 3] = [
            (&[1.0, 2.0, -1.0], &[0.5, 1.0, 0.0]),
            (&[1.0, 0.0], &[3.0, 0.0]),
            (&[1.0, 1.0], &[-2.0, -2.5]),
        ];
        for (current, next) in cases {
            let t0 = best_step(current, next);
            let energy = |t: f64| -> f64 {
                current
                    .iter()
                    .zip(next)
                    .map(|(a, b)| (a - t * (a - b)).powi(2))
                    .sum()
            };
            let best = (0..=1000)
                .map(|i| i as f64 / 1000.0)
                .min_by(|a, b| energy(*a).total_cmp(&energy(*b)))
                .unwrap();
            assert!((t0 - best).abs() <= 1e-3, "t0 {t0}, grid {best}");
        }
    }
}
