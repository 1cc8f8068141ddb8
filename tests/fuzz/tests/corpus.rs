//! Runs every fuzz target over its corpus (`corpus/<target>/`) and over truncations of each
//! corpus file, on stable and without libFuzzer, so that `cargo test` keeps the harness
//! building and catches a regression on any input that once crashed.
//!
//! Then each target runs for a couple of seconds on random edits of its corpus (no coverage
//! guidance: that is what `tools/fuzz` is for).
//!
//! A panic counts as a failure even where the code under test catches it (the third-party
//! decoders run under `catch_unwind`): the hook below counts panics per thread.

use std::cell::Cell;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::time::{Duration, Instant};

thread_local! {
    /// Panics seen on this thread since the last [`take_panics`].
    static PANICS: Cell<usize> = const { Cell::new(0) };
}

/// Installs (once) a panic hook that counts panics on the panicking thread, then prints them
/// as usual.
fn count_panics() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICS.with(|p| p.set(p.get() + 1));
            default(info);
        }));
    });
}

fn take_panics() -> usize {
    PANICS.with(|p| p.replace(0))
}

/// The corpus files of `target`, sorted.
fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("corpus")
        .join(target);
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|entry| entry.expect("listing the corpus").path())
        .filter(|path| path.is_file())
        .collect();
    files.sort();
    files
}

/// Runs `target` on every corpus file and on 16 truncations of each; returns the inputs
/// that panicked, named by file and length.
fn survive(target: &str) -> (usize, Vec<String>) {
    count_panics();
    let files = corpus(target);
    assert!(!files.is_empty(), "corpus/{target} is empty");
    let mut runs = 0;
    let mut failed = Vec::new();
    for file in &files {
        let data = fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let mut lengths: Vec<usize> = (0..16).map(|k| data.len() * k / 16).collect();
        lengths.push(data.len());
        lengths.dedup();
        for len in lengths {
            take_panics();
            let outcome =
                std::panic::catch_unwind(|| assert!(vitreous_fuzz::run(target, &data[..len])));
            runs += 1;
            if outcome.is_err() || take_panics() > 0 {
                failed.push(format!("{} (first {len} bytes)", file.display()));
            }
        }
    }
    (runs, failed)
}

/// Small xorshift generator: the mutations are the same on every run.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n.max(1) as u64) as usize
    }
}

/// Bytes that often sit at parser decisions in these formats.
const INTERESTING: &[u8] = b"\0\n\r,;.-+eE0159[]{}\"=#\xff\x7f";

/// One to four random edits of `data`: overwrite, insert, delete or repeat a range.
fn mutate(rng: &mut Rng, data: &mut Vec<u8>) {
    for _ in 0..=rng.below(4) {
        let at = rng.below(data.len() + 1);
        match rng.below(4) {
            0 if at < data.len() => data[at] = INTERESTING[rng.below(INTERESTING.len())],
            1 => data.insert(at, INTERESTING[rng.below(INTERESTING.len())]),
            2 => {
                let end = (at + 1 + rng.below(16)).min(data.len());
                data.drain(at.min(end)..end);
            }
            _ => {
                let end = (at + 1 + rng.below(64)).min(data.len());
                let piece = data[at.min(end)..end].to_vec();
                let to = rng.below(data.len() + 1);
                data.splice(to..to, piece);
            }
        }
    }
}

/// Runs `target` on random edits of its corpus files for `budget`; panics name the
/// generator state that reproduces the input.
fn mutations(target: &str, budget: Duration) -> usize {
    count_panics();
    let seeds: Vec<Vec<u8>> = corpus(target)
        .iter()
        .map(|f| fs::read(f).unwrap_or_else(|e| panic!("{}: {e}", f.display())))
        .collect();
    let start = Instant::now();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut runs = 0;
    while start.elapsed() < budget {
        let state = rng.0;
        let mut data = seeds[rng.below(seeds.len())].clone();
        mutate(&mut rng, &mut data);
        take_panics();
        let outcome = std::panic::catch_unwind(|| vitreous_fuzz::run(target, &data));
        assert!(
            outcome.is_ok() && take_panics() == 0,
            "{target}: a mutated input panicked (generator state {state:#x}, run {runs}):\n{}",
            String::from_utf8_lossy(&data)
        );
        runs += 1;
    }
    runs
}

/// Seconds of random edits per target: `VITREOUS_FUZZ_SECONDS`, default 2.
fn mutation_budget() -> Duration {
    let seconds = std::env::var("VITREOUS_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.0);
    Duration::from_secs_f64(seconds)
}

fn check(target: &str) {
    let (runs, failed) = survive(target);
    assert!(
        failed.is_empty(),
        "{target}: {} of {runs} inputs panicked:\n{}",
        failed.len(),
        failed.join("\n")
    );
    let edits = mutations(target, mutation_budget());
    println!("{target}: {runs} corpus inputs and {edits} random edits, no panic");
}

#[test]
fn trace_v1_survives_its_corpus() {
    check("trace_v1");
}

#[test]
fn sranipal_survives_its_corpus() {
    check("sranipal");
}

#[test]
fn tobii_g3_survives_its_corpus() {
    check("tobii_g3");
}

#[test]
fn neon_survives_its_corpus() {
    check("neon");
}

/// The seeds are whole recordings (the committed fixture of `trace/tests/data/neon`, packed): each
/// one imports, so the fuzzer starts past the folder's checks.
#[test]
fn every_neon_seed_imports() {
    every_seed("neon", |data| {
        let dir = tempfile::tempdir().expect("a temporary folder");
        for (name, bytes) in vitreous_fuzz::unpack_neon(data) {
            fs::write(dir.path().join(name), bytes).expect("writing a recording file");
        }
        let imported = vitreous_trace::import::neon::import_neon(dir.path());
        imported.map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn packing_a_neon_folder_round_trips() {
    let files: [(usize, &[u8]); 3] = [(0, b"ab"), (13, b"{}"), (0, b"xyz")];
    let packed = vitreous_fuzz::pack_neon(&files);
    let unpacked = vitreous_fuzz::unpack_neon(&packed);
    assert_eq!(
        unpacked,
        [("info.json", &b"{}"[..]), ("gaze ps1.raw", &b"xyz"[..])]
    );
    // A cut length takes what is left; an index past the list wraps around.
    assert_eq!(
        vitreous_fuzz::unpack_neon(&[17, 9, 0]),
        [("gaze ps1.time", &[][..])]
    );
    assert_eq!(
        vitreous_fuzz::unpack_neon(&[2, 5, 0, 0, 0, b'a']),
        [("gaze.dtype", &b"a"[..])]
    );
}

#[test]
fn bake_survives_its_corpus() {
    check("bake");
}

/// The seeds are real bakes: each one decodes.
#[test]
fn every_bake_seed_decodes() {
    every_seed("bake", |data| {
        vitreous_scene::caustics::decode_bake(data).map(drop)
    });
}

#[test]
fn scene_survives_its_corpus() {
    check("scene");
}

/// The seeds are whole scenes: served from memory, each one loads, so the fuzzer starts past
/// the asset reads rather than at "file not found".
#[test]
fn every_scene_seed_loads() {
    every_seed("scene", |data| {
        vitreous_fuzz::load_scene(data)
            .map(drop)
            .map_err(|e| e.to_string())
    });
}

/// Panics naming the first seed of `target` that `accept` refuses, with its reason.
fn every_seed(target: &str, accept: impl Fn(&[u8]) -> Result<(), String>) {
    for path in corpus(target) {
        let data = fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if let Err(e) = accept(&data) {
            panic!("{}: {e}", path.display());
        }
    }
}

#[test]
fn gltf_survives_its_corpus() {
    check("gltf");
}

#[test]
fn study_survives_its_corpus() {
    check("study");
}

#[test]
fn every_target_has_a_test_and_a_corpus() {
    assert_eq!(
        vitreous_fuzz::TARGETS,
        [
            "trace_v1", "sranipal", "tobii_g3", "neon", "scene", "gltf", "study", "bake"
        ]
    );
    for target in vitreous_fuzz::TARGETS {
        assert!(!corpus(target).is_empty(), "corpus/{target} is empty");
    }
    assert!(!vitreous_fuzz::run("no-such-target", b""));
}
