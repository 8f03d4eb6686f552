//! Units in the response CSV's header (`x [um]`, `phi_dot [rpm]`, ...): a file in other
//! units identifies as the same record in SI, each converted column is named on stderr,
//! and a unit the column's role cannot take is refused with the file, line, column and
//! the units accepted.

use std::f64::consts::PI;
use std::sync::OnceLock;

use crate::common::{identify_with_summary, rotorid, simulate};

/// table1 at 10 kHz for 0.3 s, with phi columns, in SI.
fn si_csv() -> &'static str {
    static CSV: OnceLock<String> = OnceLock::new();
    CSV.get_or_init(|| {
        simulate(&[
            "--scenario",
            "table1",
            "--duration",
            "0.3",
            "--snr-db",
            "60",
            "--seed",
            "1",
        ])
    })
}

/// `si_csv()` with a new header and every column `i` multiplied by `factors[i]` (the
/// product printed in shortest round-trip form, so it reads back as written).
fn rescaled(header: &str, factors: [f64; 6]) -> String {
    let mut out = format!("{header}\n");
    for line in si_csv().lines().skip(1) {
        let fields: Vec<String> = line
            .split(',')
            .zip(factors)
            .map(|(f, k)| {
                let v: f64 = f.parse().unwrap();
                if k == 1.0 {
                    f.to_owned()
                } else {
                    format!("{:e}", v * k)
                }
            })
            .collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The identified values of a run by `method` (parameter name, value), with its stderr.
fn values(csv: &str, method: &str) -> (Vec<(String, f64)>, String) {
    let run = identify_with_summary(
        csv,
        &["--scenario", "table1", "--out", "/dev/null"],
        &["--method", method, "-q"],
    );
    assert!(run.ok, "{}", run.stderr);
    let s = run.summary.expect("a summary");
    let v: Vec<(String, f64)> = s["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let name = p["parameter"].as_str().unwrap().to_owned();
            let v = p["value"]
                .as_f64()
                .unwrap_or_else(|| panic!("{method}: {name} withheld: {p}"));
            (name, v)
        })
        .collect();
    assert!(v.len() >= 5, "{method}: {v:?}");
    (v, run.stderr)
}

fn assert_close(a: &[(String, f64)], b: &[(String, f64)], rel: f64, what: &str) {
    assert_eq!(a.len(), b.len());
    for ((name, x), (other, y)) in a.iter().zip(b) {
        assert_eq!(name, other);
        assert!(
            (x - y).abs() <= rel * y.abs(),
            "{what}: {name} = {x:e} against {y:e} (relative {:e})",
            (x - y) / y
        );
    }
}

/// `csv` with each column `i` divided by `divisors[i]` (the definition of a decimal
/// prefix), header `t,x,z,phi,phi_dot,phi_ddot`: what the reader must make of it.
fn divided(csv: &str, divisors: [f64; 6]) -> String {
    let mut out = String::from("t,x,z,phi,phi_dot,phi_ddot\n");
    for line in csv.lines().skip(1) {
        let fields: Vec<String> = line
            .split(',')
            .zip(divisors)
            .map(|(f, d)| format!("{:e}", f.parse::<f64>().unwrap() / d))
            .collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

#[test]
fn micrometres_identify_as_metres() {
    let um = rescaled(
        "t,x [um],z [um],phi,phi_dot,phi_ddot",
        [1.0, 1e6, 1e6, 1.0, 1.0, 1.0],
    );
    // the same numbers, divided by 1e6 here and written in SI
    let si = divided(&um, [1.0, 1e6, 1e6, 1.0, 1.0, 1.0]);
    for method in ["algebraic", "modulating", "refine"] {
        let (reference, err) = values(si_csv(), method);
        assert!(!err.contains("note:"), "SI needs no note: {err}");
        let (got, err) = values(&um, method);
        assert_eq!(
            got,
            values(&si, method).0,
            "{method}: um file against its SI values"
        );
        assert_close(&got, &reference, 1e-12, method);
        assert!(
            err.contains("note: <stdin>: x in um, converted to m (x 1e-6)\n")
                && err.contains("note: <stdin>: z in um, converted to m (x 1e-6)\n"),
            "{err}"
        );
    }
}

#[test]
fn rpm_and_degrees_identify_as_radians() {
    let (deg, rpm) = (180.0 / PI, 30.0 / PI);
    let csv = rescaled(
        "t (ms),x,z,phi [deg],phi_dot [rpm],phi_ddot [rpm/s]",
        [1e3, 1.0, 1.0, deg, rpm, rpm],
    );
    for method in ["algebraic", "refine"] {
        let (reference, _) = values(si_csv(), method);
        let (got, err) = values(&csv, method);
        // 180/pi (writing) and pi/180 (reading) are not exact inverses in f64: phi, up to
        // 37 rad here, comes back a few ulps off, and so do the stamps through ms; c, the
        // least determined parameter, moves by a few 1e-12 (its standard error is ~1e-3)
        assert_close(&got, &reference, 1e-11, method);
        for note in [
            "t in ms, converted to s (x 0.001)",
            "phi in deg, converted to rad (x 0.017453292519943295)",
            "phi_dot in rpm, converted to rad/s (x 0.10471975511965977)",
            "phi_ddot in rpm/s, converted to rad/s^2 (x 0.10471975511965977)",
        ] {
            assert!(err.contains(&format!("note: <stdin>: {note}\n")), "{err}");
        }
    }
}

#[test]
fn speed_in_rpm_is_read_as_rpm_and_caught_without_its_unit() {
    // without the suffix, rpm values are taken for rad/s and the speed columns disagree:
    // the unit is what makes the file usable
    let csv = rescaled(
        "t,x,z,phi,phi_dot [rpm],phi_ddot [rpm/s]",
        [1.0, 1.0, 1.0, 1.0, 30.0 / PI, 30.0 / PI],
    );
    let (reference, _) = values(si_csv(), "refine");
    let (got, _) = values(&csv, "refine");
    assert_close(&got, &reference, 1e-12, "refine");
    let unmarked = csv.replacen("phi_dot [rpm],phi_ddot [rpm/s]", "phi_dot,phi_ddot", 1);
    let run = identify_with_summary(
        &unmarked,
        &["--scenario", "table1", "--out", "/dev/null"],
        &["--method", "refine", "-q"],
    );
    assert!(
        !run.ok || run.stderr.contains("phi_dot"),
        "rpm taken for rad/s went unnoticed: {}",
        run.stderr
    );
}

#[test]
fn unknown_and_wrong_units_are_refused_with_what_is_accepted() {
    let cases = [
        (
            "t,x [furlong],z\n0,0,0\n",
            "Error: <stdin> line 1, column 2 (x): unknown unit \"furlong\" for a displacement: \
             use one of m, mm, um (µm), nm, mil, in\n",
        ),
        (
            "t,x,z,phi,phi_dot [deg],phi_ddot\n0,0,0,0,0,0\n",
            "Error: <stdin> line 1, column 5 (phi_dot): unit \"deg\" is an angle unit, but this \
             channel holds an angular speed: use one of rad/s, rpm, Hz (rev/s), deg/s\n",
        ),
        (
            "t [h],x,z\n0,0,0\n",
            "Error: <stdin> line 1, column 1 (t): unknown unit \"h\" for a time: use one of s, \
             ms, us\n",
        ),
    ];
    for (csv, message) in cases {
        let out = rotorid()
            .args(["identify", "-", "--scenario", "table1", "--out", "-"])
            .write_stdin(csv)
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert_eq!(String::from_utf8(out.stderr).unwrap(), message);
        assert!(out.stdout.is_empty());
    }
    // an extra column's unit is not looked at
    let out = rotorid()
        .args([
            "identify",
            "-",
            "--scenario",
            "table1",
            "--out",
            "/dev/null",
            "-q",
        ])
        .write_stdin(format!(
            "{},temperature [degC]\n{}",
            si_csv().lines().next().unwrap(),
            si_csv()
                .lines()
                .skip(1)
                .map(|l| format!("{l},21.5\n"))
                .collect::<String>()
        ))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn plot_names_the_conversions_too() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("um.csv");
    std::fs::write(
        &csv,
        rescaled(
            "t,x [um],z [mm],phi,phi_dot,phi_ddot",
            [1.0, 1e6, 1e3, 1.0, 1.0, 1.0],
        ),
    )
    .unwrap();
    let out = rotorid()
        .arg("plot")
        .arg(&csv)
        .arg("--out")
        .arg(dir.path().join("p.svg"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let name = csv.to_str().unwrap();
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        format!(
            "note: {name}: x in um, converted to m (x 1e-6)\n\
             note: {name}: z in mm, converted to m (x 0.001)\n"
        )
    );
}
