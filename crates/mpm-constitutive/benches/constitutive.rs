//! Cost of one material point's constitutive update, with and without each
//! formulation's consistent tangent.
//!
//! Run: `cargo bench -p mpm-constitutive --bench constitutive`. The numbers
//! are recorded in `docs/src/benchmarks/constitutive.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mpm_constitutive::{
    ConsistentTangent, DruckerPrager, HenckyElastic, LogStrainLaw, Matching, MaterialState,
    ModifiedCamClay, ModifiedCamClayHistory, MohrCoulomb, PreviouslyConvergedTangent, Regime,
    SpatialTangent, SymSpectral, VonMises, VonMisesHistory, update,
};
use nalgebra::{Matrix3, Rotation3};

fn inputs() -> (Matrix3<f64>, Matrix3<f64>) {
    let r = Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
    let df = r * Matrix3::new(1.08, 0.05, 0.0, 0.02, 0.95, 0.01, 0.0, -0.03, 1.01);
    let f_n = Matrix3::new(1.02, 0.1, 0.0, 0.0, 0.97, 0.0, 0.0, 0.0, 1.0);
    (df, f_n)
}

fn bench_law<L: LogStrainLaw>(
    c: &mut Criterion,
    name: &str,
    law: &L,
    state: MaterialState<L::History>,
) {
    let (df, f_n) = inputs();
    bench_law_at(c, name, law, state, df, f_n);
}

fn bench_law_at<L: LogStrainLaw>(
    c: &mut Criterion,
    name: &str,
    law: &L,
    state: MaterialState<L::History>,
    df: Matrix3<f64>,
    f_n: Matrix3<f64>,
) {
    let mut g = c.benchmark_group(name);
    g.bench_function("stress", |b| {
        b.iter(|| update(law, black_box(&df), black_box(&f_n), black_box(&state)).unwrap())
    });
    g.bench_function("stress+pc_tangent", |b| {
        b.iter(|| {
            let r = update(law, black_box(&df), black_box(&f_n), black_box(&state)).unwrap();
            (
                r.p_tilde(),
                PreviouslyConvergedTangent::tangent(law, &r).unwrap(),
            )
        })
    });
    g.bench_function("stress+ul_tangent", |b| {
        b.iter(|| {
            let r = update(law, black_box(&df), black_box(&f_n), black_box(&state)).unwrap();
            (r.sigma, SpatialTangent::tangent(law, &r).unwrap())
        })
    });
    g.finish();
}

fn constitutive(c: &mut Criterion) {
    let (df, f_n) = inputs();
    let be_n = f_n * f_n.transpose();
    let hencky = HenckyElastic::new(1e6, 0.3).unwrap();
    bench_law(
        c,
        "hencky",
        &hencky,
        MaterialState {
            be: be_n,
            history: (),
        },
    );
    let neo_hookean = mpm_constitutive::NeoHookean::new(1e6, 0.3).unwrap();
    bench_law(
        c,
        "neo_hookean",
        &neo_hookean,
        MaterialState {
            be: be_n,
            history: (),
        },
    );
    let elastic_vm = VonMises::new(1e6, 0.3, 1e9, 0.0).unwrap();
    bench_law(
        c,
        "von_mises_elastic_step",
        &elastic_vm,
        MaterialState {
            be: be_n,
            history: VonMisesHistory::default(),
        },
    );
    let plastic_vm = VonMises::new(1e6, 0.3, 1e3, 1e4).unwrap();
    let check = update(
        &plastic_vm,
        &df,
        &f_n,
        &MaterialState {
            be: be_n,
            history: VonMisesHistory::default(),
        },
    )
    .unwrap();
    assert!(check.yielded(), "the plastic benchmark must yield");
    bench_law(
        c,
        "von_mises_plastic_step",
        &plastic_vm,
        MaterialState {
            be: be_n,
            history: VonMisesHistory::default(),
        },
    );

    soil(c);

    let b = df * be_n * df.transpose();
    let mut g = c.benchmark_group("kinematics");
    g.bench_function("sym_eigen", |bch| {
        bch.iter(|| SymSpectral::new(black_box(&b)).unwrap())
    });
    let s = SymSpectral::new(&b).unwrap();
    g.bench_function("dlog", |bch| bch.iter(|| black_box(&s).dlog().unwrap()));
    g.finish();
}

/// The soil laws, each regime reached from a prestressed state: $b^e_n =
/// \exp 2\varepsilon$ with $\varepsilon$ the elastic strain of principal
/// stresses `sigma` (kPa, E = 10 MPa, ν = 0.3) and a rotation as $\Delta
/// F$, so the trial stress is `sigma` in a rotated frame (c = 10 kPa,
/// φ = 30°, ψ = 10°, hardening). Modified Cam-Clay (λ̂ = 0.2, κ̂ = 0.05,
/// M = 1.2, G = 1 MPa, p_r = 1 kPa) from its own elastic strain of
/// `sigma`, on the wet and the dry side.
fn soil(c: &mut Criterion) {
    let (e, nu) = (1e7, 0.3);
    let strain = |t: [f64; 3]| {
        let tr: f64 = t.iter().sum();
        Matrix3::from_diagonal(&nalgebra::Vector3::from(
            t.map(|s| ((1.0 + nu) * s - nu * tr) * 1e3 / e),
        ))
    };
    let r = Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
    let f_n = Matrix3::identity();
    let mc = MohrCoulomb::new(e, nu, 1e4, 30.0, 10.0, 0.05 * e).unwrap();
    let dp = DruckerPrager::new(e, nu, (1e4, 30.0, 10.0), 0.05 * e, Matching::Outer).unwrap();
    let cases = [
        ("plane", Regime::Plane, [-50.0, -120.0, -400.0]),
        ("edge", Regime::CompressionEdge, [-100.0, -100.0, -500.0]),
        ("apex", Regime::Apex, [60.0, 50.0, 40.0]),
    ];
    for (name, regime, sigma) in cases {
        let be = SymSpectral::new(&(2.0 * strain(sigma))).unwrap().exp();
        let state = MaterialState {
            be,
            history: Default::default(),
        };
        let check = update(&mc, &r, &f_n, &state).unwrap();
        assert_eq!(
            check.law_state.history.regime, regime,
            "mohr_coulomb {name}"
        );
        bench_law_at(c, &format!("mohr_coulomb_{name}"), &mc, state, r, f_n);
        if regime != Regime::CompressionEdge {
            let state = MaterialState {
                be,
                history: Default::default(),
            };
            let check = update(&dp, &r, &f_n, &state).unwrap();
            assert_eq!(
                check.law_state.history.regime, regime,
                "drucker_prager {name}"
            );
            bench_law_at(c, &format!("drucker_prager_{name}"), &dp, state, r, f_n);
        }
    }
    let mcc = ModifiedCamClay::new(0.2, 0.05, 1.2, 1e6, 1e3).unwrap();
    let mcc_cases = [
        ("wet", [-120.0, -150.0, -250.0], 150.0),
        ("dry", [0.0, -20.0, -250.0], 300.0),
    ];
    for (name, sigma, pc) in mcc_cases {
        let tau = nalgebra::Vector3::from(sigma.map(|s| s * 1e3));
        let eps = mcc.elastic_strain_of(&tau).unwrap();
        let state = MaterialState {
            be: Matrix3::from_diagonal(&eps.map(|e| (2.0 * e).exp())),
            history: ModifiedCamClayHistory::new(pc * 1e3),
        };
        let check = update(&mcc, &r, &f_n, &state).unwrap();
        assert!(check.yielded(), "modified_cam_clay {name}");
        bench_law_at(c, &format!("modified_cam_clay_{name}"), &mcc, state, r, f_n);
    }
}

criterion_group!(benches, constitutive);
criterion_main!(benches);
