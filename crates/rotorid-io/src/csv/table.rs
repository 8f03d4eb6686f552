//! A whole CSV file as a [`Table`]: every column a channel, named by its header (trimmed,
//! a byte-order mark dropped, case kept), with the unit of its suffix (`probe_L [V]`), for
//! readers that need arbitrary columns (raw acquisitions, `rotorid inspect`). Every field
//! must be a number (NaN and infinities are data here, as in every reader of this crate);
//! rows as long as the header. Errors name the file, the line and the column.

use std::io::Read;

use super::columns::{
    check_length, csv_reader, line_prefix, next_raw, next_record, number_field, one_pass, Header,
};
use super::error::CsvError;
use super::records::{split_line, RawRecord};
use crate::table::{Channel, Table};
use crate::units::split_unit;

/// Read the CSV `input` whole; `file` names it in messages and in the table.
pub fn read_csv_table<R: Read>(file: &str, input: R) -> Result<Table, CsvError> {
    read(file, input, true)
}

/// [`read_csv_table`], its one-pass parse of plain lines on or off (off only in tests).
fn read<R: Read>(file: &str, input: R, fast: bool) -> Result<Table, CsvError> {
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
    // A plain line is parsed in one pass into `row` (columns::line_prefix, straight out of
    // the read buffer: the same values as the general path); any other goes field by
    // field, which names what is wrong.
    let mut row = vec![0.0; channels.len()];
    let mut fields = Vec::with_capacity(channels.len());
    loop {
        if fast {
            let taken = csv.try_line(|rest| {
                let len = line_prefix(
                    rest,
                    row.len(),
                    |_| true,
                    |j, v| {
                        row[j] = v;
                        Some(())
                    },
                )?;
                Some(((), len))
            });
            if taken.is_some() {
                for (ch, &v) in channels.iter_mut().zip(&row) {
                    ch.data.push(v);
                }
                continue;
            }
        }
        let Some(raw) = next_raw(file, &mut csv)? else {
            break;
        };
        let rec = match raw {
            RawRecord::Line { text, line } => {
                let parsed = fast
                    && one_pass(
                        text,
                        row.len(),
                        |_| true,
                        |j, v| {
                            row[j] = v;
                            Some(())
                        },
                    )
                    .is_some();
                if parsed {
                    for (ch, &v) in channels.iter_mut().zip(&row) {
                        ch.data.push(v);
                    }
                    continue;
                }
                split_line(text, line, &mut fields)
            }
            RawRecord::Quoted(rec) => rec,
        };
        let line = rec.line();
        check_length(file, &rec, line, &header)?;
        for (col, ch) in channels.iter_mut().enumerate() {
            ch.data.push(number_field(file, &rec, line, col, &ch.name)?);
        }
    }
    Ok(Table {
        file: file.to_owned(),
        channels,
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use proptest::strategy::Strategy;

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

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]

        /// With and without the one-pass parse, the same channels bit for bit (NaN and
        /// infinities included) or the same message.
        #[test]
        fn the_one_pass_parse_changes_no_value_and_no_message(
            cols in 1usize..5,
            rows in proptest::collection::vec(
                proptest::collection::vec(
                    proptest::prop_oneof![
                        4 => proptest::num::f64::ANY.prop_map(|v| format!("{v:e}")),
                        2 => (-1e3f64..1e3).prop_map(|v| v.to_string()),
                        1 => proptest::sample::select(vec![
                            "", " 1", "1 ", "nan", "NaN", "-inf", "inf", "Infinity", "1e400",
                            "+2.5", ".5", "5.", "1e", "0x10", "abc", "\"3\"", "-0", "nan(1)",
                        ]).prop_map(str::to_owned),
                    ],
                    6,
                ),
                0..6,
            ),
            ends in proptest::collection::vec(0u8..5, 1..4),
            step in 1usize..40,
        ) {
            let mut text = (0..cols).map(|c| format!("c{c}")).collect::<Vec<_>>().join(",");
            text.push('\n');
            for (i, row) in rows.iter().enumerate() {
                let n = match i % 4 { 1 => cols + 1, 3 => cols - 1, _ => cols };
                text.push_str(&row[..n].join(","));
                // LF, CRLF, a lone CR, a blank line after, or no line end at the end
                let last = i + 1 == rows.len();
                text.push_str(super::super::test_line_end(ends[i % ends.len()], last));
            }
            let bits = |fast, step| {
                let input = super::super::Trickle { text: text.as_bytes(), step };
                read("t.csv", input, fast)
                    .map(|t| {
                        t.channels
                            .iter()
                            .map(|c| c.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
                            .collect::<Vec<_>>()
                    })
                    .map_err(|e| e.to_string())
            };
            let general = bits(false, usize::MAX);
            proptest::prop_assert_eq!(&bits(true, usize::MAX), &general, "{}", text);
            proptest::prop_assert_eq!(&bits(true, step), &general, "{} bytes per read: {}", step, text);
        }
    }
}
