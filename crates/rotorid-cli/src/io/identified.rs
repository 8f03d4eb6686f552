//! The identified rotor in an identification summary (`SUMMARY.json`, see [`super::summary`]):
//! the two top-level fields `rotorid analyze` and `rotorid balance` read, and nothing else.
//!
//! ```json
//! {
//!   "rotor": {"m": 14.29, "cx": 10.0, "kx": 1.195e6, "cz": 10.0, "kz": 1.195e6,
//!             "a": 2.871, "mud": 1.5e-5, "alpha": 0.785398},
//!   "covariance": {"names": ["m", "cx", "kx", "cz", "kz", "mud_cos_alpha", "mud_sin_alpha"],
//!                  "matrix": [[3.6e-7, ...], ...]} | null
//! }
//! ```
//!
//! - `rotor`: every parameter a finite number in SI units: m \[kg\], cx, cz \[N s/m\], kx, kz
//!   \[N/m\], a \[N s^2/m\], mud = m_u d \[kg m\], alpha \[rad\] (shaft angle of the unbalance
//!   from the keyphasor reference in the direction of rotation).
//! - `covariance`: the covariance of the identified parameters, names from `m, cx, kx, cz,
//!   kz, a, mud_cos_alpha, mud_sin_alpha` (mud_cos_alpha = m_u d cos(alpha), likewise sin),
//!   one row and one column per name, SI units squared; a JSON `null` entry is infinite
//!   (an undetermined parameter). `null` for the whole field: no uncertainty is available.
//!
//! A missing field, or a value of the wrong type, is an error naming the file and the field.

use std::path::Path;

use anyhow::{anyhow, bail, Context};
use rotorid::analysis::ParameterCovariance;
use rotorid::{RotorParams, Unbalance};
use serde_json::Value;

/// The rotor parameters in `rotor`, in order, with their units.
const ROTOR_FIELDS: [(&str, &str); 8] = [
    ("m", "kg"),
    ("cx", "N s/m"),
    ("kx", "N/m"),
    ("cz", "N s/m"),
    ("kz", "N/m"),
    ("a", "N s^2/m"),
    ("mud", "kg m"),
    ("alpha", "rad"),
];

/// What a summary says about the identified rotor.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifiedRotor {
    /// The parameters; the unbalance as m_u = mud at d = 1 m (only m_u d matters).
    pub params: RotorParams,
    /// Their covariance, when the summary has one.
    pub covariance: Option<ParameterCovariance>,
}

impl IdentifiedRotor {
    /// Read the summary at `path`.
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read summary {}", path.display()))?;
        Self::parse(&path.display().to_string(), &text)
    }

    /// Parse the summary `text`; `file` names it in messages.
    pub fn parse(file: &str, text: &str) -> anyhow::Result<Self> {
        let doc: Value =
            serde_json::from_str(text).map_err(|e| anyhow!("{file}: not valid JSON: {e}"))?;
        let Some(top) = doc.as_object() else {
            bail!("{file}: expected a JSON object (an identification summary)");
        };
        let rotor = top.get("rotor").ok_or_else(|| {
            anyhow!(
                "{file}: missing field `rotor` (the identified m, cx, kx, cz, kz, a, mud, alpha)"
            )
        })?;
        let Some(rotor) = rotor.as_object() else {
            bail!("{file}: field `rotor` must be an object with m, cx, kx, cz, kz, a, mud, alpha");
        };
        let mut v = [0.0; 8];
        for (slot, (name, unit)) in v.iter_mut().zip(ROTOR_FIELDS) {
            let x = rotor
                .get(name)
                .ok_or_else(|| anyhow!("{file}: missing field `rotor.{name}` ({unit})"))?;
            *slot = x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                anyhow!("{file}: field `rotor.{name}` must be a finite number ({unit}), found {x}")
            })?;
        }
        let [m, cx, kx, cz, kz, a, mud, alpha] = v;
        let params = RotorParams {
            coupling: None,
            m,
            cx,
            cz,
            kx,
            kz,
            a,
            unbalance: Unbalance {
                m_u: mud,
                d: 1.0,
                alpha,
            },
        };
        let cov = top.get("covariance").ok_or_else(|| {
            anyhow!("{file}: missing field `covariance` ({{\"names\": [...], \"matrix\": [[...]]}} or null)")
        })?;
        let covariance = match cov {
            Value::Null => None,
            Value::Object(c) => Some(covariance(file, c)?),
            other => bail!(
                "{file}: field `covariance` must be an object {{\"names\": [...], \"matrix\": [[...]]}} or null, found {other}"
            ),
        };
        Ok(Self { params, covariance })
    }
}

fn covariance(
    file: &str,
    c: &serde_json::Map<String, Value>,
) -> anyhow::Result<ParameterCovariance> {
    let names = c
        .get("names")
        .ok_or_else(|| anyhow!("{file}: missing field `covariance.names`"))?
        .as_array()
        .ok_or_else(|| anyhow!("{file}: field `covariance.names` must be an array of names"))?
        .iter()
        .enumerate()
        .map(|(i, n)| {
            n.as_str().map(str::to_owned).ok_or_else(|| {
                anyhow!("{file}: field `covariance.names[{i}]` must be a string, found {n}")
            })
        })
        .collect::<anyhow::Result<Vec<String>>>()?;
    let rows = c
        .get("matrix")
        .ok_or_else(|| anyhow!("{file}: missing field `covariance.matrix`"))?
        .as_array()
        .ok_or_else(|| anyhow!("{file}: field `covariance.matrix` must be an array of rows"))?;
    let mut matrix = Vec::with_capacity(rows.len());
    for (i, row) in rows.iter().enumerate() {
        let row = row.as_array().ok_or_else(|| {
            anyhow!("{file}: field `covariance.matrix[{i}]` must be an array of numbers")
        })?;
        let mut out = Vec::with_capacity(row.len());
        for (j, x) in row.iter().enumerate() {
            out.push(match x {
                Value::Null => f64::INFINITY,
                x => x.as_f64().ok_or_else(|| {
                    anyhow!(
                        "{file}: field `covariance.matrix[{i}][{j}]` must be a number or null, found {x}"
                    )
                })?,
            });
        }
        matrix.push(out);
    }
    ParameterCovariance::new(names, matrix).map_err(|e| anyhow!("{file}: field `covariance`: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{"rotor": {"m": 14.29, "cx": 10, "kx": 1.195e6, "cz": 10, "kz": 1.195e6,
        "a": 2.871, "mud": 1.5e-5, "alpha": 0.7853981633974483},
        "covariance": {"names": ["m", "kx", "a"], "matrix": [[1e-6, 0.05, null], [0.05, 4e4, null], [null, null, null]]},
        "method": "refine"}"#;

    #[test]
    fn reads_rotor_and_covariance_with_null_as_undetermined() {
        let r = IdentifiedRotor::parse("s.json", GOOD).unwrap();
        assert_eq!(r.params.kx, 1.195e6);
        assert_eq!(r.params.unbalance.mud(), 1.5e-5);
        let c = r.covariance.unwrap();
        assert_eq!(c.names(), ["m", "kx", "a"]);
        assert_eq!(
            c.std(rotorid::analysis::CovarianceParameter::Kx),
            Some(200.0)
        );
        assert_eq!(c.std(rotorid::analysis::CovarianceParameter::A), None);
        let none = GOOD.replace(
            r#"{"names": ["m", "kx", "a"], "matrix": [[1e-6, 0.05, null], [0.05, 4e4, null], [null, null, null]]}"#,
            "null",
        );
        assert_eq!(
            IdentifiedRotor::parse("s.json", &none).unwrap().covariance,
            None
        );
    }

    #[test]
    fn errors_name_the_file_and_the_field() {
        let e =
            IdentifiedRotor::parse("s.json", &GOOD.replace(r#""kz": 1.195e6,"#, "")).unwrap_err();
        assert_eq!(e.to_string(), "s.json: missing field `rotor.kz` (N/m)");
        let e = IdentifiedRotor::parse("s.json", &GOOD.replace(r#""a": 2.871"#, r#""a": "x""#))
            .unwrap_err();
        assert!(e
            .to_string()
            .starts_with("s.json: field `rotor.a` must be a finite number"));
        let e = IdentifiedRotor::parse("s.json", r#"{"rotor": {}}"#).unwrap_err();
        assert_eq!(e.to_string(), "s.json: missing field `rotor.m` (kg)");
        let no_cov = GOOD.replace(r#""covariance""#, r#""other""#);
        let e = IdentifiedRotor::parse("s.json", &no_cov).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("s.json: missing field `covariance`"),
            "{e}"
        );
        let bad_name = GOOD.replace(r#""kx", "a"]"#, r#""k", "a"]"#);
        let e = IdentifiedRotor::parse("s.json", &bad_name).unwrap_err();
        assert!(e.to_string().contains("unknown parameter \"k\""), "{e}");
    }
}
