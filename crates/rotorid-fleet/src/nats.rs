//! The connection, the streams and buckets (created if absent, with the replica count
//! asked for), and publishing with `Nats-Msg-Id` that waits for the JetStream
//! acknowledgement and retries through a server restart or the loss of a cluster node.
//!
//! **Server lists.** Every connection takes a list of servers ([`parse_servers`]: URLs
//! separated by commas, as NATS clients accept them). The first reachable one is used, in
//! the order given (a dead first server costs a refused connection, or the 2 s connection
//! time-out of an unreachable host); once connected, the client also knows every server of
//! the cluster (the servers advertise them) and reconnects to any live one.
//!
//! **Replicas.** [`Fleet::replicas`] (default 1) is the replica count of every stream and
//! bucket the fleet creates (the durable consumers inherit their stream's). A stream that
//! exists already keeps its own count: [`Fleet::replica_shortfalls`] lists those with
//! fewer, and [`Fleet::set_replicas`] changes them.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

use async_nats::jetstream::{self, kv, stream};
use async_nats::ServerAddr;
use bytes::Bytes;

use crate::error::FleetError;
use crate::{ALERT_STREAM, DRIFT_BUCKET, IDENT_STREAM, LATEST_BUCKET, RAW_STREAM};

/// How long results and alerts are de-duplicated by `Nats-Msg-Id`: longer than a worker
/// takes to be declared dead (the consumer's ack wait) and its window redone.
pub const RESULT_DUPLICATE_WINDOW: Duration = Duration::from_secs(3600);
/// How long raw windows are de-duplicated (a publisher's retries).
pub const RAW_DUPLICATE_WINDOW: Duration = Duration::from_secs(600);
/// How long a publish keeps retrying (a server restart takes a few seconds).
pub const PUBLISH_RETRY_FOR: Duration = Duration::from_secs(60);
/// How long [`Fleet::set_replicas`] waits for the new replicas to be current.
pub const REPLICATION_WAIT: Duration = Duration::from_secs(300);
/// Most replicas of a stream (JetStream's own limit).
pub const MAX_REPLICAS: usize = 5;

/// The streams of the fleet, the buckets' streams included (`KV_<bucket>`), in the order
/// they are created.
pub const STREAMS: [&str; 5] = [
    RAW_STREAM,
    IDENT_STREAM,
    ALERT_STREAM,
    "KV_ROTORID_LATEST",
    "KV_ROTORID_DRIFT",
];

/// The servers of a list: URLs separated by commas (`nats://a:4222,nats://b:4222`; a
/// URL without a scheme is `nats://`, without a port 4222), blanks around them ignored.
pub fn parse_servers(list: &str) -> Result<Vec<ServerAddr>, FleetError> {
    let mut out = Vec::new();
    for item in list.split(',') {
        let url = item.trim();
        if url.is_empty() {
            return Err(FleetError::ServerList {
                url: list.to_owned(),
                message: "an empty item".into(),
            });
        }
        let addr = url
            .parse::<ServerAddr>()
            .map_err(|e| FleetError::ServerList {
                url: url.to_owned(),
                message: e.to_string(),
            })?;
        out.push(addr);
    }
    Ok(out)
}

/// The servers of options given one or more times, each a list ([`parse_servers`]), as
/// one comma-separated list.
pub fn join_servers(values: &[String]) -> Result<String, FleetError> {
    let mut all = Vec::new();
    for v in values {
        parse_servers(v)?;
        all.extend(v.split(',').map(|u| u.trim().to_owned()));
    }
    if all.is_empty() {
        return Err(FleetError::ServerList {
            url: String::new(),
            message: "no server given".into(),
        });
    }
    Ok(all.join(","))
}

/// The server a client is on: `nats://HOST:PORT (server NAME)`.
pub fn describe_server(info: &async_nats::ServerInfo) -> String {
    let host = if info.host.contains(':') {
        format!("[{}]", info.host)
    } else {
        info.host.clone()
    };
    format!("nats://{host}:{} (server {})", info.port, info.server_name)
}

/// A stream of the fleet with fewer replicas than asked for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReplicaShortfall {
    /// The stream (`ROTORID_RAW`, `KV_ROTORID_LATEST`, ...).
    pub stream: String,
    /// Its replicas.
    pub replicas: usize,
    /// The replicas asked for.
    pub wanted: usize,
}

/// A connection with its JetStream context.
#[derive(Clone, Debug)]
pub struct Fleet {
    /// The client (reconnects by itself, to any server of the list or the cluster).
    pub client: async_nats::Client,
    /// JetStream on it.
    pub js: jetstream::Context,
    /// Replicas of the streams, buckets and consumers this connection creates (1 to
    /// [`MAX_REPLICAS`]).
    pub replicas: usize,
}

impl Fleet {
    /// Connect to the first reachable server of `servers` (a list, [`parse_servers`];
    /// e.g. `nats://127.0.0.1:4222`), retrying for up to `wait`.
    pub async fn connect(servers: &str, wait: Duration) -> Result<Self, FleetError> {
        Self::connect_options(servers, wait, None).await
    }

    /// [`Fleet::connect`], saying on stderr, as `who: ...` lines, which server it is on
    /// at the start and after every reconnection, and when it has lost its server.
    pub async fn connect_reporting(
        servers: &str,
        wait: Duration,
        who: &'static str,
    ) -> Result<Self, FleetError> {
        Self::connect_options(servers, wait, Some(who)).await
    }

    async fn connect_options(
        servers: &str,
        wait: Duration,
        who: Option<&'static str>,
    ) -> Result<Self, FleetError> {
        let addrs = parse_servers(servers)?;
        let deadline = tokio::time::Instant::now() + wait;
        let cell: Arc<OnceLock<async_nats::Client>> = Arc::new(OnceLock::new());
        // the server it was on, for the line that says it lost it; and whether it did (the
        // first connection is reported below, once connect returns)
        let last: Arc<Mutex<Option<String>>> = Arc::new(Mutex::new(None));
        let lost = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let client = loop {
            let (cell2, list) = (Arc::clone(&cell), servers.to_owned());
            let (last2, lost2) = (Arc::clone(&last), Arc::clone(&lost));
            let options = async_nats::ConnectOptions::new()
                .connection_timeout(Duration::from_secs(2))
                .max_reconnects(None)
                .retain_servers_order()
                .event_callback(move |e| {
                    let (cell, list, last) = (Arc::clone(&cell2), list.clone(), Arc::clone(&last2));
                    let lost = Arc::clone(&lost2);
                    async move {
                        let Some(who) = who else { return };
                        match e {
                            async_nats::Event::Connected => {
                                let was_lost = lost.swap(false, Ordering::SeqCst);
                                if let (true, Some(c)) = (was_lost, cell.get()) {
                                    let on = describe_server(&c.server_info());
                                    eprintln!("{who}: NATS: reconnected, on {on}");
                                    *last.lock().expect("not poisoned") = Some(on);
                                }
                            }
                            async_nats::Event::Disconnected => {
                                lost.store(true, Ordering::SeqCst);
                                let was = last.lock().expect("not poisoned").clone();
                                eprintln!(
                                    "{who}: NATS: lost {}; reconnecting to any server of \
                                     {list} or its cluster",
                                    was.unwrap_or_else(|| "the server".into())
                                );
                            }
                            _ => {}
                        }
                    }
                });
            match options.connect(addrs.clone()).await {
                Ok(c) => break c,
                Err(e) if tokio::time::Instant::now() >= deadline => {
                    return Err(FleetError::nats(format!("connect {servers}"), e))
                }
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        };
        let _ = cell.set(client.clone());
        if let Some(who) = who {
            let on = describe_server(&client.server_info());
            eprintln!("{who}: NATS: on {on}");
            *last.lock().expect("not poisoned") = Some(on);
        }
        let mut js = jetstream::new(client.clone());
        js.set_timeout(Duration::from_secs(5));
        Ok(Self {
            client,
            js,
            replicas: 1,
        })
    }

    /// The same connection, creating what it creates with `replicas` replicas (1 to
    /// [`MAX_REPLICAS`]).
    pub fn with_replicas(mut self, replicas: usize) -> Result<Self, FleetError> {
        check_replicas(replicas)?;
        self.replicas = replicas;
        Ok(self)
    }

    /// The server the client is on now ([`describe_server`]).
    pub fn server(&self) -> String {
        describe_server(&self.client.server_info())
    }

    /// The server's largest message \[bytes\].
    pub fn max_payload(&self) -> usize {
        self.client.server_info().max_payload
    }

    async fn stream(
        &self,
        name: &str,
        subjects: &[&str],
        dup: Duration,
    ) -> Result<stream::Stream, FleetError> {
        let config = stream::Config {
            name: name.to_owned(),
            subjects: subjects.iter().map(|s| (*s).to_owned()).collect(),
            storage: stream::StorageType::File,
            duplicate_window: dup,
            allow_direct: true,
            num_replicas: self.replicas,
            ..Default::default()
        };
        let op = format!("create stream {name}");
        let deadline = tokio::time::Instant::now() + PUBLISH_RETRY_FOR;
        let mut pause = Duration::from_millis(100);
        loop {
            match self.js.get_or_create_stream(config.clone()).await {
                Ok(s) => return Ok(s),
                Err(e) => {
                    use jetstream::context::CreateStreamErrorKind as K;
                    if let K::JetStream(j) = e.kind() {
                        if refused_replicas(j.error_code()) && self.replicas > 1 {
                            return Err(FleetError::Replicas {
                                replicas: self.replicas,
                                stream: name.to_owned(),
                                message: j.to_string(),
                            });
                        }
                    }
                    if tokio::time::Instant::now() >= deadline {
                        return Err(FleetError::nats(op, e));
                    }
                }
            }
            tokio::time::sleep(pause).await;
            pause = (pause * 2).min(Duration::from_secs(2));
        }
    }

    /// The fleet's streams that exist with fewer replicas than [`Fleet::replicas`].
    pub async fn replica_shortfalls(&self) -> Result<Vec<ReplicaShortfall>, FleetError> {
        let mut out = Vec::new();
        for name in STREAMS {
            let info = retry(&format!("stream info {name}"), || async {
                match self.js.get_stream(name).await {
                    Ok(mut s) => s
                        .info()
                        .await
                        .map(|i| Some(i.config.num_replicas))
                        .map_err(|e| e.to_string()),
                    Err(e) if not_found(&e) => Ok(None),
                    Err(e) => Err(e.to_string()),
                }
            })
            .await?;
            if let Some(r) = info.filter(|r| (*r).max(1) < self.replicas) {
                out.push(ReplicaShortfall {
                    stream: name.to_owned(),
                    replicas: r.max(1),
                    wanted: self.replicas,
                });
            }
        }
        Ok(out)
    }

    /// Give every stream of the fleet that exists, and every durable consumer on them,
    /// `replicas` replicas; returns (stream, replicas before) per stream changed. JetStream
    /// copies the data to the new replicas (or drops them) while the fleet runs; this
    /// returns once every stream and durable consumer has its replicas and each is current
    /// (so a node lost right afterwards loses nothing), or fails after
    /// [`REPLICATION_WAIT`].
    pub async fn set_replicas(&self, replicas: usize) -> Result<Vec<(String, usize)>, FleetError> {
        check_replicas(replicas)?;
        let mut changed = Vec::new();
        for name in STREAMS {
            let op = format!("update stream {name}");
            let stream = match self.js.get_stream(name).await {
                Ok(s) => s,
                Err(e) if not_found(&e) => continue,
                Err(e) => return Err(FleetError::nats(op, e)),
            };
            let mut config = stream.cached_info().config.clone();
            let before = config.num_replicas.max(1);
            if before != replicas {
                config.num_replicas = replicas;
                match self.js.update_stream(&config).await {
                    Ok(_) => changed.push((name.to_owned(), before)),
                    Err(e) => {
                        let message = e.to_string();
                        if let jetstream::context::UpdateStreamErrorKind::JetStream(j) = e.kind() {
                            if refused_replicas(j.error_code()) {
                                return Err(FleetError::Replicas {
                                    replicas,
                                    stream: name.to_owned(),
                                    message,
                                });
                            }
                        }
                        return Err(FleetError::nats(op, message));
                    }
                }
            }
            // durable consumers that name their own count (0 follows the stream)
            let names: Vec<String> = {
                use futures_util::StreamExt as _;
                let mut n = stream.consumer_names();
                let mut v = Vec::new();
                while let Some(c) = n.next().await {
                    v.push(c.map_err(|e| FleetError::nats(format!("consumers of {name}"), e))?);
                }
                v
            };
            for c in names {
                let Ok(mut consumer) = stream
                    .get_consumer::<jetstream::consumer::pull::Config>(&c)
                    .await
                else {
                    continue;
                };
                let Ok(info) = consumer.info().await else {
                    continue;
                };
                let mut cc = info.config.clone();
                if cc.durable_name.is_none() || cc.num_replicas == 0 || cc.num_replicas == replicas
                {
                    continue;
                }
                cc.num_replicas = replicas;
                let pull = jetstream::consumer::pull::Config {
                    durable_name: cc.durable_name.clone(),
                    ack_wait: cc.ack_wait,
                    max_deliver: cc.max_deliver,
                    filter_subject: cc.filter_subject.clone(),
                    num_replicas: replicas,
                    ..Default::default()
                };
                stream
                    .create_consumer(pull)
                    .await
                    .map_err(|e| FleetError::nats(format!("update consumer {c} of {name}"), e))?;
            }
        }
        self.wait_replicated(replicas).await?;
        Ok(changed)
    }

    /// Wait until every stream of the fleet and every durable consumer on them has
    /// `replicas` replicas, each current, for up to [`REPLICATION_WAIT`].
    pub async fn wait_replicated(&self, replicas: usize) -> Result<(), FleetError> {
        use futures_util::StreamExt as _;
        let deadline = tokio::time::Instant::now() + REPLICATION_WAIT;
        let complete = |c: &Option<jetstream::stream::ClusterInfo>| match c {
            // a server that is not in a cluster: one replica, itself
            None => replicas == 1,
            Some(c) => {
                c.leader.is_some()
                    && c.replicas.len() + 1 == replicas
                    && c.replicas.iter().all(|r| r.current && !r.offline)
            }
        };
        for name in STREAMS {
            loop {
                let why = match self.js.get_stream(name).await {
                    Err(e) if not_found(&e) => break,
                    Err(e) => e.to_string(),
                    Ok(mut stream) => match stream.info().await {
                        Err(e) => e.to_string(),
                        Ok(i) if !complete(&i.cluster) => "replicas not yet current".into(),
                        Ok(_) => {
                            let mut names = stream.consumer_names();
                            let mut lagging = None;
                            while let Some(c) = names.next().await {
                                let Ok(c) = c else {
                                    lagging = Some("listing its consumers".to_owned());
                                    break;
                                };
                                let info = stream
                                    .get_consumer::<jetstream::consumer::pull::Config>(&c)
                                    .await;
                                let Ok(mut consumer) = info else { continue };
                                match consumer.info().await {
                                    Ok(i) if i.config.durable_name.is_none() => {}
                                    Ok(i) if complete(&i.cluster) => {}
                                    _ => {
                                        lagging = Some(format!("consumer {c} not yet current"));
                                        break;
                                    }
                                }
                            }
                            match lagging {
                                None => break,
                                Some(w) => w,
                            }
                        }
                    },
                };
                if tokio::time::Instant::now() >= deadline {
                    return Err(FleetError::nats(
                        format!("replicate stream {name} to {replicas}"),
                        format!("{why} after {} s", REPLICATION_WAIT.as_secs()),
                    ));
                }
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
        }
        Ok(())
    }

    /// `ROTORID_RAW` (`rotorid.raw.>`).
    pub async fn raw_stream(&self) -> Result<stream::Stream, FleetError> {
        self.stream(RAW_STREAM, &["rotorid.raw.>"], RAW_DUPLICATE_WINDOW)
            .await
    }

    /// `ROTORID_IDENT` (`rotorid.ident.>`, `rotorid.error.>`).
    pub async fn ident_stream(&self) -> Result<stream::Stream, FleetError> {
        self.stream(
            IDENT_STREAM,
            &["rotorid.ident.>", "rotorid.error.>"],
            RESULT_DUPLICATE_WINDOW,
        )
        .await
    }

    /// `ROTORID_ALERT` (`rotorid.alert.>`).
    pub async fn alert_stream(&self) -> Result<stream::Stream, FleetError> {
        self.stream(ALERT_STREAM, &["rotorid.alert.>"], RESULT_DUPLICATE_WINDOW)
            .await
    }

    async fn bucket(&self, name: &str) -> Result<kv::Store, FleetError> {
        retry(&format!("open bucket {name}"), || async {
            match self.js.get_key_value(name).await {
                Ok(s) => Ok(s),
                Err(_) => self
                    .js
                    .create_key_value(kv::Config {
                        bucket: name.to_owned(),
                        history: 1,
                        storage: stream::StorageType::File,
                        num_replicas: self.replicas,
                        ..Default::default()
                    })
                    .await
                    .map_err(|e| e.to_string()),
            }
        })
        .await
    }

    /// `ROTORID_LATEST`.
    pub async fn latest(&self) -> Result<kv::Store, FleetError> {
        self.bucket(LATEST_BUCKET).await
    }

    /// `ROTORID_DRIFT`.
    pub async fn drift(&self) -> Result<kv::Store, FleetError> {
        self.bucket(DRIFT_BUCKET).await
    }

    /// Publish `payload` on `subject` with `Nats-Msg-Id` `id` and wait for JetStream's
    /// acknowledgement, retrying (same id: the server drops a copy it already has) for up
    /// to [`PUBLISH_RETRY_FOR`]. Returns whether the server had it already.
    pub async fn publish(
        &self,
        subject: &str,
        id: &str,
        payload: Bytes,
    ) -> Result<bool, FleetError> {
        let ack = retry(&format!("publish {subject} ({id})"), || async {
            let p = jetstream::context::Publish::build()
                .payload(payload.clone())
                .message_id(id);
            self.js.send_publish(subject.to_owned(), p).await?.await
        })
        .await?;
        Ok(ack.duplicate)
    }
}

/// Whether the servers refused a stream for its replica count (for good: retrying does not
/// help).
fn refused_replicas(code: jetstream::ErrorCode) -> bool {
    // replicas > 1 on a server not in a cluster; fewer JetStream servers than replicas
    // (insufficient resources on creation, no suitable peers on an update); replicas not
    // updatable (old servers)
    use jetstream::ErrorCode as C;
    [
        C::STREAM_REPLICAS_NOT_SUPPORTED,
        C::INSUFFICIENT_RESOURCES,
        C::CLUSTER_NO_PEERS,
        C::STREAM_REPLICAS_NOT_UPDATABLE,
    ]
    .contains(&code)
}

/// Whether `e` says there is no such stream.
fn not_found(e: &jetstream::context::GetStreamError) -> bool {
    matches!(e.kind(), jetstream::context::GetStreamErrorKind::JetStream(j)
        if j.error_code() == jetstream::ErrorCode::STREAM_NOT_FOUND)
}

/// `replicas` in 1 ..= [`MAX_REPLICAS`].
pub fn check_replicas(replicas: usize) -> Result<(), FleetError> {
    if (1..=MAX_REPLICAS).contains(&replicas) {
        Ok(())
    } else {
        Err(FleetError::ReplicasRange {
            replicas,
            allowed: "1 ..= 5 (JetStream's most; 3 on a 3-node cluster survives one node lost)",
        })
    }
}

/// Run `f` until it succeeds, for up to [`PUBLISH_RETRY_FOR`], backing off 100 ms .. 2 s.
pub async fn retry<T, E, F, Fut>(operation: &str, mut f: F) -> Result<T, FleetError>
where
    E: std::fmt::Display,
    F: FnMut() -> Fut,
    Fut: std::future::Future<Output = Result<T, E>>,
{
    let deadline = tokio::time::Instant::now() + PUBLISH_RETRY_FOR;
    let mut pause = Duration::from_millis(100);
    loop {
        match f().await {
            Ok(v) => return Ok(v),
            Err(e) if tokio::time::Instant::now() >= deadline => {
                return Err(FleetError::nats(operation, e))
            }
            Err(_) => {
                tokio::time::sleep(pause).await;
                pause = (pause * 2).min(Duration::from_secs(2));
            }
        }
    }
}
