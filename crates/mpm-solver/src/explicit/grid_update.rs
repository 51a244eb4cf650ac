//! Stage 2, the grid update: nodal velocity (eq. 30), acceleration (eq.
//! 31), updated velocity (eq. 32), the velocity fixities, the friction
//! walls and the absorbing boundaries.

use nalgebra::SVector;
use rayon::prelude::*;

use super::absorbing;
use super::fixities::{FrictionWall, VelocityFixities};
use super::grid::{GridBuffer, NodeSums};
pub use super::grid::{GridState, NodeVelocity};

/// Nodes per parallel task of the grid update.
const NODES_PER_TASK: usize = 4096;

/// The energy the friction walls and the absorbing boundaries took from
/// the grid (J; per unit thickness in 2D), every part positive.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WallWork {
    /// Dissipated by friction: per sliding node the friction impulse
    /// times the tangential velocity it leaves,
    /// $m_i\,\|\mathbf v_t'\|\,(\|\mathbf v_t\| - \|\mathbf v_t'\|)$.
    pub friction: f64,
    /// Lost in the impacts: per node the wall acts on, the kinetic energy
    /// of the jump from the velocity it brought to the step to the one the
    /// wall leaves, $\tfrac12 m_i\|\mathbf v'_i - \mathbf v^n_i\|^2$ —
    /// the normal velocity stopped, and in stick the tangential one too
    /// (docs/src/theory/contact.md, "Energy bookkeeping").
    pub impact: f64,
    /// Absorbed by the dashpots of the absorbing boundaries: per node
    /// and free component the dashpot's impulse times the velocity it
    /// leaves, $\Delta t\,C_c\,{v'_c}^2$ ([`absorbing::dashpots`]).
    pub absorbed: f64,
}

impl WallWork {
    /// Every part added.
    pub fn plus(self, other: Self) -> Self {
        Self {
            friction: self.friction + other.friction,
            impact: self.impact + other.impact,
            absorbed: self.absorbed + other.absorbed,
        }
    }
}

/// Sums the threads' `buffers` into `grid` and updates the velocities
/// (eqs. 30–32); nodes without mass get zero velocity. Then the fixities:
/// $\tilde v^{n+1}_i$ is set to the prescribed value, which recomputes the
/// acceleration as the notes require (a fixity on a node without mass has
/// no effect: no point reads it); then the friction walls
/// ([`friction_walls`]) and the absorbing boundaries
/// ([`absorbing::dashpots`]) with their springs' displacements `springs`
/// (one per dashpot); the gap-checked walls act where `touched` (one flag
/// per node, [`super::touch::WallTouch`]). Returns what the walls and dashpots took
/// from the nodes for which `counted` is true (on several ranks, those the
/// rank owns).
pub fn update<const D: usize>(
    buffers: &[GridBuffer<D>],
    grid: &mut GridState<D>,
    dt: f64,
    fixities: &VelocityFixities,
    springs: &mut [SVector<f64, D>],
    touched: &[bool],
    counted: impl Fn(usize) -> bool,
) -> WallWork {
    let lo = buffers.iter().map(|b| b.lo).min().unwrap_or(usize::MAX);
    let hi = buffers.iter().map(|b| b.hi).max().unwrap_or(0);
    if lo >= hi {
        grid.lo = 0;
        grid.hi = 0;
        return WallWork::default();
    }
    grid.lo = lo;
    grid.hi = hi;
    let (mass, velocity) = (&mut grid.mass[lo..hi], &mut grid.velocity[lo..hi]);
    (
        mass.par_chunks_mut(NODES_PER_TASK),
        velocity.par_chunks_mut(NODES_PER_TASK),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(task, (mass, velocity))| {
            let start = lo + task * NODES_PER_TASK;
            for (k, (m_out, v_out)) in mass.iter_mut().zip(velocity.iter_mut()).enumerate() {
                let i = start + k;
                let mut sum = NodeSums::<D>::ZERO;
                for b in buffers {
                    if i >= b.lo && i < b.hi {
                        let n = &b.nodes[i];
                        sum.mass += n.mass;
                        sum.momentum += n.momentum;
                        sum.force += n.force;
                    }
                }
                *m_out = sum.mass;
                *v_out = if sum.mass > 0.0 {
                    let v = sum.momentum / sum.mass;
                    NodeVelocity {
                        old: v,
                        new: v + sum.force * (dt / sum.mass),
                    }
                } else {
                    NodeVelocity::default()
                };
            }
        });
    for &(node, component, value) in fixities.entries() {
        if node >= lo && node < hi && grid.mass[node] > 0.0 {
            grid.velocity[node].new[component] = value;
        }
    }
    let walls = friction_walls(grid, fixities.walls(), touched, &counted);
    WallWork {
        absorbed: absorbing::dashpots(grid, fixities.dashpots(), springs, dt, &counted),
        ..walls
    }
}

/// Coulomb friction against rigid, fixed walls at the nodes of `walls`
/// (Bardenhagen, Brackbill & Sulsky 2000, their contact algorithm with the
/// wall as the second body, of zero velocity): a node with mass whose
/// updated velocity $\tilde{\mathbf v}$ moves into its wall, $\tilde v_n =
/// \tilde{\mathbf v}\cdot\mathbf n > 0$ ($\mathbf n$ the wall's outward
/// normal), loses that normal velocity, and its tangential velocity
/// $\tilde{\mathbf v}_t$ (the components no fixity holds) shrinks by
/// $\mu\tilde v_n$ — the impulse $\mu m_i\tilde v_n$, μ times the
/// normal one — but not past zero (stick):
/// $\mathbf v_t' = \tilde{\mathbf v}_t\,\max(0, 1 - \mu\tilde v_n/\|\tilde{\mathbf v}_t\|)$.
/// A node that moves away from its wall, or along it, is left free: the
/// wall lets go; so is a node of a gap-checked wall ([`FrictionWall::gap_check`])
/// that no point touches (`touched[node]` false). Walls follow one
/// another in their order (a corner node of two walls meets both, and
/// its impact is booked once, from its velocity after both). Returns the
/// [`WallWork`] of the nodes for which `counted` is true.
pub fn friction_walls<const D: usize>(
    grid: &mut GridState<D>,
    walls: &[FrictionWall],
    touched: &[bool],
    counted: impl Fn(usize) -> bool,
) -> WallWork {
    let mut work = WallWork::default();
    // The last node whose impact was booked, and how much (walls are
    // sorted by node, so a corner's walls follow one another).
    let mut booked: Option<(usize, f64)> = None;
    for w in walls {
        let i = w.node;
        if !(i >= grid.lo && i < grid.hi && grid.mass[i] > 0.0) {
            continue;
        }
        if w.gap_check && touched.get(i) != Some(&true) {
            continue;
        }
        let outward = if w.upper { 1.0 } else { -1.0 };
        let v = &mut grid.velocity[i];
        let approach = outward * v.new[w.axis];
        if approach <= 0.0 {
            continue;
        }
        v.new[w.axis] = 0.0;
        let sliding = (0..D).filter(|&c| w.slides(c));
        let speed = sliding
            .clone()
            .map(|c| v.new[c] * v.new[c])
            .sum::<f64>()
            .sqrt();
        let left = (speed - w.mu * approach).max(0.0);
        if speed > 0.0 {
            let scale = left / speed;
            sliding.for_each(|c| v.new[c] *= scale);
        }
        if counted(i) {
            let m = grid.mass[i];
            work.friction += m * left * (speed - left);
            let impact = 0.5 * m * (v.new - v.old).norm_squared();
            let before = booked.filter(|b| b.0 == i).map_or(0.0, |b| b.1);
            work.impact += impact - before;
            booked = Some((i, impact));
        }
    }
    work
}

/// Material-point fixities on the grid: the updated grid velocities are
/// corrected so that each held point's interpolated velocity component
/// $\sum_i w_{ip}\tilde v_{i,c}$ equals its prescribed value, with the
/// smallest change of kinetic energy (lumped mass):
/// $\tilde v_{i,c} \mathrel{+}= \lambda_p w_{ip}/m_i$,
/// $\lambda_p = (v^{fix}_p - \sum_i w_{ip}\tilde v_{i,c}) / \sum_i w_{ip}^2/m_i$
/// — a Lagrange multiplier per held point, $\lambda_p/\Delta t$ its
/// reaction force — by Gauss–Seidel sweeps over the held points (which
/// couple where they share nodes) until every constraint holds to 1e-12 of
/// the velocity scale or 100 sweeps. Nodes with a nodal fixity on the
/// component do not move. `pairs[ends[k-1]..ends[k]]` (from 0 for the
/// first) are held point k's (node, weight) pairs.
///
/// Returns the largest remaining violation.
pub fn hold_points<const D: usize>(
    grid: &mut GridState<D>,
    held: &[(usize, usize, f64)],
    pairs: &[(usize, f64)],
    ends: &[usize],
    fixities: &VelocityFixities,
) -> f64 {
    let scale = velocity_scale(grid, held);
    hold_points_to(grid, held, (pairs, ends), fixities, scale)
}

/// The velocity scale of [`hold_points`]' tolerance: the largest held
/// value or updated grid velocity component.
pub fn velocity_scale<const D: usize>(grid: &GridState<D>, held: &[(usize, usize, f64)]) -> f64 {
    held.iter()
        .map(|h| h.2.abs())
        .fold(0.0, f64::max)
        .max(
            grid.velocity[grid.lo..grid.hi]
                .iter()
                .map(|v| v.new.amax())
                .fold(0.0, f64::max),
        )
        .max(f64::MIN_POSITIVE)
}

/// [`hold_points`] to the tolerance 1e-12 × `scale`.
pub fn hold_points_to<const D: usize>(
    grid: &mut GridState<D>,
    held: &[(usize, usize, f64)],
    (pairs, ends): (&[(usize, f64)], &[usize]),
    fixities: &VelocityFixities,
    scale: f64,
) -> f64 {
    let stencils = ends.iter().scan(0, |start, &end| {
        let s = &pairs[*start..end];
        *start = end;
        Some(s)
    });
    let fixed = |node: usize, c: usize| {
        fixities
            .entries()
            .binary_search_by(|&(n, k, _)| (n, k).cmp(&(node, c)))
            .is_ok()
    };
    let mut worst = 0.0;
    for _ in 0..100 {
        worst = 0.0f64;
        for (&(_, c, target), stencil) in held.iter().zip(stencils.clone()) {
            let (mut value, mut denominator) = (0.0, 0.0);
            for &(i, w) in stencil {
                value += w * grid.velocity[i].new[c];
                if grid.mass[i] > 0.0 && !fixed(i, c) {
                    denominator += w * w / grid.mass[i];
                }
            }
            let violation = target - value;
            worst = worst.max(violation.abs());
            if denominator > 0.0 {
                let lambda = violation / denominator;
                for &(i, w) in stencil {
                    if grid.mass[i] > 0.0 && !fixed(i, c) {
                        grid.velocity[i].new[c] += lambda * w / grid.mass[i];
                    }
                }
            }
        }
        if worst <= 1e-12 * scale {
            break;
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use nalgebra::SVector;

    use super::*;

    /// One node of mass 2 on the floor of a 3D grid (the wall below it,
    /// n = −e_z), its updated velocity `v`, and what the wall leaves.
    fn on_floor(v: [f64; 3], mu: f64, old: [f64; 3]) -> (SVector<f64, 3>, WallWork) {
        let mut grid = GridState::<3>::new(1);
        grid.mass[0] = 2.0;
        grid.velocity[0] = NodeVelocity {
            old: SVector::from(old),
            new: SVector::from(v),
        };
        grid.hi = 1;
        let mut walls = VelocityFixities::new();
        walls.friction([0], 2, false, mu);
        walls.finish();
        let work = friction_walls(&mut grid, walls.walls(), &[], |_| true);
        (grid.velocity[0].new, work)
    }

    /// Sliding: the normal approach 0.5 goes, the tangential speed 5
    /// (along (3, 4)/5) drops by μ·0.5 = 0.1 in its own direction; the
    /// friction work is m·|v_t'|·Δ|v_t|, the impact the energy of the jump
    /// from the velocity the node brought, (2.9, 3.9, −0.25), to the one
    /// left, (2.94, 3.92, 0).
    #[test]
    fn an_approaching_node_slides_with_coulomb_s_impulse() {
        let (v, work) = on_floor([3.0, 4.0, -0.5], 0.2, [2.9, 3.9, -0.25]);
        let expected = SVector::<f64, 3>::new(3.0, 4.0, 0.0) * (4.9 / 5.0);
        assert!((v - expected).norm() < 1e-14, "{v}");
        assert!((work.friction - 2.0 * 4.9 * 0.1).abs() < 1e-14);
        let jump = 0.04f64.powi(2) + 0.02f64.powi(2) + 0.25f64.powi(2);
        assert!((work.impact - 0.5 * 2.0 * jump).abs() < 1e-15, "{work:?}");
    }

    /// Stick: μ·v_n beyond the tangential speed stops the node; static
    /// friction does no work, and the impact is the kinetic energy of the
    /// whole velocity the node brought, tangential part included.
    #[test]
    fn a_node_sticks_when_coulomb_s_impulse_suffices() {
        let (v, work) = on_floor([0.03, -0.04, -0.5], 0.2, [0.03, -0.04, -0.1]);
        assert_eq!(v, SVector::<f64, 3>::zeros());
        assert_eq!(work.friction, 0.0);
        assert!((work.impact - 0.5 * 2.0 * (0.0025 + 0.01)).abs() < 1e-15);
    }

    /// A node moving away from the wall (or along it) is left as it is,
    /// and μ = 0 removes the normal approach only.
    #[test]
    fn a_leaving_node_is_free_and_mu_zero_only_stops_the_approach() {
        for v in [[1.0, 2.0, 0.5], [1.0, 2.0, 0.0]] {
            let (after, work) = on_floor(v, 0.5, [0.0, 0.0, -1.0]);
            assert_eq!(after, SVector::from(v));
            assert_eq!(work, WallWork::default());
        }
        let (after, work) = on_floor([1.0, 2.0, -0.5], 0.0, [1.0, 2.0, 0.0]);
        assert_eq!(after, SVector::from([1.0, 2.0, 0.0]));
        assert_eq!(work, WallWork::default());
    }

    /// A corner node of two slip walls meets both and its impact is
    /// booked once: ½ m |0 − v^n|² = ½·2·(0.25 + 1).
    #[test]
    fn a_corner_node_books_its_impact_once() {
        let mut grid = GridState::<2>::new(1);
        grid.mass[0] = 2.0;
        grid.velocity[0] = NodeVelocity {
            old: SVector::from([-0.5, -1.0]),
            new: SVector::from([-1.0, -2.0]),
        };
        grid.hi = 1;
        let mut walls = VelocityFixities::new();
        walls
            .friction([0], 0, false, 0.0)
            .friction([0], 1, false, 0.0);
        walls.finish();
        let work = friction_walls(&mut grid, walls.walls(), &[], |_| true);
        assert_eq!(grid.velocity[0].new, SVector::<f64, 2>::zeros());
        assert!((work.impact - 1.25).abs() < 1e-15, "{work:?}");
    }

    /// A gap-checked wall acts only on the nodes marked touched.
    #[test]
    fn a_gap_checked_wall_acts_only_where_touched() {
        for touched in [false, true] {
            let mut grid = GridState::<2>::new(1);
            grid.mass[0] = 1.0;
            grid.velocity[0].new = SVector::from([1.0, -1.0]);
            grid.hi = 1;
            let mut walls = VelocityFixities::new();
            walls.friction_gap_checked([0], 1, false, 0.5);
            walls.finish();
            friction_walls(&mut grid, walls.walls(), &[touched], |_| true);
            let expected = if touched { [0.5, 0.0] } else { [1.0, -1.0] };
            assert_eq!(grid.velocity[0].new, SVector::from(expected));
        }
    }

    /// On the upper face of x in 2D (n = +e_x) with y held by a fixity:
    /// the normal goes, the held component is not friction's; a node of
    /// another rank is not counted.
    #[test]
    fn held_components_do_not_slide_and_uncounted_nodes_book_nothing() {
        let mut grid = GridState::<2>::new(1);
        grid.mass[0] = 1.0;
        grid.velocity[0].new = SVector::from([0.5, 3.0]);
        grid.velocity[0].old = SVector::from([0.5, 3.0]);
        grid.hi = 1;
        let mut walls = VelocityFixities::new();
        walls.friction([0], 0, true, 0.2).fix([0], 1);
        walls.finish();
        let work = friction_walls(&mut grid, walls.walls(), &[], |_| false);
        assert_eq!(grid.velocity[0].new, SVector::from([0.0, 3.0]));
        assert_eq!(work, WallWork::default());
    }
}
