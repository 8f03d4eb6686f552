//! `rotorid paper --out DIR [--duration S] [--quiet]`: reproduce the numerical results of
//! Barredo et al. (2024) -- figures 2-9 and the identification times -- in the paper's
//! setting (Newmark data, trapezoid integrals) and ours (exact data, default quadrature).
//!
//! Writes into DIR:
//! - `fig2.png` ... `fig9.png` and `.svg`: the paper's window t = 0.10-0.23 s;
//! - `fig2_full.png` ... `fig9_full.png` and `.svg`: the whole record;
//! - `results.json`: per case, setting, parameter and direction: true value, estimate at
//!   0.3 s, relative error, identification time (1 %), the paper's reported time;
//! - `report.md` and `report.html` (self-contained, figures embedded).
//!
//! Every file is written atomically (a temporary renamed over it when complete; see
//! [`crate::io::output`]): an interrupted run leaves the previous files whole.
//!
//! See [`crate::report`] for the experiments and definitions.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use crate::io::progress::{Progress, Unit};
use crate::io::{FileMode, Output};
use crate::plot;
use crate::report::experiment::{self, Case, Run, Setting, PAPER_DT};
use crate::report::figures::case_figures;
use crate::report::results::{
    attribution as attribution_of, compare_responses, rows, ESTIMATE_TIME, TOLERANCE,
};
use crate::report::tables::case_tables;
use crate::report::{
    html, markdown, CaseInfo, FigureInfo, Report, ScenarioInfo, SettingInfo, FORMAT_VERSION,
};

/// The longest record accepted [s]: at most 6 runs of ~120 bytes per sample are held at
/// once (response and estimates), ~0.5 GB at 60 s.
const MAX_DURATION: f64 = 60.0;

/// Arguments of `rotorid paper`.
#[derive(Debug, clap::Args)]
pub struct PaperArgs {
    /// Directory for the figures, results.json, report.md and report.html (created if
    /// missing; existing files of the same names are replaced).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Record length in seconds, at least 0.3 (the estimates are read at 0.3 s).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub duration: f64,
    /// No progress on stderr and no summary on stdout.
    #[arg(long)]
    pub quiet: bool,
}

/// Run `rotorid paper`.
pub fn run(args: PaperArgs) -> anyhow::Result<()> {
    let duration = args.duration;
    if !(duration.is_finite() && (ESTIMATE_TIME..=MAX_DURATION).contains(&duration)) {
        bail!(
            "--duration {duration} is out of range: must be between {ESTIMATE_TIME} and \
             {MAX_DURATION} (s); the estimates are read at {ESTIMATE_TIME} s"
        );
    }
    let dir = &args.out;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the output directory {}", dir.display()))?;

    let figures_per_case = 8;
    let runs_per_case = Setting::COMBINATIONS.len();
    let steps = Case::ALL.len() * (runs_per_case + figures_per_case) + 3;
    let mut progress = Steps::new(steps as u64, args.quiet);

    // Per case: simulate and identify in every combination of data and rule, draw the
    // figures from the paper's setting and ours.
    let (mut runs, mut attribution, mut figures, mut responses) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for case in Case::ALL {
        let mut by_setting = Vec::new();
        for setting in Setting::COMBINATIONS {
            let run = experiment::run(case, setting, duration)?;
            attribution.push(attribution_of(&run));
            by_setting.push(run);
            progress.step();
        }
        let ours = take(&mut by_setting, Setting::Ours);
        let paper = take(&mut by_setting, Setting::Paper);
        responses.push(compare_responses(&paper, &ours));
        for f in case_figures(case, &paper, &ours) {
            let (png, svg) = (format!("{}.png", f.stem), format!("{}.svg", f.stem));
            plot::save(&f.figure, &dir.join(&png))?;
            plot::save(&f.figure, &dir.join(&svg))?;
            figures.push(FigureInfo {
                stem: f.stem,
                number: f.number,
                full: f.full,
                caption: f.caption,
                png,
                svg,
            });
            progress.step();
        }
        runs.push(paper);
        runs.push(ours);
    }
    figures.sort_by_key(|f| (f.number, f.full));

    let first = &runs[0];
    let report = Report {
        format_version: FORMAT_VERSION,
        generator: format!(
            "rotorid paper --duration {duration} (rotorid {})",
            env!("CARGO_PKG_VERSION")
        ),
        scenario: ScenarioInfo {
            name: "table1",
            rotor: first.scenario.rotor.params(),
            dt: PAPER_DT,
            duration,
            initial_state: "zero",
        },
        tolerance: TOLERANCE,
        estimate_time: ESTIMATE_TIME,
        rcond_min: first.config.rcond_min,
        settings: Setting::ALL
            .iter()
            .map(|s| SettingInfo {
                name: s.name(),
                simulation: s.method().to_string(),
                quadrature: s.quadrature().name(),
                description: s.describe(),
            })
            .collect(),
        cases: runs
            .chunks(2)
            .map(|pair| {
                let case = pair[1].case;
                let f = match case {
                    Case::Constant => [2, 3, 4, 5],
                    Case::Ramp => [6, 7, 8, 9],
                };
                CaseInfo {
                    name: case.name(),
                    description: case.describe(),
                    speed: pair[1].scenario.speed,
                    paper_figures: f,
                }
            })
            .collect(),
        rows: runs.iter().flat_map(rows).collect(),
        responses,
        attribution,
        figures,
    };
    let json = serde_json::to_string_pretty(&report).context("cannot serialise the results")?;
    write(dir, "results.json", json + "\n")?;
    progress.step();
    write(dir, "report.md", markdown::render(&report))?;
    progress.step();
    write(dir, "report.html", html::render(&report, dir)?)?;
    progress.step();
    progress.finish();

    if !args.quiet {
        outln!(
            "wrote {} figures (PNG and SVG), results.json, report.md and report.html to {}",
            report.figures.len(),
            dir.display()
        )?;
        for table in case_tables(&report) {
            outln!("{}:", table.title)?;
            for s in &table.summary {
                outln!("  - {s}")?;
            }
        }
    }
    Ok(())
}

/// Remove and return the run of `setting` (every setting in `COMBINATIONS` ran).
fn take(runs: &mut Vec<Run>, setting: Setting) -> Run {
    let i = runs
        .iter()
        .position(|r| r.setting == setting)
        .expect("every setting of COMBINATIONS ran");
    runs.swap_remove(i)
}

/// Write `contents` to `dir/name` atomically (see [`crate::io::output`]).
fn write(dir: &Path, name: &str, contents: String) -> anyhow::Result<()> {
    let path = dir.join(name);
    let shown = path.to_string_lossy();
    let mut out = Output::create(&shown, FileMode::Atomic)?;
    out.write_all(contents.as_bytes())
        .with_context(|| format!("cannot write {shown}"))?;
    out.commit()
}

/// The run's progress on stderr (`io::progress`: a bar on a terminal, lines otherwise,
/// once the run has taken 2 s), nothing under `--quiet`.
struct Steps {
    progress: Option<Progress>,
    done: u64,
}

impl Steps {
    fn new(total: u64, quiet: bool) -> Self {
        Self {
            progress: (!quiet).then(|| Progress::counting(total, "paper", Unit::Steps)),
            done: 0,
        }
    }

    /// One more step done.
    fn step(&mut self) {
        self.done += 1;
        if let Some(p) = &mut self.progress {
            p.update(self.done);
        }
    }

    fn finish(self) {
        if let Some(p) = self.progress {
            p.finish();
        }
    }
}
