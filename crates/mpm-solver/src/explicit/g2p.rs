//! Stage 3, grid to point: velocity (eq. 36), position (eq. 37, corrected),
//! velocity gradient (eq. 38), deformation gradient (eq. 39), volume and
//! density (eqs. 40–41) and the stress update.

use mpm_constitutive::IncrementalLaw;
use nalgebra::{Matrix3, SMatrix, SVector};

use super::grid::GridState;
pub use super::grid::{Gathered, gather_node};
use crate::domain::DomainError;
use crate::error::PointFailure;
use crate::mesh::NodalMesh;

/// The point's new velocity by the blend of eq. (36) and its new position
/// by the second-order update of Nairn & Hammerquist (2021),
/// $$x^{n+1}_p = x^n_p + \Delta t\sum_i w_{ip}\tilde v^{n+1}_i - \tfrac12\Delta t^2\sum_i w_{ip}a^n_i
/// = x^n_p + \tfrac{\Delta t}2\sum_i w_{ip}\left(v^n_i + \tilde v^{n+1}_i\right).$$
/// The notes print eq. (37) with $+\Delta t^2$ in place of
/// $-\tfrac12\Delta t^2$, a misprint: under a uniform acceleration $a$ the
/// printed form moves a point by $v\Delta t + 2a\Delta t^2$ instead of the
/// exact $v\Delta t + \tfrac12 a\Delta t^2$ (the free-fall test of
/// `tests/explicit.rs` pins this).
#[inline(always)]
pub fn move_point<const D: usize>(
    alpha: f64,
    dt: f64,
    g: &Gathered<D>,
    x: &mut SVector<f64, D>,
    v: &mut SVector<f64, D>,
) {
    *x += (g.new_velocity + g.old_velocity) * (0.5 * dt);
    *v = super::transfer::blend_velocity(alpha, v, &g.new_velocity, &g.old_velocity);
}

/// The largest linear shape function value of a node without mass that
/// [`grid_displacement`] takes for rounding: a point $10^{-10}$ cell
/// widths across a cell face (the GIMP collapse puts mid-points on the
/// symmetry edge at $x = -8\cdot 10^{-17}$).
pub const ROUNDING_WEIGHT: f64 = 1e-10;

/// The grid's displacement over the step at a point `x` of the
/// configuration at the step's start, interpolated with the mesh's own
/// linear shape functions $N_v$:
/// $$\Delta\mathbf u(\mathbf x) = \sum_v N_v(\mathbf x)\,\Delta\mathbf u_v,\qquad
/// \Delta\mathbf u_v = \tfrac{\Delta t}2\left(v^n_v + \tilde v^{n+1}_v\right),$$
/// the nodal displacement that [`move_point`] gives the points, except
/// that a held component moves with its prescribed velocity,
/// $\Delta u_{v,i} = \Delta t\,v^{fix}_{v,i}$: the node's own path. It is
/// the explicit counterpart of the converged displacement increment of
/// Coombs et al. 2020 eq. (35), which the rules that convect corners or
/// mid-points read (CPDI2's [`crate::ConvectedCorners`], the midpoint rules
/// of eq. 37).
///
/// - Away from held nodes it keeps a CPDI2 point with its corners: the
///   point's weights are the corner-weighted sums of the $N_v$ at the
///   corners, so the point moves by the corner-weighted mean of the
///   corners' displacements.
/// - On a held face a corner stays on the face. With
///   $\tfrac12(v^n + \tilde v^{n+1})$ there, the mapped $v^n$ of a wall
///   node (the body's velocity into the wall, or rounding) would carry a
///   corner of a body that fills the grid up to the wall out of the grid,
///   where CPDI2 cannot evaluate it.
///
/// A corner or mid-point on a face of the material's cells reads no node
/// beyond the face, but rounding can put it a hair across, where the
/// nodes beyond have no mass: weights up to [`ROUNDING_WEIGHT`] on such
/// nodes are taken as zero.
///
/// # Errors
/// `x` outside the mesh; a node with a larger $N_v(\mathbf x)$ and no
/// mass this step (its velocity is not defined).
pub fn grid_displacement<const D: usize, M: NodalMesh<D>>(
    mesh: &M,
    grid: &GridState<D>,
    fixities: &super::VelocityFixities,
    dt: f64,
    x: &SVector<f64, D>,
    stencil: &mut mpm_basis::Stencil<D>,
) -> Result<SVector<f64, D>, DomainError> {
    crate::stages::update::interpolate_nodal(mesh, x, stencil, ROUNDING_WEIGHT, |node| {
        // Entries outside lo..hi are stale; a node without mass has none.
        if !(node >= grid.lo && node < grid.hi && grid.mass[node] > 0.0) {
            return None;
        }
        let v = &grid.velocity[node];
        Some(SVector::from_fn(|i, _| match fixities.held(node, i) {
            Some(held) => dt * held,
            None => 0.5 * dt * (v.old[i] + v.new[i]),
        }))
    })
}

/// $\mathbf 1 + \Delta t\,\nabla v$ embedded in 3×3 (plane strain: the
/// out-of-plane stretch stays 1).
#[inline(always)]
pub fn increment<const D: usize>(dt: f64, grad: &SMatrix<f64, D, D>) -> Matrix3<f64> {
    let mut df = Matrix3::identity();
    for a in 0..D {
        for b in 0..D {
            df[(a, b)] += dt * grad[(a, b)];
        }
    }
    df
}

/// Eqs. (39)–(41) and the stress: $F \leftarrow (\mathbf 1 + \Delta t\nabla v)F$,
/// $V = \det(F)V^0$ from the unmodified gradient `grad`; the law advances
/// with $\mathbf 1 + \Delta t\,\overline{\nabla v}$ from `grad_bar` (equal
/// to `grad` without a locking treatment) and returns the Kirchhoff stress.
///
/// # Errors
/// $\det F \le 0$ or a failed stress update; the point is left unchanged.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn deform<const D: usize, L: IncrementalLaw>(
    law: &L,
    dt: f64,
    grad: &SMatrix<f64, D, D>,
    grad_bar: Option<&SMatrix<f64, D, D>>,
    f: &mut Matrix3<f64>,
    volume: &mut f64,
    volume0: f64,
    tau: &mut Matrix3<f64>,
    state: &mut L::State,
) -> Result<(), PointFailure> {
    let df = increment(dt, grad);
    let f_new = df * *f;
    let j = f_new.determinant();
    if j.is_nan() || j <= 0.0 {
        return Err(PointFailure::Inverted { det: j });
    }
    let df_bar = match grad_bar {
        Some(g) => increment(dt, g),
        None => df,
    };
    *tau = law.update(&df_bar, state)?;
    *f = f_new;
    *volume = j * volume0;
    Ok(())
}

/// $c_p + \|v_p\|$ of eq. (45) with $c_p = \sqrt{M/\rho_p}$, $\rho_p = m_p/V_p$
/// (eqs. 41, 46) and the P-wave modulus $M = K + \tfrac43G$.
#[inline(always)]
pub fn signal_speed<const D: usize>(
    p_wave_modulus: f64,
    mass: f64,
    volume: f64,
    v: &SVector<f64, D>,
) -> f64 {
    (p_wave_modulus * volume / mass).sqrt() + v.norm()
}

/// The end of a point's update, shared by the fused and the averaged
/// stage: [`deform`] with the unmodified gradient `grad` and the law's
/// gradient `grad_bar`, the transfer state, and the point's $c_p + \|v_p\|$
/// (with its material's modulus, [`IncrementalLaw::point_p_wave_modulus`]).
///
/// # Errors
/// As [`deform`], and a non-finite velocity.
#[inline(always)]
pub fn finish<const D: usize, L: IncrementalLaw, T: super::Transfer<D>>(
    law: &L,
    dt: f64,
    grad: &SMatrix<f64, D, D>,
    grad_bar: Option<&SMatrix<f64, D, D>>,
    point: super::PointMut<'_, D, L::State, T::PointState>,
) -> Result<f64, PointFailure> {
    deform(
        law,
        dt,
        grad,
        grad_bar,
        point.f,
        point.volume,
        point.volume0,
        point.tau,
        point.material,
    )?;
    *point.transfer = T::next_state(grad);
    let m = law.point_p_wave_modulus(point.material);
    let s = signal_speed(m, point.mass, *point.volume, point.velocity);
    if s.is_finite() {
        Ok(s)
    } else {
        Err(PointFailure::NonFinite {
            velocity: point.velocity.iter().copied().collect(),
        })
    }
}

/// The grid fields at the point at `x`: sum-factorised when the basis has
/// tensor factors ([`super::tensor::gather_point`]), node by node
/// otherwise.
///
/// # Errors
/// As [`super::p2g::visit_nodes`].
#[inline(always)]
pub fn interpolate<const D: usize, B: mpm_basis::BasisFunction<D>>(
    basis: &B,
    mesh: &B::Mesh,
    x: &SVector<f64, D>,
    domain: &B::Domain,
    grid: &GridState<D>,
    stencil: &mut mpm_basis::Stencil<D>,
) -> Result<Gathered<D>, PointFailure> {
    let node_count = grid.mass.len();
    if let Some(factors) = basis.tensor_factors(mesh, x, domain) {
        let t = factors.map_err(|e| PointFailure::Basis {
            position: x.iter().copied().collect(),
            source: crate::error::BasisFailure::Basis(e),
        })?;
        if t.last_id() < node_count {
            return Ok(super::tensor::gather_point(&t, grid));
        }
    }
    let mut g = Gathered::default();
    super::p2g::visit_nodes(basis, mesh, x, domain, node_count, stencil, |i, w, dw| {
        gather_node(&mut g, grid, i, w, dw);
    })?;
    Ok(g)
}
