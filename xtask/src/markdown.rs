//! Markdown tables and number formats for the reports.

use std::fmt::Write as _;

/// A Markdown table built row by row.
#[derive(Debug, Clone)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headings.
    pub fn new<S: AsRef<str>>(header: impl IntoIterator<Item = S>) -> Self {
        Self {
            header: header.into_iter().map(|s| s.as_ref().to_owned()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (missing cells are left empty, extra cells dropped).
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }

    /// The table as Markdown, ending with a blank line; a `|` inside a cell
    /// is escaped.
    pub fn render(&self) -> String {
        let n = self.header.len();
        let line = |cells: &[String]| {
            let mut s = String::from("|");
            for i in 0..n {
                let cell = cells.get(i).map_or("", String::as_str);
                let _ = write!(s, " {} |", cell.replace('|', "\\|"));
            }
            s.push('\n');
            s
        };
        let mut out = line(&self.header);
        out.push('|');
        out.push_str(&"---|".repeat(n));
        out.push('\n');
        for r in &self.rows {
            out.push_str(&line(r));
        }
        out.push('\n');
        out
    }
}

/// `x` in scientific notation with four significant digits: `2.440e-4`.
pub fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// The relative difference of `ours` from `paper` in per cent, signed:
/// `+0.03 %`.
pub fn rel_diff(ours: f64, paper: f64) -> String {
    format!("{:+.2} %", 100.0 * (ours - paper) / paper)
}

/// A wall time in milliseconds with a precision that suits its size.
pub fn millis(seconds: f64) -> String {
    let ms = 1e3 * seconds;
    if ms < 10.0 {
        format!("{ms:.2}")
    } else if ms < 100.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.0}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_and_formats() {
        let mut t = Table::new(["a", "b"]);
        t.row(vec!["|F|".into()]);
        assert_eq!(t.render(), "| a | b |\n|---|---|\n| \\|F\\| |  |\n\n");
        assert_eq!(sci(2.44e-4), "2.440e-4");
        assert_eq!(rel_diff(101.0, 100.0), "+1.00 %");
        assert_eq!(millis(0.0419), "41.9");
    }
}
