//! The rotorid library against independent references (one test binary:
//! `cargo test -p rotorid --test it`).

mod cross_common;
mod fe_common;
mod identify_common;

mod acquisition;
mod acquisition_iterated;
mod adequacy;
mod algebraic_windows;
mod analysis;
mod analysis_cross;
mod balance;
mod cross_algebraic;
mod cross_modulating;
mod cross_pipeline;
mod cross_reference;
mod defects;
mod fe_analysis;
mod fe_cross;
mod fe_reduction;
mod fe_refine;
mod fe_simulate;
mod identify_accuracy;
mod identify_conditioning;
mod identify_convergence;
mod identify_modes;
mod identify_quadrature;
mod identify_validation;
mod model_selection;
mod modulating_clean;
mod modulating_noise;
mod pipeline;
mod raw_reference;
mod refine_clean;
mod refine_crb;
mod refine_cross;
mod refine_identifiability;
mod refine_inputs;
mod refine_model;
mod refine_noise;
mod simulate_api;
mod simulate_exact;
mod simulate_newmark;
mod simulate_noise;
mod simulate_reference;
