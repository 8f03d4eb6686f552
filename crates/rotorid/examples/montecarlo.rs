//! Monte Carlo study of the identifiers under white measurement noise.
//!
//! ```text
//! cargo run --release -p rotorid --example montecarlo [-- --seeds N] [--out PATH]
//! ```
//!
//! Cases: table1 at a constant 1200 rpm and on the 10 rad/s^2 ramp from 600 rpm (phi(0) = 0,
//! zero initial state, dt = 0.1 ms, exact simulation), SNR 20, 40, 60 dB, record length
//! T = 0.1, 0.3, 1 s; N noise seeds each (default 100). Noise per channel c in {x, z}:
//! sigma_c = RMS(c over the record) 10^(-SNR/20) (docs/method.md section 2.5, `add_noise`).
//!
//! Methods, each through `rotorid::pipeline::identify` with its defaults (a, m_u d and
//! alpha known; m, cx, kx, cz, kz estimated):
//! - plain: the paper's algebraic identifier, each direction's final estimate (its last
//!   well-conditioned instant <= T);
//! - modulating: window 20 ms, hop 2.5 ms, 3 test functions, noise bias compensated with
//!   sigma estimated from the data;
//! - refine: maximum likelihood, initial state estimated, from the pipeline's start
//!   (docs/method.md section 5.2: the modulating estimate, else the early algebraic one).
//!
//! Per case, method and parameter: RMS relative error sqrt(mean(e^2)), bias mean(e), with
//! e = estimate / truth - 1, and the coverage of the 95 % interval estimate +- 1.96 se
//! (refine: its asymptotic ML standard errors; modulating: its sandwich standard errors;
//! plain: none, n/a). m is the x direction's for plain and modulating. CRB: the
//! Cramer-Rao bound on the relative standard deviation with the initial state unknown
//! (`crb_at_snr`, `Unknowns::default()`), the floor for any unbiased estimator.
//!
//! Writes the Markdown table to stdout and to `docs/montecarlo.md` (or `--out PATH`).

use std::fmt::Write as _;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use rotorid::model::{RotorParams, Sampling, Scenario};
use rotorid::pipeline::{
    identify, Identification, Knowledge, Method as IdMethod, Record, StartSource,
};
use rotorid::refine::{crb_at_snr, Unknowns};
use rotorid::simulate::{add_noise, simulate, Method, TimeResponse};
use rotorid::Parameter;

const NAMES: [&str; 5] = ["m", "cx", "kx", "cz", "kz"];
const SNRS: [f64; 3] = [20.0, 40.0, 60.0];
const DURATIONS: [f64; 3] = [0.1, 0.3, 1.0];
const METHODS: [&str; 3] = ["plain", "modulating", "refine"];

/// One simulated case: scenario, SNR, clean record and the bound.
struct Case {
    label: &'static str,
    scenario: Scenario,
    snr: f64,
    clean: TimeResponse,
    /// Relative CRB of m, cx, kx, cz, kz.
    crb: [f64; 5],
}

/// One method's result on one noisy record: values and standard errors of m, cx, kx, cz,
/// kz (None when the method gave no estimate).
type Outcome = Option<([f64; 5], Option<[f64; 5]>)>;

/// The three methods' outcomes on one record, and whether refine converged.
struct Run {
    case: usize,
    outcomes: [Outcome; 3],
    refine_converged: bool,
    refine_from_plain: bool,
}

#[derive(Default, Clone, Copy)]
struct Stats {
    n: usize,
    failed: usize,
    sum: [f64; 5],
    sum2: [f64; 5],
    covered: [usize; 5],
    with_se: usize,
}

fn main() {
    let mut seeds: u64 = 100;
    let mut out = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/montecarlo.md").to_string();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        match (args[i].as_str(), args.get(i + 1)) {
            ("--seeds", Some(v)) => {
                seeds = match v.parse() {
                    Ok(n) if n >= 2 => n,
                    _ => exit_usage(&format!("--seeds {v}: expected an integer >= 2")),
                };
                i += 2;
            }
            ("--out", Some(v)) => {
                out = v.clone();
                i += 2;
            }
            (a, _) => exit_usage(&format!("unknown or incomplete argument {a:?}")),
        }
    }
    let started = Instant::now();
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(2);

    // the cases, simulated and bounded in parallel
    let mut specs = Vec::new();
    for (label, base) in [
        ("1200 rpm", Scenario::table1()),
        (
            "ramp 600 rpm + 10 rad/s^2",
            Scenario::table1_ramp(600.0).expect("valid"),
        ),
    ] {
        for &t in &DURATIONS {
            for &snr in &SNRS {
                let mut s = base;
                s.sampling = Sampling::new(1e-4, t).expect("valid");
                specs.push((label, s, snr));
            }
        }
    }
    let cases: Vec<Case> = parallel_map(threads, specs.len(), |k| {
        let (label, scenario, snr) = specs[k];
        let clean = simulate(&scenario, Method::Exact).expect("simulation");
        let bound = crb_at_snr(&scenario, snr, &Unknowns::default()).expect("crb");
        let crb = NAMES.map(|n| bound.relative(n).expect("bound"));
        Case {
            label,
            scenario,
            snr,
            clean,
            crb,
        }
    });
    eprintln!(
        "{} cases simulated in {:.1} s; {} seeds each on {threads} threads",
        cases.len(),
        started.elapsed().as_secs_f64(),
        seeds
    );

    let jobs = cases.len() * seeds as usize;
    let runs: Vec<Run> = parallel_map(threads, jobs, |j| {
        let (case, seed) = (j / seeds as usize, (j % seeds as usize) as u64);
        run_one(&cases[case], case, seed)
    });

    // accumulate
    let mut stats = vec![[Stats::default(); 3]; cases.len()];
    let mut not_converged = vec![0usize; cases.len()];
    let mut from_plain = vec![0usize; cases.len()];
    for r in &runs {
        if !r.refine_converged && r.outcomes[2].is_some() {
            not_converged[r.case] += 1;
        }
        if r.refine_from_plain {
            from_plain[r.case] += 1;
        }
        for (m, o) in r.outcomes.iter().enumerate() {
            let s = &mut stats[r.case][m];
            match o {
                None => s.failed += 1,
                Some((e, se)) => {
                    s.n += 1;
                    for (i, ei) in e.iter().enumerate() {
                        s.sum[i] += ei;
                        s.sum2[i] += ei * ei;
                        if se.is_some_and(|se| ei.abs() <= 1.96 * se[i]) {
                            s.covered[i] += 1;
                        }
                    }
                    if se.is_some() {
                        s.with_se += 1;
                    }
                }
            }
        }
    }
    let elapsed = started.elapsed().as_secs_f64();
    let md = table(
        &cases,
        &stats,
        &not_converged,
        &from_plain,
        seeds,
        elapsed,
        threads,
    );
    print!("{md}");
    if let Err(e) = std::fs::write(&out, &md) {
        eprintln!("could not write {out}: {e}");
        std::process::exit(1);
    }
    let shown = std::fs::canonicalize(&out)
        .map(|p| p.display().to_string())
        .unwrap_or(out);
    eprintln!("wrote {shown} ({elapsed:.0} s)");
}

fn exit_usage(msg: &str) -> ! {
    eprintln!("{msg}\nusage: montecarlo [--seeds N (>= 2, default 100)] [--out PATH]");
    std::process::exit(2);
}

/// f(0..n) on `threads` threads (work shared through an atomic counter), in order.
fn parallel_map<T: Send>(threads: usize, n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let mut parts: Vec<Vec<(usize, T)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads.max(1))
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        if k >= n {
                            break mine;
                        }
                        mine.push((k, f(k)));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("worker panicked"))
            .collect()
    });
    let mut all: Vec<(usize, T)> = parts.drain(..).flatten().collect();
    all.sort_by_key(|(k, _)| *k);
    all.into_iter().map(|(_, v)| v).collect()
}

/// Relative errors of (m, cx, kx, cz, kz) from (m, cx, kx, cz, kz) values.
fn rel(truth: &RotorParams, v: [f64; 5]) -> [f64; 5] {
    let t = [truth.m, truth.cx, truth.kx, truth.cz, truth.kz];
    [0, 1, 2, 3, 4].map(|i| v[i] / t[i] - 1.0)
}

fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn run_one(case: &Case, index: usize, seed: u64) -> Run {
    let s = &case.scenario;
    let truth = s.rotor.params();
    let mut r = case.clean.clone();
    // distinct seeds per case and record
    add_noise(&mut r, case.snr, 1_000_000 * index as u64 + seed).expect("noise");
    let rec = Record::from_response(&r).expect("a simulated record");
    let k = Knowledge::from_scenario(s);
    // Each method through the pipeline, as every caller runs it: values of m (the x
    // direction's for the per-direction methods), cx, kx, cz, kz, even where withheld.
    let run = |method: &IdMethod| identify(&rec, &k, method).ok();
    let outcome = |id: &Option<Identification>, m: Parameter| -> Outcome {
        let id = id.as_ref()?;
        let of = |p: Parameter| id.parameter(p);
        let ps = [
            m,
            Parameter::Cx,
            Parameter::Kx,
            Parameter::Cz,
            Parameter::Kz,
        ];
        let vals = ps.map(|p| of(p).and_then(|r| r.estimate).unwrap_or(f64::NAN));
        if !finite(&vals) {
            return None;
        }
        let t = [truth.m, truth.cx, truth.kx, truth.cz, truth.kz];
        let ses = ps.map(|p| of(p).and_then(|r| r.std_error).unwrap_or(f64::NAN));
        let rel_se = [0, 1, 2, 3, 4].map(|i| ses[i] / t[i]);
        Some((rel(&truth, vals), finite(&rel_se).then_some(rel_se)))
    };
    let plain = outcome(&run(&IdMethod::algebraic()), Parameter::MX);
    let modulating = outcome(&run(&IdMethod::modulating()), Parameter::MX);
    let fit = run(&IdMethod::refine());
    let refined = outcome(&fit, Parameter::M);
    let detail = fit.as_ref().and_then(|f| f.refine.as_ref());
    Run {
        case: index,
        outcomes: [plain, modulating, refined],
        refine_converged: detail.is_some_and(|d| d.converged),
        refine_from_plain: detail.is_some_and(|d| d.start.source == StartSource::Algebraic),
    }
}

/// UTC date (YYYY-MM-DD) of the Unix time `secs` (Hinnant's days-to-civil algorithm).
fn utc_date(secs: u64) -> String {
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

fn table(
    cases: &[Case],
    stats: &[[Stats; 3]],
    not_converged: &[usize],
    from_plain: &[usize],
    seeds: u64,
    elapsed: f64,
    threads: usize,
) -> String {
    let date = utc_date(
        SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0),
    );
    let mut s = String::new();
    let cmd = if seeds == 100 {
        "cargo run --release -p rotorid --example montecarlo".to_string()
    } else {
        format!("cargo run --release -p rotorid --example montecarlo -- --seeds {seeds}")
    };
    let _ = writeln!(s, "# Monte Carlo study of the identifiers under noise\n");
    let _ = writeln!(s, "Command: `{cmd}`  ");
    let _ = writeln!(
        s,
        "Date: {date} (UTC); {seeds} noise seeds per case; {elapsed:.0} s on {threads} threads.\n"
    );
    let _ = writeln!(
        s,
        "table1 rotor (m = 14.29 kg, cx = cz = 10 N s/m, kx = kz = 1.195e6 N/m; a, m_u d, alpha \
         known), zero initial state, dt = 0.1 ms, exact simulation; white noise per channel with \
         sigma = RMS(channel over the record) x 10^(-SNR/20). Methods: **plain** = the paper's \
         algebraic identifier at the last well-conditioned instant <= T; **modulating** = \
         `identify_modulating` (window 20 ms, hop 2.5 ms, 3 test functions, noise bias \
         compensated); **refine** = maximum likelihood (initial state estimated), started from \
         the modulating estimate. For plain and modulating, m is the x direction's.\n"
    );
    let _ = writeln!(
        s,
        "Each cell: RMS relative error (its ratio to the CRB) / bias (mean relative error) / \
         coverage of the 95 % interval +-1.96 standard errors (n/a: the method gives none). \
         Row CRB: the Cramer-Rao bound on the relative standard deviation (initial state \
         unknown). `fail`: records without a (finite, well-conditioned) estimate, excluded \
         from the statistics.\n"
    );
    // summary over all cases
    let _ = writeln!(s, "## Summary over the {} cases\n", cases.len());
    let _ = writeln!(
        s,
        "| method | RMS / CRB: m, kx, kz | RMS / CRB: cx, cz | max abs(bias) / CRB | 95 % coverage | fail |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for (m, name) in METHODS.iter().enumerate() {
        let mut mk = (f64::INFINITY, 0.0f64);
        let mut c = (f64::INFINITY, 0.0f64);
        let mut bias = 0.0f64;
        let mut cover = (f64::INFINITY, 0.0f64);
        let mut failed = 0;
        for (k, case) in cases.iter().enumerate() {
            let st = &stats[k][m];
            failed += st.failed;
            if st.n == 0 {
                continue;
            }
            let n = st.n as f64;
            for i in 0..5 {
                let r = (st.sum2[i] / n).sqrt() / case.crb[i];
                let range = if i == 1 || i == 3 { &mut c } else { &mut mk };
                *range = (range.0.min(r), range.1.max(r));
                bias = bias.max((st.sum[i] / n).abs() / case.crb[i]);
                if st.with_se > 0 {
                    let v = st.covered[i] as f64 / st.with_se as f64;
                    cover = (cover.0.min(v), cover.1.max(v));
                }
            }
        }
        let cov = if cover.0.is_finite() {
            format!("{:.0} - {:.0} %", 100.0 * cover.0, 100.0 * cover.1)
        } else {
            "n/a".to_string()
        };
        let _ = writeln!(
            s,
            "| {name} | {} - {} | {} - {} | {} | {cov} | {failed} |",
            ratio(mk.0),
            ratio(mk.1),
            ratio(c.0),
            ratio(c.1),
            ratio(bias)
        );
    }
    let _ = writeln!(
        s,
        "\nWith {seeds} seeds an RMS is known to about +-{:.0} % and a coverage of 95 % to \
         about +-{:.0} points (one standard deviation).",
        100.0 / (2.0 * seeds as f64).sqrt(),
        100.0 * (0.95f64 * 0.05 / seeds as f64).sqrt()
    );

    let mut last_label = "";
    for (k, c) in cases.iter().enumerate() {
        if c.label != last_label {
            last_label = c.label;
            let _ = writeln!(s, "\n## {}\n", c.label);
            let _ = writeln!(
                s,
                "| T [s] | SNR [dB] | method | m | cx | kx | cz | kz | fail |"
            );
            let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        }
        let t = c.scenario.sampling.duration();
        let crb: Vec<String> = c.crb.iter().map(|v| format!("{v:.1e}")).collect();
        let _ = writeln!(s, "| {t} | {} | CRB | {} | |", c.snr, crb.join(" | "));
        for (m, name) in METHODS.iter().enumerate() {
            let st = &stats[k][m];
            let mut cells = Vec::new();
            for i in 0..5 {
                if st.n == 0 {
                    cells.push("-".to_string());
                    continue;
                }
                let n = st.n as f64;
                let rms = (st.sum2[i] / n).sqrt();
                let bias = st.sum[i] / n;
                let cover = if st.with_se > 0 {
                    format!("{:.0} %", 100.0 * st.covered[i] as f64 / st.with_se as f64)
                } else {
                    "n/a".to_string()
                };
                cells.push(format!(
                    "{rms:.1e} ({}) / {bias:+.1e} / {cover}",
                    ratio(rms / c.crb[i])
                ));
            }
            let mut fail = st.failed.to_string();
            if m == 2 && (not_converged[k] > 0 || from_plain[k] > 0) {
                let _ = write!(
                    fail,
                    " ({} not conv., {} from plain)",
                    not_converged[k], from_plain[k]
                );
            }
            let _ = writeln!(s, "| | | {name} | {} | {fail} |", cells.join(" | "));
        }
    }
    s
}

/// A ratio to 2 significant digits, or in scientific notation when large.
fn ratio(r: f64) -> String {
    if r < 100.0 {
        format!("{r:.2}x")
    } else {
        format!("{r:.0e}x")
    }
}
