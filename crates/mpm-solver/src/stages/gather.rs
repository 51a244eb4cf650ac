//! Point-to-grid gathers: lumped nodal mass, external force (eqs. 24, 25,
//! 29), internal force (eqs. 6, 23, 28) and the stiffness (eqs. 4, 21, 27),
//! over a [`StepSystem`] and slices of per-point quantities.
//!
//! Node-wise gathers (mass, internal force, stiffness) run one active node
//! (or block column) per task and sum over the node's points in ascending
//! order, so the result is bit-identical for any number of threads.

use mpm_constitutive::tensor::{Tensor4, idx};
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use crate::points::MaterialPoints;
use crate::stages::patch::PatchSystem;
use crate::stages::system::{NO_ENTRY, NONE, PARTIAL, StepSystem};

/// Lumped nodal mass $m_v = \sum_p S_{vp} m_p$ per active node (MPoint
/// eq. 22; the explicit solver's), into `out` (resized).
pub fn nodal_mass<const D: usize>(sys: &StepSystem<D>, mass: &[f64], out: &mut Vec<f64>) {
    out.clear();
    out.resize(sys.n_active(), 0.0);
    out.par_iter_mut().enumerate().for_each(|(v, m)| {
        *m = sys.adj[sys.adj_ptr[v]..sys.adj_ptr[v + 1]]
            .iter()
            .map(|&(p, a)| sys.values[p as usize * sys.stride + a as usize] * mass[p as usize])
            .sum();
    });
}

/// Adds $\text{scale}\,S_{vp}\,f$ to the nodes of point `p`.
#[inline]
fn scatter<const D: usize>(
    sys: &StepSystem<D>,
    f_ext: &mut [f64],
    p: usize,
    scale: f64,
    force: &SVector<f64, D>,
) {
    for s in sys.slots(p) {
        let v = sys.nodes[s] as usize;
        for i in 0..D {
            f_ext[D * v + i] += scale * sys.values[s] * force[i];
        }
    }
}

/// $f^{ext} \mathrel{+}= \lambda_1\sum_p [S_{vp}]^T(b_p + f_p)$ (eqs. 24,
/// 25, 29), plus the non-proportional body force
/// $\sum_p [S_{vp}]^T b_p(\lambda_1)$ when the points have one. Points
/// without loads cost nothing: the loops run over the loads present.
pub fn external_force<const D: usize, H, Dom>(
    sys: &StepSystem<D>,
    points: &MaterialPoints<D, H, Dom>,
    lambda1: f64,
    f_ext: &mut [f64],
) {
    for (p, b) in points.body_force.iter().enumerate() {
        scatter(sys, f_ext, p, lambda1, b);
    }
    for (p, force) in &points.point_force {
        scatter(sys, f_ext, *p, lambda1, force);
    }
    if let Some(path) = &points.body_force_path {
        for p in 0..points.position.len() {
            scatter(sys, f_ext, p, 1.0, &(path.0)(p, lambda1));
        }
    }
}

/// $f^{int}_v = \sum_p [\nabla S_{vp}]^T\{\sigma\}V$ (eqs. 6, 23, 28) from
/// each point's volume-weighted stress `stress_w` and the gradients
/// `grads` (the step's, or mapped by eq. 8), one active node per task.
pub fn internal_force<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    stress_w: &[PointStress<D>],
    f_int: &mut [f64],
) {
    f_int.par_chunks_mut(D).enumerate().for_each(|(v, f)| {
        f.iter_mut().for_each(|x| *x = 0.0);
        node_force(sys, grads, stress_w, v, f);
    });
}

/// Adds node `v`'s internal force to `f`, its points in ascending order.
#[inline(always)]
fn node_force<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    stress_w: &[PointStress<D>],
    v: usize,
    f: &mut [f64],
) {
    for &(p, a) in &sys.adj[sys.adj_ptr[v]..sys.adj_ptr[v + 1]] {
        let s = p as usize * sys.stride + a as usize;
        let sw = &stress_w[p as usize];
        for i in 0..D {
            for j in 0..D {
                f[i] += sw[(i, j)] * grads[s][j];
            }
        }
    }
}

/// A point's volume-weighted stress on the components the internal force
/// reads: $f^{int}_{v,i} = \sum_p s_{ij}\nabla_j S_{vp}$ with basis
/// gradients that have no out-of-plane component, so plane strain reads
/// the in-plane $2\times 2$ block (3D all nine).
pub type PointStress<const D: usize> = SMatrix<f64, D, D>;

/// A point's volume-weighted tangent on the components a `D`-dimensional
/// problem reads, `t[i][j][k][l]` $= T_{ijkl}$ for $i, j, k, l < D$: the
/// stiffness (eqs. 4/21, 27) contracts $T$ with basis gradients, whose
/// out-of-plane component is zero, so plane strain reads 16 of the 81
/// components of the $9\times 9$ tangent (3D reads all of them, in this
/// order). Storing all 81 costs the specialised kernel of
/// `benches/specialised.rs` 7–17 % of its pass over the points in 2D
/// (`docs/src/benchmarks/zero_cost.md`).
pub type PointTangent<const D: usize> = [[[[f64; D]; D]; D]; D];

/// Writes the `D`-dimensional components of the tangent `a`
/// ([`mpm_constitutive::tensor::idx`] storage) times `scale` into `t`.
#[inline(always)]
pub fn restrict_tangent<const D: usize>(a: &Tensor4, scale: f64, t: &mut PointTangent<D>) {
    for (i, ti) in t.iter_mut().enumerate() {
        for (j, tij) in ti.iter_mut().enumerate() {
            for (k, tijk) in tij.iter_mut().enumerate() {
                for (l, tijkl) in tijk.iter_mut().enumerate() {
                    *tijkl = a[(idx(i, j), idx(k, l))] * scale;
                }
            }
        }
    }
}

/// The stiffness (eqs. 4/21, 27) in the step's CSC pattern over free
/// dofs, $K_{(vi)(wk)} = \sum_p \nabla_j S_{vp}\,T_{ijkl}\,\nabla_l S_{wp}$
/// with each point's volume-weighted tangent `tangent_w`; one block column
/// (active node $w$) per task, each entry summed over points in ascending
/// order. Where each coupling goes comes from [`StepSystem::slot_offset`]
/// (built once per step) when it exists.
pub fn stiffness<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    tangent_w: &[PointTangent<D>],
    values: &mut [f64],
) {
    node_pass::<D, false>(sys, grads, tangent_w, &[], values, &mut []);
}

/// [`internal_force`] and [`stiffness`] in one pass over the nodes, for an
/// iteration whose tangents are known before its convergence test (the
/// same sums in the same order, so the same numbers bit for bit): each
/// point-node pair is read once for both.
pub fn internal_force_and_stiffness<const D: usize>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    stress_w: &[PointStress<D>],
    tangent_w: &[PointTangent<D>],
    f_int: &mut [f64],
    values: &mut [f64],
) {
    node_pass::<D, true>(sys, grads, tangent_w, stress_w, values, f_int);
}

/// The stiffness, with the internal force when `FORCE`.
fn node_pass<const D: usize, const FORCE: bool>(
    sys: &StepSystem<D>,
    grads: &[SVector<f64, D>],
    tangent_w: &[PointTangent<D>],
    stress_w: &[PointStress<D>],
    values: &mut [f64],
    f_int: &mut [f64],
) {
    let block = |w: usize, vals: &mut [f64], f: &mut [f64]| {
        if FORCE {
            f.iter_mut().for_each(|x| *x = 0.0);
        }
        if vals.is_empty() {
            // Every dof of w is prescribed: no column to assemble.
            if FORCE {
                node_force(sys, grads, stress_w, w, f);
            }
            return;
        }
        vals.iter_mut().for_each(|x| *x = 0.0);
        let nbs = &sys.nb[sys.nb_ptr[w]..sys.nb_ptr[w + 1]];
        let map = &sys.block_map[sys.nb_ptr[w] * D * D..sys.nb_ptr[w + 1] * D * D];
        // Column length of a block whose D columns are all present.
        let column = vals.len() / D;
        // The node's force, summed in registers.
        let mut force = [0.0f64; D];
        for &(p, b) in &sys.adj[sys.adj_ptr[w]..sys.adj_ptr[w + 1]] {
            let p = p as usize;
            let t = &tangent_w[p];
            let gw = &grads[p * sys.stride + b as usize];
            if FORCE {
                let sw = &stress_w[p];
                for i in 0..D {
                    for j in 0..D {
                        force[i] += sw[(i, j)] * gw[j];
                    }
                }
            }
            // q[i][j][k] = Σ_l T_(ij)(kl) g_w,l
            let mut q = [[[0.0f64; D]; D]; D];
            for i in 0..D {
                for j in 0..D {
                    for k in 0..D {
                        let mut acc = 0.0;
                        for l in 0..D {
                            acc += t[i][j][k][l] * gw[l];
                        }
                        q[i][j][k] = acc;
                    }
                }
            }
            let start = p * sys.stride;
            let m = sys.counts[p] as usize;
            let point_grads = &grads[start..start + m];
            let Some(&ptr) = sys.slot_offset_ptr.get(p) else {
                // Wider than the table: place each entry through the block
                // map.
                for (gv, node) in point_grads.iter().zip(&sys.nodes[start..start + m]) {
                    if let Ok(pos) = nbs.binary_search(node) {
                        scatter_wide(&map[pos * D * D..(pos + 1) * D * D], gv, &q, vals);
                    }
                }
                continue;
            };
            let row = &sys.slot_offset[ptr + b as usize * m..ptr + (b as usize + 1) * m];
            for (gv, &entry) in point_grads.iter().zip(row) {
                if entry == NO_ENTRY {
                    continue;
                }
                if entry & PARTIAL == 0 {
                    // Both nodes free: rows i and columns k are contiguous
                    // from the pair's first entry, which the table holds.
                    let base = entry as usize;
                    for k in 0..D {
                        for i in 0..D {
                            let mut acc = 0.0;
                            for j in 0..D {
                                acc += gv[j] * q[i][j][k];
                            }
                            vals[base + k * column + i] += acc;
                        }
                    }
                    continue;
                }
                let pos = (entry & !PARTIAL) as usize;
                scatter_wide(&map[pos * D * D..(pos + 1) * D * D], gv, &q, vals);
            }
        }
        if FORCE {
            f.copy_from_slice(&force);
        }
    };
    let per_node = if FORCE { D } else { 0 };
    split_blocks(
        0,
        sys.n_active(),
        values,
        0,
        f_int,
        per_node,
        &sys.block_ptr,
        &block,
    );
}

/// Adds the patch coupling of a locking treatment to a stiffness
/// assembled by [`stiffness`]: $K_{(vi)(wk)} \mathrel{+}= \sum_p
/// h_{vp,i}\,(\mathbf G_{wP} - \mathbf g_{wp})_k$ over the points $p$ of
/// every patch $P$ whose node union holds $w$ ([`PatchSystem`]; the
/// pattern must be the patch pattern of
/// [`PatchSystem::neighbours`], each entry placed through
/// [`PatchSystem::place`]). One block column per task,
/// patches and points ascending, so the sums do not depend on the thread
/// count.
pub fn patch_coupling<const D: usize>(
    sys: &StepSystem<D>,
    patches: &PatchSystem<D>,
    values: &mut [f64],
) {
    let block = |w: usize, vals: &mut [f64]| {
        let map = &sys.block_map[sys.nb_ptr[w] * D * D..sys.nb_ptr[w + 1] * D * D];
        for &(k, u) in &patches.node_patches[patches.node_ptr[w]..patches.node_ptr[w + 1]] {
            let k = k as usize;
            let len = patches.union_ptr[k + 1] - patches.union_ptr[k];
            let start = patches.place_ptr[k] + u as usize * len;
            // Neighbour position of every union node in column w's list.
            let place = &patches.place[start..start + len];
            for &p in patches.members_of(k) {
                let p = p as usize;
                let c = patches.column(sys, p, u);
                for s in sys.slots(p) {
                    let pos = place[patches.local[s] as usize] as usize;
                    let rows = &map[pos * D * D..(pos + 1) * D * D];
                    let h = &patches.h[s];
                    for i in 0..D {
                        for kk in 0..D {
                            let off = rows[i * D + kk];
                            if off != NONE {
                                vals[off as usize] += h[i] * c[kk];
                            }
                        }
                    }
                }
            }
        }
    };
    split_blocks(
        0,
        sys.n_active(),
        values,
        0,
        &mut [],
        0,
        &sys.block_ptr,
        &|w, v, _| block(w, v),
    );
}

/// Adds the coupling `gv · q` of one row node through its block-map rows
/// `map` (entries [`NONE`] skipped).
#[inline]
fn scatter_wide<const D: usize>(
    map: &[u32],
    gv: &SVector<f64, D>,
    q: &[[[f64; D]; D]; D],
    vals: &mut [f64],
) {
    for i in 0..D {
        for k in 0..D {
            let off = map[i * D + k];
            if off != NONE {
                let mut acc = 0.0;
                for j in 0..D {
                    acc += gv[j] * q[i][j][k];
                }
                vals[off as usize] += acc;
            }
        }
    }
}

/// Runs `f(w, values_of_block_w, nodal_of_w)` for the block columns
/// `lo..hi` in parallel, splitting `vals` (which starts at block `lo`,
/// value index `base`) into disjoint slices at block boundaries, and
/// `nodal` (which starts at node `lo`) into `per_node` values per node
/// (`per_node = 0` with an empty `nodal` when there is nothing per node).
#[allow(clippy::too_many_arguments)]
fn split_blocks<F>(
    lo: usize,
    hi: usize,
    vals: &mut [f64],
    base: usize,
    nodal: &mut [f64],
    per_node: usize,
    block_ptr: &[usize],
    f: &F,
) where
    F: Fn(usize, &mut [f64], &mut [f64]) + Sync,
{
    const GRAIN: usize = 64;
    if hi - lo <= GRAIN {
        let (mut rest, mut nodal_rest) = (vals, nodal);
        for w in lo..hi {
            let len = block_ptr[w + 1] - block_ptr[w];
            let (head, tail) = rest.split_at_mut(len);
            let (node, nodal_tail) = nodal_rest.split_at_mut(per_node);
            f(w, head, node);
            rest = tail;
            nodal_rest = nodal_tail;
        }
        return;
    }
    let mid = (lo + hi) / 2;
    let (left, right) = vals.split_at_mut(block_ptr[mid] - base);
    let (nodal_left, nodal_right) = nodal.split_at_mut(per_node * (mid - lo));
    rayon::join(
        || split_blocks(lo, mid, left, base, nodal_left, per_node, block_ptr, f),
        || {
            split_blocks(
                mid,
                hi,
                right,
                block_ptr[mid],
                nodal_right,
                per_node,
                block_ptr,
                f,
            )
        },
    );
}

/// Per active node, the support $\sum_p S_{vp}V_p$ and the stiffness
/// weight $\sum_p|\nabla S_{vp}|^2V_p$ (the fringe-node rules of
/// [`crate::NewtonOptions`]).
pub fn support_weights<const D: usize>(
    sys: &StepSystem<D>,
    volumes: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    (0..sys.n_active())
        .map(|v| {
            sys.adj[sys.adj_ptr[v]..sys.adj_ptr[v + 1]].iter().fold(
                (0.0, 0.0),
                |(s, k), &(p, a)| {
                    let slot = p as usize * sys.stride + a as usize;
                    let volume = volumes[p as usize];
                    (
                        s + sys.values[slot] * volume,
                        k + sys.grads[slot].norm_squared() * volume,
                    )
                },
            )
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two points on a 1D-like chain of three nodes in 2D.
    fn system() -> StepSystem<2> {
        let mut sys = StepSystem::<2> {
            stride: 2,
            nodes: vec![5, 7, 7, 9],
            values: vec![0.25, 0.75, 0.5, 0.5],
            grads: vec![SVector::<f64, 2>::new(-1.0, 0.0); 4],
            counts: vec![2, 2],
            ..StepSystem::default()
        };
        sys.number_nodes(10);
        sys.build_adjacency();
        sys
    }

    /// Two points' tangents.
    fn tangents() -> Vec<PointTangent<2>> {
        (0..2)
            .map(|p| {
                let mut t = [[[[0.0; 2]; 2]; 2]; 2];
                let a = Tensor4::from_fn(|r, c| 1.0 + (r * 9 + c + 17 * p) as f64 * 0.01);
                restrict_tangent(&a, 1.0, &mut t);
                t
            })
            .collect()
    }

    /// The stiffness placed through the table [`StepSystem::slot_offset`]
    /// and by the search it replaces, bit for bit; returns it.
    fn table_equals_search(sys: &mut StepSystem<2>) -> Vec<f64> {
        let tangent = tangents();
        let mut with_table = vec![0.0; sys.row_idx.len()];
        sys.build_slot_offsets();
        assert!(!sys.slot_offset.is_empty());
        stiffness(sys, &sys.grads, &tangent, &mut with_table);
        sys.slot_offset.clear();
        sys.slot_offset_ptr.clear();
        let mut searched = vec![f64::NAN; sys.row_idx.len()];
        stiffness(sys, &sys.grads, &tangent, &mut searched);
        assert_eq!(with_table, searched);
        with_table
    }

    /// The placement table and the search it replaces give the same
    /// stiffness, bit for bit, with free, partly prescribed and fixed
    /// nodes.
    #[test]
    fn table_and_search_place_every_entry_alike() {
        let mut sys = system();
        for (s, g) in sys.grads.iter_mut().enumerate() {
            *g = SVector::<f64, 2>::new(0.3 * s as f64 - 0.4, 1.0 / (1.0 + s as f64));
        }
        sys.build_neighbours();
        // Mesh node 5 fully free, 7 with its y prescribed, 9 fixed.
        sys.build_pattern(&|node, i| match (node, i) {
            (7, 1) | (9, _) => Some(0.0),
            _ => None,
        });
        let k = table_equals_search(&mut sys);
        assert!(k.iter().all(|v| v.is_finite() && *v != 0.0));
    }

    /// Block columns longer than the table's direct offsets (a point with
    /// 70 nodes: columns of 140 rows) place the far pairs through the
    /// block map, and still as the search does.
    #[test]
    fn long_columns_fall_back_to_the_block_map() {
        let stride = 70;
        let mut nodes: Vec<u32> = (0..70).collect();
        nodes.extend([66, 68, 70]);
        nodes.resize(2 * stride, 0);
        let mut sys = StepSystem::<2> {
            stride,
            values: vec![0.5; 2 * stride],
            grads: (0..2 * stride)
                .map(|s| SVector::<f64, 2>::new((0.7 * s as f64).sin(), (1.3 * s as f64).cos()))
                .collect(),
            nodes,
            counts: vec![70, 3],
            ..StepSystem::default()
        };
        sys.number_nodes(71);
        sys.build_adjacency();
        sys.build_neighbours();
        // Mesh node 0 fixed, every other node free: a flagged entry can
        // only be a fall-back.
        sys.build_pattern(&|node, _| (node == 0).then_some(0.0));
        let k = table_equals_search(&mut sys);
        assert!(k.iter().all(|v| v.is_finite()));
        // Both kinds of free pairs occur: direct offsets and the flagged
        // fall-back.
        sys.build_slot_offsets();
        let direct = sys
            .slot_offset
            .iter()
            .filter(|&&e| e & PARTIAL == 0)
            .count();
        let flagged = sys
            .slot_offset
            .iter()
            .filter(|&&e| e != NO_ENTRY && e & PARTIAL != 0)
            .count();
        assert!(
            direct > 0 && flagged > 0,
            "{direct} direct, {flagged} flagged"
        );
    }

    /// The restriction keeps component (ij)(kl) of the 9 × 9 storage for
    /// i, j, k, l < D, scaled; in 3D that is every component.
    #[test]
    fn the_restricted_tangent_keeps_the_in_plane_components() {
        let a = Tensor4::from_fn(|r, c| (r * 9 + c) as f64);
        let mut t2 = [[[[0.0; 2]; 2]; 2]; 2];
        restrict_tangent(&a, 0.5, &mut t2);
        assert_eq!(t2[0][1][1][0], 0.5 * (1.0 * 9.0 + 3.0));
        assert_eq!(t2[1][1][0][1], 0.5 * (4.0 * 9.0 + 1.0));
        let mut t3 = [[[[0.0; 3]; 3]; 3]; 3];
        restrict_tangent(&a, 2.0, &mut t3);
        let flat: Vec<f64> = t3.iter().flatten().flatten().flatten().copied().collect();
        let mut all: Vec<f64> = a.iter().map(|x| 2.0 * x).collect();
        all.sort_by(f64::total_cmp);
        let mut sorted = flat.clone();
        sorted.sort_by(f64::total_cmp);
        assert_eq!(sorted, all);
        assert_eq!(t3[2][0][1][2], 2.0 * (6.0 * 9.0 + 5.0));
    }

    #[test]
    fn nodal_mass_conserves_the_total_mass() {
        let sys = system();
        let mut m = Vec::new();
        nodal_mass(&sys, &[2.0, 4.0], &mut m);
        assert_eq!(m, vec![0.5, 1.5 + 2.0, 2.0]);
        assert_eq!(m.iter().sum::<f64>(), 6.0);
    }
}
