//! Model reduction of a finite-element rotor by a Ritz basis (a Craig-Bampton-like basis
//! without interface partition; docs/finite_element.md section 4):
//!
//! 1. the lowest `modes` undamped modes of (M, K_s), K_s the symmetric part of K + K_b at
//!    the nominal bearings (M-orthonormal: Cholesky M = L L^T, then the symmetric
//!    eigenproblem of L^-1 K_s L^-T);
//! 2. static shapes: the displacement under a unit load in x and in y at every bearing
//!    node and every unbalance node, solved by K + K_b (LU), since the bearing forces act
//!    at the bearing nodes and the unbalance forces at theirs and excite the modes that
//!    are left out;
//! 3. the columns made M-orthonormal together (eigen-decomposition of their Gram matrix in
//!    M, dropping the directions whose Gram eigenvalue is below 1e-12 of the largest:
//!    a static shape that the modes already span adds nothing), then rotated to diagonalise
//!    K_s within the basis, so T^T M T = I and T^T K_s T = diag(w_r^2), columns sorted by
//!    w_r.
//!
//! The reduced system ([`super::FeSystem::reduced`]) keeps the bearings exact in the
//! basis: T^T K_b T is assembled from T's rows at the bearing nodes for whatever
//! coefficients the rotor has (the basis is made at the nominal ones and may be rebuilt
//! when they move far).

use nalgebra::{DMatrix, SymmetricEigen};

use super::error::FiniteElementError;
use super::rotor::{Dof, DofKind, FiniteElementRotor};
use super::system::FeSystem;

/// Relative Gram eigenvalue below which a basis direction counts as dependent.
const DEPENDENT: f64 = 1e-12;

/// A Ritz basis T (n x r) for a finite-element rotor (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct RitzBasis {
    t: DMatrix<f64>,
    modes: usize,
    statics: usize,
    frequencies: Vec<f64>,
}

impl RitzBasis {
    /// The lowest `modes` modes of `rotor` (1 ..= n) at its bearings' values plus the
    /// static shapes at its bearing and unbalance nodes (module doc).
    pub fn new(rotor: &FiniteElementRotor, modes: usize) -> Result<Self, FiniteElementError> {
        let full = FeSystem::full(rotor);
        let n = full.len();
        if modes == 0 || modes > n {
            return Err(FiniteElementError::ModeCount { modes, n });
        }
        let m = full.mass();
        let k = full.stiffness0();
        let ks = (k + k.transpose()) * 0.5;
        // 1. modes: L^-1 Ks L^-T v = l v, phi = L^-T v
        let l = m
            .clone()
            .cholesky()
            .ok_or(FiniteElementError::MassNotPositiveDefinite)?
            .l();
        let linv = l
            .clone()
            .try_inverse()
            .ok_or(FiniteElementError::MassNotPositiveDefinite)?;
        let a = &linv * &ks * linv.transpose();
        let eig = SymmetricEigen::new((&a + a.transpose()) * 0.5);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let lt_inv = linv.transpose();
        let mut cols: Vec<nalgebra::DVector<f64>> = order[..modes]
            .iter()
            .map(|&i| &lt_inv * eig.eigenvectors.column(i))
            .collect();
        // 2. static shapes at the bearing and unbalance nodes
        let mut nodes: Vec<u32> = rotor.bearings.iter().map(|b| b.node).collect();
        nodes.extend(rotor.unbalances.iter().map(|u| u.node));
        nodes.sort_unstable();
        nodes.dedup();
        let lu = k.clone().lu();
        let mut statics = 0;
        for node in nodes {
            for kind in [DofKind::X, DofKind::Y] {
                let i = full
                    .dofs()
                    .iter()
                    .position(|&d| d == Dof::new(node, kind))
                    .expect("bearing and unbalance nodes have x and y (FiniteElementRotor::new)");
                let mut e = nalgebra::DVector::zeros(n);
                e[i] = 1.0;
                let x = lu
                    .solve(&e)
                    .filter(|x| x.iter().all(|v| v.is_finite()))
                    .ok_or(FiniteElementError::SingularStiffness)?;
                cols.push(x);
                statics += 1;
            }
        }
        // 3. M-orthonormalise together, then diagonalise Ks in the basis
        let v = DMatrix::from_columns(&cols);
        let gram = v.transpose() * m * &v;
        let ge = SymmetricEigen::new((&gram + gram.transpose()) * 0.5);
        let top = ge.eigenvalues.max();
        let keep: Vec<usize> = (0..ge.eigenvalues.len())
            .filter(|&i| ge.eigenvalues[i] > DEPENDENT * top)
            .collect();
        let w = DMatrix::from_columns(
            &keep
                .iter()
                .map(|&i| &v * ge.eigenvectors.column(i) / ge.eigenvalues[i].sqrt())
                .collect::<Vec<_>>(),
        );
        let kr = w.transpose() * &ks * &w;
        let ke = SymmetricEigen::new((&kr + kr.transpose()) * 0.5);
        let mut order: Vec<usize> = (0..ke.eigenvalues.len()).collect();
        order.sort_by(|&i, &j| ke.eigenvalues[i].total_cmp(&ke.eigenvalues[j]));
        let t = DMatrix::from_columns(
            &order
                .iter()
                .map(|&i| &w * ke.eigenvectors.column(i))
                .collect::<Vec<_>>(),
        );
        let frequencies = order
            .iter()
            .map(|&i| ke.eigenvalues[i].max(0.0).sqrt())
            .collect();
        Ok(Self {
            t,
            modes,
            statics: statics.min(keep.len().saturating_sub(modes)),
            frequencies,
        })
    }

    /// T (n x r): q = T q_r.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.t
    }

    /// r, the number of basis vectors (modes plus independent static shapes).
    pub fn len(&self) -> usize {
        self.t.ncols()
    }

    /// True for an empty basis (never: at least one mode).
    pub fn is_empty(&self) -> bool {
        self.t.ncols() == 0
    }

    /// The number of modes asked for.
    pub fn modes(&self) -> usize {
        self.modes
    }

    /// The number of static shapes kept (independent of the modes).
    pub fn statics(&self) -> usize {
        self.statics
    }

    /// sqrt of T^T K_s T's diagonal \[rad/s\], ascending: the undamped natural
    /// frequencies at rest of the reduced model (the first `modes` equal the full
    /// model's to rounding).
    pub fn frequencies(&self) -> &[f64] {
        &self.frequencies
    }

    /// The reduced system of `rotor` in this basis ([`FeSystem::reduced`]).
    pub fn system(&self, rotor: &FiniteElementRotor) -> FeSystem {
        FeSystem::reduced(rotor, &self.t)
    }
}

#[cfg(test)]
mod tests {
    use super::super::system::tests::small_rotor;
    use super::*;

    #[test]
    fn basis_is_m_orthonormal_and_keeps_the_lowest_frequencies() {
        let r = small_rotor();
        let full = FeSystem::full(&r);
        let b = RitzBasis::new(&r, 2).unwrap();
        let t = b.matrix();
        let gram = t.transpose() * full.mass() * t;
        let eye = DMatrix::<f64>::identity(b.len(), b.len());
        assert!((gram - eye).amax() < 1e-12);
        // 2 modes + static shapes at nodes 0, 1 (x, y): 6, all independent here
        assert_eq!((b.modes(), b.statics(), b.len()), (2, 4, 6));
        // the full basis (n vectors) reproduces the full model's frequencies
        let all = RitzBasis::new(&r, 8).unwrap();
        assert_eq!(all.len(), 8);
        let ks = (full.stiffness0() + full.stiffness0().transpose()) * 0.5;
        let l = full.mass().clone().cholesky().unwrap().l();
        let li = l.try_inverse().unwrap();
        let mut ev: Vec<f64> = SymmetricEigen::new(&li * ks * li.transpose())
            .eigenvalues
            .iter()
            .map(|v| v.sqrt())
            .collect();
        ev.sort_by(f64::total_cmp);
        for (a, e) in all.frequencies().iter().zip(&ev) {
            assert!((a - e).abs() < 1e-9 * e, "{a} vs {e}");
        }
        // the lowest two of the reduced model: Rayleigh-Ritz upper bounds, equal here
        // because the modes are in the basis
        for (a, e) in b.frequencies().iter().zip(&ev).take(2) {
            assert!((a - e).abs() < 1e-9 * e, "{a} vs {e}");
        }
        assert!(matches!(
            RitzBasis::new(&r, 9),
            Err(FiniteElementError::ModeCount { modes: 9, n: 8 })
        ));
    }
}
