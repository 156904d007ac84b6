//! Beltrami field files (round trip, every error with its line and face) and frame
//! conversion (round trip, against mu measured directly in the face frame).

use std::path::{Path, PathBuf};

use beltrami_fem::beltrami::{face_mu, planar_map, point_mu};
use beltrami_fem::{BeltramiField, Elements, FemError, FieldError, Frame};
use beltrami_mesh::primitives::{Cells, grid, icosphere};
use beltrami_mesh::{FaceId, Mesh, PolygonSoup};
use num_complex::Complex64;

mod common;
use common::{Rng, jittered};

/// A fresh path under the integration tests' scratch folder.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("beltrami-fem-field");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

fn parse(text: &str, faces: usize) -> Result<BeltramiField, FieldError> {
    BeltramiField::parse(Path::new("mu.txt"), text, faces)
}

#[test]
fn a_written_field_reads_back_bit_for_bit() {
    let mut rng = Rng(17);
    let mut mu: Vec<Complex64> = (0..200).map(|_| rng.mu()).collect();
    // Values whose shortest decimal forms are awkward.
    mu[0] = Complex64::new(-0.0, 0.0);
    mu[1] = Complex64::new(0.1 + 0.2, -1e-300);
    mu[2] = Complex64::new(f64::MIN_POSITIVE / 4.0, 1.0 - f64::EPSILON);
    mu[3] = Complex64::new(1.0 / 3.0, -2.0 / 3.0);
    for frame in [Frame::Global, Frame::Face] {
        let field = BeltramiField::new(frame, mu.clone());
        let path = scratch(&format!("round-trip-{}.txt", frame.name()));
        field.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text.lines().next(),
            Some(format!("# mu frame={} faces=200", frame.name()).as_str())
        );
        assert_eq!(text.lines().count(), 201);
        let back = BeltramiField::read(&path, 200).unwrap();
        assert_eq!(back.frame, frame);
        assert_eq!(back.len(), 200);
        for (a, b) in field.mu.iter().zip(&back.mu) {
            assert_eq!(a.re.to_bits(), b.re.to_bits());
            assert_eq!(a.im.to_bits(), b.im.to_bits());
        }
    }
}

#[test]
fn comments_blank_lines_and_spacing_are_accepted() {
    let text =
        "# mu faces=3   frame=face\r\n\n# a comment\n 0.5\t-0.25 \n\n1e-3 0\n  # another\n-0 0.5\n";
    let field = parse(text, 3).unwrap();
    assert_eq!(field.frame, Frame::Face);
    assert_eq!(
        field.mu,
        vec![
            Complex64::new(0.5, -0.25),
            Complex64::new(1e-3, 0.0),
            Complex64::new(0.0, 0.5)
        ]
    );
    assert_eq!(
        BeltramiField::zero(Frame::Global, 4).mu,
        vec![Complex64::default(); 4]
    );
}

#[test]
fn an_unreadable_file_names_its_path() {
    let e = BeltramiField::read(Path::new("no/such/mu.txt"), 3).unwrap_err();
    assert!(matches!(&e, FieldError::Io { path, .. } if path == Path::new("no/such/mu.txt")));
    assert!(
        e.to_string().starts_with("cannot read no/such/mu.txt"),
        "{e}"
    );
}

#[test]
fn a_missing_or_invalid_header_is_reported_on_line_1() {
    for text in [
        "",
        "0.1 0.2\n",
        "# mu frame=global\n0 0\n",
        "# mu faces=1\n0 0\n",
        "# beltrami frame=global faces=1\n0 0\n",
        "# mu frame=global faces=one\n0 0\n",
        "# mu frame=global faces=1 faces=1\n0 0\n",
        "# mu frame=global faces=1 colour=red\n0 0\n",
    ] {
        let e = parse(text, 1).unwrap_err();
        let first = text.lines().next().unwrap_or("");
        assert!(
            matches!(&e, FieldError::Header { found, .. } if found == first),
            "{text:?}: {e:?}"
        );
        assert!(
            e.to_string().starts_with("mu.txt:1: expected the header"),
            "{e}"
        );
    }
}

#[test]
fn an_unknown_frame_lists_the_known_ones() {
    let e = parse("# mu frame=polar faces=1\n0 0\n", 1).unwrap_err();
    assert!(matches!(&e, FieldError::UnknownFrame { name, .. } if name == "polar"));
    let message = e.to_string();
    assert!(
        message.contains("unknown frame `polar`") && message.contains("global, face"),
        "{message}"
    );
}

#[test]
fn face_counts_are_checked_against_the_mesh_and_the_values() {
    let e = parse("# mu frame=global faces=3\n0 0\n0 0\n0 0\n", 2).unwrap_err();
    assert!(
        matches!(
            e,
            FieldError::FaceCount {
                expected: 2,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("3 faces but the mesh has 2"), "{e}");

    let e = parse("# mu frame=global faces=3\n0 0\n0 0\n", 3).unwrap_err();
    assert!(
        matches!(
            e,
            FieldError::ValueCount {
                declared: 3,
                found: 2,
                ..
            }
        ),
        "{e:?}"
    );
    let e = parse("# mu frame=global faces=1\n0 0\n# more\n0 0\n", 1).unwrap_err();
    assert!(
        matches!(
            e,
            FieldError::ValueCount {
                declared: 1,
                found: 2,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn an_unparsable_line_is_named_with_its_text() {
    for (bad, line) in [("0.1", 4), ("0.1 abc", 4), ("0.1 0.2 0.3", 4), ("0,1 0", 4)] {
        let text = format!("# mu frame=face faces=3\n0 0\n\n{bad}\n0 0\n");
        let e = parse(&text, 3).unwrap_err();
        assert!(
            matches!(&e, FieldError::Parse { line: l, text, .. } if *l == line && text == bad),
            "{e:?}"
        );
        assert!(e.to_string().starts_with(&format!("mu.txt:{line}:")), "{e}");
    }
}

#[test]
fn non_finite_values_name_their_line_and_face() {
    for bad in ["NaN 0", "0 inf", "-infinity 0"] {
        let text = format!("# mu frame=face faces=3\n# c\n0 0\n0.1 0.1\n{bad}\n");
        let e = parse(&text, 3).unwrap_err();
        assert!(
            matches!(
                e,
                FieldError::NonFiniteValue {
                    line: 5,
                    face: FaceId(2),
                    ..
                }
            ),
            "{e:?}"
        );
    }
}

#[test]
fn mu_of_modulus_one_or_more_names_its_face_and_line() {
    for bad in ["1 0", "0 -1", "0.8 0.7"] {
        let text = format!("# mu frame=global faces=3\n0 0\n\n# c\n{bad}\n0 0\n");
        let e = parse(&text, 3).unwrap_err();
        assert!(
            matches!(e, FieldError::FileNotQuasiconformal { line: 5, face: FaceId(1), modulus, .. } if modulus >= 1.0),
            "{e:?}"
        );
        assert!(e.to_string().contains("face f1 has |mu|"), "{e}");
    }
    // Just below 1 is fine.
    parse("# mu frame=global faces=1\n0.9999999999 0\n", 1).unwrap();
}

#[test]
fn check_names_the_first_bad_face() {
    let mut field = BeltramiField::new(Frame::Face, vec![Complex64::new(0.5, 0.0); 5]);
    field.check(5).unwrap();
    assert!(matches!(
        field.check(4),
        Err(FieldError::Length {
            expected: 4,
            found: 5
        })
    ));
    field.mu[3] = Complex64::new(0.0, 1.0);
    field.mu[4] = Complex64::new(2.0, 0.0);
    assert!(matches!(
        field.check(5),
        Err(FieldError::NotQuasiconformal { face: FaceId(3), modulus }) if modulus == 1.0
    ));
    field.mu[2] = Complex64::new(f64::NAN, 0.0);
    assert!(matches!(
        field.check(5),
        Err(FieldError::NonFinite { face: FaceId(2) })
    ));
}

#[test]
fn a_measured_field_with_flips_is_written_but_not_read_as_a_prescription() {
    let field = BeltramiField::new(
        Frame::Global,
        vec![Complex64::new(0.2, 0.0), Complex64::new(1.5, 0.0)],
    );
    let path = scratch("flipped.txt");
    field.write(&path).unwrap();
    let e = BeltramiField::read(&path, 2).unwrap_err();
    assert!(
        matches!(
            e,
            FieldError::FileNotQuasiconformal {
                line: 3,
                face: FaceId(1),
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn writing_a_non_finite_value_fails_and_creates_nothing() {
    let field = BeltramiField::new(
        Frame::Face,
        vec![Complex64::new(0.0, 0.0), Complex64::new(0.0, f64::INFINITY)],
    );
    let path = scratch("non-finite.txt");
    let e = field.write(&path).unwrap_err();
    assert!(
        matches!(e, FieldError::NonFinite { face: FaceId(1) }),
        "{e:?}"
    );
    assert!(!path.exists());
}

#[test]
fn global_to_face_and_back_is_the_identity() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(9, cells, 0.3, 5);
        let mut rng = Rng(23);
        let global = BeltramiField::new(
            Frame::Global,
            (0..mesh.face_count()).map(|_| rng.mu()).collect(),
        );
        let face = global.to_frame(&mesh, Frame::Face).unwrap();
        assert_eq!(face.frame, Frame::Face);
        let back = face.to_frame(&mesh, Frame::Global).unwrap();
        assert_eq!(back.frame, Frame::Global);
        for (a, b) in global.mu.iter().zip(&back.mu) {
            assert!((a - b).norm() < 1e-15, "{a} vs {b}");
        }
        // |mu| is frame independent; the argument is not (the faces' first edges turn).
        for (a, b) in global.mu.iter().zip(&face.mu) {
            assert!((a.norm() - b.norm()).abs() < 1e-15);
        }
        assert!(
            global
                .mu
                .iter()
                .zip(&face.mu)
                .any(|(a, b)| (a - b).norm() > 1e-3)
        );
        assert_eq!(global.to_frame(&mesh, Frame::Global).unwrap(), global);
    }
}

#[test]
fn face_frame_conversion_matches_mu_measured_in_the_face_frame() {
    // f(z) = a z + b conj(z) has mu = b / a in the global frame on every face.
    let (a, b) = (Complex64::new(1.2, 0.4), Complex64::new(-0.3, 0.45));
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(10, cells, 0.35, 29);
        let map: Vec<Complex64> = mesh
            .positions()
            .iter()
            .map(|p| {
                let z = Complex64::new(p.x, p.y);
                a * z + b * z.conj()
            })
            .collect();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let d = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
        let measured = face_mu(&elements, &point_mu(&d));
        let global = BeltramiField::new(Frame::Global, vec![b / a; mesh.face_count()]);
        let converted = global.to_frame(&mesh, Frame::Face).unwrap();
        for (f, (m, c)) in measured.iter().zip(&converted.mu).enumerate() {
            assert!((m - c).norm() < 1e-12, "{cells:?} face {f}: {m} vs {c}");
        }
        // And back: the face-frame measurement converts to the global constant.
        let back = BeltramiField::new(Frame::Face, measured)
            .to_frame(&mesh, Frame::Global)
            .unwrap();
        assert!(back.mu.iter().all(|m| (m - b / a).norm() < 1e-12));
    }
}

#[test]
fn conversion_needs_a_planar_counter_clockwise_mesh_and_one_value_per_face() {
    let sphere = Mesh::from_soup(&icosphere(1)).unwrap();
    let field = BeltramiField::zero(Frame::Face, sphere.face_count());
    assert!(matches!(
        field.to_frame(&sphere, Frame::Global),
        Err(FieldError::Fem(FemError::NotPlanar { .. }))
    ));
    // Same frame: nothing to convert, any mesh.
    assert_eq!(field.to_frame(&sphere, Frame::Face).unwrap(), field);

    let plane = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
    assert!(matches!(
        field.to_frame(&plane, Frame::Global),
        Err(FieldError::Fem(FemError::Length {
            expected: 18,
            got: 80,
            ..
        }))
    ));

    // The same grid listed clockwise: normals -z, face frames are reflections.
    let soup = grid(3, 3, Cells::Triangles);
    let faces: Vec<Vec<u32>> = soup
        .faces()
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    let mut reversed = PolygonSoup::new(soup.positions.clone());
    for f in &faces {
        reversed.push_face(f);
    }
    let clockwise = Mesh::from_soup(&reversed).unwrap();
    let e = BeltramiField::zero(Frame::Global, 18)
        .to_frame(&clockwise, Frame::Face)
        .unwrap_err();
    assert!(
        matches!(e, FieldError::ReflectedFrame { face: FaceId(0) }),
        "{e:?}"
    );
}
