//! The algebraic identifier of the cross-coupled rotor (docs/method.md section
//! 3.10): per direction m and the four bearing coefficients of that row, streaming, one
//! estimate per sample, O(1) work, no allocation.
//!
//! The model (docs/method.md section 1):
//!
//! ```text
//! x:  m x'' + cxx x' + cxz z' - a w z' + kxx x + kxz z - a w' z = m_u d fx
//! z:  m z'' + czx x' + czz z' + a w x' + kzx x + kzz z          = m_u d fz
//! fx = w^2 sin(phi+alpha) - w' cos(phi+alpha),   fz = w' sin(phi+alpha) + w^2 cos(phi+alpha)
//! ```
//!
//! Multiplying by tau^2 and integrating twice (P, Q, R of [`super::identifier`],
//! docs/method.md section 3.2) turns each row into one scalar equation in five unknowns,
//! with the right-hand sides Sx, Sz of the Jeffcott identifier (the gyroscopic and
//! unbalance terms are the same):
//!
//! ```text
//! x:  m_x P[x] + cxx Q[x] + cxz Q[z] + kxx R[x] + kxz R[z] = Sx
//! z:  m_z P[z] + czx Q[x] + czz Q[z] + kzx R[x] + kzz R[z] = Sz
//!
//! P[y] = tau^2 y - 4 I1[tau y] + 2 I2[y],  Q[y] = I1[tau^2 y] - 2 I2[tau y],  R[y] = I2[tau^2 y]
//! S = I1[u] + I2[v],  ux = a tau^2 w z,  vx = -2 a tau w z + m_u d tau^2 fx,
//!                     uz = -a tau^2 w x, vz = 2 a tau w x + a tau^2 w' x + m_u d tau^2 fz
//! ```
//!
//! One equation E0: p . theta = s cannot give five unknowns; it holds at every instant,
//! so its iterated integrals I1[E0] .. I4[E0] hold too (the construction of the 3x3 system,
//! taken two integrals further, as Mendoza-Larios et al. 2021 do for bearing
//! coefficients), and together they make the 5x5 system solved at every sample:
//!
//! ```text
//! A theta = b,   row i = 0..4:   A_i = I_i[p],   b_i = I_i[s]
//! x:  p = (P[x], Q[x], Q[z], R[x], R[z]),  theta = (m_x, cxx, cxz, kxx, kxz)
//! z:  p = (P[z], Q[x], Q[z], R[x], R[z]),  theta = (m_z, czx, czz, kzx, kzz)
//!
//! I_i[P[y]] = I_i[tau^2 y] - 4 I_(i+1)[tau y] + 2 I_(i+2)[y]
//! I_i[Q[y]] = I_(i+1)[tau^2 y] - 2 I_(i+2)[tau y]
//! I_i[R[y]] = I_(i+2)[tau^2 y]
//! I_i[s]    = I_(i+1)[u] + I_(i+2)[v]
//! ```
//!
//! so every entry is a combination of I0..I6 of the ten signals the Jeffcott identifier
//! integrates, (y, tau y, tau^2 y, u, v) for y = x, z: the same cascade
//! ([`super::quadrature`]) kept to six levels instead of four. The two systems share
//! their last four columns (each row's cross terms are the other row's direct ones); each
//! is equilibrated and solved by [`super::cross_solve`] (powers-of-two scaling of rows and
//! columns, LU with partial pivoting, exact 1-norm rcond), x and z in the two lanes of one vector. The estimate
//! does not depend on the initial state and exists from the sixth sample (A(t_0) = 0).
//! The constant-speed model, tau on the nominal grid, the quadrature rules and their
//! start-up, the validation of every sample: all as the Jeffcott identifier
//! ([`AlgebraicIdentifier`](super::AlgebraicIdentifier)).
//!
//! Accuracy (docs/method.md section 3.10, tests/it/cross_algebraic.rs; exact data, dt =
//! 0.1 ms, am5, four cross-coupled rotors at 1200 rpm and on 10 rad/s^2 ramps): at
//! t = 0.1 s m and the stiffness terms within 4e-8, the direct damping within 8e-8 of
//! their values, the cross damping within 1e-5 .. 4e-5 N s/m (am5's quadrature error;
//! 1e-6 of a cross damping of 30 N s/m or more, at most 7e-8 of the direct damping). With
//! the cross terms zero in the data their estimates come out ~0 and m, c, k agree with the
//! Jeffcott identifier's. Once the free transient has decayed, a single-frequency response
//! cannot separate the five unknowns of a row: rcond falls and many instants are flagged.

use super::config::AlgebraicConfig;
use super::cross_estimate::{CrossAlgebraicEstimate, CrossDirectionEstimate};
use super::cross_solve::{solve5, N5};
use super::error::AlgebraicError;
use super::identifier::{has_avx2, signals, speed_at, validate, NS, T2Y, TY, U, V, Y};
use super::quadrature::RunningIntegrals;
use super::simd::F2;
use crate::identify::{Known, Measurement};
use crate::model::check;

/// Rows of the cascade: the signals and I1..I6.
const ROWS: usize = 7;

/// The streaming algebraic identifier of the cross-coupled rotor (module docs). Feed it
/// measurements in time order with [`push`](Self::push); each returns the estimate at
/// that instant.
#[derive(Debug, Clone)]
pub struct CrossAlgebraicIdentifier {
    known: Known,
    dt: f64,
    config: AlgebraicConfig,
    integrals: RunningIntegrals<NS, ROWS>,
    /// Samples accepted since the start (or the last reset).
    n: u64,
    /// Time of the last accepted sample \[s\].
    t_prev: f64,
    /// The CPU has AVX2: run the hot path compiled for it (same results, bit for bit).
    avx2: bool,
}

impl CrossAlgebraicIdentifier {
    /// An identifier for data sampled every `dt` \[s\] (finite, > 0), with the known
    /// quantities `known` (finite) and `config` (validated here; its `rcond_min` is the
    /// threshold of [`CrossAlgebraicEstimate::well_conditioned`] callers use, see
    /// [`DEFAULT_CROSS_ALGEBRAIC_RCOND_MIN`](super::DEFAULT_CROSS_ALGEBRAIC_RCOND_MIN)).
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
    /// Errors (the identifier is left unchanged, so the caller may skip the sample): as
    /// [`AlgebraicIdentifier::push`](super::AlgebraicIdentifier::push), a non-finite field
    /// or a time off the uniform grid.
    #[inline]
    pub fn push(&mut self, m: &Measurement) -> Result<CrossAlgebraicEstimate, AlgebraicError> {
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
    unsafe fn push_avx2(
        &mut self,
        m: &Measurement,
    ) -> Result<CrossAlgebraicEstimate, AlgebraicError> {
        self.push_portable(m)
    }

    #[inline(always)]
    fn push_portable(&mut self, m: &Measurement) -> Result<CrossAlgebraicEstimate, AlgebraicError> {
        validate(m, self.config.speed_model, self.n, self.t_prev, self.dt)?;
        let tau = (self.n as i64) as f64 * self.dt;
        let (sn, cs, w, wd) = speed_at(&self.known, self.config.speed_model, m);
        self.integrals
            .push(&signals(&self.known, tau, m.x, m.z, sn, cs, w, wd));
        self.n += 1;
        self.t_prev = m.t;
        if tau == 0.0 {
            return Ok(CrossAlgebraicEstimate {
                t: m.t,
                x: CrossDirectionEstimate::SINGULAR,
                z: CrossDirectionEstimate::SINGULAR,
            });
        }
        let (theta, rcond) = solve_both(self.integrals.levels());
        let dir = |d: usize| CrossDirectionEstimate {
            values: theta.map(|v| v[d]),
            rcond: rcond[d],
        };
        Ok(CrossAlgebraicEstimate {
            t: m.t,
            x: dir(0),
            z: dir(1),
        })
    }
}

/// Assemble the 5x5 systems of both directions from the integrals (lane 0: x, lane 1: z;
/// module docs) and solve them.
#[inline(always)]
fn solve_both(lv: &[[f64; NS]; ROWS]) -> ([[f64; 2]; N5], [f64; 2]) {
    // The (x, z) pair of signal `s` at level `k`.
    let p = |k: usize, s: usize| F2::new(lv[k][s], lv[k][s + 1]);
    let (four, two) = (F2::splat(4.0), F2::splat(2.0));
    let a: [[F2; N5]; N5] = std::array::from_fn(|i| {
        // I_i of Q[x], Q[z] and R[x], R[z]: the same in both rows' systems
        let q = |d: usize| lv[i + 1][T2Y + d] - 2.0 * lv[i + 2][TY + d];
        let r = |d: usize| lv[i + 2][T2Y + d];
        [
            p(i, T2Y) - four * p(i + 1, TY) + two * p(i + 2, Y),
            F2::splat(q(0)),
            F2::splat(q(1)),
            F2::splat(r(0)),
            F2::splat(r(1)),
        ]
    });
    let b: [F2; N5] = std::array::from_fn(|i| p(i + 1, U) + p(i + 2, V));
    let (theta, rcond) = solve5(&a, &b);
    (theta.map(F2::to_array), rcond.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::algebraic::AlgebraicIdentifier;
    use crate::model::SpeedState;

    fn measurement(t: f64) -> Measurement {
        Measurement {
            t,
            x: 1e-7 * (290.0 * t).sin() + 3e-8 * (125.0 * t).cos(),
            z: 2e-7 * (288.0 * t + 0.3).cos() - 1e-8 * (125.0 * t).sin(),
            speed: SpeedState {
                phi: 125.0 * t + 5.0 * t * t,
                omega: 125.0 + 10.0 * t,
                omega_dot: 10.0,
            },
        }
    }

    const KNOWN: Known = Known {
        a: 2.871,
        mud: 1.5e-5,
        alpha: 0.7,
    };

    #[test]
    fn simd_and_portable_paths_agree_bit_for_bit() {
        let dt = 1e-4;
        let mut fast =
            CrossAlgebraicIdentifier::new(KNOWN, dt, AlgebraicConfig::default()).unwrap();
        let mut slow = fast.clone();
        slow.avx2 = false;
        for i in 0..3000 {
            let m = measurement(i as f64 * dt);
            let (a, b) = (fast.push(&m).unwrap(), slow.push(&m).unwrap());
            assert_eq!(a.values().map(f64::to_bits), b.values().map(f64::to_bits));
            assert_eq!(a.x.rcond.to_bits(), b.x.rcond.to_bits());
            assert_eq!(a.z.rcond.to_bits(), b.z.rcond.to_bits());
        }
    }

    #[test]
    fn rejects_what_the_jeffcott_identifier_rejects_and_stays_unchanged() {
        let dt = 1e-4;
        let mut cross =
            CrossAlgebraicIdentifier::new(KNOWN, dt, AlgebraicConfig::default()).unwrap();
        let mut jeff = AlgebraicIdentifier::new(KNOWN, dt, AlgebraicConfig::default()).unwrap();
        for i in 0..10 {
            let m = measurement(i as f64 * dt);
            cross.push(&m).unwrap();
            jeff.push(&m).unwrap();
        }
        let before = cross.clone();
        let mut bad = measurement(10.0 * dt);
        bad.speed.omega = f64::NAN;
        let e = cross.push(&bad).unwrap_err().to_string();
        assert_eq!(e, jeff.push(&bad).unwrap_err().to_string());
        assert!(e.contains("phi_dot") && e.contains("sample 10"), "{e}");
        let late = measurement(10.5 * dt);
        let e = cross.push(&late).unwrap_err();
        assert_eq!(e, jeff.push(&late).unwrap_err());
        assert!(e.to_string().contains("sample 10"), "{e}");
        // unchanged: the next good sample gives what it gives without the bad ones
        let good = measurement(10.0 * dt);
        let mut fresh = before.clone();
        assert_eq!(
            cross.push(&good).unwrap().values().map(f64::to_bits),
            fresh.push(&good).unwrap().values().map(f64::to_bits)
        );
        assert_eq!(cross.samples(), 11);
        assert!(CrossAlgebraicIdentifier::new(KNOWN, 0.0, AlgebraicConfig::default()).is_err());
    }

    #[test]
    fn reset_starts_over() {
        let dt = 1e-4;
        let mut id = CrossAlgebraicIdentifier::new(KNOWN, dt, AlgebraicConfig::default()).unwrap();
        let first: Vec<_> = (0..50)
            .map(|i| id.push(&measurement(i as f64 * dt)).unwrap())
            .collect();
        id.reset();
        assert_eq!(id.samples(), 0);
        // after a reset the first time may be anything; tau restarts at 0
        let again: Vec<_> = (0..50)
            .map(|i| {
                let mut m = measurement(i as f64 * dt);
                m.t += 100.0;
                id.push(&m).unwrap()
            })
            .collect();
        for (a, b) in first.iter().zip(&again) {
            assert_eq!(a.values().map(f64::to_bits), b.values().map(f64::to_bits));
        }
        assert!(first[0].values().iter().all(|v| v.is_nan()) && first[0].x.rcond == 0.0);
    }
}
