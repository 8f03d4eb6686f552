//! The few lines `rotorid identify` prints on stderr for a person: per parameter the
//! value, the truth and error when known, and (algebraic) the identification time or
//! (modulating, refine) the standard error and Cramer-Rao bound; then every diagnostic as
//! a `warning:` line, or a `note:` line for a note (printed even with `--quiet`).

use std::fmt::Write as _;

use rotorid::pipeline::{CrbAt, Identification, MethodName, Severity, StartSource};

use crate::io::number::format_sig;

/// The `warning:` and `note:` lines: a prominent warning when refine says the record does
/// not determine the unknowns, then one line per diagnostic.
pub(crate) fn warning_lines(r: &Identification) -> Vec<String> {
    let mut out = Vec::new();
    if !r.identifiable() {
        out.push(
            "warning: NOT IDENTIFIABLE: this record does not determine every unknown (see \
             the warnings below); such values are reported with their huge or infinite \
             standard errors, must not be relied on, and are left empty in the estimates CSV"
                .to_owned(),
        );
    }
    out.extend(r.diagnostics.iter().map(|d| match d.severity {
        Severity::Warning => format!("warning: {}", d.message),
        Severity::Note => format!("note: {}", d.message),
    }));
    out
}

/// The whole report (module doc).
pub(crate) fn human(r: &Identification) -> String {
    let mut out = match r.method {
        MethodName::Refine => refine(r),
        MethodName::Modulating => modulating(r),
        MethodName::Algebraic => algebraic(r),
    };
    for w in warning_lines(r) {
        out.push('\n');
        out.push_str(&w);
    }
    out
}

fn input(r: &Identification) -> &str {
    r.input.as_deref().unwrap_or("the record")
}

/// `  m_x  =  14.2900000 kg      true 14.29  error +1.0e-9` (no newline), per-direction
/// parameter `i` (m_x, cx, kx, m_z, cz, kz), named as in the estimates CSV.
fn value_and_error(out: &mut String, r: &Identification, i: usize) {
    let p = &r.parameters[i];
    let _ = write!(out, "  {:<4} = ", p.parameter.column());
    match p.value {
        Some(v) => {
            let _ = write!(out, "{:>16} {:<6}", format_sig(v, 9), p.unit);
        }
        None => {
            let _ = write!(out, "{:>16} {:<6}", "none", "");
        }
    }
    if let (Some(t), Some(e)) = (p.truth, p.relative_error) {
        let _ = write!(out, "  true {t:<12} error {e:+.2e}");
    }
}

fn algebraic(r: &Identification) -> String {
    let mut out = String::new();
    let Some(a) = &r.algebraic else {
        return out;
    };
    let tol = a.tol.to_string();
    let _ = writeln!(
        out,
        "identified {} samples of {} ({} quadrature, tol {tol}):",
        r.record.samples,
        input(r),
        a.quadrature,
    );
    for i in 0..r.parameters.len() {
        value_and_error(&mut out, r, i);
        match r.parameters[i].identification_time_s {
            Some(t) => {
                let _ = write!(out, "  within {tol} from t = {t:.4} s");
            }
            None => {
                let _ = write!(out, "  never settled");
            }
        }
        out.push('\n');
    }
    let _ = write!(
        out,
        "  ill-conditioned instants (rcond < {:e}): x {}, z {}",
        a.rcond_min, a.flagged.x, a.flagged.z
    );
    out
}

fn modulating(r: &Identification) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "identified {} samples of {} by modulating functions",
        r.record.samples,
        input(r)
    );
    if let Some(m) = &r.modulating {
        let _ = write!(
            out,
            " ({} windows of {} s, hop {} s)",
            m.windows,
            format_sig(m.window_s, 4),
            format_sig(m.hop_s, 4)
        );
    }
    out.push_str(":\n");
    for i in 0..r.parameters.len() {
        value_and_error(&mut out, r, i);
        if let Some(e) = r.parameters[i].std_error {
            let _ = write!(out, "  +- {e:.2e}");
            if let Some(b) = r.parameters[i].crb {
                let _ = write!(out, "  (CRB {b:.2e}, {:.1}x)", e / b);
            }
        }
        out.push('\n');
    }
    if let Some(m) = &r.modulating {
        let _ = writeln!(
            out,
            "  rcond x {:.2e}, z {:.2e} (threshold {:e})",
            m.rcond.x, m.rcond.z, m.rcond_min
        );
        if let Some(at) = m.crb_at {
            let _ = writeln!(
                out,
                "  CRB: Cramer-Rao bound on the standard deviation at {}, with the estimated \
                 noise; for m_x, m_z the one-mass model's (a lower bound)",
                crb_at(at)
            );
        }
    }
    let _ = write!(out, "  noise (4th differences): {}", noise(r));
    out
}

/// Where a bound was evaluated, in words.
fn crb_at(at: CrbAt) -> &'static str {
    match at {
        CrbAt::Truth => "the scenario's rotor and initial state (the truth)",
        CrbAt::TruthParameters => "the scenario's rotor with the fitted initial state",
        CrbAt::Estimate => "the estimate (the scenario states no complete truth)",
    }
}

/// `sigma_x = ... m, sigma_z = ... m`.
fn noise(r: &Identification) -> String {
    match &r.noise {
        Some(n) => format!(
            "sigma_x = {:.3e} m, sigma_z = {:.3e} m",
            n.sigma_x_m, n.sigma_z_m
        ),
        None => "sigma_x = inf m, sigma_z = inf m".to_owned(),
    }
}

/// `1.23e-9`, or `inf` for `None`.
fn opt_e(v: Option<f64>) -> String {
    v.map_or_else(|| "inf".to_owned(), |v| format!("{v:.2e}"))
}

fn refine(r: &Identification) -> String {
    let mut out = String::new();
    let Some(d) = &r.refine else {
        return out;
    };
    let start = match (d.start.source, d.start.t_s) {
        (StartSource::Algebraic, Some(t)) => {
            format!("algebraic estimate at t = {} s", format_sig(t, 4))
        }
        (StartSource::Nominal, _) => "the scenario's values".to_owned(),
        (StartSource::Given, _) => "the given values".to_owned(),
        (StartSource::NestedModel, _) => "the Jeffcott fit, cross terms 0".to_owned(),
        _ => "modulating estimate".to_owned(),
    };
    let model = match r.model {
        rotorid::parameter::ModelKind::Jeffcott => String::new(),
        m => format!(", {m} model"),
    };
    let _ = writeln!(
        out,
        "refined {} samples of {}, t = {} .. {} s by maximum likelihood{model} (start: {start}):",
        r.record.samples,
        input(r),
        format_sig(r.record.t_first_s, 6),
        format_sig(r.record.t_last_s, 6)
    );
    let _ = writeln!(
        out,
        "  {:<6} {:>16} {:<8} {:>12} {:>11} {:>12} {:>12} {:>14} {:>10}",
        "", "value", "", "+- std err", "rel. std", "robust", "CRB", "true", "err/std"
    );
    for p in &r.parameters {
        let v = p.estimate.unwrap_or(f64::NAN);
        let _ = write!(
            out,
            "  {:<6} {:>16} {:<8} {:>12} {:>11} {:>12} {:>12}",
            p.parameter.name(),
            format_sig(v, 9),
            p.unit,
            format!("+- {}", opt_e(p.std_error)),
            p.relative_std_error
                .map_or("-".to_owned(), |r| format!("{r:.2e}")),
            p.robust_std_error
                .map_or("-".to_owned(), |r| format!("{r:.2e}")),
            opt_e(p.crb),
        );
        if let Some(t) = p.truth {
            let z = p
                .std_error
                .map_or("-".to_owned(), |e| format!("{:+.2}", (v - t) / e));
            let _ = write!(out, " {:>14} {:>10}", format_sig(t, 7), z);
        }
        out.push('\n');
    }
    if !d.initial_state.is_empty() {
        let parts: Vec<String> = d
            .initial_state
            .iter()
            .map(|s| {
                format!(
                    "{} = {:.3e} +- {} {}",
                    s.name,
                    s.value,
                    s.std_error.map_or("inf".to_owned(), |e| format!("{e:.3e}")),
                    s.unit
                )
            })
            .collect();
        let _ = writeln!(out, "  initial state: {}", parts.join(", "));
    }
    let _ = writeln!(out, "  noise (residuals): {}", noise(r));
    if let (Some(l), Some(rho)) = (d.hac_bandwidth, d.residual_lag1_autocorrelation) {
        let _ = writeln!(
            out,
            "  robust: sandwich standard error, Bartlett bandwidth {l} samples (residual lag-1 \
             autocorrelation {rho:.2}); about the Fisher one when the model fits"
        );
    }
    let at = d.crb_at.map_or("-", crb_at);
    let _ = writeln!(
        out,
        "  CRB: Cramer-Rao bound on the standard deviation at {at}, with the fitted noise"
    );
    if let Some(note) = &d.start.note {
        let _ = writeln!(out, "  start: {note}");
    }
    let _ = write!(
        out,
        "  {} after {} model passes; {}; Fisher condition number {}",
        if d.converged {
            "converged"
        } else {
            "NOT converged"
        },
        d.iterations,
        if d.identifiable {
            "identifiable"
        } else {
            "NOT identifiable"
        },
        d.condition_number
            .map_or("inf".to_owned(), |c| format!("{c:.3e}"))
    );
    out
}
