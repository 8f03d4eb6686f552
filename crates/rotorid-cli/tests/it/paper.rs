//! `rotorid paper`: every figure and report is written, images decode at the stated size,
//! the HTML is self-contained, and results.json holds every case, setting, parameter and
//! direction with numbers that only a working simulator + identifier would give.

use std::path::Path;

use crate::common::rotorid;
use serde_json::Value;

fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    // not blank: a figure has many distinct colours
    let distinct: std::collections::HashSet<&[u8]> =
        buf.chunks(info.color_type.samples()).collect();
    assert!(distinct.len() > 50, "{} looks blank", path.display());
    (info.width, info.height)
}

fn stems() -> Vec<String> {
    (2..=9)
        .flat_map(|n| [format!("fig{n}"), format!("fig{n}_full")])
        .collect()
}

#[test]
fn paper_writes_every_figure_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    rotorid()
        .args(["paper", "--duration", "0.3", "--quiet", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout("")
        .stderr(""); // no progress bar: stderr is not a terminal

    for stem in stems() {
        let (w, h) = png_size(&out.join(format!("{stem}.png")));
        assert!(w >= 1200 && h >= 800, "{stem}.png is {w} x {h}");
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{stem}.svg"
        );
        assert!(
            svg.contains("<text") && svg.contains("<polyline"),
            "{stem}.svg has no text or lines"
        );
    }

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert_eq!(
        html.matches("src=\"data:image/png;base64,").count(),
        stems().len()
    );
    for stem in stems() {
        assert!(
            html.contains(&format!("id=\"{stem}\"")),
            "{stem} not embedded"
        );
    }
    for external in ["src=\"http", "href=\"http", "<link", "<script", "url(http"] {
        assert!(
            !html.contains(external),
            "report.html refers outside itself: {external}"
        );
    }

    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    for stem in stems() {
        assert!(
            md.contains(&format!("]({stem}.png)")),
            "report.md lacks {stem}"
        );
    }

    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["scenario"]["dt"], 1e-4);
    assert_eq!(json["estimate_time"], 0.3);
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2 * 2 * 6);
    let truth = [
        ("m", 14.29, 14.29),
        ("c", 10.0, 10.0),
        ("k", 1.195e6, 1.195e6),
    ];
    for case in ["constant", "ramp"] {
        for setting in ["paper", "ours"] {
            for (p, tx, tz) in truth {
                for (dir, t) in [("x", tx), ("z", tz)] {
                    let row = rows
                        .iter()
                        .find(|r| {
                            r["case"] == case
                                && r["setting"] == setting
                                && r["parameter"] == p
                                && r["direction"] == dir
                        })
                        .unwrap_or_else(|| panic!("no row for {case} {setting} {p} {dir}"));
                    assert_eq!(row["true_value"].as_f64(), Some(t));
                    let est = row["estimate"].as_f64().expect("an estimate at 0.3 s");
                    let err = row["relative_error"].as_f64().unwrap();
                    assert!((err - (est - t) / t).abs() < 1e-12);
                    assert!((row["estimate_t"].as_f64().unwrap() - 0.3).abs() < 1e-3);
                    let paper_time = match (case, p) {
                        ("constant", _) => 0.2,
                        (_, "c") => 0.28,
                        _ => 0.1,
                    };
                    assert_eq!(row["paper_time"].as_f64(), Some(paper_time));
                    if setting == "ours" {
                        // exact data + 5th-order integrals: docs/method.md section 3.8
                        let bound = if p == "c" { 1e-5 } else { 1e-7 };
                        assert!(err.abs() < bound, "{case} ours {p}_{dir}: error {err:e}");
                        let ti = row["identification_time"].as_f64().unwrap();
                        assert!(ti < 0.06, "{case} ours {p}_{dir}: identified at {ti} s");
                        assert_eq!(row["within_paper_time"], true);
                    } else {
                        // Newmark data + trapezoid: biased, but within 1 % at 0.3 s
                        assert!(
                            err.abs() < 1e-2 && err != 0.0,
                            "{case} paper {p}_{dir}: error {err:e}"
                        );
                    }
                }
            }
        }
    }
    let responses = json["responses"].as_array().unwrap();
    assert_eq!(responses.len(), 2);
    for r in responses {
        // Newmark's period error at 0.1 ms leaves a small but non-zero difference
        let rel = r["relative"].as_f64().unwrap();
        assert!(rel > 1e-5 && rel < 1e-1, "{rel}");
    }
    assert_eq!(json["figures"].as_array().unwrap().len(), stems().len());

    // every combination of data and rule, per case; only exact data with the
    // high-order rule is free of the paper's error
    let attribution = json["attribution"].as_array().unwrap();
    assert_eq!(attribution.len(), 2 * 4);
    for a in attribution {
        let worst = a["worst_relative_error"].as_f64().unwrap().abs();
        let exact_am5 = a["simulation"] == "exact" && a["quadrature"] != "trapezoid";
        if exact_am5 {
            assert!(worst < 1e-5, "{a}");
        } else {
            assert!(worst > 1e-4 && worst < 0.1, "{a}");
        }
    }
}

#[test]
fn paper_rejects_a_short_duration_and_an_unusable_directory() {
    let dir = tempfile::tempdir().unwrap();
    rotorid()
        .args(["paper", "--duration", "0.2", "--out"])
        .arg(dir.path())
        .assert()
        .failure()
        .stderr(predicates::str::contains("--duration 0.2 is out of range"));
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    rotorid()
        .args(["paper", "--duration", "0.3", "--out"])
        .arg(&file)
        .assert()
        .failure()
        .stderr(predicates::str::contains(
            "cannot create the output directory",
        ));
}

#[test]
fn paper_reports_its_progress_without_a_terminal_unless_quiet() {
    let dir = tempfile::tempdir().unwrap();
    // the first report at once, so that the test does not depend on the machine's speed
    let out = rotorid()
        .env("ROTORID_PROGRESS_AFTER_S", "0")
        .args(["paper", "--duration", "0.3", "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    let done: Vec<(u64, u64)> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("paper: "))
        .map(|l| {
            let inner = &l[l.find('(').unwrap() + 1..l.find(" steps)").unwrap()];
            let (a, b) = inner.split_once(" of ").unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    assert!(!done.is_empty(), "no progress line: {stderr}");
    assert!(done.windows(2).all(|w| w[0].0 < w[1].0), "{stderr}");
    let (last, total) = *done.last().unwrap();
    assert_eq!(last, total, "{stderr}");
    // the summary still goes to stdout
    assert!(!out.stdout.is_empty());
}
