//! Model adequacy: records of rotors that eq. (1) does not describe (a cubic support
//! stiffness; an x support standing on a flexible foundation), simulated here by an
//! independent RK4 integrator, are flagged and their values withheld; records of the model
//! itself pass at 20, 40 and 60 dB. `cargo test --release -p rotorid --test it adequacy --
//! --ignored --nocapture` runs the 100-seed study and prints the rates.

use rotorid::pipeline::{identify, Finding, Knowledge, Method, Record, Speed};
use rotorid::simulate::{add_noise, TimeResponse};
use rotorid::test_models::table1;
use rotorid::Scenario;

/// What eq. (1) leaves out.
#[derive(Clone, Copy, Debug)]
enum Defect {
    /// kx x + k3 x^3 in x [N/m^3].
    CubicStiffness(f64),
    /// The x support on a foundation of mass mf [kg], stiffness kf [N/m], damping cf [N s/m].
    Foundation { mf: f64, kf: f64, cf: f64 },
}

/// table1 at 1200 rpm from rest with `defect`, RK4 with 20 sub-steps per sample, 1 s at
/// 10 kHz, as a response with per-sample speed.
fn simulate_defective(defect: Defect) -> TimeResponse {
    let s = Scenario::table1();
    let p = s.rotor.params();
    let w = 1200.0 * std::f64::consts::TAU / 60.0;
    let (mud, alpha) = (p.unbalance.mud(), p.unbalance.alpha);
    // state: x, z, vx, vz, xf, vxf
    let f = |t: f64, y: &[f64; 6]| -> [f64; 6] {
        let phi = w * t + alpha;
        let (fx, fz) = (mud * w * w * phi.sin(), mud * w * w * phi.cos());
        let (x, z, vx, vz, xf, vxf) = (y[0], y[1], y[2], y[3], y[4], y[5]);
        let (support_x, foundation) = match defect {
            Defect::CubicStiffness(k3) => (p.cx * vx + p.kx * x + k3 * x * x * x, 0.0),
            Defect::Foundation { mf, kf, cf } => {
                let sx = p.cx * (vx - vxf) + p.kx * (x - xf);
                (sx, (sx - cf * vxf - kf * xf) / mf)
            }
        };
        let ax = (fx - support_x + p.a * w * vz) / p.m;
        let az = (fz - p.cz * vz - p.kz * z - p.a * w * vx) / p.m;
        [vx, vz, ax, az, vxf, foundation]
    };
    let (dt, n, sub) = (1e-4, 10_001, 20);
    let h = dt / sub as f64;
    let mut y = [0.0; 6];
    let mut r = TimeResponse::with_capacity(n);
    for i in 0..n {
        let t0 = i as f64 * dt;
        r.t.push(t0);
        r.x.push(y[0]);
        r.z.push(y[1]);
        r.phi.push(w * t0);
        r.phi_dot.push(w);
        r.phi_ddot.push(0.0);
        for j in 0..sub {
            let t = t0 + j as f64 * h;
            let add = |a: &[f64; 6], k: &[f64; 6], c: f64| std::array::from_fn(|q| a[q] + c * k[q]);
            let k1 = f(t, &y);
            let k2 = f(t + h / 2.0, &add(&y, &k1, h / 2.0));
            let k3 = f(t + h / 2.0, &add(&y, &k2, h / 2.0));
            let k4 = f(t + h, &add(&y, &k3, h));
            y = std::array::from_fn(|q| {
                y[q] + h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])
            });
        }
    }
    r
}

const DEFECTS: [Defect; 2] = [
    // 5 % more stiffness at 0.3 um
    Defect::CubicStiffness(0.05 * 1.195e6 / (3e-7 * 3e-7)),
    Defect::Foundation {
        mf: 5.0,
        kf: 5e6,
        cf: 50.0,
    },
];

/// (adequacy flagged, every value withheld) for refine on `clean` with noise (`snr`, `seed`).
fn refine_flags(clean: &TimeResponse, snr: f64, seed: u64) -> (bool, bool) {
    let mut r = clean.clone();
    add_noise(&mut r, snr, seed).unwrap();
    let rec = Record::new(
        r.t.clone(),
        r.x.clone(),
        r.z.clone(),
        Speed::Samples {
            phi: r.phi.clone(),
            omega: r.phi_dot.clone(),
            omega_dot: r.phi_ddot.clone(),
        },
        1e-6,
    )
    .unwrap();
    let k = Knowledge::from_scenario(&Scenario::table1());
    let id = identify(&rec, &k, &Method::refine()).unwrap();
    let flagged = id
        .diagnostics
        .iter()
        .any(|d| matches!(d.finding, Finding::ModelInadequate { .. }));
    assert_eq!(flagged, !id.adequacy.unwrap().model_adequate);
    let withheld = id.parameters.iter().all(|p| p.value.is_none());
    (flagged, withheld)
}

/// Rates over `seeds`: false alarms on the model itself per SNR, detections per defect.
fn rates(seeds: u64) -> ([f64; 3], [f64; 2]) {
    let clean = table1().clean;
    let alarms = [20.0, 40.0, 60.0].map(|snr| {
        (0..seeds)
            .filter(|&s| refine_flags(&clean, snr, 100 + s).0)
            .count() as f64
            / seeds as f64
    });
    let detections = DEFECTS.map(|d| {
        let c = simulate_defective(d);
        (0..seeds)
            .filter(|&s| {
                let (flagged, withheld) = refine_flags(&c, 40.0, 500 + s);
                assert_eq!(flagged, withheld, "{d:?}: flagged values are withheld");
                flagged
            })
            .count() as f64
            / seeds as f64
    });
    (alarms, detections)
}

#[test]
fn wrong_models_are_flagged_and_the_model_itself_is_not() {
    let (alarms, detections) = rates(8);
    for (snr, a) in [20, 40, 60].iter().zip(alarms) {
        assert!(a <= 0.125, "{snr} dB: {a} false alarms");
    }
    for (d, r) in DEFECTS.iter().zip(detections) {
        assert_eq!(r, 1.0, "{d:?}: detected in {r}");
    }
}

#[test]
fn a_ramp_of_the_model_itself_passes() {
    // the ramp is refined with RK4 on the per-sample speed: its model error must stay
    // invisible even at 60 dB
    let clean = rotorid::test_models::table1_ramp(600.0).clean;
    for seed in 0..4 {
        assert!(!refine_flags(&clean, 60.0, 900 + seed).0, "seed {seed}");
    }
}

#[test]
#[ignore = "100-seed study (~1 min in release): cargo test --release ... -- --ignored"]
fn hundred_seed_adequacy_rates() {
    let (alarms, detections) = rates(100);
    println!("false alarms on eq. (1) at 20/40/60 dB: {alarms:?}");
    println!("detections at 40 dB, 1 s (cubic stiffness, foundation): {detections:?}");
    assert!(alarms.iter().all(|&a| a <= 0.05));
    assert!(detections.iter().all(|&d| d >= 0.95));
}

/// For refine on `clean` + noise: per parameter m, cx, kx, cz, kz, whether the estimate is
/// within 1.96 standard errors of the truth by the Fisher and by the sandwich covariance,
/// and the ratio sandwich / Fisher.
fn interval_check(clean: &TimeResponse, snr: f64, seed: u64) -> Vec<(bool, bool, f64)> {
    let mut r = clean.clone();
    add_noise(&mut r, snr, seed).unwrap();
    let rec = Record::new(
        r.t.clone(),
        r.x.clone(),
        r.z.clone(),
        Speed::Samples {
            phi: r.phi.clone(),
            omega: r.phi_dot.clone(),
            omega_dot: r.phi_ddot.clone(),
        },
        1e-6,
    )
    .unwrap();
    let k = Knowledge::from_scenario(&Scenario::table1());
    let id = identify(&rec, &k, &Method::refine()).unwrap();
    id.parameters
        .iter()
        .map(|p| {
            let err = (p.estimate.unwrap() - p.truth.unwrap()).abs();
            let (se, robust) = (p.std_error.unwrap(), p.robust_std_error.unwrap());
            (err <= 1.96 * se, err <= 1.96 * robust, robust / se)
        })
        .collect()
}

/// Coverage of the 95 % intervals (Fisher, sandwich) and the median sandwich / Fisher
/// ratio over `seeds`, pooled over m, cx, kx, cz, kz.
fn coverage(clean: &TimeResponse, snr: f64, seeds: std::ops::Range<u64>) -> (f64, f64, f64) {
    let mut all = Vec::new();
    for s in seeds {
        all.extend(interval_check(clean, snr, s));
    }
    let n = all.len() as f64;
    let fisher = all.iter().filter(|c| c.0).count() as f64 / n;
    let robust = all.iter().filter(|c| c.1).count() as f64 / n;
    let mut ratios: Vec<f64> = all.iter().map(|c| c.2).collect();
    ratios.sort_by(f64::total_cmp);
    (fisher, robust, ratios[ratios.len() / 2])
}

#[test]
fn the_sandwich_agrees_with_fisher_on_the_model_and_widens_on_wrong_ones() {
    // eq. (1) itself: the residuals are white, the bandwidth ~0, the two agree
    let (f, r, ratio) = coverage(&table1().clean, 40.0, 300..308);
    eprintln!("model itself: coverage Fisher {f:.2}, sandwich {r:.2}, median ratio {ratio:.2}");
    assert!((0.8..1.25).contains(&ratio), "{ratio}");
    assert!(f >= 0.8 && r >= 0.8, "{f} {r}");
    for d in DEFECTS {
        let (f, r, ratio) = coverage(&simulate_defective(d), 40.0, 700..708);
        eprintln!("{d:?}: coverage Fisher {f:.2}, sandwich {r:.2}, median ratio {ratio:.2}");
        assert!(ratio > 1.5, "{d:?}: {ratio}");
        assert!(r >= f, "{d:?}");
    }
}
