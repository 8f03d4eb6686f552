//! The constant-speed identifier (docs/method.md section 3.3, constant speed) against the
//! general one and against an independent, slow, whole-array implementation of its
//! formulas; batch against streaming.

use crate::identify_common::*;
use nalgebra::{Matrix3, Vector3};
use rotorid::identify::algebraic::{
    identify_batch, identify_response, measurement, AlgebraicConfig, AlgebraicIdentifier,
    Quadrature, SpeedModel,
};
use rotorid::identify::{Known, Measurement};
use rotorid::model::rpm_to_rad_per_s;
use rotorid::simulate::{simulate, Method};
use rotorid::{Sampling, Scenario, SpeedProfile};

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// table1 at constant speed with a non-zero phi0 (so that phase handling is exercised).
fn constant_scenario(duration: f64) -> (Scenario, f64, f64) {
    let phi0 = 0.4;
    let mut sc = Scenario::table1();
    sc.speed = SpeedProfile::constant_rpm(1200.0, phi0).unwrap();
    sc.sampling = Sampling::new(1e-4, duration).unwrap();
    (sc, rpm_to_rad_per_s(1200.0), phi0)
}

#[test]
fn constant_speed_mode_agrees_with_the_general_mode_on_constant_speed_data() {
    let (sc, w, phi0) = constant_scenario(0.3);
    let resp = simulate(&sc, Method::Exact).unwrap();
    let known = Known::from_rotor(&sc.rotor);
    for q in Quadrature::ALL {
        let general = AlgebraicConfig {
            quadrature: q,
            ..AlgebraicConfig::default()
        };
        let constant = AlgebraicConfig {
            speed_model: SpeedModel::Constant { omega: w, phi0 },
            ..general
        };
        let g = identify_response(&resp, known, general).unwrap();
        // The constant mode ignores the speed columns: poison them.
        let mut blind = resp.clone();
        blind.phi.iter_mut().for_each(|v| *v = f64::NAN);
        blind.phi_dot.iter_mut().for_each(|v| *v = f64::NAN);
        blind.phi_ddot.iter_mut().for_each(|v| *v = f64::NAN);
        let c = identify_response(&blind, known, constant).unwrap();
        for (eg, ec) in g.iter().zip(&c).skip(100) {
            for (a, b) in eg.values().iter().zip(ec.values()) {
                assert!(close(*a, b, 1e-12), "{q} t={}: {a} vs {b}", eg.t);
            }
            assert!(close(eg.x.rcond, ec.x.rcond, 1e-12));
        }
    }
}

/// Cumulative trapezoid over the whole array: I[0] = 0, I[n] = I[n-1] + h (f[n] + f[n-1]) / 2.
fn cum(f: &[f64], h: f64) -> Vec<f64> {
    let mut out = vec![0.0; f.len()];
    for n in 1..f.len() {
        out[n] = out[n - 1] + 0.5 * h * (f[n] + f[n - 1]);
    }
    out
}

fn cum2(f: &[f64], h: f64) -> Vec<f64> {
    cum(&cum(f, h), h)
}

fn lin(terms: &[(f64, &[f64])]) -> Vec<f64> {
    (0..terms[0].1.len())
        .map(|i| terms.iter().map(|(c, v)| c * v[i]).sum())
        .collect()
}

/// The constant-speed identifier written directly from docs/method.md sections 3.1-3.4
/// (slow, whole arrays, nalgebra LU): estimates (m, c, k) for one direction at sample `n`.
struct Reference {
    a: [Vec<f64>; 9],
    b: [Vec<f64>; 3],
}

impl Reference {
    /// `y` the direction's displacement, `other` the other one, `sign` +1 for x (Sx uses
    /// +a W on z, sin) and -1 for z (Sz uses -a W on x, cos).
    fn new(
        t: &[f64],
        y: &[f64],
        other: &[f64],
        force: &[f64],
        k: &Known,
        w: f64,
        sign: f64,
    ) -> Self {
        let h = t[1] - t[0];
        let tau: Vec<f64> = t.iter().map(|v| v - t[0]).collect();
        let ty: Vec<f64> = tau.iter().zip(y).map(|(a, b)| a * b).collect();
        let t2y: Vec<f64> = tau.iter().zip(&ty).map(|(a, b)| a * b).collect();
        // P = tau^2 y - 4 I1[tau y] + 2 I2[y];  Q = I1[tau^2 y] - 2 I2[tau y];  R = I2[tau^2 y]
        let p = lin(&[(1.0, &t2y), (-4.0, &cum(&ty, h)), (2.0, &cum2(y, h))]);
        let q = lin(&[(1.0, &cum(&t2y, h)), (-2.0, &cum2(&ty, h))]);
        let r = cum2(&t2y, h);
        // S = sign a W (I1[tau^2 o] - 2 I2[tau o]) + mud W^2 I2[tau^2 force]
        let to: Vec<f64> = tau.iter().zip(other).map(|(a, b)| a * b).collect();
        let t2o: Vec<f64> = tau.iter().zip(&to).map(|(a, b)| a * b).collect();
        let t2f: Vec<f64> = tau.iter().zip(force).map(|(a, b)| a * a * b).collect();
        let aw = sign * k.a * w;
        let s = lin(&[
            (aw, &cum(&t2o, h)),
            (-2.0 * aw, &cum2(&to, h)),
            (k.mud * w * w, &cum2(&t2f, h)),
        ]);
        Reference {
            a: [
                p.clone(),
                q.clone(),
                r.clone(),
                cum(&p, h),
                cum(&q, h),
                cum(&r, h),
                cum2(&p, h),
                cum2(&q, h),
                cum2(&r, h),
            ],
            b: [s.clone(), cum(&s, h), cum2(&s, h)],
        }
    }

    fn estimate(&self, n: usize) -> [f64; 3] {
        let a = Matrix3::from_fn(|i, j| self.a[3 * i + j][n]);
        let b = Vector3::from_fn(|i, _| self.b[i][n]);
        // Column scaling only to keep LU happy; LU with partial pivoting, not the adjugate.
        let d = Vector3::from_fn(|j, _| 1.0 / a.column(j).amax());
        let x = (a * Matrix3::from_diagonal(&d)).lu().solve(&b).unwrap();
        [x[0] * d[0], x[1] * d[1], x[2] * d[2]]
    }
}

#[test]
fn constant_speed_formulas_match_an_independent_slow_reference() {
    let (sc, w, phi0) = constant_scenario(0.3);
    let resp = simulate(&sc, Method::Exact).unwrap();
    let known = Known::from_rotor(&sc.rotor);
    let phase: Vec<f64> = resp.t.iter().map(|t| w * t + phi0 + known.alpha).collect();
    let sin: Vec<f64> = phase.iter().map(|p| p.sin()).collect();
    let cos: Vec<f64> = phase.iter().map(|p| p.cos()).collect();
    let rx = Reference::new(&resp.t, &resp.x, &resp.z, &sin, &known, w, 1.0);
    let rz = Reference::new(&resp.t, &resp.z, &resp.x, &cos, &known, w, -1.0);
    let config = AlgebraicConfig {
        quadrature: Quadrature::Trapezoid,
        ..AlgebraicConfig::constant_speed(w, phi0).unwrap()
    };
    let est = identify_response(&resp, known, config).unwrap();
    let mut compared = 0;
    for n in (200..resp.len()).step_by(97) {
        let e = &est[n];
        for (d, reference) in [(e.x, &rx), (e.z, &rz)] {
            if !d.well_conditioned(1e-4) {
                continue;
            }
            let want = reference.estimate(n);
            // Same discrete quantities, different code, order of operations and solver:
            // agreement to rounding amplified by the conditioning.
            for (got, want, tol) in [
                (d.m, want[0], 1e-8),
                (d.c, want[1], 1e-6),
                (d.k, want[2], 1e-8),
            ] {
                assert!(close(got, want, tol), "t = {}: {got} vs {want}", e.t);
            }
            compared += 1;
        }
    }
    assert!(compared > 40, "only {compared} instants compared");
}

#[test]
fn batch_is_the_streaming_fold_bit_for_bit() {
    let mut sc = Scenario::table1_ramp(600.0).unwrap();
    sc.sampling = Sampling::new(1e-4, 0.2).unwrap();
    let resp = simulate(&sc, Method::Newmark).unwrap();
    let known = Known::from_rotor(&sc.rotor);
    let ms: Vec<Measurement> = (0..resp.len()).map(|i| measurement(&resp, i)).collect();
    for q in Quadrature::ALL {
        let config = AlgebraicConfig {
            quadrature: q,
            ..AlgebraicConfig::default()
        };
        let batch = identify_batch(&ms, known, 1e-4, config).unwrap();
        let from_response = identify_response(&resp, known, config).unwrap();
        let mut id = AlgebraicIdentifier::new(known, 1e-4, config).unwrap();
        for ((m, b), r) in ms.iter().zip(&batch).zip(&from_response) {
            let s = id.push(m).unwrap();
            let bits = |e: &rotorid::identify::algebraic::AlgebraicEstimate| {
                let v = e.values();
                [
                    v[0], v[1], v[2], v[3], v[4], v[5], e.x.rcond, e.z.rcond, e.t,
                ]
                .map(f64::to_bits)
            };
            assert_eq!(bits(&s), bits(b));
            assert_eq!(bits(&s), bits(r));
        }
    }
}

#[test]
fn reset_restarts_from_the_next_sample() {
    let mut sc = Scenario::table1();
    sc.sampling = Sampling::new(1e-4, 0.2).unwrap();
    let resp = simulate(&sc, Method::Exact).unwrap();
    let known = Known::from_rotor(&sc.rotor);
    let config = AlgebraicConfig::default();
    let mut id = AlgebraicIdentifier::new(known, 1e-4, config).unwrap();
    for i in 0..500 {
        id.push(&measurement(&resp, i)).unwrap();
    }
    id.reset();
    assert_eq!(id.samples(), 0);
    let mut fresh = AlgebraicIdentifier::new(known, 1e-4, config).unwrap();
    for i in 700..resp.len() {
        // after a reset any time is accepted as the new t_0 (here a jump of 200 samples)
        let (a, b) = (
            id.push(&measurement(&resp, i)).unwrap(),
            fresh.push(&measurement(&resp, i)).unwrap(),
        );
        assert_eq!(a.values().map(f64::to_bits), b.values().map(f64::to_bits));
    }
    // and a window starting at 70 ms identifies as well as one starting at 0
    let window: Vec<Measurement> = (700..resp.len()).map(|i| measurement(&resp, i)).collect();
    let e = &identify_batch(&window, known, 1e-4, config).unwrap()[1000];
    let err = rel_errors(e, &truth(&sc));
    assert!(err[0].abs() < 1e-6 && err[2].abs() < 1e-6, "{err:?}");
}
