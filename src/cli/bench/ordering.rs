//! `beltrami bench ordering`: the fill-reducing orders of `beltrami-sparse` against
//! METIS 5's nested dissection (`METIS_NodeND`, vendored through `metis-sys`), on the
//! vertex graphs of meshes: the time to order, the exact multiply-subtract count of the
//! Cholesky factor in that order (over `n^(3/2)`), and the time of one numeric
//! factorization of a matrix on that graph (the graph Laplacian plus the identity) and
//! of one solve; for the dissections, the same factorization and solve with the first
//! split's two sides at once on two cores (`SpdSolver::with_split_order`).
//!
//! METIS is compiled only with the feature `metis-bench` (its C sources are vendored by
//! `metis-sys`); without it the METIS rows are left out.

use beltrami_fem::vertex_graph::vertex_graph_pattern;
use beltrami_mesh::Mesh;
use beltrami_sparse::{
    SolveOptions, SpdSolver, SplitOrder, amd_order, factor_count, first_split_order,
    nested_dissection_split,
};
use clap::Args;
use faer::Mat;
use faer::sparse::{SparseColMat, SymbolicSparseColMatRef};

use super::fastest;
use super::fem::{MeshCases, cases};

#[derive(Debug, Args)]
pub struct OrderingArgs {
    #[command(flatten)]
    pub cases: MeshCases,
    /// Rounds per order (the figures are the fastest round).
    #[arg(long, default_value_t = 3)]
    pub rounds: usize,
}

#[cfg(feature = "metis-bench")]
/// METIS 5's nested dissection of the symmetric pattern whose lower triangle is
/// `lower`: `order[k]` is the row eliminated `k`-th.
fn metis_order(lower: SymbolicSparseColMatRef<'_, usize>) -> anyhow::Result<Vec<usize>> {
    let n = lower.nrows();
    let mut neighbours: Vec<Vec<i32>> = vec![Vec::new(); n];
    for j in 0..n {
        for &i in lower.row_idx_of_col_raw(j) {
            if i != j {
                neighbours[i].push(i32::try_from(j)?);
                neighbours[j].push(i32::try_from(i)?);
            }
        }
    }
    let mut xadj = Vec::with_capacity(n + 1);
    let mut adjncy = Vec::new();
    xadj.push(0i32);
    for list in &neighbours {
        adjncy.extend_from_slice(list);
        xadj.push(i32::try_from(adjncy.len())?);
    }
    let mut nvtxs = i32::try_from(n)?;
    let (mut perm, mut iperm) = (vec![0i32; n], vec![0i32; n]);
    // SAFETY: the arrays describe a valid CSR graph of `nvtxs` vertices (xadj has
    // nvtxs + 1 entries, adjncy xadj[nvtxs] in range) and perm / iperm hold nvtxs
    // entries; null weights and options select METIS's defaults.
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        anyhow::bail!("METIS_NodeND failed with status {status}");
    }
    Ok(perm.into_iter().map(|k| k as usize).collect())
}

/// The graph Laplacian of `lower`'s pattern plus the identity: positive definite, with
/// every entry of the pattern.
fn laplacian_plus_identity(
    lower: SymbolicSparseColMatRef<'_, usize>,
) -> anyhow::Result<SparseColMat<usize, f64>> {
    let n = lower.nrows();
    let mut degree = vec![1.0; n];
    for j in 0..n {
        for &i in lower.row_idx_of_col_raw(j) {
            if i != j {
                degree[i] += 1.0;
                degree[j] += 1.0;
            }
        }
    }
    let values: Vec<f64> = (0..n)
        .flat_map(|j| {
            let degree = &degree;
            lower
                .row_idx_of_col_raw(j)
                .iter()
                .map(move |&i| if i == j { degree[j] } else { -1.0 })
        })
        .collect();
    Ok(SparseColMat::new(lower.to_owned()?, values))
}

pub fn run(args: &OrderingArgs) -> anyhow::Result<()> {
    println!(
        "| mesh | n | order | order s | multiply-subtracts / n^1.5 | factorization s | solve s | two sides: factorization s | two sides: solve s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, mesh) in cases(&args.cases)? {
        row_of(&name, &mesh, args.rounds)?;
    }
    Ok(())
}

/// METIS's row when the benchmark is built with the feature `metis-bench`.
fn metis() -> Option<(&'static str, Orderer)> {
    #[cfg(feature = "metis-bench")]
    return Some(("METIS", |p| Ok(whole(metis_order(p)?))));
    #[cfg(not(feature = "metis-bench"))]
    None
}

/// The fastest numeric factorization of `matrix` by `solver` and the fastest solve of
/// `rhs` after it, in seconds.
fn factor_and_solve(
    mut solver: SpdSolver<f64>,
    matrix: &SparseColMat<usize, f64>,
    rhs: &Mat<f64>,
    rounds: usize,
) -> anyhow::Result<(f64, f64)> {
    let (factor_s, ()) = fastest(rounds, || Ok(solver.factorize(matrix.as_ref())?))?;
    let (solve_s, _) = fastest(rounds, || {
        let mut x = rhs.clone();
        solver.solve_in_place(x.as_mut())?;
        Ok(x)
    })?;
    Ok((factor_s, solve_s))
}

type Orderer = fn(SymbolicSparseColMatRef<'_, usize>) -> anyhow::Result<SplitOrder>;

fn whole(order: Vec<usize>) -> SplitOrder {
    SplitOrder { order, sides: None }
}

fn row_of(name: &str, mesh: &Mesh, rounds: usize) -> anyhow::Result<()> {
    let graph = vertex_graph_pattern(mesh);
    let lower = graph.as_ref();
    let n = lower.nrows();
    let matrix = laplacian_plus_identity(lower)?;
    let ours: [(&str, Orderer); 3] = [
        ("AMD", |p| Ok(whole(amd_order(p)?))),
        ("level sets", |p| Ok(nested_dissection_split(p)?)),
        ("multilevel", |p| Ok(first_split_order(p)?)),
    ];
    let orders = ours.into_iter().chain(metis());
    let rhs = Mat::<f64>::from_fn(n, 1, |i, _| ((i % 17) as f64) - 8.0);
    for (label, order_of) in orders {
        let (order_s, split) = fastest(rounds, || order_of(lower))?;
        let count = factor_count(lower, &split.order)?.multiply_subtracts / (n as f64).powf(1.5);
        let options = SolveOptions::default();
        let whole = SpdSolver::<f64>::with_order(lower, &split.order, options)?;
        let (factor_s, solve_s) = factor_and_solve(whole, &matrix, &rhs, rounds)?;
        let sides = match split.sides {
            Some(_) => {
                let sides = SpdSolver::<f64>::with_split_order(lower, &split, options)?;
                let (factor_s, solve_s) = factor_and_solve(sides, &matrix, &rhs, rounds)?;
                format!("{factor_s:.3} | {solve_s:.4}")
            }
            None => "- | -".to_owned(),
        };
        println!(
            "| {name} | {n} | {label} | {order_s:.3} | {count:.2} | {factor_s:.3} | {solve_s:.4} | {sides} |"
        );
    }
    Ok(())
}
