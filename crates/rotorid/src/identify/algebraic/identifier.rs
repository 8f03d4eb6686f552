//! The algebraic identifier of m, c, k per direction (paper eqs. 7-8, docs/method.md
//! sections 3.1-3.4), streaming: one estimate per sample, O(1) work, no allocation.
//!
//! With tau = t - t_0 (t_0 the identifier's first sample) and the iterated integrals
//! In from t_0 ([`super::quadrature`]):
//!
//! ```text
//! P[y] = tau^2 y - 4 I1[tau y] + 2 I2[y]          (= I2[tau^2 y''])
//! Q[y] = I1[tau^2 y] - 2 I2[tau y]                (= I2[tau^2 y'])
//! R[y] = I2[tau^2 y]
//!
//! x:  m P[x] + cx Q[x] + kx R[x] = Sx
//!     Sx =  a (I1[tau^2 w z] - 2 I2[tau w z])
//!         + mud I2[tau^2 (w^2 sin(phi+alpha) - w' cos(phi+alpha))]
//! z:  m P[z] + cz Q[z] + kz R[z] = Sz
//!     Sz = -a (I1[tau^2 w x] - 2 I2[tau w x] - I2[tau^2 w' x])
//!         + mud I2[tau^2 (w' sin(phi+alpha) + w^2 cos(phi+alpha))]
//!
//! E0: p . theta = s,  p = (P, Q, R);   A = [p; I1[p]; I2[p]],  b = [s; I1[s]; I2[s]]
//! ```
//!
//! and A theta = b is solved per direction ([`super::system`]). The right-hand sides are
//! written `S = I1[u] + I2[v]` with, for x and z,
//!
//! ```text
//! ux =  a tau^2 w z,   vx = -2 a tau w z + mud tau^2 fx,   fx = w^2 sin - w' cos
//! uz = -a tau^2 w x,   vz =  2 a tau w x + a tau^2 w' x + mud tau^2 fz,   fz = w' sin + w^2 cos
//! ```
//!
//! so that every entry of A and b is a combination of I1..I4 of ten signals,
//! (y, tau y, tau^2 y, u, v) for y = x and y = z, all updated by one cascade:
//!
//! ```text
//! A = [ tau^2 y - 4 I1[tau y] + 2 I2[y]   I1[tau^2 y] - 2 I2[tau y]   I2[tau^2 y] ]
//!     [ I1[tau^2 y] - 4 I2[tau y] + 2 I3[y]   I2[tau^2 y] - 2 I3[tau y]   I3[tau^2 y] ]
//!     [ I2[tau^2 y] - 4 I3[tau y] + 2 I4[y]   I3[tau^2 y] - 2 I4[tau y]   I4[tau^2 y] ]
//! b = [ I1[u] + I2[v];  I2[u] + I3[v];  I3[u] + I4[v] ]
//! ```
//!
//! The constant-speed identifier (docs/method.md section 3.3, constant speed) is the same
//! engine with w = W, w' = 0 and phi = phi0 + W t ([`SpeedModel::Constant`]); with w' = 0
//! the w' terms vanish and the formulas reduce to `Sx = a W (I1[tau^2 z] - 2 I2[tau z]) +
//! mud W^2 I2[tau^2 sin(W t + phi0 + alpha)]`, etc.
//!
//! tau is taken on the nominal grid, tau_n = n dt: the measured times are only checked to be
//! uniform (so an absolute time base such as a Unix time does not cost precision).
//!
//! Accuracy (tests/identify_accuracy.rs; table1, exact data, dt = 0.1 ms, default order-5
//! quadrature): relative error at t = 0.1 s ~1e-9 (m), ~1e-10 (k), ~1e-7 (c), with or
//! without initial displacement and velocity; every well-conditioned estimate within
//! 6e-4 from t = 20 ms on. On x86_64 the hot path is compiled for AVX2 when the CPU has
//! it, with bit-for-bit the same results (timings: docs/performance.md).

use super::config::{AlgebraicConfig, SpeedModel};
use super::error::AlgebraicError;
use super::estimate::{AlgebraicEstimate, DirectionEstimate};
use super::quadrature::RunningIntegrals;
use super::scaled_solve::{recip_pow2, solve3};
use super::simd::F2;
use crate::identify::sampling::check_on_time;
use crate::identify::trig::sin_cos;
use crate::identify::InputError;
use crate::identify::{Known, Measurement};
use crate::model::check;

/// Number of integrated signals: (y, tau y, tau^2 y, u, v) for y = x, z, interleaved
/// (x then z for each) so that the two directions sit in adjacent lanes, and two zeros
/// (padding to a multiple of the 4 SIMD lanes of the cascade).
pub(super) const NS: usize = 12;
/// Offsets of each pair (x at the offset, z right after).
pub(super) const Y: usize = 0;
pub(super) const TY: usize = 2;
pub(super) const T2Y: usize = 4;
pub(super) const U: usize = 6;
pub(super) const V: usize = 8;

/// The streaming algebraic identifier (module docs). Feed it measurements in time order
/// with [`push`](Self::push); each returns the estimate at that instant.
#[derive(Debug, Clone)]
pub struct AlgebraicIdentifier {
    known: Known,
    dt: f64,
    config: AlgebraicConfig,
    integrals: RunningIntegrals<NS>,
    /// Samples accepted since the start (or the last reset).
    n: u64,
    /// Time of the last accepted sample \[s\].
    t_prev: f64,
    /// The CPU has AVX2: run the hot path compiled for it (same results, bit for bit:
    /// no FMA contraction, only wider vectors).
    avx2: bool,
}

impl AlgebraicIdentifier {
    /// An identifier for data sampled every `dt` \[s\] (finite, > 0), with the known
    /// quantities `known` (finite) and `config` (validated here).
    pub fn new(known: Known, dt: f64, config: AlgebraicConfig) -> Result<Self, AlgebraicError> {
        let known = known.validated()?;
        let dt = check("dt", dt, "finite and > 0 (s)", |v| v > 0.0)?;
        let config = config.validated()?;
        Ok(Self {
            known,
            dt,
            config,
            integrals: RunningIntegrals::new(config.quadrature, dt)?,
            n: 0,
            t_prev: f64::NAN,
            avx2: has_avx2(),
        })
    }

    /// The known quantities.
    pub fn known(&self) -> Known {
        self.known
    }

    /// The nominal sampling period \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The configuration.
    pub fn config(&self) -> AlgebraicConfig {
        self.config
    }

    /// Number of samples accepted since the start or the last [`reset`](Self::reset).
    pub fn samples(&self) -> u64 {
        self.n
    }

    /// Restart: the next measurement becomes t_0 (its time may be anything).
    pub fn reset(&mut self) {
        self.integrals.reset();
        self.n = 0;
        self.t_prev = f64::NAN;
    }

    /// Take the next measurement and return the estimate at its time. The first sample
    /// (tau = 0) and any instant where A is singular give NaN values with rcond = 0.
    ///
    /// Errors (the identifier is left unchanged, so the caller may skip the sample):
    /// a non-finite field ([`InputError::NotFinite`], naming it; the speed fields are
    /// only checked by the general speed model), or a time that is not the previous one
    /// plus dt within `1e-6 dt + 8 ulp(t)` ([`InputError::NonUniformSampling`]).
    #[inline]
    pub fn push(&mut self, m: &Measurement) -> Result<AlgebraicEstimate, AlgebraicError> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only when the running CPU supports AVX2.
            return unsafe { self.push_avx2(m) };
        }
        self.push_portable(m)
    }

    /// [`push`](Self::push) compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn push_avx2(&mut self, m: &Measurement) -> Result<AlgebraicEstimate, AlgebraicError> {
        self.push_portable(m)
    }

    #[inline(always)]
    fn push_portable(&mut self, m: &Measurement) -> Result<AlgebraicEstimate, AlgebraicError> {
        self.validate(m)?;
        let tau = (self.n as i64) as f64 * self.dt; // (i64 -> f64 is one instruction)
        let (sn, cs, w, wd) = speed_at(&self.known, self.config.speed_model, m);
        self.integrals
            .push(&signals(&self.known, tau, m.x, m.z, sn, cs, w, wd));
        self.n += 1;
        self.t_prev = m.t;
        if tau == 0.0 {
            // A = 0 at t_0
            return Ok(AlgebraicEstimate {
                t: m.t,
                x: DirectionEstimate::SINGULAR,
                z: DirectionEstimate::SINGULAR,
            });
        }
        let (theta, rcond) = solve_both(self.integrals.levels(), recip_pow2(tau));
        let dir = |d: usize| DirectionEstimate {
            m: theta[0][d],
            c: theta[1][d],
            k: theta[2][d],
            rcond: rcond[d],
        };
        Ok(AlgebraicEstimate {
            t: m.t,
            x: dir(0),
            z: dir(1),
        })
    }

    #[inline(always)]
    fn validate(&self, m: &Measurement) -> Result<(), AlgebraicError> {
        validate(m, self.config.speed_model, self.n, self.t_prev, self.dt)
    }
}

/// Check measurement `m`, the `n`-th since the start (the previous one at `t_prev` \[s\]),
/// for the identifier of period `dt` \[s\] and speed model `model`: every field it uses
/// finite, and on the uniform grid ([`AlgebraicIdentifier::push`] states the errors).
#[inline(always)]
pub(super) fn validate(
    m: &Measurement,
    model: SpeedModel,
    n: u64,
    t_prev: f64,
    dt: f64,
) -> Result<(), AlgebraicError> {
    let general = model == SpeedModel::General;
    // v * 0 == 0 exactly when v is finite: one test for all fields.
    let s = &m.speed;
    let speed_zero = if general {
        s.phi * 0.0 + s.omega * 0.0 + s.omega_dot * 0.0
    } else {
        0.0
    };
    if m.t * 0.0 + m.x * 0.0 + m.z * 0.0 + speed_zero != 0.0 {
        return Err(not_finite(m, general, n));
    }
    if n > 0 {
        check_on_time(n, m.t, t_prev, dt)?;
    }
    Ok(())
}

/// The error naming the first non-finite field of `m`, sample `index`.
#[cold]
fn not_finite(m: &Measurement, general: bool, index: u64) -> AlgebraicError {
    let s = &m.speed;
    let fields = [
        ("t", m.t, true),
        ("x", m.x, true),
        ("z", m.z, true),
        ("phi", s.phi, general),
        ("phi_dot", s.omega, general),
        ("phi_ddot", s.omega_dot, general),
    ];
    let (field, value, _) = fields
        .into_iter()
        .find(|&(_, v, checked)| checked && !v.is_finite())
        .unwrap_or(("t", m.t, true));
    AlgebraicError::Input(InputError::NotFinite {
        index,
        field,
        value,
    })
}

/// (sin(phi + alpha), cos(phi + alpha), w, w') for the measurement `m`.
#[inline(always)]
pub(super) fn speed_at(known: &Known, model: SpeedModel, m: &Measurement) -> (f64, f64, f64, f64) {
    match model {
        SpeedModel::General => {
            let (sn, cs) = sin_cos(m.speed.phi + known.alpha);
            (sn, cs, m.speed.omega, m.speed.omega_dot)
        }
        SpeedModel::Constant { omega, phi0 } => {
            let (sn, cs) = sin_cos((phi0 + omega * m.t) + known.alpha);
            (sn, cs, omega, 0.0)
        }
    }
}

/// True when the CPU supports AVX2 (x86_64 only).
pub(super) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The ten integrated signals at one sample (module docs), x and z interleaved, and the
/// two padding zeros.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn signals(
    k: &Known,
    tau: f64,
    x: f64,
    z: f64,
    sn: f64,
    cs: f64,
    w: f64,
    wd: f64,
) -> [f64; NS] {
    let t2 = tau * tau;
    let w2 = w * w;
    let fx = w2 * sn - wd * cs;
    let fz = wd * sn + w2 * cs;
    let (a, mud) = (k.a, k.mud);
    [
        x,
        z,
        tau * x,
        tau * z,
        t2 * x,
        t2 * z,
        a * t2 * w * z,
        -a * t2 * w * x,
        -2.0 * a * tau * w * z + mud * t2 * fx,
        2.0 * a * tau * w * x + a * t2 * wd * x + mud * t2 * fz,
        0.0,
        0.0,
    ]
}

/// Assemble A, b of both directions from the integrals (lane 0: x, lane 1: z) and solve
/// (`tau_scale` = 2^-e with 2^e <= tau < 2^(e+1)).
#[inline(always)]
fn solve_both(lv: &[[f64; NS]; 5], tau_scale: f64) -> ([[f64; 2]; 3], [f64; 2]) {
    // The (x, z) pair of signal `s` at level `k`.
    let p = |k: usize, s: usize| F2::new(lv[k][s], lv[k][s + 1]);
    let (four, two) = (F2::splat(4.0), F2::splat(2.0));
    // row i = I_i of (P, Q, R) = (tau^2 y - 4 I1[tau y] + 2 I2[y], I1[tau^2 y] -
    // 2 I2[tau y], I2[tau^2 y]); b_i = I_i of s = I1[u] + I2[v]
    let a: [[F2; 3]; 3] = std::array::from_fn(|i| {
        [
            p(i, T2Y) - four * p(i + 1, TY) + two * p(i + 2, Y),
            p(i + 1, T2Y) - two * p(i + 2, TY),
            p(i + 2, T2Y),
        ]
    });
    let b: [F2; 3] = std::array::from_fn(|i| p(i + 1, U) + p(i + 2, V));
    let (theta, rcond) = solve3(&a, &b, tau_scale);
    (theta.map(F2::to_array), rcond.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::SpeedState;

    #[test]
    fn simd_and_portable_paths_agree_bit_for_bit() {
        let known = Known {
            a: 2.871,
            mud: 1.5e-5,
            alpha: 0.7,
        };
        let dt = 1e-4;
        let mut fast = AlgebraicIdentifier::new(known, dt, AlgebraicConfig::default()).unwrap();
        let mut slow = fast.clone();
        slow.avx2 = false;
        for i in 0..3000 {
            let t = i as f64 * dt;
            let m = Measurement {
                t,
                x: 1e-7 * (290.0 * t).sin() + 3e-8 * (125.0 * t).cos(),
                z: 2e-7 * (288.0 * t + 0.3).cos() - 1e-8 * (125.0 * t).sin(),
                speed: SpeedState {
                    phi: 125.0 * t + 5.0 * t * t,
                    omega: 125.0 + 10.0 * t,
                    omega_dot: 10.0,
                },
            };
            let (a, b) = (fast.push(&m).unwrap(), slow.push(&m).unwrap());
            assert_eq!(a.values().map(f64::to_bits), b.values().map(f64::to_bits));
            assert_eq!(a.x.rcond.to_bits(), b.x.rcond.to_bits());
            assert_eq!(a.z.rcond.to_bits(), b.z.rcond.to_bits());
        }
    }
}
