//! What the dashboard holds of the fleet, in bounded memory: per machine, a ring of its
//! last [`Settings::history`] windows (window number, t0, arrival time, the stream
//! sequence of the result, value and standard error of every parameter), a ring of as many
//! 1X points, the newest window's thinned samples ([`Orbit`]), the newest result's JSON,
//! the drift baseline, and the last [`MAX_ALERTS`] alerts and [`MAX_ERRORS`] error
//! records. So the memory is bounded by the number of machines (at most
//! [`Settings::max_machines`]) times the rings, whatever the fleet has published.
//!
//! Results are read as generic JSON (the fields below), not as the library's typed
//! `Identification`: the parameters shown are those the result carries, by the name and
//! unit it gives them, so a result with other parameters (another model's `kxz`, ...) is
//! shown as it is.
//!
//! **State of a machine** (worst first): `alert` (an alert on one of its last
//! [`Settings::recent_windows`] windows), `errors` (an error record on one of them),
//! `stale` (no result or error record for [`Settings::stale_windows`] window lengths, or
//! no result yet), `ok`.

use std::collections::{BTreeMap, VecDeque};

use bytes::Bytes;
use rotorid_fleet::drift::DriftState;
use rotorid_fleet::{AlertRecord, ErrorRecord, ModelAlert, MODEL_INADEQUATE};
use serde::{Deserialize, Serialize};

use crate::raw::{OneXPoint, Orbit};

/// Alerts kept per machine.
pub const MAX_ALERTS: usize = 100;
/// Error records kept per machine.
pub const MAX_ERRORS: usize = 20;
/// Parameters (columns) kept per machine; more in a result are not shown.
pub const MAX_PARAMETERS: usize = 32;
/// Longest parameter name or unit kept \[bytes\] (longer ones are cut).
pub const MAX_NAME_LEN: usize = 64;
/// Longest error message kept \[bytes\] (longer ones are cut).
pub const MAX_MESSAGE_LEN: usize = 2000;
/// Largest result JSON kept as the newest summary \[bytes\].
pub const MAX_RESULT_BYTES: usize = 1 << 20;
/// Two-sided 95 % quantile of the normal distribution.
pub const Z95: f64 = 1.959_963_984_540_054;

/// How much the dashboard keeps and when a machine is stale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Windows kept per machine (trend and 1X rings), >= 1.
    pub history: usize,
    /// A machine is stale after this many window lengths without a result (> 0).
    pub stale_windows: f64,
    /// Machines kept; windows of further machines are ignored (and counted).
    pub max_machines: usize,
    /// An alert or error on one of a machine's last this many windows sets its state.
    pub recent_windows: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            history: 3600,
            stale_windows: 5.0,
            max_machines: 1000,
            recent_windows: 10,
        }
    }
}

/// The parts of a result (`WindowResult` JSON, docs/fleet.md) the dashboard reads.
#[derive(Debug, Deserialize)]
struct ResultIn {
    machine: String,
    window: u64,
    t0_s: f64,
    #[serde(default)]
    dt_s: Option<f64>,
    #[serde(default)]
    samples: Option<u64>,
    identification: IdentIn,
}

#[derive(Debug, Deserialize)]
struct IdentIn {
    #[serde(default)]
    method: Option<String>,
    #[serde(default)]
    parameters: Vec<ParamIn>,
}

#[derive(Debug, Deserialize)]
struct ParamIn {
    parameter: String,
    #[serde(default)]
    unit: String,
    #[serde(default)]
    value: Option<f64>,
    #[serde(default)]
    std_error: Option<f64>,
}

/// A parameter's name and SI unit, as the results give them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Column {
    /// Name (`kx`, `m_x`, ...).
    pub name: String,
    /// Unit (`N/m`, ...).
    pub unit: String,
}

/// One window's identified parameters.
#[derive(Debug, Clone, PartialEq)]
struct Point {
    window: u64,
    t0_s: f64,
    arrived_ms: i64,
    /// Sequence of the result in `ROTORID_IDENT`.
    seq: u64,
    /// (value, standard error) per column; NaN where absent, not determined or unknown.
    values: Box<[(f64, f64)]>,
}

/// A parameter value as served.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Value {
    /// Name.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Value, when determined.
    pub value: Option<f64>,
    /// Standard error, when the method gives one.
    pub std_error: Option<f64>,
}

/// An alert as served.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlertView {
    /// When it was stored \[ms since 1970, UTC\].
    pub arrived_ms: i64,
    /// The record (docs/fleet.md), its fields as published.
    #[serde(flatten)]
    pub record: Alert,
}

/// The two records published on `rotorid.alert.<ID>` (docs/fleet.md): a parameter's drift,
/// or two consecutive windows the model does not explain (told apart by `kind`, which only
/// the second has).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Alert {
    /// A parameter moved from its baseline.
    Drift(AlertRecord),
    /// The model does not explain two consecutive windows.
    Model(ModelAlert),
}

impl Alert {
    /// The window that raised it.
    pub fn window(&self) -> u64 {
        match self {
            Alert::Drift(r) => r.window,
            Alert::Model(r) => r.window,
        }
    }

    /// The machine it names.
    fn machine(&self) -> &str {
        match self {
            Alert::Drift(r) => &r.machine,
            Alert::Model(r) => &r.machine,
        }
    }

    /// The record with its texts cut to what a page shows.
    fn cut(self) -> Self {
        match self {
            Alert::Drift(mut r) => {
                r.parameter = cut(&r.parameter, MAX_NAME_LEN);
                r.unit = cut(&r.unit, MAX_NAME_LEN);
                Alert::Drift(r)
            }
            Alert::Model(mut r) => {
                r.kind = cut(&r.kind, MAX_NAME_LEN);
                r.message = cut(&r.message, MAX_ALERT_MESSAGE_LEN);
                Alert::Model(r)
            }
        }
    }
}

/// The longest model alert message kept (bytes; longer ones are cut).
const MAX_ALERT_MESSAGE_LEN: usize = 2048;

/// An error record as served.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorView {
    /// When it was stored \[ms since 1970, UTC\].
    pub arrived_ms: i64,
    /// The window, when the frame was readable.
    pub window: Option<u64>,
    /// The message (cut to [`MAX_MESSAGE_LEN`] bytes).
    pub error: String,
}

/// The newest result of a machine.
#[derive(Debug, Clone)]
struct Latest {
    window: u64,
    t0_s: f64,
    arrived_ms: i64,
    method: Option<String>,
    values: Vec<Value>,
    json: Option<Bytes>,
}

/// One machine (module doc).
#[derive(Debug, Clone, Default)]
pub struct Machine {
    columns: Vec<Column>,
    points: VecDeque<Point>,
    one_x: VecDeque<OneXPoint>,
    orbit: Option<Orbit>,
    latest: Option<Latest>,
    baseline: Option<Vec<Value>>,
    alerts: VecDeque<AlertView>,
    errors: VecDeque<ErrorView>,
    results_seen: u64,
    errors_seen: u64,
    alerts_seen: u64,
    raw_seen: u64,
    /// Newest arrival of a result or error record \[ms\].
    last_arrival_ms: Option<i64>,
    newest_raw_window: Option<u64>,
    /// Window length \[s\] of the newest result (or raw window).
    window_s: Option<f64>,
    /// Bumped on every change.
    pub version: u64,
}

/// A machine's tile on the fleet page.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tile {
    /// Machine id.
    pub id: String,
    /// `alert`, `errors`, `stale` or `ok` (module doc).
    pub state: &'static str,
    /// No result for the stale time (also when the state is worse).
    pub stale: bool,
    /// Newest identified window.
    pub window: Option<u64>,
    /// Its t0 \[s\].
    pub t0_s: Option<f64>,
    /// When its result was stored \[ms since 1970, UTC\].
    pub arrived_ms: Option<i64>,
    /// Window length \[s\].
    pub window_s: Option<f64>,
    /// Method of the newest result.
    pub method: Option<String>,
    /// Its parameters.
    pub parameters: Vec<Value>,
    /// The newest alert.
    pub last_alert: Option<AlertView>,
    /// The newest error record.
    pub last_error: Option<ErrorView>,
    /// Results, error records, alerts and raw windows read since the dashboard started
    /// (including those read back from the streams at start).
    pub results: u64,
    /// Error records read.
    pub errors: u64,
    /// Alerts read.
    pub alerts: u64,
    /// Newest raw window published.
    pub raw_window: Option<u64>,
}

/// One machine's trend, as served (`/api/machines/<ID>/trend`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trend {
    /// Machine id.
    pub id: String,
    /// The parameters, in column order.
    pub parameters: Vec<Column>,
    /// Windows, oldest first.
    pub windows: Vec<TrendPoint>,
    /// The drift baseline per parameter (value, standard error), when known.
    pub baseline: Vec<Value>,
    /// Alerts kept, oldest first.
    pub alerts: Vec<AlertView>,
    /// 1X points, oldest first.
    pub one_x: Vec<OneXPoint>,
    /// Windows the ring holds at most.
    pub history: usize,
}

/// One window of a trend.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrendPoint {
    /// Window number.
    pub window: u64,
    /// t0 \[s\].
    pub t0_s: f64,
    /// Stored \[ms since 1970, UTC\].
    pub arrived_ms: i64,
    /// Value per parameter (column order), null when not determined.
    pub values: Vec<Option<f64>>,
    /// Standard error per parameter, null when none.
    pub std_errors: Vec<Option<f64>>,
}

/// What can be wrong with a message from the bus.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MessageError {
    /// Not the JSON it should be.
    #[error("{subject}: not a valid {what}: {message}")]
    Json {
        /// Its subject.
        subject: String,
        /// What it should be.
        what: &'static str,
        /// The parser's message.
        message: String,
    },
    /// The message names another machine than its subject.
    #[error("{subject}: the message is machine {named:?}'s")]
    WrongMachine {
        /// Its subject.
        subject: String,
        /// The machine it names.
        named: String,
    },
    /// More machines than [`Settings::max_machines`].
    #[error(
        "machine {id}: not shown, the dashboard already shows {max} machines (--max-machines)"
    )]
    TooManyMachines {
        /// The machine.
        id: String,
        /// The limit.
        max: usize,
    },
}

fn cut(s: &str, max: usize) -> String {
    if s.len() <= max {
        return s.to_owned();
    }
    let mut end = max;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &s[..end])
}

fn finite(v: Option<f64>) -> Option<f64> {
    v.filter(|v| v.is_finite())
}

fn rank(state: &str) -> u8 {
    match state {
        "alert" => 0,
        "errors" => 1,
        "stale" => 2,
        _ => 3,
    }
}

impl Machine {
    fn newest_window(&self) -> Option<u64> {
        let r = self.latest.as_ref().map(|l| l.window);
        let e = self.errors.iter().filter_map(|e| e.window).max();
        r.max(e)
    }

    /// The state (module doc) at `now_ms`.
    fn state(&self, s: &Settings, now_ms: i64) -> (&'static str, bool) {
        let stale = match (self.last_arrival_ms, self.window_s, &self.latest) {
            (_, _, None) => true,
            (Some(t), Some(w), Some(_)) => (now_ms - t) as f64 > s.stale_windows * w * 1e3,
            _ => false,
        };
        let newest = self.newest_window().unwrap_or(0);
        let recent = |w: u64| w.saturating_add(s.recent_windows) > newest;
        let state = if self.alerts.iter().any(|a| recent(a.record.window())) {
            "alert"
        } else if self.errors.iter().any(|e| e.window.is_none_or(recent)) {
            "errors"
        } else if stale {
            "stale"
        } else {
            "ok"
        };
        (state, stale)
    }

    fn column(&mut self, name: &str, unit: &str) -> Option<usize> {
        if let Some(i) = self.columns.iter().position(|c| c.name == name) {
            return Some(i);
        }
        if self.columns.len() >= MAX_PARAMETERS {
            return None;
        }
        self.columns.push(Column {
            name: cut(name, MAX_NAME_LEN),
            unit: cut(unit, MAX_NAME_LEN),
        });
        Some(self.columns.len() - 1)
    }

    fn bump(&mut self) {
        self.version += 1;
    }

    /// Approximate bytes held.
    fn bytes(&self) -> usize {
        let point = std::mem::size_of::<Point>() + 16 * self.columns.len();
        let orbit = self.orbit.as_ref().map_or(0, |o| {
            8 * (o.x_um.capacity() + o.z_um.capacity())
                + std::mem::size_of_val(o.keyphasor.as_slice())
        });
        std::mem::size_of::<Self>()
            + point * self.points.capacity()
            + std::mem::size_of::<OneXPoint>() * self.one_x.capacity()
            + orbit
            + self
                .latest
                .as_ref()
                .and_then(|l| l.json.as_ref())
                .map_or(0, Bytes::len)
            + self.alerts.capacity() * (std::mem::size_of::<AlertView>() + 64)
            + self
                .errors
                .iter()
                .map(|e| e.error.len() + 48)
                .sum::<usize>()
    }
}

/// Whether the machine's rings are full (for tests and the bench).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Held {
    /// Machines.
    pub machines: usize,
    /// Windows held in the trend rings, summed over the machines.
    pub windows: usize,
    /// 1X points held, summed.
    pub one_x: usize,
    /// Approximate bytes held by the state.
    pub bytes: usize,
    /// Messages of machines beyond --max-machines, ignored.
    pub ignored: u64,
}

/// The fleet as the dashboard sees it (module doc).
#[derive(Debug, Clone, Default)]
pub struct FleetState {
    /// The limits.
    pub settings: Settings,
    machines: BTreeMap<String, Machine>,
    ignored: u64,
}

impl FleetState {
    /// An empty fleet.
    pub fn new(settings: Settings) -> Self {
        Self {
            settings,
            ..Self::default()
        }
    }

    /// The machine `id`, created when there is room.
    fn machine(&mut self, id: &str) -> Result<&mut Machine, MessageError> {
        if !self.machines.contains_key(id) {
            if self.machines.len() >= self.settings.max_machines {
                self.ignored += 1;
                return Err(MessageError::TooManyMachines {
                    id: id.to_owned(),
                    max: self.settings.max_machines,
                });
            }
            self.machines.insert(id.to_owned(), Machine::default());
        }
        Ok(self.machines.get_mut(id).expect("inserted"))
    }

    /// The machine `id`, if known.
    pub fn get(&self, id: &str) -> Option<&Machine> {
        self.machines.get(id)
    }

    /// Machine ids.
    pub fn ids(&self) -> impl Iterator<Item = &String> {
        self.machines.keys()
    }

    /// A result (JSON `WindowResult`) of machine `id` (its subject's token), stored at
    /// `arrived_ms` with sequence `seq` in `ROTORID_IDENT`.
    pub fn apply_result(
        &mut self,
        id: &str,
        seq: u64,
        arrived_ms: i64,
        json: &Bytes,
    ) -> Result<(), MessageError> {
        let subject = rotorid_fleet::ident_subject(id);
        let r: ResultIn = serde_json::from_slice(json).map_err(|e| MessageError::Json {
            subject: subject.clone(),
            what: "result",
            message: e.to_string(),
        })?;
        if r.machine != id {
            return Err(MessageError::WrongMachine {
                subject,
                named: cut(&r.machine, 80),
            });
        }
        let history = self.settings.history;
        let m = self.machine(id)?;
        let mut values = Vec::new();
        let mut cells = vec![(f64::NAN, f64::NAN); m.columns.len()];
        for p in &r.identification.parameters {
            let (v, se) = (finite(p.value), finite(p.std_error));
            values.push(Value {
                name: cut(&p.parameter, MAX_NAME_LEN),
                unit: cut(&p.unit, MAX_NAME_LEN),
                value: v,
                std_error: se,
            });
            if let Some(c) = m.column(&p.parameter, &p.unit) {
                cells.resize(m.columns.len(), (f64::NAN, f64::NAN));
                cells[c] = (v.unwrap_or(f64::NAN), se.unwrap_or(f64::NAN));
            }
        }
        // sequence 0: read from ROTORID_LATEST at start, counted when its stream copy comes
        m.results_seen += u64::from(seq > 0);
        m.last_arrival_ms = Some(m.last_arrival_ms.map_or(arrived_ms, |t| t.max(arrived_ms)));
        let point = Point {
            window: r.window,
            t0_s: r.t0_s,
            arrived_ms,
            seq,
            values: cells.into_boxed_slice(),
        };
        insert_ring(&mut m.points, point, |p| p.window, history);
        if m.latest.as_ref().is_none_or(|l| r.window >= l.window) {
            if let (Some(dt), Some(n)) = (r.dt_s, r.samples) {
                let w = dt * n as f64;
                if w.is_finite() && w > 0.0 {
                    m.window_s = Some(w);
                }
            }
            m.latest = Some(Latest {
                window: r.window,
                t0_s: r.t0_s,
                arrived_ms,
                method: r.identification.method.map(|s| cut(&s, MAX_NAME_LEN)),
                values,
                json: (json.len() <= MAX_RESULT_BYTES).then(|| json.clone()),
            });
        }
        m.bump();
        Ok(())
    }

    /// An error record (JSON `ErrorRecord`) of machine `id`.
    pub fn apply_error(
        &mut self,
        id: &str,
        arrived_ms: i64,
        json: &[u8],
    ) -> Result<(), MessageError> {
        let subject = rotorid_fleet::error_subject(id);
        let r: ErrorRecord = serde_json::from_slice(json).map_err(|e| MessageError::Json {
            subject,
            what: "error record",
            message: e.to_string(),
        })?;
        let m = self.machine(id)?;
        m.errors_seen += 1;
        m.last_arrival_ms = Some(m.last_arrival_ms.map_or(arrived_ms, |t| t.max(arrived_ms)));
        m.errors.push_back(ErrorView {
            arrived_ms,
            window: r.window,
            error: cut(&r.error, MAX_MESSAGE_LEN),
        });
        if m.errors.len() > MAX_ERRORS {
            m.errors.pop_front();
        }
        m.bump();
        Ok(())
    }

    /// An alert (JSON `AlertRecord`, or `ModelAlert` when it has `kind`) of machine `id`.
    pub fn apply_alert(
        &mut self,
        id: &str,
        arrived_ms: i64,
        json: &[u8],
    ) -> Result<(), MessageError> {
        let subject = rotorid_fleet::alert_subject(id);
        let json_error = |e: serde_json::Error| MessageError::Json {
            subject: subject.clone(),
            what: "alert",
            message: e.to_string(),
        };
        let v: serde_json::Value = serde_json::from_slice(json).map_err(json_error)?;
        let r = if v.get("kind").is_some() {
            let m: ModelAlert = serde_json::from_value(v).map_err(json_error)?;
            if m.kind != MODEL_INADEQUATE {
                return Err(MessageError::Json {
                    subject,
                    what: "alert",
                    message: format!(
                        "kind {:?} is not one this dashboard knows (\"{MODEL_INADEQUATE}\")",
                        cut(&m.kind, 80)
                    ),
                });
            }
            Alert::Model(m)
        } else {
            Alert::Drift(serde_json::from_value(v).map_err(json_error)?)
        };
        if r.machine() != id {
            return Err(MessageError::WrongMachine {
                subject,
                named: cut(r.machine(), 80),
            });
        }
        let r = r.cut();
        let m = self.machine(id)?;
        m.alerts_seen += 1;
        m.alerts.push_back(AlertView {
            arrived_ms,
            record: r,
        });
        if m.alerts.len() > MAX_ALERTS {
            m.alerts.pop_front();
        }
        m.bump();
        Ok(())
    }

    /// A raw window of machine `id`, analysed ([`crate::raw::analyse`]).
    pub fn apply_raw(
        &mut self,
        id: &str,
        analysed: Option<(Orbit, OneXPoint)>,
        window_s: f64,
    ) -> Result<(), MessageError> {
        let history = self.settings.history;
        let m = self.machine(id)?;
        m.raw_seen += 1;
        let Some((orbit, point)) = analysed else {
            m.bump();
            return Ok(());
        };
        let newest = m.newest_raw_window.is_none_or(|w| orbit.window >= w);
        if newest {
            m.newest_raw_window = Some(orbit.window);
            if m.window_s.is_none() && window_s.is_finite() && window_s > 0.0 {
                m.window_s = Some(window_s);
            }
            m.orbit = Some(orbit);
        }
        insert_ring(&mut m.one_x, point, |p| p.window, history);
        m.bump();
        Ok(())
    }

    /// The drift state of machine `id` (`ROTORID_DRIFT`): its baseline.
    pub fn set_baseline(&mut self, id: &str, drift: &DriftState) {
        let Some(m) = self.machines.get_mut(id) else {
            return;
        };
        let Some(base) = &drift.baseline else { return };
        let values: Vec<Value> = base
            .iter()
            .take(MAX_PARAMETERS)
            .map(|e| Value {
                name: cut(&e.parameter, MAX_NAME_LEN),
                unit: cut(&e.unit, MAX_NAME_LEN),
                value: finite(Some(e.value)),
                std_error: finite(Some(e.std_error)),
            })
            .collect();
        if m.baseline.as_ref() != Some(&values) {
            m.baseline = Some(values);
            m.bump();
        }
    }

    /// Whether machine `id` has a baseline.
    pub fn has_baseline(&self, id: &str) -> bool {
        self.machines.get(id).is_some_and(|m| m.baseline.is_some())
    }

    /// The tile of machine `id` at `now_ms`.
    pub fn tile(&self, id: &str, now_ms: i64) -> Option<Tile> {
        let m = self.machines.get(id)?;
        let (state, stale) = m.state(&self.settings, now_ms);
        let l = m.latest.as_ref();
        Some(Tile {
            id: id.to_owned(),
            state,
            stale,
            window: l.map(|l| l.window),
            t0_s: l.map(|l| l.t0_s),
            arrived_ms: l.map(|l| l.arrived_ms),
            window_s: m.window_s,
            method: l.and_then(|l| l.method.clone()),
            parameters: l.map(|l| l.values.clone()).unwrap_or_default(),
            last_alert: m.alerts.back().cloned(),
            last_error: m.errors.back().cloned(),
            results: m.results_seen,
            errors: m.errors_seen,
            alerts: m.alerts_seen,
            raw_window: m.newest_raw_window,
        })
    }

    /// The state of machine `id` at `now_ms` (`alert`, `errors`, `stale`, `ok`).
    pub fn state_of(&self, id: &str, now_ms: i64) -> Option<&'static str> {
        let m = self.machines.get(id)?;
        Some(m.state(&self.settings, now_ms).0)
    }

    /// Every tile, worst state first, then by id.
    pub fn tiles(&self, now_ms: i64) -> Vec<Tile> {
        let mut t: Vec<Tile> = self
            .machines
            .keys()
            .filter_map(|id| self.tile(id, now_ms))
            .collect();
        t.sort_by(|a, b| (rank(a.state), &a.id).cmp(&(rank(b.state), &b.id)));
        t
    }

    /// The trend of machine `id`: windows numbered above `after` (all when `None`), the
    /// last `last` of them.
    pub fn trend(&self, id: &str, after: Option<u64>, last: usize) -> Option<Trend> {
        let m = self.machines.get(id)?;
        let newer = |w: u64| after.is_none_or(|a| w > a);
        let sel: Vec<&Point> = m.points.iter().filter(|p| newer(p.window)).collect();
        let skip = sel.len().saturating_sub(last);
        let windows = sel[skip..]
            .iter()
            .map(|p| {
                let cell = |i: usize| p.values.get(i).copied().unwrap_or((f64::NAN, f64::NAN));
                TrendPoint {
                    window: p.window,
                    t0_s: p.t0_s,
                    arrived_ms: p.arrived_ms,
                    values: (0..m.columns.len())
                        .map(|i| finite(Some(cell(i).0)))
                        .collect(),
                    std_errors: (0..m.columns.len())
                        .map(|i| finite(Some(cell(i).1)))
                        .collect(),
                }
            })
            .collect();
        let ox: Vec<OneXPoint> = m
            .one_x
            .iter()
            .filter(|p| newer(p.window))
            .copied()
            .collect();
        let skip = ox.len().saturating_sub(last);
        Some(Trend {
            id: id.to_owned(),
            parameters: m.columns.clone(),
            windows,
            baseline: m.baseline.clone().unwrap_or_default(),
            alerts: m.alerts.iter().cloned().collect(),
            one_x: ox[skip..].to_vec(),
            history: self.settings.history,
        })
    }

    /// The trend of machine `id` as CSV: one row per window held, the parameters' values
    /// and standard errors with their units in the header, then the 1X vectors.
    pub fn trend_csv(&self, id: &str) -> Option<String> {
        use std::fmt::Write as _;
        let m = self.machines.get(id)?;
        let mut out = String::from("window,t0 [s],stored [ms since 1970 UTC]");
        for c in &m.columns {
            let _ = write!(
                out,
                ",{},{}",
                csv_text(&format!("{} [{}]", c.name, c.unit)),
                csv_text(&format!("{} std_error [{}]", c.name, c.unit))
            );
        }
        out.push_str(
            ",speed [rpm],x 1X amplitude [um],x 1X amplitude std_error [um],x 1X phase lag \
             [deg],x 1X phase lag std_error [deg],z 1X amplitude [um],z 1X amplitude \
             std_error [um],z 1X phase lag [deg],z 1X phase lag std_error [deg]\n",
        );
        let num = |v: Option<f64>| {
            v.filter(|v| v.is_finite())
                .map_or(String::new(), |v| v.to_string())
        };
        let ox: BTreeMap<u64, &OneXPoint> = m.one_x.iter().map(|p| (p.window, p)).collect();
        for p in &m.points {
            let _ = write!(out, "{},{},{}", p.window, p.t0_s, p.arrived_ms);
            for i in 0..m.columns.len() {
                let (v, se) = p.values.get(i).copied().unwrap_or((f64::NAN, f64::NAN));
                let _ = write!(out, ",{},{}", num(Some(v)), num(Some(se)));
            }
            let o = ox.get(&p.window);
            let _ = write!(out, ",{}", num(o.and_then(|o| o.speed_rpm)));
            for v in [o.and_then(|o| o.x), o.and_then(|o| o.z)] {
                let _ = write!(
                    out,
                    ",{},{},{},{}",
                    num(v.map(|v| v.amplitude_um)),
                    num(v.map(|v| v.amplitude_se_um)),
                    num(v.map(|v| v.phase_deg)),
                    num(v.and_then(|v| v.phase_se_deg))
                );
            }
            out.push('\n');
        }
        Some(out)
    }

    /// The newest result's JSON of machine `id`, as the worker published it.
    pub fn latest_json(&self, id: &str) -> Option<Bytes> {
        self.machines.get(id)?.latest.as_ref()?.json.clone()
    }

    /// The `ROTORID_IDENT` sequence of window `window` of machine `id`, while it is held.
    pub fn result_seq(&self, id: &str, window: u64) -> Option<u64> {
        let m = self.machines.get(id)?;
        let i = m.points.binary_search_by_key(&window, |p| p.window).ok()?;
        Some(m.points[i].seq)
    }

    /// The newest window's samples of machine `id`.
    pub fn orbit(&self, id: &str) -> Option<&Orbit> {
        self.machines.get(id)?.orbit.as_ref()
    }

    /// The newest error records of machine `id`, oldest first.
    pub fn errors(&self, id: &str) -> Vec<ErrorView> {
        self.machines
            .get(id)
            .map(|m| m.errors.iter().cloned().collect())
            .unwrap_or_default()
    }

    /// What is held (module doc).
    pub fn held(&self) -> Held {
        Held {
            machines: self.machines.len(),
            windows: self.machines.values().map(|m| m.points.len()).sum(),
            one_x: self.machines.values().map(|m| m.one_x.len()).sum(),
            bytes: self.machines.values().map(Machine::bytes).sum(),
            ignored: self.ignored,
        }
    }
}

/// A CSV field: quoted when it holds a comma, quote or line end.
fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// Put `item` in `ring` (sorted by `key`, at most `cap` long) in order, replacing an item
/// of the same key; the oldest go when it is full (an item older than all of a full ring
/// is dropped).
fn insert_ring<T>(ring: &mut VecDeque<T>, item: T, key: impl Fn(&T) -> u64, cap: usize) {
    let k = key(&item);
    match ring.binary_search_by_key(&k, &key) {
        Ok(i) => ring[i] = item,
        Err(0) if ring.len() >= cap => {}
        Err(i) => {
            if ring.len() >= cap {
                ring.pop_front();
                ring.insert(i - 1, item);
            } else {
                ring.insert(i, item);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(id: &str, w: u64, params: &[(&str, &str, f64, f64)]) -> Bytes {
        let ps: Vec<serde_json::Value> = params
            .iter()
            .map(|(n, u, v, se)| {
                serde_json::json!({"parameter": n, "unit": u, "value": v, "std_error": se,
                                   "determined": true})
            })
            .collect();
        Bytes::from(
            serde_json::to_vec(&serde_json::json!({
                "fleet_schema": 1, "machine": id, "window": w, "t0_s": w as f64,
                "dt_s": 1e-4, "samples": 10000,
                "identification": {"schema": 2, "method": "modulating", "parameters": ps}
            }))
            .unwrap(),
        )
    }

    #[test]
    fn the_ring_keeps_the_newest_windows_in_order_whatever_the_arrival_order() {
        let mut s = FleetState::new(Settings {
            history: 5,
            ..Settings::default()
        });
        let order = [3u64, 1, 0, 2, 9, 4, 8, 5, 7, 6, 0, 12, 11, 10];
        for (i, &w) in order.iter().enumerate() {
            let r = result("a", w, &[("kx", "N/m", w as f64, 1.0)]);
            s.apply_result("a", i as u64 + 1, 1000 * w as i64, &r)
                .unwrap();
        }
        let t = s.trend("a", None, usize::MAX).unwrap();
        let ws: Vec<u64> = t.windows.iter().map(|p| p.window).collect();
        assert_eq!(ws, vec![8, 9, 10, 11, 12]);
        assert_eq!(t.windows[0].values, vec![Some(8.0)]);
        assert_eq!(s.trend("a", Some(10), 1).unwrap().windows.len(), 1);
        assert_eq!(s.trend("a", Some(10), 9).unwrap().windows.len(), 2);
        assert_eq!(s.held().windows, 5);
        // the newest result is the highest window, whatever came last
        assert_eq!(s.tile("a", 12_000).unwrap().window, Some(12));
        assert_eq!(s.result_seq("a", 12), Some(12));
        assert_eq!(s.result_seq("a", 3), None);
    }

    #[test]
    fn memory_is_bounded_by_the_rings() {
        let mut s = FleetState::new(Settings {
            history: 50,
            max_machines: 3,
            ..Settings::default()
        });
        let mut sizes = Vec::new();
        for w in 0..400u64 {
            for id in ["a", "b", "c", "d"] {
                let r = result(id, w, &[("kx", "N/m", 1.0, 0.1), ("m", "kg", 2.0, 0.1)]);
                let got = s.apply_result(id, w, 0, &r);
                assert_eq!(got.is_err(), id == "d", "{got:?}");
            }
            sizes.push(s.held().bytes);
        }
        assert_eq!(s.held().machines, 3);
        assert_eq!(s.held().windows, 150);
        assert_eq!(s.held().ignored, 400);
        assert_eq!(sizes[399], sizes[100], "flat once the rings are full");
    }

    #[test]
    fn parameters_are_those_the_results_carry_and_states_are_ordered_worst_first() {
        let mut s = FleetState::new(Settings::default());
        let r = result(
            "b",
            0,
            &[("kxz", "N/m", 5.0, 0.5), ("<i>", "x&y", 1.0, 0.1)],
        );
        s.apply_result("b", 1, 0, &r).unwrap();
        let t = s.tile("b", 0).unwrap();
        assert_eq!(t.parameters[0].name, "kxz");
        assert_eq!(t.parameters[1].unit, "x&y");
        assert_eq!(t.state, "ok");
        // 1 s windows, stale after 5 s
        assert_eq!(s.tile("b", 5_001).unwrap().state, "stale");
        s.apply_result("a", 2, 0, &result("a", 0, &[])).unwrap();
        let err = br#"{"fleet_schema":1,"machine":"c","window":3,"stream_seq":9,"delivered":1,"error":"boom"}"#;
        s.apply_error("c", 0, err).unwrap();
        let alert = serde_json::json!({"fleet_schema":1,"machine":"a","window":0,"t0_s":0.0,
            "parameter":"kx","unit":"N/m","baseline":1.0,"baseline_std_error":0.1,"value":2.0,
            "std_error":0.1,"change":1.0,"relative_change":1.0,"z":7.0,"previous_z":6.0});
        s.apply_alert("a", 0, &serde_json::to_vec(&alert).unwrap())
            .unwrap();
        let order: Vec<(String, &str)> =
            s.tiles(1000).into_iter().map(|t| (t.id, t.state)).collect();
        assert_eq!(
            order,
            vec![
                ("a".into(), "alert"),
                ("c".into(), "errors"),
                ("b".into(), "ok"),
            ]
        );
        // a model alert (two windows the model does not explain) sets it too, and is served
        // with its own fields
        let model = serde_json::json!({"fleet_schema":1,"kind":"model_inadequate","machine":"b",
            "window":1,"t0_s":1.0,"previous_window":0,"message":"MODEL INADEQUATE: x"});
        s.apply_alert("b", 0, &serde_json::to_vec(&model).unwrap())
            .unwrap();
        let tile = s.tile("b", 1000).unwrap();
        assert_eq!(tile.state, "alert");
        let served = serde_json::to_value(tile.last_alert.unwrap()).unwrap();
        assert_eq!(served["kind"], "model_inadequate");
        assert_eq!(served["previous_window"], 0);
        assert_eq!(served["message"], "MODEL INADEQUATE: x");
        assert!(served.get("parameter").is_none());
        // a drift alert is served with its fields, no kind
        let drift = serde_json::to_value(s.tile("a", 1000).unwrap().last_alert.unwrap()).unwrap();
        assert_eq!(drift["parameter"], "kx");
        assert_eq!(drift["z"], 7.0);
        assert!(drift.get("kind").is_none());
        // an unknown kind is refused, naming it
        let other = serde_json::json!({"fleet_schema":1,"kind":"rub","machine":"b",
            "window":2,"t0_s":2.0,"previous_window":1,"message":""});
        let e = s
            .apply_alert("b", 0, &serde_json::to_vec(&other).unwrap())
            .unwrap_err();
        assert!(e.to_string().contains("\"rub\""), "{e}");
        s.apply_result("b", 2, 0, &result("b", 11, &[])).unwrap();
        // an alert 10 windows back no longer sets the state
        s.apply_result("a", 3, 0, &result("a", 10, &[])).unwrap();
        assert_eq!(s.tile("a", 1000).unwrap().state, "ok");
        // a message naming another machine than its subject is refused
        let e = s
            .apply_result("a", 4, 0, &result("b", 11, &[]))
            .unwrap_err();
        assert!(matches!(e, MessageError::WrongMachine { .. }), "{e}");
        let e = s
            .apply_result("a", 4, 0, &Bytes::from_static(b"{"))
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("rotorid.ident.a: not a valid result"),
            "{e}"
        );
    }

    #[test]
    fn csv_header_carries_units_and_rows_the_values() {
        let mut s = FleetState::new(Settings::default());
        s.apply_result("a", 1, 5, &result("a", 4, &[("k,x", "N/m", 1.5, 0.25)]))
            .unwrap();
        let csv = s.trend_csv("a").unwrap();
        let mut lines = csv.lines();
        let head = lines.next().unwrap();
        assert!(head.starts_with("window,t0 [s],stored [ms since 1970 UTC],\"k,x [N/m]\",\"k,x std_error [N/m]\",speed [rpm]"), "{head}");
        assert_eq!(lines.next().unwrap(), "4,4,5,1.5,0.25,,,,,,,,,");
    }
}
