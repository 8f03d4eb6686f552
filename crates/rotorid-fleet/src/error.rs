//! The errors of the fleet library: each names the machine, the window, the subject or
//! the field concerned and, where there is one, the allowed range.

use thiserror::Error;

use crate::frame::FrameError;

/// What went wrong (module doc).
#[derive(Debug, Error)]
pub enum FleetError {
    /// A message on `subject` (stream sequence `stream_seq`) is not a valid frame.
    #[error("message {stream_seq} on {subject} is not a valid frame: {source}")]
    Frame {
        /// The subject it came on.
        subject: String,
        /// Its sequence number in the raw stream.
        stream_seq: u64,
        /// Why.
        source: FrameError,
    },
    /// A frame on a machine's subject says it is another machine's.
    #[error("window {window} on {subject} says it is machine {frame_machine}'s")]
    WrongSubject {
        /// The subject.
        subject: String,
        /// The window number.
        window: u64,
        /// The machine in the frame.
        frame_machine: String,
    },
    /// A channel the identification needs is missing or in the wrong unit.
    #[error("machine {machine} window {window}: channel {channel}: {problem}")]
    Channel {
        /// The machine.
        machine: String,
        /// The window.
        window: u64,
        /// The channel.
        channel: String,
        /// What is wrong, with what is allowed.
        problem: String,
    },
    /// The pipeline refused the window.
    #[error("machine {machine} window {window}: {source}")]
    Pipeline {
        /// The machine.
        machine: String,
        /// The window.
        window: u64,
        /// Why.
        source: rotorid::pipeline::PipelineError,
    },
    /// No usable scenario for a machine.
    #[error("machine {machine}: scenario {path}: {message}")]
    Scenario {
        /// The machine (`*` for the scenario of every machine).
        machine: String,
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// A publisher's input that cannot be cut into windows.
    #[error("machine {machine}: {field} = {value} is outside {allowed}")]
    Input {
        /// The machine.
        machine: String,
        /// The field (`window samples`, `channel x length`, ...).
        field: String,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A window larger than the server accepts.
    #[error(
        "machine {machine} window {window} is {bytes} bytes, over the server's max_payload \
         of {max_payload} bytes: use a shorter --window-s"
    )]
    TooLarge {
        /// The machine.
        machine: String,
        /// The window.
        window: u64,
        /// Encoded size.
        bytes: usize,
        /// The server's limit.
        max_payload: usize,
    },
    /// The identification of a window failed unexpectedly (a bug, reported, not retried).
    #[error("machine {machine} window {window}: {message}")]
    Internal {
        /// The machine.
        machine: String,
        /// The window.
        window: u64,
        /// What happened.
        message: String,
    },
    /// A NATS or JetStream operation failed.
    #[error("NATS {operation}: {message}")]
    Nats {
        /// What was being done (`publish rotorid.raw.pump-7`, `connect nats://...`).
        operation: String,
        /// The client's message.
        message: String,
    },
    /// A NATS server list that is not one.
    #[error(
        "NATS server {url:?}: {message} (a server list is URLs separated by commas, e.g. \
         nats://10.0.0.1:4222,nats://10.0.0.2:4222, or the option given again per server)"
    )]
    ServerList {
        /// The item of the list.
        url: String,
        /// Why it is not a server.
        message: String,
    },
    /// A replica count out of range.
    #[error("replicas = {replicas} is out of range: {allowed}")]
    ReplicasRange {
        /// The count asked for.
        replicas: usize,
        /// What is allowed.
        allowed: &'static str,
    },
    /// A stream of the fleet that the servers cannot hold with the replicas asked for (a
    /// cluster smaller than the replica count, or a single server).
    #[error(
        "replicas = {replicas}: the NATS servers refuse stream {stream} with {replicas} \
         replicas ({message}): N replicas need a JetStream cluster of at least N servers \
         (--replicas 1 on a single server)"
    )]
    Replicas {
        /// The count asked for.
        replicas: usize,
        /// The stream.
        stream: String,
        /// The server's answer.
        message: String,
    },
    /// A message that is not the JSON it should be.
    #[error("{subject}: not a valid {what}: {message}")]
    Json {
        /// Where it came from.
        subject: String,
        /// What it should be.
        what: &'static str,
        /// The parser's message.
        message: String,
    },
}

impl FleetError {
    /// A [`FleetError::Nats`] for `operation` from any client error.
    pub fn nats(operation: impl Into<String>, e: impl std::fmt::Display) -> Self {
        Self::Nats {
            operation: operation.into(),
            message: e.to_string(),
        }
    }
}
