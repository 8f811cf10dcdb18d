//! Deferring the rest of a nudged motion to the pauses after keys (as the
//! terminal editor and `nudge run` do) changes when the work is done, not
//! what it computes: every paper session replayed that way leaves the same
//! scene, to the bit, as with every accepted motion simulated whole at
//! once, and its motion is whole when the keys stop.

use nudge::bench::without_saves;
use nudge::edit::{Core, Editor};
use nudge::script::{parse_script, run_script};
use std::path::Path;

const SESSIONS: [&str; 8] = [
    "eggs",
    "plank",
    "mug",
    "scissors",
    "scissors-bounce",
    "particle-parabola",
    "particle-polygon",
    "hat",
];

fn replay(stem: &str, defer: bool) -> Editor {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let keys = root.join(format!("tests/sessions/{stem}.keys"));
    let text = std::fs::read_to_string(&keys).expect("session keys");
    let steps = without_saves(&parse_script(&text, stem).expect("parses"));
    let mut editor =
        Editor::open(&root.join(format!("scenes/{stem}.toml"))).expect("opens the scene");
    editor.set_wall_clock(false);
    editor.set_defer_motion(defer);
    let r = run_script(&mut editor, &steps, (80, 24));
    assert!(r.failures.is_empty(), "{stem}: {:?}", r.failures);
    editor
}

#[test]
fn deferred_motions_leave_every_session_as_whole_ones_do() {
    for stem in SESSIONS {
        let whole = replay(stem, false);
        let deferred = replay(stem, true);
        let values = |e: &Editor| e.controls().values(e.scene());
        assert_eq!(values(&whole), values(&deferred), "{stem}: controls differ");
        assert_eq!(
            deferred.motion_until(),
            deferred.scene().duration,
            "{stem}: the motion is whole after the last pause"
        );
        let (a, b) = (whole.view(), deferred.view());
        assert_eq!(
            a.status.residual.to_bits(),
            b.status.residual.to_bits(),
            "{stem}"
        );
        assert_eq!(a.events, b.events, "{stem}: the collisions differ");
    }
}

#[test]
fn a_held_key_draws_prefixes_and_the_pause_completes_the_same_motion() {
    use nudge::script::{Replay, parse_keys, run_script_with};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let open = || {
        let mut e = Editor::open(&root.join("scenes/eggs.toml")).expect("opens");
        e.set_wall_clock(false);
        e.set_defer_motion(true);
        e
    };
    let keys = parse_keys(":t 0.6<CR> l l l", "held").expect("parses");
    let (select, presses) = keys.split_at(keys.len() - 3);
    let mut held = open();
    run_script(&mut held, select, (80, 24));
    let held_keys = Replay {
        pauses: false,
        ..Replay::default()
    };
    let r = run_script_with(&mut held, presses, (80, 24), held_keys);
    assert_eq!(r.frame_ms.len(), 3, "one frame per press");
    let duration = held.scene().duration;
    assert!(
        held.motion_until() > 0.6 && held.motion_until() < duration,
        "while the key is held the motion is simulated to the drag's horizon, got {}",
        held.motion_until()
    );
    let drawn_to = held
        .view()
        .paths
        .iter()
        .filter_map(|p| p.times.last().copied())
        .fold(0.0, f64::max);
    assert!(
        drawn_to <= held.motion_until() + 1e-12,
        "traces end at the horizon"
    );
    let said = held.view().status.busy.unwrap_or_default();
    assert!(
        said.starts_with(&format!("motion drawn to {:.2} s of", held.motion_until())),
        "the status line says the traces end early: {said:?}"
    );
    assert!(held.idle(), "the pause simulates the rest");
    assert_eq!(held.motion_until(), duration);
    assert_eq!(held.view().status.busy, None, "and then stops saying so");
    while held.idle() {}

    let mut paused = open();
    run_script(&mut paused, &keys, (80, 24));
    let values = |e: &Editor| e.controls().values(e.scene());
    assert_eq!(values(&held), values(&paused));
}

#[test]
fn a_settle_runs_one_update_per_pause_and_stops_where_it_is_asked_to() {
    use nudge::edit::Edit;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut e = Editor::open(&root.join("scenes/scissors.toml")).expect("opens");
    e.set_wall_clock(false);
    e.set_defer_motion(true);
    let nails = parse_script(
        ":t 0.3<CR>:nail rot 0 0 0 angvel 0 0 0<CR>:t 0.6<CR>:nail pos 0.52 0 1.45<CR>",
        "nails",
    )
    .expect("parses");
    run_script(&mut e, &nails, (80, 24));
    let values = |e: &Editor| e.controls().values(e.scene());
    let before = values(&e);

    let o = e.apply(Edit::Settle { budget_ms: 500 }).expect("settles");
    assert_eq!(o.updates, 1, "the edit makes the first update only");
    let busy = |e: &Editor| e.view().status.busy;
    assert!(
        busy(&e).is_some_and(|b| b.starts_with("settling: update 1,")),
        "{:?}",
        busy(&e)
    );
    assert!(e.idle(), "the next update waits for a pause");
    assert!(busy(&e).is_some_and(|b| b.starts_with("settling: update 2,")));
    let stopped = e.stop().expect("a settle was going on");
    assert!(
        stopped.starts_with("settle stopped after 2 update(s)"),
        "{stopped}"
    );
    assert_eq!(busy(&e), None);
    assert_ne!(values(&e), before, "what it reached is kept");
    e.apply(Edit::Undo).expect("undoes");
    assert_eq!(values(&e), before, "one undo takes back the whole settle");

    e.apply(Edit::Settle { budget_ms: 500 }).expect("settles");
    let mut pauses = 0;
    while e.idle() {
        pauses += 1;
    }
    assert!(pauses > 2, "{pauses}");
    let v = e.view();
    assert_eq!(v.status.busy, None);
    assert!(
        v.status
            .message
            .as_deref()
            .is_some_and(|m| m.starts_with("settled: ")),
        "{:?}",
        v.status.message
    );
    assert!(v.status.residual < 1e-9, "{}", v.status.residual);
}
