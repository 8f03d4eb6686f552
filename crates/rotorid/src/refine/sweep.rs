//! One pass of the discrete model over the record, with forward sensitivities, and what
//! is collected from it: the per-channel normal equations of the output-error problem
//!
//! ```text
//! r_x,k = x_k - x(t_k; theta),      J_x,kj = d x(t_k; theta) / d theta_j       (same for z)
//! S_x = sum_k r_x,k^2,   F_x = J_x^T J_x,   g_x = J_x^T r_x
//! ```
//!
//! (the channel weights 1/sigma^2 are applied afterwards, so one pass serves any sigma),
//! or simply the model response. No allocation inside the loop.

use super::unknowns::{Columns, MAXP};

/// Advances the discrete model by one sample interval.
pub(crate) trait Stepper {
    /// Advance the state y = (x, z, vx, vz) and the sensitivity columns s\[j\] = dy/dtheta_j
    /// from sample k to sample k + 1.
    fn step(&self, k: usize, y: &mut [f64; 4], s: &mut [[f64; 4]; MAXP]);
}

/// Receives the model state and sensitivities at every sample.
pub(crate) trait Sink {
    fn sample(&mut self, k: usize, y: &[f64; 4], s: &[[f64; 4]; MAXP]);
}

/// Run the model from y0 over the first `n_used` samples, feeding `sink`. The sensitivity
/// of an initial-state column starts at its unit vector, every other at zero.
pub(crate) fn sweep<S: Stepper, K: Sink>(
    stepper: &S,
    y0: [f64; 4],
    cols: &Columns,
    n_used: usize,
    sink: &mut K,
) {
    let mut y = y0;
    let mut s = [[0.0; 4]; MAXP];
    for (j, kind) in cols.kinds().iter().enumerate() {
        if let Some(i) = kind.initial_index() {
            s[j][i] = 1.0;
        }
    }
    for k in 0..n_used {
        sink.sample(k, &y, &s);
        if k + 1 < n_used {
            stepper.step(k, &mut y, &mut s);
        }
    }
}

/// Per-channel sums of one pass (upper triangles of F_x, F_z, row-major MAXP x MAXP).
#[derive(Debug, Clone)]
pub(crate) struct Normal {
    pub n: usize,
    pub samples: usize,
    pub sxx: f64,
    pub szz: f64,
    /// sum x_k^2, sum z_k^2 of the data \[m^2\].
    pub data_xx: f64,
    pub data_zz: f64,
    pub fx: [f64; MAXP * MAXP],
    pub fz: [f64; MAXP * MAXP],
    pub gx: [f64; MAXP],
    pub gz: [f64; MAXP],
}

impl Normal {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            samples: 0,
            sxx: 0.0,
            szz: 0.0,
            data_xx: 0.0,
            data_zz: 0.0,
            fx: [0.0; MAXP * MAXP],
            fz: [0.0; MAXP * MAXP],
            gx: [0.0; MAXP],
            gz: [0.0; MAXP],
        }
    }

    /// F = F_x / sigma_x^2 + F_z / sigma_z^2 (full symmetric n x n, row-major) and
    /// g = g_x / sigma_x^2 + g_z / sigma_z^2.
    pub(crate) fn combine(&self, var_x: f64, var_z: f64) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let mut f = vec![0.0; n * n];
        let mut g = vec![0.0; n];
        for i in 0..n {
            g[i] = self.gx[i] / var_x + self.gz[i] / var_z;
            for j in i..n {
                let v = self.fx[i * MAXP + j] / var_x + self.fz[i * MAXP + j] / var_z;
                f[i * n + j] = v;
                f[j * n + i] = v;
            }
        }
        (f, g)
    }
}

/// Accumulates [`Normal`] against measured x, z (or against zero data when `data` is
/// `None`, for the Fisher information alone).
pub(crate) struct NormalSink<'a> {
    pub data: Option<(&'a [f64], &'a [f64])>,
    pub acc: Normal,
}

impl Sink for NormalSink<'_> {
    #[inline]
    fn sample(&mut self, k: usize, y: &[f64; 4], s: &[[f64; 4]; MAXP]) {
        let a = &mut self.acc;
        let n = a.n;
        let (rx, rz) = match self.data {
            Some((x, z)) => {
                a.data_xx += x[k] * x[k];
                a.data_zz += z[k] * z[k];
                (x[k] - y[0], z[k] - y[1])
            }
            None => (0.0, 0.0),
        };
        a.samples += 1;
        a.sxx += rx * rx;
        a.szz += rz * rz;
        let mut jx = [0.0; MAXP];
        let mut jz = [0.0; MAXP];
        for j in 0..n {
            jx[j] = s[j][0];
            jz[j] = s[j][1];
        }
        for i in 0..n {
            a.gx[i] += jx[i] * rx;
            a.gz[i] += jz[i] * rz;
            let row = i * MAXP;
            for j in i..n {
                a.fx[row + j] += jx[i] * jx[j];
                a.fz[row + j] += jz[i] * jz[j];
            }
        }
    }
}

/// Collects the model response x_k, z_k \[m\].
pub(crate) struct ResponseSink {
    pub x: Vec<f64>,
    pub z: Vec<f64>,
}

impl Sink for ResponseSink {
    #[inline]
    fn sample(&mut self, _k: usize, y: &[f64; 4], _s: &[[f64; 4]; MAXP]) {
        self.x.push(y[0]);
        self.z.push(y[1]);
    }
}
