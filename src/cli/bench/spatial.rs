//! `beltrami bench spatial`: point location and motion on a target surface.
//!
//! For each target mesh (a generated torus of about `--faces` triangles, then the given
//! files) it times, on one thread:
//! - building the `SurfaceIndex` (face samples, kd-tree, vertex normals);
//! - locating `--points` random points near the surface: a uniformly chosen face, a
//!   uniform point on it, moved in a uniform direction by up to two mean edge lengths;
//!   as a floor, the same points' nearest face centroid in a bare kiddo tree (not the
//!   closest point, only the tree query);
//! - two steps of a flow on a source with the target's vertices. Step 1: every vertex
//!   moved off the surface (a tangent step of up to half a mean edge plus a normal
//!   offset of up to a tenth) and re-located, without hints (`locate_all`) and with a
//!   face of the vertex as hint (`locate_all_near`). Step 2: the same from where step 1
//!   landed (points inside faces, their faces as hints), re-located with hints, or
//!   walked on the surface (`move_all`) by the same tangent steps.

use std::path::PathBuf;

use super::fastest;
use anyhow::Context;
use beltrami_mesh::primitives::{Cells, torus};
use beltrami_mesh::{BuildOptions, FaceId, Mesh, Point3, SurfacePoint, Vector3, io};
use beltrami_spatial::{MoveOptions, MoveSummary, SurfaceIndex};
use clap::Args;
use kiddo::{ImmutableKdTree, SquaredEuclidean};

#[derive(Debug, Args)]
pub struct SpatialArgs {
    /// Triangles of the generated torus target (0: none).
    #[arg(long, default_value_t = 100_000)]
    pub faces: usize,
    /// Target meshes to time as well.
    #[arg(long = "mesh")]
    pub meshes: Vec<PathBuf>,
    /// Random points to locate per target.
    #[arg(long, default_value_t = 1_000_000)]
    pub points: usize,
    /// Repetitions per measurement; the table shows the fastest.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
}

/// SplitMix64: a reproducible stream of uniform numbers.
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }

    /// A uniform direction (rejection from the cube).
    fn direction(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
            );
            let n = v.norm();
            if n > 1e-3 && n <= 1.0 {
                return v / n;
            }
        }
    }

    /// A uniform point of face `f` (uniform barycentric or bilinear parameter).
    fn on_face(&mut self, mesh: &Mesh, f: FaceId) -> SurfacePoint {
        let (a, b) = (self.next(), self.next());
        if mesh.face_degree(f) == 3 {
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            SurfacePoint::in_triangle(f, [1.0 - a - b, a, b])
        } else {
            SurfacePoint::in_quad(f, a, b)
        }
    }
}

/// Timings of the flow steps on one target.
struct StepTimes {
    name: String,
    faces: usize,
    points: usize,
    cold: f64,
    warm: f64,
    next: f64,
    walk: f64,
    summary: MoveSummary,
}

/// The moved positions and the tangent steps of a flow step.
struct Step {
    moved: Vec<Point3<f64>>,
    tangents: Vec<Vector3<f64>>,
}

/// A flow step from `points`: each moved in its tangent plane by up to half of `edge` in
/// a uniform direction and off the surface by up to a tenth of `edge` along the normal.
fn perturb(
    index: &SurfaceIndex,
    points: &[SurfacePoint],
    edge: f64,
    rng: &mut Uniform,
) -> anyhow::Result<Step> {
    let mut moved = Vec::with_capacity(points.len());
    let mut tangents = Vec::with_capacity(points.len());
    for p in points {
        let frame = index.frame(p)?;
        let t = frame.tangential(&rng.direction());
        let t = if t.norm() > 0.0 {
            t.normalize()
        } else {
            frame.e1
        };
        let step = 0.5 * edge * rng.next() * t;
        let offset = 0.1 * edge * (2.0 * rng.next() - 1.0) * frame.normal;
        moved.push(frame.origin + step + offset);
        tangents.push(step);
    }
    Ok(Step { moved, tangents })
}

fn targets(args: &SpatialArgs) -> anyhow::Result<Vec<(String, Mesh)>> {
    let mut out = Vec::new();
    if args.faces > 0 {
        // n_major = 3.2 n_minor, 2 n_major n_minor triangles.
        let minor = ((args.faces as f64 / 6.4).sqrt().round() as usize).max(3);
        let major = ((args.faces as f64 / (2.0 * minor as f64)).round() as usize).max(3);
        let mesh = Mesh::from_soup(&torus(major, minor, 1.0, 0.35, Cells::Triangles))?;
        out.push((format!("torus {major}x{minor}"), mesh));
    }
    for path in &args.meshes {
        let mesh = io::read(path, &BuildOptions::default())
            .with_context(|| format!("cannot read {}", path.display()))?
            .mesh;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        out.push((name, mesh));
    }
    Ok(out)
}

pub fn run(args: &SpatialArgs) -> anyhow::Result<()> {
    let cases = targets(args)?;
    println!(
        "Index and location (1 thread, fastest of {}):",
        args.repeat.max(1)
    );
    println!();
    println!(
        "| target | faces | vertices | samples | index build s | points | locate_all s | per point us | kiddo nearest centroid s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut steps = Vec::new();
    for (name, mesh) in &cases {
        let (build, index) = fastest(args.repeat, || Ok(SurfaceIndex::new(mesh)?))?;
        let edge = mesh.edge_lengths().iter().sum::<f64>() / mesh.edge_count() as f64;
        let mut rng = Uniform(0x5EED);
        let points: Vec<Point3<f64>> = (0..args.points)
            .map(|_| {
                let f = FaceId(rng.below(mesh.face_count()) as u32);
                let x = rng.on_face(mesh, f).position(mesh);
                x + 2.0 * edge * rng.next() * rng.direction()
            })
            .collect();
        let (locate, located) = fastest(args.repeat, || Ok(index.locate_all(&points)?))?;
        std::hint::black_box(&located);
        let centroids: Vec<[f64; 3]> = mesh
            .faces()
            .map(|f| mesh.face_centroid(f).coords.into())
            .collect();
        let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&centroids)?;
        let (bare, _) = fastest(args.repeat, || {
            Ok(points
                .iter()
                .map(|p| {
                    tree.query(&[p.x, p.y, p.z])
                        .nearest_one::<SquaredEuclidean<f64>>()
                        .execute()
                        .item
                })
                .fold(0u64, |a, i| a.wrapping_add(u64::from(i))))
        })?;
        println!(
            "| {name} | {} | {} | {} | {build:.3} | {} | {locate:.3} | {:.2} | {bare:.3} |",
            mesh.face_count(),
            mesh.vertex_count(),
            index.sample_count(),
            points.len(),
            1e6 * locate / points.len() as f64,
        );

        // Flow steps on a source with the target's vertices.
        let start: Vec<SurfacePoint> = mesh
            .vertices()
            .map(|v| SurfacePoint::at_vertex(mesh, v))
            .collect();
        let moved = perturb(&index, &start, edge, &mut rng)?.moved;
        let hints: Vec<FaceId> = start.iter().map(|p| p.face).collect();
        let (cold, _) = fastest(args.repeat, || Ok(index.locate_all(&moved)?))?;
        let (warm, located) = fastest(args.repeat, || Ok(index.locate_all_near(&moved, &hints)?))?;
        // The next step starts where this one landed (points inside faces).
        let landed: Vec<SurfacePoint> = located.iter().map(|l| l.point).collect();
        let Step { moved, tangents } = perturb(&index, &landed, edge, &mut rng)?;
        let hints: Vec<FaceId> = landed.iter().map(|p| p.face).collect();
        let (next, _) = fastest(args.repeat, || Ok(index.locate_all_near(&moved, &hints)?))?;
        let options = MoveOptions::default();
        let (walk, summary) = fastest(args.repeat, || {
            let mut points = landed.clone();
            Ok(index.move_all(&mut points, &tangents, &options)?)
        })?;
        steps.push(StepTimes {
            name: name.clone(),
            faces: mesh.face_count(),
            points: start.len(),
            cold,
            warm,
            next,
            walk,
            summary,
        });
    }
    println!();
    println!(
        "Flow steps on a source with the target's vertices (1: from the vertices, 2: from where step 1 landed):"
    );
    println!();
    println!(
        "| target | faces | points | step 1 locate_all s | step 1 locate_all_near s | step 2 locate_all_near s | step 2 move_all (walk) s | faces crossed per walk | walks projected |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for t in steps {
        println!(
            "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {} |",
            t.name,
            t.faces,
            t.points,
            t.cold,
            t.warm,
            t.next,
            t.walk,
            t.summary.faces_crossed as f64 / t.points as f64,
            t.summary.projected
        );
    }
    Ok(())
}
