//! The dashboard's pages in a real browser: headless Chromium driven through chromedriver
//! (WebDriver, the `fantoccini` client) against `rotorid dashboard` reading a real
//! nats-server fed by `rotorid publish` and a real worker (the fixture of `dashboard.rs`).
//! The test reads the rendered DOM: every machine's tile with its values (compared with
//! the API's numbers to the rounding the page states), the worst first, the bus's text
//! shown as text (no markup from the bus ever becomes an element), a parameter the page
//! has never heard of (`kxz`) shown by its name and unit; the machine page's trend with
//! one point per window for every parameter, its bands, the alert marked, the orbit's
//! keyphasor dots, the 1X trend and polar points; and a window published while both pages
//! are open appearing on both without a reload.
//!
//! Needs the Debian packages `chromium` and `chromium-driver` (`.ci/test` installs them),
//! or `$CHROMIUM` and `$CHROMEDRIVER`. Every wait is on a condition, with generous time.

use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use fantoccini::{Client, ClientBuilder};
use serde_json::{json, Value};

use crate::dashboard::{get, Fleet, Proc, PATIENCE};

fn binary(var: &str, name: &str, debian: &str) -> PathBuf {
    if let Some(p) = std::env::var_os(var) {
        return p.into();
    }
    let on_path = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .map(|d| d.join(name))
            .find(|f| f.is_file())
    });
    on_path.unwrap_or_else(|| debian.into())
}

/// chromedriver on a free port, and a session of headless Chromium with a fresh profile.
async fn browser(profile: &std::path::Path) -> (Proc, Client) {
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let driver = binary("CHROMEDRIVER", "chromedriver", "/usr/bin/chromedriver");
    let child = Command::new(&driver)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e}: install the Debian packages chromium and chromium-driver (.ci/test does)",
                driver.display()
            )
        });
    let driver = Proc(Some(child));
    let t = Instant::now();
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(t.elapsed() < PATIENCE, "chromedriver did not start");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let chromium = binary("CHROMIUM", "chromium", "/usr/bin/chromium");
    let caps = json!({
        "browserName": "chrome",
        "goog:chromeOptions": {
            "binary": chromium,
            "args": [
                "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync",
                "--disable-dev-shm-usage", "--window-size=1600,1000",
                format!("--user-data-dir={}", profile.display()),
            ]
        }
    });
    let caps = caps.as_object().unwrap().clone();
    let connector = hyper_util::client::legacy::connect::HttpConnector::new();
    let client = ClientBuilder::new(connector)
        .capabilities(caps)
        .connect(&format!("http://127.0.0.1:{port}"))
        .await
        .expect("a Chromium session through chromedriver");
    (driver, client)
}

/// Run `script` until it returns something other than null or false.
async fn until(c: &Client, what: &str, script: &str) -> Value {
    let t = Instant::now();
    loop {
        let v = c.execute(script, vec![]).await.unwrap();
        if !(v.is_null() || v == Value::Bool(false)) {
            return v;
        }
        assert!(
            t.elapsed() < PATIENCE,
            "{what}: not within {PATIENCE:?} (last {v})"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// A value as the page shows it, "1 194 930 ± 140": (value, standard error).
fn shown(text: &str) -> (f64, Option<f64>) {
    let t: String = text
        .chars()
        .filter(|c| !c.is_whitespace() && *c != '\u{2009}')
        .collect();
    match t.split_once('±') {
        Some((v, e)) => (v.parse().unwrap(), Some(e.parse().unwrap())),
        None => (t.parse().unwrap(), None),
    }
}

const TILES: &str = "return Array.from(document.querySelectorAll('.tile')).map(t => ({
    id: t.dataset.id, state: t.dataset.state, window: t.dataset.window,
    href: t.getAttribute('href'),
    params: Array.from(t.querySelectorAll('tr')).map(r => [r.querySelector('th').textContent,
        r.querySelector('td.v').textContent, r.querySelector('td.u').textContent]),
    alert: t.querySelector('.line.alert').textContent,
    error: t.querySelector('.line.errors').textContent }));";

fn publish_crafted(url: &str) {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let f = rotorid_fleet::nats::Fleet::connect(url, Duration::from_secs(10))
            .await
            .unwrap();
        // a result of another model: parameters by other names, and names that are markup
        let r = json!({"fleet_schema": 1, "machine": "evil-5", "window": 0, "t0_s": 0.0,
            "dt_s": 1e-4, "samples": 10000, "identification": {"schema": 2,
            "method": "<i>m</i>", "parameters": [
                {"parameter": "kxz", "unit": "N/m", "value": 1.5e6, "std_error": 2.0e3, "determined": true},
                {"parameter": "<img src=x onerror=window.__pwned=1>", "unit": "<b>N</b>",
                 "value": 1.0, "std_error": 0.1, "determined": true}]}});
        f.publish("rotorid.ident.evil-5", "evil-5/0", serde_json::to_vec(&r).unwrap().into())
            .await
            .unwrap();
        let e = json!({"fleet_schema": 1, "machine": "evil-5", "window": 1, "stream_seq": 0,
            "delivered": 1, "error": "<script>window.__pwned=2</script> & <i>x</i>"});
        f.publish("rotorid.error.evil-5", "evil-5/1", serde_json::to_vec(&e).unwrap().into())
            .await
            .unwrap();
    });
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_pages_in_a_real_browser_show_the_fleet_and_update_live() {
    let mut f = Fleet::start();
    f.dashboard(&[]);
    let (url, addr) = (f.url.clone(), f.addr.clone());
    let f = tokio::task::spawn_blocking(move || {
        f.publish_all();
        publish_crafted(&url);
        f.settled();
        f
    })
    .await
    .unwrap();
    let api = tokio::task::spawn_blocking({
        let addr = addr.clone();
        move || get(&addr, "/api/machines").json()
    })
    .await
    .unwrap();
    assert_eq!(api["machines"].as_array().unwrap().len(), 5, "{api}");

    let profile = tempfile::tempdir().unwrap();
    let (_driver, c) = browser(profile.path()).await;
    c.goto(&format!("http://{addr}/")).await.unwrap();
    let tiles = until(
        &c,
        "the fleet page's five tiles with their newest windows",
        &format!(
            "const t = {}; return t.length === 5 && t.find(x => x.id === 'press-4').window === '4' && t.find(x => x.id === 'evil-5').state === 'errors' ? t : null;",
            TILES.trim_start_matches("return ").trim_end_matches(';')
        ),
    )
    .await;
    let tiles = tiles.as_array().unwrap();
    // worst first: the alert, the errors, then the ok ones by id
    let ids: Vec<&str> = tiles.iter().map(|t| t["id"].as_str().unwrap()).collect();
    assert_eq!(ids, ["press-4", "evil-5", "fan-3", "pump-1", "pump-2"]);
    for t in tiles {
        let id = t["id"].as_str().unwrap();
        let a = api["machines"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["id"] == id)
            .unwrap();
        assert_eq!(t["state"], a["state"], "{id}");
        assert_eq!(t["window"], a["window"].to_string(), "{id}");
        assert_eq!(t["href"], format!("/machine/{id}"));
        let rows = t["params"].as_array().unwrap();
        let want = a["parameters"].as_array().unwrap();
        assert_eq!(rows.len(), want.len(), "{id}");
        for (r, p) in rows.iter().zip(want) {
            assert_eq!(r[0], p["name"], "{id}");
            assert_eq!(r[2], p["unit"], "{id}");
            let (v, se) = shown(r[1].as_str().unwrap());
            let (pv, pse) = (
                p["value"].as_f64().unwrap(),
                p["std_error"].as_f64().unwrap(),
            );
            // rounded to the standard error's second significant digit
            assert!(
                (v - pv).abs() <= 0.05 * pse * (1.0 + 1e-9),
                "{id} {}: {r} vs {p}",
                p["name"]
            );
            let se = se.expect("every value here has a standard error");
            assert!(
                (se - pse).abs() <= 0.05 * pse * (1.0 + 1e-9),
                "{id}: {r} vs {p}"
            );
        }
    }
    let press = &tiles[0];
    let alert = press["alert"].as_str().unwrap();
    let pct: f64 = alert
        .strip_prefix("ALERT kx ")
        .and_then(|r| r.split(" %").next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("{press}"));
    assert!((pct + 5.0).abs() < 0.5, "kx dropped 5 %: {alert}");
    // the bus's text as text: no element made of it, no script run
    let evil = &tiles[1];
    assert_eq!(
        evil["params"][0],
        json!(["kxz", "1\u{2009}500\u{2009}000 ± 2\u{2009}000", "N/m"])
    );
    assert_eq!(evil["params"][1][0], "<img src=x onerror=window.__pwned=1>");
    assert_eq!(evil["params"][1][2], "<b>N</b>");
    assert!(
        evil["error"]
            .as_str()
            .unwrap()
            .contains("<script>window.__pwned=2</script> & <i>x</i>"),
        "{evil}"
    );
    let injected = c
        .execute(
            "return [document.querySelectorAll('img, script:not([src]), i').length, typeof window.__pwned];",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(injected, json!([0, "undefined"]));
    let fleet_tab = c.window().await.unwrap();
    c.execute("window.__marker = 'fleet page loaded once';", vec![])
        .await
        .unwrap();

    // the machine page of press-4, in a second tab
    let tab = c.new_window(true).await.unwrap();
    c.switch_to_window(tab.handle.clone()).await.unwrap();
    c.goto(&format!("http://{addr}/machine/press-4"))
        .await
        .unwrap();
    let trend = tokio::task::spawn_blocking({
        let addr = addr.clone();
        move || get(&addr, "/api/machines/press-4/trend").json()
    })
    .await
    .unwrap();
    let drawn = "return document.body.dataset.windows === WANT ? Array.from(document.querySelectorAll('svg.trend')).map(s => ({
        param: s.dataset.param,
        dots: Number(s.querySelector('path.dots').dataset.points),
        band: s.querySelector('path.band').getAttribute('d').length,
        baseline: s.querySelectorAll('rect.baseline').length,
        alerts: s.querySelectorAll('line.alertmark:not(.other)').length })) : null;";
    let charts = until(
        &c,
        "press-4's five windows drawn",
        &drawn.replace("WANT", "'5'"),
    )
    .await;
    let charts = charts.as_array().unwrap();
    let names: Vec<&Value> = trend["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| &p["name"])
        .collect();
    assert_eq!(charts.len(), names.len());
    for (i, ch) in charts.iter().enumerate() {
        assert_eq!(&ch["param"], names[i]);
        let determined = trend["windows"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|w| !w["values"][i].is_null())
            .count();
        assert_eq!(determined, 5);
        assert_eq!(ch["dots"], determined, "{ch}: one point per window");
        assert!(ch["band"].as_u64().unwrap() > 10, "{ch}: a 95 % band");
        assert_eq!(ch["baseline"], 1, "{ch}: the baseline band");
        let alerts = trend["alerts"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|a| a["parameter"] == ch["param"])
            .count();
        assert_eq!(
            ch["alerts"], alerts,
            "{ch}: an alert mark per alert of the parameter"
        );
        if ch["param"] == "kx" {
            assert!(alerts >= 1, "kx dropped 5 %: {trend}");
        }
    }
    let orbit = tokio::task::spawn_blocking({
        let addr = addr.clone();
        move || get(&addr, "/api/machines/press-4/orbit").json()
    })
    .await
    .unwrap();
    let rest = c
        .execute(
            "return { kp: Number(document.querySelector('#orbit g.keyphasors').dataset.points),
                 orbit: document.querySelector('#orbit path.orbitpath').getAttribute('d').split('L').length,
                 xt: !!document.querySelector('#xt path.series'), zt: !!document.querySelector('#zt path.series'),
                 amp: Array.from(document.querySelectorAll('#amp path.dots')).map(p => Number(p.dataset.points)),
                 phase: Array.from(document.querySelectorAll('#phase path.dots')).map(p => Number(p.dataset.points)),
                 polar: document.querySelectorAll('#polar circle.polar-pt').length,
                 rows: document.querySelectorAll('#params tr[data-param]').length,
                 details: document.getElementById('details').textContent,
                 csv: document.getElementById('csv').getAttribute('href'),
                 json: document.getElementById('json').getAttribute('href'),
                 axes: Array.from(document.querySelectorAll('svg text')).map(t => t.textContent) };",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(
        rest["kp"],
        orbit["keyphasor"].as_array().unwrap().len(),
        "{rest}"
    );
    assert_eq!(rest["orbit"], orbit["x_um"].as_array().unwrap().len());
    assert_eq!(
        (rest["xt"].clone(), rest["zt"].clone()),
        (json!(true), json!(true))
    );
    assert_eq!(rest["amp"], json!([5, 5]), "x and z, a point per window");
    assert_eq!(rest["phase"], json!([5, 5]));
    assert_eq!(rest["polar"], 10);
    assert_eq!(rest["rows"], 6);
    assert!(
        rest["details"].as_str().unwrap().contains("modulating"),
        "{rest}"
    );
    assert_eq!(rest["csv"], "/api/machines/press-4/trend.csv");
    assert_eq!(rest["json"], "/api/machines/press-4/summary");
    let axes: Vec<&str> = rest["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    for want in [
        "x [\u{b5}m]",
        "z [\u{b5}m]",
        "window number",
        "kx [N/m]",
        "amplitude [\u{b5}m pk]",
        "phase lag [deg]",
        "t [s]",
    ] {
        assert!(axes.contains(&want), "axis {want:?} in {axes:?}");
    }
    c.execute("window.__marker = 'machine page loaded once';", vec![])
        .await
        .unwrap();
    if let Some(dir) = std::env::var_os("ROTORID_DASHBOARD_SCREENSHOTS") {
        std::fs::write(
            PathBuf::from(&dir).join("machine.png"),
            c.screenshot().await.unwrap(),
        )
        .unwrap();
    }

    // a window published while both pages are open: both show it, neither reloads. The raw
    // window first, while no worker runs: the page shows its orbit, not yet a result; then
    // a worker, whose result alone can bring the sixth point
    let mut f = f;
    f.stop_worker();
    let f = tokio::task::spawn_blocking(move || {
        let late = f.simulate("press-4-update.csv", 1, 123, 1.0); // no alert: only the result can tell
        f.publish(&late, "press-4", 5);
        f
    })
    .await
    .unwrap();
    let shown = until(
        &c,
        "the machine page showing raw window 5's orbit",
        "return document.getElementById('orbit-title').textContent.startsWith('Orbit, window 5 ') ? document.body.dataset.windows : null;",
    )
    .await;
    assert_eq!(shown, "5", "no result for window 5 yet: no worker");
    let mut f = f;
    f.start_worker();
    let after = until(
        &c,
        "the machine page showing window 5",
        "return document.body.dataset.windows === '6' && Number(document.querySelector('svg.trend[data-param=kx] path.dots').dataset.points) === 6 ? window.__marker : null;",
    )
    .await;
    assert_eq!(after, "machine page loaded once");
    c.switch_to_window(fleet_tab).await.unwrap();
    let after = until(
        &c,
        "the fleet page's press-4 tile at window 5",
        "const t = document.querySelector('.tile[data-id=\"press-4\"]'); return t && t.dataset.window === '5' ? window.__marker : null;",
    )
    .await;
    assert_eq!(after, "fleet page loaded once");
    if let Some(dir) = std::env::var_os("ROTORID_DASHBOARD_SCREENSHOTS") {
        std::fs::write(
            PathBuf::from(&dir).join("fleet.png"),
            c.screenshot().await.unwrap(),
        )
        .unwrap();
    }
    c.close().await.unwrap();
    drop(f);
}
