//! The parameters' covariance and first-order (delta-method) propagation through a result.
//!
//! The parameters are those of the refinement's internal parametrisation
//! (`refine::Refined::covariance`): m, cx, kx, cz, kz, a, the cross-coupled bearing
//! coefficients cxz, czx, kxz, kzx (docs/method.md section 1.6; the cross-coupled model
//! calls cx, cz, kx, kz cxx, czz, kxx, kzz, and either name is accepted) and the unbalance
//! as u_c = m_u d cos(alpha), u_s = m_u d sin(alpha), in which the unbalance force is
//! linear.
//! For a result y = f(theta) with gradient g = df/dtheta at the estimate,
//!
//! ```text
//! var(y) ~ g^T Sigma g = sum_ij g_i g_j Sigma_ij
//! ```
//!
//! over the parameters the covariance names; a parameter it does not name is taken as
//! known exactly (zero variance). A parameter whose variance is NaN or infinite is
//! undetermined (the refinement writes an infinite variance, and NaN in the rest of the
//! row and column, for the parameters the data could not separate); so, conservatively,
//! are both parameters of a non-finite covariance between two finite variances. A result
//! that depends on an undetermined parameter (g_i != 0) has no standard deviation
//! (`None`); a result that does not (g_i = 0, e.g. a critical speed and the unbalance) is
//! unaffected.
//! Reference: the delta method, e.g. Casella & Berger, *Statistical Inference*, 2nd ed.,
//! 2002, sec. 5.5.4.

use std::fmt;

use serde::Serialize;

use crate::refine::Refined;

use super::error::AnalysisError;

/// A model parameter the analysis propagates uncertainty from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum CovarianceParameter {
    /// m \[kg\].
    M,
    /// cx \[N s/m\].
    Cx,
    /// kx \[N/m\].
    Kx,
    /// cz \[N s/m\].
    Cz,
    /// kz \[N/m\].
    Kz,
    /// Gyroscopic coefficient a \[N s^2/m\].
    A,
    /// u_c = m_u d cos(alpha) \[kg m\].
    MudCosAlpha,
    /// u_s = m_u d sin(alpha) \[kg m\].
    MudSinAlpha,
    /// Cross-coupled damping cxz (force in x per unit velocity in z) \[N s/m\].
    Cxz,
    /// Cross-coupled damping czx (force in z per unit velocity in x) \[N s/m\].
    Czx,
    /// Cross-coupled stiffness kxz (force in x per unit displacement in z) \[N/m\].
    Kxz,
    /// Cross-coupled stiffness kzx (force in z per unit displacement in x) \[N/m\].
    Kzx,
}

/// The names [`ParameterCovariance::new`] accepts, for messages.
pub const PARAMETER_NAMES: &str = "m, cx, kx, cz, kz, a, mud_cos_alpha, mud_sin_alpha, cxz, czx, kxz, kzx (cxx, czz, kxx, kzz for cx, cz, kx, kz)";

/// Number of parameters: the length of every gradient.
pub(crate) const NPARAM: usize = 12;

/// A gradient (or any vector) over the parameters, indexed by [`CovarianceParameter::index`].
pub(crate) type Gradient = [f64; NPARAM];

impl CovarianceParameter {
    /// The Jeffcott rotor's parameters, in index order (those of a Jeffcott fit's
    /// covariance; the cross-coupled model adds [`CovarianceParameter::CROSS`]).
    pub const ALL: [CovarianceParameter; 8] = [
        CovarianceParameter::M,
        CovarianceParameter::Cx,
        CovarianceParameter::Kx,
        CovarianceParameter::Cz,
        CovarianceParameter::Kz,
        CovarianceParameter::A,
        CovarianceParameter::MudCosAlpha,
        CovarianceParameter::MudSinAlpha,
    ];

    /// The cross-coupled bearing coefficients, in index order (after [`CovarianceParameter::ALL`]).
    pub const CROSS: [CovarianceParameter; 4] = [
        CovarianceParameter::Cxz,
        CovarianceParameter::Czx,
        CovarianceParameter::Kxz,
        CovarianceParameter::Kzx,
    ];

    /// Every parameter of either model, in index order.
    pub fn every() -> impl Iterator<Item = CovarianceParameter> {
        Self::ALL.into_iter().chain(Self::CROSS)
    }

    /// The name as the refinement writes it (`m`, ..., `mud_cos_alpha`, `mud_sin_alpha`).
    pub fn name(self) -> &'static str {
        match self {
            CovarianceParameter::M => "m",
            CovarianceParameter::Cx => "cx",
            CovarianceParameter::Kx => "kx",
            CovarianceParameter::Cz => "cz",
            CovarianceParameter::Kz => "kz",
            CovarianceParameter::A => "a",
            CovarianceParameter::MudCosAlpha => "mud_cos_alpha",
            CovarianceParameter::MudSinAlpha => "mud_sin_alpha",
            CovarianceParameter::Cxz => "cxz",
            CovarianceParameter::Czx => "czx",
            CovarianceParameter::Kxz => "kxz",
            CovarianceParameter::Kzx => "kzx",
        }
    }

    /// The parameter called `name`, if any: its [`CovarianceParameter::name`] or the
    /// cross-coupled model's name of a direct coefficient (cxx, czz, kxx, kzz for cx, cz,
    /// kx, kz).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "cxx" => Some(CovarianceParameter::Cx),
            "czz" => Some(CovarianceParameter::Cz),
            "kxx" => Some(CovarianceParameter::Kx),
            "kzz" => Some(CovarianceParameter::Kz),
            _ => Self::every().find(|p| p.name() == name),
        }
    }

    /// SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            CovarianceParameter::M => "kg",
            CovarianceParameter::Cx
            | CovarianceParameter::Cz
            | CovarianceParameter::Cxz
            | CovarianceParameter::Czx => "N s/m",
            CovarianceParameter::Kx
            | CovarianceParameter::Kz
            | CovarianceParameter::Kxz
            | CovarianceParameter::Kzx => "N/m",
            CovarianceParameter::A => "N s^2/m",
            CovarianceParameter::MudCosAlpha | CovarianceParameter::MudSinAlpha => "kg m",
        }
    }

    /// Position in [`CovarianceParameter::every`].
    pub(crate) fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for CovarianceParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The value of every parameter at a rotor: (m, cx, kx, cz, kz, a, u_c, u_s, cxz, czx,
/// kxz, kzx), the cross terms 0 for a Jeffcott rotor.
pub(crate) fn values(p: &crate::model::RotorParams) -> Gradient {
    let mud = p.unbalance.mud();
    let (s, c) = p.unbalance.alpha.sin_cos();
    let x = p.cross();
    [
        p.m,
        p.cx,
        p.kx,
        p.cz,
        p.kz,
        p.a,
        mud * c,
        mud * s,
        x.cxz,
        x.czx,
        x.kxz,
        x.kzx,
    ]
}

/// The rotor with the parameter values `v` (as [`values`] orders them), the unbalance
/// from u_c, u_s at d = 1 m; cross-coupled when `p` is.
#[cfg(test)]
pub(crate) fn with_values(
    p: &crate::model::RotorParams,
    v: &Gradient,
) -> crate::model::RotorParams {
    crate::model::RotorParams {
        m: v[0],
        cx: v[1],
        kx: v[2],
        cz: v[3],
        kz: v[4],
        a: v[5],
        unbalance: crate::model::Unbalance {
            m_u: v[6].hypot(v[7]),
            d: 1.0,
            alpha: v[7].atan2(v[6]),
        },
        coupling: p.coupling.map(|_| crate::model::CrossCoupling {
            cxz: v[8],
            czx: v[9],
            kxz: v[10],
            kzx: v[11],
        }),
    }
}

/// The covariance of a subset of the parameters (SI units of each, squared), e.g. that of
/// a maximum-likelihood fit. Build it with [`ParameterCovariance::new`] (validated) or
/// [`ParameterCovariance::from_refined`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterCovariance {
    names: Vec<String>,
    matrix: Vec<Vec<f64>>,
    #[serde(skip)]
    params: Vec<CovarianceParameter>,
    /// Per row: true when the parameter is undetermined (module doc).
    #[serde(skip)]
    undetermined: Vec<bool>,
}

impl ParameterCovariance {
    /// A covariance over the parameters `names` (from [`PARAMETER_NAMES`], each at most
    /// once) with `matrix[i][j]` = Cov(names\[i\], names\[j\]) in SI units. Errors: an unknown
    /// or repeated name, a matrix that is not square with one row per name, a negative
    /// variance. NaN or infinite entries are accepted: they mark undetermined parameters
    /// (module doc). Rows of the fit's initial state (x0, z0, vx0, vz0: nuisance
    /// parameters) are dropped: the covariance of the others is their submatrix.
    pub fn new(names: Vec<String>, matrix: Vec<Vec<f64>>) -> Result<Self, AnalysisError> {
        const NUISANCE: [&str; 4] = ["x0", "z0", "vx0", "vz0"];
        if names.iter().any(|n| NUISANCE.contains(&n.as_str())) && matrix.len() == names.len() {
            let keep: Vec<usize> = (0..names.len())
                .filter(|&i| !NUISANCE.contains(&names[i].as_str()))
                .collect();
            let sub = |row: &Vec<f64>| {
                keep.iter()
                    .map(|&j| row.get(j).copied().unwrap_or(f64::NAN))
                    .collect()
            };
            let names = keep.iter().map(|&i| names[i].clone()).collect();
            let matrix = keep.iter().map(|&i| sub(&matrix[i])).collect();
            return Self::new(names, matrix);
        }
        let mut params = Vec::with_capacity(names.len());
        for name in &names {
            let p = CovarianceParameter::from_name(name).ok_or_else(|| {
                AnalysisError::UnknownParameter {
                    name: name.clone(),
                    allowed: PARAMETER_NAMES,
                }
            })?;
            if params.contains(&p) {
                return Err(AnalysisError::DuplicateParameter { name: name.clone() });
            }
            params.push(p);
        }
        let undetermined = validate_matrix(&names, &matrix)?;
        Ok(Self {
            names,
            matrix,
            params,
            undetermined,
        })
    }

    /// The covariance of the model parameters of a fit (its initial-state rows x0, z0,
    /// vx0, vz0 are nuisance parameters and are dropped; they do not enter the analysis).
    pub fn from_refined(r: &Refined) -> Result<Self, AnalysisError> {
        let names = r.covariance_names.iter().map(|n| n.to_string()).collect();
        Self::new(names, r.covariance.clone())
    }

    /// The covariance an identification reports (`None` entries: not finite).
    pub fn from_identification(c: &crate::pipeline::Covariance) -> Result<Self, AnalysisError> {
        let matrix = c
            .matrix
            .iter()
            .map(|row| row.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            .collect();
        Self::new(c.names.clone(), matrix)
    }

    /// The parameter names, in row order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The matrix, row-major, `matrix()[i][j]` = Cov(names\[i\], names\[j\]) (SI units).
    pub fn matrix(&self) -> &[Vec<f64>] {
        &self.matrix
    }

    /// The standard deviation of parameter `p`: `Some(0.0)` when the covariance does not
    /// name it (known exactly), `None` when it is undetermined.
    pub fn std(&self, p: CovarianceParameter) -> Option<f64> {
        let mut g = [0.0; NPARAM];
        g[p.index()] = 1.0;
        self.propagate(&g)
    }

    /// True when the covariance names `p` and `p` is determined.
    pub fn is_determined(&self, p: CovarianceParameter) -> bool {
        self.params
            .iter()
            .position(|&q| q == p)
            .is_some_and(|i| !self.undetermined[i])
    }

    /// The standard deviation of a linearised result y = sum_i g_i theta_i, the gradient
    /// given as (parameter, g_i) pairs (the others 0): sqrt(g^T Sigma g) (module doc);
    /// `None` when it depends on an undetermined parameter.
    pub fn std_of_linear(&self, gradient: &[(CovarianceParameter, f64)]) -> Option<f64> {
        let mut g = [0.0; NPARAM];
        for &(p, v) in gradient {
            g[p.index()] += v;
        }
        self.propagate(&g)
    }

    /// The standard deviation sqrt(g^T Sigma g) of a result with gradient `g` (module
    /// doc); `None` when it depends on an undetermined parameter.
    pub(crate) fn propagate(&self, g: &Gradient) -> Option<f64> {
        Some(self.propagate_pair(g, g)?.max(0.0).sqrt())
    }

    /// The covariance g^T Sigma h of two results with gradients `g` and `h`; `None` when
    /// either depends on an undetermined parameter.
    pub(crate) fn propagate_pair(&self, g: &Gradient, h: &Gradient) -> Option<f64> {
        let n = self.params.len();
        let gi: Vec<f64> = self.params.iter().map(|p| g[p.index()]).collect();
        let hi: Vec<f64> = self.params.iter().map(|p| h[p.index()]).collect();
        for i in 0..n {
            if self.undetermined[i] && (gi[i] != 0.0 || hi[i] != 0.0) {
                return None;
            }
        }
        let mut s = 0.0;
        for i in (0..n).filter(|&i| !self.undetermined[i]) {
            for j in (0..n).filter(|&j| !self.undetermined[j]) {
                s += gi[i] * self.matrix[i][j] * hi[j];
            }
        }
        Some(s)
    }
}

/// The standard deviation of a result with gradient `g` under `cov`, `None` without a
/// covariance (or when undetermined).
pub(crate) fn std_of(cov: Option<&ParameterCovariance>, g: &Gradient) -> Option<f64> {
    cov.and_then(|c| c.propagate(g))
}

/// The checks every covariance passes, whatever names its parameters (module doc): square
/// with one row and one column per name, a non-negative variance for every determined
/// parameter, symmetric and positive semi-definite over the determined ones. Returns, per
/// row, whether the parameter is undetermined (a non-finite variance; and, conservatively,
/// both parameters of a non-finite covariance between two finite variances).
pub(crate) fn validate_matrix(
    names: &[String],
    matrix: &[Vec<f64>],
) -> Result<Vec<bool>, AnalysisError> {
    let n = names.len();
    if matrix.len() != n {
        return Err(AnalysisError::NotSquare {
            row: matrix.len(),
            len: matrix.len(),
            expected: n,
        });
    }
    if let Some((row, r)) = matrix.iter().enumerate().find(|(_, r)| r.len() != n) {
        return Err(AnalysisError::NotSquare {
            row,
            len: r.len(),
            expected: n,
        });
    }
    let mut undetermined: Vec<bool> = (0..n).map(|i| !matrix[i][i].is_finite()).collect();
    for i in 0..n {
        for j in 0..n {
            if !matrix[i][j].is_finite() && !undetermined[i] && !undetermined[j] {
                undetermined[i] = true;
                undetermined[j] = true;
            }
        }
    }
    for i in 0..n {
        if !undetermined[i] && matrix[i][i] < 0.0 {
            return Err(AnalysisError::NegativeVariance {
                name: names[i].clone(),
                value: matrix[i][i],
            });
        }
    }
    check_semidefinite(names, matrix, &undetermined)?;
    Ok(undetermined)
}

/// Relative tolerance of the symmetry and semi-definiteness checks (rounding of a
/// covariance computed and written in double precision is far below it).
const SEMIDEFINITE_TOLERANCE: f64 = 1e-8;

/// A covariance must be symmetric and positive semi-definite over its determined
/// parameters: each correlation within [-1, 1], and no negative eigenvalue of the
/// correlation matrix (beyond [`SEMIDEFINITE_TOLERANCE`]). A matrix that is not would give
/// imaginary standard deviations, which used to be clamped to 0 without a word.
fn check_semidefinite(
    names: &[String],
    matrix: &[Vec<f64>],
    undetermined: &[bool],
) -> Result<(), AnalysisError> {
    let idx: Vec<usize> = (0..names.len())
        .filter(|&i| !undetermined[i] && matrix[i][i] > 0.0)
        .collect();
    let sd = |i: usize| matrix[i][i].sqrt();
    for (a, &i) in idx.iter().enumerate() {
        for &j in &idx[a + 1..] {
            let (cij, cji) = (matrix[i][j], matrix[j][i]);
            let scale = sd(i) * sd(j);
            if (cij - cji).abs() > SEMIDEFINITE_TOLERANCE * scale {
                return Err(AnalysisError::NotSymmetric {
                    first: names[i].clone(),
                    second: names[j].clone(),
                    upper: cij,
                    lower: cji,
                });
            }
            let r = cij / scale;
            if r.abs() > 1.0 + SEMIDEFINITE_TOLERANCE {
                return Err(AnalysisError::NotSemidefinite {
                    detail: format!(
                        "the correlation of {} and {} is {r:.6} (must be within -1 and 1)",
                        names[i], names[j]
                    ),
                });
            }
        }
    }
    let n = idx.len();
    if n < 3 {
        return Ok(());
    }
    let corr = nalgebra::DMatrix::from_fn(n, n, |a, b| {
        let (i, j) = (idx[a], idx[b]);
        0.5 * (matrix[i][j] + matrix[j][i]) / (sd(i) * sd(j))
    });
    let eig = corr.symmetric_eigen();
    let (k, min) =
        eig.eigenvalues
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (k, v)| if v < b.1 { (k, v) } else { b },
            );
    if min < -SEMIDEFINITE_TOLERANCE * n as f64 {
        // the parameters of the offending direction, largest first
        let v = eig.eigenvectors.column(k);
        let mut parts: Vec<(f64, &str)> = (0..n)
            .map(|a| (v[a].abs(), names[idx[a]].as_str()))
            .filter(|(w, _)| *w > 0.1)
            .collect();
        parts.sort_by(|x, y| y.0.total_cmp(&x.0));
        let who: Vec<&str> = parts.iter().map(|p| p.1).collect();
        return Err(AnalysisError::NotSemidefinite {
            detail: format!(
                "its correlation matrix has the eigenvalue {min:.3e} < 0, in the direction of {}",
                who.join(", ")
            ),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_covariance_that_is_not_symmetric_or_semidefinite_is_refused_by_name() {
        // a correlation of 17 between m and kxx (what an edited summary can hold)
        let e = ParameterCovariance::new(
            names(&["m", "kxx"]),
            vec![
                vec![1e-4, 17.0 * 1e-2 * 100.0],
                vec![17.0 * 1e-2 * 100.0, 1e4],
            ],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "the covariance is not positive semi-definite: the correlation of m and kxx is 17.000000 (must be within -1 and 1)"
        );
        let e = ParameterCovariance::new(names(&["m", "kx"]), vec![vec![1.0, 0.5], vec![0.4, 1.0]])
            .unwrap_err();
        assert!(matches!(e, AnalysisError::NotSymmetric { .. }), "{e}");
        // every correlation within [-1, 1] but the three together impossible: 0.9, 0.9 and
        // -0.9 (eigenvalue 1 - 1.8 < 0)
        let c = vec![
            vec![1.0, 0.9, 0.9],
            vec![0.9, 1.0, -0.9],
            vec![0.9, -0.9, 1.0],
        ];
        let e = ParameterCovariance::new(names(&["m", "kx", "kz"]), c).unwrap_err();
        assert!(
            e.to_string()
                .contains("eigenvalue -8.000e-1 < 0, in the direction of"),
            "{e}"
        );
        // a valid one, and one with an undetermined (non-finite) parameter, pass
        let ok = vec![
            vec![1.0, 0.9, 0.0],
            vec![0.9, 1.0, 0.0],
            vec![0.0, 0.0, f64::INFINITY],
        ];
        ParameterCovariance::new(names(&["m", "kx", "kz"]), ok).unwrap();
        // rounding of a symmetric matrix written in double precision passes
        let r = vec![vec![1.0, 1.0 + 1e-12], vec![1.0, 1.0 + 2e-12]];
        ParameterCovariance::new(names(&["m", "kx"]), r).unwrap();
    }

    #[test]
    fn names_round_trip_and_are_validated() {
        for p in CovarianceParameter::ALL {
            assert_eq!(CovarianceParameter::from_name(p.name()), Some(p));
            assert_eq!(CovarianceParameter::ALL[p.index()], p);
        }
        for (i, p) in CovarianceParameter::every().enumerate() {
            assert_eq!(CovarianceParameter::from_name(p.name()), Some(p));
            assert_eq!(p.index(), i);
        }
        assert_eq!(CovarianceParameter::every().count(), NPARAM);
        assert_eq!(
            CovarianceParameter::from_name("kxx"),
            Some(CovarianceParameter::Kx)
        );
        let e = ParameterCovariance::new(names(&["kx", "kxx"]), vec![vec![1.0; 2]; 2]).unwrap_err();
        assert!(matches!(e, AnalysisError::DuplicateParameter { .. }), "{e}");
        let e = ParameterCovariance::new(names(&["m", "k"]), vec![vec![1.0; 2]; 2]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown parameter \"k\" in the covariance: expected names from m, cx, kx, cz, kz, a, mud_cos_alpha, mud_sin_alpha, cxz, czx, kxz, kzx (cxx, czz, kxx, kzz for cx, cz, kx, kz)"
        );
        let e = ParameterCovariance::new(names(&["m", "m"]), vec![vec![1.0; 2]; 2]).unwrap_err();
        assert!(matches!(e, AnalysisError::DuplicateParameter { .. }), "{e}");
        let e = ParameterCovariance::new(names(&["m", "kx"]), vec![vec![1.0, 0.0], vec![0.0]])
            .unwrap_err();
        assert_eq!(
            e,
            AnalysisError::NotSquare {
                row: 1,
                len: 1,
                expected: 2
            }
        );
        let e = ParameterCovariance::new(names(&["m"]), vec![]).unwrap_err();
        assert!(
            matches!(e, AnalysisError::NotSquare { expected: 1, .. }),
            "{e}"
        );
        let e = ParameterCovariance::new(names(&["m"]), vec![vec![-1.0]]).unwrap_err();
        assert!(matches!(e, AnalysisError::NegativeVariance { .. }), "{e}");
    }

    #[test]
    fn propagation_is_the_quadratic_form_and_skips_unrelated_undetermined_rows() {
        // m, kx correlated; a undetermined (NaN row, inf diagonal as refine writes it)
        let nan = f64::NAN;
        let c = ParameterCovariance::new(
            names(&["m", "kx", "a"]),
            vec![
                vec![4.0, 3.0, nan],
                vec![3.0, 9.0, nan],
                vec![nan, nan, f64::INFINITY],
            ],
        )
        .unwrap();
        let mut g = [0.0; NPARAM];
        g[CovarianceParameter::M.index()] = 1.0;
        g[CovarianceParameter::Kx.index()] = -2.0;
        // 4 - 2 * 2 * 3 + 4 * 9 = 28
        assert!((c.propagate(&g).unwrap() - 28f64.sqrt()).abs() < 1e-15);
        assert_eq!(c.std(CovarianceParameter::M), Some(2.0));
        assert_eq!(c.std(CovarianceParameter::Cz), Some(0.0));
        assert_eq!(c.std(CovarianceParameter::A), None);
        assert!(
            c.is_determined(CovarianceParameter::Kx) && !c.is_determined(CovarianceParameter::A)
        );
        g[CovarianceParameter::A.index()] = 1e-30;
        assert_eq!(c.propagate(&g), None);
    }
}
