//! The web server: the two pages, their assets (embedded in the binary), the JSON API, the
//! event stream; read-only (GET and HEAD only, anything else 405), with an access token
//! when one is set, and otherwise only for requests addressed to a loopback host name (so
//! a web page elsewhere cannot reach the dashboard through DNS rebinding).

use std::convert::Infallible;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

use axum::body::Body;
use axum::extract::{Path, RawQuery, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, Method, StatusCode};
use axum::middleware::{self, Next};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use serde::Serialize;
use subtle::ConstantTimeEq as _;
use tokio::sync::broadcast::error::RecvError;

use crate::follow::{now_ms, Change, Shared};

/// Most event streams open at once (pages); further ones get 503.
pub const MAX_EVENT_STREAMS: usize = 64;
/// The cookie that carries the token after a first `?token=` load.
pub const TOKEN_COOKIE: &str = "rotorid_token";

/// The server's state.
pub struct App {
    /// The fleet and the connection.
    pub shared: Arc<Shared>,
    /// The access token, when one is required.
    pub token: Option<String>,
    /// Event streams open.
    streams: AtomicUsize,
}

impl App {
    /// The server of `shared`, requiring `token` when given.
    pub fn new(shared: Arc<Shared>, token: Option<String>) -> Arc<Self> {
        Arc::new(Self {
            shared,
            token,
            streams: AtomicUsize::new(0),
        })
    }
}

/// The embedded assets: path, content type, bytes.
const ASSETS: &[(&str, &str, &str)] = &[
    (
        "app.css",
        "text/css; charset=utf-8",
        include_str!("../assets/app.css"),
    ),
    (
        "common.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/common.js"),
    ),
    (
        "plot.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/plot.js"),
    ),
    (
        "fleet.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/fleet.js"),
    ),
    (
        "machine.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/machine.js"),
    ),
];
const FLEET_PAGE: &str = include_str!("../assets/fleet.html");
const MACHINE_PAGE: &str = include_str!("../assets/machine.html");
const FAVICON: &str = include_str!("../assets/favicon.svg");

/// The router (module doc).
pub fn router(app: Arc<App>) -> Router {
    Router::new()
        .route("/", get(|| async { html(FLEET_PAGE) }))
        .route("/machine/{id}", get(machine_page))
        .route("/assets/{file}", get(asset))
        .route(
            "/favicon.svg",
            get(|| async { typed("image/svg+xml", FAVICON.into()) }),
        )
        .route("/api/status", get(status))
        .route("/api/machines", get(machines))
        .route("/api/machines/{id}", get(machine))
        .route("/api/machines/{id}/trend", get(trend))
        .route("/api/machines/{id}/trend.csv", get(trend_csv))
        .route("/api/machines/{id}/summary", get(latest_summary))
        .route(
            "/api/machines/{id}/windows/{window}/summary",
            get(window_summary),
        )
        .route("/api/machines/{id}/orbit", get(orbit))
        .route("/api/events", get(events))
        .fallback(|| async { problem(StatusCode::NOT_FOUND, "no such page".into()) })
        .layer(middleware::from_fn_with_state(Arc::clone(&app), guard))
        .with_state(app)
}

fn typed(content_type: &'static str, body: Body) -> Response {
    let mut r = Response::new(body);
    r.headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    r
}

fn html(page: &'static str) -> Response {
    typed("text/html; charset=utf-8", page.into())
}

/// A JSON body.
fn json<T: Serialize>(v: &T) -> Response {
    match serde_json::to_vec(v) {
        Ok(b) => typed("application/json", b.into()),
        Err(e) => problem(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

/// An error: status and a one-line message (plain text).
fn problem(status: StatusCode, message: String) -> Response {
    let mut r = typed("text/plain; charset=utf-8", format!("{message}\n").into());
    *r.status_mut() = status;
    r
}

/// An error of a handler (answered by `problem`).
#[derive(Debug)]
pub struct Problem {
    status: StatusCode,
    message: String,
}

impl Problem {
    fn new(status: StatusCode, message: String) -> Self {
        Self { status, message }
    }
}

impl IntoResponse for Problem {
    fn into_response(self) -> Response {
        problem(self.status, self.message)
    }
}

type Answer = Result<Response, Problem>;

/// A machine id of the path, checked as the fleet checks ids.
fn machine_id(id: &str) -> Result<&str, Problem> {
    rotorid_fleet::frame::check_machine_id(id)
        .map(|()| id)
        .map_err(|e| Problem::new(StatusCode::NOT_FOUND, format!("machine {id:?}: {e}")))
}

fn unknown(id: &str) -> Problem {
    Problem::new(
        StatusCode::NOT_FOUND,
        format!("machine {id}: no window of it has been read"),
    )
}

async fn machine_page(Path(id): Path<String>) -> Answer {
    machine_id(&id)?;
    Ok(html(MACHINE_PAGE))
}

async fn asset(Path(file): Path<String>) -> Response {
    match ASSETS.iter().find(|(name, _, _)| *name == file) {
        Some((_, ty, body)) => typed(ty, (*body).into()),
        None => problem(StatusCode::NOT_FOUND, format!("no asset {file:?}")),
    }
}

#[derive(Serialize)]
struct Status {
    server_ms: i64,
    nats: crate::follow::NatsStatus,
    held: crate::state::Held,
    history: usize,
    stale_windows: f64,
}

fn status_of(app: &App) -> Status {
    let st = app.shared.state.read().expect("not poisoned");
    Status {
        server_ms: now_ms(),
        nats: app.shared.nats_status(),
        held: st.held(),
        history: st.settings.history,
        stale_windows: st.settings.stale_windows,
    }
}

async fn status(State(app): State<Arc<App>>) -> Response {
    json(&status_of(&app))
}

async fn machines(State(app): State<Arc<App>>) -> Response {
    #[derive(Serialize)]
    struct Machines {
        #[serde(flatten)]
        status: Status,
        machines: Vec<crate::state::Tile>,
    }
    let status = status_of(&app);
    let machines = app
        .shared
        .state
        .read()
        .expect("not poisoned")
        .tiles(status.server_ms);
    json(&Machines { status, machines })
}

async fn machine(State(app): State<Arc<App>>, Path(id): Path<String>) -> Answer {
    let id = machine_id(&id)?;
    #[derive(Serialize)]
    struct Detail {
        tile: crate::state::Tile,
        /// The newest result's identification without its parameters and covariance.
        identification: Option<serde_json::Value>,
        errors: Vec<crate::state::ErrorView>,
        server_ms: i64,
    }
    let st = app.shared.state.read().expect("not poisoned");
    let now = now_ms();
    let tile = st.tile(id, now).ok_or_else(|| unknown(id))?;
    let identification = st.latest_json(id).and_then(|b| {
        let mut v: serde_json::Value = serde_json::from_slice(&b).ok()?;
        let mut ident = v.get_mut("identification")?.take();
        if let Some(o) = ident.as_object_mut() {
            o.remove("parameters");
            o.remove("covariance");
        }
        Some(ident)
    });
    Ok(json(&Detail {
        tile,
        identification,
        errors: st.errors(id),
        server_ms: now,
    }))
}

/// The query's `key=value` pairs, each key one of `allowed`, each value a whole number.
fn numbers(query: Option<&str>, allowed: &[&str]) -> Result<Vec<(String, u64)>, Problem> {
    let mut out = Vec::new();
    for pair in query.unwrap_or("").split('&').filter(|p| !p.is_empty()) {
        let (k, v) = pair.split_once('=').unwrap_or((pair, ""));
        if !allowed.contains(&k) {
            let k: String = k.chars().take(40).collect();
            return Err(Problem::new(
                StatusCode::BAD_REQUEST,
                format!("query parameter {k:?} is not one of {allowed:?}"),
            ));
        }
        let n = v.parse::<u64>().map_err(|_| {
            let v: String = v.chars().take(40).collect();
            Problem::new(
                StatusCode::BAD_REQUEST,
                format!("query parameter {k} = {v:?} must be a whole number >= 0"),
            )
        })?;
        out.push((k.to_owned(), n));
    }
    Ok(out)
}

async fn trend(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    RawQuery(q): RawQuery,
) -> Answer {
    let id = machine_id(&id)?;
    let q = numbers(q.as_deref(), &["after", "last"])?;
    let st = app.shared.state.read().expect("not poisoned");
    let history = st.settings.history;
    let get = |k: &str| q.iter().find(|(n, _)| n == k).map(|(_, v)| *v);
    let last = get("last").unwrap_or(history as u64);
    if last == 0 || last > history as u64 {
        return Err(Problem::new(
            StatusCode::BAD_REQUEST,
            format!(
                "last = {last} is out of range: 1 ..= {history} (the windows held per \
                 machine, --history)"
            ),
        ));
    }
    let t = st
        .trend(id, get("after"), last as usize)
        .ok_or_else(|| unknown(id))?;
    Ok(json(&t))
}

fn attachment(mut r: Response, name: &str) -> Response {
    if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{name}\"")) {
        r.headers_mut().insert(header::CONTENT_DISPOSITION, v);
    }
    r
}

async fn trend_csv(State(app): State<Arc<App>>, Path(id): Path<String>) -> Answer {
    let id = machine_id(&id)?;
    let csv = app.shared.state.read().expect("not poisoned").trend_csv(id);
    let csv = csv.ok_or_else(|| unknown(id))?;
    Ok(attachment(
        typed("text/csv; charset=utf-8", csv.into()),
        &format!("{id}-trend.csv"),
    ))
}

async fn latest_summary(State(app): State<Arc<App>>, Path(id): Path<String>) -> Answer {
    let id = machine_id(&id)?;
    let j = app
        .shared
        .state
        .read()
        .expect("not poisoned")
        .latest_json(id);
    let j = j.ok_or_else(|| unknown(id))?;
    Ok(attachment(
        typed("application/json", j.into()),
        &format!("{id}-latest.json"),
    ))
}

async fn window_summary(
    State(app): State<Arc<App>>,
    Path((id, window)): Path<(String, String)>,
) -> Answer {
    let id = machine_id(&id)?;
    let window = window.parse::<u64>().map_err(|_| {
        Problem::new(
            StatusCode::NOT_FOUND,
            format!("window {window:?} is not a window number (a whole number >= 0)"),
        )
    })?;
    let (seq, latest) = {
        let st = app.shared.state.read().expect("not poisoned");
        let latest = st.latest_json(id).filter(|b| {
            #[derive(serde::Deserialize)]
            struct W {
                window: u64,
            }
            serde_json::from_slice::<W>(b).is_ok_and(|w| w.window == window)
        });
        (st.result_seq(id, window), latest)
    };
    if let Some(b) = latest {
        return Ok(typed("application/json", b.into()));
    }
    let not_held = || {
        Problem::new(
            StatusCode::NOT_FOUND,
            format!(
                "machine {id} window {window}: no result held (the dashboard keeps the last \
                 --history windows)"
            ),
        )
    };
    let seq = seq.filter(|s| *s > 0).ok_or_else(not_held)?;
    let js = app.shared.js.lock().expect("not poisoned").clone();
    let js = js.ok_or_else(|| {
        Problem::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "not connected to NATS".into(),
        )
    })?;
    let got = tokio::time::timeout(Duration::from_secs(5), async {
        let s = js.get_stream(rotorid_fleet::IDENT_STREAM).await.ok()?;
        s.get_raw_message(seq).await.ok()
    })
    .await
    .map_err(|_| {
        Problem::new(
            StatusCode::GATEWAY_TIMEOUT,
            format!(
                "NATS did not answer within 5 s (stream {})",
                rotorid_fleet::IDENT_STREAM
            ),
        )
    })?;
    match got {
        Some(m) if m.subject.as_str() == rotorid_fleet::ident_subject(id) => {
            Ok(typed("application/json", m.payload.into()))
        }
        _ => Err(not_held()),
    }
}

async fn orbit(State(app): State<Arc<App>>, Path(id): Path<String>) -> Answer {
    let id = machine_id(&id)?;
    let st = app.shared.state.read().expect("not poisoned");
    let o = st.orbit(id).ok_or_else(|| {
        Problem::new(
            StatusCode::NOT_FOUND,
            format!("machine {id}: no raw window read yet"),
        )
    })?;
    Ok(json(o))
}

/// Decrements the count of open event streams when the stream is dropped.
struct Open(Arc<App>);
impl Drop for Open {
    fn drop(&mut self) {
        self.0.streams.fetch_sub(1, Ordering::SeqCst);
    }
}

fn nats_event(app: &App) -> Event {
    Event::default()
        .event("nats")
        .data(serde_json::to_string(&app.shared.nats_status()).unwrap_or_default())
}

/// Server-sent events: `nats` (the connection's status) at once and on every change,
/// `machine` (a tile) whenever a machine changes, `resync` when this page fell behind
/// (it should read /api/machines again).
async fn events(State(app): State<Arc<App>>) -> Response {
    if app.streams.fetch_add(1, Ordering::SeqCst) >= MAX_EVENT_STREAMS {
        app.streams.fetch_sub(1, Ordering::SeqCst);
        return problem(
            StatusCode::SERVICE_UNAVAILABLE,
            format!("{MAX_EVENT_STREAMS} pages are open already: close one"),
        );
    }
    let open = Open(Arc::clone(&app));
    let rx = app.shared.changes.subscribe();
    let first = Some(nats_event(&app));
    let stream =
        futures_util::stream::unfold((rx, open, first), |(mut rx, open, first)| async move {
            if let Some(e) = first {
                return Some((Ok::<_, Infallible>(e), (rx, open, None)));
            }
            let app = Arc::clone(&open.0);
            loop {
                let e = match rx.recv().await {
                    Ok(Change::Machine(id)) => {
                        let tile = app
                            .shared
                            .state
                            .read()
                            .expect("not poisoned")
                            .tile(&id, now_ms());
                        let Some(tile) = tile else { continue };
                        Event::default()
                            .event("machine")
                            .data(serde_json::to_string(&tile).unwrap_or_default())
                    }
                    Ok(Change::Nats) => nats_event(&app),
                    Err(RecvError::Lagged(_)) => Event::default().event("resync").data("{}"),
                    Err(RecvError::Closed) => return None,
                };
                return Some((Ok(e), (rx, open, None)));
            }
        });
    let mut r = Sse::new(stream)
        .keep_alive(KeepAlive::new().interval(Duration::from_secs(15)))
        .into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

/// Whether `host` (a Host header) names a loopback host: `localhost`, 127.x.y.z or [::1],
/// with or without a port.
fn loopback_host(host: &str) -> bool {
    let name = if let Some(rest) = host.strip_prefix('[') {
        rest.split(']').next().unwrap_or("")
    } else {
        host.rsplit_once(':').map_or(host, |(h, _)| h)
    };
    name.eq_ignore_ascii_case("localhost")
        || name
            .parse::<std::net::IpAddr>()
            .is_ok_and(|a| a.is_loopback())
}

/// The token a request carries: `Authorization: Bearer`, the cookie, or `?token=` (then
/// also true).
fn presented(headers: &HeaderMap, query: Option<&str>) -> Vec<(String, bool)> {
    let mut out = Vec::new();
    if let Some(b) = headers
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.strip_prefix("Bearer "))
    {
        out.push((b.trim().to_owned(), false));
    }
    for c in headers.get_all(header::COOKIE) {
        for part in c.to_str().unwrap_or("").split(';') {
            if let Some(v) = part
                .trim()
                .strip_prefix(TOKEN_COOKIE)
                .and_then(|v| v.strip_prefix('='))
            {
                out.push((v.to_owned(), false));
            }
        }
    }
    for pair in query.unwrap_or("").split('&') {
        if let Some(v) = pair.strip_prefix("token=") {
            out.push((v.to_owned(), true));
        }
    }
    out
}

fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && bool::from(a.as_bytes().ct_eq(b.as_bytes()))
}

fn secure(mut r: Response) -> Response {
    let h = r.headers_mut();
    h.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(
            "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; \
             connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'",
        ),
    );
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    h.insert(
        header::REFERRER_POLICY,
        HeaderValue::from_static("no-referrer"),
    );
    h.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    if !h.contains_key(header::CACHE_CONTROL) {
        h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    }
    r
}

/// Read-only, and the token or a loopback Host (module doc).
async fn guard(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    if req.method() != Method::GET && req.method() != Method::HEAD {
        let mut r = problem(
            StatusCode::METHOD_NOT_ALLOWED,
            format!(
                "{} is not allowed: the dashboard is read-only (GET, HEAD)",
                req.method()
            ),
        );
        r.headers_mut()
            .insert(header::ALLOW, HeaderValue::from_static("GET, HEAD"));
        return secure(r);
    }
    let Some(token) = &app.token else {
        let host = req
            .headers()
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        if !loopback_host(host) {
            let host: String = host.chars().take(80).collect();
            return secure(problem(
                StatusCode::FORBIDDEN,
                format!(
                    "Host {host:?} refused: without --token-file the dashboard answers only \
                     requests for localhost, 127.0.0.1 or [::1]"
                ),
            ));
        }
        return secure(next.run(req).await);
    };
    let given = presented(req.headers(), req.uri().query());
    match given.iter().find(|(t, _)| same(t, token)) {
        Some((_, true)) => {
            // the first load with ?token=: set the cookie, and go to the page without it
            let path = req.uri().path().to_owned();
            let rest: Vec<&str> = req
                .uri()
                .query()
                .unwrap_or("")
                .split('&')
                .filter(|p| !p.is_empty() && !p.starts_with("token="))
                .collect();
            let to = if rest.is_empty() {
                path
            } else {
                format!("{path}?{}", rest.join("&"))
            };
            let mut r = Response::new(Body::empty());
            *r.status_mut() = StatusCode::SEE_OTHER;
            if let Ok(v) = HeaderValue::from_str(&to) {
                r.headers_mut().insert(header::LOCATION, v);
            }
            let cookie = format!("{TOKEN_COOKIE}={token}; Path=/; HttpOnly; SameSite=Strict");
            if let Ok(v) = HeaderValue::from_str(&cookie) {
                r.headers_mut().insert(header::SET_COOKIE, v);
            }
            secure(r)
        }
        Some((_, false)) => secure(next.run(req).await),
        None => {
            let mut r = problem(
                StatusCode::UNAUTHORIZED,
                "this dashboard needs its access token: open it once as \
                 http://HOST:PORT/?token=TOKEN (TOKEN is the content of the --token-file \
                 given to rotorid dashboard; the page then keeps it in a cookie), or send \
                 the header Authorization: Bearer TOKEN"
                    .into(),
            );
            r.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"rotorid dashboard\""),
            );
            secure(r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_hosts() {
        for h in [
            "localhost",
            "localhost:8080",
            "127.0.0.1:1",
            "127.9.9.9",
            "[::1]:80",
            "[::1]",
        ] {
            assert!(loopback_host(h), "{h}");
        }
        for h in [
            "",
            "evil.example",
            "evil.example:8080",
            "10.0.0.1:80",
            "localhost.evil:1",
            "[::2]:1",
        ] {
            assert!(!loopback_host(h), "{h}");
        }
    }

    #[test]
    fn tokens_compare_whole() {
        assert!(same("abcdefghijklmnop", "abcdefghijklmnop"));
        assert!(!same("abcdefghijklmnop", "abcdefghijklmnoq"));
        assert!(!same("abcdefghijklmnop", "abcdefghijklmno"));
        assert!(!same("", "a"));
    }
}
