//! The model response of a finite-element fit and its sensitivities (module doc of
//! `super`).

use nalgebra::{Complex, DMatrix, DVector};

use super::{full_initial, FeInitial, FeRefineError};
use crate::model::finite_element::{
    BearingCoefficient, Dof, FeParameter, FeSystem, FiniteElementRotor,
};
use crate::model::{Sampling, SpeedProfile};
use crate::simulate::finite_element::{simulate_fe, FeInitialState, FeMethod};

/// Relative step of the bearing coefficients' forward differences.
const FD_STEP: f64 = 1e-6;

/// What a fit is of: the rotor's structure, the measured channels, the sampling, the speed,
/// the unknowns.
#[derive(Debug, Clone)]
pub struct FeProblem {
    outputs: Vec<Dof>,
    speed: SpeedProfile,
    dt: f64,
    samples: usize,
    unknowns: Vec<FeParameter>,
    initial: FeInitial,
    modes: usize,
    method: FeMethod,
    /// 2r when the initial state is estimated, else 0.
    states: usize,
    /// One constant offset per channel estimated (after the initial state).
    offsets: bool,
}

/// The response at the measured channels on every k-th sample, and its sensitivities.
#[derive(Debug, Clone)]
pub(crate) struct Evaluation {
    /// y\[c\]\[i\]: channel c at sample i k.
    pub(crate) y: Vec<Vec<f64>>,
    /// jac\[j\]\[c\]\[i\]: d y\[c\]\[i\] / d theta_j (unknowns, then the initial state,
    /// then the channels' offsets).
    pub(crate) jac: Vec<Vec<Vec<f64>>>,
    /// The decimation k.
    pub(crate) k: usize,
    /// units\[j\] = the responses to U_j = 1 and U_j = i (channels x samples).
    pub(crate) units: Vec<Vec<Vec<Vec<f64>>>>,
}

impl FeProblem {
    /// A problem for `rotor`'s structure (checked: every output a degree of freedom of the
    /// matrices, every unknown a parameter of the rotor, modes >= 1).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rotor: &FiniteElementRotor,
        outputs: Vec<Dof>,
        speed: SpeedProfile,
        dt: f64,
        samples: usize,
        unknowns: Vec<FeParameter>,
        initial: FeInitial,
        modes: usize,
    ) -> Result<Self, FeRefineError> {
        for d in &outputs {
            if rotor.matrices.index(*d).is_none() {
                return Err(FeRefineError::Record(format!(
                    "channel {d} is not a degree of freedom of the matrices (they have {})",
                    rotor
                        .matrices
                        .dofs()
                        .iter()
                        .map(Dof::to_string)
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        }
        for p in &unknowns {
            if p.get(rotor).is_none() {
                return Err(FeRefineError::Record(format!(
                    "unknown {p}: the rotor has {} bearing(s) and {} unbalance(s)",
                    rotor.bearings.len(),
                    rotor.unbalances.len()
                )));
            }
        }
        let n = rotor.matrices.n();
        if modes == 0 || modes > n {
            return Err(FeRefineError::Record(format!(
                "modes = {modes}: allowed 1 ..= {n} (the degrees of freedom)"
            )));
        }
        let r = crate::model::finite_element::RitzBasis::new(rotor, modes)?.len();
        Ok(Self {
            outputs,
            speed,
            dt,
            samples,
            unknowns,
            initial,
            modes,
            method: if speed.is_constant() {
                FeMethod::Exact
            } else {
                FeMethod::Magnus
            },
            states: match initial {
                FeInitial::Rest => 0,
                FeInitial::Estimated => 2 * r,
            },
            offsets: false,
        })
    }

    /// The same problem with one constant offset per channel estimated (`on`) or not: a
    /// conditioned raw record keeps the mean of the motion over its revolutions in each
    /// probe's DC, so its channels are the motion less an unknown constant.
    pub fn with_offsets(mut self, on: bool) -> Self {
        self.offsets = on;
        self
    }

    /// Whether each channel's constant offset is estimated.
    pub fn offsets(&self) -> bool {
        self.offsets
    }

    /// The number of initial-state unknowns (0 or 2r), first among the nuisance ones.
    pub fn states(&self) -> usize {
        self.states
    }

    /// The unknown parameters, in order.
    pub fn unknowns(&self) -> &[FeParameter] {
        &self.unknowns
    }

    /// The number of nuisance unknowns: the initial state (0 or 2r) then, when estimated,
    /// one offset per channel.
    pub fn nuisance(&self) -> usize {
        self.states + if self.offsets { self.outputs.len() } else { 0 }
    }

    /// Modes in the basis.
    pub fn modes(&self) -> usize {
        self.modes
    }

    /// The measured channels.
    pub fn outputs(&self) -> &[Dof] {
        &self.outputs
    }

    /// The sampling period \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Samples per channel.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// How the initial state is treated.
    pub fn initial(&self) -> FeInitial {
        self.initial
    }

    /// Simulate `system` on every k-th sample of the first `n` from `init` (None: rest).
    pub(crate) fn simulate(
        &self,
        system: &FeSystem,
        (k, n): (usize, usize),
        init: Option<&FeInitialState>,
    ) -> Result<Vec<Vec<f64>>, FeRefineError> {
        let steps = (n.min(self.samples) - 1) / k;
        let h = self.dt * k as f64;
        let sampling = Sampling::new(h, (steps.max(1)) as f64 * h)?;
        let r = simulate_fe(
            system,
            &self.speed,
            &sampling,
            init,
            Some(&self.outputs),
            self.method,
        )?;
        let mut q = r.q;
        for c in &mut q {
            c.truncate(steps + 1);
        }
        Ok(q)
    }

    /// The response of `rotor` (reduced to `basis`) from the initial state in `x0` (its
    /// first [`states`](Self::states) entries, reduced coordinates; none at rest) plus the
    /// channels' offsets (its last entries, when estimated) on every k-th of the first n
    /// samples (`at` = (k, n)), with the sensitivities when `jacobian`.
    pub(crate) fn evaluate(
        &self,
        rotor: &FiniteElementRotor,
        basis: &DMatrix<f64>,
        x0: &DVector<f64>,
        at: (usize, usize),
        jacobian: bool,
    ) -> Result<Evaluation, FeRefineError> {
        let k = at.0;
        let mut sys = FeSystem::reduced(rotor, basis)?;
        // unit responses of each unbalance: U = 1 and U = i, from rest
        let mut unit = rotor.clone();
        for u in unit.unbalances.iter_mut() {
            u.mud = 0.0;
        }
        let mut units = Vec::with_capacity(rotor.unbalances.len());
        for j in 0..rotor.unbalances.len() {
            let mut pair = Vec::with_capacity(2);
            for alpha in [0.0, std::f64::consts::FRAC_PI_2] {
                let mut one = unit.clone();
                one.unbalances[j].mud = 1.0;
                one.unbalances[j].alpha = alpha;
                sys.update(&one)?;
                pair.push(self.simulate(&sys, at, None)?);
            }
            units.push(pair);
        }
        // free responses of each reduced initial coordinate
        let mut free = Vec::with_capacity(self.states);
        if self.states > 0 {
            sys.update(&unit)?;
            for i in 0..self.states {
                let mut e = DVector::zeros(self.states);
                e[i] = 1.0;
                let init = full_initial(basis, &e);
                free.push(self.simulate(&sys, at, Some(&init))?);
            }
        }
        let len = units
            .first()
            .map(|p| p[0][0].len())
            .or_else(|| free.first().map(|f| f[0].len()))
            .unwrap_or((at.1.min(self.samples) - 1) / k + 1);
        let nc = self.outputs.len();
        let mut y = vec![vec![0.0; len]; nc];
        let combine = |y: &mut Vec<Vec<f64>>, a: f64, z: &[Vec<f64>]| {
            if a != 0.0 {
                for (yc, zc) in y.iter_mut().zip(z) {
                    for (v, w) in yc.iter_mut().zip(zc) {
                        *v += a * w;
                    }
                }
            }
        };
        for (u, pair) in rotor.unbalances.iter().zip(&units) {
            let c = Complex::from_polar(u.mud, u.alpha);
            combine(&mut y, c.re, &pair[0]);
            combine(&mut y, c.im, &pair[1]);
        }
        for (i, f) in free.iter().enumerate() {
            combine(&mut y, x0[i], f);
        }
        if self.offsets {
            for (c, yc) in y.iter_mut().enumerate() {
                let o = x0[self.states + c];
                yc.iter_mut().for_each(|v| *v += o);
            }
        }
        let mut jac = Vec::new();
        if jacobian {
            let init = (self.states > 0).then(|| full_initial(basis, x0));
            for &p in &self.unknowns {
                let mut col = vec![vec![0.0; len]; nc];
                match p {
                    FeParameter::Bearing { index, coefficient } => {
                        let h = FD_STEP * scale(rotor, index, coefficient);
                        let mut moved = rotor.clone();
                        let v = p.get(rotor).unwrap_or(0.0);
                        p.set(&mut moved, v + h);
                        sys.update(&moved)?;
                        let yp = self.simulate(&sys, at, init.as_ref())?;
                        for (c, ((cc, ypc), yc)) in col.iter_mut().zip(&yp).zip(&y).enumerate() {
                            // y holds the offsets, the moved response does not
                            let o = if self.offsets {
                                x0[self.states + c]
                            } else {
                                0.0
                            };
                            for ((d, a), b) in cc.iter_mut().zip(ypc).zip(yc) {
                                *d = (a + o - b) / h;
                            }
                        }
                    }
                    FeParameter::Mud { index } => {
                        let e = Complex::from_polar(1.0, rotor.unbalances[index].alpha);
                        combine(&mut col, e.re, &units[index][0]);
                        combine(&mut col, e.im, &units[index][1]);
                    }
                    FeParameter::Alpha { index } => {
                        let u = &rotor.unbalances[index];
                        let c = Complex::from_polar(u.mud, u.alpha);
                        combine(&mut col, -c.im, &units[index][0]);
                        combine(&mut col, c.re, &units[index][1]);
                    }
                }
                jac.push(col);
            }
            jac.extend(free);
            if self.offsets {
                for c in 0..nc {
                    let mut col = vec![vec![0.0; len]; nc];
                    col[c].fill(1.0);
                    jac.push(col);
                }
            }
        }
        Ok(Evaluation { y, jac, k, units })
    }
}

/// The scale of a bearing coefficient \[its unit\]: |value| for a direct one (> 0), sqrt of
/// the product of the direct ones for a cross one (damping: at least 1 N s/m).
pub(crate) fn scale(rotor: &FiniteElementRotor, index: usize, c: BearingCoefficient) -> f64 {
    let b = &rotor.bearings[index];
    let (value, direct) = if c.is_stiffness() {
        let (i, j) = c.entry();
        (b.stiffness()[i][j], (b.kxx * b.kyy).abs().sqrt())
    } else {
        let (i, j) = c.entry();
        (b.damping()[i][j], (b.cxx * b.cyy).abs().sqrt())
    };
    let s = if c.is_cross() {
        direct.max(value.abs())
    } else {
        value.abs().max(direct * 1e-3)
    };
    if c.is_stiffness() {
        s.max(1e-300)
    } else {
        s.max(1.0)
    }
}

impl Evaluation {
    /// sqrt(mean residual^2) per channel as weights 1 / sigma^2 (floored).
    pub(crate) fn residual_weights(&self, y: &[&[f64]], k: usize) -> Vec<f64> {
        self.y
            .iter()
            .zip(y)
            .map(|(m, d)| {
                let (mut s, mut n) = (0.0, 0.0);
                for (i, v) in m.iter().enumerate() {
                    let r = d[i * k] - v;
                    s += r * r;
                    n += 1.0;
                }
                let scale = d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64;
                let var = (s / n).max(1e-30 * scale).max(f64::MIN_POSITIVE);
                1.0 / var
            })
            .collect()
    }

    /// sum_c w_c sum_i r_c,i^2.
    pub(crate) fn cost(&self, y: &[&[f64]], k: usize, w: &[f64]) -> f64 {
        self.y
            .iter()
            .zip(y)
            .zip(w)
            .map(|((m, d), w)| {
                w * m
                    .iter()
                    .enumerate()
                    .map(|(i, v)| {
                        let r = d[i * k] - v;
                        r * r
                    })
                    .sum::<f64>()
            })
            .sum()
    }
}

impl Evaluation {
    /// Move the parameters that enter linearly to their weighted least-squares optimum for
    /// the others (variable projection): each unbalance whose mud and alpha are both
    /// unknown (the response is linear in U = mud e^{i alpha}) and the initial state. The
    /// response and the unbalances' sensitivity columns are updated exactly. After it, a
    /// joint Gauss-Newton step is Kaufman's variable-projection step.
    pub(crate) fn solve_linear(
        &mut self,
        problem: &FeProblem,
        rotor: &mut FiniteElementRotor,
        x0: &mut DVector<f64>,
        data: &[&[f64]],
        w: &[f64],
    ) {
        if self.jac.is_empty() {
            return;
        }
        let unknowns = problem.unknowns();
        let np = unknowns.len();
        let mut lin: Vec<usize> = Vec::new();
        let mut pairs: Vec<(usize, usize, usize)> = Vec::new();
        for (i, p) in unknowns.iter().enumerate() {
            if let FeParameter::Mud { index } = *p {
                if let Some(ia) = unknowns
                    .iter()
                    .position(|q| *q == FeParameter::Alpha { index })
                {
                    if rotor.unbalances[index].mud > 0.0 {
                        lin.push(i);
                        lin.push(ia);
                        pairs.push((index, i, ia));
                    }
                }
            }
        }
        lin.extend(np..self.jac.len());
        if lin.is_empty() {
            return;
        }
        let sub = Evaluation {
            y: self.y.clone(),
            jac: lin.iter().map(|&i| self.jac[i].clone()).collect(),
            k: self.k,
            units: Vec::new(),
        };
        let (a, g) = normal_equations(&sub, Some((data, self.k)), w);
        let Some(delta) = super::result::inverse(&a).map(|c| c * g) else {
            return;
        };
        // y += J_L delta (exact: linear)
        for (col, &i) in lin.iter().enumerate() {
            let d = delta[col];
            for (yc, jc) in self.y.iter_mut().zip(&self.jac[i]) {
                for (v, j) in yc.iter_mut().zip(jc) {
                    *v += d * j;
                }
            }
        }
        for (col, &i) in lin.iter().enumerate() {
            if i >= np {
                x0[i - np] += delta[col];
            }
        }
        for &(j, im, ia) in &pairs {
            let (cm, ca) = (
                lin.iter().position(|&x| x == im).unwrap_or(0),
                lin.iter().position(|&x| x == ia).unwrap_or(0),
            );
            let u = &mut rotor.unbalances[j];
            let c = Complex::from_polar(u.mud, u.alpha);
            let nc = c
                + Complex::from_polar(1.0, u.alpha) * delta[cm]
                + Complex::new(0.0, 1.0) * c * delta[ca];
            u.mud = nc.norm();
            u.alpha = nc.arg();
            // the columns at the new U
            let e = Complex::from_polar(1.0, u.alpha);
            for (col, (a, b)) in [(im, (e.re, e.im)), (ia, (-nc.im, nc.re))] {
                for ((o, y0), y1) in self.jac[col]
                    .iter_mut()
                    .zip(&self.units[j][0])
                    .zip(&self.units[j][1])
                {
                    for ((v, p), q) in o.iter_mut().zip(y0).zip(y1) {
                        *v = a * p + b * q;
                    }
                }
            }
        }
    }
}

/// 1 / sigma_c^2 with sigma_c each channel's white-noise level from its fourth
/// differences over the first n samples (independent of any model), floored at 1e-9 of
/// the channel's RMS.
pub(crate) fn noise_weights(y: &[&[f64]], (_, n): (usize, usize)) -> Vec<f64> {
    y.iter()
        .map(|c| {
            let c = &c[..n.min(c.len())];
            let mut d = crate::identify::modulating::noise_estimate::DifferenceNoise::default();
            for &v in c {
                d.push(v);
            }
            let rms = (c.iter().map(|v| v * v).sum::<f64>() / c.len().max(1) as f64).sqrt();
            let s = d.sigma().max(1e-9 * rms).max(f64::MIN_POSITIVE.sqrt());
            1.0 / (s * s)
        })
        .collect()
}

/// J^T W J and (with the data) J^T W r.
pub(crate) fn normal_equations(
    e: &Evaluation,
    data: Option<(&[&[f64]], usize)>,
    w: &[f64],
) -> (DMatrix<f64>, DVector<f64>) {
    let p = e.jac.len();
    let mut a = DMatrix::zeros(p, p);
    let mut g = DVector::zeros(p);
    for (c, &wc) in w.iter().enumerate() {
        let r: Option<Vec<f64>> = data.map(|(y, k)| {
            e.y[c]
                .iter()
                .enumerate()
                .map(|(i, v)| y[c][i * k] - v)
                .collect()
        });
        for i in 0..p {
            let ji = &e.jac[i][c];
            for j in 0..=i {
                let s: f64 = ji.iter().zip(&e.jac[j][c]).map(|(a, b)| a * b).sum();
                a[(i, j)] += wc * s;
            }
            if let Some(r) = &r {
                g[i] += wc * ji.iter().zip(r).map(|(a, b)| a * b).sum::<f64>();
            }
        }
    }
    for i in 0..p {
        for j in 0..i {
            a[(j, i)] = a[(i, j)];
        }
    }
    (a, g)
}
