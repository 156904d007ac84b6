//! Command-line interface: argument parsing and one module per command.

mod atlas;
mod batch;
mod bench;
mod cut;
mod distortion;
mod generate;
mod histogram;
mod info;
mod interrupt;
mod load;
mod mapping;
mod outputs;
mod param;
mod picture;
mod pins;
mod qc;
mod reference;
mod register;
mod remesh;
mod render;
mod solvers;
mod view;

use clap::{Parser, Subcommand};

/// Quasiconformal maps of triangle and quad meshes.
#[derive(Debug, Parser)]
#[command(name = "beltrami", version, about, long_about = None)]
pub struct Cli {
    /// Print nothing but results and errors.
    #[arg(short, long, global = true)]
    pub quiet: bool,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Load a mesh, validate it and print its size, topology and geometry.
    Info(info::InfoArgs),
    /// Measure the distortion of a map given as a mesh: per-face Beltrami coefficients,
    /// their statistics and the flipped faces.
    Distortion(distortion::DistortionArgs),
    /// Parameterize a mesh with a registered solver (tutte, harmonic, lscm) and write
    /// the map as texture coordinates.
    Param(param::ParamArgs),
    /// A quasiconformal map with a prescribed Beltrami coefficient or the most conformal
    /// one (lsqc, beltrami-flow) onto the plane, a disk, an annulus or the sphere.
    Qc(qc::QcArgs),
    /// Map one mesh onto another of the same topology (any genus, any number of boundary loops),
    /// bijectively and as conformally as the constraints allow, with landmarks, feature
    /// curves and fields matched on both meshes: an initial bijection, then the Beltrami
    /// flow on the target.
    Register(register::RegisterArgs),
    /// Write a generated mesh: the disk, sphere, annulus and square of the paper
    /// reproductions.
    Generate(generate::GenerateArgs),
    /// List the registered solvers and what each accepts.
    Solvers(solvers::SolversArgs),
    /// Time the library on generated and given meshes and print a table.
    Bench(bench::BenchArgs),
    /// Draw a mesh or a map as PNG: the parameter domain, the surface in 3D or both side
    /// by side, colored by |mu| or with a checkerboard of the map.
    Render(render::RenderArgs),
    /// A self-contained HTML page of a mesh or a map (WebGL; turn by dragging).
    View(view::ViewArgs),
    /// Draw the histogram of |mu| of a map as PNG (share of faces or of area).
    Histogram(histogram::HistogramArgs),
    /// Cut a surface of genus >= 1 (or with several boundary loops) into a disk along a
    /// greedy shortest system of loops and write it as OBJ.
    Cut(cut::CutArgs),
    /// Remesh a surface with the asked edge length: parameterize it, triangulate the
    /// parameter domain with constrained Delaunay refinement, lift back.
    Remesh(remesh::RemeshArgs),
    /// A texture atlas of any triangle mesh (closed or open, any genus): conformal charts
    /// with cone singularities, cut along trees through the cones, packed into the unit
    /// square; written with per-corner texture coordinates.
    Atlas(atlas::AtlasArgs),
    /// Run many param, qc, register and remesh jobs (one JSON object per line) in
    /// parallel, one JSON report line per job; `--resume` skips finished outputs.
    Batch(batch::BatchArgs),
    /// Print the command-line reference (docs/reference.md) as Markdown.
    #[command(hide = true)]
    Reference(reference::ReferenceArgs),
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Info(args) => info::run(&args, cli.quiet),
        Command::Distortion(args) => distortion::run(&args, cli.quiet),
        Command::Param(args) => param::run(&args, cli.quiet),
        Command::Qc(args) => qc::run(&args, cli.quiet),
        Command::Register(args) => register::run(&args, cli.quiet),
        Command::Generate(args) => generate::run(&args, cli.quiet),
        Command::Solvers(args) => solvers::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Cut(args) => cut::run(&args, cli.quiet),
        Command::Render(args) => render::run(&args, cli.quiet),
        Command::View(args) => view::run(&args, cli.quiet),
        Command::Histogram(args) => histogram::run(&args, cli.quiet),
        Command::Remesh(args) => remesh::run(&args, cli.quiet),
        Command::Atlas(args) => atlas::run(&args, cli.quiet),
        Command::Batch(args) => batch::run(&args, cli.quiet),
        Command::Reference(args) => reference::run(&args),
    }
}
