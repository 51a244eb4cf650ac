//! The generic core of the report: a case is a list of variants, each run
//! over the case's refinement series; a run gives its error against the
//! case's reference and its wall time, or the message of why it failed.
//! [`CaseSpec::measure`] runs every variant at every level and times it
//! (the fastest of up to [`REPEATS`] runs for short ones); [`CaseResult`]
//! holds what the analysis and the page read.

use std::time::Instant;

/// What one run returns: its error against the case's reference and the
/// solver's wall time (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Error against the reference (the case's own measure).
    pub error: f64,
    /// Wall time of the solver (s).
    pub seconds: f64,
}

/// One level of a case's refinement series.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    /// How the page names it: "k = 3", "n = 16", "40 cells".
    pub label: String,
    /// The refinement as an integer (k, n, cells), for the runs.
    pub n: usize,
    /// The mesh size h of the convergence order (in the case's units).
    pub h: f64,
}

/// One run of a variant at one level, as measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Error against the reference.
    pub error: f64,
    /// The fastest wall time of its repeats (s).
    pub seconds: f64,
    /// How many times it ran.
    pub repeats: usize,
}

/// What became of a variant at a level.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// It ran.
    Measured(Measured),
    /// It failed, with the error's message.
    Failed(String),
}

impl Outcome {
    /// The measurement, if the run succeeded.
    pub fn measured(&self) -> Option<&Measured> {
        match self {
            Outcome::Measured(m) => Some(m),
            Outcome::Failed(_) => None,
        }
    }
}

/// A run of a variant at a level: the error and time, or why it failed.
pub type RunFn = Box<dyn Fn(&Level) -> Result<Sample, String>>;

/// A variant of a case and how to run it.
pub struct VariantSpec {
    /// Its full name on the page.
    pub label: String,
    /// The name of its line's colour and marker: variants that differ only
    /// in their [`style`](Self::style) share it (and one legend entry).
    pub family: String,
    /// Index into the case's [`CaseSpec::styles`]: 0 draws solid lines and
    /// filled markers, 1 dashed lines and hollow markers.
    pub style: usize,
    /// One run.
    pub run: RunFn,
}

impl VariantSpec {
    /// A variant named `label`, its own family, run at every level.
    pub fn new(label: impl Into<String>, run: RunFn) -> Self {
        let label = label.into();
        Self {
            family: label.clone(),
            label,
            style: 0,
            run,
        }
    }

    /// The same variant drawn in `family`'s colour with line style `style`.
    pub fn styled(self, family: impl Into<String>, style: usize) -> Self {
        Self {
            family: family.into(),
            style,
            ..self
        }
    }
}

/// A case to measure: what it is, its levels and its variants.
pub struct CaseSpec {
    /// File-name part: the PNG is `img/report-<slug>.png`.
    pub slug: &'static str,
    /// Heading.
    pub title: String,
    /// The set-up, the reference, the error measure and the levels.
    pub about: String,
    /// The error's name on the plot's axis.
    pub error_name: String,
    /// What h is, with units (the tables' and orders' refinement measure).
    pub h_name: String,
    /// The refinement series, coarse to fine.
    pub levels: Vec<Level>,
    /// Names of the line styles when variants come in families (solid
    /// first); empty when every variant is its own family.
    pub styles: Vec<String>,
    /// The variants that apply.
    pub variants: Vec<VariantSpec>,
    /// Combinations of the variant axes that do not exist for the case
    /// (refused by `variant::dispatch` or the mesh), not run.
    pub absent: usize,
}

/// A measured case.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseResult {
    /// As [`CaseSpec::slug`].
    pub slug: &'static str,
    /// As [`CaseSpec::title`].
    pub title: String,
    /// As [`CaseSpec::about`].
    pub about: String,
    /// As [`CaseSpec::error_name`].
    pub error_name: String,
    /// As [`CaseSpec::h_name`].
    pub h_name: String,
    /// As [`CaseSpec::levels`].
    pub levels: Vec<Level>,
    /// As [`CaseSpec::styles`].
    pub styles: Vec<String>,
    /// Per variant, its outcome at every level.
    pub variants: Vec<VariantRuns>,
    /// As [`CaseSpec::absent`].
    pub absent: usize,
    /// Wall time of measuring the whole case, repeats included (s).
    pub seconds: f64,
}

/// A measured variant.
#[derive(Debug, Clone, PartialEq)]
pub struct VariantRuns {
    /// As [`VariantSpec::label`].
    pub label: String,
    /// As [`VariantSpec::family`].
    pub family: String,
    /// As [`VariantSpec::style`].
    pub style: usize,
    /// One per level of the case.
    pub outcomes: Vec<Outcome>,
}

impl VariantRuns {
    /// The successful runs with their levels.
    pub fn measured<'a>(
        &'a self,
        levels: &'a [Level],
    ) -> impl Iterator<Item = (&'a Level, &'a Measured)> + 'a {
        levels
            .iter()
            .zip(&self.outcomes)
            .filter_map(|(l, o)| o.measured().map(|m| (l, m)))
    }
}

/// Runs this many times at most ...
pub const REPEATS: usize = 3;
/// ... while its fastest run took less than this (s): short runs scatter
/// the most on a shared machine.
pub const SHORT_S: f64 = 0.2;

/// The first run of `run` at `level`; an error that is not a finite number
/// is a failure.
pub fn once(run: &dyn Fn(&Level) -> Result<Sample, String>, level: &Level) -> Outcome {
    match run(level) {
        Ok(s) if s.error.is_finite() => Outcome::Measured(Measured {
            error: s.error,
            seconds: s.seconds,
            repeats: 1,
        }),
        Ok(s) => Outcome::Failed(format!("the error is {}", s.error)),
        Err(e) => Outcome::Failed(e),
    }
}

/// Runs `run` at `level` once more if `m` is due a repeat (fewer than
/// [`REPEATS`] runs, the fastest under [`SHORT_S`]), keeping the fastest
/// time; the error stays the first run's (the runs are deterministic), and
/// a repeat that fails keeps the measurement. Whether it ran.
pub fn again(
    run: &dyn Fn(&Level) -> Result<Sample, String>,
    level: &Level,
    m: &mut Measured,
) -> bool {
    if m.repeats >= REPEATS || m.seconds >= SHORT_S {
        return false;
    }
    m.repeats += 1;
    if let Ok(s) = run(level) {
        m.seconds = m.seconds.min(s.seconds);
    }
    true
}

impl CaseSpec {
    /// Runs every variant at its levels, then repeats the short runs in
    /// rounds over all of them (so that a burst of other work on the
    /// machine slows one run of many rather than every repeat of one),
    /// printing a line per variant.
    pub fn measure(self) -> CaseResult {
        let started = Instant::now();
        let mut outcomes: Vec<Vec<Outcome>> = self
            .variants
            .iter()
            .map(|v| {
                self.levels
                    .iter()
                    .map(|level| once(&v.run, level))
                    .collect()
            })
            .collect();
        let mut repeating = true;
        while repeating {
            repeating = false;
            for (v, row) in self.variants.iter().zip(&mut outcomes) {
                for (level, o) in self.levels.iter().zip(row.iter_mut()) {
                    if let Outcome::Measured(m) = o {
                        repeating |= again(&v.run, level, m);
                    }
                }
            }
        }
        let mut variants = Vec::with_capacity(self.variants.len());
        for (v, outcomes) in self.variants.into_iter().zip(outcomes) {
            println!(
                "report {:<8} {:<48} {}",
                self.slug,
                v.label,
                outcomes
                    .iter()
                    .map(|o| match o {
                        Outcome::Measured(m) =>
                            format!("{:.2e} ({:.1} ms)", m.error, 1e3 * m.seconds),
                        Outcome::Failed(_) => "failed".into(),
                    })
                    .collect::<Vec<_>>()
                    .join("  ")
            );
            variants.push(VariantRuns {
                label: v.label,
                family: v.family,
                style: v.style,
                outcomes,
            });
        }
        CaseResult {
            slug: self.slug,
            title: self.title,
            about: self.about,
            error_name: self.error_name,
            h_name: self.h_name,
            levels: self.levels,
            styles: self.styles,
            variants,
            absent: self.absent,
            seconds: started.elapsed().as_secs_f64(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    fn level() -> Level {
        Level {
            label: "n = 1".into(),
            n: 1,
            h: 1.0,
        }
    }

    #[test]
    fn short_runs_are_repeated_and_the_fastest_kept() {
        let calls = Cell::new(0);
        let run = |_: &Level| {
            calls.set(calls.get() + 1);
            Ok(Sample {
                error: 0.5,
                seconds: [0.05, 0.03, 0.04, 0.01][calls.get() - 1],
            })
        };
        let Outcome::Measured(mut m) = once(&run, &level()) else {
            panic!("the run succeeded")
        };
        while again(&run, &level(), &mut m) {}
        assert_eq!(
            (calls.get(), m.repeats, m.seconds, m.error),
            (3, 3, 0.03, 0.5)
        );
    }

    #[test]
    fn long_runs_once_failures_and_nan_as_messages() {
        let long = |_: &Level| {
            Ok(Sample {
                error: 0.5,
                seconds: 1.0,
            })
        };
        let Outcome::Measured(mut m) = once(&long, &level()) else {
            panic!("the run succeeded")
        };
        assert!(!again(&long, &level(), &mut m));
        let failing = |_: &Level| Err("step 3 did not converge".to_string());
        assert_eq!(
            once(&failing, &level()),
            Outcome::Failed("step 3 did not converge".into())
        );
        let nan = |_: &Level| {
            Ok(Sample {
                error: f64::NAN,
                seconds: 1.0,
            })
        };
        assert!(matches!(once(&nan, &level()), Outcome::Failed(_)));
    }

    #[test]
    fn a_case_measures_every_level_and_repeats_the_short_runs() {
        let levels: Vec<Level> = (1..=3)
            .map(|n| Level {
                label: format!("n = {n}"),
                n,
                h: 1.0 / n as f64,
            })
            .collect();
        let spec = CaseSpec {
            slug: "t",
            title: "T".into(),
            about: String::new(),
            error_name: "e".into(),
            h_name: "h".into(),
            levels,
            styles: Vec::new(),
            variants: vec![
                VariantSpec::new(
                    "fails at n = 2",
                    Box::new(|l: &Level| {
                        if l.n == 2 {
                            Err("diverged".into())
                        } else {
                            Ok(Sample {
                                error: l.h,
                                seconds: 1e-4,
                            })
                        }
                    }),
                ),
                VariantSpec::new(
                    "slow",
                    Box::new(|l: &Level| {
                        Ok(Sample {
                            error: l.h * l.h,
                            seconds: 1.0,
                        })
                    }),
                )
                .styled("family", 1),
            ],
            absent: 0,
        };
        let r = spec.measure();
        let v = &r.variants;
        assert!(matches!(v[0].outcomes[0], Outcome::Measured(m) if m.repeats == REPEATS));
        assert_eq!(v[0].outcomes[1], Outcome::Failed("diverged".into()));
        assert!(
            matches!(v[1].outcomes[1], Outcome::Measured(m) if m.repeats == 1 && m.error == 0.25)
        );
        assert_eq!((v[1].family.as_str(), v[1].style), ("family", 1));
    }
}
