//! The grid-to-point stage of an explicit step as one loop over the
//! points (eqs. 36–41): interpolate the grid, move the point, deform it
//! (stress update, then its domain). The cell-averaged dilatation
//! (eqs. 47–53, [`super::CellAveraged`]) is a hook between the two halves
//! of that loop: the points are moved first, keeping their gradients and
//! cells, the cell sums of eq. (53) are formed, and the same loop then
//! deforms them with the averaged gradient of eq. (52). Without the
//! treatment the two halves run fused, point by point.

use mpm_basis::BasisFunction;
use mpm_constitutive::IncrementalLaw;
use nalgebra::{SMatrix, SVector};

use super::{
    DilatationTreatment, ExplicitMesh, ExplicitSolver, GridState, PointMut, PointsOf,
    TASKS_PER_THREAD, Transfer, VelocityFixities, g2p,
};
use crate::domain::{DomainContext, DomainUpdater};
use crate::error::PointFailure;
use crate::mesh::NodalMesh;
use crate::par::{self, Rows};

/// What one pass of the grid-to-point loop does to each point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pass {
    /// Move and deform each point in turn (no averaging).
    Fused,
    /// Move each point, keeping its gradient and the cell it started in.
    Move,
    /// Deform each point with its kept gradient, averaged over its cell.
    Deform,
}

impl<const D: usize, B, L, T, K, R> ExplicitSolver<D, B, L, T, K, R>
where
    B: BasisFunction<D>,
    B::Mesh: ExplicitMesh<D> + NodalMesh<D>,
    L: IncrementalLaw,
    T: Transfer<D>,
    K: DilatationTreatment,
    R: DomainUpdater<D, B::Domain>,
{
    /// Grid to point, with the dilatation averaging when the treatment
    /// asks for it; the largest signal speed.
    pub(super) fn gather(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
        dt: f64,
    ) -> Result<f64, (usize, PointFailure)> {
        if !K::AVERAGES {
            return self.pass(points, dt, Pass::Fused);
        }
        self.keep_starts(points);
        self.pass(points, dt, Pass::Move)?;
        self.sum_cell_dilatation(points);
        self.pass(points, dt, Pass::Deform)
    }

    /// Sizes the kept gradients and cells to the points and keeps their
    /// start positions (bases with domains only: the others have none to
    /// update).
    fn keep_starts(&mut self, points: &PointsOf<D, B, L, T>) {
        let n = points.len();
        self.grad_scratch.resize(n, SMatrix::zeros());
        self.cell_scratch.resize(n, 0);
        if Self::HAS_DOMAIN {
            self.position_scratch.clone_from(&points.position);
        }
    }

    /// Eq. (53), summed serially: two additions per point, with the
    /// volume at the start of the step.
    fn sum_cell_dilatation(&mut self, points: &PointsOf<D, B, L, T>) {
        self.cell_sums.fill((0.0, 0.0));
        for ((c, grad), vol) in self
            .cell_scratch
            .iter()
            .zip(&self.grad_scratch)
            .zip(&points.volume)
        {
            if let Some(sum) = self.cell_sums.get_mut(*c) {
                sum.0 += grad.trace() * vol;
                sum.1 += vol;
            }
        }
    }

    /// One pass of the grid-to-point loop over all points, in parallel
    /// over contiguous ranges; the largest signal speed (0 for
    /// [`Pass::Move`]), or the failure of the lowest-numbered point.
    fn pass(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
        dt: f64,
        pass: Pass,
    ) -> Result<f64, (usize, PointFailure)> {
        let per = task_size(points.len());
        let tasks = points.len().div_ceil(per);
        let (basis, mesh, grid, law) = (&self.basis, &self.mesh, &self.grid, &self.law);
        // With contact each point reads its own field's grid.
        let fields = self.contact.as_ref().map(|c| &c.grids[..]);
        let (rule, fixities) = (&self.domain_rule, &self.fixities);
        let (sums, starts) = (&self.cell_sums, &self.position_scratch);
        let alpha = self.transfer.alpha();
        let kept = (
            rows_or_empty(&mut self.grad_scratch, per, tasks),
            rows_or_empty(&mut self.cell_scratch, per, tasks),
        );
        let p = points;
        let data = (
            (
                Rows::new(&mut p.position, per),
                Rows::new(&mut p.velocity, per),
                Rows::new(&mut p.f, per),
                Rows::new(&mut p.volume, per),
                Rows::new(&mut p.tau, per),
                Rows::new(&mut p.material, per),
            ),
            (
                Rows::new(&mut p.transfer, per),
                Rows::new(&mut p.domain, per),
            ),
            kept,
        );
        let (mass, volume0, domain0) = (&p.mass[..], &p.volume0[..], &p.domain0[..]);
        let field_of = &p.field[..];
        par::reduce(
            data,
            1,
            &|first_task, (mut moving, mut state, mut kept)| {
                let mut stencil = basis.new_stencil();
                let deformer = Deformer::<D, B, L, R> {
                    law,
                    rule,
                    field: DomainField::new(mesh, grid, fixities, dt),
                };
                let mut signal: Result<f64, (usize, PointFailure)> = Ok(0.0);
                for t in 0..moving.0.len() {
                    let (x, v, f) = (moving.0.row(t), moving.1.row(t), moving.2.row(t));
                    let (vol, tau, mat) = (moving.3.row(t), moving.4.row(t), moving.5.row(t));
                    let (tr, dom) = (state.0.row(t), state.1.row(t));
                    let (grads, cells) = (kept.0.row(t), kept.1.row(t));
                    let task = first_task + t;
                    let mut task_signal = || -> Result<f64, (usize, PointFailure)> {
                        let mut signal: f64 = 0.0;
                        for k in 0..x.len() {
                            let point = task * per + k;
                            let (grad, start) = if pass == Pass::Deform {
                                (grads[k], *starts.get(point).unwrap_or(&x[k]))
                            } else {
                                let own = match fields {
                                    Some(f) => &f[usize::from(field_of[point])],
                                    None => grid,
                                };
                                let g = g2p::interpolate(
                                    basis,
                                    mesh,
                                    &x[k],
                                    &dom[k],
                                    own,
                                    &mut stencil,
                                )
                                .map_err(|e| (point, e))?;
                                let start = x[k];
                                if pass == Pass::Move {
                                    cells[k] = mesh.cell_of(&x[k]).unwrap_or(usize::MAX);
                                }
                                g2p::move_point(alpha, dt, &g, &mut x[k], &mut v[k]);
                                if pass == Pass::Move {
                                    grads[k] = g.grad;
                                    continue;
                                }
                                (g.grad, start)
                            };
                            let bar = (pass == Pass::Deform)
                                .then(|| averaged_gradient(&grad, sums.get(cells[k])));
                            let s = deformer
                                .deform::<T>(
                                    &grad,
                                    bar.as_ref(),
                                    PointMut {
                                        f: &mut f[k],
                                        volume: &mut vol[k],
                                        volume0: volume0[point],
                                        tau: &mut tau[k],
                                        material: &mut mat[k],
                                        transfer: &mut tr[k],
                                        mass: mass[point],
                                        velocity: &v[k],
                                    },
                                    (&start, &x[k]),
                                    (&domain0[point], &mut dom[k]),
                                )
                                .map_err(|e| (point, e))?;
                            signal = signal.max(s);
                        }
                        Ok(signal)
                    };
                    signal = worse(signal, task_signal());
                }
                signal
            },
            worse,
        )
    }
}

/// Eq. (52): the point's gradient with its dilatation replaced by its
/// cell's, `sum` = (Σ ∇·v V, Σ V) over the cell (unchanged outside the
/// grid's cells).
#[inline(always)]
fn averaged_gradient<const D: usize>(
    grad: &SMatrix<f64, D, D>,
    sum: Option<&(f64, f64)>,
) -> SMatrix<f64, D, D> {
    let mut bar = *grad;
    if let Some(&(div_v, v_sum)) = sum {
        let shift = (div_v / v_sum - grad.trace()) / D as f64;
        for a in 0..D {
            bar[(a, a)] += shift;
        }
    }
    bar
}

/// `v` in rows of `per`, or `tasks` empty rows when nothing is kept (the
/// fused pass keeps no gradients).
fn rows_or_empty<X>(v: &mut [X], per: usize, tasks: usize) -> Rows<'_, X> {
    if v.is_empty() {
        Rows::empty(tasks)
    } else {
        Rows::new(v, per)
    }
}

/// A point's domain after its step (the explicit counterpart of the
/// implicit solver's update after a converged load step): the rule sees
/// the new $F$, the step's $\Delta F = I + \Delta t\,\nabla v$ (eq. 39,
/// the unmodified gradient, as $F$ follows it), the positions before and
/// after, and for rules that convect corners or mid-points the grid's
/// displacement over the step ([`g2p::grid_displacement`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn update_domain<const D: usize, B, R>(
    rule: &R,
    field: &DomainField<'_, D, B::Mesh>,
    grad: &SMatrix<f64, D, D>,
    f: &nalgebra::Matrix3<f64>,
    position_previous: &SVector<f64, D>,
    position: &SVector<f64, D>,
    initial: &B::Domain,
    domain: &mut B::Domain,
) -> Result<(), PointFailure>
where
    B: BasisFunction<D>,
    B::Mesh: NodalMesh<D>,
    R: DomainUpdater<D, B::Domain>,
{
    let delta_f = g2p::increment(field.dt, grad);
    let ctx = DomainContext {
        initial,
        previous: domain,
        f,
        delta_f: &delta_f,
        position_previous,
        position,
    };
    let updated = rule
        .update(&ctx, |x: &SVector<f64, D>| {
            g2p::grid_displacement(
                field.mesh,
                field.grid,
                field.fixities,
                field.dt,
                x,
                &mut field.stencil.borrow_mut(),
            )
        })
        .map_err(|source| PointFailure::Domain {
            rule: rule.name(),
            source: Box::new(source),
        })?;
    *domain = updated;
    Ok(())
}

/// The second half of a point's grid-to-point update, shared by the fused
/// pass and the cell-averaged one: the stress update with the velocity
/// gradient (and, under dilatation averaging, its averaged form for the
/// volume, eq. 52), then the point's domain.
struct Deformer<'a, const D: usize, B: BasisFunction<D>, L, R> {
    law: &'a L,
    rule: &'a R,
    field: DomainField<'a, D, B::Mesh>,
}

impl<const D: usize, B, L, R> Deformer<'_, D, B, L, R>
where
    B: BasisFunction<D>,
    B::Mesh: NodalMesh<D>,
    L: IncrementalLaw,
    R: DomainUpdater<D, B::Domain>,
{
    /// Deforms one point that moved from `positions.0` to `positions.1`;
    /// `domains` are its initial and current domain. Returns its signal
    /// speed.
    #[inline(always)]
    fn deform<T: Transfer<D>>(
        &self,
        grad: &SMatrix<f64, D, D>,
        bar: Option<&SMatrix<f64, D, D>>,
        point: PointMut<'_, D, L::State, T::PointState>,
        positions: (&SVector<f64, D>, &SVector<f64, D>),
        domains: (&B::Domain, &mut B::Domain),
    ) -> Result<f64, PointFailure> {
        let f = point.f;
        let signal = g2p::finish::<D, L, T>(
            self.law,
            self.field.dt,
            grad,
            bar,
            PointMut {
                f: &mut *f,
                ..point
            },
        )?;
        if std::mem::size_of::<B::Domain>() > 0 {
            // The domain follows the unmodified gradient, as F does.
            update_domain::<D, B, R>(
                self.rule,
                &self.field,
                grad,
                f,
                positions.0,
                positions.1,
                domains.0,
                domains.1,
            )?;
        }
        Ok(signal)
    }
}

/// What a domain update reads of the grid: one per grid-to-point task.
struct DomainField<'a, const D: usize, M> {
    mesh: &'a M,
    grid: &'a GridState<D>,
    fixities: &'a VelocityFixities,
    dt: f64,
    stencil: std::cell::RefCell<mpm_basis::Stencil<D>>,
}

impl<'a, const D: usize, M> DomainField<'a, D, M> {
    /// The stencil grows on first use only (rules of the point's own
    /// deformation never read the grid).
    fn new(mesh: &'a M, grid: &'a GridState<D>, fixities: &'a VelocityFixities, dt: f64) -> Self {
        Self {
            mesh,
            grid,
            fixities,
            dt,
            stencil: std::cell::RefCell::new(mpm_basis::Stencil::default()),
        }
    }
}

/// Points per grid-to-point task.
fn task_size(n: usize) -> usize {
    n.div_ceil(rayon::current_num_threads().max(1) * TASKS_PER_THREAD)
        .max(64)
}

/// Of two partial results, the failure of the lower-numbered point, or
/// the larger value.
pub(super) fn worse(
    a: Result<f64, (usize, PointFailure)>,
    b: Result<f64, (usize, PointFailure)>,
) -> Result<f64, (usize, PointFailure)> {
    match (a, b) {
        (Ok(a), Ok(b)) => Ok(a.max(b)),
        (Err(a), Err(b)) => Err(if b.0 < a.0 { b } else { a }),
        (Err(a), Ok(_)) | (Ok(_), Err(a)) => Err(a),
    }
}
