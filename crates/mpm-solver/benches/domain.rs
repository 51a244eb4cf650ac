//! Cost of one domain update per material point for every `DomainUpdater`
//! (Coombs et al. 2020 §6.4), in 2D and 3D. The rules that move corners or
//! mid-points get the affine displacement increment
//! $(\Delta F - I)(x - x_p)$, so the figures are the rules' own cost, not
//! that of the grid interpolation the solver supplies.
//!
//! Run: `cargo bench -p mpm-solver --bench domain`; the numbers are
//! recorded in `docs/src/benchmarks/domain.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::Corners;
use mpm_solver::{
    ConvectedCorners, CornerMidpoint, DetF, DiagF, DomainContext, DomainUpdater,
    IncrementalVolumeCorrectedDiagF, Midpoint, NoUpdate, StretchU, VolumeCorrectedDiagF,
};
use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};

/// Material points per benchmark iteration.
const POINTS: usize = 1024;

/// One material point after a converged step: total and incremental
/// deformation gradients, position, GIMP half-lengths.
struct Point<const D: usize> {
    f: Matrix3<f64>,
    delta_f: Matrix3<f64>,
    position: SVector<f64, D>,
    l0: SVector<f64, D>,
    l: SVector<f64, D>,
}

/// $R(\theta)U$ with θ within ±60°·`amplitude` (about $\mathbf e_3$ in 2D,
/// a random axis in 3D), $U_{ii}$ within 1 ± 0.2·`amplitude` and upper
/// off-diagonal entries within ±0.2·`amplitude` (plane strain: $F_{33} = 1$
/// in 2D).
fn gradient<const D: usize>(next: &mut impl FnMut() -> f64, amplitude: f64) -> Matrix3<f64> {
    let axis = if D == 2 {
        Vector3::z_axis()
    } else {
        nalgebra::Unit::new_normalize(Vector3::new(next(), next(), next() + 2.0))
    };
    let rotation = Rotation3::from_axis_angle(&axis, amplitude * next() * 60f64.to_radians());
    let mut u = Matrix3::identity();
    for i in 0..D {
        u[(i, i)] += 0.2 * amplitude * next();
        for j in i + 1..D {
            u[(i, j)] = 0.2 * amplitude * next();
        }
    }
    rotation.into_inner() * u
}

/// Deterministic points: $F = \Delta F\,F_n$ with $F_n$ of amplitude 1 and
/// $\Delta F$ of amplitude 0.1 (see [`gradient`]).
fn points<const D: usize>() -> Vec<Point<D>> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        2.0 * ((state >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    };
    (0..POINTS)
        .map(|_| {
            let delta_f = gradient::<D>(&mut next, 0.1);
            let f = delta_f * gradient::<D>(&mut next, 1.0);
            let position = SVector::from_fn(|_, _| 10.0 * next());
            let l0 = SVector::from_fn(|_, _| 0.25 + 0.05 * next());
            let l = SVector::from_fn(|_, _| 0.25 + 0.05 * next());
            Point {
                f,
                delta_f,
                position,
                l0,
                l,
            }
        })
        .collect()
}

/// Times `rule` over all points; `domains[p]` is (initial, previous).
fn bench_rule<const D: usize, Dom, R>(
    c: &mut Criterion,
    rule: &R,
    points: &[Point<D>],
    domains: &[(Dom, Dom)],
    checksum: impl Fn(&Dom) -> f64,
) where
    R: DomainUpdater<D, Dom>,
{
    let mut group = c.benchmark_group(format!("domain_{D}d"));
    group.throughput(Throughput::Elements(POINTS as u64));
    group.bench_function(R::NAME, |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for (p, (initial, previous)) in points.iter().zip(domains) {
                let a = SMatrix::<f64, D, D>::from_fn(|i, j| {
                    p.delta_f[(i, j)] - if i == j { 1.0 } else { 0.0 }
                });
                let ctx = DomainContext {
                    initial,
                    previous,
                    f: &p.f,
                    delta_f: &p.delta_f,
                    position_previous: &p.position,
                    position: &p.position,
                };
                let domain = rule
                    .update(black_box(&ctx), |x| Ok(a * (x - p.position)))
                    .unwrap();
                sum += checksum(&domain);
            }
            black_box(sum)
        })
    });
    group.finish();
}

fn bench_dimension<const D: usize>(c: &mut Criterion) {
    let points = points::<D>();
    let gimp: Vec<_> = points.iter().map(|p| (p.l0, p.l)).collect();
    let first = |l: &SVector<f64, D>| l[0];
    bench_rule(c, &NoUpdate, &points, &gimp, first);
    bench_rule(c, &DetF, &points, &gimp, first);
    bench_rule(c, &DiagF, &points, &gimp, first);
    bench_rule(c, &StretchU, &points, &gimp, first);
    bench_rule(c, &CornerMidpoint, &points, &gimp, first);
    bench_rule(c, &Midpoint, &points, &gimp, first);
    bench_rule(c, &VolumeCorrectedDiagF, &points, &gimp, first);
    bench_rule(c, &IncrementalVolumeCorrectedDiagF, &points, &gimp, first);
    let corners: Vec<_> = points
        .iter()
        .map(|p| {
            let c = Corners::rectangle(&p.position, &p.l);
            (c, c)
        })
        .collect();
    bench_rule(c, &ConvectedCorners, &points, &corners, |c: &Corners<D>| {
        c.as_slice()[0][0]
    });
}

fn domain(c: &mut Criterion) {
    bench_dimension::<2>(c);
    bench_dimension::<3>(c);
}

criterion_group!(benches, domain);
criterion_main!(benches);
