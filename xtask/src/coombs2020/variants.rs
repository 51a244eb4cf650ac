//! The MPM variants the studies compare, with the names the report uses.

use mpm_cases::variant::{BasisKind, DomainUpdateKind, GimpVolumeKind, Variant};

/// Standard MPM or GIMP with a domain-update rule, CPDI2 or the quadratic
/// B-spline, all with the previously converged formulation (as in §7).
pub fn variant(basis: BasisKind, domain_update: DomainUpdateKind) -> Variant {
    Variant {
        basis,
        domain_update,
        ..Variant::default()
    }
    .resolved()
}

/// GIMP with domain-update rule `rule`.
pub fn gimp(rule: DomainUpdateKind) -> Variant {
    variant(BasisKind::Gimp, rule)
}

/// GIMP with rule `rule` whose points integrate with their domain's
/// volume, the paper's convention (`gimp_volume = domain`).
pub fn gimp_domain_volume(rule: DomainUpdateKind) -> Variant {
    Variant {
        gimp_volume: GimpVolumeKind::Domain,
        ..gimp(rule)
    }
}

/// Whether a variant integrates with its domain's volume.
pub fn domain_volume(v: &Variant) -> bool {
    v.gimp_volume == GimpVolumeKind::Domain
}

/// CPDI2 (corners convected with the grid).
pub fn cpdi2() -> Variant {
    variant(BasisKind::Cpdi2, DomainUpdateKind::Cpdi2)
}

/// Standard MPM.
pub fn linear() -> Variant {
    variant(BasisKind::Linear, DomainUpdateKind::None)
}

/// Every GIMP rule, in the paper's order.
pub const GIMP_RULES: [DomainUpdateKind; 8] = [
    DomainUpdateKind::None,
    DomainUpdateKind::DetF,
    DomainUpdateKind::DiagF,
    DomainUpdateKind::Stretch,
    DomainUpdateKind::CornerMidpoint,
    DomainUpdateKind::Midpoint,
    DomainUpdateKind::VolumeCorrectedDiagF,
    DomainUpdateKind::IncrementalVolumeCorrectedDiagF,
];

/// Standard MPM, the quadratic B-spline (plain, with one padding cell, and
/// boundary-modified), GIMP with every rule, GIMP
/// without update integrating with its domain's volume (the paper's
/// convention; with the other rules of Fig. 7 the two conventions agree to
/// round-off) and CPDI2.
pub fn all() -> Vec<Variant> {
    let mut v = vec![
        linear(),
        variant(BasisKind::BSpline2, DomainUpdateKind::None),
        variant(BasisKind::BSpline2Boundary, DomainUpdateKind::None),
    ];
    v.extend(GIMP_RULES.map(gimp));
    v.push(gimp_domain_volume(DomainUpdateKind::None));
    v.push(cpdi2());
    v
}

/// The suffix that marks the domain-volume convention in labels.
const DOMAIN_VOLUME: &str = ", V = ∏2l";

/// The report's name of a variant: basis and, for GIMP, the paper's
/// equation of the domain update.
pub fn label(v: &Variant) -> String {
    match v.basis {
        BasisKind::Linear => "standard MPM".into(),
        BasisKind::BSpline2 => "quadratic B-spline".into(),
        BasisKind::BSpline2Boundary => "quadratic B-spline, boundary-modified".into(),
        BasisKind::Cpdi2 => "CPDI2".into(),
        BasisKind::Gimp if domain_volume(v) => {
            format!("GIMP, {}{DOMAIN_VOLUME}", rule_label(v.domain_update))
        }
        BasisKind::Gimp => format!("GIMP, {}", rule_label(v.domain_update)),
    }
}

/// A short name for legends: the basis and, for GIMP, the equation.
pub fn short_label(v: &Variant) -> String {
    match v.basis {
        BasisKind::Gimp if domain_volume(v) => {
            let plain = Variant {
                gimp_volume: GimpVolumeKind::DetF,
                ..*v
            };
            format!("{}{DOMAIN_VOLUME}", short_label(&plain))
        }
        BasisKind::Gimp => match v.domain_update {
            DomainUpdateKind::None => "GIMP, no update".into(),
            DomainUpdateKind::Midpoint => "GIMP (eq. 37, Fig. 5b)".into(),
            rule => format!(
                "GIMP ({})",
                rule_label(rule).split(" (").next().unwrap_or("")
            ),
        },
        _ => label(v),
    }
}

/// The paper's name of a GIMP domain-update rule.
pub fn rule_label(rule: DomainUpdateKind) -> &'static str {
    match rule {
        DomainUpdateKind::None => "no update",
        DomainUpdateKind::DetF => "eq. 32 (det F)",
        DomainUpdateKind::DiagF => "eq. 33 (F_ii)",
        DomainUpdateKind::Stretch => "eq. 34 (U_ii)",
        DomainUpdateKind::CornerMidpoint => "eq. 37 (corners, Fig. 5a)",
        DomainUpdateKind::Midpoint => "eq. 37 (mid-points, Fig. 5b)",
        DomainUpdateKind::VolumeCorrectedDiagF => "eq. 38 (volume-corrected F_ii)",
        DomainUpdateKind::IncrementalVolumeCorrectedDiagF => "eq. 39 (incremental eq. 38)",
        DomainUpdateKind::Cpdi2 => "convected corners",
    }
}
