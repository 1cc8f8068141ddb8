//! Imports of head-worn eye-tracker recordings into the trace format: Tobii Pro Glasses 3
//! ([`tobii_g3`]) and Pupil Labs Neon native recordings ([`neon`]). (HTC Vive Pro Eye /
//! SRanipal CSVs are imported by [`crate::sranipal`].)
//!
//! Each import returns the trace samples and a [`RecordingReport`]: what was read, what was
//! written, how much of the recording has no valid eye, where the head orientation comes
//! from, and what had to be approximated. `docs/trace-import.md` describes the frames, units
//! and approximations of every format.

mod error;
mod eye_centre;
pub mod neon;
mod orientation;
mod report;
pub mod tobii_g3;

pub use error::RecordingError;
pub use report::{HeadSource, RecordingReport};

/// The samples written as a trace and read back (what an import's round-trip tests compare).
#[cfg(test)]
fn written_and_read(samples: &[crate::TraceSample]) -> Vec<crate::TraceSample> {
    let mut writer = crate::format::TraceWriter::new(Vec::new()).expect("writing to memory");
    for s in samples {
        writer
            .write(s)
            .expect("an imported sample is a valid trace sample");
    }
    let bytes = writer.finish().expect("flushing to memory");
    crate::format::TraceReader::new(&bytes[..], "t.trace")
        .expect("a written trace has a header")
        .collect::<Result<_, _>>()
        .expect("a written trace reads back")
}
