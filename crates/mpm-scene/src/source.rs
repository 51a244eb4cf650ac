//! Scene files: TOML documents deserialised into a scene type of the
//! caller's choosing, with command-line overrides.
//!
//! ```
//! use serde::Deserialize;
//! use mpm_scene::source::parse_scene;
//!
//! #[derive(Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct Material { #[serde(rename = "E")] e: f64, nu: f64 }
//!
//! #[derive(Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct Scene { h: f64, basis: String, material: Material }
//!
//! let text = "h = 0.5\nbasis = \"mpm\"\n[material]\nE = 1e6\nnu = 0.3\n";
//! let overrides = ["material.E=2e6".to_owned(), "basis=gimp".to_owned()];
//! let scene: Scene = parse_scene(text, "scene.toml", &overrides)?;
//! assert_eq!(scene.material.e, 2e6);
//! assert_eq!(scene.basis, "gimp");
//! # Ok::<(), mpm_scene::SceneError>(())
//! ```
//!
//! # Overrides
//! Each override is `key=value`. The key is a dotted path of bare keys
//! (`material.E`); tables on the path that do not exist are created. The
//! value is read as a TOML value if it is one (`1e6`, `true`, `[1, 2]`,
//! `{ E = 1e6, nu = 0.3 }`, `"quoted"`) and taken as a string otherwise
//! (`gimp`), so `basis=gimp` needs no shell-quoted quotes. In an array of
//! tables (`[[material]]`) an index addresses one table:
//! `material.1.youngs_modulus=2e7` sets the second material's modulus. Overrides are
//! applied in order to the parsed document before it is deserialised, so
//! the scene type's `#[serde(deny_unknown_fields)]` rejects an unknown
//! override key just as it rejects an unknown key in the file.
//!
//! # Errors
//! A problem in the file is reported as `origin:line:column: message` (1-based,
//! columns in characters); a problem caused by an override names the
//! override instead. NaN and infinite floats (`nan`, `inf`, or a literal too
//! large for `f64`) are refused wherever they appear.

use std::borrow::Cow;
use std::ops::Range;
use std::path::Path;

use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::SceneError;

/// Reads the TOML scene at `path`, applies `overrides` and deserialises the
/// result into `T`.
///
/// Errors name the file by `path` as given.
///
/// # Errors
/// [`SceneError::Io`] if the file cannot be read; otherwise as
/// [`parse_scene`].
pub fn load_scene<T: DeserializeOwned>(path: &Path, overrides: &[String]) -> Result<T, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_scene(&text, &path.display().to_string(), overrides)
}

/// Parses the TOML scene `text`, applies `overrides` and deserialises the
/// result into `T`. `origin` (usually the file name) prefixes error
/// messages.
///
/// # Errors
/// [`SceneError::MalformedOverride`] for an override without `=`, with an
/// empty key, key segment or value; [`SceneError::Scene`] for malformed TOML,
/// an unknown key, a wrong type or a non-finite float in `text`, with line
/// and column; [`SceneError::Override`] when an override cannot be applied
/// (its path crosses a non-table value) or is what makes the scene invalid;
/// [`SceneError::SceneUnlocated`] if the deserialiser gives no position.
pub fn parse_scene<T: DeserializeOwned>(
    text: &str,
    origin: &str,
    overrides: &[String],
) -> Result<T, SceneError> {
    parse_scene_located(text, origin, overrides).map(|(scene, _)| scene)
}

/// [`parse_scene`], also returning the [`SceneSource`] that turns the
/// spans of `toml::Spanned` fields of `T` into located errors (for checks
/// after deserialisation: a name that refers to nothing, a body outside
/// the mesh).
///
/// # Errors
/// As [`parse_scene`].
pub fn parse_scene_located<T: DeserializeOwned>(
    text: &str,
    origin: &str,
    overrides: &[String],
) -> Result<(T, SceneSource), SceneError> {
    let parsed: Vec<Override<'_>> = overrides
        .iter()
        .map(|o| Override::parse(o))
        .collect::<Result<_, _>>()?;
    let locate = SceneSource::new(text, origin, overrides);

    let mut root = DeTable::parse(text).map_err(|e| locate.error(e.span(), e.message()))?;
    if let Some(span) = first_non_finite_in_table(root.get_ref()) {
        return Err(locate.non_finite(span));
    }
    for (k, o) in parsed.iter().enumerate() {
        o.apply(root.get_mut(), locate.span_of(k))?;
    }
    // An error carrying the root table's span (e.g. a missing top-level key)
    // says nothing about where: it is reported without a position.
    let root_span = root.span();
    let scene = T::deserialize(toml::de::Deserializer::from(root)).map_err(|e| {
        let span = e.span().filter(|s| *s != root_span);
        locate.error(span, e.message())
    })?;
    Ok((scene, locate))
}

/// One `key=value` override, split and checked.
struct Override<'a> {
    text: &'a str,
    keys: Vec<&'a str>,
    value: &'a str,
}

impl<'a> Override<'a> {
    fn parse(text: &'a str) -> Result<Self, SceneError> {
        let malformed = |reason| SceneError::MalformedOverride {
            text: text.to_owned(),
            reason,
        };
        let (key, value) = text.split_once('=').ok_or_else(|| malformed("no `=`"))?;
        let (key, value) = (key.trim(), value.trim());
        if key.is_empty() {
            return Err(malformed("empty key"));
        }
        let keys: Vec<&str> = key.split('.').map(str::trim).collect();
        if keys.iter().any(|k| k.is_empty()) {
            return Err(malformed(
                "empty key segment (a leading, trailing or doubled `.`)",
            ));
        }
        if value.is_empty() {
            return Err(malformed(
                "empty value (write key=\"\" for an empty string)",
            ));
        }
        Ok(Self { text, keys, value })
    }

    fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError::Override {
            text: self.text.to_owned(),
            message: message.into(),
        }
    }

    /// The override's value: TOML if it parses as a TOML value, else a
    /// string; every span set to `span`, so that deserialisation errors in
    /// it are traced back to this override.
    fn value(&self, span: &Range<usize>) -> Result<Spanned<DeValue<'a>>, SceneError> {
        let value = match DeValue::parse(self.value) {
            Ok(v) => v,
            Err(_) => Spanned::new(0..0, DeValue::String(Cow::Borrowed(self.value))),
        };
        if first_non_finite(&value).is_some() {
            return Err(self.error("NaN and infinite values are not allowed in a scene"));
        }
        Ok(respan(value, span))
    }

    /// Inserts the value into `root` at the override's key path.
    fn apply(&self, root: &mut DeTable<'a>, span: Range<usize>) -> Result<(), SceneError> {
        let value = self.value(&span)?;
        let (last, parents) = self
            .keys
            .split_last()
            .ok_or_else(|| self.error("empty key"))?;
        let mut table = root;
        let mut depth = 0;
        while depth < parents.len() {
            let key = parents[depth];
            if !table.contains_key(key) {
                table.insert(
                    Spanned::new(span.clone(), Cow::Borrowed(key)),
                    Spanned::new(span.clone(), DeValue::Table(DeTable::new())),
                );
            }
            let path = |end: usize| self.keys[..=end].join(".");
            table = match table.get_mut(key).map(Spanned::get_mut) {
                Some(DeValue::Table(t)) => t,
                // `key.N.rest`: inside the N-th table of an array of tables
                // (`material.1.youngs_modulus`).
                Some(DeValue::Array(items)) => {
                    let count = items.len();
                    let index = parents.get(depth + 1).and_then(|k| k.parse::<usize>().ok());
                    let Some(index) = index else {
                        return Err(self.error(format!(
                            "`{}` is an array: address one of its {count} tables by index, e.g. `{}.0.{}`",
                            path(depth),
                            path(depth),
                            last
                        )));
                    };
                    depth += 1;
                    match items.get_mut(index).map(Spanned::get_mut) {
                        Some(DeValue::Table(t)) => t,
                        Some(other) => {
                            return Err(self.error(format!(
                                "`{}` is {}, not a table",
                                path(depth),
                                article(other.type_str())
                            )));
                        }
                        None => {
                            return Err(self.error(format!(
                                "`{}` has {count} entries (indices 0 to {}); there is no index {index}",
                                path(depth - 1),
                                count.saturating_sub(1)
                            )));
                        }
                    }
                }
                Some(other) => {
                    return Err(self.error(format!(
                        "`{}` is {}, not a table",
                        path(depth),
                        article(other.type_str())
                    )));
                }
                None => return Err(self.error("internal error: table just inserted is missing")),
            };
            depth += 1;
        }
        match table.get_mut(*last) {
            Some(existing) => *existing = value,
            None => {
                table.insert(Spanned::new(span, Cow::Borrowed(*last)), value);
            }
        }
        Ok(())
    }
}

/// `"an integer"`, `"a table"`.
fn article(type_name: &str) -> String {
    if type_name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {type_name}")
    } else {
        format!("a {type_name}")
    }
}

/// `value` with its own span and every nested span replaced by `span`.
fn respan<'a>(value: Spanned<DeValue<'a>>, span: &Range<usize>) -> Spanned<DeValue<'a>> {
    let inner = match value.into_inner() {
        DeValue::Array(items) => {
            DeValue::Array(items.into_iter().map(|v| respan(v, span)).collect())
        }
        DeValue::Table(table) => DeValue::Table(
            table
                .into_iter()
                .map(|(k, v)| (Spanned::new(span.clone(), k.into_inner()), respan(v, span)))
                .collect(),
        ),
        scalar => scalar,
    };
    Spanned::new(span.clone(), inner)
}

/// The span of the first NaN or infinite float in `value`.
fn first_non_finite(value: &Spanned<DeValue<'_>>) -> Option<Range<usize>> {
    match value.get_ref() {
        DeValue::Float(f) => {
            let digits: String = f.as_str().chars().filter(|&c| c != '_').collect();
            match digits.parse::<f64>() {
                Ok(x) if x.is_finite() => None,
                _ => Some(value.span()),
            }
        }
        DeValue::Array(items) => items.iter().find_map(first_non_finite),
        DeValue::Table(table) => first_non_finite_in_table(table),
        _ => None,
    }
}

fn first_non_finite_in_table(table: &DeTable<'_>) -> Option<Range<usize>> {
    table.values().find_map(first_non_finite)
}

/// Where a scene came from: its text and origin and the overrides applied
/// to it, which are given spans past the end of the text. Maps the byte
/// spans of the parsed document (`toml::Spanned` fields) to places — or,
/// for a scene written in Rust ([`Self::typed`]), to its origin alone.
#[derive(Debug, Clone, Default)]
pub struct SceneSource {
    text: String,
    origin: String,
    overrides: Vec<String>,
    /// Start of each override's virtual span.
    starts: Vec<usize>,
    /// No text: the scene was written in Rust ([`crate::typed`]).
    typed: bool,
}

impl SceneSource {
    fn new(text: &str, origin: &str, overrides: &[String]) -> Self {
        let mut starts = Vec::with_capacity(overrides.len());
        let mut next = text.len() + 1;
        for o in overrides {
            starts.push(next);
            next += o.len().max(1) + 1;
        }
        Self {
            text: text.to_owned(),
            origin: origin.to_owned(),
            overrides: overrides.to_vec(),
            starts,
            typed: false,
        }
    }

    /// The source of a scene written in Rust ([`crate::typed`]), named
    /// `origin` (e.g. "the column case's scene"): it has no file, so every
    /// error, whatever its span, is [`SceneError::SceneUnlocated`] —
    /// `origin: message`, no line and column of a file that does not
    /// exist.
    pub fn typed(origin: &str) -> Self {
        Self {
            origin: origin.to_owned(),
            typed: true,
            ..Self::default()
        }
    }

    /// The origin (file name) errors start with.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The virtual span of override `k`.
    fn span_of(&self, k: usize) -> Range<usize> {
        let start = self.starts[k];
        start..start + self.overrides[k].len().max(1)
    }

    /// An error at `span` of the parsed document: `origin:line:column:
    /// message` in the file, or naming the override the span belongs to;
    /// without a span, or for a [`Self::typed`] source, the origin only.
    pub fn error(&self, span: Option<Range<usize>>, message: &str) -> SceneError {
        let message = message.trim_end().to_owned();
        let Some(span) = span.filter(|_| !self.typed) else {
            return SceneError::SceneUnlocated {
                origin: self.origin.clone(),
                message,
            };
        };
        if span.start > self.text.len() {
            let k = self
                .starts
                .partition_point(|&s| s <= span.start)
                .saturating_sub(1);
            if let Some(o) = self.overrides.get(k) {
                return SceneError::Override {
                    text: o.clone(),
                    message,
                };
            }
        }
        let (line, column) = line_column(&self.text, span.start);
        SceneError::Scene {
            origin: self.origin.clone(),
            line,
            column,
            message,
        }
    }

    /// [`Self::error`] at the place of `value`.
    pub fn at<T>(&self, value: &Spanned<T>, message: impl AsRef<str>) -> SceneError {
        self.error(Some(value.span()), message.as_ref())
    }

    fn non_finite(&self, span: Range<usize>) -> SceneError {
        let literal = self.text.get(span.clone()).unwrap_or("").trim();
        self.error(
            Some(span),
            &format!("the float `{literal}` is not finite: NaN and infinite values are not allowed in a scene"),
        )
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
///
/// An offset past the end is clamped to the end; one inside a multi-byte
/// character is moved back to its start.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::{SceneSource, line_column};
    use crate::SceneError;

    /// A scene written in Rust has no file: an error at any span of it
    /// names the origin, without a line and column.
    #[test]
    fn a_typed_source_reports_errors_unlocated() {
        let source = SceneSource::typed("the column case's scene");
        for span in [Some(0..0), Some(12..20), None] {
            let e = source.error(span.clone(), "density must be positive\n");
            assert!(
                matches!(&e, SceneError::SceneUnlocated { origin, message }
                    if origin == "the column case's scene" && message == "density must be positive"),
                "{span:?}: {e:?}"
            );
            assert_eq!(
                e.to_string(),
                "the column case's scene: density must be positive"
            );
        }
        let at = source.at(&toml::Spanned::new(3..7, 1.0), "here");
        assert_eq!(at.to_string(), "the column case's scene: here");
        assert_eq!(source.origin(), "the column case's scene");
        // A text source of the same origin locates the same span.
        let text = SceneSource::new("a = 1\nb = 2\n", "s.toml", &[]);
        assert_eq!(text.error(Some(6..7), "m").to_string(), "s.toml:2:1: m");
    }

    #[test]
    fn line_column_is_one_based_in_characters() {
        let text = "a = 1\nbé = 2\n\nc";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 4), (1, 5));
        assert_eq!(line_column(text, 6), (2, 1));
        // 'é' is two bytes; the '=' after "bé " is the fourth character.
        assert_eq!(line_column(text, 10), (2, 4));
        // Inside 'é' moves back to its start.
        assert_eq!(line_column(text, 8), (2, 2));
        assert_eq!(line_column(text, text.len()), (4, 2));
        assert_eq!(line_column(text, 1000), (4, 2));
    }
}
