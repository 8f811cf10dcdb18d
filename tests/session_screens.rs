//! Whole screens of real scripted sessions (the editor core, key map and
//! renderer together), pinned as insta snapshots. Latencies are the only
//! non-deterministic text on screen and are masked.

use nudge::edit::Editor;
use nudge::script::{parse_keys, run_script};

fn screen(scene: &str, keys: &str, size: (u16, u16)) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let mut editor = Editor::open(&path).expect("scene opens");
    let keys = parse_keys(keys, "inline").expect("keys parse");
    let out = run_script(&mut editor, &keys, size);
    mask_latency(&out.screen)
}

/// Replace `upd 12.34ms` with `upd ‹ms›`.
fn mask_latency(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("upd ") {
        out.push_str(&rest[..i + 4]);
        rest = &rest[i + 4..];
        match rest.find("ms") {
            Some(j) if j < 12 => {
                out.push_str("‹ms›");
                rest = &rest[j + 2..];
            }
            _ => {}
        }
    }
    out.push_str(rest);
    out
}

#[test]
fn bounce_after_a_drag_and_a_nail() {
    let s = screen(
        "scenes/bounce.toml",
        "]]]]]]]]]] # a tenth of the way in\n lll kk # drag the ball right and up\n a # nail it\n 2 # side view\n",
        (80, 24),
    );
    insta::assert_snapshot!(s);
}

/// The readout, a nail's target (⊕), the motion before the last drag
/// (dotted) and the rocking at the end grouped on the timeline (┼×N).
#[test]
fn bounce_readout_target_ghost_and_grouped_contacts() {
    let s = screen("scenes/bounce.toml", "]]]]]]]]]] LL ]]]]] a", (80, 24));
    insta::assert_snapshot!(s);
}

#[test]
fn help_popup_lists_the_keys() {
    let s = screen("scenes/bounce.toml", "?", (80, 24));
    insta::assert_snapshot!(s);
}

#[test]
fn too_small_terminal_says_so() {
    let s = screen("scenes/bounce.toml", "l", (40, 10));
    assert!(s.contains("terminal too small"), "{s}");
    insta::assert_snapshot!(s);
}

/// The Jacobian popup (`I`) reads the tangents: in free flight a unit of
/// initial velocity moves the body by t (here 0.075 s) and does not turn
/// it; a unit of initial orientation turns it by 1 rad = 57.3°.
#[test]
fn the_jacobian_popup_shows_free_flight_sensitivities() {
    let s = screen("scenes/eggs.toml", "]]]]] I", (100, 40));
    let row = |name: &str| {
        s.lines()
            .find(|l| l.contains(name))
            .unwrap_or_else(|| panic!("no row {name}:\n{s}"))
            .to_string()
    };
    let v = row("egg1.velocity.x");
    assert!(v.contains(" 0.075 ") && v.contains('█'), "{v}");
    let r = row("egg1.orientation.y");
    assert!(r.contains(" 57.3 "), "{r}");
    assert!(s.contains("egg1 at t=0.075"), "{s}");
}

/// `:accuracy` on the bounce: five settings around rk4 h=1e-3 measured
/// against the reference, timed by the headless runner's stub clock (so
/// the times are fixed), the current one marked, the front highlighted.
#[test]
fn accuracy_popup_on_the_bounce() {
    let s = screen("scenes/bounce.toml", ":accuracy<Enter>", (80, 24));
    insta::assert_snapshot!(s);
}

/// Exploring the drag blocked at the ridge of the polygonal hill: the
/// alternative shown is drawn dotted over the motion, and the status line
/// gives its rank, what differs from the motion, its score and events,
/// and the keys that browse, take (Enter; S settles too) or dismiss them.
#[test]
fn alternatives_after_exploring_the_blocked_drag() {
    let blocked = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/explore/polygon-blocked.keys"),
    )
    .expect("fixture");
    let s = screen(
        "scenes/particle-polygon.toml",
        &format!("{blocked}\n:explore 512<Enter>"),
        (80, 24),
    );
    assert!(s.contains("alternative 1/"), "{s}");
    insta::assert_snapshot!(s);
}
