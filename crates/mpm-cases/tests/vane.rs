//! Wang et al. 2021 §5.5, the rotation of a vane slice
//! (`scenes/wang2021_vane_slice.toml`), and the rotating-mesh condition and
//! torque output it uses, checked where the answer is known: a solid
//! cylinder turned in a fixed ring of soil (plane strain), elastic
//! (closed form) and past yield (the limit torque 2π r_v² h k, an upper
//! bound of the vane's too).
#![allow(clippy::unwrap_used)]

use std::path::Path;

use mpm_cases::run::RunControl;
use mpm_cases::scene::{self, Problem};

const SCENE: &str = include_str!("../../../scenes/wang2021_vane_slice.toml");
const R_V: f64 = 0.05;
const R_OUT: f64 = 3.0 * R_V;
const HEIGHT: f64 = R_V;
/// k = ρ_y/√2 for ρ_y = √3·10⁴ Pa in eq. (16).
const K: f64 = 1.7320508075688772e4 / std::f64::consts::SQRT_2;
/// Shear modulus of E = 100 MPa, ν = 0.3.
const G: f64 = 1.0e8 / 2.6;

/// Torque about the axis after every step, and the torque of the outer
/// surface's reactions, for the scene with `overrides`.
fn torques(overrides: &[&str]) -> (Vec<f64>, Vec<f64>) {
    let mut set: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    set.push("output.reaction=[{name = \"vane\", set = \"vane\", about = [0.0, 0.0, 0.0]}, {name = \"outer\", set = \"outer\", about = [0.0, 0.0, 0.0]}]".to_owned());
    let (scene, src) = scene::parse(SCENE, "wang2021_vane_slice.toml", &set).unwrap();
    let scenes = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    let problem = Problem::<3>::build_in(&scene, &src, 0, scenes).unwrap();
    let (vane, outer) = (&problem.reactions[0], &problem.reactions[1]);
    let (mut t_vane, mut t_outer) = (Vec::new(), Vec::new());
    scene::run(&problem, &RunControl::default(), |_, rep, _| {
        t_vane.push(vane.moment(&problem, rep).unwrap()[2]);
        t_outer.push(outer.moment(&problem, rep).unwrap()[2]);
        Ok(())
    })
    .unwrap();
    (t_vane, t_outer)
}

/// Elastic: a rigid cylinder of radius a turned by θ in a ring fixed at b
/// (plane strain) needs T = 4π G h θ a² b² / (b² − a²) (u_θ = A r + B/r);
/// the torques of the driven and the fixed surface balance (a symmetric
/// stress carries no moment), to the Newton tolerance.
#[test]
fn an_elastic_cylinder_turns_with_the_closed_form_torque() {
    let theta = 4e-5;
    for locking in ["none", "fpatch"] {
        let (vane, outer) = torques(&[
            "mesh.file=\"meshes/cylinder_slice_test.msh\"",
            "material.0.yield_stress=1e15",
            "mesh.motion.angle=4e-5",
            "solver.steps=1",
            &format!("solver.locking=\"{locking}\""),
        ]);
        let (a2, b2) = (R_V * R_V, R_OUT * R_OUT);
        let exact = 4.0 * std::f64::consts::PI * G * HEIGHT * theta * a2 * b2 / (b2 - a2);
        // Measured: +1.4 % (standard MPM), +0.9 % (F-patch): the polygonal
        // cylinder of the coarse test mesh.
        let error = (vane[0] - exact) / exact;
        assert!(error.abs() < 0.02, "{locking}: {} against {exact}", vane[0]);
        assert!(
            (vane[0] + outer[0]).abs() < 1e-6 * vane[0],
            "{locking}: {} + {}",
            vane[0],
            outer[0]
        );
    }
}

/// Past yield the axisymmetric torque cannot exceed 2π a² h k (the rigid
/// core's surface at yield in shear). On the coarse test mesh the first
/// ring of points sits about 0.1 a outside the core, which lets the
/// discrete torque level off up to (1.1)² ≈ 1.2 times above it: F-patch
/// levels off there (measured 1.30 k-limits after 20 steps, rising at
/// 0.4 % of the elastic slope), while standard MPM keeps rising
/// (volumetric locking of the isochoric plastic flow).
#[test]
fn a_yielding_cylinder_levels_off_with_f_patch_and_not_without() {
    let limit = 2.0 * std::f64::consts::PI * R_V * R_V * HEIGHT * K;
    let run = |locking: &str| {
        torques(&[
            "mesh.file=\"meshes/cylinder_slice_test.msh\"",
            "mesh.motion.angle=6.4e-4",
            "solver.steps=8",
            &format!("solver.locking=\"{locking}\""),
        ])
        .0
    };
    let (standard, patched) = (run("none"), run("fpatch"));
    // Slope of the last two steps over the first (elastic) one's.
    let late = |t: &[f64]| (t[7] - t[5]) / 2.0 / t[0];
    assert!(late(&patched) < 0.02, "F-patch {patched:?}");
    assert!(late(&standard) > 2.0 * late(&patched), "{standard:?}");
    assert!(
        patched[7] > limit && patched[7] < 1.35 * limit,
        "F-patch {} against the limit {limit}",
        patched[7]
    );
    assert!(standard[7] > patched[7], "{standard:?} {patched:?}");
}

/// §5.5 on the quick mesh: F-patch's torque levels off, standard MPM's
/// keeps rising (Fig. 18C); both start from the same elastic slope.
#[test]
fn the_vane_slice_torque_levels_off_with_f_patch_only() {
    let run = |locking: &str| {
        torques(&[
            "mesh.file=\"meshes/vane_slice_quick.msh\"",
            &format!("solver.locking=\"{locking}\""),
        ])
        .0
    };
    let (standard, patched) = (run("none"), run("fpatch"));
    assert_eq!((standard.len(), patched.len()), (20, 20));
    assert!((standard[0] - patched[0]).abs() < 0.05 * standard[0]);
    let late = |t: &[f64]| (t[19] - t[15]) / 4.0 / t[0];
    // Measured: 6.6 % and 1.0 % of the elastic slope.
    assert!(late(&standard) > 0.04, "{standard:?}");
    assert!(late(&patched) < 0.02, "{patched:?}");
    assert!(standard[19] > 1.15 * patched[19]);
}

/// The iterative linear solver (ILU(0)-preconditioned BiCGSTAB) gives the
/// direct solver's answer on the unsymmetric F-patch stiffness past yield:
/// the same Newton iterations and torques equal to the linear tolerance.
#[test]
fn the_iterative_solver_gives_the_direct_solvers_torque() {
    let run = |linear: &str| {
        torques(&[
            "mesh.file=\"meshes/cylinder_slice_test.msh\"",
            "mesh.motion.angle=3.2e-4",
            "solver.steps=4",
            "solver.locking=\"fpatch\"",
            &format!("solver.linear=\"{linear}\""),
        ])
        .0
    };
    let (direct, iterative) = (run("direct"), run("iterative"));
    assert_eq!(direct.len(), 4);
    for (d, i) in direct.iter().zip(&iterative) {
        assert!((d - i).abs() <= 1e-8 * d.abs(), "{direct:?} {iterative:?}");
    }
}

const FULL: &str = include_str!("../../../scenes/wang2021_vane_full.toml");

/// §5.6 on the quick mesh of the full vane (`scenes/wang2021_vane_full.toml`
/// with `vane_full_quick.msh`): the empty layer above the ground holds no
/// points, F-patch's torque bends over while standard MPM's keeps most of
/// its elastic slope, and past yield the torque exceeds the slice's limit
/// scaled to the vane's height (the blades' lower ends add resistance).
#[test]
fn the_full_vane_runs_with_its_empty_layer() {
    let run = |locking: &str| {
        let set = vec![
            "mesh.file=\"meshes/vane_full_quick.msh\"".to_owned(),
            format!("solver.locking=\"{locking}\""),
        ];
        let (scene, src) = scene::parse(FULL, "wang2021_vane_full.toml", &set).unwrap();
        let scenes = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
        let problem = Problem::<3>::build_in(&scene, &src, 0, scenes).unwrap();
        // No point starts above the ground (z = 8 r_v).
        assert!(problem.position.iter().all(|x| x[2] <= 8.0 * R_V + 1e-12));
        let vane = &problem.reactions[0];
        let mut torque = Vec::new();
        scene::run(&problem, &RunControl::default(), |_, rep, _| {
            torque.push(vane.moment(&problem, rep).unwrap()[2]);
            Ok(())
        })
        .unwrap();
        torque
    };
    let (standard, patched) = (run("none"), run("fpatch"));
    assert_eq!((standard.len(), patched.len()), (10, 10));
    let late = |t: &[f64]| (t[9] - t[7]) / 2.0 / t[0];
    // Measured: 0.24 (standard) and 0.15 (F-patch) of the elastic slope;
    // on this coarse mesh F-patch has not levelled off by 0.4 mrad.
    assert!(late(&patched) < 0.2, "{patched:?}");
    assert!(late(&standard) > 1.4 * late(&patched), "{standard:?}");
    let slice_limit = 2.0 * std::f64::consts::PI * R_V * R_V * (4.0 * R_V) * K;
    assert!(
        patched[9] > slice_limit,
        "{patched:?} against {slice_limit}"
    );
    assert!(standard[9] > patched[9]);
}
