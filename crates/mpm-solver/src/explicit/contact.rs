//! Multi-field contact between deformable bodies (Bardenhagen, Brackbill
//! & Sulsky 2000, "The material-point method for granular materials",
//! CMAME 187, §3; Bardenhagen et al. 2001, "An improved contact algorithm
//! for the material point method and application to stress propagation in
//! granular material", CMES 2(4)): every point belongs to a velocity
//! field (`ExplicitPoints::field`), each field has its own nodal mass,
//! momentum, force and mass gradient on the shared grid, and at a node
//! where two fields or more have mass the fields that approach one another
//! lose their normal relative velocity and, by Coulomb's law, part of
//! their tangential one. A run without contact never enters this module:
//! the single-field stages of [`super::p2g`] and [`super::grid_update`]
//! run as before.
//!
//! At a node $i$ with fields $k$ of mass $m_k$, updated velocity
//! $\tilde{\mathbf v}_k$ (eq. 32 of the field's own sums), mass gradient
//! $\mathbf g_k = \sum_{p\in k} m_p\nabla w_{ip}$ and volume
//! $V_k = \sum_{p\in k} w_{ip}V_p$:
//!
//! - the fields meet only where two or more have mass and they fill the
//!   node, $\sum_k V_k \ge 0.99\,h^D$ ([`FILLED`]; the volume criterion of
//!   Uintah's friction contact, its `volume_constraint`): a node the
//!   functions reach past a body's surface, beside the other body, is not
//!   a contact. Without it the nodes beside a sliding block's front
//!   corner, with normals tilted towards the direction of sliding, take
//!   momentum of the slab's small mass there every step, a drag of order
//!   $m/\Delta t$ that stops the block (measured: a fill of 0.9 lets the
//!   block of `scenes/sliding_block_contact.toml` slide 3.4 mm of 16.0);
//! - centre of mass: $\tilde{\mathbf v}_{cm} = \sum_k m_k\tilde{\mathbf v}_k / \sum_k m_k$;
//! - the outward normal of field $k$, towards the others: $\mathbf g_k$
//!   points out of body $k$ ($\nabla w_{ip}$, the gradient of node $i$'s
//!   function at the point, points from the point towards the node, so
//!   $\mathbf g_k = -\nabla\rho_k(\mathbf x_i)$ for the smoothed density
//!   $\rho_k = \sum_{p\in k} m_p w$). With $\mathbf g_{rest} = \sum_{j\ne k}\mathbf g_j$,
//!   $\mathbf n_k = \mathbf g_k/\|\mathbf g_k\|$ when $\|\mathbf g_k\| >
//!   \|\mathbf g_{rest}\|$ and $-\mathbf g_{rest}/\|\mathbf g_{rest}\|$
//!   otherwise — the normal of the body with the larger gradient, the
//!   one whose surface the node sees best (a tie goes to the lowest
//!   field). With two fields
//!   $\mathbf n_B = -\mathbf n_A$ exactly, so the two corrections are
//!   equal and opposite and momentum is conserved to rounding. (The
//!   difference $\mathbf g_A - \mathbf g_B$, also antisymmetric, tilts
//!   where one body's surface ends: the block of
//!   `sliding_block_contact.toml` with μ = 0.2 slid 14.9 mm of 16.0.)
//! - approach: $\delta_n = (\tilde{\mathbf v}_k - \tilde{\mathbf v}_{cm})\cdot\mathbf n_k > 0$;
//! - the normal relative velocity goes and the tangential one
//!   $\boldsymbol\delta_t$ shrinks by $\mu\delta_n$ but not past zero
//!   (Bardenhagen et al. 2000, §3):
//!   $\tilde{\mathbf v}_k' = \tilde{\mathbf v}_{cm} + \boldsymbol\delta_t\max(0, 1 - \mu\delta_n/\|\boldsymbol\delta_t\|)$.
//!   The mapped velocities $v^n_k$ are left as they are.
//!
//! The energy is booked as for the friction walls
//! ([`super::grid_update::friction_walls`]): the friction work per field
//! is the impulse times the tangential velocity it leaves,
//! $m_k\|\boldsymbol\delta_t'\|(\|\boldsymbol\delta_t\| - \|\boldsymbol\delta_t'\|)$
//! (for two fields the impulse times the relative sliding speed), added
//! to [`WallWork::friction`]; the impact loss is the kinetic energy of the
//! normal relative velocity the field brought to the step,
//! $\tfrac12 m_k\max(0, (v^n_k - v^n_{cm})\cdot\mathbf n_k)^2$, added to
//! [`WallWork::impact`].

use std::ops::Range;

use mpm_basis::{BasisFunction, Stencil};
use nalgebra::SVector;

use super::fixities::VelocityFixities;
use super::grid::{GridState, NodeSums, NodeVelocity};
use super::grid_update::{WallWork, friction_walls};
use super::p2g::{PointsView, visit_nodes};
use super::transfer::Transfer;
use crate::error::{PointFailure, SolverError};

/// The fraction of a full node's volume ([`Contact`]'s cell volume) that
/// the fields must fill together before they meet: below it the bodies
/// are still apart, and the fields only share the node because the
/// functions reach past the bodies' surfaces.
pub const FILLED: f64 = 0.99;

/// The sums of one field at one node: those of the single-field grid and
/// the mass gradient $\sum_p m_p\nabla w_{ip}$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldSums<const D: usize> {
    /// Mass, momentum and force.
    pub sums: NodeSums<D>,
    /// $\mathbf g = \sum_p m_p\nabla w_{ip}$.
    pub mass_gradient: SVector<f64, D>,
    /// The volume the field brings to the node, $\sum_p w_{ip}V_p$.
    pub volume: f64,
}

impl<const D: usize> FieldSums<D> {
    /// Nothing.
    pub const ZERO: Self = Self {
        sums: NodeSums::ZERO,
        mass_gradient: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
        volume: 0.0,
    };
}

/// One thread's sums of every field: node `i`, field `k` at
/// `i * fields + k` (a node's fields side by side). Only the nodes
/// `lo..hi` can be non-zero.
#[derive(Debug, Clone)]
pub struct FieldBuffer<const D: usize> {
    /// The sums.
    pub sums: Vec<FieldSums<D>>,
    /// Number of fields.
    pub fields: usize,
    /// First touched node.
    pub lo: usize,
    /// One past the last touched node.
    pub hi: usize,
}

impl<const D: usize> FieldBuffer<D> {
    /// Zeroed sums of `fields` fields on `nodes` nodes.
    pub fn new(nodes: usize, fields: usize) -> Self {
        Self {
            sums: vec![FieldSums::ZERO; nodes * fields],
            fields,
            lo: usize::MAX,
            hi: 0,
        }
    }

    /// Zeroes the touched range.
    pub fn clear(&mut self) {
        if self.lo < self.hi {
            self.sums[self.lo * self.fields..self.hi * self.fields].fill(FieldSums::ZERO);
        }
        self.lo = usize::MAX;
        self.hi = 0;
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.sums.len() / self.fields.max(1)
    }
}

/// The contact of a run: the fields' friction coefficients and their
/// grids.
#[derive(Debug, Clone)]
pub struct Contact<const D: usize> {
    /// μ of each field; at a node the largest of the fields present.
    friction: Vec<f64>,
    /// The volume of a full node, $\sum_p w_{ip}V_p$ of a node inside a
    /// body: the grid's cell volume.
    cell_volume: f64,
    /// One buffer per thread.
    pub(super) buffers: Vec<FieldBuffer<D>>,
    /// The grid of each field.
    pub(super) grids: Vec<GridState<D>>,
}

impl<const D: usize> Contact<D> {
    /// Contact between `friction.len()` fields on a grid of `nodes` nodes
    /// with cells of volume `cell_volume` (area in 2D), field `k` with
    /// Coulomb coefficient `friction[k]`.
    ///
    /// # Errors
    /// Fewer than two or more than 256 fields; a coefficient that is
    /// negative or not finite; a cell volume that is not positive and
    /// finite.
    pub fn new(friction: Vec<f64>, nodes: usize, cell_volume: f64) -> Result<Self, SolverError> {
        if !(cell_volume.is_finite() && cell_volume > 0.0) {
            return Err(SolverError::InvalidInput(format!(
                "contact needs a positive cell volume, not {cell_volume}"
            )));
        }
        if !(2..=256).contains(&friction.len()) {
            return Err(SolverError::InvalidInput(format!(
                "contact needs 2 to 256 velocity fields, not {}",
                friction.len()
            )));
        }
        if let Some(mu) = friction.iter().find(|mu| !(mu.is_finite() && **mu >= 0.0)) {
            return Err(SolverError::InvalidInput(format!(
                "contact friction μ = {mu} must be finite and non-negative"
            )));
        }
        let grids = vec![GridState::new(nodes); friction.len()];
        Ok(Self {
            friction,
            cell_volume,
            buffers: Vec::new(),
            grids,
        })
    }

    /// Number of fields.
    pub fn fields(&self) -> usize {
        self.friction.len()
    }

    /// The grid of field `k` in the last step.
    pub fn grid(&self, k: usize) -> Option<&GridState<D>> {
        self.grids.get(k)
    }
}

/// [`super::p2g::scatter`] into each point's field (`field[p]`), with the
/// mass gradient: node by node through [`visit_nodes`] for every basis.
///
/// # Errors
/// The first point whose basis cannot be evaluated, with its index.
#[allow(clippy::too_many_arguments)]
pub fn scatter_fields<const D: usize, B, T>(
    basis: &B,
    mesh: &B::Mesh,
    points: &PointsView<'_, D, T::PointState, B::Domain>,
    (field, volume): (&[u8], &[f64]),
    node_position: &[SVector<f64, D>],
    gravity: &SVector<f64, D>,
    range: Range<usize>,
    buffer: &mut FieldBuffer<D>,
    stencil: &mut Stencil<D>,
) -> Result<(), (usize, PointFailure)>
where
    B: BasisFunction<D>,
    T: Transfer<D>,
{
    let node_count = buffer.nodes();
    let fields = buffer.fields;
    let (mut lo, mut hi) = (buffer.lo, buffer.hi);
    let sums = &mut buffer.sums;
    for p in range {
        let x = &points.position[p];
        let m = points.mass[p];
        let v = &points.velocity[p];
        let state = &points.transfer[p];
        let stress = points.tau[p].fixed_view::<D, D>(0, 0) * points.volume0[p];
        let body = gravity * m;
        let k = usize::from(field[p]);
        let vol = volume[p];
        visit_nodes(
            basis,
            mesh,
            x,
            &points.domain[p],
            node_count,
            stencil,
            |i, w, g| {
                let carried = if T::TAYLOR {
                    T::nodal_velocity(v, state, &(node_position[i] - x))
                } else {
                    *v
                };
                let node = &mut sums[i * fields + k];
                node.sums.add_point((w, g), m, &carried, &body, &stress);
                node.mass_gradient += g * m;
                node.volume += w * vol;
                lo = lo.min(i);
                hi = hi.max(i + 1);
            },
        )
        .map_err(|e| (p, e))?;
    }
    buffer.lo = lo;
    buffer.hi = hi;
    Ok(())
}

/// Applied point forces (eq. 21) into each point's field of `buffer`.
///
/// # Errors
/// As [`scatter_fields`].
#[allow(clippy::too_many_arguments)]
pub fn scatter_field_forces<const D: usize, B: BasisFunction<D>>(
    basis: &B,
    mesh: &B::Mesh,
    position: &[SVector<f64, D>],
    domain: &[B::Domain],
    field: &[u8],
    forces: &[(usize, SVector<f64, D>)],
    buffer: &mut FieldBuffer<D>,
    stencil: &mut Stencil<D>,
) -> Result<(), (usize, PointFailure)> {
    let (node_count, fields) = (buffer.nodes(), buffer.fields);
    for (p, f) in forces {
        let k = usize::from(field[*p]);
        let (lo, hi, sums) = (&mut buffer.lo, &mut buffer.hi, &mut buffer.sums);
        visit_nodes(
            basis,
            mesh,
            &position[*p],
            &domain[*p],
            node_count,
            stencil,
            |i, w, _| {
                sums[i * fields + k].sums.force += f * w;
                *lo = (*lo).min(i);
                *hi = (*hi).max(i + 1);
            },
        )
        .map_err(|e| (*p, e))?;
    }
    Ok(())
}

/// The grid update of a run with contact: the threads' sums of each field
/// give its velocities (eqs. 30–32) in `contact`'s grids and their sum the
/// centre-of-mass velocities in `grid`; the fields meet at the nodes two
/// or more of them reach ([`correct_node`]); then the nodal fixities and
/// the friction walls act on every field (and the fixities on `grid`),
/// the gap-checked ones where `touched` (by any body's points).
/// Returns what the contact and the walls took.
pub fn update_fields<const D: usize>(
    contact: &mut Contact<D>,
    grid: &mut GridState<D>,
    dt: f64,
    fixities: &VelocityFixities,
    touched: &[bool],
) -> WallWork {
    let buffers = &contact.buffers;
    let lo = buffers.iter().map(|b| b.lo).min().unwrap_or(usize::MAX);
    let hi = buffers.iter().map(|b| b.hi).max().unwrap_or(0);
    let (lo, hi) = if lo < hi { (lo, hi) } else { (0, 0) };
    let fields = contact.friction.len();
    let mut work = WallWork::default();
    // Per field at one node: mass, velocities, mass gradient (no
    // allocation per node).
    let mut at_node = vec![(0.0, NodeVelocity::<D>::default(), SVector::zeros()); fields];
    let full = contact.cell_volume * FILLED;
    for i in lo..hi {
        let mut total = NodeSums::<D>::ZERO;
        let mut volume = 0.0;
        for (k, slot) in at_node.iter_mut().enumerate() {
            let mut sum = FieldSums::<D>::ZERO;
            for b in buffers {
                if i >= b.lo && i < b.hi {
                    let s = &b.sums[i * fields + k];
                    sum.sums.mass += s.sums.mass;
                    sum.sums.momentum += s.sums.momentum;
                    sum.sums.force += s.sums.force;
                    sum.mass_gradient += s.mass_gradient;
                    volume += s.volume;
                }
            }
            total.mass += sum.sums.mass;
            total.momentum += sum.sums.momentum;
            total.force += sum.sums.force;
            *slot = (sum.sums.mass, velocities(&sum.sums, dt), sum.mass_gradient);
        }
        grid.mass[i] = total.mass;
        grid.velocity[i] = velocities(&total, dt);
        if volume >= full && at_node.iter().filter(|s| s.0 > 0.0).count() >= 2 {
            let met = correct_node(&mut at_node, &contact.friction);
            work = work.plus(met);
        }
        for (g, s) in contact.grids.iter_mut().zip(&at_node) {
            g.mass[i] = s.0;
            g.velocity[i] = s.1;
        }
    }
    grid.lo = lo;
    grid.hi = hi;
    for &(node, component, value) in fixities.entries() {
        if node >= lo && node < hi && grid.mass[node] > 0.0 {
            grid.velocity[node].new[component] = value;
        }
    }
    for g in &mut contact.grids {
        g.lo = lo;
        g.hi = hi;
        for &(node, component, value) in fixities.entries() {
            if node >= lo && node < hi && g.mass[node] > 0.0 {
                g.velocity[node].new[component] = value;
            }
        }
        work = work.plus(friction_walls(g, fixities.walls(), touched, |_| true));
    }
    work
}

/// $v^n = p/m$ and $\tilde v^{n+1} = v^n + \Delta t f/m$ (eqs. 30–32), zero
/// without mass.
fn velocities<const D: usize>(s: &NodeSums<D>, dt: f64) -> NodeVelocity<D> {
    if s.mass > 0.0 {
        let v = s.momentum / s.mass;
        NodeVelocity {
            old: v,
            new: v + s.force * (dt / s.mass),
        }
    } else {
        NodeVelocity::default()
    }
}

/// The contact of the fields at one node, `fields[k]` = (mass, velocities,
/// mass gradient) of field k: each field with mass that approaches the
/// centre of mass along its normal loses that normal relative velocity
/// and, by Coulomb's law with the largest μ of the fields present
/// (`friction[k]`), part of its tangential one (the module's equations).
/// Returns the friction work and the impact loss.
pub fn correct_node<const D: usize>(
    fields: &mut [(f64, NodeVelocity<D>, SVector<f64, D>)],
    friction: &[f64],
) -> WallWork {
    let (mut mass, mut momentum, mut gradient) =
        (0.0, SVector::<f64, D>::zeros(), SVector::zeros());
    let mut mu: f64 = 0.0;
    for ((m, v, g), &mu_k) in fields.iter().zip(friction) {
        if *m > 0.0 {
            mass += m;
            momentum += v.new * *m;
            gradient += g;
            mu = mu.max(mu_k);
        }
    }
    let v_cm = momentum / mass;
    let old_cm = fields
        .iter()
        .filter(|f| f.0 > 0.0)
        .map(|(m, v, _)| v.old * *m)
        .sum::<SVector<f64, D>>()
        / mass;
    let lowest = fields.iter().position(|f| f.0 > 0.0);
    let mut work = WallWork::default();
    for (k, (m, v, g)) in fields.iter_mut().enumerate() {
        if *m <= 0.0 {
            continue;
        }
        let Some(n) = normal(g, &(gradient - *g), Some(k) == lowest) else {
            continue;
        };
        let delta = v.new - v_cm;
        let approach = delta.dot(&n);
        if approach <= 0.0 {
            continue;
        }
        let tangential = delta - n * approach;
        let speed = tangential.norm();
        let left = (speed - mu * approach).max(0.0);
        let kept = if speed > 0.0 {
            tangential * (left / speed)
        } else {
            SVector::zeros()
        };
        v.new = v_cm + kept;
        work.friction += *m * left * (speed - left);
        let brought = (v.old - old_cm).dot(&n).max(0.0);
        work.impact += 0.5 * *m * brought * brought;
    }
    work
}

/// The outward unit normal of a field of mass gradient `own` against
/// the others' `rest`: its own direction when its gradient is the larger
/// (`first`: the lowest field present, which a tie gives its own), the
/// others' reversed otherwise; `None` when both vanish. With two fields
/// the normals are opposite.
fn normal<const D: usize>(
    own: &SVector<f64, D>,
    rest: &SVector<f64, D>,
    first: bool,
) -> Option<SVector<f64, D>> {
    let (a, b) = (own.norm(), rest.norm());
    let n = if a > b || (a == b && first) {
        own / a
    } else {
        -rest / b
    };
    (a.max(b) > 0.0).then_some(n)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    /// Two fields at a node in 2D: mass, new velocity, gradient.
    fn node(
        a: (f64, [f64; 2], [f64; 2]),
        b: (f64, [f64; 2], [f64; 2]),
    ) -> Vec<(f64, NodeVelocity<2>, SVector<f64, 2>)> {
        [a, b]
            .into_iter()
            .map(|(m, v, g)| {
                let v = Vector2::from(v);
                (m, NodeVelocity { old: v, new: v }, Vector2::from(g))
            })
            .collect()
    }

    fn momentum(f: &[(f64, NodeVelocity<2>, SVector<f64, 2>)]) -> SVector<f64, 2> {
        f.iter().map(|(m, v, _)| v.new * *m).sum()
    }

    /// A block (field 0, above: its mass gradient points down, out of
    /// it) sliding at 1 m/s
    /// and pressing down at 0.3 m/s on a slab at rest (field 1, below):
    /// both leave with the centre of mass's normal velocity; the
    /// tangential relative velocity 1 drops by μ times the normal relative
    /// velocity 0.3 (Coulomb), equally for both in momentum; momentum is
    /// conserved; the friction work is the impulse times the sliding speed
    /// left.
    #[test]
    fn approaching_fields_lose_normal_velocity_and_slide_with_coulomb_s_impulse() {
        let (ma, mb, mu) = (1.0, 3.0, 0.2);
        let mut f = node((ma, [1.0, -0.3], [0.0, -2.0]), (mb, [0.0, 0.0], [0.0, 5.0]));
        let before = momentum(&f);
        let work = correct_node(&mut f, &[mu, 0.0]);
        let after = momentum(&f);
        assert!((after - before).norm() < 1e-15, "{before} {after}");
        let (va, vb) = (f[0].1.new, f[1].1.new);
        assert!((va.y - vb.y).abs() < 1e-15, "normal velocities {va} {vb}");
        // Relative normal velocity 0.3: the tangential relative one loses
        // μ·0.3 = 0.06.
        assert!(
            ((va.x - vb.x) - (1.0 - mu * 0.3)).abs() < 1e-14,
            "{va} {vb}"
        );
        let impulse = ma * (1.0 - va.x);
        assert!((impulse - mb * vb.x).abs() < 1e-15);
        assert!((work.friction - impulse * (va.x - vb.x)).abs() < 1e-15);
        // The normal relative velocity's kinetic energy relative to the
        // centre of mass: ½ μ_red 0.3², μ_red = m_a m_b / (m_a + m_b).
        let reduced = ma * mb / (ma + mb);
        assert!((work.impact - 0.5 * reduced * 0.09).abs() < 1e-15);
    }

    /// Fields moving apart, or along their interface, are left free; a
    /// large μ makes them stick (the tangential relative velocity goes,
    /// no friction work).
    #[test]
    fn separating_fields_are_free_and_sticking_ones_move_together() {
        let free = node(
            (1.0, [0.5, 0.3], [0.0, -2.0]),
            (2.0, [0.0, -0.1], [0.0, 1.0]),
        );
        let mut f = free.clone();
        assert_eq!(correct_node(&mut f, &[0.5, 0.5]), WallWork::default());
        assert_eq!(f, free);
        let mut f = node(
            (1.0, [0.1, -0.3], [0.0, -2.0]),
            (2.0, [0.0, 0.0], [0.0, 1.0]),
        );
        let before = momentum(&f);
        let work = correct_node(&mut f, &[0.0, 1.0]);
        assert!((f[0].1.new - f[1].1.new).norm() < 1e-15);
        assert!((momentum(&f) - before).norm() < 1e-15);
        assert_eq!(work.friction, 0.0);
    }

    #[test]
    fn bad_contact_is_refused() {
        assert!(Contact::<2>::new(vec![0.1], 4, 1.0).is_err());
        assert!(Contact::<2>::new(vec![0.1, -0.1], 4, 1.0).is_err());
        assert!(Contact::<2>::new(vec![0.1, f64::NAN], 4, 1.0).is_err());
        assert!(Contact::<2>::new(vec![0.0; 257], 4, 1.0).is_err());
        assert!(Contact::<2>::new(vec![0.1, 0.0], 4, 0.0).is_err());
        assert_eq!(
            Contact::<2>::new(vec![0.1, 0.0], 4, 1.0)
                .expect("valid")
                .fields(),
            2
        );
    }

    /// The grid update of two fields meeting head-on at one node of a
    /// grid of unit cells: they meet (equal velocities after, momentum
    /// kept, the centre-of-mass grid holding the sum) when their volumes
    /// fill the node to [`FILLED`], and pass each other untouched just
    /// below it.
    #[test]
    fn fields_meet_only_at_filled_nodes() {
        for (volume, meet) in [(0.5, true), (0.49, false)] {
            let mut contact = Contact::<2>::new(vec![0.0, 0.0], 1, 1.0).expect("valid");
            let mut buffer = FieldBuffer::<2>::new(1, 2);
            // Field 0 on the left (its mass gradient points right, out of
            // it), moving right; field 1 on the right moving left.
            for (k, (v, g)) in [(1.0, 1.0), (-1.0, -1.0)].into_iter().enumerate() {
                let s = &mut buffer.sums[k];
                s.sums.mass = 1.0 + k as f64;
                s.sums.momentum = Vector2::new(v, 0.0) * s.sums.mass;
                s.mass_gradient = Vector2::new(g, 0.0);
                s.volume = volume * FILLED;
            }
            (buffer.lo, buffer.hi) = (0, 1);
            contact.buffers = vec![buffer];
            let mut grid = GridState::<2>::new(1);
            let mut fixities = VelocityFixities::new();
            fixities.finish();
            let work = update_fields(&mut contact, &mut grid, 0.1, &fixities, &[]);
            let (a, b) = (
                contact.grids[0].velocity[0].new,
                contact.grids[1].velocity[0].new,
            );
            assert_eq!(grid.mass[0], 3.0);
            assert!((grid.velocity[0].new.x - (1.0 - 2.0) / 3.0).abs() < 1e-15);
            if meet {
                assert!((a - b).norm() < 1e-15, "{a} {b}");
                assert!((a.x + 2.0 * b.x - (1.0 - 2.0)).abs() < 1e-15);
                assert!(work.impact > 0.0);
            } else {
                assert_eq!((a.x, b.x), (1.0, -1.0));
                assert_eq!(work, WallWork::default());
            }
        }
    }
}
