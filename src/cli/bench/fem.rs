//! `beltrami bench fem`: the cost of the finite-element layer against faer alone.
//!
//! For each disk mesh it times
//! - assembly: elements (frames, gradients), the `D_zbar` operator, the stiffness
//!   pattern and its values;
//! - LSCM (`min sum_T A_T |f_zbar|^2`, two pinned vertices) through
//!   `LeastSquaresSolver`, in the complex N form and the real 2N form: the symbolic
//!   phase (product patterns + symbolic Cholesky) and the numeric phase (refilled
//!   products + numeric Cholesky + solve);
//! - the same reduced normal matrices, assembled element by element, factored by faer
//!   directly (`SymbolicLlt`, `Llt::try_new_with_symbolic`, solve): the baseline the layer
//!   is compared with;
//! - the Dirichlet Laplacian (interior block of the stiffness matrix) through
//!   `solve_spd` against faer's own phases.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use beltrami_fem::operators::{
    ComplexDerivatives, ElementMatrices, complex_derivatives, real_block_form,
};
use beltrami_fem::{
    DofConstraints, DofMap, Elements, Frame, LeastSquaresSolver, assembly::Pattern,
};
use beltrami_mesh::primitives::{Cells, grid};
use beltrami_mesh::subdivision::subdivide;
use beltrami_mesh::{BuildOptions, Mesh, VertexId, io};
use beltrami_sparse::SolveOptions;
use beltrami_sparse::solve_spd;
use clap::Args;
use faer::prelude::Solve;
use faer::sparse::SparseColMat;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::{Mat, Par, Side};
use num_complex::Complex64;

/// The meshes a benchmark runs on: generated grids and given files.
#[derive(Debug, Args)]
pub struct MeshCases {
    /// Sizes of the generated triangle grids (unit square), in triangles.
    #[arg(long, value_delimiter = ',', default_value = "100000,400000,1000000")]
    pub triangles: Vec<usize>,
    /// Meshes to time as well; `FILE:k` subdivides the mesh 1-to-4 `k` times first.
    #[arg(long = "mesh")]
    pub meshes: Vec<String>,
}

#[derive(Debug, Args)]
pub struct FemArgs {
    #[command(flatten)]
    pub cases: MeshCases,
    /// Thread counts to time (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
}

/// Seconds since `start`.
fn secs(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// Two boundary vertices far apart: the first of the longest loop and the loop vertex
/// farthest from it.
fn far_boundary_pair(mesh: &Mesh) -> anyhow::Result<(VertexId, VertexId)> {
    let loops = mesh.boundary_loop_list();
    let Some(longest) = loops.iter().max_by_key(|l| l.vertices.len()) else {
        bail!("the benchmark needs a mesh with a boundary");
    };
    let a = longest.vertices[0];
    let pa = mesh.position(a);
    let b = longest
        .vertices
        .iter()
        .copied()
        .max_by(|&u, &v| {
            let (du, dv) = (
                (mesh.position(u) - pa).norm(),
                (mesh.position(v) - pa).norm(),
            );
            du.total_cmp(&dv)
        })
        .context("empty boundary loop")?;
    Ok((a, b))
}

/// The reduced LSCM normal matrix `sum_q w_q conj(a_qi) a_qj` over free vertices,
/// assembled element by element (`a_qi` the `D_zbar` coefficients).
fn lscm_normal_matrix(
    elements: &Elements,
    slot: &[usize],
    free: usize,
) -> anyhow::Result<SparseColMat<usize, Complex64>> {
    let mut positions = Vec::new();
    let mut values = Vec::new();
    for q in elements.points() {
        let nodes = elements.nodes(q.face);
        for (i, vi) in nodes.iter().enumerate() {
            for (j, vj) in nodes.iter().enumerate() {
                let (si, sj) = (slot[vi.idx()], slot[vj.idx()]);
                if si == usize::MAX || sj == usize::MAX {
                    continue;
                }
                let ai = Complex64::new(0.5 * q.grad[i].x, 0.5 * q.grad[i].y);
                let aj = Complex64::new(0.5 * q.grad[j].x, 0.5 * q.grad[j].y);
                positions.push((si, sj));
                values.push(ai.conj() * aj * q.weight);
            }
        }
    }
    Ok(Pattern::new(free, free, &positions)?.assemble(&values)?)
}

/// faer alone on an SPD matrix: (symbolic s, numeric s, solve s).
fn faer_phases<T>(matrix: &SparseColMat<usize, T>) -> anyhow::Result<(f64, f64, f64)>
where
    T: faer::traits::ComplexField,
{
    let t = Instant::now();
    let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower)?;
    let sym = secs(t);
    let t = Instant::now();
    let llt = Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower)?;
    let num = secs(t);
    let rhs = Mat::<T>::from_fn(matrix.nrows(), 1, |i, _| T::from_f64_impl(i as f64));
    let t = Instant::now();
    let x = llt.solve(&rhs);
    let solve = secs(t);
    std::hint::black_box(x);
    Ok((sym, num, solve))
}

/// Meshes to time: generated grids, then files (optionally subdivided).
pub fn cases(args: &MeshCases) -> anyhow::Result<Vec<(String, Mesh)>> {
    let mut out = Vec::new();
    for &t in &args.triangles {
        let n = ((t as f64 / 2.0).sqrt().round() as usize).max(1);
        out.push((
            format!("grid {n}x{n}"),
            Mesh::from_soup(&grid(n, n, Cells::Triangles))?,
        ));
    }
    for spec in &args.meshes {
        let (file, levels) = match spec.rsplit_once(':') {
            Some((f, k)) if k.chars().all(|c| c.is_ascii_digit()) => (f, k.parse::<usize>()?),
            _ => (spec.as_str(), 0),
        };
        let path = PathBuf::from(file);
        let mut mesh = io::read(&path, &BuildOptions::default())?.mesh;
        for _ in 0..levels {
            mesh = Mesh::from_soup(&subdivide(&mesh))?;
        }
        let name = path
            .file_name()
            .map_or(file.into(), |n| n.to_string_lossy().into_owned());
        out.push((
            if levels > 0 {
                format!("{name} /{levels}")
            } else {
                name
            },
            mesh,
        ));
    }
    Ok(out)
}

pub fn run(args: &FemArgs) -> anyhow::Result<()> {
    println!("Assembly (1 thread):");
    println!();
    println!(
        "| mesh | faces | vertices | elements s | D_zbar s | stiffness pattern s | stiffness values s |"
    );
    println!("|---|---|---|---|---|---|---|");
    let meshes = cases(&args.cases)?;
    for (name, mesh) in &meshes {
        print_assembly_row(name, mesh)?;
    }
    println!();
    println!("Solves (symbolic / numeric / solve, seconds):");
    println!();
    println!(
        "| mesh | system | unknowns | threads | ours: symbolic | ours: numeric + solve | faer: symbolic | faer: numeric | faer: solve |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, mesh) in &meshes {
        let systems = Systems::new(mesh)?;
        for &threads in &args.threads {
            systems.print_solve_rows(name, threads)?;
        }
        faer::set_global_parallelism(Par::Seq);
    }
    Ok(())
}

/// Times the assembly of one mesh (elements, `D_zbar`, the stiffness pattern and its
/// values) and prints its row of the assembly table.
fn print_assembly_row(name: &str, mesh: &Mesh) -> anyhow::Result<()> {
    let t = Instant::now();
    let elements = Elements::new(mesh, Frame::Face)?;
    let e = secs(t);
    let t = Instant::now();
    let d = complex_derivatives(mesh, &elements)?;
    let dz = secs(t);
    std::hint::black_box(d);
    let t = Instant::now();
    let matrices = ElementMatrices::new(mesh.vertex_count(), &elements)?;
    let p = secs(t);
    let t = Instant::now();
    let k = matrices.stiffness(&elements)?;
    let v = secs(t);
    std::hint::black_box(k);
    println!(
        "| {name} | {} | {} | {e:.3} | {dz:.3} | {p:.3} | {v:.3} |",
        mesh.face_count(),
        mesh.vertex_count()
    );
    Ok(())
}

/// The systems of one mesh whose solves are timed: LSCM with two pinned vertices (the
/// `D_zbar` operator and the reduced normal matrix, complex and real), and the
/// Dirichlet Laplacian.
struct Systems {
    /// The mesh's vertex count.
    n: usize,
    /// The two pinned vertices of LSCM.
    pins: DofConstraints,
    /// The unknowns of complex LSCM (vertices but the pinned ones).
    free: usize,
    /// `D_z`, `D_zbar` and the quadrature weights.
    d: ComplexDerivatives,
    /// The reduced LSCM normal matrix, complex.
    normal_c: SparseColMat<usize, Complex64>,
    /// The same in the real 2N form.
    normal_r: SparseColMat<usize, f64>,
    /// `D_zbar` in the real 2N form.
    real_dzbar: SparseColMat<usize, f64>,
    /// The quadrature weights, each twice (real and imaginary rows).
    real_weights: Vec<f64>,
    /// The Dirichlet Laplacian ([`dirichlet_laplacian`]).
    laplacian: SparseColMat<usize, f64>,
    /// Its right-hand side.
    rhs: Mat<f64>,
    /// Its unknowns (the interior vertices).
    ni: usize,
}

impl Systems {
    /// The systems of `mesh`, the LSCM pins at two boundary vertices far apart.
    fn new(mesh: &Mesh) -> anyhow::Result<Self> {
        let elements = Elements::new(mesh, Frame::Face)?;
        let d = complex_derivatives(mesh, &elements)?;
        let (a, b) = far_boundary_pair(mesh)?;
        let mut pins = DofConstraints::new();
        pins.fix(a, Complex64::new(0.0, 0.0))
            .fix(b, Complex64::new(1.0, 0.0));
        let n = mesh.vertex_count();
        let mut slot = vec![usize::MAX; n];
        let mut free = 0;
        for v in mesh.vertices() {
            if v != a && v != b {
                slot[v.idx()] = free;
                free += 1;
            }
        }
        let normal_c = lscm_normal_matrix(&elements, &slot, free)?;
        let normal_r = real_block_form(&normal_c)?;
        let real_dzbar = real_block_form(&d.dzbar)?;
        let real_weights: Vec<f64> = d.weights.iter().flat_map(|&w| [w, w]).collect();
        let (laplacian, rhs, ni) = dirichlet_laplacian(mesh, &elements)?;
        Ok(Self {
            n,
            pins,
            free,
            d,
            normal_c,
            normal_r,
            real_dzbar,
            real_weights,
            laplacian,
            rhs,
            ni,
        })
    }

    /// Times the solves on `threads` threads, ours against faer's phases, and prints
    /// their rows: LSCM complex N, LSCM real 2N, the Dirichlet Laplacian.
    fn print_solve_rows(&self, name: &str, threads: usize) -> anyhow::Result<()> {
        let Self { n, free, ni, .. } = *self;
        let (d, real_dzbar) = (&self.d, &self.real_dzbar);
        let options = SolveOptions {
            threads,
            ..SolveOptions::default()
        };
        faer::set_global_parallelism(options.par());

        let dofs = DofMap::<Complex64>::complex(n, &self.pins)?;
        let t = Instant::now();
        let mut solver = LeastSquaresSolver::new(d.dzbar.symbolic(), &dofs, options)?;
        let sym = secs(t);
        let zero = vec![Complex64::new(0.0, 0.0); d.dzbar.nrows()];
        let t = Instant::now();
        std::hint::black_box(solver.solve(d.dzbar.as_ref(), Some(&d.weights), &zero)?);
        let num = secs(t);
        drop(solver);
        let (fs, fnum, fsol) = faer_phases(&self.normal_c)?;
        println!(
            "| {name} | LSCM complex N | {free} | {threads} | {sym:.3} | {num:.3} | {fs:.3} | {fnum:.3} | {fsol:.3} |"
        );

        let dofs = DofMap::<f64>::real(n, &self.pins)?;
        let t = Instant::now();
        let mut solver = LeastSquaresSolver::new(real_dzbar.symbolic(), &dofs, options)?;
        let sym = secs(t);
        let zero = vec![0.0; real_dzbar.nrows()];
        let t = Instant::now();
        std::hint::black_box(solver.solve(real_dzbar.as_ref(), Some(&self.real_weights), &zero)?);
        let num = secs(t);
        drop(solver);
        let (fs, fnum, fsol) = faer_phases(&self.normal_r)?;
        println!(
            "| {name} | LSCM real 2N | {} | {threads} | {sym:.3} | {num:.3} | {fs:.3} | {fnum:.3} | {fsol:.3} |",
            2 * free
        );

        let t = Instant::now();
        std::hint::black_box(solve_spd(
            self.laplacian.as_ref(),
            self.rhs.as_ref(),
            options,
        )?);
        let ours = secs(t);
        let (fs, fnum, fsol) = faer_phases(&self.laplacian)?;
        println!(
            "| {name} | Laplacian (Dirichlet) | {ni} | {threads} | {ours:.3} (whole) | - | {fs:.3} | {fnum:.3} | {fsol:.3} |"
        );
        Ok(())
    }
}

/// The Dirichlet Laplacian: the interior block of the stiffness matrix, the boundary
/// held at `x`; with its right-hand side and its size (the interior vertices).
fn dirichlet_laplacian(
    mesh: &Mesh,
    elements: &Elements,
) -> anyhow::Result<(SparseColMat<usize, f64>, Mat<f64>, usize)> {
    let n = mesh.vertex_count();
    let k = ElementMatrices::new(n, elements)?.stiffness(elements)?;
    let mut interior = vec![usize::MAX; n];
    let mut ni = 0;
    for v in mesh.vertices() {
        if !mesh.is_boundary_vertex(v) {
            interior[v.idx()] = ni;
            ni += 1;
        }
    }
    let mut positions = Vec::new();
    let mut values = Vec::new();
    let mut rhs = Mat::<f64>::zeros(ni, 1);
    for c in 0..n {
        for (&r, &val) in k.row_idx_of_col_raw(c).iter().zip(k.val_of_col(c)) {
            match (interior[r], interior[c]) {
                (ir, usize::MAX) if ir != usize::MAX => {
                    rhs[(ir, 0)] -= val * mesh.positions()[c].x;
                }
                (ir, ic) if ir != usize::MAX => {
                    positions.push((ir, ic));
                    values.push(val);
                }
                _ => {}
            }
        }
    }
    let laplacian = Pattern::new(ni, ni, &positions)?.assemble(&values)?;
    Ok((laplacian, rhs, ni))
}
