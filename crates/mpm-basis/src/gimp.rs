//! Uniform GIMP: the generalised interpolation material point method with
//! per-point, per-axis half-lengths.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::tensor::{AxisFactors, tensor_product};
use crate::{BasisError, BasisFunction, Stencil};

/// Uniform GIMP (Bardenhagen & Kober 2004, CMES 5(6):477–495; the implicit
/// form of Charlton et al. 2017, Comput. Struct. 190:108–125, as used by
/// Coombs et al. 2020 §6.1 and AMPLE).
///
/// The material point carries an axis-aligned domain
/// $\Omega_p = \mathbf x_p \pm \mathbf l_p$ and a uniform characteristic
/// function, so $S_{vp} = \frac{1}{V_p}\int_{\Omega_p} N_v\,\mathrm d\Omega$
/// with $N_v$ the multilinear grid functions ([`crate::LinearMpm`]). This
/// factorises per axis: $S_{vp} = \prod_i S(\delta_i;\lambda_i)$ with
/// $\delta_i = (x_{p,i} - X_{v,i})/h_i$, $\lambda_i = l_{p,i}/h_i$ and the
/// piecewise-quadratic 1D overlap function ([`Gimp::shape_1d`], five
/// regions, valid for $0 < \lambda \le 1/2$):
///
/// $$S(\delta;\lambda) = \begin{cases}
/// \dfrac{(1+\lambda+\delta)^2}{4\lambda} & -1-\lambda < \delta \le -1+\lambda\\
/// 1 + \delta & -1+\lambda < \delta \le -\lambda\\
/// 1 - \dfrac{\delta^2+\lambda^2}{2\lambda} & -\lambda < \delta \le \lambda\\
/// 1 - \delta & \lambda < \delta \le 1-\lambda\\
/// \dfrac{(1+\lambda-\delta)^2}{4\lambda} & 1-\lambda < \delta < 1+\lambda\\
/// 0 & \text{otherwise,}
/// \end{cases}$$
///
/// and $\partial_j S_{vp} = \frac{1}{h_j} S'(\delta_j;\lambda_j)
/// \prod_{i\ne j} S(\delta_i;\lambda_i)$. $S$ is $C^1$, so values and
/// gradients are continuous across cell faces.
///
/// Admissible half-lengths: $0 \le l_{p,i} \le h_i/2$ (the five regions
/// above are ordered only then; a domain updater must keep the domain
/// within this bound). $l_{p,i} = 0$ gives the standard MPM factor along
/// that axis, identical to [`crate::LinearMpm`] including its face
/// convention; as $l_{p,i}\to 0$ GIMP tends to it, and it equals it exactly
/// wherever the domain contains no node line.
///
/// Grid boundary: only existing nodes are written. Partition of unity
/// therefore holds only when the domain lies inside the grid; a domain
/// sticking out of the grid loses the part of its weight that would go to
/// nodes beyond the boundary. A point outside the grid is an error.
///
/// Domain: the half-lengths $\mathbf l_p$. Errors:
/// [`BasisError::InvalidHalfLength`] for a half-length outside
/// $[0, h_i/2]$ or not finite, [`mpm_mesh::MeshError::PointOutsideGrid`]
/// (in [`BasisError::Mesh`]) for a point outside the grid.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Gimp;

impl Gimp {
    /// The 1D GIMP function and its derivative,
    /// $(S(\delta;\lambda), \mathrm dS/\mathrm d\delta)$, for the normalised
    /// distance $\delta = (x_p - X_v)/h$ and half-length $\lambda = l_p/h$.
    ///
    /// Meaningful for $0 \le \lambda \le 1/2$. For $\lambda = 0$ it returns
    /// the hat $\max(0, 1-|\delta|)$ and the derivative $-\operatorname{sign}
    /// \delta$ inside the support (one-sided at the kink $\delta = 0$).
    pub fn shape_1d(delta: f64, lambda: f64) -> (f64, f64) {
        let d = delta;
        let l = lambda;
        if l == 0.0 {
            return if d.abs() < 1.0 {
                (1.0 - d.abs(), -d.signum())
            } else {
                (0.0, 0.0)
            };
        }
        if d <= -1.0 - l {
            (0.0, 0.0)
        } else if d <= -1.0 + l {
            let a = 1.0 + l + d;
            (a * a / (4.0 * l), a / (2.0 * l))
        } else if d <= -l {
            (1.0 + d, 1.0)
        } else if d <= l {
            (1.0 - (d * d + l * l) / (2.0 * l), -d / l)
        } else if d <= 1.0 - l {
            (1.0 - d, -1.0)
        } else if d < 1.0 + l {
            let a = 1.0 + l - d;
            (a * a / (4.0 * l), -a / (2.0 * l))
        } else {
            (0.0, 0.0)
        }
    }
}

impl<const D: usize> BasisFunction<D> for Gimp {
    type Mesh = RegularGrid<D>;
    type Domain = SVector<f64, D>;
    /// At most three nodes per axis have a non-zero factor when
    /// $\lambda \le 1/2$: the support $|\delta| < 1 + \lambda$ is an open
    /// interval of length at most three cells.
    const MAX_NODES: usize = 3usize.pow(D as u32);
    const SUPPORT_RADIUS: f64 = 1.5;

    /// The half-lengths themselves.
    fn initial_domain(_: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> SVector<f64, D> {
        *half_lengths
    }

    fn evaluate(
        &self,
        mesh: &RegularGrid<D>,
        position: &SVector<f64, D>,
        half_lengths: &SVector<f64, D>,
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError> {
        out.clear();
        for axis in 0..D {
            let (l, max) = (half_lengths[axis], 0.5 * mesh.spacing()[axis]);
            if !(l.is_finite() && (0.0..=max).contains(&l)) {
                return Err(BasisError::InvalidHalfLength {
                    point: position.iter().copied().collect(),
                    axis,
                    half_length: l,
                    max,
                });
            }
        }
        let location = mesh.locate(position)?;
        let cells = mesh.cells_per_axis();
        let mut axes = [AxisFactors::<3>::EMPTY; D];
        for (i, axis) in axes.iter_mut().enumerate() {
            let (k, t, h) = (location.cell[i], location.local[i], mesh.spacing()[i]);
            let lambda = half_lengths[i] / h;
            if lambda == 0.0 {
                axis.push(k, 1.0 - t, -1.0 / h);
                axis.push(k + 1, t, 1.0 / h);
                continue;
            }
            // Node k-1 (delta = t + 1) is in the support iff t < lambda and
            // node k+2 (delta = t - 2) iff t > 1 - lambda; with lambda <= 1/2
            // at most one of them is, so three slots suffice.
            let mut factor = |node: usize, delta: f64| {
                let (s, ds) = Self::shape_1d(delta, lambda);
                axis.push(node, s, ds / h);
            };
            if t < lambda && k >= 1 {
                factor(k - 1, t + 1.0);
            }
            factor(k, t);
            factor(k + 1, t - 1.0);
            if t > 1.0 - lambda && k + 2 <= cells[i] {
                factor(k + 2, t - 2.0);
            }
        }
        tensor_product(mesh, &axes, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1D function is the average of the hat over [delta - lambda,
    /// delta + lambda], computed here by composite Simpson integration on
    /// sub-intervals split at the hat's kinks (exact for piecewise linear
    /// integrands up to rounding).
    fn hat_average(delta: f64, lambda: f64) -> f64 {
        let hat = |x: f64| (1.0 - x.abs()).max(0.0);
        let (a, b) = (delta - lambda, delta + lambda);
        let mut breaks = vec![a, b];
        breaks.extend([-1.0, 0.0, 1.0].into_iter().filter(|&k| a < k && k < b));
        breaks.sort_by(f64::total_cmp);
        let integral: f64 = breaks
            .windows(2)
            .map(|w| (w[1] - w[0]) / 6.0 * (hat(w[0]) + 4.0 * hat(0.5 * (w[0] + w[1])) + hat(w[1])))
            .sum();
        integral / (2.0 * lambda)
    }

    #[test]
    fn shape_1d_is_the_average_of_the_hat() {
        for lambda in [1e-3, 0.1, 0.25, 0.37, 0.5] {
            for step in 0..=400 {
                let delta = -1.6 + 3.2 * f64::from(step) / 400.0;
                let (s, _) = Gimp::shape_1d(delta, lambda);
                let reference = hat_average(delta, lambda);
                assert!(
                    (s - reference).abs() <= 1e-14,
                    "lambda {lambda}, delta {delta}: {s} vs {reference}"
                );
            }
        }
    }

    #[test]
    fn shape_1d_derivative_is_the_secant_of_the_hat() {
        // d/d delta of the average = (hat(delta + lambda) - hat(delta - lambda)) / (2 lambda).
        let hat = |x: f64| (1.0 - f64::abs(x)).max(0.0);
        for lambda in [1e-3, 0.1, 0.25, 0.5] {
            for step in 0..=400 {
                let delta = -1.6 + 3.2 * f64::from(step) / 400.0;
                let (_, ds) = Gimp::shape_1d(delta, lambda);
                let secant = (hat(delta + lambda) - hat(delta - lambda)) / (2.0 * lambda);
                assert!(
                    (ds - secant).abs() <= 1e-12,
                    "lambda {lambda}, delta {delta}: {ds} vs {secant}"
                );
            }
        }
    }

    #[test]
    fn shape_1d_region_values() {
        // Hand-computed values for lambda = 1/4 in each of the five regions.
        let l = 0.25;
        let cases = [
            (-1.25, 0.0, 0.0),
            (-1.0, 0.0625, 0.5), // (1/4)^2 / 1, (1/4) / (1/2)
            (-0.5, 0.5, 1.0),
            (0.0, 0.875, 0.0), // 1 - (1/16)/(1/2)
            (0.25, 0.75, -1.0),
            (0.5, 0.5, -1.0),
            (0.875, 0.140625, -0.75), // (3/8)^2, -(3/8)/(1/2)
            (1.25, 0.0, 0.0),
        ];
        for (d, s, ds) in cases {
            assert_eq!(Gimp::shape_1d(d, l), (s, ds), "delta {d}");
        }
    }

    #[test]
    fn zero_half_length_is_the_hat() {
        assert_eq!(Gimp::shape_1d(0.3, 0.0), (0.7, -1.0));
        assert_eq!(Gimp::shape_1d(-0.3, 0.0), (0.7, 1.0));
        assert_eq!(Gimp::shape_1d(1.0, 0.0), (0.0, 0.0));
    }
}
