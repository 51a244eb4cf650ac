//! The soil laws' rows (issue 43): the Mohr–Coulomb strip footing of
//! `scenes/footing_mohr_coulomb.toml` with the friction angle driven to
//! zero, associated against non-associated flow and ten times larger
//! steps, a block pulled apart under lateral confinement until its
//! points sit at the apex, and modified Cam-Clay: the undrained triaxial
//! cell of `scenes/triaxial_cam_clay.toml` normally and very heavily
//! over-consolidated and in ten times larger steps, and a geostatic
//! Cam-Clay column loaded to twice its base pressure.

use super::{Expect, Mode, Row, run_scene};

/// Prandtl–Reissner's N_c at φ (degrees): (N_q − 1) cot φ, and 2 + π at
/// φ = 0.
fn n_c(phi: f64) -> f64 {
    if phi == 0.0 {
        return 2.0 + std::f64::consts::PI;
    }
    let t = phi.to_radians().tan();
    let n_q = (std::f64::consts::PI * t).exp()
        * (std::f64::consts::FRAC_PI_4 + phi.to_radians() / 2.0)
            .tan()
            .powi(2);
    (n_q - 1.0) / t
}

/// The footing's rows.
fn footing() -> Vec<Row> {
    let text = std::fs::read_to_string(super::scenes_dir().join("footing_mohr_coulomb.toml"))
        .unwrap_or_default();
    let cohesion = 1.0e4;
    let cases: [(&str, f64, &[&str], Expect); 5] = [
        ("φ = 20°, ψ = 0 (the scene)", 20.0, &[], Expect::Converge),
        (
            "φ = 0 (Tresca)",
            0.0,
            &["friction_angle = 0.0"],
            Expect::Converge,
        ),
        (
            "φ = 10⁻³°: c cot φ = 5.7 × 10⁸ Pa",
            1e-3,
            &["friction_angle = 1.0e-3"],
            Expect::Converge,
        ),
        (
            "φ = ψ = 20° (associated)",
            20.0,
            &["dilation_angle = 20.0"],
            // Newton cycles near λ = 0.1 with F-bar (scene header): what
            // happens is recorded, not required.
            Expect::Measure,
        ),
        (
            "φ = 20°, ψ = 0, 2 steps (10× nominal)",
            20.0,
            &["steps = 2"],
            Expect::Recover,
        ),
    ];
    let mut rows = Vec::new();
    for (variant, phi, edits, expect) in cases {
        let scene = edited(&text, edits);
        let mut row = Row::new(
            "soil",
            "smooth strip footing on Mohr–Coulomb soil, 0.25 m grid, F-bar",
            variant,
            expect,
        );
        let run = run_scene(&scene, None, &[]);
        run.fill(&mut row);
        if let Some(r) = run.pointer("/reactions/footing/1") {
            let q = -r / cohesion;
            let reference = n_c(phi);
            row.error = Some((q - reference).abs() / reference);
            row.measured = format!("q/c = {q:.3} (N_c = {reference:.3})");
            row.value("q/c", q);
        }
        rows.push(row);
    }
    rows
}

/// A block under lateral confinement pulled apart until its points reach
/// the apex p = c cot φ.
fn apex() -> Row {
    let text = "[mesh]\norigin = [0.0, 0.0]\nsize = [1.0, 1.5]\ncells = [2, 3]\n\n\
                [[material]]\nname = \"m\"\nmodel = \"mohr_coulomb\"\nyoungs_modulus = 1.0e7\npoisson_ratio = 0.3\ndensity = 0.0\ncohesion = 1.0e4\nfriction_angle = 30.0\ndilation_angle = 30.0\n\n\
                [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = { box = { lower = [0.0, 0.0], upper = [1.0, 1.0] } }\npoints_per_cell = 2\n\n\
                [[node_set]]\nname = \"top\"\nregion = { box = { lower = [-0.1, 0.99], upper = [1.1, 1.01] } }\n\n\
                [[boundary]]\nset = \"y_min\"\nkind = \"fixed\"\n\n[[boundary]]\nset = \"x_min\"\nkind = \"roller\"\n\n\
                [[boundary]]\nset = \"x_max\"\nkind = \"roller\"\n\n\
                [[boundary]]\nset = \"top\"\nkind = \"displacement\"\ndisplacement = { x = 0.0, y = 0.02 }\n\n\
                [solver]\nsteps = 10\n\n[output]\nfields = [\"displacement\", \"stress\"]\n\n\
                [[output.reaction]]\nname = \"top\"\nset = \"top\"\n";
    let mut row = Row::new(
        "soil",
        "confined block pulled 2 % apart (Mohr–Coulomb, c = 10 kPa, φ = 30°): the apex in tension",
        "linear, pc, none",
        Expect::Converge,
    );
    let run = run_scene(text, None, &[]);
    run.fill(&mut row);
    if let Some(r) = run.pointer("/reactions/top/1") {
        // The top's traction per metre of the 1 m block against c cot φ.
        let apex = 1.0e4 / 30f64.to_radians().tan();
        row.error = Some((r.abs() - apex).abs() / apex);
        row.measured = format!("σ_yy = {r:.1} Pa (apex c cot φ = {apex:.1} Pa)");
        row.value("sigma_yy", r);
    }
    row
}

/// `text` with each `key = value` of `edits` replacing the first line
/// that sets `key`.
fn edited(text: &str, edits: &[&str]) -> String {
    let mut scene = text.to_owned();
    for edit in edits {
        let key = edit.split(" = ").next().unwrap_or_default();
        let line = scene
            .lines()
            .find(|l| l.starts_with(&format!("{key} =")))
            .map(str::to_owned);
        if let Some(l) = line {
            scene = scene.replacen(&l, edit, 1);
        }
    }
    scene
}

/// The Cam-Clay triaxial cell's rows: the scene, OCR = 1000 (a dry-side
/// path that softens onto the p_c floor) and 2 steps of 15 % axial strain
/// (no longer isochoric: a drained-and-sheared path, measured).
fn cam_clay_cell() -> Vec<Row> {
    let text = std::fs::read_to_string(super::scenes_dir().join("triaxial_cam_clay.toml"))
        .unwrap_or_default();
    let cases: [(&str, &[&str], Expect); 3] = [
        ("normally consolidated (the scene)", &[], Expect::Converge),
        (
            "OCR = 1000: dry side, softening to the floor p_min = 1 kPa",
            &["overconsolidation_ratio = 1000.0"],
            Expect::Converge,
        ),
        (
            "2 steps of 15 % (10× nominal)",
            &["steps = 2"],
            Expect::Converge,
        ),
    ];
    cases
        .into_iter()
        .map(|(variant, edits, expect)| {
            let mut row = Row::new(
                "soil",
                "undrained triaxial cell of modified Cam-Clay (3D, one cell)",
                variant,
                expect,
            );
            let run = run_scene(&edited(&text, edits), None, &[]);
            run.fill(&mut row);
            if let Some(uz) = run.pointer("/probes/corner/2") {
                row.measured = format!("corner point moved {uz:.4} m axially");
                row.value("uz", uz);
            }
            row
        })
        .collect()
}

/// A geostatic column of normally consolidated Cam-Clay
/// (`scenes/geostatic_column.toml` with the clay of the triaxial cell)
/// under a surface load of 200 kPa in 5 steps, and in 1: the wet side,
/// hardening.
fn cam_clay_column() -> Vec<Row> {
    let text = std::fs::read_to_string(super::scenes_dir().join("geostatic_column.toml"))
        .unwrap_or_default()
        .replace(
            "model = \"mohr_coulomb\"\nyoungs_modulus = 2.0e7\npoisson_ratio = 0.3\ndensity = 2000.0\ncohesion = 0.0\nfriction_angle = 30.0",
            "model = \"modified_cam_clay\"\ndensity = 2000.0\ncompression_index = 0.2\nswelling_index = 0.05\ncritical_state_slope = 1.2\nshear_modulus = 5.0e6\nreference_pressure = 1.0e5",
        )
        .replace(
            "[solver]\nsteps = 1",
            "[[load]]\nkind = \"traction\"\nbody = \"soil\"\nside = \"y_max\"\ntraction = [0.0, -2.0e5]\n\n[solver]\nsteps = 5\n\n[[output.probe]]\nname = \"top\"\nat = [0.5, 10.0]",
        );
    [
        ("5 steps", "steps = 5"),
        ("1 step (5× nominal)", "steps = 1"),
    ]
    .into_iter()
    .map(|(variant, steps)| {
        let mut row = Row::new(
            "soil",
            "geostatic column of normally consolidated Cam-Clay under 200 kPa",
            variant,
            Expect::Converge,
        );
        let run = run_scene(&edited(&text, &[steps]), None, &[]);
        run.fill(&mut row);
        if let Some(uy) = run.pointer("/probes/top/1") {
            row.measured = format!("surface settles {:.4} m", -uy);
            row.value("settlement", -uy);
        }
        row
    })
    .collect()
}

/// Every soil row.
pub fn rows(_mode: Mode) -> Vec<Row> {
    let mut rows = footing();
    rows.push(apex());
    rows.extend(cam_clay_cell());
    rows.extend(cam_clay_column());
    rows
}
