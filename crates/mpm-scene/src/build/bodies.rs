//! The `[[body]]` tables: the material points of every body — a lattice
//! of sub-cell centres in its region on a grid, or a rule in its elements
//! on simplices — with their volumes, masses, materials and initial
//! velocities; bodies may touch but not overlap.

use std::collections::BTreeMap;

use mpm_mesh::{RegularGrid, SimplexMesh};
use nalgebra::SVector;
use toml::Spanned;

use super::mesh::BuiltMesh;
use super::{BuiltBody, BuiltMaterial, Check, MAX_ENTITIES, SceneMesh, lookup, unique_names};
use crate::SceneError;
use crate::body::SimplexRule;
use crate::format::{BodySpec, Placement, RegionSpec};
use crate::region::{Region, point};
use crate::source::SceneSource;

/// The bodies of a scene with their points.
pub(super) struct BuiltBodies<const D: usize> {
    /// The bodies, in file order; their points are consecutive.
    pub(super) bodies: Vec<BuiltBody>,
    /// Each body's region (`None` for a group of a simplex mesh).
    pub(super) regions: Vec<Option<Region<D>>>,
    /// The points of all bodies.
    pub(super) points: Points<D>,
    /// Initial velocity of every point.
    pub(super) velocity: Vec<SVector<f64, D>>,
    /// Body index by name.
    pub(super) names: BTreeMap<String, usize>,
}

impl<const D: usize> BuiltBodies<D> {
    /// Number of points.
    pub(super) fn len(&self) -> usize {
        self.points.position.len()
    }

    /// The points of the body named `body`, or all points without a name.
    ///
    /// # Errors
    /// [`SceneError::Scene`] at a name that is not a body's.
    pub(super) fn points_of(
        &self,
        body: &Option<Spanned<String>>,
        src: &SceneSource,
    ) -> Result<std::ops::Range<usize>, SceneError> {
        Ok(match body {
            Some(b) => self.bodies[lookup(&self.names, b, "body", src)?]
                .points
                .clone(),
            None => 0..self.len(),
        })
    }

    /// The points of `range` that lie in `region`.
    pub(super) fn points_in(
        &self,
        range: std::ops::Range<usize>,
        region: &Region<D>,
    ) -> Vec<usize> {
        range
            .filter(|&p| region.contains(&self.points.position[p]))
            .collect()
    }
}

/// The bodies of `specs` on `mesh`, with the materials of
/// `material_names` and `materials`; `explicit`: the scene runs the
/// explicit solver (the only one that takes an initial velocity).
///
/// # Errors
/// [`SceneError::Scene`] at the body that is wrong, reaches outside the
/// mesh, holds no point or overlaps another.
pub(super) fn bodies<const D: usize>(
    specs: &[BodySpec],
    mesh: &BuiltMesh<D>,
    material_names: &BTreeMap<String, usize>,
    materials: &[BuiltMaterial],
    explicit: bool,
    src: &SceneSource,
) -> Result<BuiltBodies<D>, SceneError> {
    if specs.is_empty() {
        return Err(src.error(None, "a scene needs at least one [[body]]"));
    }
    unique_names(specs.iter().map(|b| &b.name), "body", src)?;
    let mut filler = Filler {
        specs,
        mesh,
        src,
        element_owner: match &mesh.mesh {
            SceneMesh::Simplex(sm) => vec![None; sm.element_count()],
            SceneMesh::Grid(_) => Vec::new(),
        },
        built: BuiltBodies {
            bodies: Vec::new(),
            regions: Vec::new(),
            points: Points::default(),
            velocity: Vec::new(),
            names: BTreeMap::new(),
        },
    };
    for (b, spec) in specs.iter().enumerate() {
        let material = lookup(material_names, &spec.material, "material", src)?;
        filler.add(b, spec, material, materials[material].density, explicit)?;
    }
    let mut built = filler.built;
    built.names = built
        .bodies
        .iter()
        .enumerate()
        .map(|(k, b)| (b.name.clone(), k))
        .collect();
    Ok(built)
}

/// The bodies while they are filled, one after the other.
struct Filler<'a, const D: usize> {
    specs: &'a [BodySpec],
    mesh: &'a BuiltMesh<D>,
    src: &'a SceneSource,
    /// The body holding each element of a simplex mesh.
    element_owner: Vec<Option<usize>>,
    built: BuiltBodies<D>,
}

impl<const D: usize> Filler<'_, D> {
    /// Adds body `b` of material `material` (of density `density`).
    fn add(
        &mut self,
        b: usize,
        spec: &BodySpec,
        material: usize,
        density: f64,
        explicit: bool,
    ) -> Result<(), SceneError> {
        let src = self.src;
        let check = Check { src };
        let region = self.region(spec)?;
        let ppc = check.at_least(&spec.points_per_cell, 1, "points_per_cell")?;
        let start = self.built.points.position.len();
        let mesh = self.mesh;
        let step = match &mesh.mesh {
            SceneMesh::Grid(grid) => self.grid_points(grid, spec, region.as_ref(), ppc)?,
            SceneMesh::Simplex(sm) => {
                self.simplex_points(sm, b, spec, region.as_ref(), ppc, start)?;
                Vec::new()
            }
        };
        let points = &mut self.built.points;
        let end = points.position.len();
        if end == start {
            return Err(src.at(
                &spec.name,
                format!(
                    "body `{}` holds no material points: no sub-cell centre at {ppc} points per cell lies in its region",
                    spec.name.get_ref()
                ),
            ));
        }
        if matches!(mesh.mesh, SceneMesh::Grid(_)) {
            self.no_overlap(spec, start..end)?;
        }
        let points = &mut self.built.points;
        for p in start..end {
            points.mass.push(points.volume[p] * density);
            points.material.push(material as u32);
            points.body.push(b as u32);
        }
        let v0 = match &spec.velocity {
            Some(v) if !explicit => {
                return Err(src.at(
                    v,
                    "a body's `velocity` (its initial velocity) applies to the explicit solver ([solver] kind = \"explicit\"); the implicit solver is quasi-static",
                ));
            }
            Some(v) => point::<D>(v, "body `velocity`", src)?,
            None => SVector::zeros(),
        };
        self.built.velocity.resize(end, v0);
        self.built.regions.push(region);
        self.built.bodies.push(BuiltBody {
            name: spec.name.get_ref().clone(),
            material,
            points: start..end,
            step,
        });
        Ok(())
    }

    /// The region of `spec` (none for a group of a simplex mesh), which
    /// must lie in the mesh.
    fn region(&self, spec: &BodySpec) -> Result<Option<Region<D>>, SceneError> {
        let (src, mesh) = (self.src, self.mesh);
        let region = match (&spec.region, &mesh.mesh) {
            (RegionSpec::Group(_), SceneMesh::Simplex(_)) => None,
            (other, _) => Some(Region::<D>::new(other, src)?),
        };
        if let Some(region) = &region {
            let (lo, hi) = region.bounds();
            let (origin, upper, tol) = (mesh.origin, mesh.upper, mesh.tol());
            if (0..D).any(|i| lo[i] < origin[i] - tol || hi[i] > upper[i] + tol) {
                return Err(src.at(
                    &spec.name,
                    format!(
                        "body `{}` reaches outside the mesh: its region spans {:?} to {:?}, the mesh {:?} to {:?}",
                        spec.name.get_ref(),
                        lo.as_slice(),
                        hi.as_slice(),
                        origin.as_slice(),
                        upper.as_slice()
                    ),
                ));
            }
        }
        Ok(region)
    }

    /// Fills `region` on the grid with `ppc` points per cell and axis;
    /// returns the lattice step.
    fn grid_points(
        &mut self,
        grid: &RegularGrid<D>,
        spec: &BodySpec,
        region: Option<&Region<D>>,
        ppc: usize,
    ) -> Result<Vec<f64>, SceneError> {
        let (src, padding) = (self.src, self.mesh.padding);
        let cells: [usize; D] = std::array::from_fn(|i| grid.cells_per_axis()[i] - 2 * padding);
        let Some(region) = region else {
            return Err(src.error(None, "internal: a grid body without a region"));
        };
        if let Some(p) = spec.placement.as_ref()
            && *p.get_ref() != Placement::Regular
        {
            let name = if *p.get_ref() == Placement::Gauss4 {
                "gauss4"
            } else {
                "keast11"
            };
            return Err(src.at(
                p,
                format!("placement = {name} places points in tetrahedra; a body on a grid has placement = regular"),
            ));
        }
        let anchor = match &spec.lattice_origin {
            Some(a) => Some(point::<D>(a, "`lattice_origin`", src)?),
            None => None,
        };
        Ok(self
            .built
            .points
            .fill(
                grid,
                padding,
                cells,
                region,
                ppc,
                anchor,
                src,
                &spec.points_per_cell,
            )?
            .as_slice()
            .to_vec())
    }

    /// Fills the elements of body `b` (its group, or those whose centroid
    /// lies in its region) by its placement rule; `start`: the number of
    /// points before it.
    fn simplex_points(
        &mut self,
        sm: &SimplexMesh<D>,
        b: usize,
        spec: &BodySpec,
        region: Option<&Region<D>>,
        ppc: usize,
        start: usize,
    ) -> Result<(), SceneError> {
        let src = self.src;
        let elements: Vec<usize> = match (&spec.region, region) {
            (RegionSpec::Group(name), _) => sm
                .element_sets()
                .get(name.get_ref())
                .ok_or_else(|| {
                    src.at(
                        name,
                        format!(
                            "the mesh has no physical group `{}` of elements; it has: {}",
                            name.get_ref(),
                            sm.element_sets().names().collect::<Vec<_>>().join(", ")
                        ),
                    )
                })?
                .to_vec(),
            (_, Some(region)) => (0..sm.element_count())
                .filter(|&e| {
                    let nodes = sm.element_nodes(e);
                    let c = nodes
                        .iter()
                        .fold(SVector::<f64, D>::zeros(), |c, &v| c + sm.nodes()[v])
                        / nodes.len() as f64;
                    region.contains(&c)
                })
                .collect(),
            (_, None) => Vec::new(),
        };
        if let Some(a) = &spec.lattice_origin {
            return Err(src.at(
                a,
                "`lattice_origin` applies to bodies on a grid (simplex bodies fill their elements)",
            ));
        }
        let rule = simplex_rule::<D>(spec, ppc, src)?;
        let per_element = match rule {
            SimplexRule::Keast11 => 11,
            SimplexRule::Gauss4 => 4,
            SimplexRule::Subdivision(_) => ppc.checked_pow(D as u32).unwrap_or(usize::MAX),
        };
        if elements
            .len()
            .saturating_mul(per_element)
            .saturating_add(start)
            > MAX_ENTITIES
        {
            return Err(src.at(
                &spec.points_per_cell,
                format!("the scene would hold more than {MAX_ENTITIES} material points"),
            ));
        }
        for &e in &elements {
            if let Some(other) = self.element_owner[e] {
                return Err(src.at(
                    &spec.name,
                    format!(
                        "body `{}` overlaps body `{}` (both hold element {e}); bodies may touch but not overlap",
                        spec.name.get_ref(),
                        self.specs[other].name.get_ref()
                    ),
                ));
            }
            self.element_owner[e] = Some(b);
        }
        let body = crate::body::Body::fill_simplices(sm, &elements, rule);
        let points = &mut self.built.points;
        points.position.extend_from_slice(&body.position);
        points.volume.extend_from_slice(&body.volume);
        points.half_lengths.extend_from_slice(&body.half_lengths);
        Ok(())
    }

    /// Refuses a grid body whose points `range` lie in an earlier body's
    /// region.
    fn no_overlap(&self, spec: &BodySpec, range: std::ops::Range<usize>) -> Result<(), SceneError> {
        let position = &self.built.points.position;
        for p in range {
            if let Some(other) = self
                .built
                .regions
                .iter()
                .position(|r| r.as_ref().is_some_and(|r| r.contains(&position[p])))
            {
                return Err(self.src.at(
                    &spec.name,
                    format!(
                        "body `{}` overlaps body `{}` (both hold {:?}); bodies may touch but not overlap",
                        spec.name.get_ref(),
                        self.specs[other].name.get_ref(),
                        position[p].as_slice()
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The placement rule of a body on simplices: `gauss4` or `keast11`
/// (tetrahedra only), or a subdivision into `ppc` per edge.
fn simplex_rule<const D: usize>(
    spec: &BodySpec,
    ppc: usize,
    src: &SceneSource,
) -> Result<SimplexRule, SceneError> {
    Ok(match spec.placement.as_ref() {
        Some(p) if *p.get_ref() != Placement::Regular => {
            let (rule, name) = match p.get_ref() {
                Placement::Gauss4 => (SimplexRule::Gauss4, "gauss4"),
                _ => (SimplexRule::Keast11, "keast11"),
            };
            if D != 3 {
                return Err(src.at(
                    p,
                    format!("placement = {name} is a rule for tetrahedra (3D meshes)"),
                ));
            }
            rule
        }
        _ => SimplexRule::Subdivision(ppc),
    })
}

/// Point arrays while the bodies are filled.
#[derive(Default)]
pub(super) struct Points<const D: usize> {
    pub(super) position: Vec<SVector<f64, D>>,
    pub(super) volume: Vec<f64>,
    pub(super) half_lengths: Vec<SVector<f64, D>>,
    pub(super) mass: Vec<f64>,
    pub(super) material: Vec<u32>,
    pub(super) body: Vec<u32>,
}

impl<const D: usize> Points<D> {
    /// The point nearest `x` (the first of equals; 0 without points).
    pub(super) fn nearest(&self, x: &SVector<f64, D>) -> usize {
        (0..self.position.len())
            .min_by(|&a, &b| {
                let (da, db) = (
                    (self.position[a] - x).norm_squared(),
                    (self.position[b] - x).norm_squared(),
                );
                da.total_cmp(&db)
            })
            .unwrap_or(0)
    }

    /// Adds the sub-cell centres (`ppc` per axis per cell of the unpadded
    /// grid) that lie in `region`; returns the lattice step.
    #[allow(clippy::too_many_arguments)]
    fn fill(
        &mut self,
        grid: &RegularGrid<D>,
        padding: usize,
        cells: [usize; D],
        region: &Region<D>,
        ppc: usize,
        anchor: Option<SVector<f64, D>>,
        src: &SceneSource,
        ppc_span: &Spanned<usize>,
    ) -> Result<SVector<f64, D>, SceneError> {
        let h = *grid.spacing();
        let step = h / ppc as f64;
        // The lattice: sub-cells of the unpadded grid, or anchored at the
        // body's own `lattice_origin` (then the region, which lies in the
        // mesh, bounds it).
        let origin = anchor.unwrap_or_else(|| grid.origin() + h * padding as f64);
        // Only the lattice over the region's bounding box is visited.
        let (lo, hi) = region.bounds();
        let mut first = [0i64; D];
        let mut count = [0usize; D];
        for i in 0..D {
            let a = ((lo[i] - origin[i]) / step[i]).floor();
            let b = ((hi[i] - origin[i]) / step[i]).ceil();
            if anchor.is_some() {
                first[i] = a as i64;
                count[i] = (b - a).max(0.0) as usize;
            } else {
                let per_axis = cells[i].saturating_mul(ppc);
                let a = (a.max(0.0) as usize).min(per_axis);
                let b = (b.max(0.0) as usize).min(per_axis);
                first[i] = a as i64;
                count[i] = b.saturating_sub(a);
            }
        }
        let total = count.iter().try_fold(1usize, |n, &c| n.checked_mul(c));
        if total.is_none_or(|t| t.saturating_add(self.position.len()) > MAX_ENTITIES) {
            return Err(src.at(
                ppc_span,
                format!("the scene would hold more than {MAX_ENTITIES} material points"),
            ));
        }
        let volume = step.iter().product::<f64>();
        for flat in 0..total.unwrap_or(0) {
            let mut rest = flat;
            let mut x = SVector::<f64, D>::zeros();
            for i in 0..D {
                let k = first[i] + (rest % count[i]) as i64;
                rest /= count[i];
                x[i] = origin[i] + (k as f64 + 0.5) * step[i];
            }
            if region.contains(&x) {
                self.position.push(x);
                self.volume.push(volume);
                self.half_lengths.push(step / 2.0);
            }
        }
        Ok(step)
    }
}
