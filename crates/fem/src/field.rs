//! Beltrami fields: one complex coefficient `mu` per face, in a stated [`Frame`].
//!
//! A value `mu_f` is the Beltrami coefficient `f_zbar / f_z` of a map on face `f`,
//! expressed in the frame named by [`BeltramiField::frame`]: the plane's own coordinate
//! `z = x + i y` ([`Frame::Global`], meshes in the plane z = 0) or each face's frame
//! ([`Frame::Face`]: real axis along the face's first edge, see [`crate::element`]). The
//! same map has different coefficients in different frames; [`BeltramiField::to_frame`]
//! converts between them with the rotation rule (Gruber-Aulisa 2022, Lemma 3.4).
//!
//! A field that prescribes a quasiconformal map has `|mu_f| < 1` on every face
//! ([`BeltramiField::check`]). A field measured from a map may have `|mu_f| > 1` on
//! flipped faces.
//!
//! # File format
//!
//! Plain text, one value per face in face order:
//!
//! ```text
//! # mu frame=global faces=3
//! 0.25 0
//! 0.1 -0.05
//! # comment lines and blank lines are allowed after the header
//! 0 0
//! ```
//!
//! - Line 1 is the header `# mu frame=<global|face> faces=<N>`: the keys `frame` and
//!   `faces` each once, in either order, separated by whitespace.
//! - Then exactly `N` value lines `re im`: two decimal numbers separated by whitespace,
//!   `mu_f = re + i im` for face `f` (the mesh's face order, which is the file's face
//!   order unless a repair dropped faces). Blank lines and further lines starting with
//!   `#` are skipped.
//! - The writer prints each number with the shortest decimal that reads back to the same
//!   `f64` (Rust's `Display`), so a written field reads back bit for bit, and writes
//!   atomically ([`beltrami_mesh::io::write_atomically`]).
//! - The reader checks the header, that `N` is the mesh's face count, that there are `N`
//!   values, that every value is finite and that `|mu| < 1`; errors name the file, the
//!   1-based line and the face ([`FieldError`]).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami_mesh::io::WriteError;
use beltrami_mesh::{FaceId, Mesh};
use num_complex::Complex64;
use thiserror::Error;

use crate::beltrami::rotate_frame;
use crate::element::check_planar;
use crate::{FemError, Frame};

/// The frames a field file may name, for error messages.
const KNOWN_FRAMES: &str = "global, face";

/// The header a field file must start with, for error messages.
const HEADER_FORMAT: &str = "# mu frame=<global|face> faces=<N>";

/// Why a Beltrami field could not be read, written, checked or converted.
#[derive(Debug, Error)]
pub enum FieldError {
    /// The file could not be opened or read (or is not UTF-8 text).
    #[error("cannot read {path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// Line 1 is not a valid header.
    #[error("{path}:1: expected the header `{HEADER_FORMAT}`, found `{found}`")]
    Header {
        /// The file.
        path: PathBuf,
        /// The first line as found (empty for an empty file).
        found: String,
    },
    /// The header names a frame that does not exist.
    #[error("{path}:1: unknown frame `{name}` (known frames: {KNOWN_FRAMES})")]
    UnknownFrame {
        /// The file.
        path: PathBuf,
        /// The frame name found.
        name: String,
    },
    /// The header's face count is not the mesh's.
    #[error("{path}:1: the field is for {found} faces but the mesh has {expected} faces")]
    FaceCount {
        /// The file.
        path: PathBuf,
        /// The mesh's face count.
        expected: usize,
        /// The count in the header.
        found: usize,
    },
    /// The number of value lines differs from the header's face count.
    #[error("{path}: the header declares {declared} faces but the file has {found} values")]
    ValueCount {
        /// The file.
        path: PathBuf,
        /// The count in the header.
        declared: usize,
        /// The number of value lines.
        found: usize,
    },
    /// A value line is not two numbers.
    #[error("{path}:{line}: expected two numbers `re im`, found `{text}`")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The line as found.
        text: String,
    },
    /// A value line holds NaN or an infinity.
    #[error("{path}:{line}: the value of face {face} is not finite")]
    NonFiniteValue {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The face the line is for.
        face: FaceId,
    },
    /// A value line has `|mu| >= 1`.
    #[error(
        "{path}:{line}: face {face} has |mu| = {modulus} >= 1 (a quasiconformal map needs |mu| < 1)"
    )]
    FileNotQuasiconformal {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The face the line is for.
        face: FaceId,
        /// `|mu|` found.
        modulus: f64,
    },
    /// A field in memory has the wrong number of values.
    #[error("the field has {found} values but the mesh has {expected} faces")]
    Length {
        /// The mesh's face count.
        expected: usize,
        /// The number of values.
        found: usize,
    },
    /// A field in memory holds NaN or an infinity.
    #[error("the value of face {face} is not finite")]
    NonFinite {
        /// The first such face.
        face: FaceId,
    },
    /// A field in memory has `|mu| >= 1`.
    #[error("face {face} has |mu| = {modulus} >= 1 (a quasiconformal map needs |mu| < 1)")]
    NotQuasiconformal {
        /// The first such face.
        face: FaceId,
        /// `|mu|` found.
        modulus: f64,
    },
    /// A frame conversion met a face whose face frame is a reflection of the global
    /// frame (a face listed clockwise in the plane z = 0), not a rotation of it.
    #[error(
        "face {face} is clockwise in the plane z = 0: its face frame is a reflection of the \
         global frame, so the field cannot be converted by a rotation"
    )]
    ReflectedFrame {
        /// The first such face.
        face: FaceId,
    },
    /// The mesh does not suit the conversion (not planar, wrong field length).
    #[error(transparent)]
    Fem(#[from] FemError),
    /// Writing the file failed; the destination is left untouched.
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// One Beltrami coefficient per face, in the frame [`BeltramiField::frame`]. See the
/// module docs for the meaning, the conventions and the file format.
#[derive(Debug, Clone, PartialEq)]
pub struct BeltramiField {
    /// The frame the values are expressed in.
    pub frame: Frame,
    /// `mu_f` for every face, by [`FaceId`].
    pub mu: Vec<Complex64>,
}

impl BeltramiField {
    /// A field from its frame and values.
    pub fn new(frame: Frame, mu: Vec<Complex64>) -> Self {
        Self { frame, mu }
    }

    /// The conformal field `mu = 0` on `faces` faces.
    pub fn zero(frame: Frame, faces: usize) -> Self {
        Self::new(frame, vec![Complex64::default(); faces])
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.mu.len()
    }

    /// True for a field on no faces.
    pub fn is_empty(&self) -> bool {
        self.mu.is_empty()
    }

    /// Checks that the field prescribes a quasiconformal map on a mesh of `face_count`
    /// faces: one value per face, every value finite and `|mu_f| < 1`. Errors name the
    /// first bad face.
    pub fn check(&self, face_count: usize) -> Result<(), FieldError> {
        if self.mu.len() != face_count {
            return Err(FieldError::Length {
                expected: face_count,
                found: self.mu.len(),
            });
        }
        for (f, mu) in self.mu.iter().enumerate() {
            let face = FaceId(f as u32);
            if !(mu.re.is_finite() && mu.im.is_finite()) {
                return Err(FieldError::NonFinite { face });
            }
            let modulus = mu.norm();
            if modulus >= 1.0 {
                return Err(FieldError::NotQuasiconformal { face, modulus });
            }
        }
        Ok(())
    }

    /// Reads a field file (see the module docs) for a mesh of `face_count` faces.
    pub fn read(path: &Path, face_count: usize) -> Result<Self, FieldError> {
        let text = beltrami_mesh::io::source::read_text(path).map_err(|error| FieldError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Self::parse(path, &text, face_count)
    }

    /// Parses the text of a field file held in memory; `path` only names the file in
    /// errors. Checks everything [`BeltramiField::read`] does.
    pub fn parse(path: &Path, text: &str, face_count: usize) -> Result<Self, FieldError> {
        let mut lines = text.lines().enumerate();
        let header = lines.next().map_or("", |(_, l)| l);
        let (frame, declared) = parse_header(path, header)?;
        if declared != face_count {
            return Err(FieldError::FaceCount {
                path: path.to_path_buf(),
                expected: face_count,
                found: declared,
            });
        }
        let mut mu = Vec::with_capacity(declared);
        for (i, raw) in lines {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let parse_error = || FieldError::Parse {
                path: path.to_path_buf(),
                line: i + 1,
                text: raw.to_string(),
            };
            let mut tokens = line.split_whitespace();
            let (Some(re), Some(im), None) = (tokens.next(), tokens.next(), tokens.next()) else {
                return Err(parse_error());
            };
            let (Ok(re), Ok(im)) = (re.parse::<f64>(), im.parse::<f64>()) else {
                return Err(parse_error());
            };
            let face = FaceId(mu.len() as u32);
            if !(re.is_finite() && im.is_finite()) {
                return Err(FieldError::NonFiniteValue {
                    path: path.to_path_buf(),
                    line: i + 1,
                    face,
                });
            }
            let value = Complex64::new(re, im);
            let modulus = value.norm();
            if modulus >= 1.0 {
                return Err(FieldError::FileNotQuasiconformal {
                    path: path.to_path_buf(),
                    line: i + 1,
                    face,
                    modulus,
                });
            }
            mu.push(value);
        }
        if mu.len() != declared {
            return Err(FieldError::ValueCount {
                path: path.to_path_buf(),
                declared,
                found: mu.len(),
            });
        }
        Ok(Self { frame, mu })
    }

    /// Writes the field file (see the module docs) atomically: `path` gets the complete
    /// file or is left as it was.
    ///
    /// Values with `|mu| >= 1` (the flipped faces of a measured map) are written as they
    /// are, so that a measurement is recorded faithfully; [`BeltramiField::read`] rejects
    /// them, since a prescribed field must be quasiconformal. Fails with
    /// [`FieldError::NonFinite`] before creating anything if a value is NaN or infinite.
    pub fn write(&self, path: &Path) -> Result<(), FieldError> {
        if let Some(f) = self
            .mu
            .iter()
            .position(|m| !(m.re.is_finite() && m.im.is_finite()))
        {
            return Err(FieldError::NonFinite {
                face: FaceId(f as u32),
            });
        }
        beltrami_mesh::io::write_atomically(path, |w| {
            writeln!(
                w,
                "# mu frame={} faces={}",
                self.frame.name(),
                self.mu.len()
            )?;
            let mut line = String::new();
            for m in &self.mu {
                line.clear();
                // Writing into a String cannot fail.
                let _ = write!(line, "{} {}", m.re, m.im);
                writeln!(w, "{line}")?;
            }
            Ok(())
        })?;
        Ok(())
    }

    /// The same field expressed in `frame`, on a mesh in the plane z = 0 (any mesh when
    /// `frame` is the field's own frame).
    ///
    /// With `theta_f` the angle from +x to face `f`'s first edge `p1 - p0`, the face frame
    /// of a counter-clockwise face is the global frame rotated by `theta_f`, so
    /// (Gruber-Aulisa 2022, Lemma 3.4; [`rotate_frame`])
    ///
    /// ```text
    /// mu_face = mu_global e^{-2 i theta_f},   mu_global = mu_face e^{2 i theta_f}.
    /// ```
    ///
    /// Fails with [`FemError::Length`] when the field does not have one value per face,
    /// [`FemError::NotPlanar`] when converting to or from [`Frame::Global`] on a mesh off
    /// the plane z = 0, and [`FieldError::ReflectedFrame`] for a face listed clockwise in
    /// the plane (normal -z), whose face frame is a reflection of the global one.
    pub fn to_frame(&self, mesh: &Mesh, frame: Frame) -> Result<Self, FieldError> {
        if self.mu.len() != mesh.face_count() {
            return Err(FemError::Length {
                what: "Beltrami field",
                expected: mesh.face_count(),
                got: self.mu.len(),
            }
            .into());
        }
        if self.frame == frame {
            return Ok(self.clone());
        }
        // Global -> face rotates by -2 theta, face -> global by +2 theta.
        let sign = match frame {
            Frame::Face => 1.0,
            Frame::Global => -1.0,
        };
        check_planar(mesh)?;
        let mu = mesh
            .faces()
            .zip(&self.mu)
            .map(|(f, &mu)| {
                if mesh.face_vector_area(f).z <= 0.0 {
                    return Err(FieldError::ReflectedFrame { face: f });
                }
                let e1 = mesh.halfedge_vector(mesh.face_halfedge(f));
                Ok(rotate_frame(mu, sign * e1.y.atan2(e1.x)))
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { frame, mu })
    }
}

/// Parses the header line into the frame and the declared face count.
fn parse_header(path: &Path, line: &str) -> Result<(Frame, usize), FieldError> {
    let invalid = || FieldError::Header {
        path: path.to_path_buf(),
        found: line.to_string(),
    };
    let mut tokens = line.split_whitespace();
    if (tokens.next(), tokens.next()) != (Some("#"), Some("mu")) {
        return Err(invalid());
    }
    let (mut frame, mut faces) = (None, None);
    for token in tokens {
        match token.split_once('=') {
            Some(("frame", name)) if frame.is_none() => {
                frame = Some(match name {
                    "global" => Frame::Global,
                    "face" => Frame::Face,
                    _ => {
                        return Err(FieldError::UnknownFrame {
                            path: path.to_path_buf(),
                            name: name.to_string(),
                        });
                    }
                });
            }
            Some(("faces", n)) if faces.is_none() => {
                faces = Some(n.parse::<usize>().map_err(|_| invalid())?);
            }
            _ => return Err(invalid()),
        }
    }
    match (frame, faces) {
        (Some(frame), Some(faces)) => Ok((frame, faces)),
        _ => Err(invalid()),
    }
}
