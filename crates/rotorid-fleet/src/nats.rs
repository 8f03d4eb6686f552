//! The connection, the streams and buckets (created if absent), and publishing with
//! `Nats-Msg-Id` that waits for the JetStream acknowledgement and retries through a server
//! restart.

use std::time::Duration;

use async_nats::jetstream::{self, kv, stream};
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

/// A connection with its JetStream context.
#[derive(Clone, Debug)]
pub struct Fleet {
    /// The client (reconnects by itself).
    pub client: async_nats::Client,
    /// JetStream on it.
    pub js: jetstream::Context,
}

impl Fleet {
    /// Connect to `url` (e.g. `nats://127.0.0.1:4222`), retrying for up to `wait`.
    pub async fn connect(url: &str, wait: Duration) -> Result<Self, FleetError> {
        let deadline = tokio::time::Instant::now() + wait;
        let client = loop {
            match async_nats::ConnectOptions::new()
                .connection_timeout(Duration::from_secs(2))
                .max_reconnects(None)
                .connect(url)
                .await
            {
                Ok(c) => break c,
                Err(e) if tokio::time::Instant::now() >= deadline => {
                    return Err(FleetError::nats(format!("connect {url}"), e))
                }
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        };
        let mut js = jetstream::new(client.clone());
        js.set_timeout(Duration::from_secs(5));
        Ok(Self { client, js })
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
            ..Default::default()
        };
        retry(&format!("create stream {name}"), || {
            self.js.get_or_create_stream(config.clone())
        })
        .await
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
