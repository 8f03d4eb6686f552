//! Modes of the rotor at a constant speed W (w' = 0): free vibration of eq. (1),
//!
//! ```text
//! M q'' + (C1 + W C2) q' + K1 q = 0,     q = u e^{lambda t}:   Q(lambda) u = 0
//! Q(lambda) = lambda^2 M + lambda (C1 + W C2) + K1
//! det Q(lambda) = (m lambda^2 + cx lambda + kx)(m lambda^2 + cz lambda + kz)
//!                - ((cxz - a W) lambda + kxz)((czx + a W) lambda + kzx)
//! ```
//!
//! with C1 = \[\[cx, cxz\], \[czx, cz\]\], C2 = \[\[0, -a\], \[a, 0\]\],
//! K1 = \[\[kx, kxz\], \[kzx, kz\]\] (the cross-coupled bearings of docs/method.md section
//! 1.6; the cross terms are 0 for the Jeffcott rotor, whose determinant is then
//! (m l^2 + cx l + kx)(m l^2 + cz l + kz) + a^2 W^2 l^2). The four roots are the eigenvalues
//! of the state matrix (nalgebra's real Schur form)
//!
//! ```text
//! A = [[0, s I], [-K1 / (m s), -(C1 + W C2) / m]],   state (q, q' / s),   s = sqrt(max(kx, kz) / m)
//! ```
//!
//! (the scaling s gives both blocks the size of the natural frequency, which keeps the
//! eigenvalues accurate to rounding), each polished by Newton steps on det Q. Of each
//! conjugate pair the root with Im lambda >= 0 describes the mode; per mode
//!
//! ```text
//! damped natural frequency  w_d = Im lambda          natural frequency  |lambda|
//! damping ratio             zeta = -Re lambda / |lambda|
//! logarithmic decrement     delta = ln(x_n / x_n+1) = -2 pi Re lambda / Im lambda = 2 pi zeta / sqrt(1 - zeta^2)
//! ```
//!
//! Whirl. The mode shape u = (X, Z) (the null vector of Q(lambda)) traces the orbit
//! x = Re(X e^{i w t}), z = Re(Z e^{i w t}), whose mean of x z' - z x' is w Im(X conj Z).
//! The shaft turns from +z toward +x: the sense in which the unbalance force of eq. (1)
//! turns (along +z at phi + alpha = 0, along +x a quarter turn later). Hence the whirl ratio
//!
//! ```text
//! kappa = -2 Im(X conj Z) / (|X|^2 + |Z|^2)   in [-1, 1]
//! ```
//!
//! is +1 for a circle in the direction of rotation (forward), -1 against it (backward)
//! and 0 for a straight line. For the isotropic undamped rotor (kx = kz = k, c = 0) the
//! modes are circles and the frequencies solve
//!
//! ```text
//! m w^2 - a W w - k = 0   (forward),      m w^2 + a W w - k = 0   (backward)
//! ```
//!
//! so for a > 0 the forward frequency rises with speed and the backward one falls. On
//! cross-coupled bearings with kzx = -kxz = Q (isotropic otherwise, c the damping) the
//! forward mode solves m l^2 + c l + k = i (a W l + Q): kzx > 0 > kxz takes damping from
//! forward whirl (stability module).
//! References: M. Lalanne & G. Ferraris, *Rotordynamics prediction in engineering*, 2nd
//! ed., Wiley, 1998, ch. 2 (Campbell diagram of the simple rotor); G. Genta, *Dynamics of
//! rotating systems*, Springer, 2005, ch. 4 (whirl direction from the mode shape).

use nalgebra::{Complex, Matrix2, Matrix4, RowVector2, Vector2};
use serde::Serialize;

use crate::model::RotorParams;

use super::error::{check_params, check_speed, check_speeds, AnalysisError};

pub(crate) type C64 = Complex<f64>;

/// |kappa| at or below this is a straight-line orbit: its sign is rounding (the
/// eigenvectors are accurate to ~1e-12 relative), so the whirl is neither direction.
pub const PLANAR_WHIRL: f64 = 1e-6;

/// A 2x2 matrix polynomial is taken as zero (a double eigenvalue with two independent
/// mode shapes: no defined whirl) when its entries are below this fraction of the size
/// of its terms.
const RANK_ZERO: f64 = 1e-10;

/// The direction of a mode's whirl relative to the shaft's rotation (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Whirl {
    /// In the direction of rotation (whirl ratio > 0).
    Forward,
    /// Against the direction of rotation (whirl ratio < 0).
    Backward,
}

impl Whirl {
    /// `forward` or `backward`.
    pub fn name(self) -> &'static str {
        match self {
            Whirl::Forward => "forward",
            Whirl::Backward => "backward",
        }
    }
}

/// One mode at one speed (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// The eigenvalue lambda \[1/s\], Im lambda >= 0.
    pub eigenvalue: C64,
    /// Damped natural frequency w_d = Im lambda \[rad/s\].
    pub frequency: f64,
    /// Natural frequency |lambda| \[rad/s\].
    pub natural_frequency: f64,
    /// Damping ratio zeta = -Re lambda / |lambda| (dimensionless; negative: unstable).
    pub damping_ratio: f64,
    /// Logarithmic decrement -2 pi Re lambda / Im lambda (dimensionless); `None` when the
    /// mode does not oscillate (Im lambda = 0: overdamped).
    pub log_dec: Option<f64>,
    /// Whirl ratio kappa in \[-1, 1\] (+1 forward circle, -1 backward circle, 0 line);
    /// `None` when the mode shape is undefined (a double eigenvalue, e.g. an isotropic
    /// rotor at rest, whose two modes share a frequency and any orbit shape).
    pub whirl_ratio: Option<f64>,
    /// Forward or backward from the sign of the whirl ratio; `None` for a straight-line
    /// orbit (|kappa| <= [`PLANAR_WHIRL`]) or an undefined mode shape.
    pub whirl: Option<Whirl>,
}

impl Mode {
    /// The mode of the eigenvalue `l` (Im l >= 0) whose orbit has the whirl ratio
    /// `whirl_ratio` (`None`: undefined mode shape): damped natural frequency Im l,
    /// damping ratio -Re l / |l|, logarithmic decrement -2 pi Re l / Im l, the whirl from
    /// the ratio's sign (module doc). Shared by the 2-DOF and finite-element analyses.
    pub(crate) fn of(l: C64, whirl_ratio: Option<f64>) -> Self {
        let n = l.norm();
        let whirl = whirl_ratio.and_then(|k| {
            if k > PLANAR_WHIRL {
                Some(Whirl::Forward)
            } else if k < -PLANAR_WHIRL {
                Some(Whirl::Backward)
            } else {
                None
            }
        });
        Mode {
            eigenvalue: l,
            frequency: l.im,
            natural_frequency: n,
            damping_ratio: if n > 0.0 { -l.re / n } else { 0.0 },
            log_dec: (l.im > 0.0).then(|| -std::f64::consts::TAU * l.re / l.im),
            whirl_ratio,
            whirl,
        }
    }

    /// Damped natural frequency \[Hz\].
    pub fn frequency_hz(&self) -> f64 {
        self.frequency / std::f64::consts::TAU
    }
}

/// Q(lambda) of the module doc at one speed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Quadratic {
    pub m: f64,
    pub cx: f64,
    pub cz: f64,
    pub kx: f64,
    pub kz: f64,
    pub a: f64,
    /// Cross-coupled bearing coefficients (0 for a Jeffcott rotor).
    pub cxz: f64,
    pub czx: f64,
    pub kxz: f64,
    pub kzx: f64,
    /// Speed W \[rad/s\].
    pub w: f64,
}

impl Quadratic {
    pub(crate) fn new(p: &RotorParams, w: f64) -> Self {
        let x = p.cross();
        Self {
            m: p.m,
            cx: p.cx,
            cz: p.cz,
            kx: p.kx,
            kz: p.kz,
            a: p.a,
            cxz: x.cxz,
            czx: x.czx,
            kxz: x.kxz,
            kzx: x.kzx,
            w,
        }
    }

    /// Q(lambda).
    pub(crate) fn at(&self, l: C64) -> Matrix2<C64> {
        let l2 = l * l;
        let aw = self.a * self.w;
        Matrix2::new(
            l2 * self.m + l * self.cx + self.kx,
            l * (self.cxz - aw) + self.kxz,
            l * (self.czx + aw) + self.kzx,
            l2 * self.m + l * self.cz + self.kz,
        )
    }

    /// dQ / dlambda = 2 lambda M + C1 + W C2.
    pub(crate) fn derivative(&self, l: C64) -> Matrix2<C64> {
        let aw = self.a * self.w;
        Matrix2::new(
            l * (2.0 * self.m) + self.cx,
            C64::new(self.cxz - aw, 0.0),
            C64::new(self.czx + aw, 0.0),
            l * (2.0 * self.m) + self.cz,
        )
    }

    /// The size of the terms of Q(lambda), to judge what is zero.
    pub(crate) fn scale(&self, l: C64) -> f64 {
        let n = l.norm();
        self.m * n * n
            + self
                .cx
                .abs()
                .max(self.cz.abs())
                .max(self.cxz.abs())
                .max(self.czx.abs())
                * n
            + self.kx.max(self.kz).max(self.kxz.abs()).max(self.kzx.abs())
            + (self.a * self.w).abs() * n
    }

    fn det(&self, l: C64) -> C64 {
        let q = self.at(l);
        q[(0, 0)] * q[(1, 1)] - q[(0, 1)] * q[(1, 0)]
    }

    fn det_derivative(&self, l: C64) -> C64 {
        let (q, d) = (self.at(l), self.derivative(l));
        d[(0, 0)] * q[(1, 1)] + q[(0, 0)] * d[(1, 1)]
            - d[(0, 1)] * q[(1, 0)]
            - q[(0, 1)] * d[(1, 0)]
    }

    /// The four roots of det Q (module doc), in no particular order.
    fn roots(&self) -> [C64; 4] {
        let s = (self.kx.max(self.kz) / self.m).sqrt();
        let (m, aw) = (self.m, self.a * self.w);
        #[rustfmt::skip]
        let a = Matrix4::new(
            0.0, 0.0, s, 0.0,
            0.0, 0.0, 0.0, s,
            -self.kx / (m * s), -self.kxz / (m * s), -self.cx / m, -(self.cxz - aw) / m,
            -self.kzx / (m * s), -self.kz / (m * s), -(self.czx + aw) / m, -self.cz / m,
        );
        let ev = a.complex_eigenvalues();
        [ev[0], ev[1], ev[2], ev[3]].map(|l| self.polish(l))
    }

    /// Newton steps on det Q from `l`, each kept only if it reduces |det Q|.
    fn polish(&self, mut l: C64) -> C64 {
        let mut p = self.det(l);
        for _ in 0..3 {
            let dp = self.det_derivative(l);
            if dp.norm() == 0.0 || p.norm() == 0.0 {
                break;
            }
            let next = l - p / dp;
            let pn = self.det(next);
            // a NaN residual is no improvement either
            if pn.norm().is_nan() || pn.norm() >= p.norm() {
                break;
            }
            (l, p) = (next, pn);
        }
        l
    }

    /// The right and left null vectors (u, r) of Q(lambda): Q u ~ 0, r Q ~ 0, for a root
    /// of det Q; `None` when Q(lambda) is zero (module doc of [`RANK_ZERO`]).
    pub(crate) fn null_vectors(&self, l: C64) -> Option<(Vector2<C64>, RowVector2<C64>)> {
        let q = self.at(l);
        let norm2 = |a: C64, b: C64| a.norm_sqr() + b.norm_sqr();
        // the larger row (a, b) gives u = (b, -a); the larger column (c, d) gives r = (d, -c)
        let (a, b) = if norm2(q[(0, 0)], q[(0, 1)]) >= norm2(q[(1, 0)], q[(1, 1)]) {
            (q[(0, 0)], q[(0, 1)])
        } else {
            (q[(1, 0)], q[(1, 1)])
        };
        let (c, d) = if norm2(q[(0, 0)], q[(1, 0)]) >= norm2(q[(0, 1)], q[(1, 1)]) {
            (q[(0, 0)], q[(1, 0)])
        } else {
            (q[(0, 1)], q[(1, 1)])
        };
        if norm2(a, b).sqrt() <= RANK_ZERO * self.scale(l) {
            return None;
        }
        Some((Vector2::new(b, -a), RowVector2::new(d, -c)))
    }

    /// The mode of root `l` (module doc).
    fn mode(&self, l: C64) -> Mode {
        let l = if l.im < 0.0 { l.conj() } else { l };
        let whirl_ratio = self.null_vectors(l).map(|(u, _)| {
            let (x, z) = (u[0], u[1]);
            -2.0 * (x * z.conj()).im / (x.norm_sqr() + z.norm_sqr())
        });
        Mode::of(l, whirl_ratio)
    }

    /// The two modes, lower damped natural frequency first: of the four roots, the two
    /// with the largest imaginary part (for an overdamped pair, one of its real roots).
    pub(crate) fn modes(&self) -> [Mode; 2] {
        let mut r = self.roots();
        r.sort_by(|a, b| b.im.total_cmp(&a.im));
        let (hi, lo) = (self.mode(r[0]), self.mode(r[1]));
        if lo.frequency <= hi.frequency {
            [lo, hi]
        } else {
            [hi, lo]
        }
    }
}

/// The two modes of the rotor `p` at the constant speed `omega` \[rad/s\] (finite, >= 0),
/// lower damped natural frequency first.
pub fn modes(p: &RotorParams, omega: f64) -> Result<[Mode; 2], AnalysisError> {
    check_params(p)?;
    check_speed(omega)?;
    Ok(Quadratic::new(p, omega).modes())
}

/// The modes over a speed grid: the data of a Campbell diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Campbell {
    /// The speeds W \[rad/s\], increasing.
    pub speeds: Vec<f64>,
    /// Per speed, the two modes, lower damped natural frequency first (mode 0 and mode 1
    /// are followed across speeds by this order).
    pub modes: Vec<[Mode; 2]>,
}

impl Campbell {
    /// Mode `i` (0: lower, 1: higher) at every speed.
    pub fn mode(&self, i: usize) -> impl Iterator<Item = &Mode> + '_ {
        self.modes.iter().map(move |m| &m[i])
    }

    /// The whirl of mode `i` over the grid: the direction most of its speeds show; `None`
    /// when none shows a direction or both are equally frequent.
    pub fn whirl(&self, i: usize) -> Option<Whirl> {
        majority_whirl(self.mode(i))
    }
}

/// The whirl most of `modes` show; `None` when none shows one or both are equally
/// frequent (the whirl of a followed mode over a Campbell diagram).
pub(crate) fn majority_whirl<'a>(modes: impl Iterator<Item = &'a Mode>) -> Option<Whirl> {
    let (mut f, mut b) = (0usize, 0usize);
    for m in modes {
        match m.whirl {
            Some(Whirl::Forward) => f += 1,
            Some(Whirl::Backward) => b += 1,
            None => {}
        }
    }
    match f.cmp(&b) {
        std::cmp::Ordering::Greater => Some(Whirl::Forward),
        std::cmp::Ordering::Less => Some(Whirl::Backward),
        std::cmp::Ordering::Equal => None,
    }
}

/// The modes of `p` at every speed of `speeds` \[rad/s\] (finite, >= 0, strictly
/// increasing, at least one).
pub fn campbell(p: &RotorParams, speeds: &[f64]) -> Result<Campbell, AnalysisError> {
    check_params(p)?;
    check_speeds(speeds, 1)?;
    Ok(Campbell {
        speeds: speeds.to_vec(),
        modes: speeds
            .iter()
            .map(|&w| Quadratic::new(p, w).modes())
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Rotor;

    #[test]
    fn null_vectors_annihilate_q() {
        let mut p = Rotor::table1().params();
        p.kz *= 1.2;
        p.cz = 30.0;
        let q = Quadratic::new(&p, 250.0);
        for m in q.modes() {
            let l = m.eigenvalue;
            let (u, r) = q.null_vectors(l).unwrap();
            let s = q.scale(l);
            assert!(
                (q.at(l) * u).norm() < 1e-9 * s * u.norm(),
                "{}",
                (q.at(l) * u).norm()
            );
            assert!((r * q.at(l)).norm() < 1e-9 * s * r.norm());
        }
    }

    /// The roots of det Q by Durand-Kerner iteration on the quartic's coefficients,
    /// expanded by hand (an algorithm independent of the state matrix and nalgebra).
    fn quartic_roots(q: &Quadratic) -> [C64; 4] {
        let aw = q.a * q.w;
        let (p1, p0) = (q.cxz - aw, q.kxz);
        let (r1, r0) = (q.czx + aw, q.kzx);
        let m = q.m;
        // det Q = (m l^2 + cx l + kx)(m l^2 + cz l + kz) - (p1 l + p0)(r1 l + r0)
        let c = [
            q.kx * q.kz - p0 * r0,
            q.cx * q.kz + q.cz * q.kx - p1 * r0 - p0 * r1,
            m * (q.kx + q.kz) + q.cx * q.cz - p1 * r1,
            m * (q.cx + q.cz),
        ]
        .map(|v| v / (m * m));
        let poly = |l: C64| (((l + c[3]) * l + c[2]) * l + c[1]) * l + c[0];
        let scale = (q.kx.max(q.kz) / m).sqrt();
        let mut z: [C64; 4] = std::array::from_fn(|k| C64::new(0.4, 0.9).powu(k as u32) * scale);
        for _ in 0..500 {
            for k in 0..4 {
                let mut d = C64::new(1.0, 0.0);
                for j in (0..4).filter(|&j| j != k) {
                    d *= z[k] - z[j];
                }
                z[k] -= poly(z[k]) / d;
            }
        }
        z
    }

    fn cross_rotor() -> RotorParams {
        let mut p = Rotor::table1().params();
        p.kz = 1.4e6;
        p.cx = 200.0;
        p.cz = 150.0;
        p.coupling = Some(crate::model::CrossCoupling {
            cxz: 20.0,
            czx: -15.0,
            kxz: -4.0e4,
            kzx: 6.0e4,
        });
        p
    }

    #[test]
    fn eigenvalues_agree_with_the_characteristic_quartic() {
        for w in [0.0, 150.0, 400.0, 900.0] {
            // (Durand-Kerner converges slowly to the double root of the isotropic rotor at
            // rest: the Jeffcott rotor here is anisotropic)
            let mut jeffcott = Rotor::table1().params();
            jeffcott.kz *= 1.3;
            jeffcott.cz = 40.0;
            for p in [cross_rotor(), jeffcott] {
                let q = Quadratic::new(&p, w);
                let scale = (p.kx.max(p.kz) / p.m).sqrt();
                let mut want = quartic_roots(&q).to_vec();
                let mut got = q.roots().to_vec();
                for v in [&mut want, &mut got] {
                    v.sort_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re)));
                }
                for (g, e) in got.iter().zip(&want) {
                    assert!(
                        (g - e).norm() < 1e-9 * scale,
                        "W = {w}: {g} vs {e} (cross {:?})",
                        p.coupling
                    );
                }
            }
        }
    }

    #[test]
    fn isotropic_cross_coupled_rotor_matches_the_closed_form() {
        // kzx = -kxz = Q, a = 0: m l^2 + c l + k = +-i Q; the + root whirls forward
        let (m, c, k, qq) = (14.29, 200.0, 1.195e6, 5.0e4);
        let p = RotorParams {
            m,
            cx: c,
            cz: c,
            kx: k,
            kz: k,
            a: 0.0,
            unbalance: crate::model::Unbalance {
                m_u: 0.0,
                d: 0.0,
                alpha: 0.0,
            },
            coupling: Some(crate::model::CrossCoupling {
                cxz: 0.0,
                czx: 0.0,
                kxz: -qq,
                kzx: qq,
            }),
        };
        let root = |s: f64| {
            let disc = (C64::new(c * c - 4.0 * m * k, 4.0 * m * s * qq)).sqrt();
            let l = (-c + disc) / (2.0 * m);
            let l2 = (-c - disc) / (2.0 * m);
            // of the two roots, the one near +i sqrt(k/m)
            if l.im > 0.0 {
                l
            } else {
                l2
            }
        };
        let (fwd, bwd) = (root(1.0), root(-1.0));
        // a = 0: both modes have the same frequency; they differ in damping and whirl
        let ms = modes(&p, 100.0).unwrap();
        let forward = ms.iter().find(|m| m.whirl == Some(Whirl::Forward)).unwrap();
        let backward = ms
            .iter()
            .find(|m| m.whirl == Some(Whirl::Backward))
            .unwrap();
        for (mode, want) in [(backward, bwd), (forward, fwd)] {
            assert!(
                (mode.eigenvalue - want).norm() < 1e-10 * want.norm(),
                "{} vs {want}",
                mode.eigenvalue
            );
            assert!((mode.whirl_ratio.unwrap().abs() - 1.0).abs() < 1e-9);
        }
        // the cross-coupled stiffness kzx > 0 > kxz takes damping from the forward mode
        assert!(forward.damping_ratio < backward.damping_ratio);
    }

    #[test]
    fn isotropic_rotor_at_rest_has_no_whirl_direction() {
        let p = Rotor::table1().params();
        let [a, b] = modes(&p, 0.0).unwrap();
        assert!((a.frequency - b.frequency).abs() < 1e-9 * a.frequency);
        assert_eq!((a.whirl, b.whirl), (None, None));
        assert_eq!(a.whirl_ratio, None);
    }
}
