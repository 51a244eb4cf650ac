//! The kinematics and linearisation shared by every patch-averaging
//! locking treatment ([`crate::locking`]; derivation in
//! `docs/src/theory/locking.md`).
//!
//! With $J_q = \det\Delta F_q$ (the motion's), weights $w_q$ and patch $P$:
//!
//! - $\Delta\bar J_P = \sum_{q\in P}w_qJ_q/\sum_{q\in P}w_q$,
//!   $\alpha_p = (\Delta\bar J_P/J_p)^{1/D}$ and $\Delta\bar F_p =
//!   \alpha_p\Delta F_p$ on the $D\times D$ block (Wang et al. 2021 eq. 9);
//! - the linearisation of $\Delta\bar F_p$ in the nodal displacements is
//!   $\delta\Delta\bar F_p\,\Delta\bar F_p^{-1} = \operatorname{dev}\mathbf
//!   l_p + \tfrac1D\big(\sum_{q\in P}\beta_q\operatorname{tr}\mathbf
//!   l_q\big)\mathbf 1$ with $\mathbf l_q = \sum_w\delta\mathbf u_w\otimes
//!   \mathbf g_{wq}$, the spatial gradients of the motion $\mathbf g_{wq} =
//!   \Delta F_q^{-T}\nabla_{\tilde X}S_{wq}$, and the deformed-volume
//!   weights $\beta_q = w_qJ_q/\sum_{r\in P}w_rJ_r$ (Wang's $v_e/v_{patch}$);
//! - so every formulation's stiffness is its standard kernel with the
//!   point's tangent scaled by $\alpha_p$, plus the rank-structured
//!   coupling $K_{(vi)(wk)} \mathrel{+}= \sum_p h_{vp,i}\,(\mathbf G_{wP} -
//!   \mathbf g_{wp})_k$, where $\mathbf G_{wP} = \sum_{q\in P}\beta_q\mathbf
//!   g_{wq}$ is the patch's average gradient and $\mathbf h_{vp} = B_p\,
//!   \nabla S_{vp}$ with $B_{p,ij} = \tfrac1D T_{ijkl}K_{kl}$ contracted
//!   with the formulation's volumetric direction
//!   ([`crate::Formulation::volumetric_direction`]).
//!
//! The patch structure (members, node unions, the node-to-patch map) is
//! built once per step; the per-iteration work allocates nothing.

use nalgebra::{Matrix3, SVector};
use rayon::prelude::*;

use crate::locking::PatchAssignment;
use crate::stages::system::StepSystem;

/// The patches of a load step and their per-iteration kinematics.
#[derive(Debug, Default)]
pub struct PatchSystem<const D: usize> {
    /// What the treatment assigned (raw patch ids and weights).
    pub assignment: PatchAssignment,
    /// Compact patch index of every point.
    pub patch_of_point: Vec<u32>,
    /// CSR patch → member points (ascending).
    pub member_ptr: Vec<usize>,
    /// See `member_ptr`.
    pub members: Vec<u32>,
    /// CSR patch → the union of its members' stencils (active node ids,
    /// ascending).
    pub union_ptr: Vec<usize>,
    /// See `union_ptr`.
    pub union: Vec<u32>,
    /// Per stencil slot, the position of its node in its point's patch
    /// union.
    pub local: Vec<u32>,
    /// CSR active node → (patch, position in the patch's union), patches
    /// ascending.
    pub node_ptr: Vec<usize>,
    /// See `node_ptr`.
    pub node_patches: Vec<(u32, u32)>,
    /// Per point, $J_q = \det\Delta F_q$ of the current iterate.
    pub det: Vec<f64>,
    /// Per patch, $\Delta\bar J_P$.
    pub det_bar: Vec<f64>,
    /// Per point, $\alpha_p$.
    pub alpha: Vec<f64>,
    /// Per point, $\beta_q$.
    pub beta: Vec<f64>,
    /// Per slot, the spatial gradient of the motion $\mathbf g_{wq}$.
    pub spatial: Vec<SVector<f64, D>>,
    /// Per union entry, $\mathbf G_{wP}$.
    pub patch_grad: Vec<SVector<f64, D>>,
    /// Per slot, $\mathbf h_{vp}$.
    pub h: Vec<SVector<f64, D>>,
    /// Per patch, a $|U|\times|U|$ table over its node union $U$: entry
    /// $(u, t)$ is the position of $U_t$ in the neighbour list of $U_u$
    /// ([`StepSystem::nb`]), so the coupling scatter places an entry
    /// without a search ([`Self::build_placement`]).
    pub place: Vec<u32>,
    /// Start of each patch's table in `place`.
    pub place_ptr: Vec<usize>,
}

/// A point whose motion inverts it ($\det\Delta F \le 0$ or not finite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvertedPoint {
    /// The point.
    pub point: usize,
    /// Its $\det\Delta F$.
    pub det: f64,
}

impl<const D: usize> PatchSystem<D> {
    /// Number of (non-empty) patches.
    pub fn patch_count(&self) -> usize {
        self.member_ptr.len().saturating_sub(1)
    }

    /// Members of compact patch `k`.
    #[inline]
    pub fn members_of(&self, k: usize) -> &[u32] {
        &self.members[self.member_ptr[k]..self.member_ptr[k + 1]]
    }

    /// Node union of compact patch `k`.
    #[inline]
    pub fn union_of(&self, k: usize) -> &[u32] {
        &self.union[self.union_ptr[k]..self.union_ptr[k + 1]]
    }

    /// Builds the patch structure from [`Self::assignment`] over the
    /// step's stencils (in active node numbering).
    pub fn build(&mut self, sys: &StepSystem<D>) {
        let n = sys.counts.len();
        let raw = &self.assignment.patch;
        // Compact the patch ids: ascending raw id.
        let mut ids: Vec<u32> = raw.clone();
        ids.sort_unstable();
        ids.dedup();
        self.patch_of_point.clear();
        self.patch_of_point.extend(
            raw.iter()
                .map(|r| ids.binary_search(r).unwrap_or_default() as u32),
        );
        let np = ids.len();
        // Members by counting sort (points ascend within a patch).
        self.member_ptr.clear();
        self.member_ptr.resize(np + 1, 0);
        for &k in &self.patch_of_point {
            self.member_ptr[k as usize + 1] += 1;
        }
        for k in 0..np {
            self.member_ptr[k + 1] += self.member_ptr[k];
        }
        self.members.clear();
        self.members.resize(n, 0);
        let mut fill = self.member_ptr[..np].to_vec();
        for (p, &k) in self.patch_of_point.iter().enumerate() {
            self.members[fill[k as usize]] = p as u32;
            fill[k as usize] += 1;
        }
        // Node unions.
        let n_active = sys.n_active();
        let mut mark = vec![u32::MAX; n_active];
        self.union_ptr.clear();
        self.union_ptr.push(0);
        self.union.clear();
        for k in 0..np {
            let start = self.union.len();
            for &p in &self.members[self.member_ptr[k]..self.member_ptr[k + 1]] {
                for s in sys.slots(p as usize) {
                    let v = sys.nodes[s];
                    if mark[v as usize] != k as u32 {
                        mark[v as usize] = k as u32;
                        self.union.push(v);
                    }
                }
            }
            self.union[start..].sort_unstable();
            self.union_ptr.push(self.union.len());
        }
        // Position of every slot's node in its patch union.
        self.local.clear();
        self.local.resize(sys.nodes.len(), 0);
        for p in 0..n {
            let k = self.patch_of_point[p] as usize;
            let union = &self.union[self.union_ptr[k]..self.union_ptr[k + 1]];
            for s in sys.slots(p) {
                self.local[s] = union.binary_search(&sys.nodes[s]).unwrap_or_default() as u32;
            }
        }
        // Node → patches.
        self.node_ptr.clear();
        self.node_ptr.resize(n_active + 1, 0);
        for &v in &self.union {
            self.node_ptr[v as usize + 1] += 1;
        }
        for v in 0..n_active {
            self.node_ptr[v + 1] += self.node_ptr[v];
        }
        self.node_patches.clear();
        self.node_patches.resize(self.union.len(), (0, 0));
        let mut fill = self.node_ptr[..n_active].to_vec();
        for k in 0..np {
            for (u, &v) in self.union[self.union_ptr[k]..self.union_ptr[k + 1]]
                .iter()
                .enumerate()
            {
                self.node_patches[fill[v as usize]] = (k as u32, u as u32);
                fill[v as usize] += 1;
            }
        }
        self.det.clear();
        self.det.resize(n, 1.0);
        self.alpha.clear();
        self.alpha.resize(n, 1.0);
        self.beta.clear();
        self.beta.resize(n, 0.0);
        self.det_bar.clear();
        self.det_bar.resize(np, 1.0);
        self.spatial.clear();
        self.spatial.resize(sys.grads.len(), SVector::zeros());
        self.h.clear();
        self.h.resize(sys.grads.len(), SVector::zeros());
        self.patch_grad.clear();
        self.patch_grad.resize(self.union.len(), SVector::zeros());
    }

    /// The neighbours of node `w` in a patch-coupled step, into `push`:
    /// the nodes sharing a patch with it (a superset of the nodes sharing
    /// a point, since a patch's union holds its points' stencils). The
    /// system builds its lists from it
    /// ([`StepSystem::build_neighbours_from`]).
    pub fn neighbours(&self, w: usize, push: &mut dyn FnMut(u32)) {
        for &(k, _) in &self.node_patches[self.node_ptr[w]..self.node_ptr[w + 1]] {
            for &v in self.union_of(k as usize) {
                push(v);
            }
        }
    }

    /// The placement table [`Self::place`], once per step after the
    /// patch neighbour lists ([`Self::neighbours`]).
    /// Every pair of a union is a neighbour pair by construction.
    pub fn build_placement(&mut self, sys: &StepSystem<D>) {
        self.place.clear();
        self.place_ptr.clear();
        self.place_ptr.push(0);
        for k in 0..self.patch_count() {
            let union = &self.union[self.union_ptr[k]..self.union_ptr[k + 1]];
            for &w in union {
                let w = w as usize;
                let nbs = &sys.nb[sys.nb_ptr[w]..sys.nb_ptr[w + 1]];
                self.place.extend(
                    union
                        .iter()
                        .map(|v| nbs.binary_search(v).unwrap_or_default() as u32),
                );
            }
            self.place_ptr.push(self.place.len());
        }
    }

    /// The patch averages of the iterate whose point increments are
    /// `increments` (the motion's $\Delta F_q$): $J_q$, $\Delta\bar J_P$,
    /// $\alpha_p$ and $\beta_q$.
    ///
    /// # Errors
    /// The lowest point whose $\det\Delta F$ is not positive and finite.
    pub fn average(&mut self, increments: &[Matrix3<f64>]) -> Result<(), InvertedPoint> {
        self.det
            .par_iter_mut()
            .zip(increments.par_iter())
            .for_each(|(j, f)| *j = f.determinant());
        if let Some(point) = self.det.iter().position(|&j| !(j > 0.0 && j.is_finite())) {
            return Err(InvertedPoint {
                point,
                det: self.det[point],
            });
        }
        let weight = &self.assignment.weight;
        for k in 0..self.patch_count() {
            let (mut w, mut wj) = (0.0, 0.0);
            for &q in self.members_of(k) {
                w += weight[q as usize];
                wj += weight[q as usize] * self.det[q as usize];
            }
            self.det_bar[k] = wj / w;
            for &q in &self.members[self.member_ptr[k]..self.member_ptr[k + 1]] {
                let q = q as usize;
                self.beta[q] = weight[q] * self.det[q] / wj;
                let ratio = self.det_bar[k] / self.det[q];
                // The D-th root; cbrt and sqrt are exact to rounding and
                // cheaper than powf.
                self.alpha[q] = match D {
                    3 => ratio.cbrt(),
                    2 => ratio.sqrt(),
                    _ => ratio.powf(1.0 / D as f64),
                };
            }
        }
        Ok(())
    }

    /// $\Delta\bar F_p = \alpha_p\Delta F_p$ on the $D\times D$ block.
    #[inline]
    pub fn modified(&self, p: usize, delta_f: &Matrix3<f64>) -> Matrix3<f64> {
        let a = self.alpha[p];
        let mut f = *delta_f;
        for i in 0..D {
            for j in 0..D {
                f[(i, j)] *= a;
            }
        }
        f
    }

    /// The spatial gradients of the motion per slot, $\mathbf g_{wq} =
    /// \alpha_q\Delta\bar F_q^{-T}\nabla_{\tilde X}S_{wq}$ (from each
    /// point's $\Delta\bar F_q^{-1}$, `inverse`), and their patch averages
    /// $\mathbf G_{wP}$.
    pub fn gradients(
        &mut self,
        sys: &StepSystem<D>,
        inverse: &(dyn Fn(usize) -> Matrix3<f64> + Sync),
    ) {
        let stride = sys.stride.max(1);
        let alpha = &self.alpha;
        self.spatial
            .par_chunks_mut(stride)
            .enumerate()
            .for_each(|(p, chunk)| {
                let m = sys.counts[p] as usize;
                let inv = inverse(p);
                let a = alpha[p];
                for (c, g) in chunk.iter_mut().take(m).enumerate() {
                    let grad = &sys.grads[p * stride + c];
                    *g = SVector::<f64, D>::from_fn(|j, _| {
                        a * (0..D).map(|i| grad[i] * inv[(i, j)]).sum::<f64>()
                    });
                }
            });
        for k in 0..self.patch_count() {
            let base = self.union_ptr[k];
            for u in base..self.union_ptr[k + 1] {
                self.patch_grad[u] = SVector::zeros();
            }
            for &q in &self.members[self.member_ptr[k]..self.member_ptr[k + 1]] {
                let q = q as usize;
                for s in sys.slots(q) {
                    self.patch_grad[base + self.local[s] as usize] +=
                        self.spatial[s] * self.beta[q];
                }
            }
        }
    }

    /// The column vector $\mathbf G_{wP} - \mathbf g_{wp}$ of point `p`
    /// for the node at position `u` of its patch union.
    #[inline]
    pub fn column(&self, sys: &StepSystem<D>, p: usize, u: u32) -> SVector<f64, D> {
        let k = self.patch_of_point[p] as usize;
        let mut c = self.patch_grad[self.union_ptr[k] + u as usize];
        for s in sys.slots(p) {
            if self.local[s] == u {
                c -= self.spatial[s];
                break;
            }
        }
        c
    }
}
