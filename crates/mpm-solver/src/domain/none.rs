//! No domain update (the "no update" column of Coombs et al. 2020 Table 2).

use super::{DisplacementField, DomainContext, DomainError, DomainUpdater};

/// Domains never change (the "no update" column of Table 2); also the only
/// sensible choice for bases without a domain (`()`).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoUpdate;

impl<const D: usize, Dom: Copy> DomainUpdater<D, Dom> for NoUpdate {
    const NAME: &'static str = "none";

    #[inline]
    fn update(
        &self,
        ctx: &DomainContext<'_, D, Dom>,
        _displacement_at: impl DisplacementField<D>,
    ) -> Result<Dom, DomainError> {
        Ok(*ctx.previous)
    }
}
