//! Frictional contact of grid nodes with a rigid flat tool in the implicit
//! solver: a node-to-rigid-surface penalty element with a Coulomb
//! stick/slip return map (Wriggers, *Computational Contact Mechanics*,
//! 2nd ed. 2006, §5.2 and §10.3; Laursen, *Computational Contact and
//! Impact Mechanics*, 2002, §5; Simo & Laursen 1992, *Comput. Struct.*
//! 42:97–116 for the return map and its non-symmetric tangent).
//!
//! The element acts on one node at a time. Its force is incremental over
//! the load step, like a point's stress: the grid is rebuilt every step,
//! so each step starts in contact at the nodes that carry material, with
//! the force the node carried at the end of the last step,
//! $(f_n^0, \mathbf t^0)$, and the relative displacement increment
//! $\mathbf d = \Delta\mathbf u_v - \Delta\mathbf u_{tool}$. With
//! $\mathbf n$ the tool's unit normal pointing into the body and
//! $P = I - \mathbf n\mathbf n^T$:
//!
//! - normal (penalty): $f_n = f_n^0 - k_n\,\mathbf n\cdot\mathbf d$; a
//!   node whose $f_n$ would be tensile ($\le 0$) separates (no force, no
//!   stiffness);
//! - tangential (elastic slip and return map): trial
//!   $\mathbf t^{tr} = P(\mathbf t^0 - k_t\,\mathbf d)$ (opposing the
//!   relative motion); stick if
//!   $|\mathbf t^{tr}| \le \mu f_n$, else slip
//!   $\mathbf t = \mu f_n\,\mathbf s$, $\mathbf s = \mathbf t^{tr}/|\mathbf t^{tr}|$.
//!
//! The force on the body is $\mathbf F = f_n\mathbf n + \mathbf t$, an
//! external force of the node: the residual gains $-\mathbf F$ and the
//! stiffness $K = -\partial\mathbf F/\partial\mathbf d$: in stick
//! $K = k_n\mathbf n\mathbf n^T + k_t P$, in slip
//! $K = k_n\mathbf n\mathbf n^T + \mu k_n\,\mathbf s\mathbf n^T +
//! \frac{\mu f_n k_t}{|\mathbf t^{tr}|}(I - \mathbf s\mathbf s^T)P$,
//! which is not symmetric (the theory page derives both).

use nalgebra::{SMatrix, SVector};

/// The default penalty factor α: $k_n = k_t = \alpha\,2G/h$ per unit
/// area (theory page, "Implicit stick/slip": the contact's compliance is
/// then $1/\alpha$ of that of one cell of the body).
pub const DEFAULT_PENALTY_FACTOR: f64 = 100.0;

/// A rigid flat tool pressing on a set of mesh nodes (a footing, a
/// platen, a base): its normal, its friction and its penalties. The tool's
/// motion is the increment [`crate::Constraints::tool_increment`] gives.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidTool<const D: usize> {
    /// Name (for messages and outputs).
    pub name: String,
    /// The mesh nodes it acts on (sorted ascending, no duplicates).
    pub nodes: Vec<usize>,
    /// Unit normal of the tool's face, pointing into the body.
    pub normal: SVector<f64, D>,
    /// Coulomb coefficient μ ≥ 0; `f64::INFINITY` for a rough tool (pure
    /// stick); 0 for a smooth one.
    pub friction: f64,
    /// Normal penalty per unit area (Pa/m); `None`: the default,
    /// [`DEFAULT_PENALTY_FACTOR`] × 2G / h.
    pub normal_stiffness: Option<f64>,
    /// Tangential penalty per unit area (Pa/m); `None`: the normal one.
    pub tangential_stiffness: Option<f64>,
}

/// The penalties and friction of one node (stiffnesses per node, force
/// per length).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeContact<const D: usize> {
    /// Unit normal into the body.
    pub normal: SVector<f64, D>,
    /// Coulomb coefficient (∞: rough).
    pub friction: f64,
    /// $k_n$.
    pub k_n: f64,
    /// $k_t$.
    pub k_t: f64,
}

/// A node's contact force: normal magnitude and tangential vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactForce<const D: usize> {
    /// $f_n \ge 0$.
    pub normal: f64,
    /// $\mathbf t$ ($\perp\mathbf n$).
    pub tangential: SVector<f64, D>,
}

/// The regime of a node after the return map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// No force (the trial normal force is tensile).
    Separated,
    /// Elastic slip within the cone.
    Stick,
    /// On the cone.
    Slip,
}

/// The response of one node: its force, regime and consistent tangent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactResponse<const D: usize> {
    /// The force on the body.
    pub force: ContactForce<D>,
    /// The regime.
    pub regime: Regime,
    /// $K = -\partial\mathbf F/\partial\mathbf d$.
    pub tangent: SMatrix<f64, D, D>,
}

impl<const D: usize> Default for ContactForce<D> {
    fn default() -> Self {
        Self {
            normal: 0.0,
            tangential: SVector::zeros(),
        }
    }
}

impl<const D: usize> ContactForce<D> {
    /// $\mathbf F = f_n\mathbf n + \mathbf t$.
    pub fn vector(&self, normal: &SVector<f64, D>) -> SVector<f64, D> {
        normal * self.normal + self.tangential
    }
}

impl<const D: usize> NodeContact<D> {
    /// The return map and its tangent at the relative increment `d` from
    /// the committed force `start` (module docs).
    pub fn respond(&self, start: &ContactForce<D>, d: &SVector<f64, D>) -> ContactResponse<D> {
        let n = self.normal;
        let f_n = start.normal - self.k_n * n.dot(d);
        if f_n <= 0.0 {
            return ContactResponse {
                force: ContactForce::default(),
                regime: Regime::Separated,
                tangent: SMatrix::zeros(),
            };
        }
        let nn = n * n.transpose() * self.k_n;
        if self.friction == 0.0 {
            // Smooth: no tangential force whatever the trial.
            return ContactResponse {
                force: ContactForce {
                    normal: f_n,
                    tangential: SVector::zeros(),
                },
                regime: Regime::Slip,
                tangent: nn,
            };
        }
        let p = SMatrix::<f64, D, D>::identity() - n * n.transpose();
        let trial = p * (start.tangential - d * self.k_t);
        let norm = trial.norm();
        let limit = self.friction * f_n;
        if norm <= limit {
            return ContactResponse {
                force: ContactForce {
                    normal: f_n,
                    tangential: trial,
                },
                regime: Regime::Stick,
                tangent: nn + p * self.k_t,
            };
        }
        let s = trial / norm;
        let mu = self.friction;
        let ss = SMatrix::<f64, D, D>::identity() - s * s.transpose();
        ContactResponse {
            force: ContactForce {
                normal: f_n,
                tangential: s * limit,
            },
            regime: Regime::Slip,
            tangent: nn + s * n.transpose() * (mu * self.k_n) + ss * p * (limit * self.k_t / norm),
        }
    }

    /// Whether the tangent may be non-symmetric (μ finite and positive:
    /// the slip tangent).
    pub fn may_be_unsymmetric(&self) -> bool {
        self.friction > 0.0 && self.friction.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no test dependency).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// Central differences of $-\mathbf F$ against the tangent, column by
    /// column; the relative error in the Frobenius norm of the tangent.
    fn fd_error<const D: usize>(
        c: &NodeContact<D>,
        f0: &ContactForce<D>,
        d: &SVector<f64, D>,
        h: f64,
    ) -> f64 {
        let r = c.respond(f0, d);
        let mut fd = SMatrix::<f64, D, D>::zeros();
        for j in 0..D {
            let mut e = SVector::<f64, D>::zeros();
            e[j] = h;
            let plus = c.respond(f0, &(d + e)).force.vector(&c.normal);
            let minus = c.respond(f0, &(d - e)).force.vector(&c.normal);
            fd.set_column(j, &(-(plus - minus) / (2.0 * h)));
        }
        (fd - r.tangent).norm() / r.tangent.norm().max(1e-300)
    }

    fn states<const D: usize>(rng: &mut Lcg, mu: f64) -> (NodeContact<D>, ContactForce<D>) {
        let mut n = SVector::<f64, D>::from_fn(|_, _| rng.next());
        n /= n.norm();
        let p = SMatrix::<f64, D, D>::identity() - n * n.transpose();
        let c = NodeContact {
            normal: n,
            friction: mu,
            k_n: 1e3 * (1.5 + rng.next()),
            k_t: 1e3 * (1.5 + rng.next()),
        };
        let f_n = 2.0 + rng.next();
        let t = p * SVector::<f64, D>::from_fn(|_, _| rng.next()) * 0.3;
        (
            c,
            ContactForce {
                normal: f_n,
                tangential: t,
            },
        )
    }

    /// The tangent of stick and slip against central differences of the
    /// force: random states in each regime, in 2D and 3D. Bound 1e-6:
    /// the force is smooth within a regime, so the central difference's
    /// truncation error is $O(h^2)$ of the curvature (about 1e-10 here)
    /// and its rounding $10^{-16}/h$ relative (about 1e-9); the same bound
    /// as the constitutive finite-difference checks.
    fn check<const D: usize>() {
        let mut rng = Lcg(7 + D as u64);
        let mut seen = [0usize; 3];
        for k in 0..400 {
            let mu = [0.0, 0.3, 0.8, f64::INFINITY][k % 4];
            let (c, f0) = states::<D>(&mut rng, mu);
            // Increments of about the elastic slip f/k: both regimes
            // and, with the scaled ones, the transition.
            let scale = [1e-4, 1e-3, 3e-3][k % 3];
            let d = SVector::<f64, D>::from_fn(|_, _| rng.next()) * scale;
            let r = c.respond(&f0, &d);
            // Near a kink (separation or the cone) the difference
            // straddles two regimes: skip states within 10 h of one.
            let f_n = f0.normal - c.k_n * c.normal.dot(&d);
            let p = SMatrix::<f64, D, D>::identity() - c.normal * c.normal.transpose();
            let trial = (p * (f0.tangential - d * c.k_t)).norm();
            let margin = 1e-5 * (c.k_n + c.k_t);
            if f_n.abs() < margin || (trial - mu * f_n).abs() < margin * (1.0 + mu.min(1e3)) {
                continue;
            }
            seen[r.regime as usize] += 1;
            if r.regime == Regime::Separated {
                continue;
            }
            let e = fd_error(&c, &f0, &d, 1e-7);
            assert!(
                e < 1e-6,
                "D = {D}, {:?}, μ = {mu}: relative error {e:e}",
                r.regime
            );
        }
        assert!(seen[1] > 20 && seen[2] > 20, "states per regime {seen:?}");
    }

    #[test]
    fn stick_and_slip_tangents_match_central_differences() {
        check::<2>();
        check::<3>();
    }

    /// Near the stick/slip transition, from each side: the tangent of the
    /// regime the state is in matches the one-sided limit (the state a
    /// relative 1e-4 of the cone inside or outside).
    #[test]
    fn tangents_match_differences_near_the_transition() {
        let mut rng = Lcg(99);
        for _ in 0..50 {
            let (c, f0) = states::<3>(&mut rng, 0.4);
            // A tangential increment along t⁰ that brings the trial to
            // the cone (1 ± 1e-4).
            let p = SMatrix::<f64, 3, 3>::identity() - c.normal * c.normal.transpose();
            let dir = p * SVector::<f64, 3>::from_fn(|_, _| rng.next());
            let dir = dir / dir.norm();
            let t0 = ContactForce {
                normal: f0.normal,
                tangential: dir * 0.1 * f0.normal,
            };
            for side in [1.0 - 1e-4, 1.0 + 1e-4] {
                let target = 0.4 * f0.normal * side;
                let d = -dir * ((target - 0.1 * f0.normal) / c.k_t);
                let r = c.respond(&t0, &d);
                let expect = if side < 1.0 {
                    Regime::Stick
                } else {
                    Regime::Slip
                };
                assert_eq!(r.regime, expect);
                // A difference step well inside the margin 1e-4 of the
                // cone (k_t h ≈ 2e-6 of a trial force 4e-5 from the cone)
                // keeps both evaluations in the regime.
                let e = fd_error(&c, &t0, &d, 1e-9);
                assert!(e < 1e-6, "{expect:?}: relative error {e:e}");
            }
        }
    }

    /// Smooth (μ = 0) keeps the normal force only; rough (μ = ∞) sticks;
    /// tension separates.
    #[test]
    fn smooth_rough_and_separation() {
        let c = NodeContact::<2> {
            normal: SVector::<f64, 2>::new(0.0, 1.0),
            friction: 0.0,
            k_n: 10.0,
            k_t: 10.0,
        };
        let f0 = ContactForce::default();
        let d = SVector::<f64, 2>::new(0.3, -0.1);
        let r = c.respond(&f0, &d);
        assert_eq!(r.regime, Regime::Slip);
        assert!((r.force.normal - 1.0).abs() < 1e-15 && r.force.tangential.norm() == 0.0);
        let rough = NodeContact {
            friction: f64::INFINITY,
            ..c
        };
        let r = rough.respond(&f0, &d);
        assert_eq!(r.regime, Regime::Stick);
        assert!((r.force.tangential[0] + 3.0).abs() < 1e-14);
        let r = c.respond(&f0, &(-d));
        assert_eq!(r.regime, Regime::Separated);
        assert_eq!(r.force, ContactForce::default());
    }
}
