//! What users hand the command: raw proximity-probe records from the independent generator
//! of the library's tests (`raw_reference`: RK4 on eq. (1), trapezoidal keyphasor notch,
//! 16 bits, runout 1X-3X, a slow roll holding the rotor's own response, 6-decimal stamps),
//! conditioned with the scenario's `[rotor]` whether or not the scenario has a `[speed]`
//! table; and response CSVs whose stamps are printed with 6 decimals, accepted with a note,
//! while 2 % jitter is refused.

use std::path::Path;

use crate::common::{rotorid, simulate};

#[path = "../../../rotorid/tests/it/raw_reference.rs"]
mod gen;

/// Write the raw record and slow roll of `turn` (seed `seed`) and a scenario with `speed`
/// (its `[speed]` lines) and `rotor` (its `[rotor]` lines, the full rotor when `None`) into
/// `dir`; returns (raw path, scenario path, the record).
fn rig(
    dir: &Path,
    turn: &gen::Turning,
    seed: u64,
    speed: Option<&str>,
    rotor: Option<&str>,
) -> (String, String, gen::Raw) {
    let r = gen::running(turn, seed);
    let slow = gen::slow_roll(r.sigma, seed);
    std::fs::write(dir.join("raw.csv"), gen::csv(&r)).unwrap();
    std::fs::write(dir.join("slow.csv"), gen::csv(&slow)).unwrap();
    let mut toml = gen::scenario_toml("slow.csv", speed);
    if let Some(lines) = rotor {
        let end = toml.find("\n\n").unwrap();
        toml.replace_range(..end, &format!("[rotor]\n{lines}"));
    }
    std::fs::write(dir.join("rig.toml"), toml).unwrap();
    let p = |n: &str| dir.join(n).to_str().unwrap().to_owned();
    (p("raw.csv"), p("rig.toml"), r)
}

/// Columns `t,x,z,...` of a response CSV.
fn xz(csv: &str) -> (Vec<f64>, Vec<f64>) {
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("t,x,z"));
    lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (f[1], f[2])
        })
        .unzip()
}

/// RMS of the 16-bit quantisation in x and z [m] (one step of 24 V / 2^16 at 7874 V/m over
/// sqrt(12); the inverse projection of probes at +-45 deg is a rotation).
const QUANTISATION: f64 = 24.0 / 65536.0 / 7874.0 / 3.464_101_615_137_754_6;

/// `rotorid condition` on the rig: (x, z error / the noise the probes carry, white and
/// quantisation; stderr).
fn condition(raw: &str, scenario: &str, r: &gen::Raw) -> ([f64; 2], String) {
    let out = rotorid()
        .args(["condition", raw, "--scenario", scenario, "--out", "-"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    let (x, z) = xz(&String::from_utf8(out.stdout).unwrap());
    let e =
        |a: &[f64], b: &[f64]| gen::rms(&a.iter().zip(b).map(|(p, q)| p - q).collect::<Vec<_>>());
    (
        [
            e(&x, &r.x) / r.sigma[0].hypot(QUANTISATION),
            e(&z, &r.z) / r.sigma[1].hypot(QUANTISATION),
        ],
        stderr,
    )
}

#[test]
fn condition_uses_the_scenarios_rotor_with_and_without_a_speed_table() {
    let dir = tempfile::tempdir().unwrap();
    for (turn, speed) in [
        (
            gen::Turning::rpm(1200.0),
            "kind = \"constant\"\nrpm = 1200.0",
        ),
        (
            gen::Turning::ramp(600.0, 10.0),
            "kind = \"ramp\"\nrpm0 = 600.0\naccel = 10.0",
        ),
    ] {
        for with_speed in [false, true] {
            let (raw, sc, r) = rig(dir.path(), &turn, 3, with_speed.then_some(speed), None);
            let (e, stderr) = condition(&raw, &sc, &r);
            eprintln!("{speed:?} [speed] {with_speed}: x, z error / noise {e:.3?}");
            assert!(e[0] <= 1.05 && e[1] <= 1.05, "{e:?}\n{stderr}");
            assert!(
                stderr.contains("note: rotor guess (the scenario's [rotor]): m = 14.29 kg"),
                "{stderr}"
            );
        }
    }
    // a [rotor] without m, c, k: no guess, and the note says why
    let known = "a = 2.871\nm_u = 0.004\nd = 0.15\nalpha_deg = 45.0";
    let (raw, sc, r) = rig(dir.path(), &gen::Turning::rpm(1200.0), 3, None, Some(known));
    let (_, stderr) = condition(&raw, &sc, &r);
    assert!(
        stderr.contains("note: no rotor guess from the scenario:") && stderr.contains("rotor.m"),
        "{stderr}"
    );
}

#[test]
fn identify_conditions_a_run_up_until_the_guess_settles() {
    // no [speed] (the keyphasor gives it): the scenario's rotor is the first guess
    let dir = tempfile::tempdir().unwrap();
    let (raw, sc, _) = rig(dir.path(), &gen::Turning::ramp(600.0, 10.0), 4, None, None);
    let summary = dir.path().join("s.json");
    let out = rotorid()
        .args([
            "identify",
            &raw,
            "--scenario",
            &sc,
            "--method",
            "refine",
            "-q",
        ])
        .args(["--out", "-", "--summary", summary.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("note: conditioned and identified in ")
            && stderr.contains("standard errors (settled"),
        "{stderr}"
    );
    // the conditioned record keeps the raw stamps, printed with 6 decimals
    assert!(stderr.contains("printed to 1e-6 s"), "{stderr}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    for p in s["parameters"].as_array().unwrap() {
        let (v, t, se) = (
            p["value"].as_f64().unwrap(),
            p["truth"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        );
        assert!(
            (v - t).abs() < 4.0 * se,
            "{}: {v} vs {t} (se {se})",
            p["parameter"]
        );
    }
}

/// A 25.6 kHz response CSV of table1 at 40 dB with its stamps rewritten by `stamp(i)`.
fn restamped(stamp: impl Fn(usize) -> String) -> String {
    let csv = simulate(&[
        "--scenario",
        "table1",
        "--dt",
        "3.90625e-5",
        "--duration",
        "0.5",
        "--snr-db",
        "40",
        "--seed",
        "9",
    ]);
    let mut out = String::new();
    for (i, line) in csv.lines().enumerate() {
        if i == 0 {
            out.push_str(line);
        } else {
            let (_, rest) = line.split_once(',').unwrap();
            out.push_str(&format!("{},{rest}", stamp(i - 1)));
        }
        out.push('\n');
    }
    out
}

#[test]
fn six_decimal_stamps_identify_without_options_and_jitter_is_refused() {
    let dt = 1.0 / 25600.0;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rounded.csv");
    std::fs::write(&path, restamped(|i| format!("{:.6}", i as f64 * dt))).unwrap();
    let summary = dir.path().join("s.json");
    let out = rotorid()
        .args(["identify", path.to_str().unwrap(), "--scenario", "table1"])
        .args(["--method", "modulating"])
        .args(["--out", "-", "--summary", summary.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("note: the time stamps are printed to 1e-6 s"),
        "{stderr}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    // a file streams: its grid is fitted over its first 4096 stamps, whose rounding
    // (0.29 us RMS) leaves the period within about 1e-7 of the truth (and no drift warning)
    let fitted = s["record"]["dt_s"].as_f64().unwrap();
    assert!((fitted - dt).abs() < 1e-7 * dt, "{fitted}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let note = s["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["kind"] == "time_stamps_rounded")
        .expect("the note in the summary");
    assert_eq!(note["severity"], "note");
    assert_eq!(note["resolution_s"].as_f64(), Some(1e-6));
    // 2 % jitter (uniform, +-0.02 dt), printed alike: refused with the stamp named
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut draw = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let jitter: Vec<f64> = (0..20_000).map(|_| 0.02 * dt * draw()).collect();
    let path = dir.path().join("jitter.csv");
    std::fs::write(
        &path,
        restamped(|i| format!("{:.6}", i as f64 * dt + jitter[i])),
    )
    .unwrap();
    let out = rotorid()
        .args(["identify", path.to_str().unwrap(), "--scenario", "table1"])
        .args(["--out", "-"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success());
    assert!(
        stderr.contains("sampling is not uniform")
            && stderr.contains(
                "the allowed deviation is 1e-6 of dt, plus 1e-6 s for stamps printed to 1e-6 s"
            )
            && stderr.contains("(--time-tolerance)"),
        "{stderr}"
    );
}
