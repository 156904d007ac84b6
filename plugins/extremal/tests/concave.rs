//! A concave boundary where the harmonic map folds (the kind of case of Weber, Myles,
//! Zorin 2012, Fig. 10 and 14): the unit disk with its boundary sent to the star
//! `r = 1 + 0.3 cos(5 t)`. The harmonic map with those boundary values (the solver's
//! start) turns faces over at the five concave arcs; the extremal map has none, and its
//! `|mu|` is nearly constant (the Teichmueller property).

mod common;

use beltrami_mesh::{Mesh, primitives};
use common::{image, solve};

#[test]
fn the_extremal_map_of_a_star_does_not_fold_where_the_harmonic_map_does() {
    let mesh = Mesh::from_soup(&primitives::disk(5)).unwrap();
    let star = image(&mesh, |z| {
        let t = z.arg();
        z * (1.0 + 0.3 * (5.0 * t).cos())
    });
    let solution = solve(&mesh, star, None, "harmonic");
    let start = solution.metrics.initial_distortion.as_ref().unwrap();
    let end = solution.metrics.distortion.as_ref().unwrap();
    let k = solution.metrics.k.unwrap();
    println!(
        "star: harmonic start {} flips, max |mu| {:.3}; extremal k {k:.4}, {} flips, |mu| mean {:.4} max {:.4} std {:.4}",
        start.flipped, start.mu_max, end.flipped, end.mu_mean, end.mu_max, end.mu_std
    );
    assert!(
        start.flipped > 50,
        "the harmonic map has {} flips",
        start.flipped
    );
    assert_eq!(end.flipped, 0);
    assert!(
        end.mu_max < 1.5 * k,
        "max |mu| {} against k {k}",
        end.mu_max
    );
    assert!(
        end.mu_std < 0.1 * k,
        "spread of |mu| {} against k {k}",
        end.mu_std
    );
}
