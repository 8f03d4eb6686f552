//! The starting point of the refinement: the output-error fit converges to the global
//! optimum from a start within a few per cent (`rotorid::refine`, module doc), which the
//! identifiers that need no start provide. In order of preference:
//!
//! 1. the modulating-function estimate over the whole record (noise-robust; method.md
//!    section 6), with m = (m_x + m_z) / 2 (or the one well-conditioned direction's m);
//! 2. the algebraic identifier's estimate (method.md section 5) at the last
//!    well-conditioned instant up to [`ALGEBRAIC_START_S`] after the first sample: early,
//!    before the plain estimate drifts under noise (method.md section 6: good to ~0.1-1 %
//!    at 0.05-0.1 s and SNR 40 dB); used when the record is shorter than one modulating
//!    window or that estimate is unusable;
//! 3. the scenario's m, cx, kx, cz, kz (nominal values), when neither identifier gives a
//!    physical estimate (no excitation, say): the fit then reports what the record can
//!    and cannot determine.
//!
//! An estimate is usable when every unknown among m, cx, kx, cz, kz comes from a
//! well-conditioned direction and is finite, with m, kx, kz > 0 (a negative damping is
//! raised to 0 by the fit itself). Quantities not estimated, and a and the unbalance
//! (whose starting values they are when estimated), come from the scenario.

use rotorid::identify::algebraic::{AlgebraicConfig, AlgebraicIdentifier, SpeedModel};
use rotorid::identify::modulating::ModulatingEstimate;
use rotorid::identify::Measurement;
use rotorid::refine::Unknowns;
use rotorid::{RotorParams, SpeedProfile, Unbalance};

use super::record::RecordData;
use super::{modulating, Context};

/// How long after the first sample [s] the algebraic start may be taken.
pub(crate) const ALGEBRAIC_START_S: f64 = 0.05;

/// Where the start came from.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Source {
    /// The modulating estimate (end of its last window at `t` [s], input time).
    Modulating {
        t: f64,
        estimate: ModulatingEstimate,
    },
    /// The algebraic estimate at `t` [s] (input time).
    Algebraic { t: f64 },
    /// The scenario's values.
    Scenario,
}

impl Source {
    /// `modulating`, `algebraic` or `scenario`.
    pub fn name(&self) -> &'static str {
        match self {
            Source::Modulating { .. } => "modulating",
            Source::Algebraic { .. } => "algebraic",
            Source::Scenario => "scenario",
        }
    }

    /// The instant of the estimate [s], if any.
    pub fn t(&self) -> Option<f64> {
        match self {
            Source::Modulating { t, .. } | Source::Algebraic { t } => Some(*t),
            Source::Scenario => None,
        }
    }
}

/// The starting point and its provenance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Start {
    pub source: Source,
    /// Every rotor parameter: the start of the unknowns, the value of the known.
    pub params: RotorParams,
    /// Why earlier sources were not used.
    pub note: Option<String>,
}

/// The scenario's values of m, cx, kx, cz, kz (`None` where it does not state them) and
/// its a [N s^2/m] and unbalance.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ScenarioValues {
    pub mck: [Option<f64>; 5],
    pub a: f64,
    pub unbalance: Unbalance,
}

/// The names of m, cx, kx, cz, kz in [`ScenarioValues::mck`] order.
pub(crate) const MCK: [&str; 5] = ["m", "cx", "kx", "cz", "kz"];

/// Which of m, cx, kx, cz, kz are unknown.
pub(crate) fn unknown_mck(u: &Unknowns) -> [bool; 5] {
    [u.m, u.cx, u.kx, u.cz, u.kz]
}

/// (m, c, k) of one direction, when it is well conditioned.
type Direction = Option<[f64; 3]>;

/// Find the start (module doc). Errors only when no source is usable.
pub(crate) fn find(
    ctx: &Context,
    rec: &RecordData,
    profile: Option<SpeedProfile>,
    unknowns: &Unknowns,
    sc: &ScenarioValues,
) -> anyhow::Result<Start> {
    let dt = rec.dt.expect("the caller checked the record has two rows");
    let mut notes = Vec::new();
    match modulating_start(ctx, rec, profile, dt) {
        Ok((est, dirs)) => match compose(dirs, unknowns, sc) {
            Ok(params) => {
                return Ok(Start {
                    source: Source::Modulating {
                        t: est.t,
                        estimate: est,
                    },
                    params,
                    note: None,
                });
            }
            Err(why) => notes.push(format!("modulating estimate unusable: {why}")),
        },
        Err(why) => notes.push(format!("no modulating estimate: {why}")),
    }
    match algebraic_start(ctx, rec, profile, dt) {
        Ok((t, dirs)) => match compose(dirs, unknowns, sc) {
            Ok(params) => {
                return Ok(Start {
                    source: Source::Algebraic { t },
                    params,
                    note: Some(notes.join("; ")),
                })
            }
            Err(why) => notes.push(format!("algebraic estimate unusable: {why}")),
        },
        Err(why) => notes.push(format!("no algebraic estimate: {why}")),
    }
    let unknown = unknown_mck(unknowns);
    let missing: Vec<&str> = (0..5)
        .filter(|&i| unknown[i] && sc.mck[i].is_none())
        .map(|i| MCK[i])
        .collect();
    if !missing.is_empty() {
        anyhow::bail!(
            "refine has no starting point: {}; the scenario {} does not state rotor.{} to \
             start from. The record may not excite the rotor at all; give nominal values in \
             the scenario to let the fit say what the record can determine",
            notes.join("; "),
            ctx.spec.origin(),
            missing.join(", rotor.")
        );
    }
    let params = compose_from(|i| sc.mck[i].expect("checked above"), sc);
    Ok(Start {
        source: Source::Scenario,
        params,
        note: Some(notes.join("; ")),
    })
}

/// The nominal time of sample `i`: t_1 + i dt [s] (the identifiers' grid).
fn nominal(rec: &RecordData, i: usize, dt: f64) -> f64 {
    rec.t[0] + i as f64 * dt
}

/// Rotor parameters with m, cx, kx, cz, kz from `mck(i)` and a, unbalance from `sc`.
fn compose_from(mck: impl Fn(usize) -> f64, sc: &ScenarioValues) -> RotorParams {
    RotorParams {
        m: mck(0),
        cx: mck(1),
        kx: mck(2),
        cz: mck(3),
        kz: mck(4),
        a: sc.a,
        unbalance: sc.unbalance,
    }
}

/// The start from per-direction estimates: unknowns from the estimate, the rest from the
/// scenario; `Err` says why it is not usable.
fn compose(dirs: [Direction; 2], u: &Unknowns, sc: &ScenarioValues) -> Result<RotorParams, String> {
    let unknown = unknown_mck(u);
    let masses: Vec<f64> = dirs.iter().flatten().map(|d| d[0]).collect();
    let est: [Option<f64>; 5] = [
        (!masses.is_empty()).then(|| masses.iter().sum::<f64>() / masses.len() as f64),
        dirs[0].map(|d| d[1]),
        dirs[0].map(|d| d[2]),
        dirs[1].map(|d| d[1]),
        dirs[1].map(|d| d[2]),
    ];
    let mut v = [0.0; 5];
    for i in 0..5 {
        v[i] = if unknown[i] {
            let Some(e) = est[i] else {
                let why = match i {
                    0 => "neither direction is well conditioned",
                    1 | 2 => "the x direction is not well conditioned",
                    _ => "the z direction is not well conditioned",
                };
                return Err(format!("{why} (no {})", MCK[i]));
            };
            let physical = e.is_finite() && (matches!(i, 1 | 3) || e > 0.0);
            if !physical {
                return Err(format!("{} = {e:.4e} is unphysical", MCK[i]));
            }
            e
        } else {
            sc.mck[i].expect("known quantities were checked to be in the scenario")
        };
    }
    Ok(compose_from(|i| v[i], sc))
}

/// The modulating estimate over the whole record and its well-conditioned directions.
fn modulating_start(
    ctx: &Context,
    rec: &RecordData,
    profile: Option<SpeedProfile>,
    dt: f64,
) -> Result<(ModulatingEstimate, [Direction; 2]), String> {
    let cfg = modulating::config(ctx);
    let mut id =
        rotorid::identify::modulating::ModulatingIdentifier::new(ctx.view.known(), dt, cfg)
            .map_err(|e| e.to_string())?;
    for i in 0..rec.len() {
        id.push(&measurement(rec, i, profile, dt))
            .map_err(|e| e.to_string())?;
    }
    let est = modulating::finish(&id, dt).map_err(|e| e.to_string())?;
    let ok = est.well_conditioned(cfg.rcond_min);
    let dirs = [
        ok[0].then_some(est.x.theta()),
        ok[1].then_some(est.z.theta()),
    ];
    Ok((est, dirs))
}

/// The algebraic estimate of each direction at its last well-conditioned instant up to
/// [`ALGEBRAIC_START_S`] after the first sample, and the later of the two instants.
fn algebraic_start(
    ctx: &Context,
    rec: &RecordData,
    profile: Option<SpeedProfile>,
    dt: f64,
) -> Result<(f64, [Direction; 2]), String> {
    let set = &ctx.settings;
    let config = AlgebraicConfig::new(set.quadrature, set.rcond_min_algebraic, SpeedModel::General)
        .map_err(|e| e.to_string())?;
    let mut id =
        AlgebraicIdentifier::new(ctx.view.known(), dt, config).map_err(|e| e.to_string())?;
    let mut best: [Option<(f64, [f64; 3])>; 2] = [None, None];
    for i in 0..rec.len() {
        if rec.t[i] - rec.t[0] > ALGEBRAIC_START_S {
            break;
        }
        let e = id
            .push(&measurement(rec, i, profile, dt))
            .map_err(|e| e.to_string())?;
        let ok = e.well_conditioned(set.rcond_min_algebraic);
        for (d, dir) in [e.x, e.z].iter().enumerate() {
            if ok[d] {
                best[d] = Some((rec.t[i], dir.theta()));
            }
        }
    }
    let t = best.iter().flatten().map(|b| b.0).fold(f64::NAN, f64::max);
    if t.is_nan() {
        return Err(format!(
            "never well conditioned in the first {ALGEBRAIC_START_S} s"
        ));
    }
    Ok((t, best.map(|b| b.map(|(_, th)| th))))
}

/// Sample `i` as the identifiers' measurement, on the nominal grid.
fn measurement(rec: &RecordData, i: usize, profile: Option<SpeedProfile>, dt: f64) -> Measurement {
    Measurement {
        t: nominal(rec, i, dt),
        x: rec.x[i],
        z: rec.z[i],
        speed: rec.speed_at(i, profile),
    }
}
