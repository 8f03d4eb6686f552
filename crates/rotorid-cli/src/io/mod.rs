//! File formats and I/O of the `rotorid` command, shared by every subcommand.
//!
//! | file | module | written by | read by |
//! |---|---|---|---|
//! | scenario TOML (rotor, speed, sampling, initial state; SI) | [`scenario`] | you | simulate, identify |
//! | finite-element matrices NPZ `M`, `K`, `G`, `C`, `Ka`, `dofs` (beside the scenario) | [`finite_element`] | you, `rotorid.ross.export` | inspect |
//! | finite-element response `t,<node>.<dof>...,phi,phi_dot,phi_ddot` (CSV or binary) | [`fe_response`] | simulate | the finite-element refine |
//! | response CSV `t,x,z,phi,phi_dot,phi_ddot` (s, m, m, rad, rad/s, rad/s^2) | [`response_csv`] | simulate | identify, plot |
//! | estimates CSV `t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z,window` | [`estimates_csv`] | identify | plot |
//! | summary JSON: the serialised `rotorid::pipeline::Identification` (docs/summary.md) | - | identify | scripts |
//! | summary JSON: identified `rotor`, `covariance` | [`identified`] | identify | analyze, balance |
//! | summary JSON of a finite-element identification: `parameters`, `covariance`, `initial_state` | [`fe_summary`] | identify | analyze, predict |
//!
//! The CSV machinery (line numbering and caps, header names and units, number parsing and
//! formatting, the response reader) is the `rotorid-io` crate's, shared with the Python
//! package; [`columns`], [`csv_error`], [`lines`] and [`number`] are its modules. Numbers
//! are written in shortest round-trip form ([`number`]): reading a value back gives the
//! identical `f64`. Readers report errors as `FILE line L, column C (NAME): ...`
//! ([`CsvError`]). Outputs go to stdout (`-`) or to a file, atomically or in place
//! ([`output`]).

pub use rotorid_io::csv::{columns, error as csv_error, lines, number};

pub mod estimates_csv;
pub mod fe_response;
pub mod fe_summary;
pub mod finite_element;
pub mod identified;
pub mod message;
pub mod output;
pub mod params;
pub mod progress;
pub mod response_csv;
pub mod scenario;
pub mod tables;

pub use estimates_csv::{
    EstimateRow, EstimatesReader, EstimatesWriter, ESTIMATES_HEADER, ESTIMATES_REQUIRED,
};
pub use output::{
    check_distinct_files, is_broken_pipe, open_input, stdout_error, FileMode, Output, StdoutClosed,
};
pub use response_csv::{ResponseReader, ResponseWriter};
pub use rotorid_io::csv::CsvError;
pub use scenario::{LoadScenario, ScenarioSpec, SimulationOverrides, Truth};
