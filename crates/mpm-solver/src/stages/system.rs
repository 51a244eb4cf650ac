//! The per-load-step system: basis stencils at the start of the step,
//! active nodes, degrees of freedom, the node-to-point adjacency and the
//! sparsity pattern of the stiffness. All of it is built once per step (the
//! active set does not change within a step) into buffers that keep their
//! capacity between steps.

use nalgebra::SVector;

/// Marker for "none" in the `u32` index maps.
pub const NONE: u32 = u32::MAX;

/// Stencils of every material point with a fixed stride, node ids in
/// active numbering after [`StepSystem::number_nodes`].
#[derive(Debug, Default)]
pub struct StepSystem<const D: usize> {
    /// Slots per point.
    pub stride: usize,
    /// Node of each stencil entry (mesh id, then active id).
    pub nodes: Vec<u32>,
    /// Basis value $S_{vp}$.
    pub values: Vec<f64>,
    /// Basis gradient $\partial S_{vp}/\partial\tilde X$.
    pub grads: Vec<SVector<f64, D>>,
    /// Number of used slots per point.
    pub counts: Vec<u32>,
    /// Active id of each mesh node, or [`NONE`].
    pub active_of_mesh: Vec<u32>,
    /// Mesh id of each active node.
    pub active: Vec<usize>,
    /// CSR over active nodes: `adj[adj_ptr[v]..adj_ptr[v+1]]` lists the
    /// (point, slot) pairs whose stencil holds `v`, points ascending.
    pub adj_ptr: Vec<usize>,
    /// See `adj_ptr`.
    pub adj: Vec<(u32, u32)>,
    /// CSR over active nodes: sorted active neighbours sharing a point.
    pub nb_ptr: Vec<usize>,
    /// See `nb_ptr`.
    pub nb: Vec<u32>,
    /// Free index of each active dof (`D * v + i`), or [`NONE`] if prescribed.
    pub free_of_dof: Vec<u32>,
    /// Prescribed increment of each active dof (zero for free ones).
    pub prescribed: Vec<f64>,
    /// Number of free dofs.
    pub n_free: usize,
    /// CSC column pointers over free dofs.
    pub col_ptr: Vec<usize>,
    /// CSC row indices.
    pub row_idx: Vec<usize>,
    /// Start of each active node's block column in the CSC values
    /// (`n_active + 1` entries; the block columns are contiguous).
    pub block_ptr: Vec<usize>,
    /// For block column `w`, entry `(pos, i, k)` at
    /// `block_map[nb_ptr[w] * D * D + (pos * D + i) * D + k]`: offset in the
    /// block's value slice of row dof `(nb[pos], i)`, column dof `(w, k)`,
    /// or [`NONE`] if either is prescribed.
    pub block_map: Vec<u32>,
    /// Per point `p` with `m` used slots, the `m × m` entries
    /// `slot_offset[slot_offset_ptr[p] + b * m + a]` that place the
    /// coupling of the node of slot `a` (row) with the node of slot `b`
    /// (block column) in the stiffness values, so that the scatter does not
    /// search the neighbour lists in every iteration. For two free nodes,
    /// the offset `first` of row `(v_a, 0)` of column `(w_b, 0)` in the
    /// block's values when it is below [`PARTIAL`]: row `(v_a, i)` of
    /// column `(w_b, k)` is then at `first` plus `i` rows and `k` column
    /// lengths. Otherwise the position `pos` of `v_a` in the neighbour list
    /// of `w_b` plus [`PARTIAL`], and the block map places each entry; or
    /// [`NO_ENTRY`] when either node has all its dofs prescribed. One byte per pair keeps the table small (64 bytes per point
    /// for linear hexahedra), which matters more than the indirection: the
    /// stiffness pass reads every point once from each of its nodes, a grid
    /// layer apart. Empty when a neighbour list has more than 126 entries
    /// (wider than the 5³ stencils of GIMP or quadratic B-splines on
    /// hexahedra) or the table would exceed
    /// [`MAX_SLOT_ENTRIES`]: the scatter then searches.
    pub slot_offset: Vec<u8>,
    /// See `slot_offset` (`n_points + 1` entries when the table is built).
    pub slot_offset_ptr: Vec<usize>,
}

/// Largest number of entries of [`StepSystem::slot_offset`] (16 MiB);
/// beyond it the stiffness scatter searches the neighbour lists.
pub const MAX_SLOT_ENTRIES: usize = 16 << 20;

/// Flag of a [`StepSystem::slot_offset`] entry placed entry by entry
/// through the block map: a node pair with a prescribed dof, or one whose
/// first offset does not fit below the flag.
pub const PARTIAL: u8 = 1 << 7;

/// A [`StepSystem::slot_offset`] entry with nothing to place: a node pair
/// of which one node has every dof prescribed (its rows or its columns are
/// not in the stiffness), or a node not in the list (never for a
/// consistent system).
pub const NO_ENTRY: u8 = u8::MAX;

impl<const D: usize> StepSystem<D> {
    /// Number of active nodes.
    pub fn n_active(&self) -> usize {
        self.active.len()
    }

    /// Slot range of point `p`.
    #[inline]
    pub fn slots(&self, p: usize) -> std::ops::Range<usize> {
        let start = p * self.stride;
        start..start + self.counts[p] as usize
    }

    /// Marks the active nodes, numbers them by ascending mesh id and
    /// rewrites the stencils in active numbering.
    pub fn number_nodes(&mut self, node_count: usize) {
        self.number_nodes_with(node_count, &mut |_| {});
    }

    /// [`Self::number_nodes`], with `unite` seeing the marks (0 for a
    /// node the points touch, [`NONE`] otherwise) before the numbering:
    /// on several ranks, it adds the nodes the other ranks' points touch.
    pub fn number_nodes_with(&mut self, node_count: usize, unite: &mut dyn FnMut(&mut [u32])) {
        self.active_of_mesh.clear();
        self.active_of_mesh.resize(node_count, NONE);
        for p in 0..self.counts.len() {
            for s in self.slots(p) {
                self.active_of_mesh[self.nodes[s] as usize] = 0;
            }
        }
        unite(&mut self.active_of_mesh);
        self.active.clear();
        for (mesh_id, slot) in self.active_of_mesh.iter_mut().enumerate() {
            if *slot != NONE {
                *slot = self.active.len() as u32;
                self.active.push(mesh_id);
            }
        }
        for p in 0..self.counts.len() {
            for s in self.slots(p) {
                self.nodes[s] = self.active_of_mesh[self.nodes[s] as usize];
            }
        }
    }

    /// Builds the node-to-point adjacency (counting sort: points ascend
    /// within each node, which fixes the summation order of the assembly
    /// whatever the number of threads).
    pub fn build_adjacency(&mut self) {
        let n = self.n_active();
        self.adj_ptr.clear();
        self.adj_ptr.resize(n + 1, 0);
        for p in 0..self.counts.len() {
            for s in self.slots(p) {
                self.adj_ptr[self.nodes[s] as usize + 1] += 1;
            }
        }
        for v in 0..n {
            self.adj_ptr[v + 1] += self.adj_ptr[v];
        }
        self.adj.clear();
        self.adj.resize(self.adj_ptr[n], (0, 0));
        let mut fill: Vec<usize> = self.adj_ptr[..n].to_vec();
        for p in 0..self.counts.len() {
            let start = p * self.stride;
            for s in self.slots(p) {
                let v = self.nodes[s] as usize;
                self.adj[fill[v]] = (p as u32, (s - start) as u32);
                fill[v] += 1;
            }
        }
    }

    /// Sorted neighbour lists: nodes sharing at least one point.
    pub fn build_neighbours(&mut self) {
        let (adj_ptr, adj) = (&self.adj_ptr, &self.adj);
        let (stride, counts, nodes) = (self.stride, &self.counts, &self.nodes);
        neighbour_lists(
            self.active.len(),
            &mut self.nb_ptr,
            &mut self.nb,
            &|w, push| {
                for &(p, _) in &adj[adj_ptr[w]..adj_ptr[w + 1]] {
                    let start = p as usize * stride;
                    for &v in &nodes[start..start + counts[p as usize] as usize] {
                        push(v);
                    }
                }
            },
        );
    }

    /// Sorted, duplicate-free neighbour lists of the nodes that
    /// `neighbours(w, push)` pushes for every node `w`: the hook through
    /// which a coupled locking treatment gives its wider pattern
    /// ([`crate::stages::patch::PatchSystem::neighbours`]: nodes sharing
    /// a patch), as [`Self::extend_neighbours`] is the ghost penalty's.
    pub fn build_neighbours_from(&mut self, neighbours: &Candidates<'_>) {
        neighbour_lists(
            self.active.len(),
            &mut self.nb_ptr,
            &mut self.nb,
            neighbours,
        );
    }

    /// Adds to every neighbour list the nodes `extra(w, push)` pushes for
    /// node `w` (the partners of a ghost-penalty face,
    /// [`crate::stages::ghost::GhostFaces::partners`]); lists stay sorted
    /// and duplicate-free. Call it before anything records positions in
    /// the lists (the patch placement, [`Self::build_pattern`]).
    pub fn extend_neighbours(&mut self, extra: &Candidates<'_>) {
        let (old_ptr, old) = (
            std::mem::take(&mut self.nb_ptr),
            std::mem::take(&mut self.nb),
        );
        neighbour_lists(
            self.active.len(),
            &mut self.nb_ptr,
            &mut self.nb,
            &|w, push| {
                for &v in &old[old_ptr[w]..old_ptr[w + 1]] {
                    push(v);
                }
                extra(w, push);
            },
        );
    }

    /// Whether every dof of active node `v` is free (after
    /// [`Self::build_pattern`]).
    #[inline]
    pub fn all_free(&self, v: usize) -> bool {
        self.free_of_dof[D * v..D * v + D]
            .iter()
            .all(|&f| f != NONE)
    }

    /// Whether every dof of active node `v` is prescribed (after
    /// [`Self::build_pattern`]).
    #[inline]
    pub fn all_prescribed(&self, v: usize) -> bool {
        self.free_of_dof[D * v..D * v + D]
            .iter()
            .all(|&f| f == NONE)
    }

    /// The placement table [`Self::slot_offset`], once per step after
    /// [`Self::build_pattern`].
    pub fn build_slot_offsets(&mut self) {
        self.slot_offset.clear();
        self.slot_offset_ptr.clear();
        let total: usize = self.counts.iter().map(|&m| (m as usize).pow(2)).sum();
        // List positions must fit below the flag, and a flagged position
        // must differ from `NO_ENTRY`.
        let widest = (0..self.n_active())
            .map(|w| self.nb_ptr[w + 1] - self.nb_ptr[w])
            .max()
            .unwrap_or(0);
        if total > MAX_SLOT_ENTRIES || widest >= (NO_ENTRY & !PARTIAL) as usize {
            return;
        }
        self.slot_offset.reserve(total);
        self.slot_offset_ptr.push(0);
        for p in 0..self.counts.len() {
            for b in self.slots(p) {
                let w = self.nodes[b] as usize;
                let nbs = &self.nb[self.nb_ptr[w]..self.nb_ptr[w + 1]];
                let w_free = self.all_free(w);
                let w_fixed = self.all_prescribed(w);
                for a in self.slots(p) {
                    let v = self.nodes[a];
                    if w_fixed || self.all_prescribed(v as usize) {
                        self.slot_offset.push(NO_ENTRY);
                        continue;
                    }
                    // Every node of the point's stencil shares the point
                    // with `w`, so it is in `w`'s neighbour list.
                    let entry = match nbs.binary_search(&v) {
                        Ok(pos) if w_free && self.all_free(v as usize) => {
                            // The offset of row (v, 0) in column (w, 0)
                            // when it fits below the flag.
                            let first = self.block_map[(self.nb_ptr[w] + pos) * D * D];
                            match u8::try_from(first) {
                                Ok(first) if first < PARTIAL => first,
                                _ => PARTIAL | pos as u8,
                            }
                        }
                        Ok(pos) => PARTIAL | pos as u8,
                        Err(_) => NO_ENTRY,
                    };
                    self.slot_offset.push(entry);
                }
            }
            self.slot_offset_ptr.push(self.slot_offset.len());
        }
    }

    /// Numbers the free dofs (ascending in `D * v + i`), records prescribed
    /// increments from `prescribed(mesh_node, component)`, and builds the
    /// CSC pattern over free dofs together with the block map.
    pub fn build_pattern(&mut self, prescribed: &dyn Fn(usize, usize) -> Option<f64>) {
        let n = self.n_active();
        self.free_of_dof.clear();
        self.prescribed.clear();
        let mut n_free = 0u32;
        for v in 0..n {
            for i in 0..D {
                match prescribed(self.active[v], i) {
                    Some(du) => {
                        self.free_of_dof.push(NONE);
                        self.prescribed.push(du);
                    }
                    None => {
                        self.free_of_dof.push(n_free);
                        self.prescribed.push(0.0);
                        n_free += 1;
                    }
                }
            }
        }
        self.n_free = n_free as usize;
        self.col_ptr.clear();
        self.col_ptr.push(0);
        self.row_idx.clear();
        self.block_ptr.clear();
        self.block_map.clear();
        for w in 0..n {
            self.block_ptr.push(self.row_idx.len());
            let nbs = &self.nb[self.nb_ptr[w]..self.nb_ptr[w + 1]];
            let base = self.block_map.len();
            self.block_map.resize(base + nbs.len() * D * D, NONE);
            for k in 0..D {
                if self.free_of_dof[D * w + k] == NONE {
                    continue;
                }
                for (pos, &v) in nbs.iter().enumerate() {
                    for i in 0..D {
                        let row = self.free_of_dof[D * v as usize + i];
                        if row != NONE {
                            let offset = self.row_idx.len() - self.block_ptr[w];
                            self.block_map[base + (pos * D + i) * D + k] = offset as u32;
                            self.row_idx.push(row as usize);
                        }
                    }
                }
                self.col_ptr.push(self.row_idx.len());
            }
        }
        self.block_ptr.push(self.row_idx.len());
    }
}

/// The candidate neighbours of node `w`, pushed one by one: `f(w, push)`.
pub type Candidates<'a> = dyn Fn(usize, &mut dyn FnMut(u32)) + 'a;

/// Sorted, duplicate-free neighbour lists of `n` nodes into the CSR
/// `nb_ptr`/`nb`: node `w`'s list holds every node `candidates(w, push)`
/// pushes.
fn neighbour_lists(
    n: usize,
    nb_ptr: &mut Vec<usize>,
    nb: &mut Vec<u32>,
    candidates: &Candidates<'_>,
) {
    let mut mark = vec![NONE; n];
    let mut row: Vec<u32> = Vec::with_capacity(64);
    nb_ptr.clear();
    nb_ptr.push(0);
    nb.clear();
    for w in 0..n {
        row.clear();
        candidates(w, &mut |v| {
            if mark[v as usize] != w as u32 {
                mark[v as usize] = w as u32;
                row.push(v);
            }
        });
        row.sort_unstable();
        nb.extend_from_slice(&row);
        nb_ptr.push(nb.len());
    }
}
