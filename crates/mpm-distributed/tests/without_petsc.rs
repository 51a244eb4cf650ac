//! Built without the `petsc` feature, a scene asking for PETSc's solver
//! builds (the key is known) but does not run: the refusal names the
//! `linear` key's file:line:column and the build command that adds PETSc.
#![cfg(not(feature = "petsc"))]
#![allow(missing_docs, clippy::unwrap_used)]

use mpm_dispatch::run::RunControl;
use mpm_scene::{self as scene, Problem};

const SCENE: &str = r#"
[mesh]
origin = [0.0, 0.0]
size = [1.0, 1.0]
cells = [4, 4]

[[material]]
name = "m"
model = "hencky"
youngs_modulus = 1e6
poisson_ratio = 0.3
density = 1000.0

[[body]]
name = "b"
material = "m"
region = { box = { lower = [0.0, 0.0], upper = [1.0, 0.5] } }
points_per_cell = 2

[[boundary]]
set = "y_min"
kind = "fixed"

[[load]]
kind = "gravity"
acceleration = [0.0, -10.0]

[solver]
linear = { petsc = "-ksp_type cg -pc_type gamg" }
"#;

#[test]
fn petsc_scene_is_refused_at_its_key_without_the_feature() {
    assert!(mpm_distributed::external_linear().is_none());
    let (scene, src) = scene::parse(SCENE, "petsc.toml", &[]).unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let control = RunControl {
        external_linear: mpm_distributed::external_linear(),
        ..RunControl::default()
    };
    let e = mpm_dispatch::implicit::run(&problem, &control, |_, _, _| Ok(())).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("petsc.toml:29:10") && text.contains("--features petsc"),
        "{text}"
    );
}
