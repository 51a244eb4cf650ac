//! `cargo xtask structure`: the two structural rules of the conventions
//! that a reviewer cannot see at a glance, checked over the workspace's
//! source (`src/` of every crate, tests and `#[cfg(test)]` modules left
//! out):
//!
//! - **long functions**: every `fn` whose body spans more than
//!   [`MAX_LINES`] lines;
//! - **import circles between files**: file A names an item of file B (a
//!   `use` or a path through `crate::`, `super::` or `self::`) and B,
//!   directly or through other files, names one of A's. Circles are the
//!   strongly connected components of that graph with more than one file.
//!
//! It reads the files as text with a small lexer (strings, characters and
//! comments skipped), not as Rust syntax, so it is an aid for review, not
//! a proof; what it reports is listed with file and line. Exit status 0;
//! `--deny` makes any finding an error (for CI once the tree is clean).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// Braces, named so that this file's own code holds none inside a
/// literal (a text-level reader counting braces would be misled by them).
const OPEN: char = '\x7b';
const CLOSE: char = '\x7d';
const OPEN_BYTE: u8 = OPEN as u8;
const CLOSE_BYTE: u8 = CLOSE as u8;

/// Longest function body allowed (lines from `fn` to its closing brace).
pub const MAX_LINES: usize = 150;

/// A function longer than [`MAX_LINES`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LongFunction {
    /// The file, relative to the workspace.
    pub file: String,
    /// The line of `fn`.
    pub line: usize,
    /// The function's name.
    pub name: String,
    /// Its length in lines.
    pub lines: usize,
}

/// Runs the check over the workspace at `root` and prints the findings.
pub fn run(root: &Path, deny: bool) -> Result<()> {
    let crates = crate_sources(root)?;
    let mut long = Vec::new();
    let mut circles = Vec::new();
    let mut files = 0;
    for (name, src) in &crates {
        let sources = rust_files(src)?;
        files += sources.len();
        let mut texts = BTreeMap::new();
        for file in &sources {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("reading {}", file.display()))?;
            let code = code_only(&text);
            let rel = file
                .strip_prefix(root)
                .unwrap_or(file)
                .display()
                .to_string();
            long.extend(long_functions(&code, &rel));
            texts.insert(module_path(src, file), (rel, code));
        }
        for circle in import_circles(&texts) {
            circles.push(format!("{name}: {}", circle.join(" → ")));
        }
    }
    long.sort_by_key(|f| std::cmp::Reverse(f.lines));
    println!(
        "{} files; {} functions over {MAX_LINES} lines; {} import circles",
        files,
        long.len(),
        circles.len()
    );
    for f in &long {
        println!("  {}:{} fn {} — {} lines", f.file, f.line, f.name, f.lines);
    }
    for c in &circles {
        println!("  circle: {c}");
    }
    if deny && (!long.is_empty() || !circles.is_empty()) {
        bail!("structure check failed");
    }
    Ok(())
}

/// Every workspace crate's name and `src` folder.
fn crate_sources(root: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut out = Vec::new();
    for parent in ["crates", "examples"] {
        let Ok(entries) = std::fs::read_dir(root.join(parent)) else {
            continue;
        };
        for entry in entries {
            let dir = entry?.path();
            if dir.join("src").is_dir() {
                let name = dir.file_name().map(|n| n.to_string_lossy().into_owned());
                out.push((name.unwrap_or_default(), dir.join("src")));
            }
        }
    }
    out.push(("xtask".into(), root.join("xtask/src")));
    out.sort();
    Ok(out)
}

/// The `.rs` files under `dir`, sorted.
fn rust_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).with_context(|| format!("listing {}", d.display()))? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The module path of `file` in the crate whose root folder is `src`:
/// `a/b.rs` and `a/b/mod.rs` are `a::b`, `lib.rs` and `main.rs` the root.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap_or(file);
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// `text` with comments, string and character literals blanked (newlines
/// kept) and `#[cfg(test)]` items removed, so that braces and paths are
/// code.
pub fn code_only(text: &str) -> String {
    let blanked = blank_literals(text);
    remove_test_items(&blanked)
}

/// Replaces every character of comments and literals by a space.
fn blank_literals(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let keep = |ch: char| if ch == '\n' { '\n' } else { ' ' };
    while i < c.len() {
        if c[i] == '/' && peek(&c, i + 1) == Some('/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '/' && peek(&c, i + 1) == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && peek(&c, i + 1) == Some('*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && peek(&c, i + 1) == Some('/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(keep(c[i]));
                    i += 1;
                }
            }
        } else if c[i] == 'r'
            && (peek(&c, i + 1) == Some('"') || peek(&c, i + 1) == Some('#'))
            && !ident_before(&c, i)
        {
            let hashes = (1..).take_while(|&k| peek(&c, i + k) == Some('#')).count();
            if peek(&c, i + 1 + hashes) != Some('"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            let end: String = std::iter::once('"')
                .chain(std::iter::repeat_n('#', hashes))
                .collect();
            out.push_str(&" ".repeat(2 + hashes));
            i += 2 + hashes;
            while i < c.len() && !c[i..].starts_with(&end.chars().collect::<Vec<_>>()) {
                out.push(keep(c[i]));
                i += 1;
            }
            out.push_str(&" ".repeat(end.len()));
            i += end.len();
        } else if c[i] == '"' {
            out.push(' ');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < c.len() {
                    out.push(keep(c[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{..}'), not a lifetime.
            let len = if peek(&c, i + 1) == Some('\\') {
                (2..12)
                    .find(|&k| peek(&c, i + k) == Some('\''))
                    .map(|k| k + 1)
            } else if peek(&c, i + 2) == Some('\'') {
                Some(3)
            } else {
                None
            };
            match len {
                Some(n) => {
                    out.push_str(&" ".repeat(n));
                    i += n;
                }
                None => {
                    out.push(c[i]);
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The character at `k`, if any.
fn peek(c: &[char], k: usize) -> Option<char> {
    c.get(k).copied()
}

/// Whether the character before `i` continues an identifier (so `r` is
/// part of a name, not a raw-string prefix).
fn ident_before(c: &[char], i: usize) -> bool {
    i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_')
}

/// Blanks the item after every `#[cfg(test)]` (up to its matching brace
/// or semicolon), keeping newlines.
fn remove_test_items(code: &str) -> String {
    let mut out: Vec<char> = code.chars().collect();
    let marker: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i + marker.len() <= out.len() {
        if out[i..i + marker.len()] != marker[..] {
            i += 1;
            continue;
        }
        let mut j = i + marker.len();
        let mut depth = 0usize;
        while j < out.len() {
            match out[j] {
                OPEN => depth += 1,
                CLOSE => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        break;
                    }
                }
                ';' if depth == 0 => break,
                _ => {}
            }
            j += 1;
        }
        for ch in &mut out[i..(j + 1).min(code.len())] {
            if *ch != '\n' {
                *ch = ' ';
            }
        }
        i = j + 1;
    }
    out.into_iter().collect()
}

/// The functions of `code` (from [`code_only`]) longer than [`MAX_LINES`].
pub fn long_functions(code: &str, file: &str) -> Vec<LongFunction> {
    let lines: Vec<&str> = code.lines().collect();
    let starts: Vec<usize> = std::iter::once(0)
        .chain(code.match_indices('\n').map(|(k, _)| k + 1))
        .collect();
    let line_of = |offset: usize| starts.partition_point(|&s| s <= offset);
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    for (at, _) in code.match_indices("fn ") {
        if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
            continue;
        }
        let name: String = code[at + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() {
            continue;
        }
        // The body: the first `{` before any `;` (a declaration without
        // body ends at `;`), then its matching `}`.
        let Some(open) = code[at..].find([OPEN, ';']).map(|k| at + k) else {
            continue;
        };
        if bytes[open] == b';' {
            continue;
        }
        let mut depth = 0usize;
        let mut close = open;
        for (k, b) in bytes[open..].iter().enumerate() {
            match *b {
                OPEN_BYTE => depth += 1,
                CLOSE_BYTE => {
                    depth -= 1;
                    if depth == 0 {
                        close = open + k;
                        break;
                    }
                }
                _ => {}
            }
        }
        let (first, last) = (line_of(at), line_of(close));
        let span = last + 1 - first;
        if span > MAX_LINES && first <= lines.len() {
            out.push(LongFunction {
                file: file.to_owned(),
                line: first,
                name,
                lines: span,
            });
        }
    }
    out
}

/// The module paths that `code` of the module `at` names: every path
/// through `crate::`, `super::` or `self::`, and the paths of `use`
/// trees, resolved to absolute module paths (the item's module and the
/// item itself; the caller keeps what is a file).
fn named_paths(at: &[String], code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for tree in use_trees(code) {
        for path in expand_use(&tree) {
            out.extend(resolve(at, &path));
        }
    }
    let bytes = code.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        for (k, _) in code.match_indices(start) {
            if k > 0
                && (bytes[k - 1].is_ascii_alphanumeric()
                    || bytes[k - 1] == b'_'
                    || bytes[k - 1] == b':')
            {
                continue;
            }
            let path: Vec<String> = code[k..]
                .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .next()
                .unwrap_or("")
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect();
            out.extend(resolve(at, &path));
        }
    }
    out
}

/// The text of every `use` declaration (after `use`, up to `;`).
fn use_trees(code: &str) -> Vec<String> {
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    for (k, _) in code.match_indices("use ") {
        if k > 0 && (bytes[k - 1].is_ascii_alphanumeric() || bytes[k - 1] == b'_') {
            continue;
        }
        if let Some(end) = code[k..].find(';') {
            out.push(
                code[k + 4..k + end]
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" "),
            );
        }
    }
    out
}

/// The paths of a `use` tree without whitespace: `a::{b, c::d}` gives
/// `a::b` and `a::c::d` (aliases and globs dropped).
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn go(prefix: &[String], tree: &str, out: &mut Vec<Vec<String>>) {
        // Split at the first `{`: the prefix path, then comma-separated
        // subtrees at depth one.
        let segments = |s: &str| -> Vec<String> {
            s.split("::")
                .map(str::trim)
                .filter(|s| !s.is_empty() && *s != "*")
                .map(str::to_owned)
                .collect()
        };
        let tree = tree.trim();
        match tree.find(OPEN) {
            None => {
                let mut p = prefix.to_vec();
                p.extend(segments(tree.split(" as ").next().unwrap_or(tree)));
                out.push(p);
            }
            Some(open) => {
                let mut p = prefix.to_vec();
                p.extend(segments(&tree[..open]));
                let inner = &tree[open + 1..tree.rfind(CLOSE).unwrap_or(tree.len())];
                let mut depth = 0;
                let mut from = 0;
                for (k, ch) in inner.char_indices() {
                    match ch {
                        OPEN => depth += 1,
                        CLOSE => depth -= 1,
                        ',' if depth == 0 => {
                            go(&p, &inner[from..k], out);
                            from = k + 1;
                        }
                        _ => {}
                    }
                }
                if from < inner.len() {
                    go(&p, &inner[from..], out);
                }
            }
        }
    }
    let mut out = Vec::new();
    go(&[], tree, &mut out);
    out
}

/// `path` named in module `at` as an absolute module path, if it starts
/// in this crate (`crate`, `super`, `self`).
fn resolve(at: &[String], path: &[String]) -> Option<Vec<String>> {
    let mut here: Vec<String> = match path.first().map(String::as_str) {
        Some("crate") => Vec::new(),
        Some("super") | Some("self") => at.to_vec(),
        _ => return None,
    };
    let mut rest = path;
    if rest.first().map(String::as_str) == Some("crate") {
        rest = &rest[1..];
    }
    while let Some(head) = rest.first() {
        match head.as_str() {
            "super" => {
                here.pop()?;
            }
            "self" => {}
            _ => break,
        }
        rest = &rest[1..];
    }
    here.extend(rest.iter().cloned());
    Some(here)
}

/// The circles among `files` (module path → (file name, code)): strongly
/// connected components of more than one file, each as its files' names.
fn import_circles(files: &BTreeMap<Vec<String>, (String, String)>) -> Vec<Vec<String>> {
    let modules: Vec<&Vec<String>> = files.keys().collect();
    let index: BTreeMap<&Vec<String>, usize> =
        modules.iter().enumerate().map(|(k, m)| (*m, k)).collect();
    // The file a path falls in: its longest prefix that is a file.
    let file_of = |path: &[String]| {
        (0..=path.len())
            .rev()
            .find_map(|n| index.get(&path[..n].to_vec()).copied())
    };
    let mut edges: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); modules.len()];
    for (k, m) in modules.iter().enumerate() {
        let (_, code) = &files[*m];
        for path in named_paths(m, code) {
            if let Some(to) = file_of(&path)
                && to != k
                // A module's own descendants are its implementation; a
                // parent (`mod.rs`) re-exporting or calling a child is
                // not a circle by itself, only with a way back.
                && !modules[to].starts_with(m)
            {
                edges[k].insert(to);
            }
        }
    }
    strongly_connected(&edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| c.into_iter().map(|k| files[modules[k]].0.clone()).collect())
        .collect()
}

/// Tarjan's strongly connected components of the graph `edges`.
fn strongly_connected(edges: &[BTreeSet<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        edges: &'a [BTreeSet<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State<'_>, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in s.edges[v].iter() {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            component.sort_unstable();
            s.out.push(component);
        }
    }
    let n = edges.len();
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(list: &[(&str, &str)]) -> BTreeMap<Vec<String>, (String, String)> {
        list.iter()
            .map(|(m, code)| {
                let path: Vec<String> = m
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned)
                    .collect();
                (path, (m.to_string(), code_only(code)))
            })
            .collect()
    }

    #[test]
    fn a_circle_through_three_files_is_found_and_a_chain_is_not() {
        let circle = files(&[
            ("", "mod a; mod b; mod c;"),
            ("a", "use crate::b::B; pub struct A;"),
            ("b", "pub struct B; fn f() -> crate::c::C { todo!() }"),
            ("c", "use super::a::{A, self as x};\npub struct C;"),
        ]);
        assert_eq!(import_circles(&circle), vec![vec!["a", "b", "c"]]);
        let chain = files(&[
            ("", "mod a; mod b;"),
            ("a", "use crate::b::B;"),
            ("b", "// use crate::a::A;\nlet s = \"crate::a::A\";"),
        ]);
        assert!(import_circles(&chain).is_empty());
    }

    #[test]
    fn a_parent_using_its_child_and_the_child_the_parent_is_a_circle_only_through_a_sibling() {
        let tree = files(&[
            ("m", "mod k; pub use k::K; pub struct P;"),
            ("m::k", "use super::P; pub struct K;"),
        ]);
        assert!(import_circles(&tree).is_empty());
    }

    #[test]
    fn long_functions_are_measured_from_fn_to_the_closing_brace() {
        let body = "    let x = \"}\";\n".repeat(MAX_LINES);
        let code = code_only(&format!(
            "fn short() {{}}\nfn long() {{\n{body}}}\n#[cfg(test)]\nmod tests {{\nfn also_long() {{\n{body}}}\n}}\n"
        ));
        let found = long_functions(&code, "x.rs");
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].name, "long");
        assert_eq!(found[0].line, 2);
        assert_eq!(found[0].lines, MAX_LINES + 2);
    }
}
