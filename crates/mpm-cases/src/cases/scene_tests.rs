//! The cases' typed scenes are the scenes of their old text: for every
//! variant and several parameter sets, `scene(p, v)` equals the parse of
//! `scene_text(p, v)`, and both refuse the same parameters with the same
//! words.

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

/// How many variants both accepted (with equal scenes) and both refused.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Count {
    matched: usize,
    refused: usize,
}

/// Compares `typed` with the parse of `text` for `p` and every variant.
fn compare<P>(
    case: &str,
    p: &P,
    text: fn(&P, &Variant) -> Result<String, SolverError>,
    typed: fn(&P, &Variant) -> Result<Scene, SolverError>,
) -> Count {
    let mut count = Count::default();
    for v in every_variant() {
        match (text(p, &v), typed(p, &v)) {
            (Ok(text), Ok(scene)) => {
                let (parsed, _) = crate::scene::parse(&text, case, &[])
                    .unwrap_or_else(|e| panic!("{case} {v:?}: {e}\n{text}"));
                assert_eq!(scene, parsed, "{case} {v:?}\n{text}");
                count.matched += 1;
            }
            (Err(a), Err(b)) => {
                assert_eq!(a.to_string(), b.to_string(), "{case} {v:?}");
                count.refused += 1;
            }
            (a, b) => panic!(
                "{case} {v:?}: the text gives {:?}, the typed scene {:?}",
                a.map(|_| "a scene"),
                b.map(|_| "a scene")
            ),
        }
    }
    count
}

#[test]
fn every_case_and_variant_gives_the_scene_of_its_text() {
    let mut total = Count::default();
    let mut add = |case: &str, params: &str, c: Count| {
        eprintln!(
            "{case} ({params}): {} variants equal, {} refused by both",
            c.matched, c.refused
        );
        total.matched += c.matched;
        total.refused += c.refused;
    };
    add(
        "column",
        "defaults",
        compare(
            "column",
            &column::ColumnParams::default(),
            column::scene_text,
            column::scene,
        ),
    );
    add(
        "shear",
        "defaults",
        compare(
            "shear",
            &shear::ShearParams::default(),
            shear::scene_text,
            shear::scene,
        ),
    );
    add(
        "cantilever",
        "defaults",
        compare(
            "cantilever",
            &cantilever::CantileverParams::default(),
            cantilever::scene_text,
            cantilever::scene,
        ),
    );
    add(
        "annulus",
        "defaults",
        compare(
            "annulus",
            &annulus::AnnulusParams::default(),
            annulus::scene_text,
            annulus::scene,
        ),
    );
    add(
        "collapse",
        "defaults",
        compare(
            "collapse",
            &collapse::CollapseParams::default(),
            collapse::scene_text,
            collapse::scene,
        ),
    );
    add(
        "stretch",
        "defaults",
        compare(
            "stretch",
            &stretch::StretchParams::default(),
            stretch::scene_text,
            stretch::scene,
        ),
    );
    eprintln!(
        "defaults, all cases: {} (case, variant) pairs equal, {} refused by both",
        total.matched, total.refused
    );
    // Every variant of the grid cases; the simplex cases' own.
    assert_eq!(total.matched, 4 * 720 + 2 + 4, "{total:?}");
}

/// The keys that only some parameters write: plasticity, a negative
/// shear, a clamped top, Gmsh files, jitter; and parameters refused.
#[test]
fn other_parameters_give_the_scene_of_their_text() {
    let column = column::ColumnParams {
        yield_stress: Some(3e4),
        hardening: 1e5,
        material: crate::material::MaterialModel::VonMises,
        ..Default::default()
    };
    let elastic_hardening = column::ColumnParams {
        hardening: 1e5,
        ..Default::default()
    };
    let bad_column = column::ColumnParams {
        h: 3.0,
        ..Default::default()
    };
    for p in [column, elastic_hardening, bad_column] {
        compare("column", &p, column::scene_text, column::scene);
    }
    for p in [
        shear::ShearParams {
            yield_stress: Some(5e3),
            shear: -2.0,
            predictor: false,
            ..Default::default()
        },
        shear::ShearParams {
            h: 0.3,
            ..Default::default()
        },
        shear::ShearParams {
            grid_offset: 1.5,
            ..Default::default()
        },
    ] {
        compare("shear", &p, shear::scene_text, shear::scene);
    }
    for p in [
        stretch::StretchParams {
            clamped_top: true,
            hardening: 10.0,
            cells: 4,
            ..Default::default()
        },
        stretch::StretchParams {
            mesh: Some("meshes/cube \"quoted\".msh".into()),
            ..Default::default()
        },
    ] {
        compare("stretch", &p, stretch::scene_text, stretch::scene);
    }
    for p in [
        annulus::AnnulusParams {
            jitter: 0.1,
            h: 0.0625,
            ..Default::default()
        },
        annulus::AnnulusParams {
            mesh: Some("meshes/annulus.msh".into()),
            ..Default::default()
        },
        annulus::AnnulusParams {
            h: -1.0,
            ..Default::default()
        },
    ] {
        compare("annulus", &p, annulus::scene_text, annulus::scene);
    }
    for p in [
        collapse::CollapseParams {
            h: 0.5,
            points_per_cell: 2,
            ..Default::default()
        },
        collapse::CollapseParams {
            h: 3.0,
            ..Default::default()
        },
    ] {
        compare("collapse", &p, collapse::scene_text, collapse::scene);
    }
    for p in [
        cantilever::CantileverParams {
            h: 0.25,
            points_per_cell: 2,
            ..Default::default()
        },
        cantilever::CantileverParams {
            points_per_cell: 3,
            ..Default::default()
        },
    ] {
        compare("cantilever", &p, cantilever::scene_text, cantilever::scene);
    }
}
