//! Raw acquisitions (probes in volts, keyphasor, slow roll) conditioned back to x, z, phi
//! and checked against the simulator's exact truth (docs/acquisition.md).

use std::f64::consts::PI;

use rotorid::acquisition::{
    condition, simulate_raw, Acquisition, AcquisitionError, AcquisitionFinding, GuessSource,
    ModelGuess, RawRecord, RawSimulation,
};
use rotorid::model::{InitialState, Rotor, Sampling, Scenario, SpeedProfile};

/// Table 1 with 40 times its unbalance (x, z ~ 10-20 um at 1200 rpm), 25.6 kHz, `duration`.
fn scenario(ramp: bool, duration: f64) -> Scenario {
    let mut p = Rotor::table1().params();
    p.unbalance.m_u = 4.0e-3;
    Scenario {
        rotor: Rotor::new(p).unwrap(),
        speed: if ramp {
            SpeedProfile::ramp(1200.0, 10.0, 0.0).unwrap()
        } else {
            SpeedProfile::constant_rpm(1200.0, 0.0).unwrap()
        },
        sampling: Sampling::new(1.0 / 25600.0, duration).unwrap(),
        initial: InitialState::default(),
    }
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    (s / n as f64).sqrt()
}

/// RMS of phi - truth after removing the whole turns between them.
fn phi_error(phi: &[f64], truth: &[f64]) -> f64 {
    let turns = ((phi[0] - truth[0]) / (2.0 * PI)).round() * 2.0 * PI;
    rms(phi.iter().zip(truth).map(|(a, b)| a - b - turns))
}

fn guess(s: &Scenario) -> ModelGuess {
    ModelGuess {
        rotor: s.rotor.params(),
        initial: None,
        source: GuessSource::Scenario,
    }
}

#[test]
fn conditioned_record_matches_the_truth_constant_and_ramp() {
    for ramp in [false, true] {
        let s = scenario(ramp, 1.0);
        let acq = Acquisition::example();
        let raw: RawSimulation = simulate_raw(&s, &acq).unwrap();
        let c = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&guess(&s))).unwrap();
        let tr = &raw.truth;
        let ephi = phi_error(&c.phi, &tr.phi);
        let ex = rms(c.x.iter().zip(&tr.x).map(|(a, b)| a - b)) / raw.noise.sigma_x;
        let ez = rms(c.z.iter().zip(&tr.z).map(|(a, b)| a - b)) / raw.noise.sigma_z;
        let ew = rms(c.phi_dot.iter().zip(&tr.phi_dot).map(|(a, b)| a - b));
        let ewd = rms(c.phi_ddot.iter().zip(&tr.phi_ddot).map(|(a, b)| a - b));
        let xamp = tr.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        eprintln!(
            "ramp {ramp}: phi rms err {ephi:.3e} rad, omega {ew:.3e} rad/s, omega_dot {ewd:.3e}, x err/noise {ex:.4}, z {ez:.4}, |x| max {xamp:.3e}, jitter {:?}",
            c.report.keyphasor.jitter_s
        );
        eprintln!(
            "{:#?}",
            c.report.model.as_ref().map(|m| (m.offset, m.initial))
        );
        eprintln!("{:?}", c.report.findings);
        assert!(ephi < 1e-3, "{ephi}");
        assert!(ex < 1.05 && ez < 1.05, "{ex} {ez}");
    }
}

/// Per-parameter errors of refine (relative to the truth) on one seed: on perfectly
/// conditioned channels (true phi, true x, z + the same noise) and on the raw record
/// conditioned in two passes (no guess, then refine's own estimate).
struct SeedErrors {
    perfect: [f64; 5],
    conditioned: [f64; 5],
    first_pass: [f64; 5],
}

const NAMES: [&str; 5] = ["m", "cx", "kx", "cz", "kz"];

fn rel_errors(fit: &rotorid::refine::Refined, truth: &rotorid::RotorParams) -> [f64; 5] {
    let t = [truth.m, truth.cx, truth.kx, truth.cz, truth.kz];
    let mut e = [0.0; 5];
    for (k, n) in NAMES.iter().enumerate() {
        e[k] = fit.get(n).unwrap().value / t[k] - 1.0;
    }
    e
}

fn refine_on(
    dt: f64,
    x: &[f64],
    z: &[f64],
    phi: &[f64],
    w: &[f64],
    wd: &[f64],
    truth: &rotorid::RotorParams,
) -> rotorid::refine::Refined {
    use rotorid::refine::{refine, Record, RefineOptions, SpeedData};
    let rec = Record {
        dt,
        x,
        z,
        speed: SpeedData::Samples {
            phi,
            omega: w,
            omega_dot: wd,
        },
    };
    let mut start = *truth;
    start.m *= 1.01;
    start.kx *= 0.99;
    start.kz *= 1.01;
    start.cx *= 1.1;
    start.cz *= 0.9;
    let fit = refine(
        &rec,
        &start,
        &InitialState::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    assert!(fit.converged, "{:?}", fit.warnings);
    fit
}

fn seed_errors(s: &Scenario, seed: u64) -> SeedErrors {
    let mut acq = Acquisition::example();
    acq.simulate.seed = seed;
    let raw = simulate_raw(s, &acq).unwrap();
    let truth = s.rotor.params();
    let dt = s.sampling.dt();
    let (n, tr) = (&raw.noisy, &raw.truth);
    let perfect = refine_on(dt, &n.x, &n.z, &tr.phi, &tr.phi_dot, &tr.phi_ddot, &truth);
    let c1 = condition(&raw.running, &acq, raw.slow_roll.as_ref(), None).unwrap();
    let f1 = refine_on(dt, &c1.x, &c1.z, &c1.phi, &c1.phi_dot, &c1.phi_ddot, &truth);
    let g = ModelGuess {
        rotor: f1.rotor,
        initial: Some(f1.initial),
        source: GuessSource::Identification,
    };
    let c2 = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&g)).unwrap();
    let f2 = refine_on(dt, &c2.x, &c2.z, &c2.phi, &c2.phi_dot, &c2.phi_ddot, &truth);
    SeedErrors {
        perfect: rel_errors(&perfect, &truth),
        conditioned: rel_errors(&f2, &truth),
        first_pass: rel_errors(&f1, &truth),
    }
}

/// RMS over seeds of conditioned / max(perfect, CRB), per parameter; prints the table.
fn study(ramp: bool, seeds: u64) -> [f64; 5] {
    use rotorid::refine::{crb_at_snr, Unknowns};
    let s = scenario(ramp, 1.0);
    let crb = crb_at_snr(&s, 40.0, &Unknowns::default()).unwrap();
    let errs: Vec<SeedErrors> = (1..=seeds).map(|k| seed_errors(&s, k)).collect();
    let rms_of = |f: &dyn Fn(&SeedErrors) -> f64| rms(errs.iter().map(f));
    let mut ratios = [0.0; 5];
    eprintln!(
        "{} ({seeds} seeds): param  perfect  pass1  pass2  CRB  ratio",
        if ramp {
            "ramp 1200 rpm + 10 rad/s^2"
        } else {
            "1200 rpm"
        }
    );
    for (k, name) in NAMES.iter().enumerate() {
        let p = rms_of(&|e| e.perfect[k]);
        let c1 = rms_of(&|e| e.first_pass[k]);
        let c = rms_of(&|e| e.conditioned[k]);
        let b = crb.relative(name).unwrap();
        ratios[k] = c / p.max(b);
        eprintln!(
            "  {name:3} {p:.2e} {c1:.2e} {c:.2e} {b:.2e} {:.2}",
            ratios[k]
        );
    }
    ratios
}

#[test]
fn refine_on_conditioned_raw_data_is_within_twice_the_perfect_channels_quick() {
    for ramp in [false, true] {
        let r = study(ramp, 3);
        for (k, v) in r.iter().enumerate() {
            assert!(*v <= 2.0, "{}: ratio {v}", NAMES[k]);
        }
    }
}

#[test]
#[ignore = "long: cargo test -p rotorid --test it acquisition_study -- --ignored --nocapture"]
fn acquisition_study_over_many_seeds() {
    for ramp in [false, true] {
        let r = study(ramp, 20);
        for (k, v) in r.iter().enumerate() {
            assert!(*v <= 2.0, "{}: ratio {v}", NAMES[k]);
        }
    }
}

fn raw_of(s: &Scenario, acq: &Acquisition) -> RawSimulation {
    simulate_raw(s, acq).unwrap()
}

fn column_mut<'a>(r: &'a mut RawRecord, name: &str) -> &'a mut Vec<f64> {
    &mut r.columns.iter_mut().find(|(n, _)| n == name).unwrap().1
}

#[test]
fn runout_left_in_is_found_and_absent_runout_is_not() {
    let s = scenario(false, 1.0);
    let acq = Acquisition::example();
    let raw = raw_of(&s, &acq);
    // Runout present, no slow-roll record: a finding names the locked components.
    let c = condition(&raw.running, &acq, None, Some(&guess(&s))).unwrap();
    let comps = c
        .report
        .findings
        .iter()
        .find_map(|f| match f {
            AcquisitionFinding::ResidualRunout {
                slow_roll_given: false,
                components,
            } => Some(components.clone()),
            _ => None,
        })
        .expect("residual runout found");
    // The 2X and 3X runout is not the model's: they must be among the components.
    assert!(comps.iter().any(|c| c.harmonic == 2), "{comps:?}");
    assert!(comps.iter().any(|c| c.harmonic == 3), "{comps:?}");
    let msg = c.report.findings[0].message();
    assert!(msg.contains("[acquisition.runout]"), "{msg}");
    // With the slow-roll record, or on data without runout, nothing is found.
    let c = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&guess(&s))).unwrap();
    assert!(c.report.findings.is_empty(), "{:?}", c.report.findings);
    // With the slow-roll record and a rotor guess far from the truth (stiffness halved),
    // what is left is found, and the advice is not to give the slow-roll record it has.
    let mut far = guess(&s);
    far.rotor.kx *= 0.5;
    far.rotor.kz *= 0.5;
    let c = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&far)).unwrap();
    let msg = c
        .report
        .findings
        .iter()
        .find(|f| {
            matches!(
                f,
                AcquisitionFinding::ResidualRunout {
                    slow_roll_given: true,
                    ..
                }
            )
        })
        .map(AcquisitionFinding::message)
        .expect("residual content found with a wrong guess");
    assert!(msg.contains("rotor guess"), "{msg}");
    assert!(!msg.contains("give a slow-roll record"), "{msg}");
    let mut clean = Acquisition::example();
    clean.simulate.runout = [vec![], vec![]];
    let raw = raw_of(&s, &clean);
    let c = condition(&raw.running, &clean, None, Some(&guess(&s))).unwrap();
    assert!(c.report.findings.is_empty(), "{:?}", c.report.findings);
    // The slow-roll runout amplitude is reported (probe 1: 2, 1, 0.5 um at 1X-3X).
    let c = condition(
        &raw_of(&s, &acq).running,
        &acq,
        raw_of(&s, &acq).slow_roll.as_ref(),
        Some(&guess(&s)),
    )
    .unwrap();
    let sr = c.report.slow_roll.unwrap();
    for (h, a) in [(1, 2.0e-6), (2, 1.0e-6), (3, 0.5e-6)] {
        assert!(
            (sr.runout[0].amplitude(h) - a).abs() < 0.01e-6,
            "{h}X {}",
            sr.runout[0].amplitude(h)
        );
    }
}

#[test]
fn missed_and_spurious_keyphasor_pulses_are_repaired() {
    let s = scenario(false, 1.0);
    let acq = Acquisition::example();
    let mut raw = raw_of(&s, &acq);
    let t = raw.truth.t.clone();
    let kp = column_mut(&mut raw.running, "kp");
    // Drop the notch of the pulse near 0.30 s and add a spurious dip at 0.612 s.
    for (i, v) in kp.iter_mut().enumerate() {
        if (0.29..0.31).contains(&t[i]) {
            *v = -8.0;
        }
        if (0.612..0.6125).contains(&t[i]) {
            *v = -14.0;
        }
    }
    let c = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&guess(&s))).unwrap();
    let k = &c.report.keyphasor;
    assert_eq!(k.missed_pulses_before_s.len(), 1, "{k:?}");
    assert_eq!(k.spurious_pulses_s.len(), 1, "{k:?}");
    assert!((k.spurious_pulses_s[0] - 0.612).abs() < 1e-4);
    let e = phi_error(&c.phi, &raw.truth.phi);
    assert!(e < 1e-3, "{e}");
    assert!(matches!(
        c.report.findings[0],
        AcquisitionFinding::KeyphasorRepaired { .. }
    ));
}

#[test]
fn unusable_inputs_are_errors_that_name_what_is_wrong() {
    let s = scenario(false, 0.3);
    let acq = Acquisition::example();
    let raw = raw_of(&s, &acq);
    // A probe column missing.
    let mut r = raw.running.clone();
    r.columns.retain(|(n, _)| n != "probe_R");
    match condition(&r, &acq, None, None) {
        Err(e @ AcquisitionError::MissingColumn { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("\"probe_R\"") && m.contains("probe 2") && m.contains("probe_L"),
                "{m}"
            );
        }
        other => panic!("{other:?}"),
    }
    // Probes 20 deg apart.
    let mut close = acq.clone();
    close.probes[1].angle = 115f64.to_radians();
    match condition(&raw.running, &close, None, None) {
        Err(AcquisitionError::ProbesTooClose { separation_deg, .. }) => {
            assert!((separation_deg - 20.0).abs() < 1e-9)
        }
        other => panic!("{other:?}"),
    }
    // No keyphasor pulse: a flat channel with noise.
    let mut r = raw.running.clone();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
    for v in column_mut(&mut r, "kp").iter_mut() {
        let n: f64 = rand::Rng::sample(&mut rng, rand_distr::StandardNormal);
        *v = -8.0 + 0.005 * n;
    }
    match condition(&r, &acq, None, None) {
        Err(e @ AcquisitionError::NoPulse { .. }) => {
            assert!(e.to_string().contains("\"kp\""), "{e}")
        }
        other => panic!("{other:?}"),
    }
    // Keyphasor faster than the sampling: a notch 0.1 deg wide (under half a sample) ...
    let mut narrow = acq.clone();
    narrow.simulate.kp_width = 0.1f64.to_radians();
    narrow.simulate.kp_edge = 0.0;
    let r = raw_of(&s, &narrow);
    match condition(&r.running, &narrow, None, None) {
        Err(AcquisitionError::KeyphasorTooFast { what, value, .. }) => {
            assert_eq!(what, "samples per pulse");
            assert!(value < 2.0)
        }
        other => panic!("{other:?}"),
    }
    // ... and a pulse every 5 samples.
    let mut r = raw.running.clone();
    for (i, v) in column_mut(&mut r, "kp").iter_mut().enumerate() {
        *v = if i % 5 < 2 { -14.0 } else { -8.0 };
    }
    match condition(&r, &acq, None, None) {
        Err(AcquisitionError::KeyphasorTooFast { what, value, .. }) => {
            assert_eq!(what, "samples per revolution");
            assert!((value - 5.0).abs() < 1e-6, "{value}")
        }
        other => panic!("{other:?}"),
    }
    // A slow-roll record with other columns.
    let mut sr = raw.slow_roll.clone().unwrap();
    sr.columns[1].0 = "probeL".into();
    match condition(&raw.running, &acq, Some(&sr), None) {
        Err(
            e @ AcquisitionError::MissingColumn {
                which: rotorid::acquisition::Which::SlowRoll,
                ..
            },
        ) => {
            let m = e.to_string();
            assert!(
                m.starts_with("the slow-roll record has no column \"probe_L\""),
                "{m}"
            );
        }
        other => panic!("{other:?}"),
    }
    // Non-finite sample, named with its time.
    let mut r = raw.running.clone();
    column_mut(&mut r, "probe_L")[100] = f64::NAN;
    match condition(&r, &acq, None, None) {
        Err(AcquisitionError::NonFinite { index, t, .. }) => {
            assert_eq!(index, 100);
            assert!((t - 100.0 / 25600.0).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn probes_not_at_right_angles_are_noted_with_the_noise_correlation_they_cause() {
    // probes 40 deg apart, no white noise: only each probe's own quantisation (10 bits over
    // 24 V, 3 um steps at 7874 V/m: independent per probe), so the conditioned x, z errors
    // correlate as the inverse projection says; the note states that correlation
    let s = scenario(false, 1.0);
    let mut acq = Acquisition::example();
    acq.probes[0].angle = 20f64.to_radians();
    acq.probes[1].angle = 60f64.to_radians();
    acq.simulate.snr_db = None;
    acq.simulate.bits = Some(10);
    acq.simulate.runout = [Vec::new(), Vec::new()];
    acq.simulate.slow_roll_rpm = 0.0;
    let raw = simulate_raw(&s, &acq).unwrap();
    let c = condition(&raw.running, &acq, None, Some(&guess(&s))).unwrap();
    let r =
        rotorid::acquisition::probes::noise_correlation([acq.probes[0].angle, acq.probes[1].angle])
            .unwrap();
    let ex: Vec<f64> = c.x.iter().zip(&raw.truth.x).map(|(a, b)| a - b).collect();
    let ez: Vec<f64> = c.z.iter().zip(&raw.truth.z).map(|(a, b)| a - b).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mx, mz) = (mean(&ex), mean(&ez));
    let cov = |a: &[f64], ma: f64, b: &[f64], mb: f64| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - ma) * (y - mb))
            .sum::<f64>()
            / a.len() as f64
    };
    let measured = cov(&ex, mx, &ez, mz) / (cov(&ex, mx, &ex, mx) * cov(&ez, mz, &ez, mz)).sqrt();
    println!("x, z error correlation {measured:.4} (inverse projection: {r:.4})");
    // 25600 samples: the sampling error of a correlation is ~(1 - r^2) / sqrt(n) ~ 0.004
    assert!((measured - r).abs() < 0.03, "{measured} vs {r}");
    assert!(r.abs() > 0.5, "{r}");
    let note = c
        .report
        .notes
        .iter()
        .find(|n| n.contains("correlated noise"))
        .unwrap_or_else(|| panic!("{:?}", c.report.notes));
    assert!(
        note.contains("40 deg apart") && note.contains(&format!("{r:+.2}")),
        "{note}"
    );
    // at right angles, no such note
    let acq = Acquisition::example();
    let raw = simulate_raw(&s, &acq).unwrap();
    let c = condition(&raw.running, &acq, None, Some(&guess(&s))).unwrap();
    assert!(
        !c.report.notes.iter().any(|n| n.contains("correlated")),
        "{:?}",
        c.report.notes
    );
}
