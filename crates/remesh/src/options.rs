//! What the remeshing is asked for: the edge length (or a vertex count), the smallest
//! angle and the size field, checked before any work.

use crate::RemeshError;

/// The largest minimum angle accepted, in degrees. Delaunay refinement terminates for
/// angle bounds up to about 20.7 degrees (Ruppert's bound `arcsin(1 / (2 sqrt 2))`) and,
/// in practice, up to about 33.8 degrees (J. R. Shewchuk, "Delaunay refinement
/// algorithms for triangular mesh generation", CGTA 22, 2002, section 3.4); above that
/// it may insert vertices forever.
pub const MAX_MIN_ANGLE: f64 = 33.8;

/// The default feature tolerance, relative to the asked edge length (see
/// [`RemeshOptions::feature_tolerance`]).
pub const FEATURE_TOLERANCE: f64 = 0.2;

/// How long the edges of the result should be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Resolution {
    /// The edge length on the surface, in the mesh's units.
    EdgeLength(f64),
    /// About this many vertices: first the edge length `L` of an equilateral
    /// triangulation of the surface's area `A` with `N` vertices, `A = N (sqrt 3 / 2)
    /// L^2` (each vertex owns two triangles of area `(sqrt 3 / 4) L^2`), then one
    /// correction by the count that gave (see [`crate::remesh`]).
    Vertices(usize),
}

/// How the asked edge length varies over the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SizeField {
    /// The same edge length everywhere.
    #[default]
    Uniform,
    /// Shorter edges where the surface bends: at a point of normal curvature `k`, the
    /// edge length whose chord deviates from the surface by the deviation `L^2 kbar / 8`
    /// that the asked length `L` has at the area-mean curvature `kbar`, i.e.
    /// `L sqrt(kbar / k)`, clamped to `[L / 4, L]`.
    Curvature,
}

/// Options of [`crate::remesh`].
#[derive(Debug, Clone, PartialEq)]
pub struct RemeshOptions {
    /// Edge length or vertex count.
    pub resolution: Resolution,
    /// The smallest angle refinement enforces in the parameter domain, in degrees
    /// (`0 < A <= 33.8`, default 30 like spade's default).
    pub min_angle: f64,
    /// Uniform or curvature-adapted edge lengths.
    pub size_field: SizeField,
    /// The most vertices the result may have (a guard against a too small edge length).
    pub max_vertices: usize,
    /// How far, relative to the asked edge length `h`, the result may pass an input
    /// vertex before that vertex is inserted and held (a crease or spike thinner than
    /// the edge length is kept instead of cut off; the boundary keeps its corners the
    /// same way). Default [`FEATURE_TOLERANCE`]; smaller follows the input more closely
    /// with more vertices, `f64::INFINITY` inserts none and keeps the asked length on
    /// rough input at the price of the distance.
    pub feature_tolerance: f64,
}

impl Default for RemeshOptions {
    fn default() -> Self {
        Self {
            resolution: Resolution::Vertices(5000),
            min_angle: 30.0,
            size_field: SizeField::Uniform,
            max_vertices: 5_000_000,
            feature_tolerance: FEATURE_TOLERANCE,
        }
    }
}

impl RemeshOptions {
    /// Options for edge length `edge_length` and the defaults otherwise.
    pub fn with_edge_length(edge_length: f64) -> Self {
        Self {
            resolution: Resolution::EdgeLength(edge_length),
            ..Self::default()
        }
    }

    /// Checks every option; the error names the option and its accepted range.
    pub fn validate(&self) -> Result<(), RemeshError> {
        match self.resolution {
            Resolution::EdgeLength(l) if !(l.is_finite() && l > 0.0) => {
                return Err(RemeshError::InvalidOption {
                    option: "edge-length",
                    message: format!("must be a finite length > 0, got {l}"),
                });
            }
            Resolution::Vertices(n) if n < 3 => {
                return Err(RemeshError::InvalidOption {
                    option: "vertices",
                    message: format!("must be at least 3, got {n}"),
                });
            }
            _ => {}
        }
        let a = self.min_angle;
        if !(a.is_finite() && a > 0.0 && a <= MAX_MIN_ANGLE) {
            return Err(RemeshError::InvalidOption {
                option: "min-angle",
                message: format!(
                    "must lie in (0, {MAX_MIN_ANGLE}] degrees, got {a}: Delaunay refinement cannot guarantee a larger smallest angle"
                ),
            });
        }
        let t = self.feature_tolerance;
        if t.is_nan() || t <= 0.0 {
            return Err(RemeshError::InvalidOption {
                option: "feature-tolerance",
                message: format!(
                    "must be > 0 (a fraction of the edge length, or inf for none), got {t}"
                ),
            });
        }
        if self.max_vertices < 3 {
            return Err(RemeshError::InvalidOption {
                option: "max-vertices",
                message: format!("must be at least 3, got {}", self.max_vertices),
            });
        }
        Ok(())
    }

    /// Refuses, before any work, a size that would make more than
    /// [`RemeshOptions::max_vertices`] vertices on a surface of area `area`: an asked
    /// vertex count above it, or an edge length `L` whose equilateral mesh has more,
    /// `n = 2 A / (sqrt(3) L^2)` (each vertex of an equilateral mesh owns two triangles
    /// of area `sqrt(3) L^2 / 4`). The estimate leaves out the boundary's vertices and a
    /// curvature size field's shorter edges, so it refuses only what is sure to be too
    /// many; refinement stops at the limit for the rest.
    pub fn check_size(&self, area: f64) -> Result<(), RemeshError> {
        let per_vertex = |l: f64| 3f64.sqrt() / 2.0 * l * l;
        let edge_length = self.edge_length(area);
        let estimate = match self.resolution {
            Resolution::Vertices(n) => n as f64,
            Resolution::EdgeLength(l) => area / per_vertex(l),
        };
        // NaN (an area of 0) passes: the steps name what is wrong with such a surface.
        if estimate > self.max_vertices as f64 {
            return Err(RemeshError::TooFine {
                edge_length,
                area,
                estimate,
                max_vertices: self.max_vertices,
                suggested: (area / (self.max_vertices as f64 * per_vertex(1.0))).sqrt(),
            });
        }
        Ok(())
    }

    /// The edge length on a surface of area `area`.
    pub fn edge_length(&self, area: f64) -> f64 {
        match self.resolution {
            Resolution::EdgeLength(l) => l,
            Resolution::Vertices(n) => (2.0 * area / (3f64.sqrt() * n as f64)).sqrt(),
        }
    }
}
