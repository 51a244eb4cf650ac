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
//!
//! # Tension cut-off
//! The pyramid admits tensile principal stresses up to its apex $c\cot
//! \phi$, far more than a soil carries: in uniaxial tension it fails at
//! $2c\cos\phi/(1 + \sin\phi)$. [`MohrCoulomb::with_tension_cutoff`]
//! adds the Rankine criterion $\tau_a \le \sigma_t$ on every principal
//! stress, perfectly plastic with associated flow, $\sigma_t\le c_0\cot
//! \phi$ so that it cuts the apex (de Souza Neto, Perić & Owen 2008,
//! ch. 8: the multi-surface return by active sets; §8.2 for the pyramid).
//! In sorted order the surfaces are the planes
//! $$ P_1 = f_1,\quad P_2: (\tau_2, \tau_3),\quad P_3: (\tau_1,
//!   \tau_2),\qquad T_a = \tau_a - \sigma_t, $$
//! $P_2$ and $P_3$ the planes of the compression and extension edges, the
//! flow of $T_a$ the unit vector $\mathbf e_a$. Elasticity is linear and
//! only the Mohr–Coulomb planes harden, so every active set $\mathcal A$
//! is the linear system $A\Delta\boldsymbol\gamma = \mathbf f^{tr}$,
//! $A_{ij} = \mathbf a_i\cdot D\mathbf n_j + h_{ij}$ with $h_{ij} = h$
//! when both planes are Mohr–Coulomb planes and 0 otherwise, the elastic
//! strain $\varepsilon^{tr} - \sum_j\Delta\gamma_j\mathbf n_j$ and
//! $\Delta\alpha = 2\cos\phi$ times the sum of the Mohr–Coulomb
//! multipliers.
//!
//! The pyramid's return is kept whenever it ends with $\tau_1\le
//! \sigma_t$ (then it satisfies every condition of the combined problem;
//! without a cut-off nothing changes). Otherwise the faces, edges and
//! vertices of the cut pyramid in the sorted sector are tried in turn, the
//! first valid one taken:
//!
//! | regime | active set | stresses |
//! | --- | --- | --- |
//! | [`Regime::Tension`] | $T_1$ | $\tau_1 = \sigma_t$ |
//! | [`Regime::TensionPlane`] | $P_1, T_1$ | $\tau_1 = \sigma_t$, $\tau_3$ on $P_1$ |
//! | [`Regime::TensionEdge`] | $T_1, T_2$ | $\tau_1 = \tau_2 = \sigma_t$ |
//! | [`Regime::TensionExtensionEdge`] | $P_1, P_3, T_1$ | $\tau_1 = \sigma_t$, $\tau_2 = \tau_3$ on $P_1$ |
//! | [`Regime::TensionCompressionEdge`] | $P_1, (P_2,) T_1, T_2$ | $\tau_1 = \tau_2 = \sigma_t$, $\tau_3$ on $P_1$ |
//! | [`Regime::TensionApex`] | $T_1, T_2, T_3$ | $\tau = \sigma_t\mathbf 1$ |
//!
//! Valid means: multipliers $\ge 0$, every plane satisfied with the
//! hardened cohesion and the order $\tau_1\ge\tau_2\ge\tau_3$ kept, all
//! to rounding. Nothing else can be active: $T_1$ alone is smooth across
//! $\tau_2 = \tau_3$ (a return to it never breaks that order), and the
//! pyramid's apex lies beyond the cut-off. The apex of the cut-off is
//! always admissible and the last resort.
//!
//! One vertex is degenerate. Where the compression edge meets the tension
//! edge four planes pass through one point: $P_1$ and $P_2$ coincide on
//! $\tau_1 = \tau_2$ ($\mathbf a_{P_1} - \mathbf a_{P_2} = (1 +
//! \sin\phi)(\mathbf e_1 - \mathbf e_2)$). The stress there is fixed by
//! $\{P_1, T_1, T_2\}$ and its hardening, whatever the split of the
//! Mohr–Coulomb multiplier $\Gamma$ between $P_1$ and $P_2$, so that
//! system is solved; its multipliers $(\Gamma, g_1, g_2)$ are valid when
//! some split leaves all four non-negative, i.e. $\Gamma\ge0$, $g_2\ge
//! 0$, $g_1 + g_2\ge0$ and $\Gamma(1 + \sin\psi) + g_1\ge0$. Requiring
//! $g_1\ge0$ instead (no $P_2$) rejects part of the trials of that
//! vertex, which then fall through to the apex of the cut-off, a wrong
//! stress (e.g. $\sigma_t\mathbf 1$ for $(\sigma_t, \sigma_t, -19.6)$ kPa
//! at $c = 10$ kPa, $\phi = \psi = 30°$, $\sigma_t = 5$ kPa).
//!
//! The tangent of an active set is the derivative of its linear system,
//! $$ \frac{\partial\tau}{\partial\varepsilon} = D - \sum_{ij}
//!   (D\mathbf n_i)(A^{-1})_{ij}(D\mathbf a_j)^T, $$
//! zero at the apex of the cut-off. The tension planes are associated,
//! so with $\psi = \phi$ every $A$ and tangent is symmetric. With $\psi
//! \ne\phi$ the tangents of the cut-off are symmetric still: $\mathbf
//! a_{P_1} - \mathbf n_{P_1} = (\sin\phi - \sin\psi)(\mathbf e_1 +
//! \mathbf e_3)$ lies in the span of the active gradients whenever $T_1$
//! is active, so flows and gradients span the same space and, without
//! hardening, the tangent is $D - DG(G^TDG)^{-1}G^TD$ ($G$ the gradients)
//! for either; the hardening moves the stress along one direction,
//! $A^{-T}\mathbf m$ with $\mathbf m$ marking the Mohr–Coulomb planes,
//! the same for both ($\mathbf e_3$, or $\mathbf e_2 + \mathbf e_3$ on
//! the extension edge). The pyramid's own regimes are not, so
//! [`LogStrainLaw::symmetric_tangent`] ($\psi = \phi$) is unchanged by
//! the cut-off.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::law::{IsotropicElasticity, LawState, LogStrainLaw};
use crate::principal::{self, Regime};
use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;
use crate::von_mises::YIELD_TOLERANCE;

/// The tensile strength of a strength-reduction trial at `factor`:
/// $\sigma_t/F$, capped at the pyramid's apex $c_0\cot\phi$ (`apex`,
/// `None` for $\phi = 0$), which the reduction does not move
/// ($(c_0/F)\cot\phi_F = c_0\cot\phi$): for $F \ge 1$ the reduced
/// cut-off still cuts the apex, for $F < 1$ (a strength increase) it would
/// not without the cap. [`MohrCoulomb::reduced`] and the scene's reduced
/// parameters share this rule.
pub fn reduced_tensile_strength(tension: f64, apex: Option<f64>, factor: f64) -> f64 {
    let reduced = tension / factor;
    apex.map_or(reduced, |apex| reduced.min(apex))
}

/// Relative rounding by which a tensile strength may exceed the apex
/// $c_0\cot\phi$ ([`MohrCoulomb::with_tension_cutoff`]).
pub const APEX_SLACK: f64 = 1e-12;

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
    /// The tensile strength $\sigma_t$ of the cut-off, if any.
    tension: Option<f64>,
}

/// What a return found, in sorted order.
struct Return {
    regime: Regime,
    /// Plastic multipliers of the planes used (apex: the volumetric
    /// plastic strain in `gamma[0]`; a return to the cut-off: the sum of
    /// its Mohr–Coulomb multipliers in `gamma[0]`).
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
            tension: None,
        })
    }

    /// The same law with the tension cut-off (Rankine) $\tau_a \le
    /// \sigma_t$ at the tensile strength $\sigma_t$ = `tensile_strength`
    /// (module docs, "Tension cut-off"): finite, $\ge 0$ and, for a
    /// friction angle $\phi > 0$, at most $c_0\cot\phi$, so that the
    /// cut-off cuts the apex of the pyramid. A value above the apex by rounding ([`APEX_SLACK`]
    /// relative, e.g. $c_0/\tan\phi$ against $c_0\cos\phi/\sin\phi$) is
    /// taken as the apex.
    pub fn with_tension_cutoff(self, tensile_strength: f64) -> Result<Self> {
        if !(tensile_strength.is_finite() && tensile_strength >= 0.0) {
            return Err(ConstitutiveError::InvalidParameter {
                name: "tensile strength",
                value: tensile_strength,
                range: "finite and >= 0",
            });
        }
        let apex = self.apex_bound().unwrap_or(f64::INFINITY);
        if tensile_strength > apex * (1.0 + APEX_SLACK) {
            return Err(ConstitutiveError::InvalidParameter {
                name: "tensile strength",
                value: tensile_strength,
                range: "<= c0 cot(friction angle), the apex of the pyramid (the cut-off must cut it)",
            });
        }
        Ok(Self {
            tension: Some(tensile_strength.min(apex)),
            ..self
        })
    }

    /// The tensile strength $\sigma_t$ of the cut-off, `None` without one.
    pub fn tension_cutoff(&self) -> Option<f64> {
        self.tension
    }

    /// $c_0\cot\phi$, the apex of the pyramid, for $\phi > 0$.
    fn apex_bound(&self) -> Option<f64> {
        (self.sin_phi > 0.0).then(|| self.cohesion * self.cos_phi / self.sin_phi)
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
    /// reduction), the dilation angle capped at the reduced friction angle,
    /// and the tensile strength divided by `factor` too. The reduced apex
    /// $(c_0/F)\cot\phi_F = c_0\cot\phi$ does not move, so for $F \ge 1$
    /// the reduced cut-off $\sigma_t/F$ still cuts it; for $F < 1$ (a
    /// strength increase) $\sigma_t/F$ is capped at the apex.
    pub fn reduced(&self, factor: f64) -> Result<Self> {
        let law = self.reduced_pyramid(factor)?;
        let Some(tension) = self.tension else {
            return Ok(law);
        };
        law.with_tension_cutoff(reduced_tensile_strength(tension, law.apex_bound(), factor))
    }

    /// [`Self::reduced`] without the cut-off.
    fn reduced_pyramid(&self, factor: f64) -> Result<Self> {
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

    /// The return of the sorted trial strain `eps` (module docs): to the
    /// pyramid, and past the cut-off when that leaves $\tau_1 > \sigma_t$.
    fn sorted_return(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Return {
        let r = self.pyramid_return(eps, history);
        let Some(t) = self.tension else {
            return r;
        };
        let tol = self.tolerance(&(self.elastic() * eps), history);
        if (self.elastic() * r.strain).max() <= t + tol {
            return r;
        }
        self.tension_return(eps, history, t, tol)
    }

    /// The return of the sorted trial strain `eps` to the pyramid alone.
    fn pyramid_return(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Return {
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
            Regime::Tension
            | Regime::TensionPlane
            | Regime::TensionEdge
            | Regime::TensionExtensionEdge
            | Regime::TensionCompressionEdge
            | Regime::TensionApex => self.active_tangent(regime),
        }
    }

    /// The regime for continued loading from a trial state the return took
    /// as elastic: the plane (or the edge or apex the stresses sit on) when
    /// the trial lies on the surface to rounding, elastic otherwise.
    fn loading_regime(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Regime {
        let regime = self.pyramid_loading_regime(eps, history);
        match self.tension {
            Some(t) => self.tension_loading_regime(eps, history, t, regime),
            None => regime,
        }
    }

    /// [`Self::loading_regime`] of the pyramid alone.
    fn pyramid_loading_regime(&self, eps: &Vector3<f64>, history: &MohrCoulombHistory) -> Regime {
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

/// A plane of the yield surface in sorted principal stresses (module docs,
/// "Tension cut-off").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Surface {
    /// The Mohr–Coulomb plane through the pair `(i, j)`, `i` the larger:
    /// $P_1 = (0, 2)$, $P_2 = (1, 2)$, $P_3 = (0, 1)$.
    Shear(usize, usize),
    /// The tension plane $T_{a+1}$: $\tau_a = \sigma_t$.
    Tension(usize),
}

const P1: Surface = Surface::Shear(0, 2);
const P3: Surface = Surface::Shear(0, 1);
const T1: Surface = Surface::Tension(0);
const T2: Surface = Surface::Tension(1);
const T3: Surface = Surface::Tension(2);

/// The active sets tried, in order, when the pyramid's return leaves
/// $\tau_1 > \sigma_t$; [`Regime::TensionApex`] is the last resort.
const CANDIDATES: [Regime; 5] = [
    Regime::Tension,
    Regime::TensionPlane,
    Regime::TensionEdge,
    Regime::TensionExtensionEdge,
    Regime::TensionCompressionEdge,
];

/// The planes solved for in a regime of the cut-off ($P_2$ of
/// [`Regime::TensionCompressionEdge`] coincides with $P_1$ there and is
/// left out: module docs).
fn active_set(regime: Regime) -> &'static [Surface] {
    match regime {
        Regime::Tension => &[T1],
        Regime::TensionPlane => &[P1, T1],
        Regime::TensionEdge => &[T1, T2],
        Regime::TensionExtensionEdge => &[P1, P3, T1],
        Regime::TensionCompressionEdge => &[P1, T1, T2],
        Regime::TensionApex => &[T1, T2, T3],
        _ => &[],
    }
}

/// The gradients and multipliers of an active set: yield gradients $\mathbf
/// a_i$ and flow directions $\mathbf n_i$ as columns (zero past the set's
/// size) and $A_{ij} = \mathbf a_i\cdot D\mathbf n_j + h_{ij}$ (the
/// identity past the set's size, so that unused multipliers vanish).
struct ActiveSystem {
    a: Matrix3<f64>,
    n: Matrix3<f64>,
    matrix: Matrix3<f64>,
}

impl MohrCoulomb {
    /// Yield gradient and flow direction of a plane.
    fn gradients(&self, surface: Surface) -> (Vector3<f64>, Vector3<f64>) {
        match surface {
            Surface::Shear(i, j) => (
                Self::plane(i, j, self.sin_phi),
                Self::plane(i, j, self.sin_psi),
            ),
            Surface::Tension(a) => {
                let e = Vector3::ith(a, 1.0);
                (e, e)
            }
        }
    }

    fn active_system(&self, set: &[Surface]) -> ActiveSystem {
        let (mut a, mut n) = (Matrix3::zeros(), Matrix3::zeros());
        for (i, &surface) in set.iter().enumerate() {
            let (ai, ni) = self.gradients(surface);
            a.set_column(i, &ai);
            n.set_column(i, &ni);
        }
        let mut matrix = a.transpose() * self.elastic() * n;
        for i in 0..3 {
            for j in 0..3 {
                match (set.get(i), set.get(j)) {
                    (Some(Surface::Shear(..)), Some(Surface::Shear(..))) => {
                        matrix[(i, j)] += self.h();
                    }
                    (Some(_), Some(_)) => {}
                    _ => matrix[(i, j)] = if i == j { 1.0 } else { 0.0 },
                }
            }
        }
        ActiveSystem { a, n, matrix }
    }

    /// The return of the sorted trial `eps` with the planes of `regime`
    /// active, from the strengths $k = 2c_n\cos\phi$ and $\sigma_t$ = `t`,
    /// and all its multipliers; `None` if $A$ is singular.
    fn active_return(
        &self,
        eps: &Vector3<f64>,
        k: f64,
        t: f64,
        regime: Regime,
    ) -> Option<(Return, Vector3<f64>)> {
        let set = active_set(regime);
        let system = self.active_system(set);
        let sigma = self.elastic() * eps;
        let f = Vector3::from_fn(|i, _| match set.get(i) {
            Some(Surface::Shear(..)) => system.a.column(i).dot(&sigma) - k,
            Some(Surface::Tension(_)) => system.a.column(i).dot(&sigma) - t,
            None => 0.0,
        });
        let gamma = system.matrix.lu().solve(&f)?;
        let shear: f64 = set
            .iter()
            .zip(gamma.iter())
            .filter(|(s, _)| matches!(s, Surface::Shear(..)))
            .map(|(_, g)| g)
            .sum();
        let r = Return {
            regime,
            gamma: Vector2::new(shear, 0.0),
            strain: eps - system.n * gamma,
        };
        Some((r, gamma))
    }

    /// Whether a return of [`Self::active_return`] solves the problem:
    /// multipliers non-negative, every plane satisfied with the hardened
    /// cohesion and the order kept, all to `tol` (a stress; multipliers to
    /// `tol`$/\mu$).
    fn admissible(
        &self,
        r: &Return,
        gamma: &Vector3<f64>,
        history: &MohrCoulombHistory,
        t: f64,
        tol: f64,
    ) -> bool {
        let tau = self.elastic() * r.strain;
        let hardened = MohrCoulombHistory {
            alpha: history.alpha + 2.0 * self.cos_phi * r.gamma[0],
            regime: r.regime,
        };
        let ordered = tau[0] >= tau[1] - tol && tau[1] >= tau[2] - tol;
        ordered
            && self.flows_forward(r.regime, gamma) >= -tol / self.elasticity.mu
            && self.yield_function(&tau, &hardened) <= tol
            && tau.max() <= t + tol
    }

    /// The smallest multiplier of a return; on
    /// [`Regime::TensionCompressionEdge`] the smallest of the conditions
    /// that some split of the main-plane multiplier between $P_1$ and
    /// $P_2$ leaves all four non-negative (module docs).
    fn flows_forward(&self, regime: Regime, gamma: &Vector3<f64>) -> f64 {
        if regime != Regime::TensionCompressionEdge {
            return gamma.min();
        }
        let first = gamma[0] * (1.0 + self.sin_psi) + gamma[1];
        gamma[0].min(gamma[2]).min(gamma[1] + gamma[2]).min(first)
    }

    /// The return past the cut-off: the first admissible candidate, else
    /// the apex of the cut-off.
    fn tension_return(
        &self,
        eps: &Vector3<f64>,
        history: &MohrCoulombHistory,
        t: f64,
        tol: f64,
    ) -> Return {
        let k = 2.0 * self.cohesion(history) * self.cos_phi;
        CANDIDATES
            .iter()
            .find_map(|&regime| {
                let (r, gamma) = self.active_return(eps, k, t, regime)?;
                self.admissible(&r, &gamma, history, t, tol).then_some(r)
            })
            .unwrap_or(Return {
                regime: Regime::TensionApex,
                gamma: Vector2::zeros(),
                strain: Vector3::from_element(t / (3.0 * self.elasticity.bulk)),
            })
    }

    /// $D - \sum_{ij}(D\mathbf n_i)(A^{-1})_{ij}(D\mathbf a_j)^T$ of a
    /// regime of the cut-off (zero at its apex).
    fn active_tangent(&self, regime: Regime) -> Matrix3<f64> {
        let de = self.elastic();
        if regime == Regime::TensionApex {
            return Matrix3::zeros();
        }
        let system = self.active_system(active_set(regime));
        let Some(inv) = system.matrix.try_inverse() else {
            return de;
        };
        de - (de * system.n) * inv * (de * system.a).transpose()
    }

    /// [`Self::loading_regime`] with the cut-off: the regime of the planes
    /// the stresses sit on when $\tau_1 = \sigma_t$ to rounding, `pyramid`
    /// (the pyramid's loading regime) otherwise.
    fn tension_loading_regime(
        &self,
        eps: &Vector3<f64>,
        history: &MohrCoulombHistory,
        t: f64,
        pyramid: Regime,
    ) -> Regime {
        let sigma = self.elastic() * eps;
        let k = 2.0 * self.cohesion(history) * self.cos_phi;
        let scale = k.max(sigma.amax());
        if sigma[0] < t - 1e-10 * scale {
            return pyramid;
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * scale;
        let shear = pyramid != Regime::Elastic;
        match (close(sigma[0], sigma[1]), close(sigma[1], sigma[2])) {
            (true, true) => Regime::TensionApex,
            (true, false) if shear => Regime::TensionCompressionEdge,
            (true, false) => Regime::TensionEdge,
            (false, true) if shear => Regime::TensionExtensionEdge,
            _ if shear => Regime::TensionPlane,
            _ => Regime::Tension,
        }
    }
}
