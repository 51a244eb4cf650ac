//! VTK XML unstructured grids (`.vtu`), the format ParaView opens for both
//! material points (vertex cells) and background grids (quads, hexahedra,
//! simplices).
//!
//! The grid is built from plain slices, so the solver needs no VTK types:
//!
//! ```no_run
//! # fn main() -> Result<(), mpm_output::OutputError> {
//! use mpm_output::vtk::{UnstructuredGrid, Values};
//! let x = [[0.0, 0.0], [1.0, 0.5]]; // 2D positions, written with z = 0
//! let p = [1.0e3, 2.0e3];
//! let mut grid = UnstructuredGrid::from_points(&x)?;
//! grid.add_vertex_cells();
//! grid.point_data("pressure", Values::scalars(&p))?;
//! grid.write(std::path::Path::new("points_0001.vtu"))?;
//! # Ok(())
//! # }
//! ```
//!
//! Files are ASCII (`format="ascii"`), with every `Float64` printed in the
//! shortest form that reads back to the same bits. Non-finite values are
//! refused when an array is added, so no file ever holds a NaN.

use std::borrow::Cow;
use std::io::{self, Write};
use std::path::Path;

use super::atomic::atomic_write_with;
use super::text::{check_finite, push_f64, xml_escape};
use crate::OutputError;

/// The VTK cell types the writer supports, with VTK's node ordering.
///
/// Node order follows VTK's documentation (`vtkCellType.h` and the figures
/// of the VTK file-format guide): for a quad, counter-clockwise; for a
/// hexahedron, the bottom face counter-clockwise then the top face; for the
/// quadratic simplices, the corners then the edge mid-nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellType {
    /// `VTK_VERTEX` (1): one point, used for material points.
    Vertex,
    /// `VTK_TRIANGLE` (5): three corners.
    Triangle,
    /// `VTK_QUAD` (9): four corners, counter-clockwise.
    Quad,
    /// `VTK_TETRA` (10): four corners.
    Tetra,
    /// `VTK_HEXAHEDRON` (12): eight corners.
    Hexahedron,
    /// `VTK_QUADRATIC_TRIANGLE` (22): three corners, then the mid-nodes of
    /// edges 0–1, 1–2, 2–0.
    QuadraticTriangle,
    /// `VTK_QUADRATIC_TETRA` (24): four corners, then the mid-nodes of edges
    /// 0–1, 1–2, 2–0, 0–3, 1–3, 2–3.
    QuadraticTetra,
}

impl CellType {
    /// VTK's numeric identifier, written into the `types` array.
    #[must_use]
    pub const fn vtk_id(self) -> u8 {
        match self {
            Self::Vertex => 1,
            Self::Triangle => 5,
            Self::Quad => 9,
            Self::Tetra => 10,
            Self::Hexahedron => 12,
            Self::QuadraticTriangle => 22,
            Self::QuadraticTetra => 24,
        }
    }

    /// Number of nodes of one cell.
    #[must_use]
    pub const fn n_nodes(self) -> usize {
        match self {
            Self::Vertex => 1,
            Self::Triangle => 3,
            Self::Quad | Self::Tetra => 4,
            Self::Hexahedron => 8,
            Self::QuadraticTriangle => 6,
            Self::QuadraticTetra => 10,
        }
    }

    /// VTK's name for the type, e.g. `"VTK_QUAD"`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Vertex => "VTK_VERTEX",
            Self::Triangle => "VTK_TRIANGLE",
            Self::Quad => "VTK_QUAD",
            Self::Tetra => "VTK_TETRA",
            Self::Hexahedron => "VTK_HEXAHEDRON",
            Self::QuadraticTriangle => "VTK_QUADRATIC_TRIANGLE",
            Self::QuadraticTetra => "VTK_QUADRATIC_TETRA",
        }
    }
}

/// The values of one data array: `Float64` tuples of a fixed number of
/// components, or `Int64` scalars. Borrowed from the caller where possible.
#[derive(Debug, Clone)]
pub enum Values<'a> {
    /// `Float64` values, `components` consecutive entries per point or cell.
    Float64 {
        /// The flattened values, tuple after tuple.
        data: Cow<'a, [f64]>,
        /// Components per tuple (1 scalar, 3 vector, 9 tensor).
        components: usize,
    },
    /// `Int64` scalars, one per point or cell.
    Int64(Cow<'a, [i64]>),
}

impl<'a> Values<'a> {
    /// One `f64` per point or cell.
    #[must_use]
    pub fn scalars(values: &'a [f64]) -> Self {
        Self::Float64 {
            data: Cow::Borrowed(values),
            components: 1,
        }
    }

    /// Three components per point or cell.
    #[must_use]
    pub fn vectors(values: &'a [[f64; 3]]) -> Self {
        Self::components(values)
    }

    /// A 3×3 tensor per point or cell, row-major
    /// (`[σxx, σxy, σxz, σyx, σyy, σyz, σzx, σzy, σzz]`), as ParaView expects.
    #[must_use]
    pub fn tensors(values: &'a [[f64; 9]]) -> Self {
        Self::components(values)
    }

    /// `N` components per point or cell.
    #[must_use]
    pub fn components<const N: usize>(values: &'a [[f64; N]]) -> Self {
        Self::Float64 {
            data: Cow::Borrowed(values.as_flattened()),
            components: N,
        }
    }

    /// `D`-dimensional vectors (`D` ≤ 3) padded with zeros to three
    /// components, e.g. 2D velocities.
    ///
    /// # Errors
    /// [`OutputError::InvalidDimension`] unless `1 <= D <= 3`.
    pub fn vectors_padded<const D: usize>(
        values: &[[f64; D]],
    ) -> Result<Values<'static>, OutputError> {
        let padded = pad_to_3d(values)?;
        Ok(Values::Float64 {
            data: Cow::Owned(padded.into_flattened()),
            components: 3,
        })
    }

    /// One `i64` per point or cell (ids, flags, counts).
    #[must_use]
    pub fn ints(values: &'a [i64]) -> Self {
        Self::Int64(Cow::Borrowed(values))
    }

    /// Number of tuples (points or cells covered).
    #[must_use]
    pub fn n_tuples(&self) -> usize {
        match self {
            Self::Float64 { data, components } => data.len() / (*components).max(1),
            Self::Int64(data) => data.len(),
        }
    }

    /// Components per tuple.
    #[must_use]
    pub fn n_components(&self) -> usize {
        match self {
            Self::Float64 { components, .. } => *components,
            Self::Int64(_) => 1,
        }
    }
}

/// Pads `D`-dimensional coordinates to three with zeros.
fn pad_to_3d<const D: usize>(values: &[[f64; D]]) -> Result<Vec<[f64; 3]>, OutputError> {
    if D == 0 || D > 3 {
        return Err(OutputError::InvalidDimension { dim: D });
    }
    Ok(values
        .iter()
        .map(|v| {
            let mut p = [0.0; 3];
            p[..D].copy_from_slice(v);
            p
        })
        .collect())
}

/// A named data array attached to points or cells.
#[derive(Debug, Clone)]
struct DataArray<'a> {
    name: String,
    values: Values<'a>,
}

/// An unstructured grid, built up and then written as one `.vtu` piece.
///
/// Point data are checked when added (the points are fixed at
/// construction); cell data are checked against the number of cells when
/// the grid is written, so cells and cell data may be added in any order.
#[derive(Debug, Clone)]
pub struct UnstructuredGrid<'a> {
    points: Cow<'a, [[f64; 3]]>,
    connectivity: Vec<usize>,
    /// End offset of each cell into `connectivity`.
    offsets: Vec<usize>,
    types: Vec<CellType>,
    point_data: Vec<DataArray<'a>>,
    cell_data: Vec<DataArray<'a>>,
}

impl<'a> UnstructuredGrid<'a> {
    /// A grid with the given 3D points (borrowed) and no cells.
    ///
    /// # Errors
    /// [`OutputError::NonFinite`] (array `"Points"`) if a coordinate is NaN
    /// or infinite.
    pub fn new(points: &'a [[f64; 3]]) -> Result<Self, OutputError> {
        Self::with_points(Cow::Borrowed(points))
    }

    /// A grid with `D`-dimensional points (`1 <= D <= 3`), padded with zero
    /// coordinates, and no cells.
    ///
    /// # Errors
    /// [`OutputError::InvalidDimension`] for `D` outside `1..=3`;
    /// [`OutputError::NonFinite`] as [`UnstructuredGrid::new`].
    pub fn from_points<const D: usize>(points: &[[f64; D]]) -> Result<Self, OutputError> {
        Self::with_points(Cow::Owned(pad_to_3d(points)?))
    }

    fn with_points(points: Cow<'a, [[f64; 3]]>) -> Result<Self, OutputError> {
        check_finite("Points", points.as_flattened(), 3)?;
        Ok(Self {
            points,
            connectivity: Vec::new(),
            offsets: Vec::new(),
            types: Vec::new(),
            point_data: Vec::new(),
            cell_data: Vec::new(),
        })
    }

    /// Number of points.
    #[must_use]
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Number of cells added so far.
    #[must_use]
    pub fn n_cells(&self) -> usize {
        self.types.len()
    }

    /// Adds one vertex cell per point, in point order: the usual way to show
    /// material points.
    pub fn add_vertex_cells(&mut self) -> &mut Self {
        let start = self.connectivity.len();
        self.connectivity.extend(0..self.points.len());
        self.offsets
            .extend((1..=self.points.len()).map(|k| start + k));
        self.types
            .extend(std::iter::repeat_n(CellType::Vertex, self.points.len()));
        self
    }

    /// Adds cells of one type from a flat connectivity list, `n_nodes()`
    /// point indices per cell in VTK order (see [`CellType`]).
    ///
    /// Nothing is added if the list is invalid.
    ///
    /// # Errors
    /// [`OutputError::CellNodeCount`] if the list's length is not a multiple
    /// of the type's node count; [`OutputError::NodeOutOfRange`] if an index
    /// is not a point (the cell index counts all cells of the grid).
    pub fn add_cells(
        &mut self,
        cell_type: CellType,
        connectivity: &[usize],
    ) -> Result<&mut Self, OutputError> {
        let n = cell_type.n_nodes();
        if !connectivity.len().is_multiple_of(n) {
            return Err(OutputError::CellNodeCount {
                cell_type: cell_type.name(),
                expected: n,
                found: connectivity.len(),
            });
        }
        if let Some(i) = connectivity
            .iter()
            .position(|&node| node >= self.points.len())
        {
            return Err(OutputError::NodeOutOfRange {
                cell: self.n_cells() + i / n,
                node: connectivity[i],
                n_points: self.points.len(),
            });
        }
        let start = self.connectivity.len();
        self.connectivity.extend_from_slice(connectivity);
        let n_new = connectivity.len() / n;
        self.offsets.extend((1..=n_new).map(|k| start + k * n));
        self.types.extend(std::iter::repeat_n(cell_type, n_new));
        Ok(self)
    }

    /// Adds a `Float64` or `Int64` array on the points.
    ///
    /// # Errors
    /// [`OutputError::InvalidName`] for an empty name or one already used on
    /// the points; [`OutputError::LengthMismatch`] unless there is one tuple
    /// per point (and the flat length is a multiple of the component count);
    /// [`OutputError::ZeroComponents`] for `Float64` data with zero
    /// components; [`OutputError::NonFinite`] naming the array and point
    /// index.
    pub fn point_data(&mut self, name: &str, values: Values<'a>) -> Result<&mut Self, OutputError> {
        check_array(name, &values, &self.point_data, "point data array")?;
        check_length(name, &values, self.points.len())?;
        self.point_data.push(DataArray {
            name: name.to_owned(),
            values,
        });
        Ok(self)
    }

    /// Adds a `Float64` or `Int64` array on the cells. Its length is checked
    /// against the number of cells when the grid is written.
    ///
    /// # Errors
    /// [`OutputError::InvalidName`] for an empty name or one already used on
    /// the cells; [`OutputError::LengthMismatch`] if the flat length is not a
    /// multiple of the component count; [`OutputError::ZeroComponents`] for
    /// `Float64` data with zero components; [`OutputError::NonFinite`] naming
    /// the array and cell index.
    pub fn cell_data(&mut self, name: &str, values: Values<'a>) -> Result<&mut Self, OutputError> {
        check_array(name, &values, &self.cell_data, "cell data array")?;
        self.cell_data.push(DataArray {
            name: name.to_owned(),
            values,
        });
        Ok(self)
    }

    /// Checks that every cell data array has one tuple per cell.
    ///
    /// # Errors
    /// [`OutputError::LengthMismatch`] naming the first array that does not.
    pub fn validate(&self) -> Result<(), OutputError> {
        for a in &self.cell_data {
            check_length(&a.name, &a.values, self.n_cells())?;
        }
        Ok(())
    }

    /// The complete `.vtu` document.
    ///
    /// # Errors
    /// As [`UnstructuredGrid::validate`].
    pub fn to_xml(&self) -> Result<String, OutputError> {
        self.validate()?;
        let mut buf = Vec::new();
        // Writing into a Vec cannot fail, and only `&str`s and numbers are
        // written, so the bytes are UTF-8.
        let _ = self.write_xml(&mut buf);
        Ok(String::from_utf8_lossy(&buf).into_owned())
    }

    /// Writes the grid to `path` (conventionally ending in `.vtu`),
    /// atomically: a reader sees the old file or the complete new one.
    ///
    /// # Errors
    /// As [`UnstructuredGrid::validate`], and [`OutputError::Io`] if the file
    /// cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        self.validate()?;
        atomic_write_with(path, |w| self.write_xml(w))
    }

    /// Writes to `path` (conventionally ending in `.pvtu`) the parallel
    /// master of `pieces` (their file names, relative to `path`'s folder):
    /// each piece a `.vtu` with the point and cell data arrays of this
    /// grid, which ParaView then opens as one dataset. Atomic, as
    /// [`UnstructuredGrid::write`].
    ///
    /// # Errors
    /// [`OutputError::Io`] if the file cannot be written.
    pub fn write_parallel(&self, path: &Path, pieces: &[String]) -> Result<(), OutputError> {
        atomic_write_with(path, |w| self.write_parallel_xml(w, pieces))
    }

    fn write_parallel_xml(&self, w: &mut dyn Write, pieces: &[String]) -> io::Result<()> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
        )?;
        writeln!(w, r#"  <PUnstructuredGrid GhostLevel="0">"#)?;
        for (tag, arrays) in [
            ("PPointData", &self.point_data),
            ("PCellData", &self.cell_data),
        ] {
            if arrays.is_empty() {
                continue;
            }
            writeln!(w, "    <{tag}>")?;
            for a in arrays {
                let (kind, components) = match &a.values {
                    Values::Float64 { components, .. } => ("Float64", *components),
                    Values::Int64(_) => ("Int64", 1),
                };
                writeln!(
                    w,
                    r#"      <PDataArray type="{kind}" Name="{}" NumberOfComponents="{components}"/>"#,
                    xml_escape(&a.name)
                )?;
            }
            writeln!(w, "    </{tag}>")?;
        }
        writeln!(w, "    <PPoints>")?;
        writeln!(
            w,
            r#"      <PDataArray type="Float64" Name="Points" NumberOfComponents="3"/>"#
        )?;
        writeln!(w, "    </PPoints>")?;
        for piece in pieces {
            writeln!(w, r#"    <Piece Source="{}"/>"#, xml_escape(piece))?;
        }
        writeln!(w, "  </PUnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")
    }

    fn write_xml(&self, w: &mut dyn Write) -> io::Result<()> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
        )?;
        writeln!(w, "  <UnstructuredGrid>")?;
        writeln!(
            w,
            r#"    <Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
            self.n_points(),
            self.n_cells()
        )?;
        write_data_section(w, "PointData", &self.point_data)?;
        write_data_section(w, "CellData", &self.cell_data)?;

        writeln!(w, "      <Points>")?;
        write_f64_array(w, "Points", self.points.as_flattened(), 3)?;
        writeln!(w, "      </Points>")?;

        writeln!(w, "      <Cells>")?;
        write_int_array(w, "connectivity", "Int64", &self.connectivity)?;
        write_int_array(w, "offsets", "Int64", &self.offsets)?;
        let types: Vec<u8> = self.types.iter().map(|t| t.vtk_id()).collect();
        write_int_array(w, "types", "UInt8", &types)?;
        writeln!(w, "      </Cells>")?;

        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </UnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")
    }
}

/// Checks an array's name and values, independent of what it is attached to.
fn check_array(
    name: &str,
    values: &Values<'_>,
    existing: &[DataArray<'_>],
    what: &'static str,
) -> Result<(), OutputError> {
    if name.trim().is_empty() {
        return Err(OutputError::InvalidName {
            what,
            name: name.to_owned(),
            reason: "must not be empty",
        });
    }
    if existing.iter().any(|a| a.name == name) {
        return Err(OutputError::InvalidName {
            what,
            name: name.to_owned(),
            reason: "is already used",
        });
    }
    match values {
        Values::Float64 { data, components } => {
            if *components == 0 {
                return Err(OutputError::ZeroComponents {
                    array: name.to_owned(),
                });
            }
            if !data.len().is_multiple_of(*components) {
                return Err(OutputError::LengthMismatch {
                    array: name.to_owned(),
                    expected: data.len().next_multiple_of(*components),
                    found: data.len(),
                });
            }
            check_finite(name, data, *components)
        }
        Values::Int64(_) => Ok(()),
    }
}

/// Checks that `values` holds one tuple per item.
fn check_length(name: &str, values: &Values<'_>, n: usize) -> Result<(), OutputError> {
    if values.n_tuples() == n {
        Ok(())
    } else {
        Err(OutputError::LengthMismatch {
            array: name.to_owned(),
            expected: n,
            found: values.n_tuples(),
        })
    }
}

fn write_data_section(w: &mut dyn Write, tag: &str, arrays: &[DataArray<'_>]) -> io::Result<()> {
    if arrays.is_empty() {
        return Ok(());
    }
    writeln!(w, "      <{tag}>")?;
    for a in arrays {
        match &a.values {
            Values::Float64 { data, components } => write_f64_array(w, &a.name, data, *components)?,
            Values::Int64(data) => write_int_array(w, &a.name, "Int64", data)?,
        }
    }
    writeln!(w, "      </{tag}>")
}

/// Values per line for scalar arrays; vectors and tensors get one tuple per
/// line.
const SCALARS_PER_LINE: usize = 6;

fn write_f64_array(
    w: &mut dyn Write,
    name: &str,
    data: &[f64],
    components: usize,
) -> io::Result<()> {
    writeln!(
        w,
        r#"        <DataArray type="Float64" Name="{}" NumberOfComponents="{components}" format="ascii">"#,
        xml_escape(name)
    )?;
    let per_line = if components == 1 {
        SCALARS_PER_LINE
    } else {
        components
    };
    let mut line = String::new();
    for chunk in data.chunks(per_line) {
        line.clear();
        line.push_str("          ");
        for (k, &x) in chunk.iter().enumerate() {
            if k > 0 {
                line.push(' ');
            }
            push_f64(&mut line, x);
        }
        writeln!(w, "{line}")?;
    }
    writeln!(w, "        </DataArray>")
}

fn write_int_array<T: std::fmt::Display>(
    w: &mut dyn Write,
    name: &str,
    vtk_type: &str,
    data: &[T],
) -> io::Result<()> {
    writeln!(
        w,
        r#"        <DataArray type="{vtk_type}" Name="{}" format="ascii">"#,
        xml_escape(name)
    )?;
    for chunk in data.chunks(16) {
        write!(w, "         ")?;
        for v in chunk {
            write!(w, " {v}")?;
        }
        writeln!(w)?;
    }
    writeln!(w, "        </DataArray>")
}
