//! Test support: a nats-server with JetStream in a temporary directory on a free loopback
//! port, simulated machines (table1 variants with noise) and their scenario files.

#![allow(dead_code)]

use std::path::Path;
use std::process::{Child, Command, Stdio};

use rotorid::model::{InitialState, Rotor, RotorParams, Sampling, Scenario};
use rotorid::simulate::{add_noise, simulate, Method as Simulation, TimeResponse};
use rotorid::SpeedProfile;
use rotorid_fleet::Channel;

pub use rotorid_fleet::test_server::Server;

/// Rotors eq. (1) does not describe, from the library's adequacy tests.
#[path = "../../../rotorid/tests/it/defects.rs"]
pub mod defects;

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

/// The command of the test worker binary, its stdout piped (for its closing line).
fn worker_command(url: &str, durable: &str, method: &str, dir: &Path, ack_wait_s: f64) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rotorid-fleet-worker"));
    cmd.args([url, durable, method])
        .arg(dir)
        .arg(ack_wait_s.to_string())
        .stdout(Stdio::piped());
    cmd
}

/// The test worker binary as a child process.
pub fn spawn_worker(url: &str, durable: &str, method: &str, dir: &Path, ack_wait_s: f64) -> Worker {
    let child = worker_command(url, durable, method, dir, ack_wait_s)
        .spawn()
        .expect("the worker starts");
    Worker(Some(child))
}

/// A verbose worker (`ROTORID_FLEET_VERBOSE`) whose stderr the test reads, to know which
/// window it holds.
pub struct Watched {
    worker: Worker,
    /// Bytes of stderr read so far that do not yet end a line.
    partial: Vec<u8>,
    /// The last window it took and has not reported done (so not acknowledged).
    holding: Option<String>,
}

pub fn spawn_watched_worker(
    url: &str,
    durable: &str,
    method: &str,
    dir: &Path,
    ack_wait_s: f64,
) -> Watched {
    let child = worker_command(url, durable, method, dir, ack_wait_s)
        .env("ROTORID_FLEET_VERBOSE", "1")
        .stderr(Stdio::piped())
        .spawn()
        .expect("the worker starts");
    {
        use std::os::fd::AsRawFd as _;
        let fd = child.stderr.as_ref().expect("piped").as_raw_fd();
        // SAFETY: fcntl on a pipe descriptor this process owns
        let ok = unsafe { libc::fcntl(fd, libc::F_SETFL, libc::O_NONBLOCK) };
        assert_eq!(ok, 0, "stderr pipe made non-blocking");
    }
    Watched {
        worker: Worker(Some(child)),
        partial: Vec::new(),
        holding: None,
    }
}

impl Watched {
    /// Read what the worker has written on stderr so far (all of it, once it is stopped).
    fn drain(&mut self) {
        use std::io::Read as _;
        let child = self.worker.0.as_mut().expect("a running worker");
        let err = child.stderr.as_mut().expect("piped");
        let mut buf = [0u8; 4096];
        loop {
            match err.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => self.partial.extend_from_slice(&buf[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => panic!("reading the worker's stderr: {e}"),
            }
        }
        while let Some(end) = self.partial.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = self.partial.drain(..=end).collect();
            let line = String::from_utf8_lossy(&line);
            let what = line.split(" (stream").next().unwrap_or("").to_owned();
            if line.trim_end().ends_with(" taken") {
                self.holding = Some(what);
            } else if line.trim_end().ends_with(" done") {
                self.holding = None;
            }
        }
    }

    /// SIGKILL the worker at a moment it holds a window it has not acknowledged (so the
    /// server must redeliver it), and return that window. Stops the worker (SIGSTOP), reads
    /// everything it wrote, and either kills it or lets it go on (SIGCONT) and tries again.
    /// A partly written "done" line still means "not acknowledged": the ack follows it.
    pub fn kill_while_holding(mut self, within: std::time::Duration) -> String {
        let start = std::time::Instant::now();
        loop {
            let pid = self.worker.0.as_ref().expect("a running worker").id() as i32;
            // SAFETY: signals to our own child, which is not reaped yet
            unsafe { libc::kill(pid, libc::SIGSTOP) };
            // wait until it is stopped (WNOWAIT: an exit stays for the final wait)
            let mut info: libc::siginfo_t = unsafe { std::mem::zeroed() };
            // SAFETY: waitid on our own child, info is a valid out pointer
            let r = unsafe {
                libc::waitid(
                    libc::P_PID,
                    pid as libc::id_t,
                    &mut info,
                    libc::WSTOPPED | libc::WEXITED | libc::WNOWAIT,
                )
            };
            assert_eq!(r, 0, "waiting for the worker to stop");
            assert_eq!(
                info.si_code,
                libc::CLD_STOPPED,
                "the worker ended before it could be killed holding a window"
            );
            self.drain();
            if let Some(w) = self.holding.take() {
                self.worker.kill();
                return w;
            }
            unsafe { libc::kill(pid, libc::SIGCONT) };
            assert!(
                start.elapsed() < within,
                "the worker never held an unacknowledged window in {within:?}"
            );
            std::thread::sleep(std::time::Duration::from_millis(7));
        }
    }
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
