//! Test problems paired with their reference solutions, shared by the tests, the benches
//! and the Monte Carlo example (feature `test-models`; after diffsol's `test_models`).
//!
//! Each [`TestModel`] is a scenario simulated exactly (matrix exponential at constant
//! speed, DoPri8 on ramps; docs/method.md section 2), optionally with white noise at an
//! SNR, together with what any identification of it must be judged against: the true
//! rotor, the knowledge a caller has, and the Cramer-Rao bound of the experiment.

use crate::model::{CrossCoupling, Rotor, RotorParams, Scenario};
use crate::pipeline::{Knowledge, Record};
use crate::refine::{crb_at_snr, Crb, Unknowns};
use crate::simulate::{add_noise, simulate, Method, TimeResponse};

/// A simulated record with its reference (module doc).
#[derive(Debug, Clone)]
pub struct TestModel {
    /// A short name for messages: `table1`, `table1_ramp600`, with `@40dB/seed` when noisy.
    pub name: String,
    /// The scenario simulated.
    pub scenario: Scenario,
    /// The response (noisy when `snr_db` is set).
    pub response: TimeResponse,
    /// The noise-free response.
    pub clean: TimeResponse,
    /// The signal-to-noise ratio of the noise added \[dB\], if any.
    pub snr_db: Option<f64>,
}

impl TestModel {
    /// `scenario` simulated exactly, noise-free.
    pub fn clean(name: &str, scenario: Scenario) -> Self {
        let clean = simulate(&scenario, Method::Exact).expect("test scenarios simulate");
        Self {
            name: name.to_owned(),
            scenario,
            response: clean.clone(),
            clean,
            snr_db: None,
        }
    }

    /// The same record with white noise at `snr_db` from `seed` (deterministic).
    pub fn with_noise(&self, snr_db: f64, seed: u64) -> Self {
        let mut response = self.clean.clone();
        add_noise(&mut response, snr_db, seed).expect("a finite SNR");
        Self {
            name: format!("{}@{snr_db}dB/{seed}", self.name),
            response,
            snr_db: Some(snr_db),
            ..self.clone()
        }
    }

    /// The true rotor.
    pub fn truth(&self) -> RotorParams {
        self.scenario.rotor.params()
    }

    /// What a caller knows: the scenario as nominal values and truth.
    pub fn knowledge(&self) -> Knowledge {
        Knowledge::from_scenario(&self.scenario)
    }

    /// The response as the pipeline's record (per-sample speed columns).
    pub fn record(&self) -> Record {
        Record::from_response(&self.response).expect("simulated records are valid")
    }

    /// The Cramer-Rao bound of this experiment for `unknowns` at its SNR (`None`
    /// noise-free).
    pub fn crb(&self, unknowns: &Unknowns) -> Option<Crb> {
        let snr = self.snr_db?;
        crb_at_snr(&self.scenario, snr, unknowns).ok()
    }
}

/// The paper's rotor (Table 1) at 1200 rpm, 1 s at 10 kHz, from rest, noise-free.
pub fn table1() -> TestModel {
    TestModel::clean("table1", Scenario::table1())
}

/// The paper's rotor on the 10 rad/s^2 run-up from `rpm0`, 1 s at 10 kHz, noise-free.
pub fn table1_ramp(rpm0: f64) -> TestModel {
    let s = Scenario::table1_ramp(rpm0).expect("a valid ramp");
    TestModel::clean(&format!("table1_ramp{rpm0}"), s)
}

/// A rotor on cross-coupled bearings (docs/method.md section 1.6): table1's m, a and
/// unbalance on stiffer, anisotropic, well damped bearings (kxx = 1.195e6, kzz = 1.4e6 N/m,
/// cxx = czz = 200 N s/m: damping ratio 2.4 %) with a destabilising cross-coupled
/// stiffness kxz = -kzx = -3e4 N/m (2.5 % of kxx; it drives forward whirl and halves its
/// damping, the threshold being about 5.8e4 N/m) and cross damping cxz = czx = 20 N s/m.
pub fn cross_coupled_rotor() -> RotorParams {
    RotorParams {
        kz: 1.4e6,
        cx: 200.0,
        cz: 200.0,
        coupling: Some(CrossCoupling {
            cxz: 20.0,
            czx: 20.0,
            kxz: -3.0e4,
            kzx: 3.0e4,
        }),
        ..Rotor::table1().params()
    }
}

/// [`cross_coupled_rotor`] at 1200 rpm, 1 s at 10 kHz, from rest, noise-free.
pub fn cross_coupled() -> TestModel {
    let s = Scenario {
        rotor: Rotor::new(cross_coupled_rotor()).expect("a valid rotor"),
        ..Scenario::table1()
    };
    TestModel::clean("cross_coupled", s)
}

/// [`cross_coupled_rotor`] on the 10 rad/s^2 run-up from `rpm0`, 1 s at 10 kHz, from rest,
/// noise-free.
pub fn cross_coupled_ramp(rpm0: f64) -> TestModel {
    let s = Scenario {
        rotor: Rotor::new(cross_coupled_rotor()).expect("a valid rotor"),
        ..Scenario::table1_ramp(rpm0).expect("a valid ramp")
    };
    TestModel::clean(&format!("cross_coupled_ramp{rpm0}"), s)
}

/// `p` with m, cz, kz 1 % high and cx, kx 1 % low: a start inside the refinement's basin,
/// as close as the identifiers' estimates get under noise.
pub fn perturbed_start(p: &RotorParams) -> RotorParams {
    RotorParams {
        m: p.m * 1.01,
        cx: p.cx * 0.99,
        kx: p.kx * 0.99,
        cz: p.cz * 1.01,
        kz: p.kz * 1.01,
        ..*p
    }
}
