//! A reader for the subset of Gmsh's MSH 4.1 ASCII format that simplex
//! meshes need.
//!
//! Sections read: `$MeshFormat` (version 4.1, ASCII), `$PhysicalNames`,
//! `$Entities` (the physical groups of every point, curve, surface and
//! volume), `$Nodes` and `$Elements`; any other section is skipped.
//! Element types: three-node triangles (Gmsh type 2) and four-node
//! tetrahedra (4) make a [`SimplexMesh`]; six-node triangles (9) and
//! ten-node tetrahedra (11) make a [`QuadraticMesh`], usable as patch
//! parents ([`crate::PatchMesh`]). Elements of lower dimension — points
//! (15), lines (1, 8), triangles in 3D (2, 9) — only carry physical groups.
//!
//! Physical groups become named node sets (all nodes of the group's
//! elements) and, for groups of the mesh dimension, named element sets. A
//! group without a name in `$PhysicalNames` is named by its tag. Nodes keep
//! the file's order; [`GmshMesh::node_tags`] maps them back to Gmsh's
//! (possibly sparse) tags, [`GmshMesh::element_tags`] likewise for elements.
//! Elements of unknown orientation are reoriented (see
//! [`SimplexMesh::new_reoriented`]).
//!
//! Every error names the file line (1-based) where it was found.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::SVector;

use crate::{MeshError, NamedSets, QuadraticMesh, SimplexMesh};

/// The mesh of a Gmsh file: linear or quadratic simplices.
#[derive(Debug, Clone, PartialEq)]
pub enum GmshElements<const D: usize> {
    /// Three-node triangles or four-node tetrahedra.
    Linear(SimplexMesh<D>),
    /// Six-node triangles or ten-node tetrahedra (patch parents).
    Quadratic(QuadraticMesh<D>),
}

/// A mesh read from a Gmsh file, with the Gmsh tags of its nodes and
/// elements.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshMesh<const D: usize> {
    /// The mesh, with the physical groups as named sets.
    pub elements: GmshElements<D>,
    /// Gmsh tag of every node (index = node id of the mesh).
    pub node_tags: Vec<usize>,
    /// Gmsh tag of every element of the mesh dimension (index = element
    /// id).
    pub element_tags: Vec<usize>,
}

/// Read the MSH 4.1 ASCII file at `path` as a `D`-dimensional mesh.
///
/// # Errors
/// [`MeshError::GmshIo`] when the file cannot be read, and the errors of
/// [`parse_msh`].
pub fn read_msh<const D: usize>(path: impl AsRef<Path>) -> Result<GmshMesh<D>, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| MeshError::GmshIo {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    parse_msh(&bytes)
}

/// Parse the contents of an MSH 4.1 ASCII file as a `D`-dimensional mesh.
///
/// # Errors
/// [`MeshError::UnsupportedDimension`] unless `D` is 2 or 3; with the line
/// where it happened: [`MeshError::GmshFormat`] (no `$MeshFormat` first,
/// version other than 4.1), [`MeshError::GmshBinary`],
/// [`MeshError::GmshSyntax`] (a malformed or missing number or header, a
/// NaN or infinite coordinate),
/// [`MeshError::GmshTruncated`], [`MeshError::GmshCount`] (a declared count
/// that the data contradicts), [`MeshError::GmshMissingSection`],
/// [`MeshError::GmshDuplicateNode`], [`MeshError::GmshUnknownNode`],
/// [`MeshError::GmshUnsupportedElement`], [`MeshError::GmshMixedOrder`],
/// [`MeshError::GmshNoElements`], [`MeshError::GmshNotPlanar`] (2D only),
/// and [`MeshError::GmshElement`] for an element the mesh rejects.
pub fn parse_msh<const D: usize>(bytes: &[u8]) -> Result<GmshMesh<D>, MeshError> {
    crate::simplex::check_dimension(D)?;
    let mut lines = Lines::new(bytes);
    read_header(&mut lines)?;
    let mut file = File::<D>::default();
    while let Some((line, text)) = lines.next_nonblank()? {
        let Some(name) = text.strip_prefix('$') else {
            return Err(syntax(line, "a section header such as $Nodes", text));
        };
        match name {
            "PhysicalNames" => read_physical_names(&mut lines, &mut file)?,
            "Entities" => read_entities(&mut lines, &mut file)?,
            "Nodes" => read_nodes(&mut lines, &mut file)?,
            "Elements" => read_elements(&mut lines, &mut file, line)?,
            other => skip_section(&mut lines, other)?,
        }
    }
    file.finish(lines.count)
}

/// Everything read so far.
struct File<const D: usize> {
    names: HashMap<(usize, i64), String>,
    entity_groups: HashMap<(usize, i64), Vec<i64>>,
    nodes: Vec<SVector<f64, D>>,
    node_tags: Vec<usize>,
    node_index: HashMap<usize, usize>,
    have_nodes: bool,
    have_elements: bool,
    /// Nodes per element of the mesh dimension (`D + 1` or quadratic), set
    /// by the first such block.
    order: Option<usize>,
    connectivity: Vec<usize>,
    element_tags: Vec<usize>,
    element_lines: Vec<usize>,
    /// Nodes of the elements of every entity, for node sets.
    entity_nodes: HashMap<(usize, i64), Vec<usize>>,
    /// Mesh elements of every top-dimensional entity, for element sets.
    entity_elements: HashMap<i64, Vec<usize>>,
}

impl<const D: usize> Default for File<D> {
    fn default() -> Self {
        Self {
            names: HashMap::new(),
            entity_groups: HashMap::new(),
            nodes: Vec::new(),
            node_tags: Vec::new(),
            node_index: HashMap::new(),
            have_nodes: false,
            have_elements: false,
            order: None,
            connectivity: Vec::new(),
            element_tags: Vec::new(),
            element_lines: Vec::new(),
            entity_nodes: HashMap::new(),
            entity_elements: HashMap::new(),
        }
    }
}

impl<const D: usize> File<D> {
    fn finish(mut self, line_count: usize) -> Result<GmshMesh<D>, MeshError> {
        if !self.have_nodes {
            return Err(MeshError::GmshMissingSection {
                line: line_count,
                section: "Nodes",
            });
        }
        if !self.have_elements {
            return Err(MeshError::GmshMissingSection {
                line: line_count,
                section: "Elements",
            });
        }
        let Some(per_element) = self.order else {
            return Err(MeshError::GmshNoElements {
                line: line_count,
                dimension: D,
            });
        };
        let (node_sets, element_sets) = self.named_sets()?;
        let nodes = std::mem::take(&mut self.nodes);
        let connectivity = std::mem::take(&mut self.connectivity);
        let elements = if per_element == D + 1 {
            let mut mesh = SimplexMesh::new_reoriented(nodes, connectivity)
                .map_err(|e| self.locate_error(e))?;
            mesh.sets_mut().replace(node_sets, element_sets);
            GmshElements::Linear(mesh)
        } else {
            let mut mesh = QuadraticMesh::new_reoriented(nodes, connectivity)
                .map_err(|e| self.locate_error(e))?;
            mesh.sets_mut().replace(node_sets, element_sets);
            GmshElements::Quadratic(mesh)
        };
        Ok(GmshMesh {
            elements,
            node_tags: self.node_tags,
            element_tags: self.element_tags,
        })
    }

    /// Attach the line and Gmsh tag to an error naming a mesh element.
    fn locate_error(&self, error: MeshError) -> MeshError {
        let element = match &error {
            MeshError::RepeatedElementNode { element, .. }
            | MeshError::DegenerateElement { element, .. }
            | MeshError::InconsistentEdgeNode { element, .. } => *element,
            MeshError::NonManifoldFace { third, .. } => *third,
            _ => return error,
        };
        match (
            self.element_lines.get(element),
            self.element_tags.get(element),
        ) {
            (Some(&line), Some(&tag)) => MeshError::GmshElement {
                line,
                tag,
                source: Box::new(error),
            },
            _ => error,
        }
    }

    fn group_name(&self, dim: usize, group: i64) -> String {
        self.names
            .get(&(dim, group))
            .cloned()
            .unwrap_or_else(|| group.to_string())
    }

    fn named_sets(&self) -> Result<(NamedSets, NamedSets), MeshError> {
        let mut node_sets = NamedSets::default();
        let mut element_sets = NamedSets::default();
        let mut entities: Vec<_> = self.entity_nodes.keys().copied().collect();
        entities.sort_unstable();
        for key in entities {
            let Some(groups) = self.entity_groups.get(&key) else {
                continue;
            };
            for &group in groups {
                let name = self.group_name(key.0, group);
                if let Some(nodes) = self.entity_nodes.get(&key) {
                    node_sets.extend(name.clone(), nodes.iter().copied(), self.nodes.len())?;
                }
                if key.0 == D
                    && let Some(elements) = self.entity_elements.get(&key.1)
                {
                    element_sets.extend(name, elements.iter().copied(), self.element_tags.len())?;
                }
            }
        }
        Ok((node_sets, element_sets))
    }
}

/// The file's lines with 1-based numbers.
struct Lines<'a> {
    rest: std::slice::Split<'a, u8, fn(&u8) -> bool>,
    /// Number of the line last returned.
    current: usize,
    /// Number of lines in the file.
    count: usize,
}

impl<'a> Lines<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        let newline: fn(&u8) -> bool = |&b| b == b'\n';
        let trailing = usize::from(bytes.last() == Some(&b'\n'));
        let count = bytes.iter().filter(|&&b| b == b'\n').count() + 1 - trailing;
        Self {
            rest: bytes.split(newline),
            current: 0,
            count: if bytes.is_empty() { 0 } else { count },
        }
    }

    /// The next line (without `\r`), or `None` at the end of the file.
    fn next(&mut self) -> Result<Option<(usize, &'a str)>, MeshError> {
        if self.current >= self.count {
            return Ok(None);
        }
        let Some(raw) = self.rest.next() else {
            return Ok(None);
        };
        self.current += 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        std::str::from_utf8(raw)
            .map(|text| Some((self.current, text.trim())))
            .map_err(|_| syntax(self.current, "text", "non-UTF-8 bytes"))
    }

    fn next_nonblank(&mut self) -> Result<Option<(usize, &'a str)>, MeshError> {
        while let Some((line, text)) = self.next()? {
            if !text.is_empty() {
                return Ok(Some((line, text)));
            }
        }
        Ok(None)
    }

    /// The next data line of `section`: truncated at the end of the file or
    /// at a `$` line.
    fn data(&mut self, section: &str) -> Result<(usize, &'a str), MeshError> {
        match self.next_nonblank()? {
            Some((line, text)) if text.starts_with('$') => Err(MeshError::GmshTruncated {
                line,
                section: section.to_string(),
            }),
            Some(found) => Ok(found),
            None => Err(MeshError::GmshTruncated {
                line: self.count + 1,
                section: section.to_string(),
            }),
        }
    }

    /// The closing `$End<section>` line.
    fn end(&mut self, section: &str) -> Result<(), MeshError> {
        match self.next_nonblank()? {
            Some((_, text)) if text.strip_prefix("$End") == Some(section) => Ok(()),
            Some((line, text)) if text.starts_with('$') => Err(MeshError::GmshTruncated {
                line,
                section: section.to_string(),
            }),
            Some((line, text)) => Err(syntax(line, "the end of the section", text)),
            None => Err(MeshError::GmshTruncated {
                line: self.count + 1,
                section: section.to_string(),
            }),
        }
    }
}

fn syntax(line: usize, expected: &'static str, found: &str) -> MeshError {
    MeshError::GmshSyntax {
        line,
        expected,
        found: found.to_string(),
    }
}

/// Whitespace-separated numbers of one line.
struct Tokens<'a> {
    line: usize,
    text: &'a str,
    rest: std::str::SplitWhitespace<'a>,
}

impl<'a> Tokens<'a> {
    fn new((line, text): (usize, &'a str)) -> Self {
        Self {
            line,
            text,
            rest: text.split_whitespace(),
        }
    }

    fn next<T: std::str::FromStr>(&mut self, expected: &'static str) -> Result<T, MeshError> {
        self.rest
            .next()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| syntax(self.line, expected, self.text))
    }

    /// How many tokens are left.
    fn remaining(&self) -> usize {
        self.rest.clone().count()
    }
}

fn read_header(lines: &mut Lines<'_>) -> Result<(), MeshError> {
    let format_error = |line, found: &str| MeshError::GmshFormat {
        line,
        found: found.to_string(),
    };
    match lines.next_nonblank()? {
        Some((_, "$MeshFormat")) => {}
        Some((line, text)) => return Err(format_error(line, text)),
        None => return Err(format_error(1, "an empty file")),
    }
    let (line, text) = lines.data("MeshFormat")?;
    let mut tokens = Tokens::new((line, text));
    let version: String = tokens.next("the version 4.1")?;
    if version != "4.1" {
        return Err(format_error(line, text));
    }
    let file_type: u32 = tokens.next("the file type 0 (ASCII)")?;
    if file_type == 1 {
        return Err(MeshError::GmshBinary { line });
    }
    if file_type != 0 {
        return Err(syntax(line, "the file type 0 (ASCII)", text));
    }
    let _data_size: usize = tokens.next("the data size")?;
    lines.end("MeshFormat")
}

fn skip_section(lines: &mut Lines<'_>, name: &str) -> Result<(), MeshError> {
    while let Some((_, text)) = lines.next()? {
        if text.strip_prefix("$End") == Some(name) {
            return Ok(());
        }
    }
    Err(MeshError::GmshTruncated {
        line: lines.count + 1,
        section: name.to_string(),
    })
}

fn read_physical_names<const D: usize>(
    lines: &mut Lines<'_>,
    file: &mut File<D>,
) -> Result<(), MeshError> {
    const SECTION: &str = "PhysicalNames";
    let count: usize = Tokens::new(lines.data(SECTION)?).next("the number of physical names")?;
    for _ in 0..count {
        let (line, text) = lines.data(SECTION)?;
        let mut tokens = Tokens::new((line, text));
        let dim: usize = tokens.next("a dimension")?;
        let tag: i64 = tokens.next("a physical tag")?;
        let (Some(open), Some(close)) = (text.find('"'), text.rfind('"')) else {
            return Err(syntax(line, "a quoted name", text));
        };
        if close <= open {
            return Err(syntax(line, "a quoted name", text));
        }
        file.names
            .insert((dim, tag), text[open + 1..close].to_string());
    }
    lines.end(SECTION)
}

fn read_entities<const D: usize>(
    lines: &mut Lines<'_>,
    file: &mut File<D>,
) -> Result<(), MeshError> {
    const SECTION: &str = "Entities";
    let mut header = Tokens::new(lines.data(SECTION)?);
    let mut counts = [0usize; 4];
    for count in &mut counts {
        *count = header.next("the number of points, curves, surfaces and volumes")?;
    }
    for (dim, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            let mut tokens = Tokens::new(lines.data(SECTION)?);
            let tag: i64 = tokens.next("an entity tag")?;
            // Points have x y z, the others a bounding box.
            let coordinates = if dim == 0 { 3 } else { 6 };
            for _ in 0..coordinates {
                let _: f64 = tokens.next("a coordinate")?;
            }
            let groups: usize = tokens.next("the number of physical tags")?;
            let tags = (0..groups)
                .map(|_| tokens.next("a physical tag"))
                .collect::<Result<Vec<i64>, _>>()?;
            if !tags.is_empty() {
                file.entity_groups.insert((dim, tag), tags);
            }
        }
    }
    lines.end(SECTION)
}

fn read_nodes<const D: usize>(lines: &mut Lines<'_>, file: &mut File<D>) -> Result<(), MeshError> {
    const SECTION: &str = "Nodes";
    let (header_line, header_text) = lines.data(SECTION)?;
    let mut header = Tokens::new((header_line, header_text));
    let blocks: usize = header.next("the number of entity blocks")?;
    let declared: usize = header.next("the number of nodes")?;
    let mut found = 0;
    for _ in 0..blocks {
        let mut block = Tokens::new(lines.data(SECTION)?);
        let _dim: usize = block.next("an entity dimension")?;
        let _entity: i64 = block.next("an entity tag")?;
        let parametric: usize = block.next("the parametric flag")?;
        let count: usize = block.next("the number of nodes in the block")?;
        for _ in 0..count {
            let (line, text) = lines.data(SECTION)?;
            let mut tokens = Tokens::new((line, text));
            let tag: usize = tokens.next("a node tag")?;
            if tokens.remaining() != 0 {
                return Err(syntax(line, "a node tag", text));
            }
            let index = file.node_tags.len();
            if file.node_index.insert(tag, index).is_some() {
                return Err(MeshError::GmshDuplicateNode { line, tag });
            }
            file.node_tags.push(tag);
        }
        for _ in 0..count {
            let (line, text) = lines.data(SECTION)?;
            let mut tokens = Tokens::new((line, text));
            let xyz: [f64; 3] = [
                tokens.next("node coordinates x y z")?,
                tokens.next("node coordinates x y z")?,
                tokens.next("node coordinates x y z")?,
            ];
            if parametric == 0 && tokens.remaining() != 0 {
                return Err(syntax(line, "node coordinates x y z", text));
            }
            if xyz.iter().any(|c| !c.is_finite()) {
                return Err(syntax(line, "finite node coordinates x y z", text));
            }
            if D == 2 && xyz[2] != 0.0 {
                return Err(MeshError::GmshNotPlanar { line, z: xyz[2] });
            }
            file.nodes.push(SVector::from_fn(|i, _| xyz[i]));
        }
        found += count;
    }
    if found != declared {
        return Err(MeshError::GmshCount {
            line: header_line,
            what: "the number of nodes",
            expected: declared,
            found,
        });
    }
    file.have_nodes = true;
    lines.end(SECTION)
}

/// Dimension and node count of the supported Gmsh element types.
fn element_type(kind: usize) -> Option<(usize, usize)> {
    match kind {
        15 => Some((0, 1)),
        1 => Some((1, 2)),
        8 => Some((1, 3)),
        2 => Some((2, 3)),
        9 => Some((2, 6)),
        4 => Some((3, 4)),
        11 => Some((3, 10)),
        _ => None,
    }
}

fn read_elements<const D: usize>(
    lines: &mut Lines<'_>,
    file: &mut File<D>,
    section_line: usize,
) -> Result<(), MeshError> {
    const SECTION: &str = "Elements";
    if !file.have_nodes {
        return Err(MeshError::GmshMissingSection {
            line: section_line,
            section: "Nodes",
        });
    }
    let (header_line, header_text) = lines.data(SECTION)?;
    let mut header = Tokens::new((header_line, header_text));
    let blocks: usize = header.next("the number of entity blocks")?;
    let declared: usize = header.next("the number of elements")?;
    let mut found = 0;
    for _ in 0..blocks {
        let (block_line, block_text) = lines.data(SECTION)?;
        let mut block = Tokens::new((block_line, block_text));
        let dim: usize = block.next("an entity dimension")?;
        let entity: i64 = block.next("an entity tag")?;
        let kind: usize = block.next("an element type")?;
        let count: usize = block.next("the number of elements in the block")?;
        let Some((kind_dim, per_element)) = element_type(kind).filter(|&(d, _)| d <= D) else {
            return Err(MeshError::GmshUnsupportedElement {
                line: block_line,
                element_type: kind,
            });
        };
        if kind_dim != dim {
            return Err(syntax(
                block_line,
                "an element type of the entity's dimension",
                block_text,
            ));
        }
        let top = dim == D;
        if top {
            match file.order {
                None => file.order = Some(per_element),
                Some(n) if n != per_element => {
                    return Err(MeshError::GmshMixedOrder {
                        line: block_line,
                        element_type: kind,
                    });
                }
                Some(_) => {}
            }
        }
        let mut set_nodes = Vec::new();
        for _ in 0..count {
            let (line, text) = lines.data(SECTION)?;
            let mut tokens = Tokens::new((line, text));
            let tag: usize = tokens.next("an element tag")?;
            let given = tokens.remaining();
            if given != per_element {
                return Err(MeshError::GmshCount {
                    line,
                    what: "the number of nodes of the element type",
                    expected: per_element,
                    found: given,
                });
            }
            for _ in 0..per_element {
                let node_tag: usize = tokens.next("a node tag")?;
                let &index = file
                    .node_index
                    .get(&node_tag)
                    .ok_or(MeshError::GmshUnknownNode {
                        line,
                        tag: node_tag,
                    })?;
                set_nodes.push(index);
                if top {
                    file.connectivity.push(index);
                }
            }
            if top {
                file.entity_elements
                    .entry(entity)
                    .or_default()
                    .push(file.element_tags.len());
                file.element_tags.push(tag);
                file.element_lines.push(line);
            }
        }
        file.entity_nodes
            .entry((dim, entity))
            .or_default()
            .extend(set_nodes);
        found += count;
    }
    if found != declared {
        return Err(MeshError::GmshCount {
            line: header_line,
            what: "the number of elements",
            expected: declared,
            found,
        });
    }
    file.have_elements = true;
    lines.end(SECTION)
}
