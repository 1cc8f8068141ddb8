//! The embedded font (DejaVu Sans, licence in `app/assets/fonts/LICENSE-DejaVu.txt`): the plots
//! and the viewer's overlay need no system fonts.

use std::sync::Once;

use anyhow::{Result, anyhow};
use plotters::style::FontStyle;

/// DejaVu Sans, TrueType.
pub static FONT_TTF: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Makes the embedded font the plots' `sans-serif` (once per process).
pub fn register_plot_font() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_TTF)
            .map_err(|_| anyhow!("the embedded DejaVu Sans font could not be parsed"));
    });
    result
}
