//! Identification of columns through the library's streaming [`Session`], exactly as
//! `rotorid identify` runs a regular file (crates/rotorid-cli/src/commands/identify/stream.rs):
//! the same knowledge and speed profile from the scenario, the grid fitted over the first
//! [`DEFAULT_GRID_HEAD`] stamps, the samples pushed in order. The same columns and options
//! thus give the identical [`Identification`] (and estimates) from Python as from the
//! command line.
//!
//! A [`Stream`] is the live form: chunks pushed as they arrive, on a given grid (`dt`) or
//! on one fitted over the stamps. A live chunk may carry the rotor angle phi alone (a
//! keyphasor): its speed and acceleration then come from the scenario's profile
//! ([`Stream::push_angle`]).

use rotorid::pipeline::{
    Identification, Knowledge, Method, Session, TimeGrid, Timing, DEFAULT_GRID_HEAD,
};
use rotorid::SpeedProfile;

use crate::columns::{Columns, Estimates, SPEED_NAMES};
use crate::error::Error;
use crate::scenario::Scenario;

/// An identification and its estimates table (algebraic: every sample's; modulating and
/// refine: the one row `rotorid identify --out` writes).
#[derive(Debug, Clone)]
pub struct Identified {
    /// The result.
    pub identification: Identification,
    /// The estimates.
    pub estimates: Estimates,
}

/// Identify the whole record `c` by `method`, knowing what `scenario` states (module doc).
pub fn identify(
    c: &Columns,
    scenario: &Scenario,
    method: &Method,
    time_tolerance: f64,
) -> Result<Identified, Error> {
    let mut s = Stream::new(scenario, method, None, time_tolerance)?;
    let mut estimates = s.push(c)?;
    let done = s.finish()?;
    estimates.append(done.estimates);
    Ok(Identified {
        identification: done.identification,
        estimates,
    })
}

/// A live identification (module doc).
pub struct Stream {
    session: Session,
    knowledge: Knowledge,
    profile: Option<SpeedProfile>,
    stamped: bool,
    /// t0, dt of a given grid.
    grid: Option<(f64, f64)>,
    origin: String,
}

impl Stream {
    /// A stream identified by `method`. `grid`: `Some((t0, dt))` \[s\] for samples on that
    /// grid (stamps, when given, are checked against it), `None` to fit the grid over the
    /// first [`DEFAULT_GRID_HEAD`] stamps (then every chunk needs `t`).
    pub fn new(
        scenario: &Scenario,
        method: &Method,
        grid: Option<(f64, f64)>,
        time_tolerance: f64,
    ) -> Result<Self, Error> {
        let time_tolerance = crate::options::time_tolerance(time_tolerance)?;
        let knowledge = scenario.knowledge()?;
        let profile = scenario.profile()?;
        let timing = match grid {
            Some((t0, dt)) => Timing::Grid {
                grid: TimeGrid::given(t0, dt)?,
                tolerance: time_tolerance,
            },
            None => Timing::Fit {
                head: DEFAULT_GRID_HEAD,
                tolerance: time_tolerance,
            },
        };
        let session = Session::new(&knowledge, method, profile, timing)?;
        Ok(Self {
            session,
            knowledge,
            profile,
            stamped: grid.is_none(),
            grid,
            origin: scenario.origin().to_owned(),
        })
    }

    /// What the stream knows besides the samples.
    pub fn knowledge(&self) -> &Knowledge {
        &self.knowledge
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> usize {
        self.session.samples()
    }

    /// Push the samples of `c`; returns the algebraic estimates they completed (none while
    /// the head of a fitted grid is held back, then all of them). On an error the samples
    /// before the offending one are taken; the error names its index in the stream.
    pub fn push(&mut self, c: &Columns) -> Result<Estimates, Error> {
        if c.speed.is_none() && self.profile.is_none() {
            return Err(Error::invalid(format!(
                "no speed: the data have no phi, phi_dot, phi_ddot and the scenario {} has \
                 no [speed] section; give the rotor angle in the data or the speed profile in \
                 the scenario",
                self.origin
            )));
        }
        if self.stamped && c.t.is_none() {
            return Err(Error::invalid(
                "t is missing: a stream without dt fits its time grid over the stamps; give \
                 t with every chunk, or dt",
            ));
        }
        let mut out = Estimates::new(self.session.model());
        let mut sink = |e: &rotorid::pipeline::SampleEstimate| out.push_sample(e);
        for i in 0..c.len() {
            self.session.push(&c.sample(i), &mut sink)?;
        }
        Ok(out)
    }

    /// Push a chunk whose speed is given in part: phi, phi_dot, phi_ddot as in
    /// [`Stream::push`] when all three or none are given; phi with phi_dot or phi_ddot
    /// missing takes the missing ones from the scenario's speed profile at each sample's
    /// time (its stamp, else t0 + i dt), e.g. a keyphasor's angle on a rotor whose speed
    /// the scenario states.
    pub fn push_angle(
        &mut self,
        t: Option<&[f64]>,
        x: &[f64],
        z: &[f64],
        speed: [Option<&[f64]>; 3],
    ) -> Result<Estimates, Error> {
        let [Some(phi), omega, omega_dot] = speed else {
            return self.push(&Columns::new(t, x, z, speed)?);
        };
        if omega.is_some() && omega_dot.is_some() {
            return self.push(&Columns::new(t, x, z, speed)?);
        }
        let Some(profile) = self.profile else {
            let missing: Vec<&str> = SPEED_NAMES[1..]
                .iter()
                .zip([omega, omega_dot])
                .filter(|(_, c)| c.is_none())
                .map(|(n, _)| *n)
                .collect();
            return Err(Error::invalid(format!(
                "phi is given without {}, and the scenario {} has no [speed] section to take                  them from: give them, or the speed profile in the scenario",
                missing.join(" and "),
                self.origin
            )));
        };
        let first = self.samples();
        let time = |i: usize| match (t, self.grid) {
            (Some(t), _) => Some(t[i]),
            (None, Some((t0, dt))) => Some(t0 + (first + i) as f64 * dt),
            (None, None) => None,
        };
        let n = x.len();
        let mut states = Vec::with_capacity(n);
        for i in 0..n.min(phi.len()) {
            states.push(time(i).map(|ti| profile.at(ti)));
        }
        let fill = |given: Option<&[f64]>, pick: fn(&rotorid::SpeedState) -> f64| -> Vec<f64> {
            match given {
                Some(v) => v.to_vec(),
                None => states
                    .iter()
                    .map(|s| s.as_ref().map_or(f64::NAN, pick))
                    .collect(),
            }
        };
        let omega = fill(omega, |s| s.omega);
        let omega_dot = fill(omega_dot, |s| s.omega_dot);
        let c = Columns::new(t, x, z, [Some(phi), Some(&omega), Some(&omega_dot)])?;
        self.push(&c)
    }

    /// Fit the grid over the stamps held back so far and identify them (a live
    /// acquisition that has paused); a no-op once started.
    pub fn start_now(&mut self) -> Result<Estimates, Error> {
        let mut out = Estimates::new(self.session.model());
        self.session.start_now(&mut |e| out.push_sample(e))?;
        Ok(out)
    }

    /// The identification of every sample pushed, and the estimates not yet returned
    /// (algebraic: those of a head never started; modulating and refine: their one row).
    pub fn finish(self) -> Result<Identified, Error> {
        let mut out = Estimates::new(self.session.model());
        let ident = self.session.finish(&mut |e| out.push_sample(e))?;
        if let Some(f) = ident.final_estimate() {
            out.push_final(&f);
        }
        Ok(Identified {
            identification: ident,
            estimates: out,
        })
    }
}

/// The summary `rotorid identify --summary` writes, with `input` and `scenario` set as the
/// caller gives them: the identification serialised by serde_json.
pub fn summary_json(
    mut ident: Identification,
    input: Option<String>,
    scenario: Option<String>,
) -> String {
    ident.input = input;
    ident.scenario = scenario;
    serde_json::to_string(&ident).expect("an identification always serialises")
}
