//! Prescribed nodal velocities (MPoint notes, below eq. 32) and Coulomb
//! friction walls on grid faces (Bardenhagen, Brackbill & Sulsky 2000)
//! and the dashpots of absorbing boundaries (Lysmer & Kuhlemeyer 1969).

use super::absorbing::Dashpot;

/// Nodal velocity fixities: after the grid update (eq. 32) the listed
/// components are set, $\tilde v_i^{n+1} = v^{fix}_i$, and their
/// acceleration recomputed as $(\tilde v_i^{n+1} - v_i^n)/\Delta t$. A slip
/// wall fixes the normal component to zero; a clamp fixes all.
///
/// Friction walls ([`VelocityFixities::friction`]) are applied in the same
/// place, after the prescribed components ([`super::grid_update::update`]):
/// a node of a wall that moves into it loses its normal velocity and, by
/// Coulomb's law, up to μ times that in tangential velocity; a node that
/// moves away is left free.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VelocityFixities {
    /// (node, component, velocity), in the order given until
    /// [`VelocityFixities::finish`] sorts them and drops repeats.
    entries: Vec<(usize, usize, f64)>,
    /// Bit `c` of entry `n`: component `c` of node `n` is held (built by
    /// [`VelocityFixities::finish`]).
    mask: Vec<u8>,
    /// The friction walls, in the order given until
    /// [`VelocityFixities::finish`] sorts them by node and face, drops
    /// repeats (the later kept) and those whose normal component is held.
    walls: Vec<FrictionWall>,
    /// The absorbing boundaries' dashpots, in the order given until
    /// [`VelocityFixities::finish`] sorts them by node and face, drops
    /// repeats (the later kept) and those whose every component is held.
    dashpots: Vec<Dashpot>,
}

/// One node of a rigid, fixed wall with Coulomb friction: the wall lies
/// beyond the grid face normal to `axis` (the face at the upper end of the
/// axis when `upper`), so its outward normal is $\mathbf n = \pm\mathbf
/// e_{axis}$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionWall {
    /// The node.
    pub node: usize,
    /// The axis normal to the wall.
    pub axis: usize,
    /// Whether the wall is at the upper end of `axis` ($\mathbf n = +\mathbf
    /// e_{axis}$) or the lower ($-\mathbf e_{axis}$).
    pub upper: bool,
    /// The Coulomb coefficient μ ≥ 0 (0: a slip wall that lets go).
    pub mu: f64,
    /// Whether the wall acts only where a point touches it over the node
    /// (the gap check, [`super::touch`]); otherwise wherever the node has
    /// mass.
    pub gap_check: bool,
    /// Bit `c`: component `c` is tangential and not held, so friction acts
    /// on it (set by [`VelocityFixities::finish`]).
    tangential: u8,
}

impl FrictionWall {
    /// The components friction acts on: those tangential to the wall that
    /// no fixity holds (after [`VelocityFixities::finish`]).
    #[inline]
    pub fn slides(&self, component: usize) -> bool {
        component < 8 && self.tangential >> component & 1 == 1
    }
}

impl VelocityFixities {
    /// No fixities.
    pub fn new() -> Self {
        Self::default()
    }

    /// Fixes component `component` of `nodes` at zero velocity.
    pub fn fix(&mut self, nodes: impl IntoIterator<Item = usize>, component: usize) -> &mut Self {
        self.prescribe(nodes, component, 0.0)
    }

    /// Prescribes component `component` of `nodes` to `velocity`; a later
    /// call on the same component replaces the value.
    pub fn prescribe(
        &mut self,
        nodes: impl IntoIterator<Item = usize>,
        component: usize,
        velocity: f64,
    ) -> &mut Self {
        self.entries
            .extend(nodes.into_iter().map(|n| (n, component, velocity)));
        self
    }

    /// Makes `nodes` nodes of a friction wall with coefficient `mu` beyond
    /// the grid face normal to `axis` (the upper face of the axis when
    /// `upper`); a later wall on the same node and face replaces the
    /// earlier. A wall acts on the components no fixity holds: where a
    /// fixity holds its normal component the node is held, not a wall.
    pub fn friction(
        &mut self,
        nodes: impl IntoIterator<Item = usize>,
        axis: usize,
        upper: bool,
        mu: f64,
    ) -> &mut Self {
        self.add_walls(nodes, axis, upper, mu, false)
    }

    /// Friction walls as [`Self::friction`] that act on a node only where
    /// a point touches the wall over it (the gap check,
    /// [`super::touch::WallTouch`]).
    pub fn friction_gap_checked(
        &mut self,
        nodes: impl IntoIterator<Item = usize>,
        axis: usize,
        upper: bool,
        mu: f64,
    ) -> &mut Self {
        self.add_walls(nodes, axis, upper, mu, true)
    }

    fn add_walls(
        &mut self,
        nodes: impl IntoIterator<Item = usize>,
        axis: usize,
        upper: bool,
        mu: f64,
        gap_check: bool,
    ) -> &mut Self {
        self.walls
            .extend(nodes.into_iter().map(|node| FrictionWall {
                node,
                axis,
                upper,
                mu,
                gap_check,
                tangential: 0,
            }));
        self
    }

    /// Makes the `(node, tributary area)` pairs of `nodes` nodes of an
    /// absorbing boundary on the grid face normal to `axis`, in a medium
    /// of normal impedance `rho_cp` $=\rho c_p$ and tangential impedance
    /// `rho_cs` $=\rho c_s$ (Pa·s/m; [`Dashpot`],
    /// [`super::absorbing::tributary_area`]); a later boundary on the same
    /// node and face replaces the earlier. Its dashpots act on the
    /// components no fixity holds.
    pub fn absorbing(
        &mut self,
        nodes: impl IntoIterator<Item = (usize, f64)>,
        axis: usize,
        rho_cp: f64,
        rho_cs: f64,
    ) -> &mut Self {
        self.absorbing_with_springs(nodes, axis, (rho_cp, rho_cs), (0.0, 0.0))
    }

    /// As [`Self::absorbing`], the impedances `(ρ c_p, ρ c_s)` (Pa·s/m),
    /// with a spring layer behind the dashpots of stiffnesses per unit
    /// area `(k_n, k_t)` (Pa/m; [`Dashpot::with_springs`]): each node
    /// carries the forces $-k A_i u$ of its accumulated displacement $u$.
    pub fn absorbing_with_springs(
        &mut self,
        nodes: impl IntoIterator<Item = (usize, f64)>,
        axis: usize,
        (rho_cp, rho_cs): (f64, f64),
        (k_n, k_t): (f64, f64),
    ) -> &mut Self {
        self.dashpots.extend(nodes.into_iter().map(|(node, area)| {
            Dashpot::new(node, axis, area, rho_cp, rho_cs).with_springs(area, k_n, k_t)
        }));
        self
    }

    /// Sorts the fixities by node and component, a later value of a
    /// repeated component replacing the earlier one, and the walls by
    /// node and face alike (the solver calls it once when it takes the
    /// fixities; calling it again changes nothing).
    pub fn finish(&mut self) {
        // Stable sort keeps the last value of a repeated component last.
        self.entries.sort_by_key(|&(n, c, _)| (n, c));
        let mut out: Vec<(usize, usize, f64)> = Vec::with_capacity(self.entries.len());
        for e in self.entries.drain(..) {
            match out.last_mut() {
                Some(last) if (last.0, last.1) == (e.0, e.1) => *last = e,
                _ => out.push(e),
            }
        }
        self.entries = out;
        self.mask.clear();
        if let Some(&(last, _, _)) = self.entries.last() {
            self.mask.resize(last + 1, 0);
        }
        for &(n, c, _) in &self.entries {
            // Components beyond the mask's bits (D > 8) are caught by the
            // solver's check of c < D.
            if c < 8 {
                self.mask[n] |= 1 << c;
            }
        }
        self.finish_walls();
        self.finish_dashpots();
    }

    /// The dashpots sorted by node and face, the later of a repeated one
    /// kept, each one's free components marked and those with none
    /// dropped.
    fn finish_dashpots(&mut self) {
        self.dashpots.sort_by_key(|d| (d.node, d.axis));
        let mut out: Vec<Dashpot> = Vec::with_capacity(self.dashpots.len());
        for d in self.dashpots.drain(..) {
            match out.last_mut() {
                Some(last) if (last.node, last.axis) == (d.node, d.axis) => *last = d,
                _ => out.push(d),
            }
        }
        for d in &mut out {
            d.free = (0..8)
                .filter(|&c| self.held(d.node, c).is_none())
                .fold(0, |bits, c| bits | 1 << c);
        }
        self.dashpots = out;
    }

    /// The walls sorted by node and face, the later of a repeated one
    /// kept, those whose normal component a fixity holds dropped, and
    /// each one's sliding components marked.
    fn finish_walls(&mut self) {
        self.walls.sort_by_key(|w| (w.node, w.axis, w.upper));
        let mut out: Vec<FrictionWall> = Vec::with_capacity(self.walls.len());
        for w in self.walls.drain(..) {
            match out.last_mut() {
                Some(last) if (last.node, last.axis, last.upper) == (w.node, w.axis, w.upper) => {
                    *last = w;
                }
                _ => out.push(w),
            }
        }
        out.retain(|w| self.held(w.node, w.axis).is_none());
        for w in &mut out {
            w.tangential = (0..8)
                .filter(|&c| c != w.axis && self.held(w.node, c).is_none())
                .fold(0, |bits, c| bits | 1 << c);
        }
        self.walls = out;
    }

    /// The prescribed velocity of component `component` of `node`, if it is
    /// held (after [`VelocityFixities::finish`]; `None` before). A bit test
    /// for a node without fixities, a binary search otherwise.
    #[inline]
    pub fn held(&self, node: usize, component: usize) -> Option<f64> {
        let held = component < 8 && self.mask.get(node).is_some_and(|m| m >> component & 1 == 1);
        if !held {
            return None;
        }
        self.entries
            .binary_search_by_key(&(node, component), |&(n, c, _)| (n, c))
            .ok()
            .map(|i| self.entries[i].2)
    }

    /// The fixed components: sorted by node and component after
    /// [`VelocityFixities::finish`], in the order given before.
    pub fn entries(&self) -> &[(usize, usize, f64)] {
        &self.entries
    }

    /// The friction walls: sorted by node and face after
    /// [`VelocityFixities::finish`], in the order given before.
    pub fn walls(&self) -> &[FrictionWall] {
        &self.walls
    }

    /// The absorbing boundaries' dashpots: sorted by node and face after
    /// [`VelocityFixities::finish`], in the order given before.
    pub fn dashpots(&self) -> &[Dashpot] {
        &self.dashpots
    }

    /// Number of fixed components.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing is fixed (friction walls and dashpots aside).
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn later_values_replace_earlier_ones() {
        let mut f = VelocityFixities::new();
        f.fix([3, 1], 0).prescribe([3], 0, 2.0).fix([3], 1);
        f.finish();
        assert_eq!(f.entries(), &[(1, 0, 0.0), (3, 0, 2.0), (3, 1, 0.0)]);
        assert_eq!(f.held(3, 0), Some(2.0));
        assert_eq!(f.held(3, 1), Some(0.0));
        assert_eq!(f.held(1, 0), Some(0.0));
        for (n, c) in [(1, 1), (0, 0), (2, 0), (3, 2), (4, 0), (3, 9)] {
            assert_eq!(f.held(n, c), None, "({n}, {c})");
        }
    }

    /// A later wall on a node's face replaces the earlier; a wall whose
    /// normal a fixity holds is dropped; held tangential components do
    /// not slide.
    #[test]
    fn walls_keep_the_later_and_yield_to_held_components() {
        let mut f = VelocityFixities::new();
        f.friction([4, 2, 7], 1, false, 0.1)
            .friction([4], 1, false, 0.3)
            .friction([4], 0, true, 0.2)
            .fix([2], 1)
            .fix([7], 0);
        f.finish();
        let walls: Vec<_> = f
            .walls()
            .iter()
            .map(|w| (w.node, w.axis, w.upper, w.mu))
            .collect();
        assert_eq!(
            walls,
            [(4, 0, true, 0.2), (4, 1, false, 0.3), (7, 1, false, 0.1)]
        );
        let [a, b, c] = f.walls() else { panic!() };
        assert!(!a.slides(0) && a.slides(1) && a.slides(2));
        assert!(b.slides(0) && !b.slides(1));
        assert!(!c.slides(0) && !c.slides(1) && c.slides(2));
    }
}
