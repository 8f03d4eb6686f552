//! The response CSV reader (and the estimates reader) on arbitrary bytes: no panic, no
//! hang; every error names the input and a line at least 1; rows come with strictly
//! increasing line numbers and finite values.

#![no_main]

use std::io::Read as _;

use libfuzzer_sys::fuzz_target;
use rotorid_fuzz::estimates_csv::EstimatesReader;
use rotorid_fuzz::lines::LineReader;
use rotorid_fuzz::response_csv::ResponseReader;

fuzz_target!(|data: &[u8]| {
    // the line reader alone, with a small cap and buffer: it hands out exactly the
    // input (or stops at a line over the cap), whatever the line ends
    let mut lines = LineReader::with_cap(data, 64);
    let (mut out, mut buf) = (Vec::new(), [0u8; 7]);
    loop {
        match lines.read(&mut buf) {
            Ok(0) => {
                assert_eq!(out, data);
                break;
            }
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(e) => {
                assert!(e.to_string().contains("is longer than 64 bytes"), "{e}");
                break;
            }
        }
    }
    match ResponseReader::new("f.csv", data) {
        Ok(mut r) => {
            let mut last_line = 1;
            loop {
                match r.next_row() {
                    Ok(Some(row)) => {
                        assert!(row.line > last_line, "line {} after {last_line}", row.line);
                        last_line = row.line;
                        assert!(row.t.is_finite() && row.x.is_finite() && row.z.is_finite());
                    }
                    Ok(None) => break,
                    Err(e) => {
                        check_error(&e);
                        break;
                    }
                }
            }
        }
        Err(e) => check_error(&e),
    }
    if let Ok(mut r) = EstimatesReader::new("e.csv", data) {
        while let Ok(Some(row)) = r.next_row() {
            assert!(row.t.is_finite());
        }
    }
});

fn check_error(e: &rotorid_fuzz::csv_error::CsvError) {
    assert!(e.line.is_none_or(|l| l >= 1));
    let text = e.to_string();
    assert!(text.starts_with("f.csv"), "{text}");
    // messages quote short prefixes: bounded whatever the input
    assert!(text.len() < 2000, "a message of {} bytes", text.len());
}
