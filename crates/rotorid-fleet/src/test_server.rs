//! A nats-server of a test's own (feature `test-server`): JetStream, its store in a
//! directory the test chooses, on a free loopback port; killed when dropped. Used by this
//! crate's end-to-end tests and the `rotorid` command's fleet tests. Needs the Debian
//! package `nats-server` (`.ci/test` installs it) or `$NATS_SERVER`.
//!
//! [`Cluster`]: three (or more) such servers in one JetStream cluster
//! (`--cluster_name`, `--cluster`, `--routes`, each with its own store directory), for the
//! tests that lose a node for good.

use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A nats-server of our own.
pub struct Server {
    pub port: u16,
    dir: PathBuf,
    child: Option<Child>,
}

/// `$NATS_SERVER`, else `nats-server` on the PATH, else the Debian package's.
fn nats_server() -> PathBuf {
    if let Some(p) = std::env::var_os("NATS_SERVER") {
        return p.into();
    }
    let on_path = std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join("nats-server").is_file()));
    if on_path {
        "nats-server".into()
    } else {
        "/usr/sbin/nats-server".into()
    }
}

fn free_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").expect("a free loopback port");
    l.local_addr().expect("its address").port()
}

impl Server {
    /// Start `nats-server -js -sd DIR` on a free port of 127.0.0.1.
    pub fn start(dir: &Path) -> Self {
        let mut s = Self {
            port: free_port(),
            dir: dir.to_owned(),
            child: None,
        };
        s.spawn();
        s
    }

    fn spawn(&mut self) {
        let child = Command::new(nats_server())
            .args(["-js", "-a", "127.0.0.1", "-p"])
            .arg(self.port.to_string())
            .arg("-sd")
            .arg(&self.dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect(
                "nats-server is not installed: `apt-get install -y nats-server` (.ci/test \
                 does it)",
            );
        self.child = Some(child);
        let t = Instant::now();
        while TcpStream::connect(("127.0.0.1", self.port)).is_err() {
            // against a hang only: a busy machine may be slow to start it
            assert!(
                t.elapsed() < Duration::from_secs(120),
                "nats-server did not start"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    pub fn url(&self) -> String {
        format!("nats://127.0.0.1:{}", self.port)
    }

    /// SIGKILL the server and start it again on the same port and store.
    pub fn restart(&mut self) {
        self.kill();
        self.spawn();
    }

    /// SIGKILL the server and leave it down (until [`Server::resume`]).
    pub fn stop(&mut self) {
        self.kill();
    }

    /// Start a stopped server again on the same port and store.
    pub fn resume(&mut self) {
        if self.child.is_none() {
            self.spawn();
        }
    }

    fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.kill();
    }
}

/// A JetStream cluster of nats-servers of our own on loopback ports, each with its own
/// store directory; every node still running is killed when dropped.
pub struct Cluster {
    /// The nodes' client ports, by index.
    pub ports: Vec<u16>,
    children: Vec<Option<Child>>,
}

/// GET `path` of the monitoring port `port`: the body, when it answers.
fn monitor_get(port: u16, path: &str) -> Option<String> {
    use std::io::{Read as _, Write as _};
    let mut s = TcpStream::connect(("127.0.0.1", port)).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n"
    )
    .ok()?;
    let mut body = String::new();
    s.read_to_string(&mut body).ok()?;
    body.split_once("\r\n\r\n").map(|(_, b)| b.to_owned())
}

impl Cluster {
    /// Start `n` nodes named `n0`, `n1`, ... (cluster `rotorid-test`), node i storing in
    /// `dir/n<i>`, and wait until every node is up and JetStream has elected its meta
    /// leader with all `n` peers (a condition, for up to 60 s: a busy machine is slow).
    pub fn start(dir: &Path, n: usize) -> Self {
        // a node that cannot bind its ports (taken meanwhile by another process) exits at
        // once: start again on other ports rather than wait for a cluster that cannot form
        let mut why = String::new();
        for attempt in 0..3 {
            match Self::try_start(&dir.join(format!("try{attempt}")), n) {
                Ok(c) => return c,
                Err(e) => why = e,
            }
        }
        panic!("the nats-server cluster did not form: {why}");
    }

    fn try_start(dir: &Path, n: usize) -> Result<Self, String> {
        // 3n distinct ports: every listener is held until all are chosen
        let listeners: Vec<std::net::TcpListener> = (0..3 * n)
            .map(|_| std::net::TcpListener::bind("127.0.0.1:0").expect("a free loopback port"))
            .collect();
        let port = |i: usize| listeners[i].local_addr().expect("its address").port();
        let ports: Vec<u16> = (0..n).map(port).collect();
        let routes: Vec<u16> = (n..2 * n).map(port).collect();
        let monitors: Vec<u16> = (2 * n..3 * n).map(port).collect();
        drop(listeners);
        let route_list = routes
            .iter()
            .map(|p| format!("nats://127.0.0.1:{p}"))
            .collect::<Vec<_>>()
            .join(",");
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let log = |i: usize| dir.join(format!("n{i}.log"));
        let mut children = Vec::new();
        for i in 0..n {
            let err = std::fs::File::create(log(i)).map_err(|e| e.to_string())?;
            let child = Command::new(nats_server())
                .args(["-js", "-a", "127.0.0.1", "-p"])
                .arg(ports[i].to_string())
                .args(["-n", &format!("n{i}"), "-m"])
                .arg(monitors[i].to_string())
                .arg("-sd")
                .arg(dir.join(format!("n{i}")))
                .args(["--cluster_name", "rotorid-test", "--cluster"])
                .arg(format!("nats://127.0.0.1:{}", routes[i]))
                .args(["--routes", &route_list])
                .stdout(Stdio::null())
                .stderr(err)
                .spawn()
                .expect(
                    "nats-server is not installed: `apt-get install -y nats-server` (.ci/test \
                     does it)",
                );
            children.push(Some(child));
        }
        let mut c = Self { ports, children };
        let t = Instant::now();
        // every node is a member of the meta group and knows its leader
        let ready = |m: u16| {
            monitor_get(m, "/jsz").is_some_and(|b| {
                let size = format!("\"cluster_size\": {n}");
                let size2 = format!("\"cluster_size\":{n}");
                (b.contains(&size) || b.contains(&size2)) && b.contains("\"leader\"")
            }) && monitor_get(m, "/healthz").is_some_and(|b| b.contains("ok"))
        };
        let tail = |i: usize| {
            let text = std::fs::read_to_string(log(i)).unwrap_or_default();
            let lines: Vec<&str> = text.lines().collect();
            lines[lines.len().saturating_sub(5)..].join("\n")
        };
        while !monitors.iter().all(|&m| ready(m)) {
            for i in 0..n {
                let exited = c.children[i]
                    .as_mut()
                    .is_some_and(|ch| ch.try_wait().ok().flatten().is_some());
                if exited {
                    return Err(format!("node n{i} exited:\n{}", tail(i)));
                }
            }
            if t.elapsed() > Duration::from_secs(60) {
                let logs: Vec<String> = (0..n).map(|i| format!("n{i}: {}", tail(i))).collect();
                return Err(format!("not formed in 60 s:\n{}", logs.join("\n")));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(c)
    }

    /// The client URL of node `i`.
    pub fn url(&self, i: usize) -> String {
        format!("nats://127.0.0.1:{}", self.ports[i])
    }

    /// Every node's URL, comma-separated, node 0 first.
    pub fn urls(&self) -> String {
        (0..self.ports.len())
            .map(|i| self.url(i))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// The index of the node named `name` (`n1` -> 1).
    pub fn index_of(&self, name: &str) -> Option<usize> {
        name.strip_prefix('n')?
            .parse()
            .ok()
            .filter(|&i: &usize| i < self.ports.len())
    }

    /// SIGKILL node `i`, for good.
    pub fn kill(&mut self, i: usize) {
        if let Some(mut c) = self.children[i].take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for i in 0..self.children.len() {
            self.kill(i);
        }
    }
}
