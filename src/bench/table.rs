//! Aligned text tables and the number formats every section prints.
//!
//! Numbers are printed at fixed precision; anything that is not a finite
//! number prints as `—`, so no `NaN` or `inf` ever reaches the output.

/// Column alignment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Align {
    Left,
    Right,
}

#[derive(Debug, Clone)]
enum Row {
    Cells(Vec<String>),
    /// Leading cells, then free text that does not widen the columns (an
    /// error message in place of the row's numbers).
    Message(Vec<String>, String),
}

/// A table with a header row; columns are as wide as their widest cell.
#[derive(Debug, Clone)]
pub(crate) struct Table {
    headers: Vec<(String, Align)>,
    rows: Vec<Row>,
}

/// Placeholder for a missing or non-finite number.
pub(crate) const MISSING: &str = "—";

fn width(s: &str) -> usize {
    s.chars().count()
}

impl Table {
    pub(crate) fn new(headers: &[(&str, Align)]) -> Table {
        Table {
            headers: headers.iter().map(|(h, a)| (h.to_string(), *a)).collect(),
            rows: Vec::new(),
        }
    }

    /// Add a row (missing trailing cells print as `—`).
    pub(crate) fn row(&mut self, cells: Vec<String>) {
        self.rows.push(Row::Cells(cells));
    }

    /// Add a row whose leading cells are followed by a message (e.g. the
    /// error that stopped this row).
    pub(crate) fn message(&mut self, lead: Vec<String>, text: impl Into<String>) {
        self.rows.push(Row::Message(lead, text.into()));
    }

    /// The table as text, each line indented by two spaces and ending in `\n`.
    pub(crate) fn render(&self) -> String {
        let n = self.headers.len();
        let mut widths: Vec<usize> = self.headers.iter().map(|(h, _)| width(h)).collect();
        for row in &self.rows {
            let cells = match row {
                Row::Cells(c) | Row::Message(c, _) => c,
            };
            for (w, c) in widths.iter_mut().zip(cells) {
                *w = (*w).max(width(c));
            }
        }
        let line = |cells: &[String], upto: usize| -> String {
            let mut s = String::from(" ");
            for (k, w) in widths.iter().enumerate().take(upto) {
                let c = cells.get(k).map(String::as_str).unwrap_or(MISSING);
                let pad = " ".repeat(w.saturating_sub(width(c)));
                s.push(' ');
                match self.headers[k].1 {
                    Align::Left => {
                        s.push_str(c);
                        s.push_str(&pad);
                    }
                    Align::Right => {
                        s.push_str(&pad);
                        s.push_str(c);
                    }
                }
                s.push(' ');
            }
            s
        };
        let mut out = String::new();
        let head: Vec<String> = self.headers.iter().map(|(h, _)| h.clone()).collect();
        out.push_str(line(&head, n).trim_end());
        out.push('\n');
        let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
        out.push_str(line(&rule, n).trim_end());
        out.push('\n');
        for row in &self.rows {
            match row {
                Row::Cells(c) => out.push_str(line(c, n).trim_end()),
                Row::Message(c, text) => {
                    let lead = line(c, c.len().min(n));
                    out.push_str(&lead);
                    out.push(' ');
                    out.push_str(text);
                }
            }
            out.push('\n');
        }
        out
    }
}

/// A duration in milliseconds at three significant digits (`0.0421`,
/// `4.21`, `42.1`, `421`).
pub(crate) fn ms(v: f64) -> String {
    if !v.is_finite() || v < 0.0 {
        return MISSING.into();
    }
    // Thresholds just below the decades, so rounding never adds a digit.
    if v >= 99.95 {
        format!("{v:.0}")
    } else if v >= 9.995 {
        format!("{v:.1}")
    } else if v >= 0.9995 {
        format!("{v:.2}")
    } else if v >= 0.09995 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    }
}

/// An error or other small positive quantity in scientific notation
/// (`3.2e-9`); exactly zero prints as `0`.
pub(crate) fn sci(v: f64) -> String {
    if !v.is_finite() {
        MISSING.into()
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// A ratio such as a speed-up (`12.3x`).
pub(crate) fn ratio(v: f64) -> String {
    if !v.is_finite() {
        MISSING.into()
    } else if v >= 100.0 {
        format!("{v:.0}x")
    } else {
        format!("{v:.1}x")
    }
}

/// A plain number with `digits` decimals.
pub(crate) fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        MISSING.into()
    }
}

/// One CSV field, quoted when it holds a comma, quote or newline.
pub(crate) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_align_and_messages_do_not_widen_them() {
        let mut t = Table::new(&[("scene", Align::Left), ("time [ms]", Align::Right)]);
        t.row(vec!["eggs".into(), ms(12.345)]);
        t.row(vec!["particle-polygon".into()]);
        t.message(
            vec!["mug".into()],
            "error: a very long message that must not widen the time column",
        );
        let text = t.render();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "  scene             time [ms]");
        assert_eq!(lines[1], "  ----------------  ---------");
        assert_eq!(lines[2], "  eggs                   12.3");
        assert_eq!(lines[3], "  particle-polygon          —");
        assert!(
            lines[4].starts_with("  mug               error: a very long"),
            "{}",
            lines[4]
        );
    }

    #[test]
    fn non_finite_numbers_print_as_a_dash() {
        for s in [
            ms(f64::NAN),
            sci(f64::INFINITY),
            ratio(f64::NAN),
            num(f64::NEG_INFINITY, 2),
            ms(-1.0),
        ] {
            assert_eq!(s, MISSING);
        }
        assert_eq!(sci(0.0), "0");
        assert_eq!(sci(3.21e-9), "3.2e-9");
        assert_eq!(ms(0.04212), "0.0421");
        assert_eq!(ms(421.2), "421");
        assert_eq!(ms(0.099_999), "0.100");
        assert_eq!(ms(9.999), "10.0");
        assert_eq!(ratio(12.34), "12.3x");
    }

    #[test]
    fn csv_fields_are_quoted_only_when_needed() {
        assert_eq!(csv_field("eggs"), "eggs");
        assert_eq!(
            csv_field("different events (9/51)"),
            "different events (9/51)"
        );
        assert_eq!(csv_field("a, \"b\""), "\"a, \"\"b\"\"\"");
    }
}
