//! `rotorid publish`, `rotorid worker` and `rotorid fleet status` against a real
//! nats-server (JetStream, its own store and port; `.ci/test` installs the Debian package):
//! a recording published in windows is identified by a worker process, the status lists
//! every window with estimates that agree with the truth, the same estimates offline
//! `rotorid identify` gives on each window's samples with the same method settings, and
//! SIGTERM stops the worker cleanly; the settings are checked before connecting.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rotorid_fleet::test_server::Server;

use crate::common::rotorid;

fn run(args: &[&str]) -> String {
    let out = rotorid().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "rotorid {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The status's estimate lines of one machine: parameter -> (value, standard error).
fn estimates(status: &str) -> Vec<(String, f64, f64)> {
    status
        .lines()
        .filter_map(|l| {
            let (name, rest) = l.trim().split_once(" = ")?;
            let (v, rest) = rest.split_once(" +- ")?;
            let e = rest.split_whitespace().next()?;
            Some((name.trim().to_owned(), v.parse().ok()?, e.parse().ok()?))
        })
        .collect()
}

/// The fleet status once `machine` has `windows` windows identified.
fn wait_for_windows(url: &str, machine: &str, windows: usize) -> String {
    let t = Instant::now();
    let n = windows.to_string();
    loop {
        let s = run(&["fleet", "status", "--nats", url]);
        let done = s.lines().any(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            f.first() == Some(&machine) && f.get(2) == Some(&n.as_str())
        });
        if done {
            return s;
        }
        assert!(
            t.elapsed() < Duration::from_secs(300), // against a hang, not a speed test
            "not identified:\n{s}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// SIGTERM: the worker finishes its window and exits 0.
fn stop(worker: std::process::Child) {
    let pid = worker.id().to_string();
    assert!(Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap()
        .success());
    let out = worker.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "worker: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_recording_published_in_windows_is_identified_by_a_worker() {
    let dir = tempfile::tempdir().unwrap();
    let server = Server::start(&dir.path().join("js"));
    let url = server.url();
    let rec = dir.path().join("r.csv");
    let rec = rec.to_str().unwrap();
    run(&[
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "3",
        "--snr-db",
        "40",
        "--seed",
        "11",
        "--out",
        rec,
        "-q",
    ]);
    run(&[
        "publish",
        rec,
        "--nats",
        &url,
        "--machine",
        "rig-1",
        "--window-s",
        "1",
    ]);
    let worker = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
        .args([
            "worker",
            "--nats",
            &url,
            "--scenario",
            "table1",
            "--method",
            "refine",
            // settings reach the worker: three unknowns, the others known from table1
            "--unknowns",
            "m,kx,kz",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let status = wait_for_windows(&url, "rig-1", 3);
    stop(worker);
    assert!(status.contains("window 2"), "{status}");
    // the latest window (2 s to 3 s) as offline identify gives it on the same samples
    let text = std::fs::read_to_string(rec).unwrap();
    let mut lines = text.lines();
    let mut window = vec![lines.next().unwrap().to_owned()];
    window.extend(lines.skip(20_000).map(str::to_owned)); // the 30 001st sample joins it
    let last = dir.path().join("w2.csv");
    std::fs::write(&last, window.join("\n") + "\n").unwrap();
    let sum = dir.path().join("w2.json");
    run(&[
        "identify",
        last.to_str().unwrap(),
        "--scenario",
        "table1",
        "--method",
        "refine",
        "--unknowns",
        "m,kx,kz",
        "--out",
        dir.path().join("e.csv").to_str().unwrap(),
        "--summary",
        sum.to_str().unwrap(),
        "-q",
    ]);
    let offline: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    let got = estimates(&status);
    assert_eq!(got.len(), 3, "m, kx, kz estimated; cx, cz known: {status}");
    for (name, v, e) in got {
        let p = offline["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["parameter"] == name.as_str())
            .unwrap_or_else(|| panic!("{name} not in the offline summary"));
        let (ov, oe, truth) = (
            p["value"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
            p["truth"].as_f64().unwrap(),
        );
        // the status prints 7 significant digits and 3 of the error
        assert!(
            (v - ov).abs() <= 1e-6 * ov.abs(),
            "{name}: {v} vs offline {ov}"
        );
        assert!(
            (e - oe).abs() <= 1e-2 * oe,
            "{name}: +- {e} vs offline {oe}"
        );
        assert!(
            (v - truth).abs() < 5.0 * e,
            "{name}: {v} +- {e}, truth {truth}"
        );
    }
}

#[test]
fn a_worker_identifies_the_cross_coupled_model_it_is_given() {
    // `--model cross_coupled` reaches the worker: each window's ten values of the
    // cross-coupled modulating identifier, as offline `identify` gives them
    let dir = tempfile::tempdir().unwrap();
    let server = Server::start(&dir.path().join("js"));
    let url = server.url();
    let scenario = dir.path().join("cross.toml");
    std::fs::write(
        &scenario,
        "[rotor]\nmodel = \"cross_coupled\"\nm = 14.29\na = 2.871\nkxx = 1.195e6\n\
         kxz = -3.0e4\nkzx = 3.0e4\nkzz = 1.4e6\ncxx = 200.0\ncxz = 20.0\nczx = 20.0\n\
         czz = 200.0\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45.0\n\n[speed]\nkind = \
         \"constant\"\nrpm = 1200.0\n\n[sampling]\ndt = 1e-4\nduration = 1.0\n",
    )
    .unwrap();
    // the workers know only what identify needs: a, the unbalance, the speed
    let known = dir.path().join("known.toml");
    std::fs::write(
        &known,
        "[rotor]\na = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45.0\n\n[speed]\n\
         kind = \"constant\"\nrpm = 1200.0\n",
    )
    .unwrap();
    let (scenario, known) = (scenario.to_str().unwrap(), known.to_str().unwrap());
    let rec = dir.path().join("r.csv");
    let rec = rec.to_str().unwrap();
    run(&[
        "simulate",
        "--scenario",
        scenario,
        "--snr-db",
        "40",
        "--seed",
        "3",
        "--out",
        rec,
        "-q",
    ]);
    run(&[
        "publish",
        rec,
        "--nats",
        &url,
        "--machine",
        "rig-2",
        "--window-s",
        "1",
    ]);
    let settings = ["--method", "modulating", "--model", "cross_coupled"];
    let worker = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
        .args(["worker", "--nats", &url, "--scenario", known])
        .args(settings)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let status = wait_for_windows(&url, "rig-2", 1);
    stop(worker);
    let sum = dir.path().join("s.json");
    run(&[
        "identify",
        rec,
        "--scenario",
        known,
        "--out",
        dir.path().join("e.csv").to_str().unwrap(),
        "--summary",
        sum.to_str().unwrap(),
        "-q",
    ]
    .iter()
    .copied()
    .chain(settings)
    .collect::<Vec<_>>());
    let offline: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    assert_eq!(offline["model"], "cross_coupled");
    let got = estimates(&status);
    let names: Vec<&str> = got.iter().map(|(n, _, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["m_x", "cxx", "cxz", "kxx", "kxz", "m_z", "czx", "czz", "kzx", "kzz"],
        "{status}"
    );
    for (name, v, e) in got {
        let p = offline["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["parameter"] == name.as_str())
            .unwrap();
        let (ov, oe) = (
            p["value"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        );
        assert!(
            (v - ov).abs() <= 1e-6 * ov.abs(),
            "{name}: {v} vs offline {ov}"
        );
        assert!(
            (e - oe).abs() <= 1e-2 * oe,
            "{name}: +- {e} vs offline {oe}"
        );
    }
}

#[test]
fn publish_refuses_a_machine_id_that_is_not_a_subject_token() {
    let out = rotorid()
        .args([
            "publish",
            "whatever.csv",
            "--nats",
            "nats://127.0.0.1:1",
            "--machine",
            "rig 1.a",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--machine \"rig 1.a\"") && err.contains("letters, digits"),
        "{err}"
    );
}

#[test]
fn worker_settings_are_checked_against_the_method_before_connecting() {
    for (args, want) in [
        (
            &["--method", "algebraic", "--window", "1"][..],
            "--window applies to --method modulating and refine only, not to --method algebraic",
        ),
        (
            &["--method", "modulating", "--restart", "0.5"][..],
            "--restart applies to --method algebraic only, not to --method modulating",
        ),
        (
            &["--method", "refine", "--rcond-min", "2"][..],
            "--rcond-min = 2 is out of range: must be in [0, 1]",
        ),
    ] {
        let out = rotorid()
            .args([
                "worker",
                "--nats",
                "nats://127.0.0.1:1",
                "--scenario",
                "table1",
            ])
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{args:?}: {err}");
    }
}

#[test]
fn server_lists_and_replica_counts_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let server = Server::start(&dir.path().join("js"));
    let url = server.url();
    let rec = dir.path().join("r.csv");
    let rec = rec.to_str().unwrap();
    run(&[
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "0.5",
        "--out",
        rec,
        "-q",
    ]);
    // a dead first server (nothing listens on port 1), then ours, given as a list and again
    // with --nats repeated: the command connects, and says which server it is on
    let list = format!("nats://127.0.0.1:1, {url}");
    for nats in [
        vec!["--nats", list.as_str()],
        vec!["--nats", "nats://127.0.0.1:1", "--nats", url.as_str()],
    ] {
        let out = rotorid()
            .args(["publish", rec, "--machine", "rig-9", "--window-s", "0.25"])
            .args(&nats)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{nats:?}: {err}");
        assert!(
            err.contains(&format!(
                "publish: NATS: on nats://127.0.0.1:{}",
                server.port
            )),
            "{err}"
        );
    }
    let status = run(&[
        "fleet",
        "status",
        "--nats",
        &format!("nats://127.0.0.1:1,{url}"),
    ]);
    assert!(status.contains("rig-9"), "{status}");
    // a stream that exists with fewer replicas is reported, and left as it is
    let out = rotorid()
        .args(["publish", rec, "--machine", "rig-9", "--nats", &url])
        .args(["--replicas", "3"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success()
            && err.contains("stream ROTORID_RAW has 1 replica(s), fewer than --replicas 3")
            && err.contains("`rotorid fleet replicas 3 --nats"),
        "{err}"
    );
    // refusals: a bad list, a replica count out of range, more replicas than servers (a
    // server of its own: no stream yet)
    let other = Server::start(&dir.path().join("js2"));
    let fresh = other.url();
    for (args, want) in [
        (
            vec!["--nats", "nats://127.0.0.1:99999"],
            "NATS server \"nats://127.0.0.1:99999\": NATS server URL is invalid: invalid port",
        ),
        (
            vec!["--nats", "nats://127.0.0.1:1,,nats://127.0.0.1:2"],
            "an empty item",
        ),
        (
            vec!["--nats", url.as_str(), "--replicas", "0"],
            "--replicas: replicas = 0 is out of range: 1 ..= 5",
        ),
        (
            vec!["--nats", fresh.as_str(), "--replicas", "3"],
            "replicas = 3: the NATS servers refuse stream ROTORID_RAW with 3 replicas",
        ),
    ] {
        let out = rotorid()
            .args(["publish", rec, "--machine", "rig-8"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
}
