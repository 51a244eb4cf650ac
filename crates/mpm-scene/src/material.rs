//! The constitutive laws reachable from scene files and the command line,
//! chosen by name at run time.
//!
//! A scene's materials run as one [`SceneLaws`]: a
//! [`MaterialSet`] of [`SceneLaw`]s, the enum over the registered laws,
//! whose history [`SceneHistory`] is the enum over their histories. The
//! law is chosen per point by a `match` beside the stress update (one
//! predictable branch per point), so every scene of a dimension, basis
//! and formulation runs one compiled solver whatever its materials; each
//! arm calls the typed law, so the numbers are those of the typed solver
//! bit for bit.
//!
//! A new law is one file in `mpm-constitutive` (an implementation of
//! `LogStrainLaw`) and one line in the [`register_laws!`] call below.

use mpm_constitutive::{
    DruckerPrager, DruckerPragerHistory, HenckyElastic, IsotropicElasticity, LawState,
    LogStrainLaw, Matching, MaterialSet, ModifiedCamClay, ModifiedCamClayHistory, MohrCoulomb,
    MohrCoulombHistory, NeoHookean, SymSpectral, Tagged, Tensor4, VonMises, VonMisesHistory,
};
use mpm_solver::{Flat, SolverError};
use nalgebra::Vector3;

/// The material parameters a law may read (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialParams {
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Yield stress ρ_y of eq. (16) (Pa), for plastic laws.
    pub yield_stress: Option<f64>,
    /// Linear isotropic hardening modulus (Pa), for plastic laws: of the
    /// yield stress (von Mises) or of the cohesion (soil laws).
    pub hardening: f64,
    /// Cohesion c (Pa), for the soil laws.
    pub cohesion: Option<f64>,
    /// Friction angle φ (degrees), for the soil laws.
    pub friction_angle: Option<f64>,
    /// Dilation angle ψ (degrees), for the soil laws.
    pub dilation_angle: f64,
    /// How the Drucker–Prager cone matches Mohr–Coulomb.
    pub matching: Option<ConeMatching>,
    /// Mohr–Coulomb's tension cut-off σ_t (Pa).
    pub tension_cutoff: Option<f64>,
    /// Modified Cam-Clay's constants.
    pub cam_clay: Option<CamClayParams>,
}

/// The constants of `modified_cam_clay` (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CamClayParams {
    /// λ̂: the slope of the normal compression line (ln p against the
    /// volumetric log strain).
    pub compression_index: f64,
    /// κ̂: the slope of the swelling line.
    pub swelling_index: f64,
    /// M: the critical-state slope q/p.
    pub critical_state_slope: f64,
    /// G (Pa).
    pub shear_modulus: f64,
    /// p_r (Pa): the pressure at zero elastic volumetric strain.
    pub reference_pressure: f64,
    /// The floor of the preconsolidation pressure (Pa).
    pub minimum_pressure: f64,
    /// The over-consolidation ratio of the initial state.
    pub overconsolidation_ratio: f64,
}

crate::variant::named_enum!(
    /// The Drucker–Prager cone's fit to Mohr–Coulomb (`matching`).
    ConeMatching {
        /// Through the compression edges (triaxial compression).
        Outer => "outer",
        /// Through the extension edges (triaxial extension).
        Inner => "inner",
        /// Mohr–Coulomb's plane-strain limit load (associated flow).
        PlaneStrain => "plane_strain",
    }
);

impl From<ConeMatching> for Matching {
    fn from(m: ConeMatching) -> Self {
        match m {
            ConeMatching::Outer => Matching::Outer,
            ConeMatching::Inner => Matching::Inner,
            ConeMatching::PlaneStrain => Matching::PlaneStrain,
        }
    }
}

impl MaterialParams {
    /// Elastic parameters only (the other keys absent).
    pub fn elastic(youngs_modulus: f64, poisson_ratio: f64) -> Self {
        Self {
            youngs_modulus,
            poisson_ratio,
            yield_stress: None,
            hardening: 0.0,
            cohesion: None,
            friction_angle: None,
            dilation_angle: 0.0,
            matching: None,
            tension_cutoff: None,
            cam_clay: None,
        }
    }

    /// The parameters of a strength-reduction trial at `factor` > 0: the
    /// cohesion, the yield stress and the hardening modulus divided by it,
    /// $\phi_F = \arctan(\tan\phi/F)$, the dilation angle capped at
    /// $\phi_F$ (as `MohrCoulomb::reduced` and `DruckerPrager::reduced`);
    /// the elastic constants kept.
    pub fn reduced(&self, factor: f64) -> Self {
        let phi = self
            .friction_angle
            .map(|phi| (phi.to_radians().tan() / factor).atan().to_degrees());
        Self {
            yield_stress: self.yield_stress.map(|y| y / factor),
            hardening: self.hardening / factor,
            cohesion: self.cohesion.map(|c| c / factor),
            tension_cutoff: self.tension_cutoff.map(|t| {
                let apex = match (self.cohesion, self.friction_angle) {
                    (Some(c), Some(phi)) if phi > 0.0 => Some(c / phi.to_radians().tan()),
                    _ => None,
                };
                mpm_constitutive::mohr_coulomb::reduced_tensile_strength(t, apex, factor)
            }),
            friction_angle: phi,
            dilation_angle: phi.map_or(self.dilation_angle, |p| self.dilation_angle.min(p)),
            ..*self
        }
    }
}

/// The laws of a scene's materials: material `k` is law `k`, each point's
/// history tagged with its material.
pub type SceneLaws = MaterialSet<SceneLaw>;

/// The largest of `lens` (a `const` helper for [`SceneHistory`]'s length).
const fn max_len(lens: &[usize]) -> usize {
    let (mut k, mut m) = (0, 0);
    while k < lens.len() {
        if lens[k] > m {
            m = lens[k];
        }
        k += 1;
    }
    m
}

/// One line per law: the variant, its name in scene files, the
/// `mpm-constitutive` type, and how it is built from [`MaterialParams`]
/// `$p`.
macro_rules! register_laws {
    ($($(#[$doc:meta])* $variant:ident => $text:literal, $ty:ty, |$p:ident| $make:expr;)+) => {
        crate::variant::named_enum!(
            /// Constitutive models (mpm-constitutive).
            MaterialModel { $($(#[$doc])* $variant => $text),+ }
        );

        /// One of the registered laws, chosen at run time (module docs).
        #[derive(Debug, Clone, PartialEq)]
        pub enum SceneLaw {
            $($(#[$doc])* $variant($ty)),+
        }

        /// The history of a [`SceneLaw`]: the variant of its law. A
        /// history of another variant (the default, before a point's
        /// first update) reads as the law's default history.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum SceneHistory {
            $($(#[$doc])* $variant(<$ty as LogStrainLaw>::History)),+
        }

        impl SceneLaw {
            /// Builds the law `model` names from `params`.
            ///
            /// # Errors
            /// [`SolverError::Material`] for invalid parameters,
            /// [`SolverError::InvalidInput`] for a parameter the model
            /// needs but was not given.
            pub fn new(model: MaterialModel, params: &MaterialParams) -> Result<Self, SolverError> {
                Ok(match model {
                    $(MaterialModel::$variant => {
                        let $p = params;
                        SceneLaw::$variant($make?)
                    })+
                })
            }

            /// The model this law is.
            pub fn model(&self) -> MaterialModel {
                match self {
                    $(SceneLaw::$variant(_) => MaterialModel::$variant,)+
                }
            }

            /// The history a point of this law starts with.
            pub fn initial_history(&self) -> SceneHistory {
                match self {
                    $(SceneLaw::$variant(_) => SceneHistory::$variant(Default::default()),)+
                }
            }
        }

        impl Default for SceneHistory {
            /// The first registered law's default history.
            fn default() -> Self {
                register_laws!(@first $(SceneHistory::$variant(Default::default())),+)
            }
        }

        impl HistoryOutput for SceneHistory {
            fn equivalent_plastic_strain(&self) -> f64 {
                match self {
                    $(SceneHistory::$variant(h) => h.equivalent_plastic_strain(),)+
                }
            }
        }

        /// The variant's index, then its history's numbers, padded to the
        /// longest history's.
        impl Flat for SceneHistory {
            const LEN: usize =
                1 + max_len(&[$(<<$ty as LogStrainLaw>::History as Flat>::LEN),+]);

            fn write(&self, out: &mut Vec<f64>) {
                let start = out.len();
                let mut index = 0.0;
                $(
                    if let SceneHistory::$variant(h) = self {
                        out.push(index);
                        h.write(out);
                    }
                    index += 1.0;
                )+
                let _ = index;
                out.resize(start + Self::LEN, 0.0);
            }

            fn read(from: &[f64]) -> Self {
                let mut index = 0.0;
                $(
                    if from[0] == index {
                        return SceneHistory::$variant(Flat::read(&from[1..]));
                    }
                    index += 1.0;
                )+
                let _ = index;
                // An index out of range (a checkpoint of another build)
                // reads as the default history.
                SceneHistory::default()
            }
        }

        impl LogStrainLaw for SceneLaw {
            type History = SceneHistory;

            const SYMMETRIC_TANGENT: bool =
                true $(&& <$ty as LogStrainLaw>::SYMMETRIC_TANGENT)+;

            #[inline(always)]
            fn return_map(&self, trial: &SymSpectral, history: &SceneHistory) -> LawState<SceneHistory> {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let h = own_history!($variant, history);
                        let s = law.return_map(trial, &h);
                        LawState {
                            tau: s.tau,
                            elastic_strain: s.elastic_strain,
                            history: SceneHistory::$variant(s.history),
                            yielded: s.yielded,
                        }
                    })+
                }
            }

            #[inline(always)]
            fn algorithmic_tangent(
                &self,
                trial: &SymSpectral,
                history: &SceneHistory,
                state: &LawState<SceneHistory>,
            ) -> Tensor4 {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let (h, s) = inner_state!($variant, history, state);
                        law.algorithmic_tangent(trial, &h, &s)
                    })+
                }
            }

            #[inline(always)]
            fn loading_tangent(
                &self,
                trial: &SymSpectral,
                history: &SceneHistory,
                state: &LawState<SceneHistory>,
            ) -> Tensor4 {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let (h, s) = inner_state!($variant, history, state);
                        law.loading_tangent(trial, &h, &s)
                    })+
                }
            }

            fn elasticity(&self) -> Option<IsotropicElasticity> {
                match self {
                    $(SceneLaw::$variant(law) => LogStrainLaw::elasticity(law),)+
                }
            }

            fn symmetric_tangent(&self) -> bool {
                match self {
                    $(SceneLaw::$variant(law) => law.symmetric_tangent(),)+
                }
            }

            fn regime(&self, state: &LawState<SceneHistory>) -> u8 {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let (_, s) = inner_state!($variant, &state.history, state);
                        law.regime(&s)
                    })+
                }
            }

            #[inline]
            fn point_shear_modulus(&self, history: &SceneHistory) -> Option<f64> {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let h = own_history!($variant, history);
                        law.point_shear_modulus(&h)
                    })+
                }
            }

            #[inline]
            fn state_p_wave_modulus(&self, be: &nalgebra::Matrix3<f64>, history: &SceneHistory) -> Option<f64> {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let h = own_history!($variant, history);
                        law.state_p_wave_modulus(be, &h)
                    })+
                }
            }

            fn stored_energy(&self, elastic_strain: &Vector3<f64>, history: &SceneHistory) -> Option<f64> {
                match self {
                    $(SceneLaw::$variant(law) => {
                        let h = own_history!($variant, history);
                        law.stored_energy(elastic_strain, &h)
                    })+
                }
            }
        }
    };
    (@first $first:expr $(, $rest:expr)*) => { $first };
}

/// The history and state of law variant `$variant` inside a
/// [`SceneHistory`] and its `LawState` (another variant reads as the
/// default history).
macro_rules! inner_state {
    ($variant:ident, $history:expr, $state:expr) => {{
        let s = LawState {
            tau: $state.tau,
            elastic_strain: $state.elastic_strain,
            history: own_history!($variant, &$state.history),
            yielded: $state.yielded,
        };
        (own_history!($variant, $history), s)
    }};
}

/// The history of law variant `$variant` in the [`SceneHistory`]
/// `$history` (a reference), or the law's default for another variant's.
macro_rules! own_history {
    ($variant:ident, $history:expr) => {{
        #[allow(unreachable_patterns)]
        let h = match $history {
            SceneHistory::$variant(h) => *h,
            _ => Default::default(),
        };
        h
    }};
}

/// The laws of `params` (material `k` is `params[k]`), each of the model
/// beside it, as one [`SceneLaws`].
///
/// # Errors
/// As [`SceneLaw::new`], and [`SolverError::Material`] for no material.
pub fn scene_laws(materials: &[(MaterialModel, MaterialParams)]) -> Result<SceneLaws, SolverError> {
    let laws = materials
        .iter()
        .map(|(model, params)| SceneLaw::new(*model, params))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(MaterialSet::new(laws)?)
}

/// A soil law's $(c, \phi, \psi)$, or an error naming the missing key.
fn strength(p: &MaterialParams, model: &str) -> Result<(f64, f64, f64), SolverError> {
    let need = |v: Option<f64>, key: &str| {
        v.ok_or_else(|| SolverError::InvalidInput(format!("material = {model} needs {key}")))
    };
    Ok((
        need(p.cohesion, "cohesion")?,
        need(p.friction_angle, "friction_angle")?,
        p.dilation_angle,
    ))
}

/// The Drucker–Prager matching, or an error asking for it.
fn matching(p: &MaterialParams) -> Result<Matching, SolverError> {
    p.matching.map(Matching::from).ok_or_else(|| {
        SolverError::InvalidInput(
            "material = drucker_prager needs matching (outer, inner or plane_strain)".into(),
        )
    })
}

/// Modified Cam-Clay from its constants, or an error naming them.
fn cam_clay(p: &MaterialParams) -> Result<ModifiedCamClay, SolverError> {
    let c = p.cam_clay.ok_or_else(|| {
        SolverError::InvalidInput(
            "material = modified_cam_clay needs compression_index, swelling_index, critical_state_slope, shear_modulus and reference_pressure".into(),
        )
    })?;
    Ok(ModifiedCamClay::new(
        c.compression_index,
        c.swelling_index,
        c.critical_state_slope,
        c.shear_modulus,
        c.reference_pressure,
    )?
    .with_minimum_pressure(c.minimum_pressure)?)
}

/// The yield stress of a plastic model, or an error naming the model.
fn yield_stress(p: &MaterialParams, model: &str) -> Result<f64, SolverError> {
    p.yield_stress
        .ok_or_else(|| SolverError::InvalidInput(format!("material = {model} needs yield_stress")))
}

register_laws! {
    /// Hencky elasticity (Coombs et al. 2020 §2).
    Hencky => "hencky", HenckyElastic, |p| HenckyElastic::new(p.youngs_modulus, p.poisson_ratio);
    /// Compressible Neo-Hookean elasticity (Bonet & Wood eq. 6.27).
    NeoHookean => "neo_hookean", NeoHookean, |p| NeoHookean::new(p.youngs_modulus, p.poisson_ratio);
    /// Von Mises elasto-plasticity with linear hardening (eq. 16).
    VonMises => "von_mises", VonMises, |p| VonMises::new(
        p.youngs_modulus,
        p.poisson_ratio,
        yield_stress(p, "von_mises")?,
        p.hardening,
    );
    /// Mohr–Coulomb with cohesion hardening and non-associated flow (de
    /// Souza Neto et al. 2008 §8.2).
    MohrCoulomb => "mohr_coulomb", MohrCoulomb, |p| {
        let (c, phi, psi) = strength(p, "mohr_coulomb")?;
        let law = MohrCoulomb::new(p.youngs_modulus, p.poisson_ratio, c, phi, psi, p.hardening)?;
        match p.tension_cutoff {
            Some(t) => law.with_tension_cutoff(t),
            None => Ok(law),
        }
    };
    /// Drucker–Prager matched to Mohr–Coulomb (de Souza Neto et al. 2008
    /// §8.3).
    DruckerPrager => "drucker_prager", DruckerPrager, |p| DruckerPrager::new(
        p.youngs_modulus,
        p.poisson_ratio,
        strength(p, "drucker_prager")?,
        p.hardening,
        matching(p)?,
    );
    /// Modified Cam-Clay at finite strain (Borja & Tamagnini 1998, with a
    /// constant shear modulus).
    ModifiedCamClay => "modified_cam_clay", ModifiedCamClay, |p| cam_clay(p);
}

/// Output quantities of a law's history.
pub trait HistoryOutput {
    /// Equivalent plastic strain (zero for elastic laws).
    fn equivalent_plastic_strain(&self) -> f64;
}

impl HistoryOutput for () {
    fn equivalent_plastic_strain(&self) -> f64 {
        0.0
    }
}

impl<H: HistoryOutput> HistoryOutput for Tagged<H> {
    fn equivalent_plastic_strain(&self) -> f64 {
        self.inner.equivalent_plastic_strain()
    }
}

impl HistoryOutput for VonMisesHistory {
    fn equivalent_plastic_strain(&self) -> f64 {
        VonMisesHistory::equivalent_plastic_strain(self)
    }
}

/// The soil laws' hardening variable $\alpha$, de Souza Neto et al.'s
/// accumulated plastic strain $\bar\varepsilon^p$ of each law.
impl HistoryOutput for MohrCoulombHistory {
    fn equivalent_plastic_strain(&self) -> f64 {
        self.alpha
    }
}

impl HistoryOutput for DruckerPragerHistory {
    fn equivalent_plastic_strain(&self) -> f64 {
        self.alpha
    }
}

/// Cam-Clay's history holds its preconsolidation pressure, not an
/// accumulated plastic strain: the field reads 0 (its stresses and
/// `p_c` tell its state).
impl HistoryOutput for ModifiedCamClayHistory {
    fn equivalent_plastic_strain(&self) -> f64 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    fn params(yield_stress: Option<f64>) -> MaterialParams {
        MaterialParams {
            youngs_modulus: 1e6,
            poisson_ratio: 0.3,
            yield_stress,
            hardening: 2e4,
            ..MaterialParams::elastic(1e6, 0.3)
        }
    }

    #[test]
    fn every_model_builds_and_bad_parameters_are_errors() {
        let mut p = params(None);
        for model in MaterialModel::ALL {
            match SceneLaw::new(*model, &p) {
                Ok(law) => assert_eq!(law.model(), *model),
                Err(e) => {
                    let needs = match model {
                        MaterialModel::VonMises => "needs yield_stress",
                        MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager => {
                            "needs cohesion"
                        }
                        MaterialModel::ModifiedCamClay => "needs compression_index",
                        _ => panic!("{model}: {e}"),
                    };
                    assert!(e.to_string().contains(needs), "{e}");
                }
            }
        }
        p.yield_stress = Some(1e3);
        assert!(SceneLaw::new(MaterialModel::VonMises, &p).is_ok());
        (p.cohesion, p.friction_angle) = (Some(1e3), Some(30.0));
        assert!(SceneLaw::new(MaterialModel::MohrCoulomb, &p).is_ok());
        let e = SceneLaw::new(MaterialModel::DruckerPrager, &p).expect_err("no matching");
        assert!(e.to_string().contains("needs matching"), "{e}");
        p.matching = Some(ConeMatching::PlaneStrain);
        assert!(SceneLaw::new(MaterialModel::DruckerPrager, &p).is_ok());
        let clay = CamClayParams {
            compression_index: 0.2,
            swelling_index: 0.05,
            critical_state_slope: 1.2,
            shear_modulus: 1e6,
            reference_pressure: 1e5,
            minimum_pressure: 0.0,
            overconsolidation_ratio: 1.0,
        };
        p.cam_clay = Some(clay);
        assert!(SceneLaw::new(MaterialModel::ModifiedCamClay, &p).is_ok());
        p.cam_clay = Some(CamClayParams {
            compression_index: 0.04,
            ..clay
        });
        assert!(matches!(
            SceneLaw::new(MaterialModel::ModifiedCamClay, &p),
            Err(SolverError::Material(_))
        ));
        p.dilation_angle = 40.0;
        assert!(matches!(
            SceneLaw::new(MaterialModel::MohrCoulomb, &p),
            Err(SolverError::Material(_))
        ));
        p.dilation_angle = 0.0;
        p.poisson_ratio = 0.5;
        assert!(matches!(
            SceneLaw::new(MaterialModel::Hencky, &p),
            Err(SolverError::Material(_))
        ));
        assert!(matches!(scene_laws(&[]), Err(SolverError::Material(_))));
        assert_eq!(
            "von_mises".parse::<MaterialModel>(),
            Ok(MaterialModel::VonMises)
        );
    }

    /// A trial log strain with a large shear, so von Mises yields, and
    /// two equal principal values.
    fn trials() -> [SymSpectral; 2] {
        let sheared = Matrix3::new(2e-2, 8e-3, 0.0, 8e-3, -1e-2, 3e-3, 0.0, 3e-3, 4e-3);
        let repeated = Matrix3::from_diagonal(&Vector3::new(-3e-2, 1e-2, 1e-2));
        [sheared, repeated].map(|e| SymSpectral::new(&e).expect("spectral"))
    }

    /// The run-time law's answers are the typed law's, bit for bit, over
    /// two successive plastic updates (the second reads the first's
    /// history).
    fn same_as_typed<L: LogStrainLaw>(
        typed: &L,
        any: &SceneLaw,
        wrap: fn(L::History) -> SceneHistory,
    ) {
        for trial in trials() {
            let (mut h, mut ha) = (L::History::default(), any.initial_history());
            for _ in 0..2 {
                let (s, sa) = (typed.return_map(&trial, &h), any.return_map(&trial, &ha));
                assert_eq!(s.tau, sa.tau);
                assert_eq!(s.elastic_strain, sa.elastic_strain);
                assert_eq!(s.yielded, sa.yielded);
                assert_eq!(wrap(s.history), sa.history);
                assert_eq!(
                    typed.algorithmic_tangent(&trial, &h, &s),
                    any.algorithmic_tangent(&trial, &ha, &sa)
                );
                assert_eq!(
                    typed.loading_tangent(&trial, &h, &s),
                    any.loading_tangent(&trial, &ha, &sa)
                );
                assert_eq!(typed.point_shear_modulus(&h), any.point_shear_modulus(&ha));
                assert_eq!(
                    typed.stored_energy(&s.elastic_strain, &s.history),
                    any.stored_energy(&sa.elastic_strain, &sa.history)
                );
                (h, ha) = (s.history, sa.history);
            }
        }
        assert_eq!(typed.elasticity(), any.elasticity());
    }

    /// A strength-reduction trial's parameters build the laws' own
    /// reduced laws (`MohrCoulomb::reduced`, `DruckerPrager::reduced`):
    /// the same stresses to rounding on a plastic trial strain (the two
    /// reach φ_F through different roundings of tan φ, 1 ulp apart); von
    /// Mises' yield stress is divided by the factor.
    #[test]
    fn reduced_parameters_build_the_reduced_laws() {
        let soil = MaterialParams {
            cohesion: Some(1e4),
            friction_angle: Some(30.0),
            dilation_angle: 25.0,
            matching: Some(ConeMatching::Inner),
            tension_cutoff: Some(5e3),
            ..params(None)
        };
        let factor = 1.37;
        let reduced = soil.reduced(factor);
        let eps = Matrix3::new(-0.02, 0.004, 0.0, 0.004, 0.01, 0.002, 0.0, 0.002, -0.003);
        let same = |a: SceneLaw, b: SceneLaw| {
            let h = a.initial_history();
            let (sa, state) = a.kirchhoff_stress(&eps, &h).expect("stress");
            let (sb, _) = b.kirchhoff_stress(&eps, &h).expect("stress");
            assert!(
                state.yielded && (sa - sb).norm() <= 1e-12 * sa.norm(),
                "{sa} {sb}"
            );
        };
        let mc = MohrCoulomb::new(1e6, 0.3, 1e4, 30.0, 25.0, 2e4)
            .and_then(|l| l.with_tension_cutoff(5e3))
            .expect("law");
        same(
            SceneLaw::new(MaterialModel::MohrCoulomb, &reduced).expect("law"),
            SceneLaw::MohrCoulomb(mc.reduced(factor).expect("law")),
        );
        let dp =
            DruckerPrager::new(1e6, 0.3, (1e4, 30.0, 25.0), 2e4, Matching::Inner).expect("law");
        same(
            SceneLaw::new(MaterialModel::DruckerPrager, &reduced).expect("law"),
            SceneLaw::DruckerPrager(dp.reduced(factor).expect("law")),
        );
        // φ_F = atan(tan 30° / 1.37) = 22.85° < ψ = 25°: ψ is capped.
        let phi_f = reduced.friction_angle.expect("reduced angle");
        assert!((phi_f - 22.852_f64).abs() < 1e-3 && reduced.dilation_angle == phi_f);
        let vm = params(Some(5e3)).reduced(2.0);
        assert_eq!(
            (vm.yield_stress, vm.hardening, vm.youngs_modulus),
            (Some(2.5e3), 1e4, 1e6)
        );
    }

    #[test]
    fn every_law_is_its_typed_law_bit_for_bit() {
        let p = params(Some(5e3));
        let hencky = HenckyElastic::new(p.youngs_modulus, p.poisson_ratio).expect("law");
        let any = SceneLaw::new(MaterialModel::Hencky, &p).expect("law");
        same_as_typed(&hencky, &any, SceneHistory::Hencky);
        let nh = NeoHookean::new(p.youngs_modulus, p.poisson_ratio).expect("law");
        let any = SceneLaw::new(MaterialModel::NeoHookean, &p).expect("law");
        same_as_typed(&nh, &any, SceneHistory::NeoHookean);
        let vm = VonMises::new(p.youngs_modulus, p.poisson_ratio, 5e3, p.hardening).expect("law");
        let any = SceneLaw::new(MaterialModel::VonMises, &p).expect("law");
        same_as_typed(&vm, &any, SceneHistory::VonMises);
        // The trial does yield, so the plastic branch was compared.
        let state = any.return_map(&trials()[0], &any.initial_history());
        assert!(state.yielded && state.history.equivalent_plastic_strain() > 0.0);
    }

    #[test]
    fn histories_survive_their_flat_form_and_a_foreign_index_reads_as_default() {
        let vm = SceneHistory::VonMises(mpm_constitutive::VonMisesHistory { alpha: 0.25 });
        for h in [SceneHistory::Hencky(()), SceneHistory::NeoHookean(()), vm] {
            let mut out = vec![7.0];
            h.write(&mut out);
            assert_eq!(out.len(), 1 + SceneHistory::LEN);
            assert_eq!(SceneHistory::read(&out[1..]), h);
        }
        assert_eq!(SceneHistory::read(&[99.0, 1.0]), SceneHistory::default());
        // A point whose history is another law's starts from the law's
        // default: the same answer as from its own default history.
        let law = SceneLaw::new(MaterialModel::VonMises, &params(Some(5e3))).expect("law");
        let trial = &trials()[0];
        assert_eq!(
            law.return_map(trial, &SceneHistory::Hencky(())),
            law.return_map(trial, &law.initial_history())
        );
    }
}
