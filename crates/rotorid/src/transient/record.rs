//! A raw record of a run-up or coast-down (probes in volts and a keyphasor, described by
//! `[acquisition]`) to each probe's order-tracked vectors in m, and the per-sample
//! quantities the spectra need (docs/transient.md section 2).
//!
//! The keyphasor gives the shaft angle phi and speed per sample exactly as for the
//! identification (`acquisition::shaft_angle`, docs/acquisition.md section 3); the
//! revolutions are counted from the keyphasor event, `psi = phi - phi_kp`, so that a
//! phase lag is measured from the event whatever `[acquisition.keyphasor] angle_deg`
//! says. Each probe's displacement towards it is its voltage over its sensitivity, in m
//! (its DC, the gap, included: the fit's constant takes it).

use serde::Serialize;

use super::error::TransientError;
use super::order::{track, OrderSettings, Tracked};
use crate::acquisition::{
    channels, keyphasor_times, shaft_angle, time_of, Acquisition, KeyphasorReport, Probe,
    RawRecord, Which,
};

/// One probe's vectors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeTrack {
    /// The probe (column, angle, sensitivity).
    pub probe: Probe,
    /// Its displacement's vectors \[m\] per revolution.
    pub tracked: Tracked,
}

/// A record order-tracked.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordTrack {
    /// What the keyphasor conditioning found.
    pub keyphasor: KeyphasorReport,
    /// Each probe's vectors, in the order of `[acquisition]`.
    pub probes: Vec<ProbeTrack>,
    /// Time per sample \[s\].
    pub t: Vec<f64>,
    /// Shaft speed per sample \[rad/s\].
    pub omega: Vec<f64>,
    /// Each probe's displacement towards it per sample \[m\], DC included.
    pub displacement: Vec<Vec<f64>>,
}

/// Order-track the probes of `raw` (`probes`: which of `acq`'s two, by index; one or
/// both) per revolution (module doc). `which` names the record in errors.
pub fn track_record(
    raw: &RawRecord,
    acq: &Acquisition,
    probes: &[usize],
    settings: &OrderSettings,
    which: Which,
) -> Result<RecordTrack, TransientError> {
    settings.validate()?;
    let stamps = time_of(raw, acq, which)?;
    let (v, kp) = channels(raw, acq, &stamps, which)?;
    let (t, _) = keyphasor_times(stamps);
    let sa = shaft_angle(&t, kp, &acq.keyphasor, which)?;
    let psi: Vec<f64> = sa.phi.iter().map(|p| p - acq.keyphasor.angle).collect();
    // events timed between samples scatter the phase of single revolutions (super::angle)
    let psi = super::angle::smooth(&t, &psi);
    let mut out = Vec::with_capacity(probes.len());
    let mut displacement = Vec::with_capacity(probes.len());
    for &k in probes {
        let p = &acq.probes[k];
        let d: Vec<f64> = v[k].iter().map(|x| x / p.sensitivity).collect();
        let tracked = track(&t, &psi, &d, settings)?;
        out.push(ProbeTrack {
            probe: p.clone(),
            tracked,
        });
        displacement.push(d);
    }
    Ok(RecordTrack {
        keyphasor: sa.report,
        probes: out,
        t,
        omega: sa.omega,
        displacement,
    })
}
