//! `rotorid dashboard` against a real nats-server fed by `rotorid publish` and a real
//! `rotorid worker`: the JSON API serves what the workers published (compared with the
//! messages read straight from the streams), the 1X vectors agree with a DFT of the
//! recording's own samples, the orbit is the recording's samples in um, alerts and
//! baselines appear, limits and the read-only rule hold, a token is required off
//! loopback, and the server carries on (with the problem in its status) while NATS is
//! gone. The browser tests (`dashboard_browser.rs`) use the same fixture.

use std::collections::BTreeMap;
use std::io::{BufRead as _, BufReader, Read as _, Write as _};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use rotorid_fleet::test_server::Server;
use serde_json::Value;

use crate::common::rotorid;

/// Generous: a busy CI machine may take long; a condition met returns at once.
pub const PATIENCE: Duration = Duration::from_secs(600);

/// A child process killed when dropped.
pub struct Proc(pub Option<Child>);
impl Drop for Proc {
    fn drop(&mut self) {
        if let Some(mut c) = self.0.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// An HTTP response.
#[derive(Debug)]
pub struct Resp {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Resp {
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.text()))
    }
}

/// One HTTP/1.1 request (Connection: close; the body read to its end).
pub fn request(method: &str, addr: &str, path: &str, headers: &[(&str, &str)]) -> Resp {
    let mut s = TcpStream::connect(addr).unwrap_or_else(|e| panic!("connect {addr}: {e}"));
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let mut req = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\n");
    if !headers.iter().any(|(k, _)| k.eq_ignore_ascii_case("host")) {
        req.push_str(&format!("Host: {addr}\r\n"));
    }
    for (k, v) in headers {
        req.push_str(&format!("{k}: {v}\r\n"));
    }
    if method != "GET" && method != "HEAD" {
        req.push_str("Content-Length: 0\r\n");
    }
    req.push_str("\r\n");
    s.write_all(req.as_bytes()).unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let end = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a header");
    let head = String::from_utf8_lossy(&raw[..end]).into_owned();
    let mut lines = head.lines();
    let status = lines.next().unwrap().split_whitespace().nth(1).unwrap();
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
        .collect();
    let mut body = raw[end + 4..].to_vec();
    let chunked = headers.iter().any(|(k, v)| {
        k.eq_ignore_ascii_case("transfer-encoding") && v.eq_ignore_ascii_case("chunked")
    });
    if chunked {
        body = dechunk(&body);
    }
    Resp {
        status: status.parse().unwrap(),
        headers,
        body,
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let Some(nl) = b.windows(2).position(|w| w == b"\r\n") else {
            return out;
        };
        let n = usize::from_str_radix(String::from_utf8_lossy(&b[..nl]).trim(), 16).unwrap_or(0);
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[nl + 2..nl + 2 + n]);
        b = &b[nl + 2 + n + 2..];
    }
}

pub fn get(addr: &str, path: &str) -> Resp {
    request("GET", addr, path, &[])
}

/// Poll `f` until it gives a value, for up to [`PATIENCE`].
pub fn wait_for<T>(what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    let t = Instant::now();
    loop {
        if let Some(v) = f() {
            return v;
        }
        assert!(t.elapsed() < PATIENCE, "{what}: not within {PATIENCE:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn run(args: &[&str]) {
    let out = rotorid().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "rotorid {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The table1 scenario file with kx scaled by `f`.
fn scenario_toml(kx_factor: f64) -> String {
    format!(
        "[rotor]\nm = 14.29\ncx = 10.0\ncz = 10.0\nkx = {:?}\nkz = 1.195e6\na = 2.871\n\
         m_u = 1.0e-4\nd = 0.15\nalpha_deg = 45.0\n\n[speed]\nkind = \"constant\"\n\
         rpm = 1200.0\n\n[sampling]\ndt = 1.0e-4\nduration = 1.0\n",
        1.195e6 * kx_factor
    )
}

/// The fleet of a test: a nats-server, a worker, recordings, and (once started) a
/// dashboard.
pub struct Fleet {
    pub dir: tempfile::TempDir,
    pub server: Server,
    pub url: String,
    worker: Proc,
    dashboard: Proc,
    /// The dashboard's `host:port`.
    pub addr: String,
}

/// The machines of [`Fleet::publish_all`] and their windows: three of table1 (3 s each),
/// and `press-4` whose kx drops by 5 % from window 3 (windows 3, 4 from a second
/// recording), which the worker alerts on window 4.
pub const MACHINES: [(&str, u64); 4] = [("pump-1", 3), ("pump-2", 3), ("fan-3", 3), ("press-4", 5)];

impl Fleet {
    /// A nats-server and a worker (modulating, table1 for every machine).
    pub fn start() -> Self {
        let dir = tempfile::tempdir().unwrap();
        let server = Server::start(&dir.path().join("js"));
        let url = server.url();
        let mut f = Self {
            dir,
            server,
            url,
            worker: Proc(None),
            dashboard: Proc(None),
            addr: String::new(),
        };
        f.start_worker();
        f
    }

    /// Start the worker (modulating, table1 for every machine).
    pub fn start_worker(&mut self) {
        let worker = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
            .args(["worker", "--nats", &self.url, "--scenario", "table1"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        self.worker = Proc(Some(worker));
    }

    /// Kill the worker: windows published meanwhile wait in the stream.
    pub fn stop_worker(&mut self) {
        self.worker = Proc(None);
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// `rotorid simulate` of table1 (kx scaled by `kx_factor`), `seconds` long, to NAME.
    pub fn simulate(&self, name: &str, seconds: u32, seed: u64, kx_factor: f64) -> PathBuf {
        let out = self.path(name);
        let scen = self.path(&format!("{name}.toml"));
        std::fs::write(&scen, scenario_toml(kx_factor)).unwrap();
        run(&[
            "simulate",
            "--scenario",
            scen.to_str().unwrap(),
            "--duration",
            &seconds.to_string(),
            "--snr-db",
            "40",
            "--seed",
            &seed.to_string(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ]);
        out
    }

    /// `rotorid publish FILE --machine ID --first-window N`.
    pub fn publish(&self, file: &Path, machine: &str, first_window: u64) {
        run(&[
            "publish",
            file.to_str().unwrap(),
            "--nats",
            &self.url,
            "--machine",
            machine,
            "--window-s",
            "1",
            "--first-window",
            &first_window.to_string(),
        ]);
    }

    /// Simulate and publish [`MACHINES`]; returns each recording (press-4: the first).
    pub fn publish_all(&self) -> BTreeMap<String, PathBuf> {
        let mut recs = BTreeMap::new();
        for (i, (m, _)) in MACHINES.iter().enumerate() {
            let f = self.simulate(&format!("{m}.csv"), 3, 10 + i as u64, 1.0);
            self.publish(&f, m, 0);
            recs.insert((*m).to_owned(), f);
        }
        let drop = self.simulate("press-4-late.csv", 2, 99, 0.95);
        self.publish(&drop, "press-4", 3);
        recs
    }

    /// Start `rotorid dashboard --listen 127.0.0.1:0` with `extra` arguments.
    pub fn dashboard(&mut self, extra: &[&str]) {
        let mut child = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
            // the windows are published at once, not in real time: never stale here
            // (stale is tested in the crate's unit tests)
            .args(["dashboard", "--nats", &self.url, "--listen", "127.0.0.1:0"])
            .args(["--stale-windows", "1e6"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        // "rotorid dashboard: http://127.0.0.1:PORT/ reading nats://..."
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_owned();
        self.dashboard = Proc(Some(child));
        self.addr = addr;
    }

    /// `/api/machines` once every machine of [`MACHINES`] shows all its windows, press-4
    /// its alert, and every machine its baseline.
    pub fn settled(&self) -> Value {
        wait_for(
            "every window, the alert and the baselines on the dashboard",
            || {
                let v = get(&self.addr, "/api/machines").json();
                let ms = v["machines"].as_array()?;
                for (id, windows) in MACHINES {
                    let t = ms.iter().find(|t| t["id"] == id)?;
                    if t["results"] != windows || t["window"] != windows - 1 {
                        return None;
                    }
                    let trend = get(&self.addr, &format!("/api/machines/{id}/trend")).json();
                    if trend["baseline"].as_array()?.is_empty() {
                        return None;
                    }
                    if trend["one_x"].as_array()?.len() as u64 != windows {
                        return None;
                    }
                }
                let press = ms.iter().find(|t| t["id"] == "press-4")?;
                (press["state"] == "alert").then_some(v)
            },
        )
    }
}

/// The fleet's messages read straight from the streams (not through the dashboard).
pub struct Streams {
    /// (machine, window) -> result JSON bytes
    pub results: BTreeMap<(String, u64), Vec<u8>>,
    /// machine -> drift state JSON
    pub drift: BTreeMap<String, Value>,
}

pub fn read_streams(url: &str) -> Streams {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let fleet = rotorid_fleet::nats::Fleet::connect(url, Duration::from_secs(10))
            .await
            .unwrap();
        let mut s = fleet
            .js
            .get_stream(rotorid_fleet::IDENT_STREAM)
            .await
            .unwrap();
        let last = s.info().await.unwrap().state.last_sequence;
        let mut results = BTreeMap::new();
        for seq in 1..=last {
            let m = s.get_raw_message(seq).await.unwrap();
            if let Some(id) = m.subject.as_str().strip_prefix("rotorid.ident.") {
                let v: Value = serde_json::from_slice(&m.payload).unwrap();
                results.insert(
                    (id.to_owned(), v["window"].as_u64().unwrap()),
                    m.payload.to_vec(),
                );
            }
        }
        let kv = fleet
            .js
            .get_key_value(rotorid_fleet::DRIFT_BUCKET)
            .await
            .unwrap();
        let mut drift = BTreeMap::new();
        for (id, _) in MACHINES {
            let b = kv.get(id).await.unwrap().unwrap();
            drift.insert(id.to_owned(), serde_json::from_slice(&b).unwrap());
        }
        Streams { results, drift }
    })
}

/// The response CSV's columns t, x, z, phi.
pub fn read_csv(path: &Path) -> [Vec<f64>; 4] {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert!(lines.next().unwrap().starts_with("t,x,z,phi"));
    let mut cols: [Vec<f64>; 4] = Default::default();
    for l in lines {
        for (c, f) in cols.iter_mut().zip(l.split(',')) {
            c.push(f.parse().unwrap());
        }
    }
    cols
}

/// 1X of `s` against `phi` by the discrete Fourier transform at the shaft frequency
/// (a projection, not the least squares the dashboard uses): (amplitude, phase lag deg).
fn dft_1x(s: &[f64], phi: &[f64]) -> (f64, f64) {
    let n = s.len() as f64;
    let mean = s.iter().sum::<f64>() / n;
    let (mut a, mut b) = (0.0, 0.0);
    for (v, p) in s.iter().zip(phi) {
        a += (v - mean) * p.cos();
        b += (v - mean) * p.sin();
    }
    let (a, b) = (2.0 * a / n, 2.0 * b / n);
    (a.hypot(b), b.atan2(a).to_degrees().rem_euclid(360.0))
}

fn param_map(tile_or_result: &Value) -> BTreeMap<String, (Value, Value, Value)> {
    tile_or_result
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let name = p.get("name").or_else(|| p.get("parameter")).unwrap();
            let value = if p.get("determined") == Some(&Value::Bool(false)) {
                Value::Null
            } else {
                p["value"].clone()
            };
            (
                name.as_str().unwrap().to_owned(),
                (p["unit"].clone(), value, p["std_error"].clone()),
            )
        })
        .collect()
}

#[test]
fn the_api_serves_what_the_workers_published() {
    let mut f = Fleet::start();
    // the dashboard first: it reads everything live
    f.dashboard(&["--history", "50"]);
    let recs = f.publish_all();
    let machines = f.settled();
    let streams = read_streams(&f.url);
    let addr = f.addr.clone();

    // the fleet page's data: each machine's newest result, worst first (press-4 alerts)
    let tiles = machines["machines"].as_array().unwrap();
    assert_eq!(tiles.len(), 4);
    assert_eq!(tiles[0]["id"], "press-4");
    assert_eq!(machines["nats"]["connected"], true, "{machines}");
    for (id, windows) in MACHINES {
        let t = tiles.iter().find(|t| t["id"] == id).unwrap();
        let newest: Value =
            serde_json::from_slice(&streams.results[&(id.to_owned(), windows - 1)]).unwrap();
        assert_eq!(
            param_map(&t["parameters"]),
            param_map(&newest["identification"]["parameters"]),
            "{id}"
        );
        assert_eq!(t["method"], "modulating");
        // the last window of a recording takes its last sample too: 10 001 samples
        assert!((t["window_s"].as_f64().unwrap() - 1.0).abs() <= 1e-4, "{t}");
        if id != "press-4" {
            assert_eq!(t["state"], "ok", "{t}");
            assert!(t["last_alert"].is_null());
        }
    }

    // every window's result: the trend's values and the summary endpoint's bytes
    for (id, windows) in MACHINES {
        let trend = get(&addr, &format!("/api/machines/{id}/trend")).json();
        let names: Vec<&str> = trend["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["m_x", "cx", "kx", "m_z", "cz", "kz"]);
        let ws = trend["windows"].as_array().unwrap();
        assert_eq!(ws.len() as u64, windows);
        for (w, p) in ws.iter().enumerate() {
            let bytes = &streams.results[&(id.to_owned(), w as u64)];
            let r: Value = serde_json::from_slice(bytes).unwrap();
            assert_eq!(p["window"], w as u64);
            assert_eq!(p["t0_s"], r["t0_s"]);
            for (i, q) in r["identification"]["parameters"]
                .as_array()
                .unwrap()
                .iter()
                .enumerate()
            {
                assert_eq!(p["values"][i], q["value"], "{id} window {w}");
                assert_eq!(p["std_errors"][i], q["std_error"], "{id} window {w}");
            }
            let s = get(&addr, &format!("/api/machines/{id}/windows/{w}/summary"));
            assert_eq!(s.status, 200, "{}", s.text());
            assert_eq!(&s.body, bytes, "{id} window {w}: the message as published");
        }
        let latest = get(&addr, &format!("/api/machines/{id}/summary"));
        assert_eq!(latest.body, streams.results[&(id.to_owned(), windows - 1)]);
        assert!(latest
            .header("content-disposition")
            .unwrap()
            .contains("attachment"));

        // the baseline band: the drift state's baseline, as the worker formed it
        let base = &streams.drift[id]["baseline"];
        assert_eq!(
            param_map(&trend["baseline"]),
            param_map(base),
            "{id}: baseline"
        );

        // the CSV: a row per window, the same numbers, units in the header
        let csv = get(&addr, &format!("/api/machines/{id}/trend.csv"));
        assert_eq!(csv.status, 200);
        let text = csv.text();
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        // window, t0, stored, then (value, standard error) of m_x, cx, kx, ...
        assert_eq!(head[7], "kx [N/m]");
        assert_eq!(head[8], "kx std_error [N/m]");
        assert!(head.contains(&"x 1X amplitude [um]"));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len() as u64, windows);
        for (row, p) in rows.iter().zip(ws) {
            let kx: f64 = row[7].parse().unwrap();
            assert_eq!(kx, p["values"][2].as_f64().unwrap());
        }
    }

    // the alert: press-4's kx dropped 5 % from window 3, alerted on window 4
    let press = tiles.iter().find(|t| t["id"] == "press-4").unwrap();
    let a = &press["last_alert"];
    assert_eq!(a["parameter"], "kx", "{a}");
    assert_eq!(a["window"], 4);
    let rel = a["relative_change"].as_f64().unwrap();
    assert!((rel + 0.05).abs() < 0.005, "{a}");
    let trend = get(&addr, "/api/machines/press-4/trend").json();
    assert!(trend["alerts"]
        .as_array()
        .unwrap()
        .iter()
        .any(|a| a["parameter"] == "kx"));

    // 1X of every window against a DFT of the recording's own samples
    for (id, _) in MACHINES.iter().take(3) {
        let [_, x, z, phi] = read_csv(&recs[*id]);
        let trend = get(&addr, &format!("/api/machines/{id}/trend")).json();
        for (w, p) in trend["one_x"].as_array().unwrap().iter().enumerate() {
            // windows of 10 000 samples; the last takes the 30 001st sample too
            let end = if w == 2 { x.len() } else { (w + 1) * 10_000 };
            let r = w * 10_000..end;
            for (probe, s) in [("x", &x), ("z", &z)] {
                let (amp, lag) = dft_1x(&s[r.clone()], &phi[r.clone()]);
                let v = &p[probe];
                let got_amp = v["amplitude_um"].as_f64().unwrap();
                let got_lag = v["phase_deg"].as_f64().unwrap();
                assert!(
                    (got_amp - amp * 1e6).abs() < 2e-3 * amp * 1e6,
                    "{id} window {w} {probe}: {got_amp} um vs DFT {} um",
                    amp * 1e6
                );
                let d = (got_lag - lag + 180.0).rem_euclid(360.0) - 180.0;
                assert!(
                    d.abs() < 0.1,
                    "{id} window {w} {probe}: {got_lag} deg vs DFT {lag}"
                );
                assert!(v["amplitude_se_um"].as_f64().unwrap() > 0.0);
            }
            assert!((p["speed_rpm"].as_f64().unwrap() - 1200.0).abs() < 1e-6);
        }
        // the orbit: the newest window's samples in um, every 5th, keyphasors at phi = 2 pi n
        let o = get(&addr, &format!("/api/machines/{id}/orbit")).json();
        assert_eq!(o["window"], 2);
        assert_eq!(o["stride"], 5);
        let xs = o["x_um"].as_array().unwrap();
        assert_eq!(xs.len(), 10_001usize.div_ceil(5));
        for (i, v) in xs.iter().enumerate() {
            let want = x[20_000 + 5 * i] * 1e6;
            assert!((v.as_f64().unwrap() - want).abs() <= 1e-12 * want.abs().max(1e-3));
        }
        let kp = o["keyphasor"].as_array().unwrap();
        // 20 revolutions: the 19 marks inside the window, and those on its two ends as
        // rounding puts phi there
        assert!((19..=21).contains(&kp.len()), "{} keyphasors", kp.len());
        for j in 1..20 {
            let at = 2.0 + 0.05 * j as f64;
            assert!(
                kp.iter()
                    .any(|k| (k["t_s"].as_f64().unwrap() - at).abs() < 1e-9),
                "no keyphasor at {at} s: {kp:?}"
            );
        }
        for k in kp {
            let t = k["t_s"].as_f64().unwrap();
            let revs = 20.0 * t; // 1200 rpm from phi = 0 at t = 0
            assert!((revs - revs.round()).abs() < 1e-6, "keyphasor at {t} s");
            let i = (((t - 2.0) / 1e-4).floor() as usize + 20_000).min(x.len() - 2);
            let (lo, hi) = (x[i].min(x[i + 1]) * 1e6, x[i].max(x[i + 1]) * 1e6);
            let kx = k["x_um"].as_f64().unwrap();
            assert!(
                kx >= lo - 1e-9 && kx <= hi + 1e-9,
                "{k} between {lo} and {hi}"
            );
        }
    }

    // limits, refusals, the read-only rule
    let r = get(&addr, "/api/machines/pump-1/trend?last=0");
    assert_eq!(r.status, 400);
    assert!(
        r.text().contains("last = 0 is out of range: 1 ..= 50"),
        "{}",
        r.text()
    );
    assert_eq!(get(&addr, "/api/machines/pump-1/trend?last=51").status, 400);
    let r = get(&addr, "/api/machines/pump-1/trend?last=2&after=0");
    let ws: Vec<u64> = r.json()["windows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["window"].as_u64().unwrap())
        .collect();
    assert_eq!(ws, [1, 2]);
    let r = get(&addr, "/api/machines/pump-1/trend?evil=1");
    assert_eq!(r.status, 400);
    assert!(r.text().contains("\"evil\" is not one of"), "{}", r.text());
    assert_eq!(get(&addr, "/api/machines/nobody/trend").status, 404);
    assert_eq!(get(&addr, "/api/machines/a.b/trend").status, 404);
    assert_eq!(get(&addr, "/machine/a%20b").status, 404);
    assert_eq!(get(&addr, "/machine/pump-1").status, 200);
    assert_eq!(
        get(&addr, "/api/machines/pump-1/windows/77/summary").status,
        404
    );
    assert_eq!(get(&addr, "/nothing").status, 404);
    for m in ["POST", "PUT", "DELETE", "PATCH"] {
        for path in ["/api/machines", "/", "/api/events", "/nothing"] {
            let r = request(m, &addr, path, &[]);
            assert_eq!(r.status, 405, "{m} {path}");
            assert_eq!(r.header("allow"), Some("GET, HEAD"));
        }
    }
    let head = request("HEAD", &addr, "/", &[]);
    assert_eq!((head.status, head.body.len()), (200, 0));
    // only requests for a loopback host (no DNS rebinding from another site)
    let r = request(
        "GET",
        &addr,
        "/api/machines",
        &[("Host", "evil.example:8080")],
    );
    assert_eq!(r.status, 403);
    assert!(r.text().contains("--token-file"), "{}", r.text());
    // the pages: no script but our own files, and no framing
    let page = get(&addr, "/");
    let csp = page.header("content-security-policy").unwrap();
    assert!(
        csp.contains("script-src 'self'") && csp.contains("default-src 'none'"),
        "{csp}"
    );
    assert!(page.text().contains("/assets/fleet.js"));
    assert!(!page.text().contains("http://") && !page.text().contains("https://"));
    for a in ["app.css", "common.js", "plot.js", "fleet.js", "machine.js"] {
        let r = get(&addr, &format!("/assets/{a}"));
        assert_eq!(r.status, 200);
        // no request to any other host: no absolute URL in any asset
        assert!(
            !r.text().contains("//cdn") && !r.text().contains("https://"),
            "{a}"
        );
        assert!(
            !r.text().contains("innerHTML"),
            "{a}: bus text only through textContent"
        );
    }
}

/// Read server-sent events from `/api/events` until `want` is seen in a `machine` event;
/// `ready` is told when the stream is open (its first event, `nats`, has come).
fn sse_until(
    addr: &str,
    ready: std::sync::mpsc::Sender<()>,
    want: impl Fn(&Value) -> bool,
) -> Value {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(PATIENCE)).unwrap();
    write!(s, "GET /api/events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut r = BufReader::new(s);
    let mut event = String::new();
    let mut line = String::new();
    let t = Instant::now();
    loop {
        line.clear();
        assert!(
            r.read_line(&mut line).unwrap() > 0,
            "the event stream ended"
        );
        assert!(t.elapsed() < PATIENCE, "no such event within {PATIENCE:?}");
        if let Some(e) = line.trim().strip_prefix("event:") {
            event = e.trim().to_owned();
            if event == "nats" {
                let _ = ready.send(());
            }
        } else if let Some(d) = line.trim().strip_prefix("data:") {
            if event == "machine" {
                let v: Value = serde_json::from_str(d.trim()).unwrap();
                if want(&v) {
                    return v;
                }
            }
        }
    }
}

#[test]
fn nats_gone_shows_in_the_status_and_the_dashboard_carries_on() {
    let mut f = Fleet::start();
    let recs = f.publish_all();
    // started after the windows: it reads them back from the streams
    f.dashboard(&[]);
    let before = f.settled();
    let addr = f.addr.clone();
    f.server.stop();
    let st = wait_for("NATS down in the status", || {
        let s = get(&addr, "/api/status").json();
        (s["nats"]["connected"] == false).then_some(s)
    });
    assert!(
        st["nats"]["problems"]
            .as_object()
            .unwrap()
            .values()
            .any(|p| p.as_str().unwrap().contains("unreachable")),
        "{st}"
    );
    // still serving what it has
    let during = get(&addr, "/api/machines").json();
    assert_eq!(during["machines"].as_array().unwrap().len(), 4);
    assert_eq!(get(&addr, "/").status, 200);
    assert_eq!(
        get(&addr, "/api/machines/pump-1/trend").json()["windows"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
    f.server.resume();
    wait_for("NATS back and every reader reading", || {
        let s = get(&addr, "/api/status").json();
        (s["nats"]["connected"] == true && s["nats"]["problems"].as_object()?.is_empty())
            .then_some(())
    });
    // a new window after the outage reaches the dashboard, and is pushed to open pages
    let addr2 = addr.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    // (an event carries the machine's tile as it is when sent: windows 3 to 5 come fast)
    let watcher = std::thread::spawn(move || {
        sse_until(&addr2, tx, |t| {
            t["id"] == "pump-1" && t["window"].as_u64() >= Some(3)
        })
    });
    rx.recv_timeout(PATIENCE).expect("the event stream opens");
    f.publish(&recs["pump-1"], "pump-1", 3);
    let ev = watcher.join().unwrap();
    assert!(ev["results"].as_u64().unwrap() >= 4, "{ev}");
    let ws = wait_for("windows 3 to 5 of pump-1 after the outage", || {
        let t = get(&addr, "/api/machines/pump-1/trend").json();
        let ws: Vec<u64> = t["windows"]
            .as_array()?
            .iter()
            .map(|w| w["window"].as_u64().unwrap())
            .collect();
        (ws.len() == 6).then_some(ws)
    });
    assert_eq!(ws, [0, 1, 2, 3, 4, 5]);
    assert_eq!(
        get(&addr, "/api/machines").json()["machines"][0]["id"],
        "press-4"
    );
    assert_eq!(before["machines"].as_array().unwrap().len(), 4);
}

#[test]
fn off_loopback_the_dashboard_needs_a_token_and_checks_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = rotorid()
        .args([
            "dashboard",
            "--nats",
            "nats://127.0.0.1:1",
            "--listen",
            "0.0.0.0:0",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--listen 0.0.0.0:0 is not a loopback address")
            && err.contains("--token-file FILE"),
        "{err}"
    );
    let short = dir.path().join("short");
    std::fs::write(&short, "abc\n").unwrap();
    let out = rotorid()
        .args([
            "dashboard",
            "--nats",
            "nats://127.0.0.1:1",
            "--listen",
            "0.0.0.0:0",
            "--token-file",
        ])
        .arg(&short)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("3 characters; it must have 16 to 256"),
        "{err}"
    );

    // with a token: every request needs it (no NATS server at all: it serves anyway)
    let token = "s3cret-token-0123456789";
    let file = dir.path().join("token");
    std::fs::write(&file, format!("{token}\n")).unwrap();
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("rotorid"))
        .args([
            "dashboard",
            "--nats",
            "nats://127.0.0.1:1",
            "--listen",
            "0.0.0.0:0",
            "--token-file",
        ])
        .arg(&file)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let _guard = Proc(Some(child));
    let port = line
        .split("0.0.0.0:")
        .nth(1)
        .unwrap()
        .split('/')
        .next()
        .unwrap();
    let addr = format!("127.0.0.1:{port}");
    let r = get(&addr, "/api/machines");
    assert_eq!(r.status, 401);
    assert!(r.text().contains("?token="), "{}", r.text());
    let wrong = format!("Bearer {}x", &token[..token.len() - 1]);
    assert_eq!(
        request("GET", &addr, "/api/machines", &[("Authorization", &wrong)]).status,
        401
    );
    let right = format!("Bearer {token}");
    let r = request("GET", &addr, "/api/machines", &[("Authorization", &right)]);
    assert_eq!(r.status, 200, "{}", r.text());
    // no NATS: the status says so
    assert_eq!(r.json()["nats"]["connected"], false);
    // ?token= once: a cookie, and the page without the token in its address
    let r = get(&addr, &format!("/machine/m-1?token={token}"));
    assert_eq!(r.status, 303);
    assert_eq!(r.header("location"), Some("/machine/m-1"));
    let cookie = r.header("set-cookie").unwrap().to_owned();
    assert!(
        cookie.contains("HttpOnly") && cookie.contains("SameSite=Strict"),
        "{cookie}"
    );
    let pair = cookie.split(';').next().unwrap();
    assert_eq!(
        request("GET", &addr, "/machine/m-1", &[("Cookie", pair)]).status,
        200
    );
    assert_eq!(
        request(
            "GET",
            &addr,
            "/machine/m-1",
            &[("Cookie", "rotorid_token=nope")]
        )
        .status,
        401
    );
    // with a token any Host is accepted (it is not reachable without the token)
    assert_eq!(
        request(
            "GET",
            &addr,
            "/api/status",
            &[("Authorization", &right), ("Host", "plant-screen:8080")]
        )
        .status,
        200
    );
}
