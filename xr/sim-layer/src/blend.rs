//! Environment blend modes: the list the app sees (the simulated headset's modes, then the
//! runtime's own) and the mode a frame is composed with on the runtime.

use openxr::sys::EnvironmentBlendMode;

/// The modes the app is offered: `added` first, then the runtime's modes not already listed.
pub fn offered(
    added: &[EnvironmentBlendMode],
    runtime: &[EnvironmentBlendMode],
) -> Vec<EnvironmentBlendMode> {
    let mut out = added.to_vec();
    for m in runtime {
        if !out.contains(m) {
            out.push(*m);
        }
    }
    out
}

/// The mode a frame submitted with `app` is forwarded with: the runtime's first (preferred)
/// mode when `app` is one the layer added and the runtime does not offer; else `app`
/// unchanged (a mode the runtime offers, or one nobody offered, which the runtime refuses).
pub fn for_runtime(
    app: EnvironmentBlendMode,
    added: &[EnvironmentBlendMode],
    runtime: &[EnvironmentBlendMode],
) -> EnvironmentBlendMode {
    if added.contains(&app) && !runtime.contains(&app) {
        runtime.first().copied().unwrap_or(app)
    } else {
        app
    }
}

/// A short name for the submitted-frames CSV.
pub fn name(mode: EnvironmentBlendMode) -> String {
    match mode {
        EnvironmentBlendMode::OPAQUE => "opaque".to_owned(),
        EnvironmentBlendMode::ADDITIVE => "additive".to_owned(),
        EnvironmentBlendMode::ALPHA_BLEND => "alpha_blend".to_owned(),
        other => other.into_raw().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use EnvironmentBlendMode as M;

    #[test]
    fn added_modes_come_first_without_repeats() {
        assert_eq!(
            offered(&[M::ADDITIVE, M::ALPHA_BLEND], &[M::OPAQUE]),
            vec![M::ADDITIVE, M::ALPHA_BLEND, M::OPAQUE]
        );
        assert_eq!(
            offered(&[M::ADDITIVE], &[M::OPAQUE, M::ADDITIVE]),
            vec![M::ADDITIVE, M::OPAQUE]
        );
        assert_eq!(offered(&[], &[M::OPAQUE]), vec![M::OPAQUE]);
    }

    #[test]
    fn only_added_modes_are_replaced() {
        let added = [M::ADDITIVE, M::ALPHA_BLEND];
        assert_eq!(for_runtime(M::ADDITIVE, &added, &[M::OPAQUE]), M::OPAQUE);
        assert_eq!(
            for_runtime(M::ALPHA_BLEND, &added, &[M::OPAQUE, M::ALPHA_BLEND]),
            M::ALPHA_BLEND
        );
        assert_eq!(for_runtime(M::OPAQUE, &added, &[M::OPAQUE]), M::OPAQUE);
        assert_eq!(for_runtime(M::ADDITIVE, &added, &[]), M::ADDITIVE);
        // Not added by the layer: left for the runtime to judge.
        assert_eq!(for_runtime(M::ADDITIVE, &[], &[M::OPAQUE]), M::ADDITIVE);
    }

    #[test]
    fn names_are_short() {
        assert_eq!(name(M::ALPHA_BLEND), "alpha_blend");
        assert_eq!(name(M::from_raw(1000)), "1000");
    }
}
