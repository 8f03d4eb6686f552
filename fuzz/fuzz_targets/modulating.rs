//! The modulating-function identifier fed an arbitrary configuration and f64 sequence:
//! errors are fine, panics are not; the estimate can be asked for at any point.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid::identify::modulating::{ModulatingConfig, ModulatingIdentifier, NoiseCompensation};
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
    let sane = v.byte() % 2 == 0;
    let dt = if sane { 1e-4 } else { v.f64() };
    let mut config = if sane {
        // short windows, so that windows complete within a short input
        ModulatingConfig::with_window(dt * f64::from(24 + v.byte() % 40))
    } else {
        ModulatingConfig::with_window(v.f64())
    };
    config.functions = usize::from(v.byte() % 6);
    config.noise = match v.byte() % 3 {
        0 => NoiseCompensation::None,
        1 => NoiseCompensation::Estimated,
        _ => NoiseCompensation::Known {
            sigma_x: v.f64(),
            sigma_z: v.f64(),
        },
    };
    if !sane {
        config.hop_s = v.f64();
        config.rcond_min = v.f64();
    }
    let Ok(mut id) = ModulatingIdentifier::new(known, dt, config) else {
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
        let _ = id.push(&m);
        if v.byte() % 64 == 0 {
            let _ = id.estimate();
        }
        i += 1;
    }
    let _ = id.estimate();
    let _ = id.noise_sigmas();
});
