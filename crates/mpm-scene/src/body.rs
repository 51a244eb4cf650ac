//! Material point bodies filling rectangular (box) regions of a grid.

use mpm_basis::{BasisFunction, Corners};
use mpm_mesh::{RegularGrid, SimplexMesh};
use nalgebra::SVector;

/// Material points laid out `points_per_cell` per direction in every cell
/// of a grid-aligned box, each with the volume of its sub-cell and the
/// half-lengths of its sub-cell as initial domain size (GIMP's
/// $l^0_p$, CPDI2's undeformed rectangle).
#[derive(Debug, Clone)]
pub struct Body<const D: usize> {
    /// Positions.
    pub position: Vec<SVector<f64, D>>,
    /// Initial volumes (plane strain: per unit thickness).
    pub volume: Vec<f64>,
    /// Initial domain half-lengths.
    pub half_lengths: Vec<SVector<f64, D>>,
    /// Sub-cell multi-index of each point within the box, for selecting
    /// points by their place in the lattice (boundary layers, load points).
    pub lattice: Vec<[usize; D]>,
    /// Points per direction in the whole box.
    pub lattice_size: [usize; D],
}

impl<const D: usize> Body<D> {
    /// Fills the box `lower..upper` (grid-aligned up to rounding) with
    /// `points_per_cell` points per direction per cell of `grid`.
    pub fn fill_box(
        grid: &RegularGrid<D>,
        lower: &SVector<f64, D>,
        upper: &SVector<f64, D>,
        points_per_cell: usize,
    ) -> Self {
        let ppc = points_per_cell.max(1);
        let h = grid.spacing();
        let mut lattice_size = [0usize; D];
        let mut step = SVector::<f64, D>::zeros();
        for i in 0..D {
            let cells = ((upper[i] - lower[i]) / h[i]).round().max(1.0) as usize;
            lattice_size[i] = cells * ppc;
            step[i] = (upper[i] - lower[i]) / lattice_size[i] as f64;
        }
        let total: usize = lattice_size.iter().product();
        let volume = step.iter().product::<f64>();
        let mut body = Self {
            position: Vec::with_capacity(total),
            volume: vec![volume; total],
            half_lengths: vec![step / 2.0; total],
            lattice: Vec::with_capacity(total),
            lattice_size,
        };
        for flat in 0..total {
            let mut rest = flat;
            let mut index = [0usize; D];
            let mut x = SVector::<f64, D>::zeros();
            for i in 0..D {
                index[i] = rest % lattice_size[i];
                rest /= lattice_size[i];
                x[i] = lower[i] + (index[i] as f64 + 0.5) * step[i];
            }
            body.position.push(x);
            body.lattice.push(index);
        }
        body
    }

    /// Material points in the elements `elements` of a simplex mesh,
    /// `rule` per element ([`SimplexRule`]), each with its share of the
    /// element's volume; the points have no domain (zero half-lengths)
    /// and no lattice.
    pub fn fill_simplices(mesh: &SimplexMesh<D>, elements: &[usize], rule: SimplexRule) -> Self {
        let local = rule.points::<D>();
        let mut body = Self {
            position: Vec::with_capacity(elements.len() * local.len()),
            volume: Vec::with_capacity(elements.len() * local.len()),
            half_lengths: Vec::new(),
            lattice: Vec::new(),
            lattice_size: [0; D],
        };
        for &e in elements {
            let nodes = mesh.element_nodes(e);
            let volume = mesh.volumes()[e];
            for (bary, share) in &local {
                let x = nodes
                    .iter()
                    .zip(bary)
                    .fold(SVector::<f64, D>::zeros(), |x, (&v, &w)| {
                        x + mesh.nodes()[v] * w
                    });
                body.position.push(x);
                body.volume.push(volume * share);
            }
        }
        body.half_lengths = vec![SVector::zeros(); body.position.len()];
        body
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether the body is empty.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// Where material points sit in a simplex, as barycentric coordinates with
/// a share of the element's volume.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimplexRule {
    /// The element split into $n^D$ sub-simplices of equal volume (in 2D
    /// the similar sub-triangles of $n$ divisions per edge; in 3D the
    /// $n^3$ tetrahedra of the Freudenthal split of the $n$-divided
    /// element), one point at each centroid.
    Subdivision(usize),
    /// The 11 points of Keast's degree-4 tetrahedral rule (Keast 1986,
    /// as used by Wang et al. 2021 §5) with equal volumes $V/11$ (the
    /// rule's own weights include a negative one, which cannot be a
    /// volume). 3D only; in 2D it falls back to `Subdivision(3)`.
    Keast11,
    /// The 4 points of the degree-2 Gauss rule on a tetrahedron (barycentric
    /// coordinates $(5+3\sqrt5)/20$ and $(5-\sqrt5)/20$, equal weights;
    /// Wang et al. 2021 §5.5 use 1, 4 and 11 points per element), volumes
    /// $V/4$. 3D only; in 2D it falls back to `Subdivision(2)`.
    Gauss4,
}

impl SimplexRule {
    /// Barycentric coordinates (D+1 entries used) and volume shares.
    pub fn points<const D: usize>(self) -> Vec<([f64; 4], f64)> {
        match (self, D) {
            (SimplexRule::Keast11, 3) => {
                let mut out = vec![([0.25; 4], 1.0 / 11.0)];
                let (a, b) = (1.0 / 14.0, 11.0 / 14.0);
                for k in 0..4 {
                    let mut w = [a; 4];
                    w[k] = b;
                    out.push((w, 1.0 / 11.0));
                }
                let (c, d) = (0.399_403_576_166_799_2, 0.100_596_423_833_200_8);
                for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
                    let mut w = [d; 4];
                    w[i] = c;
                    w[j] = c;
                    out.push((w, 1.0 / 11.0));
                }
                out
            }
            (SimplexRule::Keast11, _) => SimplexRule::Subdivision(3).points::<D>(),
            (SimplexRule::Gauss4, 3) => {
                let root5 = 5.0f64.sqrt();
                let (a, b) = ((5.0 + 3.0 * root5) / 20.0, (5.0 - root5) / 20.0);
                (0..4)
                    .map(|k| {
                        let mut w = [b; 4];
                        w[k] = a;
                        (w, 0.25)
                    })
                    .collect()
            }
            (SimplexRule::Gauss4, _) => SimplexRule::Subdivision(2).points::<D>(),
            (SimplexRule::Subdivision(n), _) => subdivision_centroids::<D>(n.max(1)),
        }
    }
}

/// Centroids of the $n^D$ equal-volume sub-simplices of a simplex
/// (Freudenthal's subdivision), in barycentric coordinates. The simplex is
/// taken as the Kuhn simplex $K = \{1 \ge y_1 \ge \dots \ge y_D \ge 0\}$
/// (affinely equivalent to any simplex, with vertices
/// $\mathbf v_k = \sum_{i \le k}\mathbf e_i$); the cubes of the
/// $1/n$-lattice split into $D!$ Kuhn simplices, of which those inside $K$
/// (tested at their centroid: $K$'s facets are faces of that
/// triangulation) are exactly $n^D$ translates and reflections of $K/n$.
fn subdivision_centroids<const D: usize>(n: usize) -> Vec<([f64; 4], f64)> {
    let share = 1.0 / (n as f64).powi(D as i32);
    let permutations = mpm_mesh::permutations(D);
    let mut out = Vec::new();
    for flat in 0..n.pow(D as u32) {
        let mut base = [0usize; 3];
        let mut rest = flat;
        for b in base.iter_mut().take(D) {
            *b = rest % n;
            rest /= n;
        }
        for perm in &permutations {
            let mut vertex = base;
            let mut y = [0.0f64; 3];
            for step in 0..=D {
                if step > 0 {
                    vertex[perm[step - 1]] += 1;
                }
                for i in 0..D {
                    y[i] += vertex[i] as f64 / ((D + 1) * n) as f64;
                }
            }
            if (1..D).all(|i| y[i - 1] > y[i]) {
                let mut w = [0.0; 4];
                w[0] = 1.0 - y[0];
                for k in 1..D {
                    w[k] = y[k - 1] - y[k];
                }
                w[D] = y[D - 1];
                out.push((w, share));
            }
        }
    }
    out
}

/// A basis as the cases use it: every [`BasisFunction`] (whose
/// `initial_domain`, `PADDING` and `SUPPORT_RADIUS` place its points).
pub trait InitialDomain<const D: usize>: BasisFunction<D> {}

impl<const D: usize, B: BasisFunction<D>> InitialDomain<D> for B {}

/// The box a material point's domain covers, for output and for measuring
/// a body by its domains (Coombs 2020 Table 7).
pub trait DomainBounds<const D: usize> {
    /// Lower and upper corners of the domain's bounding box, or `None` for
    /// bases without a domain.
    fn bounds(&self, position: &SVector<f64, D>) -> Option<(SVector<f64, D>, SVector<f64, D>)>;
}

impl<const D: usize> DomainBounds<D> for () {
    fn bounds(&self, _: &SVector<f64, D>) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        None
    }
}

/// GIMP: the box $\mathbf x_p \pm \mathbf l_p$.
impl<const D: usize> DomainBounds<D> for SVector<f64, D> {
    fn bounds(&self, position: &SVector<f64, D>) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        Some((position - self, position + self))
    }
}

/// CPDI2: the bounding box of the corners.
impl<const D: usize> DomainBounds<D> for Corners<D> {
    fn bounds(&self, _: &SVector<f64, D>) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        let b = self.bounding_box();
        Some((b.lower, b.upper))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<const D: usize>(rule: SimplexRule, count: usize) {
        let points = rule.points::<D>();
        assert_eq!(points.len(), count, "{rule:?} in {D}D");
        let total: f64 = points.iter().map(|p| p.1).sum();
        assert!((total - 1.0).abs() < 1e-14);
        for k in 0..=D {
            // Equal shares at the sub-centroids integrate the barycentric
            // coordinates exactly: the mean is the element centroid.
            let mean: f64 = points.iter().map(|(w, s)| w[k] * s).sum();
            assert!(
                (mean - 1.0 / (D + 1) as f64).abs() < 1e-14,
                "{rule:?} {k}: {mean}"
            );
        }
        for (w, _) in &points {
            assert!(w.iter().take(D + 1).all(|&x| x > 0.0));
            assert!((w.iter().take(D + 1).sum::<f64>() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn simplex_rules_place_points_inside_with_volumes_summing_to_one() {
        for n in 1..=4 {
            check::<2>(SimplexRule::Subdivision(n), n * n);
            check::<3>(SimplexRule::Subdivision(n), n * n * n);
        }
        check::<3>(SimplexRule::Keast11, 11);
        check::<3>(SimplexRule::Gauss4, 4);
        // Two divisions of a triangle: the three corner sub-triangles and
        // the middle one.
        let mut two: Vec<[f64; 3]> = SimplexRule::Subdivision(2)
            .points::<2>()
            .iter()
            .map(|(w, _)| [w[0], w[1], w[2]])
            .collect();
        two.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        let (a, b) = (4.0 / 6.0, 1.0 / 6.0);
        let expected = [[b, b, a], [b, a, b], [1.0 / 3.0; 3], [a, b, b]];
        for (got, want) in two.iter().zip(expected) {
            assert!(
                got.iter().zip(want).all(|(x, y)| (x - y).abs() < 1e-14),
                "{two:?}"
            );
        }
    }

    #[test]
    fn gauss4_integrates_quadratics_exactly() {
        // ∫ λ_i λ_j dV / V = (1 + δ_ij) / 20 on any tetrahedron.
        let points = SimplexRule::Gauss4.points::<3>();
        for i in 0..4 {
            for j in 0..4 {
                let got: f64 = points.iter().map(|(w, s)| w[i] * w[j] * s).sum();
                let want = if i == j { 0.1 } else { 0.05 };
                assert!((got - want).abs() < 1e-15, "{i}{j}: {got} vs {want}");
            }
        }
    }
}
