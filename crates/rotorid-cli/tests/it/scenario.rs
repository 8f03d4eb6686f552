//! End-to-end tests of scenario files: the shipped examples work, and every kind of
//! mistake (unknown key, missing key, wrong type, out-of-range value, bad TOML) is refused
//! with a message naming the file, the line and the key, with a non-zero exit and no panic.

use crate::common::{data, rotorid};

fn simulate(scenario: &str, extra: &[&str]) -> std::process::Output {
    rotorid()
        .args(["simulate", "--scenario", scenario, "--out", "-"])
        .args(extra)
        .output()
        .unwrap()
}

/// Write `text` as a scenario file, run simulate on it, and return stderr of the failure.
fn refused(text: &str) -> (String, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let p = path.to_str().unwrap().to_owned();
    let out = simulate(&p, &[]);
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success(), "accepted:\n{text}");
    assert_eq!(out.status.code(), Some(1));
    assert!(!err.contains("panicked"), "{err}");
    assert!(out.stdout.is_empty(), "wrote output for a bad scenario");
    (p, err)
}

fn table1_text() -> String {
    std::fs::read_to_string(data("table1.toml")).unwrap()
}

#[test]
fn the_table1_file_is_the_builtin() {
    let a = simulate("table1", &["--duration", "0.05"]);
    let b = simulate(&data("table1.toml"), &["--duration", "0.05"]);
    assert!(a.status.success() && b.status.success());
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn the_ramp_example_simulates_and_identifies() {
    let sim = simulate(&data("table1_ramp.toml"), &[]);
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    let text = String::from_utf8(sim.stdout.clone()).unwrap();
    assert_eq!(text.lines().count(), 1 + 3001);
    let row1: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|f| f.parse().unwrap())
        .collect();
    assert_eq!(row1[1], 2e-7, "initial x from [initial]");
    assert_eq!(row1[3], 30f64.to_radians(), "phi(0) from phi0_deg");
    assert_eq!(row1[5], 10.0, "w' from accel");
    let dir = tempfile::tempdir().unwrap();
    let summary = dir.path().join("s.json");
    let out = rotorid()
        .args([
            "identify",
            "-",
            "--scenario",
            &data("table1_ramp.toml"),
            "--out",
            "/dev/null",
            "-q",
        ])
        .args(["--summary", summary.to_str().unwrap()])
        .write_stdin(sim.stdout)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    for p in ["m_x", "kx", "m_z", "kz"] {
        let e = crate::common::param(&s, p)["relative_error"]
            .as_f64()
            .unwrap();
        assert!(
            e.abs() < 1e-6,
            "{p}: {e:e} (non-zero initial state must not matter)"
        );
    }
}

#[test]
fn unknown_key() {
    let (p, e) = refused(&table1_text().replace("kx = 1.195e6", "kxx = 1.195e6"));
    assert!(e.contains(&format!("{p}:7: unknown key rotor.kxx; allowed keys in [rotor]: m, cx, cz, kx, kz, a, m_u, d, alpha_deg")), "{e}");
    let (p, e) = refused(&(table1_text() + "\n[bearing]\nk = 1\n"));
    assert!(
        e.contains(&format!("{p}:28: unknown section or key `bearing`")),
        "{e}"
    );
}

#[test]
fn missing_key_and_section() {
    let (p, e) = refused(&table1_text().replace("kz = 1.195e6     # N/m\n", ""));
    assert!(
        e.contains(&format!(
            "{p}: missing key rotor.kz (N/m) (section [rotor] at line 3); simulate needs it"
        )),
        "{e}"
    );
    let text = table1_text();
    let no_speed = text[..text.find("[speed]").unwrap()].to_owned()
        + &text[text.find("[sampling]").unwrap()..];
    let (p, e) = refused(&no_speed);
    assert!(e.contains(&format!("{p}: missing section [speed]")), "{e}");
    let (p, e) = refused(&table1_text().replace("rpm = 1200.0     # rev/min\n", ""));
    assert!(
        e.contains(&format!(
            "{p}:14: missing key speed.rpm (rev/min) for kind = \"constant\""
        )),
        "{e}"
    );
}

#[test]
fn wrong_type() {
    let (p, e) = refused(&table1_text().replace("m = 14.29 ", "m = \"heavy\" "));
    assert!(
        e.contains(&format!(
            "{p}:4: rotor.m = \"heavy\" has the wrong type: must be a number (kg)"
        )),
        "{e}"
    );
    let (p, e) = refused(&table1_text().replace("kind = \"constant\"", "kind = 1"));
    assert!(
        e.contains(&format!("{p}:15: speed.kind = 1 has the wrong type")),
        "{e}"
    );
}

#[test]
fn out_of_range_value() {
    let (p, e) = refused(&table1_text().replace("kx = 1.195e6", "kx = -1.195e6"));
    assert!(
        e.contains(&format!(
            "{p}:7: rotor.kx = -1195000 is out of range: must be finite and > 0 (N/m)"
        )),
        "{e}"
    );
    let (p, e) = refused(&table1_text().replace("dt = 1.0e-4", "dt = 0.0"));
    assert!(
        e.contains(&format!(
            "{p}:19: sampling.dt = 0 is out of range: must be finite and > 0 (s)"
        )),
        "{e}"
    );
    let (p, e) = refused(&table1_text().replace("m_u = 1.0e-4", "m_u = nan"));
    assert!(
        e.contains(&format!(
            "{p}:10: rotor.m_u = NaN is out of range: must be finite and >= 0 (kg)"
        )),
        "{e}"
    );
    let (p, e) = refused(&table1_text().replace("rpm = 1200.0", "rpm = -5"));
    assert!(
        e.contains(&format!(
            "{p}:16: speed.rpm = -5 is out of range: must be finite and >= 0 (rev/min)"
        )),
        "{e}"
    );
}

#[test]
fn invalid_toml_names_the_line() {
    let (p, e) = refused(&table1_text().replace("cz = 10.0", "cz = = 10.0"));
    assert!(e.contains(&format!("{p}:6: invalid TOML")), "{e}");
}

#[test]
fn missing_file_is_a_clear_error() {
    let out = simulate("/nonexistent/s.toml", &[]);
    assert!(!out.status.success());
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(
        e.contains("cannot read scenario file /nonexistent/s.toml"),
        "{e}"
    );
}

#[test]
fn identify_accepts_a_scenario_with_only_the_known_quantities() {
    let out = rotorid()
        .args([
            "identify",
            "-",
            "--scenario",
            &data("known_only.toml"),
            "--out",
            "-",
            "-q",
        ])
        .write_stdin("t,x,z\n0,0,0\n0.1,1e-7,2e-7\n0.2,3e-7,1e-7\n0.3,2e-7,-1e-7\n")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // ... but simulate needs the whole rotor.
    let out = simulate(&data("known_only.toml"), &[]);
    assert!(!out.status.success());
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.contains("missing key rotor.m (kg)"), "{e}");
}

/// `simulate --scenario PATH` refused because PATH is over the 1 MiB cap: the message
/// names the file and the cap, and the run ends within seconds whatever PATH holds.
fn refused_as_too_large(path: &str) {
    let out = rotorid()
        .args(["simulate", "--scenario", path, "--out", "-"])
        .timeout(std::time::Duration::from_secs(300)) // against a hang, not a speed test
        .output()
        .unwrap();
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!(
            "cannot read scenario file {path}: larger than 1 MiB, the limit for scenario files"
        )),
        "{e}"
    );
}

#[test]
fn scenario_files_over_one_mib_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.toml");
    // Valid TOML (one long comment) of 2 MiB: refused for its size, not its content.
    let mut text = vec![b'#'; 2 << 20];
    text.push(b'\n');
    std::fs::write(&path, text).unwrap();
    refused_as_too_large(path.to_str().unwrap());
    // An endless device is read only up to the cap.
    refused_as_too_large("/dev/zero");
}

#[test]
fn an_endless_pipe_is_refused_after_one_mib() {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    let mut child = Command::new(env!("CARGO_BIN_EXE_rotorid"))
        .args(["simulate", "--scenario", "/dev/stdin", "--out", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // Writes comment lines until rotorid closes the pipe (then the write fails).
    let writer = std::thread::spawn(move || {
        let line = [b"#".repeat(1023), b"\n".to_vec()].concat();
        let mut written = 0usize;
        while stdin.write_all(&line).is_ok() {
            written += line.len();
        }
        written
    });
    let deadline = Instant::now() + Duration::from_secs(300); // against a hang
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            child.kill().unwrap();
            panic!("rotorid kept reading an endless scenario pipe");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let written = writer.join().unwrap();
    let mut e = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut e).unwrap();
    assert_eq!(status.code(), Some(1), "{e}");
    assert!(
        e.contains("cannot read scenario file /dev/stdin: larger than 1 MiB"),
        "{e}"
    );
    // The pipe holds at most a few buffers beyond what rotorid read.
    assert!(written < 4 << 20, "{written} bytes written");
}

/// A finite-element scenario beside numpy's matrices file (rotorid-io's fixture, written by
/// numpy.savez: dofs 0.x .. 0.ry, 3.x .. 3.ry).
fn finite_element_dir(bearing1_node: u32) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let npz = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../rotorid-io/fixtures/fe/savez.npz");
    std::fs::create_dir(dir.path().join("m")).unwrap();
    std::fs::copy(npz, dir.path().join("m/rotor.npz")).unwrap();
    let toml = dir.path().join("fe.toml");
    std::fs::write(
        &toml,
        format!(
            "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m/rotor.npz\"\n\
             [[rotor.bearing]]\nnode = 0\nkxx = 1.0e6\nkyy = 1.2e6\ncxx = 300.0\ncyy = 310.0\n\
             [[rotor.bearing]]\nnode = {bearing1_node}\nkxx = 2.0e6\nkxy = -3.0e4\nkyy = 2.5e6\n\
             [[rotor.unbalance]]\nnode = 3\nm_u = 1.0e-4\nd = 0.1\nalpha_deg = 45.0\n"
        ),
    )
    .unwrap();
    let p = toml.to_str().unwrap().to_owned();
    (dir, p)
}

#[test]
fn a_finite_element_scenario_loads_with_its_matrices_and_simulate_names_the_model() {
    let (_dir, toml) = finite_element_dir(3);
    let out = rotorid().args(["inspect", &toml]).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.starts_with(&format!(
            "{toml}: finite-element rotor, 8 degrees of freedom at 2 nodes (0 .. 3); C: given, Ka: given"
        )),
        "{text}"
    );
    let row = |name: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("no {name} in\n{text}"))
            .split_whitespace()
            .skip(1)
            .map(|v| v.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    assert_eq!(
        row("bearing0 "),
        [0.0, 1.0e6, 0.0, 0.0, 1.2e6, 300.0, 0.0, 0.0, 310.0]
    );
    assert_eq!(
        row("bearing1 "),
        [3.0, 2.0e6, -3.0e4, 0.0, 2.5e6, 0.0, 0.0, 0.0, 0.0]
    );
    let u = row("unbalance0 ");
    assert_eq!(u[0], 3.0);
    assert!(
        (u[1] - 1.0e-5).abs() < 1e-16 && (u[2] - 45.0).abs() < 1e-9,
        "{u:?}"
    );
    // simulate takes the rotor (tests/it/finite_element.rs) and names what it lacks here
    let out = simulate(&toml, &[]);
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success());
    assert!(
        err.contains(&format!("{toml}: missing section [speed]"))
            && err.contains("simulate needs it"),
        "{err}"
    );
}

#[test]
fn a_finite_element_scenario_on_a_node_without_dofs_is_refused_naming_both_files() {
    let (_dir, toml) = finite_element_dir(5);
    let out = rotorid().args(["inspect", &toml]).output().unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains(&format!(
            "{toml}:11: rotor.bearing[1].node = 5: the matrices file "
        )) && err.contains("m/rotor.npz has no degree of freedom 5.x in dofs"),
        "{err}"
    );
}
