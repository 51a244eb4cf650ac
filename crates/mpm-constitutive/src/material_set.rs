//! Several materials of one model in one analysis: a law that holds one
//! set of parameters per material and finds each point's material in its
//! history.
//!
//! The solver calls one law for every point, with the point's history
//! (its internal variables). [`MaterialSet`] stores a list of laws of the
//! same type `L`; a point's history is [`Tagged`]: the index of its
//! material and the history of that material's law. The return map and
//! the algorithmic tangent are those of the tagged law, so each point
//! behaves exactly as it would in an analysis of its material alone. A
//! scene of one material does not need the set (and does not pay for the
//! tag).
//!
//! ```
//! use mpm_constitutive::{HenckyElastic, LogStrainLaw, MaterialSet, Tagged};
//! use nalgebra::Matrix3;
//!
//! let set = MaterialSet::new(vec![
//!     HenckyElastic::new(1e6, 0.0)?,
//!     HenckyElastic::new(1e8, 0.0)?,
//! ])?;
//! let eps = Matrix3::from_diagonal_element(1e-3);
//! let (soft, _) = set.kirchhoff_stress(&eps, &Tagged::new(0, ()))?;
//! let (stiff, _) = set.kirchhoff_stress(&eps, &Tagged::new(1, ()))?;
//! assert!((stiff[(0, 0)] / soft[(0, 0)] - 100.0).abs() < 1e-12);
//! # Ok::<(), mpm_constitutive::ConstitutiveError>(())
//! ```

use crate::error::{ConstitutiveError, Result};
use crate::law::{LawState, LogStrainLaw};
use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;

/// One law per material; see the [module documentation](self).
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialSet<L> {
    laws: Vec<L>,
}

/// A point's material (an index into its [`MaterialSet`]) and the history
/// of that material's law. The default is material 0 with the law's
/// default history.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tagged<H> {
    /// Index of the point's material.
    pub material: u32,
    /// The history of the material's law.
    pub inner: H,
}

impl<H> Tagged<H> {
    /// Material `material` with history `inner`.
    pub fn new(material: u32, inner: H) -> Self {
        Self { material, inner }
    }
}

impl<L> MaterialSet<L> {
    /// The set of `laws`, material `k` being `laws[k]`.
    ///
    /// # Errors
    /// [`ConstitutiveError::MaterialSetSize`] for no law, or more than a
    /// `u32` tag can name.
    pub fn new(laws: Vec<L>) -> Result<Self> {
        if laws.is_empty() || laws.len() > u32::MAX as usize {
            return Err(ConstitutiveError::MaterialSetSize { count: laws.len() });
        }
        Ok(Self { laws })
    }

    /// The laws, by material index.
    pub fn laws(&self) -> &[L] {
        &self.laws
    }

    /// Whether `tag` names a material of the set (a history read from
    /// outside, e.g. a checkpoint, should be checked with it).
    pub fn contains<H>(&self, tag: &Tagged<H>) -> bool {
        (tag.material as usize) < self.laws.len()
    }

    /// The law of material `material`. Tags are set by whoever places the
    /// points and checked with [`Self::contains`] where they come from
    /// outside; an index past the end is a bug of the caller.
    #[inline]
    pub(crate) fn law(&self, material: u32) -> &L {
        &self.laws[material as usize]
    }
}

impl<L: LogStrainLaw> LogStrainLaw for MaterialSet<L> {
    type History = Tagged<L::History>;

    const SYMMETRIC_TANGENT: bool = L::SYMMETRIC_TANGENT;

    /// Symmetric when every member law's tangent is.
    fn symmetric_tangent(&self) -> bool {
        self.laws.iter().all(LogStrainLaw::symmetric_tangent)
    }

    fn regime(&self, state: &LawState<Self::History>) -> u8 {
        self.law(state.history.material).regime(&untagged(state))
    }

    #[inline]
    fn state_p_wave_modulus(
        &self,
        be: &nalgebra::Matrix3<f64>,
        history: &Self::History,
    ) -> Option<f64> {
        self.law(history.material)
            .state_p_wave_modulus(be, &history.inner)
    }

    #[inline(always)]
    fn return_map(&self, trial: &SymSpectral, history: &Self::History) -> LawState<Self::History> {
        let state = self.law(history.material).return_map(trial, &history.inner);
        LawState {
            tau: state.tau,
            elastic_strain: state.elastic_strain,
            history: Tagged::new(history.material, state.history),
            yielded: state.yielded,
        }
    }

    #[inline(always)]
    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        history: &Self::History,
        state: &LawState<Self::History>,
    ) -> Tensor4 {
        self.law(history.material)
            .algorithmic_tangent(trial, &history.inner, &untagged(state))
    }

    #[inline(always)]
    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &Self::History,
        state: &LawState<Self::History>,
    ) -> Tensor4 {
        self.law(history.material)
            .loading_tangent(trial, &history.inner, &untagged(state))
    }

    #[inline]
    fn point_shear_modulus(&self, history: &Self::History) -> Option<f64> {
        self.law(history.material)
            .point_shear_modulus(&history.inner)
    }
}

/// The member law's state of a set's state (the tag removed).
#[inline]
fn untagged<H: Copy>(state: &LawState<Tagged<H>>) -> LawState<H> {
    LawState {
        tau: state.tau,
        elastic_strain: state.elastic_strain,
        history: state.history.inner,
        yielded: state.yielded,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::{HenckyElastic, VonMises};
    use nalgebra::Matrix3;

    /// Every material of the set answers as its own law: stress, history
    /// and algorithmic tangent, bit for bit.
    #[test]
    fn each_tag_behaves_as_its_own_law() {
        let laws = vec![
            VonMises::new(1e6, 0.3, 1e3, 0.0).unwrap(),
            VonMises::new(5e7, 0.2, 1e9, 1e4).unwrap(),
            VonMises::new(2e5, 0.45, 50.0, 1e5).unwrap(),
        ];
        let set = MaterialSet::new(laws.clone()).unwrap();
        let eps = Matrix3::new(2e-3, 5e-4, 0.0, 5e-4, -1e-3, 2e-4, 0.0, 2e-4, 3e-4);
        let trial = SymSpectral::new(&eps).unwrap();
        for (k, law) in laws.iter().enumerate() {
            let h = Tagged::new(k as u32, Default::default());
            let got = set.return_map(&trial, &h);
            let want = law.return_map(&trial, &h.inner);
            assert_eq!(got.tau, want.tau);
            assert_eq!(got.history.inner, want.history);
            assert_eq!(got.history.material, k as u32);
            assert_eq!(
                set.algorithmic_tangent(&trial, &h, &got),
                law.algorithmic_tangent(&trial, &h.inner, &want)
            );
            // Each point's shear modulus is its material's: E / (2 (1 + ν)).
            let mu = law.elasticity().mu;
            assert_eq!(set.point_shear_modulus(&h), Some(mu));
        }
        let stiff = set.point_shear_modulus(&Tagged::new(1, Default::default()));
        assert!(
            stiff.is_some_and(|m| (m - 5e7 / 2.4).abs() < 1e-9 * m),
            "{stiff:?}"
        );
        // The three differ: yielding in the first and third only.
        let yielded: Vec<bool> = (0..3)
            .map(|k| {
                set.return_map(&trial, &Tagged::new(k, Default::default()))
                    .yielded
            })
            .collect();
        assert_eq!(yielded, [true, false, true]);
        assert!(set.contains(&Tagged::new(2, ())));
        assert!(!set.contains(&Tagged::new(3, ())));
    }

    #[test]
    fn an_empty_set_is_refused() {
        assert!(matches!(
            MaterialSet::<HenckyElastic>::new(Vec::new()),
            Err(ConstitutiveError::MaterialSetSize { count: 0 })
        ));
    }
}
