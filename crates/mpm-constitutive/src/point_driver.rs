//! A material-point driver with mixed control on fixed principal axes: the
//! laboratory paths (triaxial compression and extension, isotropic
//! compression, undrained shearing) on which the soil laws are checked
//! against closed forms.
//!
//! The axes stay those of the coordinate frame, so logarithmic strains add
//! exactly and the law's return map sees the trial elastic strain
//! $\varepsilon^{e}_n + \Delta\varepsilon$ directly (no rotation, no
//! kinematics to approximate). Each axis is driven either by a strain
//! increment or by a target Kirchhoff stress; the unknown strains of the
//! stress-controlled axes are found by Newton's method on the law's
//! algorithmic tangent, which converges in one or two iterations when the
//! tangent is consistent (a check in itself), by least squares where a
//! perfectly plastic limit makes the controlled block singular.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::law::{LawState, LogStrainLaw};
use crate::spectral::SymSpectral;

/// How one principal axis is driven over a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Control {
    /// A logarithmic strain increment.
    Strain(f64),
    /// A target principal Kirchhoff stress.
    Stress(f64),
}

/// Newton's method did not bring the controlled stresses to their targets.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "mixed control did not converge: stress residual {residual:e} after {iterations} iterations"
)]
pub struct NotConverged {
    /// The largest stress residual left.
    pub residual: f64,
    /// Iterations made.
    pub iterations: usize,
}

/// A material point on fixed principal axes (module docs).
#[derive(Debug, Clone)]
pub struct PointDriver<'a, L: LogStrainLaw> {
    law: &'a L,
    /// Principal elastic Hencky strains.
    pub elastic_strain: Vector3<f64>,
    /// Principal total Hencky strains.
    pub strain: Vector3<f64>,
    /// Converged internal variables.
    pub history: L::History,
    /// Principal Kirchhoff stresses.
    pub stress: Vector3<f64>,
    /// Newton iterations of the last step.
    pub iterations: usize,
}

impl<'a, L: LogStrainLaw> PointDriver<'a, L> {
    /// A point of `law` at the elastic strain `elastic_strain` (total
    /// strain zero: an initial stress) and `history`.
    pub fn new(law: &'a L, elastic_strain: Vector3<f64>, history: L::History) -> Self {
        let trial = Self::trial(&elastic_strain);
        let state = law.return_map(&trial, &history);
        Self {
            law,
            elastic_strain,
            strain: Vector3::zeros(),
            history,
            stress: state.tau,
            iterations: 0,
        }
    }

    fn trial(values: &Vector3<f64>) -> SymSpectral {
        SymSpectral {
            values: *values,
            vectors: Matrix3::identity(),
        }
    }

    /// One step under `controls`, the stresses converged to `tolerance`
    /// (absolute, in the stress unit). Returns the law's state.
    ///
    /// # Errors
    /// [`NotConverged`] after 50 Newton iterations.
    pub fn step(
        &mut self,
        controls: [Control; 3],
        tolerance: f64,
    ) -> Result<LawState<L::History>, NotConverged> {
        let mut de = Vector3::from_fn(|a, _| match controls[a] {
            Control::Strain(d) => d,
            Control::Stress(_) => 0.0,
        });
        let free: Vec<usize> = (0..3)
            .filter(|&a| matches!(controls[a], Control::Stress(_)))
            .collect();
        for iteration in 0..=50 {
            let trial = Self::trial(&(self.elastic_strain + de));
            let state = self.law.return_map(&trial, &self.history);
            let residual = DVector::from_iterator(
                free.len(),
                free.iter().map(|&a| match controls[a] {
                    Control::Stress(t) => state.tau[a] - t,
                    Control::Strain(_) => 0.0,
                }),
            );
            let worst = residual.amax();
            if worst <= tolerance {
                self.commit(de, state);
                self.iterations = iteration;
                return Ok(state);
            }
            let d = self.law.algorithmic_tangent(&trial, &self.history, &state);
            let jac =
                DMatrix::from_fn(free.len(), free.len(), |i, j| d[(4 * free[i], 4 * free[j])]);
            // Least squares: at a perfectly plastic limit the block is
            // singular along a flow that leaves the controlled stresses
            // unchanged (a shear between two equal lateral stresses); the
            // minimum-norm update keeps such axes together.
            let Ok(step) = jac.svd(true, true).solve(&residual, 1e-12 * d.amax()) else {
                return Err(NotConverged {
                    residual: worst,
                    iterations: iteration,
                });
            };
            for (k, &a) in free.iter().enumerate() {
                de[a] -= step[k];
            }
        }
        Err(NotConverged {
            residual: f64::INFINITY,
            iterations: 50,
        })
    }

    fn commit(&mut self, de: Vector3<f64>, state: LawState<L::History>) {
        self.strain += de;
        self.elastic_strain = state.elastic_strain;
        self.history = state.history;
        self.stress = state.tau;
    }

    /// Principal plastic strains: total minus the change of elastic strain
    /// since the start.
    pub fn plastic_strain(&self, initial_elastic: &Vector3<f64>) -> Vector3<f64> {
        self.strain - (self.elastic_strain - initial_elastic)
    }
}
