//! `beltrami generate`: the meshes of the paper reproductions, as OBJ files.

use std::path::PathBuf;

use anyhow::bail;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{self, ModifiedTorus};
use beltrami_mesh::{Mesh, PolygonSoup};
use beltrami_remesh::circle_domain::Hole;
use clap::{Args, ValueEnum};

/// The generated shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Shape {
    /// The unit disk of Wong-Zhao's Table 5.1: 4^(level+1) triangles, boundary on the
    /// circle.
    Disk,
    /// The unit sphere of Table 5.2: an octahedron refined `level` times, 8 * 4^level
    /// triangles.
    Sphere,
    /// The annulus `inner <= |z| <= 1` of Fig. 5.9: `8 * 2^level` sectors, `2^(level+1)`
    /// rings.
    Annulus,
    /// The square `[-1, 1]^2` of Table 5.3: `2^(level+5)` cells per side (33^2 vertices
    /// at level 0), each split into two triangles.
    Square,
    /// The modified torus phi_1 of Wong-Zhao's section 5.4 (r1 = 4, r2 = 1.7, r3 = 0.3):
    /// a 40 * 2^level by 16 * 2^level grid of (u, v), 1280 * 4^level triangles.
    Torus1,
    /// The modified torus phi_2 of section 5.4 (r1 = 4, r2 = 1.5, r3 = 0.4), same grid.
    Torus2,
    /// A circle domain: the unit disk minus the disks of `--holes`, edges about
    /// 2^-(level+2) long (spade's constrained Delaunay triangulation of the sampled
    /// circles and a hexagonal lattice), for `qcmc` and multiply-connected registration.
    CircleDomain,
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// What to generate.
    #[arg(value_enum)]
    pub shape: Shape,
    /// Refinement level.
    #[arg(long, default_value_t = 3)]
    pub level: usize,
    /// The annulus's inner radius.
    #[arg(long, default_value_t = 0.4)]
    pub inner: f64,
    /// The circle domain's holes, `x,y,r` each, separated by `;`.
    #[arg(
        long,
        default_value = "-0.4,0,0.2;0.35,0.3,0.15",
        allow_hyphen_values = true
    )]
    pub holes: String,
    /// Output mesh (.obj, .ply, .stl, .off, .gltf, .glb).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// The most faces `generate` makes: about 2^25 (a few GB of mesh), checked from the
/// level before any work.
const MAX_FACES: f64 = 33_554_432.0;

/// About how many faces `shape` has at `level` (exact for the primitives; for the circle
/// domain the unit disk's area over an equilateral triangle of side `2^-(level+2)`).
fn faces_at(shape: Shape, level: usize) -> f64 {
    let grow = 4f64.powi(level.min(1000) as i32);
    match shape {
        Shape::Disk => 4.0 * grow,
        Shape::Sphere => 8.0 * grow,
        // 8 * 2^level sectors by 2^(level+1) rings, two triangles per cell.
        Shape::Annulus => 32.0 * grow,
        // (32 * 2^level)^2 cells, two triangles each.
        Shape::Square => 2048.0 * grow,
        Shape::Torus1 | Shape::Torus2 => 1280.0 * grow,
        Shape::CircleDomain => {
            let h = 0.25 * 0.5f64.powi(level.min(1000) as i32);
            std::f64::consts::PI / (3f64.sqrt() / 4.0 * h * h)
        }
    }
}

pub fn run(args: &GenerateArgs, quiet: bool) -> anyhow::Result<()> {
    super::mapping::check_output_format(&args.output)?;
    super::outputs::check(&[("-o", Some(&args.output))])?;
    let faces = faces_at(args.shape, args.level);
    if faces > MAX_FACES {
        let finest = (0..args.level.min(64))
            .take_while(|&l| faces_at(args.shape, l) <= MAX_FACES)
            .last()
            .unwrap_or(0);
        bail!(
            "--level {} would make about {faces:.3e} faces, more than {MAX_FACES:.0}: at most --level {finest} for this shape",
            args.level
        );
    }
    let mesh = if args.shape == Shape::CircleDomain {
        let h = 0.25 * 0.5f64.powi(args.level as i32);
        beltrami_remesh::circle_domain::circle_domain(&holes(&args.holes)?, h)?
    } else {
        Mesh::from_soup(&soup(args)?)?
    };
    io::write(&args.output, &mesh, &VertexAttributes::default())?;
    if !quiet {
        println!(
            "{}: {} vertices, {} faces",
            args.output.display(),
            mesh.vertex_count(),
            mesh.face_count()
        );
    }
    Ok(())
}

/// The polygon soup of a primitive shape (every shape but the circle domain).
fn soup(args: &GenerateArgs) -> anyhow::Result<PolygonSoup> {
    Ok(match args.shape {
        Shape::Disk => primitives::disk(args.level),
        Shape::Sphere => primitives::octahedral_sphere(args.level),
        Shape::Annulus => {
            if !(args.inner > 0.0 && args.inner < 1.0) {
                bail!("--inner must be in (0, 1), got {}", args.inner);
            }
            primitives::annulus(args.inner, 2 << args.level, 8 << args.level)
        }
        Shape::Square => primitives::centered_square(32 << args.level),
        Shape::Torus1 | Shape::Torus2 => {
            if args.level > 6 {
                bail!("--level {} is too fine for a torus (at most 6)", args.level);
            }
            let kind = if args.shape == Shape::Torus1 {
                ModifiedTorus::Phi1
            } else {
                ModifiedTorus::Phi2
            };
            primitives::modified_torus(kind, 40 << args.level, 16 << args.level)
        }
        Shape::CircleDomain => bail!("a circle domain is not a primitive soup"),
    })
}

/// The holes of `--holes`: `x,y,r` triples separated by `;`.
fn holes(text: &str) -> anyhow::Result<Vec<Hole>> {
    text.split(';')
        .filter(|part| !part.trim().is_empty())
        .map(|part| {
            let numbers: Vec<f64> = part
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| anyhow::anyhow!("--holes: `{part}`: {e}"))?;
            let [x, y, r] = numbers[..] else {
                bail!("--holes: `{part}` is not `x,y,r`");
            };
            Ok(Hole {
                center: num_complex::Complex64::new(x, y),
                radius: r,
            })
        })
        .collect()
}
