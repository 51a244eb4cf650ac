//! Developer tasks, run as `cargo xtask <task>`.
//!
//! Tasks arrive with the work that needs them: reproducing the papers'
//! tables (`reproduce`), the error-against-run-time report and benchmark
//! summaries.

use anyhow::{Result, bail};

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    match args.next().as_deref() {
        None | Some("help") | Some("--help") | Some("-h") => {
            println!("usage: cargo xtask <task>\n\ntasks:\n  help    this message");
            Ok(())
        }
        Some(other) => bail!("unknown task `{other}` (run `cargo xtask help`)"),
    }
}
