//! The algebraic identifier fed an arbitrary configuration and f64 sequence: it may refuse
//! a value with an error, but never panics, and its estimates' rcond stay in [0, 1].

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid::identify::algebraic::{AlgebraicConfig, AlgebraicIdentifier, Quadrature, SpeedModel};
use rotorid::identify::{Known, Measurement};
use rotorid::SpeedState;
use rotorid_fuzz::Values;

fuzz_target!(|data: &[u8]| {
    let mut v = Values::new(data);
    let known = Known {
        a: v.f64(),
        mud: v.f64(),
        alpha: v.f64(),
    };
    let quadrature = match v.byte() % 4 {
        0 => Quadrature::Trapezoid,
        1 => Quadrature::AdamsMoulton3,
        2 => Quadrature::AdamsMoulton4,
        _ => Quadrature::AdamsMoulton5,
    };
    let speed_model = if v.byte() % 2 == 0 {
        SpeedModel::General
    } else {
        SpeedModel::Constant {
            omega: v.f64(),
            phi0: v.f64(),
        }
    };
    let config = AlgebraicConfig {
        quadrature,
        rcond_min: v.f64().abs().min(1.0),
        speed_model,
    };
    // half the runs on a sane grid, so the pushes get past the time check
    let sane = v.byte() % 2 == 0;
    let dt = if sane { 1e-4 } else { v.f64() };
    let Ok(mut id) = AlgebraicIdentifier::new(known, dt, config) else {
        return;
    };
    let mut i = 0u32;
    while !v.is_empty() && i < 4096 {
        let t = if sane { f64::from(i) * dt } else { v.f64() };
        let m = Measurement {
            t,
            x: v.f64(),
            z: v.f64(),
            speed: SpeedState {
                phi: v.f64(),
                omega: v.f64(),
                omega_dot: v.f64(),
            },
        };
        if let Ok(est) = id.push(&m) {
            for d in [est.x, est.z] {
                assert!((0.0..=1.0).contains(&d.rcond) || d.rcond.is_nan(), "{d:?}");
            }
        }
        i += 1;
    }
});
