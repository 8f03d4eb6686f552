//! `rotorid condition RAW --scenario S.toml --out RESPONSE.csv`: a raw acquisition (two
//! probes in volts at any angles, a keyphasor, optionally a slow-roll record) turned into
//! the response `t,x,z,phi,phi_dot,phi_ddot` by the library (`rotorid::acquisition`,
//! docs/acquisition.md), with the scenario's `[acquisition]` table. The rotor of the
//! scenario's `[rotor]`, when complete, removes the predicted slow-roll response and the
//! transient's DC bias; the notes say what was assumed.

use anyhow::Context as _;

use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::{check_distinct_files, FileMode, Output, ResponseWriter, ScenarioSpec};

/// Arguments of `rotorid condition`.
#[derive(Debug, clap::Args)]
pub struct ConditionArgs {
    /// The raw record (.csv, .mat, .tdms, .uff, .npy/.npz, .parquet) with the columns the
    /// scenario's [acquisition] names.
    #[arg(value_name = "RAW")]
    pub input: String,

    /// The scenario TOML with an [acquisition] table.
    #[arg(long, value_name = "FILE.toml")]
    pub scenario: String,

    /// The response CSV to write, or `-` for stdout.
    #[arg(long, short, value_name = "RESPONSE.csv|-")]
    pub out: String,

    /// Also write the conditioning report (keyphasor, probes, runout, findings) as JSON.
    #[arg(long, value_name = "REPORT.json")]
    pub report: Option<String>,
}

/// Run `rotorid condition`.
pub fn run(args: ConditionArgs) -> anyhow::Result<()> {
    check_distinct_files(
        &[("the input", &args.input), ("--scenario", &args.scenario)],
        &[("--out", &args.out)],
    )?;
    let spec = ScenarioSpec::load(&args.scenario)?;
    if spec.finite_element().is_some() {
        return condition_finite_element(&args, &spec);
    }
    let Some(acq) = spec.acquisition() else {
        anyhow::bail!(
            "{}: has no [acquisition] table: it names the probe and keyphasor columns (see \
             docs/acquisition.md)",
            spec.origin()
        );
    };
    let table = tables::read(&args.input)?;
    let raw = tables::raw_record(&table, acq)?;
    let slow = tables::slow_roll(&spec, acq)?;
    let c = tables::condition_for(&raw, acq, slow.as_ref(), &spec, &spec.knowledge()?, None)?;
    tables::print_report(&c);
    if let Some(path) = &args.report {
        let mut f = Output::create(path, FileMode::Atomic)?;
        serde_json::to_writer_pretty(&mut f, &c.report)
            .with_context(|| format!("cannot write {path}"))?;
        f.commit()?;
    }
    let out = Output::create(&args.out, FileMode::Atomic)?;
    let name = out.name().to_owned();
    let mut w = ResponseWriter::new(out).with_context(|| format!("cannot write {name}"))?;
    for i in 0..c.t.len() {
        let s = rotorid::SpeedState {
            phi: c.phi[i],
            omega: c.phi_dot[i],
            omega_dot: c.phi_ddot[i],
        };
        w.write(c.t[i], c.x[i], c.z[i], &s)
            .with_context(|| format!("cannot write {name}"))?;
    }
    w.into_inner().commit()
}

/// A finite-element scenario: every measured node's two probes conditioned by the 2-DOF
/// conditioning (`rotorid::acquisition::condition_fe_raw`, docs/acquisition.md section 11),
/// written as the response file of a finite-element rotor (`t`, `<node>.x`, `<node>.y`
/// ..., `phi`, `phi_dot`, `phi_ddot`; CSV or a binary format by the extension); the report
/// holds one conditioning report per node.
fn condition_finite_element(args: &ConditionArgs, spec: &ScenarioSpec) -> anyhow::Result<()> {
    let rotor = crate::io::finite_element::finite_element_of(spec)?;
    let Some(acq) = crate::io::finite_element::fe_acquisition_of(spec, &rotor)? else {
        anyhow::bail!(
            "{}: has no [acquisition] table: it names the probe columns (two per measured \
             node, [[acquisition.probe]] node = N) and the keyphasor (see docs/acquisition.md)",
            spec.origin()
        );
    };
    let table = tables::read(&args.input)?;
    let raw = tables::fe_raw_record(&table, acq)?;
    let slow = tables::fe_slow_roll(spec, acq)?;
    let c = rotorid::acquisition::condition_fe_raw(&raw, acq, slow.as_ref())?;
    print_fe_reports(&c.reports);
    if let Some(path) = &args.report {
        let mut f = Output::create(path, FileMode::Atomic)?;
        serde_json::to_writer_pretty(&mut f, &c.reports)
            .with_context(|| format!("cannot write {path}"))?;
        f.commit()?;
    }
    let table = crate::io::fe_response::fe_table(&args.out, c.response);
    crate::commands::simulate::write_any(&args.out, &table)
}

/// Each node's conditioning notes and findings on stderr.
pub(crate) fn print_fe_reports(reports: &[(u32, rotorid::acquisition::ConditionReport)]) {
    for (node, report) in reports {
        for n in &report.notes {
            eprintln!("note: node {node}: {n}");
        }
        for f in &report.findings {
            eprintln!("warning: node {node}: {}", f.message());
        }
    }
}
