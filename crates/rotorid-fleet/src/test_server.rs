//! A nats-server of a test's own (feature `test-server`): JetStream, its store in a
//! directory the test chooses, on a free loopback port; killed when dropped. Used by this
//! crate's end-to-end tests and the `rotorid` command's fleet tests. Needs the Debian
//! package `nats-server` (`.ci/test` installs it) or `$NATS_SERVER`.

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
