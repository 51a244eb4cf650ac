//! The `[[load]]` tables: gravity, point loads, tractions on a body's
//! side and manufactured body forces, each as forces on the points; the
//! implicit solver's proportional and curved forces, or the explicit
//! solver's gravitational field, constant and timed forces.

use std::collections::BTreeMap;

use mpm_solver::BodyForcePath;
use nalgebra::SVector;
use toml::Spanned;

use super::bodies::BuiltBodies;
use super::curves::CurveTable;
use super::{BuiltMaterial, Curve, CurvedForces, TimedForces, face_name, lookup};
use crate::SceneError;
use crate::format::{LoadKind, LoadSpec};
use crate::region::{Region, point};
use crate::source::SceneSource;

/// The manufactured fields `kind = "manufactured"` loads can name, with
/// their parameters.
pub const MANUFACTURED_FIELDS: [(&str, &[&str]); 1] = [(
    "annulus_torsion",
    &["inner_radius", "outer_radius", "alpha"],
)];

/// The loads of a scene.
pub(super) struct Loads<const D: usize> {
    /// Proportional body force per point (empty if none).
    pub(super) body_force: Vec<SVector<f64, D>>,
    /// Proportional point forces.
    pub(super) point_forces: Vec<(usize, SVector<f64, D>)>,
    /// Forces following load curves.
    pub(super) curved: Vec<CurvedForces<D>>,
    /// Manufactured body forces.
    pub(super) manufactured: Vec<BodyForcePath<D>>,
    /// The explicit solver's loads.
    pub(super) explicit: ExplicitLoads<D>,
}

/// The loads of an explicit run.
pub(super) struct ExplicitLoads<const D: usize> {
    /// Gravitational acceleration (the sum of the gravity loads without a
    /// curve).
    pub(super) gravity: SVector<f64, D>,
    /// Constant point forces, per point index.
    pub(super) forces: Vec<(usize, SVector<f64, D>)>,
    /// Point forces that follow a curve over the simulated time.
    pub(super) timed: Vec<TimedForces<D>>,
}

/// The loads of `specs` on the points of `bodies`, with the materials
/// `materials` (a manufactured field's shear modulus), the curves `curves`
/// and the box's faces `faces` (a traction's side); `explicit`: the scene
/// runs the explicit solver.
///
/// # Errors
/// [`SceneError::Scene`] at the load's key that is missing (at `kind`),
/// wrong or does not apply to its kind or solver.
pub(super) fn loads<const D: usize>(
    specs: &[LoadSpec],
    bodies: &BuiltBodies<D>,
    materials: &[BuiltMaterial],
    curves: &CurveTable,
    faces: &[String],
    explicit: bool,
    src: &SceneSource,
) -> Result<Loads<D>, SceneError> {
    let mut reader = Reader {
        bodies,
        materials,
        curves,
        faces,
        explicit,
        src,
        body_force: Vec::new(),
        point_forces: Vec::new(),
        curved: BTreeMap::new(),
        manufactured: Vec::new(),
        explicit_loads: ExplicitLoads {
            gravity: SVector::zeros(),
            forces: Vec::new(),
            timed: Vec::new(),
        },
    };
    for spec in specs {
        reader.load(spec)?;
    }
    let curved = reader
        .curved
        .into_iter()
        .map(|(k, force)| CurvedForces {
            curve: curves.curves[k].clone(),
            force,
        })
        .collect();
    Ok(Loads {
        body_force: reader.body_force,
        point_forces: reader.point_forces,
        curved,
        manufactured: reader.manufactured,
        explicit: reader.explicit_loads,
    })
}

/// The loads while they are read, in file order.
struct Reader<'a, const D: usize> {
    bodies: &'a BuiltBodies<D>,
    materials: &'a [BuiltMaterial],
    curves: &'a CurveTable,
    faces: &'a [String],
    explicit: bool,
    src: &'a SceneSource,
    body_force: Vec<SVector<f64, D>>,
    point_forces: Vec<(usize, SVector<f64, D>)>,
    /// Force per point, by curve index.
    curved: BTreeMap<usize, Vec<SVector<f64, D>>>,
    manufactured: Vec<BodyForcePath<D>>,
    explicit_loads: ExplicitLoads<D>,
}

impl<const D: usize> Reader<'_, D> {
    /// Adds the load `spec`.
    fn load(&mut self, spec: &LoadSpec) -> Result<(), SceneError> {
        let src = self.src;
        let kind = *spec.kind.get_ref();
        let curve = self.curves.index(&spec.curve, src)?;
        keys_of_its_kind(spec, kind, src)?;
        if self.explicit && self.explicit_field(spec, kind, curve)? {
            return Ok(());
        }
        let forces = match kind {
            LoadKind::Manufactured => {
                let range = self.bodies.points_of(&spec.body, src)?;
                let points = &self.bodies.points;
                let shear_modulus: Vec<f64> = points
                    .material
                    .iter()
                    .map(|&m| {
                        let p = &self.materials[m as usize].params;
                        p.youngs_modulus / (2.0 * (1.0 + p.poisson_ratio))
                    })
                    .collect();
                self.manufactured.push(manufactured_force::<D>(
                    spec,
                    range,
                    &points.position,
                    &points.volume,
                    shear_modulus,
                    self.curves.curves[curve].clone(),
                    src,
                )?);
                return Ok(());
            }
            LoadKind::Gravity => self.gravity(spec)?,
            LoadKind::Point => self.point(spec)?,
            LoadKind::Traction => self.traction(spec)?,
        };
        if forces.is_empty() {
            return Ok(());
        }
        self.route(kind, curve, forces);
        Ok(())
    }

    /// An explicit run's gravity without a curve (the solver's field, on
    /// every body): added to it, `true`. A manufactured load is refused;
    /// `false` for the other loads.
    fn explicit_field(
        &mut self,
        spec: &LoadSpec,
        kind: LoadKind,
        curve: usize,
    ) -> Result<bool, SceneError> {
        let src = self.src;
        match kind {
            LoadKind::Manufactured => Err(src.at(
                &spec.kind,
                "a manufactured load balances a quasi-static solution; the explicit solver does not take it",
            )),
            // A gravity load with a curve is a force m_p g c(t) on
            // each point (below), its work external work.
            LoadKind::Gravity if curve == 0 => {
                if let Some(b) = &spec.body {
                    return Err(src.at(
                        b,
                        "an explicit gravity load without a curve is the solver's gravitational field, on every body: leave out `body` (or give a `curve` to load one body's points)",
                    ));
                }
                let Some(a) = &spec.acceleration else {
                    return Err(src.at(&spec.kind, "a gravity load needs `acceleration`"));
                };
                self.explicit_loads.gravity += point::<D>(a, "`acceleration`", src)?;
                Ok(true)
            }
            LoadKind::Gravity | LoadKind::Point | LoadKind::Traction => Ok(false),
        }
    }

    /// `kind = "gravity"`: `m_p g` on the points of `body` (or all).
    fn gravity(&self, spec: &LoadSpec) -> Result<Vec<SVector<f64, D>>, SceneError> {
        let src = self.src;
        let Some(a) = &spec.acceleration else {
            return Err(src.at(&spec.kind, "a gravity load needs `acceleration`"));
        };
        let g = point::<D>(a, "`acceleration`", src)?;
        let range = self.bodies.points_of(&spec.body, src)?;
        let mut forces = Vec::new();
        for p in range {
            self.add(&mut forces, p, g * self.bodies.points.mass[p]);
        }
        Ok(forces)
    }

    /// `kind = "point"`: `force` on the point nearest `at`, or shared
    /// between the points in `region`.
    fn point(&self, spec: &LoadSpec) -> Result<Vec<SVector<f64, D>>, SceneError> {
        let src = self.src;
        if spec.body.is_some() {
            return Err(refuse(spec, "body", "gravity or traction", src));
        }
        let Some(f) = &spec.force else {
            return Err(src.at(&spec.kind, "a point load needs `force`"));
        };
        let f = point::<D>(f, "`force`", src)?;
        let points = &self.bodies.points;
        let mut forces = Vec::new();
        match (&spec.at, &spec.region) {
            (Some(at), None) => {
                let x = point::<D>(at, "`at`", src)?;
                self.add(&mut forces, points.nearest(&x), f);
            }
            (None, Some(r)) => {
                let region = Region::<D>::new(r, src)?;
                let inside = self.bodies.points_in(0..self.bodies.len(), &region);
                if inside.is_empty() {
                    return Err(src.at(
                        &spec.kind,
                        "the point load's region holds no material point",
                    ));
                }
                let share = f / inside.len() as f64;
                for p in inside {
                    self.add(&mut forces, p, share);
                }
            }
            _ => {
                return Err(src.at(&spec.kind, "a point load needs one of `at` or `region`"));
            }
        }
        Ok(forces)
    }

    /// `kind = "traction"`: `traction` times each point's face area on the
    /// points of `body` on its `side`.
    fn traction(&self, spec: &LoadSpec) -> Result<Vec<SVector<f64, D>>, SceneError> {
        let src = self.src;
        let (Some(t), Some(side), Some(b)) = (&spec.traction, &spec.side, &spec.body) else {
            return Err(src.at(
                &spec.kind,
                "a traction load needs `traction`, `side` and `body`",
            ));
        };
        let t = point::<D>(t, "`traction`", src)?;
        let k = lookup(&self.bodies.names, b, "body", src)?;
        let face = (0..D)
            .flat_map(|i| [(i, false), (i, true)])
            .find(|&(i, up)| face_name(i, up) == *side.get_ref());
        let Some((axis, up)) = face else {
            return Err(src.at(
                side,
                format!("`side` must be one of {}", self.faces.join(", ")),
            ));
        };
        let body = &self.bodies.bodies[k];
        let Some(body_region) = &self.bodies.regions[k] else {
            return Err(src.at(
                &spec.kind,
                "traction loads need a body given by a region on a grid",
            ));
        };
        if body.step.is_empty() {
            return Err(src.at(
                &spec.kind,
                "traction loads need a body on a grid (simplex bodies have no lattice)",
            ));
        }
        let mut offset = SVector::<f64, D>::zeros();
        offset[axis] = if up {
            body.step[axis]
        } else {
            -body.step[axis]
        };
        let points = &self.bodies.points;
        let mut forces = Vec::new();
        let mut loaded = 0;
        for p in body.points.clone() {
            let x = points.position[p];
            if !body_region.contains(&(x + offset)) {
                // The point's face area on that side.
                let area = points.volume[p] / body.step[axis];
                self.add(&mut forces, p, t * area);
                loaded += 1;
            }
        }
        if loaded == 0 {
            return Err(src.at(
                side,
                format!(
                    "body `{}` has no points on side {}",
                    body.name,
                    side.get_ref()
                ),
            ));
        }
        Ok(forces)
    }

    /// Adds `f` to the force on point `p` (`forces` holds every point's
    /// once one is loaded).
    fn add(&self, forces: &mut Vec<SVector<f64, D>>, p: usize, f: SVector<f64, D>) {
        if forces.is_empty() {
            forces.resize(self.bodies.len(), SVector::zeros());
        }
        forces[p] += f;
    }

    /// Files the per-point `forces` of a load of kind `kind` with curve
    /// `curve` where its solver takes them.
    fn route(&mut self, kind: LoadKind, curve: usize, forces: Vec<SVector<f64, D>>) {
        let nonzero = |forces: &[SVector<f64, D>]| -> Vec<(usize, SVector<f64, D>)> {
            forces
                .iter()
                .enumerate()
                .filter(|(_, f)| **f != SVector::<f64, D>::zeros())
                .map(|(p, f)| (p, *f))
                .collect()
        };
        if self.explicit {
            // Point loads and tractions: constant forces on their
            // points, or forces scaled by their curve over time.
            if curve == 0 {
                self.explicit_loads.forces.extend(nonzero(&forces));
            } else {
                self.explicit_loads.timed.push(TimedForces {
                    curve: self.curves.curves[curve].clone(),
                    forces: nonzero(&forces),
                });
            }
            return;
        }
        if curve == 0 {
            if kind == LoadKind::Point {
                self.point_forces.extend(nonzero(&forces));
            } else if self.body_force.is_empty() {
                self.body_force = forces;
            } else {
                self.body_force
                    .iter_mut()
                    .zip(&forces)
                    .for_each(|(a, b)| *a += b);
            }
        } else {
            let n = self.bodies.len();
            let entry = self
                .curved
                .entry(curve)
                .or_insert_with(|| vec![SVector::zeros(); n]);
            entry.iter_mut().zip(&forces).for_each(|(a, b)| *a += b);
        }
    }
}

/// Refuses `key` of a load whose kind does not take it (it applies to
/// the kinds `applies`), at the load's `kind`.
fn refuse(spec: &LoadSpec, key: &str, applies: &str, src: &SceneSource) -> SceneError {
    src.at(
        &spec.kind,
        format!("`{key}` applies to kind = {applies} loads"),
    )
}

/// Refuses the keys of `spec` that belong to another kind than `kind`.
fn keys_of_its_kind(spec: &LoadSpec, kind: LoadKind, src: &SceneSource) -> Result<(), SceneError> {
    let present: [(&str, bool, LoadKind); 8] = [
        (
            "acceleration",
            spec.acceleration.is_some(),
            LoadKind::Gravity,
        ),
        ("force", spec.force.is_some(), LoadKind::Point),
        ("at", spec.at.is_some(), LoadKind::Point),
        ("region", spec.region.is_some(), LoadKind::Point),
        ("traction", spec.traction.is_some(), LoadKind::Traction),
        ("side", spec.side.is_some(), LoadKind::Traction),
        ("field", spec.field.is_some(), LoadKind::Manufactured),
        (
            "parameters",
            spec.parameters.is_some(),
            LoadKind::Manufactured,
        ),
    ];
    for (key, given, owner) in present {
        if given && owner != kind {
            let name = match owner {
                LoadKind::Gravity => "gravity",
                LoadKind::Point => "point",
                LoadKind::Traction => "traction",
                LoadKind::Manufactured => "manufactured",
            };
            return Err(refuse(spec, key, name, src));
        }
    }
    Ok(())
}

/// The body force of a `manufactured` load on the points `range` (the
/// other points get none), per point at load factor λ: the field's force
/// per unit volume at amplitude `curve(λ)` times the point's volume.
#[allow(clippy::too_many_arguments)]
fn manufactured_force<const D: usize>(
    spec: &LoadSpec,
    range: std::ops::Range<usize>,
    position: &[SVector<f64, D>],
    volume: &[f64],
    shear_modulus: Vec<f64>,
    curve: Curve,
    src: &SceneSource,
) -> Result<BodyForcePath<D>, SceneError> {
    use std::sync::Arc;
    let Some(field) = &spec.field else {
        return Err(src.at(
            &spec.kind,
            format!(
                "a manufactured load needs `field` (one of {})",
                MANUFACTURED_FIELDS.map(|f| f.0).join(", ")
            ),
        ));
    };
    let Some((name, keys)) = MANUFACTURED_FIELDS
        .iter()
        .find(|(name, _)| name == field.get_ref())
    else {
        return Err(src.at(
            field,
            format!(
                "unknown manufactured field `{}`; the fields are: {}",
                field.get_ref(),
                MANUFACTURED_FIELDS.map(|f| f.0).join(", ")
            ),
        ));
    };
    let empty = Spanned::new(field.span(), BTreeMap::new());
    let given = spec.parameters.as_ref().unwrap_or(&empty);
    if let Some(k) = given.get_ref().keys().find(|k| !keys.contains(&k.as_str())) {
        return Err(src.at(
            given,
            format!(
                "field `{name}` has no parameter `{k}`; it takes {}",
                keys.join(", ")
            ),
        ));
    }
    let value = |key: &str| -> Result<f64, SceneError> {
        match given.get_ref().get(key) {
            Some(v) if v.is_finite() => Ok(*v),
            Some(v) => Err(src.at(given, format!("`{key}` must be finite, got {v}"))),
            None => Err(src.at(
                given,
                format!(
                    "field `{name}` needs `parameters = {{ {} }}`",
                    keys.join(", ")
                ),
            )),
        }
    };
    if D != 2 {
        return Err(src.at(field, format!("field `{name}` is a 2D field")));
    }
    let (inner, outer, alpha) = (value(keys[0])?, value(keys[1])?, value(keys[2])?);
    if !(0.0 < inner && inner < outer) {
        return Err(src.at(
            given,
            format!("`inner_radius` {inner} and `outer_radius` {outer} need 0 < inner < outer"),
        ));
    }
    // Coombs et al. 2020 §7.4, eq. (44): see `manufactured::Torsion`.
    let x0: Vec<nalgebra::Vector2<f64>> = position
        .iter()
        .map(|x| nalgebra::Vector2::new(x[0], x[1]))
        .collect();
    let v0 = volume.to_vec();
    Ok(BodyForcePath(Arc::new(move |q: usize, lambda: f64| {
        if !range.contains(&q) {
            return SVector::zeros();
        }
        let torsion = crate::manufactured::Torsion {
            inner_radius: inner,
            outer_radius: outer,
            mu: shear_modulus[q],
        };
        let b = torsion.body_force(curve.at(lambda) * alpha, &x0[q]) * v0[q];
        SVector::<f64, D>::from_fn(|i, _| if i < 2 { b[i] } else { 0.0 })
    })))
}
