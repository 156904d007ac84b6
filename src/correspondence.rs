//! The correspondence file of registration (`beltrami register --correspondence`): where
//! each source vertex lands on the target mesh.
//!
//! # Format
//!
//! Plain text, one line per source mesh vertex in [`VertexId`] order (the source file's
//! order without the vertices no face uses), nothing else:
//!
//! ```text
//! FACE b0 b1 b2
//! ```
//!
//! `FACE` is the target face holding the image, by its 0-based index in the target
//! file's face order ([`Mesh::face_to_input`]); `b0 b1 b2` are the image's barycentric
//! coordinates in that face's vertex order ([`beltrami_mesh::SurfacePoint`]), written
//! with full `f64` precision so that the file reads back exactly. A quad face gets its
//! four bilinear weights `w0 w1 w2 w3`. Fields are separated by single spaces.
//!
//! [`write()`] writes atomically (complete or absent); [`read`] checks every line and names
//! the file and the 1-based line of the first bad one ([`CorrespondenceError`]).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami_mesh::io::{WriteError, write_atomically};
use beltrami_mesh::{FaceId, Mesh, SurfacePoint, SurfacePointError, VertexId};
use thiserror::Error;

/// What is wrong with one line of a correspondence file.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LineError {
    /// The face field is not a non-negative integer.
    #[error("`{text}` is not a face index")]
    NotAnIndex {
        /// The field as written.
        text: String,
    },
    /// The face index names no face of the target mesh.
    #[error("face {index} is not a face of the target mesh")]
    NotAFace {
        /// The 0-based input index.
        index: usize,
    },
    /// A coordinate is not a number.
    #[error("`{text}` is not a number")]
    NotANumber {
        /// The field as written.
        text: String,
    },
    /// The line does not have one coordinate per vertex of its face.
    #[error("face {index} has {degree} vertices but the line has {got} coordinates")]
    CoordinateCount {
        /// The 0-based input index of the face.
        index: usize,
        /// Number of vertices of the face.
        degree: usize,
        /// Number of coordinates given.
        got: usize,
    },
    /// The coordinates are not those of a point of the face.
    #[error(transparent)]
    Point(#[from] SurfacePointError),
}

/// Why a correspondence file could not be read or written.
#[derive(Debug, Error)]
pub enum CorrespondenceError {
    /// The file could not be read.
    #[error("cannot read the correspondence {}: {error}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        error: std::io::Error,
    },
    /// The file could not be written (the destination is left untouched).
    #[error("cannot write the correspondence {}: {error}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What failed.
        #[source]
        error: WriteError,
    },
    /// The points to write are not one per source vertex.
    #[error("{got} points for a source mesh of {expected} vertices")]
    Length {
        /// Number of source vertices.
        expected: usize,
        /// Number of points.
        got: usize,
    },
    /// A point to write is not a point of the target mesh.
    #[error("the image of source vertex {vertex} (input index) is not on the target mesh: {error}")]
    OffTarget {
        /// The input index of the source vertex.
        vertex: usize,
        /// What is wrong with it.
        #[source]
        error: SurfacePointError,
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
    /// The file does not have one line per source vertex.
    #[error("{}: {got} lines for a source mesh of {expected} vertices", path.display())]
    LineCount {
        /// The file.
        path: PathBuf,
        /// Number of source vertices.
        expected: usize,
        /// Number of lines.
        got: usize,
    },
}

/// Writes `points` (the image of every vertex of `source`, by [`VertexId`], on
/// `target`) to `path` in the format of the module docs, atomically. Every point is
/// checked with [`SurfacePoint::validate`] first.
pub fn write(
    path: &Path,
    source: &Mesh,
    target: &Mesh,
    points: &[SurfacePoint],
) -> Result<(), CorrespondenceError> {
    if points.len() != source.vertex_count() {
        return Err(CorrespondenceError::Length {
            expected: source.vertex_count(),
            got: points.len(),
        });
    }
    for (v, p) in points.iter().enumerate() {
        p.validate(target)
            .map_err(|error| CorrespondenceError::OffTarget {
                vertex: source.vertex_map().to_input(VertexId(v as u32)),
                error,
            })?;
    }
    write_atomically(path, |w| {
        for p in points {
            write!(w, "{}", target.face_to_input(p.face))?;
            for c in &p.coords[..target.face_degree(p.face)] {
                write!(w, " {c}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
    .map_err(|error| CorrespondenceError::Write {
        path: path.to_path_buf(),
        error,
    })
}

/// Reads the file `path`: the image on `target` of every vertex of `source`, by
/// [`VertexId`] (format in the module docs).
pub fn read(
    path: &Path,
    source: &Mesh,
    target: &Mesh,
) -> Result<Vec<SurfacePoint>, CorrespondenceError> {
    let text =
        beltrami_mesh::io::source::read_text(path).map_err(|error| CorrespondenceError::Read {
            path: path.to_path_buf(),
            error,
        })?;
    parse(path, &text, source, target)
}

/// Parses `text`, the content of the file `path` (named in errors), like [`read`].
pub fn parse(
    path: &Path,
    text: &str,
    source: &Mesh,
    target: &Mesh,
) -> Result<Vec<SurfacePoint>, CorrespondenceError> {
    let faces = faces_by_input(target);
    let points = text
        .lines()
        .enumerate()
        .map(|(k, line)| {
            parse_line(line, &faces, target).map_err(|error| CorrespondenceError::Line {
                path: path.to_path_buf(),
                line: k + 1,
                error,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    if points.len() != source.vertex_count() {
        return Err(CorrespondenceError::LineCount {
            path: path.to_path_buf(),
            expected: source.vertex_count(),
            got: points.len(),
        });
    }
    Ok(points)
}

/// The face of every input face index of `mesh` (`None` for faces a repair dropped).
fn faces_by_input(mesh: &Mesh) -> Vec<Option<FaceId>> {
    let len = mesh
        .faces()
        .map(|f| mesh.face_to_input(f) + 1)
        .max()
        .unwrap_or(0);
    let mut faces = vec![None; len];
    for f in mesh.faces() {
        faces[mesh.face_to_input(f)] = Some(f);
    }
    faces
}

/// One line: the face by its input index, then one coordinate per face vertex.
fn parse_line(
    line: &str,
    faces: &[Option<FaceId>],
    target: &Mesh,
) -> Result<SurfacePoint, LineError> {
    let mut fields = line.split_whitespace();
    let text = fields.next().unwrap_or("");
    let index: usize = text.parse().map_err(|_| LineError::NotAnIndex {
        text: text.to_string(),
    })?;
    let face = faces
        .get(index)
        .copied()
        .flatten()
        .ok_or(LineError::NotAFace { index })?;
    let coords = fields
        .map(|t| {
            t.parse::<f64>().map_err(|_| LineError::NotANumber {
                text: t.to_string(),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let degree = target.face_degree(face);
    if coords.len() != degree {
        return Err(LineError::CoordinateCount {
            index,
            degree,
            got: coords.len(),
        });
    }
    let mut point = SurfacePoint {
        face,
        coords: [0.0; 4],
    };
    point.coords[..degree].copy_from_slice(&coords);
    point.validate(target)?;
    Ok(point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::PolygonSoup;
    use beltrami_mesh::primitives::{Cells, grid};

    /// A 3x3 triangle grid (16 vertices) as the source, and as the target two triangles
    /// and a quad.
    fn meshes() -> (Mesh, Mesh) {
        let source = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
        let grid = grid(2, 1, Cells::Quads);
        let mut target = PolygonSoup::new(grid.positions.clone());
        // Quad 0 split into two triangles, quad 1 kept: faces 0, 1 triangles, 2 a quad.
        let quads: Vec<Vec<u32>> = grid.faces().map(|f| f.to_vec()).collect();
        let q = &quads[0];
        target.push_face(&[q[0], q[1], q[2]]);
        target.push_face(&[q[0], q[2], q[3]]);
        target.push_face(&quads[1]);
        (source, Mesh::from_soup(&target).unwrap())
    }

    /// One point per source vertex, spread over the target's faces.
    fn points(source: &Mesh, target: &Mesh) -> Vec<SurfacePoint> {
        source
            .vertices()
            .map(|v| {
                let t = 0.05 * v.idx() as f64;
                let face = FaceId((v.idx() % 3) as u32);
                if target.face_degree(face) == 4 {
                    SurfacePoint::in_quad(face, t, 1.0 - t / 3.0)
                } else {
                    SurfacePoint::in_triangle(face, [t, 0.1, 0.9 - t])
                }
            })
            .collect()
    }

    #[test]
    fn points_round_trip_exactly() {
        let (source, target) = meshes();
        let points = points(&source, &target);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corr.txt");
        write(&path, &source, &target, &points).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), source.vertex_count());
        assert_eq!(lines[0], "0 0 0.1 0.9");
        assert_eq!(lines[2].split(' ').count(), 5, "a quad has four weights");
        assert_eq!(read(&path, &source, &target).unwrap(), points);
    }

    #[test]
    fn faces_are_input_indices() {
        // Target input face 1 is a duplicate of face 0 and dropped by the repair: input
        // face 2 is mesh face 1.
        let source = Mesh::from_soup(&grid(1, 1, Cells::Triangles)).unwrap();
        let mut soup = PolygonSoup::new(grid(1, 1, Cells::Quads).positions);
        soup.push_face(&[0, 1, 2]);
        soup.push_face(&[0, 1, 2]);
        soup.push_face(&[0, 2, 3]);
        let options = beltrami_mesh::BuildOptions {
            repair: beltrami_mesh::Repair::ALL,
            ..Default::default()
        };
        let (target, _) = Mesh::build(&soup, &options).unwrap();
        assert_eq!(target.face_to_input(FaceId(1)), 2);
        let points = vec![SurfacePoint::in_triangle(FaceId(1), [0.25, 0.25, 0.5]); 4];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corr.txt");
        write(&path, &source, &target, &points).unwrap();
        assert!(
            std::fs::read_to_string(&path)
                .unwrap()
                .starts_with("2 0.25 0.25 0.5\n")
        );
        assert_eq!(read(&path, &source, &target).unwrap(), points);
        let err = parse(&path, "1 1 0 0\n", &source, &target).unwrap_err();
        assert!(err.to_string().contains("face 1 is not a face"), "{err}");
    }

    #[test]
    fn bad_lines_are_named() {
        let (source, target) = meshes();
        let path = Path::new("corr.txt");
        let good = "0 1 0 0\n".repeat(15);
        for (last, line, expected) in [
            ("x 1 0 0", 16, LineError::NotAnIndex { text: "x".into() }),
            ("", 16, LineError::NotAnIndex { text: "".into() }),
            ("7 1 0 0", 16, LineError::NotAFace { index: 7 }),
            (
                "0 1 zero 0",
                16,
                LineError::NotANumber {
                    text: "zero".into(),
                },
            ),
            (
                "0 1 0",
                16,
                LineError::CoordinateCount {
                    index: 0,
                    degree: 3,
                    got: 2,
                },
            ),
            (
                "2 1 0 0",
                16,
                LineError::CoordinateCount {
                    index: 2,
                    degree: 4,
                    got: 3,
                },
            ),
        ] {
            let text = format!("{good}{last}\n");
            match parse(path, &text, &source, &target).unwrap_err() {
                CorrespondenceError::Line { line: l, error, .. } => {
                    assert_eq!((l, error), (line, expected), "{last:?}")
                }
                other => panic!("{last:?}: {other}"),
            }
        }
        // Coordinates are validated as a point of the face.
        let err = parse(path, &format!("{good}1 0.5 0.6 -0.1\n"), &source, &target).unwrap_err();
        assert!(
            matches!(
                err,
                CorrespondenceError::Line {
                    line: 16,
                    error: LineError::Point(SurfacePointError::InvalidCoordinates { .. }),
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().starts_with("corr.txt:16: "), "{err}");
        let err = parse(path, &format!("{good}1 NaN 0 1\n"), &source, &target).unwrap_err();
        assert!(
            matches!(
                err,
                CorrespondenceError::Line {
                    error: LineError::Point(SurfacePointError::NonFinite { .. }),
                    ..
                }
            ),
            "{err}"
        );
        // One line per source vertex.
        let err = parse(path, &good, &source, &target).unwrap_err();
        assert!(
            matches!(
                err,
                CorrespondenceError::LineCount {
                    expected: 16,
                    got: 15,
                    ..
                }
            ),
            "{err}"
        );
        let err = read(Path::new("/nonexistent/corr.txt"), &source, &target).unwrap_err();
        assert!(matches!(err, CorrespondenceError::Read { .. }), "{err}");
    }

    #[test]
    fn points_off_the_target_are_not_written() {
        let (source, target) = meshes();
        let mut points = points(&source, &target);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corr.txt");
        let err = write(&path, &source, &target, &points[1..]).unwrap_err();
        assert!(matches!(
            err,
            CorrespondenceError::Length {
                expected: 16,
                got: 15
            }
        ));
        points[4].face = FaceId(9);
        let err = write(&path, &source, &target, &points).unwrap_err();
        assert!(
            matches!(err, CorrespondenceError::OffTarget { vertex: 4, .. }),
            "{err}"
        );
        assert!(!path.exists());
    }
}
