//! The explicit solver's law of a scene material, chosen at run time.
//!
//! The explicit step updates each point's stress from its deformation
//! increment ([`IncrementalLaw`]). Neo-Hookean has a closed form (no
//! eigen-decomposition, `mpm_constitutive::NeoHookean`); every other
//! registered law runs through the finite-strain spectral driver
//! ([`Spectral`]) over the run-time [`SceneLaw`]. Each arm calls the
//! typed update, so the numbers are those of the typed solver bit for bit;
//! a scene's materials run as one [`ExplicitLaws`], so every explicit
//! scene of a dimension, basis, transfer and dilatation treatment runs one
//! compiled solver whatever its materials.

use mpm_constitutive::{IncrementalLaw, MaterialSet, MaterialState, NeoHookean, Spectral};
use mpm_solver::SolverError;
use nalgebra::Matrix3;

/// The constitutive crate's result.
type Result<T, E = mpm_constitutive::ConstitutiveError> = std::result::Result<T, E>;

use mpm_scene::material::{MaterialModel, MaterialParams, SceneHistory, SceneLaw};

/// The laws of a scene's materials for the explicit solver: material `k`
/// is law `k`, each point's state tagged with its material.
pub type ExplicitLaws = MaterialSet<ExplicitLaw>;

/// A scene material's incremental law (module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum ExplicitLaw {
    /// Neo-Hookean in closed form.
    ClosedForm(NeoHookean),
    /// Any registered law through the spectral driver.
    Spectral(Spectral<SceneLaw>),
}

impl ExplicitLaw {
    /// The law of `model` with `params`.
    ///
    /// # Errors
    /// As [`SceneLaw::new`]; [`SolverError::Material`] for a law without
    /// elastic constants (no wave speed).
    pub fn new(model: MaterialModel, params: &MaterialParams) -> Result<Self, SolverError> {
        Ok(match model {
            MaterialModel::NeoHookean => Self::ClosedForm(NeoHookean::new(
                params.youngs_modulus,
                params.poisson_ratio,
            )?),
            MaterialModel::ModifiedCamClay => {
                let law = SceneLaw::new(model, params)?;
                // The modulus at the reference pressure stands for the
                // law (a set's bound); each point's step takes its own
                // state's (`point_p_wave_modulus`).
                let reference = params.cam_clay.map_or(0.0, |c| c.reference_pressure);
                let m = match &law {
                    SceneLaw::ModifiedCamClay(clay) => clay.p_wave_modulus_at(reference)?,
                    _ => 0.0,
                };
                Self::Spectral(Spectral::with_p_wave_modulus(law, m)?)
            }
            _ => Self::Spectral(Spectral::new(SceneLaw::new(model, params)?)?),
        })
    }
}

/// `f` on the closed form's state ($b^e$ without history), written back
/// on success.
#[inline(always)]
fn closed_form<T>(
    state: &mut MaterialState<SceneHistory>,
    f: impl FnOnce(&mut MaterialState<()>) -> Result<T>,
) -> Result<T> {
    let mut own = MaterialState {
        be: state.be,
        history: (),
    };
    let out = f(&mut own)?;
    state.be = own.be;
    Ok(out)
}

impl IncrementalLaw for ExplicitLaw {
    type State = MaterialState<SceneHistory>;

    #[inline]
    fn update(&self, delta_f: &Matrix3<f64>, state: &mut Self::State) -> Result<Matrix3<f64>> {
        match self {
            Self::ClosedForm(law) => closed_form(state, |s| law.update(delta_f, s)),
            Self::Spectral(law) => law.update(delta_f, state),
        }
    }

    fn stored_energy(&self, state: &Self::State) -> Result<f64> {
        match self {
            Self::ClosedForm(law) => law.stored_energy(&MaterialState {
                be: state.be,
                history: (),
            }),
            Self::Spectral(law) => law.stored_energy(state),
        }
    }

    fn p_wave_modulus(&self) -> f64 {
        match self {
            Self::ClosedForm(law) => IncrementalLaw::p_wave_modulus(law),
            Self::Spectral(law) => law.p_wave_modulus(),
        }
    }

    #[inline(always)]
    fn point_p_wave_modulus(&self, state: &Self::State) -> f64 {
        match self {
            Self::ClosedForm(law) => IncrementalLaw::p_wave_modulus(law),
            Self::Spectral(law) => law.point_p_wave_modulus(state),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mpm_constitutive::{HenckyElastic, VonMises};

    fn params() -> MaterialParams {
        MaterialParams {
            youngs_modulus: 2e6,
            poisson_ratio: 0.3,
            yield_stress: Some(2e4),
            hardening: 1e4,
            ..MaterialParams::elastic(2e6, 0.3)
        }
    }

    /// Three increments, the last large enough to yield von Mises.
    fn increments() -> [Matrix3<f64>; 3] {
        [
            Matrix3::new(1.01, 0.02, 0.0, -0.01, 0.99, 0.0, 0.0, 0.0, 1.0),
            Matrix3::new(0.98, 0.0, 0.01, 0.03, 1.02, 0.0, 0.0, 0.01, 1.0),
            Matrix3::new(1.05, 0.08, 0.0, 0.0, 0.96, 0.02, 0.0, 0.0, 1.01),
        ]
    }

    /// The run-time law follows the typed law's stresses, states and
    /// energies bit for bit.
    fn same_as_typed<L: IncrementalLaw>(
        typed: &L,
        any: &ExplicitLaw,
        history: impl Fn(&L::State) -> (Matrix3<f64>, SceneHistory),
    ) {
        let (mut s, mut sa) = (
            L::State::default(),
            MaterialState::<SceneHistory>::default(),
        );
        for df in increments() {
            let (tau, tau_a) = (typed.update(&df, &mut s), any.update(&df, &mut sa));
            assert_eq!(tau.expect("typed"), tau_a.expect("run-time"));
            let (be, h) = history(&s);
            assert_eq!(be, sa.be);
            // The first update gives a history of the law's own variant.
            assert_eq!(h, sa.history);
            assert_eq!(typed.stored_energy(&s).ok(), any.stored_energy(&sa).ok());
        }
        assert_eq!(typed.p_wave_modulus(), any.p_wave_modulus());
    }

    #[test]
    fn every_law_is_its_typed_law_bit_for_bit() {
        let p = params();
        let nh = NeoHookean::new(p.youngs_modulus, p.poisson_ratio).expect("law");
        let any = ExplicitLaw::new(MaterialModel::NeoHookean, &p).expect("law");
        assert!(matches!(any, ExplicitLaw::ClosedForm(_)));
        same_as_typed(&nh, &any, |s| (s.be, SceneHistory::default()));
        let hencky =
            Spectral::new(HenckyElastic::new(p.youngs_modulus, p.poisson_ratio).expect("law"))
                .expect("spectral");
        let any = ExplicitLaw::new(MaterialModel::Hencky, &p).expect("law");
        same_as_typed(&hencky, &any, |s| (s.be, SceneHistory::Hencky(())));
        let vm =
            Spectral::new(VonMises::new(p.youngs_modulus, p.poisson_ratio, 2e4, 1e4).expect("law"))
                .expect("spectral");
        let any = ExplicitLaw::new(MaterialModel::VonMises, &p).expect("law");
        same_as_typed(&vm, &any, |s| (s.be, SceneHistory::VonMises(s.history)));
        // The last increment yields: the plastic branch was compared.
        let mut s = MaterialState::default();
        for df in increments() {
            any.update(&df, &mut s).expect("update");
        }
        assert!(mpm_scene::material::HistoryOutput::equivalent_plastic_strain(&s.history) > 0.0);
    }
}
