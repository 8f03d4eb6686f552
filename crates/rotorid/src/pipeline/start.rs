//! The refinement's starting point (docs/method.md section 5.2). The output-error fit
//! converges to the global optimum from a start within a few per cent, which the
//! identifiers that need no start provide. In order of preference:
//!
//! 1. the modulating estimate over the whole record (noise-robust), with
//!    m = (m_x + m_z) / 2 (or the one well-conditioned direction's m);
//! 2. the algebraic estimate at the last well-conditioned instant up to
//!    [`ALGEBRAIC_START_S`] after the first sample: early, before it drifts under noise;
//!    used when the record is shorter than one modulating window or that estimate is
//!    unusable;
//! 3. the nominal m, cx, kx, cz, kz, when neither gives a physical estimate (no
//!    excitation, say): the fit then reports what the record can and cannot determine.
//!
//! An estimate is usable when every unknown among m, cx, kx, cz, kz comes from a
//! well-conditioned direction and is finite, with m, kx, kz > 0 (a negative damping is
//! raised to 0 by the fit itself). Known quantities, a and the unbalance come from the
//! [`Knowledge`].
//!
//! The cross-coupled model starts from the cross-coupled modulating estimate over the
//! whole record (`CrossModulatingIdentifier`: per row m and that row's four bearing
//! coefficients) when both rows are well conditioned and the unknowns it gives are
//! physical (m, kxx, kzz > 0, finite, and a rotor the model accepts); else from the
//! Jeffcott start above with its cross-coupled coefficients at their nominal values or,
//! when none is given, 0: the Jeffcott rotor nested in it (the refinement's continuation
//! reaches cross-coupling of several per cent of the direct stiffness from there;
//! docs/method.md section 5.6), the start's note saying why.

use crate::identify::algebraic::AlgebraicIdentifier;
use crate::identify::modulating::{
    CrossModulatingIdentifier, ModulatingEstimate, ModulatingIdentifier,
};
use crate::model::{CrossCoupling, RotorParams};
use crate::parameter::{ModelKind, Parameter};
use crate::refine::Unknowns;

use super::error::PipelineError;
use super::identification::{RotorSummary, Start, StartSource};
use super::knowledge::Knowledge;
use super::method::RefineSettings;
use super::record::Record;

/// How long after the first sample \[s\] the algebraic start may be taken.
pub const ALGEBRAIC_START_S: f64 = 0.05;

/// The names of m, cx, kx, cz, kz in the order of [`mck_unknown`].
const MCK: [&str; 5] = ["m", "cx", "kx", "cz", "kz"];

/// Which of m, cx, kx, cz, kz are unknown.
pub(crate) fn mck_unknown(u: &Unknowns) -> [bool; 5] {
    [u.m, u.cx, u.kx, u.cz, u.kz]
}

/// The nominal m, cx, kx, cz, kz.
fn nominal(k: &Knowledge) -> [Option<f64>; 5] {
    let n = &k.nominal;
    [n.m, n.cx, n.kx, n.cz, n.kz]
}

/// Every quantity the fit leaves known must have a nominal value (in `model`, whose
/// names the message uses).
pub(crate) fn check_known(
    k: &Knowledge,
    u: &Unknowns,
    model: ModelKind,
) -> Result<(), PipelineError> {
    let missing: Vec<&str> = model
        .default_unknowns()
        .iter()
        .filter(|&&p| !u.selects(p) && k.nominal.get(p).is_none())
        .map(|p| p.name())
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(PipelineError::KnownValueMissing {
            missing: missing.join(", "),
        })
    }
}

/// A start and the modulating estimate it may come from.
pub(crate) struct Found {
    pub start: Start,
    pub params: RotorParams,
    pub modulating: Option<ModulatingEstimate>,
}

/// (m, c, k) of one direction, when well conditioned.
type Direction = Option<[f64; 3]>;

/// The start of the fit of `u` in `model` (module doc); an error only when no source is
/// usable.
pub(crate) fn find(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
    u: &Unknowns,
    model: ModelKind,
) -> Result<Found, PipelineError> {
    let mut found = find_jeffcott(rec, k, s, u)?;
    if model == ModelKind::CrossCoupled {
        // the Jeffcott start in the cross-coupled model: the base of the modulating start
        // (known values) and the fallback
        let nested = with_cross(&found.params, k, u);
        match cross_modulating_start(rec, k, s, u, &nested) {
            Ok((t, params)) => {
                found.params = params;
                found.start = start(
                    StartSource::Modulating,
                    Some(t),
                    &params,
                    Some("the cross-coupled modulating estimate".to_owned()),
                );
            }
            Err(why) => {
                found.params = nested;
                found.start.values = RotorSummary::of(&found.params);
                let note = format!(
                    "cross-coupled modulating estimate unusable ({why}): the Jeffcott start \
                     with the cross-coupled coefficients nominal or 0"
                );
                found.start.note = Some(match found.start.note.take() {
                    Some(n) if !n.is_empty() => format!("{n}; {note}"),
                    _ => note,
                });
            }
        }
    }
    Ok(found)
}

/// The cross-coupled modulating estimate over the whole record as the start of the
/// unknowns `u` (the rest as in `base`: known values, a and the unbalance), and the time
/// of the estimate; `Err` says why it is not usable.
fn cross_modulating_start(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
    u: &Unknowns,
    base: &RotorParams,
) -> Result<(f64, RotorParams), String> {
    let cfg = s.modulating.config;
    let mut id = CrossModulatingIdentifier::new(k.identify_known(), rec.grid().dt, cfg)
        .map_err(|e| e.to_string())?;
    for i in 0..rec.len() {
        id.push(&rec.measurement(i)).map_err(|e| e.to_string())?;
    }
    let est = id.finish().map_err(|e| e.to_string())?;
    let ok = est.well_conditioned(cfg.rcond_min);
    if !(ok[0] && ok[1]) {
        return Err(format!(
            "the {} row is not well conditioned",
            if ok[0] { "z" } else { "x" }
        ));
    }
    // x row: m_x, cxx, cxz, kxx, kxz; z row: m_z, czx, czz, kzx, kzz
    let (x, z) = (est.x.values, est.z.values);
    let pick = |q: Parameter, e: f64, current: f64| if u.selects(q) { e } else { current };
    let c = base.cross();
    let p = RotorParams {
        m: pick(Parameter::M, 0.5 * (x[0] + z[0]), base.m),
        cx: pick(Parameter::Cxx, x[1], base.cx),
        kx: pick(Parameter::Kxx, x[3], base.kx),
        cz: pick(Parameter::Czz, z[2], base.cz),
        kz: pick(Parameter::Kzz, z[4], base.kz),
        coupling: Some(CrossCoupling {
            cxz: pick(Parameter::Cxz, x[2], c.cxz),
            czx: pick(Parameter::Czx, z[1], c.czx),
            kxz: pick(Parameter::Kxz, x[4], c.kxz),
            kzx: pick(Parameter::Kzx, z[3], c.kzx),
        }),
        ..*base
    };
    let pc = p.cross();
    let finite = [p.m, p.cx, p.kx, p.cz, p.kz, pc.cxz, pc.czx, pc.kxz, pc.kzx]
        .iter()
        .all(|v| v.is_finite());
    if !finite || p.m <= 0.0 || p.kx <= 0.0 || p.kz <= 0.0 {
        return Err(format!(
            "m = {:.4e}, kxx = {:.4e}, kzz = {:.4e} are not all finite and positive",
            p.m, p.kx, p.kz
        ));
    }
    // negative direct damping or an indefinite damping matrix is left to the fit's own
    // bounds; the start must be a rotor the model accepts
    crate::model::Rotor::new(p).map_err(|e| e.to_string())?;
    Ok((est.t, p))
}

/// `p` in the cross-coupled model: its cross-coupled coefficients at their nominal values
/// where known, else 0.
pub(crate) fn with_cross(p: &RotorParams, k: &Knowledge, u: &Unknowns) -> RotorParams {
    let c = p.cross();
    let nominal = |q: Parameter, default: f64| {
        if u.selects(q) {
            k.nominal.get(q).unwrap_or(default)
        } else {
            k.nominal.get(q).unwrap_or(0.0)
        }
    };
    RotorParams {
        coupling: Some(CrossCoupling {
            cxz: nominal(Parameter::Cxz, c.cxz),
            czx: nominal(Parameter::Czx, c.czx),
            kxz: nominal(Parameter::Kxz, c.kxz),
            kzx: nominal(Parameter::Kzx, c.kzx),
        }),
        ..*p
    }
}

/// The start of m and the direct coefficients (module doc).
fn find_jeffcott(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
    u: &Unknowns,
) -> Result<Found, PipelineError> {
    let mut notes = Vec::new();
    match modulating_start(rec, k, s) {
        Ok((est, dirs)) => match compose(dirs, u, k) {
            Ok(params) => {
                return Ok(Found {
                    start: start(StartSource::Modulating, Some(est.t), &params, None),
                    params,
                    modulating: Some(est),
                })
            }
            Err(why) => notes.push(format!("modulating estimate unusable: {why}")),
        },
        Err(why) => notes.push(format!("no modulating estimate: {why}")),
    }
    match algebraic_start(rec, k, s) {
        Ok((t, dirs)) => match compose(dirs, u, k) {
            Ok(params) => {
                let note = Some(notes.join("; "));
                return Ok(Found {
                    start: start(StartSource::Algebraic, Some(t), &params, note),
                    params,
                    modulating: None,
                });
            }
            Err(why) => notes.push(format!("algebraic estimate unusable: {why}")),
        },
        Err(why) => notes.push(format!("no algebraic estimate: {why}")),
    }
    let (unknown, nom) = (mck_unknown(u), nominal(k));
    let missing: Vec<&str> = (0..5)
        .filter(|&i| unknown[i] && nom[i].is_none())
        .map(|i| MCK[i])
        .collect();
    if !missing.is_empty() {
        return Err(PipelineError::NoStart {
            why: notes.join("; "),
            missing: missing.join(", "),
        });
    }
    let params = with_mck(nom.map(|v| v.unwrap_or_default()), k);
    Ok(Found {
        start: start(StartSource::Nominal, None, &params, Some(notes.join("; "))),
        params,
        modulating: None,
    })
}

/// The reported start.
pub(crate) fn start(
    source: StartSource,
    t_s: Option<f64>,
    p: &RotorParams,
    note: Option<String>,
) -> Start {
    Start {
        source,
        t_s,
        values: RotorSummary::of(p),
        note,
    }
}

/// Rotor parameters with m, cx, kx, cz, kz from `mck` and a, unbalance from `k`.
fn with_mck(mck: [f64; 5], k: &Knowledge) -> RotorParams {
    RotorParams {
        coupling: None,
        m: mck[0],
        cx: mck[1],
        kx: mck[2],
        cz: mck[3],
        kz: mck[4],
        a: k.a,
        unbalance: k.unbalance,
    }
}

/// The start from per-direction estimates: unknowns from the estimate, the rest nominal;
/// `Err` says why it is not usable.
fn compose(dirs: [Direction; 2], u: &Unknowns, k: &Knowledge) -> Result<RotorParams, String> {
    let (unknown, nom) = (mck_unknown(u), nominal(k));
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
            // check_known ran before: every known value is there
            nom[i].unwrap_or_default()
        };
    }
    Ok(with_mck(v, k))
}

/// The modulating estimate over the whole record and its well-conditioned directions.
fn modulating_start(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
) -> Result<(ModulatingEstimate, [Direction; 2]), String> {
    let cfg = s.modulating.config;
    let mut id = ModulatingIdentifier::new(k.identify_known(), rec.grid().dt, cfg)
        .map_err(|e| e.to_string())?;
    for i in 0..rec.len() {
        id.push(&rec.measurement(i)).map_err(|e| e.to_string())?;
    }
    let est = id.finish().map_err(|e| e.to_string())?;
    let ok = est.well_conditioned(cfg.rcond_min);
    let dirs = [
        ok[0].then_some(est.x.theta()),
        ok[1].then_some(est.z.theta()),
    ];
    Ok((est, dirs))
}

/// The algebraic estimate of each direction at its last well-conditioned instant up to
/// [`ALGEBRAIC_START_S`] after the first sample, and the later of the two instants
/// (input time).
fn algebraic_start(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
) -> Result<(f64, [Direction; 2]), String> {
    let config = s.algebraic.config().map_err(|e| e.to_string())?;
    let mut id = AlgebraicIdentifier::new(k.identify_known(), rec.grid().dt, config)
        .map_err(|e| e.to_string())?;
    let t = rec.t();
    let mut best: [Option<(f64, [f64; 3])>; 2] = [None, None];
    for i in 0..rec.len() {
        if t[i] - t[0] > ALGEBRAIC_START_S {
            break;
        }
        let e = id.push(&rec.measurement(i)).map_err(|e| e.to_string())?;
        let ok = e.well_conditioned(config.rcond_min);
        for (d, dir) in [e.x, e.z].iter().enumerate() {
            if ok[d] {
                best[d] = Some((t[i], dir.theta()));
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
