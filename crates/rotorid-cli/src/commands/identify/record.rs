//! The whole response record in memory, for the batch refinement: t [s], x, z [m] and,
//! when the CSV has them, phi [rad], w [rad/s], w' [rad/s^2], one entry per validated row
//! (24 bytes per sample, 48 with the speed columns; the refinement's own tables add
//! 16 (exact discretisation) to ~200 (RK4 sub-steps) bytes per sample).

use std::io::Read;

use super::speed::SpeedColumns;
use crate::io::ResponseReader;

/// A validated record.
#[derive(Debug, Default)]
pub(crate) struct RecordData {
    /// The rows' times [s].
    pub t: Vec<f64>,
    /// Horizontal displacement [m].
    pub x: Vec<f64>,
    /// Vertical displacement [m].
    pub z: Vec<f64>,
    /// The speed columns, when the CSV has them.
    pub speed: Option<SpeedColumns>,
    /// Sampling period dt = t_2 - t_1 [s] (`None` with fewer than two rows).
    pub dt: Option<f64>,
}

impl RecordData {
    /// Read every row of `reader` (each validated, errors with file, line and column).
    pub fn read<R: Read>(mut reader: ResponseReader<R>) -> anyhow::Result<Self> {
        let mut r = RecordData {
            speed: reader.has_phi().then(SpeedColumns::default),
            ..Self::default()
        };
        while let Some(row) = reader.next_row()? {
            r.t.push(row.t);
            r.x.push(row.x);
            r.z.push(row.z);
            if let (Some(cols), Some(s)) = (r.speed.as_mut(), row.speed) {
                cols.phi.push(s.phi);
                cols.omega.push(s.omega);
                cols.omega_dot.push(s.omega_dot);
            }
        }
        r.dt = reader.dt();
        Ok(r)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// phi, w, w' at sample `i` (from the columns, else from `profile` at t_i).
    pub fn speed_at(
        &self,
        i: usize,
        profile: Option<rotorid::SpeedProfile>,
    ) -> rotorid::SpeedState {
        match (&self.speed, profile) {
            (Some(c), _) => rotorid::SpeedState {
                phi: c.phi[i],
                omega: c.omega[i],
                omega_dot: c.omega_dot[i],
            },
            (None, Some(p)) => p.at(self.t[i]),
            (None, None) => rotorid::SpeedState::default(),
        }
    }
}
