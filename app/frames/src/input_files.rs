//! The files a command reads, and the check that no output of the command names one of them:
//! an output written over its own input destroys it (a scene replaced by an error map, a
//! recording by its import). A command gathers what it reads into [`InputFiles`] and checks
//! every output file ([`InputFiles::check_file`]) and every output folder
//! ([`InputFiles::check_folder`]) before it writes anything.
//!
//! Two paths name the same file when both exist and share device and inode, so a hard link or
//! a symbolic link to an input is that input; a path that does not exist yet is compared by
//! its folder's canonical path and its file name.

use std::fs;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

use vitreous_scene::Scene;

/// An output that would replace a file the command reads.
#[derive(Debug, thiserror::Error)]
pub enum OutputClash {
    /// The output file is an input.
    #[error(
        "{option} {}: that is the input file {} ({role}), which this command reads: choose \
         another output file",
        output.display(),
        input.display()
    )]
    File {
        /// The option naming the output (`--map`).
        option: String,
        /// The output as given.
        output: PathBuf,
        /// The input as given.
        input: PathBuf,
        /// What the input is to the command (`--scene`, `the scene's floor.photo`).
        role: String,
    },
    /// A file the command writes (or replaces) inside its output folder is an input.
    #[error(
        "{option} {}: the command writes {} there, which is the input file {} ({role}): \
         choose another output folder",
        folder.display(),
        written.display(),
        input.display()
    )]
    InFolder {
        /// The option naming the folder (`--out`).
        option: String,
        /// The folder as given.
        folder: PathBuf,
        /// The file inside it the command writes.
        written: PathBuf,
        /// The input as given.
        input: PathBuf,
        /// What the input is to the command.
        role: String,
    },
}

/// Which file a path names, as far as it can be told without reading it.
#[derive(Clone, Debug, PartialEq, Eq)]
enum FileId {
    /// An existing file: its device and inode (whatever links lead to it).
    Inode(u64, u64),
    /// A path that does not exist (yet): its folder's canonical path joined with its name.
    Path(PathBuf),
}

impl FileId {
    fn of(path: &Path) -> FileId {
        if let Ok(meta) = fs::metadata(path) {
            return FileId::Inode(meta.dev(), meta.ino());
        }
        let name = path.file_name().map(PathBuf::from).unwrap_or_default();
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        FileId::Path(match fs::canonicalize(folder) {
            Ok(folder) => folder.join(name),
            Err(_) => path.to_path_buf(),
        })
    }
}

/// One file a command reads.
#[derive(Clone, Debug)]
struct Input {
    /// The path as the command was given it.
    path: PathBuf,
    /// What it is to the command, for the message.
    role: String,
    /// Which file it is, taken when it was added.
    id: FileId,
}

/// The files a command reads, to check its outputs against.
#[derive(Clone, Debug, Default)]
pub struct InputFiles {
    inputs: Vec<Input>,
}

impl InputFiles {
    /// No inputs yet.
    pub fn new() -> InputFiles {
        InputFiles::default()
    }

    /// Adds `path`, which the command reads as `role` (the option or argument that names it:
    /// `--trace`, `REFERENCE`).
    pub fn add(&mut self, path: &Path, role: &str) -> &mut InputFiles {
        self.inputs.push(Input {
            path: path.to_path_buf(),
            role: role.to_owned(),
            id: FileId::of(path),
        });
        self
    }

    /// Adds the scene file given as `option`, every asset it read and its caustic bake
    /// ([`Scene::files`]), each asset's role its field in the scene file.
    pub fn add_scene(&mut self, scene: &Scene, option: &str) -> &mut InputFiles {
        for (field, path) in scene.files() {
            let role = if field == "scene" {
                option.to_owned()
            } else {
                format!("{field} in {}", scene.path.display())
            };
            self.add(path, &role);
        }
        self
    }

    /// The input `path` names, if any.
    fn input_at(&self, path: &Path) -> Option<&Input> {
        let id = FileId::of(path);
        self.inputs.iter().find(|input| input.id == id)
    }

    /// Refuses an output file `output`, given as `option`, that is one of the inputs.
    pub fn check_file(&self, option: &str, output: &Path) -> Result<(), OutputClash> {
        match self.input_at(output) {
            Some(input) => Err(OutputClash::File {
                option: option.to_owned(),
                output: output.to_path_buf(),
                input: input.path.clone(),
                role: input.role.clone(),
            }),
            None => Ok(()),
        }
    }

    /// Refuses an output folder `folder`, given as `option`, that is an input file itself or
    /// that holds an input under a name the command writes or replaces there: `writes` says,
    /// for a path relative to `folder` (`summary.json`, `frames/000000-left.png`), whether the
    /// command writes it. The files already in `folder` and in its folders `subfolders` are
    /// looked at; a folder that does not exist holds no input.
    pub fn check_folder(
        &self,
        option: &str,
        folder: &Path,
        subfolders: &[&str],
        writes: &dyn Fn(&Path) -> bool,
    ) -> Result<(), OutputClash> {
        self.check_file(option, folder)?;
        for sub in std::iter::once("").chain(subfolders.iter().copied()) {
            let Ok(entries) = fs::read_dir(folder.join(sub)) else {
                continue;
            };
            for entry in entries.flatten() {
                let relative = Path::new(sub).join(entry.file_name());
                if !writes(&relative) {
                    continue;
                }
                if let Some(input) = self.input_at(&entry.path()) {
                    return Err(OutputClash::InFolder {
                        option: option.to_owned(),
                        folder: folder.to_path_buf(),
                        written: relative,
                        input: input.path.clone(),
                        role: input.role.clone(),
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder with `in.csv` holding `x`.
    fn folder_with_input() -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.csv");
        fs::write(&input, "x").unwrap();
        (dir, input)
    }

    #[test]
    fn an_output_naming_an_input_by_any_path_or_link_is_refused() {
        let (dir, input) = folder_with_input();
        let mut inputs = InputFiles::new();
        inputs.add(&input, "--trace");
        let e = inputs.check_file("-o", &input).unwrap_err().to_string();
        assert!(e.contains("-o ") && e.contains("is the input file"), "{e}");
        assert!(e.contains("(--trace)"), "{e}");
        // The same file through `.`, a symbolic link and a hard link.
        let dotted = dir.path().join(".").join("in.csv");
        let symlink = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&input, &symlink).unwrap();
        let hard = dir.path().join("hard.csv");
        fs::hard_link(&input, &hard).unwrap();
        for other in [&dotted, &symlink, &hard] {
            assert!(
                inputs.check_file("-o", other).is_err(),
                "{}",
                other.display()
            );
        }
        assert!(inputs.check_file("-o", &dir.path().join("out.csv")).is_ok());
        assert_eq!(fs::read(&input).unwrap(), b"x");
    }

    #[test]
    fn an_input_that_does_not_exist_yet_is_matched_by_its_folder_and_name() {
        let dir = tempfile::tempdir().unwrap();
        let mut inputs = InputFiles::new();
        inputs.add(&dir.path().join("later.csv"), "--responses");
        let through_dot = dir.path().join(".").join("later.csv");
        assert!(inputs.check_file("-o", &through_dot).is_err());
        assert!(
            inputs
                .check_file("-o", &dir.path().join("other.csv"))
                .is_ok()
        );
    }

    #[test]
    fn an_output_folder_holding_an_input_under_a_written_name_is_refused() {
        let (dir, input) = folder_with_input();
        let frames = dir.path().join("frames");
        fs::create_dir(&frames).unwrap();
        let linked = frames.join("000000-left.png");
        fs::hard_link(&input, &linked).unwrap();
        let mut inputs = InputFiles::new();
        inputs.add(&input, "--scene");
        let writes_csv = |p: &Path| p == Path::new("in.csv");
        let e = inputs
            .check_folder("--out", dir.path(), &[], &writes_csv)
            .unwrap_err()
            .to_string();
        assert!(e.contains("writes in.csv there"), "{e}");
        // Under a name the command does not write, the input is left alone.
        let writes_other = |p: &Path| p == Path::new("summary.json");
        assert!(
            inputs
                .check_folder("--out", dir.path(), &["frames"], &writes_other)
                .is_ok()
        );
        // In a subfolder, when the command writes there.
        let writes_frames = |p: &Path| p.starts_with("frames");
        let e = inputs
            .check_folder("--out", dir.path(), &["frames"], &writes_frames)
            .unwrap_err()
            .to_string();
        assert!(e.contains("frames/000000-left.png"), "{e}");
        // The folder being the input file itself, and a folder not made yet.
        assert!(
            inputs
                .check_folder("--out", &input, &[], &writes_csv)
                .is_err()
        );
        let fresh = dir.path().join("new");
        assert!(
            inputs
                .check_folder("--out", &fresh, &[], &writes_csv)
                .is_ok()
        );
        assert_eq!(fs::read(&input).unwrap(), b"x");
    }
}
