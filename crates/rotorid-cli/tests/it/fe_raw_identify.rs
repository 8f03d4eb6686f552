//! `rotorid identify RAW --scenario fe.toml --method refine`: a raw acquisition of a
//! finite-element rotor (two probes per measured node, a keyphasor) conditioned without a
//! rotor guess and identified with one constant offset per channel (the mean of the motion
//! over the record's revolutions stays in each probe's DC). Checked against the truth the
//! record was simulated from, and the offsets against the conditioned record minus the
//! simulated response (`rotorid condition` and `rotorid simulate`, independent of the fit).

use crate::common::{identify_outputs, simulate};
use crate::fe_data::{two_node, PROBES};
use crate::finite_element::{columns, param};

/// The two-node rotor's values (the scenario of `two_node`) and the guess the fit starts
/// from: every direct coefficient 25-40 % off, the unbalance 40 % and 40 deg off.
const TRUTH_AND_GUESS: [(&str, &str); 4] = [
    (
        "kxx = 1.0e6\nkyy = 1.3e6\ncxx = 200.0\ncyy = 250.0",
        "kxx = 1.3e6\nkyy = 0.9e6\ncxx = 270.0\ncyy = 170.0",
    ),
    (
        "kxx = 1.5e6\nkyy = 1.1e6\nkxy = 2.0e4\ncxx = 300.0\n",
        "kxx = 1.1e6\nkyy = 1.45e6\nkxy = 2.0e4\ncxx = 400.0\n",
    ),
    (
        "cyy = 300.0\n[[rotor.unbalance]]",
        "cyy = 200.0\n[[rotor.unbalance]]",
    ),
    (
        "m_u = 1e-4\nd = 0.1\nalpha_deg = 30.0",
        "m_u = 1.4e-4\nd = 0.1\nalpha_deg = 70.0",
    ),
];

/// The truth of each default unknown of the two-node rotor.
const TRUTH: [(&str, f64); 10] = [
    ("bearing0.kxx", 1.0e6),
    ("bearing0.kyy", 1.3e6),
    ("bearing0.cxx", 200.0),
    ("bearing0.cyy", 250.0),
    ("bearing1.kxx", 1.5e6),
    ("bearing1.kyy", 1.1e6),
    ("bearing1.cxx", 300.0),
    ("bearing1.cyy", 300.0),
    ("unbalance0.mud", 1e-5),
    ("unbalance0.alpha", 0.523_598_775_598_298_8),
];

/// `rotorid simulate --scenario TOML --raw` into DIR/raw.csv.
fn raw_record(dir: &std::path::Path, toml: &str) -> std::path::PathBuf {
    let raw = dir.join("raw.csv");
    std::fs::write(&raw, simulate(&["--scenario", toml, "--raw"])).unwrap();
    raw
}

#[test]
fn a_raw_record_of_a_finite_element_rotor_is_identified_with_its_offsets() {
    let dir = tempfile::tempdir().unwrap();
    // probes at 45/135 deg (node 0) and 0/90 deg (node 1), 60 dB, a 24-bit converter,
    // from rest at 3000 rpm for 0.2 s: the offsets (the mean of the start-up transient,
    // ~1e-3 of the amplitude) are tens of their standard errors
    let toml = two_node(
        dir.path(),
        &format!(
            "{PROBES}[acquisition.simulate]\nsnr_db = 60.0\nseed = 5\nbits = 24\n\
             runout_um = [[0.0], [0.0], [0.0], [0.0]]\n"
        ),
    );
    let text = std::fs::read_to_string(&toml).unwrap();
    let mut guess_text = text.clone();
    for (t, g) in TRUTH_AND_GUESS {
        assert!(guess_text.contains(t), "{t}");
        guess_text = guess_text.replace(t, g);
    }
    let guess = dir.path().join("guess.toml");
    std::fs::write(&guess, guess_text).unwrap();
    let raw = raw_record(dir.path(), &toml);
    let (_, s) = identify_outputs(
        dir.path(),
        raw.to_str().unwrap(),
        guess.to_str().unwrap(),
        "refine",
        &["--initial", "rest"],
    );
    assert_eq!(s["converged"], true, "{s}");
    assert_eq!(s["identifiable"], true, "{s}");
    assert_eq!(s["adequacy"]["model_adequate"], true, "{s}");
    let mut worst = 0.0f64;
    for (name, truth) in TRUTH {
        let p = param(&s, name);
        let (v, e) = (
            p["value"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        );
        let z = (v - truth) / e;
        println!("{name:18} {v:>13.6e} +- {e:.2e} (truth {truth:.6e}, z = {z:+.2})");
        worst = worst.max(z.abs());
    }
    assert!(worst < 4.5, "largest error {worst} std");
    // the offsets: the conditioned record minus the simulated response, per channel (the
    // conditioning's DC less the truth's, independent of the fit)
    let cond = columns(
        &String::from_utf8(
            crate::common::rotorid()
                .args(["condition"])
                .arg(&raw)
                .args(["--scenario", &toml, "--out", "-"])
                .output()
                .unwrap()
                .stdout,
        )
        .unwrap(),
    );
    let truth = columns(&simulate(&["--scenario", &toml]));
    let th: Vec<&str> = truth.0.split(',').collect();
    let offsets = s["offsets"].as_array().unwrap();
    assert_eq!(offsets.len(), 4);
    for (j, o) in offsets.iter().enumerate() {
        let channel = o["channel"].as_str().unwrap();
        let k = th.iter().position(|h| *h == channel).unwrap();
        assert_eq!(cond.0.split(',').nth(j + 1), Some(channel));
        let n = cond.1.len() as f64;
        let expect = cond
            .1
            .iter()
            .zip(&truth.1)
            .map(|(c, t)| c[j + 1] - t[k])
            .sum::<f64>()
            / n;
        let (v, e) = (
            o["value"].as_f64().unwrap(),
            o["std_error"].as_f64().unwrap(),
        );
        println!("offset of {channel}: {v:.4e} +- {e:.2e} m (conditioned - truth: {expect:.4e} m)");
        assert!(
            (v - expect).abs() < 4.5 * e,
            "{channel}: {v} vs {expect} (std {e})"
        );
        assert!(
            expect.abs() > 3.0 * e,
            "{channel}: the offset {expect} is not measurable"
        );
    }
}

#[test]
fn a_raw_record_taken_at_another_speed_than_the_scenario_is_refused_by_name() {
    // the keyphasor says 3000 rpm; the scenario says 3030 rpm (1 %): the model is driven by
    // the scenario's [speed], so the fit would be wrong, and is refused
    let dir = tempfile::tempdir().unwrap();
    let toml = two_node(
        dir.path(),
        &format!("{PROBES}[acquisition.simulate]\nsnr_db = 60.0\nseed = 5\n"),
    );
    let raw = raw_record(dir.path(), &toml);
    let text = std::fs::read_to_string(&toml).unwrap();
    let other = dir.path().join("other.toml");
    std::fs::write(&other, text.replace("rpm = 3000.0", "rpm = 3030.0")).unwrap();
    let out = crate::common::rotorid()
        .arg("identify")
        .arg(&raw)
        .args(["--scenario", other.to_str().unwrap(), "--method", "refine"])
        .args(["--out", dir.path().join("e.csv").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("raw.csv")
            && e.contains("keyphasor's speed departs from the scenario's [speed]")
            && e.contains("allowed 1e-3"),
        "{e}"
    );
    assert!(!dir.path().join("e.csv").exists());
}
