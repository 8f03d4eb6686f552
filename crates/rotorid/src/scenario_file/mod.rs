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
mod parse;

use std::collections::BTreeMap;
use std::fmt;

pub use error::ScenarioFileError;

use crate::model::ModelError;
use crate::{InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile, Unbalance};

/// The name of the built-in scenario, the paper's Table 1 ([`Scenario::table1`]).
pub const BUILTIN_TABLE1: &str = "table1";

/// Keys allowed in each section, with the unit shown in messages.
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
}

/// A scenario file parsed and range-checked key by key, not yet required to be complete.
/// Obtain the views with [`ScenarioSpec::simulation`] and
/// [`ScenarioSpec::identification`].
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioSpec {
    origin: String,
    builtin: Option<Scenario>,
    rotor: Section,
    speed: Option<SpeedProfile>,
    sampling: Option<Section>,
    initial: Section,
    acquisition: Option<crate::acquisition::Acquisition>,
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
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Truth {
    /// m \[kg\] (common to both directions).
    pub m: Option<f64>,
    /// cx \[N s/m\].
    pub cx: Option<f64>,
    /// cz \[N s/m\].
    pub cz: Option<f64>,
    /// kx \[N/m\].
    pub kx: Option<f64>,
    /// kz \[N/m\].
    pub kz: Option<f64>,
}

impl Truth {
    /// All five values of a validated rotor.
    pub fn from_rotor(r: &Rotor) -> Self {
        Self {
            m: Some(r.m()),
            cx: Some(r.cx()),
            cz: Some(r.cz()),
            kx: Some(r.kx()),
            kz: Some(r.kz()),
        }
    }

    /// True when no parameter is known.
    pub fn is_empty(&self) -> bool {
        [self.m, self.cx, self.cz, self.kx, self.kz]
            .iter()
            .all(Option::is_none)
    }
}

/// What `identify` needs from a scenario: the known quantities of eq. (1), the optional
/// truth, and the optional speed profile and sampling grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentificationScenario {
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
            rotor: Section::default(),
            speed: None,
            sampling: None,
            initial: Section::default(),
            acquisition: None,
        }
    }

    /// The `[acquisition]` table (probes, keyphasor, slow roll, raw-simulation settings),
    /// when the file has one; every key was checked when parsed. Its `slow_roll` path is as
    /// written, relative to the scenario file.
    pub fn acquisition(&self) -> Option<&crate::acquisition::Acquisition> {
        self.acquisition.as_ref()
    }

    /// Parse and check the TOML `text`; `origin` (the file name) prefixes every message.
    pub fn parse(origin: &str, text: &str) -> Result<Self, ScenarioFileError> {
        parse::Parser { origin, text }.parse()
    }

    /// Where the scenario came from: `table1` or the file path.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The complete scenario a simulation needs; `ov` (command-line values) take
    /// precedence.
    pub fn simulation(&self, ov: &SimulationOverrides) -> Result<Scenario, ScenarioFileError> {
        let o = &self.origin;
        let mut sc = match &self.builtin {
            Some(s) => *s,
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

    /// What the identification pipeline knows from this scenario: the known a and
    /// unbalance, its m, c, k (those stated) as nominal values and as the truth, and, when
    /// the scenario describes a whole simulation, its initial state as the true state at
    /// t = 0. The speed profile is in [`Self::identification`].
    pub fn knowledge(&self) -> Result<crate::pipeline::Knowledge, ScenarioFileError> {
        let v = self.identification()?;
        let t = &v.truth;
        let values = crate::pipeline::RotorValues {
            m: t.m,
            cx: t.cx,
            kx: t.kx,
            cz: t.cz,
            kz: t.kz,
        };
        // any grid will do: only the initial state is wanted
        let grid = SimulationOverrides {
            dt: Some(1.0),
            duration: Some(1.0),
            ..SimulationOverrides::default()
        };
        let initial = self.simulation(&grid).ok().map(|s| s.initial);
        Ok(crate::pipeline::Knowledge {
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
        if let Some(s) = &self.builtin {
            let u = s.rotor.unbalance();
            return Ok(IdentificationScenario {
                a: s.rotor.a(),
                m_u: u.m_u,
                d: u.d,
                alpha: u.alpha,
                truth: Truth::from_rotor(&s.rotor),
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
        Ok(IdentificationScenario {
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
            },
            speed: self.speed,
            sampling,
        })
    }

    fn require_rotor(&self, key: &'static str, who: &str) -> Result<f64, ScenarioFileError> {
        match self.rotor.get(key) {
            Some(n) => Ok(n.value),
            None => Err(ScenarioFileError::MissingRotorKey {
                origin: self.origin.clone(),
                key: key.to_owned(),
                unit: unit_of(&ROTOR_KEYS, key).to_owned(),
                section_line: self.rotor.line,
                needed_by: Some(who.to_owned()),
            }),
        }
    }

    /// The rotor of a complete `[rotor]` (all nine keys), whatever else the scenario
    /// lacks (a raw acquisition's scenario has no `[speed]`: its keyphasor gives the
    /// speed), or the built-in scenario's; `who` needs it (named in the error of a missing
    /// key).
    pub fn rotor(&self, who: &str) -> Result<Rotor, ScenarioFileError> {
        match &self.builtin {
            Some(s) => Ok(s.rotor),
            None => self.rotor_for(who),
        }
    }

    fn rotor_for_simulation(&self) -> Result<Rotor, ScenarioFileError> {
        self.rotor_for("simulate")
    }

    fn rotor_for(&self, who: &str) -> Result<Rotor, ScenarioFileError> {
        let mut v = [0.0; 9];
        for (i, (k, _)) in ROTOR_KEYS.iter().enumerate() {
            v[i] = self.require_rotor(k, who)?;
        }
        // Values were range-checked when parsed; this cannot fail, but keep the mapping.
        Rotor::new(rotor_params(&v)).map_err(|e| self.rotor_error(e))
    }

    fn rotor_error(&self, e: ModelError) -> ScenarioFileError {
        let line = match &e {
            ModelError::OutOfRange { field, .. } => {
                let key = rotor_key(field);
                self.rotor.get(key).and_then(|n| n.line)
            }
            ModelError::Inconsistent(_) => self.rotor.line,
        };
        ScenarioFileError::from_model(&self.origin, line, e, &ROTOR_KEY_NAMES)
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
                ModelError::Inconsistent(_) => sec.line,
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

fn rotor_key(model_field: &str) -> &'static str {
    match model_field {
        "alpha" => "alpha_deg",
        f => ROTOR_KEYS
            .iter()
            .map(|(k, _)| *k)
            .find(|k| *k == f)
            .unwrap_or("?"),
    }
}

/// The model's rotor field names and the TOML keys they are written as.
const ROTOR_KEY_NAMES: [(&str, &str); 9] = [
    ("m", "rotor.m"),
    ("cx", "rotor.cx"),
    ("cz", "rotor.cz"),
    ("kx", "rotor.kx"),
    ("kz", "rotor.kz"),
    ("a", "rotor.a"),
    ("m_u", "rotor.m_u"),
    ("d", "rotor.d"),
    ("alpha", "rotor.alpha_deg"),
];

/// RotorParams from the nine values in `ROTOR_KEYS` order (alpha in degrees).
fn rotor_params(v: &[f64; 9]) -> RotorParams {
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
    }
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
}
