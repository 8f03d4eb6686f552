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
    channels, check_time, keyphasor_times, shaft_angle, time_of, Acquisition, KeyphasorReport,
    Probe, RawRecord, ShaftAngle, TimeBase, Which,
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
    let angle = shaft_angle(&t, kp, &acq.keyphasor, which)?;
    let displacement: Vec<Vec<f64>> = probes
        .iter()
        .map(|&k| {
            let s = acq.probes[k].sensitivity;
            v[k].iter().map(|x| x / s).collect()
        })
        .collect();
    track_angle(t, angle, displacement, acq, probes, settings)
}

/// [`track_record`] of a record the caller gives away: the same checks in the same order
/// and the same results, but the record's columns are moved out of it instead of copied
/// (the time stamps, the keyphasor dropped as soon as the shaft angle is known, and each
/// probe's volts divided by its sensitivity in place), so that the record is not held
/// beside what is computed from it.
pub fn track_record_owned(
    mut raw: RawRecord,
    acq: &Acquisition,
    probes: &[usize],
    settings: &OrderSettings,
    which: Which,
) -> Result<RecordTrack, TransientError> {
    settings.validate()?;
    let n = check_time(&raw, acq, which)?;
    let probe_columns: Vec<&str> = probes
        .iter()
        .map(|&k| acq.probes[k].column.as_str())
        .collect();
    let mut later: Vec<&str> = probe_columns.clone();
    later.push(acq.keyphasor.column.as_str());
    let stamps = match &acq.time {
        TimeBase::RateHz(r) => (0..n).map(|i| i as f64 / r).collect(),
        TimeBase::Column(c) => take(&mut raw, c, &later),
    };
    // the probes and the keyphasor checked against the stamps, as `channels` does
    channels(&raw, acq, &stamps, which)?;
    let (t, _) = keyphasor_times(stamps);
    let kp = take(&mut raw, &acq.keyphasor.column, &probe_columns);
    let angle = shaft_angle(&t, &kp, &acq.keyphasor, which)?;
    drop(kp);
    let mut displacement = Vec::with_capacity(probes.len());
    for (j, &k) in probes.iter().enumerate() {
        let s = acq.probes[k].sensitivity;
        let mut d = take(&mut raw, probe_columns[j], &probe_columns[j + 1..]);
        for x in &mut d {
            *x /= s;
        }
        displacement.push(d);
    }
    drop(raw);
    track_angle(t, angle, displacement, acq, probes, settings)
}

/// The column `name` of `raw` moved out of it, or copied when one of `needed` (columns
/// still to be taken) is the same column.
fn take(raw: &mut RawRecord, name: &str, needed: &[&str]) -> Vec<f64> {
    let Some((_, v)) = raw.columns.iter_mut().find(|(n, _)| n == name) else {
        return Vec::new();
    };
    if needed.contains(&name) {
        v.clone()
    } else {
        std::mem::take(v)
    }
}

/// The tracking of a record once its times `t`, shaft angle and displacements are known.
fn track_angle(
    t: Vec<f64>,
    angle: ShaftAngle,
    displacement: Vec<Vec<f64>>,
    acq: &Acquisition,
    probes: &[usize],
    settings: &OrderSettings,
) -> Result<RecordTrack, TransientError> {
    let ShaftAngle {
        phi: mut psi,
        omega,
        report,
        ..
    } = angle;
    // psi in place of phi, w' dropped: a record's column less of each held
    for p in &mut psi {
        *p -= acq.keyphasor.angle;
    }
    // events timed between samples scatter the phase of single revolutions (super::angle)
    super::angle::smooth_in_place(&t, &mut psi);
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
