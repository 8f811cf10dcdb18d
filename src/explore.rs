//! Exploring: when the gradients are blocked, sample many worlds in
//! parallel (docs/design.md §12).
//!
//! Around the current free controls `u0`, control vectors are drawn from
//! the normal distribution in the solver's metric `M` (covariance
//! `σ² M⁻¹`), in rounds whose spread doubles (`σ = σ₀·2^k`). Each is
//! simulated without tangents up to just past the last constrained time
//! and scored by the residual the solver minimises (the constraints plus
//! the pending goal) plus a small multiple of `‖u − u0‖_M`, which prefers
//! motions close to the current one. Samples are grouped by the collision
//! signature the solver uses to detect a pop; the best few groups are
//! polished by differential updates, and the best world of each group is
//! an [`Alternative`] the user can accept as an undoable edit
//! ([`Alternative::edit`]).
//!
//! A sample whose style term alone scores it worse than the group ranked
//! last among those that can still be kept (`max(keep, polish_groups)`
//! best, as the groups stood after the previous batch) is not simulated:
//! it could neither enter nor improve a kept group, so the alternatives
//! are exactly those of simulating it (only the count of sequences seen
//! can be lower).
//!
//! Results do not depend on the number of threads: sample `i` draws from
//! its own stream seeded by `(seed, i)`, the pruning bar changes only
//! between batches, and every reduction runs in index order. [`run`] checks a cancel flag and reports progress between
//! batches, so a front end can run it on a background thread.

mod describe;
mod polish;
mod render;
mod sample;
mod world;

pub use describe::Contact;
pub use render::{json, text};

use crate::controls::Controls;
use crate::edit::{Edit, Editor};
use crate::scene::Scene;
use crate::sim::{SimError, SimOptions, simulate};
use crate::solve::{Constraint, residual_norm};
use rayon::prelude::*;
use sample::Around;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use world::{Frame, Lost, World};

/// How much to explore and how to score.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExploreOptions {
    /// Worlds to sample.
    pub samples: usize,
    /// Seed: the same seed gives the same alternatives.
    pub seed: u64,
    /// Spread of the first round, in the metric `M` (`‖Δu‖_M` per control).
    pub sigma0: f64,
    /// Rounds of equal size; the spread doubles each round.
    pub rounds: usize,
    /// Worlds simulated between cancel checks and progress reports.
    pub batch: usize,
    /// Weight of `‖u − u0‖_M` in the score (style preservation).
    pub style: f64,
    /// Differential updates that polish a group's best world.
    pub polish: usize,
    /// How many of the best groups are polished.
    pub polish_groups: usize,
    /// Most alternatives returned.
    pub keep: usize,
}

impl Default for ExploreOptions {
    fn default() -> Self {
        ExploreOptions {
            samples: 2048,
            seed: 0x5eed,
            sigma0: 0.05,
            rounds: 5,
            batch: 256,
            style: 0.01,
            polish: 8,
            polish_groups: 4,
            keep: 8,
        }
    }
}

/// Why exploring could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExploreError {
    /// The current motion itself cannot be simulated.
    #[error("the current motion cannot be simulated: {0}")]
    Sim(#[from] SimError),
    /// No free control to vary.
    #[error(
        "no free controls to explore: free a block first (e.g. `:free {body} velocity` in the editor, or `free = [\"velocity\"]` in the scene)"
    )]
    NoFreeControls { body: String },
    /// An option out of its range.
    #[error("{what} must be {rule}, got {value}")]
    BadOption {
        what: &'static str,
        rule: &'static str,
        value: String,
    },
}

/// A number for a message: never NaN or infinity.
fn shown(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "a non-finite number".into()
    }
}

impl ExploreOptions {
    fn check(&self) -> Result<(), ExploreError> {
        let bad = |what, rule, value: String| Err(ExploreError::BadOption { what, rule, value });
        if self.samples == 0 {
            return bad("samples", "at least 1", "0".into());
        }
        if self.rounds == 0 {
            return bad("rounds", "at least 1", "0".into());
        }
        if self.batch == 0 {
            return bad("batch", "at least 1", "0".into());
        }
        if !(self.sigma0.is_finite() && self.sigma0 > 0.0) {
            return bad("sigma0", "a finite number > 0", shown(self.sigma0));
        }
        if !(self.style.is_finite() && self.style >= 0.0) {
            return bad("style", "a finite number ≥ 0", shown(self.style));
        }
        Ok(())
    }
}

/// Where exploring starts: the scene with its current controls, the
/// constraints, and the goal a blocked drag left (if any). It owns copies,
/// so a front end can move it to a background thread.
#[derive(Debug, Clone)]
pub struct Start {
    pub scene: Scene,
    pub controls: Controls,
    pub constraints: Vec<Constraint>,
    pub goal: Option<Constraint>,
}

impl Start {
    /// The editor's state, with its pending (blocked) drag as the goal.
    pub fn from_editor(editor: &Editor) -> Start {
        Start {
            scene: editor.scene().clone(),
            controls: editor.controls().clone(),
            constraints: editor.constraints().to_vec(),
            goal: editor.pending_drag().cloned(),
        }
    }
}

/// Progress so far, reported between batches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tally {
    /// Worlds drawn (simulated or pruned).
    pub worlds: usize,
    /// Worlds planned.
    pub planned: usize,
    /// Worlds whose simulation stopped with an error.
    pub failed: usize,
    /// Worlds whose residual or score was not finite (skipped).
    pub non_finite: usize,
    /// Worlds not simulated: their style term alone ruled them out.
    pub pruned: usize,
    /// The best score so far.
    pub best: Option<f64>,
}

/// Cancellation and progress: both optional.
#[derive(Clone, Copy, Default)]
pub struct Progress<'a> {
    /// Set it to stop after the current batch; what was found is returned.
    pub cancel: Option<&'a AtomicBool>,
    /// Called on the calling thread after every batch.
    pub report: Option<&'a dyn Fn(&Tally)>,
}

impl Progress<'_> {
    fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn tell(&self, tally: &Tally) {
        if let Some(f) = self.report {
            f(tally);
        }
    }
}

/// The current motion, as the alternatives are compared with it.
#[derive(Debug, Clone, PartialEq)]
pub struct Current {
    /// The residual of the constraints and the goal (its score).
    pub residual: f64,
    pub signature: Vec<String>,
    pub contacts: Vec<Contact>,
    /// Collision events of the whole motion.
    pub events: usize,
    /// The free controls `u0`.
    pub controls: Vec<f64>,
}

/// The best world of one collision signature.
#[derive(Debug, Clone, PartialEq)]
pub struct Alternative {
    /// The collision signature (as the solver's pops compare them).
    pub signature: Vec<String>,
    /// `residual + style · distance`: lower is better.
    pub score: f64,
    /// Residual of the constraints and the goal.
    pub residual: f64,
    /// `‖u − u0‖_M`.
    pub distance: f64,
    /// The free controls `u`, in the order of `Controls::free`.
    pub controls: Vec<f64>,
    /// Collision events up to the horizon.
    pub events: usize,
    /// The contacts of the signature.
    pub contacts: Vec<Contact>,
    /// What differs from the current collisions, in words.
    pub description: String,
    /// The sample it grew from (`None`: polished from the current
    /// controls, which is where the gradients alone lead).
    pub sample: Option<usize>,
    /// Differential updates that polished it (0: as sampled).
    pub polished: usize,
    /// Its signature is the current motion's.
    pub same_as_current: bool,
}

impl Alternative {
    /// The undoable edit that makes this alternative the motion.
    pub fn edit(&self) -> Edit {
        Edit::SetControls(self.controls.clone())
    }
}

/// What exploring found.
#[derive(Debug, Clone, PartialEq)]
pub struct Exploration {
    pub current: Current,
    /// Best first, one per signature.
    pub alternatives: Vec<Alternative>,
    /// Names of the free controls, in the order of the controls vectors.
    pub names: Vec<String>,
    /// The goal explored towards besides the constraints.
    pub goal: Option<Constraint>,
    /// Worlds sampled (polishing not counted), failed and non-finite ones,
    /// and those not simulated because their style term alone ruled them
    /// out (`worlds − pruned` were simulated).
    pub worlds: usize,
    pub failed: usize,
    pub non_finite: usize,
    pub pruned: usize,
    /// Distinct signatures among the sampled worlds.
    pub groups: usize,
    /// Differential updates spent polishing.
    pub polish_updates: usize,
    /// Stopped early by the cancel flag.
    pub cancelled: bool,
}

/// The best world per signature, with the sample it came from and how many
/// updates polished it.
type Groups = BTreeMap<Vec<String>, (Option<usize>, usize, World)>;

/// Keep `w` if it beats its group's best (ties keep the earlier entry).
fn offer(groups: &mut Groups, sample: Option<usize>, polished: usize, w: World) {
    match groups.get(&w.signature) {
        Some((_, _, best)) if best.score <= w.score => {}
        _ => {
            groups.insert(w.signature.clone(), (sample, polished, w));
        }
    }
}

/// The groups best first (ties by sample index).
fn ranked(groups: &Groups) -> Vec<&(Option<usize>, usize, World)> {
    let mut v: Vec<_> = groups.values().collect();
    v.sort_by(|a, b| a.2.score.total_cmp(&b.2.score).then(a.0.cmp(&b.0)));
    v
}

/// The score a sample must not exceed to be worth simulating: that of the
/// `n`-th best group (`None` while there are fewer). A world scoring more
/// can neither enter the best `n` groups nor change their bests.
fn bar(groups: &Groups, n: usize) -> Option<f64> {
    let mut scores: Vec<f64> = groups.values().map(|g| g.2.score).collect();
    if n == 0 || scores.len() < n {
        return None;
    }
    scores.sort_by(f64::total_cmp);
    Some(scores[n - 1])
}

/// Explore around `start` (see the module documentation).
pub fn run(
    start: &Start,
    opts: &ExploreOptions,
    progress: &Progress<'_>,
) -> Result<Exploration, ExploreError> {
    opts.check()?;
    let (scene, controls) = (&start.scene, &start.controls);
    if controls.m() == 0 {
        let body = scene.bodies.first().map(|b| b.name.clone());
        return Err(ExploreError::NoFreeControls {
            body: body.unwrap_or_else(|| "a body".into()),
        });
    }
    let mut all: Vec<Constraint> = start.constraints.clone();
    all.extend(start.goal.clone());
    let now = simulate(scene, controls, &SimOptions::without_tangents())?;
    let u0 = controls.values(scene);
    let scales = controls.scales();
    let (lo, hi) = controls.bounds();
    // Like the solver's trials: just past the last constrained time.
    let last = all.iter().filter_map(|c| c.time(&now)).fold(0.0, f64::max);
    let horizon = last + 0.02 * scene.duration;
    let until = (!all.is_empty() && horizon < scene.duration).then_some(horizon);
    let frame = Frame {
        scene,
        controls,
        all: &all,
        u0: &u0,
        scales: &scales,
        style: opts.style,
        until,
    };
    let (signature, contacts) = frame.signature(&now);
    let current = Current {
        residual: residual_norm(&now, &all),
        signature,
        contacts,
        events: now.events.len(),
        controls: u0.iter().copied().collect(),
    };
    let around = Around {
        u0: &u0,
        scales: &scales,
        lo: &lo,
        hi: &hi,
    };
    let mut groups = Groups::new();
    let mut tally = Tally {
        worlds: 0,
        planned: opts.samples,
        failed: 0,
        non_finite: 0,
        pruned: 0,
        best: None,
    };
    // Groups that can still be kept: the alternatives and the polished.
    let kept = opts.keep.max(opts.polish_groups);
    let mut cancelled = false;
    while tally.worlds < opts.samples {
        if progress.cancelled() {
            cancelled = true;
            break;
        }
        let (from, to) = (tally.worlds, (tally.worlds + opts.batch).min(opts.samples));
        let bar = bar(&groups, kept);
        let batch: Vec<Result<World, Lost>> = (from..to)
            .into_par_iter()
            .map(|i| {
                let round = sample::round_of(i, opts.samples, opts.rounds);
                let sigma = sample::sigma(opts.sigma0, round);
                frame.world_under(around.draw(sigma, &mut sample::stream(opts.seed, i)), bar)
            })
            .collect();
        for (i, r) in (from..to).zip(batch) {
            match r {
                Ok(w) => {
                    if tally.best.is_none_or(|b| w.score < b) {
                        tally.best = Some(w.score);
                    }
                    offer(&mut groups, Some(i), 0, w);
                }
                Err(Lost::Failed) => tally.failed += 1,
                Err(Lost::NonFinite) => tally.non_finite += 1,
                Err(Lost::Pruned) => tally.pruned += 1,
            }
        }
        tally.worlds = to;
        progress.tell(&tally);
    }
    let sampled_groups = groups.len();
    let mut polish_updates = 0;
    if opts.polish > 0 && !cancelled {
        // The current controls first: where the gradients alone lead, for
        // comparison (nowhere when the drag is blocked).
        let chosen: Vec<(Option<usize>, nalgebra::DVector<f64>)> =
            std::iter::once((None, u0.clone()))
                .chain(
                    ranked(&groups)
                        .into_iter()
                        .take(opts.polish_groups)
                        .map(|(i, _, w)| (*i, w.u.clone())),
                )
                .collect();
        let polished: Vec<(Option<usize>, usize, Option<World>)> = chosen
            .par_iter()
            .map(|(i, u)| {
                let index = i.map_or(usize::MAX, |i| i);
                let seed = opts.seed ^ sample::stream(opts.seed, index).0;
                let (u, n) = polish::polish(&frame, u, opts.polish, seed);
                (*i, n, (n > 0).then(|| frame.world(u).ok()).flatten())
            })
            .collect();
        for (i, n, w) in polished {
            polish_updates += n;
            if let Some(w) = w {
                if tally.best.is_none_or(|b| w.score < b) {
                    tally.best = Some(w.score);
                }
                offer(&mut groups, i, n, w);
            }
        }
        progress.tell(&tally);
    }
    let alternatives = ranked(&groups)
        .into_iter()
        .take(opts.keep)
        .map(|(sample, polished, w)| Alternative {
            same_as_current: w.signature == current.signature,
            description: describe::differences(&current.contacts, &w.contacts),
            signature: w.signature.clone(),
            score: w.score,
            residual: w.residual,
            distance: w.distance,
            controls: w.u.iter().copied().collect(),
            events: w.events,
            contacts: w.contacts.clone(),
            sample: *sample,
            polished: *polished,
        })
        .collect();
    Ok(Exploration {
        current,
        alternatives,
        names: controls
            .free
            .iter()
            .map(|&i| controls.entries[i].name.clone())
            .collect(),
        goal: start.goal.clone(),
        worlds: tally.worlds,
        failed: tally.failed,
        non_finite: tally.non_finite,
        pruned: tally.pruned,
        groups: sampled_groups,
        polish_updates,
        cancelled,
    })
}
