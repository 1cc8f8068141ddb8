//! `[display]`: what the display does with the light vitreous draws, checked field by field.

use toml::Spanned;
use vitreous_optics::display::Compensation;
use vitreous_optics::display::dimmer::{DimmerDesc, MAX_SIGMA_CELLS};

use super::{CLOSED, Loader};
use crate::SceneError;
use crate::file::DisplayToml;

/// Magic Leap 2's segmented dimmer as vitreous models it by default (docs/headsets.md gives
/// each value's source): cells across and down the eye's view (a guess: the panel is
/// documented only as coarser than the display).
pub const DEFAULT_DIMMER_CELLS: [u32; 2] = [64, 48];
/// The panel's blur, the standard deviation of its point spread in degrees (a guess from the
/// panel's distance to the eye: docs/headsets.md).
pub const DEFAULT_DIMMER_BLUR_DEG: f32 = 1.5;
/// The largest share of the real world's light a cell takes away: the lenses pass 22 % of the
/// world's light at the least dimming and 0.3 % at the most, so the dimmer takes away at most
/// 1 - 0.3 / 22 of what an undimmed pixel shows.
pub const DEFAULT_DIMMER_MAX: f32 = 1.0 - 0.3 / 22.0;

/// How far the display's light lands from where the real world is, one standard deviation per
/// axis, degrees: a stated guess. Published evaluations of see-through headsets give the
/// placement error of world-locked content as millimetres to a centimetre at arm's length to
/// a few metres, tenths of a degree, and none gives Magic Leap 2's angular error after
/// calibration; 0.125 degrees (4 pixels at 32 pixels per degree) is the smaller of the two
/// errors the realism figures are measured at (docs/display.md).
pub const DEFAULT_REGISTRATION_ERROR_DEG: f32 = 0.125;

/// The largest registration error a scene may plan for, degrees.
pub const MAX_REGISTRATION_ERROR_DEG: f32 = 5.0;

/// Most cells on a side of the dimmer's panel.
const MAX_CELLS: u32 = 1024;

/// The `[display]` table, resolved.
pub(crate) struct Display {
    pub compensation: Compensation,
    pub global_dimmer: Option<f32>,
    pub dimmer: Option<DimmerDesc>,
    pub registration_error_deg: f32,
}

impl Loader<'_> {
    /// `[display]`, with the view's field of view (degrees, across and down) that the dimmer's
    /// blur is checked against.
    pub(super) fn display(
        &self,
        raw: &DisplayToml,
        fov_deg: [f32; 2],
    ) -> Result<Display, SceneError> {
        let global_dimmer = match &raw.global_dimmer {
            None => None,
            Some(v) => {
                Some(self.number("display.global_dimmer", Some(v), 0.0, (0.0, 1.0), CLOSED)?)
            }
        };
        let compensation = match &raw.compensation {
            None => Compensation::None,
            Some(c) => match c.get_ref().as_str() {
                "none" => Compensation::None,
                "background" => Compensation::Background,
                other => {
                    return Err(self.src.invalid(
                        c.span(),
                        "display.compensation",
                        format!("expected \"none\" or \"background\", found {other:?}"),
                    ));
                }
            },
        };
        let registration_error_deg = self.number(
            "display.registration_error_deg",
            raw.registration_error_deg.as_ref(),
            DEFAULT_REGISTRATION_ERROR_DEG,
            (0.0, MAX_REGISTRATION_ERROR_DEG),
            CLOSED,
        )?;
        let dimmer = match raw.model.as_ref().map(|m| (m, m.get_ref().as_str())) {
            None | Some((_, "additive")) => {
                self.no_dimmer_fields(raw)?;
                None
            }
            Some((_, "dimmer")) => Some(DimmerDesc {
                registration_error_deg,
                ..self.dimmer(raw, fov_deg)?
            }),
            Some((m, other)) => {
                return Err(self.src.invalid(
                    m.span(),
                    "display.model",
                    format!("expected \"additive\" or \"dimmer\", found {other:?}"),
                ));
            }
        };
        Ok(Display {
            compensation,
            global_dimmer,
            dimmer,
            registration_error_deg,
        })
    }

    /// A dimmer's fields given without `model = "dimmer"` are a mistake.
    fn no_dimmer_fields(&self, raw: &DisplayToml) -> Result<(), SceneError> {
        let spans = [
            (
                "display.dimmer_cells",
                raw.dimmer_cells.as_ref().map(Spanned::span),
            ),
            (
                "display.dimmer_blur_deg",
                raw.dimmer_blur_deg.as_ref().map(Spanned::span),
            ),
            (
                "display.dimmer_max",
                raw.dimmer_max.as_ref().map(Spanned::span),
            ),
        ];
        match spans.into_iter().find_map(|(f, s)| s.map(|s| (f, s))) {
            Some((field, span)) => Err(self.src.invalid(
                span,
                field,
                "only a display with model = \"dimmer\" has a dimmer",
            )),
            None => Ok(()),
        }
    }

    fn dimmer(&self, raw: &DisplayToml, fov_deg: [f32; 2]) -> Result<DimmerDesc, SceneError> {
        let cells = match &raw.dimmer_cells {
            None => DEFAULT_DIMMER_CELLS,
            Some(v) => {
                let [x, y] = self.array::<2>("display.dimmer_cells", v)?;
                let whole = |c: f32| c.fract() == 0.0 && (1.0..=MAX_CELLS as f32).contains(&c);
                if !(whole(x) && whole(y)) {
                    return Err(self.src.invalid(
                        v.span(),
                        "display.dimmer_cells",
                        format!(
                            "expected two whole numbers from 1 to {MAX_CELLS}, found [{x}, {y}]"
                        ),
                    ));
                }
                [x as u32, y as u32]
            }
        };
        let blur_deg = self.number(
            "display.dimmer_blur_deg",
            raw.dimmer_blur_deg.as_ref(),
            DEFAULT_DIMMER_BLUR_DEG,
            (0.0, 20.0),
            CLOSED,
        )?;
        let widest = (0..2)
            .map(|i| blur_deg * cells[i] as f32 / fov_deg[i])
            .fold(0.0f32, f32::max);
        if widest > MAX_SIGMA_CELLS {
            let span = match (&raw.dimmer_blur_deg, &raw.dimmer_cells) {
                (Some(b), _) => b.span(),
                (None, Some(c)) => c.span(),
                (None, None) => 0..0,
            };
            return Err(self.src.invalid(
                span,
                "display.dimmer_blur_deg",
                format!(
                    "a blur of {blur_deg} degrees spans {widest:.1} of the {} x {} cells over the \
                     {} x {} degree view; at most {MAX_SIGMA_CELLS}: use fewer cells or less blur",
                    cells[0], cells[1], fov_deg[0], fov_deg[1]
                ),
            ));
        }
        let max = self.number(
            "display.dimmer_max",
            raw.dimmer_max.as_ref(),
            DEFAULT_DIMMER_MAX,
            (0.0, 1.0),
            CLOSED,
        )?;
        Ok(DimmerDesc {
            cells,
            blur_deg,
            max,
            registration_error_deg: 0.0,
        })
    }
}
