//! The synchronous (1X) response of any rotor description ([`RotorDescription`]) along a
//! measured speed history, with its sensitivities to the description's parameters: the
//! model side of the mode fit ([`super::modes`], docs/transient.md section 6).
//!
//! The description's equation (module doc of [`crate::model::description`]) driven by
//! its unbalance load, with the response written as a slowly turning vector times the
//! shaft's rotation, s = W e^{i phi} (the 1X vector W, in the convention of
//! [`super::order`]: the signal is Re(W e^{i phi})), becomes
//!
//! ```text
//! M W'' + (C + w G + 2 i w M) W' + (K + w' Ka + (i w' - w^2) M + i w (C + w G)) W = (w^2 - i w') P
//! ```
//!
//! an equation in W alone, whose coefficients follow the speed w(t) and acceleration
//! w'(t). On a sweep it carries what the steady-state formula lacks: the lag of the
//! response behind a speed that moves through a resonance, and the free vibration a
//! resonance leaves behind (in W it turns at the difference of its frequency and the
//! speed). Integrated by the classical Runge-Kutta method, `substeps` steps per point,
//! with the forward sensitivities dW/dth_j (the same equation, driven by the derivative
//! of the matrices and load). Each point's vector is what the order tracking's
//! per-revolution fit makes of the signal Re(W e^{i psi}) over its interval (a revolution
//! or a speed bin): the mean of W plus the mean of conj(W) e^{-2 i psi} ([`Synchronous`]),
//! integrals taken by the same Runge-Kutta stages.
//! The speed between the points' middles is linear (w' constant per stretch); the start,
//! and any restart after a gap longer than two intervals, is the quasi-steady response
//! (W' = 0) at that speed and acceleration.
//!
//! Without times (a Bode table) the points are steady states: W = A(w)^-1 w^2 P with
//! A(w) = K - w^2 M + i w (C + w G), the response of the steady-state formula.

use std::f64::consts::TAU;

use nalgebra::{Complex, DMatrix, DVector};

use super::error::{check_finite, same_length, TransientError};
use super::order::C64;
use crate::model::description::{Derivative, DescriptionError, RotorDescription};
use crate::model::OutOfRange;

/// The points at which the 1X response is wanted.
#[derive(Debug, Clone, PartialEq)]
pub enum Sweep {
    /// A transient: each point's interval (t_start, t_end) \[s\], in time order, and the
    /// shaft speed at its middle \[rad/s\].
    Transient {
        /// Each point's interval \[s\].
        intervals: Vec<(f64, f64)>,
        /// The speed at each interval's middle \[rad/s\].
        speed: Vec<f64>,
    },
    /// Steady states at these speeds \[rad/s\] (a table without times).
    Steady {
        /// The speeds \[rad/s\].
        speed: Vec<f64>,
    },
}

impl Sweep {
    /// The points' speeds \[rad/s\].
    pub fn speed(&self) -> &[f64] {
        match self {
            Sweep::Transient { speed, .. } | Sweep::Steady { speed } => speed,
        }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.speed().len()
    }

    /// True without points.
    pub fn is_empty(&self) -> bool {
        self.speed().is_empty()
    }

    /// The sweep of the points `range` only.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Sweep {
        match self {
            Sweep::Transient { intervals, speed } => Sweep::Transient {
                intervals: intervals[range.clone()].to_vec(),
                speed: speed[range].to_vec(),
            },
            Sweep::Steady { speed } => Sweep::Steady {
                speed: speed[range].to_vec(),
            },
        }
    }

    /// Finite speeds > 0; intervals finite, each of positive length, in time order and
    /// not overlapping.
    pub fn validate(&self) -> Result<(), TransientError> {
        check_finite("speed", self.speed())?;
        if let Some(i) = self.speed().iter().position(|&w| w <= 0.0) {
            return Err(OutOfRange {
                field: "speed",
                value: self.speed()[i],
                allowed: "> 0 rad/s at every point of a mode fit",
            }
            .into());
        }
        if let Sweep::Transient { intervals, speed } = self {
            same_length("intervals", intervals.len(), "speed", speed.len())?;
            let starts: Vec<f64> = intervals.iter().map(|i| i.0).collect();
            let ends: Vec<f64> = intervals.iter().map(|i| i.1).collect();
            check_finite("t_start", &starts)?;
            check_finite("t_end", &ends)?;
            for (k, &(a, b)) in intervals.iter().enumerate() {
                let prev_end = if k > 0 { intervals[k - 1].1 } else { a };
                if b <= a || a < prev_end - 1e-9 * b.abs().max(1.0) {
                    return Err(OutOfRange {
                        field: "t_start",
                        value: a,
                        allowed: "points in time order, each interval of positive length, not overlapping the one before",
                    }
                    .into());
                }
            }
        }
        Ok(())
    }
}

/// The 1X response of the description's channels at each point, and its derivatives.
///
/// A channel's signal Re(W e^{i psi}) over one revolution has the Fourier coefficient
/// (the order tracking's 1X vector) `response + conjugate`: the mean of W and the mean
/// of conj(W) e^{-2 i psi}, which is not zero when W changes within the revolution (a
/// vector turning by some degrees per revolution through a resonance). A channel with
/// an unknown complex gain a (a fit's share of a mode) has the vector
/// `a response + conj(a) conjugate`.
#[derive(Debug, Clone, PartialEq)]
pub struct Synchronous {
    /// `response[point][channel]`: the mean of W over the point's interval (the steady
    /// vector without times) \[channel unit\].
    pub response: Vec<Vec<C64>>,
    /// `conjugate[point][channel]`: the mean of conj(W) e^{-2 i psi} (zero without
    /// times) \[channel unit\].
    pub conjugate: Vec<Vec<C64>>,
    /// `sensitivity[j][point][channel]`: the derivative of `response` with respect to
    /// th_j (empty when not asked for).
    pub sensitivity: Vec<Vec<Vec<C64>>>,
    /// The derivative of `conjugate` likewise.
    pub conjugate_sensitivity: Vec<Vec<Vec<C64>>>,
}

/// A description's matrices premultiplied by M^-1, complex, at one th.
struct Premultiplied {
    c: DMatrix<C64>,
    g: DMatrix<C64>,
    k: DMatrix<C64>,
    ka: DMatrix<C64>,
    p: DVector<C64>,
    /// Per parameter: M^-1 times its derivatives (None where the matrix does not depend
    /// on it).
    d: Vec<DerivativeM>,
}

struct DerivativeM {
    m: Option<DMatrix<C64>>,
    c: Option<DMatrix<C64>>,
    g: Option<DMatrix<C64>>,
    k: Option<DMatrix<C64>>,
    ka: Option<DMatrix<C64>>,
    p: Option<DVector<C64>>,
}

fn cplx(m: &DMatrix<f64>) -> DMatrix<C64> {
    m.map(|v| Complex::new(v, 0.0))
}

impl Premultiplied {
    fn new(
        desc: &dyn RotorDescription,
        theta: &DVector<f64>,
        sensitivities: bool,
    ) -> Result<Self, TransientError> {
        let mx = desc.matrices(theta).map_err(description)?;
        let load = desc.load(theta).map_err(description)?;
        let n = desc.coordinates();
        let lu = cplx(&mx.mass).lu();
        let inv = lu.try_inverse().ok_or_else(|| {
            TransientError::ModelResponse("the model's mass matrix M is singular".into())
        })?;
        let pm = |m: &DMatrix<f64>| &inv * cplx(m);
        let pmo = |m: &Option<DMatrix<f64>>| m.as_ref().map(|m| &inv * cplx(m));
        let mut d = Vec::new();
        if sensitivities {
            for j in 0..desc.parameters().len() {
                let Derivative {
                    mass,
                    damping,
                    gyroscopic,
                    stiffness,
                    acceleration,
                    load,
                } = desc.derivative(theta, j).map_err(description)?;
                d.push(DerivativeM {
                    m: pmo(&mass),
                    c: pmo(&damping),
                    g: pmo(&gyroscopic),
                    k: pmo(&stiffness),
                    ka: pmo(&acceleration),
                    p: load.map(|l| &inv * l),
                });
            }
        }
        debug_assert_eq!(inv.nrows(), n);
        Ok(Self {
            c: pm(&mx.damping),
            g: pm(&mx.gyroscopic),
            k: pm(&mx.stiffness),
            ka: pm(&mx.acceleration),
            p: &inv * load,
            d,
        })
    }

    /// A1 = M^-1 (C + w G) + 2 i w I and A0 = (i w' - w^2) I + i w M^-1 (C + w G) +
    /// M^-1 (K + w' Ka): W'' = b - A1 W' - A0 W.
    fn coefficients(&self, w: f64, wd: f64) -> (DMatrix<C64>, DMatrix<C64>) {
        let n = self.c.nrows();
        let mut a1 = DMatrix::zeros(n, n);
        let mut a0 = DMatrix::zeros(n, n);
        self.coefficients_into(w, wd, &mut a1, &mut a0);
        (a1, a0)
    }

    /// [`Premultiplied::coefficients`] into `a1`, `a0` (n x n), without allocating: the
    /// right-hand side's hot path. Element by element the same operations in the same
    /// order as the matrix expressions (identity entries 1 and 0 included), so the
    /// results are the same to the bit.
    fn coefficients_into(&self, w: f64, wd: f64, a1: &mut DMatrix<C64>, a0: &mut DMatrix<C64>) {
        let n = self.c.nrows();
        let (iw2, sq, iw, wd_c) = (
            Complex::new(0.0, 2.0 * w),
            Complex::new(-w * w, wd),
            Complex::new(0.0, w),
            Complex::new(wd, 0.0),
        );
        let wc = Complex::new(w, 0.0);
        for c in 0..n {
            for r in 0..n {
                let e = Complex::new(if r == c { 1.0 } else { 0.0 }, 0.0);
                let cw = self.c[(r, c)] + self.g[(r, c)] * wc;
                a1[(r, c)] = cw + e * iw2;
                a0[(r, c)] = e * sq + cw * iw + self.k[(r, c)] + self.ka[(r, c)] * wd_c;
            }
        }
    }
}

fn description(e: DescriptionError) -> TransientError {
    TransientError::Description(e)
}

/// The speed history through the points' middles (linear between them, the end
/// stretches extended).
struct History {
    t: Vec<f64>,
    w: Vec<f64>,
    /// The shaft angle at each t \[rad\] from the first (the trapezoid rule, exact on a
    /// linear speed).
    angle: Vec<f64>,
    /// The stretch of the last look-up ([`History::stretch`]): the integration asks for
    /// times in order, so the next one is nearly always in it or the one after.
    last: std::cell::Cell<usize>,
}

impl History {
    fn new(t: Vec<f64>, w: Vec<f64>) -> Self {
        let mut angle = vec![0.0; t.len()];
        for i in 1..t.len() {
            angle[i] = angle[i - 1] + 0.5 * (w[i - 1] + w[i]) * (t[i] - t[i - 1]);
        }
        Self {
            t,
            w,
            angle,
            last: std::cell::Cell::new(1),
        }
    }

    /// The stretch `i` (from point `i - 1` to point `i`, 1 <= i <= n - 1, the end
    /// stretches extended) holding `t`: `partition_point(x <= t)` clamped to 1..n-1, found
    /// from the last look-up's stretch or the one after it before searching.
    fn stretch(&self, t: f64) -> usize {
        let n = self.t.len();
        let holds = |i: usize| (i == 1 || self.t[i - 1] <= t) && (i == n - 1 || t < self.t[i]);
        let last = self.last.get();
        let i = if last < n && holds(last) {
            last
        } else if last + 1 < n && holds(last + 1) {
            last + 1
        } else {
            self.t.partition_point(|&x| x <= t).clamp(1, n - 1)
        };
        self.last.set(i);
        i
    }

    /// The shaft angle at `t` \[rad\] (from the first point's middle).
    fn angle(&self, t: f64) -> f64 {
        let n = self.t.len();
        if n == 1 {
            return self.w[0] * (t - self.t[0]);
        }
        let i = self.stretch(t);
        let (t0, w0) = (self.t[i - 1], self.w[i - 1]);
        let slope = self.slope(i);
        let d = t - t0;
        self.angle[i - 1] + w0 * d + 0.5 * slope * d * d
    }

    /// The speed's slope between points `i - 1` and `i` \[rad/s^2\].
    fn slope(&self, i: usize) -> f64 {
        let (t0, t1) = (self.t[i - 1], self.t[i]);
        if t1 > t0 {
            (self.w[i] - self.w[i - 1]) / (t1 - t0)
        } else {
            0.0
        }
    }

    /// (w, w') at `t`.
    fn at(&self, t: f64) -> (f64, f64) {
        let n = self.t.len();
        if n == 1 {
            return (self.w[0], 0.0);
        }
        let i = self.stretch(t);
        let slope = self.slope(i);
        (self.w[i - 1] + slope * (t - self.t[i - 1]), slope)
    }
}

/// The state: W, W', then S_j, S_j' per parameter (each n complex).
struct Rhs<'a> {
    pre: &'a Premultiplied,
    history: &'a History,
    n: usize,
    /// Buffers of [`Rhs::eval`], reused from call to call.
    scratch: std::cell::RefCell<Scratch>,
}

/// [`Rhs::eval`]'s working memory: A1, A0 and three vectors of n.
struct Scratch {
    a1: DMatrix<C64>,
    a0: DMatrix<C64>,
    acc: Vec<C64>,
    f: Vec<C64>,
    e: Vec<C64>,
}

impl Scratch {
    fn new(n: usize) -> Self {
        let zero = Complex::new(0.0, 0.0);
        Self {
            a1: DMatrix::from_element(n, n, zero),
            a0: DMatrix::from_element(n, n, zero),
            acc: vec![zero; n],
            f: vec![zero; n],
            e: vec![zero; n],
        }
    }
}

fn mul_add(out: &mut [C64], m: &DMatrix<C64>, v: &[C64], scale: C64) {
    let n = v.len();
    for (r, o) in out.iter_mut().enumerate() {
        let mut s = Complex::new(0.0, 0.0);
        for c in 0..n {
            s += m[(r, c)] * v[c];
        }
        *o += s * scale;
    }
}

impl Rhs<'_> {
    fn eval(&self, t: f64, y: &[C64], dy: &mut [C64]) {
        let n = self.n;
        let (w, wd) = self.history.at(t);
        let mut guard = self.scratch.borrow_mut();
        let Scratch { a1, a0, acc, f, e } = &mut *guard;
        self.pre.coefficients_into(w, wd, a1, a0);
        let minus = Complex::new(-1.0, 0.0);
        let zero = Complex::new(0.0, 0.0);
        let force = Complex::new(w * w, -wd);
        // W' and W''
        let (wv, vv) = (&y[..n], &y[n..2 * n]);
        dy[..n].copy_from_slice(vv);
        for (a, p) in acc.iter_mut().zip(self.pre.p.iter()) {
            *a = p * force;
        }
        mul_add(acc, a1, vv, minus);
        mul_add(acc, a0, wv, minus);
        dy[n..2 * n].copy_from_slice(acc);
        let wdd = &*acc;
        for (j, d) in self.pre.d.iter().enumerate() {
            let base = 2 * n * (j + 1);
            let (s, u) = (&y[base..base + n], &y[base + n..base + 2 * n]);
            dy[base..base + n].copy_from_slice(u);
            f.fill(zero);
            if let Some(dp) = &d.p {
                for (fi, p) in f.iter_mut().zip(dp.iter()) {
                    *fi += p * force;
                }
            }
            if let Some(dm) = &d.m {
                // dM (W'' + 2 i w W' + (i w' - w^2) W)
                for (i, ei) in e.iter_mut().enumerate() {
                    *ei = wdd[i]
                        + vv[i] * Complex::new(0.0, 2.0 * w)
                        + wv[i] * Complex::new(-w * w, wd);
                }
                mul_add(f, dm, e, minus);
            }
            if d.c.is_some() || d.g.is_some() {
                // (dC + w dG) (W' + i w W)
                for (i, ei) in e.iter_mut().enumerate() {
                    *ei = vv[i] + wv[i] * Complex::new(0.0, w);
                }
                if let Some(dc) = &d.c {
                    mul_add(f, dc, e, minus);
                }
                if let Some(dg) = &d.g {
                    mul_add(f, dg, e, Complex::new(-w, 0.0));
                }
            }
            if let Some(dk) = &d.k {
                mul_add(f, dk, wv, minus);
            }
            if let Some(dka) = &d.ka {
                mul_add(f, dka, wv, Complex::new(-wd, 0.0));
            }
            mul_add(f, a1, u, minus);
            mul_add(f, a0, s, minus);
            dy[base + n..base + 2 * n].copy_from_slice(f);
        }
    }
}

/// The quasi-steady state at (w, w'): W = A^-1 (w^2 - i w') P with W' = 0, A = K + w' Ka +
/// (i w' - w^2) M + i w (C + w G) (M^-1 applied throughout), and its sensitivities.
fn quasi_steady(pre: &Premultiplied, w: f64, wd: f64, n: usize) -> Option<Vec<C64>> {
    let (_, a0) = pre.coefficients(w, wd);
    let lu = a0.lu();
    let force = Complex::new(w * w, -wd);
    let rhs = &pre.p * force;
    let wv = lu.solve(&rhs)?;
    let mut y = vec![Complex::new(0.0, 0.0); 2 * n * (pre.d.len() + 1)];
    y[..n].copy_from_slice(wv.as_slice());
    let zero = vec![Complex::new(0.0, 0.0); n];
    for (j, d) in pre.d.iter().enumerate() {
        let mut f = vec![Complex::new(0.0, 0.0); n];
        if let Some(dp) = &d.p {
            for (fi, p) in f.iter_mut().zip(dp.iter()) {
                *fi += p * force;
            }
        }
        let minus = Complex::new(-1.0, 0.0);
        let wsl = wv.as_slice();
        if let Some(dm) = &d.m {
            let e: Vec<C64> = wsl.iter().map(|x| x * Complex::new(-w * w, wd)).collect();
            mul_add(&mut f, dm, &e, minus);
        }
        let iw: Vec<C64> = wsl.iter().map(|x| x * Complex::new(0.0, w)).collect();
        if let Some(dc) = &d.c {
            mul_add(&mut f, dc, &iw, minus);
        }
        if let Some(dg) = &d.g {
            mul_add(&mut f, dg, &iw, Complex::new(-w, 0.0));
        }
        if let Some(dk) = &d.k {
            mul_add(&mut f, dk, wsl, minus);
        }
        if let Some(dka) = &d.ka {
            mul_add(&mut f, dka, wsl, Complex::new(-wd, 0.0));
        }
        let s = lu.solve(&DVector::from_vec(f))?;
        let base = 2 * n * (j + 1);
        y[base..base + n].copy_from_slice(s.as_slice());
        y[base + n..base + 2 * n].copy_from_slice(&zero);
    }
    Some(y)
}

/// The integrals a step accumulates: of the state, and of its conjugate times a carrier
/// (e^{-2 i psi(t)}, the negative-frequency half of the 1X cycle).
struct Integrals<'a, F: Fn(f64) -> C64> {
    state: &'a mut [C64],
    conjugate: &'a mut [C64],
    carrier: F,
}

/// One classical Runge-Kutta step of `h` from `t`; with `acc`, adds the step's integrals
/// of the state and of its conjugate times the carrier, by the same stages (Q' = y
/// integrated with y: fourth order, as the state).
fn rk4_step<F: Fn(f64) -> C64>(
    rhs: &Rhs,
    t: f64,
    h: f64,
    y: &mut [C64],
    k: &mut [Vec<C64>; 5],
    mut acc: Option<&mut Integrals<F>>,
) {
    let m = y.len();
    let half = Complex::new(0.5 * h, 0.0);
    let full = Complex::new(h, 0.0);
    let sixth = h / 6.0;
    let [k1, k2, k3, k4, tmp] = k;
    let mut add = |state: &[C64], tau: f64, weight: f64| {
        if let Some(acc) = acc.as_deref_mut() {
            let c = (acc.carrier)(tau) * weight;
            for ((a, b), v) in acc
                .state
                .iter_mut()
                .zip(acc.conjugate.iter_mut())
                .zip(state)
            {
                *a += v * weight;
                *b += v.conj() * c;
            }
        }
    };
    rhs.eval(t, y, k1);
    add(y, t, sixth);
    for i in 0..m {
        tmp[i] = y[i] + k1[i] * half;
    }
    rhs.eval(t + 0.5 * h, tmp, k2);
    add(tmp, t + 0.5 * h, 2.0 * sixth);
    for i in 0..m {
        tmp[i] = y[i] + k2[i] * half;
    }
    rhs.eval(t + 0.5 * h, tmp, k3);
    add(tmp, t + 0.5 * h, 2.0 * sixth);
    for i in 0..m {
        tmp[i] = y[i] + k3[i] * full;
    }
    rhs.eval(t + h, tmp, k4);
    add(tmp, t + h, sixth);
    for i in 0..m {
        y[i] += (k1[i] + (k2[i] + k3[i]) * 2.0 + k4[i]) * sixth;
    }
}

/// The channels H x of the coordinate vector `x` (n complex).
fn channels(h: &DMatrix<f64>, x: &[C64]) -> Vec<C64> {
    (0..h.nrows())
        .map(|r| (0..h.ncols()).map(|c| x[c] * h[(r, c)]).sum::<C64>())
        .collect()
}

/// The 1X response of `desc` at `theta` along `sweep` (module doc), with its
/// sensitivities when `sensitivities`; `substeps` Runge-Kutta steps per point (at least 1;
/// the error falls as substeps^-4; 16 keep it below 1e-6 of the peak response through a
/// mode with a damping ratio of 0.01 at a fast sweep, measured in the tests).
pub fn synchronous(
    desc: &dyn RotorDescription,
    theta: &DVector<f64>,
    sweep: &Sweep,
    substeps: usize,
    sensitivities: bool,
) -> Result<Synchronous, TransientError> {
    sweep.validate()?;
    let n = desc.coordinates();
    let np = if sensitivities {
        desc.parameters().len()
    } else {
        0
    };
    let pre = Premultiplied::new(desc, theta, sensitivities)?;
    let h_map = desc.output_map();
    let singular = |w: f64| {
        TransientError::ModelResponse(format!(
        "the model's dynamic stiffness is singular at {w} rad/s: an undamped mode at that speed has no steady response"
    ))
    };
    let mut response = Vec::with_capacity(sweep.len());
    let mut conjugate = Vec::with_capacity(sweep.len());
    let mut sensitivity = vec![Vec::with_capacity(sweep.len()); np];
    let mut conjugate_sensitivity = vec![Vec::with_capacity(sweep.len()); np];
    let zero = vec![Complex::new(0.0, 0.0); 2 * n * (np + 1)];
    let mut push = |state: &[C64], conj: Option<&[C64]>| {
        let conj = conj.unwrap_or(&zero);
        response.push(channels(h_map, &state[..n]));
        conjugate.push(channels(h_map, &conj[..n]));
        for j in 0..np {
            let base = 2 * n * (j + 1);
            sensitivity[j].push(channels(h_map, &state[base..base + n]));
            conjugate_sensitivity[j].push(channels(h_map, &conj[base..base + n]));
        }
    };
    match sweep {
        Sweep::Steady { speed } => {
            for &w in speed {
                let y = quasi_steady(&pre, w, 0.0, n).ok_or_else(|| singular(w))?;
                push(&y, None);
            }
        }
        Sweep::Transient { intervals, speed } => {
            let history = History::new(
                intervals.iter().map(|(a, b)| 0.5 * (a + b)).collect(),
                speed.clone(),
            );
            let rhs = Rhs {
                pre: &pre,
                history: &history,
                n,
                scratch: std::cell::RefCell::new(Scratch::new(n)),
            };
            let m = 2 * n * (np + 1);
            let mut k: [Vec<C64>; 5] = std::array::from_fn(|_| vec![Complex::new(0.0, 0.0); m]);
            let steps = substeps.max(1);
            let mut y: Vec<C64> = Vec::new();
            let mut t = f64::NEG_INFINITY;
            let mut mean = vec![Complex::new(0.0, 0.0); m];
            let mut mean_conj = vec![Complex::new(0.0, 0.0); m];
            for &(a, b) in intervals {
                let len = b - a;
                if !(t.is_finite() && a - t <= 2.0 * len) {
                    let (w, wd) = history.at(a);
                    y = quasi_steady(&pre, w, wd, n).ok_or_else(|| singular(w))?;
                    t = a;
                }
                // through a short gap to the interval's start
                if a > t {
                    let gap_steps = ((a - t) / len * steps as f64).ceil().max(1.0) as usize;
                    let h = (a - t) / gap_steps as f64;
                    for _ in 0..gap_steps {
                        rk4_step::<fn(f64) -> C64>(&rhs, t, h, &mut y, &mut k, None);
                        t += h;
                    }
                    t = a;
                }
                // the interval's means, by the same stages: of W, and of conj(W) e^{-2 i psi}
                // with psi the angle from the interval's start, 2 pi at its end
                let (phi_a, phi_b) = (history.angle(a), history.angle(b));
                let scale = TAU / (phi_b - phi_a);
                let h = len / steps as f64;
                mean.fill(Complex::new(0.0, 0.0));
                mean_conj.fill(Complex::new(0.0, 0.0));
                let mut acc = Integrals {
                    state: &mut mean,
                    conjugate: &mut mean_conj,
                    carrier: |tau: f64| {
                        Complex::from_polar(1.0, -2.0 * scale * (history.angle(tau) - phi_a))
                    },
                };
                for s in 0..steps {
                    rk4_step(&rhs, t, h, &mut y, &mut k, Some(&mut acc));
                    t = a + (s + 1) as f64 * h;
                }
                for (mi, ci) in mean.iter_mut().zip(mean_conj.iter_mut()) {
                    *mi /= len;
                    *ci /= len;
                }
                t = b;
                if y.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
                    return Err(TransientError::ModelResponse(format!(
                        "the model's response is not finite at t = {b} s (a mode with a damping ratio below 0?)"
                    )));
                }
                push(&mean, Some(&mean_conj));
            }
        }
    }
    Ok(Synchronous {
        response,
        conjugate,
        sensitivity,
        conjugate_sensitivity,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stretch found from the last look-up is the binary search's, for times in
    /// order, repeated, backwards, outside the points and at them.
    #[test]
    fn a_stretch_from_the_last_one_is_the_searched_one() {
        let t: Vec<f64> = vec![0.0, 0.1, 0.25, 0.25, 0.4, 0.7, 1.0];
        let h = History::new(t.clone(), vec![1.0; t.len()]);
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let mut queries: Vec<f64> = (0..=240).map(|k| -0.1 + k as f64 * 0.005).collect();
        queries.extend(t.iter().copied());
        queries.extend((0..200).map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 1.4 - 0.2
        }));
        for q in queries {
            let searched = t.partition_point(|&v| v <= q).clamp(1, t.len() - 1);
            assert_eq!(h.stretch(q), searched, "t = {q}");
        }
    }
    use crate::model::description::{ModalDescription, Mode};

    /// Revolutions of psi = w0 t + a t^2 / 2 from t = 0: their intervals and mid speeds.
    fn revolutions(w0: f64, a: f64, count: usize) -> (Vec<(f64, f64)>, Vec<f64>) {
        let time_at = |phi: f64| {
            if a == 0.0 {
                phi / w0
            } else {
                (-w0 + (w0 * w0 + 2.0 * a * phi).sqrt()) / a
            }
        };
        let edges: Vec<f64> = (0..=count).map(|k| time_at(TAU * k as f64)).collect();
        let intervals: Vec<(f64, f64)> = edges.windows(2).map(|e| (e[0], e[1])).collect();
        let speed = intervals
            .iter()
            .map(|(s, e)| w0 + a * 0.5 * (s + e))
            .collect();
        (intervals, speed)
    }

    /// The fixed-frame response s'' + c s' + k s = (w^2 - i a) e^{i phi} by fine RK4 from
    /// the quasi-steady state, averaged as s e^{-i phi} over each interval: a different
    /// frame and step from `synchronous`.
    fn fixed_frame(k: f64, c: f64, w0: f64, a: f64, intervals: &[(f64, f64)]) -> Vec<C64> {
        let f = |t: f64, s: C64, v: C64| -> (C64, C64) {
            let w = w0 + a * t;
            let phi = w0 * t + 0.5 * a * t * t;
            let force = Complex::new(w * w, -a) * Complex::from_polar(1.0, phi);
            (v, force - v * c - s * k)
        };
        // quasi-steady start: W0 = (w^2 - i a) / (k - w^2 + i a + i w c)
        let w = w0;
        let w_0 = Complex::new(w * w, -a) / Complex::new(k - w * w, a + w * c);
        let (mut s, mut v) = (w_0, w_0 * Complex::new(0.0, w));
        let mut t = 0.0;
        let mut out = Vec::new();
        for &(t0, t1) in intervals {
            let steps = 400;
            let h = (t1 - t0) / steps as f64;
            let demod = |t: f64, s: C64| s * Complex::from_polar(1.0, -(w0 * t + 0.5 * a * t * t));
            let mut acc = demod(t, s) * 0.5;
            for i in 0..steps {
                let (k1s, k1v) = f(t, s, v);
                let (k2s, k2v) = f(t + h / 2.0, s + k1s * (h / 2.0), v + k1v * (h / 2.0));
                let (k3s, k3v) = f(t + h / 2.0, s + k2s * (h / 2.0), v + k2v * (h / 2.0));
                let (k4s, k4v) = f(t + h, s + k3s * h, v + k3v * h);
                s += (k1s + (k2s + k3s) * 2.0 + k4s) * (h / 6.0);
                v += (k1v + (k2v + k3v) * 2.0 + k4v) * (h / 6.0);
                t = t0 + (i + 1) as f64 * h;
                acc += demod(t, s) * if i + 1 == steps { 0.5 } else { 1.0 };
            }
            out.push(acc / steps as f64);
        }
        out
    }

    #[test]
    fn a_run_up_through_a_mode_matches_the_fixed_frame_solution() {
        // w_n = 300 rad/s, zeta = 0.01, from 150 rad/s at 40 rad/s^2 through the resonance
        let mode = Mode {
            omega: 300.0,
            zeta: 0.01,
        };
        let desc = ModalDescription::new(&[mode]).unwrap();
        let theta = desc.nominal().clone();
        let (w0, a) = (150.0, 40.0);
        let (intervals, speed) = revolutions(w0, a, 260);
        assert!(*speed.last().unwrap() > 1.3 * mode.omega);
        let reference = fixed_frame(theta[0], theta[1], w0, a, &intervals);
        let sweep = Sweep::Transient { intervals, speed };
        let got = synchronous(&desc, &theta, &sweep, 16, false).unwrap();
        let peak = reference.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let worst = got
            .response
            .iter()
            .zip(&reference)
            .map(|(g, r)| (g[0] - r).norm())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6 * peak, "worst {worst:e} of peak {peak:e}");
        // and the sweep's lag is there: the transient peak is not the steady one's
        let steady = synchronous(
            &desc,
            &theta,
            &Sweep::Steady {
                speed: sweep.speed().to_vec(),
            },
            1,
            false,
        )
        .unwrap();
        let argmax = |v: &[Vec<C64>]| {
            (0..v.len())
                .max_by(|&i, &j| v[i][0].norm().total_cmp(&v[j][0].norm()))
                .unwrap()
        };
        assert!(argmax(&got.response) > argmax(&steady.response));
    }

    #[test]
    fn steady_states_are_the_closed_form() {
        let desc = ModalDescription::new(&[
            Mode {
                omega: 200.0,
                zeta: 0.02,
            },
            Mode {
                omega: 500.0,
                zeta: 0.05,
            },
        ])
        .unwrap();
        let theta = desc.nominal().clone();
        let speed: Vec<f64> = (1..40).map(|i| 20.0 * i as f64).collect();
        let got = synchronous(
            &desc,
            &theta,
            &Sweep::Steady {
                speed: speed.clone(),
            },
            1,
            false,
        )
        .unwrap();
        for (r, &w) in got.response.iter().zip(&speed) {
            for j in 0..2 {
                let (k, c) = (theta[2 * j], theta[2 * j + 1]);
                let want = Complex::new(w * w, 0.0) / Complex::new(k - w * w, c * w);
                assert!((r[j] - want).norm() <= 1e-12 * want.norm());
            }
        }
        // at a constant speed the transient stays on the steady state
        let (intervals, speed) = revolutions(350.0, 0.0, 50);
        let got = synchronous(
            &desc,
            &theta,
            &Sweep::Transient { intervals, speed },
            16,
            false,
        )
        .unwrap();
        let want = Complex::new(350.0f64.powi(2), 0.0)
            / Complex::new(theta[0] - 350.0f64.powi(2), theta[1] * 350.0);
        for r in &got.response {
            assert!((r[0] - want).norm() <= 1e-9 * want.norm());
        }
    }

    #[test]
    fn sensitivities_match_finite_differences() {
        let desc = ModalDescription::new(&[
            Mode {
                omega: 300.0,
                zeta: 0.02,
            },
            Mode {
                omega: 420.0,
                zeta: 0.04,
            },
        ])
        .unwrap();
        let theta = desc.nominal().clone();
        let (intervals, speed) = revolutions(200.0, 60.0, 200);
        for sweep in [
            Sweep::Transient {
                intervals,
                speed: speed.clone(),
            },
            Sweep::Steady { speed },
        ] {
            let got = synchronous(&desc, &theta, &sweep, 16, true).unwrap();
            for j in 0..theta.len() {
                let h = 1e-6 * theta[j];
                let mut tp = theta.clone();
                tp[j] += h;
                let mut tm = theta.clone();
                tm[j] -= h;
                let p = synchronous(&desc, &tp, &sweep, 16, false).unwrap();
                let m = synchronous(&desc, &tm, &sweep, 16, false).unwrap();
                let scale = got.sensitivity[j]
                    .iter()
                    .map(|v| v[j / 2].norm())
                    .fold(0.0, f64::max);
                for r in 0..sweep.len() {
                    for ch in 0..2 {
                        let fd = (p.response[r][ch] - m.response[r][ch]) / (2.0 * h);
                        let e = (got.sensitivity[j][r][ch] - fd).norm();
                        assert!(
                            e <= 1e-5 * scale,
                            "param {j} point {r} channel {ch}: {e:e} of {scale:e}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn bad_sweeps_are_refused_by_name() {
        let desc = ModalDescription::new(&[Mode {
            omega: 300.0,
            zeta: 0.02,
        }])
        .unwrap();
        let theta = desc.nominal().clone();
        let e = synchronous(
            &desc,
            &theta,
            &Sweep::Steady {
                speed: vec![100.0, -1.0],
            },
            1,
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("speed"), "{e}");
        let e = synchronous(
            &desc,
            &theta,
            &Sweep::Transient {
                intervals: vec![(0.0, 0.1), (0.05, 0.2)],
                speed: vec![60.0, 60.0],
            },
            4,
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("time order"), "{e}");
        let e = synchronous(
            &desc,
            &DVector::from_vec(vec![1.0]),
            &Sweep::Steady { speed: vec![1.0] },
            1,
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("theta has 1"), "{e}");
    }
}
