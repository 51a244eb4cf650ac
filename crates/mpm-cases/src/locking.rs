//! Volumetric-locking studies: Cook's membrane in plane strain on
//! conforming triangles (standard MPM against F-patch) and on a regular
//! grid (standard MPM against F-bar).
//!
//! The membrane is the quadrilateral (0, 0), (48, 44), (48, 60), (0, 44),
//! clamped on its left edge, with a total vertical shear `load` spread
//! uniformly over its right edge; E = 250. The triangles are the linear
//! children of six-node triangles on the image of a structured square
//! mesh under the bilinear map of the unit square onto the membrane (its
//! iso-lines are straight, so the children tile the membrane exactly);
//! standard MPM runs on the same children and points. The grid holds a
//! lattice of points, those inside the membrane, so its boundary is a
//! staircase at the points' spacing.
//!
//! For a small load (conforming triangles, and the grid, whose points
//! stay in their cells) the traction is carried by *load points*:
//! points of negligible volume (1e-9 of their neighbours') at the two
//! Gauss points of every boundary segment of the right edge, each with
//! its share of the force, so the nodal forces are the consistent ones of
//! the edge; a probe point at the corner C = (48, 60) measures the tip
//! displacement ([`Traction::EdgeGaussPoints`]).
//!
//! At finite strain, on a background mesh (the grid, or the triangles of a
//! background box), a point of negligible volume that drifts into a cell no real
//! point covers loads nodes of negligible stiffness, and the step fails.
//! There the traction is carried by the real points of the column
//! nearest the right edge, each with the share of the edge nearest to it,
//! and the tip is the linear least-squares extrapolation to C of the
//! displacements of the points nearest C ([`extrapolated_tip`]): no
//! point of negligible volume is used ([`Traction::BoundaryColumn`]).

use mpm_basis::{LinearMpm, LinearSimplex};
use mpm_constitutive::HenckyElastic;
use mpm_mesh::{BoxMesh, PatchMesh, QuadraticMesh, RegularGrid};
use mpm_solver::{
    FBar, FPatch, ImplicitSolver, LoadStepping, LockingTreatment, MaterialPoints, NewtonOptions,
    NoLocking, NoUpdate, NodalConstraints, Parts, PreviouslyConverged, SolverError,
    UpdatedLagrangian, stages::ghost::GhostPenalty,
};

use crate::variant::FormulationKind;

/// Evaluates `$body` with the type alias `$f` naming the formulation
/// `$kind` selects (one monomorphised run per formulation).
macro_rules! with_formulation {
    ($kind:expr, $f:ident, $body:expr) => {
        match $kind {
            FormulationKind::Ul => {
                type $f = UpdatedLagrangian;
                $body
            }
            FormulationKind::Pc => {
                type $f = PreviouslyConverged;
                $body
            }
        }
    };
}
use nalgebra::Vector2;

/// Young's modulus of the membrane.
pub const YOUNG: f64 = 250.0;
/// Width of the membrane (x extent).
pub const WIDTH: f64 = 48.0;
/// Height of the right edge's lower end.
const B_Y: f64 = 44.0;
/// Height of the tip C.
pub const TIP_Y: f64 = 60.0;

/// Relative volume of a load or probe point.
const TINY: f64 = 1e-9;

/// The bilinear map of the unit square onto the membrane.
fn membrane(s: f64, t: f64) -> Vector2<f64> {
    Vector2::new(WIDTH * s, B_Y * s + t * (B_Y + (TIP_Y - 2.0 * B_Y) * s))
}

/// Whether `x` lies inside the membrane.
fn inside(x: &Vector2<f64>) -> bool {
    let s = x[0] / WIDTH;
    if !(0.0..=1.0).contains(&s) {
        return false;
    }
    let (lo, hi) = (B_Y * s, B_Y + (TIP_Y - B_Y) * s);
    x[1] >= lo && x[1] <= hi
}

/// What a Cook's membrane run is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cook {
    /// Poisson's ratio.
    pub nu: f64,
    /// Total vertical shear on the right edge.
    pub load: f64,
    /// Load steps.
    pub steps: usize,
    /// Refinement: parent elements per side (triangles) or cells per
    /// width (grid).
    pub n: usize,
    /// Statement of equilibrium (the studies use previously converged).
    pub formulation: FormulationKind,
}

/// The outcome of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CookResult {
    /// Vertical displacement of the tip C.
    pub tip: f64,
    /// Newton iterations over all steps.
    pub iterations: usize,
    /// Free degrees of freedom (last step).
    pub dofs: usize,
    /// Wall time of the solver (s).
    pub seconds: f64,
}

/// Load points on the right edge between heights `y0 < y1` (two Gauss
/// points, each with half the segment's share of `load`), nudged into
/// the body by `inset`.
fn edge_loads(y0: f64, y1: f64, load: f64, inset: f64) -> [(Vector2<f64>, f64); 2] {
    let (mid, half) = (0.5 * (y0 + y1), 0.5 * (y1 - y0));
    let g = half / 3f64.sqrt();
    let share = load * (y1 - y0) / (TIP_Y - B_Y) / 2.0;
    [
        (Vector2::new(WIDTH - inset, mid - g), share),
        (Vector2::new(WIDTH - inset, mid + g), share),
    ]
}

/// Runs `solver` on `points` to the full load; `tip` reads the tip
/// displacement from the final points.
fn finish<P>(
    mut solver: ImplicitSolver<2, P>,
    mut points: MaterialPoints<2, (), ()>,
    steps: usize,
    tip: impl FnOnce(&MaterialPoints<2, (), ()>) -> f64,
) -> Result<CookResult, SolverError>
where
    P: mpm_solver::SolverParts<2, History = (), Domain = ()>,
{
    let start = std::time::Instant::now();
    let mut dofs = 0;
    let summary = solver.run(&mut points, &LoadStepping::uniform(steps), |_, r, _| {
        dofs = r.free_dofs;
        Ok(())
    })?;
    Ok(CookResult {
        tip: tip(&points),
        iterations: summary.iterations,
        dofs,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The displacement of the last point (the probe) in y.
fn probe(points: &MaterialPoints<2, (), ()>) -> f64 {
    points.displacement.last().map_or(f64::NAN, |u| u[1])
}

/// Points of the lattice fit of [`extrapolated_tip`].
const TIP_FIT_POINTS: usize = 6;

/// The tip displacement in y extrapolated from the points nearest C: a
/// least-squares fit u_y(X) ≈ a + b · (X − C) over the
/// [`TIP_FIT_POINTS`] points whose initial positions X are nearest C
/// (and any as near as the last of them),
/// evaluated at C (a). The points lie within about a spacing of C, so the
/// extrapolation error is second order in the spacing. NaN when the fit
/// is singular.
pub fn extrapolated_tip(points: &MaterialPoints<2, (), ()>) -> f64 {
    let tip = Vector2::new(WIDTH, TIP_Y);
    let mut near: Vec<(f64, Vector2<f64>, f64)> = points
        .position
        .iter()
        .zip(&points.displacement)
        .map(|(x, u)| {
            let d = x - u - tip;
            (d.norm(), d, u[1])
        })
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Every point as near as the last of the fit's: the lattice has points
    // at equal distances from C, whose X = x − u differ in the last bits;
    // taking some of a tie and not the others would let that rounding
    // choose the fit.
    let Some(last) = near.get(TIP_FIT_POINTS.min(near.len()).saturating_sub(1)) else {
        return f64::NAN;
    };
    let reach = last.0 * (1.0 + 1e-9) + 1e-12 * WIDTH;
    let (mut normal, mut rhs) = (
        nalgebra::Matrix3::<f64>::zeros(),
        nalgebra::Vector3::zeros(),
    );
    for (_, d, u) in near.iter().take_while(|n| n.0 <= reach) {
        let row = nalgebra::Vector3::new(1.0, d[0], d[1]);
        normal += row * row.transpose();
        rhs += row * *u;
    }
    normal.lu().solve(&rhs).map_or(f64::NAN, |c| c[0])
}

/// Newton controls of the studies: normalised residual 1e-6. At ν =
/// 0.4999 (κ/μ = 5000) the residual's round-off floor — the rounding of
/// the pressure κ ln J against the small deviatoric stresses that carry
/// the load — reaches 3e-9 to 1e-6 as the mesh is refined, above the
/// default 1e-9; the study's problems are linear or mildly nonlinear, so
/// 1e-6 still leaves the tip displacement exact to the digits shown.
///
/// `weak_node_threshold` is 0 where load or probe points of negligible
/// volume must keep the nodes they touch free, the default elsewhere.
fn newton(weak_node_threshold: f64) -> NewtonOptions {
    NewtonOptions {
        weak_node_threshold,
        tolerance: 1e-6,
        ..NewtonOptions::default()
    }
}

/// The ghost penalty of the grid runs whose body moves into empty cells
/// ([`Traction::grid_newton`]): 0.01 · 2μ on the faces next to cells
/// their points fill below half. It acts on each step's increment, so it
/// makes a response depend on the number of steps at its own order, which
/// falls with refinement (`docs/src/theory/locking.md`, "Fringe cells and
/// the ghost penalty").
pub const GRID_GHOST: GhostPenalty = GhostPenalty::new(0.01);

/// How a lattice run carries the traction and measures the tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Traction {
    /// Load points of negligible volume at the Gauss points of the right
    /// edge (consistent nodal forces) and a probe point at C: exact while
    /// the body stays in the cells it starts in (a small load).
    EdgeGaussPoints,
    /// The real points of the column nearest the right edge, the tip by
    /// [`extrapolated_tip`]: robust when the body moves into empty cells
    /// (finite strain), at a first-order error in the load's position.
    BoundaryColumn,
}

impl Traction {
    /// The weak-node threshold of the run: 0 where load or probe points
    /// of negligible volume must keep the nodes they touch free.
    fn weak_node_threshold(self) -> f64 {
        match self {
            Traction::EdgeGaussPoints => 0.0,
            Traction::BoundaryColumn => NewtonOptions::default().weak_node_threshold,
        }
    }

    /// The study's Newton controls ([`newton`]) with the scheme's
    /// fringe-node rules, the same on every mesh: the weak-node rules at
    /// their defaults (the threshold 0 for
    /// [`Traction::EdgeGaussPoints`]). A grid run adds [`GRID_GHOST`]
    /// when the body moves into empty cells ([`Traction::grid_newton`]).
    pub fn newton(self) -> NewtonOptions {
        newton(self.weak_node_threshold())
    }

    /// The Newton controls of a grid run: [`Traction::newton`], and for
    /// [`Traction::BoundaryColumn`] the ghost penalty [`GRID_GHOST`]. There
    /// a point of the lattice's fringe that has just crossed into an empty
    /// cell reaches the cell's far nodes with bilinear gradients
    /// proportional to its distance from the cell edges, and nothing else
    /// reaches them: a near-mechanism of the stiffness, along which Newton
    /// corrections strained the point beyond the admissible ‖ΔF‖ (without
    /// the penalty 11 of 36 full-load runs failed with the default
    /// weak-node rules and 9 with the stiffness rule 10⁻³; none with it;
    /// `docs/src/theory/locking.md`, "Fringe cells and the ghost
    /// penalty"). Linear simplices' gradients do not depend on where the
    /// point is in its element, so the triangle runs need no penalty.
    pub fn grid_newton(self) -> NewtonOptions {
        match self {
            Traction::EdgeGaussPoints => self.newton(),
            Traction::BoundaryColumn => NewtonOptions {
                ghost: GRID_GHOST,
                ..self.newton()
            },
        }
    }

    /// The tip displacement in y of the final points.
    fn tip(self, points: &MaterialPoints<2, (), ()>) -> f64 {
        match self {
            Traction::EdgeGaussPoints => probe(points),
            Traction::BoundaryColumn => extrapolated_tip(points),
        }
    }
}

/// Cook's membrane on conforming triangles: the children of `n`×`n`×2
/// six-node triangles, three points per child, with the treatment
/// `locking` (made from the patch mesh).
///
/// # Errors
/// A [`SolverError`] when the run fails.
pub fn triangles<K, T>(cook: &Cook, locking: T) -> Result<CookResult, SolverError>
where
    K: LockingTreatment<2, mpm_mesh::SimplexMesh<2>>,
    T: FnOnce(&PatchMesh<2>) -> K,
{
    let unit = BoxMesh::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [cook.n, cook.n])
        .quadratic_mesh()?;
    let nodes = unit.nodes().iter().map(|x| membrane(x[0], x[1])).collect();
    let parents = QuadraticMesh::new(nodes, unit.connectivity().to_vec())?;
    let patches = PatchMesh::from_parents(&parents)?;
    let mesh = patches.mesh().clone();
    // Three points per child at the barycentric points (2/3, 1/6, 1/6).
    let (mut position, mut volume) = (Vec::new(), Vec::new());
    for e in 0..mesh.element_count() {
        let v = mesh.element_nodes(e);
        for k in 0..3 {
            let x = (0..3).fold(Vector2::zeros(), |acc, a| {
                acc + mesh.nodes()[v[a]] * if a == k { 2.0 / 3.0 } else { 1.0 / 6.0 }
            });
            position.push(x);
            volume.push(mesh.volumes()[e] / 3.0);
        }
    }
    let small = TINY * volume.iter().copied().fold(f64::INFINITY, f64::min);
    let inset = 1e-9 * WIDTH;
    // Right-edge nodes, bottom to top.
    let mut edge: Vec<f64> = mesh
        .nodes()
        .iter()
        .filter(|x| (x[0] - WIDTH).abs() < 1e-9)
        .map(|x| x[1])
        .collect();
    edge.sort_by(f64::total_cmp);
    let mut point_force = Vec::new();
    for w in edge.windows(2) {
        for (x, f) in edge_loads(w[0], w[1], cook.load, inset) {
            point_force.push((position.len(), Vector2::new(0.0, f)));
            position.push(x);
            volume.push(small);
        }
    }
    position.push(Vector2::new(WIDTH - inset, TIP_Y - inset));
    volume.push(small);
    let n = position.len();
    let mut points = MaterialPoints::new(position, volume, 1.0, vec![(); n])?;
    points.set_gravity(Vector2::zeros());
    points.point_force = point_force;
    let mut c = NodalConstraints::<2>::new(mesh.node_count());
    for (node, x) in mesh.nodes().iter().enumerate() {
        if x[0].abs() < 1e-9 {
            c.fix([node], 0).fix([node], 1);
        }
    }
    let law = HenckyElastic::new(YOUNG, cook.nu)?;
    let treatment = locking(&patches);
    with_formulation!(cook.formulation, F, {
        let solver: ImplicitSolver<2, Parts<LinearSimplex, F, _, K, NoUpdate, _>> =
            ImplicitSolver::new(
                LinearSimplex,
                mesh,
                law,
                treatment,
                NoUpdate,
                c,
                Traction::EdgeGaussPoints.newton(),
            );
        finish(solver, points, cook.steps, probe)
    })
}

/// Cook's membrane on the children of a box of split six-node triangles
/// that covers the membrane and the room it deforms into ([`background`]),
/// node spacing 48/`n`, with the grid's lattice of points
/// ([`grid`]) — the non-conforming background a finite-strain run needs,
/// since the body leaves a mesh fitted to it.
///
/// # Errors
/// A [`SolverError`] when the run fails.
pub fn triangles_background<K, T>(cook: &Cook, locking: T) -> Result<CookResult, SolverError>
where
    K: LockingTreatment<2, mpm_mesh::SimplexMesh<2>>,
    T: FnOnce(&PatchMesh<2>) -> K,
{
    let h = WIDTH / cook.n as f64;
    let (lower, cells) = background(h);
    // The lattice points sit at a quarter and three quarters of a cell;
    // on a box starting at a node line in y they would lie on the
    // children's diagonals, where a point's element (and its constant
    // gradient) is decided by the rounding of its displacement, step by
    // step. An eighth of a spacing up in y puts every point inside a
    // child; x = 0 stays a node line for the clamp.
    let lower = lower + Vector2::new(0.0, h / 8.0);
    // Parents of twice the spacing: the children have spacing h.
    let parents = BoxMesh::new(
        lower,
        lower + Vector2::new(cells[0] as f64 * h, cells[1] as f64 * h),
        [cells[0] / 2, cells[1] / 2],
    )
    .quadratic_mesh()?;
    let patches = PatchMesh::from_parents(&parents)?;
    let mesh = patches.mesh().clone();
    let points = lattice_points(cook, h, Traction::BoundaryColumn)?;
    let c = clamp(mesh.nodes().iter().copied(), mesh.node_count(), h);
    let law = HenckyElastic::new(YOUNG, cook.nu)?;
    let treatment = locking(&patches);
    let options = Traction::BoundaryColumn.newton();
    with_formulation!(cook.formulation, F, {
        let solver: ImplicitSolver<2, Parts<LinearSimplex, F, _, K, NoUpdate, _>> =
            ImplicitSolver::new(LinearSimplex, mesh, law, treatment, NoUpdate, c, options);
        finish(solver, points, cook.steps, |p| {
            Traction::BoundaryColumn.tip(p)
        })
    })
}

/// The lower corner and cells (even counts) of a background of spacing
/// `h` covering the membrane with room to deform: 2 cells below and left,
/// up to 1.5 × its height and 2 cells beyond its width.
fn background(h: f64) -> (Vector2<f64>, [usize; 2]) {
    let even = |x: f64| {
        let c = (x / h).ceil() as usize;
        c + c % 2
    };
    (
        Vector2::new(-2.0 * h, -2.0 * h),
        [even(WIDTH + 4.0 * h), even(1.5 * TIP_Y + 2.0 * h)],
    )
}

/// Left-edge nodes clamped.
fn clamp(nodes: impl Iterator<Item = Vector2<f64>>, count: usize, h: f64) -> NodalConstraints<2> {
    let mut c = NodalConstraints::<2>::new(count);
    for (node, x) in nodes.enumerate() {
        if x[0].abs() < 1e-9 * h {
            c.fix([node], 0).fix([node], 1);
        }
    }
    c
}

/// The membrane's lattice points (2 × 2 per cell of spacing `h`, those
/// inside) carrying the load by `traction`: with
/// [`Traction::EdgeGaussPoints`] load points on segments of the points'
/// spacing and the probe (last) are appended; with
/// [`Traction::BoundaryColumn`] the points of the column nearest the
/// right edge carry it, each the share of the edge [44, 60] nearest to it
/// (the edge split at the midpoints between them).
fn lattice_points(
    cook: &Cook,
    h: f64,
    traction: Traction,
) -> Result<MaterialPoints<2, (), ()>, SolverError> {
    let rows = (TIP_Y / h).ceil() as usize;
    let per = 2usize;
    let step = h / per as f64;
    let (mut position, mut volume) = (Vec::new(), Vec::new());
    for j in 0..rows * per {
        for i in 0..cook.n * per {
            let x = Vector2::new((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
            if inside(&x) {
                position.push(x);
                volume.push(step * step);
            }
        }
    }
    let point_force = match traction {
        Traction::EdgeGaussPoints => edge_load_points(cook, step, &mut position, &mut volume),
        Traction::BoundaryColumn => column_loads(cook, step, &position),
    };
    let n = position.len();
    let mut points = MaterialPoints::new(position, volume, 1.0, vec![(); n])?;
    points.set_gravity(Vector2::zeros());
    points.point_force = point_force;
    Ok(points)
}

/// Load points on segments of length `step` of the right edge and the
/// probe, appended to the points; the load points' forces.
fn edge_load_points(
    cook: &Cook,
    step: f64,
    position: &mut Vec<Vector2<f64>>,
    volume: &mut Vec<f64>,
) -> Vec<(usize, Vector2<f64>)> {
    let small = TINY * step * step;
    let inset = 1e-9 * WIDTH;
    let segments = ((TIP_Y - B_Y) / step).round().max(1.0) as usize;
    let mut point_force = Vec::new();
    for k in 0..segments {
        let y0 = B_Y + (TIP_Y - B_Y) * k as f64 / segments as f64;
        let y1 = B_Y + (TIP_Y - B_Y) * (k + 1) as f64 / segments as f64;
        for (x, f) in edge_loads(y0, y1, cook.load, inset) {
            point_force.push((position.len(), Vector2::new(0.0, f)));
            position.push(x);
            volume.push(small);
        }
    }
    position.push(Vector2::new(WIDTH - inset, TIP_Y - inset));
    volume.push(small);
    point_force
}

/// The forces on the points of the right column (within `step` of the
/// edge), each the share of the edge nearest to it.
fn column_loads(cook: &Cook, step: f64, position: &[Vector2<f64>]) -> Vec<(usize, Vector2<f64>)> {
    // The right column, bottom to top.
    let mut column: Vec<(usize, f64)> = position
        .iter()
        .enumerate()
        .filter(|(_, x)| x[0] > WIDTH - step)
        .map(|(p, x)| (p, x[1]))
        .collect();
    column.sort_by(|a, b| a.1.total_cmp(&b.1));
    let split = |k: usize| match k {
        0 => B_Y,
        k if k == column.len() => TIP_Y,
        k => 0.5 * (column[k - 1].1 + column[k].1),
    };
    (0..column.len())
        .map(|k| {
            let share = (split(k + 1) - split(k)) / (TIP_Y - B_Y);
            (column[k].0, Vector2::new(0.0, cook.load * share))
        })
        .collect()
}

/// Cook's membrane on a regular grid of spacing 48/`n` covering the
/// membrane and the room it deforms into ([`background`]), 2×2 lattice
/// points per cell kept inside the membrane, with the treatment
/// `locking`, the load carried by `traction`, the Newton controls
/// [`Traction::grid_newton`].
///
/// # Errors
/// A [`SolverError`] when the run fails.
pub fn grid<K>(cook: &Cook, locking: K, traction: Traction) -> Result<CookResult, SolverError>
where
    K: LockingTreatment<2, RegularGrid<2>>,
{
    grid_with(cook, locking, traction, traction.grid_newton())
}

/// [`grid`] with the Newton controls `options` (to compare fringe
/// treatments: the ghost penalty off or at another factor, other
/// weak-node rules).
///
/// # Errors
/// A [`SolverError`] when the run fails.
pub fn grid_with<K>(
    cook: &Cook,
    locking: K,
    traction: Traction,
    options: NewtonOptions,
) -> Result<CookResult, SolverError>
where
    K: LockingTreatment<2, RegularGrid<2>>,
{
    let h = WIDTH / cook.n as f64;
    let (lower, cells) = background(h);
    let grid = RegularGrid::new(lower, Vector2::new(h, h), cells)?;
    let points = lattice_points(cook, h, traction)?;
    let count = grid.node_count();
    let nodes = (0..count).map(|v| grid.node_position(v).unwrap_or_else(|_| Vector2::zeros()));
    let c = clamp(nodes, count, h);
    let law = HenckyElastic::new(YOUNG, cook.nu)?;
    with_formulation!(cook.formulation, F, {
        let solver: ImplicitSolver<2, Parts<LinearMpm, F, _, K, NoUpdate, _>> =
            ImplicitSolver::new(LinearMpm, grid, law, locking, NoUpdate, c, options);
        finish(solver, points, cook.steps, |p| traction.tip(p))
    })
}

/// The four runs of one refinement: triangles without and with F-patch
/// (conforming, or on a background box when `background`), grid without
/// and with F-bar (in that order), each its result or why it failed. The
/// background runs carry the load by [`Traction::BoundaryColumn`], the
/// others by [`Traction::EdgeGaussPoints`].
pub fn all_four(cook: &Cook, background: bool) -> [Result<CookResult, SolverError>; 4] {
    let (none, fpatch) = if background {
        (
            triangles_background(cook, |_| NoLocking),
            triangles_background(cook, FPatch::new),
        )
    } else {
        (triangles(cook, |_| NoLocking), triangles(cook, FPatch::new))
    };
    let traction = if background {
        Traction::BoundaryColumn
    } else {
        Traction::EdgeGaussPoints
    };
    [
        none,
        fpatch,
        grid(cook, NoLocking, traction),
        grid(cook, FBar::default(), traction),
    ]
}

/// What a Prandtl footing run is: a smooth rigid strip footing of
/// half-width 1 pressed into a weightless von Mises layer (half model,
/// 5 × 5, `n` cells or children across, `n` a multiple of 10 so that
/// the footing edge is a node) by a settlement `settlement`
/// reached in `steps` steps; k = ρ_y/√2 = 1, so the collapse pressure is
/// 2 + π.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footing {
    /// Poisson's ratio.
    pub nu: f64,
    /// Young's modulus (the rigidity E/k).
    pub young: f64,
    /// Node spacing: the layer's width over `n`.
    pub n: usize,
    /// Final settlement of the footing.
    pub settlement: f64,
    /// Load steps.
    pub steps: usize,
    /// Statement of equilibrium (the studies use previously converged).
    pub formulation: FormulationKind,
}

/// Width and depth of the half layer.
pub const LAYER: f64 = 5.0;
/// Footing half-width.
pub const HALF_WIDTH: f64 = 1.0;

/// A footing run: settlement and footing pressure after every converged
/// step, and the failure that stopped it early, if any.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FootingCurve {
    /// (settlement, pressure / k) per converged step.
    pub points: Vec<(f64, f64)>,
    /// Why the run stopped before the full settlement.
    pub failure: Option<String>,
    /// Newton iterations.
    pub iterations: usize,
    /// Normalised residuals of every Newton iteration, per converged step.
    pub residuals: Vec<Vec<f64>>,
    /// Wall time (s).
    pub seconds: f64,
}

/// Constraints of the layer: smooth symmetry plane and far side, fixed
/// base, the footing nodes of the surface (x ≤ half-width) settling.
fn footing_constraints(
    nodes: impl Iterator<Item = Vector2<f64>>,
    count: usize,
    settlement: f64,
) -> (NodalConstraints<2>, Vec<usize>) {
    let tol = 1e-9 * LAYER;
    let mut c = NodalConstraints::<2>::new(count);
    let mut footing = Vec::new();
    for (node, x) in nodes.enumerate() {
        if x[0].abs() < tol || (x[0] - LAYER).abs() < tol {
            c.fix([node], 0);
        }
        if x[1].abs() < tol {
            c.fix([node], 0).fix([node], 1);
        }
        if (x[1] - LAYER).abs() < tol && x[0] <= HALF_WIDTH + tol {
            c.prescribe([node], 1, -settlement);
            footing.push(node);
        }
    }
    (c, footing)
}

fn footing_run<P>(
    mut solver: ImplicitSolver<2, P>,
    mut points: MaterialPoints<2, mpm_constitutive::VonMisesHistory, ()>,
    footing: &[usize],
    f: &Footing,
) -> FootingCurve
where
    P: mpm_solver::SolverParts<2, History = mpm_constitutive::VonMisesHistory, Domain = ()>,
{
    let start = std::time::Instant::now();
    let mut curve = FootingCurve::default();
    let result = solver.run(&mut points, &LoadStepping::uniform(f.steps), |_, r, _| {
        let force = r.reaction_on(footing)[1];
        curve
            .points
            .push((r.lambda1 * f.settlement, -force / HALF_WIDTH));
        curve.iterations += r.residuals.len();
        curve.residuals.push(r.residuals.clone());
        Ok(())
    });
    if let Err(e) = result {
        curve.failure = Some(e.to_string());
    }
    curve.seconds = start.elapsed().as_secs_f64();
    curve
}

fn footing_law(f: &Footing) -> Result<mpm_constitutive::VonMises, SolverError> {
    Ok(mpm_constitutive::VonMises::new(
        f.young,
        f.nu,
        2f64.sqrt(),
        0.0,
    )?)
}

/// The footing on a regular grid with 2 × 2 points per cell.
///
/// # Errors
/// A [`SolverError`] when the problem cannot be set up (a failing run is
/// reported in the curve).
pub fn footing_grid<K>(f: &Footing, locking: K) -> Result<FootingCurve, SolverError>
where
    K: LockingTreatment<2, RegularGrid<2>>,
{
    let h = footing_spacing(f)?;
    let grid = RegularGrid::new(Vector2::new(-h, -h), Vector2::new(h, h), [f.n + 2, f.n + 2])?;
    let step = h / 2.0;
    let mut position = Vec::new();
    for j in 0..2 * f.n {
        for i in 0..2 * f.n {
            position.push(Vector2::new(
                (i as f64 + 0.5) * step,
                (j as f64 + 0.5) * step,
            ));
        }
    }
    let n = position.len();
    let mut points = MaterialPoints::new(position, vec![step * step; n], 1.0, vec![(); n])?;
    points.set_gravity(Vector2::zeros());
    let count = grid.node_count();
    let nodes = (0..count).map(|v| grid.node_position(v).unwrap_or_else(|_| Vector2::zeros()));
    let (c, footing) = footing_constraints(nodes, count, f.settlement);
    let law = footing_law(f)?;
    Ok(with_formulation!(f.formulation, F, {
        let solver: ImplicitSolver<2, Parts<LinearMpm, F, _, K, NoUpdate, _>> =
            ImplicitSolver::new(LinearMpm, grid, law, locking, NoUpdate, c, newton(0.0));
        footing_run(solver, points, &footing, f)
    }))
}

/// The footing on the children of (`n`/2)² × 2 six-node triangles (node
/// spacing as the grid's; two more parent rows above the surface), 3
/// points per child below the surface.
///
/// # Errors
/// As [`footing_grid`].
pub fn footing_triangles<K, T>(f: &Footing, locking: T) -> Result<FootingCurve, SolverError>
where
    K: LockingTreatment<2, mpm_mesh::SimplexMesh<2>>,
    T: FnOnce(&PatchMesh<2>) -> K,
{
    // Two parent rows above the surface leave room for the heave.
    let h = 2.0 * footing_spacing(f)?;
    let parents = BoxMesh::new(
        Vector2::zeros(),
        Vector2::new(LAYER, LAYER + 2.0 * h),
        [f.n / 2, f.n / 2 + 2],
    )
    .quadratic_mesh()?;
    let patches = PatchMesh::from_parents(&parents)?;
    let mesh = patches.mesh().clone();
    let (mut position, mut volume) = (Vec::new(), Vec::new());
    for e in 0..mesh.element_count() {
        let v = mesh.element_nodes(e);
        for k in 0..3 {
            let x = (0..3).fold(Vector2::zeros(), |acc, a| {
                acc + mesh.nodes()[v[a]] * if a == k { 2.0 / 3.0 } else { 1.0 / 6.0 }
            });
            if x[1] < LAYER {
                position.push(x);
                volume.push(mesh.volumes()[e] / 3.0);
            }
        }
    }
    let n = position.len();
    let mut points = MaterialPoints::new(position, volume, 1.0, vec![(); n])?;
    points.set_gravity(Vector2::zeros());
    let (c, footing) = footing_constraints(
        mesh.nodes().iter().copied(),
        mesh.node_count(),
        f.settlement,
    );
    let treatment = locking(&patches);
    let law = footing_law(f)?;
    Ok(with_formulation!(f.formulation, F, {
        let solver: ImplicitSolver<2, Parts<LinearSimplex, F, _, K, NoUpdate, _>> =
            ImplicitSolver::new(
                LinearSimplex,
                mesh,
                law,
                treatment,
                NoUpdate,
                c,
                newton(0.0),
            );
        footing_run(solver, points, &footing, f)
    }))
}

/// The four footing runs of one refinement, in the order of
/// [`all_four`]; F-patch only when `fpatch` (it is the slow one).
///
/// # Errors
/// As [`footing_grid`].
pub fn footing_all_four(
    f: &Footing,
    fpatch: bool,
) -> Result<[Option<FootingCurve>; 4], SolverError> {
    Ok([
        Some(footing_triangles(f, |_| NoLocking)?),
        if fpatch {
            Some(footing_triangles(f, FPatch::new)?)
        } else {
            None
        },
        Some(footing_grid(f, NoLocking)?),
        Some(footing_grid(f, FBar::default())?),
    ])
}

/// The node spacing of `f`, refused unless the footing edge falls on a
/// node (`n` a multiple of 10: the triangles' parents are two spacings
/// wide) — with the edge between nodes the footing's width is not the
/// one the pressure is divided by.
fn footing_spacing(f: &Footing) -> Result<f64, SolverError> {
    if f.n == 0 || !f.n.is_multiple_of(10) {
        return Err(SolverError::InvalidInput(format!(
            "footing: n = {} must be a positive multiple of 10 so that the footing edge x = {HALF_WIDTH} is a node of the grid and of the triangles",
            f.n
        )));
    }
    Ok(LAYER / f.n as f64)
}
