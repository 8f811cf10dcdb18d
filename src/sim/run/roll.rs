//! The switch of a sliding ball from slipping to rolling, an event of the
//! run (`sim::roll`): no impulse, the state is continuous, and the
//! Jacobian is carried to the rolling side (the velocities' derivatives
//! take how the switch time moves with the controls).

use super::Sim;
use crate::sim::error::SimError;
use crate::sim::rest::face;
use crate::sim::trajectory::Event;
use nalgebra::DMatrix;

impl Sim<'_> {
    /// The earliest switch of a slipping ball no later than `until`, and
    /// the ball.
    pub(super) fn next_switch(&self, until: f64) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, track) in self.traj.tracks.iter().enumerate() {
            let Some(seg) = track.segments.last() else {
                continue;
            };
            let Some((slide, roll)) = seg.slide.and_then(|s| s.roll.map(|r| (s, r))) else {
                continue;
            };
            let Some(after) = roll.switch_after(&slide.normal, &seg.start) else {
                continue;
            };
            let t = seg.t0 + after;
            if t <= until && best.is_none_or(|(b, _)| t < b) {
                best = Some((t, i));
            }
        }
        best
    }

    /// Ball `i` stops slipping at `ts`: record the event and start its
    /// rolling segment.
    pub(super) fn roll_switch(&mut self, ts: f64, i: usize) -> Result<(), SimError> {
        let Some(seg) = self.traj.tracks[i].segments.last() else {
            return Ok(());
        };
        let Some((slide, roll)) = seg.slide.and_then(|s| s.roll.map(|r| (s, r))) else {
            return Ok(());
        };
        let n = slide.normal;
        let at = roll.at(&n, &seg.start, 0.0, true);
        let m = self.traj.m;
        let mass = self.traj.mass_cols[i].map(|c| (c, self.traj.dynamics[i].mass));
        let lost = self.traj.tangent_lost[i].is_some();
        let (j0, dt_du) = if self.traj.tangent && !lost {
            let (g, dt_db) = roll.switch_gradient(&n, &seg.start);
            let mut dt = seg.j0.transpose() * nalgebra::DVector::from_column_slice(g.as_slice());
            if let Some((c, mass)) = mass.filter(|(c, _)| *c < m) {
                dt[c] += dt_db * roll.spin_accel / mass;
            }
            (roll.carry(&at, &seg.j0, mass), Some(dt))
        } else {
            (DMatrix::zeros(12, m), None)
        };
        let state = at.state;
        if !state.is_finite() {
            return Err(SimError::NonFinite {
                body: self.scene.bodies[i].name.clone(),
                t: ts,
            });
        }
        // The feature pair of the impact that began the slide.
        let Some(start) = self
            .traj
            .events
            .iter()
            .rev()
            .find(|e| e.a == i && e.slide.is_some())
            .cloned()
        else {
            return Ok(());
        };
        let mut rolling = crate::sim::rest::Slide {
            roll: Some(roll.rolled()),
            ..slide
        };
        // On a face of a hull: when the rolling ball's centre reaches its
        // edge, from here.
        if let (Some(mut f), Some(on)) = (rolling.face, face::of(self.scene, &slide)) {
            let d = &self.traj.dynamics[i];
            let edge = face::EDGE * d.reach;
            let horizon = self.traj.duration - ts;
            f.until = face::until(&rolling, &state, d.drag_k, &on, edge, horizon);
            rolling.face = Some(f);
        }
        let event = Event {
            index: self.traj.events.len(),
            t: ts,
            normal: n,
            point: state.x - n * roll.radius,
            approach: 0.0,
            separation: 0.0,
            restitution: 0.0,
            graze_ratio: f64::NAN,
            grazing: false,
            simultaneous: 1,
            rest: false,
            slide: Some(rolling),
            roll: true,
            micro: false,
            rest_time: None,
            friction: None,
            dt_du,
            pre: [state, state],
            post: [state, state],
            ..start
        };
        self.traj.events.push(event);
        self.start_segment(i, ts, state, j0, false, Some(rolling));
        Ok(())
    }
}
