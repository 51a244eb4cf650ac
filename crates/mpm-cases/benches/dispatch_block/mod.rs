//! The block under gravity of the `dispatch` benchmark, shared with its
//! `--count` mode ([`count`], instruction counts of one path): its scene,
//! its problem, points with given histories, its grid and a deterministic
//! increment. Included by `#[path]` (a file directly in `benches/` would be
//! a benchmark of its own).
#![allow(dead_code, clippy::unwrap_used)]

pub mod count;

use mpm_cases::body::InitialDomain;
use mpm_cases::scene::{self, Problem};
use mpm_mesh::RegularGrid;
use mpm_solver::MaterialPoints;

/// A block under gravity on a regular grid, base fixed, sides on rollers.
pub fn scene_text(dim: usize, basis: &str, model: &str) -> String {
    let (origin, size, cells, upper) = if dim == 2 {
        ("[0.0, 0.0]", "[1.0, 1.0]", "[32, 32]", "[1.0, 0.75]")
    } else {
        (
            "[0.0, 0.0, 0.0]",
            "[1.0, 1.0, 1.0]",
            "[10, 10, 10]",
            "[1.0, 1.0, 0.7]",
        )
    };
    let lower = if dim == 2 {
        "[0.0, 0.0]"
    } else {
        "[0.0, 0.0, 0.0]"
    };
    let g = if dim == 2 {
        "[0.0, -10.0]"
    } else {
        "[0.0, 0.0, -10.0]"
    };
    let base = if dim == 2 { "y_min" } else { "z_min" };
    let yield_stress = if model == "von_mises" {
        "yield_stress = 4e3\nhardening = 1e4\n"
    } else {
        ""
    };
    let rule = if basis == "gimp" { "stretch" } else { "none" };
    format!(
        r#"
[mesh]
origin = {origin}
size = {size}
cells = {cells}

[[material]]
name = "soil"
model = "{model}"
youngs_modulus = 1e6
poisson_ratio = 0.3
density = 2000.0
{yield_stress}
[[body]]
name = "block"
material = "soil"
region = {{ box = {{ lower = {lower}, upper = {upper} }} }}
points_per_cell = 2

[[boundary]]
set = "{base}"
kind = "fixed"

[[boundary]]
set = "x_min"
kind = "roller"

[[boundary]]
set = "x_max"
kind = "roller"

[[load]]
kind = "gravity"
acceleration = {g}

[solver]
basis = "{basis}"
domain_update = "{rule}"
steps = 1
"#
    )
}

pub fn problem<const D: usize>(basis: &str, model: &str) -> Problem<D> {
    let text = scene_text(D, basis, model);
    let (scene, src) = scene::parse(&text, "dispatch.toml", &[]).unwrap();
    Problem::<D>::build(&scene, &src, scene.solver.padding()).unwrap()
}

/// The problem's points with histories `history(point)`.
pub fn points<const D: usize, B: InitialDomain<D>, H: Copy + Default>(
    p: &Problem<D>,
    history: impl Fn(usize) -> H,
) -> MaterialPoints<D, H, B::Domain> {
    let domains = (p.position.iter().zip(&p.half_lengths))
        .map(|(x, l)| B::initial_domain(x, l))
        .collect();
    let mut points =
        MaterialPoints::new(p.position.clone(), p.volume.clone(), 0.0, domains).unwrap();
    points.mass.clone_from(&p.mass);
    points.body_force.clone_from(&p.body_force);
    points.point_force.clone_from(&p.point_forces);
    for (k, h) in points.history.iter_mut().enumerate() {
        *h = history(k);
    }
    points
}

/// The scene's regular grid (every scene here is on one).
pub fn grid_of<const D: usize>(p: &Problem<D>) -> RegularGrid<D> {
    match &p.mesh {
        scene::build::SceneMesh::Grid(g) => g.clone(),
        scene::build::SceneMesh::Simplex(_) => unreachable!("grid scenes only"),
    }
}

/// A deterministic increment of the free dofs, large enough (1 % strain
/// at the grid spacing) that von Mises yields at the base.
pub fn increment(n: usize, h: f64) -> Vec<f64> {
    (0..n)
        .map(|k| 1e-2 * h * ((k * 31 + 7) as f64).sin())
        .collect()
}
