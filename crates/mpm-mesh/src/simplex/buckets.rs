//! The fallback of point location: a uniform grid of buckets over the mesh's
//! bounding box, each listing (in ascending order) the elements whose
//! bounding box, widened by a small slack, meets the bucket. Built once per
//! mesh; a query reads the one bucket containing the point.

use nalgebra::SVector;

/// Slack, relative to the mesh's bounding-box diagonal, by which element
/// boxes are widened: far above the distance a point accepted with the
/// barycentric tolerance can lie outside its element.
const SLACK: f64 = 1e-9;

/// Uniform buckets of element bounding boxes in compressed-row layout.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Buckets<const D: usize> {
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    inverse_size: SVector<f64, D>,
    counts: [usize; D],
    offsets: Vec<usize>,
    elements: Vec<u32>,
}

/// Buckets per axis for a box of edges `extent` holding `element_count`
/// elements: about one bucket per element, of equal edge along every axis
/// longer than that edge. An axis no longer than the edge (a thin slab, a
/// mesh flattened along one axis) gets one bucket and the other axes share
/// the count, so the grid has at most $2^D$ buckets per element however
/// anisotropic the box; giving the thin axis one bucket but keeping the
/// edge of the whole volume would make the others $1/\text{thickness}$
/// times too fine (a mesh 1e-10 thick asked for 63 GB).
fn bucket_counts<const D: usize>(extent: &SVector<f64, D>, element_count: usize) -> [usize; D] {
    let n = element_count.max(1);
    let mut thick = [true; D];
    let mut edge = f64::INFINITY;
    // Each pass drops the axes no longer than the edge; the edge of the
    // remaining ones only grows, so a dropped axis stays dropped.
    for _ in 0..D {
        let axes = thick.iter().filter(|&&t| t).count();
        if axes == 0 {
            break;
        }
        // (volume / n)^(1 / axes), in logarithms: no underflow to 0 for
        // tiny extents.
        let log_volume: f64 = (0..D).filter(|&a| thick[a]).map(|a| extent[a].ln()).sum();
        edge = ((log_volume - (n as f64).ln()) / axes as f64).exp();
        let mut dropped = false;
        for a in 0..D {
            // A NaN or infinite extent (or edge) drops the axis too.
            if thick[a] && !(extent[a] > edge && extent[a].is_finite()) {
                thick[a] = false;
                dropped = true;
            }
        }
        if !dropped {
            break;
        }
    }
    std::array::from_fn(|a| {
        if thick[a] {
            ((extent[a] / edge).ceil() as usize).clamp(1, n)
        } else {
            1
        }
    })
}

impl<const D: usize> Buckets<D> {
    /// Buckets for the elements of `connectivity` (stride `D + 1`) over the
    /// box `[lower, upper]` of the nodes: about one bucket per element, of
    /// equal edge along every axis.
    pub(crate) fn new(
        nodes: &[SVector<f64, D>],
        connectivity: &[usize],
        lower: SVector<f64, D>,
        upper: SVector<f64, D>,
    ) -> Self {
        let stride = D + 1;
        let element_count = connectivity.len() / stride;
        let extent = upper - lower;
        let slack = SLACK * extent.norm();
        let counts = bucket_counts(&extent, element_count);
        let inverse_size = SVector::<f64, D>::from_fn(|a, _| counts[a] as f64 / extent[a]);
        let mut buckets = Self {
            lower,
            upper,
            inverse_size,
            counts,
            offsets: vec![0; counts.iter().product::<usize>() + 1],
            elements: Vec::new(),
        };
        // Two passes over the elements: count per bucket, then fill.
        for pass in 0..2 {
            let mut cursor = buckets.offsets.clone();
            for (element, vertices) in connectivity.chunks_exact(stride).enumerate() {
                let (lo, hi) = vertices.iter().fold(
                    (
                        SVector::repeat(f64::INFINITY),
                        SVector::repeat(f64::NEG_INFINITY),
                    ),
                    |(lo, hi): (SVector<f64, D>, SVector<f64, D>), &v| {
                        (lo.inf(&nodes[v]), hi.sup(&nodes[v]))
                    },
                );
                let first = buckets.index(&lo.add_scalar(-slack));
                let last = buckets.index(&hi.add_scalar(slack));
                let mut index = first;
                'boxes: loop {
                    let id = buckets.flat(&index);
                    if pass == 0 {
                        buckets.offsets[id + 1] += 1;
                    } else {
                        buckets.elements[cursor[id]] = element as u32;
                        cursor[id] += 1;
                    }
                    let mut axis = 0;
                    while index[axis] == last[axis] {
                        index[axis] = first[axis];
                        axis += 1;
                        if axis == D {
                            break 'boxes;
                        }
                    }
                    index[axis] += 1;
                }
            }
            if pass == 0 {
                for id in 1..buckets.offsets.len() {
                    buckets.offsets[id] += buckets.offsets[id - 1];
                }
                let total = buckets.offsets[buckets.offsets.len() - 1];
                buckets.elements = vec![0; total];
            }
        }
        buckets
    }

    /// Bucket multi-index of `x`, clamped to the grid.
    fn index(&self, x: &SVector<f64, D>) -> [usize; D] {
        std::array::from_fn(|a| {
            let r = ((x[a] - self.lower[a]) * self.inverse_size[a]).floor();
            // `as` saturates negative values (and NaN) to 0.
            (r as usize).min(self.counts[a] - 1)
        })
    }

    fn flat(&self, index: &[usize; D]) -> usize {
        index
            .iter()
            .zip(&self.counts)
            .rev()
            .fold(0, |id, (&i, &n)| id * n + i)
    }

    /// The elements whose widened bounding box contains `x` may contain it;
    /// every element containing `x` is among them, in ascending order. Empty
    /// for a point outside the widened mesh box.
    pub(crate) fn candidates(&self, x: &SVector<f64, D>) -> &[u32] {
        let slack = SLACK * (self.upper - self.lower).norm();
        let inside = (0..D).all(|a| x[a] >= self.lower[a] - slack && x[a] <= self.upper[a] + slack);
        if !inside {
            return &[];
        }
        let id = self.flat(&self.index(x));
        &self.elements[self.offsets[id]..self.offsets[id + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn about_one_bucket_per_element_however_thin_the_box() {
        // A cube: the edge of the whole volume along every axis.
        assert_eq!(
            bucket_counts(&SVector::from([1.0, 1.0, 1.0]), 1000),
            [10, 10, 10]
        );
        // Flattened along x by 1e-10, 1e-3, or to nothing: x gets one
        // bucket and y, z share the 1000 (before the fix: 1000 × 1000).
        for thickness in [1e-10, 1e-3, 0.0] {
            let counts = bucket_counts(&SVector::from([thickness, 1.0, 1.0]), 1000);
            assert_eq!(counts, [1, 32, 32], "{thickness}");
        }
        // A needle: all of them along its axis.
        assert_eq!(
            bucket_counts(&SVector::from([1e-9, 1.0, 1e-9]), 50),
            [1, 50, 1]
        );
        // Non-finite extents never ask for more buckets than elements.
        for bad in [f64::INFINITY, f64::NAN] {
            let counts = bucket_counts(&SVector::from([bad, 1.0]), 100);
            assert!(counts.iter().product::<usize>() <= 4 * 100, "{counts:?}");
        }
    }
}
