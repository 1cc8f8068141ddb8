//! Which field of view a replay draws each eye with (`--fields`): the scene's, or the
//! headset's from a recording's views lines, with the image size that keeps its pixels square.

use anyhow::{Result, bail};
use vitreous_trace::Fov;
use vitreous_trace::format::ViewsRecord;

/// The field of view a replay draws each eye with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fields {
    /// The scene's `[output]` field, for both eyes.
    #[default]
    Scene,
    /// Each eye's field from the recording's views line in force (trace version 1.5): what
    /// the headset drew. The image is as wide as asked (`--size`, else the scene's width) and,
    /// unless `--size` says otherwise, as high as makes its pixels square for the first line's
    /// left field; the scene's field, where a measure needs one (pixels per degree, the
    /// dimmer's cells), is that field too.
    Recorded,
}

/// Most a field's shape (its tangents' height over width) may differ from the image's before
/// a replay with the headset's fields warns that its pixels are not square.
const ASPECT_TOLERANCE: f32 = 0.01;

/// The shape of a field: its tangents' height over their width.
fn field_aspect(fov: Fov) -> f32 {
    (fov.angle_up_rad.tan() - fov.angle_down_rad.tan())
        / (fov.angle_right_rad.tan() - fov.angle_left_rad.tan())
}

/// The image size whose pixels are square for `fov`, `width` pixels wide.
pub fn square_pixels(width: u32, fov: Fov) -> (u32, u32) {
    let height = (width as f32 * field_aspect(fov)).round().max(1.0);
    (width, height as u32)
}

/// The first views line with a field whose shape differs from an image `image_aspect` as high
/// as wide by more than [`ASPECT_TOLERANCE`]: its time and that field's shape.
fn first_bent_field(views: &[ViewsRecord], image_aspect: f32) -> Option<(i64, f32)> {
    views.iter().find_map(|line| {
        line.eyes.iter().find_map(|eye| {
            let aspect = field_aspect(eye.fov);
            ((aspect / image_aspect - 1.0).abs() > ASPECT_TOLERANCE)
                .then_some((line.time_ns, aspect))
        })
    })
}

/// With [`Fields::Recorded`]: the recording's first field (left eye), after checking there is
/// one, with a warning for every later line whose fields' shape differs from the image's.
pub(super) fn recorded_field(
    fields: Fields,
    views: &[ViewsRecord],
    trace_name: &str,
    size: Option<(u32, u32)>,
) -> Result<Option<Fov>> {
    if fields == Fields::Scene {
        return Ok(None);
    }
    let Some(first) = views.first() else {
        bail!(
            "{trace_name} has no views lines (a recording of trace version 1.5, `vitreous run \
             --record`): --fields recorded draws the headset's fields they hold"
        );
    };
    let first_field = first.eyes[0].fov;
    let image_aspect = size.map_or(field_aspect(first_field), |(w, h)| h as f32 / w as f32);
    if let Some((time_ns, aspect)) = first_bent_field(views, image_aspect) {
        tracing::warn!(
            "{trace_name}: the headset's field at {time_ns} ns is {aspect:.3} as high as wide \
             (in tangents), the image {image_aspect:.3}: its pixels are not square there"
        );
    }
    Ok(Some(first_field))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recorded_fields_get_square_pixels_and_a_changed_shape_is_found() {
        use vitreous_trace::Pose;
        use vitreous_trace::format::HeadView;
        // 90 by 60 degrees, symmetric: tangents 2 by 1.155.
        let wide = Fov::symmetric(90f32.to_radians(), 60f32.to_radians());
        assert_eq!(square_pixels(1000, wide), (1000, 577));
        let line = |time_ns: i64, fov: Fov| ViewsRecord {
            time_ns,
            eyes: [HeadView {
                pose: Pose::IDENTITY,
                fov,
            }; 2],
        };
        let views = [
            line(0, wide),
            line(5, wide),
            line(9, Fov::symmetric(1.0, 1.0)),
        ];
        assert_eq!(first_bent_field(&views[..2], 0.577), None);
        assert_eq!(first_bent_field(&views, 0.577).map(|b| b.0), Some(9));
        // An image of another shape: the first line already.
        assert_eq!(first_bent_field(&views, 0.75).map(|b| b.0), Some(0));
        assert!(
            recorded_field(Fields::Scene, &[], "t", None)
                .unwrap()
                .is_none()
        );
        let e = recorded_field(Fields::Recorded, &[], "t.trace", None).unwrap_err();
        assert!(e.to_string().contains("t.trace has no views lines"), "{e}");
        let first = recorded_field(Fields::Recorded, &views, "t", Some((1000, 577)));
        assert_eq!(first.unwrap(), Some(wide));
    }
}
