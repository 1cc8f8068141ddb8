//! The frame's gaze sample in time order ([`GazeOrder`](crate::openxr::GazeOrder)): a sample
//! stamped before one a frame already got is not new, one stamped after the frame's display
//! time is used at that time; both counted in the session's report and warned of once a
//! session.

use vitreous_trace::GazeSample;

use super::Session;
use crate::openxr::gaze::Sampled;

impl Session {
    /// The gaze the frame displayed at `display_ns` gets for the source's `sampled`.
    pub(super) fn order_gaze(&mut self, sampled: &Sampled, display_ns: i64) -> Option<GazeSample> {
        let ordered = self.gaze_order.order(sampled.frame, display_ns);
        let tally = &mut self.report.gaze_samples;
        if ordered.out_of_order {
            if tally.out_of_order == 0 {
                tracing::warn!(
                    "frame {}: the eye tracker's sample is stamped before one already used: \
                     the newest is used again (counted in summary.json's gaze_samples)",
                    self.next_index
                );
            }
            tally.out_of_order += 1;
        }
        if let Some(ahead_ns) = ordered.ahead_ns {
            if tally.after_display == 0 {
                tracing::warn!(
                    "frame {}: the eye tracker's sample is stamped {:.1} ms after the frame's \
                     display time (its clock runs ahead of the runtime's): used, stamped at the \
                     display time (counted in summary.json's gaze_samples)",
                    self.next_index,
                    ahead_ns as f64 / 1e6
                );
            }
            tally.after_display += 1;
            tally.max_ahead_ns = tally.max_ahead_ns.max(ahead_ns);
        }
        ordered.gaze
    }
}
