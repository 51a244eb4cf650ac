//! The `mpm` program: scene files, overrides, outputs and errors.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use super::common;

use common::{mpm, run_outputs as outputs};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mpm-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn no_nan_in(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.file_name().unwrap() == "checkpoint.mpm" {
            // Binary; its writer refuses non-finite numbers (tested in
            // resume_repeats_the_uninterrupted_run).
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        let lower = text.to_lowercase();
        assert!(
            !lower.contains("nan") && !lower.contains("inf"),
            "non-finite value written"
        );
    }
}

#[test]
fn list_names_every_case() {
    let (ok, out, _) = mpm(&["list"]);
    assert!(ok);
    for case in ["column", "shear", "cantilever", "annulus", "collapse"] {
        assert!(out.contains(&format!("{case}:")), "{out}");
    }
}

/// `mpm scene --case NAME` prints the case's scene as a scene file: the
/// case's typed scene with the overrides, which `mpm run` runs as a scene.
#[test]
fn scene_prints_a_case_as_a_scene_file() {
    use mpm_cases::cases::column::{self, ColumnParams};
    use mpm_cases::variant::BasisKind;
    for case in [
        "column",
        "shear",
        "cantilever",
        "annulus",
        "collapse",
        "stretch",
    ] {
        let (ok, out, err) = mpm(&["scene", "--case", case]);
        assert!(ok, "{case}: {err}");
        let (scene, _) = mpm_cases::scene::parse(&out, case, &[]).unwrap();
        assert_eq!(scene.bodies.len(), 1, "{case}");
    }
    let (ok, out, err) = mpm(&[
        "scene",
        "--case",
        "column",
        "--set",
        "h=12.5",
        "--set",
        "basis=gimp",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.starts_with(
            "# The column case's scene (`mpm scene --case column --set h=12.5 --set basis=gimp`)"
        ),
        "{out}"
    );
    let params = ColumnParams {
        h: 12.5,
        basis: BasisKind::Gimp,
        ..ColumnParams::default()
    };
    let (scene, _) = mpm_cases::scene::parse(&out, "column.toml", &[]).unwrap();
    assert_eq!(scene, column::scene(&params, &params.variant()).unwrap());

    let dir = temp_dir("scene-of-case");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("column.toml");
    std::fs::write(&file, &out).unwrap();
    let (ok, _, err) = mpm(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["material_points"], 2 * 2 * 4);
    std::fs::remove_dir_all(&dir).unwrap();

    for (args, expected) in [
        (vec!["scene", "--case", "nope"], "unknown case `nope`"),
        (
            vec!["scene", "--case", "column", "--set", "h=3"],
            "must divide",
        ),
        (
            vec!["scene", "--case", "column", "--set", "hh=3"],
            "unknown field",
        ),
    ] {
        let (ok, _, err) = mpm(&args);
        assert!(!ok && err.contains(expected), "{args:?}: {err}");
    }
}

#[test]
fn the_issue_command_line_runs_and_writes_every_output() {
    let dir = temp_dir("column");
    let (ok, out, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--set",
        "h=1.5625",
        "--set",
        "points_per_cell=2",
        "--set",
        "basis=gimp",
        "--set",
        "domain_update=stretch",
        "--set",
        "formulation=pc",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("column [gimp pc none stretch]"), "{out}");
    for file in [
        "points.pvd",
        "grid.pvd",
        "points_0019.vtu",
        "grid_0019.vtu",
        "steps.csv",
        "iterations.csv",
        "summary.json",
    ] {
        assert!(dir.join(file).exists(), "{file} missing");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["case"], "column");
    assert_eq!(summary["variant"]["basis"], "gimp");
    assert_eq!(summary["material_points"], 128);
    assert_eq!(summary["load_steps"], 20);
    assert!(summary["newton_iterations"].as_u64().unwrap() >= 20);
    assert!(summary["wall_time_s"].as_f64().unwrap() > 0.0);
    assert!(summary["error"].as_f64().unwrap() < 5e-3);
    no_nan_in(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scene_files_run_and_bad_scenes_report_line_and_column() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/collapse.toml");
    let dir = temp_dir("collapse");
    let (ok, out, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "points_per_cell=2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(
        summary["horizontal_extent"].as_f64().unwrap() > 13.0,
        "{out}"
    );
    assert!(summary["max_height"].as_f64().unwrap() < 7.0);
    std::fs::remove_dir_all(&dir).unwrap();

    let bad = temp_dir("bad");
    std::fs::create_dir_all(&bad).unwrap();
    let path = bad.join("bad.toml");
    std::fs::write(&path, "case = \"column\"\nh = 1.5625\nbsis = \"gimp\"\n").unwrap();
    let (ok, _, err) = mpm(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        bad.join("o").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml:3:1") && err.contains("unknown field `bsis`"),
        "{err}"
    );
    std::fs::write(&path, "case = \"column\"\nh = \"fine\"\n").unwrap();
    let (ok, _, err) = mpm(&["run", path.to_str().unwrap()]);
    assert!(!ok && err.contains("bad.toml:2:5"), "{err}");
    std::fs::remove_dir_all(&bad).unwrap();
}

#[test]
fn bad_input_fails_cleanly() {
    for (args, expected) in [
        (
            vec!["run", "--case", "column", "--set", "basis=quartic"],
            "unknown variant",
        ),
        (vec!["run", "--case", "nope"], "unknown case"),
        (
            vec!["run", "--case", "collapse", "--set", "h=3"],
            "must divide",
        ),
        (
            vec!["run", "--case", "column", "--set", "h=-1"],
            "must divide",
        ),
        (
            vec!["run", "--case", "column", "--set", "youngs_modulus=-5"],
            "Young's modulus",
        ),
        (vec!["run"], "no case"),
        (
            vec!["run", "--case", "column", "--set", "gimp_volume=domain"],
            "gimp_volume = domain applies to basis = gimp",
        ),
        (
            vec!["run", "--case", "column", "--set", "gimp_volume=corners"],
            "unknown variant",
        ),
    ] {
        let (ok, _, err) = mpm(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// A step that cannot converge in the iterations allowed is halved down
/// to the minimum and the run stops with a typed error naming the step,
/// the last residual and the cause; every halving on the way is logged
/// with its cause. A tolerance below round-off is met at the rounding floor
/// instead, and the run says so. Points pulled out of the grid stop the run
/// with an error naming the point.
#[test]
fn non_convergence_and_points_leaving_the_grid_are_diagnosed() {
    let dir = temp_dir("diverge");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/coombs2020_column.toml");
    // Two iterations are too few for some steps of 0.05: each is halved,
    // the halving logged, and the run completes (16 cuts).
    let (ok, out, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "solver.max_iterations=2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let cuts: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(" cut (last residual "))
        .collect();
    assert_eq!(cuts.len(), 16, "{err}");
    assert!(
        cuts[0].starts_with("step 1 from load factor 0.0000 to 0.0500 cut")
            && cuts[0].contains("no convergence in 2 iterations"),
        "{err}"
    );
    assert!(out.contains("(16 cut)"), "{out}");
    let (ok, _, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "solver.max_iterations=1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        err.contains("load step 0")
            && err.contains("last normalised residual")
            && err.contains("no convergence in 1 iterations"),
        "{err}"
    );
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--set",
        "tolerance=1e-30",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("stalled at the rounding floor"), "{err}");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--set",
        "gravity=-2e4",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        err.contains("material point") && err.contains("lies outside the grid"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    no_nan_in(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn resume_repeats_the_uninterrupted_run() {
    // The shear case uses the secant predictor, whose memory must survive
    // the checkpoint; the cantilever writes a case table (tip.csv).
    for (case, steps) in [("shear", "30"), ("cantilever", "50")] {
        let whole = temp_dir(&format!("whole-{case}"));
        let split = temp_dir(&format!("split-{case}"));
        let args = |dir: &Path| {
            vec![
                "run".to_string(),
                "--case".into(),
                case.into(),
                "--set".into(),
                "load_steps=".to_string() + steps,
                "--out".into(),
                dir.to_str().unwrap().to_string(),
            ]
        };
        let run = |extra: &[&str], dir: &Path| {
            let mut a: Vec<String> = args(dir);
            a.extend(extra.iter().map(|s| s.to_string()));
            let a: Vec<&str> = a.iter().map(String::as_str).collect();
            mpm(&a)
        };
        let (ok, _, err) = run(&[], &whole);
        assert!(ok, "{err}");
        let (ok, out, err) = run(&["--stop-after", "7"], &split);
        assert!(ok, "{err}");
        assert!(out.contains("stopped after load step 7"), "{out}");
        assert!(!split.join("summary.json").exists());
        let (ok, out, err) = run(&["--resume", "--stop-after", "9"], &split);
        assert!(
            ok && out.contains("stopped after load step 16"),
            "{out}{err}"
        );
        let (ok, _, err) = run(&["--resume"], &split);
        assert!(ok, "{err}");
        let (a, b) = (outputs(&whole), outputs(&split));
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
        for (name, text) in &a {
            // Wall-clock columns differ between any two runs.
            let (x, y) = if name.ends_with("steps.csv") {
                (
                    common::without_timings(&String::from_utf8_lossy(text)).into_bytes(),
                    common::without_timings(&String::from_utf8_lossy(&b[name])).into_bytes(),
                )
            } else {
                (text.clone(), b[name].clone())
            };
            assert!(x == y, "{case}: {name} differs after resuming");
        }
        let summary = |dir: &Path| -> serde_json::Value {
            let mut v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                    .unwrap();
            v.as_object_mut().unwrap().remove("wall_time_s");
            v
        };
        assert_eq!(summary(&whole), summary(&split), "{case}");
        no_nan_in(&split);
    }
}

/// A run with a rigid tool (`scenes/footing_rigid.toml`, issue 44)
/// resumes bit for bit: the checkpoint holds the forces the footing's
/// nodes carry into the next step (without them the resumed step would
/// start the nodes free of force and the pressure would differ).
#[test]
fn a_run_with_a_rigid_tool_resumes_bit_for_bit() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/footing_rigid.toml");
    let (whole, split) = (temp_dir("whole-tool"), temp_dir("split-tool"));
    let run = |extra: &[&str], dir: &Path| {
        let mut a = vec![
            "run",
            scene.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        mpm(&a)
    };
    let (ok, _, err) = run(&[], &whole);
    assert!(ok, "{err}");
    let (ok, out, err) = run(&["--stop-after", "9"], &split);
    assert!(
        ok && out.contains("stopped after load step 9"),
        "{out}{err}"
    );
    let (ok, _, err) = run(&["--resume"], &split);
    assert!(ok, "{err}");
    let (a, b) = (outputs(&whole), outputs(&split));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (name, text) in &a {
        if name.ends_with("steps.csv") || name.ends_with("summary.json") {
            // Wall-clock columns differ between any two runs.
            continue;
        }
        assert!(*text == b[name], "{name} differs after resuming");
    }
    let reaction = |dir: &Path| -> serde_json::Value {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        v["reactions"].clone()
    };
    assert_eq!(reaction(&whole), reaction(&split));
}

#[test]
fn resume_refuses_another_scene_a_missing_or_a_damaged_checkpoint() {
    let dir = temp_dir("resume-errors");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--resume",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("checkpoint.mpm"), "{err}");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--stop-after",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--set",
        "h=1.5625",
        "--resume",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("other parameters"), "{err}");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "cantilever",
        "--resume",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("case `column`"), "{err}");
    let path = dir.join("checkpoint.mpm");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 8]).unwrap();
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--resume",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("not a usable checkpoint"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// A Gmsh mesh read through a scene file (its path relative to the scene),
/// written as triangles beside the points.
#[test]
fn a_gmsh_scene_runs_on_its_triangles() {
    let dir = temp_dir("gmsh-scene");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/annulus_gmsh.toml");
    let (ok, out, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "points_per_element=2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("annulus [linear pc none none]: 2472 points"),
        "{out}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["elements"], 618);
    assert!(summary["error"].as_f64().unwrap() < 1e-2);
    let grid = std::fs::read_to_string(dir.join("grid_0009.vtu")).unwrap();
    // VTK_TRIANGLE = 5 for every active cell.
    let types = grid.split("Name=\"types\"").nth(1).unwrap();
    let types = &types[types.find('>').unwrap() + 1..types.find("</DataArray>").unwrap()];
    assert!(!types.trim().is_empty() && types.split_whitespace().all(|t| t == "5"));
    no_nan_in(&dir);
    // A missing mesh file is a clear error naming it.
    let (ok, _, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "mesh=meshes/none.msh",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("none.msh"), "{err}");
}

/// The 3D Gmsh scene (ten-node tetrahedra split into linear children,
/// moving mesh) writes tetrahedra, its moved mesh, and the exact stress.
#[test]
fn a_gmsh_tetrahedral_scene_runs_with_a_moving_mesh() {
    let dir = temp_dir("gmsh-tets");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/stretch_gmsh.toml");
    let (ok, out, err) = mpm(&[
        "run",
        scene.to_str().unwrap(),
        "--set",
        "load_steps=1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("stretch [linear pc none none]: 99528 points"),
        "{out}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(summary["error"].as_f64().unwrap() < 1e-9, "{summary}");
    let steps = std::fs::read_to_string(dir.join("steps.csv")).unwrap();
    assert!(steps.starts_with("step,load_factor,iterations,reaction_x,reaction_y,reaction_z,"));
    let last = steps.lines().count() - 2;
    let grid = std::fs::read_to_string(dir.join(format!("grid_{last:04}.vtu"))).unwrap();
    let types = grid.split("Name=\"types\"").nth(1).unwrap();
    let types = &types[types.find('>').unwrap() + 1..types.find("</DataArray>").unwrap()];
    assert!(!types.trim().is_empty() && types.split_whitespace().all(|t| t == "10"));
    // The mesh is written where it moved to: the cube's top reaches y = 2.5.
    let points = grid.split("Name=\"Points\"").nth(1).unwrap();
    let points = &points[points.find('>').unwrap() + 1..points.find("</DataArray>").unwrap()];
    let top = points
        .split_whitespace()
        .skip(1)
        .step_by(3)
        .map(|y| y.parse::<f64>().unwrap())
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((top - 2.5).abs() < 1e-12, "mesh top at {top}");
    no_nan_in(&dir);
}

/// `--export-tangent` writes each step's assembled stiffness over the free
/// dofs as Matrix Market, readable by sprs (and SciPy, MATLAB): square with
/// the step's free dofs, symmetric for the elastic column (Cholesky is
/// used), with a positive diagonal. Without the flag nothing is written.
#[test]
fn export_tangent_writes_matrix_market_per_step() {
    let dir = temp_dir("tangent");
    let (ok, _, err) = mpm(&[
        "run",
        "--case",
        "column",
        "--export-tangent",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let steps = std::fs::read_to_string(dir.join("steps.csv")).unwrap();
    let header: Vec<&str> = steps.lines().next().unwrap().split(',').collect();
    let free_col = header.iter().position(|c| *c == "free_dofs").unwrap();
    for (step, line) in steps.lines().skip(1).enumerate() {
        let free: usize = line.split(',').nth(free_col).unwrap().parse().unwrap();
        let path = dir.join(format!("tangent_{step:04}.mtx"));
        let k: sprs::TriMat<f64> = sprs::io::read_matrix_market(&path).unwrap();
        let k: sprs::CsMat<f64> = k.to_csc();
        assert_eq!(k.shape(), (free, free), "{}", path.display());
        let scale = k.data().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (v, (r, c)) in &k {
            let t = k.get(c, r).copied().unwrap_or(0.0);
            assert!(
                (v - t).abs() <= 1e-12 * scale,
                "K[{r},{c}] = {v}, K[{c},{r}] = {t}"
            );
            if r == c {
                assert!(*v > 0.0, "diagonal {r}: {v}");
            }
        }
    }
    let plain = temp_dir("no_tangent");
    let (ok, _, err) = mpm(&["run", "--case", "column", "--out", plain.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        std::fs::read_dir(&plain).unwrap().all(|e| !e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .ends_with(".mtx"))
    );
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&plain);
}
