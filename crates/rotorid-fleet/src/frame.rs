//! The binary frame of one window of a machine's probe data (docs/fleet.md, "Frame").
//!
//! All numbers little-endian:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `RIDF` |
//! | 4 | 1 | version, [`FRAME_VERSION`] |
//! | 5 | 1 | flags, 0 (reserved) |
//! | 6 | 2 | channel count C, u16, 1 ..= [`MAX_CHANNELS`] |
//! | 8 | 4 | samples per channel N, u32, 1 ..= [`MAX_SAMPLES`] |
//! | 12 | 8 | window sequence number, u64 |
//! | 20 | 8 | t0, f64 \[s\]: time of sample 0, finite |
//! | 28 | 8 | dt, f64 \[s\]: sampling period, finite and > 0 |
//! | 36 | 1 | machine id length L, 1 ..= [`MAX_ID_LEN`] |
//! | 37 | L | machine id: ASCII letters, digits, `_`, `-` (a NATS subject token) |
//! | | | C times: name length (u8, 1 ..= [`MAX_NAME_LEN`]), name (ASCII letters, digits, `_`), unit length (u8, 0 ..= [`MAX_NAME_LEN`]), unit (printable ASCII) |
//! | | 8 C N | samples, f64, channel after channel |
//!
//! The frame ends exactly after the samples: decoding checks C N 8 against the bytes left
//! before it allocates anything, so a hostile length cannot make it allocate more than the
//! message's own size.

use thiserror::Error;

/// The 4 bytes every frame starts with.
pub const FRAME_MAGIC: [u8; 4] = *b"RIDF";
/// The frame version this crate writes and reads.
pub const FRAME_VERSION: u8 = 1;
/// Most channels in one frame.
pub const MAX_CHANNELS: usize = 16;
/// Most samples per channel in one frame (2^24: 28 min at 10 kHz).
pub const MAX_SAMPLES: usize = 1 << 24;
/// Longest machine id \[bytes\].
pub const MAX_ID_LEN: usize = 64;
/// Longest channel name or unit \[bytes\].
pub const MAX_NAME_LEN: usize = 32;
/// Size of the fixed header before the machine id \[bytes\].
pub const HEADER_LEN: usize = 37;

/// One named channel of a window: samples in SI `unit` (`m`, `rad`, `rad/s`, `rad/s^2`).
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Channel name, e.g. `x`, `z`, `phi`.
    pub name: String,
    /// SI unit of the samples, e.g. `m`.
    pub unit: String,
    /// The samples, one per grid time t0 + i dt.
    pub data: Vec<f64>,
}

/// One window of one machine: what a frame carries.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Machine id (a NATS subject token).
    pub machine: String,
    /// Window sequence number, per machine, increasing with time.
    pub window: u64,
    /// Time of sample 0 \[s\].
    pub t0: f64,
    /// Sampling period \[s\].
    pub dt: f64,
    /// The channels, all of the same length.
    pub channels: Vec<Channel>,
}

/// What is wrong with a frame (encoding) or with bytes (decoding). Offsets are byte
/// offsets in the frame.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FrameError {
    /// Fewer bytes than the field needs.
    #[error("frame truncated: {field} at byte {offset} needs {needed} bytes, {available} left")]
    Truncated {
        /// The field being read.
        field: &'static str,
        /// Its offset.
        offset: usize,
        /// Bytes it needs.
        needed: usize,
        /// Bytes left.
        available: usize,
    },
    /// Not a rotorid frame.
    #[error("not a rotorid frame: magic {found:02x?}, expected {FRAME_MAGIC:02x?} (\"RIDF\")")]
    Magic {
        /// The first 4 bytes.
        found: [u8; 4],
    },
    /// A version this build does not read.
    #[error("frame version {found} is not supported (this build reads version {FRAME_VERSION})")]
    Version {
        /// The version byte.
        found: u8,
    },
    /// A count or length outside its range.
    #[error("frame field {field} = {value} is outside {min} ..= {max}")]
    OutOfRange {
        /// The field.
        field: &'static str,
        /// Its value.
        value: u64,
        /// Smallest allowed.
        min: u64,
        /// Largest allowed.
        max: u64,
    },
    /// A text field with characters it may not hold.
    #[error("frame field {field} = {value:?} may hold only {allowed}")]
    Text {
        /// The field.
        field: &'static str,
        /// Its text (lossy UTF-8).
        value: String,
        /// What it may hold.
        allowed: &'static str,
    },
    /// t0 or dt not finite, or dt <= 0.
    #[error("frame field {field} = {value} s must be {allowed}")]
    Time {
        /// `t0` or `dt`.
        field: &'static str,
        /// Its value \[s\].
        value: f64,
        /// What it must be.
        allowed: &'static str,
    },
    /// The bytes after the header are not C N 8.
    #[error(
        "frame sample block is {found} bytes, but {channels} channels of {samples} samples \
         need {expected}"
    )]
    SampleBlock {
        /// Channel count.
        channels: usize,
        /// Samples per channel.
        samples: usize,
        /// C N 8.
        expected: u128,
        /// Bytes present.
        found: usize,
    },
    /// Channels of different lengths (encoding).
    #[error("channel {channel} has {len} samples, channel {first} has {expected}")]
    ChannelLength {
        /// The channel.
        channel: String,
        /// Its length.
        len: usize,
        /// The first channel's name.
        first: String,
        /// The first channel's length.
        expected: usize,
    },
    /// Two channels of one name.
    #[error("channel {name} appears twice in the frame")]
    DuplicateChannel {
        /// The name.
        name: String,
    },
}

/// A machine id: 1 ..= [`MAX_ID_LEN`] ASCII letters, digits, `_` or `-` (so that it is one
/// token of a NATS subject and one KV key).
pub fn check_machine_id(id: &str) -> Result<(), FrameError> {
    if id.is_empty() || id.len() > MAX_ID_LEN {
        return Err(FrameError::OutOfRange {
            field: "machine id length",
            value: id.len() as u64,
            min: 1,
            max: MAX_ID_LEN as u64,
        });
    }
    if !id
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
    {
        return Err(FrameError::Text {
            field: "machine id",
            value: id.to_owned(),
            allowed: "ASCII letters, digits, '_' and '-'",
        });
    }
    Ok(())
}

fn check_name(field: &'static str, s: &str) -> Result<(), FrameError> {
    let min = usize::from(field == "channel name");
    if s.len() < min || s.len() > MAX_NAME_LEN {
        return Err(FrameError::OutOfRange {
            field: if field == "channel name" {
                "channel name length"
            } else {
                "channel unit length"
            },
            value: s.len() as u64,
            min: min as u64,
            max: MAX_NAME_LEN as u64,
        });
    }
    let ok = if field == "channel name" {
        s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
    } else {
        s.bytes().all(|b| b.is_ascii_graphic())
    };
    if !ok {
        return Err(FrameError::Text {
            field,
            value: s.to_owned(),
            allowed: if field == "channel name" {
                "ASCII letters, digits and '_'"
            } else {
                "printable ASCII without spaces"
            },
        });
    }
    Ok(())
}

fn check_times(t0: f64, dt: f64) -> Result<(), FrameError> {
    if !t0.is_finite() {
        return Err(FrameError::Time {
            field: "t0",
            value: t0,
            allowed: "finite",
        });
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(FrameError::Time {
            field: "dt",
            value: dt,
            allowed: "finite and > 0",
        });
    }
    Ok(())
}

fn check_count(field: &'static str, value: usize, max: usize) -> Result<(), FrameError> {
    if value == 0 || value > max {
        return Err(FrameError::OutOfRange {
            field,
            value: value as u64,
            min: 1,
            max: max as u64,
        });
    }
    Ok(())
}

impl Frame {
    /// Samples per channel (0 without channels).
    pub fn samples(&self) -> usize {
        self.channels.first().map_or(0, |c| c.data.len())
    }

    /// The channel called `name`.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// Size of the encoded frame \[bytes\] (without checking it).
    pub fn encoded_len(&self) -> usize {
        HEADER_LEN
            + self.machine.len()
            + self
                .channels
                .iter()
                .map(|c| 2 + c.name.len() + c.unit.len() + 8 * c.data.len())
                .sum::<usize>()
    }

    /// Check every limit of the module doc.
    pub fn check(&self) -> Result<(), FrameError> {
        check_machine_id(&self.machine)?;
        check_times(self.t0, self.dt)?;
        check_count("channel count", self.channels.len(), MAX_CHANNELS)?;
        let first = &self.channels[0];
        check_count("samples per channel", first.data.len(), MAX_SAMPLES)?;
        for (i, c) in self.channels.iter().enumerate() {
            check_name("channel name", &c.name)?;
            check_name("channel unit", &c.unit)?;
            if c.data.len() != first.data.len() {
                return Err(FrameError::ChannelLength {
                    channel: c.name.clone(),
                    len: c.data.len(),
                    first: first.name.clone(),
                    expected: first.data.len(),
                });
            }
            if self.channels[..i].iter().any(|o| o.name == c.name) {
                return Err(FrameError::DuplicateChannel {
                    name: c.name.clone(),
                });
            }
        }
        Ok(())
    }

    /// The frame's bytes (module doc), after [`Frame::check`].
    pub fn encode(&self) -> Result<Vec<u8>, FrameError> {
        self.check()?;
        let mut b = Vec::with_capacity(self.encoded_len());
        b.extend_from_slice(&FRAME_MAGIC);
        b.push(FRAME_VERSION);
        b.push(0);
        b.extend_from_slice(&(self.channels.len() as u16).to_le_bytes());
        b.extend_from_slice(&(self.samples() as u32).to_le_bytes());
        b.extend_from_slice(&self.window.to_le_bytes());
        b.extend_from_slice(&self.t0.to_le_bytes());
        b.extend_from_slice(&self.dt.to_le_bytes());
        b.push(self.machine.len() as u8);
        b.extend_from_slice(self.machine.as_bytes());
        for c in &self.channels {
            b.push(c.name.len() as u8);
            b.extend_from_slice(c.name.as_bytes());
            b.push(c.unit.len() as u8);
            b.extend_from_slice(c.unit.as_bytes());
        }
        for c in &self.channels {
            for v in &c.data {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        Ok(b)
    }

    /// The frame in `bytes`, every field checked (module doc); never panics, and allocates
    /// at most about `bytes.len()`.
    pub fn decode(bytes: &[u8]) -> Result<Self, FrameError> {
        let mut r = Reader { bytes, pos: 0 };
        let magic: [u8; 4] = r.array("magic")?;
        if magic != FRAME_MAGIC {
            return Err(FrameError::Magic { found: magic });
        }
        let [version] = r.array("version")?;
        if version != FRAME_VERSION {
            return Err(FrameError::Version { found: version });
        }
        let [flags] = r.array("flags")?;
        if flags != 0 {
            return Err(FrameError::OutOfRange {
                field: "flags",
                value: flags.into(),
                min: 0,
                max: 0,
            });
        }
        let channels = u16::from_le_bytes(r.array("channel count")?) as usize;
        check_count("channel count", channels, MAX_CHANNELS)?;
        let samples = u32::from_le_bytes(r.array("samples per channel")?) as usize;
        check_count("samples per channel", samples, MAX_SAMPLES)?;
        let window = u64::from_le_bytes(r.array("window")?);
        let t0 = f64::from_le_bytes(r.array("t0")?);
        let dt = f64::from_le_bytes(r.array("dt")?);
        check_times(t0, dt)?;
        let machine = r.text("machine id")?;
        check_machine_id(&machine)?;
        let mut names = Vec::with_capacity(channels);
        for _ in 0..channels {
            let name = r.text("channel name")?;
            check_name("channel name", &name)?;
            let unit = r.text("channel unit")?;
            check_name("channel unit", &unit)?;
            if names.iter().any(|(n, _)| *n == name) {
                return Err(FrameError::DuplicateChannel { name });
            }
            names.push((name, unit));
        }
        let rest = &bytes[r.pos..];
        let expected = channels as u128 * samples as u128 * 8;
        if rest.len() as u128 != expected {
            return Err(FrameError::SampleBlock {
                channels,
                samples,
                expected,
                found: rest.len(),
            });
        }
        let channels = names
            .into_iter()
            .zip(rest.chunks_exact(8 * samples))
            .map(|((name, unit), block)| Channel {
                name,
                unit,
                data: block
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                    .collect(),
            })
            .collect();
        Ok(Self {
            machine,
            window,
            t0,
            dt,
            channels,
        })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take(&mut self, field: &'static str, n: usize) -> Result<&[u8], FrameError> {
        let available = self.bytes.len() - self.pos;
        if n > available {
            return Err(FrameError::Truncated {
                field,
                offset: self.pos,
                needed: n,
                available,
            });
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], FrameError> {
        let s = self.take(field, N)?;
        let mut a = [0; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    /// A length byte and that many bytes, as text (lossy: the callers check ASCII).
    fn text(&mut self, field: &'static str) -> Result<String, FrameError> {
        let [len] = self.array(field)?;
        let s = self.take(field, len.into())?;
        Ok(String::from_utf8_lossy(s).into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn frame(n: usize) -> Frame {
        Frame {
            machine: "pump-7".into(),
            window: 3,
            t0: 3.0,
            dt: 1e-4,
            channels: vec![
                Channel {
                    name: "x".into(),
                    unit: "m".into(),
                    data: (0..n).map(|i| i as f64 * 1e-6).collect(),
                },
                Channel {
                    name: "z".into(),
                    unit: "m".into(),
                    data: (0..n).map(|i| -(i as f64)).collect(),
                },
            ],
        }
    }

    #[test]
    fn layout_is_the_documented_one() {
        let f = frame(2);
        let b = f.encode().unwrap();
        assert_eq!(&b[0..4], b"RIDF");
        assert_eq!(b[4], 1);
        assert_eq!(b[5], 0);
        assert_eq!(u16::from_le_bytes([b[6], b[7]]), 2);
        assert_eq!(u32::from_le_bytes(b[8..12].try_into().unwrap()), 2);
        assert_eq!(u64::from_le_bytes(b[12..20].try_into().unwrap()), 3);
        assert_eq!(f64::from_le_bytes(b[20..28].try_into().unwrap()), 3.0);
        assert_eq!(f64::from_le_bytes(b[28..36].try_into().unwrap()), 1e-4);
        assert_eq!(b[36], 6);
        assert_eq!(&b[37..43], b"pump-7");
        assert_eq!(&b[43..49], b"\x01x\x01m\x01z");
        // z's unit, then x[0], x[1], z[0], z[1]
        assert_eq!(&b[49..51], b"\x01m");
        assert_eq!(f64::from_le_bytes(b[59..67].try_into().unwrap()), 1e-6);
        assert_eq!(f64::from_le_bytes(b[75..83].try_into().unwrap()), -1.0);
        assert_eq!(b.len(), 83);
        assert_eq!(f.encoded_len(), 83);
    }

    #[test]
    fn every_truncation_and_extension_is_an_error() {
        let b = frame(3).encode().unwrap();
        for n in 0..b.len() {
            assert!(Frame::decode(&b[..n]).is_err(), "prefix of {n} bytes");
        }
        let mut long = b.clone();
        long.push(0);
        assert!(matches!(
            Frame::decode(&long),
            Err(FrameError::SampleBlock { found: 49, .. })
        ));
    }

    #[test]
    fn huge_counts_are_refused_before_allocating() {
        let mut b = frame(1).encode().unwrap();
        b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(
            Frame::decode(&b),
            Err(FrameError::OutOfRange {
                field: "samples per channel",
                ..
            })
        ));
        b[8..12].copy_from_slice(&(MAX_SAMPLES as u32).to_le_bytes());
        assert!(matches!(
            Frame::decode(&b),
            Err(FrameError::SampleBlock { .. })
        ));
    }

    #[test]
    fn bad_fields_name_themselves() {
        let mut f = frame(2);
        f.machine = "a.b".into();
        assert!(f.encode().unwrap_err().to_string().contains("machine id"));
        let mut f = frame(2);
        f.dt = 0.0;
        assert!(f.encode().unwrap_err().to_string().contains("dt = 0"));
        let mut f = frame(2);
        f.channels[1].data.pop();
        assert!(matches!(
            f.encode(),
            Err(FrameError::ChannelLength { len: 1, .. })
        ));
        let mut f = frame(2);
        f.channels[1].name = "x".into();
        assert!(matches!(
            f.encode(),
            Err(FrameError::DuplicateChannel { .. })
        ));
        let mut b = frame(2).encode().unwrap();
        b[4] = 2;
        assert_eq!(Frame::decode(&b), Err(FrameError::Version { found: 2 }));
    }

    fn arb_frame() -> impl Strategy<Value = Frame> {
        (
            "[A-Za-z0-9_-]{1,64}",
            any::<u64>(),
            -1e9..1e9f64,
            1e-9..1e3f64,
            1usize..40,
            proptest::collection::vec(("[a-z_][a-z0-9_]{0,31}", "[!-~]{0,32}"), 1..6),
        )
            .prop_flat_map(|(machine, window, t0, dt, n, names)| {
                let c = names.len();
                (
                    Just((machine, window, t0, dt, names)),
                    proptest::collection::vec(any::<f64>(), n * c),
                )
            })
            .prop_map(|((machine, window, t0, dt, mut names), data)| {
                names.sort();
                names.dedup_by(|a, b| a.0 == b.0);
                let n = data.len() / names.len().max(1);
                let channels = names
                    .into_iter()
                    .enumerate()
                    .map(|(i, (name, unit))| Channel {
                        name,
                        unit,
                        data: data[i * n..(i + 1) * n].to_vec(),
                    })
                    .collect();
                Frame {
                    machine,
                    window,
                    t0,
                    dt,
                    channels,
                }
            })
    }

    proptest! {
        #[test]
        fn round_trip_is_bit_exact(f in arb_frame()) {
            let b = f.encode().unwrap();
            prop_assert_eq!(b.len(), f.encoded_len());
            let g = Frame::decode(&b).unwrap();
            prop_assert_eq!(&g.machine, &f.machine);
            prop_assert_eq!(g.window, f.window);
            prop_assert_eq!(g.t0.to_bits(), f.t0.to_bits());
            prop_assert_eq!(g.dt.to_bits(), f.dt.to_bits());
            prop_assert_eq!(g.channels.len(), f.channels.len());
            for (a, b) in g.channels.iter().zip(&f.channels) {
                prop_assert_eq!(&a.name, &b.name);
                prop_assert_eq!(&a.unit, &b.unit);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(&a.data), bits(&b.data));
            }
        }

        #[test]
        fn arbitrary_bytes_never_panic(b in proptest::collection::vec(any::<u8>(), 0..300)) {
            let _ = Frame::decode(&b);
        }

        #[test]
        fn mutated_frames_decode_or_fail_cleanly(
            f in arb_frame(), at in any::<usize>(), byte in any::<u8>()
        ) {
            let mut b = f.encode().unwrap();
            let i = at % b.len();
            b[i] = byte;
            if let Ok(g) = Frame::decode(&b) {
                prop_assert_eq!(g.encode().unwrap(), b);
            }
        }
    }
}
