//! Regions of space for bodies, node sets and loads, checked against the
//! scene's dimension once ([`Region::new`]) and then tested point by point.

use nalgebra::SVector;
use toml::Spanned;

use crate::SceneError;
use crate::source::SceneSource;

use crate::format::RegionSpec;

/// Points closer than this (relative to the region's size) to a region's
/// boundary count as inside: a body whose box ends on a cell face keeps
/// the points of that face, a node set on a face gets its nodes.
const RELATIVE_TOLERANCE: f64 = 1e-9;

/// A region checked against the dimension `D`.
#[derive(Debug, Clone, PartialEq)]
pub enum Region<const D: usize> {
    /// The box `lower ..= upper`.
    Box {
        /// Lower corner.
        lower: SVector<f64, D>,
        /// Upper corner.
        upper: SVector<f64, D>,
    },
    /// A polygon (2D only).
    Polygon(Vec<[f64; 2]>),
    /// A disc or ball.
    Sphere {
        /// Centre.
        centre: SVector<f64, D>,
        /// Radius.
        radius: f64,
    },
    /// Any of the regions.
    Union(Vec<Region<D>>),
    /// The first region and none of the others.
    Difference(Vec<Region<D>>),
}

/// `values` as a point of dimension `D`, or an error at its place naming
/// `what`.
pub fn point<const D: usize>(
    values: &Spanned<Vec<f64>>,
    what: &str,
    src: &SceneSource,
) -> Result<SVector<f64, D>, SceneError> {
    if values.get_ref().len() != D {
        return Err(src.at(
            values,
            format!(
                "{what} has {} components; the scene is {D}D (its mesh origin has {D})",
                values.get_ref().len()
            ),
        ));
    }
    Ok(SVector::from_column_slice(values.get_ref()))
}

impl<const D: usize> Region<D> {
    /// Checks `spec`: coordinates of length `D`, boxes with `lower < upper`,
    /// polygons in 2D with at least three vertices and non-zero area,
    /// positive radii, non-empty unions and differences.
    ///
    /// # Errors
    /// [`SceneError::Scene`] at the offending value.
    pub fn new(spec: &RegionSpec, src: &SceneSource) -> Result<Self, SceneError> {
        Ok(match spec {
            RegionSpec::Box { lower, upper } => {
                let lo = point::<D>(lower, "box `lower`", src)?;
                let hi = point::<D>(upper, "box `upper`", src)?;
                if (0..D).any(|i| lo[i] >= hi[i]) {
                    return Err(src.at(
                        upper,
                        format!(
                            "box `upper` {:?} must exceed `lower` {:?} on every axis",
                            upper.get_ref(),
                            lower.get_ref()
                        ),
                    ));
                }
                Region::Box {
                    lower: lo,
                    upper: hi,
                }
            }
            RegionSpec::Polygon(vertices) => {
                if D != 2 {
                    return Err(src.at(vertices, "a polygon region needs a 2D scene"));
                }
                let v = vertices.get_ref();
                if v.len() < 3 || polygon_area(v).abs() <= f64::EPSILON * bounding_scale(v).powi(2)
                {
                    return Err(src.at(
                        vertices,
                        "a polygon needs at least three vertices enclosing a non-zero area",
                    ));
                }
                Region::Polygon(v.clone())
            }
            RegionSpec::Sphere { centre, radius } => {
                let c = point::<D>(centre, "sphere `centre`", src)?;
                if *radius.get_ref() <= 0.0 {
                    return Err(src.at(radius, "a sphere's radius must be positive"));
                }
                Region::Sphere {
                    centre: c,
                    radius: *radius.get_ref(),
                }
            }
            RegionSpec::Union(parts) => {
                if parts.is_empty() {
                    return Err(src.error(None, "a union needs at least one region"));
                }
                Region::Union(
                    parts
                        .iter()
                        .map(|p| Self::new(p, src))
                        .collect::<Result<_, _>>()?,
                )
            }
            RegionSpec::Group(name) => {
                return Err(src.at(
                    name,
                    "a `group` region selects a Gmsh physical group: it applies to bodies on a Gmsh mesh only",
                ));
            }
            RegionSpec::Difference(parts) => {
                if parts.get_ref().is_empty() {
                    return Err(src.at(parts, "a difference needs at least one region"));
                }
                Region::Difference(
                    parts
                        .get_ref()
                        .iter()
                        .map(|p| Self::new(p, src))
                        .collect::<Result<_, _>>()?,
                )
            }
        })
    }

    /// Whether `x` is in the region (boundary included, up to a relative
    /// tolerance of 1e-9).
    pub fn contains(&self, x: &SVector<f64, D>) -> bool {
        match self {
            Region::Box { lower, upper } => (0..D).all(|i| {
                let tol = RELATIVE_TOLERANCE * (upper[i] - lower[i]);
                x[i] >= lower[i] - tol && x[i] <= upper[i] + tol
            }),
            Region::Polygon(v) => {
                let p = [x[0], x[1]];
                inside_polygon(v, p)
                    || distance_to_polygon(v, p) <= RELATIVE_TOLERANCE * bounding_scale(v)
            }
            Region::Sphere { centre, radius } => {
                (x - centre).norm() <= radius * (1.0 + RELATIVE_TOLERANCE)
            }
            Region::Union(parts) => parts.iter().any(|r| r.contains(x)),
            Region::Difference(parts) => {
                parts[0].contains(x) && !parts[1..].iter().any(|r| r.contains(x))
            }
        }
    }

    /// The bounding box of the region (of its first part for a difference).
    pub fn bounds(&self) -> (SVector<f64, D>, SVector<f64, D>) {
        match self {
            Region::Box { lower, upper } => (*lower, *upper),
            Region::Polygon(v) => {
                let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
                let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
                for p in v {
                    for i in 0..D.min(2) {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
                (lo, hi)
            }
            Region::Sphere { centre, radius } => (
                centre - SVector::repeat(*radius),
                centre + SVector::repeat(*radius),
            ),
            Region::Union(parts) => parts.iter().map(Region::bounds).fold(
                (
                    SVector::repeat(f64::INFINITY),
                    SVector::repeat(f64::NEG_INFINITY),
                ),
                |(lo, hi), (a, b)| (lo.inf(&a), hi.sup(&b)),
            ),
            Region::Difference(parts) => parts[0].bounds(),
        }
    }
}

/// Signed area (shoelace formula).
fn polygon_area(v: &[[f64; 2]]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// The larger side of the polygon's bounding box.
fn bounding_scale(v: &[[f64; 2]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in v {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

/// Even-odd rule.
fn inside_polygon(v: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = v.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Distance from `p` to the polygon's edges.
fn distance_to_polygon(v: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let len2 = d[0] * d[0] + d[1] * d[1];
            let t = if len2 > 0.0 {
                (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
            (q[0] * q[0] + q[1] * q[1]).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_box_sphere_union_and_difference() {
        let triangle = Region::<2>::Polygon(vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]);
        let x = |a: f64, b: f64| SVector::<f64, 2>::new(a, b);
        assert!(triangle.contains(&x(0.5, 0.5)));
        assert!(triangle.contains(&x(1.0, 1.0)), "on the hypotenuse");
        assert!(!triangle.contains(&x(1.2, 1.2)));
        let unit = Region::<2>::Box {
            lower: x(0.0, 0.0),
            upper: x(1.0, 1.0),
        };
        let hole = Region::<2>::Sphere {
            centre: x(0.5, 0.5),
            radius: 0.25,
        };
        let ring = Region::Difference(vec![unit.clone(), hole.clone()]);
        assert!(ring.contains(&x(0.1, 0.1)));
        assert!(!ring.contains(&x(0.5, 0.6)));
        let both = Region::Union(vec![triangle, unit]);
        assert!(both.contains(&x(0.2, 1.7)) && both.contains(&x(0.9, 0.95)));
        assert!(!both.contains(&x(1.5, 1.5)));
        assert_eq!(both.bounds(), (x(0.0, 0.0), x(2.0, 2.0)));
        assert!((polygon_area(&[[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]) - 2.0).abs() < 1e-15);
    }
}
