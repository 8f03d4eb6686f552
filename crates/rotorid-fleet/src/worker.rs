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

use async_nats::jetstream::consumer::{pull, DeliverPolicy, PullConsumer};
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
use crate::{alert_subject, error_subject, ident_subject, message_id, RAW_STREAM};

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
    let config = consumer_config(cfg, 0);
    retry(&format!("create consumer {}", cfg.durable), || {
        raw.get_or_create_consumer(&cfg.durable, config.clone())
    })
    .await
}

/// The workers' consumer, delivering from stream sequence `start` (0: from the first).
fn consumer_config(cfg: &WorkerConfig, start: u64) -> pull::Config {
    pull::Config {
        durable_name: Some(cfg.durable.clone()),
        ack_wait: cfg.ack_wait,
        max_deliver: -1,
        filter_subject: "rotorid.raw.>".into(),
        deliver_policy: if start > 1 {
            DeliverPolicy::ByStartSequence {
                start_sequence: start,
            }
        } else {
            DeliverPolicy::All
        },
        ..Default::default()
    }
}

/// Run a worker until `shutdown` resolves (module doc): [`prepare`], then
/// [`run_prepared`].
pub async fn run(
    fleet: &Fleet,
    cfg: &WorkerConfig,
    shutdown: impl Future<Output = ()>,
) -> Result<WorkerStats, FleetError> {
    let consumer = prepare(fleet, cfg).await?;
    run_prepared(fleet, cfg, consumer, shutdown).await
}

/// Run a worker on `consumer`, the one [`prepare`] made, until `shutdown` resolves. A
/// caller that prepared (to fail at once on a bad setup, then say it is waiting) hands
/// the consumer over rather than asking for it again: from then on a consumer that loses
/// its leader is the watch's to re-create ([`ConsumerWatch`]), not a start-up error.
pub async fn run_prepared(
    fleet: &Fleet,
    cfg: &WorkerConfig,
    mut consumer: PullConsumer,
    shutdown: impl Future<Output = ()>,
) -> Result<WorkerStats, FleetError> {
    let raw = fleet.raw_stream().await?;
    let mut watch = ConsumerWatch::new(
        tokio::time::Instant::now().into_std(),
        consumer.cached_info().ack_floor.stream_sequence,
    );
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
        let now = tokio::time::Instant::now().into_std();
        match watch.step(now) {
            Step::Pull => {}
            Step::Probe => {
                let probe = tokio::select! {
                    _ = &mut shutdown => break,
                    p = probe_consumer(fleet, &cfg.durable) => p,
                };
                let now = tokio::time::Instant::now().into_std();
                match probe {
                    Probe::Alive { ack_floor } => watch.answered(now, Some(ack_floor)),
                    Probe::Gone => {
                        eprintln!(
                            "worker: consumer {} of {RAW_STREAM} is gone; re-creating it",
                            cfg.durable
                        );
                        watch.gone(now);
                    }
                    Probe::Unanswered(why) => {
                        if watch.unanswered(now) {
                            eprintln!(
                                "worker: consumer {} of {RAW_STREAM} does not answer ({why}); \
                                 asking again",
                                cfg.durable
                            );
                        }
                    }
                }
                continue;
            }
            Step::Recreate { start } => {
                // another worker may have re-created it meanwhile: then it answers
                let probe = tokio::select! {
                    _ = &mut shutdown => break,
                    p = probe_consumer(fleet, &cfg.durable) => p,
                };
                if let Probe::Alive { ack_floor } = probe {
                    let now = tokio::time::Instant::now().into_std();
                    watch.answered(now, Some(ack_floor));
                    eprintln!(
                        "worker: consumer {} of {RAW_STREAM} answers again",
                        cfg.durable
                    );
                    continue;
                }
                let now = tokio::time::Instant::now().into_std();
                eprintln!(
                    "worker: consumer {} of {RAW_STREAM} unanswered or gone for {} s; \
                     re-creating it from stream sequence {start} (windows after the last \
                     acknowledged one may be done again, with the same result ids)",
                    cfg.durable,
                    watch.failing_for(now).as_secs()
                );
                let made = tokio::select! {
                    _ = &mut shutdown => break,
                    r = recreate_consumer(&raw, cfg, start) => r,
                };
                let now = tokio::time::Instant::now().into_std();
                match made {
                    Ok(c) => {
                        consumer = c;
                        watch.recreated(now, true);
                        eprintln!(
                            "worker: consumer {} of {RAW_STREAM} re-created; waiting for windows",
                            cfg.durable
                        );
                    }
                    Err(e) => {
                        let pause = watch.recreated(now, false);
                        eprintln!(
                            "worker: re-creating consumer {} of {RAW_STREAM} failed ({e}); \
                             trying again in {} s",
                            cfg.durable,
                            pause.as_secs_f64()
                        );
                    }
                }
                continue;
            }
        }
        let msg = tokio::select! {
            _ = &mut shutdown => break,
            m = next_message(&consumer) => m,
        };
        let Some(msg) = msg else { continue };
        watch.answered(tokio::time::Instant::now().into_std(), None);
        w.handle(msg).await?;
    }
    Ok(w.stats)
}

/// How often a worker asks its consumer's leader how it is (and how far the windows are
/// acknowledged), whether or not windows come.
pub const PROBE_EVERY: Duration = Duration::from_secs(5);
/// How long the consumer may stay unanswered (no leader: its replicas lost or an election
/// that never ends) before the worker re-creates it.
pub const UNANSWERED_FOR: Duration = Duration::from_secs(15);
/// Longest pause between attempts to re-create the consumer.
pub const RECREATE_BACKOFF_MAX: Duration = Duration::from_secs(30);

/// What a probe of the consumer found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Probe {
    /// Its leader answered; every window up to stream sequence `ack_floor` is acknowledged.
    Alive {
        /// The stream sequence of the acknowledgement floor.
        ack_floor: u64,
    },
    /// The servers say there is no such consumer (deleted, or lost with its replicas).
    Gone,
    /// Nobody answered (no leader), or an error that is not "not found".
    Unanswered(String),
}

/// What the worker does next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Pull the next window.
    Pull,
    /// Ask the consumer how it is.
    Probe,
    /// Delete and create the consumer again, delivering from stream sequence `start`.
    Recreate {
        /// The first stream sequence the new consumer delivers.
        start: u64,
    },
}

/// The worker's watch on its consumer: a worker never waits silently on a consumer that
/// has no leader or no longer exists. It probes the consumer every [`PROBE_EVERY`]; when
/// the consumer is gone, or unanswered for [`UNANSWERED_FOR`], it re-creates it from just
/// after the last acknowledgement floor it saw (a window after it may be done again, which
/// the results' message ids make harmless), retrying with a doubling pause up to
/// [`RECREATE_BACKOFF_MAX`]. Pure (times are given), so that its decisions are tested
/// without a server.
#[derive(Debug, Clone)]
pub struct ConsumerWatch {
    last_probe: std::time::Instant,
    failing_since: Option<std::time::Instant>,
    gone: bool,
    ack_floor: u64,
    backoff: Duration,
    next_attempt: Option<std::time::Instant>,
}

impl ConsumerWatch {
    /// A watch on a consumer just created or bound at `now`, acknowledged up to `ack_floor`.
    pub fn new(now: std::time::Instant, ack_floor: u64) -> Self {
        Self {
            last_probe: now,
            failing_since: None,
            gone: false,
            ack_floor,
            backoff: Duration::from_secs(1),
            next_attempt: None,
        }
    }

    /// What to do at `now`.
    pub fn step(&self, now: std::time::Instant) -> Step {
        if let Some(since) = self.failing_since {
            let due = self.next_attempt.is_none_or(|t| now >= t);
            if due && (self.gone || now.saturating_duration_since(since) >= UNANSWERED_FOR) {
                return Step::Recreate {
                    start: self.ack_floor + 1,
                };
            }
        }
        if now.saturating_duration_since(self.last_probe) >= PROBE_EVERY {
            Step::Probe
        } else {
            Step::Pull
        }
    }

    /// The consumer answered at `now` (a probe, with its acknowledgement floor, or a window).
    pub fn answered(&mut self, now: std::time::Instant, ack_floor: Option<u64>) {
        if let Some(f) = ack_floor {
            self.ack_floor = self.ack_floor.max(f);
            self.last_probe = now;
        }
        self.failing_since = None;
        self.gone = false;
        self.backoff = Duration::from_secs(1);
        self.next_attempt = None;
    }

    /// A probe at `now` was not answered; true when this starts a spell of failures.
    pub fn unanswered(&mut self, now: std::time::Instant) -> bool {
        self.last_probe = now;
        let first = self.failing_since.is_none();
        self.failing_since.get_or_insert(now);
        first
    }

    /// A probe at `now` found no such consumer.
    pub fn gone(&mut self, now: std::time::Instant) {
        self.unanswered(now);
        self.gone = true;
    }

    /// How long the consumer has been failing at `now`.
    pub fn failing_for(&self, now: std::time::Instant) -> Duration {
        self.failing_since
            .map_or(Duration::ZERO, |t| now.saturating_duration_since(t))
    }

    /// A re-creation ended at `now`; when it failed, returns the pause before the next one.
    pub fn recreated(&mut self, now: std::time::Instant, ok: bool) -> Duration {
        if ok {
            self.answered(now, None);
            self.last_probe = now;
            return Duration::ZERO;
        }
        let pause = self.backoff;
        self.last_probe = now;
        self.next_attempt = Some(now + pause);
        self.backoff = (self.backoff * 2).min(RECREATE_BACKOFF_MAX);
        pause
    }
}

/// Ask the consumer's leader for its state (answered by the leader only: a consumer
/// without one does not answer).
async fn probe_consumer(fleet: &Fleet, durable: &str) -> Probe {
    use async_nats::jetstream::response::Response;
    let subject = format!("CONSUMER.INFO.{RAW_STREAM}.{durable}");
    match fleet
        .js
        .request::<_, _, Response<async_nats::jetstream::consumer::Info>>(
            subject,
            &serde_json::json!({}),
        )
        .await
    {
        Ok(Response::Ok(info)) => Probe::Alive {
            ack_floor: info.ack_floor.stream_sequence,
        },
        Ok(Response::Err { error })
            if error.error_code() == async_nats::jetstream::ErrorCode::CONSUMER_NOT_FOUND =>
        {
            Probe::Gone
        }
        Ok(Response::Err { error }) => Probe::Unanswered(error.to_string()),
        Err(e) => Probe::Unanswered(e.to_string()),
    }
}

/// Delete the consumer (its state went with its leader) and create it again, delivering
/// from stream sequence `start`; a consumer another worker made meanwhile is bound instead.
async fn recreate_consumer(
    raw: &async_nats::jetstream::stream::Stream,
    cfg: &WorkerConfig,
    start: u64,
) -> Result<PullConsumer, String> {
    use async_nats::jetstream::stream::ConsumerErrorKind;
    match raw.delete_consumer(&cfg.durable).await {
        // deleted, or the servers answered (e.g. it is gone already)
        Ok(_) => {}
        Err(e) if matches!(e.kind(), ConsumerErrorKind::JetStream(_)) => {}
        Err(e) => return Err(format!("delete: {e}")),
    }
    raw.get_or_create_consumer(&cfg.durable, consumer_config(cfg, start))
        .await
        .map_err(|e| format!("create: {e}"))
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    fn at(t0: Instant, s: f64) -> Instant {
        t0 + Duration::from_secs_f64(s)
    }

    #[test]
    fn a_healthy_consumer_is_pulled_from_and_probed_now_and_then() {
        let t0 = Instant::now();
        let mut w = ConsumerWatch::new(t0, 7);
        assert_eq!(w.step(at(t0, 1.0)), Step::Pull);
        assert_eq!(w.step(at(t0, 5.0)), Step::Probe);
        w.answered(at(t0, 5.1), Some(12));
        assert_eq!(w.step(at(t0, 6.0)), Step::Pull);
        // windows arriving do not stop the probes (they keep the floor recent)
        w.answered(at(t0, 9.0), None);
        assert_eq!(w.step(at(t0, 10.2)), Step::Probe);
    }

    #[test]
    fn an_unanswered_consumer_is_recreated_after_the_floor_it_had_and_not_before() {
        let t0 = Instant::now();
        let mut w = ConsumerWatch::new(t0, 3);
        w.answered(at(t0, 5.0), Some(9));
        assert!(w.unanswered(at(t0, 15.0)), "a spell of failures starts");
        assert_eq!(w.step(at(t0, 16.0)), Step::Pull);
        assert_eq!(w.step(at(t0, 20.0)), Step::Probe);
        assert!(!w.unanswered(at(t0, 25.0)), "the same spell");
        assert_eq!(w.step(at(t0, 29.9)), Step::Pull, "not yet 15 s unanswered");
        // 15 s unanswered: re-create from just after the floor
        assert_eq!(w.step(at(t0, 30.0)), Step::Recreate { start: 10 });
        assert_eq!(w.failing_for(at(t0, 30.0)), Duration::from_secs(15));
        // a probe answering in between ends the spell
        w.answered(at(t0, 30.0), Some(11));
        assert_eq!(w.step(at(t0, 31.0)), Step::Pull);
        assert_eq!(w.failing_for(at(t0, 31.0)), Duration::ZERO);
    }

    #[test]
    fn a_gone_consumer_is_recreated_at_once_and_failures_back_off() {
        let t0 = Instant::now();
        let mut w = ConsumerWatch::new(t0, 0);
        w.gone(at(t0, 5.0));
        assert_eq!(w.step(at(t0, 5.0)), Step::Recreate { start: 1 });
        let pauses: Vec<f64> = (0..7)
            .map(|i| {
                w.recreated(at(t0, 10.0 * f64::from(i)), false)
                    .as_secs_f64()
            })
            .collect();
        assert_eq!(pauses, [1.0, 2.0, 4.0, 8.0, 16.0, 30.0, 30.0]);
        // not again before the pause is over
        assert_ne!(w.step(at(t0, 60.0 + 29.0)), Step::Recreate { start: 1 });
        assert_eq!(w.step(at(t0, 90.0)), Step::Recreate { start: 1 });
        assert_eq!(w.recreated(at(t0, 91.0), true), Duration::ZERO);
        assert_eq!(w.step(at(t0, 92.0)), Step::Pull);
        // the next spell starts from a short pause again
        w.gone(at(t0, 100.0));
        assert_eq!(w.recreated(at(t0, 100.0), false), Duration::from_secs(1));
    }
}
