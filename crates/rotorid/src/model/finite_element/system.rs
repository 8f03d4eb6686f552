//! The assembled equation of motion of a finite-element rotor, in any coordinates q_s with
//! q = T q_s (T = I for the full model, a Ritz basis for a reduced one, see
//! [`super::RitzBasis`]):
//!
//! ```text
//! M q'' + (C0 + w G) q' + (K0 + w' Ka) q = F(phi, w, w'),    w = phi', w' = phi''
//! C0 = C + C_b,   K0 = K + K_b
//! C_b = sum over bearings of  sum_ij c_ij b_i b_j^T,   K_b likewise with k_ij
//! F   = Re((w^2 - i w') P e^{i phi}),   P = sum over unbalances of mud e^{i alpha} (b_x - i b_y)
//! ```
//!
//! where b_x, b_y are the location vectors of a node's x and y (the unit vectors e_x, e_y
//! in the full model, their images T^T e_x, T^T e_y in a reduced one). Written out, the
//! force at an unbalance's node is `mud (w^2 cos th + w' sin th, w^2 sin th -
//! w' cos th)`, th = phi + alpha, in (x, y): the real part of (w^2 - i w') e^{i th} (1, -i).
//! P is ROSS's complex unbalance force per w^2 (`Rotor._unbalance_force`: `mud e^{i
//! alpha}` at x, `-i mud e^{i alpha}` at y).
//!
//! Because the bearings enter through their location vectors, a reduced system keeps
//! their coupling exact (T^T K_b T is assembled from T's rows at the bearing nodes, not
//! approximated), and changing a bearing coefficient changes the reduced matrices exactly
//! as the full ones: the derivative of K0 with respect to kxy of a bearing is b_x b_y^T
//! in either ([`FeSystem::derivative`]).

use nalgebra::{Complex, DMatrix, DVector};

use super::error::FiniteElementError;
use super::parameter::FeParameter;
use super::rotor::{Bearing, Dof, DofKind, FeUnbalance, FiniteElementRotor};
use crate::model::SpeedState;

/// How the system's matrices and force depend on one parameter ([`FeSystem::derivative`]).
#[derive(Debug, Clone, PartialEq)]
pub enum FeDerivative {
    /// d K0 / dp (N/m per unit of p); M, C0 and P do not depend on p.
    Stiffness(DMatrix<f64>),
    /// d C0 / dp (N s/m per unit of p); M, K0 and P do not depend on p.
    Damping(DMatrix<f64>),
    /// d P / dp (kg m per unit of p): the force's derivative is Re((w^2 - i w') dP
    /// e^{i phi}); the matrices do not depend on p.
    Load(DVector<Complex<f64>>),
}

/// The equation of motion of a finite-element rotor assembled in some coordinates (module
/// doc): the full model ([`FeSystem::full`]) or a reduced one ([`FeSystem::reduced`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FeSystem {
    /// The physical degrees of freedom (of the full model).
    dofs: Vec<Dof>,
    /// q = T q_s: None for the full model (T = I).
    basis: Option<DMatrix<f64>>,
    /// q_s = Pr q for q in span(T): (T^T M T)^-1 T^T M (None for the full model).
    projector: Option<DMatrix<f64>>,
    m: DMatrix<f64>,
    k: DMatrix<f64>,
    g: DMatrix<f64>,
    c: Option<DMatrix<f64>>,
    ka: Option<DMatrix<f64>>,
    /// Location vectors (b_x, b_y) of each bearing's node.
    bearing_at: Vec<[DVector<f64>; 2]>,
    /// Location vectors (b_x, b_y) of each unbalance's node.
    unbalance_at: Vec<[DVector<f64>; 2]>,
    bearings: Vec<Bearing>,
    unbalances: Vec<FeUnbalance>,
    /// C + C_b \[N s/m\].
    c0: DMatrix<f64>,
    /// K + K_b \[N/m\].
    k0: DMatrix<f64>,
    /// P \[kg m\].
    load: DVector<Complex<f64>>,
}

fn unit(n: usize, i: usize) -> DVector<f64> {
    let mut e = DVector::zeros(n);
    e[i] = 1.0;
    e
}

/// The (x, y) indices of `node` (checked by [`FiniteElementRotor::new`]).
fn xy(rotor: &FiniteElementRotor, node: u32) -> [usize; 2] {
    let at = |kind| {
        rotor
            .matrices
            .index(Dof::new(node, kind))
            .expect("FiniteElementRotor::new checks every bearing and unbalance node has x and y")
    };
    [at(DofKind::X), at(DofKind::Y)]
}

impl FeSystem {
    /// The full model of `rotor` (q_s = q).
    pub fn full(rotor: &FiniteElementRotor) -> Self {
        let mats = &rotor.matrices;
        let n = mats.n();
        let at = |node| xy(rotor, node).map(|i| unit(n, i));
        let mut s = Self {
            dofs: mats.dofs().to_vec(),
            basis: None,
            projector: None,
            m: mats.m().clone(),
            k: mats.k().clone(),
            g: mats.g().clone(),
            c: mats.c().cloned(),
            ka: mats.ka().cloned(),
            bearing_at: rotor.bearings.iter().map(|b| at(b.node)).collect(),
            unbalance_at: rotor.unbalances.iter().map(|u| at(u.node)).collect(),
            bearings: rotor.bearings.clone(),
            unbalances: rotor.unbalances.clone(),
            c0: DMatrix::zeros(0, 0),
            k0: DMatrix::zeros(0, 0),
            load: DVector::zeros(0),
        };
        s.assemble();
        s
    }

    /// `rotor` in the coordinates q_s of `basis` (q = T q_s, T n x r with independent
    /// columns): every matrix projected, T^T X T, and every location vector, T^T b; the
    /// bearings and unbalances then enter exactly as in the full model. Refused when T
    /// does not have n rows or T^T M T is not positive definite (dependent columns).
    pub fn reduced(
        rotor: &FiniteElementRotor,
        basis: &DMatrix<f64>,
    ) -> Result<Self, FiniteElementError> {
        let full = Self::full(rotor);
        let t = basis;
        if t.nrows() != full.len() || t.ncols() == 0 {
            return Err(FiniteElementError::Inconsistent {
                what: format!(
                    "the basis is {} x {}: it must have one row per degree of freedom ({}) \
                     and at least one column",
                    t.nrows(),
                    t.ncols(),
                    full.len()
                ),
            });
        }
        let tt = t.transpose();
        let proj = |a: &DMatrix<f64>| &tt * a * t;
        let projv = |[x, y]: &[DVector<f64>; 2]| [&tt * x, &tt * y];
        let m = symmetric(proj(&full.m));
        let tm = &tt * &full.m;
        // (T^T M T)^-1 T^T M (T^T M T = I for an M-orthonormal basis)
        let projector = m.clone().cholesky().map(|c| c.solve(&tm)).ok_or_else(|| {
            FiniteElementError::Inconsistent {
                what: "the basis has dependent columns: T^T M T is not positive definite"
                    .to_owned(),
            }
        })?;
        let mut s = Self {
            dofs: full.dofs.clone(),
            basis: Some(t.clone()),
            projector: Some(projector),
            m,
            k: proj(&full.k),
            g: proj(&full.g),
            c: full.c.as_ref().map(proj),
            ka: full.ka.as_ref().map(proj),
            bearing_at: full.bearing_at.iter().map(projv).collect(),
            unbalance_at: full.unbalance_at.iter().map(projv).collect(),
            bearings: full.bearings,
            unbalances: full.unbalances,
            c0: DMatrix::zeros(0, 0),
            k0: DMatrix::zeros(0, 0),
            load: DVector::zeros(0),
        };
        s.assemble();
        Ok(s)
    }

    /// Take the bearings' and unbalances' values of `rotor` (same count and nodes as the
    /// system was built with; the matrices and the basis are kept).
    pub fn update(&mut self, rotor: &FiniteElementRotor) -> Result<(), FiniteElementError> {
        let same_nodes = rotor.bearings.len() == self.bearings.len()
            && rotor.unbalances.len() == self.unbalances.len()
            && rotor
                .bearings
                .iter()
                .zip(&self.bearings)
                .all(|(a, b)| a.node == b.node)
            && rotor
                .unbalances
                .iter()
                .zip(&self.unbalances)
                .all(|(a, b)| a.node == b.node);
        if !same_nodes {
            return Err(FiniteElementError::Inconsistent {
                what: "the rotor's bearings and unbalances (their number and nodes) differ \
                       from those the system was built with"
                    .to_owned(),
            });
        }
        self.bearings.clone_from(&rotor.bearings);
        self.unbalances.clone_from(&rotor.unbalances);
        self.assemble();
        Ok(())
    }

    fn assemble(&mut self) {
        let n = self.m.nrows();
        let mut c0 = self.c.clone().unwrap_or_else(|| DMatrix::zeros(n, n));
        let mut k0 = self.k.clone();
        for (b, at) in self.bearings.iter().zip(&self.bearing_at) {
            let (kb, cb) = (b.stiffness(), b.damping());
            for i in 0..2 {
                for j in 0..2 {
                    k0.ger(kb[i][j], &at[i], &at[j], 1.0);
                    c0.ger(cb[i][j], &at[i], &at[j], 1.0);
                }
            }
        }
        let mut load = DVector::zeros(n);
        for (u, [bx, by]) in self.unbalances.iter().zip(&self.unbalance_at) {
            let a = Complex::from_polar(u.mud, u.alpha);
            for i in 0..n {
                load[i] += a * Complex::new(bx[i], -by[i]);
            }
        }
        self.c0 = c0;
        self.k0 = k0;
        self.load = load;
    }

    /// Number of coordinates q_s (n for the full model, r for a reduced one).
    pub fn len(&self) -> usize {
        self.m.nrows()
    }

    /// True for a system without coordinates (never, for a valid rotor).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The physical degrees of freedom.
    pub fn dofs(&self) -> &[Dof] {
        &self.dofs
    }

    /// The basis T (q = T q_s), None for the full model.
    pub fn basis(&self) -> Option<&DMatrix<f64>> {
        self.basis.as_ref()
    }

    /// Physical displacements (or velocities) `q` in the system's coordinates: q itself
    /// for the full model, its M-orthogonal projection (T^T M T)^-1 T^T M q on the basis
    /// for a reduced one (exact when q lies in the basis).
    pub fn to_coordinates(&self, q: &DVector<f64>) -> DVector<f64> {
        match &self.projector {
            None => q.clone(),
            Some(p) => p * q,
        }
    }

    /// The bearings the system holds.
    pub fn bearings(&self) -> &[Bearing] {
        &self.bearings
    }

    /// The unbalances the system holds.
    pub fn unbalances(&self) -> &[FeUnbalance] {
        &self.unbalances
    }

    /// M (kg, kg m^2 on rotations; the identity in an M-orthonormal basis).
    pub fn mass(&self) -> &DMatrix<f64> {
        &self.m
    }

    /// G, multiplied by phi'.
    pub fn gyroscopic(&self) -> &DMatrix<f64> {
        &self.g
    }

    /// Ka, multiplied by phi'', if any.
    pub fn ka(&self) -> Option<&DMatrix<f64>> {
        self.ka.as_ref()
    }

    /// C0 = C + C_b \[N s/m\].
    pub fn damping0(&self) -> &DMatrix<f64> {
        &self.c0
    }

    /// K0 = K + K_b \[N/m\].
    pub fn stiffness0(&self) -> &DMatrix<f64> {
        &self.k0
    }

    /// C0 + w G at speed `w` \[rad/s\].
    pub fn damping(&self, w: f64) -> DMatrix<f64> {
        &self.c0 + &self.g * w
    }

    /// K0 + w' Ka at angular acceleration `w_dot` \[rad/s^2\].
    pub fn stiffness(&self, w_dot: f64) -> DMatrix<f64> {
        match &self.ka {
            Some(ka) if w_dot != 0.0 => &self.k0 + ka * w_dot,
            _ => self.k0.clone(),
        }
    }

    /// The unbalance load P \[kg m\] (module doc).
    pub fn load(&self) -> &DVector<Complex<f64>> {
        &self.load
    }

    /// The unbalance force F(phi, w, w') \[N\] (module doc).
    pub fn force(&self, s: &SpeedState) -> DVector<f64> {
        force_of(&self.load, s)
    }

    /// The map from q_s to the degrees of freedom `dofs` (a selection of rows of T), or
    /// the first one the rotor does not have.
    pub fn output_map(&self, dofs: &[Dof]) -> Result<DMatrix<f64>, FiniteElementError> {
        let n = self.dofs.len();
        let mut out = DMatrix::zeros(dofs.len(), self.len());
        for (r, d) in dofs.iter().enumerate() {
            let i = self.dofs.iter().position(|e| e == d).ok_or_else(|| {
                FiniteElementError::UnknownDof {
                    name: d.to_string(),
                    n,
                }
            })?;
            match &self.basis {
                None => out[(r, i)] = 1.0,
                Some(t) => out.row_mut(r).copy_from(&t.row(i)),
            }
        }
        Ok(out)
    }

    /// The derivative of the system with respect to `p` (module doc): a bearing
    /// coefficient k_ij of bearing b is the matrix b_i b_j^T in K0 (c_ij likewise in C0);
    /// an unbalance's mud and alpha enter P only.
    pub fn derivative(&self, p: FeParameter) -> Result<FeDerivative, FiniteElementError> {
        let unknown = || FiniteElementError::UnknownParameter {
            name: p.to_string(),
            allowed: format!(
                "the system has {} bearing(s) and {} unbalance(s)",
                self.bearings.len(),
                self.unbalances.len()
            ),
        };
        match p {
            FeParameter::Bearing { index, coefficient } => {
                let at = self.bearing_at.get(index).ok_or_else(unknown)?;
                let (i, j) = coefficient.entry();
                let d = &at[i] * at[j].transpose();
                Ok(if coefficient.is_stiffness() {
                    FeDerivative::Stiffness(d)
                } else {
                    FeDerivative::Damping(d)
                })
            }
            FeParameter::Mud { index } | FeParameter::Alpha { index } => {
                let u = self.unbalances.get(index).ok_or_else(unknown)?;
                let [bx, by] = &self.unbalance_at[index];
                // P_j = mud e^{i alpha} (b_x - i b_y): d/dmud = e^{i alpha} (..),
                // d/dalpha = i mud e^{i alpha} (..)
                let a = if matches!(p, FeParameter::Mud { .. }) {
                    Complex::from_polar(1.0, u.alpha)
                } else {
                    Complex::<f64>::i() * Complex::from_polar(u.mud, u.alpha)
                };
                Ok(FeDerivative::Load(DVector::from_fn(bx.len(), |i, _| {
                    a * Complex::new(bx[i], -by[i])
                })))
            }
        }
    }

    /// The closed-form steady-state 1X response at constant speed `w` \[rad/s\]: Q with
    /// q_s(t) = Re(Q e^{i phi(t)}), the solution of
    /// `(K0 - w^2 M + i w (C0 + w G)) Q = w^2 P` (complex LU with partial pivoting).
    /// The system must not be singular there (a rotor without damping at a critical
    /// speed is).
    pub fn steady_state(&self, w: f64) -> Result<DVector<Complex<f64>>, FiniteElementError> {
        let n = self.len();
        let c = self.damping(w);
        let a = DMatrix::from_fn(n, n, |i, j| {
            Complex::new(self.k0[(i, j)] - w * w * self.m[(i, j)], w * c[(i, j)])
        });
        let rhs = self.load.map(|p| p * (w * w));
        let lu = a.lu();
        let q = lu.solve(&rhs);
        match q {
            Some(q) if q.iter().all(|z| z.re.is_finite() && z.im.is_finite()) => Ok(q),
            _ => Err(FiniteElementError::SingularSteadyState { omega: w }),
        }
    }
}

/// F = Re((w^2 - i w') P e^{i phi}) for a load P.
pub(crate) fn force_of(load: &DVector<Complex<f64>>, s: &SpeedState) -> DVector<f64> {
    let z = Complex::new(s.omega * s.omega, -s.omega_dot) * Complex::from_polar(1.0, s.phi);
    load.map(|p| (p * z).re)
}

/// (A + A^T) / 2.
fn symmetric(a: DMatrix<f64>) -> DMatrix<f64> {
    (&a + a.transpose()) * 0.5
}

#[cfg(test)]
pub(crate) mod tests {
    use std::sync::Arc;

    use super::super::parameter::BearingCoefficient;
    use super::super::rotor::FeMatrices;
    use super::*;

    /// Two nodes with x, y, rx, ry; distinct entries everywhere so that a wrong index shows.
    pub(crate) fn small_rotor() -> FiniteElementRotor {
        let dofs: Vec<Dof> = ["0.x", "0.y", "0.rx", "0.ry", "1.x", "1.y", "1.rx", "1.ry"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let n = 8;
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0);
        let m = &a * a.transpose() + DMatrix::identity(n, n) * 2.0;
        let k = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                4e5
            } else {
                1e4 * ((i + j) % 3) as f64
            }
        });
        let g = DMatrix::from_fn(n, n, |i, j| (i as f64 - j as f64) * 0.01);
        let ka = DMatrix::from_fn(n, n, |i, j| if i < j { 0.02 } else { 0.0 });
        let mats = FeMatrices::new(dofs, m, k, g, None, Some(ka)).unwrap();
        let b = Bearing {
            node: 0,
            kxx: 1e6,
            kxy: -2e5,
            kyx: 3e5,
            kyy: 1.2e6,
            cxx: 300.0,
            cxy: 10.0,
            cyx: -20.0,
            cyy: 400.0,
        };
        let u = FeUnbalance {
            node: 1,
            mud: 1e-4,
            alpha: 0.7,
        };
        FiniteElementRotor::new(Arc::new(mats), vec![b, Bearing { node: 1, ..b }], vec![u]).unwrap()
    }

    #[test]
    fn bearings_add_their_matrices_at_their_nodes_x_and_y() {
        let r = small_rotor();
        let s = FeSystem::full(&r);
        let kb = s.stiffness0() - r.matrices.k();
        let cb = s.damping0();
        // node 0's x, y are rows 0, 1; node 1's are 4, 5
        for (base, b) in [(0, r.bearings[0]), (4, r.bearings[1])] {
            let (k, c) = (b.stiffness(), b.damping());
            for i in 0..2 {
                for j in 0..2 {
                    assert_eq!(kb[(base + i, base + j)], k[i][j]);
                    assert_eq!(cb[(base + i, base + j)], c[i][j]);
                }
            }
        }
        let nonzero = kb.iter().filter(|v| **v != 0.0).count();
        assert_eq!(nonzero, 8);
    }

    #[test]
    fn force_is_the_documented_formula_at_the_unbalance_node() {
        let r = small_rotor();
        let s = FeSystem::full(&r);
        let u = r.unbalances[0];
        let st = SpeedState {
            phi: 1.3,
            omega: 210.0,
            omega_dot: -35.0,
        };
        let f = s.force(&st);
        let th = st.phi + u.alpha;
        let (w2, wd) = (st.omega * st.omega, st.omega_dot);
        let fx = u.mud * (w2 * th.cos() + wd * th.sin());
        let fy = u.mud * (w2 * th.sin() - wd * th.cos());
        assert!((f[4] - fx).abs() < 1e-14 * fx.abs().max(fy.abs()));
        assert!((f[5] - fy).abs() < 1e-14 * fx.abs().max(fy.abs()));
        assert_eq!(f.iter().filter(|v| **v != 0.0).count(), 2);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let r = small_rotor();
        let s = FeSystem::full(&r);
        let st = SpeedState {
            phi: 0.4,
            omega: 150.0,
            omega_dot: 20.0,
        };
        for p in FeParameter::all(&r) {
            let v = p.get(&r).unwrap();
            let h = 1e-6 * v.abs().max(1e-3);
            let mut r2 = r.clone();
            p.set(&mut r2, v + h);
            let mut s2 = s.clone();
            s2.update(&r2).unwrap();
            let dk = (s2.stiffness0() - s.stiffness0()) / h;
            let dc = (s2.damping0() - s.damping0()) / h;
            let df = (s2.force(&st) - s.force(&st)) / h;
            let zero = DMatrix::<f64>::zeros(8, 8);
            let (ek, ec, ef) = match s.derivative(p).unwrap() {
                FeDerivative::Stiffness(d) => (d, zero.clone(), DVector::zeros(8)),
                FeDerivative::Damping(d) => (zero.clone(), d, DVector::zeros(8)),
                FeDerivative::Load(dp) => (zero.clone(), zero.clone(), force_of(&dp, &st)),
            };
            let tol = |e: f64| 1e-6 * e.max(1e-12);
            assert!((&dk - &ek).amax() <= tol(ek.amax()), "{p}: {dk} vs {ek}");
            assert!((&dc - &ec).amax() <= tol(ec.amax()), "{p}");
            assert!(
                (&df - &ef).amax() <= 1e-5 * ef.amax().max(1e-12),
                "{p}: {df} vs {ef}"
            );
        }
        let e = s
            .derivative(FeParameter::Bearing {
                index: 2,
                coefficient: BearingCoefficient::Kxx,
            })
            .unwrap_err();
        assert!(e.to_string().contains("bearing2.kxx"), "{e}");
    }

    #[test]
    fn steady_state_satisfies_the_equation_of_motion_in_real_arithmetic() {
        // q(t) = Re(Q e^{i w t}) put into M q'' + (C0 + w G) q' + K0 q = F(t) at a few t
        let r = small_rotor();
        let s = FeSystem::full(&r);
        let w = 333.0;
        let q = s.steady_state(w).unwrap();
        let c = s.damping(w);
        let scale = s.force(&SpeedState {
            phi: 0.0,
            omega: w,
            omega_dot: 0.0,
        });
        for t in [0.0, 1e-3, 7.7e-3] {
            let e = Complex::from_polar(1.0, w * t);
            let x = q.map(|z| (z * e).re);
            let v = q.map(|z| (z * e * Complex::new(0.0, w)).re);
            let a = q.map(|z| (z * e).re * -w * w);
            let st = SpeedState {
                phi: w * t,
                omega: w,
                omega_dot: 0.0,
            };
            let res = s.mass() * a + &c * v + s.stiffness0() * x - s.force(&st);
            assert!(res.amax() < 1e-10 * scale.amax(), "{res}");
        }
    }
}
