//! Tests of the command-line parser and the command table.

use super::table::COMMANDS;
use super::*;

fn err(line: &str) -> String {
    match parse(line) {
        Ok(c) => panic!("{line} parsed as {c:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn numbers_are_strict() {
    assert_eq!(
        err("set tol nan"),
        ":set tol nan: expected a finite positive number"
    );
    assert_eq!(
        err("set tol inf"),
        ":set tol inf: expected a finite positive number"
    );
    assert_eq!(
        err("set tol -1e-9"),
        ":set tol -1e-9: expected a finite positive number"
    );
    assert_eq!(
        err("set step 1e-3x"),
        ":set step 1e-3x: expected a finite positive number"
    );
    assert_eq!(
        err("set scale velocity NaN"),
        ":set scale velocity NaN: expected a finite positive number"
    );
    assert_eq!(
        err("t infinity"),
        ":t infinity: expected a finite number ≥ 0"
    );
    assert_eq!(
        err("settle 0"),
        ":settle 0: expected milliseconds, a whole number from 1 to 60000"
    );
    assert_eq!(
        err("event -1"),
        ":event -1: expected event number as a whole number (0, 1, 2, ...)"
    );
    assert_eq!(err("set tol"), ":set tol: missing tolerance");
    assert_eq!(
        err("nail pos 1 0"),
        ":nail pos 1 0: expected three numbers x y z after position"
    );
    assert_eq!(
        err("nail pos 1 nan 0"),
        ":nail pos 1 nan: expected a finite number"
    );
    assert_eq!(
        err("float pre vel 1 2 inf"),
        ":float pre vel 1 2 inf: expected a finite number"
    );
    assert_eq!(
        err("nail pos pos"),
        ":nail pos pos: position is given twice"
    );
    assert_eq!(
        err("nail pos 1 2 3 4"),
        ":nail pos 1 2 3 4: unknown quantity; expected position, orientation, velocity or angular_velocity"
    );
}

#[test]
fn good_commands_parse() {
    use StateQuantity::*;
    assert_eq!(
        parse("nail"),
        Ok(Command::Nail {
            quantities: StateQuantity::ALL.to_vec(),
            exact: vec![]
        })
    );
    assert_eq!(
        parse("nail position velocity"),
        Ok(Command::Nail {
            quantities: vec![Position, Velocity],
            exact: vec![]
        })
    );
    assert_eq!(
        parse("nail pos 1 0 0.56 rot"),
        Ok(Command::Nail {
            quantities: vec![Position, Orientation],
            exact: vec![(Position, Vec3::new(1.0, 0.0, 0.56))]
        })
    );
    assert_eq!(
        parse("float post pos"),
        Ok(Command::Float {
            side: Some(Side::Post),
            quantities: vec![Position],
            exact: vec![]
        })
    );
    assert_eq!(
        parse("float post angvel 0 0 0 orientation -1e-3 2 0"),
        Ok(Command::Float {
            side: Some(Side::Post),
            quantities: vec![AngularVelocity, Orientation],
            exact: vec![
                (AngularVelocity, Vec3::zeros()),
                (Orientation, Vec3::new(-1e-3, 2.0, 0.0))
            ]
        })
    );
    assert_eq!(
        parse("float"),
        Ok(Command::Float {
            side: None,
            quantities: StateQuantity::ALL.to_vec(),
            exact: vec![]
        })
    );
    assert_eq!(
        parse("upright"),
        Ok(Command::Vertical(Vertical::Upright, None))
    );
    assert_eq!(
        parse("upright pre"),
        Ok(Command::Vertical(Vertical::Upright, Some(Side::Pre)))
    );
    assert_eq!(
        parse("steady post"),
        Ok(Command::Vertical(Vertical::Steady, Some(Side::Post)))
    );
    assert_eq!(parse("set tol 1e-9"), Ok(Command::SetTol(1e-9)));
    assert_eq!(parse("set step 1e-3"), Ok(Command::SetStep(1e-3)));
    assert_eq!(
        parse("set method adaptive"),
        Ok(Command::SetMethod(MethodName::Adaptive))
    );
    assert_eq!(
        parse("set scale velocity 2"),
        Ok(Command::SetScale {
            kind: ScaleKind::Velocity,
            value: 2.0
        })
    );
    assert_eq!(
        parse("free ball angular_velocity"),
        Ok(Command::SetBlock {
            body: "ball".into(),
            block: Block::AngularVelocity,
            free: true
        })
    );
    assert_eq!(
        parse("fix 0 mass"),
        Ok(Command::SetBlock {
            body: "0".into(),
            block: Block::Mass,
            free: false
        })
    );
    assert_eq!(
        parse("fix event"),
        Ok(Command::SetEventControls {
            event: None,
            free: false
        })
    );
    assert_eq!(
        parse("free event 3"),
        Ok(Command::SetEventControls {
            event: Some(3),
            free: true
        })
    );
    assert_eq!(
        err("fix event 3 4"),
        ":fix event 3 4: unexpected extra argument"
    );
    assert_eq!(parse("  t 1.25 "), Ok(Command::Time(1.25)));
    assert_eq!(parse("event 3"), Ok(Command::Event(3)));
    assert_eq!(parse("settle"), Ok(Command::Settle(SETTLE_MS)));
    assert_eq!(parse("settle 200"), Ok(Command::Settle(200)));
    assert_eq!(
        parse("w"),
        Ok(Command::Write {
            path: None,
            force: false
        })
    );
    assert_eq!(
        parse("w! ro.toml"),
        Ok(Command::Write {
            path: Some("ro.toml".into()),
            force: true
        })
    );
    assert_eq!(
        parse("wq!"),
        Ok(Command::WriteQuit {
            path: None,
            force: true
        })
    );
    assert_eq!(
        parse("w my scene.toml"),
        Ok(Command::Write {
            path: Some("my scene.toml".into()),
            force: false
        })
    );
    assert_eq!(
        parse("wq out.toml"),
        Ok(Command::WriteQuit {
            path: Some("out.toml".into()),
            force: false
        })
    );
    assert_eq!(parse("q"), Ok(Command::Quit));
    assert_eq!(parse("q!"), Ok(Command::ForceQuit));
    assert_eq!(parse("help"), Ok(Command::Help));
}

#[test]
fn unknown_words_are_named() {
    assert_eq!(err("fly"), ":fly: unknown command; try :help");
    assert_eq!(err(""), "empty command; try :help");
    assert_eq!(
        err("nail position speed"),
        ":nail position speed: unknown quantity; expected position, orientation, velocity or angular_velocity"
    );
    assert_eq!(
        err("set method euler"),
        ":set method euler: unknown method; expected rk4 or adaptive"
    );
    assert_eq!(
        err("set tol 1e-9 1e-8"),
        ":set tol 1e-9 1e-8: unexpected extra argument"
    );
    assert!(
        err("set scale spin 2")
            .starts_with(":set scale spin: unknown kind; expected one of position")
    );
    assert!(err("free ball wings").starts_with(":free ball wings: unknown block"));
    assert_eq!(err("free"), ":free: missing body (name or index)");
    assert_eq!(
        err("upright later"),
        ":upright later: expected pre, post or nothing"
    );
}

#[test]
fn no_command_word_names_two_commands() {
    let mut seen = std::collections::HashSet::new();
    for spec in COMMANDS {
        for name in spec.names {
            assert!(seen.insert(*name), ":{name} is in the table twice");
        }
    }
}

#[test]
fn every_usage_row_starts_with_a_name_of_its_command() {
    for spec in COMMANDS {
        assert!(!spec.usage.is_empty(), ":{} has no usage", spec.names[0]);
        for (usage, does) in spec.usage {
            let word = usage
                .trim_start_matches(':')
                .split_whitespace()
                .next()
                .unwrap_or_default();
            assert!(
                spec.names.contains(&word),
                "{usage} is not :{}",
                spec.names[0]
            );
            assert!(!does.trim().is_empty(), "{usage} says nothing");
        }
    }
}

/// A usage row with its optional parts dropped and placeholders filled
/// is a command line the parser accepts: the help cannot show a form
/// that does not parse.
#[test]
fn every_usage_row_parses_when_filled_in() {
    for (usage, _) in usage_rows() {
        let mut line = String::new();
        let mut depth = 0usize;
        for (i, word) in usage.trim_start_matches(':').split_whitespace().enumerate() {
            let opened = word.matches('[').count();
            let closed = word.matches(']').count();
            let optional = depth > 0 || opened > 0;
            depth = (depth + opened).saturating_sub(closed);
            if optional {
                continue;
            }
            let word = word.split('|').next().unwrap_or(word);
            let word = match word {
                w if i == 0 => w,
                "body" | "name" | "other" => "ball",
                "block" => "velocity",
                "qty.." => "orientation",
                w => w,
            };
            line.push_str(word);
            line.push(' ');
        }
        assert!(
            parse(&line).is_ok(),
            "{usage} → :{line} fails: {:?}",
            parse(&line)
        );
    }
}

#[test]
fn every_alias_parses_like_its_first_name() {
    for spec in COMMANDS {
        let first = spec.names[0];
        for alias in &spec.names[1..] {
            for args in ["", " 1", " ball velocity", " event 2"] {
                let a = parse(&format!("{first}{args}")).map_err(|e| e.problem);
                let b = parse(&format!("{alias}{args}")).map_err(|e| e.problem);
                assert_eq!(a, b, ":{alias}{args} differs from :{first}{args}");
            }
        }
    }
}
