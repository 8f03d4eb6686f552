//! The estimates CSV written by `rotorid identify`: the algebraic identifier's estimate of
//! theta = (m, c, k) per direction at each (or every N-th) sample
//! (docs/method.md section 3.4, `A(t) theta = b(t)`).
//!
//! ```text
//! t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z,window
//! s,kg,N s/m,N/m,kg,N s/m,N/m,1,1,-        (units, not written)
//! ```
//!
//! The cross-coupled model's (`--model cross_coupled`; docs/method.md sections 3.10 and
//! 4.8): per direction m and the four coefficients of that row, named as in the summary:
//!
//! ```text
//! t,m_x,cxx,cxz,kxx,kxz,m_z,czx,czz,kzx,kzz,rcond_x,rcond_z,window
//! s,kg,N s/m,N s/m,N/m,N/m,kg,N s/m,N s/m,N/m,N/m,1,1,-
//! ```
//!
//! - `t` is the sample's time as read from the input.
//! - `window` is the algebraic estimate's restart window (`--restart`; docs/method.md
//!   section 3.9): 0, 1, 2, ... in the order they start, 0 throughout without restarts. A
//!   batch method's one row leaves it empty. Files written before it existed (nine columns)
//!   are still read.
//! - `rcond_x`, `rcond_z` are the identifier's reciprocal condition numbers of the scaled
//!   3x3 system A(t) (dimensionless, in [0, 1]; 0 when exactly singular), always written.
//! - When a direction is not well conditioned at an instant (rcond below `--rcond-min`,
//!   or A(t) singular, as at t = t_0), its three fields m, c, k are left EMPTY: the
//!   identifier has no trustworthy estimate there (the paper's "spikes"). Empty fields read
//!   as NaN in pandas (`read_csv`), numpy (`genfromtxt`) and spreadsheets, and as `None`
//!   through [`EstimatesReader`] (which also reads `NaN` as `None`).
//! - Values are written in shortest round-trip form ([`super::number`]).

use std::io::{self, Read, Write};

use rotorid::parameter::ModelKind;
use rotorid_io::csv::columns::{
    check_length, csv_reader, finite_field, next_record, number_field, optional_field, CsvReader,
    Header,
};
use rotorid_io::csv::number::write_row;
use rotorid_io::csv::CsvError;

use super::params::ParameterSet;

/// The header `identify` writes for the Jeffcott model.
pub const ESTIMATES_HEADER: [&str; 10] = [
    "t", "m_x", "c_x", "k_x", "m_z", "c_z", "k_z", "rcond_x", "rcond_z", "window",
];

/// The columns an estimates file must have (`window` came later and may be absent).
pub const ESTIMATES_REQUIRED: [&str; 9] = [
    "t", "m_x", "c_x", "k_x", "m_z", "c_z", "k_z", "rcond_x", "rcond_z",
];

/// The header `identify` writes for `model`: t, each per-direction parameter's column
/// ([`rotorid::Parameter::column`]), rcond_x, rcond_z, window.
pub fn estimates_header(model: ModelKind) -> Vec<&'static str> {
    let mut h = vec!["t"];
    h.extend(model.per_direction().iter().map(|p| p.column()));
    h.extend(["rcond_x", "rcond_z", "window"]);
    h
}

/// `rows` (all of one model) as a Parquet file with the CSV's columns (optional DOUBLE: a
/// withheld estimate is a null, where the CSV leaves the field empty); `file` names it in
/// errors.
pub fn estimates_parquet(
    file: &str,
    model: ModelKind,
    rows: &[EstimateRow],
) -> Result<Vec<u8>, rotorid_io::WriteError> {
    use rotorid_io::write::{parquet_columns_bytes, ParquetColumn};
    let header = estimates_header(model);
    let n = model.per_direction().len();
    let t: Vec<f64> = rows.iter().map(|r| r.t).collect();
    let values: Vec<Vec<Option<f64>>> = (0..n)
        .map(|k| rows.iter().map(|r| r.values[k]).collect())
        .collect();
    let rcond_x: Vec<f64> = rows.iter().map(|r| r.rcond_x).collect();
    let rcond_z: Vec<f64> = rows.iter().map(|r| r.rcond_z).collect();
    // (a whole number, exact as a double: the column is a double like the others)
    let window: Vec<Option<f64>> = rows.iter().map(|r| r.window.map(|w| w as f64)).collect();
    let mut columns = vec![(header[0], ParquetColumn::Required(&t))];
    for (k, v) in values.iter().enumerate() {
        columns.push((header[1 + k], ParquetColumn::Optional(v)));
    }
    columns.push((header[n + 1], ParquetColumn::Required(&rcond_x)));
    columns.push((header[n + 2], ParquetColumn::Required(&rcond_z)));
    columns.push((header[n + 3], ParquetColumn::Optional(&window)));
    parquet_columns_bytes(file, &columns)
}

/// One row of the estimates CSV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateRow {
    /// Time t [s].
    pub t: f64,
    /// The model whose parameters the values are.
    pub model: ModelKind,
    /// The estimates of `model.per_direction()` (kg, N s/m, N/m), the rest `None`; `None`
    /// where the direction is not well conditioned or the value not determined.
    pub values: [Option<f64>; 10],
    /// Reciprocal condition number of the x system (dimensionless, [0, 1]).
    pub rcond_x: f64,
    /// Reciprocal condition number of the z system (dimensionless, [0, 1]).
    pub rcond_z: f64,
    /// The algebraic estimate's restart window (0 without restarts); `None` for a batch
    /// method's row, and in files written without the column.
    pub window: Option<u64>,
}

impl EstimateRow {
    /// A row of `model` from its per-direction values (in the order of
    /// `model.per_direction()`; extra values ignored).
    pub fn new(
        t: f64,
        model: ModelKind,
        values: &[Option<f64>],
        rcond: [f64; 2],
        window: Option<u64>,
    ) -> Self {
        let n = model.per_direction().len();
        Self {
            t,
            model,
            values: std::array::from_fn(|i| {
                if i < n {
                    values.get(i).copied().flatten()
                } else {
                    None
                }
            }),
            rcond_x: rcond[0],
            rcond_z: rcond[1],
            window,
        }
    }

    /// The Jeffcott model's six values (m_x, c_x, k_x, m_z, c_z, k_z); `None` for a row of
    /// another model.
    pub fn jeffcott(&self) -> Option<ParameterSet<Option<f64>>> {
        (self.model == ModelKind::Jeffcott)
            .then(|| ParameterSet::from_array(std::array::from_fn(|i| self.values[i])))
    }
}

/// Writes the estimates CSV of one model (header first), one whole row per `write_all`.
pub struct EstimatesWriter<W: Write> {
    out: W,
    scratch: Vec<u8>,
    model: ModelKind,
}

impl<W: Write> EstimatesWriter<W> {
    /// Write `model`'s header ([`estimates_header`]) to `out`.
    pub fn for_model(mut out: W, model: ModelKind) -> io::Result<Self> {
        let header = estimates_header(model);
        writeln!(out, "{}", header.join(","))?;
        Ok(Self {
            out,
            scratch: Vec::with_capacity(256),
            model,
        })
    }

    /// Write one row (of the writer's model).
    #[inline]
    pub fn write(&mut self, r: &EstimateRow) -> io::Result<()> {
        debug_assert_eq!(r.model, self.model, "one model per estimates file");
        let n = self.model.per_direction().len();
        let mut fields = [None; 14];
        fields[0] = Some(r.t);
        fields[1..=n].copy_from_slice(&r.values[..n]);
        fields[n + 1] = Some(r.rcond_x);
        fields[n + 2] = Some(r.rcond_z);
        // (exact: a window index is far below 2^53)
        fields[n + 3] = r.window.map(|w| w as f64);
        write_row(&mut self.out, &mut self.scratch, &fields[..n + 4])
    }

    /// Flush the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// The underlying writer (not flushed).
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Streaming reader of an estimates CSV: the nine columns of [`ESTIMATES_REQUIRED`]
/// required and `window` read when present (any order, extra columns ignored, unit suffixes
/// allowed as in [`super::columns`]); `t` finite; parameter fields empty, `NaN` (both
/// `None`) or a number; rcond a number; window empty or a whole number >= 0.
pub struct EstimatesReader<R: Read> {
    file: String,
    csv: CsvReader<R>,
    header: Header,
    model: ModelKind,
    names: Vec<&'static str>,
    cols: Vec<usize>,
    window: Option<usize>,
}

impl<R: Read> EstimatesReader<R> {
    /// Read and check the header of `input` (`file` names it in messages).
    pub fn new(file: &str, input: R) -> Result<Self, CsvError> {
        let mut csv = csv_reader(input);
        let Some(rec) = next_record(file, &mut csv)? else {
            return Err(CsvError::file(
                file,
                format!(
                    "the file is empty: expected the header {}",
                    ESTIMATES_HEADER.join(",")
                ),
            ));
        };
        let header = Header::new(&rec, rec.line());
        // a cross-coupled model's file names its coefficients cxx .. kzz
        let model = if header.find(file, "cxx")?.is_some() {
            ModelKind::CrossCoupled
        } else {
            ModelKind::Jeffcott
        };
        let mut names = estimates_header(model);
        names.pop(); // window: optional
        let cols = header.require(file, &names)?;
        let window = header.find(file, "window")?;
        Ok(Self {
            file: file.to_owned(),
            csv,
            header,
            model,
            names,
            cols,
            window,
        })
    }

    /// The model of the file's columns.
    pub fn model(&self) -> ModelKind {
        self.model
    }

    /// The next row, or `None` at the end.
    pub fn next_row(&mut self) -> Result<Option<EstimateRow>, CsvError> {
        let f = self.file.as_str();
        let Some(rec) = next_record(f, &mut self.csv)? else {
            return Ok(None);
        };
        let line = rec.line();
        let rec = &rec;
        check_length(f, rec, line, &self.header)?;
        let c = &self.cols;
        let names = &self.names;
        let opt = |i: usize| optional_field(f, rec, line, c[i], names[i]);
        let window = match self.window {
            None => None,
            Some(col) => match optional_field(f, rec, line, col, "window")? {
                None => None,
                Some(w) if w >= 0.0 && w.fract() == 0.0 && w <= 2f64.powi(53) => Some(w as u64),
                Some(w) => {
                    return Err(rotorid_io::csv::CsvError::field(
                        f,
                        line,
                        col,
                        "window",
                        format!(
                            "window {w} is not a restart window: allowed a whole number >= 0, \
                             or empty"
                        ),
                    ))
                }
            },
        };
        let n = self.model.per_direction().len();
        let mut values = [None; 10];
        for (i, v) in values.iter_mut().take(n).enumerate() {
            *v = opt(1 + i)?;
        }
        Ok(Some(EstimateRow::new(
            finite_field(f, rec, line, c[0], "t")?,
            self.model,
            &values,
            [
                number_field(f, rec, line, c[n + 1], "rcond_x")?,
                number_field(f, rec, line, c[n + 2], "rcond_z")?,
            ],
            window,
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_with_missing_directions() {
        let j = ModelKind::Jeffcott;
        let rows = [
            EstimateRow::new(0.0, j, &[], [0.0, 0.0], Some(0)),
            EstimateRow::new(
                1e-4,
                j,
                &[Some(14.29), Some(10.000_000_1), Some(1.195e6)],
                [1.5e-3, 2e-9],
                Some(12),
            ),
            EstimateRow::new(2e-4, j, &[], [1.0, 1.0], None),
        ];
        let mut w = EstimatesWriter::for_model(Vec::new(), j).unwrap();
        for r in &rows {
            w.write(r).unwrap();
        }
        let text = String::from_utf8(w.into_inner()).unwrap();
        assert_eq!(
            text,
            "t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z,window\n0,,,,,,,0,0,0\n\
             0.0001,14.29,10.0000001,1195000,,,,0.0015,2e-9,12\n0.0002,,,,,,,1,1,\n"
        );
        let mut r = EstimatesReader::new("e.csv", text.as_bytes()).unwrap();
        for row in &rows {
            assert_eq!(r.next_row().unwrap().as_ref(), Some(row));
        }
        assert_eq!(r.next_row().unwrap(), None);
    }

    #[test]
    fn nan_reads_as_missing_and_errors_are_located() {
        let h = ESTIMATES_HEADER.join(",");
        let text = format!("{h}\n0,NaN,1,2,3,4,5,0.1,0.2,0\n");
        let mut r = EstimatesReader::new("e.csv", text.as_bytes()).unwrap();
        let row = r.next_row().unwrap().unwrap().jeffcott().unwrap();
        assert_eq!(row.m_x, None);
        assert_eq!(row.k_z, Some(5.0));
        let text = format!("{h}\n0,1,x,2,3,4,5,0.1,0.2,0\n");
        let mut r = EstimatesReader::new("e.csv", text.as_bytes()).unwrap();
        assert!(r
            .next_row()
            .unwrap_err()
            .to_string()
            .starts_with("e.csv line 2, column 3 (c_x): c_x \"x\" is not a number"));
        // a file of nine columns (before `window`) reads with no window
        let old = "t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z\n0,1,2,3,4,5,6,0.1,0.2\n";
        let mut r = EstimatesReader::new("e.csv", old.as_bytes()).unwrap();
        assert_eq!(r.next_row().unwrap().unwrap().window, None);
        // a window that is no window
        for bad in ["-1", "1.5", "inf"] {
            let text = format!("{h}\n0,1,2,3,4,5,6,0.1,0.2,{bad}\n");
            let mut r = EstimatesReader::new("e.csv", text.as_bytes()).unwrap();
            let e = r.next_row().unwrap_err().to_string();
            assert!(e.starts_with("e.csv line 2, column 10 (window): "), "{e}");
        }
        let e = EstimatesReader::new("e.csv", "t,m_x\n".as_bytes())
            .err()
            .unwrap();
        assert!(e
            .to_string()
            .starts_with("e.csv line 1: the header lacks columns c_x, k_x"));
    }

    #[test]
    fn cross_coupled_rows_round_trip_under_their_own_header() {
        let c = ModelKind::CrossCoupled;
        let values: Vec<Option<f64>> = (0..10)
            .map(|i| (i != 7).then_some((i as f64 - 4.5) * 1.25))
            .collect();
        let rows = [
            EstimateRow::new(0.5, c, &values, [1e-3, 2e-4], Some(3)),
            EstimateRow::new(0.6, c, &[], [0.0, 0.0], None),
        ];
        let mut w = EstimatesWriter::for_model(Vec::new(), c).unwrap();
        for r in &rows {
            w.write(r).unwrap();
        }
        let text = String::from_utf8(w.into_inner()).unwrap();
        assert_eq!(
            text,
            "t,m_x,cxx,cxz,kxx,kxz,m_z,czx,czz,kzx,kzz,rcond_x,rcond_z,window\n\
             0.5,-5.625,-4.375,-3.125,-1.875,-0.625,0.625,1.875,,4.375,5.625,0.001,0.0002,3\n\
             0.6,,,,,,,,,,,0,0,\n"
        );
        let mut r = EstimatesReader::new("e.csv", text.as_bytes()).unwrap();
        assert_eq!(r.model(), c);
        for row in &rows {
            assert_eq!(r.next_row().unwrap().as_ref(), Some(row));
        }
        assert_eq!(rows[0].jeffcott(), None);
    }
}
