//! The `.vtu` writer, checked by reading its output back with an
//! independent XML parser.
#![allow(clippy::unwrap_used)]

use super::common;

use common::{data_array, dir_entries, element, fresh_dir, parse_xml};
use mpm_cases::output::OutputError;
use mpm_cases::output::vtk::{CellType, UnstructuredGrid, Values};

fn as_f64(v: &[i64]) -> Vec<f64> {
    v.iter().map(|&i| i as f64).collect()
}

#[test]
fn cell_type_ids_and_node_counts_match_vtk() {
    let expected = [
        (CellType::Vertex, 1, 1),
        (CellType::Triangle, 5, 3),
        (CellType::Quad, 9, 4),
        (CellType::Tetra, 10, 4),
        (CellType::Hexahedron, 12, 8),
        (CellType::QuadraticTriangle, 22, 6),
        (CellType::QuadraticTetra, 24, 10),
    ];
    for (t, id, n) in expected {
        assert_eq!((t.vtk_id(), t.n_nodes()), (id, n), "{}", t.name());
    }
}

#[test]
fn material_points_2d_round_trip_exactly() {
    let x = [[0.0, 0.0], [1.0 / 3.0, -2.5], [1e-300, 7.0e12]];
    let p = [1.0, -0.1, 12345.678];
    let v = [[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]];
    let sigma: Vec<[f64; 9]> = (0..3)
        .map(|i| std::array::from_fn(|k| (10 * i + k) as f64 + 0.5))
        .collect();
    let id = [7_i64, -1, i64::MAX];

    let mut grid = UnstructuredGrid::from_points(&x).unwrap();
    grid.add_vertex_cells();
    grid.point_data("pressure", Values::scalars(&p))
        .unwrap()
        .point_data("velocity", Values::vectors_padded(&v).unwrap())
        .unwrap()
        .point_data("stress", Values::tensors(&sigma))
        .unwrap()
        .point_data("id", Values::ints(&id))
        .unwrap();
    let doc = parse_xml(&grid.to_xml().unwrap());

    let root = element(&doc, "VTKFile");
    assert_eq!(root.attr("type"), "UnstructuredGrid");
    let piece = element(&doc, "Piece");
    assert_eq!(piece.attr("NumberOfPoints"), "3");
    assert_eq!(piece.attr("NumberOfCells"), "3");

    let points = data_array(&doc, "Points", "Points");
    assert_eq!(points.attr("NumberOfComponents"), "3");
    assert_eq!(points.attr("type"), "Float64");
    // Exact round trip, including 1/3 and a subnormal-range magnitude; z = 0.
    assert_eq!(
        points.numbers(),
        vec![0.0, 0.0, 0.0, 1.0 / 3.0, -2.5, 0.0, 1e-300, 7.0e12, 0.0]
    );

    assert_eq!(
        data_array(&doc, "Cells", "connectivity").numbers(),
        vec![0.0, 1.0, 2.0]
    );
    assert_eq!(
        data_array(&doc, "Cells", "offsets").numbers(),
        vec![1.0, 2.0, 3.0]
    );
    let types = data_array(&doc, "Cells", "types");
    assert_eq!(types.attr("type"), "UInt8");
    assert_eq!(types.numbers(), vec![1.0, 1.0, 1.0]);

    let pressure = data_array(&doc, "PointData", "pressure");
    assert_eq!(pressure.attr("NumberOfComponents"), "1");
    assert_eq!(pressure.numbers(), p.to_vec());

    let velocity = data_array(&doc, "PointData", "velocity");
    assert_eq!(velocity.attr("NumberOfComponents"), "3");
    assert_eq!(
        velocity.numbers(),
        vec![1.0, 2.0, 0.0, 3.0, 4.0, 0.0, 5.0, 6.0, 0.0]
    );

    let stress = data_array(&doc, "PointData", "stress");
    assert_eq!(stress.attr("NumberOfComponents"), "9");
    assert_eq!(stress.numbers(), sigma.as_flattened().to_vec());

    let ids = data_array(&doc, "PointData", "id");
    assert_eq!(ids.attr("type"), "Int64");
    let id_text: Vec<i64> = ids
        .text
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(id_text, id.to_vec());
}

#[test]
fn grid_cells_of_every_type_round_trip() {
    // Ten points, enough for the largest cell (quadratic tetrahedron).
    let x: Vec<[f64; 3]> = (0..10).map(|i| [i as f64, (i * i) as f64, 0.5]).collect();
    let mut grid = UnstructuredGrid::new(&x).unwrap();
    grid.add_cells(CellType::Quad, &[0, 1, 2, 3, 1, 4, 5, 2])
        .unwrap();
    grid.add_cells(CellType::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7])
        .unwrap();
    grid.add_cells(CellType::Triangle, &[0, 1, 2]).unwrap();
    grid.add_cells(CellType::Tetra, &[0, 1, 2, 3]).unwrap();
    grid.add_cells(CellType::QuadraticTriangle, &[0, 1, 2, 3, 4, 5])
        .unwrap();
    grid.add_cells(CellType::QuadraticTetra, &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9])
        .unwrap();
    assert_eq!(grid.n_cells(), 7);
    let mass = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
    let active = [1_i64, 0, 1, 0, 1, 0, 1];
    grid.cell_data("mass", Values::scalars(&mass)).unwrap();
    grid.cell_data("active", Values::ints(&active)).unwrap();

    let doc = parse_xml(&grid.to_xml().unwrap());
    let piece = element(&doc, "Piece");
    assert_eq!(piece.attr("NumberOfPoints"), "10");
    assert_eq!(piece.attr("NumberOfCells"), "7");
    assert_eq!(
        data_array(&doc, "Cells", "types").numbers(),
        as_f64(&[9, 9, 12, 5, 10, 22, 24])
    );
    assert_eq!(
        data_array(&doc, "Cells", "offsets").numbers(),
        as_f64(&[4, 8, 16, 19, 23, 29, 39])
    );
    let conn = data_array(&doc, "Cells", "connectivity").numbers();
    assert_eq!(conn.len(), 39);
    assert_eq!(&conn[..8], &as_f64(&[0, 1, 2, 3, 1, 4, 5, 2])[..]);
    assert_eq!(&conn[29..], &as_f64(&[0, 1, 2, 3, 4, 5, 6, 7, 8, 9])[..]);
    assert_eq!(
        data_array(&doc, "CellData", "mass").numbers(),
        mass.to_vec()
    );
    assert_eq!(
        data_array(&doc, "CellData", "active").numbers(),
        as_f64(&active)
    );
    // No point data was added, so there is no PointData section.
    assert!(doc.iter().all(|e| e.name != "PointData"));
}

#[test]
fn special_characters_in_names_survive() {
    let x = [[0.0; 3]];
    let s = [1.0];
    let name = r#"σ<xx> & "yy" 'zz'"#;
    let mut grid = UnstructuredGrid::new(&x).unwrap();
    grid.point_data(name, Values::scalars(&s)).unwrap();
    let doc = parse_xml(&grid.to_xml().unwrap());
    assert_eq!(data_array(&doc, "PointData", name).numbers(), vec![1.0]);
}

#[test]
fn non_finite_values_are_refused_with_array_and_index() {
    let x = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let mut grid = UnstructuredGrid::new(&x).unwrap();

    let p = [0.0, 1.0, f64::NAN];
    match grid.point_data("pressure", Values::scalars(&p)) {
        Err(OutputError::NonFinite {
            array,
            index,
            value,
        }) => {
            assert_eq!((array.as_str(), index), ("pressure", 2));
            assert!(value.is_nan());
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }

    let v = [[0.0; 3], [0.0, 0.0, f64::INFINITY], [0.0; 3]];
    let err = grid
        .point_data("velocity", Values::vectors(&v))
        .unwrap_err();
    assert!(
        matches!(&err, OutputError::NonFinite { array, index: 1, value } if array == "velocity" && *value == f64::INFINITY),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "array `velocity` has the non-finite value inf at index 1"
    );

    let bad_points = [[0.0, f64::NEG_INFINITY]];
    let err = UnstructuredGrid::from_points(&bad_points).unwrap_err();
    assert!(
        matches!(&err, OutputError::NonFinite { array, index: 0, .. } if array == "Points"),
        "{err:?}"
    );

    let c = [f64::NAN];
    let err = grid.cell_data("mass", Values::scalars(&c)).unwrap_err();
    assert!(
        matches!(&err, OutputError::NonFinite { array, index: 0, .. } if array == "mass"),
        "{err:?}"
    );

    // Nothing was attached by the failed calls.
    let doc = parse_xml(&grid.to_xml().unwrap());
    assert!(
        doc.iter()
            .all(|e| e.name != "PointData" && e.name != "CellData")
    );
}

#[test]
fn inconsistent_lengths_are_refused() {
    let x = [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let mut grid = UnstructuredGrid::new(&x).unwrap();

    let short = [1.0, 2.0];
    let err = grid.point_data("p", Values::scalars(&short)).unwrap_err();
    assert!(
        matches!(&err, OutputError::LengthMismatch { array, expected: 4, found: 2 } if array == "p"),
        "{err:?}"
    );

    // Flat data that is not a whole number of tuples.
    let ragged = Values::Float64 {
        data: vec![1.0; 7].into(),
        components: 3,
    };
    let err = grid.point_data("v", ragged).unwrap_err();
    assert!(
        matches!(&err, OutputError::LengthMismatch { found: 7, .. }),
        "{err:?}"
    );

    let empty: [[f64; 0]; 4] = [[]; 4];
    let err = grid
        .point_data("e", Values::components(&empty))
        .unwrap_err();
    assert!(
        matches!(&err, OutputError::ZeroComponents { array } if array == "e"),
        "{err:?}"
    );

    let err = grid.add_cells(CellType::Quad, &[0, 1, 2]).unwrap_err();
    assert!(
        matches!(
            err,
            OutputError::CellNodeCount {
                cell_type: "VTK_QUAD",
                expected: 4,
                found: 3
            }
        ),
        "{err:?}"
    );
    grid.add_cells(CellType::Triangle, &[0, 1, 2]).unwrap();
    let err = grid
        .add_cells(CellType::Triangle, &[0, 1, 2, 0, 2, 4])
        .unwrap_err();
    assert!(
        matches!(
            err,
            OutputError::NodeOutOfRange {
                cell: 2,
                node: 4,
                n_points: 4
            }
        ),
        "{err:?}"
    );
    assert_eq!(grid.n_cells(), 1, "a rejected batch adds no cells");

    let p = [1.0, 2.0, 3.0, 4.0];
    grid.point_data("p", Values::scalars(&p)).unwrap();
    let err = grid.point_data("p", Values::scalars(&p)).unwrap_err();
    assert!(
        matches!(&err, OutputError::InvalidName { name, .. } if name == "p"),
        "{err:?}"
    );
    let err = grid.point_data(" ", Values::scalars(&p)).unwrap_err();
    assert!(matches!(&err, OutputError::InvalidName { .. }), "{err:?}");

    // Cell data are checked against the cells when the grid is written.
    let two = [1.0, 2.0];
    grid.cell_data("c", Values::scalars(&two)).unwrap();
    let err = grid.validate().unwrap_err();
    assert!(
        matches!(&err, OutputError::LengthMismatch { array, expected: 1, found: 2 } if array == "c"),
        "{err:?}"
    );
    let dir = fresh_dir("vtk_length_mismatch");
    let path = dir.join("grid.vtu");
    assert!(grid.write(&path).is_err());
    assert!(
        dir_entries(&dir).is_empty(),
        "an invalid grid writes no file"
    );

    let four_d = [[0.0; 4]];
    let err = UnstructuredGrid::from_points(&four_d).unwrap_err();
    assert!(
        matches!(err, OutputError::InvalidDimension { dim: 4 }),
        "{err:?}"
    );
    assert!(Values::vectors_padded(&[[0.0; 0]]).is_err());
}

#[test]
fn write_replaces_the_file_atomically() {
    let dir = fresh_dir("vtk_write");
    let path = dir.join("points_0001.vtu");

    let x1 = [[0.0; 3]];
    let mut g1 = UnstructuredGrid::new(&x1).unwrap();
    g1.add_vertex_cells();
    g1.write(&path).unwrap();

    let x2 = [[0.0; 3], [1.0, 2.0, 3.0]];
    let mut g2 = UnstructuredGrid::new(&x2).unwrap();
    g2.add_vertex_cells();
    g2.write(&path).unwrap();

    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text, g2.to_xml().unwrap());
    assert_eq!(
        element(&parse_xml(&text), "Piece").attr("NumberOfPoints"),
        "2"
    );
    assert_eq!(
        dir_entries(&dir),
        vec!["points_0001.vtu".to_owned()],
        "no temporary files left"
    );
}

#[test]
fn empty_grid_is_well_formed() {
    let x: [[f64; 3]; 0] = [];
    let grid = UnstructuredGrid::new(&x).unwrap();
    let doc = parse_xml(&grid.to_xml().unwrap());
    let piece = element(&doc, "Piece");
    assert_eq!(
        (piece.attr("NumberOfPoints"), piece.attr("NumberOfCells")),
        ("0", "0")
    );
    assert!(data_array(&doc, "Points", "Points").numbers().is_empty());
}

/// The parallel master of pieces (`.pvtu`): read back with the XML
/// parser, it declares every point and cell data array of the grid with
/// its type and number of components, the points, and each piece by its
/// file, in order — what VTK's `vtkXMLPUnstructuredGridReader` needs to
/// open the pieces as one dataset.
#[test]
fn parallel_master_declares_the_arrays_and_names_the_pieces() {
    let x = [[0.0, 0.0], [1.0, 2.0]];
    let v = [[1.0, 2.0, 0.0], [3.0, 4.0, 0.0]];
    let sigma = [[0.5; 9], [1.5; 9]];
    let id = [3_i64, 4];
    let mut grid = UnstructuredGrid::from_points(&x).unwrap();
    grid.add_vertex_cells();
    grid.point_data("velocity", Values::vectors(&v)).unwrap();
    grid.point_data("cauchy_stress", Values::tensors(&sigma))
        .unwrap();
    grid.point_data("id & rank", Values::ints(&id)).unwrap();
    let dir = fresh_dir("pvtu");
    let path = dir.join("points_0003.pvtu");
    let pieces = [
        "points_0003_0.vtu".to_owned(),
        "points_0003_1.vtu".to_owned(),
    ];
    grid.write_parallel(&path, &pieces).unwrap();
    let doc = parse_xml(&std::fs::read_to_string(&path).unwrap());
    assert_eq!(element(&doc, "VTKFile").attr("type"), "PUnstructuredGrid");
    let declared: Vec<(&str, &str, &str, &str)> = doc
        .iter()
        .filter(|e| e.name == "PDataArray")
        .map(|e| {
            (
                e.parent(),
                e.attr("Name"),
                e.attr("type"),
                e.attr("NumberOfComponents"),
            )
        })
        .collect();
    assert_eq!(
        declared,
        [
            ("PPointData", "velocity", "Float64", "3"),
            ("PPointData", "cauchy_stress", "Float64", "9"),
            ("PPointData", "id & rank", "Int64", "1"),
            ("PPoints", "Points", "Float64", "3"),
        ]
    );
    let sources: Vec<&str> = doc
        .iter()
        .filter(|e| e.name == "Piece")
        .map(|e| e.attr("Source"))
        .collect();
    assert_eq!(sources, pieces);
}
