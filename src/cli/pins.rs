//! The `--pin` flag, shared by every command that pins vertices.
//!
//! `--pin v12` names vertex 12 by its 0-based index in the input file; `--pin x,y` or
//! `--pin x,y,z` names the vertex nearest to that point (z = 0 when omitted).

use std::str::FromStr;

use anyhow::{Context, bail};
use beltrami_mesh::{Mesh, Point3, VertexId};

/// A parsed `--pin` value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PinSpec {
    /// A vertex by its 0-based input index.
    Index(usize),
    /// The vertex nearest to a point.
    Near(Point3<f64>),
}

impl FromStr for PinSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if let Some(index) = s.strip_prefix('v') {
            return index
                .parse()
                .map(PinSpec::Index)
                .map_err(|_| format!("`{s}`: expected v<index>, e.g. v12"));
        }
        let coords: Result<Vec<f64>, _> = s.split(',').map(|t| t.trim().parse::<f64>()).collect();
        if let Ok(values) = &coords
            && values.iter().any(|x| !x.is_finite())
        {
            return Err(format!(
                "`{s}`: the point's coordinates must be finite numbers"
            ));
        }
        match coords.as_deref() {
            Ok([x, y]) => Ok(PinSpec::Near(Point3::new(*x, *y, 0.0))),
            Ok([x, y, z]) => Ok(PinSpec::Near(Point3::new(*x, *y, *z))),
            _ => Err(format!(
                "`{s}`: expected v<index> (e.g. v12) or a point x,y or x,y,z"
            )),
        }
    }
}

impl PinSpec {
    /// The mesh vertex this pin names.
    pub fn resolve(&self, mesh: &Mesh) -> anyhow::Result<VertexId> {
        match *self {
            PinSpec::Index(i) => {
                let map = mesh.vertex_map();
                if i >= map.input_len() {
                    bail!(
                        "--pin v{i}: the mesh has {} vertices (0-based indices)",
                        map.input_len()
                    );
                }
                map.from_input(i)
                    .with_context(|| format!("--pin v{i}: vertex {i} is used by no face"))
            }
            PinSpec::Near(p) => mesh.nearest_vertex(&p).context("the mesh has no vertices"),
        }
    }
}
