//! A rig's raw acquisition as NI-DAQmx logs it to TDMS (the probes as 16-bit codes with the
//! device's polynomial scale, as "DAQmx raw data"; the time and keyphasor columns as
//! doubles in the same raw buffer) identifies bit for bit like the same record as CSV.
//!
//! The record is `rotorid simulate --raw` of tests/data/rig.toml: its probe volts are
//! quantised to 16 bits over -24..0 V, v = -24 + k q with q = 24 / 2^16 V, all exact in
//! binary. Written as codes c = k - 32768 with the scale v = -12 + q c (what DAQmx stores
//! for a +-12 V range around -12 V), the file's volts are the CSV's exactly, so the
//! conditioning and every method give the same bits; the file is laid out as npTDMS's
//! DAQmx tests lay theirs out (crates/rotorid-io/src/tdms/daqmx.rs).

use std::path::Path;

use crate::common::{data, first_four_columns, identify_outputs, rotorid};

fn run(args: &[&str]) {
    let out = rotorid().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "rotorid {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Little-endian bytes of a u32-length-prefixed string.
fn text(v: &str) -> Vec<u8> {
    let mut b = (v.len() as u32).to_le_bytes().to_vec();
    b.extend(v.as_bytes());
    b
}

/// A property: name, TDMS type code, value bytes.
fn prop(name: &str, ty: u32, value: Vec<u8>) -> Vec<u8> {
    let mut b = text(name);
    b.extend(ty.to_le_bytes());
    b.extend(value);
    b
}

/// The metadata of channel `/'rig'/'name'` with a DAQmx format-changing index: channel data
/// type `data_type` (0xFFFFFFFF: DAQmx raw), `count` values per chunk, one scaler of DAQmx
/// type `scaler_type` at `offset` in raw buffer 0 of `width` bytes, and `props`.
fn channel(
    name: &str,
    data_type: u32,
    count: u64,
    scaler_type: u32,
    offset: u32,
    width: u32,
    props: &[Vec<u8>],
) -> Vec<u8> {
    let mut b = text(&format!("/'rig'/'{name}'"));
    b.extend(0x1269u32.to_le_bytes());
    b.extend(data_type.to_le_bytes());
    b.extend(1u32.to_le_bytes());
    b.extend(count.to_le_bytes());
    b.extend(1u32.to_le_bytes()); // one scaler: type, buffer, byte offset, bitmap, scale id
    for v in [scaler_type, 0, offset, 0, 0] {
        b.extend(v.to_le_bytes());
    }
    b.extend(1u32.to_le_bytes()); // one raw buffer
    b.extend(width.to_le_bytes());
    b.extend((props.len() as u32).to_le_bytes());
    for p in props {
        b.extend(p);
    }
    b
}

/// The raw CSV `t,probe_L,probe_R,kp` as a DAQmx TDMS file at `out`, in segments of at most
/// `per` rows, each with its metadata (the last one's value count is its own). With `dt`,
/// the time is not a channel but the waveform properties of the others (`wf_increment`
/// `dt`, `wf_start_offset` 0), as a logging task writes them.
fn write_daqmx(csv: &str, out: &Path, per: usize, dt: Option<f64>) {
    let rows = first_four_columns(csv);
    let q = 24.0 / 65536.0;
    let code = |v: f64| -> i16 {
        let k = (v + 24.0) / q;
        assert_eq!(k, k.round(), "{v} V is not on the 16-bit grid");
        (k - 32768.0) as i16
    };
    // the DAQmx scale of the probes: scale 0 the codes, scale 1 the device polynomial
    let scale = |c: Vec<u8>| {
        vec![
            prop("NI_Scaling_Status", 0x20, text("unscaled")),
            prop("NI_Number_Of_Scales", 7, 2u32.to_le_bytes().to_vec()),
            prop("NI_Scale[1]_Scale_Type", 0x20, text("Polynomial")),
            prop(
                "NI_Scale[1]_Polynomial_Coefficients_Size",
                3,
                2i32.to_le_bytes().to_vec(),
            ),
            prop(
                "NI_Scale[1]_Polynomial_Coefficients[0]",
                10,
                (-12.0f64).to_le_bytes().to_vec(),
            ),
            prop("NI_Scale[1]_Polynomial_Coefficients[1]", 10, c),
            prop(
                "NI_Scale[1]_Polynomial_Input_Source",
                7,
                0u32.to_le_bytes().to_vec(),
            ),
            prop("unit_string", 0x20, text("Volts")),
        ]
    };
    let waveform = |mut props: Vec<Vec<u8>>| {
        if let Some(dt) = dt {
            props.push(prop("wf_increment", 10, dt.to_le_bytes().to_vec()));
            props.push(prop("wf_start_offset", 10, 0f64.to_le_bytes().to_vec()));
        }
        props
    };
    let t_bytes = if dt.is_some() { 0 } else { 8 };
    let width = t_bytes + 2 + 2 + 8;
    let mut file = Vec::new();
    for (s, chunk) in rows.chunks(per).enumerate() {
        let n = chunk.len() as u64;
        let probe = || waveform(scale(q.to_le_bytes().to_vec()));
        let mut objects = Vec::new();
        if dt.is_none() {
            objects.push(channel("t", 10, n, 9, 0, width, &[]));
        }
        objects.push(channel("probe_L", u32::MAX, n, 3, t_bytes, width, &probe()));
        objects.push(channel(
            "probe_R",
            u32::MAX,
            n,
            3,
            t_bytes + 2,
            width,
            &probe(),
        ));
        objects.push(channel(
            "kp",
            10,
            n,
            9,
            t_bytes + 4,
            width,
            &waveform(vec![]),
        ));
        // the root and the group (no data, no properties), then the channels
        let mut meta = (2 + objects.len() as u32).to_le_bytes().to_vec();
        for path in ["/", "/'rig'"] {
            meta.extend(text(path));
            meta.extend(u32::MAX.to_le_bytes());
            meta.extend(0u32.to_le_bytes());
        }
        for o in &objects {
            meta.extend(o);
        }
        let mut raw = Vec::new();
        for r in chunk {
            if dt.is_none() {
                raw.extend(r[0].to_le_bytes());
            }
            raw.extend(code(r[1]).to_le_bytes());
            raw.extend(code(r[2]).to_le_bytes());
            raw.extend(r[3].to_le_bytes());
        }
        // kTocMetaData, kTocRawData, kTocNewObjList (the first segment), kTocDAQmxRawData
        let toc: u32 = 0x02 | 0x08 | 0x80 | if s == 0 { 0x04 } else { 0 };
        file.extend(b"TDSm");
        file.extend(toc.to_le_bytes());
        file.extend(4713u32.to_le_bytes());
        file.extend(((meta.len() + raw.len()) as u64).to_le_bytes());
        file.extend((meta.len() as u64).to_le_bytes());
        file.extend(meta);
        file.extend(raw);
    }
    std::fs::write(out, file).unwrap();
}

#[test]
fn a_daqmx_logged_rig_identifies_bit_for_bit_like_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    std::fs::copy(data("rig.toml"), p("rig.toml")).unwrap();
    let rig = p("rig.toml");
    let rig = rig.to_str().unwrap();
    run(&[
        "simulate",
        "--scenario",
        rig,
        "--duration",
        "0.5",
        "--raw",
        "--out",
        p("raw.csv").to_str().unwrap(),
        "--slow-roll-out",
        p("rig_slowroll.csv").to_str().unwrap(),
        "-q",
    ]);
    let csv = std::fs::read_to_string(p("raw.csv")).unwrap();
    // segments of 4096 rows, as a logging task writes a buffer at a time; the time as a
    // channel, and as the channels' waveform timing (25.6 kHz)
    write_daqmx(&csv, &p("raw.tdms"), 4096, None);
    write_daqmx(&csv, &p("raw_wf.tdms"), 4096, Some(3.90625e-5));
    let outputs = |input: &str, method: &str| {
        identify_outputs(dir.path(), p(input).to_str().unwrap(), rig, method, &[])
    };
    // (the algebraic method on this steady record gives estimates the model rejects, m < 0:
    // reported with warnings, and the conditioning's second pass keeps the nominal values)
    for method in ["algebraic", "refine"] {
        let (csv_est, csv_sum) = outputs("raw.csv", method);
        assert!(csv_est.len() > 100, "{method}: estimates written");
        for tdms in ["raw.tdms", "raw_wf.tdms"] {
            let (tdms_est, tdms_sum) = outputs(tdms, method);
            assert!(
                csv_est == tdms_est,
                "{method}, {tdms}: the estimates differ"
            );
            assert_eq!(csv_sum, tdms_sum, "{method}, {tdms}: the summaries differ");
        }
    }
}
