//! Multi-plane balancing and trial planning (`rotorid.balance`, `rotorid.plan_trials`):
//! `vectors.csv` and `masses.csv` as text (the package writes a DataFrame with
//! `to_csv`, so a DataFrame and a file go through the one reader of `rotorid balance`,
//! with the same messages), the library's computation, and `balance.json` as text, the
//! same document `rotorid balance --out` writes.

use rotorid::analysis::balance::{
    balance, plan_from_influence, BalanceMethod, BalanceOptions, Holes, MassInput, MassSet,
    VectorInput,
};
use rotorid_io::csv::{read_masses, read_vectors, Phase};

use crate::error::Error;

/// The inputs of a call, as the keyword arguments give them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Request {
    /// `vectors.csv` text and the name messages give it.
    pub vectors: (String, String),
    /// `masses.csv` text and its name.
    pub masses: (String, String),
    /// The run to balance.
    pub current: String,
    /// `ls` or `minmax`.
    pub method: String,
    /// Speeds \[rev/min\].
    pub speeds: Option<Vec<f64>>,
    /// Planes to correct.
    pub planes: Option<Vec<String>>,
    /// Limits per sensor.
    pub limits: Vec<(String, f64)>,
    /// Weights per sensor.
    pub weights: Vec<(String, f64)>,
    /// Radius per plane \[m\].
    pub radius: Vec<(String, f64)>,
    /// Radius of every other plane \[m\].
    pub default_radius: Option<f64>,
    /// Equally spaced holes per plane: (count, offset \[deg\]).
    pub holes_equal: Vec<(String, (usize, f64))>,
    /// Hole angles per plane \[deg\].
    pub holes_angles: Vec<(String, Vec<f64>)>,
    /// Available weights \[kg\].
    pub mass_set: Option<Vec<f64>>,
    /// Most weights per hole.
    pub per_hole: usize,
    /// `lag` or `lead`, for amp,phase_deg vectors.
    pub phase: Option<String>,
    /// Unit of vectors without one.
    pub unit: Option<String>,
}

/// The vectors and masses of `r`, read as `rotorid balance` reads its files.
fn inputs(r: &Request) -> Result<(Vec<VectorInput>, Vec<MassInput>), Error> {
    let phase = match r.phase.as_deref() {
        None => None,
        Some("lag") => Some(Phase::Lag),
        Some("lead") => Some(Phase::Lead),
        Some(p) => {
            return Err(Error::invalid(format!(
                "phase={p:?}: expected \"lag\" or \"lead\""
            )))
        }
    };
    let vectors = read_vectors(
        &r.vectors.0,
        r.vectors.1.as_bytes(),
        phase,
        r.unit.as_deref(),
    )?
    .into_iter()
    .map(|v| VectorInput::new(&v.run, v.speed_rpm, &v.sensor, &v.unit, v.re, v.im, v.std))
    .collect();
    let masses = read_masses(&r.masses.0, r.masses.1.as_bytes())?
        .into_iter()
        .map(|m| MassInput {
            run: m.run,
            plane: m.plane,
            mass: m.mass_kg,
            radius: m.radius_m,
            angle: m.angle_deg.to_radians(),
        })
        .collect();
    Ok((vectors, masses))
}

/// The library's options of `r`.
fn options(r: &Request) -> Result<BalanceOptions, Error> {
    let method = match r.method.as_str() {
        "ls" | "least_squares" => BalanceMethod::LeastSquares,
        "minmax" | "min_max" => BalanceMethod::MinMax,
        m => {
            return Err(Error::invalid(format!(
                "method={m:?}: expected \"ls\" (least squares) or \"minmax\""
            )))
        }
    };
    let mut holes: Vec<(String, Holes)> = Vec::new();
    for (plane, (count, offset)) in &r.holes_equal {
        if *count < 2 {
            return Err(Error::invalid(format!(
                "holes[{plane:?}] = {count}: equally spaced holes must be at least 2 (give a list of angles)"
            )));
        }
        holes.push((
            plane.clone(),
            Holes::Equal {
                count: *count,
                offset: offset.to_radians(),
            },
        ));
    }
    for (plane, angles) in &r.holes_angles {
        holes.push((
            plane.clone(),
            Holes::Angles(angles.iter().map(|a| a.to_radians()).collect()),
        ));
    }
    Ok(BalanceOptions {
        current: r.current.clone(),
        speeds_rpm: r.speeds.clone(),
        planes: r.planes.clone(),
        method,
        weights: r.weights.clone(),
        limits: r.limits.clone(),
        radius: r.radius.clone(),
        default_radius: r.default_radius,
        holes,
        mass_set: r.mass_set.clone().map(|masses| MassSet {
            masses,
            per_hole: r.per_hole,
        }),
    })
}

fn json(value: &impl serde::Serialize) -> String {
    serde_json::to_string(value).expect("the report serialises")
}

/// `balance.json` of the balance `r` asks for.
pub fn balance_json(r: &Request) -> Result<String, Error> {
    let (vectors, masses) = inputs(r)?;
    let b = balance(&vectors, &masses, &options(r)?).map_err(|e| Error::invalid(e.to_string()))?;
    Ok(json(&b.report()))
}

/// `balance.json` of the trial plan `r` asks for, changing the response by `fraction`.
pub fn plan_json(r: &Request, fraction: f64) -> Result<String, Error> {
    let (vectors, masses) = inputs(r)?;
    let p = plan_from_influence(&vectors, &masses, &options(r)?, fraction)
        .map_err(|e| Error::invalid(e.to_string()))?;
    Ok(json(&p.report()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dataframe_and_the_command_read_alike_and_errors_name_the_frame() {
        let vectors = "run,speed_rpm,sensor,re,im,unit\n\
            a,1000,s1,10,0,um\nt,1000,s1,12,1,um\na,1000,s2,0,5,um\nt,1000,s2,1,7,um\n";
        let masses = "run,plane,mass_kg,radius_m,angle_deg\na,p,0,0.1,0\nt,p,0.001,0.1,90\n";
        let r = Request {
            vectors: ("vectors_df".into(), vectors.into()),
            masses: ("masses_df".into(), masses.into()),
            current: "a".into(),
            method: "ls".into(),
            per_hole: 1,
            ..Request::default()
        };
        let j: serde_json::Value = serde_json::from_str(&balance_json(&r).unwrap()).unwrap();
        assert_eq!(j["corrections"][0]["plane"], "p");
        let bad = Request {
            vectors: ("vectors_df".into(), vectors.replace("12,1", "12,x")),
            ..r.clone()
        };
        assert_eq!(
            balance_json(&bad).unwrap_err().to_string(),
            "vectors_df line 3, column 5 (im): im \"x\" is not a number: expected a number"
        );
        let bad = Request {
            method: "median".into(),
            ..r
        };
        assert!(balance_json(&bad)
            .unwrap_err()
            .to_string()
            .starts_with("method=\"median\""));
    }
}
