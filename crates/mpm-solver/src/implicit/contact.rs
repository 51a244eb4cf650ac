//! The rigid tools' contact as stages of the implicit solver
//! ([`crate::contact`] for the element): which nodes touch a tool this
//! step, their forces in the residual, their tangents on the diagonal
//! blocks of the stiffness, the reactions, and the commit of their forces
//! at the end of a converged step. Per node, not per point: a few hundred
//! entries at most, decided at run time (no type parameter).

use mpm_constitutive::LogStrainLaw;
use nalgebra::SVector;

use super::ImplicitSolver;
use crate::boundary::Constraints;
use crate::contact::{ContactForce, ContactResponse, DEFAULT_PENALTY_FACTOR, NodeContact};
use crate::error::SolverError;
use crate::mesh::NodalMesh;
use crate::parts::{PointsOf, SolverParts};
use crate::stages::system::{NONE, StepSystem};

/// One node in contact with a tool in the current step.
#[derive(Debug, Clone, Copy)]
struct Entry<const D: usize> {
    /// The tool (index into [`Constraints::tools`]).
    tool: usize,
    /// The node's index in the tool's node list.
    index: usize,
    /// Its active id.
    node: usize,
    /// Its penalties and friction.
    law: NodeContact<D>,
    /// The tool's displacement increment over the step.
    tool_du: SVector<f64, D>,
    /// Offset of the node's diagonal block in the stiffness's block map
    /// (`nb_ptr[v] + pos` times `D²`).
    diagonal: usize,
}

/// The contact state of a solver.
#[derive(Debug, Default)]
pub(super) struct ContactState<const D: usize> {
    /// Per tool, the committed force of each of its nodes.
    committed: Vec<Vec<ContactForce<D>>>,
    /// `committed` flat, per tool and node $(f_n, \mathbf t)$: $D + 1$
    /// numbers per node ([`ImplicitSolver::contact_state`]).
    flat: Vec<f64>,
    /// The nodes in contact this step.
    entries: Vec<Entry<D>>,
    /// Per entry, the response at the current increment.
    trial: Vec<ContactResponse<D>>,
    /// Per entry, the points' external force at its node, to which the
    /// tool's force is added ([`ContactState::keep_external`]).
    base: Vec<SVector<f64, D>>,
}

impl<const D: usize> ContactState<D> {
    /// Keeps the points' external force `f_ext` at the nodes in contact
    /// (after the step's external force is assembled).
    pub(super) fn keep_external(&mut self, f_ext: &[f64]) {
        self.base.clear();
        let base = self
            .entries
            .iter()
            .map(|e| SVector::<f64, D>::from_fn(|i, _| f_ext[D * e.node + i]));
        self.base.extend(base);
    }

    /// Whether any node touches a tool this step.
    pub(super) fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Whether a tool in contact moves over this step: its motion starts
    /// the step as a prescribed increment does (the linearised start of
    /// [`crate::FirstTangent::Converged`]).
    pub(super) fn tools_move(&self) -> bool {
        self.entries
            .iter()
            .any(|e| e.tool_du.iter().any(|&u| u != 0.0))
    }
}

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// The nodes of every tool that carry material this step, with their
    /// penalties (after [`StepSystem::build_pattern`]); whether any
    /// tangent may be non-symmetric (a finite μ > 0).
    ///
    /// # Errors
    /// [`SolverError::Contact`] on several ranks, on a mesh that is not a
    /// regular grid, or for a default penalty under a law with no shear
    /// modulus.
    pub(super) fn build_contacts(
        &mut self,
        points: &PointsOf<D, P>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<bool, SolverError> {
        let tools = self.constraints.tools();
        let state = &mut self.contact;
        state.entries.clear();
        state.trial.clear();
        state.base.clear();
        if tools.is_empty() {
            return Ok(false);
        }
        let refuse = |k: usize, reason| SolverError::Contact {
            tool: tools[k].name.clone(),
            reason,
        };
        if self.ranks.is_some() {
            return Err(refuse(
                0,
                "the implicit contact is not available on several ranks (its node forces belong to no rank's points)",
            ));
        }
        let grid = self.mesh.regular_grid().ok_or_else(|| {
            refuse(
                0,
                "the tool's penalties use the cell size of a regular grid; this mesh is not one",
            )
        })?;
        // The mean spacing h̄ = (Π h_i)^(1/D) and a node's area h̄^(D−1).
        let h = grid.spacing().iter().product::<f64>().powf(1.0 / D as f64);
        let area = h.powi(D as i32 - 1);
        let law = &self.law;
        let shear = points
            .history
            .iter()
            .map(|hist| law.point_shear_modulus(hist))
            .try_fold(0.0f64, |g, s| s.map(|s| g.max(s)));
        state.committed.resize(tools.len(), Vec::new());
        let sys = &self.system;
        let mut unsymmetric = false;
        for (k, tool) in tools.iter().enumerate() {
            let k_n = match (tool.normal_stiffness, shear) {
                (Some(k), _) => k,
                (None, Some(g)) => DEFAULT_PENALTY_FACTOR * 2.0 * g / h,
                (None, None) => {
                    return Err(refuse(
                        k,
                        "its default penalty scales with the law's shear modulus, and this law gives none: give `normal_stiffness`",
                    ));
                }
            };
            let k_t = tool.tangential_stiffness.unwrap_or(k_n);
            let law = NodeContact {
                normal: tool.normal,
                friction: tool.friction,
                k_n: k_n * area,
                k_t: k_t * area,
            };
            unsymmetric |= law.may_be_unsymmetric();
            let committed = &mut state.committed[k];
            committed.resize(tool.nodes.len(), ContactForce::default());
            let tool_du = self.constraints.tool_increment(k, lambda0, lambda1);
            for (index, &mesh_node) in tool.nodes.iter().enumerate() {
                let Some(&active) = sys.active_of_mesh.get(mesh_node) else {
                    continue;
                };
                if active == NONE {
                    continue;
                }
                let v = active as usize;
                state.entries.push(Entry {
                    tool: k,
                    index,
                    node: v,
                    law,
                    tool_du,
                    diagonal: diagonal_block(sys, v),
                });
            }
        }
        Ok(unsymmetric)
    }

    /// Sets the external force at every node in contact to the points'
    /// plus the tool's force $\mathbf F$ at the current increment, and
    /// keeps the responses for the stiffness, the reactions and the
    /// commit. The tool's force is external: the residual
    /// $f^{int} - f^{ext}$ gains $-\mathbf F$, and the normalisation of
    /// eq. (40) counts it with the external forces (a platen alone loads
    /// a weightless body).
    pub(super) fn add_contact_force(&mut self) {
        let state = &mut self.contact;
        let (du, f_ext) = (&self.it.du, &mut self.it.f_ext);
        state.trial.clear();
        for (e, base) in state.entries.iter().zip(&state.base) {
            let v = e.node;
            let d = SVector::<f64, D>::from_fn(|i, _| du[D * v + i]) - e.tool_du;
            let r = e.law.respond(&state.committed[e.tool][e.index], &d);
            let f = r.force.vector(&e.law.normal);
            for i in 0..D {
                f_ext[D * v + i] = base[i] + f[i];
            }
            state.trial.push(r);
        }
    }

    /// Adds the tangents of the last [`Self::add_contact_force`] to the
    /// diagonal blocks of the stiffness `values` (free dofs only).
    pub(super) fn add_contact_stiffness(&self, values: &mut [f64]) {
        let sys = &self.system;
        for (e, r) in self.contact.entries.iter().zip(&self.contact.trial) {
            let base = sys.block_ptr[e.node];
            for k in 0..D {
                for i in 0..D {
                    let offset = sys.block_map[e.diagonal + i * D + k];
                    if offset != NONE {
                        values[base + offset as usize] += r.tangent[(i, k)];
                    }
                }
            }
        }
    }

    /// The force on the body at every node in contact (mesh id, ascending
    /// within each tool), at the current increment.
    pub(super) fn contact_forces(&self) -> Vec<(usize, SVector<f64, D>)> {
        let tools = self.constraints.tools();
        self.contact
            .entries
            .iter()
            .zip(&self.contact.trial)
            .map(|(e, r)| (tools[e.tool].nodes[e.index], r.force.vector(&e.law.normal)))
            .collect()
    }

    /// Stage 5 for the tools: the forces of the converged increment
    /// become the start of the next step; a node without material this
    /// step starts the next one free of force.
    pub(super) fn commit_contacts(&mut self) {
        let state = &mut self.contact;
        for c in &mut state.committed {
            c.iter_mut().for_each(|f| *f = ContactForce::default());
        }
        for (e, r) in state.entries.iter().zip(&state.trial) {
            state.committed[e.tool][e.index] = r.force;
        }
        state.flat.clear();
        for f in state.committed.iter().flatten() {
            state.flat.push(f.normal);
            state.flat.extend(f.tangential.iter());
        }
    }

    /// The tools' committed contact forces, per tool and node $(f_n,
    /// \mathbf t)$, for a checkpoint; empty before the first converged
    /// step or without tools.
    pub fn contact_state(&self) -> &[f64] {
        &self.contact.flat
    }

    /// Restores [`Self::contact_state`] (the forces each tool's nodes carry
    /// into the next step).
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] if `flat` does not hold $D + 1$
    /// finite numbers per node of every tool (none without tools), or a
    /// normal force is negative.
    pub fn set_contact_state(&mut self, flat: &[f64]) -> Result<(), SolverError> {
        let sizes: Vec<usize> = self
            .constraints
            .tools()
            .iter()
            .map(|t| t.nodes.len())
            .collect();
        let expected = (D + 1) * sizes.iter().sum::<usize>();
        let valid = flat.chunks(D + 1).all(|f| f[0] >= 0.0) && flat.iter().all(|x| x.is_finite());
        if !flat.is_empty() && (flat.len() != expected || !valid) {
            return Err(SolverError::InvalidInput(format!(
                "the checkpoint's contact state has {} numbers, not the {expected} finite ones (normal force ≥ 0) of the scene's tools",
                flat.len()
            )));
        }
        let mut numbers = flat.chunks(D + 1);
        let state = &mut self.contact;
        state.committed = (sizes.iter())
            .map(|&n| {
                (0..n)
                    .map(|_| match numbers.next() {
                        Some(f) => ContactForce {
                            normal: f[0],
                            tangential: SVector::from_fn(|i, _| f[1 + i]),
                        },
                        None => ContactForce::default(),
                    })
                    .collect()
            })
            .collect();
        state.flat = flat.to_vec();
        Ok(())
    }
}

/// The offset in the block map of active node `v`'s diagonal block: `v`
/// shares its own points, so it is in its own neighbour list.
fn diagonal_block<const D: usize>(sys: &StepSystem<D>, v: usize) -> usize {
    let nbs = &sys.nb[sys.nb_ptr[v]..sys.nb_ptr[v + 1]];
    let pos = nbs.binary_search(&(v as u32)).unwrap_or(0);
    (sys.nb_ptr[v] + pos) * D * D
}
