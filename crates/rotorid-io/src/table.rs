//! Named channels of samples, as any reader yields them.

/// A uniform time axis implied by the file rather than stored as a channel: sample `i` is
/// at `start + i * increment` (TDMS `wf_start_offset` / `wf_increment`, a UFF58 abscissa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeAxis {
    /// Time of the first sample \[s\].
    pub start: f64,
    /// Sampling interval \[s\], > 0.
    pub increment: f64,
}

impl TimeAxis {
    /// The times of the first `n` samples \[s\]: `start + i * increment`.
    pub fn times(&self, n: usize) -> Vec<f64> {
        (0..n).map(|i| self.time(i)).collect()
    }

    /// The time of sample `i` \[s\]: `start + i * increment`.
    #[inline]
    pub fn time(&self, i: usize) -> f64 {
        self.start + i as f64 * self.increment
    }
}

/// One channel of a file: its name, the unit the file gives, and its samples as stored
/// (not yet converted to SI; see [`crate::units`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The name as the file spells it: a CSV header without its unit suffix, a MAT
    /// variable (`x`) or struct field (`rec.x`), a TDMS `group/channel`, an NPZ array name,
    /// a Parquet column.
    pub name: String,
    /// The unit text the file gives (`um`, `rpm`, `V`), if any.
    pub unit: Option<String>,
    /// The samples, in the file's unit.
    pub data: Vec<f64>,
    /// The time axis the file implies for this channel, if any.
    pub axis: Option<TimeAxis>,
}

/// What a reader knows of a channel before reading its samples: a streaming reader's
/// catalogue ([`crate::stream`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    /// The name, as a [`Channel`] is named.
    pub name: String,
    /// The unit text the file gives, if any.
    pub unit: Option<String>,
    /// Number of samples.
    pub len: usize,
    /// The time axis the file implies for this channel, if any.
    pub axis: Option<TimeAxis>,
}

/// A channel's name, unit, length and time axis, whether its samples are held
/// ([`Channel`]) or still in the file ([`ChannelInfo`]): what selecting channels looks at.
pub(crate) trait Described {
    fn name(&self) -> &str;
    fn unit(&self) -> Option<&str>;
    fn len(&self) -> usize;
    fn axis(&self) -> Option<TimeAxis>;
}

impl Described for Channel {
    fn name(&self) -> &str {
        &self.name
    }
    fn unit(&self) -> Option<&str> {
        self.unit.as_deref()
    }
    fn len(&self) -> usize {
        self.data.len()
    }
    fn axis(&self) -> Option<TimeAxis> {
        self.axis
    }
}

impl Described for ChannelInfo {
    fn name(&self) -> &str {
        &self.name
    }
    fn unit(&self) -> Option<&str> {
        self.unit.as_deref()
    }
    fn len(&self) -> usize {
        self.len
    }
    fn axis(&self) -> Option<TimeAxis> {
        self.axis
    }
}

/// The channels of one file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// The file's name as given by the user, for messages.
    pub file: String,
    /// The channels, in file order.
    pub channels: Vec<Channel>,
    /// What the reader has to tell about the file that is not an error (a recording
    /// interrupted mid-segment, whose unfinished chunk was not read): one sentence each,
    /// for the caller to show.
    pub notes: Vec<String>,
}

impl Table {
    /// The channel called `name`: an exact match first; else, when `name` has no
    /// separator, the one channel whose last component (after `.` or `/`) is `name`.
    /// `None` when there is none or the short name is ambiguous (see [`Table::candidates`]).
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channel_index(name).map(|i| &self.channels[i])
    }

    /// The index in [`Table::channels`] of the channel [`Table::channel`] finds.
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        index_named(&self.channels, |c| &c.name, name)
    }

    /// Channels whose last component (after the last `.` or `/`) is `name`.
    pub fn candidates<'a, 'n>(&'a self, name: &'n str) -> impl Iterator<Item = &'a Channel> + 'n
    where
        'a: 'n,
    {
        indices_short_named(&self.channels, |c| &c.name, name).map(|i| &self.channels[i])
    }
}

/// The index of the item of `items` called `name` (`name_of` gives an item's name), as
/// [`Table::channel_index`] finds it: an exact match, else the one short-name match.
pub fn index_named<T>(items: &[T], name_of: impl Fn(&T) -> &str, name: &str) -> Option<usize> {
    if let Some(i) = items.iter().position(|c| name_of(c) == name) {
        return Some(i);
    }
    let mut hits = indices_short_named(items, name_of, name);
    match (hits.next(), hits.next()) {
        (Some(i), None) => Some(i),
        _ => None,
    }
}

/// The indices of the items of `items` whose name's last component is `name`.
pub(crate) fn indices_short_named<'a, 'n, T>(
    items: &'a [T],
    name_of: impl Fn(&T) -> &str + 'n,
    name: &'n str,
) -> impl Iterator<Item = usize> + 'n
where
    'a: 'n,
{
    items
        .iter()
        .enumerate()
        .filter(move |(_, c)| last_component(name_of(c)) == name)
        .map(|(i, _)| i)
}

/// The part of a channel name after its last `.` or `/`.
pub fn last_component(name: &str) -> &str {
    name.rsplit(['.', '/']).next().unwrap_or(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(name: &str) -> Channel {
        Channel {
            name: name.into(),
            unit: None,
            data: vec![],
            axis: None,
        }
    }

    #[test]
    fn short_names_resolve_only_when_unique() {
        let t = Table {
            file: "f".into(),
            channels: vec![ch("rec.x"), ch("rec.z"), ch("g1/z"), ch("t")],
            notes: Vec::new(),
        };
        assert_eq!(t.channel("rec.x").unwrap().name, "rec.x");
        assert_eq!(t.channel("x").unwrap().name, "rec.x");
        assert_eq!(t.channel("t").unwrap().name, "t");
        assert!(t.channel("z").is_none(), "z is ambiguous: rec.z and g1/z");
        assert_eq!(t.channel("g1/z").unwrap().name, "g1/z");
        assert!(t.channel("y").is_none());
    }
}
