//! Result files of a run: VTK grids and their time series for ParaView,
//! CSV tables, `summary.json` and a PNG picture of a 2D state.
//!
//! Every writer takes plain slices and names (no solver types), refuses
//! NaN and infinity with an error naming the array and index, and replaces
//! its file atomically through [`atomic_write`], so an interrupted run
//! leaves only complete files behind and can be resumed.

mod atomic;
pub mod csv;
mod error;
mod finite;
pub mod mesh_cells;
pub mod png;
pub mod pvd;
pub mod summary;
mod text;
pub mod vtk;

pub use atomic::{atomic_write, atomic_write_with, remove_temporaries};
pub use csv::{CsvTable, CsvValue};
pub use error::OutputError;
pub use mesh_cells::CellMesh;
pub use pvd::{PvdSeries, PvdStep};
pub use summary::{summary_json, write_summary};
pub use vtk::{CellType, UnstructuredGrid, Values};
