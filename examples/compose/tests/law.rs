//! The custom law verified by the framework's exported finite-difference
//! tangent checks (the same ones `mpm-constitutive` runs on its own laws).

use mpm_example_compose::StiffeningHencky;

mpm_constitutive_proptest::law_tangent_properties!(stiffening_hencky, |e, nu| {
    StiffeningHencky::new(e, nu, 50.0)
});
