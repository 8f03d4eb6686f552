//! Records read a block of rows at a time, for formats whose layout allows it (TDMS
//! segments, Parquet row groups and pages): memory then holds a few blocks, never the
//! record, so a recording of any length can be identified.
//!
//! A [`RowBlocks`] reader first reads the file's catalogue (each channel's name, unit,
//! length and time axis: [`ChannelInfo`]), checking the file's structure as the whole-file
//! reader does; then it gives the rows of the channels asked for, in order, a block at a
//! time. [`SiBlocks`] picks the channels that play t, x, z, phi, phi_dot, phi_ddot by the
//! same rules and checks as [`crate::select()`] (it plans on the catalogue, before any
//! sample is read), and converts each block to SI with the same conversions; so the samples
//! are the ones `select(read_table(..))` gives, bit for bit, in blocks.
//!
//! [`open_blocks`] opens a file this way when its format streams (`None` otherwise: read
//! it whole with [`crate::read_table`]).

use std::path::Path;

use crate::error::ReadError;
use crate::format::Format;
use crate::select::{into_roles, plan, ColumnMap, SelectError, Used, ROLES};
use crate::table::{ChannelInfo, TimeAxis};
use crate::units::Conversion;

/// A file read a block of rows at a time (module doc).
pub trait RowBlocks: Send {
    /// The file's name, for messages.
    fn file(&self) -> &str;

    /// The numeric channels, in file order, as the whole-file reader lists them.
    fn channels(&self) -> &[ChannelInfo];

    /// What the reader has to tell about the file that is not an error, as
    /// [`crate::Table::notes`].
    fn notes(&self) -> &[String];

    /// Appends the next rows of the channels `wanted` (indices into
    /// [`channels`](Self::channels), distinct, all of one length) to `out` (`out[k]` for
    /// `wanted[k]`): the same number of rows to each, at most `max_rows` (>= 1), and
    /// returns it; 0 once every row was given. Each channel's rows go on from where its last
    /// call left them (so channels of other lengths are read by other calls). An error
    /// names the file, the channel and the byte offset, as the whole-file reader's does.
    fn next_rows(
        &mut self,
        wanted: &[usize],
        max_rows: usize,
        out: &mut [Vec<f64>],
    ) -> Result<usize, ReadError>;
}

/// The check every [`RowBlocks::next_rows`] makes of its arguments: `wanted` holds
/// distinct indices below `channels`, and `out` one list for each.
pub(crate) fn check_wanted(
    file: &str,
    channels: usize,
    wanted: &[usize],
    out: &[Vec<f64>],
) -> Result<(), ReadError> {
    let distinct = wanted
        .iter()
        .enumerate()
        .all(|(j, &k)| k < channels && !wanted[..j].contains(&k));
    if distinct && wanted.len() == out.len() {
        return Ok(());
    }
    Err(ReadError::Invalid {
        file: file.to_owned(),
        channel: None,
        offset: 0,
        what: "channels asked for".into(),
        found: format!("{wanted:?} with {} lists to fill", out.len()),
        allowed: format!("distinct indices below {channels}, one list each"),
    })
}

/// The file at `path` read a block at a time, when its format allows it (TDMS, Parquet);
/// `None` for the others.
pub fn open_blocks(path: impl AsRef<Path>) -> Result<Option<Box<dyn RowBlocks>>, ReadError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    match Format::from_path(path)? {
        Format::Parquet => Ok(Some(Box::new(crate::parquet::open_blocks(&file, path)?))),
        Format::Tdms => Ok(Some(Box::new(crate::tdms::open_blocks(&file, path)?))),
        _ => Ok(None),
    }
}

/// Every row of every channel of `reader`, the channels of each length together (one
/// call of [`RowBlocks::next_rows`] gives rows of channels of one length), at most
/// `max_rows` a block: `each(channels, rows)` for each block, `rows[k]` the rows of channel
/// `channels[k]`. A reader that gives a channel more or fewer rows than its catalogue says
/// is an error (a file that changed while it was read).
pub fn for_each_block(
    reader: &mut dyn RowBlocks,
    max_rows: usize,
    each: impl FnMut(&[usize], &[Vec<f64>]),
) -> Result<(), ReadError> {
    let all: Vec<usize> = (0..reader.channels().len()).collect();
    for_each_block_of(reader, &all, max_rows, each)
}

/// [`for_each_block`] over the channels `channels` of `reader` only (indices into its
/// catalogue, distinct, each not yet read).
pub fn for_each_block_of(
    reader: &mut dyn RowBlocks,
    channels: &[usize],
    max_rows: usize,
    mut each: impl FnMut(&[usize], &[Vec<f64>]),
) -> Result<(), ReadError> {
    let lens: Vec<usize> = reader.channels().iter().map(|c| c.len).collect();
    let mut groups: Vec<usize> = channels
        .iter()
        .filter_map(|&k| lens.get(k).copied())
        .collect();
    groups.sort_unstable();
    groups.dedup();
    for len in groups {
        let wanted: Vec<usize> = channels
            .iter()
            .copied()
            .filter(|&k| lens.get(k) == Some(&len))
            .collect();
        let mut rows: Vec<Vec<f64>> = wanted.iter().map(|_| Vec::new()).collect();
        let mut total = 0usize;
        loop {
            rows.iter_mut().for_each(Vec::clear);
            let n = reader.next_rows(&wanted, max_rows.max(1), &mut rows)?;
            debug_assert!(rows.iter().all(|r| r.len() == n), "the same rows to each");
            total = total.saturating_add(n);
            if n == 0 || total > len {
                break;
            }
            each(&wanted, &rows);
        }
        if total != len {
            return Err(not_as_catalogued(&*reader, wanted[0], total));
        }
    }
    Ok(())
}

/// The error for a reader that gave channel `k` `total` rows where its catalogue says
/// otherwise.
fn not_as_catalogued(reader: &dyn RowBlocks, k: usize, total: usize) -> ReadError {
    let c = &reader.channels()[k];
    ReadError::Container {
        file: reader.file().to_owned(),
        channel: Some(c.name.clone()),
        container: "stream",
        message: format!(
            "the file gave {total} rows where its catalogue says {}; did it change while \
             it was read?",
            c.len
        ),
    }
}

/// One block of the record in SI: rows `first..first + len` of t \[s\], x, z \[m\] and,
/// when the file has them, phi \[rad\], phi_dot \[rad/s\], phi_ddot \[rad/s^2\].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SiBlock {
    /// Index of the block's first row in the record.
    pub first: usize,
    /// Time stamps \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement \[m\].
    pub z: Vec<f64>,
    /// phi \[rad\], phi_dot \[rad/s\], phi_ddot \[rad/s^2\].
    pub speed: Option<[Vec<f64>; 3]>,
}

impl SiBlock {
    /// Rows in the block.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True for a block of no rows.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// The channels of a [`RowBlocks`] reader that play t, x, z, phi, phi_dot, phi_ddot, in SI,
/// a block at a time (module doc).
pub struct SiBlocks {
    inner: Box<dyn RowBlocks>,
    /// (role, position in `wanted`, conversion), in the order of [`crate::select()`].
    order: Vec<(usize, usize, Conversion)>,
    /// The distinct channels read.
    wanted: Vec<usize>,
    /// t from the file's time axis.
    axis: Option<TimeAxis>,
    speed: bool,
    used: Vec<Used>,
    len: usize,
    /// Rows given so far.
    done: usize,
}

impl SiBlocks {
    /// The channels of `inner` that play the roles of `map`, checked on its catalogue with
    /// the checks and messages of [`crate::select()`].
    pub fn new(inner: Box<dyn RowBlocks>, map: &ColumnMap) -> Result<Self, SelectError> {
        let plan = plan(inner.file(), inner.channels(), map)?;
        let mut wanted: Vec<usize> = Vec::with_capacity(plan.order.len());
        let mut order = Vec::with_capacity(plan.order.len());
        let mut used = Vec::with_capacity(plan.order.len());
        for &(role, i, conv) in &plan.order {
            let k = match wanted.iter().position(|&w| w == i) {
                Some(k) => k,
                None => {
                    wanted.push(i);
                    wanted.len() - 1
                }
            };
            order.push((role, k, conv));
            used.push(Used {
                role: ROLES[role],
                channel: inner.channels()[i].name.clone(),
                conversion: conv,
            });
        }
        // x is planned first: its length is the record's
        let len = inner.channels()[plan.order[0].1].len;
        Ok(Self {
            inner,
            order,
            wanted,
            axis: plan.axis.map(|(a, _)| a),
            speed: plan.speed,
            used,
            len,
            done: 0,
        })
    }

    /// The file's name.
    pub fn file(&self) -> &str {
        self.inner.file()
    }

    /// What the reader noted about the file (see [`RowBlocks::notes`]).
    pub fn notes(&self) -> &[String] {
        self.inner.notes()
    }

    /// The channel that plays each role, with its conversion (as [`crate::SiColumns::used`]).
    pub fn used(&self) -> &[Used] {
        &self.used
    }

    /// True when t comes from the file's time axis.
    pub fn time_from_axis(&self) -> bool {
        self.axis.is_some()
    }

    /// True when the file has phi, phi_dot and phi_ddot.
    pub fn has_speed(&self) -> bool {
        self.speed
    }

    /// Rows in the record.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True for a record of no rows.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The next block of at most `max_rows` (>= 1) rows, `None` after the last.
    pub fn next_block(&mut self, max_rows: usize) -> Result<Option<SiBlock>, ReadError> {
        let mut raw: Vec<Vec<f64>> = self
            .wanted
            .iter()
            .map(|_| Vec::with_capacity(max_rows.min(self.len - self.done)))
            .collect();
        let n = self
            .inner
            .next_rows(&self.wanted, max_rows.max(1), &mut raw)?;
        if n == 0 && self.done == self.len {
            return Ok(None);
        }
        if n == 0 || self.done + n > self.len {
            return Err(not_as_catalogued(
                &*self.inner,
                self.wanted[0],
                self.done + n,
            ));
        }
        // each channel's buffer becomes its (first) role's column, converted in place
        let out = into_roles(&self.order, &mut raw);
        let first = self.done;
        self.done += n;
        let [t, x, z, phi, phi_dot, phi_ddot] = out;
        Ok(Some(SiBlock {
            first,
            t: match self.axis {
                Some(a) => (first..first + n).map(|i| a.time(i)).collect(),
                None => t,
            },
            x,
            z,
            speed: self.speed.then_some([phi, phi_dot, phi_ddot]),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::select::select;
    use crate::table::{Channel, Table};

    /// A table given a block at a time, `step` rows at most per call whatever is asked:
    /// the reader the stream is checked with.
    struct TableBlocks {
        table: Table,
        infos: Vec<ChannelInfo>,
        /// Rows given so far, by channel.
        done: std::collections::HashMap<usize, usize>,
        step: usize,
    }

    impl TableBlocks {
        fn new(table: Table, step: usize) -> Self {
            let infos = table
                .channels
                .iter()
                .map(|c| ChannelInfo {
                    name: c.name.clone(),
                    unit: c.unit.clone(),
                    len: c.data.len(),
                    axis: c.axis,
                })
                .collect();
            Self {
                table,
                infos,
                done: Default::default(),
                step,
            }
        }
    }

    impl RowBlocks for TableBlocks {
        fn file(&self) -> &str {
            &self.table.file
        }
        fn channels(&self) -> &[ChannelInfo] {
            &self.infos
        }
        fn notes(&self) -> &[String] {
            &self.table.notes
        }
        fn next_rows(
            &mut self,
            wanted: &[usize],
            max_rows: usize,
            out: &mut [Vec<f64>],
        ) -> Result<usize, ReadError> {
            // (the rows the channels hold, whatever the catalogue says: a test may make it lie)
            let done = self.done.get(&wanted[0]).copied().unwrap_or(0);
            let len = wanted
                .iter()
                .map(|&k| self.table.channels[k].data.len())
                .min()
                .unwrap_or(0);
            let n = max_rows.min(self.step).min(len - done);
            for (&k, o) in wanted.iter().zip(out.iter_mut()) {
                o.extend_from_slice(&self.table.channels[k].data[done..done + n]);
            }
            for &k in wanted {
                self.done.insert(k, done + n);
            }
            Ok(n)
        }
    }

    fn ch(name: &str, unit: Option<&str>, data: Vec<f64>, axis: Option<TimeAxis>) -> Channel {
        Channel {
            name: name.into(),
            unit: unit.map(str::to_owned),
            data,
            axis,
        }
    }

    /// Every block of `blocks`, concatenated, as columns.
    fn gather(mut blocks: SiBlocks, max_rows: usize) -> [Vec<f64>; 6] {
        let mut all: [Vec<f64>; 6] = Default::default();
        while let Some(b) = blocks.next_block(max_rows).unwrap() {
            assert_eq!(b.first, all[1].len());
            assert!(b.len() <= max_rows && !b.is_empty());
            for (a, part) in all.iter_mut().zip([&b.t, &b.x, &b.z]) {
                a.extend(part);
            }
            if let Some(s) = &b.speed {
                for (a, part) in all[3..].iter_mut().zip(s) {
                    a.extend(part);
                }
            }
        }
        all
    }

    #[test]
    fn blocks_in_si_are_the_selected_columns_bit_for_bit() {
        let n = 1000;
        let v = |k: f64| -> Vec<f64> { (0..n).map(|i| (i as f64 * 0.37 + k).sin()).collect() };
        let axis = TimeAxis {
            start: 0.125,
            increment: 1e-4 / 3.0,
        };
        // units to convert, a time axis, and one channel playing x and z
        let table = Table {
            file: "rec.tdms".into(),
            channels: vec![
                ch("g/probe", Some("um"), v(1.0), Some(axis)),
                ch("g/phi", Some("deg"), v(2.0), None),
                ch("g/phi_dot", Some("rpm"), v(3.0), None),
                ch("g/phi_ddot", Some("rad/s^2"), v(4.0), None),
                ch("g/other", Some("furlong"), v(5.0), None),
            ],
            notes: vec!["a note".into()],
        };
        let map = ColumnMap::parse("t,probe,probe,phi,phi_dot,phi_ddot").unwrap();
        let whole = select(table.clone(), &map).unwrap();
        for (step, max_rows) in [(1000, 1000), (7, 1000), (1000, 7), (64, 100), (1, 1)] {
            let blocks =
                SiBlocks::new(Box::new(TableBlocks::new(table.clone(), step)), &map).unwrap();
            assert_eq!(blocks.used(), whole.used.as_slice());
            assert!(blocks.time_from_axis() && blocks.has_speed());
            assert_eq!(
                (blocks.len(), blocks.notes()),
                (n, &["a note".to_owned()][..])
            );
            let got = gather(blocks, max_rows);
            let speed = whole.speed.as_ref().unwrap();
            let want = [
                &whole.t, &whole.x, &whole.z, &speed[0], &speed[1], &speed[2],
            ];
            for (role, (g, w)) in got.iter().zip(want).enumerate() {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(g),
                    bits(w),
                    "role {role}, step {step}, blocks of {max_rows}"
                );
            }
        }
    }

    #[test]
    fn every_channel_whole_by_length_and_a_reader_that_breaks_its_catalogue_is_an_error() {
        let table = Table {
            file: "rec.tdms".into(),
            channels: vec![
                ch("a", None, (0..10).map(f64::from).collect(), None),
                ch("b", None, (0..4).map(f64::from).collect(), None),
                ch("c", None, (10..20).map(f64::from).collect(), None),
            ],
            notes: Vec::new(),
        };
        let mut r = TableBlocks::new(table.clone(), 3);
        let mut got = vec![Vec::new(); 3];
        for_each_block(&mut r, 100, |which, rows| {
            for (&k, part) in which.iter().zip(rows) {
                assert!(part.len() <= 3);
                got[k].extend_from_slice(part);
            }
        })
        .unwrap();
        let want: Vec<Vec<f64>> = table.channels.iter().map(|c| c.data.clone()).collect();
        assert_eq!(got, want);
        // one channel alone, then the others: each from its start, whole
        let mut r = TableBlocks::new(table.clone(), 3);
        let mut got = vec![Vec::new(); 3];
        for only in [[2].as_slice(), &[0, 1]] {
            for_each_block_of(&mut r, only, 4, |which, rows| {
                for (&k, part) in which.iter().zip(rows) {
                    assert!(only.contains(&k));
                    got[k].extend_from_slice(part);
                }
            })
            .unwrap();
        }
        assert_eq!(got, want);
        // a catalogue that says more rows than the file gives, or fewer
        for len in [12, 8] {
            let mut r = TableBlocks::new(table.clone(), 3);
            r.infos[0].len = len;
            r.infos[2].len = len;
            let e = for_each_block(&mut r, 100, |_, _| {})
                .unwrap_err()
                .to_string();
            assert!(e.contains("catalogue says") && e.contains("\"a\""), "{e}");
            let mut r = TableBlocks::new(table.clone(), 3);
            r.infos[1].len = len;
            r.infos[2].len = len;
            let mut s = SiBlocks::new(Box::new(r), &ColumnMap::parse("b,c,c").unwrap()).unwrap();
            let e = std::iter::from_fn(|| s.next_block(5).transpose())
                .find_map(Result::err)
                .unwrap()
                .to_string();
            assert!(e.contains("catalogue says"), "{e}");
        }
    }

    #[test]
    fn a_record_refused_by_select_is_refused_before_reading() {
        let table = Table {
            file: "rec.parquet".into(),
            channels: vec![
                ch("x", None, vec![1.0, 2.0], None),
                ch("z", None, vec![1.0], None),
            ],
            notes: Vec::new(),
        };
        let map = ColumnMap::default();
        let whole = select(table.clone(), &map).unwrap_err();
        let streamed = SiBlocks::new(Box::new(TableBlocks::new(table, 1)), &map).err();
        assert_eq!(streamed, Some(whole));
    }
}
