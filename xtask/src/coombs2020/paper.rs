//! Reference values quoted from Coombs, Augarde, Brennan et al. (2020), "On
//! Lagrangian mechanics and the implicit material point method for large
//! deformation elasto-plasticity", CMAME 358:112622 (tables of §7).

/// Cell size h, horizontal extent and maximum height of a collapse (m).
pub type Collapse = (f64, f64, f64);

/// Table 6 (standard MPM collapse): material points per cell per
/// direction and the collapse for h = 2, 1, 0.5 and 0.25 m.
pub const TABLE_6: [(usize, [Collapse; 4]); 3] = [
    (
        3,
        [
            (2.0, 13.343, 6.357),
            (1.0, 13.662, 6.245),
            (0.5, 13.731, 6.245),
            (0.25, 13.787, 6.234),
        ],
    ),
    (
        6,
        [
            (2.0, 13.359, 6.437),
            (1.0, 13.735, 6.277),
            (0.5, 13.797, 6.251),
            (0.25, 13.847, 6.231),
        ],
    ),
    (
        9,
        [
            (2.0, 13.380, 6.452),
            (1.0, 13.750, 6.289),
            (0.5, 13.812, 6.255),
            (0.25, 13.863, 6.226),
        ],
    ),
];

/// Table 7 (GIMP and CPDI2 collapse, h = 1 m, 6² points per cell):
/// horizontal extent and maximum height (m) per domain-update equation.
pub mod table7 {
    /// Eq. (32), det F.
    pub const EQ32: (f64, f64) = (13.645, 6.316);
    /// Eq. (33), diagonal of F.
    pub const EQ33: (f64, f64) = (14.415, 5.546);
    /// Eq. (34), diagonal of the stretch U.
    pub const EQ34: (f64, f64) = (13.425, 6.441);
    /// Eq. (37), volume-corrected corner update with mid-sides.
    pub const EQ37: (f64, f64) = (13.769, 6.392);
    /// Eqs. (38) and (39), volume-corrected diagonal of F.
    pub const EQ38_39: (f64, f64) = (13.769, 6.257);
    /// CPDI2.
    pub const CPDI2: (f64, f64) = (13.780, 6.292);
}

/// Table 8 (GIMP collapse, eq. 37, h = 1 m, 6² points): load steps and the
/// normalised residual (eq. 40) at Newton iterations 0, 1, ...
pub const TABLE_8: [(usize, &[f64]); 4] = [
    (10, &[2.656e0, 2.697e-4, 1.626e-9, 6.057e-15]),
    (
        20,
        &[2.794e0, 3.088e-2, 2.410e-2, 2.568e-3, 3.910e-5, 6.949e-10],
    ),
    (
        30,
        &[
            2.701e0, 2.380e-2, 4.626e-2, 6.193e-3, 2.225e-4, 1.356e-7, 6.713e-14,
        ],
    ),
    (
        40,
        &[
            2.410e0, 1.759e-2, 3.049e-2, 5.156e-3, 1.497e-4, 1.944e-7, 3.159e-13,
        ],
    ),
];

/// Table 3 (GIMP cantilever, h = 0.125 m, 6² points): load steps and the
/// normalised residual (eq. 40) at Newton iterations 0, 1, ...
pub const TABLE_3: [(usize, &[f64]); 5] = [
    (10, &[1.622e1, 1.242e-1, 2.436e-4, 5.524e-5, 1.470e-10]),
    (20, &[1.107e1, 1.699e-2, 1.366e-5, 3.660e-7, 9.912e-15]),
    (40, &[8.740e0, 1.731e-3, 2.890e-6, 1.131e-10]),
    (49, &[6.774e0, 1.509e-3, 1.072e-5, 1.089e-9, 3.250e-15]),
    (50, &[6.901e0, 9.246e-4, 2.112e-6, 5.012e-11]),
];
