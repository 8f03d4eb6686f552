//! Fast generation of the unbalance phase (sin th_n, cos th_n), th_n = phi(t_n) + alpha,
//! t_n = n dt, for the Newmark hot loop, by a rotation recurrence re-synchronised exactly
//! every [`RESYNC`] steps.
//!
//! With the phase increment d_n = phi(t_{n+1}) - phi(t_n) = dt w(t_n + dt/2) (exact for
//! the constant and linear-ramp profiles, where w is linear in t):
//!
//! ```text
//! sin th_{n+1} = sin th_n cos d_n + cos th_n sin d_n
//! cos th_{n+1} = cos th_n cos d_n - sin th_n sin d_n
//! d_{n+1} = d_n + w' dt^2            (so (sin d, cos d) follow the same rotation by w' dt^2)
//! ```
//!
//! Each rotation adds a rounding error of a few ulps, so the deviation from the true phase
//! grows with the number of steps since the last re-synchronisation. At every multiple of
//! [`RESYNC`] both (sin th, cos th) and (sin d, cos d) are recomputed directly, which bounds
//! it. Measured against the phase evaluated in double-double arithmetic (unit tests), the
//! recurrence stays within 2e-14 + 4 eps |phi| of the truth, where eps |phi| is the rounding
//! any f64 evaluation of phi(t) carries anyway (a direct `sin_cos(phi(t_n) + alpha)` is off
//! by up to ~1.5 eps |phi|). For 1 s of table1 at 1200 rpm (|phi| < 130 rad) that is
//! < 3.1e-14 measured (direct: 1.3e-14); both are far below the 1e-13 budget and
//! Newmark's own ~1e-4 error. A rotation is much cheaper than a direct `sin_cos`
//! (timings: docs/performance.md).

use crate::model::SpeedProfile;

/// Steps between exact re-synchronisations of the recurrence.
pub(crate) const RESYNC: u64 = 64;

/// (sin, cos) of the unbalance phase at successive samples.
#[derive(Debug, Clone)]
pub(crate) struct PhaseGenerator {
    speed: SpeedProfile,
    alpha: f64,
    dt: f64,
    /// Index of the sample (s, c) belong to.
    n: u64,
    /// sin th_n, cos th_n.
    s: f64,
    c: f64,
    /// sin d_n, cos d_n (the increment to th_{n+1}).
    sd: f64,
    cd: f64,
    /// sin, cos of w' dt^2 (the increment of the increment).
    sa: f64,
    ca: f64,
}

impl PhaseGenerator {
    /// Positioned at sample 0.
    pub(crate) fn new(speed: &SpeedProfile, alpha: f64, dt: f64) -> Self {
        let w_dot = speed.at(0.0).omega_dot;
        let (sa, ca) = (w_dot * dt * dt).sin_cos();
        let mut g = Self {
            speed: *speed,
            alpha,
            dt,
            n: 0,
            s: 0.0,
            c: 1.0,
            sd: 0.0,
            cd: 1.0,
            sa,
            ca,
        };
        g.resync();
        g
    }

    /// Recompute (sin th_n, cos th_n) and (sin d_n, cos d_n) directly.
    fn resync(&mut self) {
        let t = self.n as f64 * self.dt;
        (self.s, self.c) = (self.speed.at(t).phi + self.alpha).sin_cos();
        // d_n = dt w(t_n + dt/2)
        (self.sd, self.cd) = (self.dt * self.speed.at(t + 0.5 * self.dt).omega).sin_cos();
    }

    /// Advance to sample n + 1 and return (sin th_{n+1}, cos th_{n+1}).
    #[inline]
    pub(crate) fn next(&mut self) -> (f64, f64) {
        self.n += 1;
        if self.n.is_multiple_of(RESYNC) {
            self.resync();
        } else {
            let (s, c, sd, cd) = (self.s, self.c, self.sd, self.cd);
            self.s = s * cd + c * sd;
            self.c = c * cd - s * sd;
            self.sd = sd * self.ca + cd * self.sa;
            self.cd = cd * self.ca - sd * self.sa;
        }
        (self.s, self.c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// a + b exactly as (hi, lo).
    fn two_sum(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        let bb = s - a;
        (s, (a - (s - bb)) + (b - bb))
    }

    /// a * b exactly as (hi, lo).
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }

    /// (sin, cos) of phi(t) + alpha with phi evaluated in double-double arithmetic
    /// (relative error ~1e-30 in the phase), for t = i dt as the model defines it.
    fn true_sin_cos(speed: &SpeedProfile, alpha: f64, t: f64) -> (f64, f64) {
        let (phi0, w0, half_a) = match *speed {
            SpeedProfile::Constant { omega, phi0 } => (phi0, omega, 0.0),
            SpeedProfile::Ramp {
                omega0,
                accel,
                phi0,
            } => (phi0, omega0, 0.5 * accel),
        };
        // phi0 + alpha + w0 t + (a/2 t) t
        let (p1, e1) = two_prod(w0, t);
        let (q, eq) = two_prod(half_a, t);
        let (p2, e2) = two_prod(q, t);
        let lo_terms = e1 + e2 + eq * t;
        let (h1, l1) = two_sum(phi0, alpha);
        let (h2, l2) = two_sum(h1, p1);
        let (h3, l3) = two_sum(h2, p2);
        let lo = l1 + l2 + l3 + lo_terms;
        let (s, c) = h3.sin_cos();
        (s + c * lo, c - s * lo)
    }

    /// Largest deviation from the true (sin, cos) over `n` steps: (recurrence, direct
    /// `sin_cos(phi(t_n) + alpha)` in f64).
    fn max_errors(speed: SpeedProfile, alpha: f64, dt: f64, n: u64) -> (f64, f64) {
        let mut g = PhaseGenerator::new(&speed, alpha, dt);
        let (mut rec, mut direct) = (0.0f64, 0.0f64);
        for i in 1..=n {
            let t = i as f64 * dt;
            let (s, c) = g.next();
            let (s0, c0) = (speed.at(t).phi + alpha).sin_cos();
            let (st, ct) = true_sin_cos(&speed, alpha, t);
            rec = rec.max((s - st).abs()).max((c - ct).abs());
            direct = direct.max((s0 - st).abs()).max((c0 - ct).abs());
        }
        (rec, direct)
    }

    fn profiles() -> [SpeedProfile; 4] {
        [
            SpeedProfile::constant_rpm(1200.0, 0.3).unwrap(),
            SpeedProfile::constant_rpm(30000.0, 0.0).unwrap(),
            SpeedProfile::ramp(0.0, 10.0, 0.0).unwrap(),
            SpeedProfile::ramp(1200.0, -50.0, 1.0).unwrap(),
        ]
    }

    #[test]
    fn recurrence_error_is_rounding_of_phi_plus_2e_14() {
        // Any f64 evaluation of phi(t) carries ~eps |phi| of rounding (up to ~1e-12 rad
        // for 10 s at 30000 rpm); the recurrence adds at most a few ulps more. For 1 s at
        // 1200 rpm (|phi| < 130 rad) the bound is 3e-14.
        for (sp, n) in profiles()
            .into_iter()
            .flat_map(|p| [(p, 10_000), (p, 100_000)])
        {
            let phi_max = (0..=n)
                .map(|i| sp.at(i as f64 * 1e-4).phi.abs())
                .fold(0.0, f64::max);
            let (rec, direct) = max_errors(sp, 0.785, 1e-4, n);
            let bound = 2e-14 + 4.0 * f64::EPSILON * phi_max;
            assert!(
                rec < bound,
                "{sp:?}: {rec:e} >= {bound:e} (direct {direct:e})"
            );
        }
    }
}
