//! `rotorid simulate`: integrate the rotor of the paper's eq. (1),
//!
//! ```text
//! m x'' + cx x' - a w z' - a w' z + kx x = m_u d ( w^2 sin(phi+alpha) - w' cos(phi+alpha) )
//! m z'' + cz z' + a w x'          + kz z = m_u d ( w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! over the scenario's sampling grid t_i = i dt (exactly `i as f64 * dt`), and write the
//! response CSV `t,x,z,phi,phi_dot,phi_ddot` (see [`crate::io::response_csv`]).
//!
//! Without noise, rows are streamed straight from the integrator's step loop (memory does
//! not grow with the record). With `--snr-db` the whole record is held in memory
//! (6 x 8 bytes per sample), because the noise level is relative to each channel's RMS
//! over the whole record (`rotorid::simulate::add_noise`, docs/method.md section 2.5).
//! A file output appears only once complete (temporary file + rename; see
//! [`crate::io::output`]); it may not be the scenario file. Runs that take more than a
//! moment report their progress on stderr ([`crate::io::progress`]).

use anyhow::Context as _;
use rotorid::simulate::{add_noise, integrator, Method, TimeResponse};

use crate::io::progress::Progress;
use crate::io::LoadScenario as _;
use crate::io::{
    check_distinct_files, is_broken_pipe, FileMode, Output, ResponseWriter, ScenarioSpec,
    SimulationOverrides,
};

const SIMULATE_EXAMPLES: &str =
    "Examples:\n  rotorid simulate --scenario table1 --out response.csv\n  \
     rotorid simulate --scenario ramp.toml --method newmark --snr-db 40 --seed 7 --out -";

/// Arguments of `rotorid simulate`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = SIMULATE_EXAMPLES,
    after_long_help = concat!(
        "Output: CSV with the header t,x,z,phi,phi_dot,phi_ddot, in SI units:\n  \
         t [s]                 time; row i is at t = i*dt exactly\n  \
         x, z [m]              disk displacement, horizontal and vertical\n  \
         phi [rad]             rotor angle\n  \
         phi_dot [rad/s]       rotor speed w\n  \
         phi_ddot [rad/s^2]    angular acceleration w'\n\
         Values are printed in shortest round-trip form: reading them back gives the identical \
         numbers.\n\n",
        "A finite-element scenario (rotor.model = \"finite_element\", docs/finite_element.md): \
         the columns t, <node>.<dof> for every degree of freedom (m; rx, ry in rad), phi, \
         phi_dot, phi_ddot, from rest, on the full model: exact at constant speed, the \
         fourth-order Magnus integrator on a ramp; --method newmark: average acceleration; \
         --snr-db adds noise to every degree of freedom at that SNR of its own RMS.\n\n",
        "Examples:\n  rotorid simulate --scenario table1 --out response.csv\n  \
         rotorid simulate --scenario ramp.toml --method newmark --snr-db 40 --seed 7 --out -"
    )
)]
pub struct SimulateArgs {
    /// The scenario: `table1` (built in: the paper's Table 1 rotor at 1200 rpm, dt = 0.1 ms,
    /// 1 s, from rest) or a TOML scenario file.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: String,

    /// Integration method. `exact` (default): exact discretisation at constant speed, DoPri8
    /// at tight tolerance otherwise, accurate to ~1e-10 of the signal. `newmark`: the paper's
    /// average-acceleration Newmark integrator (second order; ~1e-4 period error at 0.1 ms).
    #[arg(long, value_enum, default_value_t = MethodArg::Exact)]
    pub method: MethodArg,

    /// Record length [s] (overrides the scenario's sampling.duration).
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,

    /// Sampling period [s] (overrides the scenario's sampling.dt).
    #[arg(long, value_name = "S")]
    pub dt: Option<f64>,

    /// Add white Gaussian measurement noise to x and z at this signal-to-noise ratio [dB]:
    /// sigma = RMS(channel over the record) * 10^(-SNR/20). Holds the record in memory.
    #[arg(long, value_name = "DB", allow_hyphen_values = true)]
    pub snr_db: Option<f64>,

    /// Seed of the noise generator (default 0: runs are reproducible; the same seed gives
    /// byte-identical output, change it for an independent noise realisation).
    #[arg(long, value_name = "N", requires = "snr_db")]
    pub seed: Option<u64>,

    /// Initial horizontal displacement x(0) [m] (overrides [initial] x).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub initial_x: Option<f64>,

    /// Initial vertical displacement z(0) [m] (overrides [initial] z).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub initial_z: Option<f64>,

    /// Initial horizontal velocity x'(0) [m/s] (overrides [initial] vx).
    #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
    pub initial_vx: Option<f64>,

    /// Initial vertical velocity z'(0) [m/s] (overrides [initial] vz).
    #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
    pub initial_vz: Option<f64>,

    /// Output CSV file, or `-` for stdout. A file is written to a temporary name and
    /// renamed when complete, so a failed run never leaves a truncated file. A `.parquet`,
    /// `.mat` (level 5) or `.npz` file gets the same channels in that format (SI units).
    #[arg(long, short, value_name = "FILE.csv|-|FILE.parquet|FILE.mat|FILE.npz")]
    pub out: String,

    /// Write the raw acquisition of the scenario's [acquisition] instead of the response:
    /// probe voltages with gap, runout, noise and quantisation, the keyphasor pulse train
    /// and the time column, as its [acquisition.simulate] settings say (docs/acquisition.md).
    #[arg(long)]
    pub raw: bool,

    /// With --raw: also write the matching slow-roll record to this file.
    #[arg(long, value_name = "FILE", requires = "raw")]
    pub slow_roll_out: Option<String>,

    /// Do not print the noise level on stderr.
    #[arg(long, short)]
    pub quiet: bool,
}

/// `--method` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Exact discretisation / DoPri8 reference (~1e-10).
    Exact,
    /// The paper's average-acceleration Newmark integrator.
    Newmark,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Exact => Method::Exact,
            MethodArg::Newmark => Method::Newmark,
        }
    }
}

/// Run `rotorid simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    check_distinct_files(&[("--scenario", &args.scenario)], &[("--out", &args.out)])?;
    let spec = ScenarioSpec::load(&args.scenario)?;
    if spec.finite_element().is_some() {
        return simulate_finite_element(&args, &spec);
    }
    let scenario = spec.simulation(&SimulationOverrides {
        dt: args.dt,
        duration: args.duration,
        x: args.initial_x,
        z: args.initial_z,
        vx: args.initial_vx,
        vz: args.initial_vz,
    })?;
    let method = Method::from(args.method);
    let n = scenario.sampling.samples();
    if args.raw {
        return write_raw(&args, &spec, &scenario);
    }
    let format = rotorid_io::Format::from_path(std::path::Path::new(&args.out));
    if args.out != "-" && !matches!(format, Ok(rotorid_io::Format::Csv) | Err(_)) {
        return write_table_file(&args, &scenario, method);
    }
    let out = Output::create(&args.out, FileMode::Atomic)?;
    let to_stdout = out.is_stdout();
    let result = write_response(&args, &scenario, method, n, out);
    match result {
        Err(e) if to_stdout && is_broken_pipe(&e) => Ok(()),
        r => r,
    }
}

/// The response as a table of SI channels t, x, z, phi, phi_dot, phi_ddot.
fn response_table(file: &str, r: TimeResponse) -> rotorid_io::Table {
    let unit = ["s", "m", "m", "rad", "rad/s", "rad/s^2"];
    let data = [r.t, r.x, r.z, r.phi, r.phi_dot, r.phi_ddot];
    rotorid_io::Table {
        file: file.to_owned(),
        notes: Vec::new(),
        channels: ["t", "x", "z", "phi", "phi_dot", "phi_ddot"]
            .into_iter()
            .zip(data)
            .zip(unit)
            .map(|((name, data), u)| rotorid_io::Channel {
                name: name.to_owned(),
                unit: Some(u.to_owned()),
                data,
                axis: None,
            })
            .collect(),
    }
}

/// White noise at `snr_db` (seed `--seed`, default 0) added to `resp`, said on stderr
/// unless `-q`.
fn noisy(args: &SimulateArgs, resp: &mut TimeResponse, snr_db: f64) -> anyhow::Result<()> {
    let seed = args.seed.unwrap_or(0);
    let level = add_noise(resp, snr_db, seed)?;
    if !args.quiet {
        eprintln!(
            "added white noise at SNR {snr_db} dB (seed {seed}): sigma_x = {:e} m, \
             sigma_z = {:e} m",
            level.sigma_x, level.sigma_z
        );
    }
    Ok(())
}

/// `--out` in a binary format: the whole response, then the file.
fn write_table_file(
    args: &SimulateArgs,
    scenario: &rotorid::Scenario,
    method: Method,
) -> anyhow::Result<()> {
    let mut resp = rotorid::simulate::simulate(scenario, method)?;
    if let Some(snr_db) = args.snr_db {
        noisy(args, &mut resp, snr_db)?;
    }
    rotorid_io::write_table(&args.out, &response_table(&args.out, resp))?;
    Ok(())
}

/// A raw record as a table (names as the acquisition gives them; volts and s).
fn raw_table(file: &str, raw: rotorid::acquisition::RawRecord) -> rotorid_io::Table {
    rotorid_io::Table {
        file: file.to_owned(),
        notes: Vec::new(),
        channels: raw
            .columns
            .into_iter()
            .map(|(name, data)| rotorid_io::Channel {
                name,
                unit: None,
                data,
                axis: None,
            })
            .collect(),
    }
}

/// Write `t` to `path`: CSV (header = names, shortest round-trip numbers; a non-finite
/// value, which only `rotorid predict`'s unknown standard deviations are, as an empty
/// cell) or a binary format by the extension.
pub(crate) fn write_any(path: &str, t: &rotorid_io::Table) -> anyhow::Result<()> {
    let format = rotorid_io::Format::from_path(std::path::Path::new(path));
    if path != "-" && !matches!(format, Ok(rotorid_io::Format::Csv) | Err(_)) {
        rotorid_io::write_table(path, t)?;
        return Ok(());
    }
    let mut out = Output::create(path, FileMode::Atomic)?;
    let names: Vec<&str> = t.channels.iter().map(|c| c.name.as_str()).collect();
    use std::io::Write as _;
    writeln!(out, "{}", names.join(",")).with_context(|| format!("cannot write {path}"))?;
    let (mut scratch, mut row) = (Vec::with_capacity(64), Vec::with_capacity(names.len()));
    let n = t.channels.first().map_or(0, |c| c.data.len());
    for i in 0..n {
        row.clear();
        row.extend(
            t.channels
                .iter()
                .map(|c| Some(c.data[i]).filter(|v| v.is_finite())),
        );
        crate::io::number::write_row(&mut out, &mut scratch, &row)
            .with_context(|| format!("cannot write {path}"))?;
    }
    out.commit()
}

/// A finite-element scenario (docs/finite_element.md): the response at every degree of
/// freedom, columns `t`, `<node>.<dof>` ... (m or rad), `phi`, `phi_dot`, `phi_ddot`, from
/// rest. `--method exact`: exact discretisation at constant speed, the fourth-order Magnus
/// integrator on a ramp (~1e-11 of the response at 10 kHz); `newmark`: average
/// acceleration. The full model, no reduction: this is the reference.
fn simulate_finite_element(args: &SimulateArgs, spec: &ScenarioSpec) -> anyhow::Result<()> {
    use rotorid::model::finite_element::FeSystem;
    use rotorid::simulate::finite_element::{simulate_fe, FeMethod};
    let given = [
        ("--initial-x", args.initial_x),
        ("--initial-z", args.initial_z),
        ("--initial-vx", args.initial_vx),
        ("--initial-vz", args.initial_vz),
    ];
    if let Some((flag, _)) = given.iter().find(|(_, v)| v.is_some()) {
        anyhow::bail!(
            "{flag}: {} is a finite-element rotor, which is simulated from rest (the initial \
             state of the 2-DOF models does not apply)",
            spec.origin()
        );
    }
    let rotor = crate::io::finite_element::finite_element_of(spec)?;
    let (speed, sampling) = spec.fe_simulation(&SimulationOverrides {
        dt: args.dt,
        duration: args.duration,
        ..SimulationOverrides::default()
    })?;
    let method = match (args.method, speed) {
        (MethodArg::Newmark, _) => FeMethod::Newmark,
        (MethodArg::Exact, rotorid::SpeedProfile::Constant { .. }) => FeMethod::Exact,
        (MethodArg::Exact, _) => FeMethod::Magnus,
    };
    let system = FeSystem::full(&rotor);
    if args.raw {
        return write_fe_raw(args, spec, &rotor, &system, (&speed, &sampling), method);
    }
    let mut r = simulate_fe(&system, &speed, &sampling, None, None, method)?;
    if let Some(snr_db) = args.snr_db {
        let seed = args.seed.unwrap_or(0);
        let mut cols: Vec<(&'static str, &mut [f64])> =
            r.q.iter_mut()
                .map(|c| ("finite-element response", &mut c[..]))
                .collect();
        let sigmas = rotorid::simulate::add_noise_to(&mut cols, snr_db, seed)?;
        if !args.quiet {
            eprintln!(
                "added white noise at SNR {snr_db} dB (seed {seed}) to every degree of \
                 freedom: sigma {}",
                sigma_list(&r.dofs, &sigmas)
            );
        }
    }
    let table = crate::io::fe_response::fe_table(&args.out, r);
    if !args.quiet {
        eprintln!(
            "simulated the finite-element rotor of {} ({} degrees of freedom, {} bearings, \
             {} unbalances) by {method}",
            spec.origin(),
            rotor.matrices.n(),
            rotor.bearings.len(),
            rotor.unbalances.len()
        );
    }
    match write_any(&args.out, &table) {
        Err(e) if args.out == "-" && is_broken_pipe(&e) => Ok(()),
        r => r,
    }
}

/// `dof sigma unit, ...` for the noise message.
fn sigma_list(dofs: &[rotorid::model::finite_element::Dof], sigmas: &[f64]) -> String {
    let each: Vec<String> = dofs
        .iter()
        .zip(sigmas)
        .map(|(d, s)| format!("{d} {s:e} {}", d.kind.unit()))
        .collect();
    each.join(", ")
}

/// `--raw` of a finite-element scenario: the probes' volts at their nodes (two per node,
/// `[[acquisition.probe]] node = N`) and the keyphasor, from the full model's response at
/// the measured nodes (`rotorid::acquisition::simulate_fe_raw`, docs/acquisition.md
/// section 11). No slow-roll record.
fn write_fe_raw(
    args: &SimulateArgs,
    spec: &ScenarioSpec,
    rotor: &rotorid::model::finite_element::FiniteElementRotor,
    system: &rotorid::model::finite_element::FeSystem,
    (speed, sampling): (&rotorid::SpeedProfile, &rotorid::Sampling),
    method: rotorid::simulate::finite_element::FeMethod,
) -> anyhow::Result<()> {
    let Some(acq) = crate::io::finite_element::fe_acquisition_of(spec, rotor)? else {
        anyhow::bail!(
            "--raw needs an [acquisition] table in the scenario {} (two [[acquisition.probe]] \
             per measured node, each with node = N, and a keyphasor; see docs/acquisition.md)",
            spec.origin()
        );
    };
    if args.slow_roll_out.is_some() {
        anyhow::bail!(
            "--slow-roll-out: the slow-roll record of a finite-element rotor is not simulated \
             (the running record is: drop --slow-roll-out)"
        );
    }
    let sim = rotorid::acquisition::simulate_fe_raw(system, speed, sampling, acq, method)?;
    if !args.quiet {
        eprintln!(
            "raw acquisition of the finite-element rotor of {} by {method}: noise sigma {} on \
             the displacements",
            spec.origin(),
            sigma_list(&sim.truth.dofs, &sim.sigma)
        );
    }
    write_any(&args.out, &raw_table(&args.out, sim.running))
}

/// `--raw`: the raw acquisition of the scenario's [acquisition] (and its slow roll).
fn write_raw(
    args: &SimulateArgs,
    spec: &ScenarioSpec,
    scenario: &rotorid::Scenario,
) -> anyhow::Result<()> {
    let Some(acq) = spec.acquisition() else {
        anyhow::bail!(
            "--raw needs an [acquisition] table in the scenario {} (probes, keyphasor; see \
             docs/acquisition.md)",
            spec.origin()
        );
    };
    let sim = rotorid::acquisition::simulate_raw(scenario, acq)?;
    if !args.quiet {
        eprintln!(
            "raw acquisition: noise sigma_x = {:e} m, sigma_z = {:e} m on the displacements",
            sim.noise.sigma_x, sim.noise.sigma_z
        );
    }
    if let Some(path) = &args.slow_roll_out {
        let Some(slow) = sim.slow_roll else {
            anyhow::bail!(
                "--slow-roll-out: the scenario's [acquisition.simulate] has no slow roll \
                 (slow_roll_rpm)"
            );
        };
        write_any(path, &raw_table(path, slow))?;
    }
    write_any(&args.out, &raw_table(&args.out, sim.running))
}

fn write_response(
    args: &SimulateArgs,
    scenario: &rotorid::Scenario,
    method: Method,
    n: usize,
    out: Output,
) -> anyhow::Result<()> {
    let name = out.name().to_owned();
    let mut w = ResponseWriter::new(out).with_context(|| format!("cannot write {name}"))?;
    let mut integ = integrator(scenario, method)?;
    let mut progress = Progress::new(n as u64, &format!("simulate ({method})"));
    match args.snr_db {
        None => {
            let s = integ.current();
            w.write(s.t, s.x, s.z, &s.speed)
                .with_context(|| format!("cannot write {name}"))?;
            for i in 1..n {
                let s = integ.step()?;
                w.write(s.t, s.x, s.z, &s.speed)
                    .with_context(|| format!("cannot write {name}"))?;
                progress.update(i as u64);
            }
        }
        Some(snr_db) => {
            let mut resp = TimeResponse::with_capacity(n);
            resp.push(&integ.current());
            for i in 1..n {
                resp.push(&integ.step()?);
                progress.update(i as u64);
            }
            noisy(args, &mut resp, snr_db)?;
            for i in 0..resp.len() {
                let speed = rotorid::SpeedState {
                    phi: resp.phi[i],
                    omega: resp.phi_dot[i],
                    omega_dot: resp.phi_ddot[i],
                };
                w.write(resp.t[i], resp.x[i], resp.z[i], &speed)
                    .with_context(|| format!("cannot write {name}"))?;
            }
        }
    }
    progress.finish();
    w.into_inner().commit()
}
