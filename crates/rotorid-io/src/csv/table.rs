//! A whole CSV file as a [`Table`]: every column a channel, named by its header (trimmed,
//! a byte-order mark dropped, case kept), with the unit of its suffix (`probe_L [V]`), for
//! readers that need arbitrary columns (raw acquisitions, `rotorid inspect`). Every field
//! must be a number (NaN and infinities are data here, as in every reader of this crate);
//! rows as long as the header. Errors name the file, the line and the column.

use std::io::Read;

use super::columns::{check_length, csv_reader, next_record, number_field, Header};
use super::error::CsvError;
use crate::table::{Channel, Table};
use crate::units::split_unit;

/// Read the CSV `input` whole; `file` names it in messages and in the table.
pub fn read_csv_table<R: Read>(file: &str, input: R) -> Result<Table, CsvError> {
    let mut csv = csv_reader(input);
    let Some(rec) = next_record(file, &mut csv)? else {
        return Err(CsvError::file(
            file,
            "the file is empty: expected a header line naming the columns, then one row per \
             sample",
        ));
    };
    let line = rec.line();
    let header = Header::new(&rec, line);
    let mut channels: Vec<Channel> = rec
        .iter()
        .map(|raw| {
            let text = String::from_utf8_lossy(raw);
            let (name, unit) = split_unit(text.trim_start_matches('\u{feff}'));
            Channel {
                name: name.to_owned(),
                unit: unit.map(str::to_owned),
                data: Vec::new(),
                axis: None,
            }
        })
        .collect();
    while let Some(rec) = next_record(file, &mut csv)? {
        let line = rec.line();
        check_length(file, &rec, line, &header)?;
        for (col, ch) in channels.iter_mut().enumerate() {
            ch.data.push(number_field(file, &rec, line, col, &ch.name)?);
        }
    }
    Ok(Table {
        file: file.to_owned(),
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_with_units_and_case_kept() {
        let t = read_csv_table(
            "raw.csv",
            "\u{feff}t,probe_L [V], kp (mV)\n0,1.5,-2\n1e-4,1.25,NaN\n".as_bytes(),
        )
        .unwrap();
        let names: Vec<_> = t.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["t", "probe_L", "kp"]);
        assert_eq!(t.channels[1].unit.as_deref(), Some("V"));
        assert_eq!(t.channels[2].unit.as_deref(), Some("mV"));
        assert_eq!(t.channels[1].data, [1.5, 1.25]);
        assert!(t.channels[2].data[1].is_nan());
    }

    #[test]
    fn bad_fields_are_located() {
        let e = read_csv_table("raw.csv", "t,v\n0,1\n1,x\n".as_bytes()).unwrap_err();
        assert!(
            e.to_string().starts_with("raw.csv line 3, column 2 (v)"),
            "{e}"
        );
        let e = read_csv_table("raw.csv", "t,v\n0\n".as_bytes()).unwrap_err();
        assert!(e.to_string().starts_with("raw.csv line 2"), "{e}");
        assert!(read_csv_table("raw.csv", "".as_bytes()).is_err());
    }
}
