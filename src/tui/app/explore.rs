//! Exploring from the editor (`X`, `:explore`): the sampling runs on a
//! background thread with its progress on the status line (Esc cancels);
//! when it ends, its alternatives are drawn one at a time as a trace
//! beside the motion, `j`/`k` step through them, Enter accepts one (an
//! undoable edit) and Esc dismisses them.

use super::job::Job;
use super::*;
use crate::explore::{self, ExploreOptions, Progress, Start, Tally};
use crate::view::Path;
use std::sync::{Arc, Mutex};

/// One alternative as the editor shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct Alternative {
    /// What differs from the current collisions, in words.
    pub description: String,
    pub score: f64,
    pub residual: f64,
    pub events: usize,
    /// The free controls that give it.
    pub controls: Vec<f64>,
    /// Its traces, as the screen draws the motion's.
    pub paths: Vec<Path>,
}

/// What the background exploration has said so far.
#[derive(Debug, Default)]
pub struct Shared {
    tally: Option<Tally>,
    done: Option<Result<Vec<Alternative>, String>>,
}

/// Exploring, from start to choice.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Exploring {
    #[default]
    Idle,
    Running(Job<Shared>),
    /// The alternatives, best first, and the one shown.
    Browsing {
        alternatives: Arc<Vec<Alternative>>,
        index: usize,
    },
}

/// The alternatives of an exploration, with their traces.
fn alternatives(start: &Start, found: &explore::Exploration) -> Vec<Alternative> {
    found
        .alternatives
        .iter()
        .filter(|a| !a.same_as_current)
        .filter_map(|a| {
            let mut scene = start.scene.clone();
            let u = nalgebra::DVector::from_column_slice(&a.controls);
            start.controls.write(&mut scene, &u);
            let opts = crate::sim::SimOptions::without_tangents();
            let traj = crate::sim::simulate(&scene, &start.controls, &opts).ok()?;
            Some(Alternative {
                description: a.description.clone(),
                score: a.score,
                residual: a.residual,
                events: a.events,
                controls: a.controls.clone(),
                paths: crate::edit::paths_of(&scene, &traj),
            })
        })
        .collect()
}

impl App {
    /// Start exploring from the core's state on a background thread.
    pub(super) fn explore(&mut self, core: &mut impl Core, samples: usize) {
        if matches!(self.exploring, Exploring::Running(_)) {
            self.say(Level::Warning, "already exploring: Esc cancels");
            return;
        }
        let Some(start) = core.explore_start() else {
            self.say(Level::Error, "this editor cannot explore");
            return;
        };
        let opts = ExploreOptions {
            samples,
            ..ExploreOptions::default()
        };
        let spawned = Job::spawn("nudge-explore", move |s: &Mutex<Shared>, c| {
            let report = |t: &Tally| {
                if let Ok(mut sh) = s.lock() {
                    sh.tally = Some(*t);
                }
            };
            let progress = Progress {
                cancel: Some(c),
                report: Some(&report),
            };
            let done = explore::run(&start, &opts, &progress)
                .map(|found| alternatives(&start, &found))
                .map_err(|e| e.to_string());
            if let Ok(mut sh) = s.lock() {
                sh.done = Some(done);
            }
        });
        match spawned {
            Ok(job) => {
                self.exploring = Exploring::Running(job);
                self.say(
                    Level::Info,
                    format!("exploring {samples} worlds around this motion… (Esc cancels)"),
                );
            }
            Err(e) => self.say(Level::Error, format!("could not start exploring: {e}")),
        }
    }

    /// Whether an exploration is running in the background.
    pub fn exploring(&self) -> bool {
        matches!(self.exploring, Exploring::Running(_))
    }

    /// Take what the background work (exploring, `:accuracy`) has said
    /// since the last call. Returns whether the screen changed.
    pub fn poll_background(&mut self) -> bool {
        let explored = self.poll_exploring();
        self.poll_accuracy() || explored
    }

    /// Take what the background exploration has said since the last call:
    /// progress on the status line, or its alternatives. Returns whether
    /// the screen changed.
    fn poll_exploring(&mut self) -> bool {
        let Exploring::Running(job) = &self.exploring else {
            return false;
        };
        let (tally, done) = job
            .with(|sh| (sh.tally, sh.done.take()))
            .unwrap_or_else(|| (None, Some(Err("the exploring thread failed".into()))));
        match done {
            None => {
                let Some(t) = tally else {
                    return false;
                };
                let best = t
                    .best
                    .map_or("—".into(), |b| super::super::format::num(b, 7));
                let text = format!(
                    "exploring: {}/{} worlds, best score {best} (Esc cancels)",
                    t.worlds, t.planned
                );
                let changed = self.message.as_ref().is_none_or(|m| m.text != text);
                if changed {
                    // Progress is not logged: only where it ends is.
                    self.message = Some(Message {
                        text,
                        level: Level::Info,
                    });
                }
                changed
            }
            Some(result) => {
                job.join();
                match result {
                    Ok(alts) if alts.is_empty() => {
                        self.exploring = Exploring::Idle;
                        self.say(
                            Level::Warning,
                            "exploring found no other collision sequence that does better",
                        );
                    }
                    Ok(alts) => {
                        self.exploring = Exploring::Browsing {
                            alternatives: Arc::new(alts),
                            index: 0,
                        };
                        self.say_alternative();
                    }
                    Err(e) => {
                        self.exploring = Exploring::Idle;
                        self.say(Level::Error, format!("exploring stopped: {e}"));
                    }
                }
                true
            }
        }
    }

    /// Wait for a running exploration to end (headless replays, which must
    /// not depend on timing), then take its result.
    pub fn wait_background(&mut self) {
        if let Exploring::Running(job) = &self.exploring {
            job.join();
            self.poll_exploring();
        }
        self.wait_accuracy();
    }

    /// Esc while exploring: stop after the current batch.
    pub(super) fn cancel_exploring(&mut self) -> bool {
        match &self.exploring {
            Exploring::Running(job) => {
                job.cancel();
                self.say(Level::Info, "cancelling: the worlds found so far are kept");
                true
            }
            Exploring::Browsing { .. } => {
                self.exploring = Exploring::Idle;
                self.say(Level::Info, "alternatives dismissed");
                true
            }
            Exploring::Idle => false,
        }
    }

    /// Show the next or previous alternative.
    pub(super) fn step_alternative(&mut self, sense: Sense) {
        if let Exploring::Browsing {
            alternatives,
            index,
        } = &mut self.exploring
        {
            let n = alternatives.len() as i64;
            *index = (*index as i64 + sense.sign()).rem_euclid(n.max(1)) as usize;
            self.say_alternative();
        }
    }

    /// Accept the alternative shown: an undoable edit (the caller settles
    /// from it when `settling`). Whether it was taken.
    pub(super) fn accept_alternative(&mut self, core: &mut impl Core, settling: bool) -> bool {
        let Exploring::Browsing {
            alternatives,
            index,
        } = &self.exploring
        else {
            return false;
        };
        let Some(alt) = alternatives.get(*index).cloned() else {
            return false;
        };
        let k = *index + 1;
        self.exploring = Exploring::Idle;
        let taken = self
            .apply(core, Edit::SetControls(alt.controls.clone()))
            .is_some();
        if taken {
            let next = if settling {
                "settling from it"
            } else {
                "s settles from here"
            };
            self.tell(format!(
                "took alternative {k}: {} (u undoes; {next})",
                alt.description
            ));
        }
        taken
    }

    /// The alternative shown, if browsing.
    pub fn alternative(&self) -> Option<(&Alternative, usize, usize)> {
        match &self.exploring {
            Exploring::Browsing {
                alternatives,
                index,
            } => alternatives
                .get(*index)
                .map(|a| (a, *index + 1, alternatives.len())),
            _ => None,
        }
    }

    fn say_alternative(&mut self) {
        if let Some((a, k, n)) = self.alternative() {
            let text = format!(
                "alternative {k}/{n}: {}; score {}, {} events (Enter takes it, S settles too, j/k others, Esc)",
                a.description,
                super::super::format::num(a.score, 7),
                a.events
            );
            self.say(Level::Info, text);
        }
    }
}
