//! The analysis of the cross-coupled rotor (docs/method.md section 1.6, docs/analysis.md
//! section 4) against independent references: the library's exact simulator (a free
//! vibration grows above the computed threshold speed, decays below it, at the rate
//! Re lambda of the least damped mode), and a Monte Carlo over a covariance for the
//! delta-method standard deviations of the threshold speed and of the logarithmic
//! decrements.

use nalgebra::{Cholesky, DMatrix, DVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rotorid::analysis::{
    critical_speeds, stability, stability_margin, stability_with_covariance, ParameterCovariance,
    Whirl,
};
use rotorid::model::{
    rpm_to_rad_per_s, CrossCoupling, InitialState, Rotor, RotorParams, Scenario, SpeedProfile,
    Unbalance,
};
use rotorid::simulate::{simulate, Method};
use rotorid::Sampling;

/// An anisotropic rotor on cross-coupled bearings whose forward mode goes unstable near
/// 3208 rpm: kzx > 0 > kxz feeds forward whirl and, with a < 0, the forward frequency
/// (and with it the damping force c w that opposes the cross-coupling) falls with speed.
fn rotor() -> RotorParams {
    RotorParams {
        m: 14.29,
        cx: 200.0,
        cz: 180.0,
        kx: 1.195e6,
        kz: 1.25e6,
        a: -2.871,
        unbalance: Unbalance {
            m_u: 0.0,
            d: 0.0,
            alpha: 0.0,
        },
        coupling: Some(CrossCoupling {
            cxz: 10.0,
            czx: -5.0,
            kxz: -4.5e4,
            kzx: 5.5e4,
        }),
    }
}

/// Speeds from `lo` to `hi` rpm every `step` rpm \[rad/s\].
fn grid(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step).round() as usize;
    (0..=n)
        .map(|k| rpm_to_rad_per_s(lo + k as f64 * step))
        .collect()
}

/// The growth rate \[1/s\] of the orbit radius of a free vibration at constant speed `w`,
/// from the exact simulator: ln of the largest radius over the last 50 ms over that of
/// the 50 ms from 0.5 s (the more damped mode has decayed by then), per second.
fn simulated_growth_rate(p: &RotorParams, w: f64) -> f64 {
    let s = Scenario {
        rotor: Rotor::new(*p).unwrap(),
        speed: SpeedProfile::constant_rpm(w * 60.0 / std::f64::consts::TAU, 0.0).unwrap(),
        sampling: Sampling::new(1e-4, 2.0).unwrap(),
        initial: InitialState {
            x: 1e-5,
            z: 0.0,
            vx: 0.0,
            vz: 0.0,
        },
    };
    let r = simulate(&s, Method::Exact).unwrap();
    let radius = |i: usize| r.x[i].hypot(r.z[i]);
    let window = |t0: f64| {
        let i0 = (t0 / 1e-4).round() as usize;
        (i0..i0 + 500).map(radius).fold(0.0, f64::max)
    };
    let (t0, t1) = (0.5, r.t[r.t.len() - 1] - 0.05);
    (window(t1) / window(t0)).ln() / (t1 - t0)
}

#[test]
fn analysis_threshold_separates_growth_from_decay_in_the_exact_simulation() {
    let p = rotor();
    let s = stability(&p, &grid(0.0, 6000.0, 10.0)).unwrap();
    let wt = s.threshold.expect("unstable in the range");
    assert!(!s.unstable_at_start);
    assert_eq!(s.threshold_whirl, Some(Whirl::Forward));
    println!("threshold {:.3} rpm", wt * 60.0 / std::f64::consts::TAU);
    for f in [0.9, 0.97, 1.03, 1.1] {
        let w = f * wt;
        let m = stability_margin(&p, None, w).unwrap();
        let sigma = m.at.eigenvalue.re;
        let measured = simulated_growth_rate(&p, w);
        println!(
            "{f} x threshold: Re lambda {sigma:.5} 1/s, simulated {measured:.5} 1/s, log dec {:.5}",
            m.log_dec().unwrap()
        );
        assert_eq!(measured > 0.0, f > 1.0, "{f}: {measured}");
        assert_eq!(m.is_unstable(), f > 1.0);
        assert!(
            (measured / sigma - 1.0).abs() < 0.05,
            "{f}: simulated {measured} vs Re lambda {sigma}"
        );
    }
}

/// The names of the covariance (the cross-coupled summary's: cxx for cx, ...) and the
/// parameter values in that order.
const NAMES: [&str; 10] = [
    "m", "cxx", "kxx", "czz", "kzz", "a", "cxz", "czx", "kxz", "kzx",
];

fn vector(p: &RotorParams) -> [f64; 10] {
    let c = p.cross();
    [p.m, p.cx, p.kx, p.cz, p.kz, p.a, c.cxz, c.czx, c.kxz, c.kzx]
}

fn from_vector(v: &DVector<f64>) -> RotorParams {
    RotorParams {
        m: v[0],
        cx: v[1],
        kx: v[2],
        cz: v[3],
        kz: v[4],
        a: v[5],
        coupling: Some(CrossCoupling {
            cxz: v[6],
            czx: v[7],
            kxz: v[8],
            kzx: v[9],
        }),
        ..rotor()
    }
}

fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

#[test]
fn analysis_threshold_and_log_dec_std_agree_with_monte_carlo() {
    let p = rotor();
    let v = vector(&p);
    // as a fit leaves them: 0.3 % on m and k (m, k correlated), 1 % on c and a, the cross
    // terms to 1 N s/m and 300 N/m (kxz, kzx anti-correlated)
    let sd = [
        0.003 * v[0],
        0.01 * v[1],
        0.003 * v[2],
        0.01 * v[3],
        0.003 * v[4],
        0.01 * v[5].abs(),
        1.0,
        1.0,
        300.0,
        300.0,
    ];
    let mut cov = DMatrix::from_fn(10, 10, |i, j| if i == j { sd[i] * sd[i] } else { 0.0 });
    for (i, j, r) in [
        (0, 2, 0.8),
        (0, 4, 0.7),
        (2, 4, 0.6),
        (8, 9, -0.5),
        (1, 3, 0.3),
    ] {
        cov[(i, j)] = r * sd[i] * sd[j];
        cov[(j, i)] = r * sd[i] * sd[j];
    }
    let pc = ParameterCovariance::new(
        NAMES.iter().map(|s| s.to_string()).collect(),
        (0..10)
            .map(|i| (0..10).map(|j| cov[(i, j)]).collect())
            .collect(),
    )
    .unwrap();
    let speeds = grid(2000.0, 6000.0, 50.0);
    let s = stability_with_covariance(&p, Some(&pc), &speeds).unwrap();
    let (wt, wt_std) = (s.threshold.unwrap(), s.threshold_std.unwrap());
    let w_op = 0.8 * wt;
    let margin = stability_margin(&p, Some(&pc), w_op).unwrap();
    let cs = critical_speeds(&p, Some(&pc), &speeds).unwrap();
    assert_eq!(cs.len(), 2, "{cs:?}");

    let l = Cholesky::new(cov).unwrap().l();
    let mean = DVector::from_row_slice(&v);
    let mut rng = ChaCha8Rng::seed_from_u64(26);
    let n = 2000;
    let (mut th, mut ld_op, mut ld0, mut ld1) = (vec![], vec![], vec![], vec![]);
    for _ in 0..n {
        let z = DVector::from_fn(10, |_, _| StandardNormal.sample(&mut rng));
        let q = from_vector(&(&mean + &l * z));
        th.push(stability(&q, &speeds).unwrap().threshold.unwrap());
        ld_op.push(stability_margin(&q, None, w_op).unwrap().log_dec().unwrap());
        let c = critical_speeds(&q, None, &speeds).unwrap();
        ld0.push(c[0].at.log_dec.unwrap());
        ld1.push(c[1].at.log_dec.unwrap());
    }
    // 2000 draws: the sample standard deviation is within ~1.6 % (1 sigma) of the truth
    for (label, mc, linear) in [
        ("threshold speed", std_dev(&th), wt_std),
        (
            "log dec at 0.8 x threshold",
            std_dev(&ld_op),
            margin.log_dec_std.unwrap(),
        ),
        (
            "log dec at the first critical speed",
            std_dev(&ld0),
            cs[0].log_dec_std.unwrap(),
        ),
        (
            "log dec at the second critical speed",
            std_dev(&ld1),
            cs[1].log_dec_std.unwrap(),
        ),
    ] {
        println!(
            "{label}: Monte Carlo {mc:.4e}, linearised {linear:.4e}, ratio {:.4}",
            mc / linear
        );
        assert!(
            (mc / linear - 1.0).abs() < 0.10,
            "{label}: {mc} vs {linear}"
        );
    }
    println!(
        "threshold {:.2} +- {:.2} rpm; log dec at 0.8 x threshold {:.5} +- {:.5}",
        wt * 60.0 / std::f64::consts::TAU,
        wt_std * 60.0 / std::f64::consts::TAU,
        margin.log_dec().unwrap(),
        margin.log_dec_std.unwrap()
    );
}

/// The check on identified data: refine's fit of the cross-coupled rotor (40 dB,
/// constant speed from rest, several seeds) and its covariance give the least damped
/// mode's logarithmic decrement at the operating speed within 3 of its standard deviations
/// of the true rotor's.
#[test]
fn the_log_decrement_of_an_identified_cross_coupled_rotor_is_within_three_std_of_the_truth() {
    use rotorid::pipeline::{identify, Method as IdMethod, ModelChoice, RefineSettings};
    use rotorid::test_models::{cross_coupled, cross_coupled_rotor};
    let truth = cross_coupled_rotor();
    let w = rpm_to_rad_per_s(1200.0);
    let want = stability_margin(&truth, None, w)
        .unwrap()
        .log_dec()
        .unwrap();
    let method = IdMethod::Refine(RefineSettings {
        model: Some(ModelChoice::CrossCoupled),
        ..RefineSettings::default()
    });
    let mut zs = Vec::new();
    for seed in 0..6 {
        let tm = cross_coupled().with_noise(40.0, 300 + seed);
        let id = identify(&tm.record(), &tm.knowledge(), &method).unwrap();
        let p = id.rotor.as_ref().unwrap().params();
        let cov =
            ParameterCovariance::from_identification(id.covariance.as_ref().unwrap()).unwrap();
        let m = stability_margin(&p, Some(&cov), w).unwrap();
        let (ld, sd) = (m.log_dec().unwrap(), m.log_dec_std.unwrap());
        assert!(sd > 0.0 && sd < 0.2 * want, "seed {seed}: {ld} +- {sd}");
        zs.push((ld - want) / sd);
    }
    println!("log decrement at 1200 rpm {want:.5}: (identified - true) / std = {zs:.2?}");
    assert!(zs.iter().all(|z| z.abs() < 3.0), "{zs:?}");
}
