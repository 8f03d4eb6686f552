//! From a recording to windows (publisher) and from a window to a [`Record`] and its
//! [`Identification`] (worker).
//!
//! A recording of samples on the grid t0 + i dt is cut into windows of `n` samples: window
//! k holds samples k n .. (k + 1) n, its t0 is `t0 + (k n) as f64 * dt`, its number
//! `first + k`. The last window holds what is left: a remainder shorter than n / 2 joins
//! the window before (a 10 s simulation's 100 001st sample does not make a window of its
//! own that no method can identify).
//!
//! Channels the worker reads: `x`, `z` \[m\] (required) and `phi` \[rad\], `phi_dot`
//! \[rad/s\], `phi_ddot` \[rad/s^2\] (all three or none; without them the speed comes from
//! the scenario's `[speed]` profile, evaluated at the window's own times). Other channels
//! are carried but not used.

use rotorid::pipeline::{identify, Identification, Knowledge, Method, Record, Speed, TimeGrid};
use rotorid::SpeedProfile;

use crate::error::FleetError;
use crate::frame::{check_machine_id, Channel, Frame, MAX_SAMPLES};

/// The speed channels: name and SI unit.
pub const SPEED_CHANNELS: [(&str, &str); 3] = [
    ("phi", "rad"),
    ("phi_dot", "rad/s"),
    ("phi_ddot", "rad/s^2"),
];

/// Cut a recording (channels of equal length on the grid `t0 + i dt`) into windows of
/// `window_samples` samples numbered from `first` (module doc).
pub fn windows(
    machine: &str,
    t0: f64,
    dt: f64,
    channels: &[Channel],
    window_samples: usize,
    first: u64,
) -> Result<Vec<Frame>, FleetError> {
    let input = |field: &str, value: String, allowed: &str| FleetError::Input {
        machine: machine.to_owned(),
        field: field.to_owned(),
        value,
        allowed: allowed.to_owned(),
    };
    check_machine_id(machine)
        .map_err(|e| input("machine id", machine.to_owned(), &e.to_string()))?;
    if window_samples == 0 || window_samples > MAX_SAMPLES {
        return Err(input(
            "window samples",
            window_samples.to_string(),
            &format!("1 ..= {MAX_SAMPLES}"),
        ));
    }
    let len = channels.first().map_or(0, |c| c.data.len());
    if let Some(c) = channels.iter().find(|c| c.data.len() != len) {
        return Err(input(
            &format!("channel {} length", c.name),
            c.data.len().to_string(),
            &format!("{len} (the length of channel {})", channels[0].name),
        ));
    }
    let mut count = len.div_ceil(window_samples);
    if count > 1 && len - (count - 1) * window_samples < window_samples.div_ceil(2) {
        count -= 1;
    }
    let frames = (0..count)
        .map(|k| {
            let a = k * window_samples;
            let b = if k + 1 == count {
                len
            } else {
                a + window_samples
            };
            let f = Frame {
                machine: machine.to_owned(),
                window: first + k as u64,
                t0: t0 + a as f64 * dt,
                dt,
                channels: channels
                    .iter()
                    .map(|c| Channel {
                        name: c.name.clone(),
                        unit: c.unit.clone(),
                        data: c.data[a..b].to_vec(),
                    })
                    .collect(),
            };
            f.check().map_err(|e| FleetError::Frame {
                subject: crate::raw_subject(machine),
                stream_seq: 0,
                source: e,
            })?;
            Ok(f)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(frames)
}

/// The record of a window: `x`, `z` and the speed channels, or `profile` (module doc).
pub fn record_of(frame: &Frame, profile: Option<SpeedProfile>) -> Result<Record, FleetError> {
    let channel = |name: &str, unit: &str| -> Result<Option<Vec<f64>>, FleetError> {
        match frame.channel(name) {
            None => Ok(None),
            Some(c) if c.unit == unit => Ok(Some(c.data.clone())),
            Some(c) => Err(FleetError::Channel {
                machine: frame.machine.clone(),
                window: frame.window,
                channel: name.to_owned(),
                problem: format!("unit {:?}, but it must be in {unit}", c.unit),
            }),
        }
    };
    let required = |name: &str| -> Result<Vec<f64>, FleetError> {
        channel(name, "m")?.ok_or_else(|| FleetError::Channel {
            machine: frame.machine.clone(),
            window: frame.window,
            channel: name.to_owned(),
            problem: "missing: a window needs channels x and z in m".to_owned(),
        })
    };
    let (x, z) = (required("x")?, required("z")?);
    let speed: Vec<Option<Vec<f64>>> = SPEED_CHANNELS
        .iter()
        .map(|(n, u)| channel(n, u))
        .collect::<Result<_, _>>()?;
    let speed = match (speed.as_slice(), profile) {
        ([Some(phi), Some(w), Some(wd)], _) => Speed::Samples {
            phi: phi.clone(),
            omega: w.clone(),
            omega_dot: wd.clone(),
        },
        ([None, None, None], Some(p)) => Speed::Profile(p),
        (s, _) => {
            let (i, _) = SPEED_CHANNELS
                .iter()
                .enumerate()
                .find(|(i, _)| s[*i].is_none())
                .unwrap_or((0, &SPEED_CHANNELS[0]));
            return Err(FleetError::Channel {
                machine: frame.machine.clone(),
                window: frame.window,
                channel: SPEED_CHANNELS[i].0.to_owned(),
                problem: "missing: give phi, phi_dot, phi_ddot together, or none and a \
                          scenario with a [speed] section"
                    .to_owned(),
            });
        }
    };
    let pipeline = |source| FleetError::Pipeline {
        machine: frame.machine.clone(),
        window: frame.window,
        source,
    };
    let grid = TimeGrid::given(frame.t0, frame.dt).map_err(pipeline)?;
    Record::uniform(grid, x, z, speed).map_err(pipeline)
}

/// Identify one window: [`record_of`] then [`identify`].
pub fn identify_frame(
    frame: &Frame,
    knowledge: &Knowledge,
    profile: Option<SpeedProfile>,
    method: &Method,
) -> Result<Identification, FleetError> {
    let record = record_of(frame, profile)?;
    identify(&record, knowledge, method).map_err(|source| FleetError::Pipeline {
        machine: frame.machine.clone(),
        window: frame.window,
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channels(n: usize, names: &[(&str, &str)]) -> Vec<Channel> {
        names
            .iter()
            .map(|(name, unit)| Channel {
                name: (*name).into(),
                unit: (*unit).into(),
                data: (0..n).map(|i| i as f64).collect(),
            })
            .collect()
    }

    #[test]
    fn windows_cover_the_recording_once() {
        let xz = [("x", "m"), ("z", "m")];
        let lens = |len: usize| -> Vec<(usize, u64, f64, f64)> {
            windows("m", 2.0, 0.5, &channels(len, &xz), 10, 7)
                .unwrap()
                .iter()
                .map(|f| (f.samples(), f.window, f.t0, f.channels[1].data[0]))
                .collect()
        };
        assert_eq!(lens(20), [(10, 7, 2.0, 0.0), (10, 8, 7.0, 10.0)]);
        assert_eq!(lens(24), [(10, 7, 2.0, 0.0), (14, 8, 7.0, 10.0)]);
        assert_eq!(
            lens(25),
            [(10, 7, 2.0, 0.0), (10, 8, 7.0, 10.0), (5, 9, 12.0, 20.0)]
        );
        assert_eq!(lens(3), [(3, 7, 2.0, 0.0)]);
        assert!(lens(0).is_empty());
        let e = windows("m", 0.0, 1.0, &channels(5, &xz), 0, 0).unwrap_err();
        assert!(e.to_string().contains("window samples = 0"), "{e}");
        let e = windows("a.b", 0.0, 1.0, &channels(5, &xz), 2, 0).unwrap_err();
        assert!(e.to_string().contains("machine a.b"), "{e}");
    }

    fn frame(names: &[(&str, &str)]) -> Frame {
        Frame {
            machine: "m".into(),
            window: 4,
            t0: 4.0,
            dt: 1e-4,
            channels: channels(50, names),
        }
    }

    #[test]
    fn records_need_x_z_in_metres_and_all_or_no_speed_channels() {
        let p = rotorid::SpeedProfile::constant_rpm(1200.0, 0.0).unwrap();
        let ok = frame(&[("x", "m"), ("z", "m"), ("keyphasor", "V")]);
        let r = record_of(&ok, Some(p)).unwrap();
        assert_eq!((r.len(), r.grid().t0, r.grid().dt), (50, 4.0, 1e-4));
        assert!(matches!(r.speed(), Speed::Profile(_)));
        let all = [
            ("x", "m"),
            ("z", "m"),
            ("phi", "rad"),
            ("phi_dot", "rad/s"),
            ("phi_ddot", "rad/s^2"),
        ];
        assert!(matches!(
            record_of(&frame(&all), None).unwrap().speed(),
            Speed::Samples { .. }
        ));
        let msg = |f: &Frame, p| record_of(f, p).unwrap_err().to_string();
        assert!(msg(&frame(&[("x", "m")]), Some(p)).contains("channel z: missing"));
        assert!(msg(&frame(&[("x", "mm"), ("z", "m")]), Some(p)).contains("unit \"mm\""));
        assert!(msg(&frame(&all[..4]), Some(p)).contains("channel phi_ddot: missing"));
        assert!(msg(&frame(&all[..2]), None).contains("channel phi: missing"));
        let mut nan = ok.clone();
        nan.channels[1].data[3] = f64::NAN;
        assert!(msg(&nan, Some(p)).contains("machine m window 4"));
    }
}
