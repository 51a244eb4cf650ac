//! Which variants exist: the compatibility rules of basis, domain update,
//! GIMP volume and locking treatment, with their messages, in one table.
//!
//! The scene builder asks here to refuse a scene at the key that breaks a
//! rule; the dispatch asks here before it turns a variant into types, so a
//! variant built in Rust is refused with the same words. A new rule is one
//! row of [`RULES`] (and, for a new mesh or solver kind, one field of
//! [`Context`]).

use super::{BasisKind, DomainUpdateKind, GimpVolumeKind, LockingKind, Variant};

/// Where a variant is to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Context<'a> {
    /// The implicit solver on a regular grid.
    ImplicitGrid,
    /// The implicit solver on the simplex mesh named `mesh` (for the
    /// message), whose elements come in patches (split from quadratic
    /// parents) or not.
    ImplicitSimplex {
        /// The mesh as the message names it, e.g. `"a Gmsh mesh"`.
        mesh: &'a str,
        /// The elements are split from quadratic parents (F-patch applies).
        patches: bool,
    },
    /// The explicit solver (regular grids).
    Explicit,
}

/// The scene key a broken rule is reported at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// `[solver] basis`.
    Basis,
    /// `[solver] domain_update`.
    DomainUpdate,
    /// `[solver] gimp_volume`.
    GimpVolume,
    /// `[solver] locking`.
    Locking,
}

/// A broken rule: the key to blame and what to say.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// The key the message is located at.
    pub key: Key,
    /// What is wrong and what to use instead.
    pub message: String,
}

/// One rule: the key it is about and the test that breaks it, returning
/// the message.
type Rule = (Key, fn(&Variant, Context<'_>) -> Option<String>);

/// Every rule, in the order they are checked (the first broken one is
/// reported).
pub const RULES: [Rule; 6] = [
    (Key::Basis, simplex_basis),
    (Key::DomainUpdate, domain_update_fits_basis),
    (Key::GimpVolume, gimp_volume_needs_gimp),
    (Key::Locking, locking_fits_solver),
    (Key::Locking, locking_fits_mesh),
    (Key::Locking, fbar_fits_basis),
];

/// Why the implicit solver refuses `locking = cell_averaged`.
pub const CELL_AVERAGED_IMPLICIT: &str = "locking = cell_averaged is the explicit solver's dilatation averaging (solver kind = \"explicit\"); the implicit solver takes fbar (grids) or fpatch (simplex patches)";

/// Why GIMP refuses `domain_update = cpdi2`.
pub const CPDI2_UPDATE_WITH_GIMP: &str =
    "domain_update = cpdi2 convects CPDI2 corners; use it with basis = cpdi2";

impl Variant {
    /// The first rule of [`RULES`] the variant breaks in `context`.
    ///
    /// # Errors
    /// The [`Refusal`] naming the key and the reason.
    pub fn check(&self, context: Context<'_>) -> Result<(), Refusal> {
        RULES
            .iter()
            .find_map(|(key, broken)| {
                broken(self, context).map(|message| Refusal { key: *key, message })
            })
            .map_or(Ok(()), Err)
    }

    /// `Ok` for the variants of simplex meshes: linear basis, no domain
    /// update, and no locking treatment or F-patch when the mesh has
    /// patches (`patches`: split from quadratic parents); `mesh` names the
    /// mesh in the error.
    pub fn require_simplex(&self, mesh: &str, patches: bool) -> Result<(), String> {
        self.check(Context::ImplicitSimplex { mesh, patches })
            .map_err(|r| r.message)
    }

    /// `Ok` for standard MPM without domain update or locking treatment,
    /// the only variant of the annulus and stretch cases' triangles and
    /// tetrahedra without patches.
    pub fn require_standard_mpm(&self, mesh: &str) -> Result<(), String> {
        self.require_simplex(mesh, false)
    }
}

/// Simplex meshes run standard MPM: the linear basis, no domain update.
fn simplex_basis(v: &Variant, c: Context<'_>) -> Option<String> {
    let Context::ImplicitSimplex { mesh, .. } = c else {
        return None;
    };
    (v.basis != BasisKind::Linear || v.domain_update != DomainUpdateKind::None).then(|| {
        format!(
            "on {mesh} the variant is standard MPM: basis = linear, domain_update = none (got {} / {})",
            v.basis, v.domain_update
        )
    })
}

/// A domain rule needs a basis with domains: GIMP takes every rule but
/// CPDI2's, CPDI2 convects its corners, the others have no domain. The
/// one rule that holds whatever the mesh and solver, so the scene builder
/// checks it first, at `domain_update`.
pub fn domain_update_fits_basis(v: &Variant, _: Context<'_>) -> Option<String> {
    match (v.basis, v.domain_update) {
        (_, DomainUpdateKind::None) | (BasisKind::Cpdi2, DomainUpdateKind::Cpdi2) => None,
        (BasisKind::Gimp, DomainUpdateKind::Cpdi2) => Some(CPDI2_UPDATE_WITH_GIMP.into()),
        (BasisKind::Gimp, _) => None,
        (BasisKind::Cpdi2, other) => Some(format!(
            "basis = cpdi2 convects its corners with the grid; domain_update = {other} applies to gimp only"
        )),
        (other, update) => Some(format!(
            "domain_update = {update} needs basis = gimp ({other} has no domain to update)"
        )),
    }
}

/// The volume convention is GIMP's.
fn gimp_volume_needs_gimp(v: &Variant, _: Context<'_>) -> Option<String> {
    (v.basis != BasisKind::Gimp && v.gimp_volume != GimpVolumeKind::DetF)
        .then(|| format!("gimp_volume = {} applies to basis = gimp", v.gimp_volume))
}

/// Dilatation averaging is explicit; F-bar and F-patch are implicit.
fn locking_fits_solver(v: &Variant, c: Context<'_>) -> Option<String> {
    match (c, v.locking) {
        (Context::Explicit, LockingKind::FBar | LockingKind::FPatch) => Some(format!(
            "locking = {} is an implicit treatment; the explicit solver takes locking = \"none\" or \"cell_averaged\"",
            v.locking
        )),
        (Context::ImplicitGrid | Context::ImplicitSimplex { .. }, LockingKind::CellAveraged) => {
            Some(CELL_AVERAGED_IMPLICIT.into())
        }
        _ => None,
    }
}

/// F-bar averages over grid cells, F-patch over the patches of split
/// quadratic parents.
fn locking_fits_mesh(v: &Variant, c: Context<'_>) -> Option<String> {
    match (c, v.locking) {
        (Context::ImplicitGrid, LockingKind::FPatch) => Some("locking = fpatch averages over the patches of split tri6/tet10 parents and applies to simplex meshes; on a regular grid use locking = fbar".into()),
        (Context::ImplicitSimplex { mesh, patches: false }, LockingKind::FPatch) => Some(format!(
            "locking = fpatch needs patches, and {mesh} has none: split quadratic parents with [mesh] patches = true, or read a quadratic (tri6/tet10) Gmsh mesh"
        )),
        (Context::ImplicitSimplex { mesh, .. }, LockingKind::FBar) => Some(format!(
            "locking = fbar averages over grid cells and applies to regular grids; on {mesh} use locking = fpatch"
        )),
        _ => None,
    }
}

/// Scenes run F-bar with the bases whose points stay in their cells'
/// averaging (not CPDI2) and without a domain update.
fn fbar_fits_basis(v: &Variant, c: Context<'_>) -> Option<String> {
    let broken = c == Context::ImplicitGrid
        && v.locking == LockingKind::FBar
        && (v.basis == BasisKind::Cpdi2 || v.domain_update != DomainUpdateKind::None);
    broken.then(|| {
        format!(
            "scenes run locking = fbar with basis = linear, bspline2 or gimp and domain_update = none (got {} / {}); other combinations compose in Rust (mpm_solver::FBar)",
            v.basis, v.domain_update
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn every_variant() -> impl Iterator<Item = Variant> {
        use crate::variant::FormulationKind;
        BasisKind::ALL.iter().copied().flat_map(|basis| {
            DomainUpdateKind::ALL
                .iter()
                .copied()
                .flat_map(move |domain_update| {
                    LockingKind::ALL.iter().copied().flat_map(move |locking| {
                        GimpVolumeKind::ALL
                            .iter()
                            .copied()
                            .map(move |gimp_volume| Variant {
                                basis,
                                formulation: FormulationKind::Pc,
                                locking,
                                domain_update,
                                gimp_volume,
                            })
                    })
                })
        })
    }

    /// The variants the dispatch compiles solvers for are exactly those
    /// the table accepts on a grid: basis × its domain rules, F-bar only
    /// with linear, B-spline and GIMP bases without an update.
    #[test]
    fn the_grid_table_accepts_the_compiled_variants() {
        let accepted: Vec<Variant> = every_variant()
            .filter(|v| v.check(Context::ImplicitGrid).is_ok())
            .collect();
        for v in &accepted {
            assert!(
                matches!(v.locking, LockingKind::None | LockingKind::FBar),
                "{v:?}"
            );
            if v.basis != BasisKind::Gimp {
                assert_eq!(v.gimp_volume, GimpVolumeKind::DetF, "{v:?}");
            }
        }
        // GIMP: 8 rules × 2 volumes without locking, 2 volumes with F-bar;
        // CPDI2: 2 spellings of its update; three point bases × (none, fbar).
        assert_eq!(accepted.len(), 8 * 2 + 2 + 2 + 3 * 2, "{accepted:#?}");
    }

    /// On simplices only standard MPM runs, with F-patch where there are
    /// patches; the explicit solver refuses the implicit treatments.
    #[test]
    fn simplex_and_explicit_rules() {
        let standard = Variant::default();
        let patched = Context::ImplicitSimplex {
            mesh: "m",
            patches: true,
        };
        let plain = Context::ImplicitSimplex {
            mesh: "m",
            patches: false,
        };
        let fpatch = Variant {
            locking: LockingKind::FPatch,
            ..standard
        };
        assert_eq!(standard.check(plain), Ok(()));
        assert_eq!(fpatch.check(patched), Ok(()));
        assert_eq!(fpatch.check(plain).map_err(|r| r.key), Err(Key::Locking));
        let gimp = Variant {
            basis: BasisKind::Gimp,
            ..standard
        };
        assert_eq!(gimp.check(plain).map_err(|r| r.key), Err(Key::Basis));
        let fbar = Variant {
            locking: LockingKind::FBar,
            ..standard
        };
        assert!(fbar.check(Context::Explicit).is_err());
        let averaged = Variant {
            locking: LockingKind::CellAveraged,
            ..standard
        };
        assert_eq!(averaged.check(Context::Explicit), Ok(()));
        assert_eq!(
            averaged.check(Context::ImplicitGrid).map_err(|r| r.message),
            Err(CELL_AVERAGED_IMPLICIT.to_owned())
        );
    }
}
