//! The response CSV reader (and the estimates reader) on arbitrary bytes: no panic, no
//! hang; every error names the input and a line at least 1; rows come with strictly
//! increasing line numbers and finite values (units in the header converted). The record
//! splitter gives the `csv` crate's records and LineReader's line numbers, and the number
//! parser `str::parse`'s bits, on the same bytes.

#![no_main]

use std::io::Read as _;

use libfuzzer_sys::fuzz_target;
use rotorid_fuzz::estimates_csv::EstimatesReader;
use rotorid_fuzz::lines::LineReader;
use rotorid_fuzz::number::parse_f64;
use rotorid_fuzz::records::RecordReader;
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
    // the splitter against the csv crate behind a LineReader, as the readers were before
    let mut ours = RecordReader::with_cap(data, 64);
    let mut theirs = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(LineReader::with_cap(data, 64));
    let mut rec = csv::ByteRecord::new();
    loop {
        theirs.get_mut().mark();
        let reference = theirs.read_byte_record(&mut rec);
        match (ours.next_record(), reference) {
            (Ok(Some(r)), Ok(true)) => {
                assert_eq!(r.line(), theirs.get_ref().record_line());
                assert!(r.iter().eq(rec.iter()), "fields differ at line {}", r.line());
            }
            (Ok(None), Ok(false)) => break,
            // both refuse a line over the cap (ours may see it first: it reads ahead)
            (Err(e), _) => {
                assert!(e.error.to_string().contains("is longer than 64 bytes"));
                break;
            }
            (Ok(_), Err(e)) => panic!("only the csv crate failed: {e}"),
            (Ok(a), Ok(b)) => panic!("records differ: {} against {b}", a.is_some()),
        }
    }
    // the number parser against str::parse, on the input as one field
    if data.len() <= 64 {
        let std = std::str::from_utf8(data)
            .ok()
            .and_then(|s| s.trim().parse::<f64>().ok());
        let trimmed = data.trim_ascii();
        assert_eq!(
            parse_f64(trimmed).map(f64::to_bits),
            std.map(f64::to_bits),
            "{data:?}"
        );
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
                        if let Some(s) = row.speed {
                            assert!(s.phi.is_finite() && s.phi_dot.is_finite());
                            assert!(s.phi_ddot.is_finite());
                        }
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
