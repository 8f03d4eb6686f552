//! The npz reader of rotorid-io on arbitrary bytes: no panic, no hang, no allocation
//! beyond -rss_limit_mb; every error names the input; every channel read has a name and,
//! when it has a time axis, a positive finite increment. The same bytes go to the
//! finite-element matrices reader (an NPZ of M, K, G, C, Ka, dofs): no panic, every error
//! names the input, and what it reads has n x n entries in each matrix.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid_io::{fe_matrices, read_bytes, Format};

fuzz_target!(|data: &[u8]| {
    match read_bytes(Format::Npz, "fuzz.npz", data) {
        Ok(t) => {
            assert!(!t.channels.is_empty());
            for c in &t.channels {
                assert!(!c.name.is_empty() || Format::Npz == Format::Mat);
                if let Some(a) = c.axis {
                    assert!(a.increment > 0.0 && a.increment.is_finite(), "{a:?}");
                }
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.npz"), "{e}"),
    }
    match fe_matrices::read("fuzz.npz", data) {
        Ok(f) => {
            let n = f.n();
            assert!(n > 0);
            for a in [Some(&f.m), Some(&f.k), Some(&f.g), f.c.as_ref(), f.ka.as_ref()]
                .into_iter()
                .flatten()
            {
                assert_eq!(a.len(), n * n);
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.npz"), "{e}"),
    }
});
