//! The landmarks file of registration (`beltrami register --landmarks`): where given
//! source vertices and chains must go on the target mesh.
//!
//! # Format
//!
//! One constraint per line; `#` starts a comment, blank lines are skipped:
//!
//! ```text
//! v SRC_VERTEX TGT_VERTEX                 # source vertex onto a target vertex
//! p SRC_VERTEX x y z                      # source vertex onto the target point nearest (x, y, z)
//! c SRC_V1,SRC_V2,... TGT_W1,TGT_W2,...   # a source chain onto a target chain, ends fixed
//! ```
//!
//! Maps into the plane (`beltrami qc --landmarks`, the four-point problem of the
//! extremal solver) take points of the plane instead, read by [`read_planar`]:
//!
//! ```text
//! p SRC_VERTEX x y                        # source vertex onto the point x + i y
//! ```
//!
//! Vertex indices are 0-based in each mesh file's own order (the input order,
//! [`beltrami_mesh::VertexMap`]); coordinates are finite numbers. A chain has at least
//! two vertices; a source vertex has at most one `v` or `p` line. Errors
//! ([`LandmarksError`]) name the file and the 1-based line: `marks.txt:3: ...`.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let source = beltrami::mesh::Mesh::from_soup(&beltrami::mesh::primitives::disk(2))?;
//! # let target = source.clone();
//! use beltrami::landmarks::Landmarks;
//! let marks = Landmarks::read("marks.txt".as_ref(), &source, &target)?;
//! let constraints = marks.constraints(); // Landmark and open Curve constraints
//! # Ok(()) }
//! ```

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

use beltrami_core::{Constraint, Constraints, Curve, Landmark, Position};
use beltrami_mesh::{Mesh, Point3, VertexId};
use num_complex::Complex64;
use thiserror::Error;

/// Which mesh a vertex index of the file refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The source mesh (the first field of a line).
    Source,
    /// The target mesh (the second field of a `v` or `c` line).
    Target,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Source => "source",
            Side::Target => "target",
        })
    }
}

/// What is wrong with one line of a landmarks file.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LineError {
    /// A vertex field is not a non-negative integer.
    #[error("`{text}` is not a {side} vertex index")]
    NotAnIndex {
        /// The mesh the index refers to.
        side: Side,
        /// The field as written.
        text: String,
    },
    /// A vertex index names no vertex of its mesh (out of range, or used by no face).
    #[error("{side} vertex {index} is not a vertex of the {side} mesh")]
    NotAVertex {
        /// The mesh the index refers to.
        side: Side,
        /// The 0-based input index.
        index: usize,
    },
    /// A coordinate of a `p` line is not a number.
    #[error("`{text}` is not a number")]
    NotANumber {
        /// The field as written.
        text: String,
    },
    /// A coordinate of a `p` line is NaN or infinite.
    #[error("`{text}` is not finite")]
    NotFinite {
        /// The field as written.
        text: String,
    },
    /// A chain of a `c` line has fewer than two vertices.
    #[error("a {side} chain needs at least two vertices")]
    ShortChain {
        /// The mesh of the chain.
        side: Side,
    },
    /// The line is none of `v`, `p`, `c` with their fields.
    #[error("expected `v SRC TGT`, `p SRC x y z` or `c SRC,SRC,.. TGT,TGT,..`, found `{found}`")]
    Syntax {
        /// The line without its comment.
        found: String,
    },
    /// A line of a planar landmarks file that is not `p SRC x y`.
    #[error("expected `p SRC x y` (a source vertex and a point of the plane), found `{found}`")]
    PlanarSyntax {
        /// The line's content (comment removed).
        found: String,
    },
    /// A source vertex already has a `v` or `p` line.
    #[error("source vertex {index} has two landmarks (the first on line {first_line})")]
    TwoLandmarks {
        /// The 0-based input index of the source vertex.
        index: usize,
        /// The 1-based line of its first landmark.
        first_line: usize,
    },
}

/// Why a landmarks file could not be read.
#[derive(Debug, Error)]
pub enum LandmarksError {
    /// The file could not be read.
    #[error("cannot read the landmarks {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        error: std::io::Error,
    },
    /// A line is wrong.
    #[error("{}:{line}: {error}", path.display())]
    Line {
        /// The file.
        path: PathBuf,
        /// The 1-based line number.
        line: usize,
        /// What is wrong.
        #[source]
        error: LineError,
    },
}

/// One `v` or `p` line: its landmark, the target vertex ([`Position::TargetVertex`]) of
/// a `v` line or the point ([`Position::Spatial`]) of a `p` line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkLine {
    /// The 1-based line number in the file.
    pub line: usize,
    /// The landmark.
    pub landmark: Landmark,
}

/// One `c` line: a source chain onto a target chain, both of at least two vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveLine {
    /// The 1-based line number in the file.
    pub line: usize,
    /// Source vertices, in order.
    pub source: Vec<VertexId>,
    /// Target vertices, in order.
    pub target: Vec<VertexId>,
}

/// A parsed landmarks file (module docs), vertices as mesh ids.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Landmarks {
    /// The `v` and `p` lines, in file order.
    pub points: Vec<LandmarkLine>,
    /// The `c` lines, in file order.
    pub curves: Vec<CurveLine>,
}

/// The mesh vertex of the index `text` of `side`.
fn vertex(text: &str, mesh: &Mesh, side: Side) -> Result<VertexId, LineError> {
    let index: usize = text.parse().map_err(|_| LineError::NotAnIndex {
        side,
        text: text.to_string(),
    })?;
    mesh.vertex_map()
        .from_input(index)
        .ok_or(LineError::NotAVertex { side, index })
}

/// The mesh vertices of the comma-separated chain `text` of `side`.
fn chain(text: &str, mesh: &Mesh, side: Side) -> Result<Vec<VertexId>, LineError> {
    let chain = text
        .split(',')
        .map(|t| vertex(t.trim(), mesh, side))
        .collect::<Result<Vec<_>, _>>()?;
    if chain.len() < 2 {
        return Err(LineError::ShortChain { side });
    }
    Ok(chain)
}

/// A finite coordinate of a `p` line.
fn coordinate(text: &str) -> Result<f64, LineError> {
    let value: f64 = text.parse().map_err(|_| LineError::NotANumber {
        text: text.to_string(),
    })?;
    if !value.is_finite() {
        return Err(LineError::NotFinite {
            text: text.to_string(),
        });
    }
    Ok(value)
}

/// One line of the file, parsed.
enum Parsed {
    /// A `v` or `p` line.
    Point(Landmark),
    /// A `c` line: the source and target chains.
    Curve(Vec<VertexId>, Vec<VertexId>),
}

/// Parses `content`, a line without its comment and not empty.
fn parse_line(content: &str, source: &Mesh, target: &Mesh) -> Result<Parsed, LineError> {
    let fields: Vec<&str> = content.split_whitespace().collect();
    Ok(match fields.as_slice() {
        ["v", s, t] => Parsed::Point(Landmark {
            vertex: vertex(s, source, Side::Source)?,
            position: Position::TargetVertex(vertex(t, target, Side::Target)?),
        }),
        ["p", s, x, y, z] => Parsed::Point(Landmark {
            vertex: vertex(s, source, Side::Source)?,
            position: Position::Spatial(Point3::new(
                coordinate(x)?,
                coordinate(y)?,
                coordinate(z)?,
            )),
        }),
        ["c", s, t] => Parsed::Curve(
            chain(s, source, Side::Source)?,
            chain(t, target, Side::Target)?,
        ),
        _ => {
            return Err(LineError::Syntax {
                found: content.to_string(),
            });
        }
    })
}

/// The text of the landmarks file `path`.
fn read_text(path: &Path) -> Result<String, LandmarksError> {
    beltrami_mesh::io::source::read_text(path).map_err(|error| LandmarksError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// The 1-based number and content (comment removed, trimmed) of every line that has
/// any.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(k, raw)| (k + 1, raw.split('#').next().unwrap_or("").trim()))
        .filter(|(_, content)| !content.is_empty())
}

/// Reads the landmarks of a map of `source` into the plane (module docs: `p SRC x y`
/// lines) as [`Landmark`] constraints with planar positions, in file order; errors name
/// the file and line.
pub fn read_planar(path: &Path, source: &Mesh) -> Result<Vec<Landmark>, LandmarksError> {
    let text = read_text(path)?;
    let mut out: Vec<Landmark> = Vec::new();
    let mut first_line: HashMap<VertexId, usize> = HashMap::new();
    for (line, content) in content_lines(&text) {
        let at = |error| LandmarksError::Line {
            path: path.to_path_buf(),
            line,
            error,
        };
        let fields: Vec<&str> = content.split_whitespace().collect();
        let ["p", s, x, y] = fields.as_slice() else {
            return Err(at(LineError::PlanarSyntax {
                found: content.to_string(),
            }));
        };
        let vertex = vertex(s, source, Side::Source).map_err(at)?;
        let point = Complex64::new(coordinate(x).map_err(at)?, coordinate(y).map_err(at)?);
        if let Some(&first_line) = first_line.get(&vertex) {
            return Err(at(LineError::TwoLandmarks {
                index: source.vertex_map().to_input(vertex),
                first_line,
            }));
        }
        first_line.insert(vertex, line);
        out.push(Landmark {
            vertex,
            position: Position::Planar(point),
        });
    }
    Ok(out)
}

impl Landmarks {
    /// Reads and parses the file `path` against the source and target meshes.
    pub fn read(path: &Path, source: &Mesh, target: &Mesh) -> Result<Self, LandmarksError> {
        Self::parse(path, &read_text(path)?, source, target)
    }

    /// Parses `text`, the content of the file `path` (named in errors), against the
    /// source and target meshes.
    pub fn parse(
        path: &Path,
        text: &str,
        source: &Mesh,
        target: &Mesh,
    ) -> Result<Self, LandmarksError> {
        let mut out = Landmarks::default();
        let mut first_line: HashMap<VertexId, usize> = HashMap::new();
        for (line, content) in content_lines(text) {
            let at = |error| LandmarksError::Line {
                path: path.to_path_buf(),
                line,
                error,
            };
            let landmark = match parse_line(content, source, target).map_err(at)? {
                Parsed::Point(landmark) => landmark,
                Parsed::Curve(source, target) => {
                    out.curves.push(CurveLine {
                        line,
                        source,
                        target,
                    });
                    continue;
                }
            };
            let vertex = landmark.vertex;
            if let Some(&first_line) = first_line.get(&vertex) {
                return Err(at(LineError::TwoLandmarks {
                    index: source.vertex_map().to_input(vertex),
                    first_line,
                }));
            }
            first_line.insert(vertex, line);
            out.points.push(LandmarkLine { line, landmark });
        }
        Ok(out)
    }

    /// The same landmarks for the registration the other way (target onto source):
    /// each `v` line and `c` line with its two sides exchanged. A `p` line has no vertex
    /// on the target to start from: its 1-based line number is the error.
    pub fn reversed(&self) -> Result<Self, usize> {
        let points = self
            .points
            .iter()
            .map(|l| match l.landmark.position {
                Position::TargetVertex(w) => Ok(LandmarkLine {
                    line: l.line,
                    landmark: Landmark {
                        vertex: w,
                        position: Position::TargetVertex(l.landmark.vertex),
                    },
                }),
                _ => Err(l.line),
            })
            .collect::<Result<_, _>>()?;
        let curves = self
            .curves
            .iter()
            .map(|c| CurveLine {
                line: c.line,
                source: c.target.clone(),
                target: c.source.clone(),
            })
            .collect();
        Ok(Self { points, curves })
    }

    /// The constraints of the file, in file order: a [`Constraint::Landmark`] per `v`
    /// line (onto the target vertex itself) and `p` line (at its point; the solver
    /// moves the vertex to the nearest target point), then a [`Constraint::Curve`]
    /// (open) per `c` line.
    pub fn constraints(&self) -> Constraints {
        let landmarks = self.points.iter().map(|l| Constraint::Landmark(l.landmark));
        let curves = self
            .curves
            .iter()
            .map(|c| Constraint::Curve(Curve::open(c.source.clone(), c.target.clone())));
        landmarks.chain(curves).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    fn mesh() -> Mesh {
        Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap()
    }

    #[test]
    fn lines_parse_in_file_order() {
        let mesh = mesh();
        let path = Path::new("marks.txt");
        let text = "# landmarks\nv 0 5\np 3 0.5 0.5 0 # a point\n\nc 1,2,6 1, 2,6\n";
        // The chain `1, 2,6` splits into fields at the space: a syntax error.
        let err = Landmarks::parse(path, text, &mesh, &mesh).unwrap_err();
        assert!(matches!(
            err,
            LandmarksError::Line {
                line: 5,
                error: LineError::Syntax { .. },
                ..
            }
        ));
        let text = "# landmarks\nv 0 5\np 3 0.5 0.5 0 # a point\n\nc 1,2,6 1,2,6\n";
        let parsed = Landmarks::parse(path, text, &mesh, &mesh).unwrap();
        assert_eq!(
            parsed.points,
            vec![
                LandmarkLine {
                    line: 2,
                    landmark: Landmark {
                        vertex: VertexId(0),
                        position: Position::TargetVertex(VertexId(5)),
                    },
                },
                LandmarkLine {
                    line: 3,
                    landmark: Landmark {
                        vertex: VertexId(3),
                        position: Position::Spatial(Point3::new(0.5, 0.5, 0.0)),
                    },
                },
            ]
        );
        assert_eq!(parsed.curves.len(), 1);
        assert_eq!(parsed.curves[0].line, 5);
        assert_eq!(
            parsed.curves[0].source,
            vec![VertexId(1), VertexId(2), VertexId(6)]
        );
    }

    #[test]
    fn errors_name_the_file_the_line_and_what_is_wrong() {
        let mesh = mesh();
        let path = Path::new("marks.txt");
        let source_side = Side::Source;
        let target_side = Side::Target;
        for (bad, line, expected, needle) in [
            (
                "v 0 99\n",
                1,
                LineError::NotAVertex {
                    side: target_side,
                    index: 99,
                },
                "marks.txt:1: target vertex 99 is not a vertex of the target mesh",
            ),
            (
                "v x 1\n",
                1,
                LineError::NotAnIndex {
                    side: source_side,
                    text: "x".into(),
                },
                "`x` is not a source vertex index",
            ),
            (
                "v 0\n",
                1,
                LineError::Syntax {
                    found: "v 0".into(),
                },
                "expected",
            ),
            (
                "\n\np 1 x 0 0\n",
                3,
                LineError::NotANumber { text: "x".into() },
                "marks.txt:3",
            ),
            (
                "p 1 0 inf 0\n",
                1,
                LineError::NotFinite { text: "inf".into() },
                "not finite",
            ),
            (
                "c 1 2,3\n",
                1,
                LineError::ShortChain { side: source_side },
                "at least two",
            ),
            (
                "v 0 1\nv 0 2\n",
                2,
                LineError::TwoLandmarks {
                    index: 0,
                    first_line: 1,
                },
                "two landmarks",
            ),
            (
                "v 0 1\n# again\np 0 0 0 0\n",
                3,
                LineError::TwoLandmarks {
                    index: 0,
                    first_line: 1,
                },
                "marks.txt:3: source vertex 0 has two landmarks (the first on line 1)",
            ),
        ] {
            let err = Landmarks::parse(path, bad, &mesh, &mesh).unwrap_err();
            let message = err.to_string();
            assert!(message.contains(needle), "{bad:?}: {message}");
            match err {
                LandmarksError::Line {
                    path: p,
                    line: l,
                    error,
                } => {
                    assert_eq!(p, path);
                    assert_eq!((l, error), (line, expected), "{bad:?}");
                }
                other => panic!("{bad:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn an_unreadable_file_is_named() {
        let mesh = mesh();
        let err = Landmarks::read(Path::new("/nonexistent/marks.txt"), &mesh, &mesh).unwrap_err();
        assert!(matches!(err, LandmarksError::Io { .. }));
        assert!(err.to_string().contains("/nonexistent/marks.txt"), "{err}");
    }

    #[test]
    fn constraints_keep_vertex_landmarks_as_target_vertices_and_curves_open() {
        let source = mesh();
        // The target: the same grid moved, so that positions differ from the source's.
        let mut soup = grid(3, 3, Cells::Triangles);
        for p in &mut soup.positions {
            p.z = 1.0;
        }
        let target = Mesh::from_soup(&soup).unwrap();
        let text = "c 1,2 4,5\nv 0 5\np 3 0.25 0.5 2\n";
        let marks = Landmarks::parse(Path::new("m.txt"), text, &source, &target).unwrap();
        let constraints = marks.constraints();
        assert_eq!(constraints.len(), 3);
        constraints.validate(&source, Some(&target)).unwrap();
        let landmarks: Vec<&Landmark> = constraints.landmarks().collect();
        assert_eq!(
            *landmarks[0],
            Landmark {
                vertex: VertexId(0),
                position: Position::TargetVertex(VertexId(5)),
            }
        );
        assert_eq!(
            landmarks[1].position,
            Position::Spatial(Point3::new(0.25, 0.5, 2.0))
        );
        let curves: Vec<&Curve> = constraints.curves().collect();
        assert_eq!(
            *curves[0],
            Curve::open(
                vec![VertexId(1), VertexId(2)],
                vec![VertexId(4), VertexId(5)]
            )
        );
    }

    #[test]
    fn indices_are_input_indices() {
        // Input vertex 0 is used by no face: the mesh leaves it out, and input index 1
        // is mesh vertex 0.
        let grid = grid(2, 2, Cells::Triangles);
        let mut positions = vec![Point3::new(9.0, 9.0, 9.0)];
        positions.extend(&grid.positions);
        let mut soup = beltrami_mesh::PolygonSoup::new(positions);
        for face in grid.faces() {
            let shifted: Vec<u32> = face.iter().map(|v| v + 1).collect();
            soup.push_face(&shifted);
        }
        let mesh = Mesh::from_soup(&soup).unwrap();
        let path = Path::new("m.txt");
        let marks = Landmarks::parse(path, "v 1 2\n", &mesh, &mesh).unwrap();
        assert_eq!(
            marks.points[0].landmark,
            Landmark {
                vertex: VertexId(0),
                position: Position::TargetVertex(VertexId(1)),
            }
        );
        let err = Landmarks::parse(path, "v 0 2\n", &mesh, &mesh).unwrap_err();
        assert!(
            err.to_string().contains("source vertex 0 is not a vertex"),
            "{err}"
        );
    }
}
