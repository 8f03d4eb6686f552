//! The response CSV `rotorid simulate` writes and `rotorid identify` reads, read whole into
//! columns by the command's own reader (`rotorid_io::csv::ResponseReader`, whose module doc
//! has the rules), so the values are bit for bit the command's and the messages its
//! messages (`FILE line L, column C (NAME): ...`).

use std::io::Read;

use rotorid_io::csv::ResponseReader;

use crate::error::Error;

/// A response read whole: t \[s\], x, z \[m\] and, when the file has them, phi \[rad\],
/// phi_dot \[rad/s\], phi_ddot \[rad/s^2\].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Response {
    /// Time stamps \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement \[m\].
    pub z: Vec<f64>,
    /// phi, phi_dot, phi_ddot.
    pub speed: Option<[Vec<f64>; 3]>,
    /// The columns the file gives in other units than SI, each with that unit (`("x",
    /// "um")`), in the order t, x, z, phi, phi_dot, phi_ddot: their values above are
    /// converted to SI.
    pub converted: Vec<(String, String)>,
    /// What the reader noted about the file that is not an error (an interrupted TDMS
    /// recording whose unfinished chunk was not read), one sentence each.
    pub notes: Vec<String>,
}

/// Read the response CSV at `path` (module doc).
pub fn read(path: &str) -> Result<Response, Error> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    parse(path, file)
}

/// Read the record at `path` in any format `rotorid_io` reads: a CSV without `columns`
/// streamed as [`read`] does; otherwise the whole file as a table whose channels for t, x,
/// z (and phi, phi_dot, phi_ddot) `columns` names (`"t,x,z"` or six names; default the
/// role names), converted to SI from the units the file gives.
pub fn read_any(path: &str, columns: Option<&str>) -> Result<Response, Error> {
    // any other extension is read as the response CSV, as before
    let format = rotorid_io::Format::from_path(std::path::Path::new(path)).ok();
    if matches!(format, None | Some(rotorid_io::Format::Csv)) && columns.is_none() {
        return read(path);
    }
    let table = rotorid_io::read_table(path)?;
    let map = rotorid_io::ColumnMap::from_spec(columns)?;
    let notes = table.notes.clone();
    let s = rotorid_io::select(table, &map)?;
    Ok(Response {
        notes,
        converted: converted_of(&s.used),
        t: s.t,
        x: s.x,
        z: s.z,
        speed: s.speed,
    })
}

/// A record read a block of rows at a time, in SI: a TDMS or Parquet file streamed
/// (`rotorid_io::stream`: memory holds a block, whatever the record's length); any other
/// format read whole as [`read_any`] reads it, then handed out a block at a time. The
/// samples are [`read_any`]'s, bit for bit.
pub struct BlockReader {
    source: BlockSource,
    /// Rows a block holds at most.
    rows: usize,
    /// As [`Response::converted`].
    pub converted: Vec<(String, String)>,
    /// As [`Response::notes`].
    pub notes: Vec<String>,
}

enum BlockSource {
    Streamed(rotorid_io::SiBlocks),
    Whole { r: Response, next: usize },
}

/// Open the record at `path` to read it `rows` rows (>= 1) at a time; `columns` as in
/// [`read_any`].
pub fn open_blocks(path: &str, columns: Option<&str>, rows: usize) -> Result<BlockReader, Error> {
    if rows == 0 {
        return Err(Error::invalid(
            "rows = 0 is out of range: a block holds at least one row (an integer >= 1)",
        ));
    }
    let format = rotorid_io::Format::from_path(std::path::Path::new(path)).ok();
    let streamed = match format {
        Some(rotorid_io::Format::Csv) | None => None,
        Some(_) => rotorid_io::open_blocks(path)?,
    };
    let Some(reader) = streamed else {
        let r = read_any(path, columns)?;
        return Ok(BlockReader {
            rows,
            converted: r.converted.clone(),
            notes: r.notes.clone(),
            source: BlockSource::Whole { r, next: 0 },
        });
    };
    let notes = reader.notes().to_vec();
    let map = rotorid_io::ColumnMap::from_spec(columns)?;
    let blocks = rotorid_io::SiBlocks::new(reader, &map)?;
    Ok(BlockReader {
        rows,
        converted: converted_of(blocks.used()),
        notes,
        source: BlockSource::Streamed(blocks),
    })
}

/// The roles whose channel was converted to SI, each with the unit the file gave.
fn converted_of(used: &[rotorid_io::select::Used]) -> Vec<(String, String)> {
    used.iter()
        .filter(|u| !u.conversion.is_identity())
        .map(|u| (u.role.to_owned(), u.conversion.unit.to_owned()))
        .collect()
}

impl BlockReader {
    /// The next block, `None` after the last.
    pub fn next_block(&mut self) -> Result<Option<rotorid_io::SiBlock>, Error> {
        match &mut self.source {
            BlockSource::Streamed(b) => Ok(b.next_block(self.rows)?),
            BlockSource::Whole { r, next } => {
                let first = *next;
                let end = first.saturating_add(self.rows).min(r.x.len());
                if first >= end {
                    return Ok(None);
                }
                *next = end;
                Ok(Some(rotorid_io::SiBlock {
                    first,
                    t: r.t[first..end].to_vec(),
                    x: r.x[first..end].to_vec(),
                    z: r.z[first..end].to_vec(),
                    speed: r
                        .speed
                        .as_ref()
                        .map(|s| s.each_ref().map(|c| c[first..end].to_vec())),
                }))
            }
        }
    }
}

/// Read a response CSV from `input`; `file` names it in messages.
pub fn parse<R: Read>(file: &str, input: R) -> Result<Response, Error> {
    let mut reader = ResponseReader::new(file, input)?;
    let converted = reader
        .conversions()
        .into_iter()
        .map(|(name, c)| (name.to_owned(), c.unit.to_owned()))
        .collect();
    let c = reader.read_columns()?;
    Ok(Response {
        t: c.t,
        x: c.x,
        z: c.z,
        speed: c.speed,
        converted,
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse("d.csv", text.as_bytes())
            .expect_err("must be refused")
            .to_string()
    }

    #[test]
    fn any_order_units_and_extra_columns() {
        let r = parse(
            "d.csv",
            "note,Z [m],t (s),x\nabc,2,0,1\nzz,4,0.5,3\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(
            (r.t, r.x, r.z),
            (vec![0.0, 0.5], vec![1.0, 3.0], vec![2.0, 4.0])
        );
        assert!(r.speed.is_none());
        let r = parse(
            "d.csv",
            "t,x,z,phi,phi_dot,phi_ddot\n0,1.5e-7,-3.3e-300,0.1,125.66370614359172,0\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(r.z[0], -3.3e-300);
        assert_eq!(r.speed.unwrap()[1][0], 125.66370614359172);
    }

    #[test]
    fn units_convert_and_are_reported() {
        let r = parse(
            "d.csv",
            "t,x [um],z [m],phi [deg],phi_dot [rpm],phi_ddot\n0,12.5,1,180,60,0\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(r.x, vec![12.5 / 1e6]);
        assert_eq!(r.z, vec![1.0]);
        assert_eq!(
            r.converted,
            vec![
                ("x".to_owned(), "um".to_owned()),
                ("phi".to_owned(), "deg".to_owned()),
                ("phi_dot".to_owned(), "rpm".to_owned())
            ]
        );
        assert!(err("t,x [furlong],z\n").starts_with(
            "d.csv line 1, column 2 (x): unknown unit \"furlong\" for a displacement"
        ));
    }

    #[test]
    fn messages_are_the_commands() {
        assert!(err("").starts_with("d.csv: the file is empty"));
        assert!(err("t,x\n0,1\n").starts_with("d.csv line 1: the header lacks column z;"));
        assert!(err("t,x,z,phi\n").starts_with(
            "d.csv line 1: the header has some but not all of phi, phi_dot, phi_ddot: missing \
             phi_dot, phi_ddot"
        ));
        assert!(err("t,x,z,x\n")
            .starts_with("d.csv line 1, column 4 (x): column x appears twice (columns 2 and 4)"));
        let h = "t,x,z\n0,0,0\n0.1,0,0\n";
        assert_eq!(
            err(&format!("{h}0.2,abc,0\n")),
            "d.csv line 4, column 2 (x): x \"abc\" is not a number: expected a number"
        );
        assert!(err(&format!("{h}0.2,0,nan\n"))
            .starts_with("d.csv line 4, column 3 (z): z = NaN is not finite"));
        assert_eq!(
            err(&format!("{h}0.2,0\n")),
            "d.csv line 4: short row: 2 fields where the header (line 1) has 3"
        );
    }
}
