//! `beltrami bench`: timings printed as tables (the figures go to docs/benchmarks.md).

#[cfg(feature = "cg-bench")]
mod cg;
mod fem;
mod flow;
mod load;
mod ordering;
mod qcmc;
mod render;
mod spatial;

use anyhow::Context;
use clap::{Args, Subcommand};
use std::time::Instant;

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: BenchKind,
}

#[derive(Debug, Subcommand)]
pub enum BenchKind {
    /// OBJ parse time against halfedge build time, on generated grids and given meshes.
    Load(load::LoadArgs),
    /// Assembly, symbolic and numeric factorization and solve of the Laplacian and of
    /// the LSCM system (complex N form and real 2N form), against faer on the same
    /// matrices.
    Fem(fem::FemArgs),
    /// The flow's preconditioned conjugate gradients against faer's, on the systems of
    /// flows and registrations (feature `cg-bench`).
    #[cfg(feature = "cg-bench")]
    Cg(cg::CgArgs),
    /// Fill-reducing orders (AMD, nested dissection by level sets and by multilevel
    /// separators, METIS) on meshes' vertex graphs: order time, factor cost, one
    /// numeric factorization.
    Ordering(ordering::OrderingArgs),
    /// The discrete Beltrami flow against the tables of Wong-Zhao 2014, and the cost of
    /// one flow step on meshes of about 100K faces.
    Flow(flow::FlowArgs),
    /// The conformal circle-domain map (qcmc) of multiply-connected meshes, stage by
    /// stage.
    Qcmc(qcmc::QcmcArgs),
    /// Pictures (scene measure, uv and 3D rasterization, PNG encoding) of generated
    /// grids of up to ~1M triangles.
    Render(render::RenderArgs),
    /// Building the surface index, locating random points near a target surface, and
    /// one flow step (every vertex re-located, with and without hints, or walked).
    Spatial(spatial::SpatialArgs),
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    match &args.what {
        BenchKind::Load(a) => load::run(a),
        BenchKind::Fem(a) => fem::run(a),
        BenchKind::Flow(a) => flow::run(a),
        BenchKind::Ordering(a) => ordering::run(a),
        #[cfg(feature = "cg-bench")]
        BenchKind::Cg(a) => cg::run(a),
        BenchKind::Qcmc(a) => qcmc::run(a),
        BenchKind::Render(a) => render::run(a),
        BenchKind::Spatial(a) => spatial::run(a),
    }
}

/// The fastest of `repeat` runs of `f`, in seconds, and its last result.
fn fastest<T>(repeat: usize, mut f: impl FnMut() -> anyhow::Result<T>) -> anyhow::Result<(f64, T)> {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        let value = f()?;
        best = best.min(start.elapsed().as_secs_f64());
        out = Some(value);
    }
    Ok((best, out.context("at least one run")?))
}
