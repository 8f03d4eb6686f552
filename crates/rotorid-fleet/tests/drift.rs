//! Drift alerts with a real nats-server and two in-process workers: a machine whose kx drops
//! by 5 % half-way alerts within two windows; 20 unchanged machines raise no alert over
//! 10 s; a machine whose x support stands on an unmodelled foundation (eq. (1) does not
//! describe it) raises a model alert and no drift alert. Prints the largest |z| of the
//! unchanged machines (the margin to a false alarm). Then `fleet status` agrees with the
//! streams: every machine's windows, latest, alerts, the wrong model's warnings.

mod common;

use std::time::{Duration, Instant};

use common::*;
use futures_util::StreamExt as _;
use rotorid::pipeline::Method;
use rotorid_fleet::drift::DriftState;
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::publish::{publish_frames, Rate};
use rotorid_fleet::status::{render, status};
use rotorid_fleet::window::windows;
use rotorid_fleet::worker::{run, Scenarios, WorkerConfig};
use rotorid_fleet::{
    AlertRecord, Channel, ModelAlert, ALERT_STREAM, IDENT_STREAM, MODEL_INADEQUATE,
};

const UNCHANGED: usize = 20;
const WINDOW: usize = 10_000;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_five_percent_kx_drop_alerts_within_two_windows_and_nothing_else_does() {
    let tmp = tempfile::tempdir().unwrap();
    let scenarios = tmp.path().join("scenarios");
    std::fs::create_dir_all(&scenarios).unwrap();
    let server = Server::start(&tmp.path().join("js"));
    let fleet = Fleet::connect(&server.url(), Duration::from_secs(10))
        .await
        .unwrap();

    // the drifting machine: 5 s of its rotor, then 5 s with kx 5 % lower
    let p = rotor(7);
    let before = scenario(p, 5.0);
    std::fs::write(scenarios.join("drift.toml"), scenario_toml(&before)).unwrap();
    let mut low = p;
    low.kx *= 0.95;
    let (r1, r2) = (response(&before, 1), response(&scenario(low, 5.0), 2));
    let joined: Vec<Channel> = probes(&r1)
        .into_iter()
        .zip(probes(&r2))
        .map(|(mut a, b)| {
            a.data.extend(b.data);
            a
        })
        .collect();
    let mut all = vec![windows("drift", 0.0, 1e-4, &joined, WINDOW, 0).unwrap()];
    for i in 0..UNCHANGED {
        let id = format!("u{i:02}");
        let s = scenario(rotor(i), 10.0);
        std::fs::write(scenarios.join(format!("{id}.toml")), scenario_toml(&s)).unwrap();
        let r = response(&s, 1000 + i as u64);
        all.push(windows(&id, 0.0, 1e-4, &probes(&r), WINDOW, 0).unwrap());
    }
    // the wrong model: 5 s of table1 on a 5 kg foundation, 40 dB
    let table1 = scenario(rotorid::model::Rotor::table1().params(), 5.0);
    std::fs::write(scenarios.join("rub.toml"), scenario_toml(&table1)).unwrap();
    let mut wrong = defects::simulate_defective_for(defects::DEFECTS[1], 5.0);
    for v in [
        &mut wrong.t,
        &mut wrong.x,
        &mut wrong.z,
        &mut wrong.phi,
        &mut wrong.phi_dot,
        &mut wrong.phi_ddot,
    ] {
        v.truncate(50_000);
    }
    rotorid::simulate::add_noise(&mut wrong, 40.0, 77).unwrap();
    all.push(windows("rub", 0.0, 1e-4, &probes(&wrong), WINDOW, 0).unwrap());
    let total: usize = all.iter().map(Vec::len).sum::<usize>() + 2;
    for frames in &all {
        publish_frames(&fleet, frames, Rate::Max, |_| {})
            .await
            .unwrap();
    }

    // two bad messages: bytes that are no frame, and a frame on another machine's subject
    // (each must be dead-lettered with a record on rotorid.error.<ID>, never retried)
    fleet
        .publish("rotorid.raw.junk", "junk/0", "not a frame".into())
        .await
        .unwrap();
    let misplaced = all[0][0].encode().unwrap();
    fleet
        .publish("rotorid.raw.other", "other/0", misplaced.into())
        .await
        .unwrap();

    let mut cfg = WorkerConfig::new(Method::modulating(), Scenarios::Dir(scenarios.clone()));
    cfg.durable = "drift".into();
    let (tx, rx) = tokio::sync::watch::channel(false);
    let workers: Vec<_> = (0..2)
        .map(|_| {
            let (fleet, cfg, mut rx) = (fleet.clone(), cfg.clone(), rx.clone());
            tokio::spawn(async move {
                run(&fleet, &cfg, async move {
                    let _ = rx.wait_for(|&stop| stop).await;
                })
                .await
            })
        })
        .collect();
    let started = Instant::now();
    loop {
        let n = match fleet.js.get_stream(IDENT_STREAM).await {
            Ok(mut s) => s.info().await.map(|i| i.state.messages).unwrap_or(0),
            Err(_) => 0,
        };
        if n as usize >= total {
            break;
        }
        assert!(
            // a deadline only against a hang, not a speed test
            started.elapsed() < Duration::from_secs(600),
            "{n} of {total} results"
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    tx.send(true).unwrap();
    let (mut processed, mut errors) = (0, 0);
    for w in workers {
        let s = w.await.unwrap().unwrap();
        processed += s.windows;
        errors += s.errors;
    }
    assert!(processed as usize >= total - 2);
    assert_eq!(errors, 2, "the two bad messages, once each");
    let ident = fleet.js.get_stream(IDENT_STREAM).await.unwrap();
    for (id, needle) in [
        ("junk", "not a rotorid frame: magic"),
        ("other", "on rotorid.raw.other says it is machine drift's"),
    ] {
        let m = ident
            .get_last_raw_message_by_subject(&format!("rotorid.error.{id}"))
            .await
            .unwrap();
        let r: rotorid_fleet::ErrorRecord = serde_json::from_slice(&m.payload).unwrap();
        assert!(r.error.contains(needle), "{}", r.error);
    }

    // every alert
    let stream = fleet.js.get_stream(ALERT_STREAM).await.unwrap();
    let last = stream.get_info().await.unwrap().state.last_sequence;
    let mut alerts: Vec<AlertRecord> = Vec::new();
    let mut model_alerts: Vec<ModelAlert> = Vec::new();
    for seq in 1..=last {
        if let Ok(m) = stream.direct_get(seq).await {
            match serde_json::from_slice::<ModelAlert>(&m.payload) {
                Ok(a) => model_alerts.push(a),
                Err(_) => alerts.push(serde_json::from_slice(&m.payload).unwrap()),
            }
        }
    }
    for a in &model_alerts {
        eprintln!(
            "model alert: {} windows {} and {}: {}",
            a.machine, a.previous_window, a.window, a.message
        );
    }
    // every window of the wrong model is flagged: windows 1..4 each confirm with the one
    // before; nothing else raises one
    assert!(
        model_alerts.iter().all(|a| a.machine == "rub"),
        "{model_alerts:?}"
    );
    let mut confirmed: Vec<u64> = model_alerts.iter().map(|a| a.window).collect();
    confirmed.sort();
    assert_eq!(confirmed, vec![1, 2, 3, 4]);
    assert!(model_alerts
        .iter()
        .all(|a| a.kind == MODEL_INADEQUATE && a.message.contains("MODEL INADEQUATE")));
    for a in &alerts {
        eprintln!(
            "alert: {} window {} {} {:+.2} % z = {:.1} (previous {:.1})",
            a.machine,
            a.window,
            a.parameter,
            100.0 * a.relative_change,
            a.z,
            a.previous_z
        );
    }
    let false_alarms: Vec<_> = alerts.iter().filter(|a| a.machine != "drift").collect();
    let kx: Vec<_> = alerts
        .iter()
        .filter(|a| a.machine == "drift" && a.parameter == "kx")
        .collect();
    assert!(
        kx.iter().any(|a| a.window <= 6),
        "the kx drop (from window 5) is confirmed by window 6: {kx:?}"
    );
    let first = kx.iter().map(|a| a.window).min().unwrap();
    let rel = kx
        .iter()
        .find(|a| a.window == first)
        .unwrap()
        .relative_change;
    assert!((rel + 0.05).abs() < 0.01, "kx change {rel}");

    // the margin: largest |z| and single exceedances of the unchanged machines
    let kv = fleet.drift().await.unwrap();
    let mut keys = kv.keys().await.unwrap();
    let (mut zmax, mut over, mut tests) = (0.0f64, 0, 0);
    // windows of unchanged machines the model was judged not to explain: a false alarm
    // each (2 in 2100 records of correct models in the library's study), which withholds
    // that window's values, so it gives the drift test nothing and alerts nothing alone
    let (mut false_inadequate, mut untested) = (Vec::new(), 0);
    while let Some(k) = keys.next().await {
        let k = k.unwrap();
        if k == "drift" {
            continue;
        }
        let st: DriftState = serde_json::from_slice(&kv.get(&k).await.unwrap().unwrap()).unwrap();
        if k != "rub" {
            for (w, (_, message)) in &st.inadequate {
                false_inadequate.push(format!("{k} window {w}: {message}"));
                untested += usize::from(*w >= 3);
            }
        }
        for t in st.tested.values() {
            for (_, z) in &t.z {
                tests += 1;
                zmax = zmax.max(z.abs());
                over += usize::from(z.abs() > 5.0);
            }
        }
    }
    eprintln!(
        "unchanged machines: {} alerts, {tests} parameter tests, {over} single |z| > 5, \
         largest |z| = {zmax:.2}; drift machine: kx alert at window {first} (change from \
         window 5), {:+.2} %",
        false_alarms.len(),
        100.0 * rel
    );
    eprintln!(
        "unchanged windows judged inadequate: {} of {}: {false_inadequate:?}",
        false_inadequate.len(),
        UNCHANGED * 10
    );
    assert!(false_inadequate.len() <= 2, "{false_inadequate:?}");
    assert_eq!(
        tests,
        (UNCHANGED * 7 - untested) * 6,
        "windows 3..9, six parameters each"
    );
    assert!(false_alarms.is_empty(), "false alarms: {false_alarms:?}");

    // what `rotorid fleet status` shows
    let st = status(&fleet, "drift").await.unwrap();
    eprintln!("{}", render(&st));
    assert_eq!(st.machines.len(), UNCHANGED + 4, "with junk, other and rub");
    let rub = st.machines.iter().find(|m| m.machine == "rub").unwrap();
    assert_eq!(
        (rub.published, rub.identified, rub.alerts),
        (5, 5, 4),
        "rub's windows and model alerts"
    );
    assert_eq!(rub.last_model_alert.as_ref().map(|a| a.window), Some(4));
    let text = render(&st);
    let block = &text[text.find("\nrub ").expect("rub's block")..];
    assert!(
        block.contains("warning: MODEL INADEQUATE")
            && block.contains("MODEL ALERT windows 3 and 4"),
        "{block}"
    );
    let c = st.consumer.as_ref().expect("the workers' consumer");
    assert_eq!((c.pending, c.ack_pending), (0, 0));
    for m in st
        .machines
        .iter()
        .filter(|m| !["junk", "other", "rub"].contains(&m.machine.as_str()))
    {
        assert_eq!(
            (m.published, m.identified, m.errors),
            (10, 10, 0),
            "{}",
            m.machine
        );
        assert_eq!(
            m.latest.as_ref().map(|r| r.window),
            Some(9),
            "{}",
            m.machine
        );
    }
    let d = st.machines.iter().find(|m| m.machine == "drift").unwrap();
    assert_eq!(d.alerts as usize, alerts.len());
    assert_eq!(
        d.last_alert.as_ref(),
        alerts.last(),
        "the last alert stored"
    );
}
