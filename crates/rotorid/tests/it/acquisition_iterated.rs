//! The iterated conditioning (`acquisition::condition_iterated`) on raw records from the
//! independent generator of `raw_reference` (6-decimal stamps, 16 bits, runout 1X-3X, a
//! slow-roll record holding the rotor's own response), at 1200 rpm and on the 600 rpm +
//! 10 rad/s^2 run-up, 25.6 kHz, 40 dB: refine's RMS error of m, cx, kx, cz, kz within twice
//! the larger of its error on perfectly conditioned channels (the same noise on the true
//! x, z, the true phi) and the Cramer-Rao bound, with and without the scenario's rotor as
//! the first guess; and `condition` with the scenario's rotor gives x, z within 1.05 times
//! the noise the probes carry (white noise and 16-bit quantisation: on the run-up, whose
//! vibration is a quarter of that at 1200 rpm, the quantisation is 0.69 of the white
//! noise, so the conditioned x, z are 1.21 times the white noise off, which is all
//! quantisation). `cargo test --release -p rotorid --test it acquisition_iterated_study --
//! --ignored --nocapture` prints the tables of docs/acquisition.md section 9.

use rotorid::acquisition::{
    condition, condition_iterated, Acquisition, GuessSource, ModelGuess, RawRecord,
};
use rotorid::model::{Rotor, RotorParams, Sampling, Scenario, SpeedProfile};
use rotorid::pipeline::{identify, Identification, Knowledge, Method, Record, Speed};
use rotorid::refine::{crb_at_snr, Unknowns};
use rotorid::Parameter;

use super::raw_reference as gen;

const NAMES: [Parameter; 5] = [
    Parameter::M,
    Parameter::Cx,
    Parameter::Kx,
    Parameter::Cz,
    Parameter::Kz,
];

fn rotor() -> RotorParams {
    let mut p = Rotor::table1().params();
    p.unbalance.m_u = gen::M_U;
    p
}

fn raw(r: &gen::Raw) -> RawRecord {
    let [l, rr, kp] = r.volts.clone();
    RawRecord {
        columns: vec![
            ("t".into(), r.t.clone()),
            ("probe_L".into(), l),
            ("probe_R".into(), rr),
            ("kp".into(), kp),
        ],
    }
}

fn scenario_guess() -> ModelGuess {
    ModelGuess {
        rotor: rotor(),
        initial: None,
        source: GuessSource::Scenario,
    }
}

/// The library scenario of the same experiment (for the Cramer-Rao bound and the truth).
fn scenario(ramp: bool) -> Scenario {
    Scenario {
        rotor: Rotor::new(rotor()).unwrap(),
        speed: if ramp {
            SpeedProfile::ramp(600.0, 10.0, 0.0).unwrap()
        } else {
            SpeedProfile::constant_rpm(1200.0, 0.0).unwrap()
        },
        sampling: Sampling::new(1.0 / gen::RATE_HZ, (gen::SAMPLES - 1) as f64 / gen::RATE_HZ)
            .unwrap(),
        initial: Default::default(),
    }
}

fn turning(ramp: bool) -> gen::Turning {
    if ramp {
        gen::Turning::ramp(600.0, 10.0)
    } else {
        gen::Turning::rpm(1200.0)
    }
}

/// RMS of the 16-bit quantisation in x and z [m]: one step, 24 V / 2^16 at 7874 V/m,
/// over sqrt(12), and the probes' inverse projection at +-45 deg is a rotation.
const QUANTISATION: f64 = 24.0 / 65536.0 / 7874.0 / 3.464_101_615_137_754_6;

/// x, z error of a conditioned record over the noise the probes carry: the white noise
/// and the quantisation, (x, z); and over the white noise alone.
fn xz_error(x: &[f64], z: &[f64], r: &gen::Raw) -> ([f64; 2], [f64; 2]) {
    let e =
        |a: &[f64], b: &[f64]| gen::rms(&a.iter().zip(b).map(|(p, q)| p - q).collect::<Vec<_>>());
    let (ex, ez) = (e(x, &r.x), e(z, &r.z));
    (
        [
            ex / r.sigma[0].hypot(QUANTISATION),
            ez / r.sigma[1].hypot(QUANTISATION),
        ],
        [ex / r.sigma[0], ez / r.sigma[1]],
    )
}

/// Relative errors of m, cx, kx, cz, kz (refine's estimates).
fn errors(id: &Identification) -> [f64; 5] {
    let t = rotor();
    let truth = [t.m, t.cx, t.kx, t.cz, t.kz];
    std::array::from_fn(|k| {
        let p = id.parameter(NAMES[k]).expect("refined");
        p.estimate.unwrap() / truth[k] - 1.0
    })
}

/// One seed's relative errors of refine.
struct Run {
    /// On perfectly conditioned channels.
    perfect: [f64; 5],
    /// Conditioned iteratively.
    iterated: [f64; 5],
    /// Conditioned in two passes (the first guess, then the first estimate), as before
    /// (the study only: NaN otherwise).
    two_passes: [f64; 5],
    /// Passes the iteration took.
    passes: usize,
}

/// Refine's errors for one seed (`Run`) of the run-up (`ramp`) or 1200 rpm, the iteration
/// starting from `first`; `two`: also in two passes.
fn seed(ramp: bool, seed: u64, first: Option<&ModelGuess>, two: bool) -> Run {
    let r = gen::running(&turning(ramp), seed);
    let slow = gen::slow_roll(r.sigma, seed);
    let k = Knowledge::from_scenario(&scenario(ramp));
    let perfect = Record::new(
        (0..gen::SAMPLES).map(|i| i as f64 / gen::RATE_HZ).collect(),
        r.x_noisy.clone(),
        r.z_noisy.clone(),
        Speed::Samples {
            phi: r.phi.clone(),
            omega: r.w.clone(),
            omega_dot: r.w_dot.clone(),
        },
        0.0,
    )
    .unwrap();
    let p = identify(&perfect, &k, &Method::refine()).unwrap();
    let it = condition_iterated(
        &raw(&r),
        &Acquisition::example(),
        Some(&raw(&slow)),
        first,
        &k,
        &Method::refine(),
        1e-6,
    )
    .unwrap();
    let passes = it.conditioned.report.passes.as_ref().unwrap();
    assert!(passes.settled, "{passes:?}");
    let acq = Acquisition::example();
    let (rr, sr) = (raw(&r), raw(&slow));
    let refine_of = |c: &rotorid::acquisition::Conditioned| {
        let rec = Record::from_response(&c.response());
        identify(&rec.unwrap(), &k, &Method::refine()).unwrap()
    };
    let two_passes = if two {
        let c1 = condition(&rr, &acq, Some(&sr), first).unwrap();
        let g = ModelGuess::from_identification(&refine_of(&c1), &k).unwrap();
        let c2 = condition(&rr, &acq, Some(&sr), Some(&g)).unwrap();
        errors(&refine_of(&c2))
    } else {
        [f64::NAN; 5]
    };
    Run {
        perfect: errors(&p),
        iterated: errors(&it.identification),
        two_passes,
        passes: passes.passes,
    }
}

/// RMS over `seeds` of the errors on perfect channels and conditioned, the bound, and the
/// ratios conditioned / max(perfect, CRB); prints the table.
fn study(ramp: bool, seeds: u64, first: Option<&ModelGuess>, two: bool) -> [f64; 5] {
    let crb = crb_at_snr(&scenario(ramp), 40.0, &Unknowns::default()).unwrap();
    let runs: Vec<_> = (1..=seeds).map(|s| seed(ramp, s, first, two)).collect();
    let rms = |f: &dyn Fn(&Run) -> f64| {
        (runs.iter().map(|r| f(r).powi(2)).sum::<f64>() / runs.len() as f64).sqrt()
    };
    eprintln!(
        "{} ({seeds} seeds, first guess {}): passes {:?}\n  param  perfect  two-passes  iterated  CRB  ratio (two passes)",
        if ramp {
            "run-up 600 rpm + 10 rad/s^2"
        } else {
            "1200 rpm"
        },
        if first.is_some() {
            "the scenario's rotor"
        } else {
            "none"
        },
        runs.iter().map(|r| r.passes).collect::<Vec<_>>()
    );
    std::array::from_fn(|k| {
        let (p, c) = (rms(&|r| r.perfect[k]), rms(&|r| r.iterated[k]));
        let two = rms(&|r| r.two_passes[k]);
        let b = crb.relative(NAMES[k].name()).unwrap();
        let ratio = c / p.max(b);
        eprintln!(
            "  {:3} {p:.2e} {two:.2e} {c:.2e} {b:.2e} {ratio:.2} ({:.2})",
            NAMES[k].name(),
            two / p.max(b)
        );
        ratio
    })
}

#[test]
fn condition_with_the_scenarios_rotor_gives_x_z_within_the_noise() {
    for ramp in [false, true] {
        for s in [1, 2] {
            let r = gen::running(&turning(ramp), s);
            let slow = gen::slow_roll(r.sigma, s);
            let acq = Acquisition::example();
            let c = condition(&raw(&r), &acq, Some(&raw(&slow)), Some(&scenario_guess())).unwrap();
            let (e, white) = xz_error(&c.x, &c.z, &r);
            let none = condition(&raw(&r), &acq, Some(&raw(&slow)), None).unwrap();
            let (e0, _) = xz_error(&none.x, &none.z, &r);
            eprintln!(
                "ramp {ramp} seed {s}: x, z error / (white noise + quantisation) {e:.3?}, / white \
                 noise {white:.3?}; without a guess {e0:.3?}"
            );
            assert!(e[0] <= 1.05 && e[1] <= 1.05, "{e:?}");
            // without the rotor the slow roll's own response stays in the runout
            assert!(e0[0] > 1.1 && e0[1] > 1.1, "{e0:?}");
            assert!(
                c.report
                    .notes
                    .iter()
                    .any(|n| n.contains("the scenario's [rotor]")),
                "{:?}",
                c.report.notes
            );
        }
    }
}

/// The iterated conditioning of the run-up (seed `seed`) from `first`, identified by
/// refine.
fn iterated(seed: u64, first: Option<&ModelGuess>) -> (Identification, usize) {
    let r = gen::running(&turning(true), seed);
    let slow = gen::slow_roll(r.sigma, seed);
    let it = condition_iterated(
        &raw(&r),
        &Acquisition::example(),
        Some(&raw(&slow)),
        first,
        &Knowledge::from_scenario(&scenario(true)),
        &Method::refine(),
        1e-6,
    )
    .unwrap();
    let passes = it.conditioned.report.passes.clone().unwrap();
    assert!(passes.settled, "{passes:?}");
    (it.identification, passes.passes)
}

#[test]
fn the_iteration_reaches_what_the_true_rotor_gives_where_two_passes_did_not() {
    // The run-up without a first guess: the iteration ends where conditioning with the
    // true rotor ends, to a fraction of a standard error; two passes (as before) stop
    // several standard errors short (measured: m, kx, kz biased by about
    // five standard errors, the same sign on every seed). The study below measures the
    // errors against perfect channels and the bound.
    let (from_nothing, passes) = iterated(1, None);
    let (from_truth, _) = iterated(1, Some(&scenario_guess()));
    let r = gen::running(&turning(true), 1);
    let slow = gen::slow_roll(r.sigma, 1);
    let (rr, sr) = (raw(&r), raw(&slow));
    let acq = Acquisition::example();
    let k = Knowledge::from_scenario(&scenario(true));
    let refine_of = |c: &rotorid::acquisition::Conditioned| {
        identify(
            &Record::from_response(&c.response()).unwrap(),
            &k,
            &Method::refine(),
        )
        .unwrap()
    };
    let c1 = condition(&rr, &acq, Some(&sr), None).unwrap();
    let g = ModelGuess::from_identification(&refine_of(&c1), &k).unwrap();
    let two = refine_of(&condition(&rr, &acq, Some(&sr), Some(&g)).unwrap());
    let mut worst_two = 0.0f64;
    for p in NAMES {
        let (a, b) = (
            from_nothing.parameter(p).unwrap(),
            from_truth.parameter(p).unwrap(),
        );
        let se = b.std_error.unwrap();
        let d = (a.estimate.unwrap() - b.estimate.unwrap()).abs() / se;
        let d2 = (two.parameter(p).unwrap().estimate.unwrap() - b.estimate.unwrap()).abs() / se;
        eprintln!(
            "{}: iterated ({passes} passes) {d:.3} se from the true rotor's, two passes {d2:.2} se",
            p.name()
        );
        assert!(d <= 0.3, "{}: {d} standard errors", p.name());
        worst_two = worst_two.max(d2);
    }
    assert!(worst_two > 2.0, "two passes were enough here: {worst_two}");
}

#[test]
#[ignore = "long: cargo test --release -p rotorid --test it acquisition_iterated_study -- --ignored --nocapture"]
fn acquisition_iterated_study_over_many_seeds() {
    for ramp in [false, true] {
        for first in [None, Some(scenario_guess())] {
            let r = study(ramp, 10, first.as_ref(), true);
            assert!(r.iter().all(|v| *v <= 2.0), "{r:?}");
        }
    }
}

/// The generator's two halves agree: RK4 started on the closed-form steady state stays on
/// it (to 1e-9 of its amplitude over 0.2 s), and from rest it matches the library's exact
/// simulation (matrix exponential; DoPri8 on the ramp) to 1e-7 of the peak.
#[test]
fn the_generator_agrees_with_closed_forms_and_the_library() {
    let turn = gen::Turning::rpm(1200.0);
    let [xh, zh] = gen::steady(turn.w0);
    let re = |c: (f64, f64), p: f64| c.0 * p.cos() - c.1 * p.sin();
    let dre = |c: (f64, f64), p: f64| -turn.w0 * (c.0 * p.sin() + c.1 * p.cos());
    let y0 = [re(xh, 0.0), re(zh, 0.0), dre(xh, 0.0), dre(zh, 0.0)];
    let n = 5120;
    let (x, z) = gen::integrate(&turn, n, y0);
    let amp = xh.0.hypot(xh.1);
    for i in 0..n {
        let p = turn.phi(i as f64 / gen::RATE_HZ);
        assert!((x[i] - re(xh, p)).abs() < 1e-9 * amp, "x at {i}");
        assert!((z[i] - re(zh, p)).abs() < 1e-9 * amp, "z at {i}");
    }
    for (turn, speed) in [
        (
            gen::Turning::rpm(1200.0),
            rotorid::SpeedProfile::constant_rpm(1200.0, 0.0).unwrap(),
        ),
        (
            gen::Turning::ramp(600.0, 10.0),
            rotorid::SpeedProfile::ramp(600.0, 10.0, 0.0).unwrap(),
        ),
    ] {
        let mut p = rotorid::model::Rotor::table1().params();
        p.unbalance.m_u = gen::M_U;
        let sc = rotorid::Scenario {
            rotor: rotorid::model::Rotor::new(p).unwrap(),
            speed,
            sampling: rotorid::model::Sampling::new(1.0 / gen::RATE_HZ, 0.25).unwrap(),
            initial: Default::default(),
        };
        let lib = rotorid::simulate::simulate(&sc, rotorid::simulate::Method::Exact).unwrap();
        let (x, z) = gen::integrate(&turn, lib.x.len(), [0.0; 4]);
        let peak = lib.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..x.len() {
            assert!(
                (x[i] - lib.x[i]).abs() < 1e-7 * peak,
                "x at {i}: {} {}",
                x[i],
                lib.x[i]
            );
            assert!((z[i] - lib.z[i]).abs() < 1e-7 * peak, "z at {i}");
        }
    }
    // the record itself: 16-bit volts, 6-decimal stamps, noise at the stated level
    let r = gen::running(&gen::Turning::rpm(1200.0), 1);
    let q = 24.0 / 65536.0;
    for v in r.volts.iter().flatten() {
        assert!(
            ((v + 24.0) / q - ((v + 24.0) / q).round()).abs() < 1e-6,
            "{v}"
        );
    }
    for (i, t) in r.t.iter().enumerate() {
        assert!(
            (t - i as f64 / gen::RATE_HZ).abs() <= 0.5e-6 + 1e-12,
            "{i}: {t}"
        );
    }
    let e: Vec<f64> = r.x_noisy.iter().zip(&r.x).map(|(a, b)| a - b).collect();
    assert!((gen::rms(&e) / r.sigma[0] - 1.0).abs() < 0.02);
}
