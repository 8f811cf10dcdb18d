//! Exploring (docs/design.md §12): sampling many worlds finds motions the
//! gradients cannot reach, an alternative becomes the motion by an undoable
//! edit, and the result does not depend on the number of threads.

use nalgebra::Vector3;
use nudge::edit::{Core, Edit, Editor, Note, Outcome};
use nudge::explore::{self, Alternative, Exploration, ExploreOptions, Progress, Start, Tally};
use nudge::scene::StateQuantity;
use nudge::script::{parse_keys, run_script};
use nudge::sim::{Party, Side};
use nudge::solve::{Anchor, Diagnostic, Kind};
use std::cell::RefCell;
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The editor after replaying `tests/fixtures/explore/<keys>.keys` on
/// `scenes/<scene>.toml`.
fn replay(scene: &str, keys: &str) -> Editor {
    let mut editor =
        Editor::open(&root().join("scenes").join(format!("{scene}.toml"))).expect("scene opens");
    editor.set_wall_clock(false);
    let path = root()
        .join("tests/fixtures/explore")
        .join(format!("{keys}.keys"));
    let text = std::fs::read_to_string(&path).expect("key script");
    let keys = parse_keys(&text, &path.display().to_string()).expect("keys parse");
    run_script(&mut editor, &keys, (100, 30));
    editor
}

/// Explore from the editor's state on a pool of `threads` threads.
fn explore_in(threads: usize, editor: &Editor, opts: &ExploreOptions) -> Exploration {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let start = Start::from_editor(editor);
    pool.install(|| explore::run(&start, opts, &Progress::default()))
        .expect("explores")
}

/// The values of the free controls.
fn controls(editor: &Editor) -> Vec<f64> {
    editor
        .controls()
        .values(editor.scene())
        .iter()
        .copied()
        .collect()
}

/// The body's position at time `t`.
fn position(editor: &Editor, body: usize, t: f64) -> Vector3<f64> {
    editor.trajectory().state(body, t, Side::Post).x
}

/// Nudge the ball's position at `t` by the whole way to `target` (the
/// solver takes what it can of it).
fn nudge_towards(editor: &mut Editor, target: &Vector3<f64>, t: f64) -> Outcome {
    let delta = target - position(editor, 0, t);
    editor
        .apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta,
        })
        .expect("nudge")
}

/// (a) Paper §5: at t = 1 s the drag of the ball to the right is blocked
/// at the ridge: no smooth motion gets nearer and the solver's sampling
/// finds none either. Exploring from there finds motions in other
/// collision sequences, among them one that bounces off the facet beyond
/// the ridge; accepted, it is the motion, and differential edits (nudges
/// towards the goal) continue from it. They used to pop out of it at the
/// first step the sequence refused: the solver's sampling found the goal
/// met, with a lower residual, by a throw whose bounce came only after
/// the drag's time.
#[test]
fn a_drag_blocked_at_the_ridge_continues_from_an_alternative_beyond_it() {
    let mut editor = replay("particle-polygon", "polygon-blocked");
    let goal = editor
        .pending_drag()
        .cloned()
        .expect("the last drag was blocked");
    let (Anchor::Time(t), Kind::State { target, .. }) = (goal.anchor, &goal.kind) else {
        panic!("a drag of a state at a time: {goal:?}");
    };
    let target = Vector3::new(target[0], target[1], target[2]);
    let miss = |e: &Editor| (target - position(e, 0, t)).norm();
    assert!(
        miss(&editor) > 0.1,
        "the drag was not met: {}",
        miss(&editor)
    );
    let first = editor.trajectory().events[0].clone();
    assert!(first.point.x < 0.0, "the bounce is left of the ridge");

    let opts = ExploreOptions {
        keep: 64,
        ..ExploreOptions::default()
    };
    let x = explore_in(2, &editor, &opts);
    assert!(x.goal.is_some() && x.worlds == opts.samples, "{x:?}");
    assert!(
        x.current.residual > 0.1,
        "current residual {}",
        x.current.residual
    );
    // The best alternative meets the goal that the gradients could not.
    let best = &x.alternatives[0];
    assert!(
        best.residual < 1e-6 && best.score < x.current.residual,
        "best alternative: {best:?}"
    );
    let beyond: &Alternative = x
        .alternatives
        .iter()
        .find(|a| {
            a.contacts
                .first()
                .is_some_and(|c| c.other == "hill" && c.feature == "face f2-3-9-10")
        })
        .unwrap_or_else(|| {
            panic!(
                "no alternative bounces beyond the ridge:\n{}",
                explore::text(editor.scene(), &x)
            )
        });
    assert!(
        beyond.description.contains("f2-3-9-10"),
        "{}",
        beyond.description
    );

    editor
        .apply(beyond.edit())
        .expect("the alternative is accepted");
    assert!(
        editor.pending_drag().is_none(),
        "accepting retires the goal"
    );
    assert_eq!(controls(&editor), beyond.controls);
    let bounce = &editor.trajectory().events[0];
    assert!(
        bounce.key.contains("f2-3-9-10") && bounce.point.x > 0.0,
        "the accepted motion bounces beyond the ridge: {} at {:?}",
        bounce.key,
        bounce.point
    );
    // Nudges towards the goal continue from the accepted world: each
    // stays in its collision sequence (no pop back to a bounce left of
    // the ridge, nor to one moved past the drag's time, though either
    // meets the goal with a lower residual) and gets closer to the goal,
    // until the sequence can go no further and the nudge says "blocked".
    let before = miss(&editor);
    let mut last = before;
    for nudge in 0..20 {
        let out = nudge_towards(&mut editor, &target, t);
        let solver = |f: fn(&Diagnostic) -> bool| {
            out.notes
                .iter()
                .any(|n| matches!(n, Note::Solver(d) if f(d)))
        };
        assert!(
            !solver(|d| matches!(d, Diagnostic::Pop { .. })),
            "nudge {nudge} popped out of the accepted world: {:?}",
            out.notes
        );
        let bounce = &editor.trajectory().events[0];
        assert!(
            bounce.key.contains("f2-3-9-10") && bounce.t < t,
            "nudge {nudge}: the bounce beyond the ridge is kept: {} at {}",
            bounce.key,
            bounce.t
        );
        assert!(miss(&editor) <= last, "nudge {nudge} moved away");
        last = miss(&editor);
        if solver(|d| matches!(d, Diagnostic::Blocked)) {
            break;
        }
    }
    assert!(
        last < 0.75 * before,
        "nudges from {before:.3} m got only to {last:.3} m from the goal"
    );
}

/// (a, continued) The drag's goal lies where a ball leaving the ridge's
/// top goes: the ball's radius rounds the ridge's edge, so its normal
/// turns through every direction between the two facets'. Sampled alone
/// (no polishing), the best alternative bounces on that edge instead of
/// the facet left of the ridge; accepted, it is where the user's nudges
/// towards the goal meet it, in a few differential edits and without
/// leaving that collision sequence.
#[test]
fn the_drag_blocked_at_the_ridge_is_met_by_nudges_from_the_sampled_ridge_bounce() {
    let mut editor = replay("particle-polygon", "polygon-blocked");
    let goal = editor.pending_drag().cloned().expect("a blocked drag");
    let (Anchor::Time(t), Kind::State { target, .. }) = (goal.anchor, &goal.kind) else {
        panic!("a drag of a state at a time: {goal:?}");
    };
    let target = Vector3::new(target[0], target[1], target[2]);
    let miss = |e: &Editor| (target - position(e, 0, t)).norm();
    let before = miss(&editor);
    let opts = ExploreOptions {
        polish: 0,
        ..ExploreOptions::default()
    };
    let x = explore_in(2, &editor, &opts);
    let best = &x.alternatives[0];
    assert_eq!(best.polished, 0, "as sampled");
    let first = best.contacts.first().expect("a bounce");
    assert!(
        first.other == "hill" && first.feature.starts_with("edge"),
        "the best sampled world bounces on an edge of the hill: {best:?}"
    );
    assert!(
        best.residual < before,
        "{} is nearer the goal than {before}",
        best.residual
    );
    editor.apply(best.edit()).expect("accepted");
    let ridge = editor.trajectory().events[0].clone();
    assert!(
        ridge.point.x.abs() < 1e-9,
        "it bounces on the ridge's top (x = 0): {:?}",
        ridge.point
    );
    let mut last = miss(&editor);
    for nudge in 0..10 {
        let out = nudge_towards(&mut editor, &target, t);
        assert!(
            !out.notes.iter().any(|n| matches!(
                n,
                Note::Solver(Diagnostic::Pop { .. } | Diagnostic::Blocked)
            )),
            "nudge {nudge}: {:?}",
            out.notes
        );
        assert_eq!(
            editor.trajectory().events[0].key,
            ridge.key,
            "nudge {nudge} keeps the bounce on the ridge's edge"
        );
        assert!(miss(&editor) < last, "nudge {nudge} moved away");
        last = miss(&editor);
        if last < 1e-9 {
            break;
        }
    }
    assert!(
        last < 1e-9,
        "the nudges met the goal to {last:.3e} m (from {before:.3} m)"
    );
}

/// (b) Paper §6, Figure 5a: from the unedited throw, with each egg nailed
/// over its bucket, exploring finds a motion in which the eggs meet in
/// the air and each lands in its own bucket; a settle from it meets both
/// nails to 1e-9 and keeps the collision. (Settling from the unedited
/// throw meets the nails too, but with the eggs never touching: that is
/// among the alternatives as well, polished from the current controls.)
#[test]
fn eggs_nailed_in_their_buckets_meet_in_the_air_after_exploring() {
    let mut editor = replay("eggs", "eggs-nailed");
    assert_eq!(editor.constraints().len(), 2, "two nails");
    let x = explore_in(2, &editor, &ExploreOptions::default());
    assert!(
        x.current.residual > 1.0,
        "the nails are far: {}",
        x.current.residual
    );
    let meets = |a: &&Alternative| {
        a.contacts
            .iter()
            .any(|c| c.body == "egg1" && c.other == "egg2")
    };
    let alt = x.alternatives.iter().find(meets).unwrap_or_else(|| {
        panic!(
            "no alternative where the eggs meet:\n{}",
            explore::text(editor.scene(), &x)
        )
    });
    assert!(
        alt.description.contains("egg1 now hits egg2"),
        "{}",
        alt.description
    );
    assert!(alt.residual < 0.05, "close to both nails: {alt:?}");
    assert!(
        x.alternatives
            .iter()
            .any(|a| a.same_as_current && a.sample.is_none()),
        "the gradients' own path is listed too"
    );

    editor
        .apply(alt.edit())
        .expect("the alternative is accepted");
    editor
        .apply(Edit::Settle { budget_ms: 500 })
        .expect("settles");
    let residual = editor.report()["residual"].as_f64().expect("residual");
    assert!(residual <= 1e-9, "settled residual {residual:.3e}");
    let egg = |name: &str| editor.scene().body_index(name).expect("egg");
    let (egg1, egg2) = (egg("egg1"), egg("egg2"));
    let meet = editor
        .trajectory()
        .events
        .iter()
        .find(|e| e.a == egg1 && e.b == Party::Body(egg2))
        .expect("the eggs still meet");
    assert!(meet.point.z > 1.0, "in the air: {:?}", meet.point);
    let end = editor.scene().duration;
    for (body, centre) in [(egg1, -1.1), (egg2, 1.1)] {
        let p = position(&editor, body, end);
        assert!(
            (p.x - centre).abs() < 0.25 && p.y.abs() < 0.25 && p.z < 0.3,
            "egg {body} ends at {p:?}, not in its bucket at x = {centre}"
        );
    }
}

/// (c) The same seed gives the same alternatives on one thread and on
/// two: samples draw from their own streams, reductions go in index order.
#[test]
fn one_and_two_threads_find_the_same_alternatives() {
    let opts = ExploreOptions {
        samples: 384,
        batch: 100,
        ..ExploreOptions::default()
    };
    for (scene, keys) in [
        ("particle-polygon", "polygon-blocked"),
        ("eggs", "eggs-nailed"),
    ] {
        let editor = replay(scene, keys);
        let one = explore_in(1, &editor, &opts);
        let two = explore_in(2, &editor, &opts);
        assert!(!one.alternatives.is_empty(), "{scene}");
        assert_eq!(one, two, "{scene}: 1 and 2 threads differ");
        let other = explore_in(
            2,
            &editor,
            &ExploreOptions {
                seed: opts.seed + 1,
                ..opts
            },
        );
        assert_ne!(
            one.alternatives, other.alternatives,
            "{scene}: another seed, other samples"
        );
    }
}

/// A sample whose style term alone scores it worse than the last group
/// that can be kept is not simulated, and that changes nothing offered:
/// explored in one batch (nothing pruned: the bar is set between batches)
/// and in batches of 64, the alternatives are the same, though without
/// constraints (a score that is the style term alone) samples of the wider
/// rounds are pruned, the same ones on one thread as on two.
#[test]
fn samples_too_far_to_be_kept_are_not_simulated_and_change_nothing() {
    let mut editor = Editor::open(&root().join("scenes/bounce.toml")).expect("scene opens");
    editor.set_wall_clock(false);
    let opts = ExploreOptions {
        samples: 512,
        batch: 512,
        ..ExploreOptions::default()
    };
    let whole = explore_in(2, &editor, &opts);
    let pruned = explore_in(2, &editor, &ExploreOptions { batch: 64, ..opts });
    assert_eq!(whole.pruned, 0, "{whole:?}");
    assert!(pruned.pruned > 0, "{pruned:?}");
    assert!(!whole.alternatives.is_empty());
    assert_eq!(whole.alternatives, pruned.alternatives);
    assert_eq!(whole.worlds, pruned.worlds);
    assert!(pruned.groups <= whole.groups);
    // The bar moves only between batches: one thread prunes the same.
    let one = explore_in(1, &editor, &ExploreOptions { batch: 64, ..opts });
    assert_eq!(one, pruned, "1 and 2 threads differ");
}

/// Progress is reported after every batch, and the cancel flag stops the
/// run after the batch in which it was set, returning what was found.
#[test]
fn progress_is_reported_and_a_cancel_stops_between_batches() {
    let editor = replay("particle-polygon", "polygon-blocked");
    let start = Start::from_editor(&editor);
    let opts = ExploreOptions {
        samples: 300,
        batch: 64,
        ..ExploreOptions::default()
    };
    let seen: RefCell<Vec<Tally>> = RefCell::new(Vec::new());
    let cancel = AtomicBool::new(false);
    let report = |t: &Tally| {
        seen.borrow_mut().push(*t);
        if t.worlds >= 128 {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let progress = Progress {
        cancel: Some(&cancel),
        report: Some(&report),
    };
    let x = explore::run(&start, &opts, &progress).expect("explores");
    let seen = seen.into_inner();
    let worlds: Vec<usize> = seen.iter().map(|t| t.worlds).collect();
    assert_eq!(worlds, [64, 128], "{seen:?}");
    assert!(
        x.cancelled && x.worlds == 128 && x.polish_updates == 0,
        "{x:?}"
    );
    assert!(!x.alternatives.is_empty());
    let best = seen.last().and_then(|t| t.best).expect("a best score");
    assert_eq!(best, x.alternatives[0].score, "the best so far is the best");

    // Without cancelling, all batches run and the last report has them all.
    let count = RefCell::new(0);
    let report = |t: &Tally| {
        *count.borrow_mut() += 1;
        assert!(t.worlds <= t.planned && t.failed + t.non_finite <= t.worlds);
    };
    let progress = Progress {
        cancel: None,
        report: Some(&report),
    };
    let x = explore::run(&start, &opts, &progress).expect("explores");
    assert!(!x.cancelled && x.worlds == 300);
    // Five batches and one report after polishing.
    assert_eq!(count.into_inner(), 6);
}

/// Accepting an alternative is one edit: undo restores the controls and
/// the motion, redo brings the alternative back, and values the controls
/// cannot take are refused with nothing changed.
#[test]
fn set_controls_is_undoable_and_checked() {
    let mut editor = replay("particle-polygon", "polygon-blocked");
    let u0 = controls(&editor);
    let end0 = position(&editor, 0, 1.0);
    let mut u = u0.clone();
    u[3] += 0.5;
    u[5] -= 0.25;
    editor.apply(Edit::SetControls(u.clone())).expect("applies");
    assert_eq!(controls(&editor), u);
    assert!(editor.dirty());
    let end = position(&editor, 0, 1.0);
    assert!((end - end0).norm() > 0.1, "the motion changed");
    editor.apply(Edit::Undo).expect("undo");
    assert_eq!(controls(&editor), u0, "undo restores the controls");
    assert_eq!(position(&editor, 0, 1.0), end0, "and the motion");
    editor.apply(Edit::Redo).expect("redo");
    assert_eq!(controls(&editor), u);

    for bad in [vec![0.0; 2], {
        let mut v = u.clone();
        v[0] = f64::NAN;
        v
    }] {
        let e = editor.apply(Edit::SetControls(bad)).expect_err("refused");
        assert!(!e.to_string().contains("NaN"), "{e}");
        assert_eq!(controls(&editor), u, "nothing changed");
    }
}

fn nudge_cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nudge"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("runs nudge")
}

/// `nudge explore` replays the keys, explores from the blocked drag and
/// prints the alternatives (as JSON here); bad input is a plain error.
#[test]
fn the_cli_explores_after_the_keys_and_refuses_bad_input() {
    // The blocked polygon drag, 256 worlds, seed 7, as JSON; then `extra`.
    let polygon = |extra: &[&str]| {
        let mut args = vec![
            "explore",
            "scenes/particle-polygon.toml",
            "--keys",
            "tests/fixtures/explore/polygon-blocked.keys",
            "--samples",
            "256",
            "--seed",
            "7",
            "--json",
        ];
        args.extend(extra);
        nudge_cli(&args)
    };
    let out = polygon(&[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !stdout.contains("NaN") && !stdout.contains("inf"),
        "{stdout}"
    );
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("JSON");
    assert_eq!(v["worlds"], 256);
    assert!(
        v["goal"]["what"]
            .as_str()
            .is_some_and(|g| g.contains("drag of ball"))
    );
    let alts = v["alternatives"].as_array().expect("alternatives");
    assert!(!alts.is_empty());
    for a in alts {
        assert_eq!(a["controls"].as_array().map(Vec::len), Some(6), "{a}");
        assert!(a["score"].as_f64().is_some() && a["description"].is_string());
        assert!(a["signature"].is_array());
    }

    // --keep prints the best few of the same exploration.
    let kept = polygon(&["--keep", "1"]);
    let k: serde_json::Value = serde_json::from_slice(&kept.stdout).expect("JSON");
    let first = k["alternatives"].as_array().expect("alternatives");
    assert_eq!(first.len(), 1);
    assert_eq!(first[0]["controls"], alts[0]["controls"]);

    let text = nudge_cli(&["explore", "scenes/bounce.toml", "--samples", "64"]);
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(text.status.success(), "{stdout}");
    assert!(
        stdout.starts_with("explore bounce: 64 worlds sampled"),
        "{stdout}"
    );
    assert!(stdout.contains("what differs") && stdout.contains("controls:"));

    let bad = nudge_cli(&["explore", "scenes/bounce.toml", "--samples", "0"]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("samples must be at least 1, got 0"), "{err}");
    let bad = nudge_cli(&[
        "explore",
        "scenes/bounce.toml",
        "--keys",
        "tests/fixtures/explore/missing.keys",
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("reading the key script"), "{err}");
}

/// The blocked-drag key script of the polygonal hill and a fresh editor
/// on its scene.
fn polygon() -> (String, Editor) {
    let blocked =
        std::fs::read_to_string(root().join("tests/fixtures/explore/polygon-blocked.keys"))
            .expect("fixture");
    let mut editor =
        Editor::open(&root().join("scenes/particle-polygon.toml")).expect("scene opens");
    editor.set_wall_clock(false);
    (blocked, editor)
}

/// From the editor's keys: `X` after the blocked drag explores (the replay
/// waits for the background thread), the alternatives are listed one at a
/// time, Enter takes the one shown as an undoable edit and `u` undoes it.
#[test]
fn the_editor_explores_in_the_background_and_takes_an_alternative() {
    let blocked =
        std::fs::read_to_string(root().join("tests/fixtures/explore/polygon-blocked.keys"))
            .expect("fixture");
    let mut editor = polygon().1;
    let keys =
        parse_keys(&format!("{blocked}\n:explore 512<Enter>"), "explore.keys").expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    assert!(
        r.screen.contains("X explores") || r.screen.contains("alternative 1/"),
        "{}",
        r.screen
    );
    let last = r.screen.lines().last().unwrap_or_default();
    assert!(last.contains("alternative 1/"), "{}", r.screen);
    let before = controls(&editor);
    // Same script, then the second alternative is taken and undone.
    let mut editor = polygon().1;
    let keys = parse_keys(
        &format!("{blocked}\n:explore 512<Enter> j <Enter>"),
        "explore.keys",
    )
    .expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    assert!(r.screen.contains("took alternative 2"), "{}", r.screen);
    let taken = controls(&editor);
    assert_ne!(taken, before);
    editor.apply(Edit::Undo).expect("undo");
    assert_eq!(controls(&editor), before);
    // Esc dismisses without changing anything.
    let mut editor = polygon().1;
    let keys = parse_keys(
        &format!("{blocked}\n:explore 512<Enter> <Esc>"),
        "explore.keys",
    )
    .expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    assert!(r.screen.contains("alternatives dismissed"), "{}", r.screen);
    assert_eq!(controls(&editor), before);
    assert!(!r.quit);
}

/// `S` takes the alternative shown and settles from it in one key: from
/// the eggs' unedited throw with a nail over each bucket, the first
/// alternative is taken (one undoable edit) and the settle meets both
/// nails.
#[test]
fn s_takes_the_alternative_and_settles_from_it() {
    let mut editor = replay("eggs", "eggs-nailed");
    let before = editor.report()["residual"].as_f64().expect("residual");
    assert!(before > 1.0, "the nails are far: {before}");
    let keys = parse_keys(":explore<Enter> S :messages<Enter>", "s.keys").expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    let residual = editor.report()["residual"].as_f64().expect("residual");
    assert!(
        residual <= 1e-9,
        "settled residual {residual:.3e}:\n{}",
        r.screen
    );
    // The log says what happened, though the edit's warnings took the line.
    assert!(
        r.screen.contains("took alternative 1") && r.screen.contains("settling from it"),
        "{}",
        r.screen
    );
    // The taken eggs end in their buckets: the settle's error estimate
    // never asks for a tolerance tighter than the scene's 1e-9 (where its
    // finer run meets other contacts, it says that instead:
    // `estimate::tests`).
    assert!(!r.screen.contains("tighter tol"), "{}", r.screen);
    // Undo the settle, then the take: back to the unedited throw.
    editor.apply(Edit::Undo).expect("undo the settle");
    editor.apply(Edit::Undo).expect("undo the take");
    let back = editor.report()["residual"].as_f64().expect("residual");
    assert_eq!(back, before, "two undos restore the throw");
}

/// While alternatives are shown, the editing keys they do not rebind still
/// work: `:` opens the command line (Enter runs it, not "take"), and an
/// edit of the motion dismisses them.
#[test]
fn browsing_alternatives_keeps_the_command_line_and_an_edit_dismisses_them() {
    let blocked =
        std::fs::read_to_string(root().join("tests/fixtures/explore/polygon-blocked.keys"))
            .expect("fixture");
    let mut editor = polygon().1;
    let before = {
        let keys = parse_keys(&blocked, "b.keys").expect("keys");
        run_script(&mut editor, &keys, (100, 30));
        controls(&editor)
    };
    let keys = parse_keys(":explore 256<Enter> :messages<Enter>", "e.keys").expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    assert!(r.screen.contains("messages: j/k scroll"), "{}", r.screen);
    assert_eq!(
        controls(&editor),
        before,
        "Enter ran :messages, took nothing"
    );
    let keys = parse_keys("<Esc> :explore 256<Enter> P l", "e.keys").expect("keys");
    let r = run_script(&mut editor, &keys, (100, 30));
    assert!(!r.screen.contains("alternative 1/"), "{}", r.screen);
}
