//! Scene files: TOML with positions in errors, and command-line overrides
//! that go through the same validation as the file.
#![allow(clippy::unwrap_used)]

use super::common;

use common::fresh_dir;
use mpm_cases::scene::SceneError;
use mpm_cases::scene_file::{load_scene, parse_scene};
use serde::Deserialize;

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
enum Basis {
    Mpm,
    Gimp,
    Cpdi,
}

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Material {
    #[serde(rename = "E")]
    youngs_modulus: f64,
    nu: f64,
}

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Output {
    every: u32,
}

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Scene {
    name: String,
    h: f64,
    basis: Basis,
    steps: u32,
    material: Material,
    output: Option<Output>,
}

const SCENE: &str = r#"# a toy scene
name = "cantilever"
h = 0.5
basis = "mpm"
steps = 10

[material]
E = 1e6
nu = 0.3
"#;

fn ov(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| (*s).to_owned()).collect()
}

fn parse(text: &str, overrides: &[&str]) -> Result<Scene, SceneError> {
    parse_scene(text, "scene.toml", &ov(overrides))
}

/// The (line, column, message) of a located scene error.
fn located(err: &SceneError) -> (usize, usize, &str) {
    match err {
        SceneError::Scene {
            origin,
            line,
            column,
            message,
        } => {
            assert_eq!(origin, "scene.toml");
            (*line, *column, message.as_str())
        }
        other => panic!("expected a located scene error, got {other:?}"),
    }
}

/// The (override, message) of an override error.
fn from_override(err: &SceneError) -> (&str, &str) {
    match err {
        SceneError::Override { text, message } => (text.as_str(), message.as_str()),
        other => panic!("expected an override error, got {other:?}"),
    }
}

#[test]
fn valid_scene_parses() {
    let s = parse(SCENE, &[]).unwrap();
    assert_eq!(
        s,
        Scene {
            name: "cantilever".to_owned(),
            h: 0.5,
            basis: Basis::Mpm,
            steps: 10,
            material: Material {
                youngs_modulus: 1e6,
                nu: 0.3
            },
            output: None,
        }
    );
}

#[test]
fn unknown_key_reports_file_line_and_column() {
    let text = SCENE.replace("basis = \"mpm\"", "bsis = \"mpm\"");
    let err = parse(&text, &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (4, 1));
    assert!(
        message.starts_with("unknown field `bsis`, expected one of"),
        "{message}"
    );
    assert!(
        err.to_string()
            .starts_with("scene.toml:4:1: unknown field `bsis`"),
        "{err}"
    );
}

#[test]
fn unknown_key_in_nested_table_is_located() {
    let text = SCENE.replace("nu = 0.3", "nu = 0.3\n  G = 4e5");
    let err = parse(&text, &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (10, 3));
    assert!(message.contains("unknown field `G`"), "{message}");
}

#[test]
fn wrong_type_is_located_at_the_value() {
    let text = SCENE.replace("steps = 10", "steps = \"ten\"");
    let err = parse(&text, &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (5, 9));
    assert!(
        message.contains("invalid type: string \"ten\""),
        "{message}"
    );

    let text = SCENE.replace("basis = \"mpm\"", "basis = \"fem\"");
    let err = parse(&text, &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (4, 9));
    assert!(message.contains("unknown variant `fem`"), "{message}");
}

#[test]
fn malformed_toml_is_located() {
    let text = SCENE.replace("[material]", "[material");
    let err = parse(&text, &[]).unwrap_err();
    let (line, _, message) = located(&err);
    assert_eq!(line, 7);
    assert!(!message.is_empty());

    let err = parse("h = 0.5\nh = 0.25\n", &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (2, 1), "{message}");
    assert!(message.contains("duplicate"), "{message}");
}

#[test]
fn missing_key_is_reported_and_an_override_can_supply_it() {
    let text = SCENE.replace("h = 0.5\n", "");
    let err = parse(&text, &[]).unwrap_err();
    assert_eq!(err.to_string(), "scene.toml: missing field `h`");
    assert!(matches!(err, SceneError::SceneUnlocated { .. }), "{err:?}");
    // A key missing from a table is located at the table's header.
    let err = parse(&SCENE.replace("nu = 0.3\n", ""), &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column, message), (7, 1, "missing field `nu`"));
    assert_eq!(parse(&text, &["h=0.25"]).unwrap().h, 0.25);
}

#[test]
fn override_of_a_nested_key() {
    let s = parse(SCENE, &["material.E=2.5e6"]).unwrap();
    assert_eq!(s.material.youngs_modulus, 2.5e6);
    assert_eq!(s.material.nu, 0.3, "siblings are kept");

    // Missing tables on the path are created; later overrides win.
    let s = parse(
        SCENE,
        &["output.every = 5", "material.nu=0.25", "material.nu=0.2"],
    )
    .unwrap();
    assert_eq!(s.output, Some(Output { every: 5 }));
    assert_eq!(s.material.nu, 0.2);

    // A whole table as an inline table.
    let s = parse(SCENE, &["material={ E = 3e6, nu = 0.1 }"]).unwrap();
    assert_eq!(
        s.material,
        Material {
            youngs_modulus: 3e6,
            nu: 0.1
        }
    );
}

#[test]
fn override_values_take_their_toml_type() {
    // Command-line text becomes a float, an integer, a string (bare word
    // that is not TOML) or a quoted string, as the target needs.
    let s = parse(
        SCENE,
        &["h=1.5625", "steps=200", "basis=gimp", "name=\"3\""],
    )
    .unwrap();
    assert_eq!(s.h, 1.5625);
    assert_eq!(s.steps, 200);
    assert_eq!(s.basis, Basis::Gimp);
    assert_eq!(s.name, "3");

    // A string field given a bare number is a type error, blamed on the
    // override.
    let err = parse(SCENE, &["name=3"]).unwrap_err();
    let (text, message) = from_override(&err);
    assert_eq!(text, "name=3");
    assert!(message.contains("invalid type: integer `3`"), "{message}");

    // A number field given a word.
    let err = parse(SCENE, &["h=fine"]).unwrap_err();
    let (_, message) = from_override(&err);
    assert!(
        message.contains("invalid type: string \"fine\""),
        "{message}"
    );
    assert!(err.to_string().starts_with("override `h=fine`: "), "{err}");
}

#[test]
fn override_adding_an_unknown_key_is_rejected() {
    let err = parse(SCENE, &["material.G=4e5"]).unwrap_err();
    let (text, message) = from_override(&err);
    assert_eq!(text, "material.G=4e5");
    assert!(message.contains("unknown field `G`"), "{message}");

    let err = parse(SCENE, &["h=0.25", "bsis=gimp"]).unwrap_err();
    let (text, message) = from_override(&err);
    assert_eq!(text, "bsis=gimp", "the offending override is named");
    assert!(message.contains("unknown field `bsis`"), "{message}");

    // An unknown key inside a table created by the override.
    let err = parse(SCENE, &["output.evry=5"]).unwrap_err();
    assert_eq!(from_override(&err).0, "output.evry=5");
}

#[test]
fn override_through_a_non_table_is_rejected() {
    let err = parse(SCENE, &["h.x=1"]).unwrap_err();
    let (text, message) = from_override(&err);
    assert_eq!(text, "h.x=1");
    assert_eq!(message, "`h` is a float, not a table");
}

#[test]
fn malformed_overrides_are_their_own_error() {
    for (bad, reason) in [
        ("foo", "no `=`"),
        ("=3", "empty key"),
        ("  = 3", "empty key"),
        ("material..E=1", "empty key segment"),
        (".h=1", "empty key segment"),
        ("h=", "empty value"),
    ] {
        match parse(SCENE, &[bad]) {
            Err(SceneError::MalformedOverride { text, reason: r }) => {
                assert_eq!(text, bad);
                assert!(r.starts_with(reason), "{bad}: {r}");
            }
            other => panic!("{bad}: expected MalformedOverride, got {other:?}"),
        }
    }
    let err = parse(SCENE, &["foo"]).unwrap_err();
    assert!(
        err.to_string().starts_with("malformed override `foo`"),
        "{err}"
    );
}

#[test]
fn non_finite_floats_are_refused() {
    let text = SCENE.replace("h = 0.5", "h = nan");
    let err = parse(&text, &[]).unwrap_err();
    let (line, column, message) = located(&err);
    assert_eq!((line, column), (3, 5));
    assert!(message.contains("`nan` is not finite"), "{message}");

    let text = SCENE.replace("E = 1e6", "E = 1e999");
    let err = parse(&text, &[]).unwrap_err();
    let (line, _, _) = located(&err);
    assert_eq!(line, 8, "a literal that overflows f64 is infinite too");

    let err = parse(SCENE, &["material.E=-inf"]).unwrap_err();
    assert_eq!(from_override(&err).0, "material.E=-inf");
}

#[test]
fn load_scene_reads_a_file_and_names_it_in_errors() {
    let dir = fresh_dir("scene_load");
    let path = dir.join("cantilever.toml");
    std::fs::write(&path, SCENE.replace("steps = 10", "steps = -1")).unwrap();

    let err = load_scene::<Scene>(&path, &[]).unwrap_err();
    let shown = err.to_string();
    assert!(
        shown.starts_with(&format!("{}:5:9: ", path.display())),
        "{shown}"
    );

    let s: Scene = load_scene(&path, &ov(&["steps=3"])).unwrap();
    assert_eq!(s.steps, 3);

    let missing = dir.join("missing.toml");
    assert!(matches!(
        load_scene::<Scene>(&missing, &[]),
        Err(SceneError::Io { path, .. }) if path == missing
    ));
}
