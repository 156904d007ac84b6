//! Pictures without golden images: determinism, sizes, the regularity of the
//! checkerboard of an identity map, flip outlines, the camera convention, the depth
//! test, the color bar, typed errors and atomic output.

use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{Mesh, Point3, Vector2};
use beltrami_render::colormap::{CHECKER, WARNING};
use beltrami_render::histogram::{Bars, HistogramStyle, Weighting, render_histogram};
use beltrami_render::{
    Camera, ColorBy, Layout, MuRange, Picture, Raster, RenderError, Scene, Size, Style, View,
    render, viridis,
};

fn grid(n: usize) -> Mesh {
    Mesh::from_soup(&primitives::grid(n, n, Cells::Triangles)).expect("a grid is a mesh")
}

/// The planar map `f(x, y)` of a planar mesh as per-vertex texture coordinates.
fn planar_map(mesh: &Mesh, f: impl Fn(f64, f64) -> (f64, f64)) -> Layout {
    let uv: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| {
            let (u, v) = f(p.x, p.y);
            Vector2::new(u, v)
        })
        .collect();
    Layout::plane_from_vertices(mesh, &uv).expect("finite texture coordinates")
}

fn style(width: u32, height: u32, view: View, color: ColorBy) -> Style {
    Style {
        size: Size::new(width, height).expect("a valid size"),
        view,
        color,
        ..Style::default()
    }
}

fn distance(a: [u8; 3], b: [u8; 3]) -> i32 {
    (0..3)
        .map(|k| (i32::from(a[k]) - i32::from(b[k])).abs())
        .max()
        .unwrap_or(0)
}

fn pixels(picture: &Picture) -> impl Iterator<Item = (u32, u32, [u8; 3])> + '_ {
    (0..picture.height()).flat_map(move |y| {
        (0..picture.width()).map(move |x| (x, y, picture.pixel(x, y).expect("inside")))
    })
}

#[test]
fn the_same_input_gives_the_same_bytes_and_plausible_pixels() {
    let mesh = grid(24);
    let image = planar_map(&mesh, |x, y| (x + 0.3 * y * y, y + 0.1 * (3.0 * x).sin()));
    let scene = Scene::new(&mesh, Some(image)).expect("a scene");
    for color in [ColorBy::Mu, ColorBy::Checker, ColorBy::Plain] {
        let s = Style {
            wire: true,
            ..style(480, 360, View::Both, color)
        };
        let a = render(&scene, &s)
            .expect("renders")
            .encode_png()
            .expect("encodes");
        let b = render(&scene, &s)
            .expect("renders")
            .encode_png()
            .expect("encodes");
        assert_eq!(a, b, "{color:?}: two renders differ");
    }
    // Pixel statistics: the two unit-size domains cover a sizeable part of the picture,
    // and the background still dominates the margins.
    let picture = render(&scene, &style(480, 360, View::Both, ColorBy::Mu)).expect("renders");
    let drawn = pixels(&picture).filter(|p| p.2 != [255, 255, 255]).count() as f64;
    let share = drawn / f64::from(480 * 360);
    assert!((0.25..0.75).contains(&share), "drawn share {share}");
}

#[test]
fn the_picture_has_the_size_asked_for() {
    let mesh = grid(6);
    let scene = Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (x, y)))).expect("a scene");
    for (w, h) in [(64, 64), (333, 129), (1000, 700), (200, 900)] {
        for view in [View::Uv, View::Surface, View::Both] {
            let picture = render(&scene, &style(w, h, view, ColorBy::Mu)).expect("renders");
            assert_eq!((picture.width(), picture.height()), (w, h), "{view:?}");
            let bytes = picture.encode_png().expect("encodes");
            let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
            let reader = decoder.read_info().expect("a PNG");
            let info = reader.info();
            assert_eq!((info.width, info.height), (w, h));
        }
    }
}

/// Runs of the two checker colors along row `y` between the first and last checker
/// pixel, as (color index, length); antialiased pixels between squares are skipped.
fn checker_runs(picture: &Picture, y: u32) -> Vec<(usize, u32)> {
    let mut runs: Vec<(usize, u32)> = Vec::new();
    for x in 0..picture.width() {
        let c = picture.pixel(x, y).expect("inside");
        let Some(k) = (0..2).find(|&k| distance(c, CHECKER[k]) <= 4) else {
            continue;
        };
        match runs.last_mut() {
            Some((last, n)) if *last == k => *n += 1,
            _ => runs.push((k, 1)),
        }
    }
    runs
}

#[test]
fn the_checkerboard_of_an_identity_map_is_a_regular_grid() {
    let mesh = grid(40);
    let scene = Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (x, y)))).expect("a scene");
    let cells = 8;
    let s = Style {
        checker_cells: cells,
        ..style(900, 700, View::Uv, ColorBy::Checker)
    };
    let picture = render(&scene, &s).expect("renders");
    // The rows the domain covers.
    let rows: Vec<u32> = (0..picture.height())
        .filter(|&y| !checker_runs(&picture, y).is_empty())
        .collect();
    let (top, bottom) = (rows[0], rows[rows.len() - 1]);
    let side = bottom - top + 1;
    // Rows through the middle of the first, third and last rows of squares.
    for row in [0.5, 2.5, 7.5] {
        let y = top + (row / f64::from(cells) * f64::from(side)) as u32;
        let runs = checker_runs(&picture, y);
        assert_eq!(runs.len(), cells as usize, "row {y}: {runs:?}");
        for pair in runs.windows(2) {
            assert_ne!(pair[0].0, pair[1].0, "row {y}: colors alternate");
        }
        let lengths: Vec<u32> = runs.iter().map(|r| r.1).collect();
        let (lo, hi) = (
            *lengths.iter().min().expect("runs"),
            *lengths.iter().max().expect("runs"),
        );
        assert!(hi - lo <= 3, "row {y}: square widths {lengths:?}");
        // Squares are square: as wide as the domain is tall over the cell count.
        let expected = f64::from(side) / f64::from(cells);
        assert!(
            (f64::from(lo) - expected).abs() <= 3.0,
            "row {y}: widths {lengths:?}, expected about {expected}"
        );
    }
    // The lower left square has the first color (parity 0), seen from the middle of
    // the last row of squares.
    let y = top + (7.5 / f64::from(cells) * f64::from(side)) as u32;
    assert_eq!(checker_runs(&picture, y)[0].0, 0);
}

/// A 4x4 grid whose map moves the center vertex across its neighbours, folding the faces
/// around it.
fn folded_grid() -> (Mesh, Layout) {
    let mesh = grid(4);
    let center = mesh
        .positions()
        .iter()
        .position(|p| (p.x - 0.5).abs() < 1e-9 && (p.y - 0.5).abs() < 1e-9)
        .expect("the grid has a center vertex");
    let uv: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if i == center {
                Vector2::new(0.95, 0.2)
            } else {
                Vector2::new(p.x, p.y)
            }
        })
        .collect();
    let layout = Layout::plane_from_vertices(&mesh, &uv).expect("finite");
    (mesh, layout)
}

/// Pixels in the warning color inside the panels (the legend row excluded).
fn warning_pixels(picture: &Picture) -> usize {
    let bottom = picture.height() * 85 / 100;
    pixels(picture)
        .filter(|&(_, y, c)| y < bottom && distance(c, WARNING) <= 40)
        .count()
}

#[test]
fn flipped_faces_are_outlined_in_the_warning_color() {
    let (mesh, layout) = folded_grid();
    let scene = Scene::new(&mesh, Some(layout)).expect("a scene");
    let flips = scene.distortion().expect("measured").stats.flipped;
    assert!(flips > 0, "the fold flips faces");
    for view in [View::Uv, View::Both] {
        let picture = render(&scene, &style(640, 480, view, ColorBy::Plain)).expect("renders");
        assert!(
            warning_pixels(&picture) > 50,
            "{view:?}: flipped faces are outlined"
        );
    }
    let mesh = grid(4);
    let scene = Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (x, y)))).expect("a scene");
    assert_eq!(scene.distortion().expect("measured").stats.flipped, 0);
    let picture = render(&scene, &style(640, 480, View::Uv, ColorBy::Plain)).expect("renders");
    assert_eq!(warning_pixels(&picture), 0, "nothing to warn about");
}

#[test]
fn the_camera_looks_along_minus_z_at_zero_and_edge_on_at_ninety_degrees() {
    let mesh = grid(10);
    let scene = Scene::new(&mesh, None).expect("a scene");
    let covered = |camera: Camera| {
        let s = Style {
            camera,
            ..style(400, 400, View::Surface, ColorBy::Plain)
        };
        let picture = render(&scene, &s).expect("renders");
        let (top, bottom) = (picture.height() / 10, picture.height() * 85 / 100);
        pixels(&picture)
            .filter(|&(_, y, c)| y > top && y < bottom && c != [255, 255, 255])
            .count()
    };
    let front = covered(Camera::new(0.0, 0.0).expect("valid"));
    let edge = covered(Camera::new(90.0, 0.0).expect("valid"));
    let above = covered(Camera::new(0.0, 90.0).expect("valid"));
    assert!(front > 60_000, "front view covers the panel: {front}");
    assert!(edge < front / 20, "edge-on: {edge} against {front}");
    assert!(
        above < front / 20,
        "from above (+y): {above} against {front}"
    );
    // The basis is orthonormal and right-handed with `back` towards the camera.
    let b = Camera::new(30.0, 20.0).expect("valid").basis();
    assert!((b.right.cross(&b.up) - b.back).norm() < 1e-12);
    let front = Camera::default().basis();
    assert!((front.back - beltrami_mesh::Vector3::z()).norm() < 1e-12);
    assert_eq!(front.project(&Point3::new(1.0, 2.0, 3.0)), [1.0, 2.0, -3.0]);
}

#[test]
fn the_depth_test_keeps_the_nearer_triangle_in_either_order() {
    let near = [[2.0, 2.0, 0.0], [30.0, 2.0, 0.0], [2.0, 30.0, 0.0]];
    let far = [[2.0, 2.0, 1.0], [30.0, 2.0, 1.0], [2.0, 30.0, 1.0]];
    for order in [[near, far], [far, near]] {
        let mut raster = Raster::new(32, 32, [255; 3]);
        for t in order {
            let c = if t[0][2] == 0.0 { [1, 2, 3] } else { [9, 9, 9] };
            raster.triangle(t, true, |_| c);
        }
        assert_eq!(raster.color(5, 5), [1, 2, 3]);
    }
}

#[test]
fn the_rasterizer_covers_each_sample_of_a_mesh_exactly_once() {
    // A jittered grid over the raster, both orientations: no cracks, no overlaps.
    let soup = primitives::jittered_grid(13, 11, Cells::Triangles, 0.3, 7);
    let mesh = Mesh::from_soup(&soup).expect("a mesh");
    let (w, h) = (97usize, 61usize);
    for flip in [false, true] {
        let mut count = vec![0u32; w * h];
        let mut raster = Raster::new(w, h, [0; 3]);
        for f in mesh.faces() {
            let (v, _) = mesh.face_vertex_array(f);
            let p = |k: usize| {
                let q = mesh.position(v[k]);
                let y = if flip { 1.0 - q.y } else { q.y };
                [q.x * w as f64, y * h as f64, 0.0]
            };
            raster.triangle([p(0), p(1), p(2)], false, |fr| {
                assert!(fr.bary.iter().all(|b| (-1e-4..=1.0001).contains(b)));
                [0; 3]
            });
            // Count by re-rasterizing into a fresh buffer per triangle.
            let mut single = Raster::new(w, h, [0; 3]);
            single.triangle([p(0), p(1), p(2)], false, |_| [1; 3]);
            for y in 0..h {
                for x in 0..w {
                    if single.color(x, y) == [1; 3] {
                        count[y * w + x] += 1;
                    }
                }
            }
        }
        assert!(count.iter().all(|&c| c == 1), "flip {flip}: {:?}", {
            let bad: Vec<usize> = (0..w * h).filter(|&i| count[i] != 1).take(5).collect();
            bad
        });
    }
}

#[test]
fn the_color_bar_runs_from_purple_at_the_bottom_to_yellow_at_the_top() {
    let mesh = grid(6);
    let scene = Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (x, y)))).expect("a scene");
    let picture = render(&scene, &style(800, 600, View::Uv, ColorBy::Mu)).expect("renders");
    let rgb = |t: f64| viridis(t).map(|c| (c * 255.0).round() as u8);
    let found = (picture.width() * 8 / 10..picture.width()).any(|x| {
        let rows = |target: [u8; 3]| {
            (0..picture.height())
                .filter(|&y| distance(picture.pixel(x, y).expect("inside"), target) <= 3)
                .collect::<Vec<_>>()
        };
        let (top, bottom) = (rows(rgb(1.0)), rows(rgb(0.0)));
        !top.is_empty() && !bottom.is_empty() && top[top.len() - 1] < bottom[0]
    });
    assert!(
        found,
        "a column goes from yellow (top) to dark purple (bottom)"
    );
}

#[test]
fn mu_colors_follow_the_range() {
    // An affine map z + 0.3 conj(z) has |mu| = 0.3 on every face.
    let mesh = grid(8);
    let scene =
        Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (1.3 * x, 0.7 * y)))).expect("a scene");
    let d = scene.distortion().expect("measured");
    assert!(d.modulus.iter().all(|m| (m - 0.3).abs() < 1e-12));
    let range = MuRange::new(0.0, 0.6).expect("valid");
    assert_eq!(range.color(0.3), range.color(0.3));
    let s = Style {
        mu_range: range,
        ..style(400, 300, View::Uv, ColorBy::Mu)
    };
    let picture = render(&scene, &s).expect("renders");
    let center = picture
        .pixel(picture.width() * 4 / 10, picture.height() / 2)
        .expect("inside");
    assert!(distance(center, range.color(0.3)) <= 2, "{center:?}");
}

#[test]
fn texture_seams_do_not_change_the_measure() {
    // The affine map per corner, each face shifted by its own offset: seams everywhere.
    let mesh = grid(6);
    let mut corners = vec![Vector2::zeros(); beltrami_render::corner_count(&mesh)];
    for f in mesh.faces() {
        let shift = Vector2::new(f.idx() as f64, -(f.idx() as f64));
        for h in mesh.face_halfedges(f) {
            let p = mesh.position(mesh.origin(h));
            corners[h.idx()] = Vector2::new(1.3 * p.x, 0.7 * p.y) + shift;
        }
    }
    let scene =
        Scene::new(&mesh, Some(Layout::plane(&mesh, corners).expect("finite"))).expect("a scene");
    let d = scene.distortion().expect("measured");
    assert!(d.modulus.iter().all(|m| (m - 0.3).abs() < 1e-12));
    assert_eq!(d.stats.flipped, 0);
}

#[test]
fn a_map_onto_a_sphere_is_judged_against_the_radial_direction() {
    let mesh = Mesh::from_soup(&primitives::icosphere(2)).expect("a sphere");
    // A rotation of the sphere by a half turn about y: conformal, far from the source.
    let image: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(-p.x, p.y, -p.z))
        .collect();
    let scene =
        Scene::new(&mesh, Some(Layout::space(&mesh, image).expect("finite"))).expect("a scene");
    let d = scene.distortion().expect("measured");
    assert_eq!(d.stats.flipped, 0);
    assert!(d.stats.mu_max < 1e-9);
}

#[test]
fn bad_input_gets_typed_errors_naming_the_element() {
    for text in ["1600", "0x100", "axb", "100000x10", "12x-3"] {
        assert!(
            matches!(text.parse::<Size>(), Err(RenderError::Size { .. })),
            "{text}"
        );
    }
    assert_eq!(
        "640x480".parse::<Size>().expect("valid"),
        Size::new(640, 480).expect("valid")
    );
    for text in ["30", "30,95", "nan,0", "a,b"] {
        assert!(
            matches!(text.parse::<Camera>(), Err(RenderError::Camera { .. })),
            "{text}"
        );
    }
    assert_eq!("-30,20".parse::<Camera>().expect("valid").azimuth, -30.0);
    for text in ["1,0", "-1,1", "x", "0,inf"] {
        assert!(
            matches!(text.parse::<MuRange>(), Err(RenderError::MuRange { .. })),
            "{text}"
        );
    }

    let mesh = grid(3);
    let short = vec![Vector2::new(0.0, 0.0); 3];
    assert!(matches!(
        Layout::plane_from_vertices(&mesh, &short),
        Err(RenderError::Length {
            expected: 16,
            got: 3,
            ..
        })
    ));
    let mut uv: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(p.x, p.y))
        .collect();
    uv[5].y = f64::NAN;
    let error = Layout::plane_from_vertices(&mesh, &uv).expect_err("NaN");
    assert!(matches!(
        error,
        RenderError::NonFinite {
            element: "vertex",
            index: 5,
            ..
        }
    ));
    assert!(error.to_string().contains("vertex 5"), "{error}");
    let mut points = mesh.positions().to_vec();
    points[7].z = f64::INFINITY;
    assert!(matches!(
        Layout::space(&mesh, points),
        Err(RenderError::NonFinite {
            element: "vertex",
            index: 7,
            ..
        })
    ));

    // Views and colorings that need a map.
    let surface = Mesh::from_soup(&primitives::icosphere(1)).expect("a sphere");
    let scene = Scene::new(&surface, None).expect("a scene");
    for (view, color) in [
        (View::Uv, ColorBy::Plain),
        (View::Both, ColorBy::Plain),
        (View::Surface, ColorBy::Mu),
        (View::Surface, ColorBy::Checker),
    ] {
        let error = render(&scene, &style(200, 200, view, color)).expect_err("needs a map");
        assert!(
            matches!(error, RenderError::Missing(_)),
            "{view:?} {color:?}"
        );
    }
    assert!(render(&scene, &style(200, 200, View::Surface, ColorBy::Plain)).is_ok());
    // A planar mesh without a map has a uv view of its own.
    let scene = Scene::new(&mesh, None).expect("a scene");
    assert!(render(&scene, &style(200, 200, View::Uv, ColorBy::Plain)).is_ok());
}

#[test]
fn pngs_are_written_whole_or_not_at_all() {
    let mesh = grid(4);
    let scene = Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (x, y)))).expect("a scene");
    let picture = render(&scene, &style(300, 200, View::Uv, ColorBy::Mu)).expect("renders");
    let dir = tempfile::tempdir().expect("a temporary folder");

    let path = dir.path().join("map.png");
    picture.write_png(&path).expect("writes");
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&path).expect("exists"),
    ));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buffer = vec![0; reader.output_buffer_size().expect("a size")];
    let frame = reader.next_frame(&mut buffer).expect("a frame");
    assert_eq!((frame.width, frame.height), (300, 200));
    assert_eq!(&buffer[..frame.buffer_size()], picture.rgb().as_slice());

    let missing = dir.path().join("no/such/folder/map.png");
    assert!(matches!(
        picture.write_png(&missing),
        Err(RenderError::Write(_))
    ));
    assert!(!missing.exists());
    let wrong = dir.path().join("map.jpg");
    assert!(matches!(
        picture.write_png(&wrong),
        Err(RenderError::NotPng { .. })
    ));
    assert!(!wrong.exists());
    let names: Vec<_> = std::fs::read_dir(dir.path()).expect("lists").collect();
    assert_eq!(names.len(), 1, "no temporary file is left behind");
}

#[test]
fn histogram_bars_count_faces_or_area() {
    let range = MuRange::default();
    let modulus = [0.05, 0.35, 0.36, 0.99, 1.0, 3.0];
    let bars = Bars::new(&modulus, None, 10, range).expect("bars");
    let expect = [1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0].map(|n| n / 6.0);
    for (got, want) in bars.fractions.iter().zip(expect) {
        assert!((got - want).abs() < 1e-15);
    }
    assert!((bars.beyond - 2.0 / 6.0).abs() < 1e-15);
    let weights = [1.0, 0.0, 0.0, 0.0, 0.0, 3.0];
    let bars = Bars::new(&modulus, Some(&weights), 10, range).expect("bars");
    assert!((bars.fractions[0] - 0.25).abs() < 1e-15);
    assert!((bars.beyond - 0.75).abs() < 1e-15);
    let narrow =
        Bars::new(&modulus, None, 4, MuRange::new(0.3, 0.5).expect("valid")).expect("bars");
    assert!((narrow.below - 1.0 / 6.0).abs() < 1e-15);
    assert!((narrow.beyond - 3.0 / 6.0).abs() < 1e-15);
    assert!((narrow.fractions.iter().sum::<f64>() - 2.0 / 6.0).abs() < 1e-15);
    assert!(matches!(
        Bars::new(&modulus, None, 0, range),
        Err(RenderError::Bins { .. })
    ));
    assert!(matches!(
        Bars::new(&[f64::NAN], None, 5, range),
        Err(RenderError::NonFinite { index: 0, .. })
    ));
    assert!(matches!(
        Bars::new(&modulus, Some(&[1.0]), 5, range),
        Err(RenderError::Length { .. })
    ));
}

#[test]
fn the_histogram_of_a_constant_mu_is_one_bar() {
    let mesh = grid(8);
    let scene =
        Scene::new(&mesh, Some(planar_map(&mesh, |x, y| (1.3 * x, 0.7 * y)))).expect("a scene");
    let d = scene.distortion().expect("measured");
    for weighting in [Weighting::Faces, Weighting::Area] {
        let s = HistogramStyle {
            size: Size::new(600, 400).expect("valid"),
            bins: 10,
            weighting,
            ..HistogramStyle::default()
        };
        let picture = render_histogram(d, &s).expect("draws");
        assert_eq!((picture.width(), picture.height()), (600, 400));
        // Only the bar of 0.3 <= |mu| < 0.4 is drawn, in its viridis color.
        let bar = MuRange::default().color(0.35);
        let other = MuRange::default().color(0.15);
        let count = |c: [u8; 3]| pixels(&picture).filter(|p| p.2 == c).count();
        assert!(count(bar) > 1000, "{weighting:?}");
        assert_eq!(count(other), 0);
    }
}

#[test]
fn a_raster_drawn_in_bands_equals_the_raster_drawn_whole() {
    // Big pictures are drawn band by band (bounded memory); the samples must not change.
    let soup = primitives::jittered_grid(9, 7, Cells::Triangles, 0.3, 11);
    let mesh = Mesh::from_soup(&soup).expect("a mesh");
    let (w, h) = (83usize, 67usize);
    let draw = |raster: &mut Raster| {
        for f in mesh.faces() {
            let (v, _) = mesh.face_vertex_array(f);
            let p = |k: usize| {
                let q = mesh.position(v[k]);
                [q.x * w as f64, q.y * h as f64, q.x + q.y]
            };
            let c = [(f.idx() * 37 % 251) as u8, (f.idx() % 7) as u8, 9];
            raster.triangle([p(0), p(1), p(2)], true, |fr| {
                [c[0], c[1], (fr.bary[0] * 200.0) as u8]
            });
        }
    };
    let mut whole = Raster::new(w, h, [255; 3]);
    draw(&mut whole);
    for rows in [1usize, 4, 10, 66] {
        let mut top = 0;
        while top < h {
            let n = rows.min(h - top);
            let mut band = Raster::band(w, top, n, [255; 3]);
            draw(&mut band);
            for y in 0..n {
                for x in 0..w {
                    assert_eq!(band.color(x, y), whole.color(x, top + y), "{rows} rows");
                }
            }
            top += n;
        }
    }
}
