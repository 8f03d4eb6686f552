//! Maximum-likelihood refinement (placeholder until the refine module lands).
