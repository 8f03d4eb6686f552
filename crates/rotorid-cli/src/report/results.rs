//! The numbers of the report: per case, setting, parameter and direction, the estimate at
//! 0.3 s, its relative error and the identification time, beside the paper's claims.
//!
//! ```text
//! relative error        e = (theta_hat(t_r) - theta) / theta,   t_r = 0.3 s
//! identification time   T = min { t_k : |theta_hat(t_j) - theta| <= tol |theta|
//!                                       for every well-conditioned t_j >= t_k in the record }
//! ```
//!
//! with tol = 1 %. T measures convergence to the TRUE value (the paper's "tiempo de
//! identificación"); `settling_time` is the identifier's own answer without the truth
//! ([`rotorid::identify::algebraic::ConvergenceTracker`]: within 1 % of its final value). Instants
//! with rcond < rcond_min are not estimates and are skipped by both
//! (docs/method.md section 3.6). Paper's claims (Barredo et al. 2024, "Resultados"):
//! constant speed, all parameters in < 0.2 s; ramp, m and k in < 0.1 s and c in < 0.28 s.

use rotorid::identify::algebraic::ConvergenceTracker;
use rotorid::Parameter;
use serde::Serialize;

use super::experiment::{Run, PAPER_DT};

/// Relative band of the identification time (1 %).
pub const TOLERANCE: f64 = 0.01;
/// The instant the estimates are read at [s].
pub const ESTIMATE_TIME: f64 = 0.3;

/// One parameter of one direction, in one case and setting.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// `constant` or `ramp`.
    pub case: &'static str,
    /// `paper` or `ours`.
    pub setting: &'static str,
    /// `m`, `c` or `k`.
    pub parameter: &'static str,
    /// `x` or `z`.
    pub direction: &'static str,
    /// `m_x`, `c_x`, `k_x`, `m_z`, `c_z` or `k_z`.
    pub name: &'static str,
    /// `kg`, `N s/m` or `N/m`.
    pub unit: &'static str,
    /// The true value (unit above).
    pub true_value: f64,
    /// The estimate at the last well-conditioned instant at or before 0.3 s (unit above).
    pub estimate: Option<f64>,
    /// That instant [s].
    pub estimate_t: Option<f64>,
    /// (estimate - true) / true (dimensionless; None when there is no estimate or the
    /// true value is 0).
    pub relative_error: Option<f64>,
    /// Time from which every well-conditioned estimate stays within 1 % of the true value
    /// [s]; None when the last estimate is outside that band.
    pub identification_time: Option<f64>,
    /// Time from which every well-conditioned estimate stays within 1 % of the final
    /// estimate (the identifier's own convergence time, no truth needed) [s].
    pub settling_time: Option<f64>,
    /// The paper's reported identification time (an upper bound, "less than") [s].
    pub paper_time: f64,
    /// identification_time <= paper_time.
    pub within_paper_time: bool,
    /// Of the well-conditioned instants from paper_time to the end of the record, the
    /// fraction outside 1 % of the true value (dimensionless; isolated spikes near the
    /// instants where A(t) is near singular show up here).
    pub outside_after_paper_time: f64,
    /// Number of instants flagged ill-conditioned (rcond < rcond_min) in the record.
    pub flagged_instants: usize,
}

/// Largest difference between the Newmark and the exact response of one case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResponseComparison {
    /// `constant` or `ramp`.
    pub case: &'static str,
    /// max over the record of |x_exact| and |z_exact| [m].
    pub exact_peak: f64,
    /// max over the record of |x_newmark - x_exact| and |z_newmark - z_exact| [m].
    pub max_difference: f64,
    /// max_difference / exact_peak (dimensionless).
    pub relative: f64,
}

/// One combination of data and rule in one case, summarised over the six parameters:
/// which of the paper's two choices (Newmark data, trapezoid rule) causes its error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Attribution {
    /// `constant` or `ramp`.
    pub case: &'static str,
    /// `paper`, `trapezoid-rule`, `newmark-data` or `ours`.
    pub setting: &'static str,
    /// `newmark` or `exact`.
    pub simulation: String,
    /// The quadrature rule's name.
    pub quadrature: &'static str,
    /// The parameter with the largest |relative error| at 0.3 s.
    pub worst_parameter: &'static str,
    /// Its relative error (dimensionless; NaN when no parameter has an estimate).
    pub worst_relative_error: f64,
    /// The largest, over the six parameters, share of well-conditioned instants after the
    /// paper's time outside 1 % of the true value (dimensionless).
    pub worst_share_outside: f64,
}

/// Summarise `run` (any setting) as an [`Attribution`].
pub fn attribution(run: &Run) -> Attribution {
    let rows = rows(run);
    let worst = rows
        .iter()
        .filter_map(|r| r.relative_error.map(|e| (e, r.name)))
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
    Attribution {
        case: run.case.name(),
        setting: run.setting.name(),
        simulation: run.setting.method().to_string(),
        quadrature: run.setting.quadrature().name(),
        worst_parameter: worst.map_or("", |w| w.1),
        worst_relative_error: worst.map_or(f64::NAN, |w| w.0),
        worst_share_outside: rows
            .iter()
            .map(|r| r.outside_after_paper_time)
            .fold(0.0, f64::max),
    }
}

/// Position of the per-direction parameter `p` in an estimate's `values()`.
pub fn index(p: Parameter) -> usize {
    p.direction_index()
        .expect("the paper's figures show the per-direction parameters only")
}

/// The true value of `p` for the rotor of `run`.
pub fn true_value(run: &Run, p: Parameter) -> f64 {
    let r = &run.scenario.rotor;
    [r.m(), r.cx(), r.kx(), r.m(), r.cz(), r.kz()][index(p)]
}

/// `m`, `c` or `k`.
pub fn symbol(p: Parameter) -> &'static str {
    ["m", "c", "k"][index(p) % 3]
}

/// `x` or `z`.
pub fn direction(p: Parameter) -> &'static str {
    ["x", "z"][index(p) / 3]
}

/// Well-conditioned flag of parameter `p` at every estimate of `run`.
pub fn well_conditioned(run: &Run, p: Parameter) -> Vec<bool> {
    let dir = index(p) / 3;
    run.estimates
        .iter()
        .map(|e| e.well_conditioned(run.config.rcond_min)[dir] && e.values()[index(p)].is_finite())
        .collect()
}

/// Earliest time from which every instant with `ok` has `v` within `tol |truth|` of
/// `truth` (module doc); None when the last such instant is outside the band or there is
/// none.
pub fn time_within(t: &[f64], v: &[f64], ok: &[bool], truth: f64, tol: f64) -> Option<f64> {
    let band = tol * truth.abs();
    let mut answer = None;
    for i in (0..t.len()).rev() {
        if !ok[i] {
            continue;
        }
        if (v[i] - truth).abs() <= band {
            answer = Some(t[i]);
        } else {
            break;
        }
    }
    answer
}

/// Of the instants with `ok` and t >= `from`, the fraction with `v` outside
/// `tol |truth|` of `truth` (0 when there is none).
pub fn fraction_outside(t: &[f64], v: &[f64], ok: &[bool], truth: f64, tol: f64, from: f64) -> f64 {
    let band = tol * truth.abs();
    let (mut n, mut out) = (0usize, 0usize);
    for i in 0..t.len() {
        if ok[i] && t[i] >= from {
            n += 1;
            if (v[i] - truth).abs() > band {
                out += 1;
            }
        }
    }
    if n == 0 {
        0.0
    } else {
        out as f64 / n as f64
    }
}

/// The six rows of one run.
pub fn rows(run: &Run) -> Vec<Row> {
    let t: Vec<f64> = run.estimates.iter().map(|e| e.t).collect();
    let mut tracker = ConvergenceTracker::new(TOLERANCE, run.config.rcond_min)
        .expect("1 % and a validated rcond_min are in range");
    for e in &run.estimates {
        tracker.push(e);
    }
    // the sample at 0.3 s, with slack for the exact grid t_i = i dt
    let t_read = ESTIMATE_TIME + 0.5 * PAPER_DT;
    Parameter::PER_DIRECTION
        .iter()
        .map(|&p| {
            let v: Vec<f64> = run.estimates.iter().map(|e| e.values()[index(p)]).collect();
            let ok = well_conditioned(run, p);
            let truth = true_value(run, p);
            let at = (0..t.len()).rev().find(|&i| ok[i] && t[i] <= t_read);
            let estimate = at.map(|i| v[i]);
            let identification_time = time_within(&t, &v, &ok, truth, TOLERANCE);
            let paper_time = run.case.paper_time(symbol(p));
            Row {
                case: run.case.name(),
                setting: run.setting.name(),
                parameter: symbol(p),
                direction: direction(p),
                name: p.column(),
                unit: p.unit(),
                true_value: truth,
                estimate,
                estimate_t: at.map(|i| t[i]),
                relative_error: estimate
                    .filter(|_| truth != 0.0)
                    .map(|e| (e - truth) / truth),
                identification_time,
                settling_time: tracker.result(p).and_then(|c| c.identification_time),
                paper_time,
                within_paper_time: identification_time.is_some_and(|ti| ti <= paper_time),
                outside_after_paper_time: fraction_outside(
                    &t, &v, &ok, truth, TOLERANCE, paper_time,
                ),
                flagged_instants: ok.iter().filter(|o| !**o).count(),
            }
        })
        .collect()
}

/// Compare the Newmark run and the exact run of one case.
pub fn compare_responses(newmark: &Run, exact: &Run) -> ResponseComparison {
    let (a, b) = (&newmark.response, &exact.response);
    let peak = b.x.iter().chain(&b.z).fold(0.0f64, |m, v| m.max(v.abs()));
    let diff =
        a.x.iter()
            .zip(&b.x)
            .chain(a.z.iter().zip(&b.z))
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    ResponseComparison {
        case: exact.case.name(),
        exact_peak: peak,
        max_difference: diff,
        relative: if peak > 0.0 { diff / peak } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identification_time_is_the_start_of_the_final_stay_in_the_band() {
        let t = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];
        let v = [50.0, 10.05, 11.0, 10.05, 9.95, 10.0];
        let ok = [true; 6];
        assert_eq!(time_within(&t, &v, &ok, 10.0, 0.01), Some(0.3));
        // a flagged excursion does not count
        let ok = [true, true, false, true, true, true];
        assert_eq!(time_within(&t, &v, &ok, 10.0, 0.01), Some(0.1));
        // never converged at the end
        let v = [10.0, 10.0, 10.0, 10.0, 10.0, 12.0];
        assert_eq!(time_within(&t, &v, &[true; 6], 10.0, 0.01), None);
        // in the band from the first instant
        assert_eq!(
            time_within(&t, &[10.0; 6], &[true; 6], 10.0, 0.01),
            Some(0.0)
        );
    }

    #[test]
    fn fraction_outside_counts_well_conditioned_instants_from_the_given_time() {
        let t = [0.0, 0.1, 0.2, 0.3, 0.4];
        let v = [50.0, 11.0, 10.0, 12.0, 10.0];
        let ok = [true, true, true, false, true];
        assert_eq!(fraction_outside(&t, &v, &ok, 10.0, 0.01, 0.1), 1.0 / 3.0);
        assert_eq!(fraction_outside(&t, &v, &ok, 10.0, 0.01, 0.5), 0.0);
    }
}
