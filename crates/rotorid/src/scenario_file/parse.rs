//! The TOML reader of scenario files: syntax and structure from the `toml` crate (its
//! spans give the line of every key), then each key checked by hand so that every message
//! names the file, the line and the key as `section.key` (see [`super`] for the format).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use anyhow::{anyhow, bail};
use rotorid::model::ModelError;
use rotorid::{Rotor, Sampling, SpeedProfile};
use toml::Spanned;

use super::{
    located, rotor_key, rotor_key_map, rotor_params, unit_of, Num, ScenarioSpec, Section,
    INITIAL_KEYS, ROTOR_KEYS, SAMPLING_KEYS, SECTIONS, SPEED_KEYS,
};

type RawSection = BTreeMap<Spanned<String>, Spanned<toml::Value>>;

/// The shape of the speed profile named by `speed.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SpeedKind {
    Constant,
    Ramp,
}

/// Parses one scenario file's text; `origin` (the file name) prefixes every message.
pub(super) struct Parser<'a> {
    pub(super) origin: &'a str,
    pub(super) text: &'a str,
}

impl Parser<'_> {
    /// 1-based line of byte offset `pos`.
    fn line(&self, pos: usize) -> usize {
        let pos = pos.min(self.text.len());
        self.text.as_bytes()[..pos]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    fn toml_error(&self, e: toml::de::Error) -> anyhow::Error {
        let line = e.span().map(|s| self.line(s.start));
        let msg = e.message().trim_end();
        match line {
            Some(l) => anyhow!("{}:{l}: invalid TOML: {msg}", self.origin),
            None => anyhow!("{}: invalid TOML: {msg}", self.origin),
        }
    }

    pub(super) fn parse(&self) -> anyhow::Result<ScenarioSpec> {
        let o = self.origin;
        // Pass 1: the top-level keys, their lines and types.
        let top: BTreeMap<Spanned<String>, Spanned<toml::Value>> =
            toml::from_str(self.text).map_err(|e| self.toml_error(e))?;
        let mut lines = BTreeMap::new();
        for (k, v) in &top {
            let l = self.line(k.span().start);
            let name = k.get_ref().as_str();
            let Some(sec) = SECTIONS.iter().find(|s| **s == name) else {
                bail!(
                    "{o}:{l}: unknown section or key `{name}`; allowed sections: [rotor], \
                     [speed], [sampling], [initial]"
                );
            };
            if !v.get_ref().is_table() {
                bail!(
                    "{o}:{l}: `{name}` must be a section [{name}], found {} {}",
                    article(v.get_ref().type_str()),
                    v.get_ref().type_str()
                );
            }
            lines.insert(*sec, l);
        }
        // Pass 2: every section as key -> spanned value (each top-level item is a table).
        let mut raw: BTreeMap<String, RawSection> =
            toml::from_str(self.text).map_err(|e| self.toml_error(e))?;
        let mut take =
            |name: &'static str, keys: &[(&'static str, &'static str)]| match raw.remove(name) {
                Some(r) => self
                    .section(name, lines.get(name).copied(), keys, r)
                    .map(Some),
                None => Ok(None),
            };
        let rotor = take("rotor", &ROTOR_KEYS)?.map(|(s, _)| s);
        let speed = take("speed", &SPEED_KEYS[1..])?;
        let sampling = take("sampling", &SAMPLING_KEYS)?.map(|(s, _)| s);
        let initial = take("initial", &INITIAL_KEYS)?.map(|(s, _)| s);
        let Some(rotor) = rotor else {
            bail!("{o}: missing section [rotor] (a, m_u, d, alpha_deg and, to simulate, m, cx, cz, kx, kz)");
        };
        self.check_rotor(&rotor)?;
        let speed = match speed {
            Some((s, kind)) => Some(self.speed_profile(&s, kind)?),
            None => None,
        };
        if let Some(s) = &sampling {
            self.check_sampling(s)?;
        }
        let initial = initial.unwrap_or_default();
        Ok(ScenarioSpec {
            origin: o.to_owned(),
            builtin: None,
            rotor,
            speed,
            sampling,
            initial,
        })
    }

    /// Check the keys of one section: known names, numbers only; `speed.kind` (a string)
    /// is returned beside the numeric keys.
    fn section(
        &self,
        name: &str,
        line: Option<usize>,
        keys: &[(&'static str, &'static str)],
        raw: RawSection,
    ) -> anyhow::Result<(Section, Option<(SpeedKind, usize)>)> {
        let o = self.origin;
        let mut sec = Section {
            line,
            keys: BTreeMap::new(),
        };
        let mut kind = None;
        for (k, v) in raw {
            let l = self.line(k.span().start);
            let key = k.get_ref().as_str();
            if name == "speed" && key == "kind" {
                kind = Some((speed_kind(o, l, v.get_ref())?, l));
                continue;
            }
            let Some((kname, unit)) = keys.iter().find(|(kk, _)| *kk == key) else {
                let mut allowed = String::new();
                if name == "speed" {
                    allowed.push_str("kind, ");
                }
                for (i, (kk, _)) in keys.iter().enumerate() {
                    if i > 0 {
                        allowed.push_str(", ");
                    }
                    let _ = write!(allowed, "{kk}");
                }
                bail!("{o}:{l}: unknown key {name}.{key}; allowed keys in [{name}]: {allowed}");
            };
            let value = match v.get_ref() {
                toml::Value::Float(f) => *f,
                toml::Value::Integer(i) => *i as f64,
                other => bail!(
                    "{o}:{l}: {name}.{key} = {other} has the wrong type: must be a number ({unit})"
                ),
            };
            sec.keys.insert(
                kname,
                Num {
                    value,
                    line: Some(l),
                },
            );
        }
        Ok((sec, kind))
    }

    fn check_rotor(&self, rotor: &Section) -> anyhow::Result<()> {
        let o = self.origin;
        // alpha is converted from degrees: check it in the user's unit first.
        if let Some(n) = rotor.get("alpha_deg") {
            if !n.value.is_finite() {
                bail!(
                    "{o}:{}: rotor.alpha_deg = {} is out of range: must be finite (deg)",
                    n.line.unwrap_or(0),
                    n.value
                );
            }
        }
        // Range-check the keys present with the model's own rules: missing keys take a
        // valid placeholder, so any error comes from a key the user wrote.
        let placeholder = rotor_params_from_table1();
        let mut v = placeholder;
        for (i, (k, _)) in ROTOR_KEYS.iter().enumerate() {
            if let Some(n) = rotor.get(k) {
                v[i] = n.value;
            }
        }
        Rotor::new(rotor_params(&v)).map_err(|e| {
            let line = match &e {
                ModelError::OutOfRange { field, .. } => {
                    rotor.get(rotor_key(field)).and_then(|n| n.line)
                }
                ModelError::Inconsistent(_) => rotor.line,
            };
            located(o, line, e, &rotor_key_map())
        })?;
        Ok(())
    }

    /// The speed profile of a `[speed]` section of `kind`.
    fn speed_profile(
        &self,
        s: &Section,
        kind: Option<(SpeedKind, usize)>,
    ) -> anyhow::Result<SpeedProfile> {
        let o = self.origin;
        let at = s.line.map_or(String::new(), |l| format!(":{l}"));
        let Some((kind, _)) = kind else {
            bail!("{o}{at}: missing key speed.kind: must be \"constant\" or \"ramp\"");
        };
        let (needed, forbidden): (&[&str], &[&str]) = match kind {
            SpeedKind::Constant => (&["rpm"], &["rpm0", "accel"]),
            SpeedKind::Ramp => (&["rpm0", "accel"], &["rpm"]),
        };
        let kname = match kind {
            SpeedKind::Constant => "constant",
            SpeedKind::Ramp => "ramp",
        };
        for k in forbidden {
            if let Some(n) = s.get(k) {
                bail!(
                    "{o}:{}: speed.{k} does not apply to kind = \"{kname}\" (constant takes \
                     rpm; ramp takes rpm0 and accel)",
                    n.line.unwrap_or(0)
                );
            }
        }
        for k in needed {
            if s.get(k).is_none() {
                bail!(
                    "{o}{at}: missing key speed.{k} ({}) for kind = \"{kname}\"",
                    unit_of(&SPEED_KEYS, k)
                );
            }
        }
        let phi0 = s.get("phi0_deg");
        if let Some(n) = phi0 {
            if !n.value.is_finite() {
                bail!(
                    "{o}:{}: speed.phi0_deg = {} is out of range: must be finite (deg)",
                    n.line.unwrap_or(0),
                    n.value
                );
            }
        }
        let phi0 = phi0.map_or(0.0, |n| n.value.to_radians());
        let v = |k: &str| s.get(k).expect("checked above");
        let names = [
            ("rpm", "speed.rpm"),
            ("rpm0", "speed.rpm0"),
            ("accel", "speed.accel"),
            ("phi0", "speed.phi0_deg"),
        ];
        let profile = match kind {
            SpeedKind::Constant => SpeedProfile::constant_rpm(v("rpm").value, phi0),
            SpeedKind::Ramp => SpeedProfile::ramp(v("rpm0").value, v("accel").value, phi0),
        }
        .map_err(|e| {
            let line = match &e {
                ModelError::OutOfRange { field, .. } => {
                    let key = if *field == "phi0" { "phi0_deg" } else { field };
                    s.get(key).and_then(|n| n.line)
                }
                ModelError::Inconsistent(_) => s.line,
            };
            located(o, line, e, &names)
        })?;
        Ok(profile)
    }

    fn check_sampling(&self, s: &Section) -> anyhow::Result<()> {
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
                    return Err(located(
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

fn rotor_params_from_table1() -> [f64; 9] {
    let r = Rotor::table1();
    let u = r.unbalance();
    [
        r.m(),
        r.cx(),
        r.cz(),
        r.kx(),
        r.kz(),
        r.a(),
        u.m_u,
        u.d,
        u.alpha.to_degrees(),
    ]
}

/// `speed.kind` at line `l`: the string "constant" or "ramp".
fn speed_kind(o: &str, l: usize, v: &toml::Value) -> anyhow::Result<SpeedKind> {
    match v {
        toml::Value::String(s) if s == "constant" => Ok(SpeedKind::Constant),
        toml::Value::String(s) if s == "ramp" => Ok(SpeedKind::Ramp),
        toml::Value::String(s) => bail!(
            "{o}:{l}: speed.kind = \"{s}\" is not a speed profile: must be \"constant\" or \
             \"ramp\""
        ),
        other => bail!(
            "{o}:{l}: speed.kind = {other} has the wrong type: must be the string \
             \"constant\" or \"ramp\""
        ),
    }
}

fn article(type_str: &str) -> &'static str {
    match type_str.as_bytes().first() {
        Some(b'a' | b'e' | b'i' | b'o' | b'u') => "an",
        _ => "a",
    }
}
