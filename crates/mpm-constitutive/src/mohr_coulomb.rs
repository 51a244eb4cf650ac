//! Mohr–Coulomb elasto-plasticity with linear cohesion hardening and
//! non-associated flow: the exact multi-surface return in sorted principal
//! Kirchhoff stresses (de Souza Neto, Perić & Owen 2008, §8.2), in Hencky strain by the exponential map.
//!
//! Stresses are tension-positive and sorted $\tau_1\ge\tau_2\ge\tau_3$. The
//! six planes of the pyramid reduce, in sorted order, to the main plane
//! $$ f_1 = (\tau_1 - \tau_3) + (\tau_1 + \tau_3)\sin\phi - 2c\cos\phi,$$
//! with the plastic potential $g_1$ the same with $\psi$ for $\phi$, and
//! the planes $f_2$ meeting it on the two edges: the triaxial-compression
//! edge $\tau_1 = \tau_2$ (pair $(\tau_2, \tau_3)$) and the
//! triaxial-extension edge $\tau_2 = \tau_3$ (pair $(\tau_1, \tau_2)$).
//! With $c = c_0 + H\alpha$ and $\dot\alpha = 2\cos\phi\sum_i\dot\gamma_i$
//! every return is linear in the multipliers, so each regime is solved in
//! closed form:
//! - main plane: $\Delta\gamma = f_1^{tr}/(\mathbf a_1\cdot D\mathbf n_1 +
//!   h)$, $h = 4H\cos^2\phi$;
//! - an edge: the $2\times2$ system $A\Delta\boldsymbol\gamma = \mathbf
//!   f^{tr}$, $A_{ij} = \mathbf a_i\cdot D\mathbf n_j + h$;
//! - the apex ($\phi > 0$ only): $\tau = p\mathbf 1$, $p = c\cot\phi$ with
//!   $\Delta\alpha = \Delta\varepsilon^p_v\cos\phi/\sin\psi$ and
//!   $\Delta\varepsilon^p_v = (p^{tr} - p)/K$ (for $\psi = 0$, where no
//!   flow of the potential changes the volume, the apex hardens as the
//!   associated law does, $\sin\psi \to \sin\phi$; without hardening the
//!   apex is the same either way).
//!
//! The regime is chosen as de Souza Neto et al. do: the main plane when its return keeps
//! the order; otherwise the edge whose order it breaks first; the apex
//! when the edge's multipliers are not both non-negative or its order
//! breaks. At $\phi = 0$ (Tresca) the apex is never formed: $c\cot\phi$
//! does not appear anywhere in that case.
//!
//! The algorithmic tangent of each regime is the derivative of its closed
//! form, made a tensor by [`crate::principal::tangent`].

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::principal::{self, Regime};
use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;
use crate::von_mises::YIELD_TOLERANCE;

/// Internal variables of [`MohrCoulomb`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MohrCoulombHistory {
    /// Accumulated hardening variable $\alpha$ ($c = c_0 + H\alpha$).
    pub alpha: f64,
    /// The regime of the last return.
    pub regime: Regime,
}

/// Mohr–Coulomb plasticity (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MohrCoulomb {
    elasticity: IsotropicElasticity,
    cohesion: f64,
    hardening: f64,
    sin_phi: f64,
    cos_phi: f64,
    sin_psi: f64,
}

/// What a return found, in sorted order.
struct Return {
    regime: Regime,
    /// Plastic multipliers of the planes used (apex: the volumetric
    /// plastic strain in `gamma[0]`).
    gamma: Vector2<f64>,
    /// Returned elastic strain, sorted.
    strain: Vector3<f64>,
}

impl MohrCoulomb {
    /// From Young's modulus `e`, Poisson's ratio `nu`, the cohesion $c_0
    /// \ge 0$, the friction angle $\phi\in[0, 90)$ and dilation angle
    /// $\psi\in[0, \phi]$ in degrees, and the cohesion hardening modulus $H
    /// \ge 0$. A cohesionless law ($c_0 = 0$) needs $\phi > 0$.
    pub fn new(e: f64, nu: f64, cohesion: f64, phi: f64, psi: f64, hardening: f64) -> Result<Self> {
        let elasticity = IsotropicElasticity::new(e, nu)?;
        let (sin_phi, cos_phi, sin_psi) = check_strength(cohesion, phi, psi, hardening)?;
        Ok(Self {
            elasticity,
            cohesion,
            hardening,
            sin_phi,
            cos_phi,
            sin_psi,
        })
    }

    /// The elastic constants.
    pub fn elasticity(&self) -> &IsotropicElasticity {
        &self.elasticity
    }

    /// Cohesion $c_0 + H\alpha$ of a history.
    pub fn cohesion(&self, history: &MohrCoulombHistory) -> f64 {
        self.cohesion + self.hardening * history.alpha
    }

    /// The same law with $c$ and $\tan\phi$ divided by `factor` (strength
    /// reduction), the dilation angle capped at the reduced friction angle.
    pub fn reduced(&self, factor: f64) -> Result<Self> {
        let tan_phi = self.sin_phi / self.cos_phi / factor;
        let phi = tan_phi.atan().to_degrees();
        let psi = self.sin_psi.asin().to_degrees().min(phi);
        let el = &self.elasticity;
        Self::new(
            el.youngs_modulus(),
            el.poisson_ratio(),
            self.cohesion / factor,
            phi,
            psi,
            self.hardening / factor,
        )
    }

    /// The yield function $f_1$ of principal Kirchhoff stresses (any
    /// order).
    pub fn yield_function(&self, tau: &Vector3<f64>, history: &MohrCoulombHistory) -> f64 {
        let (t1, t3) = (tau.max(), tau.min());
        (t1 - t3) + (t1 + t3) * self.sin_phi - 2.0 * self.cohesion(history) * self.cos_phi
    }

    /// Gradient of a plane through the pair `(i, j)` (`i` the larger) with
    /// the sine `s` of the friction or dilation angle.
    fn plane(i: usize, j: usize, s: f64) -> Vector3<f64> {
        let mut a = Vector3::zeros();
        a[i] = 1.0 + s;
        a[j] = -(1.0 - s);
        a
    }

    /// The second plane of an edge regime: `(yield, flow)` gradients.
    fn second_plane(&self, regime: Regime) -> (Vector3<f64>, Vector3<f64>) {
        let (i, j) = match regime {
            Regime::CompressionEdge => (1, 2),
            _ => (0, 1),
        };
        (
            Self::plane(i, j, self.sin_phi),
            Self::plane(i, j, self.sin_psi),
        )
    }

    fn elastic(&self) -> Matrix3<f64> {
        principal::elastic_matrix(self.elasticity.lambda, self.elasticity.mu)
    }

    /// $h = \partial(2c\cos\phi)/\partial\gamma$.
    fn h(&self) -> f64 {
        4.0 * self.hardening * self.cos_phi * self.cos_phi
    }

    /// Below this the trial is elastic: rounding of the stresses' size.
    fn tolerance(&self, sigma: &Vector3<f64>, history: &MohrCoulombHistory) -> f64 {
        YIELD_TOLERANCE * (2.0 * self.cohesion(history) * self.cos_phi).max(sigma.amax())
    }

    /// The return of the sorted trial strain `eps` (module docs).
    fn sorted_return(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Return {
        let de = self.elastic();
        let sigma = de * eps;
        let k = 2.0 * self.cohesion(history) * self.cos_phi;
        let (a1, n1) = (
            Self::plane(0, 2, self.sin_phi),
            Self::plane(0, 2, self.sin_psi),
        );
        let f1 = a1.dot(&sigma) - k;
        if f1 <= self.tolerance(&sigma, history) {
            return Return {
                regime: Regime::Elastic,
                gamma: Vector2::zeros(),
                strain: *eps,
            };
        }
        let dg = f1 / (a1.dot(&(de * n1)) + self.h());
        let strain = eps - dg * n1;
        let t = de * strain;
        if t[0] >= t[1] && t[1] >= t[2] {
            return Return {
                regime: Regime::Plane,
                gamma: Vector2::new(dg, 0.0),
                strain,
            };
        }
        let s = self.sin_psi;
        let regime = if (1.0 - s) * sigma[0] - 2.0 * sigma[1] + (1.0 + s) * sigma[2] < 0.0 {
            Regime::CompressionEdge
        } else {
            Regime::ExtensionEdge
        };
        if let Some(r) = self.edge_return(eps, k, regime) {
            return r;
        }
        if self.sin_phi > 0.0 {
            self.apex_return(eps, history)
        } else {
            // Tresca has no apex; an edge return always exists (c > 0).
            self.edge_return_unchecked(eps, k, regime)
        }
    }

    /// The two planes of an edge (`[a1, n1, a2, n2]`, yield and flow
    /// gradients) and the matrix $A_{ij} = \mathbf a_i\cdot D\mathbf n_j +
    /// h$ of its multipliers.
    fn edge_matrix(&self, regime: Regime) -> ([Vector3<f64>; 4], Matrix2<f64>) {
        let de = self.elastic();
        let (a1, n1) = (
            Self::plane(0, 2, self.sin_phi),
            Self::plane(0, 2, self.sin_psi),
        );
        let (a2, n2) = self.second_plane(regime);
        let h = self.h();
        let a = Matrix2::new(
            a1.dot(&(de * n1)) + h,
            a1.dot(&(de * n2)) + h,
            a2.dot(&(de * n1)) + h,
            a2.dot(&(de * n2)) + h,
        );
        ([a1, n1, a2, n2], a)
    }

    fn edge_system(
        &self,
        eps: &Vector3<f64>,
        k: f64,
        regime: Regime,
    ) -> (Vector2<f64>, Vector3<f64>) {
        let sigma = self.elastic() * eps;
        let ([a1, n1, a2, n2], a) = self.edge_matrix(regime);
        let f = Vector2::new(a1.dot(&sigma) - k, a2.dot(&sigma) - k);
        let gamma = a.lu().solve(&f).unwrap_or_else(Vector2::zeros);
        let strain = eps - gamma[0] * n1 - gamma[1] * n2;
        (gamma, strain)
    }

    fn edge_return_unchecked(&self, eps: &Vector3<f64>, k: f64, regime: Regime) -> Return {
        let (gamma, strain) = self.edge_system(eps, k, regime);
        Return {
            regime,
            gamma,
            strain,
        }
    }

    /// The edge return when valid: both multipliers non-negative and the
    /// order kept.
    fn edge_return(&self, eps: &Vector3<f64>, k: f64, regime: Regime) -> Option<Return> {
        let r = self.edge_return_unchecked(eps, k, regime);
        let t = self.elastic() * r.strain;
        let ordered = match regime {
            Regime::CompressionEdge => t[1] >= t[2],
            _ => t[0] >= t[1],
        };
        (r.gamma.min() >= 0.0 && ordered).then_some(r)
    }

    /// $\cos\phi/\sin\psi$ (module docs: $\sin\phi$ for $\psi = 0$).
    fn apex_hardening(&self) -> f64 {
        let s = if self.sin_psi > 0.0 {
            self.sin_psi
        } else {
            self.sin_phi
        };
        self.cos_phi / s
    }

    /// $r = H k\cot\phi/K$ of the apex return $p(1 + r) = c_n\cot\phi +
    /// r p^{tr}$.
    fn apex_ratio(&self) -> f64 {
        self.hardening * self.apex_hardening() * self.cos_phi / self.sin_phi / self.elasticity.bulk
    }

    fn apex_return(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Return {
        let bulk = self.elasticity.bulk;
        let p_tr = bulk * eps.sum();
        let r = self.apex_ratio();
        let cot = self.cos_phi / self.sin_phi;
        let p = (self.cohesion(history) * cot + r * p_tr) / (1.0 + r);
        let volumetric = (p_tr - p) / bulk;
        Return {
            regime: Regime::Apex,
            gamma: Vector2::new(volumetric, 0.0),
            strain: Vector3::from_element(p / (3.0 * bulk)),
        }
    }

    /// $\partial\tau/\partial\varepsilon$ in sorted order for `regime`,
    /// with the multipliers' rates of the closed forms (module docs).
    fn sorted_tangent(&self, regime: Regime) -> Matrix3<f64> {
        let de = self.elastic();
        let (a1, n1) = (
            Self::plane(0, 2, self.sin_phi),
            Self::plane(0, 2, self.sin_psi),
        );
        match regime {
            Regime::Elastic => de,
            Regime::Plane => {
                let den = a1.dot(&(de * n1)) + self.h();
                de - (de * n1) * (de * a1).transpose() / den
            }
            Regime::CompressionEdge | Regime::ExtensionEdge => {
                let ([_, _, a2, n2], a) = self.edge_matrix(regime);
                let Some(inv) = a.try_inverse() else {
                    return de;
                };
                let rates = (de * a1).transpose();
                let rates2 = (de * a2).transpose();
                let dg1 = inv[(0, 0)] * rates + inv[(0, 1)] * rates2;
                let dg2 = inv[(1, 0)] * rates + inv[(1, 1)] * rates2;
                de - (de * n1) * dg1 - (de * n2) * dg2
            }
            Regime::Apex => {
                let r = self.apex_ratio();
                Matrix3::from_element(self.elasticity.bulk * r / (1.0 + r))
            }
        }
    }

    /// The regime for continued loading from a trial state the return took
    /// as elastic: the plane (or the edge or apex the stresses sit on) when
    /// the trial lies on the surface to rounding, elastic otherwise.
    fn loading_regime(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Regime {
        let sigma = self.elastic() * eps;
        let k = 2.0 * self.cohesion(history) * self.cos_phi;
        let f1 = Self::plane(0, 2, self.sin_phi).dot(&sigma) - k;
        let scale = k.max(sigma.amax());
        if f1 < -1e-10 * scale {
            return Regime::Elastic;
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * scale;
        if self.sin_phi > 0.0 && close(sigma[0], sigma[2]) {
            Regime::Apex
        } else if close(sigma[0], sigma[1]) {
            Regime::CompressionEdge
        } else if close(sigma[1], sigma[2]) {
            Regime::ExtensionEdge
        } else {
            Regime::Plane
        }
    }
}

/// Checks the strength parameters shared by the soil laws; returns $\sin
/// \phi$, $\cos\phi$, $\sin\psi$.
pub(crate) fn check_strength(
    cohesion: f64,
    phi: f64,
    psi: f64,
    hardening: f64,
) -> Result<(f64, f64, f64)> {
    if !(cohesion.is_finite() && cohesion >= 0.0) {
        return Err(ConstitutiveError::InvalidParameter {
            name: "cohesion",
            value: cohesion,
            range: "finite and >= 0",
        });
    }
    if !(phi.is_finite() && (0.0..90.0).contains(&phi)) {
        return Err(ConstitutiveError::InvalidParameter {
            name: "friction angle",
            value: phi,
            range: "in [0, 90) degrees",
        });
    }
    if !(psi.is_finite() && psi >= 0.0 && psi <= phi) {
        return Err(ConstitutiveError::InvalidParameter {
            name: "dilation angle",
            value: psi,
            range: "in [0, friction angle] degrees",
        });
    }
    if !(hardening.is_finite() && hardening >= 0.0) {
        return Err(ConstitutiveError::InvalidHardening { value: hardening });
    }
    if cohesion == 0.0 && phi == 0.0 {
        return Err(ConstitutiveError::InvalidParameter {
            name: "cohesion",
            value: cohesion,
            range: "> 0 when the friction angle is 0 (no strength)",
        });
    }
    let (sin_phi, cos_phi) = phi.to_radians().sin_cos();
    Ok((sin_phi, cos_phi, psi.to_radians().sin()))
}

impl LogStrainLaw for MohrCoulomb {
    type History = MohrCoulombHistory;

    /// Non-associated flow ($\psi \ne \phi$) makes the tangent
    /// unsymmetric; [`MohrCoulomb::symmetric_tangent`] says per law.
    const SYMMETRIC_TANGENT: bool = false;

    fn symmetric_tangent(&self) -> bool {
        self.sin_psi == self.sin_phi
    }

    fn return_map(
        &self,
        trial: &SymSpectral,
        history: &MohrCoulombHistory,
    ) -> LawState<MohrCoulombHistory> {
        let order = principal::descending(&trial.values);
        let eps = principal::sort(&trial.values, order);
        let r = self.sorted_return(&eps, history);
        let strain = principal::unsort(&r.strain, order);
        let alpha = history.alpha
            + match r.regime {
                Regime::Elastic => 0.0,
                Regime::Apex => self.apex_hardening() * r.gamma[0],
                _ => 2.0 * self.cos_phi * r.gamma.sum(),
            };
        LawState {
            tau: self.elasticity.principal_stress(&strain),
            elastic_strain: strain,
            history: MohrCoulombHistory {
                alpha,
                regime: r.regime,
            },
            yielded: r.regime != Regime::Elastic,
        }
    }

    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        _history: &MohrCoulombHistory,
        state: &LawState<MohrCoulombHistory>,
    ) -> Tensor4 {
        if !state.yielded {
            return self.elasticity.stiffness();
        }
        self.tangent_of(trial, state, state.history.regime)
    }

    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &MohrCoulombHistory,
        state: &LawState<MohrCoulombHistory>,
    ) -> Tensor4 {
        if state.yielded {
            return self.tangent_of(trial, state, state.history.regime);
        }
        let order = principal::descending(&trial.values);
        let regime = self.loading_regime(&principal::sort(&trial.values, order), history);
        if regime == Regime::Elastic {
            return self.elasticity.stiffness();
        }
        self.tangent_of(trial, state, regime)
    }

    fn regime(&self, state: &LawState<MohrCoulombHistory>) -> u8 {
        state.history.regime as u8
    }

    fn elasticity(&self) -> Option<IsotropicElasticity> {
        Some(self.elasticity)
    }

    fn stored_energy(&self, elastic_strain: &Vector3<f64>, _h: &MohrCoulombHistory) -> Option<f64> {
        Some(self.elasticity.energy(elastic_strain))
    }
}

impl MohrCoulomb {
    fn tangent_of(
        &self,
        trial: &SymSpectral,
        state: &LawState<MohrCoulombHistory>,
        regime: Regime,
    ) -> Tensor4 {
        let order = principal::descending(&trial.values);
        let d = principal::unsort_matrix(&self.sorted_tangent(regime), order);
        principal::tangent(trial, &state.tau, &d)
    }
}
