//! The convergence tracker against a brute-force computation: exact while the staircases
//! fit; when they are merged, never earlier than the truth and never later than the truth
//! for a band narrowed by the reported resolution. Bounded memory on long records.

use proptest::prelude::*;
use rotorid::identify::algebraic::{
    AlgebraicEstimate, ConvergenceTracker, DirectionEstimate, DEFAULT_STACK_CAPACITY,
};
use rotorid::Parameter;

/// (t, value, well conditioned)
type Seq = Vec<(f64, f64, bool)>;

/// Earliest well-conditioned t from which every well-conditioned value lies in
/// [lo, hi] (None if the last one does not), by brute force.
fn brute_time(seq: &Seq, lo: f64, hi: f64) -> Option<f64> {
    let good: Vec<(f64, f64)> = seq.iter().filter(|s| s.2).map(|s| (s.0, s.1)).collect();
    let mut start = None;
    for &(t, v) in good.iter().rev() {
        if lo <= v && v <= hi {
            start = Some(t);
        } else {
            break;
        }
    }
    start
}

fn band(seq: &Seq, tol: f64) -> Option<(f64, f64, f64)> {
    let f = seq.iter().rev().find(|s| s.2)?.1;
    let d = tol * f.abs();
    Some((f, f - d, f + d))
}

/// Feed the six parameters: m_x = v, c_x = -v, k_x = 1e6 v, and the z ones from `w`.
fn track(x: &Seq, z: &Seq, tol: f64, cap: usize) -> ConvergenceTracker {
    let mut tr = ConvergenceTracker::with_capacity(tol, 0.5, cap).unwrap();
    for (a, b) in x.iter().zip(z) {
        let dir = |s: &(f64, f64, bool)| DirectionEstimate {
            m: s.1,
            c: -s.1,
            k: 1e6 * s.1,
            rcond: if s.2 { 1.0 } else { 0.1 },
        };
        tr.push(&AlgebraicEstimate {
            t: a.0,
            x: dir(a),
            z: dir(b),
        });
    }
    tr
}

fn component(seq: &Seq, p: Parameter) -> Seq {
    let scale = [1.0, -1.0, 1e6][ix(p) % 3];
    seq.iter().map(|&(t, v, ok)| (t, scale * v, ok)).collect()
}

fn sequences() -> impl Strategy<Value = (Seq, Seq)> {
    (1usize..400).prop_flat_map(|n| {
        let one = prop::collection::vec((-1.0f64..1.0, 0u8..10, 0u8..20), n).prop_map(|raw| {
            // a noisy approach to 5 with occasional spikes; 10 % flagged
            let len = raw.len() as f64;
            raw.iter()
                .enumerate()
                .map(|(i, &(u, flag, spike))| {
                    let decay = (-(6.0 * i as f64 / len)).exp();
                    let v = 5.0 + 0.5 * decay * u + if spike == 0 { 2.0 * u } else { 0.01 * u };
                    (i as f64 * 1e-3, v, flag != 0)
                })
                .collect::<Seq>()
        });
        (one.clone(), one)
    })
}

fn check_exact(x: &Seq, z: &Seq, tol: f64) {
    let tr = track(x, z, tol, 1 << 20);
    for p in Parameter::PER_DIRECTION {
        let seq = component(if ix(p) < 3 { x } else { z }, p);
        let r = tr.result(p).unwrap();
        assert_eq!(r.resolution, 0.0);
        match band(&seq, tol) {
            None => {
                assert_eq!(r.final_value, None);
                assert_eq!(r.identification_time, None);
                assert_eq!(r.well_conditioned, 0);
            }
            Some((f, lo, hi)) => {
                assert_eq!(r.final_value, Some(f));
                assert_eq!(
                    r.identification_time,
                    brute_time(&seq, lo, hi),
                    "{}",
                    p.name()
                );
                assert_eq!(
                    r.well_conditioned,
                    seq.iter().filter(|s| s.2).count() as u64
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn exact_without_merging((x, z) in sequences(), tol in 0.0f64..0.2) {
        check_exact(&x, &z, tol);
    }

    #[test]
    fn conservative_with_merging((x, z) in sequences(), tol in 0.0f64..0.2, cap in 2usize..12) {
        let tr = track(&x, &z, tol, cap);
        prop_assert!(tr.stack_entries() <= 12 * cap);
        for p in Parameter::PER_DIRECTION {
            let seq = component(if ix(p) < 3 { &x } else { &z }, p);
            let r = tr.result(p).unwrap();
            let Some((f, lo, hi)) = band(&seq, tol) else { continue };
            prop_assert_eq!(r.final_value, Some(f));
            let inf = f64::INFINITY;
            let truth = brute_time(&seq, lo, hi).unwrap_or(inf);
            let got = r.identification_time.unwrap_or(inf);
            let delta = r.resolution;
            let narrowed = brute_time(&seq, lo + delta, hi - delta).unwrap_or(inf);
            prop_assert!(truth <= got, "{}: reported {} earlier than the truth {}", p.name(), got, truth);
            prop_assert!(got <= narrowed, "{}: reported {} later than {} (band narrowed by {})", p.name(), got, narrowed, delta);
        }
    }
}

#[test]
fn a_converging_sequence_reports_when_it_entered_the_band_for_good() {
    // v = 10 (1 + e^-t cos 20t): within 1 % of 10 for good once e^-t < 0.01 roughly.
    let mut tr = ConvergenceTracker::new(0.01, 1e-5).unwrap();
    let dt = 1e-3;
    let mut last_out = 0.0;
    for i in 0..=10_000 {
        let t = i as f64 * dt;
        let v = 10.0 * (1.0 + (-t).exp() * (20.0 * t).cos());
        let fin = 10.0 * (1.0 + (-10.0f64).exp() * (200.0f64).cos());
        if ((v - fin) / fin).abs() > 0.01 {
            last_out = t;
        }
        let d = DirectionEstimate {
            m: v,
            c: v,
            k: v,
            rcond: 1.0,
        };
        tr.push(&AlgebraicEstimate { t, x: d, z: d });
    }
    for r in tr.results() {
        assert_eq!(
            r.identification_time,
            Some(last_out + dt),
            "{}",
            r.parameter.name()
        );
        assert_eq!(r.final_t, Some(10.0));
        assert_eq!(r.resolution, 0.0);
    }
    // Flagged instants never count: a wild value with rcond below the threshold is ignored.
    let d = DirectionEstimate {
        m: 1e9,
        c: 1e9,
        k: 1e9,
        rcond: 1e-9,
    };
    tr.push(&AlgebraicEstimate {
        t: 10.001,
        x: d,
        z: d,
    });
    assert_eq!(
        tr.result(Parameter::Kz).unwrap().identification_time,
        Some(last_out + dt)
    );
    assert_eq!(tr.estimates(), 10_002);
}

#[test]
fn two_million_estimates_in_bounded_memory() {
    // A slowly drifting, noisy record (the worst case for the staircases: a monotone drift
    // keeps every sample a suffix extreme).
    let mut tr = ConvergenceTracker::new(0.01, 1e-5).unwrap();
    let n = 2_000_000u64;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for i in 0..n {
        let t = i as f64 * 1e-4;
        let v = 14.0 + 1e-6 * (n - i) as f64 + 1e-4 * noise();
        let d = DirectionEstimate {
            m: v,
            c: -v,
            k: 1e5 * v,
            rcond: 1.0,
        };
        tr.push(&AlgebraicEstimate { t, x: d, z: d });
    }
    assert!(tr.stack_entries() <= 12 * DEFAULT_STACK_CAPACITY);
    let r = tr.result(Parameter::MX).unwrap();
    let t = r.identification_time.unwrap();
    // Truth: the drift is 1e-6 per sample from 14 + 2 down to 14; 1 % of 14.000001 is
    // 0.14, reached when 1e-6 (n - i) <= 0.14 -> i >= n - 140000, i.e. t ~ 186 s (noise
    // +-5e-5 moves it by ~50 samples).
    assert!((t - 186.0).abs() < 0.1, "identification time {t}");
    assert!(r.resolution < 0.01 * 14.0, "resolution {}", r.resolution);
}

/// Position of `p` in an estimate's per-direction values.
fn ix(p: Parameter) -> usize {
    p.direction_index().unwrap()
}
