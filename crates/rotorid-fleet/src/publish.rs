//! Send a machine's windows to `ROTORID_RAW`: each [`Frame`] on `rotorid.raw.<ID>` with
//! `Nats-Msg-Id = <ID>/<window>`, each publish acknowledged by JetStream before the next
//! (retried through a server restart; a copy the server already has is dropped), at the
//! recording's own pace or as fast as the server takes them.

use std::time::Duration;

use bytes::Bytes;

use crate::error::FleetError;
use crate::frame::Frame;
use crate::nats::Fleet;
use crate::{message_id, raw_subject};

/// How fast windows are sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rate {
    /// Window k is sent when its last sample would have been measured: at
    /// start + (t0_k + n_k dt - t0_0) of wall time.
    Realtime,
    /// As fast as the acknowledgements come.
    Max,
}

/// What a publish did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PublishReport {
    /// Windows acknowledged by the server.
    pub windows: u64,
    /// Of which the server already had (same `Nats-Msg-Id`).
    pub duplicates: u64,
    /// Frame bytes sent.
    pub bytes: u64,
}

/// Publish `frames` (module doc); `each` is called after each acknowledged window.
pub async fn publish_frames(
    fleet: &Fleet,
    frames: &[Frame],
    rate: Rate,
    mut each: impl FnMut(&Frame),
) -> Result<PublishReport, FleetError> {
    fleet.raw_stream().await?;
    let max_payload = fleet.max_payload();
    let start = tokio::time::Instant::now();
    let first_t0 = frames.first().map_or(0.0, |f| f.t0);
    let mut report = PublishReport::default();
    for f in frames {
        let bytes = f.encode().map_err(|e| FleetError::Frame {
            subject: raw_subject(&f.machine),
            stream_seq: 0,
            source: e,
        })?;
        if bytes.len() > max_payload {
            return Err(FleetError::TooLarge {
                machine: f.machine.clone(),
                window: f.window,
                bytes: bytes.len(),
                max_payload,
            });
        }
        if rate == Rate::Realtime {
            let due = f.t0 + f.samples() as f64 * f.dt - first_t0;
            if due.is_finite() && due > 0.0 {
                tokio::time::sleep_until(start + Duration::from_secs_f64(due)).await;
            }
        }
        report.bytes += bytes.len() as u64;
        let dup = fleet
            .publish(
                &raw_subject(&f.machine),
                &message_id(&f.machine, f.window),
                Bytes::from(bytes),
            )
            .await?;
        report.windows += 1;
        report.duplicates += u64::from(dup);
        each(f);
    }
    Ok(report)
}
