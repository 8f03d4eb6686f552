//! Readers and writers of the files rotor records come in, shared by every caller of the
//! identification pipeline (the `rotorid` command, the Python package, the fleet worker).
//!
//! A reader yields a [`Table`]: named [`Channel`]s of `f64` samples, each with the unit the
//! file gives (a CSV header suffix `x [um]`, a TDMS `unit_string`, a UFF58 ordinate unit) and,
//! where the format carries one, an implied time axis. [`units`] converts a channel to SI
//! for the role it plays (time, displacement, angle, speed, acceleration) and refuses a unit
//! it does not know, naming the channel.
//!
//! The crate does no identification: it turns bytes into SI samples and back.
//!
//! [`csv`] reads the response CSV that `rotorid simulate` writes (and any CSV with the
//! same columns, units in its header converted), streaming, at close to the speed the file
//! can be read: records split in place, numbers parsed bit for bit as `str::parse` parses
//! them and written in shortest round-trip form.

pub mod csv;
pub mod table;
pub mod units;

pub use table::{Channel, Table, TimeAxis};
pub use units::{Conversion, Quantity, UnitError};
