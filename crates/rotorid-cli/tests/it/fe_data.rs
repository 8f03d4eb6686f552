//! The data of a finite-element rotor: raw acquisitions with two probes
//! per measured node (`[[acquisition.probe]] node = N`), simulated by `rotorid simulate
//! --raw` and conditioned back by `rotorid condition` (docs/acquisition.md section 11).
//! Checked against the simulated response itself (exactly, without noise; within the
//! noise and quantisation stated, with them) and, for the frame, against the 2-DOF raw
//! simulation of the same one-node rotor: a probe at theta from +x towards +y in the
//! finite-element frame is the 2-DOF probe at -theta (x = x, y = -z).

use crate::common::{rotorid, simulate};
use crate::finite_element::{columns, scenarios};

/// A two-node rotor (x, y at nodes 0 and 1): 2 kg and 3 kg joined by a shaft spring, a
/// gyroscopic coupling at node 1, a bearing at each node, an unbalance at node 1.
pub(crate) fn two_node(dir: &std::path::Path, acquisition: &str) -> String {
    let (k, g) = (2.0e6, 0.01);
    #[rustfmt::skip]
    let kk = vec![
        k, 0.0, -k, 0.0,
        0.0, k, 0.0, -k,
        -k, 0.0, k, 0.0,
        0.0, -k, 0.0, k,
    ];
    let mut gg = vec![0.0; 16];
    gg[11] = g;
    gg[14] = -g;
    let mut m = vec![0.0; 16];
    for (i, v) in [2.0, 2.0, 3.0, 3.0].into_iter().enumerate() {
        m[i * 5] = v;
    }
    rotorid_io::fe_matrices::write(
        dir.join("two.npz"),
        &rotorid_io::FeMatricesFile {
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
    let toml = dir.join("two.toml");
    std::fs::write(
        &toml,
        format!(
            "[rotor]\nmodel = \"finite_element\"\nmatrices = \"two.npz\"\n\
             [[rotor.bearing]]\nnode = 0\nkxx = 1.0e6\nkyy = 1.3e6\ncxx = 200.0\ncyy = 250.0\n\
             [[rotor.bearing]]\nnode = 1\nkxx = 1.5e6\nkyy = 1.1e6\nkxy = 2.0e4\ncxx = 300.0\n\
             cyy = 300.0\n\
             [[rotor.unbalance]]\nnode = 1\nm_u = 1e-4\nd = 0.1\nalpha_deg = 30.0\n\
             [speed]\nkind = \"constant\"\nrpm = 3000.0\n\
             [sampling]\ndt = 1e-4\nduration = 0.2\n\n{acquisition}"
        ),
    )
    .unwrap();
    toml.display().to_string()
}

/// Probes at node 1 (0 and 90 deg; the second wired the other way: s < 0) and node 0 (45
/// and 135 deg), in that order in the file; the keyphasor at phi = 0.
pub(crate) const PROBES: &str = "[acquisition]\ntime = \"t\"\n\
    [[acquisition.probe]]\ncolumn = \"b1\"\nnode = 1\nangle_deg = 0.0\nsensitivity = 7874.0\n\
    [[acquisition.probe]]\ncolumn = \"a0\"\nnode = 0\nangle_deg = 45.0\nsensitivity = 7874.0\n\
    [[acquisition.probe]]\ncolumn = \"b2\"\nnode = 1\nangle_deg = 90.0\nsensitivity = -7874.0\n\
    [[acquisition.probe]]\ncolumn = \"a1\"\nnode = 0\nangle_deg = 135.0\nsensitivity_mv_per_mil = 200.0\n\
    [acquisition.keyphasor]\ncolumn = \"kp\"\n";

/// `[acquisition.simulate]` without noise, quantisation, runout or keyphasor jitter.
const CLEAN: &str = "[acquisition.simulate]\nsnr_db = inf\nbits = 0\nkp_jitter_s = 0.0\n\
    kp_noise_v = 0.0\nrunout_um = [[0.0], [0.0], [0.0], [0.0]]\n\
    gap_v = [-9.0, -10.5, 9.5, -8.0]\n";

/// A CSV as (header, rows).
type Csv = (String, Vec<Vec<f64>>);

/// `rotorid ARGS`: stdout on success, else stderr as the error.
fn run(args: &[&str]) -> Result<String, String> {
    let out = rotorid().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    if out.status.success() {
        Ok(String::from_utf8(out.stdout).unwrap())
    } else {
        Err(stderr)
    }
}

/// Simulate the raw record of `toml`, condition it, and return the conditioned response
/// and the simulated one (same columns), each as (header, rows).
fn raw_round_trip(dir: &std::path::Path, toml: &str) -> (Csv, Csv) {
    let raw = dir.join("raw.csv");
    run(&[
        "simulate",
        "--scenario",
        toml,
        "--raw",
        "-q",
        "--out",
        raw.to_str().unwrap(),
    ])
    .unwrap();
    let cond = run(&[
        "condition",
        raw.to_str().unwrap(),
        "--scenario",
        toml,
        "--out",
        "-",
    ])
    .unwrap();
    let truth = simulate(&["--scenario", toml]);
    (columns(&cond), columns(&truth))
}

/// Per conditioned degree of freedom (header name, column in truth): the largest
/// deviation of (conditioned - truth) from its mean, that mean, the RMS of the deviation
/// and the truth's amplitude and RMS.
fn compare(cond: &Csv, truth: &Csv) -> Vec<[f64; 5]> {
    let th: Vec<&str> = truth.0.split(',').collect();
    let ch: Vec<&str> = cond.0.split(',').collect();
    let n = cond.1.len() as f64;
    ch[1..ch.len() - 3]
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let k = th.iter().position(|h| h == name).unwrap();
            let d: Vec<f64> = cond
                .1
                .iter()
                .zip(&truth.1)
                .map(|(c, t)| c[j + 1] - t[k])
                .collect();
            let mean = d.iter().sum::<f64>() / n;
            let worst = d.iter().fold(0.0f64, |a, v| a.max((v - mean).abs()));
            let rms = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            let amp = truth.1.iter().fold(0.0f64, |a, r| a.max(r[k].abs()));
            let trms = (truth.1.iter().map(|r| r[k] * r[k]).sum::<f64>() / n).sqrt();
            [worst, mean, rms, amp, trms]
        })
        .collect()
}

#[test]
fn a_raw_record_conditions_back_to_the_response_at_the_probes_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let toml = two_node(dir.path(), &format!("{PROBES}{CLEAN}"));
    let (cond, truth) = raw_round_trip(dir.path(), &toml);
    // the nodes in the order they first appear among the probes
    assert_eq!(cond.0, "t,1.x,1.y,0.x,0.y,phi,phi_dot,phi_ddot");
    assert_eq!(cond.1.len(), 2001);
    for (c, t) in cond.1.iter().zip(&truth.1) {
        assert_eq!(c[0], t[0]);
        // phi from the keyphasor, to a whole turn (the events count turns from the first):
        // the edge timed by linear interpolation (~1e-4 rad)
        let d = (c[5] - t[5]).rem_euclid(std::f64::consts::TAU);
        assert!(d.min(std::f64::consts::TAU - d) < 2e-3, "{c:?} {t:?}");
        assert!((c[6] - t[6]).abs() < 1e-6 * t[6], "{c:?} {t:?}");
    }
    // exact up to the DC: without a model the DC is the mean over whole revolutions,
    // which holds the mean of the start-up transient
    for (j, [worst, mean, _, amp, _]) in compare(&cond, &truth).into_iter().enumerate() {
        println!(
            "column {j}: off the response by {:.1e} of its amplitude {amp:.3e} m, after the \
             DC {mean:.2e} m",
            worst / amp
        );
        assert!(worst < 1e-9 * amp, "{j}: {worst:e} of {amp:e}");
        assert!(mean.abs() < 0.05 * amp, "{j}: {mean:e} of {amp:e}");
    }
}

#[test]
fn noise_and_quantisation_are_what_the_record_carries() {
    // the 16-bit step over the 24 V of [-24, 0] V, in volts and, at 7874 V/m, in metres
    let q_v = 24.0 / 65536.0;
    let q = q_v / 7874.0;
    let dir = tempfile::tempdir().unwrap();
    // white noise at 20 dB and the quantisation; then the quantisation alone
    for snr in [Some(20.0), None] {
        let toml = two_node(
            dir.path(),
            &format!(
                "{PROBES}[acquisition.simulate]\nsnr_db = {}\nseed = 3\nbits = 16\n\
                 runout_um = [[0.0], [0.0], [0.0], [0.0]]\n",
                snr.map_or("inf".to_owned(), |s: f64| s.to_string())
            ),
        );
        let (cond, truth) = raw_round_trip(dir.path(), &toml);
        // the record's volts are the ADC's: every probe sample on the grid -24 V + k q_v
        // (the CSV holds the shortest digits that read back, so k is an integer to
        // rounding), over many steps (a swing of 2 x 0.8 um x 7874 V/m = 13 mV, 34 steps)
        let (head, rows) = columns(&std::fs::read_to_string(dir.path().join("raw.csv")).unwrap());
        let mut probes = 0;
        for (j, name) in head.split(',').enumerate() {
            if !["b1", "b2", "a0", "a1"].contains(&name) {
                continue;
            }
            probes += 1;
            let mut levels = std::collections::BTreeSet::new();
            for r in &rows {
                let k = (r[j] + 24.0) / q_v;
                assert!(
                    (k - k.round()).abs() < 1e-6,
                    "{name}: {} V is not on the 16-bit grid of [-24, 0] V",
                    r[j]
                );
                levels.insert(k.round() as i64);
            }
            assert!(levels.len() >= 20, "{name}: {} levels", levels.len());
        }
        assert_eq!(probes, 4, "{head}");
        // each probe: white noise sigma = RMS 10^(-20/20) on x, y, and the quantisation,
        // RMS q / sqrt(12); the pairs are at right angles, so x, y carry the same
        for (j, [_, _, rms, _, trms]) in compare(&cond, &truth).into_iter().enumerate() {
            let sigma = snr.map_or(0.0, |s| 10f64.powf(-s / 20.0) * trms);
            let expect = (sigma * sigma + q * q / 12.0).sqrt();
            println!(
                "SNR {snr:?} dB, column {j}: error RMS {rms:.3e} m, expected {expect:.3e} m \
                 (noise {sigma:.2e}, quantisation {:.2e}; response RMS {trms:.2e})",
                q / 12f64.sqrt()
            );
            let tol = if snr.is_some() { 0.08 } else { 0.1 };
            assert!(
                (rms / expect - 1.0).abs() < tol,
                "{j}: {rms:e} vs {expect:e}"
            );
        }
    }
}

#[test]
fn a_one_node_rotor_records_the_volts_of_the_two_dof_model_with_angles_negated() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, cross) = scenarios(dir.path(), true);
    let acq = |node: &str, a1: f64, a2: f64| {
        format!(
            "\n[acquisition]\ntime = \"t\"\n\
             [[acquisition.probe]]\ncolumn = \"p1\"\n{node}angle_deg = {a1}\nsensitivity = 7874.0\n\
             [[acquisition.probe]]\ncolumn = \"p2\"\n{node}angle_deg = {a2}\nsensitivity = -5000.0\n\
             [acquisition.keyphasor]\ncolumn = \"kp\"\nangle_deg = 20.0\n\
             [acquisition.simulate]\nsnr_db = inf\nbits = 0\nkp_jitter_s = 0.0\nkp_noise_v = 0.0\n"
        )
    };
    let append = |path: &str, text: String| {
        let mut t = std::fs::read_to_string(path).unwrap();
        t.push_str(&text);
        std::fs::write(path, t).unwrap();
    };
    append(&fe, acq("node = 0\n", 30.0, 150.0));
    append(&cross, acq("", -30.0, -150.0));
    let raw = |toml: &str| {
        columns(&run(&["simulate", "--scenario", toml, "--raw", "-q", "--out", "-"]).unwrap())
    };
    let (hf, f) = raw(&fe);
    let (hc, c) = raw(&cross);
    assert_eq!(hf, "t,p1,p2,kp");
    assert_eq!(hf, hc);
    assert_eq!(f.len(), c.len());
    // probe volts: gap + s d, d ~ 1e-5 m: the two simulators agree to ~1e-9 of s d
    let mut worst = [0.0f64; 3];
    for (a, b) in f.iter().zip(&c) {
        assert_eq!(a[0], b[0]);
        for k in 1..4 {
            worst[k - 1] = worst[k - 1].max((a[k] - b[k]).abs());
        }
    }
    println!("largest difference of the volts p1, p2, kp: {worst:?} V");
    let swing = |k: usize| {
        let (lo, hi) = c
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), r| (l.min(r[k]), h.max(r[k])));
        hi - lo
    };
    for k in 1..3 {
        assert!(swing(k) > 0.01, "{k}: {}", swing(k));
        assert!(worst[k - 1] < 1e-8 * swing(k), "{k}: {worst:?}");
    }
    assert!(worst[2] < 1e-9, "{worst:?}");
}

#[test]
fn probes_at_nodes_are_checked_by_name() {
    let dir = tempfile::tempdir().unwrap();
    // the error, and the 1-based line of the `k`-th line (from 0) holding `needle` after
    // [acquisition]
    let err = |acq: &str, needle: &str, k: usize| {
        let toml = two_node(dir.path(), acq);
        let text = std::fs::read_to_string(&toml).unwrap();
        let start = text.lines().position(|l| l == "[acquisition]").unwrap();
        let line = text
            .lines()
            .enumerate()
            .skip(start)
            .filter(|(_, l)| l.contains(needle))
            .nth(k)
            .map_or(0, |(i, _)| i + 1);
        let e = run(&["simulate", "--scenario", &toml, "--raw", "--out", "-"]).unwrap_err();
        (e, format!("two.toml:{line}: "))
    };
    let probe = |col: &str, node: &str, angle: f64| {
        format!(
            "[[acquisition.probe]]\ncolumn = \"{col}\"\n{node}angle_deg = {angle}\n\
             sensitivity = 7874.0\n"
        )
    };
    let kp = "[acquisition.keyphasor]\ncolumn = \"kp\"\n";
    let head = "[acquisition]\ntime = \"t\"\n";
    // a probe without node (the scenario's lines: 17 rotor lines, a blank, [acquisition]..)
    let (e, at) = err(
        &format!(
            "{head}{}{}{kp}",
            probe("a", "node = 0\n", 0.0),
            probe("b", "", 90.0)
        ),
        "[[acquisition.probe]]",
        1,
    );
    assert!(
        e.contains(&format!("{at}missing key acquisition.probe.node"))
            && e.contains("every probe of a finite-element rotor names one"),
        "{e}"
    );
    // a node not in the matrices
    let (e, at) = err(
        &format!(
            "{head}{}{}{kp}",
            probe("a", "node = 4\n", 0.0),
            probe("b", "node = 4\n", 90.0)
        ),
        "node = 4",
        0,
    );
    assert!(
        e.contains(&format!(
            "{at}acquisition.probe[0].node = 4: the matrices file"
        )) && e.contains("two.npz has no degree of freedom 4.x")
            && e.contains("allowed nodes: 0, 1"),
        "{e}"
    );
    // one probe at a node
    let (e, at) = err(
        &format!(
            "{head}{}{}{}{kp}",
            probe("a", "node = 0\n", 0.0),
            probe("b", "node = 1\n", 90.0),
            probe("c", "node = 0\n", 90.0)
        ),
        "node = 1",
        0,
    );
    assert!(
        e.contains(&format!(
            "{at}acquisition.probe[1].node = 1: node 1 has 1 probe(s) (column \"b\")"
        )) && e.contains("needs exactly two"),
        "{e}"
    );
    // two probes at a node on the same line of sight
    let (e, _) = err(
        &format!(
            "{head}{}{}{kp}",
            probe("a", "node = 0\n", 10.0),
            probe("b", "node = 0\n", 190.0)
        ),
        "",
        0,
    );
    assert!(
        e.contains("probes at 10 deg and 190 deg (node 0) are 0.0 deg apart"),
        "{e}"
    );
    // a node in a 2-DOF scenario
    let (_, cross) = scenarios(dir.path(), false);
    let mut t = std::fs::read_to_string(&cross).unwrap();
    t.push_str(&format!(
        "\n{head}{}{}{kp}",
        probe("a", "node = 0\n", 0.0),
        probe("b", "", 90.0)
    ));
    std::fs::write(&cross, t).unwrap();
    let e = run(&["simulate", "--scenario", &cross, "--raw", "--out", "-"]).unwrap_err();
    assert!(
        e.contains("acquisition.probe[0].node: a probe's node is for a finite-element rotor")
            && e.contains("this scenario's rotor is cross_coupled"),
        "{e}"
    );
    // the slow roll of a finite-element rotor is not simulated: said, not skipped
    let toml = two_node(dir.path(), &format!("{PROBES}{CLEAN}"));
    let e = run(&[
        "simulate",
        "--scenario",
        &toml,
        "--raw",
        "--out",
        "-",
        "--slow-roll-out",
        "s.csv",
    ])
    .unwrap_err();
    assert!(
        e.contains("--slow-roll-out: the slow-roll record of a finite-element rotor"),
        "{e}"
    );
}
