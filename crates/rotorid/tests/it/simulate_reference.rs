//! The DoPri8 reference on ramps: it converges as the tolerance tightens,
//! and it agrees with an independent second method, a fixed-step classical Runge-Kutta 4
//! with Richardson extrapolation written here from eq. (1) directly.

use rotorid::model::{InitialState, Rotor, SpeedProfile};
use rotorid::simulate::{run, DoPri8Reference, TimeResponse};

/// Largest |a - b| over both channels relative to the largest |b|.
fn max_rel_diff(a: &TimeResponse, b: &TimeResponse) -> f64 {
    let amp = b.x.iter().chain(&b.z).fold(0.0f64, |m, v| m.max(v.abs()));
    let err = (0..a.len()).fold(0.0f64, |m, i| {
        m.max((a.x[i] - b.x[i]).abs()).max((a.z[i] - b.z[i]).abs())
    });
    err / amp
}

fn dopri(speed: &SpeedProfile, dt: f64, n: usize, tol: f64) -> TimeResponse {
    let r = Rotor::table1();
    let mut d =
        DoPri8Reference::with_tolerance(&r, speed, dt, InitialState::default(), tol).unwrap();
    run(&mut d, n + 1).unwrap()
}

/// Right-hand side of eq. (1), written out from the paper's equations:
/// m x'' + cx x' - a w z' - a w' z + kx x = mud ( w^2 sin(phi+alpha) - w' cos(phi+alpha) )
/// m z'' + cz z' + a w x'          + kz z = mud ( w' sin(phi+alpha) + w^2 cos(phi+alpha) )
fn rhs(r: &Rotor, sp: &SpeedProfile, t: f64, y: [f64; 4]) -> [f64; 4] {
    let p = r.params();
    let st = sp.at(t);
    let (w, wd) = (st.omega, st.omega_dot);
    let th = st.phi + p.unbalance.alpha;
    let mud = p.unbalance.m_u * p.unbalance.d;
    let [x, z, vx, vz] = y;
    let fx = mud * (w * w * th.sin() - wd * th.cos());
    let fz = mud * (wd * th.sin() + w * w * th.cos());
    [
        vx,
        vz,
        (fx - p.cx * vx + p.a * w * vz + p.a * wd * z - p.kx * x) / p.m,
        (fz - p.cz * vz - p.a * w * vx - p.kz * z) / p.m,
    ]
}

/// Classical RK4 with `sub` equal steps per sampling interval, restarting every interval
/// at t_i = i dt exactly; returns x, z at every sample.
fn rk4(sp: &SpeedProfile, dt: f64, n: usize, sub: usize) -> Vec<[f64; 2]> {
    let r = Rotor::table1();
    let mut y = [0.0; 4];
    let mut out = vec![[0.0, 0.0]];
    let add = |y: [f64; 4], k: [f64; 4], h: f64| std::array::from_fn(|j| y[j] + h * k[j]);
    for i in 0..n {
        let h = dt / sub as f64;
        for j in 0..sub {
            let t = i as f64 * dt + j as f64 * h;
            let k1 = rhs(&r, sp, t, y);
            let k2 = rhs(&r, sp, t + h / 2.0, add(y, k1, h / 2.0));
            let k3 = rhs(&r, sp, t + h / 2.0, add(y, k2, h / 2.0));
            let k4 = rhs(&r, sp, t + h, add(y, k3, h));
            y = std::array::from_fn(|m| {
                y[m] + h / 6.0 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m])
            });
        }
        out.push([y[0], y[1]]);
    }
    out
}

#[test]
fn dopri8_converges_as_the_tolerance_tightens() {
    // A coarse output grid (10 ms, ~3 rad of the natural frequency) so that the tolerance,
    // not the output interval, sets the DoPri8 step; 0.5 s of the 10 rad/s^2 ramp from
    // 600 rpm. (At the paper's 0.1 ms one DoPri8 step per interval is already accurate to
    // ~1e-13, whatever the tolerance.)
    let sp = SpeedProfile::ramp(600.0, 10.0, 0.2).unwrap();
    let (dt, n) = (1e-2, 50);
    let best = dopri(&sp, dt, n, 1e-14);
    let tols = [1e-6, 1e-8, 1e-10, 1e-12, 1e-13];
    let errs: Vec<f64> = tols
        .iter()
        .map(|&tol| max_rel_diff(&dopri(&sp, dt, n, tol), &best))
        .collect();
    eprintln!("DoPri8 error vs tol 1e-14 at tol 1e-6, 1e-8, 1e-10, 1e-12, 1e-13: {errs:?}");
    for w in errs.windows(2) {
        assert!(w[1] < w[0] / 5.0, "no convergence: {errs:?}");
    }
    // global error ~ 100 tol once the tolerance sets the step
    for (e, tol) in errs.iter().zip(tols) {
        assert!(*e < 1000.0 * tol, "tol {tol:e}: {e:e}");
    }
}

#[test]
fn dopri8_agrees_with_richardson_extrapolated_rk4_on_ramps() {
    let dt = 1e-4;
    let n = 3000;
    for sp in [
        SpeedProfile::ramp(600.0, 10.0, 0.2).unwrap(),
        SpeedProfile::ramp(0.0, 200.0, 0.0).unwrap(),
    ] {
        let reference = dopri(&sp, dt, n, 1e-13);
        // RK4 global error ~ C h^4: (16 y(h/2) - y(h)) / 15 cancels it.
        let coarse = rk4(&sp, dt, n, 4);
        let fine = rk4(&sp, dt, n, 8);
        let mut rk = reference.clone();
        let mut rk_fine = reference.clone();
        for i in 0..=n {
            rk_fine.x[i] = fine[i][0];
            rk_fine.z[i] = fine[i][1];
            rk.x[i] = (16.0 * fine[i][0] - coarse[i][0]) / 15.0;
            rk.z[i] = (16.0 * fine[i][1] - coarse[i][1]) / 15.0;
        }
        let e_fine = max_rel_diff(&rk_fine, &reference);
        let e = max_rel_diff(&rk, &reference);
        eprintln!("{sp:?}: RK4 (h = dt/8) vs DoPri8 {e_fine:.2e}, extrapolated {e:.2e}");
        assert!(e < 1e-9, "{sp:?}: {e:e}");
        // the extrapolation helped by orders of magnitude (so the agreement is not luck)
        assert!(e < e_fine / 100.0, "{e:e} vs {e_fine:e}");
    }
}
