//! "A scene pays only for the components it names": one Newton iteration's
//! assembly (ΔF from the grid increment, eq. 7; the constitutive update;
//! the internal force, eq. 23; the previously converged tangent, eqs.
//! A.3–A.6; the stiffness, eq. 21) of the plainest scene — standard MPM on
//! a regular grid, Hencky elasticity, previously converged formulation, no
//! locking, no domain update — timed two ways on the same points and
//! increment, in 2D and 3D, on 1 and 2 threads:
//!
//! - **generic**: [`ImplicitSolver::assemble_at`], the framework's path
//!   on an iteration Newton expects to correct (the update computes the
//!   tangents in the same pass, and the node pass the internal force with
//!   the stiffness); the `in_stages_*` groups time
//!   [`ImplicitSolver::assemble_in_stages_at`], the stages one by one as
//!   on an iteration that was expected to converge but did not;
//! - **specialised**: [`Specialised::assemble`], a kernel written for
//!   exactly that scene (one fused pass per point with no `Option`
//!   responses, no locking hook, no formulation dispatch; one fused pass
//!   per node for force and stiffness with a scatter map built once).
//!
//! Before timing, the set-up checks that both compute the same internal
//! force, stiffness values (in the generic solver's CSC pattern) and
//! normalised residual to 1e-12 relative, and that each is bit-identical on
//! 1 and 2 threads.
//!
//! The `stages_*` groups (one thread) say where the difference comes from:
//! the generic solver's public stages (`update_material_points`,
//! `assemble_internal_force`, `update_tangents`, `assemble_stiffness`,
//! and `update_material_points_with_tangents`, which fuses the first and
//! third)
//! against the kernel's two passes, and between them variants of the
//! kernel that add back one thing the generic path does or did: the
//! excessive-increment test (`checked_points_pass`), responses stored
//! with the tangents in a second pass (`two_sweep_points_pass`; as
//! `Option<Response>` and with the test, `stored_points_pass`), and full
//! 9 × 9 weighted tangents, which the generic path stored until it kept
//! the D⁴ components in use (`checked_full_points_pass`, and the node pass
//! reading them, `full_tensor_nodes_pass`). Each variant is checked to give
//! the kernel's result bit for bit.
//!
//! Run: `cargo bench -p mpm-solver --bench specialised`; numbers are
//! recorded in `docs/src/benchmarks/zero_cost.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group,
    criterion_main, measurement::WallTime,
};
use mpm_basis::{BasisFunction, LinearMpm, Stencil};
use mpm_constitutive::tensor::{embed, idx};
use mpm_constitutive::{
    ConsistentTangent, ConstitutiveError, HenckyElastic, MaterialState, PreviouslyConvergedTangent,
    Response, Tensor4, update,
};
use mpm_mesh::RegularGrid;
use mpm_solver::{
    ImplicitBuilder, ImplicitSolver, MaterialPoints, NewtonOptions, NoLocking, NoUpdate,
    NodalConstraints, Parts, PreviouslyConverged,
};
use nalgebra::{Matrix3, SMatrix, SVector};
use rayon::prelude::*;

type Solver<const D: usize> = ImplicitSolver<
    D,
    Parts<LinearMpm, PreviouslyConverged, HenckyElastic, NoLocking, NoUpdate, NodalConstraints<D>>,
>;
type Points<const D: usize> = MaterialPoints<D, (), ()>;

/// Marker for "none" in the index maps.
const NONE: u32 = u32::MAX;
/// Marker for "no entry" in the kernel's scatter map.
const NO_OFFSET: u8 = u8::MAX;

/// The load factor at the end of the step (the step runs from 0 to 1).
const LAMBDA1: f64 = 1.0;

/// Young's modulus and Poisson's ratio of the body.
const YOUNG: f64 = 1e6;
const POISSON: f64 = 0.3;

/// The scene of `benches/assembly.rs`: a box of `cells` unit cells filled
/// with 2^D points per cell, base fixed, gravity, on a grid that fits the
/// box; the generic solver with a prepared step and a free-dof increment.
struct Scene<const D: usize> {
    grid: RegularGrid<D>,
    points: Points<D>,
    solver: Solver<D>,
    du: Vec<f64>,
}

fn scene<const D: usize>(cells: [usize; D]) -> Scene<D> {
    let h = 1.0;
    let grid = RegularGrid::new(
        SVector::<f64, D>::zeros(),
        SVector::<f64, D>::from_element(h),
        cells,
    )
    .unwrap();
    let total: usize = cells.iter().map(|c| 2 * c).product();
    let pos: Vec<SVector<f64, D>> = (0..total)
        .map(|flat| {
            let mut rest = flat;
            SVector::<f64, D>::from_fn(|i, _| {
                let n1 = 2 * cells[i];
                let k = rest % n1;
                rest /= n1;
                (k as f64 + 0.5) * h / 2.0
            })
        })
        .collect();
    let mut points = MaterialPoints::new(
        pos,
        vec![(h / 2.0).powi(D as i32); total],
        1000.0,
        vec![(); total],
    )
    .unwrap();
    let mut g = SVector::<f64, D>::zeros();
    g[D - 1] = -10.0;
    points.set_gravity(g);
    let mut constraints = NodalConstraints::<D>::new(grid.node_count());
    let base: Vec<usize> = (0..grid.node_count())
        .filter(|&n| is_base(&grid, n))
        .collect();
    for i in 0..D {
        constraints.fix(base.iter().copied(), i);
    }
    let law = HenckyElastic::new(YOUNG, POISSON).unwrap();
    let mut solver = ImplicitBuilder::new(LinearMpm, grid.clone(), law)
        .constraints(constraints)
        .build();
    let n = solver.prepare_step(&points, 0.0, LAMBDA1).unwrap();
    let du: Vec<f64> = (0..n).map(|k| 1e-3 * ((k * 31 + 7) as f64).sin()).collect();
    // One assembly so that the solver exposes its stiffness pattern.
    solver.assemble_at(&points, &du).unwrap();
    Scene {
        grid,
        points,
        solver,
        du,
    }
}

/// The scene's only Dirichlet condition: nodes on the base are fixed in
/// every component.
fn is_base<const D: usize>(grid: &RegularGrid<D>, node: usize) -> bool {
    grid.node_position(node).unwrap()[D - 1] <= 0.0
}

/// One Newton iteration's assembly written for exactly this scene: linear
/// MPM stencils of 2^D nodes, Hencky elasticity without history, the
/// previously converged formulation (P̃ and the volume of the start of the
/// step, gradients never mapped), no locking, and Dirichlet conditions that
/// fix all components of a node at zero.
///
/// Two passes per iteration:
/// 1. per point (parallel): ΔF (eq. 7), the update, the weighted P̃ and
///    the weighted tangent restricted to the D² × D² components in use;
///    nothing else is stored;
/// 2. per active node (parallel; each node owns its D columns of the CSC
///    values and its D internal-force entries, sums run over the node's
///    points in ascending order, so the result is the same for any
///    number of threads): internal force and stiffness block column, the
///    CSC offsets read from a map built once.
struct Specialised<const D: usize> {
    law: HenckyElastic,
    /// Free dofs.
    n_free: usize,
    /// Basis gradient of slot `p * NV + a`.
    grads: Vec<SVector<f64, D>>,
    /// Per slot `p * NV + a` and component: the index of the node's
    /// increment in `du_pad` (its free dof, or `n_free`, a zero).
    dof: Vec<[u32; D]>,
    /// CSR over active nodes of the (point, slot) pairs, points ascending.
    adj_ptr: Vec<usize>,
    adj: Vec<(u32, u32)>,
    /// Whether an active node is free (all components) or fixed (none).
    free: Vec<bool>,
    /// Start of each active node's block of columns in the CSC values
    /// (`n_active + 1`).
    block_ptr: Vec<usize>,
    /// Entries per column of each free node's block.
    col_len: Vec<usize>,
    /// `((p * NV + b) * NV + a)`: position of row dof `(v_a, 0)` in column
    /// `(w_b, 0)`, which is its offset in the block of node `w_b`; row
    /// `(v_a, i)` of column `(w_b, k)` is at `+ k * col_len + i`.
    /// [`NO_OFFSET`] if `v_a` or `w_b` is fixed. A column of a linear MPM
    /// stencil has at most D·3^D ≤ 81 rows, so a byte holds it: the map
    /// streams a quarter of what `u32` offsets would.
    offset: Vec<u8>,
    /// Free index of each active dof, or [`NONE`].
    free_of_dof: Vec<u32>,
    /// External force at each active dof (gravity), as the framework's.
    f_ext: Vec<f64>,
    // Per-iteration buffers.
    du_pad: Vec<f64>,
    stress_w: Vec<SMatrix<f64, D, D>>,
    tangent_w: Vec<Restricted<D>>,
    f_int: Vec<f64>,
    values: Vec<f64>,
}

impl<const D: usize> Specialised<D> {
    /// Nodes per point.
    const NV: usize = 1 << D;

    /// Builds the kernel's arrays for `points` on `grid`: stencils, node
    /// numbering, adjacency and the scatter map into the CSC pattern
    /// `(col_ptr, row_idx)` of the generic solver.
    fn new(
        grid: &RegularGrid<D>,
        points: &Points<D>,
        n_free: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
    ) -> Self {
        let nv = Self::NV;
        let n = points.len();
        // Stencils, in mesh numbering first.
        let mut stencil = Stencil::<D>::with_capacity(nv);
        let mut mesh_nodes = Vec::with_capacity(n * nv);
        let mut basis_values = Vec::with_capacity(n * nv);
        let mut grads = Vec::with_capacity(n * nv);
        for x in &points.position {
            LinearMpm.evaluate(grid, x, &(), &mut stencil).unwrap();
            assert_eq!(stencil.len(), nv);
            mesh_nodes.extend_from_slice(&stencil.nodes);
            basis_values.extend_from_slice(&stencil.values);
            grads.extend_from_slice(&stencil.gradients);
        }
        // Active nodes ascending in mesh id; free dofs ascending in D v + i.
        let mut active_of_mesh = vec![NONE; grid.node_count()];
        for &v in &mesh_nodes {
            active_of_mesh[v] = 0;
        }
        let mut active = Vec::new();
        for (mesh, slot) in active_of_mesh.iter_mut().enumerate() {
            if *slot != NONE {
                *slot = active.len() as u32;
                active.push(mesh);
            }
        }
        let nodes: Vec<usize> = mesh_nodes
            .iter()
            .map(|&v| active_of_mesh[v] as usize)
            .collect();
        let n_active = active.len();
        let free: Vec<bool> = active.iter().map(|&m| !is_base(grid, m)).collect();
        let mut free_of_dof = vec![NONE; D * n_active];
        let mut cols_before = vec![0usize; n_active + 1];
        let mut next = 0u32;
        for v in 0..n_active {
            cols_before[v] = next as usize;
            if free[v] {
                for i in 0..D {
                    free_of_dof[D * v + i] = next;
                    next += 1;
                }
            }
        }
        cols_before[n_active] = next as usize;
        assert_eq!(next as usize, n_free, "free dofs differ from the solver's");
        assert_eq!(col_ptr.len(), n_free + 1);
        let block_ptr: Vec<usize> = cols_before.iter().map(|&c| col_ptr[c]).collect();
        let col_len: Vec<usize> = (0..n_active)
            .map(|w| {
                if !free[w] {
                    return 0;
                }
                let c = cols_before[w];
                let len = col_ptr[c + 1] - col_ptr[c];
                for k in 1..D {
                    assert_eq!(col_ptr[c + k + 1] - col_ptr[c + k], len);
                }
                len
            })
            .collect();
        let dof: Vec<[u32; D]> = nodes
            .iter()
            .map(|&v| {
                std::array::from_fn(|i| match free_of_dof[D * v + i] {
                    NONE => n_free as u32,
                    free => free,
                })
            })
            .collect();
        // Node-to-point adjacency, points ascending.
        let mut adj_ptr = vec![0usize; n_active + 1];
        for &v in &nodes {
            adj_ptr[v + 1] += 1;
        }
        for v in 0..n_active {
            adj_ptr[v + 1] += adj_ptr[v];
        }
        let mut fill = adj_ptr.clone();
        let mut adj = vec![(0u32, 0u32); adj_ptr[n_active]];
        for (s, &v) in nodes.iter().enumerate() {
            adj[fill[v]] = ((s / nv) as u32, (s % nv) as u32);
            fill[v] += 1;
        }
        // The scatter map, from the solver's pattern.
        let mut offset = vec![NO_OFFSET; n * nv * nv];
        for p in 0..n {
            for b in 0..nv {
                let w = nodes[p * nv + b];
                if !free[w] {
                    continue;
                }
                let c = cols_before[w];
                let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
                for a in 0..nv {
                    let v = nodes[p * nv + a];
                    if !free[v] {
                        continue;
                    }
                    let row = free_of_dof[D * v] as usize;
                    let pos = rows.binary_search(&row).expect("entry outside the pattern");
                    for i in 1..D {
                        assert_eq!(rows[pos + i], row + i);
                    }
                    assert!(pos < NO_OFFSET as usize);
                    offset[(p * nv + b) * nv + a] = pos as u8;
                }
            }
        }
        // The step's external force (eq. 24 at load factor 1).
        let mut f_ext = vec![0.0; D * n_active];
        for (p, force) in points.body_force.iter().enumerate() {
            for a in 0..nv {
                let s = p * nv + a;
                for i in 0..D {
                    f_ext[D * nodes[s] + i] += LAMBDA1 * basis_values[s] * force[i];
                }
            }
        }
        Self {
            law: HenckyElastic::new(YOUNG, POISSON).unwrap(),
            n_free,
            grads,
            dof,
            adj_ptr,
            adj,
            free,
            block_ptr,
            col_len,
            offset,
            free_of_dof,
            f_ext,
            du_pad: vec![0.0; n_free + 1],
            stress_w: vec![SMatrix::zeros(); n],
            tangent_w: vec![[[[[0.0; D]; D]; D]; D]; n],
            f_int: vec![0.0; D * n_active],
            values: vec![0.0; row_idx.len()],
        }
    }

    /// One Newton iteration's assembly at the free-dof increment `du`;
    /// returns the normalised residual (eq. 40) as the generic solver's
    /// `assemble_at` does.
    fn assemble(&mut self, points: &Points<D>, du: &[f64]) -> Result<f64, ConstitutiveError> {
        self.du_pad[..self.n_free].copy_from_slice(du);
        self.points_pass(points)?;
        self.nodes_pass();
        Ok(self.residual())
    }

    /// Pass 1: ΔF, the update, weighted P̃ and tangent of every point.
    fn points_pass(&mut self, points: &Points<D>) -> Result<(), ConstitutiveError> {
        let mut tangents = std::mem::take(&mut self.tangent_w);
        let result = self.fused::<_, false>(points, &mut tangents, write_restricted);
        self.tangent_w = tangents;
        result
    }

    /// ΔF of point `p` (eq. 7), embedded in 3D.
    #[inline(always)]
    fn delta_f(&self, p: usize) -> Matrix3<f64> {
        let nv = Self::NV;
        let mut g = SMatrix::<f64, D, D>::identity();
        for a in 0..nv {
            let slot = p * nv + a;
            let gs = &self.grads[slot];
            for i in 0..D {
                let u = self.du_pad[self.dof[slot][i] as usize];
                for j in 0..D {
                    g[(i, j)] += u * gs[j];
                }
            }
        }
        embed(&g)
    }

    /// The fused pass over points: ΔF, update, weighted P̃ into
    /// `stress_w`, and the tangent `a` written into the point's slot of
    /// `tangents` by `write(slot, a, volume)`. With `CHECK`, the generic
    /// solver's excessive-increment test as well (stage comparison only).
    fn fused<T: Send, const CHECK: bool>(
        &mut self,
        points: &Points<D>,
        tangents: &mut [T],
        write: impl Fn(&mut T, &Tensor4, f64) + Sync,
    ) -> Result<(), ConstitutiveError> {
        let limit = NewtonOptions::default().max_increment_norm;
        let mut stress_w = std::mem::take(&mut self.stress_w);
        let this = &*self;
        let result = tangents
            .par_iter_mut()
            .zip(stress_w.par_iter_mut())
            .enumerate()
            .try_for_each(|(p, (t, s))| {
                let state = MaterialState {
                    be: points.be[p],
                    history: (),
                };
                // Results are read in place: moving a `Response` (672
                // bytes) or a `Tensor4` out of its `Result` is a copy the
                // compiler does not elide.
                let response = update(&this.law, &this.delta_f(p), &points.f[p], &state);
                let r = response.as_ref().map_err(|e| *e)?;
                if CHECK
                    && r.delta_f.norm_squared().max(r.delta_f_inv.norm_squared()) > limit * limit
                {
                    // Reported as a constitutive error: the test is here
                    // to be timed.
                    return Err(ConstitutiveError::NonPositiveJacobian {
                        which: "ΔF",
                        det: f64::NAN,
                    });
                }
                let volume = points.volume[p];
                let p_tilde = r.p_tilde();
                *s = SMatrix::from_fn(|i, j| p_tilde[(i, j)] * volume);
                let tangent = PreviouslyConvergedTangent::tangent(&this.law, r);
                write(t, tangent.as_ref().map_err(|e| *e)?, volume);
                Ok(())
            });
        self.stress_w = stress_w;
        result
    }

    /// Pass 1 in two sweeps: the updates of all points into `responses`,
    /// then the tangents from them.
    fn points_pass_two(
        &mut self,
        points: &Points<D>,
        responses: &mut [Response<()>],
    ) -> Result<(), ConstitutiveError> {
        let mut stress_w = std::mem::take(&mut self.stress_w);
        let this = &*self;
        let result = responses
            .par_iter_mut()
            .zip(stress_w.par_iter_mut())
            .enumerate()
            .try_for_each(|(p, (response, s))| {
                let state = MaterialState {
                    be: points.be[p],
                    history: (),
                };
                *response = update(&this.law, &this.delta_f(p), &points.f[p], &state)?;
                let p_tilde = response.p_tilde();
                let volume = points.volume[p];
                *s = SMatrix::from_fn(|i, j| p_tilde[(i, j)] * volume);
                Ok(())
            });
        self.stress_w = stress_w;
        result?;
        let law = &self.law;
        self.tangent_w
            .par_iter_mut()
            .zip(responses.par_iter())
            .enumerate()
            .try_for_each(|(p, (t, r))| {
                let tangent = PreviouslyConvergedTangent::tangent(law, r);
                write_restricted(t, tangent.as_ref().map_err(|e| *e)?, points.volume[p]);
                Ok(())
            })
    }

    /// Pass 1 organised as the generic solver organised it before it kept
    /// the D⁴ tangent components only, for the stage comparison: the
    /// excessive-increment test, every point's response stored as
    /// `Option<Response>`, then the tangents computed from the stored
    /// responses in a second parallel pass and stored as full weighted
    /// 9 × 9 tensors. What it leaves out of the generic
    /// stages is the locking hook and the formulation's static dispatch
    /// (both should cost nothing) and the lowest-failure reduction.
    fn points_pass_stored(
        &mut self,
        points: &Points<D>,
        responses: &mut [Option<Response<()>>],
        tangents: &mut [Tensor4],
    ) -> Result<(), ConstitutiveError> {
        let limit = NewtonOptions::default().max_increment_norm;
        let mut stress_w = std::mem::take(&mut self.stress_w);
        let this = &*self;
        let result = responses
            .par_iter_mut()
            .zip(stress_w.par_iter_mut())
            .enumerate()
            .try_for_each(|(p, (response, s))| {
                let state = MaterialState {
                    be: points.be[p],
                    history: (),
                };
                match update(&this.law, &this.delta_f(p), &points.f[p], &state) {
                    Ok(r) => {
                        if r.delta_f.norm_squared().max(r.delta_f_inv.norm_squared())
                            > limit * limit
                        {
                            return Err(ConstitutiveError::NonPositiveJacobian {
                                which: "ΔF",
                                det: f64::NAN,
                            });
                        }
                        let volume = points.volume[p];
                        let p_tilde = r.p_tilde();
                        *s = SMatrix::from_fn(|i, j| p_tilde[(i, j)] * volume);
                        *response = Some(r);
                        Ok(())
                    }
                    Err(e) => Err(e),
                }
            });
        self.stress_w = stress_w;
        result?;
        let law = &self.law;
        tangents
            .par_iter_mut()
            .zip(responses.par_iter())
            .enumerate()
            .try_for_each(|(p, (t, r))| {
                if let Some(r) = r {
                    *t = PreviouslyConvergedTangent::tangent(law, r)? * points.volume[p];
                }
                Ok(())
            })
    }

    /// Pass 2: internal force and stiffness block column of every active
    /// node.
    fn nodes_pass(&mut self) {
        let tangents = std::mem::take(&mut self.tangent_w);
        self.nodes_pass_with(&tangents[..]);
        self.tangent_w = tangents;
    }

    /// Pass 2 reading the tangents from `tangents`.
    fn nodes_pass_with(&mut self, tangents: &(impl Tangents<D> + ?Sized)) {
        let n_active = self.free.len();
        let mut values = std::mem::take(&mut self.values);
        let mut f_int = std::mem::take(&mut self.f_int);
        self.split(tangents, 0, n_active, &mut values, &mut f_int, 0);
        self.values = values;
        self.f_int = f_int;
    }

    /// Runs [`Self::node`] for the active nodes `lo..hi` in parallel on
    /// disjoint slices of the values (starting at value `base`) and of the
    /// internal force (starting at node `lo`).
    fn split(
        &self,
        t: &(impl Tangents<D> + ?Sized),
        lo: usize,
        hi: usize,
        vals: &mut [f64],
        f: &mut [f64],
        base: usize,
    ) {
        const GRAIN: usize = 64;
        if hi - lo <= GRAIN {
            let (mut vals, mut f) = (vals, f);
            for w in lo..hi {
                let len = self.block_ptr[w + 1] - self.block_ptr[w];
                let (block, rest) = vals.split_at_mut(len);
                let (fw, f_rest) = f.split_at_mut(D);
                self.node(t, w, block, fw);
                vals = rest;
                f = f_rest;
            }
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let (left, right) = vals.split_at_mut(self.block_ptr[mid] - base);
        let (f_left, f_right) = f.split_at_mut(D * (mid - lo));
        rayon::join(
            || self.split(t, lo, mid, left, f_left, base),
            || self.split(t, mid, hi, right, f_right, self.block_ptr[mid]),
        );
    }

    /// Internal force (eq. 23) and stiffness block column (eq. 21) of
    /// active node `w`.
    #[inline]
    fn node(&self, t: &(impl Tangents<D> + ?Sized), w: usize, vals: &mut [f64], f: &mut [f64]) {
        let nv = Self::NV;
        vals.iter_mut().for_each(|x| *x = 0.0);
        f.iter_mut().for_each(|x| *x = 0.0);
        let free = self.free[w];
        let cs = self.col_len[w];
        for &(p, b) in &self.adj[self.adj_ptr[w]..self.adj_ptr[w + 1]] {
            let (p, b) = (p as usize, b as usize);
            let gw = &self.grads[p * nv + b];
            let sw = &self.stress_w[p];
            for i in 0..D {
                for j in 0..D {
                    f[i] += sw[(i, j)] * gw[j];
                }
            }
            if !free {
                continue;
            }
            let q = t.contract(p, gw);
            let offsets = &self.offset[(p * nv + b) * nv..][..nv];
            for (a, &off) in offsets.iter().enumerate() {
                if off == NO_OFFSET {
                    continue;
                }
                let gv = &self.grads[p * nv + a];
                let off = off as usize;
                for (i, qi) in q.iter().enumerate() {
                    for k in 0..D {
                        let mut acc = 0.0;
                        for j in 0..D {
                            acc += gv[j] * qi[j][k];
                        }
                        vals[off + k * cs + i] += acc;
                    }
                }
            }
        }
    }

    /// The normalised out-of-balance force (eq. 40) with the reactions at
    /// the fixed dofs.
    fn residual(&self) -> f64 {
        let (mut r2, mut d2) = (0.0, 0.0);
        for (dof, &free) in self.free_of_dof.iter().enumerate() {
            let (fi, fe) = (self.f_int[dof], self.f_ext[dof]);
            if free == NONE {
                d2 += fi * fi;
            } else {
                r2 += (fi - fe) * (fi - fe);
                d2 += fe * fe;
            }
        }
        mpm_solver::stages::convergence::ratio(r2.sqrt(), d2.sqrt())
    }

    /// The internal force at the free dofs.
    fn free_internal_force(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n_free];
        for (dof, &free) in self.free_of_dof.iter().enumerate() {
            if free != NONE {
                out[free as usize] = self.f_int[dof];
            }
        }
        out
    }

    /// The external force at the free dofs.
    fn free_external_force(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n_free];
        for (dof, &free) in self.free_of_dof.iter().enumerate() {
            if free != NONE {
                out[free as usize] = self.f_ext[dof];
            }
        }
        out
    }
}

/// Where pass 2 reads the weighted tangents from: `contract(p, g)` is
/// $q_{ijk} = \sum_l T_{ijkl}\,g_l$ of point `p`.
trait Tangents<const D: usize>: Sync {
    fn contract(&self, p: usize, g: &SVector<f64, D>) -> [[[f64; D]; D]; D];
}

/// The kernel's own store: per point the D⁴ components in use,
/// `[i][j][k][l]`.
type Restricted<const D: usize> = [[[[f64; D]; D]; D]; D];

impl<const D: usize> Tangents<D> for [Restricted<D>] {
    #[inline(always)]
    fn contract(&self, p: usize, g: &SVector<f64, D>) -> [[[f64; D]; D]; D] {
        let t = &self[p];
        let mut q = [[[0.0f64; D]; D]; D];
        for i in 0..D {
            for j in 0..D {
                for k in 0..D {
                    let mut acc = 0.0;
                    for l in 0..D {
                        acc += t[i][j][k][l] * g[l];
                    }
                    q[i][j][k] = acc;
                }
            }
        }
        q
    }
}

/// Stores the D⁴ components in use of the tangent `a` weighted by
/// `volume`.
#[inline(always)]
fn write_restricted<const D: usize>(t: &mut Restricted<D>, a: &Tensor4, volume: f64) {
    for (i, ti) in t.iter_mut().enumerate() {
        for (j, tij) in ti.iter_mut().enumerate() {
            for (k, tijk) in tij.iter_mut().enumerate() {
                for (l, tijkl) in tijk.iter_mut().enumerate() {
                    *tijkl = a[(idx(i, j), idx(k, l))] * volume;
                }
            }
        }
    }
}

/// Full weighted 9 × 9 tensors, the generic solver's former store (for
/// the stage comparison).
struct Full<'a>(&'a [Tensor4]);

impl<const D: usize> Tangents<D> for Full<'_> {
    #[inline(always)]
    fn contract(&self, p: usize, g: &SVector<f64, D>) -> [[[f64; D]; D]; D] {
        let t = &self.0[p];
        let mut q = [[[0.0f64; D]; D]; D];
        for (i, qi) in q.iter_mut().enumerate() {
            for (j, qij) in qi.iter_mut().enumerate() {
                for (k, qijk) in qij.iter_mut().enumerate() {
                    let mut acc = 0.0;
                    for l in 0..D {
                        acc += t[(idx(i, j), idx(k, l))] * g[l];
                    }
                    *qijk = acc;
                }
            }
        }
        q
    }
}

/// `‖a - b‖ / ‖b‖`.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    (d / n).sqrt()
}

/// `max |a - b| / max |b|`.
fn relative_max(a: &[f64], b: &[f64]) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    d / b.iter().map(|y| y.abs()).fold(0.0, f64::max)
}

const TOLERANCE: f64 = 1e-12;

/// The two paths compute the same thing: internal force, external force,
/// stiffness values and normalised residual to [`TOLERANCE`] relative;
/// and each gives bit-identical results on 1 and 2 threads.
fn check<const D: usize>(
    name: &str,
    s: &mut Scene<D>,
    k: &mut Specialised<D>,
    pools: &[rayon::ThreadPool],
) {
    let n = s.du.len();
    let zero = vec![0.0; n];
    let minus_f_ext = s.solver.free_residual(&s.points, &zero).unwrap();
    let residual = s.solver.free_residual(&s.points, &s.du).unwrap();
    let f_int_generic: Vec<f64> = residual
        .iter()
        .zip(&minus_f_ext)
        .map(|(r, m)| r - m)
        .collect();
    let f_ext_generic: Vec<f64> = minus_f_ext.iter().map(|m| -m).collect();
    let mut runs = Vec::new();
    for pool in pools {
        let generic = pool.install(|| {
            let ratio = s.solver.assemble_at(&s.points, &s.du).unwrap();
            (ratio, s.solver.free_stiffness().unwrap().values.to_vec())
        });
        // The iteration through the separate stages computes the same.
        let in_stages = pool.install(|| {
            let ratio = s.solver.assemble_in_stages_at(&s.points, &s.du).unwrap();
            (ratio, s.solver.free_stiffness().unwrap().values.to_vec())
        });
        assert!(
            in_stages == generic,
            "{name}: the stages differ from the fused pass"
        );
        let special = pool.install(|| {
            let ratio = k.assemble(&s.points, &s.du).unwrap();
            (ratio, k.values.clone(), k.f_int.clone())
        });
        runs.push((generic, special));
    }
    for run in &runs[1..] {
        assert!(
            run.0 == runs[0].0,
            "{name}: generic path depends on threads"
        );
        assert!(
            run.1 == runs[0].1,
            "{name}: specialised kernel depends on threads"
        );
    }
    let ((ratio_g, values_g), (ratio_s, values_s, _)) = &runs[0];
    let f_int_s = k.free_internal_force();
    let f_ext_s = k.free_external_force();
    let residual_s: Vec<f64> = f_int_s.iter().zip(&f_ext_s).map(|(i, e)| i - e).collect();
    let pattern = s.solver.free_stiffness().unwrap();
    assert_eq!(pattern.values.len(), values_s.len());
    let errors = [
        ("K values", relative(values_s, values_g)),
        ("K values (max)", relative_max(values_s, values_g)),
        ("f_int", relative(&f_int_s, &f_int_generic)),
        ("f_int (max)", relative_max(&f_int_s, &f_int_generic)),
        ("f_ext", relative(&f_ext_s, &f_ext_generic)),
        ("f_int - f_ext", relative(&residual_s, &residual)),
        ("eq. 40 ratio", ((ratio_s - ratio_g) / ratio_g).abs()),
    ];
    let bitwise = values_s == values_g;
    println!(
        "{name}: {} points, {n} free dofs, {} stiffness entries; relative differences \
         specialised vs generic: {}; K bit-identical: {bitwise}; both paths bit-identical \
         on 1 and 2 threads",
        s.points.len(),
        values_g.len(),
        errors
            .iter()
            .map(|(what, e)| format!("{what} {e:.1e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for (what, e) in errors {
        assert!(e <= TOLERANCE, "{name}: {what} differs by {e:e}");
    }
}

fn pools() -> Vec<rayon::ThreadPool> {
    [1, 2]
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        })
        .collect()
}

fn configure(group: &mut BenchmarkGroup<'_, WallTime>, points: usize) {
    group.sample_size(10);
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(2));
    group.throughput(Throughput::Elements(points as u64));
}

/// Generic against specialised on 1 and 2 threads, after the check.
fn compare<const D: usize>(c: &mut Criterion, name: &str, cells: [usize; D]) {
    let mut s = scene(cells);
    let pattern = s.solver.free_stiffness().unwrap();
    let (col_ptr, row_idx) = (pattern.col_ptr.to_vec(), pattern.row_idx.to_vec());
    let mut k = Specialised::new(&s.grid, &s.points, s.du.len(), &col_ptr, &row_idx);
    let pools = pools();
    check(name, &mut s, &mut k, &pools);
    let mut group = c.benchmark_group(format!("zero_cost_{name}"));
    configure(&mut group, s.points.len());
    for pool in &pools {
        let threads = pool.current_num_threads();
        let Scene {
            points, solver, du, ..
        } = &mut s;
        group.bench_function(BenchmarkId::new("generic", threads), |b| {
            pool.install(|| b.iter(|| black_box(solver.assemble_at(points, du).unwrap())))
        });
        group.bench_function(BenchmarkId::new("specialised", threads), |b| {
            pool.install(|| b.iter(|| black_box(k.assemble(points, du).unwrap())))
        });
    }
    group.finish();
}

/// The generic iteration through the separate stages, on 1 and 2 threads
/// (its own group: interleaved with the pair above, it moved their ratio
/// by up to 5 % on the 10⁵-point scene).
fn in_stages<const D: usize>(c: &mut Criterion, name: &str, cells: [usize; D]) {
    let mut s = scene(cells);
    let pools = pools();
    let mut group = c.benchmark_group(format!("in_stages_{name}"));
    configure(&mut group, s.points.len());
    let Scene {
        points, solver, du, ..
    } = &mut s;
    for pool in &pools {
        let threads = pool.current_num_threads();
        group.bench_function(BenchmarkId::new("generic_in_stages", threads), |b| {
            pool.install(|| b.iter(|| black_box(solver.assemble_in_stages_at(points, du).unwrap())))
        });
    }
    group.finish();
}

/// The generic solver's public stages and the kernel's passes, one thread.
fn stages<const D: usize>(c: &mut Criterion, name: &str, cells: [usize; D]) {
    let mut s = scene(cells);
    let pattern = s.solver.free_stiffness().unwrap();
    let (col_ptr, row_idx) = (pattern.col_ptr.to_vec(), pattern.row_idx.to_vec());
    let mut k = Specialised::new(&s.grid, &s.points, s.du.len(), &col_ptr, &row_idx);
    k.assemble(&s.points, &s.du).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut group = c.benchmark_group(format!("stages_{name}"));
    configure(&mut group, s.points.len());
    let Scene { points, solver, .. } = &mut s;
    // `assemble_at` in `scene` left the increment in the solver.
    group.bench_function("generic_update_material_points", |b| {
        pool.install(|| b.iter(|| solver.update_material_points(points).unwrap()))
    });
    group.bench_function("generic_assemble_internal_force", |b| {
        pool.install(|| b.iter(|| solver.assemble_internal_force()))
    });
    group.bench_function("generic_update_tangents", |b| {
        pool.install(|| b.iter(|| solver.update_tangents(points).unwrap()))
    });
    group.bench_function("generic_assemble_stiffness", |b| {
        pool.install(|| b.iter(|| solver.assemble_stiffness()))
    });
    // Last of the generic stages: it leaves no responses behind.
    group.bench_function("generic_update_material_points_with_tangents", |b| {
        pool.install(|| b.iter(|| solver.update_material_points_with_tangents(points).unwrap()))
    });
    group.bench_function("generic_assemble_internal_force_and_stiffness", |b| {
        pool.install(|| b.iter(|| solver.assemble_internal_force_and_stiffness()))
    });
    let mut responses = vec![None; points.len()];
    let mut tangents = vec![Tensor4::zeros(); points.len()];
    // The variants compute what the kernel computes.
    let reference = (k.values.clone(), k.f_int.clone());
    let full = |t: &mut Tensor4, a: &Tensor4, volume: f64| *t = a * volume;
    k.fused::<_, true>(points, &mut tangents, full).unwrap();
    k.nodes_pass_with(&Full(&tangents));
    assert!(reference == (k.values.clone(), k.f_int.clone()));
    k.points_pass_stored(points, &mut responses, &mut tangents)
        .unwrap();
    k.nodes_pass_with(&Full(&tangents));
    assert!(reference == (k.values.clone(), k.f_int.clone()));
    group.bench_function("specialised_points_pass", |b| {
        pool.install(|| b.iter(|| k.points_pass(points).unwrap()))
    });
    let state = MaterialState::default();
    let rest = update(&k.law, &Matrix3::identity(), &Matrix3::identity(), &state).unwrap();
    let mut stored = vec![rest; points.len()];
    k.points_pass_two(points, &mut stored).unwrap();
    k.nodes_pass();
    assert!(reference == (k.values.clone(), k.f_int.clone()));
    group.bench_function("two_sweep_points_pass", |b| {
        pool.install(|| b.iter(|| k.points_pass_two(points, &mut stored).unwrap()))
    });
    group.bench_function("checked_points_pass", |b| {
        let mut t = k.tangent_w.clone();
        pool.install(|| {
            b.iter(|| {
                k.fused::<_, true>(points, &mut t, write_restricted)
                    .unwrap()
            })
        })
    });
    group.bench_function("checked_full_points_pass", |b| {
        pool.install(|| b.iter(|| k.fused::<_, true>(points, &mut tangents, full).unwrap()))
    });
    group.bench_function("stored_points_pass", |b| {
        pool.install(|| {
            b.iter(|| {
                k.points_pass_stored(points, &mut responses, &mut tangents)
                    .unwrap()
            })
        })
    });
    group.bench_function("specialised_nodes_pass", |b| {
        pool.install(|| b.iter(|| k.nodes_pass()))
    });
    group.bench_function("full_tensor_nodes_pass", |b| {
        pool.install(|| b.iter(|| k.nodes_pass_with(&Full(&tangents))))
    });
    group.finish();
}

fn zero_cost(c: &mut Criterion) {
    compare::<2>(c, "2d_64x64", [64, 64]);
    compare::<3>(c, "3d_12x12x12", [12, 12, 12]);
    compare::<3>(c, "3d_25x25x20", [25, 25, 20]);
    in_stages::<2>(c, "2d_64x64", [64, 64]);
    in_stages::<3>(c, "3d_12x12x12", [12, 12, 12]);
    in_stages::<3>(c, "3d_25x25x20", [25, 25, 20]);
}

fn stage_times(c: &mut Criterion) {
    stages::<2>(c, "2d_64x64", [64, 64]);
    stages::<3>(c, "3d_12x12x12", [12, 12, 12]);
    stages::<3>(c, "3d_25x25x20", [25, 25, 20]);
}

criterion_group!(benches, zero_cost, stage_times);
criterion_main!(benches);
