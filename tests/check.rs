//! `nudge check --jacobian` reports what it compared: a block whose
//! perturbed runs the simulator refuses, a grazing contact and a changed
//! collision sequence are each named, the command exits 0, and every
//! figure is per state quantity. Scenes in `tests/fixtures/check/` and
//! `tests/hard/`.

use std::process::Command;

/// `nudge check ARGS FILE`: exit status and standard output.
fn check(args: &[&str], file: &str) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .arg("check")
        .args(args)
        .arg(file)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run nudge");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The rows of the jacobian table, trailing spaces trimmed.
fn table(out: &str) -> Vec<&str> {
    out.lines()
        .skip_while(|l| !l.starts_with("jacobian:"))
        .collect()
}

/// A ball resting on the floor with its position free used to make
/// `check --jacobian` exit 1 ("starts 6.1e-6 m inside floor"): the downward
/// perturbation is refused. Now that column is one-sided and says so.
#[test]
fn a_body_resting_on_the_floor_is_checked_one_sided_not_failed() {
    let (code, out) = check(&["--jacobian"], "tests/fixtures/check/ball-resting.toml");
    assert_eq!(code, Some(0), "{out}");
    let rows = table(&out);
    assert_eq!(
        rows[1],
        "  block                      at       position orientation   velocity    ang.vel"
    );
    assert!(
        rows.contains(&"  note: ball.position.z: one-sided difference (first order), the other side was refused: body \"ball\" starts 6.1e-6 m inside \"floor\"; bodies must not overlap what they collide with at t = 0"),
        "{out}"
    );
}

/// A box resting flat: turning it either way pushes a corner into the
/// floor, so its orientation block is not comparable, and says why.
#[test]
fn a_block_refused_on_both_sides_is_marked_not_failed() {
    let (code, out) = check(&["--jacobian"], "tests/fixtures/check/box-resting.toml");
    assert_eq!(code, Some(0), "{out}");
    let rows = table(&out);
    let at = rows
        .iter()
        .position(|r| r.starts_with("  box.orientation"))
        .expect("the orientation block");
    assert_eq!(rows[at], "  box.orientation            final  n/c refused");
    assert_eq!(
        rows[at + 1],
        "                             events n/c refused"
    );
    assert!(
        out.contains("  note: n/c refused: the perturbed runs were refused: body \"box\" starts"),
        "{out}"
    );
    assert!(
        out.contains("¹ one-sided difference: first order in the step"),
        "{out}"
    );
}

/// A grazing contact takes the grazer's Jacobian from event 0: the
/// bystander's event figures used to print `0.00e0` (nothing compared,
/// reading as perfect agreement); they now name the grazing event, in text
/// and in JSON, while its final-time figures are compared.
#[test]
fn a_block_with_nothing_compared_names_the_grazing_event() {
    let file = "tests/hard/graze-two-balls.toml";
    let (code, out) = check(&["--jacobian"], file);
    assert_eq!(code, Some(0), "{out}");
    let rows = table(&out);
    let at = rows
        .iter()
        .position(|r| r.starts_with("  bystander.position"))
        .expect("the bystander block");
    assert!(rows[at].contains(" final "), "{}", rows[at]);
    assert!(!rows[at].contains("n/c"), "final is compared: {}", rows[at]);
    assert_eq!(
        rows[at + 1],
        "                             events n/c grazing #0"
    );
    assert!(!out.contains("0.00e0"), "{out}");

    let (code, out) = check(&["--jacobian", "--json"], file);
    assert_eq!(code, Some(0));
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let blocks = v["jacobian_check"]["blocks"].as_array().expect("blocks");
    let bystander = blocks
        .iter()
        .find(|b| b["block"] == "bystander.position")
        .expect("bystander");
    assert_eq!(bystander["events"]["compared"], false);
    assert_eq!(bystander["events"]["label"], "n/c grazing #0");
    assert_eq!(bystander["final"]["compared"], true);
    for q in ["position", "orientation", "velocity", "angular_velocity"] {
        let w = bystander["final"][q]
            .as_f64()
            .expect("a number per quantity");
        assert!((0.0..1e-6).contains(&w), "{q}: {w}");
    }
}

/// Per quantity: a bouncing ball's position rows agree to round-off and
/// its orientation rows are exactly zero (nothing turns it).
#[test]
fn figures_are_per_state_quantity() {
    let (code, out) = check(&["--jacobian"], "scenes/bounce.toml");
    assert_eq!(code, Some(0), "{out}");
    let rows = table(&out);
    let at = rows
        .iter()
        .position(|r| r.starts_with("  ball.velocity"))
        .expect("the velocity block");
    let cells: Vec<&str> = rows[at].split_whitespace().collect();
    assert_eq!(cells.len(), 6, "{}", rows[at]);
    let position: f64 = cells[2].parse().expect("a number");
    assert!(position < 1e-6, "{}", rows[at]);
    assert_eq!(cells[3], "0", "no orientation dependence");
}

/// An asymmetric box spinning at ~350 rad/s for 10 s at the default RK4
/// step is off by ~3e-4 rad and ~0.07 rad/s; nothing said so. `check` now
/// prints the estimate and a warning above the threshold, and the JSON
/// report carries both.
#[test]
fn a_fast_spin_at_the_default_step_is_reported_as_inaccurate() {
    let file = "tests/fixtures/check/fast-spin.toml";
    let (code, out) = check(&[], file);
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("integration error (estimated by step halving): position 0.0e0 m, orientation 3.4e-4 rad, velocity 0.0e0 m/s, angular velocity 7.5e-2 rad/s"),
        "{out}"
    );
    assert!(
        out.contains("warning: estimated integration error 7.5e-2 rad/s in angular velocity (2e-4 relative, above 1e-4): use a smaller step or method = \"adaptive\" with a tighter tol"),
        "{out}"
    );
    let (_, out) = check(&["--json"], file);
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(v["integration_error"]["exceeds"], true);
    assert_eq!(v["integration_error"]["method"], "step halving");
    assert!(
        v["diagnostics"][0]
            .as_str()
            .unwrap_or("")
            .starts_with("estimated integration error")
    );
    // A gentle throw is well within it.
    let (_, out) = check(&[], "scenes/bounce.toml");
    assert!(
        out.contains("integration error (estimated by step halving)"),
        "{out}"
    );
    assert!(!out.contains("warning:"), "{out}");
}
