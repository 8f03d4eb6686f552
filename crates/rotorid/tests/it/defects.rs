//! Rotors eq. (1) does not describe (a cubic support stiffness; an x support standing on
//! a flexible foundation), simulated by an independent RK4 integrator: the wrong models of
//! the adequacy tests (`adequacy`), also included by the fleet's tests
//! (crates/rotorid-fleet/tests/common), which alert on them.

#![allow(dead_code)]

use rotorid::simulate::TimeResponse;
use rotorid::Scenario;

/// What eq. (1) leaves out.
#[derive(Clone, Copy, Debug)]
pub enum Defect {
    /// kx x + k3 x^3 in x [N/m^3].
    CubicStiffness(f64),
    /// The x support on a foundation of mass mf [kg], stiffness kf [N/m], damping cf [N s/m].
    Foundation { mf: f64, kf: f64, cf: f64 },
}

/// table1 at 1200 rpm from rest with `defect`, RK4 with 20 sub-steps per sample, 1 s at
/// 10 kHz, as a response with per-sample speed.
pub fn simulate_defective(defect: Defect) -> TimeResponse {
    simulate_defective_for(defect, 1.0)
}

/// The same, `seconds` long.
pub fn simulate_defective_for(defect: Defect, seconds: f64) -> TimeResponse {
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
    let (dt, sub) = (1e-4, 20);
    let n = (seconds / dt).round() as usize + 1;
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

pub const DEFECTS: [Defect; 2] = [
    // 5 % more stiffness at 0.3 um
    Defect::CubicStiffness(0.05 * 1.195e6 / (3e-7 * 3e-7)),
    Defect::Foundation {
        mf: 5.0,
        kf: 5e6,
        cf: 50.0,
    },
];
