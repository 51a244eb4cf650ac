//! The `[mesh]` table: a regular grid with its padding, a box of
//! triangles or tetrahedra (uniform or rectilinear), an annulus of
//! triangles or a Gmsh file; each key checked at its place, and the keys
//! of the other kinds refused where they are.

use std::path::Path;

use mpm_mesh::{RegularGrid, SimplexMesh};
use nalgebra::SVector;
use toml::Spanned;

use super::{AXES, Check, MAX_ENTITIES, SceneMesh};
use crate::SceneError;
use crate::format::{MeshKind, MeshSpec, Scene, SolverSpec};
use crate::region::point;
use crate::source::SceneSource;
use crate::variant::Variant;

/// The background mesh of a scene and the box the scene lies in.
pub(super) struct BuiltMesh<const D: usize> {
    /// The mesh (a grid with its padding, or simplices).
    pub(super) mesh: SceneMesh<D>,
    /// Lower corner of the box (a grid's, without its padding).
    pub(super) origin: SVector<f64, D>,
    /// Upper corner of the box.
    pub(super) upper: SVector<f64, D>,
    /// Padding cells on every side (0 for simplices).
    pub(super) padding: usize,
    /// The patch (parent element) of every element of a simplex mesh split
    /// from quadratic parents, `None` otherwise.
    pub(super) patch_of_element: Option<Vec<usize>>,
    /// A simplex mesh's quality warnings, prefixed by `[mesh]: `.
    pub(super) warnings: Vec<String>,
}

impl<const D: usize> BuiltMesh<D> {
    /// What lies this close to the box's faces is on them: 1e-9 of its
    /// longest side.
    pub(super) fn tol(&self) -> f64 {
        1e-9 * (self.upper - self.origin).max()
    }

    /// A mesh with no warnings yet.
    fn new(
        mesh: SceneMesh<D>,
        origin: SVector<f64, D>,
        upper: SVector<f64, D>,
        padding: usize,
        patch_of_element: Option<Vec<usize>>,
    ) -> Self {
        Self {
            mesh,
            origin,
            upper,
            padding,
            patch_of_element,
            warnings: Vec::new(),
        }
    }

    /// The simplices `simplices` in their bounding box.
    fn bounded(simplices: SimplexMesh<D>, patch_of_element: Option<Vec<usize>>) -> Self {
        let b = *simplices.bounding_box();
        Self::new(
            SceneMesh::Simplex(Box::new(simplices)),
            b.lower,
            b.upper,
            0,
            patch_of_element,
        )
    }
}

/// The mesh of `scene`, with at least `basis_padding` cells of padding
/// on a grid; `explicit`: the scene runs the explicit solver (regular
/// grids only, which stay where they are); Gmsh files are relative to
/// `mesh_dir`.
///
/// # Errors
/// [`SceneError::Scene`] at the key that is wrong or does not apply to
/// the mesh's kind, [`SceneError::SceneUnlocated`] for a missing key.
pub(super) fn mesh<const D: usize>(
    scene: &Scene,
    variant: &Variant,
    explicit: bool,
    basis_padding: usize,
    mesh_dir: &Path,
    src: &SceneSource,
) -> Result<BuiltMesh<D>, SceneError> {
    let m = &scene.mesh;
    if explicit {
        explicit_grid(m, &scene.solver, src)?;
    }
    if m.kind != MeshKind::Annulus {
        refuse_first(
            src,
            [
                m.inner_radius.as_ref().map(Spanned::span),
                m.outer_radius.as_ref().map(Spanned::span),
                m.layers.as_ref().map(Spanned::span),
                m.ring_nodes.as_ref().map(Spanned::span),
                m.jitter.as_ref().map(Spanned::span),
                m.seed.as_ref().map(Spanned::span),
            ],
            "`inner_radius`, `outer_radius`, `layers`, `ring_nodes`, `jitter` and `seed` apply to kind = \"annulus\" meshes",
        )?;
    }
    let mut built = match m.kind {
        MeshKind::Annulus => annulus(m, variant, src)?,
        MeshKind::Grid => grid(m, basis_padding, variant, src)?,
        MeshKind::Gmsh => gmsh(m, variant, mesh_dir, src)?,
        MeshKind::Simplex => simplex_box(m, variant, src)?,
    };
    built.warnings = match &built.mesh {
        SceneMesh::Simplex(sm) => (sm.quality().warnings().into_iter())
            .map(|w| format!("[mesh]: {w}"))
            .collect(),
        SceneMesh::Grid(_) => Vec::new(),
    };
    Ok(built)
}

/// The explicit solver's rule: a regular grid that does not move.
fn explicit_grid(m: &MeshSpec, solver: &SolverSpec, src: &SceneSource) -> Result<(), SceneError> {
    if m.kind != MeshKind::Grid {
        return Err(src.at(
            &solver.kind,
            "kind = \"explicit\" runs on regular grids ([mesh] kind = \"grid\"); simplex, annulus and Gmsh meshes take the implicit solver",
        ));
    }
    if let Some(motion) = &m.motion {
        return Err(src.at(
            &motion.kind,
            "a moving mesh follows the implicit solver's load factor; the explicit solver's grid stays where it is (prescribe velocities with [[boundary]] kind = \"velocity\")",
        ));
    }
    Ok(())
}

/// `kind = "annulus"`: a ring of triangles (2D), its node sets those of
/// [`mpm_mesh::AnnulusMesh`] and its triangles the group `domain`.
fn annulus<const D: usize>(
    m: &MeshSpec,
    variant: &Variant,
    src: &SceneSource,
) -> Result<BuiltMesh<D>, SceneError> {
    let check = Check { src };
    refuse_first(
        src,
        grid_keys(m).into_iter().chain([
            m.file.as_ref().map(Spanned::span),
            m.dimension.as_ref().map(Spanned::span),
            m.patches.as_ref().map(Spanned::span),
            m.coordinates.as_ref().map(Spanned::span),
        ]),
        "an annulus mesh takes `inner_radius`, `outer_radius`, `layers`, `ring_nodes`, `jitter` and `seed`",
    )?;
    if D != 2 {
        return Err(src.error(None, "an annulus mesh is 2D"));
    }
    let (Some(ri), Some(ro), Some(layers), Some(ring)) =
        (&m.inner_radius, &m.outer_radius, &m.layers, &m.ring_nodes)
    else {
        return Err(src.error(
            None,
            "[mesh]: an annulus needs `inner_radius`, `outer_radius`, `layers` and `ring_nodes`",
        ));
    };
    let (a, b) = (*ri.get_ref(), *ro.get_ref());
    if !(a > 0.0 && b > a && b.is_finite()) {
        return Err(src.at(
            ri,
            format!("an annulus needs 0 < inner_radius < outer_radius, got {a} and {b}"),
        ));
    }
    let layers = check.at_least(layers, 1, "mesh `layers`")?;
    let ring = check.at_least(ring, 3, "mesh `ring_nodes`")?;
    if layers.saturating_add(1).saturating_mul(ring) > MAX_ENTITIES {
        return Err(src.error(
            None,
            &format!("the annulus would have more than {MAX_ENTITIES} nodes"),
        ));
    }
    let jitter = match &m.jitter {
        Some(j) if !(0.0..=mpm_mesh::AnnulusMesh::MAX_JITTER).contains(j.get_ref()) => {
            return Err(src.at(
                j,
                format!(
                    "`jitter` must lie in [0, {}]",
                    mpm_mesh::AnnulusMesh::MAX_JITTER
                ),
            ));
        }
        Some(j) => *j.get_ref(),
        None => 0.0,
    };
    let seed = m.seed.as_ref().map_or(1, |s| *s.get_ref());
    if let Err(reason) = variant.require_standard_mpm("an annulus mesh") {
        return Err(src.at(ri, reason));
    }
    let mesh_error = |e: mpm_mesh::MeshError| src.at(ri, format!("mesh: {e}"));
    let ring_mesh = mpm_mesh::AnnulusMesh::new(a, b, layers, ring)
        .with_jitter(jitter, seed)
        .simplex_mesh()
        .map_err(mesh_error)?;
    // The same mesh in the scene's dimension (which is 2).
    let nodes = ring_mesh
        .nodes()
        .iter()
        .map(|x| SVector::<f64, D>::from_fn(|i, _| x[i]))
        .collect();
    let mut simplices =
        SimplexMesh::<D>::new(nodes, ring_mesh.connectivity().to_vec()).map_err(mesh_error)?;
    for (name, ids) in ring_mesh.node_sets().iter() {
        simplices
            .sets_mut()
            .insert_nodes(name, ids.to_vec())
            .map_err(mesh_error)?;
    }
    // Its triangles form the group `domain`, as in the Gmsh
    // annulus files.
    let all = (0..simplices.element_count()).collect();
    simplices
        .sets_mut()
        .insert_elements("domain", all)
        .map_err(mesh_error)?;
    Ok(BuiltMesh::bounded(simplices, None))
}

/// `kind = "grid"`: a regular grid with its padding.
fn grid<const D: usize>(
    m: &MeshSpec,
    basis_padding: usize,
    variant: &Variant,
    src: &SceneSource,
) -> Result<BuiltMesh<D>, SceneError> {
    if let Some(f) = m.file.as_ref() {
        return Err(src.at(f, "`file` applies to kind = \"gmsh\" meshes"));
    }
    if let Some(d) = m.dimension.as_ref() {
        return Err(src.at(
            d,
            "`dimension` applies to kind = \"gmsh\" meshes (a grid's is the length of `origin`)",
        ));
    }
    if let Some(p) = m.patches.as_ref() {
        return Err(src.at(p, "`patches` applies to kind = \"simplex\" meshes"));
    }
    if let Some(c) = m.coordinates.as_ref() {
        return Err(src.at(
            c,
            "`coordinates` applies to kind = \"simplex\" meshes (a grid's cells are equal)",
        ));
    }
    let (Some(origin), Some(size)) = (&m.origin, &m.size) else {
        return Err(src.error(
            None,
            "[mesh]: a grid needs `origin`, `size` and `cells` or `spacing`",
        ));
    };
    let (grid, origin, upper, padding) =
        grid_mesh::<D>(m, origin, size, basis_padding, variant, src)?;
    Ok(BuiltMesh::new(
        SceneMesh::Grid(grid),
        origin,
        upper,
        padding,
        None,
    ))
}

/// `kind = "gmsh"`: the MSH file `file` (relative to `mesh_dir`), its
/// quadratic elements split into their linear children.
fn gmsh<const D: usize>(
    m: &MeshSpec,
    variant: &Variant,
    mesh_dir: &Path,
    src: &SceneSource,
) -> Result<BuiltMesh<D>, SceneError> {
    refuse_first(
        src,
        grid_keys(m),
        "`origin`, `size`, `cells`, `spacing` and `padding` apply to kind = \"grid\" meshes",
    )?;
    if let Some(p) = m.patches.as_ref() {
        return Err(src.at(p, "`patches` applies to kind = \"simplex\" meshes (quadratic Gmsh elements are always split into their linear children)"));
    }
    if let Some(c) = m.coordinates.as_ref() {
        return Err(src.at(c, "`coordinates` applies to kind = \"simplex\" meshes"));
    }
    let Some(file) = &m.file else {
        return Err(src.error(None, "[mesh]: a Gmsh mesh needs `file` and `dimension`"));
    };
    let path = mesh_dir.join(file.get_ref());
    let read = mpm_mesh::read_msh::<D>(&path)
        .map_err(|e| src.at(file, format!("{}: {e}", path.display())))?;
    let mut patch_of_element = None;
    let simplices = match read.elements {
        mpm_mesh::GmshElements::Linear(mesh) => mesh,
        mpm_mesh::GmshElements::Quadratic(q) => {
            let split = mpm_mesh::PatchMesh::from_parents(&q)
                .map_err(|e| src.at(file, format!("{}: {e}", path.display())))?;
            patch_of_element = Some(split.patch_of_element().to_vec());
            split.into_mesh()
        }
    };
    if let Err(reason) = variant.require_simplex("a Gmsh mesh", patch_of_element.is_some()) {
        return Err(src.at(file, reason));
    }
    Ok(BuiltMesh::bounded(simplices, patch_of_element))
}

/// `kind = "simplex"`: a box of triangles or tetrahedra, with `cells` or
/// `spacing` (uniform) or `coordinates` (rectilinear), split into
/// patches if asked.
fn simplex_box<const D: usize>(
    m: &MeshSpec,
    variant: &Variant,
    src: &SceneSource,
) -> Result<BuiltMesh<D>, SceneError> {
    refuse_first(
        src,
        [
            m.file.as_ref().map(Spanned::span),
            m.dimension.as_ref().map(Spanned::span),
            m.padding.as_ref().map(Spanned::span),
        ],
        "`file`, `dimension` and `padding` do not apply to kind = \"simplex\" meshes (a box of triangles or tetrahedra needs no padding)",
    )?;
    let (Some(origin), Some(size)) = (&m.origin, &m.size) else {
        return Err(src.error(
            None,
            "[mesh]: a simplex box needs `origin`, `size` and `cells` or `spacing`",
        ));
    };
    let patches = m.patches.as_ref().is_some_and(|p| *p.get_ref());
    if let Err(reason) = variant.require_simplex("a simplex mesh", patches) {
        return Err(src.at(origin, format!("[mesh] kind = \"simplex\": {reason}")));
    }
    let (origin_v, upper, cells, lines) = match &m.coordinates {
        None => {
            let (grid, origin_v, upper, _) = grid_mesh::<D>(m, origin, size, 0, variant, src)?;
            (origin_v, upper, grid.cells_per_axis(), None)
        }
        Some(c) => {
            let (origin_v, upper, lines) = coordinate_lines::<D>(m, c, origin, size, src)?;
            let cells = std::array::from_fn(|a| lines[a].len() - 1);
            (origin_v, upper, cells, Some(lines))
        }
    };
    // D! simplices per cell, each split into 2^D children with
    // patches: bounded as the nodes are, before any is built.
    let per_cell = (1..=D).product::<usize>() << if patches { D } else { 0 };
    let elements = cells.iter().try_fold(per_cell, |n, &c| n.checked_mul(c));
    if elements.is_none_or(|n| n > MAX_ENTITIES) {
        let at = (m.cells.as_ref().map(Spanned::span))
            .or_else(|| m.spacing.as_ref().map(Spanned::span))
            .or_else(|| m.coordinates.as_ref().map(Spanned::span))
            .unwrap_or_else(|| size.span());
        return Err(src.error(
            Some(at),
            &format!("the mesh would have more than {MAX_ENTITIES} elements"),
        ));
    }
    let mut patch_of_element = None;
    let boxed = mpm_mesh::BoxMesh::new(origin_v, upper, cells);
    let mut simplices = if patches {
        boxed
            .quadratic_mesh()
            .and_then(|q| mpm_mesh::PatchMesh::from_parents(&q))
            .map(|split| {
                patch_of_element = Some(split.patch_of_element().to_vec());
                split.into_mesh()
            })
    } else {
        boxed.simplex_mesh()
    }
    .map_err(|e| src.at(origin, format!("mesh: {e}")))?;
    if let (Some(lines), Some(c)) = (&lines, &m.coordinates) {
        let moved = simplices
            .nodes()
            .iter()
            .map(|x| rectilinear(x, &origin_v, &upper, lines))
            .collect();
        simplices
            .move_nodes(moved)
            .map_err(|e| src.at(c, format!("mesh: {e}")))?;
    }
    Ok(BuiltMesh::new(
        SceneMesh::Simplex(Box::new(simplices)),
        origin_v,
        upper,
        0,
        patch_of_element,
    ))
}

/// The regular grid of `[mesh]`: its cells (or spacing), padding and
/// origin; returns the grid, the unpadded box and the padding.
fn grid_mesh<const D: usize>(
    m: &MeshSpec,
    origin_spec: &Spanned<Vec<f64>>,
    size_spec: &Spanned<Vec<f64>>,
    basis_padding: usize,
    variant: &Variant,
    src: &SceneSource,
) -> Result<(RegularGrid<D>, SVector<f64, D>, SVector<f64, D>, usize), SceneError> {
    let origin = point::<D>(origin_spec, "mesh `origin`", src)?;
    let size = point::<D>(size_spec, "mesh `size`", src)?;
    if let Some(axis) = (0..D).find(|&i| size[i] <= 0.0) {
        return Err(src.at(
            size_spec,
            format!(
                "mesh `size` must be positive on every axis ({} is {})",
                AXES[axis], size[axis]
            ),
        ));
    }
    let cells: [usize; D] = match (&m.cells, &m.spacing) {
        (Some(c), None) => {
            if c.get_ref().len() != D {
                return Err(src.at(
                    c,
                    format!(
                        "mesh `cells` has {} entries; the scene is {D}D",
                        c.get_ref().len()
                    ),
                ));
            }
            if c.get_ref().contains(&0) {
                return Err(src.at(c, "mesh `cells` must be at least 1 on every axis"));
            }
            std::array::from_fn(|i| c.get_ref()[i])
        }
        (None, Some(h)) => {
            let h_v = point::<D>(h, "mesh `spacing`", src)?;
            let mut cells = [0usize; D];
            for i in 0..D {
                let n = size[i] / h_v[i];
                if !(h_v[i] > 0.0
                    && n.is_finite()
                    && n >= 0.5
                    && (n - n.round()).abs() <= 1e-9 * n.max(1.0))
                {
                    return Err(src.at(
                        h,
                        format!(
                            "mesh `spacing` {} must be positive and divide the size {} along {}",
                            h_v[i], size[i], AXES[i]
                        ),
                    ));
                }
                cells[i] = n.round() as usize;
            }
            cells
        }
        (Some(c), Some(_)) => {
            return Err(src.at(c, "give mesh `cells` or `spacing`, not both"));
        }
        (None, None) => {
            return Err(src.at(size_spec, "the mesh needs `cells` or `spacing`"));
        }
    };
    let padding = match &m.padding {
        Some(p) if *p.get_ref() < basis_padding => {
            return Err(src.at(
                p,
                format!(
                    "basis = {} needs {basis_padding} padding cell(s), got {}",
                    variant.basis,
                    p.get_ref()
                ),
            ));
        }
        Some(p) => *p.get_ref(),
        None => basis_padding,
    };
    // A padding that alone passes the limit is refused at its key before
    // `2 * padding` is formed: TOML integers reach u64::MAX, and from
    // 2^63 on the double wrapped (a grid without its padding, in release).
    if padding > MAX_ENTITIES {
        let at = m.padding.as_ref().map_or(size_spec.span(), Spanned::span);
        return Err(src.error(
            Some(at),
            &format!("the grid would have more than {MAX_ENTITIES} nodes"),
        ));
    }
    let spacing = SVector::<f64, D>::from_fn(|i, _| size[i] / cells[i] as f64);
    let padded: [usize; D] = std::array::from_fn(|i| cells[i].saturating_add(2 * padding));
    let nodes = padded
        .iter()
        .try_fold(1usize, |n, &c| n.checked_mul(c.saturating_add(1)));
    if nodes.is_none_or(|n| n > MAX_ENTITIES) {
        return Err(src.at(
            m.cells.as_ref().map_or(size_spec, |_| size_spec),
            format!("the grid would have more than {MAX_ENTITIES} nodes"),
        ));
    }
    let grid = RegularGrid::new(origin - spacing * padding as f64, spacing, padded)
        .map_err(|e| src.at(origin_spec, format!("mesh: {e}")))?;
    let upper = origin + size;
    Ok((grid, origin, upper, padding))
}

/// A rectilinear box: its lower and upper corners and its node rows.
type RectilinearBox<const D: usize> = (SVector<f64, D>, SVector<f64, D>, [Vec<f64>; D]);

/// The node rows of a rectilinear simplex box (`coordinates`): D strictly
/// increasing rows from `origin` to `origin + size`, given instead of
/// `cells` and `spacing`; with the box's corners.
fn coordinate_lines<const D: usize>(
    m: &MeshSpec,
    c: &Spanned<Vec<Vec<f64>>>,
    origin_spec: &Spanned<Vec<f64>>,
    size_spec: &Spanned<Vec<f64>>,
    src: &SceneSource,
) -> Result<RectilinearBox<D>, SceneError> {
    if m.cells.is_some() || m.spacing.is_some() {
        return Err(src.at(
            c,
            "give mesh `coordinates` or `cells`/`spacing`, not both (the rows set the cells)",
        ));
    }
    let origin = point::<D>(origin_spec, "mesh `origin`", src)?;
    let size = point::<D>(size_spec, "mesh `size`", src)?;
    let rows = c.get_ref();
    if rows.len() != D {
        return Err(src.at(
            c,
            format!(
                "mesh `coordinates` has {} rows; the scene is {D}D (one row of node coordinates per axis)",
                rows.len()
            ),
        ));
    }
    let mut nodes = 1usize;
    for (a, row) in rows.iter().enumerate() {
        let (lo, hi) = (origin[a], origin[a] + size[a]);
        let tol = 1e-9 * size[a].abs();
        let increasing = row.windows(2).all(|w| w[0] < w[1]);
        let ends = row.first().is_some_and(|x| (x - lo).abs() <= tol)
            && row.last().is_some_and(|x| (x - hi).abs() <= tol);
        if row.len() < 2 || !increasing || !ends || row.iter().any(|x| !x.is_finite()) {
            return Err(src.at(
                c,
                format!(
                    "mesh `coordinates` along {}: give at least two finite, strictly increasing values from the origin {lo} to origin + size {hi}",
                    AXES[a]
                ),
            ));
        }
        nodes = nodes.saturating_mul(2 * row.len() - 1);
    }
    if nodes > MAX_ENTITIES {
        return Err(src.at(
            c,
            format!("the mesh would have more than {MAX_ENTITIES} nodes"),
        ));
    }
    let lines = std::array::from_fn(|a| {
        let mut row = rows[a].clone();
        // The box's corners exactly, so that its faces stay the node sets.
        row[0] = origin[a];
        let last = row.len() - 1;
        row[last] = origin[a] + size[a];
        row
    });
    Ok((origin, origin + size, lines))
}

/// Maps a node of the uniform box `lower..upper` with `lines[a].len() - 1`
/// cells per axis to the rectilinear box of node rows `lines`: affinely
/// within every cell, so a cell's simplices (and the mid-edge nodes of
/// quadratic parents) map onto the same split of the new cell.
fn rectilinear<const D: usize>(
    x: &SVector<f64, D>,
    lower: &SVector<f64, D>,
    upper: &SVector<f64, D>,
    lines: &[Vec<f64>; D],
) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|a, _| {
        let row = &lines[a];
        let cells = row.len() - 1;
        let t = (x[a] - lower[a]) / (upper[a] - lower[a]) * cells as f64;
        let i = (t.floor().max(0.0) as usize).min(cells - 1);
        let f = t - i as f64;
        row[i] + f * (row[i + 1] - row[i])
    })
}

/// The places of the keys of a regular grid (`origin`, `size`, `cells`,
/// `spacing`, `padding`), in that order.
fn grid_keys(m: &MeshSpec) -> [Option<std::ops::Range<usize>>; 5] {
    [
        m.origin.as_ref().map(Spanned::span),
        m.size.as_ref().map(Spanned::span),
        m.cells.as_ref().map(Spanned::span),
        m.spacing.as_ref().map(Spanned::span),
        m.padding.as_ref().map(Spanned::span),
    ]
}

/// Refuses the scene at the first of `spans` that is present (a key given
/// where it does not apply) with `message`.
fn refuse_first(
    src: &SceneSource,
    spans: impl IntoIterator<Item = Option<std::ops::Range<usize>>>,
    message: &str,
) -> Result<(), SceneError> {
    match spans.into_iter().flatten().next() {
        Some(span) => Err(src.error(Some(span), message)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use crate::{Problem, SceneError};

    /// A 2 x 2 grid with `padding` on line 6, column 11.
    fn scene(padding: &str) -> String {
        format!(
            r#"[mesh]
origin = [0.0, 0.0]
size = [1.0, 1.0]
cells = [2, 2]
# `padding` is the only key the test varies.
padding = {padding}

[[material]]
name = "m"
model = "hencky"
youngs_modulus = 1.0e6
poisson_ratio = 0.0
density = 1.0

[[body]]
name = "b"
material = "m"
region = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 1.0] }} }}
points_per_cell = 2
"#
        )
    }

    fn build(text: &str, set: &[String]) -> Result<Problem<2>, SceneError> {
        let (scene, src) = crate::parse(text, "s.toml", set)?;
        Problem::<2>::build_in(
            &scene,
            &src,
            scene.solver.padding(),
            std::path::Path::new("."),
        )
    }

    /// TOML integers reach u64::MAX: a padding of 2^63 or more made
    /// `2 * padding` wrap (in release; a panic in debug), to a grid
    /// built without its padding (2^63) or with a padding of 1 each side
    /// (2^63 + 1) while `Problem::padding` said 2^63. Refused at the key,
    /// in the file and as an override.
    #[test]
    fn a_padding_whose_double_overflows_is_refused_at_the_key() {
        let huge = [
            "9223372036854775808",
            "9223372036854775809",
            "18446744073709551615",
            "9223372036854775807",
            "50000001",
        ];
        for p in huge {
            match build(&scene(p), &[]) {
                Err(SceneError::Scene {
                    line: 6,
                    column: 11,
                    message,
                    ..
                }) => assert!(
                    message.contains("the grid would have more than 50000000 nodes"),
                    "padding = {p}: {message}"
                ),
                other => panic!("padding = {p}: {:?}", other.map(|b| b.padding)),
            }
            match build(&scene("1"), &[format!("mesh.padding={p}")]) {
                Err(SceneError::Override { message, .. }) => assert!(
                    message.contains("the grid would have more than 50000000 nodes"),
                    "--set mesh.padding={p}: {message}"
                ),
                other => panic!("--set mesh.padding={p}: {:?}", other.map(|b| b.padding)),
            }
        }
        let built = build(&scene("3"), &[]).expect("a padding of 3 builds");
        assert_eq!(built.padding, 3);
        assert_eq!(built.mesh.node_count(), 9 * 9);
    }
}
