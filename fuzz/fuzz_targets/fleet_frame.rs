//! The fleet frame decoder on arbitrary bytes: it may refuse them, naming the field, but
//! never panics nor allocates more than the input's size; a frame it accepts re-encodes to
//! the same bytes and makes a record (or an error), never a panic.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid_fleet::window::record_of;
use rotorid_fleet::Frame;

fuzz_target!(|data: &[u8]| {
    if let Ok(f) = Frame::decode(data) {
        assert_eq!(f.encode().expect("a decoded frame is valid"), data);
        let samples: usize = f.channels.iter().map(|c| c.data.len()).sum();
        assert!(samples * 8 <= data.len());
        let _ = record_of(&f, None);
    }
});
