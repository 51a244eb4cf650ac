//! One run of the `mpm` program: where it writes, whether it resumes from
//! a checkpoint, the progress display and the file output after every
//! converged step, and `summary.json` at the end. The built-in cases
//! ([`crate::cases::Case`]) and whole-problem scenes share it, so that a
//! case adds only its own checks and results.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use mpm_solver::{ObserverError, SolverError, StepReport};
use serde::Serialize;
use serde_json::{Map, Value};

use crate::CasesError;
use crate::checkpoint;
use crate::output::CellMesh;
use crate::run::{RunControl, RunOutput, Snapshot};
use crate::variant::Variant;
use crate::writer::{ExplicitSummary, RunWriter, Summary};

/// Where a run writes, whether it resumes, and the scene file it came from.
#[derive(Debug, Clone, Default)]
pub struct Session {
    /// The case name written into the checkpoint and `summary.json`
    /// (`scene` for whole-problem scenes).
    pub case: String,
    /// Output directory.
    pub out: PathBuf,
    /// Continue from the checkpoint in `out`.
    pub resume: bool,
    /// Stop (with a checkpoint) after this many converged steps.
    pub stop_after: Option<usize>,
    /// Write each step's last assembled stiffness as Matrix Market.
    pub export_tangent: bool,
    /// Directory of the scene file: relative mesh paths start there.
    pub scene_dir: PathBuf,
    /// The ranks of a run on several processes (`mpirun -n N mpm run`, a
    /// program built with the `mpi` feature); `None` for one process.
    pub ranks: Option<mpm_dispatch::on_ranks::SharedRanks>,
}

impl Session {
    /// `path` taken from the scene file's directory when relative.
    pub fn resolve(&self, path: &mut Option<PathBuf>) {
        if let Some(p) = path
            && p.is_relative()
        {
            *p = self.scene_dir.join(&*p);
        }
    }

    /// The observer and the run control for a run with parameters `p` on
    /// the output mesh `grid`: checkpoints always; with `resume`, the
    /// checkpoint of the output directory, which must have been written by
    /// the same case and parameters.
    ///
    /// # Errors
    /// [`CasesError::Checkpoint`] for a checkpoint of another case or other
    /// parameters; I/O errors of the output directory.
    pub fn start<const D: usize, M: CellMesh<D>, P: Serialize>(
        &self,
        p: &P,
        grid: M,
    ) -> Result<(Observer<D, M>, RunControl), CasesError> {
        let parameters =
            serde_json::to_value(p).map_err(|source| crate::output::OutputError::Json {
                path: self.out.join(checkpoint::FILE_NAME),
                source,
            })?;
        let (writer, resume) = if self.resume {
            let (header, checkpoint) = checkpoint::read(&self.out)?;
            if header.case != self.case || header.parameters != parameters {
                return Err(CasesError::Checkpoint {
                    path: self.out.join(checkpoint::FILE_NAME),
                    reason: format!(
                        "--resume: written by case `{}` with other parameters; run again without --resume, or with the scene and --set keys of that run",
                        header.case
                    ),
                });
            }
            (
                RunWriter::resume(&self.out, grid, header.writer)?,
                Some(checkpoint),
            )
        } else {
            (RunWriter::new(&self.out, grid)?, None)
        };
        // Temporary files of a run killed mid-write are of no use to this
        // one and must not outlive it.
        crate::output::remove_temporaries(&self.out)?;
        let control = RunControl {
            checkpoint: true,
            resume,
            external_linear: mpm_distributed::external_linear(),
            export_tangent: self.export_tangent,
            ranks: None,
        };
        let mut observer = Observer::new(writer, self.case.clone(), parameters);
        observer.stop_after = self.stop_after;
        Ok((observer, control))
    }
}

/// Progress display and file output, called after every converged step.
#[derive(Debug)]
pub struct Observer<const D: usize, M> {
    /// The output files.
    pub writer: RunWriter<D, M>,
    bar: ProgressBar,
    plain: bool,
    case: String,
    parameters: Value,
    stop_after: Option<usize>,
    steps: usize,
    /// When the progress display was last updated (explicit runs).
    last_shown: Option<Instant>,
}

impl<const D: usize, M: CellMesh<D>> Observer<D, M> {
    fn new(writer: RunWriter<D, M>, case: String, parameters: Value) -> Self {
        let plain = !std::io::stderr().is_terminal();
        let style =
            ProgressStyle::with_template("{elapsed_precise} [{bar:30}] load {percent:>3}% {msg}");
        // A terminal gets a progress bar; anything else (or a template
        // indicatif refuses) gets one line per step.
        let (bar, plain) = match style {
            Ok(style) if !plain => {
                let bar = ProgressBar::new(1000);
                bar.set_style(style.progress_chars("=> "));
                bar.enable_steady_tick(Duration::from_millis(200));
                (bar, false)
            }
            _ => (ProgressBar::hidden(), true),
        };
        Self {
            writer,
            bar,
            plain,
            case,
            parameters,
            stop_after: None,
            steps: 0,
            last_shown: None,
        }
    }

    /// Shows the converged step, writes its outputs and checkpoint, and
    /// stops the run after `stop_after` steps.
    ///
    /// # Errors
    /// [`SolverError::Observer`] for an output that cannot be written;
    /// [`SolverError::Stopped`] after `stop_after` steps.
    pub fn step(
        &mut self,
        step: usize,
        report: &StepReport<D>,
        snap: &Snapshot,
    ) -> Result<(), SolverError> {
        for cut in &report.cuts {
            let line = format!(
                "step {} from load factor {:.4} to {:.4} cut (last residual {:.2e}): {}",
                step + 1,
                cut.lambda0,
                cut.target,
                cut.last_residual,
                cut.cause
            );
            if self.plain {
                eprintln!("{line}");
            } else {
                self.bar.println(line);
            }
        }
        let residual = report.residuals.last().copied().unwrap_or(0.0);
        let mut line = format!(
            "step {} to load factor {:.4} (increment {:.3e}): {} iterations, residual {:.2e}",
            step + 1,
            report.lambda1,
            report.lambda1 - report.lambda0,
            report.iterations(),
            residual
        );
        if report.at_rounding_floor {
            line += &format!(
                " (stalled at the rounding floor {:.2e})",
                report.rounding_floor
            );
        }
        if self.plain {
            eprintln!("{line}");
        } else {
            self.bar
                .set_position((report.lambda1 * 1000.0).round() as u64);
            self.bar.set_message(line);
        }
        self.writer
            .step(step, report, snap)
            .map_err(observer_error)?;
        self.write_checkpoint(snap)?;
        self.steps += 1;
        if self.stop_after.is_some_and(|n| self.steps >= n) && report.lambda1 < 1.0 {
            self.bar.finish_and_clear();
            return Err(SolverError::Stopped {
                step: step + 1,
                load_factor: report.lambda1,
            });
        }
        Ok(())
    }

    /// Writes the checkpoint the snapshot carries, if any.
    fn write_checkpoint(&self, snap: &Snapshot) -> Result<(), SolverError> {
        if let Some(c) = &snap.checkpoint {
            checkpoint::write(
                self.writer.dir(),
                &self.case,
                self.parameters.clone(),
                c,
                self.writer.state(),
            )
            .map_err(observer_error)?;
        }
        Ok(())
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        self.writer.dir()
    }

    /// Shows the progress of an explicit run in simulated time.
    pub fn show_time(&mut self) {
        if self.plain {
            return;
        }
        if let Ok(style) =
            ProgressStyle::with_template("{elapsed_precise} [{bar:30}] time {percent:>3}% {msg}")
        {
            self.bar.set_style(style.progress_chars("=> "));
        }
    }

    /// Shows time step `step` of an explicit run (at most ten times a
    /// second; nothing on a plain output, which gets a line per output).
    pub fn explicit_step(&mut self, time: f64, end_time: f64, step: usize, dt: f64) {
        if self.plain
            || self
                .last_shown
                .is_some_and(|t| t.elapsed() < Duration::from_millis(100))
        {
            return;
        }
        self.last_shown = Some(Instant::now());
        self.bar
            .set_position((time / end_time * 1000.0).round() as u64);
        self.bar
            .set_message(format!("t = {time:.4e} s, step {step}, Δt = {dt:.3e} s"));
    }

    /// Writes output `index` of an explicit run (the VTU files and, when
    /// the snapshot carries one, the checkpoint), shows it, and stops the
    /// run after `stop_after` outputs of this session.
    ///
    /// # Errors
    /// [`SolverError::Observer`] for an output that cannot be written;
    /// [`SolverError::Stopped`] after `stop_after` outputs (`step` is the
    /// output number, `load_factor` the time).
    pub fn explicit_output(
        &mut self,
        index: usize,
        time: f64,
        end_time: f64,
        steps: usize,
        snap: &Snapshot,
    ) -> Result<(), SolverError> {
        let line = format!("output {index} at t = {time:.6e} s: {steps} time steps");
        if self.plain {
            eprintln!("{line}");
        } else {
            self.bar
                .set_position((time / end_time * 1000.0).round() as u64);
        }
        self.writer
            .output(index, time, snap)
            .map_err(observer_error)?;
        self.write_checkpoint(snap)?;
        if index == 0 {
            return Ok(());
        }
        self.steps += 1;
        if self.stop_after.is_some_and(|n| self.steps >= n) && time < end_time {
            self.bar.finish_and_clear();
            return Err(SolverError::Stopped {
                step: index,
                load_factor: time,
            });
        }
        Ok(())
    }

    /// Writes `summary.json` of an explicit run and prints its digest.
    ///
    /// # Errors
    /// I/O and serialisation errors of `summary.json`.
    pub fn finish_explicit<P: Serialize>(
        self,
        summary: ExplicitSummary<P>,
    ) -> Result<(), CasesError> {
        self.bar.finish_and_clear();
        self.writer.explicit_summary(&summary)?;
        println!(
            "{} [explicit {} {} {}]: {} points, {} time steps to t = {}, energy drift {:.3e}, {:.3} s",
            summary.case,
            summary.basis,
            summary.transfer.name(),
            summary.locking,
            summary.material_points,
            summary.time_steps,
            shown(summary.end_time),
            summary.energy_drift,
            summary.wall_time_s,
        );
        Ok(())
    }

    /// Writes `summary.json` and prints its one-line digest.
    ///
    /// # Errors
    /// I/O and serialisation errors of `summary.json`.
    pub fn finish<P: Serialize>(self, summary: Summary<P>) -> Result<(), CasesError> {
        self.bar.finish_and_clear();
        self.writer.summary(&summary)?;
        println!(
            "{} [{} {} {} {}{}]: {} points, {} steps ({} cut), {} Newton iterations, {:.3} s{}",
            summary.case,
            summary.variant.basis,
            summary.variant.formulation,
            summary.variant.locking,
            summary.variant.domain_update,
            summary.variant.gimp_volume_note(),
            summary.material_points,
            summary.load_steps,
            summary.cut_steps,
            summary.newton_iterations,
            summary.wall_time_s,
            summary
                .error
                .map(|e| format!(", error {e:.4e}"))
                .unwrap_or_default()
        );
        Ok(())
    }
}

/// `x` rounded to 12 significant digits, for messages: a time reached by
/// a sum of fixed steps (29.999999999997215) reads as the time it is (30).
pub fn shown(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// An output error as the solver's observer reports it.
pub fn observer_error(e: CasesError) -> SolverError {
    SolverError::Observer(ObserverError::new(e))
}

/// The `summary.json` of a run.
pub fn summary<const D: usize, P: Serialize>(
    case: &str,
    variant: Variant,
    points: usize,
    output: &RunOutput<D>,
    error: Option<f64>,
    results: Map<String, Value>,
    parameters: P,
) -> Summary<P> {
    Summary {
        case: case.to_string(),
        variant: variant.resolved(),
        material_points: points,
        load_steps: output.summary.steps,
        cut_steps: output.summary.cut_steps,
        newton_iterations: output.summary.iterations,
        wall_time_s: output.wall_time_s,
        error,
        results,
        parameters,
    }
}
