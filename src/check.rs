//! `nudge check --jacobian`: the tangent Jacobian against central
//! differences, per control block and per state quantity, as typed values
//! rendered at the edge (text for the terminal, JSON for `--json`).
//!
//! Every figure says what it is: a disagreement, or why nothing was
//! compared (the perturbed runs change the collision sequence, the
//! simulator refused a perturbed run, or a grazing contact took the
//! Jacobian away) — never a `0` that would read as perfect agreement.

use crate::controls::Controls;
use crate::scene::Scene;
use crate::sim::{Side, TangentError, Trajectory};
use crate::tangent::{ColumnKind, FiniteDifference, Scheme};
use nalgebra::DMatrix;
use serde_json::{Value, json};

pub mod matrix;

/// The state quantities a Jacobian row belongs to, in row order.
pub const QUANTITIES: [&str; 4] = ["position", "orientation", "velocity", "angular_velocity"];

/// Column norms below this count as zero in the relative disagreement.
const FLOOR: f64 = 1e-3;

/// Why a figure compares nothing.
#[derive(Debug, Clone, PartialEq)]
pub enum Uncompared {
    /// A perturbed run changes the collision sequence: across it the motion
    /// is not differentiable and the quotient means nothing.
    EventsDiffer,
    /// The simulator refused every perturbed run of a control.
    Refused(String),
    /// A grazing contact at this event took the Jacobian away.
    Grazing(usize),
    /// The motion has no events.
    NoEvents,
}

impl Uncompared {
    /// A short label for the table.
    pub fn label(&self) -> String {
        match self {
            Uncompared::EventsDiffer => "n/c events".into(),
            Uncompared::Refused(_) => "n/c refused".into(),
            Uncompared::Grazing(k) => format!("n/c grazing #{k}"),
            Uncompared::NoEvents => "no events".into(),
        }
    }

    fn reason(&self) -> String {
        match self {
            Uncompared::EventsDiffer => {
                "u ± h changes the collision sequence, so the difference quotient is not comparable"
                    .into()
            }
            Uncompared::Refused(why) => format!("the perturbed runs were refused: {why}"),
            Uncompared::Grazing(k) => {
                format!("a grazing contact at event {k} makes the motion non-differentiable there")
            }
            Uncompared::NoEvents => "the motion has no collision events".into(),
        }
    }
}

/// The largest relative disagreement of one block at one place (the final
/// time, or every event), per state quantity.
#[derive(Debug, Clone, PartialEq)]
pub enum Figure {
    Compared {
        /// Per quantity of [`QUANTITIES`].
        per_quantity: [f64; 4],
        /// Some column was a one-sided difference (a perturbed run was
        /// refused on one side): first order, so its figure is coarser.
        one_sided: bool,
    },
    Uncompared(Uncompared),
}

/// One control block's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockCheck {
    /// e.g. `ball.position`.
    pub name: String,
    pub at_final: Figure,
    pub at_events: Figure,
}

/// The whole check.
#[derive(Debug, Clone, PartialEq)]
pub struct JacobianCheck {
    pub blocks: Vec<BlockCheck>,
    /// Why some bodies have no Jacobian from some time on.
    pub notes: Vec<String>,
}

/// The control blocks: free columns grouped by name without the component
/// (`ball.position.x` → `ball.position`).
fn blocks(controls: &Controls) -> Vec<(String, Vec<usize>)> {
    let mut out: Vec<(String, Vec<usize>)> = Vec::new();
    for (col, &i) in controls.free.iter().enumerate() {
        let name = &controls.entries[i].name;
        let block = match name.rsplit_once('.') {
            Some((a, b)) if b.len() == 1 && name.matches('.').count() >= 2 => a.to_string(),
            _ => name.clone(),
        };
        match out.iter_mut().find(|b| b.0 == block) {
            Some(b) => b.1.push(col),
            None => out.push((block, vec![col])),
        }
    }
    out
}

/// Largest relative disagreement per quantity over the columns `cols`:
/// `|a_c − b_c| / max(|b_c|, FLOOR)` on that quantity's three rows.
fn per_quantity(a: &DMatrix<f64>, b: &DMatrix<f64>, cols: &[usize], worst: &mut [f64; 4]) {
    for (q, w) in worst.iter_mut().enumerate() {
        for &c in cols {
            let d = (a.fixed_view::<3, 1>(3 * q, c) - b.fixed_view::<3, 1>(3 * q, c)).norm();
            let r = d / b.fixed_view::<3, 1>(3 * q, c).norm().max(FLOOR);
            if r.is_finite() {
                *w = w.max(r);
            }
        }
    }
}

/// The first grazing event among the tangent errors of the bodies.
fn grazing(errors: &[TangentError]) -> Option<usize> {
    errors.iter().find_map(|e| match e {
        TangentError::Grazing { event, .. } => Some(*event),
        _ => None,
    })
}

/// Compare `traj`'s tangent Jacobians with central differences of `scene`.
///
/// # Errors
/// When the nominal run of the differences fails (it is the run `traj`
/// came from, so it does not).
pub fn jacobian_check(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
) -> Result<JacobianCheck, crate::sim::SimError> {
    let fd = FiniteDifference::new(scene, controls, Scheme::Central)?;
    Ok(compare(scene, controls, traj, &fd))
}

/// As [`jacobian_check`] with the central differences already run (the
/// Jacobian's data, [`matrix`], reuses them).
pub fn compare(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
    fd: &FiniteDifference,
) -> JacobianCheck {
    let mut out = Vec::new();
    for (name, cols) in blocks(controls) {
        let refused = cols.iter().find_map(|&c| match &fd.columns[c] {
            ColumnKind::Refused(why) => Some(why.clone()),
            _ => None,
        });
        if let Some(why) = refused {
            let u = Uncompared::Refused(why);
            out.push(BlockCheck {
                name,
                at_final: Figure::Uncompared(u.clone()),
                at_events: Figure::Uncompared(u),
            });
            continue;
        }
        let one_sided = cols
            .iter()
            .any(|&c| matches!(fd.columns[c], ColumnKind::OneSided(_)));
        let comparable = cols.iter().all(|&c| fd.comparable[c]);
        let figure = |worst: [f64; 4], compared: bool, lost: &[TangentError], none: Uncompared| {
            if !comparable {
                Figure::Uncompared(Uncompared::EventsDiffer)
            } else if compared {
                Figure::Compared {
                    per_quantity: worst,
                    one_sided,
                }
            } else {
                Figure::Uncompared(grazing(lost).map_or(none, Uncompared::Grazing))
            }
        };
        // At the final time: every body's state that has a Jacobian.
        let (mut worst, mut compared, mut lost) = ([0.0; 4], false, Vec::new());
        for b in 0..scene.bodies.len() {
            match traj.jacobian(b, scene.duration, Side::Post) {
                Ok(jt) => {
                    per_quantity(
                        &jt,
                        &fd.at(b, scene.duration, Side::Post),
                        &cols,
                        &mut worst,
                    );
                    compared = true;
                }
                Err(e) => lost.push(e),
            }
        }
        let at_final = figure(worst, compared, &lost, Uncompared::EventsDiffer);
        // At every event, just before and after the impulse: each run's own
        // event time, against J + F dt_c/du.
        let (mut worst, mut compared, mut lost) = ([0.0; 4], false, Vec::new());
        for (k, e) in traj.events.iter().enumerate() {
            for side in [Side::Pre, Side::Post] {
                match (
                    traj.jacobian_at_event(e.a, e, side),
                    fd.at_event(k, e.a, side),
                ) {
                    (Ok(jt), Some(jf)) => {
                        per_quantity(&jt, &jf, &cols, &mut worst);
                        compared = true;
                    }
                    (Err(err), _) => lost.push(err),
                    (Ok(_), None) => {}
                }
            }
        }
        let none = if traj.events.is_empty() {
            Uncompared::NoEvents
        } else {
            Uncompared::EventsDiffer
        };
        let at_events = figure(worst, compared, &lost, none);
        out.push(BlockCheck {
            name,
            at_final,
            at_events,
        });
    }
    let mut notes: Vec<String> = traj
        .tangent_lost
        .iter()
        .enumerate()
        .filter_map(|(b, lost)| {
            lost.map(|(_, e)| format!("{}: no Jacobian from {e}", scene.bodies[b].name))
        })
        .collect();
    for (c, kind) in fd.columns.iter().enumerate() {
        if let ColumnKind::OneSided(why) = kind {
            let name = &controls.entries[controls.free[c]].name;
            notes.push(format!(
                "{name}: one-sided difference (first order), the other side was refused: {why}"
            ));
        }
    }
    JacobianCheck { blocks: out, notes }
}

impl Figure {
    fn cells(&self) -> [String; 4] {
        match self {
            Figure::Compared {
                per_quantity,
                one_sided,
            } => per_quantity.map(|w| {
                let mark = if *one_sided { "¹" } else { "" };
                // An exact zero (the quantity does not depend on the block,
                // and both sides agree) reads as one.
                if w == 0.0 {
                    format!("0{mark}")
                } else {
                    format!("{w:.1e}{mark}")
                }
            }),
            Figure::Uncompared(u) => {
                let mut cells = [String::new(), String::new(), String::new(), String::new()];
                cells[0] = u.label();
                cells
            }
        }
    }

    fn json(&self) -> Value {
        match self {
            Figure::Compared {
                per_quantity,
                one_sided,
            } => {
                let mut m = serde_json::Map::new();
                for (q, w) in QUANTITIES.iter().zip(per_quantity) {
                    m.insert((*q).into(), crate::report::num(*w));
                }
                m.insert("compared".into(), json!(true));
                m.insert("one_sided".into(), json!(one_sided));
                Value::Object(m)
            }
            Figure::Uncompared(u) => json!({
                "compared": false,
                "label": u.label(),
                "reason": u.reason(),
            }),
        }
    }
}

impl JacobianCheck {
    /// The table for the terminal (79 columns).
    pub fn text(&self) -> String {
        let mut out = String::from(
            "\njacobian: tangent vs central differences (largest relative disagreement)\n",
        );
        out.push_str(&format!(
            "  {:<26} {:<6} {:>10} {:>11} {:>10} {:>10}\n",
            "block", "at", "position", "orientation", "velocity", "ang.vel"
        ));
        let mut reasons: Vec<String> = Vec::new();
        for b in &self.blocks {
            for (at, figure) in [("final", &b.at_final), ("events", &b.at_events)] {
                let c = figure.cells();
                let name = if at == "final" { b.name.as_str() } else { "" };
                out.push_str(
                    format!(
                        "  {name:<26} {at:<6} {:>10} {:>11} {:>10} {:>10}",
                        c[0], c[1], c[2], c[3]
                    )
                    .trim_end(),
                );
                out.push('\n');
                if let Figure::Uncompared(u) = figure {
                    let line = format!("{}: {}", u.label(), u.reason());
                    if !reasons.contains(&line) {
                        reasons.push(line);
                    }
                }
            }
        }
        for line in reasons.iter().chain(&self.notes) {
            out.push_str(&format!("  note: {line}\n"));
        }
        if self.blocks.iter().any(|b| {
            [&b.at_final, &b.at_events].iter().any(|f| {
                matches!(
                    f,
                    Figure::Compared {
                        one_sided: true,
                        ..
                    }
                )
            })
        }) {
            out.push_str("  ¹ one-sided difference: first order in the step\n");
        }
        out
    }

    /// The `jacobian_check` object of `nudge check --json --jacobian`.
    pub fn json(&self) -> Value {
        json!({
            "blocks": self.blocks.iter().map(|b| json!({
                "block": b.name,
                "final": b.at_final.json(),
                "events": b.at_events.json(),
            })).collect::<Vec<_>>(),
            "notes": self.notes,
        })
    }
}
