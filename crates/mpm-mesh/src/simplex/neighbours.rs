//! The element neighbour table `[NE]` of Wang et al. (2021) §4.2,
//! Algorithm 2: one neighbour per face, face `k` opposite local vertex `k`,
//! built once per mesh.
//!
//! Every face is keyed by its sorted node ids. Algorithm 2 matches equal
//! keys through a hash table; here the `(key, element, face)` records are
//! sorted instead, which groups equal keys just as well, needs no hashing,
//! and makes the result (and the error for a face of three elements)
//! independent of any hash seed. A key held by two elements links them; a
//! key held by one element is a boundary face.

use crate::MeshError;

/// Marks a boundary face in the neighbour table (the paper stores −1).
pub const NO_NEIGHBOUR: usize = usize::MAX;

/// A face of the mesh boundary: face `face` (opposite local vertex `face`)
/// of element `element`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BoundaryFace {
    /// The element holding the face.
    pub element: usize,
    /// The local face number, equal to the local vertex opposite it.
    pub face: usize,
}

/// The neighbour table (stride `D + 1`, [`NO_NEIGHBOUR`] on the boundary)
/// and the boundary faces in element order.
pub(crate) fn neighbour_table<const D: usize>(
    connectivity: &[usize],
) -> Result<(Vec<usize>, Vec<BoundaryFace>), MeshError> {
    let stride = D + 1;
    let mut records: Vec<([usize; D], usize)> = Vec::with_capacity(connectivity.len());
    for (element, vertices) in connectivity.chunks_exact(stride).enumerate() {
        for face in 0..stride {
            let mut key = [0; D];
            for (slot, &v) in key.iter_mut().zip(
                vertices
                    .iter()
                    .enumerate()
                    .filter_map(|(k, v)| (k != face).then_some(v)),
            ) {
                *slot = v;
            }
            key.sort_unstable();
            records.push((key, element * stride + face));
        }
    }
    records.sort_unstable();
    let mut neighbours = vec![NO_NEIGHBOUR; connectivity.len()];
    let mut boundary = Vec::new();
    let mut start = 0;
    while start < records.len() {
        let key = records[start].0;
        let end = records[start..]
            .iter()
            .position(|r| r.0 != key)
            .map_or(records.len(), |n| start + n);
        match &records[start..end] {
            [(_, slot)] => boundary.push(BoundaryFace {
                element: slot / stride,
                face: slot % stride,
            }),
            [(_, a), (_, b)] => {
                neighbours[*a] = b / stride;
                neighbours[*b] = a / stride;
            }
            more => {
                return Err(MeshError::NonManifoldFace {
                    nodes: key.to_vec(),
                    first: more[0].1 / stride,
                    second: more[1].1 / stride,
                    third: more[2].1 / stride,
                });
            }
        }
        start = end;
    }
    boundary.sort_unstable();
    Ok((neighbours, boundary))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_face() {
        // Square split along 0-2: triangles (0, 1, 2) and (0, 2, 3).
        let (n, b) = neighbour_table::<2>(&[0, 1, 2, 0, 2, 3]).unwrap();
        // Face 1 of element 0 is (0, 2), opposite vertex 1; face 2 of element 1
        // is (0, 2), opposite vertex 3.
        assert_eq!(
            n,
            vec![NO_NEIGHBOUR, 1, NO_NEIGHBOUR, NO_NEIGHBOUR, NO_NEIGHBOUR, 0]
        );
        assert_eq!(b.len(), 4);
        assert!(b.contains(&BoundaryFace {
            element: 0,
            face: 0
        }));
    }
}
