//! Material point data, one array per quantity (struct of arrays).

use nalgebra::{Matrix3, SVector};

use crate::error::SolverError;

/// The material points of a body. Every vector has one entry per point,
/// except the optional loads, which are empty when a scene has none (so a
/// scene without body forces or point loads pays nothing for them).
#[derive(Debug, Clone)]
pub struct MaterialPoints<const D: usize, H, Dom> {
    /// Current position $x_p$.
    pub position: Vec<SVector<f64, D>>,
    /// Total displacement since the start of the analysis.
    pub displacement: Vec<SVector<f64, D>>,
    /// Mass.
    pub mass: Vec<f64>,
    /// Initial volume $V^0_p$.
    pub volume0: Vec<f64>,
    /// Converged volume $V^n_p = \det(F_n) V^0_p$ (eq. 22).
    pub volume: Vec<f64>,
    /// Converged deformation gradient $F_n$ (3D; plane strain embedded).
    pub f: Vec<Matrix3<f64>>,
    /// Converged elastic left Cauchy–Green tensor $b^e_n$.
    pub be: Vec<Matrix3<f64>>,
    /// The material law's history.
    pub history: Vec<H>,
    /// Converged Cauchy stress (output).
    pub sigma: Vec<Matrix3<f64>>,
    /// The basis domain at the start of the analysis.
    pub domain0: Vec<Dom>,
    /// The current basis domain.
    pub domain: Vec<Dom>,
    /// Body force on each point at load factor 1 (e.g. $m_p g$), applied
    /// through eq. (24); empty when the scene has none.
    pub body_force: Vec<SVector<f64, D>>,
    /// Point loads (point index, force at load factor 1) applied through
    /// eq. (25); empty when the scene has none.
    pub point_force: Vec<(usize, SVector<f64, D>)>,
    /// A body force that is not proportional to the load factor (e.g. a
    /// manufactured solution's): the force on point `p` at load factor
    /// $\lambda$, added to the proportional loads above through eq. (24).
    pub body_force_path: Option<BodyForcePath<D>>,
}

/// The force on material point `p` at load factor $\lambda$, `f(p, λ)`.
#[derive(Clone)]
pub struct BodyForcePath<const D: usize>(
    pub std::sync::Arc<dyn Fn(usize, f64) -> SVector<f64, D> + Send + Sync>,
);

impl<const D: usize> std::fmt::Debug for BodyForcePath<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("BodyForcePath(..)")
    }
}

impl<const D: usize, H: Copy + Default, Dom: Copy> MaterialPoints<D, H, Dom> {
    /// Undeformed, unstressed points with the given positions, volumes,
    /// density and domains (one domain per point).
    pub fn new(
        position: Vec<SVector<f64, D>>,
        volume: Vec<f64>,
        density: f64,
        domain: Vec<Dom>,
    ) -> Result<Self, SolverError> {
        let n = position.len();
        if volume.len() != n || domain.len() != n {
            return Err(SolverError::InvalidInput(format!(
                "{n} positions but {} volumes and {} domains",
                volume.len(),
                domain.len()
            )));
        }
        check_points(&position, &volume)?;
        if !(density.is_finite() && density >= 0.0) {
            return Err(SolverError::InvalidInput(format!(
                "density {density} must be non-negative and finite"
            )));
        }
        Ok(Self {
            displacement: vec![SVector::zeros(); n],
            mass: volume.iter().map(|v| v * density).collect(),
            volume0: volume.clone(),
            volume,
            f: vec![Matrix3::identity(); n],
            be: vec![Matrix3::identity(); n],
            history: vec![H::default(); n],
            sigma: vec![Matrix3::zeros(); n],
            domain0: domain.clone(),
            domain,
            body_force: Vec::new(),
            point_force: Vec::new(),
            body_force_path: None,
            position,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Sets the body force of every point to $m_p\,g$ for the acceleration
    /// `g` (gravity), reached at load factor 1.
    pub fn set_gravity(&mut self, g: SVector<f64, D>) {
        self.body_force = self.mass.iter().map(|m| g * *m).collect();
    }

    /// Keeps the points `ids` (ascending indices of this set), in that
    /// order, with their loads: a rank's part of a point set that every
    /// rank built whole. Point loads are renumbered and those of other
    /// points dropped; a body-force path is asked for the kept points by
    /// their old index.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] for indices that do not ascend or lie
    /// beyond the set.
    pub fn keep(&mut self, ids: &[usize]) -> Result<(), SolverError> {
        check_kept(ids, self.len())?;
        fn pick<T: Clone>(v: &mut Vec<T>, ids: &[usize]) {
            if !v.is_empty() {
                *v = ids.iter().map(|&i| v[i].clone()).collect();
            }
        }
        pick(&mut self.position, ids);
        pick(&mut self.displacement, ids);
        pick(&mut self.mass, ids);
        pick(&mut self.volume0, ids);
        pick(&mut self.volume, ids);
        pick(&mut self.f, ids);
        pick(&mut self.be, ids);
        pick(&mut self.history, ids);
        pick(&mut self.sigma, ids);
        pick(&mut self.domain0, ids);
        pick(&mut self.domain, ids);
        pick(&mut self.body_force, ids);
        self.point_force = (self.point_force.iter())
            .filter_map(|&(p, f)| ids.binary_search(&p).ok().map(|k| (k, f)))
            .collect();
        if let Some(path) = self.body_force_path.take() {
            let old: std::sync::Arc<[usize]> = ids.into();
            self.body_force_path = Some(BodyForcePath(std::sync::Arc::new(move |k, lambda| {
                (path.0)(old.get(k).copied().unwrap_or(usize::MAX), lambda)
            })));
        }
        Ok(())
    }
}

/// Checks that the indices `ids` of points to keep ascend below `n`.
pub(crate) fn check_kept(ids: &[usize], n: usize) -> Result<(), SolverError> {
    let ascending = ids.windows(2).all(|w| w[0] < w[1]);
    if !ascending || ids.last().is_some_and(|&i| i >= n) {
        return Err(SolverError::InvalidInput(format!(
            "the points to keep must ascend below {n}"
        )));
    }
    Ok(())
}

/// Checks that every volume is positive and finite and every position
/// finite (shared by the implicit and explicit point sets).
pub(crate) fn check_points<const D: usize>(
    position: &[SVector<f64, D>],
    volume: &[f64],
) -> Result<(), SolverError> {
    if let Some((p, v)) = volume
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(SolverError::InvalidInput(format!(
            "material point {p} has volume {v}; volumes must be positive and finite"
        )));
    }
    if let Some(p) = position
        .iter()
        .position(|x| x.iter().any(|c| !c.is_finite()))
    {
        return Err(SolverError::InvalidInput(format!(
            "material point {p} has a non-finite position {:?}",
            position[p].as_slice()
        )));
    }
    Ok(())
}
