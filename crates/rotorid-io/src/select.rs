//! Which channels of a file play t, x, z, phi, phi_dot, phi_ddot, converted to SI.
//!
//! Every format names its channels its own way (a CSV header, a MAT variable or struct
//! field `rec.x`, a TDMS `group/channel`, an NPZ array, a Parquet column, the columns `0`,
//! `1`, ... of a 2-D NPY). A [`ColumnMap`] says which channel plays each role, by default
//! the role's own name; `--columns t,x,z[,phi,phi_dot,phi_ddot]` on the command line
//! overrides it. A name resolves exactly, or by its last component when that is unique
//! ([`Table::channel`]: `x` finds `rec.x`).
//!
//! [`select`] then checks the channels (x and z required; phi, phi_dot, phi_ddot all three
//! or none; equal lengths) and converts each to SI with the unit the file gives
//! ([`crate::units`]): an unknown unit is an error naming the channel. Without a time
//! channel, the time axis a format implies (TDMS `wf_increment`, a UFF58 abscissa) gives
//! t_i = start + i * increment. Channels in SI are passed through bit for bit.

use crate::table::{index_named, indices_short_named, Described, Table, TimeAxis};
use crate::units::{conversion, Conversion, Quantity, UnitError};

/// The roles, in the order `--columns` lists them.
pub const ROLES: [&str; 6] = ["t", "x", "z", "phi", "phi_dot", "phi_ddot"];

/// The quantity of each role in [`ROLES`].
pub const ROLE_QUANTITIES: [Quantity; 6] = [
    Quantity::Time,
    Quantity::Displacement,
    Quantity::Displacement,
    Quantity::Angle,
    Quantity::AngularSpeed,
    Quantity::AngularAcceleration,
];

/// Which channel plays each role (module doc).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnMap {
    /// Channel names for t, x, z, phi, phi_dot, phi_ddot.
    pub names: [String; 6],
    /// True when the user named them (`--columns`): a named speed channel that is missing
    /// is then an error rather than "no speed columns".
    pub explicit: bool,
}

impl Default for ColumnMap {
    fn default() -> Self {
        Self {
            names: ROLES.map(str::to_owned),
            explicit: false,
        }
    }
}

impl ColumnMap {
    /// The map `--columns SPEC` gives, or the default names without it.
    pub fn from_spec(spec: Option<&str>) -> Result<Self, SelectError> {
        spec.map_or_else(|| Ok(Self::default()), Self::parse)
    }

    /// Parse `t,x,z` or `t,x,z,phi,phi_dot,phi_ddot` (names separated by commas, blanks
    /// around them ignored). With three names the speed channels keep their default names.
    pub fn parse(spec: &str) -> Result<Self, SelectError> {
        let names: Vec<&str> = spec.split(',').map(str::trim).collect();
        if !(names.len() == 3 || names.len() == 6) || names.iter().any(|n| n.is_empty()) {
            return Err(SelectError::Spec {
                spec: spec.to_owned(),
            });
        }
        let mut map = Self::default();
        for (slot, name) in map.names.iter_mut().zip(&names) {
            *slot = (*name).to_owned();
        }
        map.explicit = true;
        Ok(map)
    }
}

/// A channel that cannot play its role.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SelectError {
    /// `--columns` is not 3 or 6 names.
    #[error(
        "--columns {spec:?}: give the channels of t,x,z or of t,x,z,phi,phi_dot,phi_ddot, \
         separated by commas (e.g. rec.t,rec.x,rec.z)"
    )]
    Spec {
        /// The text given.
        spec: String,
    },
    /// A required channel is not in the file.
    #[error("{file}: no channel {name:?} for {role}; the file has: {available}")]
    Missing {
        /// The file.
        file: String,
        /// The role (`x`).
        role: &'static str,
        /// The name looked for.
        name: String,
        /// The file's channel names, abbreviated.
        available: String,
    },
    /// A short name matches several channels.
    #[error(
        "{file}: {name:?} for {role} is ambiguous: it could be {candidates}; give the full name"
    )]
    Ambiguous {
        /// The file.
        file: String,
        /// The role.
        role: &'static str,
        /// The name given.
        name: String,
        /// The channels it could mean.
        candidates: String,
    },
    /// Some but not all of phi, phi_dot, phi_ddot.
    #[error(
        "{file}: has {found} but not {missing}: give all of phi, phi_dot, phi_ddot or none \
         (then the scenario's speed profile is used)"
    )]
    PartialSpeed {
        /// The file.
        file: String,
        /// The speed channels found.
        found: String,
        /// Those missing.
        missing: String,
    },
    /// Channels of different lengths.
    #[error(
        "{file}: channel {channel:?} ({role}) has {len} samples but {reference:?} has \
         {expected}: every channel of a record must have one sample per instant"
    )]
    Length {
        /// The file.
        file: String,
        /// The channel.
        channel: String,
        /// Its role.
        role: &'static str,
        /// Its length.
        len: usize,
        /// The channel it is compared with (x).
        reference: String,
        /// That channel's length.
        expected: usize,
    },
    /// No time channel and no implied time axis.
    #[error(
        "{file}: no time channel {name:?} and no time axis in the file: name the time \
         channel with --columns (e.g. --columns time,x,z)"
    )]
    NoTime {
        /// The file.
        file: String,
        /// The name looked for.
        name: String,
    },
    /// A unit that cannot be used for the role.
    #[error("{file}, channel {channel:?} ({role}): {source}")]
    Unit {
        /// The file.
        file: String,
        /// The channel.
        channel: String,
        /// Its role.
        role: &'static str,
        /// What is wrong with the unit.
        source: UnitError,
    },
}

/// The record's channels in SI (module doc).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SiColumns {
    /// Time stamps \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement \[m\].
    pub z: Vec<f64>,
    /// phi \[rad\], phi_dot \[rad/s\], phi_ddot \[rad/s^2\], when the file has them.
    pub speed: Option<[Vec<f64>; 3]>,
    /// The channel that played each role, with the conversion applied (identity for SI);
    /// t is absent when it came from the file's time axis.
    pub used: Vec<Used>,
    /// True when t came from the file's implied time axis.
    pub time_from_axis: bool,
}

/// One channel used for a role.
#[derive(Debug, Clone, PartialEq)]
pub struct Used {
    /// The role (`x`).
    pub role: &'static str,
    /// The channel's name in the file.
    pub channel: String,
    /// The unit found and its conversion to SI.
    pub conversion: Conversion,
}

/// The channels of `table` that play the roles of `map`, checked and in SI (module doc).
///
/// The table is taken by value: each channel used is moved out of it and converted in
/// place, so the result holds the samples once (a channel that plays two roles is copied
/// for the first). Every check runs before anything is moved.
pub fn select(mut table: Table, map: &ColumnMap) -> Result<SiColumns, SelectError> {
    let plan = plan(&table.file, &table.channels, map)?;
    let used = plan
        .order
        .iter()
        .map(|&(role, i, conv)| Used {
            role: ROLES[role],
            channel: table.channels[i].name.clone(),
            conversion: conv,
        })
        .collect();
    let mut buffers: Vec<Vec<f64>> = table
        .channels
        .iter_mut()
        .map(|c| std::mem::take(&mut c.data))
        .collect();
    let [t, x, z, phi, phi_dot, phi_ddot] = into_roles(&plan.order, &mut buffers);
    Ok(SiColumns {
        t: match plan.axis {
            Some((axis, n)) => axis.times(n),
            None => t,
        },
        x,
        z,
        speed: plan.speed.then_some([phi, phi_dot, phi_ddot]),
        used,
        time_from_axis: plan.axis.is_some(),
    })
}

/// The columns by role of `order` ((role, buffer index, conversion), as [`Plan::order`]):
/// each buffer of `buffers` moved to its role and converted to SI in place; a buffer that
/// plays two roles is copied for the first. The roles not in `order` are empty.
pub(crate) fn into_roles(
    order: &[(usize, usize, Conversion)],
    buffers: &mut [Vec<f64>],
) -> [Vec<f64>; 6] {
    let mut uses = vec![0_usize; buffers.len()];
    for &(_, i, _) in order {
        uses[i] += 1;
    }
    let mut out: [Vec<f64>; 6] = Default::default();
    for &(role, i, conv) in order {
        uses[i] -= 1;
        let mut data = if uses[i] == 0 {
            std::mem::take(&mut buffers[i])
        } else {
            buffers[i].clone()
        };
        conv.apply_all(&mut data);
        out[role] = data;
    }
    out
}

/// What [`select`] takes from a table, checked: (role, channel index, conversion to SI) in
/// the order the channels are used (x, z, t, phi, phi_dot, phi_ddot), the time axis and
/// length when t comes from it, and whether the speed channels are there.
pub(crate) struct Plan {
    pub(crate) order: Vec<(usize, usize, Conversion)>,
    pub(crate) axis: Option<(TimeAxis, usize)>,
    pub(crate) speed: bool,
}

/// Every check of [`select`], before anything is moved, on the `channels` of `file` (held
/// or still in the file: [`crate::stream`] plans by the catalogue).
pub(crate) fn plan<C: Described>(
    file: &str,
    channels: &[C],
    map: &ColumnMap,
) -> Result<Plan, SelectError> {
    let find = |role: usize| -> Result<Option<usize>, SelectError> {
        let name = map.names[role].as_str();
        if let Some(i) = index_named(channels, C::name, name) {
            return Ok(Some(i));
        }
        let candidates: Vec<&str> = indices_short_named(channels, C::name, name)
            .map(|i| channels[i].name())
            .collect();
        if candidates.len() > 1 {
            return Err(SelectError::Ambiguous {
                file: file.to_owned(),
                role: ROLES[role],
                name: name.to_owned(),
                candidates: candidates.join(", "),
            });
        }
        Ok(None)
    };
    let missing = |role: usize| SelectError::Missing {
        file: file.to_owned(),
        role: ROLES[role],
        name: map.names[role].clone(),
        available: available(channels),
    };
    let x = find(1)?.ok_or_else(|| missing(1))?;
    let z = find(2)?.ok_or_else(|| missing(2))?;
    let reference = &channels[x];
    let n = reference.len();
    let mut order = Vec::with_capacity(6);
    let mut check = |role: usize, i: usize| -> Result<(), SelectError> {
        let c = &channels[i];
        if c.len() != n {
            return Err(SelectError::Length {
                file: file.to_owned(),
                channel: c.name().to_owned(),
                role: ROLES[role],
                len: c.len(),
                reference: reference.name().to_owned(),
                expected: n,
            });
        }
        let conv =
            conversion(ROLE_QUANTITIES[role], c.unit()).map_err(|source| SelectError::Unit {
                file: file.to_owned(),
                channel: c.name().to_owned(),
                role: ROLES[role],
                source,
            })?;
        order.push((role, i, conv));
        Ok(())
    };
    check(1, x)?;
    check(2, z)?;
    let axis = match find(0)? {
        Some(i) => {
            check(0, i)?;
            None
        }
        None => match reference.axis().or(channels[z].axis()) {
            Some(axis) if !map.explicit || map.names[0] == ROLES[0] => Some((axis, n)),
            _ => {
                return Err(SelectError::NoTime {
                    file: file.to_owned(),
                    name: map.names[0].clone(),
                })
            }
        },
    };
    let speed_channels = [find(3)?, find(4)?, find(5)?];
    let speed = match speed_channels {
        [Some(p), Some(w), Some(a)] => {
            check(3, p)?;
            check(4, w)?;
            check(5, a)?;
            true
        }
        [None, None, None] if !(map.explicit && map.names[3..] != ROLES[3..]) => false,
        _ => {
            let (found, missing): (Vec<usize>, Vec<usize>) =
                (3..6).partition(|&r| speed_channels[r - 3].is_some());
            let names = |v: Vec<usize>| {
                v.iter()
                    .map(|&r| map.names[r].as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            return Err(SelectError::PartialSpeed {
                file: file.to_owned(),
                found: if found.is_empty() {
                    "none of them".to_owned()
                } else {
                    names(found)
                },
                missing: names(missing),
            });
        }
    };
    Ok(Plan { order, axis, speed })
}

/// The channel names for a message, at most 20.
fn available<C: Described>(channels: &[C]) -> String {
    let names: Vec<&str> = channels.iter().map(C::name).collect();
    if names.is_empty() {
        return "no channels".to_owned();
    }
    let shown = names
        .iter()
        .take(20)
        .copied()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > 20 {
        format!("{shown}, ... ({} in all)", names.len())
    } else {
        shown
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::Channel;

    fn ch(name: &str, unit: Option<&str>, data: &[f64]) -> Channel {
        Channel {
            name: name.into(),
            unit: unit.map(str::to_owned),
            data: data.to_vec(),
            axis: None,
        }
    }

    fn table(channels: Vec<Channel>) -> Table {
        Table {
            file: "rec.mat".into(),
            channels,
            notes: Vec::new(),
        }
    }

    #[test]
    fn default_names_short_names_and_units() {
        let t = table(vec![
            ch("rec.t", Some("ms"), &[0.0, 0.1, 0.2]),
            ch("rec.x", Some("um"), &[1.0, 2.0, 3.0]),
            ch("rec.z", None, &[1e-6, 2e-6, 3e-6]),
            ch("other", None, &[9.0]),
        ]);
        let s = select(t.clone(), &ColumnMap::default()).unwrap();
        assert_eq!(s.t, vec![0.0, 1e-4, 2e-4]);
        assert_eq!(s.x, vec![1e-6, 2e-6, 3e-6]);
        // SI passes through bit for bit
        assert_eq!(s.z, vec![1e-6, 2e-6, 3e-6]);
        assert!(s.speed.is_none() && !s.time_from_axis);
        let roles: Vec<_> = s.used.iter().map(|u| (u.role, u.conversion.unit)).collect();
        assert_eq!(roles, vec![("x", "um"), ("z", "m"), ("t", "ms")]);
    }

    #[test]
    fn the_channels_are_moved_not_copied() {
        // the samples are held once: each column is its channel's own buffer, converted
        // in place (t in ms here) or passed through (x, z in m)
        let t = table(vec![
            ch("t", Some("ms"), &[0.0, 0.1, 0.2]),
            ch("x", None, &[1e-6, 2e-6, 3e-6]),
            ch("z", None, &[4e-6, 5e-6, 6e-6]),
        ]);
        let ptrs: Vec<*const f64> = t.channels.iter().map(|c| c.data.as_ptr()).collect();
        let s = select(t, &ColumnMap::default()).unwrap();
        assert_eq!(
            [s.t.as_ptr(), s.x.as_ptr(), s.z.as_ptr()],
            [ptrs[0], ptrs[1], ptrs[2]]
        );
        assert_eq!(s.t, vec![0.0, 1e-4, 2e-4]);
    }

    #[test]
    fn a_channel_that_plays_two_roles_serves_both() {
        // x and z from one channel in um, t in ms: each role gets its own converted copy
        let t = table(vec![
            ch("t", Some("ms"), &[0.0, 0.1]),
            ch("probe", Some("um"), &[1.0, 2.0]),
        ]);
        let s = select(t, &ColumnMap::parse("t,probe,probe").unwrap()).unwrap();
        assert_eq!(s.x, vec![1e-6, 2e-6]);
        assert_eq!(s.z, s.x);
        assert_eq!(s.t, vec![0.0, 1e-4]);
        let channels: Vec<_> = s
            .used
            .iter()
            .map(|u| (u.role, u.channel.as_str()))
            .collect();
        assert_eq!(channels, vec![("x", "probe"), ("z", "probe"), ("t", "t")]);
    }

    #[test]
    fn explicit_columns_and_the_time_axis() {
        let mut x = ch("g/probe_x", None, &[1e-6, 2e-6]);
        x.axis = Some(TimeAxis {
            start: 0.5,
            increment: 0.25,
        });
        let t = table(vec![x, ch("g/probe_z", None, &[3e-6, 4e-6])]);
        let map = ColumnMap::parse("t, probe_x, probe_z").unwrap();
        let s = select(t.clone(), &map).unwrap();
        assert_eq!(s.t, vec![0.5, 0.75]);
        assert!(s.time_from_axis);
        // a time channel named explicitly must exist
        let e = select(
            t.clone(),
            &ColumnMap::parse("time,probe_x,probe_z").unwrap(),
        )
        .unwrap_err();
        assert!(matches!(e, SelectError::NoTime { .. }), "{e}");
    }

    #[test]
    fn what_is_refused_is_named() {
        let t = table(vec![
            ch("a.x", None, &[1.0, 2.0]),
            ch("b.x", None, &[1.0, 2.0]),
            ch("z", Some("furlong"), &[1.0, 2.0]),
            ch("t", None, &[0.0, 1.0]),
            ch("phi", None, &[0.0, 1.0]),
        ]);
        let e = select(t.clone(), &ColumnMap::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "rec.mat: \"x\" for x is ambiguous: it could be a.x, b.x; give the full name"
        );
        let e = select(t.clone(), &ColumnMap::parse("t,a.x,z").unwrap()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("rec.mat, channel \"z\" (z): unknown unit \"furlong\""),
            "{e}"
        );
        let t2 = table(vec![
            ch("x", None, &[1.0, 2.0]),
            ch("z", None, &[1.0]),
            ch("t", None, &[0.0, 1.0]),
        ]);
        let e = select(t2.clone(), &ColumnMap::default()).unwrap_err();
        assert!(
            matches!(
                e,
                SelectError::Length {
                    len: 1,
                    expected: 2,
                    ..
                }
            ),
            "{e}"
        );
        let t3 = table(vec![
            ch("x", None, &[1.0]),
            ch("z", None, &[1.0]),
            ch("t", None, &[0.0]),
            ch("phi", None, &[0.0]),
        ]);
        let e = select(t3.clone(), &ColumnMap::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "rec.mat: has phi but not phi_dot, phi_ddot: give all of phi, phi_dot, phi_ddot \
             or none (then the scenario's speed profile is used)"
        );
        let e = select(t3.clone(), &ColumnMap::parse("t,x,y").unwrap()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "rec.mat: no channel \"y\" for z; the file has: x, z, t, phi"
        );
        assert!(ColumnMap::parse("t,x").is_err());
        assert!(ColumnMap::parse("t,,z").is_err());
    }
}
