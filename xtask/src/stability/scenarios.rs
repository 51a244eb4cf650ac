//! The scenarios that run through scenes, the built-in cases and the
//! locking studies' library runs.

use std::time::Instant;

use mpm_cases::locking::{
    Cook, CookResult, Footing, FootingCurve, Traction, footing_grid, footing_triangles, grid,
    triangles,
};
use mpm_cases::variant::FormulationKind;
use mpm_solver::{FBar, FPatch, NoLocking, SolverError};

use super::{Expect, Mode, Outcome, Row, guarded, outputs_intact, run_scene};

/// The Poisson's ratios of the locking rows.
const NUS: [f64; 3] = [0.3, 0.49, 0.4999];

/// Fills `row` from a library run: the outcome (a panic caught), the wall
/// time, and the result.
fn library<T>(row: &mut Row, f: impl FnOnce() -> Result<T, SolverError>) -> Option<T> {
    let started = Instant::now();
    let (outcome, t) = Outcome::of(guarded(f), |_| 0);
    row.outcome = outcome;
    row.seconds = started.elapsed().as_secs_f64();
    t
}

/// ν × locking × formulation on the column, Cook's membrane and the
/// Prandtl footing.
pub fn locking(mode: Mode) -> Vec<Row> {
    let mut rows = Vec::new();
    let h = if mode == Mode::Quick { 3.125 } else { 0.78125 };
    for nu in NUS {
        for form in ["ul", "pc"] {
            for lock in ["none", "fbar"] {
                let mut row = Row::new(
                    "locking",
                    format!("column, ν = {nu}, h = {h} m"),
                    format!("linear, {form}, {lock}"),
                    Expect::Converge,
                );
                let set = [
                    format!("poisson_ratio={nu}"),
                    format!("formulation={form}"),
                    format!("locking={lock}"),
                    format!("h={h}"),
                ];
                run_scene("", Some("column"), &set).fill(&mut row);
                rows.push(row);
            }
        }
    }
    let n = if mode == Mode::Quick { 4 } else { 16 };
    for nu in NUS {
        for formulation in [FormulationKind::Ul, FormulationKind::Pc] {
            let cook = Cook {
                nu,
                load: 1.0,
                steps: 1,
                n,
                formulation,
            };
            let scenario = format!("Cook's membrane, ν = {nu}, n = {n}");
            type Run = fn(&Cook) -> Result<CookResult, SolverError>;
            let runs: [(&str, Run); 4] = [
                ("triangles, {f}, none", |c| triangles(c, |_| NoLocking)),
                ("triangles, {f}, fpatch", |c| triangles(c, FPatch::new)),
                ("grid, {f}, none", |c| {
                    grid(c, NoLocking, Traction::EdgeGaussPoints)
                }),
                ("grid, {f}, fbar", |c| {
                    grid(c, FBar::default(), Traction::EdgeGaussPoints)
                }),
            ];
            for (variant, run) in runs {
                let variant = variant.replace("{f}", &formulation.to_string());
                let mut row = Row::new("locking", scenario.clone(), variant, Expect::Converge);
                if let Some(r) = library(&mut row, || run(&cook)) {
                    let tip = r.tip * 100.0;
                    row.work = format!("1 step, {} iterations", r.iterations);
                    row.measured = format!("tip {tip:.4}");
                    row.value("tip", tip);
                }
                rows.push(row);
            }
        }
    }
    let (n, steps) = if mode == Mode::Quick {
        (10, 6)
    } else {
        (20, 12)
    };
    for nu in NUS {
        for formulation in [FormulationKind::Ul, FormulationKind::Pc] {
            let footing = Footing {
                nu,
                young: 1e4,
                n,
                settlement: 0.006,
                steps,
                formulation,
            };
            let scenario = format!("Prandtl footing, ν = {nu}, n = {n}");
            type Run = fn(&Footing) -> Result<FootingCurve, SolverError>;
            let runs: [(&str, Run); 4] = [
                ("triangles, {f}, none", |f| {
                    footing_triangles(f, |_| NoLocking)
                }),
                ("triangles, {f}, fpatch", |f| {
                    footing_triangles(f, FPatch::new)
                }),
                ("grid, {f}, none", |f| footing_grid(f, NoLocking)),
                ("grid, {f}, fbar", |f| footing_grid(f, FBar::default())),
            ];
            for (variant, run) in runs {
                let variant = variant.replace("{f}", &formulation.to_string());
                let mut row = Row::new("locking", scenario.clone(), variant, Expect::Converge);
                if let Some(c) = library(&mut row, || run(&footing)) {
                    row.work = format!("{} steps, {} iterations", c.points.len() - 1, c.iterations);
                    let plateau = c.points.last().map_or(0.0, |p| p.1);
                    let collapse = 2.0 + std::f64::consts::PI;
                    row.error = Some(plateau / collapse - 1.0);
                    row.measured = format!("q/k = {plateau:.3} (2 + π = {collapse:.3})");
                    row.value("pressure", plateau);
                    if let Some(f) = c.failure {
                        row.outcome = Outcome::Error {
                            error: "curve stopped early".into(),
                            message: f,
                        };
                    }
                }
                rows.push(row);
            }
        }
    }
    rows
}

/// The two-layer column's top displacement in closed form: uniaxial
/// strain with ν = 0, Hencky (σ = E ln λ / λ), σ = −ϱg(H − Y) in both
/// layers; each layer's stretch from its own E, integrated by Simpson's
/// rule.
fn two_layer_top(e_lower: f64, e_upper: f64, rho_g: f64, h: f64) -> f64 {
    let stretch = |y: f64| {
        let e = if y < 0.5 * h { e_lower } else { e_upper };
        let s = -rho_g * (h - y);
        // Newton on g(λ) = E ln λ − s λ.
        let mut l: f64 = 1.0;
        for _ in 0..60 {
            let g = e * l.ln() - s * l;
            let dg = e / l - s;
            l -= g / dg;
        }
        l
    };
    let layer = |a: f64, b: f64| {
        let m = 2000;
        let dy = (b - a) / m as f64;
        (0..=m)
            .map(|i| {
                let w = if i == 0 || i == m {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                // Stay inside the layer at its ends.
                let y = (a + i as f64 * dy).clamp(a + 1e-12, b - 1e-12);
                w * (stretch(y) - 1.0)
            })
            .sum::<f64>()
            * dy
            / 3.0
    };
    layer(0.0, 0.5 * h) + layer(0.5 * h, h)
}

/// The two-layer column with a stiffness contrast of 10⁶.
pub fn contrast(_mode: Mode) -> Vec<Row> {
    let text = std::fs::read_to_string(super::scenes_dir().join("two_layer_column.toml"))
        .unwrap_or_default()
        .replace("youngs_modulus = 1.0e7", "youngs_modulus = 1.0e11");
    let exact = two_layer_top(1e11, 1e5, 800.0, 10.0);
    let mut rows = Vec::new();
    for (basis, update) in [
        ("linear", "none"),
        ("gimp", "stretch"),
        ("bspline2", "none"),
    ] {
        for form in ["ul", "pc"] {
            let mut row = Row::new(
                "contrast",
                "two layers, E = 10¹¹ / 10⁵ Pa",
                format!("{basis}, {form}, domain {update}"),
                Expect::Converge,
            );
            let set = [
                format!("solver.basis={basis}"),
                format!("solver.domain_update={update}"),
                format!("solver.formulation={form}"),
            ];
            let run = run_scene(&text, None, &set);
            run.fill(&mut row);
            if let Some(top) = run.pointer("/probes/top/1") {
                row.error = Some((top - exact).abs() / exact.abs());
                row.measured = format!("top {top:.5} m (closed form {exact:.5})");
                row.value("top", top);
            }
            rows.push(row);
        }
    }
    rows
}

/// Load steps 10× and 100× the nominal: the cantilever of Coombs et al.
/// 2020 §7.3 (large deflection, 50 nominal steps in the paper; 100 here)
/// must converge, in one step by cutting (at 10× the coarse grid cuts
/// once, the finer one does not); the difference from the nominal run is set
/// beside the discretisation error's yardstick (the nominal run on a grid
/// of half the spacing). A homogeneous stretch (a moving mesh, affine
/// motion) is path independent and must agree to round-off.
pub fn step_size(mode: Mode) -> Vec<Row> {
    let mut rows = Vec::new();
    let h = if mode == Mode::Quick { 0.5 } else { 0.25 };
    let tip = |run: &super::SceneRun| {
        Some(nalgebra::Vector2::new(
            run.pointer("/tip_displacement/0")?,
            run.pointer("/tip_displacement/1")?,
        ))
    };
    for form in ["ul", "pc"] {
        let mut reference = None;
        for (factor, expect) in [
            (1, Expect::Converge),
            (10, Expect::Converge),
            (100, Expect::Recover),
        ] {
            let steps = 100 / factor;
            let mut row = Row::new(
                "step size",
                format!("cantilever (Coombs 2020 §7.3), h = {h} m"),
                format!("linear, {form}, {steps} steps ({factor}× nominal)"),
                expect,
            );
            let set = [
                format!("formulation={form}"),
                format!("load_steps={steps}"),
                format!("h={h}"),
            ];
            let run = run_scene("", Some("cantilever"), &set);
            run.fill(&mut row);
            if let Some(t) = tip(&run) {
                row.value("tip", t.norm());
                match reference {
                    None => {
                        // The yardstick: the same run on a grid of half the spacing.
                        let fine = run_scene(
                            "",
                            Some("cantilever"),
                            &[
                                format!("formulation={form}"),
                                format!("load_steps={steps}"),
                                format!("h={}", 0.5 * h),
                            ],
                        );
                        let yardstick = tip(&fine).map_or(f64::NAN, |f| (f - t).norm() / t.norm());
                        row.measured = format!(
                            "tip ({:.4}, {:.4}) m; at h/2 it moves by {yardstick:.2e} of it",
                            t[0], t[1]
                        );
                        row.value("yardstick", yardstick);
                        reference = Some(t);
                    }
                    Some(r) => {
                        row.error = Some((t - r).norm() / r.norm());
                        row.measured = format!("tip ({:.4}, {:.4}) m", t[0], t[1]);
                    }
                }
            }
            rows.push(row);
        }
    }
    // The elasto-plastic collapse of Coombs et al. 2020 §7.5 in more steps
    // than its 40: standard MPM stops at λ = 0.95 (measured at 80 and 100
    // steps; likely its cell-crossing error), GIMP goes on.
    let collapse = std::fs::read_to_string(super::scenes_dir().join("coombs2020_collapse.toml"))
        .unwrap_or_default();
    let counts: &[usize] = if mode == Mode::Quick {
        &[80]
    } else {
        &[40, 80, 100]
    };
    for basis in ["linear", "gimp"] {
        for &steps in counts {
            let expect = if basis == "gimp" || steps == 40 {
                Expect::Converge
            } else {
                Expect::Measure
            };
            let mut row = Row::new(
                "step size",
                "elasto-plastic collapse (Coombs 2020 §7.5, nominal 40 steps)",
                format!("{basis}, pc, {steps} steps"),
                expect,
            );
            let set = [
                format!("solver.basis={basis}"),
                format!("solver.steps={steps}"),
                "output.png=false".to_owned(),
            ];
            let run = run_scene(&collapse, None, &set);
            run.fill(&mut row);
            // The weight ϱ g V = 1 × 10⁴ × 64 N/m at λ = 1.
            if let Some(r) = run.pointer("/reactions/base/1") {
                let balance = r / 6.4e5 - 1.0;
                row.measured = format!("λ = 1 reached; base reaction / weight − 1 = {balance:.1e}");
                row.value("reaction", r);
            }
            rows.push(row);
        }
    }
    for form in ["ul", "pc"] {
        let mut reference: Option<f64> = None;
        for steps in [100, 1] {
            let mut row = Row::new(
                "step size",
                "one cell stretched homogeneously to λ = 3 (moving mesh, affine)",
                format!("linear, {form}, {steps} steps"),
                Expect::Converge,
            );
            let text = format!(
                "[mesh]\norigin = [0.0, 0.0]\nsize = [1.0, 1.0]\ncells = [1, 1]\n\n\
                 [mesh.motion]\nkind = \"stretch\"\naxis = \"y\"\nextension = 2.0\ndriven = \"y_max\"\n\n\
                 [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = 1.0e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
                 [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 1.0] }} }}\npoints_per_cell = 2\n\n\
                 [[boundary]]\nset = \"y_min\"\nkind = \"roller\"\n\n[[boundary]]\nset = \"x_min\"\nkind = \"roller\"\n\n\
                 [solver]\nformulation = \"{form}\"\nsteps = {steps}\n"
            );
            if let Some(out) = super::run_problem::<2>(&text, &mut row) {
                let syy = out.last.sigma.first().map_or(f64::NAN, |s| s[4]);
                row.value("sigma_yy", syy);
                row.measured = format!("σ_yy {syy:.10e} Pa");
                match reference {
                    None => reference = Some(syy),
                    Some(r) => row.error = Some((syy - r).abs() / r.abs()),
                }
            }
            rows.push(row);
        }
    }
    rows
}

/// Points driven out of the grid and inverted elements, implicit and
/// explicit: a typed error, and the outputs before it intact.
pub fn failures(_mode: Mode) -> Vec<Row> {
    let implicit = |body_upper: &str, boundary: &str, steps: usize| {
        format!(
            "[mesh]\norigin = [0.0, 0.0]\nsize = [4.0, 2.0]\ncells = [4, 2]\n\n\
             [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = 1.0e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
             [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.0, 0.0], upper = {body_upper} }} }}\npoints_per_cell = 2\n\n\
             {boundary}\n\
             [solver]\nsteps = {steps}\n\n[output]\nfields = [\"displacement\", \"stress\"]\n"
        )
    };
    let everything = "[[node_set]]\nname = \"all\"\nregion = { box = { lower = [-1.0, -1.0], upper = [5.0, 3.0] } }\n\n";
    let cases = [
        (
            "implicit: every node moved 6 m along x in 12 steps (the body leaves the grid)",
            implicit(
                "[1.0, 2.0]",
                &format!(
                    "{everything}[[boundary]]\nset = \"all\"\nkind = \"displacement\"\ndisplacement = {{ x = 6.0, y = 0.0 }}\n"
                ),
                12,
            ),
            Expect::Refuse("Solver::InStep"),
        ),
        (
            "implicit: a triangle mesh whose top is carried 2.5 m down through its fixed base (translation motion, 10 steps)",
            "[mesh]\nkind = \"simplex\"\norigin = [0.0, 0.0]\nsize = [2.0, 2.0]\ncells = [2, 2]\n\n\
                 [mesh.motion]\nkind = \"translation\"\ndisplacement = [0.0, -2.5]\ndriven = \"y_max\"\nfixed = \"y_min\"\n\n\
                 [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = 1.0e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
                 [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = { box = { lower = [0.0, 0.0], upper = [2.0, 2.0] } }\npoints_per_cell = 2\n\n\
                 [[boundary]]\nset = \"y_min\"\nkind = \"fixed\"\n\n\
                 [[boundary]]\nset = \"x_min\"\nkind = \"roller\"\n\n[[boundary]]\nset = \"x_max\"\nkind = \"roller\"\n\n\
                 [solver]\nsteps = 10\n\n[output]\nfields = [\"displacement\", \"stress\"]\n"
                .to_owned(),
            // The points between the carried top and the fixed base invert
            // before the mesh does: no step past λ = 0.8 converges.
            Expect::Refuse("Solver::StepTooSmall (cause Constitutive)"),
        ),
        (
            "implicit: top nodes of a fixed grid pressed down 2.5 m into a 2 m block in 10 steps",
            implicit(
                "[4.0, 2.0]",
                "[[boundary]]\nset = \"y_min\"\nkind = \"fixed\"\n\n[[boundary]]\nset = \"x_min\"\nkind = \"roller\"\n\n[[boundary]]\nset = \"x_max\"\nkind = \"roller\"\n\n[[boundary]]\nset = \"y_max\"\nkind = \"displacement\"\ndisplacement = { x = 0.0, y = -2.5 }\n",
                10,
            ),
            // The points leave the driven top nodes' cells as they are
            // pushed down: the nodes lose their support and the
            // prescription its grip (measured, not refused).
            Expect::Measure,
        ),
        (
            "explicit: a block at 20 m/s with no wall (leaves the grid)",
            "[mesh]\norigin = [0.0, 0.0]\nsize = [4.0, 1.0]\ncells = [16, 4]\n\n\
                 [[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e4\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
                 [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = { box = { lower = [0.5, 0.25], upper = [1.5, 0.75] } }\npoints_per_cell = 2\nvelocity = [20.0, 0.0]\n\n\
                 [solver]\nkind = \"explicit\"\ncfl = 0.3\nend_time = 0.5\noutput_interval = 0.02\n\n[output]\nfields = [\"displacement\", \"velocity\"]\n"
                .to_owned(),
            Expect::Refuse("Solver::ExplicitPoint"),
        ),
    ];
    let mut rows = Vec::new();
    for (scenario, text, expect) in cases {
        let mut row = Row::new("failure", scenario, "default", expect);
        let run = run_scene(&text, None, &[]);
        run.fill(&mut row);
        match outputs_intact(&run.out.0) {
            Ok(n) => {
                row.measured = format!("{n} VTU files before the error, all whole");
                row.value("vtu", n as f64);
            }
            Err(e) => {
                row.outcome = Outcome::Error {
                    error: "torn output".into(),
                    message: e,
                };
            }
        }
        rows.push(row);
    }
    rows
}

/// The explicit solver's stiff and extreme cases.
pub fn explicit(mode: Mode) -> Vec<Row> {
    let mut rows = Vec::new();
    let bar =
        std::fs::read_to_string(super::scenes_dir().join("explicit_bar.toml")).unwrap_or_default();
    // h / c = 0.25 / 10; the CFL limit is h / max(c + |v|) with v = 0.1.
    let limit = 0.25 / 10.1;
    for (factor, expect) in [
        (0.5, Expect::Converge),
        (1.5, Expect::Refuse("Solver::CflExceeded")),
        (3.0, Expect::Refuse("Solver::CflExceeded")),
    ] {
        let mut row = Row::new(
            "explicit",
            "vibrating bar, fixed Δt",
            format!("Δt = {factor} × the CFL limit"),
            expect,
        );
        let run = run_scene(
            &bar,
            None,
            &[
                format!("solver.time_step={}", factor * limit),
                "solver.end_time=2.0".into(),
            ],
        );
        run.fill(&mut row);
        if let Some(d) = run.number("energy_drift") {
            row.measured = format!("energy drift {d:+.2e}");
            row.value("drift", d);
        }
        rows.push(row);
    }
    let disks = std::fs::read_to_string(super::scenes_dir().join("explicit_disks.toml"))
        .unwrap_or_default();
    let cells = if mode == Mode::Quick { 20 } else { 40 };
    // Two pairs with a wave-speed contrast of 10³: E = 10³ and 10⁹ Pa at
    // one density (a `MaterialSet`, each point with its own modulus), and
    // one law at densities 10³ and 10⁻³ kg/m³.
    let stiff = disks.replacen(
        "[[material]]",
        "[[material]]\nname = \"stiff\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e9\npoisson_ratio = 0.3\ndensity = 1000.0\n\n[[material]]",
        1,
    );
    let light = disks.replacen(
        "[[material]]",
        "[[material]]\nname = \"light\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1000.0\npoisson_ratio = 0.3\ndensity = 0.001\n\n[[material]]",
        1,
    );
    let second_body = |text: &str, material: &str| {
        let at = text.rfind("material = \"elastic\"").unwrap_or(0);
        let mut t = text.to_owned();
        t.replace_range(
            at..at + "material = \"elastic\"".len(),
            &format!("material = \"{material}\""),
        );
        t
    };
    let scenarios = [
        (
            "colliding disks, E = 10³ and 10⁹ Pa at ϱ = 10³ kg/m³ (wave speeds 1.2 and 1200 m/s), v = ±(1, 1) m/s",
            second_body(&stiff, "stiff"),
            vec![
                "solver.end_time=0.25".to_owned(),
                format!("mesh.cells=[{cells}, {cells}]"),
            ],
            10.0,
            Expect::Converge,
        ),
        (
            "colliding disks, ϱ = 10³ and 10⁻³ kg/m³ (wave speeds 1.2 and 1200 m/s), v = ±(1, 1) m/s",
            second_body(&light, "light"),
            vec![
                "solver.end_time=0.25".to_owned(),
                format!("mesh.cells=[{cells}, {cells}]"),
            ],
            10.0,
            Expect::Converge,
        ),
        (
            "colliding disks at ±(5, 5) m/s (7 m/s against a wave speed of 1.2 m/s)",
            disks.clone(),
            vec![
                "solver.end_time=0.1".to_owned(),
                format!("mesh.cells=[{cells}, {cells}]"),
            ],
            50.0,
            Expect::Measure,
        ),
    ];
    rows.extend(wall_impacts());
    for (scenario, text, set, speed, expect) in scenarios {
        let v = 0.1 * speed;
        let text = text
            .replace(
                "velocity = [0.1, 0.1]",
                &format!("velocity = [{v:?}, {v:?}]"),
            )
            .replace(
                "velocity = [-0.1, -0.1]",
                &format!("velocity = [-{v:?}, -{v:?}]"),
            );
        let mut row = Row::new("explicit", scenario, "bspline2, flip (blend α = 1)", expect);
        let run = run_scene(&text, None, &set);
        run.fill(&mut row);
        if let Some(d) = run.number("energy_drift") {
            row.measured = format!("energy drift {d:+.2e}");
            row.value("drift", d);
        }
        rows.push(row);
    }
    rows
}

/// A soft block at 40 m/s into a fixed wall and into a friction wall,
/// which lets the block go again and books what it takes
/// (`friction_work`, `wall_work`, part of the total whose drift is
/// measured). On the friction wall the block splashes along the wall and
/// out of the grid's open bottom at t = 0.17 s (a typed error): it runs
/// to 0.1 s. An absorbing wall only slows the nodes it holds (its
/// semi-implicit dashpots shrink their velocity whatever Δt): the block
/// runs on out of the grid, a typed error, and what the dashpots took is
/// booked as `absorbed_work`.
fn wall_impacts() -> Vec<Row> {
    let wall = |kind: &str, end: f64| {
        format!(
            "[mesh]\norigin = [0.0, 0.0]\nsize = [4.0, 1.0]\ncells = [16, 4]\n\n\
             [[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e4\npoisson_ratio = 0.3\ndensity = 1000.0\n\n\
             [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.5, 0.25], upper = [1.5, 0.75] }} }}\npoints_per_cell = 2\nvelocity = [-40.0, 0.0]\n\n\
             [[boundary]]\nset = \"x_min\"\n{kind}\n\n\
             [solver]\nkind = \"explicit\"\ncfl = 0.3\nend_time = {end:?}\noutput_interval = 0.01\n"
        )
    };
    [
        ("kind = \"fixed\"", 0.2, "a fixed wall"),
        (
            "kind = \"friction\"\nfriction = 0.3",
            0.1,
            "a friction wall (μ = 0.3, it may let go; to t = 0.1 s)",
        ),
        (
            "kind = \"absorbing\"\nmaterial = \"m\"",
            0.2,
            "an absorbing wall (dashpots of its own material, which do not stop it)",
        ),
    ]
    .into_iter()
    .map(|(kind, end, name)| {
        let mut row = Row::new(
            "explicit",
            format!("a soft block at 40 m/s into {name} (wave speed 3.7 m/s)"),
            "bspline2, flip",
            Expect::Measure,
        );
        let run = run_scene(&wall(kind, end), None, &[]);
        run.fill(&mut row);
        if let Some(d) = run.number("energy_drift") {
            row.measured = format!("energy drift {d:+.2e}");
            row.value("drift", d);
        }
        let names = ["friction_work", "wall_work", "absorbed_work"];
        let taken = names.map(|k| run.pointer(&format!("/final_energies/{k}")).unwrap_or(0.0));
        for (name, w) in names.iter().zip(taken).filter(|(_, w)| *w > 0.0) {
            row.measured += &format!(", {} {w:.3e}", name.replace('_', " "));
            row.value(name, w);
        }
        row
    })
    .collect()
}

/// Degenerate Gmsh meshes.
pub fn meshes() -> Vec<Row> {
    let msh = |nodes: &[[f64; 3]], tets: &[[usize; 4]]| {
        let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n");
        let n = nodes.len();
        s += &format!("1 {n} 1 {n}\n3 1 0 {n}\n");
        for i in 1..=n {
            s += &format!("{i}\n");
        }
        for x in nodes {
            s += &format!("{} {} {}\n", x[0], x[1], x[2]);
        }
        s += "$EndNodes\n$Elements\n";
        let m = tets.len();
        s += &format!("1 {m} 1 {m}\n3 1 4 {m}\n");
        for (i, t) in tets.iter().enumerate() {
            s += &format!("{} {} {} {} {}\n", i + 1, t[0], t[1], t[2], t[3]);
        }
        s += "$EndElements\n";
        s
    };
    let cube = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let flat = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let sliver = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.5, 1e-9],
    ];
    let duplicated = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    let cases: [(&str, String, Expect); 5] = [
        (
            "one regular tetrahedron (control)",
            msh(&cube, &[[1, 2, 3, 4]]),
            Expect::Converge,
        ),
        (
            "zero-volume tetrahedron (four coplanar nodes)",
            msh(&flat, &[[1, 2, 3, 4]]),
            Expect::Measure,
        ),
        (
            "sliver tetrahedron (volume 1.7e-10 of a unit one)",
            msh(&sliver, &[[1, 2, 3, 4]]),
            Expect::Measure,
        ),
        (
            "a tetrahedron naming one node twice",
            msh(&cube, &[[1, 2, 2, 4]]),
            Expect::Measure,
        ),
        (
            "duplicated node (two ids, one position) splitting two tetrahedra",
            msh(&duplicated, &[[1, 2, 3, 4], [5, 3, 4, 6]]),
            Expect::Measure,
        ),
    ];
    cases
        .into_iter()
        .map(|(scenario, text, expect)| {
            let mut row = Row::new("mesh", scenario, "MSH 4.1 → SimplexMesh<3>", expect);
            let started = Instant::now();
            // Accepted meshes are checked as `mpm run` checks them: the
            // warnings of `SimplexMesh::quality`.
            let result = guarded(|| {
                mpm_mesh::parse_msh::<3>(text.as_bytes()).map(|m| {
                    let warnings = match &m.elements {
                        mpm_mesh::GmshElements::Linear(mesh) => mesh.quality().warnings(),
                        mpm_mesh::GmshElements::Quadratic(_) => Vec::new(),
                    };
                    (m.element_tags.len(), warnings)
                })
            });
            let (outcome, accepted) = Outcome::of(result, |_| 0);
            row.outcome = outcome;
            row.seconds = started.elapsed().as_secs_f64();
            if let Some((n, warnings)) = accepted {
                row.measured = if warnings.is_empty() {
                    format!("accepted: {n} elements, no warning")
                } else {
                    format!("accepted: {n} elements; warning: {}", warnings.join("; "))
                };
            }
            row
        })
        .collect()
}
