//! Prescribed nodal velocities (MPoint notes, below eq. 32).

/// Nodal velocity fixities: after the grid update (eq. 32) the listed
/// components are set, $\tilde v_i^{n+1} = v^{fix}_i$, and their
/// acceleration recomputed as $(\tilde v_i^{n+1} - v_i^n)/\Delta t$. A slip
/// wall fixes the normal component to zero; a clamp fixes all.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VelocityFixities {
    /// (node, component, velocity), in the order given until
    /// [`VelocityFixities::finish`] sorts them and drops repeats.
    entries: Vec<(usize, usize, f64)>,
    /// Bit `c` of entry `n`: component `c` of node `n` is held (built by
    /// [`VelocityFixities::finish`]).
    mask: Vec<u8>,
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

    /// Sorts the fixities by node and component, a later value of a
    /// repeated component replacing the earlier one (the solver calls it
    /// once when it takes the fixities; calling it again changes nothing).
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

    /// Number of fixed components.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing is fixed.
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
}
