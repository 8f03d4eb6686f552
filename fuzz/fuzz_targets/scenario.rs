//! The scenario-file parser on arbitrary text: it may refuse the file with an error that
//! names it, but never panics; a file it accepts gives views that are valid or errors.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rotorid::scenario_file::{ScenarioSpec, SimulationOverrides};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match ScenarioSpec::parse("f.toml", text) {
        Ok(spec) => {
            if let Ok(s) = spec.simulation(&SimulationOverrides::default()) {
                assert!(s.sampling.dt() > 0.0 && s.sampling.dt().is_finite());
            }
            let _ = spec.identification();
            let _ = spec.knowledge();
        }
        Err(e) => assert!(e.to_string().starts_with("f.toml"), "{e}"),
    }
});
