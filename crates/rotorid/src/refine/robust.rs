//! Standard errors that do not assume a correct model: the heteroskedasticity- and
//! autocorrelation-consistent (HAC) sandwich covariance (docs/method.md section 5.5).
//!
//! The Fisher covariance F^-1 holds when the residuals r_k = y_k - y(t_k; theta) are the
//! white noise of a correct model. A wrong model leaves correlated residuals, and then the
//! covariance of the estimate is the sandwich
//!
//! ```text
//! C = F^-1 B F^-1,   F = sum_k J_k^T W J_k,   g_k = J_k^T W r_k   (W = diag(1/sx^2, 1/sz^2))
//! B = sum_k g_k g_k^T + sum_(l=1..L) w_l sum_k (g_k g_(k-l)^T + g_(k-l) g_k^T),
//! w_l = 1 - l / (L + 1)                                                   (Bartlett)
//! ```
//!
//! (Newey & West, Econometrica 55, 1987). The bandwidth L follows Andrews' AR(1) plug-in
//! rule (Econometrica 59, 1991, eq. 6.4) from the pooled lag-1 autocorrelation rho of the
//! weighted residuals: `L = 1.1447 (alpha N)^(1/3)`, `alpha = 4 rho^2 / ((1 - rho)^2
//! (1 + rho)^2)`, at most N / 4 and [`MAX_BANDWIDTH`]. For a correct model (rho ~ 0) L is
//! ~0 and C ~ F^-1.
//!
//! Cost: one pass for the residuals' rho, one for B, O(n^2) per sample whatever L: the
//! weighted sum S_k = sum_l w_l g_(k-l) of the Bartlett window is updated from the plain
//! window sum A_k = sum_l g_(k-l) by
//!
//! ```text
//! S_(k+1) = S_k + (L g_k - A_k) / (L + 1),   A_(k+1) = A_k + g_k - g_(k-L)
//! ```
//!
//! and both are recomputed exactly from the ring of the last L scores every L samples, so
//! rounding cannot accumulate. What it cannot do: a misspecified model also *biases* the
//! estimate, and no covariance covers a bias; the pipeline withholds the values of a model
//! its residual tests reject (module `pipeline::adequacy`).

use super::discretisation::Discrete;
use super::fisher::Fisher;
use super::sweep::Sink;
use super::unknowns::{Columns, Theta, MAXP};

/// Largest bandwidth used \[samples\].
pub const MAX_BANDWIDTH: usize = 4096;

/// The sandwich covariance and how it was made (module doc).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Robust {
    /// C, n x n row-major.
    pub cov: Vec<f64>,
    /// The Bartlett bandwidth L \[samples\].
    pub bandwidth: usize,
    /// Pooled lag-1 autocorrelation of the weighted residuals.
    pub rho: f64,
}

/// The pooled lag-1 autocorrelation of the weighted residuals.
struct RhoSink<'a> {
    x: &'a [f64],
    z: &'a [f64],
    wx: f64,
    wz: f64,
    last: Option<(f64, f64)>,
    lag: f64,
    sum: f64,
}

impl Sink for RhoSink<'_> {
    fn sample(&mut self, k: usize, y: &[f64; 4], _s: &[[f64; 4]; MAXP]) {
        let (rx, rz) = (self.x[k] - y[0], self.z[k] - y[1]);
        if let Some((px, pz)) = self.last {
            self.lag += self.wx * rx * px + self.wz * rz * pz;
        }
        self.sum += self.wx * rx * rx + self.wz * rz * rz;
        self.last = Some((rx, rz));
    }
}

/// Accumulates B (module doc).
struct HacSink<'a> {
    x: &'a [f64],
    z: &'a [f64],
    wx: f64,
    wz: f64,
    n: usize,
    l: usize,
    /// The last L scores, oldest at `head`.
    ring: Vec<[f64; MAXP]>,
    head: usize,
    filled: usize,
    a: [f64; MAXP],
    s: [f64; MAXP],
    b: Vec<f64>,
}

impl HacSink<'_> {
    /// A and S recomputed from the ring (exact: no accumulated rounding).
    fn resync(&mut self) {
        let n = self.n;
        self.a = [0.0; MAXP];
        self.s = [0.0; MAXP];
        // the newest score is lag 1
        for lag in 1..=self.filled {
            let idx = (self.head + self.l - lag) % self.l;
            let w = 1.0 - lag as f64 / (self.l + 1) as f64;
            for j in 0..n {
                self.a[j] += self.ring[idx][j];
                self.s[j] += w * self.ring[idx][j];
            }
        }
    }
}

impl Sink for HacSink<'_> {
    fn sample(&mut self, k: usize, y: &[f64; 4], s: &[[f64; 4]; MAXP]) {
        let n = self.n;
        let (rx, rz) = (self.wx * (self.x[k] - y[0]), self.wz * (self.z[k] - y[1]));
        let mut g = [0.0; MAXP];
        for j in 0..n {
            g[j] = s[j][0] * rx + s[j][1] * rz;
        }
        for i in 0..n {
            for j in 0..n {
                self.b[i * n + j] += g[i] * g[j] + g[i] * self.s[j] + self.s[i] * g[j];
            }
        }
        if self.l == 0 {
            return;
        }
        // advance the windows by g_k, dropping g_(k-L) once the ring is full
        let oldest = if self.filled == self.l {
            self.ring[self.head]
        } else {
            [0.0; MAXP]
        };
        let l = self.l as f64;
        for j in 0..n {
            self.s[j] += (l * g[j] - self.a[j]) / (l + 1.0);
            self.a[j] += g[j] - oldest[j];
        }
        self.ring[self.head] = g;
        self.head = (self.head + 1) % self.l;
        self.filled = (self.filled + 1).min(self.l);
        if k % self.l == self.l - 1 {
            self.resync();
        }
    }
}

/// Andrews' AR(1) plug-in Bartlett bandwidth for `samples` scores with lag-1
/// autocorrelation `rho` (module doc).
pub(crate) fn bandwidth(rho: f64, samples: usize) -> usize {
    let rho = if rho.is_finite() {
        rho.clamp(-0.999, 0.999)
    } else {
        0.0
    };
    let alpha = 4.0 * rho * rho / ((1.0 - rho).powi(2) * (1.0 + rho).powi(2));
    let l = 1.1447 * (alpha * samples as f64).cbrt();
    (l.floor() as usize).min(samples / 4).min(MAX_BANDWIDTH)
}

/// The sandwich covariance at `theta` against the data `x`, `z` \[m\] with noise
/// variances `vx`, `vz` \[m^2\] and the Fisher covariance of `fi` (module doc).
#[allow(clippy::too_many_arguments)]
pub(crate) fn robust_covariance(
    disc: &Discrete,
    theta: &Theta,
    cols: &Columns,
    samples: usize,
    x: &[f64],
    z: &[f64],
    vx: f64,
    vz: f64,
    fi: &Fisher,
) -> Robust {
    let n = cols.n;
    let (wx, wz) = (1.0 / vx, 1.0 / vz);
    let mut rs = RhoSink {
        x,
        z,
        wx,
        wz,
        last: None,
        lag: 0.0,
        sum: 0.0,
    };
    disc.run(theta, cols, samples, &mut rs);
    let rho = rs.lag / rs.sum;
    let l = bandwidth(rho, samples);
    let mut hac = HacSink {
        x,
        z,
        wx,
        wz,
        n,
        l,
        ring: vec![[0.0; MAXP]; l],
        head: 0,
        filled: 0,
        a: [0.0; MAXP],
        s: [0.0; MAXP],
        b: vec![0.0; n * n],
    };
    disc.run(theta, cols, samples, &mut hac);
    let c = &fi.cov;
    let b = &hac.b;
    // C B C (C symmetric)
    let mut cb = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            cb[i * n + j] = (0..n).map(|m| c[i * n + m] * b[m * n + j]).sum();
        }
    }
    let mut cov = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            cov[i * n + j] = (0..n).map(|m| cb[i * n + m] * c[m * n + j]).sum();
        }
    }
    Robust {
        cov,
        bandwidth: l,
        rho,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bandwidths_of_white_and_correlated_residuals() {
        assert_eq!(bandwidth(0.0, 10_000), 0);
        assert_eq!(bandwidth(f64::NAN, 10_000), 0);
        // rho = 0.9, N = 1e4: alpha = 3.24 / (0.01 * 3.61) = 89.75; 1.1447 * 965^(1/3) = 112.0
        let l = bandwidth(0.9, 10_000);
        assert!((110..=113).contains(&l), "{l}");
        assert_eq!(bandwidth(0.999, 100), 25);
        assert_eq!(bandwidth(0.999, 1 << 30), MAX_BANDWIDTH);
    }

    #[test]
    fn the_running_bartlett_sums_equal_the_direct_ones() {
        // B from the O(n^2) recursion against the O(n^2 L) definition, on random scores
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 3;
        let (samples, l) = (500, 17);
        let scores: Vec<[f64; MAXP]> = (0..samples)
            .map(|_| {
                let mut g = [0.0; MAXP];
                g.iter_mut()
                    .take(n)
                    .for_each(|v| *v = rng.gen::<f64>() - 0.5);
                g
            })
            .collect();
        // feed the sink scores through y = data - score (unit sensitivities on column j
        // would need a model; drive the recursion directly instead)
        let mut direct = vec![0.0; n * n];
        for k in 0..samples {
            for i in 0..n {
                for j in 0..n {
                    direct[i * n + j] += scores[k][i] * scores[k][j];
                    for lag in 1..=l.min(k) {
                        let w = 1.0 - lag as f64 / (l + 1) as f64;
                        let p = &scores[k - lag];
                        direct[i * n + j] += w * (scores[k][i] * p[j] + p[i] * scores[k][j]);
                    }
                }
            }
        }
        let zeros = vec![0.0; samples];
        let mut sink = HacSink {
            x: &zeros,
            z: &zeros,
            wx: 1.0,
            wz: 1.0,
            n,
            l,
            ring: vec![[0.0; MAXP]; l],
            head: 0,
            filled: 0,
            a: [0.0; MAXP],
            s: [0.0; MAXP],
            b: vec![0.0; n * n],
        };
        // with x = z = 0 and y = (-1, 0): r_x = 1, r_z = 0, so g_j = s[j][0]
        for (k, g) in scores.iter().enumerate() {
            let mut s = [[0.0; 4]; MAXP];
            for j in 0..n {
                s[j][0] = g[j];
            }
            sink.sample(k, &[-1.0, 0.0, 0.0, 0.0], &s);
        }
        for (a, b) in sink.b.iter().zip(&direct) {
            assert!((a - b).abs() <= 1e-12 * direct.iter().map(|v| v.abs()).sum::<f64>());
        }
    }
}
