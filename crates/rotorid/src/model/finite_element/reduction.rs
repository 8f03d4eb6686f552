//! Model reduction of a finite-element rotor by a Ritz basis (a Craig-Bampton-like basis
//! without interface partition; docs/finite_element.md section 4):
//!
//! 1. the lowest `modes` undamped modes of (M, K_s), K_s the symmetric part of K + K_b at
//!    the nominal bearings (M-orthonormal: Cholesky M = L L^T, then the symmetric
//!    eigenproblem of L^-1 K_s L^-T);
//! 2. static shapes: the displacement under a unit load in x and in y at every bearing
//!    node and every unbalance node, and under a unit moment about x and about y at every
//!    unbalance node and every disk (a node whose G\[rx, ry\] is at least 0.1 of the
//!    largest), solved by K + K_b (LU): the bearing forces act at the bearing nodes, the
//!    unbalance forces at theirs and the gyroscopic moments at the disks, and each
//!    excites the modes that are left out (the moments matter: on the ROSS two-disk
//!    rotor they take the reduction error from 6e-4 to 1e-6, docs/finite_element.md);
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

/// The nodes where the gyroscopic moments act (disks): whose rx-ry entry of G is at least
/// this fraction of the largest.
const GYROSCOPIC_NODE: f64 = 0.1;

/// Nodes whose G\[rx, ry\] entry is at least [`GYROSCOPIC_NODE`] of the largest (the
/// disks: a shaft element's own polar inertia is far smaller).
fn gyroscopic_nodes(full: &FeSystem) -> Vec<u32> {
    let dofs = full.dofs();
    let g = full.gyroscopic();
    let entry = |node: u32| {
        let rx = dofs
            .iter()
            .position(|&d| d == Dof::new(node, DofKind::Rx))?;
        let ry = dofs
            .iter()
            .position(|&d| d == Dof::new(node, DofKind::Ry))?;
        Some(g[(rx, ry)].abs())
    };
    let mut nodes: Vec<u32> = dofs.iter().map(|d| d.node).collect();
    nodes.dedup();
    let top = nodes.iter().filter_map(|&n| entry(n)).fold(0.0, f64::max);
    nodes
        .into_iter()
        .filter(|&n| top > 0.0 && entry(n).is_some_and(|e| e >= GYROSCOPIC_NODE * top))
        .collect()
}

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
        Self::build(rotor, modes, true)
    }

    /// The lowest `modes` modes only, without static shapes: the classical modal
    /// truncation, for comparison (docs/finite_element.md section 4 measures what leaving
    /// out the static shapes costs).
    pub fn modes_only(
        rotor: &FiniteElementRotor,
        modes: usize,
    ) -> Result<Self, FiniteElementError> {
        Self::build(rotor, modes, false)
    }

    fn build(
        rotor: &FiniteElementRotor,
        modes: usize,
        with_statics: bool,
    ) -> Result<Self, FiniteElementError> {
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
        // 2. static shapes: x, y at the bearing and unbalance nodes; rx, ry at the
        // unbalance nodes and the gyroscopic nodes (the disks)
        let mut loads: Vec<Dof> = Vec::new();
        if with_statics {
            for node in rotor
                .bearings
                .iter()
                .map(|b| b.node)
                .chain(rotor.unbalances.iter().map(|u| u.node))
            {
                loads.extend([Dof::new(node, DofKind::X), Dof::new(node, DofKind::Y)]);
            }
            for node in rotor
                .unbalances
                .iter()
                .map(|u| u.node)
                .chain(gyroscopic_nodes(&full))
            {
                loads.extend([Dof::new(node, DofKind::Rx), Dof::new(node, DofKind::Ry)]);
            }
        }
        loads.sort_unstable();
        loads.dedup();
        let lu = k.clone().lu();
        let mut statics = 0;
        for load in loads {
            let Some(i) = full.dofs().iter().position(|&d| d == load) else {
                continue; // a node without rotations: its moments have nowhere to act
            };
            let mut e = nalgebra::DVector::zeros(n);
            e[i] = 1.0;
            let x = lu
                .solve(&e)
                .filter(|x| x.iter().all(|v| v.is_finite()))
                .ok_or(FiniteElementError::SingularStiffness)?;
            cols.push(x);
            statics += 1;
        }
        // each column to unit M-norm first, so that the dependence test below compares
        // directions, not the scales of a mode (1) and a static shape (~1e-6 m/N)
        for c in &mut cols {
            let norm = c.dot(&(m * &*c)).sqrt();
            if norm > 0.0 && norm.is_finite() {
                *c /= norm;
            }
        }
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

    /// The reduced system of `rotor` in this basis ([`FeSystem::reduced`]); `rotor` must
    /// have the degrees of freedom the basis was made for.
    pub fn system(&self, rotor: &FiniteElementRotor) -> Result<FeSystem, FiniteElementError> {
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
        // 2 modes + static shapes (x, y at nodes 0, 1; rx, ry at the unbalance's node 1 and
        // at both nodes, which carry equal G[rx, ry]): 10 vectors in 8 dimensions, 8 kept
        assert_eq!((b.modes(), b.statics(), b.len()), (2, 6, 8));
        assert_eq!(RitzBasis::modes_only(&r, 2).unwrap().len(), 2);
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
        // a basis of the wrong size or with dependent columns is refused, by name
        let t = b.matrix();
        let dependent = DMatrix::from_columns(&[t.column(0).into_owned(), t.column(0) * 2.0]);
        let e = FeSystem::reduced(&r, &dependent).unwrap_err().to_string();
        assert!(e.contains("dependent columns"), "{e}");
        let e = FeSystem::reduced(&r, &DMatrix::identity(7, 3))
            .unwrap_err()
            .to_string();
        assert!(e.contains("7 x 3") && e.contains("(8)"), "{e}");
        assert!(matches!(
            RitzBasis::new(&r, 9),
            Err(FiniteElementError::ModeCount { modes: 9, n: 8 })
        ));
    }
}
