//! The MPM variant of a run — basis, formulation, locking treatment and
//! domain update — chosen at run time by name. The basis and the
//! formulation, which shape every per-point and per-node loop, are
//! dispatched to a monomorphised solver ([`dispatch`]); the GIMP domain
//! rule and volume convention, which act once per point and step, are a
//! run-time value ([`AnyGimpRule`]), as is the locking treatment (the
//! scene runner's `Option<FBar>`).

use mpm_basis::{BoundaryBSpline, Cpdi2, Gimp, LinearMpm, QuadraticBSpline};
use mpm_mesh::RegularGrid;
use mpm_solver::{
    AnyGimpRule, ConvectedCorners, DomainUpdater, Flat, Formulation, GimpRule, NoUpdate,
    PreviouslyConverged, UpdatedLagrangian,
};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

use crate::body::InitialDomain;
use crate::run::DomainBounds;

macro_rules! named_enum {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident => $text:literal),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
        pub enum $name {
            $($(#[$vdoc])* #[serde(rename = $text)] $variant),+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The name used in scene files and `--set`.
            pub fn name(self) -> &'static str {
                match self { $($name::$variant => $text),+ }
            }
        }

        impl ::std::fmt::Display for $name {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                match s {
                    $($text => Ok($name::$variant),)+
                    other => Err(format!(
                        "unknown {} `{other}`, expected one of: {}",
                        stringify!($name),
                        [$($text),+].join(", ")
                    )),
                }
            }
        }
    };
}
pub(crate) use named_enum;

/// The bases reachable from scene files and the command line, one line
/// each: the variant, its name, the `mpm_basis` type, and the family of
/// domain rules it takes (`point`: none, `gimp`: every GIMP rule,
/// `cpdi2`: corners convected with the grid). A new basis is one file in
/// `mpm-basis` and one line here.
macro_rules! register_bases {
    ($($(#[$doc:meta])* $variant:ident => $text:literal, $ty:ty, $family:ident;)+) => {
        named_enum!(
            /// Basis functions (mpm-basis).
            BasisKind { $($(#[$doc])* $variant => $text),+ }
        );

        impl BasisKind {
            /// Padding cells the basis needs around the body
            /// (`BasisFunction::PADDING`).
            pub fn padding(self) -> usize {
                match self {
                    $(BasisKind::$variant => <$ty as mpm_basis::BasisFunction<2>>::PADDING,)+
                }
            }
        }

        /// Calls `visitor` with the basis named by `variant.basis`.
        fn dispatch_basis<const D: usize, V: VariantVisitor<D>>(
            variant: &Variant,
            visitor: V,
        ) -> Result<V::Output, String> {
            match variant.basis {
                $(BasisKind::$variant => $family::<D, V, $ty>(variant, visitor, <$ty>::default()),)+
            }
        }
    };
}

register_bases! {
    /// Standard MPM (bi/trilinear).
    Linear => "linear", LinearMpm, point;
    /// Uniform GIMP.
    Gimp => "gimp", Gimp, gimp;
    /// CPDI2.
    Cpdi2 => "cpdi2", Cpdi2, cpdi2;
    /// Quadratic B-spline.
    BSpline2 => "bspline2", QuadraticBSpline, point;
    /// Quadratic B-spline with boundary-modified functions: interpolatory
    /// at the grid's faces (a fixed face holds the body), no padding.
    BSpline2Boundary => "bspline2_boundary", BoundaryBSpline, point;
}

named_enum!(
    /// Statement of equilibrium (Coombs 2020 §3, §5).
    FormulationKind {
        /// Updated Lagrangian.
        Ul => "ul",
        /// Previously converged.
        Pc => "pc",
    }
);

named_enum!(
    /// GIMP domain update rules (Coombs 2020 §6.4).
    DomainUpdateKind {
        /// No update.
        None => "none",
        /// Eq. (32).
        DetF => "det_f",
        /// Eq. (33).
        DiagF => "diag_f",
        /// Eq. (34).
        Stretch => "stretch",
        /// Eqs. (35)–(37), corners tracked (Fig. 5a).
        CornerMidpoint => "corner_midpoint",
        /// Eqs. (36)–(37), mid-points mapped directly (Fig. 5b).
        Midpoint => "midpoint",
        /// Eq. (38).
        VolumeCorrectedDiagF => "volume_corrected_diag_f",
        /// Eq. (39).
        IncrementalVolumeCorrectedDiagF => "incremental_volume_corrected_diag_f",
        /// CPDI2: corners convected with the grid (eq. 35 form); the only
        /// rule for basis = cpdi2, chosen when `none` is given with it.
        Cpdi2 => "cpdi2",
    }
);

impl DomainUpdateKind {
    /// The GIMP rule of this name.
    ///
    /// # Errors
    /// For `cpdi2`, which convects CPDI2's corners.
    pub fn gimp_rule(self) -> Result<GimpRule, String> {
        Ok(match self {
            Self::None => GimpRule::None,
            Self::DetF => GimpRule::DetF,
            Self::DiagF => GimpRule::DiagF,
            Self::Stretch => GimpRule::Stretch,
            Self::CornerMidpoint => GimpRule::CornerMidpoint,
            Self::Midpoint => GimpRule::Midpoint,
            Self::VolumeCorrectedDiagF => GimpRule::VolumeCorrectedDiagF,
            Self::IncrementalVolumeCorrectedDiagF => GimpRule::IncrementalVolumeCorrectedDiagF,
            Self::Cpdi2 => {
                return Err(
                    "domain_update = cpdi2 convects CPDI2 corners; use it with basis = cpdi2"
                        .into(),
                );
            }
        })
    }
}

named_enum!(
    /// The integration volume of GIMP points.
    GimpVolumeKind {
        /// $\det(F)\,V^0_p$ (eqs. 5, 22), the default.
        DetF => "det_f",
        /// The domain's volume $\prod_i 2l_i$: the convention of Coombs et
        /// al. 2020's GIMP results (`mpm_solver::DomainVolume`).
        Domain => "domain",
    }
);

named_enum!(
    /// Locking treatments.
    LockingKind {
        /// Standard: none.
        None => "none",
        /// F-bar on regular grids: points of a cell share its volumetric
        /// deformation (`mpm_solver::FBar`).
        FBar => "fbar",
        /// F-patch on simplices split from tri6/tet10 parents
        /// (`mpm_solver::FPatch`, Wang et al. 2021).
        FPatch => "fpatch",
        /// The explicit solver's cell-averaged dilatation
        /// (`mpm_solver::CellAveraged`, MPoint notes eqs. 47–53).
        CellAveraged => "cell_averaged",
    }
);

/// `solver.transfer`: how the explicit solver carries velocities between
/// points and grid (`mpm_solver::explicit::Transfer`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransferKind {
    /// Particle-in-cell (α = 0): dissipative.
    Pic,
    /// Fluid-implicit-particle (α = 1), the default.
    #[default]
    Flip,
    /// The PIC/FLIP blend with FLIP fraction `alpha`.
    Blend,
    /// Taylor-PIC: PIC with the points' velocity gradients in the momentum
    /// projection.
    Tpic,
    /// Taylor-FLIP.
    Tflip,
}

impl TransferKind {
    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            TransferKind::Pic => "pic",
            TransferKind::Flip => "flip",
            TransferKind::Blend => "blend",
            TransferKind::Tpic => "tpic",
            TransferKind::Tflip => "tflip",
        }
    }
}

/// Why the implicit solver refuses `locking = cell_averaged`.
pub const CELL_AVERAGED_IMPLICIT: &str = "locking = cell_averaged is the explicit solver's dilatation averaging (solver kind = \"explicit\"); the implicit solver takes fbar (grids) or fpatch (simplex patches)";

/// A complete MPM variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Variant {
    /// Basis.
    pub basis: BasisKind,
    /// Formulation.
    pub formulation: FormulationKind,
    /// Locking treatment.
    pub locking: LockingKind,
    /// Domain update.
    pub domain_update: DomainUpdateKind,
    /// Integration volume of GIMP points.
    #[serde(default = "default_gimp_volume")]
    pub gimp_volume: GimpVolumeKind,
}

fn default_gimp_volume() -> GimpVolumeKind {
    GimpVolumeKind::DetF
}

impl Variant {
    /// `Ok` for the variants of simplex meshes: linear basis, no domain
    /// update, and no locking treatment or F-patch when the mesh has
    /// patches (`patches`: split from quadratic parents); `mesh` names the
    /// mesh in the error.
    pub fn require_simplex(&self, mesh: &str, patches: bool) -> Result<(), String> {
        if self.basis != BasisKind::Linear || self.domain_update != DomainUpdateKind::None {
            return Err(format!(
                "on {mesh} the variant is standard MPM: basis = linear, domain_update = none (got {} / {})",
                self.basis, self.domain_update
            ));
        }
        match self.locking {
            LockingKind::None => Ok(()),
            LockingKind::FPatch if patches => Ok(()),
            LockingKind::FPatch => Err(format!(
                "locking = fpatch needs patches, and {mesh} has none: split quadratic parents with [mesh] patches = true, or read a quadratic (tri6/tet10) Gmsh mesh"
            )),
            LockingKind::FBar => Err(format!(
                "locking = fbar averages over grid cells and applies to regular grids; on {mesh} use locking = fpatch"
            )),
            LockingKind::CellAveraged => Err(CELL_AVERAGED_IMPLICIT.into()),
        }
    }

    /// `Ok` for standard MPM without domain update or locking treatment,
    /// the only variant of the annulus and stretch cases' triangles and
    /// tetrahedra without patches.
    pub fn require_standard_mpm(&self, mesh: &str) -> Result<(), String> {
        self.require_simplex(mesh, false)
    }

    /// ` domain-volume` when GIMP points integrate with their domain's
    /// volume, else nothing (for one-line summaries).
    pub fn gimp_volume_note(&self) -> &'static str {
        match self.gimp_volume {
            GimpVolumeKind::DetF => "",
            GimpVolumeKind::Domain => " domain-volume",
        }
    }

    /// The variant as it runs: CPDI2 always convects its corners, so
    /// `domain_update = none` with `basis = cpdi2` reads `cpdi2`.
    pub fn resolved(self) -> Self {
        match (self.basis, self.domain_update) {
            (BasisKind::Cpdi2, DomainUpdateKind::None) => Self {
                domain_update: DomainUpdateKind::Cpdi2,
                ..self
            },
            _ => self,
        }
    }
}

impl Default for Variant {
    fn default() -> Self {
        Self {
            basis: BasisKind::Linear,
            formulation: FormulationKind::Pc,
            locking: LockingKind::None,
            domain_update: DomainUpdateKind::None,
            gimp_volume: GimpVolumeKind::DetF,
        }
    }
}

/// A computation generic over the variant's types; [`dispatch`] calls it
/// with the concrete types named by a [`Variant`].
pub trait VariantVisitor<const D: usize> {
    /// What the computation returns.
    type Output;

    /// Runs with basis `B`, formulation `F` and domain updater `U`.
    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>;
}

/// Calls `visitor` with the types of `variant`, or says why the
/// combination is not available.
pub fn dispatch<const D: usize, V: VariantVisitor<D>>(
    variant: &Variant,
    visitor: V,
) -> Result<V::Output, String> {
    if variant.basis != BasisKind::Gimp && variant.gimp_volume != GimpVolumeKind::DetF {
        return Err(format!(
            "gimp_volume = {} applies to basis = gimp",
            variant.gimp_volume
        ));
    }
    match variant.locking {
        LockingKind::None => {}
        LockingKind::CellAveraged => return Err(CELL_AVERAGED_IMPLICIT.into()),
        LockingKind::FPatch => {
            return Err("locking = fpatch averages over the patches of split tri6/tet10 parents and applies to simplex meshes; on a regular grid use locking = fbar".into());
        }
        LockingKind::FBar => {
            if variant.basis == BasisKind::Cpdi2
                || !matches!(variant.domain_update, DomainUpdateKind::None)
            {
                return Err(format!(
                    "scenes run locking = fbar with basis = linear, bspline2 or gimp and domain_update = none (got {} / {}); other combinations compose in Rust (mpm_solver::FBar)",
                    variant.basis, variant.domain_update
                ));
            }
        }
    }
    dispatch_basis(variant, visitor)
}

/// The basis `B` with formulation `variant.formulation` and updater `U`.
fn with_formulation<const D: usize, V, B, U>(
    variant: &Variant,
    v: V,
    basis: B,
    updater: U,
) -> V::Output
where
    V: VariantVisitor<D>,
    B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
    U: DomainUpdater<D, B::Domain>,
{
    match variant.formulation {
        FormulationKind::Ul => v.visit::<B, UpdatedLagrangian, U>(basis, updater),
        FormulationKind::Pc => v.visit::<B, PreviouslyConverged, U>(basis, updater),
    }
}

/// A basis without a domain: no domain rule applies.
fn point<const D: usize, V, B>(variant: &Variant, visitor: V, basis: B) -> Result<V::Output, String>
where
    V: VariantVisitor<D>,
    B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
{
    if variant.domain_update != DomainUpdateKind::None {
        return Err(format!(
            "domain_update = {} needs basis = gimp ({} has no domain to update)",
            variant.domain_update, variant.basis
        ));
    }
    Ok(with_formulation(variant, visitor, basis, NoUpdate))
}

/// CPDI2's corners are convected with the grid (eq. 35 form).
fn cpdi2<const D: usize, V, B>(variant: &Variant, visitor: V, basis: B) -> Result<V::Output, String>
where
    V: VariantVisitor<D>,
    B: InitialDomain<D, Mesh = RegularGrid<D>, Domain = mpm_basis::Corners<D>>,
    B::Domain: Flat + DomainBounds<D>,
{
    match variant.domain_update {
        DomainUpdateKind::None | DomainUpdateKind::Cpdi2 => {
            Ok(with_formulation(variant, visitor, basis, ConvectedCorners))
        }
        other => Err(format!(
            "basis = cpdi2 convects its corners with the grid; domain_update = {other} applies to gimp only"
        )),
    }
}

/// GIMP with every domain rule of Coombs et al. 2020 §6.4 and either
/// volume convention, chosen at run time ([`AnyGimpRule`]: one solver for
/// all of them).
fn gimp<const D: usize, V, B>(variant: &Variant, visitor: V, basis: B) -> Result<V::Output, String>
where
    V: VariantVisitor<D>,
    B: InitialDomain<D, Mesh = RegularGrid<D>, Domain = SVector<f64, D>>,
    B::Domain: Flat + DomainBounds<D>,
{
    let rule = AnyGimpRule {
        rule: variant.domain_update.gimp_rule()?,
        domain_volume: variant.gimp_volume == GimpVolumeKind::Domain,
    };
    Ok(with_formulation(variant, visitor, basis, rule))
}
