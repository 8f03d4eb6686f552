//! Running (cumulative) quadrature for the iterated integrals of docs/method.md section 3.1
//! (the rules: section 3.5):
//!
//! ```text
//! I1[f](t_n) = integral_{t_0}^{t_n} f,      Ik[f] = I1[I(k-1)[f]],   k = 1..4
//! ```
//!
//! on a uniform grid t_n = t_0 + n h. Level k is integrated from the values of level k - 1
//! at the nodes (a cascade), so each level carries the rule's order of accuracy. The
//! Jeffcott identifier needs I1..I4 ([`LEVELS`], the default); the cross-coupled one
//! I1..I6 ([`RunningIntegrals`]'s second parameter, the number of rows R = levels + 1).
//!
//! ## Rules (Adams-Moulton, Hairer, Nørsett & Wanner, *Solving ODEs I*, section III.1)
//!
//! Every step adds one interval, using the new node and the q - 1 before it:
//!
//! ```text
//! I(t_{n+1}) = I(t_n) + h * sum_{i=0}^{q-1} beta_i f_{n+1-i}
//!
//! Trapezoid     (q = 2, order 2):  beta = (1, 1) / 2                         error -h^3 f''/12
//! AdamsMoulton3 (q = 3, order 3):  beta = (5, 8, -1) / 12                    error -h^4 f'''/24
//! AdamsMoulton4 (q = 4, order 4):  beta = (9, 19, -5, 1) / 24                error -19 h^5 f''''/720
//! AdamsMoulton5 (q = 5, order 5):  beta = (251, 646, -264, 106, -19) / 720   error -3 h^6 f^(5)/160
//! ```
//!
//! (per-step local errors; over a fixed span the global error is O(h^order)). Each rule
//! integrates the polynomial of degree q - 1 through the q newest nodes over the newest
//! interval, and uses only samples up to the current one (causal, streaming).
//!
//! ## Start-up
//!
//! Until q nodes exist the rule has no stencil. Instead of falling back to lower-order
//! rules (whose first-interval error, O(h^3) for the trapezoid, stays in every later value
//! as a constant offset of I1, a ramp in I2, ... and is not small when the initial
//! displacement or velocity is not zero), the first q - 1 steps recompute every level at
//! every node so far from the polynomial through all nodes so far (Newton-Cotes weights
//! `integral_0^j L_i`, L_i the Lagrange basis on nodes 0..m-1). Values at nodes 1..q-2 are
//! provisional (fewer nodes); at node q - 1 all of them are recomputed from the q-node
//! interpolant, so no interval stays integrated by a lower-order rule.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::error::AlgebraicError;
use crate::model::check;

/// Number of iterated-integral levels kept by [`RunningIntegrals`] by default (I1 to I4,
/// what the 3x3 system of docs/method.md section 3.4 needs).
pub const LEVELS: usize = 4;

/// The running quadrature rule used for every iterated integral.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Quadrature {
    /// Cumulative trapezoid rule, order 2 (what the paper's results suggest; for
    /// comparison): `h (f_{n+1} + f_n) / 2`.
    #[serde(rename = "trapezoid")]
    Trapezoid,
    /// Adams-Moulton 2-step, order 3: `h (5 f_{n+1} + 8 f_n - f_{n-1}) / 12`.
    #[serde(rename = "am3")]
    AdamsMoulton3,
    /// Adams-Moulton 3-step, order 4: `h (9 f_{n+1} + 19 f_n - 5 f_{n-1} + f_{n-2}) / 24`.
    #[serde(rename = "am4")]
    AdamsMoulton4,
    /// Adams-Moulton 4-step, order 5 (the default):
    /// `h (251 f_{n+1} + 646 f_n - 264 f_{n-1} + 106 f_{n-2} - 19 f_{n-3}) / 720`.
    #[default]
    #[serde(rename = "am5")]
    AdamsMoulton5,
}

const TRAPEZOID: [f64; 2] = [0.5, 0.5];
const AM3: [f64; 3] = [5.0 / 12.0, 8.0 / 12.0, -1.0 / 12.0];
const AM4: [f64; 4] = [9.0 / 24.0, 19.0 / 24.0, -5.0 / 24.0, 1.0 / 24.0];
const AM5: [f64; 5] = [
    251.0 / 720.0,
    646.0 / 720.0,
    -264.0 / 720.0,
    106.0 / 720.0,
    -19.0 / 720.0,
];

impl Quadrature {
    /// Every rule, lowest order first.
    pub const ALL: [Quadrature; 4] = [
        Quadrature::Trapezoid,
        Quadrature::AdamsMoulton3,
        Quadrature::AdamsMoulton4,
        Quadrature::AdamsMoulton5,
    ];

    /// The name used on the command line: `trapezoid`, `am3`, `am4`, `am5` (the digit is the
    /// order).
    pub fn name(self) -> &'static str {
        match self {
            Quadrature::Trapezoid => "trapezoid",
            Quadrature::AdamsMoulton3 => "am3",
            Quadrature::AdamsMoulton4 => "am4",
            Quadrature::AdamsMoulton5 => "am5",
        }
    }

    /// Order of accuracy p: the global error over a fixed span is O(h^p).
    pub fn order(self) -> usize {
        self.weights().len()
    }

    /// The weights beta_0 (newest node) .. beta_{q-1} of one step, `h sum beta_i f_{n+1-i}`;
    /// they sum to 1. The stencil has q = `weights().len()` nodes.
    pub fn weights(self) -> &'static [f64] {
        match self {
            Quadrature::Trapezoid => &TRAPEZOID,
            Quadrature::AdamsMoulton3 => &AM3,
            Quadrature::AdamsMoulton4 => &AM4,
            Quadrature::AdamsMoulton5 => &AM5,
        }
    }
}

impl fmt::Display for Quadrature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Quadrature {
    type Err = AlgebraicError;
    /// Parse `trapezoid`, `am3`, `am4` or `am5` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.trim().to_ascii_lowercase();
        Quadrature::ALL
            .into_iter()
            .find(|q| q.name() == lower)
            .ok_or_else(|| AlgebraicError::UnknownQuadrature {
                name: s.to_string(),
            })
    }
}

/// `integral_0^j L_i(s) ds` for the Lagrange basis L_0..L_{m-1} on the nodes 0, 1, .., m-1
/// (unit spacing), for j = 0..m-1 and i = 0..m-1, written into `w[j][i]` (m <= Q <= 8;
/// each weight correctly rounded).
/// These are the Newton-Cotes weights of the start-up (module docs); row j = m - 1 of
/// m = q nodes is the Adams-Moulton rule with its weights in reverse order.
pub fn lagrange_cumulative_weights<const Q: usize>(m: usize) -> [[f64; Q]; Q] {
    // Exact integer arithmetic, one rounding per weight: the numerator polynomial
    // prod_{k != i} (s - k) has integer coefficients c_p, and
    // integral_0^j s^p ds = j^(p+1) / (p+1) = j^(p+1) (L / (p+1)) / L with L a common
    // multiple of 1..=Q (Q <= 8 keeps every integer far below 2^63).
    assert!(Q <= 8, "stencils of more than 8 nodes are not supported");
    let lcm: i64 = 840; // lcm(1..=8)
    let mut w = [[0.0; Q]; Q];
    let m = m.min(Q);
    for i in 0..m {
        let mut poly = [0i64; Q];
        poly[0] = 1;
        let mut deg = 0;
        let mut denom: i64 = 1;
        for k in (0..m).filter(|&k| k != i) {
            // poly *= (s - k)
            for p in (0..=deg + 1).rev() {
                let shifted = if p > 0 { poly[p - 1] } else { 0 };
                let here = if p <= deg { poly[p] } else { 0 };
                poly[p] = shifted - k as i64 * here;
            }
            deg += 1;
            denom *= i as i64 - k as i64;
        }
        for (j, row) in w.iter_mut().enumerate().take(m) {
            let x = j as i64;
            let mut xp = x;
            let mut num: i64 = 0;
            for (p, c) in poly.iter().enumerate().take(deg + 1) {
                num += c * xp * (lcm / (p as i64 + 1));
                xp *= x;
            }
            row[i] = num as f64 / (lcm * denom) as f64;
        }
    }
    w
}

/// The cascade for a stencil of Q nodes: a ring of the last Q nodes, each holding the
/// integrand (level 0) and levels 1..R-1 for NS signals.
#[derive(Debug, Clone)]
struct Cascade<const NS: usize, const Q: usize, const R: usize> {
    ring: [[[f64; NS]; R]; Q],
    /// Slot of the newest node.
    head: usize,
    /// Nodes pushed so far.
    nodes: u64,
    /// `step[r][s]`: h beta_age for the node in slot s when the new node is in slot r,
    /// age = (r - s) mod Q (`step[r][r]`, the new node's, is unused: see `beta0_h`).
    step: [[f64; Q]; Q],
    /// h beta_0.
    beta0_h: f64,
    /// `start[m - 1][j][i]`: h integral_0^j L_i on m nodes (start-up, m = 1..=Q).
    start: [[[f64; Q]; Q]; Q],
}

impl<const NS: usize, const Q: usize, const R: usize> Cascade<NS, Q, R> {
    fn new(beta: &[f64], h: f64) -> Self {
        debug_assert!(beta.len() == Q && Q <= 5);
        const { assert!(R >= 2, "at least one level of integrals") };
        let mut step = [[0.0; Q]; Q];
        for (r, row) in step.iter_mut().enumerate() {
            for (s, c) in row.iter_mut().enumerate() {
                let age = (r + Q - s) % Q;
                *c = h * beta[age];
            }
        }
        let mut start = [[[0.0; Q]; Q]; Q];
        for (m1, table) in start.iter_mut().enumerate() {
            let w = lagrange_cumulative_weights::<Q>(m1 + 1);
            for (trow, wrow) in table.iter_mut().zip(w.iter()) {
                for (t, v) in trow.iter_mut().zip(wrow.iter()) {
                    *t = h * v;
                }
            }
        }
        Self {
            ring: [[[0.0; NS]; R]; Q],
            head: 0,
            nodes: 0,
            step,
            beta0_h: h * beta[0],
            start,
        }
    }

    fn reset(&mut self) {
        self.ring = [[[0.0; NS]; R]; Q];
        self.head = 0;
        self.nodes = 0;
    }

    #[inline]
    fn levels(&self) -> &[[f64; NS]; R] {
        &self.ring[self.head]
    }

    #[inline(always)]
    fn push(&mut self, f: &[f64; NS]) {
        if self.nodes >= Q as u64 {
            self.step_regular(f);
        } else {
            self.step_startup(f);
        }
        self.nodes += 1;
    }

    /// Node m - 1 < Q: recompute every level at nodes 1..m-1 from the interpolant through
    /// nodes 0..m-1 (slots 0..m-1; no wrap-around yet).
    #[cold]
    fn step_startup(&mut self, f: &[f64; NS]) {
        let last = self.nodes as usize; // index of the new node
        self.head = last;
        self.ring[last] = [[0.0; NS]; R];
        self.ring[last][0] = *f;
        let w = self.start[last];
        for k in 1..R {
            for (j, wj) in w.iter().enumerate().take(last + 1).skip(1) {
                let mut acc = [0.0; NS];
                for (i, wi) in wj.iter().enumerate().take(last + 1) {
                    let src = &self.ring[i][k - 1];
                    for (a, s) in acc.iter_mut().zip(src.iter()) {
                        *a += wi * s;
                    }
                }
                self.ring[j][k] = acc;
            }
        }
    }

    /// The Adams-Moulton step: level k at the new node = level k at the previous node +
    /// h sum_i beta_i (level k - 1 at node n + 1 - i). Dispatches on the ring phase so
    /// that slot indices are compile-time constants in [`Self::step_phase`].
    #[inline(always)]
    fn step_regular(&mut self, f: &[f64; NS]) {
        let r = if self.head + 1 == Q { 0 } else { self.head + 1 };
        match r {
            0 => self.step_phase::<0>(f),
            1 => self.step_phase::<1>(f),
            2 => self.step_phase::<2>(f),
            3 => self.step_phase::<3>(f),
            _ => self.step_phase::<4>(f),
        }
    }

    /// One step with the new node going to slot SLOT (< Q; Q <= 5), in chunks of 4 signals
    /// (SIMD lanes; a scalar loop takes the NS % 4 left over). For each level: the sum
    /// over the q - 1 older nodes first, then the newest node's term.
    #[inline(always)]
    fn step_phase<const SLOT: usize>(&mut self, f: &[f64; NS]) {
        const W: usize = 4;
        let r = SLOT % Q; // SLOT < Q always; the modulo only keeps unused arms in bounds
        let old = (r + Q - 1) % Q;
        self.head = r;
        let c = self.step[r];
        let c_new = self.beta0_h;
        let ring = &mut self.ring;
        let full = NS / W * W;
        for base in (0..full).step_by(W) {
            let mut below: [f64; W] = std::array::from_fn(|l| f[base + l]);
            ring[r][0][base..base + W].copy_from_slice(&below);
            for k in 1..R {
                let mut acc: [f64; W] = std::array::from_fn(|l| ring[old][k][base + l]);
                for (s, cs) in c.iter().enumerate() {
                    if s != r {
                        let src = &ring[s][k - 1];
                        for l in 0..W {
                            acc[l] += cs * src[base + l];
                        }
                    }
                }
                for l in 0..W {
                    acc[l] += c_new * below[l];
                }
                ring[r][k][base..base + W].copy_from_slice(&acc);
                below = acc;
            }
        }
        for j in full..NS {
            let mut below = f[j];
            ring[r][0][j] = below;
            for k in 1..R {
                let mut acc = ring[old][k][j];
                for (s, cs) in c.iter().enumerate() {
                    if s != r {
                        acc += cs * ring[s][k - 1][j];
                    }
                }
                let v = acc + c_new * below;
                ring[r][k][j] = v;
                below = v;
            }
        }
    }
}

/// The cascade for each stencil size, stored inline (no indirection in the hot loop; the
/// largest variant is a few kB).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Engine<const NS: usize, const R: usize> {
    Q2(Cascade<NS, 2, R>),
    Q3(Cascade<NS, 3, R>),
    Q4(Cascade<NS, 4, R>),
    Q5(Cascade<NS, 5, R>),
}

/// Running iterated integrals I1..I(R-1) of NS signals sampled every h, with a selectable
/// [`Quadrature`]. O(NS q R) work and no allocation per sample. R, the number of rows
/// kept (the signals and R - 1 levels), is [`LEVELS`] + 1 = 5 unless given (the
/// cross-coupled identifier keeps 7: I1..I6).
///
/// ```
/// use rotorid::identify::algebraic::{Quadrature, RunningIntegrals};
/// let h = 1e-3;
/// let mut ri = RunningIntegrals::<1>::new(Quadrature::AdamsMoulton4, h).unwrap();
/// for n in 0..=1000 {
///     ri.push(&[(n as f64 * h).cos()]);
/// }
/// // I1[cos](1) = sin(1)
/// assert!((ri.levels()[1][0] - 1f64.sin()).abs() < 1e-13);
/// ```
#[derive(Debug, Clone)]
pub struct RunningIntegrals<const NS: usize, const R: usize = { LEVELS + 1 }> {
    quadrature: Quadrature,
    h: f64,
    engine: Engine<NS, R>,
}

impl<const NS: usize, const R: usize> RunningIntegrals<NS, R> {
    /// Integrals of signals sampled every `h` \[s\] (finite, > 0) with `quadrature`.
    pub fn new(quadrature: Quadrature, h: f64) -> Result<Self, AlgebraicError> {
        check("dt", h, "finite and > 0 (s)", |v| v > 0.0)?;
        let beta = quadrature.weights();
        let engine = match quadrature {
            Quadrature::Trapezoid => Engine::Q2(Cascade::new(beta, h)),
            Quadrature::AdamsMoulton3 => Engine::Q3(Cascade::new(beta, h)),
            Quadrature::AdamsMoulton4 => Engine::Q4(Cascade::new(beta, h)),
            Quadrature::AdamsMoulton5 => Engine::Q5(Cascade::new(beta, h)),
        };
        Ok(Self {
            quadrature,
            h,
            engine,
        })
    }

    /// The rule in use.
    pub fn quadrature(&self) -> Quadrature {
        self.quadrature
    }

    /// The step h \[s\].
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Number of samples pushed since construction or [`reset`](Self::reset).
    pub fn len(&self) -> u64 {
        match &self.engine {
            Engine::Q2(c) => c.nodes,
            Engine::Q3(c) => c.nodes,
            Engine::Q4(c) => c.nodes,
            Engine::Q5(c) => c.nodes,
        }
    }

    /// True before the first sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Forget every sample: the next one pushed becomes t_0.
    pub fn reset(&mut self) {
        match &mut self.engine {
            Engine::Q2(c) => c.reset(),
            Engine::Q3(c) => c.reset(),
            Engine::Q4(c) => c.reset(),
            Engine::Q5(c) => c.reset(),
        }
    }

    /// Add the next sample of every signal (the first call sets t_0; all integrals are 0
    /// there).
    #[inline(always)]
    pub fn push(&mut self, f: &[f64; NS]) {
        match &mut self.engine {
            Engine::Q2(c) => c.push(f),
            Engine::Q3(c) => c.push(f),
            Engine::Q4(c) => c.push(f),
            Engine::Q5(c) => c.push(f),
        }
    }

    /// The values at the newest node: `levels()[0]` the signals themselves, `levels()[k]`
    /// their k-fold iterated integrals Ik from t_0 (all zero before the first sample).
    #[inline]
    pub fn levels(&self) -> &[[f64; NS]; R] {
        match &self.engine {
            Engine::Q2(c) => c.levels(),
            Engine::Q3(c) => c.levels(),
            Engine::Q4(c) => c.levels(),
            Engine::Q5(c) => c.levels(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_order_is_stencil() {
        for q in Quadrature::ALL {
            let s: f64 = q.weights().iter().sum();
            assert!((s - 1.0).abs() < 1e-15, "{q}");
        }
        assert_eq!(Quadrature::Trapezoid.order(), 2);
        assert_eq!(Quadrature::AdamsMoulton5.order(), 5);
    }

    #[test]
    fn adams_moulton_is_the_last_interval_of_the_interpolant() {
        // integral_{m-2}^{m-1} L_i on nodes 0..m-1 = beta_{m-1-i}.
        for q in Quadrature::ALL {
            let beta = q.weights();
            let m = beta.len();
            let w = lagrange_cumulative_weights::<5>(m);
            for i in 0..m {
                let interval = w[m - 1][i] - w[m - 2][i];
                assert!((interval - beta[m - 1 - i]).abs() < 1e-14, "{q} i={i}");
            }
        }
    }

    #[test]
    fn start_weights_are_simpson_and_boole() {
        let w = lagrange_cumulative_weights::<5>(3);
        for (got, want) in w[2].iter().zip([1.0 / 3.0, 4.0 / 3.0, 1.0 / 3.0, 0.0]) {
            assert!((got - want).abs() < 1e-15, "{w:?}");
        }
        let w = lagrange_cumulative_weights::<5>(5);
        let boole = [14.0, 64.0, 24.0, 64.0, 14.0].map(|v| v / 45.0);
        for (got, want) in w[4].iter().zip(boole) {
            assert!((got - want).abs() < 1e-14, "{got} {want}");
        }
    }

    #[test]
    fn names_round_trip() {
        for q in Quadrature::ALL {
            assert_eq!(q.name().parse::<Quadrature>().unwrap(), q);
            assert_eq!(q.to_string(), q.name());
        }
        assert_eq!(
            "AM4".parse::<Quadrature>().unwrap(),
            Quadrature::AdamsMoulton4
        );
        let e = "simpson".parse::<Quadrature>().unwrap_err().to_string();
        assert!(e.contains("\"simpson\"") && e.contains("am5"), "{e}");
    }

    #[test]
    fn bad_step_is_rejected() {
        assert!(RunningIntegrals::<1>::new(Quadrature::Trapezoid, 0.0).is_err());
        assert!(RunningIntegrals::<1>::new(Quadrature::Trapezoid, f64::NAN).is_err());
    }

    #[test]
    fn six_levels_integrate_exp_to_the_rule_order() {
        // I_k[e^t](t) = e^t - sum_{j<k} t^j / j!: levels 1..6 (the cross-coupled
        // identifier's), error O(h^p) at every level; halving h divides it by ~2^p.
        let err = |q: Quadrature, h: f64| -> [f64; 6] {
            let mut ri = RunningIntegrals::<1, 7>::new(q, h).unwrap();
            let n = (1.0 / h).round() as usize;
            for i in 0..=n {
                ri.push(&[(i as f64 * h).exp()]);
            }
            std::array::from_fn(|k| {
                let k = k + 1;
                let (mut poly, mut term) = (0.0, 1.0);
                for j in 0..k {
                    poly += term;
                    term /= (j + 1) as f64;
                }
                (ri.levels()[k][0] - (1f64.exp() - poly)).abs() / (1f64.exp() - poly)
            })
        };
        for q in [Quadrature::AdamsMoulton4, Quadrature::AdamsMoulton5] {
            let (coarse, fine) = (err(q, 1.0 / 40.0), err(q, 1.0 / 80.0));
            for k in 0..6 {
                let ratio = coarse[k] / fine[k];
                let p = q.order() as f64;
                assert!(
                    ratio > 2f64.powf(p - 0.5) && ratio < 2f64.powf(p + 0.5),
                    "{q} level {}: {} -> {} (ratio {ratio})",
                    k + 1,
                    coarse[k],
                    fine[k]
                );
            }
            let limit = if q == Quadrature::AdamsMoulton5 {
                2e-8
            } else {
                1e-6
            };
            assert!(fine[5] < limit, "{q}: {fine:?}");
        }
    }

    #[test]
    fn more_levels_leave_the_first_four_unchanged() {
        // the cascade is level by level: keeping I5, I6 does not touch I1..I4
        let mut four = RunningIntegrals::<3>::new(Quadrature::AdamsMoulton5, 1e-3).unwrap();
        let mut six = RunningIntegrals::<3, 7>::new(Quadrature::AdamsMoulton5, 1e-3).unwrap();
        for i in 0..500 {
            let t = i as f64 * 1e-3;
            let f = [t.sin(), (3.0 * t).cos(), t * t];
            four.push(&f);
            six.push(&f);
            for k in 0..5 {
                assert_eq!(four.levels()[k], six.levels()[k]);
            }
        }
    }

    #[test]
    fn polynomials_of_the_rule_degree_are_integrated_exactly_from_the_first_sample() {
        // f = (1 + t)^d, d < q (the stencil): exact at every node n >= d (node n has n + 1
        // nodes to interpolate through during start-up), start-up included.
        for q in Quadrature::ALL {
            for d in 0..q.order() as i32 {
                let h = 0.125;
                let mut ri = RunningIntegrals::<1>::new(q, h).unwrap();
                for n in 0..12 {
                    let t = n as f64 * h;
                    ri.push(&[(1.0 + t).powi(d)]);
                    if n < d {
                        continue;
                    }
                    let want = ((1.0 + t).powi(d + 1) - 1.0) / (d + 1) as f64;
                    let got = ri.levels()[1][0];
                    assert!(
                        (got - want).abs() < 1e-13,
                        "{q} d={d} n={n}: {got} vs {want}"
                    );
                    // I2 too: ((1+t)^(d+2) - 1 - (d+2) t) / ((d+1)(d+2))
                    let want2 = ((1.0 + t).powi(d + 2) - 1.0 - (d + 2) as f64 * t)
                        / ((d + 1) * (d + 2)) as f64;
                    let got2 = ri.levels()[2][0];
                    if n > d && d + 1 < q.order() as i32 {
                        assert!((got2 - want2).abs() < 1e-13, "{q} d={d} n={n}: I2");
                    }
                }
            }
        }
    }
}
