//! The options of [`crate::Remesh`]: their declarations, the rules of the two methods
//! (checked before any work), and the options of the `beltrami-remesh` library they
//! make.

use beltrami_core::{OptionKind, OptionSpec, Options, Settings, SolverError};
use beltrami_remesh::components::Coverage;
use beltrami_remesh::in_place::{InPlaceOptions, Keep};
use beltrami_remesh::reference_angles::Reference;
use beltrami_remesh::{FEATURE_TOLERANCE, MAX_MIN_ANGLE, RemeshOptions, Resolution, SizeField};
use thiserror::Error;

use crate::NAME;

/// The longest edge length the option `edge-length` admits, in the mesh's units.
pub const MAX_EDGE_LENGTH: f64 = 1e15;

/// The largest value of the option `feature-tolerance`, in edge lengths (the option
/// `keep-features=false` inserts no input vertex at all).
pub const MAX_FEATURE_TOLERANCE: f64 = 1e6;

/// The options of the `remesh` solver. Each but `method` belongs to one method
/// ([`Method::options`]); the defaults are those of [`RemeshOptions::default`] and
/// [`InPlaceOptions::default`], except the size, which method `param` needs given.
pub const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "method",
        kind: OptionKind::Choice {
            default: "param",
            choices: &["param", "qc-angles"],
        },
        help: "param: a new triangle mesh with the asked size, made through a parameterization (needs edge-length or vertices); qc-angles: the source's own vertices moved along it towards reference angles by the QC iteration (Gruber-Aulisa 2022, section 6.2)",
    },
    OptionSpec {
        name: "edge-length",
        kind: OptionKind::Float {
            default: 0.0,
            min: 0.0,
            max: MAX_EDGE_LENGTH,
        },
        help: "param: the edge length on the surface, in the mesh's units, above 0 (give it or vertices; the default 0 gives neither)",
    },
    OptionSpec {
        name: "vertices",
        kind: OptionKind::Int {
            default: 0,
            min: 0,
            max: usize::MAX,
        },
        help: "param: about this many vertices, at least 3: the edge length of an equilateral mesh of the surface's area with that many (give it or edge-length; the default 0 gives neither)",
    },
    OptionSpec {
        name: "param",
        kind: OptionKind::Name { default: "auto" },
        help: "param: the parameterizer, any registered solver that maps into the plane, sphere for a closed genus-0 surface (two stereographic charts), or auto: lscm on a disk, on a closed genus-0 surface slit open, on a genus-0 surface with several boundary loops with its holes closed (then qcmc), on any other surface cut to a disk, with tutte when the map folds or overlaps",
    },
    OptionSpec {
        name: "min-angle",
        kind: OptionKind::Float {
            default: 30.0,
            min: 0.0,
            max: MAX_MIN_ANGLE,
        },
        help: "param: the smallest angle refinement enforces, in degrees, above 0",
    },
    OptionSpec {
        name: "size-field",
        kind: OptionKind::Choice {
            default: "uniform",
            choices: &["uniform", "curvature"],
        },
        help: "param: uniform (the asked edge length everywhere) or curvature (shorter edges where the surface bends, down to a quarter of the asked length)",
    },
    OptionSpec {
        name: "max-vertices",
        kind: OptionKind::Int {
            default: 5_000_000,
            min: 3,
            max: usize::MAX,
        },
        help: "param: the most vertices the result may have (a size that would make more is refused before any work)",
    },
    OptionSpec {
        name: "feature-tolerance",
        kind: OptionKind::Float {
            default: FEATURE_TOLERANCE,
            min: 0.0,
            max: MAX_FEATURE_TOLERANCE,
        },
        help: "param: how far the result may pass an input vertex, as a fraction of the edge length, above 0, before that vertex is inserted (creases and boundary corners kept)",
    },
    OptionSpec {
        name: "keep-features",
        kind: OptionKind::Bool { default: true },
        help: "param: insert the input vertices the result would pass by more than feature-tolerance; false inserts none (the asked length on rough input, at the price of the distance)",
    },
    OptionSpec {
        name: "components",
        kind: OptionKind::Choice {
            default: "whole",
            choices: &["whole", "each", "largest"],
        },
        help: "param, a mesh in several connected components (a scan in pieces): whole refuses it, each remeshes every component on its own (vertices shared out by area) and joins the results in the order of each component's first face, largest remeshes only the largest",
    },
    OptionSpec {
        name: "reference",
        kind: OptionKind::Choice {
            default: "optimized",
            choices: &["optimized", "equiangular"],
        },
        help: "qc-angles: the reference shapes the elements move towards: angles adapted to the vertex valences (Gruber-Aulisa 2022, Algorithm 5) or equilateral triangles and squares",
    },
    OptionSpec {
        name: "constraint",
        kind: OptionKind::Choice {
            default: "normal",
            choices: &["normal", "area"],
        },
        help: "qc-angles: how the moved vertices stay on the surface: every displacement tangent to it (section 4.1) or its area kept to first order (section 4.2)",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 10,
            min: 0,
            max: 1_000_000,
        },
        help: "qc-angles: most QC iterations",
    },
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-4,
            min: 0.0,
            max: 1.0,
        },
        help: "qc-angles: stop when no face's mu moves by more than this in an iteration, above 0",
    },
    OptionSpec {
        name: "feature-angle",
        kind: OptionKind::Float {
            default: 60.0,
            min: 0.0,
            max: 180.0,
        },
        help: "qc-angles: hold the vertices of edges whose faces' normals differ by more than this many degrees, above 0 (sharp creases and corners); 180 holds none",
    },
    OptionSpec {
        name: "project",
        kind: OptionKind::Bool { default: true },
        help: "qc-angles: move the moved vertices onto the input surface; false leaves them where the map puts them",
    },
    OptionSpec {
        name: "allow-flips",
        kind: OptionKind::Bool { default: false },
        help: "qc-angles: return the result even when faces end turned against the surface that were not turned in the input (otherwise an error names the first)",
    },
];

/// How the `remesh` solver remeshes: its option `method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// A new mesh through a parameterization ([`beltrami_remesh::remesh`]).
    Param,
    /// The source's vertices moved in place towards reference angles
    /// ([`beltrami_remesh::in_place`]).
    QcAngles,
}

impl Method {
    /// The method of resolved settings.
    pub fn of(settings: &Settings) -> Self {
        if settings.choice("method") == "qc-angles" {
            Method::QcAngles
        } else {
            Method::Param
        }
    }

    /// `param` or `qc-angles`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Param => "param",
            Method::QcAngles => "qc-angles",
        }
    }

    /// The options only this method reads, in the order a refusal names them (the sizes
    /// of `param` last).
    pub fn options(self) -> &'static [&'static str] {
        match self {
            Method::Param => &[
                "param",
                "components",
                "min-angle",
                "size-field",
                "max-vertices",
                "feature-tolerance",
                "keep-features",
                "edge-length",
                "vertices",
            ],
            Method::QcAngles => &[
                "reference",
                "constraint",
                "max-iters",
                "tolerance",
                "feature-angle",
                "project",
                "allow-flips",
            ],
        }
    }

    fn other(self) -> Self {
        match self {
            Method::Param => Method::QcAngles,
            Method::QcAngles => Method::Param,
        }
    }
}

/// Why the `remesh` solver refuses the options of a problem, before any work. Every
/// variant names the option at fault; values out of a declared range are refused
/// earlier, by [`Settings::resolve`], and values the library refuses (an edge length of
/// 0, a vertex count under 3) by [`beltrami_remesh::RemeshError::InvalidOption`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RemeshOptionError {
    /// An option of the other method was given: it would be ignored silently.
    #[error("option `{option}` is one of method {of}; method {method} does not read it")]
    OtherMethod {
        /// The option given.
        option: &'static str,
        /// The method asked for.
        method: &'static str,
        /// The method the option belongs to.
        of: &'static str,
    },
    /// Method `param` without a size.
    #[error("method param makes a new mesh: give its size with option `edge-length` or `vertices`")]
    NoSize,
    /// Method `param` with both sizes.
    #[error("options `edge-length` and `vertices` both give the size of the new mesh: give one")]
    TwoSizes,
    /// `feature-tolerance` given while `keep-features` is false.
    #[error(
        "option `feature-tolerance` is not read when `keep-features` is false (no input vertex is inserted)"
    )]
    FeaturesOff,
    /// A value inside the declared range that the method refuses (the range's closed
    /// end at 0, where the method needs a positive value).
    #[error("option `{option}` is {got}: give {expected}")]
    Value {
        /// The option.
        option: &'static str,
        /// The value given.
        got: f64,
        /// What the method takes, in words.
        expected: &'static str,
    },
}

/// Checks what `settings` (resolved from `given`, the values a user set) ask for
/// against the rules of their method: no option of the other method given, exactly one
/// size for `param` and the library's checks of its options, positive `tolerance` and
/// `feature-angle` for `qc-angles`.
pub(crate) fn check(given: &Options, settings: &Settings) -> Result<(), SolverError> {
    let refuse = |error: RemeshOptionError| Err(SolverError::plugin(NAME, error));
    let method = Method::of(settings);
    let other = method.other();
    if let Some(&option) = other.options().iter().find(|o| given.get(o).is_some()) {
        return refuse(RemeshOptionError::OtherMethod {
            option,
            method: method.name(),
            of: other.name(),
        });
    }
    match method {
        Method::Param => {
            match (given.get("edge-length"), given.get("vertices")) {
                (None, None) => return refuse(RemeshOptionError::NoSize),
                (Some(_), Some(_)) => return refuse(RemeshOptionError::TwoSizes),
                _ => {}
            }
            if !settings.flag("keep-features") && given.get("feature-tolerance").is_some() {
                return refuse(RemeshOptionError::FeaturesOff);
            }
            remesh_options(given, settings)
                .validate()
                .map_err(|error| SolverError::plugin(NAME, error))
        }
        Method::QcAngles => {
            for (option, expected) in [
                ("tolerance", "a positive number"),
                ("feature-angle", "an angle in (0, 180] degrees"),
            ] {
                let got = settings.float(option);
                if got <= 0.0 {
                    return refuse(RemeshOptionError::Value {
                        option,
                        got,
                        expected,
                    });
                }
            }
            Ok(())
        }
    }
}

/// The options of [`beltrami_remesh::remesh`] that `settings` ask for (method `param`;
/// the size given in `given`, a feature tolerance of infinity for `keep-features=false`).
pub fn remesh_options(given: &Options, settings: &Settings) -> RemeshOptions {
    RemeshOptions {
        resolution: if given.get("edge-length").is_some() {
            Resolution::EdgeLength(settings.float("edge-length"))
        } else {
            Resolution::Vertices(settings.int("vertices"))
        },
        min_angle: settings.float("min-angle"),
        size_field: match settings.choice("size-field") {
            "curvature" => SizeField::Curvature,
            _ => SizeField::Uniform,
        },
        max_vertices: settings.int("max-vertices"),
        feature_tolerance: if settings.flag("keep-features") {
            settings.float("feature-tolerance")
        } else {
            f64::INFINITY
        },
    }
}

/// The components `settings` ask to remesh (option `components`).
pub fn coverage(settings: &Settings) -> Coverage {
    match settings.choice("components") {
        "each" => Coverage::Each,
        "largest" => Coverage::Largest,
        _ => Coverage::Whole,
    }
}

/// The options of [`beltrami_remesh::in_place::remesh_in_place`] that `settings` ask for
/// (method `qc-angles`).
pub fn in_place_options(settings: &Settings) -> InPlaceOptions {
    InPlaceOptions {
        reference: match settings.choice("reference") {
            "equiangular" => Reference::Equiangular,
            _ => Reference::Optimized,
        },
        keep: match settings.choice("constraint") {
            "area" => Keep::Area,
            _ => Keep::Normal,
        },
        max_iters: settings.int("max-iters"),
        tolerance: settings.float("tolerance"),
        project: settings.flag("project"),
        feature_angle: settings.float("feature-angle"),
        allow_flips: settings.flag("allow-flips"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolve(given: &Options) -> Settings {
        Settings::resolve(NAME, OPTIONS, given).unwrap()
    }

    #[test]
    fn every_option_but_the_method_belongs_to_one_method() {
        for spec in OPTIONS {
            let of = [Method::Param, Method::QcAngles]
                .iter()
                .filter(|m| m.options().contains(&spec.name))
                .count();
            let expected = usize::from(spec.name != "method");
            assert_eq!(of, expected, "{}", spec.name);
        }
        for method in [Method::Param, Method::QcAngles] {
            for name in method.options() {
                assert!(OPTIONS.iter().any(|s| s.name == *name), "{name}");
            }
        }
    }

    #[test]
    fn the_defaults_are_the_librarys() {
        let mut given = Options::new();
        given.set_text("vertices", "5000");
        let settings = resolve(&given);
        assert_eq!(remesh_options(&given, &settings), RemeshOptions::default());
        assert_eq!(coverage(&settings), Coverage::Whole);
        assert_eq!(in_place_options(&settings), InPlaceOptions::default());
    }

    #[test]
    fn keep_features_false_is_an_infinite_feature_tolerance() {
        let mut given = Options::new();
        given
            .set_text("edge-length", "0.1")
            .set_text("keep-features", "false");
        let settings = resolve(&given);
        assert!(check(&given, &settings).is_ok());
        let options = remesh_options(&given, &settings);
        assert_eq!(options.resolution, Resolution::EdgeLength(0.1));
        assert_eq!(options.feature_tolerance, f64::INFINITY);
        given.set_text("feature-tolerance", "0.5");
        let error = check(&given, &resolve(&given)).unwrap_err();
        assert!(
            error.to_string().contains("`keep-features` is false"),
            "{error}"
        );
    }
}
