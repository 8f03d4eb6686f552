//! `rotorid identify DATA --scenario fe.toml --method refine`: a finite-element rotor's
//! bearings and unbalances by maximum likelihood on the reduced model
//! (`rotorid::refine::finite_element`, docs/finite_element.md section 6). The scenario's
//! values of the unknowns are where the fit starts; the others are known.

use anyhow::{bail, Context as _};

use rotorid::model::finite_element::FeParameter;
use rotorid::refine::finite_element::{refine_fe, FeData, FeInitial, FeRefineOptions, FeSummary};
use rotorid::simulate::finite_element::FeResponse;

use super::{IdentifyArgs, IdentifyMethod};
use crate::io::{FileMode, Output, ScenarioSpec};

/// Identify a finite-element rotor (module doc).
pub fn run(args: &IdentifyArgs, spec: &ScenarioSpec) -> anyhow::Result<()> {
    if args.method != IdentifyMethod::Refine {
        bail!(
            "{}: a finite-element rotor is identified by --method refine (maximum likelihood \
             on the reduced model), not --method {:?}",
            spec.origin(),
            args.method
        );
    }
    for (flag, given) in [
        ("--columns", args.columns.is_some()),
        ("--every", args.every.is_some()),
        ("--model", args.settings.model.is_some()),
    ] {
        if given {
            bail!("{flag} does not apply to a finite-element rotor (rotor.model = \"finite_element\")");
        }
    }
    super::check_outputs(args)?;
    let start = crate::io::finite_element::finite_element_of(spec)?;
    let mut options = FeRefineOptions::new(&start);
    if let Some(names) = &args.settings.unknowns {
        options.unknowns = FeParameter::parse_list(&names.join(","), &start)
            .map_err(|e| anyhow::anyhow!("--unknowns: {e}"))?;
    }
    if let Some(init) = &args.initial {
        options.initial = init
            .parse::<FeInitial>()
            .map_err(|e| anyhow::anyhow!("--initial: {e}"))?;
    }
    if let Some(m) = args.modes {
        let n = start.matrices.n();
        if m == 0 || m > n {
            bail!(
                "--modes = {m} is out of range: 1 ..= {n} (the degrees of freedom of the matrices)"
            );
        }
        options.modes = m;
    }
    options.offsets = args.offsets;
    let Some(&speed) = spec.speed_profile() else {
        bail!(
            "{}: a finite-element identification needs the scenario's [speed] (kind = \
             \"constant\" with rpm, or kind = \"ramp\" with rpm0 and accel [rad/s^2]): the \
             model is driven by that profile from the record's first sample",
            spec.origin()
        );
    };
    let data: FeResponse =
        if let Some(acq) = crate::io::finite_element::fe_acquisition_of(spec, &start)? {
            // a raw acquisition: each node's probes conditioned without a rotor guess, so
            // each channel keeps the mean of the motion over the record's revolutions in
            // its DC: one constant offset per channel is fitted with the parameters
            let table = crate::io::tables::read(&args.input)?;
            let raw = crate::io::tables::fe_raw_record(&table, acq)?;
            let slow = crate::io::tables::fe_slow_roll(spec, acq)?;
            let c = rotorid::acquisition::condition_fe_raw(&raw, acq, slow.as_ref())
                .with_context(|| args.input.clone())?;
            crate::commands::condition::print_fe_reports(&c.reports);
            check_keyphasor_speed(&args.input, &c.response, &speed)?;
            options.offsets = true;
            c.response
        } else {
            let data = crate::io::fe_response::read_fe_response(
                &args.input,
                &start,
                Some(&speed),
                args.time_tolerance,
            )?;
            // a record's own speed columns must be the profile the model is driven by
            if let Some(i) = (0..data.len()).find(|&i| {
                let s = speed.at(data.t[i] - data.t[0]);
                (data.phi_dot[i] - s.omega).abs() > 1e-6 * s.omega.abs().max(1.0)
            }) {
                let s = speed.at(data.t[i] - data.t[0]);
                bail!(
                    "{}: phi_dot at t = {} s is {} rad/s but the scenario's [speed] gives {} \
                     rad/s there: the finite-element fit is driven by the [speed] profile \
                     (from the record's first sample), so the record's speed must follow it \
                     (within 1e-6); measured speed is not used yet",
                    args.input,
                    data.t[i],
                    data.phi_dot[i],
                    s.omega
                );
            }
            data
        };
    let fe = FeData {
        response: &data,
        speed,
    };
    let dt = fe.checked_dt().with_context(|| args.input.clone())?;
    let fit = refine_fe(&fe, &start, &options).with_context(|| args.input.clone())?;
    let t = (data.t[0], data.t[data.t.len() - 1]);
    let mut summary = FeSummary::new(&fit, t, dt, &|_| None);
    summary.input = Some(args.input.clone());
    summary.scenario = Some(spec.origin().to_owned());
    // the estimates table: one row, t then each unknown and its standard error
    let mut out = Output::create(&args.out, FileMode::Atomic)?;
    let mut header = vec!["t".to_owned()];
    let mut row = vec![ryu_like(t.1)];
    for p in &summary.parameters {
        header.push(format!("{} [{}]", p.parameter, p.unit));
        header.push(format!("{}_std [{}]", p.parameter, p.unit));
        row.push(p.value.map(ryu_like).unwrap_or_default());
        row.push(p.std_error.map(ryu_like).unwrap_or_default());
    }
    writeln!(out, "{}\n{}", header.join(","), row.join(","))
        .with_context(|| format!("cannot write {}", args.out))?;
    out.commit()?;
    if let Some(path) = &args.summary {
        super::write_summary(path, &summary)?;
    }
    if !args.quiet {
        eprintln!("{}", report(&summary));
    } else {
        for d in &summary.diagnostics {
            eprintln!("warning: {}", serde_json::to_string(d).unwrap_or_default());
        }
    }
    Ok(())
}

use std::io::Write as _;

fn ryu_like(v: f64) -> String {
    format!("{v:e}")
}

/// Largest RMS deviation of a raw record's keyphasor speed from the scenario's profile
/// that is accepted, relative to the profile's RMS speed.
const KEYPHASOR_SPEED_TOLERANCE: f64 = 1e-3;

/// A raw record's speed from its keyphasor must follow the scenario's [speed] profile the
/// model is driven by: the RMS of (phi_dot - profile) over the RMS of the profile within
/// [`KEYPHASOR_SPEED_TOLERANCE`] (the keyphasor's speed interpolates between its events, so
/// it is compared as a whole, not sample by sample).
fn check_keyphasor_speed(
    input: &str,
    data: &FeResponse,
    speed: &rotorid::model::SpeedProfile,
) -> anyhow::Result<()> {
    let (mut d2, mut s2) = (0.0, 0.0);
    for (t, w) in data.t.iter().zip(&data.phi_dot) {
        let s = speed.at(t - data.t[0]).omega;
        d2 += (w - s) * (w - s);
        s2 += s * s;
    }
    let n = data.len().max(1) as f64;
    let (d, s) = ((d2 / n).sqrt(), (s2 / n).sqrt());
    if d.is_nan() || d > KEYPHASOR_SPEED_TOLERANCE * s.max(1.0) {
        bail!(
            "{input}: the keyphasor's speed departs from the scenario's [speed] profile by \
             {d:.4e} rad/s RMS ({:.2e} of its RMS {s:.4e} rad/s; allowed {KEYPHASOR_SPEED_TOLERANCE:e}): \
             the finite-element fit is driven by the [speed] profile from the record's first \
             sample, so set [speed] to the speed the record was taken at",
            d / s.max(1.0)
        );
    }
    Ok(())
}

/// The human report: each parameter with its standard error, the fit's verdicts.
fn report(s: &FeSummary) -> String {
    let mut lines = vec![format!(
        "finite-element refine of {} ({} samples, channels {}), initial state {:?}, {} modes \
         + {} static shapes (reduced {} of {} DOF)",
        s.input.as_deref().unwrap_or("?"),
        s.record.samples,
        s.record.channels.join(", "),
        s.initial,
        s.reduction.modes,
        s.reduction.statics,
        s.reduction.size,
        s.reduction.full
    )];
    for o in s.offsets.iter().flatten() {
        lines.push(format!(
            "  offset of {:11} {:>14.6e} +- {:.2e} m (the conditioned channel's DC)",
            o.channel, o.value, o.std_error
        ));
    }
    for p in &s.parameters {
        let v = p.estimate.unwrap_or(f64::NAN);
        let e = p.std_error.unwrap_or(f64::INFINITY);
        let bias = p
            .reduction_bias_std
            .map(|b| format!(", reduction bias {b:+.1e} std"))
            .unwrap_or_default();
        lines.push(format!(
            "  {:20} {:>14.6e} +- {:.2e} {}{}{}",
            p.parameter,
            v,
            e,
            p.unit,
            if p.determined {
                ""
            } else {
                "  (NOT DETERMINED)"
            },
            bias
        ));
    }
    lines.push(format!(
        "  converged {}, identifiable {}, model adequate {}, {} trials",
        s.converged, s.identifiable, s.adequacy.model_adequate, s.iterations
    ));
    for d in &s.diagnostics {
        lines.push(format!(
            "  warning: {}",
            serde_json::to_string(d).unwrap_or_default()
        ));
    }
    lines.join("\n")
}
