//! Helpers shared by the end-to-end tests in `tests/it/`: the `rotorid` command, the
//! path of a file in `tests/data`, a `simulate` run to a CSV string and an `identify` run
//! that also reads back its summary JSON.

use assert_cmd::Command;
use serde_json::Value;

/// The `rotorid` binary of this build.
pub fn rotorid() -> Command {
    Command::cargo_bin("rotorid").expect("the rotorid binary is built")
}

/// Path of `tests/data/NAME`.
pub fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// `simulate ARGS --out -`: the response CSV.
pub fn simulate(args: &[&str]) -> String {
    let out = rotorid()
        .arg("simulate")
        .args(args)
        .args(["--out", "-", "-q"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The result of one `identify` run.
pub struct Run {
    pub ok: bool,
    pub csv: String,
    pub stderr: String,
    pub summary: Option<Value>,
}

/// `identify - OPTIONS --summary S ARGS` on `input`, S a temporary file read back as JSON
/// (`None` if the run wrote none). Panics if the binary panicked.
pub fn identify_with_summary(input: &str, options: &[&str], args: &[&str]) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.json");
    let out = rotorid()
        .args(["identify", "-"])
        .args(options)
        .args(["--summary", path.to_str().unwrap()])
        .args(args)
        .write_stdin(input.to_owned())
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    Run {
        ok: out.status.success(),
        csv: String::from_utf8(out.stdout).unwrap(),
        stderr,
        summary: std::fs::read_to_string(&path)
            .ok()
            .map(|t| serde_json::from_str(&t).unwrap()),
    }
}

/// The entry of parameter `name` (`m`, `m_x`, `cx`, ...) in a summary's `parameters`, or
/// JSON null.
pub fn param<'a>(summary: &'a Value, name: &str) -> &'a Value {
    summary["parameters"]
        .as_array()
        .and_then(|a| a.iter().find(|p| p["parameter"] == name))
        .unwrap_or(&Value::Null)
}

/// The entry of initial-state component `name` (x0, z0, vx0, vz0) of a refine summary.
pub fn state<'a>(summary: &'a Value, name: &str) -> &'a Value {
    summary["refine"]["initial_state"]
        .as_array()
        .and_then(|a| a.iter().find(|p| p["name"] == name))
        .unwrap_or(&Value::Null)
}

/// The first four columns of every data row of CSV `text` (after its header), as numbers.
pub fn first_four_columns(text: &str) -> Vec<[f64; 4]> {
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').take(4).map(|f| f.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// `identify REC --scenario SCENARIO --method METHOD ARGS` into `dir`: the estimates CSV's
/// bytes and the summary with its "input" (the file's name) nulled, to compare the outputs
/// of one record in two files.
pub fn identify_outputs(
    dir: &std::path::Path,
    rec: &str,
    scenario: &str,
    method: &str,
    args: &[&str],
) -> (Vec<u8>, Value) {
    let (est, sum) = (dir.join("est.csv"), dir.join("s.json"));
    let out = rotorid()
        .args([
            "identify",
            rec,
            "--scenario",
            scenario,
            "--method",
            method,
            "-q",
        ])
        .args([
            "--out",
            est.to_str().unwrap(),
            "--summary",
            sum.to_str().unwrap(),
        ])
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "identify {rec} --method {method}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    s["input"] = Value::Null;
    (std::fs::read(&est).unwrap(), s)
}
