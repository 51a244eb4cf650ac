//! Wang et al. 2021 §5.2 (large-deformation elastic indentation) and §5.4
//! (double-notched plate) on the scenes' small meshes with one point per
//! element: what the paper's Figs. 11C, 15C and 16 show, asserted.
//! `cargo xtask reproduce wang2021` runs the same scenes with 11 points.
#![allow(clippy::unwrap_used)]

use mpm_cases::run::{RunControl, RunOutput};
use mpm_cases::scene::build::SceneMesh;
use mpm_cases::scene::{self, Problem};
use mpm_solver::StepReport;

const INDENTATION: &str = include_str!("../../../scenes/wang2021_indentation.toml");
const PLATE: &str = include_str!("../../../scenes/wang2021_notched_plate.toml");

/// The footing scene's quick cells with the empty layer above the ground.
const INDENTATION_QUICK_MESH: &str = "mesh.coordinates=[[0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 2.9, 4.2, 4.75, 5.0, 5.25, 5.6, 6.0]]";
const ONE_POINT: [&str; 2] = ["body.0.placement=\"regular\"", "body.0.points_per_cell=1"];

/// Runs `text` with `set` and the given locking; the problem, every step's
/// report and the run's output.
fn run(text: &str, set: &[&str], locking: &str) -> (Problem<3>, Vec<StepReport<3>>, RunOutput<3>) {
    let mut all: Vec<String> = set.iter().map(|s| (*s).to_owned()).collect();
    all.extend(ONE_POINT.iter().map(|s| (*s).to_owned()));
    all.push(format!("solver.locking=\"{locking}\""));
    let (scene, src) = scene::parse(text, "wang2021.toml", &all).unwrap();
    let problem = Problem::<3>::build(&scene, &src, 0).unwrap();
    let mut reports = Vec::new();
    let out = scene::run(&problem, &RunControl::default(), |_, rep, _| {
        reports.push(rep.clone());
        Ok(())
    })
    .unwrap();
    (problem, reports, out)
}

/// §5.2: the mesh at and above the ground goes down with the footing, the
/// mesh below is compressed linearly, the steps start at 0.1 m and double,
/// and F-patch carries less than standard MPM at the end (Fig. 11C).
#[test]
fn indentation_moves_the_mesh_with_the_footing_and_doubles_its_steps() {
    let mut end_force = Vec::new();
    for locking in ["none", "fpatch"] {
        let (problem, reports, out) = run(INDENTATION, &[INDENTATION_QUICK_MESH], locking);
        let last = reports.last().unwrap();
        assert_eq!(last.lambda1, 1.0, "{locking}: stopped at {}", last.lambda1);
        // Automatic steps: 0.1 m first, doubled after it converged.
        assert!((reports[0].lambda1 - 0.1).abs() < 1e-12);
        assert!(
            (reports[1].lambda1 - reports[1].lambda0 - 0.2).abs() < 1e-12,
            "{locking}: second increment {}",
            reports[1].lambda1 - reports[1].lambda0
        );
        let footing = &problem.reactions[0];
        end_force.push(footing.total(last)[2].abs());
        // The mesh: node v at height z moves down by z/5 m below the ground
        // and by 1 m at and above it (the grid's vertices, where the nearest
        // carried and fixed nodes are straight above and below).
        let SceneMesh::Simplex(mesh) = &problem.mesh else {
            panic!("a simplex scene")
        };
        let moved = out.last.mesh_nodes.as_ref().expect("a moving mesh");
        let levels = [0.0, 2.9, 4.2, 4.75, 5.0, 5.25, 5.6, 6.0];
        let plan = [0.0, 0.25, 0.8, 2.1, 5.0];
        let on = |v: f64, list: &[f64]| list.iter().any(|l| (l - v).abs() < 1e-12);
        let mut checked = 0;
        for (x0, x) in mesh.nodes().iter().zip(moved) {
            if on(x0[0], &plan) && on(x0[1], &plan) && on(x0[2], &levels) {
                let want = if x0[2] <= 5.0 {
                    0.8 * x0[2]
                } else {
                    x0[2] - 1.0
                };
                assert!(
                    (x[2] - want).abs() < 1e-12 && x[0] == x0[0] && x[1] == x0[1],
                    "{x0:?} moved to {x:?}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 5 * 5 * levels.len());
        // The footing, a rigid block from the ground to the top of the
        // empty layer: its base at 4 m, every node of it 1 m down.
        let nodes = mesh.nodes();
        let mut base = 0;
        for &v in &footing.nodes {
            assert!(
                (moved[v][2] - (nodes[v][2] - 1.0)).abs() < 1e-12,
                "footing node {v}"
            );
            base += usize::from((moved[v][2] - 4.0).abs() < 1e-12);
        }
        assert!(base > 0 && base < footing.nodes.len(), "{base}");
    }
    assert!(
        end_force[1] < end_force[0],
        "F-patch {} N against standard {} N",
        end_force[1],
        end_force[0]
    );
}

/// The largest reaction of a plate run and the Newton iterations of each
/// of its steps.
fn plate(cells: &str, locking: &str) -> (f64, Vec<usize>) {
    let set = format!("mesh.cells={cells}");
    let (problem, reports, _) = run(PLATE, &[&set], locking);
    assert_eq!(reports.len(), 25, "{cells} {locking}");
    let top = &problem.reactions[0];
    let peak = reports
        .iter()
        .map(|r| top.total(r)[1])
        .fold(f64::NAN, f64::max);
    (peak, reports.iter().map(StepReport::iterations).collect())
}

/// §5.4: the reaction falls as the mesh is refined (h = 2 to 1 mm), F-patch
/// carries less than standard MPM on each mesh (Fig. 15C), and F-patch's
/// Newton iterations stay at two to five per step once the ligament
/// yields (Fig. 16: four to five). Until 2026-12-05, with the elastic
/// branch at the yield surface in each step's first solve, they were four
/// to six and this test asserted that range.
#[test]
fn notched_plate_reaction_falls_with_h_and_fpatch_below_standard() {
    let (standard_2, _) = plate("[2, 4, 1]", "none");
    let (patched_2, iterations_2) = plate("[2, 4, 1]", "fpatch");
    let (standard_1, _) = plate("[4, 8, 2]", "none");
    let (patched_1, iterations_1) = plate("[4, 8, 2]", "fpatch");
    assert!(
        patched_2 < standard_2 && patched_1 < standard_1,
        "h = 2: {patched_2} vs {standard_2}; h = 1: {patched_1} vs {standard_1}"
    );
    assert!(
        standard_1 < standard_2 && patched_1 < patched_2,
        "standard {standard_2} -> {standard_1}, F-patch {patched_2} -> {patched_1}"
    );
    for its in [&iterations_2, &iterations_1] {
        assert!(
            its[5..].iter().all(|&n| (2..=5).contains(&n)),
            "F-patch iterations per step: {its:?}"
        );
    }
}
