//! Scenario files: the rotor of the paper's eq. (1) ([`crate::model`]), its speed profile,
//! the sampling grid and the initial state, written in TOML with SI units. Behind the
//! `toml` feature; this module parses text only (reading the file is the caller's).
//!
//! ```toml
//! [rotor]
//! m = 14.29        # kg          modal mass of the disk (common to x and z), > 0
//! cx = 10.0        # N s/m       support damping in x, >= 0 (cz likewise)
//! cz = 10.0
//! kx = 1.195e6     # N/m         support stiffness in x, > 0 (kz likewise)
//! kz = 1.195e6
//! a = 2.871        # N s^2/m     gyroscopic coefficient
//! m_u = 1.0e-4     # kg          unbalance mass, >= 0
//! d = 0.15         # m           unbalance radius, >= 0
//! alpha_deg = 45.0 # deg         unbalance angular position
//!
//! [speed]
//! kind = "constant"  # rpm = 1200.0 (rev/min): w = rpm 2 pi / 60 rad/s
//! rpm = 1200.0
//! # kind = "ramp":   rpm0 = 0.0 (rev/min), accel = 10.0 (rad/s^2): w(t) = w0 + accel t
//! # optional for both: phi0_deg = 0.0 (deg), the rotor angle phi(0)
//!
//! [sampling]
//! dt = 1.0e-4      # s
//! duration = 1.0   # s          samples t_i = i dt, i = 0 ..= floor(duration / dt)
//!
//! [initial]        # optional, every key defaults to 0
//! x = 0.0          # m          (z likewise)
//! vx = 0.0         # m/s        (vz likewise)
//! ```
//!
//! `rotor.model` chooses the rotor model (docs/method.md section 1.6): `"jeffcott"` (the
//! default, the keys above) or `"cross_coupled"`, the same rotor on bearings with all eight
//! coefficients, whose keys are m, a, kxx, kxz, kzx, kzz (N/m), cxx, cxz, czx, czz (N s/m),
//! m_u, d, alpha_deg. Cross terms may have any sign; the direct stiffnesses must be > 0 and
//! the damping matrix's symmetric part positive semi-definite. A caller may override the
//! model ([`ScenarioSpec::with_model`], `--model`): a Jeffcott rotor is the cross-coupled
//! one with zero cross terms, and a cross-coupled rotor's direct coefficients are the
//! Jeffcott model's cx, kx, cz, kz.
//!
//! `rotor.model = "finite_element"` is a rotor whose shaft and disks come as
//! matrices: `[rotor]` then holds `matrices` (the path of the matrices file, relative to
//! the scenario file), `[[rotor.bearing]]` and `[[rotor.unbalance]]` tables
//! ([`FiniteElementSpec`], whose module doc lists the keys). The caller reads the matrices
//! file and joins it with the spec ([`FiniteElementSpec::rotor`]); the lumped rotor's
//! views below refuse such a scenario, naming the model.
//!
//! Any form of TOML that names the same keys is the same file: dotted keys
//! (`rotor.m = 14.29`, `speed.kind = "constant"` at the top), inline tables
//! (`sampling = { dt = 1.0e-4, duration = 1.0 }`) and sections may be mixed, one form per
//! section. Integers are accepted wherever a number is expected (`kx = 1195000`); TOML's
//! `nan` and `inf` are read and then rejected by the range checks.
//!
//! The text is parsed once into a [`ScenarioSpec`], which checks every key that is present
//! (unknown keys, wrong types, out-of-range values) and offers two views:
//!
//! - [`ScenarioSpec::simulation`]: everything is required (rotor, speed, sampling); the
//!   caller may override `sampling.dt`, `sampling.duration` and `[initial]`
//!   ([`SimulationOverrides`], named by their command-line flags in messages).
//! - [`ScenarioSpec::identification`]: only what the identifier must know (`a`, `m_u`, `d`,
//!   `alpha_deg`); `m`, `cx`, `cz`, `kx`, `kz` are optional and used only as the truth to
//!   report errors against; `[speed]` is optional (needed only when the response has no
//!   phi columns) and `[sampling]` is optional.
//!
//! Every error ([`ScenarioFileError`]) names the file, the line (as editors count, from the
//! TOML parser's spans, for dotted keys and inline-table entries too), the key as
//! `section.key`, the value and the allowed range with its unit, e.g.
//! `rig.toml:7: rotor.kx = -1195000 is out of range: must be finite and > 0 (N/m)`. Range
//! rules and their words are the model's own ([`ModelError`]), with the model's field name
//! mapped to the TOML key.
//!
//! The TOML reader is in `parse.rs`; this file holds the parsed form and its views.
//! [`BUILTIN_TABLE1`] is the name callers give the built-in [`Scenario::table1`] (paper's
//! Table 1, 1200 rpm, dt = 0.1 ms, 1 s, at rest): see [`ScenarioSpec::builtin`].

mod acquisition;
mod error;
mod finite_element;
mod parse;
mod text;

use std::collections::BTreeMap;
use std::fmt;

pub use acquisition::FeAcquisitionSpec;
pub use error::{RotorModel, ScenarioFileError};
pub use finite_element::{FiniteElementSpec, FINITE_ELEMENT};

use crate::model::{CrossCoupling, ModelError};
use crate::parameter::ModelKind;
use crate::{InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile, Unbalance};

/// The name of the built-in scenario, the paper's Table 1 ([`Scenario::table1`]).
pub const BUILTIN_TABLE1: &str = "table1";

/// Keys allowed in each section, with the unit shown in messages. `[rotor]` also takes
/// `model` (a string) and, with `model = "cross_coupled"`, [`CROSS_ROTOR_KEYS`] instead.
const ROTOR_KEYS: [(&str, &str); 9] = [
    ("m", "kg"),
    ("cx", "N s/m"),
    ("cz", "N s/m"),
    ("kx", "N/m"),
    ("kz", "N/m"),
    ("a", "N s^2/m"),
    ("m_u", "kg"),
    ("d", "m"),
    ("alpha_deg", "deg"),
];
/// The keys of `[rotor]` in the cross-coupled model.
const CROSS_ROTOR_KEYS: [(&str, &str); 13] = [
    ("m", "kg"),
    ("a", "N s^2/m"),
    ("kxx", "N/m"),
    ("kxz", "N/m"),
    ("kzx", "N/m"),
    ("kzz", "N/m"),
    ("cxx", "N s/m"),
    ("cxz", "N s/m"),
    ("czx", "N s/m"),
    ("czz", "N s/m"),
    ("m_u", "kg"),
    ("d", "m"),
    ("alpha_deg", "deg"),
];
/// Every value of `[rotor]` is kept under one name whatever the model calls it: the
/// direct coefficients under the Jeffcott model's names (cxx is kept as cx).
const CANONICAL: [(&str, &str); 4] = [("cxx", "cx"), ("czz", "cz"), ("kxx", "kx"), ("kzz", "kz")];
/// The keys of `[rotor]` of `model`.
fn rotor_keys(model: ModelKind) -> &'static [(&'static str, &'static str)] {
    match model {
        ModelKind::Jeffcott => &ROTOR_KEYS,
        ModelKind::CrossCoupled => &CROSS_ROTOR_KEYS,
    }
}
/// The name a value is kept under (module doc of [`CANONICAL`]).
fn canonical(key: &'static str) -> &'static str {
    CANONICAL
        .iter()
        .find(|(k, _)| *k == key)
        .map_or(key, |(_, c)| *c)
}
/// The key `model` writes for the value kept as `canonical`.
fn written_key(model: ModelKind, canonical: &str) -> &'static str {
    rotor_keys(model)
        .iter()
        .map(|(k, _)| *k)
        .find(|k| self::canonical(k) == canonical)
        .unwrap_or("?")
}
const SPEED_KEYS: [(&str, &str); 5] = [
    ("kind", "\"constant\" or \"ramp\""),
    ("rpm", "rev/min"),
    ("rpm0", "rev/min"),
    ("accel", "rad/s^2"),
    ("phi0_deg", "deg"),
];
const SAMPLING_KEYS: [(&str, &str); 2] = [("dt", "s"), ("duration", "s")];
const INITIAL_KEYS: [(&str, &str); 4] = [("x", "m"), ("z", "m"), ("vx", "m/s"), ("vz", "m/s")];
const SECTIONS: [&str; 4] = ["rotor", "speed", "sampling", "initial"];
// `[acquisition]` is parsed apart (`acquisition.rs`): it has sub-tables and arrays.
/// What `[rotor]` and `[speed]` hold, for the messages about a missing section.
const ROTOR_CONTENTS: &str = "a, m_u, d, alpha_deg and, to simulate, m, cx, cz, kx, kz";
const SPEED_CONTENTS: &str = "kind = \"constant\" with rpm, or kind = \"ramp\" with rpm0 and accel";

/// The shape of the speed profile named by `speed.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedKind {
    /// `kind = "constant"`: `rpm`.
    Constant,
    /// `kind = "ramp"`: `rpm0` and `accel`.
    Ramp,
}

impl fmt::Display for SpeedKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Constant => "constant",
            Self::Ramp => "ramp",
        })
    }
}

/// A number read from the scenario file (or given on the command line), with its origin.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Num {
    /// The value as written (user units: deg for `*_deg`, rev/min for `rpm*`).
    value: f64,
    /// 1-based line in the file; `None` for command-line values and built-ins.
    line: Option<usize>,
}

/// A parsed `[section]`: its line and the numeric keys present.
#[derive(Debug, Clone, Default, PartialEq)]
struct Section {
    line: Option<usize>,
    keys: BTreeMap<&'static str, Num>,
}

impl Section {
    fn get(&self, key: &str) -> Option<Num> {
        self.keys.get(key).copied()
    }

    /// The same values under their canonical names ([`CANONICAL`]).
    fn canonical(self) -> Self {
        Self {
            line: self.line,
            keys: self
                .keys
                .into_iter()
                .map(|(k, v)| (canonical(k), v))
                .collect(),
        }
    }
}

/// A scenario file parsed and range-checked key by key, not yet required to be complete.
/// Obtain the views with [`ScenarioSpec::simulation`] and
/// [`ScenarioSpec::identification`].
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioSpec {
    origin: String,
    builtin: Option<Scenario>,
    /// The rotor model (`rotor.model`, or the override of [`Self::with_model`]).
    model: ModelKind,
    /// The model the file's `[rotor]` keys are written in.
    written_model: ModelKind,
    /// The `[rotor]` values, under their canonical names ([`CANONICAL`]).
    rotor: Section,
    speed: Option<SpeedProfile>,
    sampling: Option<Section>,
    initial: Section,
    acquisition: Option<crate::acquisition::Acquisition>,
    /// The `[acquisition]` of a finite-element rotor (probes at nodes).
    fe_acquisition: Option<FeAcquisitionSpec>,
    /// The rotor when `rotor.model = "finite_element"` (then `rotor` holds no key).
    finite_element: Option<FiniteElementSpec>,
}

/// Command-line values that take precedence over the scenario file in `simulate`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SimulationOverrides {
    /// `--dt` \[s\].
    pub dt: Option<f64>,
    /// `--duration` \[s\].
    pub duration: Option<f64>,
    /// `--initial-x` \[m\].
    pub x: Option<f64>,
    /// `--initial-z` \[m\].
    pub z: Option<f64>,
    /// `--initial-vx` \[m/s\].
    pub vx: Option<f64>,
    /// `--initial-vz` \[m/s\].
    pub vz: Option<f64>,
}

/// True values of the identified parameters, when the scenario states them (for reporting
/// the identification error only; the identifier never sees them).
pub type Truth = crate::pipeline::RotorValues;

/// What `identify` needs from a scenario: the known quantities of eq. (1), the optional
/// truth, and the optional speed profile and sampling grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentificationScenario {
    /// The rotor model.
    pub model: ModelKind,
    /// Gyroscopic coefficient a \[N s^2/m\].
    pub a: f64,
    /// Unbalance mass m_u \[kg\].
    pub m_u: f64,
    /// Unbalance radius d \[m\].
    pub d: f64,
    /// Unbalance angular position alpha \[rad\].
    pub alpha: f64,
    /// True m, c, k when the scenario states them.
    pub truth: Truth,
    /// The speed profile, to compute phi, w, w' at each sample when the response has no
    /// phi columns.
    pub speed: Option<SpeedProfile>,
    /// The sampling grid, if the scenario has one (informative only: `identify` takes the
    /// period from the data).
    pub sampling: Option<Sampling>,
}

impl IdentificationScenario {
    /// The quantities the algebraic identifier takes as known: a, m_u d, alpha.
    pub fn known(&self) -> crate::identify::Known {
        crate::identify::Known {
            a: self.a,
            mud: self.m_u * self.d,
            alpha: self.alpha,
        }
    }
}

impl ScenarioSpec {
    /// A spec holding an already validated scenario (`origin` names it in messages), e.g.
    /// `ScenarioSpec::builtin(BUILTIN_TABLE1, Scenario::table1())`.
    pub fn builtin(origin: &str, scenario: Scenario) -> Self {
        Self {
            origin: origin.to_owned(),
            builtin: Some(scenario),
            model: scenario.rotor.model(),
            written_model: scenario.rotor.model(),
            rotor: Section::default(),
            speed: None,
            sampling: None,
            initial: Section::default(),
            acquisition: None,
            fe_acquisition: None,
            finite_element: None,
        }
    }

    /// The `[acquisition]` table (probes, keyphasor, slow roll, raw-simulation settings),
    /// when the file has one; every key was checked when parsed. Its `slow_roll` path is as
    /// written, relative to the scenario file.
    pub fn acquisition(&self) -> Option<&crate::acquisition::Acquisition> {
        self.acquisition.as_ref()
    }

    /// The `[acquisition]` table of a finite-element scenario (two probes per measured
    /// node, `[[acquisition.probe]] node = N`), when the file has one; its nodes are
    /// checked against the matrices by [`FeAcquisitionSpec::checked`]. A finite-element
    /// scenario has no [`Self::acquisition`].
    pub fn fe_acquisition(&self) -> Option<&FeAcquisitionSpec> {
        self.fe_acquisition.as_ref()
    }

    /// The finite-element rotor's `[rotor]` (its matrices file as written, relative to the
    /// scenario file, its bearings and unbalances), when `rotor.model = "finite_element"`;
    /// the lumped rotor's views ([`Self::simulation`], [`Self::identification`],
    /// [`Self::rotor`]) then refuse the scenario.
    pub fn finite_element(&self) -> Option<&FiniteElementSpec> {
        self.finite_element.as_ref()
    }

    /// The error of a lumped rotor's view `who` of a finite-element scenario.
    fn refuse_finite_element(&self, who: &str) -> Result<(), ScenarioFileError> {
        match self.finite_element {
            Some(_) => Err(ScenarioFileError::FiniteElementRotor {
                origin: self.origin.clone(),
                line: self.rotor.line,
                who: who.to_owned(),
            }),
            None => Ok(()),
        }
    }

    /// Parse and check the TOML `text`; `origin` (the file name) prefixes every message.
    pub fn parse(origin: &str, text: &str) -> Result<Self, ScenarioFileError> {
        text::Parser { origin, text }.parse()
    }

    /// Where the scenario came from: `table1` or the file path.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The rotor model (`rotor.model`, default `jeffcott`, or the override).
    pub fn model(&self) -> ModelKind {
        self.model
    }

    /// The same scenario in `model` (module doc): a Jeffcott rotor becomes the cross-coupled
    /// rotor with zero cross terms; a cross-coupled rotor's cross terms are dropped in the
    /// Jeffcott model (they are reported as the truth no longer).
    pub fn with_model(mut self, model: ModelKind) -> Self {
        self.model = model;
        self
    }

    /// The complete scenario a simulation needs; `ov` (command-line values) take
    /// precedence.
    pub fn simulation(&self, ov: &SimulationOverrides) -> Result<Scenario, ScenarioFileError> {
        self.refuse_finite_element("simulate")?;
        let o = &self.origin;
        let mut sc = match &self.builtin {
            Some(s) => Scenario {
                rotor: in_model(&s.rotor, self.model),
                ..*s
            },
            None => {
                let rotor = self.rotor_for_simulation()?;
                let speed = match self.speed {
                    Some(p) => p,
                    None => {
                        return Err(ScenarioFileError::MissingSection {
                            origin: o.clone(),
                            section: "speed".to_owned(),
                            contents: SPEED_CONTENTS.to_owned(),
                            needed_by: Some("simulate".to_owned()),
                        })
                    }
                };
                let sampling = self.sampling_with(ov)?;
                let initial = self.initial_with(ov)?;
                return Ok(Scenario {
                    rotor,
                    speed,
                    sampling,
                    initial,
                });
            }
        };
        if ov.dt.is_some() || ov.duration.is_some() {
            let dt = ov.dt.unwrap_or(sc.sampling.dt());
            let duration = ov.duration.unwrap_or(sc.sampling.duration());
            sc.sampling = Sampling::new(dt, duration).map_err(|e| {
                ScenarioFileError::from_model(
                    o,
                    None,
                    e,
                    &[("dt", "--dt"), ("duration", "--duration")],
                )
            })?;
        }
        let mut init = sc.initial;
        init.x = ov.x.unwrap_or(init.x);
        init.z = ov.z.unwrap_or(init.z);
        init.vx = ov.vx.unwrap_or(init.vx);
        init.vz = ov.vz.unwrap_or(init.vz);
        sc.initial = init
            .validated()
            .map_err(|e| ScenarioFileError::from_model(o, None, e, INITIAL_FLAGS))?;
        Ok(sc)
    }

    /// The `[speed]` profile, when the file has one (any model).
    pub fn speed_profile(&self) -> Option<&SpeedProfile> {
        self.speed.as_ref()
    }

    /// The speed profile and sampling grid of a finite-element scenario's simulation
    /// (`ov`'s dt and duration take precedence; its initial state is refused: a
    /// finite-element simulation starts at rest).
    pub fn fe_simulation(
        &self,
        ov: &SimulationOverrides,
    ) -> Result<(SpeedProfile, Sampling), ScenarioFileError> {
        if self.finite_element.is_none() {
            return Err(ScenarioFileError::Inconsistent {
                origin: self.origin.clone(),
                line: self.rotor.line,
                message: format!(
                    "rotor.model is \"{}\": a finite-element simulation needs rotor.model = \
                     \"finite_element\"",
                    self.model.name()
                ),
            });
        }
        let speed = self
            .speed
            .ok_or_else(|| ScenarioFileError::MissingSection {
                origin: self.origin.clone(),
                section: "speed".to_owned(),
                contents: SPEED_CONTENTS.to_owned(),
                needed_by: Some("simulate".to_owned()),
            })?;
        Ok((speed, self.sampling_with(ov)?))
    }

    /// What the identification pipeline knows from this scenario: the known a and
    /// unbalance, its m, c, k (those stated) as nominal values and as the truth, and, when
    /// the scenario describes a whole simulation, its initial state as the true state at
    /// t = 0. The speed profile is in [`Self::identification`].
    pub fn knowledge(&self) -> Result<crate::pipeline::Knowledge, ScenarioFileError> {
        let v = self.identification()?;
        let values = v.truth;
        let t = &v.truth;
        // any grid will do: only the initial state is wanted
        let grid = SimulationOverrides {
            dt: Some(1.0),
            duration: Some(1.0),
            ..SimulationOverrides::default()
        };
        let initial = self.simulation(&grid).ok().map(|s| s.initial);
        Ok(crate::pipeline::Knowledge {
            model: self.model,
            a: v.a,
            unbalance: Unbalance {
                m_u: v.m_u,
                d: v.d,
                alpha: v.alpha,
            },
            nominal: values,
            truth: (!t.is_empty()).then_some(crate::pipeline::Truth { values, initial }),
        })
    }

    /// What `identify` needs: known a, m_u, d, alpha; optional truth, speed, sampling.
    pub fn identification(&self) -> Result<IdentificationScenario, ScenarioFileError> {
        self.refuse_finite_element("identify")?;
        if let Some(s) = &self.builtin {
            let rotor = in_model(&s.rotor, self.model);
            let u = rotor.unbalance();
            return Ok(IdentificationScenario {
                model: self.model,
                a: rotor.a(),
                m_u: u.m_u,
                d: u.d,
                alpha: u.alpha,
                truth: Truth::of(&rotor.params()),
                speed: Some(s.speed),
                sampling: Some(s.sampling),
            });
        }
        let need = |key: &'static str| self.require_rotor(key, "identify");
        let (a, m_u, d, alpha_deg) = (need("a")?, need("m_u")?, need("d")?, need("alpha_deg")?);
        let opt = |k: &str| self.rotor.get(k).map(|n| n.value);
        let sampling = match &self.sampling {
            Some(s) => match (s.get("dt"), s.get("duration")) {
                (Some(_), Some(_)) => Some(self.sampling_with(&SimulationOverrides::default())?),
                _ => None,
            },
            None => None,
        };
        // a Jeffcott rotor's cross terms are 0 (stated, in the cross-coupled model)
        let cross = |k: &str| match (self.model, self.written_model) {
            (ModelKind::Jeffcott, _) => None,
            (ModelKind::CrossCoupled, ModelKind::Jeffcott) => Some(0.0),
            (ModelKind::CrossCoupled, ModelKind::CrossCoupled) => opt(k),
        };
        Ok(IdentificationScenario {
            model: self.model,
            a,
            m_u,
            d,
            alpha: alpha_deg.to_radians(),
            truth: Truth {
                m: opt("m"),
                cx: opt("cx"),
                cz: opt("cz"),
                kx: opt("kx"),
                kz: opt("kz"),
                cxz: cross("cxz"),
                czx: cross("czx"),
                kxz: cross("kxz"),
                kzx: cross("kzx"),
            },
            speed: self.speed,
            sampling,
        })
    }

    /// The value kept as `key` (a canonical name, [`CANONICAL`]); missing, an error
    /// naming the key as the file's model writes it.
    fn require_rotor(&self, key: &'static str, who: &str) -> Result<f64, ScenarioFileError> {
        match self.rotor.get(key) {
            Some(n) => Ok(n.value),
            None => {
                let written = written_key(self.written_model, key);
                Err(ScenarioFileError::MissingRotorKey {
                    origin: self.origin.clone(),
                    key: written.to_owned(),
                    unit: unit_of(rotor_keys(self.written_model), written).to_owned(),
                    section_line: self.rotor.line,
                    needed_by: Some(who.to_owned()),
                })
            }
        }
    }

    /// The rotor of a complete `[rotor]` (all nine keys), whatever else the scenario
    /// lacks (a raw acquisition's scenario has no `[speed]`: its keyphasor gives the
    /// speed), or the built-in scenario's; `who` needs it (named in the error of a missing
    /// key).
    pub fn rotor(&self, who: &str) -> Result<Rotor, ScenarioFileError> {
        self.refuse_finite_element(who)?;
        match &self.builtin {
            Some(s) => Ok(s.rotor),
            None => self.rotor_for(who),
        }
    }

    fn rotor_for_simulation(&self) -> Result<Rotor, ScenarioFileError> {
        self.rotor_for("simulate")
    }

    fn rotor_for(&self, who: &str) -> Result<Rotor, ScenarioFileError> {
        let mut v = RotorArray::default();
        for (i, k) in CANONICAL_ORDER.iter().enumerate() {
            let cross = i >= 9;
            v.0[i] = if cross && self.written_model == ModelKind::Jeffcott {
                0.0
            } else {
                self.require_rotor(k, who)?
            };
        }
        // Values were range-checked when parsed; this cannot fail, but keep the mapping.
        Rotor::new(v.params(self.model))
            .map_err(|e| rotor_error(&self.origin, &self.rotor, self.written_model, e))
    }

    fn sampling_with(&self, ov: &SimulationOverrides) -> Result<Sampling, ScenarioFileError> {
        let o = &self.origin;
        let sec = self.sampling.clone().unwrap_or_default();
        let pick = |key: &str, flag: &str, v: Option<f64>| match (v, sec.get(key)) {
            (Some(value), _) => Ok(Num { value, line: None }),
            (None, Some(n)) => Ok(n),
            (None, None) => Err(ScenarioFileError::MissingSamplingKey {
                origin: o.clone(),
                key: key.to_owned(),
                flag: flag.to_owned(),
            }),
        };
        let dt = pick("dt", "--dt", ov.dt)?;
        let duration = pick("duration", "--duration", ov.duration)?;
        Sampling::new(dt.value, duration.value).map_err(|e| {
            let line = match &e {
                ModelError::OutOfRange { field: "dt", .. } => dt.line,
                ModelError::OutOfRange { .. } => duration.line,
                _ => sec.line,
            };
            let dt_key = if ov.dt.is_some() {
                "--dt"
            } else {
                "sampling.dt"
            };
            let du_key = if ov.duration.is_some() {
                "--duration"
            } else {
                "sampling.duration"
            };
            ScenarioFileError::from_model(o, line, e, &[("dt", dt_key), ("duration", du_key)])
        })
    }

    fn initial_with(&self, ov: &SimulationOverrides) -> Result<InitialState, ScenarioFileError> {
        let get = |k: &str, v: Option<f64>| v.or(self.initial.get(k).map(|n| n.value));
        let s = InitialState {
            x: get("x", ov.x).unwrap_or(0.0),
            z: get("z", ov.z).unwrap_or(0.0),
            vx: get("vx", ov.vx).unwrap_or(0.0),
            vz: get("vz", ov.vz).unwrap_or(0.0),
        };
        s.validated()
            .map_err(|e| ScenarioFileError::from_model(&self.origin, None, e, INITIAL_FLAGS))
    }
}

const INITIAL_FLAGS: &[(&str, &str)] = &[
    ("x0", "--initial-x"),
    ("z0", "--initial-z"),
    ("vx0", "--initial-vx"),
    ("vz0", "--initial-vz"),
];

/// A model error about `[rotor]` (values kept under canonical names, written in
/// `written`) as a scenario error naming the key and its line.
fn rotor_error(
    origin: &str,
    rotor: &Section,
    written: ModelKind,
    e: ModelError,
) -> ScenarioFileError {
    // the model names its fields after the model (cxx when coupled); the file after its own
    let key = |field: &str| {
        let c = if field == "alpha" {
            "alpha_deg"
        } else {
            canonical_static(field)
        };
        written_key(written, c)
    };
    match e {
        ModelError::OutOfRange { field, .. } => {
            let line = rotor.get(canonical_static(field)).and_then(|n| n.line);
            let name = format!("rotor.{}", key(field));
            ScenarioFileError::from_model(origin, line, e, &[(field, name.as_str())])
        }
        ModelError::Inconsistent(_) => ScenarioFileError::from_model(origin, rotor.line, e, &[]),
        ModelError::DampingNotDissipative { cxx, cxz, czx, czz } => {
            ScenarioFileError::DampingNotDissipative {
                origin: origin.to_owned(),
                line: rotor.line,
                cxx,
                cxz,
                czx,
                czz,
            }
        }
    }
}

/// The canonical name of a model field (`cxx` -> `cx`, `alpha` -> `alpha_deg`).
fn canonical_static(field: &str) -> &'static str {
    if field == "alpha" {
        return "alpha_deg";
    }
    CANONICAL_ORDER
        .iter()
        .chain(CANONICAL.iter().map(|(k, _)| k))
        .find(|k| **k == field)
        .map_or("?", |k| canonical(k))
}

/// The canonical names of every `[rotor]` value, in the order of [`RotorArray`].
const CANONICAL_ORDER: [&str; 13] = [
    "m",
    "cx",
    "cz",
    "kx",
    "kz",
    "a",
    "m_u",
    "d",
    "alpha_deg",
    "cxz",
    "czx",
    "kxz",
    "kzx",
];

/// Every `[rotor]` value in [`CANONICAL_ORDER`] (alpha in degrees).
#[derive(Debug, Clone, Copy, Default)]
struct RotorArray([f64; 13]);

impl RotorArray {
    /// The rotor parameters in `model` (the cross terms dropped for a Jeffcott rotor).
    fn params(&self, model: ModelKind) -> RotorParams {
        let v = &self.0;
        RotorParams {
            m: v[0],
            cx: v[1],
            cz: v[2],
            kx: v[3],
            kz: v[4],
            a: v[5],
            unbalance: Unbalance {
                m_u: v[6],
                d: v[7],
                alpha: v[8].to_radians(),
            },
            coupling: (model == ModelKind::CrossCoupled).then_some(CrossCoupling {
                cxz: v[9],
                czx: v[10],
                kxz: v[11],
                kzx: v[12],
            }),
        }
    }
}

/// `rotor` in `model`: a Jeffcott rotor gains zero cross terms, a cross-coupled one loses
/// its cross terms.
fn in_model(rotor: &Rotor, model: ModelKind) -> Rotor {
    let mut p = rotor.params();
    p.coupling = match model {
        ModelKind::Jeffcott => None,
        ModelKind::CrossCoupled => Some(p.cross()),
    };
    Rotor::new(p).unwrap_or(*rotor)
}

fn unit_of(keys: &[(&'static str, &'static str)], key: &str) -> &'static str {
    keys.iter().find(|(k, _)| *k == key).map_or("", |(_, u)| *u)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE1: &str = r#"
[rotor]
m = 14.29
cx = 10.0
cz = 10.0
kx = 1.195e6
kz = 1195000
a = 2.871
m_u = 1.0e-4
d = 0.15
alpha_deg = 45.0
[speed]
kind = "constant"
rpm = 1200.0
[sampling]
dt = 1.0e-4
duration = 1.0
"#;

    fn table1() -> ScenarioSpec {
        ScenarioSpec::builtin(BUILTIN_TABLE1, Scenario::table1())
    }

    fn err(text: &str) -> String {
        let e = ScenarioSpec::parse("s.toml", text)
            .and_then(|s| s.simulation(&SimulationOverrides::default()).map(|_| s));
        format!("{}", e.expect_err("must be rejected"))
    }

    #[test]
    fn the_toml_table1_equals_the_builtin() {
        let s = ScenarioSpec::parse("s.toml", TABLE1).unwrap();
        let sc = s.simulation(&SimulationOverrides::default()).unwrap();
        assert_eq!(sc, Scenario::table1());
        let b = table1();
        assert_eq!(b.simulation(&SimulationOverrides::default()).unwrap(), sc);
        assert_eq!(s.identification().unwrap(), b.identification().unwrap());
    }

    #[test]
    fn ramp_with_phase_and_initial_state() {
        let text = TABLE1.replace(
            "kind = \"constant\"\nrpm = 1200.0",
            "kind = \"ramp\"\nrpm0 = 600\naccel = 10\nphi0_deg = 90",
        ) + "[initial]\nx = 2e-7\nvz = 5e-5\n";
        let sc = ScenarioSpec::parse("s.toml", &text)
            .unwrap()
            .simulation(&SimulationOverrides::default())
            .unwrap();
        let SpeedProfile::Ramp {
            omega0,
            accel,
            phi0,
        } = sc.speed
        else {
            panic!("not a ramp: {:?}", sc.speed)
        };
        assert!((omega0 - 20.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(accel, 10.0);
        assert!((phi0 - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(sc.initial.x, 2e-7);
        assert_eq!(sc.initial.vz, 5e-5);
        assert_eq!(sc.initial.z, 0.0);
    }

    #[test]
    fn overrides_take_precedence_and_are_named_in_errors() {
        let s = table1();
        let ov = SimulationOverrides {
            dt: Some(2e-4),
            duration: Some(0.5),
            x: Some(1e-7),
            ..Default::default()
        };
        let sc = s.simulation(&ov).unwrap();
        assert_eq!(sc.sampling.dt(), 2e-4);
        assert_eq!(sc.sampling.samples(), 2501);
        assert_eq!(sc.initial.x, 1e-7);
        let bad = SimulationOverrides {
            dt: Some(-1.0),
            ..Default::default()
        };
        let e = format!("{}", s.simulation(&bad).unwrap_err());
        assert_eq!(
            e,
            "table1: --dt = -1 is out of range: must be finite and > 0 (s)"
        );
        let bad = SimulationOverrides {
            vx: Some(f64::NAN),
            ..Default::default()
        };
        let e = format!("{}", s.simulation(&bad).unwrap_err());
        assert!(e.contains("--initial-vx = NaN is out of range"), "{e}");
    }

    #[test]
    fn out_of_range_names_file_line_key_value_and_range() {
        let e = err(&TABLE1.replace("kx = 1.195e6", "kx = -5"));
        assert_eq!(
            e,
            "s.toml:6: rotor.kx = -5 is out of range: must be finite and > 0 (N/m)"
        );
        let e = err(&TABLE1.replace("m = 14.29", "m = nan"));
        assert_eq!(
            e,
            "s.toml:3: rotor.m = NaN is out of range: must be finite and > 0 (kg)"
        );
        let e = err(&TABLE1.replace("alpha_deg = 45.0", "alpha_deg = inf"));
        assert!(
            e.starts_with("s.toml:11: rotor.alpha_deg = inf is out of range"),
            "{e}"
        );
        let e = err(&TABLE1.replace("rpm = 1200.0", "rpm = -3"));
        assert!(
            e.starts_with("s.toml:14: speed.rpm = -3 is out of range"),
            "{e}"
        );
        let e = err(&TABLE1.replace("dt = 1.0e-4", "dt = 0"));
        assert!(
            e.starts_with("s.toml:16: sampling.dt = 0 is out of range: must be finite and > 0 (s)"),
            "{e}"
        );
        let e = err(&TABLE1.replace("duration = 1.0", "duration = 1e-5"));
        assert!(
            e.starts_with("s.toml:15: duration = 0.00001 s is shorter"),
            "{e}"
        );
    }

    #[test]
    fn unknown_missing_and_mistyped_keys_are_named() {
        let e = err(&TABLE1.replace("kx = 1.195e6", "kxx = 1.195e6"));
        assert!(
            e.starts_with("s.toml:6: unknown key rotor.kxx; allowed keys in [rotor]: m, cx"),
            "{e}"
        );
        let e = err(&TABLE1.replace("kx = 1.195e6\n", ""));
        assert!(
            e.starts_with("s.toml: missing key rotor.kx (N/m) (section [rotor] at line 2)"),
            "{e}"
        );
        let e = err(&TABLE1.replace("kx = 1.195e6", "kx = \"stiff\""));
        assert!(
            e.starts_with(
                "s.toml:6: rotor.kx = \"stiff\" has the wrong type: must be a number (N/m)"
            ),
            "{e}"
        );
        let e = err(&format!("{TABLE1}[extra]\ny = 1\n"));
        assert!(
            e.starts_with("s.toml:18: unknown section or key `extra`"),
            "{e}"
        );
        let e = err(&format!("top = 1\n{TABLE1}"));
        assert!(
            e.starts_with("s.toml:1: unknown section or key `top`"),
            "{e}"
        );
        let e = err(&format!(
            "rotor = 1\n{}",
            &TABLE1[TABLE1.find("[speed]").unwrap()..]
        ));
        assert!(
            e.starts_with("s.toml:1: `rotor` must be a section [rotor], found an integer"),
            "{e}"
        );
        let e = err(&TABLE1.replace("rpm = 1200.0", "rpm0 = 1200.0"));
        assert!(
            e.starts_with("s.toml:14: speed.rpm0 does not apply to kind = \"constant\""),
            "{e}"
        );
        let e = err(&TABLE1.replace("kind = \"constant\"", "kind = \"sine\""));
        assert!(
            e.starts_with("s.toml:13: speed.kind = \"sine\" is not a speed profile"),
            "{e}"
        );
        let e = err(&TABLE1.replace("kind = \"constant\"\n", ""));
        assert!(e.starts_with("s.toml:12: missing key speed.kind"), "{e}");
        let e = err(&TABLE1.replace("m = 14.29", "m = 14.29\nm = 3"));
        assert!(
            e.starts_with("s.toml:4: invalid TOML: duplicate key `m`"),
            "{e}"
        );
        let e = err("[rotor\n");
        assert!(e.starts_with("s.toml:1: invalid TOML"), "{e}");
        let e = err(&TABLE1[..TABLE1.find("[sampling]").unwrap()]);
        assert!(
            e.contains("missing key sampling.dt (s); give it in [sampling] or with --dt"),
            "{e}"
        );
    }

    #[test]
    fn identification_view_needs_only_the_known_quantities() {
        let s = ScenarioSpec::parse(
            "id.toml",
            "[rotor]\na = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45\nkx = 1e6\n",
        )
        .unwrap();
        let v = s.identification().unwrap();
        assert_eq!(v.truth.kx, Some(1e6));
        assert_eq!(v.truth.m, None);
        assert!(v.speed.is_none() && v.sampling.is_none());
        assert!((v.known().mud - 1.5e-5).abs() < 1e-20);
        assert!((v.alpha - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        // ... and simulate says what is missing.
        let e = format!(
            "{}",
            s.simulation(&SimulationOverrides::default()).unwrap_err()
        );
        assert!(e.starts_with("id.toml: missing key rotor.m (kg)"), "{e}");
        let s =
            ScenarioSpec::parse("id.toml", "[rotor]\na = 2.871\nm_u = 1e-4\nd = 0.15\n").unwrap();
        let e = format!("{}", s.identification().unwrap_err());
        assert!(
            e.starts_with("id.toml: missing key rotor.alpha_deg (deg)"),
            "{e}"
        );
    }

    /// TABLE1 written with dotted keys only, one key a line (line 1 is `rotor.m`).
    fn dotted_table1() -> String {
        let mut out = String::new();
        let mut section = "";
        for line in TABLE1.lines().filter(|l| !l.is_empty()) {
            match line.strip_prefix('[') {
                Some(name) => section = name.trim_end_matches(']'),
                None => out += &format!("{section}.{line}\n"),
            }
        }
        out
    }

    #[test]
    fn dotted_keys_are_the_same_file() {
        let text = dotted_table1();
        assert!(
            text.starts_with("rotor.m = 14.29\nrotor.cx = 10.0\n"),
            "{text}"
        );
        let s = ScenarioSpec::parse("d.toml", &text).unwrap();
        assert_eq!(
            s.simulation(&SimulationOverrides::default()).unwrap(),
            Scenario::table1()
        );
        assert_eq!(
            s.identification().unwrap(),
            table1().identification().unwrap()
        );
    }

    #[test]
    fn dotted_keys_are_named_at_their_own_line() {
        let text = dotted_table1();
        let e = err(&text.replace("rotor.kx = 1.195e6", "rotor.kx = -5"));
        assert_eq!(
            e,
            "s.toml:4: rotor.kx = -5 is out of range: must be finite and > 0 (N/m)"
        );
        let e = err(&text.replace("sampling.dt = 1.0e-4", "sampling.dt = 0"));
        assert!(
            e.starts_with("s.toml:12: sampling.dt = 0 is out of range"),
            "{e}"
        );
        let e = err(&text.replace("rotor.kz = 1195000", "rotor.kzz = 1195000"));
        assert!(
            e.starts_with("s.toml:5: unknown key rotor.kzz; allowed keys"),
            "{e}"
        );
        let e = err(&text.replace("rotor.a = 2.871", "rotor.a.b = 2.871"));
        assert!(
            e.starts_with("s.toml:6: rotor.a = {...} has the wrong type: must be a number"),
            "{e}"
        );
        // A section's line is that of its first dotted key.
        let e = err(&text.replace("speed.rpm = 1200.0\n", ""));
        assert_eq!(
            e,
            "s.toml:10: missing key speed.rpm (rev/min) for kind = \"constant\""
        );
        let e = err(&text.replace("rotor.m = 14.29\n", ""));
        assert!(
            e.starts_with("s.toml: missing key rotor.m (kg) (section [rotor] at line 1)"),
            "{e}"
        );
        let e = err(&format!("{text}rotor.m = 1\n"));
        assert!(
            e.starts_with("s.toml:14: invalid TOML: duplicate key `m`"),
            "{e}"
        );
    }

    #[test]
    fn inline_tables_and_mixed_forms_are_the_same_file() {
        let text = "\
rotor = { m = 14.29, cx = 10.0, cz = 10.0, kx = 1.195e6, kz = 1195000, a = 2.871, m_u = 1.0e-4, d = 0.15, alpha_deg = 45.0 }
speed.kind = \"constant\"
speed.rpm = 1200.0
[sampling]
dt = 1.0e-4
duration = 1.0
";
        let s = ScenarioSpec::parse("i.toml", text).unwrap();
        assert_eq!(
            s.simulation(&SimulationOverrides::default()).unwrap(),
            Scenario::table1()
        );
        let text = "sampling = { dt = 1.0e-4, duration = 1.0 }\n\n".to_owned() + TABLE1;
        let text = text.replace("[sampling]\ndt = 1.0e-4\nduration = 1.0\n", "");
        let s = ScenarioSpec::parse("i.toml", &text).unwrap();
        assert_eq!(
            s.simulation(&SimulationOverrides::default()).unwrap(),
            Scenario::table1()
        );
    }

    #[test]
    fn inline_table_entries_are_named_at_their_line() {
        let text = "\
# a rotor
rotor = { a = 2.871, m_u = 1e-4, d = 0.15, alpha_deg = 45 }

speed = { kind = \"ramp\", rpm0 = 0, accel = 10 }
initial = { x = 1e-6 }
";
        let s = ScenarioSpec::parse("i.toml", text).unwrap();
        assert!(matches!(
            s.identification().unwrap().speed,
            Some(SpeedProfile::Ramp { accel, .. }) if accel == 10.0
        ));
        let e = err(&text.replace("d = 0.15", "d = -1"));
        assert_eq!(
            e,
            "s.toml:2: rotor.d = -1 is out of range: must be finite and >= 0 (m)"
        );
        let e = err(&text.replace("m_u = 1e-4", "m_u = \"tiny\""));
        assert!(
            e.starts_with(
                "s.toml:2: rotor.m_u = \"tiny\" has the wrong type: must be a number (kg)"
            ),
            "{e}"
        );
        let e = err(&text.replace("kind = \"ramp\"", "kind = \"sine\""));
        assert!(
            e.starts_with("s.toml:4: speed.kind = \"sine\" is not a speed profile"),
            "{e}"
        );
        let e = err(&text.replace("accel = 10", "rpm = 10"));
        assert!(
            e.starts_with("s.toml:4: speed.rpm does not apply to kind = \"ramp\""),
            "{e}"
        );
        let e = err(&text.replace("{ x = 1e-6 }", "{ x = [1] }"));
        assert!(
            e.starts_with("s.toml:5: initial.x = [1] has the wrong type"),
            "{e}"
        );
        let e = err(&text.replace("rotor = {", "rotor = 3 #"));
        assert_eq!(
            e,
            "s.toml:2: `rotor` must be a section [rotor], found an integer"
        );
    }

    #[test]
    fn errors_carry_their_parts() {
        let text = TABLE1
            .replace("kx = 1.195e6", "kx = -5")
            .replace('\n', "\r\n");
        let e = ScenarioSpec::parse("rig.toml", &text).unwrap_err();
        assert_eq!((e.origin(), e.line()), ("rig.toml", Some(6)));
        let ScenarioFileError::OutOfRange {
            key,
            value,
            allowed,
            ..
        } = e
        else {
            panic!("not out of range: {e:?}")
        };
        assert_eq!(
            (key.as_str(), value, allowed.as_str()),
            ("rotor.kx", -5.0, "finite and > 0 (N/m)")
        );
        let e =
            ScenarioSpec::parse("rig.toml", "[speed]\nkind = \"constant\"\nrpm = 1\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "rig.toml: missing section [rotor] (a, m_u, d, alpha_deg and, to simulate, m, cx, \
             cz, kx, kz)"
        );
    }

    const CROSS: &str = r#"
[rotor]
model = "cross_coupled"
m = 14.29
a = 2.871
kxx = 1.195e6
kxz = -3.0e4
kzx = 3.0e4
kzz = 1.4e6
cxx = 200.0
cxz = 20.0
czx = -5.0
czz = 200.0
m_u = 1.0e-4
d = 0.15
alpha_deg = 45.0
[speed]
kind = "constant"
rpm = 1200.0
[sampling]
dt = 1.0e-4
duration = 1.0
"#;

    #[test]
    fn a_cross_coupled_rotor_reads_with_its_own_keys() {
        let spec = ScenarioSpec::parse("c.toml", CROSS).unwrap();
        assert_eq!(spec.model(), ModelKind::CrossCoupled);
        let sc = spec.simulation(&SimulationOverrides::default()).unwrap();
        let p = sc.rotor.params();
        let c = p.coupling.expect("cross-coupled");
        assert_eq!((p.kx, p.kz, p.cx, p.cz), (1.195e6, 1.4e6, 200.0, 200.0));
        assert_eq!((c.kxz, c.kzx, c.cxz, c.czx), (-3.0e4, 3.0e4, 20.0, -5.0));
        let id = spec.identification().unwrap();
        assert_eq!(id.model, ModelKind::CrossCoupled);
        assert_eq!((id.truth.kxz, id.truth.czx), (Some(-3.0e4), Some(-5.0)));
        let k = spec.knowledge().unwrap();
        assert_eq!(k.model, ModelKind::CrossCoupled);
        // --model jeffcott: the same rotor without its cross terms
        let j = spec.clone().with_model(ModelKind::Jeffcott);
        let sj = j.simulation(&SimulationOverrides::default()).unwrap();
        assert_eq!(sj.rotor.params().coupling, None);
        assert_eq!(j.identification().unwrap().truth.kxz, None);
        // a Jeffcott file in the cross-coupled model: zero cross terms, stated as such
        let t = table1().with_model(ModelKind::CrossCoupled);
        let st = t.simulation(&SimulationOverrides::default()).unwrap();
        assert_eq!(st.rotor.params().coupling, Some(CrossCoupling::default()));
        let file = ScenarioSpec::parse("s.toml", TABLE1)
            .unwrap()
            .with_model(ModelKind::CrossCoupled);
        let truth = file.identification().unwrap().truth;
        assert_eq!((truth.kx, truth.kzx), (Some(1.195e6), Some(0.0)));
        assert_eq!(
            file.simulation(&SimulationOverrides::default())
                .unwrap()
                .rotor
                .params()
                .coupling,
            Some(CrossCoupling::default())
        );
    }

    #[test]
    fn cross_coupled_errors_name_the_key_the_value_and_the_range() {
        let e = |text: &str| ScenarioSpec::parse("c.toml", text).unwrap_err().to_string();
        // the symmetric part of [[200, 20], [-5, 200]] is fine; make it indefinite
        let msg = e(&CROSS.replace("czx = -5.0", "czx = 500.0"));
        assert!(
            msg.starts_with("c.toml:2: rotor: the damping matrix [[cxx, cxz], [czx, czz]] = [[200, 20], [500, 200]] N s/m is not dissipative"),
            "{msg}"
        );
        let msg = e(&CROSS.replace("kzz = 1.4e6", "kzz = -1.4e6"));
        assert!(
            msg.starts_with(
                "c.toml:9: rotor.kzz = -1400000 is out of range: must be finite and > 0 (N/m)"
            ),
            "{msg}"
        );
        let msg = e(&CROSS.replace("cxx = 200.0", "cxx = -1.0"));
        assert!(
            msg.starts_with("c.toml:10: rotor.cxx = -1 is out of range"),
            "{msg}"
        );
        let msg = e(&CROSS.replace("kxz = -3.0e4", "kxz = nan"));
        assert!(
            msg.starts_with("c.toml:7: rotor.kxz = NaN is out of range: must be finite (N/m)"),
            "{msg}"
        );
        let msg = e(&CROSS.replace("kxx = 1.195e6", "kx = 1.195e6"));
        assert!(
            msg.starts_with("c.toml:6: unknown key rotor.kx; allowed keys in [rotor]: m, a, kxx")
                && msg.ends_with("(kx is a key of rotor.model = \"jeffcott\")"),
            "{msg}"
        );
        let msg = e(&TABLE1.replace("kx = 1.195e6", "kxz = 1.0"));
        assert!(
            msg.ends_with("(kxz is a key of rotor.model = \"cross_coupled\")"),
            "{msg}"
        );
        let msg = e(&CROSS.replace("\"cross_coupled\"", "\"fluid_film\""));
        assert_eq!(
            msg,
            "c.toml:3: rotor.model = \"fluid_film\" is not a rotor model: must be \"jeffcott\", \"cross_coupled\" or \"finite_element\""
        );
        let msg = e(&CROSS.replace("\"cross_coupled\"", "2"));
        assert!(
            msg.starts_with("c.toml:3: rotor.model = 2 has the wrong type"),
            "{msg}"
        );
        let spec = ScenarioSpec::parse("c.toml", &CROSS.replace("kzx = 3.0e4\n", "")).unwrap();
        let msg = spec
            .simulation(&SimulationOverrides::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("c.toml: missing key rotor.kzx (N/m)"),
            "{msg}"
        );
    }
}
