//! Fuzz targets for the readers that take files from users: the trace v1 reader, the
//! SRanipal, Tobii Pro Glasses 3 and Pupil Labs Neon importers, the scene loader, the glTF
//! model path, the study protocol, plan and responses readers, and the caustic bake reader.
//!
//! Each target is a plain function from bytes to nothing that must not panic on any input.
//! `fuzz_targets/*.rs` hand them to libFuzzer (`tools/fuzz`, `cargo fuzz`); the corpus test
//! in `tests/corpus.rs` runs them over `corpus/<target>/` on stable as part of `cargo test`.
//! Besides "no panic", the targets check properties the readers promise: whatever the trace
//! reader accepts the writer writes back to the same samples, whatever the SRanipal importer
//! produces is a valid trace, and every error message can be formatted.

use std::collections::HashMap;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use vitreous_scene::{Scene, SceneError, SceneFiles};
use vitreous_trace::format::{TraceReader, TraceSample, TraceVersion, TraceWriter};

/// Names of the targets, as in `fuzz_targets/` and `corpus/`.
pub const TARGETS: [&str; 8] = [
    "trace_v1", "sranipal", "tobii_g3", "neon", "scene", "gltf", "study", "bake",
];

/// Runs the target called `name` (one of [`TARGETS`]) on `data`; `false` for an unknown name.
pub fn run(name: &str, data: &[u8]) -> bool {
    match name {
        "trace_v1" => trace_v1(data),
        "sranipal" => sranipal(data),
        "tobii_g3" => tobii_g3(data),
        "neon" => neon(data),
        "bake" => bake(data),
        "scene" => scene(data),
        "gltf" => gltf(data),
        "study" => study(data),
        _ => return false,
    }
    true
}

/// Trace v1 text: read every sample; when all are accepted, write them with
/// [`TraceWriter`] and read the result back, which must give the same samples.
pub fn trace_v1(data: &[u8]) {
    let samples = match read_all(data) {
        Ok(samples) => samples,
        Err(message) => {
            assert!(!message.is_empty());
            return;
        }
    };
    let written = write_all(&samples);
    let again =
        read_all(&written).unwrap_or_else(|e| panic!("a written trace does not read back: {e}"));
    assert_eq!(samples, again, "writing then reading changed the samples");
}

/// A study protocol, then (after the first NUL byte) a responses file. The protocol is read as
/// if it lay in `config/studies/` (its stimuli name the shipped scenes); when it is accepted, a
/// plan for three participants must write and read back to the same trials. The responses are
/// parsed and, when accepted, analysed; the report (or the error) must format.
pub fn study(data: &[u8]) {
    use vitreous_study::{plan, protocol::Protocol, report, responses::Responses};
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (protocol_bytes, responses_bytes) = (&data[..split], data.get(split + 1..).unwrap_or(&[]));
    let studies = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/studies/fuzz.toml");
    if let Ok(text) = std::str::from_utf8(protocol_bytes) {
        match Protocol::parse(&studies, text) {
            Ok(protocol) => {
                let seed = data.len() as u64;
                let trials = plan::plan(&protocol, 3, seed);
                assert_eq!(trials.len(), 3 * protocol.trials_per_participant());
                let mut written = Vec::new();
                plan::write_plan(&mut written, &protocol, seed, &trials).expect("in memory");
                let again = plan::parse_plan(Path::new("plan.csv"), &written[..], &protocol)
                    .unwrap_or_else(|e| panic!("a written plan does not read back: {e}"));
                assert_eq!(trials, again, "writing then reading changed the plan");
            }
            Err(e) => assert!(!e.to_string().is_empty()),
        }
    }
    match Responses::parse(Path::new("responses.csv"), responses_bytes) {
        Ok(responses) => {
            let analysis = report::analyze(&responses);
            assert!(!analysis.to_string().is_empty());
            let _ = analysis.to_json().to_string();
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// SRanipal CSV text: import it; the samples of a successful import must make a valid trace
/// that reads back unchanged, and the report must format.
pub fn sranipal(data: &[u8]) {
    check_import(vitreous_trace::sranipal::parse_sranipal(data, "fuzz.csv"));
}

/// Tobii Pro Glasses 3 gaze data (gzip-compressed or plain JSON lines): import it; like
/// [`sranipal`], a successful import must make a valid trace that reads back unchanged.
pub fn tobii_g3(data: &[u8]) {
    check_import(vitreous_trace::import::tobii_g3::parse_tobii_g3(
        data, "fuzz.gz", None,
    ));
}

/// The files a Neon recording folder may hold, by the index [`neon`] inputs name them with.
pub const NEON_FILES: [&str; 16] = [
    "gaze ps1.raw",
    "gaze ps1.time",
    "gaze.dtype",
    "eye_state ps1.raw",
    "eye_state ps1.time",
    "eye_state.dtype",
    "blinks ps1.raw",
    "blinks ps1.time",
    "blinks.dtype",
    "imu ps1.raw",
    "imu ps1.time",
    "imu.dtype",
    "calibration.bin",
    "info.json",
    "gaze ps2.raw",
    "gaze ps2.time",
];

/// A Neon native recording folder, packed as the [`neon`] target reads it: per file one byte
/// (its index in [`NEON_FILES`]), its length (u32, little-endian) and its bytes.
pub fn pack_neon(files: &[(usize, &[u8])]) -> Vec<u8> {
    let mut packed = Vec::new();
    for (index, bytes) in files {
        packed.push(*index as u8);
        packed.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
        packed.extend_from_slice(bytes);
    }
    packed
}

/// The files of a packed folder ([`pack_neon`]), by name: an index wraps around the list, a
/// length past the end takes what is left, a file named twice keeps its last bytes.
pub fn unpack_neon(mut data: &[u8]) -> Vec<(&'static str, &[u8])> {
    let mut files: Vec<(&'static str, &[u8])> = Vec::new();
    while let [index, rest @ ..] = data {
        let name = NEON_FILES[*index as usize % NEON_FILES.len()];
        let (len, rest) = match rest.split_first_chunk::<4>() {
            Some((len, rest)) => (u32::from_le_bytes(*len) as usize, rest),
            None => (rest.len(), &[][..]),
        };
        let (bytes, rest) = rest.split_at(len.min(rest.len()));
        files.retain(|(n, _)| *n != name);
        files.push((name, bytes));
        data = rest;
    }
    files
}

/// A Pupil Labs Neon native recording, packed ([`pack_neon`]): its files are written to a
/// folder of their own (emptied first) and imported with
/// [`vitreous_trace::import::neon::import_neon`]; like [`sranipal`], a successful import must make a
/// valid trace that reads back unchanged.
pub fn neon(data: &[u8]) {
    thread_local! {
        static FOLDER: tempfile::TempDir = tempfile::Builder::new()
            .prefix("vitreous-fuzz-neon-")
            .tempdir()
            .expect("creating a temporary folder");
    }
    FOLDER.with(|folder| {
        let dir = folder.path();
        for entry in fs::read_dir(dir).expect("listing the recording folder") {
            fs::remove_file(entry.expect("listing the recording folder").path())
                .expect("emptying the recording folder");
        }
        for (name, bytes) in unpack_neon(data) {
            fs::write(dir.join(name), bytes).expect("writing a recording file");
        }
        check_import(vitreous_trace::import::neon::import_neon(dir));
    });
}

/// A caustic bake (OpenEXR): decoded with [`vitreous_scene::caustics::decode_bake`]; an accepted
/// bake has one finite, non-negative gain per texel.
pub fn bake(data: &[u8]) {
    match vitreous_scene::caustics::decode_bake(data) {
        Ok(bake) => {
            let texels = bake.width_px as usize * bake.height_px as usize;
            assert!(
                texels > 0 && bake.gain.len() == texels,
                "{} x {}",
                bake.width_px,
                bake.height_px
            );
            assert!(bake.gain.iter().all(|g| g.is_finite() && *g >= 0.0));
        }
        Err(reason) => assert!(!reason.is_empty()),
    }
}

/// An importer's result: the samples of a success must make a valid trace that reads back
/// unchanged, and the report (or the error) must format.
fn check_import(
    result: Result<(Vec<TraceSample>, impl std::fmt::Display), impl std::fmt::Display>,
) {
    match result {
        Ok((samples, report)) => {
            assert!(!report.to_string().is_empty());
            let written = write_all(&samples);
            let again = read_all(&written)
                .unwrap_or_else(|e| panic!("an imported trace does not read back: {e}"));
            assert_eq!(
                samples, again,
                "the imported trace changed when written and read"
            );
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// Scene TOML text: loaded with [`vitreous_scene::load_scene_from`] as `scene.toml` in a
/// folder holding the small assets of `assets/` (`model.glb`, `photo.png`, `env.hdr`). The
/// scene and the assets are served from memory: writing and reading files each time took
/// half of every execution.
pub fn scene(data: &[u8]) {
    match load_scene(data) {
        Ok(scene) => assert!(!format!("{scene:?}").is_empty()),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// What the scene target does with `data`: the scene it loads or the error.
pub fn load_scene(data: &[u8]) -> Result<Scene, SceneError> {
    let files = MemoryFiles {
        scene_path: asset_dir().join("scene.toml"),
        scene: data,
        assets: assets(),
    };
    vitreous_scene::load_scene_from(&files.scene_path, &files)
}

/// The scene under test and the assets, by path.
struct MemoryFiles<'a> {
    scene_path: PathBuf,
    scene: &'a [u8],
    assets: &'a HashMap<PathBuf, Vec<u8>>,
}

impl SceneFiles for MemoryFiles<'_> {
    fn read_bounded(&self, path: &Path, limit: u64, what: &str) -> io::Result<Vec<u8>> {
        let bytes = if path == self.scene_path {
            self.scene
        } else {
            self.assets
                .get(path)
                .ok_or_else(|| io::Error::from(io::ErrorKind::NotFound))?
        };
        if bytes.len() as u64 > limit {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("larger than {} KiB; {what}", limit / 1024),
            ));
        }
        Ok(bytes.to_vec())
    }
}

/// The files of [`asset_dir`], read once.
fn assets() -> &'static HashMap<PathBuf, Vec<u8>> {
    static ASSETS: OnceLock<HashMap<PathBuf, Vec<u8>>> = OnceLock::new();
    ASSETS.get_or_init(|| {
        let dir = asset_dir();
        let entries =
            fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
        entries
            .map(|entry| {
                let path = entry.expect("listing assets").path();
                let bytes = fs::read(&path)
                    .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
                (path, bytes)
            })
            .collect()
    })
}

/// glTF or GLB bytes: loaded with [`vitreous_scene::load_mesh`], external buffers resolved
/// against the same asset folder; an accepted mesh must be consistent.
pub fn gltf(data: &[u8]) {
    match vitreous_scene::load_mesh(data, asset_dir()) {
        Ok((mesh, _ior)) => {
            let n = mesh.positions.len();
            assert!(n > 0 && mesh.indices.len() % 3 == 0, "{mesh:?}");
            assert_eq!(mesh.normals.len(), n, "one normal per vertex");
            assert_eq!(mesh.uvs.len(), n, "one uv per vertex");
            assert!(
                mesh.indices.iter().all(|&i| (i as usize) < n),
                "an index is out of range"
            );
        }
        Err(e) => assert!(!e.is_empty()),
    }
}

/// Reads a whole trace from bytes; the error as its message.
fn read_all(data: &[u8]) -> Result<Vec<TraceSample>, String> {
    let reader = TraceReader::new(data, "fuzz.csv").map_err(|e| e.to_string())?;
    reader
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())
}

/// Writes samples as a trace (version 1.3 when any carries the tracker's report, so that a
/// report after a first sample without one is kept); every one must be accepted.
fn write_all(samples: &[TraceSample]) -> Vec<u8> {
    let version = if samples.iter().any(|s| s.gaze.report.is_some()) {
        TraceVersion::V1_3
    } else {
        TraceVersion::V1_1
    };
    let mut writer =
        TraceWriter::with_version(Vec::new(), "<output>", version).expect("writing to memory");
    for (i, sample) in samples.iter().enumerate() {
        if let Err(e) = writer.write(sample) {
            panic!("sample {i} was accepted but cannot be written: {e}\n{sample:?}");
        }
    }
    writer.finish().expect("flushing to memory")
}

/// A folder, made once per process, holding copies of the files in `assets/`: where the glTF
/// target's external buffers and the scene target's files are.
fn asset_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::Builder::new()
            .prefix("vitreous-fuzz-")
            .tempdir()
            .expect("creating a temporary folder")
            .keep();
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
        let entries = fs::read_dir(&assets)
            .unwrap_or_else(|e| panic!("cannot list {}: {e}", assets.display()));
        for entry in entries {
            let from = entry.expect("listing assets").path();
            if let Some(name) = from.file_name() {
                fs::copy(&from, dir.join(name))
                    .unwrap_or_else(|e| panic!("cannot copy {}: {e}", from.display()));
            }
        }
        dir
    })
}
