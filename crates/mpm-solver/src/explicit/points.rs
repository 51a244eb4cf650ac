//! The material points of an explicit run, one array per quantity.

use nalgebra::{Matrix3, SVector};

use crate::error::SolverError;

/// Material points for the explicit solver (struct of arrays). `S` is the
/// law's state ([`mpm_constitutive::IncrementalLaw::State`]), `T` the
/// transfer's ([`super::Transfer::PointState`]) and `Dom` the basis's
/// domain ([`mpm_basis::BasisFunction::Domain`]: `()` for standard MPM and
/// B-splines, the half-lengths for GIMP), so neither an elastic law, nor a
/// PIC transfer, nor a basis without domains costs memory per point.
#[derive(Debug, Clone)]
pub struct ExplicitPoints<const D: usize, S, T, Dom = ()> {
    /// Global id of each point: its index on one rank; it travels with the
    /// point between ranks ([`crate::ranks`]) and names it in errors.
    pub id: Vec<usize>,
    /// Position $x_p$.
    pub position: Vec<SVector<f64, D>>,
    /// Velocity $v_p$.
    pub velocity: Vec<SVector<f64, D>>,
    /// Mass $m_p$ (constant).
    pub mass: Vec<f64>,
    /// Initial volume $V^0_p$.
    pub volume0: Vec<f64>,
    /// Current volume $V_p = J_p V^0_p$ (eq. 40); the density is
    /// $\rho_p = m_p / V_p$ (eq. 41).
    pub volume: Vec<f64>,
    /// Deformation gradient $F_p$ (eq. 39; 3×3, plane strain embedded).
    pub f: Vec<Matrix3<f64>>,
    /// Kirchhoff stress $\tau_p = J_p\sigma_p$, so that the internal force
    /// of eq. (20) is $-V^0_p\tau_p\nabla w_{ip}$.
    pub tau: Vec<Matrix3<f64>>,
    /// The law's state (e.g. $b^e$ and plastic history).
    pub material: Vec<S>,
    /// The transfer's state (e.g. $\nabla v_p$ for the Taylor transfer).
    pub transfer: Vec<T>,
    /// Applied point forces $f^{app}_p$ of eq. (21) (point index, force);
    /// empty when the scene has none.
    pub point_force: Vec<(usize, SVector<f64, D>)>,
    /// Material-point fixities (point index, component, velocity): the
    /// MPoint alternative to nodal fixities. The component of the point's
    /// velocity is held at the value — in the momentum it brings to the
    /// grid, on the grid through a Lagrange multiplier per point
    /// ([`super::grid_update::hold_points`]) and after every step — and its
    /// position moves with it; empty when the scene has none.
    pub fixed_velocity: Vec<(usize, usize, f64)>,
    /// The basis's domain of each point (GIMP half-lengths), updated after
    /// every step by the solver's [`crate::domain::DomainUpdater`].
    pub domain: Vec<Dom>,
    /// The domains at the start (what rules such as eq. 34 scale).
    pub domain0: Vec<Dom>,
    /// The velocity field of each point in a run with contact between
    /// bodies ([`super::contact`], one entry per point); empty without
    /// contact: every point then belongs to the grid's one field.
    pub field: Vec<u8>,
}

impl<const D: usize, S, T, Dom> ExplicitPoints<D, S, T, Dom> {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Sets every point's velocity from a function of its position.
    pub fn set_velocity(&mut self, v: impl Fn(&SVector<f64, D>) -> SVector<f64, D>) {
        for (x, vel) in self.position.iter().zip(&mut self.velocity) {
            *vel = v(x);
        }
    }

    /// The Cauchy stress $\sigma_p = \tau_p / J_p$ of point `p`.
    pub fn cauchy(&self, p: usize) -> Matrix3<f64> {
        self.tau[p] / self.f[p].determinant()
    }

    /// Keeps the points at the indices `ids` (distinct), in that order,
    /// with their ids: a rank's part of a point set that every rank built
    /// whole, in the order it held them. Point forces and fixities are
    /// renumbered and those of other points dropped.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] for an index twice or beyond the set.
    pub fn keep(&mut self, ids: &[usize]) -> Result<(), SolverError>
    where
        S: Clone,
        T: Clone,
        Dom: Clone,
    {
        let n = self.len();
        let mut slot_of = vec![usize::MAX; n];
        for (k, &i) in ids.iter().enumerate() {
            match slot_of.get_mut(i) {
                Some(slot) if *slot == usize::MAX => *slot = k,
                _ => {
                    return Err(SolverError::InvalidInput(format!(
                        "the points to keep must be distinct and below {n}"
                    )));
                }
            }
        }
        fn pick<X: Clone>(v: &mut Vec<X>, ids: &[usize]) {
            *v = ids.iter().map(|&i| v[i].clone()).collect();
        }
        pick(&mut self.id, ids);
        pick(&mut self.position, ids);
        pick(&mut self.velocity, ids);
        pick(&mut self.mass, ids);
        pick(&mut self.volume0, ids);
        pick(&mut self.volume, ids);
        pick(&mut self.f, ids);
        pick(&mut self.tau, ids);
        pick(&mut self.material, ids);
        pick(&mut self.transfer, ids);
        pick(&mut self.domain, ids);
        pick(&mut self.domain0, ids);
        if !self.field.is_empty() {
            pick(&mut self.field, ids);
        }
        let at = |p: usize| slot_of.get(p).copied().filter(|&k| k != usize::MAX);
        self.point_force = (self.point_force.iter())
            .filter_map(|&(p, f)| at(p).map(|k| (k, f)))
            .collect();
        self.fixed_velocity = (self.fixed_velocity.iter())
            .filter_map(|&(p, axis, v)| at(p).map(|k| (k, axis, v)))
            .collect();
        Ok(())
    }
}

impl<const D: usize, S: Copy + Default, T: Copy + Default> ExplicitPoints<D, S, T> {
    /// The same points with a domain each (initial and current), for a
    /// basis with domains, e.g. `Gimp::initial_domain(x, half_lengths)`
    /// per point.
    ///
    /// # Errors
    /// A number of domains other than the number of points.
    pub fn with_domains<Dom: Copy>(
        self,
        domains: Vec<Dom>,
    ) -> Result<ExplicitPoints<D, S, T, Dom>, SolverError> {
        if domains.len() != self.len() {
            return Err(SolverError::InvalidInput(format!(
                "{} points but {} domains",
                self.len(),
                domains.len()
            )));
        }
        Ok(ExplicitPoints {
            id: self.id,
            position: self.position,
            velocity: self.velocity,
            mass: self.mass,
            volume0: self.volume0,
            volume: self.volume,
            f: self.f,
            tau: self.tau,
            material: self.material,
            transfer: self.transfer,
            point_force: self.point_force,
            fixed_velocity: self.fixed_velocity,
            domain0: domains.clone(),
            domain: domains,
            field: self.field,
        })
    }

    /// Unstressed points at rest with the given positions and volumes and a
    /// uniform density.
    ///
    /// # Errors
    /// Mismatched lengths, non-positive or non-finite volumes, non-finite
    /// positions, a negative or non-finite density.
    pub fn new(
        position: Vec<SVector<f64, D>>,
        volume: Vec<f64>,
        density: f64,
    ) -> Result<Self, SolverError> {
        let n = position.len();
        if volume.len() != n {
            return Err(SolverError::InvalidInput(format!(
                "{n} positions but {} volumes",
                volume.len()
            )));
        }
        crate::points::check_points(&position, &volume)?;
        if !(density.is_finite() && density > 0.0) {
            return Err(SolverError::InvalidInput(format!(
                "density {density} must be positive and finite"
            )));
        }
        Ok(Self {
            id: (0..n).collect(),
            velocity: vec![SVector::zeros(); n],
            mass: volume.iter().map(|v| v * density).collect(),
            volume0: volume.clone(),
            volume,
            f: vec![Matrix3::identity(); n],
            tau: vec![Matrix3::zeros(); n],
            material: vec![S::default(); n],
            transfer: vec![T::default(); n],
            point_force: Vec::new(),
            fixed_velocity: Vec::new(),
            domain: vec![(); n],
            domain0: vec![(); n],
            field: Vec::new(),
            position,
        })
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::ExplicitPoints;

    #[test]
    fn keeping_points_keeps_their_ids_state_forces_and_fixities() {
        let x = (0..4).map(|i| Vector2::new(f64::from(i), 0.0)).collect();
        let mut points: ExplicitPoints<2, u8, ()> =
            ExplicitPoints::new(x, vec![1.0; 4], 2.0).expect("points");
        points.material = vec![10, 11, 12, 13];
        points.point_force = vec![(1, Vector2::new(1.0, 0.0)), (2, Vector2::new(2.0, 0.0))];
        points.fixed_velocity = vec![(3, 1, 0.5), (0, 0, 0.0)];
        points.keep(&[1, 3]).expect("kept");
        assert_eq!(points.id, [1, 3]);
        assert_eq!(points.position[1], Vector2::new(3.0, 0.0));
        assert_eq!(points.material, [11, 13]);
        assert_eq!(points.mass, [2.0, 2.0]);
        assert_eq!(points.point_force, [(0, Vector2::new(1.0, 0.0))]);
        assert_eq!(points.fixed_velocity, [(1, 1, 0.5)]);
        assert!(points.keep(&[1, 1]).is_err(), "twice");
        assert!(points.keep(&[2]).is_err(), "beyond the set");
        points.keep(&[1, 0]).expect("any order");
        assert_eq!(points.id, [3, 1]);
        assert_eq!(points.fixed_velocity, [(0, 1, 0.5)]);
    }
}
