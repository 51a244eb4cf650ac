//! The `[[curve]]` tables: load factor against time, each row checked at
//! its curve; index 0 is the default ramp.

use std::collections::BTreeMap;

use toml::Spanned;

use super::{Curve, lookup, unique_names};
use crate::SceneError;
use crate::format::CurveSpec;
use crate::source::SceneSource;

/// The curves of a scene, by index and by name.
pub(super) struct CurveTable {
    /// Curve index by name (a name's index is its curve's minus one).
    names: BTreeMap<String, usize>,
    /// The curves, the default ramp first.
    pub(super) curves: Vec<Curve>,
}

impl CurveTable {
    /// The index of the curve `name`: 0, the default ramp, without one.
    ///
    /// # Errors
    /// [`SceneError::Scene`] at a name that is not a curve's.
    pub(super) fn index(
        &self,
        name: &Option<Spanned<String>>,
        src: &SceneSource,
    ) -> Result<usize, SceneError> {
        match name {
            None => Ok(0),
            Some(n) => lookup(&self.names, n, "curve", src).map(|k| k + 1),
        }
    }
}

/// The curves' names (for the conditions' and loads' lookups) and the
/// curves, the default ramp first.
///
/// # Errors
/// [`SceneError::Scene`] at the curve whose rows are wrong.
pub(super) fn curves(specs: &[CurveSpec], src: &SceneSource) -> Result<CurveTable, SceneError> {
    let curve_names = unique_names(specs.iter().map(|c| &c.name), "curve", src)?;
    let mut curves = vec![Curve::ramp()];
    for c in specs {
        let rows = c.points.get_ref();
        if rows.is_empty() {
            return Err(src.at(&c.points, "a curve needs at least one [time, factor] row"));
        }
        if let Some(k) = rows
            .iter()
            .position(|r| !(r[0].is_finite() && r[1].is_finite()))
        {
            return Err(src.at(
                &c.points,
                format!(
                    "curve `{}`: row {} is [{}, {}]; times and factors must be finite",
                    c.name.get_ref(),
                    k + 1,
                    rows[k][0],
                    rows[k][1]
                ),
            ));
        }
        if let Some(k) = (1..rows.len()).find(|&k| rows[k][0] <= rows[k - 1][0]) {
            return Err(src.at(
                &c.points,
                format!(
                    "curve `{}`: times must increase, but row {} has time {} after {}",
                    c.name.get_ref(),
                    k + 1,
                    rows[k][0],
                    rows[k - 1][0]
                ),
            ));
        }
        curves.push(Curve { rows: rows.clone() });
    }
    if curves.len() > u16::MAX as usize {
        return Err(src.error(None, "too many curves"));
    }
    Ok(CurveTable {
        names: curve_names,
        curves,
    })
}
