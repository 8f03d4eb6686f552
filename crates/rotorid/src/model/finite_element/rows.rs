//! The matrices from plain row-major arrays and degree-of-freedom names, as a file reader
//! gives them (`rotorid_io::fe_matrices`; this crate reads no file).

use nalgebra::DMatrix;

use super::error::FiniteElementError;
use super::rotor::{Dof, FeMatrices};

impl FeMatrices {
    /// The matrices named `dofs` (`<node>.<dof>`, parsed by [`Dof`]'s `FromStr`), each
    /// given row-major with n x n entries (n = `dofs.len()`; entry (i, j) at `i * n + j`):
    /// mass `m`, stiffness `k`, gyroscopic `g`, optional `c` and `ka`; then checked as
    /// [`FeMatrices::new`] checks them. An array of another length is a
    /// [`FiniteElementError::Shape`] error (its rows counted as its length over n).
    pub fn from_row_major(
        dofs: &[String],
        m: &[f64],
        k: &[f64],
        g: &[f64],
        c: Option<&[f64]>,
        ka: Option<&[f64]>,
    ) -> Result<Self, FiniteElementError> {
        let dofs = dofs
            .iter()
            .map(|d| d.parse::<Dof>())
            .collect::<Result<Vec<_>, _>>()?;
        let n = dofs.len();
        let matrix = |name: &'static str, a: &[f64]| {
            if a.len() != n * n {
                return Err(FiniteElementError::Shape {
                    matrix: name,
                    rows: a.len().checked_div(n).unwrap_or(0),
                    cols: n,
                    n,
                });
            }
            Ok(DMatrix::from_row_slice(n, n, a))
        };
        let m = matrix("M", m)?;
        let k = matrix("K", k)?;
        let g = matrix("G", g)?;
        let c = c.map(|c| matrix("C", c)).transpose()?;
        let ka = ka.map(|ka| matrix("Ka", ka)).transpose()?;
        Self::new(dofs, m, k, g, c, ka)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_major_arrays_are_the_matrices_rows() {
        let dofs: Vec<String> = ["0.x", "0.y"].map(String::from).to_vec();
        let m = [2.0, 0.5, 0.5, 3.0];
        let g = [0.0, 1.0, -1.0, 0.0];
        let f = FeMatrices::from_row_major(&dofs, &m, &m, &g, None, Some(&g)).unwrap();
        // row 0 is (0, 1): G[0][1] = 1, G[1][0] = -1
        assert_eq!(f.g()[(0, 1)], 1.0);
        assert_eq!(f.g()[(1, 0)], -1.0);
        assert_eq!(f.ka().unwrap()[(0, 1)], 1.0);
        assert_eq!(f.index("0.y".parse().unwrap()), Some(1));
        let e = FeMatrices::from_row_major(&dofs, &m, &m[..3], &g, None, None).unwrap_err();
        assert!(
            matches!(e, FiniteElementError::Shape { matrix: "K", .. }),
            "{e}"
        );
        let bad: Vec<String> = ["0.x", "0.z"].map(String::from).to_vec();
        let e = FeMatrices::from_row_major(&bad, &m, &m, &g, None, None).unwrap_err();
        assert!(e.to_string().contains("\"0.z\""), "{e}");
    }
}
