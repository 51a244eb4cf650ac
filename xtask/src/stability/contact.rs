//! The contact rows (issue 44): soft blocks at 40 m/s meeting by
//! multi-field contact (alike, and a stiffness contrast of 10⁵), a block
//! into a gap-checked friction wall (and the refusal of a gap check the
//! points cannot reach), and the implicit solver's rigid
//! platen of `scenes/platen_cube.toml` with penalties 10⁻³ and 10⁴ times
//! the default, partial slip (μ = 0.05) and the whole stroke in one step.

use super::{Expect, Row, run_scene};

/// Two blocks of `young_right` and 10⁴ Pa at ±40 m/s towards each
/// other, each its own contact field with μ = 0.3, FLIP on 16 × 4 cells,
/// to t = 0.1 s.
fn colliding_blocks(young_right: f64) -> String {
    format!(
        "[mesh]\norigin = [0.0, 0.0]\nsize = [4.0, 1.0]\ncells = [16, 4]\n\n\
         [[material]]\nname = \"soft\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e4\npoisson_ratio = 0.3\ndensity = 1000.0\n\n\
         [[material]]\nname = \"other\"\nmodel = \"neo_hookean\"\nyoungs_modulus = {young_right:e}\npoisson_ratio = 0.3\ndensity = 1000.0\n\n\
         [[body]]\nname = \"left\"\nmaterial = \"soft\"\nregion = {{ box = {{ lower = [0.5, 0.25], upper = [1.5, 0.75] }} }}\npoints_per_cell = 2\nvelocity = [40.0, 0.0]\n\n\
         [[body]]\nname = \"right\"\nmaterial = \"other\"\nregion = {{ box = {{ lower = [2.5, 0.25], upper = [3.5, 0.75] }} }}\npoints_per_cell = 2\nvelocity = [-40.0, 0.0]\n\n\
         [[contact]]\nbodies = [\"left\", \"right\"]\nfriction = 0.3\n\n\
         [solver]\nkind = \"explicit\"\ncfl = 0.3\nend_time = 0.1\noutput_interval = 0.01\n"
    )
}

/// A soft block at 40 m/s into a friction wall (μ = 0.3, gap-checked or
/// not) on `x_min`, to t = 0.1 s (the grid of [`colliding_blocks`]), with
/// `basis`.
fn friction_wall(basis: &str, gap_check: bool) -> String {
    "[mesh]\norigin = [0.0, 0.0]\nsize = [4.0, 1.0]\ncells = [16, 4]\n\n\
     [[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e4\npoisson_ratio = 0.3\ndensity = 1000.0\n\n\
     [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = { box = { lower = [0.5, 0.25], upper = [1.5, 0.75] } }\npoints_per_cell = 2\nvelocity = [-40.0, 0.0]\n\n\
     [[boundary]]\nset = \"x_min\"\nkind = \"friction\"\nfriction = 0.3\ngap_check = GAP\n\n\
     [solver]\nkind = \"explicit\"\ncfl = 0.3\nend_time = 0.1\noutput_interval = 0.01\n"
        .replace("GAP", &gap_check.to_string())
        + &format!("basis = \"{basis}\"\n")
}

/// The explicit rows: the drift of the total energy (contact and wall
/// losses booked) and what the contact took.
fn explicit() -> Vec<Row> {
    [
        (
            colliding_blocks(1.0e4),
            "two soft blocks at ±40 m/s meeting by multi-field contact (μ = 0.3)",
            "bspline2, flip",
            Expect::Measure,
        ),
        (
            colliding_blocks(1.0e9),
            "a soft block (E = 10⁴ Pa) at 40 m/s into a stiff one (10⁹ Pa), multi-field contact",
            "bspline2, flip",
            Expect::Measure,
        ),
        (
            friction_wall("bspline2_boundary", true),
            "a soft block at 40 m/s into a gap-checked friction wall (μ = 0.3)",
            "bspline2_boundary, flip",
            Expect::Measure,
        ),
        (
            friction_wall("bspline2_boundary", false),
            "a soft block at 40 m/s into a friction wall (μ = 0.3) without the gap check",
            "bspline2_boundary, flip",
            Expect::Measure,
        ),
        (
            friction_wall("bspline2", true),
            "a gap-checked wall with the B-splines that keep points a cell inside the grid",
            "bspline2, flip",
            Expect::Refuse("Scene"),
        ),
    ]
    .into_iter()
    .map(|(scene, name, variant, expect)| {
        let mut row = Row::new("contact", name, variant, expect);
        let run = run_scene(&scene, None, &[]);
        run.fill(&mut row);
        if let Some(d) = run.number("energy_drift") {
            row.measured = format!("energy drift {d:+.2e}");
            row.value("drift", d);
        }
        for name in ["friction_work", "wall_work"] {
            let w = run
                .pointer(&format!("/final_energies/{name}"))
                .unwrap_or(0.0);
            if w > 0.0 {
                row.measured += &format!(", {} {w:.3e}", name.replace('_', " "));
                row.value(name, w);
            }
        }
        row
    })
    .collect()
}

/// The platen's rows: the error is the mean of σ_zz under the smooth
/// platen's force against E ln 0.99 per unit area (the uniaxial Hencky
/// stress of the 1 % stroke, `scenes/platen_cube.toml`), read from the
/// platen's reaction on the quarter cube's unit face.
fn platen() -> Vec<Row> {
    let text =
        std::fs::read_to_string(super::scenes_dir().join("platen_cube.toml")).unwrap_or_default();
    let uniaxial = 1.0e7 * 0.99f64.ln();
    let cases: [(&str, Vec<&str>, Expect); 5] = [
        (
            "the scene (smooth, default penalty)",
            vec![],
            Expect::Converge,
        ),
        (
            "penalty 10⁻³ × default (3 × 10⁶ Pa/m)",
            vec!["boundary.3.normal_stiffness=3.0e6"],
            Expect::Converge,
        ),
        (
            "penalty 10⁴ × default (3 × 10¹³ Pa/m)",
            vec!["boundary.3.normal_stiffness=3.0e13"],
            Expect::Converge,
        ),
        (
            "μ = 0.05 (partial slip, a non-symmetric tangent)",
            vec!["boundary.3.friction=0.05", "boundary.2.friction=0.05"],
            Expect::Converge,
        ),
        (
            "the stroke in 1 step (5× nominal)",
            vec!["solver.steps=1"],
            Expect::Converge,
        ),
    ];
    cases
        .into_iter()
        .map(|(variant, set, expect)| {
            let mut row = Row::new(
                "contact",
                "a rigid platen compressing an elastic cube 1 % (implicit, 3D)",
                variant,
                expect,
            );
            let set: Vec<String> = set.into_iter().map(str::to_owned).collect();
            let run = run_scene(&text, None, &set);
            run.fill(&mut row);
            if let Some(f) = run.pointer("/reactions/platen/force/2") {
                row.error = Some((f - uniaxial).abs() / uniaxial.abs());
                row.measured = format!("platen force {f:.1} N (E ln 0.99 = {uniaxial:.1} N)");
                row.value("force", f);
            }
            row
        })
        .collect()
}

/// Every contact row.
pub fn rows(_mode: super::Mode) -> Vec<Row> {
    let mut rows = explicit();
    rows.extend(platen());
    rows
}
