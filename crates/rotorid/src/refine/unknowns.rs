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

use crate::model::{CrossCoupling, InitialState, RotorParams, Unbalance};
use crate::parameter::{ModelKind, Parameter};

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
    /// Estimate the cross-coupled damping cxz \[N s/m\] (cross-coupled model only).
    #[serde(default)]
    pub cxz: bool,
    /// Estimate the cross-coupled damping czx \[N s/m\] (cross-coupled model only).
    #[serde(default)]
    pub czx: bool,
    /// Estimate the cross-coupled stiffness kxz \[N/m\] (cross-coupled model only).
    #[serde(default)]
    pub kxz: bool,
    /// Estimate the cross-coupled stiffness kzx \[N/m\] (cross-coupled model only).
    #[serde(default)]
    pub kzx: bool,
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
            cxz: false,
            czx: false,
            kxz: false,
            kzx: false,
        }
    }
}

impl Unknowns {
    /// Everything of the Jeffcott model: m, cx, kx, cz, kz, a, the unbalance and the
    /// initial state.
    pub fn all() -> Self {
        Self {
            a: true,
            unbalance: true,
            ..Self::default()
        }
    }

    /// Nothing but the initial state.
    pub fn initial_state_only() -> Self {
        Self::from_parameters(&[], true)
    }

    /// The default of `model`: m and its bearing coefficients (the cross-coupled model's
    /// eight), and the initial state.
    pub fn for_model(model: ModelKind) -> Self {
        Self::from_parameters(model.default_unknowns(), true)
    }

    /// The parameters `ps` (either model's names; mud or alpha select the unbalance) and,
    /// when `initial_state`, the initial state.
    pub fn from_parameters(ps: &[Parameter], initial_state: bool) -> Self {
        let has = |q: &[Parameter]| ps.iter().any(|p| q.contains(p));
        use Parameter::*;
        Self {
            m: has(&[M, MX, MZ]),
            cx: has(&[Cx, Cxx]),
            kx: has(&[Kx, Kxx]),
            cz: has(&[Cz, Czz]),
            kz: has(&[Kz, Kzz]),
            a: has(&[A]),
            unbalance: has(&[Mud, Alpha]),
            initial_state,
            cxz: has(&[Cxz]),
            czx: has(&[Czx]),
            kxz: has(&[Kxz]),
            kzx: has(&[Kzx]),
        }
    }

    /// The model parameters selected, in `model`'s names and order (the unbalance as mud
    /// and alpha).
    pub fn parameters(&self, model: ModelKind) -> Vec<Parameter> {
        model
            .parameters()
            .iter()
            .copied()
            .filter(|&p| self.selects(p))
            .collect()
    }

    /// True when `p` (either model's name) is selected.
    pub fn selects(&self, p: Parameter) -> bool {
        use Parameter::*;
        match p {
            M | MX | MZ => self.m,
            Cx | Cxx => self.cx,
            Kx | Kxx => self.kx,
            Cz | Czz => self.cz,
            Kz | Kzz => self.kz,
            A => self.a,
            Mud | Alpha => self.unbalance,
            Cxz => self.cxz,
            Czx => self.czx,
            Kxz => self.kxz,
            Kzx => self.kzx,
        }
    }

    /// True when a cross-coupled coefficient is unknown.
    pub fn any_cross(&self) -> bool {
        self.cxz || self.czx || self.kxz || self.kzx
    }
}

/// The most columns of the Jacobian: 12 model parameters (m, 8 bearing coefficients, a,
/// u_c, u_s) + 4 initial-state components.
pub(crate) const MAXP: usize = 16;

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
    Cxz,
    Czx,
    Kxz,
    Kzx,
}

impl Kind {
    /// The parameter this column estimates, named as `model` names it (the unbalance's
    /// u_c, u_s and the initial state have none: they are reported otherwise).
    pub(crate) fn parameter(self, model: ModelKind) -> Option<Parameter> {
        let p = match self {
            Kind::M => Parameter::M,
            Kind::Cx => Parameter::Cx,
            Kind::Kx => Parameter::Kx,
            Kind::Cz => Parameter::Cz,
            Kind::Kz => Parameter::Kz,
            Kind::A => Parameter::A,
            Kind::Cxz => Parameter::Cxz,
            Kind::Czx => Parameter::Czx,
            Kind::Kxz => Parameter::Kxz,
            Kind::Kzx => Parameter::Kzx,
            Kind::Uc | Kind::Us | Kind::X0 | Kind::Z0 | Kind::Vx0 | Kind::Vz0 => return None,
        };
        model.own(p)
    }

    /// The name used in results, in `model`'s vocabulary.
    pub(crate) fn name_in(self, model: ModelKind) -> &'static str {
        self.parameter(model)
            .map_or_else(|| self.name(), Parameter::name)
    }

    /// The name used in results (the Jeffcott model's names for the direct coefficients).
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
            Kind::Cxz => "cxz",
            Kind::Czx => "czx",
            Kind::Kxz => "kxz",
            Kind::Kzx => "kzx",
        }
    }

    /// SI unit.
    pub(crate) fn unit(self) -> &'static str {
        match self {
            Kind::M => "kg",
            Kind::Cx | Kind::Cz | Kind::Cxz | Kind::Czx => "N s/m",
            Kind::Kx | Kind::Kz | Kind::Kxz | Kind::Kzx => "N/m",
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
    /// The model whose names the columns are reported by.
    pub model: ModelKind,
}

impl Columns {
    /// The columns of `u` in `model`, in the model's order of parameters
    /// ([`ModelKind::parameters`]; the unbalance as u_c, u_s), then the initial state.
    pub(crate) fn new(u: &Unknowns, model: ModelKind) -> Self {
        let phys = match model {
            ModelKind::Jeffcott => [
                (u.m, Kind::M),
                (u.cx, Kind::Cx),
                (u.kx, Kind::Kx),
                (u.cz, Kind::Cz),
                (u.kz, Kind::Kz),
                (u.a, Kind::A),
                (u.unbalance, Kind::Uc),
                (u.unbalance, Kind::Us),
                (u.cxz, Kind::Cxz),
                (u.czx, Kind::Czx),
                (u.kxz, Kind::Kxz),
                (u.kzx, Kind::Kzx),
            ],
            ModelKind::CrossCoupled => [
                (u.m, Kind::M),
                (u.cx, Kind::Cx),
                (u.cxz, Kind::Cxz),
                (u.czx, Kind::Czx),
                (u.cz, Kind::Cz),
                (u.kx, Kind::Kx),
                (u.kxz, Kind::Kxz),
                (u.kzx, Kind::Kzx),
                (u.kz, Kind::Kz),
                (u.a, Kind::A),
                (u.unbalance, Kind::Uc),
                (u.unbalance, Kind::Us),
            ],
        };
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
        Self {
            kinds,
            n,
            nphys,
            model,
        }
    }

    /// A subset: only the columns for which `keep` is true (order preserved).
    pub(crate) fn filter(&self, keep: impl Fn(Kind) -> bool) -> Self {
        let mut out = Self {
            kinds: [Kind::M; MAXP],
            n: 0,
            nphys: 0,
            model: self.model,
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
    /// Cross-coupled cxz, czx \[N s/m\], kxz, kzx \[N/m\] (0 in the Jeffcott model).
    pub cxz: f64,
    pub czx: f64,
    pub kxz: f64,
    pub kzx: f64,
}

impl Theta {
    pub(crate) fn new(p: &RotorParams, ic: &InitialState) -> Self {
        let mud = p.unbalance.m_u * p.unbalance.d;
        let (s, c) = p.unbalance.alpha.sin_cos();
        let x = p.cross();
        Self {
            cxz: x.cxz,
            czx: x.czx,
            kxz: x.kxz,
            kzx: x.kzx,
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
            Kind::Cxz => self.cxz,
            Kind::Czx => self.czx,
            Kind::Kxz => self.kxz,
            Kind::Kzx => self.kzx,
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
            Kind::Cxz => self.cxz = v,
            Kind::Czx => self.czx = v,
            Kind::Kxz => self.kxz = v,
            Kind::Kzx => self.kzx = v,
        }
    }

    /// m_u d = hypot(u_c, u_s) \[kg m\].
    pub(crate) fn mud(&self) -> f64 {
        self.uc.hypot(self.us)
    }

    /// Rotor parameters; the unbalance keeps `template`'s radius d when it is > 0
    /// (m_u = m_u d / d), else d = 1 m so that m_u carries m_u d. The model (cross-coupling
    /// or not) is `template`'s.
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
            coupling: template.coupling.map(|_| CrossCoupling {
                cxz: self.cxz,
                czx: self.czx,
                kxz: self.kxz,
                kzx: self.kzx,
            }),
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
    if let Some(c) = p.coupling {
        check("cxz", c.cxz, "finite (N s/m)", |_| true)?;
        check("czx", c.czx, "finite (N s/m)", |_| true)?;
        check("kxz", c.kxz, "finite (N/m)", |_| true)?;
        check("kzx", c.kzx, "finite (N/m)", |_| true)?;
    }
    Ok(())
}
