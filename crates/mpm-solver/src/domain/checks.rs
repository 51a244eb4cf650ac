//! Input checks shared by the domain-update rules, so that a rule returns a
//! [`DomainError`] that names the offending quantity instead of a NaN:
//! a deformation gradient must be finite with a positive determinant, and
//! half-lengths finite and non-negative.

use nalgebra::{Matrix3, SVector};

use super::DomainError;

/// $\det F$ of a deformation gradient (`name` says which: `"F"` or
/// `"ΔF"`), checked to be finite and positive.
pub(super) fn jacobian(f: &Matrix3<f64>, name: &'static str) -> Result<f64, DomainError> {
    if let Some(k) = f.iter().position(|x| !x.is_finite()) {
        return Err(DomainError::NonFiniteTensor {
            name,
            row: k % 3,
            col: k / 3,
            value: f[k],
        });
    }
    let j = f.determinant();
    if !j.is_finite() || j <= 0.0 {
        return Err(DomainError::NonPositiveJacobian { name, det: j });
    }
    Ok(j)
}

/// Checks that the half-lengths `l` (`which`: `"initial"`, `"previous"`)
/// are finite and non-negative.
pub(super) fn half_lengths<const D: usize>(
    l: &SVector<f64, D>,
    which: &'static str,
) -> Result<(), DomainError> {
    match l.iter().position(|x| !x.is_finite() || *x < 0.0) {
        Some(axis) => Err(DomainError::HalfLength {
            which,
            axis,
            value: l[axis],
        }),
        None => Ok(()),
    }
}

/// $x^{1/D}$, the root of eqs. (32) and (37)–(39): `sqrt` (2D) and `cbrt`
/// (3D) rather than `powf(1/D)`, whose exponent `1/3` is not exact.
#[inline]
pub(super) fn dimension_root<const D: usize>(x: f64) -> f64 {
    match D {
        1 => x,
        2 => x.sqrt(),
        3 => x.cbrt(),
        _ => x.powf(1.0 / D as f64),
    }
}

/// A material point's data owned in one place, for the rules' unit tests:
/// [`Fixture::ctx`] borrows it as a [`super::DomainContext`].
#[cfg(test)]
pub(super) struct Fixture<const D: usize, Dom> {
    /// The initial domain.
    pub initial: Dom,
    /// The domain at the start of the step.
    pub previous: Dom,
    /// The total deformation gradient.
    pub f: Matrix3<f64>,
    /// The increment over the step.
    pub delta_f: Matrix3<f64>,
    /// The point's position (the same before and after the step).
    pub position: SVector<f64, D>,
}

#[cfg(test)]
impl<const D: usize, Dom> Fixture<D, Dom> {
    /// A point at `position` with one step from the identity to `f`
    /// (`ΔF = F`) whose domain is `initial` before the step.
    pub fn first_step(initial: Dom, f: Matrix3<f64>, position: SVector<f64, D>) -> Self
    where
        Dom: Copy,
    {
        Self {
            initial,
            previous: initial,
            f,
            delta_f: f,
            position,
        }
    }

    /// The context of the step.
    pub fn ctx(&self) -> super::DomainContext<'_, D, Dom> {
        super::DomainContext {
            initial: &self.initial,
            previous: &self.previous,
            f: &self.f,
            delta_f: &self.delta_f,
            position_previous: &self.position,
            position: &self.position,
        }
    }

    /// The affine displacement $(\Delta F - I)(x - x_p)$ of the step about
    /// the point.
    pub fn affine_displacement(&self, x: &SVector<f64, D>) -> SVector<f64, D> {
        let a = nalgebra::SMatrix::<f64, D, D>::from_fn(|i, j| {
            self.delta_f[(i, j)] - if i == j { 1.0 } else { 0.0 }
        });
        a * (x - self.position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn jacobian_rejects_non_finite_and_non_positive() {
        let mut f = Matrix3::identity();
        f[(1, 0)] = f64::NAN;
        let e = jacobian(&f, "F").expect_err("NaN entry");
        assert!(e.to_string().contains("F[(1, 0)]"), "{e}");
        let reflect = Matrix3::from_diagonal(&nalgebra::Vector3::new(-1.0, 1.0, 1.0));
        let e = jacobian(&reflect, "ΔF").expect_err("det < 0");
        assert!(
            e.to_string().contains("det ΔF") && e.to_string().contains("not positive"),
            "{e}"
        );
        let flat = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 0.0, 1.0));
        assert!(jacobian(&flat, "F").is_err());
        assert_eq!(jacobian(&(Matrix3::identity() * 2.0), "F"), Ok(8.0));
    }

    #[test]
    fn dimension_root_is_the_d_th_root() {
        assert_eq!(dimension_root::<1>(0.7), 0.7);
        assert_eq!(dimension_root::<2>(2.25), 1.5);
        assert_eq!(dimension_root::<3>(0.125), 0.5);
        assert!((dimension_root::<4>(16.0) - 2.0).abs() <= 1e-15);
    }

    #[test]
    fn half_lengths_must_be_finite_and_non_negative() {
        assert!(half_lengths(&Vector2::new(0.0, 0.5), "initial").is_ok());
        let e = half_lengths(&Vector2::new(0.5, -1e-3), "previous").expect_err("negative");
        assert!(
            e.to_string().contains("previous") && e.to_string().contains("axis 1"),
            "{e}"
        );
        assert!(half_lengths(&Vector2::new(f64::INFINITY, 0.5), "initial").is_err());
    }
}
