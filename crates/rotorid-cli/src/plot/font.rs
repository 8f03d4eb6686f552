//! The one font every figure uses: DejaVu Sans (regular and bold), taken from the `dejavu`
//! crate's embedded bytes and registered with plotters' `ab_glyph` text renderer under the
//! family name `sans-serif`, exactly once per process.
//!
//! No system font is looked up and no font file lives in this repository: PNG text is
//! rasterised from these bytes, and SVG text is written as `<text font-family="sans-serif">`
//! (the viewer's sans-serif face; metrics were laid out with DejaVu Sans).

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

/// The family name figures ask for (plotters' `FontFamily::SansSerif`).
pub const FAMILY: &str = "sans-serif";

/// Register DejaVu Sans once; later calls return the first call's outcome.
pub fn ensure_registered() -> anyhow::Result<()> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            register_font(FAMILY, FontStyle::Normal, dejavu::sans::regular())
                .map_err(|_| "the embedded DejaVu Sans regular font did not parse".to_string())?;
            register_font(FAMILY, FontStyle::Bold, dejavu::sans::bold())
                .map_err(|_| "the embedded DejaVu Sans bold font did not parse".to_string())?;
            Ok(())
        })
        .clone()
        .map_err(anyhow::Error::msg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registers_once_and_again_without_error() {
        ensure_registered().unwrap();
        ensure_registered().unwrap();
    }
}
