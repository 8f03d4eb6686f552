//! Test support: a nats-server with JetStream in a temporary directory on a free loopback
//! port, simulated machines (table1 variants with noise) and their scenario files.

#![allow(dead_code)]

use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use rotorid::model::{InitialState, Rotor, RotorParams, Sampling, Scenario};
use rotorid::simulate::{add_noise, simulate, Method as Simulation, TimeResponse};
use rotorid::SpeedProfile;
use rotorid_fleet::Channel;

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
            assert!(
                t.elapsed() < Duration::from_secs(20),
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

/// Machine `i`'s rotor: table1 with kx, kz, cx, cz varied by a few per cent.
pub fn rotor(i: usize) -> RotorParams {
    let p = Rotor::table1().params();
    let f = |a: f64| 1.0 + a * ((i as f64 * 0.37).sin());
    RotorParams {
        kx: p.kx * f(0.05),
        kz: p.kz * f(-0.04),
        cx: p.cx * f(0.2),
        cz: p.cz * f(0.1),
        ..p
    }
}

/// A scenario of `rotor` at 1200 rpm, `seconds` at 10 kHz from rest.
pub fn scenario(rotor: RotorParams, seconds: f64) -> Scenario {
    Scenario {
        rotor: Rotor::new(rotor).expect("a valid rotor"),
        speed: SpeedProfile::constant_rpm(1200.0, 0.0).expect("valid"),
        sampling: Sampling::new(1e-4, seconds).expect("valid"),
        initial: InitialState::default(),
    }
}

/// The scenario file of `s` (every number in shortest round-trip form).
pub fn scenario_toml(s: &Scenario) -> String {
    let p = s.rotor.params();
    format!(
        "[rotor]\nm = {:?}\ncx = {:?}\ncz = {:?}\nkx = {:?}\nkz = {:?}\na = {:?}\nm_u = {:?}\n\
         d = {:?}\nalpha_deg = 45.0\n\n[speed]\nkind = \"constant\"\nrpm = 1200.0\n\n\
         [sampling]\ndt = 1.0e-4\nduration = {:?}\n",
        p.m,
        p.cx,
        p.cz,
        p.kx,
        p.kz,
        p.a,
        p.unbalance.m_u,
        p.unbalance.d,
        s.sampling.duration()
    )
}

/// The noisy response (40 dB SNR, seed `seed`): duration / dt samples from t = 0 (the
/// simulator's sample at t = duration is dropped: whole windows).
pub fn response(s: &Scenario, seed: u64) -> TimeResponse {
    let mut r = simulate(s, Simulation::Exact).expect("simulates");
    let n = (s.sampling.duration() / s.sampling.dt()).round() as usize;
    for v in [
        &mut r.t,
        &mut r.x,
        &mut r.z,
        &mut r.phi,
        &mut r.phi_dot,
        &mut r.phi_ddot,
    ] {
        v.truncate(n);
    }
    add_noise(&mut r, 40.0, seed).expect("noise");
    r
}

/// The two probe channels of a response.
pub fn probes(r: &TimeResponse) -> Vec<Channel> {
    vec![
        Channel {
            name: "x".into(),
            unit: "m".into(),
            data: r.x.clone(),
        },
        Channel {
            name: "z".into(),
            unit: "m".into(),
            data: r.z.clone(),
        },
    ]
}

/// A worker process, SIGKILLed if the test ends (or panics) without [`terminate`].
pub struct Worker(Option<Child>);

impl Worker {
    /// SIGKILL it now and reap it.
    pub fn kill(&mut self) {
        if let Some(mut c) = self.0.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.kill();
    }
}

/// The test worker binary as a child process.
pub fn spawn_worker(url: &str, durable: &str, method: &str, dir: &Path, ack_wait_s: f64) -> Worker {
    let child = Command::new(env!("CARGO_BIN_EXE_rotorid-fleet-worker"))
        .arg(url)
        .arg(durable)
        .arg(method)
        .arg(dir)
        .arg(ack_wait_s.to_string())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the worker starts");
    Worker(Some(child))
}

/// SIGTERM the worker and wait for it; returns its exit status and stdout.
pub fn terminate(mut w: Worker) -> (std::process::ExitStatus, String) {
    let mut child = w.0.take().expect("a running worker");
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    let mut out = String::new();
    if let Some(mut o) = child.stdout.take() {
        use std::io::Read as _;
        let _ = o.read_to_string(&mut out);
    }
    (child.wait().expect("the worker exits"), out)
}
