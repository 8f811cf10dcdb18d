//! Polishing a sampled world: a few of the solver's differential updates
//! towards the constraints and the goal, from the best sample of a group.
//! Sampling finds the smooth piece; the gradients then do what they do
//! well inside it (docs/design.md §12).

use super::world::Frame;
use crate::sim::{SimOptions, simulate};
use crate::solve::{self, UpdateOptions};
use nalgebra::DVector;

/// Step halvings of a polishing update (as a settle's).
const HALVINGS: usize = 8;

/// Below this residual a world is met: no more updates.
const MET: f64 = 1e-12;

/// Up to `steps` updates from `u`; the controls reached and the number of
/// updates that lowered the residual. `seed` seeds the solver's own
/// sampling at a pop.
pub(crate) fn polish(
    frame: &Frame<'_>,
    u: &DVector<f64>,
    steps: usize,
    seed: u64,
) -> (DVector<f64>, usize) {
    let controls = frame.controls;
    let mut scene = frame.scene.clone();
    controls.write(&mut scene, u);
    let opts = SimOptions {
        until: frame.until,
        ..SimOptions::default()
    };
    let mut now = controls.values(&scene);
    let Ok(mut traj) = simulate(&scene, controls, &opts) else {
        return (now, 0);
    };
    let mut last = solve::residual_norm(&traj, frame.all);
    let update = UpdateOptions {
        halvings: HALVINGS,
        seed,
        ..UpdateOptions::default()
    };
    let mut done = 0;
    for _ in 0..steps {
        if last <= MET || !last.is_finite() {
            break;
        }
        let Ok(res) = solve::update(&scene, controls, &traj, frame.all, &update) else {
            break;
        };
        let Some(tr) = res.trajectory else {
            break;
        };
        let better = res.after < last * (1.0 - 1e-9);
        if !better || !res.u.iter().all(|v| v.is_finite()) {
            break;
        }
        controls.write(&mut scene, &res.u);
        let written = controls.values(&scene);
        // A sampled pop comes without tangents, and writing `u` may
        // reparameterise an orientation: simulate afresh then.
        traj = if tr.tangent && written == res.u {
            tr
        } else {
            match simulate(&scene, controls, &opts) {
                Ok(t) => t,
                Err(_) => break,
            }
        };
        now = written;
        last = res.after;
        done += 1;
    }
    (now, done)
}
