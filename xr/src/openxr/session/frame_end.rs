//! Magic Leap 2's frame controls as `XrFrameEndInfo` chains them: the focus (reprojection)
//! plane's distance (`XrFrameEndInfoML`, XR_ML_frame_end_info) and the global dimmer
//! (`XrGlobalDimmerFrameEndInfoML`, XR_ML_global_dimmer).

use openxr as xr;

/// Magic Leap 2's structures chained to `XrFrameEndInfo`: the focus distance
/// (`XrFrameEndInfoML`) and the global dimmer (`XrGlobalDimmerFrameEndInfoML`), each when
/// given. Boxed, so that the chain's pointers stay valid while it moves.
pub(crate) struct FrameEndChain {
    focus: Option<Box<xr::sys::FrameEndInfoML>>,
    dimmer: Option<Box<xr::sys::GlobalDimmerFrameEndInfoML>>,
}

impl FrameEndChain {
    /// The chain for a focus distance (metres, clamped to at least 1 cm) and a dimmer level
    /// (clamped to 0..=1).
    pub(crate) fn new(focus_distance_m: Option<f32>, global_dimmer: Option<f32>) -> Self {
        let dimmer = global_dimmer.map(|level| {
            Box::new(xr::sys::GlobalDimmerFrameEndInfoML {
                ty: xr::sys::GlobalDimmerFrameEndInfoML::TYPE,
                next: std::ptr::null(),
                dimmer_value: level.clamp(0.0, 1.0),
                flags: xr::sys::GlobalDimmerFrameEndInfoFlagsML::ENABLED,
            })
        });
        let focus = focus_distance_m.map(|m| {
            Box::new(xr::sys::FrameEndInfoML {
                ty: xr::sys::FrameEndInfoML::TYPE,
                next: dimmer.as_deref().map_or(std::ptr::null(), |d| {
                    d as *const xr::sys::GlobalDimmerFrameEndInfoML as *const _
                }),
                focus_distance: m.max(0.01),
                flags: xr::sys::FrameEndInfoFlagsML::EMPTY,
            })
        });
        FrameEndChain { focus, dimmer }
    }

    /// Nothing to chain.
    pub(crate) fn is_empty(&self) -> bool {
        self.focus.is_none() && self.dimmer.is_none()
    }

    /// The first structure, for `XrFrameEndInfo::next`.
    pub(crate) fn head(&self) -> *const std::ffi::c_void {
        match (&self.focus, &self.dimmer) {
            (Some(f), _) => f.as_ref() as *const xr::sys::FrameEndInfoML as *const _,
            (None, Some(d)) => d.as_ref() as *const xr::sys::GlobalDimmerFrameEndInfoML as *const _,
            (None, None) => std::ptr::null(),
        }
    }

    /// The focus distance submitted, metres.
    pub(crate) fn focus_distance_m(&self) -> Option<f32> {
        self.focus.as_ref().map(|f| f.focus_distance)
    }

    /// Whether the global dimmer is submitted.
    pub(crate) fn has_global_dimmer(&self) -> bool {
        self.dimmer.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_focus_distance_leads_the_chain_to_the_global_dimmer() {
        let chain = FrameEndChain::new(Some(0.8), Some(1.5));
        assert!(!chain.is_empty());
        // SAFETY: the head is the boxed XrFrameEndInfoML the chain owns.
        let focus = unsafe { &*(chain.head() as *const xr::sys::FrameEndInfoML) };
        assert_eq!(focus.ty, xr::sys::StructureType::FRAME_END_INFO_ML);
        assert_eq!(focus.focus_distance, 0.8);
        // SAFETY: its next is the boxed XrGlobalDimmerFrameEndInfoML the chain owns.
        let dimmer = unsafe { &*(focus.next as *const xr::sys::GlobalDimmerFrameEndInfoML) };
        assert_eq!(
            dimmer.ty,
            xr::sys::StructureType::GLOBAL_DIMMER_FRAME_END_INFO_ML
        );
        // Clamped to what the extension takes, and enabled.
        assert_eq!(dimmer.dimmer_value, 1.0);
        assert!(
            dimmer
                .flags
                .contains(xr::sys::GlobalDimmerFrameEndInfoFlagsML::ENABLED)
        );
        assert!(dimmer.next.is_null());
        // The dimmer alone heads its chain; nothing asked, nothing chained.
        let alone = FrameEndChain::new(None, Some(0.2));
        // SAFETY: the head is the boxed dimmer.
        let d = unsafe { &*(alone.head() as *const xr::sys::GlobalDimmerFrameEndInfoML) };
        assert_eq!(d.dimmer_value, 0.2);
        assert!(FrameEndChain::new(None, None).is_empty());
        assert_eq!(
            FrameEndChain::new(Some(0.0), None).focus_distance_m(),
            Some(0.01)
        );
    }
}
