//! Raw acquisitions simulated from a scenario (docs/acquisition.md section 7): what two
//! proximity probes and a keyphasor would record, with the simulator's exact x, z, phi as
//! the truth.
//!
//! ```text
//! x_n, z_n = x, z + white noise at the SNR (docs/method.md section 2.5: sigma = RMS 10^(-SNR/20))
//! V_i      = V_gap,i + s_i ( x_n cos t_i + z_n sin t_i + r_i(phi) ),   r_i(phi) = sum_h A_ih cos(h phi + p_ih)
//! V_kp     = V_base -/+ D g(u),  u = phi - phi_kp - 2 pi n - w j_n  (the n-th revolution, jitter j_n ~ N(0, sigma_j))
//! g(u)     = S(u / e) (1 - S((u - W) / e)),   S(y) = 0 (y < -1/2), 1/2 + sin(pi y)/2, 1 (y > 1/2)
//! ```
//!
//! with the notch of angular width W and edges of width e centred on the event angle (so
//! the mid-level crossing of the leading edge is exactly at phi = phi_kp + w j_n), a minus
//! sign for a falling edge (a notch) and a plus for a rising one (a key); white noise of
//! `kp_noise_v` on the keyphasor; every voltage quantised to N bits over \[V_lo, V_hi\]:
//! `V_q = V_lo + round((V - V_lo) / q) q`, q = (V_hi - V_lo) / 2^N, clipped to the range.
//!
//! The slow-roll record is the same rotor at a constant `slow_roll_rpm` started in its
//! steady state (a long-established slow roll: no transient), with the same runout, gap,
//! keyphasor and noise standard deviations.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::model::{check, InitialState, Sampling, Scenario, SpeedProfile};
use crate::simulate::{add_noise, simulate, steady_state, Method, NoiseLevel, TimeResponse};

use super::error::AcquisitionError;
use super::probes::toward;
use super::{Acquisition, Edge, RawRecord, TimeBase};

/// What is added to `[acquisition.simulate] seed` to seed the keyphasor's draws (jitter,
/// noise).
pub(super) const KEYPHASOR_SEED: u64 = 0x5eed_0001;

/// One runout harmonic: A cos(h phi + p).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunoutHarmonic {
    /// Order h (1 = 1X).
    pub harmonic: u32,
    /// Amplitude A \[m\].
    pub amplitude: f64,
    /// Phase p \[rad\].
    pub phase: f64,
}

/// Settings of the raw simulation (`[acquisition.simulate]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RawSettings {
    /// DC (gap) voltage of each probe at equilibrium \[V\].
    pub gap_v: [f64; 2],
    /// Runout of each probe.
    pub runout: [Vec<RunoutHarmonic>; 2],
    /// SNR of the white noise on x, z \[dB\]; `None`: no noise.
    pub snr_db: Option<f64>,
    /// Seed of every random draw.
    pub seed: u64,
    /// ADC bits; `None`: no quantisation.
    pub bits: Option<u32>,
    /// ADC range \[V\] (low, high).
    pub range_v: [f64; 2],
    /// Keyphasor level away from the notch \[V\].
    pub kp_baseline_v: f64,
    /// Keyphasor notch (or key) depth \[V\], > 0.
    pub kp_depth_v: f64,
    /// Notch width W \[rad\].
    pub kp_width: f64,
    /// Edge width e \[rad\].
    pub kp_edge: f64,
    /// RMS timing jitter of the keyphasor events \[s\].
    pub kp_jitter_s: f64,
    /// White noise on the keyphasor \[V\].
    pub kp_noise_v: f64,
    /// Slow-roll speed \[rev/min\]; the slow-roll record is written when > 0.
    pub slow_roll_rpm: f64,
    /// Slow-roll duration \[s\].
    pub slow_roll_duration_s: f64,
}

impl Default for RawSettings {
    /// Gaps -9.0 V and -10.5 V; runout 1X-3X of a few micrometres (probe 1: 2.0, 1.0,
    /// 0.5 um; probe 2: 1.5, 0.8, 0.4 um); 40 dB; 16 bits over -24..0 V; keyphasor -8 V
    /// with a 6 V notch 10 deg wide with 2 deg edges, 1 us jitter, 5 mV noise; slow roll
    /// 100 rpm for 2 s.
    fn default() -> Self {
        let h = |harmonic, um: f64, deg: f64| RunoutHarmonic {
            harmonic,
            amplitude: um * 1e-6,
            phase: deg.to_radians(),
        };
        Self {
            gap_v: [-9.0, -10.5],
            runout: [
                vec![h(1, 2.0, 30.0), h(2, 1.0, 100.0), h(3, 0.5, 200.0)],
                vec![h(1, 1.5, -60.0), h(2, 0.8, 10.0), h(3, 0.4, 135.0)],
            ],
            snr_db: Some(40.0),
            seed: 1,
            bits: Some(16),
            range_v: [-24.0, 0.0],
            kp_baseline_v: -8.0,
            kp_depth_v: 6.0,
            kp_width: 10f64.to_radians(),
            kp_edge: 2f64.to_radians(),
            kp_jitter_s: 1e-6,
            kp_noise_v: 0.005,
            slow_roll_rpm: 100.0,
            slow_roll_duration_s: 2.0,
        }
    }
}

impl RawSettings {
    /// Check every setting (named as in `[acquisition.simulate]`).
    pub fn validate(&self) -> Result<(), AcquisitionError> {
        for g in self.gap_v {
            check("acquisition.simulate.gap_v", g, "finite (V)", |_| true)?;
        }
        for r in self.runout.iter().flatten() {
            check(
                "acquisition.simulate.runout amplitude",
                r.amplitude,
                "finite and >= 0 (m)",
                |v| v >= 0.0,
            )?;
            check(
                "acquisition.simulate.runout phase",
                r.phase,
                "finite (rad)",
                |_| true,
            )?;
            check(
                "acquisition.simulate.runout harmonic",
                r.harmonic as f64,
                "an integer from 1 to 64",
                |v| (1.0..=64.0).contains(&v),
            )?;
        }
        if let Some(s) = self.snr_db {
            check("acquisition.simulate.snr_db", s, "finite (dB)", |_| true)?;
        }
        if let Some(b) = self.bits {
            check(
                "acquisition.simulate.bits",
                b as f64,
                "an integer from 2 to 32",
                |v| (2.0..=32.0).contains(&v),
            )?;
        }
        check(
            "acquisition.simulate.range_v",
            self.range_v[1] - self.range_v[0],
            "finite with high > low (V)",
            |v| v > 0.0,
        )?;
        check(
            "acquisition.simulate.kp_baseline_v",
            self.kp_baseline_v,
            "finite (V)",
            |_| true,
        )?;
        check(
            "acquisition.simulate.kp_depth_v",
            self.kp_depth_v,
            "finite and > 0 (V)",
            |v| v > 0.0,
        )?;
        check(
            "acquisition.simulate.kp_width_deg",
            self.kp_width,
            "finite, > 0 and < 180 (deg)",
            |v| v > 0.0 && v < PI,
        )?;
        check(
            "acquisition.simulate.kp_edge_deg",
            self.kp_edge,
            "finite, >= 0 and less than the notch width (deg)",
            |v| v >= 0.0 && v < self.kp_width,
        )?;
        check(
            "acquisition.simulate.kp_jitter_s",
            self.kp_jitter_s,
            "finite and >= 0 (s)",
            |v| v >= 0.0,
        )?;
        check(
            "acquisition.simulate.kp_noise_v",
            self.kp_noise_v,
            "finite and >= 0 (V)",
            |v| v >= 0.0,
        )?;
        check(
            "acquisition.simulate.slow_roll_rpm",
            self.slow_roll_rpm,
            "finite and >= 0 (rev/min)",
            |v| v >= 0.0,
        )?;
        check(
            "acquisition.simulate.slow_roll_duration_s",
            self.slow_roll_duration_s,
            "finite and > 0 (s)",
            |v| v > 0.0,
        )?;
        Ok(())
    }
}

/// A simulated raw acquisition with its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct RawSimulation {
    /// The running record: time column (when the time base is a column), the two probes,
    /// the keyphasor, in volts.
    pub running: RawRecord,
    /// The exact response (x, z, phi, w, w').
    pub truth: TimeResponse,
    /// The exact response with the same noise on x, z as the probes carry: "perfectly
    /// conditioned channels".
    pub noisy: TimeResponse,
    /// The noise added to x and z.
    pub noise: NoiseLevel,
    /// The slow-roll record (when `slow_roll_rpm` > 0).
    pub slow_roll: Option<RawRecord>,
    /// Its exact response.
    pub slow_roll_truth: Option<TimeResponse>,
}

/// The smooth step S(y) of the module doc.
fn smooth_step(y: f64) -> f64 {
    if y <= -0.5 {
        0.0
    } else if y >= 0.5 {
        1.0
    } else {
        0.5 + 0.5 * (PI * y).sin()
    }
}

/// Quantiser of the module doc (identity without bits).
pub(super) struct Adc {
    lo: f64,
    q: f64,
    top: f64,
}

impl Adc {
    pub(super) fn new(s: &RawSettings) -> Option<Self> {
        let b = s.bits?;
        let [lo, hi] = s.range_v;
        let q = (hi - lo) / 2f64.powi(b as i32);
        Some(Self {
            lo,
            q,
            top: (2f64.powi(b as i32) - 1.0),
        })
    }
    fn apply(&self, v: f64) -> f64 {
        self.lo + ((v - self.lo) / self.q).round().clamp(0.0, self.top) * self.q
    }
}

/// The raw channels of one record from its (noisy) x, z and true phi, w.
fn channels(
    acq: &Acquisition,
    s: &RawSettings,
    x: &[f64],
    z: &[f64],
    resp: &TimeResponse,
    rng: &mut ChaCha8Rng,
) -> RawRecord {
    let adc = Adc::new(s);
    let mut cols = Vec::new();
    if let TimeBase::Column(c) = &acq.time {
        cols.push((c.clone(), resp.t.clone()));
    }
    for k in 0..2 {
        let p = &acq.probes[k];
        let v = probe_volts(p, s.gap_v[k], &s.runout[k], adc.as_ref(), x, z, &resp.phi);
        cols.push((p.column.clone(), v));
    }
    let kp = keyphasor_volts(acq, s, adc.as_ref(), &resp.phi, &resp.phi_dot, rng);
    cols.push((acq.keyphasor.column.clone(), kp));
    RawRecord { columns: cols }
}

/// The volts of probe `p` (gap `gap_v`, runout `runout`, quantised by `adc` when given)
/// for the shaft at (x, z) at angle phi, sample by sample:
/// `gap_v + s (x cos t + z sin t + r(phi))`.
pub(super) fn probe_volts(
    p: &super::Probe,
    gap_v: f64,
    runout: &[RunoutHarmonic],
    adc: Option<&Adc>,
    x: &[f64],
    z: &[f64],
    phi: &[f64],
) -> Vec<f64> {
    let quant = |v: f64| adc.map_or(v, |a| a.apply(v));
    (0..x.len())
        .map(|i| {
            let r: f64 = runout
                .iter()
                .map(|h| h.amplitude * (h.harmonic as f64 * phi[i] + h.phase).cos())
                .sum();
            quant(gap_v + p.sensitivity * (toward(p.angle, x[i], z[i]) + r))
        })
        .collect()
}

/// The keyphasor's volts for the shaft angle `phi` and speed `phi_dot` (module doc): one
/// jitter draw per revolution from `rng`, then one noise draw per sample.
pub(super) fn keyphasor_volts(
    acq: &Acquisition,
    s: &RawSettings,
    adc: Option<&Adc>,
    phi: &[f64],
    phi_dot: &[f64],
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    let n = phi.len();
    let quant = |v: f64| adc.map_or(v, |a| a.apply(v));
    let phi_kp = acq.keyphasor.angle;
    let rev = |phi: f64| ((phi - phi_kp) / (2.0 * PI) + 0.5).floor() as i64;
    let r0 = rev(phi[0]) - 1;
    let r1 = rev(phi[n - 1]) + 1;
    let jitter: Vec<f64> = (r0..=r1)
        .map(|_| s.kp_jitter_s * rng.sample::<f64, _>(StandardNormal))
        .collect();
    let sign = match acq.keyphasor.edge {
        Edge::Falling => -1.0,
        Edge::Rising => 1.0,
    };
    (0..n)
        .map(|i| {
            let psi = phi[i] - phi_kp;
            let r = rev(phi[i]);
            let u = psi - 2.0 * PI * r as f64 - phi_dot[i] * jitter[(r - r0) as usize];
            let g = if s.kp_edge > 0.0 {
                smooth_step(u / s.kp_edge) * (1.0 - smooth_step((u - s.kp_width) / s.kp_edge))
            } else if (0.0..s.kp_width).contains(&u) {
                1.0
            } else {
                0.0
            };
            let noise: f64 = rng.sample(StandardNormal);
            quant(s.kp_baseline_v + sign * s.kp_depth_v * g + s.kp_noise_v * noise)
        })
        .collect()
}

/// Simulate a raw acquisition of `scenario` (exact simulation, docs/method.md section 2)
/// with the probes, keyphasor and settings of `acq` (module doc). With `acq.time` a rate,
/// it must equal 1 / dt of the scenario.
pub fn simulate_raw(
    scenario: &Scenario,
    acq: &Acquisition,
) -> Result<RawSimulation, AcquisitionError> {
    acq.validate()?;
    let s = &acq.simulate;
    s.validate()?;
    if let TimeBase::RateHz(r) = acq.time {
        let dt = scenario.sampling.dt();
        if ((r * dt) - 1.0).abs() > 1e-9 {
            return Err(AcquisitionError::Simulate(format!(
                "acquisition.rate_hz = {r} Hz does not match the scenario's sampling.dt = {dt} s (1 / dt = {} Hz)",
                1.0 / dt
            )));
        }
    }
    let sim = |sc: &Scenario| {
        simulate(sc, Method::Exact).map_err(|e| AcquisitionError::Simulate(e.to_string()))
    };
    let truth = sim(scenario)?;
    let mut noisy = truth.clone();
    let noise = match s.snr_db {
        Some(snr) => add_noise(&mut noisy, snr, s.seed)
            .map_err(|e| AcquisitionError::Simulate(e.to_string()))?,
        None => NoiseLevel {
            sigma_x: 0.0,
            sigma_z: 0.0,
        },
    };
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed.wrapping_add(KEYPHASOR_SEED));
    let running = channels(acq, s, &noisy.x, &noisy.z, &truth, &mut rng);
    let (slow_roll, slow_roll_truth) = if s.slow_roll_rpm > 0.0 {
        let speed = SpeedProfile::constant_rpm(s.slow_roll_rpm, 0.3)?;
        let w = crate::model::rpm_to_rad_per_s(s.slow_roll_rpm);
        let ss = steady_state(&scenario.rotor, w);
        let (q, v) = (ss.displacement(0.0, 0.3), ss.velocity(0.0, 0.3));
        let sc = Scenario {
            rotor: scenario.rotor,
            speed,
            sampling: Sampling::new(scenario.sampling.dt(), s.slow_roll_duration_s)?,
            initial: InitialState {
                x: q[0],
                z: q[1],
                vx: v[0],
                vz: v[1],
            },
        };
        let tr = sim(&sc)?;
        let mut nrng = ChaCha8Rng::seed_from_u64(s.seed.wrapping_add(0x5eed_0002));
        let xs: Vec<f64> =
            tr.x.iter()
                .map(|&x| x + noise.sigma_x * nrng.sample::<f64, _>(StandardNormal))
                .collect();
        let zs: Vec<f64> =
            tr.z.iter()
                .map(|&z| z + noise.sigma_z * nrng.sample::<f64, _>(StandardNormal))
                .collect();
        let rec = channels(acq, s, &xs, &zs, &tr, &mut rng);
        (Some(rec), Some(tr))
    } else {
        (None, None)
    };
    Ok(RawSimulation {
        running,
        truth,
        noisy,
        noise,
        slow_roll,
        slow_roll_truth,
    })
}
