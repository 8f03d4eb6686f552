//! Which quantities are estimated, and the internal parameter vector.
//!
//! Internally the unbalance is the pair (u_c, u_s) = (m_u d cos alpha, m_u d sin alpha),
//! in which the force is linear and which has no singularity at m_u d = 0:
//!
//! ```text
//! m_u d sin(phi + alpha) = u_c sin(phi) + u_s cos(phi)
//! m_u d cos(phi + alpha) = u_c cos(phi) - u_s sin(phi)
//! ```
//!
//! The initial state y0 = (x0, z0, vx0, vz0) enters the response linearly; when unknown it
//! is estimated as four nuisance parameters.

use serde::{Deserialize, Serialize};

use crate::model::{InitialState, RotorParams, Unbalance};

/// The quantities to estimate; everything else is held at its starting value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Unknowns {
    /// Estimate m \[kg\].
    pub m: bool,
    /// Estimate cx \[N s/m\].
    pub cx: bool,
    /// Estimate kx \[N/m\].
    pub kx: bool,
    /// Estimate cz \[N s/m\].
    pub cz: bool,
    /// Estimate kz \[N/m\].
    pub kz: bool,
    /// Estimate the gyroscopic coefficient a \[N s^2/m\].
    pub a: bool,
    /// Estimate the unbalance m_u d \[kg m\] and its angle alpha \[rad\].
    pub unbalance: bool,
    /// Estimate the initial state x0, z0 \[m\], vx0, vz0 \[m/s\] (nuisance parameters).
    pub initial_state: bool,
}

impl Default for Unknowns {
    /// m, cx, kx, cz, kz and the initial state; a and the unbalance known.
    fn default() -> Self {
        Self {
            m: true,
            cx: true,
            kx: true,
            cz: true,
            kz: true,
            a: false,
            unbalance: false,
            initial_state: true,
        }
    }
}

impl Unknowns {
    /// Everything: m, cx, kx, cz, kz, a, the unbalance and the initial state.
    pub fn all() -> Self {
        Self {
            a: true,
            unbalance: true,
            ..Self::default()
        }
    }
}

/// The most columns of the Jacobian: 8 model parameters + 4 initial-state components.
pub(crate) const MAXP: usize = 12;

/// One internal parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    M,
    Cx,
    Kx,
    Cz,
    Kz,
    A,
    Uc,
    Us,
    X0,
    Z0,
    Vx0,
    Vz0,
}

impl Kind {
    /// The name used in results.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Kind::M => "m",
            Kind::Cx => "cx",
            Kind::Kx => "kx",
            Kind::Cz => "cz",
            Kind::Kz => "kz",
            Kind::A => "a",
            Kind::Uc => "mud_cos_alpha",
            Kind::Us => "mud_sin_alpha",
            Kind::X0 => "x0",
            Kind::Z0 => "z0",
            Kind::Vx0 => "vx0",
            Kind::Vz0 => "vz0",
        }
    }

    /// SI unit.
    pub(crate) fn unit(self) -> &'static str {
        match self {
            Kind::M => "kg",
            Kind::Cx | Kind::Cz => "N s/m",
            Kind::Kx | Kind::Kz => "N/m",
            Kind::A => "N s^2/m",
            Kind::Uc | Kind::Us => "kg m",
            Kind::X0 | Kind::Z0 => "m",
            Kind::Vx0 | Kind::Vz0 => "m/s",
        }
    }

    /// Index into the initial state (x0, z0, vx0, vz0), if this is one of its components.
    pub(crate) fn initial_index(self) -> Option<usize> {
        match self {
            Kind::X0 => Some(0),
            Kind::Z0 => Some(1),
            Kind::Vx0 => Some(2),
            Kind::Vz0 => Some(3),
            _ => None,
        }
    }
}

/// The estimated columns: model parameters first (`nphys` of them), then the initial state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Columns {
    kinds: [Kind; MAXP],
    /// Number of columns.
    pub n: usize,
    /// Number of model-parameter columns (they come first).
    pub nphys: usize,
}

impl Columns {
    pub(crate) fn new(u: &Unknowns) -> Self {
        let phys = [
            (u.m, Kind::M),
            (u.cx, Kind::Cx),
            (u.kx, Kind::Kx),
            (u.cz, Kind::Cz),
            (u.kz, Kind::Kz),
            (u.a, Kind::A),
            (u.unbalance, Kind::Uc),
            (u.unbalance, Kind::Us),
        ];
        let ic = [Kind::X0, Kind::Z0, Kind::Vx0, Kind::Vz0].map(|k| (u.initial_state, k));
        let mut kinds = [Kind::M; MAXP];
        let mut n = 0;
        let mut nphys = 0;
        for (on, k) in phys.into_iter().chain(ic) {
            if on {
                kinds[n] = k;
                n += 1;
                if k.initial_index().is_none() {
                    nphys += 1;
                }
            }
        }
        Self { kinds, n, nphys }
    }

    /// A subset: only the columns for which `keep` is true (order preserved).
    pub(crate) fn filter(&self, keep: impl Fn(Kind) -> bool) -> Self {
        let mut out = Self {
            kinds: [Kind::M; MAXP],
            n: 0,
            nphys: 0,
        };
        for &k in self.kinds() {
            if keep(k) {
                out.kinds[out.n] = k;
                out.n += 1;
                if k.initial_index().is_none() {
                    out.nphys += 1;
                }
            }
        }
        out
    }

    pub(crate) fn kinds(&self) -> &[Kind] {
        &self.kinds[..self.n]
    }

    pub(crate) fn position(&self, k: Kind) -> Option<usize> {
        self.kinds().iter().position(|&c| c == k)
    }
}

/// Every model parameter and the initial state, in the internal parametrisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Theta {
    pub m: f64,
    pub cx: f64,
    pub kx: f64,
    pub cz: f64,
    pub kz: f64,
    pub a: f64,
    pub uc: f64,
    pub us: f64,
    /// (x0, z0, vx0, vz0) \[m, m, m/s, m/s\].
    pub y0: [f64; 4],
}

impl Theta {
    pub(crate) fn new(p: &RotorParams, ic: &InitialState) -> Self {
        let mud = p.unbalance.m_u * p.unbalance.d;
        let (s, c) = p.unbalance.alpha.sin_cos();
        Self {
            m: p.m,
            cx: p.cx,
            kx: p.kx,
            cz: p.cz,
            kz: p.kz,
            a: p.a,
            uc: mud * c,
            us: mud * s,
            y0: [ic.x, ic.z, ic.vx, ic.vz],
        }
    }

    pub(crate) fn get(&self, k: Kind) -> f64 {
        match k {
            Kind::M => self.m,
            Kind::Cx => self.cx,
            Kind::Kx => self.kx,
            Kind::Cz => self.cz,
            Kind::Kz => self.kz,
            Kind::A => self.a,
            Kind::Uc => self.uc,
            Kind::Us => self.us,
            Kind::X0 => self.y0[0],
            Kind::Z0 => self.y0[1],
            Kind::Vx0 => self.y0[2],
            Kind::Vz0 => self.y0[3],
        }
    }

    pub(crate) fn set(&mut self, k: Kind, v: f64) {
        match k {
            Kind::M => self.m = v,
            Kind::Cx => self.cx = v,
            Kind::Kx => self.kx = v,
            Kind::Cz => self.cz = v,
            Kind::Kz => self.kz = v,
            Kind::A => self.a = v,
            Kind::Uc => self.uc = v,
            Kind::Us => self.us = v,
            Kind::X0 => self.y0[0] = v,
            Kind::Z0 => self.y0[1] = v,
            Kind::Vx0 => self.y0[2] = v,
            Kind::Vz0 => self.y0[3] = v,
        }
    }

    /// m_u d = hypot(u_c, u_s) \[kg m\].
    pub(crate) fn mud(&self) -> f64 {
        self.uc.hypot(self.us)
    }

    /// Rotor parameters; the unbalance keeps `template`'s radius d when it is > 0
    /// (m_u = m_u d / d), else d = 1 m so that m_u carries m_u d.
    pub(crate) fn params_with(&self, template: &RotorParams) -> RotorParams {
        let mud = self.mud();
        let d = if template.unbalance.d > 0.0 {
            template.unbalance.d
        } else {
            1.0
        };
        let alpha = if mud > 0.0 {
            self.us.atan2(self.uc)
        } else {
            template.unbalance.alpha
        };
        RotorParams {
            m: self.m,
            cx: self.cx,
            kx: self.kx,
            cz: self.cz,
            kz: self.kz,
            a: self.a,
            unbalance: Unbalance {
                m_u: mud / d,
                d,
                alpha,
            },
        }
    }

    pub(crate) fn initial(&self) -> InitialState {
        InitialState {
            x: self.y0[0],
            z: self.y0[1],
            vx: self.y0[2],
            vz: self.y0[3],
        }
    }
}

/// Check that every parameter is finite and m > 0 (c and k may be anything finite: a
/// starting point or an intermediate iterate need not be physical).
pub(crate) fn check_params(p: &RotorParams) -> Result<(), super::error::RefineError> {
    use crate::model::check;
    check("m", p.m, "finite and > 0 (kg)", |v| v > 0.0)?;
    check("cx", p.cx, "finite (N s/m)", |_| true)?;
    check("kx", p.kx, "finite (N/m)", |_| true)?;
    check("cz", p.cz, "finite (N s/m)", |_| true)?;
    check("kz", p.kz, "finite (N/m)", |_| true)?;
    check("a", p.a, "finite (N s^2/m)", |_| true)?;
    check("m_u", p.unbalance.m_u, "finite (kg)", |_| true)?;
    check("d", p.unbalance.d, "finite (m)", |_| true)?;
    check("alpha", p.unbalance.alpha, "finite (rad)", |_| true)?;
    Ok(())
}
