//! An independent generator of raw proximity-probe records, the reference of the
//! conditioning tests (`acquisition_iterated`, and the `rotorid condition` tests of the
//! CLI, which include this file): none of `rotorid::simulate`, `rotorid::acquisition` or
//! `rotorid::refine` is used. Eq. (1) is integrated here by classical RK4 with 16 steps
//! per sample on the exact phi(t) of a constant speed or a linear ramp; the slow roll is
//! the closed-form steady state of eq. (1) at its constant speed, solved here as a 2x2
//! complex system; the probes see x cos(theta) + z sin(theta) plus runout at 1X-3X; the
//! keyphasor is a trapezoidal notch (linear edges, unlike the library's raised sine)
//! with per-revolution jitter; every channel is quantised to 16 bits over -24..0 V; the
//! noise comes from a xorshift generator through Box-Muller; the stamps are printed with
//! 6 decimals, as acquisition software writes them.

#![allow(dead_code)]

use std::f64::consts::TAU;

/// The paper's rotor (Table 1) with 40 times its unbalance (x, z up to ~20 um).
pub const M: f64 = 14.29;
pub const CX: f64 = 10.0;
pub const CZ: f64 = 10.0;
pub const KX: f64 = 1.195e6;
pub const KZ: f64 = 1.195e6;
pub const A: f64 = 2.871;
pub const M_U: f64 = 4.0e-3;
pub const D: f64 = 0.15;
pub const ALPHA_DEG: f64 = 45.0;
/// 25.6 kHz, 1 s.
pub const RATE_HZ: f64 = 25_600.0;
pub const SAMPLES: usize = 25_600;
/// A probe: angle [deg], sensitivity [V/m], gap voltage [V], runout 1X-3X (um, deg).
pub type Probe = (f64, f64, f64, [(f64, f64); 3]);
/// The two probes.
pub const PROBES: [Probe; 2] = [
    (
        135.0,
        7874.0,
        -9.0,
        [(2.0, 30.0), (1.0, 100.0), (0.5, 200.0)],
    ),
    (
        45.0,
        7874.0,
        -10.5,
        [(1.5, -60.0), (0.8, 10.0), (0.4, 135.0)],
    ),
];
/// Slow roll: 100 rpm for 2 s.
pub const SLOW_RPM: f64 = 100.0;
pub const SLOW_SECONDS: f64 = 2.0;

/// How the rotor turns: phi(t) = phi0 + w0 t + accel t^2 / 2.
#[derive(Debug, Clone, Copy)]
pub struct Turning {
    /// w at t = 0 [rad/s].
    pub w0: f64,
    /// w' [rad/s^2].
    pub accel: f64,
    /// phi at t = 0 [rad].
    pub phi0: f64,
}

impl Turning {
    pub fn rpm(rpm: f64) -> Self {
        Self {
            w0: rpm * TAU / 60.0,
            accel: 0.0,
            phi0: 0.0,
        }
    }
    pub fn ramp(rpm0: f64, accel: f64) -> Self {
        Self {
            w0: rpm0 * TAU / 60.0,
            accel,
            phi0: 0.0,
        }
    }
    pub fn phi(&self, t: f64) -> f64 {
        self.phi0 + self.w0 * t + 0.5 * self.accel * t * t
    }
    pub fn w(&self, t: f64) -> f64 {
        self.w0 + self.accel * t
    }
}

/// A raw record and what it was made from.
#[derive(Debug, Clone)]
pub struct Raw {
    /// Stamps as printed (6 decimals) [s].
    pub t: Vec<f64>,
    /// Probe 1 (135 deg), probe 2 (45 deg), keyphasor [V].
    pub volts: [Vec<f64>; 3],
    /// The exact x, z [m] (noise-free).
    pub x: Vec<f64>,
    pub z: Vec<f64>,
    /// x, z with the noise the probes carry ("perfectly conditioned channels").
    pub x_noisy: Vec<f64>,
    pub z_noisy: Vec<f64>,
    /// The exact phi [rad], w [rad/s], w' [rad/s^2].
    pub phi: Vec<f64>,
    pub w: Vec<f64>,
    pub w_dot: Vec<f64>,
    /// The noise standard deviations on x, z [m].
    pub sigma: [f64; 2],
}

/// xorshift64* and Box-Muller.
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    }
}

/// Eq. (1) as a first-order system in (x, z, vx, vz) at time t.
fn rhs(turn: &Turning, t: f64, y: [f64; 4]) -> [f64; 4] {
    let (phi, w, wd) = (turn.phi(t), turn.w(t), turn.accel);
    let mud = M_U * D;
    let s = (phi + ALPHA_DEG.to_radians()).sin();
    let c = (phi + ALPHA_DEG.to_radians()).cos();
    let fx = mud * (w * w * s - wd * c);
    let fz = mud * (wd * s + w * w * c);
    let [x, z, vx, vz] = y;
    // M q'' = F - C(w) q' - K(w') q, C = diag(cx, cz) + w [[0, -a], [a, 0]],
    // K = diag(kx, kz) + w' [[0, -a], [0, 0]]
    let ax = (fx - (CX * vx - A * w * vz) - (KX * x - A * wd * z)) / M;
    let az = (fz - (CZ * vz + A * w * vx) - KZ * z) / M;
    [vx, vz, ax, az]
}

/// x, z at t_i = i / RATE_HZ from the state `y0` (x, z, vx, vz) at t = 0, RK4 with
/// `SUB` steps per sample.
pub fn integrate(turn: &Turning, n: usize, y0: [f64; 4]) -> (Vec<f64>, Vec<f64>) {
    const SUB: usize = 16;
    let h = 1.0 / RATE_HZ / SUB as f64;
    let mut y = y0;
    let (mut xs, mut zs) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        xs.push(y[0]);
        zs.push(y[1]);
        for j in 0..SUB {
            let t = (i * SUB + j) as f64 * h;
            let add = |a: [f64; 4], k: [f64; 4], f: f64| std::array::from_fn(|q| a[q] + f * k[q]);
            let k1 = rhs(turn, t, y);
            let k2 = rhs(turn, t + h / 2.0, add(y, k1, h / 2.0));
            let k3 = rhs(turn, t + h / 2.0, add(y, k2, h / 2.0));
            let k4 = rhs(turn, t + h, add(y, k3, h));
            y = std::array::from_fn(|q| {
                y[q] + h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])
            });
        }
    }
    (xs, zs)
}

/// The steady 1X response at constant speed w [rad/s]: x(t), z(t) = Re(X e^(i phi(t))),
/// Re(Z e^(i phi(t))) with (-w^2 M + i w C(w) + K) (X, Z) = m_u d w^2 e^(i alpha) (-i, 1).
pub fn steady(w: f64) -> [(f64, f64); 2] {
    type C = (f64, f64);
    let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let sub = |a: C, b: C| (a.0 - b.0, a.1 - b.1);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    // dynamic stiffness [[d11, d12], [d21, d22]]
    let d11 = (KX - w * w * M, w * CX);
    let d12 = (0.0, -w * A * w);
    let d21 = (0.0, w * A * w);
    let d22 = (KZ - w * w * M, w * CZ);
    let f = M_U * D * w * w;
    let al = ALPHA_DEG.to_radians();
    let e = (al.cos(), al.sin());
    let fx = mul((0.0, -f), e);
    let fz = mul((f, 0.0), e);
    let det = sub(mul(d11, d22), mul(d12, d21));
    let x = div(sub(mul(fx, d22), mul(d12, fz)), det);
    let z = div(sub(mul(d11, fz), mul(d21, fx)), det);
    [x, z]
}

/// RMS of `v`.
pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
}

/// The probe and keyphasor volts of a record with displacements `x`, `z` and shaft angle
/// `phi`, speed `w`; one jitter draw per revolution.
fn volts(x: &[f64], z: &[f64], phi: &[f64], w: &[f64], noise: &mut Noise) -> [Vec<f64>; 3] {
    let quantise = |v: f64| {
        let q = 24.0 / 65536.0;
        -24.0 + ((v + 24.0) / q).round().clamp(0.0, 65535.0) * q
    };
    let n = x.len();
    let mut out: [Vec<f64>; 3] = Default::default();
    for (k, (angle, s, gap, runout)) in PROBES.iter().enumerate() {
        let (c, sn) = (angle.to_radians().cos(), angle.to_radians().sin());
        out[k] = (0..n)
            .map(|i| {
                let r: f64 = runout
                    .iter()
                    .enumerate()
                    .map(|(h, (um, deg))| {
                        um * 1e-6 * ((h + 1) as f64 * phi[i] + deg.to_radians()).cos()
                    })
                    .sum();
                quantise(gap + s * (x[i] * c + z[i] * sn + r))
            })
            .collect();
    }
    // a notch 10 deg wide with 2 deg linear edges, -8 V baseline, 6 V deep; the falling
    // edge crosses mid-level where phi + w j = 0 (mod 2 pi), j ~ 1 us per revolution
    let (width, edge) = (10f64.to_radians(), 2f64.to_radians());
    let mut jitter = std::collections::HashMap::new();
    out[2] = (0..n)
        .map(|i| {
            let rev = (phi[i] / TAU + 0.5).floor() as i64;
            let j = *jitter.entry(rev).or_insert_with(|| 1e-6 * noise.normal());
            let u = phi[i] - TAU * rev as f64 + w[i] * j;
            let lead = (u / edge + 0.5).clamp(0.0, 1.0);
            let trail = ((width - u) / edge + 0.5).clamp(0.0, 1.0);
            quantise(-8.0 - 6.0 * lead.min(trail) + 0.005 * noise.normal())
        })
        .collect();
    out
}

/// The stamp of sample i as acquisition software prints it: 6 decimals.
pub fn stamp(i: usize, rate: f64) -> f64 {
    (i as f64 / rate * 1e6).round() / 1e6
}

/// A running record of `turn` from rest, 40 dB on x and z (sigma = RMS 10^(-2) per
/// channel), seed `seed`.
pub fn running(turn: &Turning, seed: u64) -> Raw {
    let n = SAMPLES;
    let t_exact: Vec<f64> = (0..n).map(|i| i as f64 / RATE_HZ).collect();
    let (x, z) = integrate(turn, n, [0.0; 4]);
    let sigma = [rms(&x) * 1e-2, rms(&z) * 1e-2];
    let mut noise = Noise(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0xD1B5_4A32_D192_ED03));
    let x_noisy: Vec<f64> = x.iter().map(|v| v + sigma[0] * noise.normal()).collect();
    let z_noisy: Vec<f64> = z.iter().map(|v| v + sigma[1] * noise.normal()).collect();
    let phi: Vec<f64> = t_exact.iter().map(|&t| turn.phi(t)).collect();
    let w: Vec<f64> = t_exact.iter().map(|&t| turn.w(t)).collect();
    let volts = volts(&x_noisy, &z_noisy, &phi, &w, &mut noise);
    Raw {
        t: (0..n).map(|i| stamp(i, RATE_HZ)).collect(),
        volts,
        x,
        z,
        x_noisy,
        z_noisy,
        phi,
        w_dot: vec![turn.accel; n],
        w,
        sigma,
    }
}

/// The slow-roll record: the rotor's own steady response at `SLOW_RPM` (the running
/// record's noise levels `sigma`), 2 s, phi(0) = 0.3 rad.
pub fn slow_roll(sigma: [f64; 2], seed: u64) -> Raw {
    let n = (SLOW_SECONDS * RATE_HZ) as usize;
    let turn = Turning {
        phi0: 0.3,
        ..Turning::rpm(SLOW_RPM)
    };
    let [xh, zh] = steady(turn.w0);
    let re = |c: (f64, f64), phi: f64| c.0 * phi.cos() - c.1 * phi.sin();
    let phi: Vec<f64> = (0..n).map(|i| turn.phi(i as f64 / RATE_HZ)).collect();
    let x: Vec<f64> = phi.iter().map(|&p| re(xh, p)).collect();
    let z: Vec<f64> = phi.iter().map(|&p| re(zh, p)).collect();
    let mut noise = Noise(0x5EED_5EED_0000_0001 ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let x_noisy: Vec<f64> = x.iter().map(|v| v + sigma[0] * noise.normal()).collect();
    let z_noisy: Vec<f64> = z.iter().map(|v| v + sigma[1] * noise.normal()).collect();
    let w = vec![turn.w0; n];
    let volts = volts(&x_noisy, &z_noisy, &phi, &w, &mut noise);
    Raw {
        t: (0..n).map(|i| stamp(i, RATE_HZ)).collect(),
        volts,
        x,
        z,
        x_noisy,
        z_noisy,
        phi,
        w,
        w_dot: vec![0.0; n],
        sigma,
    }
}

/// The steady 1X amplitude of x at `rpm` [m] (for the tests' sanity checks).
pub fn steady_amplitude_x(rpm: f64) -> f64 {
    let [x, _] = steady(rpm * TAU / 60.0);
    x.0.hypot(x.1)
}

/// The record as CSV text: `t,probe_L,probe_R,kp`, t with 6 decimals, volts with 7.
pub fn csv(r: &Raw) -> String {
    let mut s = String::from("t,probe_L,probe_R,kp\n");
    for i in 0..r.t.len() {
        s.push_str(&format!(
            "{:.6},{:.7},{:.7},{:.7}\n",
            r.t[i], r.volts[0][i], r.volts[1][i], r.volts[2][i]
        ));
    }
    s
}

/// The scenario TOML of the rig: the rotor, the acquisition (probes `probe_L` at 135 deg
/// and `probe_R` at 45 deg, keyphasor `kp`, falling edge at phi = 0, slow roll
/// `slow_roll`), and `[speed]` when `speed` is given (its TOML lines).
pub fn scenario_toml(slow_roll: &str, speed: Option<&str>) -> String {
    let mut s = format!(
        "[rotor]\nm = {M:?}\ncx = {CX:?}\ncz = {CZ:?}\nkx = {KX:?}\nkz = {KZ:?}\na = {A:?}\n\
         m_u = {M_U:?}\nd = {D:?}\nalpha_deg = {ALPHA_DEG:?}\n\n"
    );
    if let Some(sp) = speed {
        s.push_str("[speed]\n");
        s.push_str(sp);
        s.push_str("\n\n");
    }
    s.push_str(&format!(
        "[acquisition]\ntime = \"t\"\n\n[[acquisition.probe]]\ncolumn = \"probe_L\"\n\
         angle_deg = 135.0\nsensitivity = 7874.0\n\n[[acquisition.probe]]\ncolumn = \"probe_R\"\n\
         angle_deg = 45.0\nsensitivity = 7874.0\n\n[acquisition.keyphasor]\ncolumn = \"kp\"\n\
         edge = \"falling\"\nthreshold = \"auto\"\nangle_deg = 0.0\n\n[acquisition.runout]\n\
         slow_roll = \"{slow_roll}\"\n"
    ));
    s
}
