//! The constitutive laws reachable from scene files and the command line,
//! chosen by name and dispatched to a fully monomorphised computation.
//!
//! A new law is one file in `mpm-constitutive` (an implementation of
//! `LogStrainLaw`) and one line in the [`register_laws!`] call below.

use mpm_constitutive::{
    HenckyElastic, LogStrainLaw, MaterialSet, NeoHookean, Tagged, VonMises, VonMisesHistory,
};
use mpm_solver::{Flat, SolverError};

use crate::run::HistoryOutput;

/// The material parameters a law may read (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialParams {
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Yield stress ρ_y of eq. (16) (Pa), for plastic laws.
    pub yield_stress: Option<f64>,
    /// Linear isotropic hardening modulus (Pa), for plastic laws.
    pub hardening: f64,
}

/// The initial history of a point of material `material` (an index into
/// the scene's materials): the law's default history, tagged with the
/// material when the law is a [`MaterialSet`].
pub trait MaterialTag {
    /// The history a point of `material` starts with.
    fn for_material(material: u32) -> Self;
    /// The material a history belongs to (0 for laws of one material).
    fn material(&self) -> u32;
}

impl MaterialTag for () {
    fn for_material(_: u32) -> Self {}
    fn material(&self) -> u32 {
        0
    }
}

impl MaterialTag for VonMisesHistory {
    fn for_material(_: u32) -> Self {
        Self::default()
    }
    fn material(&self) -> u32 {
        0
    }
}

impl<H: Default> MaterialTag for Tagged<H> {
    fn for_material(material: u32) -> Self {
        Tagged::new(material, H::default())
    }
    fn material(&self) -> u32 {
        self.material
    }
}

/// A computation generic over the law; [`dispatch_law`] calls it with the
/// law a [`MaterialModel`] names, [`dispatch_law_set`] with a
/// [`MaterialSet`] of them.
pub trait LawVisitor {
    /// What the computation returns.
    type Output;

    /// Runs with law `law`.
    fn visit<L>(self, law: L) -> Self::Output
    where
        L: LogStrainLaw,
        L::History: HistoryOutput + Flat + MaterialTag;
}

/// One line per law: the variant, its name in scene files, and how the law
/// is built from [`MaterialParams`] `$p`.
macro_rules! register_laws {
    ($($(#[$doc:meta])* $variant:ident => $text:literal, |$p:ident| $make:expr;)+) => {
        crate::variant::named_enum!(
            /// Constitutive models (mpm-constitutive).
            MaterialModel { $($(#[$doc])* $variant => $text),+ }
        );

        /// Builds the law `model` names from `params` and calls `visitor`
        /// with it.
        ///
        /// # Errors
        /// [`SolverError::Material`] for invalid parameters,
        /// [`SolverError::InvalidInput`] for a parameter the model needs
        /// but was not given.
        pub fn dispatch_law<V: LawVisitor>(
            model: MaterialModel,
            params: &MaterialParams,
            visitor: V,
        ) -> Result<V::Output, SolverError> {
            match model {
                $(MaterialModel::$variant => {
                    let $p = params;
                    Ok(visitor.visit($make?))
                })+
            }
        }

        /// Builds one law of `model` per entry of `params` and calls
        /// `visitor` with their [`MaterialSet`] (material `k` is
        /// `params[k]`).
        ///
        /// # Errors
        /// As [`dispatch_law`], and [`SolverError::Material`] for an empty
        /// `params`.
        pub fn dispatch_law_set<V: LawVisitor>(
            model: MaterialModel,
            params: &[MaterialParams],
            visitor: V,
        ) -> Result<V::Output, SolverError> {
            match model {
                $(MaterialModel::$variant => {
                    let laws = params
                        .iter()
                        .map(|$p| -> Result<_, SolverError> { Ok($make?) })
                        .collect::<Result<Vec<_>, _>>()?;
                    Ok(visitor.visit(MaterialSet::new(laws)?))
                })+
            }
        }
    };
}

/// The yield stress of a plastic model, or an error naming the model.
fn yield_stress(p: &MaterialParams, model: &str) -> Result<f64, SolverError> {
    p.yield_stress
        .ok_or_else(|| SolverError::InvalidInput(format!("material = {model} needs yield_stress")))
}

register_laws! {
    /// Hencky elasticity (Coombs et al. 2020 §2).
    Hencky => "hencky", |p| HenckyElastic::new(p.youngs_modulus, p.poisson_ratio);
    /// Compressible Neo-Hookean elasticity (Bonet & Wood eq. 6.27).
    NeoHookean => "neo_hookean", |p| NeoHookean::new(p.youngs_modulus, p.poisson_ratio);
    /// Von Mises elasto-plasticity with linear hardening (eq. 16).
    VonMises => "von_mises", |p| VonMises::new(
        p.youngs_modulus,
        p.poisson_ratio,
        yield_stress(p, "von_mises")?,
        p.hardening,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Name;

    impl LawVisitor for Name {
        type Output = &'static str;
        fn visit<L: LogStrainLaw>(self, _: L) -> &'static str {
            std::any::type_name::<L>()
        }
    }

    #[test]
    fn every_model_builds_and_bad_parameters_are_errors() {
        let mut p = MaterialParams {
            youngs_modulus: 1e6,
            poisson_ratio: 0.3,
            yield_stress: None,
            hardening: 0.0,
        };
        let hencky = dispatch_law(MaterialModel::Hencky, &p, Name).expect("hencky");
        assert!(hencky.ends_with("HenckyElastic"), "{hencky}");
        let e = dispatch_law(MaterialModel::VonMises, &p, Name).expect_err("no yield stress");
        assert!(e.to_string().contains("needs yield_stress"), "{e}");
        p.yield_stress = Some(1e3);
        let vm = dispatch_law(MaterialModel::VonMises, &p, Name).expect("von mises");
        assert!(vm.ends_with("VonMises"), "{vm}");
        let nh = dispatch_law(MaterialModel::NeoHookean, &p, Name).expect("neo-hookean");
        assert!(nh.ends_with("NeoHookean"), "{nh}");
        p.poisson_ratio = 0.5;
        assert!(matches!(
            dispatch_law(MaterialModel::Hencky, &p, Name),
            Err(SolverError::Material(_))
        ));
        assert_eq!(
            "von_mises".parse::<MaterialModel>(),
            Ok(MaterialModel::VonMises)
        );
    }
}
