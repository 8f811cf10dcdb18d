//! The `nudge` command line: a thin shell over the library.

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use nudge::controls::Controls;
use nudge::edit::{Core, Editor};
use nudge::explore::{ExploreOptions, Progress, Start};
use nudge::scene::{self, Scene};
use nudge::sim::{SimOptions, simulate};
use nudge::tangent::{FiniteDifference, Scheme};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Interactive manipulation of rigid-body simulations in the terminal.
#[derive(Parser)]
#[command(name = "nudge", version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    /// Scene file to edit (default: the built-in eggs scene).
    scene: Option<PathBuf>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene and print its summary.
    Check {
        scene: PathBuf,
        /// Print the summary as one JSON object.
        #[arg(long)]
        json: bool,
        /// Compare the tangent Jacobian with central differences per control block.
        #[arg(long)]
        jacobian: bool,
        /// With --jacobian: a time (s) whose Jacobian rows to report; repeat for more (default: the final time).
        #[arg(long = "at", value_name = "T", requires = "jacobian")]
        at: Vec<f64>,
        /// With --jacobian: write the Jacobian matrix here as CSV.
        #[arg(long, value_name = "FILE", requires = "jacobian")]
        csv: Option<PathBuf>,
    },
    /// Replay a keystroke script headless through the editor.
    Run {
        scene: PathBuf,
        /// Keystroke script (vim notation, `#` comments).
        #[arg(long)]
        keys: PathBuf,
        /// Write the JSON report here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Write the final screen as text here.
        #[arg(long)]
        screen: Option<PathBuf>,
        /// Screen size, e.g. 80x24.
        #[arg(long, default_value = "80x24")]
        size: String,
        /// Write the before/after traces as an SVG picture here.
        #[arg(long)]
        trace_svg: Option<PathBuf>,
        /// Go on past command lines that do not parse (each is reported;
        /// the exit status is still non-zero).
        #[arg(long)]
        keep_going: bool,
        /// Print where the updates' time went, part by part.
        #[arg(long)]
        profile: bool,
    },
    /// Sample many worlds around the current controls (in parallel) and
    /// list the best alternative per collision sequence.
    Explore {
        scene: PathBuf,
        /// Replay this keystroke script first and explore from where it
        /// leaves the editor (its blocked drag, if any, is the goal).
        #[arg(long)]
        keys: Option<PathBuf>,
        /// Worlds to sample.
        #[arg(long, default_value_t = ExploreOptions::default().samples)]
        samples: usize,
        /// Seed of the sampler: the same seed gives the same alternatives.
        #[arg(long, default_value_t = ExploreOptions::default().seed)]
        seed: u64,
        /// Most alternatives printed (the best collision sequences first).
        #[arg(long, default_value_t = ExploreOptions::default().keep)]
        keep: usize,
        /// Print the alternatives as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Write the motion as a file for other programs (binary glTF).
    Export {
        scene: PathBuf,
        /// Write binary glTF 2.0 (.glb) here: meshes, and an animation sampled at --fps plus every collision.
        #[arg(long, value_name = "OUT.glb")]
        gltf: PathBuf,
        /// Animation keys per second (collisions are keyed besides).
        #[arg(long, default_value_t = nudge::export::DEFAULT_FPS)]
        fps: f64,
        /// Replay this keystroke script first and export the edited motion.
        #[arg(long, value_name = "FILE")]
        keys: Option<PathBuf>,
    },
    /// Print what accuracy costs in time.
    Bench {
        /// A reduced run (under a minute).
        #[arg(long)]
        quick: bool,
        /// Also write the work-precision rows as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Only sections whose name contains this.
        #[arg(long)]
        only: Option<String>,
    },
}

fn load(path: &Path) -> Result<Scene> {
    scene::load(path).map_err(|e| anyhow::anyhow!("{e}"))
}

fn main() {
    if let Err(e) = real_main() {
        // A closed pipe (`nudge check scene.toml | head`) is the reader's
        // choice, not a failure: stop quietly, like other Unix tools.
        let broken_pipe = e.chain().any(|c| {
            c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        });
        if broken_pipe {
            std::process::exit(0);
        }
        eprintln!("nudge: {e:#}");
        std::process::exit(1);
    }
}

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        None => {
            let mut editor = match &cli.scene {
                Some(p) => Editor::open(p).map_err(|e| anyhow::anyhow!("{e}"))?,
                None => {
                    let scene = scene::load_str(scene::DEFAULT_SCENE, "<built-in eggs>")
                        .map_err(|e| anyhow::anyhow!("{e}"))?;
                    // No file behind it: `:w` asks for a name rather than
                    // overwrite an eggs.toml that happens to be here.
                    Editor::new(scene, None).map_err(|e| anyhow::anyhow!("{e}"))?
                }
            };
            // A held key's frames wait only for the solver's trials; the
            // rest of the motion is simulated when the keys stop.
            editor.set_defer_motion(true);
            nudge::tui::run(&mut editor).context("terminal")?;
            Ok(())
        }
        Some(Command::Check {
            scene,
            json,
            jacobian,
            at,
            csv,
        }) => check(&scene, json, jacobian.then_some((at, csv))),
        Some(Command::Run {
            scene,
            keys,
            report,
            screen,
            size,
            trace_svg,
            keep_going,
            profile,
        }) => run(
            &scene, &keys, report, screen, &size, trace_svg, keep_going, profile,
        ),
        Some(Command::Explore {
            scene,
            keys,
            samples,
            seed,
            keep,
            json,
        }) => explore(&scene, keys.as_deref(), (samples, seed, keep), json),
        Some(Command::Export {
            scene,
            gltf,
            fps,
            keys,
        }) => export(&scene, &gltf, fps, keys.as_deref()),
        Some(Command::Bench { quick, csv, only }) => {
            let args = nudge::bench::BenchArgs { quick, csv, only };
            nudge::bench::run(&args, &mut std::io::stdout().lock())?;
            Ok(())
        }
    }
}

/// `nudge check`; `jacobian` holds `--at` and `--csv` when `--jacobian` is given.
fn check(path: &Path, json: bool, jacobian: Option<(Vec<f64>, Option<PathBuf>)>) -> Result<()> {
    let out = &mut std::io::stdout().lock();
    let scene = load(path)?;
    let controls = Controls::new(&scene);
    let times = match &jacobian {
        Some((at, _)) => Some(nudge::check::matrix::times(at, scene.duration)?),
        None => None,
    };
    let start = Instant::now();
    let traj = simulate(&scene, &controls, &SimOptions::default())
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let elapsed = start.elapsed();
    let fd = if jacobian.is_some() && controls.m() > 0 {
        Some(
            FiniteDifference::new(&scene, &controls, Scheme::Central)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
        )
    } else {
        None
    };
    let checked = fd
        .as_ref()
        .map(|fd| nudge::check::compare(&scene, &controls, &traj, fd));
    let matrix = times
        .as_ref()
        .map(|t| nudge::check::matrix::build(&scene, &controls, &traj, t, fd.as_ref()));
    if let (Some(m), Some((_, Some(file)))) = (&matrix, &jacobian) {
        std::fs::write(file, m.csv()).with_context(|| format!("writing {}", file.display()))?;
    }
    let jacobian = jacobian.is_some();
    let estimate = nudge::estimate::error_estimate(&scene, &controls, &traj);
    if json {
        let diagnostics: Vec<String> = match &estimate {
            Ok(e) => e.diagnostic().into_iter().collect(),
            Err(e) => vec![format!("no integration error estimate: {e}")],
        };
        let mut v = nudge::report::summary(&scene, &controls, &traj, &[], &diagnostics);
        if let Some(obj) = v.as_object_mut() {
            if let Ok(e) = &estimate {
                obj.insert("integration_error".into(), e.json());
            }
            if let Some(c) = &checked {
                obj.insert("jacobian_check".into(), c.json());
            }
            if let Some(m) = &matrix {
                obj.insert("jacobian".into(), m.json());
            }
        }
        writeln!(out, "{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    write!(out, "{}", nudge::report::text(&scene, &controls, &traj))?;
    writeln!(
        out,
        "\nsimulated with Jacobians ({} controls) in {:.3} ms",
        controls.m(),
        elapsed.as_secs_f64() * 1e3
    )?;
    match &estimate {
        Ok(e) => {
            writeln!(
                out,
                "integration error (estimated by step halving): {}",
                e.text()
            )?;
            if let Some(d) = e.diagnostic() {
                writeln!(out, "warning: {d}")?;
            }
        }
        Err(e) => writeln!(out, "integration error: not estimated ({e})")?,
    }
    match &checked {
        Some(c) => write!(out, "{}", c.text())?,
        None if jacobian => writeln!(
            out,
            "\njacobian: no free controls (free a block in the scene's `free = [...]`)"
        )?,
        None => {}
    }
    Ok(())
}

fn parse_size(size: &str) -> Result<(u16, u16)> {
    let (w, h) = size
        .split_once(['x', 'X'])
        .context("--size must look like 80x24")?;
    let (w, h): (u16, u16) = (
        w.trim().parse().context("--size width")?,
        h.trim().parse().context("--size height")?,
    );
    if w == 0 || h == 0 {
        bail!("--size must be at least 1x1, got {size}");
    }
    Ok((w, h))
}

fn read_keys(keys: &Path) -> Result<Vec<nudge::script::Step>> {
    let text = nudge::files::read_regular_text(keys, nudge::files::MAX_TEXT_BYTES)
        .with_context(|| format!("reading the key script {}", keys.display()))?;
    nudge::script::parse_script(&text, &keys.display().to_string())
        .map_err(|e| anyhow::anyhow!("{e}"))
}

/// Open `path` and replay the key script `keys` through the editor, as
/// `nudge run` does; a command line that does not parse is an error.
fn replay(path: &Path, keys: &Path) -> Result<Editor> {
    let parsed = read_keys(keys)?;
    let mut editor = Editor::open(path).map_err(|e| anyhow::anyhow!("{e}"))?;
    // A replay is deterministic: settles stop by convergence, not the clock.
    editor.set_wall_clock(false);
    let result = nudge::script::run_script(&mut editor, &parsed, (80, 24));
    if let Some(first) = result.failures.first() {
        bail!("{}:{first}: the replay stopped there", keys.display());
    }
    Ok(editor)
}

/// `nudge explore`; `sampling` is (samples, seed, keep).
fn explore(
    path: &Path,
    keys: Option<&Path>,
    (samples, seed, keep): (usize, u64, usize),
    json: bool,
) -> Result<()> {
    let editor = match keys {
        Some(k) => replay(path, k)?,
        None => {
            let mut e = Editor::open(path).map_err(|e| anyhow::anyhow!("{e}"))?;
            e.set_wall_clock(false);
            e
        }
    };
    let opts = ExploreOptions {
        samples,
        seed,
        keep,
        ..ExploreOptions::default()
    };
    let found = nudge::explore::run(&Start::from_editor(&editor), &opts, &Progress::default())?;
    let out = &mut std::io::stdout().lock();
    if json {
        let v = nudge::explore::json(editor.scene(), &found);
        writeln!(out, "{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        write!(out, "{}", nudge::explore::text(editor.scene(), &found))?;
    }
    Ok(())
}

fn export(path: &Path, out: &Path, fps: f64, keys: Option<&Path>) -> Result<()> {
    // The motion of the scene as loaded, or as the key script left it.
    let scene = match keys {
        Some(k) => replay(path, k)?.scene().clone(),
        None => load(path)?,
    };
    let traj = simulate(
        &scene,
        &Controls::new(&scene),
        &SimOptions::without_tangents(),
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let bytes = nudge::export::to_glb(&scene, &traj, fps)?;
    std::fs::write(out, bytes).with_context(|| format!("writing {}", out.display()))?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn run(
    path: &Path,
    keys: &Path,
    report: Option<PathBuf>,
    screen: Option<PathBuf>,
    size: &str,
    svg: Option<PathBuf>,
    keep_going: bool,
    profile: bool,
) -> Result<()> {
    let size = parse_size(size)?;
    let parsed = read_keys(keys)?;
    let mut editor = Editor::open(path).map_err(|e| anyhow::anyhow!("{e}"))?;
    // A replay is deterministic: settles stop by convergence, not the clock.
    editor.set_wall_clock(false);
    // As in the terminal (the replay pauses after every key, so the result
    // is the same), and `--profile` shows what waits for the pauses.
    editor.set_defer_motion(true);
    let before = editor.view();
    let replay = nudge::script::Replay {
        keep_going,
        ..Default::default()
    };
    let result = nudge::script::run_script_with(&mut editor, &parsed, size, replay);
    if let Some(p) = screen {
        std::fs::write(&p, format!("{}\n", result.screen))
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = report {
        let mut v = editor.report();
        if let Some(o) = v.as_object_mut() {
            o.insert("keys".into(), serde_json::json!(parsed.len()));
            if let Some(r) = result.render_latency() {
                o.insert("render_ms".into(), serde_json::json!({"median": nudge::report::num(r.median), "p95": nudge::report::num(r.p95), "max": nudge::report::num(r.max)}));
            }
        }
        std::fs::write(&p, serde_json::to_string_pretty(&v)?)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = svg {
        std::fs::write(&p, nudge::svg::before_after(&before, &editor.view()))
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if profile {
        print!("{}", nudge::bench::profile_table(&result));
    }
    if let Some(first) = result.failures.first() {
        for f in &result.failures {
            eprintln!("{}:{f}", keys.display());
        }
        if keep_going {
            bail!(
                "{} command line(s) of {} did not parse",
                result.failures.len(),
                keys.display()
            );
        }
        bail!(
            "{}:{first}: the replay stopped there (--keep-going goes on past such lines)",
            keys.display()
        );
    }
    Ok(())
}
