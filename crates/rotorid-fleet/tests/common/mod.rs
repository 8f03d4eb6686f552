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

/// A worker that holds the `n`-th window it takes unacknowledged until it is killed
/// (`ROTORID_FLEET_HOLD_AFTER`, `WorkerConfig::hold_after`); the test reads its stderr to
/// learn which window.
pub struct Holding {
    worker: Worker,
}

pub fn spawn_holding_worker(
    url: &str,
    durable: &str,
    method: &str,
    dir: &Path,
    ack_wait_s: f64,
    n: u64,
) -> Holding {
    let child = worker_command(url, durable, method, dir, ack_wait_s)
        .env("ROTORID_FLEET_HOLD_AFTER", n.to_string())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the worker starts");
    Holding {
        worker: Worker(Some(child)),
    }
}

impl Holding {
    /// Block until the worker says it holds its window, and return (machine, window); a
    /// worker that exits first fails the test with what it wrote.
    pub fn wait_until_holding(&mut self) -> (String, u64) {
        use std::io::BufRead as _;
        let child = self.worker.0.as_mut().expect("a running worker");
        let err = std::io::BufReader::new(child.stderr.as_mut().expect("piped"));
        let mut seen = Vec::new();
        for line in err.lines() {
            let line = line.expect("the worker's stderr");
            // "holding window W of machine M (delivery D)"
            if let Some(rest) = line.strip_prefix("holding window ") {
                let mut w = rest.split_whitespace();
                let window = w.next().and_then(|v| v.parse().ok());
                let machine = w.nth(2).map(str::to_owned);
                if let (Some(window), Some(machine)) = (window, machine) {
                    return (machine, window);
                }
            }
            seen.push(line);
        }
        panic!(
            "the worker ended before it held a window: {}",
            seen.join("\n")
        );
    }

    /// SIGKILL it (it holds its window unacknowledged) and reap it.
    pub fn kill(mut self) {
        self.worker.kill();
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
