//! Sustained machines per worker core (10 kHz, two probes, 1 s windows), broker on the same
//! machine: `cargo bench -p rotorid-fleet --bench worker`.
//!
//! For each method it measures, over the same windows:
//! - decode: `Frame::decode` of a 1 s window (160 kB);
//! - identify: `identify_frame` (record + pipeline), in this process;
//! - through the broker: one worker process (`rotorid-fleet-worker`) draining windows
//!   published beforehand to a local nats-server; time from its first result to its last.
//!
//! A machine sends one 1 s window per second, so a worker sustains 1 / (seconds per window)
//! machines; the difference between the broker and identify figures is the per-window
//! overhead (pull, publish and its acknowledgement, two KV compare-and-sets, the
//! acknowledgement). Windows: FLEET_BENCH_WINDOWS (default 30; refine a third of it).

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use common::*;
use rotorid::pipeline::{Knowledge, Method};
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::publish::{publish_frames, Rate};
use rotorid_fleet::window::{identify_frame, windows};
use rotorid_fleet::{Frame, IDENT_STREAM};

fn main() {
    let n: usize = std::env::var("FLEET_BENCH_WINDOWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    let s = scenario(rotor(0), 10.0);
    let r = response(&s, 7);
    let base = windows("bench", 0.0, 1e-4, &probes(&r), 10_000, 0).unwrap();
    let k = Knowledge::from_scenario(&s);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scenarios");
    std::fs::create_dir_all(&dir).unwrap();
    let rt = tokio::runtime::Runtime::new().unwrap();

    let bytes = base[0].encode().unwrap();
    let t = Instant::now();
    let reps = 200;
    for _ in 0..reps {
        std::hint::black_box(Frame::decode(&bytes).unwrap());
    }
    let decode = t.elapsed().as_secs_f64() / reps as f64;
    println!(
        "frame: {} bytes, decode {:.3} ms",
        bytes.len(),
        1e3 * decode
    );

    // the worker's round trips, one at a time as it does them
    {
        let server = Server::start(&tmp.path().join("js-rtt"));
        let fleet = rt
            .block_on(Fleet::connect(&server.url(), Duration::from_secs(10)))
            .unwrap();
        let ident = identify_frame(&base[0], &k, Some(s.speed), &Method::modulating()).unwrap();
        let json = bytes::Bytes::from(serde_json::to_vec(&ident).unwrap());
        let reps = 200;
        let (publish, kv) = rt.block_on(async {
            fleet.ident_stream().await.unwrap();
            let t = Instant::now();
            for i in 0..reps {
                fleet
                    .publish("rotorid.ident.rtt", &format!("rtt/{i}"), json.clone())
                    .await
                    .unwrap();
            }
            let publish = t.elapsed().as_secs_f64() / reps as f64;
            let latest = fleet.latest().await.unwrap();
            latest.put("rtt", json.clone()).await.unwrap();
            let t = Instant::now();
            for _ in 0..reps {
                let e = latest.entry("rtt").await.unwrap().unwrap();
                latest
                    .update("rtt", json.clone(), e.revision)
                    .await
                    .unwrap();
            }
            (publish, t.elapsed().as_secs_f64() / reps as f64)
        });
        println!(
            "round trips: publish a result ({} bytes) and await its ack {:.2} ms; KV \
             compare-and-set (entry + update) {:.2} ms",
            json.len(),
            1e3 * publish,
            1e3 * kv
        );
    }

    for (name, method, count) in [
        ("modulating", Method::modulating(), n),
        ("refine", Method::refine(), (n / 3).max(3)),
    ] {
        // the same 10 windows over and over, as machines b0, b1, ...
        let frames: Vec<Frame> = (0..count)
            .map(|i| {
                let mut f = base[i % base.len()].clone();
                f.machine = format!("b{}", i / base.len());
                f
            })
            .collect();
        for f in &frames {
            std::fs::write(dir.join(format!("{}.toml", f.machine)), scenario_toml(&s)).unwrap();
        }
        let t = Instant::now();
        for f in &frames {
            std::hint::black_box(identify_frame(f, &k, Some(s.speed), &method).unwrap());
        }
        let identify = t.elapsed().as_secs_f64() / count as f64;

        let server = Server::start(&tmp.path().join(format!("js-{name}")));
        let fleet = rt
            .block_on(Fleet::connect(&server.url(), Duration::from_secs(10)))
            .unwrap();
        rt.block_on(publish_frames(&fleet, &frames, Rate::Max, |_| {}))
            .unwrap();
        let worker = spawn_worker(&server.url(), "bench", name, &dir, 60.0);
        let count_now = || {
            rt.block_on(async {
                match fleet.js.get_stream(IDENT_STREAM).await {
                    Ok(mut s) => s.info().await.map(|i| i.state.messages).unwrap_or(0),
                    Err(_) => 0,
                }
            })
        };
        let mut first = None;
        let t_end = loop {
            let c = count_now();
            if c >= 1 && first.is_none() {
                first = Some((Instant::now(), c));
            }
            if c as usize >= count {
                break Instant::now();
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        let (t_first, c_first) = first.unwrap();
        let per = t_end.duration_since(t_first).as_secs_f64() / (count as u64 - c_first) as f64;
        let _ = terminate(worker);
        println!(
            "{name}: identify {:.1} ms/window ({:.1} machines per core); through the broker \
             {:.1} ms/window ({:.1} machines per worker); overhead {:.1} ms/window \
             (decode {:.2} ms); {count} windows",
            1e3 * identify,
            1.0 / identify,
            1e3 * per,
            1.0 / per,
            1e3 * (per - identify),
            1e3 * decode
        );
    }
}
