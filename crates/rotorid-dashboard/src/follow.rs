//! The NATS side: one connection that retries for ever, and one reader per stream that
//! the workers write (`ROTORID_IDENT` results and error records, `ROTORID_ALERT`,
//! `ROTORID_RAW`), plus `ROTORID_LATEST` at start and the baselines of `ROTORID_DRIFT`.
//!
//! **A reader** is an ephemeral pull consumer without acknowledgements (nothing the
//! dashboard does changes what the workers see), created from a start sequence: at first
//! the last `backfill` messages per subject, about (the stream's last sequence minus
//! `backfill` times its number of subjects), afterwards the sequence after the last one
//! read. Messages arrive in batches of a bounded count, so the client buffers at most that
//! many; a gap in the consumer's sequence (a batch lost with the connection), a missed
//! heartbeat, a server restart or any error makes the reader drop the consumer and create
//! a new one from where it was, after a second. So NATS can be slow or gone for any time:
//! the reader waits and carries on, and the pages show what is wrong meanwhile
//! ([`NatsStatus`]).
//!
//! The dashboard creates no stream and no bucket: it waits for the workers to.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex, RwLock};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use async_nats::jetstream::{self, consumer::pull, consumer::AckPolicy, consumer::DeliverPolicy};
use bytes::Bytes;
use futures_util::StreamExt as _;
use rotorid_fleet::{Frame, ALERT_STREAM, DRIFT_BUCKET, IDENT_STREAM, LATEST_BUCKET, RAW_STREAM};
use serde::Serialize;
use tokio::sync::broadcast;

use crate::raw;
use crate::state::FleetState;

/// What the pages are told changed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Change {
    /// A machine's data or state.
    Machine(String),
    /// The connection to NATS.
    Nats,
}

/// The connection to NATS as the pages show it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NatsStatus {
    /// The servers' URLs, as given (a comma-separated list).
    pub url: String,
    /// The server the dashboard is on (`nats://HOST:PORT (server NAME)`), or was on last
    /// while disconnected; `null` before the first connection.
    pub server: Option<String>,
    /// Connected now.
    pub connected: bool,
    /// Since when (connected or not) \[ms since 1970, UTC\].
    pub since_ms: i64,
    /// What is wrong, per reader (empty when all is well).
    pub problems: BTreeMap<String, String>,
}

/// What the readers and the web server share.
#[derive(Debug)]
pub struct Shared {
    /// The fleet.
    pub state: RwLock<FleetState>,
    /// The connection.
    pub nats: Mutex<NatsStatus>,
    /// Changes, for the pages' event streams.
    pub changes: broadcast::Sender<Change>,
    /// JetStream, once connected (the window summaries are read from `ROTORID_IDENT`).
    pub js: Mutex<Option<jetstream::Context>>,
}

/// Now \[ms since 1970, UTC\].
pub fn now_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// A JetStream timestamp \[ms since 1970, UTC\].
fn ms_of(t: time::OffsetDateTime) -> i64 {
    (t.unix_timestamp_nanos() / 1_000_000) as i64
}

impl Shared {
    /// A fleet with `state` and no connection yet to `url`.
    pub fn new(state: FleetState, url: &str) -> Arc<Self> {
        let (changes, _) = broadcast::channel(4096);
        Arc::new(Self {
            state: RwLock::new(state),
            nats: Mutex::new(NatsStatus {
                url: url.to_owned(),
                server: None,
                connected: false,
                since_ms: now_ms(),
                problems: BTreeMap::from([(
                    "connection".to_owned(),
                    format!("connecting to {url}"),
                )]),
            }),
            changes,
            js: Mutex::new(None),
        })
    }

    /// The connection's status.
    pub fn nats_status(&self) -> NatsStatus {
        self.nats.lock().expect("not poisoned").clone()
    }

    fn set_connected(&self, connected: bool, server: Option<String>) {
        let mut n = self.nats.lock().expect("not poisoned");
        if server.is_some() {
            n.server = server;
        }
        if n.connected != connected {
            n.connected = connected;
            n.since_ms = now_ms();
        }
        if connected {
            n.problems.remove("connection");
        } else {
            let what = match &n.server {
                Some(on) => format!(
                    "NATS server {on} unreachable: reconnecting to any server of {} or its \
                     cluster",
                    n.url
                ),
                None => format!("NATS server {} unreachable: reconnecting", n.url),
            };
            n.problems.insert("connection".into(), what);
        }
        drop(n);
        let _ = self.changes.send(Change::Nats);
    }

    /// Set (or clear, with `None`) the problem of reader `who`.
    fn problem(&self, who: &str, what: Option<String>) {
        let mut n = self.nats.lock().expect("not poisoned");
        let changed = match what {
            Some(w) => n.problems.insert(who.to_owned(), w.clone()) != Some(w),
            None => n.problems.remove(who).is_some(),
        };
        drop(n);
        if changed {
            let _ = self.changes.send(Change::Nats);
        }
    }

    fn changed(&self, id: &str) {
        let _ = self.changes.send(Change::Machine(id.to_owned()));
    }
}

/// How a stream is read.
struct Reader {
    stream: &'static str,
    prefix_len: usize,
    backfill: u64,
    batch: usize,
}

/// Connect to the servers `url` (a comma-separated list; retrying for ever, any of them
/// and of their cluster) and start the readers (module doc); returns at once.
pub async fn start(shared: Arc<Shared>, url: String, raw_backfill: u64) {
    let addrs = match rotorid_fleet::nats::parse_servers(&url) {
        Ok(a) => a,
        Err(e) => {
            shared.problem("connection", Some(e.to_string()));
            return;
        }
    };
    let s = Arc::clone(&shared);
    let cell: Arc<std::sync::OnceLock<async_nats::Client>> = Arc::default();
    let cell2 = Arc::clone(&cell);
    let options = async_nats::ConnectOptions::new()
        .retry_on_initial_connect()
        .max_reconnects(None)
        .retain_servers_order()
        .connection_timeout(Duration::from_secs(2))
        .event_callback(move |e| {
            let (s, cell) = (Arc::clone(&s), Arc::clone(&cell2));
            async move {
                match e {
                    async_nats::Event::Connected => {
                        // which server: the client's INFO of this connection
                        let on = cell
                            .get()
                            .map(|c| rotorid_fleet::nats::describe_server(&c.server_info()));
                        s.set_connected(true, on);
                    }
                    async_nats::Event::Disconnected => s.set_connected(false, None),
                    async_nats::Event::SlowConsumer(_) => s.problem(
                        "client",
                        Some("the dashboard reads messages slower than they come".into()),
                    ),
                    _ => {}
                }
            }
        });
    let client = match options.connect(addrs).await {
        Ok(c) => c,
        Err(e) => {
            shared.problem("connection", Some(format!("NATS {url}: {e}")));
            return;
        }
    };
    let _ = cell.set(client.clone());
    if client.connection_state() == async_nats::connection::State::Connected {
        let on = rotorid_fleet::nats::describe_server(&client.server_info());
        shared.set_connected(true, Some(on));
    }
    // The Connected event can come before the client has the new server's INFO (it then
    // named the server just lost): the server shown follows the client's INFO every second.
    {
        let (s, c) = (Arc::clone(&shared), client.clone());
        tokio::spawn(async move {
            loop {
                tokio::time::sleep(Duration::from_secs(1)).await;
                if c.connection_state() == async_nats::connection::State::Connected {
                    let on = rotorid_fleet::nats::describe_server(&c.server_info());
                    s.set_connected(true, Some(on));
                }
            }
        });
    }
    let mut js = jetstream::new(client.clone());
    js.set_timeout(Duration::from_secs(5));
    *shared.js.lock().expect("not poisoned") = Some(js.clone());
    let history = shared.state.read().expect("not poisoned").settings.history as u64;
    let ident = Reader {
        stream: IDENT_STREAM,
        prefix_len: "rotorid.ident.".len(),
        backfill: history,
        batch: 256,
    };
    tokio::spawn(read_results(Arc::clone(&shared), js.clone(), ident));
    let alert = Reader {
        stream: ALERT_STREAM,
        prefix_len: "rotorid.alert.".len(),
        backfill: crate::state::MAX_ALERTS as u64,
        batch: 256,
    };
    tokio::spawn(read(Arc::clone(&shared), js.clone(), alert, on_alert));
    let raw = Reader {
        stream: RAW_STREAM,
        prefix_len: "rotorid.raw.".len(),
        backfill: raw_backfill.min(history),
        // at most 8 frames (8 x 400 kB with the speed channels) in the client's buffer
        batch: 8,
    };
    tokio::spawn(read(Arc::clone(&shared), js.clone(), raw, on_raw));
    tokio::spawn(baselines(Arc::clone(&shared), js));
    tokio::spawn(tick(shared));
}

/// One message: its subject's machine token, stream sequence, store time and payload.
struct Msg<'a> {
    id: &'a str,
    subject: &'a str,
    seq: u64,
    ms: i64,
    payload: &'a Bytes,
}

fn report(who: &str, r: Result<(), String>) {
    if let Err(e) = r {
        // a bad message is worth a line on the server's log, not a banner on every page
        eprintln!("rotorid dashboard: {who}: {e}");
    }
}

fn on_ident(shared: &Shared, m: Msg<'_>) {
    let r = if m.subject.starts_with("rotorid.ident.") {
        shared
            .state
            .write()
            .expect("not poisoned")
            .apply_result(m.id, m.seq, m.ms, m.payload)
    } else if let Some(id) = m.subject.strip_prefix("rotorid.error.") {
        shared
            .state
            .write()
            .expect("not poisoned")
            .apply_error(id, m.ms, m.payload)
    } else {
        return;
    };
    let ok = r.is_ok();
    report(m.subject, r.map_err(|e| e.to_string()));
    if ok {
        let id = m.subject.rsplit('.').next().unwrap_or("");
        shared.changed(id);
    }
}

fn on_alert(shared: &Shared, m: Msg<'_>) {
    let r = shared
        .state
        .write()
        .expect("not poisoned")
        .apply_alert(m.id, m.ms, m.payload);
    let ok = r.is_ok();
    report(m.subject, r.map_err(|e| e.to_string()));
    if ok {
        shared.changed(m.id);
    }
}

fn on_raw(shared: &Shared, m: Msg<'_>) {
    let frame = match Frame::decode(m.payload) {
        Ok(f) if f.machine == m.id => f,
        Ok(f) => {
            let e = format!("the frame is machine {:?}'s", f.machine);
            return report(m.subject, Err(e));
        }
        Err(e) => return report(m.subject, Err(e.to_string())),
    };
    // the analysis (1X, keyphasors) outside the lock
    let window_s = frame.samples() as f64 * frame.dt;
    let analysed = raw::analyse(&frame);
    drop(frame);
    let r = shared
        .state
        .write()
        .expect("not poisoned")
        .apply_raw(m.id, analysed, window_s);
    let ok = r.is_ok();
    report(m.subject, r.map_err(|e| e.to_string()));
    if ok {
        shared.changed(m.id);
    }
}

/// Read `r.stream` for ever (module doc), giving each message to `handle`.
async fn read(
    shared: Arc<Shared>,
    js: jetstream::Context,
    r: Reader,
    handle: fn(&Shared, Msg<'_>),
) {
    let mut next: Option<u64> = None;
    loop {
        let e = read_from(&shared, &js, &r, &mut next, handle).await;
        shared.problem(r.stream, Some(e));
        tokio::time::sleep(Duration::from_secs(1)).await;
    }
}

/// One consumer's life: returns why it ended.
async fn read_from(
    shared: &Shared,
    js: &jetstream::Context,
    r: &Reader,
    next: &mut Option<u64>,
    handle: fn(&Shared, Msg<'_>),
) -> String {
    let mut stream = match js.get_stream(r.stream).await {
        Ok(s) => s,
        Err(e) => {
            return format!(
                "stream {}: {e} (waiting for a worker or publisher to create it)",
                r.stream
            )
        }
    };
    let start = match *next {
        Some(n) => n,
        None => {
            let (first, last) = match stream.info().await {
                Ok(i) => (i.state.first_sequence, i.state.last_sequence),
                Err(e) => return format!("stream {}: {e}", r.stream),
            };
            let subjects = match stream.info_with_subjects(">").await {
                Ok(mut s) => {
                    let mut n = 0u64;
                    while let Some(Ok(_)) = s.next().await {
                        n += 1;
                    }
                    n
                }
                Err(e) => return format!("stream {}: {e}", r.stream),
            };
            (last + 1)
                .saturating_sub(r.backfill.saturating_mul(subjects.max(1)))
                .max(first)
                .max(1)
        }
    };
    let config = pull::Config {
        deliver_policy: DeliverPolicy::ByStartSequence {
            start_sequence: start,
        },
        ack_policy: AckPolicy::None,
        inactive_threshold: Duration::from_secs(60),
        memory_storage: true,
        ..Default::default()
    };
    let consumer: jetstream::consumer::PullConsumer = match stream.create_consumer(config).await {
        Ok(c) => c,
        Err(e) => return format!("stream {}: creating a reader: {e}", r.stream),
    };
    let name = consumer.cached_info().name.clone();
    let mut messages = match consumer
        .stream()
        .max_messages_per_batch(r.batch)
        .heartbeat(Duration::from_secs(5))
        .expires(Duration::from_secs(30))
        .messages()
        .await
    {
        Ok(m) => m,
        Err(e) => return format!("stream {}: reading: {e}", r.stream),
    };
    shared.problem(r.stream, None);
    let mut expected = 1u64;
    let why = loop {
        let msg = match messages.next().await {
            Some(Ok(m)) => m,
            Some(Err(e)) => break format!("stream {}: {e}", r.stream),
            None => break format!("stream {}: the reader ended", r.stream),
        };
        let Ok(info) = msg.info() else { continue };
        if info.consumer_sequence != expected {
            break format!(
                "stream {}: messages lost in transit ({} after {}): reading again from {}",
                r.stream,
                info.consumer_sequence,
                expected - 1,
                next.unwrap_or(start)
            );
        }
        expected += 1;
        let (seq, ms) = (info.stream_sequence, ms_of(info.published));
        *next = Some(seq + 1);
        let subject = msg.subject.as_str();
        handle(
            shared,
            Msg {
                id: subject.get(r.prefix_len..).unwrap_or(""),
                subject,
                seq,
                ms,
                payload: &msg.payload,
            },
        );
    };
    drop(messages);
    let _ = stream.delete_consumer(&name).await;
    why
}

/// The results: every machine's newest result from `ROTORID_LATEST` first, then
/// `ROTORID_IDENT` for ever ([`read`]).
///
/// The seed is read once, and always before the first message of the stream: a worker
/// stores a window's result before it updates `ROTORID_LATEST`, so every window the seed
/// gives is in the stream at or before the sequence the reader then starts from, and a
/// tile's newest window is never one whose stream copy is yet to be counted in `results`,
/// except the seeded windows themselves until their copies come. (The seed used to be a
/// task of its own: read late, after an outage say, it put a newer window on a tile than
/// the reader had counted.)
async fn read_results(shared: Arc<Shared>, js: jetstream::Context, r: Reader) {
    loop {
        let attempt = tokio::time::timeout(Duration::from_secs(30), seed_latest(&shared, &js));
        let e = match attempt.await {
            Ok(Ok(())) => break,
            Ok(Err(e)) => e,
            Err(_) => format!("bucket {LATEST_BUCKET}: not read within 30 s"),
        };
        shared.problem(LATEST_BUCKET, Some(e));
        tokio::time::sleep(Duration::from_secs(1)).await;
    }
    shared.problem(LATEST_BUCKET, None);
    read(shared, js, r, on_ident).await;
}

/// Read `ROTORID_LATEST`: every machine's newest result. Its keys are listed by the
/// subjects of its stream (one request, paged), not by a key watcher (an ordered consumer
/// that ends only when it sees nothing pending, which a bucket being written may never
/// show). No bucket yet: nothing to read.
async fn seed_latest(shared: &Shared, js: &jetstream::Context) -> Result<(), String> {
    let bucket_stream = format!("KV_{LATEST_BUCKET}");
    let stream = match js.get_stream(&bucket_stream).await {
        Ok(s) => s,
        Err(e) => {
            use async_nats::jetstream::context::GetStreamErrorKind;
            use async_nats::jetstream::ErrorCode;
            return match e.kind() {
                GetStreamErrorKind::JetStream(j)
                    if j.error_code() == ErrorCode::STREAM_NOT_FOUND =>
                {
                    Ok(())
                }
                _ => Err(format!("bucket {LATEST_BUCKET}: {e}")),
            };
        }
    };
    let prefix = format!("$KV.{LATEST_BUCKET}.");
    let mut ids = Vec::new();
    let mut subjects = stream
        .info_with_subjects(format!("{prefix}>"))
        .await
        .map_err(|e| format!("bucket {LATEST_BUCKET}: {e}"))?;
    while let Some(s) = subjects.next().await {
        let (subject, _) = s.map_err(|e| format!("bucket {LATEST_BUCKET}: {e}"))?;
        if let Some(id) = subject.strip_prefix(&prefix) {
            ids.push(id.to_owned());
        }
    }
    let kv = js
        .get_key_value(LATEST_BUCKET)
        .await
        .map_err(|e| format!("bucket {LATEST_BUCKET}: {e}"))?;
    for id in ids {
        if rotorid_fleet::frame::check_machine_id(&id).is_err() {
            continue;
        }
        let entry = kv
            .entry(id.as_str())
            .await
            .map_err(|e| format!("bucket {LATEST_BUCKET} key {id}: {e}"))?;
        let Some(e) = entry.filter(|e| e.operation == async_nats::jetstream::kv::Operation::Put)
        else {
            continue;
        };
        // sequence 0: counted when its stream copy comes; the window's summary is served
        // from memory while it is the newest
        let r = shared.state.write().expect("not poisoned").apply_result(
            &id,
            0,
            ms_of(e.created),
            &e.value,
        );
        if r.is_ok() {
            shared.changed(&id);
        }
    }
    Ok(())
}

/// Every 2 s: the drift baseline of each machine that has none yet and has new windows.
async fn baselines(shared: Arc<Shared>, js: jetstream::Context) {
    let mut checked: HashMap<String, u64> = HashMap::new();
    let mut kv = None;
    loop {
        tokio::time::sleep(Duration::from_secs(2)).await;
        if kv.is_none() {
            kv = js.get_key_value(DRIFT_BUCKET).await.ok();
        }
        let Some(store) = &kv else { continue };
        let due: Vec<(String, u64)> = {
            let st = shared.state.read().expect("not poisoned");
            st.ids()
                .filter(|id| !st.has_baseline(id))
                .filter_map(|id| {
                    let v = st.get(id)?.version;
                    (checked.get(id.as_str()) != Some(&v)).then(|| (id.clone(), v))
                })
                .collect()
        };
        for (id, v) in due {
            let Ok(Some(bytes)) = store.get(id.as_str()).await else {
                checked.insert(id, v);
                continue;
            };
            checked.insert(id.clone(), v);
            if let Ok(d) = serde_json::from_slice::<rotorid_fleet::drift::DriftState>(&bytes) {
                if d.baseline.is_some() {
                    shared
                        .state
                        .write()
                        .expect("not poisoned")
                        .set_baseline(&id, &d);
                    shared.changed(&id);
                }
            }
        }
    }
}

/// Every second: machines whose state changed with time (stale) are announced.
async fn tick(shared: Arc<Shared>) {
    let mut last: HashMap<String, &'static str> = HashMap::new();
    loop {
        tokio::time::sleep(Duration::from_secs(1)).await;
        let now = now_ms();
        let changed: Vec<String> = {
            let st = shared.state.read().expect("not poisoned");
            st.ids()
                .filter_map(|id| {
                    let s = st.state_of(id, now)?;
                    (last.insert(id.clone(), s) != Some(s)).then(|| id.clone())
                })
                .collect()
        };
        for id in changed {
            shared.changed(&id);
        }
    }
}
