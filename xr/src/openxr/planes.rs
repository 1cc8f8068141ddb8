//! XR_EXT_plane_detection in a session: one detector, a detection of the level surfaces facing
//! up around the head begun at once and again [`REDETECT_FRAMES`] frames after each finished
//! one, and the planes of the last finished detection, in the app space.
//!
//! Call order in the types: [`PlaneDetector::new`] after the session exists, [`PlaneDetector::poll`]
//! once per frame with that frame's display time (begins, checks, fetches), dropped (destroying
//! the detector) before the session.

use openxr as xr;
use openxr::sys::{self, Handle};

use vitreous_trace::Pose;
use vitreous_trace::planes::DetectedPlane;

/// Frames between a finished detection and the next one begun.
pub const REDETECT_FRAMES: u64 = 90;

/// Most planes asked for.
const MAX_PLANES: u32 = 32;

/// Smallest plane asked for, square metres.
const MIN_AREA_M2: f32 = 0.01;

/// Half the side of the box around the head that planes are looked for in, metres.
const SEARCH_HALF_M: f32 = 5.0;

/// The detector, destroyed on drop.
pub struct PlaneDetector {
    handle: sys::PlaneDetectorEXT,
    fns: xr::raw::PlaneDetectionEXT,
    /// A detection is in progress.
    pending: bool,
    /// Frames since the last detection finished (counting to [`REDETECT_FRAMES`]).
    since_done: u64,
    /// Detections finished.
    pub detections: u64,
}

impl PlaneDetector {
    /// Creates the session's detector; `None` (logged) when the instance has no
    /// XR_EXT_plane_detection or the runtime refuses.
    pub fn new<G>(instance: &xr::Instance, session: &xr::Session<G>) -> Option<PlaneDetector> {
        let fns = instance.exts().ext_plane_detection?;
        let info = sys::PlaneDetectorCreateInfoEXT {
            ty: sys::PlaneDetectorCreateInfoEXT::TYPE,
            next: std::ptr::null(),
            flags: sys::PlaneDetectorFlagsEXT::EMPTY,
        };
        let mut handle = sys::PlaneDetectorEXT::NULL;
        // SAFETY: the session is live, the extension enabled (its function table loaded), the
        // create info valid and the output writable.
        let r = unsafe { (fns.create_plane_detector)(session.as_raw(), &info, &mut handle) };
        if r.into_raw() < 0 {
            tracing::warn!(
                "XR_EXT_plane_detection: creating a detector failed ({r:?}); the table is the scene's"
            );
            return None;
        }
        Some(PlaneDetector {
            handle,
            fns,
            pending: false,
            since_done: REDETECT_FRAMES,
            detections: 0,
        })
    }

    /// Moves the detection on for a frame shown at `time`, planes looked for around `head`
    /// (in `space`): begins one when due, and when one finished returns its planes facing up,
    /// in `space`.
    pub fn poll(
        &mut self,
        space: &xr::Space,
        time: xr::Time,
        head: Pose,
    ) -> Option<Vec<DetectedPlane>> {
        if !self.pending {
            self.since_done += 1;
            if self.since_done >= REDETECT_FRAMES {
                self.begin(space, time, head);
            }
            return None;
        }
        let mut state = sys::PlaneDetectionStateEXT::NONE;
        // SAFETY: the detector is live and the output writable.
        let r = unsafe { (self.fns.get_plane_detection_state)(self.handle, &mut state) };
        if r.into_raw() < 0 || state == sys::PlaneDetectionStateEXT::PENDING {
            return None;
        }
        self.pending = false;
        self.since_done = 0;
        if state != sys::PlaneDetectionStateEXT::DONE {
            tracing::warn!("XR_EXT_plane_detection: a detection ended in {state:?}");
            return None;
        }
        self.detections += 1;
        self.fetch(space, time)
    }

    /// Begins a detection of upward planes in a box around `head`.
    fn begin(&mut self, space: &xr::Space, time: xr::Time, head: Pose) {
        let orientations = [sys::PlaneDetectorOrientationEXT::HORIZONTAL_UPWARD];
        let info = sys::PlaneDetectorBeginInfoEXT {
            ty: sys::PlaneDetectorBeginInfoEXT::TYPE,
            next: std::ptr::null(),
            base_space: space.as_raw(),
            time,
            orientation_count: orientations.len() as u32,
            orientations: orientations.as_ptr(),
            semantic_type_count: 0,
            semantic_types: std::ptr::null(),
            max_planes: MAX_PLANES,
            min_area: MIN_AREA_M2,
            bounding_box_pose: sys::Posef {
                orientation: sys::Quaternionf::IDENTITY,
                position: sys::Vector3f {
                    x: head.position.x,
                    y: head.position.y,
                    z: head.position.z,
                },
            },
            bounding_box_extent: sys::Extent3Df {
                width: 2.0 * SEARCH_HALF_M,
                height: 2.0 * SEARCH_HALF_M,
                depth: 2.0 * SEARCH_HALF_M,
            },
        };
        // SAFETY: the detector and space are live; the info and the array it points to
        // outlive the call.
        let r = unsafe { (self.fns.begin_plane_detection)(self.handle, &info) };
        if r.into_raw() < 0 {
            tracing::warn!("XR_EXT_plane_detection: beginning a detection failed ({r:?})");
            self.since_done = 0;
        } else {
            self.pending = true;
        }
    }

    /// The finished detection's planes facing up, in `space` at `time` (two calls).
    fn fetch(&self, space: &xr::Space, time: xr::Time) -> Option<Vec<DetectedPlane>> {
        let info = sys::PlaneDetectorGetInfoEXT {
            ty: sys::PlaneDetectorGetInfoEXT::TYPE,
            next: std::ptr::null(),
            base_space: space.as_raw(),
            time,
        };
        let empty = sys::PlaneDetectorLocationEXT {
            ty: sys::PlaneDetectorLocationEXT::TYPE,
            next: std::ptr::null_mut(),
            plane_id: 0,
            location_flags: sys::SpaceLocationFlags::EMPTY,
            pose: sys::Posef::IDENTITY,
            extents: sys::Extent2Df {
                width: 0.0,
                height: 0.0,
            },
            orientation: sys::PlaneDetectorOrientationEXT::HORIZONTAL_UPWARD,
            semantic_type: sys::PlaneDetectorSemanticTypeEXT::UNDEFINED,
            polygon_buffer_count: 0,
        };
        let mut out = sys::PlaneDetectorLocationsEXT {
            ty: sys::PlaneDetectorLocationsEXT::TYPE,
            next: std::ptr::null_mut(),
            plane_location_capacity_input: 0,
            plane_location_count_output: 0,
            plane_locations: std::ptr::null_mut(),
        };
        // SAFETY: the detector and space are live; the first call only writes the count.
        let r = unsafe { (self.fns.get_plane_detections)(self.handle, &info, &mut out) };
        if r.into_raw() < 0 {
            tracing::warn!("XR_EXT_plane_detection: reading the planes failed ({r:?})");
            return None;
        }
        let mut locations = vec![empty; out.plane_location_count_output as usize];
        if !locations.is_empty() {
            out.plane_location_capacity_input = locations.len() as u32;
            out.plane_locations = locations.as_mut_ptr();
            // SAFETY: as above; the array holds the capacity given.
            let r = unsafe { (self.fns.get_plane_detections)(self.handle, &info, &mut out) };
            if r.into_raw() < 0 {
                tracing::warn!("XR_EXT_plane_detection: reading the planes failed ({r:?})");
                return None;
            }
            locations.truncate(out.plane_location_count_output as usize);
        }
        let located =
            sys::SpaceLocationFlags::ORIENTATION_VALID | sys::SpaceLocationFlags::POSITION_VALID;
        Some(
            locations
                .iter()
                .filter(|l| l.location_flags.contains(located))
                .map(|l| DetectedPlane {
                    pose: super::convert::pose_of(&l.pose),
                    extents: glam::Vec2::new(l.extents.width, l.extents.height),
                })
                .filter(|p| p.faces_up(10.0))
                .collect(),
        )
    }
}

impl Drop for PlaneDetector {
    fn drop(&mut self) {
        // SAFETY: the detector is live (its session outlives it: the session drops it first)
        // and not used afterwards.
        unsafe { (self.fns.destroy_plane_detector)(self.handle) };
    }
}
