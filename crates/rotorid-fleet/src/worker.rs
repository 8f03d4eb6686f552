//! The worker: a durable pull consumer on `ROTORID_RAW`, shared by any number of workers.
//!
//! For each window, in this order:
//! 1. decode the frame and build its record ([`crate::window`]);
//! 2. identify it by the pipeline (in a blocking thread, while an "in progress"
//!    acknowledgement is sent every third of the ack wait, so a long refine is not
//!    redelivered while it runs);
//! 3. publish the [`WindowResult`] on `rotorid.ident.<ID>` with `Nats-Msg-Id <ID>/<window>`
//!    (or an [`ErrorRecord`] on `rotorid.error.<ID>` when the window gives no result);
//! 4. update `ROTORID_LATEST` key `<ID>` by compare-and-set, only when the window's number
//!    is higher than the stored one's (window numbers order a machine's windows: they
//!    increase with time);
//! 5. update the drift state and publish any alert ([`crate::drift`]: a parameter that
//!    left its baseline, or two consecutive windows the model does not explain);
//! 6. acknowledge the window.
//!
//! A worker killed anywhere before 6 leaves the window unacknowledged: after the ack wait
//! the server delivers it to another worker, which redoes 1-5; the results and alerts it
//! publishes again carry the same `Nats-Msg-Id` and are dropped by the server, and the
//! KV updates are idempotent. So each window has exactly one result in `ROTORID_IDENT`
//! (within the streams' duplicate window, one hour).
//!
//! **Bad input.** A message that is not a valid frame, a frame whose machine is not its
//! subject's, a window without the channels the record needs, or one the pipeline refuses
//! is never retried: its [`ErrorRecord`] (naming the machine, the window, the subject and
//! the field) is published on `rotorid.error.<ID>` (`_` when no machine can be read) and
//! the message acknowledged (dead-lettered). A window delivered more than
//! [`WorkerConfig::max_deliveries`] times (it killed that many workers) is dead-lettered
//! the same way instead of looping.
//!
//! **Shutdown.** On SIGINT or SIGTERM ([`shutdown_signal`]) the worker finishes and
//! acknowledges the window it holds (it fetches one at a time), then returns.

use std::collections::HashMap;
use std::future::Future;
use std::io::Read as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use async_nats::jetstream::consumer::{pull, PullConsumer};
use async_nats::jetstream::kv;
use async_nats::jetstream::message::AckKind;
use async_nats::jetstream::Message;
use bytes::Bytes;
use futures_util::StreamExt as _;
use rotorid::pipeline::{Identification, Knowledge, Method};
use rotorid::scenario_file::ScenarioSpec;
use rotorid::{Scenario, SpeedProfile};

use crate::drift::{self, DriftSettings, DriftState};
use crate::error::FleetError;
use crate::frame::{check_machine_id, Frame};
use crate::nats::{retry, Fleet};
use crate::result::{ErrorRecord, WindowResult, FLEET_SCHEMA};
use crate::window::identify_frame;
use crate::{alert_subject, error_subject, ident_subject, message_id};

/// Largest scenario or baseline file read \[bytes\].
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Where each machine's scenario comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Scenarios {
    /// One scenario for every machine: `table1` (built in) or a TOML file.
    One(String),
    /// A directory of `<ID>.toml`, one per machine.
    Dir(PathBuf),
}

/// How a worker works.
#[derive(Debug, Clone)]
pub struct WorkerConfig {
    /// The durable consumer's name (shared by the workers that share the work).
    pub durable: String,
    /// The identification method.
    pub method: Method,
    /// The machines' scenarios.
    pub scenarios: Scenarios,
    /// Optional directory of `<ID>.json` (`rotorid identify --summary`) baselines.
    pub baselines: Option<PathBuf>,
    /// The drift rule.
    pub drift: DriftSettings,
    /// How long an unacknowledged window waits before redelivery (set when the consumer is
    /// created; an existing consumer keeps its own).
    pub ack_wait: Duration,
    /// Deliveries after which a window is dead-lettered.
    pub max_deliveries: i64,
    /// Print on stderr a line when a window is taken and one when it is done (just before
    /// its acknowledgement), and every dead letter and alert.
    pub verbose: bool,
    /// A hook for tests that kill a worker: after taking this many windows, hold the last
    /// one unacknowledged for ever (until the process is killed), having written
    /// `holding window W of machine M (delivery D)` on stderr, so that a kill provably
    /// lands on a window the server must redeliver. `None` (the default): never.
    pub hold_after: Option<u64>,
}

impl WorkerConfig {
    /// Defaults: durable [`crate::DEFAULT_DURABLE`], ack wait 30 s, 5 deliveries, the
    /// default drift rule.
    pub fn new(method: Method, scenarios: Scenarios) -> Self {
        Self {
            durable: crate::DEFAULT_DURABLE.to_owned(),
            method,
            scenarios,
            baselines: None,
            drift: DriftSettings::default(),
            ack_wait: Duration::from_secs(30),
            max_deliveries: 5,
            verbose: false,
            hold_after: None,
        }
    }
}

/// What a worker did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WorkerStats {
    /// Windows identified.
    pub windows: u64,
    /// Windows dead-lettered.
    pub errors: u64,
    /// Alerts published.
    pub alerts: u64,
    /// Windows it got that had been delivered before (to a worker that died, or whose
    /// acknowledgement was lost).
    pub redelivered: u64,
}

/// What a machine's windows are identified with.
struct Setup {
    knowledge: Knowledge,
    profile: Option<SpeedProfile>,
}

/// Resolves once SIGINT or SIGTERM arrives.
pub async fn shutdown_signal() {
    use tokio::signal::unix::{signal, SignalKind};
    let (Ok(mut int), Ok(mut term)) = (
        signal(SignalKind::interrupt()),
        signal(SignalKind::terminate()),
    ) else {
        return std::future::pending().await;
    };
    tokio::select! {
        _ = int.recv() => {},
        _ = term.recv() => {},
    }
}

/// The text of a file of at most [`MAX_FILE_BYTES`].
fn read_capped(path: &std::path::Path) -> Result<String, String> {
    let f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut s = String::new();
    f.take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut s)
        .map_err(|e| e.to_string())?;
    if s.len() as u64 > MAX_FILE_BYTES {
        return Err(format!("larger than {MAX_FILE_BYTES} bytes"));
    }
    Ok(s)
}

/// The scenario `arg` (`table1` or a TOML file) as the worker uses it.
fn load_setup(machine: &str, arg: &str) -> Result<Setup, FleetError> {
    let err = |message: String| FleetError::Scenario {
        machine: machine.to_owned(),
        path: arg.to_owned(),
        message,
    };
    let spec = if arg == "table1" {
        ScenarioSpec::builtin("table1", Scenario::table1())
    } else {
        let text = read_capped(std::path::Path::new(arg)).map_err(err)?;
        ScenarioSpec::parse(arg, &text).map_err(|e| err(e.to_string()))?
    };
    Ok(Setup {
        knowledge: spec.knowledge().map_err(|e| err(e.to_string()))?,
        profile: spec.identification().map_err(|e| err(e.to_string()))?.speed,
    })
}

struct Worker<'a> {
    fleet: &'a Fleet,
    cfg: &'a WorkerConfig,
    latest: kv::Store,
    drift: kv::Store,
    setups: HashMap<String, Arc<Setup>>,
    stats: WorkerStats,
    /// Windows taken (for [`WorkerConfig::hold_after`]).
    taken: u64,
}

/// Check the setup and create the streams, buckets and the consumer (all idempotent), so
/// that a worker can fail at once on a bad scenario or server.
pub async fn prepare(fleet: &Fleet, cfg: &WorkerConfig) -> Result<PullConsumer, FleetError> {
    if let Scenarios::One(s) = &cfg.scenarios {
        load_setup("*", s)?;
    }
    if let Scenarios::Dir(d) = &cfg.scenarios {
        if !d.is_dir() {
            return Err(FleetError::Scenario {
                machine: "*".into(),
                path: d.display().to_string(),
                message: "not a directory (--scenarios DIR holds one <ID>.toml per machine)".into(),
            });
        }
    }
    let raw = fleet.raw_stream().await?;
    fleet.ident_stream().await?;
    fleet.alert_stream().await?;
    fleet.latest().await?;
    fleet.drift().await?;
    let config = pull::Config {
        durable_name: Some(cfg.durable.clone()),
        ack_wait: cfg.ack_wait,
        max_deliver: -1,
        filter_subject: "rotorid.raw.>".into(),
        ..Default::default()
    };
    retry(&format!("create consumer {}", cfg.durable), || {
        raw.get_or_create_consumer(&cfg.durable, config.clone())
    })
    .await
}

/// Run a worker until `shutdown` resolves (module doc).
pub async fn run(
    fleet: &Fleet,
    cfg: &WorkerConfig,
    shutdown: impl Future<Output = ()>,
) -> Result<WorkerStats, FleetError> {
    let consumer = prepare(fleet, cfg).await?;
    let mut w = Worker {
        fleet,
        cfg,
        latest: fleet.latest().await?,
        drift: fleet.drift().await?,
        setups: HashMap::new(),
        stats: WorkerStats::default(),
        taken: 0,
    };
    tokio::pin!(shutdown);
    loop {
        let msg = tokio::select! {
            _ = &mut shutdown => break,
            m = next_message(&consumer) => m,
        };
        let Some(msg) = msg else { continue };
        w.handle(msg).await?;
    }
    Ok(w.stats)
}

/// The next window, or `None` after a pull that expired or failed (the server may be
/// restarting: the caller simply pulls again).
async fn next_message(consumer: &PullConsumer) -> Option<Message> {
    let batch = consumer
        .batch()
        .max_messages(1)
        .expires(Duration::from_secs(2))
        .messages()
        .await;
    match batch {
        // the server ends the pull after 2 s; the time-out covers a connection lost meanwhile
        Ok(mut b) => match tokio::time::timeout(Duration::from_secs(4), b.next()).await {
            Ok(Some(Ok(m))) => Some(m),
            _ => None,
        },
        Err(_) => {
            tokio::time::sleep(Duration::from_millis(250)).await;
            None
        }
    }
}

impl Worker<'_> {
    fn setup(&mut self, machine: &str) -> Result<Arc<Setup>, FleetError> {
        if let Some(s) = self.setups.get(machine) {
            return Ok(Arc::clone(s));
        }
        let arg = match &self.cfg.scenarios {
            Scenarios::One(s) => s.clone(),
            Scenarios::Dir(d) => d.join(format!("{machine}.toml")).display().to_string(),
        };
        let s = Arc::new(load_setup(machine, &arg)?);
        self.setups.insert(machine.to_owned(), Arc::clone(&s));
        Ok(s)
    }

    async fn handle(&mut self, msg: Message) -> Result<(), FleetError> {
        let (stream_seq, delivered) = msg
            .info()
            .map(|i| (i.stream_sequence, i.delivered))
            .unwrap_or((0, 1));
        let subject = msg.subject.to_string();
        let token = subject.strip_prefix("rotorid.raw.").unwrap_or("");
        let subject_machine = if check_machine_id(token).is_ok() {
            token.to_owned()
        } else {
            "_".to_owned()
        };
        let dead = |machine: &str, window: Option<u64>, error: String| ErrorRecord {
            fleet_schema: FLEET_SCHEMA,
            machine: machine.to_owned(),
            window,
            stream_seq,
            delivered: delivered.max(0) as u64,
            error,
        };
        let frame = match Frame::decode(&msg.payload) {
            Ok(f) if f.machine == subject_machine => f,
            Ok(f) => {
                let e = FleetError::WrongSubject {
                    subject: subject.clone(),
                    window: f.window,
                    frame_machine: f.machine.clone(),
                };
                let r = dead(&subject_machine, Some(f.window), e.to_string());
                return self.dead_letter(&msg, r).await;
            }
            Err(source) => {
                let e = FleetError::Frame {
                    subject: subject.clone(),
                    stream_seq,
                    source,
                };
                let r = dead(&subject_machine, None, e.to_string());
                return self.dead_letter(&msg, r).await;
            }
        };
        self.stats.redelivered += u64::from(delivered > 1);
        if self.cfg.verbose {
            eprintln!(
                "window {} of machine {} (stream seq {stream_seq}, delivery {delivered}) taken",
                frame.window, frame.machine
            );
        }
        self.taken += 1;
        if self.cfg.hold_after.is_some_and(|n| self.taken >= n) {
            eprintln!(
                "holding window {} of machine {} (delivery {delivered})",
                frame.window, frame.machine
            );
            // unacknowledged until the process is killed (WorkerConfig::hold_after)
            std::future::pending::<()>().await;
        }
        if delivered > self.cfg.max_deliveries {
            let r = dead(
                &frame.machine,
                Some(frame.window),
                format!(
                    "machine {} window {}: delivered {delivered} times without being \
                     acknowledged (more than --max-deliveries {}): each worker that took it \
                     died",
                    frame.machine, frame.window, self.cfg.max_deliveries
                ),
            );
            return self.dead_letter(&msg, r).await;
        }
        let ident = match self.setup(&frame.machine) {
            Ok(setup) => self.identify(&msg, frame.clone(), setup).await,
            Err(e) => Err(e),
        };
        let (estimates, inadequate) = match ident {
            Ok(ident) => {
                let est = (drift::estimates(&ident), drift::model_inadequate(&ident));
                let result = WindowResult {
                    fleet_schema: FLEET_SCHEMA,
                    machine: frame.machine.clone(),
                    window: frame.window,
                    t0_s: frame.t0,
                    dt_s: frame.dt,
                    samples: frame.samples() as u64,
                    identification: ident,
                };
                self.publish_result(&result).await?;
                self.stats.windows += 1;
                est
            }
            Err(e) => {
                let r = dead(&frame.machine, Some(frame.window), e.to_string());
                self.publish_error(&r).await?;
                (Vec::new(), None)
            }
        };
        self.observe_drift(&frame, estimates, inadequate).await?;
        if self.cfg.verbose {
            eprintln!(
                "window {} of machine {} (stream seq {stream_seq}, delivery {delivered}) done",
                frame.window, frame.machine
            );
        }
        ack(&msg).await;
        Ok(())
    }

    /// Identify in a blocking thread, telling the server "in progress" meanwhile.
    async fn identify(
        &self,
        msg: &Message,
        frame: Frame,
        setup: Arc<Setup>,
    ) -> Result<Identification, FleetError> {
        let method = self.cfg.method;
        let (machine, window) = (frame.machine.clone(), frame.window);
        let task = tokio::task::spawn_blocking(move || {
            identify_frame(&frame, &setup.knowledge, setup.profile, &method)
        });
        tokio::pin!(task);
        let period = (self.cfg.ack_wait / 3).max(Duration::from_millis(100));
        let mut tick = tokio::time::interval_at(tokio::time::Instant::now() + period, period);
        loop {
            tokio::select! {
                r = &mut task => {
                    return r.unwrap_or_else(|e| Err(FleetError::Internal {
                        machine,
                        window,
                        message: format!("the identification panicked: {e}"),
                    }));
                }
                _ = tick.tick() => {
                    let _ = msg.ack_with(AckKind::Progress).await;
                }
            }
        }
    }

    async fn publish_result(&mut self, r: &WindowResult) -> Result<(), FleetError> {
        let json = serde_json::to_vec(r).map_err(|e| FleetError::Json {
            subject: ident_subject(&r.machine),
            what: "result",
            message: e.to_string(),
        })?;
        let json = Bytes::from(json);
        self.fleet
            .publish(
                &ident_subject(&r.machine),
                &message_id(&r.machine, r.window),
                json.clone(),
            )
            .await?;
        self.store_latest(&r.machine, r.window, json).await
    }

    /// Put `json` under `machine` unless the stored window is the same or newer.
    async fn store_latest(
        &mut self,
        machine: &str,
        window: u64,
        json: Bytes,
    ) -> Result<(), FleetError> {
        #[derive(serde::Deserialize)]
        struct Stored {
            window: u64,
        }
        let op = format!("update {} {machine}", crate::LATEST_BUCKET);
        for _ in 0..1000 {
            let entry = retry(&op, || self.latest.entry(machine)).await?;
            let written = match entry.filter(|e| e.operation == kv::Operation::Put) {
                None => self.latest.create(machine, json.clone()).await.is_ok(),
                Some(e) => {
                    let stored = serde_json::from_slice::<Stored>(&e.value).map(|s| s.window);
                    if matches!(stored, Ok(s) if s >= window) {
                        return Ok(());
                    }
                    self.latest
                        .update(machine, json.clone(), e.revision)
                        .await
                        .is_ok()
                }
            };
            if written {
                return Ok(());
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        Err(FleetError::nats(op, "compare-and-set lost 1000 times"))
    }

    async fn publish_error(&mut self, r: &ErrorRecord) -> Result<(), FleetError> {
        let json = serde_json::to_vec(r).map_err(|e| FleetError::Json {
            subject: error_subject(&r.machine),
            what: "error record",
            message: e.to_string(),
        })?;
        let id = match r.window {
            Some(w) => message_id(&r.machine, w),
            None => format!("{}/raw-{}", r.machine, r.stream_seq),
        };
        if self.cfg.verbose {
            eprintln!("dead-lettered: {}", r.error);
        }
        self.stats.errors += 1;
        self.fleet
            .publish(&error_subject(&r.machine), &id, Bytes::from(json))
            .await
            .map(|_| ())
    }

    async fn dead_letter(&mut self, msg: &Message, r: ErrorRecord) -> Result<(), FleetError> {
        self.publish_error(&r).await?;
        ack(msg).await;
        Ok(())
    }

    /// The drift state of the window's machine, updated by compare-and-set, and its alerts
    /// published.
    async fn observe_drift(
        &mut self,
        frame: &Frame,
        estimates: Vec<drift::Estimate>,
        inadequate: Option<String>,
    ) -> Result<(), FleetError> {
        let machine = &frame.machine;
        let op = format!("update {} {machine}", crate::DRIFT_BUCKET);
        for _ in 0..1000 {
            let entry = retry(&op, || self.drift.entry(machine)).await?;
            let entry = entry.filter(|e| e.operation == kv::Operation::Put);
            let mut state = match &entry {
                Some(e) => serde_json::from_slice(&e.value).unwrap_or_default(),
                None => self.initial_drift(machine),
            };
            let alerts = state.observe(
                machine,
                frame.window,
                frame.t0,
                estimates.clone(),
                &self.cfg.drift,
            );
            let model_alerts =
                state.observe_model(machine, frame.window, frame.t0, inadequate.clone());
            for a in &model_alerts {
                let json = serde_json::to_vec(a).unwrap_or_default();
                let id = format!("{}/model", message_id(machine, a.window));
                self.fleet
                    .publish(&alert_subject(machine), &id, Bytes::from(json))
                    .await?;
                if self.cfg.verbose {
                    eprintln!(
                        "MODEL ALERT machine {machine} windows {} and {}: {}",
                        a.previous_window, a.window, a.message
                    );
                }
            }
            for a in &alerts {
                let json = serde_json::to_vec(a).unwrap_or_default();
                let id = format!("{}/{}", message_id(machine, a.window), a.parameter);
                self.fleet
                    .publish(&alert_subject(machine), &id, Bytes::from(json))
                    .await?;
                if self.cfg.verbose {
                    eprintln!(
                        "ALERT machine {machine} window {}: {} {:+.3} % (z = {:.1})",
                        a.window,
                        a.parameter,
                        100.0 * a.relative_change,
                        a.z
                    );
                }
            }
            let json = Bytes::from(serde_json::to_vec(&state).unwrap_or_default());
            let written = match &entry {
                None => self.drift.create(machine, json).await.is_ok(),
                Some(e) => self.drift.update(machine, json, e.revision).await.is_ok(),
            };
            if written {
                self.stats.alerts += (alerts.len() + model_alerts.len()) as u64;
                return Ok(());
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        Err(FleetError::nats(op, "compare-and-set lost 1000 times"))
    }

    /// A fresh state: the machine's SUMMARY baseline when one is given, else empty.
    fn initial_drift(&self, machine: &str) -> DriftState {
        let Some(dir) = &self.cfg.baselines else {
            return DriftState::default();
        };
        let path = dir.join(format!("{machine}.json"));
        match read_capped(&path).map(|t| serde_json::from_str::<Identification>(&t)) {
            Ok(Ok(summary)) => DriftState::from_summary(&summary),
            Ok(Err(e)) => {
                eprintln!(
                    "machine {machine}: baseline {} is not a summary JSON ({e}); forming \
                     the baseline from the first windows",
                    path.display()
                );
                DriftState::default()
            }
            Err(_) => DriftState::default(),
        }
    }
}

/// Acknowledge `msg` (and have the server confirm); a lost acknowledgement only means the
/// window is done again, with the same result ids.
async fn ack(msg: &Message) {
    for _ in 0..3 {
        if msg.double_ack().await.is_ok() {
            return;
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
}
