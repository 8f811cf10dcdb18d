//! The hard cases: scenes where simulators and differentiable simulators
//! are known to break, each with a pass criterion. Regression tests are
//! named after the failure they caught, with what used to break.
//!
//! Scenes live in `tests/hard/*.toml`; sweeps load one and vary it. The
//! cases are grouped by topic in `tests/hard/*.rs`; the helpers they share
//! are here.
#![allow(clippy::type_complexity)] // table-driven cases list tuples of closures

use nudge::controls::Controls;
use nudge::geometry::PartKind;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{Side, SimError, SimOptions, Trajectory, simulate};
use std::path::Path;

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/hard")
        .join(name);
    nudge::scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A paper scene as it was when the sinking and freezing bugs were found
/// (`tests/hard/paper-*.toml`, frozen copies: `scenes/` keeps evolving).
fn paper(name: &str) -> Scene {
    load(&format!("paper-{name}"))
}

/// Penetration allowed by design: a pair that just had an impulse is
/// disarmed until it separates, and fires again only at the event skin
/// (1e-9 m) inside the surface.
const SKIN: f64 = 1.1e-9;

fn run(scene: &Scene) -> Result<Trajectory, SimError> {
    simulate(
        scene,
        &Controls::new(scene),
        &SimOptions::without_tangents(),
    )
}

fn run_ok(scene: &Scene) -> Trajectory {
    run(scene).unwrap_or_else(|e| panic!("{}: {e}", scene.name))
}

/// Body-frame points of a body's hull vertices and ball parts (with radius).
fn points(scene: &Scene, b: usize) -> Vec<(Vec3, f64)> {
    let mut out = Vec::new();
    for p in &scene.bodies[b].geometry.parts {
        match p.kind {
            PartKind::Ball { radius } => out.push((p.offset.translation.vector, radius)),
            _ => out.extend(p.vertices().into_iter().map(|v| (v, 0.0))),
        }
    }
    out
}

/// Whether the vertical through `c` meets the convex hull of `pts`
/// (projected on the floor), within `tol` (m).
fn over_support(pts: &[Vec3], c: &Vec3, tol: f64) -> bool {
    let mut p: Vec<(f64, f64)> = pts.iter().map(|q| (q.x - c.x, q.y - c.y)).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    p.dedup();
    if p.len() < 3 {
        return false;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    // Andrew's monotone chain: the hull counter-clockwise.
    let mut hull: Vec<(f64, f64)> = Vec::new();
    for pass in [p.clone(), p.iter().rev().cloned().collect()] {
        let start = hull.len();
        for q in pass {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let n = hull.len();
    n >= 3
        && (0..n).all(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            cross(a, b, (0.0, 0.0)) >= -tol * (b.0 - a.0).hypot(b.1 - a.1)
        })
}

// ---------------------------------------------------------------------------
// Regressions in the simulator found by this suite.
// ---------------------------------------------------------------------------

/// Kinetic energy of body `b` in state `s`.
fn kinetic(tr: &Trajectory, b: usize, s: &nudge::sim::BodyState) -> f64 {
    let d = &tr.dynamics[b];
    let r = *s.q.to_rotation_matrix().matrix();
    0.5 * d.mass * s.v.norm_squared() + 0.5 * s.w.dot(&(r * d.inertia * r.transpose() * s.w))
}

#[path = "hard/bounces.rs"]
mod bounces;
#[path = "hard/events.rs"]
mod events;
#[path = "hard/extremes.rs"]
mod extremes;
#[path = "hard/grazing.rs"]
mod grazing;
#[path = "hard/input.rs"]
mod input;
#[path = "hard/rotation.rs"]
mod rotation;
#[path = "hard/solver.rs"]
mod solver;
