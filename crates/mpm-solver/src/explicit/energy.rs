//! Energies of an explicit run.

use mpm_constitutive::IncrementalLaw;
use nalgebra::SVector;

use super::points::ExplicitPoints;
use crate::error::{PointFailure, SolverError};

/// The energies of the points at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// $\sum_p \tfrac12 m_p\|v_p\|^2$.
    pub kinetic: f64,
    /// $\sum_p V^0_p\,\psi_p$, the law's stored energy.
    pub strain: f64,
    /// $-\sum_p m_p\,b\cdot x_p$ (zero at the origin).
    pub gravitational: f64,
    /// Work of the applied point forces since the start.
    pub external_work: f64,
    /// Energy dissipated by the friction walls since the start
    /// ([`super::WallWork::friction`]).
    pub friction_work: f64,
    /// Energy lost in impacts on the friction walls (and in stick) since the start
    /// ([`super::WallWork::impact`]).
    pub wall_work: f64,
    /// Energy absorbed by the absorbing boundaries since the start
    /// ([`super::WallWork::absorbed`]).
    pub absorbed_work: f64,
    /// Energy stored in the absorbing boundaries' spring layer,
    /// $\sum \tfrac12 K u^2$ ([`super::absorbing::spring_energy`]).
    pub spring_energy: f64,
}

impl Energies {
    /// Kinetic + strain + gravitational + what the friction walls and
    /// the absorbing boundaries took + the energy in their springs −
    /// external work: constant for a
    /// conservative scheme.
    pub fn total(&self) -> f64 {
        self.kinetic
            + self.strain
            + self.gravitational
            + self.friction_work
            + self.wall_work
            + self.absorbed_work
            + self.spring_energy
            - self.external_work
    }

    /// The same energies with what the friction walls and the absorbing
    /// boundaries took so far.
    pub fn with_wall_work(self, work: super::WallWork) -> Self {
        Self {
            friction_work: work.friction,
            wall_work: work.impact,
            absorbed_work: work.absorbed,
            ..self
        }
    }
}

/// The energies of `points` under `law` and gravity `gravity`.
///
/// # Errors
/// The law defines no stored energy for a point's state.
pub fn energies<const D: usize, L: IncrementalLaw, T, Dom>(
    law: &L,
    gravity: &SVector<f64, D>,
    points: &ExplicitPoints<D, L::State, T, Dom>,
    external_work: f64,
) -> Result<Energies, SolverError> {
    let mut e = Energies {
        external_work,
        ..Energies::default()
    };
    for p in 0..points.len() {
        let m = points.mass[p];
        e.kinetic += 0.5 * m * points.velocity[p].norm_squared();
        e.gravitational -= m * gravity.dot(&points.position[p]);
        e.strain += points.volume0[p]
            * law.stored_energy(&points.material[p]).map_err(|source| {
                SolverError::ExplicitPoint {
                    step: 0,
                    time: 0.0,
                    point: p,
                    reason: PointFailure::Constitutive(source),
                }
            })?;
    }
    Ok(e)
}
