//! Classical fourth-order Runge-Kutta on the state and its forward sensitivities, for any
//! speed history (ramps, measured speed).
//!
//! State y = (x, z, vx, vz); eq. (1) solved for the accelerations:
//!
//! ```text
//! ax = ( -kx x - kxz z - cx vx - cxz vz + a w vz + a w' z + u_c g_xc + u_s g_xs ) / m
//! az = ( -kz z - kzx x - cz vz - czx vx - a w vx          + u_c g_zc + u_s g_zs ) / m
//! ```
//!
//! (g: the unbalance shape functions of `speed_table`). The sensitivity S_j = dy/dtheta_j
//! obeys the variational equation S_j' = A(t) S_j + df/dtheta_j, with the explicit terms
//!
//! ```text
//! m: (-ax/m, -az/m)    cx: (-vx/m, 0)    kx: (-x/m, 0)    cz: (0, -vz/m)    kz: (0, -z/m)
//! a: ((w vz + w' z)/m, -w vx/m)    u_c: (g_xc/m, g_zc/m)    u_s: (g_xs/m, g_zs/m)
//! cxz: (-vz/m, 0)   kxz: (-z/m, 0)   czx: (0, -vx/m)   kzx: (0, -x/m)
//! ```
//!
//! and zero for the initial-state columns (whose S starts at a unit vector). RK4 applied
//! to the system (y, S) gives exactly the derivative of the RK4 map for y (an explicit
//! Runge-Kutta method commutes with differentiation with respect to parameters), so the
//! Jacobian is the exact Jacobian of the discrete model.
//!
//! Error: for an oscillation at frequency w_n the RK4 step of length h has the relative
//! frequency error (w_n h)^4 / 120 and the amplitude decay (w_n h)^6 / 144 per step
//! (Hairer, Norsett, Wanner, *Solving ODEs I*, sec. II.2 / stability function
//! R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24). `substeps_within` picks the number of sub-steps
//! per sample that keeps the frequency error below [`FREQ_TOL`] (or a looser bound).

use super::speed_table::ForcePoint;
use super::sweep::Stepper;
use super::unknowns::{Columns, Kind, Theta, MAXP};

/// Target bound on RK4's relative frequency error (w h)^4 / 120 (1e-9: far below the
/// relative Cramer-Rao bound ~4e-5 of m at 40 dB, and below the 1e-7 modelling budget).
pub(crate) const FREQ_TOL: f64 = 1e-9;

/// Sub-steps per sample interval `dt` \[s\] so that (w_ref dt / n)^4 / 120 <= `freq_tol`
/// (refine's own: [`FREQ_TOL`]), w_ref = max(sqrt(k/m) + |a| w_max / (2m), w_max) (the
/// forward whirl frequency bound and the forcing frequency) \[rad/s\], k = ||K||_inf =
/// max(|kx| + |kxz|, |kzx| + |kz|) (max(kx, kz) for a Jeffcott rotor).
pub(crate) fn substeps_within(t: &Theta, w_max: f64, dt: f64, freq_tol: f64) -> usize {
    // ||K||_inf bounds the stiffness matrix's eigenvalues (max(kx, kz) without coupling)
    let k = (t.kx.abs() + t.kxz.abs()).max(t.kzx.abs() + t.kz.abs());
    let wn = (k / t.m).sqrt() + t.a.abs() * w_max / (2.0 * t.m);
    let w_ref = wn.max(w_max);
    let h_max = (120.0 * freq_tol).powf(0.25) / w_ref;
    let n = (dt / h_max).ceil();
    if n.is_finite() {
        (n as usize).clamp(1, 10_000)
    } else {
        1
    }
}

/// One sample interval: `sub` RK4 steps of h = dt / sub.
pub(crate) struct Rk4Step<'a> {
    table: &'a [ForcePoint],
    sub: usize,
    h: f64,
    t: Theta,
    inv_m: f64,
    kinds: [Kind; MAXP],
    n: usize,
}

type Sens = [[f64; 4]; MAXP];

impl<'a> Rk4Step<'a> {
    /// `table` from `speed_table::rk4_table(.., sub)`.
    pub(crate) fn new(
        t: &Theta,
        cols: &Columns,
        dt: f64,
        sub: usize,
        table: &'a [ForcePoint],
    ) -> Self {
        let mut kinds = [Kind::M; MAXP];
        kinds[..cols.n].copy_from_slice(cols.kinds());
        Self {
            table,
            sub,
            h: dt / sub as f64,
            t: *t,
            inv_m: 1.0 / t.m,
            kinds,
            n: cols.n,
        }
    }

    /// One RK4 stage, fused with its bookkeeping. With d = f(t, (ty, ts)) the right-hand
    /// side at forcing point `p` (state and sensitivity equations):
    /// (acc_y, acc_s) += c_acc d and (ty, ts) = (by, bs) + c_next d (the next stage's input).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn stage(
        &self,
        p: &ForcePoint,
        ty: &mut [f64; 4],
        ts: &mut Sens,
        by: &[f64; 4],
        bs: &Sens,
        c_acc: f64,
        c_next: f64,
        acc_y: &mut [f64; 4],
        acc_s: &mut Sens,
    ) {
        let t = &self.t;
        let im = self.inv_m;
        let y = *ty;
        // the coefficients of z' and z in x'', of x' and x in z'' (cross-coupled terms 0 in
        // the Jeffcott model, which leaves each bit for bit)
        let aw = t.a * p.w - t.cxz;
        let awd = t.a * p.wd - t.kxz;
        let awz = t.a * p.w + t.czx;
        let kzx = t.kzx;
        let fx = t.uc * p.gxc + t.us * p.gxs;
        let fz = t.uc * p.gzc + t.us * p.gzs;
        let ax = im * (-t.kx * y[0] - t.cx * y[2] + aw * y[3] + awd * y[1] + fx);
        let az = im * (-t.kz * y[1] - t.cz * y[3] - awz * y[2] - kzx * y[0] + fz);
        let dy = [y[2], y[3], ax, az];
        for j in 0..self.n {
            let q = ts[j];
            let mut ex = im * (-t.kx * q[0] - t.cx * q[2] + aw * q[3] + awd * q[1]);
            let mut ez = im * (-t.kz * q[1] - t.cz * q[3] - awz * q[2] - kzx * q[0]);
            match self.kinds[j] {
                Kind::M => {
                    ex -= ax * im;
                    ez -= az * im;
                }
                Kind::Cx => ex -= y[2] * im,
                Kind::Kx => ex -= y[0] * im,
                Kind::Cz => ez -= y[3] * im,
                Kind::Kz => ez -= y[1] * im,
                Kind::Cxz => ex -= y[3] * im,
                Kind::Czx => ez -= y[2] * im,
                Kind::Kxz => ex -= y[1] * im,
                Kind::Kzx => ez -= y[0] * im,
                Kind::A => {
                    ex += (p.w * y[3] + p.wd * y[1]) * im;
                    ez -= p.w * y[2] * im;
                }
                Kind::Uc => {
                    ex += p.gxc * im;
                    ez += p.gzc * im;
                }
                Kind::Us => {
                    ex += p.gxs * im;
                    ez += p.gzs * im;
                }
                Kind::X0 | Kind::Z0 | Kind::Vx0 | Kind::Vz0 => {}
            }
            let d = [q[2], q[3], ex, ez];
            for i in 0..4 {
                acc_s[j][i] += c_acc * d[i];
                ts[j][i] = bs[j][i] + c_next * d[i];
            }
        }
        for i in 0..4 {
            acc_y[i] += c_acc * dy[i];
            ty[i] = by[i] + c_next * dy[i];
        }
    }
}

impl Stepper for Rk4Step<'_> {
    #[inline]
    fn step(&self, k: usize, y: &mut [f64; 4], s: &mut [[f64; 4]; MAXP]) {
        let h = self.h;
        let n = self.n;
        let mut ts: Sens = [[0.0; 4]; MAXP];
        for sub in 0..self.sub {
            let q = 2 * self.sub * k + 2 * sub;
            let (p0, pm, p1) = (&self.table[q], &self.table[q + 1], &self.table[q + 2]);
            // y_next = y + h/6 (k1 + 2 k2 + 2 k3 + k4), accumulated stage by stage
            let by = *y;
            let mut bs: Sens = [[0.0; 4]; MAXP];
            bs[..n].copy_from_slice(&s[..n]);
            let mut ty = by;
            ts[..n].copy_from_slice(&bs[..n]);
            self.stage(p0, &mut ty, &mut ts, &by, &bs, h / 6.0, 0.5 * h, y, s);
            self.stage(pm, &mut ty, &mut ts, &by, &bs, h / 3.0, 0.5 * h, y, s);
            self.stage(pm, &mut ty, &mut ts, &by, &bs, h / 3.0, h, y, s);
            self.stage(p1, &mut ty, &mut ts, &by, &bs, h / 6.0, 0.0, y, s);
        }
    }
}
