//! The method and its settings from keyword arguments, with the rules of `rotorid identify`
//! (crates/rotorid-cli/src/commands/identify.rs): each option belongs to some methods
//! (`tol` to algebraic only, `window` to modulating and refine, `unknowns` to refine,
//! `model = "auto"` to refine,
//! `quadrature` to algebraic and refine's algebraic start; `rcond_min` to all) and is
//! range-checked with the same words, so the same arguments give the same
//! [`Method`] from Python as from the command line.

use rotorid::identify::algebraic::Quadrature;
use rotorid::identify::modulating::{ModulatingConfig, DEFAULT_WINDOW_S};
use rotorid::parameter::Parameter;
use rotorid::pipeline::{
    AlgebraicSettings, Method, MethodName, ModelChoice, ModulatingSettings, PipelineError,
    RefineSettings,
};
use rotorid::refine::Unknowns;

use crate::error::Error;

/// The method names, as Python passes them.
pub const METHOD_NAMES: [&str; 3] = ["algebraic", "modulating", "refine"];

/// The names `unknowns` takes: the Jeffcott model's m, cx, kx, cz, kz, the cross-coupled
/// model's cxx, cxz, czx, czz, kxx, kxz, kzx, kzz, a, and unbalance (m_u d and alpha).
pub const UNKNOWN_NAMES: [&str; 15] = [
    "m",
    "cx",
    "kx",
    "cz",
    "kz",
    "a",
    "unbalance",
    "cxx",
    "cxz",
    "czx",
    "czz",
    "kxx",
    "kxz",
    "kzx",
    "kzz",
];

/// The names `model` takes.
pub const MODEL_NAMES: [&str; 3] = ["jeffcott", "cross_coupled", "auto"];

/// The options of an identification besides the method's name; `None` is the method's
/// default.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Options {
    /// The rotor model, among [`MODEL_NAMES`] (`auto`: refine only; default: the
    /// scenario's).
    pub model: Option<String>,
    /// refine: the quantities to estimate, among [`UNKNOWN_NAMES`] (default m and the
    /// model's bearing coefficients; the initial state is always estimated).
    pub unknowns: Option<Vec<String>>,
    /// Running quadrature of the algebraic identifier: trapezoid, am3, am4, am5.
    pub quadrature: Option<String>,
    /// Conditioning threshold (dimensionless, [0, 1]).
    pub rcond_min: Option<f64>,
    /// algebraic: relative band of the identification time (>= 0).
    pub tol: Option<f64>,
    /// modulating and refine: window of the modulating identifier \[s\] (> 0).
    pub window: Option<f64>,
    /// algebraic: restart period of the overlapping windows \[s\] (> 0, at least 4 dt).
    pub restart: Option<f64>,
}

/// The method called `name` (one of [`METHOD_NAMES`]).
pub fn method_name(name: &str) -> Result<MethodName, Error> {
    match name {
        "algebraic" => Ok(MethodName::Algebraic),
        "modulating" => Ok(MethodName::Modulating),
        "refine" => Ok(MethodName::Refine),
        _ => Err(Error::invalid(format!(
            "method = {name:?} is not a method: must be one of {}",
            METHOD_NAMES.join(", ")
        ))),
    }
}

/// The method `name` with the settings `o` (module doc).
pub fn method(name: &str, o: &Options) -> Result<Method, Error> {
    use MethodName::{Algebraic, Modulating, Refine};
    let method = method_name(name)?;
    let only = |option: &str, given: bool, allowed: &[MethodName]| {
        if given && !allowed.contains(&method) {
            let names: Vec<&str> = allowed.iter().map(|m| m.as_str()).collect();
            return Err(Error::invalid(format!(
                "{option} applies to method {} only, not to method {}",
                names.join(" and "),
                method.as_str()
            )));
        }
        Ok(())
    };
    only("tol", o.tol.is_some(), &[Algebraic])?;
    only("restart", o.restart.is_some(), &[Algebraic])?;
    only("quadrature", o.quadrature.is_some(), &[Algebraic, Refine])?;
    only("window", o.window.is_some(), &[Modulating, Refine])?;
    only("unknowns", o.unknowns.is_some(), &[Refine])?;
    let model = match &o.model {
        Some(name) => Some(name.parse::<ModelChoice>().map_err(|_| {
            Error::invalid(format!(
                "model = {name:?} is not a model: must be one of {}",
                MODEL_NAMES.join(", ")
            ))
        })?),
        None => None,
    };
    if model == Some(ModelChoice::Auto) && method != Refine {
        return Err(Error::invalid(format!(
            "model = \"auto\" applies to method refine only, not to method {}: choose \
             \"jeffcott\" or \"cross_coupled\"",
            method.as_str()
        )));
    }
    let fixed = model.and_then(ModelChoice::fixed);
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    let quadrature = match &o.quadrature {
        Some(q) => q
            .parse::<Quadrature>()
            .map_err(|e| Error::Pipeline(PipelineError::from(e)))?,
        None => Quadrature::default(),
    };
    let mut algebraic = AlgebraicSettings {
        quadrature,
        model: fixed,
        ..AlgebraicSettings::default()
    };
    if let Some(tol) = o.tol {
        if !ok(tol) {
            return Err(Error::invalid(format!(
                "tol = {tol} is out of range: must be finite and >= 0 (relative)"
            )));
        }
        algebraic.tol = tol;
    }
    if let Some(p) = o.restart {
        if !(p.is_finite() && p > 0.0) {
            return Err(Error::invalid(format!(
                "restart = {p} is out of range: must be finite and > 0 (s; at least 4 sampling \
                 periods)"
            )));
        }
        algebraic.restart_s = Some(p);
    }
    let window_s = o.window.unwrap_or(DEFAULT_WINDOW_S);
    if !(window_s.is_finite() && window_s > 0.0) {
        return Err(Error::invalid(format!(
            "window = {window_s} is out of range: must be finite and > 0 (s)"
        )));
    }
    let mut modulating = ModulatingSettings {
        config: ModulatingConfig::with_window(window_s),
        model: fixed,
    };
    if let Some(r) = o.rcond_min {
        if !(ok(r) && r <= 1.0) {
            return Err(Error::invalid(format!(
                "rcond_min = {r} is out of range: must be in [0, 1]"
            )));
        }
        algebraic.rcond_min = r;
        modulating.config.rcond_min = r;
    }
    Ok(match method {
        Algebraic => Method::Algebraic(algebraic),
        Modulating => Method::Modulating(modulating),
        Refine => Method::Refine(RefineSettings {
            model,
            unknowns: unknowns(o.unknowns.as_deref())?,
            algebraic,
            modulating,
            ..RefineSettings::default()
        }),
    })
}

/// The allowed deviation of the time stamps from the grid, relative to dt: finite, >= 0.
pub fn time_tolerance(v: f64) -> Result<f64, Error> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(format!(
            "time_tolerance = {v} is out of range: must be finite and >= 0 (relative to dt)"
        )))
    }
}

/// The unknowns `names` select (`None`: the model's default); the initial state is
/// always estimated.
fn unknowns(names: Option<&[String]>) -> Result<Option<Unknowns>, Error> {
    let Some(names) = names else {
        return Ok(None);
    };
    if names.is_empty() {
        return Err(Error::invalid(format!(
            "unknowns is empty: give at least one of {}",
            UNKNOWN_NAMES.join(", ")
        )));
    }
    if let Some(bad) = names.iter().find(|n| !UNKNOWN_NAMES.contains(&n.as_str())) {
        return Err(Error::invalid(format!(
            "unknowns: {bad:?} is not a parameter: must be among {}",
            UNKNOWN_NAMES.join(", ")
        )));
    }
    let ps: Vec<Parameter> = names
        .iter()
        .flat_map(|n| match n.as_str() {
            "unbalance" => vec![Parameter::Mud, Parameter::Alpha],
            other => other.parse().into_iter().collect(),
        })
        .collect();
    Ok(Some(Unknowns::from_parameters(&ps, true)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(name: &str, o: Options) -> String {
        method(name, &o).expect_err("must be refused").to_string()
    }

    #[test]
    fn defaults_are_the_pipelines() {
        assert_eq!(
            method("algebraic", &Options::default()).unwrap(),
            Method::algebraic()
        );
        assert_eq!(
            method("modulating", &Options::default()).unwrap(),
            Method::modulating()
        );
        assert_eq!(
            method("refine", &Options::default()).unwrap(),
            Method::refine()
        );
    }

    #[test]
    fn options_belong_to_their_methods_and_ranges() {
        let tol = Options {
            tol: Some(0.1),
            ..Options::default()
        };
        assert_eq!(
            err("refine", tol),
            "tol applies to method algebraic only, not to method refine"
        );
        let window = Options {
            window: Some(-1.0),
            ..Options::default()
        };
        assert_eq!(
            err("modulating", window),
            "window = -1 is out of range: must be finite and > 0 (s)"
        );
        let rcond = Options {
            rcond_min: Some(2.0),
            ..Options::default()
        };
        assert_eq!(
            err("algebraic", rcond),
            "rcond_min = 2 is out of range: must be in [0, 1]"
        );
        assert!(err("least-squares", Options::default()).starts_with("method = \"least-squares\""));
        let q = Options {
            quadrature: Some("simpson".into()),
            ..Options::default()
        };
        assert!(err("algebraic", q).contains("simpson"));
    }

    #[test]
    fn unknowns_select_parameters() {
        let o = Options {
            unknowns: Some(vec!["m".into(), "kx".into(), "unbalance".into()]),
            ..Options::default()
        };
        let Method::Refine(s) = method("refine", &o).unwrap() else {
            panic!("refine expected")
        };
        let u = s.unknowns.unwrap();
        assert!(u.m && u.kx && u.unbalance);
        assert!(!u.cx && !u.a && u.initial_state);
        let cross = Options {
            model: Some("cross_coupled".into()),
            unknowns: Some(vec!["m".into(), "kxz".into(), "czx".into()]),
            ..Options::default()
        };
        let Method::Refine(s) = method("refine", &cross).unwrap() else {
            panic!("refine expected")
        };
        let u = s.unknowns.unwrap();
        assert!(u.m && u.kxz && u.czx && !u.kzx && !u.kx);
        assert_eq!(s.model, Some(ModelChoice::CrossCoupled));
        let auto = Options {
            model: Some("auto".into()),
            ..Options::default()
        };
        assert!(err("modulating", auto).contains("refine only"));
        let typo = Options {
            model: Some("crosscoupled".into()),
            ..Options::default()
        };
        assert!(err("refine", typo).starts_with("model = \"crosscoupled\" is not a model"));
        let bad = Options {
            unknowns: Some(vec!["mass".into()]),
            ..Options::default()
        };
        assert!(err("refine", bad).starts_with("unknowns: \"mass\" is not a parameter"));
        assert!(time_tolerance(f64::NAN).is_err());
    }
}
