//! The fleet on a real 3-node nats-server cluster that the test starts (`--cluster_name`,
//! `--cluster`, `--routes`, JetStream on each node with its own store): streams, buckets and
//! the workers' consumer with 3 replicas (a stream made with 1 is reported and changed by
//! `rotorid fleet replicas 3`), 8 machines published by 8 `rotorid publish` processes, two
//! `rotorid worker`s and a dashboard, all connected to the node that leads `ROTORID_RAW`
//! (first in their server lists); that node is SIGKILLed for good while every publisher is
//! in the middle of its recording (each waits, after its second window, for the test to
//! say the node is gone). Afterwards every window has exactly one result on
//! `rotorid.ident.<ID>` and no error record, each equal to offline `rotorid identify` of its
//! slice; `ROTORID_LATEST` holds each machine's last window; `rotorid fleet status` given a
//! list that still names the dead node first lists every machine; the dashboard shows every
//! window, on another server.

use std::collections::BTreeMap;
use std::io::{BufRead as _, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use rotorid_fleet::nats::Fleet;
use rotorid_fleet::test_server::Cluster;
use serde_json::Value;

use crate::common::rotorid;
use crate::dashboard::{get, wait_for, Proc, PATIENCE};

const MACHINES: usize = 8;
/// Windows per machine: 1 s recordings in 0.25 s windows.
const WINDOWS: u64 = 4;
/// Samples per window (0.25 s at 10 kHz); the last window takes the 10 001st sample.
const N: usize = 2_500;

fn run(args: &[&str]) -> String {
    let out = rotorid().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "rotorid {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn rt() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap()
}

/// `ROTORID_RAW`'s replicas and its leader's name, once it has a leader and every
/// replica is current.
fn raw_leader(rt: &tokio::runtime::Runtime, urls: &str, replicas: usize) -> String {
    wait_for("ROTORID_RAW with a leader and its replicas current", || {
        rt.block_on(async {
            let fleet = Fleet::connect(urls, Duration::from_secs(10)).await.ok()?;
            let mut s = fleet.js.get_stream(rotorid_fleet::RAW_STREAM).await.ok()?;
            let info = s.info().await.ok()?;
            let c = info.cluster.as_ref()?;
            let leader = c.leader.clone()?;
            let current = c.replicas.iter().filter(|r| r.current).count();
            (info.config.num_replicas == replicas && current + 1 == replicas).then_some(leader)
        })
    })
}

/// Lines of a child's stderr, as they come.
fn lines_of(child: &mut std::process::Child) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    let err = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines().map_while(Result::ok) {
            if tx.send(l).is_err() {
                return;
            }
        }
    });
    rx
}

/// Wait for a line of `rx` containing `what`; returns every line read.
fn wait_line(rx: &mpsc::Receiver<String>, what: &str, seen: &mut Vec<String>) {
    loop {
        match rx.recv_timeout(PATIENCE) {
            Ok(l) => {
                let hit = l.contains(what);
                seen.push(l);
                if hit {
                    return;
                }
            }
            Err(e) => panic!("no line with {what:?} ({e}): {}", seen.join("\n")),
        }
    }
}

/// The window `w` of a response CSV (its header and rows), as `publish` cuts it.
fn slice(rec: &Path, w: u64, out: &Path) {
    let text = std::fs::read_to_string(rec).unwrap();
    let mut lines = text.lines();
    let mut s = vec![lines.next().unwrap()];
    let rows: Vec<&str> = lines.collect();
    let a = w as usize * N;
    let b = if w + 1 == WINDOWS { rows.len() } else { a + N };
    s.extend(&rows[a..b]);
    std::fs::write(out, s.join("\n") + "\n").unwrap();
}

#[test]
fn a_three_node_cluster_loses_the_raw_leader_mid_run_without_a_window_lost_or_repeated() {
    let dir = tempfile::tempdir().unwrap();
    let mut cluster = Cluster::start(&dir.path().join("cluster"), 3);
    let all = cluster.urls();
    let rt = rt();

    // a stream made with 1 replica (as by an older fleet) is reported and then changed
    rt.block_on(async {
        let fleet = Fleet::connect(&all, Duration::from_secs(10)).await.unwrap();
        fleet.raw_stream().await.unwrap();
    });
    let worker_log = |i: usize| dir.path().join(format!("worker{i}.log"));
    let spawn_worker = |i: usize, urls: &str| {
        let log = std::fs::File::create(worker_log(i)).unwrap();
        Proc(Some(
            Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
                .args(["worker", "--nats", urls, "--replicas", "3"])
                .args(["--scenario", "table1", "--ack-wait", "2", "-v"])
                .stdout(Stdio::null())
                .stderr(log)
                .spawn()
                .unwrap(),
        ))
    };
    let first = spawn_worker(0, &all);
    wait_for("the worker's report of the 1-replica stream", || {
        let log = std::fs::read_to_string(worker_log(0)).ok()?;
        log.contains("waiting for windows").then_some(())
    });
    let log = std::fs::read_to_string(worker_log(0)).unwrap();
    assert!(
        log.contains("stream ROTORID_RAW has 1 replica(s), fewer than --replicas 3")
            && log.contains("rotorid fleet replicas 3"),
        "{log}"
    );
    drop(first);
    let out = run(&["fleet", "replicas", "3", "--nats", &all]);
    assert!(
        out.contains("stream ROTORID_RAW: 1 -> 3 replica(s)"),
        "{out}"
    );
    let out = run(&["fleet", "replicas", "3", "--nats", &all]);
    assert!(out.contains("3 replica(s) already"), "{out}");

    // everyone on the raw stream's leader first
    let leader = raw_leader(&rt, &all, 3);
    let dead = cluster.index_of(&leader).expect("a node of ours leads");
    let live: Vec<usize> = (0..3).filter(|&i| i != dead).collect();
    let list = [dead, live[0], live[1]]
        .iter()
        .map(|&i| cluster.url(i))
        .collect::<Vec<_>>()
        .join(",");
    let _w0 = spawn_worker(0, &list);
    let _w1 = spawn_worker(1, &list);

    let mut dash = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
        .args(["dashboard", "--nats", &list, "--listen", "127.0.0.1:0"])
        .args(["--stale-windows", "1e6"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(dash.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let _dash = Proc(Some(dash));
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|r| r.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_owned();
    let on_leader = wait_for("the dashboard on the leader", || {
        let s = get(&addr, "/api/status").json();
        (s["nats"]["connected"] == true).then(|| s["nats"]["server"].clone())
    });
    assert!(
        on_leader
            .as_str()
            .unwrap()
            .contains(&format!("(server {leader})")),
        "{on_leader}"
    );

    // 8 recordings of 1 s, published in 0.25 s windows; each publisher waits after its
    // second window until the leader is gone
    let go = dir.path().join("go");
    let mut recs = Vec::new();
    let mut pubs = Vec::new();
    for i in 0..MACHINES {
        let rec = dir.path().join(format!("m{i}.csv"));
        run(&[
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "1",
            "--snr-db",
            "40",
            "--seed",
            &(70 + i).to_string(),
            "--out",
            rec.to_str().unwrap(),
            "-q",
        ]);
        let mut p = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
            .args(["publish", rec.to_str().unwrap(), "--nats", &list])
            .args(["--machine", &format!("m-{i}"), "--window-s", "0.25"])
            .args(["--replicas", "3"])
            .env(
                "ROTORID_PUBLISH_WAIT_AFTER",
                format!("1:{}", go.to_str().unwrap()),
            )
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let rx = lines_of(&mut p);
        recs.push(rec);
        pubs.push((p, rx, Vec::new()));
    }
    for (_, rx, seen) in &mut pubs {
        wait_line(rx, "waiting for", seen);
        assert!(
            seen.iter()
                .any(|l| l.contains(&format!("(server {leader})"))),
            "the publisher is on the leader: {}",
            seen.join("\n")
        );
    }
    cluster.kill(dead);
    eprintln!("node {leader} (ROTORID_RAW's leader) killed with SIGKILL");
    std::fs::write(&go, "").unwrap();
    for (i, (p, rx, mut seen)) in pubs.into_iter().enumerate() {
        let out = p.wait_with_output().unwrap();
        seen.extend(rx.iter());
        if i == 0 {
            eprintln!("publisher of m-0:\n{}", seen.join("\n"));
        }
        assert!(
            out.status.success(),
            "publish after the loss of its server: {}",
            seen.join("\n")
        );
        assert!(
            seen.iter()
                .any(|l| l.contains(&format!("{WINDOWS} windows of machine"))),
            "{}",
            seen.join("\n")
        );
    }

    // every window identified exactly once
    let total = MACHINES as u64 * WINDOWS;
    let patience = std::env::var("ROTORID_TEST_PATIENCE_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .map_or(PATIENCE, Duration::from_secs);
    let started = std::time::Instant::now();
    let mut last_seen = String::new();
    let results: BTreeMap<(String, u64), Value> = loop {
        let got = rt.block_on(async {
            let fleet = Fleet::connect(&list, Duration::from_secs(10)).await.ok()?;
            let mut s = fleet
                .js
                .get_stream(rotorid_fleet::IDENT_STREAM)
                .await
                .ok()?;
            let st = s.info().await.ok()?.state.clone();
            if st.messages < total {
                // what a failure shows: the workers' consumer and what they wrote
                let raw = fleet.js.get_stream(rotorid_fleet::RAW_STREAM).await.ok()?;
                let c = raw.consumer_info(rotorid_fleet::DEFAULT_DURABLE).await;
                let logs: Vec<String> = (0..2)
                    .map(|i| std::fs::read_to_string(worker_log(i)).unwrap_or_default())
                    .collect();
                last_seen = format!(
                    "{} results; consumer {c:?}; workers:\n{}",
                    st.messages,
                    logs.join("\n")
                );
                return None;
            }
            let mut got = BTreeMap::new();
            for seq in st.first_sequence..=st.last_sequence {
                let m = s.direct_get(seq).await.ok()?;
                assert!(
                    m.subject.starts_with("rotorid.ident."),
                    "a window failed: {} {}",
                    m.subject,
                    String::from_utf8_lossy(&m.payload)
                );
                let v: Value = serde_json::from_slice(&m.payload).unwrap();
                let key = (
                    v["machine"].as_str().unwrap().to_owned(),
                    v["window"].as_u64().unwrap(),
                );
                assert!(got.insert(key.clone(), v).is_none(), "{key:?} stored twice");
            }
            Some(got)
        });
        if let Some(got) = got {
            break got;
        }
        assert!(
            started.elapsed() < patience,
            "not every window's result within {patience:?}: {last_seen}"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    assert_eq!(results.len() as u64, total);

    // each equal to offline identify of its slice
    for (i, rec) in recs.iter().enumerate() {
        for w in 0..WINDOWS {
            let s = dir.path().join(format!("m{i}-{w}.csv"));
            slice(rec, w, &s);
            let sum = dir.path().join(format!("m{i}-{w}.json"));
            run(&[
                "identify",
                s.to_str().unwrap(),
                "--scenario",
                "table1",
                "--method",
                "modulating",
                "--out",
                dir.path().join("e.csv").to_str().unwrap(),
                "--summary",
                sum.to_str().unwrap(),
                "-q",
            ]);
            let offline: Value =
                serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
            let stored = &results[&(format!("m-{i}"), w)]["identification"];
            let params = |v: &Value| -> Vec<(String, Option<f64>, Option<f64>)> {
                v["parameters"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|p| {
                        (
                            p["parameter"].as_str().unwrap().to_owned(),
                            p["value"].as_f64(),
                            p["std_error"].as_f64(),
                        )
                    })
                    .collect()
            };
            let (a, b) = (params(stored), params(&offline));
            assert_eq!(a.len(), b.len(), "m-{i} window {w}");
            for ((n, v, e), (on, ov, oe)) in a.iter().zip(&b) {
                assert_eq!(n, on);
                let close = |x: Option<f64>, y: Option<f64>| match (x, y) {
                    (Some(x), Some(y)) => (x - y).abs() <= 1e-9 * y.abs().max(1e-300),
                    (None, None) => true,
                    _ => false,
                };
                assert!(
                    close(*v, *ov) && close(*e, *oe),
                    "m-{i} window {w} {n}: {v:?} +- {e:?} vs offline {ov:?} +- {oe:?}"
                );
            }
        }
    }

    // ROTORID_LATEST: each machine's last window
    rt.block_on(async {
        let fleet = Fleet::connect(&list, Duration::from_secs(10))
            .await
            .unwrap();
        let kv = fleet.latest().await.unwrap();
        for i in 0..MACHINES {
            let v = kv
                .get(format!("m-{i}"))
                .await
                .unwrap()
                .expect("a latest entry");
            let v: Value = serde_json::from_slice(&v).unwrap();
            assert_eq!(v["window"], WINDOWS - 1, "m-{i}");
        }
    });

    // the status, given the list that still names the dead node first
    let status = run(&["fleet", "status", "--nats", &list]);
    for i in 0..MACHINES {
        let row = status
            .lines()
            .find(|l| l.split_whitespace().next() == Some(&format!("m-{i}")))
            .unwrap_or_else(|| panic!("m-{i} not in the status:\n{status}"));
        let f: Vec<&str> = row.split_whitespace().collect();
        assert_eq!((f[1], f[2], f[3]), ("4", "4", "0"), "{row}");
    }

    // the dashboard carried on, on another server, and shows every window
    wait_for("every window on the dashboard", || {
        let v = get(&addr, "/api/machines").json();
        let ms = v["machines"].as_array()?;
        let all = ms.len() == MACHINES
            && ms
                .iter()
                .all(|t| t["window"] == WINDOWS - 1 && t["results"] == WINDOWS);
        (all && v["nats"]["connected"] == true).then_some(())
    });
    // and names the server it is on now (it follows the client's INFO, within a second)
    wait_for("the dashboard on a live server", || {
        let s = get(&addr, "/api/status").json();
        let on = s["nats"]["server"].as_str()?.to_owned();
        (!on.contains(&format!("(server {leader})"))).then_some(())
    });
}

/// A worker whose consumer loses its only replica (an R1 consumer, as made by hand or by an
/// older fleet, on the node that dies) says so and re-creates the consumer, then identifies
/// the windows published afterwards: it does not wait silently for ever.
#[test]
fn a_worker_whose_consumer_has_no_leader_left_recreates_it_and_carries_on() {
    use async_nats::jetstream::consumer::pull;
    let dir = tempfile::tempdir().unwrap();
    let mut cluster = Cluster::start(&dir.path().join("cluster"), 3);
    let all = cluster.urls();
    let rt = rt();
    // the raw stream with 3 replicas, the workers' consumer with 1
    let holder = rt.block_on(async {
        let fleet = Fleet::connect(&all, Duration::from_secs(10))
            .await
            .unwrap()
            .with_replicas(3)
            .unwrap();
        let raw = fleet.raw_stream().await.unwrap();
        let mut c = raw
            .create_consumer(pull::Config {
                durable_name: Some(rotorid_fleet::DEFAULT_DURABLE.into()),
                filter_subject: "rotorid.raw.>".into(),
                ack_wait: Duration::from_secs(2),
                num_replicas: 1,
                ..Default::default()
            })
            .await
            .unwrap();
        let info = c.info().await.unwrap();
        info.cluster.as_ref().unwrap().leader.clone().unwrap()
    });
    raw_leader(&rt, &all, 3);
    let dead = cluster.index_of(&holder).expect("a node of ours holds it");
    let live = (0..3)
        .filter(|&i| i != dead)
        .map(|i| cluster.url(i))
        .collect::<Vec<_>>()
        .join(",");
    let log = dir.path().join("worker.log");
    let _worker = Proc(Some(
        Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
            .args(["worker", "--nats", &live, "--replicas", "3"])
            .args(["--scenario", "table1", "--ack-wait", "2", "-v"])
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .unwrap(),
    ));
    let read_log = || std::fs::read_to_string(&log).unwrap_or_default();
    wait_for("the worker on its consumer", || {
        read_log().contains("waiting for windows").then_some(())
    });
    cluster.kill(dead);

    let rec = dir.path().join("m.csv");
    run(&[
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "1",
        "--snr-db",
        "40",
        "--seed",
        "91",
        "--out",
        rec.to_str().unwrap(),
        "-q",
    ]);
    run(&[
        "publish",
        rec.to_str().unwrap(),
        "--nats",
        &live,
        "--machine",
        "m-0",
        "--window-s",
        "0.25",
        "--replicas",
        "3",
    ]);
    wait_for(
        "every window's result after the consumer was re-created",
        || {
            rt.block_on(async {
                let fleet = Fleet::connect(&live, Duration::from_secs(10)).await.ok()?;
                let mut s = fleet
                    .js
                    .get_stream(rotorid_fleet::IDENT_STREAM)
                    .await
                    .ok()?;
                (s.info().await.ok()?.state.messages == WINDOWS).then_some(())
            })
        },
    );
    let text = read_log();
    assert!(
        text.contains("re-creating it from stream sequence")
            && text.contains("re-created; waiting for windows"),
        "{text}"
    );
}
