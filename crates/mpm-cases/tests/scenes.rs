//! Scenes as data: the two example scenes against their references, the
//! validation of malformed scenes (each error with its place), and random
//! mutations of a valid scene, which must never panic.
#![allow(clippy::unwrap_used)]

use super::common;

use mpm_cases::run::{RunControl, RunOutput};
use mpm_cases::scene::SceneError;
use mpm_cases::scene::build::SceneMesh as SceneMeshKind;
use mpm_cases::scene::{self, Problem};
use proptest::prelude::*;

const TWO_LAYER: &str = include_str!("../../../scenes/two_layer_column.toml");
const SLOPE: &str = include_str!("../../../scenes/slope.toml");
const WANG_FOOTING: &str = include_str!("../../../scenes/wang2021_footing.toml");
/// The quick mesh of the footing scene (the xtask's quick mode too).
const FOOTING_QUICK_MESH: &str = "mesh.coordinates=[[0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 0.25, 0.8, 2.1, 5.0], [0.0, 2.9, 4.2, 4.75, 5.0]]";

/// Parses, builds and runs a 2D scene.
fn run2(text: &str, overrides: &[&str]) -> (Problem<2>, RunOutput<2>) {
    let set: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let (scene, src) = scene::parse(text, "scene.toml", &set).unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    (problem, out)
}

/// Runs `mpm run scenes/<file> --out <fresh dir>`; returns the directory
/// after checking the program succeeded.
fn run_mpm(file: &str, test: &str) -> std::path::PathBuf {
    run_mpm_set(file, test, &[])
}

/// [`run_mpm`] with `--set` overrides.
fn run_mpm_set(file: &str, test: &str, set: &[&str]) -> std::path::PathBuf {
    let dir = common::fresh_dir(test);
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file);
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(&dir)
        .args(set.iter().flat_map(|s| ["--set", s]))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    dir
}

/// The final states of a scene run and of the built-in case it mirrors are
/// the same, bit for bit (compared with `assert!`: a mismatch would print
/// a thousand tensors).
fn assert_same_final_state<const D: usize>(scene: &RunOutput<D>, case: &RunOutput<D>) {
    assert!(
        scene.last.position == case.last.position,
        "final positions differ"
    );
    assert!(scene.last.sigma == case.last.sigma, "final stresses differ");
    assert!(
        scene.last.plastic_strain == case.last.plastic_strain,
        "plastic strains differ"
    );
}

/// The error of a scene that must not build, as text.
fn refusal(text: &str) -> String {
    let built =
        scene::parse(text, "bad.toml", &[]).and_then(|(scene, src)| {
            match scene::dimension(&scene, &src)? {
                2 => Problem::<2>::build(&scene, &src, scene.solver.padding()).map(|_| ()),
                _ => Problem::<3>::build(&scene, &src, scene.solver.padding()).map(|_| ()),
            }
        });
    match built {
        Ok(()) => panic!("the scene was accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The two-layer column's closed form (ν = 0, Hencky, uniaxial strain):
/// σ = E ln λ / λ = −ϱ g (H − Y) gives the stretch λ(Y) = exp(−W(−s)),
/// s = σ/E (W the principal Lambert function, here by Newton on
/// ln λ = s λ), and u(Y) = ∫₀^Y (λ − 1) dY' layer by layer (Simpson's
/// rule with 2000 panels per layer: the integrand is smooth within each).
struct TwoLayer {
    rho_g: f64,
    height: f64,
    interface: f64,
    e_lower: f64,
    e_upper: f64,
}

impl TwoLayer {
    const SCENE: TwoLayer = TwoLayer {
        rho_g: 800.0,
        height: 10.0,
        interface: 5.0,
        e_lower: 1e7,
        e_upper: 1e5,
    };

    fn sigma(&self, y: f64) -> f64 {
        -self.rho_g * (self.height - y)
    }

    fn stretch(&self, y: f64, e: f64) -> f64 {
        let s = self.sigma(y) / e;
        let mut l = 1.0f64;
        for _ in 0..50 {
            l -= (l.ln() - s * l) / (1.0 / l - s);
        }
        l
    }

    fn displacement(&self, y: f64) -> f64 {
        let simpson = |a: f64, b: f64, e: f64| {
            if b <= a {
                return 0.0;
            }
            let n = 2000;
            let h = (b - a) / n as f64;
            (0..=n)
                .map(|k| {
                    let w = if k == 0 || k == n {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * (self.stretch(a + k as f64 * h, e) - 1.0)
                })
                .sum::<f64>()
                * h
                / 3.0
        };
        simpson(0.0, y.min(self.interface), self.e_lower) + simpson(self.interface, y, self.e_upper)
    }
}

#[test]
fn two_layer_column_matches_its_closed_form_and_converges() {
    let reference = TwoLayer::SCENE;
    let mut previous = (f64::INFINITY, f64::INFINITY);
    let mut rows = Vec::new();
    for cells in [8, 16, 32, 64] {
        let cells_override = format!("mesh.cells=[1, {cells}]");
        let (problem, out) = run2(TWO_LAYER, &[&cells_override]);
        let last = &out.last;
        let mut errors = Vec::new();
        for (name, p) in &problem.probes {
            let y0 = problem.position[*p][1];
            let exact = reference.displacement(y0);
            let got = last.displacement[*p][1];
            errors.push((name.clone(), ((got - exact) / exact).abs()));
        }
        let top = errors.iter().find(|e| e.0 == "top").unwrap().1;
        let interface = errors.iter().find(|e| e.0 == "interface").unwrap().1;
        // σ_yy = −ϱ g (H − Y) at every point (eq. 42's normalisation).
        let stress_error: f64 = (0..problem.len())
            .map(|p| {
                (last.sigma[p][4] - reference.sigma(problem.position[p][1])).abs()
                    * problem.volume[p]
            })
            .sum::<f64>()
            / (reference.rho_g * reference.height * 10.0);
        rows.push((cells, top, interface, stress_error));
        assert!(
            top < previous.0 && interface < previous.1,
            "errors must fall with h: {rows:?}"
        );
        previous = (top, interface);
        // The base carries the whole weight.
        let weight = reference.rho_g * reference.height;
        let reaction = out.reports.last().unwrap().reaction[1];
        assert!((reaction - weight).abs() < 1e-9 * weight, "{reaction}");
    }
    let (_, top, interface, stress) = *rows.last().unwrap();
    assert!(top < 0.01 && interface < 0.01, "{rows:?}");
    assert!(stress < 0.01, "{rows:?}");
    eprintln!("two-layer column (cells, top, interface, stress error): {rows:?}");
}

/// The boundary-modified B-spline (`basis = "bspline2_boundary"`) holds
/// a column at its fixed base: the two-layer scene with both layers at
/// E = 10⁵ Pa (a homogeneous column under self weight), whose top
/// displacement is within 1e-3 of the closed form at 8 to 32 cells. The
/// plain spline's padding functions leave the base free to move (u(0) =
/// (u₋₁ + u₁)/8 with both fixed): its error is 20 to 500 times larger and
/// falls only at first order.
#[test]
fn the_boundary_spline_holds_the_fixed_base() {
    let reference = TwoLayer {
        e_lower: 1e5,
        ..TwoLayer::SCENE
    };
    let top_error = |basis: &str, cells: usize| {
        let basis = format!("solver.basis={basis}");
        let cells = format!("mesh.cells=[1, {cells}]");
        let set = [
            basis.as_str(),
            "solver.domain_update=none",
            "material.0.youngs_modulus=1e5",
            &cells,
        ];
        let (problem, out) = run2(TWO_LAYER, &set);
        let p = problem.probes.iter().find(|(n, _)| n == "top").unwrap().1;
        let exact = reference.displacement(problem.position[p][1]);
        let weight = reference.rho_g * reference.height;
        let reaction = out.reports.last().unwrap().reaction[1];
        assert!((reaction - weight).abs() < 1e-9 * weight, "{reaction}");
        ((out.last.displacement[p][1] - exact) / exact).abs()
    };
    let boundary = [8, 16, 32].map(|n| top_error("bspline2_boundary", n));
    let plain = [8, 16, 32].map(|n| top_error("bspline2", n));
    eprintln!("column top error at 8, 16, 32 cells: boundary spline {boundary:?}, plain {plain:?}");
    // Measured: boundary 9.4e-4, 1.3e-4, 2.5e-4 (one point's error, which
    // does not fall monotonically); plain 7.3e-2, 3.5e-2, 1.7e-2 (the
    // slip of the base, first order).
    for k in 0..3 {
        assert!(boundary[k] < 1e-3, "{boundary:?}");
        assert!(
            plain[k] > 20.0 * boundary[k],
            "{plain:?} against {boundary:?}"
        );
    }
    assert!(
        plain[2] < 0.6 * plain[1] && plain[1] < 0.6 * plain[0],
        "{plain:?}"
    );
}

#[test]
fn slope_runs_with_its_curves_and_writes_png_and_vtu() {
    let (problem, out) = run2(SLOPE, &[]);
    // Gravity ramps to 1 at load factor 0.8, then the surcharge follows:
    // at the end the base carries the weight of every point plus the
    // surcharge on the upward faces, all of it vertical load.
    let weight: f64 = problem.mass.iter().sum::<f64>() * 9.81;
    let slope = &problem.bodies[1];
    assert_eq!(slope.name, "slope");
    let surcharge = 2.0e4 * 20.0;
    let reaction = out.reports.last().unwrap().reaction[1];
    assert!(
        (reaction - weight - surcharge).abs() < 1e-8 * reaction,
        "{reaction} against {}",
        weight + surcharge
    );
    // The soil yields; the foundation (Hencky, run as von Mises with an
    // infinite yield stress) does not.
    let found = &problem.bodies[0];
    assert!(
        found
            .points
            .clone()
            .all(|p| out.last.plastic_strain[p] == 0.0)
    );
    assert!(
        slope
            .points
            .clone()
            .any(|p| out.last.plastic_strain[p] > 1e-4)
    );

    let dir = run_mpm("slope.toml", "slope_scene");
    let png = std::fs::read(dir.join("final.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    for file in [
        "points.pvd",
        "reaction_base.csv",
        "probe_crest.csv",
        "summary.json",
    ] {
        assert!(dir.join(file).exists(), "{file}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["case"], "scene");
    let base = summary["reactions"]["base"][1].as_f64().unwrap();
    assert!((base - reaction).abs() < 1e-9 * reaction);
}

/// The soil scenes through `mpm`. The footing (issue 43, "Bearing
/// capacity", on the coarsest grid that resolves the footing: 4 cells
/// under the half-width): q/c within 5 % of Prandtl–Reissner's N_c =
/// 14.835 at φ = 20°. The biaxial test: the platen's pressure rises from
/// the initial 100 kPa and stays below the plane-strain limit 300 kPa that
/// the `plane_strain` matching shares with Mohr–Coulomb.
#[test]
fn the_soil_scenes_meet_their_limits() {
    let reaction = |dir: &std::path::Path, name: &str| {
        let text = std::fs::read_to_string(dir.join(format!("reaction_{name}.csv"))).unwrap();
        text.lines()
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    let dir = run_mpm("footing_mohr_coulomb.toml", "soil_footing");
    let q = -reaction(&dir, "footing").last().copied().unwrap() / 1.0e4;
    let n_c = 14.835;
    println!("footing: q/c = {q:.3} against N_c = {n_c}");
    assert!((q - n_c).abs() <= 0.05 * n_c, "q/c = {q}");
    let dir = run_mpm("biaxial_drucker_prager.toml", "soil_biaxial");
    let p: Vec<f64> = reaction(&dir, "platen").iter().map(|r| -r).collect();
    println!(
        "biaxial: platen pressure {:.0} → {:.0} Pa",
        p[0],
        p[p.len() - 1]
    );
    assert!(p[0] > 1.0e5 && p.windows(2).all(|w| w[1] > w[0]), "{p:?}");
    assert!(p[p.len() - 1] < 3.0e5, "{p:?}");
}

/// Bearing capacity with associated flow (issue 43): φ = ψ = 30°,
/// weightless, smooth footing, quadratic B-splines with 2 x 2 points per
/// 0.25 m cell (the soil theory page says why not F-bar). The cohesive
/// footing's pressure within 5 % of c N_c = 30.140 c and the cohesionless
/// one's under a surcharge q0 within 5 % of q0 N_q = 18.401 q0
/// (Prandtl–Reissner; the issue's tolerance). Measured: 29.23 c (−3.0 %)
/// and 19.06 q0 (+3.6 %); on 0.125 m grids 29.70 c (−1.5 %) and 18.88
/// q0 (+2.6 %).
#[test]
fn associated_footings_reach_prandtl_reissner() {
    let pressure = |scene: &str, label: &str, scale: f64| {
        let dir = run_mpm(scene, label);
        let text = std::fs::read_to_string(dir.join("reaction_footing.csv")).unwrap();
        let last = text.lines().last().unwrap();
        -last.split(',').nth(2).unwrap().parse::<f64>().unwrap() / scale
    };
    let phi = 30f64.to_radians();
    let n_q = (std::f64::consts::PI * phi.tan()).exp()
        * (std::f64::consts::FRAC_PI_4 + phi / 2.0).tan().powi(2);
    let n_c = (n_q - 1.0) / phi.tan();
    let q_c = pressure("footing_associated.toml", "footing_nc30", 1.0e4);
    let q_q = pressure("footing_surcharge.toml", "footing_nq30", 1.0e4);
    println!(
        "associated footings: q/c = {q_c:.3} (N_c = {n_c:.3}), q/q0 = {q_q:.3} (N_q = {n_q:.3})"
    );
    assert!((n_c - 30.140).abs() < 1e-3 && (n_q - 18.401).abs() < 1e-3);
    assert!((q_c - n_c).abs() <= 0.05 * n_c, "q/c = {q_c}");
    assert!((q_q - n_q).abs() <= 0.05 * n_q, "q/q0 = {q_q}");
}

/// Mohr–Coulomb at φ = 0 is Tresca, whose plane-strain limit load with
/// cohesion c is von Mises' with k = ρ_y/√2 = c (both reduce to τ1 − τ3 =
/// 2c in the plane of flow, Prandtl's (2 + π)c): the footing scene run
/// with each gives one footing pressure at collapse, to 1e-3 (the laws
/// differ only through the out-of-plane stress of the points not yet at
/// the limit). Measured on the scene's 0.25 m grid: 5.4917 c with both
/// (5e-6 apart), +6.8 % of 2 + π, +3.3 % on a 0.125 m grid (the F-bar
/// excess halving with the spacing, as in the locking study).
#[test]
fn tresca_and_von_mises_footings_collapse_at_one_pressure() {
    let scene = include_str!("../../../scenes/footing_mohr_coulomb.toml");
    let tresca = scene.replace("friction_angle = 20.0", "friction_angle = 0.0");
    let von_mises = scene
        .replace("model = \"mohr_coulomb\"", "model = \"von_mises\"")
        .replace(
            "cohesion = 1.0e4\nfriction_angle = 20.0\ndilation_angle = 0.0",
            "yield_stress = 14142.135623730951",
        );
    let pressure = |text: &str| {
        let (problem, out) = run2(text, &[]);
        let footing = problem.reactions[0].clone();
        -footing.total(out.reports.last().unwrap())[1] / 1.0e4
    };
    let (t, v) = (pressure(&tresca), pressure(&von_mises));
    println!("footing at φ = 0: Tresca {t:.5} c, von Mises {v:.5} c");
    assert!((t - v).abs() <= 1e-3 * v, "Tresca {t}, von Mises {v}");
    let prandtl = 2.0 + std::f64::consts::PI;
    assert!(t > prandtl && t < 1.1 * prandtl, "{t}");
}

/// Griffiths & Lane (1999), example 1 (issue 43, "Slope"): the 2:1 slope
/// with φ' = 20°, c'/γH = 0.05, ψ = 0 has a factor of safety of 1.4 by
/// their strength reduction (Bishop & Morgenstern's charts 1.38). On the
/// scene's 1 m grid the bisection (bracket ≤ 0.01, their non-convergence
/// criterion) must land in [1.35, 1.45]; a displacement criterion (the
/// crest moving 0.005 H = 5 cm under gravity) within 0.03 of it; and the
/// mechanism of the first failed trial must run through the toe: the
/// points on the face just above the toe and at the crest move with the
/// sliding mass (more than half its largest step displacement), those
/// 10 m behind the crest do not (under 5 %).
#[test]
fn the_griffiths_lane_slope_has_their_factor_of_safety() {
    let read = |dir: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
    };
    let dir = run_mpm("griffiths_lane_slope.toml", "slope_srf");
    let summary = read(&dir);
    let sr = &summary["strength_reduction"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let (fos, held, failed) = (
        f(&sr["factor_of_safety"]),
        f(&sr["last_held"]),
        f(&sr["first_failed"]),
    );
    println!("slope: F = {fos:.4} in [{held:.4}, {failed:.4}]");
    assert!((1.35..=1.45).contains(&fos), "{fos}");
    assert!(failed > held && failed - held <= 0.01, "[{held}, {failed}]");
    let trials = sr["trials"].as_array().unwrap();
    let rows = std::fs::read_to_string(dir.join("srf.csv")).unwrap();
    assert_eq!(rows.lines().count(), trials.len() + 1, "{rows}");
    let share = &summary["mechanism"]["probe_share"];
    let (toe, crest, behind) = (f(&share["toe"]), f(&share["crest"]), f(&share["behind"]));
    println!("mechanism: toe {toe:.3}, crest {crest:.3}, behind {behind:.4}");
    assert!(toe > 0.5 && crest > 0.5 && behind < 0.05, "{share}");
    assert!(dir.join("mechanism.png").is_file());
    let dir = run_mpm_set(
        "griffiths_lane_slope.toml",
        "slope_srf_displacement",
        &SLOPE_BY_DISPLACEMENT,
    );
    let by_displacement = f(&read(&dir)["strength_reduction"]["factor_of_safety"]);
    println!("slope by displacement: F = {by_displacement:.4}");
    assert!(
        (by_displacement - fos).abs() <= 0.03,
        "{by_displacement} against {fos}"
    );
}

/// A modified Cam-Clay triaxial cell (issue 43, "a Cam-Clay triaxial
/// cell", `scenes/triaxial_cam_clay.toml`): a normally consolidated cube
/// from an isotropic 100 kPa, compressed axially with its sides moved so
/// that every step is isochoric. Its homogeneous state must follow the
/// closed form of the undrained path at every step, p/p0 = (M²/(M² +
/// η²))^((λ̂ − κ̂)/λ̂) with exponent 0.75 — exact with the exponential
/// hardening in log strains, so to 1e-10 — at J = 1, towards the critical
/// state η = M (within 1e-3 of M after λ_z = 0.739). A Cam-Clay body
/// without `initial_stress` is refused at the body.
#[test]
fn a_cam_clay_triaxial_cell_follows_the_undrained_path() {
    let text = include_str!("../../../scenes/triaxial_cam_clay.toml");
    let (scene, src) = scene::parse(text, "triaxial_cam_clay.toml", &[]).unwrap();
    let problem = Problem::<3>::build(&scene, &src, scene.solver.padding()).unwrap();
    let (p0, m) = (1.0e5, 1.2_f64);
    let mut eta = 0.0;
    let mut steps = 0;
    scene::run(&problem, &RunControl::default(), |_, _, snap| {
        for (s, f) in snap.sigma.iter().zip(&snap.f) {
            let j = nalgebra::Matrix3::from_row_slice(f).determinant();
            assert!((j - 1.0).abs() < 1e-12, "J = {j}");
            let p = -(s[0] + s[4] + s[8]) / 3.0;
            let dev =
                nalgebra::Matrix3::from_row_slice(s) + nalgebra::Matrix3::from_diagonal_element(p);
            eta = (1.5 * dev.norm_squared()).sqrt() / p;
            let closed = (m * m / (m * m + eta * eta)).powf(0.75);
            assert!(
                (p / p0 - closed).abs() <= 1e-10 * closed,
                "p/p0 = {} against {closed}",
                p / p0
            );
        }
        steps += 1;
        Ok(())
    })
    .unwrap();
    println!(
        "Cam-Clay cell: {steps} steps on the undrained path, η = {eta:.6} at the end (M = {m})"
    );
    assert_eq!(steps, 20);
    assert!(eta < m && m - eta < 1e-3, "η = {eta}");
    let refused = refusal(&text.replace(
        "initial_stress = { kind = \"isotropic\", pressure = 1.0e5 }",
        "",
    ));
    assert!(
        refused.contains("body `sample` of modified_cam_clay material `clay` needs initial_stress"),
        "{refused}"
    );
}

/// Strength reduction of an undrained (φ = 0) slope: the Griffiths & Lane
/// geometry in Tresca soil (`mohr_coulomb` with φ = 0, c = 50 kPa), and
/// in von Mises soil of the same plane-strain strength (ρ_y = √2 c, the
/// yield stress strength reduction divides). A perfectly plastic body's
/// collapse load does not depend on its stiffness, so the factor of
/// safety of a φ = 0 slope is proportional to c (Taylor's stability
/// number c/(FγH) is a constant of the geometry): doubling c must double
/// F within the bisection's resolution, the two brackets' widths (0.0078
/// each) relative to F — 0.0055. Measured: F = 2.1367 and 4.2773 (ratio
/// 2.0017), von Mises 2.1523.
#[test]
fn an_undrained_slope_has_a_factor_of_safety_proportional_to_its_strength() {
    let text = include_str!("../../../scenes/griffiths_lane_slope.toml")
        .replace("friction_angle = 20.0", "friction_angle = 0.0");
    let run = |text: &str, test: &str| -> (f64, f64) {
        let dir = common::fresh_dir(test);
        let scene = dir.join("scene.toml");
        std::fs::write(&scene, text).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
            .arg("run")
            .arg(&scene)
            .arg("--out")
            .arg(dir.join("out"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
                .unwrap();
        let sr = &summary["strength_reduction"];
        let f = |k: &str| sr[k].as_f64().unwrap();
        (f("factor_of_safety"), f("first_failed") - f("last_held"))
    };
    let (f1, w1) = run(
        &text.replace("cohesion = 1.0e4", "cohesion = 5.0e4"),
        "slope_tresca_c",
    );
    let (f2, w2) = run(
        &text.replace("cohesion = 1.0e4", "cohesion = 1.0e5"),
        "slope_tresca_2c",
    );
    let von_mises = text
        .replace("model = \"mohr_coulomb\"", "model = \"von_mises\"")
        .replace(
            "cohesion = 1.0e4\nfriction_angle = 0.0\ndilation_angle = 0.0",
            "yield_stress = 70710.67811865475",
        );
    let (fv, _) = run(&von_mises, "slope_von_mises");
    println!(
        "undrained slope: F = {f1:.4} (c), {f2:.4} (2c), ratio {:.4}; von Mises {fv:.4}",
        f2 / f1
    );
    assert!(
        (f2 / (2.0 * f1) - 1.0).abs() <= w1 / f1 + w2 / f2,
        "{f1} and {f2}"
    );
    assert!(fv > 1.0 && fv.is_finite(), "von Mises: {fv}");
}

/// The Griffiths & Lane slope's overrides for the displacement criterion.
const SLOPE_BY_DISPLACEMENT: [&str; 3] = [
    "strength_reduction.criterion=displacement",
    "strength_reduction.probe=crest",
    "strength_reduction.displacement_limit=0.05",
];

/// A Mohr–Coulomb material's keys with a tension cut-off, for the valid
/// scene's block.
const SOIL_WITH_CUTOFF: &str = "model = \"mohr_coulomb\"\ncohesion = 1e3\nfriction_angle = 30.0\ndilation_angle = 5.0\ntension_cutoff = 5e2";

/// A minimal valid 2D scene, mutated by the table below.
const VALID: &str = r#"[mesh]
origin = [0.0, 0.0]
size = [2.0, 2.0]
cells = [2, 2]

[[material]]
name = "m"
model = "hencky"
youngs_modulus = 1e6
poisson_ratio = 0.3
density = 1.0

[[body]]
name = "b"
material = "m"
region = { box = { lower = [0.0, 0.0], upper = [2.0, 1.0] } }

[[boundary]]
set = "y_min"
kind = "fixed"

[[load]]
kind = "gravity"
acceleration = [0.0, -10.0]

[solver]
steps = 2
"#;

/// The soil laws run from a scene, beside an elastic material: the valid
/// scene's block as Mohr–Coulomb and as Drucker–Prager under gravity, and
/// a Hencky layer under a Mohr–Coulomb one.
#[test]
fn soil_materials_run_from_a_scene() {
    let soil = SOIL_WITH_CUTOFF;
    let dp =
        "model = \"drucker_prager\"\nmatching = \"inner\"\ncohesion = 1e3\nfriction_angle = 30.0";
    for model in [soil, dp] {
        let text = VALID.replacen("model = \"hencky\"", model, 1);
        let (_, out) = run2(&text, &[]);
        assert_eq!(out.summary.steps, 2);
    }
    let layered = VALID.replacen(
        "[[body]]",
        &format!(
            "[[material]]\nname = \"soil\"\n{soil}\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
             [[body]]\nname = \"top\"\nmaterial = \"soil\"\nregion = {{ box = {{ lower = [0.0, 1.0], upper = [2.0, 1.5] }} }}\n\n[[body]]"
        ),
        1,
    );
    let (_, out) = run2(&layered, &[]);
    assert_eq!(out.summary.steps, 2);
}

/// A geostatic column of Mohr–Coulomb soil (issue 43, "Initial stress"):
/// 10 m of cohesionless soil (φ = 30°, K0 = 1 − sin φ = 0.5, γ = ϱ₀g =
/// 19 620 N/m³) started from σ_v = −γz, σ_h = K0σ_v with its full weight
/// from the first step (a flat load curve). The discrete weak form is
/// integrated exactly (a linear stress against the linear basis, two
/// points per cell and axis), so the column starts in equilibrium: it
/// moves less than 1e-6 H in its step and keeps its stresses to 1e-8 γH.
/// A K0 that puts the column beyond yield is refused at its key.
const GEOSTATIC: &str = include_str!("../../../scenes/geostatic_column.toml");

#[test]
fn a_geostatic_column_starts_in_equilibrium() {
    let (gamma, height, k0) = (19_620.0, 10.0, 0.5);
    // The same column of normally consolidated Cam-Clay: the K0 state
    // (η = 0.75 < M) on its yield surface, its elasticity non-linear.
    let cam_clay = GEOSTATIC.replace(
        "model = \"mohr_coulomb\"\nyoungs_modulus = 2.0e7\npoisson_ratio = 0.3\ndensity = 2000.0\ncohesion = 0.0\nfriction_angle = 30.0",
        "model = \"modified_cam_clay\"\ndensity = 2000.0\ncompression_index = 0.2\nswelling_index = 0.05\ncritical_state_slope = 1.2\nshear_modulus = 5.0e6\nreference_pressure = 1.0e5",
    );
    assert_ne!(cam_clay, GEOSTATIC);
    for (label, text) in [("Mohr-Coulomb", GEOSTATIC), ("Cam-Clay", cam_clay.as_str())] {
        let (problem, out) = run2(text, &[]);
        let last = &out.last;
        let moved = last
            .displacement
            .iter()
            .map(|u| u[0].hypot(u[1]))
            .fold(0.0, f64::max);
        assert!(moved < 1e-6 * height, "{label}: moved {moved:e} m");
        let mut worst: f64 = 0.0;
        for (p, x) in problem.position.iter().enumerate() {
            let v = -gamma * (height - x[1]);
            let s = &last.sigma[p];
            let err = [(s[4], v), (s[0], k0 * v), (s[8], k0 * v), (s[1], 0.0)]
                .iter()
                .map(|(got, want)| (got - want).abs())
                .fold(0.0, f64::max);
            assert!(
                err <= 1e-8 * gamma * height,
                "{label}: point {p} at {x:?}: {s:?} against σ_v = {v}"
            );
            worst = worst.max(err / (gamma * height));
        }
        println!("geostatic {label} column: moved {moved:.2e} m, stresses within {worst:.2e} γH");
    }
    let refused = refusal(&GEOSTATIC.replace("k0 = 0.5", "k0 = 0.2"));
    assert!(
        refused.contains("bad.toml:29:18: initial_stress of body `soil` lies beyond the yield surface of material `soil`"),
        "{refused}"
    );
    let refused = refusal(&GEOSTATIC.replace("k0 = 0.5", "k0 = -1.0"));
    assert!(
        refused.contains("bad.toml:29:18: initial_stress: `k0` must be > 0"),
        "{refused}"
    );
    let refused = refusal(&GEOSTATIC.replace("k0 = 0.5", "k0 = 0.5, depth = 1.0"));
    assert!(refused.contains("unknown field `depth`"), "{refused}");
}

#[test]
fn the_valid_scene_builds_and_runs() {
    let (problem, out) = run2(VALID, &[]);
    assert_eq!(problem.len(), 8);
    assert_eq!(out.summary.steps, 2);
}

/// Each malformed scene gives its own message at its own place.
#[test]
fn malformed_scenes_are_refused_with_a_located_message() {
    let cases: &[(&str, &str, &str)] = &[
        // (replace this, with this, expect this in the message)
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\nfriction_angle = 30.0",
            "bad.toml:7:8: material `m` (mohr_coulomb) needs cohesion",
        ),
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\ncohesion = -1.0\nfriction_angle = 30.0",
            "bad.toml:9:12: material `m`: cohesion must be >= 0 Pa",
        ),
        (
            "model = \"hencky\"",
            "model = \"drucker_prager\"\nmatching = \"outer\"\ncohesion = 0.0\nfriction_angle = 0.0",
            "bad.toml:10:12: material `m`: cohesion must be >= 0 Pa, and > 0 when friction_angle = 0",
        ),
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\ncohesion = 1.0\nfriction_angle = 95.0",
            "bad.toml:10:18: material `m`: friction_angle must lie in [0, 90) degrees",
        ),
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\ncohesion = 1.0\nfriction_angle = 20.0\ndilation_angle = 25.0",
            "bad.toml:11:18: material `m`: dilation_angle must lie in [0, friction_angle] degrees",
        ),
        (
            "model = \"hencky\"",
            "model = \"hencky\"\ncohesion = 1.0",
            "bad.toml:9:12: material `m`: cohesion applies to model = mohr_coulomb or drucker_prager",
        ),
        (
            "model = \"hencky\"",
            "model = \"drucker_prager\"\ncohesion = 1.0\nfriction_angle = 30.0",
            "bad.toml:7:8: material `m` (drucker_prager) needs matching",
        ),
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\ncohesion = 1.0\nfriction_angle = 30.0\nmatching = \"outer\"",
            "bad.toml:11:12: material `m`: matching applies to model = drucker_prager",
        ),
        (
            "model = \"hencky\"",
            "model = \"drucker_prager\"\ncohesion = 1.0\nfriction_angle = 30.0\nmatching = \"middle\"",
            "bad.toml:11:12: unknown variant `middle`, expected one of `outer`, `inner`, `plane_strain`",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\nspacings = [1.0]",
            "bad.toml:5:1: unknown field `spacings`",
        ),
        (
            "steps = 2",
            "steps = 18446744073709551615",
            "bad.toml:27:9: load increments below 1e-12 would not move the load factor (min_increment 5.293955920339377e-23: 1/steps / 1024 by default)",
        ),
        (
            "steps = 2",
            "steps = 2\nlinear = \"direct\"\nlinear_tolerance = 1e-10",
            "bad.toml:29:20: solver `linear_tolerance` applies to the iterative solvers (`linear = \"iterative\"`, `\"auto\"` or `{ petsc = ... }`) only",
        ),
        (
            "steps = 2",
            "steps = 2\nlinear = \"iterative\"\nmax_direct_dofs = 10",
            "bad.toml:29:19: solver `max_direct_dofs` applies to `linear = \"auto\"` only",
        ),
        (
            "steps = 2",
            "steps = 2\nlinear_tolerance = 2.0",
            "bad.toml:28:20: solver `linear_tolerance` must be below 1 (a relative residual)",
        ),
        (
            "steps = 2",
            "steps = 2\nlinear = \"gmres\"",
            "bad.toml:28:10: unknown variant `gmres`, expected one of `auto`, `direct`, `iterative`",
        ),
        (
            "youngs_modulus = 1e6",
            "youngs_modulus = \"stiff\"",
            "bad.toml:9:18: invalid type: string \"stiff\", expected f64",
        ),
        (
            "upper = [2.0, 1.0]",
            "upper = [3.0, 1.0]",
            "bad.toml:14:8: body `b` reaches outside the mesh: its region spans [0.0, 0.0] to [3.0, 1.0]",
        ),
        (
            "lower = [0.0, 0.0], upper = [2.0, 1.0]",
            "lower = [0.0, 0.0], upper = [0.1, 0.1]",
            "bad.toml:14:8: body `b` holds no material points",
        ),
        (
            "material = \"m\"",
            "material = \"steel\"",
            "bad.toml:15:12: no material named `steel`; the scene has: m",
        ),
        (
            "set = \"y_min\"",
            "set = \"bottom\"",
            "bad.toml:19:7: no node set named `bottom`",
        ),
        (
            "model = \"hencky\"",
            "model = \"neo_hooke\"",
            "bad.toml:8:9: unknown variant `neo_hooke`, expected one of `hencky`, `neo_hookean`, `von_mises`",
        ),
        (
            "poisson_ratio = 0.3",
            "poisson_ratio = 0.5",
            "bad.toml:7:8: material `m`: ",
        ),
        (
            "origin = [0.0, 0.0]",
            "origin = [0.0, 0.0, 0.0]",
            "bad.toml:3:8: mesh `size` has 2 components; the scene is 3D",
        ),
        (
            "acceleration = [0.0, -10.0]",
            "acceleration = [0.0, -10.0]\ncurve = \"ramp\"",
            "bad.toml:25:9: no curve named `ramp`",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"roller\"\ndisplacement = { y = 1.0 }",
            "bad.toml:20:8: `displacement` applies to kind = displacement, not roller",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"velocity\"",
            "bad.toml:20:8: kind = velocity needs the explicit solver",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"friction\"\nfriction = 0.3",
            "bad.toml:20:8: kind = friction needs the explicit solver; the implicit solver's frictional wall is kind = contact (a rigid tool)",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"fixed\"\nfriction = 0.3",
            "bad.toml:21:12: `friction` applies to kind = friction or contact, not fixed",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"contact\"\nfriction = 0.3\nrough = true",
            "bad.toml:21:12: give `friction = μ` or `rough = true`, not both (rough is pure stick)",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"contact\"\nnormal_stiffness = -1.0",
            "bad.toml:21:20: `normal_stiffness` is a penalty per unit area (Pa/m): finite and > 0, got -1",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"roller\"\nrough = true",
            "bad.toml:20:8: `rough` applies to kind = contact, not roller",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"contact\"\nnormal = { x = 0.0 }",
            "bad.toml:21:10: `normal` must not be zero",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"contact\"\ngradient = [[0.0, 1.0], [0.0, 0.0]]",
            "bad.toml:21:12: `gradient` applies to kind = displacement, not contact",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"fixed\"\ngap_check = true",
            "bad.toml:20:8: `gap_check` applies to kind = friction, not fixed",
        ),
        (
            "steps = 2",
            "steps = 0",
            "bad.toml:27:9: solver `steps` must be at least 1, got 0",
        ),
        (
            "[solver]",
            "[[curve]]\nname = \"c\"\npoints = [[0.0, 0.0], [0.5, 1.0], [0.4, 2.0]]\n[solver]",
            "bad.toml:28:10: curve `c`: times must increase, but row 3 has time 0.4 after 0.5",
        ),
        (
            "[[boundary]]",
            "[[body]]\nname = \"b2\"\nmaterial = \"m\"\nregion = { box = { lower = [0.0, 0.5], upper = [2.0, 2.0] } }\n\n[[boundary]]",
            "bad.toml:19:8: body `b2` overlaps body `b` (both hold [0.25, 0.75])",
        ),
        (
            "[[boundary]]",
            "[[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = { box = { lower = [0.0, 1.0], upper = [2.0, 2.0] } }\n\n[[boundary]]",
            "bad.toml:19:8: a second body named `b`",
        ),
        (
            "region = { box",
            "region = { polygon = [[0.0, 0.0], [1.0, 0.0]] }\nregio = { box",
            "bad.toml:17:1: unknown field `regio`",
        ),
        (
            "kind = \"gravity\"",
            "kind = \"gravity\"\nforce = [1.0, 0.0]",
            "bad.toml:23:8: `force` applies to kind = point loads",
        ),
        (
            "cells = [2, 2]",
            "spacing = [0.75, 1.0]",
            "bad.toml:4:11: mesh `spacing` 0.75 must be positive and divide the size 2 along x",
        ),
        (
            "kind = \"gravity\"\nacceleration = [0.0, -10.0]",
            "kind = \"manufactured\"\nfield = \"vortex\"",
            "bad.toml:24:9: unknown manufactured field `vortex`; the fields are: annulus_torsion",
        ),
        (
            "kind = \"gravity\"\nacceleration = [0.0, -10.0]",
            "kind = \"manufactured\"\nfield = \"annulus_torsion\"\nparameters = { inner_radius = 0.75, outer = 1.25, alpha = 0.1 }",
            "bad.toml:25:14: field `annulus_torsion` has no parameter `outer`; it takes inner_radius, outer_radius, alpha",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\nlayers = 3",
            "bad.toml:5:10: `inner_radius`, `outer_radius`, `layers`, `ring_nodes`, `jitter` and `seed` apply to kind = \"annulus\" meshes",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\npatches = true",
            "bad.toml:5:11: `patches` applies to kind = \"simplex\" meshes",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\ncoordinates = [[0.0, 2.0], [0.0, 2.0]]",
            "bad.toml:5:15: `coordinates` applies to kind = \"simplex\" meshes (a grid's cells are equal)",
        ),
        (
            "material = \"m\"",
            "material = \"m\"\nplacement = \"keast11\"",
            "bad.toml:16:13: placement = keast11 places points in tetrahedra",
        ),
        (
            "[[boundary]]",
            "[[node_set]]\nname = \"s\"\naround = \"nobody\"\n\n[[boundary]]",
            "bad.toml:20:10: no body named `nobody`; the scene has: b",
        ),
        (
            "[[boundary]]",
            "[[node_set]]\nname = \"s\"\n\n[[boundary]]",
            "bad.toml:19:8: node set `s` needs one of `region` or `around`",
        ),
        (
            "[[boundary]]\nset = \"y_min\"\nkind = \"fixed\"",
            "[[node_set]]\nname = \"s\"\naround = \"b\"\n\n[[boundary]]\nset = \"s\"\nkind = \"roller\"",
            "bad.toml:23:7: a roller needs a grid face for its normal; `s` follows a body",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"displacement\"\ngradient = [[1.0]]",
            "bad.toml:21:12: `gradient` must be 2 rows of 2 numbers in a 2D scene",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"stretch\"\naxis = \"w\"\nextension = 1.0\ndriven = \"y_max\"",
            "bad.toml:8:8: `axis` must be one of x, y",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"translation\"\naxis = \"x\"\ndisplacement = [0.0, -0.1]\nfixed = \"y_min\"\ndriven = \"y_max\"",
            "`axis` does not apply to a translation motion",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"translation\"\ndisplacement = [0.0, -0.1]\ndriven = \"y_max\"",
            "a translation needs `fixed`",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"translation\"\ndisplacement = [0.0, -0.1, 0.0]\nfixed = \"y_min\"\ndriven = \"y_max\"",
            "translation `displacement` has 3 components; the scene is 2D",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"translation\"\ndisplacement = [0.0, -0.1]\nfixed = \"x_min\"\ndriven = \"y_max\"",
            "a translation needs non-empty carried (`y_max`, 3 nodes) and fixed (`x_min`, 3 nodes) sets with no node in both",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"stretch\"\naxis = \"y\"\nextension = 1.0\nfixed = \"y_min\"\ndriven = \"y_max\"",
            "`fixed` does not apply to a stretch or rotation motion",
        ),
        (
            "[solver]",
            "[[node_set]]\nname = \"s\"\naround = \"b\"\n\n[output]\nreaction = [{ name = \"r\", set = \"s\" }]\n\n[solver]",
            "bad.toml:31:33: node set `s` follows a body (its nodes change every step)",
        ),
        // The [solver] keys of one kind are refused with the other.
        (
            "steps = 2",
            "steps = 2\nend_time = 1.0",
            "bad.toml:28:12: solver `end_time` applies to kind = \"explicit\" (the implicit solver steps the load factor: `steps`, `max_increment`, `min_increment`)",
        ),
        (
            "steps = 2",
            "steps = 2\nlocking = \"cell_averaged\"",
            "bad.toml:28:11: locking = cell_averaged is the explicit solver's dilatation averaging",
        ),
        (
            "material = \"m\"",
            "material = \"m\"\nvelocity = [1.0, 0.0]",
            "bad.toml:16:12: a body's `velocity` (its initial velocity) applies to the explicit solver",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"",
            "bad.toml:27:8: kind = \"explicit\" needs `end_time`, the simulated time to reach (s)",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nsteps = 2",
            "bad.toml:29:9: solver `steps` applies to the implicit solver; kind = \"explicit\" steps in time (`end_time`, `cfl` or `time_step`)",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ntolerance = 1e-6",
            "bad.toml:29:13: solver `tolerance` applies to the implicit solver",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nformulation = \"ul\"",
            "bad.toml:29:15: solver `formulation` applies to the implicit solver",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nbasis = \"cpdi2\"\ndomain_update = \"midpoint\"",
            "bad.toml:30:17: basis = cpdi2 convects its corners with the grid; domain_update = midpoint applies to gimp only",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nbasis = \"gimp\"\ndomain_update = \"cpdi2\"",
            "bad.toml:30:17: domain_update = cpdi2 convects CPDI2 corners; use it with basis = cpdi2",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nlocking = \"fbar\"",
            "bad.toml:29:11: locking = fbar is an implicit treatment; the explicit solver takes locking = \"none\" or \"cell_averaged\"",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = -1.0",
            "bad.toml:28:12: solver `end_time` must be positive, got -1",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5\ntime_step = 0.01",
            "bad.toml:30:13: give solver `cfl` or `time_step`, not both",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ncfl = 1.5",
            "bad.toml:29:7: solver `cfl` must lie in (0, 1], got 1.5",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ntime_step = 0.0",
            "bad.toml:29:13: solver `time_step` must be positive, got 0",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ntransfer = \"blend\"",
            "bad.toml:29:12: transfer = \"blend\" needs `alpha`, its FLIP fraction in [0, 1]",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\nalpha = 0.5",
            "bad.toml:29:9: solver `alpha` applies to transfer = \"blend\" (transfer = \"flip\" has α = 1)",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ntransfer = \"blend\"\nalpha = 1.5",
            "bad.toml:30:9: solver `alpha` must lie in [0, 1], got 1.5",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\ntransfer = \"apic\"",
            "bad.toml:29:12: unknown variant `apic`, expected one of `pic`, `flip`, `blend`, `tpic`, `tflip`",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\noutput_interval = 0.0",
            "bad.toml:29:19: solver `output_interval` must be positive, got 0",
        ),
        (
            "model = \"hencky\"\nyoungs_modulus = 1e6",
            "model = \"modified_cam_clay\"\ncompression_index = 0.2\nswelling_index = 0.05\ncritical_state_slope = 1.2\nshear_modulus = 1e6\nreference_pressure = 1e5\nyoungs_modulus = 1e6",
            "bad.toml:14:18: material `m`: youngs_modulus does not apply to model = modified_cam_clay",
        ),
        (
            "model = \"hencky\"\nyoungs_modulus = 1e6",
            "model = \"modified_cam_clay\"\ncompression_index = 0.04\nswelling_index = 0.05",
            "bad.toml:9:21: material `m`: compression_index must be > swelling_index, got 0.04",
        ),
        (
            "model = \"hencky\"\nyoungs_modulus = 1e6",
            "model = \"modified_cam_clay\"\ncompression_index = 0.2\nswelling_index = 0.05",
            "bad.toml:7:8: material `m` (modified_cam_clay) needs critical_state_slope",
        ),
        (
            "model = \"hencky\"",
            "model = \"drucker_prager\"\nmatching = \"outer\"\ncohesion = 1e3\nfriction_angle = 30.0\ntension_cutoff = 1e3",
            "bad.toml:12:18: material `m`: tension_cutoff applies to model = mohr_coulomb",
        ),
        (
            "model = \"hencky\"",
            "model = \"mohr_coulomb\"\ncohesion = 1e3\nfriction_angle = 30.0\ntension_cutoff = 1e4",
            "tensile strength = 10000 must be",
        ),
        (
            "model = \"hencky\"",
            "model = \"hencky\"\noverconsolidation_ratio = 2.0",
            "bad.toml:9:27: material `m`: overconsolidation_ratio applies to model = modified_cam_clay",
        ),
        (
            "youngs_modulus = 1e6\n",
            "",
            "bad.toml:7:8: material `m` (hencky) needs youngs_modulus",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\nlower = 0.0",
            "bad.toml:30:9: strength_reduction: `lower` must be finite and > 0, got 0",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\nlower = 2.0\nupper = 1.5",
            "bad.toml:31:9: strength_reduction: `upper` (1.5) must exceed `lower` (2)",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\nmax_trials = 1",
            "bad.toml:30:14: strength_reduction: `max_trials` must be in 2..=1000",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\ncriterion = \"displacement\"",
            "strength_reduction: `criterion = \"displacement\"` needs `probe`",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\ncriterion = \"displacement\"\nprobe = \"nowhere\"\ndisplacement_limit = 0.1",
            "bad.toml:31:9: strength_reduction: no [[output.probe]] is named `nowhere`",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\ndisplacement_limit = 0.1",
            "bad.toml:30:22: strength_reduction: `displacement_limit` belongs to `criterion = \"displacement\"`",
        ),
        (
            "steps = 2",
            "steps = 2\n\n[strength_reduction]\nbisect = true",
            "unknown field `bisect`",
        ),
        (
            "steps = 2",
            "kind = \"explicit\"\nend_time = 1.0\n\n[strength_reduction]\nlower = 1.0",
            "strength_reduction runs the implicit solver",
        ),
    ];
    let mut wrong = Vec::new();
    for (from, to, expected) in cases {
        assert!(VALID.contains(from), "{from}");
        let text = VALID.replacen(from, to, 1);
        let message = refusal(&text);
        if !message.contains(expected) {
            wrong.push(format!(
                "for `{to}`\nexpected: {expected}\n     got: {message}"
            ));
        }
    }
    // The same scene run by the explicit solver: what it cannot take
    // outside [solver], each refused where it is.
    let explicit = VALID.replacen("steps = 2", "kind = \"explicit\"\nend_time = 0.1", 1);
    let explicit_cases: &[(&str, &str, &str)] = &[
        (
            "kind = \"fixed\"",
            "kind = \"displacement\"\ndisplacement = { y = 0.1 }",
            "bad.toml:20:8: a non-zero displacement follows the implicit solver's load factor; the explicit solver holds nodes (fixed, roller, a zero displacement) or moves them at a constant velocity (kind = \"velocity\")",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"velocity\"",
            "bad.toml:20:8: kind = velocity needs `velocity = { x = …, y = … }` (m/s)",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"fixed\"\nvelocity = { x = 1.0 }",
            "bad.toml:20:8: `velocity` applies to kind = velocity, not fixed",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"friction\"",
            "bad.toml:20:8: kind = friction needs `friction = μ`, the Coulomb coefficient (≥ 0; 0 is a slip wall that lets go)",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"friction\"\nfriction = -0.1",
            "bad.toml:21:12: `friction` is a Coulomb coefficient: finite and ≥ 0, got -0.1",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"velocity\"\nvelocity = { x = 1.0 }\nfriction = 0.2",
            "bad.toml:22:12: `friction` applies to kind = friction or contact, not velocity",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"contact\"",
            "bad.toml:20:8: kind = contact (a rigid tool) needs the implicit solver; the explicit solver's frictional wall is kind = friction",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"friction\"\nfriction = 0.2\ndisplacement = { y = 0.0 }",
            "bad.toml:20:8: `displacement` applies to kind = displacement, not friction",
        ),
        (
            "[[boundary]]\nset = \"y_min\"\nkind = \"fixed\"",
            "[[node_set]]\nname = \"s\"\nregion = { box = { lower = [0.0, 0.0], upper = [2.0, 0.1] } }\n\n[[boundary]]\nset = \"s\"\nkind = \"friction\"\nfriction = 0.2",
            "bad.toml:23:7: a friction wall needs a grid face for its normal (x_max, x_min, y_max, y_min); `s` is not one",
        ),
        (
            "kind = \"fixed\"",
            "kind = \"velocity\"\nvelocity = { z = 1.0 }",
            "bad.toml:21:12: a 2D scene has no z component",
        ),
        (
            "[[boundary]]\nset = \"y_min\"\nkind = \"fixed\"",
            "[[node_set]]\nname = \"s\"\naround = \"b\"\n\n[[boundary]]\nset = \"s\"\nkind = \"fixed\"",
            "bad.toml:23:7: node set `s` follows a body; the explicit solver's conditions hold fixed sets of nodes",
        ),
        (
            "acceleration = [0.0, -10.0]",
            "acceleration = [0.0, -10.0]\nbody = \"b\"",
            "bad.toml:25:8: an explicit gravity load without a curve is the solver's gravitational field, on every body: leave out `body`",
        ),
        (
            "kind = \"gravity\"\nacceleration = [0.0, -10.0]",
            "kind = \"manufactured\"\nfield = \"annulus_torsion\"\nparameters = { inner_radius = 0.75, outer_radius = 1.25, alpha = 0.1 }",
            "bad.toml:23:8: a manufactured load balances a quasi-static solution; the explicit solver does not take it",
        ),
        (
            "cells = [2, 2]",
            "cells = [2, 2]\n\n[mesh.motion]\nkind = \"stretch\"\naxis = \"y\"\nextension = 1.0\ndriven = \"y_max\"",
            "bad.toml:7:8: a moving mesh follows the implicit solver's load factor",
        ),
        (
            "[mesh]",
            "[mesh]\nkind = \"simplex\"",
            "bad.toml:28:8: kind = \"explicit\" runs on regular grids ([mesh] kind = \"grid\")",
        ),
        (
            "density = 1.0",
            "density = 0.0",
            "bad.toml:11:11: the explicit solver needs a positive density",
        ),
        (
            "[[body]]",
            "[[material]]\nname = \"m2\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 2e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n[[body]]",
            "bad.toml:14:8: material `m2` is neo_hookean but `m` is hencky: the materials of one scene share one model",
        ),
        (
            "material = \"m\"",
            "material = \"m\"\nvelocity = [1.0, 0.0, 0.0]",
            "bad.toml:16:12: body `velocity` has 3 components; the scene is 2D",
        ),
        (
            "[solver]",
            "[output]\nreaction = [{ name = \"r\", set = \"y_min\" }]\n\n[solver]",
            "bad.toml:27:22: reaction outputs are the implicit solver's nodal reactions; the explicit solver does not compute them",
        ),
        (
            "[solver]",
            "[output]\nevery = 2\n\n[solver]",
            "bad.toml:27:9: output `every` counts the implicit solver's load steps",
        ),
    ];
    for (from, to, expected) in explicit_cases {
        assert!(explicit.contains(from), "{from}");
        let text = explicit.replacen(from, to, 1);
        let message = refusal(&text);
        if !message.contains(expected) {
            wrong.push(format!(
                "for `{to}` (explicit)\nexpected: {expected}\n     got: {message}"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn missing_sections_and_bad_overrides_are_named() {
    let start = VALID.find("[[body]]").unwrap();
    let end = VALID.find("[[boundary]]").unwrap();
    let no_body = format!("{}{}", &VALID[..start], &VALID[end..]);
    assert_eq!(refusal(&no_body), "bad.toml: missing field `body`");
    // Less padding than the basis needs.
    let thin = VALID
        .replacen("cells = [2, 2]", "cells = [2, 2]\npadding = 0", 1)
        .replacen("steps = 2", "steps = 2\nbasis = \"bspline2\"", 1);
    assert_eq!(
        refusal(&thin),
        "bad.toml:5:11: basis = bspline2 needs 1 padding cell(s), got 0"
    );
    let without_material = VALID.replacen("[[material]]", "[unused]", 1);
    assert!(refusal(&without_material).contains("unknown field `unused`"));
    // An index addresses one table of an array of tables.
    let (scene, _) =
        scene::parse(VALID, "v.toml", &["material.0.youngs_modulus=3e6".into()]).unwrap();
    assert_eq!(
        scene.materials[0]
            .youngs_modulus
            .as_ref()
            .map(|v| *v.get_ref()),
        Some(3e6)
    );
    for (set, message) in [
        (
            "material.1.density=2",
            "`material` has 1 entries (indices 0 to 0); there is no index 1",
        ),
        (
            "material.density=2",
            "`material` is an array: address one of its 1 tables by index, e.g. `material.0.density`",
        ),
        (
            "material.0.name.x=2",
            "`material.0.name` is a string, not a table",
        ),
    ] {
        let e = scene::parse(VALID, "v.toml", &[set.into()])
            .unwrap_err()
            .to_string();
        assert_eq!(e, format!("override `{set}`: {message}"));
    }
    let e = scene::parse(VALID, "v.toml", &["solver.stepz=3".into()]).unwrap_err();
    assert!(
        matches!(&e, SceneError::Override { text, message } if text == "solver.stepz=3" && message.contains("unknown field `stepz`")),
        "{e}"
    );
}

/// Random edits of a valid scene: deleting a line, truncating the file,
/// swapping a value for one of another type. Whatever the result, parsing
/// and building return (an error or a problem) and never panic.
fn mutated() -> impl Strategy<Value = String> {
    let lines: Vec<String> = VALID.lines().map(str::to_owned).collect();
    let n = lines.len();
    let values = prop_oneof![
        Just("\"text\"".to_owned()),
        Just("-1".to_owned()),
        Just("0".to_owned()),
        Just("1e300".to_owned()),
        Just("[]".to_owned()),
        Just("[1.0]".to_owned()),
        Just("[1.0, 2.0, 3.0]".to_owned()),
        Just("{}".to_owned()),
        Just("true".to_owned()),
        Just("18446744073709551615".to_owned()),
    ];
    (0..3usize, 0..n, values, 0..VALID.len()).prop_map(move |(kind, line, value, cut)| match kind {
        0 => lines
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != line)
            .map(|(_, l)| l.as_str())
            .collect::<Vec<_>>()
            .join("\n"),
        1 => {
            let mut cut = cut;
            while !VALID.is_char_boundary(cut) {
                cut -= 1;
            }
            VALID[..cut].to_owned()
        }
        _ => lines
            .iter()
            .enumerate()
            .map(|(k, l)| match (k == line, l.split_once(" = ")) {
                (true, Some((key, _))) => format!("{key} = {value}"),
                _ => l.clone(),
            })
            .collect::<Vec<_>>()
            .join("\n"),
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenes_never_panic(text in mutated()) {
        if let Ok((scene, src)) = scene::parse(&text, "m.toml", &[]) {
            let built = match scene::dimension(&scene, &src) {
                Ok(2) => Problem::<2>::build(&scene, &src, scene.solver.padding()).map(|p| p.len()),
                Ok(_) => Problem::<3>::build(&scene, &src, scene.solver.padding()).map(|p| p.len()),
                Err(e) => Err(e),
            };
            if let Ok(points) = built {
                prop_assert!(points > 0);
                // What builds also runs to an answer or a typed error.
                if let Ok(problem) = Problem::<2>::build(&scene, &src, scene.solver.padding()) {
                    let _ = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(()));
                }
            }
        }
    }
}

/// The built-in column case and its scene file give the same material
/// points and the same stresses, bit for bit, for several variants; eq.
/// (42) is then the same number.
#[test]
fn column_scene_equals_the_column_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::column::{self, ColumnParams};
    use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind};
    let text = include_str!("../../../scenes/coombs2020_column.toml");
    let variants = [
        (
            BasisKind::Gimp,
            DomainUpdateKind::Stretch,
            FormulationKind::Pc,
        ),
        (
            BasisKind::Linear,
            DomainUpdateKind::None,
            FormulationKind::Ul,
        ),
        (
            BasisKind::BSpline2,
            DomainUpdateKind::None,
            FormulationKind::Pc,
        ),
    ];
    for (basis, update, formulation) in variants {
        let params = ColumnParams {
            basis,
            domain_update: update,
            formulation,
            ..ColumnParams::default()
        };
        let case = column::ColumnCase::run(
            &params,
            &params.variant(),
            &RunControl::default(),
            |_, _, _| Ok(()),
        )
        .unwrap();
        let set = [
            format!("solver.basis={basis}"),
            format!("solver.domain_update={update}"),
            format!("solver.formulation={formulation}"),
        ];
        let set: Vec<&str> = set.iter().map(String::as_str).collect();
        let (problem, out) = run2(text, &set);
        let built = column::ColumnCase::build(&params, &params.variant()).unwrap();
        assert_eq!(problem.position, built.position, "{basis}");
        assert_eq!(
            out.last.sigma, case.output.last.sigma,
            "{basis} {update} {formulation}"
        );
        assert_eq!(out.last.position, case.output.last.position);
        let z0: Vec<f64> = problem.position.iter().map(|x| x[1]).collect();
        assert_eq!(params.error(&out.last, &z0, &problem.volume), case.error);
    }
}

/// `scenes/features.toml` runs: the prescribed displacement follows its
/// curve (the pulled end's reaction grows with it), the blocks yield
/// under their own weight and the point loads, and only the chosen fields
/// are written.
#[test]
fn features_scene_runs_with_every_remaining_key() {
    let text = include_str!("../../../scenes/features.toml");
    let (problem, out) = run2(text, &[]);
    assert_eq!(problem.bodies.len(), 2);
    assert_eq!(problem.padding, 1);
    // The hole: no point within 0.5 of its centre.
    assert!(
        problem
            .position
            .iter()
            .all(|x| (x - nalgebra::Vector2::new(2.0, 1.0)).norm() > 0.5)
    );
    // The pulled end's own reaction (the sum over every prescribed dof is
    // the body's x balance, zero to the tolerance).
    let end = problem
        .reactions
        .iter()
        .find(|r| r.name == "pulled")
        .unwrap();
    let pulled: Vec<f64> = out.reports.iter().map(|r| end.total(r)[0]).collect();
    assert!(pulled[0] > 0.0, "{pulled:?}");
    assert!(pulled.windows(2).all(|w| w[1] > w[0]), "{pulled:?}");
    for r in &out.reports {
        assert!(r.reaction[0].abs() < 1e-6 * pulled[pulled.len() - 1]);
    }
    let dir = run_mpm("features.toml", "features_scene");
    let vtu = std::fs::read_to_string(dir.join("points_0002.vtu")).unwrap();
    for (name, wanted) in [
        ("displacement", true),
        ("cauchy_stress", true),
        ("equivalent_plastic_strain", true),
        ("body", true),
        ("material", true),
        ("volume", false),
        ("deformation_gradient", false),
    ] {
        assert_eq!(vtu.contains(&format!("Name=\"{name}\"")), wanted, "{name}");
    }
    let reactions = std::fs::read_to_string(dir.join("reaction_pulled.csv")).unwrap();
    assert_eq!(reactions.lines().count(), 1 + out.reports.len());
}

/// The `[[contact]]` tables, each mistake refused where it is: an
/// implicit scene, a body that does not exist, a body twice, no body, a
/// negative friction, a material-point fixity or an absorbing boundary
/// beside contact.
#[test]
fn contact_tables_are_checked() {
    let explicit = VALID.replacen("steps = 2", "kind = \"explicit\"\nend_time = 0.1", 1);
    let contact = |table: &str| {
        explicit.replacen(
            "end_time = 0.1",
            &format!("end_time = 0.1\n\n[[contact]]\n{table}"),
            1,
        )
    };
    let cases = [
        (
            VALID.replacen("steps = 2", "steps = 2\n\n[[contact]]\nbodies = [\"b\"]", 1),
            "bad.toml:30:10: [[contact]] is a condition of the explicit solver",
        ),
        (
            contact("bodies = [\"nope\"]"),
            "bad.toml:31:11: no body named `nope`; the scene has: b",
        ),
        (
            contact("bodies = [\"b\", \"b\"]"),
            "bad.toml:31:16: body `b` is already in a contact: a body has one velocity field",
        ),
        (
            contact("bodies = []"),
            "bad.toml:31:10: contact `bodies` names no body",
        ),
        (
            contact("bodies = [\"b\"]\nfriction = -0.2"),
            "bad.toml:32:12: contact `friction` -0.2 must be finite and non-negative",
        ),
        (
            contact(
                "bodies = [\"b\"]\n\n[[point_fixity]]\nregion = { box = { lower = [0.0, 0.0], upper = [2.0, 0.5] } }\nvelocity = { x = 0.0 }",
            ),
            "bad.toml:31:10: [[contact]] is not supported with material-point fixities",
        ),
        (
            contact("bodies = [\"b\"]").replacen(
                "kind = \"fixed\"",
                "kind = \"absorbing\"\nmaterial = \"m\"",
                1,
            ),
            "bad.toml:32:10: [[contact]] is not supported with absorbing boundaries",
        ),
    ];
    for (text, expected) in cases {
        let message = refusal(&text);
        assert!(
            message.contains(expected),
            "expected: {expected}\n     got: {message}"
        );
    }
    // A valid table: the block alone in field 1 with μ = 0.3 (field 0,
    // the default one, is empty).
    let text = contact("bodies = [\"b\"]\nfriction = 0.3");
    let (scene, src) = scene::parse(&text, "scene.toml", &[]).unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let setup = problem.explicit.as_ref().unwrap().contact.as_ref().unwrap();
    assert_eq!(setup.friction, [0.0, 0.3]);
    assert!(!setup.field.is_empty() && setup.field.iter().all(|&k| k == 1));
}

/// Every key the guide page documents appears in a scene that a test of
/// this file runs.
#[test]
fn every_documented_key_is_exercised() {
    let guide = include_str!("../../../docs/src/guide/scenes.md");
    let scenes = [
        TWO_LAYER,
        SLOPE,
        include_str!("../../../scenes/features.toml"),
        include_str!("../../../scenes/ghost_plate.toml"),
        include_str!("../../../scenes/coombs2020_column.toml"),
        include_str!("../../../scenes/cube_gmsh.toml"),
        include_str!("../../../scenes/coombs2020_shear.toml"),
        include_str!("../../../scenes/wang2021_stretch.toml"),
        include_str!("../../../scenes/coombs2020_annulus.toml"),
        WANG_FOOTING,
        include_str!("../../../scenes/wang2021_vane_slice.toml"),
        include_str!("../../../scenes/wang2021_vane_full.toml"),
        include_str!("../../../scenes/wang2021_indentation.toml"),
        include_str!("../../../scenes/wang2021_notched_plate.toml"),
        include_str!("../../../scenes/explicit_bar.toml"),
        include_str!("../../../scenes/explicit_disks.toml"),
        include_str!("../../../scenes/explicit_cube.toml"),
        include_str!("../../../scenes/explicit_collapse.toml"),
        include_str!("../../../scenes/sliding_block.toml"),
        include_str!("../../../scenes/rolling_cylinder.toml"),
        include_str!("../../../scenes/sliding_block_contact.toml"),
        include_str!("../../../scenes/explicit_absorbing_gravity.toml"),
        include_str!("../../../scenes/footing_mohr_coulomb.toml"),
        include_str!("../../../scenes/footing_rigid.toml"),
        include_str!("../../../scenes/platen_cube.toml"),
        include_str!("../../../scenes/biaxial_drucker_prager.toml"),
        GEOSTATIC,
        include_str!("../../../scenes/griffiths_lane_slope.toml"),
        include_str!("../../../scenes/triaxial_cam_clay.toml"),
        SOIL_WITH_CUTOFF,
        // The displacement criterion's keys, as the slope's test sets them.
        &SLOPE_BY_DISPLACEMENT
            .map(|s| s.replace("strength_reduction.", "").replace('=', " = "))
            .join("\n"),
    ]
    .join("\n");
    let mut keys = Vec::new();
    for line in guide.lines() {
        // Table rows whose first cell is a key: "| `key` |".
        let Some(rest) = line.strip_prefix("| `") else {
            continue;
        };
        let Some((key, _)) = rest.split_once('`') else {
            continue;
        };
        let key = key.trim_start_matches("[[output.").trim_end_matches("]]");
        if key.contains(' ') || key.contains('{') || key.contains('/') {
            continue;
        }
        keys.push(key.to_owned());
    }
    // The region forms of the regions table.
    keys.extend(
        [
            "box",
            "lower",
            "upper",
            "polygon",
            "sphere",
            "centre",
            "radius",
            "union",
            "difference",
        ]
        .map(String::from),
    );
    assert!(keys.len() > 50, "{keys:?}");
    let missing: Vec<&String> = keys
        .iter()
        .filter(|k| {
            let section = format!("[[output.{k}]]");
            !((k.starts_with('[') && scenes.contains(k.as_str()))
                || scenes.contains(&format!("{k} ="))
                || scenes.contains(&format!("{k} = {{"))
                || scenes.contains(&section))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "documented keys no scene uses: {missing:?}"
    );
}

/// The built-in collapse case (Coombs et al. 2020 §7.5, Table 6) and its
/// scene file: the same points and final state bit for bit, so the same
/// Table 6 figures.
#[test]
fn collapse_scene_equals_the_collapse_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::collapse::{self, CollapseParams};
    let text = include_str!("../../../scenes/coombs2020_collapse.toml");
    let params = CollapseParams::default();
    let case = collapse::CollapseCase::run(
        &params,
        &params.variant(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let (problem, out) = run2(text, &[]);
    let built = collapse::CollapseCase::build(&params, &params.variant()).unwrap();
    assert_eq!(problem.position, built.position);
    assert_same_final_state(&out, &case.output);
    // Table 6 (h = 1 m, 3² points per cell): extent and height at the edge
    // of the points' initial half-spacing.
    let edge = |axis: usize| {
        out.last
            .position
            .iter()
            .zip(&problem.half_lengths)
            .map(|(x, l)| x[axis] + l[axis])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert_eq!(
        (edge(0), edge(1)),
        (case.horizontal_extent, case.max_height)
    );
    // Within 1 % as in tests/collapse.rs (measured: 13.669 m, +0.05 %, and
    // 6.242 m, −0.05 %).
    let (extent, height) = (edge(0), edge(1));
    assert!(((extent - 13.662) / 13.662).abs() < 0.01, "{extent}");
    assert!(((height - 6.245) / 6.245).abs() < 0.01, "{height}");
}

/// The built-in cantilever case (Coombs et al. 2020 §7.3) and its scene
/// file: the same loaded points and the same final state bit for bit.
#[test]
fn cantilever_scene_equals_the_cantilever_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::cantilever::{self, CantileverParams};
    let text = include_str!("../../../scenes/coombs2020_cantilever.toml");
    let params = CantileverParams::default();
    let case = cantilever::CantileverCase::run(
        &params,
        &params.variant(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let (problem, out) = run2(text, &[]);
    let (built, loaded) = cantilever::CantileverCase::build(&params, &params.variant()).unwrap();
    assert_eq!(problem.position, built.position);
    let forces: Vec<usize> = problem.point_forces.iter().map(|(p, _)| *p).collect();
    assert_eq!(forces, loaded.to_vec());
    assert_same_final_state(&out, &case.output);
    let tip = cantilever::tip_displacement(&out.last, loaded);
    let (_, ux, uy) = *case.tip.last().unwrap();
    assert_eq!(tip, (ux, uy));
}

/// The built-in shear case (Coombs et al. 2020 §7.2) and its scene file:
/// a body-following boundary (`around`) with a displacement gradient, a
/// lattice anchored at the body on a shifted grid; the same points and the
/// same final state bit for bit, and the homogeneous closed-form stress.
#[test]
fn shear_scene_equals_the_shear_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::shear::{self, ShearParams};
    let text = include_str!("../../../scenes/coombs2020_shear.toml");
    let params = ShearParams::default();
    let case = shear::ShearCase::run(
        &params,
        &params.variant(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let (problem, out) = run2(text, &[]);
    assert_eq!(problem.len(), case.material_points);
    assert_same_final_state(&out, &case.output);
    assert_eq!(out.summary.iterations, case.output.summary.iterations);
    // γ = 6: the closed form of the shear case's documentation.
    let (g, mu) = (6.0f64, 10e3 / (2.0 * 1.3));
    let a = (g / 2.0).asinh() * 2.0 * mu / (g * g + 4.0).sqrt();
    let (s11, s12) = (a * g, a * 2.0);
    for s in &out.last.sigma {
        assert!((s[0] - s11).abs() < 1e-6 * s11, "σ11 {} vs {s11}", s[0]);
        assert!((s[1] - s12).abs() < 1e-6 * s12, "σ12 {} vs {s12}", s[1]);
    }
}

/// The built-in stretch case (Wang et al. 2021 §5.3, Table 1) and its
/// scene file: a generated box of ten-node tetrahedra split into their
/// children, Keast points, a stretching mesh with driven nodes; the same
/// points and the same final state bit for bit.
#[test]
fn stretch_scene_equals_the_stretch_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::stretch::{self, StretchParams};
    let text = include_str!("../../../scenes/wang2021_stretch.toml");
    let params = StretchParams::default();
    let case = stretch::StretchCase::run(
        &params,
        &params.variant(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let (scene, src) = scene::parse(text, "wang2021_stretch.toml", &[]).unwrap();
    let problem = Problem::<3>::build(&scene, &src, 0).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    assert_eq!(problem.len(), case.material_points);
    assert_same_final_state(&out, &case.output);
    assert_eq!(out.summary.iterations, case.output.summary.iterations);
    // The mesh moved with the face: the top nodes are at y = 4 m.
    let top = out.last.position.iter().map(|x| x[1]).fold(0.0, f64::max);
    assert!(top > 3.8 && top < 4.0, "highest point at y = {top}");
}

/// The footing scene's rectilinear box: node rows where `coordinates`
/// puts them (the footing edge on a node), children's mid-edge nodes at
/// the midpoints, and the refusals of rows that describe no box.
#[test]
fn rectilinear_simplex_boxes_put_the_footing_edge_on_a_node() {
    let (scene, src) = scene::parse(WANG_FOOTING, "wang2021_footing.toml", &[]).unwrap();
    let problem = Problem::<3>::build(&scene, &src, 0).unwrap();
    let SceneMeshKind::Simplex(mesh) = &problem.mesh else {
        panic!("the footing runs on tetrahedra");
    };
    let planes = |axis: usize| {
        let mut v: Vec<f64> = mesh.nodes().iter().map(|x| x[axis]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        v
    };
    let expect = |rows: &[f64]| {
        // Parent rows and the children's midpoints between them.
        let mut v = vec![rows[0]];
        for w in rows.windows(2) {
            v.extend([0.5 * (w[0] + w[1]), w[1]]);
        }
        v
    };
    let (xs, zs) = (planes(0), planes(2));
    let x_rows = expect(&[0.0, 0.125, 0.25, 0.375, 0.6, 1.1, 2.3, 5.0]);
    let z_rows = expect(&[0.0, 2.7, 3.9, 4.4, 4.625, 4.75, 4.875, 5.0]);
    assert_eq!(xs.len(), x_rows.len());
    for (a, b) in xs.iter().zip(&x_rows).chain(zs.iter().zip(&z_rows)) {
        assert!((a - b).abs() < 1e-12, "{xs:?} {zs:?}");
    }
    // The footing: the 5 x 5 top nodes with x, y <= 0.25; the volume kept.
    assert_eq!(problem.reactions[0].nodes.len(), 25);
    assert_eq!(mesh.element_count(), 7 * 7 * 7 * 6 * 8);
    assert!((mesh.total_volume() - 125.0).abs() < 1e-9);
    assert_eq!(problem.len(), 11 * mesh.element_count());
    for (set, expect) in [
        (
            "mesh.coordinates=[[0.0, 5.0], [0.0, 5.0]]",
            "mesh `coordinates` has 2 rows; the scene is 3D",
        ),
        (
            "mesh.coordinates=[[0.0, 1.0, 0.5, 5.0], [0.0, 5.0], [0.0, 5.0]]",
            "mesh `coordinates` along x: give at least two finite, strictly increasing values",
        ),
        (
            "mesh.coordinates=[[0.0, 5.0], [0.0, 4.0], [0.0, 5.0]]",
            "mesh `coordinates` along y",
        ),
        (
            "mesh.cells=[2, 2, 2]",
            "give mesh `coordinates` or `cells`/`spacing`, not both",
        ),
    ] {
        let (scene, src) =
            scene::parse(WANG_FOOTING, "wang2021_footing.toml", &[set.to_owned()]).unwrap();
        let message = Problem::<3>::build(&scene, &src, 0)
            .unwrap_err()
            .to_string();
        assert!(message.contains(expect), "{set}: {message}");
    }
}

/// Wang et al. 2021 §5.1 (Fig. 8C) on a coarser mesh of its scene (4
/// parent cells per axis, one of 0.25 m under the footing, growing away
/// from it; the scene's and the paper's 20 steps of 0.1 mm): past yield the
/// standard MPM pressure keeps rising (volumetric locking at ν = 0.48)
/// while F-patch's levels off, below it and above the strip's 2 + π.
///
/// Not 10 steps of 0.2 mm: there F-patch's Newton iteration is chaotic at
/// the footing's edge. A relative change of 1e-11 in E moves its number of
/// cut steps between 3 and 9, so whether it cuts none tests rounding, not
/// the method. With 0.1 mm, E changed by ±1e-11 and ±1e-10 gives the same
/// 20 steps and 116 iterations for F-patch, 78 for standard MPM
/// (`docs/src/benchmarks/solver.md`).
#[test]
fn wang_footing_locks_with_standard_mpm_and_levels_off_with_fpatch() {
    let k = 0.85e6 / 2f64.sqrt();
    let curve = |locking: &str| {
        let set = [
            FOOTING_QUICK_MESH.to_owned(),
            format!("solver.locking=\"{locking}\""),
        ];
        let (scene, src) = scene::parse(WANG_FOOTING, "wang2021_footing.toml", &set).unwrap();
        let problem = Problem::<3>::build(&scene, &src, 0).unwrap();
        let footing = problem.reactions[0].clone();
        let mut pressure = vec![0.0];
        scene::run(&problem, &RunControl::default(), |_, rep, _| {
            let f = footing.total(rep)[2];
            pressure.push(f.abs() / (0.25 * 0.25) / k);
            Ok(())
        })
        .unwrap();
        pressure
    };
    let (standard, patched) = (curve("none"), curve("fpatch"));
    assert_eq!(standard.len(), 21);
    assert_eq!(patched.len(), 21);
    // Slope of the last fifth (steps 16 to 20) over the first step's: a
    // plateau is below 1 % of the elastic slope; standard MPM still rises
    // at more than 5 % of it.
    let late = |p: &[f64]| (p[20] - p[16]) / 4.0 / p[1];
    let (s, f) = (late(&standard), late(&patched));
    assert!(
        s > 0.05 && f < 0.01,
        "late slopes: standard {s}, F-patch {f}"
    );
    assert!(patched[20] < standard[20], "{patched:?} {standard:?}");
    assert!(patched[20] > 2.0 + std::f64::consts::PI, "{patched:?}");
}

/// A graded footing mesh on which Newton used to stall: with 0.1 mm steps
/// on a 10 GPa cube the reactions are so small that the rounding noise of
/// the out-of-balance force (about 1.5e-9 of them with F-patch, 4e-10 with
/// standard MPM) sits above the 1e-9 tolerance of eq. (40), and every
/// step was cut down to failure. Newton converges quadratically down to
/// that floor and the monitor accepts the stalled iterate there, with the
/// floor it estimated. (Elastic: with the scene's yield stress the 0.1 mm
/// step is 20 times the yield strain at the footing edge and is cut.)
#[test]
fn footing_steps_stalled_at_the_rounding_floor_are_accepted() {
    let set = [
        "material.0.yield_stress=1e15".to_owned(),
        "mesh.coordinates=[[0.0, 0.125, 0.25, 0.375, 1.5, 5.0], [0.0, 0.125, 0.25, 0.375, 1.5, 5.0], [0.0, 3.5, 4.2, 4.625, 4.75, 4.875, 5.0]]".to_owned(),
        "solver.locking=\"fpatch\"".to_owned(),
    ];
    let (scene, src) = scene::parse(WANG_FOOTING, "wang2021_footing.toml", &set).unwrap();
    let problem = Problem::<3>::build(&scene, &src, 0).unwrap();
    let mut reports = Vec::new();
    let stop = scene::run(&problem, &RunControl::default(), |step, rep, _| {
        reports.push(rep.clone());
        if step == 1 {
            return Err(mpm_solver::SolverError::Stopped {
                step: 2,
                load_factor: rep.lambda1,
            });
        }
        Ok(())
    });
    assert!(matches!(stop, Err(mpm_solver::SolverError::Stopped { .. })));
    assert_eq!(reports.len(), 2);
    for rep in &reports {
        // No step was cut: each is the scene's 1/20.
        assert!((rep.lambda1 - rep.lambda0 - 0.05).abs() < 1e-12);
        let r = &rep.residuals;
        let last = *r.last().unwrap();
        assert!(rep.at_rounding_floor, "{r:?}");
        // Above the tolerance (the floor was needed) and within ten times
        // the estimated floor, reached in a handful of iterations after a
        // quadratic descent (measured: 1.3e-3 at iteration 0, after the
        // linearised first solve, then 3.0e-8 and 2.6e-8 at the floor).
        assert!(
            last > 1e-9 && last <= 10.0 * rep.rounding_floor,
            "{r:?} floor {}",
            rep.rounding_floor
        );
        // The floor is normalised by the largest reaction of the step's
        // iterations; since the first solve is linearised about the
        // converged state (FirstTangent::Converged) that is the converged
        // reaction, not the stiffer one of the prescribed settlement alone
        // at iteration 0, so the floor reads about 20 times higher than
        // with plain Newton (measured 2.9e-8 against 1.5e-9).
        assert!(
            rep.rounding_floor > 1e-9 && rep.rounding_floor < 1e-7,
            "{}",
            rep.rounding_floor
        );
        // The elastic step's first solve, linearised about the converged
        // state, leaves only the geometric nonlinearity (1.3e-3), and one
        // Newton correction reaches the floor.
        assert!(rep.linearised_start);
        assert!(r[0] < 1e-2, "{r:?}");
        assert!(r.len() <= 4, "{r:?}");
    }
}

/// The built-in annulus case (Coombs et al. 2020 §7.4) at its defaults and
/// its scene file (a generated annulus, the manufactured body force as a
/// named field): the same points and final state bit for bit, so the same
/// error against the exact rotation field; and the case on the Gmsh mesh
/// of `scenes/annulus_gmsh.toml` is that scene with the Gmsh mesh.
#[test]
fn annulus_scene_equals_the_annulus_case() {
    use mpm_cases::cases::Solve;
    use mpm_cases::cases::annulus::{self, AnnulusParams};
    let scenes = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    let params = AnnulusParams::default();
    let case = annulus::AnnulusCase::run(
        &params,
        &params.variant(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let text = include_str!("../../../scenes/coombs2020_annulus.toml");
    let (scene, src) = scene::parse(text, "coombs2020_annulus.toml", &[]).unwrap();
    let problem = Problem::<2>::build_in(&scene, &src, 0, scenes).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    assert_eq!(problem.len(), case.material_points);
    assert_same_final_state(&out, &case.output);
    assert_eq!(out.summary.iterations, case.output.summary.iterations);
    // The scene's displacements against the exact field of eq. (44) give
    // the case's error (measured: 3.8e-3 m).
    let torsion = annulus::Torsion {
        inner_radius: 0.75,
        outer_radius: 1.25,
        mu: 0.5,
    };
    let mut sum = 0.0;
    for (p, u) in out.last.displacement.iter().enumerate() {
        let x0 = nalgebra::Vector2::new(problem.position[p][0], problem.position[p][1]);
        let exact = torsion.displacement(0.1, &x0);
        sum += (nalgebra::Vector2::new(u[0], u[1]) - exact).norm() * problem.volume[p];
    }
    let error = sum / problem.volume.iter().sum::<f64>();
    assert_eq!(error, case.error);
    // The same scene on the committed Gmsh annulus is the case on it.
    let gmsh = AnnulusParams {
        mesh: Some(scenes.join("meshes/annulus_2.msh")),
        ..AnnulusParams::default()
    };
    let on_gmsh =
        annulus::AnnulusCase::run(&gmsh, &gmsh.variant(), &RunControl::default(), |_, _, _| {
            Ok(())
        })
        .unwrap();
    let gmsh_text = text.replace(
        "kind = \"annulus\"\ninner_radius = 0.75\nouter_radius = 1.25\nlayers = 4\nring_nodes = 63\njitter = 0.0\nseed = 1",
        "kind = \"gmsh\"\nfile = \"meshes/annulus_2.msh\"\ndimension = 2",
    );
    let (scene, src) = scene::parse(&gmsh_text, "annulus_gmsh", &[]).unwrap();
    let problem = Problem::<2>::build_in(&scene, &src, 0, scenes).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    assert_same_final_state(&out, &on_gmsh.output);
}

/// Gmsh meshes in scenes: the cube of tetrahedra carries its weight on its
/// base; a 2D annulus of triangles hangs from its inner rim; the
/// mesh-specific mistakes are located.
#[test]
fn gmsh_scenes_run_on_simplices() {
    let scenes = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    let text = include_str!("../../../scenes/cube_gmsh.toml");
    let (scene, src) = scene::parse(text, "cube_gmsh.toml", &[]).unwrap();
    assert_eq!(scene::dimension(&scene, &src).unwrap(), 3);
    let problem = Problem::<3>::build_in(&scene, &src, 0, scenes).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    let weight = 2000.0 * 10.0 * 8.0;
    let reaction = out.reports.last().unwrap().reaction[2];
    assert!((reaction - weight).abs() < 1e-9 * weight, "{reaction}");
    // Uniaxial strain: σ_zz = −ϱ g (H − Z), to a few per cent on this
    // coarse mesh (volume-weighted, normalised as eq. 42).
    let error: f64 = (0..problem.len())
        .map(|p| {
            (out.last.sigma[p][8] + 2e4 * (2.0 - problem.position[p][2])).abs() * problem.volume[p]
        })
        .sum::<f64>()
        / (2e4 * 2.0 * 8.0);
    assert!(error < 0.05, "{error}");
    eprintln!(
        "cube of tetrahedra: {} points, stress error {error:.4}",
        problem.len()
    );

    let annulus = r#"
[mesh]
kind = "gmsh"
file = "meshes/annulus_0.msh"
dimension = 2

[[material]]
name = "m"
model = "hencky"
youngs_modulus = 1e6
poisson_ratio = 0.3
density = 100.0

[[body]]
name = "ring"
material = "m"
region = { group = "domain" }

[[boundary]]
set = "inner"
kind = "fixed"

[[load]]
kind = "gravity"
acceleration = [0.0, -10.0]

[solver]
steps = 2
formulation = "ul"
"#;
    let (scene, src) = scene::parse(annulus, "annulus.toml", &[]).unwrap();
    let problem = Problem::<2>::build_in(&scene, &src, 0, scenes).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    let mass: f64 = problem.mass.iter().sum();
    let reaction = out.reports.last().unwrap().reaction[1];
    assert!(
        (reaction - 10.0 * mass).abs() < 1e-9 * reaction,
        "{reaction} {mass}"
    );
    // Subdivision(2): four points per triangle.
    let SceneMeshKind::Simplex(mesh) = &problem.mesh else {
        panic!("not a simplex mesh")
    };
    assert_eq!(problem.len(), 4 * mesh.element_count());

    let refuse = |text: String| {
        let (scene, src) = scene::parse(&text, "g.toml", &[]).unwrap();
        Problem::<2>::build_in(&scene, &src, 0, scenes)
            .unwrap_err()
            .to_string()
    };
    let e = refuse(annulus.replace("annulus_0.msh", "missing.msh"));
    assert!(
        e.starts_with("g.toml:4:8: ") && e.contains("missing.msh"),
        "{e}"
    );
    let e = refuse(annulus.replace("group = \"domain\"", "group = \"ring\""));
    assert!(
        e.contains("no physical group `ring` of elements; it has: domain"),
        "{e}"
    );
    let e = refuse(annulus.replace("dimension = 2", "dimension = 2\ncells = [2, 2]"));
    assert!(e.contains("apply to kind = \"grid\" meshes"), "{e}");
    let e = refuse(annulus.replace("steps = 2", "steps = 2\nbasis = \"gimp\""));
    assert!(e.contains("standard MPM"), "{e}");
    let e = refuse(annulus.replace("set = \"inner\"", "set = \"rim\""));
    assert!(
        e.contains("no node set named `rim`") && e.contains("inner") && e.contains("outer"),
        "{e}"
    );
}

/// A scene run stopped and resumed (two materials: the tags go through the
/// checkpoint) writes the same results as an uninterrupted one; resuming
/// with another scene is refused.
#[test]
fn scene_runs_resume_to_the_same_results() {
    let mpm = |args: &[&str], dir: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
            .arg("run")
            .arg(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../scenes/two_layer_column.toml"
            ))
            .args(args)
            .arg("--out")
            .arg(dir)
            .output()
            .unwrap()
    };
    let whole = common::fresh_dir("scene_resume_whole");
    assert!(mpm(&[], &whole).status.success());
    let parts = common::fresh_dir("scene_resume_parts");
    assert!(mpm(&["--stop-after", "4"], &parts).status.success());
    let other = mpm(&["--resume", "--set", "solver.tolerance=1e-8"], &parts);
    assert!(!other.status.success());
    assert!(String::from_utf8_lossy(&other.stderr).contains("other parameters"));
    assert!(mpm(&["--resume"], &parts).status.success());
    for file in [
        "probe_top.csv",
        "probe_interface.csv",
        "reaction_base.csv",
        "steps.csv",
        "points_0009.vtu",
    ] {
        // Wall-clock columns (`seconds*` of steps.csv) differ between runs.
        let read = |dir: &std::path::Path| {
            let text =
                String::from_utf8_lossy(&std::fs::read(dir.join(file)).unwrap()).into_owned();
            if file == "steps.csv" {
                common::without_timings(&text)
            } else {
                text
            }
        };
        assert_eq!(read(&whole), read(&parts), "{file}");
    }
}

/// A block under uniaxial strain with `model = "neo_hookean"`: rollers on
/// both sides and the base, the top pushed down 0.3 m in 5 steps by a
/// mesh compressed with it (so the top stays on nodes), so that
/// F = diag(1, λ) with λ = 0.7 everywhere. The top's reaction per unit
/// width is σ_yy = τ_yy/λ with τ_yy = μ(λ² − 1) + λ_L ln λ (Bonet & Wood
/// eq. 6.29), exact for standard MPM on a homogeneous state.
#[test]
fn neo_hookean_scene_matches_uniaxial_strain() {
    let text = r#"[mesh]
origin = [0.0, 0.0]
size = [1.0, 1.0]
cells = [2, 2]

[mesh.motion]
kind = "stretch"
axis = "y"
extension = -0.3
driven = "y_max"

[[material]]
name = "m"
model = "neo_hookean"
youngs_modulus = 1e6
poisson_ratio = 0.3
density = 0.0

[[body]]
name = "b"
material = "m"
region = { box = { lower = [0.0, 0.0], upper = [1.0, 1.0] } }

[[boundary]]
set = "x_min"
kind = "roller"

[[boundary]]
set = "x_max"
kind = "roller"

[[boundary]]
set = "y_min"
kind = "roller"

[solver]
basis = "linear"
steps = 5
tolerance = 1e-12

[[output.reaction]]
name = "top"
set = "y_max"
"#;
    let (scene, src) = scene::parse(text, "neo.toml", &[]).unwrap();
    let problem = Problem::<2>::build(&scene, &src, 0).unwrap();
    let top = problem.reactions[0].clone();
    let mut reaction = 0.0;
    scene::run(&problem, &RunControl::default(), |_, rep, _| {
        reaction = top.total(rep)[1];
        Ok(())
    })
    .unwrap();
    let (e, nu, stretch) = (1e6f64, 0.3f64, 0.7f64);
    let (lambda, mu) = (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    );
    let sigma = (mu * (stretch * stretch - 1.0) + lambda * stretch.ln()) / stretch;
    // The top's reaction (the internal force on its nodes) is σ_yy·1 m.
    assert!(
        (reaction - sigma).abs() < 1e-9 * sigma.abs(),
        "reaction {reaction} against {sigma}"
    );
    // Mixing it with another model is refused (one law type per scene).
    let mixed = text.replace(
        "[[body]]",
        "[[material]]\nname = \"h\"\nmodel = \"hencky\"\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\ndensity = 0.0\n\n[[body]]",
    );
    let message = refusal(&mixed);
    assert!(
        message.contains("material `h` is hencky but `m` is neo_hookean"),
        "{message}"
    );
}

/// A Gmsh mesh with a sliver or with two nodes at one position builds
/// (both are valid meshes) with a warning that names the element or the
/// nodes; the clean mesh builds without one.
#[test]
fn slivers_and_coincident_nodes_in_a_gmsh_mesh_are_warned_about() {
    let msh = |nodes: &[[f64; 2]], triangles: &[[usize; 3]]| {
        let n = nodes.len();
        let mut s =
            format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 {n} 1 {n}\n2 1 0 {n}\n");
        for i in 1..=n {
            s += &format!("{i}\n");
        }
        for x in nodes {
            s += &format!("{} {} 0\n", x[0], x[1]);
        }
        let m = triangles.len();
        s += &format!("$EndNodes\n$Elements\n1 {m} 1 {m}\n2 1 2 {m}\n");
        for (i, t) in triangles.iter().enumerate() {
            s += &format!("{} {} {} {}\n", i + 1, t[0], t[1], t[2]);
        }
        s + "$EndElements\n"
    };
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let cases = [
        ("clean", msh(&square, &[[1, 2, 3], [1, 3, 4]]), None),
        (
            "sliver",
            msh(
                &[
                    square[0],
                    square[1],
                    square[2],
                    square[3],
                    [0.5, 1.0 + 1e-5],
                ],
                &[[1, 2, 3], [1, 3, 4], [4, 3, 5]],
            ),
            Some("1 element(s) are slivers"),
        ),
        (
            "coincident",
            msh(
                &[square[0], square[1], square[2], square[3], square[2]],
                &[[1, 2, 3], [1, 5, 4]],
            ),
            Some("share a position (the first: nodes 2 and 4)"),
        ),
    ];
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesh_warnings");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text, expected) in cases {
        std::fs::write(dir.join(format!("{name}.msh")), text).unwrap();
        let scene_text = format!(
            "[mesh]\nkind = \"gmsh\"\nfile = \"{name}.msh\"\ndimension = 2\n\n\
             [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
             [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 1.0] }} }}\n\n\
             [[boundary]]\nset = \"y_min\"\nkind = \"fixed\"\n"
        );
        let (scene, src) = scene::parse(&scene_text, "w.toml", &[]).unwrap();
        let problem =
            Problem::<2>::build_in(&scene, &src, 0, &dir).unwrap_or_else(|e| panic!("{name}: {e}"));
        match expected {
            None => assert!(
                problem.warnings.is_empty(),
                "{name}: {:?}",
                problem.warnings
            ),
            Some(text) => {
                assert_eq!(problem.warnings.len(), 1, "{name}: {:?}", problem.warnings);
                let w = &problem.warnings[0];
                assert!(w.starts_with("[mesh]: ") && w.contains(text), "{name}: {w}");
            }
        }
    }
}

/// The weak-node rule's fractions are implicit `[solver]` keys in [0, 1).
/// They trace a finding of the stability page: the base reaction of the
/// GIMP collapse (`scenes/coombs2020_collapse.toml` with basis = gimp)
/// exceeds the block's weight, 640 kN, by 1.6 % at λ = 1. Holding the
/// fringe nodes is not the cause: with both rules off the excess is the
/// same to 1e-3. The domains are: without a domain update (or with det F,
/// which shrinks them in both directions alike) the points at the base
/// keep half-lengths that reach below the grid's lower face as the block
/// compacts, where the GIMP basis has no node and drops the missing
/// share, so those points lose the partition of unity. With eq. 34 the
/// domains shrink with the vertical compaction and the reaction equals
/// the weight to 1e-3 (measured 5e-4).
#[test]
fn weak_node_keys_and_the_gimp_base_reaction() {
    let scene_file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/coombs2020_collapse.toml");
    let text = std::fs::read_to_string(&scene_file).unwrap();
    let build = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let (scene, src) = scene::parse(&text, "c.toml", &sets).unwrap();
        Problem::<2>::build(&scene, &src, scene.solver.padding())
    };
    let p = build(&[]).unwrap();
    assert_eq!(p.newton.weak_node_threshold, 1e-6);
    assert_eq!(p.newton.weak_node_stiffness, 1e-4);
    let p = build(&[
        "solver.weak_node_threshold=0",
        "solver.weak_node_stiffness=0.01",
    ])
    .unwrap();
    assert_eq!(p.newton.weak_node_threshold, 0.0);
    assert_eq!(p.newton.weak_node_stiffness, 0.01);
    let e = build(&["solver.weak_node_threshold=1.5"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("solver `weak_node_threshold` is a fraction of the largest node's, in [0, 1)"),
        "{e}"
    );
    let e = build(&["solver.weak_node_stiffness=-1"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("weak_node_stiffness"), "{e}");
    let bar = include_str!("../../../scenes/explicit_bar.toml");
    let (scene, src) =
        scene::parse(bar, "bar.toml", &["solver.weak_node_stiffness=0".into()]).unwrap();
    let e = Problem::<2>::build(&scene, &src, scene.solver.padding())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("solver `weak_node_stiffness` applies to the implicit solver"),
        "{e}"
    );

    let excess = |tag: &str, sets: &[&str]| {
        let dir = common::fresh_dir(&format!("gimp-reaction-{tag}"));
        let mut args = vec![
            "run",
            scene_file.to_str().unwrap(),
            "--set",
            "solver.basis=gimp",
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        args.extend(["--out", dir.to_str().unwrap()]);
        let (ok, _, err) = common::mpm(&args);
        assert!(ok, "{err}");
        let csv = std::fs::read_to_string(dir.join("reaction_base.csv")).unwrap();
        let last: Vec<f64> = csv
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(last[0], 1.0);
        last[2] / 640e3 - 1.0
    };
    let held = excess("held", &[]);
    let free = excess(
        "free",
        &[
            "solver.weak_node_threshold=0",
            "solver.weak_node_stiffness=0",
        ],
    );
    let stretch = excess("stretch", &["solver.domain_update=stretch"]);
    eprintln!("base reaction / weight - 1: {held} (rules on), {free} (off), {stretch} (eq. 34)");
    assert!(held > 0.01 && (held - free).abs() < 1e-3, "{held}, {free}");
    assert!(stretch.abs() < 1e-3, "{stretch}");
}

/// `ghost_penalty` and `ghost_fill` reach the Newton options on a grid;
/// other meshes, a fill without a penalty and out-of-range values are
/// refused with the key's place.
#[test]
fn ghost_penalty_keys() {
    let collapse = include_str!("../../../scenes/coombs2020_collapse.toml");
    let build = |text: &str, sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let (scene, src) = scene::parse(text, "c.toml", &sets).unwrap();
        Problem::<2>::build(&scene, &src, scene.solver.padding()).map_err(|e| e.to_string())
    };
    assert_eq!(
        build(collapse, &[]).unwrap().newton.ghost,
        mpm_solver::GhostPenalty::OFF
    );
    let p = build(collapse, &["solver.ghost_penalty=0.01"]).unwrap();
    assert_eq!(p.newton.ghost, mpm_solver::GhostPenalty::new(0.01));
    let p = build(
        collapse,
        &["solver.ghost_penalty=0.1", "solver.ghost_fill=0.25"],
    )
    .unwrap();
    assert_eq!(p.newton.ghost.factor, 0.1);
    assert_eq!(p.newton.ghost.fill, 0.25);
    for (sets, expected) in [
        (
            &["solver.ghost_fill=0.3"][..],
            "solver `ghost_fill` applies with `ghost_penalty`",
        ),
        (
            &["solver.ghost_penalty=-1"][..],
            "solver `ghost_penalty` is a multiple of the law's 2μ, >= 0",
        ),
        (
            &["solver.ghost_penalty=0.01", "solver.ghost_fill=1.5"][..],
            "solver `ghost_fill` is a fraction of a cell's volume in (0, 1]",
        ),
    ] {
        let e = build(collapse, sets).unwrap_err();
        assert!(e.contains(expected), "{e}");
        assert!(e.starts_with("override `solver.ghost_"), "{e}");
    }
    let annulus = include_str!("../../../scenes/coombs2020_annulus.toml");
    let e = build(annulus, &["solver.ghost_penalty=0.01"]).unwrap_err();
    assert!(
        e.contains("solver `ghost_penalty` acts on the faces of a regular grid's cells"),
        "{e}"
    );
}

/// `scenes/ghost_plate.toml` runs with its ghost penalty, and the penalty
/// acts: the pulled end's reaction differs from the unpenalised run's, by
/// less than 2 % (it perturbs smooth responses only slightly).
#[test]
fn ghost_plate_runs_with_the_penalty() {
    let text = include_str!("../../../scenes/ghost_plate.toml");
    let pulled = |sets: &[&str]| {
        let (problem, out) = run2(text, sets);
        let end = problem
            .reactions
            .iter()
            .find(|r| r.name == "pulled")
            .unwrap();
        (
            problem.newton.ghost,
            end.total(out.reports.last().unwrap())[0],
        )
    };
    let (ghost, with) = pulled(&[]);
    assert_eq!(ghost, mpm_solver::GhostPenalty::new(0.01));
    let (_, without) = pulled(&["solver.ghost_penalty=0"]);
    println!("pulled reaction: {with:.6e} with the penalty, {without:.6e} without");
    assert!(without > 0.0, "{without}");
    let change = ((with - without) / without).abs();
    assert!(change > 0.0 && change < 0.02, "{with} {without}");
}

/// `gimp_volume = domain` is honoured under F-bar: every GIMP point
/// integrates with its domain's volume ∏ 2lᵢ (here constant: no domain
/// update), not det F V⁰. The runner once dropped the convention when
/// F-bar was on while `summary.json` reported it; the det F run beside it
/// shows the two conventions differ by the column's compression (4 % in
/// the soft layer: ϱ g H / E = 80 · 10 · 5 / 1e5), far above the 1e-12 the
/// domain volumes are held to.
#[test]
fn gimp_domain_volume_is_honoured_under_fbar() {
    let volumes = |convention: &str| {
        let volume = format!("solver.gimp_volume={convention}");
        let set = [
            "solver.domain_update=none",
            "solver.locking=fbar",
            volume.as_str(),
        ];
        let (problem, out) = run2(TWO_LAYER, &set);
        let domain: Vec<f64> = (problem.half_lengths.iter())
            .map(|l| l.iter().map(|l| 2.0 * l).product())
            .collect();
        let largest = (out.last.volume.iter().zip(&domain))
            .map(|(v, d)| ((v - d) / d).abs())
            .fold(0.0, f64::max);
        (largest, out.last.volume.len())
    };
    let (domain, n) = volumes("domain");
    assert!(n > 0);
    assert!(domain < 1e-12, "largest relative gap to ∏ 2l: {domain:e}");
    let (det_f, _) = volumes("det_f");
    assert!(
        det_f > 1e-2,
        "det F volumes should follow the compression: {det_f:e}"
    );
}

/// Issue 44 (implicit contact): the footing of `footing_rigid.toml` is a
/// rigid tool in contact with the Tresca soil. A smooth tool frees the
/// footing's nodes horizontally, as the prescribed-node footing of
/// `footing_mohr_coulomb.toml` at φ = 0 does, and its normal penalty
/// (100 × 2G/h) sinks them by q h/(100 · 2G) ≈ 5e-8 m against the 4 mm
/// settlement: the two pressures must agree within 1 %. Prandtl's limit
/// is (2 + π) c for a rough footing as for a smooth one on weightless
/// Tresca soil, so both tools must give it within the +10 % the
/// prescribed-node test allows for the coarse grid's excess; the rough
/// tool adds a constraint to the same discrete problem, so its pressure
/// may not be below the smooth one's (the coarse grid resolves the rough
/// footing's wedge worse: measured +1.6 % above the smooth one). On the
/// 0.125 m grid the issue's "a rough one gives the same N_c" must hold
/// within its 1 %: the rough tool within 1 % of the smooth one (measured
/// +0.69 %: 5.3458 c against 5.3094 c, the prescribed nodes 5.3105 c;
/// about 9 s per run in release). Newton's iterations are printed
/// against the prescribed-node run's.
#[test]
fn a_rigid_footing_reproduces_the_prescribed_one_smooth_and_rough() {
    let prescribed = include_str!("../../../scenes/footing_mohr_coulomb.toml")
        .replace("friction_angle = 20.0", "friction_angle = 0.0");
    let rigid = include_str!("../../../scenes/footing_rigid.toml");
    let rough = rigid.replace("friction = 0.0", "rough = true");
    let run = |text: &str| {
        let (problem, out) = run2(text, &[]);
        let footing = problem.reactions[0].clone();
        let q = -footing.total(out.reports.last().unwrap())[1] / 1.0e4;
        let iterations: usize = out.reports.iter().map(|r| r.iterations()).sum();
        (q, iterations, out.reports.len())
    };
    let (q_p, it_p, steps_p) = run(&prescribed);
    let (q_s, it_s, steps_s) = run(rigid);
    let (q_r, it_r, steps_r) = run(&rough);
    println!(
        "footing at φ = 0: prescribed {q_p:.5} c ({it_p} iterations in {steps_p} steps), smooth tool {q_s:.5} c ({it_s} in {steps_s}), rough tool {q_r:.5} c ({it_r} in {steps_r})"
    );
    let prandtl = 2.0 + std::f64::consts::PI;
    assert!(
        (q_s - q_p).abs() <= 0.01 * q_p,
        "smooth tool {q_s} against {q_p}"
    );
    assert!(q_r >= q_s * (1.0 - 1e-3), "rough {q_r} below smooth {q_s}");
    for (q, what) in [(q_s, "smooth"), (q_r, "rough")] {
        assert!(q > prandtl && q < 1.1 * prandtl, "{what} tool {q}");
    }
    let fine = |text: &str| {
        let (problem, out) = run2(text, &["mesh.spacing=[0.125, 0.125]"]);
        -problem.reactions[0].total(out.reports.last().unwrap())[1] / 1.0e4
    };
    let (q_s, q_r) = (fine(rigid), fine(&rough));
    println!(
        "0.125 m grid: smooth tool {q_s:.5} c, rough tool {q_r:.5} c ({:+.2} %)",
        100.0 * (q_r / q_s - 1.0)
    );
    assert!(
        q_r >= q_s * (1.0 - 1e-3) && q_r <= 1.01 * q_s,
        "rough {q_r} against smooth {q_s}"
    );
}

/// Issue 44 (implicit contact): `platen_cube.toml`, a smooth rigid
/// platen compressing an elastic cube 1 % on a smooth rigid base (3D).
/// With both tools smooth the cube is in uniaxial stress, σ_zz the same
/// at every point; the penalty's error (the top nodes sink f/k, f their
/// share of the face, 1/4 at a corner) bends the top layer's strain by at
/// most ~1 % of the strain (theory page), so σ_zz must be uniform within
/// 3 % of its mean across the points, and its mean within 3 % of
/// E ln(0.99) (Hencky, uniaxial stress). The rough platen and base (pure
/// stick) barrel the cube: its σ_zz spread is printed and must exceed the
/// smooth one's. The platen's reaction is its force (E ln 0.99 on the
/// quarter's 1 m² within the same 3 %), and a uniform pressure acts at
/// the face's centre: its moment about (0.5, 0.5, 1) must be below 1 %
/// of the force times the half-width (the nodes' share of the face is
/// symmetric about the centre; the lateral expansion shifts it by ν ε).
#[test]
fn a_smooth_platen_leaves_the_cube_uniformly_stressed() {
    let text = include_str!("../../../scenes/platen_cube.toml");
    let spread = |text: &str| {
        let (scene, src) = scene::parse(text, "platen_cube.toml", &[]).unwrap();
        let problem = Problem::<3>::build(&scene, &src, scene.solver.padding()).unwrap();
        let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
        let szz: Vec<f64> = out.last.sigma.iter().map(|s| s[8]).collect();
        let mean = szz.iter().sum::<f64>() / szz.len() as f64;
        let worst = szz.iter().map(|s| (s - mean).abs()).fold(0.0, f64::max);
        let iterations: usize = out.reports.iter().map(|r| r.iterations()).sum();
        let last = out.reports.last().unwrap();
        let platen = &problem.reactions[0];
        let force = platen.total(last);
        let moment = platen.moment(&problem, last).unwrap();
        println!("platen force {force:?}, moment {moment:?}");
        (mean, worst / mean.abs(), iterations, force, moment)
    };
    let (mean, smooth, it_s, force, moment) = spread(text);
    let rough_text = text.replace("friction = 0.0", "rough = true");
    let (mean_r, rough, it_r, _, _) = spread(&rough_text);
    let expected = 1.0e7 * 0.99f64.ln();
    println!(
        "platen: smooth σ_zz mean {mean:.1} Pa (E ln 0.99 = {expected:.1}), spread {:.3} % ({it_s} iterations); rough mean {mean_r:.1} Pa, spread {:.2} % ({it_r} iterations)",
        100.0 * smooth,
        100.0 * rough
    );
    assert!(smooth <= 0.03, "smooth platen: σ_zz spread {smooth}");
    assert!(
        (mean - expected).abs() <= 0.03 * expected.abs(),
        "mean σ_zz {mean}"
    );
    assert!(rough > smooth, "rough {rough} against smooth {smooth}");
    assert!(
        (force[2] - expected).abs() <= 0.03 * expected.abs(),
        "{force:?}"
    );
    let lever = 0.01 * force[2].abs() * 0.5;
    assert!(
        moment[0].abs() <= lever && moment[1].abs() <= lever,
        "{moment:?}"
    );
}

/// Issue 44 (implicit contact): the platen and base of `platen_cube.toml`
/// with μ = 0.05, below the rough platen's |F_t|/F_n (0.14): the outer
/// nodes slip while the inner ones stick, so the stiffness holds the
/// non-symmetric slip tangent and every step must be solved by LU. With
/// the consistent tangent Newton converges quadratically: in every step
/// the first residual below 1e-5, r, is followed by one below
/// max(1e3 r², 1e-12) (a linear rate of 0.1 would leave 0.1 r, 10 times
/// more at r = 1e-5 and 300 times at the measured r ≈ 3e-7; the measured
/// constants are about 1 once the stick/slip set has settled and 440 in
/// the first step, where it changes under the iterations). Coulomb's
/// bound holds for the platen's total force, |F_t| ≤ μ F_n.
#[test]
fn a_slipping_platen_converges_quadratically_with_lu() {
    let text = include_str!("../../../scenes/platen_cube.toml")
        .replace("friction = 0.0", "friction = 0.05");
    let (scene, src) = scene::parse(&text, "platen_cube.toml", &[]).unwrap();
    let problem = Problem::<3>::build(&scene, &src, scene.solver.padding()).unwrap();
    let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap();
    for r in &out.reports {
        assert_eq!(format!("{:?}", r.factorisation), "Some(Lu)");
        let res = &r.residuals;
        let k = res.iter().position(|&x| x < 1e-5).unwrap();
        if k + 1 < res.len() {
            let (a, b) = (res[k], res[k + 1]);
            assert!(b <= (1e3 * a * a).max(1e-12), "{res:?}");
        }
        println!("residuals {res:?}");
    }
    let last = out.reports.last().unwrap();
    let force = problem.reactions[0].total(last);
    let ratio = (force[0].powi(2) + force[1].powi(2)).sqrt() / force[2].abs();
    println!("μ = 0.05 platen: |F_t|/F_n = {ratio:.4}");
    assert!(ratio <= 0.05 && ratio > 0.0, "{ratio}");
}

/// A rigid tool's penalties scale with the cell size: `kind = "contact"`
/// on a simplex mesh is refused at its `kind`.
#[test]
fn a_rigid_tool_on_a_simplex_mesh_is_refused() {
    let text = VALID
        .replace("cells = [2, 2]", "cells = [2, 2]\nkind = \"simplex\"")
        .replace("kind = \"fixed\"", "kind = \"contact\"");
    let e = refusal(&text);
    assert!(
        e.contains("bad.toml:21:8: kind = contact needs a regular grid"),
        "{e}"
    );
}
