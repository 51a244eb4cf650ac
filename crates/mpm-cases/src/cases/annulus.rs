//! Elastic annulus under torsion (Coombs et al. 2020 §7.4, Figs. 18–19):
//! an annulus $R_i = 0.75 \le R \le R_o = 1.25$ m on an unstructured mesh
//! of linear triangles, E = 1 Pa, ν = 0, both rims fixed, loaded by the
//! body force that makes the rotation field
//!
//! $$\theta(R) = \alpha\,\frac{16(R-R_i)^2(R-R_o)^2}{(R_i-R_o)^4}$$
//!
//! (eq. 44) the exact solution (method of manufactured solutions),
//! $\alpha = 0.1$ rad over 10 equal load steps. The displacement error
//! converges with mesh refinement at the rate of the linear basis (2) when
//! enough points per element are used (Fig. 19).
//!
//! # The manufactured body force
//! A material point at $\mathbf X = R(\cos\Theta, \sin\Theta)$ moves to
//! $\mathbf x = R(\cos\varphi, \sin\varphi)$, $\varphi = \Theta + \theta(R)$:
//! the radius is kept, so the current radius $r = R$. With
//! $\mathrm d\mathbf x = \mathrm dR\,\mathbf e_r + R\,\mathrm d\varphi\,
//! \mathbf e_\varphi$ and $\mathrm d\varphi = \mathrm d\Theta +
//! \theta'\mathrm dR$,
//!
//! $$\mathbf F = \mathbf Q\,(\mathbf I + \gamma\,\mathbf e_\Theta\otimes
//! \mathbf e_R), \qquad \gamma(R) = R\,\theta'(R),$$
//!
//! where $\mathbf Q$ rotates $(\mathbf e_R, \mathbf e_\Theta)$ onto
//! $(\mathbf e_r, \mathbf e_\varphi)$: a rigid rotation of a simple shear
//! of amount $\gamma$ with shear direction $\mathbf e_\Theta$ and normal
//! $\mathbf e_R$. $\det\mathbf F = 1$. Hencky elasticity is isotropic, so
//! the Cauchy stress is the rotated simple-shear stress; for an isochoric
//! shear it does not depend on $\lambda$ (the log strain is traceless):
//!
//! $$\sigma_{\varphi\varphi} = -\sigma_{rr} = s_{11}(\gamma) = 2\mu\,
//! \frac{\gamma\,\mathrm{asinh}(\gamma/2)}{\sqrt{\gamma^2+4}},\qquad
//! \sigma_{r\varphi} = s_{12}(\gamma) = 2\mu\,\frac{2\,\mathrm{asinh}(\gamma/2)}
//! {\sqrt{\gamma^2+4}}$$
//!
//! (the closed form of the shear case). The fields depend on $r$ only, so
//! equilibrium in polar coordinates, $\nabla\cdot\boldsymbol\sigma +
//! \mathbf b = \mathbf 0$, gives the body force per current volume
//!
//! $$b_r = s_{11}'(\gamma)\,\gamma' + \frac{2 s_{11}}{r},\qquad
//! b_\varphi = -s_{12}'(\gamma)\,\gamma' - \frac{2 s_{12}}{r},\qquad
//! \gamma' = \theta' + r\,\theta'',$$
//!
//! with $s_{11}' = 2\mu\,[\gamma/(\gamma^2+4) + 4\,\mathrm{asinh}(\gamma/2)/
//! (\gamma^2+4)^{3/2}]$ and $s_{12}' = 2\mu\,[2/(\gamma^2+4) -
//! 2\gamma\,\mathrm{asinh}(\gamma/2)/(\gamma^2+4)^{3/2}]$. Since $J = 1$
//! it is also the force per reference volume, so point $p$ carries
//! $\mathbf b(\mathbf X_p)\,V^0_p$ at the load's current $\alpha$,
//! directed along $(\mathbf e_r, \mathbf e_\varphi)$ at the current angle.
//! The tests check $s_{11}', s_{12}'$ against finite differences and
//! $\mathbf b$ against a finite-difference divergence of the stress that
//! the constitutive update computes from $\mathbf F$.

use std::path::PathBuf;

use mpm_solver::SolverError;
use nalgebra::Vector2;
use serde_json::json;

use super::{Case, Measured, Run, Solve, Solved};
use crate::material::MaterialModel;
use crate::run::RunOutput;
use crate::scene::format::{
    BodySpec, BoundaryKind, BoundarySpec, LoadSpec, MaterialSpec, MeshSpec, RegionSpec, SolverSpec,
};
use crate::scene::{Problem, Scene};
use crate::session::Session;
use crate::variant::Variant;

pub use crate::manufactured::Torsion;

crate::case_params! {
    /// Parameters of the annulus case (defaults: the paper's values).
    pub struct AnnulusParams {
        /// Target element size h (m): the generated mesh has
        /// round((R_o − R_i)/h) layers and round(2π R_o/h) nodes per ring.
        pub h: f64 = 0.125,
        /// Material points per triangle: n² at the centroids of the n²
        /// sub-triangles of n divisions per edge (the paper's 1², 2², 3², 4²).
        pub points_per_element: usize = 3,
        /// Inner radius R_i (m).
        pub inner_radius: f64 = 0.75,
        /// Outer radius R_o (m).
        pub outer_radius: f64 = 1.25,
        /// Rotation amplitude α (rad), eq. (44).
        pub alpha: f64 = 0.1,
        /// Young's modulus (Pa).
        pub youngs_modulus: f64 = 1.0,
        /// Poisson's ratio.
        pub poisson_ratio: f64 = 0.0,
        /// Number of equal load steps.
        pub load_steps: usize = 10,
        /// Newton tolerance on eq. (40).
        pub tolerance: f64 = 1e-9,
        /// Jitter of the generated mesh's interior nodes (fraction of the
        /// radial and angular steps, at most 0.2), so that the mesh is not
        /// structured.
        pub jitter: f64 = 0.0,
        /// A Gmsh MSH 4.1 file of linear triangles with physical groups
        /// `inner` and `outer` (the rims) instead of the generated mesh;
        /// relative paths are taken from the scene file's directory.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub mesh: Option<PathBuf> = None,
    }
}

/// The registered case (see [`crate::cases::Case`]).
#[derive(Debug, Clone, Copy)]
pub struct AnnulusCase;

impl Case for AnnulusCase {
    const NAME: &'static str = "annulus";
    const ABOUT: &'static str = "Coombs 2020 §7.4: elastic annulus under torsion on triangles (manufactured solution, Fig. 19)";
    type Params = AnnulusParams;

    fn scene(p: &AnnulusParams, variant: &Variant) -> Result<Scene, SolverError> {
        scene(p, variant)
    }
}

/// The annulus's result.
#[derive(Debug, Clone)]
pub struct AnnulusResult {
    /// The run.
    pub output: RunOutput<2>,
    /// Volume-weighted mean displacement error (m),
    /// $\sum_p |\mathbf u_p - \mathbf u^a(\mathbf X_p)| V^0_p / \sum_p V^0_p$.
    pub error: f64,
    /// Largest point displacement error (m).
    pub max_error: f64,
    /// Number of material points.
    pub material_points: usize,
    /// Number of triangles.
    pub elements: usize,
    /// Mean element size, $\sqrt{2A/n_e}$ (m).
    pub element_size: f64,
}

/// The annulus as a typed scene (the scene of `scenes/coombs2020_annulus.toml`
/// with the parameters filled in): the generated annulus mesh of element
/// size about `h` (round((R_o − R_i)/h) layers, at least 2, and
/// round(2π R_o/h) nodes per ring, at least 8), or the Gmsh file `mesh`
/// (linear triangles with physical groups `inner`, `outer` and `domain`);
/// both rims fixed; the manufactured body force of eq. (44).
///
/// # Errors
/// [`SolverError::InvalidInput`] for a non-positive `h` or a variant other
/// than standard MPM.
pub fn scene(p: &AnnulusParams, variant: &Variant) -> Result<Scene, SolverError> {
    variant
        .require_standard_mpm("triangles")
        .map_err(SolverError::InvalidInput)?;
    let mesh = match &p.mesh {
        Some(path) => MeshSpec::gmsh(path.display().to_string(), 2),
        None => {
            if !(p.h > 0.0 && p.h.is_finite()) {
                return Err(SolverError::InvalidInput(format!(
                    "h = {} must be positive",
                    p.h
                )));
            }
            let radial = ((p.outer_radius - p.inner_radius) / p.h).ceil().max(2.0) as usize;
            let ring = (2.0 * std::f64::consts::PI * p.outer_radius / p.h)
                .round()
                .max(8.0) as usize;
            MeshSpec::annulus(p.inner_radius, p.outer_radius, radial, ring).with_jitter(p.jitter, 1)
        }
    };
    let material = MaterialSpec::new(
        "annulus",
        MaterialModel::Hencky,
        p.youngs_modulus,
        p.poisson_ratio,
        0.0,
    );
    let body = BodySpec::new("annulus", "annulus", RegionSpec::group("domain"))
        .with_points_per_cell(p.points_per_element);
    let torsion = [
        ("inner_radius", p.inner_radius),
        ("outer_radius", p.outer_radius),
        ("alpha", p.alpha),
    ];
    Ok(Scene::new(mesh, vec![material], vec![body])
        .with_boundary(BoundarySpec::on("inner", BoundaryKind::Fixed))
        .with_boundary(BoundarySpec::on("outer", BoundaryKind::Fixed))
        .with_load(LoadSpec::manufactured("annulus_torsion", torsion))
        .with_solver(SolverSpec::implicit(variant, p.load_steps, p.tolerance)))
}

impl Solve<2> for AnnulusCase {
    type Built = Problem<2>;
    type Result = AnnulusResult;

    /// Runs the built annulus and measures the displacement error.
    fn solve(p: &AnnulusParams, problem: &Problem<2>, run: Run<'_, 2>) -> Solved<AnnulusResult> {
        let output = run.on(problem)?;
        let (elements, area) = match &problem.mesh {
            crate::scene::build::SceneMesh::Simplex(m) => (m.element_count(), m.total_volume()),
            crate::scene::build::SceneMesh::Grid(_) => (0, 0.0),
        };
        let torsion = Torsion {
            inner_radius: p.inner_radius,
            outer_radius: p.outer_radius,
            mu: p.youngs_modulus / (2.0 * (1.0 + p.poisson_ratio)),
        };
        let v0 = &problem.volume;
        let (mut sum, mut max) = (0.0f64, 0.0f64);
        for (q, u) in output.last.displacement.iter().enumerate() {
            let x0 = Vector2::new(problem.position[q][0], problem.position[q][1]);
            let exact = torsion.displacement(p.alpha, &x0);
            let e = (Vector2::new(u[0], u[1]) - exact).norm();
            sum += e * v0[q];
            max = max.max(e);
        }
        Ok(AnnulusResult {
            error: sum / v0.iter().sum::<f64>(),
            max_error: max,
            material_points: problem.len(),
            elements,
            element_size: (2.0 * area / elements.max(1) as f64).sqrt(),
            output,
        })
    }

    fn measured(r: &AnnulusResult) -> Measured<'_, 2> {
        Measured::new(&r.output, r.material_points, Some(r.error)).with([
            ("max_error", json!(r.max_error)),
            ("elements", json!(r.elements)),
            ("element_size", json!(r.element_size)),
        ])
    }

    /// A relative mesh path is taken from the scene file's directory.
    fn prepare(p: &mut AnnulusParams, session: &Session) {
        session.resolve(&mut p.mesh);
    }
}
