//! Maximum-likelihood identification of the bearings and unbalances of the ROSS two-disk
//! rotor (44 DOF) from its response at the two bearings (x, y each) computed with the FULL
//! model (the fit uses the reduced one), at 40 dB, started from an engineering guess
//! (bearing coefficients 30-70 % off, unbalance angles 40 deg off). Figures printed with
//! `cargo test -p rotorid --test it fe_refine -- --nocapture`.

use rotorid::model::finite_element::{FeParameter, FiniteElementRotor};
use rotorid::model::SpeedProfile;
use rotorid::refine::finite_element::{
    crb_fe, refine_fe, FeData, FeInitial, FeRefineOptions, FeRefined,
};

use crate::fe_common::{guess, record, ross_rotor};

fn report(fit: &FeRefined, truth: &FiniteElementRotor) -> f64 {
    let mut worst: f64 = 0.0;
    for p in &fit.parameters {
        let name = FeParameter::parse_list(&p.parameter, truth).unwrap()[0];
        let t = name.get(truth).unwrap();
        let z = (p.value - t) / p.std_error;
        worst = worst.max(z.abs());
        eprintln!(
            "  {:18} {:>14.6e} +- {:.3e} (truth {:.6e}, z = {:+.2}, crb {:?}, reduction bias {:?} std)",
            p.parameter, p.value, p.std_error, t, z, p.crb, p.reduction_bias_std
        );
    }
    eprintln!(
        "  trials {}, converged {}, identifiable {}, cond {:.2e}, adequate {}, reduction {:?}, warnings {:?}",
        fit.iterations, fit.converged, fit.identifiable, fit.condition_number, fit.model_adequate,
        fit.reduction, fit.warnings
    );
    worst
}

/// Simulate `duration` s of the truth from rest on `speed` (full model, 40 dB, `seed`),
/// identify it from the engineering guess with the initial state known, attach the
/// Cramer-Rao bound at the truth (8 modes: the full model to 1e-8), print and check: converged,
/// identifiable, adequate, every value within 4.5 std, every std within 30 % of its bound.
fn from_rest(label: &str, speed: SpeedProfile, duration: f64, seed: u64) {
    let truth = ross_rotor();
    let (rec, sigma) = record(&truth, &speed, duration, 40.0, seed);
    let data = FeData {
        response: &rec,
        speed,
    };
    let mut options = FeRefineOptions::new(&truth);
    options.initial = FeInitial::Rest;
    let t0 = std::time::Instant::now();
    let mut fit = refine_fe(&data, &guess(&truth), &options).unwrap();
    eprintln!("{label}, 40 dB, fit in {:?}", t0.elapsed());
    let crb = crb_fe(
        &data,
        &truth,
        &FeRefineOptions {
            modes: 8,
            ..options.clone()
        },
        &sigma,
    )
    .unwrap();
    fit.attach_crb(&crb);
    let worst = report(&fit, &truth);
    assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
    assert!(fit.model_adequate, "{:?}", fit.adequacy);
    assert!(worst < 4.5, "{worst}");
    for p in &fit.parameters {
        let b = p.crb.unwrap();
        assert!(p.std_error < 1.3 * b && p.std_error > 0.7 * b, "{p:?}");
    }
}

#[test]
fn fe_refine_recovers_bearings_and_unbalances_on_a_run_up_from_rest() {
    let speed = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 225.0,
        phi0: 0.0,
    };
    from_rest("run-up 0 -> 450 rad/s in 2 s", speed, 2.0, 1);
}

#[test]
fn fe_refine_recovers_bearings_and_unbalances_at_constant_speed_from_rest() {
    let speed = SpeedProfile::Constant {
        omega: 200.0,
        phi0: 0.0,
    };
    from_rest("constant 200 rad/s 1 s from rest", speed, 1.0, 2);
}

#[test]
fn fe_refine_fast_run_up_of_the_benchmark() {
    // the benchmark's case (benches/refine_fe.rs): 0 -> 450 rad/s in 1 s
    let speed = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 450.0,
        phi0: 0.0,
    };
    from_rest("run-up 0 -> 450 rad/s in 1 s", speed, 1.0, 3);
}

#[test]
fn fe_refine_estimates_the_initial_state_of_a_record_taken_mid_run() {
    // 1.2 s at constant speed from rest, the first 0.2 s cut off: the record starts in a
    // transient (the lowest mode decays in ~0.4 s), its initial state unknown
    let truth = ross_rotor();
    let omega = 250.0;
    let speed = SpeedProfile::Constant { omega, phi0: 0.0 };
    let (whole, sigma) = record(&truth, &speed, 1.2, 40.0, 4);
    let cut = 2000;
    let mut rec = whole.clone();
    rec.t = whole.t[cut..].to_vec();
    for c in rec.q.iter_mut() {
        c.drain(..cut);
    }
    rec.phi.drain(..cut);
    rec.phi_dot.drain(..cut);
    rec.phi_ddot.drain(..cut);
    let data = FeData {
        response: &rec,
        speed: SpeedProfile::Constant {
            omega,
            phi0: omega * whole.t[cut],
        },
    };
    let options = FeRefineOptions::new(&truth);
    assert_eq!(options.initial, FeInitial::Estimated);
    let t0 = std::time::Instant::now();
    let fit = refine_fe(&data, &guess(&truth), &options).unwrap();
    eprintln!(
        "constant {omega} rad/s, 1 s from t = 0.2 s, initial state estimated, fit in {:?}",
        t0.elapsed()
    );
    let worst = report(&fit, &truth);
    assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
    assert!(fit.model_adequate, "{:?}", fit.adequacy);
    assert!(worst < 4.5, "{worst}");
    // the fitted initial state in full coordinates is the truth's state at 0.2 s: its
    // response at the probes starts where the data start (to the noise)
    let s = fit.initial_state.as_ref().unwrap();
    assert_eq!(s.q.len(), truth.matrices.n());
    for (c, col) in fit.model_response.iter().enumerate() {
        assert!((col[0] - rec.q[c][0]).abs() < 5.0 * sigma[c], "{c}");
    }
}

#[test]
fn fe_refine_refuses_bad_input_by_name() {
    let truth = ross_rotor();
    let speed = SpeedProfile::Constant {
        omega: 200.0,
        phi0: 0.0,
    };
    let (rec, _) = record(&truth, &speed, 0.05, 40.0, 5);
    let opts = FeRefineOptions::new(&truth);
    let err = |r: &rotorid::simulate::finite_element::FeResponse, o: &FeRefineOptions| {
        refine_fe(&FeData { response: r, speed }, &truth, o)
            .unwrap_err()
            .to_string()
    };
    // a stamp off the grid
    let mut bad = rec.clone();
    bad.t[7] += 0.5e-4;
    let e = err(&bad, &opts);
    assert!(e.contains("sample 7") && e.contains("uniform"), "{e}");
    // a non-finite value names its channel and sample
    let mut bad = rec.clone();
    bad.q[2][11] = f64::NAN;
    let e = err(&bad, &opts);
    assert!(e.contains("10.x") && e.contains("sample 11"), "{e}");
    // a channel the matrices do not have
    let mut bad = rec.clone();
    bad.dofs[0] = "99.x".parse().unwrap();
    let e = err(&bad, &opts);
    assert!(e.contains("99.x") && e.contains("0.x, 0.y"), "{e}");
    // nothing to estimate
    let mut o = opts.clone();
    o.unknowns.clear();
    o.initial = FeInitial::Rest;
    assert!(err(&rec, &o).contains("no unknown"));
    // too few samples for 12 unknowns and 36 initial coordinates
    let mut short = rec.clone();
    short.t.truncate(100);
    for c in short.q.iter_mut() {
        c.truncate(100);
    }
    let e = err(&short, &opts);
    assert!(e.contains("100 samples") && e.contains("480"), "{e}");
}
