//! The `rotorid` command end to end (one test binary: `cargo test -p rotorid-cli --test it`).

mod common;

mod analysis;
mod balance;
mod balance_published;
mod cross;
mod daqmx;
mod dashboard;
mod dashboard_browser;
mod demo;
mod fe_analyze;
mod fe_data;
mod fe_raw_identify;
mod finite_element;
mod fleet;
mod fleet_cluster;
mod formats;
mod golden;
mod identify;
mod modulating;
mod paper;
mod plot;
mod predict;
mod raw_records;
mod refine;
mod safety;
mod scenario;
mod shell;
mod simulate;
mod transient;
mod units;
