//! Finite-element rotors (issue 27) as Python loads them: the scenario TOML with `model =
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
