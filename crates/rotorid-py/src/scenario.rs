//! Scenarios as Python makes them: the built-in `table1`, a TOML file, or keyword
//! arguments named as the file's keys. All three become the library's
//! [`ScenarioSpec`] (crates/rotorid/src/scenario_file), so every range check and message
//! is the library's: keyword arguments are written as a TOML text and parsed, and their
//! messages name the key and its allowed range without the line of that text.

use std::fmt::Write as _;
use std::io::Read as _;

use rotorid::model::rad_per_s_to_rpm;
use rotorid::parameter::ModelKind;
use rotorid::pipeline::Knowledge;
use rotorid::scenario_file::{
    ScenarioFileError, ScenarioSpec, SimulationOverrides, BUILTIN_TABLE1,
};
use rotorid::simulate::{add_noise, simulate as integrate, Method as Integration, TimeResponse};
use rotorid::SpeedProfile;

use crate::error::Error;

/// The largest scenario file read \[bytes\] (as `rotorid`: a scenario is under 1 kB).
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

/// The origin of a scenario made from keyword arguments, in messages and summaries.
pub const KEYWORDS_ORIGIN: &str = "Scenario()";

/// The keys of a scenario file, each optional (the file's units: `alpha_deg` and
/// `phi0_deg` in degrees, `rpm` and `rpm0` in rev/min, the rest SI). `model` is
/// `rotor.model` (`"jeffcott"`, the default, with cx, cz, kx, kz; `"cross_coupled"` with
/// kxx, kxz, kzx, kzz \[N/m\] and cxx, cxz, czx, czz \[N s/m\]; a key of the other model
/// is the library's error). `rpm` makes the speed constant; `rpm0` and `accel` make it a
/// ramp. `x0`, `z0`, `vx0`, `vz0` are `[initial]`'s `x`, `z`, `vx`, `vz`.
#[derive(Debug, Clone, Default, PartialEq)]
#[allow(missing_docs)]
pub struct ScenarioKeys {
    pub model: Option<String>,
    pub m: Option<f64>,
    pub cx: Option<f64>,
    pub cz: Option<f64>,
    pub kx: Option<f64>,
    pub kz: Option<f64>,
    pub kxx: Option<f64>,
    pub kxz: Option<f64>,
    pub kzx: Option<f64>,
    pub kzz: Option<f64>,
    pub cxx: Option<f64>,
    pub cxz: Option<f64>,
    pub czx: Option<f64>,
    pub czz: Option<f64>,
    pub a: Option<f64>,
    pub m_u: Option<f64>,
    pub d: Option<f64>,
    pub alpha_deg: Option<f64>,
    pub rpm: Option<f64>,
    pub rpm0: Option<f64>,
    pub accel: Option<f64>,
    pub phi0_deg: Option<f64>,
    pub dt: Option<f64>,
    pub duration: Option<f64>,
    pub x0: Option<f64>,
    pub z0: Option<f64>,
    pub vx0: Option<f64>,
    pub vz0: Option<f64>,
}

impl ScenarioKeys {
    /// The TOML text of these keys, one a line, by section.
    pub fn toml(&self) -> String {
        let rotor = [
            ("m", self.m),
            ("cx", self.cx),
            ("cz", self.cz),
            ("kx", self.kx),
            ("kz", self.kz),
            ("kxx", self.kxx),
            ("kxz", self.kxz),
            ("kzx", self.kzx),
            ("kzz", self.kzz),
            ("cxx", self.cxx),
            ("cxz", self.cxz),
            ("czx", self.czx),
            ("czz", self.czz),
            ("a", self.a),
            ("m_u", self.m_u),
            ("d", self.d),
            ("alpha_deg", self.alpha_deg),
        ];
        let kind = if self.rpm.is_some() {
            Some("constant")
        } else if self.rpm0.is_some() || self.accel.is_some() {
            Some("ramp")
        } else {
            None
        };
        let speed = [
            ("rpm", self.rpm),
            ("rpm0", self.rpm0),
            ("accel", self.accel),
            ("phi0_deg", self.phi0_deg),
        ];
        let sampling = [("dt", self.dt), ("duration", self.duration)];
        let initial = [
            ("x", self.x0),
            ("z", self.z0),
            ("vx", self.vx0),
            ("vz", self.vz0),
        ];
        let mut text = String::new();
        for (section, keys) in [
            ("rotor", &rotor[..]),
            ("speed", &speed[..]),
            ("sampling", &sampling[..]),
            ("initial", &initial[..]),
        ] {
            let given: Vec<_> = keys.iter().filter_map(|(k, v)| Some((k, (*v)?))).collect();
            let model = self.model.as_deref().filter(|_| section == "rotor");
            if given.is_empty() && !(section == "speed" && kind.is_some()) && model.is_none() {
                continue;
            }
            writeln!(text, "[{section}]").expect("writing to a String");
            if let Some(model) = model {
                writeln!(text, "model = {}", toml_string(model)).expect("writing to a String");
            }
            if section == "speed" {
                if let Some(kind) = kind {
                    writeln!(text, "kind = \"{kind}\"").expect("writing to a String");
                }
            }
            for (k, v) in given {
                writeln!(text, "{k} = {}", toml_number(v)).expect("writing to a String");
            }
        }
        text
    }
}

/// `s` as a TOML basic string that reads back identically (any text: the library then
/// names it if it is not a model).
fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                write!(out, "\\u{:04X}", u32::from(c)).expect("writing to a String")
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `v` as a TOML number that reads back identically.
fn toml_number(v: f64) -> String {
    if v.is_nan() {
        "nan".to_owned()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_owned()
    } else {
        format!("{v:e}")
    }
}

/// A scenario (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    spec: ScenarioSpec,
    /// Made from keyword arguments: messages drop the lines of the generated text.
    keywords: bool,
}

impl Scenario {
    /// The paper's Table 1 rotor at 1200 rpm, 1 s at 10 kHz, from rest (`table1`).
    pub fn table1() -> Self {
        Self {
            spec: ScenarioSpec::builtin(BUILTIN_TABLE1, rotorid::Scenario::table1()),
            keywords: false,
        }
    }

    /// `table1` or the path of a TOML file, as `rotorid --scenario` takes it.
    pub fn load(arg: &str) -> Result<Self, Error> {
        if arg == BUILTIN_TABLE1 {
            return Ok(Self::table1());
        }
        Self::from_toml_file(arg)
    }

    /// The TOML file at `path` (at most [`MAX_SCENARIO_BYTES`]); `path` names it in messages.
    pub fn from_toml_file(path: &str) -> Result<Self, Error> {
        let io = |source| Error::Io {
            path: path.to_owned(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let mut bytes = Vec::new();
        file.take(MAX_SCENARIO_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        if bytes.len() as u64 > MAX_SCENARIO_BYTES {
            return Err(Error::invalid(format!(
                "{path}: larger than {} MiB, the limit for scenario files (a scenario is a \
                 few hundred bytes of TOML)",
                MAX_SCENARIO_BYTES >> 20
            )));
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| Error::invalid(format!("{path}: not UTF-8 text")))?;
        Self::from_toml(path, &text)
    }

    /// The TOML `text`; `origin` names it in messages and summaries.
    pub fn from_toml(origin: &str, text: &str) -> Result<Self, Error> {
        Ok(Self {
            spec: ScenarioSpec::parse(origin, text)?,
            keywords: false,
        })
    }

    /// The scenario of `keys` (module doc).
    pub fn from_keys(keys: &ScenarioKeys) -> Result<Self, Error> {
        let spec = ScenarioSpec::parse(KEYWORDS_ORIGIN, &keys.toml()).map_err(without_line)?;
        Ok(Self {
            spec,
            keywords: true,
        })
    }

    /// `table1`, the file's path, or [`KEYWORDS_ORIGIN`].
    pub fn origin(&self) -> &str {
        self.spec.origin()
    }

    /// True when made from keyword arguments.
    pub fn from_keywords(&self) -> bool {
        self.keywords
    }

    /// The library's parsed form.
    pub fn spec(&self) -> &ScenarioSpec {
        &self.spec
    }

    /// What identification knows from it (see [`ScenarioSpec::knowledge`]).
    pub fn knowledge(&self) -> Result<Knowledge, Error> {
        self.spec.knowledge().map_err(|e| self.error(e))
    }

    /// Its speed profile, if it states one.
    pub fn profile(&self) -> Result<Option<SpeedProfile>, Error> {
        Ok(self.spec.identification().map_err(|e| self.error(e))?.speed)
    }

    /// The complete scenario a simulation needs, `ov` taking precedence.
    pub fn simulation(&self, ov: &SimulationOverrides) -> Result<rotorid::Scenario, Error> {
        self.spec.simulation(ov).map_err(|e| self.error(e))
    }

    /// The keys it states, in the file's units, with its model (a round trip through
    /// [`Scenario::from_keys`] gives the same scenario up to the rounding of rpm).
    pub fn keys(&self) -> Result<ScenarioKeys, Error> {
        let v = self.spec.identification().map_err(|e| self.error(e))?;
        let t = v.truth;
        let mut k = ScenarioKeys {
            model: Some(v.model.name().to_owned()),
            m: t.m,
            a: Some(v.a),
            m_u: Some(v.m_u),
            d: Some(v.d),
            alpha_deg: Some(v.alpha.to_degrees()),
            dt: v.sampling.map(|s| s.dt()),
            duration: v.sampling.map(|s| s.duration()),
            ..ScenarioKeys::default()
        };
        match v.model {
            ModelKind::Jeffcott => (k.cx, k.cz, k.kx, k.kz) = (t.cx, t.cz, t.kx, t.kz),
            ModelKind::CrossCoupled => {
                (k.cxx, k.czz, k.kxx, k.kzz) = (t.cx, t.cz, t.kx, t.kz);
                (k.cxz, k.czx, k.kxz, k.kzx) = (t.cxz, t.czx, t.kxz, t.kzx);
            }
        }
        match v.speed {
            Some(SpeedProfile::Constant { omega, phi0 }) => {
                k.rpm = Some(rad_per_s_to_rpm(omega));
                k.phi0_deg = Some(phi0.to_degrees());
            }
            Some(SpeedProfile::Ramp {
                omega0,
                accel,
                phi0,
            }) => {
                k.rpm0 = Some(rad_per_s_to_rpm(omega0));
                k.accel = Some(accel);
                k.phi0_deg = Some(phi0.to_degrees());
            }
            None => {}
        }
        if let Some(truth) = self.knowledge()?.truth {
            if let Some(i) = truth.initial {
                (k.x0, k.z0, k.vx0, k.vz0) = (Some(i.x), Some(i.z), Some(i.vx), Some(i.vz));
            }
        }
        Ok(k)
    }

    fn error(&self, e: ScenarioFileError) -> Error {
        if self.keywords {
            without_line(e)
        } else {
            e.into()
        }
    }
}

/// `e` without the line of the generated text (keyword arguments have no line).
fn without_line(mut e: ScenarioFileError) -> Error {
    use ScenarioFileError as E;
    match &mut e {
        E::InvalidToml { line, .. }
        | E::UnknownSection { line, .. }
        | E::NotASection { line, .. }
        | E::UnknownKey { line, .. }
        | E::WrongType { line, .. }
        | E::OutOfRange { line, .. }
        | E::Inconsistent { line, .. }
        | E::UnknownSpeedKind { line, .. }
        | E::SpeedKeyNotApplicable { line, .. }
        | E::MissingSpeedKind { line, .. }
        | E::MissingSpeedKey { line, .. }
        | E::DampingNotDissipative { line, .. }
        | E::UnknownModel { line, .. } => *line = None,
        _ => {}
    }
    e.into()
}

/// The simulation methods by name: `exact` and `newmark`.
pub fn integration(name: &str) -> Result<Integration, Error> {
    match name {
        "exact" => Ok(Integration::Exact),
        "newmark" => Ok(Integration::Newmark),
        _ => Err(Error::invalid(format!(
            "method = {name:?} is not a simulation method: must be \"exact\" or \"newmark\""
        ))),
    }
}

/// Simulate `scenario` (its sampling and initial state overridden by `ov`) with `method`,
/// and add white noise at `snr_db` \[dB\] from `seed`, as `rotorid simulate` does.
pub fn simulate(
    scenario: &Scenario,
    method: &str,
    ov: &SimulationOverrides,
    noise: Option<(f64, u64)>,
) -> Result<TimeResponse, Error> {
    let method = integration(method)?;
    let sc = scenario.simulation(ov)?;
    let mut resp = integrate(&sc, method)?;
    if let Some((snr_db, seed)) = noise {
        add_noise(&mut resp, snr_db, seed)?;
    }
    Ok(resp)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table1_keys() -> ScenarioKeys {
        ScenarioKeys {
            m: Some(14.29),
            cx: Some(10.0),
            cz: Some(10.0),
            kx: Some(1.195e6),
            kz: Some(1.195e6),
            a: Some(2.871),
            m_u: Some(1e-4),
            d: Some(0.15),
            alpha_deg: Some(45.0),
            rpm: Some(1200.0),
            dt: Some(1e-4),
            duration: Some(1.0),
            ..ScenarioKeys::default()
        }
    }

    #[test]
    fn keywords_give_the_scenario_of_the_same_file() {
        let s = Scenario::from_keys(&table1_keys()).unwrap();
        let sc = s.simulation(&SimulationOverrides::default()).unwrap();
        assert_eq!(sc.rotor, rotorid::Scenario::table1().rotor);
        assert_eq!(sc.speed, rotorid::Scenario::table1().speed);
        assert_eq!(s.origin(), KEYWORDS_ORIGIN);
        let k = Scenario::table1().keys().unwrap();
        assert_eq!(k.kx, Some(1.195e6));
        assert!((k.rpm.unwrap() - 1200.0).abs() < 1e-9);
    }

    #[test]
    fn keyword_errors_name_the_key_and_range_without_a_line() {
        let bad = ScenarioKeys {
            kx: Some(-1.0),
            ..table1_keys()
        };
        let e = Scenario::from_keys(&bad).unwrap_err().to_string();
        assert_eq!(
            e,
            "Scenario(): rotor.kx = -1 is out of range: must be finite and > 0 (N/m)"
        );
        let both = ScenarioKeys {
            rpm0: Some(0.0),
            ..table1_keys()
        };
        let e = Scenario::from_keys(&both).unwrap_err().to_string();
        assert!(
            e.starts_with("Scenario(): speed.rpm0 does not apply"),
            "{e}"
        );
        let partial = ScenarioKeys {
            a: None,
            ..table1_keys()
        };
        let s = Scenario::from_keys(&partial).unwrap();
        assert!(s.knowledge().unwrap_err().to_string().contains("rotor.a"));
    }

    fn cross_keys() -> ScenarioKeys {
        ScenarioKeys {
            model: Some("cross_coupled".into()),
            m: Some(14.29),
            kxx: Some(1.195e6),
            kxz: Some(-3e4),
            kzx: Some(3e4),
            kzz: Some(1.4e6),
            cxx: Some(200.0),
            cxz: Some(20.0),
            czx: Some(-20.0),
            czz: Some(200.0),
            a: Some(2.871),
            m_u: Some(1e-4),
            d: Some(0.15),
            alpha_deg: Some(45.0),
            rpm: Some(1200.0),
            dt: Some(1e-4),
            duration: Some(1.0),
            ..ScenarioKeys::default()
        }
    }

    #[test]
    fn cross_coupled_keywords_give_the_scenario_of_the_same_file() {
        let file = "[rotor]\nmodel = \"cross_coupled\"\nm = 14.29\nkxx = 1.195e6\nkxz = -3e4\n\
                    kzx = 3e4\nkzz = 1.4e6\ncxx = 200\ncxz = 20\nczx = -20\nczz = 200\n\
                    a = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45\n[speed]\nkind = \"constant\"\n\
                    rpm = 1200\n[sampling]\ndt = 1e-4\nduration = 1.0\n";
        let ov = SimulationOverrides::default();
        let from_file = Scenario::from_toml("cross.toml", file).unwrap();
        let s = Scenario::from_keys(&cross_keys()).unwrap();
        assert_eq!(
            s.simulation(&ov).unwrap(),
            from_file.simulation(&ov).unwrap()
        );
        let rotor = s.simulation(&ov).unwrap().rotor;
        assert_eq!(rotor.model(), ModelKind::CrossCoupled);
        let c = rotor.params().coupling.unwrap();
        assert_eq!((c.kxz, c.kzx, c.cxz, c.czx), (-3e4, 3e4, 20.0, -20.0));
        // the keys read back, under the model's names
        let k = from_file.keys().unwrap();
        assert_eq!(k.model.as_deref(), Some("cross_coupled"));
        assert_eq!(
            (k.kxx, k.kxz, k.czx, k.czz),
            (Some(1.195e6), Some(-3e4), Some(-20.0), Some(200.0))
        );
        assert_eq!((k.kx, k.cx), (None, None));
        let again = Scenario::from_keys(&k).unwrap();
        assert_eq!(again.simulation(&ov).unwrap().rotor, rotor);
        assert_eq!(
            Scenario::table1().keys().unwrap().model.as_deref(),
            Some("jeffcott")
        );
    }

    #[test]
    fn cross_coupled_keyword_errors_are_the_librarys_without_a_line() {
        // the damping matrix's symmetric part is not positive semi-definite
        let bad = ScenarioKeys {
            cxz: Some(500.0),
            czx: Some(500.0),
            ..cross_keys()
        };
        let e = Scenario::from_keys(&bad).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "Scenario(): rotor: the damping matrix [[cxx, cxz], [czx, czz]] = \
                           [[200, 500], [500, 200]] N s/m is not dissipative"
            ),
            "{e}"
        );
        // a Jeffcott key in the cross-coupled model, and a cross-coupled key without it
        let mixed = ScenarioKeys {
            kx: Some(1e6),
            ..cross_keys()
        };
        let e = Scenario::from_keys(&mixed).unwrap_err().to_string();
        assert!(e.starts_with("Scenario(): unknown key rotor.kx;"), "{e}");
        assert!(
            e.ends_with("(kx is a key of rotor.model = \"jeffcott\")"),
            "{e}"
        );
        let e = Scenario::from_keys(&ScenarioKeys {
            model: None,
            ..cross_keys()
        })
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("(kxx is a key of rotor.model = \"cross_coupled\")"),
            "{e}"
        );
        // any text reaches the library intact, and its message names it
        for name in ["crosscoupled", "a\"b\\c\n"] {
            let e = Scenario::from_keys(&ScenarioKeys {
                model: Some(name.into()),
                ..ScenarioKeys::default()
            })
            .unwrap_err()
            .to_string();
            assert_eq!(
                e,
                format!(
                    "Scenario(): rotor.model = \"{name}\" is not a rotor model: must be \
                     \"jeffcott\", \"cross_coupled\" or \"finite_element\""
                )
            );
        }
    }

    #[test]
    fn numbers_survive_the_toml_text() {
        for v in [0.0, -0.0, 1e-300, 1.195e6, 0.1 + 0.2, f64::MAX] {
            let k = ScenarioKeys {
                accel: Some(v),
                ..ScenarioKeys::default()
            };
            let t = k.toml();
            assert!(t.contains(&format!("accel = {v:e}")), "{t}");
        }
        let k = ScenarioKeys {
            m: Some(f64::NAN),
            ..ScenarioKeys::default()
        };
        let e = Scenario::from_keys(&k).unwrap_err().to_string();
        assert!(e.contains("rotor.m = NaN is out of range"), "{e}");
    }
}
