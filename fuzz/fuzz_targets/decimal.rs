//! The CSV decimal fast path of rotorid-io on arbitrary bytes: whatever it takes, it reads
//! bit for bit as fast-float2's `parse_partial` reads it and consumes the same bytes (it may
//! decline anything; it must never disagree).

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((v, n)) = rotorid_io::csv::decimal::parse_prefix(data) {
        let (r, m) = fast_float2::parse_partial::<f64, _>(data)
            .expect("fast-float2 reads what the fast path takes");
        assert_eq!((v.to_bits(), n), (r.to_bits(), m), "{:?}", String::from_utf8_lossy(data));
    }
});
