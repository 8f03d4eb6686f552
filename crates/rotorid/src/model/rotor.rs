//! Rotor parameters and the M, C(w), K(w') matrices and unbalance force of eq. (1).

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use super::error::{check, ModelError};
use super::speed::SpeedState;

/// Unbalance: a mass `m_u` at radius `d` and angular position `alpha` on the disk.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Unbalance {
    /// Unbalance mass m_u \[kg\], >= 0.
    pub m_u: f64,
    /// Radius of the unbalance mass d \[m\], >= 0.
    pub d: f64,
    /// Angular position alpha \[rad\] of the unbalance relative to phi = 0.
    pub alpha: f64,
}

impl Unbalance {
    /// m_u * d \[kg m\], the only combination of m_u and d the dynamics see.
    pub fn mud(&self) -> f64 {
        self.m_u * self.d
    }
}

/// Unvalidated rotor parameters, as a user writes them (SI units). Turn into a [`Rotor`]
/// with [`Rotor::new`], which checks every field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotorParams {
    /// Modal mass of the disk m \[kg\], > 0 (common to both directions).
    pub m: f64,
    /// Support damping in x, cx \[N s/m\], >= 0.
    pub cx: f64,
    /// Support damping in z, cz \[N s/m\], >= 0.
    pub cz: f64,
    /// Support stiffness in x, kx \[N/m\], > 0.
    pub kx: f64,
    /// Support stiffness in z, kz \[N/m\], > 0.
    pub kz: f64,
    /// Gyroscopic coefficient a \[N s^2/m\] (= kg), any finite value.
    pub a: f64,
    /// The unbalance that drives the rotor.
    pub unbalance: Unbalance,
}

/// A validated 2-DOF rotor (paper eq. 1). Fields are read through accessors so a `Rotor`
/// can never hold a value [`Rotor::new`] would reject.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rotor {
    p: RotorParams,
}

impl Rotor {
    /// Validate `p`: all finite; m > 0; kx, kz > 0; cx, cz >= 0; m_u, d >= 0.
    pub fn new(p: RotorParams) -> Result<Self, ModelError> {
        check("m", p.m, "finite and > 0 (kg)", |v| v > 0.0)?;
        check("cx", p.cx, "finite and >= 0 (N s/m)", |v| v >= 0.0)?;
        check("cz", p.cz, "finite and >= 0 (N s/m)", |v| v >= 0.0)?;
        check("kx", p.kx, "finite and > 0 (N/m)", |v| v > 0.0)?;
        check("kz", p.kz, "finite and > 0 (N/m)", |v| v > 0.0)?;
        check("a", p.a, "finite (N s^2/m)", |_| true)?;
        let u = p.unbalance;
        check("m_u", u.m_u, "finite and >= 0 (kg)", |v| v >= 0.0)?;
        check("d", u.d, "finite and >= 0 (m)", |v| v >= 0.0)?;
        check("alpha", u.alpha, "finite (rad)", |_| true)?;
        Ok(Self { p })
    }

    /// The paper's Table 1: m = 14.29 kg, cx = cz = 10 N s/m, kx = kz = 1.195e6 N/m,
    /// a = 2.871 N s^2/m, m_u = 1e-4 kg, d = 0.15 m, alpha = 45 deg.
    pub fn table1() -> Self {
        Self::new(RotorParams {
            m: 14.29,
            cx: 10.0,
            cz: 10.0,
            kx: 1.195e6,
            kz: 1.195e6,
            a: 2.871,
            unbalance: Unbalance {
                m_u: 1.0e-4,
                d: 0.15,
                alpha: 45f64.to_radians(),
            },
        })
        .expect("Table 1 is a valid rotor")
    }

    /// The parameters (a copy); change them and call [`Rotor::new`] for a variant.
    pub fn params(&self) -> RotorParams {
        self.p
    }
    /// m \[kg\].
    pub fn m(&self) -> f64 {
        self.p.m
    }
    /// cx \[N s/m\].
    pub fn cx(&self) -> f64 {
        self.p.cx
    }
    /// cz \[N s/m\].
    pub fn cz(&self) -> f64 {
        self.p.cz
    }
    /// kx \[N/m\].
    pub fn kx(&self) -> f64 {
        self.p.kx
    }
    /// kz \[N/m\].
    pub fn kz(&self) -> f64 {
        self.p.kz
    }
    /// Gyroscopic coefficient a \[N s^2/m\].
    pub fn a(&self) -> f64 {
        self.p.a
    }
    /// The unbalance.
    pub fn unbalance(&self) -> Unbalance {
        self.p.unbalance
    }

    /// M = m I \[kg\].
    pub fn mass_matrix(&self) -> Matrix2<f64> {
        Matrix2::identity() * self.p.m
    }

    /// C(w) = diag(cx, cz) + w [[0, -a], [a, 0]] \[N s/m\], w in rad/s.
    pub fn damping_matrix(&self, w: f64) -> Matrix2<f64> {
        let aw = self.p.a * w;
        Matrix2::new(self.p.cx, -aw, aw, self.p.cz)
    }

    /// K(w') = diag(kx, kz) + w' [[0, -a], [0, 0]] \[N/m\], w' in rad/s^2.
    pub fn stiffness_matrix(&self, w_dot: f64) -> Matrix2<f64> {
        Matrix2::new(self.p.kx, -self.p.a * w_dot, 0.0, self.p.kz)
    }

    /// Unbalance force F \[N\] at the rotor state `s`:
    /// `m_u d (w^2 sin(phi+alpha) - w' cos(phi+alpha), w' sin(phi+alpha) + w^2 cos(phi+alpha))`.
    pub fn unbalance_force(&self, s: &SpeedState) -> Vector2<f64> {
        let u = self.p.unbalance;
        let (sn, cs) = (s.phi + u.alpha).sin_cos();
        unbalance_force_from(u.mud(), s.omega, s.omega_dot, sn, cs)
    }
}

/// The unbalance force for a precomputed `sin(phi+alpha)`, `cos(phi+alpha)` (hot loops
/// that generate the phase incrementally use this).
#[inline]
pub fn unbalance_force_from(mud: f64, w: f64, w_dot: f64, sn: f64, cs: f64) -> Vector2<f64> {
    let w2 = w * w;
    Vector2::new(mud * (w2 * sn - w_dot * cs), mud * (w_dot * sn + w2 * cs))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> RotorParams {
        Rotor::table1().params()
    }

    #[test]
    fn table1_matches_the_paper() {
        let r = Rotor::table1();
        assert_eq!(r.m(), 14.29);
        assert_eq!(r.kx(), 1.195e6);
        assert!((r.unbalance().mud() - 1.5e-5).abs() < 1e-20);
        // sqrt(k/m) = 289.2 rad/s (docs/method.md section 1)
        assert!(((r.kx() / r.m()).sqrt() - 289.18).abs() < 0.01);
    }

    #[test]
    fn every_field_is_validated_and_named() {
        type Setter = fn(&mut RotorParams, f64);
        let cases: [(&str, Setter, f64); 12] = [
            ("m", |p, v| p.m = v, 0.0),
            ("m", |p, v| p.m = v, f64::NAN),
            ("cx", |p, v| p.cx = v, -1.0),
            ("cz", |p, v| p.cz = v, -1e-9),
            ("kx", |p, v| p.kx = v, 0.0),
            ("kz", |p, v| p.kz = v, f64::INFINITY),
            ("a", |p, v| p.a = v, f64::NAN),
            ("m_u", |p, v| p.unbalance.m_u = v, -1.0),
            ("d", |p, v| p.unbalance.d = v, -0.1),
            ("alpha", |p, v| p.unbalance.alpha = v, f64::NEG_INFINITY),
            ("kx", |p, v| p.kx = v, -5.0),
            ("m", |p, v| p.m = v, -14.0),
        ];
        for (name, set, bad) in cases {
            let mut p = params();
            set(&mut p, bad);
            match Rotor::new(p) {
                Err(ModelError::OutOfRange { field, allowed, .. }) => {
                    assert_eq!(field, name);
                    assert!(allowed.contains('('), "unit missing in {allowed}");
                }
                other => panic!("{name} = {bad} accepted: {other:?}"),
            }
        }
    }

    #[test]
    fn zero_damping_and_zero_unbalance_are_allowed() {
        let mut p = params();
        p.cx = 0.0;
        p.cz = 0.0;
        p.unbalance.m_u = 0.0;
        assert!(Rotor::new(p).is_ok());
    }

    #[test]
    fn error_message_states_the_range() {
        let mut p = params();
        p.m = -2.0;
        let msg = Rotor::new(p).unwrap_err().to_string();
        assert_eq!(msg, "m = -2 is out of range: must be finite and > 0 (kg)");
    }

    #[test]
    fn matrices_follow_eq_1() {
        let r = Rotor::table1();
        let c = r.damping_matrix(100.0);
        assert_eq!(c[(0, 1)], -287.1);
        assert_eq!(c[(1, 0)], 287.1);
        let k = r.stiffness_matrix(10.0);
        assert_eq!(k[(0, 1)], -28.71);
        assert_eq!(k[(1, 0)], 0.0);
        let s = SpeedState {
            phi: -r.unbalance().alpha,
            omega: 2.0,
            omega_dot: 0.0,
        };
        let f = r.unbalance_force(&s);
        assert!(f[0].abs() < 1e-20);
        assert!((f[1] - 4.0 * 1.5e-5).abs() < 1e-18);
    }
}
