//! Writes a run's results: VTU of the material points and of the active
//! grid per converged step with PVD series, CSV histories and
//! `summary.json`. Every file is written atomically, so an interrupted run
//! leaves valid files behind.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mpm_solver::StepReport;
use serde::Serialize;

use crate::CasesError;
use crate::output::{
    CellMesh, CsvTable, CsvValue, PvdSeries, PvdStep, UnstructuredGrid, Values, atomic_write_with,
    write_summary,
};
use crate::run::Snapshot;
use crate::variant::Variant;
use mpm_dispatch::on_ranks::PieceFields;

pub use mpm_scene::format::Field;

/// Output of one run in a directory, for material points in `D`
/// dimensions on the background mesh `M`.
#[derive(Debug)]
pub struct RunWriter<const D: usize, M> {
    dir: PathBuf,
    grid: M,
    points: PvdSeries,
    cells: PvdSeries,
    steps: CsvTable,
    iterations: CsvTable,
    tables: BTreeMap<String, CsvTable>,
    options: VtuOptions,
    /// The ranks writing their own pieces of the points' files (0 or 1:
    /// this writer writes them whole).
    pieces: usize,
}

/// What the VTU files of a run hold and how often they are written.
#[derive(Debug, Clone, PartialEq)]
pub struct VtuOptions {
    /// Write the VTU files of every this many steps (and of the step that
    /// reaches load factor 1).
    pub every: usize,
    /// The material-point fields written.
    pub fields: Vec<Field>,
    /// Per-point constants written with [`Field::Body`]: name and one
    /// value per point.
    pub constants: Vec<(String, Vec<f64>)>,
}

impl Default for VtuOptions {
    fn default() -> Self {
        Self {
            every: 1,
            fields: Field::ALL.to_vec(),
            constants: Vec::new(),
        }
    }
}

/// What a [`RunWriter`] has written so far, saved with a checkpoint so
/// that a resumed run extends the same series and tables.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct WriterState {
    /// Entries of `points.pvd`.
    pub points: Vec<PvdStep>,
    /// Entries of `grid.pvd`.
    pub grid: Vec<PvdStep>,
    /// `steps.csv`.
    pub steps: CsvTable,
    /// `iterations.csv`.
    pub iterations: CsvTable,
    /// Case tables by file name ([`RunWriter::case_row`]).
    pub tables: BTreeMap<String, CsvTable>,
}

/// What `summary.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct Summary<P: Serialize> {
    /// Case name.
    pub case: String,
    /// The MPM variant.
    pub variant: Variant,
    /// Number of material points.
    pub material_points: usize,
    /// Converged load steps.
    pub load_steps: usize,
    /// Load steps that were cut and retried.
    pub cut_steps: usize,
    /// Newton iterations over all steps.
    pub newton_iterations: usize,
    /// Solver wall time in seconds (file output excluded).
    pub wall_time_s: f64,
    /// Error against the case's reference, when it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<f64>,
    /// Case-specific results (e.g. `horizontal_extent`, `max_height`).
    #[serde(flatten)]
    pub results: serde_json::Map<String, serde_json::Value>,
    /// The parameters the case ran with.
    pub parameters: P,
}

/// What `summary.json` of an explicit run holds.
#[derive(Debug, Clone, Serialize)]
pub struct ExplicitSummary<P: Serialize> {
    /// Case name (`scene`).
    pub case: String,
    /// `explicit`.
    pub solver: String,
    /// Basis.
    pub basis: crate::variant::BasisKind,
    /// Velocity transfer.
    pub transfer: crate::variant::TransferKind,
    /// Its FLIP fraction α.
    pub alpha: f64,
    /// Dilatation treatment (`none` or `cell_averaged`).
    pub locking: crate::variant::LockingKind,
    /// Number of material points.
    pub material_points: usize,
    /// Time steps taken.
    pub time_steps: usize,
    /// Simulated time reached (s).
    pub end_time: f64,
    /// Outputs written, the initial state included.
    pub outputs: usize,
    /// Solver wall time in seconds (file output excluded).
    pub wall_time_s: f64,
    /// Wall time per stage of this session (`p2g`, `grid`, `g2p`), seconds.
    pub stage_times_s: serde_json::Value,
    /// Energies at t = 0 (`kinetic`, `strain`, `gravitational`,
    /// `external_work`, `friction_work`, `wall_work`, `absorbed_work`,
    /// `spring_energy`, `total`).
    pub initial_energies: serde_json::Value,
    /// Energies at the end.
    pub final_energies: serde_json::Value,
    /// (total(end) − total(0)) / the largest kinetic + strain energy of the
    /// outputs.
    pub energy_drift: f64,
    /// A run on several ranks: every new deal of the cells (`step`,
    /// `imbalance_before`, `imbalance_after`, `points_moved`); absent when
    /// there was none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rebalances: Vec<serde_json::Value>,
    /// A run on several ranks: per rank the largest and the mean over the
    /// ranks of this session's point work and grid seconds, halo and
    /// migration messages and bytes, collectives and points migrated
    /// (`mpm_dispatch::explicit::RanksReport`); absent on one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ranks: Option<serde_json::Value>,
    /// Scene results (bodies, probes, the PNG).
    #[serde(flatten)]
    pub results: serde_json::Map<String, serde_json::Value>,
    /// The parameters the run was started with.
    pub parameters: P,
}

/// Columns of `steps.csv`: reactions per component of the dimension, the
/// iteration-0 out-of-balance force as the Coombs et al. (2020) tables
/// print it (`StepReport::initial_unbalance`), the iterative linear
/// solver's iterations and the wall-clock seconds of the step and of each
/// stage (`StepReport::times`).
fn step_columns(dim: usize) -> Vec<&'static str> {
    let mut columns = vec!["step", "load_factor", "iterations"];
    columns.extend(["reaction_x", "reaction_y", "reaction_z"].iter().take(dim));
    columns.extend(["active_nodes", "free_dofs", "initial_unbalance"]);
    columns.extend([
        "linear_iterations",
        "seconds",
        "seconds_basis",
        "seconds_system",
        "seconds_material",
        "seconds_force",
        "seconds_tangent",
        "seconds_stiffness",
        "seconds_solve",
        "seconds_commit",
    ]);
    columns
}

impl<const D: usize, M: CellMesh<D>> RunWriter<D, M> {
    /// Creates `dir` (and parents) and the empty series.
    pub fn new(dir: &Path, grid: M) -> Result<Self, CasesError> {
        std::fs::create_dir_all(dir).map_err(|source| CasesError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            grid,
            points: PvdSeries::new(dir.join("points.pvd")),
            cells: PvdSeries::new(dir.join("grid.pvd")),
            steps: CsvTable::new(&step_columns(D))?,
            iterations: CsvTable::new(&["step", "iteration", "normalised_residual"])?,
            tables: BTreeMap::new(),
            options: VtuOptions::default(),
            pieces: 0,
        })
    }

    /// Sets what the VTU files hold and how often they are written.
    pub fn set_vtu_options(&mut self, options: VtuOptions) {
        self.options = options;
    }

    /// Writes the points' files as the parallel master of the pieces that
    /// `ranks` ranks write ([`write_piece`]).
    pub fn set_pieces(&mut self, ranks: usize) {
        self.pieces = ranks;
    }

    /// A writer that continues the series and tables of `state` (a resumed
    /// run); files of later steps are overwritten as the run proceeds.
    pub fn resume(dir: &Path, grid: M, state: WriterState) -> Result<Self, CasesError> {
        if state.steps.header() != step_columns(D) {
            return Err(CasesError::Checkpoint {
                path: dir.to_path_buf(),
                reason: "its steps table has other columns than this version writes".into(),
            });
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            grid,
            points: PvdSeries::with_steps(dir.join("points.pvd"), state.points),
            cells: PvdSeries::with_steps(dir.join("grid.pvd"), state.grid),
            steps: state.steps,
            iterations: state.iterations,
            tables: state.tables,
            options: VtuOptions::default(),
            pieces: 0,
        })
    }

    /// What has been written so far.
    pub fn state(&self) -> WriterState {
        WriterState {
            points: self.points.steps().to_vec(),
            grid: self.cells.steps().to_vec(),
            steps: self.steps.clone(),
            iterations: self.iterations.clone(),
            tables: self.tables.clone(),
        }
    }

    /// Appends a row to the case table `file` (e.g. the cantilever's
    /// `tip.csv`), creating it with `header` on first use, and rewrites the
    /// file atomically; the table is part of [`WriterState`].
    pub fn case_row(
        &mut self,
        file: &str,
        header: &[&str],
        row: &[CsvValue<'_>],
    ) -> Result<(), CasesError> {
        let table = match self.tables.entry(file.to_string()) {
            std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::btree_map::Entry::Vacant(e) => e.insert(CsvTable::new(header)?),
        };
        table.push_row(row)?;
        Ok(table.write(&self.dir.join(file))?)
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes the files of one converged step.
    pub fn step(
        &mut self,
        step: usize,
        report: &StepReport<D>,
        snap: &Snapshot,
    ) -> Result<(), CasesError> {
        if let Some(nodes) = &snap.mesh_nodes {
            self.grid
                .set_nodes(nodes)
                .map_err(|source| CasesError::Mesh { source })?;
        }
        if writes_vtu(self.options.every, step, report.lambda1) {
            self.write_vtu(step, report.lambda1, snap)?;
        }
        let mut row = vec![
            CsvValue::from(step),
            CsvValue::from(report.lambda1),
            CsvValue::from(report.iterations()),
        ];
        row.extend(report.reaction.iter().map(|r| CsvValue::from(*r)));
        row.extend([
            CsvValue::from(report.active_nodes),
            CsvValue::from(report.free_dofs),
            report
                .initial_unbalance
                .map_or(CsvValue::Str("".into()), CsvValue::from),
        ]);
        let t = &report.times;
        row.push(CsvValue::from(report.linear_iterations));
        row.extend(
            [
                t.total(),
                t.basis,
                t.system,
                t.material,
                t.force,
                t.tangent,
                t.stiffness,
                t.solve,
                t.commit,
            ]
            .map(CsvValue::from),
        );
        self.steps.push_row(&row)?;
        self.steps.write(&self.dir.join("steps.csv"))?;
        for (k, r) in report.residuals.iter().enumerate() {
            self.iterations.push_row(&[
                CsvValue::from(step),
                CsvValue::from(k),
                CsvValue::from(*r),
            ])?;
        }
        Ok(self.iterations.write(&self.dir.join("iterations.csv"))?)
    }

    /// Writes the VTU files (points and active grid) of output `index` of
    /// an explicit run at simulated time `time` (the series' time); no
    /// step tables.
    pub fn output(&mut self, index: usize, time: f64, snap: &Snapshot) -> Result<(), CasesError> {
        self.write_vtu(index, time, snap)
    }

    /// The VTU files (points and active grid) and the tangent of one step,
    /// at `time` in the series (the load factor, or the simulated time).
    /// On several ranks that write their own pieces ([`Self::set_pieces`])
    /// the points' file is the parallel master `points_NNNN.pvtu` of the
    /// pieces `points_NNNN_K.vtu`, each written by rank K
    /// ([`write_piece`]).
    fn write_vtu(&mut self, step: usize, time: f64, snap: &Snapshot) -> Result<(), CasesError> {
        let bounds = snap.domain_bounds.iter().copied().unzip();
        let fields = PieceFields {
            velocity: !snap.velocity.is_empty(),
            domains: !snap.domain_bounds.is_empty(),
        };
        let vtu = points_grid(
            &self.options,
            snap,
            fields,
            &self.options.constants,
            &bounds,
        )?;
        let path = if self.pieces > 1 {
            let path = self.dir.join(format!("points_{step:04}.pvtu"));
            let pieces: Vec<String> = (0..self.pieces).map(|k| piece_name(step, k)).collect();
            vtu.write_parallel(&path, &pieces)?;
            path
        } else {
            let path = self.dir.join(format!("points_{step:04}.vtu"));
            vtu.write(&path)?;
            path
        };
        self.points.push(time, &path)?;

        if let Some(k) = &snap.tangent {
            let path = self.dir.join(format!("tangent_{step:04}.mtx"));
            atomic_write_with(&path, |w| sprs::io::write_matrix_market_to_bufwrite(w, k))?;
        }
        let grid_path = self.dir.join(format!("grid_{step:04}.vtu"));
        self.write_active_grid(&grid_path, snap)?;
        Ok(self.cells.push(time, &grid_path)?)
    }

    /// The mesh cells holding material points.
    fn write_active_grid(&self, path: &Path, snap: &Snapshot) -> Result<(), CasesError> {
        let nodes = self.grid.vtk_nodes();
        let cells = self.grid.cells_holding(&snap.position);
        let mut vtu = UnstructuredGrid::new(&nodes)?;
        vtu.add_cells(M::CELL, &cells)?;
        Ok(vtu.write(path)?)
    }

    /// Writes `summary.json`.
    pub fn summary<P: Serialize>(&self, summary: &Summary<P>) -> Result<(), CasesError> {
        Ok(write_summary(&self.dir.join("summary.json"), summary)?)
    }

    /// Writes `summary.json` of an explicit run.
    pub fn explicit_summary<P: Serialize>(
        &self,
        summary: &ExplicitSummary<P>,
    ) -> Result<(), CasesError> {
        Ok(write_summary(&self.dir.join("summary.json"), summary)?)
    }
}

/// Whether an implicit run writes the VTU files of step `step`, which
/// reached `load_factor`: every `every` steps and the step that reaches 1.
pub fn writes_vtu(every: usize, step: usize, load_factor: f64) -> bool {
    (step + 1).is_multiple_of(every.max(1)) || load_factor >= 1.0 - 1e-12
}

/// The file name of rank `rank`'s piece of output `index`.
fn piece_name(index: usize, rank: usize) -> String {
    format!("points_{index:04}_{rank}.vtu")
}

/// Writes rank `rank`'s piece `points_NNNN_K.vtu` of output `index` into
/// `dir`: its own points `snap`, whose indices in the problem are `ids`,
/// with the fields of `options` (the per-point constants taken at `ids`).
/// Rank 0 writes the master that names every rank's piece
/// ([`RunWriter::set_pieces`]).
///
/// # Errors
/// Output errors (a non-finite value, the file not written).
pub fn write_piece(
    dir: &Path,
    options: &VtuOptions,
    (index, rank): (usize, usize),
    snap: &Snapshot,
    ids: &[usize],
    fields: PieceFields,
) -> Result<(), CasesError> {
    let constants: Vec<(String, Vec<f64>)> = options
        .constants
        .iter()
        .map(|(name, values)| {
            let mine = ids
                .iter()
                .map(|&id| values.get(id).copied().unwrap_or(f64::NAN));
            (name.clone(), mine.collect())
        })
        .collect();
    let bounds = snap.domain_bounds.iter().copied().unzip();
    let vtu = points_grid(options, snap, fields, &constants, &bounds)?;
    Ok(vtu.write(&dir.join(piece_name(index, rank)))?)
}

/// The material points of `snap` as vertices with the fields of
/// `options` (velocities and domains where `present` says): `constants`
/// one value per point of `snap`, `bounds` its domains' lower and upper
/// corners.
fn points_grid<'s>(
    options: &VtuOptions,
    snap: &'s Snapshot,
    present: PieceFields,
    constants: &'s [(String, Vec<f64>)],
    bounds: &'s (Vec<[f64; 3]>, Vec<[f64; 3]>),
) -> Result<UnstructuredGrid<'s>, CasesError> {
    let mut vtu = UnstructuredGrid::new(&snap.position)?;
    vtu.add_vertex_cells();
    let has = |f: Field| options.fields.contains(&f);
    if has(Field::Displacement) {
        vtu.point_data("displacement", Values::vectors(&snap.displacement))?;
    }
    if has(Field::Velocity) && present.velocity {
        vtu.point_data("velocity", Values::vectors(&snap.velocity))?;
    }
    if has(Field::Stress) {
        vtu.point_data("cauchy_stress", Values::tensors(&snap.sigma))?;
    }
    if has(Field::DeformationGradient) {
        vtu.point_data("deformation_gradient", Values::tensors(&snap.f))?;
    }
    if has(Field::Volume) {
        vtu.point_data("volume", Values::scalars(&snap.volume))?;
    }
    if has(Field::PlasticStrain) {
        vtu.point_data(
            "equivalent_plastic_strain",
            Values::scalars(&snap.plastic_strain),
        )?;
    }
    let (lower, upper) = bounds;
    if present.domains && has(Field::Domain) {
        vtu.point_data("domain_lower", Values::vectors(lower))?;
        vtu.point_data("domain_upper", Values::vectors(upper))?;
    }
    if has(Field::Body) {
        for (name, values) in constants {
            vtu.point_data(name, Values::scalars(values))?;
        }
    }
    Ok(vtu)
}
