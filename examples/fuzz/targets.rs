//! The fuzz targets: one function per input parser or library entry point that takes
//! bytes a user controls. Each returns `Ok` for accepted input and `Err` with the
//! library's error message for refused input; a panic (or a stack overflow, which ends
//! the process) is the bug to find. Shared by the driver (`examples/fuzz/main.rs`) and
//! the regression test over `tests/corpus/` (`tests/hardening.rs`).

use std::path::Path;
use std::sync::OnceLock;

use beltrami::fem::{BeltramiField, Expr};
use beltrami::landmarks::Landmarks;
use beltrami::mesh::io::{self, RawMesh};
use beltrami::mesh::primitives::{self, Cells};
use beltrami::mesh::{BuildOptions, Mesh, Point3, PolygonSoup, Repair, cut_graph, cut_to_disk};
use beltrami::{batch_job, correspondence};
use num_complex::Complex64;

/// The targets, by the name the driver and the corpus folders use.
pub const TARGETS: [&str; 14] = [
    "obj",
    "gltf",
    "ply",
    "stl",
    "off",
    "build",
    "expr",
    "field",
    "landmarks",
    "correspondence",
    "cut",
    "circle-domain",
    "remesh",
    "jobs",
];

/// Runs target `name` on `data`.
pub fn run(name: &str, data: &[u8]) -> Result<(), String> {
    match name {
        "obj" => obj(data),
        "gltf" => gltf(data),
        "ply" => positioned(Path::new("fuzz.ply"), io::ply::parse(data)),
        "stl" => positioned(Path::new("fuzz.stl"), io::stl::parse(data)),
        "off" => positioned(Path::new("fuzz.off"), io::off::parse(data)),
        "build" => build(data),
        "expr" => expr(data),
        "field" => field(data),
        "landmarks" => landmarks(data),
        "correspondence" => correspondence(data),
        "cut" => cut(data),
        "circle-domain" => circle_domain(data),
        "remesh" => remesh(data),
        "jobs" => jobs(data),
        _ => Err(format!("unknown target `{name}`")),
    }
}

/// A mesh the builder accepted, cut: `cut_graph` always, `cut_to_disk` when it is
/// connected (it refuses several components with an error, which is fine too).
fn cut_accepted(mesh: &Mesh) -> Result<(), String> {
    let graph = cut_graph(mesh);
    if graph.components.len() != mesh.components().len() {
        return Err("cut_graph lost a component".into());
    }
    cut_to_disk(mesh).map(|_| ()).map_err(|e| e.to_string())
}

fn text(data: &[u8]) -> Result<&str, String> {
    std::str::from_utf8(data).map_err(|e| e.to_string())
}

/// Options of the builder chosen by one byte: the tolerance (the default, zero,
/// negative, large) and each repair flag.
fn options(byte: u8) -> BuildOptions {
    BuildOptions {
        degenerate_area_tolerance: [1e-12, 0.0, -1.0, 1e-3][usize::from(byte & 3)],
        repair: Repair {
            drop_degenerate_faces: byte & 4 != 0,
            drop_duplicate_faces: byte & 8 != 0,
            merge_coincident_vertices: byte & 16 != 0,
        },
    }
}

fn built(path: &Path, raw: RawMesh, options: &BuildOptions) -> Result<(), String> {
    let loaded = io::build_raw(path, raw, options).map_err(|e| e.to_string())?;
    let _ = loaded.vertex_uvs();
    cut_accepted(&loaded.mesh)
}

/// The OBJ reader, then the builder with default options and the cuts.
fn obj(data: &[u8]) -> Result<(), String> {
    let path = Path::new("fuzz.obj");
    let raw = io::obj::parse(path, data).map_err(|e| e.to_string())?;
    built(path, raw, &BuildOptions::default())
}

/// A PLY, STL or OFF reader's result (a syntax error with its place), then the builder
/// and the cuts.
fn positioned(path: &Path, raw: Result<RawMesh, (io::FilePosition, String)>) -> Result<(), String> {
    let raw = raw.map_err(|(at, message)| format!("{at}: {message}"))?;
    built(path, raw, &BuildOptions::default())
}

/// The glTF/GLB reader (external buffers resolve beside a file that does not exist),
/// then the builder and the cuts.
fn gltf(data: &[u8]) -> Result<(), String> {
    let path = Path::new("/nonexistent-beltrami-fuzz/fuzz.gltf");
    let raw = io::gltf::parse_bytes(path, data).map_err(|e| e.to_string())?;
    built(path, raw, &BuildOptions::default())
}

/// Coordinates the `build` target draws from: ordinary values and the edges of the
/// accepted range.
const VALUES: [f64; 16] = [
    0.0,
    1.0,
    -1.0,
    0.5,
    2.0,
    1e-12,
    1e75,
    -1e75,
    1e76,
    1e-75,
    1e-76,
    1e300,
    1e-300,
    3.0,
    f64::NAN,
    1e-320,
];

/// A polygon soup read from bytes: byte 0 chooses the options, byte 1 the vertex count
/// (1..=16); then per vertex three bytes, each choosing a coordinate from [`VALUES`] or
/// a small integer; the rest are faces, a length byte (3, 4 or other sizes) then that
/// many vertex indices (modulo the count plus two, so some are out of range). The mesh
/// the builder accepts is cut.
fn build(data: &[u8]) -> Result<(), String> {
    let mut bytes = data.iter().copied();
    let options = options(bytes.next().unwrap_or(0));
    let n = usize::from(bytes.next().unwrap_or(3) % 16) + 1;
    let mut coordinate = || {
        let b = bytes.next().unwrap_or(0);
        if b & 0x80 != 0 {
            VALUES[usize::from(b & 15)]
        } else {
            f64::from(b & 7)
        }
    };
    let positions: Vec<Point3<f64>> = (0..n)
        .map(|_| Point3::new(coordinate(), coordinate(), coordinate()))
        .collect();
    let mut soup = PolygonSoup::new(positions);
    let mut face = Vec::new();
    while let Some(len) = bytes.next() {
        let len = match len % 8 {
            0..=3 => 3,
            4..=6 => 4,
            _ => usize::from(len % 6),
        };
        face.clear();
        face.extend((0..len).map_while(|_| bytes.next().map(|b| u32::from(b) % (n as u32 + 2))));
        soup.push_face(&face);
    }
    let (mesh, _) = Mesh::build(&soup, &options).map_err(|e| e.to_string())?;
    cut_accepted(&mesh)
}

/// The `--mu-expr` parser, then evaluation at a few points.
fn expr(data: &[u8]) -> Result<(), String> {
    let e = Expr::parse(text(data)?).map_err(|e| e.to_string())?;
    for z in [
        Complex64::new(0.0, 0.0),
        Complex64::new(0.3, -0.2),
        Complex64::new(1e300, 1e-300),
    ] {
        let _ = e.eval(z);
    }
    Ok(())
}

/// A disk (source and target of the file parsers): 16 faces.
fn disk() -> &'static Mesh {
    static DISK: OnceLock<Mesh> = OnceLock::new();
    DISK.get_or_init(|| match Mesh::from_soup(&primitives::disk(1)) {
        Ok(mesh) => mesh,
        Err(e) => panic!("the generated disk is a valid mesh: {e}"),
    })
}

/// A closed genus-1 mesh for the cut target's seeds.
pub fn torus_obj() -> String {
    let soup = primitives::torus(6, 4, 2.0, 0.7, Cells::Triangles);
    let mut out = String::new();
    for p in &soup.positions {
        out.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for f in soup.faces() {
        out.push('f');
        for v in f {
            out.push_str(&format!(" {}", v + 1));
        }
        out.push('\n');
    }
    out
}

/// A valid correspondence file for [`correspondence`]: every disk vertex onto a corner
/// of face 0.
pub fn correspondence_seed() -> String {
    (0..disk().vertex_count())
        .map(|k| format!("0 {} {} 0\n", k % 2, 1 - k % 2))
        .collect()
}

/// The Beltrami field file parser, for the disk's face count.
fn field(data: &[u8]) -> Result<(), String> {
    BeltramiField::parse(Path::new("fuzz.mu"), text(data)?, disk().face_count())
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// The landmarks file parser, the disk onto itself, and the constraints it gives.
fn landmarks(data: &[u8]) -> Result<(), String> {
    let mesh = disk();
    let marks = Landmarks::parse(Path::new("fuzz.landmarks"), text(data)?, mesh, mesh)
        .map_err(|e| e.to_string())?;
    let _ = marks.constraints();
    Ok(())
}

/// The jobs file of `beltrami batch`. An accepted file must give command lines in which
/// nothing but an option's own name reads as a flag: the command first, inputs that do
/// not start with `-`, `-o OUTPUT`, then `--name [value]` groups whose values do not
/// start with `--` and whose names are not empty, hold no `=` or space, and are not
/// help, version or the output.
fn jobs(data: &[u8]) -> Result<(), String> {
    let jobs = batch_job::parse_jobs(text(data)?).map_err(|e| e.to_string())?;
    for job in &jobs {
        let args = &job.args;
        assert_eq!(args[0], job.command, "line {}: {args:?}", job.line);
        let o = args.iter().position(|a| a == "-o").expect("no -o");
        assert!(args[1..o].iter().all(|a| !a.starts_with('-')), "{args:?}");
        assert_eq!(Path::new(&args[o + 1]), job.output, "{args:?}");
        assert!(!args[o + 1].starts_with('-'), "{args:?}");
        for (k, a) in args.iter().enumerate().skip(o + 2) {
            let is_flag = a.starts_with("--");
            let follows_flag = args[k - 1].starts_with("--") && k - 1 > o + 1;
            assert!(is_flag || follows_flag, "a bare value {a:?} in {args:?}");
            if is_flag && !follows_flag {
                assert!(a.len() > 2 && !a[2..].starts_with('-'), "{args:?}");
                assert!(
                    !a.contains('=') && !a.contains(char::is_whitespace),
                    "{args:?}"
                );
                assert!(
                    !matches!(a.as_str(), "--help" | "--version" | "--output" | "--o"),
                    "{args:?}"
                );
            }
        }
    }
    Ok(())
}

/// The correspondence file parser, the disk onto itself.
fn correspondence(data: &[u8]) -> Result<(), String> {
    let mesh = disk();
    correspondence::parse(Path::new("fuzz.corr"), text(data)?, mesh, mesh)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// An OBJ built with the options of its first byte, then cut: every mesh the builder
/// accepts, under any options, must cut without a panic.
fn cut(data: &[u8]) -> Result<(), String> {
    let (&first, rest) = data.split_first().ok_or("empty input")?;
    let path = Path::new("fuzz.obj");
    let raw = io::obj::parse(path, rest).map_err(|e| e.to_string())?;
    built(path, raw, &options(first))
}

/// A number read from a byte: with the high bit, a value of [`VALUES`] (the edges of
/// the accepted ranges, NaN); otherwise `offset + step * (b & 0x7f)`.
fn scaled(b: u8, offset: f64, step: f64) -> f64 {
    if b & 0x80 != 0 {
        VALUES[usize::from(b & 15)]
    } else {
        offset + step * f64::from(b & 0x7f)
    }
}

/// `generate circle-domain` (`beltrami_remesh::circle_domain`): byte 0 chooses the edge
/// length (0.05 to 0.4: a few thousand faces at most), then three bytes per hole (up to
/// six): its centre's x and y and its radius, in steps of 0.02 from -1.2 (holes that
/// overlap, touch, leave the disk or have no area), or values of [`VALUES`].
fn circle_domain(data: &[u8]) -> Result<(), String> {
    use beltrami::remesh::circle_domain::{Hole, circle_domain};
    let mut bytes = data.iter().copied();
    let h = 0.05 * f64::from(1 + bytes.next().unwrap_or(0) % 8);
    let mut holes = Vec::new();
    while holes.len() < 6 {
        let (Some(x), Some(y), Some(r)) = (bytes.next(), bytes.next(), bytes.next()) else {
            break;
        };
        holes.push(Hole {
            center: Complex64::new(scaled(x, -1.2, 0.02), scaled(y, -1.2, 0.02)),
            radius: scaled(r, -0.2, 0.01),
        });
    }
    circle_domain(&holes, h)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// A disk of 64 faces bent into a saddle (`z = x y / 2`), for the remesh target.
fn saddle() -> &'static Mesh {
    static SADDLE: OnceLock<Mesh> = OnceLock::new();
    SADDLE.get_or_init(|| {
        let mut soup = primitives::disk(2);
        for p in &mut soup.positions {
            p.z = 0.5 * p.x * p.y;
        }
        match Mesh::from_soup(&soup) {
            Ok(mesh) => mesh,
            Err(e) => panic!("the bent disk is a valid mesh: {e}"),
        }
    })
}

/// `beltrami remesh` of a small saddle under options read from bytes: byte 0 chooses an
/// edge length or a vertex count and the size field, then the length (0.05 to 1.32) or
/// count (0 to 2040), the smallest angle (0 to 127 degrees), the most vertices (0 to
/// 4080) and the feature tolerance (0 to 3.8), each also from [`VALUES`].
fn remesh(data: &[u8]) -> Result<(), String> {
    use beltrami::remesh::{RemeshOptions, Resolution, SizeField, param, remesh};
    let mut bytes = data.iter().copied();
    let mut next = || bytes.next().unwrap_or(0);
    let kind = next();
    let resolution = if kind & 1 == 0 {
        Resolution::EdgeLength(scaled(next(), 0.05, 0.01))
    } else {
        Resolution::Vertices(usize::from(next()) * 8)
    };
    let options = RemeshOptions {
        resolution,
        size_field: if kind & 2 == 0 {
            SizeField::Uniform
        } else {
            SizeField::Curvature
        },
        min_angle: scaled(next(), 0.0, 1.0),
        max_vertices: usize::from(next()) * 16,
        feature_tolerance: scaled(next(), 0.0, 0.03),
    };
    let registry = beltrami::registry();
    let mesh = saddle();
    let solvers = param::chosen(&registry, mesh, "auto").map_err(|e| e.to_string())?;
    remesh(
        mesh,
        &solvers,
        &options,
        &mut beltrami::core::Context::new(),
    )
    .map(|_| ())
    .map_err(|e| e.to_string())
}
