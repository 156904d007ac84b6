//! The landmarks file of `beltrami register`: one constraint per line, `#` comments.
//!
//! ```text
//! v SRC_VERTEX TGT_VERTEX            # source vertex onto a target vertex
//! p SRC_VERTEX x y z                 # source vertex onto the target point nearest (x, y, z)
//! c SRC_V1,SRC_V2,... TGT_W1,TGT_W2,...   # a source chain onto a target chain, ends fixed
//! ```
//!
//! Vertex indices are 0-based in each file's own order. Errors name the line.

use std::path::Path;

use anyhow::{Context as _, bail};
use beltrami_mesh::{Mesh, Point3, VertexId};

/// Where a landmark's source vertex goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LandmarkGoal {
    /// A target vertex.
    Vertex(VertexId),
    /// The target point nearest to a point of R^3.
    Point(Point3<f64>),
}

/// One `v` or `p` line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkLine {
    pub source: VertexId,
    pub goal: LandmarkGoal,
}

/// One `c` line.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveLine {
    pub source: Vec<VertexId>,
    pub target: Vec<VertexId>,
}

/// The parsed file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Landmarks {
    pub points: Vec<LandmarkLine>,
    pub curves: Vec<CurveLine>,
}

fn vertex(text: &str, mesh: &Mesh, side: &str) -> anyhow::Result<VertexId> {
    let index: usize = text
        .parse()
        .with_context(|| format!("`{text}` is not a {side} vertex index"))?;
    mesh.vertex_map()
        .from_input(index)
        .with_context(|| format!("{side} vertex {index} is not a vertex of the {side} mesh"))
}

fn chain(text: &str, mesh: &Mesh, side: &str) -> anyhow::Result<Vec<VertexId>> {
    let chain = text
        .split(',')
        .map(|t| vertex(t.trim(), mesh, side))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if chain.len() < 2 {
        bail!("a {side} chain needs at least two vertices");
    }
    Ok(chain)
}

/// Parses `text` (the file `path`) against the source and target meshes.
pub fn parse(path: &Path, text: &str, source: &Mesh, target: &Mesh) -> anyhow::Result<Landmarks> {
    let mut out = Landmarks::default();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = || format!("{}:{}", path.display(), k + 1);
        let fields: Vec<&str> = line.split_whitespace().collect();
        let parsed: anyhow::Result<()> = (|| {
            match fields.as_slice() {
                ["v", s, t] => out.points.push(LandmarkLine {
                    source: vertex(s, source, "source")?,
                    goal: LandmarkGoal::Vertex(vertex(t, target, "target")?),
                }),
                ["p", s, x, y, z] => {
                    let coordinate = |c: &str| -> anyhow::Result<f64> {
                        let value: f64 = c
                            .parse()
                            .with_context(|| format!("`{c}` is not a number"))?;
                        if !value.is_finite() {
                            bail!("`{c}` is not finite");
                        }
                        Ok(value)
                    };
                    out.points.push(LandmarkLine {
                        source: vertex(s, source, "source")?,
                        goal: LandmarkGoal::Point(Point3::new(
                            coordinate(x)?,
                            coordinate(y)?,
                            coordinate(z)?,
                        )),
                    });
                }
                ["c", s, t] => out.curves.push(CurveLine {
                    source: chain(s, source, "source")?,
                    target: chain(t, target, "target")?,
                }),
                _ => bail!(
                    "expected `v SRC TGT`, `p SRC x y z` or `c SRC,SRC,.. TGT,TGT,..`, found `{line}`"
                ),
            }
            Ok(())
        })();
        parsed.with_context(at)?;
    }
    let mut seen = std::collections::HashSet::new();
    for l in &out.points {
        if !seen.insert(l.source) {
            bail!(
                "{}: source vertex {} has two landmarks",
                path.display(),
                source.vertex_map().to_input(l.source)
            );
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    #[test]
    fn lines_parse_and_errors_name_the_line() {
        let mesh = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
        let path = Path::new("marks.txt");
        let text = "# landmarks\nv 0 5\np 3 0.5 0.5 0 # a point\n\nc 1,2,6 1,2,6\n";
        let parsed = parse(path, text, &mesh, &mesh).unwrap();
        assert_eq!(parsed.points.len(), 2);
        assert_eq!(parsed.points[0].goal, LandmarkGoal::Vertex(VertexId(5)));
        assert_eq!(parsed.curves[0].source.len(), 3);
        for (bad, needle) in [
            ("v 0 99\n", "marks.txt:1"),
            ("v 0\n", "expected"),
            ("\n\np 1 x 0 0\n", "marks.txt:3"),
            ("c 1 2,3\n", "at least two"),
            ("v 0 1\nv 0 2\n", "two landmarks"),
        ] {
            let message = format!("{:#}", parse(path, bad, &mesh, &mesh).unwrap_err());
            assert!(message.contains(needle), "{bad:?}: {message}");
        }
    }
}
