//! The TDMS reader of rotorid-io streamed a block of rows at a time (`tdms::open_blocks`)
//! on arbitrary bytes, against the whole-file reader: no panic, no hang; refused whenever
//! the whole-file reader refuses (every error naming the input), and otherwise the same
//! channels (names, units, lengths, time axes), notes and values bit for bit.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid_io::{read_bytes, Format, RowBlocks};

fuzz_target!(|data: &[u8]| {
    // open_blocks reads a file: the input, in a file of this process's own (left in the
    // temporary directory when the run ends)
    let path = std::env::temp_dir().join(format!("rotorid-fuzz-{}.tdms", std::process::id()));
    std::fs::write(&path, data).unwrap();
    let whole = read_bytes(Format::Tdms, "fuzz.tdms", data);
    let streamed = rotorid_io::tdms::open_blocks("fuzz.tdms", &path).and_then(|mut b| {
        // every channel, those of one length together, 7 rows at a time
        let lens: Vec<usize> = b.channels().iter().map(|c| c.len).collect();
        let mut values = vec![Vec::new(); lens.len()];
        for (k, &len) in lens.iter().enumerate() {
            if lens[..k].contains(&len) {
                continue;
            }
            let wanted: Vec<usize> = (k..lens.len()).filter(|&j| lens[j] == len).collect();
            let mut out = vec![Vec::new(); wanted.len()];
            let mut total = 0;
            loop {
                let n = b.next_rows(&wanted, 7, &mut out)?;
                assert!(n <= 7);
                total += n;
                assert!(out.iter().all(|o| o.len() == total));
                if n == 0 {
                    break;
                }
            }
            assert_eq!(total, len);
            for (j, o) in wanted.into_iter().zip(out) {
                values[j] = o;
            }
        }
        Ok((b, values))
    });
    match (whole, streamed) {
        (Ok(t), Ok((b, values))) => {
            assert_eq!(b.notes(), t.notes.as_slice());
            assert_eq!(b.channels().len(), t.channels.len());
            for ((info, c), v) in b.channels().iter().zip(&t.channels).zip(&values) {
                assert_eq!(info.name, c.name);
                assert_eq!(info.unit, c.unit);
                assert_eq!(info.axis, c.axis);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(v), bits(&c.data), "{}", c.name);
            }
        }
        (Err(_), Err(e)) => assert!(e.to_string().starts_with("fuzz.tdms"), "{e}"),
        (Ok(_), Err(e)) => panic!("read whole, refused streamed: {e}"),
        (Err(e), Ok(_)) => panic!("refused whole ({e}), read streamed"),
    }
});
