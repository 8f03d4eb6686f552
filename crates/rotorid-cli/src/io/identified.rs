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
//! - `model` (schema 3): `jeffcott` (the default when absent, as in schema 2 files) or
//!   `cross_coupled`.
//! - `rotor`: every parameter of the model a finite number in SI units: m \[kg\], cx, cz
//!   \[N s/m\], kx, kz \[N/m\], a \[N s^2/m\], mud = m_u d \[kg m\], alpha \[rad\] (shaft angle
//!   of the unbalance from the keyphasor reference in the direction of rotation); the
//!   cross-coupled model names the bearing coefficients cxx, cxz, czx, czz \[N s/m\] and
//!   kxx, kxz, kzx, kzz \[N/m\] (docs/method.md section 1.6).
//! - `covariance`: the covariance of the identified parameters, names from `m, cx, kx, cz,
//!   kz, a, mud_cos_alpha, mud_sin_alpha` (mud_cos_alpha = m_u d cos(alpha), likewise sin)
//!   and the cross-coupled model's `cxx, cxz, czx, czz, kxx, kxz, kzx, kzz`,
//!   one row and one column per name, SI units squared; a JSON `null` entry is infinite
//!   (an undetermined parameter). `null` for the whole field: no uncertainty is available.
//!
//! A missing field, or a value of the wrong type, is an error naming the file and the field.

use std::path::Path;

use anyhow::{anyhow, bail, Context};
use rotorid::analysis::ParameterCovariance;
use rotorid::model::CrossCoupling;
use rotorid::parameter::ModelKind;
use rotorid::{RotorParams, Unbalance};
use serde_json::Value;

/// The rotor parameters in `rotor`, in order, with their units.
pub(crate) const ROTOR_FIELDS: [(&str, &str); 8] = [
    ("m", "kg"),
    ("cx", "N s/m"),
    ("kx", "N/m"),
    ("cz", "N s/m"),
    ("kz", "N/m"),
    ("a", "N s^2/m"),
    ("mud", "kg m"),
    ("alpha", "rad"),
];

/// The cross-coupled model's `rotor` fields, in the summary's order.
pub(crate) const CROSS_ROTOR_FIELDS: [(&str, &str); 12] = [
    ("m", "kg"),
    ("cxx", "N s/m"),
    ("cxz", "N s/m"),
    ("czx", "N s/m"),
    ("czz", "N s/m"),
    ("kxx", "N/m"),
    ("kxz", "N/m"),
    ("kzx", "N/m"),
    ("kzz", "N/m"),
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
        let model = match top.get("model") {
            None | Some(Value::Null) => ModelKind::Jeffcott,
            Some(v) => ModelKind::ALL
                .into_iter()
                .find(|k| v.as_str() == Some(k.name()))
                .ok_or_else(|| {
                    anyhow!("{file}: field `model` must be \"jeffcott\" or \"cross_coupled\", found {v}")
                })?,
        };
        let fields: &[(&str, &str)] = match model {
            ModelKind::Jeffcott => &ROTOR_FIELDS,
            ModelKind::CrossCoupled => &CROSS_ROTOR_FIELDS,
        };
        let list = fields.iter().map(|f| f.0).collect::<Vec<_>>().join(", ");
        let rotor = top
            .get("rotor")
            .ok_or_else(|| anyhow!("{file}: missing field `rotor` (the identified {list})"))?;
        let Some(rotor) = rotor.as_object() else {
            bail!("{file}: field `rotor` must be an object with {list}");
        };
        let mut v = Vec::with_capacity(fields.len());
        for (name, unit) in fields {
            let x = rotor.get(*name).ok_or_else(|| match model {
                ModelKind::Jeffcott => anyhow!("{file}: missing field `rotor.{name}` ({unit})"),
                ModelKind::CrossCoupled => anyhow!(
                    "{file}: missing field `rotor.{name}` ({unit}; the cross-coupled model's rotor has {list})"
                ),
            })?;
            v.push(x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                anyhow!("{file}: field `rotor.{name}` must be a finite number ({unit}), found {x}")
            })?);
        }
        let (coupling, v) = match model {
            ModelKind::Jeffcott => (None, [v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]]),
            // m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz, a, mud, alpha
            ModelKind::CrossCoupled => (
                Some(CrossCoupling {
                    cxz: v[2],
                    czx: v[3],
                    kxz: v[6],
                    kzx: v[7],
                }),
                [v[0], v[1], v[5], v[4], v[8], v[9], v[10], v[11]],
            ),
        };
        let [m, cx, kx, cz, kz, a, mud, alpha] = v;
        let params = RotorParams {
            coupling,
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
    let (names, matrix) = covariance_arrays(file, c)?;
    ParameterCovariance::new(names, matrix).map_err(|e| anyhow!("{file}: field `covariance`: {e}"))
}

/// The `names` and `matrix` of a summary's `covariance` object (a JSON `null` entry:
/// infinite), checked for types only; shared with the finite-element summary
/// ([`super::fe_summary`]).
pub(crate) fn covariance_arrays(
    file: &str,
    c: &serde_json::Map<String, Value>,
) -> anyhow::Result<(Vec<String>, Vec<Vec<f64>>)> {
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
    Ok((names, matrix))
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

    #[test]
    fn reads_a_cross_coupled_rotor_by_its_model_names() {
        let text = r#"{"model": "cross_coupled",
            "rotor": {"m": 14.29, "cxx": 200, "cxz": 20, "czx": -5, "czz": 180, "kxx": 1.195e6,
                      "kxz": -3e4, "kzx": 4e4, "kzz": 1.4e6, "a": 2.871, "mud": 1.5e-5, "alpha": 0.5},
            "covariance": {"names": ["m", "kxx", "kxz", "kzx"],
                           "matrix": [[1e-6, 0, 0, 0], [0, 4e4, 0, 0], [0, 0, 9e4, 0], [0, 0, 0, 1.6e5]]}}"#;
        let r = IdentifiedRotor::parse("c.json", text).unwrap();
        let p = r.params;
        assert_eq!(
            (p.m, p.cx, p.cz, p.kx, p.kz),
            (14.29, 200.0, 180.0, 1.195e6, 1.4e6)
        );
        assert_eq!(
            p.coupling,
            Some(CrossCoupling {
                cxz: 20.0,
                czx: -5.0,
                kxz: -3e4,
                kzx: 4e4
            })
        );
        let c = r.covariance.unwrap();
        use rotorid::analysis::CovarianceParameter as P;
        assert_eq!(c.std(P::Kx), Some(200.0));
        assert_eq!(c.std(P::Kzx), Some(400.0));
        let e = IdentifiedRotor::parse("c.json", &text.replace(r#""kzx": 4e4,"#, "")).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("c.json: missing field `rotor.kzx` (N/m; the cross-coupled model's rotor has m, cxx"),
            "{e}"
        );
        let e = IdentifiedRotor::parse("c.json", &text.replace("cross_coupled", "jeffcot"))
            .unwrap_err();
        assert!(e.to_string().contains("field `model` must be"), "{e}");
    }
}
