//! Extreme but finite numbers in every numeric field of the shipped scenes:
//! ±1e308, ±f64::MAX, 1e-308, subnormals, zero, and integer extremes. Each
//! must give a located load error, a typed simulation error, or a motion
//! whose report holds only finite numbers; never a panic, and never a
//! stored motion beyond the simulation's budget.
use nudge::controls::Controls;
use nudge::scene::{SceneError, load_str};
use nudge::sim::{SimOptions, simulate};
use proptest::prelude::*;
use toml_edit::{DocumentMut, Item, Value};

/// The scenes whose fields are varied: small enough to simulate many times.
const SCENES: [&str; 4] = [
    "scenes/bounce.toml",
    "scenes/particle-parabola.toml",
    "scenes/spinning-box.toml",
    "scenes/eggs.toml",
];

/// The extreme floats tried in a float field.
const FLOATS: [f64; 10] = [
    1e308,
    -1e308,
    f64::MAX,
    -f64::MAX,
    1e-308,
    -1e-308,
    5e-324,
    f64::MIN_POSITIVE / 3.0,
    0.0,
    -0.0,
];

/// The extreme integers tried in an integer field.
const INTEGERS: [i64; 5] = [i64::MAX, i64::MIN, -1, 0, 1 << 40];

/// One step into a TOML document: a key of a table or an index of an array.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

/// The paths to every number in `item`.
fn numbers(item: &Item, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match item {
        Item::Table(t) => {
            for (k, v) in t.iter() {
                path.push(Step::Key(k.to_string()));
                numbers(v, path, out);
                path.pop();
            }
        }
        Item::ArrayOfTables(a) => {
            for (i, t) in a.iter().enumerate() {
                path.push(Step::Index(i));
                numbers(&Item::Table(t.clone()), path, out);
                path.pop();
            }
        }
        Item::Value(v) => value_numbers(v, path, out),
        Item::None => {}
    }
}

fn value_numbers(v: &Value, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        Value::Float(_) | Value::Integer(_) => out.push(path.clone()),
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(Step::Index(i));
                value_numbers(x, path, out);
                path.pop();
            }
        }
        Value::InlineTable(t) => {
            for (k, x) in t.iter() {
                path.push(Step::Key(k.to_string()));
                value_numbers(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// The value at `path`, to be replaced.
fn value_at<'a>(item: &'a mut Item, path: &[Step]) -> Option<&'a mut Value> {
    let (first, rest) = path.split_first()?;
    let next: &mut Item = match (item, first) {
        (Item::Table(t), Step::Key(k)) => t.get_mut(k)?,
        (Item::ArrayOfTables(a), Step::Index(i)) => {
            let t = a.get_mut(*i)?;
            return table_value_at(t, rest);
        }
        (Item::Value(v), _) => return inner_value_at(v, path),
        _ => return None,
    };
    if rest.is_empty() {
        next.as_value_mut()
    } else {
        value_at(next, rest)
    }
}

fn table_value_at<'a>(t: &'a mut toml_edit::Table, path: &[Step]) -> Option<&'a mut Value> {
    let (Step::Key(k), rest) = path.split_first()? else {
        return None;
    };
    let item = t.get_mut(k)?;
    if rest.is_empty() {
        item.as_value_mut()
    } else {
        value_at(item, rest)
    }
}

fn inner_value_at<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let Some((first, rest)) = path.split_first() else {
        return Some(v);
    };
    let next = match (v, first) {
        (Value::Array(a), Step::Index(i)) => a.get_mut(*i)?,
        (Value::InlineTable(t), Step::Key(k)) => t.get_mut(k)?,
        _ => return None,
    };
    inner_value_at(next, rest)
}

/// The scene at `SCENES[scene]` with its `field`-th number (cyclically)
/// replaced by the `pick`-th extreme of its kind; the text and what was
/// changed.
fn varied(scene: usize, field: usize, pick: usize) -> (String, String) {
    varied_to(
        scene,
        field,
        FLOATS[pick % FLOATS.len()],
        INTEGERS[pick % INTEGERS.len()],
    )
}

/// The same with the given float (for a float field) or integer.
fn varied_to(scene: usize, field: usize, float: f64, integer: i64) -> (String, String) {
    let path = SCENES[scene % SCENES.len()];
    let text = std::fs::read_to_string(path).expect("shipped scene");
    let mut doc: DocumentMut = text.parse().expect("shipped scene parses");
    let mut paths = Vec::new();
    numbers(doc.as_item(), &mut Vec::new(), &mut paths);
    assert!(!paths.is_empty(), "{path} has numbers");
    let at = &paths[field % paths.len()];
    let value = value_at(doc.as_item_mut(), at).expect("the path leads to a number");
    let new: Value = match value {
        Value::Integer(_) => integer.into(),
        _ => float.into(),
    };
    let what = format!("{path} {at:?} = {new}");
    *value = new;
    (doc.to_string(), what)
}

/// Load, simulate and report one varied scene; the failure, if any.
fn outcome(text: &str, what: &str) -> Result<(), String> {
    let scene = match load_str(text, "varied.toml") {
        Ok(s) => s,
        Err(SceneError::Invalid(m)) => {
            // Located: `varied.toml:LINE:COLUMN: …`.
            let located = m.strip_prefix("varied.toml:").is_some_and(|rest| {
                let mut parts = rest.splitn(3, ':');
                let line = parts.next().and_then(|l| l.parse::<u32>().ok());
                let column = parts.next().and_then(|c| c.parse::<u32>().ok());
                line.is_some() && column.is_some()
            });
            return if located {
                Ok(())
            } else {
                Err(format!("{what}: unlocated load error: {m}"))
            };
        }
    };
    let controls = Controls::new(&scene);
    let traj = match simulate(&scene, &controls, &SimOptions::default()) {
        Ok(t) => t,
        Err(e) => {
            let m = e.to_string();
            return if m.is_empty() || m.contains("NaN") {
                Err(format!("{what}: unclear simulation error: {m:?}"))
            } else {
                Ok(())
            };
        }
    };
    if traj.stored_values() > nudge::sim::MAX_STORED_VALUES {
        return Err(format!("{what}: {} numbers stored", traj.stored_values()));
    }
    let report = nudge::report::summary(&scene, &controls, &traj, &[], &[]);
    let json = serde_json::to_string(&report).expect("a report serialises");
    if json.contains("null") {
        return Err(format!("{what}: a non-finite number in the report"));
    }
    let text = nudge::report::text(&scene, &controls, &traj);
    if ["NaN", "inf"].iter().any(|bad| text.contains(bad)) {
        return Err(format!("{what}: a non-finite number in the text report"));
    }
    Ok(())
}

/// Finite floats near the ends of the range: huge, tiny and subnormal, of
/// either sign.
fn extreme_float() -> impl Strategy<Value = f64> {
    let magnitude = prop_oneof![
        1e300..=f64::MAX,
        1e-308..1e-300,
        (1u64..(1 << 52)).prop_map(f64::from_bits),
    ];
    (magnitude, any::<bool>()).prop_map(|(m, negative)| if negative { -m } else { m })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(2000), ..ProptestConfig::default() })]

    #[test]
    fn extreme_numbers_give_a_located_error_or_a_finite_motion(
        scene in 0..SCENES.len(),
        field in 0usize..1000,
        float in extreme_float(),
        integer in any::<i64>(),
    ) {
        let (text, what) = varied_to(scene, field, float, integer);
        let result = outcome(&text, &what);
        prop_assert!(result.is_ok(), "{}", result.err().unwrap_or_default());
    }
}

/// Every variant of `SCENES[scene]`: each number with each extreme.
fn every_variant(scene: usize) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(SCENES[scene]).expect("shipped scene");
    let doc: DocumentMut = text.parse().expect("parses");
    let mut paths = Vec::new();
    numbers(doc.as_item(), &mut Vec::new(), &mut paths);
    (0..paths.len())
        .flat_map(|field| {
            (0..FLOATS.len().max(INTEGERS.len())).map(move |pick| varied(scene, field, pick))
        })
        .collect()
}

/// Every field of every scene with every extreme: the exhaustive version
/// of the property.
#[test]
fn every_field_of_every_scene_with_every_extreme() {
    let variants: Vec<_> = (0..SCENES.len()).flat_map(every_variant).collect();
    assert!(variants.len() >= 1000, "{} variants", variants.len());
    let failures: Vec<String> = variants
        .iter()
        .filter_map(|(text, what)| outcome(text, what).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The `scene` fuzz target's property on every variant of every scene: an
/// accepted scene saves and loads back to the same text. With
/// `NUDGE_CORPUS=DIR` the variants are also written into `DIR` as a seed
/// corpus for that target (see docs/fuzzing.md).
#[test]
fn extreme_variants_save_and_load_back() {
    let corpus = std::env::var_os("NUDGE_CORPUS").map(std::path::PathBuf::from);
    if let Some(dir) = &corpus {
        std::fs::create_dir_all(dir).expect("create the corpus directory");
    }
    let mut accepted = 0;
    for (scene, path) in SCENES.iter().enumerate() {
        let stem = std::path::Path::new(path)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene");
        for (i, (text, what)) in every_variant(scene).iter().enumerate() {
            if let Some(dir) = &corpus {
                std::fs::write(dir.join(format!("extreme-{stem}-{i:04}.toml")), text)
                    .expect("write a corpus file");
            }
            let Ok(loaded) = load_str(text, "varied.toml") else {
                continue;
            };
            accepted += 1;
            let saved = nudge::scene::to_toml(&loaded);
            let again = load_str(&saved, "saved.toml")
                .unwrap_or_else(|e| panic!("{what}: the saved scene does not load: {e}"));
            assert_eq!(nudge::scene::to_toml(&again), saved, "{what}");
        }
    }
    assert!(accepted > 0, "some variants load");
}
