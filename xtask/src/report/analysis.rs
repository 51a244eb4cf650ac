//! What the report reads from a measured case: the observed convergence
//! orders of each variant, the accuracy levels ε to compare at, the
//! fastest run reaching each, and the one-paragraph summary.

use super::study::{CaseResult, Level, Measured, VariantRuns};
use crate::markdown::millis;

/// Errors at or below this are round-off or the Newton tolerance (1e-9 in
/// the implicit cases): a variant reproduces the reference exactly, and
/// its "order" means nothing.
pub const ROUND_OFF: f64 = 1e-8;

/// The successful runs of `v` with an error above round-off, as
/// (ln h, ln error).
fn log_points(v: &VariantRuns, levels: &[Level]) -> Vec<(f64, f64)> {
    v.measured(levels)
        .filter(|(l, m)| m.error > ROUND_OFF && l.h > 0.0)
        .map(|(l, m)| (l.h.ln(), m.error.ln()))
        .collect()
}

/// The observed order of convergence of `v`: the least-squares slope of
/// ln error against ln h over its successful levels (positive when the
/// error falls with h); `None` with fewer than two such levels.
pub fn fitted_order(v: &VariantRuns, levels: &[Level]) -> Option<f64> {
    let p = log_points(v, levels);
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The order between the two finest successful levels of `v`.
pub fn last_pair_order(v: &VariantRuns, levels: &[Level]) -> Option<f64> {
    match log_points(v, levels).as_slice() {
        [.., a, b] if a.0 != b.0 => Some((b.1 - a.1) / (b.0 - a.0)),
        _ => None,
    }
}

/// The accuracy levels of a case: up to three values 10ⁿ from the spread
/// of its successful errors (from the smallest, which some run reaches,
/// to the largest), evenly spread over that range with both ends; where
/// fewer than three decades fit, values 1, 2 or 5 × 10ⁿ; when every error
/// is round-off, [`ROUND_OFF`] alone. Loosest first.
pub fn accuracy_levels(case: &CaseResult) -> Vec<f64> {
    let errors: Vec<f64> = case
        .variants
        .iter()
        .flat_map(|v| v.measured(&case.levels).map(|(_, m)| m.error))
        .filter(|e| *e > 0.0)
        .collect();
    let lo = errors.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = errors.iter().copied().fold(0.0, f64::max);
    if errors.is_empty() {
        return Vec::new();
    }
    if hi <= ROUND_OFF {
        return vec![ROUND_OFF];
    }
    let lo = lo.max(ROUND_OFF);
    let candidates = |mantissas: &[u8]| -> Vec<f64> {
        let mut out = Vec::new();
        for e in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
            for m in mantissas {
                let c = nice(*m, e);
                if c >= lo * (1.0 - 1e-12) && c < hi {
                    out.push(c);
                }
            }
        }
        out
    };
    let mut pick = candidates(&[1]);
    if pick.len() < 3 {
        pick = candidates(&[1, 2, 5]);
    }
    if pick.is_empty() {
        // Every error within one 1-2-5 step: the step above the largest.
        let e = hi.log10().floor() as i32;
        pick = vec![
            [nice(1, e), nice(2, e), nice(5, e), nice(1, e + 1)]
                .into_iter()
                .find(|c| *c >= hi)
                .unwrap_or(hi),
        ];
    }
    let chosen: Vec<f64> = if pick.len() <= 3 {
        pick
    } else {
        let last = pick.len() - 1;
        vec![pick[0], pick[last / 2], pick[last]]
    };
    chosen.into_iter().rev().collect()
}

/// m × 10ᵉ as the literal `{m}e{e}` reads (exactly the value `1e-3` is).
fn nice(m: u8, e: i32) -> f64 {
    format!("{m}e{e}").parse().unwrap_or(f64::NAN)
}

/// The fastest run of `v` whose error is at most `eps`: its level index
/// and measurement.
pub fn fastest_of(v: &VariantRuns, eps: f64) -> Option<(usize, &Measured)> {
    v.outcomes
        .iter()
        .enumerate()
        .filter_map(|(i, o)| o.measured().map(|m| (i, m)))
        .filter(|(_, m)| m.error <= eps)
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
}

/// The fastest run of the whole case whose error is at most `eps`: the
/// variant's index, the level's index and the measurement.
pub fn fastest(case: &CaseResult, eps: f64) -> Option<(usize, usize, &Measured)> {
    case.variants
        .iter()
        .enumerate()
        .filter_map(|(j, v)| fastest_of(v, eps).map(|(i, m)| (j, i, m)))
        .min_by(|a, b| a.2.seconds.total_cmp(&b.2.seconds))
}

/// ε as the page writes it: `1e-3`, `2e-4`.
pub fn eps_label(eps: f64) -> String {
    format!("{eps:.0e}")
}

/// Whether every successful run of the case is exact to [`ROUND_OFF`].
fn exact(case: &CaseResult) -> bool {
    case.variants
        .iter()
        .flat_map(|v| v.measured(&case.levels))
        .all(|(_, m)| m.error <= ROUND_OFF)
}

/// Runs within this factor of the fastest time are a tie on a shared
/// machine.
pub const TIE: f64 = 1.25;

/// One paragraph: the cheapest run at each accuracy level, the fitted
/// orders' range and what failed.
pub fn summary(case: &CaseResult) -> String {
    let mut parts = Vec::new();
    for eps in accuracy_levels(case) {
        parts.push(match fastest(case, eps) {
            Some((j, i, m)) => {
                // Other variants whose fastest run at this level is within
                // timing noise of the winner's.
                let close = case
                    .variants
                    .iter()
                    .enumerate()
                    .filter(|(k, v)| {
                        *k != j
                            && fastest_of(v, eps).is_some_and(|(_, o)| o.seconds <= TIE * m.seconds)
                    })
                    .count();
                let tie = match close {
                    0 => String::new(),
                    1 => format!(", one other variant within {:.0} %", 100.0 * (TIE - 1.0)),
                    n => format!(", {n} other variants within {:.0} %", 100.0 * (TIE - 1.0)),
                };
                format!(
                    "error ≤ {}: **{}** at {} ({} ms, error {:.2e}{tie})",
                    eps_label(eps),
                    case.variants[j].label,
                    case.levels[i].label,
                    millis(m.seconds),
                    m.error
                )
            }
            None => format!("error ≤ {}: no run", eps_label(eps)),
        });
    }
    let mut text = if parts.is_empty() {
        "No run succeeded.".to_owned()
    } else {
        format!("Cheapest run reaching {}.", parts.join("; "))
    };
    if exact(case) && !parts.is_empty() {
        text.push_str(&format!(
            " Every run reproduces the reference to round-off or the Newton tolerance (error \
             ≤ {}), so refinement buys no accuracy and the comparison is one of cost alone.",
            eps_label(ROUND_OFF)
        ));
    } else {
        let mut orders: Vec<(f64, &str)> = case
            .variants
            .iter()
            .filter_map(|v| fitted_order(v, &case.levels).map(|p| (p, v.label.as_str())))
            .collect();
        orders.sort_by(|a, b| b.0.total_cmp(&a.0));
        if let (Some(best), Some(worst)) = (orders.first(), orders.last()) {
            if orders.len() == 1 {
                text.push_str(&format!(" Fitted order: {:.2} ({}).", best.0, best.1));
            } else if best.0 - worst.0 < 0.01 {
                text.push_str(&format!(" Fitted order: {:.2} for every variant.", best.0));
            } else {
                text.push_str(&format!(
                    " Fitted orders from {:.2} ({}) to {:.2} ({}).",
                    best.0, best.1, worst.0, worst.1
                ));
            }
        }
    }
    let failed: Vec<&str> = case
        .variants
        .iter()
        .filter(|v| {
            v.outcomes
                .iter()
                .any(|o| matches!(o, super::study::Outcome::Failed(_)))
        })
        .map(|v| v.label.as_str())
        .collect();
    if !failed.is_empty() {
        text.push_str(&format!(
            " Failed at one level or more: {} (see the table of runs).",
            failed.join("; ")
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::super::study::{Outcome, VariantRuns};
    use super::*;

    fn case(errors: &[&[f64]]) -> CaseResult {
        let levels: Vec<Level> = (0..errors[0].len())
            .map(|k| Level {
                label: format!("k = {k}"),
                n: k,
                h: 0.5f64.powi(k as i32),
            })
            .collect();
        let variants = errors
            .iter()
            .enumerate()
            .map(|(j, e)| VariantRuns {
                label: format!("v{j}"),
                family: format!("v{j}"),
                style: 0,
                outcomes: e
                    .iter()
                    .enumerate()
                    .map(|(k, &error)| {
                        if error.is_nan() {
                            Outcome::Failed("diverged".into())
                        } else {
                            Outcome::Measured(Measured {
                                error,
                                // Finer levels cost more; v1 1.5 times v0.
                                seconds: 1e-3 * 2f64.powi(k as i32) * (1.0 + 0.5 * j as f64),
                                repeats: 1,
                            })
                        }
                    })
                    .collect(),
            })
            .collect();
        CaseResult {
            slug: "test",
            title: "test".into(),
            about: String::new(),
            error_name: "error".into(),
            h_name: "h".into(),
            levels,
            styles: Vec::new(),
            variants,
            absent: 0,
            seconds: 0.0,
        }
    }

    #[test]
    fn orders_of_a_second_order_series() {
        let c = case(&[&[1e-1, 2.5e-2, 6.25e-3, 1.5625e-3]]);
        let v = &c.variants[0];
        assert!((fitted_order(v, &c.levels).expect("four levels") - 2.0).abs() < 1e-12);
        assert!((last_pair_order(v, &c.levels).expect("four levels") - 2.0).abs() < 1e-12);
        // A stalled series has order zero; a failed level is left out.
        let c = case(&[&[1e-2, 1e-2, f64::NAN, 1e-2]]);
        assert!(
            fitted_order(&c.variants[0], &c.levels)
                .expect("three levels")
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn accuracy_levels_span_the_errors() {
        let c = case(&[
            &[3e-1, 3e-2, 3e-3, 3e-4, 3e-5],
            &[2e-1, 1e-1, 8e-2, 7e-2, 6e-2],
        ]);
        assert_eq!(accuracy_levels(&c), vec![1e-1, 1e-3, 1e-4]);
        let c = case(&[&[4e-2, 2.5e-2]]);
        assert_eq!(accuracy_levels(&c), vec![5e-2]);
        let c = case(&[&[1e-9, 2e-14]]);
        assert_eq!(accuracy_levels(&c), vec![ROUND_OFF]);
    }

    #[test]
    fn the_fastest_run_below_each_level() {
        // v0 needs its finest level for 1e-3 (4 ms); v1 reaches it at
        // level 1 (3 ms).
        let c = case(&[&[1e-1, 1e-2, 1e-3], &[1e-2, 1e-3, 1e-4]]);
        let (j, i, m) = fastest(&c, 1e-3).expect("v1 reaches 1e-3");
        assert_eq!((j, i), (1, 1));
        assert!((m.seconds - 3e-3).abs() < 1e-15);
        assert_eq!(fastest(&c, 1e-2).map(|f| (f.0, f.1)), Some((1, 0)));
        assert_eq!(fastest_of(&c.variants[0], 1e-2).map(|f| f.0), Some(1));
        assert!(fastest(&c, 1e-5).is_none());
        let s = summary(&c);
        assert!(s.contains("error ≤ 1e-3: **v1** at k = 1"), "{s}");
    }
}
