//! A record as the caller holds it: borrowed columns (numpy arrays are read in place), and
//! the estimates table that comes back, one column per quantity.

use rotorid::parameter::ModelKind;
use rotorid::pipeline::{FinalEstimate, Sample, SampleEstimate};
use rotorid::SpeedState;

use crate::error::Error;

/// Per-sample speed: phi \[rad\], phi_dot = w \[rad/s\], phi_ddot = w' \[rad/s^2\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedColumns<'a> {
    /// Rotor angle phi \[rad\].
    pub phi: &'a [f64],
    /// Speed w \[rad/s\].
    pub phi_dot: &'a [f64],
    /// Acceleration w' \[rad/s^2\].
    pub phi_ddot: &'a [f64],
}

/// The columns of a record (or of a chunk of a stream), one value per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Columns<'a> {
    /// Time stamps \[s\]; `None` on a given grid.
    pub t: Option<&'a [f64]>,
    /// Horizontal displacement \[m\].
    pub x: &'a [f64],
    /// Vertical displacement \[m\].
    pub z: &'a [f64],
    /// The speed per sample; `None`: the scenario's speed profile.
    pub speed: Option<SpeedColumns<'a>>,
}

impl<'a> Columns<'a> {
    /// The columns from optional phi, phi_dot, phi_ddot: all three or none.
    pub fn new(
        t: Option<&'a [f64]>,
        x: &'a [f64],
        z: &'a [f64],
        phi: [Option<&'a [f64]>; 3],
    ) -> Result<Self, Error> {
        let speed = match phi {
            [Some(phi), Some(phi_dot), Some(phi_ddot)] => Some(SpeedColumns {
                phi,
                phi_dot,
                phi_ddot,
            }),
            [None, None, None] => None,
            _ => {
                let missing: Vec<&str> = SPEED_NAMES
                    .iter()
                    .zip(phi)
                    .filter(|(_, c)| c.is_none())
                    .map(|(n, _)| *n)
                    .collect();
                return Err(Error::invalid(format!(
                    "some but not all of phi, phi_dot, phi_ddot are given: missing {}; give \
                     all three or none (then the scenario's speed profile is used)",
                    missing.join(", ")
                )));
            }
        };
        let c = Self { t, x, z, speed };
        c.check_lengths()?;
        Ok(c)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.map_or(self.x.len(), <[f64]>::len)
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sample `i`.
    pub fn sample(&self, i: usize) -> Sample {
        Sample {
            t: self.t.map(|t| t[i]),
            x: self.x[i],
            z: self.z[i],
            speed: self.speed.map(|s| SpeedState {
                phi: s.phi[i],
                omega: s.phi_dot[i],
                omega_dot: s.phi_ddot[i],
            }),
        }
    }

    fn check_lengths(&self) -> Result<(), Error> {
        let (reference, n) = match self.t {
            Some(t) => ("t", t.len()),
            None => ("x", self.x.len()),
        };
        let mut columns = vec![("x", self.x), ("z", self.z)];
        if let Some(s) = self.speed {
            columns.extend([
                ("phi", s.phi),
                ("phi_dot", s.phi_dot),
                ("phi_ddot", s.phi_ddot),
            ]);
        }
        for (name, c) in columns {
            if c.len() != n {
                return Err(Error::invalid(format!(
                    "{name} has {} samples but {reference} has {n}: every column needs one \
                     value per sample",
                    c.len()
                )));
            }
        }
        Ok(())
    }
}

/// The speed columns' names.
pub const SPEED_NAMES: [&str; 3] = ["phi", "phi_dot", "phi_ddot"];

/// The estimates table's columns for the Jeffcott model, as `rotorid identify --out`
/// writes them.
pub const ESTIMATE_COLUMNS: [&str; 10] = [
    "t", "m_x", "c_x", "k_x", "m_z", "c_z", "k_z", "rcond_x", "rcond_z", "window",
];

/// The estimates table's columns for `model`: t, each per-direction parameter's column
/// ([`rotorid::Parameter::column`]), rcond_x, rcond_z, window (as `rotorid identify
/// --out` writes them).
pub fn estimate_columns(model: ModelKind) -> Vec<&'static str> {
    let mut c = vec!["t"];
    c.extend(model.per_direction().iter().map(|p| p.column()));
    c.extend(["rcond_x", "rcond_z", "window"]);
    c
}

/// Estimates, one row per estimate, in columns [`estimate_columns`] of the model: t \[s\],
/// the per-direction values \[kg, N s/m, N/m\] (NaN where the CLI leaves the field empty:
/// an ill-conditioned direction, a value not determined), rcond per direction, and the
/// algebraic estimate's restart window (0, 1, 2, ...; NaN on a batch method's row).
#[derive(Debug, Clone, PartialEq)]
pub struct Estimates {
    /// The model whose parameters the values are.
    pub model: ModelKind,
    /// The columns, in the order of [`estimate_columns`].
    pub columns: Vec<Vec<f64>>,
}

impl Estimates {
    /// No row, in `model`'s columns.
    pub fn new(model: ModelKind) -> Self {
        Self {
            model,
            columns: vec![Vec::new(); estimate_columns(model).len()],
        }
    }

    /// The columns' names.
    pub fn names(&self) -> Vec<&'static str> {
        estimate_columns(self.model)
    }

    /// Rows.
    pub fn len(&self) -> usize {
        self.columns[0].len()
    }

    /// True when there is no row.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The algebraic estimate at one sample: the values where well conditioned and finite.
    pub fn push_sample(&mut self, e: &SampleEstimate) {
        let n = e.values().len();
        let mut row = Vec::with_capacity(n + 4);
        row.push(e.t);
        row.extend((0..n).map(|i| e.usable(i).unwrap_or(f64::NAN)));
        // (exact: a window index is far below 2^53)
        row.extend([e.rcond[0], e.rcond[1], e.window as f64]);
        self.push(&row);
    }

    /// The one row of a batch method (modulating, refine); an empty table takes the row's
    /// model (refine's `auto` chooses it at the end).
    pub fn push_final(&mut self, f: &FinalEstimate) {
        if self.is_empty() {
            *self = Self::new(f.model);
        }
        let mut row = Vec::with_capacity(f.values.len() + 4);
        row.push(f.t_s);
        row.extend(f.values.iter().map(|v| v.unwrap_or(f64::NAN)));
        row.extend([f.rcond.x, f.rcond.z, f64::NAN]);
        self.push(&row);
    }

    /// The rows of `other` after these (an empty table takes `other`'s model: a batch
    /// method's one row may be of the model it chose).
    pub fn append(&mut self, other: Estimates) {
        if self.is_empty() {
            *self = other;
            return;
        }
        debug_assert_eq!(self.model, other.model, "rows of one model");
        for (c, o) in self.columns.iter_mut().zip(other.columns) {
            if c.is_empty() {
                *c = o;
            } else {
                c.extend(o);
            }
        }
    }

    fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.columns.len(), "a row of the table's model");
        for (c, v) in self.columns.iter_mut().zip(row) {
            c.push(*v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_is_all_three_or_none() {
        let v = [0.0; 3];
        let e = Columns::new(Some(&v), &v, &v, [Some(&v), None, Some(&v)]).unwrap_err();
        assert!(e.to_string().contains("missing phi_dot;"), "{e}");
        assert!(Columns::new(Some(&v), &v, &v, [None; 3]).is_ok());
    }

    #[test]
    fn lengths_name_the_column() {
        let (a, b) = ([0.0; 3], [0.0; 2]);
        let e = Columns::new(Some(&a), &a, &b, [None; 3]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "z has 2 samples but t has 3: every column needs one value per sample"
        );
        let e = Columns::new(None, &a, &a, [Some(&a), Some(&a), Some(&b)]).unwrap_err();
        assert!(e
            .to_string()
            .starts_with("phi_ddot has 2 samples but x has 3"));
    }
}
