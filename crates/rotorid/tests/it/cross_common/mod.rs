//! An independent reference for the cross-coupled 2-DOF rotor, written here from
//! the model note rather than taken from the library's simulator:
//!
//! ```text
//! x:  m x'' + cxx x' + cxz z' - a w z' + kxx x + kxz z - a w' z = m_u d ( w^2 sin(phi+alpha) - w' cos(phi+alpha) )
//! z:  m z'' + czx x' + czz z' + a w x' + kzx x + kzz z          = m_u d ( w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! - constant speed: the state (x, z, x', z') augmented with the forcing oscillator
//!   (sin, cos of phi + alpha) is linear and autonomous, y' = A y; it is stepped by
//!   exp(A dt) (nalgebra's matrix exponential), with every component scaled to order one
//!   first so that the exponential's rounding is relative to each entry's own size;
//! - any speed profile (ramps): the classical fourth-order Runge-Kutta method with many
//!   sub-steps per sampling interval.
//!
//! The two are checked against each other (and against the library's simulator on the
//! Jeffcott rotor) in `cross_reference.rs`. Also here: the test rotors, their stability,
//! and a Cramer-Rao bound by finite-difference sensitivities of the exact response.
#![allow(dead_code)]

use nalgebra::{DMatrix, Matrix4, SMatrix, SVector};
use rotorid::identify::{Known, CROSS_NAMES};
use rotorid::simulate::{add_noise, TimeResponse};

/// A cross-coupled rotor (SI units; names as in the model note).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossRotor {
    pub m: f64,
    pub a: f64,
    pub cxx: f64,
    pub cxz: f64,
    pub czx: f64,
    pub czz: f64,
    pub kxx: f64,
    pub kxz: f64,
    pub kzx: f64,
    pub kzz: f64,
    /// m_u d \[kg m\].
    pub mud: f64,
    /// alpha \[rad\].
    pub alpha: f64,
}

impl CrossRotor {
    /// The paper's Table 1 (Jeffcott: every cross term zero).
    pub fn table1() -> Self {
        Self {
            m: 14.29,
            a: 2.871,
            cxx: 10.0,
            cxz: 0.0,
            czx: 0.0,
            czz: 10.0,
            kxx: 1.195e6,
            kxz: 0.0,
            kzx: 0.0,
            kzz: 1.195e6,
            mud: 1.0e-4 * 0.15,
            alpha: 45f64.to_radians(),
        }
    }

    /// Table 1 on cross-coupled bearings: kzx = -kxz = 0.1 kxx (the sign that feeds forward
    /// whirl in this frame, as a fluid-film bearing's does: `cross_reference.rs`),
    /// symmetric cross damping 50 N s/m, and direct damping raised to 600 N s/m so that
    /// the rotor is stable (with 200 N s/m the least damped mode would grow at +7 1/s).
    pub fn cross() -> Self {
        Self {
            cxx: 600.0,
            czz: 600.0,
            cxz: 50.0,
            czx: 50.0,
            kxz: -0.1 * 1.195e6,
            kzx: 0.1 * 1.195e6,
            ..Self::table1()
        }
    }

    /// `cross` with weak cross damping, cxz = czx = 5 N s/m (1/120 of the direct).
    pub fn weak_cross_damping() -> Self {
        Self {
            cxz: 5.0,
            czx: 5.0,
            ..Self::cross()
        }
    }

    /// Anisotropic supports and cross terms: kzz 30 % stiffer than kxx, czz != cxx.
    pub fn anisotropic() -> Self {
        Self {
            cxx: 500.0,
            czz: 700.0,
            kzz: 1.3 * 1.195e6,
            ..Self::cross()
        }
    }

    /// Cross terms that are not antisymmetric: kxz != -kzx, cxz != czx.
    pub fn asymmetric() -> Self {
        Self {
            cxz: -60.0,
            czx: 30.0,
            kxz: -0.04 * 1.195e6,
            kzx: 0.12 * 1.195e6,
            ..Self::cross()
        }
    }

    /// The ten per-row values in the order of `CROSS_NAMES`.
    pub fn truth(&self) -> [f64; 10] {
        [
            self.m, self.cxx, self.cxz, self.kxx, self.kxz, self.m, self.czx, self.czz, self.kzx,
            self.kzz,
        ]
    }

    /// The scale each value's error is judged against: its own size, or for a cross term
    /// that is zero the direct coefficient of its row.
    pub fn scales(&self) -> [f64; 10] {
        let t = self.truth();
        // the direct coefficient of each value's row: cxz -> cxx, kxz -> kxx, czx -> czz,
        // kzx -> kzz
        let direct = [0, 1, 1, 3, 3, 5, 7, 7, 9, 9];
        std::array::from_fn(|i| {
            if t[i] != 0.0 {
                t[i].abs()
            } else {
                t[direct[i]].abs()
            }
        })
    }

    pub fn known(&self) -> Known {
        Known {
            a: self.a,
            mud: self.mud,
            alpha: self.alpha,
        }
    }

    /// d/dt (x, z, x', z') = A (x, z, x', z') + (0, 0, F / m) at speed w, acceleration wd.
    pub fn state_matrix(&self, w: f64, wd: f64) -> Matrix4<f64> {
        let m = self.m;
        let (c11, c12, c21, c22) = (
            self.cxx,
            self.cxz - self.a * w,
            self.czx + self.a * w,
            self.czz,
        );
        let (k11, k12, k21, k22) = (self.kxx, self.kxz - self.a * wd, self.kzx, self.kzz);
        Matrix4::new(
            0.0,
            0.0,
            1.0,
            0.0, //
            0.0,
            0.0,
            0.0,
            1.0, //
            -k11 / m,
            -k12 / m,
            -c11 / m,
            -c12 / m, //
            -k21 / m,
            -k22 / m,
            -c21 / m,
            -c22 / m,
        )
    }

    /// The largest real part of the free vibration's eigenvalues at constant speed w
    /// \[1/s\]: < 0 means stable.
    pub fn growth_rate(&self, w: f64) -> f64 {
        self.state_matrix(w, 0.0)
            .complex_eigenvalues()
            .iter()
            .map(|l| l.re)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The rotor with value `i` of the 13 of `PARAMS` moved by `delta`.
    fn moved(&self, i: usize, delta: f64) -> Self {
        let mut r = *self;
        let p = match i {
            0 => &mut r.m,
            1 => &mut r.cxx,
            2 => &mut r.cxz,
            3 => &mut r.czx,
            4 => &mut r.czz,
            5 => &mut r.kxx,
            6 => &mut r.kxz,
            7 => &mut r.kzx,
            8 => &mut r.kzz,
            _ => unreachable!(),
        };
        *p += delta;
        r
    }
}

/// The nine physical parameters of the model (m once) in the order of `CrossRotor::moved`.
pub const PARAMS: [&str; 9] = ["m", "cxx", "cxz", "czx", "czz", "kxx", "kxz", "kzx", "kzz"];

/// Index in `PARAMS` of each of the ten per-row values (m_x and m_z are both m).
pub const PARAM_OF_VALUE: [usize; 10] = [0, 1, 2, 5, 6, 0, 3, 4, 7, 8];

/// The speed profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Speed {
    /// w = omega \[rad/s\], phi = phi0 + omega t.
    Constant { omega: f64, phi0: f64 },
    /// w = w0 + accel t, phi = phi0 + w0 t + accel t^2 / 2.
    Ramp { w0: f64, accel: f64, phi0: f64 },
}

impl Speed {
    /// 1200 rpm from phi = 0.
    pub fn rpm1200() -> Self {
        Speed::Constant {
            omega: 1200.0 * std::f64::consts::PI / 30.0,
            phi0: 0.0,
        }
    }

    /// A 10 rad/s^2 ramp from `rpm0`.
    pub fn ramp(rpm0: f64) -> Self {
        Speed::Ramp {
            w0: rpm0 * std::f64::consts::PI / 30.0,
            accel: 10.0,
            phi0: 0.0,
        }
    }

    /// (phi, w, w') at t.
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        match *self {
            Speed::Constant { omega, phi0 } => (phi0 + omega * t, omega, 0.0),
            Speed::Ramp { w0, accel, phi0 } => {
                (phi0 + w0 * t + 0.5 * accel * t * t, w0 + accel * t, accel)
            }
        }
    }
}

/// One simulated experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    pub rotor: CrossRotor,
    pub speed: Speed,
    /// (x, z, x', z') at t = 0 \[m, m, m/s, m/s\].
    pub initial: [f64; 4],
    pub dt: f64,
    pub duration: f64,
}

impl Case {
    pub fn new(rotor: CrossRotor, speed: Speed, duration: f64) -> Self {
        Self {
            rotor,
            speed,
            initial: [0.0; 4],
            dt: 1e-4,
            duration,
        }
    }

    /// The same with a non-zero initial state (a free transient of the forced response's
    /// size).
    pub fn with_initial_state(self) -> Self {
        Self {
            initial: [2e-7, -1e-7, 1e-4, 5e-5],
            ..self
        }
    }

    /// [`Case::with_initial_state`] when `moving`, else the case as it is (from rest).
    pub fn starting(self, moving: bool) -> Self {
        if moving {
            self.with_initial_state()
        } else {
            self
        }
    }

    pub fn samples(&self) -> usize {
        (self.duration / self.dt * (1.0 + 1e-9)).floor() as usize + 1
    }

    /// The response by the reference for its speed profile: exact at constant speed, RK4
    /// with 64 sub-steps per sample otherwise (~1e-11 of the amplitude,
    /// `cross_reference.rs`).
    pub fn simulate(&self) -> TimeResponse {
        self.simulate_with(64)
    }

    /// As [`Case::simulate`] with `substeps` RK4 steps per sample on a ramp.
    pub fn simulate_with(&self, substeps: usize) -> TimeResponse {
        match self.speed {
            Speed::Constant { .. } => exact_constant(self),
            Speed::Ramp { .. } => rk4(self, substeps),
        }
    }
}

fn record(case: &Case, states: impl Iterator<Item = [f64; 2]>) -> TimeResponse {
    let mut r = TimeResponse::with_capacity(case.samples());
    for (i, [x, z]) in states.enumerate().take(case.samples()) {
        let t = i as f64 * case.dt;
        let (phi, w, wd) = case.speed.at(t);
        r.t.push(t);
        r.x.push(x);
        r.z.push(z);
        r.phi.push(phi);
        r.phi_dot.push(w);
        r.phi_ddot.push(wd);
    }
    r
}

/// Constant speed: the scaled augmented state stepped by exp(A dt) (module docs).
pub fn exact_constant(case: &Case) -> TimeResponse {
    let Speed::Constant { omega, phi0 } = case.speed else {
        panic!("exact_constant needs a constant speed");
    };
    let r = &case.rotor;
    // scales: length l, velocity l w0, the oscillator 1
    let w0 = (r.kxx.max(r.kzz) / r.m).sqrt();
    let l = r.mud / r.m;
    let s = SVector::<f64, 6>::from([l, l, l * w0, l * w0, 1.0, 1.0]);
    let a4 = r.state_matrix(omega, 0.0);
    let mut a = SMatrix::<f64, 6, 6>::zeros();
    a.fixed_view_mut::<4, 4>(0, 0).copy_from(&a4);
    let f = r.mud * omega * omega / r.m;
    a[(2, 4)] = f; // x'' += mud w^2 sin / m
    a[(3, 5)] = f; // z'' += mud w^2 cos / m
    a[(4, 5)] = omega; // sin' = w cos
    a[(5, 4)] = -omega; // cos' = -w sin
                        // scaled: y = S ys, ys' = S^-1 A S ys
    let as_ = SMatrix::<f64, 6, 6>::from_fn(|i, j| a[(i, j)] * s[j] / s[i]);
    let phi = (as_ * case.dt).exp();
    let th = phi0 + r.alpha;
    let [x0, z0, vx0, vz0] = case.initial;
    let mut y = SVector::<f64, 6>::from([x0, z0, vx0, vz0, th.sin(), th.cos()]).component_div(&s);
    let states = std::iter::from_fn(move || {
        let out = [y[0] * s[0], y[1] * s[1]];
        y = phi * y;
        Some(out)
    });
    record(case, states)
}

/// Any speed: classical RK4 with `substeps` steps per sampling interval.
pub fn rk4(case: &Case, substeps: usize) -> TimeResponse {
    let r = case.rotor;
    let speed = case.speed;
    let deriv = move |t: f64, y: &[f64; 4]| -> [f64; 4] {
        let (phi, w, wd) = speed.at(t);
        let (sn, cs) = (phi + r.alpha).sin_cos();
        let fx = r.mud * (w * w * sn - wd * cs);
        let fz = r.mud * (wd * sn + w * w * cs);
        let [x, z, vx, vz] = *y;
        let ax =
            (fx - r.cxx * vx - (r.cxz - r.a * w) * vz - r.kxx * x - (r.kxz - r.a * wd) * z) / r.m;
        let az = (fz - (r.czx + r.a * w) * vx - r.czz * vz - r.kzx * x - r.kzz * z) / r.m;
        [vx, vz, ax, az]
    };
    let h = case.dt / substeps as f64;
    let mut y = case.initial;
    let mut n = 0usize;
    let states = std::iter::from_fn(move || {
        let out = [y[0], y[1]];
        for j in 0..substeps {
            let t = n as f64 * case.dt + j as f64 * h;
            let add = |y: &[f64; 4], k: &[f64; 4], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
            let k1 = deriv(t, &y);
            let k2 = deriv(t + 0.5 * h, &add(&y, &k1, 0.5 * h));
            let k3 = deriv(t + 0.5 * h, &add(&y, &k2, 0.5 * h));
            let k4 = deriv(t + h, &add(&y, &k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        n += 1;
        Some(out)
    });
    record(case, states)
}

/// `clean` with white noise at `snr_db` per channel from `seed` (the library's noise model,
/// docs/method.md section 2.5); returns the record and (sigma_x, sigma_z).
pub fn noisy(clean: &TimeResponse, snr_db: f64, seed: u64) -> (TimeResponse, [f64; 2]) {
    let mut r = clean.clone();
    let level = add_noise(&mut r, snr_db, seed).expect("finite SNR");
    (r, [level.sigma_x, level.sigma_z])
}

/// The Cramer-Rao bound (standard deviations) of the nine parameters `PARAMS`, the
/// initial state unknown, for white noise `sigma` = (sigma_x, sigma_z) \[m\]: F = J^T J /
/// sigma^2 per channel with J by central differences of the reference response (relative
/// step 1e-4 of the parameter, or of its row's direct coefficient for a zero cross term;
/// the initial state enters linearly and is differenced exactly; ramps with 16 RK4
/// sub-steps, plenty for a bound). With `only`, the bound for that subset of the nine (the
/// others known).
pub fn crb(case: &Case, sigma: [f64; 2], only: Option<&[usize]>) -> Vec<(usize, f64)> {
    let base = case.simulate_with(16);
    let r = case.rotor;
    let values = [r.m, r.cxx, r.cxz, r.czx, r.czz, r.kxx, r.kxz, r.kzx, r.kzz];
    let direct = [0, 1, 1, 4, 4, 5, 5, 8, 8];
    let params: Vec<usize> = only.map(|o| o.to_vec()).unwrap_or_else(|| (0..9).collect());
    let mut cols: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for &i in &params {
        let scale = if values[i] != 0.0 {
            values[i].abs()
        } else {
            values[direct[i]].abs()
        };
        let h = 1e-4 * scale;
        let sim = |d: f64| {
            Case {
                rotor: r.moved(i, d),
                ..*case
            }
            .simulate_with(16)
        };
        let (p, m) = (sim(h), sim(-h));
        let d = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(u, v)| (u - v) / (2.0 * h)).collect()
        };
        cols.push((d(&p.x, &m.x), d(&p.z, &m.z)));
    }
    for k in 0..4 {
        let mut c = *case;
        c.initial[k] += if k < 2 { 1e-7 } else { 1e-4 };
        let h = c.initial[k] - case.initial[k];
        let p = c.simulate_with(16);
        let d = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(u, v)| (u - v) / h).collect()
        };
        cols.push((d(&p.x, &base.x), d(&p.z, &base.z)));
    }
    let n = cols.len();
    // scale the columns to unit norm before inverting (the bound is invariant)
    let norms: Vec<f64> = cols
        .iter()
        .map(|(x, z)| {
            (x.iter().map(|v| v * v / (sigma[0] * sigma[0])).sum::<f64>()
                + z.iter().map(|v| v * v / (sigma[1] * sigma[1])).sum::<f64>())
            .sqrt()
        })
        .collect();
    let f = DMatrix::from_fn(n, n, |i, j| {
        let (xi, zi) = &cols[i];
        let (xj, zj) = &cols[j];
        let sx: f64 = xi.iter().zip(xj).map(|(a, b)| a * b).sum();
        let sz: f64 = zi.iter().zip(zj).map(|(a, b)| a * b).sum();
        (sx / (sigma[0] * sigma[0]) + sz / (sigma[1] * sigma[1])) / (norms[i] * norms[j])
    });
    let inv = f.try_inverse().expect("Fisher information invertible");
    params
        .iter()
        .enumerate()
        .map(|(k, &i)| (i, inv[(k, k)].sqrt() / norms[k]))
        .collect()
}

/// The names of the ten per-row values.
pub fn names() -> [&'static str; 10] {
    CROSS_NAMES
}
