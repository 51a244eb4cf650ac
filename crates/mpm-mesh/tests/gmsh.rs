//! The Gmsh MSH 4.1 ASCII reader: the committed Gmsh meshes (sets, tags,
//! areas and volumes), and every malformed-input error with the line where
//! it is found.
#![allow(missing_docs, clippy::unwrap_used)]

use super::common;

use common::*;
use mpm_mesh::{GmshElements, GmshMesh, MeshError, parse_msh, read_msh};

/// Two counter-clockwise triangles of the unit square, sparse node tags
/// 10..40, a physical curve "bottom" (the edge y = 0) and a physical
/// surface "square". Line numbers are 1-based, as in the errors.
const SQUARE: [&str; 34] = [
    "$MeshFormat",          // 1
    "4.1 0 8",              // 2
    "$EndMeshFormat",       // 3
    "$PhysicalNames",       // 4
    "2",                    // 5
    "1 10 \"bottom\"",      // 6
    "2 20 \"square\"",      // 7
    "$EndPhysicalNames",    // 8
    "$Entities",            // 9
    "0 1 1 0",              // 10
    "1 0 0 0 1 0 0 1 10 0", // 11
    "1 0 0 0 1 1 0 1 20 0", // 12
    "$EndEntities",         // 13
    "$Nodes",               // 14
    "2 4 10 40",            // 15
    "1 1 0 2",              // 16
    "10",                   // 17
    "20",                   // 18
    "0 0 0",                // 19
    "1 0 0",                // 20
    "2 1 0 2",              // 21
    "30",                   // 22
    "40",                   // 23
    "1 1 0",                // 24
    "0 1 0",                // 25
    "$EndNodes",            // 26
    "$Elements",            // 27
    "2 3 1 3",              // 28
    "1 1 1 1",              // 29
    "1 10 20",              // 30
    "2 1 2 2",              // 31
    "2 10 20 30",           // 32
    "3 10 30 40",           // 33
    "$EndElements",         // 34
];

fn text(lines: &[&str]) -> Vec<u8> {
    let mut s = lines.join("\n");
    s.push('\n');
    s.into_bytes()
}

/// The square with line `line` (1-based) replaced by `by`.
fn with(line: usize, by: &str) -> Vec<u8> {
    let mut lines = SQUARE.to_vec();
    lines[line - 1] = by;
    text(&lines)
}

fn linear<const D: usize>(mesh: GmshMesh<D>) -> mpm_mesh::SimplexMesh<D> {
    match mesh.elements {
        GmshElements::Linear(m) => m,
        GmshElements::Quadratic(_) => panic!("expected a linear mesh"),
    }
}

#[test]
fn small_file_with_sparse_tags_and_groups() {
    let read = parse_msh::<2>(&text(&SQUARE)).unwrap();
    assert_eq!(read.node_tags, vec![10, 20, 30, 40]);
    assert_eq!(read.element_tags, vec![2, 3]);
    let mesh = linear(read);
    assert_eq!(mesh.connectivity(), &[0, 1, 2, 0, 2, 3]);
    assert!((mesh.total_volume() - 1.0).abs() < 1e-15);
    assert_eq!(mesh.node_sets().get("bottom"), Some(&[0, 1][..]));
    assert_eq!(mesh.node_sets().get("square"), Some(&[0, 1, 2, 3][..]));
    assert_eq!(mesh.element_sets().get("square"), Some(&[0, 1][..]));
    assert_eq!(mesh.element_sets().get("bottom"), None);
    // Windows line ends, blank lines and an unknown section are fine.
    let mut lines = SQUARE.to_vec();
    lines.insert(3, "$Comments");
    lines.insert(4, "anything $at all");
    lines.insert(5, "$EndComments");
    lines.insert(6, "");
    let crlf = lines.join("\r\n").into_bytes();
    assert_eq!(
        parse_msh::<2>(&crlf).unwrap(),
        parse_msh::<2>(&text(&SQUARE)).unwrap()
    );
}

#[test]
fn clockwise_elements_are_reoriented_and_unnamed_groups_use_their_tag() {
    let mut lines = SQUARE.to_vec();
    lines[31] = "2 10 30 20"; // clockwise
    lines[4] = "1";
    lines.remove(6); // no name for the surface group 20
    let mesh = linear(parse_msh::<2>(&text(&lines)).unwrap());
    assert_eq!(mesh.element_nodes(0), &[0, 1, 2]);
    assert!(mesh.volumes().iter().all(|&v| v > 0.0));
    assert_eq!(mesh.element_sets().get("20"), Some(&[0, 1][..]));
}

/// Every malformed input gives its typed error with the line number.
#[test]
fn malformed_files_name_the_line() {
    let cases: Vec<(Vec<u8>, MeshError)> = vec![
        (
            Vec::new(),
            MeshError::GmshFormat {
                line: 1,
                found: "an empty file".into(),
            },
        ),
        (
            with(1, "$Nodes"),
            MeshError::GmshFormat {
                line: 1,
                found: "$Nodes".into(),
            },
        ),
        (
            with(2, "2.2 0 8"),
            MeshError::GmshFormat {
                line: 2,
                found: "2.2 0 8".into(),
            },
        ),
        (with(2, "4.1 1 8"), MeshError::GmshBinary { line: 2 }),
        (
            with(2, "4.1 0"),
            MeshError::GmshSyntax {
                line: 2,
                expected: "the data size",
                found: "4.1 0".into(),
            },
        ),
        (
            // Truncated at the end of the file, inside $Nodes.
            text(&SQUARE[..20]),
            MeshError::GmshTruncated {
                line: 21,
                section: "Nodes".into(),
            },
        ),
        (
            // The second block claims three nodes: its third tag line is
            // the coordinate line 24.
            with(21, "2 1 0 3"),
            MeshError::GmshSyntax {
                line: 24,
                expected: "a node tag",
                found: "1 1 0".into(),
            },
        ),
        (
            with(15, "2 5 10 40"),
            MeshError::GmshCount {
                line: 15,
                what: "the number of nodes",
                expected: 5,
                found: 4,
            },
        ),
        (
            with(28, "2 4 1 3"),
            MeshError::GmshCount {
                line: 28,
                what: "the number of elements",
                expected: 4,
                found: 3,
            },
        ),
        (
            with(33, "3 10 30 41"),
            MeshError::GmshUnknownNode { line: 33, tag: 41 },
        ),
        (
            with(31, "2 1 3 2"),
            MeshError::GmshUnsupportedElement {
                line: 31,
                element_type: 3,
            },
        ),
        (
            with(31, "2 1 4 2"),
            MeshError::GmshUnsupportedElement {
                line: 31,
                element_type: 4,
            },
        ),
        (
            with(32, "2 10 20"),
            MeshError::GmshCount {
                line: 32,
                what: "the number of nodes of the element type",
                expected: 3,
                found: 2,
            },
        ),
        (
            with(20, "1 zero 0"),
            MeshError::GmshSyntax {
                line: 20,
                expected: "node coordinates x y z",
                found: "1 zero 0".into(),
            },
        ),
        (
            with(23, "20"),
            MeshError::GmshDuplicateNode { line: 23, tag: 20 },
        ),
        (
            with(25, "0 1 0.5"),
            MeshError::GmshNotPlanar { line: 25, z: 0.5 },
        ),
        (
            with(6, "1 10 bottom"),
            MeshError::GmshSyntax {
                line: 6,
                expected: "a quoted name",
                found: "1 10 bottom".into(),
            },
        ),
        (
            with(12, "1 0 0 0 1 1 0 1"),
            MeshError::GmshSyntax {
                line: 12,
                expected: "a physical tag",
                found: "1 0 0 0 1 1 0 1".into(),
            },
        ),
        (
            with(26, "$EndElements"),
            MeshError::GmshTruncated {
                line: 26,
                section: "Nodes".into(),
            },
        ),
        (
            with(16, "garbage"),
            MeshError::GmshSyntax {
                line: 16,
                expected: "an entity dimension",
                found: "garbage".into(),
            },
        ),
        (
            text(&SQUARE[..26]),
            MeshError::GmshMissingSection {
                line: 26,
                section: "Elements",
            },
        ),
        (
            // Only the line element: no triangles.
            text(
                &[
                    &SQUARE[..27],
                    &["1 1 1 1", "1 1 1 1", "1 10 20", "$EndElements"],
                ]
                .concat(),
            ),
            MeshError::GmshNoElements {
                line: 31,
                dimension: 2,
            },
        ),
        (
            // A six-node triangle block after the three-node one.
            text(
                &[
                    &SQUARE[..27],
                    &[
                        "2 2 1 2",
                        "2 1 2 1",
                        "2 10 20 30",
                        "2 1 9 1",
                        "3 10 30 40 10 30 40",
                    ],
                    &["$EndElements"],
                ]
                .concat(),
            ),
            MeshError::GmshMixedOrder {
                line: 31,
                element_type: 9,
            },
        ),
        (
            with(24, "garbage line"),
            MeshError::GmshSyntax {
                line: 24,
                expected: "node coordinates x y z",
                found: "garbage line".into(),
            },
        ),
        (
            with(30, "$Elements"),
            MeshError::GmshTruncated {
                line: 30,
                section: "Elements".into(),
            },
        ),
        (
            with(34, "$EndNodes"),
            MeshError::GmshTruncated {
                line: 34,
                section: "Elements".into(),
            },
        ),
        (
            with(14, "Nodes"),
            MeshError::GmshSyntax {
                line: 14,
                expected: "a section header such as $Nodes",
                found: "Nodes".into(),
            },
        ),
    ];
    for (input, expected) in cases {
        assert_eq!(parse_msh::<2>(&input), Err(expected));
    }
}

#[test]
fn invalid_elements_name_the_line_and_tag() {
    // Triangle 3 made degenerate: nodes 10, 20 and a copy of 10.
    let err = parse_msh::<2>(&with(25, "0 0 0")).unwrap_err();
    match err {
        MeshError::GmshElement { line, tag, source } => {
            assert_eq!((line, tag), (33, 3));
            assert!(matches!(
                *source,
                MeshError::DegenerateElement { element: 1, .. }
            ));
        }
        other => panic!("{other:?}"),
    }
    let err = parse_msh::<2>(&with(33, "3 10 30 10")).unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::GmshElement {
                line: 33,
                tag: 3,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .starts_with("line 33: Gmsh element 3: element 1 lists node 0 twice")
    );
}

#[test]
fn binary_and_non_text_input() {
    let mut bytes = text(&SQUARE[..3]);
    bytes.extend_from_slice(&[0xff, 0xfe, 0x00, 0x01, b'\n']);
    assert_eq!(
        parse_msh::<2>(&bytes),
        Err(MeshError::GmshSyntax {
            line: 4,
            expected: "text",
            found: "non-UTF-8 bytes".into()
        })
    );
    let mut binary = b"$MeshFormat\n4.1 1 8\n".to_vec();
    binary.extend_from_slice(&[1, 0, 0, 0, 0xff, b'\n']);
    assert_eq!(
        parse_msh::<2>(&binary),
        Err(MeshError::GmshBinary { line: 2 })
    );
}

#[test]
fn dimension_mismatch_and_io_errors() {
    assert!(matches!(
        parse_msh::<3>(&text(&SQUARE)),
        Err(MeshError::GmshNoElements { dimension: 3, .. })
    ));
    assert_eq!(
        parse_msh::<4>(&text(&SQUARE)),
        Err(MeshError::UnsupportedDimension { dimension: 4 })
    );
    let err = read_msh::<2>(data("no_such_file.msh")).unwrap_err();
    assert!(matches!(err, MeshError::GmshIo { .. }), "{err:?}");
    // The box is not planar.
    assert!(matches!(
        read_msh::<2>(data("box_tet10.msh")),
        Err(MeshError::GmshNotPlanar { .. })
    ));
}

#[test]
fn gmsh_rectangle() {
    let read = read_msh::<2>(data("rectangle_tri3.msh")).unwrap();
    assert_eq!(read.node_tags.len(), 80);
    let mesh = linear(read);
    assert_eq!(mesh.node_count(), 80);
    assert!((mesh.total_volume() - 2.0).abs() < 1e-13);
    assert_eq!(
        mesh.element_sets().get("domain").unwrap().len(),
        mesh.element_count()
    );
    for (name, axis, value) in [
        ("x0", 0, 0.0),
        ("x1", 0, 2.0),
        ("y0", 1, 0.0),
        ("y1", 1, 1.0),
    ] {
        let set = mesh.node_sets().get(name).unwrap();
        assert!(set.len() >= 6, "{name}");
        for &n in set {
            assert!((mesh.nodes()[n][axis] - value).abs() < 1e-12, "{name}");
        }
    }
}

#[test]
fn gmsh_annulus() {
    let mesh = gmsh_linear::<2>("annulus_tri3.msh");
    let exact = std::f64::consts::PI * (1.25f64.powi(2) - 0.75f64.powi(2));
    let area = mesh.total_volume();
    assert!(area < exact && area > 0.995 * exact, "{area}");
    for (name, radius) in [("inner", 0.75), ("outer", 1.25)] {
        let set = mesh.node_sets().get(name).unwrap();
        assert!(set.len() > 40);
        for &n in set {
            assert!((mesh.nodes()[n].norm() - radius).abs() < 1e-9);
        }
    }
}

#[test]
fn gmsh_quadratic_meshes() {
    let read = read_msh::<3>(data("box_tet10.msh")).unwrap();
    let GmshElements::Quadratic(parents) = read.elements else {
        panic!("tet10 file");
    };
    assert_eq!(parents.node_count(), 2144);
    assert_eq!(read.element_tags.len(), parents.element_count());
    assert_eq!(
        parents.element_sets().get("solid").unwrap().len(),
        parents.element_count()
    );
    // Face sets hold vertices and mid-edge nodes of the boundary triangles.
    for (name, axis, value) in [("x0", 0, 0.0), ("y1", 1, 1.0), ("z1", 2, 2.0)] {
        for &n in parents.node_sets().get(name).unwrap() {
            assert!((parents.nodes()[n][axis] - value).abs() < 1e-12);
        }
    }
    let read = read_msh::<2>(data("rectangle_tri6.msh")).unwrap();
    assert!(matches!(read.elements, GmshElements::Quadratic(_)));
}
