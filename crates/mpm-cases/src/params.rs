//! Case parameter structs share the variant keys (`basis`, `formulation`,
//! `locking`, `domain_update`) and the `case` key of scene files, so that a
//! scene is one flat table in which unknown keys are still rejected.

/// Defines a case parameter struct: the listed fields with their defaults,
/// plus the shared scene keys.
#[macro_export]
macro_rules! case_params {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* pub $field:ident : $ty:ty = $default:expr ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
        #[serde(deny_unknown_fields, default)]
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $ty, )*
            /// The case name (scene files name their case with it).
            #[serde(skip_serializing_if = "Option::is_none")]
            pub case: Option<String>,
            /// Basis functions.
            pub basis: $crate::variant::BasisKind,
            /// Statement of equilibrium.
            pub formulation: $crate::variant::FormulationKind,
            /// Locking treatment.
            pub locking: $crate::variant::LockingKind,
            /// GIMP domain update.
            pub domain_update: $crate::variant::DomainUpdateKind,
            /// Integration volume of GIMP points.
            pub gimp_volume: $crate::variant::GimpVolumeKind,
        }

        impl Default for $name {
            fn default() -> Self {
                let v = $crate::variant::Variant::default();
                Self {
                    $( $field: $default, )*
                    case: None,
                    basis: v.basis,
                    formulation: v.formulation,
                    locking: v.locking,
                    domain_update: v.domain_update,
                    gimp_volume: v.gimp_volume,
                }
            }
        }

        impl $name {
            /// The MPM variant these parameters name.
            pub fn variant(&self) -> $crate::variant::Variant {
                $crate::variant::Variant {
                    basis: self.basis,
                    formulation: self.formulation,
                    locking: self.locking,
                    domain_update: self.domain_update,
                    gimp_volume: self.gimp_volume,
                }
            }
        }

        impl $crate::params::CaseParams for $name {
            fn variant(&self) -> $crate::variant::Variant {
                $name::variant(self)
            }
        }
    };
}

/// What every [`case_params!`] struct offers a generic caller (e.g.
/// [`crate::cases::Solve`]).
pub trait CaseParams {
    /// The MPM variant these parameters name.
    fn variant(&self) -> crate::variant::Variant;
}
