//! The two linearized problems the QC iteration alternates with: the least-squares QC
//! map of a coefficient `mu` into the plane (complex unknowns, `f_zbar - mu f_z`) and
//! into R^3 (quaternionic, `df^- - mu df^+`, Gruber-Aulisa 2022, Algorithm 1), with what
//! the iteration reads of the current map: its own coefficient, its residual under a
//! coefficient (for the line search), its distortion.

use beltrami_core::{Map, SolverError};
use beltrami_fem::beltrami::{face_mu, planar_map, surface_map};
use beltrami_fem::operators::beltrami_operator;
use beltrami_fem::quaternion::quaternionic_mu;
use beltrami_fem::quaternionic_lsqc::SpaceSystem;
use beltrami_fem::{Distortion, Elements, LeastSquaresSolver, ReferenceNormal};
use beltrami_mesh::{Mesh, Point3};
use num_complex::Complex64;

/// A least-squares QC problem with its current map (module docs).
pub(crate) trait Linearized {
    /// The elements the coefficient lives on (one value per face, in their frames).
    fn elements(&self) -> &Elements;
    /// Replaces the current map by the minimizer for `mu`.
    fn solve(&mut self, mu: &[Complex64]) -> Result<(), SolverError>;
    /// The current map's own coefficient per face.
    fn measured(&self) -> Result<Vec<Complex64>, SolverError>;
    /// The current map's residual under `mu`, each component times the square root of
    /// its quadrature weight (its squared norm is the distortion energy).
    fn residual(&self, mu: &[Complex64]) -> Result<Vec<f64>, SolverError>;
    /// `|mu|` statistics and flips of the current map.
    fn distortion(&self) -> Result<Distortion, SolverError>;
    /// The current map.
    fn map(&self) -> Map;
}

/// Into the plane: `f_zbar - mu f_z` over the quadrature points (global frame).
pub(crate) struct Planar<'m> {
    pub(crate) mesh: &'m Mesh,
    pub(crate) elements: Elements,
    pub(crate) solver: LeastSquaresSolver<Complex64>,
    pub(crate) weights: Vec<f64>,
    /// The zero right-hand side (one entry per quadrature point).
    pub(crate) rhs: Vec<Complex64>,
    pub(crate) map: Vec<Complex64>,
}

impl Linearized for Planar<'_> {
    fn elements(&self) -> &Elements {
        &self.elements
    }

    fn solve(&mut self, mu: &[Complex64]) -> Result<(), SolverError> {
        let operator = beltrami_operator(self.mesh, &self.elements, mu)?;
        self.map = self
            .solver
            .solve(operator.as_ref(), Some(&self.weights), &self.rhs)?;
        Ok(())
    }

    fn measured(&self) -> Result<Vec<Complex64>, SolverError> {
        let point_mu: Vec<Complex64> = planar_map(&self.elements, self.map.len(), &self.map)?
            .iter()
            .map(|d| d.mu())
            .collect();
        Ok(face_mu(&self.elements, &point_mu))
    }

    fn residual(&self, mu: &[Complex64]) -> Result<Vec<f64>, SolverError> {
        let d = planar_map(&self.elements, self.map.len(), &self.map)?;
        Ok(self
            .elements
            .points()
            .iter()
            .zip(d)
            .flat_map(|(q, d)| {
                let r = (d.fzbar - mu[q.face.idx()] * d.fz) * q.weight.sqrt();
                [r.re, r.im]
            })
            .collect())
    }

    fn distortion(&self) -> Result<Distortion, SolverError> {
        let d = planar_map(&self.elements, self.mesh.vertex_count(), &self.map)?;
        Ok(Distortion::from_derivatives(&self.elements, &d)?)
    }

    fn map(&self) -> Map {
        Map::Planar(self.map.clone())
    }
}

/// Into R^3: the quaternionic `df^- - mu df^+` ([`SpaceSystem`]), measured against the
/// elements' shapes (the surface's own, or reference polygons) with the surface's
/// normals.
pub(crate) struct Space {
    pub(crate) system: SpaceSystem,
    pub(crate) vertex_count: usize,
    pub(crate) image: Vec<Point3<f64>>,
}

impl Linearized for Space {
    fn elements(&self) -> &Elements {
        self.system.elements()
    }

    fn solve(&mut self, mu: &[Complex64]) -> Result<(), SolverError> {
        self.image = self.system.solve(mu)?;
        Ok(())
    }

    fn measured(&self) -> Result<Vec<Complex64>, SolverError> {
        let elements = self.system.elements();
        Ok(face_mu(
            elements,
            &quaternionic_mu(elements, self.vertex_count, &self.image)?,
        ))
    }

    fn residual(&self, mu: &[Complex64]) -> Result<Vec<f64>, SolverError> {
        Ok(self.system.residual(mu, &self.image)?)
    }

    fn distortion(&self) -> Result<Distortion, SolverError> {
        let elements = self.system.elements();
        let d = surface_map(
            elements,
            self.vertex_count,
            &self.image,
            ReferenceNormal::Source,
        )?;
        Ok(Distortion::from_derivatives(elements, &d)?)
    }

    fn map(&self) -> Map {
        Map::Spatial(self.image.clone())
    }
}
