//! Shared fixtures for the basis tests: a test grid per dimension (and a
//! simplex mesh of the same box), point and domain strategies per basis,
//! and the checks the property macro runs.
#![allow(dead_code)]

use std::fmt::Debug;

use mpm_basis::{BasisFunction, Corners, Stencil};
use std::sync::OnceLock;

use mpm_mesh::{BoxMesh, DiagonalPattern, RegularGrid, SimplexMesh};
use nalgebra::{SMatrix, SVector};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Anisotropic test grid: origin, spacing and cells differ per axis.
pub const ORIGIN: [f64; 3] = [-1.25, 0.5, 2.0];
/// Cell sizes of the test grid.
pub const SPACING: [f64; 3] = [0.5, 0.25, 0.4];
/// Cells per axis of the test grid.
pub const CELLS: [usize; 3] = [6, 7, 5];

/// The test grid in `D` dimensions.
pub fn grid<const D: usize>() -> RegularGrid<D> {
    RegularGrid::new(
        SVector::from_fn(|i, _| ORIGIN[i]),
        SVector::from_fn(|i, _| SPACING[i]),
        std::array::from_fn(|i| CELLS[i]),
    )
    .expect("valid test grid")
}

/// The test grid's box split into simplices (Kuhn split, alternating
/// pattern): the same nodes, numbered the same way, as [`grid`].
pub fn simplex_mesh<const D: usize>() -> SimplexMesh<D> {
    let lower = SVector::from_fn(|i, _| ORIGIN[i]);
    let upper = SVector::from_fn(|i, _| node_line(i, CELLS[i]));
    BoxMesh::new(lower, upper, std::array::from_fn(|i| CELLS[i]))
        .with_pattern(DiagonalPattern::Alternating)
        .simplex_mesh()
        .expect("valid test mesh")
}

/// What the checks need from a basis's mesh.
pub trait TestMesh<const D: usize>: Sized + 'static {
    /// The shared test mesh (built once).
    fn test_mesh() -> &'static Self;
    /// Number of nodes.
    fn nodes(&self) -> usize;
    /// Position of a node.
    fn position(&self, node: usize) -> SVector<f64, D>;
    /// Whether a point lies in the meshed region.
    fn covers(&self, x: &SVector<f64, D>) -> bool;
    /// Number of cells (for hints).
    fn cells(&self) -> usize;
}

macro_rules! test_meshes {
    ($($dim:literal),*) => {$(
        impl TestMesh<$dim> for RegularGrid<$dim> {
            fn test_mesh() -> &'static Self {
                static MESH: OnceLock<RegularGrid<$dim>> = OnceLock::new();
                MESH.get_or_init(grid::<$dim>)
            }
            fn nodes(&self) -> usize {
                self.node_count()
            }
            fn position(&self, node: usize) -> SVector<f64, $dim> {
                self.node_position(node).expect("node in grid")
            }
            fn covers(&self, x: &SVector<f64, $dim>) -> bool {
                self.contains(x)
            }
            fn cells(&self) -> usize {
                self.cell_count()
            }
        }

        impl TestMesh<$dim> for SimplexMesh<$dim> {
            fn test_mesh() -> &'static Self {
                static MESH: OnceLock<SimplexMesh<$dim>> = OnceLock::new();
                MESH.get_or_init(simplex_mesh::<$dim>)
            }
            fn nodes(&self) -> usize {
                self.node_count()
            }
            fn position(&self, node: usize) -> SVector<f64, $dim> {
                SimplexMesh::nodes(self)[node]
            }
            fn covers(&self, x: &SVector<f64, $dim>) -> bool {
                self.locate_brute_force(x).is_ok()
            }
            fn cells(&self) -> usize {
                self.element_count()
            }
        }
    )*};
}

test_meshes!(2, 3);

/// Coordinate of node line `k` along `axis` of the test grid.
pub fn node_line(axis: usize, k: usize) -> f64 {
    ORIGIN[axis] + k as f64 * SPACING[axis]
}

/// Distance from `x` to the nearest node line along `axis`.
pub fn distance_to_node_line(axis: usize, x: f64) -> f64 {
    let r = (x - ORIGIN[axis]) / SPACING[axis];
    (r - r.round()).abs() * SPACING[axis]
}

/// What the tests need to know about a basis's per-point domain.
pub trait TestDomain<const D: usize>: Copy + Debug {
    /// The domain moved rigidly by `by` (for finite differences).
    fn translated(&self, by: &SVector<f64, D>) -> Self;
    /// The point that $\sum_v S_{vp}\mathbf x_v$ reproduces.
    fn reproduced_point(&self, position: &SVector<f64, D>) -> SVector<f64, D>;
}

impl<const D: usize> TestDomain<D> for () {
    fn translated(&self, _: &SVector<f64, D>) -> Self {}
    fn reproduced_point(&self, position: &SVector<f64, D>) -> SVector<f64, D> {
        *position
    }
}

/// GIMP half-lengths.
impl<const D: usize> TestDomain<D> for SVector<f64, D> {
    fn translated(&self, _: &SVector<f64, D>) -> Self {
        *self
    }
    fn reproduced_point(&self, position: &SVector<f64, D>) -> SVector<f64, D> {
        *position
    }
}

impl<const D: usize> TestDomain<D> for Corners<D> {
    fn translated(&self, by: &SVector<f64, D>) -> Self {
        Corners::translated(self, by)
    }
    fn reproduced_point(&self, _: &SVector<f64, D>) -> SVector<f64, D> {
        self.centroid().expect("valid test domain")
    }
}

/// Per-axis coordinate strategy: a uniform value in `[lo, hi]` most of the
/// time, and exactly one of `snaps` otherwise (node lines, mid-lines).
fn coordinate(lo: f64, hi: f64, snaps: Vec<f64>) -> BoxedStrategy<f64> {
    let snaps: Vec<f64> = snaps
        .into_iter()
        .filter(|s| (lo..=hi).contains(s))
        .collect();
    if snaps.is_empty() {
        (lo..=hi).boxed()
    } else {
        prop_oneof![4 => lo..=hi, 1 => proptest::sample::select(snaps)].boxed()
    }
}

fn node_lines(axis: usize) -> Vec<f64> {
    (0..=CELLS[axis]).map(|k| node_line(axis, k)).collect()
}

fn mid_lines(axis: usize) -> Vec<f64> {
    (0..CELLS[axis])
        .map(|k| ORIGIN[axis] + (k as f64 + 0.5) * SPACING[axis])
        .collect()
}

fn to_vector<const D: usize>(v: Vec<f64>) -> SVector<f64, D> {
    SVector::from_column_slice(&v)
}

/// Standard MPM cases: anywhere in the closed grid, often exactly on node
/// lines (including the boundary).
pub fn linear_cases<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, ())> {
    let axes: Vec<_> = (0..D)
        .map(|i| {
            let upper = node_line(i, CELLS[i]);
            coordinate(ORIGIN[i], upper, node_lines(i))
        })
        .collect();
    axes.prop_map(|x| (to_vector(x), ())).boxed()
}

/// GIMP cases: half-lengths in [0, h/2] (often exactly 0 or h/2), domain
/// inside the grid, the point often exactly on a node line.
pub fn gimp_cases<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, SVector<f64, D>)> {
    gimp_cases_with::<D>(true)
}

/// GIMP cases with every half-length positive (in [0.02 h, h/2]).
pub fn gimp_cases_positive<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, SVector<f64, D>)> {
    gimp_cases_with::<D>(false)
}

fn gimp_cases_with<const D: usize>(
    with_zero: bool,
) -> BoxedStrategy<(SVector<f64, D>, SVector<f64, D>)> {
    let axes: Vec<_> = (0..D)
        .map(|i| {
            let h = SPACING[i];
            let zero_weight = if with_zero { 1 } else { 0 };
            let lambda = prop_oneof![
                zero_weight => Just(0.0),
                1 => Just(0.5),
                6 => 0.02..0.5f64
            ];
            lambda
                .prop_flat_map(move |lambda| {
                    let l = lambda * h;
                    let lo = ORIGIN[i] + l;
                    let hi = node_line(i, CELLS[i]) - l;
                    (coordinate(lo, hi, node_lines(i)), Just(l))
                })
                .boxed()
        })
        .collect();
    axes.prop_map(|pairs| {
        let x = to_vector(pairs.iter().map(|p| p.0).collect());
        let l = to_vector(pairs.iter().map(|p| p.1).collect());
        (x, l)
    })
    .boxed()
}

/// Quadratic B-spline cases: the admissible region (at least half a cell
/// inside the grid), often exactly on node lines or cell mid-lines, where
/// the stencil switches, including the region's boundary.
pub fn bspline_cases<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, ())> {
    let axes: Vec<_> = (0..D)
        .map(|i| {
            let lo = ORIGIN[i] + 0.5 * SPACING[i];
            let hi = node_line(i, CELLS[i]) - 0.5 * SPACING[i];
            let mut snaps = node_lines(i);
            snaps.extend(mid_lines(i));
            coordinate(lo, hi, snaps)
        })
        .collect();
    axes.prop_map(|x| (to_vector(x), ())).boxed()
}

/// Boundary-modified B-spline cases: the whole closed grid, often exactly on
/// node lines (the boundary included) or cell mid-lines, where the linear
/// boundary half cells meet the splines.
pub fn boundary_bspline_cases<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, ())> {
    let axes: Vec<_> = (0..D)
        .map(|i| {
            let mut snaps = node_lines(i);
            snaps.extend(mid_lines(i));
            coordinate(ORIGIN[i], node_line(i, CELLS[i]), snaps)
        })
        .collect();
    axes.prop_map(|x| (to_vector(x), ())).boxed()
}

/// CPDI2 cases, a mix of
/// - small parallelograms/parallelepipeds inside one cell, in 3D with edges
///   parallel to coordinate planes (where the gradient is the derivative of
///   the values under translation), and
/// - general deformed domains spanning up to about three cells per axis.
///
/// Both are `centre + A s_c + p_c` with `A_ii = l_i`, `|A_ij| <= 0.25 l_min`
/// (i != j) and corner perturbations `|p_c| <= 0.1 l_min` per component (zero
/// for the first kind). Scaling column j of the Jacobian by `1/l_j` leaves a
/// diagonal >= 0.9 and off-diagonal column sums <= 2 * 0.35 = 0.7, so by
/// Gershgorin det J > 0 everywhere: every generated domain is valid.
pub fn cpdi2_cases<const D: usize>() -> BoxedStrategy<(SVector<f64, D>, Corners<D>)> {
    let n = Corners::<D>::COUNT;
    let in_cell = (
        proptest::collection::vec((0usize..1000, 0.35..0.65f64, 0.01..0.15f64), D),
        proptest::collection::vec(-0.25..0.25f64, D * D),
    )
        .prop_map(|(axes, shear)| {
            let centre = SVector::<f64, D>::from_fn(|i, _| {
                let (k, t, _) = axes[i];
                node_line(i, k % CELLS[i]) + t * SPACING[i]
            });
            let l = SVector::<f64, D>::from_fn(|i, _| axes[i].2 * SPACING[i]);
            // In 3D keep every edge parallel to a coordinate plane (zero
            // entry (j+1 mod 3, j) in column j): only then is the
            // trilinear N_v at most quadratic along the edges, the condition
            // for the gradient to be the translation derivative.
            let mut shear = shear;
            if D == 3 {
                for j in 0..D {
                    shear[((j + 1) % D) * D + j] = 0.0;
                }
            }
            let a = shape_matrix(&l, &shear);
            (centre, Corners::affine(&centre, &a))
        });
    let general = (
        proptest::collection::vec((0.0..=1.0f64, 0.05..1.2f64), D),
        proptest::collection::vec(-0.25..0.25f64, D * D),
        proptest::collection::vec(-0.1..0.1f64, D * n),
    )
        .prop_map(move |(axes, shear, perturbation)| {
            let l = SVector::<f64, D>::from_fn(|i, _| axes[i].1 * SPACING[i]);
            let l_min = l.min();
            let centre = SVector::<f64, D>::from_fn(|i, _| {
                let margin = l[i] + 0.6 * l_min + 1e-9;
                let span = node_line(i, CELLS[i]) - ORIGIN[i] - 2.0 * margin;
                ORIGIN[i] + margin + axes[i].0 * span
            });
            let a = shape_matrix(&l, &shear);
            let corners = Corners::from_fn(|c| {
                let p = SVector::<f64, D>::from_fn(|i, _| perturbation[c * D + i] * l_min);
                centre + a * Corners::<D>::reference(c) + p
            });
            (centre, corners)
        });
    prop_oneof![in_cell, general].boxed()
}

fn shape_matrix<const D: usize>(l: &SVector<f64, D>, shear: &[f64]) -> SMatrix<f64, D, D> {
    let l_min = l.min();
    SMatrix::from_fn(|i, j| {
        if i == j {
            l[i]
        } else {
            shear[i * D + j] * l_min
        }
    })
}

/// Finite-difference step along `axis`.
pub fn fd_step(axis: usize) -> f64 {
    1e-6 * SPACING[axis]
}

/// Rounding allowance of a central difference: values carry an absolute
/// error below 1e-13 (at most 64 products of numbers in [0, 1]), divided by
/// the step.
pub fn fd_rounding(axis: usize) -> f64 {
    1e-13 / fd_step(axis)
}

/// Evaluate into a fresh stencil with the basis's capacity and check that
/// the capacity was enough (no reallocation).
pub fn evaluate<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<Stencil<D>, TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let mut stencil = Stencil::for_basis::<B>();
    let capacity = stencil.nodes.capacity();
    basis
        .evaluate(B::Mesh::test_mesh(), x, domain, &mut stencil)
        .map_err(|e| TestCaseError::fail(format!("evaluation failed at {x:?}: {e}")))?;
    prop_assert_eq!(stencil.nodes.capacity(), capacity, "stencil reallocated");
    Ok(stencil)
}

/// Value of `node` in `stencil` (zero when absent).
pub fn value_of<const D: usize>(stencil: &Stencil<D>, node: usize) -> f64 {
    stencil.position(node).map_or(0.0, |i| stencil.values[i])
}

/// Gradient of `node` in `stencil` (zero when absent).
pub fn gradient_of<const D: usize>(stencil: &Stencil<D>, node: usize) -> SVector<f64, D> {
    stencil
        .position(node)
        .map_or(SVector::zeros(), |i| stencil.gradients[i])
}

/// Nodes present in either stencil.
pub fn union_nodes<const D: usize>(a: &Stencil<D>, b: &Stencil<D>) -> Vec<usize> {
    let mut nodes = a.nodes.clone();
    nodes.extend(b.nodes.iter().filter(|n| !a.nodes.contains(n)));
    nodes
}

/// Partition of unity $|\sum_v S_{vp} - 1| \le 10^{-12}$ and zero gradient
/// sum, relative to the gradient scale $\sum_v|\nabla S_{vp}|$.
pub fn check_partition<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let s = evaluate(basis, x, domain)?;
    let sum: f64 = s.values.iter().sum();
    prop_assert!((sum - 1.0).abs() <= 1e-12, "sum S = {}", sum);
    let grad_sum: SVector<f64, D> = s.gradients.iter().sum();
    let scale: f64 = s.gradients.iter().map(|g| g.norm()).sum();
    prop_assert!(
        grad_sum.norm() <= 1e-12 * scale.max(1.0),
        "sum grad S = {:?} (scale {})",
        grad_sum,
        scale
    );
    Ok(())
}

/// Linear reproduction $\sum_v S_{vp}\mathbf x_v = \mathbf x_p$ and
/// $\sum_v \mathbf x_v\otimes\nabla S_{vp} = \mathbf I$, tolerances relative
/// to the magnitudes summed.
pub fn check_linear_reproduction<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
    B::Domain: TestDomain<D>,
{
    let g = B::Mesh::test_mesh();
    let s = evaluate(basis, x, domain)?;
    let mut reproduced = SVector::<f64, D>::zeros();
    let mut identity = SMatrix::<f64, D, D>::zeros();
    let mut value_scale = 0.0;
    let mut gradient_scale = 0.0;
    for (node, value, gradient) in s.iter() {
        let xv = g.position(node);
        reproduced += xv * value;
        identity += xv * gradient.transpose();
        value_scale += xv.norm() * value.abs();
        gradient_scale += xv.norm() * gradient.norm();
    }
    let target = domain.reproduced_point(x);
    prop_assert!(
        (reproduced - target).norm() <= 1e-12 * value_scale.max(1.0),
        "sum S x_v = {:?}, expected {:?}",
        reproduced,
        target
    );
    let error = (identity - SMatrix::<f64, D, D>::identity()).norm();
    prop_assert!(
        error <= 1e-12 * gradient_scale.max(1.0),
        "sum x_v (x) grad S = {:?}",
        identity
    );
    Ok(())
}

/// Gradients against central differences of the values under a rigid
/// translation of the point and its domain by `±δ e_i`, for every axis
/// where `second_derivative_bound` returns `Some(M)` ($M \ge
/// |\partial_i^2 S_{vp}|$ near the point). Tolerance: the truncation bound
/// $M\delta/2$ plus the rounding allowance [`fd_rounding`]. Nodes present
/// in only one of the stencils are compared too (their value is zero in the
/// other).
pub fn check_finite_differences<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
    second_derivative_bound: impl Fn(&SVector<f64, D>, &B::Domain, usize) -> Option<f64>,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
    B::Domain: TestDomain<D>,
{
    let s = evaluate(basis, x, domain)?;
    for axis in 0..D {
        let Some(bound) = second_derivative_bound(x, domain, axis) else {
            continue;
        };
        let delta = fd_step(axis);
        let mut e = SVector::<f64, D>::zeros();
        e[axis] = delta;
        let plus = evaluate(basis, &(x + e), &domain.translated(&e))?;
        let minus = evaluate(basis, &(x - e), &domain.translated(&(-e)))?;
        let tolerance = 0.5 * bound * delta + fd_rounding(axis);
        let mut nodes = union_nodes(&plus, &minus);
        nodes.extend(
            s.nodes
                .iter()
                .filter(|n| !nodes.contains(n))
                .collect::<Vec<_>>(),
        );
        for node in nodes {
            let fd = (value_of(&plus, node) - value_of(&minus, node)) / (2.0 * delta);
            let analytic = gradient_of(&s, node)[axis];
            prop_assert!(
                (fd - analytic).abs() <= tolerance,
                "node {}, axis {}: gradient {} vs finite difference {} (tolerance {})",
                node,
                axis,
                analytic,
                fd,
                tolerance
            );
        }
    }
    Ok(())
}

/// Stencil well-formedness: at most `MAX_NODES` entries, parallel arrays,
/// unique node ids all inside the grid (id below the node count and
/// position inside the grid's box), finite values in [0, 1] and finite
/// gradients, no entry with zero value and zero gradient.
pub fn check_well_formed<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let g = B::Mesh::test_mesh();
    let s = evaluate(basis, x, domain)?;
    prop_assert!(
        s.len() <= B::MAX_NODES,
        "{} > {} nodes",
        s.len(),
        B::MAX_NODES
    );
    prop_assert_eq!(s.values.len(), s.len());
    prop_assert_eq!(s.gradients.len(), s.len());
    prop_assert!(!s.is_empty());
    for (k, (node, value, gradient)) in s.iter().enumerate() {
        prop_assert!(node < g.nodes(), "node {} outside the grid", node);
        prop_assert!(g.covers(&g.position(node)));
        prop_assert!(!s.nodes[..k].contains(&node), "node {} twice", node);
        prop_assert!(
            value.is_finite() && (-1e-15..=1.0 + 1e-15).contains(&value),
            "value {}",
            value
        );
        prop_assert!(gradient.iter().all(|g| g.is_finite()));
        prop_assert!(
            value != 0.0 || gradient.iter().any(|&g| g != 0.0),
            "empty entry {}",
            node
        );
    }
    Ok(())
}

/// A hinted evaluation ([`BasisFunction::evaluate_hinted`]) from the hint
/// `seed % cells` (or no hint, `usize::MAX`, for every fifth seed) gives
/// the values of the plain evaluation at every node (the values are
/// continuous, whichever cell is found on a shared face), and the same
/// gradients when it finds the same nodes; evaluating again from the hint
/// it wrote reproduces the stencil exactly.
pub fn check_hinted<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
    seed: usize,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let mesh = B::Mesh::test_mesh();
    let plain = evaluate(basis, x, domain)?;
    let mut hint = if seed.is_multiple_of(5) {
        usize::MAX
    } else {
        seed % mesh.cells()
    };
    let mut hinted = Stencil::for_basis::<B>();
    basis
        .evaluate_hinted(mesh, x, domain, &mut hint, &mut hinted)
        .map_err(|e| TestCaseError::fail(format!("hinted evaluation failed at {x:?}: {e}")))?;
    for node in union_nodes(&plain, &hinted) {
        let (a, b) = (value_of(&plain, node), value_of(&hinted, node));
        prop_assert!(
            (a - b).abs() <= 1e-12,
            "node {}: value {} vs {}",
            node,
            a,
            b
        );
    }
    let mut same_nodes = plain.nodes.clone();
    let mut hinted_nodes = hinted.nodes.clone();
    same_nodes.sort_unstable();
    hinted_nodes.sort_unstable();
    if same_nodes == hinted_nodes {
        for node in plain.nodes.iter().copied() {
            let (a, b) = (gradient_of(&plain, node), gradient_of(&hinted, node));
            prop_assert!(
                (a - b).norm() <= 1e-12 * a.norm().max(1.0),
                "node {} gradient",
                node
            );
        }
    }
    let mut again = Stencil::for_basis::<B>();
    basis
        .evaluate_hinted(mesh, x, domain, &mut hint, &mut again)
        .map_err(|e| TestCaseError::fail(format!("re-evaluation failed at {x:?}: {e}")))?;
    prop_assert_eq!(again, hinted);
    Ok(())
}

/// `for_each_node` visits exactly the stencil of `evaluate`, in the same
/// order, with bit-identical values and gradients (bases that override it
/// must not change a result).
pub fn check_visited<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let mesh = B::Mesh::test_mesh();
    let plain = evaluate(basis, x, domain)?;
    let mut visited = Stencil::<D>::with_capacity(B::MAX_NODES);
    let mut scratch = Stencil::for_basis::<B>();
    basis
        .for_each_node(mesh, x, domain, &mut scratch, |i, w, g| {
            visited.push(i, w, *g)
        })
        .map_err(|e| TestCaseError::fail(format!("visiting failed at {x:?}: {e}")))?;
    prop_assert_eq!(&plain.nodes, &visited.nodes);
    prop_assert_eq!(&plain.values, &visited.values);
    prop_assert_eq!(&plain.gradients, &visited.gradients);
    Ok(())
}

/// The factors of `tensor_factors` (when the basis has them) multiply out
/// to the stencil of `evaluate`: same nodes (up to products that vanish in
/// value and gradient), values and gradients to rounding, and node
/// positions consistent with the offsets.
pub fn check_tensor<const D: usize, B>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Result<(), TestCaseError>
where
    B: BasisFunction<D>,
    B::Mesh: TestMesh<D>,
{
    let mesh = B::Mesh::test_mesh();
    let Some(factors) = basis.tensor_factors(mesh, x, domain) else {
        return Ok(());
    };
    let f =
        factors.map_err(|e| TestCaseError::fail(format!("tensor factors failed at {x:?}: {e}")))?;
    let plain = evaluate(basis, x, domain)?;
    let mut count = 0;
    let total: usize = f.len.iter().product();
    for k in 0..total {
        let mut rest = k;
        let (mut id, mut value) = (f.first_id, 1.0);
        let mut gradient = SVector::<f64, D>::from_element(1.0);
        for i in 0..D {
            let c = rest % f.len[i];
            rest /= f.len[i];
            id += c * f.strides[i];
            value *= f.value[i][c];
            for j in 0..D {
                gradient[j] *= if i == j { f.slope[i][c] } else { f.value[i][c] };
            }
        }
        if value == 0.0 && gradient.iter().all(|g| *g == 0.0) {
            continue;
        }
        count += 1;
        prop_assert!(
            plain.position(id).is_some(),
            "node {} missing from the stencil",
            id
        );
        prop_assert!(
            (value - value_of(&plain, id)).abs() <= 1e-14,
            "node {}: value",
            id
        );
        prop_assert!(
            (gradient - gradient_of(&plain, id)).norm() <= 1e-12,
            "node {}: gradient",
            id
        );
    }
    prop_assert_eq!(count, plain.nodes.len());
    Ok(())
}
