//! The animation keys of each body: when, and its pose then.
//!
//! Keys fall on every frame (`k / fps`, and the final time), at every
//! collision of the body (the pose just after the impulse) and just before
//! it (at `t − ε`, the pose then), so LINEAR interpolation draws an impact
//! as the corner it is. Two keys must have strictly increasing times as
//! `f32` (glTF's requirement): `ε = max(1 µs, 2⁻²⁰ t)` is at least eight
//! `f32` steps of `t`, and where two keys still round to one time the
//! collision's key wins over the one before it, which wins over a frame's.
//! A body spinning more than 45° per frame (by its spin at the frames) gets
//! keys in between, so a viewer's shortest-path interpolation turns it the
//! right way.

use super::{ExportError, MAX_KEYS};
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::{Side, Trajectory};
use nalgebra::UnitQuaternion;

/// Largest turn between two frame keys, rad.
const MAX_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// Most keys added between two frames for a fast spin.
const MAX_SUBDIVISIONS: usize = 64;

/// Shortest gap kept before a collision's key, s.
pub const BEFORE: f64 = 1e-6;

/// What a key marks, in the order they win a shared time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum KeyKind {
    Frame,
    /// Just before a collision.
    Before,
    /// At a collision: the pose after the impulse.
    Event,
}

/// One body's keys, in z-up world coordinates (the writer turns them).
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    pub body: usize,
    /// Key times, s, as the file stores them: strictly increasing.
    pub times: Vec<f32>,
    /// The times the poses were taken at, s.
    pub seconds: Vec<f64>,
    pub kinds: Vec<KeyKind>,
    pub positions: Vec<Vec3>,
    /// Each in the hemisphere of the one before (no sign flip between keys).
    pub rotations: Vec<UnitQuaternion<f64>>,
}

/// The region the motion covers: obstacles without an edge (a plane, a
/// parabola's length) are drawn over it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// z-up world, m.
    pub centre: Vec3,
    /// Half the side of the square drawn, m.
    pub half: f64,
}

/// The frame times `k / fps` up to the duration, and the duration.
fn frames(duration: f64, fps: f64) -> Vec<f64> {
    let n = (duration * fps).floor() as usize;
    let mut out: Vec<f64> = (0..=n)
        .map(|k| k as f64 / fps)
        .filter(|&t| t <= duration)
        .collect();
    if out.last().is_none_or(|&t| t < duration) {
        out.push(duration);
    }
    out
}

/// The gap before a collision at `t` (see the module notes).
pub fn before(t: f64) -> f64 {
    BEFORE.max(t.abs() * 2f64.powi(-20))
}

/// Candidate key times of one body, sorted.
fn candidates(traj: &Trajectory, body: usize, frames: &[f64]) -> Vec<(f64, KeyKind)> {
    let mut keys: Vec<(f64, KeyKind)> = Vec::with_capacity(frames.len());
    for pair in frames.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        keys.push((a, KeyKind::Frame));
        let spin = |t: f64| traj.state(body, t, Side::Post).w.norm();
        let turn = spin(a).max(spin(b)) * (b - a);
        let parts = ((turn / MAX_TURN).ceil() as usize).clamp(1, MAX_SUBDIVISIONS + 1);
        for k in 1..parts {
            keys.push((a + (b - a) * k as f64 / parts as f64, KeyKind::Frame));
        }
    }
    if let Some(&last) = frames.last() {
        keys.push((last, KeyKind::Frame));
    }
    for e in traj.body_events(body) {
        keys.push((e.t, KeyKind::Event));
        let t = e.t - before(e.t);
        if t >= 0.0 {
            keys.push((t, KeyKind::Before));
        }
    }
    keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    keys
}

/// Keep keys whose `f32` times strictly increase; of two sharing a time,
/// the higher kind.
fn strictly_increasing(keys: Vec<(f64, KeyKind)>) -> Vec<(f32, f64, KeyKind)> {
    let mut kept: Vec<(f32, f64, KeyKind)> = Vec::with_capacity(keys.len());
    for (t, kind) in keys {
        let time = t as f32;
        while kept
            .last()
            .is_some_and(|&(last, _, k)| time <= last && kind > k)
        {
            kept.pop();
        }
        if kept.last().is_none_or(|&(last, _, _)| time > last) {
            kept.push((time, t, kind));
        }
    }
    kept
}

/// Every body's keys.
///
/// # Errors
/// More than [`MAX_KEYS`] keys in all.
pub fn tracks(scene: &Scene, traj: &Trajectory, fps: f64) -> Result<Vec<Track>, ExportError> {
    let bodies = scene.bodies.len();
    // Refuse before sampling: a long motion at a high rate is billions of keys.
    let estimate = (traj.duration * fps).ceil() * bodies as f64;
    if estimate > MAX_KEYS as f64 {
        return Err(ExportError::TooManyKeys {
            keys: estimate.min(usize::MAX as f64) as usize,
        });
    }
    let frames = frames(traj.duration, fps);
    let mut out = Vec::with_capacity(bodies);
    let mut total = 0;
    for body in 0..bodies {
        let keys = strictly_increasing(candidates(traj, body, &frames));
        total += keys.len();
        if total > MAX_KEYS {
            return Err(ExportError::TooManyKeys { keys: total });
        }
        let mut track = Track {
            body,
            times: Vec::with_capacity(keys.len()),
            seconds: Vec::with_capacity(keys.len()),
            kinds: Vec::with_capacity(keys.len()),
            positions: Vec::with_capacity(keys.len()),
            rotations: Vec::with_capacity(keys.len()),
        };
        for (time, t, kind) in keys {
            let s = traj.state(body, t, Side::Post);
            let q = match track.rotations.last() {
                Some(prev) if prev.coords.dot(&s.q.coords) < 0.0 => {
                    UnitQuaternion::new_unchecked(-s.q.into_inner())
                }
                _ => s.q,
            };
            track.times.push(time);
            track.seconds.push(t);
            track.kinds.push(kind);
            track.positions.push(s.x);
            track.rotations.push(q);
        }
        out.push(track);
    }
    Ok(out)
}

/// The square the motion covers, with the bodies' reach around it.
pub fn extent(scene: &Scene, tracks: &[Track]) -> Extent {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in tracks.iter().flat_map(|t| &t.positions) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if !(lo.iter().chain(hi.iter()).all(|v| v.is_finite())) {
        return Extent {
            centre: Vec3::zeros(),
            half: 1.0,
        };
    }
    let reach = scene
        .bodies
        .iter()
        .map(|b| b.geometry.reach())
        .fold(0.0, f64::max);
    Extent {
        centre: (lo + hi) / 2.0,
        half: (1.5 * ((hi - lo).norm() / 2.0 + reach)).max(1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_end_at_the_duration() {
        assert_eq!(frames(0.05, 60.0).len(), 4);
        assert_eq!(frames(0.06, 60.0).len(), 5);
        assert_eq!(frames(0.05, 60.0).last(), Some(&0.05));
        assert_eq!(frames(1.0, 4.0), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    }

    #[test]
    fn a_collision_key_wins_a_shared_time_and_times_strictly_increase() {
        let keys = vec![
            (0.5, KeyKind::Frame),
            (0.5, KeyKind::Event),
            (0.5 + 1e-9, KeyKind::Frame),
            (0.75, KeyKind::Frame),
        ];
        let kept = strictly_increasing(keys);
        let kinds: Vec<KeyKind> = kept.iter().map(|k| k.2).collect();
        assert_eq!(kinds, vec![KeyKind::Event, KeyKind::Frame]);
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn the_gap_before_a_collision_survives_f32() {
        for t in [1e-3, 0.5, 1.05, 37.0, 1e4, 1e5] {
            let (at, before) = (t as f32, (t - before(t)) as f32);
            assert!(before < at, "{t}");
        }
    }
}
