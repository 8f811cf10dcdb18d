//! `nudge bench` prints sane tables. Benchmarks are benchmarks: these tests
//! check the shape of the output (headers, counts, finite positive times,
//! the summary line), never how long anything took.

use nudge::bench::{BenchArgs, run};

fn bench(only: &str) -> String {
    let args = BenchArgs {
        quick: true,
        csv: None,
        only: Some(only.into()),
    };
    let mut out = Vec::new();
    if let Err(e) = run(&args, &mut out) {
        panic!("bench --only {only}: {e}");
    }
    String::from_utf8(out).unwrap_or_else(|e| panic!("output is not UTF-8: {e}"))
}

/// The rows of the table under the section heading `== name:` (header and
/// rule skipped), split on runs of spaces (an empty leading cell, as in a
/// row continuing a group, is dropped).
fn table_rows(text: &str, name: &str) -> Vec<Vec<String>> {
    let section: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with(&format!("== {name}:")))
        .skip(1)
        .take_while(|l| !l.starts_with("== "))
        .collect();
    // A section may open with a line of prose before its table.
    let start = (0..section.len().saturating_sub(1))
        .find(|&i| section[i + 1].trim_start().starts_with("---"))
        .unwrap_or(0);
    let mut lines = section.into_iter().skip(start);
    let header = lines.next().unwrap_or_default();
    assert!(
        header.starts_with("  "),
        "table header under {name}: {header:?}"
    );
    let rule = lines.next().unwrap_or_default();
    assert!(
        rule.trim_start().starts_with("---"),
        "rule under the header: {rule:?}"
    );
    lines
        .take_while(|l| {
            l.starts_with("  ") && l.split("  ").filter(|c| !c.trim().is_empty()).count() > 2
        })
        .map(|l| {
            l.split("  ")
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .map(String::from)
                .collect()
        })
        .collect()
}

fn no_nan(text: &str) {
    for bad in ["NaN", "inf"] {
        assert!(!text.contains(bad), "{bad} in the output:\n{text}");
    }
}

fn positive_ms(cell: &str, what: &str) {
    let v: f64 = cell
        .parse()
        .unwrap_or_else(|_| panic!("{what}: {cell:?} is not a number"));
    assert!(v > 0.0 && v.is_finite(), "{what}: {v}");
}

/// Every effect switched off is evaluated 0 times, and when on it is
/// evaluated (the tossed box flies, spins, lands and slides).
#[test]
fn effects_off_are_never_evaluated() {
    let text = bench("effects");
    no_nan(&text);
    assert!(text.starts_with("nudge bench --quick:"), "{text}");
    assert!(
        text.contains("== effects: each effect switched off and on"),
        "{text}"
    );
    assert!(
        !text.contains("== jacobian"),
        "--only runs one section:\n{text}"
    );
    let rows = table_rows(&text, "effects");
    let names: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        names,
        ["gravity", "drag", "gyroscopic", "collisions", "friction"],
        "{text}"
    );
    for r in &rows {
        assert_eq!(
            r.len(),
            8,
            "effect, off ms/evals/events, on ms/evals/events, reps: {r:?}"
        );
        positive_ms(&r[1], "time with the effect off");
        positive_ms(&r[4], "time with the effect on");
        assert_eq!(r[2], "0", "{} off must not be evaluated: {r:?}", r[0]);
        let on: u64 = r[5].parse().unwrap_or(0);
        assert!(on > 0, "{} on must be evaluated: {r:?}", r[0]);
    }
    let last = text.lines().last().unwrap_or_default();
    assert_eq!(
        last,
        "summary: tangent vs central differences: not measured (run the jacobian or methods section)"
    );
}

/// The latency section replays every paper session (compiled in) and
/// shows where each session's update time goes.
#[test]
fn latency_replays_every_paper_session_with_its_parts() {
    let text = bench("latency");
    no_nan(&text);
    let rows = table_rows(&text, "latency");
    let names: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        names,
        [
            "eggs",
            "plank",
            "mug",
            "scissors",
            "scissors-bounce",
            "particle-parabola",
            "particle-polygon"
        ],
        "{text}"
    );
    for r in &rows {
        assert_eq!(r.len(), 12, "{r:?}");
        assert!(r[1].parse::<usize>().is_ok_and(|n| n > 0), "{r:?}");
        // The five shares are percentages that add up to at most 100 %.
        let shares: Vec<f64> = r[5..10]
            .iter()
            .map(|c| c.trim_end_matches('%').parse::<f64>().expect("a share"))
            .collect();
        assert!(shares.iter().sum::<f64>() <= 100.0 + 5.0, "{r:?}");
    }
    // Then `l` held on every paper scene: 40 presses, each timed to its
    // frame, and the target's tally.
    let held: Vec<Vec<&str>> = text
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("scene  "))
        .skip(2)
        .take_while(|l| !l.trim_start().starts_with("target:"))
        .map(|l| {
            l.split("  ")
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .collect()
        })
        .collect();
    let held_names: Vec<&str> = held.iter().map(|r| r[0]).collect();
    assert_eq!(held_names.len(), 7, "{text}");
    assert!(names.iter().all(|n| held_names.contains(n)), "{text}");
    for r in &held {
        assert_eq!(r.len(), 7, "{r:?}");
        assert_eq!(r[1], "40", "every press reaches the core: {r:?}");
        let times: Vec<f64> = r[3..7].iter().map(|c| c.parse().expect("ms")).collect();
        assert!(times[0] <= times[1] && times[1] <= times[2], "{r:?}");
    }
    assert!(
        text.contains("target: key→frame p95 ≤ 16 ms: met on "),
        "{text}"
    );
    assert!(
        text.lines()
            .last()
            .unwrap_or_default()
            .starts_with("summary: tangent vs central differences: ")
    );
}

/// An unknown section name lists the sections and still ends with the summary.
#[test]
fn unknown_section_lists_the_sections() {
    let text = bench("no-such-section");
    assert!(text.contains("no section matches --only \"no-such-section\"; sections: jacobian, work-precision, methods, scaling, effects, latency, cliffs, explore"), "{text}");
    assert!(
        text.lines()
            .last()
            .unwrap_or_default()
            .starts_with("summary: ")
    );
}

/// The explore section samples worlds on every paper scene, from its
/// unedited motion and from where its paper session leaves the editor,
/// counts the worlds it did not need to simulate, and states the target
/// for single-body scenes.
#[test]
fn explore_counts_worlds_per_second_per_scene() {
    let text = bench("explore");
    no_nan(&text);
    let rows = table_rows(&text, "explore");
    let names: Vec<String> = rows.iter().map(|r| r[0].replace('*', "")).collect();
    let scenes = [
        "eggs",
        "plank",
        "mug",
        "scissors",
        "scissors-bounce",
        "particle-parabola",
        "particle-polygon",
    ];
    let want: Vec<String> = scenes
        .iter()
        .flat_map(|s| [s.to_string(), format!("{s} session")])
        .collect();
    assert_eq!(names, want, "{text}");
    for r in &rows {
        assert_eq!(r.len(), 10, "{r:?}");
        assert_eq!(r[4], "256", "worlds: {r:?}");
        let pruned: usize = r[5].parse().unwrap_or(usize::MAX);
        assert!(pruned < 256, "some worlds are simulated: {r:?}");
        let sequences: usize = r[7].parse().unwrap_or(0);
        assert!(sequences >= 1, "at least one collision sequence: {r:?}");
        positive_ms(&r[9], "worlds/s");
    }
    for what in ["whole motions", "after the sessions"] {
        assert!(
            text.contains(&format!(
                "  target: ≥ 2000 worlds/s for single-body scenes, {what}: met on "
            )),
            "{text}"
        );
    }
}

/// The scaling sweeps print finite positive times and a growth exponent
/// for each sweep.
#[test]
fn scaling_prints_times_and_exponents() {
    let text = bench("scaling");
    no_nan(&text);
    let rows = table_rows(&text, "scaling");
    assert!(
        rows.len() >= 9,
        "three sweeps of at least three points:\n{text}"
    );
    for r in &rows {
        let time = &r[r.len() - 3];
        positive_ms(time, "sim+J");
    }
    for what in ["N", "T", "m"] {
        assert!(
            text.contains(&format!("  time ∝ {what}^")),
            "exponent of {what}:\n{text}"
        );
    }
    // Balls that settle at restitution 0.5 and 0.8 run without an error.
    assert!(
        text.contains("Balls in a box at restitution e") && !text.contains("error"),
        "{text}"
    );
}

/// The methods section compares all three methods on every paper scene and
/// the run ends with the summary line.
#[test]
fn methods_and_the_summary_line() {
    let text = bench("methods");
    no_nan(&text);
    let rows = table_rows(&text, "methods");
    let names: Vec<&str> = rows.iter().map(|r| r[0].trim_end_matches('*')).collect();
    assert_eq!(
        names,
        [
            "eggs",
            "plank",
            "mug",
            "scissors",
            "scissors-bounce",
            "particle-parabola",
            "particle-polygon"
        ],
        "{text}"
    );
    for r in &rows {
        assert_eq!(r.len(), 10, "{r:?}");
        positive_ms(&r[2], "tangent");
        positive_ms(&r[4], "central");
        positive_ms(&r[7], "forward");
        // The tangent over central's columns is no worse than over all.
        if let (Ok(all), Ok(same)) = (r[3].parse::<f64>(), r[6].parse::<f64>()) {
            assert!(same <= all, "{r:?}");
        }
    }
    let last = text.lines().last().unwrap_or_default();
    let rest = last
        .strip_prefix("summary: tangent vs central differences: ")
        .unwrap_or_else(|| panic!("{last}"));
    let (speed, rest) = rest
        .split_once("x faster, ")
        .unwrap_or_else(|| panic!("{last}"));
    let (accuracy, rest) = rest
        .split_once("x more accurate")
        .unwrap_or_else(|| panic!("{last}"));
    assert_eq!(rest, " (median over scenes)");
    for v in [speed, accuracy] {
        let v: f64 = v.parse().unwrap_or_else(|_| panic!("{v:?} in {last}"));
        assert!(v > 0.0 && v.is_finite());
    }
}

/// The cliffs section counts the events of a fine ellipsoid rocking to
/// rest: hundreds per body today (micro-collisions), each row with a time.
#[test]
fn cliffs_count_the_rocking_events() {
    let text = bench("cliffs");
    let rows = table_rows(&text, "cliffs");
    assert!(rows.len() >= 2, "{text}");
    for r in &rows {
        let events: usize = r[2].parse().expect("an event count");
        assert!(events > 10, "it rocks: {r:?}");
        positive_ms(&r[4], "sim");
    }
    no_nan(&text);
}
