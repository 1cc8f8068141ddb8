//! Files that appear under their name only once complete.
//!
//! An [`AtomicFile`] is written to a temporary file in the target's folder (so the final
//! rename stays on one file system) and renamed over the target by [`AtomicFile::commit`].
//! An interrupted write therefore never leaves a half-written file under the final name:
//! dropped without a commit (an error, a panic), the temporary file is removed; after a
//! crash or `kill -9` it is left beside the target as `.NAME.XXXXXX.partial`.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

/// A file being written under a temporary name, renamed to its final name on commit.
#[derive(Debug)]
pub struct AtomicFile {
    /// The final path.
    path: PathBuf,
    /// The temporary file in the target's folder, until committed.
    temp: Option<BufWriter<NamedTempFile>>,
    /// The file under its final name, once committed (further writes go to it).
    committed: Option<File>,
}

impl AtomicFile {
    /// Starts writing `path`: creates a temporary file in its folder. Nothing appears under
    /// `path` until [`AtomicFile::commit`].
    pub fn create(path: impl AsRef<Path>) -> io::Result<Self> {
        let path = path.as_ref().to_path_buf();
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = path
            .file_name()
            .ok_or_else(|| {
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    "the path names a folder, not a file",
                )
            })?
            .to_string_lossy()
            .into_owned();
        let temp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".partial")
            // Like a plain create: 0666 less the umask, not tempfile's private 0600.
            .permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666))
            .tempfile_in(folder)?;
        Ok(AtomicFile {
            path,
            temp: Some(BufWriter::new(temp)),
            committed: None,
        })
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the temporary file over the final path. On failure the
    /// temporary file is kept (and removed when `self` is dropped); committing again after
    /// success only flushes.
    pub fn commit(&mut self) -> io::Result<()> {
        let Some(mut writer) = self.temp.take() else {
            return self.committed.as_mut().map_or(Ok(()), File::flush);
        };
        let synced = writer
            .flush()
            .and_then(|()| writer.get_ref().as_file().sync_all());
        if let Err(e) = synced {
            self.temp = Some(writer);
            return Err(e);
        }
        let temp = match writer.into_inner() {
            Ok(temp) => temp,
            Err(e) => {
                let (error, writer) = e.into_parts();
                self.temp = Some(writer);
                return Err(error);
            }
        };
        match temp.persist(&self.path) {
            Ok(file) => {
                self.committed = Some(file);
                Ok(())
            }
            Err(e) => {
                self.temp = Some(BufWriter::new(e.file));
                Err(e.error)
            }
        }
    }

    /// Where writes go now.
    fn target(&mut self) -> io::Result<&mut dyn Write> {
        match (&mut self.temp, &mut self.committed) {
            (Some(w), _) => Ok(w),
            (None, Some(f)) => Ok(f),
            (None, None) => Err(io::Error::other("the file was lost by a failed commit")),
        }
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.target()?.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.target()?.flush()
    }
}

/// Writes `bytes` to `path` through an [`AtomicFile`]: the old file or none is left under the
/// name if anything fails, never a half-written one.
pub fn write(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_appears_under_the_name_until_commit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.trace");
        let mut f = AtomicFile::create(&path).unwrap();
        f.write_all(b"hello").unwrap();
        f.flush().unwrap();
        assert!(!path.exists());
        f.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"hello");
        drop(f);
        // Only the final file is left.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn dropped_without_commit_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.trace");
        std::fs::write(&path, b"earlier run").unwrap();
        let mut f = AtomicFile::create(&path).unwrap();
        f.write_all(b"half").unwrap();
        f.flush().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"earlier run");
        drop(f);
        assert_eq!(std::fs::read(&path).unwrap(), b"earlier run");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn missing_folder_and_folder_paths_fail() {
        let dir = tempfile::tempdir().unwrap();
        assert!(AtomicFile::create(dir.path().join("no/such/x.trace")).is_err());
        assert!(AtomicFile::create("/").is_err());
    }
}
