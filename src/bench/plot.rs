//! A log-log scatter plot drawn with braille dots (ratatui's `Canvas`
//! rendered into a `Buffer`) and printed as plain text: each series is a
//! braille polyline through its points, each point marked by the series'
//! letter, with decade ticks on both axes.

use crate::tui::buffer_text;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::symbols::Marker;
use ratatui::widgets::Widget;
use ratatui::widgets::canvas::{Canvas, Line};

/// One series of `(x, y)` points (both positive).
#[derive(Debug, Clone)]
pub(crate) struct Series {
    pub label: String,
    pub mark: char,
    pub points: Vec<(f64, f64)>,
}

fn decade_label(d: i32) -> String {
    format!("1e{d}")
}

/// Decade bounds `[lo, hi]` (log10) covering `values`, at least one decade wide.
fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v.log10());
        hi = hi.max(v.log10());
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let (lo, mut hi) = (lo.floor(), hi.ceil());
    if hi <= lo {
        hi = lo + 1.0;
    }
    Some((lo, hi))
}

/// Plot `series` on a `cols × rows` braille canvas with log-scaled axes.
/// Non-positive and non-finite points are left out.
pub(crate) fn loglog(
    series: &[Series],
    cols: u16,
    rows: u16,
    x_name: &str,
    y_name: &str,
) -> String {
    let clean: Vec<(char, Vec<(f64, f64)>)> = series
        .iter()
        .map(|s| {
            let mut p: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            (s.mark, p)
        })
        .collect();
    let all = || clean.iter().flat_map(|(_, p)| p.iter().copied());
    let (Some((x0, x1)), Some((y0, y1))) = (bounds(all().map(|p| p.0)), bounds(all().map(|p| p.1)))
    else {
        return "  (nothing to plot)\n".into();
    };
    let (cols, rows) = (cols.max(8), rows.max(4));
    let area = Rect::new(0, 0, cols, rows);
    let mut buf = Buffer::empty(area);
    Canvas::default()
        .marker(Marker::Braille)
        .x_bounds([x0, x1])
        .y_bounds([y0, y1])
        .paint(|ctx| {
            for (_, p) in &clean {
                for w in p.windows(2) {
                    ctx.draw(&Line::new(
                        w[0].0.log10(),
                        w[0].1.log10(),
                        w[1].0.log10(),
                        w[1].1.log10(),
                        Color::Reset,
                    ));
                }
            }
            for (mark, p) in &clean {
                for (x, y) in p {
                    ctx.print(x.log10(), y.log10(), mark.to_string());
                }
            }
        })
        .render(area, &mut buf);
    let text = buffer_text(&buf);
    let lines: Vec<&str> = text.split('\n').collect();
    // Y ticks: the row of each decade.
    let mut ticks = vec![String::new(); rows as usize];
    for d in (y0 as i32)..=(y1 as i32) {
        let r = ((y1 - d as f64) / (y1 - y0) * f64::from(rows - 1)).round() as usize;
        if r < ticks.len() {
            ticks[r] = decade_label(d);
        }
    }
    let margin = ticks
        .iter()
        .map(|t| t.len())
        .max()
        .unwrap_or(0)
        .max(y_name.len().min(8));
    let mut out = format!("  {y_name:>margin$}\n");
    for (r, tick) in ticks.iter().enumerate() {
        let body = lines.get(r).copied().unwrap_or("");
        let axis = if tick.is_empty() { '│' } else { '┤' };
        out.push_str(format!("  {tick:>margin$} {axis}{body}").trim_end());
        out.push('\n');
    }
    out.push_str(&format!(
        "  {:>margin$} └{}\n",
        "",
        "─".repeat(cols as usize)
    ));
    // X ticks under the axis, skipping labels that would overlap.
    let mut xl: Vec<char> = vec![' '; cols as usize + 8];
    let mut free_from = 0usize;
    for d in (x0 as i32)..=(x1 as i32) {
        let c = ((d as f64 - x0) / (x1 - x0) * f64::from(cols - 1)).round() as usize;
        let label = decade_label(d);
        let start = c.saturating_sub(label.len() / 2);
        if start < free_from || start + label.len() > xl.len() {
            continue;
        }
        for (k, ch) in label.chars().enumerate() {
            xl[start + k] = ch;
        }
        free_from = start + label.len() + 1;
    }
    let xl: String = xl.into_iter().collect();
    out.push_str(format!("  {:>margin$}  {}", "", xl).trim_end());
    out.push('\n');
    out.push_str(&format!("  {:>margin$}  {x_name}\n", ""));
    let legend: Vec<String> = series
        .iter()
        .map(|s| format!("{} {}", s.mark, s.label))
        .collect();
    out.push_str(&format!("  {:>margin$}  {}\n", "", legend.join("   ")));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_marked_and_axes_ticked_by_decade() {
        let s = vec![
            Series {
                label: "one".into(),
                mark: 'a',
                points: vec![(1e-3, 1e-9), (1e-1, 1e-5)],
            },
            Series {
                label: "two".into(),
                mark: 'b',
                points: vec![(1e-2, 1e-7), (0.0, 1.0), (f64::NAN, 1.0)],
            },
        ];
        let text = loglog(&s, 40, 10, "time [ms]", "error");
        assert!(text.contains('a') && text.contains('b'), "{text}");
        assert!(text.contains("1e-9") && text.contains("1e-5"), "{text}");
        assert!(text.contains("1e-3") && text.contains("1e-1"), "{text}");
        assert!(
            text.chars().any(|c| ('\u{2801}'..='\u{28ff}').contains(&c)),
            "braille dots: {text}"
        );
        assert!(text.contains("a one   b two"));
        assert!(!text.contains("NaN"));
    }

    #[test]
    fn nothing_to_plot() {
        let s = vec![Series {
            label: "x".into(),
            mark: 'a',
            points: vec![(0.0, 0.0)],
        }];
        assert_eq!(loglog(&s, 20, 5, "x", "y"), "  (nothing to plot)\n");
        assert_eq!(loglog(&[], 20, 5, "x", "y"), "  (nothing to plot)\n");
    }
}
