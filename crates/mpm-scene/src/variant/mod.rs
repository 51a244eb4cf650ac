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

use crate::body::DomainBounds;

pub mod rules;
use crate::body::InitialDomain;

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
            Self::Cpdi2 => return Err(rules::CPDI2_UPDATE_WITH_GIMP.into()),
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

pub use rules::CELL_AVERAGED_IMPLICIT;

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

/// Calls `visitor` with the types of `variant` for the implicit solver on
/// a grid, or says why the combination is not available.
pub fn dispatch<const D: usize, V: VariantVisitor<D>>(
    variant: &Variant,
    visitor: V,
) -> Result<V::Output, String> {
    dispatch_in(variant, rules::Context::ImplicitGrid, visitor)
}

/// [`dispatch`] for the solver of `context`: the variant is checked
/// against the rules of that context first. The explicit runner visits
/// through here too, so a basis registered once ([`register_bases!`])
/// reaches both runners; it ignores the formulation type (the rules keep
/// the explicit scene at the default one).
pub fn dispatch_in<const D: usize, V: VariantVisitor<D>>(
    variant: &Variant,
    context: rules::Context<'_>,
    visitor: V,
) -> Result<V::Output, String> {
    variant.check(context).map_err(|refusal| refusal.message)?;
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
    debug_assert_eq!(
        variant.domain_update,
        DomainUpdateKind::None,
        "checked by the rules"
    );
    Ok(with_formulation(variant, visitor, basis, NoUpdate))
}

/// CPDI2's corners are convected with the grid (eq. 35 form).
fn cpdi2<const D: usize, V, B>(variant: &Variant, visitor: V, basis: B) -> Result<V::Output, String>
where
    V: VariantVisitor<D>,
    B: InitialDomain<D, Mesh = RegularGrid<D>, Domain = mpm_basis::Corners<D>>,
    B::Domain: Flat + DomainBounds<D>,
{
    // The rules let `none` and `cpdi2` through; both convect the corners.
    Ok(with_formulation(variant, visitor, basis, ConvectedCorners))
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
