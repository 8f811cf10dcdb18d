//! An estimate of a motion's integration error, by step halving.
//!
//! The motion is simulated again, without tangents, at twice the accuracy
//! (RK4: half the step and half the substeps; adaptive: a tolerance 2⁻⁶ as tight and half the
//! largest step), and the final states are compared. For RK4 the error of
//! the coarse run is then `16/15` of the difference (Richardson: the error
//! scales as `h⁴`); for the adaptive method the fine run's error is far
//! smaller than the coarse one's and the difference is the estimate. The
//! estimate includes what moving event times does to the final state.
//!
//! It is reported per state quantity (the largest over the bodies), and a
//! diagnostic fires when any quantity's estimate exceeds [`THRESHOLD`]
//! relative to its size (at least 1 in its unit). Its advice depends on
//! why ([`Cause`]): with the same contacts in both runs it is the
//! integration's error and names the scene's own step or tolerance to
//! change; when the finer run meets different contacts (eggs rattling in
//! a bucket, a body rocking to rest) the difference is how far the motion
//! diverges through them, which more accuracy moves but does not remove.

use crate::controls::Controls;
use crate::scene::{Method, Scene};
use crate::sim::{Side, SimError, SimOptions, Trajectory, simulate};
use crate::tangent::state_difference;

/// Relative estimated error above which a motion is reported as
/// inaccurate: `error / max(|value|, 1)` per quantity.
pub const THRESHOLD: f64 = 1e-4;

/// The estimated error of the final state, per quantity (m, rad, m/s,
/// rad/s), the largest over the bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    pub per_quantity: [f64; 4],
    /// The same relative to each quantity's size (at least 1).
    pub relative: [f64; 4],
    /// What the difference comes from, and so what to do about it.
    pub cause: Cause,
}

/// Where an estimated error comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cause {
    /// The integration itself, at the scene's fixed RK4 step (s).
    Step { step: f64 },
    /// The integration itself, at the scene's adaptive tolerance and
    /// largest step (s).
    Tolerance { tol: f64, max_step: f64 },
    /// The finer run meets other contacts from `t` (s) on: `coarse` and
    /// `fine` events in all.
    Contacts { t: f64, coarse: usize, fine: usize },
}

/// The quantities' names, in order.
pub const QUANTITIES: [&str; 4] = ["position", "orientation", "velocity", "angular velocity"];
/// Their units, in order.
pub const UNITS: [&str; 4] = ["m", "rad", "m/s", "rad/s"];

/// The scene at twice the accuracy, and the factor turning the difference
/// of the two runs into the coarse run's error. (The RK4 substeps of a
/// fast-precessing body are halved too, by [`SimOptions::substep_turn`].)
fn finer(scene: &Scene) -> (Scene, f64) {
    let mut fine = scene.clone();
    let factor = match scene.accuracy.method {
        Method::Rk4 { step } => {
            fine.accuracy.method = Method::Rk4 { step: step / 2.0 };
            16.0 / 15.0
        }
        Method::Adaptive { tol, max_step } => {
            fine.accuracy.method = Method::Adaptive {
                tol: (tol / 64.0).max(1e-14),
                max_step: max_step / 2.0,
            };
            1.0
        }
    };
    (fine, factor)
}

/// Estimate the integration error of `traj`, the motion of `scene` with
/// `controls`.
///
/// # Errors
/// When the finer simulation fails (it takes twice the steps: a motion
/// near the step budget may not fit).
pub fn error_estimate(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
) -> Result<ErrorEstimate, SimError> {
    let (fine, factor) = finer(scene);
    let defaults = SimOptions::default();
    let opts = SimOptions {
        tangent: false,
        substep_turn: defaults.substep_turn / 2.0,
        ..defaults
    };
    let refined = simulate(&fine, controls, &opts)?;
    let t = scene.duration;
    let mut per_quantity = [0.0f64; 4];
    let mut relative = [0.0f64; 4];
    for b in 0..scene.bodies.len() {
        let coarse = traj.state(b, t, Side::Post);
        let d = state_difference(&refined.state(b, t, Side::Post), &coarse);
        let sizes = [
            coarse.x.norm(),
            std::f64::consts::PI,
            coarse.v.norm(),
            coarse.w.norm(),
        ];
        for q in 0..4 {
            let e = factor * d.fixed_rows::<3>(3 * q).norm();
            if e.is_finite() {
                per_quantity[q] = per_quantity[q].max(e);
                relative[q] = relative[q].max(e / sizes[q].max(1.0));
            }
        }
    }
    let (a, b) = (traj.signature(), refined.signature());
    let cause = match a.iter().zip(&b).position(|(x, y)| x != y) {
        Some(i) => Some(i),
        None => (a.len() != b.len()).then(|| a.len().min(b.len())),
    }
    .map(|i| {
        let at = |tr: &Trajectory| tr.events.get(i).map_or(f64::INFINITY, |e| e.t);
        Cause::Contacts {
            t: at(traj).min(at(&refined)),
            coarse: a.len(),
            fine: b.len(),
        }
    })
    .unwrap_or(match scene.accuracy.method {
        Method::Rk4 { step } => Cause::Step { step },
        Method::Adaptive { tol, max_step } => Cause::Tolerance { tol, max_step },
    });
    Ok(ErrorEstimate {
        per_quantity,
        relative,
        cause,
    })
}

impl ErrorEstimate {
    /// The quantities whose estimate exceeds [`THRESHOLD`].
    pub fn exceeding(&self) -> Vec<usize> {
        (0..4).filter(|&q| self.relative[q] > THRESHOLD).collect()
    }

    /// One line: `position 1.2e-12 m, orientation …`.
    pub fn text(&self) -> String {
        (0..4)
            .map(|q| {
                format!(
                    "{} {:.1e} {}",
                    QUANTITIES[q], self.per_quantity[q], UNITS[q]
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The diagnostic when some quantity exceeds the threshold.
    pub fn diagnostic(&self) -> Option<String> {
        let over = self.exceeding();
        let worst = over
            .iter()
            .copied()
            .max_by(|&a, &b| self.relative[a].total_cmp(&self.relative[b]))?;
        let advice = match self.cause {
            Cause::Step { step } => {
                format!("use a smaller step than {step:e} s or method = \"adaptive\"")
            }
            Cause::Tolerance { tol, max_step } => {
                format!("use a tighter tol than {tol:e} or a smaller max_step than {max_step:e} s")
            }
            Cause::Contacts { t, coarse, fine } => format!(
                "at twice the accuracy the contacts differ from t = {t:.3} s ({coarse} events against {fine}): the motion diverges through its contacts, which more accuracy moves but does not remove"
            ),
        };
        Some(format!(
            "estimated integration error {:.1e} {} in {} ({:.0e} relative, above {THRESHOLD:.0e}): {advice}",
            self.per_quantity[worst], UNITS[worst], QUANTITIES[worst], self.relative[worst]
        ))
    }

    /// The `integration_error` object of a JSON report.
    pub fn json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (name, value) in QUANTITIES.iter().zip(self.per_quantity) {
            m.insert(name.replace(' ', "_"), crate::report::num(value));
        }
        m.insert("threshold".into(), crate::report::num(THRESHOLD));
        m.insert(
            "exceeds".into(),
            serde_json::Value::Bool(!self.exceeding().is_empty()),
        );
        m.insert(
            "method".into(),
            serde_json::Value::String("step halving".into()),
        );
        let cause = match self.cause {
            Cause::Step { .. } => "step",
            Cause::Tolerance { .. } => "tolerance",
            Cause::Contacts { t, .. } => {
                m.insert("contacts_differ_from".into(), crate::report::num(t));
                "contacts"
            }
        };
        m.insert("cause".into(), serde_json::Value::String(cause.into()));
        serde_json::Value::Object(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn over(cause: Cause) -> ErrorEstimate {
        ErrorEstimate {
            per_quantity: [0.0, 0.0, 0.0, 0.4],
            relative: [0.0, 0.0, 0.0, 0.04],
            cause,
        }
    }

    #[test]
    fn the_advice_names_the_scenes_own_accuracy_or_the_contacts() {
        let step = over(Cause::Step { step: 1e-3 }).diagnostic().unwrap();
        assert!(
            step.ends_with("use a smaller step than 1e-3 s or method = \"adaptive\""),
            "{step}"
        );
        let tol = over(Cause::Tolerance {
            tol: 1e-9,
            max_step: 0.05,
        })
        .diagnostic()
        .unwrap();
        assert!(
            tol.ends_with("use a tighter tol than 1e-9 or a smaller max_step than 5e-2 s"),
            "{tol}"
        );
        let contacts = over(Cause::Contacts {
            t: 1.2834,
            coarse: 201,
            fine: 203,
        })
        .diagnostic()
        .unwrap();
        assert!(
            contacts.contains("the contacts differ from t = 1.283 s (201 events against 203)")
                && !contacts.contains("tighter"),
            "{contacts}"
        );
        // Below the threshold there is nothing to say.
        let mut fine = over(Cause::Step { step: 1e-3 });
        fine.relative[3] = 1e-6;
        assert!(fine.diagnostic().is_none());
    }
}
