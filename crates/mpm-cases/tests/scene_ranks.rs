//! A scene's implicit run on several ranks through the scene runner
//! (`RunControl::ranks`, what `mpirun -n N mpm run` does over MPI), here
//! on threads: each rank keeps the points METIS deals it (whole patches
//! under F-patch), rank 0 observes the gathered snapshot. Against one
//! process: the same Newton iterations in every step; the displacements,
//! stresses and reactions differ only by the order in which the ranks'
//! sums are added (rounding), far below the Newton tolerance.

use std::sync::Arc;

use mpm_cases::run::{RunControl, Snapshot};
use mpm_cases::scene::{Problem, run};
use mpm_dispatch::on_ranks::RankRun;
use mpm_solver::ranks::ThreadRanks;

/// A strip footing pressed into a von Mises block on triangles split
/// from quadratic parents, with F-patch, or on a grid with gravity.
fn scene(simplex: bool) -> String {
    let mesh = if simplex {
        "[mesh]\nkind = \"simplex\"\norigin = [0.0, 0.0]\nsize = [2.0, 1.0]\ncells = [8, 4]\npatches = true\n"
    } else {
        "[mesh]\norigin = [0.0, 0.0]\nsize = [2.0, 1.0]\ncells = [16, 8]\n\n[[load]]\nkind = \"gravity\"\nacceleration = [0.0, -10.0]\n"
    };
    let locking = if simplex { "fpatch" } else { "none" };
    format!(
        "{mesh}
[[material]]
name = \"clay\"
model = \"von_mises\"
youngs_modulus = 1.0e6
poisson_ratio = 0.45
density = 100.0
yield_stress = 2.0e3

[[body]]
name = \"clay\"
material = \"clay\"
region = {{ box = {{ lower = [0.0, 0.0], upper = [2.0, 1.0] }} }}

[[node_set]]
name = \"footing\"
region = {{ box = {{ lower = [0.0, 0.99], upper = [0.5, 1.01] }} }}

[[boundary]]
set = \"x_min\"
kind = \"roller\"

[[boundary]]
set = \"x_max\"
kind = \"roller\"

[[boundary]]
set = \"y_min\"
kind = \"fixed\"

[[boundary]]
set = \"footing\"
kind = \"displacement\"
displacement = {{ y = -0.01 }}

[solver]
locking = \"{locking}\"
steps = 4

[[output.reaction]]
name = \"footing\"
set = \"footing\"
"
    )
}

fn problem(simplex: bool) -> Problem<2> {
    let (scene, source) = mpm_cases::scene::parse(&scene(simplex), "ranks.toml", &[]).unwrap();
    Problem::<2>::build(&scene, &source, scene.solver.padding()).unwrap()
}

/// What rank 0 saw: the snapshot after every step, the Newton iterations
/// and the footing's reaction per step.
#[derive(Debug, Default)]
struct Seen {
    snapshots: Vec<Snapshot>,
    iterations: Vec<usize>,
    reactions: Vec<f64>,
}

fn run_with(problem: &Problem<2>, control: &RunControl) -> Seen {
    let mut seen = Seen::default();
    let nodes = &problem.reactions[0].nodes;
    run(problem, control, |_, report, snap| {
        seen.snapshots.push(snap.clone());
        seen.iterations.push(report.iterations());
        seen.reactions.push(report.reaction_on(nodes)[1]);
        Ok(())
    })
    .unwrap();
    seen
}

fn on_ranks(problem: &Problem<2>, size: usize) -> Seen {
    let deal = mpm_cases::scene::ranks::rank_of_point(problem, size).unwrap();
    let mut all = ThreadRanks::run(size, |ranks| {
        let control = RunControl {
            ranks: Some(RankRun {
                ranks: Arc::new(ranks),
                rank_of_point: deal.clone(),
            }),
            ..RunControl::default()
        };
        run_with(problem, &control)
    });
    for other in &all[1..] {
        assert!(other.snapshots.is_empty(), "only rank 0 observes");
        assert!(other.iterations.is_empty());
    }
    all.swap_remove(0)
}

/// The largest difference between the entries of `a` and `b`, and the
/// largest entry of `a`.
fn difference<const N: usize>(a: &[[f64; N]], b: &[[f64; N]]) -> (f64, f64) {
    let pairs = a.iter().flatten().zip(b.iter().flatten());
    pairs.fold((0.0f64, 0.0f64), |(d, m), (x, y)| {
        (d.max((x - y).abs()), m.max(x.abs()))
    })
}

fn compare(simplex: bool) {
    let problem = problem(simplex);
    let single = run_with(&problem, &RunControl::default());
    assert!(single.snapshots.len() >= 4, "every step observed");
    for size in [2, 3] {
        let ranks = on_ranks(&problem, size);
        assert_eq!(ranks.iterations, single.iterations, "{size} ranks");
        let (a, b) = (
            single.snapshots.last().unwrap(),
            ranks.snapshots.last().unwrap(),
        );
        assert_eq!(
            a.position.len(),
            b.position.len(),
            "every point gathered once"
        );
        // The Newton tolerance (1e-9 on the normalised residual) bounds
        // what a different summation order may move; rounding alone moves
        // far less.
        let (du, u_max) = difference(&a.displacement, &b.displacement);
        assert!(du <= 1e-9 * u_max, "{size} ranks: |du| {du:e} of {u_max:e}");
        let (ds, s_max) = difference(&a.sigma, &b.sigma);
        assert!(ds <= 1e-8 * s_max, "{size} ranks: |dσ| {ds:e} of {s_max:e}");
        let dr = (single.reactions.iter().zip(&ranks.reactions))
            .fold(0.0f64, |m, (r1, rn)| m.max((r1 - rn).abs() / r1.abs()));
        eprintln!(
            "{size} ranks: iterations {:?}, |du| {:.1e} of max |u|, |dσ| {:.1e} of max |σ|, reaction {dr:.1e}",
            ranks.iterations,
            du / u_max,
            ds / s_max
        );
        for (r1, rn) in single.reactions.iter().zip(&ranks.reactions) {
            assert!(
                (r1 - rn).abs() <= 1e-8 * r1.abs(),
                "{size} ranks: {r1} against {rn}"
            );
        }
    }
}

#[test]
fn an_f_patch_footing_on_two_and_three_ranks_equals_one_process() {
    compare(true);
}

#[test]
fn a_footing_under_gravity_on_a_grid_on_two_and_three_ranks_equals_one_process() {
    compare(false);
}

#[test]
fn a_deal_that_does_not_fit_the_problem_is_refused_on_every_rank() {
    let problem = problem(false);
    let results = ThreadRanks::run(2, |ranks| {
        let control = RunControl {
            ranks: Some(RankRun {
                ranks: Arc::new(ranks),
                rank_of_point: vec![0; 3],
            }),
            ..RunControl::default()
        };
        run(&problem, &control, |_, _, _| Ok(())).map(|_| ())
    });
    for r in results {
        let e = r.unwrap_err().to_string();
        assert!(e.contains("the deal names ranks for 3 points"), "{e}");
    }
}
