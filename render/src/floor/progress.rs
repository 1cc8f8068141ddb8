//! Whether the floor fields have really been computed. The state changes only when the
//! renderer reports what happened to submitted work (submitted, then finished or failed),
//! never while commands are being recorded, so a failed submit or a lost frame leaves the
//! computation due again. A moved object or light starts a new generation: the fields are due
//! again, and reports about work of an older generation no longer change anything.
//!
//! It also knows where each persistent image may differ from its cleared value, so that a
//! computation clears and draws only the texels that can change: where the last submitted
//! work drew and where the new one draws.

use super::fields::TexelRect;

/// Where a one-time computation stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Computation {
    /// Not recorded into any submitted work (or that work failed).
    #[default]
    Missing,
    /// Recorded into work that was submitted and has not been waited for; later work on the
    /// same queue is ordered after it, so it is not recorded again.
    Submitted,
    /// Waited for: the results are in the images.
    Done,
}

/// Which texels of a floor-space image may differ from its cleared value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Written {
    /// Any of them: never drawn, or the work that drew it failed (its layout is unknown
    /// too, so the next pass treats the whole image as undefined).
    #[default]
    Anywhere,
    /// Only these (`None`: none); the image is in SHADER_READ_ONLY_OPTIMAL.
    Within(Option<TexelRect>),
}

/// What [`super::InducerPass::prepare`] recorded into a command buffer; handed back to
/// [`super::InducerPass::submitted`] once the command buffer was submitted and to
/// [`super::InducerPass::finished`] once its fence signalled (or the wait failed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Prepared {
    /// The generation (object and light pose) it was recorded for.
    pub(super) generation: u64,
    /// The fields (mask, distance, gain) were recorded.
    pub(super) fields: bool,
    /// With `fields`: the texels of the mask, distance and gain that may differ from their
    /// cleared values once it ran.
    pub(super) fields_within: Option<TexelRect>,
}

impl Prepared {
    /// Whether the fields (and a live caustic map with them) were recorded.
    pub(crate) fn computed(&self) -> bool {
        self.fields
    }
}

/// Progress of the floor fields' computation: changes only when the renderer reports what
/// happened to submitted work, never while recording.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Progress {
    /// How many times the object or the light moved since the pass was made.
    generation: u64,
    /// How many computations of the fields were submitted (of the current generation when
    /// they were).
    pub computations: u64,
    /// The mask, distance and gain fields.
    pub fields: Computation,
    /// Where the mask, distance and gain may differ from their cleared values after the
    /// work submitted so far.
    pub fields_written: Written,
}

impl Progress {
    /// What must be recorded for a frame drawing the overlay.
    pub fn plan(&self) -> Prepared {
        Prepared {
            generation: self.generation,
            fields: self.fields == Computation::Missing,
            ..Prepared::default()
        }
    }

    /// Whether `prepared` was recorded for the current pose.
    pub fn is_current(&self, prepared: Prepared) -> bool {
        prepared.generation == self.generation
    }

    /// The object or the light moved: the fields are due again, and work recorded before is
    /// of an older generation.
    pub fn invalidate(&mut self) {
        self.generation += 1;
        self.fields = Computation::Missing;
    }

    /// The work `prepared` was recorded into has been submitted.
    pub fn submitted(&mut self, prepared: Prepared) {
        // The images change whatever generation the work was recorded for.
        if prepared.fields {
            self.fields_written = Written::Within(prepared.fields_within);
        }
        if prepared.generation != self.generation {
            return;
        }
        if prepared.fields {
            self.computations += 1;
            self.fields = Computation::Submitted;
        }
    }

    /// The work `prepared` was recorded into has finished (`ok`) or can no longer be relied
    /// on (its fence wait failed).
    pub fn finished(&mut self, prepared: Prepared, ok: bool) {
        if !ok && prepared.fields {
            self.fields_written = Written::Anywhere;
        }
        if prepared.generation != self.generation {
            return;
        }
        if prepared.fields && self.fields == Computation::Submitted {
            self.fields = if ok {
                Computation::Done
            } else {
                Computation::Missing
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_count_as_computed_only_after_their_work_finished() {
        let mut progress = Progress::default();
        let first = progress.plan();
        assert_eq!(
            first,
            Prepared {
                generation: 0,
                fields: true,
                ..Prepared::default()
            }
        );
        // Recording alone changes nothing: a failed submit leaves everything to redo.
        assert_eq!(progress.plan(), first);
        progress.submitted(first);
        assert_eq!(progress.fields, Computation::Submitted);
        // Work submitted later is ordered after it: nothing to record again.
        assert_eq!(progress.plan(), Prepared::default());
        progress.finished(first, true);
        assert_eq!(progress.fields, Computation::Done);
        assert!(!progress.plan().fields);
    }

    #[test]
    fn a_move_makes_everything_due_and_ignores_older_work() {
        let mut progress = Progress::default();
        let first = progress.plan();
        progress.submitted(first);
        progress.invalidate();
        let second = progress.plan();
        assert!(second.fields && second.generation == 1);
        progress.submitted(second);
        // The older frame finishing does not mark the newer computation done ...
        progress.finished(first, true);
        assert_eq!(progress.fields, Computation::Submitted);
        // ... nor does its failure make it due again.
        progress.finished(first, false);
        assert!(!progress.plan().fields);
        progress.finished(second, true);
        assert_eq!(progress.fields, Computation::Done);
    }

    #[test]
    fn a_failed_wait_makes_the_fields_due_again() {
        let mut progress = Progress::default();
        let first = progress.plan();
        progress.submitted(first);
        progress.finished(first, false);
        assert_eq!(progress.plan(), first);
    }

    #[test]
    fn images_are_known_written_only_where_submitted_work_drew() {
        let mut progress = Progress::default();
        assert_eq!(progress.fields_written, Written::Anywhere);
        let first = Prepared {
            fields_within: Some([1, 2, 3, 4]),
            ..progress.plan()
        };
        // Recorded but not submitted: nothing drawn.
        assert_eq!(progress.fields_written, Written::Anywhere);
        progress.submitted(first);
        assert_eq!(progress.fields_written, Written::Within(Some([1, 2, 3, 4])));
        progress.finished(first, true);
        assert_eq!(progress.fields_written, Written::Within(Some([1, 2, 3, 4])));
        // Work that failed leaves the images unknown, whatever its generation.
        progress.invalidate();
        let second = Prepared {
            fields_within: None,
            ..progress.plan()
        };
        progress.submitted(second);
        assert_eq!(progress.fields_written, Written::Within(None));
        progress.invalidate();
        progress.finished(second, false);
        assert_eq!(progress.fields_written, Written::Anywhere);
    }
}
