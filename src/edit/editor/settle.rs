//! Settling: differential updates on the persistent constraints alone until
//! they hold (residual below 1e-10), stop falling, or a budget runs out.
//!
//! A settle can take a hundred updates (the scissors wedged on the peg: 130
//! ms in all), far more than a frame. With [`Editor::set_defer_motion`] on
//! (the terminal editor, key replays) the edit makes the first update and
//! the rest run one per pause ([`Core::idle`]), so the screen redraws and
//! keys are read between them: the status line shows the progress, Esc
//! ([`Core::stop`]) stops it where it is, and any other edit stops it
//! first. The whole settle is one undoable edit. Each update is the same
//! computation in the same order either way, so a replay that pauses
//! after every key settles to the same bits as one settle run at once.
//!
//! [`Core::idle`]: super::Core::idle
//! [`Core::stop`]: super::Core::stop

use super::*;

/// A settle in progress.
#[derive(Debug, Clone)]
pub(super) struct Settling {
    started: Instant,
    budget_ms: u64,
    /// The step the next update starts with: where a strongly nonlinear
    /// motion (a collision that spins a body fast) lets only a fraction of
    /// the Gauss–Newton step through, near that fraction instead of the
    /// full step: the same progress for fewer trials.
    first: f64,
    /// The residual after the last update.
    last: f64,
    updates: usize,
    /// The last update's diagnostics.
    diags: Vec<Diagnostic>,
}

impl Editor {
    /// Settle the persistent constraints: all updates now, or (deferring)
    /// the first now and the rest in the pauses. Returns the diagnostics of
    /// the last update made.
    pub(super) fn settle(&mut self, budget_ms: u64) -> Result<Vec<Diagnostic>, EditError> {
        let mut s = Settling {
            started: Instant::now(),
            budget_ms,
            first: self.opts.step,
            last: self.residual(),
            updates: 0,
            diags: Vec::new(),
        };
        if self.defer_motion {
            if self.settle_once(&mut s)? {
                self.status.busy = Some(progress(&s));
                self.settling = Some(s);
                return Ok(Vec::new());
            }
            return Ok(s.diags);
        }
        while self.settle_once(&mut s)? {}
        Ok(s.diags)
    }

    /// One settling update; whether the settle goes on.
    fn settle_once(&mut self, s: &mut Settling) -> Result<bool, EditError> {
        let out_of_time =
            self.wall_clock && s.started.elapsed().as_millis() >= u128::from(s.budget_ms.max(1));
        if s.updates >= MAX_SETTLE_UPDATES
            || out_of_time
            || s.last < 1e-10
            || self.constraints.is_empty()
        {
            return Ok(false);
        }
        let constraints = self.constraints.clone();
        let (full, halvings) = (self.opts.step, self.opts.halvings);
        self.opts.step = s.first;
        // A drag that only creeps is better reported as blocked; settling
        // towards typed values may take small steps.
        self.opts.halvings = SETTLE_HALVINGS;
        let stepped = self.step(&constraints, false);
        self.opts.step = full;
        self.opts.halvings = halvings;
        let (moved, d, after) = stepped?;
        s.updates += 1;
        s.diags = d;
        if !moved || after >= s.last * (1.0 - 1e-9) {
            return Ok(false);
        }
        let accepted = self.status.step;
        s.first = if accepted > 0.0 {
            (4.0 * accepted).min(full)
        } else {
            full
        };
        s.last = after;
        Ok(true)
    }

    /// The next update of a settle going on in the pauses: `None` when
    /// there is none, else whether the view changed.
    pub(super) fn settle_in_pause(&mut self) -> Option<bool> {
        let mut s = self.settling.take()?;
        let scene = self.scene.clone();
        match self.settle_once(&mut s) {
            Ok(true) => {
                self.status.busy = Some(progress(&s));
                self.settling = Some(s);
            }
            Ok(false) => {
                self.status.busy = None;
                self.status.message = Some(finished(&s, self.residual()));
                self.estimate_due = true;
            }
            Err(e) => {
                // The update's motion could not be simulated: back to the
                // state before it, the settle stops there.
                self.scene = scene;
                let _ = self.rebuild();
                self.status.busy = None;
                self.status.message = Some(format!("settle stopped: {e}"));
            }
        }
        self.refresh_geometry();
        self.status.residual = self.residual();
        Some(true)
    }

    /// Stop a settle going on in the pauses where it is; what it reached.
    pub(super) fn stop_settling(&mut self) -> Option<String> {
        let s = self.settling.take()?;
        self.status.busy = None;
        self.estimate_due = true;
        Some(format!(
            "settle stopped after {} update(s), residual {} (u undoes it)",
            s.updates,
            sci(self.residual())
        ))
    }
}

fn progress(s: &Settling) -> String {
    format!(
        "settling: update {}, residual {} (Esc stops)",
        s.updates,
        sci(s.last)
    )
}

fn finished(s: &Settling, residual: f64) -> String {
    let why = s
        .diags
        .last()
        .map(|d| format!(" ({d})"))
        .unwrap_or_default();
    format!(
        "settled: {} update(s), residual {}{why}",
        s.updates,
        sci(residual)
    )
}

/// A residual for the status line (`—` if it is not a finite number).
fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "—".into()
    }
}
