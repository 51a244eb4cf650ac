//! Modified Cam-Clay at finite strain (Borja & Tamagnini 1998): hyperelastic
//! pressure-dependent elasticity, the elliptical yield surface, associated
//! flow and exponential hardening, in Hencky strain and Kirchhoff stress by
//! the exponential map.
//!
//! # Equations
//! Tension is positive in $\tau$ and $\varepsilon$, as in the rest of the
//! crate; the invariants are $p = -\tfrac13\mathrm{tr}\,\tau$ (compression
//! positive), $q = \sqrt{3/2}\,\|\operatorname{dev}\tau\|$, and of the
//! elastic strain $\varepsilon_v = \mathrm{tr}\,\varepsilon^e$ (tension
//! positive), $\varepsilon_s = \sqrt{2/3}\,\|\operatorname{dev}
//! \varepsilon^e\|$.
//!
//! - Elasticity (Borja & Tamagnini's hyperelastic model with a constant
//!   shear modulus, so the law is conservative):
//!   $$ \psi = \hat\kappa\,p_r\,e^{-\varepsilon_v/\hat\kappa} + \tfrac32 G
//!   \varepsilon_s^2,\qquad p = p_r e^{-\varepsilon_v/\hat\kappa},\quad q =
//!   3G\varepsilon_s,\quad \tau = -p\,\mathbf 1 + 2G\operatorname{dev}
//!   \varepsilon^e, $$
//!   with the reference pressure $p_r$ at zero elastic volumetric strain
//!   and the tangent bulk modulus $K = p/\hat\kappa$. The pressure is
//!   positive at every strain: the law carries no tension.
//! - Yield surface and associated flow: $f = q^2/M^2 + p\,(p - p_c)$,
//!   $\Delta\varepsilon^p = \Delta\gamma\,\partial f/\partial\tau$.
//! - Hardening, exact exponential: $p_c = \max\big(p_{min},\, p_{c,n}
//!   \exp(x/(\hat\lambda - \hat\kappa))\big)$, with $x = -\Delta
//!   \varepsilon^p_v$ the plastic compaction of the step. Compaction
//!   ($x > 0$, the wet side $p > p_c/2$) hardens, dilation (the dry side)
//!   softens.
//!
//! # The minimum pressure
//! $p_{min} \ge 0$ floors the preconsolidation pressure: a dry-side
//! softening that would take $p_c$ below it leaves $p_c = p_{min}$ (perfect
//! plasticity on the ellipse of size $p_{min}$, [`CamClayRegime::Floor`]),
//! and a compaction from the floor hardens again from $p_{min}$. The elastic
//! domain therefore never shrinks below the ellipse through $p = 0$ and
//! $p = p_{min}$, however far the material is sheared or extended. The
//! history's $p_c$ is read as $\max(p_c, p_{min})$, so the default history
//! is at the floor. With $p_{min} = 0$ (the default) the law is Borja &
//! Tamagnini's; a history with $p_c = 0$ then has an empty elastic domain
//! and the return map ends near $p = 0$ (finite, but meaningless): give
//! such a law a history from [`ModifiedCamClay::history_for`].
//!
//! # Return map
//! The trial state $(\varepsilon^{tr}_v, q^{tr})$ of the trial elastic
//! strain returns along the deviatoric direction $\hat u = \operatorname{dev}
//! \varepsilon^{tr}/\|\operatorname{dev}\varepsilon^{tr}\|$: the unknowns
//! $\Delta\gamma$ and $x$ satisfy
//! $$ x = \Delta\gamma\,(2p - p_c),\qquad p = p_r e^{-(\varepsilon^{tr}_v +
//!   x)/\hat\kappa},\qquad q = \frac{q^{tr}}{1 + 6G\Delta\gamma/M^2},\qquad
//!   F(\Delta\gamma) = \frac{q^2}{M^2} + p\,(p - p_c) = 0. $$
//! For given $\Delta\gamma \ge 0$ the first equation has exactly one root
//! $x$ (its left side minus its right side increases with $x$), between 0
//! and the compaction $x^*$ that puts the state on the critical-state line
//! $2p = p_c$ (closed form); it is solved by a safeguarded Newton method.
//! The consistency condition $F(\Delta\gamma) = 0$ is solved by a second
//! safeguarded Newton method with $dF/d\Delta\gamma$ from the implicit
//! derivative of $x$: $F(0) > 0$ and $F \to -p(x^*)^2 < 0$ as
//! $\Delta\gamma \to\infty$, so a root is bracketed (by doubling) and the
//! iteration bisects (geometrically while the bracket spans decades)
//! whenever Newton leaves the bracket or would not halve its last step.
//! The multiplier is the unknown rather than $x$: for a trial on the
//! critical-state line $x = 0$ whatever $\Delta\gamma$, so $x$ does not
//! determine $\Delta\gamma$ near there, where the undrained and drained
//! paths end. Both sides of the ellipse, wet (hardening) and dry
//! (softening), take the same path. The return converges to rounding; it
//! never panics and, at worst (a degenerate history), returns the best
//! bracketed iterate.
//!
//! # Consistent tangent
//! Differentiating the two local equations $R_1 = x - \Delta\gamma(2p -
//! p_c)$ and $R_2 = F$ with respect to $a = \varepsilon^{tr}_v$ and $b =
//! q^{tr}$,
//! $$ \begin{pmatrix} 1 + \Delta\gamma(2p/\hat\kappa + h_c) & -(2p - p_c)
//!   \\ -p\,((2p - p_c)/\hat\kappa + h_c) & -2\,c\,\xi q^2/M^2 \end{pmatrix}
//!   \frac{\partial(x, \Delta\gamma)}{\partial(a, b)} = -\frac{\partial(R_1,
//!   R_2)}{\partial(a, b)}, $$
//! with $c = 6G/M^2$, $\xi = 1/(1 + c\Delta\gamma)$ and $h_c = dp_c/dx$
//! ($p_c/(\hat\lambda - \hat\kappa)$, 0 at the floor), gives
//! $\partial p/\partial(a, b)$ and $\partial q/\partial(a, b)$. With
//! $\tau_a = -p + \sqrt{2/3}\,q\,\hat u_a$ the principal tangent is
//! $$ \frac{\partial\tau_a}{\partial\varepsilon_b} = -\mathbf 1\otimes
//!   \Big(p_{,a}\mathbf 1 + \sqrt6 G\,p_{,b}\hat u\Big) + \sqrt{\tfrac23}\,
//!   \hat u\otimes\Big(q_{,a}\mathbf 1 + \sqrt6 G\,q_{,b}\hat u\Big) +
//!   2G\xi\,(\mathbb I^{dev} - \hat u\otimes\hat u), $$
//! the last term turning the deviatoric direction as for
//! [`crate::DruckerPrager`]'s cone ($\hat u = 0$ for an isotropic trial),
//! assembled into $D^{alg}$ by [`principal::tangent`]. The elastic tangent
//! is $K\,\mathbf 1\otimes\mathbf 1 + 2G\,\mathbb I^{dev}$, $K = p/\hat
//! \kappa$. The loading tangent at a trial on the surface is the plastic
//! one with $\Delta\gamma = 0$.
//!
//! Although the flow is associated and the elasticity hyperelastic,
//! $D^{alg}$ is **not** major-symmetric in a hardening step: the hardening
//! variable moves with $\partial f/\partial p$, not with $\partial f /
//! \partial p_c$ (no generalised normality), which leaves
//! $\partial q/\partial\varepsilon_v^{tr} + 3G\,\partial p/\partial q^{tr}
//! \propto q\,\Delta\gamma\,h_c\,p_c \ne 0$. It is symmetric when elastic, at
//! the floor (perfect plasticity) and for the loading tangent
//! ($\Delta\gamma = 0$); [`LogStrainLaw::symmetric_tangent`] is false.
//!
//! # Initial state and wave speed
//! The law has no stress-free state: a scene starts from an initial
//! stress through [`ModifiedCamClay::elastic_strain_of`] (the inverse of
//! the elasticity) and [`ModifiedCamClay::history_for`] (the yield locus
//! through it, scaled by the over-consolidation ratio). The bulk modulus
//! grows with the pressure, so an explicit solver takes its P-wave modulus
//! at a stated pressure bound, [`ModifiedCamClay::p_wave_modulus_at`].
//!
//! Sources: R. I. Borja and C. Tamagnini (1998), Cam-Clay plasticity, Part
//! III: Extension of the infinitesimal model to include finite strains,
//! CMAME 155:73–95 (here with a constant $G$); de Souza Neto, Perić & Owen
//! (2008), *Computational Methods for Plasticity*, ch. 10 (the modified
//! Cam-Clay model) and Appendix A (the principal tangent).

use nalgebra::{Matrix2, Matrix3, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::law::{LawState, LogStrainLaw};
use crate::principal;
use crate::spectral::SymSpectral;
use crate::tensor::{Tensor4, dyad, sym_identity};
use crate::von_mises::YIELD_TOLERANCE;

/// Exponents are clamped to this before `exp`, so that an absurd trial
/// (a compression of hundreds of $\hat\kappa$) gives a huge, finite
/// pressure rather than infinity.
const MAX_EXPONENT: f64 = 700.0;

/// Iteration cap of each safeguarded Newton method: they take 3–10
/// iterations; the cap leaves room for bisecting any bracket to rounding.
const MAX_ITERATIONS: usize = 200;

/// A trial counts as on the surface (for the loading tangent) when
/// $f \ge -$`ON_SURFACE` $s^2$, $s = \max(p, p_c, q/M)$.
const ON_SURFACE: f64 = 1e-10;

/// What the last return did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum CamClayRegime {
    /// No plastic flow.
    #[default]
    Elastic = 0,
    /// Plastic flow with exponential hardening (or softening) of $p_c$.
    Hardening = 1,
    /// Plastic flow with $p_c$ held at the floor $p_{min}$ (perfect
    /// plasticity).
    Floor = 2,
}

impl CamClayRegime {
    /// The regime of a stored code (elastic for an unknown one).
    pub fn from_code(code: u8) -> Self {
        match code {
            1 => Self::Hardening,
            2 => Self::Floor,
            _ => Self::Elastic,
        }
    }
}

/// Internal variables of [`ModifiedCamClay`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ModifiedCamClayHistory {
    /// Preconsolidation pressure $p_c$ (compression positive), read as
    /// $\max(p_c, p_{min})$.
    pub preconsolidation: f64,
    /// The plastic multiplier $\Delta\gamma$ of the step that produced this
    /// history (0 when elastic): the algorithmic tangent needs it.
    pub multiplier: f64,
    /// The regime of that step.
    pub regime: CamClayRegime,
}

impl ModifiedCamClayHistory {
    /// A converged (elastic) history with preconsolidation pressure
    /// `preconsolidation`.
    pub fn new(preconsolidation: f64) -> Self {
        Self {
            preconsolidation,
            ..Self::default()
        }
    }
}

/// Modified Cam-Clay (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModifiedCamClay {
    lambda: f64,
    kappa: f64,
    slope: f64,
    shear: f64,
    reference: f64,
    minimum: f64,
}

/// The trial state of a return.
#[derive(Debug, Clone, Copy)]
struct Trial {
    /// $\varepsilon^{tr}_v$.
    ev: f64,
    /// $q^{tr}$.
    q: f64,
    /// Unit deviatoric direction (zero for an isotropic trial).
    u: Vector3<f64>,
    /// $\max(p_{c,n}, p_{min})$.
    pc: f64,
}

/// The local state at given $(x, \Delta\gamma)$.
#[derive(Debug, Clone, Copy)]
struct Local {
    x: f64,
    dgamma: f64,
    p: f64,
    q: f64,
    pc: f64,
    /// $dp_c/dx$ (0 at the floor).
    hc: f64,
    /// $\xi = 1/(1 + 6G\Delta\gamma/M^2)$.
    xi: f64,
}

impl Local {
    /// $2p - p_c$.
    fn g(&self) -> f64 {
        2.0 * self.p - self.pc
    }

    /// The largest stress of the state, the scale of the yield function.
    fn scale(&self, slope: f64) -> f64 {
        self.p.max(self.pc).max(self.q / slope)
    }
}

/// Invariants $(p, q)$ of principal Kirchhoff stresses: $p = -\tfrac13
/// \mathrm{tr}\,\tau$ (compression positive), $q = \sqrt{3/2}\,
/// \|\operatorname{dev}\tau\|$.
pub fn invariants(tau: &Vector3<f64>) -> (f64, f64) {
    let mean = tau.sum() / 3.0;
    (-mean, 1.5f64.sqrt() * tau.map(|t| t - mean).norm())
}

fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ConstitutiveError::InvalidParameter {
            name,
            value,
            range: "positive and finite",
        })
    }
}

impl ModifiedCamClay {
    /// From the slope $\hat\lambda$ of the normal compression line and the
    /// slope $\hat\kappa$ of the unloading line in $(\ln p, \varepsilon_v)$
    /// ($\hat\lambda > \hat\kappa > 0$), the critical-state slope $M > 0$,
    /// the shear modulus $G > 0$ and the reference pressure $p_r > 0$ at
    /// zero elastic volumetric strain; no minimum pressure
    /// ([`Self::with_minimum_pressure`]).
    ///
    /// # Errors
    /// [`ConstitutiveError::InvalidParameter`] for a value out of range.
    pub fn new(
        lambda: f64,
        kappa: f64,
        slope: f64,
        shear_modulus: f64,
        reference_pressure: f64,
    ) -> Result<Self> {
        let kappa = positive("κ̂ (swelling index)", kappa)?;
        if !(lambda.is_finite() && lambda > kappa) {
            return Err(ConstitutiveError::InvalidParameter {
                name: "λ̂ (compression index)",
                value: lambda,
                range: "finite and greater than κ̂",
            });
        }
        Ok(Self {
            lambda,
            kappa,
            slope: positive("M (critical-state slope)", slope)?,
            shear: positive("G (shear modulus)", shear_modulus)?,
            reference: positive("p_r (reference pressure)", reference_pressure)?,
            minimum: 0.0,
        })
    }

    /// The same law with the floor $p_{min} \ge 0$ on the preconsolidation
    /// pressure (module docs, "The minimum pressure").
    ///
    /// # Errors
    /// [`ConstitutiveError::InvalidParameter`] for a negative or non-finite
    /// value.
    pub fn with_minimum_pressure(self, minimum: f64) -> Result<Self> {
        if !(minimum.is_finite() && minimum >= 0.0) {
            return Err(ConstitutiveError::InvalidParameter {
                name: "p_min (minimum pressure)",
                value: minimum,
                range: "non-negative and finite",
            });
        }
        Ok(Self { minimum, ..self })
    }

    /// $\hat\lambda$.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// $\hat\kappa$.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// $M$.
    pub fn slope(&self) -> f64 {
        self.slope
    }

    /// $G$.
    pub fn shear_modulus(&self) -> f64 {
        self.shear
    }

    /// $p_r$.
    pub fn reference_pressure(&self) -> f64 {
        self.reference
    }

    /// $p_{min}$.
    pub fn minimum_pressure(&self) -> f64 {
        self.minimum
    }

    /// The pressure $p = p_r e^{-\varepsilon_v/\hat\kappa}$ of the elastic
    /// volumetric strain `ev` (tension positive).
    pub fn pressure(&self, ev: f64) -> f64 {
        self.reference * (-ev / self.kappa).min(MAX_EXPONENT).exp()
    }

    /// The tangent bulk modulus $K = p/\hat\kappa$ at pressure `p`.
    pub fn bulk_modulus_at(&self, p: f64) -> f64 {
        p / self.kappa
    }

    /// The P-wave modulus $K + \tfrac43 G$ at the pressure bound `p_max`
    /// ($K = p_{max}/\hat\kappa$): an upper bound of the wave speed's
    /// modulus wherever $p \le p_{max}$, for
    /// [`crate::Spectral::with_p_wave_modulus`]. The caller states the
    /// bound (e.g. the largest initial pressure with a margin for the
    /// loading).
    ///
    /// # Errors
    /// [`ConstitutiveError::InvalidParameter`] unless `p_max` is positive
    /// and finite.
    pub fn p_wave_modulus_at(&self, p_max: f64) -> Result<f64> {
        let p = positive("pressure bound p_max", p_max)?;
        Ok(self.bulk_modulus_at(p) + 4.0 / 3.0 * self.shear)
    }

    /// The yield function $f = q^2/M^2 + p(p - p_c)$ of principal
    /// Kirchhoff stresses `tau`.
    pub fn yield_function(&self, tau: &Vector3<f64>, history: &ModifiedCamClayHistory) -> f64 {
        let (p, q) = invariants(tau);
        q * q / (self.slope * self.slope) + p * (p - self.preconsolidation(history))
    }

    /// The preconsolidation pressure of `history` as the law reads it,
    /// $\max(p_c, p_{min})$.
    pub fn preconsolidation(&self, history: &ModifiedCamClayHistory) -> f64 {
        history.preconsolidation.max(self.minimum)
    }

    /// The principal elastic strain whose stress is `tau` (principal
    /// Kirchhoff stresses, compression negative): $\varepsilon_v =
    /// -\hat\kappa\ln(p/p_r)$, $\operatorname{dev}\varepsilon =
    /// \operatorname{dev}\tau/(2G)$. With $\Delta F = \mathbf 1$ and $b^e =
    /// \exp(2\varepsilon)$ a point starts at that stress.
    ///
    /// # Errors
    /// [`ConstitutiveError::InvalidParameter`] unless $p$ is positive and
    /// finite (the law carries no tension).
    pub fn elastic_strain_of(&self, tau: &Vector3<f64>) -> Result<Vector3<f64>> {
        let p = positive("initial mean pressure p = -tr τ/3", -tau.sum() / 3.0)?;
        let ev = -self.kappa * (p / self.reference).ln();
        Ok(tau.map(|t| ev / 3.0 + (t + p) / (2.0 * self.shear)))
    }

    /// The history of a point at the stress `tau` with over-consolidation
    /// ratio `ocr` $\ge 1$: $p_c = \mathrm{OCR}\,(p + q^2/(M^2 p))$, the
    /// ellipse through `tau` scaled by the ratio (at least $p_{min}$).
    ///
    /// # Errors
    /// [`ConstitutiveError::InvalidParameter`] for $p \le 0$ or an `ocr`
    /// below 1 or not finite.
    pub fn history_for(&self, tau: &Vector3<f64>, ocr: f64) -> Result<ModifiedCamClayHistory> {
        if !(ocr.is_finite() && ocr >= 1.0) {
            return Err(ConstitutiveError::InvalidParameter {
                name: "over-consolidation ratio",
                value: ocr,
                range: "finite and at least 1",
            });
        }
        let (p, q) = invariants(tau);
        let p = positive("initial mean pressure p = -tr τ/3", p)?;
        let pc = ocr * (p + q * q / (self.slope * self.slope * p));
        Ok(ModifiedCamClayHistory::new(pc.max(self.minimum)))
    }

    /// $\hat\lambda - \hat\kappa$.
    fn plastic_index(&self) -> f64 {
        self.lambda - self.kappa
    }

    /// $c = 6G/M^2$.
    fn c(&self) -> f64 {
        6.0 * self.shear / (self.slope * self.slope)
    }

    fn trial(&self, eps: &Vector3<f64>, history: &ModifiedCamClayHistory) -> Trial {
        let ev = eps.sum();
        let dev = eps.map(|e| e - ev / 3.0);
        let norm = dev.norm();
        let u = if norm > 0.0 {
            dev / norm
        } else {
            Vector3::zeros()
        };
        Trial {
            ev,
            q: 6f64.sqrt() * self.shear * norm,
            u,
            pc: self.preconsolidation(history),
        }
    }

    /// $p_c$ after the compaction `x` from `pcn`, and $dp_c/dx$.
    fn hardened(&self, pcn: f64, x: f64) -> (f64, f64) {
        let pc = pcn * (x / self.plastic_index()).min(MAX_EXPONENT).exp();
        if pc < self.minimum {
            (self.minimum, 0.0)
        } else {
            (pc, pc / self.plastic_index())
        }
    }

    fn local(&self, t: &Trial, x: f64, dgamma: f64) -> Local {
        let (pc, hc) = self.hardened(t.pc, x);
        let xi = 1.0 / (1.0 + self.c() * dgamma);
        Local {
            x,
            dgamma,
            p: self.pressure(t.ev + x),
            q: t.q * xi,
            pc,
            hc,
            xi,
        }
    }

    /// $F$ of a local state.
    fn consistency(&self, l: &Local) -> f64 {
        l.q * l.q / (self.slope * self.slope) + l.p * (l.p - l.pc)
    }

    /// The compaction $x^*$ onto the critical-state line $2p = p_c$: the
    /// smaller root of $2p = p_{c,n}e^{x/(\hat\lambda-\hat\kappa)}$ and $2p
    /// = p_{min}$ (both sides decrease with $x$). A vanishing floor is
    /// replaced by $10^{-300}p_r$ so that the bracket stays finite for a
    /// degenerate history.
    fn critical_compaction(&self, t: &Trial) -> f64 {
        let k = self.kappa;
        let hardening_root = if t.pc > 0.0 {
            ((2.0 * self.reference / t.pc).ln() - t.ev / k) / (1.0 / k + 1.0 / self.plastic_index())
        } else {
            f64::INFINITY
        };
        let floor = self.minimum.max(1e-300 * self.reference);
        hardening_root.min(k * (2.0 * self.reference / floor).ln() - t.ev)
    }

    /// The compaction $x$ at the multiplier `dgamma` (module docs,
    /// "Return map"): the root of $x - \Delta\gamma(2p - p_c)$, increasing
    /// in $x$, in the bracket between 0 and `x_star`, from `guess`.
    fn compaction(&self, t: &Trial, dgamma: f64, x_star: f64, guess: f64) -> Local {
        if dgamma <= 0.0 {
            return self.local(t, 0.0, 0.0);
        }
        let (mut lo, mut hi) = (x_star.min(0.0), x_star.max(0.0));
        let mut x = guess.clamp(lo, hi);
        let mut last_step = f64::INFINITY;
        for _ in 0..MAX_ITERATIONS {
            let l = self.local(t, x, dgamma);
            let h = x - dgamma * l.g();
            if h > 0.0 {
                hi = x;
            } else if h < 0.0 {
                lo = x;
            } else {
                return l;
            }
            let newton = x - h / (1.0 + dgamma * (2.0 * l.p / self.kappa + l.hc));
            if (newton - x).abs() <= 1e-15 * (x.abs() + self.kappa) {
                return self.local(t, newton, dgamma);
            }
            // Far from the root Newton crawls (by about κ̂ a step down an
            // exponential): bisect when a step would not halve the last.
            let next = if newton > lo && newton < hi && (newton - x).abs() <= 0.5 * last_step {
                newton
            } else {
                0.5 * (lo + hi)
            };
            last_step = (next - x).abs();
            if hi - lo <= 1e-15 * (x.abs() + self.kappa) {
                return self.local(t, next, dgamma);
            }
            x = next;
        }
        self.local(t, x, dgamma)
    }

    /// $dF/d\Delta\gamma$ along the root $x(\Delta\gamma)$.
    fn consistency_slope(&self, l: &Local) -> f64 {
        let m2 = self.slope * self.slope;
        let dq = -self.c() * l.xi * l.q;
        let dx = l.g() / (1.0 + l.dgamma * (2.0 * l.p / self.kappa + l.hc));
        let dfdx = -l.g() * l.p / self.kappa - l.p * l.hc;
        2.0 * l.q / m2 * dq + dfdx * dx
    }

    /// The midpoint of a bisection of $[lo, hi]$ in $\Delta\gamma$:
    /// geometric while the ends are orders of magnitude apart (the root
    /// may lie decades below a first overshoot), arithmetic otherwise.
    fn midpoint(lo: f64, hi: f64) -> f64 {
        if lo <= 0.0 {
            1e-3 * hi
        } else if hi > 4.0 * lo {
            (lo * hi).sqrt()
        } else {
            0.5 * (lo + hi)
        }
    }

    /// The plastic return of a trial with $F(0) > 0$ (module docs): a
    /// safeguarded Newton method on $F(\Delta\gamma)$, the bracket
    /// $[0, \infty)$ closed by doubling.
    fn plastic_return(&self, t: &Trial) -> Local {
        let x_star = self.critical_compaction(t);
        let (mut lo, mut hi) = (0.0, f64::INFINITY);
        let mut l = self.local(t, 0.0, 0.0);
        let mut best = (f64::INFINITY, l);
        let mut last_step = f64::INFINITY;
        for _ in 0..MAX_ITERATIONS {
            let f = self.consistency(&l);
            let scale = l.scale(self.slope);
            if f.abs() / (scale * scale) < best.0 {
                best = (f.abs() / (scale * scale), l);
            }
            if f > 0.0 {
                lo = l.dgamma;
            } else if f < 0.0 {
                hi = l.dgamma;
            } else {
                return l;
            }
            let newton = l.dgamma - f / self.consistency_slope(&l);
            let fast = (newton - l.dgamma).abs() <= 0.5 * last_step || hi.is_infinite();
            let (next, converged) =
                if l.dgamma > 0.0 && (newton - l.dgamma).abs() <= 1e-14 * l.dgamma {
                    (newton, true)
                } else if newton > lo && newton < hi && fast {
                    (newton, false)
                } else if hi.is_finite() {
                    (Self::midpoint(lo, hi), hi - lo <= 1e-15 * hi)
                } else {
                    (2.0 * l.dgamma.max(0.5 / self.c()), false)
                };
            last_step = (next - l.dgamma).abs();
            l = self.compaction(t, next, x_star, l.x);
            if converged {
                return l;
            }
        }
        let scale = l.scale(self.slope);
        if self.consistency(&l).abs() / (scale * scale) < best.0 {
            l
        } else {
            best.1
        }
    }

    /// Principal stresses of the elastic strain `eps`.
    fn stress(&self, eps: &Vector3<f64>) -> Vector3<f64> {
        let ev = eps.sum();
        let p = self.pressure(ev);
        eps.map(|e| -p + 2.0 * self.shear * (e - ev / 3.0))
    }

    /// $\partial\tau_a/\partial\varepsilon_b$ at the local state `l` of the
    /// trial `t` (module docs, "Consistent tangent").
    fn principal_tangent(&self, t: &Trial, l: &Local) -> Matrix3<f64> {
        let (k, m2, c) = (self.kappa, self.slope * self.slope, self.c());
        let g = l.g();
        let jac = Matrix2::new(
            1.0 + l.dgamma * (2.0 * l.p / k + l.hc),
            -g,
            -l.p * (g / k + l.hc),
            -2.0 * c * l.xi * l.q * l.q / m2,
        );
        let rhs = Matrix2::new(
            -2.0 * l.dgamma * l.p / k,
            0.0,
            g * l.p / k,
            -2.0 * l.q * l.xi / m2,
        );
        // Singular only where dry-side softening exhausts the local
        // stiffness: the multiplier is then taken as fixed.
        let d = jac.lu().solve(&rhs).unwrap_or_else(Matrix2::zeros);
        let (p_a, p_b) = (-l.p / k * (1.0 + d[(0, 0)]), -l.p / k * d[(0, 1)]);
        let (q_a, q_b) = (
            -c * l.q * l.xi * d[(1, 0)],
            l.xi - c * l.q * l.xi * d[(1, 1)],
        );
        let one = Vector3::from_element(1.0);
        let r6g = 6f64.sqrt() * self.shear;
        let uu = t.u * t.u.transpose();
        let dev = Matrix3::identity() - Matrix3::from_element(1.0 / 3.0);
        -one * (p_a * one + r6g * p_b * t.u).transpose()
            + (2.0f64 / 3.0).sqrt() * t.u * (q_a * one + r6g * q_b * t.u).transpose()
            + 2.0 * self.shear * l.xi * (dev - uu)
    }

    /// The elastic stiffness $K\,\mathbf 1\otimes\mathbf 1 + 2G\,\mathbb
    /// I^{dev}$ at the elastic strain `eps`.
    fn elastic_stiffness(&self, eps: &Vector3<f64>) -> Tensor4 {
        let one = Matrix3::identity();
        let bulk = self.bulk_modulus_at(self.pressure(eps.sum()));
        (bulk - 2.0 * self.shear / 3.0) * dyad(&one, &one) + 2.0 * self.shear * sym_identity()
    }

    /// The local state at $\Delta\gamma = 0$ of a trial on the surface,
    /// floored when it would soften at the floor; `None` when the trial is
    /// inside the surface.
    fn loading_state(&self, t: &Trial) -> Option<Local> {
        let mut l = self.local(t, 0.0, 0.0);
        let scale = l.scale(self.slope);
        if self.consistency(&l) < -ON_SURFACE * scale * scale {
            return None;
        }
        if l.pc <= self.minimum && l.g() < 0.0 {
            l.hc = 0.0;
        }
        Some(l)
    }
}

impl LogStrainLaw for ModifiedCamClay {
    type History = ModifiedCamClayHistory;

    /// The hardening makes the tangent unsymmetric (module docs).
    const SYMMETRIC_TANGENT: bool = false;

    /// $p/\hat\kappa + \tfrac43G$ at the elastic volumetric strain
    /// $\varepsilon_v = \tfrac12\ln\det b^e$ (no eigen-decomposition).
    #[inline]
    fn state_p_wave_modulus(
        &self,
        be: &nalgebra::Matrix3<f64>,
        _history: &ModifiedCamClayHistory,
    ) -> Option<f64> {
        let ev = 0.5 * be.determinant().ln();
        Some(self.bulk_modulus_at(self.pressure(ev)) + 4.0 / 3.0 * self.shear)
    }

    fn return_map(
        &self,
        trial: &SymSpectral,
        history: &ModifiedCamClayHistory,
    ) -> LawState<ModifiedCamClayHistory> {
        let eps = &trial.values;
        let t = self.trial(eps, history);
        let at_trial = self.local(&t, 0.0, 0.0);
        let scale = at_trial.scale(self.slope);
        if self.consistency(&at_trial) <= YIELD_TOLERANCE * scale * scale {
            return LawState {
                tau: self.stress(eps),
                elastic_strain: *eps,
                history: ModifiedCamClayHistory::new(t.pc),
                yielded: false,
            };
        }
        let l = self.plastic_return(&t);
        let ev = t.ev + l.x;
        let strain = eps.map(|e| ev / 3.0 + l.xi * (e - t.ev / 3.0));
        let regime = if l.hc > 0.0 {
            CamClayRegime::Hardening
        } else {
            CamClayRegime::Floor
        };
        LawState {
            tau: eps.map(|e| -l.p + 2.0 * self.shear * l.xi * (e - t.ev / 3.0)),
            elastic_strain: strain,
            history: ModifiedCamClayHistory {
                preconsolidation: l.pc,
                multiplier: l.dgamma,
                regime,
            },
            yielded: true,
        }
    }

    fn algorithmic_tangent(
        &self,
        trial: &SymSpectral,
        history: &ModifiedCamClayHistory,
        state: &LawState<ModifiedCamClayHistory>,
    ) -> Tensor4 {
        if !state.yielded {
            return self.elastic_stiffness(&trial.values);
        }
        let t = self.trial(&trial.values, history);
        let (p, _) = invariants(&state.tau);
        let h = &state.history;
        let xi = 1.0 / (1.0 + self.c() * h.multiplier);
        let l = Local {
            x: state.elastic_strain.sum() - t.ev,
            dgamma: h.multiplier,
            p,
            q: t.q * xi,
            pc: h.preconsolidation,
            hc: match h.regime {
                CamClayRegime::Floor => 0.0,
                _ => h.preconsolidation / self.plastic_index(),
            },
            xi,
        };
        principal::tangent(trial, &state.tau, &self.principal_tangent(&t, &l))
    }

    fn loading_tangent(
        &self,
        trial: &SymSpectral,
        history: &ModifiedCamClayHistory,
        state: &LawState<ModifiedCamClayHistory>,
    ) -> Tensor4 {
        if state.yielded {
            return self.algorithmic_tangent(trial, history, state);
        }
        let t = self.trial(&trial.values, history);
        match self.loading_state(&t) {
            Some(l) => principal::tangent(trial, &state.tau, &self.principal_tangent(&t, &l)),
            None => self.elastic_stiffness(&trial.values),
        }
    }

    fn regime(&self, state: &LawState<ModifiedCamClayHistory>) -> u8 {
        state.history.regime as u8
    }

    fn point_shear_modulus(&self, _history: &ModifiedCamClayHistory) -> Option<f64> {
        Some(self.shear)
    }

    /// $\psi = \hat\kappa p + G\|\operatorname{dev}\varepsilon^e\|^2$
    /// (module docs).
    fn stored_energy(
        &self,
        elastic_strain: &Vector3<f64>,
        _history: &ModifiedCamClayHistory,
    ) -> Option<f64> {
        let ev = elastic_strain.sum();
        let dev = elastic_strain.map(|e| e - ev / 3.0);
        Some(self.kappa * self.pressure(ev) + self.shear * dev.norm_squared())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> ModifiedCamClay {
        ModifiedCamClay::new(0.2, 0.05, 1.2, 1e6, 1e3).expect("valid parameters")
    }

    #[test]
    fn the_elastic_strain_of_a_stress_gives_that_stress() {
        let law = law();
        let tau = Vector3::new(-80e3, -120e3, -150e3);
        let eps = law.elastic_strain_of(&tau).expect("compression");
        let err = (law.stress(&eps) - tau).norm() / tau.norm();
        assert!(err < 1e-14, "{err:e}");
    }

    #[test]
    fn the_stored_energy_is_the_potential_of_the_stress() {
        let law = law();
        let eps = Vector3::new(-0.21, -0.18, -0.25);
        let h = ModifiedCamClayHistory::default();
        let psi = |e: Vector3<f64>| law.stored_energy(&e, &h).unwrap_or(f64::NAN);
        let step = 1e-6;
        for a in 0..3 {
            let mut d = Vector3::zeros();
            d[a] = step;
            let fd = (psi(eps + d) - psi(eps - d)) / (2.0 * step);
            let tau = law.stress(&eps)[a];
            assert!(
                (fd - tau).abs() < 1e-6 * tau.abs(),
                "{a}: {fd} against {tau}"
            );
        }
    }
}
