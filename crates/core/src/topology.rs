//! Topology checks shared by the capability checks of solvers.

use beltrami_mesh::Mesh;

use crate::SolverError;

/// The topology of a mesh in words, e.g. "genus 1 and no boundary", "genus 0 and 3
/// boundary loops", "2 components".
pub fn describe(mesh: &Mesh) -> String {
    let components = mesh.components();
    if components.len() != 1 {
        return format!("{} components", components.len());
    }
    let c = &components[0];
    let boundary = match c.boundary_loops {
        0 => "no boundary".to_string(),
        1 => "one boundary loop".to_string(),
        b => format!("{b} boundary loops"),
    };
    format!("genus {} and {boundary}", c.genus)
}

/// `Ok` for a single topological disk; otherwise [`SolverError::Unsupported`] saying what
/// the mesh is and `advice` (what to do instead).
pub fn require_disk(solver: &'static str, mesh: &Mesh, advice: &str) -> Result<(), SolverError> {
    if mesh.is_disk() {
        return Ok(());
    }
    Err(SolverError::unsupported(
        solver,
        format!(
            "{solver} maps disk-topology meshes; this mesh has {}: {advice}",
            describe(mesh)
        ),
    ))
}

/// `Ok` for a single closed genus-0 surface; otherwise [`SolverError::Unsupported`].
pub fn require_sphere(solver: &'static str, mesh: &Mesh, advice: &str) -> Result<(), SolverError> {
    let c = mesh.components();
    if c.len() == 1 && c[0].genus == 0 && c[0].boundary_loops == 0 {
        return Ok(());
    }
    Err(SolverError::unsupported(
        solver,
        format!(
            "{solver} maps closed genus-0 meshes; this mesh has {}: {advice}",
            describe(mesh)
        ),
    ))
}
