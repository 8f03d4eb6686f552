//! The `rotorid` command end to end (one test binary: `cargo test -p rotorid-cli --test it`).

mod common;

mod analysis;
mod daqmx;
mod demo;
mod fleet;
mod formats;
mod golden;
mod identify;
mod modulating;
mod paper;
mod plot;
mod raw_records;
mod refine;
mod safety;
mod scenario;
mod simulate;
mod units;
