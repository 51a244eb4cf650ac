//! The rigid-body modes of the free dofs: the near-null space an
//! algebraic multigrid preconditioner (PETSc's GAMG, smoothed
//! aggregation) needs to coarsen an elasticity operator well (Vaněk,
//! Mandel & Brezina 1996; PETSc's `MatSetNearNullSpace`). In 2D two
//! translations and one rotation, in 3D three and three; restricted to
//! the free dofs, centred on their centroid and orthonormalised (modified
//! Gram–Schmidt), dropping a mode that the restriction makes dependent
//! (e.g. every dof of one direction prescribed).

use nalgebra::SVector;

/// The orthonormal rigid-body modes over `free` dofs, each given as
/// (position of its node, its component), in free-dof order.
pub fn rigid_body_modes<const D: usize>(free: &[(SVector<f64, D>, usize)]) -> Vec<Vec<f64>> {
    let n = free.len().max(1) as f64;
    let centre = free
        .iter()
        .fold(SVector::<f64, D>::zeros(), |c, (x, _)| c + x)
        / n;
    let rotations: &[(usize, usize)] = match D {
        2 => &[(0, 1)],
        3 => &[(0, 1), (1, 2), (2, 0)],
        _ => &[],
    };
    let translations = (0..D).map(|k| {
        free.iter()
            .map(|&(_, c)| f64::from(u8::from(c == k)))
            .collect()
    });
    // Rotation in the (a, b) plane: u_a = -x_b, u_b = x_a.
    let rotation = |&(a, b): &(usize, usize)| {
        free.iter()
            .map(|(x, c)| {
                let r = x - centre;
                if *c == a {
                    -r[b]
                } else if *c == b {
                    r[a]
                } else {
                    0.0
                }
            })
            .collect::<Vec<f64>>()
    };
    let candidates: Vec<Vec<f64>> = translations.chain(rotations.iter().map(rotation)).collect();
    orthonormalise(candidates)
}

/// Modified Gram–Schmidt, dropping a vector whose remainder is below
/// 1e-10 of its own norm (dependent on the ones kept).
fn orthonormalise(candidates: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(candidates.len());
    for mut v in candidates {
        let norm0 = dot(&v, &v).sqrt();
        for q in &basis {
            let c = dot(&v, q);
            v.iter_mut().zip(q).for_each(|(x, y)| *x -= c * y);
        }
        let norm = dot(&v, &v).sqrt();
        if norm0 > 0.0 && norm > 1e-10 * norm0 {
            v.iter_mut().for_each(|x| *x /= norm);
            basis.push(v);
        }
    }
    basis
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Modes are orthonormal, and each is a rigid motion: on a square of
    /// four nodes with all dofs free, the 2D rotation mode is proportional
    /// to (-y, x) about the centre, and the translations are constant.
    #[test]
    fn modes_are_orthonormal_rigid_motions() {
        let nodes = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        let free: Vec<(SVector<f64, 2>, usize)> = nodes
            .iter()
            .flat_map(|p| (0..2).map(move |c| (SVector::<f64, 2>::from(*p), c)))
            .collect();
        let modes = rigid_body_modes(&free);
        assert_eq!(modes.len(), 3);
        for (i, a) in modes.iter().enumerate() {
            for (j, b) in modes.iter().enumerate() {
                let d: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((d - expected).abs() < 1e-14, "({i},{j}) = {d}");
            }
        }
        // The rotation: u = s (-(y - 1/2), x - 1/2) for one scale s.
        let r = &modes[2];
        let s = r[1] / (0.0 - 0.5);
        for (k, (x, c)) in free.iter().enumerate() {
            let want = if *c == 0 { -(x[1] - 0.5) } else { x[0] - 0.5 };
            assert!((r[k] - s * want).abs() < 1e-14);
        }
    }

    /// With every y-dof prescribed, the y-translation and the rotation
    /// (which moves y) restricted to the x-dofs: the rotation is
    /// -(y - ȳ) on x-dofs, independent of the x-translation unless all
    /// nodes share one y; on one row of nodes it is dropped.
    #[test]
    fn dependent_modes_are_dropped() {
        let row: Vec<(SVector<f64, 3>, usize)> = (0..4)
            .map(|i| (SVector::<f64, 3>::new(f64::from(i), 0.0, 0.0), 0))
            .collect();
        // Only x-dofs on a line along x: the x-translation survives; the
        // rotations about z (u_x = -y) and about y (u_x = z) vanish there.
        assert_eq!(rigid_body_modes(&row).len(), 1);
    }
}
