//! End to end with a real nats-server: 20 machines x 10 s of 10 kHz data, two worker
//! processes; one is SIGKILLed while it holds an unacknowledged window (it announces the
//! window it holds and holds it for ever: `WorkerConfig::hold_after`, so the kill cannot
//! miss), and restarted; once that window has come back and been identified, the server is
//! SIGKILLed and restarted. Afterwards every window of every machine has exactly one result in
//! ROTORID_IDENT, byte for byte the JSON of an offline `identify` of the same samples
//! (cut here from the simulation, not from the frames), and ROTORID_LATEST holds each
//! machine's last window.

mod common;

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use common::*;
use rotorid::pipeline::{identify, Knowledge, Method, Record, Speed, TimeGrid};
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::publish::{publish_frames, Rate};
use rotorid_fleet::window::windows;
use rotorid_fleet::{WindowResult, FLEET_SCHEMA, IDENT_STREAM};

const MACHINES: usize = 20;
const SECONDS: f64 = 10.0;
const WINDOW: usize = 10_000; // 1 s at 10 kHz
const WINDOWS: usize = 10;
/// A deadline only against a hang, never a speed test: a busy machine may be slow.
const HANG: Duration = Duration::from_secs(600);

fn machine(i: usize) -> String {
    format!("m{i:02}")
}

/// Messages in ROTORID_IDENT.
async fn ident_count(fleet: &Fleet) -> u64 {
    match fleet.js.get_stream(IDENT_STREAM).await {
        Ok(mut s) => s.info().await.map(|i| i.state.messages).unwrap_or(0),
        Err(_) => 0,
    }
}

/// Whether ROTORID_IDENT holds the result of `window` of `machine`.
async fn has_result(fleet: &Fleet, machine: &str, window: u64) -> bool {
    let Ok(mut stream) = fleet.js.get_stream(IDENT_STREAM).await else {
        return false;
    };
    let Ok(info) = stream.info().await else {
        return false;
    };
    for seq in info.state.first_sequence..=info.state.last_sequence {
        let Ok(m) = stream.direct_get(seq).await else {
            continue;
        };
        if m.subject.as_str() != format!("rotorid.ident.{machine}") {
            continue;
        }
        if serde_json::from_slice::<WindowResult>(&m.payload).is_ok_and(|r| r.window == window) {
            return true;
        }
    }
    false
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn twenty_machines_two_workers_a_kill_and_a_server_restart() {
    let tmp = tempfile::tempdir().unwrap();
    let store = tmp.path().join("js");
    let scenarios = tmp.path().join("scenarios");
    std::fs::create_dir_all(&scenarios).unwrap();
    let mut server = Server::start(&store);
    let url = server.url();

    let sims: Vec<_> = (0..MACHINES)
        .map(|i| {
            let s = scenario(rotor(i), SECONDS);
            std::fs::write(
                scenarios.join(format!("{}.toml", machine(i))),
                scenario_toml(&s),
            )
            .unwrap();
            let r = response(&s, 100 + i as u64);
            (s, r)
        })
        .collect();

    let method = "modulating";
    let spawn = || spawn_worker(&url, "e2e", method, &scenarios, 3.0);
    // worker a works alone until it holds its third window unacknowledged
    let mut a = spawn_holding_worker(&url, "e2e", method, &scenarios, 3.0, 3);

    let fleet = Fleet::connect(&url, Duration::from_secs(10)).await.unwrap();
    let mut tasks = Vec::new();
    for (i, (_, r)) in sims.iter().enumerate() {
        let frames = windows(&machine(i), r.t[0], 1e-4, &probes(r), WINDOW, 0).unwrap();
        assert_eq!(frames.len(), WINDOWS);
        let fleet = fleet.clone();
        tasks.push(tokio::spawn(async move {
            publish_frames(&fleet, &frames, Rate::Max, |_| {}).await
        }));
    }
    for t in tasks {
        let rep = t.await.unwrap().unwrap();
        assert_eq!(rep.windows, WINDOWS as u64);
    }

    let total = (MACHINES * WINDOWS) as u64;
    let started = Instant::now();
    let wait_for = |n: u64| {
        let fleet = fleet.clone();
        async move {
            loop {
                let c = ident_count(&fleet).await;
                if c >= n {
                    return c;
                }
                assert!(
                    started.elapsed() < HANG,
                    "only {c} of {n} results after {:?}",
                    started.elapsed()
                );
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
        }
    };
    // kill worker a while it holds a window it has not acknowledged, start a new one and
    // a second; the held window comes back after the ack wait (3 s) and one of them
    // identifies it: only then is the server restarted
    let (a, (held_machine, held_window)) = tokio::task::spawn_blocking(move || {
        let held = a.wait_until_holding();
        (a, held)
    })
    .await
    .unwrap();
    a.kill();
    let a = spawn();
    let b = spawn();
    eprintln!(
        "worker killed holding window {held_window} of machine {held_machine}, restarted at {:?}",
        started.elapsed()
    );
    loop {
        if has_result(&fleet, &held_machine, held_window).await {
            break;
        }
        assert!(
            started.elapsed() < HANG,
            "window {held_window} of machine {held_machine} was never redelivered"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    wait_for(total / 2).await;
    server.restart();
    eprintln!("server restarted at {:?}", started.elapsed());
    let fleet = Fleet::connect(&url, Duration::from_secs(10)).await.unwrap();
    let wait_for = |n: u64| {
        let fleet = fleet.clone();
        async move {
            loop {
                let c = ident_count(&fleet).await;
                if c >= n {
                    return c;
                }
                assert!(
                    started.elapsed() < HANG,
                    "only {c} of {n} results after {:?}",
                    started.elapsed()
                );
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
        }
    };
    wait_for(total).await;
    eprintln!("all {total} results at {:?}", started.elapsed());
    // nothing left in flight: no window pending or delivered and unacknowledged (a
    // redelivered window would have been acknowledged after its result was dropped as a
    // copy), so the stream below is final
    loop {
        let idle = match fleet.js.get_stream(rotorid_fleet::RAW_STREAM).await {
            Ok(raw) => raw
                .consumer_info("e2e")
                .await
                .is_ok_and(|i| i.num_pending == 0 && i.num_ack_pending == 0),
            Err(_) => false,
        };
        if idle {
            break;
        }
        assert!(started.elapsed() < HANG, "windows still in flight");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let (sa, oa) = terminate(a);
    let (sb, ob) = terminate(b);
    assert!(
        sa.success() && sb.success(),
        "workers exit 0 on SIGTERM: {sa} {sb}"
    );
    eprintln!("worker a (restarted): {}worker b: {}", oa, ob);
    // the killed worker held a window unacknowledged: someone redid it
    let redelivered: u64 = [&oa, &ob]
        .iter()
        .map(|o| {
            o.split_whitespace()
                .find_map(|w| w.strip_prefix("redelivered="))
                .and_then(|n| n.parse::<u64>().ok())
                .expect("the worker's closing line")
        })
        .sum();
    assert!(
        redelivered >= 1,
        "the held window's result came from a redelivery, which the workers count"
    );

    // every stored result, by (machine, window)
    let stream = fleet.js.get_stream(IDENT_STREAM).await.unwrap();
    let last = stream.get_info().await.unwrap().state.last_sequence;
    let mut got: BTreeMap<(String, u64), Vec<Vec<u8>>> = BTreeMap::new();
    for seq in 1..=last {
        let Ok(m) = stream.direct_get(seq).await else {
            continue;
        };
        assert!(
            m.subject.starts_with("rotorid.ident."),
            "a window failed: {} {}",
            m.subject,
            String::from_utf8_lossy(&m.payload)
        );
        let r: WindowResult = serde_json::from_slice(&m.payload).unwrap();
        assert_eq!(m.subject.as_str(), format!("rotorid.ident.{}", r.machine));
        got.entry((r.machine.clone(), r.window))
            .or_default()
            .push(m.payload.to_vec());
    }
    assert_eq!(got.len(), MACHINES * WINDOWS, "one entry per window");
    let latest = fleet.latest().await.unwrap();
    for (i, (s, r)) in sims.iter().enumerate() {
        let k = Knowledge::from_scenario(s);
        for w in 0..WINDOWS {
            let stored = &got[&(machine(i), w as u64)];
            assert_eq!(stored.len(), 1, "machine {} window {w}", machine(i));
            let (a, b) = (w * WINDOW, (w + 1) * WINDOW);
            let record = Record::uniform(
                TimeGrid::given(r.t[a], 1e-4).unwrap(),
                r.x[a..b].to_vec(),
                r.z[a..b].to_vec(),
                Speed::Profile(s.speed),
            )
            .unwrap();
            let offline = identify(&record, &k, &Method::modulating()).unwrap();
            let expected = WindowResult {
                fleet_schema: FLEET_SCHEMA,
                machine: machine(i),
                window: w as u64,
                t0_s: r.t[a],
                dt_s: 1e-4,
                samples: WINDOW as u64,
                identification: offline,
            };
            let expected = serde_json::to_vec(&expected).unwrap();
            assert!(
                stored[0] == expected,
                "machine {} window {w}: the stored result differs from offline identify",
                machine(i)
            );
            if w == WINDOWS - 1 {
                let v = latest
                    .get(machine(i))
                    .await
                    .unwrap()
                    .expect("a latest entry");
                assert!(
                    v == expected,
                    "ROTORID_LATEST of {} is window {w}",
                    machine(i)
                );
            }
        }
    }
    eprintln!(
        "{} windows, each with exactly one result equal to offline identify; {redelivered} \
         redelivered; {:?} in all",
        got.len(),
        started.elapsed()
    );
}
