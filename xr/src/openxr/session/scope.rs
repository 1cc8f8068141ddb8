//! The open frame: what a begun frame has taken from the runtime (swapchain images acquired,
//! waited) and therefore what must be given back on every way out of it. The session keeps one
//! [`OpenFrame`] from xrBeginFrame to xrEndFrame; [`OpenFrame::unwind`] says, without a
//! runtime, which calls leave it when the frame cannot be shown.

use openxr as xr;

/// How far one swapchain's image has got in the open frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Hold {
    /// No image acquired.
    Free,
    /// xrAcquireSwapchainImage returned; xrWaitSwapchainImage has not (yet) succeeded.
    Acquired,
    /// The image was waited for: it may be rendered into and must be released.
    Waited,
}

/// A call that leaves an open frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Unwind {
    /// xrWaitSwapchainImage on the colour swapchain (a release needs a waited image).
    WaitColor,
    /// xrReleaseSwapchainImage on the colour swapchain.
    ReleaseColor,
    /// xrWaitSwapchainImage on the depth swapchain.
    WaitDepth,
    /// xrReleaseSwapchainImage on the depth swapchain.
    ReleaseDepth,
    /// xrEndFrame with no layers.
    EndWithoutLayers,
}

/// What the frame handed to the app carries to its xrEndFrame.
#[derive(Clone)]
pub(super) struct Handed {
    /// The frame's index.
    pub(super) index: u64,
    /// The located views, in the runtime's space (for the projection layer).
    pub(super) views: Vec<xr::View>,
    /// The colour swapchain image acquired for it.
    pub(super) image: u32,
    /// The depth swapchain image acquired for it, when depth is submitted.
    pub(super) depth_image: Option<u32>,
}

/// A frame between xrBeginFrame and xrEndFrame.
#[derive(Clone)]
pub(super) struct OpenFrame {
    /// Its predicted display time.
    pub(super) display: xr::Time,
    /// The colour swapchain image's progress.
    pub(super) color: Hold,
    /// The depth swapchain image's progress.
    pub(super) depth: Hold,
    /// Set once the frame is handed to the app (every image acquired, views located).
    pub(super) handed: Option<Handed>,
}

impl OpenFrame {
    /// A frame just begun: nothing acquired yet.
    pub(super) fn begun(display: xr::Time) -> OpenFrame {
        OpenFrame {
            display,
            color: Hold::Free,
            depth: Hold::Free,
            handed: None,
        }
    }

    /// The calls, in order, that leave this frame without showing it: every acquired image
    /// waited for (if it was not) and released, then xrEndFrame with no layers.
    pub(super) fn unwind(&self) -> Vec<Unwind> {
        let mut steps = Vec::new();
        for (hold, wait, release) in [
            (self.color, Unwind::WaitColor, Unwind::ReleaseColor),
            (self.depth, Unwind::WaitDepth, Unwind::ReleaseDepth),
        ] {
            match hold {
                Hold::Free => {}
                Hold::Acquired => steps.extend([wait, release]),
                Hold::Waited => steps.push(release),
            }
        }
        steps.push(Unwind::EndWithoutLayers);
        steps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_left_early_is_still_ended() {
        let f = OpenFrame::begun(xr::Time::from_nanos(5));
        assert_eq!(f.unwind(), [Unwind::EndWithoutLayers]);
    }

    #[test]
    fn acquired_images_are_waited_then_released_before_the_frame_ends() {
        let mut f = OpenFrame::begun(xr::Time::from_nanos(5));
        f.color = Hold::Acquired;
        assert_eq!(
            f.unwind(),
            [
                Unwind::WaitColor,
                Unwind::ReleaseColor,
                Unwind::EndWithoutLayers
            ]
        );
        f.color = Hold::Waited;
        f.depth = Hold::Acquired;
        assert_eq!(
            f.unwind(),
            [
                Unwind::ReleaseColor,
                Unwind::WaitDepth,
                Unwind::ReleaseDepth,
                Unwind::EndWithoutLayers
            ]
        );
        f.depth = Hold::Waited;
        assert_eq!(
            f.unwind(),
            [
                Unwind::ReleaseColor,
                Unwind::ReleaseDepth,
                Unwind::EndWithoutLayers
            ]
        );
    }
}
