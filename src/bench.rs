//! `nudge bench`: what accuracy costs in time (a benchmark that prints
//! tables, never a timed test). Being written: see the benchmark task.

use std::io::Write;
use std::path::PathBuf;

/// Options of `nudge bench`.
#[derive(Debug, Clone, Default)]
pub struct BenchArgs {
    /// A reduced run that finishes in under a minute.
    pub quick: bool,
    /// Also write the work-precision rows as CSV.
    pub csv: Option<PathBuf>,
    /// Only the sections whose name contains this.
    pub only: Option<String>,
}

/// Run the benchmark, printing tables to `out`.
pub fn run(_args: &BenchArgs, out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(out, "benchmark not yet written")
}
