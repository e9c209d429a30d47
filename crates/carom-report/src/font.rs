//! The font of the report's plots. plotters lays out text with ab_glyph (the workspace
//! enables that feature for the examples' bitmaps), which has no system fonts: DejaVu
//! Sans (the crate's own copy in `assets/`, with its licence, so the crate packages on
//! its own) is embedded and registered as `sans-serif` once per process.

use std::sync::Once;

use plotters::style::FontStyle;

/// The family name plots use.
pub const FAMILY: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font with plotters (idempotent).
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded file is a valid TrueType font; a failure here is a build defect.
        let registered = plotters::style::register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS);
        assert!(registered.is_ok(), "the embedded DejaVu Sans loads");
    });
}
