//! `rotorid fleet status`: per machine, the windows published, identified, dead-lettered
//! and alerted (subject counts of the streams), the newest result from `ROTORID_LATEST`
//! with its warnings (a `MODEL INADEQUATE` window's withheld values among them) and the
//! last alert (drift or model); for the workers' consumer, the windows pending.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use futures_util::TryStreamExt as _;

use crate::drift;
use crate::error::FleetError;
use crate::nats::Fleet;
use crate::result::{AlertRecord, ModelAlert, WindowResult, MODEL_INADEQUATE};
use rotorid::pipeline::Severity;

/// One machine's line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MachineStatus {
    /// Machine id.
    pub machine: String,
    /// Windows in `ROTORID_RAW`.
    pub published: u64,
    /// Results in `ROTORID_IDENT`.
    pub identified: u64,
    /// Error records in `ROTORID_IDENT`.
    pub errors: u64,
    /// Alerts in `ROTORID_ALERT`.
    pub alerts: u64,
    /// The newest result.
    pub latest: Option<WindowResult>,
    /// The newest alert, when it is a drift alert.
    pub last_alert: Option<AlertRecord>,
    /// The newest alert, when it is a model alert.
    pub last_model_alert: Option<ModelAlert>,
}

/// The workers' consumer.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ConsumerStatus {
    /// Its name.
    pub durable: String,
    /// Windows not yet delivered.
    pub pending: u64,
    /// Windows delivered, not yet acknowledged (being worked on).
    pub ack_pending: u64,
    /// Windows delivered more than once.
    pub redelivered: u64,
    /// Pull requests waiting (about the number of idle workers).
    pub waiting: u64,
}

/// The fleet.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FleetStatus {
    /// Per machine, by id.
    pub machines: Vec<MachineStatus>,
    /// The consumer, when it exists.
    pub consumer: Option<ConsumerStatus>,
}

async fn counts(
    fleet: &Fleet,
    stream: &str,
    filter: &str,
) -> Result<BTreeMap<String, u64>, FleetError> {
    let op = format!("stream info {stream}");
    let mut out = BTreeMap::new();
    let Ok(s) = fleet.js.get_stream(stream).await else {
        return Ok(out);
    };
    let prefix = filter.trim_end_matches('>');
    let mut info = s
        .info_with_subjects(filter)
        .await
        .map_err(|e| FleetError::nats(&op, e))?;
    while let Some((subject, n)) = info
        .try_next()
        .await
        .map_err(|e| FleetError::nats(&op, e))?
    {
        if let Some(id) = subject.strip_prefix(prefix) {
            out.insert(id.to_owned(), n as u64);
        }
    }
    Ok(out)
}

/// Gather the status (module doc) of the consumer `durable`.
pub async fn status(fleet: &Fleet, durable: &str) -> Result<FleetStatus, FleetError> {
    let published = counts(fleet, crate::RAW_STREAM, "rotorid.raw.>").await?;
    let identified = counts(fleet, crate::IDENT_STREAM, "rotorid.ident.>").await?;
    let errors = counts(fleet, crate::IDENT_STREAM, "rotorid.error.>").await?;
    let alerts = counts(fleet, crate::ALERT_STREAM, "rotorid.alert.>").await?;
    let mut ids: Vec<&String> = published
        .keys()
        .chain(identified.keys())
        .chain(errors.keys())
        .collect();
    ids.sort();
    ids.dedup();
    let latest = fleet.js.get_key_value(crate::LATEST_BUCKET).await.ok();
    let alert_stream = fleet.js.get_stream(crate::ALERT_STREAM).await.ok();
    let mut machines = Vec::new();
    for id in ids {
        let mut m = MachineStatus {
            machine: id.clone(),
            published: published.get(id).copied().unwrap_or(0),
            identified: identified.get(id).copied().unwrap_or(0),
            errors: errors.get(id).copied().unwrap_or(0),
            alerts: alerts.get(id).copied().unwrap_or(0),
            ..Default::default()
        };
        if let Some(kv) = &latest {
            if let Ok(Some(v)) = kv.get(id.as_str()).await {
                m.latest = serde_json::from_slice(&v).ok();
            }
        }
        if let (Some(s), true) = (&alert_stream, m.alerts > 0) {
            if let Ok(msg) = s
                .get_last_raw_message_by_subject(&crate::alert_subject(id))
                .await
            {
                m.last_model_alert = serde_json::from_slice::<ModelAlert>(&msg.payload)
                    .ok()
                    .filter(|a| a.kind == MODEL_INADEQUATE);
                if m.last_model_alert.is_none() {
                    m.last_alert = serde_json::from_slice(&msg.payload).ok();
                }
            }
        }
        machines.push(m);
    }
    let mut consumer = None;
    if let Ok(raw) = fleet.js.get_stream(crate::RAW_STREAM).await {
        if let Ok(info) = raw.consumer_info(durable).await {
            consumer = Some(ConsumerStatus {
                durable: durable.to_owned(),
                pending: info.num_pending,
                ack_pending: info.num_ack_pending as u64,
                redelivered: info.num_redelivered as u64,
                waiting: info.num_waiting as u64,
            });
        }
    }
    Ok(FleetStatus { machines, consumer })
}

/// The status as text: one block per machine, parameters with their standard errors in SI
/// units.
pub fn render(s: &FleetStatus) -> String {
    let mut out = String::new();
    match &s.consumer {
        Some(c) => {
            let _ = writeln!(
                out,
                "consumer {}: {} windows pending, {} being worked on, {} redelivered, {} idle \
                 pulls",
                c.durable, c.pending, c.ack_pending, c.redelivered, c.waiting
            );
        }
        None => out.push_str("no worker consumer yet\n"),
    }
    let _ = writeln!(
        out,
        "{} machines\n{:<16} {:>9} {:>10} {:>6} {:>6}  latest",
        s.machines.len(),
        "machine",
        "published",
        "identified",
        "errors",
        "alerts"
    );
    for m in &s.machines {
        let latest = m.latest.as_ref().map_or("-".to_owned(), |r| {
            format!(
                "window {} (t0 = {} s, {})",
                r.window,
                r.t0_s,
                r.identification.method.as_str()
            )
        });
        let _ = writeln!(
            out,
            "{:<16} {:>9} {:>10} {:>6} {:>6}  {latest}",
            m.machine, m.published, m.identified, m.errors, m.alerts
        );
        if let Some(r) = &m.latest {
            for e in drift::estimates(&r.identification) {
                let _ = writeln!(
                    out,
                    "    {:<6} = {:.6e} +- {:.2e} {}",
                    e.parameter, e.value, e.std_error, e.unit
                );
            }
            for d in &r.identification.diagnostics {
                if d.severity == Severity::Warning {
                    let _ = writeln!(out, "    warning: {}", d.message);
                }
            }
        }
        if let Some(a) = &m.last_model_alert {
            let _ = writeln!(
                out,
                "    MODEL ALERT windows {} and {} (t0 = {} s): {}",
                a.previous_window, a.window, a.t0_s, a.message
            );
        }
        if let Some(a) = &m.last_alert {
            let _ = writeln!(
                out,
                "    ALERT window {} (t0 = {} s): {} {:.6e} -> {:.6e} {} ({:+.2} %, z = {:.1})",
                a.window,
                a.t0_s,
                a.parameter,
                a.baseline,
                a.value,
                a.unit,
                100.0 * a.relative_change,
                a.z
            );
        }
    }
    out
}
