//! One module per subcommand; each exposes `XArgs` (clap) and `run(XArgs) -> anyhow::Result<()>`.

pub mod analyze;
pub mod balance;
pub mod completions;
pub mod condition;
pub mod dashboard;
pub mod demo;
pub mod fleet;
pub mod identify;
pub mod inspect;
pub mod manpages;
pub mod onex;
pub mod paper;
pub mod plot;
pub mod predict;
pub mod publish;
pub mod simulate;
pub mod transient;
pub mod worker;
