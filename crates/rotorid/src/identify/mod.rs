//! Identifiers (placeholder until the identify module lands).
