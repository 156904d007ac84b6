//! `param --components`: a mesh in pieces refused with a hint, each component mapped on
//! its own and placed side by side, or the largest alone.

use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::{BuildOptions, Mesh, PolygonSoup, Vector3};

mod common;
use common::{beltrami, s, text};

const HEMISPHERE: &str = "meshes/disk_hemisphere.obj";

/// The hemisphere and, 3 units along x, a copy scaled by `scale`: two disks in one file.
fn two_disks(dir: &Path, scale: f64) -> PathBuf {
    let raw = io::read_raw(Path::new(HEMISPHERE)).unwrap();
    let soup = &raw.soup;
    let n = soup.vertex_count() as u32;
    let mut positions = soup.positions.clone();
    positions.extend(
        soup.positions
            .iter()
            .map(|p| (p * scale) + Vector3::new(3.0, 0.0, 0.0)),
    );
    let mut both = PolygonSoup::new(positions);
    for face in soup.faces() {
        both.push_face(face);
    }
    for face in soup.faces() {
        let shifted: Vec<u32> = face.iter().map(|i| i + n).collect();
        both.push_face(&shifted);
    }
    let mesh = Mesh::build(&both, &BuildOptions::default()).unwrap().0;
    let path = dir.join(format!("two_{scale}.obj"));
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    path
}

fn uvs(path: &Path) -> Vec<[f64; 2]> {
    let loaded = io::read(path, &BuildOptions::default()).unwrap();
    loaded
        .vertex_uvs()
        .unwrap()
        .iter()
        .map(|t| [t.x, t.y])
        .collect()
}

fn report(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn a_mesh_in_pieces_is_refused_with_the_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let two = two_disks(dir.path(), 1.0);
    let out = beltrami(&[
        "param",
        s(&two),
        "--solver",
        "lscm",
        "-o",
        s(&dir.path().join("o.obj")),
    ]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("2 components"), "{stderr}");
    assert!(stderr.contains("hint: `--components each`"), "{stderr}");
}

#[test]
fn each_component_is_mapped_as_alone_and_placed_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let two = two_disks(dir.path(), 0.5);
    let (solo, joined) = (dir.path().join("solo.obj"), dir.path().join("joined.obj"));
    let joined_report = dir.path().join("joined.json");
    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "lscm",
        "-o",
        s(&solo),
        "-q",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = beltrami(&[
        "param",
        s(&two),
        "--solver",
        "lscm",
        "--components",
        "each",
        "-o",
        s(&joined),
        "--report",
        s(&joined_report),
        "-q",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (solo, joined) = (uvs(&solo), uvs(&joined));
    let n = solo.len();
    assert_eq!(joined.len(), 2 * n);
    // The first disk's map is the map of the hemisphere alone, moved: the same up to one
    // translation. (LSCM pins two far boundary vertices at 0 and 1 in each component.)
    let shift = [joined[0][0] - solo[0][0], joined[0][1] - solo[0][1]];
    for (a, b) in solo.iter().zip(&joined[..n]) {
        assert!((b[0] - a[0] - shift[0]).abs() < 1e-9 && (b[1] - a[1] - shift[1]).abs() < 1e-9);
    }
    // The second sits to the right of the first, with a gap, bottoms aligned.
    let max_x = |uv: &[[f64; 2]]| uv.iter().map(|t| t[0]).fold(f64::MIN, f64::max);
    let min = |uv: &[[f64; 2]], c: usize| uv.iter().map(|t| t[c]).fold(f64::MAX, f64::min);
    assert!(min(&joined[n..], 0) > max_x(&joined[..n]));
    assert!((min(&joined[n..], 1) - min(&joined[..n], 1)).abs() < 1e-12);
    // The report is the distortion of the joined map, as `distortion` measures it.
    let reported = report(&joined_report);
    let out = beltrami(&[
        "distortion",
        s(&two),
        s(&dir.path().join("joined.obj")),
        "--json",
    ]);
    let measured: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["mu_max", "mu_mean", "flipped"] {
        let (a, b) = (
            reported[key].as_f64().unwrap(),
            measured[key].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-12, "{key}: report {a}, distortion {b}");
    }
    assert_eq!(reported["flipped"], 0);
}

#[test]
fn largest_maps_the_largest_component_alone() {
    let dir = tempfile::tempdir().unwrap();
    let two = two_disks(dir.path(), 1.0);
    let out_path = dir.path().join("largest.obj");
    let out = beltrami(&[
        "param",
        s(&two),
        "--solver",
        "tutte",
        "--components",
        "largest",
        "-o",
        s(&out_path),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let loaded = io::read(&out_path, &BuildOptions::default()).unwrap();
    assert_eq!(loaded.mesh.vertex_count(), 1861);
    assert_eq!(loaded.mesh.component_count(), 1);
    assert!(text(&out.stdout).contains("the largest of 2 components mapped (3600 of 7200 faces)"));
}

#[test]
fn each_refuses_maps_that_cannot_be_placed_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let two = dir.path().join("two_spheres.obj");
    // Two octahedra: closed genus-0 components.
    std::fs::write(
        &two,
        "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
         v 4 0 0\nv 2 0 0\nv 3 1 0\nv 3 -1 0\nv 3 0 1\nv 3 0 -1\n\
         f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n\
         f 7 9 11\nf 9 8 11\nf 8 10 11\nf 10 7 11\nf 9 7 12\nf 8 9 12\nf 10 8 12\nf 7 10 12\n",
    )
    .unwrap();
    let out = beltrami(&[
        "param",
        s(&two),
        "--solver",
        "sphere",
        "--components",
        "each",
        "-o",
        s(&dir.path().join("o.obj")),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("joins maps into the plane side by side"),
        "{}",
        text(&out.stderr)
    );
}
