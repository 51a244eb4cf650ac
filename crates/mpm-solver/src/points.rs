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

impl<const D: usize, H: Copy + Default, Dom: Copy> MaterialPoints<D, H, Dom> {
    /// The whole set from its ranks' parts, the inverse of [`Self::keep`]:
    /// each part with the problem's indices of its points (`total` in
    /// all); point loads renumbered back. The body-force path is code, not
    /// state: the caller sets it again.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] when the parts do not hold every
    /// point once, or hold an array some parts have and others do not.
    pub fn join(parts: &[(&[usize], Self)], total: usize) -> Result<Self, SolverError> {
        fn join_one<X: Clone, P>(
            parts: &[(&[usize], P)],
            total: usize,
            array: impl Fn(&P) -> &Vec<X>,
        ) -> Result<Vec<X>, SolverError> {
            if parts.iter().all(|(_, p)| array(p).is_empty()) {
                return Ok(Vec::new());
            }
            let mut whole: Vec<Option<X>> = vec![None; total];
            for (ids, part) in parts {
                let values = array(part);
                if values.len() != ids.len() {
                    return Err(SolverError::InvalidInput(format!(
                        "joining points: a part of {} points holds {} values",
                        ids.len(),
                        values.len()
                    )));
                }
                for (&id, v) in ids.iter().zip(values) {
                    match whole.get_mut(id) {
                        Some(slot @ None) => *slot = Some(v.clone()),
                        _ => {
                            return Err(SolverError::InvalidInput(format!(
                                "joining points: point {id} twice or beyond {total}"
                            )));
                        }
                    }
                }
            }
            whole
                .into_iter()
                .enumerate()
                .map(|(id, v)| {
                    v.ok_or_else(|| {
                        SolverError::InvalidInput(format!("joining points: point {id} in no part"))
                    })
                })
                .collect()
        }
        let mut point_force = Vec::new();
        for (ids, part) in parts {
            for &(k, f) in &part.point_force {
                let id = ids.get(k).copied().ok_or_else(|| {
                    SolverError::InvalidInput(format!(
                        "joining points: a load on point {k} of a part of {}",
                        ids.len()
                    ))
                })?;
                point_force.push((id, f));
            }
        }
        point_force.sort_by_key(|&(id, _)| id);
        Ok(Self {
            position: join_one(parts, total, |p| &p.position)?,
            displacement: join_one(parts, total, |p| &p.displacement)?,
            mass: join_one(parts, total, |p| &p.mass)?,
            volume0: join_one(parts, total, |p| &p.volume0)?,
            volume: join_one(parts, total, |p| &p.volume)?,
            f: join_one(parts, total, |p| &p.f)?,
            be: join_one(parts, total, |p| &p.be)?,
            history: join_one(parts, total, |p| &p.history)?,
            sigma: join_one(parts, total, |p| &p.sigma)?,
            domain0: join_one(parts, total, |p| &p.domain0)?,
            domain: join_one(parts, total, |p| &p.domain)?,
            body_force: join_one(parts, total, |p| &p.body_force)?,
            point_force,
            body_force_path: None,
        })
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

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::MaterialPoints;

    type Points = MaterialPoints<2, (), ()>;

    fn five() -> Points {
        let x = (0..5).map(|i| Vector2::new(f64::from(i), 1.0)).collect();
        let mut p =
            Points::new(x, vec![1.0, 2.0, 3.0, 4.0, 5.0], 2.0, vec![(); 5]).expect("points");
        p.point_force = vec![(1, Vector2::new(1.0, 0.0)), (4, Vector2::new(4.0, 0.0))];
        p
    }

    #[test]
    fn the_parts_kept_join_into_the_whole_set() {
        let whole = five();
        let deal: [&[usize]; 2] = [&[0, 2, 4], &[1, 3]];
        let parts: Vec<(&[usize], Points)> = deal
            .iter()
            .map(|&ids| {
                let mut part = whole.clone();
                part.keep(ids).expect("kept");
                (ids, part)
            })
            .collect();
        let joined = Points::join(&parts, 5).expect("joined");
        assert_eq!(joined.position, whole.position);
        assert_eq!(joined.volume, whole.volume);
        assert_eq!(joined.mass, whole.mass);
        assert_eq!(joined.point_force, whole.point_force);
        assert!(joined.body_force.is_empty());
        let missing = Points::join(&parts[..1], 5).expect_err("point 1 in no part");
        assert!(
            missing.to_string().contains("point 1 in no part"),
            "{missing}"
        );
        let twice = Points::join(&[parts[0].clone(), parts[0].clone()], 5);
        assert!(twice.is_err(), "a point held twice");
    }
}
