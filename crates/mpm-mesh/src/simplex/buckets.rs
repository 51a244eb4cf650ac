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
        let volume: f64 = extent.iter().product();
        let edge = (volume / element_count as f64).powf(1.0 / D as f64);
        let counts: [usize; D] =
            std::array::from_fn(|a| ((extent[a] / edge).ceil() as usize).clamp(1, element_count));
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
