//! The finite-element rotor's parts: degrees of freedom, matrices, bearings, unbalances.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use nalgebra::DMatrix;

use super::error::FiniteElementError;

/// Which motion of a node a degree of freedom is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DofKind {
    /// Lateral displacement along +x \[m\].
    X,
    /// Lateral displacement along +y \[m\].
    Y,
    /// Right-hand rotation about +x \[rad\] (dy/dz = -rx).
    Rx,
    /// Right-hand rotation about +y \[rad\] (dx/dz = +ry).
    Ry,
}

impl DofKind {
    /// `x`, `y`, `rx`, `ry`.
    pub fn name(self) -> &'static str {
        match self {
            DofKind::X => "x",
            DofKind::Y => "y",
            DofKind::Rx => "rx",
            DofKind::Ry => "ry",
        }
    }

    /// The unit of its value: m for a displacement, rad for a rotation.
    pub fn unit(self) -> &'static str {
        match self {
            DofKind::X | DofKind::Y => "m",
            DofKind::Rx | DofKind::Ry => "rad",
        }
    }
}

/// A degree of freedom: `<node>.<dof>`, e.g. `3.x` (nodes numbered along the shaft axis
/// +z from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Dof {
    /// The node.
    pub node: u32,
    /// The motion.
    pub kind: DofKind,
}

impl Dof {
    /// `node`'s `kind`.
    pub fn new(node: u32, kind: DofKind) -> Self {
        Self { node, kind }
    }
}

impl fmt::Display for Dof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.node, self.kind.name())
    }
}

impl FromStr for Dof {
    type Err = FiniteElementError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || FiniteElementError::BadDof { name: s.to_owned() };
        let (node, kind) = s.split_once('.').ok_or_else(bad)?;
        if node.is_empty() || !node.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        let node: u32 = node.parse().map_err(|_| bad())?;
        let kind = match kind {
            "x" => DofKind::X,
            "y" => DofKind::Y,
            "rx" => DofKind::Rx,
            "ry" => DofKind::Ry,
            _ => return Err(bad()),
        };
        Ok(Self { node, kind })
    }
}

/// The shaft and disks as matrices (no bearings), one row and column per degree of
/// freedom, SI units (rows of displacements in m, of rotations in rad).
#[derive(Debug, Clone, PartialEq)]
pub struct FeMatrices {
    dofs: Vec<Dof>,
    m: DMatrix<f64>,
    k: DMatrix<f64>,
    g: DMatrix<f64>,
    c: Option<DMatrix<f64>>,
    ka: Option<DMatrix<f64>>,
}

/// Relative asymmetry of M allowed (of its largest entry).
const SYMMETRY_TOLERANCE: f64 = 1e-9;

impl FeMatrices {
    /// The matrices of `dofs`: mass `m`, stiffness `k` (shaft and disks, no bearings),
    /// gyroscopic `g` (multiplied by phi'), optional damping `c` and `ka` (multiplied by
    /// phi'', ROSS's Ksdt; taken as given). Checked: unique dofs, every matrix n x n and
    /// finite, M symmetric and positive definite.
    pub fn new(
        dofs: Vec<Dof>,
        m: DMatrix<f64>,
        k: DMatrix<f64>,
        g: DMatrix<f64>,
        c: Option<DMatrix<f64>>,
        ka: Option<DMatrix<f64>>,
    ) -> Result<Self, FiniteElementError> {
        for (j, d) in dofs.iter().enumerate() {
            if let Some(i) = dofs[..j].iter().position(|e| e == d) {
                return Err(FiniteElementError::DuplicateDof {
                    name: d.to_string(),
                    first: i,
                    second: j,
                });
            }
        }
        let n = dofs.len();
        let named = |i: usize| dofs[i].to_string();
        let mut all: Vec<(&'static str, &DMatrix<f64>)> = vec![("M", &m), ("K", &k), ("G", &g)];
        all.extend(c.as_ref().map(|c| ("C", c)));
        all.extend(ka.as_ref().map(|ka| ("Ka", ka)));
        for (name, a) in &all {
            if a.nrows() != n || a.ncols() != n {
                return Err(FiniteElementError::Shape {
                    matrix: name,
                    rows: a.nrows(),
                    cols: a.ncols(),
                    n,
                });
            }
            for col in 0..n {
                for row in 0..n {
                    let value = a[(row, col)];
                    if !value.is_finite() {
                        return Err(FiniteElementError::NotFinite {
                            matrix: name,
                            row,
                            col,
                            row_dof: named(row),
                            col_dof: named(col),
                            value,
                        });
                    }
                }
            }
        }
        let scale = m.amax();
        for col in 0..n {
            for row in 0..col {
                let (v, t) = (m[(row, col)], m[(col, row)]);
                if (v - t).abs() > SYMMETRY_TOLERANCE * scale {
                    return Err(FiniteElementError::MassNotSymmetric {
                        row,
                        col,
                        row_dof: named(row),
                        col_dof: named(col),
                        value: v,
                        transposed: t,
                    });
                }
            }
        }
        if n == 0 || m.clone().cholesky().is_none() {
            return Err(FiniteElementError::MassNotPositiveDefinite);
        }
        Ok(Self {
            dofs,
            m,
            k,
            g,
            c,
            ka,
        })
    }

    /// The degrees of freedom, in the order of the matrices' rows.
    pub fn dofs(&self) -> &[Dof] {
        &self.dofs
    }

    /// Number of degrees of freedom.
    pub fn n(&self) -> usize {
        self.dofs.len()
    }

    /// The index of `dof`, if the rotor has it.
    pub fn index(&self, dof: Dof) -> Option<usize> {
        self.dofs.iter().position(|&d| d == dof)
    }

    /// Mass matrix M (kg; kg m^2 on rotations).
    pub fn m(&self) -> &DMatrix<f64> {
        &self.m
    }

    /// Stiffness matrix K of the shaft and disks (N/m; N m/rad on rotations).
    pub fn k(&self) -> &DMatrix<f64> {
        &self.k
    }

    /// Gyroscopic matrix G, multiplied by phi' (kg; kg m^2 on rotations).
    pub fn g(&self) -> &DMatrix<f64> {
        &self.g
    }

    /// Damping matrix C of the shaft, if given (N s/m).
    pub fn c(&self) -> Option<&DMatrix<f64>> {
        self.c.as_ref()
    }

    /// The matrix multiplied by phi'' (ROSS's Ksdt), if given (kg).
    pub fn ka(&self) -> Option<&DMatrix<f64>> {
        self.ka.as_ref()
    }
}

/// A bearing: its restoring force at its node's (x, y) is `-[[kxx, kxy], [kyx, kyy]] (x,
/// y) - [[cxx, cxy], [cyx, cyy]] (x', y')`. Serialized as an object of its fields in
/// this order (the `rotor.bearings` of a finite-element summary, docs/summary.md).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Bearing {
    /// The node it stands at.
    pub node: u32,
    /// Direct stiffness in x \[N/m\] (> 0).
    pub kxx: f64,
    /// Restoring force in x per unit displacement in y \[N/m\] (any sign).
    pub kxy: f64,
    /// Restoring force in y per unit displacement in x \[N/m\] (any sign).
    pub kyx: f64,
    /// Direct stiffness in y \[N/m\] (> 0).
    pub kyy: f64,
    /// Direct damping in x \[N s/m\].
    pub cxx: f64,
    /// Damping force in x per unit velocity in y \[N s/m\].
    pub cxy: f64,
    /// Damping force in y per unit velocity in x \[N s/m\].
    pub cyx: f64,
    /// Direct damping in y \[N s/m\].
    pub cyy: f64,
}

impl Bearing {
    /// `[[kxx, kxy], [kyx, kyy]]` \[N/m\].
    pub fn stiffness(&self) -> [[f64; 2]; 2] {
        [[self.kxx, self.kxy], [self.kyx, self.kyy]]
    }

    /// `[[cxx, cxy], [cyx, cyy]]` \[N s/m\].
    pub fn damping(&self) -> [[f64; 2]; 2] {
        [[self.cxx, self.cxy], [self.cyx, self.cyy]]
    }

    /// Checked: every value finite, kxx, kyy > 0, the damping dissipative; `what` names it
    /// in errors (`bearing0`).
    pub fn validated(self, what: &str) -> Result<Self, FiniteElementError> {
        let range = |field: &'static str, value: f64, allowed: &'static str, ok: bool| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(FiniteElementError::OutOfRange {
                    what: what.to_owned(),
                    field,
                    value,
                    allowed,
                })
            }
        };
        range("kxx", self.kxx, "finite and > 0 (N/m)", self.kxx > 0.0)?;
        range("kxy", self.kxy, "finite (N/m)", true)?;
        range("kyx", self.kyx, "finite (N/m)", true)?;
        range("kyy", self.kyy, "finite and > 0 (N/m)", self.kyy > 0.0)?;
        range("cxx", self.cxx, "finite and >= 0 (N s/m)", self.cxx >= 0.0)?;
        range("cxy", self.cxy, "finite (N s/m)", true)?;
        range("cyx", self.cyx, "finite (N s/m)", true)?;
        range("cyy", self.cyy, "finite and >= 0 (N s/m)", self.cyy >= 0.0)?;
        let half = 0.5 * (self.cxy + self.cyx);
        // (with a relative allowance for rounding: an isotropic bearing given as
        // cxy = cyx = sqrt(cxx cyy) is accepted)
        if self.cxx * self.cyy < half * half * (1.0 - 1e-12) {
            return Err(FiniteElementError::DampingNotDissipative {
                what: what.to_owned(),
                cxx: self.cxx,
                cxy: self.cxy,
                cyx: self.cyx,
                cyy: self.cyy,
            });
        }
        Ok(self)
    }
}

/// An unbalance at a node: `mud` = m_u d \[kg m\] at angle `alpha` \[rad\] from +x
/// towards +y at phi = 0 (ROSS's unbalance magnitude and phase). Serialized as an object
/// of its fields in this order (the `rotor.unbalances` of a finite-element summary).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FeUnbalance {
    /// The node it stands at.
    pub node: u32,
    /// m_u d \[kg m\] (>= 0).
    pub mud: f64,
    /// Its angle at phi = 0 \[rad\].
    pub alpha: f64,
}

/// A finite-element rotor: the matrices (shared, they do not change while bearings and
/// unbalances are identified), the bearings and the unbalances.
#[derive(Debug, Clone, PartialEq)]
pub struct FiniteElementRotor {
    /// The shaft and disks.
    pub matrices: Arc<FeMatrices>,
    /// The bearings, in the order of the scenario's `[[rotor.bearing]]` (bearing0, ...).
    pub bearings: Vec<Bearing>,
    /// The unbalances, in the order of `[[rotor.unbalance]]` (unbalance0, ...).
    pub unbalances: Vec<FeUnbalance>,
}

impl FiniteElementRotor {
    /// Checked: every bearing and unbalance valid and at a node with x and y.
    pub fn new(
        matrices: Arc<FeMatrices>,
        bearings: Vec<Bearing>,
        unbalances: Vec<FeUnbalance>,
    ) -> Result<Self, FiniteElementError> {
        let at_node = |what: String, node: u32| {
            for (kind, dof) in [(DofKind::X, "x"), (DofKind::Y, "y")] {
                if matrices.index(Dof::new(node, kind)).is_none() {
                    return Err(FiniteElementError::NodeWithoutDof {
                        what: what.clone(),
                        node,
                        dof,
                    });
                }
            }
            Ok(())
        };
        for (i, b) in bearings.iter().enumerate() {
            let what = format!("bearing{i}");
            b.validated(&what)?;
            at_node(format!("bearing {i}"), b.node)?;
        }
        for (j, u) in unbalances.iter().enumerate() {
            let what = format!("unbalance{j}");
            if !(u.mud >= 0.0 && u.mud.is_finite()) {
                return Err(FiniteElementError::OutOfRange {
                    what,
                    field: "mud",
                    value: u.mud,
                    allowed: "finite and >= 0 (kg m)",
                });
            }
            if !u.alpha.is_finite() {
                return Err(FiniteElementError::OutOfRange {
                    what,
                    field: "alpha",
                    value: u.alpha,
                    allowed: "finite (rad)",
                });
            }
            at_node(format!("unbalance {j}"), u.node)?;
        }
        Ok(Self {
            matrices,
            bearings,
            unbalances,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bearings_and_unbalances_serialize_as_the_summary_contract_writes_them() {
        // the `rotor` of a finite-element SUMMARY.json (docs/summary.md): these types are
        // written as they are, so a field added to them, renamed or moved would change the
        // summary's bytes; the text below is the contract's, key for key and in order
        let b = Bearing {
            node: 3,
            kxx: 1.5e6,
            kxy: 2.0e4,
            kyx: -2.5e4,
            kyy: 1.1e6,
            cxx: 300.0,
            cxy: -20.0,
            cyx: 15.0,
            cyy: 250.0,
        };
        assert_eq!(
            serde_json::to_string(&b).unwrap(),
            r#"{"node":3,"kxx":1500000.0,"kxy":20000.0,"kyx":-25000.0,"kyy":1100000.0,"cxx":300.0,"cxy":-20.0,"cyx":15.0,"cyy":250.0}"#
        );
        let u = FeUnbalance {
            node: 1,
            mud: 1e-5,
            alpha: 0.5,
        };
        assert_eq!(
            serde_json::to_string(&u).unwrap(),
            r#"{"node":1,"mud":0.00001,"alpha":0.5}"#
        );
    }

    #[test]
    fn dof_names_round_trip_and_bad_ones_are_refused_by_name() {
        for s in ["0.x", "3.y", "12.rx", "7.ry"] {
            assert_eq!(s.parse::<Dof>().unwrap().to_string(), s);
        }
        for s in ["x", "3.z", "-1.x", ".x", "3.", "3.X", "1e2.x", "3.x.y"] {
            let e = s.parse::<Dof>().unwrap_err().to_string();
            assert!(e.contains(&format!("{s:?}")) && e.contains("rx"), "{e}");
        }
    }

    fn two_nodes() -> Vec<Dof> {
        ["0.x", "0.y", "1.x", "1.y"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect()
    }

    #[test]
    fn matrices_are_checked_naming_the_matrix_and_entry() {
        let n = 4;
        let eye = DMatrix::<f64>::identity(n, n);
        let ok = FeMatrices::new(
            two_nodes(),
            eye.clone(),
            eye.clone(),
            DMatrix::zeros(n, n),
            None,
            None,
        );
        assert_eq!(ok.unwrap().index("1.x".parse().unwrap()), Some(2));
        let e = FeMatrices::new(
            two_nodes(),
            eye.clone(),
            DMatrix::zeros(3, 3),
            DMatrix::zeros(n, n),
            None,
            None,
        )
        .unwrap_err();
        assert!(matches!(e, FiniteElementError::Shape { matrix: "K", .. }));
        let mut bad = eye.clone();
        bad[(1, 2)] = f64::NAN;
        let e = FeMatrices::new(
            two_nodes(),
            eye.clone(),
            bad,
            DMatrix::zeros(n, n),
            None,
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("K") && e.contains("0.y") && e.contains("1.x"),
            "{e}"
        );
        let mut m = eye.clone();
        m[(0, 3)] = 0.1;
        let e = FeMatrices::new(
            two_nodes(),
            m,
            eye.clone(),
            DMatrix::zeros(n, n),
            None,
            None,
        )
        .unwrap_err();
        assert!(
            matches!(e, FiniteElementError::MassNotSymmetric { .. }),
            "{e}"
        );
        let mut m = eye.clone();
        m[(3, 3)] = 0.0;
        let e = FeMatrices::new(two_nodes(), m, eye, DMatrix::zeros(n, n), None, None).unwrap_err();
        assert_eq!(e, FiniteElementError::MassNotPositiveDefinite);
    }

    #[test]
    fn bearings_and_unbalances_are_checked_by_name() {
        let n = 4;
        let eye = DMatrix::<f64>::identity(n, n);
        let mats = Arc::new(
            FeMatrices::new(
                two_nodes(),
                eye.clone(),
                eye,
                DMatrix::zeros(n, n),
                None,
                None,
            )
            .unwrap(),
        );
        let b = Bearing {
            node: 0,
            kxx: 1e6,
            kxy: -2e5,
            kyx: 3e5,
            kyy: 1.2e6,
            cxx: 300.0,
            cxy: 10.0,
            cyx: -10.0,
            cyy: 300.0,
        };
        let u = FeUnbalance {
            node: 1,
            mud: 1e-5,
            alpha: 0.5,
        };
        assert!(FiniteElementRotor::new(mats.clone(), vec![b], vec![u]).is_ok());
        let e = FiniteElementRotor::new(mats.clone(), vec![b, Bearing { kyy: -1.0, ..b }], vec![])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bearing1.kyy = -1") && e.contains("> 0 (N/m)"),
            "{e}"
        );
        let e = FiniteElementRotor::new(mats.clone(), vec![Bearing { cxy: 700.0, ..b }], vec![])
            .unwrap_err();
        assert!(matches!(
            e,
            FiniteElementError::DampingNotDissipative { .. }
        ));
        let e = FiniteElementRotor::new(mats.clone(), vec![Bearing { node: 2, ..b }], vec![])
            .unwrap_err()
            .to_string();
        assert!(e.contains("node 2") && e.contains("2.x"), "{e}");
        let e = FiniteElementRotor::new(mats, vec![], vec![FeUnbalance { mud: -1e-5, ..u }])
            .unwrap_err()
            .to_string();
        assert!(e.contains("unbalance0.mud"), "{e}");
    }
}
