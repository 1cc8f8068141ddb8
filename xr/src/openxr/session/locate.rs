//! What the runtime says of the head and the eyes for a frame, and what of it can be used. A
//! pose or field marked valid is still checked: runtimes have handed out positions that are
//! not numbers, all-zero quaternions and fields of four zero angles (asked for their views too
//! early), all marked valid. Such a frame's poses are taken as lost tracking: its position held
//! or the frame not drawn ([`super::tracking`]), warned once a session and counted.
//!
//! The views are located in the head's own frame (the VIEW space) and placed with the one head
//! pose the frame has: each eye sits in the head exactly where the runtime says, whatever the
//! two calls' predictions did apart (a runtime asked twice for one display time can answer two
//! poses a little apart, and the eyes' place in the head, which a recording keeps in its views
//! lines, would be their difference).

use openxr as xr;

use super::super::convert::{pose_of, posef_of, usable_field, usable_orientation, usable_position};
use super::super::{OpenXrError, Result, XrContext};
use super::Session;
use super::placement::compose;
use super::tracking::Poses;

impl Session {
    /// Locates the head and eyes for a frame displayed at `display`, in app space (the views'
    /// poses too).
    pub(super) fn locate(&mut self, display: xr::Time) -> Result<(Poses, Vec<xr::View>)> {
        let head = self
            .view_space
            .locate(&self.space, display)
            .xr("xrLocateSpace")?;
        let (flags, mut views) = self
            .session
            .locate_views(
                xr::ViewConfigurationType::PRIMARY_STEREO,
                display,
                &self.view_space,
            )
            .xr("xrLocateViews")?;
        if views.len() < 2 {
            return Err(OpenXrError::Unsupported(format!(
                "xrLocateViews gave {} views; expected 2",
                views.len()
            )));
        }
        let said_position = head
            .location_flags
            .contains(xr::SpaceLocationFlags::POSITION_VALID)
            && flags.contains(xr::ViewStateFlags::POSITION_VALID);
        let said_orientation = head
            .location_flags
            .contains(xr::SpaceLocationFlags::ORIENTATION_VALID)
            && flags.contains(xr::ViewStateFlags::ORIENTATION_VALID);
        let located = [&head.pose, &views[0].pose, &views[1].pose];
        let position_valid = said_position && located.iter().all(|p| usable_position(p));
        let orientation_usable = said_orientation && located.iter().all(|p| usable_orientation(p));
        if (said_position, said_orientation) != (position_valid, orientation_usable) {
            if self.report.interruptions.frames_unusable_pose == 0 {
                tracing::warn!(
                    "frame {}: the runtime marked the head's pose valid but gave {}: taken as \
                     lost tracking (counted in summary.json's interruptions)",
                    self.next_index,
                    if said_orientation && !orientation_usable {
                        "an orientation that is not a unit quaternion"
                    } else {
                        "a position that is not a finite number"
                    }
                );
            }
            self.report.interruptions.frames_unusable_pose += 1;
        }
        // A view's field is what its image is drawn with: without one the frame cannot be
        // drawn where the eye sees it, as without an orientation.
        let fields_usable = views[..2].iter().all(|v| usable_field(&v.fov));
        if said_orientation && !fields_usable {
            if self.report.interruptions.frames_unusable_field == 0 {
                let f = &views[0].fov;
                tracing::warn!(
                    "frame {}: the runtime gave a view a field of view that is none (left {}, \
                     right {}, up {}, down {} rad): the frame is not drawn (counted in \
                     summary.json's interruptions)",
                    self.next_index,
                    f.angle_left,
                    f.angle_right,
                    f.angle_up,
                    f.angle_down
                );
            }
            self.report.interruptions.frames_unusable_field += 1;
        }
        let head_pose = pose_of(&head.pose);
        for view in views.iter_mut() {
            view.pose = posef_of(&compose(&head_pose, &pose_of(&view.pose)));
        }
        let poses = Poses {
            head: head_pose,
            eyes: [pose_of(&views[0].pose), pose_of(&views[1].pose)],
            position_valid,
            orientation_valid: orientation_usable && fields_usable,
        };
        Ok((poses, views))
    }
}
