//! Raw acquisitions (probes in volts, keyphasor, slow roll) conditioned back to x, z, phi
//! and checked against the simulator's exact truth (docs/acquisition.md).

use std::f64::consts::PI;

use rotorid::acquisition::{
    condition, simulate_raw, Acquisition, AcquisitionError, AcquisitionFinding, GuessSource,
    ModelGuess, RawRecord, RawSimulation,
};
use rotorid::model::{InitialState, Rotor, Sampling, Scenario, SpeedProfile};

/// Table 1 with 40 times its unbalance (x, z ~ 10-20 um at 1200 rpm), 25.6 kHz, `duration`.
fn scenario(ramp: bool, duration: f64) -> Scenario {
    let mut p = Rotor::table1().params();
    p.unbalance.m_u = 4.0e-3;
    Scenario {
        rotor: Rotor::new(p).unwrap(),
        speed: if ramp {
            SpeedProfile::ramp(1200.0, 10.0, 0.0).unwrap()
        } else {
            SpeedProfile::constant_rpm(1200.0, 0.0).unwrap()
        },
        sampling: Sampling::new(1.0 / 25600.0, duration).unwrap(),
        initial: InitialState::default(),
    }
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    (s / n as f64).sqrt()
}

/// RMS of phi - truth after removing the whole turns between them.
fn phi_error(phi: &[f64], truth: &[f64]) -> f64 {
    let turns = ((phi[0] - truth[0]) / (2.0 * PI)).round() * 2.0 * PI;
    rms(phi.iter().zip(truth).map(|(a, b)| a - b - turns))
}

fn guess(s: &Scenario) -> ModelGuess {
    ModelGuess {
        rotor: s.rotor.params(),
        initial: None,
        source: GuessSource::Scenario,
    }
}

#[test]
fn conditioned_record_matches_the_truth_constant_and_ramp() {
    for ramp in [false, true] {
        let s = scenario(ramp, 1.0);
        let acq = Acquisition::example();
        let raw: RawSimulation = simulate_raw(&s, &acq).unwrap();
        let c = condition(&raw.running, &acq, raw.slow_roll.as_ref(), Some(&guess(&s))).unwrap();
        let tr = &raw.truth;
        let ephi = phi_error(&c.phi, &tr.phi);
        let ex = rms(c.x.iter().zip(&tr.x).map(|(a, b)| a - b)) / raw.noise.sigma_x;
        let ez = rms(c.z.iter().zip(&tr.z).map(|(a, b)| a - b)) / raw.noise.sigma_z;
        let ew = rms(c.phi_dot.iter().zip(&tr.phi_dot).map(|(a, b)| a - b));
        let ewd = rms(c.phi_ddot.iter().zip(&tr.phi_ddot).map(|(a, b)| a - b));
        let xamp = tr.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        eprintln!(
            "ramp {ramp}: phi rms err {ephi:.3e} rad, omega {ew:.3e} rad/s, omega_dot {ewd:.3e}, x err/noise {ex:.4}, z {ez:.4}, |x| max {xamp:.3e}, jitter {:?}",
            c.report.keyphasor.jitter_s
        );
        eprintln!(
            "{:#?}",
            c.report.model.as_ref().map(|m| (m.offset, m.initial))
        );
        eprintln!("{:?}", c.report.findings);
        assert!(ephi < 1e-3, "{ephi}");
        assert!(ex < 1.05 && ez < 1.05, "{ex} {ez}");
    }
}
