//! Accuracy of the exact reference (`Method::Exact`) against closed forms and against each
//! other:
//! - started on the closed-form steady state, the exact discretisation stays on it;
//! - the DoPri8 path forced onto a constant-speed profile agrees with the exact
//!   discretisation (two independent methods);
//! - a free response (no unbalance, a = 0) matches the analytic damped free vibration.

use rotorid::model::{InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile};
use rotorid::simulate::{
    run, simulate, steady_state, DoPri8Reference, ExactConstant, Integrator, Method, TimeResponse,
};

/// Largest |a - b| over both channels, divided by the largest |a| (signal amplitude).
fn max_rel_diff(a: &TimeResponse, b: &TimeResponse) -> f64 {
    assert_eq!(a.len(), b.len());
    let amp = a.x.iter().chain(&a.z).fold(0.0f64, |m, v| m.max(v.abs()));
    let err = (0..a.len()).fold(0.0f64, |m, i| {
        m.max((a.x[i] - b.x[i]).abs()).max((a.z[i] - b.z[i]).abs())
    });
    err / amp
}

/// Table 1 made anisotropic (different supports in x and z) to exercise every term.
fn anisotropic() -> Rotor {
    Rotor::new(RotorParams {
        cx: 25.0,
        cz: 8.0,
        kx: 1.0e6,
        kz: 1.4e6,
        ..Rotor::table1().params()
    })
    .unwrap()
}

#[test]
fn exact_discretisation_stays_on_the_closed_form_steady_state_for_1_s() {
    for (rotor, rpm) in [
        (Rotor::table1(), 1200.0),
        (anisotropic(), 1200.0),
        (anisotropic(), 3500.0),
    ] {
        let phi0 = 0.3;
        let speed = SpeedProfile::constant_rpm(rpm, phi0).unwrap();
        let w = speed.at(0.0).omega;
        let ss = steady_state(&rotor, w);
        let (q0, v0) = (ss.displacement(0.0, phi0), ss.velocity(0.0, phi0));
        let initial = InitialState {
            x: q0[0],
            z: q0[1],
            vx: v0[0],
            vz: v0[1],
        };
        let dt = 1e-4;
        let mut ex = ExactConstant::new(&rotor, &speed, dt, initial).unwrap();
        let amp = ss.amplitude().max();
        let mut worst = 0.0f64;
        for _ in 0..10_000 {
            let s = ex.step().unwrap();
            let q = ss.displacement(s.t, phi0);
            let v = ss.velocity(s.t, phi0);
            worst = worst.max((s.x - q[0]).abs()).max((s.z - q[1]).abs());
            // velocities too, relative to W * amplitude
            let ve = (s.vx - v[0]).abs().max((s.vz - v[1]).abs());
            assert!(
                ve < 1e-11 * w * amp,
                "rpm {rpm}, t = {}: velocity error {ve:e}",
                s.t
            );
        }
        eprintln!(
            "steady state, rpm {rpm}: max |q - q_ss| / amplitude = {:.2e}",
            worst / amp
        );
        assert!(
            worst < 1e-12 * amp,
            "rpm {rpm}: max |x - x_ss| = {:e} of the amplitude",
            worst / amp
        );
    }
}

#[test]
fn dopri8_on_a_constant_speed_agrees_with_the_exact_discretisation() {
    // Table 1 from rest (transient + forced response), 1 s at 0.1 ms, and the anisotropic
    // rotor at a second speed and a coarser grid (where the tolerance, not dt, sets the
    // DoPri8 step).
    let cases = [
        (Rotor::table1(), 1200.0, 1e-4, 1.0),
        (anisotropic(), 3500.0, 5e-4, 0.5),
    ];
    for (rotor, rpm, dt, duration) in cases {
        let sc = Scenario {
            rotor,
            speed: SpeedProfile::constant_rpm(rpm, 0.7).unwrap(),
            sampling: Sampling::new(dt, duration).unwrap(),
            initial: InitialState::default(),
        };
        let exact = simulate(&sc, Method::Exact).unwrap();
        let mut d = DoPri8Reference::new(&sc.rotor, &sc.speed, dt, sc.initial).unwrap();
        let dopri = run(&mut d, sc.sampling.samples()).unwrap();
        let e = max_rel_diff(&exact, &dopri);
        eprintln!("dopri8 vs exact, rpm {rpm}, dt {dt}: {e:.2e} of the amplitude");
        assert!(e < 1e-10, "rpm {rpm}, dt {dt}: {e:e}");
    }
}

/// x(t) = e^{-zeta w t} (x0 cos(wd t) + (v0 + zeta w x0) / wd sin(wd t)) for
/// m x'' + c x' + k x = 0.
fn damped_free(m: f64, c: f64, k: f64, x0: f64, v0: f64, t: f64) -> f64 {
    let w = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = w * (1.0 - zeta * zeta).sqrt();
    (-zeta * w * t).exp() * (x0 * (wd * t).cos() + (v0 + zeta * w * x0) / wd * (wd * t).sin())
}

#[test]
fn free_response_matches_the_analytic_damped_vibration() {
    // a = 0, no unbalance: x and z are two independent damped oscillators, so the speed
    // profile is irrelevant. Heavier damping than table1 so the decay is visible in 0.5 s.
    let rotor = Rotor::new(RotorParams {
        a: 0.0,
        cx: 150.0,
        cz: 60.0,
        kx: 1.0e6,
        kz: 1.4e6,
        unbalance: rotorid::model::Unbalance {
            m_u: 0.0,
            ..Rotor::table1().unbalance()
        },
        ..Rotor::table1().params()
    })
    .unwrap();
    let initial = InitialState {
        x: 2e-6,
        z: -1e-6,
        vx: 3e-4,
        vz: 5e-4,
    };
    let p = rotor.params();
    let dt = 1e-4;
    let n = 5000;
    let amp = 2e-6f64.max(5e-4 / (p.kz / p.m).sqrt());
    let constant = SpeedProfile::constant_rpm(1200.0, 0.0).unwrap();
    let ramp = SpeedProfile::ramp(0.0, 10.0, 0.0).unwrap();
    let integrators: Vec<(&str, Box<dyn Integrator>, f64)> = vec![
        (
            "exact",
            Box::new(ExactConstant::new(&rotor, &constant, dt, initial).unwrap()),
            1e-12,
        ),
        (
            "dopri8",
            Box::new(DoPri8Reference::new(&rotor, &ramp, dt, initial).unwrap()),
            1e-11,
        ),
    ];
    for (name, mut integ, tol) in integrators {
        let s0 = integ.current();
        assert_eq!((s0.x, s0.z, s0.vx, s0.vz), (2e-6, -1e-6, 3e-4, 5e-4));
        let mut worst = 0.0f64;
        for _ in 0..n {
            let s = integ.step().unwrap();
            let x = damped_free(p.m, p.cx, p.kx, initial.x, initial.vx, s.t);
            let z = damped_free(p.m, p.cz, p.kz, initial.z, initial.vz, s.t);
            worst = worst.max((s.x - x).abs()).max((s.z - z).abs());
        }
        eprintln!(
            "free response, {name}: {:.2e} of the amplitude",
            worst / amp
        );
        assert!(worst < tol * amp, "{name}: {:e}", worst / amp);
    }
}
