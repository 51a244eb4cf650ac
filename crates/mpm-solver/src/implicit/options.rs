//! Newton–Raphson controls.

/// Halvings of a Newton correction that inverts a material point before
/// the step fails.
pub const MAX_BACKTRACKS: usize = 10;

/// Newton–Raphson controls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Tolerance on the normalised out-of-balance force, eq. (40).
    pub tolerance: f64,
    /// Maximum number of iterations (linear solves) per step.
    pub max_iterations: usize,
    /// The step is declared divergent when the normalised residual exceeds
    /// this factor times its value at iteration 0.
    pub divergence_factor: f64,
    /// Nodes whose support volume $\sum_p S_{vp}V^n_p$ and stiffness
    /// weight $\sum_p |\nabla S_{vp}|^2 V^n_p$ are both below this
    /// fraction of the largest are held fixed over the step. Such fringe
    /// nodes (a GIMP domain or B-spline stencil barely reaching them) add
    /// next to no stiffness; left free they make the stiffness nearly
    /// singular, and the nearly arbitrary increments they receive would
    /// move the points through $S_{vp}\Delta u_v$ (eq. 31). A node whose
    /// value vanishes at its points but whose gradient does not (a linear
    /// simplex's node opposite a point lying on an edge) is not held: it
    /// sets the point's strain. Zero disables the rule.
    pub weak_node_threshold: f64,
    /// Nodes whose stiffness weight $\sum_p |\nabla S_{vp}|^2 V^n_p$ is below
    /// this fraction of the largest are held fixed over the step too. For
    /// domain-based bases (GIMP, CPDI2, B-splines) value and gradient of a
    /// fringe node vanish together, so holding it adds a reaction of the
    /// order of $\sigma\,\nabla S_{vp}V_p$, which is small; left free, two
    /// such nodes touched by one point only form a mechanism (a rotation
    /// that strains no point) along which Newton iterates run away.
    /// Standard MPM's far-side nodes keep gradients of order $1/h$ and are
    /// not affected. Zero disables the rule.
    pub weak_node_stiffness: f64,
    /// Start each step's iterations from the previous step's converged
    /// increment, scaled by the ratio of load increments, at the free
    /// nodes that were active then (a secant predictor). Off, the free
    /// nodes start at zero increment, as in Coombs et al. 2020. The
    /// predictor saves iterations on smooth load paths and keeps Newton on
    /// the branch of the previous step where the equilibrium path has
    /// bifurcations (perfect plasticity).
    pub predictor: bool,
    /// Largest admissible $\max(\|\Delta F\|_F, \|\Delta F^{-1}\|_F)$ of
    /// any material point within one load step (the identity has
    /// $\sqrt3$; 10 allows principal stretches from about 0.1 to 9.9). An
    /// iterate beyond it fails the step, which is retried with a smaller
    /// increment: Newton iterates that slide along a near-mechanism grow a
    /// point's stretch geometrically while the Hencky stress
    /// $\propto \ln\lambda/\lambda$ and hence the residual decay, and would
    /// otherwise "converge" with the point flung far away.
    pub max_increment_norm: f64,
    /// Accept an iterate whose Newton iteration has stalled (removed less
    /// than half of the residual) with an out-of-balance force within this
    /// factor of its estimated rounding noise, although eq. (40) is above
    /// `tolerance` ([`crate::stages::convergence::NewtonMonitor`]). The
    /// noise is $u\sum_p\|T_p\|_F|\nabla S_{vp}|$ per node: absolute, so
    /// on small increments of stiff bodies the normalised residual cannot
    /// fall below about floor/reaction (measured on the Wang 2021 §5.1
    /// footing with 0.1 mm steps: 0.34 of the estimate for standard MPM,
    /// 0.9 for F-patch, i.e. 4e-10 and 1.5e-9 against a 1e-9 tolerance).
    /// Zero restores eq. (40) alone.
    pub rounding_floor_factor: f64,
    /// The tangent of a step's first solve when the step starts from
    /// prescribed increments alone (no predictor).
    pub first_tangent: FirstTangent,
    /// The ghost penalty on the faces of cut cells
    /// ([`crate::stages::ghost`]; off by default). It needs a regular grid
    /// and a law with an elastic shear modulus.
    pub ghost: crate::stages::ghost::GhostPenalty,
    /// The linear solver [`crate::ImplicitSolver::new`] builds.
    pub linear: crate::linear::LinearChoice,
}

/// Which state the first Newton solve of a displacement-driven step
/// linearises about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FirstTangent {
    /// The converged state at the start of the step, as a finite-element
    /// code that imposes the prescribed increments in its first solve
    /// (e.g. AMPLE): $K_{ff}(0)\Delta\mathbf u_f = \mathbf f^{ext}_f -
    /// \mathbf f^{int}_f(0) - K_{fp}(0)\Delta\mathbf u_p$
    /// ([`crate::ImplicitSolver`]'s `linearised_start`), one assembly and
    /// solve more per step, then Newton from that iterate. Without it,
    /// Newton starts from the prescribed increments alone, where the layer
    /// of elements next to the driven nodes carries the whole increment:
    /// past yield it linearises about that layer's plastic (for perfect
    /// plasticity, deviatorically singular) tangent, the first correction
    /// concentrates the increment in it and the step can diverge although
    /// the equilibrium it seeks is elastic.
    #[default]
    Converged,
    /// The trial state of the prescribed increments (plain Newton from
    /// that iterate).
    Trial,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 30,
            divergence_factor: 1e6,
            weak_node_threshold: 1e-6,
            weak_node_stiffness: 1e-4,
            predictor: false,
            max_increment_norm: 10.0,
            rounding_floor_factor: 10.0,
            first_tangent: FirstTangent::Converged,
            ghost: crate::stages::ghost::GhostPenalty::OFF,
            linear: crate::linear::LinearChoice::default(),
        }
    }
}
