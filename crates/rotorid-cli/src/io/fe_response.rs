//! The response file of a finite-element rotor (docs/formats.md, "The response
//! file of a finite-element rotor"): one row per sample, the columns
//!
//! ```text
//! t            [s]        time, uniform (the same grid rule as the 2-DOF response)
//! <node>.<dof> [m, rad]   each measured degree of freedom, named as in the matrices' dofs
//! phi, phi_dot, phi_ddot  [rad, rad/s, rad/s^2], all three or none (then the scenario's [speed])
//! ```
//!
//! in any format `rotorid_io::read_table` reads (CSV, Parquet, NPZ, MAT, TDMS, UFF58, NPY):
//! what `rotorid simulate --scenario fe.toml --out f.csv|f.parquet|f.npz` writes reads back
//! bit for bit. The rules follow the 2-DOF response reader's (`rotorid_io::csv::response`):
//! a unit suffix converts a used column to SI (`0.x [um]`, `phi_dot [rpm]`), a column that
//! is neither `t`, a degree of freedom nor a speed column is ignored (as the 2-DOF reader
//! ignores extra columns) but said on stderr; a name of the form `<node>.<anything>` is
//! taken as a degree of freedom, so a misspelt or absent one (`6.z`, `9.x` on a rotor
//! without node 9) is an error listing the allowed ones rather than an ignored column.

use anyhow::{anyhow, bail, Context as _};
use rotorid::model::finite_element::{Dof, DofKind, FiniteElementRotor};
use rotorid::pipeline::{PipelineError, TimeGrid};
use rotorid::simulate::finite_element::FeResponse;
use rotorid::SpeedProfile;
use rotorid_io::units::{conversion, Quantity};
use rotorid_io::{Format, Table};

/// `r` as the table `rotorid simulate` writes (`file` names it): the channels `t`,
/// `<node>.<dof>` ..., `phi`, `phi_dot`, `phi_ddot`, each with its SI unit (s; m for x, y
/// and rad for rx, ry; rad, rad/s, rad/s^2).
pub fn fe_table(file: &str, r: FeResponse) -> Table {
    let header = r.header();
    let unit = |name: &str| match name {
        "t" => "s",
        "phi" => "rad",
        "phi_dot" => "rad/s",
        "phi_ddot" => "rad/s^2",
        _ if name.ends_with(".rx") || name.ends_with(".ry") => "rad",
        _ => "m",
    };
    let mut data = vec![r.t];
    data.extend(r.q);
    data.extend([r.phi, r.phi_dot, r.phi_ddot]);
    Table {
        file: file.to_owned(),
        notes: Vec::new(),
        channels: header
            .into_iter()
            .zip(data)
            .map(|(name, data)| rotorid_io::Channel {
                unit: Some(unit(&name).to_owned()),
                name,
                data,
                axis: None,
            })
            .collect(),
    }
}

/// The speed columns, in the order of the file and of [`FeResponse`].
const SPEED: [(&str, Quantity); 3] = [
    ("phi", Quantity::Angle),
    ("phi_dot", Quantity::AngularSpeed),
    ("phi_ddot", Quantity::AngularAcceleration),
];

/// Read the response file `path` of the finite-element `rotor` (module doc): the measured
/// degrees of freedom in the file's column order, t, and phi, phi_dot, phi_ddot from the
/// file or, when it has none, from `speed` (the scenario's `[speed]`) at each t. Every
/// stamp within `time_tolerance` dt of the uniform grid fitted over them (as for the
/// 2-DOF response: `rotorid::pipeline::TimeGrid::fit`; the default is
/// `rotorid::pipeline::DEFAULT_TIME_TOLERANCE`). Notes (converted units, ignored columns)
/// go to stderr.
pub fn read_fe_response(
    path: &str,
    rotor: &FiniteElementRotor,
    speed: Option<&SpeedProfile>,
    time_tolerance: f64,
) -> anyhow::Result<FeResponse> {
    let table = super::tables::read(path)?;
    let csv = matches!(
        Format::from_path(std::path::Path::new(path)),
        Ok(Format::Csv)
    );
    fe_response_of(table, rotor, speed, time_tolerance, &|i| {
        if csv {
            csv_line(path, i)
        } else {
            None
        }
    })
}

/// The allowed degrees of freedom of `rotor`, for messages: `0.x, 0.y, 0.rx, ...`.
fn allowed(rotor: &FiniteElementRotor) -> String {
    let d: Vec<String> = rotor.matrices.dofs().iter().map(Dof::to_string).collect();
    d.join(", ")
}

/// True when `name` is meant as a degree of freedom: `<digits>.<anything>`.
fn looks_like_dof(name: &str) -> bool {
    name.split_once('.')
        .is_some_and(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// [`read_fe_response`] on a table already read; `line_of(i)` is the file's line of
/// sample i when the file has lines (a CSV).
fn fe_response_of(
    mut table: Table,
    rotor: &FiniteElementRotor,
    speed: Option<&SpeedProfile>,
    time_tolerance: f64,
    line_of: &dyn Fn(usize) -> Option<u64>,
) -> anyhow::Result<FeResponse> {
    let file = table.file.clone();
    let mut t_col = None;
    let mut speed_cols: [Option<usize>; 3] = [None; 3];
    let mut dofs: Vec<(Dof, usize)> = Vec::new();
    let mut ignored = Vec::new();
    for (i, c) in table.channels.iter().enumerate() {
        let name = c.name.as_str();
        let dup = |what: &str| anyhow!("{file}: column {name:?} appears twice ({what})");
        if name == "t" {
            if t_col.replace(i).is_some() {
                return Err(dup("the time"));
            }
        } else if let Some(k) = SPEED.iter().position(|(n, _)| *n == name) {
            if speed_cols[k].replace(i).is_some() {
                return Err(dup("a speed column"));
            }
        } else if looks_like_dof(name) {
            let dof = name
                .parse::<Dof>()
                .ok()
                .filter(|d| rotor.matrices.index(*d).is_some())
                .ok_or_else(|| {
                    anyhow!(
                        "{file}: column {name:?} is not a degree of freedom of the rotor's \
                         matrices: allowed {} (<node>.<dof>, dof one of x, y, rx, ry)",
                        allowed(rotor)
                    )
                })?;
            if dofs.iter().any(|(d, _)| *d == dof) {
                return Err(dup("a degree of freedom"));
            }
            dofs.push((dof, i));
        } else {
            ignored.push(name.to_owned());
        }
    }
    if dofs.is_empty() {
        bail!(
            "{file}: no column of a measured degree of freedom: name at least one as in the \
             matrices' dofs ({}); the file has: {}",
            allowed(rotor),
            table
                .channels
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let found: Vec<&str> = SPEED
        .iter()
        .zip(speed_cols)
        .filter(|(_, c)| c.is_some())
        .map(|((n, _), _)| *n)
        .collect();
    if !(found.is_empty() || found.len() == 3) {
        let missing: Vec<&str> = SPEED
            .iter()
            .zip(speed_cols)
            .filter(|(_, c)| c.is_none())
            .map(|((n, _), _)| *n)
            .collect();
        bail!(
            "{file}: has {} but not {}: give all of phi, phi_dot, phi_ddot or none (then the \
             scenario's speed profile is used)",
            found.join(", "),
            missing.join(", ")
        );
    }
    if !ignored.is_empty() {
        eprintln!(
            "note: {file}: column(s) {} ignored: neither t, a degree of freedom of the matrices \
             nor phi, phi_dot, phi_ddot",
            ignored.join(", ")
        );
    }
    // Each used column: its role's quantity, converted to SI, equal lengths, finite.
    let n = table.channels[dofs[0].1].data.len();
    let axis = table.channels[dofs[0].1].axis;
    let mut take = |i: usize, q: Quantity, role: &str| -> anyhow::Result<Vec<f64>> {
        let c = &mut table.channels[i];
        if c.data.len() != n {
            bail!(
                "{file}: column {:?} has {} samples but {:?} has {n}: every column must have \
                 one sample per instant",
                c.name,
                c.data.len(),
                dofs[0].0.to_string()
            );
        }
        let conv = conversion(q, c.unit.as_deref())
            .with_context(|| format!("{file}, column {:?} ({role})", c.name))?;
        if !conv.is_identity() {
            eprintln!(
                "note: {file}: {} ({role}) in {}, converted to {} (x {:e})",
                c.name,
                conv.unit,
                q.si(),
                conv.factor()
            );
        }
        let mut data = std::mem::take(&mut c.data);
        if let Some(k) = data.iter().position(|v| !v.is_finite()) {
            let at = match line_of(k) {
                Some(l) => format!("{file} line {l}, column {} ({})", i + 1, c.name),
                None => format!("{file}, column {:?}, sample {k}", c.name),
            };
            bail!(
                "{at}: {} = {} is not finite: every value must be a finite number",
                c.name,
                data[k]
            );
        }
        conv.apply_all(&mut data);
        Ok(data)
    };
    let t = match t_col {
        Some(i) => take(i, Quantity::Time, "time")?,
        None => match axis {
            Some(axis) => {
                eprintln!("note: {file}: time from the file's time axis (no column t)");
                axis.times(n)
            }
            None => bail!(
                "{file}: no time column t (and no time axis in the file): the response of a \
                     finite-element rotor has the columns t, <node>.<dof>..., and optionally \
                     phi, phi_dot, phi_ddot"
            ),
        },
    };
    let mut q = Vec::with_capacity(dofs.len());
    for &(d, i) in &dofs {
        let quantity = match d.kind {
            DofKind::X | DofKind::Y => Quantity::Displacement,
            DofKind::Rx | DofKind::Ry => Quantity::Angle,
        };
        q.push(take(i, quantity, "degree of freedom")?);
    }
    let [phi, phi_dot, phi_ddot] = match speed_cols {
        [Some(a), Some(b), Some(c)] => [
            take(a, SPEED[0].1, "phi")?,
            take(b, SPEED[1].1, "phi_dot")?,
            take(c, SPEED[2].1, "phi_ddot")?,
        ],
        _ => {
            let Some(profile) = speed else {
                bail!(
                    "{file}: no columns phi, phi_dot, phi_ddot and the scenario has no [speed]: \
                     give one or the other"
                );
            };
            let s: Vec<_> = t.iter().map(|&t| profile.at(t)).collect();
            [
                s.iter().map(|s| s.phi).collect(),
                s.iter().map(|s| s.omega).collect(),
                s.iter().map(|s| s.omega_dot).collect(),
            ]
        }
    };
    if let Err(e) = TimeGrid::fit(&t, time_tolerance) {
        let index = match &e {
            PipelineError::NonUniformSampling { index, .. }
            | PipelineError::NotIncreasing { index, .. } => Some(*index),
            _ => None,
        };
        return Err(match index.and_then(line_of) {
            Some(l) => anyhow!("{file} line {l}: {e}"),
            None => anyhow!("{file}: {e}"),
        });
    }
    Ok(FeResponse {
        dofs: dofs.into_iter().map(|(d, _)| d).collect(),
        t,
        q,
        phi,
        phi_dot,
        phi_ddot,
    })
}

/// The line of the CSV file `path` that holds sample `i` (the header is line 1; blank
/// lines count), found by reading it again: only on the way to an error message.
fn csv_line(path: &str, i: usize) -> Option<u64> {
    use rotorid_io::csv::columns::{csv_reader, next_record};
    let f = std::fs::File::open(path).ok()?;
    let mut csv = csv_reader(std::io::BufReader::new(f));
    next_record(path, &mut csv).ok()??;
    for _ in 0..i {
        next_record(path, &mut csv).ok()??;
    }
    let line = next_record(path, &mut csv).ok()??.line();
    Some(line)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::simulate::{run, MethodArg, SimulateArgs};
    use rotorid_io::FeMatricesFile;

    /// A two-node rotor (x, y at nodes 0 and 1, no rotations): 2 kg and 3 kg joined by a
    /// shaft spring, a gyroscopic coupling at node 1, a bearing at each node, an unbalance
    /// at node 1, at 3000 rpm for 0.05 s at 10 kHz.
    fn scenario(dir: &std::path::Path) -> String {
        let k = 2.0e6;
        let g = 0.01;
        #[rustfmt::skip]
        let kk = vec![
            k, 0.0, -k, 0.0,
            0.0, k, 0.0, -k,
            -k, 0.0, k, 0.0,
            0.0, -k, 0.0, k,
        ];
        #[rustfmt::skip]
        let gg = vec![
            0.0, 0.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0,
            0.0, 0.0, 0.0, g,
            0.0, 0.0, -g, 0.0,
        ];
        let mut m = vec![0.0; 16];
        for (i, v) in [2.0, 2.0, 3.0, 3.0].into_iter().enumerate() {
            m[i * 5] = v;
        }
        rotorid_io::fe_matrices::write(
            dir.join("m.npz"),
            &FeMatricesFile {
                file: String::new(),
                dofs: ["0.x", "0.y", "1.x", "1.y"].map(str::to_owned).to_vec(),
                m,
                k: kk,
                g: gg,
                c: None,
                ka: None,
            },
        )
        .unwrap();
        let toml = dir.join("fe.toml");
        std::fs::write(
            &toml,
            "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m.npz\"\n\
             [[rotor.bearing]]\nnode = 0\nkxx = 1.0e6\nkyy = 1.3e6\ncxx = 200.0\ncyy = 250.0\n\
             [[rotor.bearing]]\nnode = 1\nkxx = 1.5e6\nkyy = 1.1e6\nkxy = 2.0e4\ncxx = 300.0\ncyy = 300.0\n\
             [[rotor.unbalance]]\nnode = 1\nm_u = 1e-4\nd = 0.1\nalpha_deg = 30.0\n\
             [speed]\nkind = \"ramp\"\nrpm0 = 3000.0\naccel = 100.0\n\
             [sampling]\ndt = 1e-4\nduration = 0.05\n",
        )
        .unwrap();
        toml.display().to_string()
    }

    fn simulate_to(scenario: &str, out: &str, snr_db: Option<f64>) -> anyhow::Result<()> {
        run(SimulateArgs {
            scenario: scenario.to_owned(),
            method: MethodArg::Exact,
            duration: None,
            dt: None,
            snr_db,
            seed: None,
            initial_x: None,
            initial_z: None,
            initial_vx: None,
            initial_vz: None,
            out: out.to_owned(),
            raw: false,
            slow_roll_out: None,
            quiet: true,
        })
    }

    fn rotor(scenario: &str) -> FiniteElementRotor {
        crate::io::finite_element::load_finite_element(scenario).unwrap()
    }

    fn read(path: &std::path::Path, r: &FiniteElementRotor) -> anyhow::Result<FeResponse> {
        read_fe_response(
            path.to_str().unwrap(),
            r,
            None,
            rotorid::pipeline::DEFAULT_TIME_TOLERANCE,
        )
    }

    #[test]
    fn what_simulate_writes_reads_back_bit_for_bit_in_every_format() {
        let dir = tempfile::tempdir().unwrap();
        let toml = scenario(dir.path());
        let r = rotor(&toml);
        // the reference: the library's simulation, as simulate runs it (Magnus on a ramp)
        let spec = rotorid::scenario_file::ScenarioSpec::parse(
            &toml,
            &std::fs::read_to_string(&toml).unwrap(),
        )
        .unwrap();
        let (speed, sampling) = spec.fe_simulation(&Default::default()).unwrap();
        let want = rotorid::simulate::finite_element::simulate_fe(
            &rotorid::model::finite_element::FeSystem::full(&r),
            &speed,
            &sampling,
            None,
            None,
            rotorid::simulate::finite_element::FeMethod::Magnus,
        )
        .unwrap();
        assert_eq!(want.len(), 501);
        for ext in ["csv", "parquet", "npz"] {
            let path = dir.path().join(format!("r.{ext}"));
            simulate_to(&toml, path.to_str().unwrap(), None).unwrap();
            let got = read(&path, &r).unwrap();
            assert_eq!(got, want, "{ext}");
        }
        // with noise: the file is what the reader gives back, in every format alike
        let noisy: Vec<FeResponse> = ["csv", "parquet", "npz"]
            .iter()
            .map(|ext| {
                let path = dir.path().join(format!("n.{ext}"));
                simulate_to(&toml, path.to_str().unwrap(), Some(30.0)).unwrap();
                read(&path, &r).unwrap()
            })
            .collect();
        assert_ne!(noisy[0].q, want.q);
        assert_eq!(noisy[0], noisy[1]);
        assert_eq!(noisy[0], noisy[2]);
        // a MAT file cannot name a channel 0.x (a MATLAB identifier starts with a letter):
        // simulate refuses it by name rather than writing something the reader cannot map
        let e = simulate_to(&toml, dir.path().join("r.mat").to_str().unwrap(), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"0\" is not a MATLAB identifier"), "{e}");
    }

    /// The file `name` in `dir` holding `text`.
    fn file(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn columns_by_name_units_and_the_speed_profile() {
        let dir = tempfile::tempdir().unwrap();
        let r = rotor(&scenario(dir.path()));
        // any column order, a unit suffix, an ignored column, phi from the profile
        let p = file(
            dir.path(),
            "a.csv",
            "1.y [um],temp,t,0.x\n1.5,20,0,1e-6\n-2.5,20,0.001,2e-6\n3,21,0.002,3e-6\n",
        );
        let speed = rotorid::SpeedProfile::constant_rpm(600.0, 0.0).unwrap();
        let got = read_fe_response(p.to_str().unwrap(), &r, Some(&speed), 1e-6).unwrap();
        assert_eq!(
            got.dofs,
            vec!["1.y".parse().unwrap(), "0.x".parse().unwrap()]
        );
        assert_eq!(got.q[0], vec![1.5e-6, -2.5e-6, 3e-6]);
        assert_eq!(got.q[1], vec![1e-6, 2e-6, 3e-6]);
        assert_eq!(got.t, vec![0.0, 0.001, 0.002]);
        assert_eq!(got.phi_dot, vec![20.0 * std::f64::consts::PI; 3]);
        assert_eq!(got.phi[2], speed.at(0.002).phi);
        // without phi and without [speed]
        let e = read(&p, &r).unwrap_err().to_string();
        assert!(
            e.contains("no columns phi, phi_dot, phi_ddot and the scenario has no [speed]"),
            "{e}"
        );
    }

    #[test]
    fn each_fault_is_named_with_file_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let r = rotor(&scenario(dir.path()));
        let err = |name: &str, text: &str| {
            let p = file(dir.path(), name, text);
            format!("{:#}", read(&p, &r).unwrap_err())
        };
        // a degree of freedom the matrices do not have, and a misspelt one
        for (col, name) in [("2.x", "n.csv"), ("1.z", "z.csv"), ("0.rx", "r.csv")] {
            let e = err(
                name,
                &format!("t,0.x,{col},phi,phi_dot,phi_ddot\n0,1,2,0,1,0\n"),
            );
            assert!(
                e.contains(&format!(
                    "{name}: column \"{col}\" is not a degree of freedom"
                )) && e.contains("allowed 0.x, 0.y, 1.x, 1.y"),
                "{e}"
            );
        }
        // no degree of freedom at all
        let e = err("none.csv", "t,x,z,phi,phi_dot,phi_ddot\n0,1,2,0,1,0\n");
        assert!(
            e.contains("none.csv: no column of a measured degree of freedom"),
            "{e}"
        );
        // some of the speed columns
        let e = err("p.csv", "t,0.x,phi,phi_dot\n0,1,0,1\n");
        assert!(e.contains("has phi, phi_dot but not phi_ddot"), "{e}");
        // a non-finite value: its line (blank lines count) and column
        let e = err(
            "nan.csv",
            "t,0.x,0.y,phi,phi_dot,phi_ddot\n0,1,2,0,1,0\n\n1e-3,NaN,2,0,1,0\n",
        );
        assert!(
            e.contains("nan.csv line 4, column 2 (0.x): 0.x = NaN is not finite"),
            "{e}"
        );
        // non-uniform time: the 2-DOF reader's rule and words, with the line
        let e = err(
            "t.csv",
            "t,0.x,phi,phi_dot,phi_ddot\n0,1,0,1,0\n1,1,0,1,0\n2,1,0,1,0\n3,1,0,1,0\n4.00005,1,0,1,0\n5,1,0,1,0\n",
        );
        assert!(
            e.contains("t.csv line 6: sample 4: sampling is not uniform: t = 4.00005 s"),
            "{e}"
        );
        // a column twice
        let e = err("d.csv", "t,0.x,0.x,phi,phi_dot,phi_ddot\n0,1,1,0,1,0\n");
        assert!(e.contains("column \"0.x\" appears twice"), "{e}");
        // a unit of the wrong quantity
        let e = err("u.csv", "t,0.x [rpm],phi,phi_dot,phi_ddot\n0,1,0,1,0\n");
        assert!(
            e.contains("u.csv, column \"0.x\" (degree of freedom)"),
            "{e}"
        );
    }
}
