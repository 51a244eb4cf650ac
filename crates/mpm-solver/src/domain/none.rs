//! No domain update (the "no update" column of Coombs et al. 2020 Table 2).

use nalgebra::SVector;

use super::{DomainContext, DomainError, DomainUpdater};

/// Domains never change (the "no update" column of Table 2); also the only
/// sensible choice for bases without a domain (`()`).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoUpdate;

impl<const D: usize, Dom: Copy> DomainUpdater<D, Dom> for NoUpdate {
    const NAME: &'static str = "none";

    #[inline]
    fn update<U>(
        &self,
        ctx: &DomainContext<'_, D, Dom>,
        _displacement_at: U,
    ) -> Result<Dom, DomainError>
    where
        U: Fn(&SVector<f64, D>) -> Result<SVector<f64, D>, DomainError>,
    {
        Ok(*ctx.previous)
    }
}
