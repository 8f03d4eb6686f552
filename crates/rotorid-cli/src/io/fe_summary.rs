//! The identified finite-element rotor of an identification summary (`model` =
//! `"finite_element"`; the contract of /work/notes/fe-summary-contract.md, docs/summary.md),
//! rebuilt on its scenario's matrices: the one place `rotorid analyze` and `rotorid predict`
//! read it.
//!
//! ```json
//! {
//!   "model": "finite_element",
//!   "parameters": [{"parameter": "bearing0.kxx", "unit": "N/m", "value": 1.0e6, ...}, ...],
//!   "rotor": {"bearings": [{"node": 0, ...}], "unbalances": [{"node": 2, ...}]},
//!   "covariance": {"names": ["bearing0.kxx", ...], "matrix": [[...]]} | null,
//!   "initial": "rest" | "estimated",
//!   "initial_state": null | {"dofs": [...], "q": [...], "v": [...]}
//! }
//! ```
//!
//! The identified rotor is the scenario's (matrices, bearings, unbalances) with each entry
//! of `parameters` set to its `value` (SI units, [`FeParameter`] names); `rotor` is only
//! checked against the scenario (the same number of bearings and unbalances at the same
//! nodes: a summary read with another rotor's scenario is refused). `covariance` over the
//! unknowns, a `null` entry infinite (undetermined). The initial state is rest unless
//! `initial` is `"estimated"`; then `initial_state` gives q \[m, rad\] and v \[m/s, rad/s\]
//! for every degree of freedom, by name. Every error names the file and the field.

use std::path::Path;

use anyhow::{anyhow, bail, Context as _};
use nalgebra::DVector;
use rotorid::analysis::FeCovariance;
use rotorid::model::finite_element::{Dof, FeParameter, FiniteElementRotor};
use rotorid::simulate::finite_element::FeInitialState;
use serde_json::{Map, Value};

use super::identified::covariance_arrays;

/// What a finite-element summary says, on its scenario's rotor.
#[derive(Debug, Clone)]
pub struct IdentifiedFe {
    /// The scenario's rotor with the identified values set.
    pub rotor: FiniteElementRotor,
    /// Their covariance, when the summary has one.
    pub covariance: Option<FeCovariance>,
    /// The estimated initial state (`initial` = `"estimated"`); `None`: rest.
    pub initial: Option<FeInitialState>,
}

/// The `model` field of the summary text `text` (`jeffcott` when absent, as the 2-DOF
/// reader takes it); `file` names it in messages.
pub fn summary_model(file: &str, text: &str) -> anyhow::Result<String> {
    let doc: Value =
        serde_json::from_str(text).map_err(|e| anyhow!("{file}: not valid JSON: {e}"))?;
    match doc.get("model") {
        None | Some(Value::Null) => Ok("jeffcott".to_owned()),
        Some(Value::String(s)) => Ok(s.clone()),
        Some(v) => bail!(
            "{file}: field `model` must be \"jeffcott\", \"cross_coupled\" or \
             \"finite_element\", found {v}"
        ),
    }
}

/// True when the summary at `path` is a finite-element one (its `model`).
pub fn is_finite_element_summary(path: &Path) -> anyhow::Result<bool> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read summary {}", path.display()))?;
    Ok(summary_model(&path.display().to_string(), &text)? == "finite_element")
}

impl IdentifiedFe {
    /// Read the summary at `path` on `scenario_rotor` (the rotor of its scenario file).
    pub fn read(path: &Path, scenario_rotor: FiniteElementRotor) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read summary {}", path.display()))?;
        Self::parse(&path.display().to_string(), &text, scenario_rotor)
    }

    /// Parse the summary `text` (module doc) on `rotor`; `file` names it in messages.
    pub fn parse(file: &str, text: &str, mut rotor: FiniteElementRotor) -> anyhow::Result<Self> {
        let doc: Value =
            serde_json::from_str(text).map_err(|e| anyhow!("{file}: not valid JSON: {e}"))?;
        let Some(top) = doc.as_object() else {
            bail!("{file}: expected a JSON object (an identification summary)");
        };
        let model = summary_model(file, text)?;
        if model != "finite_element" {
            bail!(
                "{file}: field `model` is \"{model}\": a finite-element summary (model \
                 \"finite_element\") is needed here"
            );
        }
        if let Some(r) = top.get("rotor").filter(|r| !r.is_null()) {
            check_rotor(file, r, &rotor)?;
        }
        let all = FeParameter::all(&rotor);
        let names: Vec<String> = all.iter().map(|p| p.to_string()).collect();
        let rows = top
            .get("parameters")
            .ok_or_else(|| anyhow!("{file}: missing field `parameters` (the identified values)"))?
            .as_array()
            .ok_or_else(|| anyhow!("{file}: field `parameters` must be an array of objects"))?;
        for (i, row) in rows.iter().enumerate() {
            let name = row
                .get("parameter")
                .and_then(Value::as_str)
                .ok_or_else(|| {
                    anyhow!("{file}: field `parameters[{i}].parameter` must be a parameter name")
                })?;
            let Some(&p) = all.iter().find(|p| p.to_string() == name) else {
                bail!(
                    "{file}: field `parameters[{i}].parameter` = {name:?} is not a parameter \
                     of the scenario's rotor: allowed {}",
                    names.join(", ")
                );
            };
            let value = row
                .get("value")
                .and_then(Value::as_f64)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow!(
                        "{file}: field `parameters[{i}].value` ({name}) must be a finite \
                         number ({}), found {}",
                        p.unit(),
                        row.get("value")
                            .map_or("nothing".to_owned(), Value::to_string)
                    )
                })?;
            p.set(&mut rotor, value);
        }
        let covariance = match top.get("covariance") {
            None => bail!(
                "{file}: missing field `covariance` ({{\"names\": [...], \"matrix\": [[...]]}} \
                 or null)"
            ),
            Some(Value::Null) => None,
            Some(Value::Object(c)) => {
                let (names, matrix) = covariance_arrays(file, c)?;
                Some(
                    FeCovariance::new(&rotor, names, matrix)
                        .map_err(|e| anyhow!("{file}: field `covariance`: {e}"))?,
                )
            }
            Some(other) => bail!(
                "{file}: field `covariance` must be an object {{\"names\": [...], \"matrix\": \
                 [[...]]}} or null, found {other}"
            ),
        };
        let initial = match top.get("initial") {
            None | Some(Value::Null) => None,
            Some(Value::String(s)) if s == "rest" => None,
            Some(Value::String(s)) if s == "estimated" => Some(initial_state(
                file,
                top.get("initial_state").unwrap_or(&Value::Null),
                &rotor,
            )?),
            Some(v) => {
                bail!("{file}: field `initial` must be \"rest\" or \"estimated\", found {v}")
            }
        };
        Ok(Self {
            rotor,
            covariance,
            initial,
        })
    }
}

/// The summary's `rotor` has the scenario's bearings and unbalances (count and nodes).
fn check_rotor(file: &str, r: &Value, rotor: &FiniteElementRotor) -> anyhow::Result<()> {
    let nodes = |key: &str| -> anyhow::Result<Vec<u64>> {
        let Some(list) = r.get(key) else {
            return Ok(Vec::new());
        };
        let list = list
            .as_array()
            .ok_or_else(|| anyhow!("{file}: field `rotor.{key}` must be an array"))?;
        list.iter()
            .enumerate()
            .map(|(i, b)| {
                b.get("node").and_then(Value::as_u64).ok_or_else(|| {
                    anyhow!("{file}: field `rotor.{key}[{i}].node` must be a node number")
                })
            })
            .collect()
    };
    let want_b: Vec<u64> = rotor.bearings.iter().map(|b| u64::from(b.node)).collect();
    let want_u: Vec<u64> = rotor.unbalances.iter().map(|u| u64::from(u.node)).collect();
    for (key, got, want) in [
        ("bearings", nodes("bearings")?, want_b),
        ("unbalances", nodes("unbalances")?, want_u),
    ] {
        if got != want {
            bail!(
                "{file}: field `rotor.{key}` is at nodes {got:?} but the scenario's rotor has \
                 its {key} at nodes {want:?}: give the scenario the summary was identified with"
            );
        }
    }
    Ok(())
}

/// `initial_state` {"dofs", "q", "v"} in the rotor's order of degrees of freedom.
fn initial_state(
    file: &str,
    v: &Value,
    rotor: &FiniteElementRotor,
) -> anyhow::Result<FeInitialState> {
    let Some(obj) = v.as_object() else {
        bail!(
            "{file}: field `initial_state` must be {{\"dofs\": [...], \"q\": [...], \"v\": \
             [...]}} when `initial` is \"estimated\", found {v}"
        );
    };
    let dofs = rotor.matrices.dofs();
    let n = dofs.len();
    let names = array(file, obj, "dofs")?;
    if names.len() != n {
        bail!(
            "{file}: field `initial_state.dofs` has {} entries: the rotor has {n} degrees of \
             freedom, each must be given",
            names.len()
        );
    }
    let mut at = Vec::with_capacity(n);
    for (i, d) in names.iter().enumerate() {
        let dof = d
            .as_str()
            .and_then(|s| s.parse::<Dof>().ok())
            .and_then(|d| rotor.matrices.index(d))
            .ok_or_else(|| {
                anyhow!("{file}: field `initial_state.dofs[{i}]` = {d} is not a degree of freedom of the rotor")
            })?;
        if at.contains(&dof) {
            bail!("{file}: field `initial_state.dofs[{i}]` = {d} appears twice");
        }
        at.push(dof);
    }
    let values = |key: &str, unit: &str| -> anyhow::Result<DVector<f64>> {
        let list = array(file, obj, key)?;
        if list.len() != n {
            bail!(
                "{file}: field `initial_state.{key}` has {} entries: one per entry of dofs ({n})",
                list.len()
            );
        }
        let mut out = DVector::zeros(n);
        for (i, x) in list.iter().enumerate() {
            out[at[i]] = x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                anyhow!("{file}: field `initial_state.{key}[{i}]` must be a finite number ({unit}), found {x}")
            })?;
        }
        Ok(out)
    };
    Ok(FeInitialState {
        q: values("q", "m or rad")?,
        v: values("v", "m/s or rad/s")?,
    })
}

fn array<'a>(file: &str, obj: &'a Map<String, Value>, key: &str) -> anyhow::Result<&'a Vec<Value>> {
    obj.get(key)
        .and_then(Value::as_array)
        .ok_or_else(|| anyhow!("{file}: field `initial_state.{key}` must be an array"))
}
