//! Named node and element sets: boundary node sets of the generators
//! (`"x0"`, `"x1"`, …, `"inner"`, `"outer"`) and Gmsh physical groups.

use std::collections::BTreeMap;

use crate::MeshError;

/// Sets of node or element ids by name, each sorted and without repeats.
///
/// Names are kept in a `BTreeMap`, so iteration is in name order and
/// deterministic.
///
/// ```
/// use mpm_mesh::NamedSets;
/// let mut sets = NamedSets::default();
/// sets.insert("base", vec![3, 1, 3, 2], 10)?;
/// assert_eq!(sets.get("base"), Some(&[1, 2, 3][..]));
/// assert!(sets.insert("bad", vec![10], 10).is_err());
/// # Ok::<(), mpm_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NamedSets {
    sets: BTreeMap<String, Vec<usize>>,
}

impl NamedSets {
    /// Insert (or replace) the set `name` with the ids `ids`, sorted and
    /// deduplicated.
    ///
    /// # Errors
    /// [`MeshError::SetIdOutOfRange`] naming the set and the first id not
    /// below `count`; the sets are then unchanged.
    pub fn insert(
        &mut self,
        name: impl Into<String>,
        mut ids: Vec<usize>,
        count: usize,
    ) -> Result<(), MeshError> {
        let name = name.into();
        if let Some(&id) = ids.iter().find(|&&id| id >= count) {
            return Err(MeshError::SetIdOutOfRange {
                set: name,
                id,
                count,
            });
        }
        ids.sort_unstable();
        ids.dedup();
        self.sets.insert(name, ids);
        Ok(())
    }

    /// Insert (or replace) the set `name` with ids the caller built from a
    /// valid mesh, so they need no range check.
    pub(crate) fn insert_trusted(&mut self, name: impl Into<String>, mut ids: Vec<usize>) {
        ids.sort_unstable();
        ids.dedup();
        self.sets.insert(name.into(), ids);
    }

    /// Add `ids` to the set `name` (creating it), keeping it sorted and
    /// without repeats; used for Gmsh physical groups spread over several
    /// entities.
    ///
    /// # Errors
    /// As [`NamedSets::insert`].
    pub fn extend(
        &mut self,
        name: impl Into<String>,
        ids: impl IntoIterator<Item = usize>,
        count: usize,
    ) -> Result<(), MeshError> {
        let name = name.into();
        let mut all = self.sets.remove(&name).unwrap_or_default();
        all.extend(ids);
        self.insert(name, all, count)
    }

    /// The set `name`, if present.
    pub fn get(&self, name: &str) -> Option<&[usize]> {
        self.sets.get(name).map(Vec::as_slice)
    }

    /// The names, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.sets.keys().map(String::as_str)
    }

    /// `(name, ids)` pairs in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &[usize])> {
        self.sets.iter().map(|(k, v)| (k.as_str(), v.as_slice()))
    }

    /// Number of sets.
    pub fn len(&self) -> usize {
        self.sets.len()
    }

    /// Whether there are no sets.
    pub fn is_empty(&self) -> bool {
        self.sets.is_empty()
    }
}

/// The named node and element sets of one mesh, with the node and element
/// counts that bound their ids.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MeshSets {
    nodes: NamedSets,
    elements: NamedSets,
    node_count: usize,
    element_count: usize,
}

impl MeshSets {
    /// No sets, for a mesh of `node_count` nodes and `element_count`
    /// elements.
    pub(crate) fn new(node_count: usize, element_count: usize) -> Self {
        Self {
            node_count,
            element_count,
            ..Self::default()
        }
    }

    /// Replace all sets (ids already checked by the caller).
    pub(crate) fn replace(&mut self, nodes: NamedSets, elements: NamedSets) {
        self.nodes = nodes;
        self.elements = elements;
    }

    /// Named node sets (boundary sets of the generators, Gmsh physical
    /// groups).
    pub fn nodes(&self) -> &NamedSets {
        &self.nodes
    }

    /// Named element sets (Gmsh physical groups of the mesh dimension).
    pub fn elements(&self) -> &NamedSets {
        &self.elements
    }

    /// Insert (or replace) the node set `name`.
    ///
    /// # Errors
    /// [`MeshError::SetIdOutOfRange`] for an id that is not a node.
    pub fn insert_nodes(
        &mut self,
        name: impl Into<String>,
        ids: Vec<usize>,
    ) -> Result<(), MeshError> {
        self.nodes.insert(name, ids, self.node_count)
    }

    /// Insert (or replace) the element set `name`.
    ///
    /// # Errors
    /// [`MeshError::SetIdOutOfRange`] for an id that is not an element.
    pub fn insert_elements(
        &mut self,
        name: impl Into<String>,
        ids: Vec<usize>,
    ) -> Result<(), MeshError> {
        self.elements.insert(name, ids, self.element_count)
    }
}
