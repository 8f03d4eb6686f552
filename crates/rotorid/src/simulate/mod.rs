//! Simulators (placeholder until the simulate module lands).
