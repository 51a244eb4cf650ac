//! The atomic writer and the series, table and summary files built on it.
#![allow(clippy::unwrap_used)]

use super::common;

use std::path::Path;

use common::{dir_entries, element, fresh_dir, parse_xml};
use mpm_cases::output::OutputError;
use mpm_cases::output::{
    CsvTable, CsvValue, PvdSeries, atomic_write, atomic_write_with, write_summary,
};
use serde::Serialize;

// ---------------------------------------------------------------- atomic

#[test]
fn atomic_write_replaces_content_and_leaves_no_temporary() {
    let dir = fresh_dir("atomic_replace");
    let path = dir.join("a.txt");
    atomic_write(&path, b"first").unwrap();
    atomic_write(&path, b"second, longer").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second, longer");
    assert_eq!(dir_entries(&dir), vec!["a.txt".to_owned()]);
}

#[test]
fn atomic_write_into_missing_directory_fails_and_creates_nothing() {
    let dir = fresh_dir("atomic_missing_dir");
    let missing = dir.join("no_such_dir");
    let path = missing.join("a.txt");
    let err = atomic_write(&path, b"data").unwrap_err();
    match &err {
        OutputError::Io { path: p, source } => {
            assert_eq!(p, &path);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
    assert!(err.to_string().contains("no_such_dir/a.txt"), "{err}");
    assert!(!missing.exists());
    assert!(dir_entries(&dir).is_empty());
}

#[test]
fn failed_write_leaves_the_old_file_intact() {
    let dir = fresh_dir("atomic_failed_write");
    let path = dir.join("summary.json");
    atomic_write(&path, b"old content").unwrap();

    // The writer fails half-way, after some bytes went to the temporary.
    let err = atomic_write_with(&path, |w| {
        w.write_all(b"new partial")?;
        Err(std::io::Error::other("disk full (simulated)"))
    })
    .unwrap_err();
    assert!(err.to_string().contains("disk full"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"old content");
    assert_eq!(
        dir_entries(&dir),
        vec!["summary.json".to_owned()],
        "temporary removed"
    );
}

#[test]
fn failed_rename_leaves_target_and_no_temporary() {
    let dir = fresh_dir("atomic_failed_rename");
    // The target is a non-empty directory: the rename must fail.
    let target = dir.join("out.vtu");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"x").unwrap();
    assert!(matches!(
        atomic_write(&target, b"data"),
        Err(OutputError::Io { .. })
    ));
    assert!(target.join("keep").exists());
    assert_eq!(dir_entries(&dir), vec!["out.vtu".to_owned()]);
}

#[test]
fn path_without_file_name_is_refused() {
    assert!(matches!(
        atomic_write(Path::new("/"), b"x"),
        Err(OutputError::InvalidPath { .. })
    ));
}

// ---------------------------------------------------------------- pvd

fn datasets(path: &Path) -> Vec<(f64, String, String)> {
    let doc = parse_xml(&std::fs::read_to_string(path).unwrap());
    assert_eq!(element(&doc, "VTKFile").attr("type"), "Collection");
    doc.iter()
        .filter(|e| e.name == "DataSet")
        .map(|e| {
            assert_eq!(e.parent(), "Collection");
            (
                e.attr("timestep").parse().unwrap(),
                e.attr("part").to_owned(),
                e.attr("file").to_owned(),
            )
        })
        .collect()
}

#[test]
fn pvd_is_a_valid_series_after_every_step() {
    let dir = fresh_dir("pvd_series");
    let pvd = dir.join("points.pvd");
    let mut series = PvdSeries::new(&pvd);
    let times = [0.0, 0.1, 1.0 / 3.0];
    for (k, &t) in times.iter().enumerate() {
        // A path under the collection's directory is stored relative to it.
        series
            .push(t, &dir.join(format!("points_{k:04}.vtu")))
            .unwrap();
        let ds = datasets(&pvd);
        assert_eq!(ds.len(), k + 1, "the file lists every step so far");
        for (j, (time, part, file)) in ds.iter().enumerate() {
            assert_eq!(*time, times[j]);
            assert_eq!(part, "0");
            assert_eq!(file, &format!("points_{j:04}.vtu"));
        }
    }
    assert_eq!(series.steps().len(), 3);
    assert_eq!(dir_entries(&dir), vec!["points.pvd".to_owned()]);

    // Relative paths are kept as given, with `/` separators.
    let mut other = PvdSeries::new(dir.join("grid.pvd"));
    other.push(0.5, Path::new("grid/./step_1.vtu")).unwrap();
    assert_eq!(datasets(&dir.join("grid.pvd"))[0].2, "grid/step_1.vtu");
}

#[test]
fn pvd_refuses_times_that_do_not_advance() {
    let dir = fresh_dir("pvd_times");
    let pvd = dir.join("s.pvd");
    let mut series = PvdSeries::new(&pvd);
    series.push(1.0, Path::new("a.vtu")).unwrap();
    for bad in [1.0, 0.5, f64::NAN, f64::INFINITY] {
        let err = series.push(bad, Path::new("b.vtu")).unwrap_err();
        assert!(
            matches!(err, OutputError::InvalidTime { previous, .. } if previous == 1.0),
            "{err:?}"
        );
    }
    assert_eq!(datasets(&pvd).len(), 1, "refused steps are not written");
    assert_eq!(series.steps().len(), 1);
}

#[test]
fn pvd_step_is_dropped_when_the_write_fails() {
    let dir = fresh_dir("pvd_write_fails");
    let mut series = PvdSeries::new(dir.join("missing").join("s.pvd"));
    assert!(matches!(
        series.push(0.0, Path::new("a.vtu")),
        Err(OutputError::Io { .. })
    ));
    assert!(series.steps().is_empty(), "a failed push can be retried");
}

// ---------------------------------------------------------------- csv

#[test]
fn csv_table_writes_header_rows_and_quotes() {
    let dir = fresh_dir("csv_table");
    let path = dir.join("convergence.csv");
    let mut t = CsvTable::new(&["h", "n_points", "error", "note"]).unwrap();
    t.push_row(&[0.5.into(), 16_usize.into(), 0.1.into(), "coarse".into()])
        .unwrap();
    t.push_row(&[
        0.25.into(),
        64_usize.into(),
        2.5e-7.into(),
        "says \"fine\", really".into(),
    ])
    .unwrap();
    t.push_row(&[
        (-1.0).into(),
        CsvValue::Int(-3),
        1e-300.into(),
        String::new().into(),
    ])
    .unwrap();
    t.write(&path).unwrap();
    let expected = "h,n_points,error,note\n\
                    0.5,16,0.1,coarse\n\
                    0.25,64,2.5e-7,\"says \"\"fine\"\", really\"\n\
                    -1,-3,1e-300,\n";
    assert_eq!(std::fs::read_to_string(&path).unwrap(), expected);
    assert_eq!(t.n_rows(), 3);
    // Every float reads back exactly.
    let third_row = expected.lines().nth(3).unwrap();
    assert_eq!(
        third_row.split(',').nth(2).unwrap().parse::<f64>().unwrap(),
        1e-300
    );
}

#[test]
fn csv_refuses_nan_naming_column_and_row() {
    let mut t = CsvTable::new(&["step", "residual"]).unwrap();
    t.push_row(&[0_usize.into(), 1.0.into()]).unwrap();
    let err = t.push_row(&[1_usize.into(), f64::NAN.into()]).unwrap_err();
    match &err {
        OutputError::NonFinite {
            array,
            index,
            value,
        } => {
            assert_eq!((array.as_str(), *index), ("residual", 1));
            assert!(value.is_nan());
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    assert_eq!(t.n_rows(), 1, "the bad row is not kept");
    assert!(!t.to_csv().contains("NaN"));
}

#[test]
fn csv_refuses_bad_shapes_and_names() {
    let mut t = CsvTable::new(&["a", "b"]).unwrap();
    let err = t.push_row(&[1.0.into()]).unwrap_err();
    assert!(
        matches!(&err, OutputError::LengthMismatch { array, expected: 2, found: 1 } if array == "row 0"),
        "{err:?}"
    );
    let none: [&str; 0] = [];
    assert!(matches!(
        CsvTable::new(&none),
        Err(OutputError::InvalidName { .. })
    ));
    assert!(matches!(
        CsvTable::new(&["a", ""]),
        Err(OutputError::InvalidName { .. })
    ));
    assert!(
        matches!(CsvTable::new(&["a", "a"]), Err(OutputError::InvalidName { name, .. }) if name == "a")
    );
}

// ---------------------------------------------------------------- summary

#[derive(Serialize)]
struct Level {
    h: f64,
    error: f64,
}

#[derive(Serialize)]
struct Summary {
    case: String,
    converged: bool,
    newton_iterations: Vec<u32>,
    levels: Vec<Level>,
    rate: Option<f64>,
}

fn summary() -> Summary {
    Summary {
        case: "cantilever".to_owned(),
        converged: true,
        newton_iterations: vec![4, 5, 4],
        levels: vec![
            Level {
                h: 0.5,
                error: 1e-2,
            },
            Level {
                h: 0.25,
                error: 2.5e-3,
            },
        ],
        rate: None,
    }
}

#[test]
fn summary_json_round_trips() {
    let dir = fresh_dir("summary");
    let path = dir.join("summary.json");
    write_summary(&path, &summary()).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.ends_with("}\n"));
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["case"], "cantilever");
    assert_eq!(v["converged"], true);
    assert_eq!(v["newton_iterations"], serde_json::json!([4, 5, 4]));
    assert_eq!(v["levels"][1]["error"].as_f64(), Some(2.5e-3));
    assert!(v["rate"].is_null(), "None is a legitimate null");
    assert_eq!(dir_entries(&dir), vec!["summary.json".to_owned()]);
}

#[test]
fn summary_with_nan_is_refused_and_old_file_kept() {
    let dir = fresh_dir("summary_nan");
    let path = dir.join("summary.json");
    write_summary(&path, &summary()).unwrap();
    let before = std::fs::read(&path).unwrap();

    let mut bad = summary();
    bad.levels[1].error = f64::NAN;
    let err = write_summary(&path, &bad).unwrap_err();
    assert!(
        matches!(&err, OutputError::NonFiniteField { field, .. } if field == "levels[1].error"),
        "{err:?}"
    );
    let mut bad = summary();
    bad.rate = Some(f64::INFINITY);
    let err = write_summary(&path, &bad).unwrap_err();
    assert_eq!(err.to_string(), "field `rate` has the non-finite value inf");
    assert_eq!(std::fs::read(&path).unwrap(), before);
}
