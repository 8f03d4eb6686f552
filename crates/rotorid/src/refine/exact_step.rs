//! Exact discretisation at constant speed W (docs/method.md sections 2.2 and 5.1.3; Van
//! Loan 1978).
//!
//! With the forcing oscillator (s, c) = (sin phi, cos phi), phi = phi0 + W t, appended to
//! the state, eq. (1) at w' = 0 is the autonomous linear system Y' = A Y,
//! Y = (x, z, vx, vz, s, c):
//!
//! ```text
//!       [    0       0         1             0          0        0     ]
//!       [    0       0         0             1          0        0     ]
//! A  =  [ -kx/m   -kxz/m    -cx/m     (aW - cxz)/m   W^2 uc/m  W^2 us/m ]
//!       [ -kzx/m  -kz/m  -(aW + czx)/m   -cz/m     -W^2 us/m  W^2 uc/m ]
//!       [    0       0         0             0          0        W     ]
//!       [    0       0         0             0         -W        0     ]
//! ```
//!
//! (the cross-coupled terms cxz, czx, kxz, kzx are 0 in the Jeffcott model).
//!
//! so the samples obey Y_k+1 = Phi Y_k exactly, Phi = exp(A dt): no discretisation error
//! at all, only rounding. The sensitivity of Phi to a parameter theta_j is the Frechet
//! derivative of the exponential in the direction E_j = dA/dtheta_j, read from the
//! block-triangular exponential (C. F. Van Loan, "Computing integrals involving the
//! matrix exponential", IEEE TAC 23(3), 1978):
//!
//! ```text
//! exp( [ A  E_j ] dt )  =  [ Phi  dPhi/dtheta_j ]
//!      [ 0   A  ]          [  0        Phi      ]
//! ```
//!
//! and the forward sensitivities of the discrete model are
//! S_j,k+1 = Phi S_j,k + (dPhi/dtheta_j) Y_k: the exact Jacobian of the discrete model.
//! The oscillator rows of Phi and of every dPhi/dtheta_j are parameter-free (A is block
//! upper triangular), so only rows 0..4 are kept, and (s_k, c_k) are taken from the exact
//! phase W k dt + phi0 at each sample.

use nalgebra::SMatrix;

use super::sweep::Stepper;
use super::unknowns::{Columns, Kind, Theta, MAXP};

pub(crate) type M6 = SMatrix<f64, 6, 6>;
type M12 = SMatrix<f64, 12, 12>;

/// One exact step at constant speed: rows 0..4 of Phi and of dPhi/dtheta_j.
pub(crate) struct ExactStep<'a> {
    phi: [[f64; 6]; 4],
    dphi: [[[f64; 6]; 4]; MAXP],
    n: usize,
    nphys: usize,
    osc: &'a [[f64; 2]],
}

/// The augmented system matrix A of the module doc.
pub(crate) fn system_matrix(t: &Theta, w: f64) -> M6 {
    let im = 1.0 / t.m;
    let w2 = w * w;
    let mut a = M6::zeros();
    a[(0, 2)] = 1.0;
    a[(1, 3)] = 1.0;
    // cross-coupled terms: 0 in the Jeffcott model, which leaves every entry bit for bit
    a[(2, 0)] = -t.kx * im;
    a[(2, 1)] = -t.kxz * im;
    a[(2, 2)] = -t.cx * im;
    a[(2, 3)] = (t.a * w - t.cxz) * im;
    a[(2, 4)] = w2 * t.uc * im;
    a[(2, 5)] = w2 * t.us * im;
    a[(3, 0)] = -t.kzx * im;
    a[(3, 1)] = -t.kz * im;
    a[(3, 2)] = -(t.a * w + t.czx) * im;
    a[(3, 3)] = -t.cz * im;
    a[(3, 4)] = -w2 * t.us * im;
    a[(3, 5)] = w2 * t.uc * im;
    a[(4, 5)] = w;
    a[(5, 4)] = -w;
    a
}

/// E = dA/dtheta for one model parameter (rows 2 and 3 only).
fn direction(kind: Kind, a: &M6, t: &Theta, w: f64) -> M6 {
    let im = 1.0 / t.m;
    let w2 = w * w;
    let mut e = M6::zeros();
    match kind {
        Kind::M => {
            for c in 0..6 {
                e[(2, c)] = -a[(2, c)] * im;
                e[(3, c)] = -a[(3, c)] * im;
            }
        }
        Kind::Cx => e[(2, 2)] = -im,
        Kind::Kx => e[(2, 0)] = -im,
        Kind::Cz => e[(3, 3)] = -im,
        Kind::Kz => e[(3, 1)] = -im,
        Kind::Cxz => e[(2, 3)] = -im,
        Kind::Czx => e[(3, 2)] = -im,
        Kind::Kxz => e[(2, 1)] = -im,
        Kind::Kzx => e[(3, 0)] = -im,
        Kind::A => {
            e[(2, 3)] = w * im;
            e[(3, 2)] = -w * im;
        }
        Kind::Uc => {
            e[(2, 4)] = w2 * im;
            e[(3, 5)] = w2 * im;
        }
        Kind::Us => {
            e[(2, 5)] = w2 * im;
            e[(3, 4)] = -w2 * im;
        }
        Kind::X0 | Kind::Z0 | Kind::Vx0 | Kind::Vz0 => {}
    }
    e
}

/// The balancing of the state (x, z, vx, vz, s, c): the velocities over `s` \[rad/s\],
/// the undamped natural frequency sqrt(||K|| / m) (1 when it is 0 or not finite). In SI
/// units A mixes k/m ~ 1e5 with 1, and the exponential's Pade degree and squarings follow
/// the norm: D^-1 A D (D = diag(1, 1, s, s, 1, 1)) has entries ~ s, so A dt needs a lower
/// degree and fewer squarings (on the adequacy verdict's long steps, none instead of
/// five) and is as accurate; exp(A dt) = D exp(D^-1 A D dt) D^-1, and the Frechet
/// derivative transforms the same way. Used by the adequacy verdict's fit only
/// (`Discrete::balanced`): its results differ from the plain ones at the rounding level.
fn balancing(a: &M6) -> [f64; 6] {
    let k = a[(2, 0)]
        .abs()
        .max(a[(2, 1)].abs())
        .max(a[(3, 0)].abs())
        .max(a[(3, 1)].abs());
    let s = k.sqrt();
    let s = if s.is_finite() && s > 0.0 { s } else { 1.0 };
    [1.0, 1.0, s, s, 1.0, 1.0]
}

/// D^-1 `m` D for the balancing `d` ([`balancing`]).
fn similar(m: &M6, d: &[f64; 6]) -> M6 {
    M6::from_fn(|i, j| m[(i, j)] * d[j] / d[i])
}

/// Rows 0..4 of the Frechet derivative of exp at `a_dt` in direction `e_dt` (Van Loan),
/// both balanced by `d` (the result is returned unbalanced). The direction is scaled to
/// the norm of `a_dt` first (the derivative is linear in it), so the scaling-and-squaring
/// of the 12x12 exponential is chosen for A, not for E.
fn frechet_rows(a_dt: &M6, e_dt: &M6, d: &[f64; 6]) -> [[f64; 6]; 4] {
    let (a_dt, e_dt) = (&similar(a_dt, d), &similar(e_dt, d));
    let mut out = [[0.0; 6]; 4];
    let en = e_dt.abs().max();
    if en == 0.0 {
        return out;
    }
    let rho = a_dt.abs().max().max(f64::MIN_POSITIVE) / en;
    let mut big = M12::zeros();
    big.fixed_view_mut::<6, 6>(0, 0).copy_from(a_dt);
    big.fixed_view_mut::<6, 6>(6, 6).copy_from(a_dt);
    big.fixed_view_mut::<6, 6>(0, 6).copy_from(&(e_dt * rho));
    let ex = crate::expm::exp12(&big);
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = ex[(r, 6 + c)] / rho * d[r] / d[c];
        }
    }
    out
}

impl<'a> ExactStep<'a> {
    /// Phi and dPhi/dtheta_j for the parameters `t` at speed `w` \[rad/s\] and step `dt` \[s\];
    /// `osc` holds (sin phi_k, cos phi_k) for every sample.
    /// With `balanced`, the exponentials are taken on the balanced state ([`balancing`]).
    pub(crate) fn new(
        t: &Theta,
        cols: &Columns,
        w: f64,
        dt: f64,
        osc: &'a [[f64; 2]],
        balanced: bool,
    ) -> Self {
        let a = system_matrix(t, w);
        let a_dt = a * dt;
        let d = if balanced { balancing(&a) } else { [1.0; 6] };
        let ex = crate::expm::exp6(&similar(&a_dt, &d));
        let mut phi = [[0.0; 6]; 4];
        for (r, row) in phi.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = ex[(r, c)] * d[r] / d[c];
            }
        }
        let mut dphi = [[[0.0; 6]; 4]; MAXP];
        for (j, &kind) in cols.kinds()[..cols.nphys].iter().enumerate() {
            dphi[j] = frechet_rows(&a_dt, &(direction(kind, &a, t, w) * dt), &d);
        }
        Self {
            phi,
            dphi,
            n: cols.n,
            nphys: cols.nphys,
            osc,
        }
    }

    /// Phi as a 6x6 matrix (rows 4, 5: the rotation of the forcing oscillator), for tests.
    #[cfg(test)]
    pub(crate) fn full_phi(t: &Theta, w: f64, dt: f64) -> M6 {
        (system_matrix(t, w) * dt).exp()
    }
}

impl Stepper for ExactStep<'_> {
    #[inline]
    fn step(&self, k: usize, y: &mut [f64; 4], s: &mut [[f64; 4]; MAXP]) {
        let [sn, cs] = self.osc[k];
        let v = [y[0], y[1], y[2], y[3], sn, cs];
        let p = &self.phi;
        for (j, sj) in s.iter_mut().enumerate().take(self.n) {
            let q = *sj;
            let mut out = [0.0; 4];
            for (r, o) in out.iter_mut().enumerate() {
                *o = p[r][0] * q[0] + p[r][1] * q[1] + p[r][2] * q[2] + p[r][3] * q[3];
            }
            if j < self.nphys {
                let d = &self.dphi[j];
                for (r, o) in out.iter_mut().enumerate() {
                    *o += d[r][0] * v[0]
                        + d[r][1] * v[1]
                        + d[r][2] * v[2]
                        + d[r][3] * v[3]
                        + d[r][4] * v[4]
                        + d[r][5] * v[5];
                }
            }
            *sj = out;
        }
        for (r, yr) in y.iter_mut().enumerate() {
            *yr = p[r][0] * v[0]
                + p[r][1] * v[1]
                + p[r][2] * v[2]
                + p[r][3] * v[3]
                + p[r][4] * v[4]
                + p[r][5] * v[5];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{InitialState, Rotor};

    /// Table 1 on cross-coupled bearings, every parameter of that model unknown.
    fn cross_coupled() -> (Theta, Columns) {
        let mut p = Rotor::table1().params();
        p.coupling = Some(crate::model::CrossCoupling {
            cxz: 3.0,
            czx: -2.0,
            kxz: 1.0e5,
            kzx: -1.2e5,
        });
        let t0 = Theta::new(&p, &InitialState::default());
        let u = super::super::Unknowns {
            cxz: true,
            czx: true,
            kxz: true,
            kzx: true,
            ..super::super::Unknowns::all()
        };
        let cols = Columns::new(&u, crate::parameter::ModelKind::CrossCoupled);
        (t0, cols)
    }

    /// The Van Loan derivative agrees with a central difference of exp(A(theta) dt), for
    /// every parameter of the cross-coupled model.
    #[test]
    fn frechet_derivative_matches_central_difference() {
        let w = 125.0;
        let dt = 1e-4;
        let (t0, cols) = cross_coupled();
        let osc = [[0.0, 1.0]];
        let st = ExactStep::new(&t0, &cols, w, dt, &osc, false);
        for (j, &kind) in cols.kinds()[..cols.nphys].iter().enumerate() {
            let v0 = t0.get(kind);
            let h = 1e-5 * v0.abs().max(1e-6);
            let (mut tp, mut tm) = (t0, t0);
            tp.set(kind, v0 + h);
            tm.set(kind, v0 - h);
            let fd =
                (ExactStep::full_phi(&tp, w, dt) - ExactStep::full_phi(&tm, w, dt)) / (2.0 * h);
            let scale = fd.abs().max();
            for r in 0..4 {
                for c in 0..6 {
                    let err = (st.dphi[j][r][c] - fd[(r, c)]).abs();
                    assert!(
                        err <= 1e-7 * scale + 100.0 * f64::EPSILON / h,
                        "{}: dPhi[{r}][{c}] = {} vs {}",
                        kind.name(),
                        st.dphi[j][r][c],
                        fd[(r, c)]
                    );
                }
            }
        }
    }

    /// The balanced exponentials are the plain ones to rounding, on a step of one sample
    /// and on one of 27 (longer than the adequacy verdict's longest at table1's natural
    /// frequency, 26), where A dt reaches ~230 in the plain state.
    #[test]
    fn balanced_steps_are_the_plain_ones() {
        let w = 125.0;
        let (t0, cols) = cross_coupled();
        let osc = [[0.0, 1.0]];
        for dt in [1e-4, 27e-4] {
            let plain = ExactStep::new(&t0, &cols, w, dt, &osc, false);
            let bal = ExactStep::new(&t0, &cols, w, dt, &osc, true);
            let close = |a: &[[f64; 6]; 4], b: &[[f64; 6]; 4], what: &str| {
                let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                for r in 0..4 {
                    for c in 0..6 {
                        assert!(
                            (a[r][c] - b[r][c]).abs() <= 1e-11 * scale,
                            "{what} dt {dt}: [{r}][{c}] {} vs {}",
                            a[r][c],
                            b[r][c]
                        );
                    }
                }
            };
            close(&plain.phi, &bal.phi, "Phi");
            for (j, &kind) in cols.kinds()[..cols.nphys].iter().enumerate() {
                close(&plain.dphi[j], &bal.dphi[j], kind.name());
            }
        }
    }
}
