//! Read speed per format, in input MB/s, on files of 2^20 f64 samples (one channel) made by
//! the reference tools:
//!
//! ```text
//! python3 crates/rotorid-io/fixtures/make.py --bench /tmp/rotorid-io-bench   # numpy, scipy, h5py, npTDMS, pyuff, pyarrow
//! ROTORID_IO_BENCH_DIR=/tmp/rotorid-io-bench cargo bench -p rotorid-io --bench read
//! ```
//!
//! Without `ROTORID_IO_BENCH_DIR` the bench says so and measures nothing.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rotorid_io::{read_bytes, Format};

const FILES: &[(&str, Format)] = &[
    ("x.npy", Format::Npy),
    ("x.npz", Format::Npz),
    ("x.mat", Format::Mat),
    ("x_compressed.mat", Format::Mat),
    ("x_v73.mat", Format::Mat),
    ("x.tdms", Format::Tdms),
    ("x_10seg.tdms", Format::Tdms),
    ("x.uff", Format::Uff58),
    ("x_ascii.uff", Format::Uff58),
    ("x.parquet", Format::Parquet),
];

fn read(c: &mut Criterion) {
    let Ok(dir) = std::env::var("ROTORID_IO_BENCH_DIR") else {
        eprintln!(
            "ROTORID_IO_BENCH_DIR is not set: make the files with fixtures/make.py --bench DIR"
        );
        return;
    };
    let mut g = c.benchmark_group("read");
    g.sample_size(10);
    for &(name, format) in FILES {
        let path = std::path::Path::new(&dir).join(name);
        let Ok(bytes) = std::fs::read(&path) else {
            eprintln!("{}: missing, skipped", path.display());
            continue;
        };
        let t = read_bytes(format, name, &bytes).expect("bench file reads");
        assert_eq!(t.channels[0].data.len(), 1 << 20, "{name}");
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| read_bytes(format, name, &bytes).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, read);
criterion_main!(benches);
