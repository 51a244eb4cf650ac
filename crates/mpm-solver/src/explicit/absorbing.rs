//! Absorbing boundaries on grid faces: the viscous boundary of Lysmer &
//! Kuhlemeyer (1969), one normal and one tangential dashpot per node,
//! applied semi-implicitly after the friction walls, with an optional
//! spring layer (a normal and a tangential spring per node on the node's
//! accumulated displacement) so a body under gravity does not sink.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use super::grid::GridState;

/// One node of a viscous (absorbing) boundary on the grid face normal to
/// `axis`: the dashpots $C_n = \rho c_p A_i$ on the normal component and
/// $C_t = \rho c_s A_i$ on each tangential one (N·s/m; per unit
/// thickness in 2D), $A_i$ the node's tributary area on the face
/// ([`tributary_area`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dashpot {
    /// The node.
    pub node: usize,
    /// The axis normal to the face.
    pub axis: usize,
    /// $C_n = \rho c_p A_i$, the normal dashpot.
    pub normal: f64,
    /// $C_t = \rho c_s A_i$, each tangential dashpot.
    pub tangential: f64,
    /// $K_n = k_n A_i$ (N/m), the normal spring of the spring layer
    /// (zero without one).
    pub normal_spring: f64,
    /// $K_t = k_t A_i$ (N/m), each tangential spring.
    pub tangential_spring: f64,
    /// Bit `c`: component `c` is not held, so its dashpot acts (set by
    /// [`super::VelocityFixities::finish`]).
    pub(super) free: u8,
}

impl Dashpot {
    /// A dashpot on `node` of the face normal to `axis` whose tributary
    /// area is `area`, for a medium of normal impedance $\rho c_p$ and
    /// tangential impedance $\rho c_s$ (Pa·s/m).
    pub fn new(node: usize, axis: usize, area: f64, rho_cp: f64, rho_cs: f64) -> Self {
        Self {
            node,
            axis,
            normal: rho_cp * area,
            tangential: rho_cs * area,
            normal_spring: 0.0,
            tangential_spring: 0.0,
            free: 0,
        }
    }

    /// The same dashpot with the springs of a layer of stiffnesses `k_n`
    /// and `k_t` per unit area (Pa/m) on its `area`.
    pub fn with_springs(self, area: f64, k_n: f64, k_t: f64) -> Self {
        Self {
            normal_spring: k_n * area,
            tangential_spring: k_t * area,
            ..self
        }
    }

    /// The spring of `component`: $K_n$ on the normal, $K_t$ on the others.
    #[inline]
    pub fn spring(&self, component: usize) -> f64 {
        self.along(component, self.normal_spring, self.tangential_spring)
    }

    /// `normal` on the face's normal component, `tangential` on the others.
    #[inline]
    fn along(&self, component: usize, normal: f64, tangential: f64) -> f64 {
        if component == self.axis {
            normal
        } else {
            tangential
        }
    }

    /// Whether the dashpot has a spring.
    pub fn has_springs(&self) -> bool {
        self.normal_spring != 0.0 || self.tangential_spring != 0.0
    }

    /// Whether the dashpot acts on `component`: one that no fixity holds
    /// (after [`super::VelocityFixities::finish`]).
    #[inline]
    pub fn damps(&self, component: usize) -> bool {
        component < 8 && self.free >> component & 1 == 1
    }

    /// The dashpot of `component`: $C_n$ on the normal, $C_t$ on the others.
    #[inline]
    pub fn coefficient(&self, component: usize) -> f64 {
        self.along(component, self.normal, self.tangential)
    }

    /// Whether the coefficients are finite and non-negative.
    pub fn is_valid(&self) -> bool {
        [
            self.normal,
            self.tangential,
            self.normal_spring,
            self.tangential_spring,
        ]
        .iter()
        .all(|c| c.is_finite() && *c >= 0.0)
    }
}

/// The tributary area of `node` on the face of `grid` normal to `axis`:
/// the product over the in-face axes of the half-spacings on each side of
/// the node, $h$ inside the grid and $h/2$ at its ends (2D: a length, the
/// area per unit thickness; 1 in 1D).
///
/// # Panics
/// `node` is not a node of `grid`.
pub fn tributary_area<const D: usize>(grid: &RegularGrid<D>, node: usize, axis: usize) -> f64 {
    let index = grid.node_index(node).expect("a node of the grid");
    let cells = grid.cells_per_axis();
    (0..D)
        .filter(|&a| a != axis)
        .map(|a| {
            let h = grid.spacing()[a];
            let sides = usize::from(index[a] > 0) + usize::from(index[a] < cells[a]);
            0.5 * h * sides as f64
        })
        .product()
}

/// The viscous boundary (Lysmer & Kuhlemeyer 1969) at the nodes of
/// `dashpots`, with its spring layer, semi-implicitly: the dashpot force
/// $-C\,v'$ and the spring force $-K\,u^{n+1}$, $u^{n+1} = u^n + \Delta
/// t\,v'$ the node's accumulated displacement (`displacement`, one per
/// dashpot), are taken with the velocity they leave, so each free
/// component becomes
/// $v'_c = (m_i\tilde v_c - \Delta t\,K_c u^n_c)/(m_i + \Delta t\,C_c +
/// \Delta t^2 K_c)$ — unconditionally stable, however large $C$, $K$ or
/// $\Delta t$ — and $u_c$ advances by $\Delta t\,v'_c$. Nodes without mass
/// are skipped (their displacement stays); a node of two faces (a corner)
/// meets both in turn. Only the nodes for which `counted` is true (on
/// several ranks, those the rank owns) advance their displacement and
/// book their energy: returned, the dashpot work plus the spring's
/// numerical dissipation, the impulse times the velocity it leaves less
/// the change of the stored energy $\tfrac12 K_c u_c^2$,
/// $\sum_c \Delta t\,(C_c + \tfrac12\Delta t\,K_c)\,{v'_c}^2$ (the
/// convention of the friction work, [`super::WallWork`]).
///
/// # Panics
/// `displacement` is shorter than `dashpots`.
pub fn dashpots<const D: usize>(
    grid: &mut GridState<D>,
    dashpots: &[Dashpot],
    displacement: &mut [SVector<f64, D>],
    dt: f64,
    counted: impl Fn(usize) -> bool,
) -> f64 {
    let mut absorbed = 0.0;
    for (d, u) in dashpots.iter().zip(displacement.iter_mut()) {
        let i = d.node;
        if !(i >= grid.lo && i < grid.hi && grid.mass[i] > 0.0) {
            continue;
        }
        let m = grid.mass[i];
        let v = &mut grid.velocity[i].new;
        let owned = counted(i);
        let mut work = 0.0;
        for c in (0..D).filter(|&c| d.damps(c)) {
            let (damping, spring) = (dt * d.coefficient(c), dt * dt * d.spring(c));
            v[c] = (m * v[c] - spring * u[c] / dt) / (m + damping + spring);
            work += (damping + 0.5 * spring) * v[c] * v[c];
            if owned {
                u[c] += dt * v[c];
            }
        }
        if owned {
            absorbed += work;
        }
    }
    absorbed
}

/// The energy stored in the springs of `dashpots` at their nodes'
/// displacements `displacement`, $\sum_i\sum_c \tfrac12 K_c u_c^2$ over the
/// free components.
pub fn spring_energy<const D: usize>(
    dashpots: &[Dashpot],
    displacement: &[SVector<f64, D>],
) -> f64 {
    dashpots
        .iter()
        .zip(displacement)
        .filter(|(d, _)| d.has_springs())
        .map(|(d, u)| {
            (0..D)
                .filter(|&c| d.damps(c))
                .map(|c| 0.5 * d.spring(c) * u[c] * u[c])
                .sum::<f64>()
        })
        // From +0: an empty `sum` of floats is −0, which the summary
        // would write as such.
        .fold(0.0, |total, e| total + e)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::explicit::VelocityFixities;
    use nalgebra::{Vector2, Vector3};

    /// 2D: h inside, h/2 at the ends; 3D: the product of both in-face
    /// half-spacings on each side.
    #[test]
    fn tributary_areas_are_the_half_spacings_on_each_side() {
        let g = RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.25), [4, 2]).unwrap();
        let base: Vec<f64> = (0..5)
            .map(|i| tributary_area(&g, g.node_id([i, 0]).unwrap(), 1))
            .collect();
        assert_eq!(base, [0.25, 0.5, 0.5, 0.5, 0.25]);
        let side: Vec<f64> = (0..3)
            .map(|j| tributary_area(&g, g.node_id([4, j]).unwrap(), 0))
            .collect();
        assert_eq!(side, [0.125, 0.25, 0.125]);
        let g = RegularGrid::new(Vector3::zeros(), Vector3::new(1.0, 2.0, 4.0), [2, 2, 1]).unwrap();
        let at = |i, j| tributary_area(&g, g.node_id([i, j, 0]).unwrap(), 2);
        assert_eq!([at(0, 0), at(1, 0), at(1, 1)], [0.5, 1.0, 2.0]);
        let total: f64 = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| at(i, j))
            .sum();
        assert_eq!(total, 2.0 * 4.0);
    }

    /// A grid of one node of mass 2 moving at (1, −3).
    fn one_node() -> GridState<2> {
        let mut grid = GridState::<2>::new(1);
        grid.mass[0] = 2.0;
        grid.velocity[0].new = SVector::from([1.0, -3.0]);
        grid.hi = 1;
        grid
    }

    /// The normal component meets C_n, the tangential C_t, a held
    /// component neither; the work is Σ Δt C v'² on counted nodes only.
    #[test]
    fn each_free_component_is_damped_semi_implicitly() {
        let mut grid = one_node();
        let mut f = VelocityFixities::new();
        f.absorbing([(0, 0.5)], 1, 8.0, 4.0);
        f.finish();
        let dt = 0.5;
        // C_n = 4, C_t = 2: v_y = 2·(−3)/(2 + 2), v_x = 2·1/(2 + 1).
        let mut u = vec![SVector::zeros(); 1];
        let work = dashpots(&mut grid, f.dashpots(), &mut u, dt, |_| true);
        let v = grid.velocity[0].new;
        assert!((v - Vector2::new(2.0 / 3.0, -1.5)).norm() < 1e-15, "{v}");
        let expected = dt * (4.0 * 1.5 * 1.5 + 2.0 * (2.0 / 3.0) * (2.0 / 3.0));
        assert!((work - expected).abs() < 1e-14);

        grid.velocity[0].new = SVector::from([1.0, -3.0]);
        let mut f = VelocityFixities::new();
        f.absorbing([(0, 0.5)], 1, 8.0, 4.0).fix([0], 0);
        f.finish();
        let work = dashpots(&mut grid, f.dashpots(), &mut u, dt, |_| false);
        assert_eq!(grid.velocity[0].new, Vector2::new(1.0, -1.5));
        assert_eq!(work, 0.0);
    }

    /// With springs: v' = (m ṽ − Δt K u)/(m + Δt C + Δt² K) per free
    /// component, u advances by Δt v' on counted nodes only, the work is
    /// Σ Δt (C + ½ Δt K) v'², and the stored energy ½ K u².
    #[test]
    fn springs_and_dashpots_are_solved_together() {
        let mut grid = one_node();
        let mut f = VelocityFixities::new();
        f.absorbing_with_springs([(0, 0.5)], 1, (8.0, 4.0), (16.0, 4.0));
        f.finish();
        let dt = 0.5;
        let mut u = vec![SVector::from([0.5, -1.0])];
        // C_n = 4, C_t = 2, K_n = 8, K_t = 2.
        let work = dashpots(&mut grid, f.dashpots(), &mut u, dt, |_| true);
        let vx = (2.0 * 1.0 - dt * 2.0 * 0.5) / (2.0 + dt * 2.0 + dt * dt * 2.0);
        let vy = (2.0 * -3.0 + dt * 8.0) / (2.0 + dt * 4.0 + dt * dt * 8.0);
        let v = grid.velocity[0].new;
        assert!((v - Vector2::new(vx, vy)).norm() < 1e-15, "{v}");
        assert!((u[0] - Vector2::new(0.5 + dt * vx, -1.0 + dt * vy)).norm() < 1e-15);
        let expected = dt * ((2.0 + 0.5 * dt * 2.0) * vx * vx + (4.0 + 0.5 * dt * 8.0) * vy * vy);
        assert!((work - expected).abs() < 1e-14);
        let stored = 0.5 * 2.0 * u[0].x * u[0].x + 0.5 * 8.0 * u[0].y * u[0].y;
        assert!((spring_energy(f.dashpots(), &u) - stored).abs() < 1e-15);
        let before = u[0];
        assert_eq!(
            dashpots(&mut grid, f.dashpots(), &mut u, dt, |_| false),
            0.0
        );
        assert_eq!(u[0], before);
    }
}
