//! The readers that stream a block of rows at a time (rotorid_io::stream: Parquet, TDMS) on
//! arbitrary bytes, against the same bytes read whole: the first byte picks the format
//! (even: Parquet, odd: TDMS) and the second the block size; the rest is the file. No
//! panic, no hang, no allocation beyond -rss_limit_mb; every error names the file; a file
//! the whole-file reader refuses is refused, and a file read both ways gives the same
//! channels (names, units, lengths, axes) and the same samples, bit for bit.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid_io::{open_blocks, read_bytes, Format};

fuzz_target!(|data: &[u8]| {
    let [pick, size, file @ ..] = data else {
        return;
    };
    let (format, ext) = if pick % 2 == 0 {
        (Format::Parquet, "parquet")
    } else {
        (Format::Tdms, "tdms")
    };
    let path = std::env::temp_dir().join(format!("rotorid-fuzz-{}.{ext}", std::process::id()));
    std::fs::write(&path, file).unwrap();
    let name = path.display().to_string();
    let whole = read_bytes(format, &name, file);
    let mut blocks = match open_blocks(&path) {
        Ok(Some(b)) => b,
        Ok(None) => return, // (a format that does not stream yet)
        Err(e) => {
            assert!(e.to_string().starts_with(&name), "{e}");
            return;
        }
    };
    // every channel, those of one length together (a reader gives rows of channels of
    // one length)
    let lens: Vec<usize> = blocks.channels().iter().map(|c| c.len).collect();
    let mut got: Vec<Vec<f64>> = lens.iter().map(|_| Vec::new()).collect();
    let block = usize::from(*size) * 97 + 1;
    let mut groups = lens.clone();
    groups.sort_unstable();
    groups.dedup();
    let streamed = groups.into_iter().try_for_each(|len| {
        let wanted: Vec<usize> = (0..lens.len()).filter(|&k| lens[k] == len).collect();
        let mut out = vec![Vec::new(); wanted.len()];
        loop {
            let n = blocks.next_rows(&wanted, block, &mut out)?;
            assert!(n <= block && out.iter().all(|o| o.len() == out[0].len()));
            if n == 0 {
                break;
            }
        }
        for (k, o) in wanted.into_iter().zip(out) {
            got[k] = o;
        }
        Ok(())
    });
    match (whole, streamed) {
        (Ok(t), Ok::<(), rotorid_io::ReadError>(())) => {
            assert_eq!(t.channels.len(), blocks.channels().len());
            for ((c, info), d) in t.channels.iter().zip(blocks.channels()).zip(&got) {
                assert_eq!(
                    (&c.name, &c.unit, c.axis, c.data.len()),
                    (&info.name, &info.unit, info.axis, info.len)
                );
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(d), bits(&c.data), "{}", c.name);
            }
            assert_eq!(t.notes, blocks.notes());
        }
        (Err(e), Ok(())) => panic!("refused whole ({e}), read a block at a time"),
        (_, Err(e)) => assert!(e.to_string().starts_with(&name), "{e}"),
    }
});
