//! The velocity transfer between points and grid: PIC, FLIP, their blend
//! and the Taylor (affine) variants (MPoint theory notes eqs. 29, 34–36 and
//! 54–59).

use std::fmt::Debug;

use nalgebra::{SMatrix, SVector};

/// How point velocities go to the grid (eq. 29) and come back (eq. 36).
///
/// The per-point state is an associated type, so a PIC or FLIP run carries
/// no velocity-gradient matrix per point.
pub trait Transfer<const D: usize>: Copy + Send + Sync + Debug {
    /// What each point keeps between steps for the transfer: `()`, or the
    /// velocity gradient $\nabla v_p$ for the Taylor transfer.
    type PointState: Copy + Default + Send + Sync + Debug + PartialEq;

    /// Whether [`Transfer::nodal_velocity`] reads the offset (a Taylor or
    /// affine term); without one the solver does not compute it.
    const TAYLOR: bool = false;

    /// The FLIP fraction $\alpha$ of eq. (36): 0 is PIC, 1 is FLIP.
    fn alpha(&self) -> f64;

    /// The velocity a point with velocity `v` and state `state` carries to
    /// a node at offset `dx` $= x_i - x_p$: $v_p$, or
    /// $v_p + \nabla v_p\,(x_i - x_p)$ with the Taylor term (eq. 29).
    fn nodal_velocity(
        v: &SVector<f64, D>,
        state: &Self::PointState,
        dx: &SVector<f64, D>,
    ) -> SVector<f64, D>;

    /// The state after the grid-to-point update, from the new velocity
    /// gradient $\nabla v_p^{n+1}$ of eq. (38).
    fn next_state(grad_v: &SMatrix<f64, D, D>) -> Self::PointState;

    /// When [`Transfer::nodal_velocity`] is affine, $v_p + C_p(x_i - x_p)$,
    /// the matrix $C_p$: the sum-factorised kernels of tensor-product bases
    /// use it. `None` (the default) for a transfer with a Taylor term of
    /// another form, which then takes the node-by-node path.
    #[inline(always)]
    fn affine(state: &Self::PointState) -> Option<SMatrix<f64, D, D>> {
        let _ = state;
        None
    }
}

/// Particle-in-cell: $v_p^{n+1} = \sum_i w_{ip}\tilde v_i^{n+1}$ (eq. 35).
/// Dissipative; no per-point state.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pic;

/// Fluid-implicit-particle: $v_p^{n+1} = v_p^n + \sum_i w_{ip}(\tilde v_i^{n+1} - v_i^n)$
/// (eq. 34), the MPoint default. Conserves energy better than PIC and keeps
/// null-space noise.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flip;

/// The blend of eq. (36) with FLIP fraction `alpha` in [0, 1] (Stomakhin
/// et al. 2013; Nairn's damping form, eqs. 58–59, is the same update —
/// [`nairn_velocity`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlipPic {
    /// $\alpha$.
    pub alpha: f64,
}

/// The Taylor transfer (TPIC for `alpha` = 0, TFLIP for 1): the point's
/// velocity gradient enriches the projection of momentum, eq. (29)
/// (Nakamura et al. 2023).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Taylor {
    /// $\alpha$ of the velocity update (eq. 36).
    pub alpha: f64,
}

impl Taylor {
    /// Taylor-PIC.
    pub const PIC: Self = Self { alpha: 0.0 };
    /// Taylor-FLIP.
    pub const FLIP: Self = Self { alpha: 1.0 };
}

macro_rules! stateless {
    ($ty:ty, $alpha:expr) => {
        impl<const D: usize> Transfer<D> for $ty {
            type PointState = ();

            #[inline(always)]
            fn alpha(&self) -> f64 {
                #[allow(clippy::redundant_closure_call)]
                ($alpha)(self)
            }

            #[inline(always)]
            fn nodal_velocity(v: &SVector<f64, D>, _: &(), _: &SVector<f64, D>) -> SVector<f64, D> {
                *v
            }

            #[inline(always)]
            fn next_state(_: &SMatrix<f64, D, D>) {}
        }
    };
}

stateless!(Pic, |_: &Pic| 0.0);
stateless!(Flip, |_: &Flip| 1.0);
stateless!(FlipPic, |t: &FlipPic| t.alpha);

/// The velocity gradient a Taylor-transfer point keeps, $\nabla v_p$ (zero
/// by default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityGradient<const D: usize>(pub SMatrix<f64, D, D>);

impl<const D: usize> Default for VelocityGradient<D> {
    fn default() -> Self {
        Self(SMatrix::zeros())
    }
}

impl<const D: usize> Transfer<D> for Taylor {
    type PointState = VelocityGradient<D>;
    const TAYLOR: bool = true;

    #[inline(always)]
    fn alpha(&self) -> f64 {
        self.alpha
    }

    #[inline(always)]
    fn nodal_velocity(
        v: &SVector<f64, D>,
        grad: &VelocityGradient<D>,
        dx: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        v + grad.0 * dx
    }

    #[inline(always)]
    fn next_state(grad_v: &SMatrix<f64, D, D>) -> VelocityGradient<D> {
        VelocityGradient(*grad_v)
    }

    #[inline(always)]
    fn affine(state: &VelocityGradient<D>) -> Option<SMatrix<f64, D, D>> {
        Some(state.0)
    }
}

/// Eq. (36): $v_p^{n+1} = \bar{\tilde v} + \alpha(v_p^n - \bar v)$ with the
/// interpolated new and old grid velocities $\bar{\tilde v} = \sum_i w_{ip}\tilde v_i^{n+1}$
/// and $\bar v = \sum_i w_{ip} v_i^n$.
#[inline(always)]
pub fn blend_velocity<const D: usize>(
    alpha: f64,
    v_p: &SVector<f64, D>,
    new_grid: &SVector<f64, D>,
    old_grid: &SVector<f64, D>,
) -> SVector<f64, D> {
    new_grid + (v_p - old_grid) * alpha
}

/// Nairn's form of the same update, eqs. (58)–(59):
/// $v_p^{n+1} = v_p^n + \left(\bar a - \beta(v_p^n - \bar v)\right)\Delta t$ with
/// $\bar a = (\bar{\tilde v} - \bar v)/\Delta t$ and $\beta = (1-\alpha)/\Delta t$.
/// Expanding, $v_p^n + \bar{\tilde v} - \bar v - (1-\alpha)(v_p^n - \bar v)
/// = \bar{\tilde v} + \alpha(v_p^n - \bar v)$: eq. (36). Kept for the test
/// that shows the two agree.
pub fn nairn_velocity<const D: usize>(
    alpha: f64,
    dt: f64,
    v_p: &SVector<f64, D>,
    new_grid: &SVector<f64, D>,
    old_grid: &SVector<f64, D>,
) -> SVector<f64, D> {
    let acceleration = (new_grid - old_grid) / dt;
    let beta = (1.0 - alpha) / dt;
    v_p + (acceleration - (v_p - old_grid) * beta) * dt
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn nairn_damping_form_is_the_blend() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..1000 {
            let alpha = 0.5 * (next() + 1.0);
            let dt = 10f64.powf(-6.0 + 5.0 * (next() + 1.0) / 2.0);
            let v = Vector3::new(next(), next(), next());
            let a = Vector3::new(next(), next(), next());
            let b = Vector3::new(next(), next(), next());
            let blend = blend_velocity(alpha, &v, &a, &b);
            let nairn = nairn_velocity(alpha, dt, &v, &a, &b);
            assert!((blend - nairn).norm() < 1e-9, "{blend} vs {nairn}");
        }
        // PIC forgets the point velocity, FLIP keeps its difference.
        let (v, a, b) = (Vector3::x(), Vector3::y(), Vector3::z());
        assert_eq!(blend_velocity(0.0, &v, &a, &b), a);
        assert_eq!(blend_velocity(1.0, &v, &a, &b), v + a - b);
    }

    #[test]
    fn taylor_projection_adds_the_gradient_term() {
        let g = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 3.0, 4.0);
        let v = SVector::<f64, 2>::new(0.5, -0.5);
        let dx = SVector::<f64, 2>::new(0.1, 0.2);
        let t = <Taylor as Transfer<2>>::nodal_velocity(&v, &VelocityGradient(g), &dx);
        assert!((t - SVector::<f64, 2>::new(1.0, 0.6)).norm() < 1e-15);
        assert_eq!(<Pic as Transfer<2>>::nodal_velocity(&v, &(), &dx), v);
        assert_eq!(
            <FlipPic as Transfer<2>>::alpha(&FlipPic { alpha: 0.3 }),
            0.3
        );
    }
}
