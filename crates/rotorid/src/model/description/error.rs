//! What is wrong with a parameter name, a parameter vector or a description's parts.

use crate::model::finite_element::FiniteElementError;

/// An error of the model description; every variant carries the offending value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// A name that is no parameter's.
    #[error("unknown parameter {name:?}: expected one of {allowed}")]
    UnknownName {
        /// The name as given.
        name: String,
        /// The names accepted, in words.
        allowed: &'static str,
    },
    /// A parameter the model does not have.
    #[error("{name} is not a parameter of this model: it has {allowed}")]
    NotInModel {
        /// The parameter's name.
        name: String,
        /// The model's parameters, comma-separated.
        allowed: String,
    },
    /// A parameter another vocabulary has no name for.
    #[error("{name} has no {vocabulary}: it is not a parameter of that model")]
    NoCounterpart {
        /// The parameter's name.
        name: String,
        /// The type asked for (`Parameter`, `FeParameter`).
        vocabulary: &'static str,
    },
    /// A parameter value outside its allowed range (this includes NaN and infinity).
    #[error("{name} = {value} is out of range: must be {allowed}")]
    OutOfRange {
        /// The parameter's name.
        name: String,
        /// The rejected value.
        value: f64,
        /// The allowed range, with the unit.
        allowed: String,
    },
    /// A parameter vector of the wrong length.
    #[error("theta has {got} entries: the model has {expected} parameters")]
    ThetaLength {
        /// The number of the model's parameters.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A parameter index past the end.
    #[error("parameter index {index} is out of range: the model has {len} parameters (0 ..= {})", len.saturating_sub(1))]
    ParameterIndex {
        /// The index given.
        index: usize,
        /// The number of the model's parameters.
        len: usize,
    },
    /// A reduction basis that does not fit the rotor.
    #[error(
        "the basis is {rows} x {cols}: it must have one row per degree of freedom ({n}), at \
         least one column and independent columns (T^T M T positive definite)"
    )]
    Basis {
        /// Its rows.
        rows: usize,
        /// Its columns.
        cols: usize,
        /// The rotor's degrees of freedom.
        n: usize,
    },
    /// A modal model of no mode.
    #[error("a modal model needs at least one mode: none was given")]
    NoModes,
    /// The finite-element rotor's own error (an unknown channel, ...).
    #[error(transparent)]
    FiniteElement(#[from] FiniteElementError),
}
