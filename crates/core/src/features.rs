//! Scalar fields on the vertices of a source and a target mesh that a registration
//! matches: an intensity, a curvature, a sulcal depth given per vertex on both meshes
//! ([`Goal::Features`](crate::Goal::Features)).

use beltrami_mesh::Mesh;

/// One value per vertex of the source and one per vertex of the target, in each mesh's
/// vertex order. The two fields are compared after each is standardized (its
/// area-weighted mean subtracted, divided by its standard deviation), so they may be
/// given in different units.
#[derive(Debug, Clone, PartialEq)]
pub struct Features {
    /// The source's field, per source vertex.
    pub source: Vec<f64>,
    /// The target's field, per target vertex.
    pub target: Vec<f64>,
}

impl Features {
    /// Refuses fields whose lengths are not the meshes' vertex counts, with a value
    /// that is NaN or infinite (naming the vertex by its input index), or that are
    /// constant (nothing to match). The message is for the solver to wrap.
    pub fn check(&self, source: &Mesh, target: &Mesh) -> Result<(), String> {
        for (side, values, mesh) in [
            ("source", &self.source, source),
            ("target", &self.target, target),
        ] {
            if values.len() != mesh.vertex_count() {
                return Err(format!(
                    "the {side} feature has {} values, but the {side} has {} vertices",
                    values.len(),
                    mesh.vertex_count()
                ));
            }
            if let Some(v) = mesh.vertices().find(|v| !values[v.idx()].is_finite()) {
                return Err(format!(
                    "the {side} feature is not finite at vertex {} (input index)",
                    mesh.vertex_map().to_input(v)
                ));
            }
            let first = values.first().copied().unwrap_or_default();
            if values.iter().all(|&x| x == first) {
                return Err(format!(
                    "the {side} feature is constant: there is nothing to match"
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::icosphere;

    #[test]
    fn wrong_counts_nan_and_constant_fields_are_refused() {
        let mesh = Mesh::from_soup(&icosphere(1)).unwrap();
        let n = mesh.vertex_count();
        let ramp: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let good = Features {
            source: ramp.clone(),
            target: ramp.clone(),
        };
        assert_eq!(good.check(&mesh, &mesh), Ok(()));
        let short = Features {
            source: ramp[1..].to_vec(),
            target: ramp.clone(),
        };
        assert!(
            short
                .check(&mesh, &mesh)
                .unwrap_err()
                .contains("source feature has")
        );
        let mut nan = good.clone();
        nan.target[5] = f64::NAN;
        assert!(nan.check(&mesh, &mesh).unwrap_err().contains("vertex 5"));
        let flat = Features {
            source: ramp,
            target: vec![2.0; n],
        };
        assert!(flat.check(&mesh, &mesh).unwrap_err().contains("constant"));
    }
}
