//! The identification pipeline's streaming session fed arbitrary samples (time stamps,
//! displacements, speed) for each method: it may refuse a sample or the record with an
//! error, but never panics, and what it reports is finite or withheld.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid::pipeline::{Knowledge, Method, Sample, Session, Timing};
use rotorid::{Scenario, SpeedState};
use rotorid_fuzz::Values;

fuzz_target!(|data: &[u8]| {
    let mut v = Values::new(data);
    let method = match v.byte() % 3 {
        0 => Method::algebraic(),
        1 => Method::modulating(),
        _ => Method::refine(),
    };
    let knowledge = Knowledge::from_scenario(&Scenario::table1());
    let timing = Timing::Fit {
        head: 2 + v.byte() as usize % 16,
        tolerance: v.f64().abs().min(1.0),
    };
    let profile = (v.byte() % 2 == 0).then_some(Scenario::table1().speed);
    let Ok(mut s) = Session::new(&knowledge, &method, profile, timing) else {
        return;
    };
    let with_speed = profile.is_none();
    let mut t = 0.0;
    let mut n = 0;
    while !v.is_empty() && n < 600 {
        t += 1e-4 * (1.0 + 1e-3 * (v.byte() as f64 - 128.0) / 128.0);
        let speed = with_speed.then(|| SpeedState {
            phi: v.f64(),
            omega: v.f64(),
            omega_dot: v.f64(),
        });
        let sample = Sample {
            t: Some(if v.byte() == 0 { v.f64() } else { t }),
            x: v.f64() * 1e-6,
            z: v.f64() * 1e-6,
            speed,
        };
        if s.push(&sample, &mut |_| {}).is_err() {
            return;
        }
        n += 1;
    }
    if let Ok(id) = s.finish(&mut |_| {}) {
        for p in &id.parameters {
            assert!(p.value.is_none_or(f64::is_finite));
        }
    }
});
