//! Every case is expressible as a scene file: its typed scene, written
//! with `toml::to_string` and parsed again, is the same scene, for every
//! variant the case accepts. And a case's scene has no file, so its errors
//! name the case's scene without a line and column.

use mpm_solver::SolverError;

use super::{annulus, cantilever, collapse, column, shear, stretch};
use crate::scene::Scene;
use crate::variant::{
    BasisKind, DomainUpdateKind, FormulationKind, GimpVolumeKind, LockingKind, Variant,
};

/// Every combination of the variant's five names (5 × 2 × 4 × 9 × 2).
fn every_variant() -> Vec<Variant> {
    let mut all = Vec::new();
    for &basis in BasisKind::ALL {
        for &formulation in FormulationKind::ALL {
            for &locking in LockingKind::ALL {
                for &domain_update in DomainUpdateKind::ALL {
                    for &gimp_volume in GimpVolumeKind::ALL {
                        all.push(Variant {
                            basis,
                            formulation,
                            locking,
                            domain_update,
                            gimp_volume,
                        });
                    }
                }
            }
        }
    }
    all
}

/// Writes and reads back the scene of `p` with every variant `scene`
/// accepts; returns how many it accepted.
fn round_trips<P>(
    case: &str,
    p: &P,
    scene: fn(&P, &Variant) -> Result<Scene, SolverError>,
) -> usize {
    let mut accepted = 0;
    for v in every_variant() {
        let Ok(typed) = scene(p, &v) else { continue };
        let text = toml::to_string(&typed).unwrap_or_else(|e| panic!("{case} {v:?}: {e}"));
        let (parsed, _) = crate::scene::parse(&text, case, &[])
            .unwrap_or_else(|e| panic!("{case} {v:?}: {e}\n{text}"));
        assert_eq!(parsed, typed, "{case} {v:?}\n{text}");
        accepted += 1;
    }
    accepted
}

#[test]
fn every_case_round_trips_through_a_scene_file() {
    let accepted = [
        round_trips("column", &column::ColumnParams::default(), column::scene),
        round_trips("shear", &shear::ShearParams::default(), shear::scene),
        round_trips(
            "cantilever",
            &cantilever::CantileverParams::default(),
            cantilever::scene,
        ),
        round_trips(
            "collapse",
            &collapse::CollapseParams::default(),
            collapse::scene,
        ),
        round_trips(
            "annulus",
            &annulus::AnnulusParams::default(),
            annulus::scene,
        ),
        round_trips(
            "stretch",
            &stretch::StretchParams::default(),
            stretch::scene,
        ),
    ];
    // The grid cases write every variant (the build refuses those that do
    // not run); the annulus standard MPM (UL, PC), the stretch also F-patch.
    assert_eq!(accepted, [720, 720, 720, 720, 2, 4]);
    // The keys only some parameters write.
    let plastic = column::ColumnParams {
        yield_stress: Some(3e4),
        hardening: 1e5,
        material: crate::material::MaterialModel::VonMises,
        ..Default::default()
    };
    assert_eq!(round_trips("column", &plastic, column::scene), 720);
    let gmsh = stretch::StretchParams {
        mesh: Some("meshes/cube \"quoted\".msh".into()),
        clamped_top: true,
        ..Default::default()
    };
    assert_eq!(round_trips("stretch", &gmsh, stretch::scene), 4);
    let jitter = annulus::AnnulusParams {
        jitter: 0.1,
        ..Default::default()
    };
    assert_eq!(round_trips("annulus", &jitter, annulus::scene), 2);
}

/// A case's parameters the scene refuses: the message names the case's
/// scene, with no line and column of a file that does not exist.
#[test]
fn a_case_scene_error_names_the_case_not_a_line() {
    let p = column::ColumnParams {
        youngs_modulus: -5.0,
        ..Default::default()
    };
    let e = <column::ColumnCase as super::Solve<2>>::build(&p, &p.variant())
        .map(|_| ())
        .expect_err("a negative modulus is refused");
    let message = e.to_string();
    let rest = message
        .strip_prefix("invalid input: case column: the column case's scene: ")
        .unwrap_or_else(|| panic!("{message}"));
    assert!(rest.contains("Young's modulus"), "{message}");
    assert!(!rest.starts_with(|c: char| c.is_ascii_digit()), "{message}");
}
