//! What the Vulkan validation layers reported on a command's device, as its summary says it.

use serde::Serialize;
use vitreous_render::GpuContext;

/// Validation layer results.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ValidationSummary {
    /// Whether the layers were on.
    pub enabled: bool,
    /// Warning messages.
    pub warnings: u32,
    /// Error messages.
    pub errors: u32,
    /// The first messages' texts.
    pub messages: Vec<String>,
}

impl ValidationSummary {
    /// What the validation layers reported on `ctx`'s device so far.
    pub fn of(ctx: &GpuContext) -> ValidationSummary {
        let v = ctx.validation();
        ValidationSummary {
            enabled: ctx.validation_enabled(),
            warnings: v.warnings(),
            errors: v.errors(),
            messages: v.messages(),
        }
    }

    /// The summary of a run whose device was followed by `later`'s (a new session after a
    /// loss): the counts added, the messages one after the other.
    pub fn then(&mut self, later: &ValidationSummary) {
        self.enabled &= later.enabled;
        self.warnings += later.warnings;
        self.errors += later.errors;
        self.messages.extend(later.messages.iter().cloned());
    }

    /// An error when the layers reported anything: the counts, the first message, and
    /// `summary` (the file the rest is in), when there is one.
    pub fn check(&self, summary: Option<&std::path::Path>) -> anyhow::Result<()> {
        if self.errors + self.warnings == 0 {
            return Ok(());
        }
        let see = summary.map_or(String::new(), |p| format!(" (see {})", p.display()));
        anyhow::bail!(
            "the Vulkan validation layers reported {} errors and {} warnings{see}, first: {}",
            self.errors,
            self.warnings,
            self.messages.first().map(String::as_str).unwrap_or("")
        )
    }
}
