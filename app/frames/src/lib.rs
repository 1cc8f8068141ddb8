//! vitreous-frames: one frame from an XR backend's input to the renderer's look, shared by
//! every command (`run` on a headset, `replay`, `view`, `bench`, `soak`, `study run`).
//!
//! A frame goes: the backend's [`FrameInput`](vitreous_trace::FrameInput) (head, eyes, gaze) ->
//! the motion clock's poses of the scene (with the live edits) -> the look planner's decision
//! (effect set, gaze image, defocus of both images) -> the renderer's per-eye descriptions ->
//! the renderer's frame -> the frame log and the command's sink.
//!
//! | module | what it is |
//! |---|---|
//! | [`frame_loop`] | the one loop: wait, plan, render, hand to the command's sink |
//! | [`look`] | each frame's look: the effect set plus the gaze-dependent defocus (eq. 13-14) |
//! | [`defocus_model`] | the numbers eq. 13-14 need of a scene, and both images' blur |
//! | [`blur_stack`] | the blur stacks sized for the scene's defocus |
//! | [`render_desc`] | a loaded scene and a backend's views as the renderer's descriptions |
//! | [`motion_clock`] | frame times to the scene's poses, with the live edits |
//! | [`scene_edit`] | the live edits: moving, turning and placing the glass, the light, the floor |
//! | [`focus`] | the filtered fixation depth a headset's focus plane follows |
//! | [`director`] | who decides each frame's condition and gaze image: the user, or a study |
//! | [`conditions`] | the effect conditions a live run cycles through, and its live commands |
//! | [`frame_log`] | `frames.csv`: each frame's defocus decision |
//! | [`gaze_watch`] | whether the eye tracker gives usable samples: its dropouts |
//! | [`output`] | files a command writes: frame PNGs, previews, whole or not at all |
//! | [`input_files`] | the files a command reads, which none of its outputs may name |
//! | [`sphere_check_view`] | a replay's eye images beside the sphere check's |
//! | [`readback_check`] | whether a submitted image shows the object, and nothing where the blend mode needs none |
//! | [`setup`] | what every command does before its loop: size check, the trace |
//! | [`validation`] | what the Vulkan validation layers reported |
//! | [`spread`] | the median and spread of a timing |
//! | [`resident`] | the process's resident memory, sampled over a session's frames |
//! | [`soak`] | a trace replayed again and again on one device: resident memory, heap, validation |
//! | [`interrupt`] | Ctrl-C and SIGTERM end a headless run after the current frame |
//! | [`test_frame`] | frame inputs for tests |

pub mod blur_stack;
pub mod conditions;
pub mod defocus_model;
pub mod director;
pub mod focus;
pub mod frame_log;
pub mod frame_loop;
pub mod gaze_watch;
pub mod input_files;
pub mod interrupt;
pub mod look;
pub mod motion_clock;
pub mod output;
pub mod readback_check;
pub mod render_desc;
pub mod resident;
pub mod scene_edit;
pub mod setup;
pub mod soak;
pub mod sphere_check_view;
pub mod spread;
pub mod test_frame;
pub mod validation;
pub mod wearer;
