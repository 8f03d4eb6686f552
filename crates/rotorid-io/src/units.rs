//! Units of the channels a record is made of, and their conversion to SI.
//!
//! A channel plays a role with a [`Quantity`]: `t` is a time, `x` and `z` displacements,
//! `phi` an angle, `phi_dot` an angular speed, `phi_ddot` an angular acceleration, a probe
//! or keyphasor a voltage. The unit the file gives (a CSV header suffix `x [um]` or
//! `x (um)`, a TDMS `unit_string`, a UFF58 ordinate unit) is looked up with
//! [`conversion`]; no unit means SI. Accepted, case-insensitively, blanks ignored, `µ`/`μ`
//! read as `u`, `²` as `^2`:
//!
//! | quantity | SI | also accepted |
//! |---|---|---|
//! | time | `s` | `ms`, `us` |
//! | displacement | `m` | `mm`, `um` (`µm`, `micron`), `nm`, `mil` (25.4 um), `in` (25.4 mm) |
//! | angle | `rad` | `deg` (`°`), `rev` (2 pi rad) |
//! | angular speed | `rad/s` | `rpm` (`r/min`, `rev/min`), `Hz` (`rev/s`), `deg/s` |
//! | angular acceleration | `rad/s^2` | `rpm/s`, `Hz/s` (`rev/s^2`), `deg/s^2` |
//! | voltage | `V` | `mV` |
//!
//! An unknown unit, or a unit of another quantity (`x [rpm]`), is an error that lists what
//! the role takes ([`UnitError`]). Decimal prefixes divide by an exact power of ten (one
//! correctly rounded operation: `1.5 mm` becomes exactly 0.0015's nearest `f64`, `3.3 um`
//! lands within one ulp of 3.3e-6); the other factors (pi/30 for rpm, 25.4e-6 for mil)
//! multiply. SI units convert by identity: the values are bit for bit those of the file.

use std::f64::consts::PI;
use std::fmt;

/// What a channel measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Time \[s\].
    Time,
    /// Displacement \[m\].
    Displacement,
    /// Angle \[rad\].
    Angle,
    /// Angular speed \[rad/s\].
    AngularSpeed,
    /// Angular acceleration \[rad/s^2\].
    AngularAcceleration,
    /// Voltage \[V\] (raw probe and keyphasor channels).
    Voltage,
}

impl Quantity {
    /// The SI unit.
    pub fn si(self) -> &'static str {
        match self {
            Quantity::Time => "s",
            Quantity::Displacement => "m",
            Quantity::Angle => "rad",
            Quantity::AngularSpeed => "rad/s",
            Quantity::AngularAcceleration => "rad/s^2",
            Quantity::Voltage => "V",
        }
    }

    /// The units accepted, for messages.
    pub fn accepted(self) -> &'static str {
        match self {
            Quantity::Time => "s, ms, us",
            Quantity::Displacement => "m, mm, um (µm), nm, mil, in",
            Quantity::Angle => "rad, deg, rev",
            Quantity::AngularSpeed => "rad/s, rpm, Hz (rev/s), deg/s",
            Quantity::AngularAcceleration => "rad/s^2, rpm/s, Hz/s (rev/s^2), deg/s^2",
            Quantity::Voltage => "V, mV",
        }
    }

    /// `a` or `an`, for the quantity's name in messages.
    pub fn article(self) -> &'static str {
        match self {
            Quantity::Angle | Quantity::AngularSpeed | Quantity::AngularAcceleration => "an",
            _ => "a",
        }
    }

    /// The quantity's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Time => "time",
            Quantity::Displacement => "displacement",
            Quantity::Angle => "angle",
            Quantity::AngularSpeed => "angular speed",
            Quantity::AngularAcceleration => "angular acceleration",
            Quantity::Voltage => "voltage",
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How a value in the file's unit becomes SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// Already SI: unchanged.
    Identity,
    /// Divided by this power of ten (decimal prefixes).
    Div(f64),
    /// Multiplied by this factor.
    Mul(f64),
}

/// A unit found for a channel: its canonical spelling and the way to SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conversion {
    /// The quantity.
    pub quantity: Quantity,
    /// The unit's canonical spelling (`um`, `rpm`).
    pub unit: &'static str,
    /// How values become SI.
    pub scale: Scale,
}

impl Conversion {
    /// The SI conversion of `quantity` (no unit given).
    pub fn si(quantity: Quantity) -> Self {
        Self {
            quantity,
            unit: quantity.si(),
            scale: Scale::Identity,
        }
    }

    /// `v` in SI.
    #[inline]
    pub fn apply(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Identity => v,
            Scale::Div(d) => v / d,
            Scale::Mul(m) => v * m,
        }
    }

    /// Convert every value of `data` in place.
    pub fn apply_all(&self, data: &mut [f64]) {
        if self.scale != Scale::Identity {
            for v in data {
                *v = self.apply(*v);
            }
        }
    }

    /// True for the SI unit (values unchanged).
    pub fn is_identity(&self) -> bool {
        self.scale == Scale::Identity
    }

    /// The factor to SI (for messages: `1 um = 1e-6 m`).
    pub fn factor(&self) -> f64 {
        match self.scale {
            Scale::Identity => 1.0,
            Scale::Div(d) => 1.0 / d,
            Scale::Mul(m) => m,
        }
    }
}

/// A unit that cannot be used for a channel.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UnitError {
    /// The unit is not one we know.
    #[error("unknown unit {unit:?} for {} {expected}: use one of {accepted}", expected.article(), accepted = expected.accepted())]
    Unknown {
        /// The unit as written.
        unit: String,
        /// The quantity the channel's role needs.
        expected: Quantity,
    },
    /// The unit is known but measures something else.
    #[error("unit {unit:?} is {} {found} unit, but this channel holds {} {expected}: use one of {accepted}{hint}", found.article(), expected.article(), accepted = expected.accepted(), hint = hint(*found, *expected))]
    WrongQuantity {
        /// The unit as written.
        unit: String,
        /// What the unit measures.
        found: Quantity,
        /// The quantity the channel's role needs.
        expected: Quantity,
    },
}

/// What to do about a channel of `found` where `expected` is needed, when there is more to
/// say than the units to use.
fn hint(found: Quantity, expected: Quantity) -> &'static str {
    match (found, expected) {
        (Quantity::Voltage, Quantity::Displacement) => {
            " (a proximity probe's volts become a displacement through the scenario's \
             [acquisition] table: each probe's column, angle and sensitivity, and the \
             keyphasor; docs/acquisition.md)"
        }
        _ => "",
    }
}

/// Every unit we know: spelling (normalised, see [`normalise_unit`]), canonical spelling,
/// quantity, scale.
const UNITS: &[(&str, &str, Quantity, Scale)] = {
    use Quantity::*;
    use Scale::*;
    const DEG: f64 = PI / 180.0;
    &[
        ("s", "s", Time, Identity),
        ("sec", "s", Time, Identity),
        ("ms", "ms", Time, Div(1e3)),
        ("us", "us", Time, Div(1e6)),
        ("m", "m", Displacement, Identity),
        ("mm", "mm", Displacement, Div(1e3)),
        ("um", "um", Displacement, Div(1e6)),
        ("micron", "um", Displacement, Div(1e6)),
        ("microns", "um", Displacement, Div(1e6)),
        ("nm", "nm", Displacement, Div(1e9)),
        ("mil", "mil", Displacement, Mul(25.4e-6)),
        ("mils", "mil", Displacement, Mul(25.4e-6)),
        ("in", "in", Displacement, Mul(0.0254)),
        ("inch", "in", Displacement, Mul(0.0254)),
        ("rad", "rad", Angle, Identity),
        ("deg", "deg", Angle, Mul(DEG)),
        ("°", "deg", Angle, Mul(DEG)),
        ("degree", "deg", Angle, Mul(DEG)),
        ("degrees", "deg", Angle, Mul(DEG)),
        ("rev", "rev", Angle, Mul(2.0 * PI)),
        ("rad/s", "rad/s", AngularSpeed, Identity),
        ("rpm", "rpm", AngularSpeed, Mul(PI / 30.0)),
        ("r/min", "rpm", AngularSpeed, Mul(PI / 30.0)),
        ("rev/min", "rpm", AngularSpeed, Mul(PI / 30.0)),
        ("hz", "Hz", AngularSpeed, Mul(2.0 * PI)),
        ("rev/s", "Hz", AngularSpeed, Mul(2.0 * PI)),
        ("rps", "Hz", AngularSpeed, Mul(2.0 * PI)),
        ("deg/s", "deg/s", AngularSpeed, Mul(DEG)),
        ("rad/s^2", "rad/s^2", AngularAcceleration, Identity),
        ("rad/s2", "rad/s^2", AngularAcceleration, Identity),
        ("rpm/s", "rpm/s", AngularAcceleration, Mul(PI / 30.0)),
        ("hz/s", "Hz/s", AngularAcceleration, Mul(2.0 * PI)),
        ("rev/s^2", "Hz/s", AngularAcceleration, Mul(2.0 * PI)),
        ("rev/s2", "Hz/s", AngularAcceleration, Mul(2.0 * PI)),
        ("deg/s^2", "deg/s^2", AngularAcceleration, Mul(DEG)),
        ("deg/s2", "deg/s^2", AngularAcceleration, Mul(DEG)),
        ("v", "V", Voltage, Identity),
        ("volt", "V", Voltage, Identity),
        ("volts", "V", Voltage, Identity),
        ("mv", "mV", Voltage, Div(1e3)),
        ("millivolt", "mV", Voltage, Div(1e3)),
        ("millivolts", "mV", Voltage, Div(1e3)),
    ]
};

/// The spelling units are compared in: blanks dropped, lower case, `µ`/`μ` as `u`,
/// `²` as `^2`, `**2` as `^2`.
pub fn normalise_unit(unit: &str) -> String {
    let mut s = String::with_capacity(unit.len());
    for c in unit.chars() {
        match c {
            c if c.is_whitespace() => {}
            'µ' | 'μ' => s.push('u'),
            '²' => s.push_str("^2"),
            c => s.extend(c.to_lowercase()),
        }
    }
    s.replace("**2", "^2")
}

/// Look `unit` up; `None` when unknown.
pub fn lookup(unit: &str) -> Option<Conversion> {
    let key = normalise_unit(unit);
    UNITS
        .iter()
        .find(|(spelling, _, _, _)| *spelling == key)
        .map(|&(_, unit, quantity, scale)| Conversion {
            quantity,
            unit,
            scale,
        })
}

/// The conversion of a channel holding `expected` whose file gives the unit `unit`
/// (`None` or empty: SI).
pub fn conversion(expected: Quantity, unit: Option<&str>) -> Result<Conversion, UnitError> {
    let Some(unit) = unit.map(str::trim).filter(|u| !u.is_empty()) else {
        return Ok(Conversion::si(expected));
    };
    match lookup(unit) {
        Some(c) if c.quantity == expected => Ok(c),
        Some(c) => Err(UnitError::WrongQuantity {
            unit: unit.to_owned(),
            found: c.quantity,
            expected,
        }),
        None => Err(UnitError::Unknown {
            unit: unit.to_owned(),
            expected,
        }),
    }
}

/// Split a header name into the name and the unit of a trailing suffix in brackets or
/// parentheses: `"x [um]"` -> `("x", Some("um"))`, `"phi_dot (rpm)"` ->
/// `("phi_dot", Some("rpm"))`, `"t"` -> `("t", None)`. The name is trimmed; a suffix with
/// nothing before it is not a unit (`"[x]"` is a name).
pub fn split_unit(header: &str) -> (&str, Option<&str>) {
    let s = header.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(inner) = s.strip_suffix(close) {
            if let Some(i) = inner.rfind(open) {
                let head = inner[..i].trim_end();
                if !head.is_empty() {
                    return (head, Some(inner[i + open.len_utf8()..].trim()));
                }
            }
        }
    }
    (s, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn si_is_bit_for_bit() {
        let c = conversion(Quantity::Displacement, Some("m")).unwrap();
        assert!(c.is_identity());
        for v in [1e-300, 0.1, -3.7e-5, f64::MIN_POSITIVE] {
            assert_eq!(c.apply(v).to_bits(), v.to_bits());
        }
        assert!(conversion(Quantity::Time, None).unwrap().is_identity());
        assert!(conversion(Quantity::Time, Some("  "))
            .unwrap()
            .is_identity());
    }

    #[test]
    fn decimal_prefixes_land_within_one_ulp_of_the_decimal() {
        let um = conversion(Quantity::Displacement, Some("µm")).unwrap();
        for (text_um, text_m) in [("12.5", "1.25e-5"), ("3.3", "3.3e-6"), ("0.7", "7e-7")] {
            let v: f64 = text_um.parse().unwrap();
            let m: f64 = text_m.parse().unwrap();
            let ulps = (um.apply(v).to_bits() as i64 - m.to_bits() as i64).abs();
            assert!(
                ulps <= 1,
                "{text_um} um -> {:e}, {ulps} ulp from {text_m}",
                um.apply(v)
            );
        }
        let mm = conversion(Quantity::Displacement, Some("mm")).unwrap();
        assert_eq!(mm.apply(1.5), 0.0015);
        let ms = conversion(Quantity::Time, Some("ms")).unwrap();
        assert_eq!(ms.apply(0.1), 1e-4);
    }

    #[test]
    fn factors_against_their_definitions() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * b.abs();
        let c = |q, u| conversion(q, Some(u)).unwrap();
        // 1 mil = 0.001 in = 25.4 um; 1 in = 25.4 mm (exact by definition).
        assert!(close(
            c(Quantity::Displacement, "mil").apply(1.0),
            0.0254 / 1000.0
        ));
        assert!(close(
            c(Quantity::Displacement, "in").apply(1.0),
            25.4 / 1000.0
        ));
        // 60 rpm = 1 rev/s = 2 pi rad/s; 1 Hz of shaft speed = 1 rev/s.
        assert!(close(
            c(Quantity::AngularSpeed, "rpm").apply(60.0),
            2.0 * PI
        ));
        assert!(close(c(Quantity::AngularSpeed, "Hz").apply(1.0), 2.0 * PI));
        assert!(close(
            c(Quantity::AngularSpeed, "rev/min").apply(3000.0),
            100.0 * PI
        ));
        assert!(close(c(Quantity::Angle, "deg").apply(180.0), PI));
        assert!(close(c(Quantity::Angle, "rev").apply(0.5), PI));
        assert!(close(
            c(Quantity::AngularAcceleration, "rpm/s").apply(30.0),
            PI
        ));
        assert!(close(
            c(Quantity::AngularAcceleration, "rad/s²").apply(2.0),
            2.0
        ));
        assert!(close(c(Quantity::Voltage, "mV").apply(200.0), 0.2));
    }

    #[test]
    fn spelling_variants() {
        for u in ["um", "µm", "μm", "UM", " u m ", "micron"] {
            assert_eq!(
                conversion(Quantity::Displacement, Some(u)).unwrap().unit,
                "um",
                "{u}"
            );
        }
        for u in ["rad/s^2", "rad/s2", "rad/s²", "rad/s**2", "RAD/S^2"] {
            assert!(conversion(Quantity::AngularAcceleration, Some(u))
                .unwrap()
                .is_identity());
        }
    }

    #[test]
    fn unknown_and_wrong_units_say_what_is_accepted() {
        let e = conversion(Quantity::Displacement, Some("furlong")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown unit \"furlong\" for a displacement: use one of m, mm, um (µm), nm, mil, in"
        );
        let e = conversion(Quantity::Displacement, Some("rpm")).unwrap_err();
        assert!(matches!(
            e,
            UnitError::WrongQuantity {
                found: Quantity::AngularSpeed,
                expected: Quantity::Displacement,
                ..
            }
        ));
        assert!(e.to_string().contains("rpm"), "{e}");
        assert!(!e.to_string().contains("[acquisition]"), "{e}");
        // a probe's volts (as DAQmx names them) where metres are needed: the way to them
        let e = conversion(Quantity::Displacement, Some("Volts")).unwrap_err();
        assert!(
            e.to_string().starts_with(
                "unit \"Volts\" is a voltage unit, but this channel holds a displacement: use \
                 one of m, mm, um (µm), nm, mil, in (a proximity probe's volts become a \
                 displacement through the scenario's [acquisition] table"
            ),
            "{e}"
        );
        // rad/s is a speed, not an angle.
        assert!(conversion(Quantity::Angle, Some("rad/s")).is_err());
    }

    #[test]
    fn header_suffixes() {
        assert_eq!(split_unit("x [um]"), ("x", Some("um")));
        assert_eq!(split_unit(" phi_dot (rpm) "), ("phi_dot", Some("rpm")));
        assert_eq!(split_unit("t[s]"), ("t", Some("s")));
        assert_eq!(split_unit("t"), ("t", None));
        assert_eq!(split_unit("[x]"), ("[x]", None));
        assert_eq!(split_unit("x []"), ("x", Some("")));
        assert_eq!(split_unit("a (b) [mm]"), ("a (b)", Some("mm")));
    }
}
