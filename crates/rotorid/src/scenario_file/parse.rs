//! The TOML reader of scenario files: syntax and structure from `toml_edit` (the parser
//! under the `toml` crate), whose spans give the line of every key, whether written under
//! a `[section]` header, as a dotted key (`rotor.m = 14.29`) or in an inline table
//! (`rotor = { m = 14.29 }`); then each key is checked by hand so that every message names
//! the file, the line and the key as `section.key` (see [`super`] for the format).
//!
//! `toml_edit` is used directly rather than through `toml`'s serde interface because serde
//! sees no span for the implicit table of a dotted key, so `toml::Spanned` cannot read
//! `rotor.m = 14.29`.

use std::collections::BTreeMap;

use toml_edit::{ImDocument, Item, Key, Value};

use super::acquisition::Acquisitions;
use super::error::RotorModel;
use super::finite_element::{FINITE_ELEMENT, FINITE_ELEMENT_KEYS};
use super::text::Parser;
use super::{
    rotor_error, rotor_keys, unit_of, Num, RotorArray, ScenarioFileError, ScenarioSpec, Section,
    SpeedKind, CANONICAL_ORDER, INITIAL_KEYS, ROTOR_CONTENTS, SAMPLING_KEYS, SECTIONS, SPEED_KEYS,
};
use crate::model::ModelError;
use crate::parameter::ModelKind;
use crate::{Rotor, Sampling, SpeedProfile};

/// One `key = value` of a section, as read from the document.
struct Entry<'a> {
    key: &'a str,
    /// 1-based line of the key.
    line: Option<usize>,
    value: Raw,
    /// The value as written, on one line (for messages).
    written: String,
}

/// A value as the checks need it.
enum Raw {
    Number(f64),
    String(String),
    Other,
}

impl Parser<'_> {
    /// The entry `key = value` of a section; `None` for a sub-table (`[rotor.m]`).
    fn entry<'a>(&self, key: &'a str, at: Option<&Key>, value: Option<&Value>) -> Entry<'a> {
        let raw = match value {
            Some(Value::Float(f)) => Raw::Number(*f.value()),
            // Integers beyond 2^53 round to the nearest f64, as TOML floats do.
            Some(Value::Integer(i)) => Raw::Number(*i.value() as f64),
            Some(Value::String(s)) => Raw::String(s.value().clone()),
            _ => Raw::Other,
        };
        Entry {
            key,
            line: self.key_line(at),
            value: raw,
            written: self.written(value.and_then(Value::span)),
        }
    }

    fn origin(&self) -> String {
        self.origin.to_owned()
    }

    pub(super) fn parse(&self) -> Result<ScenarioSpec, ScenarioFileError> {
        let doc = ImDocument::parse(self.text).map_err(|e| ScenarioFileError::InvalidToml {
            origin: self.origin(),
            line: e.span().map(|s| self.line(s.start)),
            message: e.message().trim_end().to_owned(),
        })?;
        let root = doc.as_table();
        // The top level: only the four sections, each a table in any of TOML's forms.
        let mut raw: BTreeMap<&str, (Option<usize>, Vec<Entry<'_>>)> = BTreeMap::new();
        let mut acquisition = None;
        let mut rotor_item = None;
        for (name, item) in root.iter() {
            let line = self.key_line(root.key(name));
            if name == "rotor" {
                rotor_item = Some((item, line));
            }
            if name == "acquisition" {
                acquisition = Some((item, line));
                continue;
            }
            let Some(sec) = SECTIONS.iter().find(|s| **s == name) else {
                return Err(ScenarioFileError::UnknownSection {
                    origin: self.origin(),
                    line,
                    name: name.to_owned(),
                });
            };
            let entries = match item {
                Item::Table(t) => t
                    .iter()
                    .map(|(k, it)| self.entry(k, t.key(k), it.as_value()))
                    .collect(),
                Item::Value(Value::InlineTable(t)) => t
                    .iter()
                    .map(|(k, v)| self.entry(k, t.key(k), Some(v)))
                    .collect(),
                other => {
                    return Err(ScenarioFileError::NotASection {
                        origin: self.origin(),
                        line,
                        name: name.to_owned(),
                        found: other.type_name().to_owned(),
                    })
                }
            };
            raw.insert(sec, (line, entries));
        }
        // None: a finite-element rotor, whose [rotor] has tables and a path
        let model = match raw.get_mut("rotor") {
            Some((_, entries)) => self.rotor_model(entries)?,
            None => Some(ModelKind::Jeffcott),
        };
        let finite_element = match (model, rotor_item) {
            (None, Some((item, line))) => {
                if let Some((line, _)) = raw.get("initial") {
                    return Err(ScenarioFileError::Inconsistent {
                        origin: self.origin(),
                        line: *line,
                        message: "[initial] (x, z, vx, vz) is the initial state of a lumped \
                                  rotor (jeffcott, cross_coupled): a finite_element rotor's is \
                                  not given in the scenario"
                            .to_owned(),
                    });
                }
                Some(self.finite_element(item, line)?)
            }
            _ => None,
        };
        // [acquisition] once the model is known: a finite-element rotor's probes name nodes
        let (acquisition, fe_acquisition) = match acquisition {
            None => (None, None),
            Some((item, line)) => match self.acquisition(item, line, model)? {
                Acquisitions::Lumped(a) => (Some(*a), None),
                Acquisitions::FiniteElement(a) => (None, Some(a)),
            },
        };
        let model = model.unwrap_or(ModelKind::Jeffcott);
        let fe_rotor = finite_element
            .is_some()
            .then(|| raw.remove("rotor"))
            .flatten()
            .map(|(line, _)| Section {
                line,
                keys: BTreeMap::new(),
            });
        let mut take = |name: &'static str, keys: &[(&'static str, &'static str)]| {
            raw.remove(name)
                .map(|(line, entries)| self.section(name, line, keys, entries))
                .transpose()
        };
        let rotor = match fe_rotor {
            Some(s) => Some(s),
            None => take("rotor", rotor_keys(model))?.map(|(s, _)| s.canonical()),
        };
        let speed = take("speed", &SPEED_KEYS[1..])?;
        let sampling = take("sampling", &SAMPLING_KEYS)?.map(|(s, _)| s);
        let initial = take("initial", &INITIAL_KEYS)?.map(|(s, _)| s);
        // a scenario holding only [acquisition] describes a raw record for the analyses
        // that need no model (`rotorid transient`); what needs the rotor asks for its keys
        let acquisition_only = rotor.is_none() && acquisition.is_some() && speed.is_none();
        let (rotor, check) = match rotor {
            Some(r) => (Some(r), true),
            None if acquisition_only => (Some(Section::default()), false),
            None => (None, true),
        };
        let Some(rotor) = rotor else {
            return Err(ScenarioFileError::MissingSection {
                origin: self.origin(),
                section: "rotor".to_owned(),
                contents: ROTOR_CONTENTS.to_owned(),
                needed_by: None,
            });
        };
        if finite_element.is_none() && check {
            self.check_rotor(&rotor, model)?;
        }
        let speed = match speed {
            Some((s, kind)) => Some(self.speed_profile(&s, kind)?),
            None => None,
        };
        if let Some(s) = &sampling {
            self.check_sampling(s)?;
        }
        Ok(ScenarioSpec {
            origin: self.origin(),
            builtin: None,
            model,
            written_model: model,
            rotor,
            speed,
            sampling,
            initial: initial.unwrap_or_default(),
            acquisition,
            fe_acquisition,
            finite_element,
        })
    }

    /// `rotor.model` (the string "jeffcott", "cross_coupled" or "finite_element"; default
    /// Jeffcott), taken out of the section's entries; `None` for "finite_element".
    fn rotor_model(
        &self,
        entries: &mut Vec<Entry<'_>>,
    ) -> Result<Option<ModelKind>, ScenarioFileError> {
        let Some(i) = entries.iter().position(|e| e.key == "model") else {
            return Ok(Some(ModelKind::Jeffcott));
        };
        let Entry {
            line,
            value,
            written,
            ..
        } = entries.remove(i);
        match value {
            Raw::String(s) if s == FINITE_ELEMENT => Ok(None),
            Raw::String(s) => s
                .parse()
                .map(Some)
                .map_err(|_| ScenarioFileError::UnknownModel {
                    origin: self.origin(),
                    line,
                    value: s,
                }),
            Raw::Number(_) | Raw::Other => Err(ScenarioFileError::WrongType {
                origin: self.origin(),
                line,
                key: "rotor.model".to_owned(),
                value: written,
                expected: "the string \"jeffcott\", \"cross_coupled\" or \"finite_element\""
                    .to_owned(),
            }),
        }
    }

    /// Check the keys of one section: known names, numbers only; `speed.kind` (a string)
    /// is returned beside the numeric keys.
    fn section(
        &self,
        name: &str,
        line: Option<usize>,
        keys: &[(&'static str, &'static str)],
        entries: Vec<Entry<'_>>,
    ) -> Result<(Section, Option<SpeedKind>), ScenarioFileError> {
        let mut sec = Section {
            line,
            keys: BTreeMap::new(),
        };
        let mut kind = None;
        for Entry {
            key,
            line,
            value,
            written,
        } in entries
        {
            if name == "speed" && key == "kind" {
                kind = Some(self.speed_kind(line, value, written)?);
                continue;
            }
            let Some((kname, unit)) = keys.iter().find(|(kk, _)| *kk == key) else {
                let names = keys.iter().map(|(k, _)| *k);
                let allowed: Vec<&str> = match name {
                    "speed" => std::iter::once("kind").chain(names).collect(),
                    "rotor" => names.chain(std::iter::once("model")).collect(),
                    _ => names.collect(),
                };
                let other_model = (name == "rotor")
                    .then(|| {
                        ModelKind::ALL
                            .into_iter()
                            .find(|m| {
                                rotor_keys(*m) != keys
                                    && rotor_keys(*m).iter().any(|(k, _)| *k == key)
                            })
                            .map(RotorModel::Lumped)
                            .or(FINITE_ELEMENT_KEYS
                                .contains(&key)
                                .then_some(RotorModel::FiniteElement))
                    })
                    .flatten();
                return Err(ScenarioFileError::UnknownKey {
                    origin: self.origin(),
                    line,
                    section: name.to_owned(),
                    key: key.to_owned(),
                    allowed: allowed.join(", "),
                    other_model,
                });
            };
            let Raw::Number(value) = value else {
                return Err(ScenarioFileError::WrongType {
                    origin: self.origin(),
                    line,
                    key: format!("{name}.{key}"),
                    value: written,
                    expected: format!("a number ({unit})"),
                });
            };
            sec.keys.insert(kname, Num { value, line });
        }
        Ok((sec, kind))
    }

    /// `speed.kind`: the string "constant" or "ramp".
    fn speed_kind(
        &self,
        line: Option<usize>,
        v: Raw,
        written: String,
    ) -> Result<SpeedKind, ScenarioFileError> {
        match v {
            Raw::String(s) if s == "constant" => Ok(SpeedKind::Constant),
            Raw::String(s) if s == "ramp" => Ok(SpeedKind::Ramp),
            Raw::String(value) => Err(ScenarioFileError::UnknownSpeedKind {
                origin: self.origin(),
                line,
                value,
            }),
            Raw::Number(_) | Raw::Other => Err(ScenarioFileError::WrongType {
                origin: self.origin(),
                line,
                key: "speed.kind".to_owned(),
                value: written,
                expected: "the string \"constant\" or \"ramp\"".to_owned(),
            }),
        }
    }

    /// `key = value is out of range: must be finite (deg)` for a non-finite angle.
    fn not_finite_deg(&self, key: &str, n: Num) -> ScenarioFileError {
        ScenarioFileError::OutOfRange {
            origin: self.origin(),
            line: n.line,
            key: key.to_owned(),
            value: n.value,
            allowed: "finite (deg)".to_owned(),
        }
    }

    fn check_rotor(&self, rotor: &Section, model: ModelKind) -> Result<(), ScenarioFileError> {
        // alpha is converted from degrees: check it in the user's unit first.
        if let Some(n) = rotor.get("alpha_deg") {
            if !n.value.is_finite() {
                return Err(self.not_finite_deg("rotor.alpha_deg", n));
            }
        }
        // Range-check the keys present with the model's own rules: missing keys take a
        // valid placeholder (table1, no cross-coupling), so any error comes from a key the
        // user wrote.
        let mut v = rotor_values_of_table1();
        for (i, k) in CANONICAL_ORDER.iter().enumerate() {
            if let Some(n) = rotor.get(k) {
                v.0[i] = n.value;
            }
        }
        Rotor::new(v.params(model)).map_err(|e| rotor_error(self.origin, rotor, model, e))?;
        Ok(())
    }

    /// The speed profile of a `[speed]` section of `kind`.
    fn speed_profile(
        &self,
        s: &Section,
        kind: Option<SpeedKind>,
    ) -> Result<SpeedProfile, ScenarioFileError> {
        let Some(kind) = kind else {
            return Err(ScenarioFileError::MissingSpeedKind {
                origin: self.origin(),
                line: s.line,
            });
        };
        let (needed, forbidden): (&[&str], &[&str]) = match kind {
            SpeedKind::Constant => (&["rpm"], &["rpm0", "accel"]),
            SpeedKind::Ramp => (&["rpm0", "accel"], &["rpm"]),
        };
        for k in forbidden {
            if let Some(n) = s.get(k) {
                return Err(ScenarioFileError::SpeedKeyNotApplicable {
                    origin: self.origin(),
                    line: n.line,
                    key: (*k).to_owned(),
                    kind,
                });
            }
        }
        for k in needed {
            if s.get(k).is_none() {
                return Err(ScenarioFileError::MissingSpeedKey {
                    origin: self.origin(),
                    line: s.line,
                    key: (*k).to_owned(),
                    unit: unit_of(&SPEED_KEYS, k).to_owned(),
                    kind,
                });
            }
        }
        let phi0 = s.get("phi0_deg");
        if let Some(n) = phi0 {
            if !n.value.is_finite() {
                return Err(self.not_finite_deg("speed.phi0_deg", n));
            }
        }
        let phi0 = phi0.map_or(0.0, |n| n.value.to_radians());
        let v = |k: &str| s.get(k).map_or(f64::NAN, |n| n.value);
        let names = [
            ("rpm", "speed.rpm"),
            ("rpm0", "speed.rpm0"),
            ("accel", "speed.accel"),
            ("phi0", "speed.phi0_deg"),
        ];
        match kind {
            SpeedKind::Constant => SpeedProfile::constant_rpm(v("rpm"), phi0),
            SpeedKind::Ramp => SpeedProfile::ramp(v("rpm0"), v("accel"), phi0),
        }
        .map_err(|e| {
            let line = match &e {
                ModelError::OutOfRange { field, .. } => {
                    let key = if *field == "phi0" { "phi0_deg" } else { field };
                    s.get(key).and_then(|n| n.line)
                }
                _ => s.line,
            };
            ScenarioFileError::from_model(self.origin, line, e, &names)
        })
    }

    fn check_sampling(&self, s: &Section) -> Result<(), ScenarioFileError> {
        // Each key alone: dt and duration must be finite and > 0 (the pair is checked in
        // the views, where command-line overrides may replace either).
        for key in ["dt", "duration"] {
            if let Some(n) = s.get(key) {
                let (dt, du) = if key == "dt" {
                    (n.value, f64::MAX / 4.0)
                } else {
                    (f64::MIN_POSITIVE, n.value)
                };
                if let Err(e @ ModelError::OutOfRange { .. }) = Sampling::new(dt, du) {
                    return Err(ScenarioFileError::from_model(
                        self.origin,
                        n.line,
                        e,
                        &[("dt", "sampling.dt"), ("duration", "sampling.duration")],
                    ));
                }
            }
        }
        Ok(())
    }
}

/// table1's values in [`CANONICAL_ORDER`], without cross-coupling.
fn rotor_values_of_table1() -> RotorArray {
    let r = Rotor::table1();
    let u = r.unbalance();
    RotorArray([
        r.m(),
        r.cx(),
        r.cz(),
        r.kx(),
        r.kz(),
        r.a(),
        u.m_u,
        u.d,
        u.alpha.to_degrees(),
        0.0,
        0.0,
        0.0,
        0.0,
    ])
}
