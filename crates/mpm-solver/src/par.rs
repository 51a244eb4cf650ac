//! Parallel loops over points, nodes and tasks, compiled once per kind of
//! data they touch rather than once per loop and solver type.
//!
//! A rayon iterator chain is a type built from its closures, and a closure
//! inside a generic solver is a new type for every instantiation of that
//! solver: each of the two dozen solvers a crate compiles carried its own
//! copy of rayon's splitting, joining and job machinery for each of its
//! loops, 45 % of the LLVM IR of `mpm-dispatch` (`cargo llvm-lines`,
//! docs/src/benchmarks/build.md). Here the splitting is generic over the
//! data only ([`Split`]: slices and tuples of them, whose element types
//! follow the dimension and the point state) and the loop body is a trait
//! object called once per part: the per-item loop inside a part stays
//! monomorphised and inlined, and rayon's machinery is compiled once per
//! kind of data.
//!
//! Parts are consecutive, cover every item once, and results combine left
//! to right, so what a loop computes does not depend on how it was split
//! (the thread count changes only which thread runs a part).

use std::ops::Range;

/// Per-item views of data that split at an item index: slices, [`Rows`]
/// of a slice, an item count ([`Items`]), and tuples of these with the
/// same number of items.
pub trait Split: Send + Sized {
    /// Number of items.
    fn items(&self) -> usize;
    /// The first `mid` items and the rest.
    fn split(self, mid: usize) -> (Self, Self);
}

impl<T: Send> Split for &mut [T] {
    fn items(&self) -> usize {
        self.len()
    }

    fn split(self, mid: usize) -> (Self, Self) {
        self.split_at_mut(mid)
    }
}

impl<T: Sync> Split for &[T] {
    fn items(&self) -> usize {
        self.len()
    }

    fn split(self, mid: usize) -> (Self, Self) {
        self.split_at(mid)
    }
}

/// Items without data: the indices of a range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Items(pub Range<usize>);

impl Split for Items {
    fn items(&self) -> usize {
        self.0.len()
    }

    fn split(self, mid: usize) -> (Self, Self) {
        let at = self.0.start + mid;
        (Items(self.0.start..at), Items(at..self.0.end))
    }
}

/// A slice read as consecutive rows of `width` elements (the last row may
/// be shorter): one item per row. A width of 0 gives `items` empty rows.
#[derive(Debug)]
pub struct Rows<'a, T> {
    data: &'a mut [T],
    width: usize,
    items: usize,
}

impl<'a, T> Rows<'a, T> {
    /// `data` in rows of `width` (> 0).
    pub fn new(data: &'a mut [T], width: usize) -> Self {
        let width = width.max(1);
        Self {
            items: data.len().div_ceil(width),
            data,
            width,
        }
    }

    /// `items` rows of no elements.
    pub fn empty(items: usize) -> Self {
        Self {
            data: &mut [],
            width: 0,
            items,
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.items
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.items == 0
    }

    /// Row `k` of this part.
    #[inline]
    pub fn row(&mut self, k: usize) -> &mut [T] {
        let start = (k * self.width).min(self.data.len());
        let end = (start + self.width).min(self.data.len());
        &mut self.data[start..end]
    }

    /// The rows in order.
    pub fn rows(&mut self) -> impl Iterator<Item = &mut [T]> {
        let width = self.width;
        let items = self.items;
        let mut rest: &mut [T] = self.data;
        (0..items).map(move |_| {
            let all = std::mem::take(&mut rest);
            let (row, tail) = all.split_at_mut(width.min(all.len()));
            rest = tail;
            row
        })
    }
}

impl<T: Send> Split for Rows<'_, T> {
    fn items(&self) -> usize {
        self.items
    }

    fn split(self, mid: usize) -> (Self, Self) {
        let at = (mid * self.width).min(self.data.len());
        let (a, b) = self.data.split_at_mut(at);
        let width = self.width;
        (
            Rows {
                data: a,
                width,
                items: mid,
            },
            Rows {
                data: b,
                width,
                items: self.items - mid,
            },
        )
    }
}

macro_rules! split_tuple {
    ($first:ident $(, $rest:ident)*) => {
        impl<$first: Split $(, $rest: Split)*> Split for ($first, $($rest,)*) {
            fn items(&self) -> usize {
                self.0.items()
            }

            #[allow(non_snake_case)]
            fn split(self, mid: usize) -> (Self, Self) {
                let ($first, $($rest,)*) = self;
                let $first = $first.split(mid);
                $(let $rest = $rest.split(mid);)*
                (($first.0, $($rest.0,)*), ($first.1, $($rest.1,)*))
            }
        }
    };
}

split_tuple!(A);
split_tuple!(A, B);
split_tuple!(A, B, C);
split_tuple!(A, B, C, E);
split_tuple!(A, B, C, E, F);
split_tuple!(A, B, C, E, F, G);

/// The number of items below which a part is not split: about eight parts
/// per thread, at least `grain` items each.
fn part_size(items: usize, grain: usize) -> usize {
    let parts = 8 * rayon::current_num_threads();
    items.div_ceil(parts).max(grain).max(1)
}

/// Calls `f(start, part)` for consecutive parts of `data` (`start` the
/// index of the part's first item), in parallel, and combines the results
/// left to right with `combine`. `f` runs at least once (on no items when
/// `data` has none).
pub fn reduce<S: Split, R: Send>(
    data: S,
    grain: usize,
    f: &(dyn Fn(usize, S) -> R + Sync),
    combine: fn(R, R) -> R,
) -> R {
    let size = part_size(data.items(), grain);
    reduce_from(0, data, size, f, combine)
}

fn reduce_from<S: Split, R: Send>(
    start: usize,
    data: S,
    size: usize,
    f: &(dyn Fn(usize, S) -> R + Sync),
    combine: fn(R, R) -> R,
) -> R {
    let n = data.items();
    if n <= size {
        return f(start, data);
    }
    let mid = n / 2;
    let (a, b) = data.split(mid);
    let (ra, rb) = rayon::join(
        || reduce_from(start, a, size, f, combine),
        || reduce_from(start + mid, b, size, f, combine),
    );
    combine(ra, rb)
}

/// [`reduce`] without a result.
pub fn for_each<S: Split>(data: S, grain: usize, f: &(dyn Fn(usize, S) + Sync)) {
    reduce(data, grain, f, |(), ()| ())
}

/// [`reduce`] keeping the leftmost `Some`: the failure of the lowest part
/// that failed.
pub fn first<S: Split, E: Send>(
    data: S,
    grain: usize,
    f: &(dyn Fn(usize, S) -> Option<E> + Sync),
) -> Option<E> {
    reduce(data, grain, f, |a, b| a.or(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_every_item_once_in_order() {
        for n in [0usize, 1, 7, 64, 1000] {
            let mut a = vec![0usize; n];
            let mut b = vec![0.0f64; 3 * n];
            for_each(
                (&mut a[..], Rows::new(&mut b, 3)),
                1,
                &|start, (a, mut b)| {
                    for (k, a) in a.iter_mut().enumerate() {
                        *a += start + k + 1;
                        b.row(k).iter_mut().for_each(|x| *x += (start + k) as f64);
                    }
                },
            );
            assert!(a.iter().enumerate().all(|(i, &v)| v == i + 1));
            assert!(b.iter().enumerate().all(|(i, &v)| v == (i / 3) as f64));
        }
    }

    #[test]
    fn ragged_rows_and_empty_rows_split_with_their_items() {
        let mut data: Vec<usize> = (0..10).collect();
        let (mut a, mut b) = Rows::new(&mut data, 4).split(2);
        assert_eq!((a.items(), b.items()), (2, 1));
        assert_eq!(a.row(1), &[4, 5, 6, 7]);
        assert_eq!(b.row(0), &[8, 9]);
        let (e, f) = Rows::<f64>::empty(5).split(3);
        assert_eq!((e.items(), f.items()), (3, 2));
        let mut r = Rows::new(&mut data, 3);
        assert_eq!(
            r.rows().map(|row| row.len()).collect::<Vec<_>>(),
            [3, 3, 3, 1]
        );
    }

    #[test]
    fn the_lowest_failure_wins_whatever_the_split() -> Result<(), rayon::ThreadPoolBuildError> {
        let fails = [17usize, 400, 999];
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let found = pool.install(|| {
                first(Items(0..1000), 1, &|start, items| {
                    (0..items.items())
                        .map(|k| start + k)
                        .find(|p| fails.contains(p))
                })
            });
            assert_eq!(found, Some(17));
        }
        Ok(())
    }
}
