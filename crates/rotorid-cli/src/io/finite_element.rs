//! Finite-element rotors: the scenario's `[rotor]` with `model =
//! "finite_element"` ([`rotorid::scenario_file::FiniteElementSpec`]) joined with its
//! matrices file (`rotorid_io::fe_matrices`), whose path is relative to the scenario file.
//! Every message names the file at fault: the scenario (file and line), or the matrices
//! file (and its member).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _};
use rotorid::model::finite_element::{FeMatrices, FiniteElementRotor};
use rotorid::scenario_file::ScenarioSpec;

use super::scenario::LoadScenario as _;

/// The path of the matrices file `rel` (as written in `[rotor]`) of the scenario file
/// `origin`: relative to the scenario file's directory, as written when absolute.
pub fn matrices_path(origin: &str, rel: &str) -> PathBuf {
    let base = Path::new(origin).parent().unwrap_or(Path::new("."));
    base.join(rel)
}

/// The finite-element rotor of the scenario `spec` (parsed from a file): its matrices file
/// read and checked, its bearings and unbalances placed on it.
pub fn finite_element_of(spec: &ScenarioSpec) -> anyhow::Result<FiniteElementRotor> {
    let Some(fe) = spec.finite_element() else {
        bail!(
            "{}: rotor.model is \"{}\": a finite-element rotor needs rotor.model = \
             \"finite_element\" with rotor.matrices",
            spec.origin(),
            spec.model().name()
        );
    };
    let path = matrices_path(spec.origin(), &fe.matrices);
    let file = path.display().to_string();
    let at = match fe.matrices_line() {
        Some(l) => format!("{}:{l}", spec.origin()),
        None => spec.origin().to_owned(),
    };
    let read = rotorid_io::fe_matrices::read_file(&file, &path).with_context(|| {
        format!(
            "the matrices file of {at} (rotor.matrices = {:?})",
            fe.matrices
        )
    })?;
    let matrices = FeMatrices::from_row_major(
        &read.dofs,
        &read.m,
        &read.k,
        &read.g,
        read.c.as_deref(),
        read.ka.as_deref(),
    )
    .map_err(|e| anyhow!("{file}: {e}"))?;
    Ok(fe.rotor(Arc::new(matrices), &file)?)
}

/// The `[acquisition]` of the finite-element scenario `spec` (two probes per measured
/// node), each probe's node checked against `rotor`'s matrices (the file named in the
/// message); `None` when the scenario has no `[acquisition]`.
pub fn fe_acquisition_of<'a>(
    spec: &'a ScenarioSpec,
    rotor: &FiniteElementRotor,
) -> anyhow::Result<Option<&'a rotorid::acquisition::FeAcquisition>> {
    let (Some(acq), Some(fe)) = (spec.fe_acquisition(), spec.finite_element()) else {
        return Ok(None);
    };
    let file = matrices_path(spec.origin(), &fe.matrices)
        .display()
        .to_string();
    Ok(Some(acq.checked(&rotor.matrices, &file)?))
}

/// The finite-element rotor of the scenario file at `toml_path` ([`finite_element_of`]).
pub fn load_finite_element(toml_path: &str) -> anyhow::Result<FiniteElementRotor> {
    finite_element_of(&ScenarioSpec::load(toml_path)?)
}

#[cfg(test)]
mod tests {
    use rotorid_io::FeMatricesFile;

    use super::*;

    /// A two-node rotor (x, y, rx, ry at nodes 0 and 1): a diagonal, positive definite M.
    fn matrices(dofs: &[&str]) -> FeMatricesFile {
        let n = dofs.len();
        let diag = |v: f64| {
            (0..n * n)
                .map(|i| if i % (n + 1) == 0 { v } else { 0.0 })
                .collect::<Vec<_>>()
        };
        FeMatricesFile {
            file: String::new(),
            dofs: dofs.iter().map(|s| s.to_string()).collect(),
            m: diag(2.0),
            k: diag(1e6),
            g: vec![0.0; n * n],
            c: None,
            ka: Some(diag(1e-3)),
        }
    }

    const DOFS: [&str; 8] = ["0.x", "0.y", "0.rx", "0.ry", "1.x", "1.y", "1.rx", "1.ry"];

    const SCENARIO: &str = "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m/rotor.npz\"\n\
        [[rotor.bearing]]\nnode = 0\nkxx = 1.0e6\nkyy = 1.2e6\ncxx = 300.0\ncyy = 300.0\n\
        [[rotor.unbalance]]\nnode = 1\nm_u = 1.0e-4\nd = 0.1\nalpha_deg = 30.0\n";

    fn setup(dofs: &[&str], scenario: &str) -> (tempfile::TempDir, String) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("m")).unwrap();
        rotorid_io::fe_matrices::write(dir.path().join("m/rotor.npz"), &matrices(dofs)).unwrap();
        let toml = dir.path().join("fe.toml");
        std::fs::write(&toml, scenario).unwrap();
        let t = toml.display().to_string();
        (dir, t)
    }

    #[test]
    fn the_matrices_file_is_found_beside_the_scenario_and_joined() {
        let (_dir, toml) = setup(&DOFS, SCENARIO);
        let r = load_finite_element(&toml).unwrap();
        assert_eq!(r.matrices.n(), 8);
        assert_eq!(r.matrices.m()[(4, 4)], 2.0);
        assert_eq!(r.matrices.ka().unwrap()[(7, 7)], 1e-3);
        assert!(r.matrices.c().is_none());
        assert_eq!(r.bearings[0].kyy, 1.2e6);
        assert_eq!(r.unbalances[0].node, 1);
        assert!((r.unbalances[0].alpha - 30f64.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn each_fault_is_named_with_its_file() {
        // a bad dof name: the matrices file and the name
        let (_d, toml) = setup(
            &["0.x", "0.y", "0.rx", "0.ry", "1.x", "1.y", "1.rz", "1.ry"],
            SCENARIO,
        );
        let e = format!("{:#}", load_finite_element(&toml).unwrap_err());
        assert!(e.contains("m/rotor.npz: degree of freedom \"1.rz\""), "{e}");
        // an unbalance at a node without y
        let (_d, toml) = setup(&["0.x", "0.y", "1.x"], SCENARIO);
        let e = format!("{:#}", load_finite_element(&toml).unwrap_err());
        assert!(
            e.contains("fe.toml:11: rotor.unbalance[0].node = 1: the matrices file")
                && e.contains("has no degree of freedom 1.y"),
            "{e}"
        );
        // no matrices file: the scenario's line and the path tried
        let (_d, toml) = setup(&DOFS, &SCENARIO.replace("m/rotor.npz", "none.npz"));
        let e = format!("{:#}", load_finite_element(&toml).unwrap_err());
        assert!(
            e.contains("the matrices file of")
                && e.contains("fe.toml:3 (rotor.matrices = \"none.npz\")")
                && e.contains("none.npz:"),
            "{e}"
        );
        // a lumped scenario
        let (_d, toml) = setup(
            &DOFS,
            "[rotor]\nm = 14.29\na = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 0.0\n",
        );
        let e = format!("{:#}", load_finite_element(&toml).unwrap_err());
        assert!(e.contains("rotor.model is \"jeffcott\""), "{e}");
    }
}
