//! Writes a run's results: VTU of the material points and of the active
//! grid per converged step with PVD series, CSV histories and
//! `summary.json`. Every file is written atomically, so an interrupted run
//! leaves valid files behind.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mpm_mesh::RegularGrid;
use mpm_solver::StepReport;
use serde::Serialize;

use crate::CasesError;
use crate::output::{
    CellType, CsvTable, CsvValue, PvdSeries, PvdStep, UnstructuredGrid, Values, write_summary,
};
use crate::run::Snapshot;
use crate::variant::Variant;

/// Output of one run in a directory.
#[derive(Debug)]
pub struct RunWriter {
    dir: PathBuf,
    grid: RegularGrid<2>,
    points: PvdSeries,
    cells: PvdSeries,
    steps: CsvTable,
    iterations: CsvTable,
    tables: BTreeMap<String, CsvTable>,
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

impl RunWriter {
    /// Creates `dir` (and parents) and the empty series.
    pub fn new(dir: &Path, grid: RegularGrid<2>) -> Result<Self, CasesError> {
        std::fs::create_dir_all(dir).map_err(|source| CasesError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            grid,
            points: PvdSeries::new(dir.join("points.pvd")),
            cells: PvdSeries::new(dir.join("grid.pvd")),
            steps: CsvTable::new(&[
                "step",
                "load_factor",
                "iterations",
                "reaction_x",
                "reaction_y",
                "active_nodes",
                "free_dofs",
            ])?,
            iterations: CsvTable::new(&["step", "iteration", "normalised_residual"])?,
            tables: BTreeMap::new(),
        })
    }

    /// A writer that continues the series and tables of `state` (a resumed
    /// run); files of later steps are overwritten as the run proceeds.
    pub fn resume(
        dir: &Path,
        grid: RegularGrid<2>,
        state: WriterState,
    ) -> Result<Self, CasesError> {
        if state.steps.header() != Self::new(dir, grid.clone())?.steps.header() {
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
        table.write(&self.dir.join(file))
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes the files of one converged step.
    pub fn step(
        &mut self,
        step: usize,
        report: &StepReport<2>,
        snap: &Snapshot,
    ) -> Result<(), CasesError> {
        let name = format!("points_{step:04}.vtu");
        let path = self.dir.join(&name);
        let mut vtu = UnstructuredGrid::new(&snap.position)?;
        vtu.add_vertex_cells();
        vtu.point_data("displacement", Values::vectors(&snap.displacement))?;
        vtu.point_data("cauchy_stress", Values::tensors(&snap.sigma))?;
        vtu.point_data("deformation_gradient", Values::tensors(&snap.f))?;
        vtu.point_data("volume", Values::scalars(&snap.volume))?;
        vtu.point_data(
            "equivalent_plastic_strain",
            Values::scalars(&snap.plastic_strain),
        )?;
        vtu.write(&path)?;
        self.points.push(report.lambda1, &path)?;

        let grid_path = self.dir.join(format!("grid_{step:04}.vtu"));
        self.write_active_grid(&grid_path, snap)?;
        self.cells.push(report.lambda1, &grid_path)?;

        self.steps.push_row(&[
            CsvValue::from(step),
            CsvValue::from(report.lambda1),
            CsvValue::from(report.iterations()),
            CsvValue::from(report.reaction[0]),
            CsvValue::from(report.reaction[1]),
            CsvValue::from(report.active_nodes),
            CsvValue::from(report.free_dofs),
        ])?;
        self.steps.write(&self.dir.join("steps.csv"))?;
        for (k, r) in report.residuals.iter().enumerate() {
            self.iterations.push_row(&[
                CsvValue::from(step),
                CsvValue::from(k),
                CsvValue::from(*r),
            ])?;
        }
        self.iterations.write(&self.dir.join("iterations.csv"))
    }

    /// The grid cells holding material points, as VTK quads.
    fn write_active_grid(&self, path: &Path, snap: &Snapshot) -> Result<(), CasesError> {
        let positions: Vec<nalgebra::SVector<f64, 2>> = snap
            .position
            .iter()
            .map(|x| nalgebra::SVector::<f64, 2>::new(x[0], x[1]))
            .collect();
        let nodes: Vec<[f64; 3]> = (0..self.grid.node_count())
            .map(|n| {
                let x = self.grid.node_position(n).unwrap_or_default();
                [x[0], x[1], 0.0]
            })
            .collect();
        let mut connectivity = Vec::new();
        let [nx, _] = self.grid.nodes_per_axis();
        for (i, j) in positions
            .iter()
            .filter_map(|x| self.grid.cell_containing(x).ok())
            .map(|c| (c[0], c[1]))
        {
            let base = j * nx + i;
            connectivity.extend_from_slice(&[base, base + 1, base + 1 + nx, base + nx]);
        }
        // One quad per cell (several points share a cell).
        let mut quads: Vec<[usize; 4]> = connectivity
            .chunks(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        quads.sort_unstable();
        quads.dedup();
        let flat: Vec<usize> = quads.iter().flatten().copied().collect();
        let mut vtu = UnstructuredGrid::new(&nodes)?;
        vtu.add_cells(CellType::Quad, &flat)?;
        vtu.write(path)
    }

    /// Writes `summary.json`.
    pub fn summary<P: Serialize>(&self, summary: &Summary<P>) -> Result<(), CasesError> {
        write_summary(&self.dir.join("summary.json"), summary)
    }
}
