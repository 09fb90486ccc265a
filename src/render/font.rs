//! The one font of every picture, DejaVu Sans (its licence is beside it in assets/fonts/),
//! compiled into the binary so that a picture needs no system font and comes out the same on
//! every machine.

use plotters::style::{register_font, FontStyle};
use std::sync::OnceLock;

/// The family name pictures ask plotters for. "sans-serif" is also plotters' default family,
/// so any plotters text in the process (the SVG plot of `isph study` too) finds this font.
pub const FAMILY: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the font with plotters, once per process. With plotters' `ab_glyph` feature,
/// plotters has no font at all until one is registered: text layout fails without this.
pub fn register() -> Result<(), String> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok {
        Ok(())
    } else {
        Err("the embedded DejaVu Sans font could not be parsed".to_owned())
    }
}
