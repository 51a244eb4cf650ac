//! Optional check of the `.vtu`/`.pvd` output with VTK's own reader (the
//! one ParaView uses), through the Python `vtk` package.
//!
//! Ignored by default so CI does not depend on Python packages. Run it with
//! `cargo test -p mpm-cases --release --test suite vtk_python -- --ignored`, with
//! `MPM_VTK_PYTHON` naming a Python that has `vtk` installed (default
//! `python3`).
#![allow(clippy::unwrap_used)]

use super::common;

use std::path::Path;
use std::process::Command;

use common::fresh_dir;
use mpm_cases::output::{CellType, PvdSeries, UnstructuredGrid, Values, write_summary};
use serde_json::json;

#[test]
#[ignore = "needs a Python with the vtk package (MPM_VTK_PYTHON)"]
fn vtk_reads_our_files() {
    let dir = fresh_dir("vtk_python");

    // Material points in 2D with every kind of array.
    let x = [[0.0, 0.0], [0.5, 0.25], [1.0 / 3.0, 1e-300]];
    let p = [1.0, -2.0, 0.1];
    let v = [[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]];
    let sigma: Vec<[f64; 9]> = (0..3)
        .map(|i| std::array::from_fn(|k| (10 * i + k) as f64))
        .collect();
    let id = [3_i64, 1, 2];
    let mut points = UnstructuredGrid::from_points(&x).unwrap();
    points.add_vertex_cells();
    points
        .point_data("p", Values::scalars(&p))
        .unwrap()
        .point_data("v", Values::vectors_padded(&v).unwrap())
        .unwrap()
        .point_data("sigma", Values::tensors(&sigma))
        .unwrap()
        .point_data("id", Values::ints(&id))
        .unwrap();

    // One cell of every supported type on ten points.
    let y: Vec<[f64; 3]> = (0..10)
        .map(|i| [f64::from(i), f64::from(i * i), f64::from(i % 3)])
        .collect();
    let mut grid = UnstructuredGrid::new(&y).unwrap();
    let cells: [(CellType, &[usize]); 7] = [
        (CellType::Vertex, &[9]),
        (CellType::Triangle, &[0, 1, 2]),
        (CellType::Quad, &[0, 1, 2, 3]),
        (CellType::Tetra, &[0, 1, 2, 3]),
        (CellType::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]),
        (CellType::QuadraticTriangle, &[0, 1, 2, 3, 4, 5]),
        (CellType::QuadraticTetra, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]),
    ];
    for (t, nodes) in cells {
        grid.add_cells(t, nodes).unwrap();
    }
    let mass = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
    grid.cell_data("mass", Values::scalars(&mass)).unwrap();

    points.write(&dir.join("points_0000.vtu")).unwrap();
    grid.write(&dir.join("grid.vtu")).unwrap();
    let mut series = PvdSeries::new(dir.join("points.pvd"));
    series.push(0.0, &dir.join("points_0000.vtu")).unwrap();
    points.write(&dir.join("points_0001.vtu")).unwrap();
    series.push(0.5, &dir.join("points_0001.vtu")).unwrap();

    let padded: Vec<f64> = x.iter().flat_map(|q| [q[0], q[1], 0.0]).collect();
    let v3: Vec<f64> = v.iter().flat_map(|q| [q[0], q[1], 0.0]).collect();
    let manifest = json!({
        "grids": {
            "points_0000.vtu": {
                "n_points": 3, "n_cells": 3, "cell_types": [1, 1, 1], "cell_sizes": [1, 1, 1],
                "points": padded,
                "point_data": {
                    "p": [1, p], "v": [3, v3], "sigma": [9, sigma.as_flattened()], "id": [1, id],
                },
                "cell_data": {},
            },
            "grid.vtu": {
                "n_points": 10, "n_cells": 7,
                "cell_types": cells.iter().map(|(t, _)| t.vtk_id()).collect::<Vec<_>>(),
                "cell_sizes": cells.iter().map(|(t, _)| t.n_nodes()).collect::<Vec<_>>(),
                "points": y.as_flattened(),
                "point_data": {},
                "cell_data": { "mass": [1, mass] },
            },
        },
        "pvd": "points.pvd",
        "pvd_times": [0.0, 0.5],
    });
    write_summary(&dir.join("expected.json"), &manifest).unwrap();

    let python = std::env::var("MPM_VTK_PYTHON").unwrap_or_else(|_| "python3".to_owned());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/check_vtk.py");
    let out = Command::new(&python)
        .arg(&script)
        .arg(&dir)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {python}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "VTK check failed:\n{stdout}\n{stderr}"
    );
    assert_eq!(stdout.matches("ok ").count(), 3, "{stdout}");
}
