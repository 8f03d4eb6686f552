//! `rotorid`: simulate rotor-bearing vibration and identify its physical parameters.
//!
//! A thin entry point: parse the command line, run one command, and print any error as
//! `Error: ` and its causes, each once ([`io::message`]), with a non-zero exit code.

use clap::{CommandFactory, Parser, Subcommand};

/// `println!` that returns an error instead of panicking when stdout cannot be written:
/// [`io::StdoutClosed`] when its reader went away (`rotorid analyze ... | head -1`), which
/// `main` ends quietly.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err(crate::io::stdout_error)
    }};
}

/// `print!` as [`outln!`] is `println!`.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).map_err(crate::io::stdout_error)
    }};
}

mod commands;
mod io;

#[global_allocator]
static ALLOCATOR: rotorid_alloc::HugePageAdvice = rotorid_alloc::HugePageAdvice;
mod plot;
mod report;

/// `rotorid --version`: the package version and the commit it was built from
/// (`0.1.0 (abc1234)`; `(unknown commit)` for a build outside a git checkout; build.rs).
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (", env!("ROTORID_COMMIT"), ")");

/// Identify the mass, damping and stiffness of a rotor-bearing system from its vibration.
#[derive(Debug, Parser)]
#[command(name = "rotorid", version = VERSION, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate the rotor's response x(t), z(t) and write it as CSV.
    Simulate(commands::simulate::SimulateArgs),
    /// Identify m, c, k in both directions from a response CSV (a file or a live pipe).
    Identify(commands::identify::IdentifyArgs),
    /// Simulate the paper's rotor, identify it, and print a table beside the paper's figures.
    Demo(commands::demo::DemoArgs),
    /// Reproduce the paper's figures 2-9 and results as images and a report.
    Paper(commands::paper::PaperArgs),
    /// Plot a simulate or identify CSV as PNG or SVG.
    Plot(commands::plot::PlotArgs),
    /// Campbell diagram, critical speeds, stability and unbalance response, with uncertainty.
    Analyze(commands::analyze::AnalyzeArgs),
    /// The identified finite-element rotor's response at unmeasured degrees of freedom, with
    /// a standard-deviation band from the identification's covariance.
    Predict(commands::predict::PredictArgs),
    /// Correction masses with their uncertainty: multi-plane, multi-speed influence
    /// coefficients (least squares or min-max, split into holes, trial planning), or one
    /// plane from an identified unbalance or two runs.
    Balance(Box<commands::balance::BalanceArgs>),
    /// The 1X vector of each probe of raw records (probes, keyphasor) as vectors.csv rows.
    Onex(commands::onex::OnexArgs),
    /// A run-up or coast-down: Bode, polar and cascade plots, critical speeds with API 684
    /// amplification factors and separation margins.
    Transient(commands::transient::TransientArgs),
    /// Turn a raw acquisition (probe volts, keyphasor, slow roll) into a response CSV.
    Condition(commands::condition::ConditionArgs),
    /// List the channels of a record (CSV, MAT, TDMS, UFF58, NPY/NPZ, Parquet).
    Inspect(commands::inspect::InspectArgs),
    Publish(commands::publish::PublishArgs),
    Worker(commands::worker::WorkerArgs),
    Fleet(commands::fleet::FleetArgs),
    Dashboard(commands::dashboard::DashboardArgs),
    /// Print the shell completion script for bash, zsh, fish, powershell or elvish.
    Completions(commands::completions::CompletionsArgs),
    /// Write the manual pages (roff, section 1): rotorid.1 and one per command.
    Manpages(commands::manpages::ManpagesArgs),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simulate(args) => commands::simulate::run(args),
        Command::Identify(args) => commands::identify::run(args),
        Command::Demo(args) => commands::demo::run(args),
        Command::Paper(args) => commands::paper::run(args),
        Command::Plot(args) => commands::plot::run(args),
        Command::Analyze(args) => commands::analyze::run(args),
        Command::Predict(args) => commands::predict::run(args),
        Command::Balance(args) => commands::balance::run(*args),
        Command::Onex(args) => commands::onex::run(args),
        Command::Transient(args) => commands::transient::run(args),
        Command::Condition(args) => commands::condition::run(args),
        Command::Inspect(args) => commands::inspect::run(args),
        Command::Publish(args) => commands::publish::run(args),
        Command::Worker(args) => commands::worker::run(args),
        Command::Fleet(args) => commands::fleet::run(args),
        Command::Dashboard(args) => commands::dashboard::run(args),
        Command::Completions(args) => commands::completions::run(args, Cli::command()),
        Command::Manpages(args) => commands::manpages::run(args, Cli::command()),
    };
    if let Err(err) = result {
        if err.is::<io::StdoutClosed>() {
            // the reader of our output went away (`| head`): nothing more to say
            std::process::exit(0);
        }
        eprintln!("Error: {}", io::message::error_message(&err));
        std::process::exit(1);
    }
}
