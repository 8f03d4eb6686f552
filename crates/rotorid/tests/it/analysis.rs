//! The analysis against independent references: the analytic modes at rest, the
//! closed-form characteristic polynomial at speed (gyroscopic splitting), the steady-state
//! oracle for the unbalance response, a Monte Carlo over the covariance for the
//! linearised standard deviations, and simulated balancing (simulate, identify, balance,
//! re-simulate with the correction added).

use std::f64::consts::{PI, TAU};

use nalgebra::{Cholesky, Complex, DMatrix, DVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rotorid::analysis::{
    balance_from_runs, balance_from_unbalance, campbell, critical_speeds, modes, one_x,
    response_per_unbalance, stability, unbalance_response, AnalysisError, CovarianceParameter,
    ParameterCovariance, Probe, RunVectors, TrialMass, Whirl,
};
use rotorid::model::{rpm_to_rad_per_s, InitialState, Rotor, RotorParams, Scenario, Unbalance};
use rotorid::refine::{refine, Record, RefineOptions, Unknowns};
use rotorid::simulate::{add_noise, simulate, steady_state, Method, TimeResponse};

/// Speeds 0 to `max_rpm` every `step_rpm` \[rad/s\].
fn grid(max_rpm: f64, step_rpm: f64) -> Vec<f64> {
    let n = (max_rpm / step_rpm).round() as usize;
    (0..=n)
        .map(|k| rpm_to_rad_per_s(k as f64 * step_rpm))
        .collect()
}

/// Table 1 with stiffer, more damped vertical supports.
fn anisotropic() -> RotorParams {
    RotorParams {
        kz: 1.6e6,
        cx: 40.0,
        cz: 120.0,
        ..Rotor::table1().params()
    }
}

fn with_unbalance(p: &RotorParams, u: Complex<f64>) -> RotorParams {
    RotorParams {
        unbalance: Unbalance {
            m_u: u.norm() / p.unbalance.d,
            d: p.unbalance.d,
            alpha: u.arg(),
        },
        ..*p
    }
}

fn unbalance_of(p: &RotorParams) -> Complex<f64> {
    Complex::from_polar(p.unbalance.mud(), p.unbalance.alpha)
}

#[test]
fn modes_at_rest_are_the_two_single_degree_of_freedom_oscillators() {
    // At W = 0 the directions decouple: m q'' + c q' + k q = 0 each, natural frequency
    // sqrt(k/m), damping ratio c / (2 sqrt(k m)), straight-line orbits.
    let p = anisotropic();
    let [lo, hi] = modes(&p, 0.0).unwrap();
    for (mode, c, k) in [(lo, p.cx, p.kx), (hi, p.cz, p.kz)] {
        let wn = (k / p.m).sqrt();
        let zeta = c / (2.0 * (k * p.m).sqrt());
        assert!((mode.natural_frequency - wn).abs() < 1e-12 * wn, "{mode:?}");
        assert!((mode.frequency - wn * (1.0 - zeta * zeta).sqrt()).abs() < 1e-12 * wn);
        assert!((mode.damping_ratio - zeta).abs() < 1e-9 * zeta, "{mode:?}");
        let delta = TAU * zeta / (1.0 - zeta * zeta).sqrt();
        assert!((mode.log_dec.unwrap() - delta).abs() < 1e-9 * delta);
        assert!(mode.whirl_ratio.unwrap().abs() < 1e-9, "{mode:?}");
        assert_eq!(mode.whirl, None);
    }
    // table1 (isotropic): 289.2 rad/s (docs/method.md section 1), zeta = 0.0012
    let [a, b] = modes(&Rotor::table1().params(), 0.0).unwrap();
    for m in [a, b] {
        assert!((m.natural_frequency - 289.18).abs() < 0.01);
        assert!((m.damping_ratio - 10.0 / (2.0 * (1.195e6f64 * 14.29).sqrt())).abs() < 1e-12);
    }
}

#[test]
fn gyroscopic_splitting_follows_the_characteristic_polynomial() {
    // Isotropic, undamped: m w^2 -/+ a W w - k = 0 for forward/backward circles.
    let p = RotorParams {
        cx: 0.0,
        cz: 0.0,
        ..Rotor::table1().params()
    };
    for rpm in [500.0, 3000.0, 12000.0] {
        let w = rpm_to_rad_per_s(rpm);
        let (aw, disc) = (p.a * w, (p.a * w).powi(2) + 4.0 * p.m * p.kx);
        let forward = (aw + disc.sqrt()) / (2.0 * p.m);
        let backward = (-aw + disc.sqrt()) / (2.0 * p.m);
        let [lo, hi] = modes(&p, w).unwrap();
        assert!((lo.frequency - backward).abs() < 1e-12 * backward, "{rpm}");
        assert!((hi.frequency - forward).abs() < 1e-12 * forward, "{rpm}");
        assert_eq!(
            (lo.whirl, hi.whirl),
            (Some(Whirl::Backward), Some(Whirl::Forward))
        );
        assert!((lo.whirl_ratio.unwrap() + 1.0).abs() < 1e-9);
        assert!((hi.whirl_ratio.unwrap() - 1.0).abs() < 1e-9);
        assert!(lo.damping_ratio.abs() < 1e-12 && hi.damping_ratio.abs() < 1e-12);
    }
    // Damped, anisotropic: the roots are those of
    // det Q = (m l^2 + cx l + kx)(m l^2 + cz l + kz) + a^2 W^2 l^2; check Vieta's formulas
    // for the monic quartic on {l1, conj l1, l2, conj l2}.
    let p = anisotropic();
    for rpm in [0.0, 1500.0, 4000.0, 20000.0] {
        let w = rpm_to_rad_per_s(rpm);
        let [a, b] = modes(&p, w).unwrap();
        let r = [
            a.eigenvalue,
            a.eigenvalue.conj(),
            b.eigenvalue,
            b.eigenvalue.conj(),
        ];
        let m2 = p.m * p.m;
        let e1: Complex<f64> = r.iter().sum();
        let e4: Complex<f64> = r.iter().product();
        let mut e2 = Complex::new(0.0, 0.0);
        let mut e3 = Complex::new(0.0, 0.0);
        for i in 0..4 {
            for j in i + 1..4 {
                e2 += r[i] * r[j];
                for k in j + 1..4 {
                    e3 += r[i] * r[j] * r[k];
                }
            }
        }
        let want = [
            -(p.cx + p.cz) / p.m,
            (p.m * (p.kx + p.kz) + p.cx * p.cz + (p.a * w).powi(2)) / m2,
            -(p.cx * p.kz + p.cz * p.kx) / m2,
            p.kx * p.kz / m2,
        ];
        // the size of each coefficient's terms, for a relative comparison
        let wn2 = p.kz / p.m;
        let size = [wn2.sqrt(), wn2, wn2.powf(1.5), wn2 * wn2];
        for (k, (got, want)) in [e1, e2, e3, e4].iter().zip(want).enumerate() {
            assert!(
                (got - want).norm() < 1e-12 * size[k],
                "{rpm} rpm, e{}: {got} vs {want}",
                k + 1
            );
        }
        if rpm > 0.0 {
            // the lower mode whirls backward, the higher forward, once the speed has
            // turned the straight-line modes at rest into ellipses
            assert_eq!(
                (a.whirl, b.whirl),
                (Some(Whirl::Backward), Some(Whirl::Forward)),
                "{rpm}"
            );
        }
    }
}

#[test]
fn table1_has_two_critical_speeds_below_3500_rpm() {
    // Zero damping: 1X meets m w^2 -/+ a w^2 - k = 0 at W^2 = k / (m + a) (backward) and
    // k / (m - a) (forward): 2519.9 and 3089.2 rpm. Damping of 1e-3 moves them by ~1e-6.
    let p = Rotor::table1().params();
    let undamped = RotorParams {
        cx: 0.0,
        cz: 0.0,
        ..p
    };
    let want = [(p.kx / (p.m + p.a)).sqrt(), (p.kx / (p.m - p.a)).sqrt()];
    let speeds = grid(6000.0, 10.0);
    let cs = critical_speeds(&undamped, None, &speeds).unwrap();
    assert_eq!(cs.len(), 2);
    for (c, w) in cs.iter().zip(want) {
        assert!((c.speed - w).abs() < 1e-11 * w, "{} vs {w}", c.speed);
    }
    let cs = critical_speeds(&p, None, &speeds).unwrap();
    assert_eq!(cs.len(), 2);
    for (c, w) in cs.iter().zip(want) {
        assert!((c.speed - w).abs() < 1e-5 * w, "{} vs {w}", c.speed);
        assert!(c.rpm() < 3500.0);
        assert!((c.at.frequency - c.speed).abs() < 1e-9 * c.speed);
        assert_eq!(c.std, None);
    }
    assert_eq!(
        (cs[0].whirl(), cs[0].mode, cs[1].whirl(), cs[1].mode),
        (Some(Whirl::Backward), 0, Some(Whirl::Forward), 1)
    );
    assert!((cs[0].rpm() - 2519.9).abs() < 0.1 && (cs[1].rpm() - 3089.2).abs() < 0.1);
    // the Campbell diagram's modes carry the same labels
    let c = campbell(&p, &speeds).unwrap();
    assert_eq!(
        (c.whirl(0), c.whirl(1)),
        (Some(Whirl::Backward), Some(Whirl::Forward))
    );
    // a is larger than m: the forward frequency outruns 1X and never meets it
    let big_a = RotorParams { a: 20.0, ..p };
    let cs = critical_speeds(&big_a, None, &grid(60000.0, 100.0)).unwrap();
    assert_eq!(cs.len(), 1);
    assert_eq!(cs[0].whirl(), Some(Whirl::Backward));
}

#[test]
fn stability_minimum_log_dec_and_threshold() {
    let p = Rotor::table1().params();
    let speeds = grid(6000.0, 10.0);
    let s = stability(&p, &speeds).unwrap();
    assert!(s.is_stable());
    let c = campbell(&p, &speeds).unwrap();
    let min = c
        .modes
        .iter()
        .flatten()
        .filter_map(|m| m.log_dec)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(s.min_log_dec, Some(min));
    // ~ 2 pi zeta = 7.6e-3 for zeta = 1.2e-3, everywhere
    assert!(min > 0.006 && min < 0.009, "{min}");
    // an identified damping below zero: the rotor is unstable from the start of the range
    let bad = RotorParams { cx: -2.0, ..p };
    let s = stability(&bad, &speeds).unwrap();
    assert_eq!(s.threshold, Some(0.0));
    assert!(s.min_log_dec.unwrap() < 0.0);
    // ... but at speed the gyroscopic coupling shares cz with the x motion: from 1000 rpm
    // on, both modes are damped by about (cx + cz) / 2 > 0
    let from_1000: Vec<f64> = speeds[100..].to_vec();
    assert!(stability(&bad, &from_1000).unwrap().is_stable());
}

#[test]
fn unbalance_response_is_the_steady_state_oracle() {
    let p = anisotropic();
    let rotor = Rotor::new(p).unwrap();
    let speeds = grid(6000.0, 250.0);
    let probe45 = Probe { angle: PI / 4.0 };
    let r = unbalance_response(&p, None, &speeds, &[Probe::X, Probe::Z, probe45]).unwrap();
    for (k, &w) in speeds.iter().enumerate() {
        let ss = steady_state(&rotor, w);
        let phi0 = 0.3;
        for t in [0.0, 0.0123, 0.1] {
            // the oracle's displacement against Re(V e^{i phi}), phi = W t + phi0
            let q = ss.displacement(t, phi0);
            let e = Complex::from_polar(1.0, w * t + phi0);
            for ch in &r.channels {
                let n = (ch.probe.angle.sin(), ch.probe.angle.cos());
                let want = n.0 * q[0] + n.1 * q[1];
                let got = ch.points[k].unwrap().vector * e;
                let scale = ss.amplitude().norm().max(1e-300);
                assert!(
                    (got.re - want).abs() < 1e-12 * scale,
                    "{w} rad/s probe {}: {} vs {want}",
                    ch.probe.angle,
                    got.re
                );
            }
        }
        if w > 0.0 {
            // amplitude and lag of x: |Q_x| and -(arg Q_x + alpha)
            let x = r.channels[0].points[k].unwrap();
            assert!((x.amplitude - ss.amplitude()[0]).abs() < 1e-12 * x.amplitude);
            let lag = (-(ss.phase()[0] + p.unbalance.alpha)).rem_euclid(TAU);
            let d = (x.phase_lag.unwrap() - lag).abs();
            assert!(d.min(TAU - d) < 1e-10, "{w}: {:?} vs {lag}", x.phase_lag);
        }
    }
    // well below the first critical speed the response follows the force: lag = theta - alpha
    let slow = unbalance_response(&p, None, &[10.0], &[Probe::Z, Probe::X]).unwrap();
    for ch in &slow.channels {
        let want = (ch.probe.angle - p.unbalance.alpha).rem_euclid(TAU);
        let got = ch.points[0].unwrap().phase_lag.unwrap();
        assert!((got - want).abs() < 1e-3, "{got} vs {want}");
    }
}

/// A covariance like a fit's: relative standard deviations `rel`, correlations `corr`.
fn covariance(p: &RotorParams, rel: [f64; 8], corr: &[(usize, usize, f64)]) -> DMatrix<f64> {
    let u = unbalance_of(p);
    let v = [p.m, p.cx, p.kx, p.cz, p.kz, p.a, u.re, u.im];
    let s: Vec<f64> = (0..8).map(|i| rel[i] * v[i].abs()).collect();
    let mut c = DMatrix::from_fn(8, 8, |i, j| if i == j { s[i] * s[i] } else { 0.0 });
    for &(i, j, r) in corr {
        c[(i, j)] = r * s[i] * s[j];
        c[(j, i)] = r * s[i] * s[j];
    }
    c
}

fn parameter_covariance(c: &DMatrix<f64>) -> ParameterCovariance {
    ParameterCovariance::new(
        CovarianceParameter::ALL
            .iter()
            .map(|p| p.name().to_string())
            .collect(),
        (0..8)
            .map(|i| (0..8).map(|j| c[(i, j)]).collect())
            .collect(),
    )
    .unwrap()
}

/// `p` moved by `d` = (dm, dcx, dkx, dcz, dkz, da, du_c, du_s).
fn moved(p: &RotorParams, d: &DVector<f64>) -> RotorParams {
    let u = unbalance_of(p) + Complex::new(d[6], d[7]);
    with_unbalance(
        &RotorParams {
            m: p.m + d[0],
            cx: p.cx + d[1],
            kx: p.kx + d[2],
            cz: p.cz + d[3],
            kz: p.kz + d[4],
            a: p.a + d[5],
            ..*p
        },
        u,
    )
}

/// `m` with parameter `i` undetermined, as the refinement writes it: an infinite variance
/// and NaN in the rest of its row and column.
fn undetermined(m: &[Vec<f64>], i: usize) -> Vec<Vec<f64>> {
    let mut m = m.to_vec();
    for row in m.iter_mut() {
        row[i] = f64::NAN;
    }
    m[i].fill(f64::NAN);
    m[i][i] = f64::INFINITY;
    m
}

fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

#[test]
fn linearised_standard_deviations_agree_with_monte_carlo() {
    // Parameters spread as a poor identification would leave them (1-3 % on m, k, a; 20 %
    // on c; 2 % on the unbalance), m and k strongly correlated as fits give them.
    let p = anisotropic();
    let cov = covariance(
        &p,
        [0.02, 0.2, 0.02, 0.2, 0.02, 0.03, 0.02, 0.02],
        &[
            (0, 2, 0.9),
            (0, 4, 0.8),
            (2, 4, 0.7),
            (1, 3, -0.3),
            (6, 7, 0.4),
        ],
    );
    let pc = parameter_covariance(&cov);
    // a grid around the two critical speeds (2520-3500 rpm) keeps the 4000 draws quick
    let speeds: Vec<f64> = (15..=40)
        .map(|k| rpm_to_rad_per_s(100.0 * k as f64))
        .collect();
    let cs = critical_speeds(&p, Some(&pc), &speeds).unwrap();
    assert_eq!(cs.len(), 2);
    let probe_speed = rpm_to_rad_per_s(1800.0);
    let lin = unbalance_response(&p, Some(&pc), &[probe_speed], &[Probe::X]).unwrap();
    let lin = lin.channels[0].points[0].unwrap();

    let l = Cholesky::new(cov).unwrap().l();
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let n = 4000;
    let (mut w0, mut w1, mut amp, mut lag) = (vec![], vec![], vec![], vec![]);
    for _ in 0..n {
        let z = DVector::from_fn(8, |_, _| StandardNormal.sample(&mut rng));
        let q = moved(&p, &(&l * z));
        let c = critical_speeds(&q, None, &speeds).unwrap();
        assert_eq!(c.len(), 2);
        w0.push(c[0].speed);
        w1.push(c[1].speed);
        let r = unbalance_response(&q, None, &[probe_speed], &[Probe::X]).unwrap();
        let v = r.channels[0].points[0].unwrap();
        amp.push(v.amplitude);
        lag.push(v.phase_lag.unwrap());
    }
    // the sample standard deviation of 4000 draws is within ~1.1 % (1 sigma) of the truth
    for (label, mc, linear) in [
        ("backward critical speed", std_dev(&w0), cs[0].std.unwrap()),
        ("forward critical speed", std_dev(&w1), cs[1].std.unwrap()),
        (
            "amplitude at 1800 rpm",
            std_dev(&amp),
            lin.std_amplitude.unwrap(),
        ),
        (
            "phase lag at 1800 rpm",
            std_dev(&lag),
            lin.std_phase_lag.unwrap(),
        ),
    ] {
        println!("{label}: Monte Carlo {mc:.4e}, linearised {linear:.4e}");
        assert!(
            (mc / linear - 1.0).abs() < 0.05,
            "{label}: {mc} vs {linear}"
        );
    }

    // an undetermined parameter the critical speeds do not depend on leaves their std
    // alone; one they depend on removes it
    let names = pc.names().to_vec();
    let u_bad = ParameterCovariance::new(names.clone(), undetermined(pc.matrix(), 6)).unwrap();
    let c = critical_speeds(&p, Some(&u_bad), &speeds).unwrap();
    assert_eq!(c[0].std, cs[0].std);
    let r = unbalance_response(&p, Some(&u_bad), &[probe_speed], &[Probe::X]).unwrap();
    assert_eq!(r.channels[0].points[0].unwrap().std_amplitude, None);
    let m_bad = ParameterCovariance::new(names, undetermined(pc.matrix(), 0)).unwrap();
    assert_eq!(m_bad.std(CovarianceParameter::M), None);
    let c = critical_speeds(&p, Some(&m_bad), &speeds).unwrap();
    assert_eq!((c[0].std, c[1].std), (None, None));
}

/// Table 1 at 1200 rpm for `duration` s from rest (the paper's experiment).
fn table1(duration: f64) -> Scenario {
    let s = Scenario::table1();
    Scenario {
        sampling: rotorid::Sampling::new(s.sampling.dt(), duration).unwrap(),
        ..s
    }
}

/// The 1X amplitudes of x and z of a simulated record.
fn amplitudes(r: &TimeResponse) -> [f64; 2] {
    [&r.x, &r.z].map(|s| one_x(s, &r.phi).unwrap().unwrap().amplitude)
}

/// Simulate the scenario with the rotor's unbalance replaced by `u`.
fn simulate_with(s: &Scenario, u: Complex<f64>) -> TimeResponse {
    let p = with_unbalance(&s.rotor.params(), u);
    let s = Scenario {
        rotor: Rotor::new(p).unwrap(),
        ..*s
    };
    simulate(&s, Method::Exact).unwrap()
}

/// Identify m, cx, kx, cz, kz and the unbalance from the record, starting 1-2 % off.
fn identify(s: &Scenario, resp: &TimeResponse) -> rotorid::refine::Refined {
    let t = s.rotor.params();
    let start = RotorParams {
        m: t.m * 1.01,
        cx: t.cx * 0.98,
        kx: t.kx * 0.99,
        cz: t.cz * 1.02,
        kz: t.kz * 1.01,
        unbalance: Unbalance {
            m_u: t.unbalance.m_u * 1.3,
            alpha: t.unbalance.alpha + 0.4,
            ..t.unbalance
        },
        ..t
    };
    let opts = RefineOptions {
        unknowns: Unknowns {
            unbalance: true,
            ..Unknowns::default()
        },
        ..RefineOptions::default()
    };
    let rec = Record::from_simulation(s, resp);
    let fit = refine(&rec, &start, &InitialState::default(), &opts).unwrap();
    assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
    fit
}

#[test]
fn balancing_from_the_identified_unbalance_removes_the_1x_vibration() {
    let s = table1(1.0);
    let truth = unbalance_of(&s.rotor.params());
    let clean = simulate(&s, Method::Exact).unwrap();
    let before = amplitudes(&clean);
    let radius = 0.15;

    // noise-free: the identified unbalance is exact to the fit's tolerance
    let fit = identify(&s, &clean);
    let cov = ParameterCovariance::from_refined(&fit).unwrap();
    let b = balance_from_unbalance(&fit.rotor, Some(&cov), radius).unwrap();
    let after = amplitudes(&simulate_with(&s, truth + b.correction.unbalance()));
    let reduction = [before[0] / after[0], before[1] / after[1]];
    println!(
        "noise-free: correction {:?}, 1X reduction {reduction:?}",
        b.correction
    );
    assert!(reduction.iter().all(|&r| r >= 20.0), "{reduction:?}");
    assert!((b.correction.angle - (s.rotor.unbalance().alpha + PI)).abs() < 1e-6);
    assert!((b.correction.mass * radius / truth.norm() - 1.0).abs() < 1e-6);

    // SNR 40 dB, several noise realisations: the residual unbalance is the estimation
    // error, whose size the standard errors predict
    let mut ratios = Vec::new();
    for seed in 0..4 {
        let mut noisy = clean.clone();
        add_noise(&mut noisy, 40.0, 100 + seed).unwrap();
        let fit = identify(&s, &noisy);
        let cov = ParameterCovariance::from_refined(&fit).unwrap();
        let b = balance_from_unbalance(&fit.rotor, Some(&cov), radius).unwrap();
        let residual = truth + b.correction.unbalance();
        let after = amplitudes(&simulate_with(&s, residual));
        let predicted = b.reduction.unwrap();
        let measured = [before[0] / after[0], before[1] / after[1]];
        println!(
            "seed {seed}: predicted reduction {predicted:.0} (residual {:.2e} kg m), measured {measured:.0?}, std mass {:.2e} kg angle {:.2e} rad",
            b.residual_unbalance.unwrap(),
            b.correction.std_mass.unwrap(),
            b.correction.std_angle.unwrap()
        );
        // the re-simulated response scales with the unbalance (same transfer, same
        // transient): the measured reduction is |U| / |residual|
        for m in measured {
            assert!(
                (m * residual.norm() / truth.norm() - 1.0).abs() < 0.02,
                "{m}"
            );
        }
        assert!(measured.iter().all(|&r| r >= 20.0), "{measured:?}");
        ratios.push(residual.norm() / b.residual_unbalance.unwrap());
        // and the error is consistent with the covariance of (u_c, u_s): Mahalanobis
        // distance below the 99.9 % point of chi^2 with 2 degrees of freedom
        let (ic, is) = (
            cov.names()
                .iter()
                .position(|n| n == "mud_cos_alpha")
                .unwrap(),
            cov.names()
                .iter()
                .position(|n| n == "mud_sin_alpha")
                .unwrap(),
        );
        let m = cov.matrix();
        let s2 = nalgebra::Matrix2::new(m[ic][ic], m[ic][is], m[is][ic], m[is][is]);
        let err = nalgebra::Vector2::new(
            fit.rotor.unbalance.mud() * fit.rotor.unbalance.alpha.cos() - truth.re,
            fit.rotor.unbalance.mud() * fit.rotor.unbalance.alpha.sin() - truth.im,
        );
        let d2 = (err.transpose() * s2.try_inverse().unwrap() * err)[(0, 0)];
        assert!(d2 < 13.8, "seed {seed}: Mahalanobis^2 {d2}");
    }
    // over the seeds, the RMS of |residual| / predicted residual is about 1 (chi^2 with 8
    // degrees of freedom / 8: 99.9 % within [0.07, 3.3] for the mean square)
    let ms = ratios.iter().map(|r| r * r).sum::<f64>() / ratios.len() as f64;
    println!("mean square of |residual| / predicted: {ms:.3}");
    assert!(ms > 0.07 && ms < 3.3, "{ratios:?}");
}

#[test]
fn influence_coefficients_from_two_simulated_runs_balance_the_rotor() {
    // Runs at 1200 rpm for 1 s from rest: the 1X vectors carry a little of the free
    // transient, so the correction is accurate to about a per cent, not to rounding.
    let s = table1(1.0);
    let truth = unbalance_of(&s.rotor.params());
    let trial = TrialMass {
        mass: 2e-4,
        radius: 0.1,
        angle: 200f64.to_radians(),
    };
    let t = Complex::from_polar(trial.mass * trial.radius, trial.angle);
    let vectors = |r: &TimeResponse| RunVectors {
        x: one_x(&r.x, &r.phi).unwrap().unwrap(),
        z: one_x(&r.z, &r.phi).unwrap().unwrap(),
    };
    let reference = simulate(&s, Method::Exact).unwrap();
    let trial_run = simulate_with(&s, truth + t);
    let radius = 0.15;
    let b = balance_from_runs(&vectors(&reference), &vectors(&trial_run), &trial, radius)
        .unwrap()
        .unwrap();
    let c = b.correction.unbalance();
    println!("correction {:?}, want {}", b.correction, -truth);
    assert!(
        (c + truth).norm() < 0.02 * truth.norm(),
        "{c} vs {}",
        -truth
    );
    let before = amplitudes(&reference);
    let after = amplitudes(&simulate_with(&s, truth + c));
    println!(
        "influence coefficients: 1X reduction x {:.0}, z {:.0}",
        before[0] / after[0],
        before[1] / after[1]
    );
    assert!(
        before[0] / after[0] >= 20.0 && before[1] / after[1] >= 20.0,
        "{before:?} -> {after:?}"
    );
    // the influence coefficients are the model's response per unit unbalance
    let w = rpm_to_rad_per_s(1200.0);
    let p = s.rotor.params();
    for (h, probe) in b.influence.iter().zip([Probe::X, Probe::Z]) {
        let want = response_per_unbalance(&p, w, probe).unwrap().unwrap();
        assert!((h - want).norm() < 0.02 * want.norm(), "{h} vs {want}");
    }

    // Pure steady-state runs (started on the steady state): exact to rounding
    let steady = |u: Complex<f64>| {
        let p = with_unbalance(&p, u);
        let ss = steady_state(&Rotor::new(p).unwrap(), w);
        let (q, v) = (ss.displacement(0.0, 0.0), ss.velocity(0.0, 0.0));
        let sc = Scenario {
            rotor: Rotor::new(p).unwrap(),
            initial: InitialState {
                x: q[0],
                z: q[1],
                vx: v[0],
                vz: v[1],
            },
            ..table1(0.2)
        };
        vectors(&simulate(&sc, Method::Exact).unwrap())
    };
    let b = balance_from_runs(&steady(truth), &steady(truth + t), &trial, radius)
        .unwrap()
        .unwrap();
    let c = b.correction.unbalance();
    assert!(
        (c + truth).norm() < 1e-8 * truth.norm(),
        "{c} vs {}",
        -truth
    );
    assert!((b.correction.angle - (p.unbalance.alpha + PI)).abs() < 1e-8);
}

#[test]
fn bad_inputs_are_rejected_with_their_name_and_range() {
    let p = Rotor::table1().params();
    let e = modes(&RotorParams { m: 0.0, ..p }, 1.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m = 0 is out of range: must be finite and > 0 (kg)"
    );
    let e = modes(&p, -1.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "speed = -1 is out of range: must be finite and >= 0 (rad/s)"
    );
    let e = critical_speeds(&p, None, &[0.0, 10.0, 10.0]).unwrap_err();
    assert_eq!(
        e,
        AnalysisError::NotIncreasing {
            index: 2,
            value: 10.0,
            previous: 10.0
        }
    );
    let e = critical_speeds(&p, None, &[0.0]).unwrap_err();
    assert!(matches!(e, AnalysisError::TooFew { needed: 2, .. }), "{e}");
    let e = balance_from_unbalance(&p, None, 0.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "radius = 0 is out of range: must be finite and > 0 (m)"
    );
    let e = unbalance_response(&p, None, &[1.0], &[Probe { angle: f64::NAN }]).unwrap_err();
    assert!(e.to_string().starts_with("probe angle = NaN"), "{e}");
}
