//! Finite-element rotors as Python loads them: the scenario TOML with `model =
//! "finite_element"` joined with its matrices file (NPZ, relative to the scenario), every
//! check the library's and `rotorid_io`'s, as the `rotorid` command makes them
//! (crates/rotorid-cli/src/io/finite_element.rs).

use std::path::Path;
use std::sync::Arc;

use rotorid::model::finite_element::{FeMatrices, FiniteElementRotor};
use rotorid_io::FeMatricesFile;

use crate::error::Error;
use crate::scenario::Scenario;

/// The matrices file at `path` as stored (row-major matrices, dofs as written).
pub fn read_matrices(path: &str) -> Result<FeMatricesFile, Error> {
    Ok(rotorid_io::fe_matrices::read_file(path, Path::new(path))?)
}

/// The finite-element rotor of the scenario file at `toml_path`, and the path of its
/// matrices file (relative to the scenario's directory).
pub fn load(toml_path: &str) -> Result<(FiniteElementRotor, String), Error> {
    let sc = Scenario::from_toml_file(toml_path)?;
    let spec = sc.spec();
    let Some(fe) = spec.finite_element() else {
        return Err(Error::invalid(format!(
            "{toml_path}: rotor.model is \"{}\": a finite-element rotor needs rotor.model = \
             \"finite_element\" with rotor.matrices",
            spec.model().name()
        )));
    };
    let base = Path::new(toml_path).parent().unwrap_or(Path::new("."));
    let path = base.join(&fe.matrices).display().to_string();
    let read = read_matrices(&path)?;
    let matrices = FeMatrices::from_row_major(
        &read.dofs,
        &read.m,
        &read.k,
        &read.g,
        read.c.as_deref(),
        read.ka.as_deref(),
    )
    .map_err(|e| Error::invalid(format!("{path}: {e}")))?;
    let rotor = fe.rotor(Arc::new(matrices), &path)?;
    Ok((rotor, path))
}

/// Identify the bearings and unbalances of the finite-element rotor of the scenario at
/// `toml_path` (its values of the unknowns are the start) from the record `t` \[s\] and
/// `channels` (`<node>.<dof>`, SI), as `rotorid identify --method refine` does: the
/// summary as JSON (docs/summary.md, "Finite-element rotors"). `unknowns` as
/// `--unknowns` (None: the default), `initial` `rest` or `estimated` (None: estimated),
/// `modes` (None: 6, at most the degrees of freedom).
pub fn identify(
    t: Vec<f64>,
    channels: Vec<(String, Vec<f64>)>,
    toml_path: &str,
    unknowns: Option<&str>,
    initial: Option<&str>,
    modes: Option<usize>,
    offsets: bool,
) -> Result<String, Error> {
    use rotorid::model::finite_element::{Dof, FeParameter};
    use rotorid::refine::finite_element::{
        refine_fe, FeData, FeInitial, FeRefineOptions, FeSummary,
    };
    use rotorid::scenario_file::SimulationOverrides;
    use rotorid::simulate::finite_element::FeResponse;

    let (start, _) = load(toml_path)?;
    let sc = Scenario::from_toml_file(toml_path)?;
    let (speed, _) = sc.spec().fe_simulation(&SimulationOverrides {
        dt: Some(1.0),
        duration: Some(1.0),
        ..SimulationOverrides::default()
    })?;
    let mut options = FeRefineOptions::new(&start);
    if let Some(u) = unknowns {
        options.unknowns = FeParameter::parse_list(u, &start)
            .map_err(|e| Error::invalid(format!("unknowns: {e}")))?;
    }
    if let Some(i) = initial {
        options.initial = i
            .parse::<FeInitial>()
            .map_err(|e| Error::invalid(format!("initial: {e}")))?;
    }
    if let Some(m) = modes {
        let n = start.matrices.n();
        if m == 0 || m > n {
            return Err(Error::invalid(format!(
                "modes = {m} is out of range: 1 ..= {n} (the degrees of freedom of the matrices)"
            )));
        }
        options.modes = m;
    }
    options.offsets = offsets;
    let mut dofs = Vec::with_capacity(channels.len());
    let mut q = Vec::with_capacity(channels.len());
    for (name, col) in channels {
        let dof: Dof = name.parse().map_err(|e| {
            Error::invalid(format!(
                "column {name:?}: {e} (columns are t and `<node>.<dof>`, dof one of x, y, rx, ry)"
            ))
        })?;
        if col.len() != t.len() {
            return Err(Error::invalid(format!(
                "column {name} has {} samples, t has {}",
                col.len(),
                t.len()
            )));
        }
        dofs.push(dof);
        q.push(col);
    }
    let n = t.len();
    let speed_at: Vec<_> = t.iter().map(|&ti| speed.at(ti - t[0])).collect();
    let data = FeResponse {
        dofs,
        q,
        phi: speed_at.iter().map(|s| s.phi).collect(),
        phi_dot: speed_at.iter().map(|s| s.omega).collect(),
        phi_ddot: speed_at.iter().map(|s| s.omega_dot).collect(),
        t,
    };
    let fe = FeData {
        response: &data,
        speed,
    };
    let dt = fe.checked_dt().map_err(|e| Error::invalid(e.to_string()))?;
    let fit = refine_fe(&fe, &start, &options).map_err(|e| Error::invalid(e.to_string()))?;
    let mut summary = FeSummary::new(&fit, (data.t[0], data.t[n - 1]), dt, &|_| None);
    summary.scenario = Some(toml_path.to_owned());
    serde_json::to_string(&summary).map_err(|e| Error::invalid(e.to_string()))
}
