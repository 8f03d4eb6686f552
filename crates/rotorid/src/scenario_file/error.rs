//! The errors of scenario files: each variant carries what the message shows (file, line,
//! key, value, allowed range with its unit), so that a caller can point at the mistake
//! without parsing the text.

use std::fmt;

use thiserror::Error;

use crate::model::ModelError;

use super::SpeedKind;

/// A scenario file that cannot be used, or a view ([`super::ScenarioSpec::simulation`],
/// [`super::ScenarioSpec::identification`]) that lacks something it needs.
///
/// Every message starts with `FILE:LINE: ` (lines counted from 1, as editors do) or, when
/// no single line is at fault, `FILE: `. Keys are written `section.key` (`rotor.kx`), or
/// as the command-line flag (`--dt`) when the value came from [`super::SimulationOverrides`].
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ScenarioFileError {
    /// The text is not valid TOML (the `toml_edit` parser's message).
    #[error("{}: invalid TOML: {message}", At(origin, line))]
    InvalidToml {
        /// The file name.
        origin: String,
        /// The line of the error, if the parser knows it.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A top-level name that is not one of the four sections.
    #[error(
        "{}: unknown section or key `{name}`; allowed sections: [rotor], [speed], \
         [sampling], [initial], [acquisition]",
        At(origin, line)
    )]
    UnknownSection {
        /// The file name.
        origin: String,
        /// The line of the name.
        line: Option<usize>,
        /// The name as written.
        name: String,
    },
    /// A section name given a value that is not a table (`rotor = 1`).
    #[error(
        "{}: `{name}` must be a section [{name}], found {} {found}",
        At(origin, line),
        article(found)
    )]
    NotASection {
        /// The file name.
        origin: String,
        /// The line of the name.
        line: Option<usize>,
        /// The section's name.
        name: String,
        /// The TOML type found (`integer`, `string`, `array`, ...).
        found: String,
    },
    /// A key that its section does not have.
    #[error(
        "{}: unknown key {section}.{key}; allowed keys in [{section}]: {allowed}{}",
        At(origin, line),
        other_model.map_or(String::new(), |m| format!(" ({key} is a key of rotor.model = \"{}\")", m.name()))
    )]
    UnknownKey {
        /// The file name.
        origin: String,
        /// The line of the key.
        line: Option<usize>,
        /// The section (`rotor`).
        section: String,
        /// The key as written.
        key: String,
        /// The section's keys, comma-separated.
        allowed: String,
        /// The model whose key it is, when it is another model's rotor key (the message
        /// then says `kxx is a key of rotor.model = "cross_coupled"`).
        other_model: Option<RotorModel>,
    },
    /// A value of the wrong TOML type (`rotor.m = "heavy"`).
    #[error(
        "{}: {key} = {value} has the wrong type: must be {expected}",
        At(origin, line)
    )]
    WrongType {
        /// The file name.
        origin: String,
        /// The line of the key.
        line: Option<usize>,
        /// `section.key`.
        key: String,
        /// The value as written in the file.
        value: String,
        /// What is expected, with the unit (`a number (kg)`).
        expected: String,
    },
    /// A number outside its allowed range (NaN and infinity included).
    #[error(
        "{}: {key} = {value} is out of range: must be {allowed}",
        At(origin, line)
    )]
    OutOfRange {
        /// The file name (or `table1`).
        origin: String,
        /// The line of the key; `None` for command-line values and built-ins.
        line: Option<usize>,
        /// `section.key`, or the command-line flag (`--dt`).
        key: String,
        /// The value, in the unit of the key (deg for `*_deg`, rev/min for `rpm*`).
        value: f64,
        /// The allowed range in words, with its unit (`finite and > 0 (N/m)`).
        allowed: String,
    },
    /// Values that are each valid but do not fit together (the model's message).
    #[error("{}: {message}", At(origin, line))]
    Inconsistent {
        /// The file name (or `table1`).
        origin: String,
        /// The line of the key or section at fault, if any.
        line: Option<usize>,
        /// The model's message.
        message: String,
    },
    /// The cross-coupled bearings' damping matrix would feed energy into the rotor.
    #[error(
        "{}: rotor: the damping matrix [[cxx, cxz], [czx, czz]] = [[{cxx}, {cxz}], [{czx}, \
         {czz}]] N s/m is not dissipative: its symmetric part must be positive semi-definite, \
         i.e. cxx >= 0, czz >= 0 and cxx czz >= ((cxz + czx) / 2)^2",
        At(origin, line)
    )]
    DampingNotDissipative {
        /// The file name.
        origin: String,
        /// The line of the `[rotor]` section.
        line: Option<usize>,
        /// rotor.cxx \[N s/m\].
        cxx: f64,
        /// rotor.cxz \[N s/m\].
        cxz: f64,
        /// rotor.czx \[N s/m\].
        czx: f64,
        /// rotor.czz \[N s/m\].
        czz: f64,
    },
    /// `rotor.model` is a string but not a model.
    #[error(
        "{}: rotor.model = \"{value}\" is not a rotor model: must be \"jeffcott\", \
         \"cross_coupled\" or \"finite_element\"",
        At(origin, line)
    )]
    UnknownModel {
        /// The file name.
        origin: String,
        /// The line of the key.
        line: Option<usize>,
        /// The string written.
        value: String,
    },
    /// A view that takes a lumped rotor (jeffcott or cross_coupled) asked of a scenario
    /// whose rotor is a finite-element one ([`super::ScenarioSpec::finite_element`]).
    #[error(
        "{}: rotor.model = \"finite_element\": {who} does not take a finite-element rotor \
         (only rotor.model = \"jeffcott\" or \"cross_coupled\")",
        At(origin, line)
    )]
    FiniteElementRotor {
        /// The file name.
        origin: String,
        /// The line of `rotor.model`.
        line: Option<usize>,
        /// What asked for the lumped rotor (`simulate`, `identify`).
        who: String,
    },
    /// `speed.kind` is a string but not a speed profile.
    #[error(
        "{}: speed.kind = \"{value}\" is not a speed profile: must be \"constant\" or \"ramp\"",
        At(origin, line)
    )]
    UnknownSpeedKind {
        /// The file name.
        origin: String,
        /// The line of the key.
        line: Option<usize>,
        /// The string written.
        value: String,
    },
    /// A `[speed]` key that the profile's kind does not take (`rpm0` with `constant`).
    #[error(
        "{}: speed.{key} does not apply to kind = \"{kind}\" (constant takes rpm; ramp takes \
         rpm0 and accel)",
        At(origin, line)
    )]
    SpeedKeyNotApplicable {
        /// The file name.
        origin: String,
        /// The line of the key.
        line: Option<usize>,
        /// The key (`rpm0`).
        key: String,
        /// The profile's kind.
        kind: SpeedKind,
    },
    /// A whole section is missing.
    #[error(
        "{origin}: missing section [{section}] ({contents}){}",
        NeededBy(needed_by)
    )]
    MissingSection {
        /// The file name.
        origin: String,
        /// The section (`speed`).
        section: String,
        /// What the section holds, in words.
        contents: String,
        /// The view that needs it (`simulate`), if only some views do.
        needed_by: Option<String>,
    },
    /// A `[rotor]` key that a view needs.
    #[error(
        "{origin}: missing key rotor.{key} ({unit}){}{}",
        SectionAt(section_line),
        NeededBy(needed_by)
    )]
    MissingRotorKey {
        /// The file name.
        origin: String,
        /// The key (`kz`).
        key: String,
        /// Its unit (`N/m`).
        unit: String,
        /// The line of `[rotor]`; `None` when there is no such section.
        section_line: Option<usize>,
        /// The view that needs it (`simulate`, `identify`).
        needed_by: Option<String>,
    },
    /// `[speed]` without `kind`.
    #[error(
        "{}: missing key speed.kind: must be \"constant\" or \"ramp\"",
        At(origin, line)
    )]
    MissingSpeedKind {
        /// The file name.
        origin: String,
        /// The line of `[speed]`.
        line: Option<usize>,
    },
    /// A key that the speed profile's kind needs (`rpm` for `constant`).
    #[error(
        "{}: missing key speed.{key} ({unit}) for kind = \"{kind}\"",
        At(origin, line)
    )]
    MissingSpeedKey {
        /// The file name.
        origin: String,
        /// The line of `[speed]`.
        line: Option<usize>,
        /// The key (`rpm`).
        key: String,
        /// Its unit (`rev/min`).
        unit: String,
        /// The profile's kind.
        kind: SpeedKind,
    },
    /// A key of `[acquisition]` that must be given.
    #[error("{}: missing key {key} ({what})", At(origin, line))]
    MissingKey {
        /// The file name.
        origin: String,
        /// The line of the table that lacks it.
        line: Option<usize>,
        /// `table.key` (`acquisition.keyphasor.column`).
        key: String,
        /// What it holds, with its unit.
        what: String,
    },
    /// A sampling value given neither in `[sampling]` nor on the command line.
    #[error("{origin}: missing key sampling.{key} (s); give it in [sampling] or with {flag}")]
    MissingSamplingKey {
        /// The file name.
        origin: String,
        /// The key (`dt`).
        key: String,
        /// The command-line flag that may give it instead (`--dt`).
        flag: String,
    },
}

/// A value of `rotor.model`: a lumped model or the finite-element rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotorModel {
    /// `jeffcott` or `cross_coupled`.
    Lumped(crate::parameter::ModelKind),
    /// `finite_element`.
    FiniteElement,
}

impl RotorModel {
    /// Its name in `rotor.model`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Lumped(m) => m.name(),
            Self::FiniteElement => super::FINITE_ELEMENT,
        }
    }
}

impl ScenarioFileError {
    /// The file name (or `table1`) the error is about.
    pub fn origin(&self) -> &str {
        match self {
            Self::InvalidToml { origin, .. }
            | Self::UnknownSection { origin, .. }
            | Self::NotASection { origin, .. }
            | Self::UnknownKey { origin, .. }
            | Self::WrongType { origin, .. }
            | Self::OutOfRange { origin, .. }
            | Self::Inconsistent { origin, .. }
            | Self::UnknownSpeedKind { origin, .. }
            | Self::SpeedKeyNotApplicable { origin, .. }
            | Self::MissingSection { origin, .. }
            | Self::MissingRotorKey { origin, .. }
            | Self::MissingSpeedKind { origin, .. }
            | Self::MissingSpeedKey { origin, .. }
            | Self::MissingSamplingKey { origin, .. }
            | Self::MissingKey { origin, .. }
            | Self::DampingNotDissipative { origin, .. }
            | Self::FiniteElementRotor { origin, .. }
            | Self::UnknownModel { origin, .. } => origin,
        }
    }

    /// The 1-based line the message starts with, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            Self::InvalidToml { line, .. }
            | Self::UnknownSection { line, .. }
            | Self::NotASection { line, .. }
            | Self::UnknownKey { line, .. }
            | Self::WrongType { line, .. }
            | Self::OutOfRange { line, .. }
            | Self::Inconsistent { line, .. }
            | Self::UnknownSpeedKind { line, .. }
            | Self::SpeedKeyNotApplicable { line, .. }
            | Self::MissingSpeedKind { line, .. }
            | Self::MissingSpeedKey { line, .. }
            | Self::MissingKey { line, .. }
            | Self::DampingNotDissipative { line, .. }
            | Self::FiniteElementRotor { line, .. }
            | Self::UnknownModel { line, .. } => *line,
            Self::MissingSection { .. }
            | Self::MissingRotorKey { .. }
            | Self::MissingSamplingKey { .. } => None,
        }
    }

    /// A model error about the value of `line` as a scenario error, the model's field name
    /// renamed to the user's key with `names` (`("kx", "rotor.kx")`, `("dt", "--dt")`).
    pub(super) fn from_model(
        origin: &str,
        line: Option<usize>,
        e: ModelError,
        names: &[(&str, &str)],
    ) -> Self {
        match e {
            ModelError::OutOfRange {
                field,
                value,
                allowed,
            } => Self::OutOfRange {
                origin: origin.to_owned(),
                line,
                key: names
                    .iter()
                    .find(|(f, _)| *f == field)
                    .map_or(field, |(_, k)| *k)
                    .to_owned(),
                value,
                allowed: allowed.to_owned(),
            },
            ModelError::Inconsistent(message) => Self::Inconsistent {
                origin: origin.to_owned(),
                line,
                message,
            },
            ModelError::DampingNotDissipative { cxx, cxz, czx, czz } => {
                Self::DampingNotDissipative {
                    origin: origin.to_owned(),
                    line,
                    cxx,
                    cxz,
                    czx,
                    czz,
                }
            }
        }
    }
}

/// `FILE:LINE` or `FILE`.
struct At<'a>(&'a str, &'a Option<usize>);

impl fmt::Display for At<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.1 {
            Some(l) => write!(f, "{}:{l}", self.0),
            None => f.write_str(self.0),
        }
    }
}

/// `; simulate needs it`, or nothing.
struct NeededBy<'a>(&'a Option<String>);

impl fmt::Display for NeededBy<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(who) => write!(f, "; {who} needs it"),
            None => Ok(()),
        }
    }
}

/// ` (section [rotor] at line L)` or ` (no [rotor] section)`.
struct SectionAt<'a>(&'a Option<usize>);

impl fmt::Display for SectionAt<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(l) => write!(f, " (section [rotor] at line {l})"),
            None => f.write_str(" (no [rotor] section)"),
        }
    }
}

/// `a` or `an` before a TOML type name.
fn article(type_name: &str) -> &'static str {
    match type_name.as_bytes().first() {
        Some(b'a' | b'e' | b'i' | b'o' | b'u') => "an",
        _ => "a",
    }
}
