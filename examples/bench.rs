//! Run `nudge bench` without the CLI: `cargo run --release --example bench -- [--quick] [--csv FILE] [--only NAME]`.

use nudge::bench::{BenchArgs, run};
use std::path::PathBuf;

fn main() {
    let mut args = BenchArgs::default();
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--quick" => args.quick = true,
            "--csv" => args.csv = it.next().map(PathBuf::from),
            "--only" => args.only = it.next(),
            other => {
                eprintln!("unknown argument {other:?}; use [--quick] [--csv FILE] [--only NAME]");
                std::process::exit(2);
            }
        }
    }
    let stdout = std::io::stdout();
    if let Err(e) = run(&args, &mut stdout.lock()) {
        eprintln!("bench: {e}");
        std::process::exit(1);
    }
}
