//! Rotor parameters and the M, C(w), K(w') matrices and unbalance force of eq. (1), for
//! the paper's Jeffcott rotor and for the same rotor on cross-coupled bearings
//! (docs/method.md section 1.6):
//!
//! ```text
//! C(w)  = [[cx, cxz], [czx, cz]] + w  [[0, -a], [a, 0]]
//! K(w') = [[kx, kxz], [kzx, kz]] + w' [[0, -a], [0, 0]]
//! ```
//!
//! kxz is the bearing's restoring force in x per unit displacement in z \[N/m\] (it stands on
//! the left of the x equation, as kx does); likewise cxz \[N s/m\], and czx, kzx in z. The
//! Jeffcott rotor is the model without them ([`RotorParams::coupling`] `None`); the
//! cross-coupled model names its direct coefficients cxx, czz, kxx, kzz (the fields cx, cz,
//! kx, kz).

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use super::error::{check, ModelError};
use super::speed::SpeedState;
use crate::parameter::{ModelKind, Parameter};

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

/// The cross-coupled coefficients of the bearings (module doc): the off-diagonal terms of
/// the damping and stiffness matrices. Any sign; all zero is a Jeffcott rotor written in
/// the cross-coupled model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CrossCoupling {
    /// Damping force in x per unit velocity in z, cxz \[N s/m\].
    pub cxz: f64,
    /// Damping force in z per unit velocity in x, czx \[N s/m\].
    pub czx: f64,
    /// Restoring force in x per unit displacement in z, kxz \[N/m\].
    pub kxz: f64,
    /// Restoring force in z per unit displacement in x, kzx \[N/m\].
    pub kzx: f64,
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
    /// The bearings' cross-coupled coefficients: `None` is the paper's Jeffcott rotor (the
    /// Jeffcott model), `Some` the cross-coupled model (module doc).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling: Option<CrossCoupling>,
}

impl RotorParams {
    /// The model these parameters describe: Jeffcott without coupling, else cross-coupled.
    pub fn model(&self) -> ModelKind {
        match self.coupling {
            None => ModelKind::Jeffcott,
            Some(_) => ModelKind::CrossCoupled,
        }
    }

    /// The cross-coupled coefficients (all zero for a Jeffcott rotor).
    pub fn cross(&self) -> CrossCoupling {
        self.coupling.unwrap_or_default()
    }

    /// The value of `p` \[its unit\], when `p` is a parameter of these values' model (m_x
    /// and m_z are m; mud and alpha the unbalance's).
    pub fn get(&self, p: Parameter) -> Option<f64> {
        let c = self.coupling;
        Some(match p {
            Parameter::M | Parameter::MX | Parameter::MZ => self.m,
            Parameter::Cx | Parameter::Cxx => self.cx,
            Parameter::Kx | Parameter::Kxx => self.kx,
            Parameter::Cz | Parameter::Czz => self.cz,
            Parameter::Kz | Parameter::Kzz => self.kz,
            Parameter::A => self.a,
            Parameter::Mud => self.unbalance.mud(),
            Parameter::Alpha => self.unbalance.alpha,
            Parameter::Cxz => c?.cxz,
            Parameter::Czx => c?.czx,
            Parameter::Kxz => c?.kxz,
            Parameter::Kzx => c?.kzx,
        })
    }

    /// Set `p` to `v` \[its unit\]; a cross-coupled coefficient makes the model cross-coupled
    /// (the other cross terms 0 unless set), mud keeps the radius d (d = 1 m when d is 0).
    pub fn set(&mut self, p: Parameter, v: f64) {
        fn cross(c: &mut Option<CrossCoupling>) -> &mut CrossCoupling {
            c.get_or_insert_with(CrossCoupling::default)
        }
        match p {
            Parameter::M | Parameter::MX | Parameter::MZ => self.m = v,
            Parameter::Cx | Parameter::Cxx => self.cx = v,
            Parameter::Kx | Parameter::Kxx => self.kx = v,
            Parameter::Cz | Parameter::Czz => self.cz = v,
            Parameter::Kz | Parameter::Kzz => self.kz = v,
            Parameter::A => self.a = v,
            Parameter::Mud => {
                if self.unbalance.d == 0.0 {
                    self.unbalance.d = 1.0;
                }
                self.unbalance.m_u = v / self.unbalance.d;
            }
            Parameter::Alpha => self.unbalance.alpha = v,
            Parameter::Cxz => cross(&mut self.coupling).cxz = v,
            Parameter::Czx => cross(&mut self.coupling).czx = v,
            Parameter::Kxz => cross(&mut self.coupling).kxz = v,
            Parameter::Kzx => cross(&mut self.coupling).kzx = v,
        }
    }
}

/// A validated 2-DOF rotor (paper eq. 1). Fields are read through accessors so a `Rotor`
/// can never hold a value [`Rotor::new`] would reject.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rotor {
    p: RotorParams,
}

impl Rotor {
    /// Validate `p`: all finite; m > 0; kx, kz > 0; cx, cz >= 0; m_u, d >= 0; with
    /// cross-coupling (names of the cross-coupled model: kxx, kzz, cxx, czz) the cross terms
    /// any finite value and the damping matrix's symmetric part positive semi-definite
    /// (cxx czz >= ((cxz + czx) / 2)^2: the bearings dissipate energy, they cannot feed it).
    pub fn new(p: RotorParams) -> Result<Self, ModelError> {
        check("m", p.m, "finite and > 0 (kg)", |v| v > 0.0)?;
        let cross = p.coupling.is_some();
        let name = |jeffcott: &'static str, coupled: &'static str| {
            if cross {
                coupled
            } else {
                jeffcott
            }
        };
        check(name("cx", "cxx"), p.cx, "finite and >= 0 (N s/m)", |v| {
            v >= 0.0
        })?;
        check(name("cz", "czz"), p.cz, "finite and >= 0 (N s/m)", |v| {
            v >= 0.0
        })?;
        check(name("kx", "kxx"), p.kx, "finite and > 0 (N/m)", |v| v > 0.0)?;
        check(name("kz", "kzz"), p.kz, "finite and > 0 (N/m)", |v| v > 0.0)?;
        check("a", p.a, "finite (N s^2/m)", |_| true)?;
        let u = p.unbalance;
        check("m_u", u.m_u, "finite and >= 0 (kg)", |v| v >= 0.0)?;
        check("d", u.d, "finite and >= 0 (m)", |v| v >= 0.0)?;
        check("alpha", u.alpha, "finite (rad)", |_| true)?;
        if let Some(c) = p.coupling {
            check("cxz", c.cxz, "finite (N s/m)", |_| true)?;
            check("czx", c.czx, "finite (N s/m)", |_| true)?;
            check("kxz", c.kxz, "finite (N/m)", |_| true)?;
            check("kzx", c.kzx, "finite (N/m)", |_| true)?;
            let s = 0.5 * (c.cxz + c.czx);
            if p.cx * p.cz < s * s {
                return Err(ModelError::DampingNotDissipative {
                    cxx: p.cx,
                    cxz: c.cxz,
                    czx: c.czx,
                    czz: p.cz,
                });
            }
        }
        Ok(Self { p })
    }

    /// The model of this rotor (Jeffcott without cross-coupling, else cross-coupled).
    pub fn model(&self) -> ModelKind {
        self.p.model()
    }

    /// The cross-coupled coefficients (zero for a Jeffcott rotor).
    pub fn cross(&self) -> CrossCoupling {
        self.p.cross()
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
            coupling: None,
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

    /// C(w) = [[cx, cxz], [czx, cz]] + w [[0, -a], [a, 0]] \[N s/m\], w in rad/s (cxz = czx
    /// = 0 for a Jeffcott rotor).
    pub fn damping_matrix(&self, w: f64) -> Matrix2<f64> {
        let aw = self.p.a * w;
        let c = self.cross();
        Matrix2::new(self.p.cx, c.cxz - aw, c.czx + aw, self.p.cz)
    }

    /// K(w') = [[kx, kxz], [kzx, kz]] + w' [[0, -a], [0, 0]] \[N/m\], w' in rad/s^2 (kxz =
    /// kzx = 0 for a Jeffcott rotor).
    pub fn stiffness_matrix(&self, w_dot: f64) -> Matrix2<f64> {
        let c = self.cross();
        Matrix2::new(self.p.kx, c.kxz - self.p.a * w_dot, c.kzx, self.p.kz)
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
