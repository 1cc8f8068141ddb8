//! The one frame loop, driven by any XR backend: wait for a frame, turn its views into the
//! renderer's parameters, render (into the renderer's own images, or the backend's swapchain
//! image for the frame), end the frame, and hand finished frames to a sink.

use std::collections::VecDeque;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{Composition, Look, Renderer, ScenePose};
use vitreous_trace::{Blend, FrameInput, SessionEvent};
use vitreous_xr::{Backend, FrameEndHints, FrameTarget};

use crate::render_desc;

/// How one frame is drawn and what comes back of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FramePlan {
    /// Which layers are drawn, and how.
    pub look: Look,
    /// What to read back.
    pub want: Want,
}

/// Plans frames and receives them as they finish on the GPU.
pub trait FrameSink {
    /// Sees each frame's input as soon as the backend hands it out (e.g. to record it).
    fn started(&mut self, _input: &FrameInput) -> Result<()> {
        Ok(())
    }

    /// Where the object and the light are for this frame (called before
    /// [`FrameSink::plan`]); `None` leaves them where the previous frame had them.
    fn pose(&mut self, _input: &FrameInput) -> Option<ScenePose> {
        None
    }

    /// The light's share of the floor's light for this frame (called after
    /// [`FrameSink::pose`]); `None` leaves it as it was (at first the scene's `[light] share`).
    fn light_share(&mut self) -> Option<f32> {
        None
    }

    /// How to draw this frame and what to read back of it.
    fn plan(&mut self, input: &FrameInput) -> FramePlan;

    /// What to ask of the display for this frame beyond its images (called after
    /// [`FrameSink::plan`], before the backend ends the frame): none by default.
    fn frame_end_hints(&mut self, _input: &FrameInput) -> FrameEndHints {
        FrameEndHints::default()
    }

    /// Handles a finished frame (its input and its results), in frame order.
    fn finished(&mut self, input: &FrameInput, result: &FrameResult) -> Result<()>;

    /// What happened to the session since the frame before (`frame`: the frame the backend
    /// handed out after it, `None` when the session ended), oldest first: called before the
    /// frame is planned, and once more at the end when the ending brought any.
    fn session_events(
        &mut self,
        _frame: Option<&FrameInput>,
        _events: &[SessionEvent],
    ) -> Result<()> {
        Ok(())
    }

    /// Whether to end the run before the next frame (e.g. on Ctrl-C); frames in flight are
    /// still finished and handed to [`FrameSink::finished`].
    fn stop_requested(&self) -> bool {
        false
    }
}

/// Timing of one frame, as `summary.json` reports it.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FrameRecord {
    /// Frame index.
    pub index: u64,
    /// Display time of the frame, nanoseconds on the backend's clock.
    pub time_ns: i64,
    /// CPU time the frame itself costs (view set-up, command recording, submission; not the
    /// wait for an earlier frame's slot), milliseconds.
    pub cpu_ms: f64,
    /// GPU time of the frame's rendering, milliseconds (`null` without timestamp support).
    pub gpu_ms: Option<f64>,
    /// Defocus kernel width K_g (eq. 13) of the refracted image, background photo pixels
    /// (`null` without defocus, or while the gaze image is unknown).
    pub refracted_k_g_px: Option<f32>,
    /// Defocus kernel width K_g of the surface image, surface texture pixels.
    pub surface_k_g_px: Option<f32>,
}

/// Runs frames until the backend ends the session or the sink asks to stop; returns each
/// finished frame's timing.
pub fn run<B: Backend>(
    backend: &mut B,
    renderer: &mut Renderer,
    sink: &mut dyn FrameSink,
) -> Result<Vec<FrameRecord>> {
    let mut in_flight: VecDeque<(FrameInput, f64, Look)> = VecDeque::new();
    let mut records = Vec::new();
    while !sink.stop_requested() {
        let Some(input) = backend.wait_frame().context("waiting for the next frame")? else {
            let events = backend.take_events();
            if !events.is_empty() {
                sink.session_events(None, &events)?;
            }
            break;
        };
        let events = backend.take_events();
        if !events.is_empty()
            && let Err(e) = sink.session_events(Some(&input), &events)
        {
            backend.abandon_frame();
            return Err(e);
        }
        // Between wait_frame and end_frame an error must give the frame back to the backend
        // (release its images, end it unshown) before it is returned.
        let drawn = draw(backend, renderer, sink, &input);
        let (prepare_ms, plan, done) = match drawn {
            Ok(d) => d,
            Err(e) => {
                backend.abandon_frame();
                return Err(e);
            }
        };
        backend.set_frame_end_hints(sink.frame_end_hints(&input));
        backend.end_frame(&input).context("ending a frame")?;
        in_flight.push_back((input, prepare_ms, plan.look));
        if let Some(result) = done {
            finish(&mut in_flight, sink, &mut records, result)?;
        }
    }
    for result in renderer.flush().context("finishing the last frames")? {
        finish(&mut in_flight, sink, &mut records, result)?;
    }
    Ok(records)
}

/// Plans and renders one frame where the backend says; returns the CPU time of the planning
/// (milliseconds), the plan, and the result of a frame that finished meanwhile.
fn draw<B: Backend>(
    backend: &B,
    renderer: &mut Renderer,
    sink: &mut dyn FrameSink,
    input: &FrameInput,
) -> Result<(f64, FramePlan, Option<FrameResult>)> {
    sink.started(input)?;
    let started = Instant::now();
    if let Some(pose) = sink.pose(input) {
        renderer.set_pose(pose);
    }
    if let Some(share) = sink.light_share() {
        renderer.set_light_share(share);
    }
    let plan = sink.plan(input);
    let params = render_desc::frame_params(input, plan.look);
    let prepare_ms = started.elapsed().as_secs_f64() * 1e3;
    let done = match backend.frame_target() {
        FrameTarget::Own => renderer.submit(&params, plan.want),
        FrameTarget::Swapchain {
            index,
            depth_index,
            blend,
        } => renderer.submit_external_with_depth(
            index as usize,
            depth_index.map(|d| d as usize),
            &params,
            plan.want,
            composition_for(blend),
        ),
    }
    .context("rendering a frame")?;
    Ok((prepare_ms, plan, done))
}

/// How the renderer composes the eye images for a display blend mode.
pub fn composition_for(blend: Blend) -> Composition {
    match blend {
        Blend::Additive => Composition::Additive,
        Blend::AlphaBlend => Composition::AlphaBlend,
        Blend::Opaque => Composition::Opaque,
    }
}

/// Hands the oldest frame in flight, now finished, to the sink and records its timing.
fn finish(
    in_flight: &mut VecDeque<(FrameInput, f64, Look)>,
    sink: &mut dyn FrameSink,
    records: &mut Vec<FrameRecord>,
    result: FrameResult,
) -> Result<()> {
    let (input, prepare_ms, look) = in_flight.pop_front().expect("a frame in flight per result");
    sink.finished(&input, &result)?;
    records.push(FrameRecord {
        index: input.index,
        time_ns: input.time_ns,
        cpu_ms: prepare_ms + result.timing.cpu_submit_ms,
        gpu_ms: result.timing.gpu_ms,
        refracted_k_g_px: look.defocus.map(|d| d.refracted_k_g_px),
        surface_k_g_px: look.defocus.map(|d| d.surface_k_g_px),
    });
    Ok(())
}

/// Fails when the Vulkan validation layers reported anything to `renderer`'s context.
pub fn ensure_validation_clean(renderer: &Renderer) -> Result<()> {
    let v = renderer.context().validation();
    if v.errors() + v.warnings() > 0 {
        anyhow::bail!(
            "the Vulkan validation layers reported {} errors and {} warnings; first: {}",
            v.errors(),
            v.warnings(),
            v.messages().first().map(String::as_str).unwrap_or("")
        );
    }
    Ok(())
}
