//! The `:accuracy` popup: a row per measured setting (the current one
//! marked `●`, the chosen one `▸`, the Pareto-optimal ones highlighted and
//! marked `front`), its final-state and Jacobian errors against the
//! reference and its time per update, in the units and precision of
//! `nudge bench --only work-precision`.

use super::wrap;
use crate::bench::accuracy::Error;
use crate::scene::{Accuracy, Method};
use crate::tui::app::Measurements;
use crate::tui::format::{NOT_A_NUMBER, ms, num, truncate};
use crate::tui::theme::Theme;
use ratatui::text::Line;

/// The popup's lines for a popup `width` columns wide.
pub fn lines(m: &Measurements, theme: Theme, width: usize) -> Vec<Line<'static>> {
    let mut out: Vec<Line<'static>> = wrap(
        &format!(
            "errors against {}: final state, and Jacobian at t={} s; update: a drag at t={} s",
            m.reference,
            num(m.t_eval, 7),
            num(m.t_drag, 7)
        ),
        width,
    )
    .into_iter()
    .map(Line::raw)
    .collect();
    if m.stale {
        out.extend(
            wrap(
                "measured on the scene as it was before the last edit: A measures again",
                width,
            )
            .into_iter()
            .map(|l| Line::styled(l, theme.changed())),
        );
    }
    out.push(Line::raw(""));
    out.push(Line::styled(
        truncate(
            &format!(
                "   {:<6} {:<9} {:>6} {:>10} {:>10} {:>9}",
                "method", "setting", "root", "state err", "J err", "update ms"
            ),
            width,
        ),
        theme.dim(),
    ));
    for (k, r) in m.rows.iter().enumerate() {
        let cursor = if k == m.selected { '▸' } else { ' ' };
        let current = if r.current { '●' } else { ' ' };
        let (method, setting) = method_setting(&r.accuracy);
        let lead = format!(
            "{cursor}{current} {method:<6} {setting:<9} {:>6}",
            format!("{:.0e}", r.accuracy.root_tol)
        );
        let front = m.front.get(k).copied().flatten();
        let text = match &r.result {
            Ok(measured) => format!(
                "{lead} {:>10} {:>10} {:>9}  {}",
                error_cell(&measured.state),
                error_cell(&measured.jacobian),
                ms(measured.update.ms),
                match front {
                    Some(true) => "front",
                    Some(false) => "",
                    None => NOT_A_NUMBER,
                }
            ),
            Err(e) => format!("{lead} failed: {e}"),
        };
        let mut style = if front == Some(true) {
            theme.info()
        } else {
            ratatui::style::Style::new()
        };
        if k == m.selected {
            style = style.patch(theme.selected());
        }
        out.push(Line::styled(truncate(&text, width), style));
    }
    out.push(Line::raw(""));
    let mut legend = String::from(
        "● current setting. front: no other setting is both faster per update (by 25 %) \
         and more accurate (final-state error 2× smaller). ≠ev k/n: the collisions differ \
         from the reference's (k of n agree). update: median ms of a drag of the first body \
         by 1 mm with the scene's constraints, as nudge bench --only work-precision times it.",
    );
    if m.freed {
        legend.push_str(" The scene has no free controls: every initial state was freed.");
    }
    out.extend(
        wrap(&legend, width)
            .into_iter()
            .map(|l| Line::styled(l, theme.dim())),
    );
    out
}

/// `dopri5`, `tol=1e-9` or `rk4`, `h=1e-3`, as the bench's table.
fn method_setting(a: &Accuracy) -> (&'static str, String) {
    match a.method {
        Method::Rk4 { step } => ("rk4", format!("h={step:.0e}")),
        Method::Adaptive { tol, .. } => ("dopri5", format!("tol={tol:.0e}")),
    }
}

/// An error as the bench prints it (`3.1e-7`), shorter when there is no
/// number.
fn error_cell(e: &Error) -> String {
    match e {
        Error::Value(v) if !v.is_finite() => NOT_A_NUMBER.into(),
        Error::Value(v) if *v == 0.0 => "0".into(),
        Error::Value(v) => format!("{v:.1e}"),
        Error::DifferentEvents { agree, total } => format!("≠ev {agree}/{total}"),
        Error::Unavailable(_) => NOT_A_NUMBER.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_never_show_nan_or_inf() {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(error_cell(&Error::Value(v)), NOT_A_NUMBER);
        }
        assert_eq!(error_cell(&Error::Value(3.14e-7)), "3.1e-7");
        assert_eq!(
            error_cell(&Error::DifferentEvents { agree: 2, total: 5 }),
            "≠ev 2/5"
        );
    }
}
