//! The overlay's text: scene, condition and eyes; what the cursor fixates; the gaze pipeline's
//! decision, depths, K_g and separability; timings; the trace position and the keys.

use super::*;

impl ViewSink<'_> {
    /// The overlay's lines.
    pub(super) fn overlay_lines(&self) -> Vec<String> {
        let depth = |d: FixationDepth| match d {
            FixationDepth::Known { depth_m, .. } => format!("{depth_m:.3} m"),
            FixationDepth::Unknown => "-".into(),
        };
        let (filter, reflection, forced) = self.looks.settings();
        let shared = self.shared.borrow();
        let mut lines = vec![
            format!(
                "{}  |  {}  |  eyes {}  |  {}  |  reflection {reflection:?}",
                self.loaded
                    .scene
                    .path
                    .file_name()
                    .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
                self.looks.condition(),
                shared.eyes,
                match (self.preview, self.misregistration) {
                    (false, _) => "display light".to_owned(),
                    (true, 0) => "see-through preview".to_owned(),
                    (true, i) => format!(
                        "see-through preview, display {} deg right",
                        super::MISREGISTRATION_DEG[i]
                    ),
                },
            ),
            format!(
                "cursor fixates the {:?} image at {:.3} m{}",
                shared.fixation.0,
                shared.fixation.1,
                if shared.noise { " (with noise)" } else { "" }
            ),
        ];
        match (self.looks.gaze_state(), self.looks.planner().last_defocus()) {
            (Some(state), Some(d)) => {
                lines.push(format!(
                    "gaze image {} (forced: {forced})  |  depth raw {}, filtered {} ({filter})",
                    d.image,
                    depth(state.raw_depth),
                    depth(state.filtered_depth)
                ));
                lines.push(match d.defocus {
                    Some(k) => format!(
                        "K_g refracted {:.2} px, surface {:.2} px",
                        k.refracted_k_g_px, k.surface_k_g_px
                    ),
                    None => "K_g: none (gaze image unknown)".into(),
                });
                lines.extend(state.separability.map(|s| s.summary().line()));
            }
            _ => lines.push("no defocus in this condition (gaze image not used)".into()),
        }
        let (cpu, gpu, fps) = self.timing;
        lines.push(format!(
            "GPU {} ms  |  CPU {cpu:.1} ms  |  {fps:.1} frames/s  |  F1: keys",
            gpu.map_or("n/a".into(), |g| format!("{g:.1}"))
        ));
        if let Some((at, of, paused)) = shared.trace {
            lines.push(format!(
                "trace {at:.2} / {of:.2} s{}  (K pause, L step, J / Shift+L seek)",
                if paused { ", paused" } else { "" }
            ));
        }
        if let Some(status) = &self.status {
            lines.push(status.clone());
        }
        if self.help {
            lines.extend(KEYS.iter().map(|(k, w)| format!("{k}: {w}")));
        }
        lines
    }
}
