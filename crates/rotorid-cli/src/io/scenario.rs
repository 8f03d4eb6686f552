//! Scenario files: `--scenario table1` (the built-in [`rotorid::Scenario::table1`]) or the
//! path of a TOML file, read here with a size cap and parsed by the library
//! ([`rotorid::scenario_file`], which documents the format and every message).
//!
//! Any argument other than `table1` is a path (write `./table1` for a file called
//! `table1`). Pipes (`--scenario <(generate)`) are read too; whatever the file, at most
//! [`MAX_SCENARIO_BYTES`] + 1 bytes are read, so `/dev/zero` is refused at once.

use std::fs::File;
use std::io::Read as _;

use anyhow::{bail, Context as _};
use rotorid::Scenario;

pub use rotorid::scenario_file::{ScenarioSpec, SimulationOverrides, Truth, BUILTIN_TABLE1};

/// The largest scenario file read [bytes]: a complete scenario is under 1 kB, so 1 MiB
/// leaves room for any comments while refusing a wrong path (a log, a device) quickly.
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

/// `ScenarioSpec::load(arg)`: the scenario named on the command line.
pub trait LoadScenario: Sized {
    /// `table1` (the built-in scenario) or the path of a TOML scenario file of at most
    /// [`MAX_SCENARIO_BYTES`].
    fn load(arg: &str) -> anyhow::Result<Self>;
}

impl LoadScenario for ScenarioSpec {
    fn load(arg: &str) -> anyhow::Result<Self> {
        if arg == BUILTIN_TABLE1 {
            return Ok(Self::builtin(BUILTIN_TABLE1, Scenario::table1()));
        }
        let text = read_capped(arg)?;
        Ok(Self::parse(arg, &text)?)
    }
}

/// The text of the file at `path`, refused beyond [`MAX_SCENARIO_BYTES`] without reading
/// the rest.
fn read_capped(path: &str) -> anyhow::Result<String> {
    let cannot = || format!("cannot read scenario file {path}");
    let file = File::open(path).with_context(cannot)?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENARIO_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(cannot)?;
    if bytes.len() as u64 > MAX_SCENARIO_BYTES {
        bail!(
            "cannot read scenario file {path}: larger than {} MiB, the limit for scenario \
             files (a scenario is a few hundred bytes of TOML)",
            MAX_SCENARIO_BYTES >> 20
        );
    }
    String::from_utf8(bytes).with_context(|| format!("{}: not UTF-8 text", cannot()))
}
