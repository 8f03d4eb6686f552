//! `rotorid identify`: read a response CSV, identify it through the library's pipeline
//! (`rotorid::pipeline`: the method, its start, the masking of what the record does not
//! determine and every diagnostic are decided there), and write the estimates CSV, the
//! summary (the serialised `Identification`) and a report on stderr.

mod args;
mod finite_element;
mod report;
mod stream;

pub use args::{method_of, IdentifyArgs, IdentifyMethod, MethodOptions};

use anyhow::Context as _;

use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::{check_distinct_files, is_broken_pipe, open_input, FileMode, Output, ScenarioSpec};

/// Run `rotorid identify`: scenario and options -> pipeline -> outputs.
pub fn run(args: IdentifyArgs) -> anyhow::Result<()> {
    let spec = ScenarioSpec::load(&args.scenario)?;
    if spec.finite_element().is_some() {
        return finite_element::run(&args, &spec);
    }
    for (flag, given) in [
        ("--initial", args.initial.is_some()),
        ("--modes", args.modes.is_some()),
        ("--offsets", args.offsets),
    ] {
        if given {
            anyhow::bail!(
                "{flag} applies to a finite-element rotor only (rotor.model = \"finite_element\"), \
                 not to the {} model of {}",
                spec.model().name(),
                spec.origin()
            );
        }
    }
    let method = method_of(args.method, &args.settings, args.every)?;
    if !(args.time_tolerance.is_finite() && args.time_tolerance >= 0.0) {
        anyhow::bail!(
            "--time-tolerance = {} is out of range: must be finite and >= 0 (relative to dt)",
            args.time_tolerance
        );
    }
    check_outputs(&args)?;
    let columns = args.columns.as_deref();
    let (name, input) = if let Some(acq) = spec.acquisition() {
        // a raw acquisition: conditioned and identified until the rotor guess settles,
        // then identified as any record
        let table = tables::read(&args.input)?;
        let raw = tables::raw_record(&table, acq)?;
        let slow = tables::slow_roll(&spec, acq)?;
        let c = tables::condition_for(
            &raw,
            acq,
            slow.as_ref(),
            &spec,
            &spec.knowledge()?,
            Some((&method, args.time_tolerance)),
        )?;
        tables::print_report(&c);
        let cols = tables::conditioned_columns(c);
        (args.input.clone(), stream::Source::Columns(cols))
    } else if tables::is_tabular(&args.input, columns) {
        // a TDMS or Parquet file is read a block of rows at a time as it is identified
        let source = match tables::blocks(&args.input, columns)? {
            Some(blocks) => stream::Source::Blocks(blocks),
            None => {
                let table = tables::read(&args.input)?;
                stream::Source::Columns(tables::columns(table, columns)?)
            }
        };
        (args.input.clone(), source)
    } else {
        if columns.is_some() {
            anyhow::bail!(
                "--columns needs a file (it is read whole), not {}",
                args.input
            );
        }
        let (name, input) = open_input(&args.input)?;
        (name, stream::Source::Csv(input))
    };
    let live = args.input == "-" || !std::fs::metadata(&args.input).is_ok_and(|m| m.is_file());
    // Parquet is written whole at the end (atomically); CSV row by row as it goes
    let parquet = args.out != "-"
        && matches!(
            rotorid_io::Format::from_path(std::path::Path::new(&args.out)),
            Ok(rotorid_io::Format::Parquet)
        );
    let mode = if parquet {
        FileMode::Atomic
    } else {
        FileMode::Direct
    };
    let out = Output::create(&args.out, mode)?;
    let to_stdout = out.is_stdout();
    let io = stream::Io {
        name: &name,
        out_name: &args.out,
        live,
        parquet,
        every: args.every.unwrap_or(1),
        progress_bytes: if args.quiet || live {
            None
        } else {
            std::fs::metadata(&args.input).ok().map(|m| m.len())
        },
    };
    let mut ident = match stream::identify(&io, input, out, &spec, &method, args.time_tolerance) {
        Ok(i) => i,
        Err(e) if to_stdout && is_broken_pipe(&e) => return Ok(()),
        Err(e) => return Err(e),
    };
    ident.input = Some(args.input.clone());
    ident.scenario = Some(spec.origin().to_owned());
    if let Some(path) = &args.summary {
        write_summary(path, &ident)?;
    }
    let text = if args.quiet {
        report::warning_lines(&ident).join("\n")
    } else {
        report::human(&ident)
    };
    if !text.is_empty() {
        eprintln!("{text}");
    }
    Ok(())
}

/// Refuse an output (`--out`, `--summary`) that is the input, the scenario or the other
/// output: identify's check for every model.
fn check_outputs(args: &IdentifyArgs) -> anyhow::Result<()> {
    let mut outputs = vec![("--out", args.out.as_str())];
    if let Some(s) = &args.summary {
        outputs.push(("--summary", s.as_str()));
    }
    check_distinct_files(
        &[("the input", &args.input), ("--scenario", &args.scenario)],
        &outputs,
    )
}

/// Write `summary` to `path` as pretty JSON and a newline, atomically (a reader never sees
/// half of it).
fn write_summary(path: &str, summary: &impl serde::Serialize) -> anyhow::Result<()> {
    let mut f = Output::create(path, FileMode::Atomic)?;
    serde_json::to_writer_pretty(&mut f, summary)
        .with_context(|| format!("cannot write {path}"))?;
    std::io::Write::write_all(&mut f, b"\n").with_context(|| format!("cannot write {path}"))?;
    f.commit()
}
