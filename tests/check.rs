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
        out.contains("warning: estimated integration error 7.5e-2 rad/s in angular velocity (2e-4 relative, above 1e-4): use a smaller step than 1e-3 s or method = \"adaptive\""),
        "{out}"
    );
    let (_, out) = check(&["--json"], file);
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(v["integration_error"]["exceeds"], true);
    assert_eq!(v["integration_error"]["method"], "step halving");
    assert_eq!(v["integration_error"]["cause"], "step");
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

/// `check --jacobian --json` with `--at` times, and the CSV beside it.
fn jacobian_data(file: &str, at: &[&str], csv: &str) -> serde_json::Value {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(csv);
    let mut args = vec!["--jacobian", "--json"];
    for t in at {
        args.extend(["--at", t]);
    }
    let csv_arg = path.display().to_string();
    args.extend(["--csv", &csv_arg]);
    let (code, out) = check(&args, file);
    assert_eq!(code, Some(0), "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    v["jacobian"].clone()
}

/// A CSV row: its label and cells, an empty cell as `None`.
type CsvRow = (String, Vec<Option<f64>>);

/// The CSV's header and rows.
fn read_csv(name: &str) -> (Vec<String>, Vec<CsvRow>) {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let text = std::fs::read_to_string(&path).expect("the CSV was written");
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| {
            let mut cells = l.split(',');
            let label = cells.next().expect("a label").to_string();
            let values = cells
                .map(|c| (!c.is_empty()).then(|| c.parse::<f64>().expect("a number")))
                .collect();
            (label, values)
        })
        .collect();
    (header, rows)
}

/// The eggs' Jacobian at two times: 24 rows per time (2 bodies × 4
/// quantities × 3), one column per free control in the control vector's
/// order; a column equals a central difference taken here through the
/// library (orientation as the exp-map vector's difference); the CSV holds
/// the same numbers bit for bit.
#[test]
fn the_jacobian_is_data_in_json_and_csv() {
    use nudge::controls::Controls;
    use nudge::sim::{Side, SimOptions, simulate};

    let j = jacobian_data("scenes/eggs.toml", &["0.75", "1.5"], "eggs-jacobian.csv");
    let scene = nudge::scene::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/eggs.toml"
    )))
    .expect("eggs loads");
    let controls = Controls::new(&scene);
    let names: Vec<String> = controls
        .free
        .iter()
        .map(|&i| controls.entries[i].name.clone())
        .collect();
    assert_eq!(j["controls"], serde_json::json!(names));
    assert_eq!(j["times"], serde_json::json!([0.75, 1.5]));
    let rows: Vec<&str> = j["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|r| r.as_str().expect("a label"))
        .collect();
    assert_eq!(rows.len(), 48);
    assert_eq!(rows[0], "egg1.position.x@0.75");
    assert_eq!(rows[5], "egg1.orientation.z@0.75");
    assert_eq!(rows[12], "egg2.position.x@0.75");
    assert_eq!(rows[47], "egg2.angular_velocity.z@1.5");
    let matrix = j["matrix"].as_array().expect("matrix");
    assert_eq!(matrix.len(), rows.len());
    let value = |r: usize, c: usize| matrix[r][c].as_f64().expect("a finite number");
    for row in matrix {
        assert_eq!(row.as_array().expect("a row").len(), names.len());
    }

    // A central difference of egg1's spin about y, through the library.
    let col = names
        .iter()
        .position(|n| n == "egg1.angular_velocity.y")
        .expect("a free control");
    let h = 1e-5;
    let run = |sign: f64| {
        let mut s = scene.clone();
        let u = controls.values(&scene);
        controls.set(&mut s, controls.free[col], u[col] + sign * h);
        simulate(&s, &controls, &SimOptions::without_tangents()).expect("simulates")
    };
    let (plus, minus) = (run(1.0), run(-1.0));
    assert_eq!(plus.signature(), minus.signature(), "no event changes");
    let (mut diff, mut norm) = (0.0_f64, 0.0_f64);
    for (ti, t) in [0.75, 1.5].into_iter().enumerate() {
        for b in 0..2 {
            let (p, m) = (plus.state(b, t, Side::Post), minus.state(b, t, Side::Post));
            let r = |s: &nudge::sim::BodyState| s.orientation_vector();
            let parts = [p.x - m.x, r(&p) - r(&m), p.v - m.v, p.w - m.w];
            for (k, d) in parts.iter().flat_map(|v| v.iter()).enumerate() {
                let fd = d / (2.0 * h);
                let tangent = value(24 * ti + 12 * b + k, col);
                diff = diff.max((tangent - fd).abs());
                norm = norm.max(fd.abs());
            }
        }
    }
    assert!(norm > 0.1, "the spin moves egg1: {norm}");
    assert!(
        diff < 1e-5 * norm,
        "tangent vs difference: {diff} of {norm}"
    );
    let checked = &j["columns"][col];
    assert_eq!(checked["control"], "egg1.angular_velocity.y");
    assert_eq!(checked["comparable"], true);
    assert_eq!(checked["rows_compared"], 48);
    assert!(checked["disagreement"].as_f64().expect("a number") < 1e-4);

    let (header, csv_rows) = read_csv("eggs-jacobian.csv");
    assert_eq!(header[0], "row");
    assert_eq!(header[1..], names[..]);
    assert_eq!(csv_rows.len(), rows.len());
    // Both files hold shortest round-trip numbers; serde_json's default
    // parser may round the last bit (Rust's `parse` does not): one ulp.
    for (r, (label, cells)) in csv_rows.iter().enumerate() {
        assert_eq!(label, rows[r]);
        assert_eq!(cells.len(), names.len());
        for (c, cell) in cells.iter().enumerate() {
            let (a, b) = (cell.expect("a number"), value(r, c));
            assert!(
                (a - b).abs() <= f64::EPSILON * a.abs(),
                "{label} {}: {a} vs {b}",
                names[c]
            );
        }
    }
}

/// A grazing contact took the grazer's Jacobian: its rows are `null` with
/// the reason (and empty in the CSV); the bystander's are numbers.
#[test]
fn a_grazed_body_has_null_rows_with_the_reason() {
    let j = jacobian_data("tests/hard/graze-two-balls.toml", &[], "graze.csv");
    assert_eq!(j["times"], serde_json::json!([1.0]));
    let rows = j["rows"].as_array().expect("rows");
    let (header, csv_rows) = read_csv("graze.csv");
    let mut nulls = 0;
    for (r, label) in rows.iter().enumerate() {
        let label = label.as_str().expect("a label");
        let row = &j["matrix"][r];
        if label.starts_with("grazer.") {
            assert!(row.is_null(), "{label}: {row}");
            let why = j["reasons"][label].as_str().expect("a reason");
            assert!(why.starts_with("grazing contact at event 0"), "{why}");
            assert!(csv_rows[r].1.iter().all(Option::is_none), "{label}");
            nulls += 1;
        } else {
            assert!(j["reasons"].get(label).is_none(), "{label}");
            let numbers = row.as_array().expect("numbers");
            assert!(numbers.iter().all(serde_json::Value::is_f64), "{label}");
            assert_eq!(csv_rows[r].1.len(), header.len() - 1);
        }
    }
    assert_eq!(nulls, 12);
}

/// A time outside the motion is refused with the range; `--at` and
/// `--csv` need `--jacobian`.
#[test]
fn a_jacobian_time_outside_the_motion_is_refused() {
    let (code, out) = check(&["--jacobian", "--at", "6"], "scenes/bounce.toml");
    assert_eq!(code, Some(1), "{out}");
    let err = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .args(["check", "scenes/bounce.toml", "--jacobian", "--at", "6"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run nudge");
    assert_eq!(
        String::from_utf8_lossy(&err.stderr),
        "nudge: --at 6: outside the motion; give a time in s from 0 to 5, e.g. --at 5\n"
    );
    let (code, _) = check(&["--csv", "x.csv"], "scenes/bounce.toml");
    assert_eq!(code, Some(2), "clap refuses --csv without --jacobian");
}
