//! Material point state as a flat list of numbers, so that a run can write
//! a checkpoint after every converged step and resume from it with results
//! identical to an uninterrupted run.
//!
//! Every per-point quantity implements [`Flat`]: a fixed number of `f64`
//! per value, written and read in a fixed order. The whole
//! [`MaterialPoints`] is then a header (point count and array lengths)
//! followed by its arrays ([`MaterialPoints::to_flat`],
//! [`MaterialPoints::from_flat`]).

use mpm_basis::Corners;
use mpm_constitutive::{
    CamClayRegime, DruckerPragerHistory, MaterialState, ModifiedCamClayHistory, MohrCoulombHistory,
    Regime, Tagged, VonMisesHistory,
};
use nalgebra::{Matrix3, SVector};

use crate::error::SolverError;
use crate::explicit::VelocityGradient;
use crate::points::MaterialPoints;

/// A value stored as exactly [`Flat::LEN`] numbers.
pub trait Flat: Sized {
    /// Numbers per value.
    const LEN: usize;
    /// Appends the value's numbers to `out`.
    fn write(&self, out: &mut Vec<f64>);
    /// Reads a value from exactly [`Flat::LEN`] numbers.
    fn read(from: &[f64]) -> Self;
}

impl Flat for () {
    const LEN: usize = 0;
    fn write(&self, _out: &mut Vec<f64>) {}
    fn read(_from: &[f64]) -> Self {}
}

impl Flat for f64 {
    const LEN: usize = 1;
    fn write(&self, out: &mut Vec<f64>) {
        out.push(*self);
    }
    fn read(from: &[f64]) -> Self {
        from[0]
    }
}

impl<const D: usize> Flat for SVector<f64, D> {
    const LEN: usize = D;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.as_slice());
    }
    fn read(from: &[f64]) -> Self {
        SVector::from_column_slice(&from[..D])
    }
}

impl Flat for Matrix3<f64> {
    const LEN: usize = 9;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.as_slice());
    }
    fn read(from: &[f64]) -> Self {
        Matrix3::from_column_slice(&from[..9])
    }
}

impl Flat for VonMisesHistory {
    const LEN: usize = 1;
    fn write(&self, out: &mut Vec<f64>) {
        out.push(self.alpha);
    }
    fn read(from: &[f64]) -> Self {
        VonMisesHistory { alpha: from[0] }
    }
}

/// A soil law's history: the hardening variable and the regime's code.
macro_rules! flat_soil_history {
    ($($ty:ty),+) => {$(
        impl Flat for $ty {
            const LEN: usize = 2;
            fn write(&self, out: &mut Vec<f64>) {
                out.push(self.alpha);
                out.push(f64::from(self.regime as u8));
            }
            fn read(from: &[f64]) -> Self {
                Self {
                    alpha: from[0],
                    // Codes 0..=4 only (written above).
                    regime: Regime::from_code(from[1] as u8),
                }
            }
        }
    )+};
}

flat_soil_history!(MohrCoulombHistory, DruckerPragerHistory);

/// Cam-Clay's preconsolidation pressure, the step's multiplier (its
/// tangent needs it) and the regime's code.
impl Flat for ModifiedCamClayHistory {
    const LEN: usize = 3;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend([
            self.preconsolidation,
            self.multiplier,
            f64::from(self.regime as u8),
        ]);
    }
    fn read(from: &[f64]) -> Self {
        Self {
            preconsolidation: from[0],
            multiplier: from[1],
            regime: CamClayRegime::from_code(from[2] as u8),
        }
    }
}

impl<const D: usize> Flat for Corners<D> {
    const LEN: usize = D << D;
    fn write(&self, out: &mut Vec<f64>) {
        for c in self.as_slice() {
            out.extend_from_slice(c.as_slice());
        }
    }
    fn read(from: &[f64]) -> Self {
        Corners::from_fn(|c| SVector::from_column_slice(&from[c * D..(c + 1) * D]))
    }
}

impl<T: Flat> Flat for (usize, T) {
    const LEN: usize = 1 + T::LEN;
    fn write(&self, out: &mut Vec<f64>) {
        out.push(self.0 as f64);
        self.1.write(out);
    }
    fn read(from: &[f64]) -> Self {
        (from[0] as usize, T::read(&from[1..]))
    }
}

/// The material index as a float (exact below 2^53, and a `u32` is), then
/// the inner history. A negative, fractional or too large stored index
/// reads as `u32::MAX`, which no material set contains
/// (`MaterialSet::contains` then refuses it).
impl<H: Flat> Flat for Tagged<H> {
    const LEN: usize = 1 + H::LEN;
    fn write(&self, out: &mut Vec<f64>) {
        out.push(f64::from(self.material));
        self.inner.write(out);
    }
    fn read(from: &[f64]) -> Self {
        let m = from[0];
        let material = if m >= 0.0 && m < f64::from(u32::MAX) && m.fract() == 0.0 {
            m as u32
        } else {
            u32::MAX
        };
        Tagged::new(material, H::read(&from[1..]))
    }
}

/// An explicit law's state: $b^e$, then the law's history.
impl<H: Flat> Flat for MaterialState<H> {
    const LEN: usize = 9 + H::LEN;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.be.as_slice());
        self.history.write(out);
    }
    fn read(from: &[f64]) -> Self {
        MaterialState {
            be: Matrix3::from_column_slice(&from[..9]),
            history: H::read(&from[9..]),
        }
    }
}

/// A Taylor-transfer point's velocity gradient.
impl<const D: usize> Flat for VelocityGradient<D> {
    const LEN: usize = D * D;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.0.as_slice());
    }
    fn read(from: &[f64]) -> Self {
        VelocityGradient(nalgebra::SMatrix::from_column_slice(&from[..D * D]))
    }
}

fn write_all<T: Flat>(values: &[T], out: &mut Vec<f64>) {
    out.push(values.len() as f64);
    for v in values {
        v.write(out);
    }
}

/// Reads `[len, values...]` from the front of `from`, advancing it.
fn read_all<T: Flat>(from: &mut &[f64], what: &str) -> Result<Vec<T>, SolverError> {
    let bad = |why: String| SolverError::InvalidInput(format!("checkpoint {what}: {why}"));
    let (&len, rest) = from.split_first().ok_or_else(|| bad("truncated".into()))?;
    if !(len >= 0.0 && len.fract() == 0.0 && len <= u32::MAX as f64) {
        return Err(bad(format!("invalid length {len}")));
    }
    let len = len as usize;
    let need = len * T::LEN;
    if rest.len() < need {
        return Err(bad(format!(
            "{len} values need {need} numbers, {} left",
            rest.len()
        )));
    }
    let values = if T::LEN == 0 {
        (0..len).map(|_| T::read(&[])).collect()
    } else {
        rest[..need].chunks_exact(T::LEN).map(T::read).collect()
    };
    *from = &rest[need..];
    Ok(values)
}

impl<const D: usize, H: Flat, Dom: Flat> MaterialPoints<D, H, Dom> {
    /// The state of every point as numbers (see the module docs).
    pub fn to_flat(&self) -> Vec<f64> {
        let mut out = Vec::new();
        out.push(D as f64);
        write_all(&self.position, &mut out);
        write_all(&self.displacement, &mut out);
        write_all(&self.mass, &mut out);
        write_all(&self.volume0, &mut out);
        write_all(&self.volume, &mut out);
        write_all(&self.f, &mut out);
        write_all(&self.be, &mut out);
        write_all(&self.history, &mut out);
        write_all(&self.sigma, &mut out);
        write_all(&self.domain0, &mut out);
        write_all(&self.domain, &mut out);
        write_all(&self.body_force, &mut out);
        write_all(&self.point_force, &mut out);
        out
    }

    /// Points from [`Self::to_flat`]'s numbers. A
    /// [`MaterialPoints::body_force_path`] is code, not state: the caller
    /// sets it again.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] when the numbers are truncated, have
    /// the wrong dimension or arrays of inconsistent lengths.
    pub fn from_flat(mut from: &[f64]) -> Result<Self, SolverError> {
        let bad = |why: String| SolverError::InvalidInput(format!("checkpoint: {why}"));
        match from.split_first() {
            Some((&d, rest)) if d == D as f64 => from = rest,
            Some((&d, _)) => return Err(bad(format!("written in {d}D, read in {D}D"))),
            None => return Err(bad("empty".into())),
        }
        let from = &mut from;
        let points = Self {
            position: read_all(from, "position")?,
            displacement: read_all(from, "displacement")?,
            mass: read_all(from, "mass")?,
            volume0: read_all(from, "volume0")?,
            volume: read_all(from, "volume")?,
            f: read_all(from, "f")?,
            be: read_all(from, "be")?,
            history: read_all(from, "history")?,
            sigma: read_all(from, "sigma")?,
            domain0: read_all(from, "domain0")?,
            domain: read_all(from, "domain")?,
            body_force: read_all(from, "body_force")?,
            point_force: read_all(from, "point_force")?,
            body_force_path: None,
        };
        if !from.is_empty() {
            return Err(bad(format!("{} numbers left over", from.len())));
        }
        let n = points.position.len();
        let lengths = [
            points.displacement.len(),
            points.mass.len(),
            points.volume0.len(),
            points.volume.len(),
            points.f.len(),
            points.be.len(),
            points.history.len(),
            points.sigma.len(),
            points.domain0.len(),
            points.domain.len(),
        ];
        if lengths.iter().any(|&l| l != n)
            || !(points.body_force.is_empty() || points.body_force.len() == n)
            || points.point_force.iter().any(|(p, _)| *p >= n)
        {
            return Err(bad(format!(
                "inconsistent array lengths for {n} points: {lengths:?}"
            )));
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn points_round_trip_exactly_and_bad_input_is_an_error() {
        let mut points: MaterialPoints<2, VonMisesHistory, Corners<2>> = MaterialPoints::new(
            vec![Vector2::new(0.25, 0.5), Vector2::new(1.0 / 3.0, 2.0)],
            vec![0.125, 0.5],
            7.0,
            vec![
                Corners::rectangle(&Vector2::new(0.25, 0.5), &Vector2::new(0.1, 0.2)),
                Corners::rectangle(&Vector2::new(1.0 / 3.0, 2.0), &Vector2::new(0.3, 0.1)),
            ],
        )
        .expect("points");
        points.history[1].alpha = 0.1 + 1e-17;
        points.f[0][(0, 1)] = std::f64::consts::PI;
        points.set_gravity(Vector2::new(0.0, -9.81));
        points.point_force = vec![(1, Vector2::new(3.0, 4.0))];
        let flat = points.to_flat();
        let back =
            MaterialPoints::<2, VonMisesHistory, Corners<2>>::from_flat(&flat).expect("round trip");
        assert_eq!(back.to_flat(), flat);
        assert_eq!(back.history, points.history);
        assert_eq!(back.domain, points.domain);
        assert_eq!(back.point_force, points.point_force);
        assert!(MaterialPoints::<3, VonMisesHistory, Corners<3>>::from_flat(&flat).is_err());
        assert!(
            MaterialPoints::<2, VonMisesHistory, Corners<2>>::from_flat(&flat[..flat.len() - 1])
                .is_err()
        );
        let mut extra = flat.clone();
        extra.push(0.0);
        assert!(MaterialPoints::<2, VonMisesHistory, Corners<2>>::from_flat(&extra).is_err());
        assert!(MaterialPoints::<2, (), ()>::from_flat(&flat).is_err());
    }
}
