//! Analysis of a finite-element rotor (docs/analysis.md, "Finite-element
//! rotors"): Campbell diagram, critical speeds, stability and the unbalance per plane, with
//! standard deviations from a covariance over [`FeParameter`]s (e.g. that of an
//! identification).
//!
//! The model is the full finite-element rotor ([`FeSystem::full`]) at a constant speed W
//! (w' = 0, so Ka does not enter):
//!
//! ```text
//! M q'' + (C0 + W G) q' + K0 q = 0,     q = u e^{lambda t}:   Q(lambda) u = 0
//! Q(lambda) = lambda^2 M + lambda (C0 + W G) + K0
//! ```
//!
//! **Eigenvalues.** Those of the first-order form x' = A x, x = (q, q'),
//! A = \[\[0, I\], \[-M^-1 K0, -M^-1 (C0 + W G)\]\], balanced (Parlett-Reinsch, as the exact
//! simulator balances its exponential: SI state matrices mix entries ~1 with ~1e10) and
//! computed by nalgebra's real Schur form; then each one used is polished by Newton steps
//! on the two-sided Rayleigh functional of Q,
//!
//! ```text
//! lambda <- lambda - (r Q(lambda) u) / (r Q'(lambda) u),     Q'(lambda) = 2 lambda M + C0 + W G
//! ```
//!
//! with u and r the right and left null vectors of Q(lambda) (Q u ~ 0, r Q ~ 0, no
//! conjugation), each one step of inverse iteration, both from one complex LU with
//! partial pivoting of Q(lambda) (the `complex_lu` module; r from its transposed solve). A
//! mode is an eigenvalue with Im lambda > 0 and a damping ratio below 0.9
//! ([`MAX_DAMPING_RATIO`]): overdamped, real eigenvalues have no damped natural frequency
//! and are left out, and so are nearly real ones, whose imaginary part is rounding or the
//! small split the gyroscopic coupling gives an overdamped pair (a shaft with proportional
//! damping C = a M + b K has such pairs among its high modes; followed as modes, they
//! crowded the candidates and produced spurious critical speeds near 0 rpm); per mode, as for the 2-DOF models: damped natural
//! frequency w_d = Im lambda, damping ratio -Re lambda / |lambda|, logarithmic decrement
//! -2 pi Re lambda / Im lambda.
//!
//! **Whirl.** The orbit of a node with x and y is x = Re(X e^{i w t}), y = Re(Y e^{i w t}),
//! (X, Y) the node's entries of u. The shaft turns from +x towards +y, so the whirl ratio
//!
//! ```text
//! kappa = 2 Im(X conj Y) / (|X|^2 + |Y|^2)   in [-1, 1]
//! ```
//!
//! is +1 for a circle in the direction of rotation (forward), -1 against it, 0 for a line;
//! it is taken at the node of the largest orbit (|X|^2 + |Y|^2), where the mode is best
//! seen. Under the map of docs/finite_element.md section 2 (y = -z) this is the 2-DOF
//! models' kappa = -2 Im(X conj Z) / (|X|^2 + |Z|^2). An eigenvalue within 1e-8 of
//! another (relative) is double: its mode shape, hence its whirl and its derivatives, is
//! undefined (`None`), as for the 2-DOF models.
//!
//! **Tracking across speeds.** The lowest `modes` modes at the first speed are followed
//! over the grid: at each speed the lowest `modes + 4` modes are candidates, and each
//! followed mode takes the candidate that minimises
//! |lambda_c - lambda_pred| / |lambda_pred| + (1 - MAC), lambda_pred its eigenvalue at the
//! previous speed advanced by d lambda / d W (below), MAC the modal assurance criterion of
//! the two mode shapes in the mass inner product (|u^H M v|^2 / (u^H M u v^H M v)), taken
//! greedily from the smallest cost. Forward and backward modes that cross keep their
//! identity (their slopes differ and their shapes are orthogonal circles), where ordering
//! by frequency would swap them.
//!
//! **Derivatives** of a simple eigenvalue (Lancaster 1966; Tisseur & Meerbergen 2001), as
//! for the 2-DOF models:
//!
//! ```text
//! d lambda / d p = -r (dQ/dp) u / (r Q'(lambda) u)
//! dQ/dk_ij = b_i b_j^T,   dQ/dc_ij = lambda b_i b_j^T   (bearing coefficients, FeSystem::derivative)
//! dQ/dW = lambda G
//! ```
//!
//! (the unbalance does not move the eigenvalues). Checked against central differences of
//! the polished eigenvalues in the tests.
//!
//! **Critical speeds** are the roots of Im lambda_j(W) - W for each followed mode j: sign
//! changes on the grid, refined by safeguarded Newton steps (d/dW from the derivative above;
//! bisection when a step leaves the bracket) with the eigenvalue continued from the
//! bracket's end, to rounding. Standard deviations by the implicit function theorem,
//! dW_c / dp = -(d w_d / dp) / (d w_d / dW - 1), and the logarithmic decrement's at W_c as
//! its total derivative d delta / dp + (d delta / dW)(dW_c / dp); var = g^T Sigma g over the
//! covariance's parameters ([`FeCovariance`]).
//!
//! **Stability** over the followed modes as for the 2-DOF models (the stability module):
//! the smallest logarithmic decrement over the grid, and the threshold speed where the least
//! damped mode's damping ratio first falls below -1e-9, refined on that mode's damping
//! ratio, with dW_th / dp = -(d Re lambda / dp) / (d Re lambda / dW); `stable_from` after an
//! instability. Modes above the followed ones are not examined.
//!
//! **Unbalance per plane** ([`fe_unbalances`]): each unbalance's m_u d and angle with
//! their standard deviations from the covariance (0 when the covariance does not name them:
//! known; `None` when undetermined). The node is reported: its axial position is not in the
//! matrices file.

use nalgebra::{Complex, DMatrix, DVector};

use super::complex_lu::ComplexLu;
use super::covariance::validate_matrix;
use super::critical::CriticalSpeed;
use super::error::{check_speed, check_speeds, AnalysisError};
use super::modes::{majority_whirl, Mode, Whirl, C64};
use super::stability::{Stability, StabilityMargin, UNSTABLE_ZETA};
use crate::model::check;
use crate::model::finite_element::{
    DofKind, FeDerivative, FeParameter, FeSystem, FiniteElementError, FiniteElementRotor,
};

/// Candidates beyond the followed modes at each speed (module doc).
const EXTRA_CANDIDATES: usize = 4;

/// Two eigenvalues closer than this (relative) are one double eigenvalue.
const DOUBLE: f64 = 1e-8;

/// Eigenvalues damped above this ratio (-Re lambda / |lambda|; a logarithmic decrement of
/// 13.7) are not modes: a real, overdamped pair that rounding or the gyroscopic coupling
/// gives a tiny imaginary part (module doc).
pub const MAX_DAMPING_RATIO: f64 = 0.9;

/// A root is refined until its bracket is narrower than this fraction of the speed.
const BRACKET: f64 = 1e-13;

/// The covariance of some of a finite-element rotor's parameters ([`FeParameter`] names,
/// SI units squared), e.g. the `covariance` of an identification summary. A non-finite
/// variance marks an undetermined parameter (as for [`super::ParameterCovariance`]): a
/// result that depends on one has no standard deviation.
#[derive(Debug, Clone, PartialEq)]
pub struct FeCovariance {
    params: Vec<FeParameter>,
    names: Vec<String>,
    matrix: Vec<Vec<f64>>,
    undetermined: Vec<bool>,
}

impl FeCovariance {
    /// The covariance over `names` (each a single parameter of `rotor`, `bearing0.kxx` ..
    /// `unbalance<j>.alpha`, at most once) with `matrix[i][j]` = Cov(names\[i\],
    /// names\[j\]). Refused: an unknown name (naming what the rotor has), a group name, a
    /// repeat, a matrix that is not square, not symmetric or not positive semi-definite, a
    /// negative variance.
    pub fn new(
        rotor: &FiniteElementRotor,
        names: Vec<String>,
        matrix: Vec<Vec<f64>>,
    ) -> Result<Self, AnalysisError> {
        let all = FeParameter::all(rotor);
        let mut params = Vec::with_capacity(names.len());
        for name in &names {
            let Some(&p) = all.iter().find(|p| p.to_string() == *name) else {
                // an unknown name: parse_list's error lists what the rotor has
                FeParameter::parse_list(name, rotor)?;
                return Err(FiniteElementError::UnknownParameter {
                    name: name.clone(),
                    allowed: "a covariance names single parameters (bearing<i>.kxx .. \
                              bearing<i>.cyy, unbalance<j>.mud, unbalance<j>.alpha), not groups"
                        .to_owned(),
                }
                .into());
            };
            if params.contains(&p) {
                return Err(AnalysisError::DuplicateParameter { name: name.clone() });
            }
            params.push(p);
        }
        let undetermined = validate_matrix(&names, &matrix)?;
        Ok(Self {
            params,
            names,
            matrix,
            undetermined,
        })
    }

    /// The parameters, in row order.
    pub fn parameters(&self) -> &[FeParameter] {
        &self.params
    }

    /// Their names, in row order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The matrix, `matrix()[i][j]` = Cov(parameters\[i\], parameters\[j\]) (SI units).
    pub fn matrix(&self) -> &[Vec<f64>] {
        &self.matrix
    }

    /// True when parameter `i` (row order) is undetermined.
    pub fn is_undetermined(&self, i: usize) -> bool {
        self.undetermined[i]
    }

    /// The standard deviation of `p` (its unit): `Some(0.0)` when the covariance does not
    /// name it (known exactly), `None` when it is undetermined.
    pub fn std(&self, p: FeParameter) -> Option<f64> {
        match self.params.iter().position(|&q| q == p) {
            None => Some(0.0),
            Some(i) if self.undetermined[i] => None,
            Some(i) => Some(self.matrix[i][i].max(0.0).sqrt()),
        }
    }

    /// sqrt(g^T Sigma g) for a gradient `g` over [`Self::parameters`] (in row order);
    /// `None` when it depends on an undetermined parameter (g_i != 0).
    pub fn propagate(&self, g: &[f64]) -> Option<f64> {
        let n = self.params.len();
        debug_assert_eq!(g.len(), n);
        if (0..n).any(|i| self.undetermined[i] && g[i] != 0.0) {
            return None;
        }
        let mut s = 0.0;
        for i in (0..n).filter(|&i| !self.undetermined[i]) {
            for j in (0..n).filter(|&j| !self.undetermined[j]) {
                s += g[i] * self.matrix[i][j] * g[j];
            }
        }
        Some(s.max(0.0).sqrt())
    }
}

/// One polished eigenvalue with its null vectors (module doc).
#[derive(Debug, Clone)]
struct Eig {
    l: C64,
    /// Right null vector: Q(l) u ~ 0 (unit 2-norm).
    u: DVector<C64>,
    /// Left null vector: r^T Q(l) ~ 0 (unit 2-norm).
    r: DVector<C64>,
    /// r^T Q'(l) u.
    den: C64,
    /// False for a double eigenvalue (module doc).
    simple: bool,
}

/// The eigen-solver of one rotor at any speed (module doc).
struct Solver {
    sys: FeSystem,
    /// M^-1 K0, M^-1 C0, M^-1 G.
    mk: DMatrix<f64>,
    mc: DMatrix<f64>,
    mg: DMatrix<f64>,
    /// M and G as complex matrices.
    m_c: DMatrix<C64>,
    g_c: DMatrix<C64>,
    /// (node, index of x, index of y) of every node with both.
    nodes: Vec<(u32, usize, usize)>,
    /// The right-hand side of inverse iteration (fixed, generic).
    b: DVector<C64>,
}

fn dot(a: &DVector<C64>, b: &DVector<C64>) -> C64 {
    a.iter().zip(b.iter()).map(|(x, y)| x * y).sum()
}

/// r^T A u (no conjugation) for a real square matrix A: sum over the columns j of
/// (column j . r) u_j, down contiguous columns.
fn bilinear(a: &DMatrix<f64>, r: &DVector<C64>, u: &DVector<C64>) -> C64 {
    let n = a.nrows();
    let r = r.as_slice();
    let mut s = Complex::new(0.0, 0.0);
    for (col, &uj) in a.as_slice().chunks_exact(n).zip(u.iter()) {
        let (mut re, mut im) = (0.0, 0.0);
        for (&aij, ri) in col.iter().zip(r) {
            re += aij * ri.re;
            im += aij * ri.im;
        }
        s += Complex::new(re, im) * uj;
    }
    s
}

fn complex(a: &DMatrix<f64>) -> DMatrix<C64> {
    a.map(|v| Complex::new(v, 0.0))
}

impl Solver {
    fn new(rotor: &FiniteElementRotor) -> Self {
        let sys = FeSystem::full(rotor);
        let chol = sys
            .mass()
            .clone()
            .cholesky()
            .expect("FeMatrices::new checks that M is positive definite");
        let mk = chol.solve(sys.stiffness0());
        let mc = chol.solve(sys.damping0());
        let mg = chol.solve(sys.gyroscopic());
        let dofs = sys.dofs();
        let mut nodes = Vec::new();
        for (ix, d) in dofs.iter().enumerate() {
            if d.kind == DofKind::X {
                if let Some(iy) = dofs
                    .iter()
                    .position(|e| e.node == d.node && e.kind == DofKind::Y)
                {
                    nodes.push((d.node, ix, iy));
                }
            }
        }
        let n = sys.len();
        let b = DVector::from_fn(n, |i, _| {
            let t = i as f64;
            Complex::new(1.0 + 0.5 * (1.3 * t).cos(), 0.3 + 0.4 * (0.7 * t).sin())
        });
        Self {
            m_c: complex(sys.mass()),
            g_c: complex(sys.gyroscopic()),
            sys,
            mk,
            mc,
            mg,
            nodes,
            b,
        }
    }

    fn n(&self) -> usize {
        self.sys.len()
    }

    /// Every eigenvalue at speed `w` with Im lambda > 0 and a damping ratio below
    /// [`MAX_DAMPING_RATIO`], by increasing Im lambda (module doc).
    fn eigenvalues(&self, w: f64) -> Vec<C64> {
        let n = self.n();
        let a = DMatrix::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => 0.0,
            (true, false) => f64::from(u8::from(j - n == i)),
            (false, true) => -self.mk[(i - n, j)],
            (false, false) => -(self.mc[(i - n, j - n)] + w * self.mg[(i - n, j - n)]),
        });
        let d = crate::expm::balancing(&a);
        let scaled = DMatrix::from_fn(2 * n, 2 * n, |i, j| a[(i, j)] * d[j] / d[i]);
        let mut ev: Vec<C64> = scaled
            .complex_eigenvalues()
            .iter()
            .copied()
            .filter(|l| l.im > 0.0 && -l.re < MAX_DAMPING_RATIO * l.norm())
            .collect();
        ev.sort_by(|a, b| a.im.total_cmp(&b.im));
        ev
    }

    /// The right and left null vectors of Q(l) = l^2 M + l C + K0 by one step of inverse
    /// iteration each, both from one LU factorization of Q(l) (in `lu`); `None` when Q(l)
    /// is exactly singular in floating point.
    fn null_vectors(
        &self,
        lu: &mut ComplexLu,
        c: &DMatrix<f64>,
        l: C64,
    ) -> Option<(DVector<C64>, DVector<C64>)> {
        let (m, k) = (self.sys.mass(), self.sys.stiffness0());
        let l2 = l * l;
        lu.factor(|i, j| l2 * m[(i, j)] + l * c[(i, j)] + k[(i, j)]);
        let u = lu.solve(&self.b)?;
        let r = lu.solve_transposed(&self.b)?;
        let (nu, nr) = (u.norm(), r.norm());
        if !(nu.is_finite() && nr.is_finite() && nu > 0.0 && nr > 0.0) {
            return None;
        }
        Some((u.unscale(nu), r.unscale(nr)))
    }

    /// The eigenvalue near `l0` at speed `w`, polished (module doc).
    fn refine(&self, w: f64, l0: C64) -> Option<Eig> {
        let c = self.sys.damping(w);
        let mut lu = ComplexLu::new(self.n());
        let mut l = l0;
        let mut last = None;
        for _ in 0..8 {
            let (u, r) = match self.null_vectors(&mut lu, &c, l) {
                Some(v) => v,
                // exactly singular: l is an eigenvalue to rounding; move off it
                None => {
                    let lp = l * (1.0 + 4.0 * f64::EPSILON);
                    self.null_vectors(&mut lu, &c, lp)?
                }
            };
            // r^T Q(l) u and r^T Q'(l) u from r^T M u, r^T C u, r^T K0 u
            let rmu = bilinear(self.sys.mass(), &r, &u);
            let rcu = bilinear(&c, &r, &u);
            let rku = bilinear(self.sys.stiffness0(), &r, &u);
            let den = l * 2.0 * rmu + rcu;
            let num = l * l * rmu + l * rcu + rku;
            if den.norm() == 0.0 || !den.norm().is_finite() {
                return None;
            }
            let step = num / den;
            let done = !step.norm().is_finite() || step.norm() <= 4.0 * f64::EPSILON * l.norm();
            if step.norm().is_finite() {
                l -= step;
            }
            last = Some(Eig {
                l,
                u,
                r,
                den,
                simple: true,
            });
            if done {
                break;
            }
        }
        last
    }

    /// The lowest `count` modes at `w`, polished, by increasing Im lambda (fewer when the
    /// rotor has fewer oscillating modes); double eigenvalues marked.
    fn candidates(&self, w: f64, count: usize) -> Vec<Eig> {
        let ev = self.eigenvalues(w);
        let mut out: Vec<Eig> = ev
            .iter()
            .take(count)
            .filter_map(|&l| self.refine(w, l))
            .collect();
        for e in &mut out {
            let li = e.l;
            let double = ev
                .iter()
                .filter(|&&e| (e - li).norm() <= DOUBLE * li.norm())
                .count()
                > 1;
            e.simple = !double;
        }
        out.sort_by(|a, b| a.l.im.total_cmp(&b.l.im));
        out
    }

    /// d lambda / dW (module doc).
    fn d_dw(&self, e: &Eig) -> C64 {
        -(e.l * dot(&e.r, &(&self.g_c * &e.u))) / e.den
    }

    /// d lambda / dp for each of `params`; `None` for a double eigenvalue.
    fn d_dparams(&self, e: &Eig, params: &[FeParameter]) -> Option<Vec<C64>> {
        if !e.simple {
            return None;
        }
        params
            .iter()
            .map(|&p| {
                Some(match self.sys.derivative(p).ok()? {
                    FeDerivative::Stiffness(d) => -dot(&e.r, &(complex(&d) * &e.u)) / e.den,
                    FeDerivative::Damping(d) => -e.l * dot(&e.r, &(complex(&d) * &e.u)) / e.den,
                    FeDerivative::Load(_) => Complex::new(0.0, 0.0),
                })
            })
            .collect()
    }

    /// The mode of `e` (module doc).
    fn mode(&self, e: &Eig) -> Mode {
        let whirl_ratio = if e.simple {
            self.nodes
                .iter()
                .map(|&(_, ix, iy)| (e.u[ix], e.u[iy]))
                .max_by(|a, b| {
                    (a.0.norm_sqr() + a.1.norm_sqr()).total_cmp(&(b.0.norm_sqr() + b.1.norm_sqr()))
                })
                .filter(|(x, y)| x.norm_sqr() + y.norm_sqr() > 0.0)
                .map(|(x, y)| 2.0 * (x * y.conj()).im / (x.norm_sqr() + y.norm_sqr()))
        } else {
            None
        };
        Mode::of(e.l, whirl_ratio)
    }

    /// |u^H M v|^2 / (u^H M u v^H M v), with `mu` = M u and `mv` = M v.
    fn mac(u: &DVector<C64>, mu: &DVector<C64>, v: &DVector<C64>, mv: &DVector<C64>) -> f64 {
        let uv = u.dotc(mv).norm_sqr();
        let uu = u.dotc(mu).norm();
        let vv = v.dotc(mv).norm();
        if uu > 0.0 && vv > 0.0 {
            uv / (uu * vv)
        } else {
            0.0
        }
    }

    /// The lowest `modes` modes at the first speed, followed over `speeds` (module doc):
    /// per speed, per mode.
    fn track(&self, speeds: &[f64], modes: usize) -> Result<Vec<Vec<Eig>>, AnalysisError> {
        let count = modes + EXTRA_CANDIDATES;
        let mut out: Vec<Vec<Eig>> = Vec::with_capacity(speeds.len());
        for (k, &w) in speeds.iter().enumerate() {
            let cands = self.candidates(w, count);
            if cands.len() < modes {
                check(
                    "modes",
                    modes as f64,
                    "at most the number of oscillating modes of the rotor at every speed of \
                     the range",
                    |_| false,
                )?;
            }
            if k == 0 {
                out.push(cands.into_iter().take(modes).collect());
                continue;
            }
            let prev = &out[k - 1];
            let dw = w - speeds[k - 1];
            let pred: Vec<C64> = prev
                .iter()
                .map(|e| {
                    if e.simple {
                        e.l + self.d_dw(e) * dw
                    } else {
                        e.l
                    }
                })
                .collect();
            // M u of each mode and candidate, once
            let m_prev: Vec<DVector<C64>> = prev.iter().map(|e| &self.m_c * &e.u).collect();
            let m_cands: Vec<DVector<C64>> = cands.iter().map(|e| &self.m_c * &e.u).collect();
            let mut costs = Vec::with_capacity(modes * cands.len());
            for (j, e) in prev.iter().enumerate() {
                for (c, cand) in cands.iter().enumerate() {
                    let dist = (cand.l - pred[j]).norm() / pred[j].norm().max(f64::MIN_POSITIVE);
                    let mac = Self::mac(&e.u, &m_prev[j], &cand.u, &m_cands[c]);
                    costs.push((dist + (1.0 - mac), j, c));
                }
            }
            costs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut chosen: Vec<Option<usize>> = vec![None; modes];
            let mut taken = vec![false; cands.len()];
            for (_, j, c) in costs {
                if chosen[j].is_none() && !taken[c] {
                    chosen[j] = Some(c);
                    taken[c] = true;
                }
            }
            out.push(
                chosen
                    .into_iter()
                    .map(|c| cands[c.expect("at least `modes` candidates")].clone())
                    .collect(),
            );
        }
        Ok(out)
    }

    /// The root in [a, b] of `f(eigenvalue at W, W, d lambda / dW)` = (value, d value /
    /// dW), whose sign differs at the two ends; the eigenvalue continued from the end of
    /// smaller |value| (module doc).
    fn root(
        &self,
        f: impl Fn(&Eig, f64, C64) -> (f64, f64),
        (mut a, ea): (f64, &Eig),
        (mut b, eb): (f64, &Eig),
    ) -> (f64, Eig) {
        let mut fa = f(ea, a, self.d_dw(ea)).0;
        let fb = f(eb, b, self.d_dw(eb)).0;
        let (mut w, mut e) = if fa.abs() <= fb.abs() {
            (a, ea.clone())
        } else {
            (b, eb.clone())
        };
        for _ in 0..100 {
            let dl = self.d_dw(&e);
            let (fw, dfw) = f(&e, w, dl);
            if fw == 0.0 {
                break;
            }
            if (fw > 0.0) == (fa > 0.0) {
                a = w;
                fa = fw;
            } else {
                b = w;
            }
            let newton = w - fw / dfw;
            let next = if newton.is_finite() && newton > a && newton < b {
                newton
            } else {
                0.5 * (a + b)
            };
            if (next - w).abs() <= BRACKET * b.abs() || b - a <= BRACKET * b.abs() {
                break;
            }
            let guess = e.l + dl * (next - w);
            match self.refine(next, guess) {
                Some(mut n) => {
                    n.simple = e.simple;
                    e = n;
                    w = next;
                }
                None => break,
            }
        }
        (w, e)
    }
}

/// The followed modes over a speed grid: the data of a Campbell diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct FeCampbell {
    /// The speeds W \[rad/s\], increasing.
    pub speeds: Vec<f64>,
    /// Per speed, the followed modes (mode j is the j-th lowest at the first speed,
    /// followed across speeds: module doc).
    pub modes: Vec<Vec<Mode>>,
}

impl FeCampbell {
    /// How many modes are followed.
    pub fn count(&self) -> usize {
        self.modes.first().map_or(0, Vec::len)
    }

    /// Mode `j` at every speed.
    pub fn mode(&self, j: usize) -> impl Iterator<Item = &Mode> + '_ {
        self.modes.iter().map(move |m| &m[j])
    }

    /// The whirl of mode `j` over the grid: the direction most of its speeds show; `None`
    /// when none shows one or both are equally frequent.
    pub fn whirl(&self, j: usize) -> Option<Whirl> {
        majority_whirl(self.mode(j))
    }
}

/// The analysis of a finite-element rotor over a speed grid (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct FeAnalysis {
    /// The followed modes at every speed.
    pub campbell: FeCampbell,
    /// The critical speeds, by increasing speed; `mode` is the followed mode's index.
    pub critical: Vec<CriticalSpeed>,
    /// Stability over the followed modes; mode indices are the followed modes'.
    pub stability: Stability,
}

/// Check `modes` against the rotor: 1 ..= n.
fn check_modes(modes: usize, n: usize) -> Result<(), AnalysisError> {
    if modes == 0 || modes > n {
        check(
            "modes",
            modes as f64,
            "1 ..= the number of degrees of freedom of the rotor",
            |_| false,
        )?;
    }
    Ok(())
}

/// d delta / d x for an eigenvalue derivative `d` at `l`: delta = -2 pi Re l / Im l.
fn d_log_dec(l: C64, d: C64) -> f64 {
    -std::f64::consts::TAU * (d.re * l.im - l.re * d.im) / (l.im * l.im)
}

/// d zeta / d x for an eigenvalue derivative `d` at `l`: zeta = -Re l / |l|.
fn d_zeta(l: C64, d: C64) -> f64 {
    let n = l.norm();
    let dn = (l.conj() * d).re / n;
    -(d.re * n - l.re * dn) / (n * n)
}

/// The Campbell diagram, critical speeds and stability of `rotor` (its full model) over
/// `speeds` \[rad/s\] (finite, >= 0, strictly increasing, at least one; two for critical
/// speeds), following its lowest `modes` modes (1 ..= the number of degrees of freedom),
/// with standard deviations under `cov` (module doc). The grid must be fine enough that no
/// followed mode crosses 1X twice between two neighbouring speeds.
pub fn fe_analysis(
    rotor: &FiniteElementRotor,
    cov: Option<&FeCovariance>,
    speeds: &[f64],
    modes: usize,
) -> Result<FeAnalysis, AnalysisError> {
    check_speeds(speeds, 1)?;
    let solver = Solver::new(rotor);
    check_modes(modes, solver.n())?;
    let tracked = solver.track(speeds, modes)?;
    let campbell = FeCampbell {
        speeds: speeds.to_vec(),
        modes: tracked
            .iter()
            .map(|row| row.iter().map(|e| solver.mode(e)).collect())
            .collect(),
    };
    let params: Vec<FeParameter> = cov.map_or_else(Vec::new, |c| c.parameters().to_vec());
    // critical speeds: Im lambda_j(W) - W changes sign
    let mut critical = Vec::new();
    for j in 0..modes {
        for (k, pair) in tracked.windows(2).enumerate() {
            let (ea, eb) = (&pair[0][j], &pair[1][j]);
            let (wa, wb) = (speeds[k], speeds[k + 1]);
            if (ea.l.im > wa) == (eb.l.im > wb) {
                continue;
            }
            let (wc, e) = solver.root(|e, w, dl| (e.l.im - w, dl.im - 1.0), (wa, ea), (wb, eb));
            critical.push(critical_speed(&solver, j, wc, &e, &params, cov));
        }
    }
    critical.sort_by(|a, b| a.speed.total_cmp(&b.speed));
    let stability = stability(&solver, speeds, &tracked, &campbell.modes, &params, cov);
    Ok(FeAnalysis {
        campbell,
        critical,
        stability,
    })
}

/// The critical speed `wc` of followed mode `j`, whose eigenvalue there is `e`, with its
/// standard deviations (module doc).
fn critical_speed(
    solver: &Solver,
    j: usize,
    wc: f64,
    e: &Eig,
    params: &[FeParameter],
    cov: Option<&FeCovariance>,
) -> CriticalSpeed {
    let dl_dw = solver.d_dw(e);
    let slope = dl_dw.im - 1.0;
    let grads = solver
        .d_dparams(e, params)
        .filter(|_| slope != 0.0 && slope.is_finite());
    let std_of = |g: Vec<f64>| cov.and_then(|c| c.propagate(&g));
    let std = grads
        .as_ref()
        .and_then(|dl| std_of(dl.iter().map(|d| -d.im / slope).collect()));
    let log_dec_std = grads.as_ref().filter(|_| e.l.im > 0.0).and_then(|dl| {
        let dd_dw = d_log_dec(e.l, dl_dw);
        std_of(
            dl.iter()
                .map(|d| d_log_dec(e.l, *d) + dd_dw * (-d.im / slope))
                .collect(),
        )
    });
    CriticalSpeed {
        speed: wc,
        std,
        mode: j,
        at: solver.mode(e),
        log_dec_std,
    }
}

/// The standard deviation of the speed where mode `e`'s Re lambda crosses 0:
/// dW / dp = -(d Re lambda / dp) / (d Re lambda / dW).
fn crossing_std(
    solver: &Solver,
    e: &Eig,
    params: &[FeParameter],
    cov: Option<&FeCovariance>,
) -> Option<f64> {
    let slope = solver.d_dw(e).re;
    if slope == 0.0 || !slope.is_finite() {
        return None;
    }
    let dl = solver.d_dparams(e, params)?;
    let g: Vec<f64> = dl.iter().map(|d| -d.re / slope).collect();
    cov.and_then(|c| c.propagate(&g))
}

/// The least damped of the followed modes at one speed: (index, damping ratio).
fn least_damped(row: &[Eig]) -> (usize, f64) {
    row.iter()
        .enumerate()
        .map(|(j, e)| (j, -e.l.re / e.l.norm()))
        .fold((0, f64::INFINITY), |b, x| if x.1 < b.1 { x } else { b })
}

/// Stability over the followed modes (module doc; the 2-DOF stability module's rules);
/// `modes` are those of `tracked`.
fn stability(
    solver: &Solver,
    speeds: &[f64],
    tracked: &[Vec<Eig>],
    modes: &[Vec<Mode>],
    params: &[FeParameter],
    cov: Option<&FeCovariance>,
) -> Stability {
    let mut out = Stability::unscanned();
    // the crossing of mode j's damping ratio (+ shift) between grid speeds k - 1 and k
    let crossing = |j: usize, k: usize, shift: f64| {
        solver.root(
            |e, _, dl| (-e.l.re / e.l.norm() + shift, d_zeta(e.l, dl)),
            (speeds[k - 1], &tracked[k - 1][j]),
            (speeds[k], &tracked[k][j]),
        )
    };
    let zeta = |e: &Eig| -e.l.re / e.l.norm();
    let mut last_stable: Option<(usize, f64)> = None;
    let mut last_unstable: Option<usize> = None;
    for (k, row) in tracked.iter().enumerate() {
        let w = speeds[k];
        out.note_modes(w, modes[k].iter());
        let (jl, z) = least_damped(row);
        let unstable = z < -UNSTABLE_ZETA;
        if out.threshold.is_none() && unstable {
            match last_stable {
                None => {
                    out.threshold = Some(w);
                    out.unstable_at_start = true;
                    out.threshold_mode = Some(jl);
                    out.threshold_whirl = solver.mode(&row[jl]).whirl;
                }
                Some((ka, za)) => {
                    let shift = if za > 0.0 { 0.0 } else { UNSTABLE_ZETA };
                    let sign_change = (zeta(&tracked[ka][jl]) + shift > 0.0) != (z + shift > 0.0);
                    let (wt, e) = if ka + 1 == k && sign_change {
                        crossing(jl, k, shift)
                    } else {
                        (w, row[jl].clone())
                    };
                    out.threshold = Some(wt);
                    out.threshold_mode = Some(jl);
                    out.threshold_whirl = solver.mode(&e).whirl;
                    out.threshold_std = crossing_std(solver, &e, params, cov);
                }
            }
        }
        if unstable {
            out.stable_from = None;
            out.stable_from_std = None;
            last_unstable = Some(k);
        } else {
            if let Some(ku) = last_unstable.filter(|&ku| last_stable.is_none_or(|(s, _)| s < ku)) {
                // the mode least damped at the last unstable speed becomes stable
                let (j, _) = least_damped(&tracked[ku]);
                let shift = if z > 0.0 { 0.0 } else { UNSTABLE_ZETA };
                let sign_change =
                    (zeta(&tracked[ku][j]) + shift > 0.0) != (zeta(&row[j]) + shift > 0.0);
                let (ws, e) = if ku + 1 == k && sign_change {
                    crossing(j, k, shift)
                } else {
                    (w, row[j].clone())
                };
                out.stable_from = Some(ws);
                out.stable_from_std = crossing_std(solver, &e, params, cov);
            }
            last_stable = Some((k, z));
        }
    }
    out
}

/// The stability margin of `rotor` at the speed `omega` \[rad/s\] (finite, >= 0): the least
/// damped of its lowest `modes` modes there (`mode` its index among them, by increasing
/// frequency) with the standard deviation of its logarithmic decrement under `cov`.
pub fn fe_stability_margin(
    rotor: &FiniteElementRotor,
    cov: Option<&FeCovariance>,
    omega: f64,
    modes: usize,
) -> Result<StabilityMargin, AnalysisError> {
    check_speed(omega)?;
    let solver = Solver::new(rotor);
    check_modes(modes, solver.n())?;
    let mut cands = solver.candidates(omega, modes + EXTRA_CANDIDATES);
    cands.truncate(modes);
    if cands.is_empty() {
        check(
            "modes",
            modes as f64,
            "at most the number of oscillating modes of the rotor",
            |_| false,
        )?;
    }
    let (j, _) = least_damped(&cands);
    let e = &cands[j];
    let params: Vec<FeParameter> = cov.map_or_else(Vec::new, |c| c.parameters().to_vec());
    let log_dec_std = solver.d_dparams(e, &params).and_then(|dl| {
        let g: Vec<f64> = dl.iter().map(|d| d_log_dec(e.l, *d)).collect();
        cov.and_then(|c| c.propagate(&g))
    });
    Ok(StabilityMargin {
        speed: omega,
        mode: j,
        at: solver.mode(e),
        log_dec_std,
    })
}

/// One unbalance of a finite-element rotor with its uncertainty ([`fe_unbalances`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeUnbalanceEstimate {
    /// Its position in `[[rotor.unbalance]]` (`unbalance<index>`).
    pub index: usize,
    /// The node it stands at (the plane; its axial position is not in the matrices file).
    pub node: u32,
    /// m_u d \[kg m\].
    pub mud: f64,
    /// Its standard deviation \[kg m\]: 0 when the covariance does not name it (known),
    /// `None` without a covariance or when undetermined.
    pub mud_std: Option<f64>,
    /// Its angle at phi = 0 from +x towards +y \[rad\].
    pub alpha: f64,
    /// Its standard deviation \[rad\] (as `mud_std`).
    pub alpha_std: Option<f64>,
}

/// Every unbalance of `rotor` with its standard deviations under `cov` (module doc).
pub fn fe_unbalances(
    rotor: &FiniteElementRotor,
    cov: Option<&FeCovariance>,
) -> Vec<FeUnbalanceEstimate> {
    rotor
        .unbalances
        .iter()
        .enumerate()
        .map(|(index, u)| FeUnbalanceEstimate {
            index,
            node: u.node,
            mud: u.mud,
            mud_std: cov.and_then(|c| c.std(FeParameter::Mud { index })),
            alpha: u.alpha,
            alpha_std: cov.and_then(|c| c.std(FeParameter::Alpha { index })),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::analysis::{critical_speeds, stability_with_covariance, ParameterCovariance};
    use crate::model::finite_element::{Bearing, BearingCoefficient, Dof, FeMatrices, FeUnbalance};
    use crate::model::{CrossCoupling, RotorParams};

    fn dofs(names: &[&str]) -> Vec<Dof> {
        names.iter().map(|s| s.parse().unwrap()).collect()
    }

    /// The one-node finite-element rotor of a 2-DOF rotor `p` (docs/finite_element.md
    /// section 2: x = x, y = -z; kxy = -kxz, kyx = -kzx, likewise c; alpha - 90 deg).
    fn one_node(p: &RotorParams) -> FiniteElementRotor {
        let (m, a) = (p.m, p.a);
        let z = DMatrix::zeros(2, 2);
        let mats = FeMatrices::new(
            dofs(&["0.x", "0.y"]),
            DMatrix::from_row_slice(2, 2, &[m, 0.0, 0.0, m]),
            z,
            DMatrix::from_row_slice(2, 2, &[0.0, a, -a, 0.0]),
            None,
            Some(DMatrix::from_row_slice(2, 2, &[0.0, a, 0.0, 0.0])),
        )
        .unwrap();
        let x = p.cross();
        let b = Bearing {
            node: 0,
            kxx: p.kx,
            kxy: -x.kxz,
            kyx: -x.kzx,
            kyy: p.kz,
            cxx: p.cx,
            cxy: -x.cxz,
            cyx: -x.czx,
            cyy: p.cz,
        };
        let u = FeUnbalance {
            node: 0,
            mud: p.unbalance.mud(),
            alpha: p.unbalance.alpha - std::f64::consts::FRAC_PI_2,
        };
        FiniteElementRotor::new(Arc::new(mats), vec![b], vec![u]).unwrap()
    }

    /// A correlated covariance over (cx, kx, cz, kz, cxz, czx, kxz, kzx) of `p` for the
    /// 2-DOF analysis, and the same one over the one-node rotor's names (the cross terms'
    /// signs flipped).
    fn covariances(
        p: &RotorParams,
        fe: &FiniteElementRotor,
    ) -> (ParameterCovariance, FeCovariance) {
        let x = p.cross();
        let sd = [
            0.1 * p.cx,
            0.02 * p.kx,
            0.1 * p.cz,
            0.02 * p.kz,
            5.0 + 0.1 * x.cxz.abs(),
            5.0 + 0.1 * x.czx.abs(),
            2e3 + 0.05 * x.kxz.abs(),
            2e3 + 0.05 * x.kzx.abs(),
        ];
        let n = sd.len();
        let corr = |i: usize, j: usize| {
            if i == j {
                1.0
            } else {
                0.3 * (((i * 5 + j * 5 + i * j) % 7) as f64 / 7.0 - 0.4)
            }
        };
        let matrix: Vec<Vec<f64>> = (0..n)
            .map(|i| (0..n).map(|j| corr(i, j) * sd[i] * sd[j]).collect())
            .collect();
        let two = ["cx", "kx", "cz", "kz", "cxz", "czx", "kxz", "kzx"];
        let fe_names = [
            "bearing0.cxx",
            "bearing0.kxx",
            "bearing0.cyy",
            "bearing0.kyy",
            "bearing0.cxy",
            "bearing0.cyx",
            "bearing0.kxy",
            "bearing0.kyx",
        ];
        let sign = |i: usize| if i >= 4 { -1.0 } else { 1.0 };
        let flipped: Vec<Vec<f64>> = (0..n)
            .map(|i| (0..n).map(|j| sign(i) * sign(j) * matrix[i][j]).collect())
            .collect();
        (
            ParameterCovariance::new(two.map(String::from).to_vec(), matrix).unwrap(),
            FeCovariance::new(fe, fe_names.map(String::from).to_vec(), flipped).unwrap(),
        )
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn a_one_node_rotor_has_the_cross_coupled_models_modes_critical_speeds_and_stds() {
        let mut p = crate::test_models::cross_coupled_rotor();
        p.coupling = Some(CrossCoupling {
            cxz: 20.0,
            czx: -12.0,
            kxz: -3.0e4,
            kzx: 4.0e4,
        });
        p.cz = 120.0;
        let fe = one_node(&p);
        let (cov2, cov) = covariances(&p, &fe);
        let grid: Vec<f64> = (0..=60).map(|k| 10.0 * k as f64).collect();
        let fa = fe_analysis(&fe, Some(&cov), &grid, 2).unwrap();
        let two = critical_speeds(&p, Some(&cov2), &grid).unwrap();
        assert_eq!(fa.critical.len(), 2);
        assert_eq!(two.len(), 2);
        for (f, t) in fa.critical.iter().zip(&two) {
            assert!(rel(f.speed, t.speed) < 1e-9, "{} vs {}", f.speed, t.speed);
            assert_eq!(f.whirl(), t.whirl());
            assert!(f.whirl().is_some());
            let (fd, td) = (f.at.log_dec.unwrap(), t.at.log_dec.unwrap());
            assert!(rel(fd, td) < 1e-9, "{fd} vs {td}");
            let (fs, ts) = (f.std.unwrap(), t.std.unwrap());
            assert!(rel(fs, ts) < 1e-7, "{fs} vs {ts}");
            let (fs, ts) = (f.log_dec_std.unwrap(), t.log_dec_std.unwrap());
            assert!(rel(fs, ts) < 1e-7, "{fs} vs {ts}");
        }
        // the Campbell diagram: the same two modes at every speed (sorted by frequency)
        let c2 = crate::analysis::campbell(&p, &grid).unwrap();
        for (k, row) in fa.campbell.modes.iter().enumerate() {
            let mut f: Vec<&Mode> = row.iter().collect();
            f.sort_by(|a, b| a.frequency.total_cmp(&b.frequency));
            for (a, b) in f.iter().zip(&c2.modes[k]) {
                assert!(rel(a.frequency, b.frequency) < 1e-9, "speed {k}");
                assert!(rel(a.damping_ratio, b.damping_ratio) < 1e-9, "speed {k}");
                assert_eq!(a.whirl, b.whirl, "speed {k}");
            }
        }
    }

    #[test]
    fn a_one_node_rotor_has_the_cross_coupled_models_threshold_and_its_std() {
        let mut p = crate::test_models::cross_coupled_rotor();
        p.a = -2.871;
        p.kx = 1.195e6;
        p.kz = 1.25e6;
        p.cx = 200.0;
        p.cz = 180.0;
        p.coupling = Some(CrossCoupling {
            cxz: 10.0,
            czx: -5.0,
            kxz: -4.5e4,
            kzx: 5.5e4,
        });
        let fe = one_node(&p);
        let (cov2, cov) = covariances(&p, &fe);
        let grid: Vec<f64> = (0..=90).map(|k| 10.0 * k as f64).collect();
        let fa = fe_analysis(&fe, Some(&cov), &grid, 2).unwrap();
        let two = stability_with_covariance(&p, Some(&cov2), &grid).unwrap();
        let (ft, tt) = (fa.stability.threshold.unwrap(), two.threshold.unwrap());
        assert!(!two.unstable_at_start && tt > 100.0, "{two:?}");
        assert!(rel(ft, tt) < 1e-9, "{ft} vs {tt}");
        let (fs, ts) = (
            fa.stability.threshold_std.unwrap(),
            two.threshold_std.unwrap(),
        );
        assert!(rel(fs, ts) < 1e-6, "{fs} vs {ts}");
        assert_eq!(fa.stability.threshold_whirl, two.threshold_whirl);
        assert!(rel(fa.stability.min_log_dec.unwrap(), two.min_log_dec.unwrap()) < 1e-9);
        // the margin at 0.8 x threshold
        let w = 0.8 * tt;
        let fm = fe_stability_margin(&fe, Some(&cov), w, 2).unwrap();
        let tm = crate::analysis::stability_margin(&p, Some(&cov2), w).unwrap();
        assert!(rel(fm.log_dec().unwrap(), tm.log_dec().unwrap()) < 1e-9);
        assert!(rel(fm.log_dec_std.unwrap(), tm.log_dec_std.unwrap()) < 1e-7);
    }

    /// Two nodes with x, y, rx, ry, a disk's gyroscopic coupling at node 1, bearings at
    /// both nodes (cross-coupled, anisotropic).
    fn two_node_rotor() -> FiniteElementRotor {
        let d = dofs(&["0.x", "0.y", "0.rx", "0.ry", "1.x", "1.y", "1.rx", "1.ry"]);
        let n = 8;
        let mut m = DMatrix::<f64>::zeros(n, n);
        for (i, v) in [8.0, 8.0, 0.05, 0.05, 12.0, 12.0, 0.09, 0.09]
            .iter()
            .enumerate()
        {
            m[(i, i)] = *v;
        }
        // a beam element of length 0.4 m between the nodes (x-z plane and y-z plane)
        let (ei, l) = (2.0e5, 0.4);
        let kb = |a: f64, b: f64| {
            DMatrix::from_row_slice(
                4,
                4,
                &[
                    12.0,
                    6.0 * l * a,
                    -12.0,
                    6.0 * l * b,
                    6.0 * l * a,
                    4.0 * l * l,
                    -6.0 * l * a,
                    2.0 * l * l,
                    -12.0,
                    -6.0 * l * a,
                    12.0,
                    -6.0 * l * b,
                    6.0 * l * b,
                    2.0 * l * l,
                    -6.0 * l * b,
                    4.0 * l * l,
                ],
            ) * (ei / (l * l * l))
        };
        let mut k = DMatrix::<f64>::zeros(n, n);
        // (x, ry) with dx/dz = +ry; (y, rx) with dy/dz = -rx
        let sub = kb(1.0, 1.0);
        let xi = [0, 3, 4, 7];
        let yi = [1, 2, 5, 6];
        let sy = [1.0, -1.0, 1.0, -1.0];
        for a in 0..4 {
            for b in 0..4 {
                k[(xi[a], xi[b])] += sub[(a, b)];
                k[(yi[a], yi[b])] += sy[a] * sy[b] * sub[(a, b)];
            }
        }
        let mut g = DMatrix::<f64>::zeros(n, n);
        g[(6, 7)] = 0.16;
        g[(7, 6)] = -0.16;
        g[(2, 3)] = 0.01;
        g[(3, 2)] = -0.01;
        let mats = FeMatrices::new(d, m, k, g, None, None).unwrap();
        let b0 = Bearing {
            node: 0,
            kxx: 1.0e6,
            kxy: -1.5e5,
            kyx: 2.0e5,
            kyy: 1.3e6,
            cxx: 400.0,
            cxy: 20.0,
            cyx: -30.0,
            cyy: 500.0,
        };
        let b1 = Bearing {
            node: 1,
            kxx: 1.6e6,
            kyy: 1.1e6,
            cxx: 300.0,
            cyy: 350.0,
            ..b0
        };
        let u = FeUnbalance {
            node: 1,
            mud: 2e-4,
            alpha: 0.4,
        };
        FiniteElementRotor::new(Arc::new(mats), vec![b0, b1], vec![u]).unwrap()
    }

    #[test]
    fn eigenvalue_derivatives_match_central_differences() {
        let r = two_node_rotor();
        let s = Solver::new(&r);
        let w = 350.0;
        let params = FeParameter::all(&r);
        for e in s.candidates(w, 4) {
            let dl = s.d_dparams(&e, &params).unwrap();
            for (p, d) in params.iter().zip(&dl) {
                let v = p.get(&r).unwrap();
                let h = 1e-6 * v.abs().max(1e3);
                let at = |x: f64| {
                    let mut q = r.clone();
                    p.set(&mut q, x);
                    Solver::new(&q).refine(w, e.l).unwrap().l
                };
                let fd = (at(v + h) - at(v - h)) / (2.0 * h);
                assert!(
                    (fd - d).norm() <= 1e-6 * d.norm() + 1e-11 * e.l.norm() / h,
                    "{p} at {}: {fd} vs {d}",
                    e.l
                );
                if matches!(p, FeParameter::Mud { .. } | FeParameter::Alpha { .. }) {
                    assert_eq!(d.norm(), 0.0);
                } else {
                    assert!(d.norm() > 0.0, "{p}");
                }
            }
            let h = 1e-3;
            let fd =
                (s.refine(w + h, e.l).unwrap().l - s.refine(w - h, e.l).unwrap().l) / (2.0 * h);
            let d = s.d_dw(&e);
            assert!(
                (fd - d).norm() < 1e-6 * d.norm() + 1e-12 * e.l.norm() / h,
                "{fd} vs {d}"
            );
        }
    }

    #[test]
    fn critical_speed_stds_are_their_central_difference_gradients() {
        let r = two_node_rotor();
        let grid: Vec<f64> = (0..=80).map(|k| 10.0 * k as f64).collect();
        let base = fe_analysis(&r, None, &grid, 4).unwrap();
        assert!(base.critical.len() >= 2, "{:?}", base.critical);
        for p in [
            FeParameter::Bearing {
                index: 0,
                coefficient: BearingCoefficient::Kxx,
            },
            FeParameter::Bearing {
                index: 1,
                coefficient: BearingCoefficient::Cyx,
            },
        ] {
            // a covariance of that parameter alone, variance 1: std = |dW_c / dp|
            let cov = FeCovariance::new(&r, vec![p.to_string()], vec![vec![1.0]]).unwrap();
            let a = fe_analysis(&r, Some(&cov), &grid, 4).unwrap();
            let v = p.get(&r).unwrap();
            let h = 1e-5 * v.abs().max(1e3);
            let at = |x: f64| {
                let mut q = r.clone();
                p.set(&mut q, x);
                fe_analysis(&q, None, &grid, 4).unwrap().critical
            };
            let (up, dn) = (at(v + h), at(v - h));
            for (i, c) in a.critical.iter().enumerate() {
                let fd = ((up[i].speed - dn[i].speed) / (2.0 * h)).abs();
                let std = c.std.unwrap();
                assert!(
                    (fd - std).abs() <= 1e-5 * std + 1e-12 * c.speed / h,
                    "{p}, critical {i} at {}: {fd} vs {std}",
                    c.speed
                );
                let fd =
                    ((up[i].at.log_dec.unwrap() - dn[i].at.log_dec.unwrap()) / (2.0 * h)).abs();
                let std = c.log_dec_std.unwrap();
                assert!(
                    (fd - std).abs() <= 1e-5 * std + 1e-12 / h,
                    "{p}, log dec {i}: {fd} vs {std}"
                );
            }
        }
    }

    #[test]
    fn crossing_modes_keep_their_identity() {
        // two uncoupled one-node rotors in one set of matrices: node 0's forward mode
        // (100 rad/s at rest, rising) crosses node 1's backward mode (150 rad/s, falling)
        let d = dofs(&["0.x", "0.y", "1.x", "1.y"]);
        let m = DMatrix::<f64>::identity(4, 4);
        let mut g = DMatrix::<f64>::zeros(4, 4);
        g[(0, 1)] = 0.5;
        g[(1, 0)] = -0.5;
        g[(2, 3)] = 0.5;
        g[(3, 2)] = -0.5;
        let mats = FeMatrices::new(d, m, DMatrix::zeros(4, 4), g, None, None).unwrap();
        let b = |node: u32, k: f64| Bearing {
            node,
            kxx: k,
            kxy: 0.0,
            kyx: 0.0,
            kyy: k * 1.02,
            cxx: 2.0,
            cxy: 0.0,
            cyx: 0.0,
            cyy: 2.0,
        };
        let r =
            FiniteElementRotor::new(Arc::new(mats), vec![b(0, 1e4), b(1, 2.25e4)], vec![]).unwrap();
        let grid: Vec<f64> = (0..=40).map(|k| 5.0 * k as f64).collect();
        let a = fe_analysis(&r, None, &grid, 4).unwrap();
        let c = &a.campbell;
        // mode 1 (node 0's upper mode: forward, rising) ends above mode 2 (node 1's lower:
        // backward, falling): they crossed
        let last = c.modes.last().unwrap();
        assert!(last[1].frequency > last[2].frequency, "{last:?}");
        for j in 0..4 {
            let whirls: Vec<Option<Whirl>> = c.mode(j).skip(1).map(|m| m.whirl).collect();
            assert!(
                whirls.iter().all(|w| *w == whirls[0] && w.is_some()),
                "mode {j}: {whirls:?}"
            );
        }
        assert_eq!(c.whirl(1), Some(Whirl::Forward));
        assert_eq!(c.whirl(2), Some(Whirl::Backward));
        // each followed mode's frequency changes smoothly (no jump at the crossing)
        for j in 0..4 {
            let f: Vec<f64> = c.mode(j).map(|m| m.frequency).collect();
            for k in 2..f.len() {
                let second = f[k] - 2.0 * f[k - 1] + f[k - 2];
                assert!(second.abs() < 1.0, "mode {j} at {}: {f:?}", grid[k]);
            }
        }
    }

    #[test]
    fn unbalances_and_covariance_names() {
        let r = two_node_rotor();
        let cov = FeCovariance::new(
            &r,
            vec!["unbalance0.mud".into(), "unbalance0.alpha".into()],
            vec![vec![4e-12, 0.0], vec![0.0, 1e-4]],
        )
        .unwrap();
        let u = fe_unbalances(&r, Some(&cov));
        assert_eq!(u.len(), 1);
        assert_eq!((u[0].node, u[0].mud, u[0].alpha), (1, 2e-4, 0.4));
        assert_eq!(u[0].mud_std, Some(2e-6));
        assert_eq!(u[0].alpha_std, Some(1e-2));
        assert_eq!(fe_unbalances(&r, None)[0].mud_std, None);
        // a known unbalance: std 0; an undetermined one: None
        let known = FeCovariance::new(&r, vec!["bearing0.kxx".into()], vec![vec![1.0]]).unwrap();
        assert_eq!(fe_unbalances(&r, Some(&known))[0].alpha_std, Some(0.0));
        let und = FeCovariance::new(&r, vec!["unbalance0.mud".into()], vec![vec![f64::INFINITY]])
            .unwrap();
        assert_eq!(fe_unbalances(&r, Some(&und))[0].mud_std, None);
        for (bad, why) in [
            ("bearing2.kxx", "bearing0 .. bearing1"),
            ("bearings", "not groups"),
            ("kxx", "bearing0 .. bearing1"),
        ] {
            let e = FeCovariance::new(&r, vec![bad.into()], vec![vec![1.0]])
                .unwrap_err()
                .to_string();
            assert!(e.contains(bad) && e.contains(why), "{e}");
        }
        let e = FeCovariance::new(
            &r,
            vec!["bearing0.kxx".into(), "bearing0.kxx".into()],
            vec![vec![1.0, 0.0], vec![0.0, 1.0]],
        )
        .unwrap_err();
        assert!(matches!(e, AnalysisError::DuplicateParameter { .. }), "{e}");
        let e = fe_analysis(&r, None, &[0.0, 10.0], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("modes") && e.contains("1 ..="), "{e}");
    }
}
