//! One sampled world: simulate a control vector without tangents up to the
//! horizon and score it by the solver's residual and its distance from the
//! current controls (docs/design.md §12).

use super::describe::{self, Contact};
use super::sample::distance;
use crate::controls::Controls;
use crate::scene::Scene;
use crate::sim::{SimOptions, Trajectory, simulate};
use crate::solve::{self, Constraint, residual_norm};
use nalgebra::DVector;

/// What every world is measured against.
pub(crate) struct Frame<'a> {
    pub scene: &'a Scene,
    pub controls: &'a Controls,
    /// The constraints and the goal: what the solver minimises.
    pub all: &'a [Constraint],
    pub u0: &'a DVector<f64>,
    pub scales: &'a DVector<f64>,
    /// Weight of `‖Δu‖_M` in the score.
    pub style: f64,
    /// Simulate up to here (`None`: the whole motion).
    pub until: Option<f64>,
}

/// A simulated and scored world.
#[derive(Debug, Clone)]
pub(crate) struct World {
    pub u: DVector<f64>,
    /// `residual + style · distance`.
    pub score: f64,
    /// The residual norm of the constraints and the goal.
    pub residual: f64,
    /// `‖u − u0‖_M`.
    pub distance: f64,
    /// The collision signature that decides its group.
    pub signature: Vec<String>,
    /// The contacts of the signature, for the description.
    pub contacts: Vec<Contact>,
    /// Collision events up to the horizon.
    pub events: usize,
}

/// Why a world has no score.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Lost {
    /// The simulation stopped with an error (bodies stuck together, too
    /// many events, a state that left the finite numbers).
    Failed,
    /// It ran, but its residual or score is not a finite number (e.g. a
    /// floating constraint whose collision does not happen).
    NonFinite,
    /// Not simulated: its style term alone already scores it below every
    /// group it could enter (see [`Frame::bound`]).
    Pruned,
}

impl Frame<'_> {
    /// The signature and contacts of a motion: the causal events of the
    /// constraints and goal, or every event when there are none.
    pub(crate) fn signature(&self, tr: &Trajectory) -> (Vec<String>, Vec<Contact>) {
        let keep = if self.all.is_empty() {
            vec![true; tr.events.len()]
        } else {
            solve::causal_events(tr, self.all)
        };
        let signature = tr
            .signature()
            .into_iter()
            .zip(&keep)
            .filter_map(|(s, k)| k.then_some(s))
            .collect();
        (signature, describe::contacts(self.scene, tr, &keep))
    }

    /// A lower bound of `u`'s score known before simulating it: the style
    /// term `style · ‖u − u0‖_M` (the residual is a norm, never negative).
    pub(crate) fn bound(&self, u: &DVector<f64>) -> f64 {
        self.style * distance(&(u - self.u0), self.scales)
    }

    /// Simulate and score `u`, unless its [`Frame::bound`] exceeds `bar`.
    pub(crate) fn world_under(&self, u: DVector<f64>, bar: Option<f64>) -> Result<World, Lost> {
        match bar {
            Some(bar) if self.bound(&u) > bar => Err(Lost::Pruned),
            _ => self.world(u),
        }
    }

    /// Simulate and score `u`.
    pub(crate) fn world(&self, u: DVector<f64>) -> Result<World, Lost> {
        if !u.iter().all(|v| v.is_finite()) {
            return Err(Lost::NonFinite);
        }
        let mut scene = self.scene.clone();
        self.controls.write(&mut scene, &u);
        let opts = SimOptions {
            until: self.until,
            ..SimOptions::without_tangents()
        };
        let tr = simulate(&scene, self.controls, &opts).map_err(|_| Lost::Failed)?;
        let residual = residual_norm(&tr, self.all);
        let distance = distance(&(&u - self.u0), self.scales);
        let score = residual + self.style * distance;
        if !(score.is_finite() && residual.is_finite()) {
            return Err(Lost::NonFinite);
        }
        let (signature, contacts) = self.signature(&tr);
        Ok(World {
            u,
            score,
            residual,
            distance,
            signature,
            contacts,
            events: tr.events.len(),
        })
    }
}
