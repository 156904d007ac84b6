//! End-to-end runs of `beltrami distortion`: affine and conformal maps with known mu,
//! similarities of surfaces, flips judged against the reference normal chosen from the
//! image (plane, sphere, source) or against a target, and bad input.

use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{BuildOptions, Mesh, Point3, Vector2, Vector3};
use num_complex::Complex64;
use serde_json::Value;

mod common;
use common::{beltrami, s, text};

/// Runs `distortion ... --json` and returns the report.
fn report(args: &[&str]) -> Value {
    let mut all = vec!["distortion", "--json"];
    all.extend_from_slice(args);
    let out = beltrami(&all);
    assert!(out.status.success(), "{}", text(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number `{key}` in {v}"))
}

/// Writes `mesh` with the given positions (or its own) and texture coordinates.
fn write_mesh(
    path: &Path,
    mesh: &Mesh,
    positions: Option<&[Point3<f64>]>,
    uvs: Option<&[Vector2<f64>]>,
) {
    let attributes = VertexAttributes {
        positions,
        uvs,
        ..VertexAttributes::default()
    };
    io::obj::write(path, mesh, &attributes).unwrap();
}

/// The map `f(z) = a z + b conj(z) + c` of the plane: `mu = b / a` everywhere.
fn affine(p: &Point3<f64>, a: Complex64, b: Complex64) -> Vector2<f64> {
    let z = Complex64::new(p.x, p.y);
    let w = a * z + b * z.conj() + Complex64::new(0.5, -2.0);
    Vector2::new(w.re, w.im)
}

#[test]
fn an_affine_planar_map_has_mu_k_on_every_face() {
    let dir = tempfile::tempdir().unwrap();
    let (a, k) = (Complex64::new(1.5, 0.5), Complex64::new(0.25, -0.2));
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = Mesh::from_soup(&grid(12, 9, cells)).unwrap();
        let n = mesh.face_count();
        let uv: Vec<Vector2<f64>> = mesh
            .positions()
            .iter()
            .map(|p| affine(p, a, a * k))
            .collect();
        let (source, mapped, per_face) = (
            dir.path().join("source.obj"),
            dir.path().join("mapped.obj"),
            dir.path().join("mu.txt"),
        );
        write_mesh(&source, &mesh, None, None);
        write_mesh(&mapped, &mesh, None, Some(&uv));

        let v = report(&[s(&source), s(&mapped), "--per-face", s(&per_face)]);
        assert_eq!(v["faces"], n);
        assert_eq!(v["flipped"], 0);
        assert_eq!(v["frame"], "global");
        assert_eq!(v["map"], "vt");
        for key in ["mu_mean", "mu_max", "mu_l2"] {
            assert!((number(&v, key) - k.norm()).abs() < 1e-12, "{key} in {v}");
        }
        assert!(number(&v, "mu_std") < 1e-12, "{v}");
        // |k| = 0.32: every face in the bin [0.3, 0.4).
        let counts: Vec<u64> = v["histogram"]["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .collect();
        assert_eq!(counts, [0, 0, 0, n as u64, 0, 0, 0, 0, 0, 0]);
        assert_eq!(v["histogram"]["at_least_one"], 0);

        let file = std::fs::read_to_string(&per_face).unwrap();
        let mut lines = file.lines();
        assert_eq!(
            lines.next(),
            Some(format!("# mu frame=global faces={n}").as_str())
        );
        let values: Vec<&str> = lines.collect();
        assert_eq!(values.len(), n);
        for line in values {
            let mut parts = line.split(' ').map(|t| t.parse::<f64>().unwrap());
            let mu = Complex64::new(parts.next().unwrap(), parts.next().unwrap());
            assert!((mu - k).norm() < 1e-12, "{line}");
        }
    }
}

#[test]
fn the_text_report_has_the_statistics_and_the_histogram() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).unwrap();
    let uv: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| affine(p, Complex64::new(1.0, 0.0), Complex64::new(0.55, 0.0)))
        .collect();
    let (source, mapped) = (dir.path().join("s.obj"), dir.path().join("m.obj"));
    write_mesh(&source, &mesh, None, None);
    write_mesh(&mapped, &mesh, None, Some(&uv));
    let out = beltrami(&["distortion", s(&source), s(&mapped)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    for line in [
        "mu in the global frame",
        "faces           32",
        "flipped         0",
        "|mu| mean       5.500000e-1",
        "|mu| max        5.500000e-1",
        "|mu| L2 (area)  5.500000e-1",
        "[0.5, 0.6)    32",
        ">= 1          0",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in\n{stdout}");
    }
}

/// Scale 1.7, rotation by 35 degrees about z then 20 degrees about x, translation.
fn similarity(p: &Point3<f64>) -> Point3<f64> {
    let (sa, ca) = 35f64.to_radians().sin_cos();
    let (sb, cb) = 20f64.to_radians().sin_cos();
    let (x, y) = (ca * p.x - sa * p.y, sa * p.x + ca * p.y);
    let (y, z) = (cb * y - sb * p.z, sb * y + cb * p.z);
    Point3::from(1.7 * Vector3::new(x, y, z) + Vector3::new(0.3, 4.0, -1.0))
}

#[test]
fn a_similarity_of_a_surface_is_conformal() {
    let dir = tempfile::tempdir().unwrap();
    let hemisphere = io::read(
        Path::new("meshes/disk_hemisphere.obj"),
        &BuildOptions::default(),
    )
    .unwrap()
    .mesh;
    let torus = Mesh::from_soup(&torus(20, 12, 2.0, 0.7, Cells::Quads)).unwrap();
    for (name, mesh, source) in [
        (
            "hemisphere",
            &hemisphere,
            PathBuf::from("meshes/disk_hemisphere.obj"),
        ),
        ("torus", &torus, dir.path().join("torus.obj")),
    ] {
        if name == "torus" {
            write_mesh(&source, mesh, None, None);
        }
        let image: Vec<Point3<f64>> = mesh.positions().iter().map(similarity).collect();
        let mapped = dir.path().join(format!("{name}-similar.obj"));
        let per_face = dir.path().join(format!("{name}-mu.txt"));
        write_mesh(&mapped, mesh, Some(&image), None);
        let v = report(&[s(&source), s(&mapped), "--per-face", s(&per_face)]);
        assert_eq!(v["faces"], mesh.face_count());
        assert_eq!(v["flipped"], 0, "{name}");
        assert_eq!(v["map"], "positions");
        assert_eq!(v["frame"], "face");
        assert!(number(&v, "mu_max") < 1e-9, "{name}: {v}");
        let file = std::fs::read_to_string(&per_face).unwrap();
        assert!(file.starts_with(&format!("# mu frame=face faces={}\n", mesh.face_count())));
    }
}

#[test]
fn the_stereographic_projection_of_the_hemisphere_is_nearly_conformal() {
    // The bundled mesh is the cap z >= 0.098 of the unit sphere. Projection from the
    // south pole, w = (x + i y) / (1 + z), is conformal: mu is only the discretization
    // error (measured: mean 0.0095, max 0.018). The orthographic projection (x, y) has
    // |mu| = tan^2(phi / 2) at polar angle phi: measured mean 0.33.
    let dir = tempfile::tempdir().unwrap();
    let source = Path::new("meshes/disk_hemisphere.obj");
    let mesh = io::read(source, &BuildOptions::default()).unwrap().mesh;
    let stereographic: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(p.x, p.y) / (1.0 + p.z))
        .collect();
    let orthographic: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(p.x, p.y))
        .collect();
    let (a, b) = (dir.path().join("stereo.obj"), dir.path().join("ortho.obj"));
    write_mesh(&a, &mesh, None, Some(&stereographic));
    write_mesh(&b, &mesh, None, Some(&orthographic));

    let conformal = report(&[s(source), s(&a)]);
    assert_eq!(conformal["faces"], 3600);
    assert_eq!(conformal["flipped"], 0);
    assert_eq!(conformal["frame"], "face");
    let mean = number(&conformal, "mu_mean");
    assert!(mean < 0.02, "{conformal}");
    assert!(number(&conformal, "mu_max") < 0.03, "{conformal}");

    let squashed = report(&[s(source), s(&b)]);
    assert_eq!(squashed["flipped"], 0);
    let ortho_mean = number(&squashed, "mu_mean");
    assert!(ortho_mean > 0.25, "{squashed}");
    assert!(ortho_mean > 20.0 * mean, "{ortho_mean} vs {mean}");
    // The boundary circle z = 0.098: tan^2(phi / 2) = (1 - z) / (1 + z) = 0.82.
    let max = number(&squashed, "mu_max");
    assert!(max > 0.7 && max < 0.83, "{squashed}");
}

#[test]
fn a_face_collapsed_by_the_map_is_measured_not_refused() {
    // A planar source lifted onto the saddle z = x y, with one triangle's third vertex
    // sent to the midpoint of its first two: that image face has no area.
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).unwrap();
    let mut image: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.x * p.y))
        .collect();
    let f = beltrami_mesh::FaceId(18);
    let v: Vec<_> = mesh.face_vertices(f).collect();
    image[v[2].idx()] = midpoint(image[v[0].idx()], image[v[1].idx()]);
    let (source, mapped, per_face) = (
        dir.path().join("plane.obj"),
        dir.path().join("collapsed.obj"),
        dir.path().join("mu.txt"),
    );
    write_mesh(&source, &mesh, None, None);
    write_mesh(&mapped, &mesh, Some(&image), None);
    let v = report(&[s(&source), s(&mapped), "--per-face", s(&per_face)]);
    assert_eq!(v["frame"], "global");
    assert_eq!(v["map"], "positions");
    assert!(v["flipped"].as_u64().unwrap() >= 1, "{v}");
    assert!(v["histogram"]["at_least_one"].as_u64().unwrap() >= 1, "{v}");
    let file = std::fs::read_to_string(&per_face).unwrap();
    assert!(file.starts_with("# mu frame=global faces=32\n"));
    // Face 18 is on line 20.
    let line = file.lines().nth(19).unwrap();
    let mut parts = line.split(' ').map(|t| t.parse::<f64>().unwrap());
    let mu = Complex64::new(parts.next().unwrap(), parts.next().unwrap());
    assert!((mu.norm() - 1.0).abs() < 1e-12, "{line}");
}

/// The midpoint of `a` and `b`.
fn midpoint(a: Point3<f64>, b: Point3<f64>) -> Point3<f64> {
    Point3::from((a.coords + b.coords) / 2.0)
}

#[test]
fn flips_are_judged_radially_or_against_the_target() {
    // A half turn about z: conformal, and no fold, though near the equator each image
    // face's normal points against its source face's normal. Without a target the image,
    // on the unit sphere, is judged against the radial direction; with one against the
    // target's normals at the images.
    let dir = tempfile::tempdir().unwrap();
    let sphere = Mesh::from_soup(&icosphere(3)).unwrap();
    let target = Mesh::from_soup(&icosphere(2)).unwrap();
    let image: Vec<Point3<f64>> = sphere
        .positions()
        .iter()
        .map(|p| Point3::new(-p.x, -p.y, p.z))
        .collect();
    let (source, mapped, target_path) = (
        dir.path().join("sphere.obj"),
        dir.path().join("turned.obj"),
        dir.path().join("target.obj"),
    );
    write_mesh(&source, &sphere, None, None);
    write_mesh(&mapped, &sphere, Some(&image), None);
    write_mesh(&target_path, &target, None, None);

    let alone = report(&[s(&source), s(&mapped)]);
    assert_eq!(alone["reference"], "radial");
    assert_eq!(alone["flipped"], 0, "{alone}");
    assert!(number(&alone, "mu_max") < 1e-9, "{alone}");
    let against_target = report(&[s(&source), s(&mapped), "--target", s(&target_path)]);
    assert_eq!(against_target["reference"], "target");
    assert_eq!(against_target["flipped"], 0, "{against_target}");

    // A vertex slid along the surface past its neighbours folds part of its fan:
    // flipped with or without the target.
    let mut folded = image.clone();
    let p = folded[0].coords;
    let tangent = p
        .cross(&beltrami_mesh::Vector3::new(0.3, 0.5, 0.8))
        .normalize();
    folded[0] = Point3::from((p + 0.3 * tangent).normalize());
    let folded_path = dir.path().join("folded.obj");
    write_mesh(&folded_path, &sphere, Some(&folded), None);
    for extra in [vec![], vec!["--target", s(&target_path)]] {
        let mut args = vec![s(&source), s(&folded_path)];
        args.extend(extra);
        let v = report(&args);
        assert!(v["flipped"].as_u64().unwrap() >= 1, "{v}");
    }
}

/// Twice the signed area of the triangle `a b c` of the plane z = 0.
fn signed_area2(a: &Point3<f64>, b: &Point3<f64>, c: &Point3<f64>) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

#[test]
fn a_folded_planar_map_given_as_positions_is_judged_in_the_plane() {
    // 40 x 40 cells of two triangles on the unit square. Past x = 0.75 the map turns
    // back at half speed, x -> 0.75 - (x - 0.75) / 2: the 10 columns of cells beyond the
    // fold line (a grid line) are reversed, 800 of 3200 triangles (|mu| = 3 there), and
    // the rest is the identity. As positions `v x y 0` the image's own normals would turn
    // over with the fold; the plane z = 0 is the reference.
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(40, 40, Cells::Triangles)).unwrap();
    assert_eq!(mesh.face_count(), 3200);
    let fold = |p: &Point3<f64>| {
        let x = if p.x > 0.75 {
            0.75 - 0.5 * (p.x - 0.75)
        } else {
            p.x
        };
        Point3::new(x, p.y, 0.0)
    };
    let image: Vec<Point3<f64>> = mesh.positions().iter().map(fold).collect();
    let uv: Vec<Vector2<f64>> = image.iter().map(|p| Vector2::new(p.x, p.y)).collect();
    let (source, positions, texture) = (
        dir.path().join("square.obj"),
        dir.path().join("folded.obj"),
        dir.path().join("folded-vt.obj"),
    );
    write_mesh(&source, &mesh, None, None);
    write_mesh(&positions, &mesh, Some(&image), None);
    write_mesh(&texture, &mesh, None, Some(&uv));

    // The independent count: signed areas of the image triangles as written.
    let written = io::read(&positions, &BuildOptions::default()).unwrap().mesh;
    assert!(written.positions().iter().all(|p| p.z == 0.0));
    let negative = written
        .faces()
        .filter(|&f| {
            let p: Vec<Point3<f64>> = written
                .face_vertices(f)
                .map(|v| written.position(v))
                .collect();
            signed_area2(&p[0], &p[1], &p[2]) < 0.0
        })
        .count();
    assert_eq!(negative, 800);

    let as_positions = report(&[s(&source), s(&positions)]);
    assert_eq!(as_positions["map"], "positions");
    assert_eq!(as_positions["reference"], "plane");
    assert_eq!(as_positions["flipped"], 800, "{as_positions}");
    assert_eq!(as_positions["histogram"]["at_least_one"], 800);
    assert!((number(&as_positions, "mu_max") - 3.0).abs() < 1e-9);

    // The same map as texture coordinates: the same count and the same |mu|.
    let as_vt = report(&[s(&source), s(&texture)]);
    assert_eq!(as_vt["map"], "vt");
    assert_eq!(as_vt["reference"], "plane");
    assert_eq!(as_vt["flipped"], 800, "{as_vt}");
    for key in ["mu_mean", "mu_max", "mu_l2"] {
        let (a, b) = (number(&as_positions, key), number(&as_vt, key));
        assert!((a - b).abs() <= 1e-12 * b.max(1.0), "{key}: {a} vs {b}");
    }

    // The text report names the reference.
    let out = beltrami(&["distortion", s(&source), s(&positions)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("flipped         800"), "{stdout}");
    assert!(
        stdout.contains("flips judged against +z (the image lies in the plane z = 0)"),
        "{stdout}"
    );
}

#[test]
fn an_image_off_the_plane_and_the_sphere_is_judged_by_the_source_with_a_note() {
    // The square lifted onto the saddle z = x y: neither planar nor spherical.
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(6, 6, Cells::Triangles)).unwrap();
    let image: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.x * p.y))
        .collect();
    let (source, mapped) = (dir.path().join("square.obj"), dir.path().join("saddle.obj"));
    write_mesh(&source, &mesh, None, None);
    write_mesh(&mapped, &mesh, Some(&image), None);
    let v = report(&[s(&source), s(&mapped)]);
    assert_eq!(v["reference"], "source");
    assert_eq!(v["flipped"], 0);
    let note = v["notes"][0].as_str().unwrap_or_default();
    assert!(note.contains("--target"), "{v}");
    let out = beltrami(&["distortion", s(&source), s(&mapped)]);
    assert!(out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("flips are judged against the normals of") && err.contains("--target"),
        "{err}"
    );
    assert!(text(&out.stdout).contains("flips judged against SOURCE's normals"));
    // Judged against the saddle itself, given as the target: the same answer, no note.
    let v = report(&[s(&source), s(&mapped), "--target", s(&mapped)]);
    assert_eq!(v["reference"], "target");
    assert_eq!(v["flipped"], 0);
    assert_eq!(v["notes"], serde_json::json!([]));
}

#[test]
fn mismatched_connectivity_names_the_first_differing_face() {
    let dir = tempfile::tempdir().unwrap();
    let soup = grid(4, 4, Cells::Triangles);
    let mesh = Mesh::from_soup(&soup).unwrap();
    let source = dir.path().join("source.obj");
    write_mesh(&source, &mesh, None, None);

    // The diagonal of cell (1, 2) flipped: faces 2 * 9 and 2 * 9 + 1 change.
    let mut other = beltrami_mesh::PolygonSoup::new(soup.positions.clone());
    for (i, f) in soup.faces().enumerate() {
        match i {
            18 => other.push_face(&[f[0], f[1], soup.face(19)[2]]),
            19 => other.push_face(&[soup.face(18)[1], f[1], f[2]]),
            _ => other.push_face(f),
        }
    }
    let flipped_diagonal = Mesh::from_soup(&other).unwrap();
    let mapped = dir.path().join("mapped.obj");
    write_mesh(&mapped, &flipped_diagonal, None, None);
    let out = beltrami(&["distortion", s(&source), s(&mapped)]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = text(&out.stderr);
    assert!(
        err.contains("does not have the connectivity of") && err.contains("face 18 has vertices"),
        "{err}"
    );

    let smaller = Mesh::from_soup(&grid(4, 3, Cells::Triangles)).unwrap();
    write_mesh(&mapped, &smaller, None, None);
    let out = beltrami(&["distortion", s(&source), s(&mapped)]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("it has 24 faces, the source has 32"));
}

#[test]
fn texture_seams_are_measured_face_by_face_and_a_target_for_a_planar_map_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("square.obj");
    std::fs::write(
        &source,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    // Vertex 2 (0-based) has vt 3 in the first face and vt 5 in the second.
    let seams = dir.path().join("seams.obj");
    std::fs::write(
        &seams,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 2 2\n\
         f 1/1 2/2 3/3\nf 1/1 3/5 4/4\n",
    )
    .unwrap();
    // The first face is mapped by the identity (mu = 0); the second, (0,0) (1,1) (0,1)
    // onto (0,0) (2,2) (0,1), by u = 2x, v = x + y: f_z = (3 + i)/2, f_zbar = (1 + i)/2,
    // |mu| = |(1 + i)/(3 + i)| = sqrt(20)/10.
    let v = report(&[s(&source), s(&seams)]);
    assert_eq!(v["flipped"], 0);
    assert!(
        (number(&v, "mu_max") - 20f64.sqrt() / 10.0).abs() < 1e-12,
        "{v}"
    );
    assert!(
        (number(&v, "mu_mean") - 20f64.sqrt() / 20.0).abs() < 1e-12,
        "{v}"
    );

    let uv = dir.path().join("uv.obj");
    std::fs::write(
        &uv,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let out = beltrami(&["distortion", s(&source), s(&uv), "--target", s(&source)]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("--target applies only to maps into R^3"));
    // Without --target it runs: the identity has mu = 0.
    let v = report(&[s(&source), s(&uv)]);
    assert!(number(&v, "mu_max") < 1e-15, "{v}");
}

#[test]
fn unwritable_output_and_missing_input_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
    let source = dir.path().join("s.obj");
    write_mesh(&source, &mesh, None, None);
    let per_face = dir.path().join("no/such/dir/mu.txt");
    let out = beltrami(&[
        "distortion",
        s(&source),
        s(&source),
        "--per-face",
        s(&per_face),
    ]);
    assert!(!out.status.success());
    // Refused before any work, naming the flag and the missing folder.
    let err = text(&out.stderr);
    assert!(
        err.contains("--per-face") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!per_face.exists());

    let out = beltrami(&["distortion", s(&source), "no/such/mapped.obj"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("cannot read no/such/mapped.obj"));

    let out = beltrami(&["distortion", "--help"]);
    assert!(out.status.success());
    assert!(text(&out.stdout).contains("--per-face"));
}
