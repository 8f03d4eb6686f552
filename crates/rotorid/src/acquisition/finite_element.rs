//! Raw acquisitions of a finite-element rotor (docs/acquisition.md section 11):
//! two proximity probes at each measured node (`[[acquisition.probe]] node = N`) and one
//! keyphasor, to the response at the measured nodes' `x`, `y`, and back.
//!
//! **Frame.** The finite-element frame is x, y with the shaft turning from +x towards +y
//! (docs/finite_element.md). A probe's `angle_deg` in a finite-element scenario is the
//! direction from the shaft centre to the probe **from +x towards +y** (ROSS's probe
//! orientation), and it reads `d = x cos theta + y sin theta`. This is the 2-DOF probe
//! equation `d = x cos theta + z sin theta` (angles from +x towards +z) with y in the
//! place of z, so each node's pair is conditioned by the 2-DOF conditioning itself
//! ([`super::condition`], no copy of it) with the angles as given, and its `x`, `z`
//! outputs are the node's `x`, `y`. The same physical probe in the 2-DOF frame of a
//! one-node rotor (x = x, y = -z, docs/finite_element.md section 2) has the angle
//! theta_2DOF = -theta_FE.
//!
//! **Conditioning** ([`condition_fe_raw`]): per node, [`super::condition`] on the node's
//! two probes, the record's keyphasor and time, and the slow-roll record when given,
//! without a rotor guess (the guess of the 2-DOF conditioning is a 2-DOF rotor): the DC of
//! each probe is its mean over whole revolutions, so the conditioned displacements are the
//! motion less its mean over those revolutions (the mean of a free transient stays in the
//! DC; docs/acquisition.md section 6). phi, phi', phi'' come from the keyphasor, the same
//! for every node.
//!
//! **Simulation** ([`simulate_fe_raw`]): the response at the measured nodes' x, y
//! ([`crate::simulate::finite_element::simulate_fe`]), white noise at the SNR on each of
//! those columns ([`crate::simulate::add_noise_to`], in node order, x then y), and the
//! probes' volts and the keyphasor by the same functions as the 2-DOF raw simulation
//! ([`super::raw`]).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::error::AcquisitionError;
use super::raw::{keyphasor_volts, probe_volts, Adc, KEYPHASOR_SEED};
use super::{condition, Acquisition, ConditionReport, RawRecord, TimeBase};
use crate::model::finite_element::{Dof, DofKind, FeSystem};
use crate::model::{Sampling, SpeedProfile};
use crate::simulate::finite_element::{simulate_fe, FeMethod, FeResponse};

/// The two probes of one measured node.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeNodeProbes {
    /// The node (its `x` and `y` are measured).
    pub node: u32,
    /// The acquisition of this node's pair: the record's time base, keyphasor, runout
    /// settings and raw-simulation settings, with the node's two probes (in the order of
    /// `[[acquisition.probe]]`; angles from +x towards +y) and their gaps and runouts in
    /// `simulate.gap_v`, `simulate.runout`.
    pub acquisition: Acquisition,
}

/// The `[acquisition]` of a finite-element scenario: the probe pairs by node, in the
/// order their nodes first appear in `[[acquisition.probe]]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeAcquisition {
    /// One entry per measured node, at least one.
    pub nodes: Vec<FeNodeProbes>,
}

impl FeAcquisition {
    /// The measured degrees of freedom: `<node>.x`, `<node>.y` per node, in order.
    pub fn dofs(&self) -> Vec<Dof> {
        self.nodes
            .iter()
            .flat_map(|n| [Dof::new(n.node, DofKind::X), Dof::new(n.node, DofKind::Y)])
            .collect()
    }

    /// The settings shared by every node (time, keyphasor, runout, simulation): the first
    /// node's acquisition.
    pub fn common(&self) -> Result<&Acquisition, AcquisitionError> {
        self.nodes.first().map(|n| &n.acquisition).ok_or_else(|| {
            AcquisitionError::Simulate("no probes: [[acquisition.probe]] names no node".into())
        })
    }
}

/// A conditioned raw record of a finite-element rotor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeConditioned {
    /// t, the measured nodes' x and y \[m\] (columns `<node>.x`, `<node>.y`), phi, phi',
    /// phi''.
    pub response: FeResponse,
    /// The conditioning report of each node's pair, in the order of `response`'s nodes
    /// (its `x`, `z` are the node's x, y).
    pub reports: Vec<(u32, ConditionReport)>,
}

/// Condition the raw record `raw` of a finite-element rotor (module doc): each node's
/// pair by [`super::condition`] without a rotor guess, with the slow-roll record `slow`
/// when given; the response at `<node>.x`, `<node>.y` of every node of `acq`.
pub fn condition_fe_raw(
    raw: &RawRecord,
    acq: &FeAcquisition,
    slow: Option<&RawRecord>,
) -> Result<FeConditioned, AcquisitionError> {
    acq.common()?;
    let mut response = FeResponse {
        dofs: acq.dofs(),
        ..FeResponse::default()
    };
    let mut reports = Vec::with_capacity(acq.nodes.len());
    for (k, n) in acq.nodes.iter().enumerate() {
        let c = condition(raw, &n.acquisition, slow, None)?;
        if k == 0 {
            response.t = c.t;
            response.phi = c.phi;
            response.phi_dot = c.phi_dot;
            response.phi_ddot = c.phi_ddot;
        }
        response.q.push(c.x);
        response.q.push(c.z);
        reports.push((n.node, c.report));
    }
    Ok(FeConditioned { response, reports })
}

/// A simulated raw acquisition of a finite-element rotor, with its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct FeRawSimulation {
    /// The record: the time column (when the time base is a column), every probe's volts
    /// (in node order, each node's two probes in their order), the keyphasor.
    pub running: RawRecord,
    /// The exact response at the measured degrees of freedom.
    pub truth: FeResponse,
    /// The same with the white noise the probes carry.
    pub noisy: FeResponse,
    /// The noise's standard deviation on each measured degree of freedom \[m\].
    pub sigma: Vec<f64>,
}

/// Simulate the raw acquisition `acq` of the finite-element `system` over `sampling` at
/// `speed` with `method`, from rest (module doc). Every node's `[acquisition.simulate]`
/// shares the first's SNR, seed, ADC and keyphasor settings; the gaps and runouts are
/// per probe. With the time base a rate, it must be 1 / dt. The slow-roll record is not
/// simulated for a finite-element rotor (an error when `slow_roll_rpm` > 0 is asked for
/// by the caller).
pub fn simulate_fe_raw(
    system: &FeSystem,
    speed: &SpeedProfile,
    sampling: &Sampling,
    acq: &FeAcquisition,
    method: FeMethod,
) -> Result<FeRawSimulation, AcquisitionError> {
    let common = acq.common()?;
    for n in &acq.nodes {
        n.acquisition.validate()?;
        n.acquisition.simulate.validate()?;
    }
    let s = &common.simulate;
    if let TimeBase::RateHz(r) = common.time {
        let dt = sampling.dt();
        if ((r * dt) - 1.0).abs() > 1e-9 {
            return Err(AcquisitionError::Simulate(format!(
                "acquisition.rate_hz = {r} Hz does not match the scenario's sampling.dt = {dt} s (1 / dt = {} Hz)",
                1.0 / dt
            )));
        }
    }
    let dofs = acq.dofs();
    let truth = simulate_fe(system, speed, sampling, None, Some(&dofs), method)
        .map_err(|e| AcquisitionError::Simulate(e.to_string()))?;
    let mut noisy = truth.clone();
    let sigma = match s.snr_db {
        Some(snr) => {
            let mut cols: Vec<(&'static str, &mut [f64])> = noisy
                .q
                .iter_mut()
                .map(|c| ("finite-element response", &mut c[..]))
                .collect();
            crate::simulate::add_noise_to(&mut cols, snr, s.seed)
                .map_err(|e| AcquisitionError::Simulate(e.to_string()))?
        }
        None => vec![0.0; dofs.len()],
    };
    let adc = Adc::new(s);
    let mut columns = Vec::with_capacity(2 * acq.nodes.len() + 2);
    if let TimeBase::Column(c) = &common.time {
        columns.push((c.clone(), truth.t.clone()));
    }
    for (k, n) in acq.nodes.iter().enumerate() {
        let (x, y) = (&noisy.q[2 * k], &noisy.q[2 * k + 1]);
        let ns = &n.acquisition.simulate;
        for (j, p) in n.acquisition.probes.iter().enumerate() {
            let v = probe_volts(
                p,
                ns.gap_v[j],
                &ns.runout[j],
                adc.as_ref(),
                x,
                y,
                &truth.phi,
            );
            columns.push((p.column.clone(), v));
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed.wrapping_add(KEYPHASOR_SEED));
    let kp = keyphasor_volts(
        common,
        s,
        adc.as_ref(),
        &truth.phi,
        &truth.phi_dot,
        &mut rng,
    );
    columns.push((common.keyphasor.column.clone(), kp));
    Ok(FeRawSimulation {
        running: RawRecord { columns },
        truth,
        noisy,
        sigma,
    })
}
