//! The model's help in conditioning (docs/acquisition.md section 6): the probes' DC level
//! is the gap at the rotor's equilibrium, but the mean of the measured motion over the
//! record is not zero (a free transient over T has a mean ~ its amplitude / (w_n T)), and
//! only the model knows it. Given a rotor guess, with per-sample speed from the keyphasor,
//!
//! ```text
//! x_k - x_f,k = sum_j s_j x_j,k + o_x + sum_h (a_xh cos h phi_k + b_xh sin h phi_k) + e_x,k
//! z_k - z_f,k = sum_j s_j z_j,k + o_z + sum_h (a_zh cos h phi_k + b_zh sin h phi_k) + e_z,k
//! ```
//!
//! is solved by linear least squares: (x_f, z_f) is the model response from the given
//! initial state (or from rest), (x_j, z_j) the responses of the unforced model to unit
//! initial states (when the initial state is not given; their weights s_j are the fitted
//! initial state), o the offsets (removed from x, z: the DC correction) and the harmonics
//! 1..3 locked to phi the residual runout (reported, never removed: 1X also holds whatever
//! the guess gets wrong about the unbalance response).

use serde::Serialize;

use crate::model::{InitialState, RotorParams};
use crate::refine::{model_response, Discretisation, Experiment, SpeedData};

use super::error::AcquisitionError;
use super::runout::{harmonic_row, solve_normal, Harmonics};

/// Harmonics of the residual examined for runout.
pub const RESIDUAL_HARMONICS: usize = 3;

/// Result of the model-assisted fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelFit {
    /// Initial state used or fitted (at the record's first sample).
    pub initial: InitialState,
    /// True when the initial state was fitted here.
    pub initial_fitted: bool,
    /// Offsets (o_x, o_z) \[m\] of the measured x, z from the model's zero.
    pub offset: [f64; 2],
    /// Residual harmonics locked to phi, x then z.
    pub harmonics: [Harmonics; 2],
    /// Residual RMS per channel \[m\].
    pub residual_rms: [f64; 2],
    /// Standard error of one harmonic amplitude, sigma sqrt(2 / N) \[m\], x then z.
    pub harmonic_std_error: [f64; 2],
}

/// The fit of the module doc on samples at t_k = k dt.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit(
    rotor: &RotorParams,
    initial: Option<InitialState>,
    dt: f64,
    phi: &[f64],
    omega: &[f64],
    omega_dot: &[f64],
    x: &[f64],
    z: &[f64],
) -> Result<ModelFit, AcquisitionError> {
    let n = x.len();
    let exp = Experiment {
        dt,
        samples: n,
        speed: SpeedData::Samples {
            phi,
            omega,
            omega_dot,
        },
    };
    let ic0 = initial.unwrap_or_default();
    let forced = model_response(rotor, &ic0, &exp, Discretisation::Auto)?;
    let mut basis = Vec::new();
    if initial.is_none() {
        let mut free = *rotor;
        free.unbalance.m_u = 0.0;
        let wn = (rotor.kx.max(rotor.kz) / rotor.m).sqrt();
        let u = 1e-6;
        for j in 0..4 {
            let mut ic = InitialState::default();
            match j {
                0 => ic.x = u,
                1 => ic.z = u,
                2 => ic.vx = u * wn,
                _ => ic.vz = u * wn,
            }
            basis.push(model_response(&free, &ic, &exp, Discretisation::Auto)?);
        }
    }
    let nb = basis.len();
    let h = RESIDUAL_HARMONICS;
    let p = nb + 2 + 4 * h;
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    let mut rowx = vec![0.0; p];
    let mut rowz = vec![0.0; p];
    let mut harm = vec![0.0; 2 * h];
    for k in 0..n {
        harmonic_row(phi[k], h, &mut harm);
        rowx.iter_mut().for_each(|v| *v = 0.0);
        rowz.iter_mut().for_each(|v| *v = 0.0);
        for (j, bs) in basis.iter().enumerate() {
            rowx[j] = bs.x[k];
            rowz[j] = bs.z[k];
        }
        rowx[nb] = 1.0;
        rowz[nb + 1] = 1.0;
        rowx[nb + 2..nb + 2 + 2 * h].copy_from_slice(&harm);
        rowz[nb + 2 + 2 * h..].copy_from_slice(&harm);
        let (rx, rz) = (x[k] - forced.x[k], z[k] - forced.z[k]);
        for r in 0..p {
            b[r] += rowx[r] * rx + rowz[r] * rz;
            for c in r..p {
                a[r * p + c] += rowx[r] * rowx[c] + rowz[r] * rowz[c];
            }
        }
    }
    for r in 0..p {
        for c in 0..r {
            a[r * p + c] = a[c * p + r];
        }
    }
    let sol = solve_normal(&a, &b, p);
    // Residual RMS.
    let (mut sx, mut sz) = (0.0, 0.0);
    for k in 0..n {
        harmonic_row(phi[k], h, &mut harm);
        let mut mx = forced.x[k] + sol[nb];
        let mut mz = forced.z[k] + sol[nb + 1];
        for (j, bs) in basis.iter().enumerate() {
            mx += sol[j] * bs.x[k];
            mz += sol[j] * bs.z[k];
        }
        for q in 0..2 * h {
            mx += sol[nb + 2 + q] * harm[q];
            mz += sol[nb + 2 + 2 * h + q] * harm[q];
        }
        sx += (x[k] - mx).powi(2);
        sz += (z[k] - mz).powi(2);
    }
    let rms = [(sx / n as f64).sqrt(), (sz / n as f64).sqrt()];
    let init = if initial.is_none() {
        let wn = (rotor.kx.max(rotor.kz) / rotor.m).sqrt();
        InitialState {
            x: sol[0] * 1e-6,
            z: sol[1] * 1e-6,
            vx: sol[2] * 1e-6 * wn,
            vz: sol[3] * 1e-6 * wn,
        }
    } else {
        ic0
    };
    let harmonics_of = |off: usize| Harmonics {
        mean: 0.0,
        cos: (0..h).map(|q| sol[off + 2 * q]).collect(),
        sin: (0..h).map(|q| sol[off + 2 * q + 1]).collect(),
    };
    let se = (2.0 / n as f64).sqrt();
    Ok(ModelFit {
        initial: init,
        initial_fitted: initial.is_none(),
        offset: [sol[nb], sol[nb + 1]],
        harmonics: [harmonics_of(nb + 2), harmonics_of(nb + 2 + 2 * h)],
        residual_rms: rms,
        harmonic_std_error: [rms[0] * se, rms[1] * se],
    })
}
