//! Records in every format rotorid reads: the same record written by each format's
//! reference tool (NPZ, Parquet, MAT level 5 and v7.3, TDMS, UFF 58b: the fixtures of
//! crates/rotorid-io) and by `rotorid simulate --out` (Parquet, MAT, NPZ) identifies bit
//! for bit like its CSV; `--columns` picks channels by other names; `inspect` lists a
//! file's channels; a raw acquisition (probe volts, keyphasor, slow roll) is conditioned
//! and identified within its standard errors.

use std::path::Path;

use serde_json::Value;

use crate::common::{data, first_four_columns, identify_outputs, rotorid};

fn run(args: &[&str]) -> (String, String) {
    let out = rotorid().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "rotorid {args:?}: {stderr}");
    (String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

fn summary(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

const METHODS: [&str; 3] = ["algebraic", "modulating", "refine"];

/// `identify REC --scenario table1 --method METHOD [--columns COLUMNS]` into `dir`: the
/// estimates CSV's bytes and the summary with its "input" (the file's name) nulled.
fn identify(dir: &Path, rec: &str, method: &str, columns: Option<&str>) -> (Vec<u8>, Value) {
    let args = match columns {
        Some(c) => vec!["--columns", c],
        None => vec![],
    };
    identify_outputs(dir, rec, "table1", method, &args)
}

/// Asserts that `rec` identifies with every method exactly as `reference` did.
fn identifies_like(dir: &Path, rec: &str, columns: Option<&str>, reference: &[(Vec<u8>, Value)]) {
    for (method, (e0, s0)) in METHODS.iter().zip(reference) {
        let (est, s) = identify(dir, rec, method, columns);
        assert!(
            &est == e0,
            "{rec} {method}: the estimates differ from the CSV's"
        );
        assert_eq!(&s, s0, "{rec} {method}: the summary differs from the CSV's");
    }
}

/// The formats' acceptance test: one record (crates/rotorid-io/fixtures/ident.csv, made by
/// `rotorid simulate`) written by each ecosystem's reference tool (fixtures/make.py:
/// numpy, pyarrow, scipy.io.savemat, h5py as MATLAB -v7.3, npTDMS, pyuff 58b) identifies
/// bit for bit like the CSV with every method.
#[test]
fn every_reference_tools_file_identifies_bit_for_bit_like_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = |n: &str| format!("{}/../rotorid-io/fixtures/{n}", env!("CARGO_MANIFEST_DIR"));
    let reference: Vec<_> = METHODS
        .iter()
        .map(|m| identify(dir.path(), &fixture("ident.csv"), m, None))
        .collect();
    for (file, columns) in [
        ("ident.npz", None),
        ("ident.parquet", None),
        ("ident_v5.mat", None),
        // rec.t, rec.x, ... found by their short names
        ("ident_struct_v5_compressed.mat", None),
        ("ident_v73.mat", None),
        // rotor/t, rotor/x, ...: time from the t channel, not from the waveform axis
        // (wf_start_offset 0.25 s) that x, z, phi, ... carry
        ("ident.tdms", None),
        (
            "ident.tdms",
            Some("rotor/t,rotor/x,rotor/z,rotor/phi,rotor/phi_dot,rotor/phi_ddot"),
        ),
        // a dataset per channel, t among them (record 7's abscissa, E13.5 text, starts at
        // 0.25 s)
        ("ident_58b.uff", None),
    ] {
        identifies_like(dir.path(), &fixture(file), columns, &reference);
    }
}

/// Our own writers (`simulate --out` Parquet, MAT, NPZ) keep a record bit for bit too.
#[test]
fn every_format_rotorid_writes_identifies_bit_for_bit_like_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let mut reference = Vec::new();
    for ext in ["csv", "parquet", "mat", "npz"] {
        let rec = dir.path().join(format!("r.{ext}"));
        let rec = rec.to_str().unwrap();
        run(&[
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.5",
            "--snr-db",
            "40",
            "--seed",
            "5",
            "--out",
            rec,
            "-q",
        ]);
        if ext == "csv" {
            reference = METHODS
                .iter()
                .map(|m| identify(dir.path(), rec, m, None))
                .collect();
        } else {
            identifies_like(dir.path(), rec, None, &reference);
        }
    }
}

#[test]
fn estimates_as_parquet_hold_the_csv_values_and_nulls_where_it_is_empty() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_string_lossy().into_owned();
    let rec = p("r.csv");
    run(&[
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "0.3",
        "--snr-db",
        "40",
        "--out",
        &rec,
        "-q",
    ]);
    for method in ["algebraic", "refine"] {
        let (csv, pq) = (
            p(&format!("e_{method}.csv")),
            p(&format!("e_{method}.parquet")),
        );
        for out in [&csv, &pq] {
            let mut args = vec![
                "identify",
                &rec,
                "--scenario",
                "table1",
                "--method",
                method,
                "--out",
                out,
                "-q",
            ];
            if method == "algebraic" {
                args.extend(["--every", "7"]);
            }
            run(&args);
        }
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let expected: Vec<Vec<Option<f64>>> = lines
            .map(|l| l.split(',').map(|f| f.parse().ok()).collect())
            .collect();
        let reader = SerializedFileReader::new(std::fs::File::open(&pq).unwrap()).unwrap();
        let mut got = Vec::new();
        for row in reader.get_row_iter(None).unwrap() {
            let row = row.unwrap();
            let mut values = Vec::new();
            for (k, (name, field)) in row.get_column_iter().enumerate() {
                assert_eq!(name, header[k], "{method}: column {k}");
                values.push(match field {
                    Field::Double(v) => Some(*v),
                    Field::Null => None,
                    other => panic!("{method}: {name} holds {other:?}"),
                });
            }
            got.push(values);
        }
        assert!(
            expected.len() > 1 || method == "refine",
            "{method}: {} rows",
            expected.len()
        );
        assert_eq!(got.len(), expected.len(), "{method}: rows");
        for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
            let bits =
                |v: &[Option<f64>]| v.iter().map(|x| x.map(f64::to_bits)).collect::<Vec<_>>();
            assert_eq!(bits(g), bits(e), "{method}: row {i}");
        }
        if method == "algebraic" {
            assert!(
                expected[0][1].is_none(),
                "the first instant is withheld (a null)"
            );
        }
    }
}

#[test]
fn printing_into_a_closed_pipe_ends_quietly() {
    // `rotorid inspect FILE | head -1`: head has gone when rotorid writes (the pipe's read
    // end is closed before rotorid starts, so the write surely fails with EPIPE); the run
    // ends with success and nothing on stderr, and what it writes to files is written
    let fixture = format!(
        "{}/../rotorid-io/fixtures/ident.parquet",
        env!("CARGO_MANIFEST_DIR")
    );
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("balance.json");
    let json_arg = json.to_str().unwrap();
    let identified = data("identified_table1.json");
    let runs: [&[&str]; 2] = [
        &["inspect", &fixture],
        &[
            "balance",
            &identified,
            "--radius",
            "0.15",
            "--rpm",
            "3000",
            "--out",
            json_arg,
        ],
    ];
    for args in runs {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin!("rotorid"))
            .args(args)
            .stdout(writer)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {:?}: {stderr}", out.status);
        assert!(stderr.is_empty(), "{args:?}: nothing on stderr: {stderr}");
    }
    assert!(
        summary(&json)["mass_kg"].is_number(),
        "balance.json written"
    );
}

#[test]
fn columns_pick_channels_by_other_names_and_inspect_lists_them() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("r.csv");
    let s = crate::common::simulate(&["--scenario", "table1", "--duration", "0.2"]);
    // the same record with other column names and x, z in micrometres
    let mut text = String::from("time [s],probe x [um],probe z [um]\n");
    for line in s.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        text.push_str(&format!("{:?},{:?},{:?}\n", f[0], f[1] * 1e6, f[2] * 1e6));
    }
    std::fs::write(&csv, text).unwrap();
    let (listing, _) = run(&["inspect", csv.to_str().unwrap()]);
    assert!(listing.contains("3 channels"), "{listing}");
    assert!(
        listing.contains("probe x") && listing.contains("um"),
        "{listing}"
    );
    assert!(
        listing.contains("10000.000000"),
        "the sample rate: {listing}"
    );
    let est = dir.path().join("e.csv");
    let (_, stderr) = run(&[
        "identify",
        csv.to_str().unwrap(),
        "--scenario",
        "table1",
        "--method",
        "modulating",
        "--columns",
        "time,probe x,probe z",
        "--out",
        est.to_str().unwrap(),
    ]);
    assert!(stderr.contains("converted to m"), "{stderr}");
    assert!(stderr.contains("error"), "{stderr}");
    // a channel that is not there is named with what the file has
    let out = rotorid()
        .args([
            "identify",
            csv.to_str().unwrap(),
            "--scenario",
            "table1",
            "--columns",
        ])
        .args(["t,x,z", "--out", est.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("no channel \"x\" for x; the file has: time, probe x, probe z"),
        "{err}"
    );
}

#[test]
fn a_raw_acquisition_is_conditioned_and_identified() {
    let dir = tempfile::tempdir().unwrap();
    let rig = dir.path().join("rig.toml");
    std::fs::copy(data("rig.toml"), &rig).unwrap();
    let raw = dir.path().join("rig_raw.csv");
    let slow = dir.path().join("rig_slowroll.csv");
    run(&[
        "simulate",
        "--scenario",
        rig.to_str().unwrap(),
        "--raw",
        "--out",
        raw.to_str().unwrap(),
        "--slow-roll-out",
        slow.to_str().unwrap(),
        "-q",
    ]);
    let header = std::fs::read_to_string(&raw).unwrap();
    assert!(
        header.starts_with("t,probe_L,probe_R,kp\n"),
        "{}",
        &header[..40]
    );
    // conditioned: a response CSV, x and z of micrometres
    let resp = dir.path().join("resp.csv");
    run(&[
        "condition",
        raw.to_str().unwrap(),
        "--scenario",
        rig.to_str().unwrap(),
        "--out",
        resp.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&resp).unwrap();
    assert!(text.starts_with("t,x,z,phi,phi_dot,phi_ddot\n"));
    let peak = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!((5e-6..3e-5).contains(&peak), "peak x {peak:e} m");
    // the conditioned orbit with its keyphasor dots, drawn from the raw record and from
    // the conditioned CSV alike
    let orbits: Vec<Vec<(f64, f64)>> = [&raw, &resp]
        .iter()
        .enumerate()
        .map(|(i, input)| {
            let svg = dir.path().join(format!("orbit{i}.svg"));
            run(&[
                "plot",
                input.to_str().unwrap(),
                "--scenario",
                rig.to_str().unwrap(),
                "--out",
                svg.to_str().unwrap(),
            ]);
            let text = std::fs::read_to_string(&svg).unwrap();
            assert!(
                text.contains("keyphasor (phi = 0 deg)"),
                "no keyphasor legend"
            );
            circles(&text)
        })
        .collect();
    assert_eq!(orbits[0], orbits[1], "raw and conditioned CSV plot alike");
    // one dot per keyphasor event (1200 rpm for 1 s: 20), then the legend's dot; each where
    // the test finds phi passing 0 (mod 2 pi) in the conditioned CSV, x and z interpolated
    // linearly, up to the plot's map from metres to pixels (equal scales, y downwards)
    let dots = &orbits[0][..orbits[0].len() - 1];
    let rows = first_four_columns(&text);
    let tau = std::f64::consts::TAU;
    let expected: Vec<(f64, f64)> = rows
        .windows(2)
        .filter(|w| (w[1][3] / tau).floor() > (w[0][3] / tau).floor())
        .map(|w| {
            let s = (tau * (w[1][3] / tau).floor() - w[0][3]) / (w[1][3] - w[0][3]);
            (
                w[0][1] + s * (w[1][1] - w[0][1]),
                w[0][2] + s * (w[1][2] - w[0][2]),
            )
        })
        .collect();
    assert!(
        (19..=21).contains(&expected.len()),
        "{} events",
        expected.len()
    );
    assert_eq!(dots.len(), expected.len());
    // least squares for cx = a + k x, cy = b - k z
    let n = dots.len() as f64;
    let mean = |f: &dyn Fn(usize) -> f64| (0..dots.len()).map(f).sum::<f64>() / n;
    let (mx, mz) = (mean(&|i| expected[i].0), mean(&|i| expected[i].1));
    let (mcx, mcy) = (mean(&|i| dots[i].0), mean(&|i| dots[i].1));
    let num = mean(&|i| {
        (expected[i].0 - mx) * (dots[i].0 - mcx) - (expected[i].1 - mz) * (dots[i].1 - mcy)
    });
    let den = mean(&|i| (expected[i].0 - mx).powi(2) + (expected[i].1 - mz).powi(2));
    let k = num / den;
    assert!(k > 0.0, "{k} px/m");
    for (d, e) in dots.iter().zip(&expected) {
        let (cx, cy) = (mcx + k * (e.0 - mx), mcy - k * (e.1 - mz));
        let off = (d.0 - cx).hypot(d.1 - cy);
        assert!(
            off < 1.5,
            "dot {d:?} is {off} px from where phi = 0 ({cx}, {cy})"
        );
    }

    let sum = dir.path().join("s.json");
    run(&[
        "identify",
        raw.to_str().unwrap(),
        "--scenario",
        rig.to_str().unwrap(),
        "--method",
        "refine",
        "--out",
        dir.path().join("e.csv").to_str().unwrap(),
        "--summary",
        sum.to_str().unwrap(),
        "-q",
    ]);
    let s = summary(&sum);
    assert!(
        s["diagnostics"].as_array().unwrap().is_empty(),
        "{}",
        s["diagnostics"]
    );
    for p in s["parameters"].as_array().unwrap() {
        let (v, t, e) = (
            p["value"].as_f64().unwrap(),
            p["truth"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        );
        assert!(
            (v - t).abs() < 4.0 * e,
            "{}: {v} vs {t} +- {e}",
            p["parameter"]
        );
    }
}

/// The centres (cx, cy) of the `<circle>` elements of an SVG, in order.
fn circles(svg: &str) -> Vec<(f64, f64)> {
    let attr = |el: &str, name: &str| -> f64 {
        let start = el.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        let end = start + el[start..].find('"').unwrap();
        el[start..end].parse().unwrap()
    };
    svg.split("<circle")
        .skip(1)
        .map(|el| (attr(el, "cx"), attr(el, "cy")))
        .collect()
}

#[test]
fn a_parquet_record_is_identified_as_it_is_read() {
    // A Parquet file is read a block of rows at a time while the rows before are
    // identified (rotorid_io::stream): a null at row 40000 of x stops the run there, after
    // the estimates of the rows before it were written (read whole, the file would give
    // none), and the error names the column and the row.
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_owned();
    run(&[
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "5",
        "--out",
        &p("r.csv"),
        "-q",
    ]);
    let table = rotorid_io::read_table(p("r.csv")).unwrap();
    let null_at = 40_000;
    let x: Vec<Option<f64>> = table
        .channel("x")
        .unwrap()
        .data
        .iter()
        .enumerate()
        .map(|(i, &v)| (i != null_at).then_some(v))
        .collect();
    let cols: Vec<(&str, rotorid_io::write::ParquetColumn<'_>)> = table
        .channels
        .iter()
        .map(|c| {
            let col = if c.name == "x" {
                rotorid_io::write::ParquetColumn::Optional(&x)
            } else {
                rotorid_io::write::ParquetColumn::Required(&c.data)
            };
            (c.name.as_str(), col)
        })
        .collect();
    let bytes = rotorid_io::write::parquet_columns_bytes("r.parquet", &cols).unwrap();
    std::fs::write(p("r.parquet"), bytes).unwrap();
    let out = rotorid()
        .args([
            "identify",
            &p("r.parquet"),
            "--scenario",
            "table1",
            "--out",
            &p("e.csv"),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("r.parquet, channel \"x\"") && stderr.contains("row 40000 of row group 0"),
        "{stderr}"
    );
    let written = std::fs::read_to_string(p("e.csv")).unwrap();
    // (a header, then a row per sample from the grid's head on)
    let rows = written.lines().count().saturating_sub(1);
    assert!(
        rows > 10_000 && rows < null_at,
        "{rows} estimate rows written before the null"
    );
}

#[test]
fn inspect_of_a_streamed_file_lists_what_the_whole_file_holds() {
    // TDMS and Parquet files are inspected a block of rows at a time (channels of one
    // length together): each line's samples, unit, min and max are those of the channel
    // read whole by rotorid_io, computed here by a plain fold
    let fixtures = format!("{}/../rotorid-io/fixtures", env!("CARGO_MANIFEST_DIR"));
    // and a file of several blocks, its extremes and a NaN in different ones
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join("long.parquet");
    let n = 200_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let x: Vec<f64> = (0..n)
        .map(|i| match i {
            10 => -7.5,
            150_000 => f64::NAN,
            199_990 => 9.25,
            _ => (i as f64 * 0.01).sin(),
        })
        .collect();
    use rotorid_io::write::ParquetColumn::Required;
    let bytes = rotorid_io::write::parquet_columns_bytes(
        "long.parquet",
        &[("t", Required(&t)), ("x", Required(&x))],
    )
    .unwrap();
    std::fs::write(&long, bytes).unwrap();
    let mut lines_checked = 0;
    for name in [
        "ident.parquet",
        "rec.parquet",
        "ident.tdms",
        "rec.tdms",
        "interleaved.tdms",
        "long",
    ] {
        let path = match name {
            "long" => long.to_str().unwrap().to_owned(),
            _ => format!("{fixtures}/{name}"),
        };
        let table = rotorid_io::read_table(&path).unwrap();
        let (listing, _) = run(&["inspect", &path]);
        let rows: Vec<&str> = listing.lines().skip(2).collect();
        assert_eq!(rows.len(), table.channels.len(), "{name}: {listing}");
        for (row, c) in rows.iter().zip(&table.channels) {
            // the name (it may hold blanks), then samples, unit, rate, min, max
            let rest = row.trim_start().strip_prefix(c.name.as_str());
            assert!(rest.is_some(), "{name}: {row} is not {}", c.name);
            let f: Vec<&str> = std::iter::once(c.name.as_str())
                .chain(rest.unwrap_or_default().split_whitespace())
                .collect();
            let (lo, hi) = c
                .data
                .iter()
                .filter(|v| !v.is_nan())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let shown = |v: f64| {
                if v.is_finite() {
                    format!("{v:.6e}")
                } else {
                    "-".to_owned()
                }
            };
            let want = [
                c.name.clone(),
                c.data.len().to_string(),
                c.unit.clone().unwrap_or("-".into()),
            ];
            assert_eq!(f[..3], want, "{name}: {row}");
            assert_eq!(f[4..6], [shown(lo), shown(hi)], "{name}: {row}");
            let nan = c.data.iter().filter(|v| v.is_nan()).count();
            assert_eq!(
                row.contains(&format!("({nan} NaN)")),
                nan > 0,
                "{name}: {row}"
            );
            lines_checked += 1;
        }
    }
    assert!(lines_checked >= 20, "{lines_checked}");
}

#[test]
fn inspect_names_the_first_bad_channel_in_file_order_whichever_thread_reads_it() {
    // inspect reads a streamed file's channels on two threads, each taking the next: of b
    // (a null late) and d (a null early), b is named, as a read one by one would name it
    use rotorid_io::write::ParquetColumn::{Optional, Required};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two_bad.parquet");
    let ok: Vec<f64> = (0..100_000).map(f64::from).collect();
    let hole = |at: usize| -> Vec<Option<f64>> {
        (0..100_000)
            .map(|i| (i != at).then_some(i as f64))
            .collect()
    };
    let (b, d) = (hole(99_000), hole(1));
    let cols = [
        ("a", Required(&ok)),
        ("b", Optional(&b)),
        ("c", Required(&ok)),
        ("d", Optional(&d)),
    ];
    let bytes = rotorid_io::write::parquet_columns_bytes("two_bad.parquet", &cols).unwrap();
    std::fs::write(&path, bytes).unwrap();
    for _ in 0..10 {
        let out = rotorid()
            .args(["inspect", path.to_str().unwrap()])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains("channel \"b\"") && stderr.contains("row 99000 of row group 0"),
            "{stderr}"
        );
    }
}

#[test]
fn a_panic_of_the_parquet_crate_is_an_error_without_a_panic_message() {
    // Found by fuzzing read_parquet: a BYTE_STREAM_SPLIT page shorter than its value count,
    // on which the parquet crate (59.3.2) indexes out of bounds. rotorid reports an error
    // naming the file, the column, its row group and the column chunk's offset (1569: the
    // page header there begins the 575 bytes the footer gives it, and the next header
    // follows them), exits 1, and prints no "panicked" line or backtrace.
    let fixture = format!(
        "{}/../rotorid-io/fixtures/panic_bss.parquet",
        env!("CARGO_MANIFEST_DIR")
    );
    for command in ["inspect", "identify"] {
        let mut cmd = rotorid();
        cmd.env("RUST_BACKTRACE", "1").args([command, &fixture]);
        if command == "identify" {
            cmd.args(["--scenario", "table1", "--out", "-"]);
        }
        let out = cmd.output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command}: {stderr}");
        assert!(
            stderr.contains(
                "panic_bss.parquet, channel \"z\": the Parquet column chunk of row group 0 \
                 (575 bytes) at byte 1569 is malformed: the parquet reader failed on it"
            ),
            "{command}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{command}: {stderr}");
    }
}

#[test]
fn an_error_says_its_cause_once() {
    // The readers' errors carry their cause in their message and as their source: printed
    // once, not once per link of the chain.
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.tdms");
    let out = rotorid()
        .args(["inspect", missing.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("missing.tdms: "), "{stderr}");
    assert_eq!(stderr.matches("os error 2").count(), 1, "{stderr}");
}

#[test]
fn an_interrupted_tdms_recording_is_read_up_to_its_last_whole_chunk_with_a_note() {
    // npTDMS's rec.tdms as a writer leaves it when the recording stops mid-segment: the last
    // segment's next offset all ones, its raw data cut short
    let mut f = std::fs::read(format!(
        "{}/../rotorid-io/fixtures/rec.tdms",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let mut seg = 0;
    loop {
        let next = u64::from_le_bytes(f[seg + 12..seg + 20].try_into().unwrap()) as usize;
        if seg + 28 + next == f.len() {
            break;
        }
        seg += 28 + next;
    }
    f[seg + 12..seg + 20].copy_from_slice(&u64::MAX.to_le_bytes());
    f.truncate(f.len() - 3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.tdms");
    std::fs::write(&path, &f).unwrap();
    let (out, err) = run(&["inspect", path.to_str().unwrap()]);
    assert!(out.contains("channel"), "{out}");
    assert!(
        err.contains("cut.tdms: the segment whose raw data starts at byte")
            && err.contains("was left open by its writer (an interrupted recording)"),
        "{err}"
    );
}
