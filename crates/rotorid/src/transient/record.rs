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
use super::order::{track_signals, OrderSettings, Tracked};
use crate::acquisition::{
    channels, keyphasor_times, shaft_angle, time_of, Acquisition, KeyphasorReport, Probe,
    RawRecord, ShaftAngle, Which,
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
    let ShaftAngle {
        phi: mut psi,
        omega,
        report,
        ..
    } = shaft_angle(&t, kp, &acq.keyphasor, which)?;
    // psi in place of phi, w' dropped: a record's column less of each held
    for p in &mut psi {
        *p -= acq.keyphasor.angle;
    }
    // events timed between samples scatter the phase of single revolutions (super::angle)
    let psi = super::angle::smooth(&t, &psi);
    let displacement: Vec<Vec<f64>> = probes
        .iter()
        .map(|&k| {
            let s = acq.probes[k].sensitivity;
            v[k].iter().map(|x| x / s).collect()
        })
        .collect();
    let signals: Vec<&[f64]> = displacement.iter().map(Vec::as_slice).collect();
    // the probes tracked together: one set of normal equations per revolution for both
    let tracked = track_signals(&t, &psi, &signals, settings)?;
    drop(psi);
    let out = probes
        .iter()
        .zip(tracked)
        .map(|(&k, tracked)| ProbeTrack {
            probe: acq.probes[k].clone(),
            tracked,
        })
        .collect();
    Ok(RecordTrack {
        keyphasor: report,
        probes: out,
        t,
        omega,
        displacement,
    })
}
